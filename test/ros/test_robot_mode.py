# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's URDF mode without ROS: what its parameters load, and a tick's URDF joints.

See issue 31. :class:`RobotValues` turns the values of the node's tick (the
scene's coordinates, compiled) into the URDF's joints; checked against
:meth:`Robot.solve` (the same bits) and against ``UrdfFk``, the independent
4x4 forward kinematics of test/helpers.py (every loop closed within 1e-12 of
its size).
"""

from pathlib import Path

from helpers import UrdfFk
import numpy as np
import pytest

from mech_kinematics.errors import SceneError, UrdfError
from mech_kinematics.ros.robot_mode import load_source, RobotValues
from mech_kinematics.ros.ticker import compiled_tick
from mech_kinematics.scene import DEFAULT_SCENE, scene_text
from mech_kinematics.solver.compiler import NotCompiled

DATA = Path(__file__).resolve().parents[1] / 'data' / 'urdf'
ROBOTS = ('robotiq_2f_85', 'robotiq_2f_140', 'abb_irb2400_12_155', 'fanuc_m900ia260l')
#: A loop closes within this, over its size (the contract's exactness).
RTOL_CLOSURE = 1e-12
#: Joint values (rad) the time path gives against the echoed input: the scene's rounding.
ATOL_ECHO = 1e-13


def _source(name):
    return load_source(str(DATA / f'{name}.urdf'),
                       loop_closures=str(DATA / f'{name}.loop_closures.yaml'))


def _inputs(robot, count, seed=31):
    """Return ``count`` sets of actuated positions and speeds near the reference pose."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        yield ([robot.start(n) + rng.uniform(-0.3, 0.3) for n in robot.actuated],
               [rng.uniform(-2.0, 2.0) for _ in robot.actuated])


def _tick(scene):
    tick = compiled_tick(scene, scene.output_joints, scene.output_points, ())
    assert not isinstance(tick, NotCompiled), tick.reason

    def solve(positions, speeds):
        n = len(positions)
        if n == 1:
            return tick(positions[0], speeds[0], 0.0, 1e-6, 0)[0]
        return tick(positions, speeds, [0.0] * n, 1e-6, [0] * n)[0]
    return solve


@pytest.mark.parametrize('name', ROBOTS)
def test_a_ticks_urdf_joints_are_robot_solves_to_the_bit(name):
    """From an input: the compiled tick's joints are Robot.solve's, bit for bit, in its order."""
    source = _source(name)
    robot, scene = source.robot, source.scene
    values = RobotValues(robot, scene.output_joints, scene.output_points)
    solve = _tick(scene)
    assert values.names == robot.joint_names
    assert [d.name for d in values.drivers] == list(robot.actuated)
    m = len(values.names)
    for positions, speeds in _inputs(robot, 20):
        answer = robot.solve(dict(zip(robot.actuated, positions, strict=True)),
                             dict(zip(robot.actuated, speeds, strict=True)))
        out = values.values(solve(*values.scene_inputs(positions, speeds)), (positions, speeds))
        assert out[:m] == [answer.joints[n].position for n in values.names]
        assert out[m:2 * m] == [answer.joints[n].velocity for n in values.names]


@pytest.mark.parametrize('name', ROBOTS)
def test_every_published_state_closes_every_loop_in_the_urdfs_own_kinematics(name):
    """Input and clock paths: UrdfFk closes every loop within 1e-12 of its size."""
    source = _source(name)
    robot, scene = source.robot, source.scene
    fk = UrdfFk((DATA / f'{name}.urdf').read_text(), DATA / f'{name}.loop_closures.yaml')
    values = RobotValues(robot, scene.output_joints, scene.output_points)
    solve = _tick(scene)
    m = len(values.names)
    worst = 0.0
    for positions, speeds in _inputs(robot, 20, seed=7):
        tick = solve(*values.scene_inputs(positions, speeds))
        for given in ((positions, speeds), None):
            out = values.values(tick, given)
            joints = dict(zip(values.names, out[:m], strict=True))
            for closure, gap in fk.gaps(joints).items():
                worst = max(worst, gap / fk.loop_size(closure))
        # On the clock, every joint of a loop from the scene's coordinates: the echo's value.
        on_clock = values.values(tick)
        np.testing.assert_allclose(on_clock[:m], out[:m], rtol=0, atol=ATOL_ECHO)
    assert worst <= RTOL_CLOSURE


def test_the_clock_path_keeps_an_actuated_joint_outside_the_loops_at_its_reference():
    """drive: time: joint_1 of the ABB arm (no loop, no driver) stays at its reference, at rest."""
    source = _source('abb_irb2400_12_155')
    robot, scene = source.robot, source.scene
    values = RobotValues(robot, scene.output_joints, scene.output_points)
    positions = [0.4] * len(robot.actuated)
    out = values.values(_tick(scene)(*values.scene_inputs(positions, [1.0] * len(positions))))
    m, k = len(values.names), values.names.index('joint_1')
    assert (out[k], out[m + k], out[2 * m + k]) == (robot.start('joint_1'), 0.0, 0.0)
    assert values.clock_note == ''


def test_a_mimic_driver_is_noted_for_the_clock():
    """drive: time moves the 2F-85's mimic-driven finger on its own: the node warns so."""
    source = _source('robotiq_2f_85')
    values = RobotValues(source.robot, source.scene.output_joints, source.scene.output_points)
    assert values.clock_note.startswith(
        'URDF mode with drive: time: the scene drivers right_outer_knuckle '
        '(right_outer_knuckle_joint mimics finger_joint) move on their own')


def test_the_urdf_text_and_a_path_load_the_same_robot():
    """robot_description (the text) is the robot scene:=PATH.urdf names; its text unchanged."""
    path = DATA / 'robotiq_2f_85.urdf'
    closures = str(DATA / 'robotiq_2f_85.loop_closures.yaml')
    by_path = load_source(str(path), loop_closures=closures)
    by_text = load_source(DEFAULT_SCENE, path.read_text(), closures)
    assert by_text.robot.joint_names == by_path.robot.joint_names
    assert by_text.robot.description.text == path.read_text()
    assert by_text.origin == 'robot_description' and by_path.origin == str(path)
    assert by_path.text.startswith(f'# The planar loops of {path}, as a scene')
    scene = load_source(DEFAULT_SCENE)
    assert scene.robot is None and scene.text == scene_text(DEFAULT_SCENE)


@pytest.mark.parametrize('kwargs, error, line', [
    ({'scene': 'five_bar', 'loop_closures': 'x.yaml'}, SceneError,
     'Expected loop_closures with a robot described in URDF (scene:=PATH.urdf or '
     'robot_description), got scene five_bar'),
    ({'scene': 'five_bar', 'actuated_joints': ['a']}, SceneError,
     'Expected actuated_joints with a robot described in URDF'),
    ({'scene': 'five_bar', 'robot_description': '<robot name="r"/>'}, SceneError,
     'Expected the robot in one parameter, scene:=ROBOT.urdf or robot_description, got both '
     '(scene five_bar)'),
    ({'scene': str(DATA / 'robotiq_2f_85.urdf')}, UrdfError,
     'Expected a robot with a closed loop'),
    ({'scene': str(DATA / 'minitaur_leg.urdf'), 'actuated_joints': [
        'motor_front_leftR_joint', 'motor_front_leftL_joint']}, UrdfError,
     'the loop is not planar'),
    ({'scene': str(DATA / 'robotiq_2f_85.urdf'),
      'loop_closures': str(DATA / 'robotiq_2f_85.loop_closures.yaml'),
      'actuated_joints': ['nope']}, UrdfError, 'got "nope", no joint of the robot'),
    ({'scene': DEFAULT_SCENE, 'robot_description': '<robot name="r">'}, UrdfError,
     '<robot_description>: '),
])
def test_what_does_not_load_is_refused_in_one_line(kwargs, error, line):
    """Parameters that do not go together, or a robot refused: one line saying what was wrong."""
    with pytest.raises(error) as raised:
        load_source(**kwargs)
    assert line in str(raised.value) and '\n' not in str(raised.value)
