"""Recorder (sampling, netCDF layout, chunking, atomic writes) and checkpoint/resume."""
from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr

import mbd
from mbd.elements import BodySpring, GroundSupport, SpeedDrive, TorqueSource


def scene(frame=None, torque=0.05):
    """A fixed housing, a rotor held by a PI speed drive (internal state) and a second body on a spring."""
    b = mbd.ModelBuilder(frame=frame, gravity=(0.0, -9.81))
    h = b.add_body("housing", 10.0, 1.0, pose=(0.0, 0.2, 0.0), fixed=True)
    r = b.add_body("rotor", 1.0, 2e-3)
    a = b.add_body("arm", 0.2, 1e-4, pose=(0.05, 0.0, 0.0))
    b.add(GroundSupport("bearing", r, kx=5e5, cx=20.0))
    b.add(SpeedDrive("motor", r, omega_ref=30.0, k=50.0, c=0.5, k_i=500.0))
    b.add(BodySpring("link", [r, h], [a, a], k=[2e4, 1e3], c=[1.0, 0.1], marker_a=[[0.05, 0.0], [0.0, -0.2]]))
    b.add(TorqueSource("load", a, torque=torque))
    return b.build()


def q0v0(model):
    fs = model.frame.at(0.0)
    P = model.pose0[~model.fixed]
    V = np.array([[0.0, 0.0, 30.0], [0.0, 1.5, 30.0]])
    q, v = mbd.to_reference(P, V, fs)
    return q.ravel(), v.ravel()


PROBES = [mbd.BodyMotion(), mbd.BodyMotion(name="fixedmotion", frame="fixed"),
          mbd.ElementOutput("link", meta={"fx": ("N", "link force x"), "fy": ("N", "link force y"),
                                          "deflection": ("m", "link deflection")},
                            instances={"instance": ("link name", ["rotor-arm", "housing-arm"]),
                                       "stiff": ("1 for the stiff link", [1, 0])}),
          mbd.ElementOutput("bearing", keys=["fx"])]


def pose(ds, name="motion"):
    """(n_t, n_bodies, 3) poses (x, y, θ) reassembled from position [m] and angle [rad]."""
    return np.concatenate([ds[f"{name}.position"].values, ds[f"{name}.angle"].values[..., None]], axis=-1)


def run(model, path, t_end=0.05, dt=2e-3, h=5e-4, chunk=4, **kw):
    rec = mbd.Recorder(path, dt=dt, probes=PROBES, chunk=chunk, attrs={"scene": "test"})
    q0, v0 = q0v0(model)
    kw.setdefault("controller", mbd.FixedStep(h))
    return mbd.simulate(model, q0, v0, t_end, recorder=rec, progress=False, **kw)


def test_results_file_layout_readable_by_xarray(tmp_path):
    model = scene(mbd.Frame.rotating(25.0))
    res = run(model, tmp_path / "out.nc")
    assert res.results_path == tmp_path / "out.nc"
    with xr.open_dataset(res.results_path, engine="h5netcdf") as ds:
        assert ds["motion.position"].dims == ("time", "motion.body", "axis")
        assert ds["motion.angle"].dims == ("time", "motion.body")
        assert list(ds["axis"].values) == ["x", "y"]
        assert list(ds["motion.body"].values) == ["housing", "rotor", "arm"]
        assert ds["fixedmotion.acceleration"].shape == (ds.sizes["time"], 3, 2)
        assert ds["link.fx"].dims == ("time", "link.instance") and ds.sizes["link.instance"] == 2
        kinds = ("position", "angle", "velocity", "angular_velocity", "acceleration", "angular_acceleration")
        assert set(ds.data_vars) == {*(f"{p}.{k}" for p in ("motion", "fixedmotion") for k in kinds),
                                     "link.fx", "link.fy", "link.deflection", "bearing.fx"}
        units = {k: ds[k].attrs.get("units") for k in ds.variables}
        assert units["motion.position"] == "m" and units["motion.angle"] == "rad"
        assert units["fixedmotion.angular_acceleration"] == "rad/s^2" and units["link.deflection"] == "m"
        assert "fixed frame" in ds["fixedmotion.velocity"].attrs["long_name"]
        # instance coordinates: names given by the probe, extra ones attached; an index without them
        assert list(ds["link.fx"]["link.instance"].values) == ["rotor-arm", "housing-arm"]
        assert list(ds["link.fx"]["link.stiff"].values) == [1, 0]
        assert list(ds["bearing.instance"].values) == [0] and "units" not in ds["bearing.fx"].attrs
        assert ds["bearing.fx"].attrs["long_name"]
        assert ds.attrs["scene"] == "test"
        run_attrs = json.loads(ds.attrs["run"])
        assert run_attrs["steps"] == res.steps and run_attrs["n_accepted"] == res.steps
        assert ds["time"].attrs["units"] == "s" and ds["time"].dtype == float
        # the housing is fixed in I: in I it stays put with zero velocity and acceleration
        np.testing.assert_allclose(pose(ds, "fixedmotion")[:, 0], [[0.0, 0.2, 0.0]] * ds.sizes["time"], atol=1e-14)
        for k in ("velocity", "angular_velocity"):
            np.testing.assert_allclose(ds[f"fixedmotion.{k}"].values[:, 0], 0.0, atol=1e-12)
        for k in ("acceleration", "angular_acceleration"):
            np.testing.assert_allclose(ds[f"fixedmotion.{k}"].values[:, 0], 0.0, atol=1e-10)
    assert not (tmp_path / "out.nc.parts").exists()        # chunks removed after the final file


@pytest.mark.parametrize("t_start, dt, h", [(0.0, 2e-3, 5e-4), (0.0013, 1.7e-3, 7e-4), (0.0, 5e-4, 2e-3)],
                         ids=["dt=4h", "dt-not-multiple", "dt<h"])
def test_sampling_times_and_interpolation(tmp_path, t_start, dt, h):
    """Samples at t_start + k·dt, independent of the step; values interpolated between steps."""
    m, k = 1.0, 4e4
    b = mbd.ModelBuilder()
    a = b.add_body("a", m, 1.0)
    b.add(GroundSupport("s", a, kx=k, k_theta=k))
    model = b.build()
    t_end = 0.02
    rec = mbd.Recorder(tmp_path / "o.nc", dt=dt, t_start=t_start, probes=[mbd.BodyMotion()], chunk=5)
    res = mbd.simulate(model, np.array([1e-3, 0, 0]), np.zeros(3), t_end, controller=mbd.FixedStep(h),
                       stepper=mbd.HHT(alpha=0.0, newton_tol=1e-8), recorder=rec, progress=False)
    with xr.open_dataset(res.results_path, engine="h5netcdf") as ds:
        t = ds["time"].values
        x = ds["motion.position"].values[:, 0, 0]
        vx = ds["motion.velocity"].values[:, 0, 0]
    kmax = int(np.floor((t_end - t_start) / dt + 1e-9))
    np.testing.assert_array_equal(t, t_start + np.arange(kmax + 1) * dt)
    w = np.sqrt(k / m)
    # trapezoidal phase error ~ (wh)²·wt/12 plus cubic-Hermite interpolation error
    err_bound = 1e-3 * ((w * h) ** 2 * w * t_end / 12 + (w * h) ** 3 / 10) * 3
    np.testing.assert_allclose(x, 1e-3 * np.cos(w * t), atol=err_bound)
    np.testing.assert_allclose(vx, -1e-3 * w * np.sin(w * t), atol=err_bound * w * 2)


def test_samples_on_step_boundaries_equal_the_states(tmp_path):
    model = scene()
    res = run(model, tmp_path / "o.nc", t_end=0.01, dt=1e-3, h=5e-4)
    with xr.open_dataset(res.results_path, engine="h5netcdf") as ds:
        q_last = pose(ds)[-1]
        fx_last = ds["link.fx"].values[-1]
    qf, vf = model.full(res.state.t, res.state.q, res.state.v)
    np.testing.assert_array_equal(q_last, qf.reshape(-1, 3))
    sysm = mbd.System(model)
    np.testing.assert_allclose(fx_last, sysm.outputs(res.state.t, res.state.q, res.state.v, res.state.z)["link"]["fx"],
                               rtol=1e-12)


def test_chunks_stream_to_disk_during_the_run(tmp_path):
    """Memory stays bounded: at most ``chunk`` samples are held; full chunks appear on disk mid-run."""
    path = tmp_path / "o.nc"
    seen = []
    holder = {}

    def torque(t):
        rec = holder.get("rec")
        if rec is not None and t > 0.03:
            seen.append((len(list(rec.parts.glob("chunk_*.npz"))), len(rec._times)))
        return 0.05

    model = scene(torque=torque)
    rec = mbd.Recorder(path, dt=1e-3, probes=PROBES, chunk=3)
    holder["rec"] = rec
    q0, v0 = q0v0(model)
    res = mbd.simulate(model, q0, v0, 0.05, controller=mbd.FixedStep(5e-4), recorder=rec, progress=False)
    assert seen and max(n for n, _ in seen) >= 9          # ≥ 30 samples written as chunks of 3
    assert max(b for _, b in seen) <= 3
    with xr.open_dataset(res.results_path, engine="h5netcdf") as ds:
        assert ds.sizes["time"] == 51
        np.testing.assert_allclose(np.diff(ds["time"].values), 1e-3, rtol=1e-9)


def test_results_file_is_atomic(tmp_path):
    """A run that fails leaves no partial results file and does not touch an existing one."""
    path = tmp_path / "o.nc"
    run(scene(), path, t_end=0.01)
    before = path.read_bytes()

    def torque(t):
        if t > 0.02:
            raise RuntimeError("motor controller fault")
        return 0.05

    with pytest.raises(RuntimeError, match="motor controller fault"):
        run(scene(torque=torque), path, t_end=0.05)
    assert path.read_bytes() == before                      # the old file, complete and unchanged
    assert not list(tmp_path.glob(".o.nc.tmp*"))
    path.unlink()
    with pytest.raises(RuntimeError):
        run(scene(torque=torque), path, t_end=0.05)
    assert not path.exists()


class _Interrupt(mbd.Observer):
    """Ctrl-C once the run passes t (an observer sees every accepted step, on either engine)."""

    def __init__(self, t):
        self.t, self.armed = t, True

    def step(self, s0, s1):
        if self.armed and s1.t > self.t:
            self.armed = False
            raise KeyboardInterrupt


@pytest.mark.parametrize("engine", ["compiled", "numpy"])
@pytest.mark.parametrize("controller", [mbd.FixedStep(4e-4), mbd.Adaptive(h0=1e-4, h_min=1e-9)],
                         ids=["fixed", "adaptive"])
def test_checkpoint_resume_gives_identical_results(tmp_path, controller, engine):
    stepper = mbd.HHT(alpha=-0.1, tol=mbd.Tolerance(rtol=1e-5, atol_pos=1e-9, atol_rot=1e-8))
    t_end = 0.06
    kw = dict(t_end=t_end, controller=controller, stepper=stepper, engine=engine)
    # reference: uninterrupted, with the same checkpoint cadence (a checkpoint drops the cached LU)
    ref = run(scene(), tmp_path / "ref.nc", checkpoint=mbd.Checkpoint(tmp_path / "ref.ckpt", every=7), **kw)
    assert ref.engine == engine
    model = scene()
    ck = mbd.Checkpoint(tmp_path / "run.ckpt", every=7)
    with pytest.raises(KeyboardInterrupt):
        run(model, tmp_path / "run.nc", checkpoint=ck, observers=[_Interrupt(0.037)], **kw)
    assert ck.path.exists() and not (tmp_path / "run.nc").exists()
    res = run(model, tmp_path / "run.nc", checkpoint=ck, resume=True, observers=[_Interrupt(np.inf)], **kw)
    assert res.resumed_from is not None and 0.0 < res.resumed_from <= 0.037
    assert not ck.path.exists()                              # removed after a complete run
    np.testing.assert_array_equal(res.state.q, ref.state.q)
    np.testing.assert_array_equal(res.state.v, ref.state.v)
    np.testing.assert_array_equal(res.state.z["motor"], ref.state.z["motor"])
    assert res.steps == ref.steps and res.counters == ref.counters
    with xr.open_dataset(ref.results_path, engine="h5netcdf") as a, \
            xr.open_dataset(res.results_path, engine="h5netcdf") as b:
        assert set(a.data_vars) == set(b.data_vars)
        np.testing.assert_array_equal(a["time"].values, b["time"].values)
        for name in a.data_vars:
            assert np.array_equal(a[name].values, b[name].values), name


def test_resume_without_checkpoint_starts_fresh(tmp_path):
    ck = mbd.Checkpoint(tmp_path / "none.ckpt", every=3)
    a = run(scene(), tmp_path / "a.nc", t_end=0.01, checkpoint=ck)
    b = run(scene(), tmp_path / "b.nc", t_end=0.01, checkpoint=ck, resume=True)
    assert b.resumed_from is None
    np.testing.assert_array_equal(a.state.q, b.state.q)


def test_recorder_rejects_bad_probes(tmp_path):
    with pytest.raises(mbd.ModelError, match="dt"):
        mbd.Recorder(tmp_path / "x.nc", dt=0.0, probes=[])
    with pytest.raises(mbd.ModelError, match="frame"):
        mbd.BodyMotion(frame="inertial")
    with pytest.raises(mbd.ModelError, match="quantities"):
        mbd.BodyMotion(quantities=("q", "jerk"))
    model = scene()
    rec = mbd.Recorder(tmp_path / "x.nc", dt=1e-3, probes=[mbd.ElementOutput("link", keys=["fz"])])
    with pytest.raises(mbd.ModelError, match="fz"):
        mbd.simulate(model, *q0v0(model), 0.001, controller=mbd.FixedStep(1e-3), recorder=rec, progress=False)
    rec = mbd.Recorder(tmp_path / "x.nc", dt=1e-3, probes=[mbd.ElementOutput("link", instances={"instance": ("x", ["a"])})])
    with pytest.raises(mbd.ModelError, match="1 values for dimension 'link.instance' of size 2"):
        mbd.simulate(model, *q0v0(model), 0.001, controller=mbd.FixedStep(1e-3), recorder=rec, progress=False)
    rec = mbd.Recorder(tmp_path / "x.nc", dt=1e-3, probes=[mbd.ElementOutput("nope")])
    with pytest.raises(mbd.ModelError, match="nope"):
        mbd.simulate(model, *q0v0(model), 0.001, controller=mbd.FixedStep(1e-3), recorder=rec, progress=False)


class _Seen(mbd.Observer):
    def __init__(self):
        self.steps = []

    def bind(self, model, system, state):
        self.t_start = state.t

    def step(self, s0, s1):
        self.steps.append((s0.t, s1.t))


def test_observers_see_every_accepted_step_and_time_means_are_trapezoids(tmp_path):
    """Every accepted step reaches every observer once, in order, whatever the recorder, and no rejected
    one (the first step, h0 = 10 ms, is too large: 4 rejections); TimeMean of a function linear in time is
    exact (the trapezoid rule), here over the steps that end in [t0, t1]."""
    seen = _Seen()
    mean = mbd.TimeMean(lambda system, s: np.array([s.t, 2.0]), 0.01, 0.03)
    res = run(scene(), tmp_path / "r.nc", t_end=0.04, controller=mbd.Adaptive(h0=1e-2, h_min=1e-9),
              observers=[seen, mean])
    assert len(seen.steps) == res.steps == res.counters["accepted"] and res.counters["rejected"] > 0
    ends = np.array(seen.steps)
    assert ends[0, 0] == seen.t_start and ends[-1, 1] == pytest.approx(0.04)
    np.testing.assert_array_equal(ends[1:, 0], ends[:-1, 1])          # contiguous: no step skipped
    covered = ends[(ends[:, 1] > 0.01) & (ends[:, 0] < 0.03)]
    assert mean.mean[0] == pytest.approx(0.5 * (covered[0, 0] + covered[-1, 1]), rel=1e-12)
    assert mean.mean[1] == pytest.approx(2.0, rel=1e-12)


class _Steps(mbd.Observer):
    """The accepted steps of a compiled run, block by block (to replay them into a second recorder)."""

    def __init__(self):
        self.steps = []

    def step(self, s0, s1):
        self.steps.append((s0, s1))


def _link_speed(outputs):
    """An elementwise quantity derived from the link's outputs (a caller's film or error, say)."""
    return {"work_rate": np.asarray(outputs["fx"], float) * np.exp(-np.asarray(outputs["deflection"], float) ** 2)}


def _arm_spin(t, X, V, A, outputs):
    """An elementwise quantity of the bodies and one family's outputs, one sample or a block's (..., nb, 3)."""
    return np.cos(X[..., 1, 2]) * V[..., 2, 2] + np.asarray(outputs["bearing"]["fx"], float)[..., 0] * t


@pytest.mark.parametrize("frame", [None, mbd.Frame.rotating(25.0)], ids=["inertial", "rotating"])
def test_block_samples_equal_the_samples_taken_one_by_one(tmp_path, frame):
    """The compiled path records a block's samples at once (record_block: the motion as arrays over the samples, a
    ``batched`` derived quantity over all of them); the numpy path takes them one by one (record). Replaying the same
    accepted steps both ways gives the same file to the last bit, a derived quantity marked batched equal to the same
    one evaluated sample by sample (a rotating frame: its fixed bodies' frame accelerations, the fixed-frame motion)."""
    probes = [*PROBES,
              mbd.ElementOutput("link", keys=["work_rate"], derived=_link_speed, batched=True),
              mbd.DerivedOutput("spin_rows", _arm_spin, "1", "arm spin, a block at once", batched=True),
              mbd.DerivedOutput("spin_ones", _arm_spin, "1", "arm spin, sample by sample")]
    model = scene(frame)
    q0, v0 = q0v0(model)
    seen = _Steps()
    blocks = mbd.Recorder(tmp_path / "blocks.nc", dt=7e-4, probes=probes, chunk=5)
    res = mbd.simulate(model, q0, v0, 0.03, controller=mbd.Adaptive(h0=1e-4, h_min=1e-9), recorder=blocks,
                       observers=[seen], engine="compiled", progress=False)
    assert res.engine == "compiled" and len(seen.steps) == res.steps
    one = mbd.Recorder(tmp_path / "ones.nc", dt=7e-4, probes=probes, chunk=3)
    first = seen.steps[0][0]
    one.bind(model, mbd.System(model), first)
    one.reset()
    one.record(first, None, first=True)
    for s0, s1 in seen.steps:
        one.record(s0, s1)
    one.finalize()
    with xr.open_dataset(tmp_path / "blocks.nc", engine="h5netcdf") as a, \
            xr.open_dataset(tmp_path / "ones.nc", engine="h5netcdf") as b:
        assert a.sizes["time"] == b.sizes["time"] == int(np.floor(0.03 / 7e-4 + 1e-9)) + 1
        assert set(a.variables) == set(b.variables)
        for name in a.variables:
            assert np.array_equal(a[name].values, b[name].values), name
        np.testing.assert_array_equal(a["spin_rows"].values, a["spin_ones"].values)
        assert np.ptp(a["link.work_rate"].values) > 0 and np.ptp(a["spin_rows"].values) > 0     # not constants


def test_results_file_the_same_whatever_the_chunks_joined_per_write(tmp_path, monkeypatch):
    """finalize joins the chunks into groups of up to WRITE_BYTES per write: one group or one chunk per write, the
    file holds the same samples (every chunk in its place, none twice)."""
    import mbd.recorder as recorder

    whole = run(scene(), tmp_path / "whole.nc", t_end=0.03, chunk=4)
    monkeypatch.setattr(recorder, "WRITE_BYTES", 1)        # every chunk written on its own
    parts = run(scene(), tmp_path / "parts.nc", t_end=0.03, chunk=4)
    with xr.open_dataset(whole.results_path, engine="h5netcdf") as a, \
            xr.open_dataset(parts.results_path, engine="h5netcdf") as b:
        assert a.sizes["time"] == 16 and np.all(np.diff(a["time"].values) > 0)
        for name in a.variables:
            assert np.array_equal(a[name].values, b[name].values), name
