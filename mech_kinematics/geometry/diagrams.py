# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Space, velocity and acceleration diagrams of a scene, drawn from the exact solution.

The geometry comes first, as plain frozen dataclasses that any front end can
draw (matplotlib here; RViz markers elsewhere):

- :func:`space_from_state`: the mechanism itself (links, ground pivots,
  sliders and their guides);
- :func:`velocity_polygon_from_state`: the velocity diagram of the textbooks.
  The pole ``o`` is the image of every ground point; each point's absolute
  velocity ends at its lower-case letter; each link contributes the relative
  velocity of its end with respect to its start (``bc`` is ``v_CB``); a
  slotted lever contributes the coincident point ``b'`` of the pin ``B`` and
  the sliding velocity ``b'b``;
- :func:`acceleration_polygon_from_state`: the acceleration diagram. Each
  link's relative acceleration is split into its normal (centripetal)
  component, parallel to the link and pointing to its start, ending at an
  intermediate letter (``c_b``), and its tangential component, perpendicular
  to the link; a slotted lever adds the Coriolis component ``2 omega v`` and
  the sliding acceleration;
- :func:`diagram_from_scene`: all three at one crank angle, with the link
  values and, on request, the instant centres.

This module is pure geometry (NumPy only): the ROS markers and the
matplotlib drawings of :mod:`mech_kinematics.tools.diagram` both read it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from enum import Enum
import math
from typing import Any
import warnings

import numpy as np
import numpy.typing as npt

from .instant_centres import (bodies_from_scene, BodyKind, check_full_state, full_scene,
                              instant_centres_from_state, InstantCentres,
                              locked_bodies, slide_angle, Topology, varying_links)
from ..errors import NearSingularWarning
from ..solver import Scene, solve, State
from ..solver.graph import Graph, Joint
from ..solver.plan import diameter
from ..units import turns_from_degrees

__all__ = [
    'ActuatorShape', 'COLOURS', 'Diagram', 'DriverValues', 'GuideLine', 'LinkShape',
    'LinkValues', 'PinValues', 'Pivot', 'Polygon', 'SliderShape', 'SliderValues', 'SpaceDiagram',
    'Table', 'Vector', 'VectorKind', 'acceleration_polygon_from_state', 'arrows_from_state',
    'colours_from_scene', 'diagram_from_scene', 'space_from_state', 'strokes_from_scene',
    'tables_from_diagram', 'fmt_sense', 'fmt_value', 'nice_scale', 'scale_text', 'varying_links',
    'velocity_polygon_from_state',
]

Array = npt.NDArray[np.float64]

#: Letter of the pole of the velocity and acceleration diagrams.
POLE = 'o'
#: Samples of one crank turn used to find the stroke of a slider.
STROKE_SAMPLES = 720


class VectorKind(Enum):
    """The role of a vector in a velocity or acceleration diagram."""

    ABSOLUTE = 'absolute'      # from the pole to a point's letter
    RELATIVE = 'relative'      # of a link's end with respect to its start
    NORMAL = 'normal'          # centripetal component, parallel to the link
    TANGENTIAL = 'tangential'  # perpendicular to the link
    CORIOLIS = 'coriolis'      # 2 omega x v of a pin sliding in a turning slot
    SLIP = 'slip'              # of a pin relative to the coincident point of its slot


@dataclass(frozen=True)
class Vector:
    """One vector of a diagram, from letter ``tail`` to letter ``head``.

    Attributes
    ----------
    tail, head : str
        Letters at its ends (``'b'``, ``'c'``; ``'c_b'`` for the end of the
        normal component of C relative to B; ``"b'"`` for the point of a
        slotted lever coinciding with pin B).
    start, end : ndarray, shape (2,)
        Its ends in the diagram, in m/s or m/s^2 (the pole at the origin).
    quantity : str
        What it represents: ``'v_CB'``, ``'a_CB^n'``, ``"a_BB'^c"``, ...
    kind : VectorKind
        Its role in the diagram.
    body : str or None
        The link whose motion it comes from (absolute vectors: ``None``).
    also : str
        Another name of the same vector, e.g. ``'v_C'`` for ``v_CD`` when D is
        on the ground; ``''`` if none.
    """

    tail: str
    head: str
    start: Array
    end: Array
    quantity: str
    kind: VectorKind
    body: str | None = None
    also: str = ''

    @property
    def value(self) -> float:
        """Magnitude, m/s or m/s^2."""
        return float(math.hypot(*(self.end - self.start)))

    @property
    def direction_deg(self) -> float:
        """Direction in degrees CCW from +x, in [0, 360); NaN for a zero vector."""
        dx, dy = self.end - self.start
        if dx == 0.0 and dy == 0.0:
            return math.nan
        return math.degrees(math.atan2(dy, dx)) % 360.0


@dataclass(frozen=True)
class Polygon:
    """A velocity or acceleration diagram.

    Attributes
    ----------
    quantity : str
        ``'velocity'`` or ``'acceleration'``.
    unit : str
        ``'m/s'`` or ``'m/s^2'``.
    letters : dict of str to ndarray, shape (2,)
        Every letter's position (pole, points, coincident points, ends of
        components), in ``unit``; ground points sit at the pole.
    vectors : tuple of Vector
        In construction order.
    pole : str
        Letter of the pole.
    ground : tuple of str
        Letters of the ground points (all at the pole).
    """

    quantity: str
    unit: str
    letters: dict[str, Array]
    vectors: tuple[Vector, ...]
    pole: str = POLE
    ground: tuple[str, ...] = ()

    def find(self, quantity: str) -> Vector:
        """Return the vector representing ``quantity`` (or having it as ``also``)."""
        for vector in self.vectors:
            if quantity in (vector.quantity, vector.also):
                return vector
        msg = f'Expected a quantity drawn in the {self.quantity} diagram, got {quantity!r}'
        raise KeyError(msg)


@dataclass(frozen=True)
class LinkShape:
    """A moving link of the space diagram.

    Attributes
    ----------
    name : str
        The link's name.
    kind : BodyKind
        Crank, link or slotted lever.
    points : tuple of str
        Named points fixed on it.
    outline : ndarray, shape (n, 2)
        A segment (n = 2) through its extreme points, or the convex polygon of
        its points (n > 2, not repeated), m. A lever's outline runs through
        the pin in its slot; an intermittent (Geneva) wheel's is the polygon
        of its slots' mouths, whether the pin is in a slot or not.
    slots : tuple of (ndarray, ndarray)
        An intermittent wheel's slots, each from its inner end to its mouth
        (m); slot 0 lies along the wheel's angle. Empty for other links.
    """

    name: str
    kind: BodyKind
    points: tuple[str, ...]
    outline: Array
    slots: tuple[tuple[Array, Array], ...] = ()


@dataclass(frozen=True)
class Pivot:
    """A ground point carrying a revolute joint (drawn hatched)."""

    point: str
    xy: Array


@dataclass(frozen=True)
class SliderShape:
    """A slider block at ``point``, sliding along direction ``angle`` (rad) on ``guide``."""

    name: str
    point: str
    xy: Array
    angle: float
    guide: str


@dataclass(frozen=True)
class GuideLine:
    """The fixed straight guide of an RRP slider, over its stroke, m."""

    slider: str
    start: Array
    end: Array


@dataclass(frozen=True)
class ActuatorShape:
    """A link whose length is an actuator's (a cylinder), from ``start`` to ``end``, m."""

    link: str
    start: Array
    end: Array


@dataclass(frozen=True)
class SpaceDiagram:
    """The mechanism at one instant (positions in m).

    Attributes
    ----------
    points : dict of str to ndarray, shape (2,)
        Every named point.
    ground : tuple of str
        The ground points.
    links : tuple of LinkShape
        Every moving link except slider blocks.
    pivots : tuple of Pivot
        Ground points with a pin joint.
    sliders : tuple of SliderShape
        Every slider block.
    guides : tuple of GuideLine
        Fixed guides.
    actuators : tuple of ActuatorShape
        The links whose length is an actuator's (:func:`varying_links`), also in ``links``.
    """

    points: dict[str, Array]
    ground: tuple[str, ...]
    links: tuple[LinkShape, ...]
    pivots: tuple[Pivot, ...]
    sliders: tuple[SliderShape, ...]
    guides: tuple[GuideLine, ...]
    actuators: tuple[ActuatorShape, ...] = ()

    def extent(self) -> tuple[Array, Array]:
        """Return the lower-left and upper-right corners of everything drawn, m."""
        xy = [*self.points.values(), *(g.start for g in self.guides),
              *(g.end for g in self.guides)]
        for link in self.links:
            xy.extend(link.outline)
        stack = np.array(xy)
        return stack.min(axis=0), stack.max(axis=0)


@dataclass(frozen=True)
class LinkValues:
    """Length (m), angle (rad), angular velocity (rad/s) and acceleration (rad/s^2) of a link.

    ``length`` is ``None`` for a slotted lever (its working length is its
    slider's coordinate).
    """

    name: str
    points: tuple[str, ...]
    length: float | None
    angle: float
    omega: float
    alpha: float
    engaged: bool | None = None  # an intermittent (Geneva) lever: its pin in a slot or not


@dataclass(frozen=True)
class SliderValues:
    """Coordinate (m), velocity (m/s) and acceleration (m/s^2) of a slider."""

    name: str
    s: float
    velocity: float
    acceleration: float


@dataclass(frozen=True)
class PinValues:
    """A pin's rubbing velocity (m/s): its radius (m) times the bodies' relative angular speed."""

    point: str
    bodies: tuple[str, str]
    radius: float
    relative_omega: float
    rubbing: float


@dataclass(frozen=True)
class DriverValues:
    """A driver's position (rad or m), speed and acceleration (per s, per s^2), its joint type.

    ``crank``: whether it is a crank (the driver's kind says, ``v1_crank``):
    another turning driver, a motor, is named, never called a crank.
    """

    name: str
    joint_type: str
    position: float
    speed: float
    accel: float
    crank: bool = False


@dataclass(frozen=True)
class Diagram:
    """The three diagrams of a scene at one crank angle.

    Attributes
    ----------
    scene : str
        Scene name.
    angle, speed, accel : float
        Crank angle (rad), angular velocity (rad/s), angular acceleration
        (rad/s^2).
    space : SpaceDiagram
        The mechanism.
    velocity, acceleration : Polygon
        The velocity and acceleration diagrams.
    links : tuple of LinkValues
        Every moving link.
    sliders : tuple of SliderValues
        Every slider.
    instant_centres : InstantCentres or None
        The instant centres, if requested.
    pins : tuple of PinValues
        The rubbing velocity at every pin of the scene's ``pins``.
    drivers : tuple of DriverValues
        Every driver's position and rates, in scene order (``angle``,
        ``speed`` and ``accel`` are the first one's).
    refused : str
        Why the velocity and acceleration polygons are not drawn (then both
        are ``None``), or ''.
    """

    scene: str
    angle: float
    speed: float
    accel: float
    space: SpaceDiagram
    velocity: Polygon | None
    acceleration: Polygon | None
    links: tuple[LinkValues, ...]
    sliders: tuple[SliderValues, ...]
    instant_centres: InstantCentres | None = None
    pins: tuple[PinValues, ...] = ()
    drivers: tuple[DriverValues, ...] = ()
    refused: str = ''


# --- geometry -------------------------------------------------------------


@dataclass(frozen=True)
class _Edge:
    """A link's relative motion from point ``start`` to point ``end`` (both on ``body``)."""

    body: str
    start: str
    end: str
    pin: str | None = None   # for a lever's coincident point: the pin in the slot
    slider: str | None = None


def _letters(scene: Scene, state: State) -> dict[str, str]:
    """Lower-case letter of every point (its name where that would be ambiguous)."""
    names = list(state.complex_points)
    lower = [name.lower() for name in names]
    return {name: (low if lower.count(low) == 1 and (low != POLE or name in scene.ground)
                   else name)
            for name, low in zip(names, lower, strict=True)}


def _coincident(pin: str) -> str:
    return f"{pin}'"


def _edges(scene: Scene, state: State) -> list[_Edge]:
    """Every link's relative motions (the graph's), in the order the solver places the points."""
    edges = [_Edge(m.body, m.start, m.end) if m.slider is None else
             _Edge(m.body, m.start, _coincident(m.end), m.end, m.slider)
             for m in scene.graph.motions]
    order = {name: index for index, name in enumerate(state.complex_points)}

    def rank(edge: _Edge) -> float:
        if edge.pin is not None:
            return order[edge.pin] + 0.5
        return float(order[edge.end])

    return sorted(edges, key=rank)


def _check_state(scene: Scene, state: State) -> Topology:
    topology = bodies_from_scene(scene)
    check_full_state(topology, scene, state)
    return topology


def _xy(z: complex) -> Array:
    return np.array([z.real, z.imag])


def _sub(*names: str) -> str:
    return ('' if all(len(n.rstrip("'")) == 1 for n in names) else ',').join(names)


def _pin_of(scene: Scene) -> dict[str, tuple[str, str, str]]:
    """Return the coincident point of every pin sliding in a body: (body, its start, the pin)."""
    return {_coincident(m.end): (m.body, m.start, m.end) for m in scene.graph.motions
            if m.slider is not None}


def _locked(state: State) -> set[str]:
    """Return the intermittent (Geneva) levers locked at this state (the pin out of its slot)."""
    return {name for name, engagement in state.intermittent.items()
            if not bool(engagement.engaged)}


def _polygon_start(scene: Scene, state: State, index: int,
                   coincident: Callable[[float, float, complex], complex],
                   ) -> tuple[dict[str, str], dict[str, tuple[str, str, str]], dict[str, complex],
                              dict[str, complex], dict[str, Array]]:
    """Letters, slotted-lever pins, positions and values of one polygon.

    ``index`` picks velocity (1) or acceleration (2) from the solution; the
    coincident point of every slotted lever gets ``coincident(omega, alpha, r)``
    with ``r`` from the lever's pivot to its pin.
    """
    _check_state(scene, state)
    letter = _letters(scene, state)
    pins = _pin_of(scene)
    position = {name: complex(pva[0]) for name, pva in state.complex_points.items()}
    values = {name: complex(pva[index]) for name, pva in state.complex_points.items()}
    for name, (body, pivot, pin) in pins.items():
        joint = state.joints[body]
        position[name] = position[pin]
        values[name] = coincident(float(joint.velocity), float(joint.acceleration),
                                  position[pin] - position[pivot])
        letter[name] = _coincident(letter[pin])
    letters = {POLE: np.zeros(2)}
    letters.update({letter[name]: _xy(value) for name, value in values.items()})
    return letter, pins, position, values, letters


def _slip_vectors(scene: Scene, state: State, letter: Mapping[str, str],
                  letters: Mapping[str, Array], index: int, symbol: str) -> list[Vector]:
    """Sliding along a fixed direction (a translating yoke's slot): the slider's rate."""
    vectors = []
    graph = scene.graph
    for slip in graph.joints:  # a block sliding on a body that translates
        line = slip.line
        if line is None or slip.on == graph.ground or graph.bodies[slip.on].turns_with:
            continue
        start, end, angle = line.through, slip.at, line.angle
        joint = state.joints[slip.name]
        rate = float(joint.velocity if index == 1 else joint.acceleration)
        tail = letters[letter[start]]
        vectors.append(Vector(letter[start], letter[end], tail,
                              tail + rate * np.array([math.cos(angle), math.sin(angle)]),
                              symbol.format(_sub(end, start)), VectorKind.SLIP, slip.name))
    return vectors


def _absolute_vectors(scene: Scene, values: Mapping[str, complex], letter: Mapping[str, str],
                      drawn: set[str], symbol: str) -> list[Vector]:
    """Absolute vectors from the pole to every moving point not drawn from a ground point."""
    return [Vector(POLE, letter[name], np.zeros(2), _xy(value), f'{symbol}_{name}',
                   VectorKind.ABSOLUTE)
            for name, value in values.items() if name not in scene.ground and name not in drawn]


def velocity_polygon_from_state(scene: Scene, state: State) -> Polygon:
    """Return the velocity diagram of ``scene`` in ``state``.

    Parameters
    ----------
    scene : Scene
        The mechanism (not pruned by ``outputs``: see :func:`full_scene`).
    state : State
        Its solution at one crank angle.

    Returns
    -------
    Polygon
        The pole ``o`` with every ground point; for every link the relative
        velocity ``omega x r`` of its end with respect to its start, from the
        start's letter; for every slotted lever the coincident point ``b'``
        and the sliding velocity ``b'b`` (not for a Geneva wheel locked
        between engagements: its pin is out of the slot); the absolute
        velocity of every moving point not already drawn from a ground point.
    """
    letter, pins, position, velocity, letters = _polygon_start(
        scene, state, 1, lambda omega, alpha, r: 1j * omega * r)
    ground = tuple(letter[name] for name in scene.ground)
    locked = _locked(state)
    vectors: list[Vector] = []
    drawn: set[str] = set()
    for edge in _edges(scene, state):
        omega = float(state.joints[edge.body].velocity)
        r = position[edge.end] - position[edge.start]
        start = letters[letter[edge.start]]
        rel = 1j * omega * r
        on_ground = edge.start in scene.ground
        quantity = f'v_{_sub(edge.end, edge.start)}'
        vectors.append(Vector(letter[edge.start], letter[edge.end], start,
                              start + _xy(rel), quantity, VectorKind.RELATIVE, edge.body,
                              f'v_{edge.end}' if on_ground else ''))
        if on_ground:
            drawn.add(edge.end)
        if edge.pin is not None and edge.body not in locked:
            assert edge.slider is not None
            pivot = pins[edge.end][1]
            e = position[edge.pin] - position[pivot]
            e /= abs(e)
            slip = float(state.joints[edge.slider].velocity) * e
            tail = letters[letter[edge.end]]
            vectors.append(Vector(letter[edge.end], letter[edge.pin], tail, tail + _xy(slip),
                                  f'v_{_sub(edge.pin, edge.end)}', VectorKind.SLIP,
                                  edge.slider))
    vectors += _slip_vectors(scene, state, letter, letters, 1, 'v_{}')
    vectors += _absolute_vectors(scene, velocity, letter, drawn, 'v')
    return Polygon('velocity', 'm/s', letters, tuple(vectors), POLE, ground)


def acceleration_polygon_from_state(scene: Scene, state: State) -> Polygon:
    """Return the acceleration diagram of ``scene`` in ``state``.

    Parameters
    ----------
    scene : Scene
        The mechanism (not pruned by ``outputs``: see :func:`full_scene`).
    state : State
        Its solution at one crank angle.

    Returns
    -------
    Polygon
        For every link, from its start's letter ``s``: the normal component
        ``-omega^2 r`` (parallel to the link, toward its start) to the letter
        ``e_s``, the tangential component ``alpha x r`` (perpendicular) from
        there, and the total relative acceleration from ``s``; for every
        slotted lever with pin B, after the components of the coincident
        point ``b'``, the Coriolis component ``2 omega x v_slip`` to ``b_b'``
        and the sliding acceleration from there to ``b`` (not for a locked
        Geneva wheel); the absolute
        acceleration of every moving point not already drawn from a ground
        point. Components are computed from the links' omega and alpha, and
        the letters of points are the solver's point accelerations, so the
        polygons close exactly when the solution is consistent.
    """
    letter, _, position, accel, letters = _polygon_start(
        scene, state, 2, lambda omega, alpha, r: (1j * alpha - omega * omega) * r)
    ground = tuple(letter[name] for name in scene.ground)
    locked = _locked(state)
    vectors: list[Vector] = []
    drawn: set[str] = set()
    for edge in _edges(scene, state):
        joint = state.joints[edge.body]
        omega, alpha = float(joint.velocity), float(joint.acceleration)
        r = position[edge.end] - position[edge.start]
        tail, head = letter[edge.start], letter[edge.end]
        middle = f'{head}_{tail}'
        start = letters[tail]
        normal = start + _xy(-omega * omega * r)
        letters[middle] = normal
        sub = _sub(edge.end, edge.start)
        on_ground = edge.start in scene.ground
        vectors.append(Vector(tail, middle, start, normal, f'a_{sub}^n', VectorKind.NORMAL,
                              edge.body))
        vectors.append(Vector(middle, head, normal, normal + _xy(1j * alpha * r),
                              f'a_{sub}^t', VectorKind.TANGENTIAL, edge.body))
        vectors.append(Vector(tail, head, start, start + _xy((1j * alpha - omega * omega) * r),
                              f'a_{sub}', VectorKind.RELATIVE, edge.body,
                              f'a_{edge.end}' if on_ground else ''))
        if on_ground:
            drawn.add(edge.end)
        if edge.pin is not None and edge.body not in locked:
            assert edge.slider is not None
            e = r / abs(r)
            slider = state.joints[edge.slider]
            coriolis = 2j * omega * float(slider.velocity) * e
            sliding = float(slider.acceleration) * e
            pin = letter[edge.pin]
            kink = f'{pin}_{head}'
            corner = letters[head] + _xy(coriolis)
            letters[kink] = corner
            sub = _sub(edge.pin, edge.end)
            vectors.append(Vector(head, kink, letters[head], corner, f'a_{sub}^c',
                                  VectorKind.CORIOLIS, edge.slider))
            vectors.append(Vector(kink, pin, corner, corner + _xy(sliding), f'a_{sub}^s',
                                  VectorKind.SLIP, edge.slider))
    vectors += _slip_vectors(scene, state, letter, letters, 2, 'a_{}^s')
    vectors += _absolute_vectors(scene, accel, letter, drawn, 'a')
    return Polygon('acceleration', 'm/s^2', letters, tuple(vectors), POLE, ground)


def _outline(xy: Array) -> Array:
    """Segment through collinear points, or their convex hull (counter-clockwise).

    Computed on the points moved to their centre and divided by their extent,
    so that the SVD and the hull's cross products stay in range for any size
    (a Geneva wheel of radius 1e300 m); the points returned are the originals.
    """
    centre = xy.mean(axis=0)
    if not np.isfinite(centre).all():  # the sum overflowed: the middle of the extent instead
        centre = xy.min(axis=0) / 2 + xy.max(axis=0) / 2
    d = xy - centre
    size = float(np.abs(d).max()) if len(xy) else 0.0
    if size == 0.0:
        return np.array([xy[0], xy[0]])
    d = d / size
    _, _, vt = np.linalg.svd(d)
    axis = vt[0]
    across = d @ np.array([-axis[1], axis[0]])
    if float(np.abs(across).max()) <= 1e-9:
        along = d @ axis
        return np.array([xy[int(np.argmin(along))], xy[int(np.argmax(along))]])
    order = sorted(range(len(d)), key=lambda i: (d[i, 0], d[i, 1]))

    def turn(o: int, a: int, b: int) -> float:
        return float((d[a, 0] - d[o, 0]) * (d[b, 1] - d[o, 1])
                     - (d[a, 1] - d[o, 1]) * (d[b, 0] - d[o, 0]))

    lower: list[int] = []
    upper: list[int] = []
    for p in order:
        while len(lower) >= 2 and turn(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(order):
        while len(upper) >= 2 and turn(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return xy[lower[:-1] + upper[:-1]]


def strokes_from_scene(scene: Scene,
                       samples: int = STROKE_SAMPLES) -> dict[str, tuple[float, float]]:
    """Return the range of every RRP slider's coordinate over one crank turn, m.

    Parameters
    ----------
    scene : Scene
        The mechanism.
    samples : int
        Crank angles sampled over the turn.

    Returns
    -------
    dict of str to (float, float)
        ``(s_min, s_max)`` over the angles at which the mechanism assembles;
        empty for a scene with several drivers (no one crank's turn: guides
        are then drawn around their blocks).
    """
    scene = full_scene(scene)
    graph = scene.graph
    sliders = [name for name, guide in graph.slides() if guide == graph.ground]
    if not sliders or scene.input is None or len(scene.drivers) > 1:
        return {}
    angles = np.linspace(0.0, 2.0 * math.pi, samples, endpoint=False)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', NearSingularWarning)
        state = solve(scene, angles)
    strokes = {}
    for name in sliders:
        s = state.joints[name].position[state.valid]
        if s.size:
            strokes[name] = (float(s.min()), float(s.max()))
    return strokes


def space_from_state(scene: Scene, state: State,
                     strokes: Mapping[str, tuple[float, float]] | None = None) -> SpaceDiagram:
    """Return the mechanism of ``scene`` in ``state`` as shapes to draw.

    Parameters
    ----------
    scene : Scene
        The mechanism (not pruned by ``outputs``: see :func:`full_scene`).
    state : State
        Its solution at one crank angle.
    strokes : mapping of str to (float, float), optional
        Range of each RRP slider's coordinate, m (:func:`strokes_from_scene`),
        over which its guide is drawn; by default a short guide around the
        block.

    Returns
    -------
    SpaceDiagram
        Points, links, ground pivots, slider blocks and guides, m.
    """
    topology = _check_state(scene, state)
    graph = scene.graph
    points = {name: _xy(complex(p)) for name, (p, _, _) in state.complex_points.items()}
    size = diameter(complex(p) for p, _, _ in state.complex_points.values()) or 1.0
    locked = set(locked_bodies(graph, state))
    links = []
    for body in topology.bodies.values():
        if body.kind in (BodyKind.GROUND, BodyKind.SLIDER):
            continue
        drawn = _drawn_points(graph, body.name)
        xy = [points[name] for name in drawn]
        slots: tuple[tuple[Array, Array], ...] = ()
        for joint in graph.joints:  # the pins sliding in its slots
            if joint.on != body.name or joint.line is None or joint.driver:
                continue
            if joint.copies == 1:
                xy.append(points[joint.at])
            else:  # a Geneva wheel: the polygon of its slots' mouths
                slots = _slots(graph, joint, state, points)
                xy += [mouth for _, mouth in slots]
        links.append(LinkShape(body.name, body.kind, drawn, _outline(np.array(xy)), slots))
    pinned = {point for a, b, point in topology.pins
              if topology.ground in (a, b)}
    pivots = tuple(Pivot(name, points[name]) for name in scene.ground if name in pinned)
    sliders = []
    guides = []
    rods = set(graph.cylinders())
    for joint in graph.joints:  # the blocks, and the fixed guides they slide on
        line = joint.line
        if line is None or joint in rods or joint.on in locked:
            continue
        sliders.append(SliderShape(joint.name, joint.at, points[joint.at],
                                   slide_angle(graph, joint, state), joint.on))
        if joint.on == graph.ground:
            guides.append(GuideLine(*fixed_guide(joint.name, points[line.through], line.angle,
                                                 state, strokes or {}, size)))
    actuators = tuple(ActuatorShape(name, *(points[p] for p in _drawn_points(graph, name)[:2]))
                      for name in varying_links(scene))
    return SpaceDiagram(points, tuple(scene.ground), tuple(links), pivots, tuple(sliders),
                        tuple(guides), actuators)


def _rods(graph: Graph) -> set[str]:
    """Return the blocks a driver slides (a cylinder's rod: drawn with its barrel)."""
    return {j.body for j in graph.cylinders()}


def _drawn_points(graph: Graph, body: str) -> tuple[str, ...]:
    """Return a body's points as drawn: its own, then the pins its driven blocks carry.

    A cylinder is drawn from its barrel's start to its rod's pin (a driven
    block sliding along it), one link whose length varies.
    """
    return graph.bodies[body].points + tuple(j.at for j in graph.cylinders() if j.on == body)


def _slots(graph: Graph, joint: Joint, state: State, points: Mapping[str, Array]
           ) -> tuple[tuple[Array, Array], ...]:
    """Return (inner end, mouth) of each of a joint's evenly spaced slots (a Geneva wheel's).

    The slots reach from 85 % of the wheel's clearance of the pin's circle to
    where that circle crosses them; the pin turns about the origin of the body
    carrying it (the crank's centre).
    """
    line = joint.line
    assert line is not None and line.angle_of is not None
    carrier = next(j.on for j in graph.joints if j.body == joint.body and j.line is None)
    frame = graph.bodies[carrier].frame
    assert frame is not None
    centre, wheel, pin = (points[name] for name in (frame.origin, line.through, joint.at))
    distance = float(np.hypot(*(wheel - centre)))
    radius = float(np.hypot(*(pin - centre)))
    mouth = distance * math.sqrt(max(1.0 - (radius / distance) ** 2, 0.0))
    inner = 0.85 * (distance - radius)
    angle = float(state.joints[line.angle_of].position)
    slots = []
    for i in range(joint.copies):
        turn = angle + 2 * math.pi * i / joint.copies
        u = np.array([math.cos(turn), math.sin(turn)])
        slots.append((wheel + inner * u, wheel + mouth * u))
    return tuple(slots)


def fixed_guide(slider: str, through: Any, angle: float, state: Any,
                strokes: Mapping[str, tuple[float, float]], size: float
                ) -> tuple[str, Any, Any]:
    """Return (slider, start, end) of a fixed guide through ``through`` at ``angle`` (rad).

    The guide is drawn over the slider's stroke (or around its place, where no
    stroke is known), padded by 8 % of the drawing's ``size``.
    """
    u = np.array([math.cos(angle), math.sin(angle)])
    s = float(state.joints[slider].position)
    low, high = strokes.get(slider, (s, s))
    pad = 0.08 * size
    return slider, through + (min(low, s) - pad) * u, through + (max(high, s) + pad) * u


def arrows_from_state(scene: Scene, state: State, velocity_scale: float,
                      acceleration_scale: float,
                      points: Sequence[str] | None = None) -> tuple[Vector, ...]:
    """Return velocity and acceleration arrows drawn on the mechanism.

    Parameters
    ----------
    scene : Scene
        The mechanism.
    state : State
        Its solution at one crank angle; it needs only the listed points.
    velocity_scale : float
        Arrow length per unit velocity, m per (m/s).
    acceleration_scale : float
        Arrow length per unit acceleration, m per (m/s^2).
    points : sequence of str, optional
        Points to draw arrows at; by default every moving point of ``state``.

    Returns
    -------
    tuple of Vector
        For each point, an :attr:`VectorKind.ABSOLUTE` velocity arrow
        (``quantity`` ``'v_P'``) then an acceleration arrow (``'a_P'``),
        starting at the point, in m.
    """
    names = [name for name in state.complex_points if name not in scene.ground] \
        if points is None else list(points)
    arrows = []
    for name in names:
        p, v, a = (complex(x) for x in state.complex_points[name])
        start = _xy(p)
        arrows.append(Vector(name, name, start, start + velocity_scale * _xy(v), f'v_{name}',
                             VectorKind.ABSOLUTE))
        arrows.append(Vector(name, name, start, start + acceleration_scale * _xy(a),
                             f'a_{name}', VectorKind.ABSOLUTE))
    return tuple(arrows)


def _values(scene: Scene, state: State,
            topology: Topology) -> tuple[tuple[LinkValues, ...], tuple[SliderValues, ...]]:
    graph = scene.graph
    rods = _rods(graph)
    links = []
    sliders = []
    for name, body in topology.bodies.items():
        if body.kind is BodyKind.GROUND or name in rods:
            continue  # (a cylinder's rod is its driver's row)
        joint = state.joints[name]
        if body.kind is BodyKind.SLIDER:
            sliders.append(SliderValues(name, float(joint.position), float(joint.velocity),
                                        float(joint.acceleration)))
        else:
            engagement = state.intermittent.get(name)
            links.append(LinkValues(name, _drawn_points(graph, name), graph.bodies[name].length,
                                    float(joint.position), float(joint.velocity),
                                    float(joint.acceleration),
                                    None if engagement is None else bool(engagement.engaged)))
    return tuple(links), tuple(sliders)


def _pins(scene: Scene, state: State) -> tuple[PinValues, ...]:
    radii = {pin.point: pin.radius for pin in scene.pins}
    return tuple(PinValues(point, bodies, radii[point], float(state.rubbing[point]) / radii[point],
                           float(state.rubbing[point]))
                 for point, bodies in scene.pin_bodies.items())


def diagram_from_scene(scene: Scene, angle: float | None = None, speed: float | None = None,
                       accel: float | None = None, *, degrees: bool = False,
                       instant_centres: bool = False,
                       inputs: Mapping[str, float] | None = None,
                       speeds: Mapping[str, float] | None = None,
                       accels: Mapping[str, float] | None = None) -> Diagram:
    """Solve ``scene`` at one crank angle (or drivers' positions) and build its three diagrams.

    Parameters
    ----------
    scene : Scene
        The mechanism; a scene pruned by ``outputs`` is solved in full.
    angle : float, optional
        Crank angle, rad (degrees if ``degrees``); default the scene's.
    speed : float, optional
        Crank angular velocity, rad/s, + CCW; default the scene's.
    accel : float, optional
        Crank angular acceleration, rad/s^2, + CCW; default the scene's.
    degrees : bool, keyword-only
        Whether ``angle`` is in degrees.
    instant_centres : bool, keyword-only
        Whether to compute the instant centres too.
    inputs, speeds, accels : mapping of str to float, keyword-only
        For a scene with several drivers (or an actuator): positions (rad, or
        m), speeds (rad/s or m/s) and accelerations by driver name, SI; a
        driver left out takes the scene's default. ``angle``, ``speed`` and
        ``accel`` are then not used.

    Returns
    -------
    Diagram
        Space, velocity and acceleration diagrams and the links' values; the
        polygons are ``None``, and ``refused`` says why, where a link's
        length varies (:func:`varying_links`).

    Raises
    ------
    AssemblyError
        If the mechanism cannot be assembled at ``angle`` (or ``inputs``).
    """
    scene = full_scene(scene)
    drivers = scene.drivers
    several = not scene.single_crank
    if several or inputs is not None:
        names = [d.name for d in drivers]
        for given in (inputs, speeds, accels):
            unknown = sorted(set(given or {}) - set(names))
            if unknown:
                msg = (f'Expected drivers of {scene.name} ({", ".join(names)}), got '
                       f'{", ".join(unknown)}')
                raise ValueError(msg)
        xs = [float((inputs or {}).get(d.name, d.start)) for d in drivers]
        vs = [float((speeds or {}).get(d.name, d.speed)) for d in drivers]
        accs = [float((accels or {}).get(d.name, d.accel)) for d in drivers]
        state = (solve(scene, xs[0], vs[0], accs[0]) if len(drivers) == 1
                 else solve(scene, xs, vs, accs))
        theta = xs[0]
    else:
        if angle is None:
            theta, turns = scene.input.angle, scene.input.turns
        elif degrees and abs(angle) > 360.0:  # counted from the start: whole turns read exactly
            theta, turns = turns_from_degrees(angle)
        else:
            theta, turns = (math.radians(angle) if degrees else float(angle)), 0
        state = solve(scene, theta, speed, accel, turns=turns)
    motions = state.drivers
    values = tuple(DriverValues(d.name, d.joint_type, float(motions[d.name].position),
                                float(motions[d.name].velocity),
                                float(motions[d.name].acceleration), d.v1_crank)
                   for d in drivers)
    topology = bodies_from_scene(scene)
    links, sliders = _values(scene, state, topology)
    centres = instant_centres_from_state(scene, state) if instant_centres else None
    varying = varying_links(scene)
    refused = ''
    velocity: Polygon | None = None
    acceleration: Polygon | None = None
    if varying:
        refused = (f'no velocity or acceleration polygon: link{"s" if len(varying) > 1 else ""} '
                   f'{", ".join(varying)} change{"" if len(varying) > 1 else "s"} length (an '
                   f"actuator's), which these polygons do not draw")
    else:
        velocity = velocity_polygon_from_state(scene, state)
        acceleration = acceleration_polygon_from_state(scene, state)
    return Diagram(scene.name, theta, values[0].speed, values[0].accel,
                   space_from_state(scene, state, strokes_from_scene(scene)),
                   velocity, acceleration, links, sliders, centres, _pins(scene, state), values,
                   refused)


# --- value tables ---------------------------------------------------------


@dataclass(frozen=True)
class Table:
    """A table of text cells: a title, column headings and rows."""

    title: str
    columns: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]


def fmt_value(value: float) -> str:
    """Format a value for a table or a label: 4 significant digits, '-' if not finite."""
    if not math.isfinite(value):
        return '-'
    if 1e4 <= abs(value) < 1e9:
        return f'{value:.0f}'
    text = f'{value:.4g}'
    return '0' if text in ('0', '-0') else text


def fmt_sense(value: float) -> str:
    """Return ' CCW' or ' CW' for the sign of an angular quantity, '' for 0."""
    return '' if value == 0.0 else (' CCW' if value > 0 else ' CW')


def nice_scale(required: float) -> float:
    """Smallest of 1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 times a power of ten that is >= ``required``."""
    if not (required > 0.0 and math.isfinite(required)):
        return 1.0
    power = 10.0 ** math.floor(math.log10(required))
    for step in (1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0):
        if step * power >= required * (1 - 1e-12):
            return step * power
    return 10.0 * power


def _pair(tail: str, head: str) -> str:
    """Letters of a vector: ``'bc'``, or ``'b c_b'`` where a letter is not a single one."""
    single = all(len(x.rstrip("'")) == 1 for x in (tail, head))
    return f'{tail}{head}' if single else f'{tail} {head}'


def scale_text(scale: float, unit: str) -> str:
    """Return the legend of a drawing scale, e.g. ``1 cm = 0.1 m/s``."""
    return f'1 cm = {scale:g} {unit}'


def tables_from_diagram(diagram: Diagram,
                        scales: Mapping[str, float] | None = None) -> dict[str, Table]:
    """Return the value tables printed under the three panels.

    Parameters
    ----------
    diagram : Diagram
        The diagrams.
    scales : mapping of str to float, optional
        Drawing scales per cm, by ``'velocity'`` and ``'acceleration'``; when
        given, a column lists each vector's drawn length in cm.

    Returns
    -------
    dict of str to Table
        ``'space'`` (links: length, angle, omega, alpha, a Geneva wheel
        marked engaged or locked; sliders; actuators: length, rates; pins: radius, relative angular
        speed, rubbing velocity; instant centres if computed),
        ``'velocity'`` and ``'acceleration'`` (every vector drawn: letters,
        quantity, magnitude, direction).
    """
    rows: list[tuple[str, ...]] = []
    for link in diagram.links:
        length = '-' if link.length is None else fmt_value(link.length)
        points = ''.join(link.points) if all(len(p) == 1 for p in link.points) \
            else ','.join(link.points)
        if link.engaged is not None:
            points += ' (engaged)' if link.engaged else ' (locked)'
        rows.append((link.name, points, length,
                     fmt_value(math.degrees(link.angle)),
                     fmt_value(link.omega) + fmt_sense(link.omega),
                     fmt_value(link.alpha) + fmt_sense(link.alpha)))
    for slider in diagram.sliders:
        rows.append((slider.name, 'slider', f's = {fmt_value(slider.s)}', '-',
                     f'{fmt_value(slider.velocity)} m/s',
                     f'{fmt_value(slider.acceleration)} m/s\u00b2'))
    shown = {slider.name for slider in diagram.sliders}
    for driver in diagram.drivers:  # an actuator: its length and extension rate
        if not driver.joint_type.angular and driver.name not in shown:
            rows.append((driver.name, 'actuator', f'L = {fmt_value(driver.position)}', '-',
                         f'{fmt_value(driver.speed)} m/s', f'{fmt_value(driver.accel)} m/s\u00b2'))
    for pin in diagram.pins:  # seed 001: rubbing velocity = |omega_a - omega_b| r
        rows.append((f'pin {pin.point}', '/'.join(pin.bodies), f'r = {fmt_value(pin.radius)}',
                     '-', f'\u0394\u03c9 {fmt_value(pin.relative_omega)}',
                     f'rubbing {fmt_value(pin.rubbing)} m/s'))
    tables = {'space': Table('Links and sliders',
                             ('link', 'points', 'length m', 'angle \u00b0', '\u03c9 rad/s',
                              '\u03b1 rad/s\u00b2'), tuple(rows))}
    centres = diagram.instant_centres
    if centres is not None:
        rows = []
        for centre in centres:
            if centre.point is not None:
                x, y = fmt_value(centre.point[0]), fmt_value(centre.point[1])
            else:
                assert centre.direction is not None
                normal = math.degrees(math.atan2(centre.direction[1], centre.direction[0]))
                x, y = 'at infinity', f'toward {fmt_value(normal % 180.0)}\u00b0'
            rows.append((centres.label(centre), ' - '.join(centre.bodies), x, y))
        tables['centres'] = Table('Instant centres', ('centre', 'links', 'x m', 'y m'),
                                  tuple(rows))
    for polygon in (diagram.velocity, diagram.acceleration):
        if polygon is None:  # refused (diagram.refused says why)
            continue
        scale = None if scales is None else scales.get(polygon.quantity)
        unit = polygon.unit.replace('^2', '\u00b2')
        columns: tuple[str, ...] = ('vector', 'quantity', unit, 'dir \u00b0')
        if scale is not None:
            columns += ('cm',)
        rows = []
        for vector in polygon.vectors:
            quantity = vector.quantity + (f' = {vector.also}' if vector.also else '')
            row: tuple[str, ...] = (_pair(vector.tail, vector.head), quantity,
                                    fmt_value(vector.value),
                                    fmt_value(vector.direction_deg) if vector.value > 0 else '-')
            if scale is not None:
                row += (f'{vector.value / scale:.2f}',)
            rows.append(row)
        title = polygon.quantity.capitalize()
        tables[polygon.quantity] = Table(title, columns, tuple(rows))
    return tables


# --- colours (plain data: the drawings and the RViz markers share them) ---

#: Colours of the moving bodies, in Kennedy numbering order (the ground is black).
COLOURS = ('#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2',
           '#17becf', '#bcbd22', '#7f7f7f')


def colours_from_scene(scene: Scene) -> dict[str, str]:
    """Return the colour of every moving body of ``scene`` (Kennedy numbering order)."""
    bodies = bodies_from_scene(scene).bodies
    rods = _rods(scene.graph)
    moving = [name for name, body in bodies.items()
              if body.kind is not BodyKind.GROUND and name not in rods]
    return {name: COLOURS[i % len(COLOURS)] for i, name in enumerate(moving)}
