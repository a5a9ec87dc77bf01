"""The statistics' accumulators: the running sums of every per-step quantity (:mod:`.quantities`) over its window
— time-weighted Σx dt and Σx² dt, maxima, minima — each window's length, the cages' angles and the pocket-impact
counts, in :class:`Accumulators`; the arithmetic is one compiled loop over a block of steps
(:func:`accumulate_steps`), so that a block of a few hundred steps costs one call.

Per step [t_a, t_b] of size h, a quantity x is taken linear in the step (the trapezoid rule) between the
step fractions w_a (the window's start inside the step, else 0) and w_1 (its window's end inside the step,
else 1): Σx += ½(x(w_a) + x(w_1))·dt, Σx² += ½(x(w_a)² + x(w_1)²)·dt, dt = (w_1 − w_a)·h; max and min of
its two ends over steps with dt > 0. A mesh quantity's window ends at t1; a bearing's when its cage has
turned its whole number of revolutions relative to the carrier (its angle integrated by the same rule).

The kernels compile (or load from numba's cache) before a run's first step, announced when they must compile
(:func:`compile_accumulators`). Without numba the same functions run as plain Python (slowly, but the results
are the same).
"""
from __future__ import annotations

import math

import numpy as np

try:
    from numba import njit as _njit
    from mbd import compiled as _compiled      # kernels_cached is read through the package when called
    jit = _njit(cache=True)
except ImportError:      # pragma: no cover - numba is a dependency; this keeps the module importable
    _compiled = None

    def jit(fn):
        return fn

__all__ = ["Accumulators", "accumulate_steps", "compile_accumulators", "IMPACT_ROWS", "FlankPeaks", "accumulate_flank",
           "FLANK_RANGE", "FLANK_BINS", "DYNAMIC_PERCENTILE", "PeakProfiles", "power_terms"]

# the drive-flank force's distribution: x/F_nom in FLANK_BINS equal bins over [0, FLANK_RANGE), one more above
FLANK_RANGE = 8.0
FLANK_BINS = 8000
DYNAMIC_PERCENTILE = 99.0

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


@jit
def _spread(hist, j, lo, hi, dt, scale):
    """Add the time ``dt`` a linear piece spends going between the values ``lo`` ≤ ``hi`` to column ``j`` of
    ``hist`` (bins of x/scale), in proportion to each bin's share of [lo, hi]: a linear piece spends equal times in
    equal value intervals."""
    nb = hist.shape[1] - 1
    width = FLANK_RANGE / nb
    a, b = max(lo / scale, 0.0), max(hi / scale, 0.0)
    ka, kb = min(int(a / width), nb), min(int(b / width), nb)
    if kb == ka or b <= a:
        hist[j, ka] += dt
        return
    span = b - a
    for k in range(ka, kb + 1):
        left = k * width if k > ka else a
        right = (k + 1) * width if k < kb else b
        if k == nb:
            right = b
        if right > left:
            hist[j, k] += dt * (right - left) / span


@jit
def accumulate_flank(t, V, t0, t_end, period, scale, hist, sums, cyc):
    """The drive-flank force's distribution and its mesh-cycle peaks over [t0, t_end] from the steps between the
    rows of ``t`` (K+1,) / ``V`` (K+1, n) (one column per mesh instance), linear within a step: ``hist`` (n,
    FLANK_BINS + 1) the time spent in each bin of x/``scale`` (the last: above FLANK_RANGE), ``sums`` (2, n) Σx dt
    and the time covered, ``cyc`` (4, n) the sum of the finished cycles' peaks, their count, the current cycle's
    peak and its index (cycle k = [t0 + k·period, t0 + (k+1)·period]; a step is cut at the cycle edges, the force
    there interpolated). All updated in place."""
    K = t.size - 1
    n = V.shape[1]
    for i in range(K):
        t_a, t_b = t[i], t[i + 1]
        if t_b <= t0 or t_a >= t_end:
            continue
        h = t_b - t_a
        s_a = max(t_a, t0)
        stop = min(t_b, t_end)
        while s_a < stop:
            k = int(math.floor((s_a - t0) / period + 1e-9))
            s_b = min(stop, t0 + (k + 1) * period)
            if s_b <= s_a:
                s_b = stop
            wa, wb = (s_a - t_a) / h, (s_b - t_a) / h
            dt = s_b - s_a
            for j in range(n):
                x0, x1 = V[i, j], V[i + 1, j]
                va, vb = x0 + wa * (x1 - x0), x0 + wb * (x1 - x0)
                sums[0, j] += 0.5 * (va + vb) * dt
                sums[1, j] += dt
                _spread(hist, j, min(va, vb), max(va, vb), dt, scale)
                if cyc[3, j] != k:
                    if cyc[3, j] >= 0.0:
                        cyc[0, j] += cyc[2, j]
                        cyc[1, j] += 1.0
                    cyc[3, j] = k
                    cyc[2, j] = -np.inf
                cyc[2, j] = _max(cyc[2, j], _max(va, vb))
            s_a = s_b


@jit
def power_terms(x, scale, exponent, out):
    """out[j] = (x[j]/scale)^exponent over the flat arrays ``x``, ``out``: the life's power terms of a block of states,
    e.g. the ISO/TS 16281 slice terms (q_k/q_c,k)^e of :func:`.quantities.slice_quantities` (e = 4 and 9/2, the
    raceways' exponents of :mod:`components.life`). A whole or half-whole exponent up to 31.5 by squaring, times √y for
    the half ((y²)² and (y²)² √y: arithmetic only, the compiler runs it in SIMD lanes, where numpy's power is a library
    call an element); any other by ``**``. numpy's (x/scale)**exponent to a few ulp
    (tests/components/test_slice_terms.py)."""
    twice = 2.0 * exponent
    m = int(twice)
    if m != twice or m < 0 or m > 63:
        for j in range(x.size):
            out[j] = (x[j] / scale) ** exponent
        return
    whole, half = m >> 1, (m & 1) == 1
    for j in range(x.size):
        y = x[j] / scale
        r, b = 1.0, y
        for bit in range(5):        # y^whole, a select per bit (no branch on y)
            if (whole >> bit) & 1:
                r = r * b
            b = b * b
        out[j] = r * math.sqrt(y) if half else r


class FlankPeaks:
    """The drive flank's force over whole carrier revolutions (:func:`accumulate_flank`): its time-weighted
    distribution, mean and mesh-cycle peaks per mesh instance, for the dynamic factors of
    :func:`.summaries.mesh_summary`.

    ``keys``, ``sizes``: the drive-force quantities, in order, and their instances (one column each); ``t0``,
    ``t_end``: the window [s]; ``period``: one mesh cycle [s]; ``scale``: the nominal drive-flank force [N] the bins
    are counted in; ``revolutions``: the whole carrier revolutions the window spans (0: whole mesh cycles only)."""

    def __init__(self, keys, sizes, t0: float, t_end: float, period: float, scale: float, revolutions: int):
        self.revolutions = int(revolutions)
        self.keys, self.sizes = tuple(keys), tuple(int(n) for n in sizes)
        self.t0, self.t_end, self.period, self.scale = float(t0), float(t_end), float(period), float(scale)
        n = sum(self.sizes)
        self.hist = np.zeros((n, FLANK_BINS + 1))
        self.sums = np.zeros((2, n))
        self.cyc = np.zeros((4, n))
        self.cyc[3] = -1.0
        self.cyc[2] = -np.inf

    def add_steps(self, t, rows) -> None:
        """K steps: their K+1 ends ``t`` and the quantities at them (``rows``, the drive forces among them)."""
        # C order, as compile_accumulators compiles the kernel (the outputs' columns join in F order: a second
        # compile, about a second, in every process whose cache lacked it)
        V = np.ascontiguousarray(np.concatenate([np.asarray(rows[k], float).reshape(t.size, -1) for k in self.keys],
                                                axis=1))
        accumulate_flank(np.ascontiguousarray(t, float), V, self.t0, self.t_end, self.period, self.scale, self.hist, self.sums,
                         self.cyc)

    def complete(self) -> bool:
        """Has the window been covered to its end?"""
        return bool(self.sums[1].size) and float(self.sums[1].min()) >= (self.t_end - self.t0) * (1.0 - 1e-9)

    def _split(self, x) -> dict:
        edges = np.cumsum((0,) + self.sizes)
        return {k: x[..., a:b] for k, a, b in zip(self.keys, edges[:-1], edges[1:])}

    def results(self) -> dict:
        """{key: {"mean", "percentile", "cycle_peak_mean", "cycles"}} per instance (arrays): the time mean, the
        DYNAMIC_PERCENTILE-th percentile of the time distribution (linear within a bin; inf when it lies above
        FLANK_RANGE × scale) and the mean of the whole cycles' peaks; NaN without a whole window."""
        T = self.sums[1]
        mean = np.where(T > 0, self.sums[0] / np.where(T > 0, T, 1.0), np.nan)
        cum = np.cumsum(self.hist, axis=1)
        goal = DYNAMIC_PERCENTILE / 100.0 * T
        width = FLANK_RANGE / FLANK_BINS
        pct = np.full(T.size, np.nan)
        for j in range(T.size):
            if T[j] <= 0:
                continue
            k = int(np.searchsorted(cum[j], goal[j], side="left"))
            if k >= FLANK_BINS:
                pct[j] = np.inf
                continue
            below = cum[j, k - 1] if k > 0 else 0.0
            frac = (goal[j] - below) / self.hist[j, k] if self.hist[j, k] > 0 else 0.0
            pct[j] = (k + frac) * width * self.scale
        peaks, count = self.cyc[0].copy(), self.cyc[1].copy()
        if self.complete():                      # the last cycle ended with the window: it is whole
            last = self.cyc[3] >= 0
            peaks += np.where(last, self.cyc[2], 0.0)
            count += last
        cyc = np.where(count > 0, peaks / np.where(count > 0, count, 1.0), np.nan)
        parts = {name: self._split(x) for name, x in (("mean", mean), ("percentile", pct), ("cycle_peak_mean", cyc),
                                                         ("cycles", count))}
        return {k: {name: parts[name][k] for name in parts} for k in self.keys}

    def state_dict(self) -> dict:
        return {"hist": self.hist, "sums": self.sums, "cyc": self.cyc}

    def load_state_dict(self, d: dict) -> None:
        self.hist[:], self.sums[:], self.cyc[:] = d["hist"], d["sums"], d["cyc"]


class Accumulators:
    """The running sums of every quantity over its window: per instance Σx dt, Σx² dt, max and min (one flat
    (4, n) array; :meth:`stats` reads it back), the time each bearing's window and the global (mesh) one have
    covered, the cages' angles relative to the carrier, and the pocket impacts (:data:`IMPACT_ROWS`).

    ``n_bearings``; ``t0``, ``t1`` the nominal window [s]; ``target`` (n_b,) the whole cage revolutions that end
    each bearing's window, or None (the nominal window); ``pocket_bearing`` (n_p,) each pocket's bearing and
    ``v_floor`` (n_p,) the impact law's approach-speed floor (slower onsets are touches); ``entry_dwell`` (n_b,) the
    time [s] a roller of each bearing must have spent out of the load zone for its loading to count as an entry
    (:meth:`_entries`; None: 0, every loading)."""

    def __init__(self, n_bearings: int, t0: float, t1: float, target, pocket_bearing, v_floor, entry_dwell=None):
        self.t0, self.t1 = float(t0), float(t1)
        self.has_target = target is not None
        self.target = np.asarray(target if target is not None else np.zeros(n_bearings), float)
        self.pocket_bearing = np.asarray(pocket_bearing, np.int64)
        self.v_floor = np.asarray(v_floor, float)
        self.flat, self.acc, self.keys, self.owners = None, {}, (), {}
        self.T = np.zeros(n_bearings + 1)                   # time covered by each bearing's window, the global one
        self.angle = np.zeros(n_bearings)                   # cage angle relative to the carrier since t0
        self.open = np.ones(n_bearings, bool)               # bearing windows still open
        self.t_close = np.full(n_bearings, np.nan)
        self.imp = np.zeros((len(IMPACT_ROWS), self.pocket_bearing.size))
        self.impact = dict(zip(IMPACT_ROWS, self.imp)) if self.imp.size else None    # row views
        self.entry = None          # (3, n_rollers): load-zone entries, Σ slip and Σ p·Δv at them (:meth:`_entries`)
        self.exit_time = None      # (n_rollers,): when each roller last left the load zone [s] (−inf: not yet)
        self.entry_dwell = np.zeros(n_bearings) if entry_dwell is None else np.asarray(entry_dwell, float)
        self._entry_keys = None

    def layout(self, sizes: dict, owners: dict, cage_speed: str, pocket_force: str, entry_keys=None) -> None:
        """Lay the flat accumulator out (zeros; ±inf extrema) for the quantities ``sizes`` {key: instances}, in that
        order, each instance tagged with its bearing (``owners`` {key: (n,) or None: the global window}); if it
        holds sums already (a checkpoint), only its views. ``cage_speed``, ``pocket_force``: the keys whose
        columns the kernel reads for the cages' angles and the impact peaks; ``entry_keys`` (loaded, slip, p·Δv): the
        per-roller quantities whose load-zone entries are counted (:meth:`_entries`), None: none."""
        keys = list(sizes)
        edges = np.concatenate([[0], np.cumsum([sizes[k] for k in keys])]).astype(int)
        self.keys, self.owners = keys, dict(owners)
        self._own_flat = np.concatenate([owners[k] if owners[k] is not None else np.full(sizes[k], -1)
                                         for k in keys]).astype(np.int64)
        if self.flat is None:
            n = int(edges[-1])
            self.flat = np.stack([np.zeros(n), np.zeros(n), np.full(n, -np.inf), np.full(n, np.inf)])
        self.acc = {k: self.flat[:, a:b] for k, a, b in zip(keys, edges[:-1], edges[1:])}
        col = dict(zip(keys, edges[:-1]))
        self._cage_cols = (col[cage_speed] + np.arange(self.angle.size)).astype(np.int64) \
            if cage_speed in col else np.zeros(0, np.int64)
        if entry_keys is not None and entry_keys[0] in sizes:
            self._entry_keys, self._entry_owner = tuple(entry_keys), np.asarray(owners[entry_keys[0]], np.int64)
            if self.entry is None:
                self.entry = np.zeros((3, sizes[entry_keys[0]]))
                self.exit_time = np.full(sizes[entry_keys[0]], -np.inf)
        npk = self.imp.shape[1]
        self._pocket_cols = (col[pocket_force] + np.arange(npk)).astype(np.int64) if npk else np.zeros(0, np.int64)

    def closed(self, t_start: float) -> bool:
        """Has every window ended before ``t_start``?"""
        return t_start >= self.t1 and not self.open.any()

    def _flatten(self, rows, K: int) -> np.ndarray:
        return np.concatenate([np.asarray(rows[k], float).reshape(K, -1) for k in self.keys], axis=1)

    def add_steps(self, t, rows, Z) -> None:
        """K steps: their K+1 ends ``t``, each quantity at them (``rows``), the pockets' stored approach speeds
        ``Z`` (K+1, n_p)."""
        V = self._flatten(rows, t.size)
        Zf = np.ascontiguousarray(Z, float) if self.imp.size else np.zeros((t.size, 0))
        accumulate_steps(t, V, self._own_flat, self.flat, self.T, self.angle, self.open, self.t_close, self.target,
                         self.has_target, self.t0, self.t1, self._cage_cols, self._pocket_cols, self.pocket_bearing,
                         Zf, self.v_floor, self.imp)
        if self._entry_keys is not None:
            self._entries(t, rows)

    def _entries(self, t, rows) -> None:
        """The load-zone entries of K steps: a roller unloaded at a step's start and loaded at its end (the first
        of the ``entry_keys`` quantities) that had been out of the load zone for at least its bearing's
        ``entry_dwell`` (since the first unloaded state after it last left; a roller flickering at the zone's edge
        does not enter it again), in its bearing's window (the step ending after t0 and by the window's end),
        counted with its slip at the step's start (the last state out of the load zone) and its pin contact's p·Δv at
        the step's end (the first state in it): ``entry`` rows count, Σ slip [%], Σ p·Δv [W/m²]."""
        loaded, slip, pv = (np.asarray(rows[k], float).reshape(t.size, -1) for k in self._entry_keys)
        t = np.asarray(t, float)
        was, now = loaded[:-1] > 0.0, loaded[1:] > 0.0
        enter, leave = ~was & now, was & ~now
        # when each roller last left the zone, as of each step (a step leaves or enters, never both)
        left = np.maximum.accumulate(np.where(leave, t[1:, None], -np.inf), axis=0)
        left = np.maximum(left, self.exit_time[None, :])
        self.exit_time = left[-1].copy()
        if not enter.any():
            return
        end = np.where(self.open, np.inf, self.t_close) if self.has_target else np.full(self.open.size, self.t1)
        t_b = t[1:, None]
        own = self._entry_owner
        enter &= (t_b > self.t0) & (t_b <= end[own][None, :]) & (t[:-1, None] - left >= self.entry_dwell[own][None, :])
        self.entry[0] += enter.sum(axis=0)
        self.entry[1] += np.where(enter, slip[:-1], 0.0).sum(axis=0)
        self.entry[2] += np.where(enter, pv[1:], 0.0).sum(axis=0)

    def add_samples(self, rows) -> None:
        """K equally weighted states (``rows`` as for :meth:`add_steps`): each counts one unit of time in every
        window, so means are plain averages and max/min the extremes over the states."""
        K = len(rows[self.keys[0]])
        V = self._flatten(rows, K)
        self.flat[0] += V.sum(axis=0)
        self.flat[1] += (V * V).sum(axis=0)
        np.maximum(self.flat[2], V.max(axis=0), out=self.flat[2])
        np.minimum(self.flat[3], V.min(axis=0), out=self.flat[3])
        self.T += K

    def close_impacts(self) -> None:
        """Impacts still in progress when their window ended count with the peak they reached."""
        im = self.impact
        if im is None:
            return
        act = im["active"] > 0
        im["peak_sum"] += np.where(act, im["peak_now"], 0.0)
        np.maximum(im["peak_max"], np.where(act, im["peak_now"], 0.0), out=im["peak_max"])
        im["active"][act] = 0.0
        im["peak_now"][act] = 0.0

    # reading back ---------------------------------------------------------------------------------
    def integral(self, key: str) -> np.ndarray:
        """Σx dt of a quantity over its window (per instance; equally weighted samples: Σx)."""
        return self.acc[key][0]

    def time(self, key: str) -> np.ndarray:
        """The time each instance of a quantity's window covers [s] (samples: their count)."""
        own = self.owners[key]
        return self.T[:-1][own] if own is not None else np.full(self.acc[key].shape[1], self.T[-1])

    def stats(self, key: str) -> dict[str, np.ndarray]:
        """mean, rms, max, min of a quantity over its window (arrays per instance)."""
        acc = self.acc[key]
        own = self.owners[key]
        T = self.T[:-1][own] if own is not None else self.T[-1]
        T = np.where(np.asarray(T) > 0, T, np.nan)
        return {"mean": acc[0] / T, "rms": np.sqrt(np.maximum(acc[1], 0.0) / T), "max": acc[2], "min": acc[3]}

    def aggregate_rms(self, key: str, bearings) -> float:
        """RMS of a quantity over every instance that belongs to ``bearings`` (time-weighted, all windows)."""
        own = self.owners[key]
        mine = np.isin(own, bearings)
        T = self.T[:-1][own[mine]]
        return float(np.sqrt(self.acc[key][1][mine].sum() / T.sum()))

    @property
    def duration(self) -> float:
        """Length of the global (mesh) window covered so far [s]."""
        return self.T[-1]

    def window_length(self, bearing: int) -> float:
        """Length of bearing ``bearing``'s window covered so far [s]."""
        return float(self.T[bearing])

    def cage_revolutions(self, sel) -> float:
        """Cage revolutions relative to the carrier in the windows of the bearings ``sel``, summed."""
        return float(np.abs(self.angle[sel]).sum() / (2 * math.pi))

    # checkpoints ---------------------------------------------------------------------------------
    def state_dict(self) -> dict:
        d = {"acc": self.flat} if self.flat is not None else {}
        d.update({f"imp__{k}": v for k, v in (self.impact or {}).items()})
        d.update({"T_global": np.array(self.T[-1]), "T_bearing": self.T[:-1], "angle": self.angle,
                  "open": self.open, "t_close": self.t_close})
        if self.entry is not None:
            d["entry"], d["entry_exit"] = self.entry, self.exit_time
        return d

    def load_state_dict(self, d: dict) -> None:
        """The sums of :meth:`state_dict` (lay them out again with :meth:`layout`)."""
        self.acc, self.flat = {}, (d["acc"].copy() if "acc" in d else None)
        for k in IMPACT_ROWS:
            if f"imp__{k}" in d:
                self.impact[k][:] = d[f"imp__{k}"]
        if "T_global" in d:
            self.T[:-1], self.T[-1] = d["T_bearing"], float(d["T_global"])
            self.angle[:], self.open[:], self.t_close[:] = d["angle"], d["open"].astype(bool), d["t_close"]
        self.entry = d["entry"].copy() if "entry" in d else None
        self.exit_time = d["entry_exit"].copy() if "entry_exit" in d else None


def accumulators_cached() -> bool:
    """Does numba's disk cache hold the accumulators of this code (plain Python without numba: nothing to compile)?"""
    return _compiled is None or all(_compiled.kernels_cached(k) for k in (accumulate_steps, accumulate_flank, power_terms))


def compile_accumulators() -> None:
    """Compile (or load) the accumulators now, on a one-step toy window: a run does it before its first step (a
    progress bar's ETA then leaves the compile out), saying so when it must compile, as the engine's kernels."""
    if _compiled is None:      # pragma: no cover - plain Python
        return
    i0, f0 = np.zeros(0, np.int64), np.zeros(0)
    def toy():
        accumulate_steps(np.array([0.0, 1.0]), np.zeros((2, 1)), np.array([-1]), np.zeros((4, 1)), np.zeros(2),
                         np.zeros(1), np.ones(1, bool), np.zeros(1), np.ones(1), False, 0.0, 1.0, i0, i0, i0,
                         np.zeros((2, 0)), f0, np.zeros((8, 0)))
        accumulate_flank(np.array([0.0, 1.0]), np.ones((2, 1)), 0.0, 1.0, 0.5, 1.0, np.zeros((1, FLANK_BINS + 1)),
                         np.zeros((2, 1)), np.array([[0.0], [0.0], [-np.inf], [-1.0]]))
        power_terms(np.ones(1), 1.0, 4.5, np.empty(1))
    _compiled.compile_announced(toy, cold=not accumulators_cached(), what="the statistics' accumulator kernels",
                                done="accumulator kernels", about="a few seconds")


class PeakProfiles:
    """Per bearing, the slice loads of its most loaded roller at that roller's peak instant (docs/model.md §13.2: a
    maximum over the states of the window — the step ends, or the samples of a static solution): the roller with the
    largest pin load Σ_k q_k over its bearing's window, its pin and bore slice loads [N] at that state, the time [s]
    and the roller (instance index within its bearing, row by row). ``n_bearings``, ``n_slices``; the rollers of the
    quantities are grouped bearing by bearing, equally many each (:func:`.quantities.plan_of`)."""

    def __init__(self, n_bearings: int, n_slices: int):
        self.load = np.full(n_bearings, -np.inf)
        self.time = np.full(n_bearings, np.nan)
        self.roller = np.full(n_bearings, -1, np.int64)
        self.pin = np.zeros((n_bearings, n_slices))
        self.bore = np.zeros((n_bearings, n_slices))

    def add(self, t, Q, pin, bore, owner, lo: float, end) -> None:
        """K states at times ``t`` (K,): roller pin loads ``Q`` (K, n_r), slice loads ``pin``, ``bore`` (K, n_r·n_s);
        ``owner`` (n_r,) each roller's bearing; a state counts for a bearing when lo ≤ t ≤ ``end`` [bearing] (its
        window's end, inf while open)."""
        t, Q = np.asarray(t, float), np.asarray(Q, float)
        K, n_r = Q.shape
        nb, n_s = self.pin.shape
        z = n_r // nb
        ok = ~((t[:, None] < lo) | (t[:, None] > np.asarray(end, float)[owner][None, :]))     # NaN times: samples
        flat = np.where(ok, Q, -np.inf).reshape(K, nb, z).transpose(1, 0, 2).reshape(nb, K * z)
        i = flat.argmax(axis=1)
        best = flat[np.arange(nb), i]
        better = best > self.load
        if not better.any():
            return
        k, j = np.divmod(i, z)
        b = np.flatnonzero(better)
        r = b * z + j[b]
        self.load[b], self.time[b], self.roller[b] = best[b], t[k[b]], j[b]
        self.pin[b] = np.asarray(pin, float).reshape(K, n_r, n_s)[k[b], r]
        self.bore[b] = np.asarray(bore, float).reshape(K, n_r, n_s)[k[b], r]

    def state_dict(self) -> dict:
        return {"load": self.load, "time": self.time, "roller": self.roller, "pin": self.pin, "bore": self.bore}

    def load_state_dict(self, d: dict) -> None:
        for k in ("load", "time", "roller", "pin", "bore"):
            getattr(self, k)[...] = d[k]
