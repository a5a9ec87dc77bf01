"""Sparse LU of matrices that share one sparsity pattern (the Newton matrix of a model).

Symbolic analysis once: SuperLU (scipy) chooses the fill-reducing symmetric order (minimum degree on
AᵀA + A, as the numpy path asks it) and gives the patterns of L and U from a random matrix on the
pattern (no cancellation). Numeric refactorisation, compiled: left-looking column LU on that fixed
pattern with diagonal pivots — the numpy path's choice (``diag_pivot_thresh = 0``): the Newton matrix
M + (1+α)(γhC + βh²K) is dominated by its diagonal mass, and the LU only drives Newton (the residual is
exact). A zero or non-finite pivot reports failure; the caller then falls back to partial pivoting.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit

__all__ = ["FixedPatternLU"]


@njit(cache=True)
def _factor(n, indptr, indices, data, iperm, perm, Lp, Li, Lx, Up, Ui, Ux, x):
    """Left-looking LU of B = A[perm][:, perm] on the fixed patterns (Lp, Li), (Up, Ui) (CSC, rows
    ascending, L without its unit diagonal, U with the diagonal last). Returns False on a zero pivot."""
    for k in range(n):
        c = perm[k]
        for p in range(indptr[c], indptr[c + 1]):       # scatter column k of B
            x[iperm[indices[p]]] = data[p]
        for p in range(Up[k], Up[k + 1] - 1):            # U(j, k), j < k ascending: x[j] is final
            j = Ui[p]
            ujk = x[j]
            for q in range(Lp[j], Lp[j + 1]):
                x[Li[q]] -= Lx[q] * ujk
        for p in range(Up[k], Up[k + 1]):
            Ux[p] = x[Ui[p]]
            x[Ui[p]] = 0.0
        piv = Ux[Up[k + 1] - 1]
        if piv == 0.0 or not np.isfinite(piv):
            for q in range(Lp[k], Lp[k + 1]):
                x[Li[q]] = 0.0
            return False
        inv = 1.0 / piv
        for q in range(Lp[k], Lp[k + 1]):
            Lx[q] = x[Li[q]] * inv
            x[Li[q]] = 0.0
    return True


@njit(cache=True)
def _solve(n, perm, Lp, Li, Lx, Up, Ui, Ux, b, y):
    """x with A x = b from the factors of B = A[perm][:, perm] (y: work array)."""
    for i in range(n):
        y[i] = b[perm[i]]
    for j in range(n):                                   # L y = c (unit diagonal), column-oriented
        yj = y[j]
        for q in range(Lp[j], Lp[j + 1]):
            y[Li[q]] -= Lx[q] * yj
    for j in range(n - 1, -1, -1):                      # U y = y, column-oriented, diagonal last
        d = Up[j + 1] - 1
        y[j] /= Ux[d]
        yj = y[j]
        for p in range(Up[j], d):
            y[Ui[p]] -= Ux[p] * yj
    x = np.empty(n)
    for i in range(n):
        x[perm[i]] = y[i]
    return x


class FixedPatternLU:
    """LU of n×n CSC matrices with the pattern (indptr, indices); ``factor(data)`` then ``solve(b)``."""

    def __init__(self, indptr, indices, n: int):
        self.n = int(n)
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
        # SuperLU: A[perm_r⁻¹...]: row i of A goes to row perm_r[i] of L U; our perm maps back
        self.iperm = np.ascontiguousarray(lu.perm_c, dtype=np.int64)
        self.perm = np.argsort(self.iperm).astype(np.int64)
        L = sp.csc_matrix(lu.L)
        L.sort_indices()
        U = sp.csc_matrix(lu.U)
        U.sort_indices()
        strict = sp.tril(L, k=-1, format="csc")
        strict.sort_indices()
        self.Lp, self.Li = strict.indptr.astype(np.int64), strict.indices.astype(np.int64)
        self.Up, self.Ui = U.indptr.astype(np.int64), U.indices.astype(np.int64)
        if not np.all(self.Ui[self.Up[1:] - 1] == np.arange(n)):
            raise RuntimeError("FixedPatternLU: U has a structurally zero diagonal")
        self.Lx = np.zeros(self.Li.size)
        self.Ux = np.zeros(self.Ui.size)
        self._x = np.zeros(n)
        self._y = np.zeros(n)
        self.ok = False

    @property
    def fill(self) -> int:
        """Entries of L and U (L's unit diagonal not counted)."""
        return self.Li.size + self.Ui.size

    def factor(self, data) -> bool:
        """Factor the matrix with values ``data`` on the pattern; False on a zero or non-finite pivot."""
        data = np.ascontiguousarray(data, dtype=float)
        self.ok = bool(_factor(self.n, self.indptr, self.indices, data, self.iperm, self.perm, self.Lp,
                               self.Li, self.Lx, self.Up, self.Ui, self.Ux, self._x))
        return self.ok

    def solve(self, b) -> np.ndarray:
        if not self.ok:
            raise RuntimeError("FixedPatternLU.solve before a successful factor")
        return _solve(self.n, self.perm, self.Lp, self.Li, self.Lx, self.Up, self.Ui, self.Ux,
                      np.ascontiguousarray(b, dtype=float), self._y)
