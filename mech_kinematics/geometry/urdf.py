# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A URDF of a scene's bodies on the frames the node puts on ``/tf`` (``robot_description``).

RViz's RobotModel display and Foxglove's URDF layer draw each URDF link at the
pose ``/tf`` gives its frame, so the URDF's links are named exactly as the
node's frames (:mod:`mech_kinematics.geometry.frames`, named
``<prefix>/<name>`` under ``frame_id``, as :mod:`mech_kinematics.ros.tf`
publishes them):

- the root link ``frame_id`` (the ground frame), nothing drawn;
- one link per ground point ``<prefix>/<point>`` (``/tf_static``), a fixed
  joint at the point, drawn as a pin (a cylinder along z);
- one link per frame on ``/tf`` ``<prefix>/<joint>``, a floating joint (the
  pose comes from ``/tf``), drawn in the frame's own coordinates: a bar
  (box) from the frame's origin to every other point of the body, a pin at
  each of its points; a slotted lever reaches as far as its pin goes in a
  turn; a slider is a block along its x axis (the guide);
- one link per IMU with a frame of its own (``angle`` not 0),
  ``<prefix>/<name>``, nothing drawn, a fixed joint to its link's frame at
  the sensor's point, turned by ``angle`` (as the node's ``/tf`` has it).

The body's points are read off the solved scene at the first crank angle
that assembles, in the frame's coordinates; they are fixed on the body, so
this holds at every angle. Pure: NumPy and the standard library
(``xml.etree``).
"""

from __future__ import annotations

from collections.abc import Sequence
import math
from typing import Any
import warnings
import xml.etree.ElementTree as ET

import numpy as np

from .diagrams import space_from_state
from .frames import child_frame, frames_from_scene, FrameSpec, poses_from_state, sensor_offsets
from .instant_centres import bodies_from_scene, BodyKind, full_scene
from ..errors import NearSingularWarning
from ..solver import Scene, solve, State

__all__ = ['Visual', 'joint_name', 'urdf_from_scene', 'visuals_from_scene']

#: Crank angles tried for a pose that assembles, and sampled for a lever's reach.
SAMPLES = 72

#: Bar width, block size and pin radius as fractions of the mechanism's size.
BAR_WIDTH = 0.02
PIN_RADIUS = 0.015
BLOCK_LENGTH = 0.08
THICKNESS = 0.01

COLOURS = {'crank': (0.84, 0.15, 0.16, 1.0),
           'link': (0.12, 0.47, 0.71, 1.0), 'lever': (0.17, 0.63, 0.17, 1.0),
           'slider': (1.0, 0.5, 0.05, 1.0), 'pin': (0.1, 0.1, 0.1, 1.0)}


def joint_name(child: str) -> str:
    """Return the URDF joint that attaches link ``child`` to the root."""
    return f'{child}_joint'


class Visual:
    """One shape of a link, in the link's frame (m, rad).

    Attributes
    ----------
    shape : {'box', 'cylinder'}
        A box of ``size`` (x, y, z) or a cylinder of ``size`` (radius, length) along z.
    xyz : (float, float, float)
        Its centre.
    yaw : float
        Its rotation about z.
    material : str
        A key of :data:`COLOURS`.
    """

    def __init__(self, shape: str, size: Sequence[float], xyz: Sequence[float], yaw: float,
                 material: str) -> None:
        self.shape, self.size, self.xyz, self.yaw, self.material = \
            shape, tuple(size), tuple(xyz), yaw, material


def _bar(x: float, y: float, width: float, material: str) -> Visual:
    """Return a bar from the origin to (x, y)."""
    return Visual('box', (math.hypot(x, y), width, THICKNESS * width / BAR_WIDTH),
                  (x / 2, y / 2, 0.0), math.atan2(y, x), material)


def _pin(x: float, y: float, radius: float) -> Visual:
    return Visual('cylinder', (radius, 4 * radius), (x, y, 0.0), 0.0, 'pin')


def _assembled(scene: Scene) -> State:
    """Return the full state at the scene's crank angle, or the first angle that assembles.

    A scene with several drivers (or an actuator) is drawn where its drivers start.

    Raises
    ------
    AssemblyError
        The solver's, where the drivers start (or, for one crank, at its
        angle, when no angle over a turn can be solved).
    """
    drivers = scene.drivers
    if scene.input is None or len(drivers) > 1:
        starts = [driver.start for driver in drivers]
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', NearSingularWarning)
            # One driver (an actuator) takes solve's one-driver signature: a bare value.
            return solve(scene, starts[0] if len(starts) == 1 else starts)
    angles = scene.input.angle + np.linspace(0.0, 2 * math.pi, SAMPLES, endpoint=False)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', NearSingularWarning)
        states = solve(scene, angles)
        valid = np.flatnonzero(states.valid)
        if not valid.size:
            # None of them: the solver's own refusal at the scene's crank angle says why.
            return solve(scene, scene.input.angle, turns=scene.input.turns)
        return solve(scene, float(angles[valid[0]]))


def _stroke(actuator: Any) -> tuple[float, float]:
    """Return an actuator's shortest and longest lengths, m (its start where it has no stroke)."""
    return actuator.stroke if actuator.stroke is not None else (actuator.start, actuator.start)


def _local(origin: complex, angle: float, point: complex) -> tuple[float, float]:
    z = (point - origin) * complex(math.cos(angle), -math.sin(angle))
    return z.real, z.imag


def _lever_reach(scene: Scene, ends: tuple[str, str]) -> float:
    """Return the farthest the pin goes along a slotted lever over a turn, m.

    ``ends`` are the lever's pivot and the pin that slides along it.
    """
    angles = scene.input.angle + np.linspace(0.0, 2 * math.pi, SAMPLES, endpoint=False)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', NearSingularWarning)
        states = solve(scene, angles)
    points = states.complex_points
    gap = np.abs(points[ends[1]][0] - points[ends[0]][0])[states.valid]
    return float(gap.max()) if gap.size else 0.0


def visuals_from_scene(scene: Scene, frames: Sequence[FrameSpec] | None = None,
                       ) -> tuple[list[Visual], dict[str, list[Visual]]]:
    """Return a ground point's pin and the visuals of each frame's body, in its frame.

    ``frames`` defaults to the frames of the scene's output joints (those the
    node puts on ``/tf``).
    """
    frames = frames_from_scene(scene) if frames is None else tuple(frames)
    full = full_scene(scene)
    state = _assembled(full)
    space = space_from_state(full, state)
    low, high = space.extent()
    size = float(np.hypot(*(high - low))) or 1.0
    width, radius = BAR_WIDTH * size, PIN_RADIUS * size
    topology = bodies_from_scene(full)
    # An actuator is a prismatic joint between its two pins: the cylinder's body (the
    # link it drives, at its start pin) is drawn as a barrel as long as the actuator
    # at its shortest, its rod (the actuator's frame, at the other pin) reaching back
    # by the stroke.
    graph = full.graph
    drivers = {d.name: d for d in full.drivers}
    slides = [j for j in graph.joints if j.line is not None]
    rods = tuple(graph.cylinders())
    actuators = {j.name: drivers[j.name] for j in rods}
    cylinders = {j.on: drivers[j.name] for j in rods}
    # A link whose length varies (a slotted lever) is drawn out to the farthest its
    # pin slides: from its slot's point to the pin.
    levers = {j.on: (j.line.through, j.at) for j in slides  # type: ignore[union-attr]
              if not j.driver and j.line.angle_of == j.on}  # type: ignore[union-attr]
    points = {name: complex(p) for name, (p, _, _) in state.complex_points.items()}
    visuals: dict[str, list[Visual]] = {}
    for frame, pose in zip(frames, poses_from_state(frames, state), strict=True):
        origin = complex(pose.x, pose.y)
        shapes: list[Visual] = []
        if frame.joint in actuators or frame.joint in cylinders:
            shortest, longest = _stroke(actuators.get(frame.joint) or cylinders[frame.joint])
            if frame.joint in actuators:  # the rod, from its pin back into the barrel
                shapes.append(_bar(-(longest - shortest) - 0.1 * shortest, 0.0, 0.6 * width,
                                   'slider'))
            else:  # the barrel, from its pin
                shapes.append(_bar(0.9 * shortest, 0.0, 1.8 * width, 'link'))
            shapes.append(_pin(0.0, 0.0, radius))
            visuals[frame.joint] = shapes
            continue
        body = topology.bodies[frame.joint]
        if body.kind is BodyKind.SLIDER:
            shapes.append(Visual('box', (BLOCK_LENGTH * size, 2.5 * width, 1.5 * width),
                                 (0.0, 0.0, 0.0), 0.0, 'slider'))
        else:
            material = body.kind.value
            on_body = [_local(origin, pose.angle, points[name]) for name in body.points]
            for x, y in on_body:
                if math.hypot(x, y) > 1e-9 * size:
                    shapes.append(_bar(x, y, width, material))
            if frame.joint in levers:
                shapes.append(_bar(_lever_reach(full, levers[frame.joint]), 0.0, width,
                                   material))
            shapes += [_pin(x, y, radius) for x, y in on_body]
        visuals[frame.joint] = shapes
    return [_pin(0.0, 0.0, 1.5 * radius)], visuals


def _fmt(*values: float) -> str:
    # Exact (shortest round trip); round-off below a picometre (or picoradian) is written 0.
    return ' '.join(repr(float(v if abs(v) >= 1e-12 else 0.0) + 0.0) for v in values)


def _add_visuals(link: ET.Element, shapes: Sequence[Visual]) -> None:
    for shape in shapes:
        visual = ET.SubElement(link, 'visual')
        ET.SubElement(visual, 'origin', xyz=_fmt(*shape.xyz), rpy=_fmt(0.0, 0.0, shape.yaw))
        geometry = ET.SubElement(visual, 'geometry')
        if shape.shape == 'box':
            ET.SubElement(geometry, 'box', size=_fmt(*shape.size))
        else:
            ET.SubElement(geometry, 'cylinder', radius=_fmt(shape.size[0]),
                          length=_fmt(shape.size[1]))
        ET.SubElement(visual, 'material', name=shape.material)


def urdf_from_scene(scene: Scene, frame_id: str = 'mechanism', prefix: str = '') -> str:
    """Return the URDF (XML text) of ``scene`` on the node's frames.

    Parameters
    ----------
    scene : Scene
        The mechanism.
    frame_id : str
        The root link: the node's ``frame_id``.
    prefix : str
        The node's ``tf_prefix``; ``''`` means ``frame_id``, as for the node.

    Returns
    -------
    str
        The URDF document, one link per frame on ``/tf`` and ``/tf_static``
        plus the root, each attached to the root by one joint (an IMU's own
        frame to its link's).

    Raises
    ------
    AssemblyError
        If the scene assembles at no crank angle.
    """
    prefix = prefix or frame_id
    pin, visuals = visuals_from_scene(scene)
    robot = ET.Element('robot', name=scene.name)
    for name, rgba in COLOURS.items():
        material = ET.SubElement(robot, 'material', name=name)
        ET.SubElement(material, 'color', rgba=_fmt(*rgba))
    ET.SubElement(robot, 'link', name=frame_id)
    # Ground points: fixed where /tf_static puts them; bodies: floating, posed by /tf.
    attachments: list[tuple[str, list[Visual], tuple[float, float] | None]] = [
        (child_frame(prefix, name), pin, (float(x), float(y)))
        for name, (x, y) in scene.ground.items()]
    attachments += [(child_frame(prefix, joint), shapes, None)
                    for joint, shapes in visuals.items()]
    # An actuator's rod hangs on its cylinder's body by a prismatic joint along it.
    outputs = set(scene.output_joints)
    rods = {child_frame(prefix, j.body): (child_frame(prefix, j.on), j.name)
            for j in scene.graph.cylinders() if j.body in outputs and j.on in outputs}
    for child, shapes, at in attachments:
        link = ET.SubElement(robot, 'link', name=child)
        _add_visuals(link, shapes)
        if child in rods:
            body, name = rods[child]
            element = ET.SubElement(robot, 'joint', name=joint_name(child), type='prismatic')
            ET.SubElement(element, 'parent', link=body)
            ET.SubElement(element, 'child', link=child)
            ET.SubElement(element, 'axis', xyz='1 0 0')
            low, high = _stroke(next(d for d in scene.drivers if d.name == name))
            ET.SubElement(element, 'limit', lower=_fmt(low), upper=_fmt(high), effort='0',
                          velocity='0')
            continue
        element = ET.SubElement(robot, 'joint', name=joint_name(child),
                                type='floating' if at is None else 'fixed')
        ET.SubElement(element, 'parent', link=frame_id)
        ET.SubElement(element, 'child', link=child)
        if at is not None:
            ET.SubElement(element, 'origin', xyz=_fmt(*at, 0.0), rpy='0 0 0')
    _add_sensors(robot, scene, prefix)
    ET.indent(robot)
    return '<?xml version="1.0"?>\n' + ET.tostring(robot, encoding='unicode') + '\n'


def _add_sensors(robot: ET.Element, scene: Scene, prefix: str) -> None:
    """Add a link and a fixed joint for every IMU with a frame of its own (``angle`` not 0)."""
    own = [spec for spec in scene.imus if spec.angle != 0.0]
    if not own:
        return
    full = full_scene(scene)
    frames = {f.joint: f for f in frames_from_scene(full, [spec.link for spec in own])}
    offsets = sensor_offsets(own, frames, _assembled(full))
    for spec in own:
        child = child_frame(prefix, spec.name)
        ET.SubElement(robot, 'link', name=child)
        element = ET.SubElement(robot, 'joint', name=joint_name(child), type='fixed')
        ET.SubElement(element, 'parent', link=child_frame(prefix, spec.link))
        ET.SubElement(element, 'child', link=child)
        ET.SubElement(element, 'origin', xyz=_fmt(*offsets[spec.name], 0.0),
                      rpy=_fmt(0.0, 0.0, spec.angle))
