# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""RViz markers of a solved scene: the space diagram and the velocity and acceleration arrows.

:func:`marker_array_from_state` turns the pure geometry of
:mod:`mech_kinematics.diagram` (:func:`~mech_kinematics.diagram.space_from_state`,
:func:`~mech_kinematics.diagram.arrows_from_state`) into a
``visualization_msgs/msg/MarkerArray``, in the plane z = 0. The message
packages are imported inside the function, so this module imports with NumPy
alone. :class:`MarkerThrottle` picks the ticks of the node that publish
markers (at most :data:`MAX_RATE_HZ`, whatever the tick rate).

The array holds, in this order (``ns``, ``id``):

- ``links``, 0 .. n-1: one ``LINE_STRIP`` per moving link (its outline, closed
  for a link of more than two points);
- ``guides``, 0: one ``LINE_LIST`` of the fixed slider guides (if any);
- ``sliders``, 0 .. n-1: one ``CUBE`` per slider block, turned to its guide;
- ``actuators``, 0 .. n-1: one ``CYLINDER`` per link whose length is a linear
  actuator's, from pin to pin (its axis along the link);
- ``joints``, 0: one ``SPHERE_LIST`` of every named point, ground points dark;
- ``velocity``, 0 .. m-1: one ``ARROW`` per arrow point, from the point to
  point + ``velocity_scale`` * v;
- ``acceleration``, 0 .. m-1: the same with ``acceleration_scale`` * a;
- ``reactions``, 0 .. r-1: on a scene whose forces the node publishes, one
  ``ARROW`` per joint from its point to point + ``force_scale`` * F, F the
  force its reaction puts on the joint's body (:mod:`~mech_kinematics.ros.wrenches`;
  a lock's, a moment only, is an arrow of no length).

The count and the ids depend only on the scene, so every array replaces the
previous one in RViz.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
import math
from typing import Any

from ..geometry.diagrams import arrows_from_state, COLOURS, space_from_state, SpaceDiagram
from ..solver import Scene, State
from ..units import NS_PER_S

__all__ = [
    'DEFAULT_ACCELERATION_SCALE', 'DEFAULT_VELOCITY_SCALE', 'MAX_RATE_HZ', 'MarkerThrottle',
    'NAMESPACES', 'marker_array_from_state', 'marker_size_from_space',
]

#: Default arrow length per unit velocity, m per (m/s).
DEFAULT_VELOCITY_SCALE = 0.1
#: Default arrow length per unit acceleration, m per (m/s^2).
DEFAULT_ACCELERATION_SCALE = 0.01
#: Highest rate at which the node publishes markers, Hz.
MAX_RATE_HZ = 30.0
#: Marker namespaces, in the order of the array.
NAMESPACES = ('links', 'guides', 'sliders', 'actuators', 'joints', 'velocity',
              'acceleration', 'reactions')
#: The longest reaction arrow with ``force_scale`` 0 (automatic), a fraction of the size.
AUTO_FORCE_LENGTH = 0.3

# Sizes as fractions of the mechanism's size (marker_size_from_space).
LINE_WIDTH = 0.012
JOINT_DIAMETER = 0.035
SHAFT_DIAMETER = 0.010
HEAD_DIAMETER = 0.025
BLOCK_LENGTH = 0.07
BLOCK_HEIGHT = 0.04
ACTUATOR_DIAMETER = 0.03

# Colours as (r, g, b, a).
GROUND_RGBA = (0.2, 0.2, 0.2, 1.0)
POINT_RGBA = (0.95, 0.95, 0.95, 1.0)
GUIDE_RGBA = (0.35, 0.35, 0.35, 1.0)
SLIDER_RGBA = (0.55, 0.55, 0.6, 0.9)
ACTUATOR_RGBA = (0.9, 0.75, 0.1, 0.9)
VELOCITY_RGBA = (0.0, 0.6, 0.2, 1.0)
ACCELERATION_RGBA = (0.85, 0.1, 0.1, 1.0)
REACTION_RGBA = (0.75, 0.2, 0.85, 1.0)


def _rgba(colour: str) -> tuple[float, float, float, float]:
    """Return ``'#rrggbb'`` as (r, g, b, 1.0)."""
    r, g, b = (int(colour[i:i + 2], 16) / 255.0 for i in (1, 3, 5))
    return r, g, b, 1.0


def marker_size_from_space(space: SpaceDiagram) -> float:
    """Return the size of the mechanism drawn in ``space``: the larger side of its extent, m."""
    lo, hi = space.extent()
    size = float(max(hi - lo))
    return size if size > 0.0 else 1.0


def marker_array_from_state(scene: Scene, state: State, *, frame_id: str = 'mechanism',
                            stamp: Any = None,
                            velocity_scale: float = DEFAULT_VELOCITY_SCALE,
                            acceleration_scale: float = DEFAULT_ACCELERATION_SCALE,
                            points: Sequence[str] | None = None, size: float | None = None,
                            strokes: Mapping[str, tuple[float, float]] | None = None,
                            reactions: Sequence[tuple[complex, complex]] = (),
                            force_scale: float = 0.0) -> Any:
    """Return the mechanism of ``scene`` in ``state`` as a ``visualization_msgs/MarkerArray``.

    Parameters
    ----------
    scene : Scene
        The mechanism, not pruned by ``outputs`` (see
        :func:`~mech_kinematics.instant_centres.full_scene`).
    state : State
        Its solution at one crank angle.
    frame_id : str
        ``header.frame_id`` of every marker.
    stamp : builtin_interfaces.msg.Time, optional
        ``header.stamp`` of every marker; zero by default.
    velocity_scale : float
        Arrow length per unit velocity, m per (m/s), >= 0.
    acceleration_scale : float
        Arrow length per unit acceleration, m per (m/s^2), >= 0.
    points : sequence of str, optional
        Points that get a velocity and an acceleration arrow; by default every
        moving point of ``state``.
    size : float, optional
        Size of the mechanism, m, which sets line widths, sphere and block
        sizes; by default :func:`marker_size_from_space` of this state.
    strokes : mapping of str to (float, float), optional
        Range of each RRP slider's coordinate, m, over which its guide is drawn
        (:func:`~mech_kinematics.diagram.strokes_from_scene`).
    reactions : sequence of (complex, complex)
        Each joint's point and the force on its body (x + iy, m and N), drawn
        as the ``reactions`` arrows.
    force_scale : float
        Arrow length per unit force, m per N, >= 0; 0 draws the largest
        force :data:`AUTO_FORCE_LENGTH` of the mechanism's size long.

    Returns
    -------
    visualization_msgs.msg.MarkerArray
        The markers listed in the module's description, positions in m.

    Raises
    ------
    ValueError
        If a scale is negative or not finite, or ``size`` is not positive.
    """
    from geometry_msgs.msg import Point
    from std_msgs.msg import ColorRGBA
    from visualization_msgs.msg import Marker, MarkerArray

    for name, value in (('velocity_scale', velocity_scale),
                        ('acceleration_scale', acceleration_scale),
                        ('force_scale', force_scale)):
        if not (math.isfinite(value) and value >= 0.0):
            msg = f'Expected `{name}` to be a finite number >= 0, got {value!r}'
            raise ValueError(msg)
    if size is not None and not (math.isfinite(size) and size > 0.0):
        msg = f'Expected `size` to be a finite number > 0 m, got {size!r}'
        raise ValueError(msg)

    space = space_from_state(scene, state, strokes)
    arrows = arrows_from_state(scene, state, velocity_scale, acceleration_scale, points=points)
    unit = marker_size_from_space(space) if size is None else float(size)
    markers = []

    def marker(ns: str, ident: int, kind: int, rgba: tuple[float, ...],
               scale: tuple[float, float, float]) -> Any:
        m = Marker(ns=ns, id=ident, type=kind, action=Marker.ADD)
        if stamp is not None:
            m.header.stamp = stamp
        m.header.frame_id = frame_id
        m.pose.orientation.w = 1.0
        m.scale.x, m.scale.y, m.scale.z = scale
        m.color.r, m.color.g, m.color.b, m.color.a = rgba
        markers.append(m)
        return m

    def point(xy: Any) -> Any:
        return Point(x=float(xy[0]), y=float(xy[1]))

    line = (LINE_WIDTH * unit, 0.0, 0.0)
    for i, link in enumerate(space.links):
        m = marker('links', i, Marker.LINE_STRIP, _rgba(COLOURS[i % len(COLOURS)]), line)
        outline = list(link.outline)
        if len(outline) > 2:
            outline.append(outline[0])
        m.points = [point(xy) for xy in outline]
    if space.guides:
        m = marker('guides', 0, Marker.LINE_LIST, GUIDE_RGBA, line)
        m.points = [point(xy) for guide in space.guides for xy in (guide.start, guide.end)]
    block = (BLOCK_LENGTH * unit, BLOCK_HEIGHT * unit, BLOCK_HEIGHT * unit)
    for i, slider in enumerate(space.sliders):
        m = marker('sliders', i, Marker.CUBE, SLIDER_RGBA, block)
        m.pose.position = point(slider.xy)
        m.pose.orientation.z = math.sin(slider.angle / 2.0)
        m.pose.orientation.w = math.cos(slider.angle / 2.0)
    thick = ACTUATOR_DIAMETER * unit
    for i, actuator in enumerate(space.actuators):
        axis = actuator.end - actuator.start
        m = marker('actuators', i, Marker.CYLINDER, ACTUATOR_RGBA,
                   (thick, thick, float(math.hypot(*axis))))
        m.pose.position = point((actuator.start + actuator.end) / 2.0)
        # The cylinder's axis is its z: turned a quarter about y onto x, then about z.
        half = math.atan2(axis[1], axis[0]) / 2.0
        quarter = math.sqrt(0.5)
        m.pose.orientation.w = math.cos(half) * quarter
        m.pose.orientation.x = -math.sin(half) * quarter
        m.pose.orientation.y = math.cos(half) * quarter
        m.pose.orientation.z = math.sin(half) * quarter
    diameter = JOINT_DIAMETER * unit
    m = marker('joints', 0, Marker.SPHERE_LIST, POINT_RGBA, (diameter, diameter, diameter))
    ground = set(space.ground)
    m.points = [point(xy) for xy in space.points.values()]
    m.colors = [ColorRGBA(r=r, g=g, b=b, a=a) for r, g, b, a in (
        GROUND_RGBA if name in ground else POINT_RGBA for name in space.points)]
    # scale.z = 0: the head's length follows the arrow's.
    shaft = (SHAFT_DIAMETER * unit, HEAD_DIAMETER * unit, 0.0)
    for ns, rgba, first in (('velocity', VELOCITY_RGBA, 0),
                            ('acceleration', ACCELERATION_RGBA, 1)):
        for i, arrow in enumerate(arrows[first::2]):
            m = marker(ns, i, Marker.ARROW, rgba, shaft)
            m.points = [point(arrow.start), point(arrow.end)]
    if reactions:
        per_newton = force_scale
        if per_newton == 0.0:
            largest = max(abs(force) for _, force in reactions)
            per_newton = AUTO_FORCE_LENGTH * unit / largest if largest > 0.0 else 0.0
        for i, (at, force) in enumerate(reactions):
            m = marker('reactions', i, Marker.ARROW, REACTION_RGBA, shaft)
            end = at + per_newton * force
            m.points = [point((at.real, at.imag)), point((end.real, end.imag))]
    return MarkerArray(markers=markers)


class MarkerThrottle:
    """Pick the ticks that publish markers: at most ``max_rate_hz``, whatever the tick rate.

    A tick publishes if at least ``ceil(interval / period)`` ticks have passed
    since the last one that did (so markers follow the tick deadlines, at most
    ``max_rate_hz``), and at least ``interval - slack`` of monotonic time (so
    that ticks on a simulated clock running faster than real time are held to
    the same bound). The first tick publishes.

    Parameters
    ----------
    max_rate_hz : float
        Highest marker rate, Hz.
    slack_ns : int
        Tolerance of the time test for the jitter of the ticks, ns.
    """

    def __init__(self, max_rate_hz: float = MAX_RATE_HZ, slack_ns: int = 1_000_000) -> None:
        if not (math.isfinite(max_rate_hz) and max_rate_hz > 0.0):
            msg = f'Expected `max_rate_hz` > 0, got {max_rate_hz!r}'
            raise ValueError(msg)
        self.interval_ns = round(NS_PER_S / max_rate_hz)
        self.slack_ns = slack_ns
        self._ticks = 0
        self._last_ns: int | None = None

    def due(self, period_ns: int, now_ns: int) -> bool:
        """Count a tick of period ``period_ns`` at monotonic ``now_ns``; return if it publishes."""
        self._ticks += 1
        if self._last_ns is not None and (
                self._ticks < -(-self.interval_ns // period_ns)
                or now_ns - self._last_ns < self.interval_ns - self.slack_ns):
            return False
        self._ticks = 0
        self._last_ns = now_ns
        return True
