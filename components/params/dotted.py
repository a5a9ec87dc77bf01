"""Dotted paths over a tree of parameter objects: overrides (``with_overrides``), the list of keys, the table
``dpgt params`` shows, TOML out and in. They work on any :class:`Params` tree (the whole machine, the bearing
rig, one section)."""
from __future__ import annotations

import json
import tomllib
from typing import Any, Mapping, TypeVar

from ..names import did_you_mean
from ..units import KINDS, ParameterError, Quantity, format_quantity, unit_text
from ._machinery import Params, Span, convert, param_fields

__all__ = ["with_overrides", "parameter_names", "flatten", "describe", "parameter_rows", "to_toml",
           "overrides_from_toml", "spans"]

_P = TypeVar("_P", bound=Params)


def flatten(params: Params, prefix: str = "") -> dict[str, Any]:
    """{dotted path: value} of every leaf parameter (nested objects expanded)."""
    out: dict[str, Any] = {}
    for f in param_fields(type(params)):
        v = getattr(params, f.name)
        path = f"{prefix}{f.name}"
        if isinstance(v, Params):
            out.update(flatten(v, path + "."))
        else:
            out[path] = v
    return out


def spans(params: Params) -> dict[str, Span]:
    """{dotted path: :class:`Span`} of every parameter that holds the assumed value its range was declared with
    (``assumed(value, note, span=Span(...))``; a value overridden since is the user's: it has no range)."""
    out: dict[str, Span] = {}
    for path in flatten(params):
        *owner_path, name = path.split(".")
        owner = params
        for p in owner_path:
            owner = getattr(owner, p)
        span = owner.source(name).span
        if span is not None:
            out[path] = span
    return out


def parameter_names(params: Params) -> list[str]:
    """All dotted leaf paths accepted by :func:`with_overrides`."""
    return list(flatten(params))


def _unknown(params: Params, key: str, path: str) -> ParameterError:
    names = [f"{path}{n}" for n in parameter_names(params)]
    hint = did_you_mean(f"{path}{key}", names)
    where = (f"the keys of {path.rstrip('.')}: `dpgt params --grep {path.rstrip('.')}`" if path else
             "every key: `dpgt params`")
    if not hint and len(names) <= 12:          # a short list helps more than a command
        where = f"valid keys: {', '.join(names)}"
    return ParameterError.at(f"{path}{key}", f"unknown parameter{hint}; {where}")


def _override(params: _P, overrides: Mapping[str, Any], path: str) -> _P:
    nested_fields = {f.name for f in param_fields(type(params)) if f.metadata["spec"].kind == "nested"}
    leaf_fields = {f.name for f in param_fields(type(params))} - nested_fields
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
            base = convert(type(params)._spec(head), f"{path}{head}", base)
        changes[head] = _override(base, sub, f"{path}{head}.")
    try:
        return params.replace(**changes)
    except ParameterError as e:
        raise e.renamed(type(params)._prefix, path.rstrip(".")) from None


def with_overrides(params: _P, overrides: Mapping[str, Any] | None) -> _P:
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
        return "; ".join(", ".join(f"{f.name}={_describe_value(getattr(e, f.name))}" for f in param_fields(type(e)))
                         for e in v) or "none"
    return repr(v) if isinstance(v, str) else str(v)


def _si_at(view, path: str):
    for part in path.split("."):
        view = view[part]
    return view


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
            unit = unit_text(Quantity(1.0, kind.si_unit).units) if kind is not None and resolved is not None else ""
        elif isinstance(v, Quantity):
            value, unit = f"{v.magnitude:g}", unit_text(v.units)
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
        for f in param_fields(type(obj)):
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
