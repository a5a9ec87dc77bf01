"""The parameter reference, ``docs/parameters.md``, generated from the parameter classes.

Every key of the machine as a user writes it (a dotted key of ``--set KEY=VALUE`` or a table of a ``--params``
TOML file), its unit (or its kind when it is not a quantity), the reference machine's value, its source tag and
its one-line meaning — read from the fields of :mod:`components.params` and the preset of
:mod:`components.presets`, nothing restated. ``python -m scenarios.params --reference`` writes the file;
``tests/components/test_parameter_reference.py`` holds the committed file to what :func:`reference_markdown` writes now,
so it cannot go stale. The model behind the values: ``docs/model.md``.
"""
from __future__ import annotations

import dataclasses
import math
import re
import warnings
from dataclasses import dataclass
from fractions import Fraction

from .geometry import kinematics
from .params import Params, flatten, parameter_rows
from .presets import CONDITIONS, OIL_GRADES, reference_bearing_rig, reference_dpgt, reference_gears
from .units import KINDS, Q_, ParameterError, quantity, ureg

__all__ = ["Row", "reference_rows", "entry_rows", "unit_text", "reference_markdown", "NON_QUANTITY_KINDS"]

# kinds of fields that are not quantities, and how the reference names them in its unit column
NON_QUANTITY_KINDS = {"count": "count", "sign": "±1", "flag": "true/false", "choice": "one of", "name": "name",
                      "tooth": "tooth index or \"all\"", "entries": "list of tables"}
_SUPERSCRIPT = {2: "²", 3: "³"}


@dataclass(frozen=True)
class Row:
    """One parameter: ``key`` as a user writes it, ``value`` as the reference machine has it, ``unit`` (a unit
    text, "1" for a dimensionless quantity, or the kind of a value that is not a quantity), ``kind`` (the field's
    kind: a key of :data:`components.units.KINDS` or of :data:`NON_QUANTITY_KINDS`), ``source`` (``[paper]``,
    ``[derived]``, ``[assumed]``; empty for an entry's field), ``meaning`` and the source's ``note``."""
    key: str
    value: str
    unit: str
    kind: str
    source: str
    meaning: str
    note: str = ""


def _symbol(name: str) -> str:
    return {"degree_Celsius": "°C", "degree": "deg"}.get(name, ureg.get_symbol(name))


def _power(e: float) -> str:
    f = Fraction(e).limit_denominator(100)
    if f.denominator == 1:
        return "" if f.numerator == 1 else _SUPERSCRIPT.get(f.numerator, f"^{f.numerator}")
    return f"^({f.numerator}/{f.denominator})"


def unit_text(units) -> str:
    """A pint unit as it reads in the reference: ``N/m^(10/9)``, ``kg·m²``, ``N/(mm·µm)``; ``1`` when
    dimensionless (pint's own pretty form writes 10/9 as a decimal superscript)."""
    items = [(name, float(e)) for name, e in Q_(1.0, units).unit_items()]
    num = [_symbol(n) + _power(e) for n, e in items if e > 0]
    den = [_symbol(n) + _power(-e) for n, e in items if e < 0]
    top = "·".join(num) or "1"
    if not den:
        return top
    return f"{top}/{den[0]}" if len(den) == 1 else f"{top}/({'·'.join(den)})"


def _number(x: float) -> str:
    return f"{x:.4g}" if isinstance(x, float) and not float(x).is_integer() else f"{x:g}"


def _spec(params: Params, path: str):
    """The field specification of the leaf ``path`` (owner walked from ``params``)."""
    *owner_path, name = path.split(".")
    owner = params
    for p in owner_path:
        owner = getattr(owner, p)
    return type(owner)._spec(name)


def _si_at(si, path: str):
    for part in path.split("."):
        si = si[part]
    return si


def _unit_of(spec) -> str:
    """The unit column of a field from its kind alone: the SI unit of a quantity ("1" dimensionless), else the
    kind of value (the choices of a choice)."""
    if spec.kind in KINDS:
        return unit_text(ureg.parse_units(KINDS[spec.kind].si_unit))
    if spec.kind == "choice":
        return "one of " + ", ".join(f'"{c}"' for c in spec.choices)
    return NON_QUANTITY_KINDS[spec.kind]


def _value_and_unit(spec, value, si_value) -> tuple[str, str]:
    """(value, unit) columns of one leaf: a quantity as given, a value left to its rule resolved in SI, a
    choice, name, flag or count as TOML writes it."""
    kind = spec.kind
    if kind in KINDS:
        if value is None:                       # left to its rule: resolved in SI where it is one number
            if isinstance(si_value, (int, float)):
                return f"{si_value:.4g} (rule)", _unit_of(spec)
            return "(rule: per mesh, see the derived values)", _unit_of(spec)
        return f"{value.magnitude:g}", unit_text(value.units)
    if kind == "flag":
        return ("true" if value else "false"), _unit_of(spec)
    if kind == "entries":
        return ("[] (none)" if not value else f"{len(value)} entries"), _unit_of(spec)
    if kind in ("choice", "name") or (kind == "tooth" and value == "all"):
        return f'"{value}"', _unit_of(spec)
    return str(value), _unit_of(spec)


def reference_rows(params: Params) -> list[Row]:
    """Every leaf parameter of ``params`` (a DPGTParams, or another parameter object) as a :class:`Row`, in the
    order of the classes' fields."""
    try:
        si = params.si()
    except ParameterError:                      # a machine that cannot be laid out: no resolved values
        si = None
    text = {r["key"]: r for r in parameter_rows(params)}
    out = []
    for path, value in flatten(params).items():
        spec = _spec(params, path)
        si_value = _si_at(si, path) if si is not None and value is None else None
        shown, unit = _value_and_unit(spec, value, si_value)
        r = text[path]
        out.append(Row(path, shown, unit, spec.kind, r["source"], r["meaning"], r["note"]))
    return out


def entry_rows(prefix: str, cls: type) -> list[Row]:
    """The fields of one entry of a list of tables (e.g. ``errors.pinhole``): key ``prefix[i].field``, the field's
    default (or "required"), its unit or kind and its meaning."""
    out = []
    for f in dataclasses.fields(cls):
        if "spec" not in f.metadata:
            continue
        spec = f.metadata["spec"]
        if f.default is dataclasses.MISSING:
            shown, unit = "required", _unit_of(spec)
        else:
            default = quantity(f.name, f.default, spec.kind) if spec.kind in KINDS else f.default
            shown, unit = _value_and_unit(spec, default, None)
        out.append(Row(f"{prefix}[i].{f.name}", shown, unit, spec.kind, "", " ".join(spec.doc.split())))
    return out


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def _table(rows: list[Row], source: bool = True) -> list[str]:
    head = "| key | value | unit | source | meaning |" if source else "| key | default | unit | meaning |"
    lines = [head, "|---|---|---|---|---|" if source else "|---|---|---|---|"]
    for r in rows:
        meaning = r.meaning + (f" — {r.note}" if r.note and r.note not in r.meaning else "")
        cells = [f"`{r.key}`", r.value, r.unit] + ([r.source] if source else []) + [meaning]
        lines.append("| " + " | ".join(_cell(c) for c in cells) + " |")
    return lines


def _first_paragraph(doc: str | None) -> str:
    """A docstring's first paragraph on one line, its reStructuredText roles and literals as Markdown code."""
    text = " ".join((doc or "").strip().split("\n\n")[0].split())
    return re.sub(r":(?:func|class|mod|meth|data):`~?([^`]+)`", r"`\1`", text).replace("``", "`")


def _conditions() -> list[str]:
    """The study's operating conditions, with the speeds and frequencies the reference gears give them."""
    g = reference_gears().si()
    z = (g.sun.teeth, g.inner_planet.teeth, g.outer_planet.teeth, g.ring.teeth)
    lines = ["| condition | carrier n_c | output power P | sun | f_c | f_m = z_r f_c | sun torque T_s (forward) |",
             "|---|---|---|---|---|---|---|"]
    for c, (speed, power) in CONDITIONS.items():
        k = kinematics(*z, speed.to("rad/s").magnitude, power.to("W").magnitude)
        lines.append(f"| {c} | {speed.magnitude:g} r/min | {power.to('kW').magnitude:g} kW | "
                     f"{k.sun_speed * 30 / math.pi:.1f} r/min | {k.carrier_frequency:.4g} Hz | "
                     f"{k.mesh_frequency:.5g} Hz | {k.sun_torque:.1f} N m |")
    return lines


def _derived(params) -> list[str]:
    """What ``params.si()`` resolves from the parameters: layout, ratios, per-mesh data, bearing radii."""
    si = params.si()
    lay, b = si.layout, si.bearing
    rows = [("si.layout.r_ca", lay.r_ca * 1e3, "mm", "sun–inner planet centre distance m (z_s + z_a)/2"),
            ("si.layout.r_cb", lay.r_cb * 1e3, "mm", "ring–outer planet centre distance m (z_r − z_b)/2"),
            ("si.layout.l_ab", lay.l_ab * 1e3, "mm", "inner–outer planet centre distance m (z_a + z_b)/2"),
            ("si.layout.delta_psi", math.degrees(lay.delta_psi), "deg", "angle between a pair's planets seen from the axis"),
            ("si.layout.sun_ratio", lay.sun_ratio, "1", "ω_s/ω_c = 1 − z_r/z_s (ring fixed)"),
            ("si.layout.inner_ratio", lay.inner_ratio, "1", "ω_a/ω_c = 1 + z_r/z_a"),
            ("si.layout.outer_ratio", lay.outer_ratio, "1", "ω_b/ω_c = 1 − z_r/z_b"),
            ("si.layout.assembly_number", lay.assembly_number, "1", "(z_r − z_s)/N: an integer, so equally spaced pairs assemble"),
            ("si.bearing.inner_raceway_radius", b.inner_raceway_radius * 1e3, "mm", "R_i = (d_m − D)/2, the pin"),
            ("si.bearing.outer_raceway_radius", b.outer_raceway_radius * 1e3, "mm", "R_o = (d_m + D + P_d)/2, the planet bore")]
    for key, m in lay.meshes.items():
        p = f"si.layout.meshes[\"{key}\"]"
        rows += [(f"{p}.contact_ratio", m.contact_ratio, "1", f"{key}: transverse contact ratio ε_α"),
                 (f"{p}.line_load", m.line_load * 1e-3, "N/mm", f"{key}: nominal line load F_t/b of the operating "
                                                                "point (K_A = 1)"),
                 (f"{p}.stiffness.theoretical", m.stiffness.theoretical * 1e-9, "N/(mm·µm)",
                  f"{key}: ISO 6336-1 theoretical single stiffness c'_th = 1/q'"),
                 (f"{p}.stiffness.single", m.stiffness.single * 1e-9, "N/(mm·µm)",
                  f"{key}: ISO 6336-1 single stiffness c' = c'_th C_M C_R C_B × load correction "
                  f"({m.stiffness.load_factor:.4g})"),
                 (f"{p}.stiffness.mean", m.stiffness.mean * 1e-9, "N/(mm·µm)",
                  f"{key}: ISO 6336-1 mesh stiffness c_γα = c'(0.75 ε_α + 0.25)"),
                 (f"{p}.k_mean", m.k_mean, "N/m", f"{key}: mean mesh stiffness c_γα × common face width"),
                 (f"{p}.k_single", m.k_single, "N/m", f"{key}: single-contact stiffness of the rectangular wave, "
                                                                   "c' × common face width"),
                 (f"{p}.k_double", m.k_double, "N/m", f"{key}: double-contact stiffness, 1.75 k_single"),
                 (f"{p}.damping", m.damping, "N·s/m", f"{key}: mesh damping 2 ζ_m √(k_mean m_eq)"),
                 (f"{p}.backlash", m.backlash * 1e3, "mm", f"{key}: normal backlash j_bn")]
    lines = ["| where (`DPGTParams.si()`) | value | unit | what |", "|---|---|---|---|"]
    lines += [f"| `{k}` | {_number(float(v))} | {u} | {_cell(w)} |" for k, v, u, w in rows]
    return lines


def _oil_grades() -> list[str]:
    lines = ["| grade | viscosity at 40 °C | at 100 °C | source |", "|---|---|---|---|"]
    for name, d in OIL_GRADES.items():
        v40, v100 = d["viscosity_40"], d["viscosity_100"]
        lines.append(f"| {name} | {Q_(v40.value).magnitude:g} mm²/s | {Q_(v100.value).magnitude:g} mm²/s | "
                     f"[{v100.source.tag}] {_cell(v100.source.note)} |")
    return lines


HEADER = """# Parameters of the reference machine

<!-- Generated by `python -m scenarios.params --reference` from components/params/ and components/presets.py;
do not edit by hand (tests/components/test_parameter_reference.py holds this file to the generator). -->

Every parameter of the DPGT and its planet bearings, as a user writes it: the key of `--set KEY=VALUE` (e.g.
`--set bearing.clearance="30 um"`) and of a `--params` TOML file (dotted tables: `[bearing.cage]` then
`mass = "0.05 kg"`), in every command; `dpgt params --grep WORD` shows the same for a machine you describe. The
value is the reference machine's at operating condition 3, forward; a value is given with any unit of its
dimension (`"0.02 mm"` = `"20 um"`), a dimensionless one as a number. A value left to a rule (e.g. the roller
mass from its size) is shown resolved, in SI, and follows the values it is made from when they change.

Source tags: **[paper]** the source study's tables and text; **[derived]** computed from paper values or a
standard; **[assumed]** an engineering estimate, its basis after the meaning. What the parameters mean in the
model: [`model.md`](model.md)."""


def _entry_lists(prefix: str, cls: type) -> list[tuple[str, type]]:
    """(dotted key, entry class) of every list of tables in the nested class ``cls`` and the classes nested in it."""
    out = []
    for g in dataclasses.fields(cls):
        spec = g.metadata.get("spec")
        if spec is not None and spec.kind == "entries":
            out.append((f"{prefix}.{g.name}", spec.cls))
        elif spec is not None and spec.kind == "nested":
            out += _entry_lists(f"{prefix}.{g.name}", spec.cls)
    return out


def reference_markdown() -> str:
    """The whole reference (``docs/parameters.md``) of the reference machine at its defaults."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # the reference design's two known tip-circle warnings
        params = reference_dpgt()
        rows = reference_rows(params)
        derived = _derived(params)
    lines = [HEADER, "", "## Operating conditions", "",
             "The source study's four conditions (`--conditions 1,2,3,4` of the studies), ring fixed, sun driven, "
             "carrier loaded; reverse turns every speed the other way. Speeds and frequencies from the reference "
             "gears (docs/model.md §1.3).", "", *_conditions()]
    for f in dataclasses.fields(type(params)):
        if "spec" not in f.metadata:
            continue
        spec = f.metadata["spec"]
        mine = [r for r in rows if r.key == f.name or r.key.startswith(f.name + ".")]
        what = _first_paragraph(spec.cls.__doc__) if spec.kind == "nested" else f"{spec.doc[0].upper()}{spec.doc[1:]}."
        lines += ["", f"## `{f.name}`", "", what, ""]
        lines += _table(mine)
        if spec.kind == "nested":
            for key, cls in _entry_lists(f.name, spec.cls):
                lines += ["", f"### `[[{key}]]`", "", _first_paragraph(cls.__doc__)
                          + f" One table per entry in a TOML file (`[[{key}]]`); errors name the entry as "
                            f"`{key}[0]`.", ""]
                lines += _table(entry_rows(key, cls), source=False)
    lines += ["", "## Derived values", "",
              "What `DPGTParams.si()` resolves from the parameters above (the reference machine), [derived]; the model "
              "behind them: docs/model.md §1.", "", *derived,
              "", "## Oil grades", "",
              "The ISO VG grades the lubricant study takes (`--oil`; `components.presets.oil_grade`): each sets "
              "`lubricant.viscosity_40` and `lubricant.viscosity_100`.", "", *_oil_grades()]
    rig = reference_bearing_rig()
    lines += ["", "## Bearing rig", "",
              f"{_first_paragraph(type(rig).__doc__)} Python only: `components.rig.build_bearing_rig(bearing, ..., "
              "rig=with_overrides(reference_bearing_rig(), {KEY: VALUE}))`; `dpgt bearing_rig` takes the bearing's "
              "`bearing.*` keys above.", "", *_table(reference_rows(rig))]
    lines += ["", "## A single planetary set", "",
              "`dpgt modal` and `components.planetary.build_single_planetary` read a TOML format of their own, "
              "listed in the docstring of `components/planetary.py` (example values [assumed]).", ""]
    return "\n".join(lines)
