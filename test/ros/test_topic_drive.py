# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The rules of ``drive: topic`` for one input message, without ROS. See issue 18."""

from dataclasses import dataclass
import math

from hypothesis import given, strategies as st
import pytest

import mech_kinematics as mk
from mech_kinematics.ros.topic_drive import RefusedInput, TopicDrive, TopicInput

NS = 1_000_000_000


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
    (['left', 'boom_cyl', 'wrist'], [0.0, 1.5, 2.0], [], r"unknown joint\(s\) 'wrist'"),
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
            r'5.000000009 s, 1 ns earlier')
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
