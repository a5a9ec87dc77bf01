"""The teeth of every gear: deviations, profile modification and faults as the tooth-pair mesh law's data.

``params.errors.tooth`` (deviations given tooth by tooth), ``errors.flank_class`` (drawn for an ISO 1328-1
class, :mod:`components.tolerances`) and ``errors.tooth_fault`` (a tooth's stiffness factor) resolve here
into each gear's tooth table, and ``gears.*.tip_relief*`` into each mesh's relief; :func:`mesh_pairs` gives
a mesh family's :class:`mbd.elements.tooth_pairs.ToothPairs`. A machine with none of these has perfect
teeth: its meshes use the rectangular law, which the pair law reduces to exactly.

Deviations are material excess along the line of action per tooth flank face (ccw = the face towards
the gear's +θ side, index 0; cw index 1), as one cubic in x = 2ξ − 1 over the active profile
(ξ = 0 its start, 1 the tip): a pitch deviation p (an ISO 1328-1 arc on the reference circle) turns the tooth
forward by p/r, which moves its flank by p·cos α along the line of action: +p·cos α on the ccw face and
−p·cos α on the cw face; slope f_Hα gives f_Hα·x/2; a barrel form of range f gives f·(1 − 3x²)/3, an s-form
f·(5x³ − 3x)/4 (Legendre P2, P3 scaled to range 1: no straight-line part, as ISO's form deviation).
"""
from __future__ import annotations

import numpy as np

from mbd.elements.tooth_pairs import ToothPairs, tooth_table

from .tolerances import draw_teeth, flank_tolerances
from .units import ParameterError

__all__ = ["has_teeth", "gear_names", "gear_table", "mesh_pairs", "check_teeth", "RELIEF_EXPONENT"]

GEAR_TYPE = {"sun": "sun", "ring": "ring", "a": "inner_planet", "b": "outer_planet"}
RELIEF_EXPONENT = {"linear": 1.0, "parabolic": 2.0}
_FACES = {"ccw": (0,), "cw": (1,), "both": (0, 1)}
_FACE_SIGN = np.array([1.0, -1.0])


def _type(name: str) -> str:
    return GEAR_TYPE[name if name in ("sun", "ring") else name[0]]


def gear_names(N: int) -> list[str]:
    return ["sun", "ring", *(f"a{n + 1}" for n in range(N)), *(f"b{n + 1}" for n in range(N))]


def _relief_given(si) -> bool:
    return any(si.gears[t].tip_relief > 0.0 for t in ("sun", "inner_planet", "outer_planet", "ring"))


def has_teeth(si) -> bool:
    """Does the machine have anything the tooth-pair law needs (deviations, a class, a fault, a relief)?"""
    e = si.errors
    return bool(e.tooth or e.flank_class or e.tooth_fault or _relief_given(si))


def _class_gears(sel: str, N: int) -> list[str]:
    if sel == "all":
        return gear_names(N)
    if sel == "planets":
        return gear_names(N)[2:]
    return [sel]


def _excess(pitch, slope, form, shape: str) -> np.ndarray:
    """(..., 2, 4) cubic coefficients of deviations (..., 2) per face (module docstring)."""
    c = np.zeros(np.shape(pitch) + (4,))
    c[..., 0] = _FACE_SIGN * pitch
    c[..., 1] = 0.5 * slope
    if shape == "barrel":
        c[..., 0] += form / 3.0
        c[..., 2] -= form
    else:
        c[..., 1] -= 0.75 * form
        c[..., 3] += 1.25 * form
    return c


def gear_table(si, name: str) -> np.ndarray:
    """The flat tooth table of gear ``name`` (:func:`mbd.elements.tooth_pairs.tooth_table`)."""
    g = si.gears[_type(name)]
    z, N = int(g.teeth), si.layout.planets
    base = np.cos(g.pressure_angle)        # a pitch arc on the reference circle -> along the line of action
    ex = np.zeros((z, 2, 4))
    for c in si.errors.flank_class:
        if name in _class_gears(c.gear, N):
            d = draw_teeth(name, z, flank_tolerances(g.module, 2.0 * g.pitch_radius, c.grade), c.seed,
                           c.systematic_share)
            ex += _excess(base * d["pitch"], d["slope"], d["form"], "barrel")
    for x in si.errors.tooth:
        if x.gear != name:
            continue
        rows = slice(None) if x.tooth == "all" else slice(x.tooth, x.tooth + 1)
        one = np.zeros((2,))
        faces = list(_FACES[x.flank])
        mask = np.zeros(2)
        mask[faces] = 1.0
        ex[rows] += _excess(one + base * x.pitch, one + x.slope, one + x.form, x.form_shape) * mask[:, None]
    factor = np.ones(z)
    for f in si.errors.tooth_fault:
        if f.gear == name:
            factor[f.tooth] *= f.stiffness_factor
    return tooth_table(z, ex, factor)


def _relief(si, gear_type: str, mg) -> tuple[float, float, float]:
    """(C_a, ξ_a, e) of a gear type's tip relief in mesh ``mg`` (ξ_a from the relief length over the path)."""
    g = si.gears[gear_type]
    if g.tip_relief == 0.0:
        return 0.0, 0.0, 1.0
    path = mg.contact_ratio * mg.base_pitch
    return g.tip_relief, 1.0 - g.tip_relief_length / path, RELIEF_EXPONENT[g.tip_relief_shape]


def mesh_pairs(si, mg, gear1: list[str], gear2: list[str]) -> ToothPairs:
    """The tooth-pair data of one mesh family (``mg`` its :class:`components.geometry.MeshGeometry`, the gear
    names per instance). Flank f's pairs are counted from its own entry (``mg.entry_shift(f)``): the pair
    of gear-1 tooth i enters at P_f ≡ −i, that of gear-2 tooth k at Q_f ≡ σk (see ``_phase2``)."""
    names = list(dict.fromkeys(gear1 + gear2))
    tables = {n: gear_table(si, n) for n in names}
    start, pos = {}, 0
    for n in names:
        start[n], pos = pos, pos + tables[n].size
    n = len(gear1)
    entry = np.array([mg.entry_shift(1), mg.entry_shift(-1)])
    phase2 = np.array([_phase2(mg, 1), _phase2(mg, -1)])
    return ToothPairs(entry=np.tile(entry, (n, 1)), phase2=np.tile(phase2, (n, 1)),
                      relief1=np.tile(_relief(si, mg.gear1, mg), (n, 1)),
                      relief2=np.tile(_relief(si, mg.gear2, mg), (n, 1)),
                      table=np.concatenate([tables[x] for x in names]),
                      start1=np.array([start[g] for g in gear1], float),
                      start2=np.array([start[g] for g in gear2], float))


def _phase2(mg, flank: int) -> float:
    """c_f of Q_f = −σ z2 (θ2 − φ_e)/2π + c_f, which is σk when the pair of gear-2 tooth k enters on ``flank``.

    Gear 2's tooth phase at the pitch point q = z2 (θ2 − φ_e − π·[external])/2π is ≡ −k when its tooth k is
    centred there (its body angle θ2 holds tooth 0), and rolling keeps q = −σ p + const. The pair of tooth k
    on flank f has its contact at s = (σ f (p − p_i) + 1/4) p_b, at −p_b/4 when tooth k is centred (symmetry),
    so tooth k is centred at p_i − σf/2 and the pair enters σf/2 − h_f after that (h_f = entry_shift(f)):
    c_f = σ (z2/2)·[external] − σ f/2 + h_f."""
    sig, ext = mg.sigma, 0.0 if mg.internal else 1.0
    return sig * 0.5 * mg.z2 * ext - 0.5 * sig * flank + mg.entry_shift(flank)


def check_teeth(si) -> None:
    """Every tooth entry names a gear and tooth the machine has, deviations stay below a tenth of the module,
    a class names gears once, and every tip relief is shorter than the active profile of each mesh it enters."""
    e, N = si.errors, si.layout.planets
    names = gear_names(N)
    for i, x in enumerate(e.tooth):
        path = f"errors.tooth[{i}]"
        if x.gear not in names:
            raise ParameterError.at(f"{path}.gear", f"{x.gear!r} names planet {x.gear[1:]}, but the machine has {N} "
                                                    f"planets per row ('a1'..'a{N}', 'b1'..'b{N}')")
        g = si.gears[_type(x.gear)]
        if x.tooth != "all" and x.tooth >= g.teeth:
            raise ParameterError.at(f"{path}.tooth", f"must be in 0..{g.teeth - 1} ({x.gear} has {g.teeth} teeth) "
                                                     f'or "all", got {x.tooth}')
        for key in ("pitch", "slope", "form"):
            v = getattr(x, key)
            if abs(v) > 0.1 * g.module:
                raise ParameterError.at(f"{path}.{key}", f"{v * 1e6:.4g} um is larger than a tenth of the module "
                                                         f"({g.module * 1e5:.4g} um): not a deviation of a real tooth")
    seen = set()
    for i, c in enumerate(e.flank_class):
        gears = _class_gears(c.gear, N)
        if c.gear not in ("all", "planets") and c.gear not in names:
            raise ParameterError.at(f"errors.flank_class[{i}].gear", f"{c.gear!r} names planet {c.gear[1:]}, but the "
                                                                     f"machine has {N} planets per row")
        twice = seen.intersection(gears)
        if twice:
            raise ParameterError.at(f"errors.flank_class[{i}].gear", f"{sorted(twice)} already has a flank tolerance "
                                                                     "class: one class per gear")
        seen.update(gears)
    for key, mg in si.layout.meshes.items():
        path = mg.contact_ratio * mg.base_pitch
        for gt in (mg.gear1, mg.gear2):
            g = si.gears[gt]
            if g.tip_relief > 0.0 and not (0.0 < g.tip_relief_length <= path):
                raise ParameterError.at(f"gears.{gt}.tip_relief_length",
                                        f"must be in (0, {path * 1e3:.4g} mm], the active profile of the {key} mesh "
                                        f"(contact ratio {mg.contact_ratio:.3f} x base pitch), got "
                                        f"{g.tip_relief_length * 1e3:.4g} mm")
            if g.tip_relief > 0.1 * g.module:
                raise ParameterError.at(f"gears.{gt}.tip_relief", f"{g.tip_relief * 1e6:.4g} um is larger than a tenth "
                                                                  f"of the module ({g.module * 1e5:.4g} um)")
