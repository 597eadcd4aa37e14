# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Intermittent drives (``RPR`` with ``slots``): the Geneva wheel over many crank turns.

See issue 11. The packaged ``geneva`` scene (Beer & Johnston's Sample Problem
in seed 000: R = 50 mm, four slots, 10 rad/s CCW) engages from 135 to 225 deg
of every crank turn; the wheel is locked between, and indexes a quarter turn
clockwise per crank turn. The exact values are computed here with mpmath (and
the 50-digit reference of ``mech_kinematics.verify.reference`` for the engaged
RPR motion), never by the solver's own formulas.
"""

from __future__ import annotations

import dataclasses
import json
import math
import warnings

import mpmath
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.__main__ import main
from mech_kinematics.ros.ticker import tick_function, values_from_state
from mech_kinematics.verify import reference as ref

SLOTS = 4
INDEX = 2 * math.pi / SLOTS  # rad per crank turn
OMEGA = 10.0  # rad/s, the scene's crank speed
#: The Geneva's jump of angular acceleration at the slot's mouth: omega^2 tan(pi / n).
JUMP = OMEGA ** 2 * math.tan(math.pi / SLOTS)
ENTRY, EXIT = math.radians(135.0), math.radians(225.0)  # of window 0
#: Finite-difference offsets from the engagement instants, rad of crank.
OFFSETS = (1e-3, 1e-5, 1e-7)


@pytest.fixture(scope='module')
def geneva():
    """Return the packaged Geneva wheel."""
    return mk.load_scene('geneva')


def with_wheel_point(scene):
    """Return ``scene`` with a point W carried by the wheel, 30 mm along its slot 0."""
    return dataclasses.replace(scene, points=(
        mk.CarriedPoint('W', 'wheel', 'S', 'P', (0.03, 0.0)),))


def wrapped(x):
    """Return ``x`` wrapped to (-pi, pi]."""
    return -math.remainder(-x, 2 * math.pi)


def exact_held(scene, j):
    """Return the exact held wheel angle c - j pi / n (rad, 60 digits) for the scene's doubles."""
    with mpmath.workdps(60):
        (dx, dy), (sx, sy) = scene.ground['D'], scene.ground['S']
        c = mpmath.atan2(mpmath.mpf(dy) - mpmath.mpf(sy), mpmath.mpf(dx) - mpmath.mpf(sx))
        return c - j * mpmath.pi / SLOTS


def angle_error(got, exact):
    """Return |got - exact| modulo 2 pi, exact being an mpf."""
    with mpmath.workdps(60):
        d = mpmath.mpf(got) - exact
        d -= 2 * mpmath.pi * mpmath.nint(d / (2 * mpmath.pi))
        return float(abs(d))


def test_dwell_is_exactly_still(geneva):
    """Between engagements the wheel's angle keeps its bits; velocity, acceleration are 0.0."""
    scene = with_wheel_point(geneva)
    degrees = np.concatenate([np.linspace(225.01, 494.99, 400), [360.0, 359.999, 360.001]])
    state = mk.solve(scene, np.radians(degrees))
    assert state.valid.all()
    wheel = state.joints['wheel']
    assert np.unique(wheel.position).size == 1  # the same bits across the dwell and turn 0/1
    assert (wheel.velocity == 0.0).all() and (wheel.acceleration == 0.0).all()
    bound = state.error_bound.joints['wheel']
    assert (bound.velocity == 0.0).all() and (bound.acceleration == 0.0).all()
    w = state.points['W']
    assert (w.velocity == 0.0).all() and (w.acceleration == 0.0).all()
    assert (state.error_bound.points['W'].velocity == 0.0).all()
    assert not state.intermittent['wheel'].engaged.any()
    for deg in (230.0, 360.0, 490.0):  # the single-angle path: the same bits
        single = mk.solve(scene, math.radians(deg))
        assert single.joints['wheel'].position == wheel.position[0]
        assert single.joints['wheel'].velocity == 0.0 == single.joints['wheel'].acceleration
    # Held at the exit direction of window 0: c - pi / n, to its bound.
    assert angle_error(wheel.position[0], exact_held(geneva, 1)) <= bound.position[0]


def test_indexes_exactly_one_slot_per_turn_over_100_turns(geneva):
    """Over 100 crank turns the locked wheel steps by 2 pi / n each turn, within its bounds."""
    turns = np.arange(101)
    state = mk.solve(geneva, math.radians(300.0), turns=turns)  # in every turn's dwell
    assert state.valid.all()
    position = state.joints['wheel'].position
    bound = state.error_bound.joints['wheel'].position
    for k in range(100):
        step = wrapped(position[k] - position[k + 1])
        assert abs(step - INDEX) <= bound[k] + bound[k + 1] + 4 * np.spacing(math.pi), k
        # and the exact held angle of the dwell after window k: c - (2k + 1) pi / n
        assert angle_error(position[k], exact_held(geneva, 2 * k + 1)) <= bound[k]
    # The wheel is back where it was every n turns, bit for bit.
    np.testing.assert_array_equal(position[SLOTS:], position[:-SLOTS])
    # The same through the single-angle path and as one angle counted from the start.
    for k in (0, 1, 7, 100):
        single = mk.solve(geneva, math.radians(300.0), turns=k).joints['wheel'].position
        assert single == position[k]
        counted = mk.solve(geneva, math.radians(300.0) + 2 * math.pi * k)
        assert counted.joints['wheel'].position == position[k]


def test_engaged_windows_turn_back_by_the_index(geneva):
    """In window k the wheel is the plain RPR's angle less k 2 pi / n; rates unchanged."""
    angle = geneva.input.angle  # 150 deg: engaged
    first = mk.solve(geneva, angle)
    for k in (1, 2, 3, 5, 99):
        state = mk.solve(geneva, angle, turns=k)
        wheel, bound = state.joints['wheel'], state.error_bound.joints['wheel']
        assert state.intermittent['wheel'].engaged and state.intermittent['wheel'].window == k
        # k 2 pi / n taken modulo 2 pi first: this test's own arithmetic rounds little.
        expected = first.joints['wheel'].position - (k % SLOTS) * INDEX
        assert abs(wrapped(expected - wheel.position)) <= (
            bound.position + first.error_bound.joints['wheel'].position
            + 4 * np.spacing(math.pi))
        assert wheel.velocity == first.joints['wheel'].velocity
        assert wheel.acceleration == first.joints['wheel'].acceleration


def test_huge_turn_counts_lose_nothing(geneva):
    """turns=4e15 + 1 gives the bits of turns=1: no huge unwrapped angle is ever formed."""
    for angle in (geneva.input.angle, math.radians(300.0)):
        small = mk.solve(geneva, angle, turns=1)
        huge = mk.solve(geneva, angle, turns=4 * 10 ** 15 + 1)
        assert huge.joints['wheel'].position == small.joints['wheel'].position
        assert huge.intermittent['wheel'].window == 4 * 10 ** 15 + 1
        assert huge.error_bound.joints['wheel'].position == \
            small.error_bound.joints['wheel'].position


def test_engaged_values_are_the_plain_rpr_ones_in_turn_0(geneva):
    """The published (engaged) answers are unchanged: window 0 is the plain RPR, bit for bit."""
    plain = dataclasses.replace(geneva, dyads=(dataclasses.replace(geneva.dyads[0], slots=None),))
    theta = np.radians(np.linspace(135.5, 224.5, 50))
    got, expected = mk.solve(geneva, theta), mk.solve(plain, theta)
    for name in ('wheel', 'pin_slot', 'driver'):
        for quantity in ('position', 'velocity', 'acceleration'):
            np.testing.assert_array_equal(getattr(got.joints[name], quantity),
                                          getattr(expected.joints[name], quantity))


@pytest.mark.parametrize('offset', OFFSETS)
def test_velocity_is_continuous_at_engagement(geneva, offset):
    """At a slot's mouth the wheel's speed tends to 0 from inside: |omega| ~ omega tan(pi/n) h."""
    for edge, inside in ((ENTRY, ENTRY + offset), (EXIT, EXIT - offset)):
        engaged = mk.solve(geneva, inside)
        locked = mk.solve(geneva, 2 * edge - inside)
        assert engaged.intermittent['wheel'].engaged and not locked.intermittent['wheel'].engaged
        omega = engaged.joints['wheel'].velocity
        assert abs(omega) <= (1 + 2 * offset) * OMEGA * math.tan(math.pi / SLOTS) * offset
        assert locked.joints['wheel'].velocity == 0.0
        # and the angle meets the held one to second order
        gap = abs(wrapped(engaged.joints['wheel'].position - locked.joints['wheel'].position))
        assert gap <= 0.51 * math.tan(math.pi / SLOTS) * offset ** 2 + 1e-15


@pytest.mark.parametrize('offset', OFFSETS)
def test_acceleration_jumps_are_reported_not_smeared(geneva, offset):
    """Either side of entry and exit the acceleration is the reported one-sided limit."""
    for edge, key in ((ENTRY, 'entry'), (EXIT, 'exit')):
        before, after = mk.solve(geneva, edge - offset), mk.solve(geneva, edge + offset)
        engagement = before.intermittent['wheel']
        limits = getattr(engagement, f'{key}_acceleration')
        assert getattr(engagement, key) == pytest.approx(edge, abs=1e-15)
        sides = (before.joints['wheel'].acceleration, after.joints['wheel'].acceleration)
        assert sides[0 if key == 'exit' else 1] != 0.0
        assert sides[1 if key == 'exit' else 0] == 0.0  # locked: exactly 0
        np.testing.assert_allclose(sides, limits, rtol=0, atol=4.0 * OMEGA * OMEGA * offset)
    assert mk.solve(geneva, ENTRY + 0.1).intermittent['wheel'].entry_acceleration == \
        pytest.approx((0.0, -JUMP), rel=1e-15)
    assert mk.solve(geneva, ENTRY + 0.1).intermittent['wheel'].exit_acceleration == \
        pytest.approx((JUMP, 0.0), rel=1e-15)


#: The engagement instants of the first two turns, deg: entry and exit of windows 0 and 1.
INSTANTS = (135.0, 225.0, 495.0, 585.0)
#: Crank speeds, rad/s: CCW, CW and at rest (a crank at rest counts as turning CCW).
SPEEDS = (OMEGA, -OMEGA, 0.0)


def edge_at(degrees):
    """Return 'entry' or 'exit': which end of a window of the packaged wheel ``degrees`` is."""
    return 'entry' if math.remainder(degrees - 135.0, 360.0) == 0.0 else 'exit'


def one_sided(engagement, edge, speed):
    """Return (after, before): the wheel's acceleration either side of ``edge`` of a window.

    Taken from the Engagement record, which gives them for a crank turning
    CCW; a crank turning CW passes the instant the other way.
    """
    before, after = getattr(engagement, f'{edge}_acceleration')
    return (before, after) if speed < 0.0 else (after, before)


@pytest.mark.parametrize('speed', SPEEDS)
@pytest.mark.parametrize('degrees', INSTANTS)
def test_engagement_instants_are_answered_one_sided(geneva, degrees, speed):
    """At entry and exit: the side after the jump, the other side in "jumps". See issue 19.

    The wheel's acceleration is the one-sided limit after the instant in the
    crank's sense of motion, within its own bound of the exact limit
    -+omega^2 tan(pi / n); position and velocity are those of either side; the
    point W carried by the wheel jumps with it, the crank and the pin do not.
    """
    scene = with_wheel_point(geneva)
    state = mk.solve(scene, math.radians(degrees), speed)
    engagement = state.intermittent['wheel']
    after, before = one_sided(engagement, edge_at(degrees), speed)
    wheel, bound = state.joints['wheel'], state.error_bound.joints['wheel']
    assert wheel.acceleration == after
    assert state.jumps['joints'] == {'wheel': {'acceleration': before}}
    assert engagement.engaged and engagement.window == int(degrees // 360.0)
    with mpmath.workdps(60):
        jump = mpmath.mpf(speed) ** 2 * mpmath.tan(mpmath.pi / SLOTS)
        exact = mpmath.sign(after) * jump  # the exact one-sided limit (0 if held after)
        assert abs(mpmath.mpf(wheel.acceleration) - exact) <= bound.acceleration
    assert bound.acceleration <= 1e-14 * max(JUMP, 1.0)
    assert abs(wheel.velocity) <= bound.velocity <= 1e-12 * OMEGA  # 0 on both sides
    edge = exact_held(geneva, 2 * int(degrees // 360.0) + (1 if degrees % 360 == 225 else -1))
    assert angle_error(wheel.position, edge) <= bound.position <= 1e-13
    # W is carried by the wheel 30 mm from S: a_W = (i alpha - omega^2) (W - S), omega ~ 0.
    w = state.complex_points['W']
    arm = w[0] - complex(*scene.ground['S'])
    assert abs(arm) == pytest.approx(0.03, rel=1e-12)
    assert w[2] == pytest.approx(1j * after * arm, abs=1e-12 * OMEGA ** 2)
    other = state.jumps['points']['W']['acceleration']
    assert list(state.jumps['points']) == ['W']
    np.testing.assert_allclose(other, [-before * arm.imag, before * arm.real],
                               rtol=0, atol=1e-12 * OMEGA ** 2)
    data = state.as_dict()['jumps']
    assert data['joints'] == {'wheel': {'acceleration': before}}
    assert data['points']['W']['acceleration'] == [float(x) for x in other]


def test_the_other_side_is_a_solve_a_hair_before(geneva):
    """The "jumps" side equals a solve a little before the instant, the answer one after."""
    scene = with_wheel_point(geneva)
    for degrees in INSTANTS:
        for speed in (OMEGA, -OMEGA):
            theta, step = math.radians(degrees), math.copysign(1e-9, speed)
            state = mk.solve(scene, theta, speed)
            before, after = mk.solve(scene, theta - step, speed), mk.solve(scene, theta + step,
                                                                           speed)
            got = state.jumps['joints']['wheel']['acceleration']
            assert got == pytest.approx(before.joints['wheel'].acceleration, abs=1e-6)
            assert state.joints['wheel'].acceleration == pytest.approx(
                after.joints['wheel'].acceleration, abs=1e-6)
            np.testing.assert_allclose(state.jumps['points']['W']['acceleration'],
                                       before.points['W'].acceleration, rtol=0, atol=1e-7)
            np.testing.assert_allclose(state.points['W'].acceleration,
                                       after.points['W'].acceleration, rtol=0, atol=1e-7)


def test_no_jumps_away_from_the_instants(geneva):
    """At other angles "jumps" is empty and absent from the JSON; a scene without one never."""
    for degrees in (134.99, 135.01, 150.0, 224.99, 300.0):
        state = mk.solve(geneva, math.radians(degrees))
        assert state.jumps == {} and 'jumps' not in state.as_dict()
        assert not geneva.jumps_at(math.radians(degrees))
    four_bar = mk.load_scene('khurmi_four_bar_ad150')
    assert four_bar.intermittent == () and not four_bar.jumps_at(1.0)
    assert mk.solve(four_bar, np.linspace(0, 6, 7)).jumps == {}
    assert geneva.intermittent == ('wheel',)
    for degrees in INSTANTS:
        assert geneva.jumps_at(math.radians(degrees))
    assert geneva.jumps_at(math.radians(135.0), turns=10 ** 12)


@pytest.mark.parametrize('speed', SPEEDS)
def test_both_paths_answer_the_instants_alike(geneva, speed):
    """In an array the instants are valid, and both paths give the same bits and jumps."""
    scene = with_wheel_point(geneva)
    degrees = np.array([*INSTANTS, 150.0, 300.0, 135.0])
    turns = np.array([0, 0, 0, 0, 0, 0, 7])
    vector = mk.solve(scene, np.radians(degrees), speed, turns=turns)
    assert vector.valid.all()
    jumped = ~np.isnan(vector.jumps['joints']['wheel']['acceleration'])
    np.testing.assert_array_equal(jumped, [True] * 4 + [False, False, True])
    assert np.isnan(vector.jumps['points']['W']['acceleration'][~jumped]).all()
    vector_bounds = vector.error_bound.raw()
    for index, (deg, k) in enumerate(zip(degrees, turns, strict=True)):
        single = mk.solve(scene, math.radians(deg), speed, turns=int(k))
        for name, joint in single.joints.items():
            position = vector.joints[name].position[index]
            assert abs(joint.position - position) <= np.spacing(abs(position))
            for quantity in ('velocity', 'acceleration'):
                assert getattr(joint, quantity) == getattr(vector.joints[name], quantity)[index]
        for name, values in single.error_bound.raw()[0].items():
            assert tuple(values) == tuple(x[index] for x in vector_bounds[0][name]), name
        assert single.complex_points['W'][2] == vector.complex_points['W'][2][index]
        if single.jumps:
            assert single.jumps['joints']['wheel']['acceleration'] == \
                vector.jumps['joints']['wheel']['acceleration'][index]
            np.testing.assert_array_equal(single.jumps['points']['W']['acceleration'],
                                          vector.jumps['points']['W']['acceleration'][index])
        assert bool(single.jumps) == jumped[index]
        assert single.intermittent['wheel'].engaged == vector.intermittent['wheel'].engaged[index]


def test_the_tick_answers_the_instants_as_solve_does(geneva):
    """The node's tick, compiled or not, publishes the instants with mk.solve's values."""
    tick, _ = tick_function(geneva)
    for degrees in INSTANTS:
        for speed in SPEEDS:
            theta, turns = math.radians(degrees % 360.0), int(degrees // 360.0)
            values, _ = tick(theta, speed, 0.0, mk.MAX_ERROR, turns)
            state = mk.solve(geneva, theta, speed, 0.0, turns=turns)
            assert values == values_from_state(state, geneva.output_joints,
                                               geneva.output_points)


def test_solve_command_reports_the_jumps_in_json(geneva, capsys):
    """`solve geneva --angle-deg 510` is window 1, engaged, with its jumps in "intermittent"."""
    assert main(['solve', 'geneva', '--angle-deg', '510']) == 0
    data = json.loads(capsys.readouterr().out)
    wheel = data['intermittent']['wheel']
    assert wheel['engaged'] is True and wheel['window'] == 1
    assert wheel['entry']['angle'] == pytest.approx(math.radians(495.0), rel=1e-15)
    assert wheel['exit']['angle'] == pytest.approx(math.radians(585.0), rel=1e-15)
    assert wheel['entry']['acceleration'] == pytest.approx([0.0, -JUMP], rel=1e-15)
    assert wheel['exit']['acceleration'] == pytest.approx([JUMP, 0.0], rel=1e-15)
    assert data['input']['angle'] == pytest.approx(math.radians(510.0), rel=1e-15)
    expected = mk.solve(geneva, math.radians(150.0), turns=1).joints['wheel'].position
    assert data['joints']['wheel']['position'] == expected
    assert 'jumps' not in data
    # An engagement instant is answered: the side after it, the other in "jumps" (issue 19).
    for degrees, after, before in (('135', -JUMP, 0.0), ('585', 0.0, JUMP)):
        assert main(['solve', 'geneva', '--angle-deg', degrees]) == 0
        data = json.loads(capsys.readouterr().out)
        assert data['joints']['wheel']['acceleration'] == pytest.approx(after, rel=1e-15)
        assert data['jumps'] == {'joints': {'wheel': {'acceleration': pytest.approx(
            before, rel=1e-15)}}, 'points': {}}
    assert main(['solve', 'geneva', '--angle-deg', '135', '--speed-rpm', '-60']) == 0
    data = json.loads(capsys.readouterr().out)
    assert data['joints']['wheel']['acceleration'] == 0.0
    assert data['jumps']['joints']['wheel']['acceleration'] == pytest.approx(
        -(2 * math.pi) ** 2, rel=1e-14)


def test_bounds_cover_the_exact_values(geneva):
    """Engaged in windows 0..5 and held in dwells, |solver - exact| <= bound (60 digits)."""
    checked = 0
    for degrees in (140.0, 150.0, 180.0, 200.0, 222.0, 30.0, 300.0):
        theta = math.radians(degrees)
        exact = ref.reference(geneva, theta)  # the reference's RPR is always engaged
        for k in range(6):
            state = mk.solve(geneva, theta, turns=k)
            wheel, bound = state.joints['wheel'], state.error_bound.joints['wheel']
            if state.intermittent['wheel'].engaged:
                with mpmath.workdps(60):
                    angle = exact.joints['wheel'][0] - k * 2 * mpmath.pi / SLOTS
                omega, alpha = (float(x) for x in exact.joints['wheel'][1:])
                assert abs(wheel.velocity - omega) <= bound.velocity
                assert abs(wheel.acceleration - alpha) <= bound.acceleration
            else:
                side = 1 if math.remainder(theta - math.pi, 2 * math.pi) > 0 else -1
                angle = exact_held(geneva, 2 * k + side)
                assert wheel.velocity == 0.0 == wheel.acceleration
            assert angle_error(wheel.position, angle) <= bound.position, (degrees, k)
            slot = exact.joints['pin_slot']  # |SP| and its rates, engaged or not
            got = state.joints['pin_slot']
            bounds = state.error_bound.joints['pin_slot']
            for index, quantity in enumerate(('position', 'velocity', 'acceleration')):
                assert abs(getattr(got, quantity) - float(slot[index])) <= \
                    getattr(bounds, quantity)
            checked += 1
    assert checked == 42


def test_both_paths_give_the_same_bits_near_the_mouths(geneva):
    """Near entry and exit both paths give the same bits (bounds, rates), refusals too."""
    offsets = np.concatenate([-np.logspace(-2, -15, 14), [0.0], np.logspace(-15, -2, 14)])
    theta = np.concatenate([ENTRY + offsets, EXIT + offsets, [2.0, 5.0]])
    turns = np.tile([0, 3, 10 ** 12], theta.size)[:theta.size]
    vector = mk.solve(geneva, theta, turns=turns)
    for index, (angle, k) in enumerate(zip(theta, turns, strict=True)):
        try:
            single = mk.solve(geneva, float(angle), turns=int(k))
        except mk.UntrustedError:
            assert not vector.valid[index]
            continue
        assert vector.valid[index]
        for name, joint in single.joints.items():
            # Angles come from atan2, which NumPy and libm may round an ulp apart.
            position = vector.joints[name].position[index]
            assert abs(joint.position - position) <= np.spacing(abs(position))
            for quantity in ('velocity', 'acceleration'):
                assert getattr(joint, quantity) == getattr(vector.joints[name], quantity)[index]
        got, table = single.error_bound.raw()[0], vector.error_bound.raw()[0]
        for name, values in got.items():
            assert tuple(values) == tuple(x[index] for x in table[name]), name
        assert single.intermittent['wheel'].engaged == vector.intermittent['wheel'].engaged[index]


@pytest.mark.parametrize(('turns', 'message'), [(1.5, 'whole number'), (True, 'whole number'),
                                                (np.array([0.5]), 'whole number'),
                                                ('2', 'whole number')])
def test_turns_must_be_whole(geneva, turns, message):
    """`turns` is an int or an array of ints; anything else is a ValueError saying so."""
    with pytest.raises(ValueError, match=message):
        mk.solve(geneva, 0.3, turns=turns)


def test_turns_mean_nothing_to_a_continuous_mechanism():
    """For a four-bar, turns=k gives the bits of turns=0 (only the reported angle differs)."""
    scene = mk.load_scene('khurmi_four_bar_ad150')
    base, moved = mk.solve(scene, 0.7), mk.solve(scene, 0.7, turns=-3)
    assert base.joints['rocker'].position == moved.joints['rocker'].position
    assert moved.as_dict()['input']['angle'] == pytest.approx(0.7 - 6 * math.pi, rel=1e-15)


SCENE = """\
name: geneva_six
units: {length: mm, angle: deg}
ground: {D: [0, 0], S: [0, 100]}
input: {link: driver, center: D, point: P, length: 50, angle: 80, speed_rpm: 60}
dyads:
  - {type: RPR, link: wheel, center: S, through: P, slider: pin_slot, slots: 6}
"""


def test_a_six_slot_wheel_written_in_general_terms(tmp_path):
    """A 6-slot wheel above its driver: 60 deg per turn, engaged for 120 deg around 90 deg."""
    path = tmp_path / 'six.yaml'
    path.write_text(SCENE)
    scene = mk.load_scene(path)
    theta = np.radians([29.0, 31.0, 90.0, 149.0, 151.0, 380.0])
    state = mk.solve(scene, theta)
    np.testing.assert_array_equal(state.intermittent['wheel'].engaged,
                                  [False, True, True, True, False, False])
    held = state.joints['wheel'].position
    assert wrapped(held[0] - held[5]) == pytest.approx(math.pi / 3, abs=1e-14)
    assert held[4] == held[5]  # the dwell after window 0 lasts into turn 1
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        middle = mk.solve(scene, math.radians(90.0))
    # At the line of centres the pin is closest: omega = -w R / (l - R) = -2 pi / 1 rad/s.
    assert middle.joints['wheel'].velocity == pytest.approx(-2 * math.pi, rel=1e-14)


@pytest.mark.parametrize(('speed', 'accel'), [(2 * math.pi, 0.0), (-3.0, 1.0), (0.0, 5.0)])
def test_a_six_slot_wheel_is_answered_one_sided_at_its_instants(tmp_path, speed, accel):
    """Entry at 30 deg, exit at 150 deg: the one-sided limits -+omega^2 tan(30 deg). Issue 19."""
    path = tmp_path / 'six.yaml'
    path.write_text(SCENE)
    scene = mk.load_scene(path)
    for degrees, edge, sign in ((30.0, 'entry', -1), (150.0, 'exit', 1)):
        state = mk.solve(scene, math.radians(degrees), speed, accel)
        after, before = one_sided(state.intermittent['wheel'], edge, speed)
        got = state.joints['wheel'].acceleration
        assert got == after and state.jumps['joints']['wheel']['acceleration'] == before
        with mpmath.workdps(60):
            exact = sign * mpmath.mpf(speed) ** 2 * mpmath.tan(mpmath.pi / 6)
            side = exact if (edge == 'entry') == (speed >= 0.0) else 0
            assert abs(mpmath.mpf(got) - side) <= state.error_bound.joints['wheel'].acceleration
        # and a hair after the instant the plain solve agrees, to first order
        step = math.copysign(1e-8, speed) if speed else 1e-8
        near = mk.solve(scene, math.radians(degrees) + step, speed, accel)
        assert near.joints['wheel'].acceleration == pytest.approx(after, abs=1e-6)


@pytest.mark.parametrize(('edit', 'message'), [
    (('slots: 6', 'slots: 5'), r'dyads\[0\]\.slots: Expected the pin P to enter the 5 slots of '
                               r'"wheel" tangentially: D and S 85\.06508084 mm apart \(pin radius '
                               r'50 mm / sin\(180 deg / 5\)\) or a pin radius of 58\.77852523 mm, '
                               r'to 1e-9, got 100 mm apart'),
    (('slots: 6', 'slots: 2'), r'dyads\[0\]\.slots: expected a whole number of slots from 3 to '
                               r'1000, got 2'),
    (('slots: 6', 'slots: six'), r'dyads\[0\]\.slots: expected a whole number of slots'),
    (('S: [0, 100]', 'S: [0, 100.001]'), r'tangentially.*got 100\.001 mm apart'),
    (('through: P', 'through: S'), r'dyads\[0\]\.through: Expected the pin of intermittent RPR '
                                   r'"wheel" \(slots: 6\) to be a point fixed on the crank '
                                   r'"driver" \(P\), got "S"'),
])
def test_an_intermittent_lever_that_cannot_work_is_refused(tmp_path, edit, message):
    """Bad slots, a pin off the crank or a geometry without tangential entry: one clear line."""
    path = tmp_path / 'bad.yaml'
    path.write_text(SCENE.replace(*edit))
    with pytest.raises(mk.SceneError, match=message):
        mk.load_scene(path)
