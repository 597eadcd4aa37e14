# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""What a robot in URDF is refused for: one line naming the joint and why. See issue 31."""

from helpers import khurmi_pin, khurmi_urdf, UrdfFk
import pytest

import mech_kinematics as mk
from mech_kinematics.errors import UrdfError
from mech_kinematics.robot import load_robot

TRIAD = """<robot name="triad">
  <link name="ground"/><link name="crank"/><link name="l1"/><link name="t"/>
  <link name="l2"/><link name="l3"/>
  <joint name="O" type="revolute"><parent link="ground"/><child link="crank"/>
    <axis xyz="0 0 1"/>{limit}</joint>
  <joint name="B" type="revolute"><parent link="crank"/><child link="l1"/>
    <origin xyz="0.1 0 0"/><axis xyz="0 0 1"/>{limit}</joint>
  <joint name="T1" type="revolute"><parent link="l1"/><child link="t"/>
    <origin xyz="0.2 0.1 0"/><axis xyz="0 0 1"/>{limit}</joint>
  <joint name="C" type="revolute"><parent link="ground"/><child link="l2"/>
    <origin xyz="0.3 0.4 0"/><axis xyz="0 0 1"/>{limit}</joint>
  <joint name="D" type="revolute"><parent link="ground"/><child link="l3"/>
    <origin xyz="0.6 0 0"/><axis xyz="0 0 1"/>{limit}</joint>
  <constraint name="T2" type="revolute"><parent link="t"/><parent_origin xyz="0.1 0.1 0"/>
    <child link="l2"/><child_origin xyz="0.1 -0.2 0"/></constraint>
  <constraint name="T3" type="revolute"><parent link="t"/><parent_origin xyz="0.2 0 0"/>
    <child link="l3"/><child_origin xyz="-0.1 0.1 0"/></constraint>
</robot>
""".replace('{limit}', '<limit lower="-3" upper="3" effort="1" velocity="1"/>')


def _refused(text, **kwargs):
    with pytest.raises(UrdfError) as caught:
        load_robot(text, **kwargs)
    assert '\n' not in str(caught.value)
    return caught.value


def test_an_axis_off_the_normal_is_refused_naming_the_joint_and_the_angle():
    """The rocker's axis tilted 1e-9 rad: not planar, by 1e-09 rad, at rocker_pivot."""
    error = _refused(khurmi_urdf().replace('<axis xyz="0 0 -1"/>', '<axis xyz="0 1e-9 -1"/>'))
    assert error.joint == 'rocker_pivot'
    assert 'by 1e-09 rad' in str(error) and 'not planar' in str(error)


def test_a_tilt_within_the_tolerance_is_solved_and_closes():
    """An axis 1e-13 rad off the normal is planar enough: it closes within 1e-12."""
    text = khurmi_urdf().replace('<axis xyz="0 0 -1"/>', '<axis xyz="0 1e-13 -1"/>')
    answer = load_robot(text).solve({'motor': 0.5})
    fk = UrdfFk(text)
    values = {n: j.position for n, j in answer.joints.items()}
    assert fk.gaps(values)['pin_C'] <= 1e-12 * fk.loop_size('pin_C')


def test_a_zero_pose_that_does_not_close_is_refused_with_the_gap():
    """The rocker's closure point moved 2 mm along x: refused, 0.002 m apart."""
    coupler, rocker = khurmi_pin()
    text = khurmi_urdf().replace(f'<child_origin xyz="{rocker.real!r} ',
                                 f'<child_origin xyz="{rocker.real + 0.002!r} ')
    error = _refused(text)
    assert error.joint == 'pin_C'
    assert '0.002 m apart' in str(error) and '1e-06 of its size' in str(error)


def test_a_triad_is_solved_not_refused():
    """A class-III group (three links on a floating triangle) is a triad (issue 43).

    Closed within 1e-12 m in the test's own forward kinematics where its
    branch reaches; beyond, one line naming the triad.
    """
    robot = load_robot(TRIAD, actuated=['O'])
    for q in (0.0, 0.3):
        values = {n: j.position for n, j in robot.solve({'O': q}).joints.items()}
        assert max(UrdfFk(TRIAD).gaps(values).values()) < 1e-12, q
    with pytest.raises(mk.AssemblyError, match='triad t') as caught:
        robot.solve({'O': 1.0})
    assert '\n' not in str(caught.value)


def test_a_relative_driver_is_refused_saying_why():
    """Driving the elbow (between two moving links): our kinds drive no relative angle."""
    error = _refused(khurmi_urdf(), actuated=['elbow'])
    assert error.joint == 'elbow' and 'no relative angle' in str(error)


def test_more_drivers_than_degrees_of_freedom_are_refused():
    """Two actuated joints on a one-degree-of-freedom loop: refused, both named."""
    error = _refused(khurmi_urdf(), actuated=['motor', 'rocker_pivot'])
    assert '1 degree of freedom' in str(error) and 'motor, rocker_pivot' in str(error)


def test_a_reference_pose_gives_the_other_branch():
    """Drawn crossed (a reference pose with C mirrored across BD), it stays on that branch."""
    import cmath
    import math
    scene = mk.load_scene('khurmi_four_bar_ad150')
    points = mk.solve(scene, scene.input.angle).complex_points
    b, c, d = (points[n][0] for n in 'BCD')
    u = (d - b) / abs(d - b)
    mirrored = b + u * ((c - b) / u).conjugate()
    reference = {'elbow': cmath.phase((mirrored - b) / (c - b)),
                 'rocker_pivot': -cmath.phase((mirrored - d) / (c - d))}
    text = khurmi_urdf()
    crossed = load_robot(text, reference=reference).solve({'motor': 0.0})
    assert crossed.joints['elbow'].position == pytest.approx(reference['elbow'], abs=1e-12)
    assert crossed.joints['rocker_pivot'].position == pytest.approx(
        reference['rocker_pivot'], abs=1e-12)
    fk = UrdfFk(text)
    values = {n: j.position for n, j in crossed.joints.items()}
    assert fk.gaps(values)['pin_C'] <= 1e-12 * fk.loop_size('pin_C')
    assert abs(math.remainder(reference['elbow'], math.tau)) > 0.1


def test_a_tree_without_a_closure_is_refused():
    """No <constraint>, no closing frames, no sidecar: a tree has no loop to solve."""
    text = khurmi_urdf()
    start, end = text.index('<constraint'), text.index('</constraint>') + len('</constraint>')
    error = _refused(text[:start] + text[end:])
    assert 'no loop' in str(error)


def test_a_robot_without_actuated_joints_is_refused_saying_where_each_door_gives_them():
    """No --actuated, no sidecar's, no <transmission>: one line, the loop's joints listed.

    The line names how each door takes them (a command's flag, the node's
    parameter, the API's argument, the URDF's transmissions), so the node's
    user is not sent to a command-line flag the node has not got.
    """
    text = khurmi_urdf()
    start, end = text.index('<transmission'), text.index('</transmission>') + 15
    error = str(_refused(text[:start] + text[end:]))
    assert error.split(': ', 1)[1].startswith(
        'Expected the actuated joints (--actuated J1,J2,... to a command, '
        'actuated_joints:=[J1, J2, ...] to the node, actuated= to the API, or '
        '<transmission>/<ros2_control> joints in the URDF), got none: the joints of its loops '
        'are ')
    for joint in ('motor', 'rocker_pivot', 'elbow'):
        assert joint in error.split('the joints of its loops are ')[1]
