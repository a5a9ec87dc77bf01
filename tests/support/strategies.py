"""Shared hypothesis strategies and numerical checks for the test suite.

Strategies draw physically sensible SI values (log-uniform over decades where the scale matters);
the checks compare an element family's exact (forward-mode) Jacobians with central finite
differences of :func:`mbd.element.evaluate` and verify Newton's third law. Any element family —
generic or a component's contact law — can be checked with :func:`assert_jacobians_match` and
:func:`assert_third_law`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from hypothesis import strategies as st

import mbd
from mbd.element import evaluate
from mbd.elements import BodySpring, GroundSupport, TorsionalSpring
from mbd.model import FrameState

__all__ = [
    "log_uniform", "masses", "inertias", "stiffnesses", "dampings", "angles", "frame_states",
    "full_states", "NetworkSpec", "networks", "build_network", "accelerating_profile",
    "scatter_forces", "element_jacobians_full", "fd_jacobians_full", "assert_jacobians_match",
    "assert_third_law", "fixed_frame_momenta",
]


# ---------------------------------------------------------------------------------- strategies
def log_uniform(lo: float, hi: float) -> st.SearchStrategy[float]:
    """Floats spread evenly over the decades between lo > 0 and hi."""
    return st.floats(np.log10(lo), np.log10(hi)).map(lambda e: float(10.0 ** e))


def masses(lo=1e-3, hi=10.0):          # kg: a roller (grams) to a ring gear
    return log_uniform(lo, hi)


def inertias(lo=1e-7, hi=1e-1):        # kg m^2
    return log_uniform(lo, hi)


def stiffnesses(lo=1e2, hi=1e8):       # N/m or N m/rad
    return log_uniform(lo, hi)


def dampings(lo=1e-2, hi=1e3, zero=True):
    s = log_uniform(lo, hi)
    return st.one_of(st.just(0.0), s) if zero else s


def angles(span=np.pi):
    return st.floats(-span, span)


@st.composite
def frame_states(draw, rotating=True, max_omega=500.0, max_domega=1e4) -> FrameState:
    """A FrameState (φ, Ω, Ω̇); with rotating=False the inertial one."""
    if not rotating:
        return FrameState(0.0, 0.0, 0.0)
    return FrameState(draw(angles(10.0)), draw(st.floats(-max_omega, max_omega)),
                      draw(st.floats(-max_domega, max_domega)))


@st.composite
def full_states(draw, n_bodies: int, pos=0.2, vel=2.0, angle=np.pi, spin=100.0):
    """(q_full, v_full) of n_bodies bodies: positions within ±pos m, angles within ±angle rad."""
    def arr(scale_xy, scale_t):
        vals = [draw(st.floats(-s, s)) for _ in range(n_bodies) for s in (scale_xy, scale_xy, scale_t)]
        return np.array(vals, dtype=float)
    return arr(pos, angle), arr(vel, spin)


def accelerating_profile(omega0: float, domega: float):
    """Frame profile t -> (φ, Ω, Ω̇) of a uniformly accelerating frame (φ the exact integral of Ω)."""
    def profile(t):
        return omega0 * t + 0.5 * domega * t * t, omega0 + domega * t, domega
    return profile


@dataclass(frozen=True)
class NetworkSpec:
    """A free-floating network of bodies joined by BodySprings (and optionally TorsionalSprings)."""
    mass: tuple
    inertia: tuple
    pos: tuple            # (nb, 2) nominal positions in the fixed frame [m]
    pairs: tuple          # ((a, b), ...) spring connections
    k: tuple
    c: tuple
    marker_a: tuple       # (ns, 2) offsets in body axes [m]
    marker_b: tuple
    k_t: tuple            # torsional stiffness per pair (0: none)


@st.composite
def networks(draw, min_bodies=2, max_bodies=4, markers=True, damping=True, torsion=True):
    """Bodies on a chain (plus one random extra link) of BodySprings. markers=False puts every
    marker at the body centre (the force law is then linear in x, y)."""
    nb = draw(st.integers(min_bodies, max_bodies))
    mass = tuple(draw(masses(0.05, 5.0)) for _ in range(nb))
    inertia = tuple(draw(inertias(1e-4, 1e-1)) for _ in range(nb))
    pos = tuple((0.1 * i + draw(st.floats(-0.02, 0.02)), draw(st.floats(-0.05, 0.05))) for i in range(nb))
    pairs = [(i, i + 1) for i in range(nb - 1)]
    if nb > 2 and draw(st.booleans()):
        pairs.append((0, nb - 1))
    ns = len(pairs)
    k = tuple(draw(stiffnesses(1e2, 1e4)) for _ in range(ns))
    c = tuple(draw(dampings(1e-2, 1.0)) if damping else 0.0 for _ in range(ns))
    mk = (lambda: (draw(st.floats(-0.05, 0.05)), draw(st.floats(-0.05, 0.05)))) if markers else (lambda: (0.0, 0.0))
    marker_a = tuple(mk() for _ in range(ns))
    marker_b = tuple(mk() for _ in range(ns))
    k_t = tuple(draw(st.one_of(st.just(0.0), stiffnesses(1.0, 1e2))) if torsion else 0.0 for _ in range(ns))
    return NetworkSpec(mass, inertia, pos, tuple(pairs), k, c, marker_a, marker_b, k_t)


def build_network(spec: NetworkSpec, frame=None, gravity=(0.0, 0.0), supports: dict | None = None) -> mbd.Model:
    """Model of a NetworkSpec; ``supports`` (optional) are GroundSupport keyword arguments for body 0."""
    b = mbd.ModelBuilder(frame=frame, gravity=gravity)
    bodies = [b.add_body(f"b{i}", m, J, pose=(x, y, 0.0))
              for i, (m, J, (x, y)) in enumerate(zip(spec.mass, spec.inertia, spec.pos))]
    ia = np.array([p[0] for p in spec.pairs])
    ib = np.array([p[1] for p in spec.pairs])
    b.add(BodySpring("spring", ia, ib, k=np.array(spec.k), c=np.array(spec.c),
                     marker_a=np.array(spec.marker_a), marker_b=np.array(spec.marker_b)))
    if any(spec.k_t):
        b.add(TorsionalSpring("torsion", ia, ib, k=np.array(spec.k_t)))
    if supports:
        b.add(GroundSupport("support", bodies[0], **supports))
    return b.build()


# ------------------------------------------------------------------------------------- checks
def scatter_forces(elem, F: np.ndarray, nfull: int) -> np.ndarray:
    """Full generalized-force vector from an element family's (n, k) forces."""
    out = np.zeros(nfull)
    np.add.at(out, elem.dofs.ravel(), F.ravel())
    return out


def element_jacobians_full(elem, t, fs, q, v, z=None):
    """(F, ∂F/∂q, ∂F/∂v) of one family on the full coordinate vector, from evaluate(jac=True)."""
    nfull = q.size
    F, _, Jq, Jv = evaluate(elem, t, fs, q, v, z, jac=True)
    r = np.repeat(elem.dofs[:, :, None], elem.n_local, axis=2).ravel()
    c = np.repeat(elem.dofs[:, None, :], elem.n_local, axis=1).ravel()
    JQ = np.zeros((nfull, nfull))
    JV = np.zeros((nfull, nfull))
    np.add.at(JQ, (r, c), Jq.ravel())
    np.add.at(JV, (r, c), Jv.ravel())
    return scatter_forces(elem, F, nfull), JQ, JV


def fd_jacobians_full(elem, t, fs, q, v, z=None, rel=1e-6):
    """Central finite differences of the full force vector w.r.t. every entry of q and of v."""
    nfull = q.size

    def force(qq, vv):
        F, _, _, _ = evaluate(elem, t, fs, qq, vv, z, jac=False)
        return scatter_forces(elem, F, nfull)

    JQ = np.zeros((nfull, nfull))
    JV = np.zeros((nfull, nfull))
    for j in range(nfull):
        for x, J, first in ((q, JQ, True), (v, JV, False)):
            h = rel * max(1.0, abs(x[j]))
            xp, xm = x.copy(), x.copy()
            xp[j] += h
            xm[j] -= h
            fp = force(xp, v) if first else force(q, xp)
            fm = force(xm, v) if first else force(q, xm)
            J[:, j] = (fp - fm) / (2 * h)
    return JQ, JV


def assert_jacobians_match(elem, t, fs, q, v, z=None, rtol=1e-6, rel=1e-6, force_noise=0.0):
    """Exact Jacobians of ``elem`` equal central finite differences to within rtol·max|J| plus the differences'
    resolution: the forces' round-off (eps·|F|, and ``force_noise`` [N] where a force is computed from terms much
    larger than itself, e.g. a mesh deflection from base radius × an angle of many turns) over the step."""
    F, JQ, JV = element_jacobians_full(elem, t, fs, q, v, z)
    FQ, FV = fd_jacobians_full(elem, t, fs, q, v, z, rel=rel)
    F0, _, _, _ = evaluate(elem, t, fs, q, v, z, jac=False)
    np.testing.assert_allclose(F, scatter_forces(elem, F0, q.size), rtol=1e-12, atol=1e-12 * (1 + np.abs(F).max()),
                               err_msg=f"{elem.name}: forces with and without Jacobians differ")
    # a central difference cannot resolve below the round-off of the forces it subtracts
    fd_noise = (16 * np.finfo(float).eps * (1.0 + np.abs(F).max()) + force_noise) / rel
    for name, A, B in (("dF/dq", JQ, FQ), ("dF/dv", JV, FV)):
        scale = max(np.abs(A).max(), np.abs(B).max(), 1e-300)
        err = np.abs(A - B).max()
        assert err <= rtol * scale + fd_noise, (f"{elem.name}: {name} differs from finite differences by {err:.3e} "
                                               f"(scale {scale:.3e}, FD resolution {fd_noise:.1e})")


def assert_third_law(elem, t, fs, q, v, z=None, rtol=1e-10):
    """Per instance: Σ F = 0 and Σ moments about the origin (torques + r × F at body centres) = 0."""
    F, _, _, _ = evaluate(elem, t, fs, q, v, z, jac=False)
    nbod = elem.n_local // 3
    fx = F[:, 0::3]
    fy = F[:, 1::3]
    tq = F[:, 2::3]
    x = q[elem.dofs[:, 0::3]]
    y = q[elem.dofs[:, 1::3]]
    mom = tq + x * fy - y * fx
    scale = np.abs(F).sum(axis=1) * (1.0 + np.abs(x).max(axis=1) + np.abs(y).max(axis=1)) + 1e-300
    for label, s in (("sum of Fx", fx.sum(axis=1)), ("sum of Fy", fy.sum(axis=1)), ("moment", mom.sum(axis=1))):
        bad = np.abs(s) > rtol * scale
        assert not bad.any(), f"{elem.name}: {label} over its {nbod} bodies is {s[bad]} (not zero)"


def fixed_frame_momenta(model: mbd.Model, t: float, q: np.ndarray, v: np.ndarray):
    """Linear momentum (2,) and angular momentum about the fixed origin of all free bodies, in I."""
    fs = model.frame.at(t)
    qf, vf = model.full(t, q, v)
    Q, V = mbd.to_fixed(qf.reshape(-1, 3), vf.reshape(-1, 3), fs)
    free = ~model.fixed
    m, J = model.mass[free], model.inertia[free]
    Q, V = Q[free], V[free]
    p = np.array([np.sum(m * V[:, 0]), np.sum(m * V[:, 1])])
    L = np.sum(J * V[:, 2] + m * (Q[:, 0] * V[:, 1] - Q[:, 1] * V[:, 0]))
    return p, L
