# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``drive: topic``, ``target`` and ``trajectory`` on the node: a state per message or point.

``drive: topic`` subscribes to ``input_joint_states``, ``drive: target`` to
``input_targets`` (:mod:`~mech_kinematics.ros.target_drive`) and ``drive:
trajectory`` to ``input_trajectory`` (``trajectory_msgs/msg/JointTrajectory``):
each of its points, of the drivers or of targets, with one velocity and one
acceleration per name, is a state stamped at the header's stamp (the node's
clock at receipt where it is zero, "start now" in ROS) plus the point's
``time_from_start``, with its accelerations, the efforts of that motion and
the scene's IMU readings (an input without accelerations has none: topic and
target drives publish no ``imu/NAME``).

The rules of one input message are :mod:`~mech_kinematics.ros.topic_drive`'s
(pure); :class:`InputSubscription` is their node side. It subscribes at
configure (so that the subscription's QoS overrides are declared with the
others) and publishes only while active: for each message it reads the
drivers (or the one-line reason it is refused), solves them with the
function that serves (:class:`~mech_kinematics.ros.solver_path.SolverPath`),
and publishes the state with the message's stamp (the state topics, without
accelerations, and ``/tf`` by ``tf_rate_hz`` of the input's time), counting
it in the diagnostics' :class:`~mech_kinematics.ros.diagnostics.TickStats`.

rclpy's executor rebuilds its wait set of every service, timer and
subscription of the node for each message it hands over: behind by a burst,
the node would pay that per message. Each call of the callback takes up to
:data:`INPUT_BURST` more messages waiting in the subscription's queue (as the
executor takes them), then lets the executor serve the rest.

Thread use: the executor's thread only.
"""

from __future__ import annotations

from collections.abc import Mapping
import math
import time
from typing import Any, TYPE_CHECKING

from builtin_interfaces.msg import Time
from rclpy.qos import QoSDurabilityPolicy, QoSHistoryPolicy, QoSProfile, QoSReliabilityPolicy
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory

from . import topics
from .cdr import marker, MessageTemplate, STAMP_MARKER
from .messages import TickMessages
from .parameters import TARGET, TOPIC, TRAJECTORY
from .publishing import qos_options, RCLError
from .target_drive import robot_target_drive, scene_target_drive, TargetDrive
from .ticker import general_tick
from .topic_drive import RefusedInput, TopicDrive, TopicInput
from ..errors import AssemblyError, UntrustedError
from ..solver.context import NEAR_SINGULAR
from ..units import NS_PER_S

if TYPE_CHECKING:
    from .diagnostics import TickStats
    from .publishing import Publishing
    from .robot_mode import RobotValues
    from .solver_path import SolverPath

__all__ = ['INPUT_BURST', 'INPUT_DEPTH', 'InputSubscription', 'PASSED_TEMPLATES']

#: History depth of the input_joint_states subscription (a second of input at 1 kHz, as the
#: state publishers keep: a stall of the executor loses no message).
INPUT_DEPTH = 1000
#: Input messages one call of the subscription's callback takes from its queue at most.
INPUT_BURST = 100
#: ``joint_states`` templates kept for the sets of passed joints seen (all dropped past it).
PASSED_TEMPLATES = 16


class InputSubscription:
    """The node driven from ``input_joint_states``: one state published per message.

    Parameters
    ----------
    node : rclpy.node.Node
        Where the subscription is created; its logger says what is refused.
    scene : Scene
        The scene loaded.
    solver : SolverPath
        The function that solves the drivers.
    publishing : Publishing
        The scene's publishers.
    stats : TickStats
        The diagnostics' counters.
    frame_id, extra_joints : str
        The ground frame; what an input's other joints do (``refuse``,
        ``ignore``, ``pass``).
    jump_back_s : float
        ``stamp_jump_back_s``: an earlier stamp by more than this resets the order.
    robot : RobotValues, optional
        In URDF mode: the input names the actuated joints (URDF names and
        values), turned into the scene's drivers; ``joint_states`` names the
        URDF's joints (the actuated ones echoed as given).
    drive : str, optional
        ``topic`` (default); ``target``: subscribe to ``input_targets`` and read
        each message's targets into the drivers that put them there
        (:class:`~.target_drive.TargetDrive`); ``trajectory``: subscribe to
        ``input_trajectory`` and publish each point.
    target_robot : Robot, optional
        In URDF mode with ``target``: the robot whose joints and frames the
        targets name.
    branch : mapping of str to int, optional
        ``target_branch``: the working mode of every answer to targets.

    Attributes
    ----------
    topic : TopicDrive
        The per-message rules.
    active : bool
        Whether messages are published (the node's lifecycle: active).
    """

    def __init__(self, node: Any, scene: Any, solver: SolverPath, publishing: Publishing,
                 stats: TickStats, *, frame_id: str, extra_joints: str,
                 jump_back_s: float, robot: RobotValues | None = None,
                 drive: str = TOPIC, target_robot: Any = None,
                 branch: Mapping[str, int] | None = None) -> None:
        self.node, self.solver, self.publishing, self.stats = node, solver, publishing, stats
        self.frame_id = frame_id
        self.robot = robot
        self.scene = scene
        self._assembly_ticks: dict[tuple[int, ...], Any] = {}
        joints, points = scene.output_joints, scene.output_points
        drivers = scene.drivers
        if robot is not None:
            joints, drivers = robot.names, robot.drivers
        # What the input determines: positions always, velocities when a message has them.
        # With effort: static (publishing.forces), each joint's effort too.
        #: By (velocities known, accelerations known).
        self.messages = {(known, accels): TickMessages(
            joints, points, frame_id, velocities=known, accelerations=accels,
            efforts_first=publishing.efforts_first)
            for known, accels in ((True, False), (False, False), (True, True))}
        rules = {'jump_back_ns': round(jump_back_s * NS_PER_S), 'published_joints': joints}
        self.topic: TopicDrive | TargetDrive
        self.drive = drive
        if drive == TOPIC:
            self.topic = TopicDrive(drivers, extra_joints=extra_joints, **rules)
        else:
            named: dict[str, Any] = {'branch': branch}
            if drive == TRAJECTORY:
                named['topic_name'] = topics.INPUT_TRAJECTORY
            self.topic = scene_target_drive(scene, solver.max_error, **rules, **named) \
                if target_robot is None else \
                robot_target_drive(target_robot, drivers, solver.max_error, **rules, **named)
        self.active = False
        #: joint_states templates with the passed joints, by (names, velocities, efforts).
        self._passed: dict[tuple[tuple[str, ...], bool, bool], MessageTemplate | None] = {}
        qos = QoSProfile(history=QoSHistoryPolicy.KEEP_LAST, depth=INPUT_DEPTH,
                         reliability=QoSReliabilityPolicy.RELIABLE,
                         durability=QoSDurabilityPolicy.VOLATILE)
        kind, name = {TOPIC: (JointState, topics.INPUT_JOINT_STATES),
                      TARGET: (JointState, topics.INPUT_TARGETS),
                      TRAJECTORY: (JointTrajectory, topics.INPUT_TRAJECTORY)}[drive]
        self._message = self.trajectory if drive == TRAJECTORY else self.message
        self.topic_name = name
        self.subscription: Any = node.create_subscription(
            kind, name, self.on_input, qos, qos_overriding_options=qos_options())

    def close(self) -> None:
        """Stop publishing and destroy the subscription."""
        self.active = False
        subscription, self.subscription = self.subscription, None
        if subscription is not None:
            self.node.destroy_subscription(subscription)

    def on_input(self, msg: JointState | JointTrajectory) -> None:
        """Publish the state of each input message waiting, from ``msg`` on, with its stamp."""
        self._message(msg)
        subscription = self.subscription
        for _ in range(INPUT_BURST):
            if subscription is None or self.subscription is not subscription:
                return
            with subscription.handle:
                taken = subscription.handle.take_message(subscription.msg_type,
                                                         subscription.raw)
            if taken is None:
                return
            self._message(taken[0])

    def message(self, msg: JointState) -> None:
        """Publish the state of one input message with its stamp, or say why not."""
        stamp = msg.header.stamp
        self.answer(stamp.sec, stamp.nanosec, msg.name, msg.position, msg.velocity, msg.effort)

    def trajectory(self, msg: JointTrajectory) -> None:
        """Publish the state of each point of a trajectory at its time, or say why not."""
        stamp = msg.header.stamp
        start = stamp.sec * NS_PER_S + stamp.nanosec
        if start == 0:      # "start now" (as a trajectory controller reads it)
            start = self.node.get_clock().now().nanoseconds
        for point in msg.points:
            at = point.time_from_start
            sec, nanosec = divmod(start + at.sec * NS_PER_S + at.nanosec, NS_PER_S)
            self.answer(sec, nanosec, msg.joint_names, point.positions, point.velocities, (),
                        point.accelerations)

    def answer(self, sec: int, nanosec: int, names: Any, positions: Any, velocities: Any,
               efforts: Any, accelerations: Any = None) -> None:
        """Publish the state of one input (a message, a point) with its stamp, or say why not."""
        received = time.monotonic_ns()
        if not self.active:
            return      # inactive (lifecycle), or cleaned up while the message waited
        topic, stats, publishing = self.topic, self.stats, self.publishing
        stamp_ns = sec * NS_PER_S + nanosec
        given = None
        try:
            given = topic.read(sec, nanosec, names, positions, velocities, efforts) \
                if accelerations is None else \
                topic.read(sec, nanosec, names, positions, velocities, efforts, accelerations)
            values, measure = self._solve(given)
            if self.robot is not None:   # in the assembly Robot.solve answers (robot/assembly.py)
                values, measure = self.robot.answer(
                    (values, measure), (given.positions, given.speeds, given.accels),
                    lambda combo: self._solve(given, self._assembly_tick(combo)))
        except (RefusedInput, AssemblyError) as exc:
            if isinstance(exc, AssemblyError) and self.robot is not None and given is not None:
                exc = exc.located(self.robot.where(given.positions))  # the URDF's joints
            kind = 'refused input' if isinstance(exc, RefusedInput) else \
                'not trusted' if isinstance(exc, UntrustedError) else 'cannot assemble'
            stats.record(stamp_ns, time.monotonic_ns() - received, False, error=str(exc),
                         refusal=kind)
            self.node.get_logger().warning(f'no state published: {exc}',
                                           throttle_duration_sec=1.0)
            return
        sec, nanosec = divmod(given.stamp_ns, NS_PER_S)
        rendered = self.messages[given.speeds is not None, given.accels is not None
                                 ].render_values(values, sec, nanosec)
        if given.passed is not None:    # extra_joints: pass: names that change per message
            rendered = (self._joint_state_passed(given, values, sec, nanosec), *rendered[1:])
        try:
            for publish, data in zip(publishing.publish_state, rendered, strict=True):
                publish(data)
            if publishing.forces is not None:
                publishing.publish_forces(values, sec, nanosec)
            if publishing.imus is not None and given.accels is not None:
                publishing.publish_imus(values, sec, nanosec)   # accelerations known: a reading
        except RCLError as exc:    # the middleware refused: this input's state is lost
            reason = str(exc).split(',', 1)[0]
            stats.publish_failed(given.stamp_ns, time.monotonic_ns() - received, False, reason)
            self.node.get_logger().warning(
                f'a state was not delivered ({reason}): a reliable subscriber may be too slow '
                'for the input; counted on diagnostics (publish_failures)',
                throttle_duration_sec=1.0)
            return
        if given.jumped_from_ns is not None:
            publishing.next_tf = 0   # /tf's rate counts from the new order
            self.node.get_logger().warning(
                f'{self.topic_name}: the stamp jumped back '
                f'{(given.jumped_from_ns - given.stamp_ns) / NS_PER_S:.9g} s (more than '
                'stamp_jump_back_s): published, the order starts again from it',
                throttle_duration_sec=1.0)
        if publishing.tf_due(given.stamp_ns):
            publishing.tf_frames(values, sec, nanosec)
        topic.published(given.stamp_ns)
        stats.record(given.stamp_ns, time.monotonic_ns() - received, False, measure=measure,
                     near_singular=measure < NEAR_SINGULAR)
        stats.topic_input(given.stamp_ns, given.jumped_from_ns, given.ignored,
                          given.passed.names if given.passed is not None else ())

    def _joint_state_passed(self, given: TopicInput, values: Any, sec: int,
                            nanosec: int) -> JointState | bytes:
        """Return ``joint_states`` with the input's other joints after the mechanism's.

        Rendered from a template of its names (:data:`PASSED_TEMPLATES` kept:
        a robot's motors name the same joints in every message), so that a
        message of the motors costs a pack, not a Python message; a template
        that cannot be made (a name whose bytes hold a slot's marker) gives
        the message itself.
        """
        name, position, velocity, effort = self.topic.joint_state_arrays(given, values)
        first = self.publishing.efforts_first
        if first is not None and len(values) > first:   # effort: static: the mechanism's
            n = len(self.topic.published_joints)
            effort = [*values[first:first + n],
                      *(effort[n:] if effort else [math.nan] * (len(name) - n))]
        key = (tuple(name), bool(velocity), bool(effort))
        template = self._passed.get(key)
        if template is None and key not in self._passed:
            if len(self._passed) >= PASSED_TEMPLATES:
                self._passed.clear()
            self._passed[key] = template = self._passed_template(*key)
        if template is not None:
            return template.render(sec, nanosec, [*position, *velocity, *effort])
        msg = JointState(name=name, position=position, velocity=velocity, effort=effort)
        msg.header.stamp = Time(sec=sec, nanosec=nanosec)
        msg.header.frame_id = self.frame_id
        return msg

    def _passed_template(self, names: tuple[str, ...], velocities: bool,
                         efforts: bool) -> MessageTemplate | None:
        """Return the template of ``joint_states`` naming ``names``, or None if it cannot be."""
        n = len(names)
        counts = (n, n * velocities, n * efforts)
        slots = [[marker(sum(counts[:k]) + i) for i in range(count)]
                 for k, count in enumerate(counts)]
        msg = JointState(name=list(names), position=slots[0], velocity=slots[1],
                         effort=slots[2])
        msg.header.stamp = Time(sec=STAMP_MARKER[0], nanosec=STAMP_MARKER[1])
        msg.header.frame_id = self.frame_id
        try:
            return MessageTemplate(msg, sum(counts))
        except ValueError:
            return None

    def _assembly_tick(self, combo: tuple[int, ...]) -> Any:
        """Return the tick of the robot's scene in another assembly (the general solver's)."""
        tick = self._assembly_ticks.get(combo)
        if tick is None:
            frames = [(f.origin, f.angle_of, f.angle) for f in self.publishing.frames]
            scene = self.robot.assemblies.scene(combo, self.scene)
            tick = general_tick(scene, self.scene.output_joints, self.scene.output_points,
                                frames)
            self._assembly_ticks[combo] = tick
        return tick

    def _solve(self, given: TopicInput, tick: Any = None) -> tuple[Any, float]:
        """Return (the tick function's values, the singularity measure) for one input.

        Unknown velocities are solved as zero and left out of what is published;
        the accelerations are solved as zero and left out unless given (a
        trajectory's point). ``tick``: another tick function
        than the solver's (the robot's scene in another assembly).
        """
        solver = self.solver
        positions, speeds, accels = given.positions, given.speeds, given.accels
        if self.robot is not None:
            forces = self.publishing.forces
            if forces is not None:    # a robot's forces read the actuated joints as given
                forces.inputs = (positions, speeds, accels)
            positions, speeds = self.robot.scene_inputs(positions, speeds)
            accels = self.robot.scene_rates(accels)
        n = len(positions)
        speeds = (0.0,) * n if speeds is None else speeds
        accels = (0.0,) * n if accels is None else accels
        solve = solver.solve if tick is None else tick
        assert solve is not None
        if n == 1:
            return solve(positions[0], speeds[0], accels[0], solver.max_error, 0)
        return solve(positions, speeds, accels, solver.max_error, (0,) * n)
