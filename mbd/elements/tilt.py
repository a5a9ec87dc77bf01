"""Element families on tilt coordinates (docs/model.md §2.4): the gyroscopic terms of a spinning body's slopes
and a linear spring-damper on single coordinates.

A body's slope pair s = s_x + i s_y (complex notation in R; its axis passes through c + ζ s) obeys, in R turning
at Ω with the body's absolute spin ω = Ω + θ̇ (the rigid-rotor equations linearised in the slope, e.g. Genta,
*Dynamics of Rotating Systems*, 2005, §4.3; Lalanne & Ferraris, *Rotordynamics Prediction in Engineering*, 1998,
ch. 2):

    J_d s̈ + i (2 J_d Ω − J_p ω) ṡ + Ω (J_p ω − J_d Ω) s + i J_d Ω̇ s = Σ_k ζ_k F_k.

Its J_d part is the frame terms of a point of mass J_d at position s, which the engine adds to every slope pair
(mbd.assembly); :class:`SlopeGyroscopic` is the rest, moved to the force side:

    Q = i J_p ω ṡ − Ω J_p ω s,   i.e.   Q_x = −J_p ω (ṡ_y + Ω s_x),   Q_y = J_p ω (ṡ_x − Ω s_y).

(In the inertial frame, Ω = 0, it is the familiar gyroscopic moment J_p ω k × (rate of the axis).) The term
i J_p ω ṡ does no work; −Ω J_p ω s is the centrifugal stiffening of the spinning body seen from R. The spin
equation's reaction (second order in the slope, J_p d/dt ½ Im(s̄ ṡ)) is left out: the family puts no torque on
θ, so the slope's gyroscopic coupling to the spin rate is one-way (exact to first order in s).
"""
from __future__ import annotations

import numpy as np

from .. import ad
from ..errors import ModelError
from ..element import Element, body_dofs, marker, marker_velocity

__all__ = ["SlopeGyroscopic", "CoordinateSpring", "BeamSupport"]


def _index_columns(name: str, *cols) -> np.ndarray:
    arrs = [np.atleast_1d(np.asarray(c, dtype=np.int64)) for c in cols]
    n = max(a.size for a in arrs)
    if any(a.size not in (1, n) for a in arrs):
        raise ModelError(f"{name}: coordinate index arrays must have equal length or 1, got {[a.size for a in arrs]}")
    return np.column_stack([np.broadcast_to(a, (n,)) for a in arrs]).astype(np.int64)


class SlopeGyroscopic(Element):
    """Gyroscopic and spin-stiffening terms of spinning bodies' slope pairs (module docstring).

    ``spin``: the full index of each body's θ; ``slopes``: its (s_x, s_y) full indices (ModelBuilder.add_slopes);
    ``polar_inertia``: J_p [kg·m²]. Local coordinates (θ, s_x, s_y)."""
    batched = True
    n_local = 3
    compiled_twin = "generic.slope_gyroscopic"

    def __init__(self, name, spin, slopes, polar_inertia):
        self.name = name
        slopes = np.atleast_2d(np.asarray(slopes, dtype=np.int64))
        if slopes.shape[-1] != 2:
            raise ModelError(f"{name}: slopes must be (n, 2) full indices (s_x, s_y), got shape {slopes.shape}")
        self.dofs = _index_columns(name, spin, slopes[:, 0], slopes[:, 1])
        self.polar_inertia = self._per_instance("polar_inertia", polar_inertia, positive=True)

    def kernel(self, t, fs, q, v, z):
        W = fs.omega
        H = self.polar_inertia * (W + v[0])          # J_p ω, ω = Ω + θ̇ the absolute spin
        Qx = -H * (v[2] + W * q[1])
        Qy = H * (v[1] - W * q[2])
        return [0.0 * q[0], Qx, Qy], {"spin_momentum": H}


class CoordinateSpring(Element):
    """Linear spring-damper on single coordinates: Q = −k (q − q0) − c q̇ on full index ``dof`` (a tilt coordinate
    against the reference frame, e.g. a slope's support in R). Local coordinate: the one."""
    batched = True
    n_local = 1
    compiled_twin = "generic.coordinate_spring"

    def __init__(self, name, dof, k, c=0.0, q0=0.0):
        self.name = name
        self.dofs = _index_columns(name, dof)
        self.stiffness = self._per_instance("k", k, nonneg=True)
        self.damping = self._per_instance("c", c, nonneg=True)
        self.q0 = self._per_instance("q0", q0)

    def kernel(self, t, fs, q, v, z):
        Q = -self.stiffness * (q[0] - self.q0) - self.damping * v[0]
        return [Q], {"force": Q}


class BeamSupport(Element):
    """A body B (a pin) held by a marker of body A (the carrier) as a beam's station is held by its clamps: its
    translation d = P_B − P_A, its slope pair s (B's, ModelBuilder.add_slopes; A has none) and its turn θ_B − θ_A
    on the condensed beam stiffness at the station, per transverse direction (docs/model.md §8.8)

        [F; M] = −[[k_uu, k_us], [k_us, k_ss]] [d; s] − [[c_u, 0], [0, c_s]] [ḋ_A; ṡ_A],   T = −k_θ(θ_B − θ_A) − c_θ(θ̇_B − θ̇_A),

    F the force on B at its centre, M the generalised force on s, T the torque on B (−T on A). The stiffness part is
    the potential U = ½k_uu|d|² + k_us d·s + ½k_ss|s|² + ½k_θ(θ_B − θ_A)² (isotropic across the axis, so the same in
    any frame): its force −F acts on A at A's marker (−∂U/∂θ_A; the z-moment k_us d × s that this leaves is the
    slope pair's, as the invariance of U under a rigid turn requires). The damping acts on the rates seen from A,
    ḋ_A = ḋ − θ̇_A k × d and ṡ_A = ṡ − θ̇_A k × s (as :class:`BodySpring`): the translational damper's force acts on A
    at B's centre, the slope damper's M_c = −c_s ṡ_A puts the torque M_c·(−k × s) on A, so that their power is
    −c_u|ḋ_A|² − c_s|ṡ_A|²: no frame and no rigid motion of the pair makes a damping force. Local coordinates: A (x, y, θ), B (x, y, θ), s.

    ``slopes`` (n, 2): B's slope pair's full indices; ``marker_a`` (2,) or (n, 2): B's station on A in A's axes [m];
    ``k_uu`` [N/m], ``k_us`` [N/rad], ``k_ss`` [N m/rad], ``k_theta`` [N m/rad]; ``c_u``, ``c_s``, ``c_theta`` their
    dampings (≥ 0). Outputs: "fx", "fy" (F), "deflection" |d| [m], "slope_x", "slope_y" (s in R) [rad]."""
    batched = True
    n_local = 8
    compiled_twin = "generic.beam_support"

    def __init__(self, name, body_a, body_b, slopes, *, marker_a, k_uu, k_us, k_ss, k_theta, c_u=0.0, c_s=0.0,
                 c_theta=0.0):
        self.name = name
        slopes = np.atleast_2d(np.asarray(slopes, dtype=np.int64))
        if slopes.shape[-1] != 2:
            raise ModelError(f"{name}: slopes must be (n, 2) full indices (s_x, s_y), got shape {slopes.shape}")
        bodies = body_dofs(body_a, body_b)
        if slopes.shape[0] not in (1, bodies.shape[0]):
            raise ModelError(f"{name}: slopes must have one row per instance ({bodies.shape[0]}), got {slopes.shape[0]}")
        self.dofs = np.hstack([bodies, np.broadcast_to(slopes, (bodies.shape[0], 2))]).astype(np.int64)
        self.marker_a = self._per_instance_xy("marker_a", marker_a)
        self.k_uu = self._per_instance("k_uu", k_uu, positive=True)
        self.k_us = self._per_instance("k_us", k_us)
        self.k_ss = self._per_instance("k_ss", k_ss, positive=True)
        if np.any(self.k_us ** 2 >= self.k_uu * self.k_ss):
            raise ModelError(f"{name}: the stiffness [[k_uu, k_us], [k_us, k_ss]] must be positive definite "
                             f"(k_us^2 < k_uu k_ss), got k_us = {k_us!r}")
        self.k_theta = self._per_instance("k_theta", k_theta, positive=True)
        self.c_u = self._per_instance("c_u", c_u, nonneg=True)
        self.c_s = self._per_instance("c_s", c_s, nonneg=True)
        self.c_theta = self._per_instance("c_theta", c_theta, nonneg=True)

    def kernel(self, t, fs, q, v, z):
        qa, qb, s = q[:3], q[3:6], q[6:8]
        va, vb, ds = v[:3], v[3:6], v[6:8]
        Pa, ra = marker(qa, self.marker_a)
        Va = marker_velocity(va, ra)
        dx, dy = qb[0] - Pa[0], qb[1] - Pa[1]
        udx = vb[0] - Va[0] + va[2] * dy                 # ḋ_A = ḋ − θ̇_A k × d
        udy = vb[1] - Va[1] - va[2] * dx
        usx = ds[0] + va[2] * s[1]                       # ṡ_A = ṡ − θ̇_A k × s
        usy = ds[1] - va[2] * s[0]
        Kx, Ky = -self.k_uu * dx - self.k_us * s[0], -self.k_uu * dy - self.k_us * s[1]     # the beam's force
        Cx, Cy = -self.c_u * udx, -self.c_u * udy
        Fx, Fy = Kx + Cx, Ky + Cy
        Dx, Dy = -self.c_s * usx, -self.c_s * usy
        Mx = -self.k_us * dx - self.k_ss * s[0] + Dx
        My = -self.k_us * dy - self.k_ss * s[1] + Dy
        T = -self.k_theta * (qb[2] - qa[2]) - self.c_theta * (vb[2] - va[2])
        ex, ey = ra[0] + dx, ra[1] + dy                  # B's centre from A's centre
        # on A: the beam's force at A's marker (−∂U/∂θ_A), the damper's at B's centre, the slope damper's reaction
        torque_a = (-1.0 * (ra[0] * Ky - ra[1] * Kx) - (ex * Cy - ey * Cx) + (Dx * s[1] - Dy * s[0]) - T)
        forces = [-1.0 * Fx, -1.0 * Fy, torque_a, Fx, Fy, T, Mx, My]
        return forces, {"fx": Fx, "fy": Fy, "deflection": ad.hypot(dx, dy), "slope_x": s[0], "slope_y": s[1]}
