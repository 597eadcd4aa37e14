# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node driven from a topic (``drive: topic``), over real DDS, from another process.

See issue 18. This process publishes ``JointState`` messages with distinct
stamps to the node's ``input_joint_states``; the node must publish exactly one
state per accepted message on every state topic (and /tf), stamped with the
input's stamp, positions as the solver gives them, velocities only when the
input has them, accelerations never; each bad message is refused on
``diagnostics`` with its reason while the node goes on.
"""

import math
import time

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from lifecycle_msgs.msg import Transition
from lifecycle_msgs.srv import ChangeState
import numpy as np
import pytest
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from rclpy.qos import QoSProfile, ReliabilityPolicy
from ros_helpers import (cannot_start, exited, NodeProcess, NS, SESSION, stamp_ns, STARTUP_S,
                         wait_for, wait_for_parameters)
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


class TopicNode:
    """A node with drive: topic in a namespace of its own, and what it publishes, as received."""

    def __init__(self, ros, tmp_path, name, *args, input_topic=None, wait=True,
                 input_qos=INPUT_QOS):
        self.ns = f'{SESSION}/{name}'
        self.prefix = f'{SESSION[1:]}_{name}'
        self.js = ros.collect(JointState, f'{self.ns}/joint_states')
        self.jt = ros.collect(JointTrajectory, f'{self.ns}/joint_accelerations')
        self.pt = ros.collect(MultiDOFJointTrajectory, f'{self.ns}/point_accelerations')
        self.tf = ros.collect(TFMessage, '/tf')
        self.diag = ros.collect(DiagnosticArray, f'{self.ns}/diagnostics')
        self.input = ros.node.create_publisher(
            JointState, input_topic or f'{self.ns}/input_joint_states', input_qos)
        self.proc = NodeProcess(tmp_path, '-r', f'__ns:={self.ns}', '-p', f'scene:={SCENE}',
                                '-p', 'drive:=topic', '-p', 'tf_rate_hz:=10000.0',
                                '-p', f'tf_prefix:={self.prefix}', *args)
        if wait:
            self.wait_for_subscription()

    def wait_for_subscription(self):
        wait_for(lambda: self.input.get_subscription_count() > 0 or self.proc.proc.poll(),
                 STARTUP_S, 'the node subscribing to input_joint_states')
        assert self.proc.proc.poll() is None, self.proc.output()

    def send(self, stamp, names, positions, velocities=()):
        msg = JointState(name=list(names), position=list(positions),
                         velocity=list(velocities))
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp, NS)
        self.input.publish(msg)

    def tf_stamps(self):
        return [stamp_ns(t) for m in self.tf for t in m.transforms
                if t.child_frame_id == f'{self.prefix}/crank']

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
        (['crank', 'wrist'], [0.1, 0.2], [], "unknown joint(s) 'wrist'"),
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
    change = ros.node.create_client(ChangeState, f'{node.ns}/mech_kinematics/change_state')

    def transition(transition_id):
        request = ChangeState.Request(transition=Transition(id=transition_id))
        assert ros.call(change.call_async(request)).success

    try:
        assert change.wait_for_service(timeout_sec=STARTUP_S)
        transition(Transition.TRANSITION_CONFIGURE)
        node.wait_for_subscription()
        node.send(T0 + 1, ['crank'], [0.1])       # inactive: nothing
        transition(Transition.TRANSITION_ACTIVATE)
        node.send(T0 + 2, ['crank'], [0.2])
        wait_for(lambda: node.js, ANSWER_S, 'a state once active')
        transition(Transition.TRANSITION_DEACTIVATE)
        node.send(T0 + 3, ['crank'], [0.3])       # inactive again: nothing
        transition(Transition.TRANSITION_ACTIVATE)
        node.send(T0 + 4, ['crank'], [0.4])
        wait_for(lambda: len(node.js) >= 2, ANSWER_S, 'a state once active again')
        time.sleep(0.3)
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
    node = TopicNode(ros, tmp_path, 'topic_five_bar', '-p', 'scene:=five_bar')
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
    node = TopicNode(ros, tmp_path, 'topic_excavator', '-p', 'scene:=excavator')
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


@pytest.mark.parametrize('args, words', [
    (['-p', 'drive:=topic', '-p', 'markers:=true'], ['markers: expected false with drive: topic']),
    (['-p', 'drive:=stream'], ["drive: expected one of time, topic, got 'stream'"]),
])
def test_a_bad_drive_at_start_is_one_line_and_exit_1(tmp_path, args, words):
    """``drive`` takes time or topic; markers (velocity arrows) are refused with topic."""
    proc = NodeProcess(tmp_path, '-r', f'__ns:={SESSION}/topic_bad_start', *args)
    status, output = exited(proc)
    assert status == 1, output
    fatal = cannot_start(output)
    assert len(fatal) == 1, output
    assert all(word in fatal[0] for word in words), output
