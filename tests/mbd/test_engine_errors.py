"""Bad input fails early with ModelError naming the parameter; integration failures raise
IntegrationError with time, step and culprit, and save the last good state; the progress bar."""
from __future__ import annotations

import dataclasses

import importlib

import numpy as np
import pytest

import mbd
from mbd.element import Element, body_dofs
from mbd.elements import BodySpring, GroundSupport, SpeedDrive, TorqueSource, TorsionalSpring

sim_module = importlib.import_module("mbd.simulate")


def two_bodies(frame=None):
    b = mbd.ModelBuilder(frame=frame)
    a = b.add_body("a", 1.0, 0.1)
    c = b.add_body("c", 1.0, 0.1, pose=(0.1, 0.0, 0.0))
    return b, a, c


# ------------------------------------------------------------------------------- model data
@pytest.mark.parametrize("mass, inertia, match", [(-1.0, 0.1, "mass"), (0.0, 0.1, "mass"), (np.nan, 0.1, "mass"),
                                                  (1.0, -0.1, "inertia"), (1.0, np.inf, "inertia")])
def test_bad_body_data(mass, inertia, match):
    b = mbd.ModelBuilder()
    with pytest.raises(mbd.ModelError, match=match):
        b.add_body("rotor", mass, inertia)


def test_bad_pose_gravity_and_names():
    b = mbd.ModelBuilder()
    with pytest.raises(mbd.ModelError, match="pose"):
        b.add_body("a", 1.0, 1.0, pose=(0.0, np.nan, 0.0))
    with pytest.raises(mbd.ModelError, match="pose"):
        b.add_body("a", 1.0, 1.0, pose=(0.0, 0.0))
    with pytest.raises(mbd.ModelError, match="gravity"):
        mbd.ModelBuilder(gravity=(0.0, 0.0, -9.81))
    b.add_body("a", 1.0, 1.0)
    with pytest.raises(mbd.ModelError, match="'a'.*twice"):
        b.add_body("a", 1.0, 1.0)
    b.add(TorqueSource("t", 0, 1.0))
    with pytest.raises(mbd.ModelError, match="'t'.*twice"):
        b.add(TorqueSource("t", 0, 1.0))
    with pytest.raises(mbd.ModelError, match="at least one body"):
        mbd.ModelBuilder().build()
    m = b.build()
    with pytest.raises(mbd.ModelError, match="'nobody'"):
        m.body("nobody")
    with pytest.raises(mbd.ModelError, match="'nothing'"):
        m.element("nothing")


@pytest.mark.parametrize("make, match", [
    (lambda: BodySpring("s", 0, 1, k=-1.0), "'k'"),
    (lambda: BodySpring("s", 0, 1, k=1.0, c=-2.0), "'c'"),
    (lambda: BodySpring("s", [0, 1], [1, 2], k=[1.0, 2.0, 3.0]), "'k'"),
    (lambda: BodySpring("s", [0, 1], [1, 2], k=1.0, marker_a=[[0, 0], [0, 0], [0, 0]]), "'marker_a'"),
    (lambda: BodySpring("s", 0, 1, k=1.0, marker_b=(0.0, np.nan)), "'marker_b'"),
    (lambda: GroundSupport("g", 0, kx=np.nan), "'kx'"),
    (lambda: GroundSupport("g", 0, kx=1.0, ky=-1.0), "'ky'"),
    (lambda: GroundSupport("g", [0, 1], kx=1.0, anchor=[1.0, 2.0, 3.0]), "'anchor'"),
    (lambda: TorsionalSpring("t", 0, 1, k=1.0, c=-1.0), "'c'"),
    (lambda: SpeedDrive("d", 0, omega_ref=np.inf, k=1.0), "omega_ref"),
    (lambda: SpeedDrive("d", 0, omega_ref=1.0, k=0.0), "'k'"),
    (lambda: TorqueSource("t", [0, 1], torque=[1.0, 2.0, 3.0]), "'torque'"),
    (lambda: mbd.elements.Ramp(1.0, 0.5), "t0 <= t1"),
], ids=lambda x: x if isinstance(x, str) else "")
def test_bad_element_parameters_name_the_parameter(make, match):
    with pytest.raises(mbd.ModelError, match=match):
        make()


def test_mismatched_index_arrays():
    with pytest.raises(mbd.ModelError, match="index arrays"):
        body_dofs([0, 1], [0, 1, 2])
    with pytest.raises(mbd.ModelError, match="index arrays"):
        BodySpring("s", [0, 1], [1, 2, 3], k=1.0)


def test_dof_index_out_of_range_names_the_element():
    b, a, c = two_bodies()
    b.add(BodySpring("link", a, 7, k=1.0))                 # a body of some other, larger model
    with pytest.raises(mbd.ModelError, match="'link'.*out of range"):
        b.build()


def test_malformed_dofs_array_names_the_element():
    class Bad(Element):
        k = 3
        name = "bad"

        def __init__(self):
            self.dofs = np.zeros((2, 2), dtype=np.int64)

    b, a, c = two_bodies()
    b.add(Bad())
    with pytest.raises(mbd.ModelError, match="'bad'.*dofs"):
        b.build()


@pytest.mark.parametrize("alpha", [0.1, -0.34, -1.0, np.nan])
def test_alpha_outside_range(alpha):
    with pytest.raises(mbd.ModelError, match="alpha"):
        mbd.HHT(alpha=alpha)
    with pytest.raises(mbd.ModelError, match="alpha"):
        mbd.hht_coefficients(alpha)


def test_bad_settings():
    with pytest.raises(mbd.ModelError, match="rtol"):
        mbd.Tolerance(rtol=-1e-3)
    with pytest.raises(mbd.ModelError, match="atol_pos"):
        mbd.Tolerance(atol_pos=-1e-9)
    with pytest.raises(mbd.ModelError, match="FixedStep.h"):
        mbd.FixedStep(0.0)
    with pytest.raises(mbd.ModelError, match="h_min"):
        mbd.Adaptive(h0=1e-6, h_min=1e-3)
    with pytest.raises(mbd.ModelError, match="every"):
        mbd.Checkpoint("x", every=0)
    with pytest.raises(mbd.ModelError, match="newton_tol"):
        mbd.HHT(alpha=-0.3, newton_tol=2.0)
    with pytest.raises(TypeError, match="alpha"):        # no default α: the production one is mbd.PRODUCTION
        mbd.HHT()
    with pytest.raises(mbd.ModelError, match="method"):
        dataclasses.replace(mbd.PRODUCTION, method="rk4")
    with pytest.raises(mbd.ModelError, match="alpha"):
        dataclasses.replace(mbd.PRODUCTION, alpha=-0.5)


@pytest.mark.parametrize("bad", ["q0", "v0"])
def test_nan_initial_state_names_it(bad):
    b, a, c = two_bodies()
    b.add(BodySpring("link", a, c, k=10.0))
    m = b.build()
    q0, v0 = np.zeros(6), np.zeros(6)
    (q0 if bad == "q0" else v0)[4] = np.nan
    with pytest.raises(mbd.ModelError, match=rf"{bad}.*NaN.*y of body 'c'"):
        mbd.simulate(m, q0, v0, 1.0, controller=mbd.FixedStep(0.1), progress=False)


def test_simulate_argument_errors():
    b, a, c = two_bodies()
    m = b.build()
    with pytest.raises(mbd.ModelError, match="controller"):
        mbd.simulate(m, np.zeros(6), np.zeros(6), 1.0)
    with pytest.raises(mbd.ModelError, match="t_end"):
        mbd.simulate(m, np.zeros(6), np.zeros(6), -1.0, controller=mbd.FixedStep(0.1))
    with pytest.raises(mbd.ModelError, match="6 entries"):
        mbd.simulate(m, np.zeros(5), np.zeros(6), 1.0, controller=mbd.FixedStep(0.1))
    with pytest.raises(mbd.ModelError, match="q0 and v0"):
        mbd.simulate(m, None, None, 1.0, controller=mbd.FixedStep(0.1))


# -------------------------------------------------------------------------- integration errors
class Breaker(Element):
    """A stiff contact that turns non-finite after t_break (a stand-in for a contact law blowing up)."""
    n_local = 3

    def __init__(self, name, body, t_break):
        self.name = name
        self.dofs = body_dofs(body)
        self.t_break = t_break

    def kernel(self, t, fs, q, v, z):
        f = -1e6 * (q[0] - 0.5)
        if t > self.t_break:
            f = f * np.nan
        zero = 0.0 * q[0]
        return [f, zero, zero], {}


@pytest.mark.parametrize("controller", [mbd.FixedStep(1e-3, max_halvings=4), mbd.Adaptive(h0=1e-3, h_min=1e-6)],
                         ids=["fixed", "adaptive"])
def test_step_below_minimum_raises_with_diagnostics_and_saves_state(tmp_path, controller):
    b, a, c = two_bodies()
    b.add(BodySpring("link", a, c, k=100.0))
    b.add(Breaker("contact", a, t_break=0.0105))
    m = b.build()
    saved = tmp_path / "failed.npz"
    with pytest.raises(mbd.IntegrationError) as exc:
        mbd.simulate(m, np.zeros(6), np.zeros(6), 0.1, controller=controller, failed_state_path=saved,
                     progress=False)
    err = exc.value
    msg = str(err)
    assert "t = 1.0" in msg and "h = " in msg and "'contact'" in msg, msg
    assert err.state is not None and 0.009 <= err.state.t <= 0.0105
    assert err.saved_to == str(saved) and saved.exists()
    # the loop's counters up to the failure travel with the exception
    c = err.counters
    assert set(c) == {"residual", "jacobian", "factor", "newton", "accepted", "rejected"}
    assert c["accepted"] > 0 and c["rejected"] > 0 and c["factor"] > 0 and c["newton"] >= c["accepted"]
    s, extra = mbd.load_state(saved)
    assert s.t == err.state.t and np.array_equal(s.q, err.state.q) and extra["reason"]


def test_non_finite_initial_forces_name_the_family():
    b, a, c = two_bodies()
    b.add(Breaker("contact", a, t_break=-1.0))
    m = b.build()
    with pytest.raises(mbd.IntegrationError, match=r"t = 0.*\['contact'\]"):
        mbd.simulate(m, np.zeros(6), np.zeros(6), 0.1, controller=mbd.FixedStep(1e-3), progress=False)


# ------------------------------------------------------------------------------- progress bar
class FakeClock:
    """perf_counter that advances 1 s per call: every run looks long enough to show the bar."""

    def __init__(self):
        self.t = 0.0

    def perf_counter(self):
        self.t += 1.0
        return self.t


def _short_run(progress):
    b, a, c = two_bodies()
    b.add(BodySpring("link", a, c, k=10.0))
    return mbd.simulate(b.build(), np.zeros(6), np.ones(6), 0.05, controller=mbd.FixedStep(1e-3), progress=progress)


@pytest.mark.parametrize("progress, env, shown", [(True, None, True), (False, None, False), (None, "0", False),
                                                  (None, None, True)])
def test_progress_bar_switch(monkeypatch, capfd, progress, env, shown):
    monkeypatch.setattr(sim_module, "time", FakeClock())
    if env is None:
        monkeypatch.delenv("DPGT_PROGRESS", raising=False)
    else:
        monkeypatch.setenv("DPGT_PROGRESS", env)
    _short_run(progress)
    out, err = capfd.readouterr()
    assert ("simulating" in err) is shown
    if not shown:
        assert out == "" and err == ""
