# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Unit conversions: the one place that knows rpm, degrees, millimetres and nanoseconds.

Everything the package computes and prints is SI (m, rad, s). Users may give
lengths in mm, angles in degrees and crank speeds in rpm; these helpers turn
them into SI and back. They accept floats, NumPy arrays and ``mpmath``
numbers alike (pass ``pi=mpmath.pi`` for the latter), so the 50-digit
reference uses the same formulas as the solver.

A driver's rate keeps the unit it was given in (a crank's ``speed_rpm`` its
rpm, its ``speed`` its rad/s, an actuator's ``speed`` its m/s) until the
one conversion to SI (:func:`si_from_rate`), where it is used: the node's time
base converts it there, exactly.
"""

from __future__ import annotations

from fractions import Fraction
import math
from typing import Any

__all__ = [
    'ANGLE_UNITS', 'LENGTH_UNITS', 'NS_PER_S', 'RATE_UNITS', 'degrees_from_radians',
    'rad_per_s_from_rpm', 'radians_from_degrees', 'rate_from_si', 'reduce_radians',
    'rpm_from_rad_per_s', 'si_from_rate', 'turns_from_degrees',
]

#: Length units a scene may use: name -> how many of them make one metre.
LENGTH_UNITS = {'m': 1.0, 'mm': 1000.0}
#: Angle units a scene may use.
ANGLE_UNITS = ('deg', 'rad')
#: Units a driver's rate may be given in: name -> the SI unit it is converted to.
RATE_UNITS = {'rpm': 'rad/s', 'rad/s': 'rad/s', 'm/s': 'm/s'}
#: Nanoseconds per second (ROS stamps are integer nanoseconds).
NS_PER_S = 1_000_000_000
#: 2 pi as an exact rational to 400 significant digits: enough to reduce any double
#: (below 2**1024) to within a turn with every bit right (:func:`reduce_radians`).
_TWO_PI = 2 * Fraction(
    '3.14159265358979323846264338327950288419716939937510582097494459230781640628620899862803'
    '4825342117067982148086513282306647093844609550582231725359408128481117450284102701938521'
    '1055596446229489549303819644288109756659334461284756482337867831652712019091456485669234'
    '6034861045432664821339360726024914127372458700660631558817488152092096282925409171536436'
    '789259036001133053054882046652138414695194151160')


def rad_per_s_from_rpm(rpm: Any, pi: Any = math.pi) -> Any:
    """Return a speed in rpm (revolutions per minute) as rad/s: ``rpm * pi / 30``.

    For a float whose product with pi overflows (above 5.7e307 rpm), ``rpm /
    30 * pi``: the largest float in rpm is 1.88e307 rad/s, not inf.
    """
    speed = rpm * pi / 30
    if isinstance(speed, float) and math.isinf(speed) and math.isfinite(rpm):
        return rpm / 30 * pi
    return speed


def rpm_from_rad_per_s(speed: Any, pi: Any = math.pi) -> Any:
    """Return a speed in rad/s as rpm: ``speed * 30 / pi`` (or ``speed / pi * 30`` on overflow)."""
    rpm = speed * 30 / pi
    if isinstance(rpm, float) and math.isinf(rpm) and math.isfinite(speed):
        return speed / pi * 30
    return rpm


def si_from_rate(value: Any, unit: str) -> Any:
    """Return a driver's rate given in ``unit`` (:data:`RATE_UNITS`) in SI: rad/s or m/s.

    Only rpm is converted (:func:`rad_per_s_from_rpm`); a rate in rad/s or m/s
    is returned as it is, to the bit.
    """
    if unit == 'rpm':
        return rad_per_s_from_rpm(value)
    _check_rate_unit(unit)
    return value


def rate_from_si(value: Any, unit: str) -> Any:
    """Return a driver's rate in SI (rad/s or m/s) in ``unit`` (:data:`RATE_UNITS`)."""
    if unit == 'rpm':
        return rpm_from_rad_per_s(value)
    _check_rate_unit(unit)
    return value


def _check_rate_unit(unit: str) -> None:
    if unit not in RATE_UNITS:
        msg = f'Expected a rate unit in {", ".join(RATE_UNITS)}, got {unit!r}'
        raise ValueError(msg)


def radians_from_degrees(angle: Any, pi: Any = math.pi) -> Any:
    """Return an angle in degrees as radians."""
    return angle * (pi / 180)


def degrees_from_radians(angle: Any, pi: Any = math.pi) -> Any:
    """Return an angle in radians as degrees."""
    return angle * (180 / pi)


def turns_from_degrees(degrees: float) -> tuple[float, int]:
    """Split a crank angle in degrees, counted from the start, into (rad within a turn, turns).

    ``degrees = 360 * turns + rest`` exactly (IEEE remainder), ``rest`` in
    [-180, 180]; the angle is ``rest`` in radians. So 450 is 90 deg in turn 1,
    and 36000090 is 90 deg in turn 100000, with no rounding of the whole turns
    (counted exactly, as the float difference would round beyond 2**53 turns).
    """
    rest = math.remainder(degrees, 360.0)
    if abs(degrees) <= 2.0 ** 53:
        return radians_from_degrees(rest), round((degrees - rest) / 360.0)
    return radians_from_degrees(rest), int((Fraction(degrees) - Fraction(rest)) / 360)


def reduce_radians(angle: float) -> tuple[float, int]:
    """Split a crank angle in rad, counted from the start, into (rad within a turn, turns).

    ``angle = rest + 2 pi turns`` with the float ``angle`` taken as exact and
    ``rest`` in [-pi, pi] correctly rounded: the reduction uses 2 pi to 400
    digits, so even 1e308 rad keeps every bit of its place within the turn
    (a float 2 pi would be off by 2.4e-16 rad per turn).
    """
    if abs(angle) <= math.pi:
        return angle, 0
    exact = Fraction(angle)
    turns = round(exact / _TWO_PI)
    return float(exact - turns * _TWO_PI), turns
