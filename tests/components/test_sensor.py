"""The rig's housing accelerometer as transfer paths (docs/model.md §12, components.sensor): the passing-planet
window, each path against a closed form, the loads recorded on the housing, and the planet-phasing rule that
says which sidebands a sensor can see (components.geometry.sideband_origin) — on every path of a simulated
perfect machine."""
from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from components.geometry import sideband_origin
from components.params import SensorParams, with_overrides
from components.presets import reference_dpgt, rig_accelerometer
from components.scene import SceneOptions
from components.sensor import (HousingLoads, hann_window, housing_paths, mesh_path, mode_acceleration, rocking_lever,
                               sensor_axis, sensor_from_dict)
from components.units import ParameterError
from scenarios.core.analysis import amplitude_spectrum
from scenarios.core.runner import RunConfig, run_case
from scenarios.spectrum import _whole_revolutions, sensor_paths

from tests.support.dpgt_runs import build

widths = st.floats(0.05, 2 * math.pi)
angles = st.floats(-20.0, 20.0)


def _sensor(**changes):
    """The rig's sensor (SI) with some values changed (SI floats; housing values by their names)."""
    s = rig_accelerometer().si()
    housing = {k: changes.pop(k) for k in list(changes) if k in s.housing.__dataclass_fields__}
    return dataclasses.replace(s, housing=dataclasses.replace(s.housing, **housing), **changes)


# ---------------------------------------------------------------------------------------------------------
# the window and the mesh path
# ---------------------------------------------------------------------------------------------------------
@given(widths, angles)
def test_window_is_one_at_the_sensor_zero_beyond_half_width_and_symmetric(width, d):
    w = float(hann_window(d, width))
    assert 0.0 <= w <= 1.0
    assert float(hann_window(0.0, width)) == 1.0
    assert float(hann_window(-d, width)) == pytest.approx(w, abs=1e-12)
    assert float(hann_window(d + 2 * math.pi, width)) == pytest.approx(w, abs=1e-9)
    wrapped = abs((d + math.pi) % (2 * math.pi) - math.pi)
    if wrapped >= 0.5 * width:
        assert w == 0.0
    assert float(hann_window(0.25 * width, width)) == pytest.approx(0.5)      # cos²(π/4)


@given(widths)
def test_window_is_smooth_value_and_slope_vanish_at_its_edge(width):
    """A passing planet fades in without a step in weight or slope: near the edge w ≈ (π ε/W)²."""
    for eps in (1e-3, 1e-4):
        e = eps * width
        inside = float(hann_window(0.5 * width - e, width))
        assert inside == pytest.approx((math.pi * e / width) ** 2, rel=1e-3)
        slope = (inside - float(hann_window(0.5 * width - 2 * e, width))) / e
        assert abs(slope) <= 4 * math.pi ** 2 * e / width ** 2       # → 0 at the edge
    if width < 2 * math.pi - 2e-9:      # a full-circle window has no outside: past π it wraps back in
        assert float(hann_window(0.5 * width + 1e-9, width)) == 0.0


def test_mesh_path_by_hand():
    """Planets at the sensor (w = 1), a quarter width away (w = 1/2) and opposite (w = 0); forces on the ring
    in the fixed frame, read along the radial axis at ψ_s = 90° (the y axis) and the tangential one (−x)."""
    s = _sensor()
    psi = np.array([s.angle, s.angle + 0.25 * s.window_width, s.angle + math.pi])
    F = np.array([[70.0, 600.0], [-20.0, 300.0], [900.0, 5000.0]])
    assert float(mesh_path(psi, F, s)) == pytest.approx((600.0 + 0.5 * 300.0) / 6.07)
    tangential = dataclasses.replace(s, direction="tangential")
    assert float(mesh_path(psi, F, tangential)) == pytest.approx((-70.0 + 0.5 * 20.0) / 6.07)
    two = mesh_path(np.stack([psi, psi]), np.stack([F, 2 * F]), s)          # broadcasting over samples
    assert two == pytest.approx([750.0 / 6.07, 1500.0 / 6.07])


def test_the_mesh_path_reads_the_forces_vibration_not_their_steady_load():
    """Three planets orbiting at f_c = 1 Hz, each pressing on the ring with a steady 5 kN radial and 1.8 kN
    tangential load (steady in its own directions: it turns with the planet) plus a 300 N radial vibration at
    f_m = 20 f_c, over one whole revolution: the vibration is the 300 N part alone, and the mesh path reads it
    alone — the steady load, which would read 5 kN / m_eq at every planet pass, reads nothing."""
    from components.sensor import paths, vibration
    s = _sensor()
    t = np.arange(4000) / 4000.0
    psi = 2 * np.pi * t[:, None] + 2 * np.pi * np.arange(3) / 3
    c, sn = np.cos(psi), np.sin(psi)
    radial_vib = 300.0 * np.sin(2 * np.pi * 20.0 * t)[:, None] * np.ones(3)
    on_ring = lambda r, q: np.stack([r * c - q * sn, r * sn + q * c], axis=-1)     # noqa: E731
    steady, vib = on_ring(5000.0 + 0 * psi, 1800.0 + 0 * psi), on_ring(radial_vib, 0 * psi)
    assert np.abs(vibration(psi, steady + vib) - vib).max() < 1e-9
    zero = np.zeros((t.size, 2))
    read = lambda F: paths(t, psi, F, zero, np.zeros(t.size), s)["mesh"]           # noqa: E731
    assert np.abs(read(steady)).max() < 1e-9
    assert read(steady + vib) == pytest.approx(mesh_path(psi, vib, s), abs=1e-9)
    assert np.abs(mesh_path(psi, steady, s)).max() > 0.5 * 5000.0 / 6.07          # what the law alone reads


# ---------------------------------------------------------------------------------------------------------
# one mode: closed forms
# ---------------------------------------------------------------------------------------------------------
def _steady_line(t, x, f):
    """(amplitude, phase [rad]) of the sinusoid at f in x, by least squares (x ≈ a sin(ωt + φ))."""
    M = np.column_stack([np.sin(2 * np.pi * f * t), np.cos(2 * np.pi * f * t), np.ones_like(t)])
    s, c, _ = np.linalg.lstsq(M, x, rcond=None)[0]
    return math.hypot(s, c), math.atan2(c, s)


@pytest.mark.parametrize("ratio", [0.5, 1.0, 2.7])
def test_mode_reads_the_closed_form_steady_state_of_a_sinusoidal_load(ratio):
    """m ẍ + c ẋ + k x = F0 sin ωt: at steady state ẍ = −ω² X sin(ωt − φ), X = F0/√((k − mω²)² + (cω)²),
    tan φ = cω/(k − mω²) (φ in (0, π)): below, at (|ẍ| = F0/(2ζ m) there) and above resonance. 400 samples a
    period (first-order hold of a sine: amplitude error (π f dt)²/3 ≈ 2e-5); the start transient has decayed
    by e^(−ζ ω_n t) < 1e-9 where the line is fitted (t > 70 ms). A factor 2 in ζ, a wrong sign or exponent fails."""
    m, fn, zeta, F0 = 50.0, 1000.0, 0.05, 300.0
    f = ratio * fn
    t = np.arange(0, 0.09, 1 / (400 * f))
    a = mode_acceleration(t, F0 * np.sin(2 * np.pi * f * t), m, fn, zeta)
    wn, w = 2 * np.pi * fn, 2 * np.pi * f
    k, c = m * wn ** 2, 2 * zeta * m * wn
    X = F0 / math.hypot(k - m * w ** 2, c * w)
    phi = math.atan2(c * w, k - m * w ** 2)
    late = t > 0.07
    amp, ph = _steady_line(t[late], a[late], f)
    assert amp == pytest.approx(w ** 2 * X, rel=1e-4)
    assert math.remainder(ph - (math.pi - phi), 2 * math.pi) == pytest.approx(0.0, abs=1e-4)
    if ratio == 1.0:
        assert amp == pytest.approx(F0 / (2 * zeta * m), rel=1e-4)


def test_mode_starts_at_its_static_deflection_and_settles_after_a_step():
    """A static load reads zero from the first sample (the mode starts at rest at load/k); a step ΔF (a ramp over
    one sample for the first-order hold) brings ẍ ≈ ΔF/m at once, which then rings at ω_d and decays as
    e^(−ζ ω_n t) to zero."""
    m, fn, zeta = 2.9, 630.0, 0.05
    t = np.arange(0, 0.2, 5e-5)
    assert np.all(mode_acceleration(t, np.full(t.size, -1234.5), m, fn, zeta) == 0.0)
    load = np.where(t < 0.05, 200.0, 500.0)
    a = mode_acceleration(t, load, m, fn, zeta)
    assert np.all(a[t < 0.05] == 0.0)
    i = np.flatnonzero(t >= 0.05)[0]
    assert 0.5 * 300.0 / m < a[i] <= 300.0 / m                  # the ramp of one sample: ≈ ΔF/m, not more
    wn = 2 * np.pi * fn
    decayed = 300.0 / m * math.exp(-zeta * wn * (0.15 - 0.05))  # envelope 0.1 s after the step: ~2e-9
    assert np.abs(a[t > 0.15]).max() <= 2 * decayed


def test_the_sensor_geometry_by_hand():
    """(k × (r_s − r_O))·e with O = (0, −h): radial at 0° reads −h per unit rocking, at 180° +h, at 90° (on the
    vertical through O) nothing; tangential at 90° reads r_s + h, at 0° r_s. The axis e in the fixed frame."""
    R, h = 0.1, 0.2
    for angle, direction, lever in ((0.0, "radial", -h), (math.pi, "radial", h), (0.5 * math.pi, "radial", 0.0),
                                    (0.5 * math.pi, "tangential", R + h), (0.0, "tangential", R)):
        s = _sensor(angle=angle, direction=direction, radius=R, rocking_centre_depth=h)
        assert rocking_lever(s) == pytest.approx(lever, abs=1e-15)
    assert rocking_lever(_sensor(angle=-0.5 * math.pi)) == 0.0 == rocking_lever(_sensor())    # exactly: the rig's
    np.testing.assert_allclose(sensor_axis(_sensor(angle=0.3, direction="tangential")), [-math.sin(0.3), math.cos(0.3)])


def test_torque_and_bearing_paths_against_the_modes_closed_forms():
    """A sinusoidal torque M0 and force (Fx, Fy) on the housing, sensor radial at 0° (reads x and rocking with
    lever −h): torque path = −h·(rocking ẍ of M0), bearing path = (translation ẍ of Fx) + (−h)·(rocking ẍ of
    −h Fx) — each mode's closed form H(ω) = −ω²/(k − mω² + i cω), summed as phasors; Fy is not read."""
    s = _sensor(angle=0.0, direction="radial")
    H, f = s.housing, 1700.0
    t = np.arange(0, 0.13, 1 / (400 * f))       # the rocking mode's transient: e^(−t/5 ms) < 3e-9 after 0.1 s
    w = 2 * np.pi * f
    M0, Fx0, Fy0 = 80.0, 300.0, 1000.0
    out = housing_paths(t, np.column_stack([Fx0 * np.sin(w * t), Fy0 * np.cos(w * t)]), M0 * np.sin(w * t), s)

    def resp(m, fn, zeta):
        wn = 2 * np.pi * fn
        return -w ** 2 / (m * (wn ** 2 - w ** 2) + 1j * 2 * zeta * m * wn * w)
    rock = resp(H.rocking_inertia, H.rocking_frequency, H.rocking_damping_ratio)
    shift = resp(H.mass, H.translation_frequency, H.translation_damping_ratio)
    h = H.rocking_centre_depth
    expected = {"torque": -h * rock * M0, "bearing": Fx0 * (shift + h * h * rock)}
    late = t > 0.1
    for name, z in expected.items():
        amp, ph = _steady_line(t[late], out[name][late], f)
        assert amp == pytest.approx(abs(z), rel=1e-4), name
        assert math.remainder(ph - np.angle(z), 2 * math.pi) == pytest.approx(0.0, abs=1e-4), name


def test_the_sensor_at_the_sources_place_is_derived_from_its_position():
    """The carrier bearing's boss (components.presets.carrier_bearing_accelerometer): the window spans the circle, so
    a planet 120° away weighs cos²(60°) = 1/4 and one opposite 0; m_eq is the ring's mass plus the housing's and
    follows them; the torque path's lever is 0 (radial at the top), the housing is the machine's."""
    from components.presets import SENSOR_PRESETS, carrier_bearing_accelerometer

    base = reference_dpgt(2)
    p = carrier_bearing_accelerometer(base)
    assert p.source("window_width").tag == "derived" and p.source("equivalent_mass").tag == "derived"
    assert p.source("radius").tag == "assumed" and "carrier axis" in p.source("radius").note
    s = p.si()
    assert s.window_width == pytest.approx(2 * math.pi) and s.radius < base.si().gears.ring.pitch_radius
    w = hann_window(np.array([0.0, 2 * math.pi / 3, -2 * math.pi / 3, math.pi]), s.window_width)
    assert w == pytest.approx([1.0, 0.25, 0.25, 0.0], abs=1e-12)
    assert s.equivalent_mass == pytest.approx(6.07 + 50.0)
    heavier = with_overrides(base, {"gears.ring.mass": "7 kg", "rig.sensor.housing.mass": "60 kg"})
    assert carrier_bearing_accelerometer(heavier).si().equivalent_mass == pytest.approx(67.0)
    assert rocking_lever(s) == 0.0 and s.housing == base.si().rig.sensor.housing
    assert SENSOR_PRESETS["housing_top"](base) == base.rig.sensor and SENSOR_PRESETS["carrier_bearing"](base) == p


def test_sensor_parameters_are_checked_and_sourced():
    p = rig_accelerometer()
    for name in ("angle", "radius", "window_width", "equivalent_mass", "direction"):
        assert p.source(name).tag == "assumed"
    for name in ("mass", "translation_frequency", "translation_damping_ratio", "rocking_inertia", "rocking_frequency",
                 "rocking_damping_ratio", "rocking_centre_depth"):
        assert p.housing.source(name).tag == "assumed" and p.housing.source(name).note
    assert "McFadden" in p.source("window_width").note
    base = reference_dpgt(2)
    for key, value, message in (("rig.sensor.window_width", "400 deg", r"in \(0, 360 deg\]"),
                                ("rig.sensor.direction", "axial", "expected one of"),
                                ("rig.sensor.radius", "0 m", "must be > 0"),
                                ("rig.sensor.housing.mass", "50 m", "expected a mass"),
                                ("rig.sensor.housing.rocking_frequency", "600 m", "expected a frequency"),
                                ("rig.sensor.housing.translation_damping_ratio", -0.1, "must be > 0"),
                                ("rig.sensor.housing.rocking_centre_depth", "-1 m", "must be >= 0")):
        with pytest.raises(ParameterError, match=rf"^{key.replace('.', '[.]')}: .*{message}"):
            with_overrides(base, {key: value})
    assert with_overrides(base, {"rig.sensor.angle": "30 deg"}).si().rig.sensor.angle == pytest.approx(math.radians(30))
    s = base.si().rig.sensor
    assert sensor_from_dict(json.loads(json.dumps(s.to_dict()))) == s


# ---------------------------------------------------------------------------------------------------------
# the loads on the housing, on a scene and recorded
# ---------------------------------------------------------------------------------------------------------
def test_housing_loads_are_minus_the_supports_in_the_fixed_frame():
    """Sun, ring and carrier displaced from their anchors and at rest in the fixed frame, seen from a frame
    turned by φ: the housing receives k·d in the fixed frame (minus the support's force −k d on the body), the
    ring's torsional support torque k_θ Δθ, and no torque from the sun's and carrier's supports."""
    import mbd

    p = reference_dpgt(2)
    scene = build(p, bearings="linear")
    model = scene.model
    sup = model.element("support")
    t = 2e-3
    fs = model.frame.at(t)
    c, s = math.cos(fs.phi), math.sin(fs.phi)
    qf, vf = (x.reshape(-1, 3).copy() for x in model.full(0.0, scene.q0, scene.v0))
    d = {"sun": (1e-6, -2e-6), "ring": (3e-6, 0.5e-6), "carrier": (-1e-6, 4e-6)}     # in the fixed frame
    for name, (dX, dY) in d.items():
        i = model.body(name).index
        qf[i, :2] = (c * dX + s * dY, -s * dX + c * dY)                           # to R: Rot(−φ)
        vf[i] = (fs.omega * qf[i, 1], -fs.omega * qf[i, 0], -fs.omega)            # at rest in the fixed frame
    ring = model.body("ring").index
    qf[ring, 2] = sup.theta0[list(sup.dofs[:, 0] // 3).index(ring)] - fs.phi + 1e-5
    q, v = qf.ravel()[model.free], vf.ravel()[model.free]
    loads = HousingLoads(scene)
    FX, FY, M = loads.loads(t, mbd.System(model).outputs(t, q, v, {}))
    for j, name in enumerate(loads.bodies):
        assert FX[j] == pytest.approx(sup.kx[j] * d[name][0], rel=1e-9)
        assert FY[j] == pytest.approx(sup.kx[j] * d[name][1], rel=1e-9)
        assert M[j] == pytest.approx(sup.k_theta[j] * 1e-5 if name == "ring" else 0.0, rel=1e-9, abs=0.0)


@pytest.mark.slow
def test_the_housing_loads_and_the_sensor_are_recorded_only_when_asked(tmp_path):
    """RunConfig(sensor=True) records housing.force_x/force_y/torque with units and long names, per supported
    body, equal to minus the supports' forces turned into the fixed frame (from the recorded body motion); it
    stores the sensor's parameters, and sensor_paths turns the file into the paths: the mesh path equals the
    window formula applied to the recorded planet angles and the ring-mesh forces' vibration (less their mean in
    each planet's radial and tangential directions), the sum is the housing sensor.
    Without it nothing is added."""
    import xarray as xr

    p = reference_dpgt(2)
    cfg = RunConfig(settle=1e-3, window=1e-3, sample_rate=20000.0, progress=False,
                    options=SceneOptions(bearings="linear"))
    run_case(p, cfg, tmp_path / "plain")
    run_case(p, dataclasses.replace(cfg, sensor=True), tmp_path / "sensor")
    with xr.open_dataset(tmp_path / "plain" / "results.nc", engine="h5netcdf") as ds:
        assert not [k for k in ds.variables if k.startswith("housing")] and "sensor" not in ds.attrs
    path = tmp_path / "sensor" / "results.nc"
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        assert ds["housing.force_x"].attrs["units"] == "N" and ds["housing.torque"].attrs["units"] == "N m"
        assert "fixed frame" in ds["housing.force_y"].attrs["long_name"]
        assert list(ds["housing.force_x.instance"].values) == ["sun", "ring", "carrier"]
        bodies = list(ds["motion.body"].values)
        phi = ds["fixed.angle"].values[:, 1] - ds["motion.angle"].values[:, bodies.index("carrier")]
        assert list(ds["fixed.body"].values)[1] == "carrier"
        # the carrier's support in R (−k x − c u, u its ground-relative velocity), turned into the fixed frame
        sup = p.si().support
        k = sup.carrier_stiffness
        cdamp = 2 * sup.damping_ratio * math.sqrt(k * p.si().gears.carrier_mass)
        X, V = ds["fixed.position"].values[:, 1], ds["fixed.velocity"].values[:, 1]
        np.testing.assert_allclose(ds["housing.force_x"].values[:, 2], k * X[:, 0] + cdamp * V[:, 0], rtol=1e-6,
                                   atol=1e-6 * np.abs(k * X).max())
        np.testing.assert_allclose(ds["housing.force_y"].values[:, 2], k * X[:, 1] + cdamp * V[:, 1], rtol=1e-6,
                                   atol=1e-6 * np.abs(k * X).max())
        s = sensor_from_dict(json.loads(ds.attrs["sensor"]))
        assert s == p.si().rig.sensor
        outer = [bodies.index(f"b{n + 1}") for n in range(3)]
        P = ds["motion.position"].values[:, outer]
        psi = np.arctan2(P[..., 1], P[..., 0]) + phi[:, None]
        e = sensor_axis(s)
        fx, fy = ds["mesh_br.fx"].values, ds["mesh_br.fy"].values            # on the ring, in R
        Fx = fx * np.cos(phi)[:, None] - fy * np.sin(phi)[:, None]           # in I
        Fy = fx * np.sin(phi)[:, None] + fy * np.cos(phi)[:, None]
        # the vibration: less the mean in each planet's own radial and tangential directions
        rad, tan = Fx * np.cos(psi) + Fy * np.sin(psi), -Fx * np.sin(psi) + Fy * np.cos(psi)
        rad, tan = rad - rad.mean(axis=0), tan - tan.mean(axis=0)
        F = (rad * np.cos(psi) - tan * np.sin(psi)) * e[0] + (rad * np.sin(psi) + tan * np.cos(psi)) * e[1]
        w = np.cos(np.pi * ((psi - s.angle + np.pi) % (2 * np.pi) - np.pi) / s.window_width) ** 2
        w[np.abs((psi - s.angle + np.pi) % (2 * np.pi) - np.pi) >= 0.5 * s.window_width] = 0.0
        expected = (w * F).sum(axis=1) / s.equivalent_mass
    t, paths = sensor_paths(path)
    assert np.abs(expected).max() > 1.0
    np.testing.assert_allclose(paths["mesh"], expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max())
    np.testing.assert_array_equal(paths["housing"], paths["mesh"] + paths["torque"] + paths["bearing"])
    with pytest.raises(ValueError, match="RunConfig"):
        sensor_paths(tmp_path / "plain" / "results.nc")


# ---------------------------------------------------------------------------------------------------------
# the planet-phasing rule
# ---------------------------------------------------------------------------------------------------------
def test_phasing_rule_hand_worked_n3_z82():
    """z_r = 82, N = 3: 82 + k divisible by 3 for k = −4, −1, 2, 5; the axis carries k = ±1 only."""
    got = {k: sideband_origin(k, 82, 3) for k in range(-6, 7)}
    assert [k for k, o in got.items() if o == "phasing"] == [-1]
    assert [k for k, o in got.items() if o == "transfer path"] == [-4, 2, 5]
    assert all(got[k] == "errors" for k in (-3, 0, 1, 3))          # f_m, f_m + f_c, f_m ± 3 f_c
    assert sideband_origin(1, 82, 3, harmonic=2) == "phasing"       # 164 + 1 = 165 = 3·55


def test_phasing_rule_hand_worked_in_phase_and_five_planets():
    """z_r = 80, N = 4 (in phase, 80/4 = 20): f_m and f_m ± 4 f_c through a window, nothing at the axis
    (in-phase planets excite no translation, Lin & Parker); z_r = 97, N = 5: 97 ≡ 2 (mod 5): k = −2, 3 at
    the first harmonic, and 2·97 + 1 = 195: the axis sees 2 f_m + f_c."""
    assert {k for k in range(-6, 7) if sideband_origin(k, 80, 4) != "errors"} == {-4, 0, 4}
    assert all(sideband_origin(k, 80, 4) != "phasing" for k in range(-6, 7))
    assert {k for k in range(-6, 7) if sideband_origin(k, 97, 5) != "errors"} == {-2, 3}
    assert sideband_origin(1, 97, 5, harmonic=2) == "phasing"
    assert sideband_origin(-1, 97, 5, harmonic=2) == "errors"


@pytest.mark.parametrize("z_r, n", [(82, 3), (80, 4), (97, 5), (71, 4)])
def test_phasing_rule_against_a_synthetic_train(z_r, n):
    """N identical planets, each contributing a function of its own angle: g(z_r ψ_n) (a mesh wave with
    harmonics) weighted by a Hann window (housing sensor), or turned with the carrier e^{iψ_n} (axis sensor:
    x component). Over one carrier revolution each carrier order m = z_r + k is a DFT bin; the lines the
    synthetic signal holds are exactly those the rule allows."""
    M = 4096
    psi_c = 2 * np.pi * np.arange(M) / M
    psi = psi_c[:, None] + 2 * np.pi * np.arange(n)[None, :] / n
    mesh = 1.0 + 0.3 * np.cos(z_r * psi + 0.4) + 0.1 * np.sin(2 * z_r * psi)
    housing = (hann_window(psi - 0.7, 2.0) * mesh).sum(axis=1)      # 2 rad: no order of it vanishes
    axis = (np.cos(psi + 0.2) * mesh).sum(axis=1)
    for signal, kinds in ((housing, ("phasing", "transfer path")), (axis, ("phasing",))):
        spec = np.abs(np.fft.rfft(signal)) / M
        for k in range(-6, 7):
            present = spec[z_r + k] > 1e-9 * n         # lines are O(0.01 n); cancelled ones O(1e-16)
            assert present == (sideband_origin(k, z_r, n) in kinds), (z_r, n, k, spec[z_r + k])


def test_the_spectrum_window_leaks_nothing_beyond_the_neighbouring_bins():
    """A line on a bin next to one 1e9 times weaker three bins away (f_m − f_c and f_m at three carrier
    revolutions): the periodic Hann window reads the weak one to 1e-6 (the symmetric one would bury it
    under ~1e-4 of the strong line's leakage)."""
    n, dt = 1800, 5e-5
    t = np.arange(n) * dt
    df = 1 / (n * dt)
    x = 20.0 * np.sin(2 * np.pi * 243 * df * t + 0.3) + 2e-8 * np.cos(2 * np.pi * 246 * df * t)
    f, a, _ = amplitude_spectrum(t, x)
    assert a[243] == pytest.approx(20.0, rel=1e-12)
    assert a[246] == pytest.approx(2e-8, rel=1e-6)


# the lines planet phasing cancels for z_r = 82, N = 3: f_m, f_m + f_c, f_m ± 3 f_c among them
CANCELLED = (-6, -5, -3, -2, 0, 1, 3, 4, 6)


# one mesh stiffness for the three meshes, where the planets' periodic motion is stable (perfect_linear_run)
ONE_STIFFNESS = {"mesh.c_gamma_alpha": "20 N/(mm*um)", "mesh.stiffness_ratio": 1.5}


@pytest.fixture(scope="module")
def perfect_linear_run(tmp_path_factory):
    """A perfect machine without gravity on linear bearings (2000 r/min, 200 kW): three carrier revolutions
    after 0.1 s, with the loads on the housing (~9 s). The planets start in different mesh phases, so the
    start's transient is not shared alike: it leaves 5e-4 of f_m − f_c in the cancelled lines after 0.03 s,
    5e-6 after 0.06 s (measured), and has decayed below the integrator's level by 0.1 s.

    The meshes have one stiffness, c_γα = 20 N/(mm·µm), and k_double/k_single = 1.5: there the planets' motion
    settles on the symmetric periodic motion the phasing rule is about, to the integrator's level (the worst
    cancelled line of the mesh path over its f_m − f_c: 3.0e-8 in the three revolutions from 0.12 s, 2.1e-8 from
    0.21 s). With the ISO 6336 stiffness of the reference machine (16.2 / 15.6 / 21.7 N/(mm·µm), ratio 1.75) it
    settles instead on a motion whose planets differ by a constant share: 1.46e-6 from 0.12 s and from 0.21 s
    alike (with one stiffness of 16 and 22 N/(mm·µm): 1.15e-4 and 9.3e-6, as constant; the start's transient,
    4.5e-4 in the first three revolutions from 0.03 s, has decayed by 0.12 s). Constant, it is neither the start
    decaying nor a parametric instability of the linearised train (Lin & Parker 2002), which would grow, and
    the nearest first-order instability regions (f_m = 2733 Hz against 2f_i or f_i ± f_j of `python -m
    scenarios.modal --dpgt --conditions 2`: 0.8 % / 2.7 % / 2.5 % / 0.5 % away for ISO / 16 / 20 / 22) do not
    order the levels; what sets it is open (docs/faults.md). One stiffness keeps this test's bound
    (1e-6) at the integrator's level; the reference machine's residual, 1.5e-6, would need 1e-5."""
    out = tmp_path_factory.mktemp("perfect_linear")
    p = with_overrides(reference_dpgt(2), ONE_STIFFNESS)
    cfg = RunConfig(settle=0.1, window=0.09, sample_rate=20000.0, progress=False, sensor=True,
                    options=SceneOptions(bearings="linear", gravity=False))
    s = run_case(p, cfg, out)
    return out / "results.nc", s["f_c_hz"], s["f_m_hz"]


@pytest.mark.slow
@pytest.mark.parametrize("where", [dict(), dict(angle=math.radians(30.0)),
                                   dict(angle=math.radians(-20.0), direction="tangential")],
                         ids=["rig sensor", "radial at 30 deg", "tangential at -20 deg"])
def test_a_perfect_machine_keeps_the_cancelled_lines_on_every_path(perfect_linear_run, where):
    """Gravity off, linear bearings: on every path and on their sum, the lines planet phasing cancels — f_m,
    f_m + f_c, f_m ± 3 f_c among them — stay at the simulation's numerical level. Mesh, bearing and the sum:
    below 1e-6 of the path's own f_m − f_c (measured ≤ 4e-8: the planets are time-shifted copies of each other
    to the integrator's tolerance). Torque: a net torque keeps only the mesh orders N divides (3 f_m: 0.6 m/s²
    at 30°), so around f_m the path holds nothing but the integrator's broadband noise (2.7e-6 m/s², 1e-7 of
    the sum's f_m − f_c): its cancelled lines stay within 3× its band median and below 1e-6 of the sum's
    f_m − f_c. At the rig's sensor (radial, on the vertical through the rocking centre) the torque path's
    lever is 0, and so is the path.

    The full model (gravity, roller bearings; `python -m scenarios.spectrum --perfect`, one tooth cycle, ≈ 200 s,
    tests/scenarios/test_spectrum_full_model.py): the sum's cancelled lines at 0.1–7.6× the floor between the
    carrier orders (f_m 2.6×, f_m + f_c 7.6×, f_m ± 3f_c 2.7×; ≤ 1.9 % of f_m − f_c in m/s²), the bearing path's
    f_m + f_c at 12.5× its own floor: the roller bearings leave the planets' load shares slightly apart, which a net
    force shows at f_m + f_c."""
    path, fc, fm = perfect_linear_run
    s = dataclasses.replace(reference_dpgt(2).si().rig.sensor, **where)
    t, paths = _whole_revolutions(*sensor_paths(path, s), fc)
    assert round((t[-1] - t[0] + t[1] - t[0]) * fc) == 3
    spectra = {name: amplitude_spectrum(t, x) for name, x in paths.items()}
    df = spectra["housing"][2]
    line = lambda name, freq: spectra[name][1][int(round(freq / df))]
    worst = {name: max(line(name, fm + k * fc) for k in CANCELLED) for name in paths}
    reference = line("housing", fm - fc)
    assert reference > 10.0
    for name in ("mesh", "bearing", "housing"):
        assert line(name, fm - fc) > 1.0, name
        assert worst[name] < 1e-6 * line(name, fm - fc), (name, worst[name], line(name, fm - fc))
    if rocking_lever(s) == 0.0:
        assert not paths["torque"].any()
        return
    f, a, _ = spectra["torque"]
    floor = np.median(a[(f > fm - 6.5 * fc) & (f < fm + 6.5 * fc)])
    assert line("torque", 3 * fm) > 1e4 * floor                 # the path is alive: its own line
    assert worst["torque"] < 3 * floor and worst["torque"] < 1e-6 * reference, (worst["torque"], floor)



@pytest.fixture(scope="module")
def identical_teeth_run(tmp_path_factory):
    """The run of :func:`perfect_linear_run` (its mesh stiffness too) with real but identical teeth: every tooth of
    every gear carries the same profile slope (6 µm), barrel form (4 µm) and a 2 µm thicker ccw flank — the
    tooth-pair law, with no difference between the planets."""
    from components.params import with_overrides
    out = tmp_path_factory.mktemp("identical_teeth")
    gears = ["sun", "ring", "a1", "a2", "a3", "b1", "b2", "b3"]
    p = with_overrides(reference_dpgt(2), {**ONE_STIFFNESS, "errors.tooth": [
        {"gear": g, "tooth": "all", "flank": "both", "slope": "6 um", "form": "4 um"} for g in gears] + [
        {"gear": g, "tooth": "all", "flank": "ccw", "pitch": "2 um"} for g in gears]})
    cfg = RunConfig(settle=0.1, window=0.09, sample_rate=20000.0, progress=False, sensor=True,
                    options=SceneOptions(bearings="linear", gravity=False))
    s = run_case(p, cfg, out)
    return out / "results.nc", s["f_c_hz"], s["f_m_hz"], s


@pytest.mark.slow
def test_identical_teeth_on_every_planet_keep_the_cancelled_lines(identical_teeth_run, perfect_linear_run):
    """Real teeth alike on every gear excite every planet's meshes alike, shifted by the planets' phases: the
    lines planet phasing cancels stay at the integrator's level on every path, while the teeth do change the
    meshes' excitation: the loaded transmission error's p2p drops from 4.8 to 1.6 µm on the ring mesh (the barrel
    form takes material off both ends of each flank, which eases the load handover like a profile relief;
    equal slopes on mating flanks cancel). That level is not the perfect machine's 4e-8: each tooth
    pair's contact begins where its gap closes, a kink in the force that every planet meets at another point of
    the shared step grid, so the planets differ by the local error the step control allows. Measured (worst
    cancelled line over the path's f_m − f_c): mesh 9.9e-4, bearing 1.2e-5, sum 6.9e-4 at the production
    tolerance (10 nm); 3.0e-4, 3.0e-5, 2.1e-4 at 1 nm (the same run with IntegratorSettings atol_pos = 1e-9). The
    rig's machine, whose planets' teeth differ, brings f_m to 1.8e-2 of f_m − f_c on the mesh path."""
    path, fc, fm, s = identical_teeth_run
    t, paths = _whole_revolutions(*sensor_paths(path, reference_dpgt(2).si().rig.sensor), fc)
    spectra = {name: amplitude_spectrum(t, x) for name, x in paths.items()}
    df = spectra["housing"][2]
    line = lambda name, freq: spectra[name][1][int(round(freq / df))]
    for name in ("mesh", "bearing", "housing"):
        worst = max(line(name, fm + k * fc) for k in CANCELLED)
        assert line(name, fm - fc) > 1.0, name
        assert worst < 3e-3 * line(name, fm - fc), (name, worst, line(name, fm - fc))
    import xarray as xr
    te = lambda p: float(np.ptp(xr.open_dataset(p)["mesh_br.transmission_error"].values))
    assert te(path) < 0.5 * te(perfect_linear_run[0])


@pytest.mark.slow
def test_the_reference_stiffness_leaves_a_constant_planet_to_planet_share(tmp_path):
    """The perfect machine of :func:`perfect_linear_run` on the reference machine's ISO 6336 mesh stiffness: the lines
    planet phasing cancels neither decay nor grow — the worst over the mesh path's f_m − f_c is the same in the
    three revolutions from 0.12 s and from 0.21 s (seen 1.46e-6 both), far above the integrator's level that one
    stiffness of 20 N/(mm·µm) reaches (2e-8) and far below anything a sensor could tell (docs/faults.md)."""
    p = reference_dpgt(2)
    cfg = RunConfig(settle=0.12, window=0.18, sample_rate=20000.0, progress=False, sensor=True,
                    options=SceneOptions(bearings="linear", gravity=False))
    s = run_case(p, cfg, tmp_path)
    fc, fm = s["f_c_hz"], s["f_m_hz"]
    t, paths = sensor_paths(tmp_path / "results.nc", p.si().rig.sensor)
    n3 = int(round(3 / fc / (t[1] - t[0])))
    worst = []
    for w in range(2):
        f, a, df = amplitude_spectrum(t[w * n3:(w + 1) * n3], paths["mesh"][w * n3:(w + 1) * n3])
        line = lambda freq: a[int(round(freq / df))]
        worst.append(max(line(fm + k * fc) for k in CANCELLED) / line(fm - fc))
    assert worst[1] == pytest.approx(worst[0], rel=0.05), worst
    assert 1e-7 < worst[0] < 1e-5, worst
