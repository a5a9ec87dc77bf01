"""The machinery behind the parameter classes: field specifications, conversion and checks, provenance, the
``Params`` base and the declaration of SI classes.

What it is for: a parameter class (``components/params/gears.py`` ...) is a frozen, keyword-only dataclass whose
fields are declared with the helpers here (:func:`param`, :func:`positive`, :func:`nonneg`, :func:`rule`,
:func:`nested`, :func:`entries`, :func:`named`: kind, bounds, one-line meaning); :class:`Params` converts and
checks every value at construction, keeps its :class:`Source` and gives ``si()``. Its SI class is written out
next to it with :func:`si_of` (typed fields a type checker and an IDE see; values ``si()`` resolves or adds
declared with :func:`computed`), and checked against the parameter fields when the module is imported.

Code that *uses* parameters (builders, studies, tests) need not touch this module: it imports the parameter
classes and the tools (``with_overrides``, ``to_toml``, ...) from :mod:`components.params`. A new parameter class
needs only the field helpers, :class:`Params`, :func:`si_of` and :func:`computed`.
"""
from __future__ import annotations

import dataclasses
import functools
import math
import numbers
import re
from dataclasses import MISSING, dataclass, field
from types import MappingProxyType
from typing import (TYPE_CHECKING, Any, Callable, ClassVar, ForwardRef, Generic, Mapping, Self, TypeVar,
                    dataclass_transform, get_args, get_origin, get_type_hints)

import numpy as np

from ..names import did_you_mean
from ..units import ParameterError, Quantity, quantity, to_si

__all__ = ["Source", "Sourced", "Span", "paper", "derived", "assumed", "Spec", "param", "positive", "nonneg", "rule", "nested",
           "entries", "named", "param_fields", "convert", "Params", "SI", "Derived", "computed", "si_of", "si_extends",
           "fields_of"]


# ---------------------------------------------------------------------------------------------
# provenance
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Span:
    """The range an [assumed] value may plausibly take, with its basis: what a sensitivity study
    (``scenarios.sensitivity``) varies it over. ``low`` < ``high`` in the parameter's kind (strings such as
    ``"1e6 N/m"`` are converted and checked against the field's bounds when the parameter is built, and the
    assumed value must lie inside); ``log``: spread evenly in the logarithm (a range over decades, e.g. a
    support from floating to rigid), else evenly in the value."""

    low: Any
    high: Any
    basis: str
    log: bool = False


@dataclass(frozen=True)
class Source:
    """Where a value comes from: tag ``paper`` | ``derived`` | ``assumed`` | ``user`` | ``default``.

    ``value`` is the value the tag was given to (filled in automatically); a parameter whose current
    value differs from it is reported as ``user``. ``span``: the range of an assumed value (:class:`Span`), or None.
    """

    tag: str
    note: str = ""
    value: Any = field(default=None, compare=False, repr=False)
    span: Span | None = field(default=None, compare=False, repr=False)

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


def assumed(value, note: str = "", span: Span | None = None) -> Sourced:
    """An engineering estimate; say its basis in ``note`` and, where a study should vary it, its plausible range in
    ``span`` (:class:`Span`: low, high, basis, log)."""
    return Sourced(value, Source("assumed", note, span=span))


_USER = Source("user")


# ---------------------------------------------------------------------------------------------
# field specifications
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Spec:
    """What a parameter field accepts, kept in the field's metadata (``f.metadata["spec"]``)."""

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


def param(kind: str, doc: str = "", *, default=MISSING, **kw) -> Any:
    """A parameter field of ``kind`` (a units kind such as ``"length"``, or ``"count"``, ``"sign"``, ``"flag"``,
    ``"choice"``, ``"tooth"``) with its one-line meaning and optional bounds (``lo``, ``hi``, ``bound_text``)."""
    return field(default=default, metadata={"spec": Spec(kind, doc=doc, **kw)})


def positive(kind: str, doc: str = "", **kw) -> Any:
    """A parameter field > 0."""
    return param(kind, doc, lo=0.0, lo_open=True, bound_text="> 0", **kw)


def nonneg(kind: str, doc: str = "", **kw) -> Any:
    """A parameter field >= 0."""
    return param(kind, doc, lo=0.0, bound_text=">= 0", **kw)


def rule(kind: str, tag: str, note: str, doc: str = "") -> Any:
    """An optional positive value that follows a rule when None (``tag``, ``note``: the rule's source); the
    SI class declares the resolved value with :func:`computed`."""
    return param(kind, doc or note, default=None, lo=0.0, lo_open=True, bound_text="> 0", optional=True,
                 rule=Source(tag, note))


def nested(cls: type, doc: str = "") -> Any:
    """A nested parameter object of class ``cls`` (a TOML table)."""
    return param("nested", doc, cls=cls)


def entries(cls: type, doc: str = "") -> Any:
    """A list of tables, each one ``cls`` (e.g. one manufacturing error); empty by default."""
    return param("entries", doc, cls=cls, default=())


def named(pattern: str, what: str, doc: str = "") -> Any:
    """A name matching the regular expression ``pattern`` (``what``: how the expected names read in an error)."""
    return param("name", doc, pattern=pattern, bound_text=what)


def _check_bounds(spec: Spec, name: str, x: float, shown) -> None:
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


def convert(spec: Spec, name: str, value):
    """Check and convert one user value for a field (``name``: its dotted path, for the error message)."""
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
                fs = param_fields(spec.cls)
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


def _convert_entries(spec: Spec, name: str, value) -> tuple:
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
            raise ParameterError.at(path, f"expected a table of {[f.name for f in param_fields(spec.cls)]}, "
                                          f"got {type(item).__name__}")
        try:
            out.append(spec.cls(**item))
        except ParameterError as e:
            raise e.renamed(spec.cls._prefix, path) from None
        except TypeError:
            fs = param_fields(spec.cls)
            unknown = sorted(set(item) - {f.name for f in fs})
            missing = [f.name for f in fs if f.name not in item and f.default is MISSING]
            hint = did_you_mean(unknown[0], [f.name for f in fs]) if unknown else ""
            raise ParameterError.at(path, f"needs {missing} (unknown keys: {unknown}{hint})") from None
    return tuple(out)


def _checked_span(spec: Spec, name: str, span: Span | None, value) -> Span | None:
    """``span`` with its ends converted like a value of the field (``name``: its dotted path), checked: both inside
    the field's bounds, low < high (a log span: low > 0), the value between them."""
    if span is None:
        return None
    if not isinstance(span, Span):
        raise ParameterError.at(name, f"a range must be a Span(low, high, basis), got {span!r}")
    try:
        converted, lo, hi = _converted_span(spec, name, span)
    except TypeError:                   # unhashable ends (e.g. numpy values): convert them each time
        converted, lo, hi = _converted_span.__wrapped__(spec, name, span)
    x = to_si(value) if value is not None else None
    if x is not None and not lo <= x <= hi:
        raise ParameterError.at(name, f"the value {value} lies outside its range [{span.low}, {span.high}]")
    return converted


@functools.lru_cache(maxsize=1024)
def _converted_span(spec: Spec, name: str, span: Span) -> tuple[Span, float, float]:
    """(the span with its ends converted, low and high in SI), checked; cached: the reference machine's ranges are
    declared anew each time it is built, and pint's parsing would cost a build ~30 %."""
    if spec.kind in ("count", "sign", "flag", "choice", "name", "tooth", "nested", "entries"):
        raise ParameterError.at(name, f"a range needs a quantity; this parameter is a {spec.kind}")
    low, high = convert(spec, f"{name} (range low)", span.low), convert(spec, f"{name} (range high)", span.high)
    lo, hi = to_si(low), to_si(high)
    if not lo < hi:
        raise ParameterError.at(name, f"empty range: low {span.low!r} must be below high {span.high!r}")
    if span.log and not lo > 0.0:
        raise ParameterError.at(name, f"a log range needs low > 0, got {span.low!r}")
    if not span.basis.strip():
        raise ParameterError.at(name, "a range needs its basis (why these ends)")
    return Span(low, high, span.basis, bool(span.log)), lo, hi


def param_fields(cls) -> tuple:
    """The parameter fields of a parameter class (those declared with a :class:`Spec`), in order."""
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


def fields_of(obj) -> dict:
    """{name: value} of a dataclass, one level (nested objects kept as they are)."""
    return {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj)}


# ---------------------------------------------------------------------------------------------
# SI classes: one frozen dataclass per parameter class, written out next to it and checked against it
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Derived:
    """A value ``si()`` computes: a field of the SI class declared with :func:`computed` (name, type, doc);
    ``ParamsClass._si_derived`` lists them. A name that is also a parameter field is that parameter's
    rule-resolved value (its SI type wins)."""

    name: str
    type: Any
    doc: str


@dataclass(frozen=True)
class SI:
    """Base of the SI classes (``GearSI``, ``BearingSI``, ..., ``DPGTSI``): frozen, keyword-only
    dataclasses of SI floats, ints, strings, flags and nested SI objects."""

    def replace(self, **changes) -> Self:
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict:
        """{name: value}, nested SI objects as dicts (other objects, e.g. the layout, as they are)."""
        return {f.name: _si_dict(getattr(self, f.name)) for f in dataclasses.fields(self)}

    def __getitem__(self, name: str) -> Any:
        """Field by name (for code that picks a field from a string, e.g. ``si.gears[name]``)."""
        if name not in self.__dataclass_fields__:
            raise KeyError(name)
        return getattr(self, name)

    if not TYPE_CHECKING:      # hidden from type checkers: with it every misspelt field would type-check
        def __getattr__(self, name):   # only reached for names that are not fields: say what there is
            if name.startswith("__"):
                raise AttributeError(name)
            raise AttributeError(f"no SI value {name!r} in {type(self).__name__}; available: "
                                 f"{', '.join(self.__dataclass_fields__)}")


def _si_dict(v):
    return v.to_dict() if isinstance(v, SI) else v


def computed(doc: str) -> Any:
    """An SI field that ``si()`` computes: a derived value (a radius, a ratio) or a rule-resolved parameter (then
    its type may differ from the parameter's, e.g. ``float`` for an optional value). ``doc``: its meaning and unit."""
    return field(metadata={"doc": doc, "computed": True})


def _si_type(spec: Spec):
    """The SI type of a parameter field of ``spec``: what its SI class must declare (unless computed)."""
    if spec.kind == "nested":
        return spec.cls.SI
    if spec.kind == "entries":
        return tuple[spec.cls.SI, ...]
    t = {"count": int, "sign": int, "flag": bool, "choice": str, "name": str,
         "tooth": int | str}.get(spec.kind, float)
    return t | None if spec.optional else t


def _si_doc(title: str, items) -> str:
    return title + "\n\nFields (SI units):\n" + "\n".join(f"* ``{n}``: {d}" for n, _, d in items)


def _own_annotations(cls) -> dict[str, Any]:
    """The class's own field annotations, evaluated (the modules use ``from __future__ import annotations``)."""
    hints = get_type_hints(cls)
    return {n: hints[n] for n in cls.__dict__.get("__annotations__", {})}


def _computed_docs(cls) -> dict[str, str]:
    return {n: v.metadata["doc"] for n, v in vars(cls).items()
            if isinstance(v, dataclasses.Field) and v.metadata.get("computed")}


def _finish_si(cls, items: list, title: str):
    """Make ``cls`` the frozen keyword-only dataclass of ``items`` (name, type, doc), each field's doc in its
    metadata, the docstring listing them."""
    for n, _, d in items:
        if n not in vars(cls):
            setattr(cls, n, field(metadata={"doc": d}))
    cls.__annotations__ = {n: t for n, t, _ in items}
    cls = dataclass(frozen=True, kw_only=True)(cls)
    cls.__doc__ = _si_doc(title, items)
    return cls


def _declared_si_name(params_cls) -> str | None:
    """The SI class ``params_cls`` names in its base ``Params["XSI"]`` (what type checkers give ``si()``)."""
    for base in getattr(params_cls, "__orig_bases__", ()):
        if get_origin(base) is Params:
            (arg,) = get_args(base)
            return arg.__forward_arg__ if isinstance(arg, ForwardRef) else getattr(arg, "__name__", str(arg))
    return None


_T = TypeVar("_T")


@dataclass_transform(kw_only_default=True, frozen_default=True, field_specifiers=(computed,))
def si_of(params_cls: type[Params]) -> Callable[[type[_T]], type[_T]]:
    """Class decorator: the decorated class (fields annotated, no defaults) is the SI class of ``params_cls``
    and becomes a frozen keyword-only dataclass; ``params_cls.si()`` returns it.

    It declares every parameter field of ``params_cls``, in order, with its SI type (``float`` for a quantity,
    ``int`` for a count, the nested parameter class's SI class, ``tuple[EntrySI, ...]`` for a list, ``| None``
    for an optional value); then the values ``si()`` adds. A field that ``si()`` resolves or adds is declared
    ``name: type = computed("meaning [unit]")`` and its value comes from ``params_cls._si_values``. Checked here,
    at import: a parameter missing or out of order, a wrong type, or an extra field not computed fails with
    the class and field named."""
    def deco(cls: type[_T]) -> type[_T]:
        if not (isinstance(params_cls, type) and issubclass(params_cls, Params)):
            raise TypeError(f"si_of({params_cls!r}): expected a Params subclass")
        if "SI" in vars(params_cls):
            raise TypeError(f"{params_cls.__name__} already has its SI class {params_cls.SI.__name__}")
        declared = _declared_si_name(params_cls)
        if declared != cls.__name__:
            raise TypeError(f"{params_cls.__name__} must subclass Params[\"{cls.__name__}\"] so that si() is typed "
                            f"{cls.__name__}; it names {declared!r}")
        own, done = _own_annotations(cls), _computed_docs(cls)
        specs = {f.name: f.metadata["spec"] for f in param_fields(params_cls)}
        missing = [n for n in specs if n not in own]
        if missing:
            raise TypeError(f"{cls.__name__} lacks the fields {missing} of {params_cls.__name__}")
        extra = [n for n in own if n not in specs]
        if list(own) != [*specs, *extra]:
            raise TypeError(f"{cls.__name__} must declare the fields of {params_cls.__name__} in their order "
                            f"{list(specs)}, then its computed values; got {list(own)}")
        items = []
        for n, t in own.items():
            if n in done:
                items.append((n, t, done[n]))
                continue
            if n in vars(cls):
                raise TypeError(f"{cls.__name__}.{n}: an SI field takes no default (a value si() computes is "
                                f"declared {n}: T = computed(doc))")
            if n not in specs:
                raise TypeError(f"{cls.__name__}.{n} is no field of {params_cls.__name__}: declare what si() adds "
                                f"as {n}: T = computed(doc)")
            want = _si_type(specs[n])
            if t != want:
                raise TypeError(f"{cls.__name__}.{n} is declared {t!r}, but {params_cls.__name__}.{n} "
                                f"({specs[n].kind}) gives {want!r} (a value si() resolves: computed(doc))")
            items.append((n, t, specs[n].doc))
        title = cls.__doc__ if "__doc__" in vars(cls) and cls.__doc__ else \
            f"SI values of :class:`{params_cls.__name__}`."
        si_cls = _finish_si(cls, items, title)
        params_cls.SI = si_cls
        params_cls._si_derived = tuple(Derived(n, t, d) for n, t, d in items if n in done)
        return si_cls
    return deco


@dataclass_transform(kw_only_default=True, frozen_default=True, field_specifiers=(computed,))
def si_extends(cls: type[_T]) -> type[_T]:
    """Class decorator: an SI class with its base SI class's fields plus computed ones (each
    ``name: type = computed(doc)``): a section as the whole machine sees it (e.g. the operating point with its
    kinematics). Its docstring is the title of the generated field list."""
    base = cls.__mro__[1]
    if not (issubclass(base, SI) and dataclasses.is_dataclass(base)):
        raise TypeError(f"{cls.__name__}: si_extends needs an SI class as the first base, got {base.__name__}")
    own, done = _own_annotations(cls), _computed_docs(cls)
    plain = [n for n in own if n not in done]
    if plain:
        raise TypeError(f"{cls.__name__}: the fields {plain} are not declared with computed(doc)")
    if not cls.__doc__:
        raise TypeError(f"{cls.__name__}: give it a docstring (the title of its field list)")
    return _finish_si(cls, [(n, t, done[n]) for n, t in own.items()], cls.__doc__)


# ---------------------------------------------------------------------------------------------
# base class
# ---------------------------------------------------------------------------------------------
_S = TypeVar("_S", bound=SI)


@dataclass(frozen=True, kw_only=True)
class Params(Generic[_S]):
    """Base of all parameter classes: conversion, provenance, replace, SI view. A parameter class subclasses
    ``Params["ItsSI"]`` (the SI class, declared with :func:`si_of`), so that ``si()`` is typed."""

    _prefix: ClassVar[str] = ""
    SI: ClassVar[type]                      # the SI class, declared with @si_of(this class)
    _si_derived: ClassVar[tuple] = ()       # Derived(...): the SI class's computed fields (set by si_of)
    sources: Mapping[str, Source] = field(default_factory=dict, compare=False, repr=False)

    def __post_init__(self):
        names = {f.name for f in param_fields(type(self))}
        tags: dict[str, Source] = {}
        for key, src in dict(self.sources).items():
            if key not in names:
                raise ParameterError.at(self._path(key), f"source given for an unknown parameter"
                                                         f"{did_you_mean(key, names)}; valid: {sorted(names)}")
            tags[key] = src if isinstance(src, Source) else Source(str(src))
        for f in param_fields(type(self)):
            value = getattr(self, f.name)
            if isinstance(value, Sourced):
                tags[f.name] = value.source
                value = value.value
            value = convert(f.metadata["spec"], self._path(f.name), value)
            object.__setattr__(self, f.name, value)
            src = tags.get(f.name)
            if src is not None and src.value is None:  # remember what the tag was given to
                span = _checked_span(f.metadata["spec"], self._path(f.name), src.span, value)
                tags[f.name] = dataclasses.replace(src, value=value, span=span)
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
        f = next(f for f in param_fields(type(self)) if f.name == name)
        if f.default is not MISSING and _same(convert(spec, name, f.default), value):
            return Source("default", spec.doc)
        return _USER

    @classmethod
    def _spec(cls, name: str) -> Spec:
        for f in param_fields(cls):
            if f.name == name:
                return f.metadata["spec"]
        valid = [f.name for f in param_fields(cls)]
        raise ParameterError.at(cls._path(name), f"unknown parameter{did_you_mean(name, valid)}; valid: {valid}")

    def replace(self, **changes) -> Self:
        """A copy with some fields changed (values converted and checked like at construction)."""
        valid = [f.name for f in param_fields(type(self))]
        for key in changes:
            if key not in valid:
                raise ParameterError.at(self._path(key), f"unknown parameter{did_you_mean(key, valid)}; valid: {valid}")
        return dataclasses.replace(self, **changes)

    def si(self) -> _S:
        """All values in SI units as a ``type(self).SI`` (rule-based values resolved, derived values
        added). Computed once per object (parameter objects are immutable)."""
        cached = self.__dict__.get("_si_cache")
        if cached is None:
            base = {f.name: _to_si_value(getattr(self, f.name)) for f in param_fields(type(self))}
            cached = self.SI(**{**base, **self._si_values(base)})
            object.__setattr__(self, "_si_cache", cached)
        return cached

    def _si_values(self, v: dict) -> dict:
        """Rule-resolved and derived values (the SI class's computed fields) from the fields' SI values ``v``."""
        return {}


def _to_si_value(v):
    if isinstance(v, Params):
        return v.si()
    if isinstance(v, tuple):
        return tuple(_to_si_value(x) for x in v)
    return to_si(v) if isinstance(v, Quantity) else v
