# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The mechanism as one graph of bodies and joints: the model every concern reads.

A scene's kinds (its drivers, dyads and carried points, one module each)
each declare their part of the mechanism as a :class:`Fragment`: the bodies
they add (a link, a slotted lever, a slider block, a cylinder's barrel and
rod), the joints that join those to bodies already placed (revolute pins,
prismatic contacts, a driver's joint, an intermittent drive's engagement and
lock), the coordinates they move (the output joints of docs/scene_format.md, each
of a :class:`JointType`) and the relative motions the velocity polygons walk.
:func:`build_graph` joins the fragments into one :class:`Graph`, once, when a
scene is loaded (:attr:`~.mechanism.Scene.graph`).

Every other concern reads the graph and never asks which kind a step is: the
frames on ``/tf`` and the URDF we publish, the diagrams and their outlines,
instant centres, rubbing at pins, assembly studies, the forces through the
loop. Adding a kind touches none of them: it declares its fragment. Adding a
concern touches no kind: it walks the graph (as Pinocchio's algorithms walk
its ``Model``).

The joint types are :class:`JointType` values, strings (``'revolute'``,
``'prismatic'``, what ``State.joints[name].type`` and the JSON show) that
carry what the rest of the package needs to know of them: the table of a
solve's context their values sit in, the kinds of their values, their units,
their text in the scene's units. Nothing outside this module and the kinds
compares a joint type with a name: it asks the type.

Pure data: no NumPy, no solving.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field, replace
from enum import Enum
import math
from typing import Any, TYPE_CHECKING

if TYPE_CHECKING:
    from .model import SceneUnits

__all__ = ['Body', 'Frame', 'Fragment', 'GROUND', 'Graph', 'Joint', 'JointType', 'LOCK',
           'Line', 'Motion', 'PRISMATIC', 'REVOLUTE', 'Role', 'THE_GROUND', 'build_graph',
           'joint_type', 'pin', 'slide']

#: The ground body's name, unless the scene uses it for a link or slider (then ``_ground``).
GROUND = 'ground'
#: What a fragment writes for the ground (a guide on it, a joint to it): never a scene name.
THE_GROUND = '<ground>'


class JointType(str):
    """A kind of joint, and what its coordinate means: a string, e.g. ``'revolute'``.

    A ``JointType`` is equal to its name (``REVOLUTE`` and ``'revolute'``), prints and
    serializes as it, and carries the facts the rest of the package asks of
    it instead of comparing names:

    Attributes
    ----------
    table : str or None
        The table of a solve's context its coordinate's values sit in:
        ``'links'`` (an angle as a unit complex number, the angular velocity
        and acceleration, each with its bound) or ``'sliders'`` (a length and
        its rates); ``None`` for a joint with no coordinate (a lock).
    quantities : tuple of str
        The kinds of its position, velocity and acceleration, for messages
        (``'angle'``, ...; ``'position'``, ...).
    units : tuple of str
        The SI units of its position, velocity and acceleration.
    angular : bool
        Whether its position is an angle: reported wrapped to (-pi, pi], a
        driver's counted in whole turns, shown in the scene's angle unit.
    """

    table: str | None
    quantities: tuple[str, str, str]
    units: tuple[str, str, str]
    angular: bool

    def __new__(cls, name: str, table: str | None, quantities: tuple[str, str, str],
                units: tuple[str, str, str], angular: bool) -> JointType:
        """Return the joint type ``name`` with its facts."""
        self = super().__new__(cls, name)
        self.table, self.quantities, self.units, self.angular = table, quantities, units, angular
        return self

    def __repr__(self) -> str:
        """Show it as its name, as a plain string shows."""
        return str.__repr__(self)

    def __reduce__(self) -> tuple[Callable[[str], JointType], tuple[str]]:
        """Pickle it as its name (one object per type)."""
        return joint_type, (str(self),)

    def scene_unit(self, units: SceneUnits) -> str:
        """Return the unit its positions are written in in a scene of ``units``."""
        return units.angle if self.angular else units.length

    def scene_value(self, value: float, units: SceneUnits) -> float:
        """Return a position (rad or m) in the scene's unit."""
        from ..units import LENGTH_UNITS
        return units.angle_value(value) if self.angular else value * LENGTH_UNITS[units.length]

    def text(self, value: float, units: SceneUnits) -> str:
        """Return a position (rad or m) as text in the scene's unit, e.g. ``'30 deg'``."""
        return units.angle_text(value) if self.angular else units.length_text(value)

    def reported(self, value: Any) -> Any:
        """Return a position as reported: an angle wrapped to (-pi, pi], a length as it is."""
        return math.remainder(value, math.tau) if self.angular else value


#: A joint whose coordinate is an angle (a pin; as an output joint, a link's absolute angle).
REVOLUTE = JointType('revolute', 'links', ('angle', 'angular velocity', 'angular acceleration'),
                     ('rad', 'rad/s', 'rad/s^2'), True)
#: A joint whose coordinate is a length along a line (a slider, an actuator).
PRISMATIC = JointType('prismatic', 'sliders', ('position', 'velocity', 'acceleration'),
                      ('m', 'm/s', 'm/s^2'), False)
#: A joint that holds a body still while it is engaged (a Geneva wheel's lock): no coordinate.
LOCK = JointType('lock', None, ('position', 'velocity', 'acceleration'), ('', '', ''), False)

_TYPES = {str(t): t for t in (REVOLUTE, PRISMATIC, LOCK)}


def joint_type(name: str) -> JointType:
    """Return the joint type called ``name`` (``'revolute'``, ``'prismatic'`` or ``'lock'``)."""
    try:
        return _TYPES[name]
    except KeyError:
        msg = f'Expected a joint type in {", ".join(_TYPES)}, got {name!r}'
        raise ValueError(msg) from None


class Role(Enum):
    """What a body is: how it is numbered, described and drawn."""

    GROUND = 'ground'
    CRANK = 'crank'
    LINK = 'link'
    LEVER = 'lever'     # a slotted lever (an RPR's, a Geneva wheel)
    SLIDER = 'slider'   # a block sliding on a guide: on the ground, in a slot, a cylinder's rod


@dataclass(frozen=True)
class Frame:
    """Where a body's frame sits: at point ``origin``, its x axis at an angle.

    ``angle_of`` names the coordinate (a revolute output joint) whose position
    is the frame's angle; ``None`` for a body that only translates, whose
    frame keeps the fixed ``angle`` (rad).
    """

    origin: str
    angle_of: str | None
    angle: float = 0.0


@dataclass(frozen=True)
class Body:
    """A rigid body: the ground, a link, a slotted lever, a slider block.

    Attributes
    ----------
    name : str
        The link's, slider's or actuator's name (the ground's is :data:`GROUND`).
    role : Role
        What it is.
    points : tuple of str
        The named points fixed on it, in the order they were placed (its pins,
        the points carried by it); a pin sliding in it is not fixed on it.
    frame : Frame or None
        Its frame (``/tf``); ``None`` for the ground.
    guide : str or None
        For a slider block: the body it slides on (the ground's name for a
        fixed guide).
    length : float or None
        For a link: the fixed distance between its first two points, m;
        ``None`` for any other body, and where that distance varies.
    """

    name: str
    role: Role
    points: tuple[str, ...]
    frame: Frame | None
    guide: str | None = None
    length: float | None = None

    @property
    def turns_with(self) -> str | None:
        """The coordinate whose angular velocity is its own; ``None`` where it only translates."""
        return None if self.frame is None else self.frame.angle_of


@dataclass(frozen=True)
class Line:
    """A straight line fixed on a body: through point ``through``, at an angle.

    Its direction is ``angle`` (rad) plus, where ``angle_of`` names a
    coordinate, that coordinate's position (as a :class:`Frame`'s angle): a
    slot along a lever turns with it (``angle_of`` the lever, ``angle`` 0), a
    fixed guide or a translating yoke's slot keeps its ``angle``.
    """

    through: str
    angle_of: str | None
    angle: float = 0.0


@dataclass(frozen=True)
class Joint:
    """A joint between two bodies.

    Attributes
    ----------
    name : str
        Its name: the coordinate it moves for a driver or a prismatic joint
        (a crank's link, a slider, an actuator), else the point of a pin
        (``POINT/BODY`` where several pins share a point).
    type : JointType
        Revolute, prismatic, or a lock.
    body : str
        The body it moves (the child: the body the fragment adds).
    on : str
        The body it joins that body to (the parent; for a pin fixed on several
        bodies, the first that carried it).
    at : str
        Its point: a pin's centre, a block's point on its line, the pivot a
        lock holds.
    line : Line or None
        For a prismatic joint: the line its point slides on, fixed on ``on``.
    driver : bool
        Whether a driver moves it (a crank's motor, an actuator).
    intermittent : bool
        Whether it acts only part of the cycle (a Geneva slot while the pin is
        in it; the wheel's lock while it is not).
    copies : int
        How many identical slots it stands for, evenly spaced about ``on``'s
        frame origin (a Geneva wheel's ``n``); 1 elsewhere.
    """

    name: str
    type: JointType
    body: str
    on: str
    at: str
    line: Line | None = None
    driver: bool = False
    intermittent: bool = False
    copies: int = 1


@dataclass(frozen=True)
class Motion:
    """A relative motion the velocity and acceleration polygons walk.

    Point ``end`` moves on ``body`` about point ``start`` fixed on it; with a
    ``slider``, ``end`` is a pin sliding in ``body`` (the motion is that of
    the body's point under the pin, then the slider's sliding to the pin).
    """

    body: str
    start: str
    end: str
    slider: str | None = None


@dataclass(frozen=True)
class Fragment:
    """What one kind adds to the mechanism (one driver, dyad or carried point).

    Attributes
    ----------
    key : str
        The item's name in messages (its new point, lever or carried point).
    bodies : tuple of Body
        The bodies it adds.
    joints : tuple of Joint
        The joints it adds. A joint's ``on`` may be ``None``: the body that
        carries its point ``at`` (resolved by :func:`build_graph`).
    coordinates : mapping of str to JointType
        The output joints it moves (links' angles, sliders, actuators).
    motions : tuple of Motion
        Its relative motions, for the polygons.
    carried : tuple of (str, str)
        Points it fixes on bodies already placed: (body, point).
    """

    key: str
    bodies: tuple[Body, ...] = ()
    joints: tuple[Any, ...] = ()
    coordinates: Mapping[str, JointType] = field(default_factory=dict)
    motions: tuple[Motion, ...] = ()
    carried: tuple[tuple[str, str], ...] = ()


def pin(body: str, at: str, on: str | None = None, *, driver: bool = False,
        name: str | None = None) -> Joint:
    """Return a revolute joint of ``body`` at ``at`` (on the body carrying it, unless ``on``)."""
    return Joint(name or at, REVOLUTE, body, on or '', at, driver=driver)


def slide(body: str, at: str, name: str, line: Line, on: str | None = None,
          *, driver: bool = False, intermittent: bool = False, copies: int = 1) -> Joint:
    """Return a prismatic joint ``name``: ``body``'s point ``at`` slides on ``line`` of ``on``.

    ``on`` defaults to the body carrying the line's point.
    """
    return Joint(name, PRISMATIC, body, on or '', at, line, driver, intermittent, copies)


@dataclass(frozen=True)
class Graph:
    """A mechanism's bodies and joints: built once per scene, read by every concern.

    Attributes
    ----------
    ground : str
        The ground body's name.
    bodies : dict of str to Body
        Every body, the ground first, then in the scene's order (drivers,
        dyads; the points carried on a body appended to its ``points``).
    joints : tuple of Joint
        Every joint, in the same order, each ``on`` resolved.
    coordinates : dict of str to JointType
        Every output joint (coordinate) of the mechanism, drivers first.
    motions : tuple of Motion
        The relative motions of the polygons, in the scene's order.
    fragments : tuple of Fragment
        What each kind added, in the scene's order (drivers, dyads, points).
    drivers : tuple of str
        The drivers' coordinates, in the scene's order.
    """

    ground: str
    bodies: dict[str, Body]
    joints: tuple[Joint, ...]
    coordinates: dict[str, JointType]
    motions: tuple[Motion, ...]
    fragments: tuple[Fragment, ...]
    drivers: tuple[str, ...]

    def frames(self) -> Iterator[tuple[str, Frame]]:
        """Yield (body, frame) of every moving body, in order."""
        for name, body in self.bodies.items():
            if body.frame is not None:
                yield name, body.frame

    def carriers(self, point: str) -> tuple[str, ...]:
        """Return the bodies ``point`` is fixed on, in order."""
        return tuple(name for name, body in self.bodies.items() if point in body.points)

    def pins(self) -> Iterator[tuple[str, str, str]]:
        """Yield (body, body, point) for every two bodies sharing a point (each pin's pair)."""
        owners: dict[str, list[str]] = {}
        for body in self.bodies.values():
            for point in body.points:
                owners.setdefault(point, []).append(body.name)
        for point, owned in owners.items():
            for i, a in enumerate(owned):
                for b in owned[i + 1:]:
                    yield a, b, point

    def slides(self) -> Iterator[tuple[str, str]]:
        """Yield (block, guide body) of every slider block."""
        for name, body in self.bodies.items():
            if body.guide is not None:
                yield name, body.guide

    def cylinders(self) -> Iterator[Joint]:
        """Yield every driven prismatic joint whose guide is a barrel: a cylinder's rod.

        An actuator's rod slides in its barrel, a link with no fixed length
        (the link whose length it drives). A driven prismatic joint on the
        ground is a driven block on a fixed guide (a slider driver's), one
        along a rigid link a driven collar: a slider block like any other.
        """
        for joint in self.joints:
            if joint.driver and joint.line is not None and joint.on != self.ground \
                    and self.bodies[joint.on].length is None:
                yield joint

    def prismatic(self, block: str) -> Joint:
        """Return the prismatic joint a slider block slides by."""
        return next(j for j in self.joints if j.body == block and j.line is not None)

    def pivots(self) -> dict[str, str]:
        """Return body -> ground point of every body turning about a ground pivot (a pin)."""
        return {j.body: j.at for j in self.joints if j.on == self.ground and j.type.table
                and j.line is None}

    def intermittent(self) -> set[str]:
        """Return the bodies an intermittent joint moves or holds (a Geneva wheel, its block)."""
        return {name for j in self.joints if j.intermittent for name in (j.body, j.on)
                if name != self.ground}

    def reversing(self) -> dict[str, JointType]:
        """Return the coordinates that can reverse (dead centres): rockers and guided sliders.

        The angle of a body turning about a ground pivot that no driver turns,
        the slider of a block on a fixed guide; none of an intermittent drive,
        which only indexes.
        """
        skip = self.intermittent()
        result: dict[str, JointType] = {}
        for joint in self.joints:
            if joint.on != self.ground or joint.driver or joint.body in skip \
                    or not joint.type.table:
                continue
            if joint.line is not None:
                result[joint.name] = joint.type
            elif self.bodies[joint.body].turns_with == joint.body:
                result[joint.body] = self.coordinates[joint.body]
        return result


def build_graph(fragments: Iterable[Fragment], names: Iterable[str],
                ground_points: Iterable[str], drivers: Iterable[str]) -> Graph:
    """Join the kinds' fragments into one graph.

    ``names`` are every name the scene uses (the ground body takes
    :data:`GROUND` unless it is one of them); ``ground_points`` the scene's
    fixed points, carried by the ground; ``drivers`` the drivers' names.
    :data:`THE_GROUND` in a fragment stands for the ground body. A joint whose
    ``on`` is empty is put on the first body carrying its point (its line's
    point, for a prismatic joint); pins sharing a point are named
    ``POINT/BODY`` (``/`` is in no scene name).
    """
    fragments = tuple(fragments)
    ground = GROUND if GROUND not in set(names) else '_' + GROUND

    def named(body: str) -> str:
        return ground if body == THE_GROUND else body

    points: dict[str, list[str]] = {ground: list(ground_points)}
    added: dict[str, Body] = {}
    for fragment in fragments:
        for body in fragment.bodies:
            fixed = points.setdefault(body.name, [])
            fixed.extend(p for p in body.points if p not in fixed)
            added.setdefault(body.name, body)
        for name, point in fragment.carried:
            points[name].append(point)
    owner: dict[str, str] = {}
    for name, fixed in points.items():
        for point in fixed:
            owner.setdefault(point, name)
    joints = []
    for fragment in fragments:
        for joint in fragment.joints:
            where = joint.line.through if joint.line is not None else joint.at
            joints.append(replace(joint, on=named(joint.on) if joint.on else owner[where]))
    count = Counter(j.name for j in joints)
    joints = [replace(j, name=f'{j.at}/{j.body}') if count[j.name] > 1 else j for j in joints]
    bodies = {ground: Body(ground, Role.GROUND, tuple(points[ground]), None)}
    for name, body in added.items():
        bodies[name] = replace(body, points=tuple(points[name]),
                               guide=None if body.guide is None else named(body.guide))
    coordinates: dict[str, JointType] = {}
    for fragment in fragments:
        coordinates.update(fragment.coordinates)
    return Graph(ground, bodies, tuple(joints), coordinates,
                 tuple(m for f in fragments for m in f.motions), fragments, tuple(drivers))
