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
- ABB IRB 2400-12/1.55: ros-industrial/abb at
  77db19bdb098f50d9569d1cab03ee657627e934e,
  ``abb_irb2400_support/urdf/irb2400_12_155_macro.xacro`` (xacro expanded,
  no meshes, no base or tool0 frame); Apache License 2.0 (its package.xml),
  author Dan Solomon, Southwest Research Institute. Its parallel arm (levers
  a and b, faked with ``<mimic>`` joints of joint_3) closed by a
  ``loop_closures.yaml`` written here.
- FANUC M-900iA/260L: ros-industrial/fanuc at
  8fee5e30e535378758ace26dfdffb8ab0403e23c,
  ``fanuc_m900ia_support/urdf/m900ia260l_macro.xacro`` (xacro expanded, no
  meshes, no base, flange or tool0 frame); BSD 3-Clause, Copyright (c)
  2012-2015, TU Delft Robotics Institute. Its parallel bar linkage (plink_1
  and plink_2, faked with ``<mimic>`` joints of joint_3) closed likewise.
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
#: Step of the central differences (s) and what O(h^2) allows at it (relative to the rate).
H_DIFFERENCE = 1e-4
RTOL_DIFFERENCE = 1e-6
GRIPPERS = ['robotiq_2f_85', 'robotiq_2f_140']
ARMS = ['abb_irb2400_12_155', 'fanuc_m900ia260l']
#: Per robot, the actuated joint that drives its loops and the range swept (rad): the
#: grippers' strokes; the ABB's joint_3 <limit>; the FANUC's joint_3 kept 0.07 rad inside
#: its parallelogram's change points at +-pi/2, which its <limit> reaches (see below).
SWEEPS = {'robotiq_2f_85': ('finger_joint', 0.0, 0.7),
          'robotiq_2f_140': ('finger_joint', 0.0, 0.7),
          'abb_irb2400_12_155': ('joint_3', -1.0472, 1.1345),
          'fanuc_m900ia260l': ('joint_3', -1.5, 1.5)}
REAL = GRIPPERS + ARMS


def _real(name, reference=None):
    """Return a real robot of test/data/urdf, read by us and by ``UrdfFk``."""
    urdf, closures = DATA / f'{name}.urdf', DATA / f'{name}.loop_closures.yaml'
    return (load_robot(urdf, closures, reference=reference),
            UrdfFk(urdf.read_text(), closures))


def _states(robot, name, count, seed=31):
    """Yield ``count`` (positions, speeds, accels) of the actuated joints over the sweep.

    The joint that drives the loops steps through its range; every other
    actuated joint (an arm's five other axes, which carry the loop in space)
    takes a random position, and every actuated joint a random rate.
    """
    joint, low, high = SWEEPS[name]
    rng = np.random.default_rng(seed)
    for q in np.linspace(low, high, count):
        positions = {n: float(q) if n == joint else float(rng.uniform(-1.0, 1.0))
                     for n in robot.actuated}
        speeds = {n: float(rng.uniform(-2.0, 2.0)) for n in robot.actuated}
        accels = {n: float(rng.uniform(-5.0, 5.0)) for n in robot.actuated}
        yield positions, speeds, accels


@pytest.mark.parametrize('name', REAL)
def test_a_real_robot_closes_every_loop_in_its_own_kinematics(name):
    """Over its sweep the joints we answer close every loop within 1e-12 of its size."""
    robot, fk = _real(name)
    worst = 0.0
    checked = 0
    for positions, speeds, accels in _states(robot, name, 15):
        answer = robot.solve(positions, speeds, accels)
        values = {n: j.position for n, j in answer.joints.items()}
        assert set(positions) <= set(values)   # the joints outside the loops carry them
        gaps = fk.gaps(values)
        assert len(gaps) == len(robot.planar.mechanisms)   # one closure per loop, each checked
        for closure, gap in gaps.items():
            worst = max(worst, gap / fk.loop_size(closure))
        # The rates keep the loops closed: the pose moved by h along them misses by O(h^3).
        moved = {n: j.position + H * j.velocity + 0.5 * H * H * j.acceleration
                 for n, j in answer.joints.items()}
        size = max(fk.loop_size(c) for c in gaps)
        assert max(fk.gaps(moved).values()) <= 50 * H ** 3 * size
        checked += 1
    assert checked == 15
    assert worst <= RTOL_CLOSURE


@pytest.mark.parametrize('name', REAL)
def test_a_real_robots_rates_match_central_differences_of_its_positions(name):
    """Every joint's velocity and acceleration against central differences (h = 1e-4 s).

    The actuated joints move as p + v t + a t^2 / 2; the differences of the
    positions we answer at t = -h, 0, h match our rates to O(h^2).
    """
    robot, _ = _real(name)
    passive = [n for n in robot.joint_names if n not in robot.actuated]
    assert passive
    h = H_DIFFERENCE
    for p, v, a in _states(robot, name, 5, seed=7):
        now, before, after = (robot.solve({n: p[n] + t * v[n] + 0.5 * t * t * a[n] for n in p},
                                          {n: v[n] + t * a[n] for n in p}, a)
                              for t in (0.0, -h, h))
        for joint in passive:
            q = np.unwrap([s.joints[joint].position for s in (before, now, after)])
            motion = now.joints[joint]
            scale = 1 + abs(motion.velocity) + abs(motion.acceleration)
            assert (q[2] - q[0]) / (2 * h) == pytest.approx(motion.velocity,
                                                            abs=RTOL_DIFFERENCE * scale)
            assert (q[2] - 2 * q[1] + q[0]) / h ** 2 == pytest.approx(motion.acceleration,
                                                                      abs=1e-3 * scale)


@pytest.mark.parametrize('name', GRIPPERS)
def test_a_mimic_of_the_motor_drives_the_other_finger_and_the_loops_keep_the_rules(name):
    """The right outer knuckle mimics finger_joint (a loop's input); inner mimics do not stray."""
    robot, _ = _real(name)
    assert robot.actuated == ('finger_joint',)
    assert set(robot.joint_names) == {
        'finger_joint', 'right_outer_knuckle_joint', 'left_inner_knuckle_joint',
        'left_inner_finger_joint', 'right_inner_knuckle_joint', 'right_inner_finger_joint'}
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
    robot, _ = _real('robotiq_2f_85')
    answer = robot.solve({'finger_joint': 0.3})
    assert set(answer.limits) == {'left_inner_finger_joint', 'right_inner_finger_joint'}
    assert answer.limits['left_inner_finger_joint']['position'] == pytest.approx(-0.3,
                                                                                 abs=1e-12)


@pytest.mark.parametrize('name', ARMS)
def test_an_arms_parallelogram_hangs_on_link_2_and_keeps_its_mimic_rules(name):
    """Its loop's ground is link_2, joint_3 its crank; the levers keep their rules in bounds.

    Joints 1 and 2 carry the loop in space and pass through as given, like
    joints 4 to 6; the two levers, mimic joints of joint_3 in the URDF, are
    solved by the loop and match their rules (multiplier +-1) in position,
    velocity and acceleration within the error bounds the answer publishes.
    """
    robot, _ = _real(name)
    (loop,) = robot.planar.mechanisms
    assert loop['ground'] == 'link_2'
    assert [d.name for d in robot.planar.drivers] == ['joint_3']
    levers = [n for n in robot.joint_names if n not in robot.actuated]
    assert len(levers) == 2
    for positions, speeds, accels in _states(robot, name, 9):
        answer = robot.solve(positions, speeds, accels)
        assert answer.mimic == {}
        for n in robot.actuated:
            assert answer.joints[n].position == positions[n]
        for n in levers:
            rule = robot.description.joints[n].mimic
            assert rule.joint == 'joint_3'
            motion = answer.joints[n]
            bound = answer.bounds[n]
            exact = (rule.multiplier * positions['joint_3'] + rule.offset,
                     rule.multiplier * speeds['joint_3'], rule.multiplier * accels['joint_3'])
            for got, want, allowed in zip((motion.position, motion.velocity,
                                           motion.acceleration), exact, bound, strict=True):
                assert abs(got - want) <= allowed


def test_the_fanucs_joint_3_limit_reaches_past_its_parallelograms_change_point():
    """Its joint_3 <limit> reaches the parallelogram folded flat (+-pi/2 from link_2).

    At 1.570796 (its upper limit, 3.3e-7 rad from the fold) moving at
    1 rad/s the solver refuses in one line (its rates cannot be trusted); at
    -1.8 (past the fold, inside the limit) the loop answers the assembly its
    levers' <mimic> rules pick (issue 43, item 5: the parallelogram, closed,
    no stray; the zero pose's branch alone was a crossed parallelogram whose
    levers strayed by more than 0.1 rad); a reference pose past the fold
    answers the same down to the lower limit.
    """
    robot, fk = _real('fanuc_m900ia260l')
    assert robot.description.joints['joint_3'].limits == (-2.116665, 1.570796)
    with pytest.raises(mk.AssemblyError) as caught:
        robot.solve({'joint_3': 1.570796}, {'joint_3': 1.0})
    message = str(caught.value)
    assert '\n' not in message and 'closure_0' in message and 'cannot be trusted' in message
    # Where: the URDF's actuated joint and its value, not the scene's driver it maps to.
    assert ' at joint_3 = 1.5708 rad: ' in message and 'crank angle' not in message
    answer = robot.solve({'joint_3': -1.8})
    values = {n: j.position for n, j in answer.joints.items()}
    assert fk.gaps(values)['closure_0'] <= RTOL_CLOSURE * fk.loop_size('closure_0')
    assert answer.mimic == {}
    scene, ruled = robot.scene, robot.assemblies.ruled     # the zero pose's branch alone
    robot.assemblies.ruled = ()
    try:
        crossed = robot.solve({'joint_3': -1.8})
    finally:
        robot.assemblies.ruled = ruled
    assert robot.scene is scene and set(crossed.mimic) == {'pjoint_1', 'pjoint_2'}
    assert all(abs(item['stray']) > 0.1 for item in crossed.mimic.values())
    past, _ = _real('fanuc_m900ia260l', reference={'joint_3': -1.8})
    for q in (-1.8, -2.116665):
        answer = past.solve({'joint_3': q})
        values = {n: j.position for n, j in answer.joints.items()}
        assert fk.gaps(values)['closure_0'] <= RTOL_CLOSURE * fk.loop_size('closure_0')
        assert answer.mimic == {}


#: Per robot, what `solve` is given (degrees): the loops' driver and, on an arm, the axes
#: that carry its loop in space.
CLI_INPUTS = {'robotiq_2f_85': ['finger_joint=20'], 'robotiq_2f_140': ['finger_joint=20'],
              'abb_irb2400_12_155': ['joint_1=30', 'joint_2=-15', 'joint_3=20'],
              'fanuc_m900ia260l': ['joint_1=30', 'joint_2=-15', 'joint_3=20']}


@pytest.mark.parametrize('name', REAL)
def test_solve_on_a_real_robot_prints_joints_that_close_its_loops(name, capsys):
    """`solve ROBOT.urdf --closures ... --input J=DEG` prints joints closing every loop.

    The printed positions close every loop in the URDF's own forward
    kinematics within 1e-12 of its size, and each mimic joint the loops solve
    sits on its rule (the 2F-85's left inner knuckle at finger_joint's 20 deg).
    """
    import json
    import xml.etree.ElementTree as ET
    urdf = DATA / f'{name}.urdf'
    closures = DATA / f'{name}.loop_closures.yaml'
    args = ['solve', str(urdf), '--closures', str(closures)]
    for given in CLI_INPUTS[name]:
        args += ['--input', given]
    assert cli_main(args) == 0
    data = json.loads(capsys.readouterr().out)
    fk = UrdfFk(urdf.read_text(), closures)
    assert data['robot'] == ET.fromstring(urdf.read_text()).get('name')
    positions = {n: j['position'] for n, j in data['joints'].items()}
    for given in CLI_INPUTS[name]:
        joint, degrees = given.split('=')
        assert positions[joint] == math.radians(float(degrees))
    for closure, gap in fk.gaps(positions).items():
        assert gap <= RTOL_CLOSURE * fk.loop_size(closure)
    assert 'mimic' not in data
    for joint, (_, _, _, _, _, rule) in fk.joints.items():
        if rule is not None and joint in positions:
            leader, multiplier, offset = rule
            assert positions[joint] == pytest.approx(multiplier * positions[leader] + offset,
                                                     abs=1e-12)


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
