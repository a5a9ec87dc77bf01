"""The compiled assembly: every element family, the rotating-frame and gravity terms, the scatter into
the fixed sparse pattern — one compiled call, the same quantities as :meth:`mbd.System.evaluate`.

:class:`CompiledSystem` is built from a :class:`mbd.System` (its fused families, pattern and maps):
each family is packed once (:mod:`mbd.compiled` convention) into a record of a numba typed list; the
compiled :func:`assemble` loops over the records and dispatches on the family's kind id to its kernel.

Threads (``threads`` > 1, opt-in): the families of :data:`.registry.THREADED_KINDS` (every bearing's contacts) are
cut into ``threads`` fixed chunks of instances and evaluated at once on the threads (:func:`_threaded`, the engine's
one parallel function, called through :func:`threads_run`), for every Jacobian and, on the sliced machine, for every
residual (:func:`_partition`); the other families, and then the scatter of every family into the forces and the
pattern in the family order, stay in the calling thread. A kernel's instances are independent of each other, so
every force, Jacobian entry and step is bit-identical to the serial assembly's, whatever the thread count
(docs/numerics.md §5 "Threads"). A set of families without the :data:`.registry.THREADED` flag (one thread, the
default) compiles no parallel code.
"""
from __future__ import annotations

import contextlib
import os

import numba
import numpy as np
from numba import literally, njit, prange
from numba.core import types as nbtypes
from numba.core.errors import TypingError
from numba.extending import overload
from numba.typed import List

from ..assembly import Evaluation, System
from ..errors import ModelError
from .registry import (KIND_IDS, THREADED, THREADED_KINDS, entry, evaluate_for, evaluate_threaded_for, fingerprint,
                       groups_of, groups_to_compile, kind_of, update_for)
from .. import compiled as _compiled     # cached_groups is read through the package when called

__all__ = ["CompiledSystem", "assemble", "usable_cores", "check_threads"]


def usable_cores() -> int:
    """The cores this process may run threads on (its CPU affinity, at most numba's thread pool)."""
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:          # no affinity on this platform
        cores = os.cpu_count() or 1
    return max(1, min(cores, numba.config.NUMBA_NUM_THREADS))


def check_threads(threads) -> int:
    """``threads`` as an int, or a one-line ModelError: an integer from 1 to the usable cores."""
    cores = usable_cores()
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or not 1 <= threads <= cores:
        raise ModelError(f"threads must be an integer from 1 to the {cores} usable cores of this machine, "
                         f"got {threads!r}")
    return int(threads)


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


@njit(cache=True, parallel=True)
def _threaded(groups, t, phi, omega, qf, vf, fams, zs, jac, par):
    """The threads' work, one chunk each (``prange``: chunk c on thread c): each family of ``par``
    (:data:`.registry.THREADED_KINDS`) gathered and evaluated over its c-th range of instances. A kernel's instances
    are independent of each other: the rows are those of one call over all. The engine's one parallel function."""
    literally(groups)
    fam_ids, bounds, mask, residual = par
    for c in prange(bounds.shape[1] - 1):
        for h in range(fam_ids.size):
            kind, dofs, P, G, zi, keep, mp, ql, vl, Fl, Jql, Jvl = fams[fam_ids[h]]
            lo, hi = bounds[h, c], bounds[h, c + 1]
            k = dofs.shape[1]
            for i in range(lo, hi):
                for j in range(k):
                    ql[i, j] = qf[dofs[i, j]]
                    vl[i, j] = vf[dofs[i, j]]
            evaluate_threaded_for(groups, kind, t, phi, omega, 0.0, ql[lo:hi], vl[lo:hi], zs[zi][lo:hi], P[lo:hi], G,
                                  Fl[lo:hi], Jql[lo:hi], Jvl[lo:hi], jac)


def threads_run(groups, t, phi, omega, qf, vf, fams, zs, jac, par):
    raise NotImplementedError("compiled code only")


@overload(threads_run, prefer_literal=True)
def _threads_run(groups, t, phi, omega, qf, vf, fams, zs, jac, par):
    """For a set with the :data:`.registry.THREADED` flag: the families of the partition ``par`` (:func:`_partition`)
    evaluated on the threads (:func:`_threaded`) for a Jacobian, and for a residual when the partition says it pays;
    returns whether they were. For a serial set a function returning False: no parallel code and, once LLVM has
    inlined it, no test in the assembly's loop. A called function, not an inlined overload: numba compiles an inlined
    overload's implementation on its own first and then types it again where it is inlined (with its callees: the
    dispatch and every family kernel once more, ≈ 3 s of the first compile)."""
    if not isinstance(groups, nbtypes.IntegerLiteral):
        raise TypingError("threads_run: groups must be a literal int (numba.literally at the entry point)")
    if groups.literal_value & THREADED:
        def run(groups, t, phi, omega, qf, vf, fams, zs, jac, par):
            threaded = jac or par[3][0] != 0
            if threaded:
                _threaded(groups, t, phi, omega, qf, vf, fams, zs, jac, par)
            return threaded
    else:
        def run(groups, t, phi, omega, qf, vf, fams, zs, jac, par):
            return False
    return run


@njit(cache=True)
def assemble(groups, t, q, v, fams, zs, jac, sysd, F, Jq, Jv):
    """Generalized forces F on the free DOFs and, with ``jac``, J_q, J_v on the pattern (in place). ``groups``: the
    family groups of ``fams`` (:func:`.registry.groups_of`), compiled as a literal (one specialisation per set)."""
    literally(groups)
    (free, fixed_idx, fixed_q_I, omega, gx, gy, mx, Jb, bx, by, bt, frame_map, n_full, par) = sysd
    qf, vf = _full(t, q, v, free, fixed_idx, fixed_q_I, omega, n_full)
    phi = omega * t
    Ffull = np.zeros(n_full)
    if jac:
        Jq[:] = 0.0
        Jv[:] = 0.0
    threaded = threads_run(groups, t, phi, omega, qf, vf, fams, zs, jac, par)
    r = 0
    for rec in fams:                          # each family gathered, evaluated (unless on the threads above) and
        kind, dofs, P, G, zi, keep, mp, ql, vl, Fl, Jql, Jvl = rec      # scattered, in the family order
        n, k = dofs.shape
        if not (threaded and par[2][r]):
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
        r += 1
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
    (free, fixed_idx, fixed_q_I, omega, gx, gy, mx, Jb, bx, by, bt, frame_map, n_full, _) = sysd
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


class _Threads:
    def __init__(self, n):
        self.n = n

    def __enter__(self):
        self.before = numba.get_num_threads()
        numba.set_num_threads(self.n)

    def __exit__(self, *exc):
        numba.set_num_threads(self.before)


_NO_THREADS = contextlib.nullcontext()


def _partition(system: System, kinds, threads: int) -> tuple:
    """The fixed work of each thread (:func:`_threaded`): the records of the families of
    :data:`.registry.THREADED_KINDS` (fam_ids), their instances cut into ``threads`` contiguous ranges of nearly equal
    size (bounds (n_fam, threads + 1)), which records those are (mask, per record), and whether a residual-only
    assembly runs them on the threads too (residual, (1,)): when they hold the sliced contacts. A planar machine's
    threaded families cost ≈ 11 µs a residual, about what a parallel region's start and join cost on top of it,
    the sliced machine's ≈ 46 µs (docs/numerics.md §5 "Threads"). Empty for one thread."""
    if threads == 1:
        return (np.zeros(0, np.int64), np.zeros((0, 1), np.int64), np.zeros(0, np.int64), np.zeros(1, np.int64))
    ids = {KIND_IDS[t] for t in THREADED_KINDS}
    fam_ids = [r for r, kind in enumerate(kinds) if kind.id in ids]
    bounds = np.array([np.linspace(0, system._evals[r][0].n, threads + 1).round() for r in fam_ids],
                      np.int64).reshape(len(fam_ids), threads + 1)
    mask = np.zeros(len(kinds), np.int64)
    mask[fam_ids] = 1
    residual = np.array([any(kinds[r].id == KIND_IDS["sliced.sliced_race"] for r in fam_ids)], np.int64)
    return np.asarray(fam_ids, np.int64), bounds, mask, residual


class CompiledSystem:
    """The compiled twin of a :class:`mbd.System` (same fused families, pattern and maps).

    Raises NotImplementedError (naming the family or the frame) for what the compiled path cannot do:
    a frame with a Python speed profile, or a family without a compiled twin (see :mod:`.registry`)."""

    def __init__(self, system: System, threads: int = 1):
        self.threads = check_threads(threads)
        if self.threads > 1:      # before numba starts its OpenMP pool: waiting threads sleep, not spin (a user's own
            os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")     # setting stays); docs/numerics.md §5 "Threads"
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
        needed = groups_of(kinds) | (THREADED if self.threads > 1 else 0)
        self.groups = groups_to_compile(needed, _compiled.cached_groups("stepper.advance"))
        for rec in fams[1:]:
            _push(self.fams, rec)
        fixed = np.flatnonzero(m.fixed)
        frame_map = system._frame_map if system.rotating else np.zeros(0, np.int64)
        self.sysd = (m.free.astype(np.int64), (3 * fixed).astype(np.int64), np.ascontiguousarray(m.pose0[fixed], float),
                     float(m.frame.omega), float(m.gravity[0]), float(m.gravity[1]),
                     np.asarray(system._mx, float), np.asarray(system._J, float), system._bx.astype(np.int64),
                     system._by.astype(np.int64), system._bt.astype(np.int64), np.asarray(frame_map, np.int64),
                     m.n_full, _partition(system, kinds, self.threads))
        self._assemble: dict = {}     # the compiled assembly per fingerprint of q and v (:meth:`evaluate`)

    def threads_set(self):
        """A context in which numba's parallel code runs on :attr:`threads` threads (the calling thread's setting,
        restored after); a serial system's (no parallel code) changes nothing."""
        return _Threads(self.threads) if self.groups & THREADED else _NO_THREADS

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
        if not self.groups & THREADED:
            run(self.groups, *args)
        else:
            with self.threads_set():
                run(self.groups, *args)
        return Evaluation(F, Jq if jac else None, Jv if jac else None)
