"""HHT's Newton iteration really converges on stiff, switching contacts.

A regression test for a defect found while studying larger steps: after a Jacobian refresh the next
iteration computed its contraction rate against ``prev = inf``, got 0 and accepted any correction, so
at h = 10 µs on the DPGT 40 of 60 steps ended up to 114·atol from the solution. Here every accepted step
is checked from outside: one exact Newton correction at the accepted state must be below the tolerance.
"""
import numpy as np
import pytest
import scipy.sparse.linalg as spla

import mbd
from mbd.hht import NewtonCache
from scenarios.numerics.common import rig_problem


@pytest.mark.parametrize("h", [5e-6, 1e-5])
def test_accepted_steps_are_converged_on_the_bearing_rig(h):
    prob = rig_problem()
    system = mbd.System(prob.model)
    st = mbd.HHT(alpha=-0.3)
    beta, gamma = st.beta_gamma
    s = st.initial_state(system, 0.0, prob.built.q0, prob.built.v0)
    cache = NewtonCache()
    remaining, refreshed = [], 0
    for _ in range(150):                      # the start transient: rollers and cage find their contacts
        hh = h
        new, info = st.step(system, s, hh, cache)
        while not info.converged:
            hh /= 2
            assert hh > h / 64, f"Newton failed at t = {s.t}: {info.reason}"
            new, info = st.step(system, s, hh, cache)
        refreshed += info.jacobian_refreshed
        # the step's equations hold the element internal states at their start values (z updates after
        # acceptance, e.g. an impact's onset speed), so the outside check uses them too
        ev = system.evaluate(new.t, new.q, new.v, s.z, jac=True)
        F = ev.F
        A = system.newton_matrix(ev, 1.0, (1 + st.alpha) * gamma * hh, (1 + st.alpha) * beta * hh * hh)
        r = prob.model.mdiag * new.a - (1 + st.alpha) * F + st.alpha * s.f
        da = spla.splu(A.tocsc()).solve(r)
        remaining.append(np.max(np.abs(beta * hh * hh * da) / st.tol.scale(prob.model, s.q, new.q)))
        s = new
    assert refreshed > 5                       # the case exercises refreshes inside the iteration
    # η‖Δ‖ ≤ newton_tol stops the iteration; the true remaining correction is of that order (10× margin
    # for the estimate η, which is only a model of the contraction)
    assert max(remaining) < 10 * st.newton_tol, f"worst remaining correction {max(remaining):.3g} (scaled)"


def test_factorization_falls_back_to_partial_pivoting(monkeypatch):
    """The Newton matrix is factorized with diagonal pivots; where that meets a zero pivot (SuperLU
    raises), partial pivoting takes over and the step still converges to the same solution."""
    import mbd.hht as hht

    prob = rig_problem()
    system = mbd.System(prob.model)
    st = mbd.HHT(alpha=-0.3)
    s = st.initial_state(system, 0.0, prob.built.q0, prob.built.v0)
    ref, info_ref = st.step(system, s, 5e-6, NewtonCache())
    real, calls = hht.spla.splu, []

    def no_diagonal_pivots(A, **kw):
        calls.append(kw.get("permc_spec"))
        if kw.get("diag_pivot_thresh") == 0.0:
            raise RuntimeError("Factor is exactly singular")
        return real(A, **kw)

    monkeypatch.setattr(hht.spla, "splu", no_diagonal_pivots)
    new, info = st.step(system, s, 5e-6, NewtonCache())
    assert info.converged and info_ref.converged
    assert "COLAMD" in calls
    scale = st.tol.scale(prob.model, s.q, new.q)
    assert np.max(np.abs(new.q - ref.q) / scale) < 10 * st.newton_tol


class _Remaining(mbd.Observer):
    """One exact Newton correction (numpy reference path, fresh Jacobian) at every accepted state."""

    def __init__(self, stepper):
        self.st, self.remaining = stepper, []

    def bind(self, model, system, state):
        self.model, self.system = model, mbd.System(model)

    def step(self, s0, s1):
        st, h = self.st, s1.t - s0.t
        beta, gamma = st.beta_gamma
        ev = self.system.evaluate(s1.t, s1.q, s1.v, s0.z, jac=True)    # z held at the step's start, as HHT does
        A = self.system.newton_matrix(ev, 1.0, (1 + st.alpha) * gamma * h, (1 + st.alpha) * beta * h * h)
        r = self.model.mdiag * s1.a - (1 + st.alpha) * ev.F + st.alpha * s0.f
        da = spla.splu(A.tocsc()).solve(r)
        self.remaining.append(float(np.max(np.abs(beta * h * h * da) / st.tol.scale(self.model, s0.q, s1.q))))


def test_accepted_steps_are_converged_on_the_loaded_dpgt():
    """The full DPGT 3 ms into its load ramp, 1000 fixed steps of 5 µs on the compiled engine, every accepted
    step checked from outside. Roller contacts switch in most steps and the largest Newton correction jumps
    between DOFs. The test on the max norm's rate (``per_component=False``, the former test),
    from this same state, accepted step 696 0.17·atol from its solution (3 steps above 1e-2, 11 above 3e-3;
    from the state its own ramp reaches: 0.014 at step 959, 0.019 at step 1499 in 2000 steps; 0.067 in the
    settled benchmark window, 0.13 with the adaptive production setting). Each DOF at its own rate: worst
    0.0032 here (1 step above 3e-3), 0.0040 in 2000 steps (measured). Iterations per step: 4.98 (4.88 with
    the max-norm test); the bound 5.4 catches a policy that stops reusing the LU well or iterates to no end."""
    from tests.support.dpgt_runs import ramp_state

    sc, s = ramp_state(0.003, "compiled")
    st = mbd.PRODUCTION.stepper()
    check = _Remaining(st)
    res = mbd.simulate(sc.model, t_end=s.t + 1000 * 5e-6, state=s.copy(), stepper=st, controller=mbd.FixedStep(5e-6),
                       progress=False, observers=[check])
    assert res.engine == "compiled" and len(check.remaining) >= 1000
    assert max(check.remaining) < 10 * st.newton_tol, f"worst remaining correction {max(check.remaining):.3g}"
    assert res.counters["newton"] / res.steps < 5.4
