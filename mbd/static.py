"""Quasi-static steady state of a model in its reference frame R.

The dynamic equations M a = F(q, v, t) (frame terms included) with the transient left out: every body
moves rigidly and steadily in R — it spins at a constant rate and its centre either rests or orbits a
fixed point of R at a constant rate (a roller about its pin in the carrier frame). At one instant t the
nominal (kinematic) poses are known; the solution is the small displacement δq from them at which the
forces balance the steady motion's inertia:

    r(q) = F(q, v(q), t) − M a(q) = 0,   v, a: the steady motion at the displaced pose q,

on the free DOFs that are not *held*. A held DOF keeps its kinematic value and its equation is dropped:
its force residual is the reaction a prescribed motion needs (a speed drive's torque; a roller's or a
cage's spin, which nothing in a static balance fixes). Newton on the exact Jacobian
∂r/∂q = J_q + J_v ∂v/∂q − M ∂a/∂q (the element families' own), from the kinematic pose with the load
brought in by a Newton homotopy r(q) − (1 − λ) r(q_start), λ: 0 → 1 in steps that halve on failure.
Directions that no force holds (a roller floating in its clearance) carry a vanishing residual; a small
mass-proportional shift of the Newton matrix keeps their LU regular, and a backtracking line search on
the scaled residual keeps a contact's opening and closing from throwing Newton about.

It solves the same model as :func:`mbd.simulate`, not another one: its solution is the dynamic run's mean
where the dynamics do not rectify (the tests compare both on the same scenes).
"""
from __future__ import annotations

import os
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .assembly import System
from .errors import ModelError
from .model import Model

_TRACE = bool(os.environ.get("MBD_STATIC_TRACE"))
_ACCEPT = float(os.environ.get("MBD_ACCEPT", "2.0"))
_LAST_FAILURE = None

__all__ = ["SteadyMotion", "StaticSolution", "directions", "solve_static"]


@dataclass(frozen=True)
class SteadyMotion:
    """Every body's steady rigid motion in R, from a pose and velocity at ``t0`` (full vectors, in R).

    ``orbit`` (n_bodies,): the rate [rad/s] in R at which a body's centre circles a point of R (0: the
    centre rests in R). The circle's centre follows from the velocity: v = ω k × (x − c). ``host`` (n_bodies,):
    the body (index, −1: none) whose displacement the circle's centre shares — a roller circles its cage's
    centre, wherever the cage sits (a host rests in R). Spin rates are the angular velocities' θ entries."""
    t0: float
    q0: np.ndarray      # (nb, 3) poses in R at t0
    spin: np.ndarray    # (nb,) angular rate in R [rad/s]
    orbit: np.ndarray   # (nb,) orbital rate in R [rad/s]
    centre: np.ndarray  # (nb, 2) orbit centre in R [m] with its host at its kinematic pose
    host: np.ndarray    # (nb,) host body index or −1

    @staticmethod
    def from_state(model: Model, q0: np.ndarray, v0: np.ndarray, orbit, t0: float = 0.0, host=None,
                   rest_tol: float = 1e-9) -> "SteadyMotion":
        """``q0``, ``v0``: the free DOFs in R at ``t0`` (a built scene's kinematic initial state); ``orbit``:
        the bodies' orbital rates in R (n_bodies,). A body declared resting must not move in R (its speed
        below ``rest_tol`` [m/s]); otherwise its steady motion is unknown here and it is refused."""
        qf, vf = model.full(t0, q0, v0)
        P, V = qf.reshape(-1, 3), vf.reshape(-1, 3)
        w = np.asarray(orbit, float)
        if w.shape != (model.n_bodies,) or not np.all(np.isfinite(w)):
            raise ModelError(f"orbit: one finite rate [rad/s] per body ({model.n_bodies}) expected, got shape {w.shape}")
        centre = P[:, :2].copy()
        moving = np.flatnonzero((w != 0.0) & ~model.fixed)
        # v = ω k × (x − c)  ⇒  x − c = (v_y, −v_x)/ω
        centre[moving, 0] -= V[moving, 1] / w[moving]
        centre[moving, 1] += V[moving, 0] / w[moving]
        still = (w == 0.0) & ~model.fixed & (np.hypot(V[:, 0], V[:, 1]) > rest_tol)
        if still.any():
            i = int(np.flatnonzero(still)[0])
            raise ModelError(f"steady motion: body {model.body_names[i]!r} moves in the reference frame "
                             f"({np.hypot(*V[i, :2]):.3g} m/s) but no orbit rate was given for it; a static solution "
                             "needs every body's centre at rest in R or circling a point of R")
        spin = np.where(model.fixed, 0.0, V[:, 2])
        host = np.full(model.n_bodies, -1, np.int64) if host is None else np.asarray(host, np.int64)
        hosted = np.flatnonzero(host >= 0)
        if host.shape != (model.n_bodies,) or np.any(w[host[hosted]] != 0.0) or np.any(model.fixed[host[hosted]]):
            raise ModelError("steady motion: host must give one body index (or -1) per body, each host a free body "
                             "whose centre rests in R")
        return SteadyMotion(float(t0), P.copy(), spin, np.where(model.fixed, 0.0, w), centre, host)

    def at(self, model: Model, t: float, q_free: np.ndarray | None = None):
        """(q, v, a) on the free DOFs at time t: the kinematic pose, or — given ``q_free`` — the steady
        velocity and acceleration at that (displaced) pose: v = ω k × (x − c), a = −ω² (x − c)."""
        dt = t - self.t0
        P = self.q0.copy()
        c, s = np.cos(self.orbit * dt), np.sin(self.orbit * dt)
        r = P[:, :2] - self.centre
        P[:, 0] = self.centre[:, 0] + c * r[:, 0] - s * r[:, 1]
        P[:, 1] = self.centre[:, 1] + s * r[:, 0] + c * r[:, 1]
        P[:, 2] += self.spin * dt
        q = P.ravel()[model.free] if q_free is None else np.asarray(q_free, float)
        X = np.zeros((model.n_bodies, 3))
        X.ravel()[model.free] = q
        r = X[:, :2] - self.centre
        hosted = np.flatnonzero(self.host >= 0)
        h = self.host[hosted]
        r[hosted] -= X[h, :2] - self.q0[h, :2]        # the centre moves with its host
        V = np.column_stack([-self.orbit * r[:, 1], self.orbit * r[:, 0], self.spin])
        A = np.column_stack([-self.orbit ** 2 * r[:, 0], -self.orbit ** 2 * r[:, 1], np.zeros(model.n_bodies)])
        return q, V.ravel()[model.free], A.ravel()[model.free]


@dataclass
class StaticSolution:
    """One static state: ``q``, ``v``, ``a`` on the free DOFs at time ``t`` (v and a: the steady motion at q),
    ``z`` the element internal states used, ``residual`` r(q) with the held DOFs' reactions in it,
    Newton ``iterations`` (all load steps) and ``wall_s``."""
    t: float
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    z: dict
    residual: np.ndarray
    iterations: int
    load_steps: int
    wall_s: float


class _Problem:
    """The unknowns x = (δ, u): displacements δ along the solved directions B (n, m) from ``q_ref``, and spin-rate
    changes u of the DOFs ``spin`` (their angle held, their rate set by velocity-dependent forces: a roller
    spins where its raceway tractions balance). g(x) = (Bᵀ r, r[spin]) and its Jacobian."""

    SPIN_TIME = float(os.environ.get('MBD_SPIN_TIME', '1e-6'))     # [s]: the pseudo-mass of a spin rate, J·SPIN_TIME, in the continuation's metric

    def __init__(self, system: System, evaluator, motion: SteadyMotion, t: float, basis: sp.csc_matrix,
                 spin: np.ndarray, q_ref: np.ndarray, z: dict):
        m = system.model
        self.system, self.evaluate, self.motion, self.t, self.B, self.z = system, evaluator, motion, t, basis, z
        self.model, self.spin, self.q_ref = m, np.asarray(spin, np.int64), q_ref
        self.mdiag = m.mdiag
        self.Bt = basis.T.tocsr()
        self.nB = basis.shape[1]
        # ∂v/∂q and ∂a/∂q of the orbiting bodies: (x, y) blocks ω [[0, −1], [1, 0]] and −ω² I on the body's own
        # coordinates, the opposite on its host's
        f2f = m.full_to_free
        w = motion.orbit
        bodies = np.flatnonzero((w != 0.0) & ~m.fixed)
        ix, iy = f2f[3 * bodies], f2f[3 * bodies + 1]
        wb = w[bodies]
        rows, cols, dv, da = [iy, ix, ix, iy], [ix, iy, ix, iy], [wb, -wb, -wb ** 2, -wb ** 2], None
        hb = motion.host[bodies]
        sel = hb >= 0
        hx, hy = f2f[3 * hb[sel]], f2f[3 * hb[sel] + 1]
        rows += [iy[sel], ix[sel], ix[sel], iy[sel]]
        cols += [hx, hy, hx, hy]
        dv += [-wb[sel], wb[sel], wb[sel] ** 2, wb[sel] ** 2]
        n = m.ndof
        R, C, D = np.concatenate(rows), np.concatenate(cols), np.concatenate(dv)
        is_v = np.concatenate([np.ones(2 * bodies.size, bool), np.zeros(2 * bodies.size, bool),
                               np.ones(2 * sel.sum(), bool), np.zeros(2 * sel.sum(), bool)])
        self.dv = sp.csc_matrix((D[is_v], (R[is_v], C[is_v])), shape=(n, n))
        self.da = sp.csc_matrix((D[~is_v], (R[~is_v], C[~is_v])), shape=(n, n))
        M_B = np.asarray((self.Bt @ sp.diags(m.mdiag) @ basis).diagonal())    # mass along each direction
        self.M = np.concatenate([M_B, m.mdiag[self.spin] * self.SPIN_TIME])

    def label(self, i: int) -> str:
        """A readable name of unknown i (for traces and errors): its body and direction."""
        m = self.model
        if i >= self.nB:
            return m.body_names[int(m.free[self.spin[i - self.nB]]) // 3] + ".spin_rate"
        rows = self.B[:, i].nonzero()[0]
        dof = int(m.free[rows[0]])
        kind = "xyθ"[dof % 3] if rows.size == 1 else ("radial" if rows.size == 2 else "xy"[dof % 3] + " (carrying)")
        return f"{m.body_names[dof // 3]}.{kind}"

    def state(self, x: np.ndarray):
        """(q, v, a) on the free DOFs at the unknowns x."""
        q = self.q_ref + self.B @ x[: self.nB]
        _, v, a = self.motion.at(self.model, self.t, q)
        v[self.spin] += x[self.nB:]
        return q, v, a

    def full_residual(self, x: np.ndarray, jac: bool = False):
        """r on every free DOF and, with ``jac``, (∂r/∂q, ∂r/∂v) (CSC)."""
        q, v, a = self.state(x)
        ev = self.evaluate(self.t, q, v, self.z, jac)
        r = ev.F - self.mdiag * a
        if not jac:
            return r, None
        sysm = self.system
        Jq, Jv = sysm._csc(ev.Jq), sysm._csc(ev.Jv)
        return r, ((Jq + Jv @ self.dv - sp.diags(self.mdiag) @ self.da).tocsc(), Jv)

    def residual(self, x: np.ndarray, jac: bool = False):
        """g(x) and, with ``jac``, K = −∂g/∂x (CSC)."""
        r, J = self.full_residual(x, jac)
        g = np.concatenate([self.Bt @ r, r[self.spin]])
        if not jac:
            return g, None
        Jq, Jv = J
        S = self.spin
        top = sp.hstack([self.Bt @ Jq @ self.B, self.Bt @ Jv[:, S]])
        bottom = sp.hstack([Jq[S, :] @ self.B, Jv[S][:, S]])
        return g, (-sp.vstack([top, bottom])).tocsc()


def _evaluator(system: System, engine: str):
    """F(t, q, v, z, jac): the compiled twin of ``system`` when it can (``engine`` "auto"), else numpy."""
    if engine not in ("auto", "compiled", "numpy"):
        raise ModelError(f"engine must be 'auto', 'compiled' or 'numpy', got {engine!r}")
    if engine == "numpy":
        return system.evaluate
    try:
        from .compiled.system import CompiledSystem
        cs = CompiledSystem(system)
    except (ImportError, NotImplementedError) as exc:
        if engine == "compiled":
            raise ModelError(f"solve_static: the compiled path cannot evaluate this model: {exc}") from None
        return system.evaluate
    return lambda t, q, v, z, jac: cs.evaluate(t, q, v, z, jac)


def directions(model: Model, motion: SteadyMotion, t: float, hold=(), hold_tangential: bool = True):
    """The solved directions at time t, (n_free, m) sparse: a unit column per free DOF not in ``hold``; an
    orbiting body's x and y replaced by one radial direction about its orbit centre when ``hold_tangential``
    (its place on the circle is then held like its spin: a roller in its pocket), last, in body order.
    Returns (B, the bodies of those radial columns)."""
    n, f2f = model.ndof, model.full_to_free
    keep = np.ones(n, bool)
    keep[np.asarray(hold, dtype=np.int64)] = False
    orbiting = np.flatnonzero((motion.orbit != 0.0) & ~model.fixed) if hold_tangential else np.zeros(0, int)
    keep[f2f[3 * orbiting]] = keep[f2f[3 * orbiting + 1]] = False
    solved = np.flatnonzero(keep)
    rows, cols, vals = [solved], [np.arange(solved.size)], [np.ones(solved.size)]
    q = motion.at(model, t)[0]
    X = np.zeros((model.n_bodies, 3))
    X.ravel()[model.free] = q
    d = X[orbiting, :2] - motion.centre[orbiting]
    d /= np.hypot(d[:, 0], d[:, 1])[:, None]
    radial = solved.size + np.arange(orbiting.size)
    rows += [f2f[3 * orbiting], f2f[3 * orbiting + 1]]
    cols += [radial, radial]
    vals += [d[:, 0], d[:, 1]]
    # a hosted body's place on its circle is held relative to its host: the host's x and y carry it along
    col_of = -np.ones(n, np.int64)
    col_of[solved] = np.arange(solved.size)
    hosted = orbiting[motion.host[orbiting] >= 0]
    for j in (0, 1):
        hc = col_of[f2f[3 * motion.host[hosted] + j]]
        ok = hc >= 0
        rows.append(f2f[3 * hosted[ok] + j])
        cols.append(hc[ok])
        vals.append(np.ones(int(ok.sum())))
    m = solved.size + orbiting.size
    return sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, m)), orbiting


def solve_static(model: Model, motion: SteadyMotion, t: float, *, hold=(), hold_tangential: bool = True,
                 spin=(), q_start: np.ndarray | None = None, z: dict | None = None, system: System | None = None,
                 engine: str = "auto", evaluator=None, length_tol: float = 1e-11, spin_tol: float = 1e-6,
                 max_iter: int = 300, max_step: float = 2e-5, max_spin_step: float = 1e3,
                 regularization: float = 1e-12) -> StaticSolution:
    """The static state at time ``t`` (see the module docstring).

    ``hold``: free-DOF indices kept at their kinematic values (their equations dropped); ``hold_tangential``:
    orbiting bodies solved along their radius only (:func:`directions`). ``spin``: held angle DOFs whose
    *rate* is solved instead, from their own equation (a roller's spin, where its tractions balance).
    ``q_start``: the pose to start from (default: the kinematic pose at t; give the previous instant's
    solution to continue along a sequence). ``z``: element internal states (default: their initial values).
    Converged when every solved direction's residual would move it less than ``length_tol`` [m] under its own
    stiffness (angles at their body's radius of gyration), every spin rate less than ``spin_tol`` [rad/s].
    ``max_step`` [m], ``max_spin_step`` [rad/s]: the largest change of one unknown in one step. Raises
    ModelError in one line when it does not converge (naming the worst unknown's body)."""
    t0 = time.perf_counter()
    system = system if system is not None else System(model)
    evaluate = evaluator if evaluator is not None else _evaluator(system, engine)
    z = system.init_internal() if z is None else z
    spin = np.asarray(spin, dtype=np.int64)
    B, radial = directions(model, motion, t, np.concatenate([np.asarray(hold, np.int64), spin]), hold_tangential)
    q_kin = motion.at(model, t)[0]
    prob = _Problem(system, evaluate, motion, t, B, spin, q_kin, z)
    x = np.zeros(B.shape[1] + spin.size)
    if q_start is not None:     # the start's displacement along the solved directions only
        x[: B.shape[1]] = B.T @ (np.asarray(q_start, float) - q_kin)
    # each unknown's scale: 1 for a translation, the body's radius of gyration for an angle; spin rates their own
    body = model.free // 3
    gyr = np.where(model.angle_dofs, np.sqrt(model.inertia[body] / model.mass[body]), 1.0)
    rho = np.asarray(abs(B).T @ gyr).ravel() / np.asarray(abs(B).sum(axis=0)).ravel()
    tol = np.concatenate([length_tol / rho, np.full(spin.size, spin_tol)])
    cap = np.concatenate([max_step / rho, np.full(spin.size, max_spin_step)])
    # local unknowns, solved body by body inside each step: an orbiting body's radius and, if solved, its spin rate
    nB = B.shape[1]
    loc_r = nB - radial.size + np.arange(radial.size)
    spin_body = model.free[spin] // 3
    pos = {int(b): i for i, b in enumerate(spin_body)}
    loc_u = np.array([nB + pos[int(b)] if int(b) in pos else -1 for b in radial], np.int64)
    x, iters, ok = _ptc(prob, x, tol, cap, max_iter, regularization, loc_r, loc_u)
    if not ok:
        global _LAST_FAILURE
        _LAST_FAILURE = (prob, x, loc_r, loc_u)      # for a post-mortem (tests and traces)
        g, K = prob.residual(x, jac=True)
        worst = int(np.argmax(np.abs(g) / (np.abs(K.diagonal()) + prob.M) / tol))
        dof = int(B[:, worst].nonzero()[0][0]) if worst < B.shape[1] else int(spin[worst - B.shape[1]])
        raise ModelError(f"solve_static: no static state found at t = {t:.6g} s in {max_iter} steps (worst: body "
                         f"{model.body_names[int(model.free[dof]) // 3]!r}): a body without support, or a load no "
                         "contact can carry?")
    r = prob.full_residual(x)[0]
    q, v, a = prob.state(x)
    return StaticSolution(float(t), q, v, a, z, r, iters, 1, time.perf_counter() - t0)


def _bracketed(x, dx, g, lo, hi, cap):
    """One safeguarded step per unknown of a decreasing scalar function: the Newton step ``dx`` clipped to
    ``cap``, or — when it leaves the bracket (lo, hi) that the residual's sign keeps — the bracket's midpoint;
    without a bracket on the side the residual points to, a full ``cap`` that way."""
    lo = np.where(g > 0, np.maximum(lo, x), lo)
    hi = np.where(g < 0, np.minimum(hi, x), hi)
    step = np.where(np.isfinite(dx), np.clip(dx, -cap, cap), np.sign(g) * cap)
    new = x + step
    bad = ~((new > lo) & (new < hi))
    both = np.isfinite(lo) & np.isfinite(hi)
    new = np.where(bad & both, 0.5 * (lo + hi), new)
    new = np.where(bad & ~both, x + np.sign(g) * cap, new)
    return new, lo, hi


def _local_solve(prob: _Problem, x: np.ndarray, lr: np.ndarray, lu: np.ndarray, tol: np.ndarray, cap: np.ndarray,
                 max_iter: int = 80):
    """Solve every local group — (radius, spin rate) of one body, coupled to other groups only through the
    outer unknowns — for fixed outer unknowns, all groups at once: 2×2 Newton per group on derivatives taken
    by one perturbation of all radii and one of all spin rates (groups do not couple, so each group's change
    is its own), each unknown kept inside a bracket from its residual's sign (the radial force falls as the
    radius grows — the outer contact closes, the inner one opens; the traction moment falls as the spin
    rate grows), every step clipped to its cap. Returns (x, g at x, converged)."""
    x = x.copy()
    has_u = lu >= 0
    u = lu[has_u]
    lo_r, hi_r = np.full(lr.size, -np.inf), np.full(lr.size, np.inf)
    lo_u, hi_u = np.full(u.size, -np.inf), np.full(u.size, np.inf)
    g = prob.residual(x)[0]
    for _ in range(max_iter):
        gr, gu = g[lr], g[u]
        if np.all(np.abs(gr) <= prob.floor[lr]) and np.all(np.abs(gu) <= prob.floor[u]):
            return x, g, True
        hr = 1e-3 * cap[lr]
        xp = x.copy()
        xp[lr] += hr
        gp = prob.residual(xp)[0]
        krr = -(gp[lr] - gr) / hr                      # −∂g_r/∂r
        kur = np.zeros(lr.size)
        kur[has_u] = -(gp[u] - gu) / hr[has_u]         # −∂g_u/∂r
        kru, kuu = np.zeros(lr.size), np.ones(lr.size)
        gu_all = np.zeros(lr.size)
        gu_all[has_u] = gu
        if u.size:
            hu = 1e-3 * cap[u]
            xp = x.copy()
            xp[u] += hu
            gp = prob.residual(xp)[0]
            kru[has_u] = -(gp[lr[has_u]] - gr[has_u]) / hu
            kuu[has_u] = -(gp[u] - gu) / hu
        det = krr * kuu - kru * kur
        ok = (det > 0) & (krr > 0) & (kuu > 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            dr = np.where(ok, (kuu * gr - kru * gu_all) / det, np.where(krr > 0, gr / krr, np.nan))
            du = np.where(ok, (krr * gu_all - kur * gr) / det, np.where(kuu > 0, gu_all / kuu, np.nan))
        x[lr], lo_r, hi_r = _bracketed(x[lr], dr, gr, lo_r, hi_r, cap[lr])
        if u.size:
            x[u], lo_u, hi_u = _bracketed(x[u], du[has_u], gu, lo_u, hi_u, cap[u])
        g = prob.residual(x)[0]
    return x, g, False


def _ptc(prob: _Problem, x: np.ndarray, tol: np.ndarray, cap: np.ndarray, max_iter: int, regularization: float,
         lr: np.ndarray, lu: np.ndarray):
    """Pseudo-transient continuation on the outer unknowns with the local ones eliminated (:func:`_local_solve`
    after every step, so the outer problem sees each body's contacts settled): implicit Euler steps of the
    overdamped flow M x' = g, (K_c + μM) Δ = g_c with K_c the Schur complement of the local blocks and
    μ = 1/Δτ. μ starts where no unknown moves more than its ``cap`` and follows the residual, μ ← μ·|g_new|/|g|
    (halved again while it falls; |g|² = Σ g²/M over the outer unknowns), down to ``regularization``·max K/M —
    the last steps are Newton's. A step that more than doubles |g| is retried with a tenfold μ; every step is
    clipped per unknown to its ``cap``. Converged when every unknown's residual would move it less than its
    tolerance under its own stiffness, |g_i| ≤ (|K_ii| + μ_min M_i)·tol_i. Returns (x, steps, converged)."""
    M = prob.M
    n = M.size
    loc = np.concatenate([lr, lu[lu >= 0]])
    outer = np.setdiff1d(np.arange(n), loc)
    Mo = M[outer]
    norm = lambda y: float(np.sqrt(np.sum(y[outer] ** 2 / Mo)))
    g, K = prob.residual(x, jac=True)
    mu_min = regularization * float(np.max(np.abs(K.diagonal()) / M))
    prob.floor = (np.abs(K.diagonal()) + mu_min * M) * tol
    x, g, _ = _local_solve(prob, x, lr, lu, tol, cap)
    g, K = prob.residual(x, jac=True)
    mu = max(float(np.max(np.abs(g[outer]) / (Mo * cap[outer]))), mu_min)
    steps = 0
    for k in range(max_iter + 1):
        prob.floor = (np.abs(K.diagonal()) + mu_min * M) * tol
        if np.all(np.abs(g) <= prob.floor):
            return x, k, True
        if k == max_iter:
            break
        # Schur complement of the local blocks (block diagonal: no two local groups share an element)
        Koo, Kol, Klo, Kll = K[outer][:, outer], K[outer][:, loc], K[loc][:, outer], K[loc][:, loc].tocsc()
        try:
            lu_ll = spla.splu(Kll + sp.diags(mu_min * M[loc]))
            X = lu_ll.solve(Klo.toarray())
            y = lu_ll.solve(g[loc])
            Kc = Koo.toarray() - Kol @ X
            gc = g[outer] - Kol @ y
            d = np.linalg.solve(Kc + np.diag(mu * Mo), gc)
        except (RuntimeError, np.linalg.LinAlgError):
            return x, k, False
        if not np.all(np.isfinite(d)):
            return x, k, False
        d = np.clip(d, -cap[outer], cap[outer])
        x_new = x.copy()
        x_new[outer] += d
        x_new[loc] += np.clip(y - X @ d, -cap[loc], cap[loc])          # the locals' linear prediction
        x_new, g_new, _ = _local_solve(prob, x_new, lr, lu, tol, cap)
        ratio = norm(g_new) / max(norm(g), 1e-300) if np.all(np.isfinite(g_new)) else np.inf
        if _TRACE:
            c = np.abs(g) / prob.floor
            top = outer[np.argsort(-np.abs(g[outer]) / np.sqrt(Mo))[:3]]
            print(f"{k} mu {mu:.2e} |g| {norm(g):.3e} -> {norm(g_new):.3e} clipped {np.mean(np.abs(d) >= cap[outer]):.2f} "
                  f"worst {c.max():.1e} at {prob.label(int(np.argmax(c)))}; largest g: "
                  + ", ".join(f"{prob.label(int(i))} {g[i]:.3g}" for i in top))
        if ratio > _ACCEPT:
            mu = max(10.0 * mu, mu_min * 10.0)
            continue
        x = x_new
        g, K = prob.residual(x, jac=True)
        mu = max(mu * (0.5 * ratio if ratio <= 1.0 else ratio), mu_min)
    return x, max_iter, False
