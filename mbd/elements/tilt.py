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

from ..errors import ModelError
from ..element import Element

__all__ = ["SlopeGyroscopic", "CoordinateSpring"]


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
