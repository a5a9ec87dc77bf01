"""HHT-α stepper for M a = F(q, v, t), Newton on the accelerations.

Scheme (Hilber–Hughes–Taylor, α ∈ [−1/3, 0]; α = 0 is the trapezoidal rule):
    q₁ = q₀ + h v₀ + h² ((½ − β) a₀ + β a₁)
    v₁ = v₀ + h ((1 − γ) a₀ + γ a₁)
    M a₁ = (1 + α) F(q₁, v₁, t₁) − α F(q₀, v₀, t₀)
with β = (1 − α)²/4 and γ = ½ − α (derived in :func:`hht_coefficients`, nowhere else).
Newton matrix: ∂r/∂a₁ = M + (1+α)(γh·C + βh²·K), C = −∂F/∂v, K = −∂F/∂q.

Jacobian/LU reuse policy (modified Newton, after SciPy's Radau): the LU is kept across steps while
h is unchanged; when Newton contracts too slowly (rate > ``rate_refresh``) the Jacobian is
re-evaluated at the *current iterate* and the iteration continues (contacts that switch within a step
make an old Jacobian stale); a step fails only when Newton diverges on a fresh Jacobian or runs out of
iterations, and the controller then shrinks h. These decisions are :class:`NewtonPolicy`'s (pure, testable
without a model). Each step reports in its :class:`StepInfo` how many residual evaluations, Jacobian
evaluations, factorizations and Newton iterations it used; :func:`mbd.simulate` sums them.
"""
from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np
import scipy.sparse.linalg as spla

from . import rules
from .assembly import System
from .errors import ModelError
from .model import State

__all__ = ["HHT", "StepInfo", "hht_coefficients", "Tolerance", "NewtonCache", "NewtonPolicy", "NewtonAction"]


def hht_coefficients(alpha: float) -> tuple[float, float]:
    """(β, γ) of HHT-α; raises for α outside [−1/3, 0]."""
    if not (-1.0 / 3.0 - 1e-15 <= alpha <= 0.0):
        raise ModelError(f"HHT alpha must lie in [-1/3, 0], got {alpha!r}")
    return (1.0 - alpha) ** 2 / 4.0, 0.5 - alpha


@dataclass(frozen=True)
class Tolerance:
    """Error scale per DOF: atol + rtol·|q|, with separate absolute tolerances for lengths and angles.

    The default is absolute only (rtol = 0): a relative tolerance on *positions* would depend on where
    the origin lies (a roller 85 mm from the axis would get 1000× the tolerance of one at 85 µm), so in
    a multibody model the meaningful scale is an absolute length (10 nm ≈ 1e-3 of a Hertz deflection)."""
    rtol: float = 0.0
    atol_pos: float = 1e-8     # m
    atol_rot: float = 1e-6     # rad

    def __post_init__(self):
        for k in ("atol_pos", "atol_rot"):
            val = getattr(self, k)
            if not (np.isfinite(val) and val > 0):
                raise ModelError(f"Tolerance.{k} must be > 0, got {val!r}")
        if not (np.isfinite(self.rtol) and self.rtol >= 0):
            raise ModelError(f"Tolerance.rtol must be >= 0, got {self.rtol!r}")

    def scale(self, model, q0, q1) -> np.ndarray:
        atol = np.where(model.angle_dofs, self.atol_rot, self.atol_pos)
        if self.rtol == 0.0:
            return atol
        return atol + self.rtol * np.maximum(np.abs(q0), np.abs(q1))


@dataclass
class StepInfo:
    converged: bool
    iterations: int           # Newton iterations (each evaluates the forces once)
    rate: float               # last Newton contraction rate
    error: float = np.nan     # scaled local error estimate (RMS), set by the stepper
    jacobian_refreshed: bool = False
    reason: str = ""
    residuals: int = 0        # force evaluations without Jacobian
    jacobians: int = 0        # force + Jacobian evaluations
    factorizations: int = 0   # LU factorizations (attempted)


class NewtonAction(Enum):
    """What Newton does after an iteration that did not converge."""
    CONTINUE = "continue"                        # iterate again on the same matrix
    REFRESH = "refresh"                          # new Jacobian + LU at the current iterate
    REFRESH_AT_PREVIOUS = "refresh at previous"  # the last correction made it worse: undo it, then refresh
    DIVERGED = "diverged"
    OUT_OF_ITERATIONS = "out of iterations"


@dataclass(frozen=True)
class NewtonPolicy:
    """The modified-Newton rules of one HHT step, as pure functions of plain numbers.

    Convergence (Hairer): η‖Δ‖ ≤ newton_tol with η = θ/(1−θ) from the rate θ observed on one matrix; the
    first iteration on a matrix has no rate (η = ∞) and must be below 1e-2·newton_tol. With
    ``per_component`` (the default) the test holds for every DOF with its own rate
    (:func:`mbd.rules.newton_converged_each`): the rate of the max norm is not the rate of the DOF that is
    slowest to converge. A rate above ``rate_refresh`` (of the max norm) refreshes the Jacobian, at most
    ``max_refresh`` times per step; a rate ≥ 1 after that is divergence."""
    newton_tol: float = 1e-3     # bound on η‖Δq‖ (scaled by the Tolerance); 0.03 left ~k·3e-10 m of force
                                 # error in stiff elements (a 2e-4 bias seen in a mesh test)
    max_iter: int = 10
    rate_refresh: float = 0.3    # contraction rate above which the Jacobian is refreshed
    max_refresh: int = 2         # Jacobian refreshes per step before a rate >= 1 counts as divergence
    reuse: bool = True           # False: fresh Jacobian + LU at the start of every step
    per_component: bool = True   # False: the test on the max norm alone (the former test, kept to compare)

    def __post_init__(self):
        if self.max_iter < 1 or not (0 < self.newton_tol < 1):
            raise ModelError("HHT/Newton: max_iter must be >= 1 and newton_tol in (0, 1)")

    def refactor_at_start(self, have_lu: bool, h_lu: float, h: float) -> bool:
        """A fresh Jacobian + LU before the first iteration: none kept, made for another h, or no reuse."""
        return not have_lu or h_lu != h or not self.reuse

    @staticmethod
    def rate(nrm: float, prev: float) -> float:
        """Contraction rate θ of this correction against the previous one on the same matrix."""
        return float(rules.newton_rate(nrm, prev))

    @staticmethod
    def eta(rate: float | None) -> float:
        """η = θ/(1−θ); ∞ without a rate (first iteration on a matrix) or when θ ≥ 1."""
        return float(rules.newton_eta(0.0 if rate is None else rate, rate is not None))

    def converged(self, eta: float, nrm: float) -> bool:
        return bool(rules.newton_converged(eta, nrm, self.newton_tol))

    def converged_each(self, x: np.ndarray, prev: np.ndarray | None) -> bool:
        """The per-component test on the scaled corrections ``x`` and ``prev`` (None: first on a matrix)."""
        return bool(rules.newton_converged_each(x, x if prev is None else prev, prev is not None, self.newton_tol))

    def after_iteration(self, it: int, rate: float | None, refreshes: int) -> NewtonAction:
        """Next move after unconverged iteration ``it`` (1-based) with contraction ``rate`` (None on the
        first iteration on a matrix) and ``refreshes`` Jacobian refreshes already made in this step."""
        code = rules.newton_action(it, 0.0 if rate is None else rate, rate is not None, refreshes,
                                   self.rate_refresh, self.max_refresh, self.max_iter)
        return _ACTIONS[code]


_ACTIONS = {rules.CONTINUE: NewtonAction.CONTINUE, rules.REFRESH: NewtonAction.REFRESH,
            rules.REFRESH_AT_PREVIOUS: NewtonAction.REFRESH_AT_PREVIOUS, rules.DIVERGED: NewtonAction.DIVERGED,
            rules.OUT_OF_ITERATIONS: NewtonAction.OUT_OF_ITERATIONS}


@dataclass(frozen=True)
class HHT:
    """HHT-α stepper. The Newton settings (defaults and meaning in :class:`NewtonPolicy`) stay flat
    fields so callers write ``HHT(alpha=..., newton_tol=...)``; :attr:`policy` bundles them."""
    alpha: float                 # no default: the production value is mbd.PRODUCTION.alpha
    newton_tol: float = NewtonPolicy.newton_tol
    max_iter: int = NewtonPolicy.max_iter
    rate_refresh: float = NewtonPolicy.rate_refresh
    max_refresh: int = NewtonPolicy.max_refresh
    reuse: bool = NewtonPolicy.reuse
    per_component: bool = NewtonPolicy.per_component
    tol: Tolerance = Tolerance()

    def __post_init__(self):
        hht_coefficients(self.alpha)
        self.policy   # checks the Newton settings

    @property
    def policy(self) -> NewtonPolicy:
        """The Newton reuse/refresh rules from this stepper's settings."""
        return NewtonPolicy(newton_tol=self.newton_tol, max_iter=self.max_iter, rate_refresh=self.rate_refresh,
                            max_refresh=self.max_refresh, reuse=self.reuse, per_component=self.per_component)

    @property
    def beta_gamma(self):
        return hht_coefficients(self.alpha)

    def error_constant(self) -> float:
        """Local displacement error ≈ (β − 1/6) h² (a₁ − a₀)  (Zienkiewicz & Xie)."""
        beta, _ = self.beta_gamma
        return beta - 1.0 / 6.0

    # ------------------------------------------------------------------------------------------
    def initial_state(self, system: System, t0: float, q0, v0, z=None) -> State:
        """The start state with a₀ = M⁻¹F(q₀, v₀) (one residual evaluation; simulate counts it)."""
        q0 = np.asarray(q0, float)
        v0 = np.asarray(v0, float)
        n = system.ndof
        if q0.shape != (n,) or v0.shape != (n,):
            raise ModelError(f"initial q and v must have {n} entries (free DOFs), got {q0.shape}, {v0.shape}")
        for label, x in (("q0", q0), ("v0", v0)):
            bad = np.flatnonzero(~np.isfinite(x))
            if bad.size:   # name the parameter and the first offending body coordinate
                full = int(system.model.free[bad[0]])
                body, _, coord = system.model.coordinate_name(full).rpartition(".")
                coord = {"θ": "theta"}.get(coord, coord)
                raise ModelError(f"initial state: {label} contains NaN or inf at {bad.size} free DOF(s), first "
                                 f"{label}[{bad[0]}] = {x[bad[0]]} ({coord} of body {body!r})")
        z = system.init_internal() if z is None else z
        f = system.forces(t0, q0, v0, z)
        system.check_finite(t0, f, q0, v0, z)
        return State(t0, q0.copy(), v0.copy(), f / system.model.mdiag, f, z)

    def step(self, system: System, s: State, h: float, cache: "NewtonCache") -> tuple[State, StepInfo]:
        """One step of size h from s. Never mutates s. Returns (new state, info)."""
        beta, gamma = self.beta_gamma
        M = system.model.mdiag
        t1 = s.t + h
        qp = s.q + h * s.v + h * h * (0.5 - beta) * s.a   # predictor parts that do not depend on a₁
        vp = s.v + h * (1.0 - gamma) * s.a
        bh2, gh = beta * h * h, gamma * h
        a1 = s.a.copy()
        a1, info = self._newton(system, s, cache, t1, qp, vp, a1, bh2, gh, h, M)
        if not info.converged:
            cache.lu = None
            return s, info
        q1 = qp + bh2 * a1
        v1 = vp + gh * a1
        scale = self.tol.scale(system.model, s.q, q1)
        err = self.error_constant() * h * h * (a1 - s.a) / scale
        info.error = float(np.sqrt(np.mean(err * err))) if err.size else 0.0
        z1 = self._update_internal(system, s, t1, q1, v1)
        # F₁ implied by the converged a₁ (exact for the scheme; equals F(q₁, v₁) to Newton tolerance)
        f1 = (M * a1 + self.alpha * s.f) / (1.0 + self.alpha)
        return State(t1, q1, v1, a1, f1, z1), info

    def _refresh(self, system, cache, t1, q1, v1, z, h, bh2, gh):
        """New Jacobian + LU at (q1, v1) (one Jacobian evaluation, one factorization). Returns the forces
        there (the next Newton iteration is at this very point and reuses them), or None when the Newton
        matrix is not usable."""
        ev = system.evaluate(t1, q1, v1, z, jac=True)
        A = system.newton_matrix(ev, 1.0, (1.0 + self.alpha) * gh, (1.0 + self.alpha) * bh2)
        cache.h = h
        if not np.all(np.isfinite(A.data)):
            cache.lu = None
            return None
        try:
            # diagonal pivots on a symmetric fill-reducing order: A = M + (1+α)(γhC + βh²K) is dominated by
            # its diagonal mass; 2.8x faster than partial pivoting on the DPGT, and the LU only drives Newton
            # (the residual is exact), so it cannot bias a converged step
            cache.lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0)
        except RuntimeError:          # a zero diagonal pivot: fall back to partial pivoting
            try:
                cache.lu = spla.splu(A, permc_spec="COLAMD")
            except RuntimeError:      # exactly singular
                cache.lu = None
                return None
        return ev.F

    def _newton(self, system, s, cache, t1, qp, vp, a1, bh2, gh, h, M):
        """Newton on a₁ under :class:`NewtonPolicy`: the LU is reused while it contracts well; a slow
        iteration refreshes the Jacobian at the current iterate (at the previous one when the last
        correction made it worse) and continues. Returns (a₁, StepInfo with this step's work)."""
        pol, a_ = self.policy, self.alpha
        n_res = n_jac = 0                     # this step's residual and Jacobian (+ LU) evaluations
        fresh, refreshes = False, 0
        rate = 0.0                            # last observed contraction rate (reported)

        def info(converged, it, rate, reason=""):
            return StepInfo(converged, it, rate, jacobian_refreshed=fresh, reason=reason,
                                residuals=n_res, jacobians=n_jac, factorizations=n_jac)

        F_here = None                         # forces at the current iterate, when a refresh computed them
        if pol.refactor_at_start(cache.lu is not None, cache.h, h):
            F_here = self._refresh(system, cache, t1, qp + bh2 * a1, vp + gh * a1, s.z, h, bh2, gh)
            n_jac, fresh = n_jac + 1, True
            if F_here is None:
                return a1, info(False, 0, np.inf, "singular Newton matrix")
        prev = x_prev = None                  # correction of the previous iteration with the same matrix
        for it in range(1, pol.max_iter + 1):
            q1 = qp + bh2 * a1
            v1 = vp + gh * a1
            if F_here is None:
                F1 = system.forces(t1, q1, v1, s.z)
                n_res += 1
            else:
                F1, F_here = F_here, None
            if not np.all(np.isfinite(F1)):
                return a1, info(False, it, np.inf, "non-finite forces")
            r = M * a1 - (1.0 + a_) * F1 + a_ * s.f
            da = cache.lu.solve(r)
            a1 = a1 - da
            x = np.abs(bh2 * da) / self.tol.scale(system.model, s.q, q1)     # scaled corrections
            nrm = float(np.max(x)) if x.size else 0.0
            if not np.isfinite(nrm):
                return a1, info(False, it, np.inf, "non-finite Newton correction")
            rate_now = None if prev is None else pol.rate(nrm, prev)
            rate = rate if rate_now is None else rate_now
            if pol.converged_each(x, x_prev) if pol.per_component else pol.converged(pol.eta(rate_now), nrm):
                return a1, info(True, it, rate)
            action = pol.after_iteration(it, rate_now, refreshes)
            if action is NewtonAction.DIVERGED:
                return a1, info(False, it, rate, "Newton diverged")
            if action is NewtonAction.OUT_OF_ITERATIONS:
                break
            if action in (NewtonAction.REFRESH, NewtonAction.REFRESH_AT_PREVIOUS):
                if action is NewtonAction.REFRESH_AT_PREVIOUS:
                    a1 = a1 + da
                F_here = self._refresh(system, cache, t1, qp + bh2 * a1, vp + gh * a1, s.z, h, bh2, gh)
                n_jac, fresh = n_jac + 1, True
                if F_here is None:
                    return a1, info(False, it, rate, "singular Newton matrix")
                refreshes += 1
                prev = x_prev = None
                continue
            prev, x_prev = nrm, x
        return a1, info(False, pol.max_iter, rate, "Newton did not converge in max_iter")

    def _update_internal(self, system, s, t1, q1, v1):
        if not s.z or system.freeze_internal:
            return s.z
        m = system.model
        fs0, fs1 = m.frame.at(s.t), m.frame.at(t1)
        q0f, v0f = m.full(s.t, s.q, s.v)
        q1f, v1f = m.full(t1, q1, v1)
        z1 = dict(s.z)
        for e in m.elements:
            if e.name in s.z:
                d = e.dofs
                z1[e.name] = e.update_internal(s.z[e.name], s.t, t1, fs0, fs1, list(q0f[d].T),
                                               list(v0f[d].T), list(q1f[d].T), list(v1f[d].T))
        return z1


@dataclass
class NewtonCache:
    lu: object = None
    h: float = np.nan

