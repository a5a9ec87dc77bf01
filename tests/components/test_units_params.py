"""Units, parameter objects, provenance, overrides, TOML and the reference preset."""
import dataclasses
import math
import warnings

import pint
import pytest
from hypothesis import given, settings, strategies as st

from components import geometry as geo
from components.params import (SI, BearingParams, CageParams, DPGTSI, GearParams, Params, Source, assumed,
                               describe, flatten, overrides_from_toml, parameter_names, to_toml,
                               with_overrides)
from components.presets import CONDITIONS, load_toml, operating_point, reference_bearing, reference_dpgt
from components.units import Q_, ParameterError, format_quantity, quantity, to_si, ureg

RPM = 2 * math.pi / 60


# ------------------------------------------------------------------ units
def test_rpm_converts_to_rad_per_s():
    q = quantity("operating.carrier_speed", "4200 rpm", "angular_velocity")
    assert to_si(q) == pytest.approx(4200 * RPM, rel=1e-14)
    assert q.to("rad/s").magnitude == pytest.approx(439.822971502571, rel=1e-14)
    assert to_si(quantity("n", "3 rev/s", "angular_velocity")) == pytest.approx(6 * math.pi)
    assert to_si(quantity("n", "10 deg/s", "angular_velocity")) == pytest.approx(math.radians(10))


def test_a_frequency_given_as_a_rotation_speed_counts_revolutions_as_cycles():
    """The pint trap: the radian is dimensionless in pint, so pint alone reads "600 rpm" as
    600·2π/60 = 62.83 Hz. One revolution is one cycle: 600 rpm = 600/60 = 10 Hz; 2π·10 rad/s = 10 Hz."""
    f = lambda v: to_si(quantity("rig.carrier_drive_bandwidth", v, "frequency"))
    assert f("600 rpm") == pytest.approx(10.0, rel=1e-14)                   # 600 rev / 60 s
    assert f("4800 rpm") == pytest.approx(80.0, rel=1e-14)
    assert f("62.83185307179586 rad/s") == pytest.approx(10.0, rel=1e-14)   # 2π·10 rad/s
    assert f("360 deg/s") == pytest.approx(1.0, rel=1e-14) and f("3 rev/s") == pytest.approx(3.0, rel=1e-14)
    assert f("80 Hz") == 80.0 and f("1.2 kHz") == pytest.approx(1200.0) and f("80 1/s") == 80.0
    assert f("600 rpm") != pytest.approx(600 * RPM)                        # not pint's 62.83
    with pytest.raises(ParameterError, match=r"^rig\.carrier_drive_bandwidth: .*give Hz \(cycles per second\)"):
        f("1 rad**2/s")
    # and through the parameters, as --set gives it: the drive bandwidth the model uses, in Hz
    p = with_overrides(reference_dpgt(), {"rig.carrier_drive_bandwidth": "4800 rpm"})
    assert p.si().rig.carrier_drive_bandwidth == pytest.approx(80.0, rel=1e-14)
    assert p.si().rig.carrier_drive_bandwidth == reference_dpgt().si().rig.carrier_drive_bandwidth
    sensor = with_overrides(reference_dpgt(), {"rig.sensor.housing.rocking_frequency": "37800 rpm"})
    assert sensor.si().rig.sensor.housing.rocking_frequency == pytest.approx(630.0, rel=1e-14)   # 37800/60


def test_a_rotation_speed_in_rpm_and_rev_per_s_by_hand():
    """rpm → rad/s by 2π/60, rev/s by 2π (numbers by hand); Hz and 1/s for a speed are refused in one line naming
    the parameter and the units to use."""
    w = lambda v: to_si(quantity("operating.carrier_speed", v, "angular_velocity"))
    assert w("600 rpm") == pytest.approx(20 * math.pi, rel=1e-14)          # 600·2π/60
    assert w("10 rev/s") == pytest.approx(20 * math.pi, rel=1e-14)
    assert w("20 rad/s") == 20.0
    for bad in ("10 Hz", "10 1/s", "10 kHz"):
        with pytest.raises(ParameterError) as exc:
            w(bad)
        msg = str(exc.value)
        assert msg.startswith("operating.carrier_speed: expected an angular velocity") and "\n" not in msg
        assert "use rpm, rad/s or rev/s" in msg
    p = with_overrides(reference_dpgt(), {"operating.carrier_speed": "600 rpm"})
    assert p.si().operating.carrier_speed == pytest.approx(20 * math.pi, rel=1e-14)


def test_hz_and_bare_numbers_are_refused_where_ambiguous():
    with pytest.raises(ParameterError, match=r"^operating\.carrier_speed: .*Hz"):
        quantity("operating.carrier_speed", "70 Hz", "angular_velocity")
    with pytest.raises(ParameterError, match=r"gears\.sun\.pressure_angle: expected an angle"):
        quantity("gears.sun.pressure_angle", 0.35, "angle")
    with pytest.raises(ParameterError, match="give units"):
        quantity("bearing.clearance", 3, "length")
    assert to_si(quantity("x", 0.07, "dimensionless")) == 0.07
    assert to_si(quantity("x", "5 %", "dimensionless")) == pytest.approx(0.05)
    assert to_si(quantity("a", "20 deg", "angle")) == pytest.approx(math.radians(20), rel=1e-15)


def test_error_message_names_parameter_value_and_expected_unit():
    with pytest.raises(ParameterError) as exc:
        quantity("bearing.clearance", "3 kg", "length")
    assert str(exc.value) == "bearing.clearance: expected a length (e.g. '20 um'), got '3 kg'"
    assert exc.value.parameter == "bearing.clearance"
    assert isinstance(exc.value, ValueError)
    with pytest.raises(ParameterError, match="not a quantity pint can read"):
        quantity("bearing.clearance", "three mm", "length")
    with pytest.raises(ParameterError, match="finite"):
        quantity("bearing.clearance", "nan mm", "length")


def test_foreign_registry_quantity_is_rehomed():
    other = pint.UnitRegistry()
    q = quantity("bearing.clearance", other.Quantity(20, "um"), "length")
    assert q._REGISTRY is ureg and to_si(q) == pytest.approx(20e-6)


def test_fractional_exponent_units_palmgren():
    k_mm = quantity("k", "5.683e5 N/mm**(10/9)", "contact_stiffness")
    assert to_si(k_mm) == pytest.approx(5.683e5 * 1e3 ** (10 / 9), rel=1e-12)
    assert to_si(k_mm) == pytest.approx(1.22e9, rel=5e-3)
    with pytest.raises(ParameterError, match="line-contact stiffness"):
        quantity("k", "1e9 N/m", "contact_stiffness")


@given(st.floats(1e-9, 1e9), st.sampled_from(["mm", "um", "m", "N/mm**(10/9)", "N/(mm*um)", "rpm", "kW", "deg"]))
def test_format_quantity_round_trips_exactly(x, unit):
    q = Q_(x, unit)
    back = Q_(format_quantity(q))
    assert to_si(back) == pytest.approx(to_si(q), rel=1e-14)


# ------------------------------------------------------------------ parameter objects
def test_units_round_trip_mm_in_m_inside():
    b = reference_bearing()
    assert str(b.pitch_diameter.units) == "millimeter"     # the object keeps the user's units
    s = b.si()
    assert s.pitch_diameter == pytest.approx(0.039, rel=1e-15)
    assert s.clearance == pytest.approx(20e-6, rel=1e-12)
    assert s.inner_raceway_radius == pytest.approx(31.5e-3 / 2)
    assert s.outer_raceway_radius == pytest.approx((46.5e-3 + 20e-6) / 2)
    # docs/model.md §8: P_d = 2R_o − 2R_i − 2D
    assert 2 * s.outer_raceway_radius - 2 * s.inner_raceway_radius - 2 * s.roller_diameter == pytest.approx(s.clearance)


def test_derived_bearing_values():
    s = reference_bearing().si()
    assert s.roller_mass == pytest.approx(3.1e-3, rel=0.01)                  # PARAMETERS: 3.1 g
    assert s.roller_mass == pytest.approx(7850 * math.pi * 7.5e-3 ** 2 / 4 * 9e-3, rel=1e-12)
    assert s.roller_inertia == pytest.approx(s.roller_mass * 7.5e-3 ** 2 / 8, rel=1e-12)
    assert s.contact_stiffness == pytest.approx(1.22e9, rel=5e-3)            # Palmgren, l = 9 mm
    # the same from Palmgren's δ[mm] = 3.84e-5 Q^0.9 / l^0.8 at Q = 1 kN (coefficient rounded to 8.06e4)
    q, l_mm = 1000.0, 9.0
    delta_m = 3.84e-5 * q ** 0.9 / l_mm ** 0.8 * 1e-3
    assert s.contact_stiffness * delta_m ** (10 / 9) == pytest.approx(q, rel=3e-3)
    assert s.cage.inertia == pytest.approx(0.04 * (39e-3 / 2) ** 2)


def test_gear_inertia_rules_follow_overrides():
    p = reference_dpgt()
    s = p.si().gears
    assert s.sun.inertia == pytest.approx(0.5 * 1.088 * 0.0465 ** 2)
    assert s.ring.inertia == pytest.approx(6.07 * 0.123 ** 2)                 # thin ring
    assert s.carrier_inertia == pytest.approx(0.5 * 7.751 * (1.2 * 0.087) ** 2)
    q = with_overrides(p, {"gears.sun.mass": "2.176 kg"})
    assert q.si().gears.sun.inertia == pytest.approx(2 * s.sun.inertia)
    assert q.gears.sun.source("inertia").tag == "assumed"                    # still the rule
    r = with_overrides(p, {"gears.sun.inertia": "0.002 kg*m^2"})
    assert r.si().gears.sun.inertia == pytest.approx(0.002)
    assert r.gears.sun.source("inertia").tag == "user"


def test_contact_stiffness_follows_roller_length_unless_given():
    p = reference_dpgt()
    q = with_overrides(p, {"bearing.roller_length": "18 mm"})
    assert q.si().bearing.contact_stiffness == pytest.approx(p.si().bearing.contact_stiffness * 2 ** (8 / 9))
    r = with_overrides(p, {"bearing.contact_stiffness": "1.5e9 N/m**(10/9)"})
    assert r.si().bearing.contact_stiffness == pytest.approx(1.5e9)


@pytest.mark.parametrize("key, value, match", [
    ("bearing.clearance", "-3 um", r"^bearing\.clearance: must be >= 0"),
    ("bearing.clearance", "3 kg", r"^bearing\.clearance: expected a length"),
    ("gears.planets", 0, r"^gears\.planets: must be >= 1"),
    ("gears.planets", 2.5, r"^gears\.planets: expected an integer"),
    ("gears.planets", True, r"^gears\.planets: expected an integer"),
    ("bearing.rollers", 2, r"^bearing\.rollers: must be >= 3"),
    ("gears.handedness", 0, r"^gears\.handedness: expected \+1 or -1"),
    ("gears.sun.mass", "-1 kg", r"^gears\.sun\.mass: must be > 0"),
    ("gears.ring.teeth", "many", r"^gears\.ring\.teeth: expected an integer"),
    ("gears.sun.pressure_angle", "50 deg", r"^gears\.sun\.pressure_angle: must be between 0 and 45 deg"),
    ("bearing.cage.restitution", 1.5, r"^bearing\.cage\.restitution: must be in \(0, 1\], got 1\.5"),
    ("bearing.cage.guide_clearance", "-0.1 mm", r"^bearing\.cage\.guide_clearance: must be >= 0"),
    ("mesh.stiffness_ratio", 0.5, r"^mesh\.stiffness_ratio: must be >= 1"),
    ("operating.direction", "left", r"^operating\.direction: expected one of"),
    ("operating.carrier_speed", "70 Hz", r"^operating\.carrier_speed: .*angle unit"),
    ("gravity", "9.81 m", r"^gravity: expected an acceleration"),
])
def test_invalid_values_name_the_parameter(key, value, match):
    with pytest.raises(ParameterError, match=match) as exc:
        with_overrides(reference_dpgt(), {key: value})
    assert exc.value.parameter == key


def test_direct_construction_checks_values():
    with pytest.raises(ParameterError, match=r"^bearing\.clearance: must be >= 0"):
        dataclasses.replace(reference_bearing(), clearance="-1 um")
    with pytest.raises(ParameterError, match=r"^gear\.teeth"):
        GearParams(teeth=2, module="3 mm", pressure_angle="20 deg", face_width="30 mm", mass="1 kg")
    with pytest.raises(ParameterError, match=r"^bearing\.cage\.mass: is required"):
        CageParams(mass=None, pocket_clearance="0.1 mm", guide_clearance="0.1 mm", pocket_stiffness="1e7 N/m",
                   guide_stiffness="1e7 N/m", restitution=0.8, pocket_friction=0.1, guide_friction=0.1,
                   friction_speed="0.01 m/s", impact_speed_floor="0.01 m/s", impact_law="exact", land_law="dry",
                   land_width="4 mm", land_min_film="1 um", guidance="outer_land", pocket_radial_clearance="0.15 mm",
                   pocket_law="dry", pocket_min_film="1 um")
    with pytest.raises(TypeError):  # a forgotten field is a programming error, caught by the dataclass
        BearingParams(pitch_diameter="39 mm")


def test_nested_table_errors_are_located():
    with pytest.raises(ParameterError, match=r"^gears\.sun: a GearParams table needs all of"):
        with_overrides(reference_dpgt(), {"gears.sun": {"teeth": 30}})
    with pytest.raises(ParameterError, match=r"^gears\.sun\.teeth: must be >= 3"):
        with_overrides(reference_dpgt(), {"gears.sun": {**flatten(reference_dpgt().gears.sun), "teeth": 1}})


# ------------------------------------------------------------------ provenance
def test_preset_source_tags():
    p = reference_dpgt()
    tags = {
        "gears.sun.teeth": "paper", "gears.ring.face_width": "paper", "gears.carrier_mass": "paper",
        "gears.handedness": "assumed", "gears.sun.inertia": "assumed", "gears.planets": "paper",
        "bearing.pitch_diameter": "paper", "bearing.rollers": "paper", "bearing.clearance": "assumed",
        "bearing.roller_mass": "derived", "bearing.contact_stiffness": "derived",
        "bearing.cage.pocket_stiffness": "assumed", "mesh.mean_stiffness": "derived",
        "mesh.c_gamma_alpha": "derived", "mesh.stiffness_ratio": "derived", "operating.carrier_speed": "paper", "operating.output_power": "paper",
        "lubricant.density": "assumed", "support.ring_tangential_stiffness": "assumed", "gravity": "assumed",
    }
    for path, tag in tags.items():
        *owner, name = path.split(".")
        obj = p
        for part in owner:
            obj = getattr(obj, part)
        assert obj.source(name).tag == tag, path
    # every leaf carries a paper/derived/assumed tag in the preset
    for path in parameter_names(p):
        *owner, name = path.split(".")
        obj = p
        for part in owner:
            obj = getattr(obj, part)
        assert obj.source(name).tag in ("paper", "derived", "assumed"), path
    text = describe(p)
    assert "bearing.clearance" in text and "[assumed]" in text and "[paper]" in text and "[derived]" in text


def test_override_marks_user_unless_unchanged_or_sourced():
    p = reference_dpgt()
    q = with_overrides(p, {"bearing.clearance": "30 um"})
    assert q.bearing.source("clearance").tag == "user"
    assert q.bearing.clearance == Q_(30, "um")
    assert q.bearing.source("pitch_diameter").tag == "paper"
    same = with_overrides(p, {"bearing.clearance": "0.02 mm"})  # equal value: provenance kept
    assert same.bearing.source("clearance").tag == "assumed"
    tagged = with_overrides(p, {"bearing.clearance": assumed("40 um", "C3 clearance")})
    assert tagged.bearing.source("clearance") == Source("assumed", "C3 clearance")
    # dataclasses.replace bypasses with_overrides; the stale tag is still not reported
    r = dataclasses.replace(p.bearing, clearance="50 um")
    assert r.source("clearance").tag == "user"
    assert p.bearing.source("clearance").tag == "assumed"  # the original is untouched (frozen)


def test_unknown_override_keys_name_the_near_ones_and_where_the_rest_are():
    with pytest.raises(ParameterError) as exc:
        with_overrides(reference_dpgt(), {"bearing.clearence": "30 um"})
    msg = str(exc.value)
    assert msg.startswith("bearing.clearence: unknown parameter (did you mean 'bearing.clearance'?)")
    assert msg.endswith("`dpgt params --grep bearing`")      # the section's keys, not a list of fifty
    assert "bearing.roller_diameter" not in msg and "gears.planets" not in msg
    with pytest.raises(ParameterError, match=r"^bearings\.clearance: unknown parameter \(did you mean "
                                             r"'bearing\.clearance'\?\); every key: `dpgt params`$"):
        with_overrides(reference_dpgt(), {"bearings.clearance": "30 um"})
    with pytest.raises(ParameterError, match=r"^gears\.sun\.teeth\.x: unknown parameter"):
        with_overrides(reference_dpgt(), {"gears.sun.teeth.x": 1})
    with pytest.raises(ParameterError, match=r"^sources: unknown parameter"):
        with_overrides(reference_dpgt(), {"sources": {}})


def test_overrides_several_levels_at_once():
    p = with_overrides(reference_dpgt(), {"bearing.clearance": "30 um", "gears.planets": 4, "gears.sun.teeth": 29,
                                          "bearing.cage.mass": "50 g", "operating.direction": "reverse"})
    assert (p.gears.planets, p.gears.sun.teeth, p.operating.direction) == (4, 29, "reverse")
    s = p.si()
    assert s.bearing.clearance == pytest.approx(30e-6) and s.bearing.cage.mass == pytest.approx(0.05)
    assert s.operating.carrier_speed == pytest.approx(-4200 * RPM)
    assert s.layout.psi_a.shape == (4,)


# ------------------------------------------------------------------ TOML
def test_toml_loading(tmp_path):
    f = tmp_path / "machine.toml"
    f.write_text('gravity = "0 m/s^2"\n[bearing]\nclearance = "30 um"\n[bearing.cage]\nmass = "0.05 kg"\n'
                 '[gears]\nplanets = 4\nhandedness = 1\n[gears.sun]\nteeth = 29\n', encoding="utf-8")
    p = load_toml(f)
    assert p.bearing.clearance == Q_(30, "um") and p.bearing.source("clearance").tag == "user"
    assert (p.gears.planets, p.gears.handedness, p.gears.sun.teeth) == (4, 1, 29)
    assert p.si().gravity == 0.0 and p.si().bearing.cage.mass == pytest.approx(0.05)
    assert p.bearing.source("pitch_diameter").tag == "paper"
    f.write_text("[bearing]\nclearence = \"30 um\"\n", encoding="utf-8")
    with pytest.raises(ParameterError, match=r"^bearing\.clearence: unknown parameter"):
        load_toml(f)
    f.write_text("[bearing]\nclearance = 30\n", encoding="utf-8")
    with pytest.raises(ParameterError, match=r"^bearing\.clearance: expected a length .*give units"):
        load_toml(f)
    with pytest.raises(ParameterError, match="invalid TOML"):
        overrides_from_toml("[bearing\n")


def test_toml_round_trip_is_lossless():
    p = with_overrides(reference_dpgt(2, "reverse"), {"bearing.contact_stiffness": "5.7e5 N/mm**(10/9)",
                                                      "gears.sun.inertia": "1.3e-3 kg*m^2"})
    text = to_toml(p)
    q = with_overrides(reference_dpgt(), overrides_from_toml(text))
    assert q == p
    assert q.si().bearing.contact_stiffness == p.si().bearing.contact_stiffness
    assert q.bearing.source("pitch_diameter").tag == "paper"
    assert q.bearing.source("contact_stiffness").tag == "user"


# ------------------------------------------------------------------ SI view and operating points
def test_si_view_is_plain_floats_and_read_only():
    s = reference_dpgt().si()
    assert isinstance(s, DPGTSI)
    # a choice among names (a law, a relief shape) stays a name
    choices = {f.name for c in _params_classes() for f in dataclasses.fields(c)
               if "spec" in f.metadata and f.metadata["spec"].kind == "choice"}
    lists = {f.name for c in _params_classes() for f in dataclasses.fields(c)     # a nested list of tables
             if "spec" in f.metadata and f.metadata["spec"].kind == "entries"}
    for sect in ("bearing", "gears", "mesh", "support", "lubricant"):
        for k, v in s[sect].to_dict().items():
            if isinstance(v, dict):
                assert all(isinstance(x, (int, float, bool)) or x is None or (isinstance(x, str) and y in choices)
                           or (isinstance(x, tuple) and y in lists) for y, x in v.items()), (sect, k)
            elif k in choices:
                assert isinstance(v, str), (sect, k)
            else:
                assert isinstance(v, (int, float, bool)) or v is None, (sect, k)
    with pytest.raises(AttributeError):
        s.gravity = 0
    with pytest.raises(AttributeError, match="no SI value"):
        s.bearing.clearence
    assert s.support.ring_torsional_stiffness == pytest.approx(1e9 * 0.123 ** 2)


def _params_classes(cls=Params):
    for sub in cls.__subclasses__():
        yield sub
        yield from _params_classes(sub)


@pytest.mark.parametrize("cls", list(_params_classes()), ids=lambda c: c.__name__)
def test_si_classes_have_the_parameter_fields_and_the_declared_derived_values(cls):
    si_fields = {f.name: f.type for f in dataclasses.fields(cls.SI)}
    params = [f.name for f in dataclasses.fields(cls) if "spec" in f.metadata]
    derived = [d.name for d in cls._si_derived]
    assert list(si_fields) == params + [n for n in derived if n not in params]
    assert issubclass(cls.SI, SI) and cls.SI.__dataclass_params__.frozen


def test_si_objects_are_cached_and_support_replace_and_to_dict():
    p = reference_dpgt()
    s = p.si()
    assert p.si() is s and p.bearing.si() is p.bearing.si()
    b = dataclasses.replace(s.bearing, clearance=1e-5)
    assert b.clearance == 1e-5 and s.bearing.clearance == pytest.approx(20e-6)
    assert s.bearing.replace(rows=2).rows == 2
    d = s.to_dict()
    assert d["bearing"]["cage"]["mass"] == pytest.approx(0.04) and d["layout"] is s.layout
    assert s.gears["sun"] is s.gears.sun
    with pytest.raises(KeyError):
        s.gears["moon"]


def test_operating_conditions():
    assert {k: (v[0].to("rpm").magnitude, v[1].to("kW").magnitude) for k, v in CONDITIONS.items()} == \
        {1: (1000, 200), 2: (2000, 200), 3: (4200, 200), 4: (4200, 0)}
    op = operating_point(1, "reverse").si()
    assert op.carrier_speed == pytest.approx(-1000 * RPM) and op.sign == -1 and op.output_power == 2e5
    with pytest.raises(ParameterError, match=r"^operating\.condition"):
        operating_point(5)
    with pytest.raises(ParameterError, match=r"^operating\.direction"):
        operating_point(1, "backwards")


@pytest.mark.parametrize("condition, n_c, n_s", [(3, 4200, -6909.7), (2, 2000, -3290.3)])
@pytest.mark.parametrize("direction", ["forward", "reverse"])
def test_sun_speed_and_power_balance(condition, n_c, n_s, direction):
    sign = 1 if direction == "forward" else -1
    k = reference_dpgt(condition, direction).si().operating
    assert k.carrier_speed / RPM == pytest.approx(sign * n_c, rel=1e-12)
    assert k.sun_speed / RPM == pytest.approx(sign * n_s, abs=0.05)
    assert k.sun_torque * k.sun_speed == pytest.approx(200e3)               # the sun drives
    assert k.carrier_torque * k.carrier_speed == pytest.approx(-200e3)      # the carrier is loaded
    assert k.sun_torque + k.carrier_torque + k.ring_torque == pytest.approx(0, abs=1e-9)
    assert k.mesh_frequency == pytest.approx(82 * n_c / 60)


def test_no_load_condition_has_no_torques():
    k = reference_dpgt(4).si().operating
    assert (k.sun_torque, k.carrier_torque, k.ring_torque) == (0.0, 0.0, 0.0)


# ------------------------------------------------------------------ property tests
bearing_values = st.fixed_dictionaries({
    "bearing.pitch_diameter": st.floats(10, 80).map(lambda x: f"{x} mm"),
    "bearing.roller_diameter": st.floats(1, 20).map(lambda x: f"{x} mm"),
    "bearing.roller_length": st.floats(2, 40).map(lambda x: f"{x} mm"),
    "bearing.rollers": st.integers(3, 40),
    "bearing.clearance": st.floats(0, 200).map(lambda x: f"{x} um"),
    "bearing.cage.pocket_clearance": st.floats(0, 1).map(lambda x: f"{x} mm"),
})


@settings(max_examples=60, deadline=None)
@given(bearing_values)
def test_random_bearings_checks_never_crash_and_si_is_consistent(values):
    p = with_overrides(reference_dpgt(), values)
    found = geo.design_findings(p)
    assert all(f.severity in ("error", "warning") and f.parameter and f.message for f in found)
    s = p.si().bearing
    for key, v in values.items():
        *_, leaf = key.split(".")
        sect = s.cage if ".cage." in key else s
        assert sect[leaf] == pytest.approx(to_si(Q_(v)) if isinstance(v, str) else v, rel=1e-12)
    assert s.outer_raceway_radius - s.inner_raceway_radius - s.roller_diameter == pytest.approx(s.clearance / 2, abs=1e-15)
    assert s.contact_stiffness == pytest.approx(geo.palmgren_stiffness(s.roller_length))
    fits = s.pitch_diameter * math.sin(math.pi / s.rollers) > s.roller_diameter and s.roller_diameter < s.pitch_diameter
    errors = {f.parameter for f in found if f.severity == "error"}
    assert fits == ("bearing.rollers" not in errors and "bearing.roller_diameter" not in errors)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if errors:
            with pytest.raises(ParameterError):
                geo.check_design(p)
        else:
            geo.check_design(p)


def test_backlash_defaults_to_the_iso_minimum_per_mesh_and_zero_is_allowed():
    """docs/model.md §1.5: j_bn,min = (2/3)(0.06 + 0.0005 a + 0.03 m_n) mm, a per mesh type, tagged [derived]."""
    p = reference_dpgt()
    si = p.si()
    for key, a_mm, b_mm in (("sun_inner", 82.5, 0.1275), ("inner_outer", 72.0, 0.124), ("outer_ring", 87.0, 0.129)):
        m = si.layout.meshes[key]
        assert m.centre_distance == pytest.approx(a_mm * 1e-3)
        assert m.backlash == pytest.approx(b_mm * 1e-3, rel=1e-12) == si.mesh[f"backlash_{key}"]
        assert p.mesh.source(f"backlash_{key}").tag == "derived"
    zero = with_overrides(p, {"mesh.backlash_outer_ring": "0 um"}).si().layout.meshes
    assert zero["outer_ring"].backlash == 0.0 and zero["sun_inner"].backlash == pytest.approx(1.275e-4)
    with pytest.raises(ParameterError, match=r"^mesh\.backlash_sun_inner: must be >= 0"):
        with_overrides(p, {"mesh.backlash_sun_inner": "-1 um"})


def test_planet_inertia_is_an_annulus_with_the_bearing_bore_unless_given():
    p = reference_dpgt()
    si = p.si()
    bore = si.bearing.outer_raceway_radius
    for g in ("inner_planet", "outer_planet"):
        gp = si.gears[g]
        assert gp.inertia == pytest.approx(0.5 * gp.mass * (gp.pitch_radius ** 2 + bore ** 2), rel=1e-12)
    assert si.gears.sun.inertia == pytest.approx(0.5 * si.gears.sun.mass * si.gears.sun.pitch_radius ** 2)
    given = with_overrides(p, {"gears.outer_planet.inertia": "4e-4 kg*m^2"}).si().gears
    assert given.outer_planet.inertia == pytest.approx(4e-4) and given.inner_planet.inertia == si.gears.inner_planet.inertia
    # the bore follows the bearing: a larger clearance, a (slightly) larger annulus
    wider = with_overrides(p, {"bearing.clearance": "100 um"}).si().gears.inner_planet.inertia
    assert wider > si.gears.inner_planet.inertia


def test_bearing_rows_is_a_count_of_at_least_one():
    assert reference_dpgt().bearing.rows == 1 and reference_dpgt().bearing.source("rows").tag == "paper"
    assert with_overrides(reference_dpgt(), {"bearing.rows": 2}).si().bearing.rows == 2
    with pytest.raises(ParameterError, match=r"^bearing\.rows"):
        with_overrides(reference_dpgt(), {"bearing.rows": 0})


@pytest.mark.parametrize("unit, text", [("N/m**(10/9)", "N/m^(10/9)"), ("N*s/m**(10/9)", "N·s/m^(10/9)"),
                                        ("kg*m**2", "kg·m²"), ("mm**2/s", "mm²/s"), ("dimensionless", "1")])
def test_a_unit_reads_as_written_and_back_to_itself(unit, text):
    """A fractional exponent as ^(p/q), not pint's decimal superscripts; the text parses back to the same unit."""
    from components.units import unit_text, ureg
    assert unit_text(ureg.Unit(unit)) == text
    back = text.replace("^", "**").replace("·", "*").replace("²", "**2")
    assert ureg.Quantity(1.0, back).to(unit).magnitude == pytest.approx(1.0, rel=1e-15)
