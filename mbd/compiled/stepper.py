"""The compiled HHT-α step loop: predictor, Newton under the reuse/refresh rules of :mod:`mbd.rules`,
the fixed-pattern LU, the error estimate, the internal-state update and the step-size controller —
many accepted steps per call, the same arithmetic in the same order as :class:`mbd.HHT` with
:func:`mbd.simulate` (tests require identical counters and states to round-off).

A call advances until ``t_end``, until ``max_steps`` steps were accepted (the caller then records,
observes, checkpoints) or until the step size falls below the controller's floor (a failure the caller
reports with the last good state). A zero diagonal pivot falls back to a dense LU with partial pivoting
(the numpy path falls back to SuperLU with partial pivoting).

Compiled as one function, for a short first compile: numba links a callee's code into its caller and optimises it
again there, once per level, so the loop's helpers (:func:`_step`, :func:`_newton`, :func:`_refresh_at`,
:func:`_refresh`, :func:`_lu_solve`, :func:`_scale`) are inlined into :func:`advance` at numba's IR level
(``inline="always"``; the Newton loop refreshes the Jacobian and LU at one place, so one inlined copy of the assembly
call and the factorisation serves both the first refresh and those the rules ask for), and the assembly gets ``jac`` as
a run-time bool (``bool(True)``: a constant would be typed as a literal and compile the assembly and every family
kernel twice; the kernels branch on it per contact). docs/numerics.md §5 "The compile" has the measurements.
"""
from __future__ import annotations

import numpy as np
from numba import literally, njit

from .. import rules
from .sparse_lu import _factor, _solve
from .system import assemble, update_internal

__all__ = ["advance", "FAIL_REASONS"]

# why a step failed (StepInfo.reason of the numpy path)
FAIL_REASONS = ("", "singular Newton matrix", "non-finite forces", "non-finite Newton correction",
                "Newton diverged", "Newton did not converge in max_iter")
_SINGULAR, _NONFINITE_F, _NONFINITE_DA, _DIVERGED, _MAX_ITER = 1, 2, 3, 4, 5


@njit(cache=True)
def _dense_lu(A):
    """In-place LU with partial pivoting of a dense matrix; (ok, pivots)."""
    n = A.shape[0]
    piv = np.arange(n)
    for k in range(n):
        p = k + np.argmax(np.abs(A[k:, k]))
        if A[p, k] == 0.0 or not np.isfinite(A[p, k]):
            return False, piv
        if p != k:
            for j in range(n):
                A[k, j], A[p, j] = A[p, j], A[k, j]
            piv[k], piv[p] = piv[p], piv[k]
        inv = 1.0 / A[k, k]
        for i in range(k + 1, n):
            A[i, k] *= inv
            lik = A[i, k]
            if lik != 0.0:
                for j in range(k + 1, n):
                    A[i, j] -= lik * A[k, j]
    return True, piv


@njit(cache=True)
def _dense_solve(A, piv, b):
    n = b.size
    y = np.empty(n)
    for i in range(n):
        y[i] = b[piv[i]]
    for i in range(n):
        for j in range(i):
            y[i] -= A[i, j] * y[j]
    for i in range(n - 1, -1, -1):
        for j in range(i + 1, n):
            y[i] -= A[i, j] * y[j]
        y[i] /= A[i, i]
    return y


@njit(cache=True, inline="always")
def _refresh(groups, t1, q1, v1, c_C, c_K, fams, zs, sysd, pat, lu, F, Jq, Jv, A):
    """New Jacobian + LU at (q1, v1): the forces there in F; 0 = sparse LU, 1 = dense fallback,
    -1 = unusable Newton matrix."""
    indptr, indices, Mdata, mdiag = pat
    n = mdiag.size
    arrs, D, dpiv = lu
    assemble(groups, t1, q1, v1, fams, zs, bool(True), sysd, F, Jq, Jv)       # a run-time flag (module docstring)
    for e in range(A.size):
        A[e] = Mdata[e] - c_C * Jv[e] - c_K * Jq[e]
        if not np.isfinite(A[e]):
            return -1
    if _factor(arrs, A):
        return 0
    if D.shape[0] != n:                               # no room for the dense fallback (a large model)
        return -1
    D[:, :] = 0.0                                     # a zero diagonal pivot: partial pivoting
    for c in range(n):
        for p in range(indptr[c], indptr[c + 1]):
            D[indices[p], c] = A[p]
    ok, pv = _dense_lu(D)
    for i in range(n):
        dpiv[i] = pv[i]
    return 1 if ok else -1


@njit(cache=True, inline="always")
def _refresh_at(groups, t1, h, bh2, gh, c_C, c_K, fams, zs, sysd, pat, lu, cache, work, cnt):
    """Jacobian + LU at the current iterate a₁ (its forces left in work's F1); False when unusable."""
    qp, vp, a1, q1, v1, F1, r, sc, x, xp, Jq, Jv, A = work
    for i in range(a1.size):
        q1[i] = qp[i] + bh2 * a1[i]
        v1[i] = vp[i] + gh * a1[i]
    kind = _refresh(groups, t1, q1, v1, c_C, c_K, fams, zs, sysd, pat, lu, F1, Jq, Jv, A)
    cnt[1] += 1
    cache[1] = h
    if kind < 0:
        cache[0] = 0.0
        return False
    cache[0], cache[2] = 1.0, kind
    return True


@njit(cache=True, inline="always")
def _lu_solve(kind, lu, r, n):
    arrs, D, dpiv = lu
    if kind == 0:
        return _solve(arrs, r)
    return _dense_solve(D, dpiv, r)


@njit(cache=True, inline="always")
def _scale(atol, rtol, q0, q1, out):
    for i in range(atol.size):
        out[i] = atol[i] if rtol == 0.0 else atol[i] + rtol * max(abs(q0[i]), abs(q1[i]))


@njit(cache=True, inline="always")
def _newton(groups, t, q, v, a, f, h, prm, atol, rtol, fams, zs, sysd, pat, lu, cache, work, cnt):
    """Newton on a₁ (returns it in work's a1); (converged, iterations, rate, reason). ``cache``:
    [LU valid (1/0), h of the LU, LU kind (0 sparse, 1 dense)]; ``cnt``: this step's residuals, Jacobians."""
    alpha, beta, gamma = prm[0], prm[1], prm[2]
    newton_tol, max_iter, rate_refresh, max_refresh, reuse = prm[4], int(prm[5]), prm[6], int(prm[7]), prm[8] > 0
    per_component = prm[9] > 0
    qp, vp, a1, q1, v1, F1, r, sc, x, xp, Jq, Jv, A = work
    n = q.size
    mdiag = pat[3]
    bh2, gh = beta * h * h, gamma * h
    c_C, c_K = (1.0 + alpha) * gh, (1.0 + alpha) * bh2
    have_F = False
    refreshes = 0
    rate = 0.0
    refresh = cache[0] == 0.0 or cache[1] != h or not reuse
    has_prev = False
    prev = 0.0
    it = 0
    while True:
        if refresh:           # the one place the Jacobian and LU are refreshed (one inlined copy of the assembly call)
            if not _refresh_at(groups, t + h, h, bh2, gh, c_C, c_K, fams, zs, sysd, pat, lu, cache, work, cnt):
                return False, it, np.inf if it == 0 else rate, _SINGULAR
            have_F = True
            refresh = False
        it += 1
        if it > max_iter:
            break
        for i in range(n):
            q1[i] = qp[i] + bh2 * a1[i]
            v1[i] = vp[i] + gh * a1[i]
        if not have_F:
            assemble(groups, t + h, q1, v1, fams, zs, bool(False), sysd, F1, Jq, Jv)   # run-time flag
            cnt[0] += 1
        have_F = False
        for i in range(n):
            if not np.isfinite(F1[i]):
                return False, it, np.inf, _NONFINITE_F
            r[i] = mdiag[i] * a1[i] - (1.0 + alpha) * F1[i] + alpha * f[i]
        da = _lu_solve(int(cache[2]), lu, r, n)
        _scale(atol, rtol, q, q1, sc)
        nrm = 0.0
        for i in range(n):
            a1[i] -= da[i]
            x[i] = abs(bh2 * da[i]) / sc[i]                # scaled corrections
            nrm = max(nrm, x[i])
        if not np.isfinite(nrm):
            return False, it, np.inf, _NONFINITE_DA
        rate_now = rules.newton_rate(nrm, prev) if has_prev else 0.0
        if has_prev:
            rate = rate_now
        if per_component:
            conv = rules.newton_converged_each(x, xp, has_prev, newton_tol)
        else:
            conv = rules.newton_converged(rules.newton_eta(rate_now, has_prev), nrm, newton_tol)
        if conv:
            return True, it, rate, 0
        action = rules.newton_action(it, rate_now, has_prev, refreshes, rate_refresh, max_refresh, max_iter)
        if action == rules.DIVERGED:
            return False, it, rate, _DIVERGED
        if action == rules.OUT_OF_ITERATIONS:
            break
        if action == rules.REFRESH or action == rules.REFRESH_AT_PREVIOUS:
            if action == rules.REFRESH_AT_PREVIOUS:
                for i in range(n):
                    a1[i] += da[i]
            refresh = True    # at the loop's top, before the next iteration (or the end of the iterations)
            refreshes += 1
            has_prev = False
            continue
        prev = nrm
        for i in range(n):
            xp[i] = x[i]
        has_prev = True
    return False, max_iter, rate, _MAX_ITER


@njit(cache=True, inline="always")
def _step(groups, t, q, v, a, f, h, prm, atol, rtol, fams, zs, sysd, pat, lu, cache, work, cnt, out):
    """One HHT step of size h from (t, q, v, a, f) into ``out`` = (q1, v1, a1, f1) without touching the
    start; (converged, iterations, rate, reason, error)."""
    alpha, beta, gamma, errc = prm[0], prm[1], prm[2], prm[3]
    qp, vp, a1, q1, v1, F1, r, sc, x, xp, Jq, Jv, A = work
    n = q.size
    for i in range(n):                        # predictor parts that do not depend on a₁
        qp[i] = q[i] + h * v[i] + h * h * (0.5 - beta) * a[i]
        vp[i] = v[i] + h * (1.0 - gamma) * a[i]
        a1[i] = a[i]
    conv, it, rate, reason = _newton(groups, t, q, v, a, f, h, prm, atol, rtol, fams, zs, sysd, pat, lu, cache, work,
                                     cnt)
    if not conv:
        cache[0] = 0.0
        return False, it, rate, reason, np.nan
    bh2, gh = beta * h * h, gamma * h
    q1o, v1o, a1o, f1o = out
    mdiag = pat[3]
    for i in range(n):
        q1o[i] = qp[i] + bh2 * a1[i]
        v1o[i] = vp[i] + gh * a1[i]
        a1o[i] = a1[i]
        f1o[i] = (mdiag[i] * a1[i] + alpha * f[i]) / (1.0 + alpha)   # F₁ implied by the converged a₁
    _scale(atol, rtol, q, q1o, sc)
    err = np.empty(n)
    for i in range(n):
        err[i] = errc * h * h * (a1[i] - a[i]) / sc[i]
    return True, it, rate, 0, np.sqrt(np.mean(err * err)) if n else 0.0


@njit(cache=True)
def advance(groups, t, q, v, a, f, h, t_end, max_steps, prm, ctrl, atol, rtol, freeze, fams, zs, sysd, pat, lu, cache,
            work, counters, out, log):
    """Steps from (t, q, v, a, f) (updated in place, with zs) until t_end, ``max_steps`` accepted steps or a
    step size below the floor. ``ctrl`` = [kind (0 fixed, 1 adaptive), h_fixed | h_max, reject_error |
    safety, grow_max, shrink_min, fail_factor, hold, h_floor]. ``counters`` (int64): residual, jacobian,
    factor, newton, accepted, rejected. ``log`` (K, 3 + 4n + n_z): per accepted step t₁, h, error, then
    q₁, v₁, a₁, f₁ and the internal states (the observers' states). Returns (t, h, accepted, status, iterations, rate, reason):
    status 0 = t_end reached, 1 = max_steps, 2 = step size below the floor. ``groups``: the system's family
    groups (:func:`.registry.groups_of`), a literal: the loop is compiled once per set of families."""
    literally(groups)
    n = q.size
    span = max(abs(t_end), 1.0)
    cnt = np.zeros(2, np.int64)
    q1, v1, a1, f1 = out
    acc = 0
    it, rate, reason = 0, 0.0, 0
    while t < t_end - 1e-12 * span:
        if acc >= max_steps:
            return t, h, acc, 1, it, rate, reason
        h_try = min(h, t_end - t)
        cnt[0], cnt[1] = 0, 0
        conv, it, rate, reason, error = _step(groups, t, q, v, a, f, h_try, prm, atol, rtol, fams, zs, sysd, pat, lu,
                                              cache, work, cnt, out)
        counters[0] += cnt[0]
        counters[1] += cnt[1]
        counters[2] += cnt[1]
        counters[3] += it
        if ctrl[0] == 0.0:
            ok, h_next = rules.fixed_decide(h_try, conv, error, ctrl[1], ctrl[2])
        else:
            ok, h_next = rules.adaptive_decide(h_try, conv, error, ctrl[1], ctrl[2], ctrl[3], ctrl[4], ctrl[5],
                                               ctrl[6])
        if not ok:
            counters[5] += 1
            if h_next < ctrl[7]:
                return t, h_next, acc, 2, it, rate, reason
            h = h_next
            continue
        counters[4] += 1
        if not freeze:
            update_internal(groups, t, t + h_try, q, v, q1, v1, fams, zs, sysd)
        t = t + h_try
        for i in range(n):
            q[i], v[i], a[i], f[i] = q1[i], v1[i], a1[i], f1[i]
        row = log[acc]
        row[0], row[1], row[2] = t, h_try, error
        for i in range(n):                    # element-wise copies: a slice assignment from an array compiles
            row[3 + i] = q[i]                 # numba's shape-mismatch message (≈ 3 s of the first compile)
            row[3 + n + i] = v[i]
            row[3 + 2 * n + i] = a[i]
            row[3 + 3 * n + i] = f[i]
        off = 3 + 4 * n
        for zi in range(1, len(zs)):          # the element internal states, flattened in slot order
            flat = zs[zi].ravel()
            for i in range(flat.size):
                row[off + i] = flat[i]
            off += flat.size
        acc += 1
        h = h_next
    return t, h, acc, 0, it, rate, reason
