"""The parameter package after its split: the SI classes are declared so that a type checker sees
their fields (mypy on a snippet), the declaration is checked against the parameter fields at import, and the
package still offers every name the single module offered."""
import dataclasses
import os
import re
import subprocess
import sys
import textwrap
from dataclasses import dataclass
from typing import ClassVar

import pytest

import components.params as P
from components import geometry as geo
from components.params._machinery import SI, Params, computed, param, positive, si_extends, si_of
from components.units import Quantity

from tests.support import ROOT


# every public name the single module components/params.py defined before the split (its __all__ listed 55;
# ErrorsSI, FlankClassParams, FlankClassSI, PinholeErrorSI, RollerDiameterErrorSI, RunoutSI, SpallSI,
# ToothDeviationParams, ToothDeviationSI, ToothFaultSI were importable but missing from it)
OLD_NAMES = {
    "BearingParams", "BearingRigParams", "BearingRigSI", "BearingSI", "CageParams", "CageSI", "CarrierRippleParams",
    "CarrierRippleSI", "DPGTOperatingSI", "DPGTParams", "DPGTSI", "DPGTSupportSI", "Derived", "ErrorsParams",
    "ErrorsSI", "FlankClassParams", "FlankClassSI", "GearParams", "GearSI", "GearSetParams", "GearSetSI",
    "HousingParams", "HousingSI", "LifeParams", "LifeSI", "LubricantParams", "LubricantSI", "MeshParams", "MeshSI",
    "OperatingPoint", "OperatingSI", "Params", "PinholeErrorParams", "PinholeErrorSI", "RigParams", "RigSI",
    "RollerDiameterErrorParams", "RollerDiameterErrorSI", "RunoutParams", "RunoutSI", "SI", "SensorParams",
    "SensorSI", "SlideRollTractionParams", "SlideRollTractionSI", "Source", "Sourced", "SpallParams", "SpallSI",
    "SupportParams", "SupportSI", "ToothDeviationParams", "ToothDeviationSI", "ToothFaultParams", "ToothFaultSI",
    "assumed", "derived", "describe", "flatten", "overrides_from_toml", "paper", "parameter_names",
    "parameter_rows", "to_toml", "with_overrides"}


# names the package gained since: the range an assumed value carries and the list of them; a knot of the operating
# point's schedule; a pin's slope and a pinhole measured at its two ends
ADDED = {"Span", "spans", "SchedulePointParams", "SchedulePointSI", "PinParams", "PinSI", "PinSlopeParams", "PinSlopeSI",
         "PinholeEndsParams", "PinholeEndsSI"}


def test_the_package_offers_every_name_of_the_old_module():
    assert set(P.__all__) == OLD_NAMES | ADDED and len(P.__all__) == len(OLD_NAMES | ADDED)
    for name in OLD_NAMES:
        assert getattr(P, name).__name__ == name
    for name in OLD_NAMES:
        obj = getattr(P, name)
        if isinstance(obj, type) and issubclass(obj, Params) and obj is not Params:
            si = getattr(P, obj.SI.__name__)
            assert si is obj.SI and si.__module__ == obj.__module__        # each SI class next to its Params class


# ------------------------------------------------------------------ a type checker sees the SI fields
GOOD = '''\
from components.params import DPGTParams, with_overrides
from components.presets import reference_dpgt


def diameter(p: DPGTParams) -> float:
    return p.si().bearing.roller_diameter


reveal_type(reference_dpgt().si().gears.sun.teeth)
reveal_type(with_overrides(reference_dpgt(), {"bearing.clearance": "30 um"}).si().operating.sun_speed)
reveal_type(reference_dpgt().si().errors.pinhole)
reveal_type(reference_dpgt().bearing.si().cage.inertia)
'''

BAD = '''\
from components.params import DPGTParams


def misspelt(p: DPGTParams) -> float:
    return p.si().bearing.roller_diametre


def wrong_type(p: DPGTParams) -> str:
    return p.si().bearing.roller_diameter


def frozen(p: DPGTParams) -> None:
    p.si().bearing.clearance = 1.0
'''


def test_a_type_checker_sees_the_fields_of_the_si_classes(tmp_path):
    """mypy on two snippets: field access through ``params.si()`` type-checks with the fields' own types; a
    misspelt field, a float where a str is wanted and an assignment to a frozen field are errors. (Before the
    SI classes were declared, the first snippet failed: ``SI? has no attribute "bearing"``.)"""
    pytest.importorskip("mypy", reason="mypy is a test extra (pip install -e '.[test]')")
    (tmp_path / "good.py").write_text(GOOD)
    (tmp_path / "bad.py").write_text(BAD)
    env = {**os.environ, "MYPYPATH": str(ROOT)}        # this checkout's code, not an installed copy
    out = subprocess.run([sys.executable, "-m", "mypy", "--follow-imports=silent", "--show-error-codes",
                          "--no-error-summary", "--cache-dir", str(tmp_path / "cache"), "good.py", "bad.py"],
                         cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    lines = [ln for ln in out.stdout.splitlines() if re.match(r"(good|bad)\.py:\d+: ", ln)]
    assert lines, out.stdout + out.stderr
    errors = {(ln.split(":")[0], int(ln.split(":")[1])): ln for ln in lines if ": error: " in ln}
    revealed = [ln.split("Revealed type is ")[1] for ln in lines if "Revealed type is" in ln]
    assert [k for k in errors if k[0] == "good.py"] == [], out.stdout
    assert revealed == ['"int"', '"float"', '"tuple[components.params.errors.PinholeErrorSI, ...]"',
                        '"float | None"'], out.stdout
    assert sorted(errors) == [("bad.py", 5), ("bad.py", 9), ("bad.py", 13)], out.stdout
    assert '"BearingSI" has no attribute "roller_diametre"' in errors["bad.py", 5]
    assert 'got "float", expected "str"' in errors["bad.py", 9]
    assert '"clearance"' in errors["bad.py", 13] and "read-only" in errors["bad.py", 13]


# ------------------------------------------------------------------ the SI declaration is checked at import
def _toy(si_name: str = "ToySI"):
    """A fresh parameter class (each may get one SI class) naming ``si_name`` as its SI class."""
    @dataclass(frozen=True, kw_only=True)
    class Toy(Params[si_name]):
        _prefix: ClassVar[str] = "toy"
        teeth: int = param("count", "number of teeth", lo=3, bound_text=">= 3")
        length: Quantity = positive("length", "a length")

        def _si_values(self, v):
            return dict(twice=2.0 * v["length"])
    return Toy


def test_a_correct_si_declaration_gives_typed_si_values_and_its_docs():
    Toy = _toy()

    @si_of(Toy)
    class ToySI(SI):
        teeth: int
        length: float
        twice: float = computed("twice the length [m]")

    s = Toy(teeth=20, length="3 mm").si()
    assert type(s) is ToySI and Toy.SI is ToySI
    assert (s.teeth, s.length, s.twice) == (20, pytest.approx(3e-3, rel=1e-15), pytest.approx(6e-3, rel=1e-15))
    assert [(f.name, f.type) for f in dataclasses.fields(ToySI)] == [("teeth", int), ("length", float),
                                                                     ("twice", float)]
    assert [f.metadata["doc"] for f in dataclasses.fields(ToySI)] == ["number of teeth", "a length",
                                                                      "twice the length [m]"]
    assert [d.name for d in Toy._si_derived] == ["twice"]
    assert "* ``twice``: twice the length [m]" in ToySI.__doc__
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.teeth = 3
    with pytest.raises(TypeError):
        ToySI(teeth=20, length=0.003)                      # every field is required, keyword-only
    with pytest.raises(TypeError, match="already has its SI class ToySI"):
        si_of(Toy)(type("ToySI", (SI,), {"__annotations__": {"teeth": "int", "length": "float"}}))


@pytest.mark.parametrize("body, problem", [
    ({"teeth": "int"}, r"ToySI lacks the fields \['length'\] of Toy"),
    ({"length": "float", "teeth": "int"}, r"ToySI must declare the fields of Toy in their order"),
    ({"teeth": "int", "length": "int"}, r"ToySI\.length is declared <class 'int'>, but Toy\.length \(length\) "
                                        r"gives <class 'float'>"),
    ({"teeth": "int", "length": "float", "twice": "float"}, r"ToySI\.twice is no field of Toy"),
])
def test_a_wrong_si_declaration_fails_at_import_naming_the_field(body, problem):
    with pytest.raises(TypeError, match=problem):
        si_of(_toy())(type("ToySI", (SI,), {"__annotations__": body, "__module__": __name__}))


def test_a_parameter_field_in_an_si_class_takes_no_default_and_the_names_agree():
    with pytest.raises(TypeError, match=r"ToySI\.length: an SI field takes no default"):
        si_of(_toy())(type("ToySI", (SI,), {"__annotations__": {"teeth": "int", "length": "float"},
                                            "length": 0.0, "__module__": __name__}))
    with pytest.raises(TypeError, match=r'Toy must subclass Params\["ToySI"\].*it names \'OtherSI\''):
        si_of(_toy("OtherSI"))(type("ToySI", (SI,), {"__annotations__": {"teeth": "int", "length": "float"},
                                                     "__module__": __name__}))
    with pytest.raises(TypeError, match=r"the fields \['extra'\] are not declared with computed"):
        si_extends(type("MoreSI", (P.SupportSI,), {"__annotations__": {"extra": "float"}, "__doc__": "More.",
                                                   "__module__": __name__}))


def test_the_machine_operating_point_has_every_nominal_value_of_the_kinematics():
    """DPGTOperatingSI = the operating point's SI fields + geometry.Kinematics's others (written out, so a field
    added to Kinematics must be declared there)."""
    names = [f.name for f in dataclasses.fields(P.DPGTOperatingSI)]
    op = [f.name for f in dataclasses.fields(P.OperatingSI)]
    kin = [f.name for f in dataclasses.fields(geo.Kinematics)]
    assert names == op + [n for n in kin if n not in op] and set(kin) <= set(names)


def test_the_machinery_says_what_it_is_for():
    import components.params._machinery as machinery

    doc = textwrap.dedent(machinery.__doc__)
    assert "need not touch this module" in doc and "si_of" in doc
    for mod in ("gears", "bearing", "operating", "sensor", "errors", "machine", "dotted"):
        assert f"``{mod}``" in P.__doc__                                 # the package's map names each module
