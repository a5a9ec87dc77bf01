"""The same Model as a first-order system y = (q, v) for scipy.integrate.solve_ivp.

ẏ = (v, M⁻¹ F(q, v, t)) with the sparse Jacobian [[0, I], [M⁻¹ ∂F/∂q, M⁻¹ ∂F/∂v]], so Radau, BDF
and LSODA use the same physics and the same analytic element Jacobians as HHT — evaluated by the
same engine path (``engine``: the compiled one wherever it can be built, as :func:`mbd.simulate`).
Element internal states (a PI drive's integral) are held at their initial value here: compare scenes
without them.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.integrate import solve_ivp

from .assembly import System
from .model import Model

__all__ = ["FirstOrderSystem", "solve_scipy", "ScipyResult"]

IMPLICIT = ("Radau", "BDF", "LSODA")


class FirstOrderSystem:
    def __init__(self, model: Model, z=None, engine: str = "auto"):
        self.model = model
        self.system = System(model)
        self.z = self.system.init_internal() if z is None else z
        self.evaluator, self.engine = self.system, "numpy"
        if engine != "numpy":
            try:
                from .compiled.system import CompiledSystem  # deferred: numba kernels, optional (numpy falls back)
                self.evaluator, self.engine = CompiledSystem(self.system), "compiled"
                self.evaluator.set_internal(self.z)
            except (ImportError, NotImplementedError):
                if engine == "compiled":
                    raise
        self.n = model.ndof
        self.minv = 1.0 / model.mdiag
        n = self.n
        self._I = sp.identity(n, format="csr")
        self.nfev = 0
        self.njev = 0

    def fun(self, t, y):
        self.nfev += 1
        q, v = y[: self.n], y[self.n:]
        F = self.evaluator.evaluate(t, q, v, self.z).F
        return np.concatenate([v, self.minv * F])

    def jac(self, t, y):
        self.njev += 1
        q, v = y[: self.n], y[self.n:]
        ev = self.evaluator.evaluate(t, q, v, self.z, jac=True)
        _, C, K = self.system.matrices(ev)
        Minv = sp.diags(self.minv)
        top = sp.hstack([sp.csr_matrix((self.n, self.n)), self._I])
        bot = sp.hstack([Minv @ (-K), Minv @ (-C)])
        return sp.vstack([top, bot], format="csc")

    def sparsity(self):
        """Structural pattern of the Jacobian (for finite-difference grouping, ``jac_sparsity``).

        Built from the assembler's fixed pattern, not from Jacobian values: entries that happen to
        be zero at one state (sparse products drop them) are still structurally nonzero."""
        s, n = self.system, self.n
        ones = sp.csc_matrix((np.ones(s.nnz), s._indices, s._indptr), shape=(n, n))
        P = sp.vstack([sp.hstack([sp.csr_matrix((n, n)), self._I]), sp.hstack([ones, ones])], format="csc")
        P.data[:] = 1.0
        return P


@dataclass
class ScipyResult:
    t: np.ndarray
    y: np.ndarray
    success: bool
    message: str
    wall_s: float
    nfev: int
    njev: int
    nlu: int
    engine: str = "numpy"      # the engine path that evaluated the residual and Jacobian


def solve_scipy(model: Model, q0, v0, t_span, method="Radau", rtol=1e-6, atol=1e-9, t_eval=None,
                max_wall_s: float | None = None, z=None, engine: str = "auto", **kw) -> ScipyResult:
    """Integrate with solve_ivp. ``max_wall_s`` stops a run that takes too long (reported, not hidden);
    ``engine`` evaluates the residual and Jacobian (as :func:`mbd.simulate`)."""
    fo = FirstOrderSystem(model, z, engine)
    y0 = np.concatenate([np.asarray(q0, float), np.asarray(v0, float)])
    start = time.perf_counter()
    def capped(t, y):
        if time.perf_counter() - start > max_wall_s:
            raise TimeoutError(f"{method} exceeded {max_wall_s:.0f} s wall time at t = {t:.6e} s")
        return fo.fun(t, y)

    fun = fo.fun if max_wall_s is None else capped
    opts = dict(method=method, rtol=rtol, atol=atol, t_eval=t_eval, **kw)
    if method == "LSODA":   # LSODA's Fortran core takes only a dense (or banded) Jacobian
        opts["jac"] = lambda t, y: fo.jac(t, y).toarray()
    elif method in IMPLICIT:
        opts["jac"] = fo.jac
    try:
        sol = solve_ivp(fun, t_span, y0, **opts)
        ok, msg, t, y, nlu = sol.success, sol.message, sol.t, sol.y, getattr(sol, "nlu", 0)
    except TimeoutError as exc:
        ok, msg, t, y, nlu = False, str(exc), np.array([]), np.zeros((y0.size, 0)), 0
    return ScipyResult(t, y, ok, msg, time.perf_counter() - start, fo.nfev, fo.njev, nlu, fo.engine)
