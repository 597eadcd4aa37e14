# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Exact readings of an inertial sensor rigidly mounted on a moving link.

A sensor ``name: {link: L, point: P, gravity: [gx, gy], angle: beta}`` sits at
point ``P`` of link ``L`` with its x axis at ``beta`` from the link's (the
link's ``/tf`` frame turned by ``beta``). What an ideal IMU there reads is a
function of the solved state alone:

- orientation ``phi = theta_L + beta`` (rad, wrapped to (-pi, pi]): the
  rotation of the sensor frame about z;
- angular velocity ``omega_L`` (rad/s about z): a planar body turns at one
  rate everywhere on it;
- linear acceleration ``R(-phi) (a_P - g)`` (m/s^2, in the sensor frame):
  an accelerometer measures specific force, the acceleration less gravity
  (at rest with ``g = [0, -9.80665]`` it reads ``+9.80665`` along the
  world's +y).

Each reading carries an absolute error bound built from the state's own
bounds: the acceleration's ``e_a + |a_P - g| e_phi`` (a rotation by an angle
off by ``e_phi`` moves a vector by at most ``|v| e_phi``) plus the rounding
of the rotation itself. Scalars for one crank angle, arrays for many.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
import math
from typing import Any

import numpy as np

from .bounds import LARGEST, U
from .errors import SceneError
from .units import reduce_radians

__all__ = ['MAX_GRAVITY', 'ImuReading', 'ImuSpec', 'imu_links', 'imu_outputs', 'imu_reading',
           'imu_values']

#: Rounding of ``R(-phi) v`` with ``cos``/``sin`` and two products and a sum per
#: component, relative to ``|v|``: a few units of roundoff, taken generously.
_ROTATION_ROUNDING = 8.0 * U
#: Largest ``|gx| + |gy|`` of a sensor's gravity, m/s^2 (half the largest double): at
#: rest a reading is at most ``|gx| + |gy|`` and its bound sums ``|g|``, ``|gx|`` and
#: ``|gy|``, so both stay finite. A larger gravity is refused when the scene is built.
MAX_GRAVITY = LARGEST / 2


@dataclass(frozen=True)
class ImuSpec:
    """A sensor ``name`` at ``point`` on ``link``; ``gravity`` m/s^2, ``angle`` rad.

    ``angle`` is a direction: one beyond [-pi, pi] is kept reduced exactly to
    within it (:func:`~.units.reduce_radians`), so that the orientation
    ``theta_L + angle`` wraps to (-pi, pi] and its bound stays that of an
    angle within a turn, however many turns were written.
    """

    name: str
    link: str
    point: str
    gravity: tuple[float, float] = (0.0, 0.0)
    angle: float = 0.0

    def __post_init__(self) -> None:
        """Refuse a gravity or angle that is not a finite number, or a gravity that overflows."""
        for value, what in ((self.gravity[0], 'gravity[0]'), (self.gravity[1], 'gravity[1]'),
                            (self.angle, 'angle')):
            if not math.isfinite(value):
                msg = f'imus.{self.name}.{what}: expected a finite number, got {value!r}'
                raise ValueError(msg)
        gx, gy = self.gravity
        if not abs(gx) + abs(gy) <= MAX_GRAVITY:
            msg = (f'Expected a gravity whose readings stay within the range of doubles '
                   f'(abs(gx) + abs(gy) at most {MAX_GRAVITY:.6g} m/s^2), got '
                   f'[{gx:.6g}, {gy:.6g}] m/s^2')
            raise SceneError(msg, (self, 'gravity'))
        if abs(self.angle) > math.pi:
            object.__setattr__(self, 'angle', reduce_radians(float(self.angle))[0])


@dataclass(frozen=True)
class ImuReading:
    """What the sensor reads, and the bound of each reading's error.

    ``linear_acceleration`` has shape (2,) or (n, 2), in the sensor frame;
    its bound is on the norm of the error vector.
    """

    orientation: Any
    angular_velocity: Any
    linear_acceleration: Any
    orientation_bound: Any
    angular_velocity_bound: Any
    linear_acceleration_bound: Any

    def as_dict(self, vector: bool) -> dict[str, Any]:
        """Return the ``solve`` JSON's ``imus.NAME`` (floats, or arrays where ``vector``)."""
        def value(x: Any) -> Any:
            return x if vector else float(x)

        accel = self.linear_acceleration
        return {'angular_velocity': value(self.angular_velocity),
                'linear_acceleration': accel if vector else [float(accel[0]), float(accel[1])],
                'orientation': value(self.orientation)}

    def bounds_dict(self, vector: bool) -> dict[str, Any]:
        """Return the bounds shaped like :meth:`as_dict` (one norm for the acceleration)."""
        def value(x: Any) -> Any:
            return x if vector else float(x)

        return {'angular_velocity': value(self.angular_velocity_bound),
                'linear_acceleration': value(self.linear_acceleration_bound),
                'orientation': value(self.orientation_bound)}


def imu_reading(state: Any, spec: ImuSpec) -> ImuReading:
    """Return what ``spec``'s sensor reads in ``state`` (a :class:`State`), with bounds.

    ``spec.link`` must be a revolute joint of the state and ``spec.point`` a
    point of it (the scene's outputs must keep both).
    """
    joint = state.joints[spec.link]
    point = state.points[spec.point]
    joint_bound = state.error_bound.joints[spec.link]
    point_bound = state.error_bound.points[spec.point]
    phi = np.asarray(joint.position, dtype=np.float64) + spec.angle
    phi = np.where(phi > math.pi, phi - 2 * math.pi, np.where(phi <= -math.pi,
                                                              phi + 2 * math.pi, phi))
    c, s = np.cos(phi), np.sin(phi)
    with np.errstate(over='ignore', invalid='ignore'):  # beyond doubles: inf, refused by solve
        a = np.asarray(point.acceleration, dtype=np.float64) - np.asarray(spec.gravity)
        ax, ay = a[..., 0], a[..., 1]
        reading = np.stack((c * ax + s * ay, c * ay - s * ax), axis=-1)
        size = np.hypot(ax, ay)
        e_phi = np.asarray(joint_bound.position) + U * (abs(phi) + abs(spec.angle))
        e_accel = (np.asarray(point_bound.acceleration) + size * e_phi
                   + _ROTATION_ROUNDING * (size + abs(spec.gravity[0]) + abs(spec.gravity[1])))
    scalar = np.ndim(phi) == 0
    if scalar:
        return ImuReading(float(phi), float(joint.velocity), reading,
                          float(e_phi), float(joint_bound.velocity), float(e_accel))
    return ImuReading(phi, np.asarray(joint.velocity), reading, e_phi,
                      np.asarray(joint_bound.velocity), e_accel)


def imu_links(scene: Any) -> dict[str, tuple[str, ...]]:
    """Return every moving link of ``scene`` and the points fixed on it, in scene order.

    The bodies of the mechanism's graph that turn on their own (every crank,
    dyad link, slotted lever, a cylinder's barrel) and the points fixed on
    each: its pins (a crank's centre and tip, a dyad link's start and new pin,
    a lever's pivot) and the points carried by it (``points:``); a pin sliding
    in a slotted lever or a cylinder's barrel is not fixed on it.
    """
    return {name: body.points for name, body in scene.graph.bodies.items()
            if body.turns_with == name}


def imu_outputs(scene: Any, joint_types: dict[str, str], joints: Sequence[str] | None,
                points: Sequence[str] | None
                ) -> tuple[tuple[str, ...] | None, tuple[str, ...] | None]:
    """Check ``scene.imus``; return the outputs with what every sensor needs added.

    Each sensor's link must be a moving link (a revolute joint of
    ``joint_types``, the whole scene's) and its point a point fixed on that
    link (:func:`imu_links`). Listed outputs (``None``: everything) gain the
    sensors' links and points they leave out, after the listed ones.

    Raises
    ------
    SceneError
        Naming the sensor's ``link`` or ``point`` field (``where`` is the spec).
    """
    specs = tuple(scene.imus)
    if not specs:
        return (None if joints is None else tuple(joints),
                None if points is None else tuple(points))
    fixed = imu_links(scene)
    taken = {*scene.ground, *joint_types, *(p for on in fixed.values() for p in on)}
    for spec in specs:
        if spec.name in taken:
            msg = (f'Expected a sensor name not used for a point, link or slider, got '
                   f'"{spec.name}"')
            raise SceneError(msg, (spec, 'name'))
        if spec.link not in fixed:
            moving = ', '.join(fixed)
            got = (f'slider "{spec.link}", which does not turn' if spec.link in joint_types
                   else f'ground point "{spec.link}", which does not move'
                   if spec.link in scene.ground else f'unknown "{spec.link}"')
            msg = f'Expected a moving link ({moving}), got {got}'
            raise SceneError(msg, (spec, 'link'))
        on = fixed.get(spec.link, ())
        if spec.point not in on:
            msg = (f'Expected a point carried by or lying on link "{spec.link}" '
                   f'({", ".join(on)}), got "{spec.point}"')
            raise SceneError(msg, (spec, 'point'))
    if joints is not None:
        joints = (*joints, *(name for name in dict.fromkeys(s.link for s in specs)
                             if name not in joints))
    if points is not None:
        points = (*points, *(name for name in dict.fromkeys(s.point for s in specs)
                             if name not in points))
    return joints, points


def imu_values(theta: float, omega: float, ax: float, ay: float, spec: ImuSpec,
               gravity: tuple[float, float] | None = None
               ) -> tuple[float, float, float, float]:
    """Return one instant's (orientation, angular velocity, x, y acceleration) of a sensor.

    ``theta`` (rad) and ``omega`` (rad/s) are its link's angle and angular
    velocity, ``ax, ay`` (m/s^2) its point's acceleration in the ground frame:
    the readings of :func:`imu_reading` for plain floats, without bounds (the
    node's tick). The same formulas, in :mod:`math`. ``gravity`` (m/s^2):
    the gravity taken off, when not the sensor's own (the node's ``gravity``
    parameter, which a sensor of the scene's gravity follows); a reading it
    makes overflow is ``inf``, which the caller refuses.
    """
    phi = theta + spec.angle
    if phi > math.pi:
        phi -= 2 * math.pi
    elif phi <= -math.pi:
        phi += 2 * math.pi
    c, s = math.cos(phi), math.sin(phi)
    gx, gy = spec.gravity if gravity is None else gravity
    x, y = ax - gx, ay - gy
    return phi, omega, c * x + s * y, c * y - s * x
