"""What the model outputs (docs/model.md §13), defined once.

Every derived quantity a user reads — a planet bearing's load (pin reaction), roller and cage forces,
each mesh flank's force and deflection, cage accelerations in the carrier frame (own, relative to the
planet, radial/tangential), cage slip, pocket impacts — is computed here, and every statistic of them is
taken here, by :class:`WindowStatistics`, an observer of the one simulation loop (:func:`mbd.simulate`):

* on **every accepted integrator step**, never on recorded samples: means and RMS values are
  time-weighted (trapezoid over the steps), maxima are maxima over the steps, so neither depends on a
  recorder's sample rate;
* over a **window** that the runner sizes with :func:`default_window` (whole revolutions of the slowest
  cage relative to the carrier: every roller passes the load zone equally often);
* the **carrier frame** C turns at the nominal carrier speed (the pin and the load zone are fixed on the
  carrier); *radial* is from the carrier axis through the planet's centre, *tangential* 90° ahead.
  Both are independent of where the planet sits and of the frame the model is integrated in.

The rig's accelerometer on the housing (docs/model.md §12) and its transfer paths are in :mod:`components.sensor`.

Bearing lives (:mod:`components.life` owns the laws): ISO 281's from the bearing load's equivalent
(mean P^(10/3)), and the ISO/TS 16281-style one from every roller's raceway loads, accumulated here as
(Q/Q_c)^4.5 on the pin (stationary relative to the load) and (Q/Q_c)^4 on the bore (rotating).

Element family names come from :mod:`components.families` (re-exported here).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import mbd
from mbd.ad import wrap_angle
from mbd.simulate import ENGINES
from mbd.elements.ehl import thermal_factor

from .accumulate import IMPACT_ROWS, accumulate_steps, warm_accumulators
from .bearing import bearing_kinematics, cage_slip_pct
from .families import FAMILY, MESH_FAMILY
from .life import (LIFE_EXPONENT, ROTATING_EXPONENT, STATIONARY_EXPONENT, equivalent_load, hours, iso281_life,
                   iso281_rating, lundberg_palmgren_life, raceway_ratings, relative_life)
from .lubrication import bearing_film
# the words and units of summary keys: owned by the results module, re-exported here
from .results.summary import DIMENSIONLESS_KEYS, SUMMARY_WORDS, UNIT_SUFFIXES, unit_of_key

__all__ = ["FAMILY", "MESH_FAMILY", "BearingSeries", "LIFE_EXPONENT", "bearing_map", "default_window", "cage_period",
           "WindowStatistics", "carrier_frame_motion", "radial_tangential", "pin_reactions", "relative_life",
           "contact_film", "SUMMARY_WORDS", "UNIT_SUFFIXES", "DIMENSIONLESS_KEYS", "unit_of_key"]



# ----------------------------------------------------------------------------------------------
# which instances belong to which bearing
# ----------------------------------------------------------------------------------------------
def bearing_map(scene) -> list[dict]:
    """Per bearing: name, kind (inner/outer), pair index, planet, cage, and the instance ranges of the
    roller families (all rollers of all bearings share one family each, in bearing order)."""
    out = []
    for n, pair in enumerate(scene.pairs):
        for kind in ("inner", "outer"):
            h, planet = pair.bearing(kind), pair.planet(kind)
            rec = {"name": f"{planet}.pb", "kind": kind, "pair": n, "planet": planet, "type": h.kind}
            if h.kind == "rollers":
                rec.update({"rollers": list(h.rollers), "race_inner": [h.race_inner.start, h.race_inner.stop],
                            "race_outer": [h.race_outer.start, h.race_outer.stop]})
                if h.pocket is not None:
                    rec["pocket"] = [h.pocket.start, h.pocket.stop]
                if h.guide is not None:
                    rec["guide"] = h.guide.start
                if h.cage is not None:
                    rec["cage"] = h.cage
            else:
                rec["spring"] = h.spring.start
            out.append(rec)
    return out


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


# ----------------------------------------------------------------------------------------------
# kinematics in the carrier frame
# ----------------------------------------------------------------------------------------------
def carrier_frame_motion(model, t, q, v, a, omega_c: float, full=None):
    """(x, v, a) of every body, (K, nb, 3) each, at K states (``t`` (K,), ``q``, ``v``, ``a`` (K, n_free)), in the
    frame turning at the nominal carrier speed ``omega_c`` (its orientation at t is immaterial: only lengths
    and projections are read); ``full``: ``model.full_batch(t, q, v)`` if the caller has it."""
    t = np.asarray(t, float)
    K = t.size
    qf, vf = model.full_batch(t, q, v) if full is None else full
    af = np.zeros_like(qf)
    af[:, model.free] = a
    X, V, A = (x.reshape(K, -1, 3) for x in (qf, vf, af))
    fr = model.frame
    if fr.profile is None and fr.omega == omega_c:
        return X, V, A
    Xi, Vi, Ai = mbd.to_fixed(X, V, model.frame_batch(t), A)
    phi = omega_c * t[:, None]
    c, s = np.cos(phi), np.sin(phi)
    rot = lambda x, y: (c * x + s * y, -s * x + c * y)          # Rot(−φ)
    Om = omega_c
    x, y = rot(Xi[..., 0], Xi[..., 1])
    vx, vy = rot(Vi[..., 0], Vi[..., 1])
    vx, vy = vx + Om * y, vy - Om * x                               # v_C = Rot(−φ) v_I − Ω k × x_C
    ax, ay = rot(Ai[..., 0], Ai[..., 1])
    ax, ay = ax + 2 * Om * vy + Om * Om * x, ay - 2 * Om * vx + Om * Om * y   # a_C = Rot(−φ) a_I − 2Ω k × v_C + Ω² x_C
    return (np.stack([x, y, Xi[..., 2] - phi], axis=-1), np.stack([vx, vy, Vi[..., 2] - Om], axis=-1),
            np.stack([ax, ay, Ai[..., 2]], axis=-1))


def pin_reactions(race_inner: dict, rollers, bearing_of_roller, n_bearings: int, rows: int = 1) -> np.ndarray:
    """(..., n_bearings, 2) force each bearing's rollers exert on its pin, in the model's frame: minus the sum
    of the inner-raceway contact forces on the rollers ``rollers`` (instance indices of the race_inner
    family; its ``fx``, ``fy`` (..., n) are per physical roller, so × ``rows``), grouped by ``bearing_of_roller``."""
    fx = np.asarray(race_inner["fx"], float)[..., rollers]
    fy = np.asarray(race_inner["fy"], float)[..., rollers]
    owner = np.asarray(bearing_of_roller)
    S = np.zeros((owner.size, n_bearings))
    S[np.arange(owner.size), owner] = 1.0
    return -rows * np.stack([fx @ S, fy @ S], axis=-1)


def contact_film(race: dict, bearing, lubricant, inner: bool) -> dict[str, np.ndarray]:
    """The EHL film of every contact of one raceway family, from its outputs ``race`` ("load" [N] per
    physical roller, "rolling_speed" [m/s]): :func:`components.lubrication.bearing_film`'s "film_min" h_min
    and "film_central" h_c [m] (Pan & Hamrock, thinned by Murch & Wilson's φ_T), "film_min_isothermal",
    "film_thermal_loading", "film_thermal_factor" and "film_load_parameter", and "film_lambda" Λ = h_min/σ;
    NaN where a roller carries no load. ``bearing``, ``lubricant``: the SI parameter objects; ``inner``:
    the pin's raceway."""
    film = bearing_film(race["load"], race["rolling_speed"], bearing, lubricant, inner)
    return {**film, "film_lambda": film["film_min"] / lubricant.roughness}


def radial_tangential(vec, planet_xy, carrier_xy):
    """(radial, tangential) components of vectors (..., 2): radial from the carrier axis through the
    planet centre, tangential 90° ahead of it (all arrays in one frame, broadcasting over samples)."""
    er = np.asarray(planet_xy, float) - np.asarray(carrier_xy, float)
    er = er / np.linalg.norm(er, axis=-1, keepdims=True)
    vec = np.asarray(vec, float)
    return (vec[..., 0] * er[..., 0] + vec[..., 1] * er[..., 1],
            -vec[..., 0] * er[..., 1] + vec[..., 1] * er[..., 0])


class BearingSeries:
    """Each planet bearing's load (the pin reaction) and its cage's slip at every recorded sample, for results.nc
    (the statistics take every step; these are the histories to plot). The load is split as the statistics split
    it — radial from the carrier axis through the planet, tangential 90° ahead — and the slip is the cage's speed
    below its epicyclic speed, both relative to the carrier, as ``cage_slip_pct``."""

    def __init__(self, scene):
        model = scene.model
        self.bmap = bearing_map(scene)
        idx = lambda name: model.body(name).index
        self.planet = np.array([idx(b["planet"]) for b in self.bmap])
        self.carrier = idx("carrier")
        self.rows = int(scene.bearing.rows)
        self.rollers = self.bmap[0]["type"] == "rollers"
        if self.rollers:
            self.roller_bearing = np.concatenate([np.full(b["race_inner"][1] - b["race_inner"][0], i)
                                                  for i, b in enumerate(self.bmap)])
        else:
            self.spring = np.array([b["spring"] for b in self.bmap])
        self.cage = np.array([idx(b["cage"]) for b in self.bmap]) if self.rollers and "cage" in self.bmap[0] else None
        self.bearing = scene.bearing
        self.names = tuple(b["name"] for b in self.bmap)

    def load(self, t, X, V, A, outputs) -> np.ndarray:
        """(radial, tangential) pin reaction per bearing [N], (2, nb)."""
        if self.rollers:
            pin = pin_reactions(outputs[FAMILY["race_inner"]], slice(None), self.roller_bearing, len(self.bmap), self.rows)
        else:
            lin = outputs[FAMILY["linear"]]
            pin = -np.column_stack([lin["fx"][self.spring], lin["fy"][self.spring]])
        return np.array(radial_tangential(pin, X[self.planet, :2], X[self.carrier, :2]))

    def slip(self, t, X, V, A, outputs) -> np.ndarray:
        """Cage slip per bearing [%] (``cage_slip_pct``'s definition) from the body speeds ``V`` (bodies, 3)."""
        return cage_slip_pct(self.bearing, V[self.cage, 2] - V[self.carrier, 2], V[self.planet, 2] - V[self.carrier, 2])

    def probes(self) -> list:
        where = "radial: from the carrier axis through the planet; tangential 90 deg ahead"
        out = [mbd.DerivedOutput("bearing.load_radial", lambda *a: self.load(*a)[0], "N",
                                 f"planet bearing load (pin reaction), radial component ({where})", instances=self.names),
               mbd.DerivedOutput("bearing.load_tangential", lambda *a: self.load(*a)[1], "N",
                                 f"planet bearing load (pin reaction), tangential component ({where})",
                                 instances=self.names)]
        if self.cage is not None:
            out.append(mbd.DerivedOutput("bearing.cage_slip", self.slip, "percent",
                                         "cage speed below its epicyclic speed, relative to the carrier",
                                         instances=self.names))
        return out


# ----------------------------------------------------------------------------------------------
# the observer
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class _Plan:
    """Index arrays of the bearings (built once at bind): everything a snapshot needs, vectorised."""
    kinds: np.ndarray            # (nb,) "inner" / "outer"
    rollers: bool
    planet: np.ndarray           # body index per bearing
    cage: np.ndarray | None      # body index per bearing (rollers with a cage)
    carrier: int
    roller_bearing: np.ndarray | None   # bearing index of every race_inner instance
    roller_body: np.ndarray | None      # body index of every roller (race_inner order)
    pocket_bearing: np.ndarray | None
    guide: np.ndarray | None     # guide instance per bearing
    spring: np.ndarray | None    # bearing_linear instance per bearing
    rows: int


class WindowStatistics(mbd.Observer):
    """Statistics of a DPGT-like scene from ``t0`` on, on every accepted step (module docstring).

    Window: the mesh quantities cover [t0, t1]. A bearing's quantities (its load, rollers, pockets, cage)
    cover whole revolutions of its cage relative to the carrier, as many as fit in the nominal window,
    ``round((t1 − t0)/T_cage)`` — so they end when that cage has turned that far, not at t1: the cage
    slips (≈ 0.7 % at condition 3) and a nominal window would cut every roller's orbit at a different
    point of the load zone. Run the simulation to :attr:`t_end` (t1 plus a margin for the slip); a cage
    that slips more than the margin ends at the run's end and is reported with whole_revolutions false.

    ``scene``: a :class:`~components.dpgt.PlanetBearingScene` (its pairs, see :func:`bearing_map`; speeds; bearing;
    lubricant; the loaded flank of each mesh type; the sun torque). After the run, :meth:`summary` gives the numbers.
    ``outputs``: what evaluates the element outputs (:func:`mbd.output_evaluator`): "auto" (the compiled kernels),
    "compiled" or "numpy" (the reference kernels, as the tests use them to hold the compiled ones).
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
        self.bmap = bearing_map(scene)
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
        self._lubricant = scene.lubricant       # None: no film statistics (e.g. the bearing rig)
        self._qc = raceway_ratings(scene.bearing)    # (pin, bore) roller contact ratings [N]
        # the planet's speed relative to its pin, per bearing kind: the revolutions a life counts
        self._w_rel = {k: float(sp.planet(k)) - self.omega_c for k in ("inner", "outer")}

    # setup -------------------------------------------------------------------------------------
    def bind(self, model, system, state) -> None:
        self.model, self.system = model, system
        self._outputs = mbd.output_evaluator(system, self.outputs)
        warm_accumulators()      # compiled (or loaded) before the first step, not inside the run's time
        fams = {e.name for e in model.elements}
        bm = self.bmap
        idx = lambda name: model.body(name).index
        rollers = bm[0]["type"] == "rollers"
        b = self.scene.bearing
        cage = np.array([idx(x["cage"]) for x in bm]) if rollers and "cage" in bm[0] else None
        rb = np.concatenate([np.full(x["race_inner"][1] - x["race_inner"][0], i) for i, x in enumerate(bm)]) \
            if rollers else None
        rbody = np.array([idx(r) for x in bm for r in x["rollers"]]) if rollers else None
        pb = np.concatenate([np.full(x["pocket"][1] - x["pocket"][0], i) for i, x in enumerate(bm)]) \
            if rollers and FAMILY["pocket"] in fams else None
        self.plan = _Plan(
            kinds=np.array([x["kind"] for x in bm]), rollers=rollers, planet=np.array([idx(x["planet"]) for x in bm]),
            cage=cage, carrier=idx("carrier"), roller_bearing=rb, roller_body=rbody, pocket_bearing=pb,
            guide=np.array([x["guide"] for x in bm]) if rollers and "guide" in bm[0] else None,
            spring=np.array([x["spring"] for x in bm]) if not rollers else None,
            rows=int(getattr(b, "rows", 1)))
        self.meshes = {k: f for k, f in MESH_FAMILY.items() if f in fams}
        self._families = {FAMILY[k] for k in ("race_inner", "race_outer", "pocket", "guide", "linear")} \
            | set(self.meshes.values())
        # approach-speed floor of the impact law: slower onsets are touches
        self._floor = model.element(FAMILY["pocket"]).v_min * (1.0 + 1e-9) if pb is not None else np.zeros(0)
        self._pocket_owner = pb.astype(np.int64) if pb is not None else np.zeros(0, np.int64)
        if rollers:    # _by_bearing: each bearing's rollers are one run of the race families, all runs equally long
            counts = np.bincount(rb, minlength=len(bm))
            if np.any(np.diff(rb) < 0) or np.any(counts != counts[0]):
                raise mbd.ModelError(f"statistics: every planet bearing needs the same number of rollers, listed "
                                     f"bearing by bearing; got {counts.tolist()} in the order {rb.tolist()}")
        self._target = np.asarray(self.target if self.target is not None else np.zeros(len(bm)), float)
        self.reset()

    def reset(self) -> None:
        nb = self.plan.planet.size
        self._acc, self._flat = {}, None
        self._Tw = np.zeros(nb + 1)                             # time covered by each bearing's window, the global one
        self._angle = np.zeros(nb)                              # cage angle relative to the carrier since t0
        self._open = np.ones(nb, bool)                          # bearing windows still open
        self._t_close = np.full(nb, np.nan)
        self._prev = None
        self.ref_roller = None       # (inner, outer) race_inner instance of the reference rollers
        self._imp = np.zeros((len(IMPACT_ROWS), self._pocket_owner.size))
        self._impact = dict(zip(IMPACT_ROWS, self._imp)) if self._imp.size else None   # row views

    def _owner(self, key: str):
        """Bearing index of each instance of a snapshot quantity, or None for the global window."""
        p = self.plan
        if key.startswith("roller_"):
            return p.roller_bearing
        if key == "pocket_force":
            return p.pocket_bearing
        if key.startswith(("load_", "cage_", "guide_", "planet_", "film_", "heat_", "traction_")):
            return np.arange(p.planet.size)
        return None

    # states -> derived quantities ----------------------------------------------------------------
    def snapshot(self, s) -> dict[str, np.ndarray]:
        """Every derived quantity at state ``s`` (arrays per bearing / roller / mesh): :meth:`snapshots` of one."""
        z = {k: np.asarray(v)[None] for k, v in s.z.items()}
        rows = self.snapshots(np.array([s.t]), s.q[None], s.v[None], s.a[None], z)
        return {k: v[0] for k, v in rows.items()}

    def snapshots(self, t, q, v, a, z) -> dict[str, np.ndarray]:
        """Every derived quantity at K states (``t`` (K,), ``q``, ``v``, ``a`` (K, n), ``z`` {family: (K, ...)}):
        arrays (K, per bearing / roller / mesh), each from vectorised expressions over the K states; until the
        reference rollers are chosen also the rollers' angles about their planets ("_roller_angle")."""
        p, m = self.plan, self.model
        full = m.full_batch(t, q, v)         # once for the outputs and the motion (≈ 2 µs a state)
        out = self._outputs.outputs_batch(t, q, v, z, families=self._families, full=full)
        X, V, A = carrier_frame_motion(m, t, q, v, a, self.omega_c, full=full)
        radial = lambda vec: radial_tangential(vec, X[:, p.planet, :2], X[:, p.carrier, :2][:, None, :])
        K, nb = t.size, p.planet.size
        snap: dict[str, np.ndarray] = {}
        if p.rollers:
            ri, ro = out[FAMILY["race_inner"]], out[FAMILY["race_outer"]]
            pin = pin_reactions(ri, slice(None), p.roller_bearing, nb, p.rows)
            snap["roller_inner_load"] = np.asarray(ri["load"], float)
            snap["roller_outer_load"] = np.asarray(ro["load"], float)
            # Lundberg–Palmgren: (Q/Q_c)^p, the pin stationary and the bore rotating relative to the load
            snap["roller_inner_fatigue"] = (snap["roller_inner_load"] / self._qc[0]) ** STATIONARY_EXPONENT
            snap["roller_outer_fatigue"] = (snap["roller_outer_load"] / self._qc[1]) ** ROTATING_EXPONENT
            snap["heat_traction"], snap["traction_coefficient"] = self._traction_heat(ri, ro)
            if self._lubricant is not None:
                snap.update(self._film(ri, ro))
                snap["film_lambda"] = snap["film_thinnest"] / self._lubricant.roughness
            if p.pocket_bearing is not None:
                snap["pocket_force"] = np.asarray(out[FAMILY["pocket"]]["force"], float)
        else:
            lin = out[FAMILY["linear"]]
            pin = -np.stack([lin["fx"][:, p.spring], lin["fy"][:, p.spring]], axis=-1)   # fx, fy act on the planet
        pin = self._to_carrier(pin, t)
        snap["load_radial"], snap["load_tangential"] = radial(pin)
        snap["load_magnitude"] = np.hypot(pin[..., 0], pin[..., 1])
        snap["load_life"] = snap["load_magnitude"] ** LIFE_EXPONENT
        snap["load_x"], snap["load_y"] = pin[..., 0], pin[..., 1]
        if self.omega_c != 0.0:      # the carrier's speed against its reference: has the drive settled?
            snap["carrier_speed_error"] = (V[:, p.carrier, 2] / self.omega_c)[:, None]
        if p.cage is not None:
            a_own = A[:, p.cage, :2]
            a_rel = a_own - A[:, p.planet, :2]
            snap["cage_acc_radial"], snap["cage_acc_tangential"] = radial(a_own)
            snap["cage_acc_magnitude"] = np.hypot(a_own[..., 0], a_own[..., 1])
            snap["cage_acc_rel_radial"], snap["cage_acc_rel_tangential"] = radial(a_rel)
            snap["cage_acc_rel_magnitude"] = np.hypot(a_rel[..., 0], a_rel[..., 1])
            snap["cage_acc_x"], snap["cage_acc_y"] = a_rel[..., 0], a_rel[..., 1]
            snap["cage_speed_rel"] = V[:, p.cage, 2] - V[:, p.carrier, 2][:, None]
            snap["planet_speed_rel"] = V[:, p.planet, 2] - V[:, p.carrier, 2][:, None]
            if p.guide is not None:
                g = out[FAMILY["guide"]]
                snap["guide_force"] = np.asarray(g["force"], float)[:, p.guide]
                snap["heat_land"] = np.abs(np.asarray(g["friction"], float) * g["sliding_speed"])[:, p.guide]
        for key, fam in self.meshes.items():
            o, f = out[fam], self.flanks.get(key, 1)
            drive, coast = ("", "_coast") if f > 0 else ("_coast", "")
            snap[f"{key}_drive_force"] = np.asarray(o["force" + (drive or "_drive")], float)
            snap[f"{key}_coast_force"] = np.asarray(o["force" + (coast or "_drive")], float)
            snap[f"{key}_drive_deflection"] = np.asarray(o["deflection" + drive], float)
            snap[f"{key}_coast_deflection"] = np.asarray(o["deflection" + coast], float)
        if p.rollers and self.ref_roller is None:    # read only to choose the reference rollers (_accumulate)
            d = X[:, p.roller_body, :2] - X[:, p.planet[p.roller_bearing], :2]
            snap["_roller_angle"] = np.arctan2(d[..., 1], d[..., 0])
        return snap

    def _by_bearing(self, x_inner, x_outer) -> np.ndarray:
        """(K, n_b, 2Z): each bearing's roller contacts, its inner-raceway ones then its outer ones, from a
        quantity of the two race families, ``x_inner``, ``x_outer`` (K, n_b·Z) in race_inner order (reshapes and one
        copy: a fancy-index gather over all contacts cost ≈ 1.4 µs a state per reduction)."""
        K, nb = x_inner.shape[0], self.plan.planet.size
        return np.concatenate([np.reshape(x_inner, (K, nb, -1)), np.reshape(x_outer, (K, nb, -1))], axis=-1)

    def _traction_heat(self, race_inner, race_outer) -> tuple[np.ndarray, np.ndarray]:
        """Per bearing: the power the roller–raceway traction dissipates, Σ |F_t v_s| over every physical
        roller and both raceways [W], and the largest traction coefficient |F_t|/Q of a loaded contact."""
        def heat(r):
            return self.plan.rows * np.abs(np.asarray(r["traction"], float) * np.asarray(r["slip_velocity"], float))

        def coefficient(r):
            Q, Ft = np.asarray(r["load"], float), np.asarray(r["traction"], float)
            return np.where(Q > 0.0, np.abs(Ft) / np.where(Q > 0.0, Q, 1.0), 0.0)

        return (np.sum(self._by_bearing(heat(race_inner), heat(race_outer)), axis=-1),
                np.max(self._by_bearing(coefficient(race_inner), coefficient(race_outer)), axis=-1))

    def _film(self, race_inner, race_outer) -> dict[str, np.ndarray]:
        """Per bearing, over its loaded roller contacts (both raceways): the thinnest EHL film h_min [m] with
        and without the thermal reduction, the thermal loading L of the contact with the thinnest film, the
        largest L and load parameter W' of any, and the smallest h_c/h_min (< 1: Pan & Hamrock's fit beyond
        its range); NaN where no roller is loaded."""
        b, lub = self.scene.bearing, self._lubricant
        fi, fo = (contact_film(race, b, lub, inner) for race, inner in ((race_inner, True), (race_outer, False)))
        f = lambda key: self._by_bearing(fi[key], fo[key])               # (K, n_b, 2Z)
        h_min = f("film_min")
        loaded = ~np.isnan(h_min)

        def extreme(x, low):
            e = (np.min if low else np.max)(np.where(loaded, x, np.inf if low else -np.inf), axis=-1)
            return np.where(np.isfinite(e), e, np.nan)

        first = np.argmin(np.where(loaded, h_min, np.inf), axis=-1)[..., None]      # (K, n_b, 1): thinnest first
        pick = lambda x: np.take_along_axis(x, first, axis=-1)[..., 0]
        with np.errstate(invalid="ignore", divide="ignore"):
            ratio = f("film_central") / h_min
        L = f("film_thermal_loading")
        return {"film_thinnest": extreme(h_min, True),
                "film_thinnest_isothermal": extreme(f("film_min_isothermal"), True),
                "film_thinnest_loading": np.where(pick(loaded), pick(L), np.nan),
                "film_thermal_loading": extreme(L, False),
                "film_load_parameter": extreme(f("film_load_parameter"), False),
                "film_central_ratio": extreme(ratio, True)}

    def _to_carrier(self, vec, t):
        """Vectors (K, n, 2) given in the model's frame R at times ``t`` (K,), in the carrier frame C."""
        fr = self.model.frame
        if fr.profile is None and fr.omega == self.omega_c:
            return vec
        d = self.model.frame_batch(t).phi - self.omega_c * t[:, None]
        c, s = np.cos(d), np.sin(d)
        return np.stack([c * vec[..., 0] - s * vec[..., 1], s * vec[..., 0] + c * vec[..., 1]], axis=-1)

    # accumulation --------------------------------------------------------------------------------
    def _closed(self, t_start) -> bool:
        return t_start >= self.t1 and not self._open.any()

    def step(self, s0, s1) -> None:
        """One accepted step (the numpy engine's path; the compiled engine hands blocks to :meth:`on_block`)."""
        if s1.t <= self.t0 or self._closed(s0.t):
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
        if t[-1] <= self.t0 or self._closed(t[0]):
            return
        i0 = max(int(np.searchsorted(t, self.t0, side="right")) - 1, 0)     # the step that reaches t0 starts here
        t, q, v, a, z = block.arrays()
        rows = self.snapshots(t[i0:], q[i0:], v[i0:], a[i0:], {k: x[i0:] for k, x in z.items()})
        fam = FAMILY["pocket"]
        self._accumulate(t[i0:], rows, z[fam][i0:, :, 0] if fam in z else np.zeros((t.size - i0, 0)))

    def _accumulate(self, t, rows, Z) -> None:
        """Hand K steps (``rows``: each quantity at their K+1 ends; ``Z``: the pockets' stored approach speeds)
        to the accumulators; the first call chooses the reference rollers and lays the accumulators out."""
        if self.ref_roller is None and self.plan.rollers:
            i = int(np.searchsorted(t, self.t0, side="right")) - 1 if t[0] < self.t0 else 0
            i = min(max(i, 0), t.size - 2)
            wa = (max(t[i], self.t0) - t[i]) / (t[i + 1] - t[i])
            self._choose_reference({k: rows[k][i] for k in ("_roller_angle", "load_x", "load_y")},
                                   {k: rows[k][i + 1] for k in ("_roller_angle", "load_x", "load_y")}, wa)
        if self._flat is None:
            self._layout({k: x[-1] for k, x in rows.items()})
        V = np.concatenate([np.asarray(rows[k], float).reshape(t.size, -1) for k in self._keys], axis=1)
        Zf = np.ascontiguousarray(Z, float) if self._imp.size else np.zeros((t.size, 0))
        accumulate_steps(t, V, self._own_flat, self._flat, self._Tw, self._angle, self._open, self._t_close,
                         self._target, self.target is not None, self.t0, self.t1, self._cage_cols,
                         self._pocket_cols, self._pocket_owner, Zf, self._floor, self._imp)
        self._prev = {k: x[-1].copy() for k, x in rows.items()}

    def add_samples(self, rows) -> None:
        """Equally weighted states instead of integrator steps (a static solution's snapshots,
        :mod:`components.static`): ``rows`` as :meth:`snapshots` returns them; each state counts one unit of
        time in every window, so means are plain averages and max/min the extremes over the states."""
        K = len(rows["load_x"])
        if self.ref_roller is None and self.plan.rollers:
            first = {k: rows[k][0] for k in ("_roller_angle", "load_x", "load_y")}
            self._choose_reference(first, first, 0.0)
        if self._flat is None:
            self._layout({k: x[-1] for k, x in rows.items()})
        V = np.concatenate([np.asarray(rows[k], float).reshape(K, -1) for k in self._keys], axis=1)
        self._flat[0] += V.sum(axis=0)
        self._flat[1] += (V * V).sum(axis=0)
        np.maximum(self._flat[2], V.max(axis=0), out=self._flat[2])
        np.minimum(self._flat[3], V.min(axis=0), out=self._flat[3])
        self._Tw += K

    def _layout(self, x) -> None:
        """One flat accumulator (sum, sum of squares, max, min) for every quantity of a snapshot, each
        instance tagged with its bearing (or −1: the global window); ``_acc[key]`` are views into it."""
        keys = [k for k in x if not k.startswith("_")]
        sizes = [np.size(x[k]) for k in keys]
        edges = np.concatenate([[0], np.cumsum(sizes)]).astype(int)
        self._keys = keys
        self._own_flat = np.concatenate([self._owner(k) if self._owner(k) is not None else np.full(n, -1)
                                         for k, n in zip(keys, sizes)]).astype(np.int64)
        if self._flat is None:
            n = int(edges[-1])
            self._flat = np.stack([np.zeros(n), np.zeros(n), np.full(n, -np.inf), np.full(n, np.inf)])
        self._acc = {k: self._flat[:, a:b] for k, a, b in zip(keys, edges[:-1], edges[1:])}
        col = dict(zip(keys, edges[:-1]))
        self._cage_cols = (col["cage_speed_rel"] + np.arange(self.plan.planet.size)).astype(np.int64) \
            if "cage_speed_rel" in col else np.zeros(0, np.int64)
        npk = self._imp.shape[1]
        self._pocket_cols = (col["pocket_force"] + np.arange(npk)).astype(np.int64) if npk else np.zeros(0, np.int64)

    def _choose_reference(self, x0, x1, w):
        """Reference roller of each bearing kind: the roller of pair 1's bearing (index 0) nearest its load-zone
        centre (opposite the pin force: the loaded rollers press the pin away from them) at the window
        start."""
        p = self.plan
        ang = x0["_roller_angle"] + w * (x1["_roller_angle"] - x0["_roller_angle"])
        ref = []
        for kind in ("inner", "outer"):
            i = int(np.flatnonzero(p.kinds == kind)[0])
            Fx = x0["load_x"][i] + w * (x1["load_x"][i] - x0["load_x"][i])
            Fy = x0["load_y"][i] + w * (x1["load_y"][i] - x0["load_y"][i])
            zone = math.atan2(-Fy, -Fx)
            mine = np.flatnonzero(p.roller_bearing == i)
            off = wrap_angle(ang[mine] - zone)
            ref.append(int(mine[np.argmin(np.abs(off))]))
        self.ref_roller = tuple(ref)

    def _close_impacts(self) -> None:
        """Impacts still in progress when their window ended count with the peak they reached."""
        im = self._impact
        if im is None:
            return
        act = im["active"] > 0
        im["peak_sum"] += np.where(act, im["peak_now"], 0.0)
        np.maximum(im["peak_max"], np.where(act, im["peak_now"], 0.0), out=im["peak_max"])
        im["active"][act] = 0.0
        im["peak_now"][act] = 0.0

    # checkpoints ---------------------------------------------------------------------------------
    def state_dict(self) -> dict:
        d = {"acc": self._flat} if self._flat is not None else {}
        d.update({f"imp__{k}": v for k, v in (self._impact or {}).items()})
        d.update({f"prev__{k}": v for k, v in (self._prev or {}).items()})
        d.update({"T_global": np.array(self._Tw[-1]), "T_bearing": self._Tw[:-1], "angle": self._angle,
                  "open": self._open, "t_close": self._t_close,
                  "ref": np.array(self.ref_roller if self.ref_roller is not None else (-1, -1))})
        return d

    def load_state_dict(self, d: dict) -> None:
        self._acc, self._flat = {}, (d["acc"].copy() if "acc" in d else None)
        for k in IMPACT_ROWS:
            if f"imp__{k}" in d:
                self._impact[k][:] = d[f"imp__{k}"]
        self._prev = {k[6:]: v.copy() for k, v in d.items() if k.startswith("prev__")} or None
        if self._flat is not None and self._prev is not None:
            self._layout(self._prev)
        if "T_global" in d:
            self._Tw[:-1], self._Tw[-1] = d["T_bearing"], float(d["T_global"])
            self._angle[:], self._open[:], self._t_close[:] = d["angle"], d["open"].astype(bool), d["t_close"]
        ref = tuple(int(x) for x in d.get("ref", (-1, -1)))
        self.ref_roller = None if ref[0] < 0 else ref

    # results -------------------------------------------------------------------------------------
    def stats(self, key: str) -> dict[str, np.ndarray]:
        """mean, rms, max, min of a snapshot quantity over its window (arrays per instance)."""
        acc = self._acc[key]
        own = self._owner(key)
        T = self._Tw[:-1][own] if own is not None else self._Tw[-1]
        T = np.where(np.asarray(T) > 0, T, np.nan)
        return {"mean": acc[0] / T, "rms": np.sqrt(np.maximum(acc[1], 0.0) / T), "max": acc[2], "min": acc[3]}

    def aggregate_rms(self, key: str, bearings) -> float:
        """RMS of a quantity over every instance that belongs to ``bearings`` (time-weighted, all windows)."""
        own = self._owner(key)
        mine = np.isin(own, bearings)
        T = self._Tw[:-1][own[mine]]
        return float(np.sqrt(self._acc[key][1][mine].sum() / T.sum()))

    @property
    def duration(self) -> float:
        """Length of the global (mesh) window covered so far [s]."""
        return self._Tw[-1]

    def summary(self) -> dict:
        """The statistics users read, per bearing kind (see README: summary.json)."""
        if self.duration <= 0.0:
            raise mbd.ModelError(f"no accepted step fell into the statistics window [{self.t0}, {self.t1}] s")
        self._close_impacts()
        p = self.plan
        out: dict = {"window_s": [self.t0, self.t1], "window_duration_s": self.duration}
        if "carrier_speed_error" in self._acc:
            # the time mean: a settled drive oscillates about its reference (mesh dynamics), an unsettled one is off
            out["carrier_speed_error_mean_pct"] = float(100.0 * self.stats("carrier_speed_error")["mean"][0])
        for kind in ("inner", "outer"):
            sel = np.flatnonzero(p.kinds == kind)
            ref = int(sel[0])
            d: dict = {"window_s": [self.t0, float(self.t0 + self._Tw[:-1][ref])]}
            if self.target is not None:
                d["whole_revolutions"] = bool(not self._open[sel].any())
            lr, lt, lm = self.stats("load_radial"), self.stats("load_tangential"), self.stats("load_magnitude")
            mean_vec = np.hypot(lr["mean"], lt["mean"])
            d["bearing_load_mean_N"] = float(mean_vec[ref])
            d["bearing_load_mean_all_N"] = float(mean_vec[sel].mean())
            # load sharing between the planets of this row (ISO 6336's K_γ: the most loaded over the mean)
            d["bearing_load_mean_per_planet_N"] = [float(x) for x in mean_vec[sel]]
            d["load_sharing_factor"] = float(mean_vec[sel].max() / mean_vec[sel].mean())
            d["bearing_load_radial_mean_N"] = float(lr["mean"][ref])
            d["bearing_load_tangential_mean_N"] = float(lt["mean"][ref])
            d["bearing_load_max_N"] = float(lm["max"][ref])
            d["bearing_load_max_per_planet_N"] = [float(x) for x in lm["max"][sel]]
            d["equivalent_load_N"] = float(self.stats("load_life")["mean"][ref] ** (1.0 / LIFE_EXPONENT))
            if p.rollers:
                self._roller_summary(d, kind, sel)
                self._heat_summary(d, ref, sel)
                if self._lubricant is not None:
                    self._film_summary(d, sel)
            self._life_summary(d, kind, ref, sel)
            if p.cage is not None:
                self._cage_summary(d, ref, sel)
            d["life_L10_relative"] = None     # filled by a study relative to its forward run
            out[kind] = d
        out["meshes"] = self._mesh_summary()
        return out

    def _roller_summary(self, d, kind, sel):
        p = self.plan
        r = self.ref_roller[0 if kind == "inner" else 1]
        mine = np.isin(p.roller_bearing, sel)
        al = {}
        for name, key in (("inner_race", "roller_inner_load"), ("outer_race", "roller_outer_load")):
            st = self.stats(key)
            d[f"roller_{name}_rms_N"] = float(st["rms"][r])
            d[f"roller_{name}_max_N"] = float(st["max"][r])
            d[f"roller_{name}_mean_N"] = float(st["mean"][r])
            al[f"roller_{name}_rms_N"] = self.aggregate_rms(key, sel)
            al[f"roller_{name}_max_N"] = float(st["max"][mine].max())
        mean_loads = self.stats("roller_inner_load")["mean"][p.roller_bearing == p.roller_bearing[r]]
        d["roller_inner_race_mean_spread"] = float((mean_loads.max() - mean_loads.min()) / mean_loads.mean())
        if p.pocket_bearing is not None:
            st = self.stats("pocket_force")
            pk = np.isin(p.pocket_bearing, sel)
            # pocket instances follow the rollers one to one
            d["roller_cage_rms_N"] = float(st["rms"][r])
            d["roller_cage_max_N"] = float(max(st["max"][r], -st["min"][r]))
            al["roller_cage_rms_N"] = self.aggregate_rms("pocket_force", sel)
            al["roller_cage_max_N"] = float(max(st["max"][pk].max(), -st["min"][pk].min()))
            if self._impact is not None:
                im = self._impact
                count = im["count"][pk].sum()
                revs = self._cage_revolutions(sel)
                d["pocket_impacts"] = int(count)
                d["pocket_impacts_per_rev"] = float(count / revs) if revs > 0 else None
                d["pocket_touches_per_rev"] = float(im["touches"][pk].sum() / revs) if revs > 0 else None
                d["pocket_impact_speed_max_m_s"] = float(im["speed_max"][pk].max())
                d["pocket_impact_speed_mean_m_s"] = float(im["speed_sum"][pk].sum() / count) if count else 0.0
                d["pocket_impact_peak_max_N"] = float(im["peak_max"][pk].max())
                d["pocket_impact_peak_mean_N"] = float(im["peak_sum"][pk].sum() / count) if count else 0.0
        d["all_rollers"] = al

    def _life_summary(self, d, kind, ref, sel):
        """ISO 281 L10 from the bearing load and the ISO/TS 16281-style L10 from the roller loads
        (:mod:`components.life`), in 10^6 revolutions of the planet relative to its pin and in hours at the
        nominal relative speed: pair 1's bearing, and in ``all_rollers`` every bearing of this kind pooled."""
        p, b, w = self.plan, self.scene.bearing, self._w_rel[kind]
        d["dynamic_load_rating_N"] = iso281_rating(b)
        cases = [(d, np.array([ref]))]
        if p.rollers:
            cases.append((d["all_rollers"], sel))
        # each planet's own bearing: the most loaded one's life is what unequal load sharing costs
        each = [({}, np.array([i])) for i in sel]
        for out, bearings in cases + each:
            P = float(np.mean(self.stats("load_life")["mean"][bearings]) ** (1.0 / LIFE_EXPONENT))
            out["life_iso281_Mrev"] = iso281_life(P, b)
            out["life_iso281_h"] = hours(out["life_iso281_Mrev"], w)
            if not p.rollers:
                continue
            mine = np.isin(p.roller_bearing, bearings)
            q_pin = self._qc[0] * float(equivalent_load(self.stats("roller_inner_fatigue")["mean"][mine].mean(),
                                                        STATIONARY_EXPONENT))
            q_bore = self._qc[1] * float(equivalent_load(self.stats("roller_outer_fatigue")["mean"][mine].mean(),
                                                         ROTATING_EXPONENT))
            out["roller_equivalent_load_pin_N"], out["roller_equivalent_load_bore_N"] = q_pin, q_bore
            out["life_iso16281_Mrev"] = lundberg_palmgren_life(q_pin, q_bore, b)
            out["life_iso16281_h"] = hours(out["life_iso16281_Mrev"], w)
        d["life_iso281_per_planet_h"] = [e["life_iso281_h"] for e, _ in each]
        if p.rollers:
            d["life_iso16281_per_planet_h"] = [e["life_iso16281_h"] for e, _ in each]

    def _heat_summary(self, d, ref, sel):
        """Heat from traction and land friction (time means, W): the reference bearing's and the mean of its
        kind; the largest traction coefficient of a loaded contact."""
        for key, name in (("heat_traction", "traction"), ("heat_land", "land")):
            if key in (self._keys or ()):
                m = self.stats(key)["mean"]
                d[f"heat_{name}_W"] = float(m[ref])
                d[f"heat_{name}_all_W"] = float(m[sel].mean())
        d["traction_coefficient_max"] = float(self.stats("traction_coefficient")["max"][sel].max())

    def _film_summary(self, d, sel):
        """The thinnest EHL film of the bearings ``sel`` (every bearing of this kind): its smallest value in
        the window and its time mean (the worst bearing's), in metres and as Λ = h_min/σ; the smallest
        isothermal film; the largest thermal loading L at the thinnest film's contact, and of any loaded
        contact with its factor φ_T(L) (the smallest); the largest load parameter W' and the smallest h_c/h_min
        of Pan & Hamrock's fit."""
        h, lam = self.stats("film_thinnest"), self.stats("film_lambda")
        d["film_min_m"] = float(h["min"][sel].min())
        d["film_mean_m"] = float(h["mean"][sel].min())
        d["lambda_min"] = float(lam["min"][sel].min())
        d["lambda_mean"] = float(lam["mean"][sel].min())
        d["film_min_isothermal_m"] = float(self.stats("film_thinnest_isothermal")["min"][sel].min())
        d["film_min_thermal_loading"] = float(self.stats("film_thinnest_loading")["max"][sel].max())
        L = float(self.stats("film_thermal_loading")["max"][sel].max())
        d["film_thermal_loading_max"] = L
        d["film_thermal_factor_min"] = float(thermal_factor(L))      # φ_T falls as L grows
        d["film_load_parameter_max"] = float(self.stats("film_load_parameter")["max"][sel].max())
        d["film_central_ratio_min"] = float(self.stats("film_central_ratio")["min"][sel].min())

    def _cage_revolutions(self, sel) -> float:
        """Cage revolutions relative to the carrier in the windows of the bearings ``sel``, summed."""
        return float(np.abs(self._angle[sel]).sum() / (2 * math.pi))

    def _cage_summary(self, d, ref, sel):
        p = self.plan
        for view in ("", "rel_"):
            for comp in ("radial", "tangential", "magnitude"):
                st = self.stats(f"cage_acc_{view}{comp}")
                d[f"cage_acc_{view}{comp}_rms_m_s2"] = float(st["rms"][ref])
                d[f"cage_acc_{view}{comp}_max_m_s2"] = float(max(st["max"][ref], -st["min"][ref]))
        for comp in ("x", "y"):
            d[f"cage_acc_{comp}_rms_m_s2"] = float(self.stats(f"cage_acc_{comp}")["rms"][ref])
        # every cage of this bearing type: RMS over all their windows (steadier than one cage's)
        d["all_cages"] = {f"cage_acc_{view}{comp}_rms_m_s2": self.aggregate_rms(f"cage_acc_{view}{comp}", sel)
                          for view in ("", "rel_") for comp in ("radial", "tangential", "magnitude")}
        slip = cage_slip_pct(self.scene.bearing, self.stats("cage_speed_rel")["mean"], self.stats("planet_speed_rel")["mean"])
        d["cage_slip_pct"] = float(slip[ref])
        d["cage_slip_all_pct"] = float(slip[sel].mean())
        d["cage_revolutions"] = float(abs(self._angle[ref]) / (2 * math.pi))
        if p.guide is not None:
            st = self.stats("guide_force")
            d["cage_guide_rms_N"] = float(st["rms"][ref])
            d["cage_guide_max_N"] = float(st["max"][ref])
            d["cage_guide_mean_N"] = float(st["mean"][ref])
            d.setdefault("all_rollers", {})["cage_guide_rms_N"] = self.aggregate_rms("guide_force", sel)
            d["all_cages"]["cage_guide_rms_N"] = d["all_rollers"]["cage_guide_rms_N"]

    def _mesh_summary(self) -> dict:
        """Per mesh type, over all planet pairs: mean (average of the pairs) and max of each flank; the loaded
        transmission error's peak-to-peak (the drive flank's compression, max − min over the window) and the
        dynamic factor K_v = max / mean of the drive flank's force (ISO 6336-1's notion, from the run; None when
        the train transmits no torque), the largest of the pairs and per pair."""
        out = {}
        for key in self.meshes:
            d = {"drive_flank": int(self.flanks.get(key, 1))}
            for flank in ("drive", "coast"):
                f, x = self.stats(f"{key}_{flank}_force"), self.stats(f"{key}_{flank}_deflection")
                d[f"{flank}_force_mean_N"] = float(f["mean"].mean())
                d[f"{flank}_force_max_N"] = float(f["max"].max())
                d[f"{flank}_deflection_mean_m"] = float(x["mean"].mean())
                d[f"{flank}_deflection_max_m"] = float(x["max"].max())
                d[f"{flank}_force_mean_per_pair_N"] = [float(y) for y in f["mean"]]
            f, x = self.stats(f"{key}_drive_force"), self.stats(f"{key}_drive_deflection")
            te = x["max"] - x["min"]
            # K_v has no meaning where the train transmits no torque (condition 4): no nominal load to scale
            loaded = self.scene.sun_torque != 0.0
            kv = f["max"] / np.where(loaded & (f["mean"] > 0), f["mean"], np.nan)
            d["te_peak_to_peak_m"] = float(te.max())
            d["te_peak_to_peak_per_pair_m"] = [float(y) for y in te]
            d["dynamic_factor"] = float(np.nanmax(kv)) if np.any(np.isfinite(kv)) else None
            d["dynamic_factor_per_pair"] = [float(y) if np.isfinite(y) else None for y in kv]
            out[key] = d
        return out
