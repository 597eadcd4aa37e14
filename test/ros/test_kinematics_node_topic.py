# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node driven from a topic (``drive: topic``), over real DDS, from another process.

See issue 18. This process publishes ``JointState`` messages with distinct
stamps to the node's ``input_joint_states``; the node must publish exactly one
state per accepted message on every state topic (and /tf), stamped with the
input's stamp, positions as the solver gives them, velocities only when the
input has them, accelerations never; each bad message is refused on
``diagnostics`` with its reason while the node goes on.

A message sent before the node's subscription has matched this process's
publisher is lost (the publisher may see the match first), so every node is
first greeted (:meth:`TopicNode.handshake`): messages stamped before
:data:`T0` are sent until one is answered; what answers them is not kept.
"""

import math
import time

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from lifecycle_msgs.msg import Transition
import numpy as np
import pytest
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from rclpy.qos import QoSProfile, ReliabilityPolicy
from ros_helpers import (cannot_start, Lifecycle, NodeProcess, NS, refused_starts, RELIABLE,
                         send_until, SESSION, stamp_ns, STARTUP_S, wait_for,
                         wait_for_parameters)
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage
from trajectory_msgs.msg import JointTrajectory, MultiDOFJointTrajectory

import mech_kinematics as mk

#: A scene that does not assemble for crank angles 103.8..256.2 deg (its crank: 'crank').
SCENE = 'four_bar_coupler_points'
#: Published values are the compiled tick's, the reference the general solver's (rad, m, /s).
ATOL = 1e-12
INPUT_QOS = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
#: Deadline for the node's answers to arrive, s.
ANSWER_S = 10.0
#: The first stamp sent, ns (any positive instant: the node never reads its own clock here).
T0 = 1_700_000_000 * NS
#: The stamp of the first greeting (TopicNode.handshake), ns; greetings are 1 ms apart.
HELLO = T0 - 100 * NS


class TopicNode:
    """A node with drive: topic in a namespace of its own, and what it publishes, as received."""

    def __init__(self, ros, tmp_path, name, *args, scene=SCENE, input_topic=None, wait=True,
                 input_qos=INPUT_QOS, drive='topic', greeting=None, input_type=JointState):
        self.ns = f'{SESSION}/{name}'
        self.prefix = f'{SESSION[1:]}_{name}'
        # What the greetings send: the drivers at their start, or (names, positions) given.
        if greeting is None:
            drivers = mk.load_scene(scene).drivers
            greeting = ([d.name for d in drivers], [d.start for d in drivers])
        self.greeting = greeting
        self.greeted = []
        # The states answering the greetings (stamped before T0) are not kept.
        self.js = self._collect(ros, JointState, 'joint_states')
        self.jt = self._collect(ros, JointTrajectory, 'joint_accelerations')
        self.pt = self._collect(ros, MultiDOFJointTrajectory, 'point_accelerations')
        self.tf = ros.collect(TFMessage, '/tf')
        self.diag = ros.collect(DiagnosticArray, f'{self.ns}/diagnostics')
        self.input_type = input_type
        self.input = ros.node.create_publisher(
            input_type, input_topic or f'{self.ns}/input_joint_states', input_qos)
        self.input_name = (input_topic or 'input_joint_states').rsplit('/', 1)[-1]
        self.hello = HELLO
        self.proc = NodeProcess(tmp_path, '-r', f'__ns:={self.ns}', '-p', f'scene:={scene}',
                                '-p', f'drive:={drive}', '-p', 'tf_rate_hz:=10000.0',
                                '-p', f'tf_prefix:={self.prefix}', *args)
        if wait:
            self.wait_for_subscription()
            self.handshake()

    def _collect(self, ros, msg_type, topic):
        kept = []

        def keep(msg):
            if stamp_ns(msg) >= T0:
                kept.append(msg)
            elif msg_type is JointState:
                self.greeted.append(msg)
        ros.node.create_subscription(msg_type, f'{self.ns}/{topic}', keep, RELIABLE)
        return kept

    def wait_for_subscription(self):
        wait_for(lambda: self.input.get_subscription_count() > 0 or self.proc.proc.poll(),
                 STARTUP_S, f'the node subscribing to {self.input_name}')
        assert self.proc.proc.poll() is None, self.proc.output()

    def handshake(self):
        """Send the drivers at their start until the node answers one (it hears us from then).

        The publisher may see the node's subscription before the subscription has
        matched the publisher: a message sent then is lost. The greetings are
        stamped 1 ms apart before T0, and their answers are not kept.
        """
        def greet():
            self.send(self.hello, *self.greeting)
            self.hello += 1_000_000

        send_until(greet, lambda: self.greeted or self.proc.proc.poll() is not None,
                   STARTUP_S, f'the node answering a greeting on {self.input_name}', every=0.2)
        assert self.proc.proc.poll() is None, self.proc.output()

    def send(self, stamp, names, positions, velocities=(), efforts=()):
        """Send one input at ``stamp``: a JointState, or a one-point trajectory at rest."""
        if self.input_type is JointTrajectory:
            self.send_points(stamp, names, [(0, positions, velocities or [0.0] * len(names),
                                             [0.0] * len(names))])
            return
        msg = JointState(name=list(names), position=list(positions),
                         velocity=list(velocities), effort=list(efforts))
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp, NS)
        self.input.publish(msg)

    def send_points(self, stamp, names, points):
        """Send a trajectory stamped ``stamp``: points (time_from_start ns, p, v, a)."""
        from trajectory_msgs.msg import JointTrajectoryPoint

        msg = JointTrajectory(joint_names=list(names))
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp, NS)
        for at, p, v, a in points:
            point = JointTrajectoryPoint(positions=list(p), velocities=list(v),
                                         accelerations=list(a))
            point.time_from_start.sec, point.time_from_start.nanosec = divmod(at, NS)
            msg.points.append(point)
        self.input.publish(msg)

    def tf_stamps(self):
        return [stamp_ns(t) for m in self.tf for t in m.transforms
                if t.child_frame_id == f'{self.prefix}/crank' and stamp_ns(t) >= T0]

    def solver_statuses(self, since=0):
        """Return the solver statuses on diagnostics from message ``since`` on, oldest first."""
        return [status for msg in self.diag[since:] for status in msg.status
                if status.name.endswith(': solver')]

    def refusal(self, since, reason):
        """Return the first solver status from message ``since`` on that says ``reason``."""
        found = [s for s in self.solver_statuses(since) if reason in s.message]
        return found[0] if found else None

    def stop(self):
        status, _ = self.proc.stop()
        assert status == 0, self.proc.output()


def test_one_state_per_input_message_with_its_stamp(ros, tmp_path):
    """N messages with distinct stamps: N states on every topic, each with its input's stamp."""
    node = TopicNode(ros, tmp_path, 'topic_states')
    scene = mk.load_scene(SCENE)
    angles = np.linspace(-1.5, 1.5, 40)    # assembles everywhere here
    stamps = [T0 + 1_000_000 * i + 7 * i * i for i in range(len(angles))]
    speeds = [3.0 - 0.1 * i if i % 2 else None for i in range(len(angles))]
    try:
        for stamp, angle, speed in zip(stamps, angles, speeds, strict=True):
            node.send(stamp, ['crank'], [angle], [] if speed is None else [speed])
        for name, got in (('joint_states', node.js), ('joint_accelerations', node.jt),
                          ('point_accelerations', node.pt)):
            wait_for(lambda got=got: len(got) >= len(stamps), ANSWER_S, name)
        wait_for(lambda: len(node.tf_stamps()) >= len(stamps), ANSWER_S, '/tf')
        assert node.proc.proc.poll() is None
    finally:
        node.stop()
    for got in (node.js, node.jt, node.pt):
        assert [stamp_ns(m) for m in got] == stamps
    assert node.tf_stamps() == stamps
    for js, jt, pt, angle, speed in zip(node.js, node.jt, node.pt, angles, speeds,
                                        strict=True):
        state = mk.solve(scene, angle, 0.0 if speed is None else speed, 0.0)
        joints = scene.output_joints
        assert js.name == list(joints)
        np.testing.assert_allclose(js.position, [state.joints[n].position for n in joints],
                                   rtol=0, atol=ATOL)
        np.testing.assert_allclose(jt.points[0].positions, js.position, rtol=0, atol=0)
        assert not jt.points[0].accelerations and not pt.points[0].accelerations
        xy = [c for n in scene.output_points for c in state.points[n].position]
        np.testing.assert_allclose(
            [c for t in pt.points[0].transforms for c in (t.translation.x, t.translation.y)],
            xy, rtol=0, atol=ATOL)
        if speed is None:
            assert not js.velocity and not jt.points[0].velocities
            assert not pt.points[0].velocities
        else:
            velocities = [state.joints[n].velocity for n in joints]
            np.testing.assert_allclose(js.velocity, velocities, rtol=0, atol=ATOL)
            assert js.velocity[0] == speed
            np.testing.assert_allclose(jt.points[0].velocities, velocities, rtol=0, atol=ATOL)
            np.testing.assert_allclose(
                [c for v in pt.points[0].velocities for c in (v.linear.x, v.linear.y)],
                [c for n in scene.output_points for c in state.points[n].velocity],
                rtol=0, atol=ATOL)


def test_bad_messages_are_refused_on_diagnostics_and_the_node_goes_on(ros, tmp_path):
    """Each bad message publishes nothing and says why on diagnostics; good ones go on."""
    node = TopicNode(ros, tmp_path, 'topic_refusals')
    bad = [
        (['crank', 'wrist'], [0.1, 0.2], [],
         "unknown joint(s) 'wrist' (extra_joints:=ignore|pass takes the drivers"),
        (['rocker'], [0.1], [], "unknown joint(s) 'rocker'"),
        ([], [], [], "got none for 'crank'"),
        (['crank'], [math.nan], [], "expected a finite position of 'crank', got nan"),
        (['crank'], [0.1], [1.0, 2.0], 'expected no velocity or one per name (1), got 2'),
        (['crank'], [math.pi], [], 'circles about B (radius 0.066 m) and D (radius 0.056 m) '
         'do not meet'),
        (['crank'], [0.2], [], 'expected a stamp after the last published one'),
    ]
    published = []
    stamp = T0
    try:
        for names, positions, velocities, reason in bad:
            stamp += NS
            node.send(stamp, ['crank'], [0.1])
            published.append(stamp)
            count = len(published)
            wait_for(lambda n=count: len(node.js) >= n, ANSWER_S, 'a good state')
            seen = len(node.diag)
            # The backwards one repeats the good stamp just published; the others are later.
            node.send(stamp if 'stamp after' in reason else stamp + 1, names, positions,
                      velocities)
            status = wait_for(lambda n=seen, r=reason: node.refusal(n, r), ANSWER_S,
                              f'diagnostics saying {reason!r}')
            assert status.level == DiagnosticStatus.ERROR, status.message
            kind = 'cannot assemble' if 'do not meet' in reason else 'refused input'
            assert status.message.startswith(f'{kind} at 1 of '), status.message
            assert reason in {v.key: v.value for v in status.values}['last_error']
            if 'stamp after' in reason:
                stamp += 1      # the later, good message below must pass the refused one
        stamp += NS
        node.send(stamp, ['crank'], [0.3], [1.0])
        published.append(stamp)
        wait_for(lambda: len(node.js) >= len(published), ANSWER_S, 'the last good state')
        seen = len(node.diag)
        wait_for(lambda: node.solver_statuses(seen), ANSWER_S, 'diagnostics after the last')
        values = {v.key: v.value for v in node.solver_statuses(seen)[-1].values}
        assert node.proc.proc.poll() is None
    finally:
        node.stop()
    assert [stamp_ns(m) for m in node.js] == published
    assert [stamp_ns(m) for m in node.pt] == published
    assert int(values['unsolved_ticks_total']) == len(bad)
    assert 'Traceback' not in node.proc.output()


def test_a_managed_node_publishes_only_while_active(ros, tmp_path):
    """managed:=true: subscribed from configure, a state per message only while active."""
    node = TopicNode(ros, tmp_path, 'topic_managed', '-p', 'managed:=true', wait=False)

    def transition(transition_id):
        assert life.transition(transition_id)

    try:
        life = Lifecycle(ros, f'{node.ns}/mech_kinematics')
        transition(Transition.TRANSITION_CONFIGURE)
        node.wait_for_subscription()
        transition(Transition.TRANSITION_ACTIVATE)
        node.handshake()                          # from now on every message reaches it
        transition(Transition.TRANSITION_DEACTIVATE)
        node.send(T0 + 1, ['crank'], [0.1])       # inactive: nothing
        transition(Transition.TRANSITION_ACTIVATE)
        node.send(T0 + 2, ['crank'], [0.2])
        wait_for(lambda: node.js, ANSWER_S, 'a state once active')
        transition(Transition.TRANSITION_DEACTIVATE)
        node.send(T0 + 3, ['crank'], [0.3])       # inactive again: nothing
        transition(Transition.TRANSITION_ACTIVATE)
        node.send(T0 + 4, ['crank'], [0.4])
        # Answers come in the order sent: T0 + 1's and T0 + 3's would come before this one.
        wait_for(lambda: any(stamp_ns(m) == T0 + 4 for m in node.js), ANSWER_S,
                 'a state once active again')
    finally:
        node.stop()
    assert [stamp_ns(m) for m in node.js] == [T0 + 2, T0 + 4]


def test_the_input_topic_is_remapped_and_drive_is_read_only(ros, tmp_path):
    """``-r input_joint_states:=/motors/joint_states`` drives the node; ``drive`` stays topic.

    Setting ``drive`` while running is refused with a reason; the node goes on
    publishing a state per message, and nothing of the grid's runs meanwhile.
    """
    motors = f'{SESSION}/motors/joint_states'
    node = TopicNode(ros, tmp_path, 'topic_remap', '-r', f'input_joint_states:={motors}',
                     input_topic=motors)
    params = AsyncParameterClient(ros.node, f'{node.ns}/mech_kinematics')
    try:
        wait_for_parameters(params)
        node.send(T0 + 5, ['crank'], [0.25], [2.0])
        wait_for(lambda: node.js, ANSWER_S, 'a state from the remapped topic')
        [result] = ros.call(params.set_parameters([Parameter('drive', value='time')])).results
        assert not result.successful
        assert 'drive' in result.reason and 'read-only' in result.reason, result.reason
        [value] = ros.call(params.get_parameters(['drive'])).values
        assert value.string_value == 'topic'
        time.sleep(0.5)     # a grid would have published 50 states by now
        assert len(node.js) == 1
        node.send(T0 + 6, ['crank'], [0.5])
        wait_for(lambda: len(node.js) == 2, ANSWER_S, 'a state after the refusal')
    finally:
        node.stop()
    assert [stamp_ns(m) for m in node.js] == [T0 + 5, T0 + 6]
    assert node.js[0].position[0] == 0.25 and node.js[0].velocity[0] == 2.0
    assert node.js[1].position[0] == 0.5 and not node.js[1].velocity
    assert any('parameter refused: drive: read-only' in line
               for line in node.proc.output().splitlines())


def test_the_input_qos_is_overridden_like_the_publishers(ros, tmp_path):
    """A best-effort publisher drives a node whose input's reliability is overridden.

    ``qos_overrides./NS/input_joint_states.subscription.reliability:=best_effort``
    (a reliable subscription would not match that publisher).
    """
    ns = f'{SESSION}/topic_qos'
    node = TopicNode(ros, tmp_path, 'topic_qos', '-p',
                     f'qos_overrides.{ns}/input_joint_states.subscription.reliability:='
                     'best_effort', input_qos=QoSProfile(
                         depth=10, reliability=ReliabilityPolicy.BEST_EFFORT))
    sent = []

    def send_until_answered():
        # Best effort: a message sent before the match is complete is lost; send again.
        sent.append(T0 + len(sent))
        node.send(sent[-1], ['crank'], [0.2])
        return node.js

    try:
        wait_for(send_until_answered, ANSWER_S, 'a state from a best-effort input')
    finally:
        node.stop()
    assert stamp_ns(node.js[0]) in sent


def test_several_drivers_from_one_message(ros, tmp_path):
    """Five-bar: both cranks in one message give the whole state; one missing is refused."""
    scene = mk.load_scene('five_bar')
    node = TopicNode(ros, tmp_path, 'topic_five_bar', scene='five_bar')
    poses = [(1.5 + 0.01 * i, 1.0 - 0.02 * i, 0.5 * i - 2.0, 1.0) for i in range(10)]
    try:
        for i, (left, right, v_left, v_right) in enumerate(poses):
            # The message's order need not be the scene's.
            node.send(T0 + i, ['right_crank', 'left_crank'], [right, left], [v_right, v_left])
        wait_for(lambda: len(node.pt) >= len(poses), ANSWER_S, 'the five-bar states')
        seen = len(node.diag)
        node.send(T0 + 100, ['left_crank'], [1.5])
        status = wait_for(lambda: node.refusal(seen, "got none for 'right_crank'"), ANSWER_S,
                          'the refusal of a message missing a crank')
        assert status.level == DiagnosticStatus.ERROR
    finally:
        node.stop()
    assert [stamp_ns(m) for m in node.js] == [T0 + i for i in range(len(poses))]
    for msg, (left, right, v_left, v_right) in zip(node.js, poses, strict=True):
        state = mk.solve(scene, [left, right], [v_left, v_right], [0.0, 0.0])
        np.testing.assert_allclose(msg.position, [state.joints[n].position for n in msg.name],
                                   rtol=0, atol=ATOL)
        np.testing.assert_allclose(msg.velocity, [state.joints[n].velocity for n in msg.name],
                                   rtol=0, atol=ATOL)


def test_an_actuator_length_outside_its_stroke_is_refused(ros, tmp_path):
    """Excavator: cylinder lengths in, the arm out; a length beyond the stroke is refused."""
    scene = mk.load_scene('excavator')
    node = TopicNode(ros, tmp_path, 'topic_excavator', scene='excavator')
    try:
        node.send(T0, ['boom_cyl', 'stick_cyl'], [2.8, 3.1])
        wait_for(lambda: node.js, ANSWER_S, 'the excavator state')
        seen = len(node.diag)
        node.send(T0 + 1, ['boom_cyl', 'stick_cyl'], [3.4, 3.1])
        reason = "expected 'boom_cyl' within its stroke [2, 3.3] m, got 3.4 m"
        wait_for(lambda: node.refusal(seen, reason), ANSWER_S, 'the stroke refusal')
        node.send(T0 + 2, ['boom_cyl', 'stick_cyl'], [3.3, 2.5])     # both limits: inclusive
        wait_for(lambda: len(node.js) >= 2, ANSWER_S, 'a state at the stroke limits')
    finally:
        node.stop()
    assert [stamp_ns(m) for m in node.js] == [T0, T0 + 2]
    state = mk.solve(scene, [3.3, 2.5])
    msg = node.js[1]
    assert not msg.velocity
    np.testing.assert_allclose(msg.position, [state.joints[n].position for n in msg.name],
                               rtol=0, atol=ATOL)


def values_of(status):
    return {v.key: v.value for v in status.values}


def test_a_far_future_stamp_does_not_end_the_stream(ros, tmp_path):
    """Issue 33: after one message stamped 2^31 - 1 s, ordinary messages are published again.

    Every later message was refused as "not after the last published one". An
    earlier stamp by more than stamp_jump_back_s (1 s) resets the order, is
    published (/tf too) and is said on diagnostics (WARN, counted, the jump); one
    earlier by less is still refused.
    """
    node = TopicNode(ros, tmp_path, 'topic_far_future')
    far = (2**31 - 1) * NS
    stamps = [T0, far, T0 + NS, T0 + NS + 2_000_000]
    try:
        for i, (stamp, angle) in enumerate(zip(stamps[:3], (0.1, 0.2, 0.3), strict=True)):
            seen = len(node.diag)
            node.send(stamp, ['crank'], [angle])
            wait_for(lambda n=i + 1: len(node.js) >= n, ANSWER_S, f'the state stamped {stamp}')
        jump = 'from 2147483647.000000000 s to 1700000001.000000000 s, 447483646 s back'
        status = wait_for(lambda: node.refusal(seen, 'input stamp jumped back'), ANSWER_S,
                          'diagnostics saying the stamp jumped back')
        assert status.level == DiagnosticStatus.WARN
        assert status.message == ('input stamp jumped back 1 time(s) (the order reset), last '
                                  f'{jump}')
        node.send(stamps[3], ['crank'], [0.4])
        wait_for(lambda: len(node.js) >= 4, ANSWER_S, 'the state after the jump')
        seen = len(node.diag)
        node.send(stamps[3] - 1_000_000, ['crank'], [0.5])     # 1 ms back: out of order
        status = wait_for(lambda: node.refusal(seen, 'expected a stamp after'), ANSWER_S,
                          'the refusal of a stamp 1 ms back')
        assert status.level == DiagnosticStatus.ERROR
        values = values_of(status)
        wait_for(lambda: len(node.tf_stamps()) >= 4 and len(node.pt) >= 4, ANSWER_S,
                 '/tf and point_accelerations after the jump')
    finally:
        node.stop()
    assert [stamp_ns(m) for m in node.js] == stamps
    assert [stamp_ns(m) for m in node.pt] == stamps
    assert node.tf_stamps() == stamps
    np.testing.assert_allclose([m.position[0] for m in node.js], [0.1, 0.2, 0.3, 0.4],
                               rtol=0, atol=ATOL)
    assert values['stamp_jumps_back_total'] == '1' and values['last_stamp_jump_back'] == jump
    assert 'stamp_jump_back_s' in values['last_error']
    assert any('the stamp jumped back 447483646 s' in line
               for line in node.proc.output().splitlines())


#: A robot's whole joint_states: the crank among joints of other parts (and the coupler,
#: which the node computes itself).
ROBOT = ['wrist', 'crank', 'coupler', 'gripper']


def test_extra_joints_pass_puts_the_robots_other_joints_after_the_mechanisms(ros, tmp_path):
    """extra_joints:=pass: the input's other joints are published unchanged after ours.

    Issue 33: a real /joint_states carries every joint of the robot. The crank is
    taken; 'wrist' and 'gripper' follow the mechanism's joints in joint_states
    with their position, velocity and effort (effort NaN, unknown, for the
    mechanism's); 'coupler', published by the node, is ignored, not passed twice.
    Diagnostics say which joints were passed and ignored.
    """
    scene = mk.load_scene(SCENE)
    joints = list(scene.output_joints)
    node = TopicNode(ros, tmp_path, 'topic_pass', '-p', 'extra_joints:=pass')
    try:
        node.send(T0, ROBOT, [0.3, 0.2, 9.9, 0.05], [0.5, 2.0, 0.0, -0.1], [1.0, 2.0, 3.0, 4.0])
        node.send(T0 + 1, ROBOT[::-1], [0.06, 9.9, 0.25, 0.31])
        wait_for(lambda: len(node.js) >= 2 and len(node.jt) >= 2, ANSWER_S, 'two states')
        # The solver status of the first diagnostics whose last published stamp is the
        # second message's: its window holds that tick (a later one says 'no ticks').
        status = wait_for(lambda: [s for msg in node.diag
                                   if any(values_of(t).get('last_published_stamp_ns')
                                          == str(T0 + 1) for t in msg.status)
                                   for s in msg.status if s.name.endswith(': solver')],
                          ANSWER_S, 'diagnostics of the second state')[0]
    finally:
        node.stop()
    first, second = node.js
    assert first.name == [*joints, 'wrist', 'gripper']
    state = mk.solve(scene, 0.2, 2.0, 0.0)
    np.testing.assert_allclose(first.position, [*(state.joints[n].position for n in joints),
                                                0.3, 0.05], rtol=0, atol=ATOL)
    np.testing.assert_allclose(first.velocity, [*(state.joints[n].velocity for n in joints),
                                                0.5, -0.1], rtol=0, atol=ATOL)
    np.testing.assert_array_equal(first.effort, [math.nan] * len(joints) + [1.0, 4.0])
    assert second.name == [*joints, 'gripper', 'wrist']
    assert list(second.position[-2:]) == [0.06, 0.31]
    assert not second.velocity and not second.effort
    assert [m.joint_names for m in node.jt] == [joints, joints]
    values = values_of(status)
    assert status.level == DiagnosticStatus.OK, status.message
    assert (values['extra_joints'], values['passed_joints'], values['ignored_joints']) == \
        ('pass', 'gripper, wrist', 'coupler')


def test_extra_joints_ignore_takes_the_drivers_and_says_what_it_dropped(ros, tmp_path):
    """extra_joints:=ignore: a message with other joints publishes the mechanism's state only."""
    node = TopicNode(ros, tmp_path, 'topic_ignore', '-p', 'extra_joints:=ignore')
    try:
        node.send(T0, ROBOT, [0.3, 0.2, 9.9, 0.05], [0.5, 2.0, 0.0, -0.1])
        wait_for(lambda: node.js, ANSWER_S, 'the state')
        seen = len(node.diag)
        status = wait_for(lambda: node.solver_statuses(seen), ANSWER_S, 'diagnostics')[-1]
    finally:
        node.stop()
    [msg] = node.js
    assert msg.name == list(mk.load_scene(SCENE).output_joints)
    assert msg.position[0] == 0.2 and msg.velocity[0] == 2.0 and not msg.effort
    values = values_of(status)
    assert (values['extra_joints'], values['ignored_joints'], values['passed_joints']) == \
        ('ignore', 'wrist, coupler, gripper', '')


#: Bad drives at start: (arguments, words of the one line that refuses them).
BAD_DRIVES = [
    (['-p', 'drive:=topic', '-p', 'markers:=true'], ['markers: expected false with drive: topic']),
    (['-p', 'drive:=stream'],
     ["drive: expected one of time, topic, target, trajectory, got 'stream'"]),
]


@pytest.fixture(scope='module')
def bad_drives(tmp_path_factory):
    """(status, output) of each start of BAD_DRIVES, by its arguments (run side by side)."""
    results = refused_starts(tmp_path_factory.mktemp('topic_bad_start'), [
        ['-r', f'__ns:={SESSION}/topic_bad_start{i}', *args]
        for i, (args, _) in enumerate(BAD_DRIVES)])
    return {tuple(args): result for (args, _), result in zip(BAD_DRIVES, results, strict=True)}


@pytest.mark.parametrize('args, words', BAD_DRIVES)
def test_a_bad_drive_at_start_is_one_line_and_exit_1(bad_drives, args, words):
    """``drive`` takes time or topic; markers (velocity arrows) are refused with topic."""
    status, output = bad_drives[tuple(args)]
    assert status == 1, output
    fatal = cannot_start(output)
    assert len(fatal) == 1, output
    assert all(word in fatal[0] for word in words), output
