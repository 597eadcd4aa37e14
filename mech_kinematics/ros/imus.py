# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``sensor_msgs/msg/Imu`` of a scene's inertial sensors, and their frames on ``/tf``.

Each sensor of the scene's ``imus`` (:class:`~mech_kinematics.imu.ImuSpec`)
is published on ``imu/NAME`` (:func:`~mech_kinematics.ros.topics.imu_topic`)
with what an ideal IMU reads there (:func:`~mech_kinematics.imu.imu_values`),
stamped like the state:

- ``header.frame_id``: the link's ``/tf`` frame when the sensor's ``angle``
  is 0 (the sensor's axes are the link's), else a frame of the sensor's own,
  ``<prefix>/NAME``, a child of the link's frame turned by ``angle`` with
  its origin at the sensor's point, published on ``/tf`` with the link
  frames (:class:`ImuFrames`);
- ``orientation``: the sensor frame's rotation about z in the node's
  ``frame_id``, ``(0, 0, sin(phi/2), cos(phi/2))``;
- ``angular_velocity``: ``(0, 0, omega)``, rad/s;
- ``linear_acceleration``: ``(x, y, 0)`` in the sensor frame, m/s^2, gravity
  included (specific force);
- every covariance all zeros: the readings are exact (no noise, error bounds
  printed by ``solve``), so there is no measured variance to
  give; ``sensor_msgs/Imu`` reads zeros as "covariance unknown", which is what
  a filter under test should be told: bring your own noise model. Element 0
  is never -1: every reading is given. (The bounds are below 1e-12 of the
  readings: ``test/test_imu.py`` checks it.)

The message is rendered from a pre-serialized template
(:class:`~mech_kinematics.ros.cdr.MessageTemplate`) as the node's other
messages are; :func:`imu_from_values` builds the same message as an object
(a test checks the two byte for byte).
"""

from __future__ import annotations

from collections.abc import Sequence
import math
from typing import Any

from builtin_interfaces.msg import Time
from sensor_msgs.msg import Imu

from .cdr import marker, MessageTemplate, STAMP_MARKER
from ..geometry.frames import child_frame
from ..imu import imu_values, ImuSpec

__all__ = ['ImuFrames', 'ImuMessages', 'imu_frame', 'imu_from_values']


def imu_frame(spec: ImuSpec, prefix: str) -> str:
    """Return the ``header.frame_id`` of ``spec``'s messages: its link's frame or its own."""
    return child_frame(prefix, spec.link if spec.angle == 0.0 else spec.name)


def _imu(frame_id: str, stamp: Any, values: Sequence[float]) -> Imu:
    """Return an ``Imu`` of (sin(phi/2), cos(phi/2), omega, x, y)."""
    msg = Imu()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.orientation.z, msg.orientation.w = values[0], values[1]
    msg.angular_velocity.z = values[2]
    msg.linear_acceleration.x, msg.linear_acceleration.y = values[3], values[4]
    return msg


def _slots(theta: float, omega: float, ax: float, ay: float, spec: ImuSpec,
           gravity: tuple[float, float] | None = None
           ) -> tuple[float, float, float, float, float]:
    phi, omega, x, y = imu_values(theta, omega, ax, ay, spec, gravity)
    half = 0.5 * phi
    return math.sin(half), math.cos(half), omega, x, y


def imu_from_values(spec: ImuSpec, prefix: str, sec: int, nanosec: int, theta: float,
                    omega: float, ax: float, ay: float) -> Imu:
    """Return ``spec``'s ``Imu`` from its link's angle, rate and its point's acceleration."""
    return _imu(imu_frame(spec, prefix), Time(sec=sec, nanosec=nanosec),
                _slots(theta, omega, ax, ay, spec))


class ImuMessages:
    """The ``Imu`` messages of a scene's sensors, rendered from the flat values of a tick.

    Parameters
    ----------
    specs : sequence of ImuSpec
        The sensors, in publish order.
    joints, points : sequence of str
        The joints and points of the tick's values, in their order (see
        :func:`mech_kinematics.ros.ticker.values_from_state`); they must
        hold every sensor's link and point.
    prefix : str
        Prefix of the frame names (the node's ``tf_prefix`` or ``frame_id``).
    scene_gravity : (float, float) or None, optional
        The scene's top-level ``gravity`` (None: not given). A sensor whose
        own ``gravity`` equals it follows the node's ``gravity`` parameter
        (:meth:`follow_gravity`); any other keeps its own (the v3 meaning).
    """

    def __init__(self, specs: Sequence[ImuSpec], joints: Sequence[str], points: Sequence[str],
                 prefix: str, scene_gravity: tuple[float, float] | None = None) -> None:
        self.specs = tuple(specs)
        #: The sensors that follow the ``gravity`` parameter: their gravity is the scene's.
        self.following = tuple(s.name for s in self.specs if scene_gravity is not None
                               and tuple(s.gravity) == tuple(scene_gravity))
        #: Per sensor, the gravity its readings take off, m/s^2 (replaced whole).
        self.gravity = tuple(tuple(s.gravity) for s in self.specs)
        self.frames = tuple(imu_frame(spec, prefix) for spec in self.specs)
        nj, npt = len(joints), len(points)
        accel = 3 * nj + 4 * npt
        #: Per sensor, the values' index of its link's angle, rate, point's x and y acceleration.
        self.indices = tuple((joints.index(s.link), nj + joints.index(s.link),
                              accel + 2 * points.index(s.point),
                              accel + 2 * points.index(s.point) + 1) for s in self.specs)
        stamp = Time(sec=STAMP_MARKER[0], nanosec=STAMP_MARKER[1])
        self._templates = tuple(MessageTemplate(_imu(frame, stamp, [marker(i) for i in range(5)]),
                                                5) for frame in self.frames)
        self.prefix = prefix

    def render_values(self, values: Sequence[float], sec: int,
                      nanosec: int) -> list[bytes | None]:
        """Return every sensor's serialized ``Imu`` from a tick's flat ``values``.

        ``None`` for a sensor whose reading is beyond the range of doubles (its
        point's acceleration less its gravity overflows): never an ``inf``.
        """
        out: list[bytes | None] = []
        for template, spec, (i, j, k, m), g in zip(self._templates, self.specs, self.indices,
                                                   self.gravity, strict=True):
            slots = _slots(values[i], values[j], values[k], values[m], spec, g)
            out.append(template.render(sec, nanosec, slots)
                       if all(map(math.isfinite, slots)) else None)
        return out

    def follow_gravity(self, gravity: Sequence[float]) -> None:
        """Take ``gravity`` ([gx, gy], m/s^2) off the readings of the sensors that follow it.

        The node's ``gravity`` parameter: from the next instant published,
        as the forces take it. A reading it makes overflow is not published
        (:meth:`render_values`).
        """
        g = (float(gravity[0]), float(gravity[1]))
        self.gravity = tuple(g if spec.name in self.following else own
                             for spec, own in zip(self.specs, self.gravity, strict=True))

    def frame_transforms(self, local: dict[str, tuple[float, float]]) -> list[Any]:
        """Return the ``TransformStamped`` of every sensor with a frame of its own (stamp unset).

        ``local`` maps each such sensor's name to its point's coordinates in
        its link's frame, m (:func:`~mech_kinematics.geometry.frames.sensor_offsets`).
        """
        from geometry_msgs.msg import TransformStamped

        transforms = []
        for spec, frame in zip(self.specs, self.frames, strict=True):
            if spec.angle == 0.0:
                continue
            t = TransformStamped()
            t.header.frame_id = child_frame(self.prefix, spec.link)
            t.child_frame_id = frame
            t.transform.translation.x, t.transform.translation.y = local[spec.name]
            t.transform.rotation.z = math.sin(spec.angle / 2)
            t.transform.rotation.w = math.cos(spec.angle / 2)
            transforms.append(t)
        return transforms


class ImuFrames:
    """The ``/tf`` message of the sensors' own frames: fixed on their links, stamped per tick.

    Parameters
    ----------
    transforms : sequence of TransformStamped
        :meth:`ImuMessages.frame_transforms`; at least one.
    """

    def __init__(self, transforms: Sequence[Any]) -> None:
        from tf2_msgs.msg import TFMessage

        stamp = Time(sec=STAMP_MARKER[0], nanosec=STAMP_MARKER[1])
        for t in transforms:
            t.header.stamp = stamp
        self._template = MessageTemplate(TFMessage(transforms=list(transforms)), 0)

    def render(self, sec: int, nanosec: int) -> bytes:
        """Return the serialized ``TFMessage`` stamped ``sec, nanosec``."""
        return self._template.render(sec, nanosec, ())
