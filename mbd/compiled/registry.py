"""Which compiled kernel evaluates which element family, and the compiled dispatch on it (static if-chains,
compiled per set of family groups: numba caches each, no first-class functions needed).

Each family declares its twin where it is defined (``Element.compiled_twin = "module.name"``: the kernels
``pack_name``, ``evaluate_name`` and, with internal state, ``update_name`` of ``mbd.compiled.module``); here
each twin has a kind id and a branch of :func:`evaluate_kind` (and of :func:`update_kind`). Adding a compiled
family: its kernels in a kernel module, the declaration on the family, an id in :data:`KIND_IDS` and the
branches (tests/test_architecture.py checks that they agree).

A twin may also give its family's outputs (``outputs_name`` and the names of its rows, ``NAME_OUTPUTS``, in its
module; a branch of :func:`outputs_kind`): :class:`mbd.compiled.outputs.CompiledOutputs` evaluates them for K
states at once. The others' outputs come from the numpy kernels.

Lazy compile per family group. The kernel modules are the groups (:data:`GROUPS`, a bit each); a compiled system
passes the set it uses (``groups``, a bit mask, :func:`groups_of`) down the step loop as a literal, so numba
compiles the loop, the assembly and the dispatch once per set (and caches each on disk): the if-chains below are
templates, each set's dispatch is a copy of them in which an absent group's module is a stand-in that compiles
to nothing (:func:`evaluate_for`, :func:`update_for`, :func:`outputs_for`). The bearing rig (no gears) then never
compiles the mesh and tooth-pair kernels; a set already cached that contains a system's is loaded instead of
compiling the system's own (:func:`groups_to_compile`).

Threads: the flag :data:`THREADED` beside the modules' bits asks for the threaded assembly (:mod:`.system`), whose
parallel function dispatches through :func:`evaluate_threaded_for`, a copy of the branches of the families of
:data:`THREADED_KINDS` only (the other kernels are not compiled into it)."""
from __future__ import annotations

import types
from dataclasses import dataclass
from typing import Callable

import numpy as np
from numba import njit
from numba.core import types as nbtypes
from numba.core.errors import TypingError
from numba.extending import overload

from . import contact, generic, mesh, sliced

__all__ = ["Kind", "KIND_IDS", "GROUPS", "THREADED", "THREADED_KINDS", "OUTPUT_NAMES", "output_names", "kind_of",
           "groups_of", "groups_to_compile", "call", "evaluate_for", "evaluate_threaded_for", "update_for", "outputs_for"]


@dataclass(frozen=True)
class Kind:
    id: int
    pack: Callable            # element -> (P, G)
    evaluate: Callable
    update: Callable | None   # None: the family has no internal state
    group: int                # its kernel module's bit in GROUPS


(_RACE, _POCKET, _GUIDE, _DRAG, _MESH, _SUPPORT, _BODY_SPRING, _TORSION, _TORQUE, _FORCE, _SPEED, _GYRO,
 _COORD_SPRING, _SLICED_RACE, _SLICED_MESH, _RETENTION, _POCKET_FILM, _CAGE_DRAG, _BEAM_SUPPORT, _RACE_FILM) = range(20)

# compiled twin (as the families declare it) -> its id in the dispatch below
KIND_IDS = {
    "contact.race": _RACE, "contact.pocket": _POCKET, "contact.guide": _GUIDE, "contact.drag": _DRAG,
    "contact.retention": _RETENTION,
    "mesh.gear_mesh": _MESH,
    "generic.ground_support": _SUPPORT, "generic.body_spring": _BODY_SPRING, "generic.torsional_spring": _TORSION,
    "generic.torque_source": _TORQUE, "generic.force_source": _FORCE, "generic.speed_drive": _SPEED,
    "generic.slope_gyroscopic": _GYRO, "generic.coordinate_spring": _COORD_SPRING,
    "generic.beam_support": _BEAM_SUPPORT,
    "sliced.sliced_race": _SLICED_RACE, "sliced.sliced_gear_mesh": _SLICED_MESH,
    "contact.pocket_film": _POCKET_FILM, "contact.cage_drag": _CAGE_DRAG,
    "contact.race_film": _RACE_FILM,
}
_MODULES = {"contact": contact, "generic": generic, "mesh": mesh, "sliced": sliced}
# kernel module -> its bit in a system's ``groups`` (the unit of the lazy compile)
GROUPS = {"contact": 1, "generic": 2, "mesh": 4, "sliced": 8}
# a flag in ``groups`` beside the modules' bits: the threaded assembly (:mod:`.system`, ``threads`` > 1), whose
# heaviest families (:data:`THREADED_KINDS`) run in chunks of instances on the threads; a set without it compiles no
# parallel code at all
THREADED = 256
# the twins that run in chunks on the threads (the contacts of every bearing: most of a step's kernel time, measured
# in docs/numerics.md §5 "Threads"); the others stay in the calling thread
THREADED_KINDS = ("contact.race", "contact.pocket", "contact.guide", "contact.drag", "sliced.sliced_race")
# twins that give their outputs (outputs_kind) -> the reference's names of the rows they write
# (the meshes' are not among them: numpy's batched mesh kernels, the face-sliced one's too, take as long over a block
# as a compiled one)
OUTPUT_NAMES = {"contact.race": contact.RACE_OUTPUTS, "contact.pocket": contact.POCKET_OUTPUTS,
                "contact.guide": contact.GUIDE_OUTPUTS, "contact.retention": contact.RETENTION_OUTPUTS,
                "sliced.sliced_race": sliced.SLICED_RACE_OUTPUTS}


def output_names(elem) -> tuple | None:
    """The names of the rows the twin of ``elem`` writes (:data:`OUTPUT_NAMES`; the sliced race's go on with a row
    per slice of the family, :func:`.sliced.sliced_race_output_names`), or None when its twin gives no outputs."""
    twin = type(elem).compiled_twin
    if twin == "sliced.sliced_race":
        return sliced.sliced_race_output_names(elem.n_s)
    return OUTPUT_NAMES.get(twin)


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
                getattr(mod, f"update_{name}", None), GROUPS[module])


def groups_of(kinds) -> int:
    """The ``groups`` mask (:data:`GROUPS`) of the families of these :class:`Kind` s."""
    mask = 0
    for k in kinds:
        mask |= k.group
    return mask


def groups_to_compile(needed: int, cached) -> int:
    """The family groups to run with: ``needed`` when cached, else the smallest ``cached`` set that contains it
    (loading a superset takes a second, compiling the exact set most of a minute), else ``needed`` (compiled). The
    :data:`THREADED` flag is not a group: a serial run never loads the threaded assembly, nor a threaded one the serial."""
    if needed in cached:
        return needed
    supersets = [g for g in cached if g & needed == needed and g & THREADED == needed & THREADED]
    return min(supersets, key=lambda g: (bin(g).count("1"), g)) if supersets else needed


_ENTRIES: dict = {}


def fingerprint(a):
    """What numba's type of an argument depends on (an array's dtype, ndim, layout, writeability, alignment; a
    typed container's numba type; else the Python type), at a fraction of the cost of numba's typeof."""
    if isinstance(a, np.ndarray):
        f = a.flags
        return a.dtype.str, a.ndim, f.c_contiguous, f.f_contiguous, f.writeable, f.aligned
    if isinstance(a, tuple):
        return tuple(fingerprint(x) for x in a)
    return getattr(a, "_numba_type_", type(a))


def entry(dispatcher, groups: int, *args):
    """The compiled (or loaded) ``dispatcher`` for ``groups`` as a literal and these arguments' types, kept per
    argument fingerprint (numba's typeof of every argument cost ≈ 0.1 ms a call). Call it as
    ``entry(...)(groups, *args)``; a caller whose arguments keep their types may keep it (:func:`call` does not)."""
    key = (dispatcher, groups, tuple(fingerprint(a) for a in args))
    found = _ENTRIES.get(key)
    if found is None:
        sig = (nbtypes.literal(int(groups)),) + tuple(dispatcher.typeof_pyval(a) for a in args)
        found = _ENTRIES[key] = dispatcher.compile(sig)
    return found


def call(dispatcher, groups: int, *args):
    """``dispatcher(groups, *args)`` compiled (or loaded) for ``groups`` as a literal. A plain call would type
    groups as int64, which has no compiled copy: numba would then retry a compile of the entry point on every
    call before numba.literally sends it to the literal one (≈ 50 ms a block: the engine ran 40 % slower)."""
    return entry(dispatcher, groups, *args)(groups, *args)


@njit(cache=True)
def _absent(*args):
    """The stand-in of an absent group's kernels (never called: no family of that group is in the system)."""


@njit(cache=True)
def _absent_update(z, *args):
    return np.copy(z)


def _stand_in(module) -> types.ModuleType:
    """A module whose every kernel is the no-op :func:`_absent` (numba compiles nothing of ``module``)."""
    stub = types.ModuleType(f"absent {module.__name__}")
    for name in dir(module):
        if name.startswith(("evaluate_", "outputs_")):
            setattr(stub, name, _absent)
        elif name.startswith("update_"):
            setattr(stub, name, _absent_update)
    return stub


_STAND_INS = {name: _stand_in(mod) for name, mod in _MODULES.items()}
_VARIANTS: dict = {}


def _variant(template, groups):
    """``template`` (an if-chain below) with the modules of the groups not in ``groups`` (a literal int type)
    replaced by stand-ins: the implementation :func:`evaluate_for` etc. compile for that set."""
    if not isinstance(groups, nbtypes.IntegerLiteral):
        raise TypingError(f"{template.__name__}: groups must be a literal int (numba.literally at the entry point)")
    key = (template.__name__, groups.literal_value)
    if key not in _VARIANTS:
        env = dict(template.__globals__)
        env.update({name: (_MODULES[name] if key[1] & bit else _STAND_INS[name]) for name, bit in GROUPS.items()})
        _VARIANTS[key] = types.FunctionType(template.__code__, env, template.__name__, template.__defaults__)
    return _VARIANTS[key]


# What the compiled code calls, with groups a literal: the template compiled for that set. Explicit arguments, not
# *args (through a *args tuple the engine once ran ≈ 40 % slower). jac arrives as a run-time bool: one compiled copy
# of every kernel serves residuals and Jacobians (mbd.compiled.stepper's docstring; the step costs the same).
def evaluate_for(groups, kind, t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    raise NotImplementedError("compiled code only")


@overload(evaluate_for, prefer_literal=True)
def _evaluate_for(groups, kind, t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    return _variant(evaluate_kind, groups)


def evaluate_threaded_for(groups, kind, t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    raise NotImplementedError("compiled code only")


@overload(evaluate_threaded_for, prefer_literal=True)
def _evaluate_threaded_for(groups, kind, t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    return _variant(evaluate_threaded_kind, groups)


def update_for(groups, kind, z, t0, t1, phi0, phi1, ql0, vl0, ql1, vl1, P, G):
    raise NotImplementedError("compiled code only")


@overload(update_for, prefer_literal=True)
def _update_for(groups, kind, z, t0, t1, phi0, phi1, ql0, vl0, ql1, vl1, P, G):
    return _variant(update_kind, groups)


def outputs_for(groups, kind, t, phi, omega, domega, ql, vl, z, P, G, O):
    raise NotImplementedError("compiled code only")


@overload(outputs_for, prefer_literal=True)
def _outputs_for(groups, kind, t, phi, omega, domega, ql, vl, z, P, G, O):
    return _variant(outputs_kind, groups)


def evaluate_kind(groups, kind, t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    """The forces (and Jacobians) of one family (the template of :func:`evaluate_for`; ``groups`` selects the copy)."""
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
    elif kind == _GYRO:
        generic.evaluate_slope_gyroscopic(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _COORD_SPRING:
        generic.evaluate_coordinate_spring(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _BEAM_SUPPORT:
        generic.evaluate_beam_support(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _SLICED_RACE:
        sliced.evaluate_sliced_race(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _SLICED_MESH:
        sliced.evaluate_sliced_gear_mesh(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _RETENTION:
        contact.evaluate_retention(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _POCKET_FILM:
        contact.evaluate_pocket_film(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _CAGE_DRAG:
        contact.evaluate_cage_drag(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _RACE_FILM:
        contact.evaluate_race_film(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)


def evaluate_threaded_kind(groups, kind, t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    """The branches of :func:`evaluate_kind` for the families of :data:`THREADED_KINDS` only (the template of
    :func:`evaluate_threaded_for`, called on the threads: the others' kernels are not compiled into it)."""
    if kind == _RACE:
        contact.evaluate_race(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _POCKET:
        contact.evaluate_pocket(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _GUIDE:
        contact.evaluate_guide(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _DRAG:
        contact.evaluate_drag(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)
    elif kind == _SLICED_RACE:
        sliced.evaluate_sliced_race(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)


def update_kind(groups, kind, z, t0, t1, phi0, phi1, ql0, vl0, ql1, vl1, P, G):
    """The internal state after an accepted step (families without state keep z)."""
    if kind == _POCKET:
        return contact.update_pocket(z, t0, t1, ql0, vl0, ql1, vl1, P, G)
    if kind == _GUIDE:
        return contact.update_guide(z, t0, t1, ql0, vl0, ql1, vl1, P, G)
    if kind == _RETENTION:
        return contact.update_retention(z, t0, t1, ql0, vl0, ql1, vl1, P, G)
    if kind == _SPEED:
        return generic.update_speed_drive(z, t0, t1, ql0, vl0, ql1, vl1, P, G, phi0, phi1)
    return np.copy(z)


def outputs_kind(groups, kind, t, phi, omega, domega, ql, vl, z, P, G, O):
    """The outputs of a family whose twin gives them (:data:`OUTPUT_NAMES`) into the rows of O."""
    if kind == _RACE:
        contact.outputs_race(t, phi, omega, domega, ql, vl, z, P, G, O)
    elif kind == _POCKET:
        contact.outputs_pocket(t, phi, omega, domega, ql, vl, z, P, G, O)
    elif kind == _GUIDE:
        contact.outputs_guide(t, phi, omega, domega, ql, vl, z, P, G, O)
    elif kind == _RETENTION:
        contact.outputs_retention(t, phi, omega, domega, ql, vl, z, P, G, O)
    elif kind == _SLICED_RACE:
        sliced.outputs_sliced_race(t, phi, omega, domega, ql, vl, z, P, G, O)

