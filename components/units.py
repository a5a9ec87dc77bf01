"""Units for the components package: one pint registry, checked conversion, SI floats.

Everything user-facing (parameters, presets, scenario files) carries units; everything inside the
engine is plain SI floats. This module is the only bridge:

* ``ureg`` / ``Q_`` — THE registry of the package (pint quantities from different registries cannot be
  mixed; quantities from another registry are re-parsed into this one).
* :func:`quantity` — turn a user value (pint quantity, string such as ``"3 mm"``, ``"4200 rpm"``,
  ``"200 kW"``, ``"20 deg"``, or a bare number for dimensionless values) into a quantity of the
  expected kind, or raise :class:`ParameterError` naming the parameter, the value and the expected unit.
* :func:`to_si` — a quantity as a float in SI base units (radians for angles, rad/s for speeds).

Angles: pint treats the radian as dimensionless, so "1 Hz" converts to "1 rad/s" without complaint
(a factor 2π error for a speed meant as revolutions per second), and "600 rpm" to "62.8 Hz" (not 10).
Angular velocities must therefore carry an angle unit (rad/s, rpm, rev/s, deg/s); ``Hz`` and ``1/s`` are
refused as ambiguous. A frequency (cycles per second) given as a rotation speed is converted with one cycle =
one revolution = 2π rad ("600 rpm" → 10 Hz, "62.83 rad/s" → 10 Hz, "360 deg/s" → 1 Hz), never with pint's
radian = 1. Angles likewise need an angle unit (``"20 deg"``, ``"0.35 rad"``): a bare number could be either.
"""
from __future__ import annotations

import math
import numbers
from fractions import Fraction
from typing import NamedTuple

import pint

__all__ = ["ureg", "Q_", "Quantity", "ParameterError", "KINDS", "Kind", "quantity", "to_si", "format_quantity",
           "unit_text"]

ureg = pint.UnitRegistry()
ureg.define("rev = revolution")  # "rev/s", "rev/min" read naturally next to pint's built-in "rpm"
Q_ = ureg.Quantity
Quantity = pint.Quantity


class ParameterError(ValueError):
    """An invalid parameter value. ``parameter`` is the dotted name at fault (None if not one value)."""

    def __init__(self, message: str, parameter: str | None = None, problem: str | None = None):
        super().__init__(message)
        self.parameter = parameter
        self.problem = problem

    @classmethod
    def at(cls, parameter: str, problem: str) -> "ParameterError":
        """The standard form: ``"<parameter>: <problem>"``."""
        return cls(f"{parameter}: {problem}", parameter=parameter, problem=problem)

    def renamed(self, old_prefix: str, new_prefix: str) -> "ParameterError":
        """The same error with the parameter's leading ``old_prefix`` replaced (for nested objects)."""
        if self.parameter is None or self.problem is None:
            return self
        name = self.parameter
        if old_prefix and (name == old_prefix or name.startswith(old_prefix + ".")):
            name = name[len(old_prefix):]
            name = new_prefix + name if new_prefix else name.lstrip(".")
        elif not old_prefix and new_prefix:
            name = f"{new_prefix}.{name}"
        return ParameterError.at(name, self.problem)


class Kind(NamedTuple):
    label: str        # "a length": used in error messages
    si_unit: str      # the SI unit whose dimensionality defines the kind (and TOML output unit)
    example: str      # a valid value shown in error messages
    angle_power: int = 0  # required power of the radian in the base units (angles, angular speeds)


KINDS: dict[str, Kind] = {
    "dimensionless": Kind("a dimensionless number", "dimensionless", "0.07"),
    "angle": Kind("an angle", "rad", "20 deg", angle_power=1),
    "length": Kind("a length", "m", "20 um"),
    "mass": Kind("a mass", "kg", "0.557 kg"),
    "inertia": Kind("a polar moment of inertia", "kg*m**2", "0.01 kg*m^2"),
    "density": Kind("a density", "kg/m**3", "7850 kg/m^3"),
    "angular_velocity": Kind("an angular velocity", "rad/s", "4200 rpm", angle_power=1),
    "velocity": Kind("a velocity", "m/s", "0.3 m/s"),
    "acceleration": Kind("an acceleration", "m/s**2", "9.81 m/s^2"),
    "force": Kind("a force", "N", "100 N"),
    "torque": Kind("a torque", "N*m", "100 N*m"),
    "power": Kind("a power", "W", "200 kW"),
    "stiffness": Kind("a stiffness (force per length)", "N/m", "1e8 N/m"),
    "frequency": Kind("a frequency (cycles per second; for speeds use an angular velocity)", "Hz", "80 Hz"),
    "time": Kind("a time", "s", "0.05 s"),
    "damping": Kind("a viscous damping coefficient (force per velocity)", "N*s/m", "2000 N*s/m"),
    "torsional_stiffness": Kind("a torsional stiffness", "N*m/rad", "1.5e7 N*m/rad"),
    "contact_stiffness": Kind("a line-contact stiffness (force per length^(10/9))", "N/m**(10/9)",
                              "1.22e9 N/m**(10/9)"),
    "stiffness_per_width": Kind("a mesh stiffness per face width", "N/m**2", "20 N/(mm*um)"),
    "temperature": Kind("a temperature", "K", "60 degC"),
    "kinematic_viscosity": Kind("a kinematic viscosity", "m**2/s", "68 mm^2/s"),
    "dynamic_viscosity": Kind("a dynamic viscosity", "Pa*s", "0.03 Pa*s"),
    "pressure_viscosity": Kind("a pressure-viscosity coefficient", "1/Pa", "2e-8 1/Pa"),
    "pressure": Kind("a pressure or elastic modulus", "Pa", "210 GPa"),
    "per_temperature": Kind("a coefficient per kelvin", "1/K", "7.2e-4 1/K"),
    "thermal_conductivity": Kind("a thermal conductivity", "W/(m*K)", "0.13 W/(m*K)"),
}

_TOL = 1e-9  # tolerance on dimension exponents (pint stores 10/9 as a float)


def _same_dimensionality(a, b) -> bool:
    da, db = dict(a), dict(b)
    return all(abs(da.get(k, 0.0) - db.get(k, 0.0)) < _TOL for k in set(da) | set(db))


def _kind_of(dimension: str) -> Kind:
    if dimension in KINDS:
        return KINDS[dimension]
    try:
        ureg.parse_units(dimension)
    except Exception as exc:  # a programming error, not a user error
        raise ValueError(f"unknown dimension {dimension!r}; use one of {sorted(KINDS)} or a unit") from exc
    return Kind(f"a quantity in {dimension}", dimension, f"1 {dimension}")


def _shown(value) -> str:
    return value if isinstance(value, str) else str(value)


def _offset_quantity(text: str):
    """'<number> <unit>' read as Q_(number, unit) — the form pint needs for offset units (degC, degF)."""
    num, _, unit = text.strip().partition(" ")
    try:
        return Q_(float(num), unit.strip())
    except Exception:
        return None


def quantity(name: str, value, dimension: str) -> Quantity:
    """``value`` as a pint quantity of ``dimension`` (a key of :data:`KINDS` or a unit string).

    Accepts a pint Quantity (any registry), a string ``"<number> <unit>"``, or a real number when the
    dimension is ``"dimensionless"``. Raises :class:`ParameterError` naming ``name`` otherwise.
    """
    kind = _kind_of(dimension)
    expect = f"expected {kind.label} (e.g. '{kind.example}')"
    if isinstance(value, bool) or value is None:
        raise ParameterError.at(name, f"{expect}, got {value!r}")
    if isinstance(value, pint.Quantity):
        if value._REGISTRY is not ureg:  # re-home a foreign quantity through its text form
            value = Q_(value.magnitude, str(value.units))
        q = value
    elif isinstance(value, str):
        try:
            q = Q_(value.strip())
        except Exception:
            q = _offset_quantity(value)          # "60 degC": pint cannot multiply an offset unit
            if q is None:
                raise ParameterError.at(name, f"{expect}, got {value!r} which is not a quantity pint can read") from None
        if not isinstance(q, pint.Quantity):  # pint returns a plain number for e.g. "3"
            q = Q_(q)
    elif isinstance(value, numbers.Real):
        if dimension != "dimensionless":
            raise ParameterError.at(name, f"{expect}, got the bare number {value!r}: give units")
        q = Q_(float(value))
    else:
        raise ParameterError.at(name, f"{expect}, got {value!r} of type {type(value).__name__}")

    if not isinstance(q.magnitude, numbers.Real):
        raise ParameterError.at(name, f"{expect}, got {_shown(value)!r}: a scalar is required")
    want = ureg.parse_units(kind.si_unit).dimensionality if dimension != "dimensionless" else {}
    if not _same_dimensionality(q.dimensionality, want):
        raise ParameterError.at(name, f"{expect}, got {_shown(value)!r}")
    power = dict(q.to_base_units().unit_items()).get("radian", 0)
    if dimension == "frequency" and abs(power) > _TOL:
        # a rotation speed where cycles per second are meant: one revolution is one cycle (2π rad), not pint's 1 rad
        if abs(power - 1) > _TOL:
            raise ParameterError.at(name, f"{expect}, got {_shown(value)!r}: give Hz (cycles per second) or a "
                                          f"rotation speed (rpm, rev/s, rad/s)")
        q = Q_(float(q.to_base_units().magnitude) / (2.0 * math.pi), "Hz")
    if kind.angle_power:
        if abs(power - kind.angle_power) > _TOL:
            hint = " ('Hz' and '1/s' are ambiguous for a rotation speed: use rpm, rad/s or rev/s)" \
                if dimension == "angular_velocity" else " (a bare number could be radians or degrees)"
            raise ParameterError.at(name, f"{expect}, got {_shown(value)!r}: needs an angle unit{hint}")
    if not math.isfinite(float(q.magnitude)):
        raise ParameterError.at(name, f"{expect}, got {_shown(value)!r}: must be finite")
    return q


def to_si(q) -> float:
    """A scalar quantity (or plain number) as a float in SI base units; angles in rad, speeds in rad/s."""
    if isinstance(q, pint.Quantity):
        return float(q.to_base_units().magnitude)
    return float(q)


def _exponent(e: float) -> str:
    f = Fraction(e).limit_denominator(1000)
    if f.denominator == 1:
        return str(f.numerator)
    return f"({f.numerator}/{f.denominator})"


def unit_text(u) -> str:
    """A unit as a reader writes it: pint's short pretty form ("kg·m²", "N/m"), with a fractional exponent as
    ``^(p/q)`` ("N/m^(10/9)", where pint's form would print m¹⋅¹¹¹¹¹); "1" for no unit."""
    items = (1 * u).unit_items()
    if all(float(e).is_integer() for _, e in items):
        return f"{u:~P}" or "1"

    def part(name, e):
        sym = ureg.get_symbol(name)
        return sym if e == 1 else f"{sym}^{_exponent(e)}"
    num = "·".join(part(n, e) for n, e in items if e > 0) or "1"
    den = "·".join(part(n, -e) for n, e in items if e < 0)
    return f"{num}/{den}" if den else num


def format_quantity(q: Quantity) -> str:
    """Text that :func:`quantity` reads back to the same value (exact exponents, full precision)."""
    parts = []
    for unit, power in q.unit_items():
        parts.append(unit if power == 1 else f"{unit} ** {_exponent(power)}")
    units = " * ".join(parts)
    return f"{q.magnitude!r} {units}".strip()
