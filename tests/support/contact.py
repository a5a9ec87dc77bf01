"""The contact families' test scenes and checks (mbd.elements.contact, docs/model.md §8), shared by the contact tests
(tests/mbd/test_contact_*.py), the compiled-kernel tests (test_compiled_contact) and the raceway-defect tests
(test_race_spall), and by bench_compiled_contact: the reference bearing's geometry and contact laws, scenes that
place rollers, cages and pins in a given contact state (race, pocket, guide, drag) with hypothesis strategies
drawing such states, and the checks — exact Jacobians against fourth-order finite differences, Newton's third law,
objectivity, and the compiled kernels against the reference to round-off.

Geometry of the reference bearing (docs/parameters.md): d_m = 39 mm, D = 7.5 mm, l = 9 mm, K = 1.22e9 N/m^(10/9),
P_d = 20 µm.
"""
from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, settings, strategies as st

from mbd.compiled.registry import kind_of
from mbd.element import evaluate
from mbd.elements.contact import (DryLand, EHLTraction, ExactRestitution, GuideContact, LubricantDrag, PocketContact,
                                  PocketRetention, RaceContact, SlideRollTraction, TanhTraction, restitution_lambda)
from mbd.model import FrameState

# the reference bearing (docs/parameters.md)
DM, DR, LR = 39e-3, 7.5e-3, 9e-3
K_HZ = 1.22e9
PD = 20e-6
R_IN = (DM - DR) / 2
R_OUT = (DM + DR) / 2 + PD / 2
M_ROLLER = 7850.0 * np.pi * (DR / 2) ** 2 * LR
RCA = 82.5e-3                      # pin radius on the carrier
Z = 12
C_P, C_G, K_P, K_G = 1e-4, 1.5e-4, 2e7, 2e7
E_SET = 0.8                        # coefficient of restitution of pocket and guide impacts
V_MIN = 0.0137                     # [m/s] approach-speed floor (an odd value: no kink at a drawn speed)
R_LAND = R_OUT - C_G
FS = FrameState(0.3, 40.0, 0.0)    # kernels must not depend on the frame: any state will do
LEVER = 0.02                       # [m] to compare angle columns / torque rows with lengths / forces

SETTINGS = settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])


# ---------------------------------------------------------------------------------------------
# helpers
def rot(a):
    return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])


def kcross(w, r):
    """ω k × r for a planar vector r."""
    return w * np.array([-r[1], r[0]])


def local_forces(elem, ql, vl, z=None):
    f, _ = elem.kernel(0.0, FS, list(ql.T), list(vl.T), z)
    return np.column_stack([np.broadcast_to(np.asarray(fi, float), (elem.n,)) for fi in f])


# power-of-two steps: x ± h and x ± 2h are exact in floating point for the magnitudes used here
STEP_Q = (2.0 ** -30, 2.0 ** -30, 2.0 ** -26)   # m, m, rad
STEP_V = (2.0 ** -20, 2.0 ** -20, 2.0 ** -14)   # m/s, m/s, rad/s


def fd_jacobians(elem, qf, vf, z=None):
    """Fourth-order central differences of the local forces w.r.t. local q and v."""
    ql, vl = qf[elem.dofs], vf[elem.dofs]
    out = []
    for wrt_v, steps in ((False, STEP_Q), (True, STEP_V)):
        J = np.empty((elem.n, elem.n_local, elem.n_local))
        for j in range(elem.n_local):
            h = steps[j % 3]

            def f(m):
                x = (vl if wrt_v else ql).copy()
                x[:, j] += m * h
                return local_forces(elem, ql, x, z) if wrt_v else local_forces(elem, x, vl, z)

            J[:, :, j] = (8.0 * (f(1) - f(-1)) - (f(2) - f(-2))) / (12.0 * h)
        out.append(J)
    return out


# round-off scales of the outputs that are not forces (SI); forces are compared relative to the largest
# (penetration rates: the direction of a tiny guide eccentricity carries the round-off of the centres)
OUT_ATOL = {"deflection": 1e-15, "offset": 1e-15, "penetration": 1e-15, "eccentricity": 1e-15,
            "slip_velocity": 1e-11, "rolling_speed": 1e-11, "sliding_speed": 1e-11, "angle": 1e-12, "penetration_rate": 1e-9, "approach_speed": 1e-9}


def assert_jacobians(elem, qf, vf, rtol=1e-6, z=None):
    F, out, Jq, Jv = evaluate(elem, 0.0, FS, qf, vf, z, True)
    F0, out0, _, _ = evaluate(elem, 0.0, FS, qf, vf, z, False)
    # Dual and plain paths agree to round-off (Dual division multiplies by the reciprocal)
    np.testing.assert_allclose(F, F0, rtol=1e-12, atol=1e-12 * np.abs(F0).max())
    for key in out0:
        np.testing.assert_allclose(out[key], out0[key], rtol=1e-12, atol=OUT_ATOL.get(key, 1e-12 * np.abs(F0).max()))
    assert np.all(np.isfinite(Jq)) and np.all(np.isfinite(Jv))
    Nq, Nv = fd_jacobians(elem, qf, vf, z)
    k = elem.n_local
    S = np.ones((k, k))
    S[2::3, :] /= LEVER      # torque rows
    S[:, 2::3] *= LEVER      # angle columns
    row = S[:, 0]
    for name, Ja, Jn, steps in (("dF/dq", Jq, Nq, STEP_Q), ("dF/dv", Jv, Nv, STEP_V)):
        h = np.resize(steps, k)
        for i in range(elem.n):
            a, b = Ja[i] * S, Jn[i] * S
            scale = np.abs(a).max()
            err = np.abs(a - b)
            # round-off floor of the differences, ~1.5 ε|F|/h (matters where a force barely depends on a
            # coordinate, e.g. a pocket force at the onset of an impact, which does not depend on ḋ)
            noise = 100 * np.finfo(float).eps * np.max(np.abs(F0[i]) * row) * S[0] / h
            ok = err <= rtol * (np.abs(a) + scale) + noise
            assert ok.all(), f"{elem.name} {name} instance {i}: max err {err.max():.3e}, scale {scale:.3e}\n{a}\n{b}"
    return F, out


def assert_balanced(elem, qf, vf, z=None):
    """Forces sum to zero and moments about the origin balance (Newton's third law)."""
    F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, z, False)
    x = qf[elem.dofs]
    fx = F[:, 0] + F[:, 3]
    fy = F[:, 1] + F[:, 4]
    mz = F[:, 2] + F[:, 5] + x[:, 0] * F[:, 1] - x[:, 1] * F[:, 0] + x[:, 3] * F[:, 4] - x[:, 4] * F[:, 3]
    scale = np.abs(F).max() + 1e-300
    assert np.all(np.abs(fx) <= 1e-13 * scale) and np.all(np.abs(fy) <= 1e-13 * scale)
    assert np.all(np.abs(mz) <= 1e-13 * scale * (np.abs(x[:, [0, 1, 3, 4]]).max() + LEVER))
    return F, out


def assert_objective(elem, qf, vf, alpha, w, u, z=None):
    """Rotating the whole configuration by alpha and superposing a rigid motion (angular speed w about
    the origin, translation u) rotates the forces and leaves torques and outputs unchanged."""
    F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, z, False)
    nb = qf.size // 3
    q2, v2 = qf.reshape(nb, 3).copy(), vf.reshape(nb, 3).copy()
    Rm = rot(alpha)
    q2[:, :2] = q2[:, :2] @ Rm.T
    q2[:, 2] += alpha
    v2[:, :2] = v2[:, :2] @ Rm.T + np.asarray(u) + w * np.column_stack([-q2[:, 1], q2[:, 0]])
    v2[:, 2] += w
    F2, out2, _, _ = evaluate(elem, 0.0, FS, q2.ravel(), v2.ravel(), z, False)
    scale = np.abs(F).max() + 1e-300
    for b in (0, 3):
        np.testing.assert_allclose(F2[:, b:b + 2], F[:, b:b + 2] @ Rm.T, rtol=0, atol=1e-8 * scale)
        np.testing.assert_allclose(F2[:, b + 2], F[:, b + 2], rtol=0, atol=1e-8 * scale * LEVER)
    for key in out:
        if key not in ("angle", "fx", "fy"):
            # a roller centred in its pocket (s = 0) has no nearer wall: ḋ = sign(s)·ṡ is defined off s = 0
            sel = np.abs(out["offset"]) > 1e-12 if key == "penetration_rate" and "offset" in out else slice(None)
            np.testing.assert_allclose(out2[key][sel], out[key][sel], rtol=1e-7, atol=OUT_ATOL.get(key, 1e-8 * scale))
    if "fx" in out:   # force-vector outputs rotate with the configuration
        f1 = np.column_stack([out["fx"], out["fy"]]) @ Rm.T
        np.testing.assert_allclose(np.column_stack([out2["fx"], out2["fy"]]), f1, rtol=0, atol=1e-8 * scale)


def power_of(F, vf, elem):
    """Mechanical power of the element's generalized forces, per instance."""
    return np.sum(F * vf[elem.dofs], axis=1)


# ---------------------------------------------------------------------------------------------
# roller–raceway scenes: body 0 is the race body (carrier with a pin, or planet), bodies 1..n rollers
def race_scene(kind, pose, vel, psi, angles, deltas, v_normal, v_orbit, slips):
    """Rollers pressed δ_j into the raceway at angles_j (in race-body axes), with normal and
    tangential centre velocities relative to the raceway centre, and the spin that gives slip v_s."""
    n = len(angles)
    # the pin's marker at the carrier's pin radius; the bore's a little off the planet's centre (a pinhole-sized
    # offset), so that the race body's moment about its centre is exercised for both raceways
    mk = (RCA if kind == "inner" else 5e-5) * np.array([np.cos(psi), np.sin(psi)])
    R = R_IN if kind == "inner" else R_OUT
    qf, vf = np.zeros(3 * (n + 1)), np.zeros(3 * (n + 1))
    qf[:3], vf[:3] = pose, vel
    cb, th, vb, wb = np.asarray(pose[:2]), pose[2], np.asarray(vel[:2]), vel[2]
    rc = rot(th) @ mk
    c, vc = cb + rc, vb + kcross(wb, rc)
    for j in range(n):
        a = th + angles[j]
        e = np.array([np.cos(a), np.sin(a)])
        t = np.array([-e[1], e[0]])
        rho = R + DR / 2 - deltas[j] if kind == "inner" else R - DR / 2 + deltas[j]
        p = c + rho * e
        pdot = vc + v_normal[j] * e + v_orbit[j] * t
        P = c + R * e                                      # contact point on the raceway surface
        race_speed = (vb + kcross(wb, P - cb)) @ t
        b = R - rho                                        # P − p = b e, so roller surface speed = ṗ·t + θ̇ b
        spin = (slips[j] + race_speed - pdot @ t) / b
        qf[3 * (j + 1):3 * (j + 2)] = (p[0], p[1], 0.7 * j)
        vf[3 * (j + 1):3 * (j + 2)] = (pdot[0], pdot[1], spin)
    return qf, vf, mk, R


# the test laws (the preset's values, docs/parameters.md): elements have no defaults for them
TANH = TanhTraction(mu_max=0.08, v0=0.3)
EHL = SlideRollTraction(A=-0.04, B=5.0, C=40.0, D=0.04, u_reg=0.1, s_eps=1e-4)
FILM = EHLTraction(eta0=0.025, alpha_p=2.2e-8, E_red=2.31e11, length=LR, tau_L0=2e6, gamma_L=0.07, G_e=1e9,
                   u_reg=0.1, beta=0.038, k_oil=0.13)
LAW = dict(exponent=10.0 / 9.0, zeta=0.05, traction=TANH)


def race_element(kind, n, mk, R, traction=TANH, zeta=0.05, multiplicity=1, damping_ramp=0.0):
    return RaceContact("race", np.arange(1, n + 1), 0, kind=kind, race_marker=mk, R_race=R, D=DR, K=K_HZ,
                       exponent=10.0 / 9.0, zeta=zeta, m_roller=M_ROLLER, traction=traction,
                       multiplicity=multiplicity, damping_ramp=damping_ramp)


N = 4
floats = st.floats


@st.composite
def race_states(draw, kind):
    pose = (draw(floats(-2e-3, 2e-3)), draw(floats(-2e-3, 2e-3)), draw(floats(-np.pi, np.pi)))
    if kind == "outer":   # the planet stands on the pin circle
        pose = (pose[0] + RCA * np.cos(pose[2]), pose[1] + RCA * np.sin(pose[2]), pose[2])
    vel = (draw(floats(-2.0, 2.0)), draw(floats(-2.0, 2.0)), draw(floats(-500.0, 500.0)))
    psi = draw(floats(-np.pi, np.pi))
    lst = lambda s: draw(st.lists(s, min_size=N, max_size=N))  # noqa: E731
    angles = lst(floats(-np.pi, np.pi))
    touching = lst(st.booleans())
    depth = lst(floats(2e-6, 3e-5))
    gap = lst(floats(2e-6, 1e-4))
    deltas = [d if c else -g for c, d, g in zip(touching, depth, gap)]
    v_normal = lst(floats(-0.3, 0.3))
    v_orbit = lst(floats(-5.0, 5.0))
    slips = lst(floats(-2.0, 2.0))
    return pose, vel, psi, angles, deltas, v_normal, v_orbit, slips


# ---------------------------------------------------------------------------------------------
# pocket: body 0 cage, bodies 1..n rollers
def pocket_scene(pose, vel, pockets, offsets, radial, v_circ, v_rad, spins, mu=0.1, restitution=E_SET,
                 multiplicity=1):
    n = len(pockets)
    qf, vf = np.zeros(3 * (n + 1)), np.zeros(3 * (n + 1))
    qf[:3], vf[:3] = pose, vel
    cg, th = np.asarray(pose[:2]), pose[2]
    psi = 2 * np.pi * np.asarray(pockets) / Z
    for j in range(n):
        beta = th + psi[j] + offsets[j] / (DM / 2)
        e = np.array([np.cos(beta), np.sin(beta)])
        t = np.array([-e[1], e[0]])
        p = cg + (DM / 2 + radial[j]) * e
        pdot = np.asarray(vel[:2]) + kcross(vel[2], p - cg) + v_circ[j] * t + v_rad[j] * e
        qf[3 * (j + 1):3 * (j + 2)] = (p[0], p[1], -0.3 * j)
        vf[3 * (j + 1):3 * (j + 2)] = (pdot[0], pdot[1], spins[j])
    elem = PocketContact("pocket", np.arange(1, n + 1), 0, pocket_angle=psi, pitch_radius=DM / 2, clearance=C_P,
                         K_p=K_P, restitution=restitution, impact_law=ExactRestitution(), v_min=V_MIN, mu=mu,
                         v_mu=0.05, D=DR, multiplicity=multiplicity)
    return qf, vf, elem, psi


@st.composite
def pocket_states(draw):
    lst = lambda s: draw(st.lists(s, min_size=N, max_size=N))  # noqa: E731
    pose = (0.08 + draw(floats(-2e-4, 2e-4)), 0.02 + draw(floats(-2e-4, 2e-4)), draw(floats(-np.pi, np.pi)))
    vel = (draw(floats(-20, 20)), draw(floats(-20, 20)), draw(floats(-300, 300)))
    pockets = lst(st.integers(0, Z - 1))
    inside = lst(st.booleans())
    sgn = lst(st.sampled_from([-1.0, 1.0]))
    a_in = lst(floats(0.0, C_P - 1e-6))
    a_out = lst(floats(C_P + 1e-6, C_P + 5e-5))
    offsets = [s * (i_ if c else o) for s, c, i_, o in zip(sgn, inside, a_in, a_out)]
    radial = lst(floats(-2e-4, 2e-4))
    v_circ = lst(floats(-0.05, 0.05))
    v_rad = lst(floats(-0.5, 0.5))
    spins = lst(floats(-3000, 3000))
    return pose, vel, pockets, offsets, radial, v_circ, v_rad, spins


# retention (a roller-centred cage's pocket, radially): body 0 cage, bodies 1..n rollers
C_R = 0.15e-3                      # [m] radial pocket play of a roller-centred cage (the reference bearing's)


def retention_scene(pose, vel, pockets, offsets, radial, v_circ, v_rad, spins, mu=0.1, restitution=E_SET,
                    multiplicity=1):
    """Rollers at their pockets' angles (+ offsets along the pitch circle) and radial offsets ``radial`` from the
    pitch circle, with circumferential and radial speeds relative to the cage and spins."""
    qf, vf, _, psi = pocket_scene(pose, vel, pockets, offsets, radial, v_circ, v_rad, spins, mu=mu,
                                  restitution=restitution, multiplicity=multiplicity)
    n = len(pockets)
    elem = PocketRetention("retention", np.arange(1, n + 1), 0, pitch_radius=DM / 2, clearance=C_R, K_r=K_P,
                           restitution=restitution, impact_law=ExactRestitution(), v_min=V_MIN, mu=mu, v_mu=0.05,
                           D=DR, multiplicity=multiplicity)
    return qf, vf, elem, psi


@st.composite
def retention_states(draw):
    """As :func:`pocket_states`, the radial offsets inside or beyond the radial play C_R, either side."""
    pose, vel, pockets, offsets, _, v_circ, v_rad, spins = draw(pocket_states())
    lst = lambda s: draw(st.lists(s, min_size=N, max_size=N))  # noqa: E731
    inside = lst(st.booleans())
    sgn = lst(st.sampled_from([-1.0, 1.0]))
    a_in = lst(floats(0.0, C_R - 1e-6))
    a_out = lst(floats(C_R + 1e-6, C_R + 5e-5))
    radial = [s * (i_ if c else o) for s, c, i_, o in zip(sgn, inside, a_in, a_out)]
    return pose, vel, pockets, offsets, radial, v_circ, v_rad, spins


@st.composite
def stored_speeds(draw, n=N):
    """Internal state z of an impact family: stored approach speeds v₀ (0: the impact begins in this step)
    and arbitrary cached values in the other columns (they do not enter the forces)."""
    z = np.zeros((n, 4))
    z[:, 0] = draw(st.lists(st.one_of(st.just(0.0), floats(0.02, 3.0)), min_size=n, max_size=n))
    z[:, 1:3] = np.array(draw(st.lists(floats(-1e-4, 1e-4), min_size=2 * n, max_size=2 * n))).reshape(n, 2)
    z[:, 3] = 1.0
    return z


def expected_impact_force(K, x, xd, v_stored, e=E_SET):
    """K x (1 + λ ẋ/v₀) ≥ 0 for x > 0; v₀ the stored speed, or max(ẋ, v_min) at an onset."""
    lam = float(restitution_lambda(e))
    v0 = np.where(v_stored > 0, v_stored, np.maximum(xd, V_MIN))
    return np.where(x > 0, np.maximum(K * x * (1 + lam * xd / v0), 0.0), 0.0), np.where(x > 0, v0, 0.0)


# ---------------------------------------------------------------------------------------------
# guide: body 0 planet, bodies 1..n cages (one per instance)
def guide_scene(pose, vel, ecc, angles, v_rad, v_tan, cage_spin, mu=0.1, e=E_SET, land=None):
    n = len(ecc)
    qf, vf = np.zeros(3 * (n + 1)), np.zeros(3 * (n + 1))
    qf[:3], vf[:3] = pose, vel
    co = np.asarray(pose[:2])
    for j in range(n):
        nvec = np.array([np.cos(angles[j]), np.sin(angles[j])])
        tvec = np.array([-nvec[1], nvec[0]])
        cg = co + ecc[j] * nvec
        vg = np.asarray(vel[:2]) + v_rad[j] * nvec + v_tan[j] * tvec
        qf[3 * (j + 1):3 * (j + 2)] = (cg[0], cg[1], 0.2 * j)
        vf[3 * (j + 1):3 * (j + 2)] = (vg[0], vg[1], cage_spin[j])
    elem = GuideContact("guide", np.arange(1, n + 1), 0, clearance=C_G, K_g=K_G, restitution=e,
                        impact_law=ExactRestitution(), v_min=V_MIN, mu=mu, v_mu=0.05, land_radius=R_LAND,
                        land=land if land is not None else DryLand())
    return qf, vf, elem


@st.composite
def guide_states(draw):
    lst = lambda s: draw(st.lists(s, min_size=N, max_size=N))  # noqa: E731
    pose = (0.07 + draw(floats(-1e-3, 1e-3)), -0.04 + draw(floats(-1e-3, 1e-3)), draw(floats(-np.pi, np.pi)))
    vel = (draw(floats(-20, 20)), draw(floats(-20, 20)), draw(floats(-1500, 1500)))
    which = lst(st.sampled_from(["zero", "inside", "contact"]))
    a_in = lst(floats(1e-7, C_G - 1e-6))
    a_out = lst(floats(C_G + 1e-6, C_G + 5e-5))
    ecc = [0.0 if w == "zero" else (i_ if w == "inside" else o) for w, i_, o in zip(which, a_in, a_out)]
    angles = lst(floats(-np.pi, np.pi))
    v_rad = lst(floats(-0.05, 0.05))
    v_tan = lst(floats(-1.0, 1.0))
    spin = lst(floats(-500, 500))
    return pose, vel, ecc, angles, v_rad, v_tan, spin


# ---------------------------------------------------------------------------------------------
# drag: body 0 carrier (pin at a marker), bodies 1..n rollers
C_D, RHO_OIL = 1.0, 45.0
DRAG_COEF = C_D * RHO_OIL * DR * LR * DM ** 2 / 8


def drag_scene(pose, vel, psi, angles, radial, orbit, v_rad, spins, multiplicity=1, eta=None):
    n = len(angles)
    mk = np.array([RCA * np.cos(psi), RCA * np.sin(psi)])
    qf, vf = np.zeros(3 * (n + 1)), np.zeros(3 * (n + 1))
    qf[:3], vf[:3] = pose, vel
    rc = rot(pose[2]) @ mk
    c, vc = np.asarray(pose[:2]) + rc, np.asarray(vel[:2]) + kcross(vel[2], rc)
    for j in range(n):
        e = np.array([np.cos(angles[j]), np.sin(angles[j])])
        p = c + (DM / 2 + radial[j]) * e
        pdot = vc + kcross(orbit[j], p - c) + v_rad[j] * e
        qf[3 * (j + 1):3 * (j + 2)] = (p[0], p[1], 0.0)
        vf[3 * (j + 1):3 * (j + 2)] = (pdot[0], pdot[1], spins[j])
    elem = LubricantDrag("drag", np.arange(1, n + 1), 0, race_marker=mk, C_d=C_D, rho=RHO_OIL, D=DR, l=LR, d_m=DM,
                         multiplicity=multiplicity, eta=eta)
    omega_m = np.asarray(orbit) - vel[2]
    return qf, vf, elem, omega_m


@st.composite
def drag_states(draw):
    lst = lambda s: draw(st.lists(s, min_size=N, max_size=N))  # noqa: E731
    pose = (draw(floats(-1e-3, 1e-3)), draw(floats(-1e-3, 1e-3)), draw(floats(-np.pi, np.pi)))
    vel = (draw(floats(-2, 2)), draw(floats(-2, 2)), draw(floats(-500, 500)))
    # orbital speed relative to the carrier kept away from 0, where Ω|Ω| is only C¹ (finite differences
    # are O(h) wrong there; the exact zero Jacobian at Ω_m = 0 is checked separately)
    rel = [s * m for s, m in zip(lst(st.sampled_from([-1.0, 1.0])), lst(floats(1.0, 800.0)))]
    orbit = [vel[2] + r for r in rel]
    return (pose, vel, draw(floats(-np.pi, np.pi)), lst(floats(-np.pi, np.pi)), lst(floats(-5e-5, 5e-5)),
            orbit, lst(floats(-0.1, 0.1)), lst(floats(-3000, 3000)))


# ---------------------------------------------------------------------------------------------
# compiled kernel = reference (mbd.compiled.contact against mbd.element.evaluate over mbd.elements.contact)
#
# F and J_q are held to the relative bound alone (an all-zero reference block must be matched by zeros). J_v has a
# floor per instance, JV_FLOOR·|F| (|F| the instance's largest force entry; JV_FLOOR_FILM with the EHL film law):
# the reference's own round-off, which sets the error where the exact derivative is zero or a small difference of
# larger terms and no other term fills the block (no contact damping, ∂F/∂ẋ = 0 at an onset):
# - at the onset of an impact (v₀ = ẋ of the iterate) F = K x (1 + λ) does not depend on ẋ: the compiled ∂F/∂ẋ
#   is exactly 0, the reference's dual numbers give λẋ/ẋ − λ ≠ 0 (an ulp of λ, times K x/v₀);
# - a saturated friction law's sech² = 1 − tanh² (numpy's SIMD tanh and libm's differ by an ulp);
# - the slide-to-roll traction at |s| ≫ s_eps: the reference differentiates s/a with the cancellation 1 − (s/a)²,
#   the compiled kernel uses the exact s_eps²/a³.
# Each is an ulp of a force over the law's speed scale, so the floor scales with the instance's force, as F's own
# floor does. Impacts: v₀ ≥ v_min = 0.0137 m/s, at most 1.6e-14 s/m per newton; friction: v_mu = 0.05 m/s. Largest
# error beyond the relative bound seen, per newton of |F| (1500 examples of every test, 96 000 instances): 2.7e-15
# s/m (pocket, guide), none where F = 0: JV_FLOOR = 1e-13. The EHL film law saturates at the slip speed
# v_ref = h_c·τ_L/η_eff, which at the heaviest drawn contacts (5 GPa, η_eff at its elastic limit G_e·b/u) is
# 5e-7 m/s: an ulp of the traction (≈ 0.07 |F| there) over it is 3e-11 s/m per newton of |F|. Seen: 8.2e-15 (J_v
# 5.1e-6 N·s/m on 1.9e4 N, off by 1.6e-10) and 6.7e-12 (J_v 7.7 on 2.3e4 N, off by 1.5e-7, 2e-8 of the block;
# found by hypothesis while a planted error was in, which it does not touch: ζ = 0), two draws that an
# absolute floor of 1e-10 did not cover: JV_FLOOR_FILM = 3e-10. A real error (a wrong term, sign or branch) shows
# in the blocks of ordinary states, many orders above it (a factor 2 on the race's damping Jacobian fails every
# race test).
RTOL = 1e-10           # of the largest entry of the instance's block
RTOL_FILM = 1e-8       # Jacobians with the EHL traction law (see assert_matches_reference)
ATOL = 1e-300          # F and J_q: an all-zero reference block must be matched by zeros
JV_FLOOR = 1e-13       # J_v's floor per newton of the instance's force [s/m in SI] (above)
JV_FLOOR_FILM = 3e-10  # the same with the EHL film traction law (above)


def compiled(elem, fs, qf, vf, z, jac, t=0.0):
    """(F, J_q, J_v) of the compiled kernel; outputs start as NaN so that every entry must be written."""
    twin = kind_of(type(elem))
    pack, kernel = twin.pack, twin.evaluate
    P, G = pack(elem)
    ql, vl = np.ascontiguousarray(qf[elem.dofs]), np.ascontiguousarray(vf[elem.dofs])
    n, k = ql.shape
    zz = np.zeros((n, 0)) if z is None else np.ascontiguousarray(z, dtype=float)
    F, Jq, Jv = np.full((n, k), np.nan), np.full((n, k, k), np.nan), np.full((n, k, k), np.nan)
    kernel(t, fs.phi, fs.omega, fs.domega, ql, vl, zz, P, G, F, Jq, Jv, jac)
    return F, Jq, Jv


def assert_blocks_close(name, A, B, atol, rtol=RTOL):
    """|A − B| <= rtol·max|B| + atol per instance block (``atol`` one number or one per instance)."""
    assert A.shape == B.shape and np.all(np.isfinite(A)), name
    atol = np.broadcast_to(atol, (B.shape[0],))
    for i in range(B.shape[0]):
        err = np.abs(A[i] - B[i]).max()
        scale = np.abs(B[i]).max()
        assert err <= rtol * scale + atol[i], f"{name} instance {i}: max error {err:.3e}, scale {scale:.3e}\n{A[i]}\n{B[i]}"


def assert_matches_reference(elem, fs, qf, vf, z=None, jq_floor=0.0, jv_floor=0.0):
    """Compiled and reference kernels agree; an impact family's all-zero z is the reference's z = None.
    ``jq_floor``/``jv_floor``: per-instance round-off floors of the Jacobians the caller measured (added to the
    bounds below)."""
    t = 0.25
    zr = None if z is not None and not np.any(z) else z
    Fr, _, Jqr, Jvr = evaluate(elem, t, fs, qf, vf, zr, True)
    F0r, _, _, _ = evaluate(elem, t, fs, qf, vf, zr, False)
    F, Jq, Jv = compiled(elem, fs, qf, vf, z, True, t)
    F0, _, _ = compiled(elem, fs, qf, vf, z, False, t)
    # the EHL film law's Jacobian passes through exp(−α_p p) (α_p p up to ≈ 40) and a saturating tanh, whose
    # 1 − tanh² the reference's dual numbers form with cancellation: seen up to 2.4e-10 of the block
    film = isinstance(getattr(elem, "traction", None), EHLTraction)
    rj = RTOL_FILM if film else RTOL
    # F's floor: the round-off of its inputs carried through the law, eps·(|J_q||q| + |J_v||v|) per instance —
    # a force that is the tiny difference of large terms (a centred cage's film force, seen 1.5e-10 N from
    # terms of 1e-2 N, compiled and reference apart by 1.4e-18 N) cannot agree to 1e-10 of itself
    q_loc, v_loc = (np.abs(x[elem.dofs]).max(axis=1) for x in (qf, vf))
    floor = 1e-13 * (np.abs(Jqr).max(axis=(1, 2)) * q_loc + np.abs(Jvr).max(axis=(1, 2)) * v_loc) + ATOL
    for A, B, what in ((F, Fr, "F"), (F0, F0r, "F (no jac)")):
        for i in range(B.shape[0]):
            assert_blocks_close(f"{elem.name} {what} [{i}]", A[i:i + 1], B[i:i + 1], floor[i])
    assert_blocks_close(f"{elem.name} J_q", Jq, Jqr, ATOL + np.asarray(jq_floor), rj)
    # J_v's floor: its round-off is a force over a speed (above, at JV_FLOOR), so it scales with the force
    floor_v = (JV_FLOOR_FILM if film else JV_FLOOR) * np.abs(Fr).max(axis=1)
    assert_blocks_close(f"{elem.name} J_v", Jv, Jvr, floor_v + np.asarray(jv_floor), rj)
    np.testing.assert_array_equal(F0, F)     # the value path does not depend on jac
    return Fr
