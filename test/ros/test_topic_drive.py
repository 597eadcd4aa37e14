# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The rules of ``drive: topic`` for one input message, without ROS. See issues 18 and 33."""

from dataclasses import dataclass
import math

from hypothesis import given, strategies as st
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.ros.topic_drive import (IGNORE, PASS, PassedJoints, RefusedInput,
                                             TopicDrive, TopicInput)

NS = 1_000_000_000
#: The largest stamp a builtin_interfaces/Time holds (int32 seconds), ns: a bad clock's.
FAR_FUTURE = (2**31 - 1) * NS


@dataclass(frozen=True)
class Driver:
    """A driver as the rules see it: a name and an optional stroke (m)."""

    name: str
    stroke: tuple[float, float] | None = None


TWO = (Driver('left'), Driver('boom_cyl', (1.0, 1.8)))


def refused(drive, *args, match):
    with pytest.raises(RefusedInput, match=match) as info:
        drive.read(*args)
    assert '\n' not in info.value.reason
    assert info.value.reason.startswith('input_joint_states: expected ')
    return info.value.reason


def test_a_scene_driver_is_read_with_its_velocity():
    """A one-crank scene: the crank's position and velocity, the stamp in ns."""
    scene = mk.load_scene('khurmi_four_bar_ad150')
    drive = TopicDrive(scene.drivers)
    assert drive.names == (scene.input.link,)
    got = drive.read(12, 345, [scene.input.link], [0.25], [-3.5])
    assert got == TopicInput(12 * NS + 345, (0.25,), (-3.5,))


def test_names_in_any_order_give_scene_order():
    """The message may list the drivers in any order; positions come back in scene order."""
    drive = TopicDrive(TWO)
    got = drive.read(1, 0, ['boom_cyl', 'left'], [1.5, 0.5], [0.1, -2.0])
    assert got.positions == (0.5, 1.5)
    assert got.speeds == (-2.0, 0.1)


def test_no_velocities_leaves_them_unknown():
    """An empty velocity array: positions only, speeds None (never guessed as zero)."""
    got = TopicDrive(TWO).read(1, 0, ['left', 'boom_cyl'], [0.5, 1.5], [])
    assert got.speeds is None
    assert got.positions == (0.5, 1.5)


@pytest.mark.parametrize('names, positions, velocities, match', [
    (['left', 'boom_cyl', 'wrist'], [0.0, 1.5, 2.0], [],
     r"unknown joint\(s\) 'wrist' \(extra_joints:=ignore\|pass takes the drivers and drops or "
     r'passes the others\)$'),
    (['left'], [0.0], [], "got none for 'boom_cyl'"),
    (['left', 'left', 'boom_cyl'], [0.0, 0.0, 1.5], [], "'left' twice"),
    (['left', 'boom_cyl'], [0.0], [], r'one position per name \(2\), got 1'),
    (['left', 'boom_cyl'], [], [], r'one position per name \(2\), got 0'),
    (['left', 'boom_cyl'], [math.nan, 1.5], [], "finite position of 'left', got nan"),
    (['left', 'boom_cyl'], [0.0, math.inf], [], "finite position of 'boom_cyl', got inf"),
    (['left', 'boom_cyl'], [0.0, 1.5], [1.0], r'no velocity or one per name \(2\), got 1'),
    (['left', 'boom_cyl'], [0.0, 1.5], [1.0, 2.0, 3.0], 'got 3'),
    (['left', 'boom_cyl'], [0.0, 1.5], [-math.inf, 0.0], "finite velocity of 'left'"),
    (['left', 'boom_cyl'], [0.0, 1.9], [], r"'boom_cyl' within its stroke \[1, 1.8\] m, got 1.9"),
    (['left', 'boom_cyl'], [0.0, 0.999], [], 'within its stroke'),
])
def test_bad_messages_are_refused_with_their_reason(names, positions, velocities, match):
    """Unknown, missing or repeated names, bad arrays, NaN/inf and off-stroke lengths."""
    refused(TopicDrive(TWO), 1, 0, names, positions, velocities, match=match)


def test_stroke_limits_are_inclusive():
    """A length at either stroke limit is accepted."""
    drive = TopicDrive(TWO)
    assert drive.read(1, 0, ['left', 'boom_cyl'], [0.0, 1.0], []).positions == (0.0, 1.0)
    assert drive.read(2, 0, ['left', 'boom_cyl'], [0.0, 1.8], []).positions == (0.0, 1.8)


def test_stamps_must_increase_after_a_published_state():
    """An earlier or equal stamp than the last published one is refused; a later one is read."""
    drive = TopicDrive(TWO)
    args = (['left', 'boom_cyl'], [0.0, 1.5], [])
    drive.published(drive.read(5, 10, *args).stamp_ns)
    refused(drive, 5, 9, *args, match=r'after the last published one \(5.000000010 s\), got '
            r'5.000000009 s, 1 ns earlier \(earlier by more than stamp_jump_back_s, 1 s, resets '
            r'the order\)$')
    refused(drive, 5, 10, *args, match='got the same stamp again')
    assert drive.read(5, 11, *args).stamp_ns == 5 * NS + 11


def test_a_refused_or_unpublished_message_does_not_move_the_last_stamp():
    """Only published states count: a message read but not published leaves the bound."""
    drive = TopicDrive(TWO)
    args = (['left', 'boom_cyl'], [0.0, 1.5], [])
    drive.read(9, 0, *args)         # read, then (say) the mechanism did not assemble
    assert drive.read(8, 0, *args).stamp_ns == 8 * NS
    assert drive.last_stamp_ns is None


@pytest.mark.parametrize('sec, nanosec', [(0, 0), (-1, 999_999_999)])
def test_a_zero_or_negative_stamp_is_refused(sec, nanosec):
    """A message never stamped (0) cannot stamp the state; say to stamp it."""
    refused(TopicDrive(TWO), sec, nanosec, ['left', 'boom_cyl'], [0.0, 1.5], [],
            match='header.stamp set to the instant of the positions')


@given(st.permutations(range(2)), st.floats(-10, 10), st.floats(1.0, 1.8),
       st.one_of(st.none(), st.tuples(st.floats(-1e3, 1e3), st.floats(-1e3, 1e3))))
def test_any_order_of_a_good_message_reads_the_same(order, angle, length, speeds):
    """Permuting the message's entries never changes what is read."""
    names = ['left', 'boom_cyl']
    positions = [angle, length]
    velocities = [] if speeds is None else list(speeds)
    permuted = ([names[i] for i in order], [positions[i] for i in order],
                [velocities[i] for i in order] if velocities else [])
    got = TopicDrive(TWO).read(3, 4, *permuted)
    assert got == TopicInput(3 * NS + 4, (angle, length),
                             None if speeds is None else tuple(speeds))


def test_one_far_future_stamp_does_not_end_the_stream():
    """Issue 33: after a state stamped 2^31 - 1 s, an ordinary stamp resets the order.

    It was refused as "not after the last published one", and so was every later
    message. A stamp more than stamp_jump_back_s (1 s) before the last is read, says
    the stamp it jumped back from, and once published is the new bound.
    """
    drive = TopicDrive(TWO)
    args = (['left', 'boom_cyl'], [0.0, 1.5], [])
    drive.published(drive.read(1_700_000_000, 0, *args).stamp_ns)
    wild = drive.read(2**31 - 1, 0, *args)
    assert wild.jumped_from_ns is None
    drive.published(wild.stamp_ns)
    back = drive.read(1_700_000_001, 0, *args)
    assert back == TopicInput(1_700_000_001 * NS, (0.0, 1.5), None, jumped_from_ns=FAR_FUTURE)
    drive.published(back.stamp_ns)
    assert drive.last_stamp_ns == 1_700_000_001 * NS
    later = drive.read(1_700_000_001, 10_000_000, *args)
    assert later.jumped_from_ns is None and later.stamp_ns == 1_700_000_001 * NS + 10_000_000


@pytest.mark.parametrize('earlier_ns, refused_as', [
    (0, 'got the same stamp again'),
    (1, '1 ns earlier'),
    (NS, f'{NS} ns earlier'),                   # exactly the bound: still out of order
])
def test_a_stamp_earlier_by_at_most_the_bound_is_still_refused(earlier_ns, refused_as):
    """Earlier than the last published stamp by 0 (equal), 1 ns or exactly 1 s: out of order."""
    drive = TopicDrive(TWO)
    args = (['left', 'boom_cyl'], [0.0, 1.5], [])
    drive.published(drive.read(100, 0, *args).stamp_ns)
    stamp = 100 * NS - earlier_ns
    refused(drive, *divmod(stamp, NS), *args, match=refused_as)
    assert drive.last_stamp_ns == 100 * NS
    beyond = 100 * NS - NS - 1                  # 1 ns beyond the bound: a jump back
    assert drive.read(*divmod(beyond, NS), *args).jumped_from_ns == 100 * NS


def test_the_jump_back_bound_is_a_parameter():
    """jump_back_ns=0 resets on any earlier stamp; an equal stamp is still refused."""
    drive = TopicDrive(TWO, jump_back_ns=0)
    args = (['left', 'boom_cyl'], [0.0, 1.5], [])
    drive.published(drive.read(100, 5, *args).stamp_ns)
    refused(drive, 100, 5, *args, match='the same stamp again')
    assert drive.read(100, 4, *args).jumped_from_ns == 100 * NS + 5
    drive.jump_back_ns = 3600 * NS
    refused(drive, 99, 0, *args, match=r'stamp_jump_back_s, 3600 s, resets the order')


def test_a_jumped_back_message_refused_for_another_reason_resets_nothing():
    """Only a published state moves the bound: a jump back that cannot be read leaves it."""
    drive = TopicDrive(TWO)
    drive.published(FAR_FUTURE)
    refused(drive, 10, 0, ['left', 'boom_cyl'], [0.0, 9.0], [], match='within its stroke')
    assert drive.last_stamp_ns == FAR_FUTURE


@pytest.mark.parametrize('kwargs, match', [
    ({'extra_joints': 'keep'}, "extra_joints in .*, got 'keep'"),
    ({'jump_back_ns': -1}, 'jump_back_ns >= 0, got -1'),
])
def test_bad_settings_are_refused(kwargs, match):
    """An extra_joints mode outside refuse|ignore|pass or a negative bound is a ValueError."""
    with pytest.raises(ValueError, match=match):
        TopicDrive(TWO, **kwargs)


#: A robot's whole /joint_states: the two drivers among its other joints, in its order.
ROBOT = (['wrist', 'left', 'gripper', 'boom_cyl', 'coupler'],
         [0.3, 0.5, math.nan, 1.5, 0.7], [0.1, -2.0, 0.0, 0.4, 0.2])


def test_extra_joints_ignore_takes_the_drivers_and_says_which_were_dropped():
    """With ignore the drivers are read as if alone; the others are listed, whatever they hold."""
    got = TopicDrive(TWO, extra_joints=IGNORE).read(3, 0, *ROBOT)
    assert got == TopicInput(3 * NS, (0.5, 1.5), (-2.0, 0.4),
                             ignored=('wrist', 'gripper', 'coupler'))
    assert got.passed is None


def test_extra_joints_pass_passes_the_others_after_the_mechanisms_joints():
    """With pass the other joints go to joint_states unchanged, after the mechanism's joints.

    A joint the node publishes itself ('coupler', computed) is not passed twice: it
    is ignored. Velocities are passed when the message has them, efforts likewise,
    NaN (unknown) for the mechanism's joints.
    """
    drive = TopicDrive(TWO, extra_joints=PASS, published_joints=('left', 'coupler', 'boom'))
    efforts = [5.0, 6.0, 7.0, 8.0, 9.0]
    got = drive.read(3, 0, *ROBOT, efforts)
    assert got.ignored == ('coupler',)
    assert got.passed.names == ('wrist', 'gripper')
    np.testing.assert_array_equal(got.passed.positions, (0.3, math.nan))
    assert got.passed.velocities == (0.1, 0.0) and got.passed.efforts == (5.0, 7.0)
    values = [1.0, 2.0, 3.0, 10.0, 20.0, 30.0, 7.0, 7.0, 7.0]     # p, v, a of the three
    names, positions, velocities, effort = drive.joint_state_arrays(got, values)
    assert names == ['left', 'coupler', 'boom', 'wrist', 'gripper']
    np.testing.assert_array_equal(positions, [1.0, 2.0, 3.0, 0.3, math.nan])
    assert velocities == [10.0, 20.0, 30.0, 0.1, 0.0]
    np.testing.assert_array_equal(effort, [math.nan] * 3 + [5.0, 7.0])
    # Positions only: no velocity anywhere, no effort.
    got = drive.read(4, 0, ROBOT[0], ROBOT[1], [])
    assert got.passed == PassedJoints(('wrist', 'gripper'), got.passed.positions, None, None)
    assert drive.joint_state_arrays(got, values)[2:] == ([], [])


def test_extra_joints_pass_checks_the_effort_array():
    """With pass, an effort array neither empty nor one per name is refused (not passable)."""
    drive = TopicDrive(TWO, extra_joints=PASS)
    refused(drive, 3, 0, *ROBOT, [1.0, 2.0],
            match=r'no effort or one per name \(5\), got 2 \(extra_joints: pass passes them')
    assert TopicDrive(TWO).read(3, 0, ['left', 'boom_cyl'], [0.5, 1.5], [], [1.0]).passed is None


@pytest.mark.parametrize('mode', [IGNORE, PASS])
def test_extra_joints_do_not_excuse_the_drivers(mode):
    """With ignore or pass, a missing driver, a repeated name or a NaN driver is refused."""
    drive = TopicDrive(TWO, extra_joints=mode)
    refused(drive, 1, 0, ['left', 'wrist'], [0.0, 1.0], [], match="got none for 'boom_cyl'")
    refused(drive, 1, 0, ['left', 'boom_cyl', 'wrist', 'wrist'], [0.0, 1.5, 1.0, 1.0], [],
            match="'wrist' twice")
    refused(drive, 1, 0, ['wrist', 'left', 'boom_cyl'], [0.0, math.nan, 1.5], [],
            match="finite position of 'left'")
    refused(drive, 1, 0, ['wrist', 'left', 'boom_cyl'], [0.0, 0.5], [],
            match=r'one position per name \(3\), got 2')
