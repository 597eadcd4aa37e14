# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""What the node publishes of a scene (ros/publishing.py), on a stand-in node.

The publishers, their QoS and overrides, the latched messages, what one tick
publishes (``/tf`` by its rate), the IMUs and the markers, decoded from the
bytes published. The node's topics seen from a subscriber are the
``test_kinematics_node_*`` files'.
"""

import math

from builtin_interfaces.msg import Time
import pytest
from rclpy.qos import QoSDurabilityPolicy, QoSReliabilityPolicy
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import Imu, JointState
from std_msgs.msg import String
from trajectory_msgs.msg import JointTrajectory, MultiDOFJointTrajectory
from visualization_msgs.msg import MarkerArray

import mech_kinematics as mk
from mech_kinematics.ros.diagnostics import Status, WARN
from mech_kinematics.ros.publishing import (diagnostic_array, Markers, Publishing, TF_DEPTH,
                                            tf_period_ns)
from mech_kinematics.ros.ticker import general_tick
from mech_kinematics.ros.wrenches import ForcesTick, reaction_wrench
from mech_kinematics.units import NS_PER_S

#: The stamp of the first tick here, ns.
STAMP = 1_700_000_000 * NS_PER_S + 250_000_000


class Publisher:
    """A stand-in publisher: what was published, and how it was created."""

    def __init__(self, msg_type, topic, qos, options):
        self.msg_type, self.topic, self.qos, self.options = msg_type, topic, qos, options
        self.sent = []

    def publish(self, msg):
        self.sent.append(msg)

    def decoded(self):
        """Return what was published, bytes decoded as the publisher's type."""
        return [deserialize_message(m, self.msg_type) if isinstance(m, bytes) else m
                for m in self.sent]


class Logger:
    def __init__(self):
        self.lines = []

    def warning(self, text, **kwargs):
        self.lines.append(text)


class Clock:
    def now(self):
        return self

    def to_msg(self):
        return Time(sec=7, nanosec=8)


class Guard:
    def __init__(self, callback):
        self.callback, self.triggered = callback, 0

    def trigger(self):
        self.triggered += 1


class Node:
    """What Publishing and Markers use of a node; ``fail_at``: the publisher that is refused."""

    def __init__(self, fail_at=None):
        self.publishers, self.destroyed, self.guards = [], [], []
        self.fail_at = fail_at
        self.logger = Logger()

    def create_publisher(self, msg_type, topic, qos, qos_overriding_options=None):
        if len(self.publishers) == self.fail_at:
            msg = f'{topic}: a QoS override refused'
            raise ValueError(msg)
        publisher = Publisher(msg_type, topic, qos, qos_overriding_options)
        self.publishers.append(publisher)
        return publisher

    def destroy_publisher(self, publisher):
        self.destroyed.append(publisher)

    def create_guard_condition(self, callback):
        self.guards.append(Guard(callback))
        return self.guards[-1]

    def get_logger(self):
        return self.logger

    def get_clock(self):
        return Clock()

    def topic(self, name):
        return next(p for p in self.publishers if p.topic == name)


def _publishing(scene, node=None, tf_rate_hz=100.0):
    node = node or Node()
    return node, Publishing(node, scene, frame_id='mechanism', tf_prefix='', tf_rate_hz=tf_rate_hz,
                            scene_path=scene.name)


def _values(publishing, scene, angle):
    """Return a tick's values at ``angle`` (the drivers' starts for several drivers)."""
    tick = general_tick(publishing.tick_scene, scene.output_joints, scene.output_points,
                        [(f.origin, f.angle_of, f.angle) for f in publishing.frames])
    if len(scene.drivers) == 1:
        return tick(angle, scene.drivers[0].speed, 0.0, 1e-6)[0]
    starts = tuple(d.start for d in scene.drivers)
    return tick(starts, (0.1,) * len(starts), (0.0,) * len(starts), 1e-6, (0,) * len(starts))[0]


def test_the_publishers_of_a_scene_and_their_qos():
    """The state topics reliable, depth 1000, volatile; /tf_static and the texts latched."""
    node, publishing = _publishing(mk.load_scene('khurmi_four_bar_ad150'))
    assert [p.topic for p in node.publishers] == [
        'joint_states', 'joint_accelerations', 'point_accelerations', '/tf', '/tf_static',
        'robot_description', 'scene']
    assert [p.msg_type for p in node.publishers[:3]] == [
        JointState, JointTrajectory, MultiDOFJointTrajectory]
    for p in node.publishers[:3]:
        assert (p.qos.depth, p.qos.reliability, p.qos.durability) == (
            1000, QoSReliabilityPolicy.RELIABLE, QoSDurabilityPolicy.VOLATILE)
    assert node.topic('/tf').qos.depth == TF_DEPTH
    for topic in ('/tf_static', 'robot_description', 'scene'):
        assert (node.topic(topic).qos.depth, node.topic(topic).qos.durability) == (
            1, QoSDurabilityPolicy.TRANSIENT_LOCAL)
    # Every publisher but the two texts takes the QoS overrides.
    assert [p.options is not None for p in node.publishers] == [True] * 5 + [False] * 2
    [static] = node.topic('/tf_static').decoded()
    assert [t.child_frame_id for t in static.transforms] == ['mechanism/A', 'mechanism/D']
    [text] = node.topic('scene').sent
    assert isinstance(text, String) and text.data.startswith('name: khurmi_four_bar_ad150\n')
    assert node.topic('robot_description').sent[0].data.startswith('<?xml')
    assert publishing.publishers == node.publishers


def test_a_tick_publishes_every_state_topic_and_tf_by_its_rate():
    """Three messages a tick stamped with it; /tf at tf_rate_hz by stamp, from the same values."""
    scene = mk.load_scene('khurmi_four_bar_ad150')
    node, publishing = _publishing(scene, tf_rate_hz=50.0)
    period = NS_PER_S // 100
    for k in range(5):
        stamp = STAMP + k * period
        publishing.tick(_values(publishing, scene, 0.1 * k), stamp, *divmod(stamp, NS_PER_S))
    states = node.topic('joint_states').decoded()
    assert [(m.header.stamp.sec, m.header.stamp.nanosec) for m in states] == [
        divmod(STAMP + k * period, NS_PER_S) for k in range(5)]
    state = mk.solve(scene, 0.4)
    assert list(states[-1].name) == list(scene.output_joints)
    assert states[-1].position[0] == state.joints['crank'].position
    assert len(node.topic('joint_accelerations').sent) == 5
    assert len(node.topic('point_accelerations').sent) == 5
    tf = node.topic('/tf').decoded()        # 50 Hz of a 100 Hz stream: ticks 0, 2 and 4
    assert node.topic('/tf').msg_type.__name__ == 'TFMessage'
    assert [m.transforms[0].header.stamp.nanosec for m in tf] == [
        (STAMP + k * period) % NS_PER_S for k in (0, 2, 4)]
    assert tf[-1].transforms[0].child_frame_id == 'mechanism/crank'


def test_tf_off_publishes_no_frame_and_looks_again_in_a_second():
    """tf_rate_hz 0: nothing on /tf; an input's /tf is never due."""
    scene = mk.load_scene('khurmi_four_bar_ad150')
    node, publishing = _publishing(scene, tf_rate_hz=0.0)
    assert tf_period_ns(0.0) is None and tf_period_ns(250.0) == 4_000_000
    publishing.tick(_values(publishing, scene, 0.0), STAMP, *divmod(STAMP, NS_PER_S))
    assert node.topic('/tf').sent == [] and publishing.next_tf == STAMP + NS_PER_S
    assert not publishing.tf_due(STAMP + 2 * NS_PER_S)
    publishing.tf_period_ns = tf_period_ns(10.0)
    assert publishing.tf_due(STAMP + 2 * NS_PER_S)
    assert not publishing.tf_due(STAMP + 2 * NS_PER_S + 99_999_999)
    assert publishing.tf_due(STAMP + 2 * NS_PER_S + 100_000_000)


def test_the_imus_publish_every_tick_and_their_frames_are_known():
    """A scene's sensors: imu/NAME each tick, from the tick's values."""
    scene = mk.load_scene('boom')
    node, publishing = _publishing(scene)
    assert node.topic('imu/boom_head').msg_type is Imu
    publishing.tick(_values(publishing, scene, scene.drivers[0].start), STAMP,
                    *divmod(STAMP, NS_PER_S))
    [imu] = node.topic('imu/boom_head').decoded()
    assert imu.header.frame_id == 'mechanism/boom'
    assert (imu.header.stamp.sec, imu.header.stamp.nanosec) == divmod(STAMP, NS_PER_S)


def test_a_publisher_refused_at_set_up_leaves_none_behind():
    """A QoS override refused on the fourth publisher: the three made are destroyed."""
    node = Node(fail_at=3)
    with pytest.raises(ValueError, match='^/tf: a QoS override refused$'):
        _publishing(mk.load_scene('khurmi_four_bar_ad150'), node)
    assert node.destroyed == node.publishers and len(node.destroyed) == 3
    node, publishing = _publishing(mk.load_scene('khurmi_four_bar_ad150'))
    publishing.close()
    assert node.destroyed == node.publishers and publishing.publishers == []


def test_markers_are_built_from_the_samples_handed_over_at_most_30_a_second():
    """The tick hands a sample over (the guard fires); the executor's call publishes it."""
    scene = mk.load_scene('khurmi_four_bar_ad150')
    node = Node()
    markers = Markers(node, scene, 'mechanism', lambda: (0.1, 0.01, 0.0))
    period = NS_PER_S // 1000
    for _ in range(10):     # 10 ticks at 1 kHz: the first is due, the next 9 are not
        markers.request(period, 7, 8, 0.5, -4.0, 0.0)
    assert node.guards[0].triggered == 1
    markers.publish()
    [array] = node.topic('markers').sent
    assert isinstance(array, MarkerArray) and array.markers
    assert {(m.header.stamp.sec, m.header.stamp.nanosec) for m in array.markers} == {(7, 8)}
    markers.publish()       # nothing handed over since
    assert len(node.topic('markers').sent) == 1
    markers.close()
    assert node.destroyed == [node.topic('markers')]
    markers.request(period, 9, 0, 0.5, -4.0, 0.0)
    markers.publish()       # cleaned up while the sample waited: nothing
    assert len(node.topic('markers').sent) == 1


def test_the_diagnostics_message_holds_every_status():
    """Each status as a DiagnosticStatus, the header stamped and framed."""
    msg = diagnostic_array([Status(WARN, 'n: solver', 'near-singular', 'scene',
                                   (('solver_path', 'compiled'),))], Time(sec=3), 'mechanism')
    [status] = msg.status
    assert (status.level, status.name, status.message, status.hardware_id) == (
        b'\x01', 'n: solver', 'near-singular', 'scene')
    assert [(kv.key, kv.value) for kv in status.values] == [('solver_path', 'compiled')]
    assert (msg.header.stamp.sec, msg.header.frame_id) == (3, 'mechanism')


def _forces_publishing(name):
    scene = mk.load_scene(name)
    node, publishing = _publishing(scene)
    frames = [(f.origin, f.angle_of, f.angle) for f in publishing.frames]
    forces = ForcesTick(publishing.tick_scene, scene.output_joints, scene.output_points, frames,
                        static=False)
    publishing.add_forces(forces)
    return scene, node, publishing, forces


def test_a_tick_publishes_efforts_reactions_and_shaking():
    """A forces tick's values: effort in joint_states, a WrenchStamped per joint and shaking."""
    scene, node, publishing, forces = _forces_publishing('engine')
    crank = scene.drivers[0]
    values, _ = forces(0.7, crank.speed, 0.0, 1e-6)
    publishing.tick(values, STAMP, *divmod(STAMP, NS_PER_S))
    state = mk.solve(scene, 0.7, crank.speed, 0.0)
    [js] = node.topic('joint_states').decoded()
    assert list(js.effort) == [state.forces.efforts['crank'], 0.0, 0.0]
    for joint in forces.reactions:
        [wrench] = node.topic(f'reactions/{joint.name}').decoded()
        assert (wrench.wrench.force.x, wrench.wrench.force.y, wrench.wrench.torque.z) == \
            reaction_wrench(joint, state.forces, state)
        assert (wrench.header.stamp.sec, wrench.header.frame_id) == (STAMP // NS_PER_S,
                                                                     'mechanism')
    [shaking] = node.topic('shaking').decoded()
    assert (shaking.wrench.force.x, shaking.wrench.force.y, shaking.wrench.torque.z) == (
        state.forces.shaking_force.real, state.forces.shaking_force.imag,
        state.forces.shaking_moment)
    # Forces left out: the motion is published with an empty effort, no wrench, a warning.
    forces.refusal = 'the forces cannot be bounded here (rod (statics singular))'
    publishing.tick(values[:forces.forces_first], STAMP + 1, *divmod(STAMP + 1, NS_PER_S))
    assert list(node.topic('joint_states').decoded()[-1].effort) == []
    assert len(node.topic('shaking').sent) == 1
    assert node.logger.lines[-1] == f'forces not published: {forces.refusal}'


def test_reaction_arrows_start_at_the_joints_along_the_forces():
    """Markers draw each joint's reaction from its point, the largest 0.3 of the size long."""
    scene, node, publishing, forces = _forces_publishing('shaper')
    markers = Markers(node, scene, 'mechanism', lambda: (0.1, 0.01, 0.0), forces)
    markers.request(NS_PER_S // 100, 7, 8, 0.5, scene.drivers[0].speed, 0.0)
    markers.publish()
    [array] = node.topic('markers').sent
    arrows = [m for m in array.markers if m.ns == 'reactions']
    assert [m.id for m in arrows] == list(range(len(forces.reactions)))
    state = mk.solve(scene, 0.5, scene.drivers[0].speed, 0.0)
    lengths = []
    for joint, arrow in zip(forces.reactions, arrows, strict=True):
        start, end = arrow.points
        at = state.complex_points[joint.at][0]
        assert (start.x, start.y) == (at.real, at.imag)
        fx, fy, _ = reaction_wrench(joint, state.forces, state)
        length = math.hypot(end.x - start.x, end.y - start.y)
        lengths.append(length)
        assert (end.x - start.x) * fy == pytest.approx((end.y - start.y) * fx, abs=1e-9 * length)
    assert max(lengths) == pytest.approx(0.3 * markers.size, rel=1e-12)
