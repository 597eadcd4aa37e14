# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's side of its parameters (ros/node_parameters.py), on a node that does not spin.

The rules are parameters.py's (``test_ros_parameters.py``); here, what a
scene's drivers add and what a set does: the first crank's two names, the
drive changes asked of the clock's driver, refusals with their reason (logged
once), and a drive that leaves an actuator's stroke at once. rclpy calls the
three callbacks from ``set_parameters`` itself, so no executor is needed.
"""

import math

import pytest
import rclpy
from rclpy.parameter import Parameter

import mech_kinematics as mk
from mech_kinematics.ros.driver import TickDriver
from mech_kinematics.ros.node_parameters import (description, DriverParameters,
                                                 NodeParameters, spec_default_is_none)
from mech_kinematics.ros.parameters import spec
from mech_kinematics.units import NS_PER_S


def test_a_description_says_the_unit_and_range_or_the_choices():
    """ros2 param describe shows a double's unit and range, a string's choices."""
    assert description(spec('rate_hz')) == (
        'Publish rate: tick k is stamped t0 + k / rate_hz exactly [Hz, 1 to 10000]')
    assert description(spec('late_ticks')).endswith('[catch_up | skip]')
    assert description(spec('frame_id')) == spec('frame_id').description
    assert spec_default_is_none('crank_speed_rpm') and not spec_default_is_none('rate_hz')
    assert not spec_default_is_none('inputs.crank.speed_rpm')


def test_a_scenes_drivers_add_their_parameters_and_what_each_one_drives():
    """Each driver's inputs.NAME.*, the first crank's aliases, the bound on cranks only."""
    five_bar = DriverParameters(mk.load_scene('five_bar').drivers)
    assert five_bar.aliases == {'crank_speed_rpm': 'inputs.left_crank.speed_rpm',
                                'crank_accel': 'inputs.left_crank.accel'}
    assert five_bar.keys['crank_speed_rpm'] == [('left_crank', 'speed_rpm')]
    assert five_bar.keys['inputs.right_crank.accel'] == [('right_crank', 'accel')]
    assert five_bar.keys['max_crank_speed_rpm'] == [('left_crank', 'max_speed_rpm'),
                                                    ('right_crank', 'max_speed_rpm')]
    assert five_bar.requests({'crank_speed_rpm': 30, 'max_crank_speed_rpm': 600.0,
                              'rate_hz': 50.0}) == {
        'left_crank': {'speed_rpm': 30.0, 'max_speed_rpm': 600.0},
        'right_crank': {'max_speed_rpm': 600.0}}
    excavator = DriverParameters(mk.load_scene('excavator').drivers)
    assert excavator.aliases == {} and excavator.keys['max_crank_speed_rpm'] == []
    assert list(excavator.specs) == ['inputs.boom_cyl.speed', 'inputs.boom_cyl.accel',
                                     'inputs.stick_cyl.speed', 'inputs.stick_cyl.accel']
    assert excavator.stroke_changes([Parameter('inputs.boom_cyl.speed', value=0.1),
                                     Parameter('rate_hz', value=10.0)]) == {
        'boom_cyl': {'speed': ('inputs.boom_cyl.speed', 0.1)}}
    assert five_bar.stroke_changes([Parameter('crank_speed_rpm', value=1.0)]) == {}


def test_either_name_of_the_first_cranks_speed_sets_both():
    """crank_speed_rpm brings inputs.FIRST.speed_rpm with it, and the other way round."""
    params = DriverParameters(mk.load_scene('five_bar').drivers)
    added = params.with_aliases([Parameter('inputs.left_crank.speed_rpm', value=30.0)])
    assert [(p.name, p.value) for p in added] == [
        ('inputs.left_crank.speed_rpm', 30.0), ('crank_speed_rpm', 30.0)]
    both = [Parameter('crank_accel', value=1.0), Parameter('inputs.left_crank.accel', value=2.0)]
    assert params.with_aliases(both) == both     # both given: the rule refuses one later


@pytest.fixture
def node(ros):
    """Return a node in the test's context with one parameter given at start (as -p does)."""
    node = rclpy.create_node('node_parameters_test', context=ros.context,
                             parameter_overrides=[Parameter('rate_hz', value=500)])
    yield node
    node.destroy_node()


def _declared(node, scene_name):
    """Return (NodeParameters on ``node``, its clock driver, the changes seen, the starts)."""
    driver = TickDriver(10 * 1_000_000, 0)
    changes = []
    params = NodeParameters(node, driver, lambda values, requested: changes.append(
        (values, requested)))
    params.declare()
    params.starting = False
    starts = params.declare_drivers(mk.load_scene(scene_name))
    for d, start in zip(mk.load_scene(scene_name).drivers, starts, strict=True):
        driver.add_drive(d.name, start.kind, **start.start)
    return params, driver, changes, starts


def test_declared_values_reach_the_clock_and_a_set_drives_at_the_next_instant(node):
    """-p rate_hz:=500 is the double 500.0 and the grid's period; a speed set is requested."""
    params, driver, changes, starts = _declared(node, 'five_bar')
    assert node.get_parameter('rate_hz').value == 500.0 and driver.period_ns == 2_000_000
    assert node.get_parameter('crank_speed_rpm').value == 30.0
    assert node.get_parameter('inputs.left_crank.speed_rpm').value == 30.0
    assert [s.start['speed_rpm'] for s in starts] == [30.0, 30.0]    # the scene's rpm
    result = node.set_parameters([Parameter('crank_speed_rpm', value=-45)])
    assert result[0].successful
    assert node.get_parameter('inputs.left_crank.speed_rpm').value == -45.0
    assert driver.drives['left_crank'].pending == {'speed_rpm': -45.0}
    assert changes[-1] == ({'crank_speed_rpm': -45.0, 'inputs.left_crank.speed_rpm': -45.0},
                           True)
    node.set_parameters([Parameter('rate_hz', value=250.0), Parameter('late_ticks',
                                                                      value='skip')])
    assert (driver.period_ns, driver.catch_up) == (4_000_000, False)
    assert driver.max_behind_ns == round(0.1 * NS_PER_S)


@pytest.mark.parametrize('name, value, reason', [
    ('rate_hz', 0.0, 'rate_hz: expected 1 <= value <= 10000 Hz, got 0.0'),
    ('inputs.right_crank.speed_rpm', 20_000.0,
     'inputs.right_crank.speed_rpm: expected |inputs.right_crank.speed_rpm| <= '
     'max_crank_speed_rpm (10000 rpm), got 20000 rpm'),
    ('crank_accel', 'fast', "crank_accel: expected a number (rad/s^2), got string 'fast'"),
    # Changeable while running only where the node publishes a robot's forces.
    ('payloads', ['platform=1.0'], 'payloads: Expected a robot whose forces the node '
     'publishes (URDF mode, its links carrying <inertial>) to change it while running'),
])
def test_a_refused_value_says_why_and_changes_nothing(node, name, value, reason):
    """A refusal is the service's reason, and the value and the drive stay as they were."""
    _, driver, changes, _ = _declared(node, 'five_bar')
    seen = len(changes)
    [result] = node.set_parameters([Parameter(name, value=value)])
    assert not result.successful and result.reason.startswith(reason)
    assert len(changes) == seen and all(not d.pending for d in driver.drives.values())


def test_a_drive_that_leaves_an_actuators_stroke_at_once_is_refused(node):
    """boom_cyl at 3.3 m (its longest) may not extend; retracting is taken."""
    params, driver, _, _ = _declared(node, 'excavator')
    node.set_parameters([Parameter('inputs.boom_cyl.speed', value=-0.1)])
    assert driver.drives['boom_cyl'].pending == {'speed': -0.1}
    # Not started: a drive from a start at the longest length.
    params.drivers.drivers['boom_cyl'] = mk.Actuator('boom_cyl', 3.3, 0.0, 0.0, (2.0, 3.3))
    [result] = node.set_parameters([Parameter('inputs.boom_cyl.speed', value=0.1)])
    assert not result.successful
    assert result.reason == ('inputs.boom_cyl.speed = 0.1: expected a drive that keeps actuator '
                             'boom_cyl within its stroke [2, 3.3] m, got one that leaves it at '
                             'once (at 3.3 m)')


def test_the_start_line_names_the_scene_and_every_effective_value(node):
    """The info line at start: the scene, its outputs, every parameter and the drivers'."""
    params, _, _, _ = _declared(node, 'five_bar')
    line = params.start_line(mk.load_scene('five_bar'))
    assert line.startswith("scene 'five_bar' (khurmi_four_bar_ad150): joints [")
    assert "; drive='time', crank_speed_rpm=30.0, crank_accel=0.0, " in line
    assert line.endswith('inputs.right_crank.speed_rpm=30.0, inputs.right_crank.accel=0.0')
    assert math.isfinite(params.driver_values(mk.load_scene('five_bar').drivers[0])['accel'])
