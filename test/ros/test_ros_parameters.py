# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's parameter table and its rules, without ROS."""

import math

import pytest

from mech_kinematics.ros.parameters import (bounded_by_max_crank_speed, driver_parameters,
                                            extra_joints_default, first_crank_aliases,
                                            joint_refusal, PARAMETERS, rate_default, refusal,
                                            spec)
from mech_kinematics.scene import MAX_FILE_BYTES
from mech_kinematics.solver.actuator import Actuator
from mech_kinematics.solver.crank import Crank
from mech_kinematics.units import rad_per_s_from_rpm


@pytest.mark.parametrize('name, value, reason', [
    ('rate_hz', 0.0, 'rate_hz: expected 1 <= value <= 10000 Hz, got 0.0'),
    ('rate_hz', math.nan, 'rate_hz: expected a finite number, got nan'),
    ('rate_hz', 'fast', "rate_hz: expected a number (Hz), got string 'fast'"),
    ('rate_hz', True, 'rate_hz: expected a number (Hz), got bool True'),
    ('scene', 123, 'scene: expected a string, got number 123'),
    ('scene', '', "scene: expected a non-empty string, got ''"),
    ('frame_id', 5, 'frame_id: expected a string, got number 5'),
    ('markers', 'yes', "markers: expected true or false, got string 'yes'"),
    ('late_ticks', 'later', "late_ticks: expected one of catch_up, skip, got 'later'"),
    ('drive', 'topics', "drive: expected one of time, topic, target, trajectory, got 'topics'"),
    ('drive', 1, 'drive: expected a string, got number 1'),
    ('max_catch_up_s', -1.0, 'max_catch_up_s: expected 0 <= value <= 10 s, got -1.0'),
    ('extra_joints', 'keep', "extra_joints: expected one of refuse, ignore, pass, got 'keep'"),
    ('stamp_jump_back_s', -0.5, 'stamp_jump_back_s: expected 0 <= value <= 1e+09 s, got -0.5'),
    ('actuated_joints', 3,
     "actuated_joints: expected a list of joint names (e.g. ['j1', 'j2']), got number 3"),
    ('actuated_joints', 'finger_joint', 'actuated_joints: expected a list of joint names '
     "(e.g. ['j1', 'j2']), got string 'finger_joint'"),
    ('actuated_joints', ['a', 'a'],
     "actuated_joints: expected one or more distinct non-empty joint names, got ['a', 'a']"),
    ('actuated_joints', ['a', ''],
     "actuated_joints: expected one or more distinct non-empty joint names, got ['a', '']"),
    ('loop_closures', 7, 'loop_closures: expected a string, got number 7'),
])
def test_bad_values_are_refused_with_a_reason(name, value, reason):
    """Each bad value gets one line naming the parameter, what it expects and what it got."""
    assert refusal(name, value) == reason


@pytest.mark.parametrize('name, limit', [('tf_prefix', 256), ('frame_id', 256), ('scene', 4096),
                                         ('loop_closures', 4096),
                                         ('robot_description', MAX_FILE_BYTES)])
def test_every_string_is_bounded(name, limit):
    """Issue 33: a 10 MB tf_prefix took the start 7 s; a name over 256, a path over 4096, no.

    A URDF's text (``robot_description``) is bounded as a scene file is (8 MiB).
    """
    assert refusal(name, 'a' * limit) is None
    reason = refusal(name, 'a' * 10_000_000)
    assert reason == (f'{name}: expected at most {limit} characters, got 10000000: '
                      f"'{'a' * 30}'...")
    assert all(p.max_chars in (256, 4096, MAX_FILE_BYTES) for p in PARAMETERS
               if p.kind == 'string')


def test_urdf_mode_passes_the_robots_other_joints_by_default():
    """extra_joints is unset unless given: refuse for a scene, pass in URDF mode (issue 31)."""
    assert spec('extra_joints').default is None
    assert (extra_joints_default(False), extra_joints_default(True)) == ('refuse', 'pass')
    assert refusal('actuated_joints', ['finger_joint', 'wrist']) is None
    assert refusal('robot_description', '') is None and refusal('loop_closures', '') is None


def test_good_values_and_foreign_names_pass():
    """In-range values (integers for doubles too) and names the node does not own pass."""
    assert refusal('rate_hz', 500) is None
    assert refusal('late_ticks', 'skip') is None
    assert refusal('use_sim_time', 'anything') is None


def test_the_speed_may_not_exceed_its_bound():
    """|crank_speed_rpm| > max_crank_speed_rpm is refused; equal is fine."""
    assert joint_refusal({'crank_speed_rpm': -3000.0, 'max_crank_speed_rpm': 3000.0}) is None
    assert 'max_crank_speed_rpm (2000 rpm), got -3000 rpm' in joint_refusal(
        {'crank_speed_rpm': -3000.0, 'max_crank_speed_rpm': 2000.0})


def test_markers_are_refused_with_drive_topic():
    """The arrows would show values a topic does not give: markers need drive: time (issue 18)."""
    assert joint_refusal({'drive': 'time', 'markers': True}) is None
    assert joint_refusal({'drive': 'topic', 'markers': False}) is None
    assert joint_refusal({'drive': 'topic', 'markers': True}) == (
        'markers: expected false with drive: topic (the arrows would show velocities and '
        'accelerations the input does not give), got true')
    assert spec('drive').default == 'time' and spec('drive').read_only
    assert joint_refusal({'drive': 'trajectory', 'markers': True}) == (
        "markers: expected false with drive: trajectory (the markers follow the clock's grid, "
        'which does not run), got true')


def test_every_parameter_is_described():
    """Every parameter has a type, a description, and a range for every double."""
    for p in PARAMETERS:
        assert p.kind in ('double', 'string', 'bool', 'string_array') and p.description
        if p.kind == 'double':
            assert p.low is not None and p.high is not None and p.unit
    assert spec('rate_hz').default == 100.0


@pytest.mark.parametrize('name, value', [
    ('frame_id', '/'), ('frame_id', '/mechanism'), ('frame_id', 'a//b'), ('frame_id', 'a/'),
    ('frame_id', 'two words'), ('frame_id', 'tab\there'), ('tf_prefix', '../..'),
    ('tf_prefix', '.'), ('tf_prefix', '/robot'), ('tf_prefix', 'robot/'),
])
def test_frame_ids_are_refused_where_tf2_would(name, value):
    """``frame_id:=/`` and ``tf_prefix:=../..`` put ``//crank`` on /tf: refused (issue 21)."""
    assert refusal(name, value) == (
        f"{name}: expected a tf2 frame id (no leading '/', no empty, '.' or '..' part "
        f"between '/', no space), got {value!r}; e.g. 'mechanism' or 'robot/base'")


@pytest.mark.parametrize('name, value', [
    ('frame_id', 'mechanism'), ('frame_id', 'robot_1/base'), ('tf_prefix', ''),
    ('tf_prefix', 'left/arm'), ('frame_id', 'a.b'),
])
def test_good_frame_ids_pass(name, value):
    assert refusal(name, value) is None


def test_an_empty_parameter_name_is_refused():
    """The parameter named '' was accepted and listed (issue 21)."""
    assert refusal('', 5) == 'expected a parameter name, got an empty one (with value 5)'


def test_a_huge_refused_value_is_not_echoed_whole():
    """A 1 MB refused string was echoed whole into the log: the message stays short."""
    reason = refusal('late_ticks', 'x' * 1_000_000)
    assert reason == (f"late_ticks: expected one of catch_up, skip, got '{'x' * 59}... "
                      '(1000000 characters)')


def test_the_speed_bound_refusal_says_what_to_do():
    """Blaming max_crank_speed_rpm, which the user never set, now says how to go faster."""
    assert joint_refusal({'crank_speed_rpm': 20000.0, 'max_crank_speed_rpm': 10000.0}) == (
        'crank_speed_rpm: expected |crank_speed_rpm| <= max_crank_speed_rpm (10000 rpm), got '
        '20000 rpm; set max_crank_speed_rpm (up to 100000) first to go faster')


@pytest.mark.parametrize('rate_hz', [1.0, 100.0, 1000.0, 4000.0, 10_000.0])
@pytest.mark.parametrize('max_catch_up_s', [0.0, 0.1, 1.0, 10.0])
def test_a_catch_up_burst_fits_the_history(rate_hz, max_catch_up_s):
    """A late wake-up publishes at most the history depth of missed instants.

    A 10 s SIGSTOP at 1 kHz published 10,001 instants at once and a KEEP_LAST
    1000 reader lost 1,712 of them (issue 21); older instants are now skipped.
    """
    from mech_kinematics.ros.parameters import catch_up_window_ns, STATE_DEPTH
    from mech_kinematics.ros.schedule import period_ns_from_rate, TickGrid

    period = period_ns_from_rate(rate_hz)
    grid = TickGrid(0, period)
    window = catch_up_window_ns(max_catch_up_s, period)
    due = grid.take(20 * 10**9, window)        # woke 20 s late
    wanted = min(round(max_catch_up_s * 1e9) // period + 1, STATE_DEPTH)
    assert len(due.instants) == wanted <= STATE_DEPTH
    assert window <= round(max_catch_up_s * 1e9)


FIVE_BAR = (Crank('left', 'A', 'B', 0.1, speed=-4 * math.pi),
            Crank('right', 'E', 'D', 0.1, speed=2 * math.pi, accel=1.5))
EXCAVATOR = (Actuator('boom_cyl', 1.0, 0.05, 0.0), Actuator('stick_cyl', 1.0, -0.02, 0.01))


def test_each_driver_has_its_parameters_with_the_scenes_defaults():
    """Cranks: inputs.NAME.speed_rpm, .accel; actuators: inputs.NAME.speed, .accel (issue 18)."""
    specs = {p.name: p for p in driver_parameters(FIVE_BAR + EXCAVATOR)}
    assert list(specs) == ['inputs.left.speed_rpm', 'inputs.left.accel',
                           'inputs.right.speed_rpm', 'inputs.right.accel',
                           'inputs.boom_cyl.speed', 'inputs.boom_cyl.accel',
                           'inputs.stick_cyl.speed', 'inputs.stick_cyl.accel']
    assert specs['inputs.left.speed_rpm'].default == -120.0     # rounded, not -119.99...
    assert specs['inputs.right.speed_rpm'].default == 60.0
    assert specs['inputs.right.accel'].default == 1.5
    assert specs['inputs.boom_cyl.speed'].default == 0.05
    assert specs['inputs.stick_cyl.accel'].default == 0.01
    assert specs['inputs.left.speed_rpm'].unit == 'rpm'
    assert specs['inputs.boom_cyl.speed'].unit == 'm/s'
    assert specs['inputs.boom_cyl.accel'].unit == 'm/s^2'
    assert all(p.kind == 'double' and not p.read_only and p.description
               for p in specs.values())


@pytest.mark.parametrize('name, value, reason', [
    ('inputs.left.speed_rpm', 2e5, 'inputs.left.speed_rpm: expected -100000 <= value <= 100000 '
     'rpm, got 200000.0'),
    ('inputs.boom_cyl.speed', 'fast', 'inputs.boom_cyl.speed: expected a number (m/s), got '
     "string 'fast'"),
    ('inputs.boom_cyl.accel', math.inf, 'inputs.boom_cyl.accel: expected a finite number, got '
     'inf'),
    ('inputs.boom_cyl.speed_rpm', 1.0, 'inputs.boom_cyl.speed_rpm: expected the parameter of a '
     'driver of the scene (inputs.boom_cyl.accel, inputs.boom_cyl.speed, inputs.left.accel, '
     'inputs.left.speed_rpm), got none'),
    ('inputs.wrist.speed', 1.0, 'inputs.wrist.speed: expected the parameter of a driver'),
])
def test_driver_parameters_are_refused_with_a_reason(name, value, reason):
    """A bad value, or a parameter of a driver the scene lacks, is refused naming it."""
    drivers = {p.name: p for p in driver_parameters(FIVE_BAR[:1] + EXCAVATOR[:1])}
    assert refusal(name, value, drivers).startswith(reason)
    assert refusal('inputs.boom_cyl.speed', -0.5, drivers) is None


def test_a_rate_keeps_the_unit_the_scene_gave_it():
    """A crank's speed_rpm is its parameter's default to the bit; rad/s are rounded rpm."""
    rpm = 7.123456789012345     # more digits than 12: a round trip through rad/s rounded them
    crank = Crank('c', 'A', 'B', 0.1, speed=rad_per_s_from_rpm(rpm), rpm=rpm)
    assert crank.rate == ('speed_rpm', rpm, 'rpm')
    assert rate_default(crank) == rpm
    [speed, _] = driver_parameters([crank])
    assert (speed.name, speed.default, speed.unit) == ('inputs.c.speed_rpm', rpm, 'rpm')
    assert rate_default(FIVE_BAR[0]) == -120.0
    assert FIVE_BAR[0].rate == ('speed', -4 * math.pi, 'rad/s')
    assert rate_default(EXCAVATOR[1]) == -0.02
    bounded = [bounded_by_max_crank_speed(d) for d in FIVE_BAR + EXCAVATOR]
    assert bounded == [True, True, False, False]


def test_crank_speed_rpm_stays_the_first_cranks_name():
    """crank_speed_rpm and crank_accel alias the first driver's parameters when it is a crank."""
    assert first_crank_aliases(FIVE_BAR) == {'crank_speed_rpm': 'inputs.left.speed_rpm',
                                             'crank_accel': 'inputs.left.accel'}
    assert first_crank_aliases(EXCAVATOR) == {}
    assert first_crank_aliases(EXCAVATOR[:1] + FIVE_BAR) == {}


def test_every_cranks_speed_is_bounded():
    """max_crank_speed_rpm bounds every crank's inputs.NAME.speed_rpm too (issue 18)."""
    assert joint_refusal({'inputs.right.speed_rpm': 3000.0, 'max_crank_speed_rpm': 3000.0}) is None
    assert joint_refusal({'inputs.right.speed_rpm': -3001.0, 'max_crank_speed_rpm': 3000.0}) == (
        'inputs.right.speed_rpm: expected |inputs.right.speed_rpm| <= max_crank_speed_rpm '
        '(3000 rpm), got -3001 rpm; set max_crank_speed_rpm (up to 100000) first to go faster')
    assert joint_refusal({'inputs.boom_cyl.speed': 500.0, 'max_crank_speed_rpm': 1.0}) is None
