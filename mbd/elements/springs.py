"""Linear spring-dampers: body–ground supports, body–body bushings between markers, torsional springs."""
from __future__ import annotations

import numpy as np

from .. import ad
from ..element import Element, body_dofs, marker, marker_velocity, point_force


class GroundSupport(Element):
    """Spring-damper from each body's centre to an anchor fixed in the inertial frame.

    Translational stiffness ``kx``, ``ky`` (and damping ``cx``, ``cy``) act along the *fixed*
    frame's axes; ``ky=None`` means isotropic (then the support is the same in R and I). Optional
    torsional spring ``k_theta``/``c_theta`` to the fixed angle ``theta0``. Damping acts on the
    velocity relative to ground, so a support in a rotating frame does not drag the body along R.
    """
    batched = True
    n_local = 3
    compiled_twin = "generic.ground_support"

    def __init__(self, name, bodies, kx, cx=0.0, ky=None, cy=None, anchor=(0.0, 0.0),
                 k_theta=0.0, c_theta=0.0, theta0=0.0):
        self.name = name
        self.dofs = body_dofs(bodies)
        self.kx = self._per_instance("kx", kx, nonneg=True)
        self.ky = self.kx if ky is None else self._per_instance("ky", ky, nonneg=True)
        self.cx = self._per_instance("cx", cx, nonneg=True)
        self.cy = self.cx if cy is None else self._per_instance("cy", cy, nonneg=True)
        self.isotropic = ky is None and cy is None
        self.anchor = self._per_instance_xy("anchor", anchor)
        self.k_theta = self._per_instance("k_theta", k_theta, nonneg=True)
        self.c_theta = self._per_instance("c_theta", c_theta, nonneg=True)
        self.theta0 = self._per_instance("theta0", theta0)

    def kernel(self, t, fs, q, v, z):
        c, s = np.cos(fs.phi), np.sin(fs.phi)
        W = fs.omega
        ax, ay = self.anchor[:, 0], self.anchor[:, 1]
        # displacement and ground-relative velocity, expressed in R
        dx = q[0] - (c * ax + s * ay)
        dy = q[1] - (-s * ax + c * ay)
        ux = v[0] - W * q[1]
        uy = v[1] + W * q[0]
        if self.isotropic:
            Fx = -self.kx * dx - self.cx * ux
            Fy = -self.kx * dy - self.cx * uy
        else:  # rotate into I, apply the axis-aligned law, rotate back
            dX, dY = c * dx - s * dy, s * dx + c * dy
            uX, uY = c * ux - s * uy, s * ux + c * uy
            FX = -self.kx * dX - self.cx * uX
            FY = -self.ky * dY - self.cy * uY
            Fx, Fy = c * FX + s * FY, -s * FX + c * FY
        T = -self.k_theta * (q[2] + fs.phi - self.theta0) - self.c_theta * (v[2] + W)
        return [Fx, Fy, T], {"fx": Fx, "fy": Fy, "torque": T}


class BodySpring(Element):
    """Isotropic bushing between a marker on body A and a marker on body B.

    F_B = −k d − c ḋ_A with d = P_B − P_A and ḋ_A = (Ṗ_B − Ṗ_A) − θ̇_A k × d, the rate of the
    deflection seen from body A. F_B acts on B at its marker P_B and −F_B on A at the same point, so
    forces and moments balance exactly, the spring is conservative, the damper only dissipates (its
    power is −c|ḋ_A|²) and neither a rigid motion of the pair nor the choice of reference frame
    produces a damping force (the R-frame rate Ṗ_B − Ṗ_A alone would make the damper depend on Ω).
    Typical use: a planet (B, marker at its centre) on a linear bearing to its pin (A, the carrier).
    """
    batched = True
    n_local = 6
    compiled_twin = "generic.body_spring"

    def __init__(self, name, body_a, body_b, k, c=0.0, marker_a=(0.0, 0.0), marker_b=(0.0, 0.0)):
        self.name = name
        self.dofs = body_dofs(body_a, body_b)
        self.stiffness = self._per_instance("k", k, nonneg=True)
        self.damping = self._per_instance("c", c, nonneg=True)
        self.marker_a = self._per_instance_xy("marker_a", marker_a)
        self.marker_b = self._per_instance_xy("marker_b", marker_b)

    def kernel(self, t, fs, q, v, z):
        qa, qb, va, vb = q[:3], q[3:], v[:3], v[3:]
        Pa, ra = marker(qa, self.marker_a)
        Pb, rb = marker(qb, self.marker_b)
        Va = marker_velocity(va, ra)
        Vb = marker_velocity(vb, rb)
        dx, dy = Pb[0] - Pa[0], Pb[1] - Pa[1]
        ux = Vb[0] - Va[0] + va[2] * dy        # ḋ_A = Ṗ_B − Ṗ_A − θ̇_A k × d: the velocity of P_B
        uy = Vb[1] - Va[1] - va[2] * dx        # relative to the point of A under it
        Fx = -self.stiffness * dx - self.damping * ux
        Fy = -self.stiffness * dy - self.damping * uy
        fa = point_force((ra[0] + dx, ra[1] + dy), (-Fx, -Fy))   # both at P_B
        fb = point_force(rb, (Fx, Fy))
        return fa + fb, {"fx": Fx, "fy": Fy, "deflection": ad.hypot(dx, dy)}


class TorsionalSpring(Element):
    """Torsional spring-damper on the relative angle θ_B − θ_A − θ0 of two bodies."""
    batched = True
    n_local = 6
    compiled_twin = "generic.torsional_spring"

    def __init__(self, name, body_a, body_b, k, c=0.0, theta0=0.0):
        self.name = name
        self.dofs = body_dofs(body_a, body_b)
        self.stiffness = self._per_instance("k", k, nonneg=True)
        self.damping = self._per_instance("c", c, nonneg=True)
        self.theta0 = self._per_instance("theta0", theta0)

    def kernel(self, t, fs, q, v, z):
        T = -self.stiffness * (q[5] - q[2] - self.theta0) - self.damping * (v[5] - v[2])
        zero = 0.0 * q[0]
        return [zero, zero, -T, zero, zero, T], {"torque": T}
