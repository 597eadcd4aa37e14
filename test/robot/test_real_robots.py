# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Public robots described in URDF, solved and checked with their own kinematics. Issue 31.

Fixtures in test/data/urdf (README.md there has each one's provenance, the
part written here and the licence text):

- Robotiq 2F-85 and 2F-140 grippers: ros-industrial/robotiq at
  45196f6558fe8ba9d89bc8a105396c68c3e7e892,
  ``robotiq_2f_85_gripper_visualization/urdf/robotiq_arg2f_85_model_macro.xacro``
  and ``robotiq_2f_140_gripper_visualization/urdf/robotiq_arg2f_140_model_macro.xacro``
  (xacro expanded by hand, no meshes); BSD 3-Clause, Copyright (c) 2013,
  ROS-Industrial. Their loops (faked with ``<mimic>`` joints in the URDF)
  closed by a ``loop_closures.yaml`` written here.
- Minitaur's front left leg: bulletphysics/bullet3 at
  00361afea58c67592bffa79d2aeceebb87c8ba2a, ``data/quadruped/minitaur.urdf``,
  cut to one leg; BSD 2-Clause style, Copyright (c) 2017, Erwin Coumans,
  Google Inc. Its closure, PyBullet's knee constraint points, added as a
  ``<constraint type="spherical">``.

The check does not trust our decomposition: ``UrdfFk`` (test/helpers.py)
reads the same files with xml.etree and closes each loop with 4x4 transforms.
"""

import math
from pathlib import Path

from helpers import UrdfFk
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.__main__ import main as cli_main
from mech_kinematics.errors import UrdfError
from mech_kinematics.robot import load_robot

DATA = Path(__file__).resolve().parents[1] / 'data' / 'urdf'
#: A loop closes within this, over its size (the contract's exactness).
RTOL_CLOSURE = 1e-12
#: Step of the extrapolation (s): a pose moved by our rates misses closure by O(h^3).
H = 1e-3
GRIPPERS = ['robotiq_2f_85', 'robotiq_2f_140']


def _gripper(name):
    urdf, closures = DATA / f'{name}.urdf', DATA / f'{name}.loop_closures.yaml'
    return load_robot(urdf, closures), UrdfFk(urdf.read_text(), closures)


@pytest.mark.parametrize('name', GRIPPERS)
def test_a_gripper_closes_both_fingers_in_its_own_kinematics(name):
    """Over its stroke the joints we answer close both finger loops within 1e-12 of their size."""
    robot, fk = _gripper(name)
    assert robot.actuated == ('finger_joint',)
    assert set(robot.joint_names) == {
        'finger_joint', 'right_outer_knuckle_joint', 'left_inner_knuckle_joint',
        'left_inner_finger_joint', 'right_inner_knuckle_joint', 'right_inner_finger_joint'}
    worst = 0.0
    for q in np.linspace(0.0, 0.7, 15):
        answer = robot.solve({'finger_joint': float(q)}, {'finger_joint': 1.5},
                             {'finger_joint': -4.0})
        values = {n: j.position for n, j in answer.joints.items()}
        for closure, gap in fk.gaps(values).items():
            worst = max(worst, gap / fk.loop_size(closure))
        # The rates keep the loops closed: the pose moved by h along them misses by O(h^3).
        moved = {n: j.position + H * j.velocity + 0.5 * H * H * j.acceleration
                 for n, j in answer.joints.items()}
        assert max(fk.gaps(moved).values()) <= 50 * H ** 3 * 0.1
    assert worst <= RTOL_CLOSURE


@pytest.mark.parametrize('name', GRIPPERS)
def test_a_mimic_of_the_motor_drives_the_other_finger_and_the_loops_keep_the_rules(name):
    """The right outer knuckle mimics finger_joint (a loop's input); inner mimics do not stray."""
    robot, _ = _gripper(name)
    rule = robot.description.joints['right_outer_knuckle_joint'].mimic
    answer = robot.solve({'finger_joint': 0.4}, {'finger_joint': 2.0})
    right = answer.joints['right_outer_knuckle_joint']
    assert right.position == rule.multiplier * 0.4 + rule.offset
    assert right.velocity == rule.multiplier * 2.0
    assert answer.mimic == {}    # the parallelograms keep the exporter's +-1 rules
    for side in ('left', 'right'):
        for part in ('inner_knuckle_joint', 'inner_finger_joint'):
            joint = robot.description.joints[f'{side}_{part}']
            expected = joint.mimic.multiplier * 0.4 + joint.mimic.offset
            assert answer.joints[joint.name].position == pytest.approx(expected, abs=1e-12)


def test_the_2f_85s_limits_disagree_with_its_mimic_rules_and_are_reported():
    """Its inner fingers' [0, 0.8757] against multiplier -1: reported under limits, solved."""
    robot, _ = _gripper('robotiq_2f_85')
    answer = robot.solve({'finger_joint': 0.3})
    assert set(answer.limits) == {'left_inner_finger_joint', 'right_inner_finger_joint'}
    assert answer.limits['left_inner_finger_joint']['position'] == pytest.approx(-0.3,
                                                                                 abs=1e-12)


def test_solve_on_a_real_gripper_prints_its_joints(capsys):
    """`solve robotiq_2f_85.urdf --closures ... --input finger_joint=20` answers in JSON."""
    import json
    urdf = DATA / 'robotiq_2f_85.urdf'
    closures = DATA / 'robotiq_2f_85.loop_closures.yaml'
    assert cli_main(['solve', str(urdf), '--closures', str(closures), '--input',
                     'finger_joint=20']) == 0
    data = json.loads(capsys.readouterr().out)
    assert data['joints']['left_inner_knuckle_joint']['position'] == pytest.approx(
        math.radians(20), abs=1e-12)
    assert data['robot'] == 'robotiq_arg2f_85_model'


def test_minitaurs_leg_is_refused_as_not_planar_naming_the_joint():
    """pi/2 written 1.57075 and pi 3.141592: its axes are 9.3e-5 rad apart, refused in one line."""
    with pytest.raises(UrdfError) as caught:
        load_robot(DATA / 'minitaur_leg.urdf',
                   actuated=['motor_front_leftR_joint', 'motor_front_leftL_joint'])
    message = str(caught.value)
    assert '\n' not in message
    assert caught.value.joint == 'motor_front_leftL_joint'
    assert 'off it by 9.27e-05 rad' in message and 'not planar' in message


def test_urdf2scene_writes_a_real_gripper_as_a_scene(tmp_path):
    """The 2F-140's scene loads; its cranks and RRRs carry the URDF's names."""
    out = tmp_path / 'gripper.yaml'
    assert cli_main(['urdf2scene', str(DATA / 'robotiq_2f_140.urdf'), '--closures',
                     str(DATA / 'robotiq_2f_140.loop_closures.yaml'), '-o', str(out)]) == 0
    scene = mk.load_scene(out)
    assert [d.name for d in scene.drivers] == ['left_outer_knuckle', 'right_outer_knuckle']
    assert {d.point for d in scene.dyads} == {'closure_0', 'closure_1'}
