"""components.outputs: the statistics are measured on every accepted step (not on recorded samples),
survive a checkpoint/resume unchanged, and the radial/tangential views do not depend on where a planet
sits or on the frame the model is integrated in."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

import mbd
from components.outputs import WindowStatistics, default_window
from components.presets import reference_dpgt
from scenarios.core.runner import RunConfig, run_case

from tests.support import dpgt_runs
from tests.support.dpgt_runs import CONTROLLER, build

RADIAL_KEYS = ("load_radial", "load_tangential", "load_magnitude", "cage_acc_radial", "cage_acc_tangential",
               "cage_acc_magnitude", "cage_acc_rel_radial", "cage_acc_rel_tangential", "cage_acc_rel_magnitude",
               "roller_inner_load", "pocket_force", "guide_force", "sun_inner_drive_force", "outer_ring_drive_force")


def _numbers(d, prefix=""):
    """{path: float} of every numeric leaf of a summary."""
    out = {}
    for k, v in d.items():
        if isinstance(v, dict):
            out.update(_numbers(v, f"{prefix}{k}."))
        elif isinstance(v, (int, float)) and not isinstance(v, bool):
            out[prefix + k] = float(v)
    return out


@pytest.mark.slow
def test_statistics_do_not_depend_on_the_recording_rate(tmp_path):
    """The same run recorded at 25 kHz and at 4 kHz gives the same summary statistics, to the bit: they come from the
    integrator's steps, which the recorder does not touch (only the run times and the sample count differ)."""
    p = reference_dpgt(3, "forward")
    s = {rate: run_case(p, RunConfig(settle=1.5e-3, window=1.5e-3, sample_rate=rate, progress=False),
                        tmp_path / f"r{int(rate)}") for rate in (25000.0, 4000.0)}
    a, b = _numbers(s[25000.0]), _numbers(s[4000.0])
    skip = {"wall_s", "compile_s", "samples", "timing"}      # run times and memory: not the run's numbers
    keys = [k for k in a if k.split(".")[-1] not in skip and not k.startswith("timing")]
    assert len(keys) > 60 and s[25000.0]["samples"] > 5 * s[4000.0]["samples"]
    assert s[4000.0]["engine"] == "compiled" and s[4000.0]["engine_note"] is None      # which engine ran
    assert set(a) == set(b)
    assert {k: b[k] for k in keys if b[k] != a[k] and not (np.isnan(a[k]) and np.isnan(b[k]))} == {}
    # and the whole file (lists, words, warnings), less what names the sample rate or times the run
    rest = lambda d: json.dumps({k: v for k, v in d.items() if k not in skip | {
        "fingerprint", "parameters_fingerprint", "run_description"}}, sort_keys=True)
    assert rest(s[4000.0]) == rest(s[25000.0])


class _Interrupt(mbd.Observer):
    def __init__(self, t):
        self.t = t

    def step(self, s0, s1):
        if self.t is not None and s1.t > self.t:
            self.t = None
            raise KeyboardInterrupt


@pytest.mark.slow
def test_statistics_resume_from_a_checkpoint_unchanged(tmp_path):
    bs = build(reference_dpgt(3, "reverse"))
    t0, t1 = 1.0e-3, 2.5e-3
    runs = []
    for interrupt in (None, 1.8e-3):
        ck = mbd.Checkpoint(tmp_path / f"ck{interrupt}.npz", every=40)
        stats = WindowStatistics(bs, t0, t1)
        kw = dict(stepper=mbd.HHT(alpha=-0.3), controller=CONTROLLER, progress=False, checkpoint=ck)
        if interrupt is not None:
            with pytest.raises(KeyboardInterrupt):
                mbd.simulate(bs.model, bs.q0, bs.v0, stats.t_end, observers=[stats, _Interrupt(interrupt)], **kw)
            stats = WindowStatistics(bs, t0, t1)       # a new process would start from nothing
        res = mbd.simulate(bs.model, bs.q0, bs.v0, stats.t_end, observers=[stats], resume=True, **kw)
        assert (res.resumed_from is not None) == (interrupt is not None)
        runs.append(stats.summary())
    assert json.dumps(runs[0], sort_keys=True) == json.dumps(runs[1], sort_keys=True)


@pytest.fixture(scope="module")
def settled():
    """A moving, loaded state of the full model (gravity off), 1 ms after the kinematic start."""
    bs = build(reference_dpgt(3, "forward"), gravity=False)
    res = mbd.simulate(bs.model, bs.q0, bs.v0, 1e-3, stepper=mbd.HHT(alpha=-0.3), controller=CONTROLLER,
                       progress=False)
    stats = WindowStatistics(bs, 0.0, 1e-3)
    stats.bind(bs.model, mbd.System(bs.model), res.state)
    return bs, res.state, stats


def _rotated(model, s, beta):
    """The state with the whole machine turned by beta about the axis (positions, velocities,
    accelerations rotated; angles + beta)."""
    c, sn = math.cos(beta), math.sin(beta)
    out = []
    for x, add in ((s.q, beta), (s.v, 0.0), (s.a, 0.0)):
        full = np.zeros(3 * model.n_bodies)
        full[model.free] = x
        X = full.reshape(-1, 3).copy()
        X[:, 0], X[:, 1] = c * X[:, 0] - sn * X[:, 1], sn * X[:, 0] + c * X[:, 1]
        X[:, 2] += add
        out.append(X.ravel()[model.free])
    return mbd.State(s.t, out[0], out[1], out[2], s.f, s.z)


def test_radial_and_tangential_views_do_not_depend_on_where_the_planet_sits(settled):
    """Turn the whole machine by one planet pitch: every radial/tangential quantity and magnitude is the
    same to round-off, while x/y components (which depend on the planet's position) change."""
    bs, s, stats = settled
    a = stats.snapshot(s)
    b = stats.snapshot(_rotated(bs.model, s, 2 * math.pi / 3))
    for k in RADIAL_KEYS:
        np.testing.assert_allclose(b[k], a[k], rtol=1e-7, atol=1e-7 * np.abs(a[k]).max(), err_msg=k)
    assert np.abs(b["load_x"] - a["load_x"]).max() > 0.1 * np.abs(a["load_x"]).max()
    assert np.abs(b["cage_acc_x"] - a["cage_acc_x"]).max() > 0.1 * np.abs(a["cage_acc_x"]).max()


def test_statistics_are_the_same_in_the_fixed_and_the_rotating_frame(settled):
    """The same physical state seen from the fixed frame (a model built with frame='fixed') gives the
    same derived quantities: accelerations are taken in the carrier frame whatever frame integrates."""
    bs, s, stats = settled
    fixed = build(reference_dpgt(3, "forward"), gravity=False, frame="fixed")
    m, mf = bs.model, fixed.model
    qf, vf = m.full(s.t, s.q, s.v)
    af = np.zeros_like(qf)
    af[m.free] = s.a
    Q, V, A = mbd.to_fixed(qf.reshape(-1, 3), vf.reshape(-1, 3), m.frame.at(s.t), af.reshape(-1, 3))
    sf = mbd.State(s.t, Q.ravel()[mf.free], V.ravel()[mf.free], A.ravel()[mf.free], s.f, s.z)
    other = WindowStatistics(fixed, 0.0, 1e-3)
    other.bind(mf, mbd.System(mf), sf)
    a, b = stats.snapshot(s), other.snapshot(sf)
    for k in (*RADIAL_KEYS, "load_x", "load_y", "cage_acc_x", "cage_acc_y", "cage_speed_rel"):
        np.testing.assert_allclose(b[k], a[k], rtol=1e-7, atol=1e-7 * np.abs(a[k]).max(), err_msg=k)


def test_default_window_is_whole_revolutions_of_the_slowest_cage():
    assert default_window(0.02, [7e-3, 5e-3]) == pytest.approx(0.021)
    assert default_window(0.021, [7e-3]) == pytest.approx(0.021)       # already whole: unchanged
    assert default_window(0.02, [math.inf]) == 0.02                      # no turning cage: the base


def test_quasi_static_transmission_error_and_dynamic_factor():
    """One planet pair (every mesh then carries F = T_s/r_b,sun exactly by statics), linear bearings, no
    gravity, the carrier at 10 r/min (f_m = 13.7 Hz, far below every mode): the loaded transmission error of
    each mesh steps between the single- and double-contact compressions, p2p = F (1/k_single − 1/k_double)
    (measured within 0.2 %), and the drive force's largest value over its mean, the mean cycle peak over the mean
    (K_v) and its 99th percentile over the mean are all 1 (measured 1.0003–1.0007); the window, shorter than a
    carrier revolution, counts whole mesh cycles (2)."""
    ov = {"gears.planets": "1", "operating.carrier_speed": "10 rpm", "operating.output_power": "0.5 kW",
          "rig.load_ramp_mesh_periods": "0.2", "gravity": "0 m/s^2"}
    p = dpgt_runs.with_overrides(dpgt_runs.reference_dpgt(3), {**dpgt_runs.FAST_DRIVE, **ov})
    f_m = p.si().operating.mesh_frequency
    _, st, _, _ = dpgt_runs.run(3, "forward", ov, window=2.0 / f_m, settle=0.05, bearings="linear")
    s = st.summary()["meshes"]
    for key, M in p.si().layout.meshes.items():
        d = s[key]
        F = d["drive_force_mean_N"]
        assert F == pytest.approx(abs(p.si().operating.sun_torque) / p.si().layout.meshes["sun_inner"].base_radius1,
                                  rel=1e-3)
        assert d["te_peak_to_peak_m"] == pytest.approx(F * (1 / M.k_single - 1 / M.k_double), rel=0.005), key
        for name in ("drive_flank_peak_over_mean", "dynamic_factor", "dynamic_factor_p99"):
            assert 1.0 <= d[name] < 1.002, (key, name)
        assert d["dynamic_factor_carrier_revolutions"] == 0 and d["dynamic_factor_mesh_cycles"] == 2
        assert d["te_peak_to_peak_per_pair_m"] == [d["te_peak_to_peak_m"]]
