"""The operating point and the rigs around the machine: the source's test rig (carrier speed drive with its
ripple, sun-torque ramp, accelerometer) and the single-bearing test rig (docs/model.md §1.3, §10.3, §10.5)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from ..units import Quantity
from ..units import ParameterError
from ._machinery import SI, Params, computed, entries, nested, nonneg, param, positive, rule, si_of
from .sensor import SensorParams, SensorSI

__all__ = ["OperatingPoint", "OperatingSI", "SchedulePointParams", "SchedulePointSI", "CarrierRippleParams", "CarrierRippleSI", "RigParams", "RigSI",
           "BearingRigParams", "BearingRigSI"]


@dataclass(frozen=True, kw_only=True)
class SchedulePointParams(Params["SchedulePointSI"]):
    """One knot of the operating point's schedule in time (docs/model.md §10.3): the carrier speed and the torques
    as fractions of the operating point's, linearly interpolated between knots."""
    _prefix: ClassVar[str] = "operating.schedule"
    time: Quantity = nonneg("time", "time of the knot from the run's start")
    speed: Quantity = nonneg("dimensionless", "carrier speed reference there, a fraction of operating.carrier_speed")
    torque: Quantity = param("dimensionless", "sun torque there, a fraction of the operating point's "
                                              "(output_power at carrier_speed)")


@si_of(SchedulePointParams)
class SchedulePointSI(SI):
    time: float
    speed: float
    torque: float


@dataclass(frozen=True, kw_only=True)
class OperatingPoint(Params["OperatingSI"]):
    """Ring fixed, sun driven, carrier loaded. ``carrier_speed`` is a magnitude; ``direction`` gives
    its sense (forward = counter-clockwise seen from the input side = positive); ``output_power`` < 0 brakes (the
    carrier drives the sun: the torques turn over, the speeds stay).

    ``schedule`` (empty: a steady operating point): knots (time, speed, torque) of a piecewise-linear schedule —
    the carrier drive's speed reference is ``speed`` × carrier_speed and the sun torque ``torque`` × its steady
    value, linear between knots and held before the first and after the last (a start-up, a load drop; docs/model.md
    §10.3). Times must increase strictly.

    si(): carrier_speed signed [rad/s], output_power [W], direction (str) and sign (±1);
    ``DPGTParams.si().operating`` adds the nominal speeds and torques (:class:`geometry.Kinematics`).
    """

    _prefix: ClassVar[str] = "operating"
    carrier_speed: Quantity = param("angular_velocity", "carrier speed magnitude n_c", lo=0.0,
                                    bound_text=">= 0 (give the sense with direction)")
    output_power: Quantity = param("power", "output power P (> 0 driving: the sun drives the carrier; < 0 braking: "
                                            "the carrier drives the sun)")
    direction: str = param("choice", "sense of rotation", choices=("forward", "reverse"), default="forward")
    schedule: tuple[SchedulePointParams, ...] = entries(SchedulePointParams, "a schedule in time of the carrier "
                                                        "speed and the torque, fractions of the point's (empty: steady)")

    def __post_init__(self):
        super().__post_init__()
        times = [k.time for k in self.schedule]
        for i in range(1, len(times)):
            if not times[i] > times[i - 1]:
                raise ParameterError.at(f"operating.schedule[{i}].time", f"must be later than the knot before "
                                                                          f"({times[i - 1]}), got {times[i]}")

    def _si_values(self, v):
        sign = 1 if v["direction"] == "forward" else -1
        return dict(sign=sign, carrier_speed=sign * v["carrier_speed"])


@si_of(OperatingPoint)
class OperatingSI(SI):
    carrier_speed: float = computed("signed carrier speed [rad/s] (+: forward)")
    output_power: float
    direction: str
    schedule: tuple[SchedulePointSI, ...]
    sign: int = computed("+1 forward, -1 reverse")


def _ripple_amplitude(order: int):
    return param("angular_velocity", f"amplitude A_{order} of the carrier speed reference's ripple at {order} x f_c",
                 lo=0.0, bound_text=">= 0 rad/s (the phase gives its sign)")


@dataclass(frozen=True, kw_only=True)
class CarrierRippleParams(Params["CarrierRippleSI"]):
    """Carrier-synchronous speed ripple of the rig's carrier speed drive (docs/model.md §10.3: the loading motor and
    its coupling). The drive's speed reference becomes ω_c + Σ_k A_k cos(k ω_c t + φ_k) over the orders
    k = 1, 2, 4 of the carrier frequency, its angle reference the exact integral
    (:class:`mbd.elements.SpeedDrive` ``ripple``). Every amplitude 0: an ideal drive."""

    _prefix: ClassVar[str] = "carrier_ripple"
    ORDERS: ClassVar[tuple] = (1, 2, 4)
    amplitude_1: Quantity = _ripple_amplitude(1)
    phase_1: Quantity = param("angle", "phase of the order-1 ripple at t = 0")
    amplitude_2: Quantity = _ripple_amplitude(2)
    phase_2: Quantity = param("angle", "phase of the order-2 ripple at t = 0")
    amplitude_4: Quantity = _ripple_amplitude(4)
    phase_4: Quantity = param("angle", "phase of the order-4 ripple at t = 0")


@si_of(CarrierRippleParams)
class CarrierRippleSI(SI):
    amplitude_1: float
    phase_1: float
    amplitude_2: float
    phase_2: float
    amplitude_4: float
    phase_4: float


@dataclass(frozen=True, kw_only=True)
class RigParams(Params["RigSI"]):
    """The source's test rig around the train (docs/model.md §10.3): the loading motor holds the carrier at its
    speed through a PI speed drive (stiffness, damping and integral gain from the bandwidth and damping
    ratio on the train's kinetic inertia), with its carrier-synchronous speed ripple, and the driving
    motor's sun torque is ramped in."""

    _prefix: ClassVar[str] = "rig"
    carrier_drive_bandwidth: Quantity = positive("frequency", "bandwidth of the carrier speed drive")
    carrier_drive_damping_ratio: Quantity = nonneg("dimensionless", "damping ratio of the carrier speed drive")
    carrier_ripple: CarrierRippleParams = nested(CarrierRippleParams, "speed ripple of the carrier drive at "
                                                                      "orders 1, 2, 4 of f_c")
    load_ramp_mesh_periods: Quantity = nonneg("dimensionless", "length of the sun-torque ramp in mesh periods "
                                                               "(0: the full torque at t = 0)")
    load_ramp_max: Quantity = nonneg("time", "longest sun-torque ramp (near-zero speeds have no mesh period)")
    sensor: SensorParams = nested(SensorParams, "the accelerometer on the housing (recorded when a run asks)")


@si_of(RigParams)
class RigSI(SI):
    carrier_drive_bandwidth: float
    carrier_drive_damping_ratio: float
    carrier_ripple: CarrierRippleSI
    load_ramp_mesh_periods: float
    load_ramp_max: float
    sensor: SensorSI


@dataclass(frozen=True, kw_only=True)
class BearingRigParams(Params["BearingRigSI"]):
    """The single-bearing test rig (:func:`components.rig.build_bearing_rig`, docs/model.md §10.5): a
    planet-like outer ring on the bearing, its spin held by a speed drive, the radial load ramped in and
    a settling dashpot from the ring to ground. The ramp and the dashpot do not change the static solution."""

    _prefix: ClassVar[str] = "bearing_rig"
    ring_mass: Quantity = positive("mass", "outer ring mass")
    ring_radius: Quantity = positive("length", "outer ring radius for its inertia rule")
    ring_inertia: Quantity | None = rule("inertia", "assumed", "solid disc of the ring radius, m r^2/2")
    ring_tilt_inertia: Quantity | None = rule("inertia", "assumed", "thin disc: half the polar inertia",
                                              "the ring's diametral moment of inertia (its slopes: the sliced model)")
    tilt_support_stiffness: Quantity = positive("torsional_stiffness", "the housing's support holding the ring's "
                                                                       "slope at zero, the pin carrying the given tilt "
                                                                       "(the sliced model)")
    drive_bandwidth: Quantity = positive("frequency", "bandwidth of the ring's speed drive")
    drive_damping_ratio: Quantity = nonneg("dimensionless", "damping ratio of the ring's speed drive")
    settle_damping_ratio: Quantity = nonneg("dimensionless", "ring-to-ground dashpot as a fraction of the critical "
                                                             "damping of the ring's radial mode on the loaded bearing")
    load_ramp_periods: Quantity = nonneg("dimensionless", "length of the load ramp in periods of that radial mode")
    gravity: Quantity = nonneg("acceleration", "gravitational acceleration along -y (scene option gravity)")

    def _si_values(self, v):
        J = v["ring_inertia"] if v["ring_inertia"] is not None else 0.5 * v["ring_mass"] * v["ring_radius"] ** 2
        return dict(ring_inertia=J,
                    ring_tilt_inertia=v["ring_tilt_inertia"] if v["ring_tilt_inertia"] is not None else 0.5 * J)


@si_of(BearingRigParams)
class BearingRigSI(SI):
    ring_mass: float
    ring_radius: float
    ring_inertia: float = computed("outer ring polar moment of inertia [kg m^2] (given, or the rule)")
    ring_tilt_inertia: float = computed("outer ring diametral moment of inertia [kg m^2] (given, or the rule)")
    tilt_support_stiffness: float
    drive_bandwidth: float
    drive_damping_ratio: float
    settle_damping_ratio: float
    load_ramp_periods: float
    gravity: float
