"""Drives and loads: torque sources and speed drives (a speed-controlled motor), each optionally following a
piecewise-linear schedule in time (:class:`Schedule`)."""
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


@dataclass(frozen=True)
class Schedule:
    """A piecewise-linear factor of time f(t) through the knots (t_k, f_k), k = 0 … m−1: linear between knots,
    f_0 before t_0 and f_{m−1} after t_{m−1} (one knot: a constant). ``times`` [s] strictly increasing and finite,
    ``values`` [1] finite. A drive or load multiplies its nominal value by f (a speed schedule's angle reference
    is the exact integral, :meth:`excess`).

    ``packed`` is the layout the compiled kernels read (:mod:`mbd.compiled.generic`): [m, t_0…, f_0…, C_0…], with
    C_k = ∫_{t_0}^{t_k} (f − 1) dτ at the knots (trapezoids: exact for a piecewise-linear f)."""
    times: tuple
    values: tuple

    def __post_init__(self):
        t = np.asarray(self.times, dtype=float).ravel()
        f = np.asarray(self.values, dtype=float).ravel()
        if t.size < 1 or t.size != f.size:
            raise ModelError(f"Schedule: need as many times as values (at least one knot), got {t.size} times and "
                             f"{f.size} values")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(f))):
            raise ModelError(f"Schedule: times [s] and values must be finite, got {list(t)} and {list(f)}")
        if np.any(np.diff(t) <= 0.0):
            raise ModelError(f"Schedule: times must increase strictly [s], got {list(t)}")
        object.__setattr__(self, "times", tuple(float(x) for x in t))
        object.__setattr__(self, "values", tuple(float(x) for x in f))
        C = np.zeros(t.size)
        for k in range(1, t.size):      # ∫ (f − 1) over each segment, the same sums the kernels read
            C[k] = C[k - 1] + (t[k] - t[k - 1]) * ((f[k - 1] - 1.0) + 0.5 * (f[k] - f[k - 1]))
        object.__setattr__(self, "_packed", np.concatenate([[float(t.size)], t, f, C]))

    @property
    def packed(self) -> np.ndarray:
        return self._packed

    def __call__(self, t: float) -> float:
        """f(t)."""
        return schedule_at(self._packed, t)[0]

    def excess(self, t: float) -> float:
        """∫_0^t (f(τ) − 1) dτ [s]: what a speed schedule adds to the constant-speed angle ω t, divided by ω
        (exactly 0 for f ≡ 1, so a schedule of ones leaves the constant-speed reference bit for bit)."""
        return schedule_at(self._packed, t)[1]

    def is_constant(self) -> bool:
        return len(set(self.values)) == 1


def _excess_from_start(S, t: float) -> tuple[float, float]:
    """(f(t), ∫_{t_0}^{t} (f − 1) dτ) of the packed schedule S (:attr:`Schedule.packed`)."""
    m = int(S[0])
    if t <= S[1]:
        f = S[1 + m]
        return f, (f - 1.0) * (t - S[1])
    if t >= S[m]:
        f = S[2 * m]
        return f, S[3 * m] + (f - 1.0) * (t - S[m])
    k = 0
    while S[2 + k] <= t:        # the segment [t_k, t_{k+1}) holding t
        k += 1
    tk, fk = S[1 + k], S[1 + m + k]
    f = fk + (S[2 + m + k] - fk) * (t - tk) / (S[2 + k] - tk)
    return f, S[1 + 2 * m + k] + (t - tk) * ((fk - 1.0) + 0.5 * (f - fk))


def schedule_at(S, t: float) -> tuple[float, float]:
    """(f(t), ∫_0^t (f − 1) dτ) of the packed schedule S; the compiled kernels repeat these operations."""
    f, e = _excess_from_start(S, t)
    return f, e - _excess_from_start(S, 0.0)[1]


class TorqueSource(Element):
    """Torque on bodies: ``torque`` [N·m] scalar/(n,) constant, scaled by ``ramp`` (a callable of t) and by
    ``schedule`` (a :class:`Schedule`: T(t) = T_0 ρ(t) f(t)), or ``torque`` a callable t -> (n,) torques."""
    n_local = 3
    compiled_twin = "generic.torque_source"

    def __init__(self, name, bodies, torque, ramp: Callable[[float], float] | None = None,
                 schedule: Schedule | None = None):
        self.name = name
        self.dofs = body_dofs(bodies)
        if callable(torque):
            self.fn, self.torque = torque, None
        else:
            self.fn, self.torque = None, self._per_instance("torque", torque)
        self.ramp = ramp
        if schedule is not None and not isinstance(schedule, Schedule):
            raise ModelError(f"{name}: schedule must be an mbd.elements.Schedule, got {schedule!r}")
        self.schedule = schedule

    def torque_at(self, t):
        T = np.broadcast_to(np.asarray(self.fn(t), float), (self.n,)) if self.fn else self.torque
        T = T * (self.ramp(t) if self.ramp else 1.0)
        return T if self.schedule is None else T * self.schedule(t)

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

    ``schedule``: a :class:`Schedule` f(t) of the speed (a run-up, a run-down): ω_ref(t) = ω f(t) and
    θ_ref(t) = θ0 + ω t + ω ∫_0^t (f − 1) dτ, its exact integral (a schedule of ones: the constant-speed
    reference bit for bit). Not with ripple (its harmonics are tied to a constant speed).
    """
    n_local = 3
    compiled_twin = "generic.speed_drive"

    def __init__(self, name, body, omega_ref, k, c=0.0, k_i=0.0, theta0=0.0, ripple=None,
                 schedule: Schedule | None = None):
        self.name = name
        self.dofs = body_dofs(body)
        self.theta0 = self.omega_ref = None        # constant speed: θ0 (n,) and ω_ref [rad/s]
        self.ripple = self._ripple(ripple)
        if schedule is not None and not isinstance(schedule, Schedule):
            raise ModelError(f"{name}: schedule must be an mbd.elements.Schedule, got {schedule!r}")
        if schedule is not None and (self.ripple.size or callable(omega_ref)):
            raise ModelError(f"{name}: a speed schedule needs a constant omega_ref without ripple")
        self.schedule = schedule
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
            elif schedule is not None:
                self.profile = lambda t: self._scheduled(t, th0, w)
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

    def _scheduled(self, t, th0, w):
        f, e = schedule_at(self.schedule.packed, t)     # the compiled kernel computes the same
        return (th0 + w * t) + w * e, np.full(self.n, w * f)

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
