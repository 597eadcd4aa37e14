# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``drive: topic``'s node side (ros/topic_input.py) on a stand-in node: one state a message.

The per-message rules are topic_drive.py's (``test_topic_drive.py``); here,
what the subscription does with a message: its state published with its
stamp (no accelerations; velocities only when given), ``/tf`` by the input's
time, the other joints passed through, a refusal counted with its reason, a
stamp's jump back said, and nothing while inactive. The node driven over DDS
is ``test_kinematics_node_topic.py``'s.
"""

import math
from pathlib import Path

from builtin_interfaces.msg import Time
from rclpy.qos import QoSReliabilityPolicy
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import JointState

import mech_kinematics as mk
from mech_kinematics.ros.diagnostics import TickStats
from mech_kinematics.ros.parameters import STATIC, TOPIC
from mech_kinematics.ros.publishing import Publishing, RCLError
from mech_kinematics.ros.robot_mode import load_source
from mech_kinematics.ros.solver_path import SolverPath
from mech_kinematics.ros.topic_input import INPUT_DEPTH, InputSubscription
from mech_kinematics.ros.wrenches import forces_tick

#: The real robots' URDFs.
URDF = Path(__file__).resolve().parents[1] / 'data' / 'urdf'
#: A stamp of an input, s.
SEC = 1_700_000_000


class Publisher:
    def __init__(self, msg_type, topic):
        self.msg_type, self.topic, self.sent = msg_type, topic, []

    def publish(self, msg):
        self.sent.append(msg)


class Logger:
    def __init__(self):
        self.lines = []

    def warning(self, text, **kwargs):
        self.lines.append(text)

    info = warning


class Clock:
    def now(self):
        return self

    def to_msg(self):
        return Time()


class Node:
    """What the input subscription and the publishing use of a node."""

    def __init__(self):
        self.publishers, self.subscriptions, self.destroyed = {}, [], []
        self.logger = Logger()

    def create_publisher(self, msg_type, topic, qos, qos_overriding_options=None):
        self.publishers[topic] = Publisher(msg_type, topic)
        return self.publishers[topic]

    def create_subscription(self, msg_type, topic, callback, qos, qos_overriding_options=None):
        self.subscriptions.append((msg_type, topic, callback, qos, qos_overriding_options))
        return object()

    def destroy_subscription(self, subscription):
        self.destroyed.append(subscription)

    def destroy_publisher(self, publisher):
        pass

    def get_logger(self):
        return self.logger

    def get_clock(self):
        return Clock()


def _input(scene_name, extra_joints='refuse', tf_rate_hz=100.0, source=None):
    """Return (the node, an active InputSubscription on the scene or robot, its stats)."""
    scene = mk.load_scene(scene_name) if source is None else source.scene
    node, stats = Node(), TickStats(mk.NEAR_SINGULAR)
    publishing = Publishing(node, scene, frame_id='mechanism', tf_prefix='',
                            tf_rate_hz=tf_rate_hz, scene_path=scene_name, source=source)
    solver = SolverPath(1e-6)
    solver.setup(publishing.tick_scene, scene, [(f.origin, f.angle_of, f.angle)
                                                for f in publishing.frames], node.logger.info)
    subscription = InputSubscription(node, scene, solver, publishing, stats,
                                     frame_id='mechanism', extra_joints=extra_joints,
                                     jump_back_s=1.0, robot=publishing.robot_values)
    subscription.active = True
    return node, subscription, stats


def _message(nanosec, names, positions, velocities=(), sec=SEC):
    msg = JointState(name=list(names), position=list(positions), velocity=list(velocities))
    msg.header.stamp.sec, msg.header.stamp.nanosec = sec, nanosec
    return msg


def _decoded(node, topic):
    publisher = node.publishers[topic]
    return [deserialize_message(m, publisher.msg_type) if isinstance(m, bytes) else m
            for m in publisher.sent]


def test_the_subscription_is_reliable_with_a_second_of_history_at_1_khz():
    """input_joint_states: JointState, reliable, depth 1000, overrides accepted."""
    node, subscription, _ = _input('five_bar')
    [(msg_type, topic, callback, qos, options)] = node.subscriptions
    assert (msg_type, topic, qos.depth, qos.reliability) == (
        JointState, 'input_joint_states', INPUT_DEPTH, QoSReliabilityPolicy.RELIABLE)
    assert options is not None and callback == subscription.on_input
    subscription.close()
    assert len(node.destroyed) == 1 and not subscription.active


def test_a_message_publishes_the_state_with_its_stamp_and_without_accelerations():
    """The drivers' positions and velocities in: the solver's state at them, the input's stamp."""
    node, subscription, stats = _input('five_bar')
    subscription.message(_message(5, ['right_crank', 'left_crank'], [1.0, 1.5], [0.5, -0.5]))
    [state] = _decoded(node, 'joint_states')
    solved = mk.solve(mk.load_scene('five_bar'), [1.5, 1.0], [-0.5, 0.5], [0.0, 0.0])
    assert (state.header.stamp.sec, state.header.stamp.nanosec) == (SEC, 5)
    names = list(state.name)
    assert state.position[names.index('left_distal')] == solved.joints['left_distal'].position
    assert state.velocity[names.index('left_distal')] == solved.joints['left_distal'].velocity
    [trajectory] = _decoded(node, 'joint_accelerations')
    assert list(trajectory.points[0].accelerations) == []
    assert len(_decoded(node, '/tf')) == 1
    window = stats.take_window()
    assert (window.published, window.unsolved) == (1, 0)


def test_without_velocities_none_are_published():
    """A message with positions only: joint_states' velocity is empty."""
    node, subscription, _ = _input('five_bar')
    subscription.message(_message(5, ['left_crank', 'right_crank'], [1.5, 1.0]))
    [state] = _decoded(node, 'joint_states')
    assert list(state.velocity) == [] and len(state.position) == len(state.name)


def test_a_refused_message_publishes_nothing_and_is_counted_with_its_reason():
    """A driver missing: nothing published, ERROR's reason on diagnostics, one warning."""
    node, subscription, stats = _input('five_bar')
    subscription.message(_message(5, ['left_crank'], [1.5]))
    assert node.publishers['joint_states'].sent == []
    window = stats.take_window()
    assert (window.unsolved, window.last_refusal) == (1, 'refused input')
    assert 'right_crank' in window.last_error
    assert node.logger.lines[-1] == f'no state published: {window.last_error}'


def test_a_robots_refusal_names_its_urdf_joint_where_the_scenes_driver_stood():
    """URDF mode: the refusal says where the actuated joint stands, under the URDF's name.

    The FANUC's joint_3 at its upper limit, 3.3e-7 rad from its parallelogram's
    fold, moving at 1 rad/s: refused (its rates cannot be trusted) at
    ``joint_3 = 1.5708 rad``, never at the scene's crank angle the joint maps to.
    """
    source = load_source(str(URDF / 'fanuc_m900ia260l.urdf'),
                         loop_closures=str(URDF / 'fanuc_m900ia260l.loop_closures.yaml'))
    node, subscription, stats = _input('fanuc', extra_joints='pass', source=source)
    names = list(source.robot.actuated)    # joint_1 to joint_6: joint_3 drives the loop
    at = [0.0] * len(names)
    at[names.index('joint_3')] = 1.570796
    subscription.message(_message(5, names, at, [1.0] * len(names)))
    assert node.publishers['joint_states'].sent == []
    window = stats.take_window()
    assert (window.unsolved, window.last_refusal) == (1, 'not trusted')
    assert ' at joint_3 = 1.5708 rad: ' in window.last_error    # the loop's joint alone
    assert 'crank angle' not in window.last_error and '\n' not in window.last_error
    assert node.logger.lines[-1] == f'no state published: {window.last_error}'
    at[names.index('joint_3')] = -1.8    # past the fold: solved
    subscription.message(_message(6, names, at, [1.0] * len(names)))
    [state] = _decoded(node, 'joint_states')
    assert list(state.name) == list(source.robot.joint_names)


def test_tf_follows_the_inputs_time_and_starts_again_after_a_jump_back():
    """/tf at tf_rate_hz of the stamps; a stamp 2 s back is published and said, /tf again."""
    node, subscription, stats = _input('five_bar', tf_rate_hz=10.0)
    names = ['left_crank', 'right_crank']
    for k in range(4):      # 40 ms apart, /tf every 100 ms: at 0 and 120 ms
        subscription.message(_message(k * 40_000_000, names, [1.5, 1.0]))
    assert [m.transforms[0].header.stamp.nanosec for m in _decoded(node, '/tf')] == [
        0, 120_000_000]
    subscription.message(_message(0, names, [1.5, 1.0], sec=SEC - 2))
    assert len(_decoded(node, 'joint_states')) == 5 and len(_decoded(node, '/tf')) == 3
    assert node.logger.lines[-1].startswith('input_joint_states: the stamp jumped back 2.12 s')
    assert stats.take_window().stamp_jumps_back == 1


def test_other_joints_pass_through_after_the_mechanisms():
    """extra_joints: pass: an input's other joints unchanged in joint_states, after ours."""
    node, subscription, stats = _input('five_bar', extra_joints='pass')
    subscription.message(_message(5, ['left_crank', 'gripper', 'right_crank'],
                                  [1.5, 0.25, 1.0], [0.0, 0.5, 0.0]))
    [state] = _decoded(node, 'joint_states')
    assert list(state.name)[-1] == 'gripper' and state.header.frame_id == 'mechanism'
    assert (state.position[-1], state.velocity[-1]) == (0.25, 0.5)
    assert list(state.effort) == []         # the message has none
    assert stats.take_window().passed_joints == ('gripper',)


def test_passed_joints_are_rendered_from_a_template_of_their_names():
    """Issue 31: joint_states with passed joints is CDR from a template per set of names.

    Efforts: NaN for the mechanism's joints, the input's for the passed ones; a
    message naming other joints gets its own template, and both are exact.
    """
    node, subscription, _ = _input('five_bar', extra_joints='pass')
    first = _message(5, ['left_crank', 'gripper', 'right_crank'], [1.5, 0.25, 1.0],
                     [0.0, 0.5, 0.0])
    first.effort = [9.0, -2.5, 7.0]
    subscription.message(first)
    subscription.message(_message(6, ['wrist', 'right_crank', 'left_crank', 'gripper'],
                                  [-0.75, 1.0, 1.5, 0.125]))
    assert all(isinstance(m, bytes) for m in node.publishers['joint_states'].sent)
    one, two = _decoded(node, 'joint_states')
    assert list(one.name)[-1] == 'gripper' and one.header.stamp.nanosec == 5
    assert (one.position[-1], one.velocity[-1], one.effort[-1]) == (0.25, 0.5, -2.5)
    assert all(math.isnan(e) for e in one.effort[:-1])
    assert list(two.name)[-2:] == ['wrist', 'gripper'] and list(two.position)[-2:] == [-0.75,
                                                                                       0.125]
    assert list(two.velocity) == [] and list(two.effort) == []
    assert list(one.position)[:-1] == list(two.position)[:-2]     # the same drivers


def _static_input(scene_name, extra_joints):
    """Return (the node, an active subscription with effort: static, the scene)."""
    scene, node, stats = mk.load_scene(scene_name), Node(), TickStats(mk.NEAR_SINGULAR)
    publishing = Publishing(node, scene, frame_id='mechanism', tf_prefix='',
                            tf_rate_hz=100.0, scene_path=scene_name)
    frames = [(f.origin, f.angle_of, f.angle) for f in publishing.frames]
    forces = forces_tick(scene, publishing.tick_scene, frames, drive=TOPIC, effort=STATIC)
    publishing.add_forces(forces)
    solver = SolverPath(1e-6)
    solver.setup(publishing.tick_scene, scene, frames, node.logger.info, forces)
    subscription = InputSubscription(node, scene, solver, publishing, stats,
                                     frame_id='mechanism', extra_joints=extra_joints,
                                     jump_back_s=1.0, robot=publishing.robot_values)
    subscription.active = True
    return node, subscription, scene


def test_static_efforts_with_the_passed_joints():
    """effort: static: the mechanism's efforts at rest, then the passed joints' (NaN if none)."""
    node, subscription, scene = _static_input('five_bar_payload', 'pass')
    names = ['left_crank', 'gripper', 'right_crank']
    subscription.message(_message(5, names, [2.0, 0.25, 1.0], [0.3, 0.5, -0.2]))
    rest = mk.solve(scene, [2.0, 1.0], [0.0, 0.0], [0.0, 0.0])
    expected = [float(rest.forces.efforts.get(j, 0.0)) for j in scene.output_joints]
    assert any(expected)
    msg = _message(6, names, [2.0, 0.25, 1.0], [0.3, 0.5, -0.2])
    msg.effort = [1.0, 7.5, 2.0]
    subscription.message(msg)
    first, second = _decoded(node, 'joint_states')
    assert list(first.effort[:-1]) == expected and math.isnan(first.effort[-1])
    assert list(second.effort) == [*expected, 7.5]
    assert len(_decoded(node, 'shaking')) == 2
    # Without passed joints, the template's efforts: the same values.
    node, subscription, _ = _static_input('five_bar_payload', 'refuse')
    subscription.message(_message(5, ['left_crank', 'right_crank'], [2.0, 1.0]))
    [state] = _decoded(node, 'joint_states')
    assert list(state.effort) == expected and list(state.velocity) == []


def test_an_inactive_node_publishes_nothing():
    """Deactivated (lifecycle), or cleaned up while a message waited: nothing, not counted."""
    node, subscription, stats = _input('five_bar')
    subscription.active = False
    subscription.message(_message(5, ['left_crank', 'right_crank'], [1.5, 1.0]))
    assert node.publishers['joint_states'].sent == [] and stats.take_window().instants == 0


def test_a_publish_the_middleware_refuses_is_counted_and_the_next_message_published():
    """A publish refused (RCLError: a slow reliable reader): counted, said, the next one sent."""
    node, subscription, stats = _input('five_bar')
    publishing = subscription.publishing
    sent, refuse = [], [True]

    def publish(data):
        if refuse.pop() if refuse else False:
            raise RCLError('Failed to publish: cannot publish data, at rmw_publish.cpp:120')
        sent.append(data)

    publishing.publish_state = (publish, *publishing.publish_state[1:])
    names = ['left_crank', 'right_crank']
    subscription.message(_message(5, names, [1.5, 1.0]))
    subscription.message(_message(6, names, [1.5, 1.0]))
    assert len(sent) == 1
    window = stats.take_window()
    assert (window.instants, window.published, window.publish_failures) == (2, 1, 1)
    assert node.logger.lines[0].startswith(
        'a state was not delivered (Failed to publish: cannot publish data)')
