# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A robot described in URDF: its loops solved in closed form, every joint under its own name.

:class:`Robot` holds the URDF as read (:mod:`.description`), the scene its
planar loops become (:mod:`.planar`, the same one ``urdf2scene`` writes) and
the maps between them. :meth:`Robot.solve` takes the actuated joints' values
(the URDF's own: rad or m from each joint's zero, positive about its axis as
written), solves the scene with :func:`mech_kinematics.solve` and answers
every joint of every loop, the actuated ones and the mimic joints whose
leader is known, with velocities and accelerations exact (the scene's link
rates, differenced), and error bounds.

For a node: :attr:`Robot.joint_names` are the joints it publishes,
:meth:`Robot.knows` says which joints of an input message it answers (every
other one passes through), :meth:`Robot.scene_inputs` turns the actuated
joints' values into the scene's drivers' and :meth:`Robot.joints_from_state`
turns the scene's state back into URDF joints, so that a compiled tick of
the scene can serve a robot. Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
import math
import os
from typing import Any

import numpy as np

from .assembly import Assemblies, pick, wrap_revolute
from .description import Description, read_description
from .forces import (check_gravity, ForcesLeftOut, GRAVITY, JointReaction, LinkLoad,
                     robot_forces, RobotEfforts, with_payloads)
from .planar import DriverMap, JointMap, Planar, planar_from_description
from ..bounds import MAX_ERROR
from ..errors import AssemblyError, SceneError, UrdfError
from ..solver import Scene, solve, State
from ..solver.graph import JointType
from ..solver.state import JointMotion

__all__ = ['MIMIC_TOLERANCE', 'Robot', 'RobotState', 'load_robot']

#: A joint strays from its ``<mimic>`` rule when they differ by more (rad or m).
MIMIC_TOLERANCE = 1e-9
_EPS = float(np.finfo(np.float64).eps)


@dataclass(frozen=True)
class RobotState:
    """Every URDF joint the robot knows at one instant (or an array of them).

    Attributes
    ----------
    robot : str
        The robot's name.
    inputs : dict of str to JointMotion
        The actuated joints as given (rad or m, their rates).
    joints : dict of str to JointMotion
        Every joint of every loop, the actuated ones and the mimic joints
        whose leader is known: the URDF's own values.
    bounds : dict of str to tuple of float
        Per joint, the error bounds of its position, velocity and acceleration.
    state : State
        The scene's state (points in the loops' plane).
    mimic : dict of str to dict
        Every answered joint with a ``<mimic>`` whose leader is answered (a
        loop's joint, an actuated one) whose value strays from its rule by
        more than :data:`MIMIC_TOLERANCE`: ``{'leader', 'rule', 'stray'}``
        (the rule's value, the joint's minus it).
    limits : dict of str to dict
        A joint outside its ``<limit>``: ``{'position', 'lower', 'upper'}``.
    efforts : RobotEfforts or None
        For a URDF with ``<inertial>``: the efforts of the actuated joints
        that drive its loops, with their bounds and the gravity used
        (:mod:`.forces`); ``None`` without, or where they are left out.
    forces_left_out : str or None
        Why the efforts are left out (a mass the loops do not carry, a
        moving ground), or ``None``.
    reactions : dict of str to JointReaction
        With the efforts, at one instant: each revolute joint and pin of
        every loop, the load its parent puts on its child in the child
        link's frame (:class:`~.forces.JointReaction`).
    """

    robot: str
    inputs: dict[str, JointMotion]
    joints: dict[str, JointMotion]
    bounds: dict[str, tuple[Any, Any, Any]]
    state: State
    mimic: dict[str, dict[str, Any]] = field(default_factory=dict)
    limits: dict[str, dict[str, Any]] = field(default_factory=dict)
    efforts: RobotEfforts | None = None
    forces_left_out: str | None = None
    reactions: dict[str, JointReaction] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        """Return what ``solve ROBOT.urdf`` prints: the URDF's joints, the scene's points."""
        vector = not isinstance(self.state.valid, bool)

        def value(x: Any) -> Any:
            return x if vector else float(x)

        scene = self.state.as_dict()
        out: dict[str, Any] = {
            'robot': self.robot, 'scene': scene['scene'],
            'inputs': {name: {'position': value(j.position), 'speed': value(j.velocity),
                              'accel': value(j.acceleration)} for name, j in self.inputs.items()},
            'joints': {name: {'type': str(j.type), 'position': value(j.position),
                              'velocity': value(j.velocity),
                              'acceleration': value(j.acceleration)}
                       for name, j in self.joints.items()},
            'points': scene['points']}
        if self.mimic:
            out['mimic'] = {name: {k: (v if isinstance(v, str) else value(v))
                                   for k, v in item.items()} for name, item in self.mimic.items()}
        if self.limits:
            out['limits'] = {name: {k: value(v) for k, v in item.items()}
                             for name, item in self.limits.items()}
        if self.efforts is not None:
            out['gravity'] = list(self.efforts.gravity)
            if self.efforts.loads:
                out['link_loads'] = [{'link': load.link, 'force': list(load.force),
                                      'point': list(load.point), 'torque': list(load.torque)}
                                     for load in self.efforts.loads]
            out['efforts'] = {name: value(x) for name, x in self.efforts.efforts.items()}
            if self.efforts.actuators:
                out['actuator_efforts'] = {
                    name: {'joint': joint, 'effort': value(x)}
                    for name, (joint, x, _) in self.efforts.actuators.items()}
        if self.reactions:
            out['reactions'] = {name: r.as_dict() for name, r in self.reactions.items()}
        if self.forces_left_out is not None:
            out['forces_left_out'] = self.forces_left_out
        out['error_bound'] = {
            'joints': {name: {'position': value(b[0]), 'velocity': value(b[1]),
                              'acceleration': value(b[2])} for name, b in self.bounds.items()},
            'points': scene['error_bound']['points']}
        if self.efforts is not None:
            out['error_bound']['efforts'] = {name: value(b)
                                             for name, b in self.efforts.bounds.items()}
            if self.efforts.actuators:
                out['error_bound']['actuator_efforts'] = {
                    name: value(b) for name, (_, _, b) in self.efforts.actuators.items()}
        if self.reactions:
            out['error_bound']['reactions'] = {
                name: {'force': r.force_bound, 'torque': r.torque_bound}
                for name, r in self.reactions.items()}
        return out


class Robot:
    """A robot described in URDF whose planar loops we solve.

    Build it with :func:`load_robot` (or :meth:`from_urdf`).

    Attributes
    ----------
    name : str
        The robot's name.
    description : Description
        The URDF as read, with its closures.
    planar : Planar
        Its loops as a scene mapping, with the maps of its joints.
    scene : Scene
        That scene, built.
    actuated : tuple of str
        The actuated joints: what :meth:`solve` takes.
    joint_names : tuple of str
        The joints :meth:`solve` answers, in order: the actuated ones, then
        every joint of every loop, then the mimic joints outside the loops
        whose leader is among them.
    reference : dict of str to float
        Every moving joint's value in the reference pose (rad or m).
    gravity : tuple of float
        Gravity in the URDF's root frame, m/s^2 (default
        :data:`~.forces.GRAVITY`); :meth:`solve` takes another.
    forces : RobotForces or None
        Its masses over its loops (:mod:`.forces`); ``None`` for a URDF
        without ``<inertial>``.
    """

    def __init__(self, description: Description, actuated: Iterable[str] | None = None,
                 reference: Mapping[str, float] | None = None) -> None:
        self.description = description
        self.name = description.name
        self.planar: Planar = planar_from_description(description, actuated, reference)
        from ..scene import parse_scene
        try:
            self.scene: Scene = parse_scene(self.planar.data)
        except SceneError as error:
            raise UrdfError(f'{description.source}: Expected its loops to assemble where its '
                            f'actuated joints start, got: {error}') from None
        self.reference = description.pose(reference)
        maps = self.planar.joints
        self.actuated = self.planar.actuated
        self._driven = {d.name: d for d in self.planar.drivers}
        names = list(self.actuated)
        names += [n for n in maps if n not in names]
        self._mimic_out: list[str] = []
        known = set(names)
        changed = True
        while changed:  # mimic joints outside the loops, whose leader we answer
            changed = False
            for joint in description.joints.values():
                if joint.mimic is not None and joint.name not in known \
                        and joint.mimic.joint in known:
                    names.append(joint.name)
                    known.add(joint.name)
                    self._mimic_out.append(joint.name)
                    changed = True
        self.joint_names = tuple(names)
        self._maps: dict[str, JointMap] = maps
        # Every answered joint's <mimic> whose leader is answered: a loop's joint, an actuated
        # one (given, so free to break it), and those that follow it (0 stray: checked alike).
        self._rules = {n: rule for n in names if (rule := description.joints[n].mimic)
                       is not None and rule.joint in known}
        self.gravity: tuple[float, float, float] = GRAVITY
        self.forces = robot_forces(self)
        #: The loops whose ``<mimic>`` rules pick their assembly (:mod:`.assembly`).
        self.assemblies = Assemblies(self, MIMIC_TOLERANCE)

    @classmethod
    def from_urdf(cls, source: str | os.PathLike[str], closures: str | os.PathLike[str] | None
                  = None, actuated: Iterable[str] | None = None,
                  reference: Mapping[str, float] | None = None,
                  payloads: Mapping[str, tuple[float, Any]] | None = None) -> Robot:
        """Read a URDF (path or text) and its closures; see :func:`load_robot`."""
        description = read_description(source, closures)
        if payloads:
            description = with_payloads(description, payloads)
        return cls(description, actuated, reference)

    def knows(self, joint: str) -> bool:
        """Return whether :meth:`solve` answers ``joint`` (else a node passes it through)."""
        return joint in self.joint_names

    def start(self, joint: str) -> float:
        """Return an actuated joint's value in the reference pose (rad or m)."""
        return self.reference.get(joint, 0.0)

    def joint_type(self, joint: str) -> JointType:
        """Return a joint's type (revolute or prismatic)."""
        kind = self.description.joints[joint].type
        assert kind is not None
        return kind

    def _inputs(self, positions: Mapping[str, Any] | None, speeds: Mapping[str, Any] | None,
                accels: Mapping[str, Any] | None) -> dict[str, tuple[Any, Any, Any]]:
        """Return every actuated joint's (position, speed, accel), defaults filled in."""
        for what, given in (('positions', positions), ('speeds', speeds),
                            ('accels', accels)):
            for name in given or {}:
                if name not in self.actuated:
                    msg = (f'Expected {what} of the actuated joints '
                           f'({", ".join(self.actuated)}), got "{name}"')
                    raise ValueError(msg)
        out = {}
        for name in self.actuated:
            p = (positions or {}).get(name, self.start(name))
            out[name] = (p, (speeds or {}).get(name, 0.0), (accels or {}).get(name, 0.0))
        return out

    def _urdf_driver(self, driver: DriverMap, inputs: Mapping[str, tuple[Any, Any, Any]]
                     ) -> tuple[Any, Any, Any]:
        """Return a scene driver's URDF joint (position, speed, accel): given, or its mimic's."""
        if driver.mimic is None:
            return inputs[driver.name]
        rule = driver.mimic
        p, v, a = inputs[rule.joint]
        return rule.multiplier * p + rule.offset, rule.multiplier * v, rule.multiplier * a

    def scene_inputs(self, inputs: Mapping[str, tuple[Any, Any, Any]]
                     ) -> tuple[list[Any], list[Any], list[Any]]:
        """Return the scene drivers' positions, speeds and accels for the actuated joints'.

        ``inputs`` maps every actuated joint to its (position, speed, accel):
        rad, rad/s, rad/s^2 or m, m/s, m/s^2. A crank's angle is its scene
        reference plus sigma times the joint's turn from its reference; a
        cylinder's length likewise.
        """
        positions, speeds, accels = [], [], []
        for driver in self.planar.drivers:
            p, v, a = self._urdf_driver(driver, inputs)
            positions.append(driver.scene_value(p))
            speeds.append(driver.sigma * v)
            accels.append(driver.sigma * a)
        return positions, speeds, accels

    def solve(self, positions: Mapping[str, Any] | None = None,
              speeds: Mapping[str, Any] | None = None, accels: Mapping[str, Any] | None = None,
              *, max_error: float = MAX_ERROR, gravity: Iterable[float] | None = None,
              loads: Iterable[LinkLoad] = (), forces: bool = True) -> RobotState:
        """Solve the robot where its actuated joints stand.

        Parameters
        ----------
        positions, speeds, accels : mapping of str to float or array, optional
            Per actuated joint: rad, rad/s, rad/s^2 (revolute) or m, m/s,
            m/s^2 (prismatic). Positions default to the reference pose's,
            rates to 0. Arrays (all of one shape) solve many instants.
        max_error : float, optional
            As :func:`mech_kinematics.solve`'s.
        gravity : (float, float, float), optional
            m/s^2 in the URDF's root frame; default :attr:`gravity`.
        loads : iterable of LinkLoad, optional
            Forces and torques on links the loops move, in the root frame
            (:class:`~.forces.LinkLoad`): in the efforts and reactions.
        forces : bool, optional
            False: the kinematics only, no efforts or reactions (an inverse's
            iterations, :mod:`.targets`). Default True.

        Returns
        -------
        RobotState
            With the efforts of the actuated joints that drive the loops
            (``efforts``) where the URDF has ``<inertial>``: the forces of the
            motion given (with rates left at 0: static, gravity alone).

        Raises
        ------
        AssemblyError
            Where the loops cannot close: the scene's dyad and reason, at the
            actuated joints' values under the URDF's names
            (``at finger_joint = 0.9 rad: ...``, :meth:`where`); its subclass
            UntrustedError where the efforts of one instant cannot be bounded.
        ValueError
            A joint that is not actuated; gravity not finite or above
            :data:`~.forces.MAX_GRAVITY`.
        """
        g = self.gravity if gravity is None else check_gravity(tuple(gravity))
        link_loads = tuple(loads)
        if link_loads and self.forces is not None:
            self.forces.check_loads(link_loads, 'loads')
        inputs = self._inputs(positions, speeds, accels)
        p, v, a = self.scene_inputs(inputs)
        try:
            state = self._assembled(p, v, a, inputs, max_error)
        except AssemblyError as error:  # one instant (arrays mask what they refuse)
            raise error.located(self.where({n: x[0] for n, x in inputs.items()})) from None
        answer = self.joints_from_state(state, inputs)
        if self.forces is None or not forces:
            return answer
        try:
            efforts = self.forces.efforts(state, inputs, g, max_error, link_loads)
        except ForcesLeftOut as why:
            return replace(answer, forces_left_out=str(why))
        except AssemblyError as error:
            raise error.located(self.where({n: x[0] for n, x in inputs.items()})) from None
        if isinstance(state.valid, np.ndarray):   # an instant whose efforts are not bounded
            failures = {**state.failures, **efforts.failures}
            state = replace(state, valid=state.valid & efforts.valid, failures=failures)
            answer = replace(answer, state=state)
            return replace(answer, efforts=efforts)
        reactions = self.forces.reactions(
            efforts, {n: float(j.position) for n, j in answer.joints.items()},
            {n: float(b[0]) for n, b in answer.bounds.items()})
        return replace(answer, efforts=efforts, reactions=reactions)

    def solve_targets(self, targets: Mapping[str, float],
                      speeds: Mapping[str, float] | None = None,
                      accels: Mapping[str, float] | None = None, *,
                      start: Mapping[str, float] | None = None, max_error: float = MAX_ERROR,
                      forces: Mapping[str, float] | None = None,
                      gravity: Iterable[float] | None = None,
                      loads: Iterable[LinkLoad] = (),
                      branch: Mapping[str, int] | None = None) -> Any:
        """Solve the robot driven from its targets (docs/targets.md, :mod:`.targets`).

        Parameters
        ----------
        targets : mapping of str to float
            One per actuated joint: a joint :meth:`solve` answers (rad or m,
            the URDF's) or a link frame origin's coordinate in the root frame,
            ``'FRAME.x'``, ``'.y'``, ``'.z'`` (m).
        speeds, accels : mapping of str to float, optional
            The targets' velocities and accelerations (SI); left out: at rest.
        start : mapping of str to float, optional
            Actuated joints' values the answer is continued from; default the
            reference pose's.
        max_error : float, optional
            As :meth:`solve`'s; also the largest bound of an actuated joint's
            value over its scale (1 rad, or the loops' size).
        forces : mapping of str to float, optional
            Forces (N) or torques (N m) along targets: ``target_efforts``
            holds the actuated joints' share, ``J^T F``.
        gravity, loads
            As :meth:`solve`'s, for the efforts of the motion (with ``<inertial>``).
        branch : mapping of str to int, optional
            The working mode: revolute joints of the loops (not actuated), each
            with the sign (+1 or -1) asked of its value wrapped to (-pi, pi]
            (docs/targets.md).

        Returns
        -------
        Inverse
            Its ``answer`` a :class:`RobotState` (with the efforts where the
            URDF has ``<inertial>``).

        Raises
        ------
        TargetError
            A target the robot does not answer, out of reach, or near a
            singular point of the map.
        """
        from .targets import solve_robot_targets

        return solve_robot_targets(self, targets, speeds, accels, start=start,
                                   max_error=max_error, forces=forces,
                                   gravity=None if gravity is None else tuple(gravity),
                                   loads=tuple(loads), branch=branch)

    def _assembled(self, p: list[Any], v: list[Any], a: list[Any],
                   inputs: Mapping[str, tuple[Any, Any, Any]], max_error: float) -> State:
        """Return the scene's state in the assembly answered (:mod:`.assembly`).

        The reference pose's branches, unless a loop's ``<mimic>`` rules pick
        another: then the scene in that assembly, solved (for arrays, each
        instant in its own, merged).
        """
        def one(scene: Scene) -> State:
            if len(p) == 1:  # one driver: solve's one-driver signature takes bare values
                return solve(scene, p[0], v[0], a[0], max_error=max_error)
            return solve(scene, p, v, a, max_error=max_error)

        assemblies = self.assemblies
        if not assemblies:
            return one(self.scene)
        states: dict[tuple[int, ...], State] = {}

        def at(combo: tuple[int, ...]) -> dict[str, Any] | None:
            if combo not in states:
                try:
                    states[combo] = one(assemblies.scene(combo, self.scene))
                except AssemblyError:
                    if combo == assemblies.zero:
                        raise
                    return None
            answer = self.joints_from_state(states[combo], inputs)
            return {n: j.position for n, j in answer.joints.items()}

        chosen = {combo: mask for combo, mask in assemblies.choose(at).items()
                  if at(combo) is not None}   # (one that does not assemble: the reference's)
        if len(chosen) <= 1:
            return states[next(iter(chosen), assemblies.zero)]
        merged = states[assemblies.zero]
        for combo, mask in chosen.items():
            merged = pick(mask, states[combo], merged)
        return merged

    def where(self, positions: Mapping[str, Any] | Iterable[Any]) -> str:
        """Return where the loops' actuated joints stand, for a message: ``j3 = 0.5 rad``.

        ``positions``: by actuated joint, or one per actuated joint in
        :attr:`actuated`'s order. Each joint that drives a loop (a mimic's
        leader for a mimic that does) once, under the URDF's name: a refusal
        names these, not the scene's drivers they were mapped to, nor the
        joints outside every loop.
        """
        given = positions if isinstance(positions, Mapping) else \
            dict(zip(self.actuated, positions, strict=True))
        names = dict.fromkeys(d.name if d.mimic is None else d.mimic.joint
                              for d in self.planar.drivers)
        return ', '.join(f'{name} = {float(given[name]):.6g} {self.joint_type(name).units[0]}'
                         for name in names)

    def joints_from_state(self, state: State, inputs: Mapping[str, tuple[Any, Any, Any]]
                          ) -> RobotState:
        """Return the URDF joints of a scene's state solved for ``inputs`` (see :meth:`solve`)."""
        joints: dict[str, JointMotion] = {}
        bounds: dict[str, tuple[Any, Any, Any]] = {}
        given = {}
        for name, (p, v, a) in inputs.items():
            motion = JointMotion(self.joint_type(name), p, v, a)
            given[name] = motion
            joints[name] = motion
            bounds[name] = (0.0, 0.0, 0.0)
        for driver in self.planar.drivers:  # a mimic that drives a loop: its rule's value
            if driver.mimic is not None:
                p, v, a = self._urdf_driver(driver, inputs)
                joints[driver.name] = JointMotion(driver.type, p, v, a)
                bounds[driver.name] = (_EPS * abs(p), _EPS * abs(v), _EPS * abs(a))
        coordinates = state.joints
        errors = state.error_bound.joints
        for name, item in self._maps.items():
            if name in joints:
                continue
            joints[name], bounds[name] = self._joint(item, coordinates, errors)
        for name in self._mimic_out:
            rule = self.description.joints[name].mimic
            assert rule is not None
            leader = joints[rule.joint]
            joints[name] = JointMotion(self.joint_type(name),
                                       rule.multiplier * leader.position + rule.offset,
                                       rule.multiplier * leader.velocity,
                                       rule.multiplier * leader.acceleration)
            lb = bounds[rule.joint]
            bounds[name] = tuple(abs(rule.multiplier) * b for b in lb)  # type: ignore[assignment]
        ordered = {name: joints[name] for name in self.joint_names}
        return RobotState(self.name, given, ordered,
                          {name: bounds[name] for name in self.joint_names}, state,
                          self._strays(ordered), self._outside(ordered))

    def _joint(self, item: JointMap, coordinates: Mapping[str, JointMotion],
               errors: Mapping[str, Any]) -> tuple[JointMotion, tuple[Any, Any, Any]]:
        """Return one loop joint's motion and bounds from the scene's coordinates."""
        if item.type.angular:
            terms = [(1.0, item.child, item.child_ref), (-1.0, item.parent, item.parent_ref)]
        else:
            terms = [(1.0, item.slider, item.slider_ref)]
        p: Any = 0.0
        v: Any = 0.0
        a: Any = 0.0
        bp: Any = 0.0
        bv: Any = 0.0
        ba: Any = 0.0
        size = 0.0
        for sign, coordinate, ref in terms:
            if coordinate is None:
                continue
            motion = coordinates[coordinate]
            bound = errors[coordinate]
            p = p + sign * (motion.position - ref)
            v = v + sign * motion.velocity
            a = a + sign * motion.acceleration
            bp, bv, ba = bp + bound.position, bv + bound.velocity, ba + bound.acceleration
            size += abs(ref) + math.pi
        value = item.reference + item.sigma * p
        if item.type.angular:
            value = wrap_revolute(value, item.center)
        # The sums above and the wrap round each once or twice more.
        rounding = 8 * _EPS * (size + abs(item.reference) + np.abs(value))
        motion = JointMotion(item.type, value, item.sigma * v, item.sigma * a)
        return motion, (bp + rounding, bv + 4 * _EPS * np.abs(v), ba + 4 * _EPS * np.abs(a))

    def _strays(self, joints: Mapping[str, JointMotion]) -> dict[str, dict[str, Any]]:
        """Return the answered joints that stray from their ``<mimic>`` rule (every one)."""
        out = {}
        for name, rule in self._rules.items():
            expected = rule.multiplier * joints[rule.joint].position + rule.offset
            stray = joints[name].position - expected
            if self.joint_type(name).angular:
                stray = wrap_revolute(stray)
            if np.any(np.abs(stray) > MIMIC_TOLERANCE):
                out[name] = {'leader': rule.joint, 'rule': expected, 'stray': stray}
        return out

    def _outside(self, joints: Mapping[str, JointMotion]) -> dict[str, dict[str, Any]]:
        """Return the joints outside their ``<limit>`` (reported, never refused)."""
        out = {}
        for name, motion in joints.items():
            joint = self.description.joints[name]
            if joint.limits is None or joint.urdf_type == 'continuous':
                continue
            lower, upper = joint.limits
            position = motion.position
            if np.any((position < lower) | (position > upper)):
                out[name] = {'position': position, 'lower': lower, 'upper': upper}
        return out


def load_robot(source: str | os.PathLike[str], closures: str | os.PathLike[str] | None = None,
               actuated: Iterable[str] | None = None,
               reference: Mapping[str, float] | None = None,
               payloads: Mapping[str, tuple[float, Any]] | None = None) -> Robot:
    """Read a robot described in URDF and make the scene of its planar loops.

    Parameters
    ----------
    source : str or path
        A URDF file, or its text (``robot_description``).
    closures : str or path, optional
        The closures beside the URDF: a scikit-robot ``loop_closures.yaml``, a
        file of ``<constraint>`` elements, an Extended-URDF ``robot.yaml`` or a
        fusion2URDF ``robot_data.yaml``, told by content (the other forms are
        inside the URDF).
    actuated : iterable of str, optional
        The actuated joints; default: the sidecar's ``independent`` joints,
        else the URDF's ``<transmission>`` and ``<ros2_control>`` joints.
    reference : mapping of str to float, optional
        A reference pose (rad or m per joint) whose branches the loops keep;
        default the URDF's zero pose.
    payloads : mapping of str to (float, (float, float, float)), optional
        Point masses on links, ``{LINK: (kg, (x, y, z))}`` in the link's
        frame: welded to it (:func:`~.forces.with_payloads`).

    Returns
    -------
    Robot

    Raises
    ------
    UrdfError
        One line naming the source, the joint and why.
    """
    return Robot.from_urdf(source, closures, actuated, reference, payloads)
