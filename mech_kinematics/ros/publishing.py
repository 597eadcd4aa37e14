# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""What the node publishes of a scene: the state topics, ``/tf``, the IMUs, markers, descriptions.

:class:`Publishing` creates the publishers of one scene on a node (with the
QoS of the node's contract and the standard overrides) and publishes a tick's values
(:mod:`~mech_kinematics.ros.ticker`'s flat list) as the messages rendered
from pre-serialized templates (:mod:`~mech_kinematics.ros.messages`,
:mod:`~mech_kinematics.ros.tf`, :mod:`~mech_kinematics.ros.imus`): the three
state messages every tick, the sensors' ``imu/NAME``, and ``/tf`` at
``tf_rate_hz`` by stamp; on a scene whose forces it publishes
(:meth:`Publishing.add_forces`), ``joint_states.effort``, ``reactions/JOINT``
and ``shaking`` (:mod:`~mech_kinematics.ros.wrenches`). At set-up it latches ``/tf_static``,
``robot_description`` and ``scene``. :class:`Markers` builds the RViz
markers in the executor's thread from the samples the tick thread hands over
(at most 30 a second), so that the tick thread keeps its deadlines.

A node here is anything with ``create_publisher`` (and, for the markers,
``create_guard_condition``): the tests give a stand-in and read what was
published, without a running node (``test/ros/test_publishing.py``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace
import math
import threading
import time
from typing import Any

from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import WrenchStamped
from rclpy.exceptions import InvalidTopicNameException
from rclpy.impl.implementation_singleton import rclpy_implementation
from rclpy.qos import QoSDurabilityPolicy, QoSHistoryPolicy, QoSProfile, QoSReliabilityPolicy
from rclpy.qos_overriding_options import QoSOverridingOptions, QoSPolicyKind
from rclpy.validate_topic_name import validate_topic_name
from sensor_msgs.msg import Imu, JointState
from std_msgs.msg import String
from trajectory_msgs.msg import JointTrajectory, MultiDOFJointTrajectory
from visualization_msgs.msg import MarkerArray

from . import topics
from .diagnostics import Status
from .drive import solve_at_start
from .imus import ImuFrames, ImuMessages
from .markers import marker_array_from_state, marker_size_from_space, MarkerThrottle
from .messages import TickMessages
from .parameters import STATE_DEPTH
from .robot_mode import RobotValues, Source
from .schedule import period_ns_from_rate
from .tf import static_tf_message, TfMessages
from .watchdog import PublishWatch
from .wrenches import ForcesTick, reaction_wrench
from ..errors import AssemblyError
from ..geometry.diagrams import space_from_state, strokes_from_scene
from ..geometry.frames import angle_joints, frames_from_scene, origin_points, sensor_offsets
from ..geometry.instant_centres import full_scene
from ..geometry.urdf import urdf_from_scene
from ..scene import scene_text
from ..solver.solve import solve
from ..units import NS_PER_S

__all__ = ['Markers', 'Publishing', 'QOS_OVERRIDES', 'RCLError', 'TF_DEPTH', 'diagnostic_array',
           'diagnostic_status_from', 'qos_options', 'state_qos', 'tf_period_ns', 'tf_qos']

#: /tf and /tf_static as tf2's broadcasters offer them.
TF_DEPTH = 100
#: Every publisher accepts ``qos_overrides./TOPIC.publisher.POLICY`` for these policies.
QOS_OVERRIDES = QoSPolicyKind.HISTORY, QoSPolicyKind.DEPTH, QoSPolicyKind.RELIABILITY, \
    QoSPolicyKind.DURABILITY

_LEVELS = {0: DiagnosticStatus.OK, 1: DiagnosticStatus.WARN, 2: DiagnosticStatus.ERROR,
           3: DiagnosticStatus.STALE}

#: What rclpy raises when the middleware refuses a publish (a reliable subscriber too slow
#: for the rate filled the writer's history, shared memory is full): the tick thread and the
#: topic input count it and go on.
RCLError = rclpy_implementation.RCLError


def qos_options() -> QoSOverridingOptions:
    """Return the QoS overrides every publisher (and the input subscription) accepts."""
    return QoSOverridingOptions(policy_kinds=QOS_OVERRIDES)


def tf_qos(static: bool) -> QoSProfile:
    """Return the profile of ``/tf`` (volatile) or ``/tf_static`` (transient local, depth 1)."""
    return QoSProfile(history=QoSHistoryPolicy.KEEP_LAST, depth=1 if static else TF_DEPTH,
                      reliability=QoSReliabilityPolicy.RELIABLE,
                      durability=QoSDurabilityPolicy.TRANSIENT_LOCAL if static
                      else QoSDurabilityPolicy.VOLATILE)


def state_qos() -> QoSProfile:
    """Return a new profile of the state publishers (overrides change the profile they get)."""
    return QoSProfile(history=QoSHistoryPolicy.KEEP_LAST, depth=STATE_DEPTH,
                      reliability=QoSReliabilityPolicy.RELIABLE,
                      durability=QoSDurabilityPolicy.VOLATILE)


def tf_period_ns(rate_hz: float) -> int | None:
    """Return the period of ``/tf`` at ``tf_rate_hz``, ns (``None``: off)."""
    return None if rate_hz <= 0.0 else period_ns_from_rate(rate_hz)


def diagnostic_status_from(status: Status) -> DiagnosticStatus:
    """Return ``status`` as a ``diagnostic_msgs/DiagnosticStatus``."""
    return DiagnosticStatus(level=_LEVELS[status.level], name=status.name,
                            message=status.message, hardware_id=status.hardware_id,
                            values=[KeyValue(key=k, value=v) for k, v in status.values])


def diagnostic_array(statuses: Sequence[Status], stamp: Time, frame_id: str) -> DiagnosticArray:
    """Return the ``diagnostics`` message of ``statuses``."""
    msg = DiagnosticArray(status=[diagnostic_status_from(s) for s in statuses])
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    return msg


class Publishing:
    """The publishers of one scene on ``node``, and what a tick or an input message publishes.

    Parameters
    ----------
    node : rclpy.node.Node
        Where the publishers are created; its logger says what cannot be published.
    scene : Scene
        The scene loaded.
    frame_id, tf_prefix : str
        The ground frame, and the prefix of the child frames ('' for ``frame_id``).
    tf_rate_hz : float
        The rate of ``/tf`` (0: off).
    scene_path : str
        The ``scene`` parameter: its file's text is published on ``scene``.
    source : Source, optional
        What the node loaded (:func:`~mech_kinematics.ros.robot_mode.load_source`):
        its text is published on ``scene``; in URDF mode (``source.robot``)
        the state topics name the URDF's joints (:attr:`robot_values`), the
        URDF is published unchanged on ``robot_description``, and nothing on
        ``/tf``: robot_state_publisher draws the robot from ``joint_states``
        and the URDF (our link frames, a second copy of the loops in the
        scene's plane, would stand beside its tree unconnected).
    watch : PublishWatch, optional
        Every publish of a tick (state, forces, IMUs, ``/tf``) stamps a slot
        of it while it runs, for the node's watchdog
        (:mod:`~mech_kinematics.ros.watchdog`).

    Attributes
    ----------
    tick_scene : Scene
        The scene the ticks solve: ``scene``, outputting also the points and
        joints the frames on ``/tf`` need (only the scene's own outputs are
        published on the state topics).
    frames : tuple of FrameSpec
        The frames on ``/tf`` ((origin, angle joint, fixed angle) each).
    publishers : list
        Every publisher created (the node destroys them at clean-up).
    tf_period_ns : int or None
        The period of ``/tf``, ns (``None``: off); the node sets it when
        ``tf_rate_hz`` changes.
    next_tf : int
        The first stamp at which ``/tf`` is published again, ns.
    robot_values : RobotValues or None
        In URDF mode, the URDF's joints of a tick's values.
    """

    def __init__(self, node: Any, scene: Any, *, frame_id: str, tf_prefix: str,
                 tf_rate_hz: float, scene_path: str, source: Source | None = None,
                 watch: PublishWatch | None = None) -> None:
        self.node = node
        self.watch, self.slot = watch, None if watch is None else watch.slot()
        self.frame_id = frame_id
        self.tf_prefix = tf_prefix
        self.prefix = tf_prefix or frame_id
        self.publishers: list[Any] = []
        robot = source.robot if source is not None else None
        self.robot_values = None if robot is None else \
            RobotValues(robot, scene.output_joints, scene.output_points)
        self.messages = TickMessages(scene.output_joints if robot is None else robot.joint_names,
                                     scene.output_points, frame_id)
        self.tf: TfMessages | None = None
        self.frames: tuple[Any, ...] = ()
        self.imus: ImuMessages | None = None
        self.imu_frames: ImuFrames | None = None
        try:
            self.publish_state = tuple(
                self._watched(topic, self._publisher(kind, topic, state_qos())) for kind, topic
                in ((JointState, topics.JOINT_STATES),
                    (JointTrajectory, topics.JOINT_ACCELERATIONS),
                    (MultiDOFJointTrajectory, topics.POINT_ACCELERATIONS)))
            self.tick_scene = self._setup_tf(scene) if robot is None else scene
            self._setup_imus(scene)
            self._publish_descriptions(scene, scene_path, tf_prefix, source)
        except BaseException:
            self.close()    # a QoS override refused, a sensor beyond doubles: none left behind
            raise
        #: Where the frames' poses start in a tick's values.
        self.tf_first = 3 * len(scene.output_joints) + 6 * len(scene.output_points)
        self.tf_period_ns = tf_period_ns(tf_rate_hz)
        self.next_tf = 0
        #: The forces tick whose values carry the forces (None: no forces published).
        self.forces: ForcesTick | None = None
        self.efforts_first: int | None = None

    def add_forces(self, forces: ForcesTick) -> None:
        """Publish the forces of ``forces``' values: efforts, ``reactions/JOINT``, ``shaking``.

        The wrenches' topics and messages are the forces tick's
        (:meth:`ForcesTick.topics`, :meth:`ForcesTick.messages`: a scene's in
        ``frame_id``, a robot's in each child link's frame). A joint whose
        name makes no valid ROS topic name (a URDF's ``a-b``) has no reaction
        topic: said at set-up, one warning naming the joints.
        """
        joints, points = self.messages.joints, self.messages.points
        self.efforts_first = forces.forces_first
        self.messages = TickMessages(joints, points, self.frame_id,
                                     efforts_first=forces.forces_first)
        self.force_messages = forces.messages(self.frame_id, self.tf_prefix)
        publish: list[Any] = []
        invalid = []
        for topic in forces.topics():
            try:
                validate_topic_name(topic)
            except InvalidTopicNameException:
                invalid.append(topic.partition('/')[2])
                publish.append(None)
                continue
            publish.append(self._watched(topic, self._publisher(WrenchStamped, topic,
                                                                state_qos())))
        self.publish_forces_to = tuple(publish)
        if invalid:
            self.node.get_logger().warning(
                f'no reactions/JOINT topic for {", ".join(invalid)}: not valid in a ROS topic '
                'name (letters, digits and _, not starting with a digit)')
        self.forces = forces

    def publish_forces(self, values: Sequence[float], sec: int, nanosec: int) -> None:
        """Publish a tick's reactions and shaking, or say why its forces are left out."""
        first = self.efforts_first
        assert self.forces is not None and first is not None
        if len(values) <= first:
            self.node.get_logger().warning(f'forces not published: {self.forces.refusal}',
                                           throttle_duration_sec=1.0)
            return
        for publish, data in zip(self.publish_forces_to,
                                 self.force_messages.render(values, first, sec, nanosec),
                                 strict=True):
            if publish is not None:
                publish(data)

    def close(self) -> None:
        """Destroy every publisher created."""
        publishers, self.publishers = self.publishers, []
        for publisher in publishers:
            self.node.destroy_publisher(publisher)

    def _watched(self, topic: str, publisher: Any) -> Callable[[Any], None]:
        """Return ``publisher``'s publish, stamping the watch's slot while it runs."""
        if self.watch is None or self.slot is None:
            return publisher.publish  # type: ignore[no-any-return]
        return self.watch.wrap(self.slot, topic, publisher.publish)

    def _publisher(self, msg_type: Any, topic: str, qos: QoSProfile,
                   overrides: bool = True) -> Any:
        publisher = self.node.create_publisher(
            msg_type, topic, qos, **({'qos_overriding_options': qos_options()} if overrides
                                     else {}))
        self.publishers.append(publisher)
        return publisher

    def _setup_tf(self, scene: Any) -> Any:
        """Create the /tf and /tf_static publishers; return the scene the ticks solve."""
        try:
            from tf2_msgs.msg import TFMessage
        except ImportError:
            self.node.get_logger().warning(
                'tf2_msgs is not installed (make install builds it): no frames on /tf')
            return scene
        frames = frames_from_scene(scene)
        self.tf = TfMessages(frames, self.frame_id, self.prefix)
        self.frames = frames
        self._pub_tf = self._publisher(TFMessage, topics.TF, tf_qos(False))
        self._publish_tf = self._watched(topics.TF, self._pub_tf)
        tf_static = self._publisher(TFMessage, topics.TF_STATIC, tf_qos(True))
        tf_static.publish(static_tf_message(scene.ground, self.frame_id, self.prefix,
                                            self.node.get_clock().now().to_msg()))
        points = [p for p in origin_points(frames) if p not in scene.output_points]
        joints = [j for j in angle_joints(frames) if j not in scene.output_joints]
        if not points and not joints:
            return scene
        return replace(scene, outputs_points=(*scene.output_points, *points),
                       outputs_joints=(*scene.output_joints, *joints))

    def _setup_imus(self, scene: Any) -> None:
        """Create a publisher on ``imu/NAME`` for each of the scene's sensors, and their frames.

        A sensor turned on its link (``angle`` not 0) has a frame of its own,
        published on ``/tf`` with the link frames (when ``/tf`` is on).
        """
        if not scene.imus:
            return
        self.imus = ImuMessages(scene.imus, scene.output_joints, scene.output_points,
                                self.prefix, scene.gravity)
        self._publish_imu = tuple(
            self._watched(topics.imu_topic(spec.name),
                          self._publisher(Imu, topics.imu_topic(spec.name), state_qos()))
            for spec in scene.imus)
        if self.tf is not None:
            # The sensors' offsets on their links, from any pose: the drivers' starts.
            starts = [driver.start for driver in scene.drivers]
            rest = [0.0] * len(starts)
            state = (solve(self.tick_scene, starts[0], 0.0, 0.0, max_error=math.inf)
                     if len(starts) == 1 else
                     solve(self.tick_scene, starts, rest, rest, max_error=math.inf))
            frames = {f.joint: f for f in self.frames}
            transforms = self.imus.frame_transforms(sensor_offsets(scene.imus, frames, state))
            if transforms:
                self.imu_frames = ImuFrames(transforms)

    def _publish_descriptions(self, scene: Any, scene_path: str, tf_prefix: str,
                              source: Source | None = None) -> None:
        """Publish the URDF on ``robot_description`` and the scene's text on ``scene``, latched.

        Transient local, depth 1: a late subscriber (RViz, robot_state_publisher,
        the recorder) gets them. In URDF mode the URDF is the user's, unchanged.
        """
        description = self._publisher(String, topics.ROBOT_DESCRIPTION, tf_qos(True), False)
        text = self._publisher(String, topics.SCENE, tf_qos(True), False)
        text.publish(String(data=scene_text(scene_path) if source is None else source.text))
        if source is not None and source.robot is not None:
            description.publish(String(data=source.robot.description.text))
            return
        try:
            urdf = urdf_from_scene(scene, self.frame_id, tf_prefix)
        except AssemblyError as error:
            self.node.get_logger().warning(f'no robot_description: {error}')
            return
        description.publish(String(data=urdf))

    # -- what a tick publishes (the tick thread) ------------------------------

    def tick(self, values: Sequence[float], stamp: int, sec: int, nanosec: int) -> None:
        """Publish a tick's state at ``stamp`` (``sec``, ``nanosec``): every topic, /tf by rate."""
        if self.robot_values is not None:
            values = self.robot_values.values(values)
        joint_states, joint_accel, point_accel = self.messages.render_values(
            values, sec, nanosec)
        publish_js, publish_jt, publish_pt = self.publish_state
        publish_js(joint_states)
        publish_jt(joint_accel)
        publish_pt(point_accel)
        if self.forces is not None:
            self.publish_forces(values, sec, nanosec)
        if self.imus is not None:
            self.publish_imus(values, sec, nanosec)
        if stamp >= self.next_tf:
            tf_period = self.tf_period_ns
            if self.tf is not None and tf_period is not None:
                self.tf_frames(values, sec, nanosec)
                self.next_tf = stamp + tf_period
            else:
                self.next_tf = stamp + NS_PER_S    # off: look again in a second

    def tf_frames(self, values: Sequence[float], sec: int, nanosec: int) -> None:
        """Publish the frames on ``/tf`` (the links', then the sensors' own) of a tick's values."""
        assert self.tf is not None
        self._publish_tf(self.tf.render_values(values, self.tf_first, sec, nanosec))
        if self.imu_frames is not None:    # a sensor's frame is a position: known here
            self._publish_tf(self.imu_frames.render(sec, nanosec))

    def tf_due(self, stamp: int) -> bool:
        """Return whether ``/tf`` is on and due at ``stamp`` (an input's); if so, count it."""
        if self.tf is None or self.tf_period_ns is None or stamp < self.next_tf:
            return False
        self.next_tf = stamp + self.tf_period_ns
        return True

    def publish_imus(self, values: Sequence[float], sec: int, nanosec: int) -> None:
        """Publish every sensor's ``Imu`` of a tick's values (none whose reading overflows)."""
        assert self.imus is not None
        for publish, data, sensor in zip(self._publish_imu,
                                         self.imus.render_values(values, sec, nanosec),
                                         self.imus.specs, strict=True):
            if data is None:
                self.node.get_logger().warning(f'imu/{sensor.name}: no reading published: '
                                               'beyond the range of doubles',
                                               throttle_duration_sec=1.0)
            else:
                publish(data)


class Markers:
    """RViz markers of a scene, built in the executor's thread from samples the ticks hand over.

    Parameters
    ----------
    node : rclpy.node.Node
        Where the publisher and the guard condition are created.
    scene : Scene
        The scene loaded (its whole mechanism is drawn, its outputs' arrows).
    frame_id : str
        The frame of the markers.
    scales : callable
        ``scales()`` returns (velocity scale, acceleration scale, force scale)
        now (the parameters ``marker_velocity_scale``,
        ``marker_acceleration_scale``, ``marker_force_scale``).
    forces : ForcesTick or None
        On a scene whose forces the node publishes, its forces tick: the
        reactions are drawn as arrows, solved with its current ``dynamics``
        (``effort: static``: at rest).
    """

    def __init__(self, node: Any, scene: Any, frame_id: str,
                 scales: Callable[[], tuple[float, float, float]],
                 forces: ForcesTick | None = None) -> None:
        self.node = node
        self.frame_id = frame_id
        self.scales = scales
        self.points = scene.output_points
        # A robot's reactions are in its links' frames, not drawn in the scene's (URDF mode).
        self.forces = forces if forces is not None and forces.scene_reactions else None
        # The motion alone (the forces, with the parameters' values, are the forces tick's).
        self.scene = full_scene(scene if forces is None else forces.kinematics)
        self.strokes = strokes_from_scene(self.scene)
        try:
            self.size: float | None = marker_size_from_space(space_from_state(
                self.scene, solve_at_start(self.scene)))
        except AssemblyError:
            self.size = None    # the part beyond the outputs cannot assemble here
        self.throttle = MarkerThrottle()
        self._lock = threading.Lock()
        self._request: tuple[int, int, Any, Any, Any] | None = None
        self._guard = node.create_guard_condition(self.publish)
        self.publisher: Any = node.create_publisher(MarkerArray, topics.MARKERS, 10,
                                                    qos_overriding_options=qos_options())

    def close(self) -> None:
        """Destroy the publisher: a sample handed over later publishes nothing."""
        publisher, self.publisher = self.publisher, None
        if publisher is not None:
            self.node.destroy_publisher(publisher)

    def request(self, period_ns: int, sec: int, nanosec: int, angle: Any, speed: Any,
                accel: Any) -> None:
        """Hand a tick's drivers over for markers, if they are due (the tick thread)."""
        if self.throttle.due(period_ns, time.monotonic_ns()):
            with self._lock:
                self._request = (sec, nanosec, angle, speed, accel)
            self._guard.trigger()

    def publish(self) -> None:
        """Publish the markers of the last sample handed over, if any (the executor's thread)."""
        with self._lock:
            request, self._request = self._request, None
        if request is None or self.publisher is None:
            return
        sec, nanosec, angle, speed, accel = request
        try:
            state = solve(self.scene, angle, speed, accel)
            reactions = self._reactions(state, angle)
        except AssemblyError:
            return      # a part beyond the outputs cannot assemble: no markers this time
        velocity_scale, acceleration_scale, force_scale = self.scales()
        self.publisher.publish(marker_array_from_state(
            self.scene, state, frame_id=self.frame_id, stamp=Time(sec=sec, nanosec=nanosec),
            velocity_scale=velocity_scale, acceleration_scale=acceleration_scale,
            points=self.points, size=self.size, strokes=self.strokes, reactions=reactions,
            force_scale=force_scale))

    def _reactions(self, state: Any, angle: Any) -> list[tuple[complex, complex]]:
        """Return each joint's point and the force on its body at ``state`` (none: no forces)."""
        forces = self.forces
        if forces is None:
            return []
        at = state
        if forces.static:
            rest = 0.0 if forces.drivers == 1 else (0.0,) * forces.drivers
            at = solve(self.scene, angle, rest, rest)
        solved = forces.dynamics.forces(at, math.inf)
        if not solved.valid:    # the statics degenerate here: no arrows, never a guess
            return []
        out = []
        for joint in forces.reactions:
            fx, fy, _ = reaction_wrench(joint, solved, at)
            out.append((complex(at.complex_points[joint.at][0]), complex(fx, fy)))
        return out
