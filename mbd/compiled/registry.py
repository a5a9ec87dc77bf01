"""Which compiled kernel evaluates which element family, and the compiled dispatch on it (a static if-chain:
numba can cache it, no first-class functions needed).

Each family declares its twin where it is defined (``Element.compiled_twin = "module.name"``: the kernels
``pack_name``, ``evaluate_name`` and, with internal state, ``update_name`` of ``mbd.compiled.module``); here
each twin has a kind id and a branch of :func:`evaluate_kind` (and of :func:`update_kind`). Adding a compiled
family: its kernels in a kernel module, the declaration on the family, an id in :data:`KIND_IDS` and the
branches (tests/test_architecture.py checks that they agree).

A twin may also give its family's outputs (``outputs_name`` and the names of its rows, ``NAME_OUTPUTS``, in its
module; a branch of :func:`outputs_kind`): :class:`mbd.compiled.outputs.CompiledOutputs` evaluates them for K
states at once. The others' outputs come from the numpy kernels."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from numba import njit

from . import contact, generic, mesh

__all__ = ["Kind", "KIND_IDS", "OUTPUT_NAMES", "kind_of", "evaluate_kind", "update_kind", "outputs_kind"]


@dataclass(frozen=True)
class Kind:
    id: int
    pack: Callable            # element -> (P, G)
    evaluate: Callable
    update: Callable | None   # None: the family has no internal state


_RACE, _POCKET, _GUIDE, _DRAG, _MESH, _SUPPORT, _BODY_SPRING, _TORSION, _TORQUE, _FORCE, _SPEED = range(11)

# compiled twin (as the families declare it) -> its id in the dispatch below
KIND_IDS = {
    "contact.race": _RACE, "contact.pocket": _POCKET, "contact.guide": _GUIDE, "contact.drag": _DRAG,
    "mesh.gear_mesh": _MESH,
    "generic.ground_support": _SUPPORT, "generic.body_spring": _BODY_SPRING, "generic.torsional_spring": _TORSION,
    "generic.torque_source": _TORQUE, "generic.force_source": _FORCE, "generic.speed_drive": _SPEED,
}
_MODULES = {"contact": contact, "generic": generic, "mesh": mesh}
# twins that give their outputs (outputs_kind) -> the reference's names of the rows they write
# (the meshes' are not among them: numpy's batched mesh kernel takes as long over a block as the compiled one)
OUTPUT_NAMES = {"contact.race": contact.RACE_OUTPUTS, "contact.pocket": contact.POCKET_OUTPUTS,
                "contact.guide": contact.GUIDE_OUTPUTS}


def kind_of(cls) -> Kind | None:
    """The compiled twin a family class declares (``cls.compiled_twin``), or None when it declares none. A
    declared twin the registry does not know raises LookupError: a typo must not send runs to the numpy path."""
    twin = cls.compiled_twin
    if twin is None:
        return None
    module, _, name = twin.partition(".")
    if twin not in KIND_IDS or module not in _MODULES:
        raise LookupError(f"{cls.__name__}.compiled_twin = {twin!r}: no such compiled kernel "
                          f"(mbd.compiled.registry.KIND_IDS has {sorted(KIND_IDS)})")
    mod = _MODULES[module]
    return Kind(KIND_IDS[twin], getattr(mod, f"pack_{name}"), getattr(mod, f"evaluate_{name}"),
                getattr(mod, f"update_{name}", None))


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


@njit(cache=True)
def outputs_kind(kind, t, phi, omega, domega, ql, vl, z, P, G, O):
    """The outputs of a family whose twin gives them (:data:`OUTPUT_NAMES`) into the rows of O."""
    if kind == _RACE:
        contact.outputs_race(t, phi, omega, domega, ql, vl, z, P, G, O)
    elif kind == _POCKET:
        contact.outputs_pocket(t, phi, omega, domega, ql, vl, z, P, G, O)
    elif kind == _GUIDE:
        contact.outputs_guide(t, phi, omega, domega, ql, vl, z, P, G, O)
