# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Forces through the loop: inverse dynamics over the mechanism's graph, with error bounds.

A scene with ``masses``, ``gravity`` or ``loads`` (docs/scene_format.md,
"Forces") has a :class:`Dynamics`: its bodies' inertias, the constant loads
and gravity, laid over the graph of bodies and joints (:mod:`.graph`). At a
solved instant (a :class:`~.state.State`, one or an array) it answers what
every driver must push (its *effort*), what every joint carries (its
*reaction*) and what the frame feels (the *shaking* force and moment), each
with an absolute error bound: :meth:`Dynamics.forces`.

The method is the kinetostatics of the textbooks, written once for any
graph: every moving body gives three equations (its forces and its moment
about its frame's origin equal its mass times its centre of mass's
acceleration, and its inertia times its angular acceleration plus the
moment of that), every joint brings its unknowns (a pin its two force
components, a prismatic joint the force normal to its line and the moment
the line exerts, a driver its effort, a Geneva lock its holding moment).
An intermittent joint acts on the side the kinematics answer
(``Engagement.driven``: at a mouth, the side after the jump): its slot or
its lock; :func:`~.solve.solve` solves the other side's forces too
(``State.jumps['forces']``).
The equations split by the kinds that added the bodies (each kind's part of
the graph is an Assur group, statically determinate on its own, or a driver
with its link): solved from the last group placed back to the drivers, each
group's unknowns are those of its own joints, and the forces its joints put
on earlier bodies are known when those are solved. A kind declares only its
bodies and joints; nothing here asks which kind a group is.

Bounds: each group's small system ``A x = b`` is solved in doubles and
bounded a posteriori: with ``X`` an approximate inverse of ``A`` and ``R = I
- A X``, ``|x - x_exact| <= |X| t + |X| |R| 1 ||t|| / (1 - ||R||)`` where
``t`` bounds the residual of the exact system at the computed ``x`` (the
computed residual, its rounding, and the error bounds of ``A``'s entries
times ``|x|`` and of ``b``'s, which come from the kinematic bounds of the
positions and accelerations and from the later groups' reactions). Where
``||R||`` is not below one half (a toggle, where the statics degenerate) the
instant has no bound and is refused.

Pure NumPy: no ROS, no drawing.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
import math
from types import SimpleNamespace
from typing import Any, cast, TYPE_CHECKING

import numpy as np

from .compiler import NotCompiled
from .graph import Graph, Joint
from .model import _check_finite, _check_name
from .recording import Recorder, Unrecordable
from ..bounds import LARGEST, magnitude, U
from ..errors import SceneError

if TYPE_CHECKING:
    from .state import State

__all__ = ['Dynamics', 'Forces', 'Load', 'Mass', 'Reaction', 'given_forces_refusal']

#: Single instants of one scene on the general path before its forces are written out
#: (:meth:`Dynamics._write`): writing them out costs what a few general instants do.
COMPILE_AFTER = 8
#: Array calls of one scene on the general path before its forces are written out.
ARRAY_COMPILE_AFTER = 2
#: Pivot sequences written out for a scene's arrays at most: one with more (the excavator
#: meets 6) keeps the general path for its arrays, which a chain of functions, each run over
#: the instants the last left, was slower than (bench/forces_bench.py).
ARRAY_SEQUENCES = 2
#: Instants a written-out function runs at once over a longer array (its temporaries stay
#: in the cache: twice as fast over 100,000 instants as all at once, bench/forces_bench.py).
ARRAY_CHUNK = 8192
#: Pivot sequences written out per scene at most (a turn of the packaged scenes meets 1 to 3).
MAX_SEQUENCES = 8

#: Rounding of one correctly rounded operation, as a multiple of |result| (NumPy's
#: products and sums of a few terms: gamma_k = k U / (1 - k U) for k operations).
_GAMMA = 2.0 * U


def _gamma(k: int) -> float:
    return k * U / (1.0 - k * U)


def _finite_pair(owner: Any, key: str, what: str, form: str) -> None:
    """Check that ``owner.key`` is two finite numbers and store them as a tuple of floats.

    Refused naming ``what`` (``Expected WHAT as FORM``, then each value finite).
    """
    pair = tuple(getattr(owner, key))
    if len(pair) != 2:
        msg = f'Expected {what} as {form}, got {getattr(owner, key)!r}'
        raise SceneError(msg, (owner, key))
    for value in pair:
        _check_finite(value, what, (owner, key))
    object.__setattr__(owner, key, (float(pair[0]), float(pair[1])))


@dataclass(frozen=True)
class Mass:
    """The inertia of one moving body.

    Parameters
    ----------
    body : str
        The body: a link, a slider block, a cylinder's barrel (its link) or
        rod (its actuator), as the graph names them.
    mass : float
        kg, > 0.
    com : (float, float)
        Its centre of mass in the body's frame (x along the link from its
        start, y to its left), m.
    inertia : float
        kg m^2 about the centre of mass, z axis, >= 0.
    """

    body: str
    mass: float
    com: tuple[float, float] = (0.0, 0.0)
    inertia: float = 0.0

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.body, 'a body with a mass', (self, 'body'))
        if not (math.isfinite(self.mass) and self.mass > 0.0):
            msg = f'Expected the mass of "{self.body}" to be positive, got {self.mass!r} kg'
            raise SceneError(msg, (self, 'mass'))
        _finite_pair(self, 'com', f'the centre of mass of "{self.body}"', '[x, y]')
        if not (math.isfinite(self.inertia) and self.inertia >= 0.0):
            msg = (f'Expected the inertia of "{self.body}" to be 0 or more, got '
                   f'{self.inertia!r} kg m^2')
            raise SceneError(msg, (self, 'inertia'))


@dataclass(frozen=True)
class Load:
    """A constant external load: a force at a point, or a torque on a moving body.

    Parameters
    ----------
    name : str
        Its name (the node's ``loads.NAME.*`` parameters).
    point : str or None
        The point a force acts at.
    force : (float, float) or None
        N, in the scene's frame.
    link : str or None
        The body a torque acts on; for a force, the body it acts on, which must
        carry ``point`` (by default: the slider block at that point if there is
        one, as a gas force on a piston, else the first link placed there).
    torque : float or None
        N m about z, + CCW.
    at : (float, float) or None
        For a force on ``link`` without ``point``: where it acts, in the body's
        own frame (m), as a mass's ``com`` is given (a URDF link's force at a
        point of the link).
    table : (str, tuple of (float, float, float)) or None
        Instead of ``force``: a force that depends on where a joint stands,
        ``(joint, rows)``, each row ``(position, fx, fy)`` (rad or m; N), the
        positions non-decreasing (two rows at one position: a jump, the later
        row from it on), linear between rows (:meth:`force_at`). A revolute
        joint's rows lie within one turn from the first and repeat every turn
        (between the last row and the first a turn on, linear too); a
        prismatic joint's force below the first row is the first row's, above
        the last the last's. A press's working stroke is such a table.
    """

    name: str
    point: str | None = None
    force: tuple[float, float] | None = None
    link: str | None = None
    torque: float | None = None
    at: tuple[float, float] | None = None
    table: tuple[str, tuple[tuple[float, float, float], ...]] | None = None
    #: For a table over a revolute joint: its rows repeat every turn (the Dynamics gives its
    #: loads this from the joint's kind).
    periodic: bool = False

    def __post_init__(self) -> None:
        """Validate the fields: a force at a point, or a torque on a link, not both."""
        _check_name(self.name, 'a load name', (self, 'name'))
        if self.table is not None:
            self._check_table()
        at_point = self.point is not None or self.force is not None or self.table is not None
        twist = self.torque is not None
        placed = self.point is not None or (self.at is not None and self.link is not None
                                            and self.point is None)
        given = (self.force is None) != (self.table is None)
        if at_point == twist or (at_point and (not placed or not given)) \
                or (twist and (self.link is None or self.at is not None)):
            msg = (f'Expected load "{self.name}" to be {{point, force}} (optionally with the '
                   f'link it acts on) or {{link, torque}}, got point={self.point!r}, '
                   f'force={self.force!r}, link={self.link!r}, torque={self.torque!r}')
            raise SceneError(msg, (self, 'name'))
        if self.force is not None:
            _finite_pair(self, 'force', f'the force of load "{self.name}"', '[fx, fy]')
        if self.torque is not None:
            _check_finite(self.torque, f'the torque of load "{self.name}"', (self, 'torque'))
        if self.at is not None and self.table is not None:
            msg = f'Expected load "{self.name}" at a scene point for a table, got at={self.at!r}'
            raise SceneError(msg, (self, 'at'))
        if self.at is not None:
            _finite_pair(self, 'at', f'the point of load "{self.name}"', '[x, y]')

    def _check_table(self) -> None:
        assert self.table is not None
        joint, raw = self.table
        rows = tuple(tuple(float(v) for v in row) for row in raw)
        if len(rows) < 2 or any(len(row) != 3 for row in rows):
            msg = (f'Expected the table of load "{self.name}" as at least two rows [position, '
                   f'fx, fy], got {list(raw)!r}')
            raise SceneError(msg, (self, 'table'))
        for row in rows:
            for value in row:
                _check_finite(value, f'the table of load "{self.name}"', (self, 'table'))
        positions = [row[0] for row in rows]
        if any(b < a for a, b in zip(positions, positions[1:], strict=False)) or any(
                a == b == c for a, b, c in zip(positions, positions[1:], positions[2:],
                                               strict=False)):
            msg = (f'Expected the positions of load "{self.name}"\'s table in order, at most '
                   f'two rows at one position (a jump), got {positions}')
            raise SceneError(msg, (self, 'table'))
        object.__setattr__(self, 'table', (str(joint), rows))

    @property
    def largest(self) -> float:
        """Return the largest force the load can give, N (its table's largest row)."""
        if self.table is not None:
            return max(magnitude(complex(fx, fy)) for _, fx, fy in self.table[1])
        return magnitude(complex(*self.force)) if self.force is not None else 0.0

    def force_at(self, position: Any) -> tuple[Any, Any]:
        """Return the table's force where its joint stands (``position``, rad or m), and its slope.

        ``(force, slope)``: complex N, and N per rad (or m), floats for a float
        and arrays for an array: the same NumPy operations either way, so one
        instant and an array give the same bits.
        """
        assert self.table is not None
        rows = np.asarray(self.table[1], dtype=np.float64)
        xp, fx, fy = rows[:, 0], rows[:, 1], rows[:, 2]
        x = np.asarray(position, dtype=np.float64)
        if self.periodic:   # the rows repeat every turn: the last to the first a turn on
            x = xp[0] + np.mod(x - xp[0], math.tau)
            xp = np.append(xp, xp[0] + math.tau)
            fx, fy = np.append(fx, fx[0]), np.append(fy, fy[0])
        else:
            x = np.clip(x, xp[0], xp[-1])
        k = np.clip(np.searchsorted(xp, x, side='right') - 1, 0, len(xp) - 2)
        span = xp[k + 1] - xp[k]
        with np.errstate(divide='ignore', invalid='ignore'):
            t = np.where(span > 0.0, (x - xp[k]) / np.where(span > 0.0, span, 1.0), 0.0)
        force = (fx[k] + t * (fx[k + 1] - fx[k])) + 1j * (fy[k] + t * (fy[k + 1] - fy[k]))
        slope = np.where(span > 0.0, np.hypot(fx[k + 1] - fx[k], fy[k + 1] - fy[k])
                         / np.where(span > 0.0, span, 1.0), 0.0)
        if force.ndim == 0:
            return complex(force), float(slope)
        return force, slope


def given_forces_refusal(masses: Sequence[Mass], loads: Sequence[Load],
                         gravity: tuple[float, float]) -> tuple[Any, str, str] | None:
    """Return why the forces a scene gives overflow a double, or None where they do not.

    The forces given are the weights of the moving bodies (their total mass
    times ``|g|``) and the loads' forces: each, and their sum, must be finite
    doubles (at most :data:`~mech_kinematics.bounds.LARGEST`, 1.8e308 N), or
    the forces at an instant, which add them, cannot be either. Returns
    ``(element, field, reason)``: the mass whose total overflows, gravity
    (``element`` None) whose weight does, or the first load that makes the
    sum overflow; ``reason`` starts with "expected" (the caller puts the key
    before it).
    """
    mass = 0.0
    for m in masses:
        mass += m.mass
        if not math.isfinite(mass):
            return m, 'mass', (f"expected the moving bodies' masses to add up to a finite "
                               f'mass, got {m.mass!r} kg')
    g = magnitude(complex(*gravity))
    weight = mass * g
    if not (math.isfinite(g) and math.isfinite(weight)):
        return None, 'gravity', (f'expected [gx, gy] whose weight on the moving bodies '
                                 f'({mass:.6g} kg) is a finite force (at most {LARGEST:.4g} '
                                 f'N), got {list(gravity)} m/s^2')
    total = weight
    for load in loads:
        if load.force is None and load.table is None:
            continue
        total += load.largest
        if not math.isfinite(total):
            return load, 'force', (f"expected the loads' forces and the weights "
                                   f'({weight:.4g} N) to add up to a finite force (at most '
                                   f'{LARGEST:.4g} N), got {list(load.force)} N')
    return None


@dataclass(frozen=True)
class Reaction:
    """What one joint carries: the force (and moment) on ``on`` from ``by`` at point ``at``.

    A pin has ``force`` (N, scene frame); a prismatic joint ``normal`` (N,
    along its line's direction turned +90 deg) and ``moment`` (N m about
    ``at``); a lock ``moment`` only. Each with its bound (``*_bound``).
    """

    at: str
    on: str
    by: str
    force: Any = None
    normal: Any = None
    moment: Any = None
    force_bound: Any = None
    normal_bound: Any = None
    moment_bound: Any = None

    def as_dict(self, vector: bool) -> dict[str, Any]:
        """Return the contract's ``{"at", "on", "by", "force" | "normal", "moment"}``."""
        def value(x: Any) -> Any:
            return x if vector else float(x)

        data: dict[str, Any] = {'at': self.at, 'on': self.on, 'by': self.by}
        if self.force is not None:
            data['force'] = _pair(self.force, vector)
        if self.normal is not None:
            data['normal'] = value(self.normal)
        if self.moment is not None:
            data['moment'] = value(self.moment)
        return data

    def bound_dict(self, vector: bool) -> dict[str, Any]:
        """Return the bounds shaped like :meth:`as_dict`'s values (a force's: one norm)."""
        def value(x: Any) -> Any:
            return x if vector else float(x)

        data: dict[str, Any] = {}
        if self.force is not None:
            data['force'] = value(self.force_bound)
        if self.normal is not None:
            data['normal'] = value(self.normal_bound)
        if self.moment is not None:
            data['moment'] = value(self.moment_bound)
        return data


def _pair(z: Any, vector: bool) -> Any:
    if vector:
        return np.stack((np.real(z), np.imag(z)), axis=-1)
    return [float(np.real(z)), float(np.imag(z))]


@dataclass(frozen=True)
class Forces:
    """The forces of a state: efforts, reactions, shaking, each with its bound (SI units).

    Attributes
    ----------
    efforts : dict of str to float or ndarray
        Each driver's effort: a crank's torque (N m, + CCW), an actuator's
        force (N, + extending).
    reactions : dict of str to Reaction
        Every joint between two bodies, by the graph's joint name.
    shaking_force : complex or ndarray of complex
        The resultant force the joints put on the ground, N (x + iy).
    shaking_moment : float or ndarray
        Their moment about the scene's origin, N m.
    effort_bounds : dict of str to float or ndarray
        The efforts' bounds.
    shaking_bounds : (float, float) or arrays
        The bounds of the shaking force (a norm) and moment.
    valid : bool or ndarray of bool
        Where the forces could be bounded (a toggle leaves them undetermined).
    scale : float or ndarray
        The forces' scale (N): the largest of every force computed, of every
        body's inertia force and weight and of every load; moments are judged
        on ``scale`` times the mechanism's size.
    failures : dict of str to ndarray of bool
        For arrays: per reason, the instants refused.
    worst : (str, float, float) or None
        For one instant refused: the value whose bound exceeds its limit most
        (its name in ``as_dict()``), its bound and the limit.
    """

    efforts: dict[str, Any]
    reactions: dict[str, Reaction]
    shaking_force: Any
    shaking_moment: Any
    effort_bounds: dict[str, Any]
    shaking_bounds: tuple[Any, Any]
    valid: Any
    scale: Any
    failures: dict[str, Any] = field(default_factory=dict)
    worst: tuple[str, float, float] | None = None

    def as_dict(self, vector: bool) -> dict[str, Any]:
        """Return ``"efforts"``, ``"reactions"`` and ``"shaking"`` as ``State.as_dict()``."""
        def value(x: Any) -> Any:
            return x if vector else float(x)

        return {'efforts': {name: value(x) for name, x in self.efforts.items()},
                'reactions': {name: r.as_dict(vector) for name, r in self.reactions.items()},
                'shaking': {'force': _pair(self.shaking_force, vector),
                            'moment': value(self.shaking_moment)}}

    def spread(self, at: Any, shape: tuple[int, ...]) -> Forces:
        """Return these forces of the instants ``at`` (indices) in arrays of ``shape``.

        NaN (a force: NaN + NaN i) at the other instants, ``valid`` False
        there: the shape of ``State.jumps``' values.
        """
        def put(some: Any) -> Any:
            if some is None:
                return None
            some = np.asarray(some)
            out = np.full(shape, False if some.dtype == bool else np.nan, dtype=some.dtype)
            out[at] = some
            return out

        reactions = {name: Reaction(r.at, r.on, r.by, put(r.force), put(r.normal),
                                    put(r.moment), put(r.force_bound), put(r.normal_bound),
                                    put(r.moment_bound)) for name, r in self.reactions.items()}
        return Forces({n: put(v) for n, v in self.efforts.items()}, reactions,
                      put(self.shaking_force), put(self.shaking_moment),
                      {n: put(v) for n, v in self.effort_bounds.items()},
                      (put(self.shaking_bounds[0]), put(self.shaking_bounds[1])),
                      put(self.valid), put(self.scale),
                      {reason: put(mask) for reason, mask in self.failures.items()})

    def bound_dict(self, vector: bool) -> dict[str, Any]:
        """Return the bounds, shaped like :meth:`as_dict`'s (a force's bound is one norm)."""
        def value(x: Any) -> Any:
            return x if vector else float(x)

        return {'efforts': {name: value(x) for name, x in self.effort_bounds.items()},
                'reactions': {name: r.bound_dict(vector) for name, r in self.reactions.items()},
                'shaking': {'force': value(self.shaking_bounds[0]),
                            'moment': value(self.shaking_bounds[1])}}


#: The unknowns a joint brings, by what it is: a pin's force components, a prismatic
#: joint's normal force and moment, a driver's effort after those, a lock's moment.
_PIN, _SLIDE, _LOCK = ('x', 'y'), ('normal', 'moment'), ('moment',)


def _components(joint: Joint) -> tuple[str, ...]:
    if joint.type.table is None:     # a lock: it holds the body's angle
        return _LOCK
    base = _PIN if joint.line is None else _SLIDE
    return (*base, 'effort') if joint.driver else base


@dataclass(frozen=True)
class _Config:
    """One group's system while a set of its joints acts (an intermittent drive's phase)."""

    joints: tuple[int, ...]             # indices into the group's joints that act
    columns: tuple[tuple[int, str], ...]  # (joint index, component) of each unknown
    rows: tuple[tuple[int, int], ...]   # (body index in the group, 0 fx / 1 fy / 2 moment)


@dataclass(frozen=True)
class _Group:
    """One kind's part of the statics: the equations of its bodies, the unknowns of its joints."""

    key: str
    bodies: tuple[str, ...]
    joints: tuple[Joint, ...]
    configs: dict[tuple[bool, ...], _Config]
    levers: tuple[str, ...]     # the intermittent levers whose phase picks the config


class Dynamics:
    """A scene's masses, loads and gravity over its graph; :meth:`forces` at a solved state.

    Parameters
    ----------
    graph : Graph
        The mechanism's bodies and joints.
    masses : sequence of Mass
        The bodies with inertia (the others are massless).
    loads : sequence of Load
        Constant external loads.
    gravity : (float, float)
        m/s^2, in the scene's frame.
    points : collection of str
        Every point of the scene (for the loads' ``point``).
    size : float
        The mechanism's size, m (moments are judged on the force scale times it).

    Raises
    ------
    SceneError
        Naming the key: a mass on a body the graph lacks (or the ground), a load
        on an unknown point or body, a part of the mechanism whose joint
        reactions statics cannot determine, or gravity or a load whose forces
        overflow a double (:func:`given_forces_refusal`).
    """

    def __init__(self, graph: Graph, masses: Sequence[Mass], loads: Sequence[Load],
                 gravity: tuple[float, float], points: Sequence[str], size: float) -> None:
        self.graph = graph
        self.gravity = complex(*gravity)
        self.size = size
        moving = [name for name in graph.bodies if name != graph.ground]
        self.masses: dict[str, Mass] = {}
        for mass in masses:
            if mass.body not in graph.bodies or mass.body == graph.ground:
                got = ('the ground, which does not move' if mass.body == graph.ground
                       else f'unknown "{mass.body}"')
                msg = f'Expected a moving body ({", ".join(moving)}), got {got}'
                raise SceneError(msg, (mass, 'body'))
            if mass.body in self.masses:
                msg = f'Expected each body once in masses, got "{mass.body}" twice'
                raise SceneError(msg, (mass, 'body'))
            self.masses[mass.body] = mass
        owner: dict[str, str] = {}   # point -> the body a force there acts on by default
        for name, body in graph.bodies.items():
            for point in body.points:
                block = body.points == (point,) and body.guide is not None
                if point not in owner or (block and owner[point] != graph.ground):
                    owner[point] = name
        given = tuple(loads)
        used: list[Load] = []   # each load as the forces read it (a table's turn said)
        self.point_loads: dict[str, list[Load]] = {}
        self.torque_loads: dict[str, list[Load]] = {}
        names: set[str] = set()
        for load in given:
            if load.name in names:
                msg = f'Expected each load name once, got "{load.name}" twice'
                raise SceneError(msg, (load, 'name'))
            names.add(load.name)
            acting = load
            if load.table is not None:
                kind = graph.coordinates.get(load.table[0])
                if kind is None:
                    msg = (f'Expected load "{load.name}"\'s table over a joint of the scene '
                           f'({", ".join(graph.coordinates)}), got "{load.table[0]}"')
                    raise SceneError(msg, (load, 'table'))
                if kind.angular and load.table[1][-1][0] - load.table[1][0][0] > math.tau:
                    msg = (f'Expected load "{load.name}"\'s table over a revolute joint within '
                           f'one turn from its first row, got rows from '
                           f'{load.table[1][0][0]!r} to {load.table[1][-1][0]!r} rad')
                    raise SceneError(msg, (load, 'table'))
                if kind.angular != load.periodic:
                    acting = replace(load, periodic=bool(kind.angular))
            used.append(acting)
            if load.point is not None:
                body = owner.get(load.point) if load.link is None else load.link
                if load.link is not None and (load.link not in graph.bodies or load.point
                                              not in graph.bodies[load.link].points):
                    msg = (f'Expected load "{load.name}" on a body carrying {load.point} '
                           f'({", ".join(graph.carriers(load.point)) or "none"}), got '
                           f'"{load.link}"')
                    raise SceneError(msg, (load, 'link'))
                if load.point not in points or body is None:
                    msg = f'Expected a load at a point of the scene, got unknown "{load.point}"'
                    raise SceneError(msg, (load, 'point'))
                if body == graph.ground:
                    msg = (f'Expected load "{load.name}" at a moving point, got "{load.point}", '
                           f'fixed on the ground (a load there moves nothing)')
                    raise SceneError(msg, (load, 'point'))
                self.point_loads.setdefault(body, []).append(acting)
                continue
            # On a body: a force at a point of its frame (``at``), or a torque.
            assert load.link is not None
            if load.link not in graph.bodies or load.link == graph.ground:
                msg = f'Expected a load on a moving body ({", ".join(moving)}), got ' + (
                    'the ground' if load.link == graph.ground else f'unknown "{load.link}"')
                raise SceneError(msg, (load, 'link'))
            loads_on = self.point_loads if load.force is not None else self.torque_loads
            loads_on.setdefault(load.link, []).append(acting)
        self.loads = tuple(used)
        refused = given_forces_refusal(tuple(self.masses.values()), given, gravity)
        if refused is not None:
            element, key, reason = refused
            raise SceneError(reason, (element, key))
        self.groups = self._groups()
        #: Why one instant's forces are not written out (:meth:`_write`), or None.
        self.compiled_single: NotCompiled | None = None
        self._fast: list[Callable[..., Any]] = []     # one per pivot sequence, the last used first
        self._sequences: set[Any] = set()
        self._general = 0               # single instants on the general path
        #: Why arrays' forces are not written out, or None.
        self.compiled_array: NotCompiled | None = None
        self._fast_array: list[Any] = []    # one per pivot sequence, in the order met
        self._array_sequences: set[Any] = set()
        self._arrays = 0                # array calls

    # --- structure -------------------------------------------------------------------

    def _groups(self) -> tuple[_Group, ...]:
        """Return the kinds' groups, the last placed first (each needs only later ones solved)."""
        graph = self.graph
        group_of: dict[str, int] = {}
        raw = []
        for fragment in graph.fragments:
            bodies = tuple(b.name for b in fragment.bodies)
            if not bodies:
                continue
            for name in bodies:
                group_of[name] = len(raw)
            names = set(bodies)
            joints = tuple(j for j in graph.joints if j.body in names)
            raw.append((fragment.key, bodies, joints))
        # A group waits for the groups of the bodies its joints hang on: solve in reverse.
        order: list[int] = []
        state = [0] * len(raw)

        def visit(index: int) -> None:
            if state[index] == 2:
                return
            state[index] = 1
            for joint in raw[index][2]:
                parent = group_of.get(joint.on)
                if parent is not None and parent != index and state[parent] != 2:
                    visit(parent)
            state[index] = 2
            order.append(index)

        for index in range(len(raw)):
            visit(index)
        return tuple(self._group(*raw[index]) for index in reversed(order))

    def _group(self, key: str, bodies: tuple[str, ...], joints: tuple[Joint, ...]) -> _Group:
        graph = self.graph
        levers = tuple(dict.fromkeys(j.on if j.type.table is not None else j.body
                                     for j in joints if j.intermittent))
        configs: dict[tuple[bool, ...], _Config] = {}
        phases = [()] if not levers else [(True,), (False,)] if len(levers) == 1 else None
        if phases is None:
            msg = (f'Expected one intermittent drive in {key}, got {len(levers)}: forces are '
                   f'solved for one')
            raise SceneError(msg)
        for phase in phases:
            engaged = phase[0] if phase else True
            acting = tuple(i for i, j in enumerate(joints) if not j.intermittent
                           or (j.type.table is None) != engaged)
            columns = tuple((i, c) for i in acting for c in _components(joints[i]))
            rows = []
            for b, body in enumerate(bodies):
                rows += [(b, 0), (b, 1)]
                origin = graph.bodies[body].frame.origin  # type: ignore[union-attr]
                turns = any(self._turns(joints[i], body, origin) for i in acting)
                later = any(j.on == body and (j.line is not None or j.at != origin)
                            for j in graph.joints if j not in joints)
                if turns or later:
                    rows.append((b, 2))
                elif (given := self._moment_given(body)) is not None:
                    phase = 'engaged' if engaged else 'locked'
                    msg = (f'Expected the statics of {key} to be determined, got {body}, which '
                           f'turns freely about {origin} while {phase} and has a moment to '
                           f'carry (its centre of mass off {origin}, an inertia or a load): '
                           f'give it no mass there')
                    raise SceneError(msg, given)
            if len(rows) != len(columns):
                msg = (f'Expected the joint reactions of {key} to be determined by statics, got '
                       f'{len(rows)} equations for {len(columns)} unknowns')
                raise SceneError(msg)
            configs[phase] = _Config(acting, columns, tuple(rows))
        return _Group(key, bodies, joints, configs, levers)

    @staticmethod
    def _turns(joint: Joint, body: str, origin: str) -> bool:
        """Whether a joint puts a moment on ``body`` about its frame's origin."""
        if joint.body != body and joint.on != body:
            return False
        return joint.line is not None or joint.type.table is None or joint.driver \
            or joint.at != origin

    def _moment_given(self, body: str) -> tuple[Any, str] | None:
        """Return what gives ``body`` a moment about its frame's origin (the key to name)."""
        mass = self.masses.get(body)
        if mass is not None and mass.com != (0.0, 0.0):
            return mass, 'com'
        if mass is not None and mass.inertia:
            return mass, 'inertia'
        for load in self.torque_loads.get(body, ()):
            return load, 'link'
        origin = self.graph.bodies[body].frame.origin  # type: ignore[union-attr]
        for load in self.point_loads.get(body, ()):
            if (load.point != origin) if load.at is None else load.at != (0.0, 0.0):
                return load, 'point' if load.at is None else 'at'
        return None

    def needs(self) -> tuple[set[str], set[str]]:
        """Return the joints (coordinates) and points a state must hold for :meth:`forces`."""
        joints: set[str] = set(self.graph.drivers)
        points: set[str] = set()
        for body in self.graph.bodies.values():
            if body.frame is None:
                continue
            points.add(body.frame.origin)
            if body.frame.angle_of is not None:
                joints.add(body.frame.angle_of)
        for joint in self.graph.joints:
            points.add(joint.at)
            if joint.line is not None:
                points.add(joint.line.through)
                if joint.line.angle_of is not None:
                    joints.add(joint.line.angle_of)
        points.update(load.point for load in self.loads if load.point is not None)
        joints.update(load.table[0] for load in self.loads if load.table is not None)
        return joints, points

    # --- at a solved state -----------------------------------------------------------

    def forces(self, state: State, max_error: float) -> Forces:
        """Return the forces at a solved state (one instant or an array), bounded.

        ``max_error`` is the tolerance: a value whose bound exceeds it times
        the force scale (moments: times the scale and the mechanism's size)
        makes the instant invalid (``Forces.valid``, ``Forces.failures``).

        One instant runs written out (:meth:`_write`) once the scene
        has had :data:`COMPILE_AFTER` instants on the general path, an array
        once it has had :data:`ARRAY_COMPILE_AFTER` arrays: one function per
        pivot sequence met (at most :data:`MAX_SEQUENCES`; for arrays
        :data:`ARRAY_SEQUENCES`, beyond which they take the general path), the general
        path's bits and bounds; an instant none of them settles (a refusal,
        another pivot sequence) takes the general path. ``compiled_single``
        and ``compiled_array`` say why a scene is not written out. The lists
        of functions are replaced, never changed in place: a thread reading
        one while another writes a function sees the old list or the new.
        """
        if state.valid.__class__ is bool:
            fast = self._fast
            for index, function in enumerate(fast):
                try:
                    answer = function(state, max_error)
                except (OverflowError, ZeroDivisionError):  # the general path says what
                    answer = None
                if answer is False:     # another pivot sequence: try the next
                    continue
                if answer is not None:
                    if index:   # the last used first (a new list: another thread may read)
                        self._fast = [function, *(f for f in fast if f is not function)]
                    return cast(Forces, answer)
                break
            self._general += 1
            if self._general > COMPILE_AFTER and self.compiled_single is None \
                    and len(fast) < MAX_SEQUENCES:
                pivots: dict[str, list[tuple[int, ...]]] = {}
                forces = self._forces(state, max_error, pivots)
                key = tuple((name, tuple(p)) for name, p in pivots.items())
                if forces.valid is True and key not in self._sequences:
                    self._sequences.add(key)
                    written = self._write(state, max_error, vector=False)
                    if isinstance(written, NotCompiled):
                        self.compiled_single = written
                    else:
                        self._fast = [written, *self._fast]
                return forces
            return self._forces(state, max_error)
        self._arrays += 1
        if self._arrays <= ARRAY_COMPILE_AFTER or self.compiled_array is not None:
            return self._forces(state, max_error)
        with np.errstate(all='ignore'):
            size = int(np.size(state.valid))
            if size <= ARRAY_CHUNK:
                answer = self._array_forces(state, max_error, 0)
            else:   # in blocks whose temporaries stay in the cache: the same operations
                parts = [self._array_forces(_Subset(state, slice(i, i + ARRAY_CHUNK)),
                                            max_error, 0) for i in range(0, size, ARRAY_CHUNK)]
                answer = None if any(p is None for p in parts) else _concatenate(
                    cast('list[Forces]', parts))
        return self._forces(state, max_error) if answer is None else answer

    def _array_forces(self, state: Any, max_error: float, start: int) -> Forces | None:
        """Return the forces of an array from the written-out functions from ``start`` on.

        Each function settles the instants of its pivot sequence; the others go
        to the next (written from the first of them), the last to the general
        path; the answers are put back in place. None: the scene meets more
        than :data:`ARRAY_SEQUENCES` sequences, its arrays go to the general
        path from now on (each function costs, on an array, what the general
        path does on a few times fewer instants).
        """
        fast = self._fast_array
        valid = np.asarray(state.valid, dtype=bool)
        if start == len(fast):
            written: Any = None
            first = np.flatnonzero(valid)
            if first.size:
                pivots: dict[str, list[tuple[int, ...]]] = {}
                one = self._forces(cast('State', _Subset(state, int(first[0]))), max_error,
                                   pivots)
                key = tuple((name, tuple(p)) for name, p in pivots.items())
                if one.valid is True and key not in self._array_sequences:
                    if len(fast) == ARRAY_SEQUENCES:
                        self.compiled_array = NotCompiled(
                            f'more than {ARRAY_SEQUENCES} pivot sequences over its arrays (a '
                            f'function each costs more than the general path)')
                        return None
                    self._array_sequences.add(key)
                    written = self._write(_Subset(state, int(first[0])), max_error,
                                          vector=True)
                    if isinstance(written, NotCompiled):
                        self.compiled_array = written
                    else:
                        fast = self._fast_array = [*fast, written]
            if not callable(written):
                return self._forces(state, max_error)
        forces, ok = fast[start](state, max_error)
        object.__setattr__(forces, 'efforts', _broadcast(forces.efforts, valid.shape))
        settled = np.broadcast_to(ok, valid.shape)
        redo = valid & ~settled
        object.__setattr__(forces, 'valid', valid & settled)
        if not redo.any():
            return cast(Forces, forces)
        part = self._array_forces(_Subset(state, redo), max_error, start + 1)
        return None if part is None else _merge(forces, redo, part)

    def _write(self, state: Any, max_error: float, vector: bool) -> Any:
        """Return the forces written out from the general path at ``state``, or why not.

        :meth:`_forces` runs once on the values of a :class:`.recording.Recorder`
        at ``state`` (an instant the general path answered): the function
        written holds its operations on the branches that instant took (its
        pivots, its tests), guarded (see :mod:`.recording`). ``vector``: the
        same operations on arrays, returning ``(forces, ok)`` with ``ok`` the
        instants it settles. A :class:`.compiler.NotCompiled` with the reason
        where the scene's forces are not written out.
        """
        tabled = next((load.name for load in self.loads if load.table is not None), None)
        if tabled is not None:
            return NotCompiled(f'load "{tabled}" depends on where its joint stands (a table): '
                               f'not written out, the general path serves it')
        for group in self.groups:
            if group.levers:
                return NotCompiled(f'{group.key}: an intermittent drive (its phase picks the '
                                   f'statics of each instant)')
        recorder = Recorder(vector, _FUNCTIONS, {'cos': math.cos, 'sin': math.sin})
        try:
            forces = self._forces(cast('State', _Recorded(recorder, state)),
                                  cast(float, recorder.parameter('max_error', max_error)))
            return recorder.written(forces, 'forces', f'<forces of {self.graph.ground}>')
        except Unrecordable as exc:
            return NotCompiled(f'forces not written out: {exc}')

    def path(self) -> dict[str, str]:
        """Return which path serves the forces now, of one instant and of arrays, and why.

        ``{'single': ..., 'array': ...}``, each one line: ``written out (N
        pivot sequences)``, ``general: REASON`` where they are not written out
        (:meth:`_write`), or ``general (written out after N instants)`` /
        ``(... arrays)`` before the first is written.
        """
        def one(fast: list[Any], why: NotCompiled | None, after: str) -> str:
            if why is not None:
                return f'general: {why.reason}'
            if fast:
                n = len(fast)
                return f'written out ({n} pivot sequence{"s" if n > 1 else ""})'
            return f'general (written out after {after})'

        return {'single': one(self._fast, self.compiled_single, f'{COMPILE_AFTER} instants'),
                'array': one(self._fast_array, self.compiled_array,
                             f'{ARRAY_COMPILE_AFTER} arrays')}

    def _forces(self, state: State, max_error: float,
                pivots: dict[str, list[tuple[int, ...]]] | None = None) -> Forces:
        """Return :meth:`forces` on the general path; record each group's pivots in ``pivots``."""
        kin = _Kinematics(self.graph, state)
        biggest = kin.biggest
        done: dict[str, _Carried] = {}   # joint -> what it carries, solved
        scale: Any = 0.0
        # Where the kinematics answered (an array's other instants are theirs to explain).
        valid: Any = np.asarray(state.valid, dtype=bool) if kin.vector else True
        failures: dict[str, Any] = {}
        with np.errstate(all='ignore'):     # an overflow is refused below, never warned
            inertial = {name: self._inertial(name, kin) for name in kin.frames}
            finite: Any = True
            isfinite = np.isfinite if kin.vector else _finite
            for F, M, _, _ in inertial.values():
                scale = biggest(scale, magnitude(F))
                finite = finite & isfinite(F) & isfinite(M)
            # The least scale, as the kinematics' floors: every body's weight and the inertia
            # force of its mass at the state's scale of acceleration (every force may be 0).
            scales = state.scales
            gravity = magnitude(self.gravity)
            for mass in self.masses.values():
                scale = biggest(scale, mass.mass * (gravity + scales['acceleration'])
                                + mass.inertia * scales['angular acceleration'] / self.size)
            for load in self.loads:
                if load.force is not None or load.table is not None:
                    scale = biggest(scale, load.largest)
                else:
                    scale = biggest(scale, abs(load.torque or 0.0) / self.size)
            if kin.vector:
                overflow = valid & ~np.asarray(finite, dtype=bool)
                if np.any(overflow):
                    failures['forces (overflow)'] = overflow
                    valid = valid & ~overflow
            elif not finite:
                failures['forces (overflow)'] = True
                valid = False
            for group in self.groups:
                solved, ok = self._solve(group, kin, inertial, done, None if pivots is None
                                         else pivots.setdefault(group.key, []))
                if ok is not True:
                    bad = valid & ~np.asarray(ok, dtype=bool) if kin.vector else not ok
                    if np.any(bad):
                        failures.setdefault(f'{group.key} (statics singular)', bad)
                    valid = valid & ok
                done.update(solved)
            for carried in done.values():
                scale = biggest(scale, magnitude(carried.force))
                scale = biggest(scale, abs(carried.couple) / self.size)
            return self._result(done, kin, scale, valid, failures, max_error)

    def _inertial(self, name: str, kin: _Kinematics) -> tuple[Any, Any, Any, Any]:
        """Return a body's inertia wrench less its loads, about its frame's origin, and bounds.

        ``(F, M, eF, eM)``: ``F = m (a_c - g) - loads``, ``M = I alpha + r x m (a_c - g)
        - their moments``, with ``r`` from the frame's origin to the centre of mass.
        """
        origin, theta, omega, alpha, e = kin.frames[name]
        F: Any = 0j
        M: Any = 0.0
        eF: Any = 0.0
        eM: Any = 0.0
        mass = self.masses.get(name)
        if mass is not None:
            m, com = mass.mass, complex(*mass.com)
            r = com * kin.expi(theta) if com else 0j
            a_o = kin.acceleration(origin)
            spin = 1j * alpha - omega * omega
            a_c = a_o + spin * r
            F = m * (a_c - self.gravity)
            M = mass.inertia * alpha + _cross(r, F)
            e_theta, e_omega, e_alpha = e
            a_com, a_spin = magnitude(com), magnitude(spin)
            e_r = a_com * (e_theta + 4 * U)
            e_spin = e_alpha + 2 * abs(omega) * e_omega + 2 * U * a_spin
            e_ac = (kin.acceleration_bound(origin) + e_spin * a_com + a_spin * e_r
                    + 4 * U * magnitude(a_c))
            a_F = magnitude(F)
            eF = m * e_ac + 2 * U * a_F
            eM = (mass.inertia * (e_alpha + U * abs(alpha)) + e_r * a_F + a_com * eF
                  + 4 * U * (abs(M) + a_com * a_F))
        for load in self.point_loads.get(name, ()):
            e_force: Any = 0.0
            if load.table is None:
                force = complex(*load.force)  # type: ignore[misc]
            else:   # where its joint stands: the position's error times the slope
                joint = load.table[0]
                force, slope = load.force_at(kin.joint_position(joint))
                e_force = slope * kin.joint_position_bound(joint) + 4 * U * magnitude(force)
            point = load.point
            if point is None:   # at a point of the body's frame, turned with it (a com's way)
                at = complex(*load.at)  # type: ignore[misc]
                d = at * kin.expi(theta)
                a_d = magnitude(d)
                e_d = magnitude(at) * (e[0] + 4 * U)
            else:
                d = kin.position(point) - kin.position(origin)
                a_d = magnitude(d)
                e_d = kin.position_bound(point) + kin.position_bound(origin) + U * a_d
            F = F - force
            M = M - _cross(d, force)
            a_force = magnitude(force)
            eF = eF + U * (magnitude(F) + a_force) + e_force
            eM = eM + e_d * a_force + 3 * U * (a_d * a_force + abs(M)) + a_d * e_force
        for load in self.torque_loads.get(name, ()):
            M = M - float(load.torque)  # type: ignore[arg-type]
            eM = eM + U * abs(M)
        return F, M, eF, eM

    def _solve(self, group: _Group, kin: _Kinematics,
               inertial: Mapping[str, tuple[Any, Any, Any, Any]],
               done: Mapping[str, _Carried],
               pivots: list[tuple[int, ...]] | None = None) -> tuple[dict[str, _Carried], Any]:
        """Return what the group's joints carry, and where it could be bounded."""
        if len(group.configs) == 1:
            config = next(iter(group.configs.values()))
            return self._solve_config(group, config, kin, inertial, done, pivots)
        engaged = kin.engaged(group.levers[0])
        if not kin.vector:     # one instant: one phase
            return self._solve_config(group, group.configs[(bool(engaged),)], kin, inertial,
                                      done, pivots)
        on, ok_on = self._solve_config(group, group.configs[(True,)], kin, inertial, done)
        off, ok_off = self._solve_config(group, group.configs[(False,)], kin, inertial, done)
        engaged = np.asarray(engaged, dtype=bool)
        merged = {name: _Carried.where(engaged, on[name], off[name]) for name in on}
        return merged, np.where(engaged, ok_on, ok_off)

    def _solve_config(self, group: _Group, config: _Config, kin: _Kinematics,
                      inertial: Mapping[str, tuple[Any, Any, Any, Any]],
                      done: Mapping[str, _Carried],
                      pivots: list[tuple[int, ...]] | None = None
                      ) -> tuple[dict[str, _Carried], Any]:
        k = len(config.rows)
        row_of = {row: index for index, row in enumerate(config.rows)}
        index_of = {body: b for b, body in enumerate(group.bodies)}
        A: list[list[Any]] = [[_ZERO] * k for _ in range(k)]
        EA: list[list[Any]] = [[0.0] * k for _ in range(k)]
        b: list[Any] = [0.0] * k
        Eb: list[Any] = [0.0] * k
        arms: dict[tuple[str, str], tuple[Any, Any]] = {}

        def arm(at: str, body: str) -> tuple[Any, Any]:
            """Return the vector from a body's frame origin to a point, with its bound."""
            key = (at, body)
            if key not in arms:
                origin = kin.frames[body][0]
                if at == origin:
                    arms[key] = None, 0.0
                else:
                    d = kin.position(at) - kin.position(origin)
                    arms[key] = d, (kin.position_bound(at) + kin.position_bound(origin)
                                    + U * magnitude(d))
            return arms[key]

        def put(body: str, sign: float, column: int, unit: Any, e_unit: Any,
                at: str | None) -> None:
            """Add a unit force ``unit`` at point ``at`` (or a unit couple: ``at`` None)."""
            bi = index_of.get(body)
            if bi is None:
                return
            moment = row_of.get((bi, 2))
            if at is None:
                if moment is not None:
                    A[moment][column] += sign
                return
            fx, fy = row_of[(bi, 0)], row_of[(bi, 1)]
            A[fx][column] += sign * unit.real
            A[fy][column] += sign * unit.imag
            if e_unit is not _EXACT:
                EA[fx][column] += e_unit
                EA[fy][column] += e_unit
            if moment is not None:
                d, e_d = arm(at, body)
                if d is not None:
                    A[moment][column] += sign * _cross(d, unit)
                    EA[moment][column] += magnitude(d) * (e_unit + 3 * U) + e_d

        units = []
        for column, (i, component) in enumerate(config.columns):
            joint = group.joints[i]
            unit, e_unit, at = _unit(joint, component, kin)
            units.append((unit, e_unit, at))
            put(joint.body, 1.0, column, unit, e_unit, at)
            put(joint.on, -1.0, column, unit, e_unit, at)
        # The right-hand side: the bodies' inertia wrenches, less their loads, plus what the
        # joints already solved (later groups') put on them.
        for (bi, component), row in row_of.items():
            F, M, eF, eM = inertial[group.bodies[bi]]
            if component == 0:
                b[row], Eb[row] = F.real, eF
            elif component == 1:
                b[row], Eb[row] = F.imag, eF
            else:
                b[row], Eb[row] = M, eM
        for carried in done.values():
            joint = carried.joint
            bi = index_of.get(joint.on)
            if bi is None:
                continue
            force = carried.force
            a_force = magnitude(force)
            e_force = carried.force_bound + U * a_force
            fx, fy = row_of[(bi, 0)], row_of[(bi, 1)]
            b[fx] = b[fx] + force.real
            b[fy] = b[fy] + force.imag
            Eb[fx] = Eb[fx] + e_force
            Eb[fy] = Eb[fy] + e_force
            moment = row_of.get((bi, 2))
            if moment is not None:
                d, e_d = arm(joint.at, joint.on)
                if d is None:
                    d = 0j
                turn = _cross(d, force) + carried.couple
                b[moment] = b[moment] + turn
                a_d = magnitude(d)
                Eb[moment] = Eb[moment] + (a_d * carried.force_bound + e_d * a_force
                                           + carried.couple_bound
                                           + 4 * U * (a_d * a_force + abs(turn)))
        x, e_x, ok = _bounded_solve(A, EA, b, Eb, kin.vector, kin.biggest, pivots)
        carried_by: dict[str, _Carried] = {}
        acting = set(config.joints)
        for i, joint in enumerate(group.joints):
            if i not in acting:
                carried_by[joint.name] = _Carried.idle(joint)
                continue
            force: Any = 0j
            e_force: Any = 0.0
            couple: Any = 0.0
            e_couple: Any = 0.0
            parts: dict[str, tuple[Any, Any]] = {}
            for column, (j, component) in enumerate(config.columns):
                if j != i:
                    continue
                value, bound = x[column], e_x[column]
                parts[component] = (value, bound)
                unit, e_unit, at = units[column]
                if at is None:
                    couple = couple + value
                    e_couple = e_couple + bound + U * abs(couple)
                else:
                    force = force + value * unit
                    e_force = e_force + bound + abs(value) * e_unit + 2 * U * magnitude(force)
            carried_by[joint.name] = _Carried(joint, force, e_force, couple, e_couple, parts)
        return carried_by, ok

    def _result(self, done: Mapping[str, _Carried], kin: _Kinematics, scale: Any, valid: Any,
                failures: dict[str, Any], max_error: float) -> Forces:
        graph = self.graph
        efforts: dict[str, Any] = {}
        effort_bounds: dict[str, Any] = {}
        reactions: dict[str, Reaction] = {}
        shaking: Any = 0j
        e_shaking: Any = 0.0
        moment: Any = 0.0
        e_moment: Any = 0.0
        force_limit = max_error * kin.biggest(scale, _TINY)
        moment_limit = force_limit * self.size
        untrusted: Any = False
        worst: list[tuple[float, str, float, float]] = []

        def judge(name: str, bound: Any, limit: Any) -> Any:
            bad = np.logical_not(bound <= limit) if kin.vector else not bound <= limit
            if not kin.vector and bad and valid:    # the worst of an instant otherwise sound
                ratio = float(bound) / float(limit) if float(limit) > 0 else math.inf
                worst.append((ratio, name, float(bound), float(limit)))
            return bad

        for joint in graph.joints:
            carried = done.get(joint.name)
            if carried is None:
                continue
            parts = carried.parts
            if joint.driver:
                value, bound = parts.get('effort', (0.0, 0.0))
                efforts[joint.name], effort_bounds[joint.name] = value, bound
                limit = force_limit if joint.line is not None else moment_limit
                untrusted = untrusted | judge(f'efforts.{joint.name}', bound, limit)
            if joint.type.table is None:    # a lock: its holding moment
                value, bound = parts.get('moment', (0.0, 0.0))
                reaction = Reaction(joint.at, joint.body, joint.on, moment=value,
                                    moment_bound=bound)
                untrusted = untrusted | judge(f'reactions.{joint.name}.moment', bound,
                                              moment_limit)
            elif joint.line is None:
                (fx, e_fx), (fy, e_fy) = parts.get('x', (0.0, 0.0)), parts.get('y', (0.0, 0.0))
                bound = e_fx + e_fy
                reaction = Reaction(joint.at, joint.body, joint.on, force=fx + 1j * fy,
                                    force_bound=bound)
                untrusted = untrusted | judge(f'reactions.{joint.name}.force', bound,
                                              force_limit)
            else:
                normal, e_normal = parts.get('normal', (0.0, 0.0))
                couple, e_couple = parts.get('moment', (0.0, 0.0))
                reaction = Reaction(joint.at, joint.body, joint.on, normal=normal,
                                    moment=couple, normal_bound=e_normal, moment_bound=e_couple)
                untrusted = (untrusted
                             | judge(f'reactions.{joint.name}.normal', e_normal, force_limit)
                             | judge(f'reactions.{joint.name}.moment', e_couple, moment_limit))
            reactions[joint.name] = reaction
            if joint.on == graph.ground:
                at = kin.position(joint.at)
                force = carried.force
                shaking = shaking - force
                e_shaking = e_shaking + carried.force_bound + U * magnitude(shaking)
                turn = _cross(at, force) + carried.couple
                moment = moment - turn
                a_at, a_force = magnitude(at), magnitude(force)
                e_moment = e_moment + (a_at * carried.force_bound
                                       + kin.position_bound(joint.at) * a_force
                                       + carried.couple_bound
                                       + 4 * U * (a_at * a_force + abs(moment)))
        untrusted = (untrusted | judge('shaking.force', e_shaking, force_limit)
                     | judge('shaking.moment', e_moment, moment_limit))
        if kin.vector:
            untrusted = untrusted & np.asarray(valid, dtype=bool)
            if np.any(untrusted):
                failures['forces (untrusted)'] = untrusted
            valid = np.asarray(valid, dtype=bool) & ~untrusted
            shape = kin.shape
            efforts = _broadcast(efforts, shape)
        else:
            valid = bool(valid) and not bool(untrusted)
        return Forces(efforts, reactions, shaking, moment, effort_bounds,
                      (e_shaking, e_moment), valid, scale, failures,
                      max(worst)[1:] if worst else None)


#: The least scale a force is judged on (the smallest normal double), N.
_TINY = float(np.finfo(np.float64).tiny)
#: A unit vector known exactly (a pin's x or y direction): no bound to add.
_EXACT = 0.0
#: A structural zero of a statics matrix (this object, not any 0.0): skipped by the solve.
_ZERO = float('0')


def _cross(a: Any, b: Any) -> Any:
    """Return the z component of the cross product of two vectors given as complex numbers."""
    return a.real * b.imag - a.imag * b.real


def _unit(joint: Joint, component: str, kin: _Kinematics) -> tuple[Any, Any, str | None]:
    """Return the unit force (complex, its bound, its point) of one unknown; None: a couple."""
    if component == 'x':
        return 1.0 + 0j, _EXACT, joint.at
    if component == 'y':
        return 1j, _EXACT, joint.at
    if component == 'moment' or (component == 'effort' and joint.line is None):
        return 0j, _EXACT, None
    line = joint.line
    assert line is not None
    if joint.copies > 1:   # one of several slots: the one its point is in, from the line's point
        d = kin.position(joint.at) - kin.position(line.through)
        length = magnitude(d)
        u = d / length
        e_u = (kin.position_bound(joint.at) + kin.position_bound(line.through)) * 2 / length \
            + 4 * U
    else:
        angle, e_angle = kin.line_angle(line)
        u = kin.expi(angle)
        e_u = e_angle + 2 * U
    return (1j * u if component == 'normal' else u), e_u, joint.at


def _bounded_solve(A: list[list[Any]], EA: list[list[Any]], b: list[Any], Eb: list[Any],
                   vector: bool, biggest: Callable[[Any, Any], Any],
                   pivots: list[tuple[int, ...]] | None = None
                   ) -> tuple[list[Any], list[Any], Any]:
    """Return ``x`` solving ``A x = b``, a bound of its error, and where the bound holds.

    Gauss-Jordan elimination with partial pivoting, on the entries as they
    are (floats for one instant, arrays for many: the same operations), gives
    ``x`` and the inverse ``X``. The bound, to first order as the kinematics'
    are: ``|X| t`` with ``t`` the computed residual ``|b - A x|``, its
    rounding, and the entries' errors ``EA |x| + Eb``. Where ``A`` is within
    rounding of singular (its condition number beyond ``1 / (64 k U)``: a
    toggle, where the statics degenerate), there is no bound. For one
    instant, ``pivots`` (a list) receives, at each step, the row offsets that
    led the search for the largest pivot, the last picked (a function written
    out from an instant holds those tests: :meth:`Dynamics._write`).
    """
    k = len(b)
    # The augmented matrix [A | I]; structural zeros stay _ZERO and are skipped.
    M = [list(row) + [1.0 if c == r else _ZERO for c in range(k)] for r, row in enumerate(A)]
    ok: Any = True
    for j in range(k):
        candidates = [M[r][j] for r in range(j, k)]
        if vector:
            stacked = np.abs(np.broadcast_arrays(*candidates))
            best = np.argmax(stacked, axis=0)
            if np.any(best):
                rows = M[j:]
                picked = [np.choose(best, [row[c] for row in rows]) for c in range(2 * k)]
                for offset in range(1, k - j):
                    mine = best == offset
                    if np.any(mine):
                        M[j + offset] = [np.where(mine, M[j][c], M[j + offset][c])
                                         for c in range(2 * k)]
                M[j] = picked
            pivot = M[j][j]
            ok = ok & (np.abs(pivot) > 0.0)
        else:
            # The first largest magnitude (as max() picks it); each row that led on the
            # way is recorded: the tests a function written out from here makes.
            sizes = [abs(c) for c in candidates]
            best, led = 0, [0]
            for r in range(1, k - j):
                if sizes[r] > sizes[best]:
                    best = r
                    led.append(r)
            if pivots is not None:
                pivots.append(tuple(led))
            if best:
                M[j], M[j + best] = M[j + best], M[j]
            pivot = M[j][j]
            if pivot == 0.0:
                return [math.nan] * k, [math.inf] * k, False
        with np.errstate(all='ignore'):
            inverse = 1.0 / pivot
            row = [v if v is _ZERO else v * inverse for v in M[j]]
            row[j] = 1.0
            M[j] = row
            for r in range(k):
                factor = M[r][j]
                if r == j or factor is _ZERO:
                    continue
                target = M[r]
                M[r] = [t if v is _ZERO else t - factor * v
                        for t, v in zip(target, row, strict=True)]
                M[r][j] = _ZERO
    X = [row[k:] for row in M]
    with np.errstate(all='ignore'):
        x = [sum([v * w for v, w in zip(row, b, strict=True)]) for row in X]
        t = []
        a_norm: Any = 0.0
        for r, row in enumerate(A):
            entries = [(v, c) for c, v in enumerate(row) if v is not _ZERO]
            products = [v * x[c] for v, c in entries]
            residual = b[r] - sum(products)
            size = sum([abs(p) for p in products]) + abs(b[r])
            a_norm = biggest(a_norm, sum([abs(v) for v, _ in entries]))
            error = sum([EA[r][c] * abs(x[c]) for _, c in entries]) + Eb[r]
            t.append(abs(residual) + _gamma(k + 1) * size + error)
        x_norm: Any = 0.0
        e_x = []
        for row in X:
            magnitudes = [abs(v) for v in row]
            x_norm = biggest(x_norm, sum(magnitudes))
            e_x.append(sum([v * w for v, w in zip(magnitudes, t, strict=True)]))
        condition = a_norm * x_norm
        ok = ok & (condition * (64 * k * U) < 1.0)
        # First order, as the kinematics: the inverse's own rounding scales the bound by
        # at most 1 / (1 - k U cond), under 1 + 1/63 where it is answered.
        grow = 1.0 / (1.0 - k * U * condition) if not vector else np.where(
            ok, 1.0 / (1.0 - k * U * condition), np.inf)
        e_x = [e * grow for e in e_x]
    if not vector:
        ok = bool(ok) and all(_finite(v) for v in (*x, *e_x))
        if not ok:
            e_x = [math.inf] * k
    else:
        ok = np.asarray(ok, dtype=bool)
        for value in (*x, *e_x):
            ok = ok & np.isfinite(value)
        e_x = [np.where(ok, e, np.inf) for e in e_x]
    return x, e_x, ok


class _Subset:
    """The instants ``index`` of an array state: what the forces read of it (one or an array)."""

    def __init__(self, state: Any, index: Any) -> None:
        size = np.shape(state.valid)

        def take(value: Any) -> Any:
            if isinstance(value, np.ndarray) and value.shape == size:
                return value[index]
            return value

        def motion(m: Any) -> SimpleNamespace:
            return SimpleNamespace(position=take(m.position), velocity=take(m.velocity),
                                   acceleration=take(m.acceleration))

        valid = take(np.asarray(state.valid, dtype=bool))
        self.valid = bool(valid) if np.ndim(valid) == 0 else valid
        self.complex_points = {name: tuple(take(v) for v in values)
                               for name, values in state.complex_points.items()}
        bounds = state.error_bound
        self.error_bound = SimpleNamespace(
            points={name: motion(b) for name, b in bounds.points.items()},
            joints={name: motion(b) for name, b in bounds.joints.items()})
        self.joints = {name: motion(m) for name, m in state.joints.items()}
        self.scales = {name: take(v) for name, v in state.scales.items()}
        self.intermittent = {name: SimpleNamespace(driven=take(e.driven))
                             for name, e in state.intermittent.items()}


def _merge(forces: Forces, redo: Any, part: Forces) -> Forces:
    """Return ``forces`` with the instants ``redo`` replaced by ``part``'s (arrays)."""
    shape = redo.shape

    def put(whole: Any, some: Any) -> Any:
        if whole is None:
            return None
        out = np.array(np.broadcast_to(whole, shape), dtype=np.result_type(whole, some))
        out[redo] = some
        return out

    reactions = {}
    for name, r in forces.reactions.items():
        p = part.reactions[name]
        reactions[name] = Reaction(r.at, r.on, r.by, put(r.force, p.force),
                                   put(r.normal, p.normal), put(r.moment, p.moment),
                                   put(r.force_bound, p.force_bound),
                                   put(r.normal_bound, p.normal_bound),
                                   put(r.moment_bound, p.moment_bound))
    failures = dict(forces.failures)
    for reason, mask in part.failures.items():
        full = np.zeros(shape, dtype=bool)
        full[redo] = mask
        failures[reason] = failures[reason] | full if reason in failures else full
    return Forces({n: put(v, part.efforts[n]) for n, v in forces.efforts.items()}, reactions,
                  put(forces.shaking_force, part.shaking_force),
                  put(forces.shaking_moment, part.shaking_moment),
                  {n: put(v, part.effort_bounds[n]) for n, v in forces.effort_bounds.items()},
                  (put(forces.shaking_bounds[0], part.shaking_bounds[0]),
                   put(forces.shaking_bounds[1], part.shaking_bounds[1])),
                  put(forces.valid, part.valid), put(forces.scale, part.scale), failures)


def _concatenate(parts: list[Forces]) -> Forces:
    """Return the forces of consecutive blocks of instants as those of the whole array."""
    def join(values: list[Any], shapes: list[Any]) -> Any:
        if values[0] is None:
            return None
        pairs = zip(values, shapes, strict=True)
        return np.concatenate([np.broadcast_to(v, s) for v, s in pairs])

    shapes = [np.shape(p.valid) for p in parts]
    first = parts[0]
    reactions = {}
    for name, r in first.reactions.items():
        fields = {f: join([getattr(p.reactions[name], f) for p in parts], shapes)
                  for f in ('force', 'normal', 'moment', 'force_bound', 'normal_bound',
                            'moment_bound')}
        reactions[name] = Reaction(r.at, r.on, r.by, **fields)
    failures = {}
    for reason in dict.fromkeys(k for p in parts for k in p.failures):
        failures[reason] = join([p.failures.get(reason, np.zeros(s, dtype=bool))
                                 for p, s in zip(parts, shapes, strict=True)], shapes)
    return Forces({n: join([p.efforts[n] for p in parts], shapes) for n in first.efforts},
                  reactions, join([p.shaking_force for p in parts], shapes),
                  join([p.shaking_moment for p in parts], shapes),
                  {n: join([p.effort_bounds[n] for p in parts], shapes)
                   for n in first.effort_bounds},
                  (join([p.shaking_bounds[0] for p in parts], shapes),
                   join([p.shaking_bounds[1] for p in parts], shapes)),
                  join([p.valid for p in parts], shapes), join([p.scale for p in parts], shapes),
                  failures)


@dataclass(frozen=True)
class _Carried:
    """What one solved joint puts on its child body: a force at its point and a couple."""

    joint: Joint
    force: Any
    force_bound: Any
    couple: Any
    couple_bound: Any
    parts: dict[str, tuple[Any, Any]]

    @classmethod
    def idle(cls, joint: Joint) -> _Carried:
        """Return a joint that carries nothing (an intermittent joint out of action)."""
        parts = {c: (0.0, 0.0) for c in _components(joint)}
        return cls(joint, 0j, 0.0, 0.0, 0.0, parts)

    @classmethod
    def where(cls, mask: Any, a: _Carried, b: _Carried) -> _Carried:
        """Return ``a`` where ``mask`` holds, else ``b`` (one joint, two phases)."""
        parts = {c: (np.where(mask, a.parts[c][0], b.parts[c][0]),
                     np.where(mask, a.parts[c][1], b.parts[c][1])) for c in a.parts}
        return cls(a.joint, np.where(mask, a.force, b.force),
                   np.where(mask, a.force_bound, b.force_bound),
                   np.where(mask, a.couple, b.couple),
                   np.where(mask, a.couple_bound, b.couple_bound), parts)


class _Kinematics:
    """What the forces read of a solved state: points, frames, lines, with their bounds.

    Floats for one instant, arrays for many: the same arithmetic serves both.
    """

    def __init__(self, graph: Graph, state: State) -> None:
        self.state = state
        self.vector = not isinstance(state.valid, (bool, np.bool_))
        self.shape: tuple[int, ...] = np.shape(state.valid) if self.vector else ()
        if state.__class__ is _Recorded:    # a run written out (Dynamics._write): recorded
            recorder = cast(_Recorded, state).recorder
            self.biggest, self.expi = recorder.function('biggest'), recorder.function('expi')
        else:
            self.biggest = np.fmax if self.vector else max
            self.expi = _expi_array if self.vector else _expi
        self.points = state.complex_points
        bounds = state.error_bound
        self.point_bounds = bounds.points
        self.joint_bounds = bounds.joints
        self.frames: dict[str, tuple[str, Any, Any, Any, tuple[Any, Any, Any]]] = {}
        for name, body in graph.bodies.items():
            frame = body.frame
            if frame is None:
                continue
            if frame.angle_of is None:
                self.frames[name] = (frame.origin, frame.angle, 0.0, 0.0,
                                     (U * abs(frame.angle), 0.0, 0.0))
                continue
            joint = state.joints[frame.angle_of]
            b = self.joint_bounds[frame.angle_of]
            self.frames[name] = (frame.origin, joint.position + frame.angle, joint.velocity,
                                 joint.acceleration, (b.position, b.velocity, b.acceleration))

    def position(self, point: str) -> Any:
        return self.points[point][0]

    def joint_position(self, joint: str) -> Any:
        return self.state.joints[joint].position

    def joint_position_bound(self, joint: str) -> Any:
        return self.joint_bounds[joint].position

    def acceleration(self, point: str) -> Any:
        return self.points[point][2]

    def position_bound(self, point: str) -> Any:
        return self.point_bounds[point].position

    def acceleration_bound(self, point: str) -> Any:
        return self.point_bounds[point].acceleration

    def line_angle(self, line: Any) -> tuple[Any, Any]:
        """Return a line's direction in the ground frame and its bound, rad."""
        if line.angle_of is None:
            return line.angle, U * abs(line.angle)
        joint = self.state.joints[line.angle_of]
        bound = self.joint_bounds[line.angle_of].position
        return joint.position + line.angle, bound + U * abs(line.angle)

    def engaged(self, lever: str) -> Any:
        """Return whether an intermittent drive acts (else its lock), on the side answered.

        ``Engagement.driven``: at an engagement instant the side the kinematics
        answer (the lock holds at a mouth the pin leaves turning forward).
        """
        return self.state.intermittent[lever].driven


def _broadcast(efforts: dict[str, Any], shape: tuple[int, ...]) -> dict[str, Any]:
    """Return an array's efforts each in the array's shape (a constant effort too)."""
    return {name: np.broadcast_to(value, shape) for name, value in efforts.items()}


def _finite(z: Any) -> Any:
    """Return whether a float or complex of one instant is finite (in its own arithmetic)."""
    return z - z == 0


#: The functions the forces call by another name on arrays (np.fmax is max without NaN).
_FUNCTIONS: dict[str, tuple[Callable[..., Any], Callable[..., Any], str | None]] = {}


def _expi(angle: float) -> complex:
    return complex(math.cos(angle), math.sin(angle))


def _expi_array(angle: Any) -> Any:
    return np.cos(angle) + 1j * np.sin(angle)


_FUNCTIONS.update(biggest=(max, np.fmax, '{1} if {1} > {0} else {0}'),
                  expi=(_expi, _expi_array, 'complex(cos({0}), sin({0}))'))


class _Recorded:
    """A state read through a :class:`.recording.Recorder` (one instant: its ``valid`` is True)."""

    valid = True

    def __init__(self, recorder: Recorder, state: Any) -> None:
        self.recorder = recorder
        self._state = recorder.reader('state', state)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._state, name)
