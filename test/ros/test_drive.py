# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's drivers on the clock (ros/drive.py): time bases and starts, without ROS.

Issue 30: a rate keeps the unit the scene gave it up to the time base, which
converts it once; the node asks the driver's kind, never which kind it is.
"""

import math

import pytest

import mech_kinematics as mk
from mech_kinematics.ros.drive import (check_start, DEFAULT_MAX_CRANK_SPEED_RPM, drive_start,
                                       driven_rate, max_crank_speed_default, MAX_SPEED_KEY,
                                       position_text, solve_at_start, stroke_refusal,
                                       timebase_kind, transposed)
from mech_kinematics.ros.parameters import rate_default
from mech_kinematics.ros.timebase import ActuatorTimebase, CrankTimebase
from mech_kinematics.solver.actuator import Actuator
from mech_kinematics.solver.crank import Crank
from mech_kinematics.units import NS_PER_S, rad_per_s_from_rpm

#: Instants at which the published speeds are compared, ns: the start, a ragged one, a year on.
INSTANTS = (0, 1, 123_456_789, 365 * 86_400 * NS_PER_S + 7)


def _crank_scene(speed: str) -> mk.Scene:
    """Return the Khurmi four-bar with its crank's speed written as ``speed`` (a YAML key)."""
    return mk.parse_scene({
        'name': 'four_bar', 'units': {'length': 'mm', 'angle': 'deg'},
        'ground': {'A': [0, 0], 'D': [150, 0]},
        'input': {'link': 'crank', 'center': 'A', 'point': 'B', 'length': 40, 'angle': 60,
                  **speed, 'accel': 0},
        'dyads': [{'type': 'RRR', 'point': 'C', 'branch': 1, 'links': [
            {'name': 'coupler', 'from': 'B', 'length': 150},
            {'name': 'rocker', 'from': 'D', 'length': 80}]}]})


def _values(driver, **given):
    """Return a driver's parameter values as the node has them: the scene's, then ``given``."""
    values = {driver.rate_parameter.key: rate_default(driver), 'accel': driver.accel,
              MAX_SPEED_KEY: DEFAULT_MAX_CRANK_SPEED_RPM}
    values.update(given)
    return values


def test_a_crank_of_7_rpm_reaches_the_time_base_as_exactly_7_rpm():
    """speed_rpm: 7 starts the time base at 7.0 rpm (no rad/s round trip), same velocity bits.

    Before, the node handed the time base the scene's 7 pi / 30 rad/s and the
    parameter showed rpm_from_rad_per_s of it rounded; the published speed was
    the float 7 pi / 30 either way, and is still.
    """
    crank = _crank_scene({'speed_rpm': 7}).input
    assert crank.rpm == 7.0 and crank.rate == ('speed_rpm', 7.0, 'rpm')
    start = drive_start(crank, _values(crank))
    assert start.kind is CrankTimebase
    assert start.start['speed_rpm'] == 7.0 and type(start.start['speed_rpm']) is float
    assert start.start['speed'] is None
    assert start.speed == crank.speed == rad_per_s_from_rpm(7.0)
    new = start.kind(0, **start.start)
    # What the node built before: the scene's own speed in rad/s.
    old = CrankTimebase(0, crank.angle, None, 0.0, DEFAULT_MAX_CRANK_SPEED_RPM,
                        speed=crank.speed)
    for t in INSTANTS:
        assert new.sample(t).speed.hex() == old.sample(t).speed.hex() == crank.speed.hex()
    assert new.speed(10 * NS_PER_S) * 60 == 7      # exactly 7 turns a minute


def test_a_crank_in_rad_per_s_keeps_rad_per_s():
    """speed: 10 (rad/s) starts the time base at 10 rad/s; its parameter shows rounded rpm."""
    crank = _crank_scene({'speed': 10}).input
    assert crank.rpm is None and crank.rate == ('speed', 10.0, 'rad/s')
    assert rate_default(crank) == 95.4929658551     # 12 significant digits
    start = drive_start(crank, _values(crank))
    assert start.start['speed'] == 10.0 and start.start['speed_rpm'] is None
    assert start.kind(0, **start.start).sample(123_456_789).speed == 10.0


def test_a_parameter_set_apart_from_the_scene_drives_in_its_own_unit():
    """A crank speed set by its parameter drives in rpm, an actuator's in m/s."""
    crank = _crank_scene({'speed': 10}).input
    assert driven_rate(crank, 30.0) == ('speed_rpm', 30.0, 'rpm')
    # Given as crank_speed_rpm at start (own=False), even the scene's value is the parameter's.
    assert driven_rate(crank, rate_default(crank), own=False) == (
        'speed_rpm', rate_default(crank), 'rpm')
    cyl = Actuator('cyl', 1.0, 0.05)
    assert driven_rate(cyl, 0.05) == ('speed', 0.05, 'm/s')
    assert driven_rate(cyl, -0.5) == ('speed', -0.5, 'm/s')


def test_a_scene_crank_in_rad_per_s_beyond_the_default_bound_drives_in_rpm():
    """1500 rad/s (14324 rpm): the bound defaults to its rpm and holds it; driven in rpm."""
    crank = _crank_scene({'speed': 1500}).input
    bound = max_crank_speed_default([crank], None)
    assert bound == rate_default(crank) == 14323.9448783
    rate = driven_rate(crank, rate_default(crank))
    assert rate == ('speed_rpm', 14323.9448783, 'rpm')
    timebase = CrankTimebase(0, 0.0, rate.value, 0.0, bound)
    assert timebase.sample(NS_PER_S).speed == rad_per_s_from_rpm(bound)


def test_each_driver_gets_the_time_base_of_its_joint_type():
    """An angle's driver a crank time base (turns, bound), a length's an actuator's."""
    crank = Crank('c', 'A', 'B', 0.1, speed=1.0, turns=3)
    cyl = Actuator('cyl', 1.2, 0.05, 0.5, (1.0, 1.5))
    assert timebase_kind(crank) is CrankTimebase and timebase_kind(cyl) is ActuatorTimebase
    start = drive_start(crank, _values(crank, accel=2.0, **{MAX_SPEED_KEY: 600.0}))
    assert start.start == {'angle': 0.0, 'speed_rpm': None, 'speed': 1.0, 'accel': 2.0,
                           'max_speed_rpm': 600.0, 'turns': 3}
    assert (start.position, start.speed, start.accel, start.turns) == (0.0, 1.0, 2.0, 3)
    start = drive_start(cyl, _values(cyl))
    assert start.start == {'length': 1.2, 'speed': 0.05, 'accel': 0.5}
    assert (start.position, start.speed, start.accel, start.turns) == (1.2, 0.05, 0.5, 0)
    assert start.kind(0, **start.start).sample(0) == (1.2, 0.05, 0.5)


def test_the_bound_defaults_to_the_fastest_crank_or_the_speed_given():
    """max_crank_speed_rpm: 10000 rpm, or a crank's (never an actuator's) or crank_speed_rpm."""
    slow, fast = Crank('a', 'A', 'B', 0.1), Crank('b', 'C', 'D', 0.1,
                                                  speed=rad_per_s_from_rpm(-12_000.0),
                                                  rpm=-12_000.0)
    cyl = Actuator('cyl', 1.0, 99.0)
    assert max_crank_speed_default([slow, cyl], None) == DEFAULT_MAX_CRANK_SPEED_RPM
    assert max_crank_speed_default([slow, fast], None) == 12_000.0
    assert max_crank_speed_default([slow], -20_000.0) == 20_000.0


def test_a_start_that_solve_refuses_is_one_line_naming_the_scene():
    """What solve refuses at the drivers' start, the node refuses to start with."""
    scene = _crank_scene({'speed_rpm': -120})
    crank = scene.input
    starts = [drive_start(crank, _values(crank))]
    check_start(scene, starts, 1e-6)
    with pytest.raises(mk.SceneError, match=r'^four_bar: .*cannot be trusted') as error:
        check_start(scene, starts, 1e-15)
    assert '\n' not in str(error.value)


def test_the_start_state_and_several_drivers_transposed():
    """The start solve holds each driver's start; several drivers' states in scene order."""
    scene = mk.load_scene('five_bar')
    state = solve_at_start(scene)
    for d in scene.drivers:
        assert state.joints[d.name].position == pytest.approx(math.remainder(d.start, math.tau))
    assert transposed([(1, (0.1, 0.2, 0.3)), (0, (1.0, 2.0, 3.0))]) == (
        (1, 0), ((0.1, 1.0), (0.2, 2.0), (0.3, 3.0)))
    assert position_text(0.5) == 'crank angle 0.500000 rad'
    assert position_text((0.5, 1.25)) == 'driver positions 0.500000, 1.250000'


def test_a_drive_that_leaves_the_stroke_at_once_is_refused():
    """At a limit, moving out: refused naming the actuator and its stroke; moving back: taken."""
    cyl = Actuator('cyl', 1.5, 0.0, 0.0, (1.0, 1.5))
    change = {'speed': ('inputs.cyl.speed', 0.1)}
    # Not started yet: from its start values.
    assert stroke_refusal(cyl, None, 0, change, _values(cyl)) == (
        'inputs.cyl.speed = 0.1: expected a drive that keeps actuator cyl within its stroke '
        '[1, 1.5] m, got one that leaves it at once (at 1.5 m)')
    assert stroke_refusal(cyl, None, 0, {'speed': ('inputs.cyl.speed', -0.1)},
                          _values(cyl)) is None
    # Running: from its length now (1.25 m, moving out at 0.25 m/s from 0: 1.5 m at 1 s).
    timebase = ActuatorTimebase(0, 1.25, 0.25, 0.0)
    assert stroke_refusal(cyl, timebase, NS_PER_S // 2, {'accel': ('inputs.cyl.accel', 1.0)},
                          _values(cyl)) is None
    assert stroke_refusal(cyl, timebase, NS_PER_S, {'accel': ('inputs.cyl.accel', 1.0)},
                          _values(cyl)) == (
        'inputs.cyl.accel = 1.0: expected a drive that keeps actuator cyl within its stroke '
        '[1, 1.5] m, got one that leaves it at once (at 1.5 m)')
    assert timebase.sample(NS_PER_S) == (1.5, 0.25, 0.0)     # the trial left it alone
    assert stroke_refusal(Crank('c', 'A', 'B', 0.1), None, 0, {'accel': ('x', 1.0)},
                          {}) is None
