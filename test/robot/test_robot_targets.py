# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A URDF robot driven from its output: joints and ``FRAME.x|y|z`` targets (issue 41, item 2).

Every value is checked against the URDF's own forward kinematics written
apart from the package (``UrdfFk`` in test/helpers.py, read with
xml.etree): the joints answered put the target frame's origin where it was
asked (1e-12 of the loops' size) over hypothesis-drawn targets around
Gepetto's five-bar's reference pose (its effector driven in its plane, the
URDF's y and z); the frame's velocity and acceleration answered against
central differences of that kinematics along the answered motion; the
Jacobian against central differences of the forward solve. The frame's
position and its rounding bound against a 50-digit walk of the same chain
(mpmath). The lift arm (masses) gives the efforts of the motion and a
passive joint as its target.
"""

import json
import math
from pathlib import Path

from helpers import gepetto_five_bar_reference, UrdfFk
from hypothesis import given, settings, strategies as st
import mpmath
import numpy as np
import pytest

from mech_kinematics.__main__ import main as cli_main
from mech_kinematics.errors import TargetError
from mech_kinematics.robot import load_robot
from mech_kinematics.robot.targets import frame_motion

DATA = Path(__file__).resolve().parents[1] / 'data' / 'urdf'
GEPETTO = DATA / 'gepetto_5bar_linkage.urdf'
GEPETTO_LOOP = DATA / 'gepetto_5bar_linkage.robot.yaml'
LIFT = DATA / 'lift_arm.urdf'
#: The contract's exactness: a target reached within this of the loops' size.
RTOL_REACHED = 1e-12
#: Central differences' step (s along the motion, rad or m for a column) and tolerance.
H = 1e-4
#: The velocity's step along the motion: its central difference errs by H^2 |x'''| / 6, and
#: where a motor's answered acceleration is large (86 rad/s^2 at dy = 0.0625, dz = 0.01,
#: vz = 0.5) that is 1.9e-6 at 1e-4, above the tolerance; 100 times less at 1e-5, with
#: rounding (eps / H) far below it.
H_VELOCITY = 1e-5
#: The acceleration's step: its second difference errs by H^2 |x''''| / 12, which at 1e-4
#: was 1.9e-4 m/s^2 (above the tolerance) where a motor's answered acceleration is 173
#: rad/s^2 (dy = 0.078125, dz = 0.01, vz = 0.5: the error fell as H^2, 1.7e-3 at 3e-4,
#: 1.7e-5 at 3e-5); 7e-6 at 2e-5, with rounding (eps |x| / H^2, 3e-7) below it.
H_ACCELERATION = 2e-5
RTOL_DIFFERENCE = 1e-6


def _five_bar():
    robot = load_robot(GEPETTO, GEPETTO_LOOP, None, gepetto_five_bar_reference())
    return robot, UrdfFk(GEPETTO.read_text(), GEPETTO_LOOP)


FIVE, FIVE_FK = _five_bar()
SIZE = FIVE.solve(forces=False).state.error_bound.size


def _effector(fk, robot, q):
    """Return the effector's origin by the test's own kinematics, the loops solved at ``q``."""
    answer = robot.solve(q, forces=False, max_error=math.inf)
    return fk.transforms({n: float(j.position) for n, j in answer.joints.items()})[
        'effector'][:3, 3]


@settings(max_examples=25, deadline=None)
@given(dy=st.floats(-0.08, 0.08), dz=st.floats(0.01, 0.08),
       vy=st.floats(-0.5, 0.5), vz=st.floats(-0.5, 0.5),
       ay=st.floats(-2.0, 2.0), az=st.floats(-2.0, 2.0))
def test_the_five_bar_driven_by_its_effector_puts_it_there_at_its_rates(dy, dz, vy, vz, ay, az):
    """The motors answered move the URDF's effector as asked: position, velocity, acceleration."""
    p0 = _effector(FIVE_FK, FIVE, {})
    goal = {'effector.y': float(p0[1] + dy), 'effector.z': float(p0[2] + dz)}
    inverse = FIVE.solve_targets(goal, {'effector.y': vy, 'effector.z': vz},
                                 {'effector.y': ay, 'effector.z': az})
    assert inverse.drivers == ('mot1', 'mot2')
    q, qd, qdd = (dict(zip(inverse.drivers, inverse.motion[:, k], strict=True))
                  for k in range(3))
    reached = _effector(FIVE_FK, FIVE, q)
    np.testing.assert_allclose(reached[1:], [goal['effector.y'], goal['effector.z']],
                               rtol=0, atol=RTOL_REACHED * SIZE)
    assert abs(reached[0] - p0[0]) <= RTOL_REACHED * SIZE     # the plane is x = const

    def at(t):
        return _effector(FIVE_FK, FIVE, {n: q[n] + qd[n] * t + qdd[n] * t * t / 2 for n in q})

    velocity = (at(H_VELOCITY) - at(-H_VELOCITY)) / (2 * H_VELOCITY)
    acceleration = (at(H_ACCELERATION) - 2 * at(0.0) + at(-H_ACCELERATION)) / (
        H_ACCELERATION * H_ACCELERATION)
    np.testing.assert_allclose(velocity[1:], [vy, vz], rtol=0,
                               atol=RTOL_DIFFERENCE * (1 + abs(vy) + abs(vz)))
    np.testing.assert_allclose(acceleration[1:], [ay, az], rtol=0,
                               atol=1e-4 * (1 + abs(ay) + abs(az) + vy * vy + vz * vz))
    # What the answer says it reached is what it reached, within its bounds.
    for i, name in enumerate(inverse.targets):
        assert abs(inverse.reached[i, 0] - goal[name]) <= inverse.reached_bound[i, 0] + \
            RTOL_REACHED * SIZE


def test_the_jacobian_is_the_central_difference_of_the_forward_solve():
    p0 = _effector(FIVE_FK, FIVE, {})
    inverse = FIVE.solve_targets({'effector.y': float(p0[1] + 0.01),
                                  'effector.z': float(p0[2] + 0.03)})
    q = dict(zip(inverse.drivers, inverse.motion[:, 0], strict=True))
    for j, name in enumerate(inverse.drivers):
        plus = _effector(FIVE_FK, FIVE, {**q, name: q[name] + H})
        minus = _effector(FIVE_FK, FIVE, {**q, name: q[name] - H})
        np.testing.assert_allclose(inverse.jacobian[:, j], ((plus - minus) / (2 * H))[1:],
                                   rtol=0, atol=RTOL_DIFFERENCE)
    np.testing.assert_allclose(inverse.jacobian @ inverse.inverse, np.eye(2), atol=1e-12)


def _mp_origin(path, description, link, values):
    """``link``'s origin in the root frame by a 50-digit walk of the URDF's chain as written."""
    import xml.etree.ElementTree as ET

    mpmath.mp.dps = 50
    written = {}
    for element in ET.parse(path).getroot().findall('joint'):
        origin = element.find('origin')
        xyz, rpy = ((origin.get(key, '0 0 0') if origin is not None else '0 0 0').split()
                    for key in ('xyz', 'rpy'))
        written[element.get('name')] = ([mpmath.mpf(v) for v in xyz],
                                        [mpmath.mpf(v) for v in rpy])
    m = mpmath.eye(4)
    for joint in description.chain(link):
        xyz, rpy = written[joint.name]
        origin = _mp_rpy(*rpy)
        for i in range(3):
            origin[i, 3] = xyz[i]
        m = m * origin
        if joint.type is None:
            continue
        x = mpmath.mpf(values.get(joint.name, 0.0))
        axis = [mpmath.mpf(a) for a in joint.axis]
        if joint.type.angular:
            m = m * _mp_rotation(axis, x)
        else:
            m = m * _mp_translation([a * x for a in axis])
    return [m[i, 3] for i in range(3)]


def _mp_rpy(roll, pitch, yaw):
    c, s = mpmath.cos, mpmath.sin
    m = mpmath.eye(4)
    rot = [[c(yaw) * c(pitch), c(yaw) * s(pitch) * s(roll) - s(yaw) * c(roll),
            c(yaw) * s(pitch) * c(roll) + s(yaw) * s(roll)],
           [s(yaw) * c(pitch), s(yaw) * s(pitch) * s(roll) + c(yaw) * c(roll),
            s(yaw) * s(pitch) * c(roll) - c(yaw) * s(roll)],
           [-s(pitch), c(pitch) * s(roll), c(pitch) * c(roll)]]
    for i in range(3):
        for k in range(3):
            m[i, k] = rot[i][k]
    return m


def _mp_rotation(axis, angle):
    x, y, z = axis
    c, s = mpmath.cos(angle), mpmath.sin(angle)
    t = 1 - c
    m = mpmath.eye(4)
    rot = [[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
           [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
           [t * x * z - s * y, t * y * z + s * x, t * z * z + c]]
    for i in range(3):
        for k in range(3):
            m[i, k] = rot[i][k]
    return m


def _mp_translation(vector):
    m = mpmath.eye(4)
    for i, v in enumerate(vector):
        m[i, 3] = v
    return m


@pytest.mark.parametrize('path, closures, link', [
    (GEPETTO, GEPETTO_LOOP, 'effector'), (LIFT, None, 'tool_frame')])
def test_a_frames_position_and_its_rounding_bound_against_50_digits(path, closures, link):
    """Walked in doubles, the origin is within its bound of a 50-digit walk at the same values."""
    reference = gepetto_five_bar_reference() if closures else None
    robot = load_robot(path, closures, None, reference)
    description = robot.description
    for turn in np.linspace(-0.3, 0.3, 7):
        q = {name: robot.start(name) + float(turn) for name in robot.actuated}
        answer = robot.solve(q, forces=False)
        values = description.pose({n: float(j.position) for n, j in answer.joints.items()})
        exact = {n: (0.0, 0.0, 0.0) for n in values}   # the values taken as exact
        motion, bounds = frame_motion(description, link, values, {}, exact, 1.0)
        ours = _mp_origin(path, description, link, values)
        for axis in range(3):
            error = abs(mpmath.mpf(float(motion[0, axis])) - ours[axis])
            assert error <= bounds[0, axis], (turn, axis, float(error), bounds[0, axis])
        np.testing.assert_array_equal(motion[0], description.transforms(values)[link][:3, 3])


def test_the_lift_arm_driven_by_its_tool_and_by_a_passive_joint():
    """Masses: the efforts of the motion answered are the forward solve's at the motors' motion."""
    robot = load_robot(LIFT)
    inverse = robot.solve_targets({'tool_frame.z': 0.45}, {'tool_frame.z': 0.1},
                                  forces={'tool_frame.z': -50.0})
    q, qd, qdd = (dict(zip(inverse.drivers, inverse.motion[:, k], strict=True))
                  for k in range(3))
    forward = robot.solve(q, qd, qdd)
    assert inverse.answer.efforts.efforts == forward.efforts.efforts
    fk = UrdfFk(LIFT.read_text())
    tool = fk.transforms({n: float(j.position) for n, j in forward.joints.items()})['tool_frame']
    assert abs(tool[2, 3] - 0.45) <= RTOL_REACHED * forward.state.error_bound.size
    # Virtual work: the motor's share of the tool's force, times its speed, is the force's power.
    (name,) = inverse.drivers
    assert inverse.target_efforts[name] * qd[name] == pytest.approx(-50.0 * 0.1, rel=1e-12)
    elbow = float(forward.joints['elbow'].position)
    passive = robot.solve_targets({'elbow': elbow})
    assert passive.motion[0, 0] == pytest.approx(q[name], abs=1e-12)


@pytest.mark.parametrize('targets, words', [
    ({'tool_frame.w': 0.1}, "got 'tool_frame.w'"),
    ({'nowhere.x': 0.1}, "got 'nowhere.x'"),
    ({'tool_frame.z': 0.4, 'tool_frame.x': 0.8}, 'as many targets as lift_arm has actuated '
                                                 'joints (1: lift_joint), got 2'),
    ({'tool_frame.z': 5.0}, 'out of reach'),
])
def test_a_bad_target_is_refused_in_one_line(targets, words):
    with pytest.raises(TargetError, match=None) as caught:
        load_robot(LIFT).solve_targets(targets)
    assert words in str(caught.value) and '\n' not in str(caught.value)


def test_solve_drives_a_urdf_from_its_frame(capsys):
    """The CLI's answer is the API's: joints, the Jacobian, the efforts, the bounds."""
    status = cli_main(['solve', str(LIFT), '--target', 'tool_frame.z=0.45',
                       '--target-speed', 'tool_frame.z=0.1', '--indent', '0'])
    assert status == 0
    out = json.loads(capsys.readouterr().out)
    inverse = load_robot(LIFT).solve_targets({'tool_frame.z': 0.45}, {'tool_frame.z': 0.1})
    assert out['inputs']['lift_joint']['position'] == float(inverse.motion[0, 0])
    assert out['jacobian'] == {'rows': ['tool_frame.z'], 'columns': ['lift_joint'],
                               'matrix': inverse.jacobian.tolist(),
                               'inverse': inverse.inverse.tolist()}
    assert out['efforts'] == {k: float(v) for k, v in inverse.answer.efforts.efforts.items()}
    assert out['error_bound']['targets']['tool_frame.z'] == [
        float(x) for x in inverse.reached_bound[0]]
    assert cli_main(['solve', str(LIFT), '--target', 'tool_frame.q=0.4']) == 2
    err = capsys.readouterr().err
    assert err.startswith('error: Expected a target to be a joint lift_arm answers')
    assert err.count('\n') == 1
