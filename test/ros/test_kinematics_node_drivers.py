# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Each driver's parameters on the running node, ``inputs.NAME.*`` (issue 18).

For every driver NAME the node has ``inputs.NAME.speed_rpm`` and
``inputs.NAME.accel`` (a crank) or ``inputs.NAME.speed`` and
``inputs.NAME.accel`` (an actuator); ``crank_speed_rpm`` and ``crank_accel``
stay the first crank's names: setting either name sets both.
"""

import pytest
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from ros_helpers import NodeProcess, Ros, SESSION, STARTUP_S, wait_for, wait_for_parameters
from sensor_msgs.msg import JointState

from mech_kinematics.units import rad_per_s_from_rpm

#: The default scene's crank (khurmi_four_bar_ad150).
CRANK = 'crank'


@pytest.fixture(scope='module')
def ros():
    ros = Ros()
    yield ros
    ros.close()


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
        assert node.set('crank_speed_rpm', 45.0).successful
        assert node.get('crank_speed_rpm', f'inputs.{CRANK}.speed_rpm') == [45.0, 45.0]
        result = node.set(f'inputs.{CRANK}.speed_rpm', -60)     # an integer for a double
        assert result.successful, result.reason
        assert node.get('crank_speed_rpm', f'inputs.{CRANK}.speed_rpm') == [-60.0, -60.0]
        count = len(node.js)
        wait_for(lambda: len(node.js) > count + 20, 5.0, 'joint_states after the change')
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
    try:
        status = proc.proc.wait(timeout=STARTUP_S)
    finally:
        if proc.proc.poll() is None:
            proc.proc.kill()
    output = proc.output()
    fatal = [line for line in output.splitlines() if 'cannot start' in line]
    assert status == 1 and len(fatal) == 1, output
    assert (f'crank_speed_rpm and inputs.{CRANK}.speed_rpm are the same value: expected one of '
            'them or equal values, got 30.0 and 40.0') in fatal[0]
