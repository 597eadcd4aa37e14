# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Every closure form users have, read by content and solved (issue 43, item 2).

Fixtures in test/data/urdf (README.md there: each one's source, what is ours,
the licence):

- Gepetto/example-parallel-robots' planar five-bar (``robots/5bar_linkage``):
  its URDF and its Extended-URDF ``robot.yaml`` (``closed_loop``, ``type:
  ['6d']``, ``name_mot``), as published; BSD 3-Clause, LAAS-CNRS, INRIA.
- Adriaeik/fusion2URDF's example ``Assem1`` (an arm with a servo gripper whose
  fingers slide on the gripper's base): its URDF and its ``robot_data.yaml``
  (``closing_joints``: two **prismatic** closures), as published (refused: its
  angles are written to 6 digits, its loop is not planar within 1e-12), and
  the same with pi/2 and pi written to 17 digits (solved); MIT, Adrian
  Valaker Eikeland.
- The Robotiq 2F-85 (ros-industrial/robotiq, BSD 3-Clause) with its finger
  loops written here as a file of ``<constraint>`` elements, as Isaac Sim's
  ``<loop_joint>`` and as URDF+'s ``<loop>`` (no public file of these forms
  for a planar loop was found).
- OnRobot's RG2 (OnRobot/onrobot-ros2, BSD-3-Clause): its URDF as published
  (refused: one finger's axis is written ``1.5708``, its loop is not planar
  within 1e-12) and with that angle written pi/2 to 17 digits (solved), its
  two finger parallelograms written here as a file of ``<constraint>``
  elements beside it, as the issue's user had them.

Each loop is checked closed in ``helpers.UrdfFk``, which reads every form
again with xml.etree and PyYAML and closes it with 4x4 transforms.
"""

from pathlib import Path
import shutil

from helpers import gepetto_five_bar_reference, UrdfFk
import numpy as np
import pytest

from mech_kinematics.errors import UrdfError
from mech_kinematics.robot import load_robot
from mech_kinematics.robot.description import read_description

DATA = Path(__file__).resolve().parents[1] / 'data' / 'urdf'
#: A loop closes within this, over its size (the contract's exactness).
RTOL_CLOSURE = 1e-12
#: name -> (URDF, closure file or None, actuated or None, {joint: (low, high)} swept,
#: the closures' form, their kind).
FORMS = {
    'constraint file': ('robotiq_2f_85.urdf', 'robotiq_2f_85.constraints.xml', None,
                        {'finger_joint': (0.0, 0.7)}, '<constraint>', 'pin'),
    'constraint file (RG2)': ('onrobot_rg2_exact.urdf', 'onrobot_rg2.constraints.xml',
                              ['finger_joint'], {'finger_joint': (0.0, 1.22277767395)},
                              '<constraint>', 'pin'),
    'loop_joint': ('robotiq_2f_85.loop_joint.urdf', None, None,
                   {'finger_joint': (0.0, 0.7)}, '<loop_joint>', 'pin'),
    'loop': ('robotiq_2f_85.loop.urdf', None, None,
             {'finger_joint': (0.0, 0.7)}, '<loop>', 'pin'),
    'robot.yaml 6d': ('gepetto_5bar_linkage.urdf', 'gepetto_5bar_linkage.robot.yaml', None,
                      {'mot1': (-0.4, 0.4), 'mot2': (0.3, -0.3)}, 'robot.yaml',
                      'weld'),
    'robot_data.yaml prismatic': ('fusion2urdf_assem1_exact.urdf',
                                  'fusion2urdf_assem1_exact.robot_data.yaml', ['servo_joint'],
                                  {'servo_joint': (-0.95, -0.05)}, 'robot_data.yaml',
                                  'slide'),
}


def _robot(form, closures=None):
    urdf, name, actuated, _, _, _ = FORMS[form]
    closure_path = closures or (None if name is None else DATA / name)
    reference = gepetto_five_bar_reference() if form.startswith('robot.yaml') else None
    return (load_robot(DATA / urdf, closure_path, actuated, reference),
            UrdfFk((DATA / urdf).read_text(), closure_path))


@pytest.mark.parametrize('form', FORMS)
def test_each_form_is_read_and_its_loops_close_in_the_tests_own_kinematics(form):
    """Over a sweep of its motors, every closure of the file closes within 1e-12 of its loop."""
    robot, fk = _robot(form)
    _, _, _, sweep, written, kind = FORMS[form]
    closures = robot.description.closures
    assert closures and {c.form for c in closures} == {written}
    assert {c.kind.value for c in closures} == {kind}
    assert len(fk.closures) == len(closures)
    assert set(robot.actuated) == set(sweep)
    worst = 0.0
    rng = np.random.default_rng(43)
    for t in np.linspace(0.0, 1.0, 9):
        positions = {n: lo + t * (hi - lo) for n, (lo, hi) in sweep.items()}
        speeds = {n: float(rng.uniform(-1.0, 1.0)) for n in sweep}
        answer = robot.solve(positions, speeds)
        values = {n: j.position for n, j in answer.joints.items()}
        gaps = fk.gaps(values)
        assert len(gaps) == len(closures)
        for name, gap in gaps.items():
            worst = max(worst, gap / fk.loop_size(name))
        # The rates keep the loops closed: moved by h along them, they miss by O(h^2).
        h = 1e-6
        moved = {n: j.position + h * j.velocity for n, j in answer.joints.items()}
        assert max(fk.gaps(moved).values()) <= 1e-9 * max(fk.loop_size(c) for c in gaps)
    assert worst <= RTOL_CLOSURE


def test_the_five_bars_open_zero_pose_is_refused_naming_the_weld():
    """Exported 0.3 m open: a weld the reference pose does not close is refused, as a pin is."""
    with pytest.raises(UrdfError, match=r'closure "closedloop1_ACclosedloop1_B": Expected the '
                       r'reference pose to close the loop within 1e-06 of its size '
                       r'\(0\.967678 m\), got its two frames 0\.3 m apart and turned 1\.57 rad'):
        load_robot(DATA / 'gepetto_5bar_linkage.urdf', DATA / 'gepetto_5bar_linkage.robot.yaml')


def test_the_five_bar_closed_by_a_3d_point_is_solved(tmp_path):
    """The same robot.yaml with type ['3d']: the two spheres joined at a point, both idle."""
    closures = tmp_path / 'robot.yaml'
    closures.write_text((DATA / 'gepetto_5bar_linkage.robot.yaml').read_text().replace(
        "['6d']", "['3d']"))
    robot, fk = _robot('robot.yaml 6d', closures)
    assert [c.kind.value for c in robot.description.closures] == ['pin']
    reference = gepetto_five_bar_reference(closures)
    worst = 0.0
    for t in np.linspace(-0.3, 0.3, 7):
        answer = robot.solve({'mot1': t, 'mot2': -0.5 * t})
        values = {n: j.position for n, j in answer.joints.items()}
        assert values['closedloop1_B'] == reference['closedloop1_B']   # held: idle
        for name, gap in fk.gaps(values).items():
            worst = max(worst, gap / fk.loop_size(name))
    assert worst <= RTOL_CLOSURE


def test_the_five_bars_idle_sphere_turns_with_its_first_joint():
    """Gepetto's 6d weld of two joint frames leaves a sphere free to spin between coaxial pins.

    It turns with rod_2 (its first joint, closedloop1_A, stays at 0 with rate 0);
    closedloop1_B answers the turn of end_rod relative to rod_2.
    """
    robot, _ = _robot('robot.yaml 6d')
    assert robot.description.independent == ('mot1', 'mot2')
    answer = robot.solve({'mot1': 0.3, 'mot2': -0.2}, {'mot1': 1.0, 'mot2': 0.5})
    held = answer.joints['closedloop1_A']
    assert (held.position, held.velocity) == (0.0, 0.0)
    assert answer.joints['closedloop1_B'].velocity != 0.0


def test_the_published_fusion2urdf_file_is_read_and_refused_as_not_planar():
    """Its two prismatic closing joints are read; its 6-digit angles tilt the loop by 4e-7 rad."""
    urdf, data = DATA / 'fusion2urdf_assem1.urdf', DATA / 'fusion2urdf_assem1.robot_data.yaml'
    description = read_description(urdf, data)
    assert [(c.name, c.kind.value, c.link_a, c.link_b) for c in description.closures] == [
        ('left_slider', 'slide', 'led_base', 'acc_right_gripper'),
        ('right_slider', 'slide', 'led_base', 'acc_left_gripper')]
    with pytest.raises(UrdfError, match=r'the loop is not planar') as error:
        load_robot(urdf, data, ['servo_joint'])
    assert 'off it by 4.1e-07 rad' in str(error.value)


def test_the_published_rg2_is_read_and_refused_as_not_planar_naming_the_joint():
    """The right finger's pi/2, written 1.5708 by OnRobot, tilts its loop 3.7e-6 rad."""
    urdf, closures = DATA / 'onrobot_rg2.urdf', DATA / 'onrobot_rg2.constraints.xml'
    description = read_description(urdf, closures)
    assert [(c.name, c.link_a, c.link_b) for c in description.closures] == [
        ('right_finger_loop', 'right_inner_proximal_finger_link', 'right_finger_base_link'),
        ('left_finger_loop', 'left_inner_proximal_finger_link', 'left_finger_base_link')]
    with pytest.raises(UrdfError, match=r'joint "right_inner_proximal_finger_joint": .*the '
                       r'loop is not planar') as error:
        load_robot(urdf, closures, ['finger_joint'])
    assert 'off it by 3.67e-06 rad' in str(error.value)


def test_the_rg2s_fingers_stay_parallel_to_its_body_as_its_mimic_rules_say():
    """Each finger base turns back by the finger joint (-1), each inner link with it (+1).

    The covers hang from the outer links by mimics outside the loops (-1, then +1 on the
    cover arm): placed as hinges those rules turn (they carry masses), they follow them.
    """
    robot, _ = _robot('constraint file (RG2)')
    hinges = {d.name for d in robot.planar.drivers if d.mimic is not None}
    assert {'right_finger_cover_arm_joint', 'left_finger_cover_joint'} <= hinges
    for q in (0.0, 0.3, 0.9, 1.22):
        joints = robot.solve({'finger_joint': q}, {'finger_joint': 0.5}).joints
        for side in ('right', 'left'):
            for name, gain in (('finger_base', -1.0), ('inner_proximal_finger', 1.0),
                               ('finger_cover_arm', -1.0), ('finger_cover', 1.0)):
                joint = joints[f'{side}_{name}_joint']
                assert joint.position == pytest.approx(gain * q, abs=1e-12)
                assert joint.velocity == pytest.approx(gain * 0.5, abs=1e-12)


def test_a_closure_file_is_told_by_its_content_not_its_name(tmp_path):
    """The same robot.yaml, robot_data.yaml and constraint file under other names."""
    for form in ('robot.yaml 6d', 'robot_data.yaml prismatic', 'constraint file'):
        urdf, closures, actuated, sweep, written, _ = FORMS[form]
        renamed = tmp_path / f'closures_{len(written)}.txt'
        shutil.copy(DATA / closures, renamed)
        robot, _ = _robot(form, renamed)
        assert {c.form for c in robot.description.closures} == {written}


@pytest.mark.parametrize('name, text, expected', [
    ('robot.yaml', "closed_loop: [['closedloop1_A', 'closedloop1_B']]\ntype: ['7d']\n",
     r"robot\.yaml: robot\.yaml \(Extended URDF\): type\[0\]: Expected 6d or 3d, got '7d'"),
    ('robot.yaml', "closed_loop: [['closedloop1_A', 'nowhere']]\ntype: ['6d']\n",
     r'robot\.yaml \(Extended URDF\): closed_loop\[0\]: Expected a link or joint of the robot'
     r" \(a Pinocchio frame\), got 'nowhere'"),
    ('robot.yaml', "closed_loop: [['closedloop1_A', 'closedloop1_B']]\ntype: ['6d', '3d']\n",
     r'robot\.yaml \(Extended URDF\): type: Expected one of 6d, 3d per closed_loop pair \(1\)'),
    ('robot.yaml', "closed_loop: [['closedloop1_A', 'closedloop1_B']]\njoint_name: [free1]\n"
     'joint_type: [UJOINT_XY]\n',
     r'robot\.yaml \(Extended URDF\): joint_type\[0\]: Expected SPHERICAL .*"free1"'),
    ('robot_data.yaml', 'closing_joints:\n- {name: pin, type: ball, parent: rod, child: rod_3}\n',
     r'robot_data\.yaml \(fusion2URDF\): closing_joints\[0\] "pin"\.type: Expected revolute, '),
    ('robot_data.yaml', 'closing_joints:\n- {name: pin, type: revolute, parent: rod, '
     'child: rod_3, origin_xyz_m: [0, 1]}\n',
     r'closing_joints\[0\] "pin"\.origin_xyz_m: Expected \[x, y, z\] \(finite numbers\), '
     r'got \[0, 1\]'),
    ('constraints.xml', '<constraints><link name="x"/></constraints>',
     r'constraints\.xml: Expected a file of <constraint> elements, got <constraints> with no '),
    ('constraints.xml', '<constraints><constraint name="c" type="revolute"><parent link="rod"/>'
     '<child link="ghost"/></constraint></constraints>',
     r'<constraint name="c">: Expected <child link="..."/> naming a link of the robot, got '
     r"'ghost'"),
    ('other.yaml', 'joints: {}\n',
     r'other\.yaml: Expected a loop_closures\.yaml \(closures:\), a file of <constraint> '
     r'elements, an Extended-URDF robot\.yaml \(closed_loop:\) or a fusion2URDF '
     r'robot_data\.yaml \(closing_joints:\), got a mapping with keys joints'),
])
def test_a_malformed_closure_file_is_refused_in_one_line_naming_form_file_and_element(
        tmp_path, name, text, expected):
    """A refusal names the file, the form and the element at fault, on one line."""
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(UrdfError, match=expected) as error:
        read_description(DATA / 'gepetto_5bar_linkage.urdf', path)
    assert str(path) in str(error.value) and '\n' not in str(error.value)


@pytest.mark.parametrize('tag, body, expected', [
    ('loop_joint', '<loop_joint name="x" type="revolute"><link1 link="rod"/>'
     '<link2 link="ghost"/></loop_joint>',
     r'<loop_joint name="x">: Expected <link2 link="..."/> naming a link of the robot, got '
     r"'ghost'"),
    ('loop', '<loop name="y" type="screw"><predecessor link="rod"/><successor link="rod_3"/>'
     '</loop>', r'<loop name="y">: Expected a type in revolute, continuous, spherical, '
     r"prismatic, fixed, got 'screw'"),
    ('loop_joint', '<loop_joint name="z" type="revolute"><link1 link="rod" xyz="0 1"/>'
     '<link2 link="rod_3"/></loop_joint>',
     r'<loop_joint name="z"> <link1> xyz to be 3 finite numbers, got \'0 1\''),
])
def test_a_malformed_loop_element_in_a_urdf_is_refused_in_one_line(tag, body, expected):
    """Isaac Sim's <loop_joint> and URDF+'s <loop>: the element and the URDF named."""
    text = (DATA / 'gepetto_5bar_linkage.urdf').read_text().replace('</robot>',
                                                                    body + '</robot>')
    with pytest.raises(UrdfError, match=expected) as error:
        read_description(text)
    assert '<robot_description>' in str(error.value) and '\n' not in str(error.value)


def _slides_in_urdf(tag):
    """Return the fusion2URDF gripper's URDF with its two slides written as ``tag`` elements.

    Each slide's frame on its child at the zero pose comes from ``UrdfFk``
    (our own forward kinematics), its rpy from SciPy.
    """
    from scipy.spatial.transform import Rotation

    text = (DATA / 'fusion2urdf_assem1_exact.urdf').read_text()
    fk = UrdfFk(text, DATA / 'fusion2urdf_assem1_exact.robot_data.yaml')

    def attributes(frame):
        xyz = ' '.join(repr(float(v)) for v in frame[:3, 3])
        rpy = ' '.join(repr(float(v)) for v in Rotation.from_matrix(frame[:3, :3]).as_euler('xyz'))
        return f'xyz="{xyz}" rpy="{rpy}"'

    elements = []
    for name, _, a, fa, b, fb in fk.closures:
        axis = ' '.join(repr(float(v)) for v in fk.slides[name])
        if tag == 'constraint':
            elements.append(
                f'<constraint name="{name}" type="prismatic"><parent link="{a}"/>'
                f'<parent_origin {attributes(fa)}/><parent_axis xyz="{axis}"/>'
                f'<child link="{b}"/><child_origin {attributes(fb)}/>'
                f'<child_axis xyz="{axis}"/></constraint>')
        else:
            elements.append(f'<loop_joint name="{name}" type="prismatic"><link1 link="{a}" '
                            f'{attributes(fa)}/><link2 link="{b}" {attributes(fb)}/>'
                            f'<axis xyz="{axis}"/></loop_joint>')
    return text.replace('</robot>', '\n'.join(elements) + '\n</robot>')


@pytest.mark.parametrize('tag', ['constraint', 'loop_joint'])
def test_a_prismatic_constraint_or_loop_joint_in_the_urdf_is_a_slide_closing_its_loop(tag):
    """The gripper's fingers slide on its base: <constraint type="prismatic"> (once refused)."""
    text = _slides_in_urdf(tag)
    robot = load_robot(text, actuated=['servo_joint'])
    fk = UrdfFk(text)
    assert {c.kind.value for c in robot.description.closures} == {'slide'}
    assert len(fk.slides) == 2
    worst = 0.0
    for servo in np.linspace(-0.95, -0.05, 7):
        answer = robot.solve({'servo_joint': float(servo)})
        gaps = fk.gaps({n: j.position for n, j in answer.joints.items()})
        worst = max(worst, *(gap / fk.loop_size(name) for name, gap in gaps.items()))
    assert worst <= RTOL_CLOSURE


def test_the_nodes_loop_closures_takes_every_form():
    """What the node loads from scene:=ROBOT.urdf and loop_closures:=FILE (no DDS needed)."""
    from mech_kinematics.ros.robot_mode import load_source

    for form in ('constraint file', 'robot_data.yaml prismatic'):
        urdf, closures, actuated, sweep, written, _ = FORMS[form]
        source = load_source(str(DATA / urdf), loop_closures=str(DATA / closures),
                             actuated_joints=actuated)
        assert {c.form for c in source.robot.description.closures} == {written}
        assert set(source.robot.actuated) == set(sweep)
    # The open five-bar: refused from its zero pose, solved from reference_pose (rad),
    # the joints of Robot.solve from the same reference, to the bit (issue 43, item 4).
    urdf, closures, _, _, _, _ = FORMS['robot.yaml 6d']
    with pytest.raises(UrdfError, match='give a reference pose that closes it'):
        load_source(str(DATA / urdf), loop_closures=str(DATA / closures))
    reference = gepetto_five_bar_reference()
    source = load_source(str(DATA / urdf), loop_closures=str(DATA / closures),
                         reference_pose=[f'{n}={v!r}' for n, v in reference.items()])
    robot = load_robot(DATA / urdf, DATA / closures, None, reference)
    given = {n: robot.start(n) + 0.05 for n in robot.actuated}
    got, expected = source.robot.solve(given).joints, robot.solve(given).joints
    assert {n: (j.position, j.velocity, j.acceleration) for n, j in got.items()} == {
        n: (j.position, j.velocity, j.acceleration) for n, j in expected.items()}


@pytest.mark.parametrize('entry, said', [
    ('mot1', 'reference_pose: Expected JOINT=VALUE with JOINT a moving joint of the robot ('),
    ('nothing=0.1', 'reference_pose: Expected JOINT=VALUE with JOINT a moving joint of '),
    ('mot1=fast', "reference_pose: Expected mot1=VALUE a finite number (rad), got 'mot1=fast'"),
    ('mot1=nan', "reference_pose: Expected mot1=VALUE a finite number (rad), got 'mot1=nan'"),
])
def test_a_bad_reference_pose_parameter_is_one_line_naming_it(entry, said):
    """Not JOINT=VALUE, not a moving joint, not a finite number: one line."""
    from mech_kinematics.ros.robot_mode import load_source

    urdf, closures, _, _, _, _ = FORMS['robot.yaml 6d']
    with pytest.raises(UrdfError) as caught:
        load_source(str(DATA / urdf), loop_closures=str(DATA / closures),
                    reference_pose=[entry])
    assert '\n' not in str(caught.value) and str(caught.value).startswith(said)


def test_a_reference_pose_parameter_needs_a_robot():
    """A scene has its own pose: reference_pose with a scene is refused in one line."""
    from mech_kinematics.errors import SceneError
    from mech_kinematics.ros.robot_mode import load_source

    with pytest.raises(SceneError, match=r'Expected reference_pose with a robot described in '
                                         r'URDF'):
        load_source('khurmi_four_bar_ad150', reference_pose=['crank=0.1'])


def test_revolute_closing_joints_of_a_robot_data_yaml_close_their_loops(tmp_path):
    """fusion2URDF's closing_joints with type revolute: the 2F-85's finger loops, pins."""
    import xml.etree.ElementTree as ET

    items = []
    for c in ET.parse(DATA / 'robotiq_2f_85.constraints.xml').getroot():
        xyz = ', '.join(c.find('parent_origin').get('xyz').split())
        axis = ', '.join(c.find('parent_axis').get('xyz').split())
        items.append(f'  - name: {c.get("name")}\n    type: revolute\n'
                     f'    parent: {c.find("parent").get("link")}\n'
                     f'    child: {c.find("child").get("link")}\n'
                     f'    origin_xyz_m: [{xyz}]\n    origin_rpy_rad: [0.0, 0.0, 0.0]\n'
                     f'    axis: [{axis}]\n')
    closures = tmp_path / 'robot_data.yaml'
    closures.write_text('metadata:\n  design_name: gripper\nclosing_joints:\n' + ''.join(items)
                        + 'rigid_groups: {}\n')
    urdf = DATA / 'robotiq_2f_85.urdf'
    robot = load_robot(urdf, closures)
    fk = UrdfFk(urdf.read_text(), closures)
    assert [c.kind.value for c in robot.description.closures] == ['pin', 'pin']
    worst = 0.0
    for q in np.linspace(0.0, 0.7, 8):
        answer = robot.solve({'finger_joint': float(q)})
        gaps = fk.gaps({n: j.position for n, j in answer.joints.items()})
        assert len(gaps) == 2
        worst = max(worst, *(gap / fk.loop_size(name) for name, gap in gaps.items()))
    assert worst <= RTOL_CLOSURE
