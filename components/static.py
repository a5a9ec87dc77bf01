"""The DPGT's quasi-static solution: the same model's steady state in the carrier frame (:mod:`mbd.static`),
at a few instants spread over the mesh and roller positions, and the statistics users read from it.

The steady motion is the scene's kinematic one: gears spin at their nominal speeds, planets rest on the
carrier, every roller circles its pin at its cage's pure-rolling speed. Held (its equation dropped,
:func:`mbd.static.solve_static`): the carrier's angle (the speed drive supplies whatever torque the balance
needs). Solved: every body's translation (a roller's along its radius only: it keeps its pocket's centre), the
gears' and planets' twist, each cage's rate with its rollers' orbits (its slip) and each roller's spin rate.
The sun torque is at its full value (after its ramp).

Statistics (:meth:`components.outputs.WindowStatistics.add_samples`): each snapshot weighs the same, and the
quantities are the ones a dynamic run averages (one definition). What only a dynamic run can give — cage
slip and accelerations, pocket impacts, a mesh's dynamic factor and transmission-error range — is left out
of the summary and named in ``omitted``.
"""
from __future__ import annotations

import math
import time

import numpy as np

import mbd
from mbd.static import SteadyMotion, _evaluator, carry, solve_static

from .outputs import WindowStatistics, cage_period
from .units import ParameterError

__all__ = ["STATIC_LIVES_NOTE", "steady_motion", "held_dofs", "snapshot_times", "solve_snapshots", "static_statistics", "static_summary",
           "rate_groups", "DYNAMIC_ONLY", "DEFAULT_SNAPSHOTS", "MOVES", "RATE_STEP"]

# summary keys a static solution cannot give (they need the motion's transients)
# what a static solution's lives are: every output that shows them says it (summary.json, the studies' tables)
STATIC_LIVES_NOTE = ("lives from the quasi-static solution's mean loads: they leave out the dynamic load (the meshes' "
                     "dynamic factor, impacts, cage motion), which shortens a life for the same mean load (a life goes "
                     "with the mean of a power of the load); where the load hardly fluctuates a static and a dynamic "
                     "life differ by what their mean loads differ, either way, and a forward/reverse change can differ "
                     "from the dynamic one where the two directions' loads fluctuate unequally")
# The rollers' slip and what follows from it (their share of time in the load zone, the entry, the smearing indicator)
# are a dynamic run's: out of the load zone a roller's spin keeps the memory of its inertia and slows by 1.4–28 % under
# EHL traction, where a static roller spins at the balance of its place (within 0.3 %), and in the load zone, where the
# speeds agree within 2.4 %, the slip is their small difference (docs/model.md §16)
DYNAMIC_ONLY = ("cage_", "pocket_", "guide_", "heat_land", "whole_revolutions", "carrier_speed_error",
                "te_peak_to_peak", "dynamic_factor", "drive_flank_peak", "roller_cage_", "roller_slip_",
                "roller_entr", "roller_loaded_share", "smearing_")


def _rollers(scene):
    for pair in scene.pairs:
        for kind in ("inner", "outer"):
            h = pair.bearing(kind)
            if h.kind == "rollers":
                yield h


def steady_motion(scene) -> SteadyMotion:
    """The scene's kinematic steady motion in its frame: rollers circle their pins at the cage's pure-rolling
    speed, every other body's centre rests (the carrier frame; a fixed frame is refused with the body that moves)."""
    m = scene.model
    orbit = np.zeros(m.n_bodies)
    host = np.full(m.n_bodies, -1)
    for h in _rollers(scene):
        for r in h.rollers:
            orbit[m.body(r).index] = h.omega_cage - m.frame.omega
            if h.cage is not None:       # each roller keeps its pocket's centre, wherever the cage sits
                host[m.body(r).index] = m.body(h.cage).index
    return SteadyMotion.from_state(m, scene.q0, scene.v0, orbit, host)


def held_dofs(scene) -> np.ndarray:
    """Free-DOF indices held at their steady values: the carrier's angle (its speed drive supplies the torque)."""
    m = scene.model
    idx = m.full_to_free[[3 * m.body("carrier").index + 2]]
    return idx[idx >= 0]


def rate_groups(scene) -> list:
    """The spin rates solved (:func:`mbd.static.solve_static`): each cage with its rollers' orbits (the cage
    turns where the moments on it and its rollers balance: its slip) and each roller's own spin (where its
    raceway tractions' moments balance). Rollers keep the centres of their pockets."""
    m = scene.model
    out = []
    for h in _rollers(scene):
        rollers = [m.body(r).index for r in h.rollers]
        out.append((m.body(h.cage).index if h.cage else -1, rollers))
        out += [(r, []) for r in rollers]
    return out


def snapshot_times(scene, n: int) -> np.ndarray:
    """``n`` instants after the load ramp spread over one carrier revolution — gravity and the ring (its teeth
    and runout) turn once relative to the carrier in it, the sun and planets whole times plus a fraction, each
    cage about twice — and over the mesh cycle: instant k sits at (k + ½)/n of the revolution, moved on by less
    than a mesh period to the mesh phase (j_k + ½)/n, j_k = k·p mod n with p coprime to n near n/φ (a Fibonacci
    lattice: the pairs (revolution, mesh phase) fill the unit square evenly; every mesh phase stratum once).
    Without a turning carrier: one revolution of the slowest cage."""
    if not (isinstance(n, (int, np.integer)) and n >= 1):
        raise mbd.ModelError(f"snapshots must be an integer >= 1, got {n!r}")
    sp, b = scene.speeds, scene.bearing
    T = 2.0 * math.pi / abs(sp.carrier) if sp.carrier != 0.0 else \
        max((cage_period(b, sp.carrier, sp.planet(k)) for k in ("inner", "outer")), default=math.inf)
    f_m = scene.f_m
    t0 = float(scene.ramp)
    if not np.isfinite(T):
        T = 1.0 / f_m if f_m > 0 else 1.0
    k = np.arange(n)
    t = t0 + (k + 0.5) / n * T
    if f_m > 0:
        p = max(1, round(n / 1.618033988749895))
        while math.gcd(p, n) != 1:
            p += 1
        phase = ((k * p) % n + 0.5) / n
        t += ((phase - t * f_m) % 1.0) / f_m
    return t


# snapshots a static solution averages unless asked otherwise: over one carrier revolution, 16 put the bearings' mean
# roller loads within 1.2 % of a dynamic run's (8: 1.5 %; tests/components/test_load_path.py) and halve the tooth
# errors' noise in a machine's K_γ (class 7: ±0.02 at 8 snapshots)
DEFAULT_SNAPSHOTS = 16

# a rate unknown's largest step [rad/s]: a roller whose tractions saturate (large slip) has a spin torque with no
# stiffness, and a long step throws it deep into saturation, where its torque pulls the cage's rate back and forth
# (the reference machine at ≥ 28 µm clearance did not converge with 1000 rad/s; its rollers spin 4200–5100 rad/s at
# condition 3, its slip in the load zone is a few rad/s)
RATE_STEP = 10.0

# where an instant has no static state, the snapshot moves on by these fractions of a mesh period, in turn
MOVES = (0.02, -0.02, 0.05, -0.05)


def solve_snapshots(scene, times, engine: str = "auto", system: mbd.System | None = None) -> list:
    """Static solutions at ``times``; each starts from the previous one carried over (:func:`mbd.static.carry`: the
    rollers' displacements and spin rates by their angle in the load zone), the first from the kinematic pose.

    Some instants have no static state: a body rests on a force's jump — a tooth pair's damping switches on with
    its closing gap's rate (docs/model.md §7.1), so the force has no root there. Such a snapshot is moved on by a
    small fraction of a mesh period (:data:`MOVES`; a snapshot sits at the middle of its mesh-phase stratum, 1/n of
    a mesh period wide, so a 2 % move stays inside it for n < 25 snapshots, a 5 % move for n < 10);
    the solutions' ``t`` say where each was taken, and a snapshot that no move solves raises the first error, the
    operating point named."""
    m = scene.model
    system = system if system is not None else mbd.System(m)
    motion, hold, rates = steady_motion(scene), held_dofs(scene), rate_groups(scene)
    ev = _evaluator(system, engine)
    period = 1.0 / scene.f_m if scene.f_m > 0 else 0.0

    def attempts(t):
        """(time, start, walk) in the order tried: each instant and its moves, from the previous instant carried
        over, failing that from the kinematic pose (the previous instant's contacts can be a worse start than
        none); walking free modes (gears floating in their backlash) only where none of these solves."""
        for walk in (False, True):
            for move in (0.0, *(MOVES if period > 0 else ())):
                tm = t + move * period
                for start in ([carry(m, motion, out[-1], tm, rates)] if out else []) + [(None, None)]:
                    yield tm, start, walk

    out = []
    for t in (float(x) for x in times):
        first = None
        for tm, start, walk in attempts(t):
            try:
                out.append(solve_static(m, motion, tm, hold=hold, rates=rates, q_start=start[0],
                                        rates_start=start[1], system=system, evaluator=ev, max_rate_step=RATE_STEP,
                                        walk=walk))
                break
            except mbd.ModelError as exc:
                first = first or exc
        else:
            raise mbd.ModelError(f"{_point(scene)}: {first} (a dynamic run, --mode dynamic, needs none)") \
                from None
    return out


def _point(scene) -> str:
    """The operating point a failure names: the carrier's speed and the sun torque."""
    sp, T = getattr(scene, "speeds", None), getattr(scene, "sun_torque", None)
    if sp is None or T is None:
        return "the static solution"
    return f"the operating point at carrier speed {sp.carrier * 30.0 / math.pi:.6g} r/min, sun torque {T:.4g} N m"


def static_statistics(scene, n_snapshots: int = DEFAULT_SNAPSHOTS, engine: str = "auto"):
    """(statistics, solutions): the :class:`~components.outputs.WindowStatistics` of ``n_snapshots`` static
    solutions (each an equally weighted sample) and the solutions themselves."""
    m = scene.model
    system = mbd.System(m)
    times = snapshot_times(scene, n_snapshots)
    sols = solve_snapshots(scene, times, engine=engine, system=system)
    ts = np.array([s.t for s in sols])
    stats = WindowStatistics(scene, float(ts.min()), float(ts.max()) + 1e-9, whole_revolutions=False)
    stats.prepare(m, system)      # samples, not steps: no accumulators to compile
    z = {k: np.stack([np.asarray(s.z[k]) for s in sols]) for k in sols[0].z}
    rows = stats.snapshots(ts, np.stack([s.q for s in sols]),
                           np.stack([s.v for s in sols]), np.stack([s.a for s in sols]), z)
    stats.add_samples(rows, ts)
    return stats, sols


def check_steady(params) -> None:
    """Refuse an operating point with a schedule in time (``operating.schedule``): a static solution is the steady
    state of one operating point, so a start-up or a torque drop has none."""
    if params.si().operating.schedule:
        raise ParameterError.at("operating.schedule", "a static solution is of a steady operating point; a schedule "
                                                      "in time needs a dynamic run (--mode dynamic)")


def static_summary(scene, n_snapshots: int = DEFAULT_SNAPSHOTS, engine: str = "auto") -> dict:
    """The statistics of ``n_snapshots`` static solutions in summary.json's keys (dynamic-only ones left out and
    listed in ``omitted``), with the solver's cost."""
    t_wall = time.perf_counter()
    stats, sols = static_statistics(scene, n_snapshots, engine)
    asked = snapshot_times(scene, n_snapshots)
    omitted: set[str] = set()
    summary = _drop(stats.summary(), omitted)
    summary["mode"] = "static"
    summary["lives_ignore_dynamic_load"] = True          # STATIC_LIVES_NOTE
    summary["snapshots"] = len(sols)
    summary["omitted"] = sorted(omitted)
    summary["static_solver"] = {"steps": int(sum(s.steps for s in sols)),
                                "solve_s": float(sum(s.wall_s for s in sols)),
                                "wall_s": time.perf_counter() - t_wall,
                                # snapshots moved off an instant without a static state (solve_snapshots)
                                "moved": int(sum(s.t != t for s, t in zip(sols, asked)))}
    return summary


def _drop(d, omitted: set):
    if not isinstance(d, dict):
        return d
    out = {}
    for k, v in d.items():
        if k.startswith(DYNAMIC_ONLY) or k in ("window_s", "window_duration_s"):
            omitted.add(k)
            continue
        out[k] = _drop(v, omitted)
    return out
