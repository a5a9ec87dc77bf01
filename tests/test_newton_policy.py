"""NewtonPolicy: HHT's Jacobian/LU reuse and refresh rules on plain numbers (no model)."""
import math

import pytest

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
