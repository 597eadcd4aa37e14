# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A scene written out: as YAML (``urdf2scene``) and as a robot description (URDF).

:func:`scene_yaml` writes the scene a robot's loops become, with a header
saying how each URDF joint follows the scene's coordinates.

:func:`robot_urdf_from_scene` writes a scene as a real robot description:
a spanning tree of the mechanism's graph (from the ground, the drivers'
joints and the prismatic joints taken first) as revolute and prismatic
joints, every other joint (a pin) as a ``<constraint type="revolute">``
element (ros/urdfdom#264), and a ``<transmission>`` per driver, so that
:func:`~.robot.load_robot` reads it back as the same mechanism. Each link's
frame has the orientation of the body's ``/tf`` frame and its origin at the
pin (or sliding point) by which the tree reaches it, so the zero pose is the
scene's drivers' start; its visuals are those of the floating description
(:mod:`mech_kinematics.geometry.urdf`). A Geneva wheel's intermittent slot
has no form in a URDF: refused. Pure: the standard library and NumPy.
"""

from __future__ import annotations

import cmath
from collections.abc import Mapping
import math
from typing import Any
import xml.etree.ElementTree as ET

import yaml

from .planar import Planar
from ..errors import UrdfError
from ..geometry.frames import child_frame, FrameSpec, poses_from_state
from ..geometry.instant_centres import full_scene
from ..geometry.urdf import _add_visuals, _assembled, _fmt, COLOURS, Visual, visuals_from_scene
from ..solver import Scene

__all__ = ['robot_urdf_from_scene', 'scene_yaml']


def scene_yaml(planar: Planar, source: str,
               reactions: Mapping[str, Mapping[str, Any]] | None = None) -> str:
    """Return the scene mapping of a robot's loops as YAML, with how its joints follow it.

    ``reactions``: the robot's :func:`~.forces.reaction_maps` (with masses),
    written as ``urdf_reactions``: what the view draws its reactions with.
    """
    lines = [f'# The planar loops of {source}, as a scene (docs/urdf.md).',
             '# Each URDF joint of a loop is its value in the reference pose plus sigma times',
             "# the change of the scene's coordinates it follows (rad or m):"]
    for item in planar.joints.values():
        if item.type.angular:
            ends = ((item.child, item.child_ref), (item.parent, item.parent_ref))
            parts = [f'{name} - {ref!r}' for name, ref in ends if name is not None]
            turn = ' - '.join(f'({p})' for p in parts) or '0'
        else:
            turn = f'{item.slider} - {item.slider_ref!r}'
        sign = '+' if item.sigma > 0 else '-'
        lines.append(f'#   {item.name} = {item.reference!r} {sign} ({turn})')
    for driver in planar.drivers:
        lines.append(f'# driver {driver.scene} = {driver.scene_ref!r} '
                     f'{"+" if driver.sigma > 0 else "-"} ({driver.name} - {driver.reference!r})'
                     + (f' ({driver.name} mimics {driver.mimic.joint})' if driver.mimic else ''))
    if planar.names:
        lines.append('# Scene names of URDF names: '
                     + ', '.join(f'{k} -> {v}' for k, v in planar.names.items()))
    data = dict(planar.data)
    if planar.masses:
        lines.append("# masses: from each link's <inertial> (welded links added up); the URDF has "
                     'no gravity: add')
        lines.append('# gravity: [gx, gy] in the scene frame, whose x and y are, in the ground '
                     "link's frame:")
        for mechanism in planar.mechanisms:
            lines.append(f"#   {mechanism['ground']}: x {_vector(mechanism['x'])}, "
                         f"y {_vector(mechanism['y'])}")
        data['masses'] = planar.masses
    if planar.drivers:  # what the view needs to draw the robot from its joint_states
        data['urdf_drivers'] = {d.scene: {'joint': d.name, 'joint_reference': float(d.reference),
                                          'reference': float(d.scene_ref),
                                          'factor': float(d.sigma)} for d in planar.drivers}
    if reactions:   # where each reactions/JOINT acts in the plane, and how its axes turn
        data['urdf_reactions'] = {name: dict(item) for name, item in reactions.items()}
    body = yaml.safe_dump(data, sort_keys=False, default_flow_style=None, width=99)
    return '\n'.join(lines) + '\n' + body


def _vector(values: Any) -> str:
    return '[' + ', '.join(f'{float(v):.12g}' for v in values) + ']'


def _priority(joint: Any) -> int:
    """Order the tree takes the graph's joints in: drivers, prismatic joints, then pins."""
    if joint.driver:
        return 0
    return 2 if joint.type.angular else 1


def robot_urdf_from_scene(scene: Scene, frame_id: str = 'mechanism', prefix: str = '') -> str:
    """Return a scene as a robot description: a tree of joints, each loop closed by a constraint.

    Parameters
    ----------
    scene : Scene
        The mechanism (drawn at its drivers' start: the URDF's zero pose).
    frame_id : str
        The root link: the ground.
    prefix : str
        Other links are ``<prefix>/<body>``; ``''`` means ``frame_id``.

    Raises
    ------
    UrdfError
        For a scene with an intermittent drive (a Geneva wheel), which no URDF tree describes.
    AssemblyError
        If the scene assembles nowhere it is drawn.
    """
    prefix = prefix or frame_id
    graph = scene.graph
    for joint in graph.joints:
        if joint.intermittent:
            msg = (f'{scene.name}: Expected joints that act all the time, got "{joint.name}", '
                   f'an intermittent drive (a Geneva wheel), which a URDF tree with '
                   f'constraints cannot describe')
            raise UrdfError(msg, joint=joint.name)
    full = full_scene(scene)
    state = _assembled(full)
    points = {name: complex(p) for name, (p, _, _) in state.complex_points.items()}
    angles: dict[str, float] = {graph.ground: 0.0}
    origins: dict[str, complex] = {graph.ground: 0j}
    for pose in poses_from_state(_all_frames(scene), state):
        angles[pose.joint] = pose.angle     # the /tf frames' own rule (geometry/frames.py)
        origins[pose.joint] = complex(pose.x, pose.y)
    # The spanning tree: drivers' joints, then prismatic joints, then pins (Kruskal).
    parent = {body: body for body in graph.bodies}

    def find(x: str) -> str:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    tree, cuts = [], []
    for joint in sorted(graph.joints, key=_priority):
        if joint.type.table is None:
            continue
        a, b = find(joint.on), find(joint.body)
        if a != b:
            parent[a] = b
            tree.append(joint)
        else:
            cuts.append(joint)
    for joint in cuts:
        if not joint.type.angular:
            msg = (f'{scene.name}: Expected every loop to close at a pin, got prismatic joint '
                   f'"{joint.name}" left out of the tree')
            raise UrdfError(msg, joint=joint.name)
    # Orient the tree from the ground; each link's frame at its joint's point.
    order, at = [graph.ground], {graph.ground: 0j}
    edges = {}
    remaining = list(tree)
    while remaining:
        for joint in list(remaining):
            if joint.on in at or joint.body in at:
                up, down = (joint.on, joint.body) if joint.on in at else (joint.body, joint.on)
                edges[down] = (up, joint)
                at[down] = points[joint.at]
                order.append(down)
                remaining.remove(joint)
    names = {graph.ground: frame_id}
    names.update({body: child_frame(prefix, body) for body in graph.bodies
                  if body != graph.ground})

    def local(body: str, z: complex) -> complex:
        return (z - at[body]) * cmath.exp(-1j * angles[body])

    robot = ET.Element('robot', name=scene.name)
    for name, rgba in COLOURS.items():
        material = ET.SubElement(robot, 'material', name=name)
        ET.SubElement(material, 'color', rgba=_fmt(*rgba))
    visuals = _visuals(full, origins, angles, at)
    for body in order:
        link = ET.SubElement(robot, 'link', name=names[body])
        _add_visuals(link, visuals.get(body, []))
    for body in order[1:]:
        up, joint = edges[body]
        name = joint.name.replace('/', '__')
        element = ET.SubElement(robot, 'joint', name=name,
                                type='revolute' if joint.type.angular else 'prismatic')
        ET.SubElement(element, 'parent', link=names[up])
        ET.SubElement(element, 'child', link=names[body])
        offset = local(up, at[body])
        ET.SubElement(element, 'origin', xyz=_fmt(offset.real, offset.imag, 0.0),
                      rpy=_fmt(0.0, 0.0, math.remainder(angles[body] - angles[up], math.tau)))
        if joint.type.angular:
            ET.SubElement(element, 'axis', xyz='0 0 1')
            ET.SubElement(element, 'limit', lower=_fmt(-math.pi), upper=_fmt(math.pi),
                          effort='0', velocity='0')
        else:
            line = joint.line
            direction = line.angle + (0.0 if line.angle_of is None else
                                      float(state.joints[line.angle_of].position))
            sign = 1.0 if body == joint.body else -1.0
            axis = sign * cmath.exp(1j * (direction - angles[body]))
            ET.SubElement(element, 'axis', xyz=_fmt(axis.real, axis.imag, 0.0))
            ET.SubElement(element, 'limit', lower='-1000', upper='1000', effort='0',
                          velocity='0')
    for joint in cuts:
        element = ET.SubElement(robot, 'constraint', name=joint.name.replace('/', '__'),
                                type='revolute')
        for end, body in (('parent', joint.on), ('child', joint.body)):
            ET.SubElement(element, end, link=names[body])
            z = local(body, points[joint.at])
            ET.SubElement(element, f'{end}_origin', xyz=_fmt(z.real, z.imag, 0.0), rpy='0 0 0')
            ET.SubElement(element, f'{end}_axis', xyz='0 0 1')
    for joint in tree:
        if joint.driver:
            name = joint.name.replace('/', '__')
            transmission = ET.SubElement(robot, 'transmission', name=f'{name}_transmission')
            ET.SubElement(transmission, 'type').text = \
                'transmission_interface/SimpleTransmission'
            element = ET.SubElement(transmission, 'joint', name=name)
            ET.SubElement(element, 'hardwareInterface').text = \
                'hardware_interface/PositionJointInterface'
            actuator = ET.SubElement(transmission, 'actuator', name=f'{name}_motor')
            ET.SubElement(actuator, 'mechanicalReduction').text = '1'
    ET.indent(robot)
    return '<?xml version="1.0"?>\n' + ET.tostring(robot, encoding='unicode') + '\n'


def _visuals(scene: Scene, origins: dict[str, complex], angles: dict[str, float],
             at: dict[str, complex]) -> dict[str, list[Visual]]:
    """Return each body's visuals (the floating description's), moved to its link's frame."""
    _, shapes = visuals_from_scene(scene, _all_frames(scene))
    out = {}
    for body, items in shapes.items():
        if body not in at:
            continue
        shift = (origins[body] - at[body]) * cmath.exp(-1j * angles[body])
        out[body] = [Visual(v.shape, v.size, (v.xyz[0] + shift.real, v.xyz[1] + shift.imag,
                                              v.xyz[2]), v.yaw, v.material) for v in items]
    return out


def _all_frames(scene: Scene) -> Any:
    return tuple(FrameSpec(body, f.origin, f.angle_of, f.angle)
                 for body, f in scene.graph.frames())
