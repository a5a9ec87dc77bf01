"""Drives and loads: torque sources and speed drives (a speed-controlled motor)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..element import Element, body_dofs
from ..errors import ModelError


@dataclass(frozen=True)
class Ramp:
    """Smooth (C¹) ramp 0 → 1 between t0 and t1: loads are applied without an impulse."""
    t0: float = 0.0
    t1: float = 0.0

    def __post_init__(self):
        if not (np.isfinite(self.t0) and np.isfinite(self.t1) and self.t1 >= self.t0):
            raise ModelError(f"Ramp: need finite t0 <= t1 [s], got t0={self.t0!r}, t1={self.t1!r}")

    def __call__(self, t: float) -> float:
        if t >= self.t1:
            return 1.0
        if t <= self.t0:
            return 0.0
        s = (t - self.t0) / (self.t1 - self.t0)
        return s * s * (3.0 - 2.0 * s)


class TorqueSource(Element):
    """Torque on bodies: ``torque`` [N·m] scalar/(n,) constant, scaled by ``ramp`` (a callable of t),
    or ``torque`` a callable t -> (n,) torques."""
    n_local = 3
    compiled_twin = "generic.torque_source"

    def __init__(self, name, bodies, torque, ramp: Callable[[float], float] | None = None):
        self.name = name
        self.dofs = body_dofs(bodies)
        if callable(torque):
            self.fn, self.torque = torque, None
        else:
            self.fn, self.torque = None, self._per_instance("torque", torque)
        self.ramp = ramp

    def torque_at(self, t):
        T = np.broadcast_to(np.asarray(self.fn(t), float), (self.n,)) if self.fn else self.torque
        return T * (self.ramp(t) if self.ramp else 1.0)

    def kernel(self, t, fs, q, v, z):
        T = self.torque_at(t)
        zero = np.zeros(self.n)
        return [zero, zero, T], {"torque": T}


class SpeedDrive(Element):
    """Speed-controlled motor: torsional spring-damper (and optional integral term) between a body's
    angle in the *fixed* frame and the prescribed angle θ_ref(t) = theta0 + ω_ref·t.

    T = k (θ_ref − θ) + c (ω_ref − θ̇) + k_i ∫(θ_ref − θ) dt. The integral is an internal state,
    advanced (trapezoidal rule) after each accepted step and held constant within a step.
    ``omega_ref`` may be a callable t -> (θ_ref, ω_ref) for speed profiles.

    ``ripple``: harmonics (Ω_j [rad/s], A_j [rad/s], φ_j [rad]) added to a constant speed (a motor's
    speed ripple): ω_ref(t) = ω + Σ_j A_j cos(Ω_j t + φ_j) and θ_ref(t) = θ0 + ω t + Σ_j (A_j/Ω_j)
    sin(Ω_j t + φ_j), its exact integral. Without ripple the reference is evaluated as without the term.
    """
    n_local = 3
    compiled_twin = "generic.speed_drive"

    def __init__(self, name, body, omega_ref, k, c=0.0, k_i=0.0, theta0=0.0, ripple=None):
        self.name = name
        self.dofs = body_dofs(body)
        self.theta0 = self.omega_ref = None        # constant speed: θ0 (n,) and ω_ref [rad/s]
        self.ripple = self._ripple(ripple)
        if callable(omega_ref):
            if self.ripple.size:
                raise ModelError(f"{name}: ripple needs a constant omega_ref (a profile carries its own)")
            self.profile = omega_ref
        else:
            w = float(omega_ref)
            if not np.isfinite(w):
                raise ModelError(f"{name}: omega_ref must be a finite speed in rad/s, got {omega_ref!r}")
            th0 = self._per_instance("theta0", theta0)
            self.theta0, self.omega_ref = th0, w
            if self.ripple.size:
                self.profile = lambda t: self._rippled(t, th0, w)
            else:
                self.profile = lambda t: (th0 + w * t, np.full(self.n, w))
        self.stiffness = self._per_instance("k", k, positive=True)
        self.damping = self._per_instance("c", c, nonneg=True)
        self.k_i = self._per_instance("k_i", k_i, nonneg=True)

    def _ripple(self, ripple) -> np.ndarray:
        """(m, 3) harmonics [Ω, A, φ]: finite, Ω ≠ 0 (θ_ref holds A/Ω)."""
        h = np.zeros((0, 3)) if ripple is None else np.asarray(ripple, dtype=float)
        if h.size % 3 or not np.all(np.isfinite(h)) or np.any(h.reshape(-1, 3)[:, 0] == 0.0):
            raise ModelError(f"{self.name}: ripple must be finite (Ω [rad/s], A [rad/s], φ [rad]) rows with "
                             f"Ω != 0, got {ripple!r}")
        return h.reshape(-1, 3)

    def _rippled(self, t, th0, w):
        dth, dw = 0.0, 0.0
        for Om, A, ph in self.ripple:          # the compiled kernel sums in the same order
            dth = dth + A / Om * np.sin(Om * t + ph)
            dw = dw + A * np.cos(Om * t + ph)
        return (th0 + w * t) + dth, np.full(self.n, w + dw)

    def init_internal(self):
        return np.zeros(self.n) if np.any(self.k_i > 0) else None

    def _error(self, t, fs, q, v):
        th_ref, w_ref = self.profile(t)
        return th_ref - (q[2] + fs.phi), w_ref - (v[2] + fs.omega)

    def kernel(self, t, fs, q, v, z):
        e, de = self._error(t, fs, q, v)
        T = self.stiffness * e + self.damping * de
        if z is not None:
            T = T + self.k_i * z
        zero = 0.0 * q[0]
        return [zero, zero, T], {"torque": T, "angle_error": e}

    def update_internal(self, z, t0, t1, fs0, fs1, q0, v0, q1, v1):
        if z is None:
            return z
        e0, _ = self._error(t0, fs0, q0, v0)
        e1, _ = self._error(t1, fs1, q1, v1)
        return z + 0.5 * (t1 - t0) * (e0 + e1)
