"""Gear meshes: mesh constants u0 and stiffness phases from the real tooth positions.

Tooth convention (shared with :mod:`components.geometry`): a gear's tooth 0 lies at its body angle
θ; at assembly each gear is turned to the angle γ at which its teeth mate with the gear it meshes
with (the sun has γ = 0). The mesh position p = z₁(θ₁ − φ_e)/2π + p0 counts gear 1's teeth passing
the line of centres; p0 places the stiffness wave's double-contact zone where a new tooth pair enters
on the *loaded* flank (:meth:`MeshGeometry.wave_p0`), so phases between planets, between mesh types and
between forward and reverse follow from the geometry, never from hand-set numbers.
"""
from __future__ import annotations

import numpy as np

from mbd import ModelError
from mbd.elements.gear_mesh import GearMesh, SlicedGearMesh, StiffnessShape, mesh_offset
from mbd.elements.tooth_pairs import ToothPairs

from .scene import Scene
from .units import ParameterError

__all__ = ["add_mesh_family"]


def add_mesh_family(scene: Scene, family: str, mg, *, gear1: list[str], gear2: list[str], theta1_0, theta2_0,
                    flank: int, time_varying: bool, smoothing: float, ratio: float, damping_ramp: float,
                    errors: dict, pairs: ToothPairs | None = None, face_slices: int | None = None) -> slice:
    """Add the N meshes of one type (``mg`` a :class:`components.geometry.MeshGeometry`).
    ``theta*_0`` are the gears' body angles at assembly (tooth 0 at the body angle); u0 makes both
    flanks' compression zero there. ``damping_ramp``: the compression over which a flank's damping grows
    (``mesh.damping_ramp``). ``errors``: per-instance runout offsets
    (:func:`components.faults.mesh_error_args`; {} for a perfect machine); ``pairs``: the tooth-pair law's
    data (:func:`components.teeth.mesh_pairs`) of a machine whose teeth are not perfect, else None (the
    rectangular law, which the pair law then equals). A constant stiffness with pairs splits a constant
    over the pairs (k_double/k_single = 1). ``face_slices``: n_m, the face-sliced law on the gears' slope pairs
    (:class:`mbd.elements.gear_mesh.SlicedGearMesh`; the gears with slopes declared by the scene at build), or None."""
    th1, th2 = np.asarray(theta1_0, float), np.asarray(theta2_0, float)
    phi = np.asarray(mg.line_angle, float)
    rb1, rb2 = mg.base_radius1, mg.base_radius2
    u0 = mesh_offset(mg.internal, rb1, rb2, th1, th2, phi)
    if time_varying or pairs is not None:
        # the single/double-contact wave needs 1 <= ε < 2 and non-overlapping ramps: refuse with the
        # parameter's name here (StiffnessShape would raise a bare ModelError from inside the build)
        eps = mg.contact_ratio
        if eps >= 2.0:
            raise ParameterError.at(f"gears.{mg.gear1}", f"{mg.name} contact ratio {eps:.4f} >= 2: the single/double "
                                                         "tooth stiffness wave is undefined (use mesh_stiffness='constant')")
        s_max = min(eps - 1.0, 2.0 - eps)
        if smoothing > s_max:
            raise ParameterError.at("mesh.smoothing_width", f"{smoothing:g} is too wide for the {mg.name} mesh: its contact "
                                                            f"ratio {eps:.4f} allows at most {s_max:.4g} (ramps may not overlap)")
        shape = StiffnessShape.rectangular(mg.contact_ratio, ratio=ratio if time_varying else 1.0, smoothing=smoothing)
        # geometry's p0 assumes body angle 0 at assembly; here the body angle already holds γ₁
        p0 = np.mod(mg.wave_p0(flank) - mg.p0, 1.0)
    else:
        shape = StiffnessShape.constant()
        p0 = np.zeros_like(phi)
    if face_slices is not None:
        fam = scene.family(family, SlicedGearMesh, (), resolve=_sliced_mesh_dofs, internal=mg.internal,
                           stiffness=shape, slices=int(face_slices), pairs=pairs)
        n = phi.size
        return fam.add(n, gear1=gear1, gear2=gear2, rb1=rb1, rb2=rb2, alpha=mg.pressure_angle, a0=mg.centre_distance,
                       teeth1=mg.z1, k_mean=mg.k_mean, c_mesh=mg.damping, damping_ramp=damping_ramp, u0=u0, p0=p0,
                       backlash=mg.backlash, phi_ref=phi, face_width=mg.face_width, **errors)
    fam = scene.family(family, GearMesh, ("gear1", "gear2"), internal=mg.internal, stiffness=shape, pairs=pairs)
    n = phi.size
    return fam.add(n, gear1=gear1, gear2=gear2, rb1=rb1, rb2=rb2, alpha=mg.pressure_angle, a0=mg.centre_distance,
                   teeth1=mg.z1, k_mean=mg.k_mean, c_mesh=mg.damping, damping_ramp=damping_ramp, u0=u0, p0=p0,
                   backlash=mg.backlash, phi_ref=phi,
                   **errors)


def _sliced_mesh_dofs(cat, scene):
    """The face-sliced family's arguments: body indices, and the slope pairs of the gears that have them (every
    instance of a family alike: all of its gears 1, or none, have slopes; the same for gears 2)."""
    out = dict(cat)
    for key in ("gear1", "gear2"):
        names = [str(x) for x in out[key]]
        out[key] = np.array([scene.index[nm] for nm in names], np.int64)
        has = [nm in scene.slope_index for nm in names]
        if any(has) and not all(has):
            raise ModelError(f"{key}: some gears of one mesh family have slopes and some not")
        out["slopes1" if key == "gear1" else "slopes2"] = (np.array([scene.slope_index[nm] for nm in names], np.int64)
                                                         if all(has) else None)
    return out
