"""What a DPGT ``results.nc`` holds, in words and units: the one table the runner records from.

* :data:`OUTPUTS` — per element family, the output keys the runner records with their CF units and
  long names (from the element docstrings in ``mbd/elements``: contact.py, gear_mesh.py, drives.py,
  springs.py). Forces are per physical roller (one row), vectors are in the reference frame R.
* :data:`PIN_OUTPUTS` — the elastic pins' bending slope magnitude and deflection, recorded along the pin beam
  family when the pins are elastic (computed by :func:`components.statistics.quantities.pin_bending`).
* :data:`FILM_OUTPUTS` — the EHL film of every roller–raceway contact, recorded along the raceway
  families when the scene has a lubricant (computed by :func:`components.outputs.contact_film`).
* :func:`instance_coords` — per family, which bearing / roller / planet / mesh each instance is
  (from ``scene.pairs`` and :func:`components.outputs.bearing_map`).
* :func:`element_probes` — the :class:`mbd.ElementOutput` probes carrying both.
* :func:`drawing_geometry` — the gears' and bearings' drawing geometry, stored as the file's ``geometry``.

Body motion ("motion": all bodies in R; "fixed": sun, carrier, ring in the fixed frame) is described
by the recorder itself (:mod:`mbd.recorder`): ``<probe>.position`` [m], ``.angle`` [rad],
``.velocity`` [m/s], ``.angular_velocity`` [rad/s], ``.acceleration`` [m/s^2],
``.angular_acceleration`` [rad/s^2].
"""
from __future__ import annotations

from functools import partial

import numpy as np

from mbd import ElementOutput

from ..families import FAMILY, MESH_FAMILY
from ..outputs import bearing_map, contact_film
from ..statistics.quantities import pin_bending

__all__ = ["OUTPUTS", "FILM_OUTPUTS", "PIN_OUTPUTS", "MESH_WORDS", "instance_coords", "element_probes", "drawing_geometry",
           "loaded_transmission_error"]

MESH_WORDS = {MESH_FAMILY["sun_inner"]: "sun–inner planet mesh",
              MESH_FAMILY["inner_outer"]: "inner planet–outer planet mesh",
              MESH_FAMILY["outer_ring"]: "outer planet–ring mesh"}


def _mesh(words: str) -> dict:
    # the element names flank f = +1 "drive" and f = −1 "coast"; which one the torque path loads depends on
    # the direction (summary.json meshes.<type>.drive_flank), so the file says flank +1 / −1
    return {"force": ("N", f"{words} force, flank +1 minus flank −1"),
            "force_drive": ("N", f"{words} flank +1 force"),
            "force_coast": ("N", f"{words} flank −1 force"),
            "deflection": ("m", f"{words} flank +1 deflection (< 0: a gap)"),
            "deflection_coast": ("m", f"{words} flank −1 deflection (< 0: a gap)"),
            "fx": ("N", f"{words} force on the second gear, x in R"),
            "fy": ("N", f"{words} force on the second gear, y in R")}


# family -> {output key: (units, long_name)}; the keys listed are the ones the runner records
OUTPUTS = {
    FAMILY["race_inner"]: {
        "load": ("N", "roller–inner race contact load"),
        "fx": ("N", "roller–inner race force on the roller, x in R"),
        "fy": ("N", "roller–inner race force on the roller, y in R"),
        "angle": ("rad", "roller angle about the pin centre, in pin axes"),
        "deflection": ("m", "roller–inner race contact deflection (< 0: a gap)")},
    FAMILY["race_outer"]: {
        "load": ("N", "roller–outer race contact load"),
        "fx": ("N", "roller–outer race force on the roller, x in R"),
        "fy": ("N", "roller–outer race force on the roller, y in R")},
    FAMILY["pocket"]: {
        "force": ("N", "roller–cage pocket force (> 0: the roller pushes the cage forward)"),
        "offset": ("m", "roller circumferential offset in its cage pocket")},
    FAMILY["retention"]: {
        "force": ("N", "roller–cage pocket radial retention force of a roller-centred cage (> 0: the roller presses "
                       "the cage outwards)"),
        "offset": ("m", "roller radial offset from the cage's pitch circle")},
    FAMILY["guide"]: {
        "force": ("N", "cage–guide land normal force"),
        "fx": ("N", "cage–guide land force on the cage, x in R"),
        "fy": ("N", "cage–guide land force on the cage, y in R"),
        "eccentricity": ("m", "cage centre eccentricity relative to the planet bore")},
    FAMILY["linear"]: {
        "fx": ("N", "linear planet bearing force on the planet, x in R"),
        "fy": ("N", "linear planet bearing force on the planet, y in R")},
    **{f: _mesh(w) for f, w in MESH_WORDS.items()},
    "carrier_drive": {"torque": ("N m", "carrier speed-drive torque on the carrier")},
    FAMILY["pin_beam"]: {
        "slope_x": ("rad", "elastic pin's bending slope against its pinhole at the bearing's centre, x in R"),
        "slope_y": ("rad", "elastic pin's bending slope against its pinhole at the bearing's centre, y in R"),
        "fx": ("N", "carrier's force on the elastic pin at the bearing's centre, x in R"),
        "fy": ("N", "carrier's force on the elastic pin at the bearing's centre, y in R")},
}

# the elastic pins' bending (components.statistics.quantities.pin_bending, the statistics' definition), recorded along
# the pin beam family: key -> (units, long_name)
PIN_OUTPUTS = {"slope": ("rad", "elastic pin's bending slope magnitude against its pinhole at the bearing's centre"),
               "deflection": ("m", "elastic pin's deflection from its pinhole at the bearing's centre")}


def _film(race: str) -> dict:
    where = f"roller–{race} race contact"
    return {"film_min": ("m", f"EHL minimum film thickness h_min of the {where} (Pan–Hamrock × φ_T; NaN: no load)"),
            "film_central": ("m", f"EHL central film thickness h_c of the {where} (Pan–Hamrock × φ_T; NaN: no load)"),
            "film_lambda": ("1", f"film parameter Λ = h_min/σ of the {where} (NaN: no load)"),
            "film_thermal_factor": ("1", f"thermal reduction φ_T (Murch–Wilson) in h_min and h_c of the {where}: "
                                         "isothermal film = film / φ_T (NaN: no load)")}


# the film of each raceway family (recorded when the scene has a lubricant): family -> (inner raceway?, keys)
FILM_OUTPUTS = {FAMILY["race_inner"]: (True, _film("inner")), FAMILY["race_outer"]: (False, _film("outer"))}

_BEARING_COORDS = {  # coordinate -> (long_name, field of the bearing_map record)
    "bearing": ("planet bearing name", "name"),
    "planet": ("planet the bearing carries", "planet"),
    "pair": ("planet pair index from 0 (index n is pair n+1, planets a{n+1} and b{n+1})", "pair"),
    "bearing_kind": ("bearing of the inner (a) or outer (b) planet of the pair", "kind"),
}


def instance_coords(scene) -> dict[str, dict[str, tuple[str, list]]]:
    """family -> {coordinate: (long_name, one value per instance)}; "instance" names each instance
    ("a1.pb.roller3", "a1.pb.cage", "a1.pb", "sun-a1", "carrier")."""
    rows: dict[str, dict[int, dict]] = {}

    def put(fam, i, **vals):
        rows.setdefault(fam, {})[i] = vals

    for b in bearing_map(scene):
        base = {c: b[field] for c, (_, field) in _BEARING_COORDS.items()}
        if b["type"] == "rollers":
            for fam in ("race_inner", "race_outer", "pocket", "retention"):
                if fam in b:
                    start, stop = b[fam]
                    for j, i in enumerate(range(start, stop)):
                        put(FAMILY[fam], i, instance=b["rollers"][j], **base, roller=j)
            if "guide" in b:
                put(FAMILY["guide"], b["guide"], instance=f"{b['name']}.cage", **base)
        else:
            put(FAMILY["linear"], b["spring"], instance=b["name"], **base)
        if "pin_beam" in b:
            put(FAMILY["pin_beam"], b["pin_beam"], instance=f"{b['planet']}.pin", **base)
    for n, pair in enumerate(scene.pairs):
        gears = {"sun_inner": ("sun", pair.inner), "inner_outer": (pair.inner, pair.outer),
                 "outer_ring": (pair.outer, "ring")}
        for key, (g1, g2) in gears.items():
            put(MESH_FAMILY[key], n, instance=f"{g1}-{g2}", pair=n, gear1=g1, gear2=g2)
    put("carrier_drive", 0, instance="carrier")

    words = {"instance": "instance name", **{c: w for c, (w, _) in _BEARING_COORDS.items()},
             "roller": "roller index in its bearing (pocket j at angle 2πj/Z in cage axes)",
             "gear1": "first gear of the mesh", "gear2": "second gear of the mesh (fx, fy act on it)"}
    out = {}
    for fam, by_index in rows.items():
        recs = [by_index[i] for i in sorted(by_index)]
        if sorted(by_index) != list(range(len(recs))):
            raise ValueError(f"family {fam!r}: instances {sorted(by_index)} do not cover 0..n-1")
        names = [k for k in recs[0]]
        if fam in MESH_WORDS:
            words_f = dict(words, instance=f"{MESH_WORDS[fam]} name (first gear-second gear)")
        else:
            words_f = dict(words, instance={FAMILY["guide"]: "cage name", FAMILY["linear"]: "planet bearing name",
                                            FAMILY["pin_beam"]: "elastic pin name",
                                            "carrier_drive": "driven body"}.get(fam, "roller name"))
        out[fam] = {k: (words_f[k], [r[k] for r in recs]) for k in names}
    return out


def loaded_transmission_error(outputs, flank: int) -> dict:
    """The loaded transmission error of a mesh family's instances: the compression of the flank the torque
    path loads (``flank`` = ±1) along its line of action [m] — 0 where perfect rigid teeth touch, the
    elastic deflection plus the teeth's deviations under load, < 0 while that flank is open."""
    return {"transmission_error": np.asarray(outputs["deflection" if flank > 0 else "deflection_coast"], float)}


def element_probes(scene) -> list[ElementOutput]:
    """The element outputs the runner records: every family of :data:`OUTPUTS` the scene has, with
    units, long names and instance coordinates; with a lubricant (``scene.lubricant``), the
    raceway families' film (:data:`FILM_OUTPUTS`) as well; for every mesh its loaded transmission error
    (:func:`loaded_transmission_error`, from the flank ``scene.flanks`` says the torque loads)."""
    fams = {e.name for e in scene.model.elements}
    coords = instance_coords(scene)
    lub = scene.lubricant
    flanks = {MESH_FAMILY[k]: f for k, f in scene.flanks.items()}
    probes = []
    for f, meta in OUTPUTS.items():
        if f not in fams:
            continue
        derived = None
        if lub is not None and f in FILM_OUTPUTS:
            inner, film = FILM_OUTPUTS[f]
            meta = {**meta, **film}
            derived = partial(contact_film, bearing=scene.bearing, lubricant=lub, inner=inner)
        if f == FAMILY["pin_beam"]:
            meta = {**meta, **PIN_OUTPUTS}
            derived = pin_bending
        if f in flanks:
            meta = {**meta, "transmission_error": (
                "m", f"{MESH_WORDS[f]} loaded transmission error: compression of the drive flank (flank "
                     f"{flanks[f]:+d}, the one the torque path loads) along its line of action (0: perfect rigid "
                     "teeth touching; < 0: that flank open)")}
            derived = partial(loaded_transmission_error, flank=flanks[f])
        # every derived quantity here is elementwise over the samples: a block's samples at once
        probes.append(ElementOutput(f, list(meta), meta=meta, instances=coords.get(f), derived=derived,
                                    batched=True))
    return probes


def drawing_geometry(params) -> dict:
    """Drawing geometry of a :class:`components.params.DPGTParams`, SI floats, JSON-safe.

    The runner stores it in the results file's ``geometry`` attribute, so that viz needs nothing but
    the file to draw a run."""
    si = params.si()
    G, B, lay = si.gears, si.bearing, si.layout
    parts = {"sun": G.sun, "inner_planet": G.inner_planet, "outer_planet": G.outer_planet, "ring": G.ring}
    return {
        "module": float(G.sun.module),
        "teeth": {k: int(g.teeth) for k, g in parts.items()},
        "pitch_radius": {k: float(g.pitch_radius) for k, g in parts.items()},
        "r_ca": float(lay.r_ca),
        "r_cb": float(lay.r_cb),
        # the carrier plate as in the inertia rule of gears.carrier_inertia (disc of radius 1.2 r_cb)
        "carrier_radius": 1.2 * float(lay.r_cb),
        # pin (bearing) centres in carrier axes, per planet pair: exact positions for the drawing
        "pins": {"inner": np.asarray(lay.centres_a, float).tolist(),
                 "outer": np.asarray(lay.centres_b, float).tolist()},
        "bearing": {"d_m": float(B.pitch_diameter), "D": float(B.roller_diameter),
                    "clearance": float(B.clearance), "Z": int(B.rollers),
                    "R_i": float(B.inner_raceway_radius), "R_o": float(B.outer_raceway_radius),
                    "guide_clearance": float(B.cage.guide_clearance),
                    "pocket_clearance": float(B.cage.pocket_clearance)},
    }
