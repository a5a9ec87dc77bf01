"""Operating points as data: one grammar for the source's four conditions and a user's own points.

A point is a speed (of the carrier or the sun), a load (a power or a torque; its sign says driving or braking), a
direction (forward/reverse; optional: a study that sweeps the directions then runs both), an oil temperature
(optional: else the machine's ``lubricant.temperature``) and a name. The source's conditions 1–4
(:data:`components.presets.CONDITIONS`) are the named presets ``1``–``4``: a case of a preset builds its parameters
exactly as before (same folder ``c3_forward``, same fingerprint), a user point its own from the machine.

Where points come from (:func:`study_points`):

* ``--conditions 1,3`` — presets;
* ``--operating "cruise: 1500 rpm, 120 kW"`` (repeatable; :func:`parse_point`): items separated by commas, each
  read by its unit — a speed (``rpm``, ``rad/s``; ``sun`` before or after it: the sun's speed, else the
  carrier's; a negative speed turns in reverse), a power (``kW``) or a torque (``N*m``: on the shaft whose speed is
  given; power = torque × that shaft's speed, the train lossless), ``forward``/``reverse``, an oil temperature
  (``degC``, optionally after the word ``oil``); ``name:`` in front (default ``p1``, ``p2``… in order);
* ``[[operating_point]]`` tables in the ``--params`` file, keys ``name``, ``carrier_speed`` or ``sun_speed``,
  ``power`` or ``torque``, ``direction``, ``oil_temperature``;
* a ``--params`` file's own ``[operating]`` table (``carrier_speed``, ``output_power``, ``direction``) — the machine's
  point, named after the file — when nothing else names a point.

A ``--set operating.*`` (or ``lubricant.temperature`` beside a point's oil temperature) that would change a point
is refused in one line: it would relabel the run (a folder named for one point holding another).
"""
from __future__ import annotations

import hashlib
import math
import re
import tomllib
from dataclasses import asdict, dataclass, replace
from pathlib import Path

from components.geometry import speed_ratio
from components.params import overrides_from_toml
from components.presets import CONDITIONS
from components.units import ParameterError, quantity, to_si

__all__ = ["Point", "parse_point", "preset", "points_from_toml", "file_overrides", "study_points", "point_overrides",
           "check_oil_temperature", "checked_point", "machine_identity", "points_of", "machine_overrides",
           "point_words", "file_without", "point_label", "point_tag", "point_order", "OIL_RANGE_C",
           "OIL_MIN_VISCOSITY"]

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_.\-]*$")
_WORDS = {"forward", "reverse"}

# the oil temperatures a point may ask for: the lubricant's Walther line (ASTM D341) is fitted between 40 and 100 degC
# and read at the point's temperature; ASTM D341's simple form (Z = nu + 0.7) holds down to nu = 2 mm^2/s, below
# which the line is refused; and a mineral oil's range of continuous service, from near its pour point to its
# oxidation limit, is taken as 0-150 degC [assumed] (a data sheet's own range, where known, is the better bound)
OIL_RANGE_C = (0.0, 150.0)
OIL_MIN_VISCOSITY = 2.0e-6      # m^2/s: ASTM D341's Walther form with the constant 0.7


@dataclass(frozen=True)
class Point:
    """One operating point as plain data (strings with their units, as the user gave them: it travels to a Dask
    worker and converts there). ``condition``: the preset 1–4 it is (None: a user point)."""
    name: str
    speed: str | None = None          # magnitude with its unit ("1500 rpm"); None only for a preset
    shaft: str = "carrier"            # whose speed: "carrier" or "sun"
    load: str | None = None           # "120 kW" or "800 N*m"; negative: braking
    direction: str | None = None      # None: the study's --directions
    oil_temperature: str | None = None
    condition: int | None = None

    @property
    def is_preset(self) -> bool:
        return self.condition is not None

    def as_dict(self) -> dict:
        return {k: v for k, v in asdict(self).items() if v is not None}


def preset(condition: int) -> Point:
    """The source's operating condition ``condition`` (1–4) as a point named by its number."""
    if condition not in CONDITIONS:
        raise ParameterError.at("--conditions", f"takes 1, 2, 3 and/or 4 (docs/parameters.md), got {condition!r}")
    speed, power = CONDITIONS[condition]
    return Point(name=str(condition), speed=f"{speed:~P}", load=f"{power:~P}", condition=condition)


def _quantity_kind(text: str):
    """(kind, si value) of one item of a point: a speed, power, torque or temperature, else None."""
    for kind in ("angular_velocity", "power", "torque", "temperature"):
        try:
            return kind, to_si(quantity("x", text, kind))
        except (ParameterError, ValueError, TypeError):
            continue
    return None


def parse_point(text: str, default_name: str = "p1", where: str = "--operating") -> Point:
    """A point from its text (module docstring), e.g. ``"cruise: 1500 rpm, 120 kW, reverse, oil 80 degC"``; a
    ParameterError naming ``where`` and the item otherwise."""
    raw = str(text).strip()
    name = default_name
    m = re.match(r"^\s*([^:,]*?)\s*:(.*)$", raw)          # a name (checked below) before the first colon
    if m:
        name, raw = m.group(1), m.group(2)
    items = [x.strip() for x in raw.split(",") if x.strip()]
    if not items:
        raise ParameterError.at(where, f"expected 'NAME: SPEED, POWER or TORQUE[, forward|reverse][, oil TEMP]' "
                                       f"(e.g. \"cruise: 1500 rpm, 120 kW\"), got {text!r}")
    fields: dict = {"name": name}
    for item in items:
        low = item.lower()
        if low in _WORDS:
            _once(fields, "direction", low, where, text)
            continue
        shaft = "carrier"
        for word in ("sun", "carrier"):
            if low.startswith(word + " ") or low.endswith(" " + word):
                shaft, item = word, (item[len(word):] if low.startswith(word) else item[:-len(word)]).strip()
                break
        if item.lower().startswith("oil "):
            item = item[4:].strip()
        kind = _quantity_kind(item)
        if kind is None:
            raise ParameterError.at(where, f"{item!r} in {text!r} is not a speed (rpm), a power (kW), a torque (N*m), "
                                           f"an oil temperature (degC) or forward/reverse")
        k, v = kind
        if k == "angular_velocity":
            _once(fields, "speed", item, where, text)
            fields["shaft"] = shaft
        elif k in ("power", "torque"):
            _once(fields, "load", item, where, text)
        else:
            _once(fields, "oil_temperature", item, where, text)
    return checked_point(Point(**fields), where)


def _once(fields: dict, key: str, value, where: str, text: str) -> None:
    if key in fields:
        raise ParameterError.at(where, f"{text!r} gives the {key.replace('_', ' ')} twice ({fields[key]!r}, {value!r})")
    fields[key] = value


def checked_point(p: Point, where: str) -> Point:
    """A point whose name is a folder-safe word, with a speed and a load (a preset's numbers are its own)."""
    if not _NAME.match(p.name) or p.name.isdigit():
        raise ParameterError.at(where, f"a point's name is a word of letters, digits, '_', '-' or '.' starting with a "
                                       f"letter (1-4 are the source's conditions), got {p.name!r}")
    if p.speed is None or p.load is None:
        missing = "a speed (e.g. 1500 rpm)" if p.speed is None else "a power or a torque (e.g. 120 kW)"
        raise ParameterError.at(where, f"point {p.name!r} needs {missing}")
    w = to_si(quantity(f"{where} {p.name} speed", p.speed, "angular_velocity"))
    if not math.isfinite(w):
        raise ParameterError.at(where, f"point {p.name!r}: the speed must be finite, got {p.speed!r}")
    if w < 0:        # a negative speed turns the other way
        if p.direction == "forward":
            raise ParameterError.at(where, f"point {p.name!r}: a negative speed ({p.speed}) turns in reverse, but "
                                           f"the point says forward")
        mag = p.speed.strip()[1:].strip()
        p = replace(p, speed=mag, direction="reverse")
    if p.shaft not in ("carrier", "sun"):
        raise ParameterError.at(where, f"point {p.name!r}: the speed is the carrier's or the sun's, got {p.shaft!r}")
    if p.direction is not None and p.direction not in _WORDS:
        raise ParameterError.at(where, f"point {p.name!r}: direction is forward or reverse, got {p.direction!r}")
    return p


_TOML_KEYS = {"name", "carrier_speed", "sun_speed", "power", "torque", "direction", "oil_temperature"}


def points_from_toml(path) -> list[Point]:
    """The ``[[operating_point]]`` tables of the TOML file ``path`` (module docstring), in order."""
    data = _toml(path)
    tables = data.get("operating_point", [])
    if isinstance(tables, dict):
        tables = [tables]
    out = []
    for i, t in enumerate(tables):
        where = f"{path} [[operating_point]] #{i + 1}"
        bad = sorted(set(t) - _TOML_KEYS)
        if bad:
            raise ParameterError.at(where, f"unknown key {bad[0]!r}; the keys are {', '.join(sorted(_TOML_KEYS))}")
        if ("carrier_speed" in t) == ("sun_speed" in t):
            raise ParameterError.at(where, "give one of carrier_speed and sun_speed")
        if ("power" in t) == ("torque" in t):
            raise ParameterError.at(where, "give one of power and torque")
        shaft = "carrier" if "carrier_speed" in t else "sun"
        out.append(checked_point(Point(name=str(t.get("name", f"p{i + 1}")), speed=str(t[f"{shaft}_speed"]),
                                       shaft=shaft, load=str(t.get("power", t.get("torque"))),
                                       direction=t.get("direction"), oil_temperature=t.get("oil_temperature")), where))
    return out


def _toml(path) -> dict:
    try:
        return tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except UnicodeDecodeError as exc:
        raise ParameterError.at(f"--params {path}", str(exc)) from None
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError.at(f"--params {path}", f"invalid TOML: {exc}") from None


def file_overrides(path) -> dict:
    """The parameter overrides of a ``--params`` file without its ``[[operating_point]]`` tables."""
    data = _toml(path)
    if "operating_point" not in data:
        return overrides_from_toml(Path(path).read_text(encoding="utf-8"))
    return _flatten({k: v for k, v in data.items() if k != "operating_point"})


def _flatten(d, prefix: str = "") -> dict:
    out = {}
    for k, v in d.items():
        if isinstance(v, dict):
            out.update(_flatten(v, f"{prefix}{k}."))
        else:
            out[f"{prefix}{k}"] = v
    return out


_OPERATING = ("operating.carrier_speed", "operating.output_power", "operating.direction")


def study_points(conditions: str | None, operating: list[str] | None, params_file: str | None, sets: dict,
                 default: str) -> list[Point]:
    """The points a study runs (module docstring): ``--conditions`` (None: not given), ``--operating`` texts, the
    ``--params`` file's ``[[operating_point]]`` tables or its ``[operating]`` table (the machine's own point, when it
    gives the speed and the power and nothing else names a point); the study's ``default`` conditions when none of
    them names a point. Refused in one line: a ``--set operating.*`` (a point sets it: it would relabel the run), a
    file's ``[operating]`` beside other points or without its speed and power, a point named twice."""
    for key in sorted(k for k in sets if k.startswith("operating.")):
        raise ParameterError(f"{key} is set by this study's {_OPTION.get(key, '--conditions or --operating')}, not "
                             f"by --set (a point gives the speed, the load and the direction: --operating "
                             f"\"NAME: SPEED, LOAD[, reverse]\")", parameter=key)
    file_ops = {k: v for k, v in (file_overrides(params_file) if params_file else {}).items()
                if k.startswith("operating.")}
    pts = [preset(int(c)) for c in str(conditions).split(",") if c.strip()] if conditions else []
    pts += [parse_point(t, f"p{i + 1}") for i, t in enumerate(operating or [])]
    if params_file:
        pts += points_from_toml(params_file)
    if file_ops:
        complete = {"operating.carrier_speed", "operating.output_power"} <= set(file_ops)
        if pts or not complete:
            key = sorted(file_ops)[0]
            why = (f"beside the points {', '.join(p.name for p in pts)}" if pts else
                   "(a file's [operating] table with carrier_speed and output_power is the machine's own point)")
            raise ParameterError(f"{key} is set by this study's {_OPTION.get(key, '--conditions or --operating')}, "
                                 f"not by --params {params_file} {why}", parameter=key)
        pts = [_machine_point(file_ops, params_file)]
    if not pts:
        pts = [preset(int(c)) for c in default.split(",")]
    names = [p.name for p in pts]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ParameterError.at("--operating", f"the point {dup[0]!r} is named twice")
    return pts


_OPTION = {"operating.carrier_speed": "--conditions or --operating", "operating.output_power":
           "--conditions or --operating", "operating.direction": "--directions"}


def _machine_point(ops: dict, params_file: str) -> Point:
    """The point a machine file's ``[operating]`` table gives, named after the file."""
    name = re.sub(r"[^A-Za-z0-9_.\-]", "_", Path(params_file).stem)
    if not _NAME.match(name) or name.isdigit():
        name = f"m_{name}"
    unknown = sorted(set(ops) - set(_OPERATING))
    if unknown:
        raise ParameterError.at(unknown[0], f"--params {params_file}: the operating point takes carrier_speed, "
                                            f"output_power and direction")
    return checked_point(Point(name=name, speed=str(ops["operating.carrier_speed"]),
                               load=str(ops["operating.output_power"]), direction=ops.get("operating.direction")),
                         f"--params {params_file} [operating]")


def check_oil_temperature(text: str, lubricant_si, where: str) -> None:
    """Refuse an oil temperature outside :data:`OIL_RANGE_C` or where the lubricant's Walther line gives less than
    :data:`OIL_MIN_VISCOSITY` (one line naming ``where``)."""
    from components.lubrication import walther_viscosity  # deferred: it imports the engine (numba), which parsing does not need
    T = to_si(quantity(where, text, "temperature"))
    lo, hi = OIL_RANGE_C
    if not lo + 273.15 <= T <= hi + 273.15:
        raise ParameterError.at(where, f"oil temperature {text} is outside the lubricant's range {lo:g}-{hi:g} degC")
    nu = walther_viscosity(lubricant_si.viscosity_40, lubricant_si.viscosity_100, T)
    if nu < OIL_MIN_VISCOSITY:
        raise ParameterError.at(where, f"oil temperature {text}: the lubricant's viscosity there ({nu * 1e6:.2g} "
                                       f"mm^2/s) is below the {OIL_MIN_VISCOSITY * 1e6:g} mm^2/s its Walther line "
                                       f"(ASTM D341) holds to")


def point_overrides(point: Point, params) -> dict:
    """The parameter overrides that put the machine ``params`` at ``point`` (a user point; a preset's are its
    ``reference_dpgt(condition, direction)``): the carrier speed (a sun speed through the machine's own ratio
    |ω_s/ω_c| = |1 − z_r/z_s|, :func:`components.geometry.speed_ratio`), the output power (a torque times the speed
    of its shaft, the one whose speed the point gives; lossless; negative: braking), the direction and the oil
    temperature."""
    where = f"point {point.name}"
    g = params.gears.si()
    w = to_si(quantity(f"{where} speed", point.speed, "angular_velocity"))      # the given shaft's speed
    w_c = w if point.shaft == "carrier" else w / abs(speed_ratio(g.sun.teeth, g.ring.teeth))
    kind, value = _quantity_kind(point.load)
    power = value if kind == "power" else value * w
    out = {"operating.carrier_speed": point.speed if point.shaft == "carrier" else f"{w_c!r} rad/s",
           "operating.output_power": point.load if kind == "power" else f"{power!r} W"}
    if point.direction is not None:
        out["operating.direction"] = point.direction
    if point.oil_temperature is not None:
        check_oil_temperature(point.oil_temperature, params.lubricant.si(), f"{where} oil temperature")
        out["lubricant.temperature"] = point.oil_temperature
    return out


def point_label(point: Point, direction: str) -> str:
    """A case's folder name: ``c3_forward`` for a preset, the point's name (with the study's direction when the
    point leaves it open) for a user point."""
    if point.is_preset:
        return f"c{point.condition}_{direction}"
    return point.name if point.direction is not None else f"{point.name}_{direction}"


def point_tag(condition) -> str:
    """How files of one point are named: ``c3`` for a preset, the name for a user point."""
    return f"c{condition}" if isinstance(condition, int) else str(condition)


def point_order(condition):
    """Sort key: presets by number first, then user points by name."""
    return (0, condition, "") if isinstance(condition, int) else (1, 0, str(condition))


def machine_identity(params_file: str | None, overrides: dict) -> dict:
    """The machine a study ran (every output names it): its file's name (or the reference machine), a short
    fingerprint of the file's text and the overrides, and the overrides echoed."""
    h = hashlib.sha256()
    text = Path(params_file).read_bytes() if params_file else b"reference"
    h.update(text)
    h.update(repr(sorted((k, str(v)) for k, v in overrides.items())).encode())
    name = Path(params_file).name if params_file else "reference machine"
    fp = h.hexdigest()[:8]
    over = ", ".join(f"{k}={v}" for k, v in sorted(overrides.items()))
    return {"name": name, "fingerprint": fp, "overrides": {k: str(v) for k, v in overrides.items()},
            "label": f"{name} [{fp}]" + (f" with {over}" if over else "")}


def points_of(a, sets: dict) -> list[Point]:
    """A study's points from its parsed command line (``--conditions``, ``--operating``, ``--params``) and its
    ``--set`` overrides ``sets`` (:func:`study_points`; the study's default conditions when nothing names a point)."""
    given = a.conditions if getattr(a, "conditions_given", True) else None
    return study_points(given, getattr(a, "operating", None), getattr(a, "params", None), sets,
                        default=str(a.conditions))


def machine_overrides(sets: dict, points: list[Point]) -> dict:
    """The ``--set`` overrides that describe the machine (not the operating point, which the points set); an oil
    temperature set for every run beside a point that sets its own is refused (it would be silently replaced)."""
    own = [p.name for p in points if p.oil_temperature is not None]
    if own and "lubricant.temperature" in sets:
        raise ParameterError.at("lubricant.temperature", f"--set sets it, but the point {own[0]} sets its own oil "
                                                         f"temperature: give it in one place")
    return {k: v for k, v in sets.items() if not k.startswith("operating.")}


def point_words(condition) -> str:
    """How a table or a figure names a point: ``condition 3`` for a preset, ``point cruise`` for a user point."""
    return f"condition {condition}" if isinstance(condition, int) else f"point {condition}"


def file_without(params_file: str | None, owned: dict[str, str]) -> tuple[dict, list[str]]:
    """A study that sweeps some parameters (``owned``: key → its option) takes a ``--params`` file that also sets
    them: the file's other overrides (not its operating point, which :func:`points_of` reads) and the keys the
    sweep's values replace (the caller says so in one line)."""
    if not params_file:
        return {}, []
    fo = file_overrides(params_file)
    replaced = sorted(k for k in fo if k in owned)
    return {k: v for k, v in fo.items() if k not in owned and not k.startswith("operating.")}, replaced
