"""Scalar rules shared by the numpy engine path and the compiled one, written once.

Newton's reuse/refresh decisions (:class:`mbd.hht.NewtonPolicy`) and the step-size controllers'
accept/next-h decisions (:mod:`mbd.control`) are plain functions of numbers. They are compiled with
numba when it is importable (the compiled stepper calls them from compiled code); without numba they
stay plain Python, and the numpy path works the same.
"""
from __future__ import annotations

import math

try:
    from numba import njit as _njit

    def jit(fn):
        return _njit(cache=True)(fn)
except ImportError:      # pragma: no cover - the numpy path needs no compiler
    def jit(fn):
        return fn

__all__ = ["CONTINUE", "REFRESH", "REFRESH_AT_PREVIOUS", "DIVERGED", "OUT_OF_ITERATIONS", "newton_rate",
           "newton_eta", "newton_converged", "newton_converged_each", "newton_action", "adaptive_decide",
           "fixed_decide"]

# what Newton does after an unconverged iteration (codes of mbd.hht.NewtonAction)
CONTINUE, REFRESH, REFRESH_AT_PREVIOUS, DIVERGED, OUT_OF_ITERATIONS = 0, 1, 2, 3, 4


@jit
def newton_rate(nrm, prev):
    """Contraction rate θ of a correction against the previous one on the same matrix."""
    return nrm / prev if prev > 0 else 0.0


@jit
def newton_eta(rate, has_rate):
    """η = θ/(1−θ); ∞ without a rate (first iteration on a matrix) or when θ ≥ 1."""
    return rate / (1.0 - rate) if has_rate and rate < 1.0 else math.inf


@jit
def newton_converged(eta, nrm, newton_tol):
    """Hairer's test η‖Δ‖ ≤ tol; without a rate the correction itself must be 100× below it."""
    return eta * nrm <= newton_tol or nrm <= 1e-2 * newton_tol


@jit
def newton_converged_each(x, prev, has_prev, newton_tol):
    """Hairer's test per component: every scaled correction x_j (|Δq_j| / its error scale) is below
    1e-2·tol, or contracts against the previous correction on the same matrix (θ_j = x_j/prev_j < 1) with
    η_j·x_j ≤ tol, η_j = θ_j/(1−θ_j). The test on the max norm alone takes the rate of the norm, which
    is not the rate of any one component: when the largest correction moves to another DOF between two
    iterations (a roller whose contact switched), θ = ‖x‖/‖prev‖ can be 0.01 while that DOF contracts at
    0.7 — measured on the DPGT, such a step was accepted 0.067·atol from its solution (η‖x‖ = 7e-4).
    Never looser than :func:`newton_converged` (for the largest component θ_j ≥ ‖x‖/‖prev‖)."""
    small = 1e-2 * newton_tol
    for j in range(x.size):
        xj = x[j]
        if xj <= small:
            continue
        if not has_prev or not xj < prev[j]:      # no rate, or θ_j ≥ 1: nothing bounds the rest
            return False
        th = xj / prev[j]
        if th / (1.0 - th) * xj > newton_tol:
            return False
    return True


@jit
def newton_action(it, rate, has_rate, refreshes, rate_refresh, max_refresh, max_iter):
    """Next move after unconverged iteration ``it`` (1-based): a slow contraction refreshes the Jacobian
    (at the previous iterate when the correction made it worse) up to ``max_refresh`` times per step; a
    rate ≥ 1 after that is divergence."""
    if has_rate and rate > rate_refresh:
        if rate >= 1.0 and refreshes >= max_refresh:
            return DIVERGED
        if refreshes < max_refresh and it < max_iter:
            return REFRESH_AT_PREVIOUS if rate >= 1.0 else REFRESH
    return OUT_OF_ITERATIONS if it >= max_iter else CONTINUE


@jit
def adaptive_decide(h, converged, error, h_max, safety, grow_max, shrink_min, fail_factor, hold):
    """(accept, next h) of :class:`mbd.control.Adaptive`: error exponent 1/3 (local displacement error
    O(h³)), safety factor, growth limits; a growth within ``hold`` keeps h (and the LU)."""
    if not converged:
        return False, h * fail_factor
    err = max(error, 1e-10)
    fac = min(grow_max, max(shrink_min, safety * err ** (-1.0 / 3.0)))
    accept = err <= 1.0
    if accept and 1.0 <= fac <= hold:
        fac = 1.0
    return accept, min(h_max, h * fac)


@jit
def fixed_decide(h, converged, error, h_fixed, reject_error):
    """(accept, next h) of :class:`mbd.control.FixedStep`: halve on failure, back to h_fixed after."""
    if converged and error <= reject_error:
        return True, h_fixed
    return False, h / 2
