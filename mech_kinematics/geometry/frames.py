# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A coordinate frame on every moving link and slider block of a scene (for ``/tf``).

A link's frame has its origin at the point the link starts from in the scene
(the crank's ``center``, a dyad link's ``from``, an RPR lever's ``center``)
and its x axis along the link, at the link's angle (its joint position); a
point carried by the link at ``local`` coordinates in the scene sits at the
same coordinates in this frame when the link starts at its ``origin``. A
slider's frame sits at the block (an RRP's new point, an RPR's pin) with its
x axis along the guide (an RRP's fixed guide direction, an RPR's lever).

:func:`frames_from_scene` names the frames once; :func:`poses_from_state`
reads their poses off a solved state. Pure geometry: NumPy only.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
import math
from typing import Any

import numpy as np

from ..solver import Scene, State

__all__ = ['FrameSpec', 'Pose', 'angle_joints', 'carried_motion', 'child_frame',
           'frames_from_scene', 'origin_points', 'poses_from_state', 'sensor_offsets']


@dataclass(frozen=True)
class FrameSpec:
    """Where a joint's frame sits.

    Attributes
    ----------
    joint : str
        The link or slider the frame belongs to (the child frame's last part).
    origin : str
        The point at the frame's origin.
    angle_of : str or None
        The joint whose position is the frame's angle, or ``None`` for a fixed
        ``angle`` (an RRP guide).
    angle : float
        The fixed angle, rad (when ``angle_of`` is ``None``).
    """

    joint: str
    origin: str
    angle_of: str | None
    angle: float = 0.0


@dataclass(frozen=True)
class Pose:
    """A frame's pose in the ground frame: origin (m) and angle (rad, CCW from +x)."""

    joint: str
    x: float
    y: float
    angle: float


def child_frame(prefix: str, name: str) -> str:
    """Return the frame id of link, slider or ground point ``name``: ``<prefix>/<name>``."""
    return f'{prefix}/{name}' if prefix else name


def frames_from_scene(scene: Scene, joints: Sequence[str] | None = None) -> tuple[FrameSpec, ...]:
    """Return the frames of ``joints`` (default: the scene's output joints), in that order.

    A joint that moves no body of its own (a motor's relative angle: its hinge's
    link has the frame) has none.
    """
    graph = scene.graph
    specs = {body: FrameSpec(body, frame.origin, frame.angle_of, frame.angle)
             for body, frame in graph.frames()}
    names = scene.output_joints if joints is None else joints
    return tuple(specs[name] for name in names
                 if name in specs or name not in graph.coordinates)


def origin_points(frames: Sequence[FrameSpec]) -> tuple[str, ...]:
    """Return the points whose positions the frames need, each once, in order."""
    return tuple(dict.fromkeys(f.origin for f in frames))


def angle_joints(frames: Sequence[FrameSpec]) -> tuple[str, ...]:
    """Return the joints whose positions the frames take their angles from, each once."""
    return tuple(dict.fromkeys(f.angle_of for f in frames if f.angle_of is not None))


def poses_from_state(frames: Sequence[FrameSpec], state: State) -> list[Pose]:
    """Return the pose of every frame in a state solved for one crank angle.

    ``state`` must hold every point of :func:`origin_points` and every joint
    the frames take their angle from.
    """
    points, joints = state.complex_points, state.joints
    poses = []
    for f in frames:
        p = points[f.origin][0]
        angle = f.angle if f.angle_of is None else float(joints[f.angle_of].position)
        poses.append(Pose(f.joint, float(p.real), float(p.imag), angle))
    return poses


def carried_motion(frame: FrameSpec, local: tuple[float, float], state: State
                   ) -> tuple[Any, Any]:
    """Return the position and velocity (complex, m and m/s) of a point fixed in a frame.

    ``local`` is the point in ``frame`` (its x and y, m); ``state`` one instant
    or arrays, holding the frame's origin and the joint it takes its angle
    from. The frame's angle is :func:`poses_from_state`'s; the point moves
    with the frame's origin and turns with its angle: ``p = o + e^(i theta) l``,
    ``v = v_o + i omega e^(i theta) l``.
    """
    origin = state.complex_points[frame.origin]
    lever = complex(*local)
    if frame.angle_of is None:
        turned = complex(math.cos(frame.angle), math.sin(frame.angle)) * lever
        return origin[0] + turned, origin[1]
    joint = state.joints[frame.angle_of]
    turned = np.exp(1j * np.asarray(joint.position, dtype=np.float64)) * lever
    return origin[0] + turned, origin[1] + 1j * np.asarray(joint.velocity) * turned


def sensor_offsets(specs: Sequence[Any], frames: Mapping[str, FrameSpec],
                   state: State) -> dict[str, tuple[float, float]]:
    """Return each IMU's point in its link's frame (``frames[spec.link]``), m.

    ``specs`` are :class:`~mech_kinematics.imu.ImuSpec`; the point is fixed on
    the link, so one solved instant gives the coordinates of every instant (to
    rounding). ``state`` must hold each frame's origin, its link and point: a
    sensor's own frame (``angle`` not 0) is this offset, turned by ``angle``.
    """
    offsets = {}
    for spec in specs:
        frame = frames[spec.link]
        theta = float(state.joints[spec.link].position)
        d = complex(state.complex_points[spec.point][0]) - complex(
            state.complex_points[frame.origin][0])
        z = d * complex(math.cos(theta), -math.sin(theta))
        offsets[spec.name] = (z.real, z.imag)
    return offsets
