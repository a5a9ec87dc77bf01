"""The rig's housing accelerometer (MODEL.md §3.10, components.outputs) and the planet-phasing rule that
says which sidebands a sensor can see (components.geometry.sideband_origin)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from components.geometry import sideband_origin
from components.outputs import HousingSensor, hann_window, sensor_acceleration
from components.params import SensorParams, with_overrides
from components.presets import reference_dpgt, rig_accelerometer
from components.scene import SceneOptions
from scenarios.runner import RunConfig, run_case

from dpgt_runs import build

widths = st.floats(0.05, 2 * math.pi)
angles = st.floats(-20.0, 20.0)


# ---------------------------------------------------------------------------------------------------------
# the window
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


def test_sensor_acceleration_by_hand():
    """Planets at the sensor (w = 1), a quarter width away (w = 1/2) and opposite (w = 0)."""
    s = rig_accelerometer().si()
    psi = np.array([s.angle, s.angle + 0.25 * s.window_width, s.angle + math.pi])
    F = np.array([600.0, 300.0, 5000.0])
    a = sensor_acceleration(psi, F, 2.0, s)
    assert float(a) == pytest.approx((600.0 + 0.5 * 300.0) / s.equivalent_mass + 2.0)
    # broadcasting over samples
    a2 = sensor_acceleration(np.stack([psi, psi]), np.stack([F, 2 * F]), np.array([0.0, 1.0]), s)
    assert a2 == pytest.approx([750.0 / s.equivalent_mass, 1500.0 / s.equivalent_mass + 1.0])


def test_sensor_parameters_are_checked_and_sourced():
    p = rig_accelerometer()
    for name in ("angle", "window_width", "equivalent_mass", "direction"):
        assert p.source(name).tag == "assumed"
    assert "McFadden" in p.source("window_width").note
    with pytest.raises(Exception, match=r"sensor.window_width.*360 deg"):
        SensorParams(angle="0 deg", window_width="400 deg", equivalent_mass="1 kg", direction="radial")
    with pytest.raises(Exception, match="sensor.direction"):
        SensorParams(angle="0 deg", window_width="90 deg", equivalent_mass="1 kg", direction="axial")
    assert with_overrides(reference_dpgt(2), {"rig.sensor.angle": "30 deg"}).si().rig.sensor.angle == \
        pytest.approx(math.radians(30))


# ---------------------------------------------------------------------------------------------------------
# the sensor on a scene
# ---------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("direction", ["radial", "tangential"])
def test_sensor_on_the_scene_reads_the_planet_at_it_and_the_housing(direction):
    """Sensor placed on planet b1 (narrow window: b1 alone counts), in a frame turned by φ: it reads b1's
    ring-mesh force along its axis over m_eq plus the carrier's acceleration along it."""
    import mbd

    p = reference_dpgt(2)
    scene = build(p, bearings="linear", mesh_stiffness="constant")
    model = scene.model
    b1 = model.body(scene.handles["pairs"][0].outer).index
    c = model.body("carrier").index
    q = np.array(scene.q0, float)
    q[np.flatnonzero(model.free == 3 * b1 + 2)] += 0.01       # turn b1 past its backlash: its ring mesh deflects
    qf, vf = model.full(0.0, q, scene.v0)
    X, V = qf.reshape(-1, 3), vf.reshape(-1, 3)
    V[c, :2] = 0.0                                      # carrier at rest in R: a_I = Rot(φ) a_R
    A = np.zeros_like(X)
    A[c, :2] = (3.0, -4.0)
    t = 1e-3
    phi = model.frame.at(t).phi
    psi_b1 = math.atan2(X[b1, 1], X[b1, 0])
    s = with_overrides(p, {"rig.sensor.angle": f"{psi_b1 + phi} rad", "rig.sensor.window_width": "10 deg",
                           "rig.sensor.direction": direction}).si().rig.sensor
    outs = mbd.System(model).outputs(t, q, scene.v0, {})
    e = np.array([math.cos(psi_b1), math.sin(psi_b1)])          # the sensor's axis in R
    if direction == "tangential":
        e = np.array([-e[1], e[0]])
    o = outs["mesh_br"]
    F = o["fx"][0] * e[0] + o["fy"][0] * e[1]
    assert abs(F) > 100.0
    expected = F / s.equivalent_mass + A[c, :2] @ e
    assert HousingSensor(scene, s)(t, X, V, A, outs)[0] == pytest.approx(expected, rel=1e-9, abs=1e-9)


@pytest.mark.slow
def test_sensor_is_recorded_only_when_asked(tmp_path):
    """RunConfig(sensor=True) records sensor.acceleration [m/s^2]; it equals the formula applied to the
    recorded planet positions, ring-mesh forces and carrier acceleration. Without it nothing is added."""
    import xarray as xr

    p = reference_dpgt(2)
    cfg = RunConfig(settle=1e-3, window=1e-3, sample_rate=20000.0, progress=False,
                    options=SceneOptions(bearings="linear"))
    run_case(p, cfg, tmp_path / "plain")
    run_case(p, RunConfig(**{**cfg.__dict__, "sensor": True}), tmp_path / "sensor")
    with xr.open_dataset(tmp_path / "plain" / "results.nc", engine="h5netcdf") as ds:
        assert "sensor.acceleration" not in ds
    with xr.open_dataset(tmp_path / "sensor" / "results.nc", engine="h5netcdf") as ds:
        a = ds["sensor.acceleration"]
        assert a.attrs["units"] == "m/s^2" and "MODEL.md 3.10" in a.attrs["long_name"]
        bodies = list(ds["motion.body"].values)
        ic = list(ds["fixed.body"].values).index("carrier")
        phi = ds["fixed.angle"].values[:, ic] - ds["motion.angle"].values[:, bodies.index("carrier")]
        outer = [bodies.index(f"b{n + 1}") for n in range(3)]
        P = ds["motion.position"].values[:, outer]                     # (time, N, 2) in R
        psi = np.arctan2(P[..., 1], P[..., 0]) + phi[:, None]
        s = p.si().rig.sensor
        axis = s.angle + (0.0 if s.direction == "radial" else 0.5 * math.pi)
        F = (ds["mesh_br.fx"].values * np.cos(axis - phi)[:, None] + ds["mesh_br.fy"].values * np.sin(axis - phi)[:, None])
        a_c = ds["fixed.acceleration"].values[:, ic]
        housing = a_c[:, 0] * math.cos(axis) + a_c[:, 1] * math.sin(axis)
        expected = sensor_acceleration(psi, F, housing, s)
        assert np.abs(expected).max() > 1.0
        np.testing.assert_allclose(a.values[:, 0], expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max())


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
