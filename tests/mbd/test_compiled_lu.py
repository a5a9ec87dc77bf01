"""The compiled fixed-pattern sparse LU (mbd.compiled.sparse_lu) against scipy's SuperLU."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from hypothesis import given, settings, strategies as st

from mbd.compiled.sparse_lu import FixedPatternLU


def _pattern(n, density, seed):
    """A structurally symmetric pattern with a full diagonal, like a Newton matrix."""
    rng = np.random.default_rng(seed)
    R = sp.random(n, n, density=density, random_state=rng, format="csc")
    P = ((R + R.T + sp.identity(n)) != 0).astype(float).tocsc()
    P.sort_indices()
    return P


@settings(max_examples=40, deadline=None)
@given(n=st.integers(1, 60), density=st.floats(0.0, 0.3), seed=st.integers(0, 2**31), scale=st.floats(-6, 6))
def test_solves_like_superlu_on_every_matrix_of_the_pattern(n, density, seed, scale):
    P = _pattern(n, density, seed)
    lu = FixedPatternLU(P.indptr, P.indices, n)
    rng = np.random.default_rng(seed + 1)
    for _ in range(3):       # refactorise new values on the same pattern
        vals = rng.standard_normal(P.nnz) * 10.0 ** scale
        A = sp.csc_matrix((vals, P.indices, P.indptr), shape=(n, n))
        A = (A + sp.diags(np.abs(A).sum(axis=1).A1 + 10.0 ** scale)).tocsc()   # dominant diagonal
        A.sort_indices()
        assert np.array_equal(A.indptr, P.indptr) and np.array_equal(A.indices, P.indices)
        assert lu.factor(A.data)
        b = rng.standard_normal(n)
        x = lu.solve(b)
        ref = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0).solve(b)
        np.testing.assert_allclose(x, ref, rtol=1e-10, atol=1e-12 * np.abs(ref).max())
        assert np.abs(A @ x - b).max() <= 1e-12 * (np.abs(A).max() * np.abs(x).max() + np.abs(b).max())


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
