"""The statistics' accumulators, compiled: one loop over a run's accepted steps that turns the per-step
quantities (:meth:`components.outputs.WindowStatistics.snapshot`) into time-weighted sums, maxima, minima,
window ends and pocket-impact counts. :class:`~components.outputs.WindowStatistics` owns what they mean (its
docstring); this module owns only the arithmetic, so that a block of a few hundred steps costs one call.

Per step [t_a, t_b] of size h, a quantity x is taken linear in the step (the trapezoid rule) between the
step fractions w_a (the window's start inside the step, else 0) and w_1 (its window's end inside the step,
else 1): Σx += ½(x(w_a) + x(w_1))·dt, Σx² += ½(x(w_a)² + x(w_1)²)·dt, dt = (w_1 − w_a)·h; max and min of
its two ends over steps with dt > 0. A mesh quantity's window ends at t1; a bearing's when its cage has
turned its whole number of revolutions relative to the carrier (its angle integrated by the same rule).

Without numba the same functions run as plain Python (slowly, but the results are the same).
"""
from __future__ import annotations

import math
import sys
import time

import numpy as np

from mbd.compile_time import compiling

try:
    from numba import njit as _njit
    jit = _njit(cache=True)
except ImportError:      # pragma: no cover - numba is a dependency; this keeps the module importable
    def jit(fn):
        return fn

__all__ = ["accumulate_steps", "warm_accumulators", "IMPACT_ROWS"]

# rows of the impact accumulator (one column per pocket contact)
IMPACT_ROWS = ("count", "touches", "speed_sum", "speed_max", "peak_sum", "peak_max", "peak_now", "active")


@jit
def _max(a, b):
    """max with NaN winning (as numpy's maximum)."""
    if a != a or b != b:
        return np.nan
    return a if a >= b else b


@jit
def _min(a, b):
    if a != a or b != b:
        return np.nan
    return a if a <= b else b


@jit
def _bearing_ends(i, wa, t_a, h, V, cage_cols, has_target, target, t1, angle, is_open, t_close, end):
    """Fraction of step i at which each bearing's window ends, into ``end`` (1: still open after it; wa:
    closed before it); the cage angles, open flags and closing times are updated."""
    nb = end.size
    if not has_target:             # the nominal window for every bearing
        w = min(1.0, (t1 - t_a) / h)
        for b in range(nb):
            end[b] = max(w, wa) if is_open[b] else wa
        if cage_cols.size:         # still count the cage's revolutions (impacts per revolution)
            for b in range(nb):
                w0, w1 = V[i, cage_cols[b]], V[i + 1, cage_cols[b]]
                ws_a = w0 + wa * (w1 - w0)
                ws_b = w0 + end[b] * (w1 - w0)
                angle[b] = angle[b] + 0.5 * (ws_a + ws_b) * (end[b] - wa) * h
        if w < 1.0:
            for b in range(nb):
                is_open[b] = False
        return
    for b in range(nb):
        w0, w1 = V[i, cage_cols[b]], V[i + 1, cage_cols[b]]
        ws_a = w0 + wa * (w1 - w0)
        new = angle[b] + 0.5 * (ws_a + w1) * (1.0 - wa) * h
        phi_a, phi_b = abs(angle[b]), abs(new)
        goal = 2.0 * math.pi * target[b]
        closing = is_open[b] and phi_b >= goal
        frac = 1.0
        if closing:
            frac = (goal - phi_a) / (phi_b - phi_a if phi_b > phi_a else 1.0)
        if is_open[b]:
            end[b] = wa + min(max(frac, 0.0), 1.0) * (1.0 - wa)
            angle[b] = math.copysign(goal, new) if closing else new
        else:
            end[b] = wa
        if closing:
            t_close[b] = t_a + end[b] * h
            is_open[b] = False


@jit
def _impacts(i, t_b, t0, t_a, h, wb, V, Z, pocket_cols, pocket_bearing, v_floor, imp):
    """Pocket impacts of step i: onsets (the pocket's stored approach speed turning > 0) faster than the
    element's speed floor, their speed and peak force (up to each bearing's window end); slower onsets are
    touches. ``imp``: rows :data:`IMPACT_ROWS`."""
    for k in range(pocket_cols.size):
        b = pocket_bearing[k]
        z0, z1 = Z[i, k], Z[i + 1, k]
        in_window = t_b > t0 and t_b <= t_a + wb[b] * h
        contact = z0 <= 0.0 and z1 > 0.0 and in_window
        touch = contact and z1 <= v_floor[k]
        onset = contact and not touch
        if touch:
            imp[1, k] += 1.0
        ended = imp[7, k] > 0.0 and (z1 <= 0.0 or not in_window)
        f0, f1 = V[i, pocket_cols[k]], V[i + 1, pocket_cols[k]]
        force = abs(f0 + wb[b] * (f1 - f0))
        if imp[7, k] > 0.0:
            imp[6, k] = _max(imp[6, k], force)
        if ended:
            imp[4, k] += imp[6, k]
            imp[5, k] = _max(imp[5, k], imp[6, k])
            imp[7, k] = 0.0
            imp[6, k] = 0.0
        if onset:
            imp[0, k] += 1.0
            imp[2, k] += z1
            imp[3, k] = _max(imp[3, k], z1)
            imp[7, k] = 1.0
            imp[6, k] = force


@jit
def accumulate_steps(t, V, own, acc, T, angle, is_open, t_close, target, has_target, t0, t1, cage_cols,
                     pocket_cols, pocket_bearing, Z, v_floor, imp):
    """Accumulate the steps between consecutive rows of ``t`` (K+1,) / ``V`` (K+1, n_q) (every quantity,
    flattened) into ``acc`` (4, n_q): Σx dt, Σx² dt, max, min; ``own`` (n_q,): each column's bearing or −1
    (the mesh window [t0, t1]); ``T`` (n_b + 1,): time covered by each bearing's window, then the global
    one; ``angle``, ``is_open``, ``t_close``, ``target`` (n_b,): the cages' angles, open windows, closing
    times and whole revolutions (``has_target`` false: the nominal window); ``cage_cols`` (n_b,): the
    columns of the cage speed relative to the carrier (empty without cages); ``pocket_cols``,
    ``pocket_bearing``, ``v_floor`` (n_p,), ``Z`` (K+1, n_p): the pocket forces' columns, their bearings,
    speed floors and stored approach speeds; ``imp`` (8, n_p) the impact rows. All updated in place."""
    K = t.size - 1
    nb = angle.size
    nq = own.size
    wb = np.empty(nb)
    for i in range(K):
        t_a, t_b = t[i], t[i + 1]
        any_open = False
        for b in range(nb):
            any_open = any_open or is_open[b]
        if t_b <= t0 or (t_a >= t1 and not any_open):
            continue
        h = t_b - t_a
        wa = (max(t_a, t0) - t_a) / h
        wg = (min(t_b, t1) - t_a) / h
        _bearing_ends(i, wa, t_a, h, V, cage_cols, has_target, target, t1, angle, is_open, t_close, wb)
        for j in range(nq):
            w1 = wb[own[j]] if own[j] >= 0 else wg
            x0, x1 = V[i, j], V[i + 1, j]
            va, vb = x0 + wa * (x1 - x0), x0 + w1 * (x1 - x0)
            dt = max(w1 - wa, 0.0) * h
            acc[0, j] += 0.5 * (va + vb) * dt
            acc[1, j] += 0.5 * (va * va + vb * vb) * dt
            if dt > 0.0:
                acc[2, j] = _max(acc[2, j], _max(va, vb))
                acc[3, j] = _min(acc[3, j], _min(va, vb))
        for b in range(nb):
            T[b] += max(wb[b] - wa, 0.0) * h
        T[nb] += max(wg - wa, 0.0) * h
        if pocket_cols.size:
            _impacts(i, t_b, t0, t_a, h, wb, V, Z, pocket_cols, pocket_bearing, v_floor, imp)


def warm_accumulators() -> None:
    """Compile (or load) the accumulators now, on a one-step toy window with the argument types of the statistics'
    calls, timed as compile time (:mod:`mbd.compile_time`): the statistics call it when they are bound, so a run
    that must compile them does so before its first step (not inside its progress bar and wall time) and says so."""
    i0, f0 = np.zeros(0, np.int64), np.zeros(0)
    # numba's count of compiles (cache misses) in this process; none without numba (plain Python: nothing compiles)
    misses = lambda: sum(accumulate_steps.stats.cache_misses.values()) if hasattr(accumulate_steps, "stats") else 0
    m0, t0 = misses(), time.perf_counter()
    with compiling():
        accumulate_steps(np.array([0.0, 1.0]), np.zeros((2, 1)), np.array([-1]), np.zeros((4, 1)), np.zeros(2),
                         np.zeros(1), np.ones(1, bool), np.zeros(1), np.ones(1), False, 0.0, 1.0, i0, i0, i0,
                         np.zeros((2, 0)), f0, np.zeros((8, 0)))
    if misses() > m0:
        print(f"components: statistics' accumulators compiled in {time.perf_counter() - t0:.0f} s (the first run of "
              "this code on this machine; then cached)", file=sys.stderr, flush=True)
