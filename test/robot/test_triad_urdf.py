# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A URDF whose loop needs a triad (issue 43): read, solved with bounds, closed in its own FK.

Before the triad, robot/planar.py refused the loop ("no dyad places links
link_e, link_f, rocker, coupler: a group of higher class (such as a triad)").
The URDF is the packaged Stephenson III written by ``urdf --robot``
(robot/writer.py): its tree cut at two pins closed by ``<constraint>``s.
"""

from pathlib import Path

from helpers import UrdfFk
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.robot.robot import load_robot
from mech_kinematics.robot.writer import robot_urdf_from_scene

SCENE_FILE = Path(__file__).resolve().parents[2] / 'config' / 'scenes' / 'stephenson_iii.yaml'
#: The loops' closure in the test's own 4x4 forward kinematics (m).
ATOL_GAP = 1e-12


@pytest.fixture(scope='module')
def urdf():
    """Return the Stephenson III as a URDF with <constraint> closures."""
    return robot_urdf_from_scene(mk.load_scene(SCENE_FILE))


@pytest.mark.parametrize('theta', [0.3, 2.0, -2.5, 4.5])
def test_the_triad_loop_closes_in_the_urdfs_own_kinematics(urdf, theta):
    """Every closure's frames coincide within 1e-12 m at the joint values answered."""
    robot = load_robot(urdf)
    assert robot.actuated == ('crank',)
    state = robot.solve({'crank': theta})
    values = {name: float(joint.position) for name, joint in state.joints.items()}
    gaps = UrdfFk(urdf).gaps(values)
    assert len(gaps) == 2 and max(gaps.values()) < ATOL_GAP, gaps


def test_the_urdf_answers_the_scenes_motion_with_bounds(urdf):
    """The coupler turns as the scene's (its URDF zero is the scene's start); bounds small."""
    robot = load_robot(urdf)
    scene = mk.load_scene(SCENE_FILE)
    for q in (0.0, 1.0, -2.0):
        state = robot.solve({'crank': q}, {'crank': 2.0})
        expected = mk.solve(scene, scene.input.angle + q, 2.0).joints['coupler']
        turned = state.state.joints['mechanism_coupler']  # (the URDF's link names)
        assert abs(turned.velocity - expected.velocity) < 1e-12 * max(1, abs(expected.velocity))
        assert abs(turned.acceleration - expected.acceleration) < 1e-11 * max(
            1, abs(expected.acceleration))
        bounds = np.array([b for joint in state.bounds.values() for b in joint])
        assert np.all(np.isfinite(bounds)) and bounds.max() < 1e-8  # rad, rad/s, rad/s^2 (~10)
