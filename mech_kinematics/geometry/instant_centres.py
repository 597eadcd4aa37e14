# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Instantaneous centres of rotation of every pair of links of a scene.

The *bodies* of a mechanism are the ground, every moving link (the crank, the
links of the dyads, the slotted levers) and every slider block: an RRP block
translates on its fixed guide, an RPR block turns with its slotted lever and
slides in it. With ``n`` bodies there are ``n (n - 1) / 2`` instant centres.

Two independent constructions are offered:

- :func:`instant_centres_from_state` finds, for each pair of bodies, the point
  where their relative velocity field vanishes, from the solved angular and
  linear velocities;
- :func:`instant_centres_from_kennedy` starts from the primary centres (every
  pin joint; a sliding pair has its centre at infinity normal to the slide)
  and applies Kennedy's theorem (the three centres of any three bodies are
  collinear), from positions only. Some centres of multi-loop chains cannot
  be found this way; they are left out.

Centres at infinity are explicit: :attr:`InstantCentre.point` is ``None`` and
:attr:`InstantCentre.direction` gives the direction. Homogeneous coordinates
(:meth:`InstantCentre.homogeneous`) treat both kinds alike.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, replace
from enum import Enum
import itertools
import math
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import SceneError
from ..solver import Scene, State
from ..solver.graph import Graph, GROUND, Joint, Role

__all__ = [
    'GROUND', 'Body', 'BodyKind', 'Centre', 'InstantCentre', 'InstantCentres', 'Topology',
    'bodies_from_scene', 'centres_as_dict', 'full_scene', 'instant_centres_from_kennedy',
    'instant_centres_from_state', 'varying_links',
]

#: A relative angular velocity below this fraction of ``|relative velocity| /
#: size`` puts the centre at infinity (relative translation).
REL_TRANSLATION = 1e-12
#: Two bodies whose relative velocity, at every point of the mechanism, is below
#: this fraction of the largest point speed have no relative motion at this
#: instant (e.g. a four-bar's coupler and rocker when the crank is in line with
#: the ground link); their centre is then taken as their joint's.
REL_MOTION = 1e-10
#: Homogeneous cross products (in units of the mechanism's size) below this
#: are treated as degenerate: two coincident centres, or two coincident lines.
DEGENERATE = 1e-9


#: What a body of the mechanism is (the graph's :class:`~mech_kinematics.solver.graph.Role`).
BodyKind = Role


class Centre(Enum):
    """How an instant centre was found."""

    VELOCITY = 'velocity'   # where the relative velocity field vanishes
    PIN = 'pin'             # a revolute joint: a primary centre
    SLIDE = 'slide'         # a sliding pair: a primary centre at infinity
    KENNEDY = 'kennedy'     # intersection of two lines of Kennedy's theorem


@dataclass(frozen=True)
class Body:
    """A rigid body of the mechanism.

    Attributes
    ----------
    name : str
        The link's or slider's name, or :data:`GROUND`.
    kind : BodyKind
        Ground, crank, link, slotted lever or slider block.
    points : tuple of str
        Named points fixed on the body, in the order they are defined.
    number : int
        Its number in Kennedy's notation: 1 for the ground, then 2, 3, ... in
        the scene's order.
    guide : str or None
        For a slider block: the RPR lever it slides in, or :data:`GROUND` for
        a fixed guide.
    """

    name: str
    kind: BodyKind
    points: tuple[str, ...]
    number: int
    guide: str | None = None


@dataclass(frozen=True)
class Topology:
    """The bodies of a scene and the joints between them.

    Attributes
    ----------
    bodies : dict of str to Body
        Every body, ground first, in Kennedy numbering order.
    pins : tuple of (str, str, str)
        Revolute joints as ``(body, body, point)``.
    slides : tuple of (str, str)
        Sliding pairs as ``(slider block, guide body)``.
    ground : str
        Name of the ground body.
    """

    bodies: dict[str, Body]
    pins: tuple[tuple[str, str, str], ...]
    slides: tuple[tuple[str, str], ...]
    ground: str


def full_scene(scene: Scene) -> Scene:
    """Return ``scene`` with every joint and point reported (its outputs unpruned)."""
    if scene.outputs_joints is None and scene.outputs_points is None:
        return scene
    return replace(scene, outputs_joints=None, outputs_points=None)


def bodies_from_scene(scene: Scene) -> Topology:
    """Return the bodies of ``scene`` and their pin and sliding joints.

    Parameters
    ----------
    scene : Scene
        The mechanism.

    Returns
    -------
    Topology
        Ground first, then the crank, the dyads' links, levers and slider
        blocks in the scene's order.
    """
    graph = scene.graph
    bodies = {name: Body(name, body.role, body.points, number, body.guide)
              for number, (name, body) in enumerate(graph.bodies.items(), start=1)}
    return Topology(bodies, tuple(graph.pins()), tuple(graph.slides()), graph.ground)


@dataclass(frozen=True)
class InstantCentre:
    """The instant centre of two bodies.

    Attributes
    ----------
    bodies : (str, str)
        The two bodies, in Kennedy numbering order.
    point : ndarray, shape (2,), or None
        Position, m; ``None`` for a centre at infinity.
    direction : ndarray, shape (2,), or None
        Unit vector toward a centre at infinity (its sign is arbitrary: both
        ends of a line meet at infinity); ``None`` for a finite centre.
    method : Centre
        How it was found.
    """

    bodies: tuple[str, str]
    point: npt.NDArray[np.float64] | None
    direction: npt.NDArray[np.float64] | None
    method: Centre

    @property
    def at_infinity(self) -> bool:
        """Whether the centre is at infinity (the two bodies translate relatively)."""
        return self.point is None

    def homogeneous(self, size: float = 1.0) -> npt.NDArray[np.float64]:
        """Return unit homogeneous coordinates ``(x / size, y / size, 1)`` normalised.

        Parameters
        ----------
        size : float
            Length unit, m (use the mechanism's size so that the coordinates
            are of order one).

        Returns
        -------
        ndarray, shape (3,)
            Unit vector, defined up to sign; the last entry is 0 at infinity.
        """
        if self.point is None:
            assert self.direction is not None
            h = np.array([self.direction[0], self.direction[1], 0.0])
        else:
            h = np.array([self.point[0] / size, self.point[1] / size, 1.0])
        unit: npt.NDArray[np.float64] = h / np.linalg.norm(h)
        return unit


def _centre_from_homogeneous(bodies: tuple[str, str], h: npt.NDArray[np.float64], size: float,
                             method: Centre, infinite: bool) -> InstantCentre:
    if infinite:
        d = h[:2] / math.hypot(h[0], h[1])
        return InstantCentre(bodies, None, d, method)
    return InstantCentre(bodies, h[:2] / h[2] * size, None, method)


@dataclass(frozen=True)
class InstantCentres:
    """Every instant centre found for a scene at one instant.

    Attributes
    ----------
    topology : Topology
        The bodies and joints.
    centres : dict of (str, str) to InstantCentre
        Keyed by the pair of bodies in Kennedy numbering order.
    size : float
        Size of the mechanism at this instant (largest distance between two of
        its points), m: the length unit of the homogeneous coordinates.
    """

    topology: Topology
    centres: dict[tuple[str, str], InstantCentre]
    size: float
    _index: dict[frozenset[str], InstantCentre] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        """Index the centres by unordered pair."""
        object.__setattr__(self, '_index',
                           {frozenset(key): centre for key, centre in self.centres.items()})

    def __getitem__(self, pair: tuple[str, str]) -> InstantCentre:
        """Return the centre of two bodies, given in either order."""
        try:
            return self._index[frozenset(pair)]
        except KeyError:
            msg = f'Expected a pair of distinct bodies with a known centre, got {pair!r}'
            raise KeyError(msg) from None

    def __contains__(self, pair: object) -> bool:
        """Whether the centre of the pair of bodies is known."""
        return isinstance(pair, tuple) and frozenset(pair) in self._index

    def __iter__(self) -> Iterator[InstantCentre]:
        """Iterate over the centres in Kennedy numbering order."""
        return iter(self.centres.values())

    def __len__(self) -> int:
        """Return the number of centres."""
        return len(self.centres)

    def label(self, centre: InstantCentre) -> str:
        """Return the textbook label of a centre, e.g. ``'I13'`` (``'I2,11'`` past 9)."""
        a, b = (self.topology.bodies[name].number for name in centre.bodies)
        sep = '' if max(a, b) < 10 else ','
        return f'I{a}{sep}{b}'


def _pairs(topology: Topology) -> list[tuple[str, str]]:
    return list(itertools.combinations(topology.bodies, 2))


def varying_links(scene: Scene) -> tuple[str, ...]:
    """Return the links whose length varies (an actuator's): not one rigid body.

    The relative velocity of a link's end about its start is ``omega x r`` only
    for a rigid link; a cylinder's adds its extension rate along it. (A slotted
    lever's length varies too, but its pin's sliding is modelled: it has a slider.)
    """
    return tuple(dict.fromkeys(joint.on for joint in scene.graph.cylinders()))


def one_driver(scene: Scene, what: str) -> None:
    """Refuse, in one line, a scene with several drivers where ``what`` needs one crank.

    Velocity polygons and Kennedy's instant centres describe a mechanism of
    one degree of freedom driven by one crank (issue 18).
    """
    drivers = scene.drivers
    if scene.input is None or len(drivers) > 1:
        names = ', '.join(driver.name for driver in drivers)
        msg = (f'Expected a scene driven by one crank for {what}, got scene "{scene.name}" '
               f'with {len(drivers)} driver{"s" * (len(drivers) > 1)} ({names})')
        raise SceneError(msg)


def check_full_state(topology: Topology, scene: Scene, state: State) -> None:
    """Refuse anything but the state of one crank angle of the full ``scene``."""
    if isinstance(state.valid, np.ndarray):
        msg = f'Expected the state of one crank angle, got an array of shape {state.valid.shape}'
        raise ValueError(msg)
    if state.scene != scene.name:
        msg = f'Expected a state of scene "{scene.name}", got one of "{state.scene}"'
        raise ValueError(msg)
    missing = [point for body in topology.bodies.values() for point in body.points
               if point not in state.complex_points]
    missing += [name for name, body in topology.bodies.items()
                if body.kind is not BodyKind.GROUND and name not in state.joints]
    if missing:
        msg = (f'Expected a state with every point and joint of scene "{scene.name}" (solve '
               f'full_scene(scene)), got one missing {sorted(set(missing))}')
        raise ValueError(msg)


def _size(state: State) -> float:
    positions = [p for p, _, _ in state.complex_points.values()]
    size = max((abs(a - b) for a in positions for b in positions), default=0.0)
    return size if size > 0.0 else 1.0


def _body_motion(topology: Topology, state: State,
                 name: str) -> tuple[float, complex, complex]:
    """Return ``(omega, reference point, its velocity)`` of a body."""
    body = topology.bodies[name]
    if body.kind is BodyKind.GROUND:
        return 0.0, 0j, 0j
    p, v, _ = state.complex_points[body.points[0]]
    return _omega(topology, state, name), complex(p), complex(v)


def _omega(topology: Topology, state: State, name: str) -> float:
    """Return a body's angular velocity: a slider block turns with what it slides on."""
    body = topology.bodies[name]
    if body.kind is BodyKind.GROUND:
        return 0.0
    if body.kind is BodyKind.SLIDER:
        guide = body.guide
        assert guide is not None
        return _omega(topology, state, guide)
    return float(state.joints[name].velocity)


def instant_centres_from_state(scene: Scene, state: State) -> InstantCentres:
    """Return the instant centre of every pair of bodies from the solved velocities.

    The centre of bodies i and j is where ``v_i(x) - v_j(x) = 0`` with
    ``v_k(x) = v_k(P_k) + omega_k x (x - P_k)``; if their angular velocities
    are equal (relative translation) it is at infinity, normal to the relative
    velocity. Two bodies with no relative motion at this instant (a four-bar's
    coupler and rocker when the crank is in line with the frame) have every
    point as a centre; their joint is returned (method :attr:`Centre.PIN` or
    :attr:`Centre.SLIDE`).

    Parameters
    ----------
    scene : Scene
        The mechanism.
    state : State
        Its state at one crank angle, with every point and joint (solve
        :func:`full_scene` of a pruned scene).

    Returns
    -------
    InstantCentres
        All ``n (n - 1) / 2`` centres, method :attr:`Centre.VELOCITY`.

    Raises
    ------
    ValueError
        If ``state`` is not of one crank angle or misses points or joints, or
        two bodies that share no joint have the same motion.
    SceneError
        If a link changes length (:func:`varying_links`); any number of
        drivers is fine.
    """
    varying = varying_links(scene)  # any number of drivers, but rigid bodies only
    if varying:
        msg = (f'Expected rigid links for instant centres, got scene "{scene.name}" whose link '
               f'{", ".join(varying)} changes length (an actuator\'s: its barrel and rod are two '
               f'bodies)')
        raise SceneError(msg)
    topology = bodies_from_scene(scene)
    check_full_state(topology, scene, state)
    size = _size(state)
    motion = {name: _body_motion(topology, state, name) for name in topology.bodies}
    positions = np.array([complex(p) for p, _, _ in state.complex_points.values()])
    speed = max(abs(complex(v)) for _, v, _ in state.complex_points.values())
    primary = _primary(topology, scene, state, size)
    centres = {}
    for a, b in _pairs(topology):
        wa, pa, va = motion[a]
        wb, pb, vb = motion[b]
        dw = wa - wb
        # relative velocity field c + i dw x; zero at x = i c / dw
        c = (va - 1j * wa * pa) - (vb - 1j * wb * pb)
        if float(np.abs(c + 1j * dw * positions).max()) <= REL_MOTION * speed:
            # no relative motion at this instant: every point is a centre; take the joint's
            key = frozenset((a, b))
            if key not in primary:
                msg = (f'Expected bodies "{a}" and "{b}" to move relative to each other, got '
                       f'the same motion: their instant centre is undefined')
                raise ValueError(msg)
            h, method = primary[key]
            centres[(a, b)] = _centre_from_homogeneous((a, b), h, size, method,
                                                       method is Centre.SLIDE)
            continue
        ic = 1j * c
        h = np.array([ic.real / size, ic.imag / size, dw])
        infinite = abs(dw) * size <= REL_TRANSLATION * abs(c)
        centres[(a, b)] = _centre_from_homogeneous((a, b), h, size, Centre.VELOCITY, infinite)
    return InstantCentres(topology, centres, size)


def _line(p: npt.NDArray[np.float64], q: npt.NDArray[np.float64]
          ) -> npt.NDArray[np.float64] | None:
    """Return the unit homogeneous line through two points, or None if they coincide."""
    line = np.cross(p, q)
    norm = float(np.linalg.norm(line))
    return None if norm <= DEGENERATE else line / norm


def _primary(topology: Topology, scene: Scene, state: State, size: float
             ) -> dict[frozenset[str], tuple[npt.NDArray[np.float64], Centre]]:
    """Return the primary centres: pin joints, and sliding pairs at infinity (homogeneous)."""
    known: dict[frozenset[str], tuple[npt.NDArray[np.float64], Centre]] = {}

    def put(a: str, b: str, h: npt.NDArray[np.float64], method: Centre) -> None:
        known.setdefault(frozenset((a, b)), (h / np.linalg.norm(h), method))

    for a, b, point in topology.pins:
        p = complex(state.complex_points[point][0])
        put(a, b, np.array([p.real / size, p.imag / size, 1.0]), Centre.PIN)
    graph = scene.graph
    for slider, guide in topology.slides:
        angle = slide_angle(graph, graph.prismatic(slider), state)
        # normal to the slide: perpendicular to the direction of sliding
        put(slider, guide, np.array([-math.sin(angle), math.cos(angle), 0.0]), Centre.SLIDE)
    return known


def instant_centres_from_kennedy(scene: Scene, state: State) -> InstantCentres:
    """Return the instant centres found by Kennedy's theorem, from positions only.

    The primary centres are the pin joints and, for every sliding pair, a
    centre at infinity normal to the slide (the fixed guide of an RRP slider,
    the slot of an RPR lever). Then, repeatedly, the centre of bodies i and j
    is the intersection of the lines ``I_ik I_jk`` and ``I_im I_jm`` for two
    other bodies k and m whose centres with i and j are known (of the
    candidate pairs of lines, the best conditioned); parallel lines meet at
    infinity. A Geneva wheel locked between engagements moves with the ground:
    its centre with any body is the ground's, and its pin, out of the slot,
    slides across the crank's radius.

    Parameters
    ----------
    scene : Scene
        The mechanism.
    state : State
        Its state at one crank angle, with every point and joint; only
        positions and joint angles are used.

    Returns
    -------
    InstantCentres
        The centres that could be found (all of them for a four-bar or a
        slider-crank), in Kennedy numbering order.
    """
    one_driver(scene, "instant centres (one driver's)")
    topology = bodies_from_scene(scene)
    check_full_state(topology, scene, state)
    size = _size(state)
    known = _primary(topology, scene, state, size)
    # A locked Geneva wheel moves with the ground: its centre with any body is the ground's.
    locked = locked_bodies(scene.graph, state)

    pairs = _pairs(topology)
    while True:
        for lever in locked:
            for body in topology.bodies:
                if body in (lever, topology.ground):
                    continue
                ours, theirs = frozenset((lever, body)), frozenset((topology.ground, body))
                if theirs in known and ours not in known:
                    known[ours] = known[theirs]
                elif ours in known and theirs not in known:
                    known[theirs] = known[ours]
        best: tuple[float, str, str, npt.NDArray[np.float64]] | None = None
        for a, b in pairs:
            if frozenset((a, b)) in known:
                continue
            lines = []
            for k in topology.bodies:
                ik, jk = known.get(frozenset((a, k))), known.get(frozenset((b, k)))
                if k in (a, b) or ik is None or jk is None:
                    continue
                line = _line(ik[0], jk[0])
                if line is not None:
                    lines.append(line)
            for l1, l2 in itertools.combinations(lines, 2):
                h = np.cross(l1, l2)
                score = float(np.linalg.norm(h))
                if score > DEGENERATE and (best is None or score > best[0]):
                    best = (score, a, b, h)
        if best is None:
            break
        _, a, b, h = best
        known[frozenset((a, b))] = (h / np.linalg.norm(h), Centre.KENNEDY)

    centres = {}
    for a, b in pairs:
        entry = known.get(frozenset((a, b)))
        if entry is None:
            continue
        h, method = entry
        infinite = abs(h[2]) <= DEGENERATE * math.hypot(h[0], h[1]) and method is not Centre.PIN
        centres[(a, b)] = _centre_from_homogeneous((a, b), h, size, method, infinite)
    return InstantCentres(topology, centres, size)


def slide_angle(graph: Graph, joint: Joint, state: State) -> float:
    """Return the direction, rad, in which a prismatic joint's block slides in a solved state.

    Its line's angle (:class:`~mech_kinematics.solver.graph.Line`); for one of
    several slots (a Geneva wheel's), the direction of the one the pin is in,
    from the line's point. An intermittent slot out of engagement holds no
    pin: the block then rides the pin's body across its radius (a Geneva
    crank's pin between slots).
    """
    line = joint.line
    assert line is not None
    engagement = state.intermittent.get(joint.on) if joint.intermittent else None
    start, turn = line.through, 0.0
    if engagement is not None and not bool(engagement.engaged):
        pin = next(j for j in graph.joints if j.body == joint.body and j.line is None)
        frame = graph.bodies[pin.on].frame
        assert frame is not None
        start, turn = frame.origin, math.pi / 2
    elif joint.copies == 1:
        if line.angle_of is None:
            return line.angle
        angle = float(state.joints[line.angle_of].position)
        return angle + line.angle if line.angle else angle
    p, o = (complex(state.complex_points[name][0]) for name in (joint.at, start))
    return math.atan2(p.imag - o.imag, p.real - o.real) + turn


def locked_bodies(graph: Graph, state: State) -> tuple[str, ...]:
    """Return the bodies an intermittent lock holds to the ground in a solved state."""
    return tuple(joint.body for joint in graph.joints if joint.type.table is None
                 and joint.intermittent and not bool(state.intermittent[joint.body].engaged))


def centres_as_dict(centres: InstantCentres) -> dict[str, Mapping[str, Any]]:
    """Return the centres as plain data keyed by label (for JSON or tables)."""
    result: dict[str, Mapping[str, Any]] = {}
    for centre in centres:
        entry: dict[str, Any] = {'bodies': list(centre.bodies), 'method': centre.method.value}
        if centre.point is None:
            assert centre.direction is not None
            entry['at_infinity'] = True
            entry['direction_deg'] = math.degrees(math.atan2(centre.direction[1],
                                                             centre.direction[0])) % 180.0
        else:
            entry['at_infinity'] = False
            entry['point'] = [float(centre.point[0]), float(centre.point[1])]
        result[centres.label(centre)] = entry
    return result
