# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""One answer from every door: the one wrap of a revolute value, the assembly the rules pick.

Issue 43, item 5. A revolute value is wrapped in one place
(``robot.assembly.wrap_revolute``: the same bits for a float and an array);
where a URDF's ``<mimic>`` rules relate a loop's joints, the assembly answered
is the one that keeps them: the Robotiq 2F-85's finger loops are
parallelograms whose rules (+-1 of finger_joint) hold on the reference
branch up to the change point near 1.94 rad and on the other branch from
there to the next, near 5.08 rad; driven to 40 rad the reference branch
answered the crossed assembly (strays of 0.34 and 1.06 rad).
"""

import math
from pathlib import Path

from helpers import assert_entry_is_the_single_answer, numpy_is_libm, UrdfFk
import numpy as np
import pytest

from mech_kinematics.robot import load_robot
from mech_kinematics.robot.assembly import wrap_revolute

DATA = Path(__file__).resolve().parents[1] / 'data' / 'urdf'
RTOL_CLOSURE = 1e-12


def _gripper():
    urdf, closures = DATA / 'robotiq_2f_85.urdf', DATA / 'robotiq_2f_85.loop_closures.yaml'
    return load_robot(urdf, closures), UrdfFk(urdf.read_text(), closures)


def test_the_wrap_is_exact_in_minus_pi_to_pi_and_the_same_bits_for_floats_and_arrays():
    """(c - pi, c + pi]: pi stays pi, -pi becomes pi; each value a whole number of turns away."""
    rng = np.random.default_rng(5)
    values = np.concatenate([[math.pi, -math.pi, 0.0, -0.0, 3 * math.pi, 40.0, -1e6, 1e-300,
                              np.nextafter(math.pi, 4), np.nextafter(-math.pi, -4)],
                             rng.uniform(-50, 50, 200)])
    for centre in (0.0, 0.43785, -2.0):
        array = wrap_revolute(values, centre)
        floats = [wrap_revolute(float(v), centre) for v in values]
        assert array.tolist() == floats
        off = array - centre
        assert np.all(off <= math.pi + 1e-15) and np.all(off > -math.pi - 1e-15)
        turns = (values - array) / math.tau
        assert np.abs(turns - np.round(turns)).max() < 1e-9
    assert wrap_revolute(math.pi) == math.pi and wrap_revolute(-math.pi) == math.pi
    assert wrap_revolute(40.0) == 40.0 - 6 * math.tau    # fmod is exact; so is one step
    assert math.isnan(wrap_revolute(math.inf))


def test_the_grippers_parallelograms_keep_their_rules_through_the_change_points_and_at_40_rad():
    """Over two turns and at 40 rad: no stray, loops closed; the reference branch alone strays."""
    robot, fk = _gripper()
    assert len(robot.assemblies.ruled) == 2       # one per finger loop, one dyad each
    reference = robot.assemblies.scene(robot.assemblies.zero, robot.scene)
    # Through the change points (near 1.94 and 5.08 rad, and a turn less), kept 0.09 off them.
    for q in [-6.0, -5.0, -4.0, -3.0, -2.0, -1.0, 0.0, 1.0, 1.85, 2.03, 3.0, 4.0, 4.99, 5.17,
              6.0, 12.0, 40.0]:
        answer = robot.solve({'finger_joint': float(q)}, {'finger_joint': 1.5})
        assert answer.mimic == {}, q
        gaps = fk.gaps({n: j.position for n, j in answer.joints.items()})
        assert max(g / fk.loop_size(c) for c, g in gaps.items()) <= RTOL_CLOSURE
        for side in ('left', 'right'):
            knuckle = answer.joints[f'{side}_inner_knuckle_joint']
            assert knuckle.velocity == pytest.approx(1.5, abs=1e-12)   # the rule's rate
    robot.scene, kept = reference, robot.scene    # the reference branch alone, at 40 rad
    robot.assemblies.ruled, ruled = (), robot.assemblies.ruled
    try:
        crossed = robot.solve({'finger_joint': 40.0})
    finally:
        robot.scene, robot.assemblies.ruled = kept, ruled
    assert abs(crossed.mimic['left_inner_finger_joint']['stray']) > 1.0


def test_an_array_answers_each_instant_in_its_own_assembly_to_the_bit():
    """A sweep across both change points as one array: every value the single solve's.

    To the bit where NumPy's ``arctan2`` and ``hypot`` are the C library's;
    where NumPy runs its own AVX-512 loops, each value within the two solves'
    error bounds (``helpers.assert_entry_is_the_single_answer``), in the same
    assembly.
    """
    robot, _ = _gripper()
    q = np.array([0.3, 1.0, 2.5, 3.6, 4.9, 5.5, 40.0, -3.0])
    many = robot.solve({'finger_joint': q}, {'finger_joint': np.full(q.shape, 0.7)})
    assert bool(np.all(many.state.valid)) and many.mimic == {}
    for i, x in enumerate(q):
        one = robot.solve({'finger_joint': float(x)}, {'finger_joint': 0.7})
        assert_entry_is_the_single_answer(one.state, many.state, i)
        for name in robot.joint_names:
            got, want = many.joints[name], one.joints[name]
            for k, quantity in enumerate(('position', 'velocity')):
                a = float(np.broadcast_to(getattr(got, quantity), q.shape)[i])
                b = getattr(want, quantity)
                bound_a = float(np.broadcast_to(many.bounds[name][k], q.shape)[i])
                bound_b = one.bounds[name][k]
                if numpy_is_libm():
                    assert (a, bound_a) == (b, bound_b), (name, quantity)
                else:
                    assert abs(a - b) <= bound_a + bound_b, (name, quantity, a, b)


def test_a_loop_without_rules_keeps_the_reference_branch():
    """The gripper with its <mimic> rules commented out has no rule to pick an assembly by."""
    robot = load_robot(DATA / 'robotiq_2f_85.urdf', DATA / 'robotiq_2f_85.loop_closures.yaml')
    text = (DATA / 'robotiq_2f_85.urdf').read_text()
    plain = load_robot(text.replace('<mimic', '<!-- mimic').replace(
        'offset="0"/>', 'offset="0"/ -->'), DATA / 'robotiq_2f_85.loop_closures.yaml',
        actuated=['finger_joint', 'right_outer_knuckle_joint'])
    assert robot.assemblies and not plain.assemblies
