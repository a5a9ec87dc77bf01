"""NewtonPolicy: HHT's Jacobian/LU reuse and refresh rules on plain numbers (no model)."""
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import mbd
from mbd.hht import NewtonAction as A, NewtonPolicy

POL = NewtonPolicy(newton_tol=1e-3, max_iter=10, rate_refresh=0.3, max_refresh=2, reuse=True)


def test_hht_builds_its_policy_from_its_fields():
    st = mbd.HHT(alpha=-0.3, newton_tol=1e-4, max_iter=7, rate_refresh=0.5, max_refresh=1, reuse=False)
    assert st.policy == NewtonPolicy(newton_tol=1e-4, max_iter=7, rate_refresh=0.5, max_refresh=1, reuse=False)
    assert mbd.HHT(alpha=-0.3).policy == NewtonPolicy()      # same defaults


@pytest.mark.parametrize("kw", [{"max_iter": 0}, {"newton_tol": 0.0}, {"newton_tol": 1.0}])
def test_invalid_settings_are_refused(kw):
    with pytest.raises(mbd.ModelError, match="newton_tol"):
        NewtonPolicy(**kw)


def test_refactor_at_step_start():
    assert POL.refactor_at_start(False, 1e-5, 1e-5)             # no LU kept
    assert POL.refactor_at_start(True, 1e-5, 2e-5)              # LU made for another h
    assert POL.refactor_at_start(True, math.nan, 1e-5)          # never factorized
    assert not POL.refactor_at_start(True, 1e-5, 1e-5)          # reuse it
    no_reuse = NewtonPolicy(reuse=False)
    assert no_reuse.refactor_at_start(True, 1e-5, 1e-5)


def test_rate_and_eta():
    assert NewtonPolicy.rate(0.2, 0.8) == 0.25
    assert NewtonPolicy.rate(0.2, 0.0) == 0.0                   # previous correction exactly zero
    assert NewtonPolicy.eta(None) == math.inf                   # first iteration on a matrix: no rate
    assert NewtonPolicy.eta(0.25) == pytest.approx(1.0 / 3.0)
    assert NewtonPolicy.eta(1.0) == math.inf and NewtonPolicy.eta(2.0) == math.inf


def test_converged():
    assert POL.converged(1.0, 1e-3)                             # η‖Δ‖ = tol: on the boundary, accepted
    assert not POL.converged(1.0, 1.1e-3)
    assert POL.converged(0.1, 5e-3)                             # fast contraction accepts a larger ‖Δ‖
    # without a rate (η = ∞) only a correction below 1e-2·tol counts
    assert POL.converged(math.inf, 1e-5)
    assert not POL.converged(math.inf, 2e-5)
    assert POL.converged(math.inf, 0.0)


def test_after_iteration_continues_without_a_rate_or_with_a_good_one():
    assert POL.after_iteration(1, None, 0) is A.CONTINUE        # first iteration on a matrix
    assert POL.after_iteration(3, 0.3, 0) is A.CONTINUE         # at rate_refresh: still good enough
    assert POL.after_iteration(3, 0.1, 2) is A.CONTINUE


def test_after_iteration_refreshes_a_slow_contraction():
    assert POL.after_iteration(2, 0.5, 0) is A.REFRESH
    assert POL.after_iteration(2, 0.99, 1) is A.REFRESH
    # the correction made it worse: refresh at the previous iterate
    assert POL.after_iteration(2, 1.0, 0) is A.REFRESH_AT_PREVIOUS
    assert POL.after_iteration(4, 3.0, 1) is A.REFRESH_AT_PREVIOUS


def test_after_iteration_diverges_only_after_max_refresh():
    assert POL.after_iteration(5, 1.0, 2) is A.DIVERGED
    assert POL.after_iteration(10, 5.0, 2) is A.DIVERGED        # divergence is reported before running out
    # a slow but contracting iteration with no refreshes left keeps going
    assert POL.after_iteration(5, 0.9, 2) is A.CONTINUE


def test_after_iteration_out_of_iterations():
    assert POL.after_iteration(10, None, 0) is A.OUT_OF_ITERATIONS
    assert POL.after_iteration(10, 0.1, 0) is A.OUT_OF_ITERATIONS
    # no refresh on the last iteration: there would be no iteration left to use it
    assert POL.after_iteration(10, 0.5, 0) is A.OUT_OF_ITERATIONS
    assert POL.after_iteration(10, 1.5, 1) is A.OUT_OF_ITERATIONS
    one = NewtonPolicy(max_iter=1)
    assert one.after_iteration(1, None, 0) is A.OUT_OF_ITERATIONS


# --- the per-component test ---------------------------------------------------------------

def test_converged_each_takes_every_component_at_its_own_rate():
    """Measured on the DPGT: after a refresh the largest correction moved from one DOF (6.1) to another
    (0.067, 0.096 the iteration before). The max norm's rate 0.011 accepted that step; the DOF itself
    contracts at 0.7, and the remaining correction measured from outside was 0.067 (67× the tolerance)."""
    prev, x = np.array([6.1, 0.096]), np.array([1e-3, 0.067])
    assert POL.converged(POL.eta(POL.rate(x.max(), prev.max())), x.max())
    assert not POL.converged_each(x, prev)
    # each component contracting fast enough: θ = 0.01 and 0.05, η_j x_j = 1e-6 and 2.6e-5
    assert POL.converged_each(np.array([1e-4, 5e-4]), np.array([1e-2, 1e-2]))
    # one component just too slow: θ = 0.5, η x = 1.1e-3 > 1e-3
    assert not POL.converged_each(np.array([1e-4, 1.1e-3]), np.array([1e-2, 2.2e-3]))


def test_converged_each_without_a_rate_or_with_a_growing_component():
    assert POL.converged_each(np.array([1e-5, 0.0]), None)              # all below 1e-2·tol: no rate needed
    assert not POL.converged_each(np.array([1e-5, 2e-5]), None)
    # a component that does not contract (θ ≥ 1) above 1e-2·tol: nothing bounds what is left of it
    assert not POL.converged_each(np.array([1e-9, 1e-4]), np.array([1.0, 1e-4]))
    # below 1e-2·tol it does not count, whatever its rate
    assert POL.converged_each(np.array([1e-9, 1e-5]), np.array([1.0, 1e-6]))
    assert POL.converged_each(np.zeros(0), None)


@given(st.lists(st.tuples(st.floats(0, 1e2), st.floats(1e-12, 1e2)), min_size=1, max_size=8),
       st.floats(1e-6, 0.5))
def test_converged_each_is_never_looser_than_the_max_norm_test(pairs, tol):
    x, prev = (np.array(c) for c in zip(*pairs))
    pol = NewtonPolicy(newton_tol=tol)
    if pol.converged_each(x, prev):
        assert pol.converged(pol.eta(pol.rate(x.max(), prev.max())), x.max())
    if pol.converged_each(x, None):
        assert pol.converged(math.inf, x.max())


def test_hht_passes_the_test_choice_to_its_policy():
    assert mbd.HHT(alpha=-0.3).policy.per_component
    assert not mbd.HHT(alpha=-0.3, per_component=False).policy.per_component
