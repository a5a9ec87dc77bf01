"""The observer that takes the statistics of a run (:class:`WindowStatistics`): it wires the per-step quantities
(:mod:`.quantities`), the accumulators (:mod:`.accumulate`) and the summaries (:mod:`.summaries`) to the one
simulation loop (:func:`mbd.simulate`), and sizes the window (:func:`default_window`, :func:`cage_period`)."""
from __future__ import annotations

import math

import numpy as np

import mbd
from mbd.simulate import ENGINES

from ..bearing import bearing_kinematics
from ..families import FAMILY
from ..sliced_bearing import pressure_scales
from . import quantities as Q
from .accumulate import PeakProfiles, Accumulators, FlankPeaks, compile_accumulators
from .summaries import equivalent_slice_loads, run_summary

__all__ = ["WindowStatistics", "default_window", "cage_period"]


def cage_period(b, omega_pin: float, omega_planet: float) -> float:
    """Time of one cage revolution relative to the pin [s] in pure rolling (inf when it does not turn)."""
    w_cage, _ = bearing_kinematics(b, omega_pin, omega_planet)
    rel = abs(w_cage - omega_pin)
    return 2.0 * math.pi / rel if rel > 0 else math.inf


def default_window(base: float, periods) -> float:
    """``base`` [s] rounded up to whole revolutions of the slowest cage (the longest of ``periods``)."""
    T = max((p for p in periods if np.isfinite(p)), default=0.0)
    if T <= 0.0:
        return base
    return math.ceil(base / T - 1e-9) * T


class WindowStatistics(mbd.Observer):
    """Statistics of a DPGT-like scene from ``t0`` on, on every accepted step (:mod:`components.outputs`).

    Window: the mesh quantities cover [t0, t1]. A bearing's quantities (its load, rollers, pockets, cage)
    cover whole revolutions of its cage relative to the carrier, as many as fit in the nominal window,
    ``round((t1 − t0)/T_cage)`` — so they end when that cage has turned that far, not at t1: the cage
    slips (≈ 0.7 % at condition 3) and a nominal window would cut every roller's orbit at a different
    point of the load zone. Run the simulation to :attr:`t_end` (t1 plus a margin for the slip); a cage
    that slips more than the margin ends at the run's end and is reported with whole_revolutions false.

    ``scene``: a :class:`~components.dpgt.PlanetBearingScene` (its pairs, see :func:`.quantities.bearing_map`;
    speeds; bearing; lubricant; the loaded flank of each mesh type; the sun torque). After the run, :meth:`summary`
    gives the numbers. ``outputs``: what evaluates the element outputs (:func:`mbd.output_evaluator`): "auto" (the
    compiled kernels), "compiled" or "numpy" (the reference kernels, as the tests use them to hold the compiled ones).
    """

    MARGIN = 0.05      # extra run time for slipping cages, as a fraction of the window

    def __init__(self, scene, t0: float, t1: float, whole_revolutions: bool = True, outputs: str = "auto"):
        if not (np.isfinite(t0) and np.isfinite(t1) and t1 > t0):
            raise mbd.ModelError(f"statistics window must satisfy t1 > t0 [s], got [{t0!r}, {t1!r}]")
        if outputs not in ENGINES:
            raise mbd.ModelError(f"outputs must be one of {ENGINES}, got {outputs!r}")
        self.outputs = outputs
        self.t0, self.t1 = float(t0), float(t1)
        self.scene = scene
        self.bmap = Q.bearing_map(scene)
        sp = scene.speeds
        self.omega_c = float(sp.carrier)
        self.flanks = dict(scene.flanks)
        rollers = self.bmap[0]["type"] == "rollers" and "cage" in self.bmap[0]
        self.target = None
        if whole_revolutions and rollers:
            b = scene.bearing
            T = {k: cage_period(b, self.omega_c, sp.planet(k)) for k in ("inner", "outer")}
            revs = np.array([(self.t1 - self.t0) / T[x["kind"]] for x in self.bmap])
            if np.all(np.isfinite(revs)) and np.all(revs >= 0.5):
                self.target = np.maximum(np.round(revs), 1.0)
        self.t_end = self.t1 + (self.MARGIN * (self.t1 - self.t0) if self.target is not None else 0.0)
        # the planet's speed relative to its pin, per bearing kind: the revolutions a life counts
        self._w_rel = {k: float(sp.planet(k)) - self.omega_c for k in ("inner", "outer")}
        # a load-zone entry follows at least one roller pitch of the cage's orbit out of the zone (in pure rolling):
        # a shorter gap is a roller flickering at the zone's edge (Accumulators._entries)
        self.entry_dwell = None
        if rollers:
            pitch = {k: cage_period(scene.bearing, self.omega_c, sp.planet(k)) / scene.bearing.rollers
                     for k in ("inner", "outer")}
            self.entry_dwell = np.array([pitch[x["kind"]] if np.isfinite(pitch[x["kind"]]) else 0.0
                                         for x in self.bmap])

    # setup -------------------------------------------------------------------------------------
    def bind(self, model, system, state) -> None:
        """Before a run's first step: :meth:`prepare`, and compile the accumulators the steps will use."""
        self.prepare(model, system)
        compile_accumulators()

    def prepare(self, model, system) -> None:
        """Build the plan and the output evaluator (enough for samples, :meth:`add_samples`, without steps)."""
        self.model, self.system = model, system
        self._outputs = mbd.output_evaluator(system, self.outputs)
        self.plan = Q.plan_of(self.scene, model)
        self.meshes = self.plan.meshes
        self.reset()

    def reset(self) -> None:
        p = self.plan
        # approach-speed floor of the impact law: slower onsets are touches
        pockets = p.pocket_bearing if p.pocket_bearing is not None else np.zeros(0, np.int64)
        floor = self.model.element(FAMILY["pocket"]).v_min * (1.0 + 1e-9) if pockets.size else np.zeros(0)
        self.sums = Accumulators(p.planet.size, self.t0, self.t1, self.target, pockets, floor, self.entry_dwell)
        self.flank = self._flank_peaks()
        self.peak = PeakProfiles(p.planet.size, p.slices) if p.slices else None    # the sliced model's profiles
        self._prev = None            # the quantities at the last step's end: the next step's start
        self.ref_roller = None       # (inner, outer) race_inner instance of the reference rollers

    def _flank_peaks(self) -> FlankPeaks | None:
        """The drive flanks' dynamic-factor statistics (:class:`.accumulate.FlankPeaks`) over whole carrier revolutions
        from t0 (as many as fit in [t0, t1]; fewer than one: whole mesh cycles), counted in mesh cycles of
        z_s |ω_s − ω_c|/2π, binned in the nominal drive-flank force |T_s|/(N r_b,sun) (every mesh of the train carries
        it quasi-statically); None without a sun mesh, without torque or without motion."""
        fam = self.plan.meshes.get("sun_inner")
        w_s, w_c = float(self.scene.speeds.sun), self.omega_c
        if fam is None or self.scene.sun_torque == 0.0 or w_c == 0.0 or w_s == w_c:
            return None
        sun = self.model.element(fam)
        f_m = float(sun.teeth1[0]) * abs(w_s - w_c) / (2.0 * math.pi)
        T_m, T_c = 1.0 / f_m, 2.0 * math.pi / abs(w_c)
        span = self.t1 - self.t0
        revs = math.floor(span / T_c + 1e-9)
        t_end = self.t0 + (revs * T_c if revs >= 1 else math.floor(span / T_m + 1e-9) * T_m)
        if t_end <= self.t0:
            return None
        scale = abs(self.scene.sun_torque) / (len(self.scene.pairs) * float(sun.rb1[0]))
        keys = [f"{k}_drive_force" for k in self.plan.meshes]
        sizes = [self.model.element(f).n for f in self.plan.meshes.values()]
        return FlankPeaks(keys, sizes, self.t0, t_end, T_m, scale, revs)

    # states -> quantities ------------------------------------------------------------------------
    def snapshot(self, s) -> dict[str, np.ndarray]:
        """Every per-step quantity at state ``s`` (arrays per bearing / roller / mesh): :meth:`snapshots` of one."""
        z = {k: np.asarray(v)[None] for k, v in s.z.items()}
        rows = self.snapshots(np.array([s.t]), s.q[None], s.v[None], s.a[None], z)
        return {k: v[0] for k, v in rows.items()}

    def snapshots(self, t, q, v, a, z) -> dict[str, np.ndarray]:
        """Every per-step quantity at K states (:func:`.quantities.quantities`); until the reference rollers are
        chosen also the rollers' angles about their planets ("_roller_angle")."""
        return Q.quantities(self.plan, self.model, self._outputs, t, q, v, a, z, roller_angles=self.ref_roller is None)

    # accumulation --------------------------------------------------------------------------------
    def step(self, s0, s1) -> None:
        """One accepted step (the numpy engine's path; the compiled engine hands blocks to :meth:`on_block`)."""
        if s1.t <= self.t0 or self.sums.closed(s0.t):
            return
        x0 = self._prev if self._prev is not None else self.snapshot(s0)
        x1 = self.snapshot(s1)
        fam = FAMILY["pocket"]
        zs = [np.asarray(s.z[fam])[:, 0] if fam in s.z else np.zeros(0) for s in (s0, s1)]
        self._accumulate(np.array([s0.t, s1.t]), {k: np.stack([x0[k], x1[k]]) for k in x1}, np.stack(zs))

    def on_block(self, block) -> None:
        """A compiled block of steps: the quantities of all its states from the first step that reaches the
        window on, in one vectorised pass, then the compiled accumulators."""
        t = np.concatenate([[block.start.t], block.log[:, 0]])
        if t[-1] <= self.t0 or self.sums.closed(t[0]):
            return
        i0 = max(int(np.searchsorted(t, self.t0, side="right")) - 1, 0)     # the step that reaches t0 starts here
        t, q, v, a, z = block.arrays()
        rows = self.snapshots(t[i0:], q[i0:], v[i0:], a[i0:], {k: x[i0:] for k, x in z.items()})
        fam = FAMILY["pocket"]
        self._accumulate(t[i0:], rows, z[fam][i0:, :, 0] if fam in z else np.zeros((t.size - i0, 0)))

    def _accumulate(self, t, rows, Z) -> None:
        """Hand K steps (``rows``: each quantity at their K+1 ends; ``Z``: the pockets' stored approach speeds)
        to the accumulators; the first call chooses the reference rollers at the window's start."""
        if self.ref_roller is None and self.plan.rollers:
            i = int(np.searchsorted(t, self.t0, side="right")) - 1 if t[0] < self.t0 else 0
            i = min(max(i, 0), t.size - 2)
            wa = (max(t[i], self.t0) - t[i]) / (t[i + 1] - t[i])
            self.ref_roller = Q.reference_rollers(self.plan, _at(rows, i), _at(rows, i + 1), wa)
        self._layout(rows)
        self.sums.add_steps(t, rows, Z)
        if self.flank is not None:
            self.flank.add_steps(t, rows)
        if self.peak is not None:      # the bearing windows as the sums just closed them
            s = self.sums
            end = np.where(s.open, np.inf, s.t_close) if s.has_target else np.full(s.open.size, self.t1)
            self.peak.add(t, rows["roller_inner_load"], rows["_slice_inner"], rows["_slice_outer"],
                          self.plan.roller_bearing, self.t0, end)
        self._prev = {k: x[-1].copy() for k, x in rows.items()}

    def add_samples(self, rows, t=None) -> None:
        """Equally weighted states instead of integrator steps (a static solution's snapshots,
        :mod:`components.static`): ``rows`` as :meth:`snapshots` returns them; each state counts one unit of
        time in every window, so means are plain averages and max/min the extremes over the states; ``t`` their
        times [s] (the peak profiles' instants; NaN when not given)."""
        if self.ref_roller is None and self.plan.rollers:
            first = _at(rows, 0)
            self.ref_roller = Q.reference_rollers(self.plan, first, first, 0.0)
        self._layout(rows)
        self.sums.add_samples(rows)
        if self.peak is not None:      # every sample counts
            K = len(rows["roller_inner_load"])
            self.peak.add(np.full(K, np.nan) if t is None else np.asarray(t, float), rows["roller_inner_load"], rows["_slice_inner"], rows["_slice_outer"],
                          self.plan.roller_bearing, -np.inf, np.full(self.plan.planet.size, np.inf))

    def _layout(self, rows) -> None:
        """Lay the accumulators out for the quantities of ``rows`` once (the leading-underscore ones are not
        accumulated)."""
        if self.sums.acc:
            return
        keys = [k for k in rows if not k.startswith("_")]
        self.sums.layout({k: int(np.size(rows[k][-1])) for k in keys}, {k: Q.owner(self.plan, k) for k in keys},
                         cage_speed=Q.CAGE_SPEED, pocket_force=Q.POCKET_FORCE,
                         entry_keys=(Q.ROLLER_LOADED, Q.ROLLER_SLIP, Q.ROLLER_PV_PIN))

    # checkpoints ---------------------------------------------------------------------------------
    def state_dict(self) -> dict:
        d = self.sums.state_dict()
        d.update({f"flank__{k}": v for k, v in (self.flank.state_dict() if self.flank is not None else {}).items()})
        d.update({f"prev__{k}": v for k, v in (self._prev or {}).items()})
        d["ref"] = np.array(self.ref_roller if self.ref_roller is not None else (-1, -1))
        d.update({f"peak__{k}": v for k, v in (self.peak.state_dict() if self.peak is not None else {}).items()})
        return d

    def load_state_dict(self, d: dict) -> None:
        self.sums.load_state_dict(d)
        if self.flank is not None and "flank__hist" in d:
            self.flank.load_state_dict({k[7:]: v for k, v in d.items() if k.startswith("flank__")})
        self._prev = {k[6:]: v.copy() for k, v in d.items() if k.startswith("prev__")} or None
        if self.sums.flat is not None and self._prev is not None:
            self._layout({k: x[None] for k, x in self._prev.items()})
        if self.peak is not None and "peak__load" in d:
            self.peak.load_state_dict({k[6:]: v for k, v in d.items() if k.startswith("peak__")})
        ref = tuple(int(x) for x in d.get("ref", (-1, -1)))
        self.ref_roller = None if ref[0] < 0 else ref

    # results -------------------------------------------------------------------------------------
    def stats(self, key: str) -> dict[str, np.ndarray]:
        """mean, rms, max, min of a per-step quantity over its window (arrays per instance)."""
        return self.sums.stats(key)

    def aggregate_rms(self, key: str, bearings) -> float:
        """RMS of a quantity over every instance that belongs to ``bearings`` (time-weighted, all windows)."""
        return self.sums.aggregate_rms(key, bearings)

    @property
    def duration(self) -> float:
        """Length of the global (mesh) window covered so far [s]."""
        return self.sums.duration

    def slice_profiles(self) -> dict | None:
        """The sliced model's profiles per bearing (None for the planar model): along the most loaded roller at its
        peak instant (:class:`.accumulate.PeakProfiles`) its pin and bore slice loads [N] and Hertz pressures
        p = c √q [Pa] (:func:`components.sliced_bearing.pressure_scales`), the instant [s], the roller (within its
        bearing, row by row) and its row; and each bearing's equivalent slice loads per row over its window and its
        rollers, the ISO/TS 16281 life's q_e,k (pin exponent 4.5, bore 4; :mod:`.summaries`) [N]. Arrays by bearing
        (:func:`.quantities.bearing_map`'s order), slice, row."""
        if self.peak is None:
            return None
        p, pk = self.plan, self.peak
        c_pin, c_bore = pressure_scales(p.bearing, p.slices)
        z = p.roller_bearing.size // p.planet.size // p.explicit_rows        # rollers per row
        qe = equivalent_slice_loads(self.sums, p)
        return {"names": [x["name"] for x in self.bmap], "load_pin": pk.pin.copy(), "load_bore": pk.bore.copy(),
                "pressure_pin": c_pin * np.sqrt(pk.pin), "pressure_bore": c_bore * np.sqrt(pk.bore),
                "time": pk.time.copy(), "roller": pk.roller.copy(), "row": pk.roller // z,
                "equivalent_pin": qe[0], "equivalent_bore": qe[1]}

    def summary(self) -> dict:
        """The statistics users read, per bearing kind (see README: summary.json; :mod:`.summaries`)."""
        if self.duration <= 0.0:
            raise mbd.ModelError(f"no accepted step fell into the statistics window [{self.t0}, {self.t1}] s")
        self.sums.close_impacts()
        return run_summary(self.sums, self.plan, self.ref_roller, self._w_rel, self.scene.sun_torque != 0.0,
                           self.flank)


def _at(rows, i: int) -> dict:
    """The reference-roller inputs of ``rows`` at row ``i``."""
    return {k: rows[k][i] for k in ("_roller_angle", "load_x", "load_y")}
