"""Compiled (numba) engine path. The plain numpy path (:mod:`mbd.element`, :mod:`mbd.assembly`,
:mod:`mbd.hht`) stays the reference: tests hold the two together to round-off.

Kernel convention (one module per group of element families; every function ``@njit(cache=True)``):

``pack(elem) -> (P, G)``
    Python side, once at assembly: the family's per-instance parameters as one C-contiguous float64
    array P of shape (n, n_p) (column order documented in the module) and its family-wide values as
    a float64 array G (law ids, law coefficients). Raises :class:`NotImplementedError` naming the
    family when it uses something the compiled path cannot do (e.g. a Python callable of time).

``evaluate(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)``
    t the time; (phi, omega, domega) the reference frame's angle, speed and acceleration; ql, vl the
    (n, k) local coordinates (x, y, θ per body, in R); z the (n, n_z) internal state (a (n, 0) array
    when the family has none); writes the generalized forces F (n, k) and, when ``jac``, J_q = ∂F/∂q
    and J_v = ∂F/∂v (n, k, k) — the same quantities as :func:`mbd.element.evaluate`.

``update(z, t0, t1, ql0, vl0, ql1, vl1, P, G) -> z1`` (families with internal state only)
    the internal state after an accepted step, as ``Element.update_internal``.
"""
