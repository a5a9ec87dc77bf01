"""The compiled assembly: every element family, the rotating-frame and gravity terms, the scatter into
the fixed sparse pattern — one compiled call, the same quantities as :meth:`mbd.System.evaluate`.

:class:`CompiledSystem` is built from a :class:`mbd.System` (its fused families, pattern and maps):
each family is packed once (:mod:`mbd.compiled` convention) into a record of a numba typed list; the
compiled :func:`assemble` loops over the records and dispatches on the family's kind id to its kernel.
"""
from __future__ import annotations

import numpy as np
from numba import literally, njit
from numba.typed import List

from ..assembly import Evaluation, System
from .registry import entry, evaluate_for, fingerprint, groups_of, groups_to_compile, kind_of, update_for
from .. import compiled as _compiled     # cached_groups is read through the package when called

__all__ = ["CompiledSystem", "assemble"]


@njit(cache=True)
def _full(t, q, v, free, fixed_idx, fixed_q_I, omega, n_full):
    """Full coordinates in R: free DOFs from (q, v), fixed bodies at rest in the fixed frame I."""
    qf = np.zeros(n_full)
    vf = np.zeros(n_full)
    phi = omega * t
    c, s = np.cos(phi), np.sin(phi)
    for b in range(fixed_idx.size):          # to_reference with zero velocity in I
        i = fixed_idx[b]
        x, y = fixed_q_I[b, 0], fixed_q_I[b, 1]
        xr, yr = c * x + s * y, -s * x + c * y
        qf[i], qf[i + 1], qf[i + 2] = xr, yr, fixed_q_I[b, 2] - phi
        vf[i], vf[i + 1], vf[i + 2] = omega * yr, -omega * xr, -omega
    for j in range(free.size):
        qf[free[j]] = q[j]
        vf[free[j]] = v[j]
    return qf, vf


@njit(cache=True)
def _list_of(item):
    """A typed list holding ``item``. Built here (cached on disk) rather than by numba.typed.List from Python,
    whose methods compile afresh in every process (≈ 1 s per worker)."""
    out = List()
    out.append(item)
    return out


@njit(cache=True)
def _push(items, item):
    items.append(item)


@njit(cache=True)
def assemble(groups, t, q, v, fams, zs, jac, sysd, F, Jq, Jv):
    """Generalized forces F on the free DOFs and, with ``jac``, J_q, J_v on the pattern (in place). ``groups``: the
    family groups of ``fams`` (:func:`.registry.groups_of`), compiled as a literal (one specialisation per set)."""
    literally(groups)
    (free, fixed_idx, fixed_q_I, omega, gx, gy, mx, Jb, bx, by, bt, frame_map, n_full) = sysd
    qf, vf = _full(t, q, v, free, fixed_idx, fixed_q_I, omega, n_full)
    phi = omega * t
    Ffull = np.zeros(n_full)
    if jac:
        Jq[:] = 0.0
        Jv[:] = 0.0
    for rec in fams:
        kind, dofs, P, G, zi, keep, mp, ql, vl, Fl, Jql, Jvl = rec
        n, k = dofs.shape
        for i in range(n):
            for j in range(k):
                ql[i, j] = qf[dofs[i, j]]
                vl[i, j] = vf[dofs[i, j]]
        evaluate_for(groups, kind, t, phi, omega, 0.0, ql, vl, zs[zi], P, G, Fl, Jql, Jvl, jac)
        for i in range(n):
            for j in range(k):
                Ffull[dofs[i, j]] += Fl[i, j]
        if jac:
            flat_q = Jql.reshape(-1)
            flat_v = Jvl.reshape(-1)
            for e in range(keep.size):
                Jq[mp[e]] += flat_q[keep[e]]
                Jv[mp[e]] += flat_v[keep[e]]
    for j in range(free.size):
        F[j] = Ffull[free[j]]
    c, s = np.cos(phi), np.sin(phi)
    W2 = omega * omega
    nb = bx.size
    for b in range(nb):                       # gravity (given in I) on the bodies (the first Jb.size entries; slope
        x, y, vx, vy = q[bx[b]], q[by[b]], v[bx[b]], v[by[b]]     # pairs follow), then the frame's inertial forces,
        if b < Jb.size:                                            # added in the numpy path's order
            F[bx[b]] += mx[b] * (c * gx + s * gy)
            F[by[b]] += mx[b] * (-s * gx + c * gy)
        F[bx[b]] += mx[b] * (W2 * x + 2 * omega * vy)
        F[by[b]] += mx[b] * (W2 * y - 2 * omega * vx)
    if jac and frame_map.size:                # pattern order: (bx,bx), (bx,by), (by,bx), (by,by)
        for b in range(nb):
            Jq[frame_map[b]] += mx[b] * W2
            Jq[frame_map[3 * nb + b]] += mx[b] * W2
            Jv[frame_map[nb + b]] += 2 * omega * mx[b]
            Jv[frame_map[2 * nb + b]] -= 2 * omega * mx[b]


@njit(cache=True)
def update_internal(groups, t0, t1, q0, v0, q1, v1, fams, zs, sysd):
    """Every stateful family's internal state after an accepted step (in place in zs)."""
    literally(groups)
    (free, fixed_idx, fixed_q_I, omega, gx, gy, mx, Jb, bx, by, bt, frame_map, n_full) = sysd
    q0f, v0f = _full(t0, q0, v0, free, fixed_idx, fixed_q_I, omega, n_full)
    q1f, v1f = _full(t1, q1, v1, free, fixed_idx, fixed_q_I, omega, n_full)
    for rec in fams:
        kind, dofs, P, G, zi, keep, mp, ql, vl, Fl, Jql, Jvl = rec
        if zs[zi].shape[1] == 0:
            continue
        n, k = dofs.shape
        ql0, vl0 = np.empty((n, k)), np.empty((n, k))
        for i in range(n):
            for j in range(k):
                ql0[i, j], vl0[i, j] = q0f[dofs[i, j]], v0f[dofs[i, j]]
                ql[i, j], vl[i, j] = q1f[dofs[i, j]], v1f[dofs[i, j]]
        z1 = update_for(groups, kind, zs[zi], t0, t1, omega * t0, omega * t1, ql0, vl0, ql, vl, P, G)
        z = zs[zi]
        for i in range(n):                    # element-wise: a slice assignment from an array compiles numba's
            for j in range(z.shape[1]):       # shape-mismatch message (seconds of the first compile)
                z[i, j] = z1[i, j]


class CompiledSystem:
    """The compiled twin of a :class:`mbd.System` (same fused families, pattern and maps).

    Raises NotImplementedError (naming the family or the frame) for what the compiled path cannot do:
    a frame with a Python speed profile, or a family without a compiled twin (see :mod:`.registry`)."""

    def __init__(self, system: System):
        m = system.model
        if m.frame.profile is not None:
            raise NotImplementedError("compiled path: the reference frame has a Python speed profile")
        self.system, self.model, self.ndof, self.nnz = system, m, system.ndof, system.nnz
        self.state_names: list[str] = []
        self.state_shapes: list[tuple] = []
        fams, zs, kinds = [], _list_of(np.zeros((0, 0))), []      # zs slot 0: families without internal state
        for (e, parts), (keep, mp) in zip(system._evals, system._maps):
            kind = kind_of(type(e))
            if kind is None:
                raise NotImplementedError(f"compiled path: no compiled kernel for family {e.name!r} "
                                          f"({type(e).__name__} declares no compiled_twin)")
            P, G = kind.pack(e)
            kinds.append(kind)
            zi = 0
            z0 = e.init_internal()
            if z0 is not None:                     # kept (n, n_z) here, the element's own shape in a State
                zi = len(zs)
                _push(zs, np.ascontiguousarray(np.reshape(z0, (e.n, -1)), dtype=float))
                self.state_names.append(parts[0][0])
                self.state_shapes.append(np.shape(z0))
            n, k = e.dofs.shape
            fams.append((kind.id, np.ascontiguousarray(e.dofs, dtype=np.int64), P, G, zi,
                         keep.astype(np.int64), np.asarray(mp, np.int64), np.zeros((n, k)), np.zeros((n, k)),
                         np.zeros((n, k)), np.zeros((n, k, k)), np.zeros((n, k, k))))
        if not fams:      # numba cannot type an empty list of families: nothing to compile for
            raise NotImplementedError("compiled path: the model has no element families")
        self.fams, self.zs = _list_of(fams[0]), zs
        # the kernel groups (registry.GROUPS) this system compiles: its own, or a cached set containing them
        self.groups = groups_to_compile(groups_of(kinds), _compiled.cached_groups("stepper.advance"))
        for rec in fams[1:]:
            _push(self.fams, rec)
        fixed = np.flatnonzero(m.fixed)
        frame_map = system._frame_map if system.rotating else np.zeros(0, np.int64)
        self.sysd = (m.free.astype(np.int64), (3 * fixed).astype(np.int64), np.ascontiguousarray(m.pose0[fixed], float),
                     float(m.frame.omega), float(m.gravity[0]), float(m.gravity[1]),
                     np.asarray(system._mx, float), np.asarray(system._J, float), system._bx.astype(np.int64),
                     system._by.astype(np.int64), system._bt.astype(np.int64), np.asarray(frame_map, np.int64),
                     m.n_full)
        self._assemble: dict = {}     # the compiled assembly per fingerprint of q and v (:meth:`evaluate`)

    def set_internal(self, z: dict) -> None:
        """Load the element internal states of a :class:`mbd.State` into the compiled slots."""
        for i, name in enumerate(self.state_names, start=1):
            self.zs[i][:, :] = np.reshape(z[name], self.zs[i].shape)

    def internal(self) -> dict:
        return {name: self.zs[i].reshape(shape).copy()
                for i, (name, shape) in enumerate(zip(self.state_names, self.state_shapes), start=1)}

    def evaluate(self, t, q, v, z: dict | None = None, jac: bool = False) -> Evaluation:
        """As :meth:`mbd.System.evaluate` (z: the internal states; None keeps the loaded ones)."""
        if z is not None:
            self.set_internal(z)
        F = np.empty(self.ndof)
        Jq, Jv = (np.empty(self.nnz), np.empty(self.nnz)) if jac else (np.empty(0), np.empty(0))
        q, v = np.ascontiguousarray(q, float), np.ascontiguousarray(v, float)
        args = (float(t), q, v, self.fams, self.zs, bool(jac), self.sysd, F, Jq, Jv)
        # the compiled entry per q, v fingerprint, the system's own arguments keeping their types: fingerprinting the
        # family tuples at every call cost ≈ 20 µs, half of an evaluation (a static solve makes thousands)
        key = (fingerprint(q), fingerprint(v))
        run = self._assemble.get(key)
        if run is None:
            run = self._assemble[key] = entry(assemble, self.groups, *args)
        run(self.groups, *args)
        return Evaluation(F, Jq if jac else None, Jv if jac else None)
