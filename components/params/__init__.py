"""Parameter objects of the DPGT: frozen dataclasses of pint quantities, each value with its source.

Where things are
----------------
* ``gears``     — :class:`GearParams`, :class:`GearSetParams`, :class:`MeshParams`
* ``bearing``   — the planet bearing: :class:`BearingParams` with :class:`CageParams`,
  :class:`SlideRollTractionParams`, :class:`LifeParams`; the oil: :class:`LubricantParams`
* ``operating`` — :class:`OperatingPoint`; the rigs: :class:`RigParams` (with :class:`CarrierRippleParams`),
  :class:`BearingRigParams`
* ``sensor``    — the accelerometer :class:`SensorParams` on the :class:`HousingParams`
* ``errors``    — manufacturing errors and faults, :class:`ErrorsParams` and one class per kind of entry
* ``machine``   — the whole machine :class:`DPGTParams` (and :class:`SupportParams`)
* ``dotted``    — :func:`with_overrides`, :func:`flatten`, :func:`parameter_names`, :func:`parameter_rows`,
  :func:`describe`, :func:`to_toml`, :func:`overrides_from_toml`, :func:`spans` (the ranges of assumed values)
* ``_machinery`` — how a parameter class works (field specifications, conversion, provenance, the ``Params``
  and ``SI`` bases, :func:`~components.params._machinery.si_of`); code that uses parameters need not touch it.

Import everything from here (``from components.params import DPGTParams, with_overrides``); each class's SI
class sits next to it (``GearParams`` / ``GearSI``).

Design
------
* Every parameter class is a frozen, keyword-only dataclass. Its fields hold pint quantities (or ints,
  bools, strings for counts, flags, choices; or nested parameter objects). At construction every value
  may be given as a pint quantity, a string (``"3 mm"``, ``"4200 rpm"``) or, for dimensionless values,
  a number; ``__post_init__`` converts and checks it (dimension, sign, integrality) and raises
  :class:`~components.units.ParameterError` naming the dotted parameter, e.g. ``bearing.clearance``.
* Provenance: wrap a value with :func:`paper`, :func:`derived` or :func:`assumed` (``Sourced``) to tag it;
  ``obj.source("clearance")`` returns its :class:`Source` (tag ``paper``/``derived``/``assumed``, or
  ``user`` once a value differs from the tagged one, ``default`` for an untouched field default).
  Optional values left ``None`` follow a documented rule (e.g. the Palmgren stiffness from the roller
  length, gear inertias from the pitch radius); their source is that rule's tag, and they follow the
  values they derive from when those are overridden.
* Overrides: :func:`with_overrides` ``(params, {"bearing.clearance": "30 um", "gears.planets": 4})``
  with dotted paths (unknown paths raise ParameterError listing the valid ones); :func:`components.presets.load_toml`
  reads the same dotted structure from a TOML file; :func:`to_toml` writes it back (lossless).
* Conversion to SI happens once: ``obj.si()`` returns a frozen, typed SI dataclass (``GearParams.si()``
  → :class:`GearSI`, ``BearingParams`` → :class:`BearingSI`, ..., ``DPGTParams`` → :class:`DPGTSI`) of
  floats (SI base units: m, kg, s, rad, rad/s, N/m, N/m^(10/9) ...), ints, strings, flags and nested SI
  objects, with the rule-based values resolved and the convenient derived values added (gear radii,
  raceway radii, ...). Each SI class is written out next to its Params class (``@si_of(GearParams)``), so
  type checkers and IDEs see its fields; the values ``si()`` resolves or adds are declared ``computed(doc)``
  and ``_si_values`` computes them; the import checks the SI class against the parameter fields.
  ``DPGTParams.si()`` also contains ``layout`` (:class:`components.geometry.Layout`: planet positions,
  meshes, phases) and the nominal kinematics/torques in ``operating`` (:class:`DPGTOperatingSI`).
  ``si()`` is computed once per object; SI objects have ``replace`` and ``to_dict``. Builders read
  only ``si()``; nothing downstream touches pint.

Single values are checked here (positive masses, clearances ≥ 0, N ≥ 1, Z ≥ 3, h = ±1, ...); how
values fit together (rollers fit, gears assemble, tip circles clear) is checked by
:func:`components.geometry.check_design`, which a builder should call before building.
"""
from ._machinery import SI, Derived, Params, Source, Sourced, Span, assumed, derived, paper
from .bearing import (BearingParams, BearingSI, CageParams, CageSI, LifeParams, LifeSI, LubricantParams, LubricantSI,
                      PinParams, PinSI, ProfileParams, ProfilePointParams, ProfilePointSI, ProfileSI, SlicingParams,
                      SlicingSI, SlideRollTractionParams, SlideRollTractionSI)
from .dotted import (describe, flatten, overrides_from_toml, parameter_names, parameter_rows, spans, to_toml,
                     with_overrides)
from .errors import (ErrorsParams, ErrorsSI, FlankClassParams, FlankClassSI, PinholeEndsParams, PinholeEndsSI,
                     PinholeErrorParams, PinholeErrorSI, PinSlopeParams, PinSlopeSI, RollerDiameterErrorParams,
                     RollerDiameterErrorSI, RunoutParams, RunoutSI, SpallParams, SpallSI, ToothDeviationParams,
                     ToothDeviationSI, ToothFaultParams, ToothFaultSI)
from .gears import GearParams, GearSetParams, GearSetSI, GearSI, MeshParams, MeshSI
from .machine import DPGTOperatingSI, DPGTParams, DPGTSI, DPGTSupportSI, SupportParams, SupportSI
from .operating import (BearingRigParams, BearingRigSI, CarrierRippleParams, CarrierRippleSI, OperatingPoint,
                        OperatingSI, RigParams, RigSI, SchedulePointParams, SchedulePointSI)
from .sensor import HousingParams, HousingSI, SensorParams, SensorSI

__all__ = [
    "Source", "Sourced", "Span", "paper", "derived", "assumed", "SI", "Derived", "Params",
    "GearParams", "GearSetParams", "CageParams", "SlideRollTractionParams", "LifeParams", "BearingParams", "LubricantParams",
    "PinParams", "PinSI",
    "SupportParams", "MeshParams", "OperatingPoint", "HousingParams", "SensorParams", "CarrierRippleParams", "RigParams",
    "SchedulePointParams", "DPGTParams", "BearingRigParams",
    "ErrorsParams", "PinholeErrorParams", "RunoutParams", "RollerDiameterErrorParams", "SpallParams", "ToothFaultParams",
    "ToothDeviationParams", "FlankClassParams", "PinSlopeParams", "PinholeEndsParams",
    "GearSI", "GearSetSI", "CageSI", "SlideRollTractionSI", "LifeSI", "BearingSI", "LubricantSI", "SupportSI", "MeshSI",
    "OperatingSI", "HousingSI", "SensorSI", "CarrierRippleSI", "RigSI", "SchedulePointSI", "DPGTSI", "DPGTOperatingSI", "DPGTSupportSI",
    "BearingRigSI", "ErrorsSI", "PinholeErrorSI", "RunoutSI", "RollerDiameterErrorSI", "SpallSI", "ToothFaultSI",
    "ToothDeviationSI", "FlankClassSI", "PinSlopeSI", "PinholeEndsSI",
    "with_overrides", "parameter_names", "flatten", "describe", "parameter_rows", "to_toml", "overrides_from_toml",
    "spans",
]
