# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A robot's planar loops as a scene: bodies, pins and slides, decomposed into our kinds.

From a :class:`~.description.Description` and its actuated joints:

1. **Bodies.** Links joined by fixed joints (or welded by a closure) are one
   rigid body, in the frame of its link nearest the root. Every moving joint
   and every pin closure joins two bodies.
2. **Loops.** The biconnected components of that graph of bodies with more
   than one joint are the mechanisms (a leg's five-bar, a gripper's
   four-bar); every other joint is outside every loop and passes through.
   A mechanism's ground is its body nearest the root.
3. **The plane.** Every revolute axis of a mechanism (and a closure's, where
   written) must be parallel to one normal, every prismatic axis across it,
   within :data:`PLANAR_TOLERANCE` rad: else refused naming the joint whose
   axis is off and by how much. The plane's frame is fixed on the ground body.
4. **Geometry**, at the reference pose (the zero pose unless given): each
   body's points (its pins, each closure's point on it) in the plane, each
   from that body's own frame, so that a closure whose two points miss each
   other by a rounding still gives each body its exact shape. A closure
   whose points miss by more than :data:`GAP_TOLERANCE` of the loop's size
   is refused with the gap (a weld: its two frames' distance and turn; a
   slide closure, which is one more prismatic joint of the loop: its origins
   off its line, and its turn). A body with two coaxial pins and nothing else
   (idle: it could spin between them) turns with its first revolute joint,
   held at its reference value.
5. **Drivers and dyads.** An actuated revolute joint on the ground is a
   crank; an actuated prismatic joint between a barrel and a rod, each
   pinned once, is a cylinder (an actuator). Then, while bodies remain, a
   dyad of our kinds whose attachments are known is placed (Assur groups of
   class II): RRR (two links, or a link and a cylinder), RRP (a link and a
   block on a guide of the ground), RPR (a lever on a ground pivot, its slot
   through the pivot, and the block in it), RPP (a yoke on a ground guide and
   the block in its slot). Where no dyad is ready, a triad (class III: a
   link with three pins to three unplaced links, each pinned to a placed
   body). Each group's branch is the reference pose's. What neither places
   (a group of a higher class) is refused.

The result is a scene mapping (what ``urdf2scene`` writes, read by
:func:`~mech_kinematics.scene.parse_scene`) and, for every URDF joint of
every loop, the affine map from the scene's coordinates to the joint's own
value: a revolute joint's value is its reference value plus ``sigma`` (+1
or -1: its axis along or against the plane's normal) times the turn of its
child body relative to its parent body; a prismatic joint's is its
reference value plus ``kappa`` (+1 or -1) times the change of the scene's
slider coordinate it moves. Pure: NumPy only.
"""

from __future__ import annotations

import cmath
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, field
import math
import re
from typing import Any

import numpy as np

from .assembly import revolute_centre
from .description import Closure, ClosureKind, Description, UrdfJoint
from .transforms import Matrix
from ..errors import UrdfError
from ..solver.graph import JointType, PRISMATIC, REVOLUTE
from ..solver.model import IDENTIFIER

__all__ = ['DriverMap', 'GAP_TOLERANCE', 'JointMap', 'PLANAR_TOLERANCE', 'Planar',
           'TOGGLE_TOLERANCE', 'planar_from_description']

#: Largest angle (rad) between a revolute axis and the loop's normal (or a prismatic axis
#: and the plane), and largest offset of a slot or cylinder line from its pin over the
#: loop's size: an exact planar solution closes the URDF's own loops to about this.
PLANAR_TOLERANCE = 1e-12
#: Largest gap between a closure's two points at the reference pose, over the loop's size.
GAP_TOLERANCE = 1e-6
#: A joint's value in the model within this (relative) of its pose's is the pose's.
SNAP = 1e-13
#: Smallest sine of the angle at a dyad's new pin at the reference pose (its branch).
TOGGLE_TOLERANCE = 1e-9


@dataclass(frozen=True)
class JointMap:
    """How one URDF joint of a loop follows the scene's coordinates.

    A revolute joint: ``value = reference + sigma * ((child - child_ref) -
    (parent - parent_ref))`` with ``child`` and ``parent`` the scene's angle
    coordinates its bodies turn with (``None``: a body that does not turn:
    the ground, a block on a guide). A prismatic joint: ``value = reference +
    sigma * (slider - slider_ref)``, ``slider`` the scene's coordinate.
    ``center`` is the middle of the joint's limits (0 without): a revolute
    value is reported within pi of it.
    """

    name: str
    type: JointType
    sigma: float
    reference: float
    child: str | None = None
    child_ref: float = 0.0
    parent: str | None = None
    parent_ref: float = 0.0
    slider: str | None = None
    slider_ref: float = 0.0
    center: float = 0.0
    mechanism: int = 0


@dataclass(frozen=True)
class DriverMap:
    """A scene driver from a URDF joint: ``scene = scene_ref + sigma * (urdf - reference)``.

    ``mimic`` is the joint's mimic rule where the driver is a mimic joint
    whose leader is an actuated joint (its value follows the leader's).
    """

    name: str
    scene: str
    type: JointType
    sigma: float
    reference: float
    scene_ref: float
    mimic: Any = None

    def scene_value(self, value: Any) -> Any:
        """Return the scene driver's position at the URDF joint's ``value`` (rad or m)."""
        return self.scene_ref + self.sigma * (value - self.reference)

    def joint_value(self, value: Any) -> Any:
        """Return the URDF joint's value at the scene driver's position ``value``."""
        return self.reference + (value - self.scene_ref) / self.sigma

    @property
    def gain(self) -> tuple[str, float]:
        """Return the joint that moves this driver and d(scene value) / d(its value).

        The actuated joint itself (``sigma``), or a mimic's leader (``sigma``
        times the multiplier): the driver's scene effort times the gain is the
        generalised force on that joint (the same power).
        """
        if self.mimic is None:
            return self.name, self.sigma
        return self.mimic.joint, self.sigma * self.mimic.multiplier


@dataclass
class Planar:
    """A robot's loops as a scene mapping, with the maps of its joints.

    Attributes
    ----------
    data : dict
        The scene mapping (``parse_scene``'s input), SI units.
    drivers : tuple of DriverMap
        The scene's drivers in its order, each from a URDF joint.
    joints : dict of str to JointMap
        Every URDF joint of every loop.
    mechanisms : list of dict
        Per mechanism: its ``ground`` link, ``links``, ``joints``, ``normal``
        and the scene plane's axes ``x`` and ``y`` (in the ground link's
        frame), ``size`` (m), ``gap`` (the largest closure gap at the
        reference pose, m), ``bodies`` (the scene's bodies it became),
        ``body_names`` (each moving URDF body's scene body) and ``drivers``
        (the URDF joints that drive it, a mimic among them).
    actuated : tuple of str
        The actuated joints (given, the sidecar's or the URDF's).
    names : dict of str to str
        URDF name -> scene name, where they differ (a name that is no
        identifier, or used twice).
    masses : dict of str to dict
        The scene's ``masses:`` from the ``<inertial>`` of the links each
        moving body holds (``urdf2scene`` writes them; ``data`` leaves them
        out, so that solving a robot's joints computes no forces).
    links : dict of str to (str, ndarray, ndarray)
        Each URDF link a loop moves: its scene body and the affine map of a
        point of the link's frame (m) into the body's own frame (the one a
        mass's ``com`` is given in): ``local = A @ p + b``, ``A`` 2x3. Only
        where the robot has masses (what its forces, and loads on its links,
        read); empty otherwise (:meth:`link_frame` gives one when asked).
    planes : dict of str to (str, ndarray, ndarray)
        Each URDF link a loop moves: its scene body and the map of a point of
        the link's frame into the scene's plane in the reference pose (``A @
        p + b``).
    lifts : dict of str to (int, ndarray, ndarray)
        Each of those links: its mechanism's index and the affine map of a
        point ``z`` of the scene's plane (m) to the ground link's frame at the
        height of the link's frame origin over the plane, ``E @ z + o``
        (``E`` 3x2: the plane's axes): where that origin is when ``z`` is
        its place in the plane.
    pins : dict of str to str
        Each joint and closure of a loop -> the scene point at its pin (its
        name, or another where :attr:`names` says so: a motor named after the
        joint may hold its name).
    """

    data: dict[str, Any]
    drivers: tuple[DriverMap, ...]
    joints: dict[str, JointMap]
    mechanisms: list[dict[str, Any]]
    actuated: tuple[str, ...] = ()
    names: dict[str, str] = field(default_factory=dict)
    masses: dict[str, dict[str, Any]] = field(default_factory=dict)
    links: dict[str, tuple[str, Any, Any]] = field(default_factory=dict)
    planes: dict[str, tuple[str, Any, Any]] = field(default_factory=dict)
    lifts: dict[str, tuple[int, Any, Any]] = field(default_factory=dict)
    pins: dict[str, str] = field(default_factory=dict)

    def link_frame(self, link: str) -> tuple[str, Any, Any]:
        """Return a moving link's map into its scene body's own frame (:attr:`links`' form).

        Read from :attr:`links` where the robot has masses, else found from the
        scene solved where its drivers start (``KeyError``: a link no loop moves).
        """
        if link in self.links:
            return self.links[link]
        body = self.planes[link][0]
        return _link_frames({link: self.planes[link]}, _body_poses(self.data, [body]))[link]


# --- names -----------------------------------------------------------------------------


class _Names:
    """Scene names for URDF names: identifiers, each used once across the scene."""

    def __init__(self) -> None:
        self.used: set[str] = set()
        self.given: dict[tuple[str, str], str] = {}
        self.changed: dict[str, str] = {}

    def __call__(self, kind: str, urdf: str) -> str:
        key = (kind, urdf)
        if key in self.given:
            return self.given[key]
        base = re.sub(r'[^A-Za-z0-9_]', '_', urdf) or '_'
        if not IDENTIFIER.match(base):
            base = '_' + base
        name, count = base, 1
        while name in self.used or name == 'ground':
            count += 1
            name = f'{base}_{count}'
        self.used.add(name)
        self.given[key] = name
        if name != urdf:
            self.changed[urdf] = name
        return name


# --- the graph of bodies ---------------------------------------------------------------


@dataclass
class _Edge:
    """A joint between two bodies: a tree joint (revolute, prismatic, free) or a pin closure."""

    name: str
    a: str                      # the parent side's body (a closure's link_a)
    b: str                      # the child side's body
    kind: str                   # 'pin', 'slide' or 'free'
    joint: UrdfJoint | None = None
    closure: Closure | None = None


def _bodies(description: Description, weld: list[Closure],
            locked: Mapping[str, Matrix] | None = None
            ) -> tuple[dict[str, str], dict[str, Matrix]]:
    """Return link -> body (its group's link nearest the root) and each link in its body.

    Links joined by fixed joints, links welded by a closure, and the links of a
    ``locked`` joint (name -> its child's frame in its parent's), are one body.
    """
    parent = {link: link for link in description.links}

    def find(x: str) -> str:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    rigid: list[tuple[str, str, Matrix]] = []
    for joint in description.joints.values():
        if not joint.moving:
            rigid.append((joint.parent, joint.child, joint.origin))
    for closure in weld:
        rigid.append((closure.link_a, closure.link_b,
                      closure.frame_a @ np.linalg.inv(closure.frame_b)))
    for name, motion in (locked or {}).items():
        joint = description.joints[name]
        rigid.append((joint.parent, joint.child, motion))
    for a, b, _ in rigid:
        parent[find(a)] = find(b)
    groups: dict[str, list[str]] = {}
    for link in description.links:
        groups.setdefault(find(link), []).append(link)
    body_of: dict[str, str] = {}
    in_body: dict[str, Matrix] = {}
    neighbours: dict[str, list[tuple[str, Matrix]]] = {}
    for a, b, t in rigid:
        neighbours.setdefault(a, []).append((b, t))
        neighbours.setdefault(b, []).append((a, np.linalg.inv(t)))
    for members in groups.values():
        top = min(members, key=lambda link: (description.depth(link), description.order(link)))
        in_body[top] = np.eye(4)
        stack = [top]
        while stack:
            link = stack.pop()
            body_of[link] = top
            for other, t in neighbours.get(link, ()):
                if other not in in_body:
                    in_body[other] = in_body[link] @ t
                    stack.append(other)
    return body_of, in_body


def _idle_joints(description: Description, body_of: dict[str, str],
                 in_body: dict[str, Matrix], edges: list[_Edge], pose: Mapping[str, float]
                 ) -> dict[str, Matrix]:
    """Return the joints to lock (name -> its child's frame in its parent's at the pose).

    An idle body has two pins and nothing else, coaxial (the same point,
    parallel axes where written), at least one a revolute joint: it could spin
    between them without moving the loop (Extended URDF's ``6d`` closure of
    two joint frames makes one, its ``3d`` closure two). It turns with the body
    of its first revolute joint in file order: that joint is locked at its
    pose's value, the other pin answers the turn.
    """
    touching: dict[str, list[_Edge]] = {}
    for edge in edges:
        touching.setdefault(edge.a, []).append(edge)
        touching.setdefault(edge.b, []).append(edge)
    root = body_of[description.root]
    order = list(description.joints)
    out: dict[str, Matrix] = {}
    for body, mine in touching.items():
        if body == root or len(mine) != 2 or any(e.kind != 'pin' for e in mine) \
                or all(e.joint is None for e in mine):
            continue
        ends = []
        for edge in mine:
            ends.append(_pin_on(edge, body, body_of, in_body))
        (p, u), (q, v) = ends
        # math.hypot in floats: a point at 1e308 m overflows no square (no numpy warning)
        scale = max(1.0, math.hypot(*map(float, p)), math.hypot(*map(float, q)))
        gap = math.hypot(*(float(a) - float(b) for a, b in zip(p, q, strict=True)))
        if gap > PLANAR_TOLERANCE * scale or (
                u is not None and v is not None
                and float(np.linalg.norm(np.cross(u, v))) > PLANAR_TOLERANCE):
            continue
        first = min((e.joint for e in mine if e.joint is not None),
                    key=lambda j: order.index(j.name))
        if first.name not in out:
            out[first.name] = first.motion(pose.get(first.name, 0.0))
    return out


def _pin_on(edge: _Edge, body: str, body_of: dict[str, str], in_body: dict[str, Matrix]
            ) -> tuple[np.ndarray, np.ndarray | None]:
    """Return a pin's point and axis (None: not written) in the frame of ``body``, one end."""
    if edge.joint is not None:
        joint = edge.joint
        frame = in_body[joint.child] if body_of[joint.child] == body \
            else in_body[joint.parent] @ joint.origin
        return frame[:3, 3], frame[:3, :3] @ np.asarray(joint.axis)
    closure = edge.closure
    assert closure is not None
    link, on, axis = ((closure.link_a, closure.frame_a, closure.axis_a)
                      if body_of[closure.link_a] == body else
                      (closure.link_b, closure.frame_b, closure.axis_b))
    frame = in_body[link] @ on
    return frame[:3, 3], None if axis is None else in_body[link][:3, :3] @ np.asarray(axis)


def _components(bodies: list[str], edges: list[_Edge]) -> list[list[int]]:
    """Return the biconnected components (lists of edge indices) of a multigraph."""
    adjacency: dict[str, list[tuple[str, int]]] = {b: [] for b in bodies}
    for index, edge in enumerate(edges):
        adjacency[edge.a].append((edge.b, index))
        adjacency[edge.b].append((edge.a, index))
    order: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[int] = []
    out: list[list[int]] = []
    counter = 0
    for start in bodies:
        if start in order:
            continue
        order[start] = low[start] = counter
        counter += 1
        work: list[tuple[str, int, Iterator[tuple[str, int]]]] = [
            (start, -1, iter(adjacency[start]))]
        while work:
            node, via, neighbours = work[-1]
            advanced = False
            for other, index in neighbours:
                if index == via:
                    continue
                if other not in order:
                    stack.append(index)
                    order[other] = low[other] = counter
                    counter += 1
                    work.append((other, index, iter(adjacency[other])))
                    advanced = True
                    break
                if order[other] < order[node]:
                    stack.append(index)
                    low[node] = min(low[node], order[other])
            if advanced:
                continue
            work.pop()
            if work:
                parent_node = work[-1][0]
                low[parent_node] = min(low[parent_node], low[node])
                if low[node] >= order[parent_node]:
                    component = []
                    while stack:
                        index = stack.pop()
                        component.append(index)
                        if index == via:
                            break
                    out.append(component)
    return out


# --- geometry helpers ------------------------------------------------------------------


def _rotation_angle(rotation: Matrix, axis: Iterable[float]) -> float:
    """Return the angle of ``rotation`` about the unit ``axis`` (rad)."""
    a = np.asarray(tuple(axis), dtype=np.float64)
    vee = np.array([rotation[2, 1] - rotation[1, 2], rotation[0, 2] - rotation[2, 0],
                    rotation[1, 0] - rotation[0, 1]])
    # A rotation by q about a: R - R^T = 2 sin q [a]x and trace R = 1 + 2 cos q.
    return math.atan2(0.5 * float(a @ vee), 0.5 * (float(np.trace(rotation)) - 1.0))


def _angle(v: complex) -> float:
    return math.atan2(v.imag, v.real)


def _diameter(points: Iterable[complex]) -> float:
    """Return the largest distance between two of ``points`` (0 for fewer than two).

    The farthest two points are corners of the convex hull: the hull (Andrew's
    monotone chain, n log n) of the distinct points, then every pair of what
    it keeps. A point is dropped only where it turns clearly inward (by more
    than 1e-9 of the turn's size, far above rounding), so every corner is kept
    and the answer is the distance of every pair, to the bit. Points on a
    circle (a hull of them all) cost the pairs of the hull.
    """
    unique = sorted({(z.real, z.imag) for z in points})
    if len(unique) < 3:
        return abs(complex(*unique[0]) - complex(*unique[-1])) if unique else 0.0

    def inward(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> bool:
        ax, ay, bx, by = a[0] - o[0], a[1] - o[1], b[0] - o[0], b[1] - o[1]
        return ax * by - ay * bx < -1e-9 * math.hypot(ax, ay) * math.hypot(bx, by)

    hull: list[tuple[float, float]] = []
    for chain in (unique, unique[::-1]):  # the lower half, then the upper
        start = len(hull)
        for p in chain:
            while len(hull) >= start + 2 and inward(hull[-2], hull[-1], p):
                hull.pop()
            hull.append(p)
    corners = np.array([complex(x, y) for x, y in dict.fromkeys(hull)])
    best = 0.0
    for i in range(len(corners) - 1):
        d = corners[i + 1:] - corners[i]
        best = max(best, float(np.hypot(d.real, d.imag).max()))  # abs(complex) is hypot
    return best


def _fmt(vector: Iterable[float]) -> str:
    return '[' + ', '.join(f'{v:.6g}' for v in vector) + ']'


# --- one mechanism ---------------------------------------------------------------------


class _Mechanism:
    """One loop component: its bodies, pins and slides in its plane, and its dyads."""

    def __init__(self, index: int, edges: list[_Edge], model: dict[str, Matrix],
                 in_body: dict[str, Matrix], body_of: dict[str, str], description: Description,
                 ground: str, pose: Mapping[str, float]) -> None:
        self.index = index
        self.edges = edges
        self.description = description
        self.ground = ground
        self.bodies = sorted({e.a for e in edges} | {e.b for e in edges},
                             key=description.order)
        self.source = description.source
        to_ground = np.linalg.inv(model[ground])
        # Each link's frame in the ground's frame, by its body's geometry (the model).
        bodies = set(self.bodies)
        self.frame = {link: to_ground @ model[body_of[link]] @ in_body[link]
                      for link in description.links if body_of[link] in bodies}
        self.body_of = body_of
        self.pose = pose
        self._plane()
        self._points()

    def fail(self, msg: str, joint: str | None = None) -> UrdfError:
        return UrdfError(f'{self.source}: {msg}', joint=joint)

    # The plane: its normal from the revolute axes, every axis checked.
    def _axis(self, edge: _Edge) -> list[tuple[str, np.ndarray]]:
        if edge.joint is not None:
            joint = edge.joint
            frame = self.frame[joint.parent] @ joint.origin
            return [(joint.name, frame[:3, :3] @ np.asarray(joint.axis))]
        closure = edge.closure
        assert closure is not None
        out = []
        for link, axis in ((closure.link_a, closure.axis_a), (closure.link_b, closure.axis_b)):
            if axis is not None:
                out.append((closure.name, self.frame[link][:3, :3] @ np.asarray(axis)))
        return out

    def _plane(self) -> None:
        turning = [(name, axis) for e in self.edges if e.kind == 'pin' for name, axis
                   in self._axis(e)]
        if not turning:
            raise self.fail(f'joint "{self.edges[0].name}": Expected a loop with a revolute '
                            f'joint, got one of prismatic joints only', self.edges[0].name)
        first, normal = turning[0]
        normal = normal / np.linalg.norm(normal)
        worst = (0.0, '', '')
        for edge in self.edges:
            if edge.kind == 'free':
                raise self.fail(f'joint "{edge.name}": Expected the joints of a loop to be '
                                f'revolute, continuous or prismatic, got '
                                f'{edge.joint.urdf_type if edge.joint else "?"}', edge.name)
            for name, axis in self._axis(edge):
                axis = axis / np.linalg.norm(axis)
                if edge.kind == 'pin':
                    off = math.atan2(float(np.linalg.norm(np.cross(axis, normal))),
                                     abs(float(axis @ normal)))
                    what = 'parallel to'
                else:
                    off = math.asin(min(1.0, abs(float(axis @ normal))))
                    what = 'across'
                if off > worst[0]:
                    worst = (off, name, what)
        if worst[0] > PLANAR_TOLERANCE:
            off, name, what = worst
            links = ', '.join(self.bodies[:6]) + (', ...' if len(self.bodies) > 6 else '')
            raise self.fail(
                f'joint "{name}": Expected every joint of the loop through {links} to turn '
                f'about an axis parallel to its normal {_fmt(normal)} (in link '
                f'"{self.ground}", from joint "{first}") or slide across it, got an axis '
                f'{worst[2].replace("parallel to", "off it").replace("across", "off the plane")}'
                f' by {off:.3g} rad (more than {PLANAR_TOLERANCE:g}): the loop is not planar',
                name)
        # The normal's sign: along the ground's z, else y, else x; the plane's x from the
        # ground's x (or y).
        for basis in np.eye(3)[::-1]:
            if abs(float(normal @ basis)) > 1e-6:
                if normal @ basis < 0:
                    normal = -normal
                break
        x = np.eye(3)[0] if np.linalg.norm(np.cross(np.eye(3)[0], normal)) > 0.5 \
            else np.eye(3)[1]
        e1 = x - (x @ normal) * normal
        e1 /= np.linalg.norm(e1)
        self.normal, self.e1, self.e2 = normal, e1, np.cross(normal, e1)
        self.first = first

    def flat(self, point: np.ndarray) -> complex:
        """Return a point of the ground's frame (3 or 4 components) in the plane."""
        p = np.asarray(point)[:3]
        return complex(float(p @ self.e1), float(p @ self.e2))

    def sign(self, edge: _Edge) -> float:
        """Return +1 where a joint's axis points along the normal, -1 against."""
        assert edge.joint is not None
        frame = self.frame[edge.joint.parent] @ edge.joint.origin
        return 1.0 if float(frame[:3, :3] @ np.asarray(edge.joint.axis) @ self.normal) > 0 \
            else -1.0

    def _points(self) -> None:
        """Each body's points (its pins) in the plane, each from that body's own frame."""
        self.pins: dict[str, dict[str, complex]] = {b: {} for b in self.bodies}
        self.pin_ends: dict[str, tuple[str, str]] = {}
        self.slides: dict[str, _Edge] = {}
        self.edges_of: dict[str, list[_Edge]] = {b: [] for b in self.bodies}
        self.gaps: list[tuple[float, str]] = []
        slide_closures: list[_Edge] = []
        for edge in self.edges:
            self.edges_of[edge.a].append(edge)
            self.edges_of[edge.b].append(edge)
            if edge.kind == 'slide':
                self.slides[edge.name] = edge
                if edge.closure is not None:
                    slide_closures.append(edge)
                continue
            if edge.joint is not None:
                joint = edge.joint
                on_a = self.frame[joint.parent] @ joint.origin
                on_b = self.frame[joint.child]
            else:
                closure = edge.closure
                assert closure is not None
                on_a = self.frame[closure.link_a] @ closure.frame_a
                on_b = self.frame[closure.link_b] @ closure.frame_b
                # hypot, not a norm of squares: points 1e308 m apart are that far, not inf.
                gap = math.hypot(*(float(a) - float(b) for a, b in zip(on_a[:3, 3], on_b[:3, 3],
                                                                       strict=True)))
                self.gaps.append((gap, edge.name))
            self.pins[edge.a][edge.name] = self.flat(on_a[:, 3])
            self.pins[edge.b][edge.name] = self.flat(on_b[:, 3])
            self.pin_ends[edge.name] = (edge.a, edge.b)
        self.size = _diameter(p for pins in self.pins.values() for p in pins.values()) or 1.0
        for edge in slide_closures:
            off, turn = self._slide_gap(edge)
            self.gaps.append((off + turn * self.size, edge.name))
        for gap, name in self.gaps:
            if gap > GAP_TOLERANCE * self.size:
                raise self.fail(
                    f'closure "{name}": Expected the reference pose to close the loop within '
                    f'{GAP_TOLERANCE:g} of its size ({self.size:.6g} m), got its two points '
                    f'{gap:.3g} m apart', name)

    def slide_direction(self, edge: _Edge, block: str) -> complex:
        """Return the unit direction ``block`` moves relative to the other body per +1 m."""
        u = self.flat(self._slide_axis(edge))
        u /= abs(u)
        return u if block == edge.b else -u

    def _slide_axis(self, edge: _Edge) -> np.ndarray:
        """Return a slide's axis in the ground's frame: a joint's, or a closure's on link_a."""
        if edge.joint is not None:
            frame = self.frame[edge.joint.parent] @ edge.joint.origin
            return frame[:3, :3] @ np.asarray(edge.joint.axis)
        closure = edge.closure
        assert closure is not None and closure.axis_a is not None
        return self.frame[closure.link_a][:3, :3] @ np.asarray(closure.axis_a)

    def _slide_gap(self, edge: _Edge) -> tuple[float, float]:
        """Return a slide closure's miss at the reference pose: off its line (m), turned (rad).

        A prismatic closure holds its two frames parallel and their origins on
        one line along its axis.
        """
        closure = edge.closure
        assert closure is not None
        on_a = self.frame[closure.link_a] @ closure.frame_a
        on_b = self.frame[closure.link_b] @ closure.frame_b
        axis = self._slide_axis(edge)
        axis = axis / np.linalg.norm(axis)
        d = on_b[:3, 3] - on_a[:3, 3]
        off = float(np.linalg.norm(d - (d @ axis) * axis))
        turn = abs(_rotation_angle(on_a[:3, :3].T @ on_b[:3, :3], on_a[:3, :3].T @ self.normal))
        return off, turn

    def reference_value(self, joint: UrdfJoint) -> float:
        """Return a joint's value in the model's geometry (its pose's, to the closures' gaps)."""
        relative = np.linalg.inv(self.frame[joint.parent] @ joint.origin) \
            @ self.frame[joint.child]
        given = self.pose.get(joint.name, 0.0)
        assert joint.type is not None
        if joint.type.angular:
            angle = _rotation_angle(relative[:3, :3], joint.axis)
            value = given + math.remainder(angle - given, math.tau)
            # Through the tree alone the model is the pose: keep its value to the bit.
            return given if abs(value - given) <= SNAP * math.pi else value
        value = float(np.asarray(joint.axis) @ relative[:3, 3])
        return given if abs(value - given) <= SNAP * self.size else value


# --- the decomposition -----------------------------------------------------------------


class _Builder:
    """Places every mechanism's bodies by drivers and dyads: the scene mapping and the maps."""

    def __init__(self, description: Description, actuated: tuple[str, ...],
                 pose: Mapping[str, float]) -> None:
        self.description = description
        self.source = description.source
        self.actuated = actuated
        self.pose = pose
        self.names = _Names()
        self.ground: dict[str, list[float]] = {}
        self.inputs: list[dict[str, Any]] = []
        self.dyads: list[dict[str, Any]] = []
        self.points: dict[str, dict[str, Any]] = {}
        self.drivers: list[DriverMap] = []
        self.joint_maps: dict[str, JointMap] = {}
        self.offset = 0.0
        #: URDF body (its link nearest the root) -> the scene body it became.
        self.body_names: dict[str, str] = {}
        #: Scene body -> (mass kg, centre of mass in the scene's plane, inertia kg m^2 about
        #: it and the plane's normal), from the <inertial> of the URDF links it holds.
        self.mass_props: dict[str, tuple[float, complex, float]] = {}
        #: URDF link a loop moves -> (its scene body, ``A``, ``b``): a point of the link's
        #: frame ``p`` is ``complex(*(A @ p + b))`` in the scene's plane (reference pose).
        self.link_planes: dict[str, tuple[str, Any, Any]] = {}
        #: URDF link a loop moves -> (its mechanism's index, ``E``, ``o``): a point of the
        #: scene's plane ``z`` (m) at the height of the link's frame origin over the plane is
        #: ``E @ z + o`` in the mechanism's ground link's frame (``E`` 3x2).
        self.link_lifts: dict[str, tuple[int, Any, Any]] = {}

    def fail(self, msg: str, joint: str | None = None) -> UrdfError:
        return UrdfError(f'{self.source}: {msg}', joint=joint)

    # Names in the scene.
    def point(self, pin: str) -> str:
        return self.names('point', pin)

    def link(self, body: str) -> str:
        return self.names('link', body)

    def slider(self, joint: str) -> str:
        return self.names('slider', joint)

    def build(self, m: _Mechanism) -> None:
        self.m = m
        # Lay the mechanisms side by side in the scene's plane (each is solved in its own).
        xs = [p.real for pins in m.pins.values() for p in pins.values()]
        shift = self.offset - min(xs)
        self.shift = complex(shift, 0.0)
        self.offset = shift + max(xs) + 0.5 * m.size
        self.known: set[str] = {m.ground}
        self.placed: set[str] = set()
        # A body's angle: the scene coordinate it turns with and that coordinate's value in
        # the reference pose; (None, 0) for a body that does not turn.
        self.turns: dict[str, tuple[str | None, float]] = {m.ground: (None, 0.0)}
        for pin, z in m.pins[m.ground].items():
            self.ground[self.point(pin)] = self.xy(z)
            self.placed.add(pin)
        self.cylinders = self._cylinders()
        #: Actuated revolute joints between two moving links, until placed: (edge, mimic,
        #: index among the drivers, the motor's input entry).
        self.hinges: dict[str, tuple[_Edge, Any, int, dict[str, Any]]] = {}
        self._drivers()
        while len(self.known) < len(m.bodies):
            if not self._dyad():
                if self.hinges:
                    name, (edge, _, _, _) = next(iter(self.hinges.items()))
                    raise self.fail(
                        f'joint "{name}": Expected an actuated revolute joint between two '
                        f'moving links to turn a link about one the loop places without it (a '
                        f'hinge), or to be the knee of a loop re-rooted at it (a fold: one link '
                        f'pinned to a placed body, the other to a link pinned to one), got one '
                        f'between links "{edge.a}" and "{edge.b}", neither placed first nor so '
                        f'held: our kinds drive no relative angle there', name)
                left = [b for b in m.bodies if b not in self.known]
                joint = next(e.name for b in left for e in m.edges_of[b])
                raise self.fail(
                    f'joint "{joint}": Expected the loop through {", ".join(m.bodies[:6])} to '
                    f'decompose into dyads of our kinds (RRR, RRP, RPR, RPP, a cylinder) or '
                    f'triads, got links {", ".join(left)} that none places: a group of higher '
                    'class, a slider on a moving guide, a slot off its pivot or an actuated '
                    'joint our kinds do not drive', joint)
        self._joint_maps()
        self._masses()

    def _masses(self) -> None:
        """Gather each moving body's <inertial>s: mass, centre of mass, inertia about the normal.

        Links welded into one body add up (the parallel-axis theorem about their
        common centre of mass, distances measured in the plane).
        """
        m = self.m
        n = m.normal
        inertials = self.description.inertials
        held: dict[str, list[str]] = {}     # body -> its links with an <inertial>, file order
        for link in self.description.links:
            if link in inertials:
                held.setdefault(m.body_of[link], []).append(link)
        for link, body in m.body_of.items():
            if body != m.ground and body in m.bodies and link in m.frame \
                    and body in self.body_names:
                frame = m.frame[link]
                axes = np.array([m.e1, m.e2])
                shift = np.array([self.shift.real, self.shift.imag])
                self.link_planes[link] = (self.body_names[body], axes @ frame[:3, :3],
                                          axes @ frame[:3, 3] + shift)
                self.link_lifts[link] = (m.index, axes.T, float(n @ frame[:3, 3]) * n
                                         - axes.T @ shift)
        for body in m.bodies:
            if body == m.ground:
                continue
            parts = []
            for link in held.get(body, ()):
                inertial = inertials[link]
                frame = m.frame[link] @ inertial.origin
                rotation = frame[:3, :3]
                tensor = rotation @ inertial.inertia @ rotation.T
                parts.append((inertial.mass, m.flat(frame[:3, 3]) + self.shift,
                              float(n @ tensor @ n)))
            if not parts:
                continue
            total = math.fsum(p[0] for p in parts)
            com = sum((p[0] * p[1] for p in parts), 0j) / total
            inertia = math.fsum(i + mass * abs(c - com) ** 2 for mass, c, i in parts)
            self.mass_props[self.body_names[body]] = (total, com, inertia)

    def xy(self, z: complex) -> list[float]:
        w = z + self.shift
        return [w.real, w.imag]

    # --- drivers ---------------------------------------------------------------------------
    def _cylinders(self) -> dict[str, tuple[str, str, str, str]]:
        """Return actuated slide -> (barrel, rod, barrel's pin, rod's pin)."""
        m = self.m
        out = {}
        for name, edge in m.slides.items():
            if name not in self.drivers_here or m.ground in (edge.a, edge.b):
                continue    # a block driven on a fixed guide is a slider driver (_slider)
            ends = []
            for body in (edge.a, edge.b):
                others = [e for e in m.edges_of[body] if e is not edge]
                pins = [e for e in others if e.kind == 'pin']
                if len(others) != 1 or len(pins) != 1:
                    raise self.fail(
                        f'joint "{name}": Expected an actuated prismatic joint to be a cylinder '
                        f'(a barrel and a rod, each pinned once to the mechanism) or a block '
                        f'on a fixed guide, got link "{body}" with {len(others)} other joints',
                        name)
                ends.append(pins[0].name)
            out[name] = (edge.a, edge.b, ends[0], ends[1])
        return out

    def _drivers(self) -> None:
        m = self.m
        for name in self.drivers_here:   # a motor takes its joint's name before any point does
            edge = next(e for e in m.edges if e.name == name)
            if edge.kind == 'pin' and m.ground not in (edge.a, edge.b):
                self.names('motor', name)
        for name in self.drivers_here:
            edge = next(e for e in m.edges if e.name == name)
            joint = edge.joint
            assert joint is not None and joint.type is not None
            mimic = self.mimics.get(name)
            if joint.type.angular:
                if m.ground not in (edge.a, edge.b):
                    # A motor between two moving links: a hinge, placed once either link is
                    # (its angle and map then); its place among the drivers kept now.
                    entry: dict[str, Any] = {'motor': self.names('motor', name), 'speed': 0.0}
                    self.hinges[name] = (edge, mimic, len(self.drivers), entry)
                    self.inputs.append(entry)
                    self.drivers.append(None)    # type: ignore[arg-type]
                    continue
                self._crank(edge, mimic)
            elif m.ground in (edge.a, edge.b):
                self._slider(edge, mimic)
            # A cylinder is placed with the dyad that uses it.

    def _crank(self, edge: _Edge, mimic: Any) -> None:
        m = self.m
        body = edge.b if edge.a == m.ground else edge.a
        crank_link, tip, length, phi0, sigma, reference = self._turned(edge, body)
        start = self.pose.get(edge.name, 0.0)
        self.inputs.append({'link': crank_link, 'center': self.point(edge.name),
                            'point': self.point(tip), 'length': length,
                            'angle': phi0 + sigma * (start - reference), 'speed': 0.0})
        self.drivers.append(DriverMap(edge.name, crank_link, REVOLUTE, sigma, reference, phi0,
                                      mimic))

    def _turned(self, edge: _Edge, body: str) -> tuple[str, str, float, float, float, float]:
        """Place ``body``, turned about the actuated revolute joint ``edge`` (a crank, a hinge).

        Return its scene link, its tip (a pin away from the joint), its length,
        its angle at the reference pose, the joint's sign (``sigma``) and its
        reference value; its other pins are carried on it.
        """
        m = self.m
        centre = m.pins[body][edge.name]
        tip = self._tip(body, edge.name, centre)
        link = self.link(body)
        self.body_names[body] = link
        phi0 = _angle(m.pins[body][tip] - centre)
        assert edge.joint is not None
        sigma = m.sign(edge) * (1.0 if body == edge.b else -1.0)
        reference = m.reference_value(edge.joint)
        self.point(edge.name), self.point(tip)     # named before the pins it carries
        self.placed.add(tip)
        self._known(body, (link, phi0), edge.name, tip, phi0)
        return link, tip, abs(m.pins[body][tip] - centre), phi0, sigma, reference

    def _slider(self, edge: _Edge, mimic: Any) -> None:
        """Add a block driven along a fixed guide: position = (value - reference) along it."""
        m = self.m
        block = edge.b if edge.a == m.ground else edge.a
        pins = [e for e in m.edges_of[block] if e.kind == 'pin']
        others = [e for e in m.edges_of[block] if e is not edge and e.kind != 'pin']
        if len(pins) != 1 or others:
            raise self.fail(
                f'joint "{edge.name}": Expected an actuated prismatic joint on the ground to '
                f'drive a block pinned once to the mechanism (a slider), got link "{block}" '
                f'with {len(pins)} pins and {len(others)} other joints', edge.name)
        pin = pins[0].name
        g = m.slide_direction(edge, block)
        through = self.point(f'{edge.name}_guide')
        self.ground[through] = self.xy(m.pins[block][pin])
        assert edge.joint is not None
        reference = m.reference_value(edge.joint)
        name = self.slider(edge.name)
        self.inputs.append({'slider': name, 'point': self.point(pin),
                            'guide': {'through': through, 'angle': _angle(g)},
                            'position': self.pose.get(edge.name, 0.0) - reference,
                            'speed': 0.0})
        self.drivers.append(DriverMap(edge.name, name, PRISMATIC, 1.0, reference, 0.0, mimic))
        self.slider_of[edge.name] = (name, 1.0, 0.0)
        self.body_names[block] = name
        self.placed.add(pin)
        self._known(block, (None, 0.0), None, None, 0.0)

    def _tip(self, body: str, centre_pin: str, centre: complex) -> str:
        """Return a pin of ``body`` away from ``centre``: the crank's tip (added if none)."""
        m = self.m
        far = [p for p, z in m.pins[body].items()
               if p != centre_pin and abs(z - centre) > TOGGLE_TOLERANCE * m.size]
        if far:
            return far[0]
        tip = f'{body}_tip'
        m.pins[body][tip] = centre + 0.1 * m.size
        return tip

    # --- known bodies and carried points ---------------------------------------------------
    def _known(self, body: str, turns: tuple[str | None, float], origin: str | None,
               xaxis: str | None, direction: float) -> None:
        """Mark ``body`` placed; carry its other pins on it from (origin, x toward xaxis)."""
        m = self.m
        self.known.add(body)
        self.turns[body] = turns
        for pin, z in m.pins[body].items():
            if pin in self.placed:
                continue
            if origin is None or xaxis is None:
                raise self.fail(f'joint "{pin}": Expected a block that only slides to carry '
                                f'its one pin, got link "{body}" carrying another', pin)
            local = (z - m.pins[body][origin]) * complex(math.cos(direction),
                                                         -math.sin(direction))
            self.points[self.point(pin)] = {'link': turns[0], 'origin': self.point(origin),
                                            'xaxis': self.point(xaxis),
                                            'local': [local.real, local.imag]}
            self.placed.add(pin)

    def _known_pin(self, body: str) -> list[_Edge]:
        """Return ``body``'s pins to placed bodies."""
        return [e for e in self.m.edges_of[body] if e.kind == 'pin'
                and (e.b if e.a == body else e.a) in self.known]

    def _branch(self, p1: complex, p2: complex, c: complex, what: str, joint: str) -> int:
        cross = ((p2 - p1).conjugate() * (c - p1)).imag
        scale = abs(p2 - p1) * abs(c - p1) or 1.0
        if abs(cross) <= TOGGLE_TOLERANCE * scale:
            raise self.fail(
                f'joint "{joint}": Expected the reference pose to show the branch of {what}, '
                f'got its pins in line (a toggle or dead centre): give a reference pose '
                f'away from it', joint)
        return 1 if cross > 0 else -1

    # --- dyads -----------------------------------------------------------------------------
    def _dyad(self) -> bool:
        return (self._hinge() or self._rrr() or self._rrp() or self._rpr() or self._rpp()
                or self._triad() or self._fold())

    def _hinge(self) -> bool:
        """Place a link a motor turns on a placed one: its angle the parent's plus the motor's."""
        for name, (edge, mimic, index, entry) in self.hinges.items():
            if (edge.a in self.known) == (edge.b in self.known):
                continue
            parent, child = (edge.a, edge.b) if edge.a in self.known else (edge.b, edge.a)
            coordinate, parent_angle = self.turns[parent]
            if coordinate is None:
                raise self.fail(
                    f'joint "{name}": Expected an actuated revolute joint to turn a link about '
                    f'a link that turns, got one on "{parent}", a block that only slides', name)
            link, tip, length, phi0, sigma, reference = self._turned(edge, child)
            relative = phi0 - parent_angle
            entry['angle'] = relative + sigma * (self.pose.get(name, 0.0) - reference)
            self.dyads.append({'type': 'hinge', 'link': link, 'parent': self.link(parent),
                               'center': self.point(name), 'point': self.point(tip),
                               'length': length, 'motor': entry['motor']})
            self.drivers[index] = DriverMap(name, entry['motor'], REVOLUTE, sigma, reference,
                                            relative, mimic)
            del self.hinges[name]
            return True
        return False

    def _fold(self) -> bool:
        """Place a loop re-rooted at a motor between two links neither placed: a fold.

        The rocker is pinned to a placed body; the coupler, which the motor
        turns on the rocker, to a crank pinned to a placed body (a four-bar
        driven at its coupler-to-rocker pin).
        """
        m = self.m
        for name, (edge, mimic, index, entry) in self.hinges.items():
            if edge.a in self.known or edge.b in self.known:
                continue
            for rocker, coupler in ((edge.a, edge.b), (edge.b, edge.a)):
                if self._unit(rocker) != ('link', rocker) or \
                        self._unit(coupler) != ('link', coupler):
                    continue
                starts = [e for e in self._known_pin(rocker) if e.name != name]
                if not starts:
                    continue
                for knee in m.edges_of[coupler]:
                    crank = knee.b if knee.a == coupler else knee.a
                    if knee is edge or knee.kind != 'pin' or crank in self.known or \
                            crank == rocker or self._unit(crank) != ('link', crank):
                        continue
                    anchors = [e for e in self._known_pin(crank) if e.name != knee.name]
                    if anchors:
                        self._place_fold(name, edge, mimic, index, entry, (rocker, coupler, crank),
                                         (starts[0].name, knee.name, anchors[0].name))
                        return True
        return False

    def _place_fold(self, name: str, edge: _Edge, mimic: Any, index: int, entry: dict[str, Any],
                    bodies: tuple[str, str, str], pins: tuple[str, str, str]) -> None:
        """Add the fold of ``bodies`` (rocker, coupler, crank) at ``pins`` (D, B, A)."""
        m = self.m
        rocker, coupler, crank = bodies
        d_pin, b_pin, a_pin = pins
        p_a, p_b = m.pins[crank][a_pin], m.pins[crank][b_pin]
        p_d, p_c = m.pins[rocker][d_pin], m.pins[rocker][name]
        c_c, c_b = m.pins[coupler][name], m.pins[coupler][b_pin]
        names = [self.link(body) for body in bodies]
        for body, link in zip(bodies, names, strict=True):
            self.body_names[body] = link
        angles = [_angle(p_c - p_d), _angle(c_b - c_c), _angle(p_b - p_a)]
        assert edge.joint is not None
        sigma = m.sign(edge) * (1.0 if coupler == edge.b else -1.0)
        reference = m.reference_value(edge.joint)
        relative = angles[1] - angles[0]
        entry['angle'] = relative + sigma * (self.pose.get(name, 0.0) - reference)
        point, knee = self.point(b_pin), self.point(name)
        self.dyads.append({
            'type': 'fold', 'point': point, 'pin': knee, 'links': [
                {'name': names[2], 'from': self.point(a_pin), 'length': abs(p_b - p_a)},
                {'name': names[0], 'from': self.point(d_pin), 'length': abs(p_c - p_d)}],
            'coupler': {'name': names[1], 'length': abs(c_b - c_c)}, 'motor': entry['motor'],
            'branch': self._branch(p_a, p_d, p_b, f'fold {point}', b_pin)})
        self.drivers[index] = DriverMap(name, entry['motor'], REVOLUTE, sigma, reference,
                                        relative, mimic)
        del self.hinges[name]
        self.placed.update((b_pin, name))
        self._known(crank, (names[2], angles[2]), a_pin, b_pin, angles[2])
        self._known(rocker, (names[0], angles[0]), d_pin, name, angles[0])
        self._known(coupler, (names[1], angles[1]), name, b_pin, angles[1])

    def _unit(self, body: str) -> tuple[str, str] | None:
        """Return (kind, key): ``body`` as an RRR element: a link, or a cylinder's barrel."""
        for name, (barrel, rod, _, _) in self.cylinders.items():
            if body in (barrel, rod):
                return 'cylinder', name
        if any(e.kind == 'slide' for e in self.m.edges_of[body]):
            return None
        return 'link', body

    def _rrr(self) -> bool:
        m = self.m
        for pin, (a, b) in m.pin_ends.items():
            if a in self.known or b in self.known:
                continue
            sides = []
            for body in (a, b):
                unit = self._unit(body)
                if unit is None:
                    break
                if unit[0] == 'cylinder':
                    barrel, rod, pa, pb = self.cylinders[unit[1]]
                    if pin not in (pa, pb):
                        break
                    start = pb if pin == pa else pa
                    if start not in self.placed:
                        break
                    sides.append(('cylinder', unit[1], start))
                    continue
                known = [e for e in self._known_pin(body) if e.name != pin]
                if not known:
                    break
                sides.append(('link', body, known[0].name))
            else:
                self._place_rrr(pin, (a, b), sides)
                return True
        return False

    def _place_rrr(self, pin: str, bodies: tuple[str, str], sides: list[tuple[str, str, str]]
                   ) -> None:
        m = self.m
        links = []
        ends = []
        for body, (kind, key, start) in zip(bodies, sides, strict=True):
            if kind == 'cylinder':
                barrel, rod, pa, pb = self.cylinders[key]
                on_start = m.pins[barrel if start == pa else rod][start]
                on_end = m.pins[rod if start == pa else barrel][pin]
                name = self.link(barrel)
                self.body_names[barrel], self.body_names[rod] = name, self.slider(key)
                links.append({'name': name, 'from': self.point(start),
                              'actuator': self.slider(key)})
                self._actuator(key, on_start, on_end, start == pa)
            else:
                on_start, on_end = m.pins[body][start], m.pins[body][pin]
                name = self.link(body)
                self.body_names[body] = name
                links.append({'name': name, 'from': self.point(start),
                              'length': abs(on_end - on_start)})
            ends.append((on_start, on_end, name, start))
        (p1, c1, _, _), (p2, c2, _, _) = ends
        branch = self._branch(p1, p2, c1, f'RRR {pin}', pin)
        self.dyads.append({'type': 'RRR', 'point': self.point(pin), 'links': links,
                           'branch': branch})
        self.placed.add(pin)
        for body, (kind, key, start), (on_start, on_end, name, _) in zip(
                bodies, sides, ends, strict=True):
            phi0 = _angle(on_end - on_start)
            if kind == 'cylinder':
                barrel, rod, _, _ = self.cylinders[key]
                for part in (barrel, rod):
                    self._known(part, (name, phi0), None, None, phi0)
            else:
                self._known(body, (name, phi0), start, pin, phi0)

    def _triad(self) -> bool:
        """Place a ternary link held by three links from placed pins (a class-III group)."""
        m = self.m
        for body in m.bodies:
            if body in self.known or self._unit(body) != ('link', body) or self._known_pin(body):
                continue
            arms = []
            for edge in m.edges_of[body]:
                other = edge.b if edge.a == body else edge.a
                if edge.kind != 'pin' or other in self.known or self._unit(other) != (
                        'link', other) or any(arm[0] == other for arm in arms):
                    continue
                starts = [e for e in self._known_pin(other) if e.name != edge.name]
                if starts:
                    arms.append((other, edge.name, starts[0].name))
            if len(arms) == 3:
                self._place_triad(body, arms)
                return True
        return False

    def _place_triad(self, body: str, arms: list[tuple[str, str, str]]) -> None:
        m = self.m
        ends = [m.pins[body][pin] for _, pin, _ in arms]
        base = abs(ends[1] - ends[0])
        if base <= TOGGLE_TOLERANCE * m.size:
            raise self.fail(f'joint "{arms[0][1]}": Expected the pins of ternary link '
                            f'"{body}" apart, got two at one place', arms[0][1])
        angle = _angle(ends[1] - ends[0])
        local = (ends[2] - ends[0]) * complex(math.cos(angle), -math.sin(angle))
        links = []
        for other, pin, start in arms:
            name = self.link(other)
            self.body_names[other] = name
            links.append({'name': name, 'from': self.point(start),
                          'length': abs(m.pins[other][pin] - m.pins[other][start])})
        name = self.link(body)
        self.body_names[body] = name
        self.dyads.append({'type': 'triad', 'link': {
            'name': name, 'pins': [self.point(pin) for _, pin, _ in arms], 'length': base,
            'local': [local.real, local.imag]}, 'links': links, 'angle': angle})
        self.placed.update(pin for _, pin, _ in arms)
        for (other, pin, start), link in zip(arms, links, strict=True):
            phi0 = _angle(m.pins[other][pin] - m.pins[other][start])
            self._known(other, (link['name'], phi0), start, pin, phi0)
        self._known(body, (name, angle), arms[0][1], arms[1][1], angle)

    def _actuator(self, joint: str, on_start: complex, on_end: complex, from_barrel: bool
                  ) -> None:
        """Add the cylinder ``joint`` as an actuator: length = |rod's pin - barrel's pin|."""
        m = self.m
        edge = m.slides[joint]
        barrel, rod, pa, pb = self.cylinders[joint]
        pa_z = m.pins[barrel][pa]
        pb_z = m.pins[rod][pb]
        u = m.slide_direction(edge, rod)
        line = pb_z - pa_z
        offset = abs((u.conjugate() * line).imag)
        if offset > PLANAR_TOLERANCE * m.size:
            raise self.fail(
                f'joint "{joint}": Expected a cylinder\'s line through both its pins, got '
                f"the rod's pin {offset:.3g} m off the line of the barrel's pin", joint)
        kappa = 1.0 if (u.conjugate() * line).real > 0 else -1.0
        assert edge.joint is not None
        reference = m.reference_value(edge.joint)
        length0 = abs(line)
        mimic = self.mimics.get(joint)
        start = self.pose.get(joint, 0.0)
        self.inputs.append({'actuator': self.slider(joint),
                            'length': length0 + kappa * (start - reference), 'speed': 0.0})
        self.drivers.append(DriverMap(joint, self.slider(joint), PRISMATIC, kappa, reference,
                                      length0, mimic))
        self.slider_of[joint] = (self.slider(joint), kappa, length0)

    def _block(self, body: str) -> list[_Edge] | None:
        """Return a block's (slide, pin) where ``body`` has exactly those two joints."""
        edges = self.m.edges_of[body]
        if len(edges) != 2 or body == self.m.ground:
            return None
        slides = [e for e in edges if e.kind == 'slide']
        pins = [e for e in edges if e.kind == 'pin']
        if len(slides) != 1 or len(pins) != 1 or slides[0].name in self.cylinders:
            return None
        return [slides[0], pins[0]]

    def _blocks(self) -> Iterator[tuple[str, _Edge, _Edge, str, str]]:
        """Yield each block not yet placed: (body, slide, pin, slid on, pinned to).

        A block: a moving body with exactly one slide and one pin (not a
        cylinder's); ``slid on`` is the body across its slide, ``pinned to``
        the one across its pin. The RRP, RPR and RPP each take one.
        """
        for body in self.m.bodies:
            if body in self.known:
                continue
            block = self._block(body)
            if block is None:
                continue
            slide, pin = block
            yield (body, slide, pin, slide.a if slide.b == body else slide.b,
                   pin.a if pin.b == body else pin.b)

    def _rrp(self) -> bool:
        m = self.m
        for body, slide, pin, guide, link in self._blocks():
            if guide != m.ground:
                continue
            if link in self.known or self._unit(link) != ('link', link):
                continue
            known = [e for e in self._known_pin(link) if e.name != pin.name]
            if not known:
                continue
            self._place_rrp(body, slide, pin, link, known[0].name)
            return True
        return False

    def _place_rrp(self, block: str, slide: _Edge, pin: _Edge, link: str, start: str) -> None:
        m = self.m
        c_block = m.pins[block][pin.name]
        g = m.slide_direction(slide, block)
        through = self.point(f'{slide.name}_guide')
        self.ground[through] = self.xy(c_block)
        p1, c1 = m.pins[link][start], m.pins[link][pin.name]
        foot = ((p1 - c_block) * g.conjugate()).real      # the solutions' midpoint along g
        if abs(foot) <= TOGGLE_TOLERANCE * m.size:
            raise self.fail(
                f'joint "{pin.name}": Expected the reference pose to show the branch of RRP '
                f'{pin.name}, got its link square to the guide (a dead centre): give a '
                f'reference pose away from it', pin.name)
        name = self.link(link)
        self.body_names[link], self.body_names[block] = name, self.slider(slide.name)
        self.dyads.append({'type': 'RRP', 'point': self.point(pin.name),
                           'link': {'name': name, 'from': self.point(start),
                                    'length': abs(c1 - p1)},
                           'guide': {'through': through, 'angle': _angle(g)},
                           'slider': self.slider(slide.name), 'branch': 1 if foot < 0 else -1})
        self.placed.add(pin.name)
        self.slider_of[slide.name] = (self.slider(slide.name), 1.0, 0.0)
        self._known(block, (None, 0.0), None, None, 0.0)
        phi0 = _angle(c1 - p1)
        self._known(link, (name, phi0), start, pin.name, phi0)

    def _rpr(self) -> bool:
        m = self.m
        for body, slide, pin, lever, pinned in self._blocks():
            if pinned not in self.known or lever in self.known or lever == m.ground:
                continue
            pivots = [e for e in m.edges_of[lever] if e.kind == 'pin'
                      and m.ground in (e.a, e.b)]
            if not pivots:
                continue
            self._place_rpr(lever, body, slide, pin, pivots[0].name)
            return True
        return False

    def _place_rpr(self, lever: str, block: str, slide: _Edge, pin: _Edge, pivot: str) -> None:
        m = self.m
        o = m.pins[lever][pivot]
        b = m.pins[block][pin.name]
        u = m.slide_direction(slide, block)
        offset = abs((u.conjugate() * (b - o)).imag)
        if offset > PLANAR_TOLERANCE * m.size:
            raise self.fail(
                f'joint "{slide.name}": Expected a slot through its lever\'s pivot '
                f'"{pivot}" (an RPR), got it {offset:.3g} m off the pivot', slide.name)
        along = (u.conjugate() * (b - o)).real
        if abs(along) <= TOGGLE_TOLERANCE * m.size:
            raise self.fail(f'joint "{slide.name}": Expected the reference pose to have the '
                            f'pin "{pin.name}" off its lever\'s pivot, got it on the pivot',
                            slide.name)
        kappa = 1.0 if along > 0 else -1.0
        name = self.link(lever)
        self.body_names[lever], self.body_names[block] = name, self.slider(slide.name)
        self.dyads.append({'type': 'RPR', 'link': name, 'center': self.point(pivot),
                           'through': self.point(pin.name), 'slider': self.slider(slide.name)})
        self.slider_of[slide.name] = (self.slider(slide.name), kappa, abs(along))
        phi0 = _angle(kappa * u)
        self._known(block, (name, phi0), None, None, phi0)
        # The lever's frame: its pivot, x along its slot toward the pin.
        self.m.pins[lever].setdefault(pin.name, o + kappa * u * abs(along))
        self.placed.add(pin.name)
        self._known(lever, (name, phi0), pivot, pin.name, phi0)

    def _rpp(self) -> bool:
        m = self.m
        for body, slot, pin, yoke, pinned in self._blocks():
            if pinned not in self.known or yoke in self.known or yoke == m.ground:
                continue
            edges = m.edges_of[yoke]
            guides = [e for e in edges if e.kind == 'slide' and e is not slot
                      and m.ground in (e.a, e.b)]
            if len(edges) != 2 or len(guides) != 1:
                continue
            self._place_rpp(yoke, body, guides[0], slot, pin)
            return True
        return False

    def _place_rpp(self, yoke: str, block: str, guide: _Edge, slot: _Edge, pin: _Edge) -> None:
        m = self.m
        b = m.pins[block][pin.name]
        g = m.slide_direction(guide, yoke)
        w = m.slide_direction(slot, block)
        if abs((g.conjugate() * w).imag) <= TOGGLE_TOLERANCE:
            raise self.fail(f'joint "{slot.name}": Expected a yoke\'s slot to cross its guide '
                            f'"{guide.name}", got them parallel', slot.name)
        through = self.point(f'{guide.name}_guide')
        self.ground[through] = self.xy(b)
        new = f'{slot.name}_crossing'
        self.body_names[yoke] = self.slider(guide.name)
        self.body_names[block] = self.slider(slot.name)
        self.dyads.append({'type': 'RPP', 'point': self.point(new),
                           'through': self.point(pin.name),
                           'guide': {'through': through, 'angle': _angle(g)},
                           'slot_angle': _angle(w), 'slider': self.slider(guide.name),
                           'slot_slider': self.slider(slot.name)})
        self.slider_of[guide.name] = (self.slider(guide.name), 1.0, 0.0)
        self.slider_of[slot.name] = (self.slider(slot.name), 1.0, 0.0)
        self._known(yoke, (None, 0.0), None, None, 0.0)
        self._known(block, (None, 0.0), None, None, 0.0)

    # --- the URDF joints -------------------------------------------------------------------
    def _joint_maps(self) -> None:
        m = self.m
        for edge in m.edges:
            joint = edge.joint
            if joint is None or joint.type is None:
                continue
            reference = m.reference_value(joint)
            if joint.type.angular:
                child, child_ref = self.turns[edge.b]
                parent, parent_ref = self.turns[edge.a]
                centre = revolute_centre(joint)
                self.joint_maps[joint.name] = JointMap(
                    joint.name, REVOLUTE, m.sign(edge), reference, child, child_ref, parent,
                    parent_ref, center=centre, mechanism=m.index)
            else:
                slider, kappa, slider_ref = self.slider_of[joint.name]
                self.joint_maps[joint.name] = JointMap(
                    joint.name, PRISMATIC, kappa, reference, slider=slider,
                    slider_ref=slider_ref, mechanism=m.index)


def _edges(description: Description, weld: list[Closure], locked: Mapping[str, Matrix]
           ) -> tuple[dict[str, str], dict[str, Matrix], list[_Edge]]:
    """Return the bodies (:func:`_bodies`) and the joints and closures between them."""
    source = description.source
    body_of, in_body = _bodies(description, weld, locked)
    edges: list[_Edge] = []
    for joint in description.joints.values():
        if not joint.moving or joint.name in locked:
            continue
        a, b = body_of[joint.parent], body_of[joint.child]
        kind = 'free' if joint.type is None else 'pin' if joint.type.angular else 'slide'
        if a == b:
            raise UrdfError(f'{source}: joint "{joint.name}": Expected a joint of a loop to '
                            f'move, got its links "{joint.parent}" and "{joint.child}" welded '
                            f'by a closure', joint=joint.name)
        edges.append(_Edge(joint.name, a, b, kind, joint=joint))
    for closure in description.closures:
        if closure.kind is ClosureKind.WELD:
            continue
        kind = 'pin' if closure.kind is ClosureKind.PIN else 'slide'
        if kind == 'slide' and (closure.axis_a is None or closure.axis_b is None):
            raise UrdfError(f'{source}: closure "{closure.name}": Expected a prismatic closure '
                            f'to give its axis, got none', joint=closure.name)
        a, b = body_of[closure.link_a], body_of[closure.link_b]
        if a == b:
            raise UrdfError(f'{source}: closure "{closure.name}": Expected it to join two '
                            f'moving parts, got links "{closure.link_a}" and '
                            f'"{closure.link_b}" of one rigid body', joint=closure.name)
        edges.append(_Edge(closure.name, a, b, kind, closure=closure))
    return body_of, in_body, edges


class _Hanging:
    """The mimic joints a loop carries links by, outside every loop, where those links have mass.

    A link hanging from a moving body of a loop by a revolute ``<mimic>`` joint
    whose leader is actuated (an exporter's cover or finger pad, moved by a
    hidden linkage the mimic rule stands for), its axis parallel to the
    loop's normal, is placed by a hinge that rule turns: its weight and
    inertia then load the leader's effort (the rule's multiplier times the
    hinge's torque) and the loop's reactions. Only where a link at or beyond
    it holds an ``<inertial>``: without masses nothing is added to the scene.
    """

    def __init__(self, description: Description, edges: list[_Edge], in_loops: set[str],
                 body_of: Mapping[str, str], tree: Mapping[str, Matrix],
                 actuated: tuple[str, ...]) -> None:
        self.tree = tree
        self.actuated = actuated
        self.below: dict[str, list[_Edge]] = {}
        for edge in edges:
            if edge.joint is not None and edge.b not in in_loops:
                self.below.setdefault(edge.a, []).append(edge)
        # The bodies with a mass at or below them: each mass marks its way up the tree (no
        # recursion: a chain outside the loops may be long).
        parent = {e.b: e.a for edges_below in self.below.values() for e in edges_below}
        self.heavy: set[str] = set()
        for body in {body_of[link] for link in description.inertials}:
            while body not in self.heavy:
                self.heavy.add(body)
                if body not in parent:
                    break
                body = parent[body]

    def on(self, m: _Mechanism, ground: Matrix) -> list[_Edge]:
        """Return the hanging mimic edges ``m`` carries (parent side first), or none."""
        normal = ground[:3, :3] @ m.normal
        out: list[_Edge] = []
        frontier = [b for b in m.bodies if b != m.ground]
        while frontier:
            body = frontier.pop(0)
            for edge in self.below.get(body, ()):
                joint = edge.joint
                assert joint is not None
                if joint.type is None or not joint.type.angular or joint.mimic is None \
                        or joint.mimic.joint not in self.actuated or edge.b not in self.heavy:
                    continue
                axis = (self.tree[joint.parent] @ joint.origin)[:3, :3] @ np.asarray(joint.axis)
                axis = axis / np.linalg.norm(axis)
                off = math.atan2(float(np.linalg.norm(np.cross(axis, normal))),
                                 abs(float(axis @ normal)))
                if off <= PLANAR_TOLERANCE:
                    out.append(edge)
                    frontier.append(edge.b)
        return out


def _check_welds(m: _Mechanism, weld: list[Closure], tree: Mapping[str, Matrix]) -> None:
    """Refuse a weld closure of ``m`` that the reference pose does not close.

    Its two frames, each where the tree puts its link, must coincide within
    :data:`GAP_TOLERANCE` of the loop's size (their origins' distance plus
    their turn times the size), as a pin's two points must.
    """
    for closure in weld:
        if m.body_of[closure.link_a] not in m.bodies:
            continue
        on_a = tree[closure.link_a] @ closure.frame_a
        on_b = tree[closure.link_b] @ closure.frame_b
        apart = float(np.linalg.norm(on_a[:3, 3] - on_b[:3, 3]))
        turn = math.acos(max(-1.0, min(1.0, 0.5 * (float(np.trace(on_a[:3, :3].T
                                                                  @ on_b[:3, :3])) - 1.0))))
        if apart + turn * m.size > GAP_TOLERANCE * m.size:
            raise m.fail(
                f'closure "{closure.name}": Expected the reference pose to close the loop '
                f'within {GAP_TOLERANCE:g} of its size ({m.size:.6g} m), got its two frames '
                f'{apart:.3g} m apart and turned {turn:.3g} rad (give a reference pose that '
                'closes it)', closure.name)
    m.gaps.extend(
        (float(np.linalg.norm((tree[c.link_a] @ c.frame_a)[:3, 3]
                              - (tree[c.link_b] @ c.frame_b)[:3, 3])), c.name)
        for c in weld if m.body_of[c.link_a] in m.bodies)


def _actuated_names(description: Description, actuated: Iterable[str] | None,
                    loop_joints: list[str]) -> tuple[str, ...]:
    """Return the actuated joints: given, else the sidecar's, else the URDF's; else refuse."""
    source = description.source
    if actuated is not None:
        names = tuple(actuated)
        how = 'the actuated joints given'
    elif description.independent is not None:
        names = description.independent
        how = "the sidecar's independent joints"
    elif description.actuated:
        names = description.actuated
        how = "the URDF's <transmission>/<ros2_control> joints"
    else:
        candidates = ', '.join(loop_joints) or 'none'
        raise UrdfError(f'{source}: Expected the actuated joints (--actuated J1,J2,... to a '
                        f'command, actuated_joints:=[J1, J2, ...] to the node, actuated= to the '
                        f'API, or <transmission>/<ros2_control> joints in the URDF), got '
                        f'none: the joints of its loops are {candidates}')
    for name in names:
        joint = description.joints.get(name)
        if joint is None or joint.type is None:
            candidates = ', '.join(loop_joints) or 'none'
            got = 'no joint of the robot' if joint is None else f'a {joint.urdf_type} joint'
            raise UrdfError(f'{source}: Expected {how} to be revolute, continuous or prismatic '
                            f'joints of the robot (those of its loops: {candidates}), got '
                            f'"{name}", {got}', joint=name)
    return tuple(dict.fromkeys(names))


def _pinned_once(description: Description, edges: list[_Edge], tree: Mapping[str, Matrix]
                 ) -> None:
    """Refuse a closure named as another closure or a joint, or a second pin of two bodies.

    A closure's name is its scene point's, so two of one name would be one
    point; two pins between the same two bodies are a closure written twice
    (at one point) or a weld (at two), never a loop that moves.
    """
    source = description.source
    names = {e.name: e for e in edges if e.joint is not None}
    pins: dict[frozenset[str], _Edge] = {}
    for edge in edges:
        closure = edge.closure
        if closure is not None:
            other = names.setdefault(edge.name, edge)
            if other is not edge:
                what = 'closure' if other.closure is not None else 'joint'
                raise UrdfError(f'{source}: closure "{edge.name}": Expected every closure to '
                                f'have a name of its own, got "{edge.name}" twice (the other '
                                f'{what} joins links "{_ends(other)[0]}" and '
                                f'"{_ends(other)[1]}")', joint=edge.name)
        if edge.kind != 'pin':
            continue
        first = pins.setdefault(frozenset((edge.a, edge.b)), edge)
        if first is edge:
            continue
        late = edge if edge.closure is not None else first
        early = first if late is edge else edge
        p, q = (_pin_point(e, tree) for e in (early, late))
        apart = math.hypot(*(float(a) - float(b) for a, b in zip(p, q, strict=True)))
        scale = max(math.hypot(*map(float, p)), math.hypot(*map(float, q)))
        why = ('at the same point: one pin written twice' if apart <= GAP_TOLERANCE * scale
               else f'{apart:.3g} m apart, they weld them: join them by a fixed joint or a '
               f'<constraint type="link">')
        who = 'closure' if late.closure is not None else 'joint'
        raise UrdfError(f'{source}: {who} "{late.name}": Expected two bodies to be pinned '
                        f'together once, got links "{_ends(late)[0]}" and "{_ends(late)[1]}" '
                        f'pinned by "{early.name}" too ({why})', joint=late.name)


def _ends(edge: _Edge) -> tuple[str, str]:
    """Return the URDF links an edge joins (a joint's parent and child, a closure's links)."""
    if edge.joint is not None:
        return edge.joint.parent, edge.joint.child
    assert edge.closure is not None
    return edge.closure.link_a, edge.closure.link_b


def _pin_point(edge: _Edge, tree: Mapping[str, Matrix]) -> Any:
    """Return a pin's point in the root frame at the reference pose."""
    if edge.joint is not None:
        return (tree[edge.joint.parent] @ edge.joint.origin)[:3, 3]
    assert edge.closure is not None
    return (tree[edge.closure.link_a] @ edge.closure.frame_a)[:3, 3]


def planar_from_description(description: Description, actuated: Iterable[str] | None = None,
                            reference: Mapping[str, float] | None = None) -> Planar:
    """Return the scene of a robot's planar loops and the maps of its joints.

    Parameters
    ----------
    description : Description
        The robot as read.
    actuated : iterable of str, optional
        The driven joints; default the sidecar's independent joints, else the
        URDF's transmissions and ros2_control command interfaces.
    reference : mapping of str to float, optional
        A reference pose (joint -> rad or m) whose branches the loops keep;
        default the zero pose (a mimic joint not given follows its rule).

    Raises
    ------
    UrdfError
        One line naming the joint and why (see the module's docstring).
    """
    source = description.source
    for name in reference or {}:
        if name not in description.joints or description.joints[name].type is None:
            raise UrdfError(f'{source}: Expected the reference pose to name moving joints of '
                            f'the robot, got "{name}"', joint=name)
    pose = description.pose(reference)
    weld = [c for c in description.closures if c.kind is ClosureKind.WELD]
    locked: dict[str, Matrix] = {}
    while True:
        body_of, in_body, edges = _edges(description, weld, locked)
        idle = _idle_joints(description, body_of, in_body, edges, pose)
        if not idle:
            break
        locked.update(idle)
    bodies = sorted(set(body_of.values()), key=description.order)
    components = [sorted(c) for c in _components(bodies, edges) if len(c) > 1]
    components.sort(key=lambda c: c[0])
    loop_joints = [edges[i].name for c in components for i in c if edges[i].joint is not None]
    if not components:
        raise UrdfError(f'{source}: Expected a robot with a closed loop (a <constraint>, '
                        f'closing frames or a loop_closures.yaml), got a tree with no loop')
    actuated_names = _actuated_names(description, actuated, loop_joints)
    # Every link's frame at the reference pose, by the tree.
    tree = description.transforms(pose)
    _pinned_once(description, edges, tree)
    model = {body: tree[body] for body in bodies}
    builder = _Builder(description, actuated_names, pose)
    mechanisms = []
    claimed: set[str] = set()
    in_loops = {b for c in components for i in c for b in (edges[i].a, edges[i].b)}
    hanging = _Hanging(description, edges, in_loops, body_of, tree, actuated_names)
    for index, component in enumerate(components):
        part = [edges[i] for i in component]
        members = {e.a for e in part} | {e.b for e in part}
        ground = min(members, key=lambda b: (description.depth(b), description.order(b)))
        m = _Mechanism(index, part, model, in_body, body_of, description, ground, pose)
        hangers = hanging.on(m, model[ground])
        if hangers:
            m = _Mechanism(index, part + hangers, model, in_body, body_of, description, ground,
                           pose)
        _check_welds(m, weld, tree)
        names = {e.name for e in m.edges}
        here = [n for n in actuated_names if n in names]
        mimics = {}
        dof = 3 * (len(m.bodies) - 1) - 2 * len(m.edges)
        for edge in part:  # a mimic whose leader is actuated drives the loop it is in
            joint = edge.joint
            if len(here) >= dof - len(hangers) or joint is None or joint.mimic is None \
                    or edge.name in here:
                continue
            leader = joint.mimic.joint
            if leader in actuated_names and leader not in names:
                here.append(edge.name)
                mimics[edge.name] = joint.mimic
        for edge in hangers:   # a hanging mimic: a hinge its leader turns (_Hanging)
            assert edge.joint is not None and edge.joint.mimic is not None
            here.append(edge.name)
            mimics[edge.name] = edge.joint.mimic
        if dof <= 0 or len(here) != dof:
            links = ', '.join(m.bodies[:6]) + (', ...' if len(m.bodies) > 6 else '')
            candidates = ', '.join(e.name for e in part if e.joint is not None)
            what = ('rigid (it cannot move)' if dof <= 0 else
                    f'{dof} degree{"s" if dof != 1 else ""} of freedom')
            got = ', '.join(here) or 'none'
            raise UrdfError(f'{source}: joint "{part[0].name}": Expected the loop through '
                            f'{links} to have as many actuated joints as degrees of freedom, '
                            f'got a loop that is {what} with actuated joints: {got} (its joints: '
                            f'{candidates})', joint=part[0].name)
        claimed.update(here)
        builder.drivers_here = here
        builder.mimics = mimics
        builder.slider_of = {}
        before = set(builder.body_names.values())
        builder.build(m)
        for name in locked:   # an idle body's first joint: held at its reference value
            joint = description.joints[name]
            body = body_of[joint.child]
            if body in m.bodies:
                turn, turn_ref = builder.turns[body]
                centre = revolute_centre(joint)
                builder.joint_maps[name] = JointMap(
                    name, REVOLUTE, 1.0, pose.get(name, 0.0), turn, turn_ref, turn, turn_ref,
                    center=centre, mechanism=index)
        mechanisms.append({'ground': ground, 'links': list(m.bodies),
                           'joints': [e.name for e in m.edges],
                           'bodies': [n for n in dict.fromkeys(builder.body_names.values())
                                      if n not in before],
                           'body_names': {b: builder.body_names[b] for b in m.bodies
                                          if b in builder.body_names},
                           'drivers': list(here),
                           'normal': [float(v) for v in m.normal],
                           'x': [float(v) for v in m.e1], 'y': [float(v) for v in m.e2],
                           'size': m.size, 'gap': max((g for g, _ in m.gaps), default=0.0)})
    data: dict[str, Any] = {
        'name': builder.names('robot', description.name),
        'description': f'The planar loops of the URDF robot "{description.name}".',
        'units': {'length': 'm', 'angle': 'rad'},
        'ground': builder.ground, 'inputs': builder.inputs}
    if builder.dyads:
        data['dyads'] = builder.dyads
    if builder.points:
        data['points'] = builder.points
    # The bodies' frames, for the masses and the links' loads: none without masses (no forces;
    # Planar.link_frame finds one when asked).
    poses = _body_poses(data, [*builder.mass_props, *(body for body, _, _
                                                      in builder.link_planes.values())]
                        ) if builder.mass_props else {}
    return Planar(data, tuple(builder.drivers), builder.joint_maps, mechanisms, actuated_names,
                  dict(builder.names.changed), _scene_masses(builder.mass_props, poses),
                  _link_frames(builder.link_planes, poses) if poses else {},
                  dict(builder.link_planes), dict(builder.link_lifts),
                  {urdf: name for (kind, urdf), name in builder.names.given.items()
                   if kind == 'point'})


def _body_poses(data: dict[str, Any], bodies: Iterable[str]) -> dict[str, Any]:
    """Return each of ``bodies``' own frame (its /tf pose) at the drivers' start.

    The reference pose the plane's points were taken in: where a centre of
    mass (:func:`_scene_masses`) and a link's points (:func:`_link_frames`) go
    into their body's frame. The scene is solved once for both.
    """
    wanted = sorted(set(bodies))
    if not wanted:
        return {}
    from ..geometry.frames import frames_from_scene, poses_from_state
    from ..geometry.urdf import _assembled
    from ..scene import parse_scene

    scene = parse_scene(data)
    return {pose.joint: pose for pose in poses_from_state(
        frames_from_scene(scene, wanted), _assembled(scene))}


def _link_frames(planes: Mapping[str, tuple[str, Any, Any]], poses: Mapping[str, Any]
                 ) -> dict[str, tuple[str, Any, Any]]:
    """Return each moving link's map into its scene body's own frame (:attr:`Planar.links`)."""
    out: dict[str, tuple[str, Any, Any]] = {}
    for link, (body, a, b) in planes.items():
        pose = poses.get(body)
        if pose is None:
            continue
        c, s = math.cos(pose.angle), math.sin(pose.angle)
        turn = np.array([[c, s], [-s, c]])   # by -angle
        out[link] = (body, turn @ a, turn @ (b - np.array([pose.x, pose.y])))
    return out


def _scene_masses(props: Mapping[str, tuple[float, complex, float]], poses: Mapping[str, Any]
                  ) -> dict[str, dict[str, Any]]:
    """Return the scene's ``masses:``: each body's centre of mass in its own /tf frame."""
    out: dict[str, dict[str, Any]] = {}
    for body, (mass, com, inertia) in props.items():
        pose = poses[body]
        local = (com - complex(pose.x, pose.y)) * cmath.exp(-1j * pose.angle)
        out[body] = {'mass': mass, 'com': [local.real, local.imag], 'inertia': inertia}
    return out
