# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``tf2_msgs/msg/TFMessage`` of the link frames (``/tf``) and the ground points (``/tf_static``).

The frames are those of :mod:`mech_kinematics.geometry.frames`, each named
``<prefix>/<joint>`` (a ground point ``<prefix>/<point>``), children of the
node's ``frame_id``, in the plane z = 0: a rotation about z by the frame's
angle. :class:`TfMessages` renders the ``/tf`` message of a tick from a
pre-serialized template (:class:`~mech_kinematics.ros.cdr.MessageTemplate`), as
the node's other messages are; :func:`static_tf_message` builds the
``/tf_static`` message once.

``tf2_msgs`` is imported inside the functions: it is not among the PyPI
wheels and is built at set-up time (``scripts/build_tf2_msgs.py``); without
it the node runs with ``/tf`` off.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
import math
from typing import Any

from .cdr import marker, MessageTemplate, STAMP_MARKER
from ..geometry.frames import child_frame, FrameSpec, Pose

__all__ = ['TfMessages', 'child_frame', 'static_tf_message']

#: The absolute topics every TF broadcaster uses (namespaces do not apply).


def _transform(parent: str, child: str, stamp: Any, x: float, y: float, angle: float) -> Any:
    from geometry_msgs.msg import TransformStamped

    t = TransformStamped()
    t.header.stamp = stamp
    t.header.frame_id = parent
    t.child_frame_id = child
    t.transform.translation.x = x
    t.transform.translation.y = y
    t.transform.rotation.z = math.sin(angle / 2)
    t.transform.rotation.w = math.cos(angle / 2)
    return t


class TfMessages:
    """The ``/tf`` message of the link and slider frames, rendered as CDR bytes from a template.

    Parameters
    ----------
    frames : sequence of FrameSpec
        The frames, in publish order.
    parent : str
        The parent frame (the node's ``frame_id``).
    prefix : str
        Prefix of the child frames.
    """

    def __init__(self, frames: Sequence[FrameSpec], parent: str, prefix: str) -> None:
        from builtin_interfaces.msg import Time
        from geometry_msgs.msg import TransformStamped
        from tf2_msgs.msg import TFMessage

        self.frames = tuple(frames)
        self.children = tuple(child_frame(prefix, f.joint) for f in self.frames)
        stamp = Time(sec=STAMP_MARKER[0], nanosec=STAMP_MARKER[1])
        transforms = []
        for i, child in enumerate(self.children):
            t = TransformStamped()
            t.header.stamp = stamp
            t.header.frame_id = parent
            t.child_frame_id = child
            t.transform.translation.x = marker(4 * i)
            t.transform.translation.y = marker(4 * i + 1)
            t.transform.rotation.z = marker(4 * i + 2)
            t.transform.rotation.w = marker(4 * i + 3)
            transforms.append(t)
        self._template = MessageTemplate(TFMessage(transforms=transforms), 4 * len(transforms))

    def render(self, poses: Sequence[Pose], sec: int, nanosec: int) -> bytes:
        """Return the serialized ``TFMessage`` of ``poses`` (in frame order), stamped alike."""
        flat: list[float] = []
        for pose in poses:
            flat += (pose.x, pose.y, pose.angle)
        return self.render_values(flat, 0, sec, nanosec)

    def render_values(self, values: Sequence[float], first: int, sec: int,
                      nanosec: int) -> bytes:
        """Return the ``TFMessage`` of the poses ``values[first:]`` as (x, y, angle) triples."""
        out: list[float] = []
        sin, cos = math.sin, math.cos
        for i in range(first, first + 3 * len(self.frames), 3):
            half = 0.5 * values[i + 2]
            out += (values[i], values[i + 1], sin(half), cos(half))
        return self._template.render(sec, nanosec, out)


def static_tf_message(ground: Mapping[str, tuple[float, float]], parent: str, prefix: str,
                      stamp: Any) -> Any:
    """Return the ``/tf_static`` ``TFMessage``: a frame at every ground point (no rotation)."""
    from tf2_msgs.msg import TFMessage

    return TFMessage(transforms=[
        _transform(parent, child_frame(prefix, name), stamp, float(x), float(y), 0.0)
        for name, (x, y) in ground.items()])
