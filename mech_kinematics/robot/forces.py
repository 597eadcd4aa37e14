# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Forces of a robot described in URDF: its actuated joints' efforts with its own masses.

A URDF's ``<inertial>`` elements give the scene its loops become its
``masses`` (:func:`~.planar.planar_from_description`: each moving body's mass,
centre of mass and inertia about the loop's normal, welded links added up).
Gravity is given in the URDF's root frame (default :data:`GRAVITY`, REP 103:
z up) and projected exactly into each loop's plane through the pose of the
loop's ground (the part along the loop's normal is carried by the bearings:
it loads no actuator). Each group of loops that sees one gravity in the
scene's frame is solved by one :class:`~mech_kinematics.solver.forces.Dynamics`
(the scene's own inverse dynamics, with its error bounds); a loop's drivers'
efforts come back to the URDF joints through the drivers' map
(:attr:`.planar.DriverMap.gain`): a crank's torque times ``sigma`` (+1 where
the joint's axis is the loop's normal), a cylinder's force times ``kappa``,
a mimic driver's times its multiplier too, on its leader. So each effort is
the generalised force the joint's actuator applies, positive along its
``<axis>``: the sum of effort times joint velocity is the power put in.

What the planar forces cannot carry is left out with the reason
(:class:`ForcesLeftOut`), never guessed: a mass on a link that hangs from a
loop's moving body through a joint outside every loop (its weight loads the
loop's actuators through a motion the loops do not solve), a loop whose
ground moves (its carrying joints given a speed or an acceleration), or whose
ground's pose depends on a joint that is not actuated. Masses on a loop's
ground, or on links nearer the root, load only joints outside every loop,
whose efforts are not computed here. Pure: NumPy only.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
import math
from typing import Any, TYPE_CHECKING
import warnings

import numpy as np

from .description import ClosureKind
from ..errors import MechKinematicsError, NearSingularWarning, UrdfError
from ..solver.forces import Dynamics, Forces, Load, Mass
from ..solver.scaling import _size
from ..solver.solve import refuse_forces

if TYPE_CHECKING:
    from .description import Description
    from .robot import Robot
    from ..solver import State

__all__ = ['ForcesLeftOut', 'GRAVITY', 'JointReaction', 'LinkLoad', 'MAX_GRAVITY', 'MAX_LOAD',
           'EffortSweep', 'RobotEfforts', 'RobotForces', 'SWEEP_SAMPLES', 'check_gravity',
           'effort_sweeps', 'parse_link_loads', 'reaction_maps', 'reaction_names', 'robot_forces',
           'with_payloads']

#: Gravity in the URDF's root frame by default, m/s^2 (REP 103: z up; standard gravity).
GRAVITY = (0.0, 0.0, -9.80665)
#: The largest gravity accepted, m/s^2 (1e5 g: beyond it the forces overflow sooner than
#: any machine's loads make sense).
MAX_GRAVITY = 1e6
#: Dynamics kept per robot (one per group of loops and gravity in their plane).
_CACHE = 16
#: Positions of an actuated joint's range :func:`effort_sweeps` solves, both ends.
SWEEP_SAMPLES = 721
_U = float(np.finfo(np.float64).eps) / 2


#: The largest force (N) or torque (N m) a link load may have: its forces stay far from
#: the doubles' range, as gravity's (:data:`MAX_GRAVITY`) do.
MAX_LOAD = 1e12


@dataclass(frozen=True)
class LinkLoad:
    """A force and a torque on a URDF link, in the URDF's root frame.

    ``force`` (N) acts at ``point`` of the link's frame (m); ``torque`` (N m)
    on the link. In a loop's plane the force's in-plane part acts at that
    point and the torque's part along the plane's normal on the link's body;
    the rest is carried by the bearings (in no effort), as gravity's is.
    """

    link: str
    force: tuple[float, float, float] = (0.0, 0.0, 0.0)
    point: tuple[float, float, float] = (0.0, 0.0, 0.0)
    torque: tuple[float, float, float] = (0.0, 0.0, 0.0)


def _three(text: str) -> tuple[float, float, float] | None:
    try:
        values = tuple(float(v) for v in text.split(','))
    except ValueError:
        return None
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        return None
    return values[0], values[1], values[2]


def parse_link_loads(forces: Sequence[str], torques: Sequence[str], force_flag: str,
                     torque_flag: str) -> tuple[LinkLoad, ...]:
    """Return ``LINK=FX,FY,FZ[@X,Y,Z]`` forces and ``LINK=TX,TY,TZ`` torques as link loads.

    N and N m in the URDF's root frame, the point in the link's frame (m,
    default its origin). One load per link (its force and torque together);
    refused in one line (``ValueError``) naming the flag: an entry not in that
    form, a value not finite or above :data:`MAX_LOAD`, a link given twice.
    """
    out: dict[str, LinkLoad] = {}
    for flag, entries, form in ((force_flag, forces, 'LINK=FX,FY,FZ or LINK=FX,FY,FZ@X,Y,Z'),
                                (torque_flag, torques, 'LINK=TX,TY,TZ')):
        seen: set[str] = set()
        for entry in entries:
            link, sep, rest = entry.partition('=')
            link = link.strip()
            values, at, where = rest.partition('@')
            vector = _three(values)
            point = _three(where) if at else (0.0, 0.0, 0.0)
            if not sep or not link or vector is None or point is None \
                    or (at and flag == torque_flag):
                msg = f'{flag}: Expected {form}, three finite numbers each, got {entry!r}'
                raise ValueError(msg)
            if math.hypot(*vector) > MAX_LOAD:
                msg = (f'{flag}: Expected a load of at most {MAX_LOAD:g} in size, got '
                       f'{entry!r}')
                raise ValueError(msg)
            if link in seen:
                msg = f'{flag}: Expected each link once, got "{link}" twice'
                raise ValueError(msg)
            seen.add(link)
            old = out.get(link, LinkLoad(link))
            out[link] = (LinkLoad(link, vector, point, old.torque) if flag == force_flag
                         else LinkLoad(link, old.force, old.point, vector))
    return tuple(out.values())


class ForcesLeftOut(Exception):  # noqa: N818 - a reason, not an error of the caller's
    """Why a robot's efforts are left out at a state (one line); never raised to a user."""


def check_gravity(gravity: Sequence[float], what: str = 'gravity') -> tuple[float, float, float]:
    """Return gravity as three floats, or refuse in one line (``ValueError``) naming ``what``."""
    try:
        values = tuple(float(g) for g in gravity)
    except (TypeError, ValueError):
        values = ()
    if len(values) != 3 or not all(math.isfinite(g) for g in values) \
            or math.hypot(*values) > MAX_GRAVITY:
        msg = (f"Expected {what} as [gx, gy, gz] in the URDF's root frame, m/s^2, finite and "
               f'at most {MAX_GRAVITY:g} in size, got {list(gravity)!r}')
        raise ValueError(msg)
    x, y, z = values
    return x, y, z


@dataclass(frozen=True)
class RobotEfforts:
    """The efforts of a robot's actuated joints at a state, with their bounds.

    Attributes
    ----------
    efforts : dict of str to float or ndarray
        Per actuated joint that drives a loop (or leads a mimic that does):
        N m (revolute) or N (prismatic), positive along its ``<axis>``.
    bounds : dict of str to float or ndarray
        Their absolute error bounds.
    gravity : tuple of float
        The gravity used, m/s^2 in the root frame.
    forces : list of Forces
        The scene's forces, one per group of loops solved together.
    valid : bool or ndarray of bool
        Where every group's forces could be bounded (arrays: the instants
        whose efforts stand; one instant not bounded is refused instead).
    failures : dict of str to ndarray of bool
        For arrays: per reason, the instants refused.
    groups : tuple of tuple of int
        The mechanisms each of ``forces`` solved.
    actuators : dict of str to (str, value, bound)
        Per ``<transmission>`` actuator with a ``<mechanicalReduction>`` of
        one of those joints: its joint and its effort (the joint's divided by
        the reduction: the same power at the actuator's speed, reduction
        times the joint's), with its bound.
    loads : tuple of LinkLoad
        The link loads the efforts carry (in the root frame).
    """

    efforts: dict[str, Any]
    bounds: dict[str, Any]
    gravity: tuple[float, float, float]
    forces: list[Forces]
    valid: Any = True
    failures: dict[str, Any] = field(default_factory=dict)
    groups: tuple[tuple[int, ...], ...] = ()
    actuators: dict[str, tuple[str, Any, Any]] = field(default_factory=dict)
    loads: tuple[LinkLoad, ...] = ()


@dataclass(frozen=True)
class JointReaction:
    """The load a loop joint's parent puts on its child, in the child link's frame.

    At the joint's origin (a closure's: its ``<child_origin>``), in the axes
    of ``frame``, the child link (a closure's too, whatever the rotation of its
    ``<child_origin>``). ``force`` holds
    the loop's plane's part (N): the part along the pivots' axis, and the
    bending moments, are not determined by a planar loop's statics (with
    parallel pins it is overconstrained in space: the bearings share them by
    their stiffness) and are not in it. ``torque`` (N m) is the actuator's
    about the joint's axis (its effort; 0 for a passive joint).
    """

    frame: str
    force: tuple[float, float, float]
    torque: tuple[float, float, float]
    force_bound: float
    torque_bound: float

    def as_dict(self) -> dict[str, Any]:
        """Return ``{"frame", "force", "torque"}``."""
        return {'frame': self.frame, 'force': list(self.force), 'torque': list(self.torque)}


class RobotForces:
    """A robot's masses over its loops: :meth:`efforts` at a solved scene state.

    Build it with ``RobotForces(robot)``; ``None`` from :func:`robot_forces`
    for a robot whose URDF has no ``<inertial>``.
    """

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        planar = robot.planar
        description = robot.description
        self.mechanisms = planar.mechanisms
        self.size = _size(robot.scene)
        self._cache: dict[tuple[Any, ...], Dynamics] = {}
        self._last: Dynamics | None = None     # the statics the last instant took
        #: Per mechanism whose ground no joint carries: its rotation in the root frame, and
        #: the scene loads given link loads become in its plane.
        self._fixed_rotations: dict[int, Any] = {}
        self._fixed_loads: dict[tuple[Any, ...], tuple[Load, ...]] = {}
        #: Each URDF link's body (itself, or the loop link it is welded to), the closures and
        #: the drivers by name: what :meth:`reactions` looks up at every instant.
        self._bodies = self._welded_bodies()
        self._closures = {c.name: c for c in description.closures}
        self._drivers = {d.name: d for d in planar.drivers}
        masses = planar.masses
        self.masses = [tuple(Mass(body, item['mass'], tuple(item['com']), item['inertia'])
                             for body, item in masses.items() if body in m['bodies'])
                       for m in self.mechanisms]
        moving: dict[str, int] = {}      # URDF link of a loop's moving body -> its mechanism
        for index, m in enumerate(self.mechanisms):
            for link in m['links']:
                if link != m['ground']:
                    moving[link] = index
        self.moving_links = moving
        #: Why no forces can be given at all (a mass the loops do not carry), or None.
        self.refused: str | None = self._hanging(moving)
        #: Per mechanism: the moving joints from the root down to its ground.
        self.carriers = [[j.name for j in description.chain(m['ground']) if j.type is not None]
                         for m in self.mechanisms]

    def _hanging(self, moving: Mapping[str, int]) -> str | None:
        """Return why a mass hangs from a loop's moving body outside every loop, or None."""
        description = self.robot.description
        body_of = self._bodies
        loop_joints = {j for m in self.mechanisms for j in m['joints']}
        for link in description.links:
            if link not in description.inertials:
                continue
            for joint in reversed(description.chain(link)):
                parent = body_of[joint.parent]
                if joint.moving and joint.name not in loop_joints and parent in moving:
                    return (f'link "{link}": Expected masses on the links the loops move (or '
                            f'on their grounds and nearer the root), got a mass that hangs '
                            f'from "{parent}" (a moving link of a loop) through joint '
                            f'"{joint.name}", outside every loop: its weight loads that loop\'s '
                            'actuators through a motion the loops do not solve')
        return None

    def _welded_bodies(self) -> dict[str, str]:
        """Return each URDF link's body: itself, or the loop link it is welded to."""
        description = self.robot.description
        out: dict[str, str] = {}
        for link in description.links:
            up = link
            while True:
                joint = description.parent_joint(up)
                if joint is None or joint.moving:
                    break
                up = joint.parent
            out[link] = up
        return out

    def check_loads(self, loads: Sequence[LinkLoad], what: str = '--link-force') -> None:
        """Refuse (``ValueError``, one line naming the link) a load on a link no loop moves."""
        links = self.robot.description.links
        for load in loads:
            if load.link not in links:
                more = ', ...' if len(links) > 8 else ''
                msg = (f'{what}: load on link "{load.link}": Expected a link of the robot '
                       f'({", ".join(links[:8])}{more}), got none of that name')
                raise ValueError(msg)
            if load.link not in self.moving_links:
                msg = (f'{what}: load on link "{load.link}": Expected a link a loop moves '
                       f'({", ".join(sorted(self.moving_links))}), got one it does not: its '
                       "load reaches no loop's actuator")
                raise ValueError(msg)

    # --- gravity in each loop's plane ----------------------------------------------------

    def _plane_gravity(self, index: int, gravity: tuple[float, float, float],
                       inputs: Mapping[str, tuple[Any, Any, Any]]) -> tuple[float, float]:
        """Return gravity in mechanism ``index``'s scene frame at the ground's pose (m/s^2)."""
        m = self.mechanisms[index]
        rotation = self._ground_rotation(index, inputs, any(gravity))
        local = rotation.T @ np.asarray(gravity, dtype=np.float64)
        return (float(local @ np.asarray(m['x'])), float(local @ np.asarray(m['y'])))

    def _plane_loads(self, index: int, loads: Sequence[LinkLoad],
                     inputs: Mapping[str, tuple[Any, Any, Any]]) -> tuple[Load, ...]:
        """Return the link loads on mechanism ``index``'s bodies as loads of its scene.

        The force's in-plane part at the point (in the body's own frame), the
        torque's part along the plane's normal; both from the root frame at the
        ground's pose.
        """
        mine = [(k, load) for k, load in enumerate(loads)
                if self.moving_links.get(load.link) == index]
        if not mine:
            return ()
        fixed = not self.carriers[index]    # the same loads in the plane at every instant
        if fixed and (index, tuple(loads)) in self._fixed_loads:
            return self._fixed_loads[(index, tuple(loads))]
        m = self.mechanisms[index]
        rotation = self._ground_rotation(index, inputs, True)
        x, y = np.asarray(m['x']), np.asarray(m['y'])
        normal = np.cross(x, y)
        out: list[Load] = []
        for k, load in mine:
            body, a, b = self.robot.planar.links[load.link]
            force = rotation.T @ np.asarray(load.force, dtype=np.float64)
            fx, fy = float(force @ x), float(force @ y)
            if fx or fy:
                at = a @ np.asarray(load.point, dtype=np.float64) + b
                out.append(Load(f'link_load_{k}', link=body, force=(fx, fy),
                                at=(float(at[0]), float(at[1]))))
            tz = float((rotation.T @ np.asarray(load.torque, dtype=np.float64)) @ normal)
            if tz:
                out.append(Load(f'link_load_{k}_torque', link=body, torque=tz))
        if fixed:
            if len(self._fixed_loads) >= _CACHE:
                self._fixed_loads.pop(next(iter(self._fixed_loads)))
            self._fixed_loads[(index, tuple(loads))] = tuple(out)
        return tuple(out)

    def _ground_rotation(self, index: int, inputs: Mapping[str, tuple[Any, Any, Any]],
                         needed: bool) -> Any:
        """Return mechanism ``index``'s ground's rotation in the root frame at its pose.

        ``needed``: a carrying joint that is not given is refused
        (:class:`ForcesLeftOut`); else its value is taken as 0 (nothing
        projected depends on it).
        """
        if not self.carriers[index]:    # a ground at a fixed pose: its rotation, once
            fixed = self._fixed_rotations.get(index)
            if fixed is None:
                fixed = self.robot.description.transforms({})[
                    self.mechanisms[index]['ground']][:3, :3]
                self._fixed_rotations[index] = fixed
            return fixed
        robot = self.robot
        description = robot.description
        m = self.mechanisms[index]
        values: dict[str, float] = {}
        for name in self.carriers[index]:
            joint = description.joints[name]
            source, gain = name, 1.0
            if name not in inputs and joint.mimic is not None and joint.mimic.joint in inputs:
                source, gain = joint.mimic.joint, joint.mimic.multiplier
            if source not in inputs:
                if not needed:
                    continue
                raise ForcesLeftOut(
                    f'the ground of the loop through {", ".join(m["links"][:4])} ("{m["ground"]}")'
                    f' is carried by joint "{name}", which is not actuated: its pose, and so '
                    f"gravity (and any link load) in the loop's plane, is not known")
            p, v, a = inputs[source]
            if np.any(np.asarray(v) != 0) or np.any(np.asarray(a) != 0):
                raise ForcesLeftOut(
                    f'the ground of the loop through {", ".join(m["links"][:4])} ("{m["ground"]}")'
                    f' moves (joint "{name}" is given a speed or an acceleration): the planar '
                    'forces hold with the ground at rest; give its carrying joints no speed '
                    'and no acceleration')
            p = np.asarray(p, dtype=np.float64)
            if p.ndim and not np.all(p == p.flat[0]):
                raise ForcesLeftOut(
                    f'joint "{name}" carries the ground of the loop through '
                    f'{", ".join(m["links"][:4])} and takes several positions over the array: '
                    'solve each pose of the ground on its own')
            value = float(p.flat[0]) if p.ndim else float(p)
            if joint.mimic is not None and source != name:
                value = gain * value + joint.mimic.offset
            values[name] = value
        frames = description.transforms(values)
        return frames[m['ground']][:3, :3]

    def _dynamics(self, members: tuple[int, ...], g: tuple[float, float],
                  loads: tuple[Load, ...] = ()) -> Dynamics:
        key = (members, g, loads)
        dynamics = self._cache.get(key)
        if dynamics is None:
            if len(self._cache) >= _CACHE:
                self._cache.pop(next(iter(self._cache)))
            masses = [mass for i in members for mass in self.masses[i]]
            dynamics = Dynamics(self.robot.scene.graph, masses, loads, g, (), self.size)
            self._cache[key] = dynamics
        self._last = dynamics
        return dynamics

    def path(self) -> str:
        """Return which path served the last instant's statics, and why (``Dynamics.path``)."""
        last = self._last
        return 'no instant solved yet' if last is None else last.path()['single']

    # --- at a state ---------------------------------------------------------------------

    def efforts(self, state: State, inputs: Mapping[str, tuple[Any, Any, Any]],
                gravity: tuple[float, float, float], max_error: float,
                loads: Sequence[LinkLoad] = ()) -> RobotEfforts:
        """Return the efforts of the loops' actuated joints at a solved scene state.

        ``inputs``: every actuated joint's (position, speed, accel) the state
        was solved for (:meth:`.Robot.solve`'s); ``loads``: forces and torques
        on links the loops move (:class:`LinkLoad`, checked by
        :meth:`check_loads`).

        Raises
        ------
        ForcesLeftOut
            What the planar forces cannot carry (see the module's docstring).
        UntrustedError
            One instant whose efforts cannot be bounded within ``max_error``
            (a toggle, where the statics degenerate).
        """
        if self.refused is not None:
            raise ForcesLeftOut(self.refused)
        groups: dict[tuple[Any, ...], list[int]] = {}
        for index in range(len(self.mechanisms)):
            key = (self._plane_gravity(index, gravity, inputs),
                   self._plane_loads(index, loads, inputs))
            groups.setdefault(key, []).append(index)
        vector = not isinstance(state.valid, bool)
        efforts: dict[str, Any] = {}
        bounds: dict[str, Any] = {}
        answers = []
        valid: Any = True
        failures: dict[str, Any] = {}
        for (g, plane_loads), members in groups.items():
            forces = self._dynamics(tuple(members), g, plane_loads).forces(state,
                                                                           float(max_error))
            if not vector and not forces.valid:
                refuse_forces(state, forces, max_error)
            answers.append(forces)
            if vector:
                valid = valid & np.asarray(forces.valid, dtype=bool)
                for reason, where in forces.failures.items():
                    failures[reason] = failures[reason] | where if reason in failures \
                        else where
            for index in members:
                for driver in self.robot.planar.drivers:
                    if driver.name not in self.mechanisms[index]['drivers']:
                        continue
                    leader, gain = driver.gain
                    value = gain * forces.efforts[driver.scene]
                    bound = abs(gain) * forces.effort_bounds[driver.scene]
                    if leader in efforts:
                        total = efforts[leader] + value
                        bound = bounds[leader] + bound + _U * np.abs(total)
                        value = total
                    efforts[leader], bounds[leader] = value, bound
        ordered = [name for name in self.robot.actuated if name in efforts]
        actuators = {}
        for name in ordered:
            if name in self.robot.description.reductions:
                actuator, reduction = self.robot.description.reductions[name]
                value = efforts[name] / reduction
                actuators[actuator] = (name, value,
                                       bounds[name] / abs(reduction) + _U * np.abs(value))
        return RobotEfforts({n: efforts[n] for n in ordered}, {n: bounds[n] for n in ordered},
                            gravity, answers, valid, failures,
                            tuple(tuple(members) for members in groups.values()), actuators,
                            tuple(loads))

    def reactions(self, efforts: RobotEfforts, positions: Mapping[str, float],
                  bounds: Mapping[str, float]) -> dict[str, JointReaction]:
        """Return each loop's revolute joints' and pins' reactions at one instant.

        ``positions``: every joint's value (the answer's), ``bounds`` their
        position bounds. A prismatic joint of a loop is not given.
        """
        robot = self.robot
        description = robot.description
        frames = description.transforms(positions)
        body_of, closures, drivers = self._bodies, self._closures, self._drivers
        spread = math.fsum(abs(float(b)) for b in bounds.values())
        out: dict[str, JointReaction] = {}
        for forces, members in zip(efforts.forces, efforts.groups, strict=True):
            by_at: dict[tuple[str, frozenset[str]], Any] = {}
            for name, reaction in forces.reactions.items():
                if reaction.force is not None:
                    by_at[(reaction.at, frozenset((reaction.on, reaction.by)))] = (name, reaction)
            for index in members:
                m = self.mechanisms[index]
                scene_body = {**m['body_names'], m['ground']: robot.scene.graph.ground}
                ground = frames[m['ground']]
                for name in m['joints']:
                    joint = description.joints.get(name)
                    if joint is not None:
                        if joint.type is None or not joint.type.angular:
                            continue
                        parent, child = joint.parent, joint.child
                        axis = np.asarray(joint.axis, dtype=np.float64)
                    else:
                        closure = closures[name]
                        parent, child = closure.link_a, closure.link_b
                        axis = None
                    a, b = scene_body.get(body_of[parent]), scene_body.get(body_of[child])
                    point = robot.planar.pins.get(name, name)
                    found = by_at.get((point, frozenset((a, b))))
                    if a is None or b is None or found is None:
                        continue
                    _, reaction = found
                    f = complex(reaction.force)
                    if reaction.on != b:
                        f = -f
                    planar = f.real * np.asarray(m['x']) + f.imag * np.asarray(m['y'])
                    # In the child link's axes (a closure's too: its <child_origin>
                    # places the point, its rotation does not turn the answer).
                    turn = ground[:3, :3].T @ frames[child][:3, :3]   # a rotation's inverse
                    force = turn.T @ planar
                    torque = np.zeros(3)
                    torque_bound = 0.0
                    driver = drivers.get(name)
                    if driver is not None and axis is not None:
                        tau = driver.sigma * forces.efforts[driver.scene]
                        torque = tau * axis
                        torque_bound = float(forces.effort_bounds[driver.scene])
                    f_bound = float(reaction.force_bound) + abs(f) * (spread + 16 * _U)
                    out[name] = JointReaction(child, tuple(float(v) for v in force),
                                              tuple(float(v) for v in torque), f_bound,
                                              torque_bound)
        return out


def reaction_names(robot: Robot) -> tuple[tuple[str, str], ...]:
    """Return each loop's revolute joints and pins: ``(name, child link)``.

    In the mechanisms' order, as :meth:`RobotForces.reactions` answers them,
    in the child link's axes.
    """
    description = robot.description
    closures = {c.name: c for c in description.closures}
    out = []
    for m in robot.planar.mechanisms:
        for name in m['joints']:
            joint = description.joints.get(name)
            if joint is not None:
                if joint.type is not None and joint.type.angular:
                    out.append((name, joint.child))
                continue
            closure = closures.get(name)
            if closure is not None and closure.kind is ClosureKind.PIN:
                out.append((closure.name, closure.link_b))
    return tuple(dict((item[0], item) for item in out).values())


def reaction_maps(robot: Robot) -> dict[str, dict[str, Any]]:
    """Return, per reaction whose child link a loop moves, where it acts in the scene.

    ``{JOINT: {frame, body, at, axes}}``: the child link, its scene body, the
    scene point at the pin, and the 2x3 map of a vector of the link's axes
    into the body's own frame (``Planar.link_frame``): the scene's
    ``urdf_reactions`` (:class:`~mech_kinematics.solver.mechanism.RobotReaction`).
    """
    planar = robot.planar
    out = {}
    for name, child in reaction_names(robot):
        if child not in planar.planes:
            continue    # on a loop's ground: it does not turn in the plane
        body, a, _ = planar.link_frame(child)
        out[name] = {'frame': child, 'body': body, 'at': planar.pins.get(name, name),
                     'axes': [[float(v) for v in row] for row in np.asarray(a)]}
    return out


def parse_payloads(entries: Sequence[str],
                   what: str) -> dict[str, tuple[float, tuple[float, ...]]]:
    """Return ``LINK=KG`` or ``LINK=KG@X,Y,Z`` entries as ``{LINK: (kg, (x, y, z))}``.

    The commands' ``--payload`` and the node's ``payloads`` alike; ``what``
    names them in the ValueError (an entry not in that form, a link twice).
    """
    out: dict[str, tuple[float, tuple[float, ...]]] = {}
    for entry in entries:
        link, sep, rest = entry.partition('=')
        mass, at, point = rest.partition('@')
        link = link.strip()
        try:
            value = (float(mass), tuple(float(v) for v in point.split(',')) if at
                     else (0.0, 0.0, 0.0))
        except ValueError:
            value = None
        if not sep or not link or value is None or len(value[1]) != 3:
            msg = f'{what}: Expected LINK=KG or LINK=KG@X,Y,Z, got {entry!r}'
            raise ValueError(msg)
        if link in out:
            msg = f'{what}: Expected each link once, got "{link}" twice'
            raise ValueError(msg)
        out[link] = value
    return out


def with_payloads(description: Description,
                  payloads: Mapping[str, tuple[float, Sequence[float]]]) -> Description:
    """Return ``description`` with point masses added to links: ``{LINK: (kg, (x, y, z))}``.

    A payload (a part in a gripper, a tool) is a point mass at a point of a
    link, in the link's frame (m): it is welded to the link, added to its
    ``<inertial>`` (the total mass, the common centre of mass, the inertia
    about it by the parallel-axis theorem). Refused in one line
    (``UrdfError``) naming the link: a link the robot lacks, a mass not
    finite and above 0, a point not three finite numbers.
    """
    from dataclasses import replace

    from .description import Inertial
    from .transforms import translation

    inertials = dict(description.inertials)
    for link, (mass, point) in payloads.items():
        where = f'{description.source}: payload on link "{link}"'
        if link not in description.links:
            more = ', ...' if len(description.links) > 8 else ''
            known = ', '.join(description.links[:8]) + more
            raise UrdfError(f'{where}: Expected a link of the robot ({known}), got none of '
                            'that name')
        try:
            m = float(mass)
            p = np.array([float(v) for v in point], dtype=np.float64)
        except (TypeError, ValueError):
            m, p = math.nan, np.zeros(0)
        if not (math.isfinite(m) and m > 0.0) or p.shape != (3,) or not np.all(np.isfinite(p)):
            raise UrdfError(f'{where}: Expected a mass above 0 kg at a point [x, y, z] of the '
                            f'link (m, finite), got {mass!r} kg at {point!r}')
        old = inertials.get(link)
        if old is None:
            inertials[link] = Inertial(m, translation(p), np.zeros((3, 3)))
            continue
        c_old = old.origin[:3, 3]
        rotation = old.origin[:3, :3]
        total = old.mass + m
        com = (old.mass * c_old + m * p) / total
        tensor = rotation @ old.inertia @ rotation.T      # in the link's axes
        for part, at in ((old.mass, c_old), (m, p)):
            d = at - com
            tensor = tensor + part * (float(d @ d) * np.eye(3) - np.outer(d, d))
        inertials[link] = Inertial(total, translation(com), tensor)
    return replace(description, inertials=inertials)


def robot_forces(robot: Robot) -> RobotForces | None:
    """Return a robot's forces, or None where its URDF has no ``<inertial>`` with a mass."""
    return RobotForces(robot) if robot.description.inertials else None


@dataclass(frozen=True)
class EffortSweep:
    """The actuated joints' efforts at rest over one actuated joint's range.

    What :func:`effort_sweeps` gives, per actuated joint swept.

    Attributes
    ----------
    joint : str
        The actuated joint swept.
    positions : ndarray, shape (n,)
        Its values, rad or m, from the low end of its range to the high end.
    held : dict of str to float
        The other actuated joints, held at their reference values.
    gravity : tuple of float
        m/s^2 in the root frame.
    efforts : dict of str to ndarray, shape (n,)
        Each actuated joint's effort there (N m or N, positive along its
        ``<axis>``): what its actuator applies to hold the robot still; NaN
        where not solved.
    bounds : dict of str to ndarray, shape (n,)
        Their error bounds.
    valid : ndarray of bool, shape (n,)
        Where the loops close and the efforts are bounded.
    refused : str
        Why the first position not solved was not ('' where every one was).
    angular : bool
        Whether the joint swept is revolute (rad; its effort N m) or prismatic.
    """

    joint: str
    positions: Any
    held: dict[str, float]
    gravity: tuple[float, float, float]
    efforts: dict[str, Any]
    bounds: dict[str, Any]
    valid: Any
    refused: str = ''
    angular: bool = True

    def extremes(self, name: str) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """Return joint ``name``'s (largest, least) effort as (value, position, bound)."""
        values = np.where(self.valid, self.efforts[name], np.nan)
        out = []
        for k in (int(np.nanargmax(values)), int(np.nanargmin(values))):
            out.append((float(values[k]), float(self.positions[k]),
                        float(self.bounds[name][k])))
        return out[0], out[1]


def effort_sweeps(robot: Robot, samples: int = SWEEP_SAMPLES,
                  gravity: Sequence[float] | None = None,
                  loads: Sequence[LinkLoad] = ()) -> list[EffortSweep]:
    """Return each actuated joint's sweep of the efforts at rest, the others held.

    Each actuated joint in turn goes over its range (its URDF ``<limit>``;
    without one, where ``solve --target`` seeks start poses: a turn about its
    reference value for a revolute joint, its loops' size either way for a
    prismatic one) at ``samples`` evenly spaced values, every other actuated joint at
    its reference value, every speed and acceleration zero: the statics, the
    torques and forces the actuators hold the robot with under ``gravity``
    (the root frame's, default the robot's) and ``loads``, from
    :meth:`.Robot.solve` on the array path. Where the loops do not close or
    the efforts cannot be bounded (a toggle, a change point) the efforts are
    NaN and the first reason is kept.

    Raises
    ------
    ValueError
        A robot without ``<inertial>``s (no forces), fewer than 2 samples.
    """
    from .targets import joint_sweep

    if robot.forces is None:
        msg = f'Expected a robot whose links carry <inertial>s, got {robot.name} without'
        raise ValueError(msg)
    if samples < 2:
        msg = f'Expected at least 2 samples, got {samples}'
        raise ValueError(msg)
    g = robot.gravity if gravity is None else check_gravity(tuple(gravity))
    size = float(robot.solve(max_error=math.inf, forces=False).state.error_bound.size)
    out = []
    for joint in robot.actuated:
        limits = robot.description.joints[joint].limits
        low, high = joint_sweep(robot, joint, size) if limits is None else limits
        q = np.linspace(float(low), float(high), samples)
        held = {n: float(robot.start(n)) for n in robot.actuated if n != joint}
        if any(joint in carriers for carriers in robot.forces.carriers):
            # It turns a loop's ground: the planar forces take one pose of it at a time.
            valid, refused, values, bounds = _sweep_each(robot, joint, q, held, g, loads)
        else:
            valid, refused, values, bounds = _sweep_array(robot, joint, q, held, g, loads)
        out.append(EffortSweep(
            joint, q, held, g,
            {n: np.where(valid, np.asarray(v, dtype=np.float64) + 0.0 * q, np.nan)
             for n, v in values.items()},
            {n: np.asarray(b, dtype=np.float64) + 0.0 * q for n, b in bounds.items()},
            valid, refused, robot.joint_type(joint).angular))
    return out


def _sweep_array(robot: Robot, joint: str, q: Any, held: Mapping[str, float],
                 g: tuple[float, float, float], loads: Sequence[LinkLoad]
                 ) -> tuple[Any, str, dict[str, Any], dict[str, Any]]:
    """Return (valid, the first refusal, efforts, bounds) of ``joint`` over ``q``: one array."""
    positions = {joint: q, **{n: np.full(len(q), x) for n, x in held.items()}}
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', NearSingularWarning)
        answer = robot.solve(positions, max_error=math.inf, gravity=g, loads=loads)
    state, efforts = answer.state, answer.efforts
    valid = np.asarray(state.valid, dtype=bool) & (efforts is not None)
    refused = answer.forces_left_out or ''
    if not refused and not valid.all():
        first = int(np.flatnonzero(~valid)[0])
        reason = next((why for why, mask in state.failures.items()
                       if np.asarray(mask, dtype=bool)[first]), 'not solved')
        refused = f'at {joint} = {q[first]:.6g}: {reason}'
    if efforts is None:     # without efforts, none
        return valid, refused, {}, {}
    return valid, refused, dict(efforts.efforts), dict(efforts.bounds)


def _sweep_each(robot: Robot, joint: str, q: Any, held: Mapping[str, float],
                g: tuple[float, float, float], loads: Sequence[LinkLoad]
                ) -> tuple[Any, str, dict[str, Any], dict[str, Any]]:
    """Return :func:`_sweep_array`'s answer solving each pose of ``joint`` on its own."""
    valid = np.zeros(len(q), dtype=bool)
    refused = ''
    values: dict[str, Any] = {}
    bounds: dict[str, Any] = {}
    for k, x in enumerate(q):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter('ignore', NearSingularWarning)
                answer = robot.solve({joint: float(x), **held}, max_error=math.inf, gravity=g,
                                     loads=loads)
        except MechKinematicsError as error:
            refused = refused or f'at {joint} = {x:.6g}: {error}'
            continue
        if answer.efforts is None:
            refused = refused or f'at {joint} = {x:.6g}: {answer.forces_left_out}'
            continue
        valid[k] = True
        for name, value in answer.efforts.efforts.items():
            values.setdefault(name, np.full(len(q), np.nan))[k] = value
            bounds.setdefault(name, np.full(len(q), np.nan))[k] = answer.efforts.bounds[name]
    return valid, refused, values, bounds
