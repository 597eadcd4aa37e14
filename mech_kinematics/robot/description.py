# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A robot as it is written: a URDF, its loop closures and its actuated joints.

The URDF's links and joints are read by ``urdf_parser_py`` (ROS's own Python
URDF reader, the ``urdfdom_py`` package), on an XML tree that lxml parses here
with entities and the network turned off (a URDF is text from anyone). The
``<robot version>`` gate is ours (urdf_parser_py knows 1.0 only): 1.0, 1.1 and
1.2 are read (:data:`URDF_VERSIONS`), and an ``<origin quat_xyzw>`` (1.1) of a
joint, an inertial or a constraint is read here, exactly. What no URDF library
reads is read here from the same tree:

- ``<constraint>`` elements, as proposed in ros/urdfdom#264 and
  ros/urdfdom_headers#108 (``name``, ``type``; ``<parent link>``,
  ``<parent_origin xyz rpy>``, ``<parent_axis xyz>`` and the same for the
  child; the axis in the constraint's frame). ``revolute``, ``continuous``,
  ``spherical`` and ``universal`` close a loop at a point (in a planar loop
  they all act as a pin); ``link`` (or ``fixed``) welds two links; a
  ``prismatic`` one is a slide (the frames parallel, their origins on one line
  along its axis);
- onshape-to-robot's closing frames: the links ``closing_NAME_1`` and
  ``closing_NAME_2`` (frames: fixed child links) whose origins coincide;
- ``<transmission>`` joints and ``<ros2_control>`` joints with a
  ``<command_interface>``: the actuated joints (a joint with state
  interfaces only is measured, not driven);

- Isaac Sim's ``<loop_joint>`` and URDF+'s ``<loop>`` (:func:`urdf_loops`);

and, beside the URDF, scikit-robot's ``loop_closures.yaml`` (its
``LoopClosureSolver``): ``closures: [{link_a, link_b, point, axis}]`` with the
point and axis in the root frame at the zero pose, ``dependent`` and
``independent`` joint lists (``independent``: the driven joints), or any other
form :func:`read_closure_file` recognises by content (a file of ``<constraint>``
elements, an Extended-URDF ``robot.yaml``, a fusion2URDF ``robot_data.yaml``).

Every failure is one :class:`~mech_kinematics.errors.UrdfError` line naming
the source and what is wrong. Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from enum import Enum
import math
import os
from pathlib import Path
import re
import threading
from typing import Any

import numpy as np

from .transforms import Matrix, rotation_about, transform, translation
from ..errors import SceneError, UrdfError
from ..solver.graph import JointType, PRISMATIC, REVOLUTE

__all__ = ['Closure', 'ClosureKind', 'Description', 'FORMS', 'Inertial', 'Mimic', 'UrdfJoint',
           'read_closure_file', 'read_description', 'URDF_TYPES', 'URDF_VERSIONS', 'urdf_loops']

#: The ``<robot version>`` values read (none given: 1.0), as urdfdom 6 writes them:
#: 1.1 adds ``quat_xyzw`` to ``<origin>`` (read) and capsule geometry, 1.2 a
#: ``<limit>``'s acceleration, deceleration and jerk (neither used by a loop:
#: ignored, never refused).
URDF_VERSIONS = ('1.0', '1.1', '1.2')

#: A URDF joint type -> the joint type of its coordinate (None: no coordinate we solve).
URDF_TYPES: dict[str, JointType | None] = {
    'revolute': REVOLUTE, 'continuous': REVOLUTE, 'prismatic': PRISMATIC, 'fixed': None,
    'floating': None, 'planar': None}
#: URDF joint types that move (a floating or planar joint moves, but with no one coordinate).
MOVING = frozenset({'revolute', 'continuous', 'prismatic', 'floating', 'planar'})
#: A ``<constraint>`` type -> what it closes.
CONSTRAINT_TYPES = {'revolute': 'pin', 'continuous': 'pin', 'spherical': 'pin',
                    'universal': 'pin', 'link': 'weld', 'fixed': 'weld', 'prismatic': 'slide'}
#: A ``<constraint>`` type we refuse -> what to do instead (none: every type is read).
REFUSED_CONSTRAINTS: dict[str, str] = {}
#: The name of an onshape-to-robot closing frame: ``closing_NAME_1`` or ``closing_NAME_2``.
CLOSING_FRAME = re.compile(r'closing_(.+)_([12])\Z')

_PARSE_LOCK = threading.Lock()
#: The XML is parsed this many bytes at a time.
_FEED_BYTES = 1 << 16


class ClosureKind(Enum):
    """What a loop closure joins: a point of each link (a pin), or the two links rigidly."""

    PIN = 'pin'
    WELD = 'weld'
    SLIDE = 'slide'


@dataclass(frozen=True)
class Closure:
    """One cut of a loop: two links joined where the tree does not join them.

    Attributes
    ----------
    name : str
        Its name (a constraint's, ``closing_NAME``, ``closure_I`` of a sidecar).
    kind : ClosureKind
        A pin (the two frames' origins coincide) or a weld (the frames coincide).
    link_a, link_b : str
        The two links.
    frame_a, frame_b : ndarray, shape (4, 4)
        The closure's frame on each link, in that link's frame (m).
    axis_a, axis_b : tuple of float or None
        A pin's axis in each link's frame where it is written; ``None`` for a
        point (closing frames) or a weld.
    form : str
        Where it was written: ``<constraint>``, ``closing frames`` or the sidecar.
    """

    name: str
    kind: ClosureKind
    link_a: str
    frame_a: Matrix
    link_b: str
    frame_b: Matrix
    axis_a: tuple[float, float, float] | None
    axis_b: tuple[float, float, float] | None
    form: str


@dataclass(frozen=True)
class Mimic:
    """A ``<mimic>``: value = ``multiplier`` x the leader's + ``offset``."""

    joint: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class UrdfJoint:
    """A URDF joint as written (SI units).

    Attributes
    ----------
    name, urdf_type, parent, child : str
        Its name, its type as written (``revolute``, ``continuous``,
        ``prismatic``, ``fixed``, ``floating``, ``planar``), its links.
    type : JointType or None
        The joint type of its coordinate (:data:`URDF_TYPES`); ``None`` for a
        fixed joint and for a floating or planar one.
    origin : ndarray, shape (4, 4)
        Its ``<origin>``: the child's frame at value 0 in the parent's.
    axis : tuple of float
        Its unit ``<axis>`` in its own frame (default x).
    limits : tuple of float or None
        ``(lower, upper)`` from ``<limit>`` where ``upper > lower``.
    mimic : Mimic or None
        Its ``<mimic>``.
    """

    name: str
    urdf_type: str
    type: JointType | None
    parent: str
    child: str
    origin: Matrix
    axis: tuple[float, float, float]
    limits: tuple[float, float] | None = None
    mimic: Mimic | None = None

    @property
    def moving(self) -> bool:
        """Whether it moves (every type but ``fixed``)."""
        return self.urdf_type in MOVING

    def motion(self, value: float) -> Matrix:
        """Return the child's frame in the parent's at ``value`` (rad or m)."""
        if self.type is None:
            return self.origin
        if self.type.angular:
            return self.origin @ rotation_about(self.axis, value)
        return self.origin @ translation(np.multiply(self.axis, value))


@dataclass(frozen=True)
class Inertial:
    """A link's ``<inertial>``: its mass (kg), its frame (the centre of mass) and inertia.

    ``origin`` is the inertial frame in the link's (4x4: the centre of mass at
    its origin), ``inertia`` the 3x3 tensor about the centre of mass in that
    frame's axes (kg m^2), both as the URDF writes them.
    """

    mass: float
    origin: Matrix
    inertia: Matrix


@dataclass(frozen=True)
class Description:
    """A robot as written: its URDF's links and joints, closures and actuated joints.

    Attributes
    ----------
    name : str
        The ``<robot name>``.
    source : str
        The URDF's path, or ``<robot_description>`` for text.
    text : str
        The URDF's text, unchanged.
    links : tuple of str
        Every link, in file order.
    joints : dict of str to UrdfJoint
        Every joint, in file order.
    root : str
        The root link.
    closures : tuple of Closure
        The loop closures, every form together.
    actuated : tuple of str
        The joints the URDF says are driven (``<transmission>``,
        ``<ros2_control>`` command interfaces), in file order.
    independent : tuple of str or None
        A sidecar's ``independent`` joints (``None`` without a sidecar).
    inertials : dict of str to Inertial
        Each link's ``<inertial>`` with a mass above 0 (a link without one,
        or of mass 0, is massless).
    reductions : dict of str to (str, float)
        A joint of a ``<transmission>`` with one ``<actuator>`` whose
        ``<mechanicalReduction>`` is written: (the actuator's name, the
        reduction: joint effort = reduction x actuator effort, as ros_control's
        SimpleTransmission).
    """

    name: str
    source: str
    text: str
    links: tuple[str, ...]
    joints: dict[str, UrdfJoint]
    root: str
    closures: tuple[Closure, ...] = ()
    actuated: tuple[str, ...] = ()
    independent: tuple[str, ...] | None = None
    inertials: dict[str, Inertial] = field(default_factory=dict)
    reductions: dict[str, tuple[str, float]] = field(default_factory=dict)
    _parent: dict[str, UrdfJoint] = field(default_factory=dict, repr=False, compare=False)
    _order: dict[str, int] = field(default_factory=dict, repr=False, compare=False)
    _depth: dict[str, int] = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self) -> None:
        """Index each link's parent joint, place in the file and depth (linear in the links)."""
        self._parent.update({j.child: j for j in self.joints.values()})
        self._order.update({link: i for i, link in enumerate(self.links)})
        for link in self.links:  # each link's depth once: up to the first link whose is known
            path: list[str] = []
            while link not in self._depth and link in self._parent \
                    and len(path) <= len(self.links):  # a cycle ends the walk (refused later)
                path.append(link)
                link = self._parent[link].parent
            depth = self._depth.get(link, 0)
            for below in reversed(path):
                depth += 1
                self._depth[below] = depth

    def parent_joint(self, link: str) -> UrdfJoint | None:
        """Return the joint whose child is ``link`` (``None`` for the root)."""
        return self._parent.get(link)

    def order(self, link: str) -> int:
        """Return ``link``'s place in :attr:`links` (file order), a sort key."""
        return self._order[link]

    def chain(self, link: str) -> list[UrdfJoint]:
        """Return the joints from the root down to ``link``, in order."""
        out = []
        joint = self._parent.get(link)
        while joint is not None:
            out.append(joint)
            joint = self._parent.get(joint.parent)
        out.reverse()
        return out

    def depth(self, link: str) -> int:
        """Return how many joints ``link`` is below the root."""
        return self._depth.get(link, 0)

    def pose(self, values: Mapping[str, float] | None = None) -> dict[str, float]:
        """Return every moving joint's value: ``values``, else its mimic rule, else 0.

        A mimic joint not given follows its leader (value = multiplier x
        leader + offset), as joint_state_publisher draws it.
        """
        values = dict(values or {})
        out: dict[str, float] = {}

        def value(name: str, seen: tuple[str, ...] = ()) -> float:
            if name in out:
                return out[name]
            joint = self.joints[name]
            if name in values:
                out[name] = float(values[name])
            elif joint.mimic is not None and joint.mimic.joint not in seen:
                rule = joint.mimic
                out[name] = rule.multiplier * value(rule.joint, (*seen, name)) + rule.offset
            else:
                out[name] = 0.0
            return out[name]

        for name, joint in self.joints.items():
            if joint.type is not None:
                value(name)
        return out

    def transforms(self, values: Mapping[str, float] | None = None) -> dict[str, Matrix]:
        """Return every link's frame in the root's at the joint values :meth:`pose` gives."""
        pose = self.pose(values)
        out: dict[str, Matrix] = {self.root: np.eye(4)}
        for link in sorted(self.links, key=lambda link: self._depth.get(link, 0)):  # parents 1st
            if link not in out:
                joint = self._parent[link]
                out[link] = out[joint.parent] @ joint.motion(pose.get(joint.name, 0.0))
        return out


def _fail(source: str, msg: str, joint: str | None = None) -> UrdfError:
    return UrdfError(f'{source}: {msg}', joint=joint)


def _floats(text: str | None, count: int, what: str, source: str,
            default: tuple[float, ...] | None = None) -> tuple[float, ...]:
    """Return ``count`` finite numbers from an XML attribute, or refuse in one line."""
    if text is None:
        if default is None:
            raise _fail(source, f'Expected {what} ({count} numbers), got none')
        return default
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        values = ()
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise _fail(source, f'Expected {what} to be {count} finite numbers, got {text!r}')
    return values


def _unit(vector: tuple[float, ...], what: str, source: str, joint: str | None = None
          ) -> tuple[float, float, float]:
    # Scaled by its largest component first, so that 0 0 1e-300 (whose squares underflow)
    # and 0 0 1e200 (whose squares overflow) are the directions they are.
    largest = max((abs(v) for v in vector), default=0.0)
    if not largest > 0.0 or not all(math.isfinite(v) for v in vector):
        raise _fail(source, f'Expected {what} to be a non-zero direction, got '
                    f'{" ".join(f"{v:g}" for v in vector)}', joint)
    scaled = [v / largest for v in vector]
    norm = math.sqrt(sum(v * v for v in scaled))
    x, y, z = (v / norm for v in scaled)
    return x, y, z


def _origin(element: Any, what: str, source: str, version: str = '1.0') -> Matrix:
    """Return the transform of an ``<origin xyz rpy>`` or ``<origin xyz quat_xyzw>`` (1.1)."""
    if element is None:
        return np.eye(4)
    xyz = _floats(element.get('xyz'), 3, f'{what} xyz', source, (0.0, 0.0, 0.0))
    quat = element.get('quat_xyzw')
    if quat is None:
        rpy = _floats(element.get('rpy'), 3, f'{what} rpy', source, (0.0, 0.0, 0.0))
        return transform(xyz, rpy)
    if version == '1.0':
        raise _fail(source, f'{what}: Expected quat_xyzw only in a URDF of version 1.1 or '
                            'later (<robot version="1.1">), got it in version 1.0')
    if element.get('rpy') is not None:
        raise _fail(source, f'{what}: Expected rpy or quat_xyzw, got both')
    q = _floats(quat, 4, f'{what} quat_xyzw', source)
    try:
        return transform(xyz, quat_xyzw=q)
    except ValueError:
        raise _fail(source, f'Expected {what} quat_xyzw to be a non-zero quaternion, got '
                            f'{quat!r}') from None


def _version(root: Any, source: str) -> str:
    """Return the URDF's ``<robot version>`` (1.0 when none is given), or refuse in one line."""
    text = root.get('version')
    if text is None:
        return '1.0'
    match = re.fullmatch(r'\s*(\d+)\.(\d+)\s*', text)
    version = None if match is None else f'{int(match[1])}.{int(match[2])}'
    if version not in URDF_VERSIONS:
        form = '' if match is not None else ' (the form MAJOR.MINOR)'
        raise _fail(source, f'Expected <robot version> {", ".join(URDF_VERSIONS)}{form}, '
                            f'got {text!r}')
    return str(version)


def _quaternion_origins(root: Any, version: str, source: str) -> dict[tuple[str, str], Matrix]:
    """Return the ``<origin quat_xyzw>`` transforms of joints and inertials, read exactly.

    urdf_parser_py reads ``rpy`` only; these replace its origins (keys ``('joint',
    NAME)`` and ``('inertial', LINK)``).
    """
    out: dict[tuple[str, str], Matrix] = {}
    for kind, parent_tag, path in (('joint', 'joint', 'origin'),
                                   ('inertial', 'link', 'inertial/origin')):
        for parent in root.findall(parent_tag):
            origin = parent.find(path)
            if origin is not None and origin.get('quat_xyzw') is not None:
                name = parent.get('name') or ''
                out[kind, name] = _origin(origin, f'{parent_tag} "{name}" <{path}>', source,
                                          version)
    return out


class _Collect:
    """Collect urdf_parser_py's complaints (it prints them) instead of printing them."""

    def __init__(self) -> None:
        self.messages: list[str] = []

    def __call__(self, message: str) -> None:
        self.messages.append(message)


def _parse_xml(text: str, source: str) -> Any:
    """Return the root element of ``text``, parsed with no entities and no network."""
    from lxml import etree
    parser = etree.XMLParser(resolve_entities=False, no_network=True, huge_tree=False,
                             remove_comments=True, remove_pis=True, load_dtd=False)
    nul = text.find('\x00')
    if nul >= 0:  # named here: libxml2 may report it as the tag it cut short
        line, column = text.count('\n', 0, nul) + 1, nul - text.rfind('\n', 0, nul)
        raise _fail(source, f'Expected a URDF (XML), got text that is not XML: a NUL character '
                            f'(U+0000), line {line}, column {column}')
    data = text.encode('utf-8')
    try:
        # Fed in pieces: between two a signal's handler runs (the node's start ends at once
        # on a stop, ros/startup.py); one call on 6 MB held it for 4 s on a loaded machine.
        for start in range(0, max(len(data), 1), _FEED_BYTES):
            parser.feed(data[start:start + _FEED_BYTES])
        root = parser.close()
    except etree.XMLSyntaxError as error:
        # The feeding parser's own line can be vaguer ("no element found") than the
        # error libxml2 logged last ("Entity 'xx' not defined"): that one is said, on one
        # line (lxml's message may hold a newline: a NUL's).
        last = error.error_log.last_error if error.error_log else None
        said = f'{last.message}, line {last.line}, column {last.column}' if last else error
        said = ' '.join(str(said).split())
        raise _fail(source, f'Expected a URDF (XML), got text that is not XML: {said}') from None
    if root.tag != 'robot':
        raise _fail(source, f'Expected a URDF whose root element is <robot>, got <{root.tag}>')
    return root


def _read_links_and_joints(root: Any, source: str) -> Any:
    """Return urdf_parser_py's robot for ``root``, its complaints kept, not printed."""
    from lxml import etree
    import urdf_parser_py.urdf as urdf
    from urdf_parser_py.xml_reflection import core

    known = {'link', 'joint', 'material', 'transmission', 'gazebo'}
    # urdf_parser_py reads <robot> in time quadratic in its children (it removes each one
    # read from the front of a list of them): the robot is read from its attributes alone,
    # then each child as urdf_parser_py would, in order, with the same path for its errors.
    # What we read ourselves, or what no URDF reader reads, is left out; so is the version,
    # our gate (_version: urdf_parser_py knows only 1.0).
    attributes = {k: v for k, v in root.attrib.items() if k != 'version'}
    shell = etree.Element(root.tag, attributes)
    refl = urdf.Robot.XML_REFL
    collect = _Collect()
    with _PARSE_LOCK:  # urdf_parser_py reports through a module-level function
        saved = core.on_error
        core.on_error = collect
        try:
            path = core.Path(refl.tag, tree=etree.ElementTree(shell))
            robot = urdf.Robot.from_xml(shell, path)
            for child in root:
                if not isinstance(child.tag, str) or child.tag not in known:
                    continue
                if child.tag == 'link' and (child.find('visual') is not None
                                            or child.find('collision') is not None):
                    child = _without_shapes(child)   # no loop uses them (1.1's capsule)
                index = 1 + len(robot.get_aggregate_list(child.tag))  # 1-based, as XPath
                refl.element_map[child.tag].add_from_xml(
                    robot, child, core.Path(child.tag, parent=path, suffix=f'[{index}]'))
            return robot
        except Exception as error:  # noqa: BLE001 - the library raises anything: one line
            text = ' '.join(str(error).split()) or type(error).__name__
            raise _fail(source, f'Expected a valid URDF, got: {text}') from None
        finally:
            core.on_error = saved


def _without_shapes(link: Any) -> Any:
    """Return a copy of a ``<link>`` without its ``<visual>`` and ``<collision>``."""
    import copy

    out = copy.copy(link)   # lxml: a deep copy of this element alone, not of its tree
    for shape in [*out.findall('visual'), *out.findall('collision')]:
        out.remove(shape)
    return out


def _inertials(robot: Any, source: str, quaternions: Mapping[tuple[str, str], Matrix]
               ) -> dict[str, Inertial]:
    """Return each link's ``<inertial>`` of mass above 0, checked (one line naming the link)."""
    out: dict[str, Inertial] = {}
    for link in robot.links:
        inertial = getattr(link, 'inertial', None)
        if inertial is None:
            continue
        mass = float(inertial.mass if inertial.mass is not None else 0.0)
        if not math.isfinite(mass) or mass < 0.0:
            raise _fail(source, f'link "{link.name}": Expected its <inertial> mass to be a '
                                f'finite number >= 0 kg, got {mass!r}')
        if mass == 0.0:
            continue
        origin = inertial.origin
        xyz = tuple(float(v) for v in (origin.xyz if origin is not None and origin.xyz
                                       is not None else (0.0, 0.0, 0.0)))
        rpy = tuple(float(v) for v in (origin.rpy if origin is not None and origin.rpy
                                       is not None else (0.0, 0.0, 0.0)))
        i = inertial.inertia
        names = ('ixx', 'ixy', 'ixz', 'iyy', 'iyz', 'izz')
        values = [float(getattr(i, k, 0.0) or 0.0) if i is not None else 0.0 for k in names]
        if not all(math.isfinite(v) for v in (*xyz, *rpy, *values)):
            raise _fail(source, f'link "{link.name}": Expected its <inertial> origin and '
                                f'inertia to be finite, got xyz {xyz} rpy {rpy} inertia '
                                f'{dict(zip(names, values, strict=True))}')
        ixx, ixy, ixz, iyy, iyz, izz = values
        tensor = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        # A rigid body's: positive semi-definite, each principal moment at most the sum of
        # the other two (a 1e-9 kg exporter's dummy, or a point mass of inertia 0, is one).
        low, middle, high = (float(v) for v in np.linalg.eigvalsh(tensor))
        slack = 1e-12 * max(abs(tensor).max(), 1e-300)
        if low < -slack or low + middle < high - slack:
            given = dict(zip(names, values, strict=True))
            what = ('positive semi-definite' if low < -slack else
                    "a rigid body's (each principal moment at most the sum of the other two)")
            raise _fail(source, f'link "{link.name}": Expected its <inertial> inertia to be '
                                f'{what}, got {given}')
        frame = quaternions.get(('inertial', link.name))
        out[link.name] = Inertial(mass, transform(xyz, rpy) if frame is None else frame, tensor)
    return out


def _joints(robot: Any, source: str, quaternions: Mapping[tuple[str, str], Matrix]
            ) -> dict[str, UrdfJoint]:
    links = {link.name for link in robot.links}
    out: dict[str, UrdfJoint] = {}
    children: dict[str, str] = {}
    for joint in robot.joints:
        name = joint.name
        where = f'joint "{name}"'
        if name in out:
            raise _fail(source, f'Expected every joint to have a name of its own, got "{name}" '
                        'twice', name)
        kind = joint.type
        if kind not in URDF_TYPES:
            raise _fail(source, f'{where}: Expected a type in {", ".join(URDF_TYPES)}, got '
                        f'{kind!r}', name)
        for end in (joint.parent, joint.child):
            if end not in links:
                raise _fail(source, f'{where}: Expected its parent and child to be links of '
                            f'the robot, got unknown link "{end}"', name)
        if joint.child in children:
            raise _fail(source, f'{where}: Expected each link to be the child of one joint (a '
                        f'URDF is a tree: close a loop with a <constraint>), got link '
                        f'"{joint.child}" the child of "{children[joint.child]}" too', name)
        children[joint.child] = name
        origin = np.eye(4)
        if joint.origin is not None:
            xyz = tuple(float(v) for v in (joint.origin.xyz or (0.0, 0.0, 0.0)))
            rpy = tuple(float(v) for v in (joint.origin.rpy or (0.0, 0.0, 0.0)))
            if not all(math.isfinite(v) for v in xyz + rpy):
                raise _fail(source, f'{where}: Expected a finite <origin>, got xyz '
                            f'{xyz} rpy {rpy}', name)
            origin = transform(xyz, rpy)
        origin = quaternions.get(('joint', name), origin)
        axis: tuple[float, float, float] = (1.0, 0.0, 0.0)
        if joint.axis is not None and URDF_TYPES[kind] is not None:
            axis = _unit(tuple(float(v) for v in joint.axis), f"{where}'s <axis>", source,
                         name)
        limits = None
        if joint.limit is not None and joint.limit.lower is not None \
                and joint.limit.upper is not None:
            lower, upper = float(joint.limit.lower), float(joint.limit.upper)
            if math.isfinite(lower) and math.isfinite(upper) and upper > lower:
                limits = (lower, upper)
        mimic = None
        if joint.mimic is not None:
            rule = joint.mimic
            mimic = Mimic(rule.joint, 1.0 if rule.multiplier is None else float(rule.multiplier),
                          0.0 if rule.offset is None else float(rule.offset))
            if not (math.isfinite(mimic.multiplier) and math.isfinite(mimic.offset)):
                raise _fail(source, f'{where}: Expected a finite <mimic> multiplier and offset, '
                            f'got {mimic.multiplier!r} and {mimic.offset!r}', name)
        out[name] = UrdfJoint(name, kind, URDF_TYPES[kind], joint.parent, joint.child, origin,
                              axis, limits, mimic)
    for joint in out.values():
        if joint.mimic is not None and (joint.mimic.joint not in out
                                        or out[joint.mimic.joint].type is None):
            raise _fail(source, f'joint "{joint.name}": Expected its <mimic> to follow a '
                        f'moving joint of the robot, got "{joint.mimic.joint}"', joint.name)
    _mimic_chains(out, source)
    return out


def _mimic_chains(joints: Mapping[str, UrdfJoint], source: str) -> None:
    """Refuse a cycle of ``<mimic>`` rules (a joint that mimics itself, w1 -> w2 -> w1)."""
    done: set[str] = set()
    for name in joints:
        chain: list[str] = []
        joint: str | None = name
        while joint is not None and joint not in done:
            if joint in chain:
                cycle = chain[chain.index(joint):] + [joint]
                raise _fail(source, f'joint "{joint}": Expected its <mimic> rule to lead to a '
                            f'joint that mimics none, got a cycle: '
                            f'{" mimics ".join(cycle)}', joint)
            chain.append(joint)
            rule = joints[joint].mimic
            joint = None if rule is None else rule.joint
        done.update(chain)


def _root(links: tuple[str, ...], joints: dict[str, UrdfJoint], source: str) -> str:
    children = {j.child for j in joints.values()}
    roots = [link for link in links if link not in children]
    if len(roots) != 1:
        got = ', '.join(roots[:5]) or 'none (the joints make a cycle)'
        raise _fail(source, f'Expected one root link (a URDF is a tree), got {got}')
    parent = {j.child: j.parent for j in joints.values()}
    up: set[str] = {roots[0]}  # links whose path up reaches the root
    for link in links:  # a cycle among the joints leaves some link without a path up
        path: list[str] = []
        seen: set[str] = set()
        while link not in up and link in parent:  # each link walked once: linear
            if link in seen:
                raise _fail(source, f'Expected the joints to make a tree, got a cycle through '
                            f'link "{link}"')
            seen.add(link)
            path.append(link)
            link = parent[link]
        up.update(path)
    return roots[0]


def _constraints(root: Any, links: set[str], source: str, version: str
                 ) -> Iterator[Closure]:
    for element in root.findall('constraint'):
        name = element.get('name') or ''
        where = f'<constraint name="{name}">'
        kind = element.get('type', '')
        if kind not in CONSTRAINT_TYPES:
            extra = REFUSED_CONSTRAINTS.get(kind, '')
            raise _fail(source, f'{where}: Expected a type in {", ".join(CONSTRAINT_TYPES)}, '
                        f'got {kind!r}{extra}')
        ends = []
        for end in ('parent', 'child'):
            link = element.find(end)
            link_name = None if link is None else link.get('link')
            if link_name not in links:
                raise _fail(source, f'{where}: Expected <{end} link="..."/> naming a link of the '
                            f'robot, got {link_name!r}')
            frame = _origin(element.find(f'{end}_origin'), f'{where} {end}_origin', source,
                            version)
            axis = element.find(f'{end}_axis')
            direction = None if axis is None else _unit(
                _floats(axis.get('xyz'), 3, f'{where} {end}_axis xyz', source),
                f'{where} {end}_axis', source)
            ends.append((link_name, frame, direction))
        closure_kind = ClosureKind(CONSTRAINT_TYPES[kind])
        axes = []
        for _, frame, axis in ends:  # each axis is written in its constraint frame
            axes.append(None if axis is None or closure_kind is ClosureKind.WELD else
                        tuple(float(v) for v in frame[:3, :3] @ np.asarray(axis)))
        (link_a, frame_a, _), (link_b, frame_b, _) = ends
        yield Closure(name or f'constraint_{link_a}_{link_b}', closure_kind, str(link_a),
                      frame_a, str(link_b), frame_b, axes[0], axes[1], '<constraint>')


def _closing_frames(joints: dict[str, UrdfJoint], links: tuple[str, ...],
                    source: str) -> Iterator[Closure]:
    pairs: dict[str, dict[str, str]] = {}
    for link in links:
        match = CLOSING_FRAME.match(link)
        if match:
            pairs.setdefault(match[1], {})[match[2]] = link
    for name, pair in pairs.items():
        if len(pair) != 2:
            have = next(iter(pair.values()))
            missing = f'closing_{name}_{"2" if "1" in pair else "1"}'
            raise _fail(source, f'Expected closing frames in pairs, got "{have}" without '
                        f'"{missing}"')
        yield Closure(f'closing_{name}', ClosureKind.PIN, pair['1'], np.eye(4), pair['2'],
                      np.eye(4), None, None, 'closing frames')


# --- the closure forms beside the URDF (--closures FILE), told by content -------------
#
# Beside the URDF, one of: scikit-robot's loop_closures.yaml (a mapping with
# ``closures``, :func:`_loop_closures_yaml`); a file of ``<constraint>``
# elements (XML: urdfdom#264's element outside the URDF, under any root element,
# or one ``<constraint>`` as the root); an Extended-URDF ``robot.yaml`` (Gepetto's
# example-parallel-robots, read by Pinocchio: ``closed_loop: [[FRAME_A, FRAME_B],
# ...]``, ``type: ['6d'|'3d', ...]``, ``name_mot``; a frame is a link, or a joint:
# its child link's frame, as Pinocchio's joint frames; ``6d`` welds the two
# frames, ``3d`` joins their origins); a fusion2URDF ``robot_data.yaml`` (a
# mapping with ``closing_joints``: each ``{name, type, parent, child,
# origin_xyz_m, origin_rpy_rad, axis}``, the joint's frame in the parent link as
# a URDF joint's ``<origin>``, met by the child link at the zero pose). And
# inside the URDF: Isaac Sim's ``<loop_joint>`` and URDF+'s ``<loop>``
# (:func:`urdf_loops`).


#: The forms ``--closures FILE`` takes, as the refusal of anything else lists them.
FORMS = ('a loop_closures.yaml (closures:)', 'a file of <constraint> elements',
         'an Extended-URDF robot.yaml (closed_loop:)',
         'a fusion2URDF robot_data.yaml (closing_joints:)')
#: A joint type (of a closing joint, a loop joint or a loop) -> what it closes.
JOINT_CLOSURES = {'revolute': ClosureKind.PIN, 'continuous': ClosureKind.PIN,
                  'spherical': ClosureKind.PIN, 'prismatic': ClosureKind.SLIDE,
                  'fixed': ClosureKind.WELD}
#: An Extended-URDF constraint type -> what it closes.
EXTENDED_TYPES = {'6d': ClosureKind.WELD, '3d': ClosureKind.PIN}


def read_closure_file(path: str | os.PathLike[str], description: Description
                      ) -> tuple[tuple[Closure, ...], tuple[str, ...] | None]:
    """Read the closures beside a URDF in any form of :data:`FORMS`, told by content.

    Returns the closures and the driven joints the file names (``None``
    where it names none).
    """
    from ..scene import _decode, _read_bytes

    where = str(path)
    try:
        text = _decode(Path(path), _read_bytes(Path(path)))
    except SceneError as error:
        raise UrdfError(f'{where}: {error}') from None
    if text.lstrip().startswith('<'):
        return _constraint_file(text, where, description), None
    from ..yaml12 import read_scene_yaml
    section = _closing_joints_section(text)
    try:
        data = read_scene_yaml(text if section is None else section)
    except SceneError as error:
        raise UrdfError(f'{where}: {error}') from None
    if isinstance(data, dict) and 'closed_loop' in data:
        return _extended_urdf(data, where, description)
    if isinstance(data, dict) and 'closing_joints' in data:
        return _fusion2urdf(data, where, description), None
    if isinstance(data, dict) and 'closures' in data:
        return _loop_closures_yaml(data, where, description)
    got = (f'a mapping with keys {", ".join(sorted(map(str, data))[:6])}'
           if isinstance(data, dict) else f'{type(data).__name__}')
    raise UrdfError(f'{where}: Expected {", ".join(FORMS[:-1])} or {FORMS[-1]}, got {got}')


def _closing_joints_section(text: str) -> str | None:
    """Return a robot_data.yaml's top-level ``closing_joints:`` block alone (None: none).

    fusion2URDF writes links, joints, inertias and more before it: only this
    block is parsed (the rest is not read), which keeps the reading as fast
    as a loop_closures.yaml's.
    """
    match = re.search(r'^closing_joints\s*:', text, re.M)
    if match is None:
        return None
    end = re.compile(r'^[^\s#-]', re.M).search(text, match.end())
    return text[match.start():len(text) if end is None else end.start()]


# --- a file of <constraint> elements ---------------------------------------------------


def _constraint_file(text: str, where: str, description: Description) -> tuple[Closure, ...]:
    from lxml import etree
    parser = etree.XMLParser(resolve_entities=False, no_network=True, huge_tree=False,
                             remove_comments=True, remove_pis=True, load_dtd=False)
    form = 'a file of <constraint> elements'
    try:
        root = etree.fromstring(text.encode('utf-8'), parser)
    except etree.XMLSyntaxError as error:
        raise UrdfError(f'{where}: Expected {form} (XML), got text that is not XML: '
                        f'{error}') from None
    if root.tag == 'constraint':
        wrapper = etree.Element('constraints')
        wrapper.append(root)
        root = wrapper
    version = _version(root, where) if root.get('version') is not None else '1.2'
    found = tuple(_constraints(root, set(description.links), where, version))
    if not found:
        raise UrdfError(f'{where}: Expected {form}, got <{root.tag}> with no <constraint> '
                        'child')
    return found


# --- Extended URDF: robot.yaml ---------------------------------------------------------


def _frame_of(name: Any, description: Description) -> str | None:
    """Return the link whose frame a Pinocchio frame name is (a joint: its child)."""
    if not isinstance(name, str):
        return None
    joint = description.joints.get(name)
    if joint is not None:
        return joint.child
    return name if name in description.links else None


def _names(data: dict[str, Any], key: str, at: str) -> list[str]:
    value = data[key]
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise UrdfError(f'{at}{key}: Expected a list of names, got {value!r:.80}')
    return value


def _extended_urdf(data: dict[str, Any], where: str, description: Description
                   ) -> tuple[tuple[Closure, ...], tuple[str, ...] | None]:
    at = f'{where}: robot.yaml (Extended URDF): '
    known = {'closed_loop', 'type', 'name_mot', 'joint_name', 'joint_type'}
    unknown = set(data) - known
    if unknown:
        raise UrdfError(f'{at}Expected keys {", ".join(sorted(known))}, got '
                        f'{", ".join(sorted(map(str, unknown)))}')
    loops = data['closed_loop']
    if not isinstance(loops, list) or not loops:
        raise UrdfError(f'{at}closed_loop: Expected [[FRAME_A, FRAME_B], ...], got '
                        f'{loops!r:.80}')
    types = data.get('type', ['6d'] * len(loops))
    if not isinstance(types, list) or len(types) != len(loops):
        raise UrdfError(f'{at}type: Expected one of {", ".join(EXTENDED_TYPES)} per closed_loop '
                        f'pair ({len(loops)}), got {types!r:.80}')
    for index, kind in enumerate(data.get('joint_type') or []):
        if kind != 'SPHERICAL':   # a ball joint in a planar loop turns about the normal only
            names = data.get('joint_name') or []
            joint = names[index] if isinstance(names, list) and index < len(names) else '?'
            raise UrdfError(f'{at}joint_type[{index}]: Expected SPHERICAL (read as the URDF '
                            f'joint "{joint}" itself), got {kind!r:.40}: a joint turned into '
                            f'{kind!r:.20} is not read')
    closures = []
    for index, (pair, kind) in enumerate(zip(loops, types, strict=True)):
        here = f'{at}closed_loop[{index}]'
        if not isinstance(pair, list) or len(pair) != 2:
            raise UrdfError(f'{here}: Expected [FRAME_A, FRAME_B], got {pair!r:.80}')
        links = [_frame_of(name, description) for name in pair]
        for name, link in zip(pair, links, strict=True):
            if link is None:
                raise UrdfError(f'{here}: Expected a link or joint of the robot (a Pinocchio '
                                f'frame), got {name!r:.80}')
        closure_kind = EXTENDED_TYPES.get(str(kind).lower())
        if closure_kind is None:
            raise UrdfError(f'{at}type[{index}]: Expected {" or ".join(EXTENDED_TYPES)}, got '
                            f'{kind!r:.40}')
        a, b = links
        closures.append(Closure(f'{pair[0]}C{pair[1]}', closure_kind, str(a), np.eye(4), str(b),
                                np.eye(4), None, None, 'robot.yaml'))
    independent = None
    if 'name_mot' in data:
        independent = tuple(_names(data, 'name_mot', at))
    return tuple(closures), independent


# --- fusion2URDF: robot_data.yaml ------------------------------------------------------


def _vector(item: dict[str, Any], key: str, here: str, default: tuple[float, ...] | None
            ) -> tuple[float, float, float]:
    value = item.get(key, default)
    if not isinstance(value, (list, tuple)) or len(value) != 3 or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
            for v in value):
        raise UrdfError(f'{here}.{key}: Expected [x, y, z] (finite numbers), got '
                        f'{value!r:.80}')
    x, y, z = (float(v) for v in value)
    return x, y, z


def _fusion2urdf(data: dict[str, Any], where: str, description: Description
                 ) -> tuple[Closure, ...]:
    at = f'{where}: robot_data.yaml (fusion2URDF): closing_joints'
    items = data['closing_joints']
    if not isinstance(items, list) or not items:
        raise UrdfError(f'{at}: Expected a list of closing joints ({{name, type, parent, child, '
                        f'origin_xyz_m, origin_rpy_rad, axis}}), got {items!r:.80}')
    zero = description.transforms({name: 0.0 for name, j in description.joints.items()
                                   if j.type is not None})
    closures = []
    for index, item in enumerate(items):
        here = f'{at}[{index}]'
        if not isinstance(item, dict):
            raise UrdfError(f'{here}: Expected {{name, type, parent, child, origin_xyz_m, '
                            f'origin_rpy_rad, axis}}, got {item!r:.80}')
        name = str(item.get('name', f'closing_{index}'))
        here = f'{at}[{index}] "{name}"'
        kind = JOINT_CLOSURES.get(str(item.get('type')))
        if kind is None:
            raise UrdfError(f'{here}.type: Expected {", ".join(JOINT_CLOSURES)}, got '
                            f'{item.get("type")!r:.40}')
        ends = []
        for key in ('parent', 'child'):
            if item.get(key) not in zero:
                raise UrdfError(f'{here}.{key}: Expected a link of the robot, got '
                                f'{item.get(key)!r:.80}')
            ends.append(str(item[key]))
        frame = transform(_vector(item, 'origin_xyz_m', here, (0.0, 0.0, 0.0)),
                          _vector(item, 'origin_rpy_rad', here, (0.0, 0.0, 0.0)))
        axis = _unit(_vector(item, 'axis', here, (1.0, 0.0, 0.0)), f'{here}.axis', where)
        parent, child = ends
        on_child = np.linalg.inv(zero[child]) @ zero[parent] @ frame
        closures.append(_closure(name, kind, parent, frame, child, on_child, axis,
                                 'robot_data.yaml'))
    return tuple(closures)


def _closure(name: str, kind: ClosureKind, link_a: str, frame_a: Matrix, link_b: str,
             frame_b: Matrix, axis: tuple[float, float, float] | None, form: str) -> Closure:
    """Return a closure whose axis (in ``frame_a``'s axes, as a joint's) is on both links."""
    if kind is ClosureKind.WELD or axis is None:
        return Closure(name, kind, link_a, frame_a, link_b, frame_b, None, None, form)
    direction = np.asarray(axis)
    ax, ay, az = (float(v) for v in frame_a[:3, :3] @ direction)
    bx, by, bz = (float(v) for v in frame_b[:3, :3] @ direction)
    return Closure(name, kind, link_a, frame_a, link_b, frame_b, (ax, ay, az), (bx, by, bz),
                   form)


# --- inside the URDF: <loop_joint> (Isaac Sim) and <loop> (URDF+) ----------------------


def urdf_loops(root: Any, links: set[str], source: str, version: str) -> Iterator[Closure]:
    """Yield the closures of a URDF's ``<loop_joint>`` and ``<loop>`` elements."""
    for tag, ends in (('loop_joint', ('link1', 'link2')),
                      ('loop', ('predecessor', 'successor'))):
        for element in root.findall(tag):
            name = element.get('name') or ''
            where = f'<{tag} name="{name}">'
            kind = JOINT_CLOSURES.get(element.get('type', ''))
            if kind is None:
                raise UrdfError(f'{source}: {where}: Expected a type in '
                                f'{", ".join(JOINT_CLOSURES)}, got {element.get("type")!r}')
            sides = []
            for end in ends:
                part = element.find(end)
                link = None if part is None else part.get('link')
                if link not in links:
                    raise UrdfError(f'{source}: {where}: Expected <{end} link="..."/> naming a '
                                    f'link of the robot, got {link!r}')
                sides.append((str(link), _end_frame(element, part, end, where, source,
                                                    version)))
            axis_element = element.find('axis')
            axis = None
            if axis_element is not None or kind is ClosureKind.SLIDE:
                text = None if axis_element is None else axis_element.get('xyz')
                axis = _unit(_floats(text, 3, f'{where} <axis> xyz', source, (1.0, 0.0, 0.0)),
                             f'{where} <axis>', source)
            (link_a, frame_a), (link_b, frame_b) = sides
            yield _closure(name or f'{tag}_{link_a}_{link_b}', kind, link_a, frame_a, link_b,
                           frame_b, axis, f'<{tag}>')


def _end_frame(element: Any, part: Any, end: str, where: str, source: str, version: str
               ) -> Matrix:
    """Return one end's frame: xyz/rpy on the end, an ``<origin>`` in it, or ``<END_origin>``."""
    if part.get('xyz') is not None or part.get('rpy') is not None \
            or part.get('quat_xyzw') is not None:
        return _origin(part, f'{where} <{end}>', source, version)
    inner = part.find('origin')
    if inner is None:
        inner = element.find(f'{end}_origin')
    return _origin(inner, f'{where} <{end}> origin', source, version)


def _sidecar(path: str | os.PathLike[str], description: Description,
             ) -> tuple[tuple[Closure, ...], tuple[str, ...] | None]:
    """Read the closures beside the URDF: any form :func:`read_closure_file` tells by content."""
    return read_closure_file(path, description)


def _loop_closures_yaml(data: Any, where: str, description: Description,
                        ) -> tuple[tuple[Closure, ...], tuple[str, ...] | None]:
    """Read scikit-robot's ``loop_closures.yaml`` (parsed): closures and independent joints."""
    if not isinstance(data, dict) or not isinstance(data.get('closures'), list) \
            or not data['closures']:
        raise UrdfError(f'{where}: Expected a loop_closures.yaml (closures: [{{link_a, link_b, '
                        f'point, axis}}], dependent, independent), got no closures')
    unknown = set(data) - {'closures', 'dependent', 'independent'}
    if unknown:
        raise UrdfError(f'{where}: Expected keys closures, dependent and independent, got '
                        f'{", ".join(sorted(map(str, unknown)))}')
    zero = description.transforms({name: 0.0 for name, j in description.joints.items()
                                   if j.type is not None})
    closures = []
    for index, item in enumerate(data['closures']):
        at = f'{where}: closures[{index}]'
        if not isinstance(item, dict) or set(item) != {'link_a', 'link_b', 'point', 'axis'}:
            raise UrdfError(f'{at}: Expected {{link_a, link_b, point, axis}}, got '
                            f'{item!r:.80}')
        ends = []
        for key in ('link_a', 'link_b'):
            if item[key] not in zero:
                raise UrdfError(f'{at}.{key}: Expected a link of the robot, got '
                                f'{item[key]!r:.80}')
            ends.append(item[key])
        vectors = []
        for key in ('point', 'axis'):
            value = item[key]
            if not isinstance(value, list) or len(value) != 3 or not all(
                    isinstance(v, (int, float)) and not isinstance(v, bool)
                    and math.isfinite(v) for v in value):
                raise UrdfError(f'{at}.{key}: Expected [x, y, z] (finite numbers, the root '
                                f'frame at the zero pose), got {value!r:.80}')
            vectors.append(np.asarray(value, dtype=np.float64))
        point, axis = vectors
        axis_unit = _unit(tuple(axis), f'{at}.axis', where)
        frames = []
        for link in ends:
            inverse = np.linalg.inv(zero[link])
            frames.append(inverse @ translation(point))
        axes = [tuple(float(v) for v in np.linalg.inv(zero[link])[:3, :3]
                      @ np.asarray(axis_unit)) for link in ends]
        closures.append(Closure(f'closure_{index}', ClosureKind.PIN, ends[0], frames[0], ends[1],
                                frames[1], axes[0], axes[1], 'loop_closures.yaml'))
    independent = data.get('independent')
    if independent is not None:
        if not isinstance(independent, list) or not all(isinstance(n, str) for n in independent):
            raise UrdfError(f'{where}: independent: Expected a list of joint names, got '
                            f'{independent!r:.80}')
        independent = tuple(independent)
    return tuple(closures), independent


def _actuated(root: Any) -> tuple[str, ...]:
    """Return the joints of ``<transmission>`` and ``<ros2_control>`` command interfaces."""
    names: list[str] = []
    for element in root.findall('transmission'):
        for joint in element.findall('joint'):
            if joint.get('name'):
                names.append(joint.get('name'))
    for element in root.findall('ros2_control'):
        for joint in element.findall('joint'):
            if joint.get('name') and joint.findall('command_interface'):
                names.append(joint.get('name'))
    return tuple(dict.fromkeys(names))


def _reductions(root: Any, source: str) -> dict[str, tuple[str, float]]:
    """Return joint -> (actuator, mechanicalReduction) of each one-joint ``<transmission>``."""
    out: dict[str, tuple[str, float]] = {}
    for element in root.findall('transmission'):
        joints, actuators = element.findall('joint'), element.findall('actuator')
        if len(joints) != 1 or len(actuators) != 1 or not joints[0].get('name'):
            continue
        text = actuators[0].findtext('mechanicalReduction')
        if text is None:
            text = joints[0].findtext('mechanicalReduction')
        if text is None:
            continue
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        name = joints[0].get('name')
        if not math.isfinite(value) or value == 0.0:
            raise _fail(source, f'joint "{name}": Expected its <transmission>\'s '
                        f'<mechanicalReduction> to be a finite number other than 0, got '
                        f'{text.strip()!r}', name)
        out[name] = (actuators[0].get('name') or f'{name}_actuator', value)
    return out


def read_description(source: str | os.PathLike[str], closures: str | os.PathLike[str] | None
                     = None) -> Description:
    """Read a robot: a URDF (a path, or its text) and its loop closures.

    Parameters
    ----------
    source : str or path
        A URDF file, or the URDF's text (a string starting with ``<``).
    closures : str or path, optional
        The closures beside it, in any form of :data:`FORMS`.

    Returns
    -------
    Description

    Raises
    ------
    UrdfError
        One line naming the source and what is wrong.
    """
    from ..scene import _decode, _read_bytes

    text_given = isinstance(source, str) and source.lstrip().startswith('<')
    name = '<robot_description>' if text_given else str(source)
    if text_given:
        text = str(source)
    else:
        try:
            text = _decode(Path(source), _read_bytes(Path(source)))
        except SceneError as error:
            raise UrdfError(str(error)) from None
    root = _parse_xml(text, name)
    version = _version(root, name)
    quaternions = _quaternion_origins(root, version, name)
    robot = _read_links_and_joints(root, name)
    links = tuple(link.name for link in robot.links)
    if len(set(links)) != len(links):
        twice = next(link for link in links if links.count(link) > 1)
        raise _fail(name, f'Expected every link to have a name of its own, got "{twice}" twice')
    if not links:
        raise _fail(name, 'Expected a URDF with at least one link, got none')
    joints = _joints(robot, name, quaternions)
    root_link = _root(links, joints, name)
    found = tuple(_constraints(root, set(links), name, version)) + tuple(
        _closing_frames(joints, links, name)) + tuple(urdf_loops(root, set(links), name, version))
    inertials = _inertials(robot, name, quaternions)
    reductions = _reductions(root, name)
    description = Description(str(robot.name or 'robot'), name, text, links, joints, root_link,
                              found, _actuated(root), inertials=inertials,
                              reductions=reductions)
    if closures is None:
        return description
    extra, independent = _sidecar(closures, description)
    return Description(description.name, name, text, links, joints, root_link,
                       found + extra, description.actuated, independent, inertials,
                       reductions=reductions)
