# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Unit conversions: the one place that knows rpm, degrees, millimetres and nanoseconds.

Everything the package computes and prints is SI (m, rad, s). Users may give
lengths in mm, angles in degrees and crank speeds in rpm; these helpers turn
them into SI and back. They accept floats, NumPy arrays and ``mpmath``
numbers alike (pass ``pi=mpmath.pi`` for the latter), so the 50-digit
reference uses the same formulas as the solver.
"""

from __future__ import annotations

import math
from typing import Any

__all__ = [
    'ANGLE_UNITS', 'LENGTH_UNITS', 'NS_PER_S', 'degrees_from_radians', 'rad_per_s_from_rpm',
    'radians_from_degrees', 'rpm_from_rad_per_s',
]

#: Length units a scene may use: name -> how many of them make one metre.
LENGTH_UNITS = {'m': 1.0, 'mm': 1000.0}
#: Angle units a scene may use.
ANGLE_UNITS = ('deg', 'rad')
#: Nanoseconds per second (ROS stamps are integer nanoseconds).
NS_PER_S = 1_000_000_000


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


def radians_from_degrees(angle: Any, pi: Any = math.pi) -> Any:
    """Return an angle in degrees as radians."""
    return angle * (pi / 180)


def degrees_from_radians(angle: Any, pi: Any = math.pi) -> Any:
    """Return an angle in radians as degrees."""
    return angle * (180 / pi)
