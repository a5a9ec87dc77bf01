"""Timing loops over the compiled engine's parts (``scenarios.bench_breakdown``): each calls one part ``reps`` times
in compiled code, so a timing holds no Python. They live here, beside the kernels they inline, so that the kernel
cache's staleness guard (:func:`mbd.compiled._drop_stale_kernels`) drops them with the kernels: a loop cached
elsewhere would keep timing a changed kernel's old code. Those that reach the family kernels take the system's
kernel groups first, a literal (:func:`.registry.call`), as the engine's own loop does."""
from __future__ import annotations

from numba import literally, njit

from .registry import evaluate_for
from .sparse_lu import _factor, _solve
from .system import assemble, update_internal

__all__ = ["repeat_kernel", "repeat_assemble", "repeat_lu", "repeat_solve", "repeat_update", "replay"]


@njit(cache=True)
def repeat_kernel(groups, reps, kind, t, phi, omega, ql, vl, z, P, G, F, Jq, Jv, jac):
    literally(groups)
    for _ in range(reps):
        evaluate_for(groups, kind, t, phi, omega, 0.0, ql, vl, z, P, G, F, Jq, Jv, jac)


@njit(cache=True)
def repeat_assemble(groups, reps, t, q, v, fams, zs, jac, sysd, F, Jq, Jv):
    literally(groups)
    for _ in range(reps):
        assemble(groups, t, q, v, fams, zs, jac, sysd, F, Jq, Jv)


@njit(cache=True)
def repeat_lu(reps, c_C, c_K, Mdata, Jq, Jv, A, lu):
    """The Newton matrix M − c_C J_v − c_K J_q formed and factored, as the step loop's refresh does (``lu``: the
    factors' arrays, :attr:`.sparse_lu.FixedPatternLU.arrays`)."""
    ok = True
    for _ in range(reps):
        for e in range(A.size):
            A[e] = Mdata[e] - c_C * Jv[e] - c_K * Jq[e]
        ok = _factor(lu, A)
    return ok


@njit(cache=True)
def repeat_solve(reps, lu, b):
    s = 0.0
    for _ in range(reps):
        s += _solve(lu, b)[0]
    return s


@njit(cache=True)
def repeat_update(groups, reps, t0, t1, q0, v0, q1, v1, fams, zs, sysd):
    literally(groups)
    for _ in range(reps):
        update_internal(groups, t0, t1, q0, v0, q1, v1, fams, zs, sysd)


@njit(cache=True)
def replay(groups, steps, cr, cj, cs, t, q, v, fams, zs, sysd, F, Jq, Jv, c_C, c_K, Mdata, A, lu, b, t0, q0, v0):
    """The parts in a step's mix and order (per step: a Jacobian + LU when their count per step has accrued to one,
    then the residuals and solves accrued, then the internal-state update), without the loop's own arithmetic."""
    literally(groups)
    aj, ar, asol = 0.0, 0.0, 0.0
    for _ in range(steps):
        aj += cj
        if aj >= 1.0:
            aj -= 1.0
            assemble(groups, t, q, v, fams, zs, bool(True), sysd, F, Jq, Jv)    # run-time flags, as the step loop
            for e in range(A.size):
                A[e] = Mdata[e] - c_C * Jv[e] - c_K * Jq[e]
            _factor(lu, A)
        ar += cr
        asol += cs
        while ar >= 1.0 or asol >= 1.0:
            if ar >= 1.0:
                ar -= 1.0
                assemble(groups, t, q, v, fams, zs, bool(False), sysd, F, Jq, Jv)
            if asol >= 1.0:
                asol -= 1.0
                _solve(lu, b)
        update_internal(groups, t0, t, q0, v0, q, v, fams, zs, sysd)
