# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's forces over real DDS, from another process (issue 32).

``joint_states.effort``, ``reactions/JOINT`` and ``shaking`` against
``mk.solve`` at the same instant (the drivers read from ``joint_states``);
``gravity`` and ``loads.NAME.force`` set while running (bad values refused
with their reason, good ones in effect from an instant on); with ``drive:
topic`` no effort unless ``effort: static``, which diagnostics say.
"""

from dataclasses import replace
import math

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import WrenchStamped
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from ros_helpers import (cannot_start, exited, NodeProcess, NS, RELIABLE, send_until, SESSION,
                         stamp_ns, STARTUP_S, wait_for, wait_for_parameters)
from sensor_msgs.msg import JointState

import mech_kinematics as mk
from mech_kinematics.ros import topics
from mech_kinematics.ros.wrenches import forces_values, reaction_joints

SCENE = 'engine'
#: The node's forces against mk.solve's at the position it published: the same doubles in,
#: the same operations (a forces tick is mk.solve's general path): equal but for the turns.
RTOL_FORCES = 1e-12
#: Stamps of the input messages sent to a topic-driven node, ns.
T0 = 1_700_000_000 * NS


def _forces(scene, msg):
    """Return the forces' values mk.solve gives at a joint_states message's crank state."""
    crank = msg.name.index('crank')
    state = mk.solve(scene, msg.position[crank], msg.velocity[crank], 0.0)
    return forces_values(state.forces, state, scene.output_joints,
                         reaction_joints(scene.dynamics))


def _close(a, b):
    if a is None:
        return False
    scale = max(1.0, *(abs(x) for x in b))
    return len(a) == len(b) and all(abs(x - y) <= RTOL_FORCES * scale
                                    for x, y in zip(a, b, strict=True))


class ForcesNode:
    """A node on the engine scene in a namespace of its own, and what it publishes."""

    def __init__(self, ros, tmp_path, name, *args):
        self.ros = ros
        self.ns = f'{SESSION}/{name}'
        self.js = ros.collect(JointState, f'{self.ns}/joint_states')
        self.reactions = {j.name: ros.collect(WrenchStamped,
                                              f'{self.ns}/{topics.reaction_topic(j.name)}')
                          for j in reaction_joints(mk.load_scene(SCENE).dynamics)}
        self.shaking = ros.collect(WrenchStamped, f'{self.ns}/{topics.SHAKING}')
        self.diag = ros.collect(DiagnosticArray, f'{self.ns}/diagnostics')
        self.proc = NodeProcess(tmp_path, '-r', f'__ns:={self.ns}', '-p', f'scene:={SCENE}',
                                *args)
        self.params = AsyncParameterClient(ros.node, f'{self.ns}/mech_kinematics')
        wait_for_parameters(self.params)

    def set(self, name, value):
        [result] = self.ros.call(self.params.set_parameters(
            [Parameter(name, value=value)])).results
        return result

    def get(self, name):
        [value] = self.ros.call(self.params.get_parameters([name])).values
        return list(value.double_array_value)

    def complete(self):
        """Return the states received whose wrenches all arrived, in order."""
        return [m for m in list(self.js) if self.published(m) is not None]

    def published(self, msg):
        """Return the forces the node published at ``msg``'s stamp, in forces_values' order.

        None while a wrench of that stamp has not arrived (or its effort is empty).
        """
        stamp = stamp_ns(msg)
        values = list(msg.effort)
        for received in (*self.reactions.values(), self.shaking):
            found = [w for w in list(received) if stamp_ns(w) == stamp]
            if len(found) != 1 or not values:
                return None
            wrench = found[0].wrench
            values += (wrench.force.x, wrench.force.y, wrench.torque.z)
        return values

    def effort_status(self, key='effort'):
        return [v.value for m in self.diag for s in m.status for v in s.values
                if v.key == key]

    def stop(self):
        status, _ = self.proc.stop()
        assert status == 0, self.proc.output()


def test_efforts_reactions_and_shaking_are_solves_at_the_same_instant(ros, tmp_path):
    """Every forces message equals mk.solve's at the crank state of its stamp; 0 for passives."""
    node = ForcesNode(ros, tmp_path, 'forces_time', '-p', 'rate_hz:=100')
    scene = mk.load_scene(SCENE)
    try:
        # Each reader matches the node in its own time: the states judged are the first 20
        # whose wrenches all arrived (those of the very first may never reach this process).
        wait_for(lambda: len(node.complete()) >= 20, STARTUP_S, '20 states with their forces')
        wait_for(node.effort_status, STARTUP_S, 'diagnostics')
    finally:
        node.stop()
    assert node.effort_status()[-1] == 'dynamic: inertia, gravity and loads'
    # The node wrote the statics out before its first tick, and says so (mk.paths' record).
    assert node.effort_status('forces_path')[-1] == 'written out (1 pivot sequence)'
    checked = 0
    for msg in node.complete()[:20]:
        expected = _forces(scene, msg)
        assert list(msg.effort[1:]) == [0.0, 0.0]     # the rod's and the piston's: passive
        assert msg.effort[0] != 0.0
        got = node.published(msg)
        assert _close(got, expected), (got, expected)
        checked += 1
    assert checked == 20


def test_gravity_and_loads_change_while_running(ros, tmp_path):
    """Bad values are refused with their reason; a good one is in effect from an instant on."""
    node = ForcesNode(ros, tmp_path, 'forces_params', '-p', 'rate_hz:=100')
    scene = mk.load_scene(SCENE)
    try:
        wait_for(lambda: len(node.shaking) >= 5, STARTUP_S, 'the first forces')
        for value, reason in (([0.0, 1.0, 2.0], 'gravity: expected [x, y], two numbers'),
                              ([math.nan, 0.0], 'gravity: expected two finite numbers'),
                              ('down', "gravity: expected [x, y] (m/s^2), got string 'down'")):
            result = node.set('gravity', value)
            assert not result.successful
            assert result.reason.startswith(reason), result.reason
        assert node.get('gravity') == [0.0, -9.81]
        assert node.set('gravity', [0, 0]).successful      # integers, as -p gives them
        assert node.set('loads.gas.force', [0.0, -1000.0]).successful
        assert node.get('gravity') == [0.0, 0.0]
        [gas] = scene.loads
        changed = replace(scene, gravity=(0.0, 0.0), loads=(replace(gas, force=(0.0, -1000.0)),))
        count = len(node.js)

        def new_forces():
            return [m for m in node.js[count:]
                    if _close(node.published(m), _forces(changed, m))]
        wait_for(lambda: len(node.js) > count + 10 and new_forces(), STARTUP_S,
                 'a state with the new gravity and load')
    finally:
        node.stop()
    first = stamp_ns(new_forces()[0])
    # From the first instant with the new values on, every one has them (one whose wrenches
    # were still on the way when the node stopped is not judged).
    later = [m for m in node.js if stamp_ns(m) > first and node.published(m) is not None]
    assert len(later) >= 10
    for m in later:
        assert _close(node.published(m), _forces(changed, m))
    # The first states whose wrenches arrived (each reader matches the node in its own time:
    # the wrenches of the very first states may never reach this process), before the change.
    before = node.complete()[:5]
    assert len(before) == 5 and stamp_ns(before[-1]) < first
    for m in before:
        assert _close(node.published(m), _forces(scene, m))


def _topic_node(ros, tmp_path, name, *args):
    node = ForcesNode(ros, tmp_path, name, '-p', 'drive:=topic', *args)
    node.input = ros.node.create_publisher(JointState, f'{node.ns}/input_joint_states',
                                           RELIABLE)
    node.stamp = T0

    def send():
        msg = JointState(name=['crank'], position=[0.3 + 1e-3 * (node.stamp - T0) / NS],
                         velocity=[50.0])
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(node.stamp, NS)
        node.input.publish(msg)
        node.stamp += NS // 100
    node.send = send
    return node


def test_topic_drive_leaves_the_efforts_out(ros, tmp_path):
    """drive: topic: the input gives no accelerations, so no effort, reactions or shaking."""
    node = _topic_node(ros, tmp_path, 'forces_topic')
    try:
        send_until(node.send, lambda: len(node.js) >= 3, STARTUP_S, 'states for the input')
        wait_for(node.effort_status, STARTUP_S, 'diagnostics')
    finally:
        node.stop()
    assert all(list(m.effort) == [] for m in node.js)
    assert list(m.velocity for m in node.js)[0]
    assert not node.shaking and not any(node.reactions.values())
    assert node.effort_status()[-1].startswith('left out: the input gives no accelerations')


def test_topic_drive_with_static_effort_publishes_the_statics(ros, tmp_path):
    """effort: static: the forces of gravity and the gas load at rest, said on diagnostics."""
    node = _topic_node(ros, tmp_path, 'forces_static', '-p', 'effort:=static')
    scene = mk.load_scene(SCENE)
    try:
        send_until(node.send, lambda: len(node.js) >= 3 and len(node.shaking) >= 3, STARTUP_S,
                   'states with forces for the input')
        wait_for(node.effort_status, STARTUP_S, 'diagnostics')
    finally:
        node.stop()
    reactions = reaction_joints(scene.dynamics)
    for msg in node.js[:3]:
        moving = mk.solve(scene, msg.position[0], 50.0, 0.0)
        rest = mk.solve(scene, msg.position[0], 0.0, 0.0)
        assert list(msg.velocity) == [float(moving.joints[j].velocity)
                                      for j in scene.output_joints]
        assert node.published(msg) == forces_values(rest.forces, rest, scene.output_joints,
                                                    reactions)
        inertia = forces_values(moving.forces, moving, scene.output_joints, reactions)
        assert node.published(msg) != inertia
    assert node.effort_status()[-1] == 'static: gravity and loads only, inertia neglected'


#: Finite values whose forces overflow a double (issue 42, item 1): the engine's moving
#: bodies weigh 24 kg, so |g| x 24 kg overflows; a load whose |F| does (abs() of the complex
#: 1.5e308 + 1.5e308j raised OverflowError, which killed the node: status 1, no answer).
OVERFLOWING = (('loads.gas.force', [1.5e308, 1.5e308], "loads.gas.force: expected the loads' "
                'forces and the weights (235.4 N) to add up to a finite force'),
               ('gravity', [1.5e308, 1.5e308], 'gravity: expected [gx, gy] whose weight on the '
                'moving bodies (24 kg) is a finite force'),
               ('gravity', [1.7e308, -1.7e308], 'gravity: expected [gx, gy] whose weight'),
               ('gravity', [1e308, 1e308], 'gravity: expected [gx, gy] whose weight'))


def test_values_whose_forces_overflow_are_refused_and_the_node_goes_on(ros, tmp_path):
    """Each is refused with its reason through the service; the node keeps publishing forces."""
    node = ForcesNode(ros, tmp_path, 'forces_overflow', '-p', 'rate_hz:=100')
    try:
        wait_for(lambda: len(node.shaking) >= 5, STARTUP_S, 'the first forces')
        for name, value, reason in OVERFLOWING:
            result = node.set(name, value)
            assert not result.successful, (name, value, node.proc.output())
            assert result.reason.startswith(reason), result.reason
        assert node.get('gravity') == [0.0, -9.81]
        assert node.get('loads.gas.force') == [0.0, -17892.35190989812]
        count = len(node.shaking)
        wait_for(lambda: len(node.shaking) >= count + 5, STARTUP_S,
                 'forces published after the refusals')
        assert node.proc.proc.poll() is None, node.proc.output()
    finally:
        node.stop()


def test_a_value_whose_forces_overflow_given_at_start_is_one_line(tmp_path):
    """-p gravity:=[1.5e308, 1.5e308]: exit 1 with one line naming the parameter."""
    for name, value, reason in OVERFLOWING[:2]:
        proc = NodeProcess(tmp_path / name, '-r', f'__ns:={SESSION}/forces_overflow_start',
                           '-p', f'scene:={SCENE}', '-p', f'{name}:={value}')
        status, output = exited(proc)
        assert status == 1, output
        [line] = cannot_start(output)
        assert output.count('\n') == 1, output
        assert f'cannot start: {reason}' in line, line
