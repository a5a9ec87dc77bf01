"""docs/parameters.md, the parameter reference generated from the parameter classes (components.parameter_reference):
the committed file is what the generator writes now (so it never goes stale), it lists every key a user can set,
and every parameter in it has a unit whose dimension is the parameter's (or says what kind of value it is) and a
source tag. The values it shows are checked against the parameters they describe and against published numbers."""
from __future__ import annotations

import math
import re
import warnings

import pytest

from components.parameter_reference import NON_QUANTITY_KINDS, entry_rows, reference_markdown, reference_rows
from components.params import ErrorsParams, flatten, parameter_names
from components.presets import reference_bearing_rig, reference_dpgt
from components.units import KINDS, quantity, to_si, ureg

from tests.support import ROOT

REFERENCE = ROOT / "docs" / "parameters.md"
TAGS = {"[paper]", "[derived]", "[assumed]"}


def _machine():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")           # the reference design's two known tip-circle warnings
        p = reference_dpgt()
        p.si()
    return p


def _doc_table_keys(text: str) -> list[str]:
    """The first column of every table row of the document that holds a backticked key."""
    return re.findall(r"^\| `([^`]+)` \|", text, flags=re.M)


def _pint_text(text: str) -> str:
    """The reference's unit text as pint reads it (its symbols: ·, ², ³, ^(a/b), °C)."""
    return text.replace("°C", "degC").replace("·", "*").replace("²", "**2").replace("³", "**3").replace("^", "**")


def _pint_unit(text: str):
    return ureg.parse_units(_pint_text(text))


def _dims(units) -> dict:
    return {k: float(v) for k, v in (1.0 * units).to_base_units().dimensionality.items()}


def _same_dims(a: dict, b: dict) -> bool:
    return all(abs(a.get(k, 0.0) - b.get(k, 0.0)) < 1e-9 for k in set(a) | set(b))


def test_the_committed_reference_is_what_the_generator_writes():
    assert REFERENCE.read_text(encoding="utf-8") == reference_markdown(), \
        "docs/parameters.md is stale: run `python -m scenarios.params --reference` and commit it"


def test_the_reference_lists_every_key_a_user_can_set_once():
    machine_part, rig_part = REFERENCE.read_text(encoding="utf-8").split("\n## Bearing rig\n")
    keys = _doc_table_keys(machine_part)
    machine = parameter_names(_machine())
    listed = [k for k in keys if k in machine]
    assert listed == machine                                   # every key, in the classes' order, none twice
    entries = [f.name for f in ErrorsParams.__dataclass_fields__.values() if "spec" in f.metadata]
    for name in entries:                                       # every field of every list of tables
        cls = ErrorsParams._spec(name).cls
        fields = [f for f in cls.__dataclass_fields__.values() if "spec" in f.metadata]
        assert fields and all(f"errors.{name}[i].{f.name}" in keys for f in fields), name
    assert _doc_table_keys(rig_part) == parameter_names(reference_bearing_rig())


@pytest.mark.parametrize("which", ["dpgt", "bearing_rig"])
def test_every_parameter_has_a_unit_of_its_dimension_or_its_kind_and_a_source_tag(which):
    params = _machine() if which == "dpgt" else reference_bearing_rig()
    values = flatten(params)
    si = params.si()
    for r in reference_rows(params):
        assert r.source in TAGS, (r.key, r.source)            # nothing untagged ([default]) or [user]
        if r.kind in KINDS:
            unit = _pint_unit(r.unit)
            assert _same_dims(_dims(unit), _dims(ureg.parse_units(KINDS[r.kind].si_unit))), (r.key, r.unit)
            # the value as shown, in the unit shown, is the parameter's (a given one exactly, a rule's to 4 digits)
            shown = float(r.value.split()[0]) if r.value[0] in "-0123456789" else None
            if values[r.key] is not None:
                given = quantity(r.key, f"{shown} {_pint_text(r.unit)}", r.kind)
                assert math.isclose(to_si(given), to_si(values[r.key]), rel_tol=1e-5), (r.key, r.value, r.unit)
            elif shown is not None:
                node = si
                for part in r.key.split("."):
                    node = node[part]
                assert math.isclose(shown, node, rel_tol=5e-4), (r.key, r.value, node)
            else:
                assert "rule" in r.value, r.key
        else:
            assert r.kind in NON_QUANTITY_KINDS and r.unit.startswith(NON_QUANTITY_KINDS[r.kind]), (r.key, r.unit)


def test_entry_fields_have_units_or_kinds():
    for name in ("pinhole", "runout", "roller_diameter", "spall", "tooth_fault", "tooth", "flank_class"):
        for r in entry_rows(f"errors.{name}", ErrorsParams._spec(name).cls):
            if r.kind in KINDS:
                assert _same_dims(_dims(_pint_unit(r.unit)), _dims(ureg.parse_units(KINDS[r.kind].si_unit))), r
            else:
                assert r.unit.startswith(NON_QUANTITY_KINDS[r.kind]), r
    depth = next(r for r in entry_rows("errors.spall", ErrorsParams._spec("spall").cls) if r.key.endswith("depth"))
    assert (depth.value, depth.unit) == ("required", "m")


def test_published_and_closed_form_values_read_as_the_source_gives_them():
    rows = {r.key: r for r in reference_rows(_machine())}
    assert (rows["gears.ring.teeth"].value, rows["gears.ring.teeth"].source) == ("82", "[paper]")
    assert (rows["bearing.clearance"].value, rows["bearing.clearance"].unit) == ("20", "µm")
    # Palmgren: delta[mm] = 3.84e-5 Q^0.9 / l^0.8  <=>  Q = K delta^(10/9), K in N/mm^(10/9) for l = 9 mm, in SI
    K_mm = (1.0 / 3.84e-5) ** (10 / 9) * 9.0 ** (0.8 * 10 / 9)
    K = rows["bearing.contact_stiffness"]
    assert K.unit == "N/m^(10/9)" and math.isclose(float(K.value.split()[0]), K_mm * 1e3 ** (10 / 9), rel_tol=2e-3)
    # the source's Table: carrier 4200 r/min <-> sun 6910 r/min, 2000 <-> 3290 (ring fixed, z_s = 31, z_r = 82)
    text = REFERENCE.read_text(encoding="utf-8")
    assert "| 3 | 4200 r/min | 200 kW | -6909.7 r/min |" in text and "| 2 | 2000 r/min | 200 kW | -3290.3 r/min |" in text


def test_the_reference_command_writes_the_file_and_refuses_other_options(tmp_path, capsys):
    from scenarios import cli

    out = tmp_path / "parameters.md"
    assert cli.main(["params", "--reference", str(out)]) == 0
    assert out.read_text(encoding="utf-8") == reference_markdown()
    assert cli.main(["params", "--reference", str(out), "--set", "bearing.clearance=30 um"]) == 2
    assert "--reference documents the reference machine at its defaults; it takes no --set" in capsys.readouterr().err
