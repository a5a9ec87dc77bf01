"""Step-size controllers: they alone accept/reject a step and choose the next h (diffrax's split)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import rules
from .errors import ModelError

__all__ = ["FixedStep", "Adaptive"]


@dataclass(frozen=True)
class FixedStep:
    """Constant h. A step whose Newton iteration fails is retried with h/2 (up to ``max_halvings``
    times) and the controller returns to h afterwards; the error estimate is only reported — except
    that a step whose scaled error estimate exceeds ``reject_error`` (default 1e6: 1 cm at the default
    10 nm tolerance) is treated as failed: a blown-up state must never be accepted (forces of 1e50 N
    were seen at h = 20 µs on the DPGT while a Newton defect, since fixed, accepted unconverged steps;
    the guard stays as a second line of defence)."""
    h: float
    max_halvings: int = 6
    reject_error: float = 1e6

    def __post_init__(self):
        if not (np.isfinite(self.h) and self.h > 0):
            raise ModelError(f"FixedStep.h must be > 0 s, got {self.h!r}")

    def initial(self) -> float:
        return self.h

    @property
    def h_min(self) -> float:
        return self.h / 2 ** self.max_halvings

    def decide(self, h: float, converged: bool, error: float) -> tuple[bool, float]:
        ok, h_next = rules.fixed_decide(h, converged, error, self.h, self.reject_error)
        return bool(ok), float(h_next)


@dataclass(frozen=True)
class Adaptive:
    """Accept when the scaled local error estimate (RMS) ≤ 1; next h from the error with exponent
    1/3 (local displacement error is O(h³)), a safety factor and growth limits.
    Newton failure → reject and h·``fail_factor``. Below ``h_min`` the loop raises."""
    h0: float
    h_min: float = 1e-10
    h_max: float = np.inf
    safety: float = 0.9
    grow_max: float = 2.0
    shrink_min: float = 0.2
    fail_factor: float = 0.25
    hold: float = 1.2    # keep h (and the LU) when the proposed change is within this factor up

    def __post_init__(self):
        if not (self.h0 > 0 and self.h_min > 0 and self.h_max >= self.h0 >= self.h_min):
            raise ModelError(f"Adaptive: need 0 < h_min <= h0 <= h_max [s], got h0={self.h0}, h_min={self.h_min}, h_max={self.h_max}")

    def initial(self) -> float:
        return self.h0

    def decide(self, h: float, converged: bool, error: float) -> tuple[bool, float]:
        ok, h_next = rules.adaptive_decide(h, converged, error, self.h_max, self.safety, self.grow_max,
                                           self.shrink_min, self.fail_factor, self.hold)
        return bool(ok), float(h_next)
