# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""What the solve and its compiled paths share: the quick trust test and a revolute joint's angle.

:func:`.solve.solve` and every function :mod:`.compiler` writes judge a
single-angle state by the same quick test (:func:`trust_limits` or
:func:`floor_limits`, on the reported names of :data:`TRUST_TEST`) and report
a revolute joint's angle the same way (:func:`wrapped_angle`). They live here,
below both, so that the compiler never imports the solve it serves.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ['TRUST_TEST', 'floor_limits', 'trust_limits', 'wrapped_angle', 'wrapped_angles']


def trust_limits(tol: float, omega: float, alpha: float, size: float,
                 crank_length: float) -> tuple[float, float, float, float, float, float]:
    """Return the quick trust test's six limits: ``tol`` times each kind's floor.

    In order: position, velocity and acceleration (``size``, the crank tip's
    speed ``a |omega|`` and acceleration ``a (omega^2 + |alpha|)``), angle,
    angular velocity and angular acceleration (1 rad, ``|omega|``,
    ``omega^2 + |alpha|``). The floors are at most the scales
    (:attr:`.State.scales`), so a state whose reported bounds are all within
    them passes the solve's exact test. With :data:`TRUST_TEST` the one
    source of the test for the general path and every compiled one.
    """
    w = abs(omega)
    rate = w * w + abs(alpha)
    return (tol * size, tol * (crank_length * w), tol * (crank_length * rate), tol, tol * w,
            tol * rate)


#: The quick trust test: per context table, the solver's attribute listing the
#: reported names in it, and which :func:`trust_limits` bound their values' bounds.
TRUST_TEST = (('points', 'out_points', (0, 1, 2)), ('links', 'out_links', (3, 4, 5)),
              ('sliders', 'out_sliders', (0, 1, 2)))


def floor_limits(tol: float, size: float, floors: tuple[Any, Any, Any, Any]
                 ) -> tuple[float, float, float, float, float, float]:
    """Return the quick trust test's six limits from the drivers' floors (several drivers).

    ``floors``: the velocity, acceleration, angular velocity and angular
    acceleration floors (``_Solver.floors``). As :func:`trust_limits` (which
    gives the same for one crank), in the same order.
    """
    speed, accel, turn, turn_accel = floors
    return (tol * size, tol * speed, tol * accel, tol, tol * turn, tol * turn_accel)


def wrapped_angle(e: complex) -> float:
    """Return the angle of unit complex ``e`` (one value), wrapped to (-pi, pi], rad."""
    theta = math.atan2(e.imag, e.real)
    return math.pi if theta == -math.pi else theta


def wrapped_angles(e: Any) -> Any:
    """Return the angles of an array of unit complex numbers ``e``, wrapped to (-pi, pi], rad.

    The array path's :func:`wrapped_angle`.
    """
    theta = np.arctan2(e.imag, e.real)
    if np.fmin.reduce(theta, axis=None) == -np.pi:    # the least, NaN left out
        theta[theta == -np.pi] = np.pi
    return theta
