"""External forces on body centres, given in the fixed frame (e.g. the radial load of a bearing rig)."""
from __future__ import annotations

from typing import Callable

import numpy as np

from ..element import Element, body_dofs
from ..errors import ModelError


class ForceSource(Element):
    """Force (Fx, Fy) in the *fixed* frame on each body's centre, scaled by ``ramp(t)``.
    ``force`` is an (n, 2) / (2,) constant [N] or a callable t -> (n, 2)."""
    n_local = 3
    compiled_twin = "generic.force_source"

    def __init__(self, name, bodies, force, ramp: Callable[[float], float] | None = None):
        self.name = name
        self.dofs = body_dofs(bodies)
        if callable(force):
            self.fn, self.force = force, None
        else:
            f = np.asarray(force, dtype=float)
            self.fn, self.force = None, np.broadcast_to(f, (self.n, 2)).copy()
        self.ramp = ramp

    def check(self):
        if self.force is not None and not np.all(np.isfinite(self.force)):
            raise ModelError(f"{self.name}: force must be finite [N], got {self.force!r}")

    def kernel(self, t, fs, q, v, z):
        F = np.broadcast_to(np.asarray(self.fn(t), float), (self.n, 2)) if self.fn else self.force
        s = self.ramp(t) if self.ramp else 1.0
        c, sn = np.cos(fs.phi), np.sin(fs.phi)
        FX, FY = s * F[:, 0], s * F[:, 1]
        Fx, Fy = c * FX + sn * FY, -sn * FX + c * FY      # fixed frame → R
        return [Fx, Fy, np.zeros(self.n)], {"fx": FX, "fy": FY}
