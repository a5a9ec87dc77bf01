"""Parameter objects of the DPGT: frozen dataclasses of pint quantities, each value with its source.

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
  raceway radii, ...). Each SI class is generated from its Params class's fields (:func:`_with_si`) plus
  the ``_si_derived`` declarations (name, type, doc) that ``_si_values`` computes: one field list.
  ``DPGTParams.si()`` also contains ``layout`` (:class:`components.geometry.Layout`: planet positions,
  meshes, phases) and the nominal kinematics/torques in ``operating`` (:class:`DPGTOperatingSI`).
  ``si()`` is computed once per object; SI objects have ``replace`` and ``to_dict``. Builders read
  only ``si()``; nothing downstream touches pint.

Single values are checked here (positive masses, clearances ≥ 0, N ≥ 1, Z ≥ 3, h = ±1, ...); how
values fit together (rollers fit, gears assemble, tip circles clear) is checked by
:func:`components.geometry.check_design`, which a builder should call before building.
"""
from __future__ import annotations

import dataclasses
import json
import math
import numbers
import re
import tomllib
from dataclasses import MISSING, dataclass, field
from types import MappingProxyType
from typing import Any, ClassVar, Mapping

import numpy as np

from . import geometry as geo
from .names import did_you_mean
from .units import KINDS, ParameterError, Quantity, format_quantity, quantity, to_si

__all__ = [
    "Source", "Sourced", "paper", "derived", "assumed", "SI", "Derived", "Params",
    "GearParams", "GearSetParams", "CageParams", "SlideRollTractionParams", "LifeParams", "BearingParams", "LubricantParams",
    "SupportParams", "MeshParams", "OperatingPoint", "HousingParams", "SensorParams", "CarrierRippleParams", "RigParams",
    "DPGTParams", "BearingRigParams",
    "ErrorsParams", "PinholeErrorParams", "RunoutParams", "RollerDiameterErrorParams", "SpallParams", "ToothFaultParams",
    "GearSI", "GearSetSI", "CageSI", "SlideRollTractionSI", "LifeSI", "BearingSI", "LubricantSI", "SupportSI", "MeshSI",
    "OperatingSI", "HousingSI", "SensorSI", "CarrierRippleSI", "RigSI", "DPGTSI", "DPGTOperatingSI", "DPGTSupportSI",
    "BearingRigSI",
    "with_overrides", "parameter_names", "flatten", "describe", "parameter_rows", "to_toml", "overrides_from_toml",
]


# ---------------------------------------------------------------------------------------------
# provenance
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Source:
    """Where a value comes from: tag ``paper`` | ``derived`` | ``assumed`` | ``user`` | ``default``.

    ``value`` is the value the tag was given to (filled in automatically); a parameter whose current
    value differs from it is reported as ``user``.
    """

    tag: str
    note: str = ""
    value: Any = field(default=None, compare=False, repr=False)

    def __str__(self) -> str:
        return f"[{self.tag}]" + (f" {self.note}" if self.note else "")


@dataclass(frozen=True)
class Sourced:
    """A value with its source, accepted by every parameter field at construction."""

    value: Any
    source: Source


def paper(value, note: str = "") -> Sourced:
    """A value from the source study's tables or text."""
    return Sourced(value, Source("paper", note))


def derived(value, note: str = "") -> Sourced:
    """A value computed from paper values."""
    return Sourced(value, Source("derived", note))


def assumed(value, note: str = "") -> Sourced:
    """An engineering estimate; say its basis in ``note``."""
    return Sourced(value, Source("assumed", note))


_USER = Source("user")


# ---------------------------------------------------------------------------------------------
# field specifications
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class _Spec:
    kind: str                      # a units kind, or "count" | "sign" | "flag" | "choice" | "name" | "tooth" | "nested" | "entries"
    lo: float | None = None        # bounds on the SI value
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    bound_text: str = ""           # how the bound reads in an error message
    optional: bool = False         # None allowed: the value then follows ``rule``
    rule: Source | None = None
    choices: tuple = ()
    cls: type | None = None        # "nested": the parameter class; "entries": the class of one entry
    pattern: str = ""              # "name": the regular expression a value must match
    doc: str = ""


def _param(kind: str, doc: str = "", *, default=MISSING, **kw):
    return field(default=default, metadata={"spec": _Spec(kind, doc=doc, **kw)})


def _pos(kind, doc="", **kw):
    return _param(kind, doc, lo=0.0, lo_open=True, bound_text="> 0", **kw)


def _nonneg(kind, doc="", **kw):
    return _param(kind, doc, lo=0.0, bound_text=">= 0", **kw)


def _rule(kind, tag, note, doc=""):
    """An optional positive value that follows a rule when None."""
    return _param(kind, doc or note, default=None, lo=0.0, lo_open=True, bound_text="> 0", optional=True,
                  rule=Source(tag, note))


def _backlash(which: str):
    """Normal backlash of one mesh type: >= 0, or None for the ISO/TR 10064-2 minimum (see geometry)."""
    return _param("length", f"normal backlash j_bn of the {which} (0: both flanks touch, not a real gear)",
                  default=None, lo=0.0, bound_text=">= 0", optional=True,
                  rule=Source("derived", "ISO/TR 10064-2 minimum for steel gears in a steel housing: "
                                         "j_bn,min = (2/3)(0.06 + 0.0005 a + 0.03 m_n) mm, a and m_n in mm"))


def _nested(cls, doc=""):
    return _param("nested", doc, cls=cls)


def _entries(cls, doc=""):
    """A list of tables, each one ``cls`` (e.g. one manufacturing error); empty by default."""
    return _param("entries", doc, cls=cls, default=())


def _name(pattern: str, what: str, doc=""):
    return _param("name", doc, pattern=pattern, bound_text=what)


def _check_bounds(spec: _Spec, name: str, x: float, shown) -> None:
    bad = (spec.lo is not None and (x < spec.lo or (spec.lo_open and x == spec.lo))) or \
          (spec.hi is not None and (x > spec.hi or (spec.hi_open and x == spec.hi)))
    if bad:
        raise ParameterError.at(name, f"must be {spec.bound_text}, got {shown!r}")


def _as_int(name: str, value, what: str) -> int:
    if isinstance(value, (bool, np.bool_)):
        raise ParameterError.at(name, f"expected {what}, got {value!r}")
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real) and math.isfinite(value) and float(value).is_integer():
        return int(value)
    if isinstance(value, str):
        try:
            return int(value.strip())
        except ValueError:
            pass
    raise ParameterError.at(name, f"expected {what}, got {value!r}")


def _convert(spec: _Spec, name: str, value):
    """Check and convert one user value for a field (see the module docstring)."""
    if value is None:
        if spec.optional:
            return None
        raise ParameterError.at(name, "is required (got None)")
    k = spec.kind
    if k == "nested":
        if isinstance(value, spec.cls):
            return value
        if isinstance(value, Mapping):
            try:
                return spec.cls(**value)
            except ParameterError as e:
                raise e.renamed(spec.cls._prefix, name) from None
            except TypeError:
                fs = _param_fields(spec.cls)
                unknown = sorted(set(value) - {f.name for f in fs})
                missing = [f.name for f in fs if f.name not in value
                           and f.default is MISSING and f.default_factory is MISSING]
                hint = did_you_mean(unknown[0], [f.name for f in fs]) if unknown else ""
                raise ParameterError.at(name, f"a {spec.cls.__name__} table needs all of {missing} "
                                              f"(unknown: {unknown}{hint}); to change single values use dotted "
                                              f"overrides such as '{name}.{fs[0].name}'") from None
        raise ParameterError.at(name, f"expected {spec.cls.__name__} or a table, got {type(value).__name__}")
    if k == "count":
        v = _as_int(name, value, "an integer")
        _check_bounds(spec, name, v, value)
        return v
    if k == "sign":
        v = _as_int(name, value, "+1 or -1")
        if v not in (-1, 1):
            raise ParameterError.at(name, f"expected +1 or -1, got {value!r}")
        return v
    if k == "flag":
        if not isinstance(value, (bool, np.bool_)):
            raise ParameterError.at(name, f"expected true or false, got {value!r}")
        return bool(value)
    if k == "name":
        if not (isinstance(value, str) and re.fullmatch(spec.pattern, value)):
            near = [n for n in ("sun", "ring") if re.fullmatch(spec.pattern, n)]     # the gears' fixed names
            hint = did_you_mean(value, near) if isinstance(value, str) and near else ""
            raise ParameterError.at(name, f"expected {spec.bound_text}, got {value!r}{hint}")
        return value
    if k == "entries":
        return _convert_entries(spec, name, value)
    if k == "tooth":
        if value == "all":
            return value
        v = _as_int(name, value, 'a tooth index >= 0 or "all"')
        if v < 0:
            raise ParameterError.at(name, f'expected a tooth index >= 0 or "all", got {value!r}')
        return v
    if k == "choice":
        if value not in spec.choices:
            raise ParameterError.at(name, f"expected one of {list(spec.choices)}, got {value!r}"
                                          f"{did_you_mean(value, spec.choices) if isinstance(value, str) else ''}")
        return value
    q = quantity(name, value, k)
    _check_bounds(spec, name, to_si(q), value if isinstance(value, (str, numbers.Real)) else str(q))
    return q


def _convert_entries(spec: _Spec, name: str, value) -> tuple:
    """A list of tables (mappings or ``spec.cls`` objects) → a tuple of ``spec.cls``; errors name the entry,
    e.g. ``errors.pinhole[1].radial``."""
    if isinstance(value, (str, bytes, Mapping)) or not isinstance(value, (list, tuple)):
        raise ParameterError.at(name, f"expected a list of {spec.cls.__name__} tables (TOML: [[{name}]]), "
                                      f"got {type(value).__name__}")
    out = []
    for i, item in enumerate(value):
        path = f"{name}[{i}]"
        if isinstance(item, spec.cls):
            out.append(item)
            continue
        if not isinstance(item, Mapping):
            raise ParameterError.at(path, f"expected a table of {[f.name for f in _param_fields(spec.cls)]}, "
                                          f"got {type(item).__name__}")
        try:
            out.append(spec.cls(**item))
        except ParameterError as e:
            raise e.renamed(spec.cls._prefix, path) from None
        except TypeError:
            fs = _param_fields(spec.cls)
            unknown = sorted(set(item) - {f.name for f in fs})
            missing = [f.name for f in fs if f.name not in item and f.default is MISSING]
            hint = did_you_mean(unknown[0], [f.name for f in fs]) if unknown else ""
            raise ParameterError.at(path, f"needs {missing} (unknown keys: {unknown}{hint})") from None
    return tuple(out)


def _param_fields(cls) -> tuple:
    return tuple(f for f in dataclasses.fields(cls) if "spec" in f.metadata)


def _same(a, b) -> bool:
    if isinstance(a, Quantity) or isinstance(b, Quantity):
        if not (isinstance(a, Quantity) and isinstance(b, Quantity)):
            return False
        if a.dimensionality != b.dimensionality:
            return False
        x, y = to_si(a), to_si(b)
        return x == y or abs(x - y) <= 1e-12 * max(abs(x), abs(y))
    return type(a) is type(b) and a == b


# ---------------------------------------------------------------------------------------------
# SI classes: one frozen dataclass per parameter class, generated from its fields
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Derived:
    """A value ``si()`` computes, declared on the Params class (``_si_derived``) with its type and doc.
    A name that is also a parameter field is that parameter's rule-resolved value (its SI type wins)."""

    name: str
    type: Any
    doc: str


@dataclass(frozen=True)
class SI:
    """Base of the generated SI classes (``GearSI``, ``BearingSI``, ..., ``DPGTSI``): frozen, keyword-only
    dataclasses of SI floats, ints, strings, flags and nested SI objects."""

    def replace(self, **changes) -> "SI":
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict:
        """{name: value}, nested SI objects as dicts (other objects, e.g. the layout, as they are)."""
        return {f.name: _si_dict(getattr(self, f.name)) for f in dataclasses.fields(self)}

    def __getitem__(self, name: str):
        """Field by name (for code that picks a field from a string, e.g. ``si.gears[name]``)."""
        if name not in self.__dataclass_fields__:
            raise KeyError(name)
        return getattr(self, name)

    def __getattr__(self, name):   # only reached for names that are not fields: say what there is
        if name.startswith("__"):
            raise AttributeError(name)
        raise AttributeError(f"no SI value {name!r} in {type(self).__name__}; available: "
                             f"{', '.join(self.__dataclass_fields__)}")


def _si_dict(v):
    return v.to_dict() if isinstance(v, SI) else v


def _si_type(spec: "_Spec"):
    if spec.kind == "nested":
        return spec.cls.SI
    if spec.kind == "entries":
        return tuple
    t = {"count": int, "sign": int, "flag": bool, "choice": str, "name": str,
         "tooth": int | str}.get(spec.kind, float)
    return t | None if spec.optional else t


def _make_si(name: str, fields: list, doc: str, bases: tuple = (SI,)) -> type:
    cls = dataclasses.make_dataclass(name, fields, bases=bases, frozen=True, kw_only=True,
                                     namespace={"__doc__": doc, "__module__": __name__})
    cls.__module__ = __name__
    return cls


def _si_fields(items) -> list:
    """make_dataclass field specs from (name, type, doc) triples."""
    return [(n, t, field(metadata={"doc": d})) for n, t, d in items]


def _si_doc(title: str, items) -> str:
    return title + "\n\nFields (SI units):\n" + "\n".join(f"* ``{n}``: {d}" for n, _, d in items)


def _with_si(name: str):
    """Class decorator (above ``@dataclass``): build the SI class ``name`` from the parameter fields
    and the ``_si_derived`` declarations, as ``cls.SI``; ``si()`` returns instances of it."""
    def deco(cls):
        derived = {d.name: d for d in cls.__dict__.get("_si_derived", ())}
        items = []
        for f in _param_fields(cls):
            spec = f.metadata["spec"]
            d = derived.pop(f.name, None)
            items.append((f.name, d.type if d else _si_type(spec), d.doc if d else spec.doc))
        items += [(d.name, d.type, d.doc) for d in derived.values()]
        cls.SI = _make_si(name, _si_fields(items), _si_doc(f"SI values of :class:`{cls.__name__}`.", items))
        return cls
    return deco


def _extend_si(name: str, base: type, items, title: str) -> type:
    """An SI class with ``base``'s fields plus ``items`` (name, type, doc): a section as the whole
    machine sees it (e.g. the operating point with its kinematics)."""
    return _make_si(name, _si_fields(items), _si_doc(title, items), bases=(base,))


def _fields_of(obj) -> dict:
    """{name: value} of a dataclass, one level (nested objects kept as they are)."""
    return {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj)}


# ---------------------------------------------------------------------------------------------
# base class
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True, kw_only=True)
class Params:
    """Base of all parameter classes: conversion, provenance, replace, SI view."""

    _prefix: ClassVar[str] = ""
    SI: ClassVar[type]                      # the SI class, made by @_with_si from the fields
    _si_derived: ClassVar[tuple] = ()       # Derived(...): values si() computes
    sources: Mapping[str, Source] = field(default_factory=dict, compare=False, repr=False)

    def __post_init__(self):
        names = {f.name for f in _param_fields(type(self))}
        tags: dict[str, Source] = {}
        for key, src in dict(self.sources).items():
            if key not in names:
                raise ParameterError.at(self._path(key), f"source given for an unknown parameter"
                                                         f"{did_you_mean(key, names)}; valid: {sorted(names)}")
            tags[key] = src if isinstance(src, Source) else Source(str(src))
        for f in _param_fields(type(self)):
            value = getattr(self, f.name)
            if isinstance(value, Sourced):
                tags[f.name] = value.source
                value = value.value
            value = _convert(f.metadata["spec"], self._path(f.name), value)
            object.__setattr__(self, f.name, value)
            src = tags.get(f.name)
            if src is not None and src.value is None:  # remember what the tag was given to
                tags[f.name] = dataclasses.replace(src, value=value)
        object.__setattr__(self, "sources", MappingProxyType(tags))

    @classmethod
    def _path(cls, name: str) -> str:
        return f"{cls._prefix}.{name}" if cls._prefix else name

    def source(self, name: str) -> Source:
        """Provenance of field ``name`` (see :class:`Source`)."""
        spec = self._spec(name)
        value = getattr(self, name)
        src = self.sources.get(name)
        if src is not None and _same(src.value, value):
            return src
        if value is None and spec.rule is not None:
            return spec.rule
        f = next(f for f in _param_fields(type(self)) if f.name == name)
        if f.default is not MISSING and _same(_convert(spec, name, f.default), value):
            return Source("default", spec.doc)
        return _USER

    @classmethod
    def _spec(cls, name: str) -> _Spec:
        for f in _param_fields(cls):
            if f.name == name:
                return f.metadata["spec"]
        valid = [f.name for f in _param_fields(cls)]
        raise ParameterError.at(cls._path(name), f"unknown parameter{did_you_mean(name, valid)}; valid: {valid}")

    def replace(self, **changes) -> "Params":
        """A copy with some fields changed (values converted and checked like at construction)."""
        valid = [f.name for f in _param_fields(type(self))]
        for key in changes:
            if key not in valid:
                raise ParameterError.at(self._path(key), f"unknown parameter{did_you_mean(key, valid)}; valid: {valid}")
        return dataclasses.replace(self, **changes)

    def si(self) -> SI:
        """All values in SI units as a ``type(self).SI`` (rule-based values resolved, derived values
        added). Computed once per object (parameter objects are immutable)."""
        cached = self.__dict__.get("_si_cache")
        if cached is None:
            base = {f.name: _to_si_value(getattr(self, f.name)) for f in _param_fields(type(self))}
            cached = self.SI(**{**base, **self._si_values(base)})
            object.__setattr__(self, "_si_cache", cached)
        return cached

    def _si_values(self, v: dict) -> dict:
        """Rule-resolved and derived values (see ``_si_derived``) from the fields' SI values ``v``."""
        return {}


def _to_si_value(v):
    if isinstance(v, Params):
        return v.si()
    if isinstance(v, tuple):
        return tuple(_to_si_value(x) for x in v)
    return to_si(v) if isinstance(v, Quantity) else v


# ---------------------------------------------------------------------------------------------
# gears
# ---------------------------------------------------------------------------------------------
@_with_si("GearSI")
@dataclass(frozen=True, kw_only=True)
class GearParams(Params):
    """One standard involute spur gear (no profile shift).

    si() (:class:`GearSI`) adds pitch_radius, base_radius, tip_radius, root_radius and resolves ``inertia``.
    """

    _prefix: ClassVar[str] = "gear"
    teeth: int = _param("count", "number of teeth", lo=3, bound_text=">= 3")
    module: Quantity = _pos("length", "module m")
    pressure_angle: Quantity = _param("angle", "pressure angle α", lo=0.0, hi=math.pi / 4, lo_open=True,
                                      hi_open=True, bound_text="between 0 and 45 deg")
    face_width: Quantity = _pos("length", "face width")
    mass: Quantity = _pos("mass", "mass")
    inertia: Quantity | None = _rule("inertia", "assumed", "solid disc at the pitch radius, m r^2/2; a planet of a "
                                                           "DPGT: annulus m (r^2 + r_bore^2)/2 with its bearing bore "
                                                           "(internal gear: thin ring at the pitch radius, m r^2)")
    internal: bool = _param("flag", "internal gear (teeth inside, the ring)", default=False)
    addendum_coefficient: Quantity = _nonneg("dimensionless", "addendum h_a/m (standard 1)", default=1.0)
    dedendum_coefficient: Quantity = _nonneg("dimensionless", "dedendum h_f/m (standard 1.25)", default=1.25)
    tip_relief: Quantity = _nonneg("length", "tip relief C_a: material removed at the tip, along the line of action "
                                             "(a profile modification; 0: none)", default="0 um")
    tip_relief_length: Quantity = _nonneg("length", "length L_a of the tip relief: roll length along the line of "
                                                    "action from the tip", default="0 mm")
    tip_relief_shape: str = _param("choice", "how the relief grows from its start to the tip", default="linear",
                                   choices=("linear", "parabolic"))

    _si_derived: ClassVar[tuple] = (
        Derived("inertia", float, "polar moment of inertia [kg m^2] (given, or the rule)"),
        Derived("pitch_radius", float, "pitch circle radius m z / 2 [m]"),
        Derived("base_radius", float, "base circle radius [m]"),
        Derived("tip_radius", float, "tip (addendum) circle radius [m]"),
        Derived("root_radius", float, "root (dedendum) circle radius [m]"),
    )

    def _si_values(self, v):
        g = geo.GearGeometry(teeth=v["teeth"], module=v["module"], pressure_angle=v["pressure_angle"],
                             internal=v["internal"], addendum_coefficient=v["addendum_coefficient"],
                             dedendum_coefficient=v["dedendum_coefficient"])
        inertia = v["inertia"]
        if inertia is None:
            inertia = v["mass"] * g.pitch_radius ** 2 * (1.0 if self.internal else 0.5)
        return dict(inertia=inertia, pitch_radius=g.pitch_radius, base_radius=g.base_radius,
                    tip_radius=g.tip_radius, root_radius=g.root_radius)
GearSI = GearParams.SI


@_with_si("GearSetSI")
@dataclass(frozen=True, kw_only=True)
class GearSetParams(Params):
    """Sun, inner planets, outer planets, ring and carrier of the double planetary set.

    ``handedness`` h: the outer planet stands at ψ_b = ψ_a + h·Δψ (+1: it leads its inner planet in the
    positive angular direction). ``planet_angle`` ψ_0: angle of pair 1's inner planet (a1) at t = 0.
    """

    _prefix: ClassVar[str] = "gears"
    sun: GearParams = _nested(GearParams, "sun gear")
    inner_planet: GearParams = _nested(GearParams, "inner planets (mesh with the sun)")
    outer_planet: GearParams = _nested(GearParams, "outer planets (mesh with the ring)")
    ring: GearParams = _nested(GearParams, "ring gear (internal)")
    carrier_mass: Quantity = _pos("mass", "carrier mass")
    carrier_inertia: Quantity | None = _rule("inertia", "assumed", "disc of radius 1.2 r_cb, m (1.2 r_cb)^2/2")
    planets: int = _param("count", "planet pairs N", lo=1, bound_text=">= 1")
    handedness: int = _param("sign", "planet-pair handedness h = +1 or -1")
    planet_angle: Quantity = _param("angle", "angle psi_0 of the first inner planet", default="0 deg")

    _si_derived: ClassVar[tuple] = (
        Derived("carrier_inertia", float, "carrier polar moment of inertia [kg m^2] (given, or the rule)"),)

    def _si_values(self, v):
        if v["carrier_inertia"] is not None:
            return {}
        r_cb = 0.5 * v["sun"].module * (v["ring"].teeth - v["outer_planet"].teeth)
        return dict(carrier_inertia=0.5 * v["carrier_mass"] * (1.2 * r_cb) ** 2)
GearSetSI = GearSetParams.SI


# ---------------------------------------------------------------------------------------------
# planet bearing
# ---------------------------------------------------------------------------------------------
@_with_si("CageSI")
@dataclass(frozen=True, kw_only=True)
class CageParams(Params):
    """Cage of a planet bearing: outer-raceway (planet bore) guided, with Z pockets.

    :class:`CageSI` ``inertia`` stays None when the rule applies: the rule needs the bearing's pitch
    diameter, and ``BearingParams.si().cage`` has it resolved."""

    _prefix: ClassVar[str] = "bearing.cage"
    mass: Quantity = _pos("mass", "cage mass")
    inertia: Quantity | None = _rule("inertia", "assumed", "m (d_m/2)^2: mass on the pitch circle")
    pocket_clearance: Quantity = _nonneg("length", "circumferential pocket clearance per side C_p")
    guide_clearance: Quantity = _nonneg("length", "radial guiding clearance C_g")
    pocket_stiffness: Quantity = _pos("stiffness", "pocket contact stiffness K_p")
    guide_stiffness: Quantity = _pos("stiffness", "guide-land contact stiffness K_g")
    restitution: Quantity = _param("dimensionless", "coefficient of restitution of pocket and guide impacts",
                                   lo=0.0, hi=1.0, lo_open=True, bound_text="in (0, 1]")
    pocket_friction: Quantity = _nonneg("dimensionless", "pocket wall friction coefficient")
    guide_friction: Quantity = _nonneg("dimensionless", "guide land friction coefficient")
    friction_speed: Quantity = _pos("velocity", "sliding speed v_mu over which pocket and land friction "
                                                "rise to mu (tanh regularisation)")
    impact_speed_floor: Quantity = _pos("velocity", "smallest approach speed v0 in the impact damping "
                                                    "c = lambda(e)/v0 (slower contacts count as this speed)")
    impact_law: str = _param("choice", "impact damping law lambda(e) of pocket and guide impacts "
                                       "(mbd.elements.IMPACT_LAWS)",
                             choices=("exact", "hunt_crossley", "lankarani_nikravesh", "flores"))
    land_law: str = _param("choice", "guide land: dry (solid contact, Coulomb friction) or hydrodynamic (an oil "
                                     "film, short journal bearing)", choices=("dry", "hydrodynamic"))
    land_width: Quantity = _pos("length", "axial width of the guide lands (both sides together), for the film")
    land_min_film: Quantity = _pos("length", "thinnest film the hydrodynamic land keeps before the solid contact")
CageSI = CageParams.SI


@_with_si("SlideRollTractionSI")
@dataclass(frozen=True, kw_only=True)
class SlideRollTractionParams(Params):
    """Coefficients of the slide-to-roll traction curve μ(s) = (A + B s) e^(−C s) + D
    (:class:`mbd.elements.SlideRollTraction`), used when ``bearing.traction_law = "slide_roll"``."""

    _prefix: ClassVar[str] = "bearing.slide_roll_traction"
    A: Quantity = _param("dimensionless", "curve coefficient A (A + D = 0: no traction in pure rolling)")
    B: Quantity = _param("dimensionless", "curve coefficient B")
    C: Quantity = _nonneg("dimensionless", "curve decay C")
    D: Quantity = _param("dimensionless", "traction at large slide-to-roll ratio D")
    rolling_speed_reg: Quantity = _pos("velocity", "rolling speed below which the slide-to-roll ratio is regularised")
    ratio_reg: Quantity = _pos("dimensionless", "slide-to-roll ratio smoothing at s = 0")
SlideRollTractionSI = SlideRollTractionParams.SI


@_with_si("LifeSI")
@dataclass(frozen=True, kw_only=True)
class LifeParams(Params):
    """Rating factors of the planet bearing's fatigue life (:mod:`components.life`): ISO 281's basic
    dynamic load rating C_r = b_m f_c (i l)^(7/9) Z^(3/4) D^(29/27), f_c ∝ λν, and the raceway ratings
    of the ISO/TS 16281-style life, which keep b_m but not λν (that life sums the roller loads itself)."""

    _prefix: ClassVar[str] = "bearing.life"
    material_factor: Quantity = _pos("dimensionless", "rating factor b_m for contemporary material and "
                                                      "manufacturing quality (ISO 281:2007 Table 1)")
    reduction_factor: Quantity = _param("dimensionless", "ISO 281's reduction λν of the Lundberg-Palmgren line-"
                                                         "contact rating (edge stresses, real stress distribution)",
                                        lo=0.0, hi=1.0, lo_open=True, bound_text="in (0, 1]")
LifeSI = LifeParams.SI


@_with_si("BearingSI")
@dataclass(frozen=True, kw_only=True)
class BearingParams(Params):
    """Cylindrical roller planet bearing (same for inner and outer planets), with its cage.

    Inner raceway = carrier pin, diameter d_m − D; outer raceway = planet bore, diameter d_m + D + P_d
    (P_d the diametral clearance). si() adds inner_raceway_radius, outer_raceway_radius and resolves
    roller_mass, roller_inertia, contact_stiffness and cage.inertia.
    """

    _prefix: ClassVar[str] = "bearing"
    pitch_diameter: Quantity = _pos("length", "pitch diameter d_m")
    roller_diameter: Quantity = _pos("length", "roller diameter D")
    roller_length: Quantity = _pos("length", "effective roller length l")
    rollers: int = _param("count", "rollers Z per bearing", lo=3, bound_text=">= 3")
    rows: int = _param("count", "roller rows (identical rows move as one in the planar model)", lo=1,
                       bound_text=">= 1")
    clearance: Quantity = _nonneg("length", "diametral clearance P_d")
    roller_density: Quantity = _pos("density", "roller material density")
    roller_mass: Quantity | None = _rule("mass", "derived", "solid cylinder: density x pi D^2 l / 4")
    roller_inertia: Quantity | None = _rule("inertia", "derived", "solid cylinder: m D^2 / 8")
    contact_stiffness: Quantity | None = _rule("contact_stiffness", "derived",
                                               "Palmgren line contact: K = 8.06e4 l^(8/9) N/mm^(10/9), l in mm")
    contact_exponent: Quantity = _param("dimensionless", "load-deflection exponent p of Q = K delta^p", lo=1.0,
                                        bound_text=">= 1")
    contact_damping_ratio: Quantity = _nonneg("dimensionless", "roller-raceway contact damping ratio")
    traction_law: str = _param("choice", "roller-raceway traction law (ehl: from the lubricant's film)",
                               choices=("tanh", "slide_roll", "ehl"))
    traction_mu_max: Quantity = _nonneg("dimensionless", "traction curve maximum mu_max (mu = mu_max tanh(v/v0))")
    traction_v0: Quantity = _pos("velocity", "traction curve slip velocity scale v0")
    slide_roll_traction: SlideRollTractionParams = _nested(SlideRollTractionParams, "slide-to-roll traction curve")
    linear_stiffness: Quantity = _pos("stiffness", "radial stiffness of a bearing modelled as a linear spring "
                                                   "(scene option bearings=linear)")
    linear_damping: Quantity = _nonneg("damping", "radial damping of a bearing modelled as a linear spring")
    elastic_modulus: Quantity = _pos("pressure", "Young's modulus of rollers and raceways (EHL film)")
    poisson_ratio: Quantity = _param("dimensionless", "Poisson's ratio of rollers and raceways", lo=0.0, hi=0.5,
                                     hi_open=True, bound_text="in [0, 0.5)")
    cage: CageParams = _nested(CageParams, "cage")
    life: LifeParams = _nested(LifeParams, "fatigue life rating factors")

    _si_derived: ClassVar[tuple] = (
        Derived("roller_mass", float, "mass of one physical roller [kg] (given, or the rule)"),
        Derived("roller_inertia", float, "polar moment of inertia of one roller [kg m^2] (given, or the rule)"),
        Derived("contact_stiffness", float, "roller-raceway line contact stiffness K [N/m^(10/9)] (given, or Palmgren)"),
        Derived("inner_raceway_radius", float, "R_i = (d_m - D)/2, the pin [m]"),
        Derived("outer_raceway_radius", float, "R_o = (d_m + D + P_d)/2, the planet bore [m]"),
    )

    def _si_values(self, v):
        dm, dr, ln = v["pitch_diameter"], v["roller_diameter"], v["roller_length"]
        m = v["roller_mass"] if v["roller_mass"] is not None else v["roller_density"] * math.pi * dr ** 2 * ln / 4.0
        cage = v["cage"]
        if cage.inertia is None:
            cage = cage.replace(inertia=cage.mass * (dm / 2.0) ** 2)
        return dict(roller_mass=m,
                    roller_inertia=v["roller_inertia"] if v["roller_inertia"] is not None else m * dr ** 2 / 8.0,
                    contact_stiffness=(v["contact_stiffness"] if v["contact_stiffness"] is not None
                                       else geo.palmgren_stiffness(ln)),
                    cage=cage, inner_raceway_radius=(dm - dr) / 2.0,
                    outer_raceway_radius=(dm + dr + v["clearance"]) / 2.0)
BearingSI = BearingParams.SI


# ---------------------------------------------------------------------------------------------
# environment, supports, meshes, operating point
# ---------------------------------------------------------------------------------------------
@_with_si("LubricantSI")
@dataclass(frozen=True, kw_only=True)
class LubricantParams(Params):
    """The oil and the oil–air mixture around the rollers (docs/model.md §8.7, §9).

    Drag: F = C_d ρ D l (d_m Ω_m)^2 / 8 with the mixture density. Film: the oil's kinematic viscosity at
    40 °C and 100 °C (an ISO VG grade's data sheet) gives its viscosity at the operating temperature by
    Walther's equation (ASTM D341), times its density at that temperature (from the density at 15 °C and
    the thermal expansion); with the pressure–viscosity coefficient and the surfaces' composite roughness
    it sets the EHL film of every roller contact, thinned by inlet shear heating through the oil's thermal
    conductivity and its temperature–viscosity coefficient β (:mod:`components.lubrication`).
    ``oil_viscosity`` (the dynamic viscosity at the operating temperature [Pa·s]) and
    ``temperature_viscosity`` (β [1/K]) follow from these unless given; a viscosity given directly (a study
    of viscosity) keeps β of the grade's line at the operating temperature."""

    _prefix: ClassVar[str] = "lubricant"
    drag_coefficient: Quantity = _nonneg("dimensionless", "drag coefficient C_d")
    density: Quantity = _nonneg("density", "oil-air mixture density")
    oil_density: Quantity = _pos("density", "density of the oil itself at 15 degC")
    thermal_expansion: Quantity = _param("per_temperature", "volumetric thermal expansion alpha_rho of the oil: "
                                                            "rho(T) = rho_15 (1 - alpha_rho (T - 15 degC))",
                                         lo=0.0, hi=0.01, hi_open=True, bound_text="in [0, 0.01) 1/K")
    viscosity_40: Quantity = _pos("kinematic_viscosity", "kinematic viscosity at 40 degC (ISO VG: the grade)")
    viscosity_100: Quantity = _pos("kinematic_viscosity", "kinematic viscosity at 100 degC")
    temperature: Quantity = _pos("temperature", "oil temperature in the bearing")
    pressure_viscosity: Quantity = _pos("pressure_viscosity", "pressure-viscosity coefficient alpha_p (Barus)")
    thermal_conductivity: Quantity = _pos("thermal_conductivity", "thermal conductivity k of the oil (the film's "
                                                                  "thermal reduction, Murch-Wilson)")
    roughness: Quantity = _pos("length", "composite roughness sigma = sqrt(Rq1^2 + Rq2^2) of roller and raceway")
    limiting_shear_stress: Quantity = _pos("pressure", "limiting shear stress at zero pressure tau_L0 (EHL traction)")
    limiting_shear_slope: Quantity = _nonneg("dimensionless", "pressure slope gamma_L of the limiting shear stress "
                                                              "tau_L = tau_L0 + gamma_L p (Bair-Winer)")
    film_speed_reg: Quantity = _pos("velocity", "entraining speed below which the EHL traction's film is regularised")
    film_shear_modulus: Quantity = _pos("pressure", "elastic shear modulus G_e of the film in the contact (EHL "
                                                    "traction's linear region, Johnson-Tevaarwerk)")

    oil_viscosity: Quantity | None = _rule("dynamic_viscosity", "derived", "Walther (ASTM D341) at the temperature, "
                                                                          "times the oil density there")
    temperature_viscosity: Quantity | None = _rule("per_temperature", "derived",
                                                   "beta = -(1/eta) d(eta)/dT of Walther's line and the density "
                                                   "at the temperature")

    _si_derived: ClassVar[tuple] = (
        Derived("oil_viscosity", float, "dynamic viscosity at the operating temperature [Pa s] (given, or Walther)"),
        Derived("temperature_viscosity", float, "temperature-viscosity coefficient beta at the operating "
                                                "temperature [1/K] (given, or Walther)"),
    )

    def _si_values(self, v):
        from .lubrication import dynamic_viscosity, oil_density, temperature_viscosity
        if not v["viscosity_100"] < v["viscosity_40"]:
            raise ParameterError.at("lubricant.viscosity_100", "must be below lubricant.viscosity_40 "
                                                                 "(an oil thins as it warms)")
        line = (v["viscosity_40"], v["viscosity_100"])
        if not oil_density(v["oil_density"], v["thermal_expansion"], v["temperature"]) > 0.0:
            raise ParameterError.at("lubricant.temperature", "the oil's density at this temperature would be <= 0 "
                                                             "with lubricant.thermal_expansion")
        eta = v["oil_viscosity"]
        beta = v["temperature_viscosity"]
        return dict(
            oil_viscosity=eta if eta is not None else dynamic_viscosity(*line, v["oil_density"],
                                                                        v["thermal_expansion"], v["temperature"]),
            temperature_viscosity=beta if beta is not None else temperature_viscosity(*line, v["thermal_expansion"],
                                                                                      v["temperature"]))
LubricantSI = LubricantParams.SI


@_with_si("SupportSI")
@dataclass(frozen=True, kw_only=True)
class SupportParams(Params):
    """Isotropic translational supports of sun, ring and carrier; torsional support of the ring.

    The ring's torsional support is given as a tangential stiffness k on u = r_r·θ_r (r_r its pitch
    radius); ``DPGTParams.si().support`` adds ring_torsional_stiffness = k·r_r^2 [N·m/rad].
    """

    _prefix: ClassVar[str] = "support"
    sun_stiffness: Quantity = _nonneg("stiffness", "sun translational support stiffness")
    ring_stiffness: Quantity = _nonneg("stiffness", "ring translational support stiffness")
    carrier_stiffness: Quantity = _nonneg("stiffness", "carrier translational support stiffness")
    damping_ratio: Quantity = _nonneg("dimensionless", "support damping ratio")
    ring_tangential_stiffness: Quantity = _nonneg("stiffness", "ring torsional support as tangential stiffness "
                                                               "at the ring pitch radius")
SupportSI = SupportParams.SI


@_with_si("MeshSI")
@dataclass(frozen=True, kw_only=True)
class MeshParams(Params):
    """Mesh stiffness and damping, common to the three meshes.

    k_mean of a mesh = ``mean_stiffness`` if given, else c_γα × the mesh's common face width; the
    time-varying stiffness is a smoothed rectangular wave with k_double/k_single = ``stiffness_ratio``;
    ``smoothing_width`` is the width of its steps as a fraction of one mesh cycle. Resolved per mesh in
    ``DPGTParams.si().layout.meshes``.
    """

    _prefix: ClassVar[str] = "mesh"
    c_gamma_alpha: Quantity = _pos("stiffness_per_width", "ISO 6336 mean mesh stiffness per face width")
    mean_stiffness: Quantity | None = _rule("stiffness", "derived", "c_gamma_alpha x common face width of each mesh")
    stiffness_ratio: Quantity = _param("dimensionless", "k_double / k_single", lo=1.0, bound_text=">= 1")
    smoothing_width: Quantity = _param("dimensionless", "step width of the stiffness wave, fraction of a mesh cycle",
                                       lo=0.0, hi=0.5, lo_open=True, bound_text="in (0, 0.5]")
    damping_ratio: Quantity = _nonneg("dimensionless", "mesh damping ratio zeta_m")
    backlash_sun_inner: Quantity | None = _backlash("sun-inner planet meshes")
    backlash_inner_outer: Quantity | None = _backlash("inner-outer planet meshes")
    backlash_outer_ring: Quantity | None = _backlash("outer planet-ring meshes")
MeshSI = MeshParams.SI


@_with_si("OperatingSI")
@dataclass(frozen=True, kw_only=True)
class OperatingPoint(Params):
    """Ring fixed, sun driven, carrier loaded. ``carrier_speed`` is a magnitude; ``direction`` gives
    its sense (forward = counter-clockwise seen from the input side = positive).

    si(): carrier_speed signed [rad/s], output_power [W], direction (str) and sign (±1);
    ``DPGTParams.si().operating`` adds the nominal speeds and torques (:class:`geometry.Kinematics`).
    """

    _prefix: ClassVar[str] = "operating"
    carrier_speed: Quantity = _param("angular_velocity", "carrier speed magnitude n_c", lo=0.0,
                                     bound_text=">= 0 (give the sense with direction)")
    output_power: Quantity = _nonneg("power", "output power P")
    direction: str = _param("choice", "sense of rotation", choices=("forward", "reverse"), default="forward")

    _si_derived: ClassVar[tuple] = (
        Derived("carrier_speed", float, "signed carrier speed [rad/s] (+: forward)"),
        Derived("sign", int, "+1 forward, -1 reverse"),
    )

    def _si_values(self, v):
        sign = 1 if v["direction"] == "forward" else -1
        return dict(sign=sign, carrier_speed=sign * v["carrier_speed"])
OperatingSI = OperatingPoint.SI


@_with_si("HousingSI")
@dataclass(frozen=True, kw_only=True)
class HousingParams(Params):
    """The housing the rig's accelerometer sits on, as two rigid-body modes on its mounting (docs/model.md §12),
    each a linear mass–spring–damper driven one way by what the train puts on the housing
    (:mod:`components.sensor`): a translation (modal mass m_h, the same in x and y) and a rocking about the
    mounting's elastic centre O, ``rocking_centre_depth`` below the gear axis (a gearbox on feet rocks about
    its foot plane), with modal inertia J_O about O. Each mode: natural frequency and damping ratio."""

    _prefix: ClassVar[str] = "housing"
    mass: Quantity = _pos("mass", "modal mass m_h of the housing's translation (the housing's mass)")
    translation_frequency: Quantity = _pos("frequency", "natural frequency of the housing's translation on its mounting")
    translation_damping_ratio: Quantity = _pos("dimensionless", "damping ratio of the housing's translation")
    rocking_inertia: Quantity = _pos("inertia", "modal inertia J_O of the housing's rocking about its mounting's "
                                                "elastic centre O")
    rocking_frequency: Quantity = _pos("frequency", "natural frequency of the housing's rocking on its mounting")
    rocking_damping_ratio: Quantity = _pos("dimensionless", "damping ratio of the housing's rocking")
    rocking_centre_depth: Quantity = _nonneg("length", "depth h of the rocking centre O below the gear axis "
                                                       "(along -Y of the fixed frame, the foot plane)")
HousingSI = HousingParams.SI


@_with_si("SensorSI")
@dataclass(frozen=True, kw_only=True)
class SensorParams(Params):
    """The rig's accelerometer on the housing (docs/model.md §12) at angle ``angle`` ψ_s of the fixed frame and
    distance ``radius`` from the gear axis, along its axis e (radial at ψ_s, or tangential 90° ahead). It reads
    the sum of three paths (:mod:`components.sensor`):

    * mesh: Σ_n w(ψ_n − ψ_s)·(F_n·e)/m_eq — each outer planet's ring-mesh force on the ring F_n weighted by a
      Hann window w of full angular width ``window_width`` of the planet's distance from the sensor (McFadden &
      Smith 1985; Inalpolat & Kahraman 2009), m_eq = ``equivalent_mass``;
    * torque: the housing's rocking (``housing``) driven by the ring's torsional support torque;
    * bearing: the housing's translation and rocking driven by the sun's and carrier's bearing forces and the
      ring's seat force."""

    _prefix: ClassVar[str] = "sensor"
    angle: Quantity = _param("angle", "angle psi_s of the sensor on the housing, in the fixed frame")
    radius: Quantity = _pos("length", "distance of the sensor from the gear axis")
    window_width: Quantity = _param("angle", "full angular width of the Hann window over which a passing "
                                             "planet's ring-mesh force reaches the sensor",
                                    lo=0.0, hi=2.0 * math.pi, lo_open=True, bound_text="in (0, 360 deg]")
    equivalent_mass: Quantity = _pos("mass", "equivalent mass m_eq of the mesh path: mesh force / m_eq is the "
                                             "acceleration the sensor reads")
    direction: str = _param("choice", "sensor axis: radial (through the ring's axis) or tangential",
                            choices=("radial", "tangential"))
    housing: HousingParams = _nested(HousingParams, "the housing's translation and rocking (torque and bearing paths)")
SensorSI = SensorParams.SI


def _ripple_amplitude(order: int):
    return _param("angular_velocity", f"amplitude A_{order} of the carrier speed reference's ripple at {order} x f_c",
                  lo=0.0, bound_text=">= 0 rad/s (the phase gives its sign)")


@_with_si("CarrierRippleSI")
@dataclass(frozen=True, kw_only=True)
class CarrierRippleParams(Params):
    """Carrier-synchronous speed ripple of the rig's carrier speed drive (docs/model.md §10.3: the loading motor and
    its coupling). The drive's speed reference becomes ω_c + Σ_k A_k cos(k ω_c t + φ_k) over the orders
    k = 1, 2, 4 of the carrier frequency, its angle reference the exact integral
    (:class:`mbd.elements.SpeedDrive` ``ripple``). Every amplitude 0: an ideal drive."""

    _prefix: ClassVar[str] = "carrier_ripple"
    ORDERS: ClassVar[tuple] = (1, 2, 4)
    amplitude_1: Quantity = _ripple_amplitude(1)
    phase_1: Quantity = _param("angle", "phase of the order-1 ripple at t = 0")
    amplitude_2: Quantity = _ripple_amplitude(2)
    phase_2: Quantity = _param("angle", "phase of the order-2 ripple at t = 0")
    amplitude_4: Quantity = _ripple_amplitude(4)
    phase_4: Quantity = _param("angle", "phase of the order-4 ripple at t = 0")
CarrierRippleSI = CarrierRippleParams.SI


@_with_si("RigSI")
@dataclass(frozen=True, kw_only=True)
class RigParams(Params):
    """The source's test rig around the train (docs/model.md §10.3): the loading motor holds the carrier at its
    speed through a PI speed drive (stiffness, damping and integral gain from the bandwidth and damping
    ratio on the train's kinetic inertia), with its carrier-synchronous speed ripple, and the driving
    motor's sun torque is ramped in."""

    _prefix: ClassVar[str] = "rig"
    carrier_drive_bandwidth: Quantity = _pos("frequency", "bandwidth of the carrier speed drive")
    carrier_drive_damping_ratio: Quantity = _nonneg("dimensionless", "damping ratio of the carrier speed drive")
    carrier_ripple: CarrierRippleParams = _nested(CarrierRippleParams, "speed ripple of the carrier drive at "
                                                                       "orders 1, 2, 4 of f_c")
    load_ramp_mesh_periods: Quantity = _nonneg("dimensionless", "length of the sun-torque ramp in mesh periods "
                                                                "(0: the full torque at t = 0)")
    load_ramp_max: Quantity = _nonneg("time", "longest sun-torque ramp (near-zero speeds have no mesh period)")
    sensor: SensorParams = _nested(SensorParams, "the accelerometer on the housing (recorded when a run asks)")
RigSI = RigParams.SI


# the operating point and the supports as the whole machine sees them (they need the gears)
DPGTOperatingSI = _extend_si(
    "DPGTOperatingSI", OperatingSI,
    [(f.name, float, "see geometry.Kinematics") for f in dataclasses.fields(geo.Kinematics)
     if f.name not in {g.name for g in dataclasses.fields(OperatingSI)}],
    "An operating point with its nominal speeds [rad/s], frequencies [Hz] and torques [N m] "
    "(:class:`geometry.Kinematics`).")
DPGTSupportSI = _extend_si(
    "DPGTSupportSI", SupportSI,
    [("ring_torsional_stiffness", float, "ring_tangential_stiffness x r_ring^2 [N m/rad]")],
    "Supports with the ring's torsional stiffness.")


# ---------------------------------------------------------------------------------------------
# manufacturing errors and faults (docs/model.md §11): lists of entries, none by default (a perfect machine)
# ---------------------------------------------------------------------------------------------
_PLANET = r"[ab][1-9][0-9]*"
_PLANET_TEXT = "a planet name 'a1'..'aN' (inner) or 'b1'..'bN' (outer)"
_GEAR = r"sun|ring|" + _PLANET
_GEAR_TEXT = "a gear name: 'sun', 'ring', 'a1'..'aN' or 'b1'..'bN'"


@_with_si("PinholeErrorSI")
@dataclass(frozen=True, kw_only=True)
class PinholeErrorParams(Params):
    """A carrier pinhole off its nominal position: the planet's pin (its bearing's inner raceway) is
    displaced on the carrier, radially (away from the carrier axis +) and tangentially (+ in the sense of
    increasing planet angle)."""
    _prefix: ClassVar[str] = "errors.pinhole"
    planet: str = _name(_PLANET, _PLANET_TEXT, "the planet whose pin is displaced")
    radial: Quantity = _param("length", "radial position error of the pin (+ outwards)")
    tangential: Quantity = _param("length", "tangential position error of the pin (+ with the planet angle)")
PinholeErrorSI = PinholeErrorParams.SI


@_with_si("RunoutSI")
@dataclass(frozen=True, kw_only=True)
class RunoutParams(Params):
    """Eccentricity of a gear's teeth: their centre sits ``eccentricity`` from the gear's rotation centre,
    at ``phase`` in the gear's body axes (tooth 0 at phase 0), turning with the gear; the meshes see it
    through their exact kinematics. Radial runout (total indicator reading) = 2 × eccentricity."""
    _prefix: ClassVar[str] = "errors.runout"
    gear: str = _name(_GEAR, _GEAR_TEXT, "the eccentric gear")
    eccentricity: Quantity = _nonneg("length", "offset of the tooth centre from the rotation centre (runout / 2)")
    phase: Quantity = _param("angle", "direction of the offset in the gear's body axes")
RunoutSI = RunoutParams.SI


@_with_si("RollerDiameterErrorSI")
@dataclass(frozen=True, kw_only=True)
class RollerDiameterErrorParams(Params):
    """One roller of a planet bearing larger (+) or smaller (−) than nominal (every row of that roller)."""
    _prefix: ClassVar[str] = "errors.roller_diameter"
    planet: str = _name(_PLANET, _PLANET_TEXT, "the planet whose bearing has the roller")
    roller: int = _param("count", "roller index 0..Z-1 (roller 0 starts on the carrier's radial line)", lo=0.0,
                         bound_text=">= 0")
    deviation: Quantity = _param("length", "diameter deviation of the roller (+ larger)")
RollerDiameterErrorSI = RollerDiameterErrorParams.SI


@_with_si("SpallSI")
@dataclass(frozen=True, kw_only=True)
class SpallParams(Params):
    """A local raceway defect: a roller over it loses ``depth`` of its contact deflection, ramped in over
    ``edge`` at both ends. On the pin (raceway "inner", fixed on the carrier: ``position`` measured from
    the carrier's radial line through the planet, + with the planet angle) or on the planet's bore
    (raceway "outer", turning with the planet: ``position`` in the planet's body axes)."""
    _prefix: ClassVar[str] = "errors.spall"
    planet: str = _name(_PLANET, _PLANET_TEXT, "the planet whose bearing has the defect")
    raceway: str = _param("choice", "inner (the pin) or outer (the planet bore)", choices=("inner", "outer"))
    position: Quantity = _param("angle", "angular position of the defect's centre on its raceway")
    width: Quantity = _pos("length", "length of the defect along the raceway")
    depth: Quantity = _pos("length", "depth of the defect")
    edge: Quantity = _pos("length", "length over which the depth ramps in at each end (<= width)")
SpallSI = SpallParams.SI


@_with_si("ToothFaultSI")
@dataclass(frozen=True, kw_only=True)
class ToothFaultParams(Params):
    """One tooth of a gear weakened (a crack: the stiffness of every tooth pair it forms scaled by
    ``stiffness_factor``) or missing (factor 0), in every mesh the tooth enters."""
    _prefix: ClassVar[str] = "errors.tooth_fault"
    gear: str = _name(_GEAR, _GEAR_TEXT, "the gear with the faulty tooth")
    tooth: int = _param("count", "tooth index 0..z-1 (tooth 0 on the gear's body x axis)", lo=0.0, bound_text=">= 0")
    stiffness_factor: Quantity = _param("dimensionless", "stiffness of the faulty tooth's pairs / healthy (0: missing)",
                                        lo=0.0, hi=1.0, bound_text="in [0, 1]")
ToothFaultSI = ToothFaultParams.SI


_TOOTH_GEAR_TEXT = "a gear name: 'sun', 'ring', 'a1'..'aN' or 'b1'..'bN'"


@_with_si("ToothDeviationSI")
@dataclass(frozen=True, kw_only=True)
class ToothDeviationParams(Params):
    """Deviations of one tooth's flank (or of every tooth) from the perfect involute, ISO 1328-1 quantities,
    along the line of action. ``flank`` "ccw" is the tooth flank that faces the gear's counter-clockwise
    (+θ, forward) side, "cw" the other; "both" sets both. Signs: ``pitch`` + = the flank sits ahead of its
    theoretical position in the counter-clockwise sense (a tooth with "both" at +5 µm is turned 5 µm
    forward: the single pitch deviations f_pt are the differences of neighbouring teeth's values);
    ``slope`` f_Hα + = more material at the tip than at the start of the active profile; ``form`` f_fα:
    the range of the deviation left after removing its straight line, + = more material mid-profile
    ("barrel") or towards the tip ("s"). Entries for the same tooth and flank add up."""
    _prefix: ClassVar[str] = "errors.tooth"
    gear: str = _name(_GEAR, _TOOTH_GEAR_TEXT, "the gear whose tooth deviates")
    tooth: Any = _param("tooth", 'tooth index 0..z-1 (tooth 0 on the gear\'s body x axis) or "all"')
    flank: str = _param("choice", "which flank of the tooth", choices=("ccw", "cw", "both"))
    pitch: Quantity = _param("length", "cumulative pitch deviation F_pk: where the flank sits, + ahead "
                                       "counter-clockwise", default="0 um")
    slope: Quantity = _param("length", "profile slope deviation f_Ha (+: material towards the tip)", default="0 um")
    form: Quantity = _param("length", "profile form deviation f_fa, the range of the curved part (+: material "
                                      "mid-profile for 'barrel', towards the tip for 's')", default="0 um")
    form_shape: str = _param("choice", "shape of the form deviation: barrel (a parabola) or s (a cubic)",
                             choices=("barrel", "s"), default="barrel")
ToothDeviationSI = ToothDeviationParams.SI


@_with_si("FlankClassSI")
@dataclass(frozen=True, kw_only=True)
class FlankClassParams(Params):
    """Tooth deviations drawn for gears of an ISO 1328-1:2013 flank tolerance class (``components.tolerances``):
    every tooth flank's cumulative pitch deviation, profile slope and profile form deviation, normal with
    the class's tolerance at 3σ (per tooth), the profile deviations split into a part common to every tooth
    of a gear flank (``systematic_share`` of their variance: one grinding set-up) and a tooth-to-tooth part.
    Every gear draws its own teeth (reproducibly from ``seed`` and its name)."""
    _prefix: ClassVar[str] = "errors.flank_class"
    gear: str = _name(r"all|planets|" + _GEAR, "'all', 'planets' or " + _TOOTH_GEAR_TEXT, "the gears of this class")
    grade: int = _param("count", "ISO 1328-1:2013 flank tolerance class 1 (finest) .. 11", lo=1, hi=11,
                        bound_text="in 1..11")
    seed: int = _param("count", "seed of the random draw", lo=0, bound_text=">= 0")
    systematic_share: Quantity = _param("dimensionless", "share of the profile deviations' variance common to every "
                                                         "tooth of a gear flank", lo=0.0, hi=1.0,
                                        bound_text="in [0, 1]")
FlankClassSI = FlankClassParams.SI


@_with_si("ErrorsSI")
@dataclass(frozen=True, kw_only=True)
class ErrorsParams(Params):
    """Manufacturing errors and faults of the machine (docs/model.md §11); every list empty: the perfect
    machine. In TOML each entry is a table, e.g. ``[[errors.pinhole]]`` with ``planet``, ``radial``,
    ``tangential`` (README, "A damaged machine")."""
    _prefix: ClassVar[str] = "errors"
    pinhole: tuple = _entries(PinholeErrorParams, "carrier pinhole position errors")
    runout: tuple = _entries(RunoutParams, "gear eccentricities")
    roller_diameter: tuple = _entries(RollerDiameterErrorParams, "roller diameter deviations")
    spall: tuple = _entries(SpallParams, "raceway spalls")
    tooth_fault: tuple = _entries(ToothFaultParams, "cracked or missing teeth")
    tooth: tuple = _entries(ToothDeviationParams, "tooth flank deviations, tooth by tooth")
    flank_class: tuple = _entries(FlankClassParams, "tooth deviations drawn for an ISO 1328-1 flank tolerance class")

    @property
    def perfect(self) -> bool:
        return not any(getattr(self, f.name) for f in _param_fields(type(self)))
ErrorsSI = ErrorsParams.SI


@_with_si("DPGTSI")
@dataclass(frozen=True, kw_only=True)
class DPGTParams(Params):
    """The whole machine: gears, planet bearing (with cage), lubricant, supports, meshes, operating
    point and gravity (magnitude, along −Y of the fixed frame).

    si() has one section per field plus ``layout`` (:class:`geometry.Layout`); ``support`` gains
    ring_torsional_stiffness and ``operating`` the fields of :class:`geometry.Kinematics`. It raises
    ParameterError if the gears cannot be laid out: run :func:`geometry.check_design` first.
    """

    _prefix: ClassVar[str] = ""
    gears: GearSetParams = _nested(GearSetParams, "gear set")
    bearing: BearingParams = _nested(BearingParams, "planet bearing")
    lubricant: LubricantParams = _nested(LubricantParams, "lubricant")
    support: SupportParams = _nested(SupportParams, "supports")
    mesh: MeshParams = _nested(MeshParams, "meshes")
    operating: OperatingPoint = _nested(OperatingPoint, "operating point")
    rig: RigParams = _nested(RigParams, "test rig: carrier speed drive and load ramp")
    gravity: Quantity = _nonneg("acceleration", "gravitational acceleration (0 switches gravity off)")
    errors: ErrorsParams = _nested(ErrorsParams, "manufacturing errors and faults (every list empty: the perfect machine)")

    _si_derived: ClassVar[tuple] = (
        Derived("gears", GearSetSI, "gear set; planet inertias resolved with the bearing bore"),
        Derived("support", DPGTSupportSI, "supports and the ring's torsional stiffness"),
        Derived("mesh", MeshSI, "meshes, backlash resolved per mesh type"),
        Derived("operating", DPGTOperatingSI, "operating point with its nominal speeds and torques"),
        Derived("layout", geo.Layout, "planet positions, meshes, phases (geometry.Layout)"),
    )

    def _si_values(self, v):
        gears = _planets_with_bore(self.gears, v["gears"], v["bearing"].outer_raceway_radius)
        sup = v["support"]
        support = DPGTSupportSI(**_fields_of(sup), ring_torsional_stiffness=(
            sup.ring_tangential_stiffness * gears.ring.pitch_radius ** 2))
        lay = geo.layout(self, gears_si=gears, mesh_si=v["mesh"])
        mesh = v["mesh"].replace(**{f"backlash_{k}": m.backlash for k, m in lay.meshes.items()})
        op = v["operating"]
        kin = geo.kinematics(gears.sun.teeth, gears.inner_planet.teeth, gears.outer_planet.teeth,
                             gears.ring.teeth, op.carrier_speed, op.output_power)
        operating = DPGTOperatingSI(**{**_fields_of(op), **_fields_of(kin)})
        return dict(gears=gears, support=support, mesh=mesh, operating=operating, layout=lay)
DPGTSI = DPGTParams.SI


def _planets_with_bore(gears: GearSetParams, g: "GearSetSI", bore: float) -> "GearSetSI":
    """The planets' inertia rule in a DPGT: an annulus m (r^2 + r_bore^2)/2, the bore being the
    bearing's outer raceway (given inertias stay)."""
    for name in ("inner_planet", "outer_planet"):
        if getattr(gears, name).inertia is None:
            gp = getattr(g, name)
            g = g.replace(**{name: gp.replace(inertia=0.5 * gp.mass * (gp.pitch_radius ** 2 + bore ** 2))})
    return g


@_with_si("BearingRigSI")
@dataclass(frozen=True, kw_only=True)
class BearingRigParams(Params):
    """The single-bearing test rig (:func:`components.rig.build_bearing_rig`, docs/model.md §10.5): a
    planet-like outer ring on the bearing, its spin held by a speed drive, the radial load ramped in and
    a settling dashpot from the ring to ground. The ramp and the dashpot do not change the static solution."""

    _prefix: ClassVar[str] = "bearing_rig"
    ring_mass: Quantity = _pos("mass", "outer ring mass")
    ring_radius: Quantity = _pos("length", "outer ring radius for its inertia rule")
    ring_inertia: Quantity | None = _rule("inertia", "assumed", "solid disc of the ring radius, m r^2/2")
    drive_bandwidth: Quantity = _pos("frequency", "bandwidth of the ring's speed drive")
    drive_damping_ratio: Quantity = _nonneg("dimensionless", "damping ratio of the ring's speed drive")
    settle_damping_ratio: Quantity = _nonneg("dimensionless", "ring-to-ground dashpot as a fraction of the critical "
                                                              "damping of the ring's radial mode on the loaded bearing")
    load_ramp_periods: Quantity = _nonneg("dimensionless", "length of the load ramp in periods of that radial mode")
    gravity: Quantity = _nonneg("acceleration", "gravitational acceleration along -y (scene option gravity)")

    _si_derived: ClassVar[tuple] = (
        Derived("ring_inertia", float, "outer ring polar moment of inertia [kg m^2] (given, or the rule)"),)

    def _si_values(self, v):
        if v["ring_inertia"] is not None:
            return {}
        return dict(ring_inertia=0.5 * v["ring_mass"] * v["ring_radius"] ** 2)
BearingRigSI = BearingRigParams.SI


# ---------------------------------------------------------------------------------------------
# dotted paths: overrides, listing, TOML
# ---------------------------------------------------------------------------------------------
def flatten(params: Params, prefix: str = "") -> dict[str, Any]:
    """{dotted path: value} of every leaf parameter (nested objects expanded)."""
    out: dict[str, Any] = {}
    for f in _param_fields(type(params)):
        v = getattr(params, f.name)
        path = f"{prefix}{f.name}"
        if isinstance(v, Params):
            out.update(flatten(v, path + "."))
        else:
            out[path] = v
    return out


def parameter_names(params: Params) -> list[str]:
    """All dotted leaf paths accepted by :func:`with_overrides`."""
    return list(flatten(params))


def _unknown(params: Params, key: str, path: str) -> ParameterError:
    names = [f"{path}{n}" for n in parameter_names(params)]
    hint = did_you_mean(f"{path}{key}", names)
    return ParameterError.at(f"{path}{key}", f"unknown parameter{hint}; valid keys: {', '.join(names)}")


def _override(params: Params, overrides: Mapping[str, Any], path: str) -> Params:
    nested_fields = {f.name for f in _param_fields(type(params)) if f.metadata["spec"].kind == "nested"}
    leaf_fields = {f.name for f in _param_fields(type(params))} - nested_fields
    changes: dict[str, Any] = {}
    groups: dict[str, dict[str, Any]] = {}
    for key, value in overrides.items():
        head, _, rest = key.partition(".")
        if rest and head in nested_fields:
            groups.setdefault(head, {})[rest] = value
        elif not rest and (head in leaf_fields or head in nested_fields):
            changes[head] = value
        else:
            raise _unknown(params, key, path)
    for head, sub in groups.items():
        base = changes.pop(head, getattr(params, head))
        if not isinstance(base, Params):
            base = _convert(type(params)._spec(head), f"{path}{head}", base)
        changes[head] = _override(base, sub, f"{path}{head}.")
    try:
        return params.replace(**changes)
    except ParameterError as e:
        raise e.renamed(type(params)._prefix, path.rstrip(".")) from None


def with_overrides(params: Params, overrides: Mapping[str, Any] | None) -> Params:
    """A copy of ``params`` with dotted-path overrides, e.g. ``{"bearing.clearance": "30 um",
    "gears.planets": 4, "gears.sun.teeth": 29}``; values are checked like at construction and
    overridden values are tagged ``user`` (unless given as :class:`Sourced`)."""
    if not overrides:
        return params
    return _override(params, dict(overrides), "")


def _describe_value(v) -> str:
    if isinstance(v, Quantity):
        return f"{v:~P}"
    if isinstance(v, tuple):                 # a list of entries (e.g. manufacturing errors)
        return "; ".join(", ".join(f"{f.name}={_describe_value(getattr(e, f.name))}" for f in _param_fields(type(e)))
                         for e in v) or "none"
    return repr(v) if isinstance(v, str) else str(v)


def _si_at(view, path: str):
    for part in path.split("."):
        view = view[part]
    return view


def _unit_text(u) -> str:
    text = f"{u:~P}"
    return text or "1"


def parameter_rows(params: Params) -> list[dict[str, str]]:
    """Every leaf parameter as text: ``key`` (dotted), ``value`` and ``unit`` (a value left to its rule resolved, in
    SI), ``source`` (its tag, ``[paper]`` ...), ``note`` (the source's note) and ``meaning`` (the field's one-line
    description). What :func:`describe` and ``dpgt params`` show."""
    try:
        si = params.si()
    except ParameterError:
        si = None
    rows = []
    for path, v in flatten(params).items():
        *owner_path, name = path.split(".")
        owner = params
        for p in owner_path:
            owner = getattr(owner, p)
        spec = type(owner)._spec(name)
        if v is None:
            resolved = _si_at(si, path) if si is not None else None
            kind = KINDS.get(spec.kind)
            value = f"{resolved:.6g}" if isinstance(resolved, (int, float)) else "(rule)"
            unit = _unit_text(Quantity(1.0, kind.si_unit).units) if kind is not None and resolved is not None else ""
        elif isinstance(v, Quantity):
            value, unit = f"{v.magnitude:g}", _unit_text(v.units)
        else:
            value, unit = _describe_value(v), ""
        src = owner.source(name)
        rows.append({"key": path, "value": value, "unit": unit, "source": f"[{src.tag}]", "note": src.note,
                     "meaning": " ".join(spec.doc.split()), "shown": (
                         f"{_si_at(si, path):.6g} (SI)" if v is None and si is not None and _si_at(si, path) is not None
                         else "(rule)" if v is None else _describe_value(v))})
    return rows


def describe(params: Params) -> str:
    """A table: dotted path, value (rule-based values resolved, in SI), source tag and note."""
    rows = [(r["key"], r["shown"], f"{r['source']}" + (f" {r['note']}" if r["note"] else "")) for r in parameter_rows(params)]
    w0 = max(len(r[0]) for r in rows)
    w1 = max(len(r[1]) for r in rows)
    return "\n".join(f"{a:<{w0}}  {b:<{w1}}  {c}" for a, b, c in rows)


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, Quantity):
        if v.dimensionless and str(v.units) == "dimensionless":
            return repr(float(v.magnitude))
        return json.dumps(format_quantity(v))
    return json.dumps(str(v))


def to_toml(params: Params) -> str:
    """The parameters as TOML (dotted tables, values as exact unit strings, sources as comments).
    Values left None (following their rule) are written as comments: loading keeps the base's value."""
    lines: list[str] = []

    def emit(obj: Params, path: str):
        subs, lists = [], []
        for f in _param_fields(type(obj)):
            v = getattr(obj, f.name)
            if isinstance(v, Params):
                subs.append((f.name, v))
            elif f.metadata["spec"].kind == "entries":
                lists.append((f.name, v))
            elif v is None:
                lines.append(f"# {f.name}: {obj.source(f.name)}")
            else:
                lines.append(f"{f.name} = {_toml_value(v)}  # {obj.source(f.name)}")
        for name, entries in lists:          # arrays of tables: [[path.name]] per entry
            for entry in entries:
                lines.append("")
                lines.append(f"[[{path}{name}]]")
                emit(entry, f"{path}{name}.")
        for name, sub in subs:
            lines.append("")
            lines.append(f"[{path}{name}]")
            emit(sub, f"{path}{name}.")

    emit(params, "")
    return "\n".join(lines) + "\n"


def overrides_from_toml(text: str) -> dict[str, Any]:
    """Parse TOML text into {dotted path: value} (nested tables flattened)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ParameterError(f"invalid TOML: {e}") from None
    out: dict[str, Any] = {}

    def walk(d: Mapping, prefix: str):
        for k, v in d.items():
            if isinstance(v, Mapping):
                walk(v, f"{prefix}{k}.")
            else:
                out[f"{prefix}{k}"] = v

    walk(data, "")
    return out
