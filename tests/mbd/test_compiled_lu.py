"""The compiled fixed-pattern sparse LU (mbd.compiled.sparse_lu): 3×3 blocks on SuperLU's order, against a
scalar column LU on the same order (bit for bit) and against scipy's SuperLU and spsolve (the solution)."""
from __future__ import annotations

import warnings

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from hypothesis import given, settings, strategies as st

import mbd
from components.dpgt import build_dpgt
from components.params import with_overrides
from components.presets import reference_dpgt
from mbd.compiled.runner import _tilts_late
from mbd.compiled.sparse_lu import FixedPatternLU

from tests.support.dpgt_runs import ramp_state


def _pattern(n, density, seed):
    """A structurally symmetric pattern with a full diagonal, like a Newton matrix."""
    rng = np.random.default_rng(seed)
    R = sp.random(n, n, density=density, random_state=rng, format="csc")
    P = ((R + R.T + sp.identity(n)) != 0).astype(float).tocsc()
    P.sort_indices()
    return P


def _column_lu_solve(A, perm, b):
    """The scalar left-looking column LU of A[perm][:, perm] with diagonal pivots, dense, and its solve: every
    entry takes its updates from the earlier columns in ascending order (the later ones in descending order in
    the backward solve), one multiply and one subtraction each (numpy ufuncs: no fused multiply-add)."""
    B = A.toarray()[np.ix_(perm, perm)]
    n = B.shape[0]
    L, U = np.eye(n), np.zeros((n, n))
    for k in range(n):
        x = B[:, k].copy()
        for j in range(k):
            x[j + 1:] -= L[j + 1:, j] * x[j]
        U[:k + 1, k] = x[:k + 1]
        L[k + 1:, k] = x[k + 1:] * (1.0 / x[k])
    y = b[perm].copy()
    for j in range(n):
        y[j + 1:] -= L[j + 1:, j] * y[j]
    for j in range(n - 1, -1, -1):
        y[j] /= U[j, j]
        y[:j] -= U[:j, j] * y[j]
    out = np.empty(n)
    out[perm] = y
    return out


def _dominant(P, rng, scale):
    vals = rng.standard_normal(P.nnz) * 10.0 ** scale
    A = sp.csc_matrix((vals, P.indices, P.indptr), shape=P.shape)
    A = (A + sp.diags(np.abs(A).sum(axis=1).A1 + 10.0 ** scale)).tocsc()   # dominant diagonal
    A.sort_indices()
    assert np.array_equal(A.indptr, P.indptr) and np.array_equal(A.indices, P.indices)
    return A


@settings(max_examples=40, deadline=None)
@given(n=st.integers(1, 60), density=st.floats(0.0, 0.3), seed=st.integers(0, 2**31), scale=st.floats(-6, 6))
def test_solves_like_superlu_on_every_matrix_of_the_pattern(n, density, seed, scale):
    P = _pattern(n, density, seed)
    lu = FixedPatternLU(P.indptr, P.indices, n)
    rng = np.random.default_rng(seed + 1)
    for _ in range(3):       # refactorise new values on the same pattern
        A = _dominant(P, rng, scale)
        assert lu.factor(A.data)
        b = rng.standard_normal(n)
        x = lu.solve(b)
        ref = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0).solve(b)
        np.testing.assert_allclose(x, ref, rtol=1e-10, atol=1e-12 * np.abs(ref).max())
        assert np.abs(A @ x - b).max() <= 1e-12 * (np.abs(A).max() * np.abs(x).max() + np.abs(b).max())
        np.testing.assert_array_equal(x, _column_lu_solve(A, lu.perm, b))     # the blocks change no bit


@settings(max_examples=40, deadline=None)
@given(n=st.integers(2, 50), density=st.floats(0.0, 0.3), seed=st.integers(0, 2**31), groups=st.integers(1, 20))
def test_late_columns_follow_their_group_and_change_no_solution(n, density, seed, groups):
    """Columns marked late go after the other columns of their group and before the first column outside it that
    they or the group couple to; the factors are still the scalar column LU's on that order, bit for bit."""
    P = _pattern(n, density, seed)
    rng = np.random.default_rng(seed + 2)
    group = rng.integers(0, groups, n)
    late = rng.random(n) < 0.3
    late[0] = True
    lu = FixedPatternLU(P.indptr, P.indices, n, late, group)
    at = np.empty(n, np.int64)
    at[lu.perm] = np.arange(n)
    assert np.array_equal(np.sort(lu.perm), np.arange(n))
    base = FixedPatternLU(P.indptr, P.indices, n)
    assert np.array_equal(lu.perm[~late[lu.perm]], base.perm[~late[base.perm]])     # the others keep their order
    for d in np.flatnonzero(late):
        own = np.flatnonzero((group == group[d]) & ~late)
        assert np.all(at[own] < at[d])
        near = np.unique(np.concatenate([P.indices[P.indptr[c]:P.indptr[c + 1]] for c in [d, *own]]))
        near = near[~late[near] & (group[near] != group[d])]
        later = near[at[near] > (at[own].max() if own.size else -1)]
        assert np.all(at[d] < at[later])
        # nothing but late columns between d and the column SuperLU's order had before it
        prev = [c for c in base.perm[:base.perm.tolist().index(min(later, key=lambda c: at[c]))]
                if not late[c]] if later.size else []
        assert all(at[c] < at[d] for c in prev)
    for _ in range(2):
        A = _dominant(P, rng, 0.0)
        assert lu.factor(A.data)
        b = rng.standard_normal(n)
        x = lu.solve(b)
        np.testing.assert_allclose(x, spla.spsolve(A, b), rtol=1e-10, atol=1e-12 * np.abs(x).max())
        np.testing.assert_array_equal(x, _column_lu_solve(A, lu.perm, b))


def test_a_zero_pivot_is_reported_not_divided_by():
    P = _pattern(5, 0.3, 3)
    lu = FixedPatternLU(P.indptr, P.indices, 5)
    assert not lu.factor(np.zeros(P.nnz))
    with pytest.raises(RuntimeError, match="before a successful factor"):
        lu.solve(np.ones(5))
    ok = sp.csc_matrix((np.where(P.indices == np.repeat(np.arange(5), np.diff(P.indptr)), 2.0, 0.1),
                        P.indices, P.indptr), shape=(5, 5))
    assert lu.factor(ok.data)                          # the work arrays were left clean by the failure
    np.testing.assert_allclose(ok @ lu.solve(np.arange(5.0)), np.arange(5.0), rtol=1e-13, atol=1e-13)
    bad = ok.data.copy()
    bad[0] = np.nan
    assert not lu.factor(bad)
    assert lu.factor(ok.data)                          # and by a failure in a later column
    np.testing.assert_allclose(ok @ lu.solve(np.arange(5.0)), np.arange(5.0), rtol=1e-13, atol=1e-13)


def test_the_dense_fallback_pivots_where_the_diagonal_is_zero():
    from mbd.compiled.stepper import _dense_lu, _dense_solve
    rng = np.random.default_rng(4)
    A = rng.standard_normal((6, 6))
    A[0, 0] = 0.0                                      # diagonal pivoting would divide by zero here
    D = A.copy()
    ok, piv = _dense_lu(D)
    b = rng.standard_normal(6)
    assert ok
    np.testing.assert_allclose(_dense_solve(D, piv, b), np.linalg.solve(A, b), rtol=1e-12, atol=1e-12)
    ok, _ = _dense_lu(np.zeros((3, 3)))
    assert not ok


@pytest.fixture(scope="module")
def newton_matrices():
    """The DPGT's Newton matrices M + (1+α)(γhC + βh²K) (HHT α = −0.3, h = 5 µs) 3 ms into its load ramp: the
    planar machine and the sliced one (21 slices a roller, every slope and tilt at zero) at the same state."""
    sc, s = ramp_state(0.003, "compiled")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sliced = build_dpgt(with_overrides(reference_dpgt(3, "forward"),
                                           {"bearing.model": "sliced", "bearing.slicing.slices": 21}))
    hht, h = mbd.HHT(alpha=-0.3), 5e-6
    beta, gamma = hht.beta_gamma
    out = {}
    for name, model in (("planar", sc.model), ("sliced", sliced.model)):
        ext = lambda x: np.concatenate([x, np.zeros(model.ndof - x.size)])          # noqa: E731
        system = mbd.System(model)
        ev = system.evaluate(s.t, ext(s.q), ext(s.v), dict(s.z), jac=True)
        A = system.newton_matrix(ev, 1.0, 0.7 * gamma * h, 0.7 * beta * h * h)
        A.sort_indices()
        out[name] = (system, A, ev.F)
    return out


@pytest.mark.parametrize("machine", ["planar", "sliced"])
def test_the_machines_newton_matrix_is_solved_as_scipy_solves_it(newton_matrices, machine):
    """The residual of the solve at round-off, the solution scipy's to round-off (the matrix's condition allows
    it), and bit for bit the scalar column LU's on the same order; the blocks pad little."""
    system, A, F = newton_matrices[machine]
    assert np.array_equal(A.indptr, system._indptr) and np.array_equal(A.indices, system._indices)
    late, group = _tilts_late(system.model)
    lu = FixedPatternLU(system._indptr, system._indices, system.ndof, late, group)
    assert lu.factor(A.data)
    for b in (F, np.random.default_rng(7).standard_normal(system.ndof)):
        x = lu.solve(b)
        ref = spla.spsolve(A.tocsc(), b)
        assert np.abs(A @ x - b).max() <= 1e-13 * (abs(A).max() * np.abs(x).max())
        np.testing.assert_allclose(x, ref, rtol=0, atol=1e-9 * np.abs(ref).max())
        np.testing.assert_array_equal(x, _column_lu_solve(A, lu.perm, b))
    # a body's x, y, θ make a block: the planar machine's 87 bodies in 88 blocks (SuperLU splits one body)
    assert 3 * lu.blocks - system.ndof <= 0.05 * system.ndof
    names = [system.model.coordinate_name(int(f)) for f in system.model.free]
    if machine == "planar":                            # no tilt: SuperLU's order as it is
        assert late is None
        assert np.array_equal(lu.perm, FixedPatternLU(system._indptr, system._indices, system.ndof).perm)
        return
    # the sliced machine: every roller's tilt after its x, y, θ and before its cage, so that no block column
    # of L joins two rollers (with the tilts first, three to a block, each tilt block joined three rollers)
    at = {names[c]: k for k, c in enumerate(lu.perm)}
    tilts = [nm for nm in names if nm.endswith(".tilt")]
    assert len(tilts) == 72 and late.sum() == 72
    for t in tilts:
        body, bearing = t[:-len(".tilt")], t.split(".pb.")[0]
        assert max(at[f"{body}.{c}"] for c in "xyθ") < at[t] < at[f"{bearing}.pb.cage.x"]
    pos, BLp, BLi = lu.arrays[4], lu.arrays[5], lu.arrays[6]
    blocks = [set() for _ in range(lu.blocks)]         # the coordinates of each block
    for c, place in enumerate(pos):
        blocks[place // 3].add(names[c])
    roller = [len({nm.rsplit(".", 1)[0] for nm in b}) == 1 and ".roller" in next(iter(b))
              and not any(nm.endswith(".tilt") for nm in b) for b in blocks]
    assert sum(roller) == 72
    for J in np.flatnonzero(roller):
        assert not any(roller[I] for I in BLi[BLp[J]:BLp[J + 1]]), sorted(blocks[J])
