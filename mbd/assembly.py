"""Assembly: element families → residual forces and a sparse Newton matrix with a fixed pattern.

The integrator sees only this interface (Chrono's ChIntegrable idea):
    evaluate(t, q, v, z, jac)          -> Evaluation: F on the free DOFs (and Jacobian values on the pattern)
    newton_matrix(ev, c_M, c_C, c_K)   -> c_M·M + c_C·C + c_K·K as CSC (C = −∂F/∂v, K = −∂F/∂q)
The sparsity pattern (every element block, the frame terms, the mass diagonal) is computed once;
a Jacobian evaluation only fills ``data`` arrays through a precomputed scatter map. A System holds
no evaluation results between calls: what an evaluation computes is returned, and the caller (the
stepper, a linearization) passes it on; evaluations are counted by the simulate loop, not here.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from . import ad
from .element import evaluate
from .errors import IntegrationError, ModelError
from .model import Model

__all__ = ["System", "Evaluation"]


@dataclass(frozen=True)
class Evaluation:
    """The result of one force evaluation: ``F`` on the free DOFs and, when the Jacobian was asked
    for, ∂F/∂q and ∂F/∂v as data arrays on the System's fixed CSC pattern (else None)."""
    F: np.ndarray
    Jq: np.ndarray | None = None
    Jv: np.ndarray | None = None


def _fused_families(elements, fuse: bool):
    """[(element to evaluate, [(family name, instance slice)])]: families with equal fuse keys are
    concatenated into one (fewer Python-level kernel calls; identical results)."""
    groups: dict = {}
    for e in elements:
        key = e.fuse_key() if fuse and e.init_internal() is None else None
        groups.setdefault(key if key is not None else ("solo", id(e)), []).append(e)
    out = []
    for members in groups.values():
        e = members[0] if len(members) == 1 else type(members[0]).fuse(members)
        parts, start = [], 0
        for mem in members:
            parts.append((mem.name, slice(start, start + mem.n)))
            start += mem.n
        out.append((e, parts))
    return out


class System:
    """``freeze_internal``: hold every element internal state at its value (as the first-order form of
    :mod:`mbd.scipy_adapter` does), so an HHT run and a scipy run integrate the same equations."""

    def __init__(self, model: Model, fuse: bool = True, freeze_internal: bool = False):
        self.model = model
        self.freeze_internal = bool(freeze_internal)
        self.ndof = n = model.ndof
        m = model
        f2f = m.full_to_free
        self._evals = _fused_families(m.elements, fuse)
        rows, cols, self._blocks = [], [], []
        # element blocks: entry (i, j) of every instance, kept where both DOFs are free
        for e, _ in self._evals:
            fr = f2f[e.dofs]                                   # (n, k)
            r = np.repeat(fr[:, :, None], e.n_local, axis=2)         # (n, k, k): row = local i
            c = np.repeat(fr[:, None, :], e.n_local, axis=1)         # col = local j
            keep = ((r >= 0) & (c >= 0)).ravel()
            self._blocks.append(np.flatnonzero(keep))
            rows.append(r.ravel()[keep])
            cols.append(c.ravel()[keep])
        # frame terms: 2×2 (x, y) block of every free body when R rotates, then of every slope pair (a point of
        # mass J_d at s, docs/model.md §2.4); gravity acts on the bodies alone (the first len(_J) entries)
        self.rotating = not m.frame.is_inertial
        free_bodies = np.flatnonzero(~m.fixed)
        self._free_bodies = free_bodies
        bx, by = f2f[3 * free_bodies], f2f[3 * free_bodies + 1]
        mx = m.mass[free_bodies]
        if m.slope_pairs.size:
            sp_ = m.slope_pairs
            bx, by = np.concatenate([bx, f2f[sp_[:, 0]]]), np.concatenate([by, f2f[sp_[:, 1]]])
            mx = np.concatenate([mx, m.extra_inertia[sp_[:, 0] - m.n_body_coords]])
        if self.rotating:
            rows.append(np.concatenate([bx, bx, by, by]))
            cols.append(np.concatenate([bx, by, bx, by]))
        # mass diagonal
        diag = np.arange(n)
        rows.append(diag)
        cols.append(diag)
        allr = np.concatenate(rows) if rows else np.zeros(0, int)
        allc = np.concatenate(cols) if cols else np.zeros(0, int)
        key = allc.astype(np.int64) * n + allr  # CSC order: by column, then row
        uniq, inv = np.unique(key, return_inverse=True)
        self.nnz = uniq.size
        self._indices = (uniq % n).astype(np.int32)
        self._indptr = np.searchsorted(uniq // n, np.arange(n + 1)).astype(np.int32)
        # split the inverse map back per block
        off = 0
        self._maps = []
        for keep, r in zip(self._blocks, rows[: len(self._evals)]):
            self._maps.append((keep, inv[off: off + r.size]))
            off += r.size
        if self.rotating:
            self._frame_map = inv[off: off + 4 * bx.size]
            off += 4 * bx.size
        self._diag_map = inv[off: off + n]
        self._M = np.zeros(self.nnz)
        self._M[self._diag_map] = m.mdiag
        self._mx = mx
        self._J = m.inertia[free_bodies]
        self._bx, self._by = bx, by
        self._bt = f2f[3 * free_bodies + 2]
        # element dofs flattened, for the force scatter
        self._dofs_flat = [e.dofs.ravel() for e, _ in self._evals]
        self.has_gravity = bool(np.any(m.gravity != 0.0))

    # ------------------------------------------------------------------------------------------
    def init_internal(self) -> dict:
        z = {}
        for e in self.model.elements:
            zi = e.init_internal()
            if zi is not None:
                z[e.name] = np.asarray(zi, dtype=float)
        return z

    def evaluate(self, t: float, q: np.ndarray, v: np.ndarray, z: dict, jac: bool = False) -> Evaluation:
        """Total generalized force on the free DOFs; with ``jac`` also ∂F/∂q and ∂F/∂v on the pattern."""
        m = self.model
        fs = m.frame.at(t)
        qf, vf = m.full(t, q, v)
        Ffull = np.zeros(m.n_full)
        Jq_all = np.zeros(self.nnz) if jac else None
        Jv_all = np.zeros(self.nnz) if jac else None
        for (e, parts), flat, (keep, mp) in zip(self._evals, self._dofs_flat, self._maps):
            F, _, Jq, Jv = evaluate(e, t, fs, qf, vf, z.get(parts[0][0]) if len(parts) == 1 else None, jac)
            Ffull += np.bincount(flat, weights=F.ravel(), minlength=Ffull.size)
            if jac:
                Jq_all += np.bincount(mp, weights=Jq.ravel()[keep], minlength=self.nnz)
                Jv_all += np.bincount(mp, weights=Jv.ravel()[keep], minlength=self.nnz)
        F = Ffull[m.free]
        self._add_frame_terms(F, Jq_all, Jv_all, fs, q, v)
        return Evaluation(F, Jq_all, Jv_all)

    def forces(self, t: float, q: np.ndarray, v: np.ndarray, z: dict) -> np.ndarray:
        """F alone (shorthand for ``evaluate(...).F``)."""
        return self.evaluate(t, q, v, z).F

    def _add_frame_terms(self, F, Jq, Jv, fs, q, v):
        """Centrifugal, Coriolis, Euler and gravity terms of every free body and slope pair (docs/model.md §2.3,
        §2.4), added in place to F and, when given (not None), to the Jacobian data Jq, Jv."""
        m = self.model
        bx, by, bt, mx = self._bx, self._by, self._bt, self._mx
        if self.has_gravity:
            c, s = np.cos(fs.phi), np.sin(fs.phi)
            gx, gy = m.gravity
            nb = self._J.size           # the bodies; slope pairs (after them) feel no gravity
            F[bx[:nb]] += mx[:nb] * (c * gx + s * gy)
            F[by[:nb]] += mx[:nb] * (-s * gx + c * gy)
        if not self.rotating:
            return
        W, dW = fs.omega, fs.domega
        x, y, vx, vy = q[bx], q[by], v[bx], v[by]
        F[bx] += mx * (W * W * x + 2 * W * vy + dW * y)
        F[by] += mx * (W * W * y - 2 * W * vx - dW * x)
        F[bt] -= self._J * dW
        if Jq is not None:
            nb = bx.size
            # pattern order: (bx,bx), (bx,by), (by,bx), (by,by)
            jq = np.concatenate([mx * W * W, mx * dW, -mx * dW, mx * W * W])
            jv = np.concatenate([np.zeros(nb), 2 * W * mx, -2 * W * mx, np.zeros(nb)])
            Jq += np.bincount(self._frame_map, weights=jq, minlength=self.nnz)
            Jv += np.bincount(self._frame_map, weights=jv, minlength=self.nnz)

    def _csc(self, data) -> sp.csc_matrix:
        return sp.csc_matrix((data, self._indices, self._indptr), shape=(self.ndof, self.ndof))

    @staticmethod
    def _jacobian(ev: Evaluation):
        if ev.Jq is None or ev.Jv is None:
            raise ModelError("this needs an evaluation with the Jacobian: System.evaluate(..., jac=True)")
        return ev.Jq, ev.Jv

    def newton_matrix(self, ev: Evaluation, c_M: float, c_C: float, c_K: float) -> sp.csc_matrix:
        """c_M·M + c_C·C + c_K·K with C = −J_v, K = −J_q from the Jacobian evaluation ``ev``."""
        Jq, Jv = self._jacobian(ev)
        return self._csc(c_M * self._M - c_C * Jv - c_K * Jq)

    def matrices(self, ev: Evaluation):
        """(M, C, K) as CSC from the Jacobian evaluation ``ev`` (for linearization)."""
        Jq, Jv = self._jacobian(ev)
        return self._csc(self._M.copy()), self._csc(-Jv), self._csc(-Jq)

    # ------------------------------------------------------------------------------------------
    def family_forces(self, t, q, v, z) -> dict[str, float]:
        """Largest generalized-force magnitude of each element family (for diagnostics)."""
        m = self.model
        fs = m.frame.at(t)
        qf, vf = m.full(t, q, v)
        out = {}
        for e in m.elements:
            with np.errstate(all="ignore"):
                F, _, _, _ = evaluate(e, t, fs, qf, vf, z.get(e.name), False)
            out[e.name] = float(np.nanmax(np.abs(F))) if F.size and np.isfinite(F).all() else float("nan") if F.size else 0.0
        return out

    def outputs(self, t, q, v, z, families=None) -> dict[str, dict[str, np.ndarray]]:
        """Every family's outputs at a state (only those named in ``families``, when given)."""
        m = self.model
        fs = m.frame.at(t)
        qf, vf = m.full(t, q, v)
        res = {}
        for e, parts in self._evals:
            if families is not None and not any(name in families for name, _ in parts):
                continue
            F, out, _, _ = evaluate(e, t, fs, qf, vf, z.get(parts[0][0]) if len(parts) == 1 else None, False)
            for name, sl in parts:
                res[name] = out if len(parts) == 1 else {k: np.asarray(v)[sl] for k, v in out.items()}
        return res

    def outputs_batch(self, t, q, v, z, families=None, full=None) -> dict[str, dict[str, np.ndarray]]:
        """:meth:`outputs` at K states at once: ``t`` (K,), ``q``, ``v`` (K, n_free), ``z`` {family: (K, ...)}
        give arrays (K, n). A family whose kernel is elementwise over its instances (``Element.batched``:
        parameters (n,), internal states read as ``z[..., j]``) takes (K, n) columns and evaluates the K
        states in one call; the others (drives with a time profile) are evaluated state by state. ``full``:
        ``model.full_batch(t, q, v)`` when the caller has it already (it costs ≈ 2 µs a state on the DPGT)."""
        m = self.model
        t = np.asarray(t, float)
        K = t.size
        qf, vf = m.full_batch(t, q, v) if full is None else full
        fs = m.frame_batch(t)
        res = {}
        for e, parts in self._evals:
            if families is not None and not any(name in families for name, _ in parts):
                continue
            zi = z.get(parts[0][0]) if len(parts) == 1 else None
            if e.batched:
                ql, vl = qf[:, e.dofs], vf[:, e.dofs]            # (K, n, k)
                _, out = e.kernel(t[:, None], fs, list(np.moveaxis(ql, 2, 0)), list(np.moveaxis(vl, 2, 0)), zi)
                out = {key: np.broadcast_to(np.asarray(ad.value(val), float), (K, e.n)) for key, val in out.items()}
            else:
                rows = [evaluate(e, t[k], m.frame.at(t[k]), qf[k], vf[k], None if zi is None else zi[k], False)[1]
                        for k in range(K)]
                out = {key: np.stack([np.broadcast_to(np.asarray(r[key], float), (e.n,)) for r in rows])
                       for key in rows[0]}
            for name, sl in parts:
                res[name] = out if len(parts) == 1 else {k: val[:, sl] for k, val in out.items()}
        return res

    def check_finite(self, t, F, q, v, z):
        if not np.all(np.isfinite(F)):
            fam = self.family_forces(t, q, v, z)
            bad = [k for k, x in fam.items() if not np.isfinite(x)]
            raise IntegrationError(f"non-finite forces at t = {t:.6e} s from element families {bad or 'frame/gravity'}")
