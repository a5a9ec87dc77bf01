"""The per-step quantities the statistics take (docs/model.md §13): pure functions of a block of K states — pin
reactions, roller loads and their fatigue terms, traction heat, the EHL film, pocket and guide forces, cage motion
in the carrier frame, mesh flanks. Nothing here accumulates or remembers: the same states give the same rows.

Frames: the **carrier frame** C turns at the nominal carrier speed (the pin and the load zone are fixed on the
carrier); *radial* is from the carrier axis through the planet's centre, *tangential* 90° ahead. Both are
independent of where the planet sits and of the frame the model is integrated in.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import mbd
from mbd.ad import wrap_angle

from ..bearing import bearing_kinematics, roller_slip_pct
from ..families import FAMILY, MESH_FAMILY
from ..life import LIFE_EXPONENT, ROTATING_EXPONENT, STATIONARY_EXPONENT, raceway_ratings, sliced_raceway_ratings
from ..lubrication import bearing_film, contact_pressure
from .accumulate import power_terms

__all__ = ["bearing_map", "Plan", "plan_of", "owner", "quantities", "carrier_frame_motion", "to_carrier",
           "radial_tangential", "pin_reactions", "contact_film", "traction_heat", "film_extremes",
           "reference_rollers", "slice_quantities", "pin_beam_instances", "pin_bending", "roller_slip_quantities", "CAGE_SPEED", "POCKET_FORCE",
           "ROLLER_LOADED", "ROLLER_SLIP", "ROLLER_PV_PIN"]

# the quantities the accumulators read beyond their sums: the cage speed (its window's revolutions) and the
# pocket force (impact peaks)
CAGE_SPEED, POCKET_FORCE = "cage_speed_rel", "pocket_force"
# the quantities the load-zone entries read (:meth:`.accumulate.Accumulators.add_steps`): a roller loaded on the pin
# (1/0), its slip [%] and its pin contact's p·Δv [W/m²] (the last two not accumulated themselves)
ROLLER_LOADED, ROLLER_SLIP, ROLLER_PV_PIN = "roller_loaded", "_roller_slip", "_roller_pv_pin"


# ----------------------------------------------------------------------------------------------
# which instances belong to which bearing
# ----------------------------------------------------------------------------------------------
def bearing_map(scene) -> list[dict]:
    """Per bearing: name, kind (inner/outer), pair index, planet, cage, and the instance ranges of the
    roller families (all rollers of all bearings share one family each, in bearing order)."""
    out = []
    model = getattr(scene, "model", None)
    n_pin = pin_beam_instances(model) if model is not None else None
    for n, pair in enumerate(scene.pairs):
        for kind in ("inner", "outer"):
            h, planet = pair.bearing(kind), pair.planet(kind)
            rec = {"name": f"{planet}.pb", "kind": kind, "pair": n, "planet": planet, "type": h.kind}
            if h.kind == "rollers":
                rec.update({"rollers": list(h.rollers), "race_inner": [h.race_inner.start, h.race_inner.stop],
                            "race_outer": [h.race_outer.start, h.race_outer.stop]})
                if h.pocket is not None:
                    rec["pocket"] = [h.pocket.start, h.pocket.stop]
                if h.retention is not None:
                    rec["retention"] = [h.retention.start, h.retention.stop]
                if h.guide is not None:
                    rec["guide"] = h.guide.start
                if h.cage is not None:
                    rec["cage"] = h.cage
            else:
                rec["spring"] = h.spring.start
            if n_pin is not None:
                rec["pin_beam"] = n_pin[planet]
            out.append(rec)
    return out


def pin_beam_instances(model) -> dict[str, int] | None:
    """{planet: the instance of the pin beam family (:class:`mbd.elements.tilt.BeamSupport`) holding its pin}, or None:
    rigid pins (no such family). A pin body is named ``<planet>.pin`` (:func:`components.dpgt.add_elastic_pin`)."""
    fam = [e for e in model.elements if e.name == FAMILY["pin_beam"]]
    if not fam:
        return None
    names = [model.body_names[j // 3] for j in fam[0].dofs[:, 3]]
    return {nm[:-len(".pin")]: i for i, nm in enumerate(names)}


def pin_bending(beam) -> dict[str, np.ndarray]:
    """The elastic pin's bending at its bearing's centre from the pin beam's outputs ``beam``: its slope against the
    carrier's pinhole |s| [rad] (the magnitude of the slope pair, frame-independent) and its deflection |d| [m]
    (the beam's own output). The one definition of both, for the statistics and results.nc."""
    return {"slope": np.hypot(np.asarray(beam["slope_x"], float), np.asarray(beam["slope_y"], float)),
            "deflection": np.asarray(beam["deflection"], float)}


@dataclass(frozen=True)
class Plan:
    """What the quantities of one scene's model read, built once (:func:`plan_of`): index arrays of the bearings
    (vectorised over them), the carrier speed, the meshes and the bearing's ratings."""
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
    rows: int                    # physical rollers one roller body stands for (the planar model's folded rows)
    omega_c: float               # nominal carrier speed [rad/s]: the carrier frame's
    meshes: dict                 # mesh type -> its family, those the model has
    flanks: dict                 # mesh type -> its loaded flank (+1/−1)
    bearing: object              # the bearing's SI parameters
    lubricant: object | None     # None: no film (e.g. the bearing rig)
    qc: tuple                    # (pin, bore) roller contact ratings [N]
    families: frozenset          # the element families whose outputs the quantities read
    slices: int = 0              # slices per roller of the sliced contact (0: the planar contact)
    roller_row: np.ndarray | None = None   # row of every race_inner instance (the sliced model's explicit rows)
    explicit_rows: int = 1       # rows built roller by roller (the sliced model: bearing.rows; the planar: 1)
    pin_beam: np.ndarray | None = None     # pin beam instance per bearing (elastic pins; None: rigid pins)


def plan_of(scene, model) -> Plan:
    """The :class:`Plan` of ``scene`` (:func:`bearing_map`; speeds; bearing; lubricant; flanks) on its built model."""
    bm = bearing_map(scene)
    fams = {e.name for e in model.elements}
    idx = lambda name: model.body(name).index
    rollers = bm[0]["type"] == "rollers"
    b = scene.bearing
    rb = np.concatenate([np.full(x["race_inner"][1] - x["race_inner"][0], i) for i, x in enumerate(bm)]) \
        if rollers else None
    if rollers:    # _by_bearing: each bearing's rollers are one run of the race families, all runs equally long
        counts = np.bincount(rb, minlength=len(bm))
        if np.any(np.diff(rb) < 0) or np.any(counts != counts[0]):
            raise mbd.ModelError(f"statistics: every planet bearing needs the same number of rollers, listed "
                                 f"bearing by bearing; got {counts.tolist()} in the order {rb.tolist()}")
    meshes = {k: f for k, f in MESH_FAMILY.items() if f in fams}
    sliced = rollers and getattr(b, "model", "planar") == "sliced"
    explicit = int(b.rows) if sliced else 1          # the sliced model builds every row; the planar folds them
    roller_row = (np.tile(np.repeat(np.arange(explicit), counts[0] // explicit), len(bm)) if rollers else None)
    return Plan(
        kinds=np.array([x["kind"] for x in bm]), rollers=rollers, planet=np.array([idx(x["planet"]) for x in bm]),
        cage=np.array([idx(x["cage"]) for x in bm]) if rollers and "cage" in bm[0] else None,
        carrier=idx("carrier"), roller_bearing=rb,
        roller_body=np.array([idx(r) for x in bm for r in x["rollers"]]) if rollers else None,
        pocket_bearing=np.concatenate([np.full(x["pocket"][1] - x["pocket"][0], i) for i, x in enumerate(bm)])
        if rollers and FAMILY["pocket"] in fams else None,
        guide=np.array([x["guide"] for x in bm]) if rollers and "guide" in bm[0] else None,
        spring=np.array([x["spring"] for x in bm]) if not rollers else None,
        rows=1 if sliced else int(getattr(b, "rows", 1)), omega_c=float(scene.speeds.carrier),
        meshes=meshes, flanks=dict(scene.flanks), bearing=b, lubricant=scene.lubricant, qc=raceway_ratings(b),
        families=frozenset({FAMILY[k] for k in ("race_inner", "race_outer", "pocket", "guide", "linear", "pin_beam")}
                           | set(meshes.values())),
        slices=int(b.slicing.slices) if sliced else 0, roller_row=roller_row, explicit_rows=explicit,
        pin_beam=np.array([x["pin_beam"] for x in bm]) if "pin_beam" in bm[0] else None)


def owner(p: Plan, key: str):
    """Bearing index of each instance of the quantity ``key``, or None: a mesh quantity (the global window)."""
    if key.startswith("roller_"):
        return p.roller_bearing
    if key.startswith("slice_"):           # per roller and slice, roller by roller
        return np.repeat(p.roller_bearing, p.slices)
    if key == POCKET_FORCE:
        return p.pocket_bearing
    if key.startswith(("load_", "cage_", "guide_", "planet_", "film_", "heat_", "traction_", "pin_")):
        return np.arange(p.planet.size)
    return None


# ----------------------------------------------------------------------------------------------
# every quantity of K states
# ----------------------------------------------------------------------------------------------
def quantities(p: Plan, model, evaluator, t, q, v, a, z, roller_angles: bool) -> dict[str, np.ndarray]:
    """Every per-step quantity at K states (``t`` (K,), ``q``, ``v``, ``a`` (K, n), ``z`` {family: (K, ...)}):
    arrays (K, per bearing / roller / mesh), from vectorised expressions over the K states; ``evaluator`` gives
    the element outputs (:func:`mbd.output_evaluator`); ``roller_angles``: also the rollers' angles about their
    planets ("_roller_angle", read only to choose the reference rollers)."""
    full = model.full_batch(t, q, v)         # once for the outputs and the motion (≈ 2 µs a state)
    out = evaluator.outputs_batch(t, q, v, z, families=p.families, full=full)
    X, V, A = carrier_frame_motion(model, t, q, v, a, p.omega_c, full=full)
    snap: dict[str, np.ndarray] = roller_quantities(p, out) if p.rollers else {}
    if p.rollers:
        snap.update(roller_slip_quantities(p, out, V))
    snap.update(load_quantities(p, model, t, out, X))
    if p.omega_c != 0.0:      # the carrier's speed against its reference: has the drive settled?
        snap["carrier_speed_error"] = (V[:, p.carrier, 2] / p.omega_c)[:, None]
    if p.cage is not None:
        snap.update(cage_quantities(p, out, X, V, A))
    snap.update(mesh_quantities(p, out))
    if p.pin_beam is not None:      # elastic pins (bearing.pin.model = "elastic", docs/model.md §8.8)
        bend = pin_bending(out[FAMILY["pin_beam"]])
        snap["pin_slope"], snap["pin_deflection"] = bend["slope"][:, p.pin_beam], bend["deflection"][:, p.pin_beam]
    if p.rollers and roller_angles:
        d = X[:, p.roller_body, :2] - X[:, p.planet[p.roller_bearing], :2]
        snap["_roller_angle"] = np.arctan2(d[..., 1], d[..., 0])
    return snap


def roller_quantities(p: Plan, out) -> dict[str, np.ndarray]:
    """Per roller: raceway loads and their Lundberg–Palmgren terms (Q/Q_c)^e, the pin stationary and the bore
    rotating relative to the load; per bearing: traction heat and coefficient, the film; per pocket: its force."""
    ri, ro = out[FAMILY["race_inner"]], out[FAMILY["race_outer"]]
    snap = {"roller_inner_load": np.asarray(ri["load"], float), "roller_outer_load": np.asarray(ro["load"], float)}
    snap["roller_inner_fatigue"] = (snap["roller_inner_load"] / p.qc[0]) ** STATIONARY_EXPONENT
    snap["roller_outer_fatigue"] = (snap["roller_outer_load"] / p.qc[1]) ** ROTATING_EXPONENT
    snap["heat_traction"], snap["traction_coefficient"] = traction_heat(ri, ro, p.planet.size, p.rows)
    if p.lubricant is not None:
        snap.update(film_extremes(ri, ro, p.bearing, p.lubricant, p.planet.size))
        snap["film_lambda"] = snap["film_thinnest"] / p.lubricant.roughness
    if p.pocket_bearing is not None:
        snap[POCKET_FORCE] = np.asarray(out[FAMILY["pocket"]]["force"], float)
    if "max_slice_load" in ri:            # the sliced contact (bearing.model = "sliced", docs/model.md §8.8)
        snap.update(slice_quantities(p, ri, ro))
    return snap


def roller_slip_quantities(p: Plan, out, V) -> dict[str, np.ndarray]:
    """Per roller: loaded on the pin or not (``roller_loaded``, 1/0: the load zone; the bore carries every roller's
    centrifugal load all round), its slip (:func:`components.bearing.roller_slip_pct`, speeds relative to the
    carrier from the carrier-frame speeds ``V``) split into the load zone and out of it (``roller_slip_loaded``,
    ``roller_slip_unloaded``: slip × 1/0, whose time integrals over the loaded time are the zones' means), and the
    frictional power density p·Δv [W/m²] of its contacts — the Hertz peak pressure of the contact
    (:func:`components.lubrication.contact_pressure`) times its sliding speed — the larger of pin and bore
    (``roller_pv``); the slip itself and the pin's p·Δv for the load-zone entries (not accumulated)."""
    ri, ro = out[FAMILY["race_inner"]], out[FAMILY["race_outer"]]
    w_c = V[:, p.carrier, 2][:, None]
    slip = roller_slip_pct(p.bearing, V[:, p.roller_body, 2] - w_c, V[:, p.planet[p.roller_bearing], 2] - w_c)
    loaded = (np.asarray(ri["load"], float) > 0.0).astype(float)
    pv = {inner: contact_pressure(r["load"], p.bearing, inner) * np.abs(np.asarray(r["slip_velocity"], float))
          for inner, r in ((True, ri), (False, ro))}
    return {ROLLER_LOADED: loaded, "roller_slip_loaded": slip * loaded, "roller_slip_unloaded": slip * (1.0 - loaded),
            "roller_pv": np.maximum(pv[True], pv[False]), ROLLER_SLIP: slip, ROLLER_PV_PIN: pv[True]}


def slice_quantities(p: Plan, ri, ro) -> dict[str, np.ndarray]:
    """Per roller: its largest slice load on each raceway, its pin contact's larger end-slice load and middle-slice
    load; per bearing: the misalignment it sees, |σ_pin − σ_bore| [rad] (the pin's and the bore's slopes, read at
    its first roller: every roller of a bearing sees the same two)."""
    snap = {"roller_inner_slice_max": np.asarray(ri["max_slice_load"], float),
            "roller_outer_slice_max": np.asarray(ro["max_slice_load"], float),
            "roller_inner_edge_load": np.asarray(ri["edge_load"], float),
            "roller_inner_mid_load": np.asarray(ri["mid_load"], float)}
    first = np.searchsorted(p.roller_bearing, np.arange(p.planet.size))
    dx = np.asarray(ri["race_slope_x"], float)[..., first] - np.asarray(ro["race_slope_x"], float)[..., first]
    dy = np.asarray(ri["race_slope_y"], float)[..., first] - np.asarray(ro["race_slope_y"], float)[..., first]
    snap["planet_misalignment"] = np.hypot(dx, dy)
    # per roller and slice, the ISO/TS 16281 slice terms (q_k/q_c,k)^e (pin stationary, bore rotating relative to the
    # load, as the roller loads' life): (K, rollers·n_s), roller by roller
    qc = sliced_raceway_ratings(p.bearing, p.slices)
    for race, out, e, c in (("inner", ri, STATIONARY_EXPONENT, qc[0]), ("outer", ro, ROTATING_EXPONENT, qc[1])):
        q = np.stack([np.asarray(out[f"slice_load_{k}"], float) for k in range(p.slices)], axis=-1)
        q = q.reshape(q.shape[:-2] + (-1,))
        terms = np.empty_like(q)
        power_terms(q.reshape(-1), c, e, terms.reshape(-1))          # (q/c)^e, compiled
        snap[f"slice_{race}_fatigue"] = terms
        snap[f"_slice_{race}"] = q     # the loads: the peak profile (not accumulated)
    return snap


def load_quantities(p: Plan, model, t, out, X) -> dict[str, np.ndarray]:
    """Per bearing, its load (the pin reaction) in the carrier frame: radial, tangential, magnitude, x, y, and
    its ISO 281 term |F|^(10/3)."""
    if p.rollers:
        pin = pin_reactions(out[FAMILY["race_inner"]], slice(None), p.roller_bearing, p.planet.size, p.rows)
    else:
        lin = out[FAMILY["linear"]]
        pin = -np.stack([lin["fx"][:, p.spring], lin["fy"][:, p.spring]], axis=-1)   # fx, fy act on the planet
    pin = to_carrier(model, pin, t, p.omega_c)
    snap = dict(zip(("load_radial", "load_tangential"), radial(p, X, pin)))
    snap["load_magnitude"] = np.hypot(pin[..., 0], pin[..., 1])
    snap["load_life"] = snap["load_magnitude"] ** LIFE_EXPONENT
    snap["load_x"], snap["load_y"] = pin[..., 0], pin[..., 1]
    return snap


def cage_quantities(p: Plan, out, X, V, A) -> dict[str, np.ndarray]:
    """Per cage, in the carrier frame: its acceleration (own and relative to its planet; radial, tangential,
    magnitude; the relative one's x, y), its speed and the planet's relative to the carrier; guide-land force
    and friction heat."""
    a_own = A[:, p.cage, :2]
    a_rel = a_own - A[:, p.planet, :2]
    snap = {}
    snap["cage_acc_radial"], snap["cage_acc_tangential"] = radial(p, X, a_own)
    snap["cage_acc_magnitude"] = np.hypot(a_own[..., 0], a_own[..., 1])
    snap["cage_acc_rel_radial"], snap["cage_acc_rel_tangential"] = radial(p, X, a_rel)
    snap["cage_acc_rel_magnitude"] = np.hypot(a_rel[..., 0], a_rel[..., 1])
    snap["cage_acc_x"], snap["cage_acc_y"] = a_rel[..., 0], a_rel[..., 1]
    snap[CAGE_SPEED] = V[:, p.cage, 2] - V[:, p.carrier, 2][:, None]
    snap["planet_speed_rel"] = V[:, p.planet, 2] - V[:, p.carrier, 2][:, None]
    if p.guide is not None:
        g = out[FAMILY["guide"]]
        snap["guide_force"] = np.asarray(g["force"], float)[:, p.guide]
        snap["heat_land"] = np.abs(np.asarray(g["friction"], float) * g["sliding_speed"])[:, p.guide]
    return snap


def mesh_quantities(p: Plan, out) -> dict[str, np.ndarray]:
    """Per mesh type and planet pair: force and deflection of the drive flank (the loaded one, ``p.flanks``) and
    of the coast flank."""
    snap = {}
    for key, fam in p.meshes.items():
        o, f = out[fam], p.flanks.get(key, 1)
        drive, coast = ("", "_coast") if f > 0 else ("_coast", "")
        snap[f"{key}_drive_force"] = np.asarray(o["force" + (drive or "_drive")], float)
        snap[f"{key}_coast_force"] = np.asarray(o["force" + (coast or "_drive")], float)
        snap[f"{key}_drive_deflection"] = np.asarray(o["deflection" + drive], float)
        snap[f"{key}_coast_deflection"] = np.asarray(o["deflection" + coast], float)
    return snap


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
    X, V, A = (model.body_poses(x) for x in (qf, vf, af))          # (K, nb, 3): tilt coordinates left out
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


def to_carrier(model, vec, t, omega_c: float):
    """Vectors (K, n, 2) given in the model's frame R at times ``t`` (K,), in the carrier frame C."""
    fr = model.frame
    if fr.profile is None and fr.omega == omega_c:
        return vec
    d = model.frame_batch(t).phi - omega_c * t[:, None]
    c, s = np.cos(d), np.sin(d)
    return np.stack([c * vec[..., 0] - s * vec[..., 1], s * vec[..., 0] + c * vec[..., 1]], axis=-1)


def radial_tangential(vec, planet_xy, carrier_xy):
    """(radial, tangential) components of vectors (..., 2): radial from the carrier axis through the
    planet centre, tangential 90° ahead of it (all arrays in one frame, broadcasting over samples)."""
    er = np.asarray(planet_xy, float) - np.asarray(carrier_xy, float)
    er = er / np.linalg.norm(er, axis=-1, keepdims=True)
    vec = np.asarray(vec, float)
    return (vec[..., 0] * er[..., 0] + vec[..., 1] * er[..., 1],
            -vec[..., 0] * er[..., 1] + vec[..., 1] * er[..., 0])


def radial(p: Plan, X, vec):
    """:func:`radial_tangential` of per-bearing vectors (K, nb, 2) about each bearing's planet, positions ``X``."""
    return radial_tangential(vec, X[:, p.planet, :2], X[:, p.carrier, :2][:, None, :])


# ----------------------------------------------------------------------------------------------
# forces, heat, film
# ----------------------------------------------------------------------------------------------
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


def by_bearing(x_inner, x_outer, n_bearings: int) -> np.ndarray:
    """(K, n_b, 2Z): each bearing's roller contacts, its inner-raceway ones then its outer ones, from a
    quantity of the two race families, ``x_inner``, ``x_outer`` (K, n_b·Z) in race_inner order (reshapes and one
    copy: a fancy-index gather over all contacts cost ≈ 1.4 µs a state per reduction)."""
    K = x_inner.shape[0]
    return np.concatenate([np.reshape(x_inner, (K, n_bearings, -1)), np.reshape(x_outer, (K, n_bearings, -1))],
                          axis=-1)


def traction_heat(race_inner, race_outer, n_bearings: int, rows: int) -> tuple[np.ndarray, np.ndarray]:
    """Per bearing: the power the roller–raceway traction dissipates, Σ |F_t v_s| over every physical
    roller (``rows`` per roller body) and both raceways [W], and the largest traction coefficient |F_t|/Q of a
    loaded contact."""
    def heat(r):
        return rows * np.abs(np.asarray(r["traction"], float) * np.asarray(r["slip_velocity"], float))

    def coefficient(r):
        Q, Ft = np.asarray(r["load"], float), np.asarray(r["traction"], float)
        return np.where(Q > 0.0, np.abs(Ft) / np.where(Q > 0.0, Q, 1.0), 0.0)

    return (np.sum(by_bearing(heat(race_inner), heat(race_outer), n_bearings), axis=-1),
            np.max(by_bearing(coefficient(race_inner), coefficient(race_outer), n_bearings), axis=-1))


def contact_film(race: dict, bearing, lubricant, inner: bool) -> dict[str, np.ndarray]:
    """The EHL film of every contact of one raceway family, from its outputs ``race`` ("load" [N] per
    physical roller, "rolling_speed" [m/s]): :func:`components.lubrication.bearing_film`'s "film_min" h_min
    and "film_central" h_c [m] (Pan & Hamrock, thinned by Murch & Wilson's φ_T), "film_min_isothermal",
    "film_thermal_loading", "film_thermal_factor" and "film_load_parameter", and "film_lambda" Λ = h_min/σ;
    NaN where a roller carries no load. ``bearing``, ``lubricant``: the SI parameter objects; ``inner``:
    the pin's raceway."""
    film = bearing_film(race["load"], race["rolling_speed"], bearing, lubricant, inner)
    return {**film, "film_lambda": film["film_min"] / lubricant.roughness}


def film_extremes(race_inner, race_outer, bearing, lubricant, n_bearings: int) -> dict[str, np.ndarray]:
    """Per bearing, over its loaded roller contacts (both raceways): the thinnest EHL film h_min [m] with
    and without the thermal reduction, the thermal loading L of the contact with the thinnest film, the
    largest L and load parameter W' of any, and the smallest h_c/h_min (< 1: Pan & Hamrock's fit beyond
    its range); NaN where no roller is loaded."""
    fi, fo = (contact_film(race, bearing, lubricant, inner)
              for race, inner in ((race_inner, True), (race_outer, False)))
    f = lambda key: by_bearing(fi[key], fo[key], n_bearings)               # (K, n_b, 2Z)
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


# ----------------------------------------------------------------------------------------------
# reference rollers
# ----------------------------------------------------------------------------------------------
def reference_rollers(p: Plan, x0, x1, w) -> tuple[int, int]:
    """Reference roller of each bearing kind (race_inner instances): the roller of pair 1's bearing (index 0)
    nearest its load-zone centre (opposite the pin force: the loaded rollers press the pin away from them) at
    the fraction ``w`` between the quantities ``x0`` and ``x1`` ("_roller_angle", "load_x", "load_y")."""
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
    return tuple(ref)
