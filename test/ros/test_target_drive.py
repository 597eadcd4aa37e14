# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``drive: target``'s rules (issue 41), without ROS: targets in, the drivers that reach them out.

Checked against the forward solve of the drivers found (the targets come back)
and against the topic drive's rules (the stamp's order), each refusal one line
naming ``input_targets``.
"""

from __future__ import annotations

import math
from pathlib import Path
import re

from helpers import gepetto_five_bar_reference
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.robot import load_robot
from mech_kinematics.robot.targets import frame_motion
from mech_kinematics.ros.robot_mode import RobotValues
from mech_kinematics.ros.target_drive import (robot_target_drive, scene_target_drive,
                                              target_branch)
from mech_kinematics.ros.topic_drive import RefusedInput

pytestmark = pytest.mark.filterwarnings('ignore::mech_kinematics.NearSingularWarning')

FIVE = mk.load_scene('five_bar')


def drive():
    return scene_target_drive(FIVE, 1e-6, published_joints=FIVE.output_joints)


def test_a_stream_of_targets_gives_the_drivers_that_reach_them():
    """P along a line at 0.1 m/s: each answer's forward solve puts P there, at that speed."""
    rules = drive()
    for k in range(5):
        p = [0.06 + 0.001 * k, 0.22]
        given = rules.read(100, k * 1_000_000, ['P.x', 'P.y'], p, [0.1, 0.0])
        state = mk.solve(FIVE, list(given.positions), list(given.speeds), [0.0, 0.0])
        np.testing.assert_allclose(state.points['P'].position, p, atol=1e-15)
        np.testing.assert_allclose(state.points['P'].velocity, [0.1, 0.0], atol=1e-15)
        rules.published(given.stamp_ns)
        assert rules.start == list(given.positions)
    # Without velocities the speeds are unknown (left out), as with drive: topic.
    given = rules.read(101, 0, ['P.y', 'P.x'], [0.22, 0.06], [])
    assert given.speeds is None
    state = mk.solve(FIVE, list(given.positions), [0.0, 0.0], [0.0, 0.0])
    np.testing.assert_allclose(state.points['P'].position, [0.06, 0.22], atol=1e-15)


def test_the_working_mode_is_continued_from_the_last_state():
    """Two paths to one target from two start poses answer their own modes' drivers."""
    rules = drive()
    here = rules.read(100, 0, ['P.x', 'P.y'], [0.06, 0.22], [])
    rules.published(here.stamp_ns)
    inverse = mk.solve_targets(FIVE, {'P.x': 0.06, 'P.y': 0.22})
    assert list(here.positions) == [float(x) for x in inverse.motion[:, 0]]
    # The left leg's other elbow: the crank angles where |B - P| = 160 mm, |B - A| = 120 mm.
    d = math.hypot(0.06, 0.22)
    half = math.acos((0.12 ** 2 + d ** 2 - 0.16 ** 2) / (2 * 0.12 * d))
    elbows = (math.atan2(0.22, 0.06) + half, math.atan2(0.22, 0.06) - half)
    assert here.positions[0] == pytest.approx(elbows[0], abs=1e-12)
    other = scene_target_drive(FIVE, 1e-6, published_joints=FIVE.output_joints)
    other.start = [elbows[1] + 0.05, here.positions[1] - 0.05]
    again = other.read(100, 0, ['P.x', 'P.y'], [0.06, 0.22], [])
    assert again.positions[0] == pytest.approx(elbows[1], abs=1e-12)
    state = mk.solve(FIVE, list(again.positions), [0.0, 0.0], [0.0, 0.0])
    np.testing.assert_allclose(state.points['P'].position, [0.06, 0.22], atol=1e-15)


@pytest.mark.parametrize(('names', 'positions', 'velocities', 'words'), [
    (['P.x'], [0.06], [], 'as many targets as the scene has drivers'),
    (['P.x', 'P.q'], [0.06, 0.2], [], "got 'P.q'"),
    (['P.x', 'P.y'], [0.06], [], 'one position per target'),
    (['P.x', 'P.y'], [0.06, 0.22], [0.1], 'no velocity or one per target'),
    (['P.x', 'P.y'], [0.06, math.nan], [], "finite position of target 'P.y'"),
    (['P.x', 'P.y'], [0.06, 0.42], [], 'out of reach'),
    (['P.x', 'P.x'], [0.06, 0.22], [], 'each target once'),
])
def test_bad_messages_are_refused_in_one_line(names, positions, velocities, words):
    rules = drive()
    with pytest.raises(RefusedInput, match=words) as caught:
        rules.read(100, 0, names, positions, velocities)
    assert caught.value.reason.startswith('input_targets: ')
    assert '\n' not in caught.value.reason
    assert rules.start == [d.start for d in FIVE.drivers]    # nothing moved


def test_the_stamp_rules_are_the_topic_drives():
    rules = drive()
    given = rules.read(100, 0, ['P.x', 'P.y'], [0.06, 0.22], [])
    rules.published(given.stamp_ns)
    with pytest.raises(RefusedInput, match='input_targets: expected a stamp after'):
        rules.read(100, 0, ['P.x', 'P.y'], [0.061, 0.22], [])


def test_target_branch_answers_every_message_in_the_mode_asked():
    """B and D both positive (not the start pose's mode): each answer is solve_targets' in it."""
    branch = target_branch(['B=+1', 'D=+'], 'target')
    assert branch == {'B': 1, 'D': 1}
    rules = scene_target_drive(FIVE, 1e-6, published_joints=FIVE.output_joints, branch=branch)
    start = [d.start for d in FIVE.drivers]
    for k in range(3):
        p = {'P.x': 0.06 + 0.002 * k, 'P.y': 0.22}
        given = rules.read(100, k * 1_000_000, list(p), list(p.values()), [])
        inverse = mk.solve_targets(FIVE, p, start=start, branch=branch)
        np.testing.assert_allclose(given.positions, inverse.motion[:, 0], rtol=0, atol=1e-12)
        assert all(angle > 0 for angle in inverse.branch.values())
        rules.published(given.stamp_ns)
        start = list(given.positions)
    plain = mk.solve_targets(FIVE, {'P.x': 0.06, 'P.y': 0.22})
    assert not np.allclose(plain.motion[:, 0], inverse.motion[:, 0], atol=1e-3)


@pytest.mark.parametrize('entries, drive, words', [
    (['B=+1'], 'time', 'target_branch: Expected drive: target or trajectory'),
    (['B=2'], 'target', 'target_branch: expected JOINT=+1 or JOINT=-1 (the sign of the '
                        "joint's angle), got 'B=2'"),
    (['B=+1', 'B=-1'], 'trajectory', 'target_branch: expected each joint once, got B twice'),
])
def test_target_branch_refused_in_one_line(entries, drive, words):
    with pytest.raises(ValueError, match='^' + re.escape(words)):
        target_branch(entries, drive)
    assert target_branch([], 'time') is None


def test_target_branch_names_a_joint_between_two_moving_links():
    with pytest.raises(mk.TargetError, match=r'Expected target_branch to name joints between '
                                             r'two moving bodies \(.*B.*\), got A'):
        scene_target_drive(FIVE, 1e-6, published_joints=FIVE.output_joints, branch={'A': 1})


def test_target_branch_on_a_urdf_robot_reads_its_loop_joints():
    """Gepetto's five-bar by its effector, free1 asked positive: Robot.solve_targets' answer."""
    data = Path(__file__).resolve().parents[1] / 'data' / 'urdf'
    robot = load_robot(data / 'gepetto_5bar_linkage.urdf',
                       data / 'gepetto_5bar_linkage.robot.yaml',
                       reference=gepetto_five_bar_reference())
    drivers = RobotValues(robot, robot.scene.output_joints, robot.scene.output_points).drivers
    rules = robot_target_drive(robot, drivers, 1e-6, published_joints=robot.joint_names,
                               branch={'free1': 1})
    start = robot.solve(forces=False)
    assert start.joints['free1'].position < 0      # the reference pose's mode is the other
    d = robot.description
    p0 = frame_motion(d, 'effector', d.pose({n: float(j.position)
                                             for n, j in start.joints.items()}), {}, {}, 1.0)[0][0]
    goal = {'effector.y': float(p0[1]) + 0.02, 'effector.z': float(p0[2]) + 0.03}
    given = rules.read(100, 0, list(goal), list(goal.values()), [])
    inverse = robot.solve_targets(goal, branch={'free1': 1})
    assert inverse.answer.joints['free1'].position > 0
    np.testing.assert_allclose(given.positions, inverse.motion[:, 0], rtol=0, atol=1e-12)
    with pytest.raises(mk.TargetError, match='got mot1'):
        robot_target_drive(robot, drivers, 1e-6, published_joints=robot.joint_names,
                           branch={'mot1': 1})
