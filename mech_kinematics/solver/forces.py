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

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
import math
from typing import Any, TYPE_CHECKING

import numpy as np

from .graph import Graph, Joint
from .model import _check_finite, _check_name
from ..bounds import U
from ..errors import SceneError

if TYPE_CHECKING:
    from .state import State

__all__ = ['Dynamics', 'Forces', 'Load', 'Mass', 'Reaction']

#: Rounding of one correctly rounded operation, as a multiple of |result| (NumPy's
#: products and sums of a few terms: gamma_k = k U / (1 - k U) for k operations).
_GAMMA = 2.0 * U


def _gamma(k: int) -> float:
    return k * U / (1.0 - k * U)


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
        com = tuple(self.com)
        if len(com) != 2:
            msg = f'Expected the centre of mass of "{self.body}" as [x, y], got {self.com!r}'
            raise SceneError(msg, (self, 'com'))
        for value in com:
            _check_finite(value, f'the centre of mass of "{self.body}"', (self, 'com'))
        object.__setattr__(self, 'com', (float(com[0]), float(com[1])))
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
        The point a force acts at (on the body it was placed on).
    force : (float, float) or None
        N, in the scene's frame.
    link : str or None
        The body a torque acts on.
    torque : float or None
        N m about z, + CCW.
    """

    name: str
    point: str | None = None
    force: tuple[float, float] | None = None
    link: str | None = None
    torque: float | None = None

    def __post_init__(self) -> None:
        """Validate the fields: a force at a point, or a torque on a link, not both."""
        _check_name(self.name, 'a load name', (self, 'name'))
        at_point = self.point is not None or self.force is not None
        on_link = self.link is not None or self.torque is not None
        if at_point == on_link or (at_point and (self.point is None or self.force is None)) \
                or (on_link and (self.link is None or self.torque is None)):
            msg = (f'Expected load "{self.name}" to be {{point, force}} or {{link, torque}}, '
                   f'got point={self.point!r}, force={self.force!r}, link={self.link!r}, '
                   f'torque={self.torque!r}')
            raise SceneError(msg, (self, 'name'))
        if self.force is not None:
            force = tuple(self.force)
            if len(force) != 2:
                msg = f'Expected the force of load "{self.name}" as [fx, fy], got {self.force!r}'
                raise SceneError(msg, (self, 'force'))
            for value in force:
                _check_finite(value, f'the force of load "{self.name}"', (self, 'force'))
            object.__setattr__(self, 'force', (float(force[0]), float(force[1])))
        if self.torque is not None:
            _check_finite(self.torque, f'the torque of load "{self.name}"', (self, 'torque'))


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
        on an unknown point or body, or a part of the mechanism whose joint
        reactions statics cannot determine.
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
        owner = {}
        for name, body in graph.bodies.items():
            for point in body.points:
                owner.setdefault(point, name)
        self.loads = tuple(loads)
        self.point_loads: dict[str, list[Load]] = {}
        self.torque_loads: dict[str, list[Load]] = {}
        names: set[str] = set()
        for load in self.loads:
            if load.name in names:
                msg = f'Expected each load name once, got "{load.name}" twice'
                raise SceneError(msg, (load, 'name'))
            names.add(load.name)
            if load.point is not None:
                body = owner.get(load.point)
                if load.point not in points or body is None:
                    msg = f'Expected a load at a point of the scene, got unknown "{load.point}"'
                    raise SceneError(msg, (load, 'point'))
                if body == graph.ground:
                    msg = (f'Expected load "{load.name}" at a moving point, got "{load.point}", '
                           f'fixed on the ground (a load there moves nothing)')
                    raise SceneError(msg, (load, 'point'))
                self.point_loads.setdefault(body, []).append(load)
            else:
                assert load.link is not None
                if load.link not in graph.bodies or load.link == graph.ground:
                    msg = f'Expected a load on a moving body ({", ".join(moving)}), got ' + (
                        'the ground' if load.link == graph.ground else f'unknown "{load.link}"')
                    raise SceneError(msg, (load, 'link'))
                self.torque_loads.setdefault(load.link, []).append(load)
        self.groups = self._groups()

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
                elif self._moment_given(body):
                    phase = 'engaged' if engaged else 'locked'
                    msg = (f'Expected the statics of {key} to be determined, got {body}, which '
                           f'turns freely about {origin} while {phase} and has a moment to '
                           f'carry (its centre of mass off {origin}, an inertia or a load): '
                           f'give it no mass there')
                    raise SceneError(msg)
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

    def _moment_given(self, body: str) -> bool:
        mass = self.masses.get(body)
        if mass is not None and (mass.inertia or mass.com != (0.0, 0.0)):
            return True
        if self.torque_loads.get(body):
            return True
        origin = self.graph.bodies[body].frame.origin  # type: ignore[union-attr]
        return any(load.point != origin for load in self.point_loads.get(body, ()))

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
        return joints, points

    # --- at a solved state -----------------------------------------------------------

    def forces(self, state: State, max_error: float) -> Forces:
        """Return the forces at a solved state (one instant or an array), bounded.

        ``max_error`` is the tolerance: a value whose bound exceeds it times
        the force scale (moments: times the scale and the mechanism's size)
        makes the instant invalid (``Forces.valid``, ``Forces.failures``).
        """
        kin = _Kinematics(self.graph, state)
        shape = kin.shape
        done: dict[str, _Carried] = {}   # joint -> what it carries, solved
        scale = np.zeros(shape)
        valid = np.ones(shape, dtype=bool)
        failures: dict[str, Any] = {}
        inertial = {name: self._inertial(name, kin) for name in kin.frames}
        for F, _, _, _ in inertial.values():
            scale = np.fmax(scale, np.abs(F))
        for load in self.loads:
            if load.force is not None:
                scale = np.fmax(scale, abs(complex(*load.force)))
            else:
                scale = np.fmax(scale, abs(load.torque or 0.0) / self.size)
        for group in self.groups:
            solved, ok = self._solve(group, kin, inertial, done)
            if not np.all(ok):
                failures[f'{group.key} (statics singular)'] = ~ok
                valid &= ok
            done.update(solved)
        for carried in done.values():
            scale = np.fmax(scale, np.abs(carried.force))
            scale = np.fmax(scale, np.abs(carried.couple) / self.size)
        return self._result(done, kin, scale, valid, failures, max_error)

    def _inertial(self, name: str, kin: _Kinematics) -> tuple[Any, Any, Any, Any]:
        """Return a body's inertia wrench less its loads, about its frame's origin, and bounds.

        ``(F, M, eF, eM)``: ``F = m (a_c - g) - loads``, ``M = I alpha + r x m (a_c - g)
        - their moments``, with ``r`` from the frame's origin to the centre of mass.
        """
        origin, theta, omega, alpha, e = kin.frames[name]
        zero = np.zeros(kin.shape)
        F, M, eF, eM = zero + 0j, zero, zero, zero
        mass = self.masses.get(name)
        if mass is not None:
            m, com = mass.mass, complex(*mass.com)
            turn = np.exp(1j * theta) if kin.vector or theta else 1.0 + 0j
            r = com * turn
            a_o = kin.acceleration(origin)
            spin = 1j * alpha - omega * omega
            a_c = a_o + spin * r
            F = m * (a_c - self.gravity)
            M = mass.inertia * alpha + _cross(r, F)
            e_theta, e_omega, e_alpha = e
            e_r = abs(com) * (e_theta + 4 * U)
            e_spin = e_alpha + 2 * np.abs(omega) * e_omega + 2 * U * np.abs(spin)
            e_ac = (kin.acceleration_bound(origin) + e_spin * abs(com)
                    + np.abs(spin) * e_r + 4 * U * np.abs(a_c))
            eF = m * e_ac + 2 * U * np.abs(F)
            eM = (mass.inertia * (e_alpha + U * np.abs(alpha)) + e_r * np.abs(F)
                  + abs(com) * eF + 4 * U * (np.abs(M) + abs(com) * np.abs(F)))
        for load in self.point_loads.get(name, ()):
            force = complex(*load.force)  # type: ignore[misc]
            d = kin.position(load.point) - kin.position(origin)  # type: ignore[arg-type]
            F = F - force
            M = M - _cross(d, force)
            e_d = (kin.position_bound(load.point) + kin.position_bound(origin)  # type: ignore
                   + U * np.abs(d))
            eF = eF + U * (np.abs(F) + abs(force))
            eM = eM + e_d * abs(force) + 3 * U * (np.abs(d) * abs(force) + np.abs(M))
        for load in self.torque_loads.get(name, ()):
            M = M - float(load.torque)  # type: ignore[arg-type]
            eM = eM + U * np.abs(M)
        return F, M, eF, eM

    def _solve(self, group: _Group, kin: _Kinematics,
               inertial: Mapping[str, tuple[Any, Any, Any, Any]],
               done: Mapping[str, _Carried]) -> tuple[dict[str, _Carried], Any]:
        """Return what the group's joints carry, and where it could be bounded."""
        results: dict[tuple[bool, ...], tuple[dict[str, _Carried], Any]] = {}
        for phase, config in group.configs.items():
            results[phase] = self._solve_config(group, config, kin, inertial, done)
        if len(results) == 1:
            return next(iter(results.values()))
        engaged = np.asarray(kin.engaged(group.levers[0]), dtype=bool)
        (on, ok_on), (off, ok_off) = results[(True,)], results[(False,)]
        merged = {name: _Carried.where(engaged, on[name], off[name]) for name in on}
        return merged, np.where(engaged, ok_on, ok_off)

    def _solve_config(self, group: _Group, config: _Config, kin: _Kinematics,
                      inertial: Mapping[str, tuple[Any, Any, Any, Any]],
                      done: Mapping[str, _Carried]) -> tuple[dict[str, _Carried], Any]:
        shape = kin.shape
        k = len(config.rows)
        row_of = {row: index for index, row in enumerate(config.rows)}
        index_of = {body: b for b, body in enumerate(group.bodies)}
        A = np.zeros((*shape, k, k))
        EA = np.zeros((*shape, k, k))
        b = np.zeros((*shape, k))
        Eb = np.zeros((*shape, k))
        origins = {body: kin.frames[body][0] for body in group.bodies}

        def put(body: str, column: int, unit: Any, e_unit: Any, at: str | None) -> None:
            """Add a unit force ``unit`` at point ``at`` (or a unit couple: ``at`` None)."""
            sign = 1.0
            if body.startswith('-'):
                body, sign = body[1:], -1.0
            if body not in index_of:
                return
            bi = index_of[body]
            if at is None:
                if (bi, 2) in row_of:
                    A[..., row_of[(bi, 2)], column] += sign
                return
            A[..., row_of[(bi, 0)], column] += sign * np.real(unit)
            A[..., row_of[(bi, 1)], column] += sign * np.imag(unit)
            EA[..., row_of[(bi, 0)], column] += e_unit
            EA[..., row_of[(bi, 1)], column] += e_unit
            if (bi, 2) in row_of:
                origin = origins[body]
                d = kin.position(at) - kin.position(origin)
                e_d = kin.position_bound(at) + kin.position_bound(origin) + U * np.abs(d)
                A[..., row_of[(bi, 2)], column] += sign * _cross(d, unit)
                EA[..., row_of[(bi, 2)], column] += np.abs(d) * (e_unit + 3 * U) + e_d

        units = {}
        for column, (i, component) in enumerate(config.columns):
            joint = group.joints[i]
            unit, e_unit, at = _unit(joint, component, kin)
            units[column] = (unit, e_unit, at)
            put(joint.body, column, unit, e_unit, at)
            put('-' + joint.on, column, unit, e_unit, at)
        # The right-hand side: the bodies' inertia wrenches, less their loads, plus what the
        # joints already solved (later groups') put on them.
        for (bi, component), row in row_of.items():
            body = group.bodies[bi]
            F, M, eF, eM = inertial[body]
            if component < 2:
                part = np.real(F) if component == 0 else np.imag(F)
                b[..., row] = part
                Eb[..., row] = eF
            else:
                b[..., row] = M
                Eb[..., row] = eM
        for carried in done.values():
            joint = carried.joint
            if joint.on not in index_of:
                continue
            bi = index_of[joint.on]
            origin = origins[joint.on]
            b[..., row_of[(bi, 0)]] += np.real(carried.force)
            b[..., row_of[(bi, 1)]] += np.imag(carried.force)
            Eb[..., row_of[(bi, 0)]] += carried.force_bound + U * np.abs(carried.force)
            Eb[..., row_of[(bi, 1)]] += carried.force_bound + U * np.abs(carried.force)
            if (bi, 2) in row_of:
                d = kin.position(joint.at) - kin.position(origin)
                e_d = (kin.position_bound(joint.at) + kin.position_bound(origin)
                       + U * np.abs(d))
                moment = _cross(d, carried.force) + carried.couple
                b[..., row_of[(bi, 2)]] += moment
                Eb[..., row_of[(bi, 2)]] += (np.abs(d) * carried.force_bound
                                             + e_d * np.abs(carried.force)
                                             + carried.couple_bound + 4 * U * (
                                                 np.abs(d) * np.abs(carried.force)
                                                 + np.abs(moment)))
        x, e_x, ok = _bounded_solve(A, EA, b, Eb)
        carried_by: dict[str, _Carried] = {}
        for i, joint in enumerate(group.joints):
            if i not in config.joints:
                carried_by[joint.name] = _Carried.idle(joint, shape)
                continue
            force = np.zeros(shape) + 0j
            e_force = np.zeros(shape)
            couple = np.zeros(shape)
            e_couple = np.zeros(shape)
            parts: dict[str, tuple[Any, Any]] = {}
            for column, (j, component) in enumerate(config.columns):
                if j != i:
                    continue
                value, bound = x[..., column], e_x[..., column]
                parts[component] = (value, bound)
                unit, e_unit, at = units[column]
                if at is None:
                    couple = couple + value
                    e_couple = e_couple + bound + U * np.abs(couple)
                else:
                    force = force + value * unit
                    e_force = e_force + bound + np.abs(value) * e_unit + 2 * U * np.abs(force)
            carried_by[joint.name] = _Carried(joint, force, e_force, couple, e_couple, parts)
        return carried_by, ok

    def _result(self, done: Mapping[str, _Carried], kin: _Kinematics, scale: Any, valid: Any,
                failures: dict[str, Any], max_error: float) -> Forces:
        graph = self.graph
        efforts: dict[str, Any] = {}
        effort_bounds: dict[str, Any] = {}
        reactions: dict[str, Reaction] = {}
        shaking = np.zeros(kin.shape) + 0j
        e_shaking = np.zeros(kin.shape)
        moment = np.zeros(kin.shape)
        e_moment = np.zeros(kin.shape)
        size = self.size
        force_limit = max_error * np.fmax(scale, np.finfo(float).tiny)
        moment_limit = force_limit * size
        untrusted = np.zeros(kin.shape, dtype=bool)
        worst: list[tuple[float, str, Any, Any]] = []

        def judge(name: str, bound: Any, limit: Any) -> Any:
            bad = ~(bound <= limit)
            if not kin.vector and bool(bad):
                ratio = float(bound) / float(limit) if float(limit) > 0 else math.inf
                worst.append((ratio, name, float(bound), float(limit)))
            return bad

        for joint in graph.joints:
            carried = done.get(joint.name)
            if carried is None:
                continue
            parts = carried.parts
            if joint.driver:
                value, bound = parts.get('effort', (np.zeros(kin.shape), np.zeros(kin.shape)))
                efforts[joint.name], effort_bounds[joint.name] = value, bound
                limit = force_limit if joint.line is not None else moment_limit
                untrusted |= judge(f'efforts.{joint.name}', bound, limit)
            if joint.type.table is None:    # a lock: its holding moment
                reaction = Reaction(joint.at, joint.body, joint.on,
                                    moment=parts.get('moment', (carried.couple,))[0],
                                    moment_bound=parts.get('moment', (0, carried.couple_bound))[1])
                untrusted |= judge(f'reactions.{joint.name}.moment', reaction.moment_bound,
                                   moment_limit)
            elif joint.line is None:
                force = parts['x'][0] + 1j * parts['y'][0] if 'x' in parts else carried.force
                bound = (np.hypot(parts['x'][1], parts['y'][1]) if 'x' in parts
                         else carried.force_bound)
                reaction = Reaction(joint.at, joint.body, joint.on, force=force,
                                    force_bound=bound)
                untrusted |= judge(f'reactions.{joint.name}.force', bound, force_limit)
            else:
                normal, e_normal = parts.get('normal', (np.zeros(kin.shape),) * 2)
                couple, e_couple = parts.get('moment', (np.zeros(kin.shape),) * 2)
                reaction = Reaction(joint.at, joint.body, joint.on, normal=normal,
                                    moment=couple, normal_bound=e_normal, moment_bound=e_couple)
                untrusted |= (judge(f'reactions.{joint.name}.normal', e_normal, force_limit)
                              | judge(f'reactions.{joint.name}.moment', e_couple, moment_limit))
            reactions[joint.name] = reaction
            if joint.on == graph.ground:
                at = kin.position(joint.at)
                shaking = shaking - carried.force
                e_shaking = e_shaking + carried.force_bound + U * np.abs(shaking)
                turn = _cross(at, carried.force) + carried.couple
                moment = moment - turn
                e_moment = e_moment + (np.abs(at) * carried.force_bound
                                       + kin.position_bound(joint.at) * np.abs(carried.force)
                                       + carried.couple_bound
                                       + 4 * U * (np.abs(at) * np.abs(carried.force)
                                                  + np.abs(moment)))
        untrusted |= (judge('shaking.force', e_shaking, force_limit)
                      | judge('shaking.moment', e_moment, moment_limit))
        untrusted &= valid
        if np.any(untrusted):
            failures['forces (untrusted)'] = untrusted
        valid = valid & ~untrusted
        if not kin.vector:
            valid = bool(valid)
        return Forces(efforts, reactions, shaking, moment, effort_bounds,
                      (e_shaking, e_moment), valid, scale, failures,
                      max(worst)[1:] if worst else None)


def _cross(a: Any, b: Any) -> Any:
    """Return the z component of the cross product of two vectors given as complex numbers."""
    return np.real(a) * np.imag(b) - np.imag(a) * np.real(b)


def _unit(joint: Joint, component: str, kin: _Kinematics) -> tuple[Any, Any, str | None]:
    """Return the unit force (complex, its bound, its point) of one unknown; None: a couple."""
    if component == 'x':
        return 1.0 + 0j, 0.0, joint.at
    if component == 'y':
        return 1j, 0.0, joint.at
    if component == 'moment' or (component == 'effort' and joint.line is None):
        return 0j, 0.0, None
    line = joint.line
    assert line is not None
    angle, e_angle = kin.line_angle(line)
    u = np.exp(1j * angle)
    e_u = e_angle + 2 * U
    return (1j * u if component == 'normal' else u), e_u, joint.at


def _bounded_solve(A: Any, EA: Any, b: Any, Eb: Any) -> tuple[Any, Any, Any]:
    """Return ``x`` solving ``A x = b``, a bound of its error, and where the bound holds.

    The bound covers the rounding of the solve and the errors ``EA`` and
    ``Eb`` of the entries (see the module): ``|X| t + |X| |R| 1 ||t|| / (1 -
    rho)``; where ``rho`` (the norm of ``I - A X`` with its rounding and the
    entries' errors) is not below 1/2, the system is too near singular.
    """
    k = A.shape[-1]
    with np.errstate(all='ignore'):
        try:
            X = np.linalg.inv(A)
        except np.linalg.LinAlgError:
            X = np.linalg.pinv(A)
        x = np.einsum('...ij,...j->...i', X, b)
        absA, absX = np.abs(A), np.abs(X)
        residual = b - np.einsum('...ij,...j->...i', A, x)
        products = np.einsum('...ij,...j->...i', absA, np.abs(x))
        t = (np.abs(residual) + _gamma(k + 1) * (products + np.abs(b))
             + np.einsum('...ij,...j->...i', EA, np.abs(x)) + Eb)
        R = np.eye(k) - A @ X
        R_true = np.abs(R) + _gamma(k) * (absA @ absX) + EA @ absX
        rho = R_true.sum(axis=-1).max(axis=-1)
        t_norm = t.max(axis=-1)
        spill = np.einsum('...ij,...j->...i', absX @ R_true, np.ones(k))
        e_x = (np.einsum('...ij,...j->...i', absX, t)
               + spill * (t_norm / (1.0 - rho))[..., None])
        ok = (rho < 0.5) & np.isfinite(e_x).all(axis=-1) & np.isfinite(x).all(axis=-1)
    e_x = np.where(ok[..., None], e_x, np.inf)
    return x, e_x, ok


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
    def idle(cls, joint: Joint, shape: tuple[int, ...]) -> _Carried:
        """Return a joint that carries nothing (an intermittent joint out of action)."""
        zero = np.zeros(shape)
        parts = {c: (zero, zero) for c in _components(joint)}
        return cls(joint, zero + 0j, zero, zero, zero, parts)

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
    """What the forces read of a solved state: points, frames, lines, with their bounds."""

    def __init__(self, graph: Graph, state: State) -> None:
        self.state = state
        self.vector = not isinstance(state.valid, (bool, np.bool_))
        self.shape: tuple[int, ...] = np.shape(state.valid) if self.vector else ()
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
                zero = np.zeros(self.shape)
                self.frames[name] = (frame.origin, frame.angle + zero, zero, zero,
                                     (U * abs(frame.angle) + zero, zero, zero))
                continue
            joint = state.joints[frame.angle_of]
            b = self.joint_bounds[frame.angle_of]
            self.frames[name] = (frame.origin, np.asarray(joint.position) + frame.angle,
                                 np.asarray(joint.velocity), np.asarray(joint.acceleration),
                                 (np.asarray(b.position), np.asarray(b.velocity),
                                  np.asarray(b.acceleration)))

    def position(self, point: str) -> Any:
        return np.asarray(self.points[point][0])

    def acceleration(self, point: str) -> Any:
        return np.asarray(self.points[point][2])

    def position_bound(self, point: str) -> Any:
        return np.asarray(self.point_bounds[point].position)

    def acceleration_bound(self, point: str) -> Any:
        return np.asarray(self.point_bounds[point].acceleration)

    def line_angle(self, line: Any) -> tuple[Any, Any]:
        """Return a line's direction in the ground frame and its bound, rad."""
        if line.angle_of is None:
            return line.angle + np.zeros(self.shape), U * abs(line.angle)
        joint = self.state.joints[line.angle_of]
        bound = self.joint_bounds[line.angle_of].position
        return np.asarray(joint.position) + line.angle, np.asarray(bound) + U * abs(line.angle)

    def engaged(self, lever: str) -> Any:
        return self.state.intermittent[lever].engaged
