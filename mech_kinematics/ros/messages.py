# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""ROS messages from a solved :class:`~mech_kinematics.State` (the node's output).

``*_from_state`` build ordinary message objects; :class:`TickMessages` renders
the same three messages as CDR bytes from templates, which is what the node
publishes every tick. Both are tested to give byte-identical results.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Transform, Twist
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import (JointTrajectory, JointTrajectoryPoint,
                                 MultiDOFJointTrajectory, MultiDOFJointTrajectoryPoint)

from .cdr import marker, MessageTemplate, STAMP_MARKER
from .ticker import values_from_state

__all__ = [
    'TickMessages', 'joint_state_from_state', 'joint_trajectory_from_state',
    'multi_dof_trajectory_from_state',
]


def _stamp(sec: int, nanosec: int) -> Time:
    return Time(sec=sec, nanosec=nanosec)


def _joint_state(names: Sequence[str], frame_id: str, stamp: Time,
                 position: list[float], velocity: list[float],
                 effort: list[float] | None = None) -> JointState:
    msg = JointState(name=list(names), position=position, velocity=velocity,
                     effort=effort or [])
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    return msg


def _joint_trajectory(names: Sequence[str], frame_id: str, stamp: Time,
                      values: Sequence[list[float]]) -> JointTrajectory:
    positions, velocities, accelerations = values
    msg = JointTrajectory(joint_names=list(names), points=[JointTrajectoryPoint(
        positions=positions, velocities=velocities, accelerations=accelerations)])
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    return msg


def _multi_dof(names: Sequence[str], frame_id: str, stamp: Time,
               xy: Sequence[list[float]]) -> MultiDOFJointTrajectory:
    """Build the point message; ``xy`` holds flat [x0, y0, x1, y1, ...] for p, v, a.

    An empty ``v`` or ``a`` leaves that quantity out (no entries).
    """
    p, v, a = xy
    point = MultiDOFJointTrajectoryPoint()
    for i in range(len(names)):
        transform = Transform()
        transform.translation.x, transform.translation.y = p[2 * i], p[2 * i + 1]
        transform.rotation.w = 1.0
        point.transforms.append(transform)
        if v:
            velocity = Twist()
            velocity.linear.x, velocity.linear.y = v[2 * i], v[2 * i + 1]
            point.velocities.append(velocity)
        if a:
            acceleration = Twist()
            acceleration.linear.x, acceleration.linear.y = a[2 * i], a[2 * i + 1]
            point.accelerations.append(acceleration)
    msg = MultiDOFJointTrajectory(joint_names=list(names), points=[point])
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    return msg


def _joint_values(state: Any, names: Sequence[str]) -> tuple[list[float], ...]:
    joints = state.joints
    return ([float(joints[n].position) for n in names],
            [float(joints[n].velocity) for n in names],
            [float(joints[n].acceleration) for n in names])


def _point_values(state: Any, names: Sequence[str]) -> tuple[list[float], ...]:
    out: tuple[list[float], ...] = ([], [], [])
    for n in names:
        for values, z in zip(out, state.complex_points[n], strict=True):
            values.append(float(z.real))
            values.append(float(z.imag))
    return out


def joint_state_from_state(state: Any, names: Sequence[str], frame_id: str,
                           sec: int, nanosec: int, *, efforts: bool = False) -> JointState:
    """Return ``sensor_msgs/JointState``: name, position and velocity of the joints ``names``.

    With ``efforts``, ``effort`` holds each driver's effort from ``state.forces``
    (N m for a crank, N for an actuator) and 0 for every other joint
    (frictionless); without, it is empty.
    """
    position, velocity, _ = _joint_values(state, names)
    effort = None
    if efforts:
        given = state.forces.efforts
        effort = [float(given[n]) if n in given else 0.0 for n in names]
    return _joint_state(names, frame_id, _stamp(sec, nanosec), position, velocity, effort)


def joint_trajectory_from_state(state: Any, names: Sequence[str], frame_id: str,
                                sec: int, nanosec: int) -> JointTrajectory:
    """Return ``trajectory_msgs/JointTrajectory``: one point with positions, velocities, accels."""
    return _joint_trajectory(names, frame_id, _stamp(sec, nanosec), _joint_values(state, names))


def multi_dof_trajectory_from_state(state: Any, names: Sequence[str], frame_id: str,
                                    sec: int, nanosec: int) -> MultiDOFJointTrajectory:
    """Return ``trajectory_msgs/MultiDOFJointTrajectory``: one point, position/velocity/acceleration of every point ``names`` (z = 0, rotation identity)."""  # noqa: E501
    return _multi_dof(names, frame_id, _stamp(sec, nanosec), _point_values(state, names))


class TickMessages:
    """The three state messages of a tick, rendered as CDR bytes from templates.

    Parameters
    ----------
    joints : sequence of str
        Joint names, in publish order.
    points : sequence of str
        Point names, in publish order.
    frame_id : str
        ``header.frame_id`` of every message.
    efforts_first : int or None, keyword-only
        Where each joint's effort sits in the values of a tick function that
        solves forces (:class:`~mech_kinematics.ros.wrenches.ForcesTick`: one
        per joint after the frames' poses); ``joint_states`` then carries them
        in ``effort``. The values of an instant whose forces were left out end
        before that index: its ``effort`` is empty. ``None``: never efforts.
    velocities, accelerations : bool, keyword-only
        Whether the messages carry the velocities, the accelerations. A
        quantity left out is an empty array (``velocity`` of a JointState,
        ``velocities`` / ``accelerations`` of a trajectory point): what the
        node publishes when it is driven from a topic whose messages do not
        determine it (see :mod:`~mech_kinematics.ros.topic_drive`). The slots
        keep their places in the values of a tick function either way.

    Raises
    ------
    ValueError
        If ``accelerations`` is asked without ``velocities``.
    """

    def __init__(self, joints: Sequence[str], points: Sequence[str], frame_id: str, *,
                 velocities: bool = True, accelerations: bool = True,
                 efforts_first: int | None = None) -> None:
        if accelerations and not velocities:
            msg = 'Expected velocities with accelerations (a template keeps a prefix of slots)'
            raise ValueError(msg)
        self.joints = tuple(joints)
        self.points = tuple(points)
        nj, npt = len(self.joints), len(self.points)
        stamp = _stamp(*STAMP_MARKER)

        def slots(start: int, count: int, kept: bool = True) -> list[float]:
            return [marker(i) for i in range(start, start + count)] if kept else []

        v, a = velocities, accelerations
        joint_slots = (slots(0, nj), slots(nj, nj, v), slots(2 * nj, nj, a))
        point_slots = (slots(0, 2 * npt), slots(2 * npt, 2 * npt, v),
                       slots(4 * npt, 2 * npt, a))
        self._joint_state = MessageTemplate(
            _joint_state(self.joints, frame_id, stamp, *joint_slots[:2]), (1 + v) * nj)
        self.efforts_first = efforts_first
        self._joint_state_efforts = None
        if efforts_first is not None and nj:
            # The efforts' slots follow the velocities' in the template and read the values
            # where the forces tick puts them (MessageTemplate's ``where``).
            n = (1 + v) * nj
            self._joint_state_efforts = MessageTemplate(
                _joint_state(self.joints, frame_id, stamp, *joint_slots[:2],
                             slots(n, nj)), n + nj,
                where=[*range(n), *range(efforts_first, efforts_first + nj)])
        self._joint_trajectory = MessageTemplate(_joint_trajectory(
            self.joints, frame_id, stamp, joint_slots), sum(map(len, joint_slots)))
        self._points = MessageTemplate(_multi_dof(self.points, frame_id, stamp, point_slots),
                                       sum(map(len, point_slots)))

    def render(self, state: Any, sec: int, nanosec: int) -> tuple[bytes, bytes, bytes]:
        """Return (joint_states, joint_accelerations, point_accelerations) as CDR bytes."""
        return self.render_values(values_from_state(state, self.joints, self.points), sec,
                                  nanosec)

    def render_values(self, values: Sequence[float], sec: int,
                      nanosec: int) -> tuple[bytes, bytes, bytes]:
        """Return the three messages from the flat values of a tick function.

        ``values`` is in the order of :func:`mech_kinematics.ros.ticker.values_from_state`
        (joints' positions, velocities, accelerations, then the points' positions,
        velocities, accelerations as x, y), which is the order of the slots.
        """
        joint_state = self._joint_state
        if self._joint_state_efforts is not None and len(values) > self.efforts_first:
            joint_state = self._joint_state_efforts
        return (joint_state.render(sec, nanosec, values),
                self._joint_trajectory.render(sec, nanosec, values),
                self._points.render(sec, nanosec, values, 3 * len(self.joints)))
