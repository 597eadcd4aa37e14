# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""What a robot in URDF is refused for: one line naming the joint and why. See issue 31."""

import math

from helpers import khurmi_pin, khurmi_urdf, solve_urdf_text, UrdfFk
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


def test_a_four_bar_driven_at_its_elbow_is_re_rooted_there_and_closes():
    """The elbow (crank to coupler, neither placed first) drives a fold (issue 41, item 1).

    At the elbow angle the motor-driven four-bar shows, the loop re-rooted at the elbow
    answers the same joints and rates (1e-14), and closes in the test's own kinematics.
    """
    text = khurmi_urdf()
    by_motor, by_elbow = load_robot(text), load_robot(text, actuated=['elbow'])
    assert [d['type'] for d in by_elbow.planar.data['dyads']] == ['fold']
    fk = UrdfFk(text)
    for q in (0.3, 1.0, 2.0, 4.0):
        given = by_motor.solve({'motor': q}, {'motor': 1.5})
        elbow = given.joints['elbow']
        answer = by_elbow.solve({'elbow': elbow.position}, {'elbow': elbow.velocity})
        for name, joint in given.joints.items():
            got = answer.joints[name]
            assert abs(math.remainder(got.position - joint.position, math.tau)) <= 1e-14
            assert got.velocity == pytest.approx(joint.velocity, abs=1e-13)
        values = {n: j.position for n, j in answer.joints.items()}
        assert fk.gaps(values)['pin_C'] <= 1e-12 * fk.loop_size('pin_C')


def test_a_relative_driver_no_kind_drives_is_refused_saying_why():
    """The triad's B (crank to l1): neither placed first, nor a fold's knee: one line."""
    error = _refused(TRIAD, actuated=['B'])
    assert error.joint == 'B' and 'no relative angle' in str(error)
    assert 'a fold' in str(error)


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


# --- issue 42: errors in one line, naming the right cause ----------------------------------


@pytest.mark.parametrize('where', ['<link name="frame"/>', '</robot>'])
def test_a_nul_in_a_urdf_is_one_line(tmp_path, capsys, where):
    """A NUL gave two lines (lxml's message holds a newline), or named a tag it cut short."""
    text = khurmi_urdf().replace(where, where.replace('/>', '/>\x00').replace('</', '</\x00'),
                                 1)
    assert '\x00' in text
    nul = text.index('\x00')
    line, column = text.count('\n', 0, nul) + 1, nul - text.rfind('\n', 0, nul)
    status, out, err = solve_urdf_text(tmp_path, capsys, text)
    assert (status, out) == (2, '')
    assert len(err.splitlines()) == 1
    said = ('Expected a URDF (XML), got text that is not XML: a NUL character (U+0000), '
            f'line {line}, column {column}')
    assert err.rstrip('\n').endswith(said), err


def test_a_closure_point_at_1e308_is_refused_with_its_gap_and_no_warning(tmp_path, capsys):
    """The gap of a pin at 1e308 m: 1e+308 m, no numpy overflow warning (was inf, warned)."""
    coupler, _ = khurmi_pin()
    text = khurmi_urdf().replace(f'<parent_origin xyz="{coupler.real!r} {coupler.imag!r} ',
                                 '<parent_origin xyz="1e308 0 ', 1)
    assert '1e308' in text
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        error = _refused(text)
    assert error.joint == 'pin_C' and 'got its two points 1e+308 m apart' in str(error)
    status, _, err = solve_urdf_text(tmp_path, capsys, text)
    assert status == 2 and len(err.splitlines()) == 1 and 'inf' not in err


@pytest.mark.parametrize('z', ['-1e-300', '-1e200', '-5e-324', '-1.7e308'])
def test_a_tiny_or_huge_axis_is_the_direction_it_is(z):
    """<axis xyz="0 0 -1e-300"> and "0 0 -1e200" were refused as no non-zero direction."""
    text = khurmi_urdf()
    given = text.replace('<axis xyz="0 0 -1"/>', f'<axis xyz="0 0 {z}"/>', 1)
    assert given != text
    robot = load_robot(given)
    assert robot.description.joints['rocker_pivot'].axis == (0.0, 0.0, -1.0)
    expected = load_robot(text).solve({'motor': 0.7}).joints
    got = load_robot(given).solve({'motor': 0.7}).joints
    assert {n: j.position for n, j in got.items()} == {n: j.position for n, j in expected.items()}


def test_a_zero_axis_is_still_refused():
    """0 0 0 is no direction: refused naming the joint."""
    error = _refused(khurmi_urdf().replace('<axis xyz="0 0 -1"/>', '<axis xyz="0 0 0"/>', 1))
    assert error.joint == 'rocker_pivot' and 'non-zero direction, got 0 0 0' in str(error)


def _constraint(text):
    start, end = text.index('<constraint'), text.index('</constraint>') + len('</constraint>')
    return text[start:end], end


def test_a_closure_written_twice_is_refused_as_such(tmp_path, capsys):
    """The <constraint> copied: refused as a name twice (was "a loop that is rigid")."""
    text = khurmi_urdf()
    closure, end = _constraint(text)
    error = _refused(text[:end] + closure + text[end:])
    assert error.joint == 'pin_C'
    assert str(error).endswith('closure "pin_C": Expected every closure to have a name of its '
                               'own, got "pin_C" twice (the other closure joins links "coupler" '
                               'and "rocker")')
    status, out, err = solve_urdf_text(tmp_path, capsys, text[:end] + closure + text[end:])
    assert (status, out) == (2, '') and len(err.splitlines()) == 1 and 'rigid' not in err


def test_a_second_pin_of_two_links_is_refused_naming_both():
    """The same pin under another name: one pin written twice; elsewhere: a weld."""
    text = khurmi_urdf()
    closure, end = _constraint(text)
    error = _refused(text[:end] + closure.replace('pin_C', 'pin_C2') + text[end:])
    assert error.joint == 'pin_C2'
    assert str(error).endswith('closure "pin_C2": Expected two bodies to be pinned together '
                               'once, got links "coupler" and "rocker" pinned by "pin_C" too (at '
                               'the same point: one pin written twice)')
    import numpy as np
    frames = load_robot(text).description.transforms()
    b = frames['coupler'][:, 3]                       # the elbow, on the coupler's origin
    on_rocker = np.linalg.inv(frames['rocker']) @ b
    xyz = ' '.join(repr(float(v)) for v in on_rocker[:3])
    second = (f'<constraint name="pin_B" type="revolute"><parent link="coupler"/>'
              f'<parent_origin xyz="0 0 0"/><child link="rocker"/><child_origin '
              f'xyz="{xyz}"/></constraint>')
    error = _refused(text[:end] + second + text[end:])
    assert error.joint == 'pin_B'
    assert str(error).endswith('got links "coupler" and "rocker" pinned by "pin_C" too (0.15 m '
                               'apart, they weld them: join them by a fixed joint or a '
                               '<constraint type="link">)')


def test_a_closure_named_as_a_joint_is_refused():
    """A closure named "elbow" would be the elbow's scene point too."""
    text = khurmi_urdf().replace('name="pin_C"', 'name="elbow"')
    error = _refused(text)
    assert error.joint == 'elbow' and 'got "elbow" twice (the other joint joins links ' \
        '"crank" and "coupler")' in str(error)


@pytest.mark.parametrize('flag', [['--input', 'motor=1e17'], ['--angle-deg', '1e17'],
                                  ['--input', 'motor=36000280']])
def test_a_crank_given_beyond_a_turn_is_reduced_exactly(tmp_path, capsys, flag):
    """--input motor=1e17 (deg) turns the loop as -80 does (was refused as within rounding).

    The joint is echoed as given (math.radians of it, as a scene's crank is),
    and listed outside its limits; the loop's joints are those of -80 deg to
    the bit, as a scene's --angle-deg 1e17 is.
    """
    import math
    status, out, err = solve_urdf_text(tmp_path, capsys, khurmi_urdf(), *flag)
    assert (status, err) == (0, '')
    import json
    got = json.loads(out)
    degrees = float(flag[1].split('=')[-1])
    assert got['inputs']['motor']['position'] == math.radians(degrees)
    assert got['limits']['motor']['position'] == math.radians(degrees)
    within_a_turn = f'motor={math.remainder(degrees, 360.0)!r}'
    status, out, _ = solve_urdf_text(tmp_path, capsys, khurmi_urdf(), '--input', within_a_turn)
    within = json.loads(out)
    for name in ('elbow', 'rocker_pivot'):
        assert got['joints'][name] == within['joints'][name]
    assert got['points'] == within['points']


@pytest.mark.parametrize('turns', [3 * 10 ** 9, 2 ** 52])
def test_a_reference_beyond_a_turn_is_reduced_exactly(tmp_path, capsys, turns):
    """--reference motor=360*N (deg) is the zero pose to the bit (was refused: a gap)."""
    import json
    answers = []
    for degrees in (360.0 * turns, 0.0):
        status, out, err = solve_urdf_text(tmp_path, capsys, khurmi_urdf(), '--input',
                                           'motor=30', '--reference', f'motor={degrees!r}')
        assert (status, err) == (0, '')
        answers.append(json.loads(out))
    assert answers[0]['joints'] == answers[1]['joints']
    assert answers[0]['points'] == answers[1]['points']


def test_a_joint_a_mimic_rule_involves_is_taken_as_given(tmp_path, capsys):
    """The crank leads a <mimic>: 1e17 deg is its value (the rule's), not reduced to -80."""
    import json
    text = khurmi_urdf().replace('</robot>', """<link name="e1"/>
      <joint name="w1" type="revolute"><parent link="frame"/><child link="e1"/>
        <axis xyz="1 0 0"/><mimic joint="motor" multiplier="0.5"/></joint></robot>""")
    status, out, _ = solve_urdf_text(tmp_path, capsys, text, '--input', 'motor=400')
    assert status == 0
    import math
    assert json.loads(out)['joints']['w1']['position'] == 0.5 * math.radians(400)


@pytest.mark.parametrize('xyz', ['nan 0 1', '0 nan -1', '0 inf 1', '0 0 -inf'])
def test_an_axis_that_is_not_finite_is_refused(xyz):
    """Scaled by its largest component, a NaN beside a 1 must still be refused."""
    error = _refused(khurmi_urdf().replace('<axis xyz="0 0 -1"/>', f'<axis xyz="{xyz}"/>', 1))
    assert error.joint == 'rocker_pivot' and 'non-zero direction' in str(error)
