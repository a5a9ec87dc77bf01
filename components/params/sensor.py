"""Parameters of the rig's accelerometer and the housing it sits on (docs/model.md §12)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from ..units import Quantity
from ._machinery import SI, Params, nested, nonneg, param, positive, si_of

__all__ = ["HousingParams", "HousingSI", "SensorParams", "SensorSI"]


@dataclass(frozen=True, kw_only=True)
class HousingParams(Params["HousingSI"]):
    """The housing the rig's accelerometer sits on, as two rigid-body modes on its mounting (docs/model.md §12),
    each a linear mass–spring–damper driven one way by what the train puts on the housing
    (:mod:`components.sensor`): a translation (modal mass m_h, the same in x and y) and a rocking about the
    mounting's elastic centre O, ``rocking_centre_depth`` below the gear axis (a gearbox on feet rocks about
    its foot plane), with modal inertia J_O about O. Each mode: natural frequency and damping ratio."""

    _prefix: ClassVar[str] = "housing"
    mass: Quantity = positive("mass", "modal mass m_h of the housing's translation (the housing's mass)")
    translation_frequency: Quantity = positive("frequency", "natural frequency of the housing's translation on its "
                                                            "mounting")
    translation_damping_ratio: Quantity = positive("dimensionless", "damping ratio of the housing's translation")
    rocking_inertia: Quantity = positive("inertia", "modal inertia J_O of the housing's rocking about its mounting's "
                                                    "elastic centre O")
    rocking_frequency: Quantity = positive("frequency", "natural frequency of the housing's rocking on its mounting")
    rocking_damping_ratio: Quantity = positive("dimensionless", "damping ratio of the housing's rocking")
    rocking_centre_depth: Quantity = nonneg("length", "depth h of the rocking centre O below the gear axis "
                                                      "(along -Y of the fixed frame, the foot plane)")


@si_of(HousingParams)
class HousingSI(SI):
    mass: float
    translation_frequency: float
    translation_damping_ratio: float
    rocking_inertia: float
    rocking_frequency: float
    rocking_damping_ratio: float
    rocking_centre_depth: float


@dataclass(frozen=True, kw_only=True)
class SensorParams(Params["SensorSI"]):
    """The rig's accelerometer on the housing (docs/model.md §12) at angle ``angle`` ψ_s of the fixed frame and
    distance ``radius`` from the gear axis, along its axis e (radial at ψ_s, or tangential 90° ahead). It reads
    the sum of three paths (:mod:`components.sensor`):

    * mesh: Σ_n w(ψ_n − ψ_s)·(F_n·e)/m_eq — each outer planet's ring-mesh force on the ring F_n weighted by a
      Hann window w of full angular width ``window_width`` of the planet's distance from the sensor (McFadden &
      Smith 1985; Inalpolat & Kahraman 2009), m_eq = ``equivalent_mass``;
    * torque: the housing's rocking (``housing``) driven by the ring's torsional support torque;
    * bearing: the housing's translation and rocking driven by the sun's and carrier's bearing forces and the
      ring's seat force."""

    _prefix: ClassVar[str] = "sensor"
    angle: Quantity = param("angle", "angle psi_s of the sensor on the housing, in the fixed frame")
    radius: Quantity = positive("length", "distance of the sensor from the gear axis")
    window_width: Quantity = param("angle", "full angular width of the Hann window over which a passing "
                                            "planet's ring-mesh force reaches the sensor",
                                   lo=0.0, hi=2.0 * math.pi, lo_open=True, bound_text="in (0, 360 deg]")
    equivalent_mass: Quantity = positive("mass", "equivalent mass m_eq of the mesh path: mesh force / m_eq is the "
                                                 "acceleration the sensor reads")
    direction: str = param("choice", "sensor axis: radial (through the ring's axis) or tangential",
                           choices=("radial", "tangential"))
    housing: HousingParams = nested(HousingParams, "the housing's translation and rocking (torque and bearing paths)")


@si_of(SensorParams)
class SensorSI(SI):
    angle: float
    radius: float
    window_width: float
    equivalent_mass: float
    direction: str
    housing: HousingSI
