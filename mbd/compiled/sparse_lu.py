"""Sparse LU of matrices that share one sparsity pattern (the Newton matrix of a model), in 3×3 blocks.

Symbolic analysis once: SuperLU (scipy) chooses the fill-reducing symmetric order (minimum degree on
AᵀA + A, as the numpy path asks it) and gives the patterns of L and U from a random matrix on the
pattern (no cancellation). On the DPGT that order is the bordered elimination by itself: every roller's
DOFs first (each couples only to its cage, its planet and the carrier that holds its pin), then the
cages, then the planets, the carrier, the sun and the ring — L and U hold 5 319 entries for the planar
machine's 4 941. Columns the caller marks late (``late``, with each column's ``group``, its body) move after their
group's other columns, right before the first column that either couples to (:func:`_late_order`): the sliced
machine's roller tilts, which minimum degree would eliminate first, three rollers' to a block, joining those rollers
in the block pattern. Without late columns the order is SuperLU's as it is.

Blocks: the ordered columns are cut into blocks of 3 — a run of columns with one pattern (a body's x, y, θ:
its element blocks couple all of them) fills blocks of 3, shorter runs share one (the sliced machine's
rollers' tilt coordinates, three rollers' of one bearing), and a block a column short is padded with a decoupled
unit column. The block pattern is the block graph's own elimination (it holds the scalar L and U). Each
block is a dense 3×3, so the factor and the solves run fixed-size code per block instead of a loop per
column through index arrays.

Numeric refactorisation, compiled: left-looking block LU on that fixed pattern with diagonal pivots — the
numpy path's choice (``diag_pivot_thresh = 0``): the Newton matrix M + (1+α)(γhC + βh²K) is dominated by
its diagonal mass, and the LU only drives Newton (the residual is exact). A zero or non-finite pivot
reports failure; the caller then falls back to partial pivoting. Every entry of L and U takes its
updates in the scalar left-looking LU's order on SuperLU's order (from the earlier columns, ascending;
the solves' from the earlier and the later columns, in their order), and a structurally zero entry of a
block contributes an exact zero: the factors and the solution are those of the scalar column LU on the
same order, bit for bit up to the sign of a zero (``tests/mbd/test_compiled_lu.py``).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit

__all__ = ["FixedPatternLU"]

_B = 3          # block size: a body's x, y, θ (the kernels below are written out for it)


@njit(cache=True)
def _factor(lu, data):
    """Left-looking 3×3-block LU of the ordered matrix with entries ``data`` (the pattern's CSC order) into the
    factors of ``lu`` (:attr:`FixedPatternLU.arrays`). X: the block column being eliminated, row-major (3 rows ×
    3 columns a block row); L, U blocks and the diagonal blocks (L strict lower with a unit diagonal, U upper)
    row-major. Returns False on a zero or non-finite pivot (X left clean)."""
    Sp, Sidx, Sx, dummy, pos, BLp, BLi, Lx, BUp, BUi, Ux, Dx, X, y = lu
    nb = Sp.size - 1
    for K in range(nb):
        k0 = 3 * K
        for p in range(Sp[K], Sp[K + 1]):                       # scatter block column K
            X[Sx[p]] = data[Sidx[p]]
        for c in range(3):
            if dummy[k0 + c]:
                X[3 * (k0 + c) + c] = 1.0
        for q in range(BUp[K], BUp[K + 1]):                     # U(J, K), J < K ascending
            J = BUi[q]
            x = 9 * J
            l10, l20, l21 = Dx[x + 3], Dx[x + 6], Dx[x + 7]     # J's own columns first (its diagonal block's L)
            u00, u01, u02 = X[x], X[x + 1], X[x + 2]
            u10 = X[x + 3] - l10 * u00
            u11 = X[x + 4] - l10 * u01
            u12 = X[x + 5] - l10 * u02
            u20 = (X[x + 6] - l20 * u00) - l21 * u10
            u21 = (X[x + 7] - l20 * u01) - l21 * u11
            u22 = (X[x + 8] - l20 * u02) - l21 * u12
            o = 9 * q
            Ux[o], Ux[o + 1], Ux[o + 2] = u00, u01, u02
            Ux[o + 3], Ux[o + 4], Ux[o + 5] = u10, u11, u12
            Ux[o + 6], Ux[o + 7], Ux[o + 8] = u20, u21, u22
            for e in range(9):
                X[x + e] = 0.0
            for b in range(BLp[J], BLp[J + 1]):                 # X(I, :) −= L(I, J) U(J, K), J's columns in order
                i = 9 * BLi[b]
                m = 9 * b
                for r in range(3):
                    a0, a1, a2 = Lx[m + 3 * r], Lx[m + 3 * r + 1], Lx[m + 3 * r + 2]
                    t = i + 3 * r
                    X[t] = ((X[t] - a0 * u00) - a1 * u10) - a2 * u20
                    X[t + 1] = ((X[t + 1] - a0 * u01) - a1 * u11) - a2 * u21
                    X[t + 2] = ((X[t + 2] - a0 * u02) - a1 * u12) - a2 * u22
        x = 9 * K                                               # the diagonal block, column by column
        ok = True
        for c in range(3):
            for j in range(c):                                  # column c's updates from K's earlier columns
                ujc = X[x + 3 * j + c]
                for r in range(j + 1, 3):
                    X[x + 3 * r + c] -= Dx[x + 3 * r + j] * ujc
                for b in range(BLp[K], BLp[K + 1]):
                    i = 9 * BLi[b]
                    m = 9 * b
                    X[i + c] -= Lx[m + j] * ujc
                    X[i + 3 + c] -= Lx[m + 3 + j] * ujc
                    X[i + 6 + c] -= Lx[m + 6 + j] * ujc
            for r in range(c + 1):
                Dx[x + 3 * r + c] = X[x + 3 * r + c]
            piv = X[x + 4 * c]
            if piv == 0.0 or not np.isfinite(piv):
                ok = False
                break
            inv = 1.0 / piv
            for r in range(c + 1, 3):
                Dx[x + 3 * r + c] = X[x + 3 * r + c] * inv
            for b in range(BLp[K], BLp[K + 1]):
                i = 9 * BLi[b]
                m = 9 * b
                Lx[m + c] = X[i + c] * inv
                Lx[m + 3 + c] = X[i + 3 + c] * inv
                Lx[m + 6 + c] = X[i + 6 + c] * inv
        for e in range(9):
            X[x + e] = 0.0
        for b in range(BLp[K], BLp[K + 1]):
            i = 9 * BLi[b]
            for e in range(9):
                X[i + e] = 0.0
        if not ok:
            return False
    return True


@njit(cache=True)
def _solve(lu, b):
    """x with A x = b from the factors in ``lu`` (forward with L by block columns, backward with U by block
    columns; padded entries stay zero)."""
    Sp, Sidx, Sx, dummy, pos, BLp, BLi, Lx, BUp, BUi, Ux, Dx, X, y = lu
    nb = Sp.size - 1
    for i in range(y.size):
        y[i] = 0.0
    for c in range(b.size):
        y[pos[c]] = b[c]
    for J in range(nb):                                         # L y = c (unit diagonal)
        j0 = 3 * J
        d = 9 * J
        y0 = y[j0]
        y1 = y[j0 + 1] - Dx[d + 3] * y0
        y2 = (y[j0 + 2] - Dx[d + 6] * y0) - Dx[d + 7] * y1
        y[j0 + 1], y[j0 + 2] = y1, y2
        for q in range(BLp[J], BLp[J + 1]):
            i0 = 3 * BLi[q]
            m = 9 * q
            y[i0] = ((y[i0] - Lx[m] * y0) - Lx[m + 1] * y1) - Lx[m + 2] * y2
            y[i0 + 1] = ((y[i0 + 1] - Lx[m + 3] * y0) - Lx[m + 4] * y1) - Lx[m + 5] * y2
            y[i0 + 2] = ((y[i0 + 2] - Lx[m + 6] * y0) - Lx[m + 7] * y1) - Lx[m + 8] * y2
    for K in range(nb - 1, -1, -1):                             # U y = y, the later columns first
        k0 = 3 * K
        d = 9 * K
        y2 = y[k0 + 2] / Dx[d + 8]
        y1 = (y[k0 + 1] - Dx[d + 5] * y2) / Dx[d + 4]
        y0 = ((y[k0] - Dx[d + 2] * y2) - Dx[d + 1] * y1) / Dx[d]
        y[k0], y[k0 + 1], y[k0 + 2] = y0, y1, y2
        for q in range(BUp[K], BUp[K + 1]):
            j0 = 3 * BUi[q]
            m = 9 * q
            y[j0] = ((y[j0] - Ux[m + 2] * y2) - Ux[m + 1] * y1) - Ux[m] * y0
            y[j0 + 1] = ((y[j0 + 1] - Ux[m + 5] * y2) - Ux[m + 4] * y1) - Ux[m + 3] * y0
            y[j0 + 2] = ((y[j0 + 2] - Ux[m + 8] * y2) - Ux[m + 7] * y1) - Ux[m + 6] * y0
    x = np.empty(b.size)
    for c in range(b.size):
        x[c] = y[pos[c]]
    return x


def _runs(S: sp.csr_matrix, n: int) -> list[int]:
    """Block widths over the ordered columns: runs of one pattern (with the column itself) in blocks of 3, the
    shorter runs sharing a block while they fit."""
    rows = [frozenset(S.indices[S.indptr[k]:S.indptr[k + 1]].tolist()) | {k} for k in range(n)]
    runs, k = [], 0
    while k < n:
        w = 1
        while k + w < n and rows[k + w] == rows[k]:
            w += 1
        while w > _B:
            runs.append(_B)
            w, k = w - _B, k + _B
        runs.append(w)
        k += w
    blocks: list[int] = []
    for w in runs:
        if w < _B and blocks and blocks[-1] + w <= _B:
            blocks[-1] += w
        else:
            blocks.append(w)
    return blocks


def _late_order(perm, sym, late, group) -> np.ndarray:
    """SuperLU's order ``perm`` with every ``late`` column moved after the other columns of its ``group`` (its
    body), right before the first column eliminated after them that either couples to (the body's other
    neighbours: elimination joins them); the late columns keep their relative order. On the sliced machine a
    roller's tilt couples to a subset of its x, y, θ's neighbours, so minimum degree eliminates it first, one
    column at a time; three to a block, the tilts of three rollers then join those rollers' blocks in the block
    pattern. After the rollers and before their cage they share blocks with no such fill."""
    n = perm.size
    pos = np.empty(n, np.int64)
    pos[perm] = np.arange(n)
    key = 2 * pos                                    # the others keep their places, a late one goes between two
    for d in np.flatnonzero(late):
        own = np.flatnonzero((group == group[d]) & ~late)
        near = np.unique(np.concatenate([sym.indices[sym.indptr[c]:sym.indptr[c + 1]] for c in [d, *own]]))
        near = near[~late[near] & (group[near] != group[d])]
        after = pos[own].max() if own.size else -1
        near = pos[near][pos[near] > after]
        key[d] = 2 * (near.min() if near.size else n) - 1
    return np.lexsort((pos, key)).astype(np.int64)


class FixedPatternLU:
    """LU of n×n CSC matrices with the pattern (indptr, indices); ``factor(data)`` then ``solve(b)``. ``late``,
    ``group`` (optional, (n,) bool and int): columns eliminated after the other columns of their group (module text).
    ``arrays``: the factors and their pattern, for :func:`_factor` and :func:`_solve` in compiled code."""

    def __init__(self, indptr, indices, n: int, late=None, group=None):
        self.n = n = int(n)
        self.indptr = np.ascontiguousarray(indptr, dtype=np.int64)
        self.indices = np.ascontiguousarray(indices, dtype=np.int64)
        nnz = self.indices.size
        pattern = sp.csc_matrix((np.ones(nnz), self.indices, self.indptr), shape=(n, n))
        rng = np.random.default_rng(0)                   # random values: no cancellation in the sample
        sym = (pattern + pattern.T).tocsc()
        sample = sp.csc_matrix((1.0 + rng.random(sym.nnz), sym.indices, sym.indptr), shape=(n, n))
        sample = (sample + sp.identity(n) * (4.0 * n)).tocsc()
        lu = spla.splu(sample, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0)
        if not np.array_equal(lu.perm_r, lu.perm_c):     # cannot happen with a dominant diagonal
            raise RuntimeError("FixedPatternLU: SuperLU chose off-diagonal pivots on the sample")
        # SuperLU: column c of A is column perm_c[c] of L U; perm[k]: the column of A eliminated k-th
        iperm = np.asarray(lu.perm_c, dtype=np.int64)
        perm = np.argsort(iperm)
        if late is not None and (np.shape(late) != (n,) or np.shape(group) != (n,)):
            raise ValueError(f"FixedPatternLU: late and group must be arrays of shape ({n},), "
                             f"got {np.shape(late)} and {np.shape(group)}")
        if late is not None and np.any(late):
            perm = _late_order(perm, sym, np.asarray(late, bool), np.asarray(group, np.int64))
            iperm = np.argsort(perm)
            ordered = sp.csc_matrix(sample[perm][:, perm])
            ordered.sort_indices()
            lu = spla.splu(ordered, permc_spec="NATURAL", diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))
            if not (np.array_equal(lu.perm_c, np.arange(n)) and np.array_equal(lu.perm_r, np.arange(n))):
                raise RuntimeError("FixedPatternLU: SuperLU reordered the late columns' order")
        L = sp.tril(sp.csc_matrix(lu.L), k=-1).tocoo()
        U = sp.csc_matrix(lu.U).tocoo()
        self.fill = int(L.nnz + U.nnz)                   # scalar entries of L (no unit diagonal) and U
        # blocks over the order
        S = ((sym != 0).tocsr()[perm][:, perm]).tocsr()
        S.sort_indices()
        widths = _runs(S, n)
        nb = len(widths)
        blk = np.repeat(np.arange(nb), widths)
        slot = np.concatenate([np.arange(w) for w in widths]) if n else np.zeros(0, np.int64)
        where = 3 * blk + slot                           # padded place of the k-th eliminated column
        dummy = np.ones(3 * nb, np.int64)
        dummy[where] = 0
        # the block pattern: the block graph of L + U eliminated in the block order (natural, diagonal pivots)
        br = np.concatenate([blk[L.row], blk[U.row], np.arange(nb)])
        bc = np.concatenate([blk[L.col], blk[U.col], np.arange(nb)])
        Q = sp.csc_matrix((np.ones(br.size), (br, bc)), shape=(nb, nb))
        Q = ((Q + Q.T) != 0).astype(float).tocsc()
        Q.data = 1.0 + rng.random(Q.nnz)
        Q = (Q + sp.identity(nb) * (4.0 * nb)).tocsc()
        qlu = spla.splu(Q, permc_spec="NATURAL", diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))
        if not (np.array_equal(qlu.perm_c, np.arange(nb)) and np.array_equal(qlu.perm_r, np.arange(nb))):
            raise RuntimeError("FixedPatternLU: SuperLU reordered the block graph")
        BL = sp.tril(sp.csc_matrix(qlu.L), k=-1, format="csc")
        BL.sort_indices()
        BU = sp.triu(sp.csc_matrix(qlu.U), k=1, format="csc")
        BU.sort_indices()
        have = set(zip(*sp.tril(abs(BL) + abs(BU.T) + sp.identity(nb), format="coo").nonzero()))
        lo = np.maximum(br, bc), np.minimum(br, bc)
        if not all((int(r), int(c)) in have for r, c in zip(*lo)):
            raise RuntimeError("FixedPatternLU: the block pattern misses an entry of L or U")
        # A's entries by block column: its index in data, its place in X (padded row, column within the block)
        place = where[iperm]                             # padded place of A's row / column c
        col = np.repeat(np.arange(n), np.diff(self.indptr))
        pr, pc = place[self.indices], place[col]
        order = np.lexsort((pr, pc))
        Sp = np.searchsorted(pc[order] // 3, np.arange(nb + 1)).astype(np.int64)
        i64 = lambda a: np.ascontiguousarray(a, dtype=np.int64)          # noqa: E731
        self.blocks = nb
        self.perm = perm                                 # perm[k]: the column of A eliminated k-th
        self.arrays = (Sp, i64(order), i64(3 * pr[order] + pc[order] % 3), dummy, i64(place),
                       i64(BL.indptr), i64(BL.indices), np.zeros(9 * BL.indices.size),
                       i64(BU.indptr), i64(BU.indices), np.zeros(9 * BU.indices.size),
                       np.zeros(9 * nb), np.zeros(9 * nb), np.zeros(3 * nb))
        self.ok = False

    def factor(self, data) -> bool:
        """Factor the matrix with values ``data`` on the pattern; False on a zero or non-finite pivot."""
        data = np.ascontiguousarray(data, dtype=float)
        self.ok = bool(_factor(self.arrays, data))
        return self.ok

    def solve(self, b) -> np.ndarray:
        if not self.ok:
            raise RuntimeError("FixedPatternLU.solve before a successful factor")
        return _solve(self.arrays, np.ascontiguousarray(b, dtype=float))
