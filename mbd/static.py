"""Quasi-static steady state of a model in its reference frame R.

The dynamic equations M a = F(q, v, t) (frame terms included) with the transient left out. Every body moves
rigidly and steadily in R: it spins at a constant rate, and its centre rests or circles a point of R at a
constant rate (a roller about its pin in the carrier frame; the point may move with a *host* body: a roller
circles its cage's centre wherever the cage sits). At an instant t the steady motion gives every pose; the
static state is the displacement from it, and the change of some spin rates, at which

    r(q, u) = F(q, v(q, u), t) − M a(q, u) = 0,   v, a: the steady motion at the displaced pose q,

on the unknowns:

* **displacements** of every free DOF that is not held, except that an orbiting body moves along its radius
  and along its circle (about its orbit centre; a hosted body also with its host);
* **spin rates** u of the bodies named in ``spin``: their angle keeps its steady value and their rate is
  solved from their own equation — a roller spins where its raceway tractions balance, a cage turns where
  its pockets and land balance (its slip); a host's rate also turns the orbits of the bodies it hosts.

A *held* DOF keeps its steady value and its equation is dropped: its residual is the reaction the prescribed
motion needs (a speed drive's torque). The Jacobian is exact: ∂r/∂q = J_q + J_v ∂v/∂q − M ∂a/∂q with the
element families' own J_q, J_v.

The solver (:func:`solve_static`): the orbiting bodies' unknowns are *local* — no element joins two of them —
so they are solved body by body inside every step (:func:`_local_solve`: small Newton systems with
brackets, all bodies at once), and the rest by pseudo-transient continuation on the Schur complement
(:func:`_ptc`), which walks bodies across their clearances and ends in Newton's quadratic convergence. Where
that stalls on a direction without stiffness — gears floating in their backlash under the drag torques at idle — a
last pass walks those free modes to their contacts (:func:`_walk_free_modes`).

It solves the same model as :func:`mbd.simulate`, not another one: where the dynamics do not rectify, its
solution is the dynamic run's mean (the tests compare both on the same scenes).
"""
from __future__ import annotations

import os
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from threadpoolctl import threadpool_limits

from .assembly import System
from .errors import ModelError
from .model import TILT, Model

__all__ = ["SteadyMotion", "StaticSolution", "carry", "solve_static"]

_TRACE = bool(os.environ.get("MBD_STATIC_TRACE"))     # MBD_STATIC_TRACE=1: a line per continuation step (stdout)


@dataclass(frozen=True)
class SteadyMotion:
    """Every body's steady rigid motion in R, from a pose and velocity at ``t0``.

    ``orbit`` (n_bodies,): the rate [rad/s] in R at which a body's centre circles a point of R (0: the centre
    rests in R); the circle's centre follows from the velocity, v = ω k × (x − c). ``host`` (n_bodies,): the body
    (index, −1: none) that carries the body's place on its circle when it is displaced (a roller keeps its pocket
    whatever the cage does; a host rests in R). ``placed`` (n_bodies,): resting bodies that keep their place on a
    circle about their ``centre`` all the same — displaced only along its radius (a roller in a held cage).
    Velocities and accelerations are those of the circle about the fixed centre. Spin rates are the angular
    velocities' θ entries."""
    t0: float
    q0: np.ndarray      # (nb, 3) poses in R at t0
    spin: np.ndarray    # (nb,) angular rate in R [rad/s]
    orbit: np.ndarray   # (nb,) orbital rate in R [rad/s]
    centre: np.ndarray  # (nb, 2) orbit centre in R [m], its host at its steady pose
    host: np.ndarray    # (nb,) host body index or −1
    placed: np.ndarray  # (nb,) bool: resting, but kept on a circle about its centre
    extra: np.ndarray | None = None   # the tilt coordinates' values at t0 (they rest in R); None: the model has none

    def full(self, model: Model, X: np.ndarray, extra: np.ndarray | None = None) -> np.ndarray:
        """The free DOFs of body poses (or velocities) X (nb, 3) and tilt coordinates ``extra`` (default: the
        steady ones for poses; pass zeros for velocities)."""
        if not model.has_tilt:
            return X.ravel()[model.free]
        return model.full_of_poses(X, self.extra if extra is None else extra)[model.free]

    @staticmethod
    def split(model: Model, q: np.ndarray) -> np.ndarray:
        """(nb, 3) body poses of free DOFs q (fixed bodies' entries 0; tilt coordinates dropped)."""
        X = np.zeros(model.n_full)
        X[model.free] = q
        return model.poses(X)

    def circling(self, model: Model) -> np.ndarray:
        """Indices of the free bodies moved only along (and, optionally, around) a circle: orbiting or placed."""
        return np.flatnonzero(((self.orbit != 0.0) | self.placed) & ~model.fixed)

    @staticmethod
    def from_state(model: Model, q0: np.ndarray, v0: np.ndarray, orbit, host=None, t0: float = 0.0,
                   rest_tol: float = 1e-9, circles=None) -> "SteadyMotion":
        """``q0``, ``v0``: the free DOFs in R at ``t0`` (a built scene's kinematic initial state); ``orbit``: the
        bodies' orbital rates in R; ``host``: their hosts (default none); ``circles``: {body index: centre (x, y)}
        for resting bodies kept on a circle about that centre (placed). A body declared resting must not move in
        R (speed below ``rest_tol`` [m/s]): its steady motion would be unknown, and it is refused."""
        qf, vf = model.full(t0, q0, v0)
        P, V = model.poses(qf), model.poses(vf)
        extra = qf[model.n_body_coords:].copy() if model.has_tilt else None
        if model.has_tilt and np.any(np.abs(vf[model.n_body_coords:]) > rest_tol):
            raise ModelError("steady motion: a tilt coordinate moves in the reference frame; a static solution needs "
                             "every slope and tilt at rest in R")
        nb = model.n_bodies
        w = np.asarray(orbit, float)
        if w.shape != (nb,) or not np.all(np.isfinite(w)):
            raise ModelError(f"orbit: one finite rate [rad/s] per body ({nb}) expected, got shape {w.shape}")
        w = np.where(model.fixed, 0.0, w)
        host = np.full(nb, -1, np.int64) if host is None else np.asarray(host, np.int64)
        hosted = np.flatnonzero(host >= 0)
        if host.shape != (nb,) or np.any(host >= nb) or np.any(w[host[hosted]] != 0.0) \
                or np.any(model.fixed[host[hosted]]) or np.any(w[hosted] == 0.0):
            raise ModelError("host: one body index (or -1) per body expected; a hosted body must orbit, its host be "
                             "a free body whose centre rests in R")
        centre = P[:, :2].copy()
        moving = np.flatnonzero(w != 0.0)
        centre[moving, 0] -= V[moving, 1] / w[moving]        # v = ω k × (x − c)  ⇒  x − c = (v_y, −v_x)/ω
        centre[moving, 1] += V[moving, 0] / w[moving]
        placed = np.zeros(nb, bool)
        for b, c in (circles or {}).items():
            if not (0 <= int(b) < nb) or w[int(b)] != 0.0 or model.fixed[int(b)]:
                raise ModelError(f"circles: body {b!r} must be a free body without an orbit rate")
            placed[int(b)] = True
            centre[int(b)] = np.asarray(c, float)
        still = (w == 0.0) & ~model.fixed & (np.hypot(V[:, 0], V[:, 1]) > rest_tol)
        if still.any():
            i = int(np.flatnonzero(still)[0])
            raise ModelError(f"steady motion: body {model.body_names[i]!r} moves in the reference frame "
                             f"({np.hypot(*V[i, :2]):.3g} m/s) but has no orbit rate; a static solution needs every "
                             "body's centre at rest in R or circling a point of R")
        return SteadyMotion(float(t0), P.copy(), np.where(model.fixed, 0.0, V[:, 2]), w, centre, host, placed, extra)

    def poses(self, t: float) -> np.ndarray:
        """(nb, 3) steady poses at time t."""
        dt = t - self.t0
        P = self.q0.copy()
        c, s = np.cos(self.orbit * dt), np.sin(self.orbit * dt)
        r = P[:, :2] - self.centre
        P[:, 0] = self.centre[:, 0] + c * r[:, 0] - s * r[:, 1]
        P[:, 1] = self.centre[:, 1] + s * r[:, 0] + c * r[:, 1]
        P[:, 2] += self.spin * dt
        return P

    def at(self, model: Model, t: float, q_free: np.ndarray | None = None, d_spin: np.ndarray | None = None,
           d_orbit: np.ndarray | None = None):
        """(q, v, a) on the free DOFs at time t: the steady pose, or — given ``q_free`` — the steady velocity and
        acceleration at that displaced pose, v = ω k × (x − c), a = −ω² (x − c), with the spin and orbital rates
        changed by ``d_spin``, ``d_orbit`` (nb,)."""
        q = self.full(model, self.poses(t)) if q_free is None else np.asarray(q_free, float)
        X = self.split(model, q)
        r = X[:, :2] - self.centre          # the motion is about the fixed centre (a host only carries the place)
        w = self.orbit if d_orbit is None else self.orbit + d_orbit
        spin = self.spin if d_spin is None else self.spin + d_spin
        V = np.column_stack([-w * r[:, 1], w * r[:, 0], spin])
        A = np.column_stack([-w * w * r[:, 0], -w * w * r[:, 1], np.zeros(model.n_bodies)])
        rest = None if self.extra is None else np.zeros_like(self.extra)
        return q, self.full(model, V, rest), self.full(model, A, rest)


@dataclass
class StaticSolution:
    """One static state at time ``t``: ``q``, ``v``, ``a`` on the free DOFs (the steady motion at q with the solved
    rates), ``z`` the element internal states used, ``residual`` r with the held DOFs' reactions in it, ``rates``
    the solved rate changes (one per rate group), the continuation's ``steps`` and ``wall_s``."""
    t: float
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    z: dict
    residual: np.ndarray
    rates: np.ndarray
    steps: int
    wall_s: float


class _Problem:
    """Unknowns x = (δ, u): displacements δ along the columns of B (n_free, m) from the steady pose, and rate
    changes u, one per *rate group* (a body whose spin rate changes by u, −1 for none, and bodies whose orbital
    rates change by u: a cage and its rollers turn together). Each rate's equation is the generalized force
    conjugate to the velocities it changes (virtual power): the torque on the spinning body plus the moments
    about their orbit centres of the forces on the orbiting ones. g(x) = (Bᵀ r, Wᵀ r) with W (n_free, n_u)
    those velocity directions, and K = −∂g/∂x."""

    RATE_TIME = 1e-6    # [s]: a rate's pseudo-mass (its inertia about the axis)·RATE_TIME in the continuation

    def __init__(self, system: System, evaluator, motion: SteadyMotion, t: float, B: sp.csc_matrix,
                 groups: list, z: dict):
        m = system.model
        self.system, self.evaluate, self.motion, self.t, self.B, self.z = system, evaluator, motion, t, B, z
        self.model = m
        f2f = m.full_to_free
        self.q_ref = motion.full(m, motion.poses(t))
        self.Bt = B.T.tocsr()
        self.Bd = B.toarray()
        sysm = system
        self._rows = sysm._indices.astype(np.int64)
        self._cols = np.repeat(np.arange(m.ndof), np.diff(sysm._indptr))
        self.nB, self.nu = B.shape[1], len(groups)
        self.orbiting = motion.circling(m)
        self.ix, self.iy = f2f[3 * self.orbiting], f2f[3 * self.orbiting + 1]
        # rate groups flattened: spinning bodies (group, body); orbiting members (group, body)
        self.spin_g = np.array([j for j, (sb, _) in enumerate(groups) if sb >= 0], np.int64)
        self.spin_b = np.array([sb for sb, _ in groups if sb >= 0], np.int64)
        self.orb_g = np.array([j for j, (_, ob) in enumerate(groups) for _b in ob], np.int64)
        self.orb_b = np.array([b for _, ob in groups for b in ob], np.int64)
        if np.any(motion.orbit[self.orb_b] == 0.0):
            raise ModelError("solve_static: a rate group names an orbiting body that does not orbit")
        self.spin_dofs, self.ox, self.oy = f2f[3 * self.spin_b + 2], f2f[3 * self.orb_b], f2f[3 * self.orb_b + 1]
        M_B = np.asarray((self.Bt @ sp.diags(m.mdiag) @ B).diagonal())
        rho = np.hypot(*(motion.poses(t)[self.orb_b, :2] - motion.centre[self.orb_b]).T) if self.orb_b.size else np.zeros(0)
        J = np.bincount(self.spin_g, m.inertia[self.spin_b], self.nu) + np.bincount(self.orb_g, m.mass[self.orb_b] * rho ** 2, self.nu)
        self.M = np.concatenate([M_B, J * self.RATE_TIME])
        self.floor = np.zeros(self.M.size)
        self.names = [m.body_names[sb] if sb >= 0 else m.body_names[ob[0]] + "…" for sb, ob in groups]

    def label(self, i: int) -> str:
        """A readable name of unknown i (traces, errors): its body and what it is."""
        m = self.model
        if i >= self.nB:
            return self.names[i - self.nB] + ".rate"
        rows = self.B[:, i].nonzero()[0]
        if rows.size == 2 and int(m.free[rows[0]]) // 3 == int(m.free[rows[1]]) // 3 \
                and int(m.free[rows[0]]) < m.n_body_coords:
            vals = self.B[rows, i].toarray().ravel()
            body = int(m.free[rows[0]]) // 3
            r = self.motion.poses(self.t)[body, :2] - self.motion.centre[body]
            return f"{m.body_names[body]}.{'radial' if abs(vals @ r) > 0.5 * np.hypot(*r) else 'tangential'}"
        return m.coordinate_name(int(m.free[rows[0]]))

    def _parts(self, x: np.ndarray):
        """(q, X (nb, 3) poses, d_spin, d_orbit) at the unknowns x."""
        m = self.model
        q = self.q_ref + self.B @ x[: self.nB]
        X = self.motion.split(m, q)
        u = x[self.nB:]
        ds, do = np.zeros(m.n_bodies), np.zeros(m.n_bodies)
        ds[self.spin_b] = u[self.spin_g]
        do[self.orb_b] = u[self.orb_g]
        return q, X, ds, do

    def state(self, x: np.ndarray):
        """(q, v, a) on the free DOFs at the unknowns x."""
        q, _, ds, do = self._parts(x)
        return self.motion.at(self.model, self.t, q, ds, do)

    def _equations(self, r: np.ndarray, X: np.ndarray) -> np.ndarray:
        """g = (Bᵀ r, per rate group: the torque on its spinning body + the moments of its orbiting ones)."""
        ro = X[self.orb_b, :2] - self.motion.centre[self.orb_b]
        mom = ro[:, 0] * r[self.oy] - ro[:, 1] * r[self.ox]
        rates = np.bincount(self.spin_g, r[self.spin_dofs], self.nu) + np.bincount(self.orb_g, mom, self.nu)
        return np.concatenate([self.Bt @ r, rates])

    def full_residual(self, x: np.ndarray) -> np.ndarray:
        """r on every free DOF (held ones: their reactions)."""
        q, v, a = self.state(x)
        return self.evaluate(self.t, q, v, self.z, False).F - self.model.mdiag * a

    def residual(self, x: np.ndarray, jac: bool = False):
        """g(x) and, with ``jac``, K = −∂g/∂x (dense: a few hundred unknowns)."""
        q, X, ds, do = self._parts(x)
        _, v, a = self.motion.at(self.model, self.t, q, ds, do)
        ev = self.evaluate(self.t, q, v, self.z, jac)
        r = ev.F - self.model.mdiag * a
        g = self._equations(r, X)
        if not jac:
            return g, None
        m, mo = self.model, self.motion
        Jq, Jv = self._dense(ev.Jq), self._dense(ev.Jv)
        # the steady motion's dependence on the pose, v = w k × r, a = −w² r: column operations on J_v and M
        w = (mo.orbit + do)[self.orbiting]
        ix, iy = self.ix, self.iy
        drq = Jq.copy()
        drq[:, ix] += Jv[:, iy] * w
        drq[:, iy] -= Jv[:, ix] * w
        drq[ix, ix] += m.mdiag[ix] * w * w
        drq[iy, iy] += m.mdiag[iy] * w * w
        # ... and on the rates: a spin rate moves its θ rate; an orbital rate v = k × r, a = −2 w r
        ro = X[self.orb_b, :2] - mo.centre[self.orb_b]
        wo = (mo.orbit + do)[self.orb_b]
        W = np.zeros((m.ndof, self.nu))
        W[self.spin_dofs, self.spin_g] = 1.0
        W[self.ox, self.orb_g] = -ro[:, 1]
        W[self.oy, self.orb_g] = ro[:, 0]
        dru = Jv @ W
        dru[self.ox, self.orb_g] += m.mdiag[self.ox] * 2 * wo * ro[:, 0]
        dru[self.oy, self.orb_g] += m.mdiag[self.oy] * 2 * wo * ro[:, 1]
        # rows: Bᵀ, and the rates' W(q)ᵀ — whose own dependence on q adds r's moment arm terms
        Bd = self.Bd
        rows = np.vstack([Bd.T, W.T])
        dq = rows @ drq
        dq[self.nB + self.orb_g, self.ox] += r[self.oy]
        dq[self.nB + self.orb_g, self.oy] -= r[self.ox]
        return g, -np.hstack([dq @ Bd, rows @ dru])

    def _dense(self, data: np.ndarray) -> np.ndarray:
        """A Jacobian's data on the system's CSC pattern as a dense (n, n) array."""
        n = self.model.ndof
        out = np.zeros((n, n))
        out[self._rows, self._cols] = data
        return out


def _evaluator(system: System, engine: str):
    """F(t, q, v, z, jac): the compiled twin of ``system`` when it can (``engine`` "auto"), else numpy."""
    if engine not in ("auto", "compiled", "numpy"):
        raise ModelError(f"engine must be 'auto', 'compiled' or 'numpy', got {engine!r}")
    if engine == "numpy":
        return system.evaluate
    try:
        from .compiled.system import CompiledSystem  # deferred: numba kernels, optional (numpy falls back)
        cs = CompiledSystem(system)
    except (ImportError, NotImplementedError) as exc:
        if engine == "compiled":
            raise ModelError(f"solve_static: the compiled path cannot evaluate this model: {exc}") from None
        return system.evaluate
    loaded = [None]

    def evaluate(t, q, v, z, jac):      # the internal states are loaded once per dict, not at every call
        if z is loaded[0]:
            return cs.evaluate(t, q, v, None, jac)
        loaded[0] = z
        return cs.evaluate(t, q, v, z, jac)
    return evaluate


def _directions(model: Model, motion: SteadyMotion, t: float, held: np.ndarray, tangential: bool):
    """(B, groups): B (n_free, m) the displacement directions — a unit column per free DOF that is neither held
    nor an orbiting body's x or y (a host's x and y also move its guests), then per orbiting body its radial
    and (``tangential``) its tangential direction about its orbit centre; groups (L, 2) those bodies' radial
    and tangential columns (−1: none)."""
    n, f2f = model.ndof, model.full_to_free
    keep = ~held.copy()
    orbiting = motion.circling(model)
    keep[f2f[3 * orbiting]] = keep[f2f[3 * orbiting + 1]] = False
    solved = np.flatnonzero(keep)
    col_of = -np.ones(n, np.int64)
    col_of[solved] = np.arange(solved.size)
    rows, cols, vals = [solved], [np.arange(solved.size)], [np.ones(solved.size)]
    hosted = orbiting[motion.host[orbiting] >= 0]
    for j in (0, 1):
        hc = col_of[f2f[3 * motion.host[hosted] + j]]
        ok = hc >= 0
        rows.append(f2f[3 * hosted[ok] + j])
        cols.append(hc[ok])
        vals.append(np.ones(int(ok.sum())))
    X = motion.poses(t)
    e = X[orbiting, :2] - motion.centre[orbiting]
    e /= np.hypot(e[:, 0], e[:, 1])[:, None]
    L = orbiting.size
    rad = solved.size + np.arange(L)
    tan = solved.size + L + np.arange(L) if tangential else -np.ones(L, np.int64)
    for c, (ux, uy) in ((rad, (e[:, 0], e[:, 1])), (tan, (-e[:, 1], e[:, 0]))):
        if c[0] >= 0 if L else False:
            rows += [f2f[3 * orbiting], f2f[3 * orbiting + 1]]
            cols += [c, c]
            vals += [ux, uy]
    m = solved.size + L * (2 if tangential else 1)
    B = sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, m))
    return B, orbiting, np.column_stack([rad, tan])


def _tilt_columns(model: Model, B: sp.csc_matrix, orbiting: np.ndarray) -> np.ndarray:
    """(L,) the column of B that moves each orbiting body's own tilt coordinate (a roller's tilt in its radial–axial
    plane; −1: none, or held). No element joins two orbiting bodies' tilts (each roller's contacts are its own), so a
    roller's tilt can join its radius and spin in its local group (:func:`_local_solve`). That is the second pass of
    :func:`solve_static`, where the continuation with the tilts among the outer unknowns stalls: a roller at the load
    zone's edge, on the bore under its centrifugal load alone, has a small tilt stiffness and a moment that steps as
    the pin's slices touch one by one; Newton's steps throw it across those kinks, every step of the others is refused
    with it, and the continuation crawls. In its local group it has its own halving and its own quartered bound."""
    out = -np.ones(orbiting.size, np.int64)
    if not model.has_tilt:
        return out
    kind, owner = np.asarray(model.extra_kind), np.asarray(model.extra_owner)
    rows = B.tocsr()
    where = {int(b): k for k, b in enumerate(orbiting)}
    for j in np.flatnonzero(kind == TILT):
        k = where.get(int(owner[j]))
        f = int(model.full_to_free[model.n_body_coords + j])
        if k is None or f < 0:
            continue
        cols = rows[f].indices
        if cols.size == 1:
            out[k] = int(cols[0])
    return out


def solve_static(model: Model, motion: SteadyMotion, t: float, *, hold=(), rates=(), tangential: bool = False,
                 q_start: np.ndarray | None = None, rates_start=None, z: dict | None = None,
                 system: System | None = None, engine: str = "auto", evaluator=None, length_tol: float = 1e-11,
                 rate_tol: float = 1e-6,
                 max_steps: int = 200, max_step: float = 2e-5, max_rate_step: float = 1e3,
                 regularization: float = 1e-12, force_rtol: float = 1e-8, walk: bool = True) -> StaticSolution:
    """The static state at time ``t`` (module docstring).

    ``hold``: free-DOF indices kept at their steady values (equations dropped). ``rates``: rate groups, each
    (body whose spin rate is solved or −1, [orbiting bodies whose orbital rates change with it]); a spinning
    body's angle is held. A group of one spinning orbiting body and nothing else is *local* (a roller's spin),
    solved with that body's radius inside every step. ``tangential``: orbiting bodies move along their circle
    (else they keep their place on it, carried by their host; their tangential force is then a reaction).
    ``q_start``, ``rates_start``: a pose and rate changes to start from (default the steady pose and rates; a
    sequence of instants starts each from the last, :func:`carry`). ``z``: element internal states (default
    their initial values). Converged when every unknown's residual would move it less than its tolerance under
    its own stiffness — ``length_tol`` [m] (angles at their body's radius of gyration), ``rate_tol`` [rad/s] — or
    is below ``force_rtol`` of the largest force balanced at the start (at its length scale: a body floating in
    a clearance keeps a round-off force and no stiffness); ``max_step`` [m] and ``max_rate_step`` [rad/s] bound
    one step; ``walk``: a last pass walks free modes to their contacts where the others fail (a caller with other
    starts to try first turns it off and tries it last). One-line ModelError, naming the worst unknown, when it
    fails."""
    with threadpool_limits(limits=1, user_api="blas"):     # dense systems of a few hundred: threads only contend
        return _solve(model, motion, t, hold, rates, tangential, q_start, rates_start, z, system, engine, evaluator,
                      length_tol, rate_tol, max_steps, max_step, max_rate_step, regularization, force_rtol, walk)


def _solve(model, motion, t, hold, rates, tangential, q_start, rates_start, z, system, engine, evaluator, length_tol,
           rate_tol, max_steps, max_step, max_rate_step, regularization, force_rtol, walk) -> StaticSolution:
    t_wall = time.perf_counter()
    system = system if system is not None else System(model)
    evaluate = evaluator if evaluator is not None else _evaluator(system, engine)
    z = system.init_internal() if z is None else z
    rates = [(int(sb), [int(b) for b in ob]) for sb, ob in rates]
    held = np.zeros(model.ndof, bool)
    held[np.asarray(hold, np.int64)] = True
    for sb, _ in rates:
        if sb >= 0:
            held[model.full_to_free[3 * sb + 2]] = True
    B, orbiting, groups = _directions(model, motion, t, held, tangential)
    prob = _Problem(system, evaluate, motion, t, B, rates, z)
    nB = B.shape[1]
    x = np.zeros(nB + len(rates))
    if q_start is not None:     # the start's displacement along the solved directions (least squares: a host's
        x[:nB] = np.linalg.lstsq(prob.Bd, np.asarray(q_start, float) - prob.q_ref, rcond=None)[0]   # columns carry guests)
    if rates_start is not None:
        x[nB:] = np.asarray(rates_start, float)
    own = -np.ones(model.n_bodies, np.int64)          # each orbiting body's own spin-rate group
    for j, (sb, ob) in enumerate(rates):
        if sb >= 0 and not ob and motion.orbit[sb] != 0.0:
            own[sb] = nB + j
    local = np.column_stack([groups, own[orbiting]])           # (L, 3): radius, place, own spin rate
    tilt = _tilt_columns(model, B, orbiting)
    # (L, 4): with its tilt, where it has one (a sliced bearing's roller): the continuation that stalls on a tilt
    local_tilt = np.column_stack([local, tilt]) if np.any(tilt >= 0) else None
    nbod = model.n_bodies         # each free DOF's body, and its inertia (an angle's scale: the radius of gyration)
    body = np.concatenate([np.repeat(np.arange(nbod), 3), model.extra_owner])[model.free]
    J = np.concatenate([np.repeat(model.inertia, 3), model.extra_inertia])[model.free]
    gyr = np.where(model.angle_dofs, np.sqrt(J / model.mass[body]), 1.0)
    scale = np.asarray(abs(B).T @ gyr).ravel() / np.asarray(abs(B).sum(axis=0)).ravel()
    tol = np.concatenate([length_tol / scale, np.full(len(rates), rate_tol)])
    cap = np.concatenate([max_step / scale, np.full(len(rates), max_rate_step)])
    # a force no displacement resolves: a fraction force_rtol of the largest force being balanced at the start, at
    # each unknown's length scale (a body floating in a clearance carries a round-off residual and no stiffness)
    g0 = np.abs(prob.residual(x)[0][:nB])
    prob.force_floor = np.concatenate([force_rtol * float(g0.max(initial=0.0)) * scale,
                                       np.zeros(len(rates))])
    x_start = x.copy()
    x, steps, ok = _ptc(prob, x, local, tol, cap, max_steps, regularization, bisect=True)
    if not ok and local_tilt is not None:   # again with each roller's tilt in its local group (a roller at the load
        x, more, ok = _ptc(prob, x_start, local_tilt, tol, cap, max_steps, regularization, bisect=True)  # zone's edge)
        steps += more
    if not ok:      # again without the rates' bisection: a machine without load (rates flip as the loads come in)
        x, more, ok = _ptc(prob, x_start, local, tol, cap, max_steps, regularization, bisect=False)
        steps += more
    if not ok and walk:     # again walking the free modes: a gear train floating in its backlash under drag torques
        x, more, ok = _ptc(prob, x_start, local, tol, cap, max_steps, regularization, bisect=True, walk=True)
        steps += more
    if not ok:
        worst = int(np.argmax(np.abs(prob.residual(x)[0]) / np.maximum(prob.floor, 1e-300)))
        raise ModelError(f"solve_static: no static state at t = {t:.6g} s after {steps} steps (worst unknown: "
                         f"{prob.label(worst)}): a body without support, a load no contact can carry, or a state "
                         f"resting on a force's jump (a contact's damping at its onset)?")
    q, v, a = prob.state(x)
    return StaticSolution(float(t), q, v, a, z, prob.full_residual(x), x[nB:].copy(), steps, time.perf_counter() - t_wall)


def carry(model: Model, motion: SteadyMotion, sol: StaticSolution, t: float, rates=()) -> tuple[np.ndarray, np.ndarray]:
    """A start for time ``t`` from the solution ``sol`` of another instant: every displacement carried over, except
    that orbiting bodies have moved along their circles — theirs (radial and tangential) are interpolated, as a
    function of the angle on the circle, among the bodies sharing that circle's centre and rate (a bearing's
    rollers: the load zone stays where it was); so are the rates of groups that spin one such body. Returns
    (q_start, rates_start) for :func:`solve_static` with the same ``rates``."""
    P0, P1 = motion.poses(sol.t), motion.poses(t)
    X = motion.split(model, sol.q)
    D = X - P0
    D[model.fixed] = 0.0
    orb = motion.circling(model)
    rates = [(int(sb), list(ob)) for sb, ob in rates]
    u = np.asarray(sol.rates, float).copy() if len(rates) else np.zeros(0)
    own = {sb: j for j, (sb, ob) in enumerate(rates) if sb >= 0 and not ob}
    key = np.round(np.column_stack([motion.centre[orb], motion.orbit[orb]]), 12)
    for k in np.unique(key, axis=0):
        grp = orb[np.all(key == k, axis=1)]
        c = motion.centre[grp]
        r0, r1 = P0[grp, :2] - c, P1[grp, :2] - c
        a0, a1 = np.arctan2(r0[:, 1], r0[:, 0]), np.arctan2(r1[:, 1], r1[:, 0])
        e0 = r0 / np.hypot(*r0.T)[:, None]
        rad, tan = np.sum(D[grp, :2] * e0, axis=1), e0[:, 0] * D[grp, 1] - e0[:, 1] * D[grp, 0]
        order = np.argsort(a0)
        per = lambda v: np.interp(a1, a0[order], v[order], period=2 * np.pi)
        e1 = r1 / np.hypot(*r1.T)[:, None]
        rr, tt = per(rad), per(tan)
        D[grp, 0], D[grp, 1] = rr * e1[:, 0] - tt * e1[:, 1], rr * e1[:, 1] + tt * e1[:, 0]
        idx = [own.get(int(b), -1) for b in grp]
        if all(i >= 0 for i in idx):
            u[idx] = per(u[idx])
    extra = None
    if model.has_tilt:          # the tilt coordinates carried over as they are
        full = np.zeros(model.n_full)
        full[model.free] = sol.q
        extra = full[model.n_body_coords:]
    return motion.full(model, P1 + D, extra), u





def _local_solve(prob: _Problem, x: np.ndarray, local: np.ndarray, cap: np.ndarray, max_iter: int = 100):
    """Solve every local group (a row of ``local``: radius, place and own spin rate of one orbiting body, and its
    tilt in a second pass (:func:`_tilt_columns`), −1 where absent) for fixed outer unknowns, all groups at once. No
    element joins two groups, so one perturbation of every group's first unknown gives each group's first Jacobian
    column, and so on: a 3×3 (4×4 with the tilt)
    Newton system per group (an unknown whose own stiffness is not positive steps by its cap along its
    residual). Steps are clipped to their caps and damped per group: a group whose scaled residual grew has
    its next step halved (a contact that opened or closed too far), one whose residual fell regains full steps —
    grown measured against both the new and the last floor, so that a floor drifting with its stiffness (a roller's
    spin on a flat EHL traction curve) does not read as growth and halve the steps to nothing.
    Returns (x, g, converged)."""
    x = x.copy()
    L = local.shape[0]
    idx = np.where(local >= 0, local, 0)
    present = local >= 0
    damp = np.ones(L)
    size = np.full(L, np.inf)
    nl = local.shape[1]
    last_floor = np.ones((L, nl))
    reach = cap[idx].copy()                 # each unknown's own step bound: quartered when its residual flips sign
    sign = np.zeros((L, nl))
    g = prob.residual(x)[0]
    for _ in range(max_iter):
        gl = np.where(present, g[idx], 0.0)
        Kl = np.zeros((L, nl, nl))
        for j in range(nl):
            if not present[:, j].any():
                Kl[:, j, j] = 1.0
                continue
            h = 10.0 * prob.tol[idx[:, j]]      # short: a difference straddling a contact onset would see its stiffness early
            xp = x.copy()
            xp[local[present[:, j], j]] += h[present[:, j]]
            gp = np.where(present, prob.residual(xp)[0][idx], 0.0)
            Kl[:, :, j] = np.where(present[:, j, None], -(gp - gl) / h[:, None], 0.0)
            Kl[~present[:, j], j, j] = 1.0
        diag = np.diagonal(Kl, axis1=1, axis2=2)
        # each unknown's own stiffness times its tolerance, or the force floor
        floor = np.maximum((np.abs(diag) + prob.mu_min * prob.M[idx]) * prob.tol[idx], prob.force_floor[idx])
        # settled: below its floor, or bracketed by sign changes within its tolerance (a force that jumps at a
        # contact's onset — the compression-rate damping of a contact whose races are not concentric — has no
        # exact root: the body rests at the jump)
        scaled = np.where(present & (reach > prob.tol[idx]), np.abs(gl) / floor, 0.0)
        if np.all(scaled <= 1.0):
            return x, g, True
        # grown: the scaled residual grew, and so did the residual itself over the last floor — a residual creeping
        # down a flat traction curve (EHL) while its stiffness, and so its floor, drifts is not growth
        new_size = scaled.max(axis=1)
        same_floor = np.where(present & (reach > prob.tol[idx]), np.abs(gl) / last_floor, 0.0).max(axis=1)
        grown = (new_size > size) & (same_floor > size)
        damp = np.where(grown, 0.5 * damp, np.minimum(1.0, 2.0 * damp))
        size, last_floor = new_size, floor
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            fin = np.all(np.isfinite(Kl), axis=(1, 2))
            det = np.where(fin, np.linalg.det(np.where(fin[:, None, None], Kl, np.eye(nl))), 0.0)
            good = np.all(diag > 0, axis=1) & (det > 0)
            d = np.linalg.solve(np.where(good[:, None, None], Kl, np.eye(nl)), gl[..., None])[..., 0]
            good &= np.all(np.isfinite(d), axis=1)
            d = np.where(good[:, None], d, np.where(diag > 0, gl / diag, np.sign(gl) * cap[idx]))
        flipped = sign * np.sign(gl) < 0
        reach = np.where(flipped, 0.25 * reach, np.minimum(cap[idx], 1.5 * reach))
        sign = np.sign(gl)
        d = np.clip(d * damp[:, None], -reach, reach)
        x[local[present]] += d[present]
        g = prob.residual(x)[0]
    return x, g, False


def _ptc(prob: _Problem, x: np.ndarray, local: np.ndarray, tol: np.ndarray, cap: np.ndarray, max_steps: int,
         regularization: float, bisect: bool = True, walk: bool = False):
    """Pseudo-transient continuation on the outer unknowns, the local ones solved after every step
    (:func:`_local_solve`): implicit Euler steps of the overdamped flow M x' = g, (K_c + μM) Δ = g_c with K_c the
    Schur complement of the local blocks and μ = 1/Δτ. μ starts where no unknown moves more than its ``cap``
    and follows the residual, μ ← μ·|g_new|/|g| (halved again while it falls; |g|² = Σ g²/M over the outer
    unknowns), down to ``regularization``·max K/M: the last steps are Newton's. A step that more than doubles
    |g| is retried with a tenfold μ, and so is any growth once |g| is a hundredth of its start or μ at its
    floor (Newton's steps can cycle across a kink of the forces); steps are clipped to their caps. A rate unknown
    (a cage's, with its rollers' orbits) whose step reached its bound and flipped the sign of its residual jumped
    across its root: with ``bisect``, its bound is quartered, and regrows by half while no jump recurs. A saturating
    traction makes the cage's moment a step of ≈ ±20 N·m within ≈ 1 rad/s with flat shoulders, where the stiffness
    is nil and Newton's steps from one shoulder land on the other; the shrinking bound brings the rate into the
    step, where Newton converges (:func:`_solve` runs the continuation again without it where it fails: at no load the
    rates' residuals flip as the loads come in, not by jumping). With ``walk``, a refused step first walks the
    free modes, if any, to their contacts (:func:`_walk_free_modes`: gears floating in their backlash under the
    drag torques at idle and light load) and goes on from there. Converged
    when every unknown's residual would move it less than its tolerance under its own stiffness,
    |g_i| ≤ (|K_ii| + μ_min M_i)·tol_i. Stops, unconverged, when μ has grown 10⁴-fold over its start (no step
    lowers |g|). Returns (x, steps, converged)."""
    M = prob.M
    loc = np.sort(local[local >= 0])
    outer = np.setdiff1d(np.arange(M.size), loc)
    Mo = M[outer]
    forces = outer[outer < prob.nB]        # the continuation follows the forces; rates settle with them
    norm = lambda y: float(np.sqrt(np.sum(y[forces] ** 2 / M[forces])))
    g, K = prob.residual(x, jac=True)
    mu_min = regularization * float(np.max(np.abs(np.diagonal(K)) / M))
    prob.mu_min, prob.tol = mu_min, tol
    prob.floor = np.maximum((np.abs(np.diagonal(K)) + mu_min * M) * tol, prob.force_floor)
    x, g, local_ok = _local_solve(prob, x, local, cap)
    g, K = prob.residual(x, jac=True)
    mu = max(float(np.max(np.abs(g[outer]) / (Mo * cap[outer]))), mu_min)
    g_start, mu_start = norm(g), mu
    # the outer rates (a cage's with its rollers'): a step that reached its bound and flipped the rate's residual
    # jumped across its root — the bound is quartered (it regrows by half a step while no such jump recurs)
    rt = outer[outer >= prob.nB]
    reach, sign = cap.copy(), np.sign(g)
    for k in range(max_steps + 1):
        prob.floor = np.maximum((np.abs(np.diagonal(K)) + mu_min * M) * tol, prob.force_floor)
        if np.all(np.abs(g[outer]) <= prob.floor[outer]) and local_ok:
            return x, k, True
        if k == max_steps or mu > 1e4 * mu_start:   # no step, however short, lowers |g|: resting on a force's jump
            break
        try:
            x_new, g_new, ok_new, clipped = _ptc_step(prob, x, g, K, outer, loc, mu, mu_min, local, cap, reach)
        except np.linalg.LinAlgError:
            return x, k, False
        ratio = norm(g_new) / max(norm(g), 1e-300) if np.all(np.isfinite(g_new)) else np.inf
        if _TRACE:
            top = outer[np.argsort(-np.abs(g[outer]) / np.sqrt(Mo))[:3]]
            print(f"{k} mu {mu:.2e} local {ok_new} |g| {norm(g):.3e} -> {norm(g_new):.3e} largest: "
                  + ", ".join(f"{prob.label(int(i))} {g[i]:.3g}" for i in top))
        # a step that doubles |g| is refused; so is any growth once |g| is a hundredth of its start (the contacts
        # are in: what remains is Newton's end game) or μ at its floor — near a kink of the forces (a tooth pair's
        # stiffness edge, a contact closing) Newton's steps can cycle between two states on either side of it
        if ratio > 2.0 or (ratio > 1.0 and (mu <= mu_min or norm(g) < 1e-2 * g_start)):
            walked = _walk_free_modes(prob, x, g, K, outer, loc, local, cap, norm) if walk else None
            if walked is None:
                mu = max(10.0 * mu, 10.0 * mu_min)
                continue
            x_new, g_new, ok_new = walked
            ratio, clipped = norm(g_new) / max(norm(g), 1e-300), np.zeros(outer.size, bool)
        x, local_ok = x_new, ok_new
        g, K = prob.residual(x, jac=True)
        jumped = np.zeros(M.size, bool)
        jumped[outer] = clipped
        jumped[rt] &= (sign[rt] * np.sign(g[rt]) < 0) & bisect
        reach[rt] = np.where(jumped[rt], 0.25 * reach[rt], np.minimum(cap[rt], 1.5 * reach[rt]))
        sign = np.sign(g)
        mu = max(mu * (0.5 * ratio if ratio <= 1.0 else ratio), mu_min)
    return x, k, False              # the steps taken (fewer than max_steps where μ ran away)


def _ptc_step(prob: _Problem, x: np.ndarray, g: np.ndarray, K: np.ndarray, outer: np.ndarray, loc: np.ndarray,
              mu: float, mu_min: float, local: np.ndarray, cap: np.ndarray, reach: np.ndarray):
    """One step of :func:`_ptc` from x (its residual g, K): the outer unknowns' implicit Euler step on the Schur
    complement of the local blocks, clipped to ``reach``, the locals' linear prediction, then their own solve.
    Returns (x_new, g_new, converged locals, clipped outer steps); raises LinAlgError where the step has none."""
    M = prob.M
    Koo, Kol = K[np.ix_(outer, outer)], K[np.ix_(outer, loc)]
    Klo, Kll = K[np.ix_(loc, outer)], K[np.ix_(loc, loc)]
    # the local residuals are settled (solved, or resting at a force's jump): the outer step does not chase them
    X = np.linalg.solve(Kll + np.diag(mu_min * M[loc]), Klo)
    d = np.linalg.solve(Koo - Kol @ X + np.diag(mu * M[outer]), g[outer])
    if not np.all(np.isfinite(d)):
        raise np.linalg.LinAlgError("a step without a finite value")
    clipped = np.abs(d) >= reach[outer]
    d = np.clip(d, -reach[outer], reach[outer])
    x_new = x.copy()
    x_new[outer] += d
    x_new[loc] += np.clip(-X @ d, -cap[loc], cap[loc])        # the locals' linear prediction
    x_new, g_new, ok_new = _local_solve(prob, x_new, local, cap)
    return x_new, g_new, ok_new, clipped


def _walk_free_modes(prob: _Problem, x: np.ndarray, g: np.ndarray, K: np.ndarray, outer: np.ndarray,
                     loc: np.ndarray, local: np.ndarray, cap: np.ndarray, norm, max_walks: int = 8):
    """The free modes walked along their forces until their contacts close, or None. A body or a train of bodies
    inside a clearance — gears rolling together in their backlash, their flanks open — has a direction of no
    stiffness along which a constant force pushes it (the drag torques at idle): the continuation's steps see no
    stiffness there, every step short enough not to overshoot the contact leaves |g| where it was, and a longer one
    closes the contact too far and is refused. Each walk (:func:`_walk`) closes one contact at least and may leave
    another free mode (the sun rolling on the two inner planets whose flanks closed first, towards the third):
    walked in turn, up to ``max_walks``, then the locals solved. The state is kept even where |g| grew (the mode
    balances as a whole, its bodies not yet one by one: the first flanks to close carry the others' drag); the
    continuation goes on from it with the closed contacts' stiffness. Returns (x, g, locals converged)."""
    n0 = norm(g)
    walked = False
    for _ in range(max_walks):
        x_new = _walk(prob, x, g, K, outer, loc, cap)
        if x_new is None:
            break
        x, walked = x_new, True
        g, K = prob.residual(x, jac=True)
    if not walked:
        return None
    x, g, ok = _local_solve(prob, x, local, cap)
    if _TRACE:
        print(f"walk: |g| {n0:.4g} -> {norm(g):.4g}")
    if not np.all(np.isfinite(g)):
        return None
    return x, g, ok


def _walk(prob: _Problem, x: np.ndarray, g: np.ndarray, K: np.ndarray, outer: np.ndarray, loc: np.ndarray,
          cap: np.ndarray):
    """One walk of the free modes (:func:`_walk_free_modes`): x where the force along them vanishes, or None. The
    free modes: the mass-scaled singular directions of the Schur complement (the locals following) whose singular
    values are below μ_min (stiffness the regularization would hide); the walk: along the force projected on them,
    w, marched in steps of one cap until the force along w, wᵀg, changes sign (a contact closed), its root then
    bracketed (:func:`scipy.optimize.brentq`) to within the unknowns' tolerances. A root where the modes already are
    (within those tolerances) is no walk: None, and the continuation's μ grows as it would without."""
    from scipy.optimize import brentq     # deferred: only the last pass walks
    M = prob.M
    Kll = K[np.ix_(loc, loc)] + np.diag(prob.mu_min * M[loc])
    X = np.linalg.solve(Kll, K[np.ix_(loc, outer)])
    Kc = K[np.ix_(outer, outer)] - K[np.ix_(outer, loc)] @ X
    s = 1.0 / np.sqrt(M[outer])
    _, S, Vt = np.linalg.svd(s[:, None] * Kc * s[None, :])
    N = Vt[S < prob.mu_min]
    if _TRACE:
        print(f"walk: {len(N)} free modes, singular values {S[-len(N) - 1:]}, mu_min {prob.mu_min:.3g}")
    if not len(N):
        return None
    w = np.zeros(M.size)
    w[outer] = s * (N.T @ (N @ (s * g[outer])))
    w[loc] = -X @ w[outer]
    moved = np.abs(w) > 1e-12 * np.abs(w).max()
    if not moved.any() or np.all(np.abs(g[moved]) <= prob.floor[moved]):
        return None
    h = float(np.min(cap[moved] / np.abs(w[moved])))
    phi = lambda a: float(w[outer] @ prob.residual(x + a * w)[0][outer])
    if not phi(0.0) > 0.0:           # |N s g|² in exact arithmetic: a force along the modes that rounds away
        return None
    lo, hi = 0.0, None
    for k in range(1, 65):           # a clearance of up to 64 caps
        f = phi(k * h)
        if not np.isfinite(f):
            return None
        if f <= 0.0:
            hi = k * h
            break
        lo = k * h
    if hi is None:
        return None
    xtol = float(np.min(prob.tol[moved] / np.abs(w[moved])))
    a = brentq(phi, lo, hi, xtol=xtol, maxiter=200)
    if _TRACE:
        print(f"walk: bracket [{lo:.3g}, {hi:.3g}] at {a:.6g}")
    if np.all(np.abs(a * w) <= prob.tol):       # the force along the modes vanishes where they are: nothing to walk
        return None
    return x + a * w
