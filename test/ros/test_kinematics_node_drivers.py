# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Each driver's parameters on the running node, ``inputs.NAME.*`` (issue 18).

For every driver NAME the node has ``inputs.NAME.speed_rpm`` and
``inputs.NAME.accel`` (a crank) or ``inputs.NAME.speed`` and
``inputs.NAME.accel`` (an actuator); ``crank_speed_rpm`` and ``crank_accel``
stay the first crank's names: setting either name sets both.
"""

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
import numpy as np
import pytest
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from ros_helpers import (cannot_start, exited, NodeProcess, NS, SESSION, stamp_ns, STARTUP_S,
                         wait_for, wait_for_parameters, wrap)
from sensor_msgs.msg import JointState
from visualization_msgs.msg import MarkerArray

import mech_kinematics as mk
from mech_kinematics.scene import scene_text
from mech_kinematics.units import rad_per_s_from_rpm

#: The default scene's crank (khurmi_four_bar_ad150).
CRANK = 'crank'
#: A crank angle that the time base fixes exactly, rad.
ATOL_TIMEBASE = 1e-9
#: The published state against the general solver at the published drivers (rad, rad/s).
ATOL_STATE = 1e-9


class Node:
    """A node of its own, its parameter client and its joint_states."""

    def __init__(self, ros, tmp_path, name, *args):
        self.ros = ros
        self.ns = f'{SESSION}/{name}'
        self.js = ros.collect(JointState, f'{self.ns}/joint_states')
        self.proc = NodeProcess(tmp_path, '-r', f'__ns:={self.ns}', *args)
        self.params = AsyncParameterClient(ros.node, f'{self.ns}/mech_kinematics')
        wait_for_parameters(self.params)

    def get(self, *names):
        return [v.double_value for v in
                self.ros.call(self.params.get_parameters(list(names))).values]

    def set(self, name, value):
        [result] = self.ros.call(self.params.set_parameters(
            [Parameter(name, value=value)])).results
        return result

    def stop(self):
        status, _ = self.proc.stop()
        assert status == 0, self.proc.output()


def test_the_first_cranks_two_names_are_one_value(ros, tmp_path):
    """inputs.crank.speed_rpm given at start is crank_speed_rpm; setting either sets both."""
    node = Node(ros, tmp_path, 'drivers_alias', '-p', f'inputs.{CRANK}.speed_rpm:=30',
                '-p', 'rate_hz:=200.0')
    try:
        assert node.get('crank_speed_rpm', f'inputs.{CRANK}.speed_rpm') == [30.0, 30.0]
        assert node.get('crank_accel', f'inputs.{CRANK}.accel') == [0.0, 0.0]
        wait_for(lambda: node.js, STARTUP_S, 'joint_states')
        assert node.js[0].velocity[0] == rad_per_s_from_rpm(30.0)
        assert node.set('crank_speed_rpm', 45.0).successful
        assert node.get('crank_speed_rpm', f'inputs.{CRANK}.speed_rpm') == [45.0, 45.0]
        result = node.set(f'inputs.{CRANK}.speed_rpm', -60)     # an integer for a double
        assert result.successful, result.reason
        assert node.get('crank_speed_rpm', f'inputs.{CRANK}.speed_rpm') == [-60.0, -60.0]
        count = len(node.js)
        wait_for(lambda: len(node.js) > count + 20, STARTUP_S, 'joint_states after the change')
        assert node.js[-1].velocity[0] == rad_per_s_from_rpm(-60.0)
        assert node.set(f'inputs.{CRANK}.accel', 2.5).successful
        assert node.get('crank_accel') == [2.5]
        refused = node.set(f'inputs.{CRANK}.speed_rpm', 2e4)
        assert not refused.successful
        assert refused.reason.startswith(f'inputs.{CRANK}.speed_rpm: expected '
                                         f'|inputs.{CRANK}.speed_rpm| <= max_crank_speed_rpm')
        assert node.get('crank_speed_rpm', f'inputs.{CRANK}.speed_rpm') == [-60.0, -60.0]
        refused = node.set('inputs.wrist.speed', 1.0)
        assert not refused.successful
    finally:
        node.stop()


def test_both_names_given_different_values_is_one_line_and_exit_1(tmp_path):
    """-p crank_speed_rpm:=30 -p inputs.crank.speed_rpm:=40: refused at start, naming both."""
    proc = NodeProcess(tmp_path, '-r', f'__ns:={SESSION}/drivers_both', '-p',
                       'crank_speed_rpm:=30.0', '-p', f'inputs.{CRANK}.speed_rpm:=40.0')
    status, output = exited(proc)
    fatal = cannot_start(output)
    assert status == 1 and len(fatal) == 1, output
    assert (f'crank_speed_rpm and inputs.{CRANK}.speed_rpm are the same value: expected one of '
            'them or equal values, got 30.0 and 40.0') in fatal[0]


def _index(msg, name):
    return list(msg.name).index(name)


def test_five_bar_drives_each_crank_as_an_exact_function_of_time(ros, tmp_path):
    """Two cranks at their own speeds; a change of one applies to it alone, continuously."""
    scene = mk.load_scene('five_bar')
    node = Node(ros, tmp_path, 'drivers_five_bar', '-p', 'scene:=five_bar',
                '-p', 'rate_hz:=200.0', '-p', 'inputs.right_crank.speed_rpm:=-15')
    try:
        assert node.get('crank_speed_rpm', 'inputs.left_crank.speed_rpm',
                        'inputs.right_crank.speed_rpm') == [30.0, 30.0, -15.0]
        wait_for(lambda: len(node.js) > 40, STARTUP_S, 'joint_states of the five-bar')
        before = len(node.js)
        assert node.set('inputs.right_crank.speed_rpm', 10.0).successful
        wait_for(lambda: len(node.js) > before + 60, STARTUP_S, 'joint_states after the change')
    finally:
        node.stop()
    left, right = _index(node.js[0], 'left_crank'), _index(node.js[0], 'right_crank')
    omega_left = rad_per_s_from_rpm(30.0)
    first, t0 = node.js[0], stamp_ns(node.js[0])
    for msg in node.js:
        t = (stamp_ns(msg) - t0) / NS
        expected = first.position[left] + omega_left * t
        assert abs(wrap(msg.position[left] - expected)) < ATOL_TIMEBASE
        assert msg.velocity[left] == omega_left
        assert msg.velocity[right] in (rad_per_s_from_rpm(-15.0), rad_per_s_from_rpm(10.0))
        # Every joint as the solver gives it at the published drivers.
        state = mk.solve(scene, [msg.position[left], msg.position[right]],
                         [msg.velocity[left], msg.velocity[right]], [0.0, 0.0])
        np.testing.assert_allclose(msg.position, [state.joints[n].position for n in msg.name],
                                   rtol=0, atol=ATOL_STATE)
        np.testing.assert_allclose(msg.velocity, [state.joints[n].velocity for n in msg.name],
                                   rtol=0, atol=ATOL_STATE)
    assert node.js[-1].velocity[right] == rad_per_s_from_rpm(10.0)
    # The right crank's angle stays continuous through the change.
    for a, b in zip(node.js, node.js[1:], strict=False):
        dt = (stamp_ns(b) - stamp_ns(a)) / NS
        step = wrap(b.position[right] - a.position[right])
        assert abs(step) <= rad_per_s_from_rpm(15.0) * dt + ATOL_TIMEBASE


def test_excavator_cylinder_runs_to_its_stroke_end_and_is_refused_there(ros, tmp_path):
    """A boom cylinder at 0.2 m/s: exact lengths up to 3.3 m, then refusals on diagnostics.

    A speed that takes it further out is refused at the parameter with its
    reason; one that brings it back is taken, and states are published again.
    (0.2 m/s: 3.5 s from 2.6 to 3.3 m, so that the subscriber, matched while the
    node starts, sees the cylinder moving out even on a loaded machine.)
    """
    node = Node(ros, tmp_path, 'drivers_excavator', '-p', 'scene:=excavator',
                '-p', 'inputs.boom_cyl.speed:=0.2')
    diag = ros.collect(DiagnosticArray, f'{node.ns}/diagnostics')
    try:
        assert node.get('inputs.boom_cyl.speed', 'inputs.stick_cyl.speed',
                        'inputs.boom_cyl.accel') == [0.2, 0.0, 0.0]
        wait_for(lambda: any('boom_cyl' in s.message and s.level == DiagnosticStatus.ERROR
                             for m in diag for s in m.status), 15.0,
                 'diagnostics saying the boom cylinder left its stroke')
        refused = node.set('inputs.boom_cyl.speed', 0.3)
        assert not refused.successful
        assert refused.reason.startswith('inputs.boom_cyl.speed = 0.3: expected a drive that '
                                         'keeps actuator boom_cyl within its stroke [2, 3.3] m, '
                                         'got one that leaves it at once'), refused.reason
        assert node.get('inputs.boom_cyl.speed') == [0.2]
        count = len(node.js)
        result = node.set('inputs.boom_cyl.speed', -2.0)
        assert result.successful, result.reason
        wait_for(lambda: len(node.js) > count + 10, 10.0, 'states once back within the stroke')
    finally:
        node.stop()
    boom, stick = _index(node.js[0], 'boom_cyl'), _index(node.js[0], 'stick_cyl')
    assert all(2.0 <= m.position[boom] <= 3.3 for m in node.js)
    assert all(m.position[stick] == 3.0 and m.velocity[stick] == 0.0 for m in node.js)
    out = [m for m in node.js if m.velocity[boom] == 0.2]
    assert out, 'no state of the cylinder moving out'
    first, t0 = out[0], stamp_ns(out[0])
    for msg in out:
        expected = first.position[boom] + 0.2 * (stamp_ns(msg) - t0) / NS
        assert msg.position[boom] == pytest.approx(expected, abs=1e-12)
    assert node.js[-1].velocity[boom] == -2.0


def test_excavator_at_a_stroke_end_refuses_to_start_moving_out(tmp_path):
    """A cylinder at its stroke's end given a speed out of it: one line, exit 1."""
    text = scene_text('excavator').replace('length: 2.6\n', 'length: 3.3\n', 1)
    assert 'length: 3.3\n' in text
    path = tmp_path / 'excavator_out.yaml'
    path.write_text(text)
    proc = NodeProcess(tmp_path, '-r', f'__ns:={SESSION}/drivers_out', '-p', f'scene:={path}',
                       '-p', 'inputs.boom_cyl.speed:=0.1')
    status, output = exited(proc)
    fatal = cannot_start(output)
    assert status == 1 and len(fatal) == 1, output
    assert 'keeps actuator boom_cyl within its stroke [2, 3.3] m' in fatal[0]


@pytest.mark.parametrize('scene', ['five_bar', 'excavator'])
def test_markers_of_a_scene_of_several_drivers(ros, tmp_path, scene):
    """markers:=true on a scene of several drivers: it starts, ticks and draws."""
    node = Node(ros, tmp_path, f'drivers_markers_{scene}', '-p', f'scene:={scene}',
                '-p', 'markers:=true')
    markers = ros.collect(MarkerArray, f'{node.ns}/markers')
    try:
        wait_for(lambda: len(markers) >= 3 and len(node.js) >= 3, STARTUP_S,
                 'markers and joint_states')
    finally:
        node.stop()
    assert all(m.markers for m in markers)
    assert 'Traceback' not in node.proc.output()


@pytest.mark.parametrize(('scene', 'driver', 'key', 'rate', 'si'), [
    ('five_bar_elbow', 'elbow', 'speed_rpm', 2.0, rad_per_s_from_rpm(2.0)),
    # 0.02 m/s: block A runs 0.34 m to the end of its stroke in 17 s (at 0.5 m/s, 0.68 s: beside
    # two CPU hogs the subscription matched after it, and fewer than 40 states came).
    ('double_slider', 'block_a', 'speed', -0.02, -0.02)])
def test_a_motor_and_a_slider_are_driven_in_time_by_their_parameters(ros, tmp_path, scene, driver,
                                                                     key, rate, si):
    """A motor's relative angle (rpm, as a crank's) and a slider's position move in time.

    Each published state is the solver's at the published drivers, and the driver moves at
    the rate its parameter sets (issue 41's drivers on the node).
    """
    loaded = mk.load_scene(scene)
    node = Node(ros, tmp_path, f'drivers_{scene}', '-p', f'scene:={scene}', '-p',
                'rate_hz:=200.0', '-p', f'inputs.{driver}.{key}:={rate}')
    try:
        assert node.get(f'inputs.{driver}.{key}') == [rate]
        wait_for(lambda: len(node.js) > 40, STARTUP_S, f'joint_states of {scene}')
    finally:
        node.stop()
    names = [d.name for d in loaded.drivers]
    for msg in node.js:
        at = [_index(msg, n) for n in names]
        assert msg.velocity[at[names.index(driver)]] == si
        positions = [msg.position[i] for i in at]
        speeds = [msg.velocity[i] for i in at]
        state = mk.solve(loaded, positions[0] if len(at) == 1 else positions,
                         speeds[0] if len(at) == 1 else speeds,
                         0.0 if len(at) == 1 else [0.0] * len(at))
        np.testing.assert_allclose(msg.position, [state.joints[n].position for n in msg.name],
                                   rtol=0, atol=ATOL_STATE)
    first, last = node.js[0], node.js[-1]
    moved = last.position[_index(last, driver)] - first.position[_index(first, driver)]
    assert moved == pytest.approx(si * (stamp_ns(last) - stamp_ns(first)) / NS, abs=1e-9)
