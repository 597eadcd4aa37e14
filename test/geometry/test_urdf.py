# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The scene's URDF (robot_description) and the `urdf` tool. See issue 20.

The links must be exactly the frames the node puts on /tf and /tf_static (so
RViz and Foxglove pose them from /tf), and what each link draws must sit on
the scene's points at every crank angle, not only the one it was built at.
"""

import math
import xml.etree.ElementTree as ET

from helpers import crank_scene_names, driver_scene_names
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.__main__ import main as cli_main
from mech_kinematics.geometry.frames import frames_from_scene, poses_from_state
from mech_kinematics.geometry.instant_centres import bodies_from_scene, full_scene
from mech_kinematics.geometry.urdf import urdf_from_scene

#: Drawn pins against solved points, m (relative to the mechanism's size).
RTOL_PLACE = 1e-12
SCENES = crank_scene_names()  # several drivers: test_solve_drivers (issue 18)


def _links_and_joints(text):
    robot = ET.fromstring(text)
    assert robot.tag == 'robot'
    links = {link.get('name'): link for link in robot.findall('link')}
    joints = {joint.find('child').get('link'): joint for joint in robot.findall('joint')}
    return robot, links, joints


@pytest.mark.parametrize('name', SCENES)
def test_one_link_per_tf_frame_each_a_child_of_frame_id(name):
    """Links: frame_id, <prefix>/<output joint> (floating) and <prefix>/<ground point> (fixed)."""
    scene = mk.load_scene(name)
    robot, links, joints = _links_and_joints(urdf_from_scene(scene, 'base', 'robot1'))
    assert robot.get('name') == scene.name
    moving = {f'robot1/{joint}' for joint in scene.output_joints}
    ground = {f'robot1/{point}' for point in scene.ground}
    assert set(links) == {'base'} | moving | ground
    assert set(joints) == moving | ground                    # the root has no parent
    assert len(robot.findall('joint')) == len(joints)        # one joint per child
    for child, joint in joints.items():
        assert joint.find('parent').get('link') == 'base'    # as /tf: every frame under frame_id
        assert joint.get('type') == ('floating' if child in moving else 'fixed')
    for point, (x, y) in scene.ground.items():
        origin = joints[f'robot1/{point}'].find('origin')
        assert [float(v) for v in origin.get('xyz').split()] == [x, y, 0.0]
    names = [j.get('name') for j in robot.findall('joint')] + list(links)
    assert len(names) == len(set(names))


def test_prefix_defaults_to_frame_id_as_on_tf():
    """An empty tf_prefix names the frames <frame_id>/<name>, as the node's /tf does."""
    _, links, _ = _links_and_joints(urdf_from_scene(mk.load_scene('slider_crank_150_600')))
    assert set(links) == {'mechanism', 'mechanism/O', 'mechanism/crank', 'mechanism/rod',
                          'mechanism/piston'}


def _placed_pins(link, pose):
    """Ground positions of a link's pins when its frame is at ``pose``."""
    out = []
    for visual in link.findall('visual'):
        if visual.find('geometry/cylinder') is None:
            continue
        x, y, _ = (float(v) for v in visual.find('origin').get('xyz').split())
        c, s = math.cos(pose.angle), math.sin(pose.angle)
        out.append(np.array([pose.x + c * x - s * y, pose.y + s * x + c * y]))
    return out


@pytest.mark.parametrize('name', SCENES)
def test_pins_land_on_the_bodys_points_at_other_crank_angles(name):
    """Posed by the frames of another crank angle, each body's pins sit on its solved points."""
    scene = mk.load_scene(name)
    full = full_scene(scene)
    frames = frames_from_scene(scene)
    topology = bodies_from_scene(full)
    _, links, _ = _links_and_joints(urdf_from_scene(scene, 'm', 'p'))
    states = mk.solve(full, scene.input.angle + np.linspace(0.1, 2 * math.pi, 7))
    size = max(abs(v) for xy in scene.ground.values() for v in xy) + scene.input.length
    checked = 0
    for k in np.flatnonzero(states.valid):
        state = mk.solve(full, float(scene.input.angle + np.linspace(0.1, 2 * math.pi, 7)[k]))
        points = {n: np.array([p.real, p.imag]) for n, (p, _, _) in state.complex_points.items()}
        for frame, pose in zip(frames, poses_from_state(frames, state), strict=True):
            body = topology.bodies[frame.joint]
            pins = _placed_pins(links[f'p/{frame.joint}'], pose)
            if not pins:
                continue        # a slider block: no pins of its own
            assert len(pins) == len(body.points)
            for pin, point in zip(pins, body.points, strict=True):
                np.testing.assert_allclose(pin, points[point], rtol=0, atol=RTOL_PLACE * size)
            checked += 1
    assert checked >= len(frames)


def test_a_crank_is_a_bar_of_its_length_along_x():
    """The four-bar's crank (AB = 40 mm) is one box 0.040 m long, centred at (0.020, 0)."""
    _, links, _ = _links_and_joints(urdf_from_scene(mk.load_scene('khurmi_four_bar_ad150')))
    boxes = [v for v in links['mechanism/crank'].findall('visual')
             if v.find('geometry/box') is not None]
    assert len(boxes) == 1
    length = float(boxes[0].find('geometry/box').get('size').split()[0])
    assert length == pytest.approx(0.040, abs=1e-12)
    assert boxes[0].find('origin').get('xyz') == '0.02 0.0 0.0'


def test_urdf_tool_writes_the_same_document(tmp_path, capsys):
    """`urdf SCENE -o FILE` writes urdf_from_scene's text; a bad scene is one line, status 2."""
    out = tmp_path / 'four_bar.urdf'
    assert cli_main(['urdf', 'khurmi_four_bar_ad150', '-o', str(out), '--frame-id', 'base',
                     '--tf-prefix', 'r']) == 0
    assert out.read_text() == urdf_from_scene(mk.load_scene('khurmi_four_bar_ad150'), 'base',
                                              'r')
    capsys.readouterr()
    assert cli_main(['urdf', 'no_such_scene']) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and 'no_such_scene' in err


IMU_SCENE = """\
name: imu_urdf
units: {length: mm, angle: deg}
ground: {A: [0, 0], D: [150, 0]}
input: {link: crank, center: A, point: B, length: 40, angle: 60, speed_rpm: -120}
dyads:
  - type: RRR
    point: C
    links:
      - {name: coupler, from: B, length: 150}
      - {name: rocker, from: D, length: 80}
points:
  E: {link: coupler, origin: B, xaxis: C, local: [30, 20]}
imus:
  tip: {link: coupler, point: E, angle: 30}
  arm: {link: rocker, point: C}
"""


def test_an_imu_turned_on_its_link_has_a_fixed_link_at_its_point(tmp_path):
    """Issue 18: imus.tip (angle 30 deg) is a link fixed to the coupler's, at E, turned 30 deg.

    A sensor with angle 0 uses its link's frame: no link of its own.
    """
    path = tmp_path / 'imu_urdf.yaml'
    path.write_text(IMU_SCENE)
    scene = mk.load_scene(path)
    robot, links, joints = _links_and_joints(urdf_from_scene(scene, 'base', 'r'))
    assert 'r/tip' in links and 'r/arm' not in links
    joint = joints['r/tip']
    assert joint.get('type') == 'fixed' and joint.find('parent').get('link') == 'r/coupler'
    origin = joint.find('origin')
    x, y, z = (float(v) for v in origin.get('xyz').split())
    assert [float(v) for v in origin.get('rpy').split()] == [0.0, 0.0, math.radians(30)]
    # Placed by the coupler's pose at other crank angles, (x, y) lands on E.
    frames = frames_from_scene(scene, ['coupler'])
    for angle in np.linspace(0.0, 2 * np.pi, 7):
        state = mk.solve(full_scene(scene), float(angle))
        [pose] = poses_from_state(frames, state)
        c, s = math.cos(pose.angle), math.sin(pose.angle)
        np.testing.assert_allclose([pose.x + c * x - s * y, pose.y + s * x + c * y],
                                   state.points['E'].position, rtol=0, atol=1e-15)
    assert z == 0.0


# --- several drivers: an actuator is a prismatic joint between its two pins (issue 18) ---


def test_an_actuator_is_a_prismatic_joint_between_its_two_pins():
    """The rod hangs on the cylinder's body by a prismatic joint along x, limited to the stroke.

    Its /tf frame sits at the rod's pin, along the cylinder: the actuator's length
    from the body's frame, at every pose.
    """
    scene = mk.load_scene('excavator')
    _, links, joints = _links_and_joints(urdf_from_scene(scene))
    for actuator, body in (('boom_cyl', 'boom_cyl_body'), ('stick_cyl', 'stick_cyl_body')):
        joint = joints[f'mechanism/{actuator}']
        assert joint.get('type') == 'prismatic'
        assert joint.find('parent').get('link') == f'mechanism/{body}'
        assert joint.find('child').get('link') == f'mechanism/{actuator}'
        assert joint.find('axis').get('xyz') == '1 0 0'
        stroke = next(d.stroke for d in scene.drivers if d.name == actuator)
        limit = joint.find('limit')
        assert (float(limit.get('lower')), float(limit.get('upper'))) == stroke
        assert f'mechanism/{actuator}' in links
    frames = frames_from_scene(scene)
    for lengths in ([2.0, 2.5], [2.6, 3.0], [3.3, 3.9]):
        poses = {p.joint: p for p in poses_from_state(frames, mk.solve(scene, lengths))}
        for actuator, body, length in (('boom_cyl', 'boom_cyl_body', lengths[0]),
                                       ('stick_cyl', 'stick_cyl_body', lengths[1])):
            rod, base = poses[actuator], poses[body]
            assert rod.angle == base.angle
            along = complex(rod.x - base.x, rod.y - base.y) * complex(
                math.cos(base.angle), -math.sin(base.angle))
            assert along.real == pytest.approx(length, rel=1e-14)
            assert along.imag == pytest.approx(0.0, abs=1e-14)


@pytest.mark.parametrize('name', driver_scene_names())
def test_several_driver_scenes_have_a_urdf_on_their_frames(name):
    """One URDF link per /tf frame and ground point, as for one crank (issue 18).

    The packaged boom too, whose one driver is an actuator (issue 33: it raised
    "Expected the state of one crank angle, got an array of shape (1,)").
    """
    scene = mk.load_scene(name)
    _, links, joints = _links_and_joints(urdf_from_scene(scene))
    frames = {f'mechanism/{f.joint}' for f in frames_from_scene(scene)}
    ground = {f'mechanism/{name_}' for name_ in scene.ground}
    assert set(links) == {'mechanism', *frames, *ground}
    assert len(joints) == len(frames) + len(ground)


# --- a scene whose every state is refused (issue 33) --------------------------------------


def test_a_scene_refused_at_every_angle_is_one_line_not_a_type_error(tmp_path, capsys):
    """A Scotch yoke whose slot is 1e-9 deg off its guide: no state to draw, one line, exit 2.

    Its yoke is 2.9e9 m out and every state's bound is refused (untrusted). The
    URDF code built ``AssemblyError(msg)``, whose signature is (dyad, angle,
    reason): a TypeError. It now raises the solver's own refusal at the scene's
    angle, and the tool says it in the scene's units.
    """
    data = mk.scene.read_scene_yaml(mk.scene.scene_text('scotch_yoke'))
    data['dyads'][0]['slot_angle'] = 1e-9
    path = tmp_path / 'yoke.yaml'
    path.write_text(mk.scene.scene_text('scotch_yoke').replace('slot_angle: 90',
                                                               'slot_angle: 1e-9'))
    scene = mk.load_scene(path)
    assert scene == mk.parse_scene(data)
    with pytest.raises(mk.UntrustedError) as caught:
        urdf_from_scene(scene)
    assert caught.value.dyad == 'RPP Y' and caught.value.angle == scene.input.angle
    assert cli_main(['urdf', str(path)]) == 2
    out, err = capsys.readouterr()
    assert out == ''
    assert err.startswith('error: scotch_yoke: Expected a pose to draw its URDF in, got none: '
                          'RPP Y cannot be solved at its crank angle 30 deg, nor at any of a '
                          'turn: the position of points.Y cannot be trusted: expected its error '
                          'bound to be at most 1e-06 x 0.05 m')
    assert err.count('\n') == 1
