"""Integrator settings as one frozen object, and the production preset every scenario starts from.

``PRODUCTION`` is the setting the studies run with (README "Defaults, and why"; measured in
docs/numerics.md): HHT-α with α = −0.3 (damps unresolved contact ringing), adaptive steps with a local
displacement error of 10 nm (1e-3 of a Hertz deflection) and 1 µrad, h ≤ 10 µs. A study changes
it with ``dataclasses.replace(PRODUCTION, ...)``, never by restating it. The engine is "auto": the
compiled path (:mod:`mbd.compiled`, ~12× faster on the DPGT) wherever it can be built, else numpy.
"""
from __future__ import annotations

from dataclasses import dataclass

from .control import Adaptive, FixedStep
from .errors import ModelError
from .hht import HHT, Tolerance

__all__ = ["IntegratorSettings", "PRODUCTION"]


@dataclass(frozen=True)
class IntegratorSettings:
    """``method``: "hht-adaptive" or "hht-fixed"; ``alpha`` HHT α; ``h`` the fixed step or the adaptive
    controller's first step [s]; ``h_max``/``h_min`` its bounds [s]; ``atol_pos`` [m], ``atol_rot`` [rad]
    the local error the adaptive controller holds (and the scale of Newton's tolerance); ``engine`` the
    engine path of :func:`mbd.simulate` ("auto", "compiled" or "numpy")."""
    method: str
    alpha: float
    h: float
    h_max: float
    h_min: float
    atol_pos: float
    atol_rot: float
    engine: str

    def __post_init__(self):
        if self.method not in ("hht-adaptive", "hht-fixed"):
            raise ModelError(f"integration.method must be 'hht-adaptive' or 'hht-fixed', got {self.method!r}")
        if self.engine not in ("auto", "compiled", "numpy"):
            raise ModelError(f"integration.engine must be 'auto', 'compiled' or 'numpy', got {self.engine!r}")
        self.stepper()       # checks α and the tolerances
        self.controller()    # checks the steps

    def stepper(self) -> HHT:
        return HHT(alpha=self.alpha, tol=Tolerance(atol_pos=self.atol_pos, atol_rot=self.atol_rot))

    def controller(self):
        if self.method == "hht-fixed":
            return FixedStep(self.h)
        return Adaptive(h0=self.h, h_max=self.h_max, h_min=self.h_min)


PRODUCTION = IntegratorSettings(method="hht-adaptive", alpha=-0.3, h=5e-6, h_max=1e-5, h_min=1e-9,
                                atol_pos=1e-8, atol_rot=1e-6, engine="auto")
