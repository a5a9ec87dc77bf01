"""Which compiled kernel evaluates which element family: a kind id per family class, and the compiled
dispatch on it (a static if-chain: numba can cache it, no first-class functions needed).

Adding a compiled family: its pack/evaluate(/update) in a kernel module, an id below, one branch in
:func:`evaluate_kind` (and :func:`update_kind` when it has internal state)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from ..elements import (BodySpring, ForceSource, GearMesh, GroundSupport, GuideContact, LubricantDrag,
                        PocketContact, RaceContact, SpeedDrive, TorqueSource, TorsionalSpring)
from . import contact, generic, mesh

__all__ = ["Kind", "KINDS", "evaluate_kind", "update_kind"]


@dataclass(frozen=True)
class Kind:
    id: int
    pack: object          # element -> (P, G)


_RACE, _POCKET, _GUIDE, _DRAG, _MESH, _SUPPORT, _BODY_SPRING, _TORSION, _TORQUE, _FORCE, _SPEED = range(11)

KINDS = {
    RaceContact: Kind(_RACE, contact.pack_race),
    PocketContact: Kind(_POCKET, contact.pack_pocket),
    GuideContact: Kind(_GUIDE, contact.pack_guide),
    LubricantDrag: Kind(_DRAG, contact.pack_drag),
    GearMesh: Kind(_MESH, mesh.pack_gear_mesh),
    GroundSupport: Kind(_SUPPORT, generic.pack_ground_support),
    BodySpring: Kind(_BODY_SPRING, generic.pack_body_spring),
    TorsionalSpring: Kind(_TORSION, generic.pack_torsional_spring),
    TorqueSource: Kind(_TORQUE, generic.pack_torque_source),
    ForceSource: Kind(_FORCE, generic.pack_force_source),
    SpeedDrive: Kind(_SPEED, generic.pack_speed_drive),
}


@njit(cache=True)
def evaluate_kind(kind, t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    if kind == _RACE:
        contact.evaluate_race(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _POCKET:
        contact.evaluate_pocket(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _GUIDE:
        contact.evaluate_guide(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _DRAG:
        contact.evaluate_drag(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _MESH:
        mesh.evaluate_gear_mesh(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _SUPPORT:
        generic.evaluate_ground_support(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _BODY_SPRING:
        generic.evaluate_body_spring(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _TORSION:
        generic.evaluate_torsional_spring(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _TORQUE:
        generic.evaluate_torque_source(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _FORCE:
        generic.evaluate_force_source(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _SPEED:
        generic.evaluate_speed_drive(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)


@njit(cache=True)
def update_kind(kind, z, t0, t1, phi0, phi1, ql0, vl0, ql1, vl1, P, G):
    """The internal state after an accepted step (families without state keep z)."""
    if kind == _POCKET:
        return contact.update_pocket(z, t0, t1, ql0, vl0, ql1, vl1, P, G)
    if kind == _GUIDE:
        return contact.update_guide(z, t0, t1, ql0, vl0, ql1, vl1, P, G)
    if kind == _SPEED:
        return generic.update_speed_drive(z, t0, t1, ql0, vl0, ql1, vl1, P, G, phi0, phi1)
    return np.copy(z)
