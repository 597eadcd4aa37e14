# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Masses from a URDF's ``<inertial>`` (issue 32, INTERFACE v4's urdf2scene): the scene's masses.

Each moving body's mass, centre of mass and inertia about the plane's normal
come from the ``<inertial>`` of the links it holds. The centre of mass is
checked against the URDF's own forward kinematics (``UrdfFk``, written apart
from the package) at poses away from the reference: the scene's centre of
mass, carried by its body's /tf frame, is the URDF's, projected on the plane.
"""

import math

from helpers import khurmi_urdf, UrdfFk
import numpy as np
import pytest
import yaml

import mech_kinematics as mk
from mech_kinematics.__main__ import main as cli_main
from mech_kinematics.geometry.frames import frames_from_scene, poses_from_state
from mech_kinematics.robot import load_robot
from mech_kinematics.robot.transforms import transform

#: The four-bar's links' inertials: link -> (mass, xyz, rpy, (ixx, iyy, izz)).
INERTIALS = {
    'crank': (0.4, (0.02, 0.003, 0.011), (0.3, -0.2, 0.5), (1e-4, 2e-4, 3e-4)),
    'coupler': (1.1, (0.07, -0.01, -0.02), (0.0, 0.0, 0.0), (5e-4, 6e-4, 7e-4)),
    'rocker': (0.7, (0.03, 0.004, 0.0), (1.2, 0.4, -0.7), (2e-4, 4e-4, 5e-4)),
}
#: A weight welded to the coupler by a fixed joint: one body with it.
WELDED = (0.25, (0.1, 0.02, 0.005))
#: Where the four-bar hangs: tilted and shifted in space.
MOUNT = '<origin xyz="1 -2 0.5" rpy="0.4 -1.1 2.3"/>'


def _inertial(mass, xyz, rpy=(0.0, 0.0, 0.0), diagonal=(0.0, 0.0, 0.0)):
    ixx, iyy, izz = diagonal
    return (f'<inertial><mass value="{mass!r}"/><origin xyz="{" ".join(map(repr, xyz))}" '
            f'rpy="{" ".join(map(repr, rpy))}"/><inertia ixx="{ixx!r}" ixy="0" ixz="0" '
            f'iyy="{iyy!r}" iyz="0" izz="{izz!r}"/></inertial>')


def _urdf():
    """Khurmi's four-bar on a tilted mount, its links with inertials, a weight on the coupler."""
    text = khurmi_urdf()
    for link, (mass, xyz, rpy, diagonal) in INERTIALS.items():
        text = text.replace(f'<link name="{link}"/>',
                            f'<link name="{link}">{_inertial(mass, xyz, rpy, diagonal)}</link>')
    mass, xyz = WELDED
    weight = (f'<link name="weight">{_inertial(mass, (0.0, 0.0, 0.0))}</link>'
              f'<joint name="weight_mount" type="fixed"><parent link="coupler"/>'
              f'<child link="weight"/><origin xyz="{" ".join(map(repr, xyz))}"/></joint>')
    return text.replace(
        '<link name="frame"/>', '<link name="world"/><link name="frame"/><joint name="mount" '
        f'type="fixed"><parent link="world"/><child link="frame"/>{MOUNT}</joint>' + weight)


def _coms_3d(fk, values):
    """Return each moving link group's centre of mass in the world frame (the URDF's FK)."""
    frames = fk.transforms(values)
    out = {}
    for link, (mass, xyz, rpy, _) in INERTIALS.items():
        out.setdefault(link, []).append((mass, (frames[link] @ transform(xyz, rpy))[:3, 3]))
    mass, xyz = WELDED
    out['coupler'].append((mass, (frames['weight'] @ transform((0, 0, 0)))[:3, 3]))
    return {link: sum(m * p for m, p in parts) / sum(m for m, _ in parts)
            for link, parts in out.items()}


def test_the_scene_masses_are_the_urdfs_inertials_projected_on_the_plane():
    """Mass totals, and each centre of mass where the URDF's FK puts it, at several poses."""
    text = _urdf()
    robot = load_robot(text)
    masses = robot.planar.masses
    assert set(masses) == set(INERTIALS)
    assert masses['coupler']['mass'] == pytest.approx(1.1 + 0.25, rel=1e-15)
    assert masses['crank']['mass'] == 0.4
    scene = mk.parse_scene({**robot.planar.data, 'masses': masses})
    fk = UrdfFk(text)
    [mechanism] = robot.planar.mechanisms
    ground = fk.transforms({})[mechanism['ground']]
    e1, e2 = (ground[:3, :3] @ np.array(mechanism[axis]) for axis in ('x', 'y'))
    # The scene's plane: its x and y in the world, its origin shifted along x: the motor's
    # pin (the origin of link "frame") is where the scene's ground point says.
    motor = fk.transforms({})['frame'][:3, 3] - ground[:3, 3]
    shift = complex(*robot.planar.data['ground']['motor']) - complex(motor @ e1, motor @ e2)
    assert shift.imag == pytest.approx(0.0, abs=1e-15)
    for motor in (0.0, 0.7, -1.9, 2.8):
        answer = robot.solve({'motor': motor})
        values = {name: joint.position for name, joint in answer.joints.items()}
        [angle], _, _ = robot.scene_inputs({'motor': (motor, 0.0, 0.0)})
        state = mk.solve(scene, angle)
        coms = _coms_3d(fk, values)
        frames = frames_from_scene(scene, list(masses))
        poses = {p.joint: p for p in poses_from_state(frames, state)}
        for body, spec in masses.items():
            pose = poses[body]
            com = complex(pose.x, pose.y) + complex(*spec['com']) * complex(
                math.cos(pose.angle), math.sin(pose.angle))
            c = coms[body] - ground[:3, 3]
            expected = complex(c @ e1, c @ e2)
            assert abs(com - (expected + shift)) <= 1e-12, (motor, body, com, expected)


def test_the_inertia_about_the_normal_turns_the_tensor_and_adds_welded_links():
    """n.R I R^T.n for a turned inertial, plus m d^2 for a weight welded at a distance."""
    masses = load_robot(_urdf()).planar.masses
    mass, xyz, rpy, diagonal = INERTIALS['rocker']
    rotation = transform((0, 0, 0), rpy)[:3, :3]
    normal = np.array([0.0, 0.0, -1.0])     # the rocker's axis: the same line either way
    tensor = rotation @ np.diag(diagonal) @ rotation.T
    assert masses['rocker']['inertia'] == pytest.approx(normal @ tensor @ normal, rel=1e-12)
    mass, xyz, _, diagonal = INERTIALS['coupler']
    w_mass, w_xyz = WELDED
    com = (mass * np.array(xyz[:2]) + w_mass * np.array(w_xyz[:2])) / (mass + w_mass)
    expected = (diagonal[2] + mass * np.sum((np.array(xyz[:2]) - com) ** 2)
                + w_mass * np.sum((np.array(w_xyz[:2]) - com) ** 2))
    assert masses['coupler']['inertia'] == pytest.approx(expected, rel=1e-12)


def test_urdf2scene_writes_the_masses_and_the_planes_axes_for_gravity(tmp_path, capsys):
    """The YAML has masses: a scene that loads with forces; its header gives the plane's axes."""
    path = tmp_path / 'robot.urdf'
    path.write_text(_urdf())
    assert cli_main(['urdf2scene', str(path)]) == 0
    out = capsys.readouterr().out
    assert '# gravity: [gx, gy] in the scene frame' in out
    data = yaml.safe_load(out)
    assert set(data['masses']) == set(INERTIALS)
    scene = mk.parse_scene({**data, 'gravity': [0.0, -9.81]})
    assert scene.dynamics is not None
    state = mk.solve(scene, scene.input.angle, 3.0, 0.0)
    assert math.isfinite(state.forces.efforts['crank'])


def test_a_negative_mass_is_one_line_naming_the_link(tmp_path, capsys):
    """<mass value="-1"/>: refused, the link named."""
    path = tmp_path / 'robot.urdf'
    path.write_text(_urdf().replace('<mass value="0.7"/>', '<mass value="-0.7"/>'))
    assert cli_main(['urdf2scene', str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and 'link "rocker"' in err[0] and '-0.7' in err[0], err
