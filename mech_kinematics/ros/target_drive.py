# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node driven from its output: one ``input_targets`` message in, the drivers found out.

With ``drive: target`` the node subscribes to ``input_targets``
(``sensor_msgs/msg/JointState``): each message names targets (as many as the
scene has drivers, each a joint the scene reports or a point's ``POINT.x`` or
``POINT.y``; in URDF mode as many as the actuated joints, each a joint the
robot answers or a link frame origin's ``FRAME.x|y|z`` in the root frame; SI:
rad, m, and rad/s, m/s in ``velocity``), and the node
publishes the state that puts them there, stamped with the message's stamp,
as ``drive: topic`` publishes a state per message: ``joint_states`` then
carries the drivers' values a motor controller needs.

:class:`TargetDrive` turns a message into the drivers' positions (and
speeds, when the message has a velocity per target) with
:func:`~mech_kinematics.solver.inverse.continue_to`, continued from the drivers
of the last state published (at first the scene's start pose): a stream of
targets keeps the working mode it starts in. The drivers found are then read
by :class:`~.topic_drive.TopicDrive`'s rules (the stamp's order, a stroke),
every refusal naming ``input_targets``. A message is refused, and nothing is
published for it, when a target is named twice, is not one the scene reports,
or the count is not the drivers'; when a position or velocity is missing or
not finite; when a target is out of reach or the answer near a singular point
of the map (the one line of
:class:`~mech_kinematics.errors.TargetError`); and by the topic drive's rules.

Pure: no ROS. Thread use: one thread (the executor's), as TopicDrive.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
import math
from typing import Any, NoReturn

from .parameters import TARGET, TRAJECTORY
from .topic_drive import RefusedInput, TopicDrive, TopicInput
from .topics import INPUT_TARGETS
from ..errors import TargetError
from ..solver.inverse import check_branch, continue_to, parse_branch, scene_targets, TargetMap

__all__ = ['TargetDrive', 'robot_target_drive', 'scene_target_drive', 'target_branch']

#: Sets of target names whose maps are kept (all dropped past it).
MAPS = 16


class TargetDrive:
    """The rules of ``drive: target`` for one scene, and where its next answer continues from.

    Parameters
    ----------
    drivers : sequence
        What the drivers found are read as (:class:`~.topic_drive.TopicDrive`'s
        drivers: a scene's, or a robot's actuated joints), in the maps' order.
    targets_of : callable
        Target names -> their :class:`~mech_kinematics.solver.inverse.TargetMap`
        (raising :class:`~mech_kinematics.errors.TargetError` for names it lacks).
    start : sequence of float
        The drivers' values the first answer continues from (the start pose).
    max_error : float
        The solver's tolerance, which the inverse's drivers' bounds meet too.
    branch : mapping of str to int, optional
        The working mode of every answer (``target_branch``: joint -> +1 or
        -1, :func:`~mech_kinematics.solver.inverse.in_mode`); checked against
        the joints the maps read (:class:`TargetError`).
    **topic : Any
        What :class:`~.topic_drive.TopicDrive` takes beside the drivers
        (``extra_joints`` is ``refuse``: a message names targets only).
    """

    def __init__(self, drivers: Sequence[Any], targets_of: Callable[[tuple[str, ...]], TargetMap],
                 start: Sequence[float], max_error: float, topic_name: str = INPUT_TARGETS,
                 branch: Mapping[str, int] | None = None, **topic: Any) -> None:
        self.targets_of = targets_of
        self.max_error = max_error
        self.branch = dict(branch) if branch else None
        if self.branch:    # the joints a mode reads are the loop's, whatever the targets
            check_branch(targets_of(tuple(d.name for d in drivers)), self.branch,
                         'target_branch')
        self.topic_name = topic_name
        self.topic = TopicDrive(drivers, topic=topic_name, **topic)
        self.names = self.topic.names
        self.published_joints = self.topic.published_joints
        self.start = [float(x) for x in start]
        self._pending: list[float] | None = None
        #: The targets and Jacobian at the start, by target names (the last answer's).
        self._known: tuple[tuple[str, ...], Any] | None = None
        self._pending_known: tuple[tuple[str, ...], Any] | None = None
        self._maps: dict[tuple[str, ...], TargetMap] = {}

    @property
    def last_stamp_ns(self) -> int | None:
        """The stamp of the last state published, ns (None before the first)."""
        return self.topic.last_stamp_ns

    def read(self, sec: int, nanosec: int, names: Sequence[str], positions: Sequence[float],
             velocities: Sequence[float], efforts: Sequence[float] = (),
             accelerations: Sequence[float] | None = None) -> TopicInput:
        """Return the drivers that put the message's targets where it says (TopicInput).

        ``accelerations`` (``drive: trajectory``'s points): the targets'
        accelerations, one per name as the velocities must be then; the
        drivers' are in the answer (``accels``). A point that names the
        drivers themselves is taken as given.

        Raises
        ------
        RefusedInput
            If the message is refused (see the module's docstring), with the reason.
        """
        if accelerations is not None:
            if len(velocities) != len(names) or len(accelerations) != len(names):
                self._refuse(f'expected one velocity and one acceleration per name '
                             f'({len(names)}: the efforts of the motion need them), got '
                             f'{len(velocities)} and {len(accelerations)}')
            accels = [float(x) for x in accelerations]
            for name, value in zip(names, accels, strict=True):
                if not math.isfinite(value):
                    self._refuse(f'expected a finite acceleration of {name!r}, got {value!r}')
            if set(names) == set(self.names) and len(names) == len(self.names):
                given = self.topic.read(sec, nanosec, names, positions, velocities)
                where = {name: i for i, name in enumerate(names)}
                self._pending = list(given.positions)
                self._pending_known = None
                return replace(given, accels=tuple(accels[where[n]] for n in self.names))
        else:
            accels = None
        key = tuple(names)
        tmap = self._maps.get(key)
        if tmap is None:
            try:
                tmap = self.targets_of(key)
            except TargetError as error:
                self._refuse(str(error))
            if len(self._maps) >= MAPS:
                self._maps.clear()
            self._maps[key] = tmap
        if len(positions) != len(names):
            self._refuse(f'expected one position per target ({len(names)}), got '
                         f'{len(positions)}')
        if len(velocities) not in (0, len(names)):
            self._refuse(f'expected no velocity or one per target ({len(names)}), got '
                         f'{len(velocities)}')
        goal = [float(x) for x in positions]
        speeds = [float(v) for v in velocities] if len(velocities) else None
        for what, values in (('position', goal), ('velocity', speeds or ())):
            for name, value in zip(names, values, strict=False):
                if not math.isfinite(value):
                    self._refuse(f'expected a finite {what} of target {name!r}, got {value!r}')
        known = self._known[1] if self._known is not None and self._known[0] == key else None
        try:       # the accelerations and the forward answer only for a trajectory's points
            inverse = continue_to(tmap, goal, self.start, speeds, accels,
                                  max_error=self.max_error, known=known,
                                  answer=accels is not None, branch=self.branch)
        except TargetError as error:
            self._refuse(str(error))
        drivers = [float(x) for x in inverse.motion[:, 0]]
        rates = [float(x) for x in inverse.motion[:, 1]] if speeds is not None else []
        given = self.topic.read(sec, nanosec, self.names, drivers, rates)
        self._pending = drivers
        self._pending_known = (key, inverse.columns)
        if accels is None:
            return given
        return replace(given, accels=tuple(float(x) for x in inverse.motion[:, 2]))

    def joint_state_arrays(self, given: TopicInput, values: Sequence[float]) -> tuple[
            list[str], list[float], list[float], list[float]]:
        """Return ``joint_states``' arrays (:meth:`.TopicDrive.joint_state_arrays`)."""
        return self.topic.joint_state_arrays(given, values)

    def published(self, stamp_ns: int) -> None:
        """Note the state at ``stamp_ns`` published: the next answer continues from it."""
        self.topic.published(stamp_ns)
        if self._pending is not None:
            self.start, self._pending = self._pending, None
            self._known, self._pending_known = self._pending_known, None

    def _refuse(self, reason: str) -> NoReturn:
        raise RefusedInput(f'{self.topic_name}: {reason}')


def target_branch(entries: Sequence[str] | None, drive: str) -> dict[str, int] | None:
    """Return the ``target_branch`` parameter as {joint: sign}, or refuse it (ValueError).

    None where it is not given (or empty); refused with a drive that takes no
    targets, for an entry not ``JOINT=+1|-1`` or a joint named twice.
    """
    if not entries:
        return None
    if drive not in (TARGET, TRAJECTORY):
        msg = (f'target_branch: Expected drive: target or trajectory with target_branch (the '
               f'working mode of the answers to targets), got drive: {drive}')
        raise ValueError(msg)
    out: dict[str, int] = {}
    for entry in entries:
        try:
            name, sign = parse_branch(entry)
        except ValueError as error:
            raise ValueError(f'target_branch: {error}') from None
        if name in out:
            raise ValueError(f'target_branch: expected each joint once, got {name} twice')
        out[name] = sign
    return out


def scene_target_drive(scene: Any, max_error: float, **topic: Any) -> TargetDrive:
    """Return the target drive of a scene: its points and joints, from its start pose."""
    return TargetDrive(scene.drivers, lambda names: scene_targets(scene, names),
                       [d.start for d in scene.drivers], max_error, **topic)


def robot_target_drive(robot: Any, drivers: Sequence[Any], max_error: float,
                       **topic: Any) -> TargetDrive:
    """Return the target drive of a URDF robot: its joints and frames, from its reference pose.

    ``drivers``: the actuated joints as the URDF mode reads them
    (:class:`~.robot_mode.RobotValues`' drivers, in ``robot.actuated``'s order).
    """
    from ..robot.targets import robot_targets

    return TargetDrive(drivers, lambda names: robot_targets(robot, names),
                       [robot.start(name) for name in robot.actuated], max_error, **topic)
