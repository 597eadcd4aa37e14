# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's forces in URDF mode: the actuated joints' efforts and each loop pin's reaction.

A robot whose URDF's links carry ``<inertial>`` has its forces
(:class:`~mech_kinematics.robot.forces.RobotForces`, what ``Robot.solve``
answers). :class:`RobotForcesTick` is the node's tick on such a robot, the
URDF mode's :class:`~mech_kinematics.ros.wrenches.ForcesTick`: the loops'
kinematics solved as the scene's forces tick solves them, then at that state
(``effort: static``: at the same positions at rest) the efforts and the
reactions of :class:`RobotForces` with the ``gravity`` parameter (three
components in the URDF's root frame), appended to the tick's values in the
layout of the URDF's joints (after :class:`~mech_kinematics.ros.robot_mode.RobotValues`
has mapped the scene's coordinates onto them):

- one effort per published joint (:attr:`Robot.joint_names
  <mech_kinematics.robot.Robot.joint_names>`): an actuated joint's, positive
  along its ``<axis>``; 0 for a passive joint of a loop (frictionless); NaN
  (unknown, as ros2_control marks it) for an actuated joint outside every
  loop and for a mimic joint outside the loops, whose efforts the loops do
  not give;
- per revolute joint and pin of a loop, its reaction ``(fx, fy, fz, tx, ty,
  tz)``: the load the parent puts on the child, in the child link's axes,
  at the joint's origin (:class:`~mech_kinematics.robot.forces.JointReaction`:
  the part along the pins' axis and the bending moments are not in it).

An instant whose forces cannot be bounded, or that the planar forces cannot
carry (:class:`~mech_kinematics.robot.forces.ForcesLeftOut`), keeps its
kinematics and leaves the forces out, with the reason, as in scene mode.

No rclpy here but the message classes :mod:`~mech_kinematics.ros.wrenches`
imports; tested in ``test/ros/test_robot_forces.py``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace
import math
from typing import Any


from .parameters import DYNAMIC, INPUT_DRIVES, ParameterSpec, STATIC
from .robot_mode import RobotValues
from .ticker import values_from_state
from .topics import reaction_topic
from .wrenches import compiled_motion, ForceMessages, ForcesTick
from ..errors import AssemblyError, SceneError
from ..geometry.frames import child_frame
from ..robot.forces import (check_gravity, ForcesLeftOut, GRAVITY, parse_link_loads,
                            reaction_names)

__all__ = ['RobotForcesTick', 'robot_forces_note', 'robot_forces_tick']


def robot_forces_note(robot: Any) -> str | None:
    """Return why a robot has no forces to publish ('' for none to say), or None if it has.

    ``''``: its URDF has no ``<inertial>`` (nothing to say: a robot described
    for its kinematics); a reason: its masses are not carried by its loops
    (:attr:`RobotForces.refused <mech_kinematics.robot.forces.RobotForces.refused>`).
    """
    model = robot.forces
    if model is None:
        return ''
    return model.refused


class RobotForcesTick(ForcesTick):
    """The node's tick on a robot with masses: its kinematics' values, then its forces'.

    Parameters
    ----------
    robot : Robot
        The robot (with :attr:`~mech_kinematics.robot.Robot.forces`).
    scene : Scene
        The scene the ticks solve (the robot's loops, outputting what
        :class:`RobotValues` reads).
    static : bool, keyword-only
        ``effort: static``: gravity alone, solved at the same positions at rest.
    gravity : (float, float, float), keyword-only
        m/s^2 in the URDF's root frame until the parameter says otherwise.
    unloaded : Description or None, keyword-only
        The robot's description before its payloads; with it, ``payloads``
        is a forces parameter, changeable while running (:meth:`apply`).
    payloads : sequence of str, keyword-only
        The ``payloads`` parameter's entries the robot was built with.

    Attributes
    ----------
    names : tuple of str
        The URDF's joints published, whose efforts lead the forces' values.
    reactions : tuple of str
        The joints whose reactions follow the efforts, in order.
    links : tuple of str
        Each reaction's child link (its message's frame, with ``tf_prefix``).
    forces_first : int
        Where the forces start in the values as published (the URDF's joints'
        positions, velocities, accelerations, then the scene's points).
    g : tuple of float
        The gravity the next instant is solved with (replaced whole, read
        once per instant).
    """

    scene_reactions = False

    def __init__(self, robot: Any, scene: Any, *, static: bool,
                 gravity: Sequence[float] = GRAVITY, unloaded: Any = None,
                 payloads: Sequence[str] = ()) -> None:
        self.robot = robot
        self.unloaded = unloaded
        self.payloads = list(payloads)
        #: The model a change of ``payloads`` builds while it is judged, for :meth:`apply`.
        self._pending: tuple[list[str], Any] | None = None
        #: The ``link_forces`` and ``link_torques`` entries the loads come from.
        self.link_forces: list[str] = []
        self.link_torques: list[str] = []
        self.kinematics = replace(scene, gravity=None, masses=(), loads=(),
                                  outputs_joints=scene.output_joints,
                                  outputs_points=scene.output_points)
        self.motion = compiled_motion(self.kinematics)
        self.joints, self.points, self.frames = scene.output_joints, scene.output_points, ()
        self.static = static
        self.drivers = len(scene.drivers)
        self.values = RobotValues(robot, self.joints, self.points)
        self.names = tuple(robot.joint_names)
        found = reaction_names(robot)
        self.reactions = tuple(name for name, _ in found)
        self.links = tuple(link for _, link in found)
        self.forces_first = 3 * len(self.names) + 6 * len(self.points)
        #: What an instant is solved with, read once by it: (model, gravity, link loads); the
        #: one home of all three (:attr:`model`, :attr:`g`, :attr:`loads` read it).
        self._state: tuple[Any, ...] = (robot.forces, check_gravity(gravity), ())
        self.refusal = ''
        self.refused = 0
        self._samples: list[Any] | None = None
        index = {name: k for k, name in enumerate(self.names)}
        self._actuated = tuple((name, index[name]) for name in robot.actuated)
        drivers = {d.name for d in robot.planar.drivers}
        actuated = set(robot.actuated)
        # Per published joint: its effort from the answer ('effort'), 0 (a passive joint of a
        # loop, frictionless) or NaN (not given by the loops).
        self._fill = tuple('effort' if name in actuated else
                           0.0 if name in robot.planar.joints and name not in drivers else
                           math.nan for name in self.names)

    # -- the parameters -----------------------------------------------------------------

    def parameters(self) -> tuple[ParameterSpec, ...]:
        """Return ``gravity`` (three components in the URDF's root frame, m/s^2) and ``payloads``.

        ``payloads`` is the node's own parameter (declared before the robot is
        read); listed here where it can change while running (``unloaded``).
        """
        gravity = ParameterSpec(
            'gravity', 'xyz', list(self.g),
            "Gravity [gx, gy, gz] in the URDF's root frame, from the next instant published "
            "([0, 0, 0]: none; the part along a loop's pivots is carried by its bearings). "
            'Defaults to [0, 0, -9.80665] (REP 103: z up)', 'm/s^2')
        loads = tuple(ParameterSpec(
            name, 'string_array', list(getattr(self, name)),
            f"{what} on links, {form} each (in the URDF's root frame{where}), from the next "
            'instant published', '', may_be_empty=True) for name, what, form, where in (
                ('link_forces', 'Forces', 'LINK=FX,FY,FZ[@X,Y,Z]',
                 ", N, at a point of the link's frame, m"),
                ('link_torques', 'Torques', 'LINK=TX,TY,TZ', ', N m')))
        if self.unloaded is None:
            return (gravity, *loads)
        return (gravity, *loads, ParameterSpec(
            'payloads', 'string_array', list(self.payloads),
            "Point masses welded to links, LINK=KG or LINK=KG@X,Y,Z each (kg, m in the link's "
            'frame), from the next instant published', '', may_be_empty=True))

    def parameters_refusal(self, values: Mapping[str, Any]) -> str | None:
        """Return why ``values`` are refused: gravity beyond :data:`MAX_GRAVITY`, a bad payload.

        A new ``payloads`` is built here (the robot's masses with it), so that
        :meth:`apply` only swaps it in: refused in one line naming the entry or
        the link, or where the loops would not carry the masses.
        """
        try:
            check_gravity(values['gravity'])
        except ValueError as error:
            return f'gravity: {error}'
        try:
            self._link_loads(values)
        except ValueError as error:
            return str(error)
        payloads = list(values.get('payloads') or [])
        if self.unloaded is None or payloads == self.payloads:
            return None
        try:
            model = self._model_of(payloads)
        except (ValueError, SceneError) as error:   # UrdfError is a SceneError
            line = str(error).splitlines()[0]
            return line if line.startswith('payloads') else f'payloads: {line}'
        self._pending = (payloads, model)
        return None

    def _link_loads(self, values: Mapping[str, Any], model: Any = None) -> tuple[Any, ...]:
        """Return the link loads ``values`` give (the current ones where a name is absent)."""
        forces = values['link_forces'] if 'link_forces' in values else self.link_forces
        torques = values['link_torques'] if 'link_torques' in values else self.link_torques
        loads = parse_link_loads(list(forces or []), list(torques or []), 'link_forces',
                                 'link_torques')
        (self.model if model is None else model).check_loads(loads, 'link_forces')
        return loads

    def _model_of(self, payloads: list[str]) -> Any:
        """Return the robot's forces with ``payloads`` (entries) instead of its own."""
        from ..robot import Robot
        from ..robot.forces import with_payloads
        from .robot_mode import payloads_from_parameter

        parsed = payloads_from_parameter(payloads)
        description = with_payloads(self.unloaded, parsed) if parsed else self.unloaded
        robot = Robot(description, self.robot.actuated, self.robot.reference)
        if robot.forces is None:
            msg = ('Expected masses for the forces the node publishes, got none: no link of '
                   'the URDF carries an <inertial> and no payload is left')
            raise ValueError(msg)
        if robot.forces.refused is not None:
            raise ValueError(robot.forces.refused)
        return robot.forces

    def apply(self, values: Mapping[str, Any]) -> None:
        """Solve the next instants with the new gravity or payloads (forces written out first).

        ``values`` holds what changed (all of them at start). The tick reads the
        model once an instant, so an instant has the old masses or the new.
        """
        g = check_gravity(values['gravity']) if 'gravity' in values else self.g
        model, payloads = self.model, self.payloads
        if 'payloads' in values and self.unloaded is not None:
            given = list(values['payloads'] or [])
            if given != self.payloads:
                pending = self._pending
                model = pending[1] if pending is not None and pending[0] == given else \
                    self._model_of(given)
                payloads = given
        self._pending = None
        loads = self._link_loads(values, model)
        self.warm(g, model, loads)
        # Read once an instant, as one tuple: an instant has all the old or all the new.
        self.link_forces = list(values.get('link_forces', self.link_forces) or [])
        self.link_torques = list(values.get('link_torques', self.link_torques) or [])
        self._state = (model, g, loads)
        self.payloads = payloads

    @property
    def model(self) -> Any:
        """The robot's forces the next instant is solved with (its masses)."""
        return self._state[0]

    @property
    def g(self) -> tuple[float, float, float]:
        """The gravity the next instant is solved with, m/s^2 in the URDF's root frame."""
        return self._state[1]

    @property
    def loads(self) -> tuple[Any, ...]:
        """The link loads the next instant is solved with (:class:`LinkLoad` each)."""
        return self._state[2]

    def gravity(self) -> list[float]:
        """Return the gravity the forces are solved with, m/s^2 in the URDF's root frame."""
        return list(self.g)

    def path(self) -> str:
        """Return which path solved the last instant's statics, for ``diagnostics``."""
        return self.model.path()

    def topics(self) -> list[str]:
        """Return ``reactions/JOINT`` of each reaction, in order (no ``shaking``)."""
        return [reaction_topic(name) for name in self.reactions]

    def messages(self, frame_id: str, tf_prefix: str) -> ForceMessages:
        """Return the reactions' messages, each in its child link's frame (with ``tf_prefix``)."""
        return ForceMessages([child_frame(tf_prefix, link) for link in self.links],
                             len(self.names), len(self.reactions), width=6, shaking=False)

    # -- the tick -----------------------------------------------------------------------

    def warm(self, dynamics: Any = None, model: Any = None, loads: Any = None) -> Any:
        """Solve the forces where the drivers go, with gravity ``dynamics`` (or the tick's).

        As the scene's forces tick does (:meth:`ForcesTick.warm`): the forces'
        straight-line code of each group of loops is written here, before the
        ticks and before a new gravity (``model``, link ``loads``) takes effect.
        """
        current_model, current_g, current_loads = self._state
        g = current_g if dynamics is None else dynamics
        state_of = (current_model if model is None else model, g,
                    current_loads if loads is None else loads)
        if self._samples is None:
            self._samples = self._sample_states()
        for state in self._samples:
            values = values_from_state(state, self.joints, self.points, ())
            try:
                self._forces(values, state, math.inf, state_of, None)
            except (ForcesLeftOut, AssemblyError):
                continue
        return g

    def __call__(self, theta: Any, omega: Any, alpha: Any, tol: float,
                 turns: Any = 0) -> tuple[list[float], float]:
        """Return ``(values, measure)`` as a tick function does, the forces after the motion."""
        values, measure, at = self._motion(theta, omega, alpha, tol, turns)
        given = self.inputs
        try:
            forces = self._forces(values, at, tol, self._state, given)
        except (ForcesLeftOut, AssemblyError) as why:
            urdf = self.values.values(values, given)
            where = self.robot.where([urdf[k] for _, k in self._actuated])
            self.refusal = f'at {where}: {why}'
            self.refused += 1
            return values, measure
        return values + forces, measure

    def _forces(self, values: list[float], at: Any, tol: float, solved_with: tuple[Any, ...],
                given: Any) -> list[float]:
        """Return the forces' values at ``at`` (``values``: the scene's, of the same positions).

        ``solved_with``: (model, gravity, link loads), read once an instant.
        """
        model, g, loads = solved_with
        urdf = self.values.values(values, given)
        n = len(self.names)
        if self.static:
            inputs = {name: (urdf[k], 0.0, 0.0) for name, k in self._actuated}
        else:
            inputs = {name: (urdf[k], urdf[n + k], urdf[2 * n + k])
                      for name, k in self._actuated}
        efforts = model.efforts(at, inputs, g, tol, loads)
        reactions = model.reactions(efforts, dict(zip(self.names, urdf[:n])), {})
        given_efforts = efforts.efforts
        out = [(float(given_efforts[name]) if name in given_efforts else math.nan)
               if fill == 'effort' else fill for name, fill in zip(self.names, self._fill)]
        for name in self.reactions:
            reaction = reactions.get(name)
            if reaction is None:
                raise ForcesLeftOut(f'no reaction of {name} at this instant')
            out += (*reaction.force, *reaction.torque)
        return out


def robot_forces_tick(robot: Any, scene: Any, *, drive: str, effort: str,
                      unloaded: Any = None, payloads: Sequence[str] = ()
                      ) -> RobotForcesTick | None:
    """Return the forces tick of a robot on the node, or ``None`` where none is published.

    None for a robot without forces (:func:`robot_forces_note`), and with
    ``drive: topic`` unless ``effort: static`` (the input gives no
    accelerations), as for a scene (:func:`~mech_kinematics.ros.wrenches.forces_tick`).
    ``unloaded`` and ``payloads``: as :class:`RobotForcesTick` takes them (with
    ``unloaded``, ``payloads`` can change while running).
    """
    if robot_forces_note(robot) is not None or (drive in INPUT_DRIVES and effort == DYNAMIC):
        return None
    return RobotForcesTick(robot, scene, static=effort == STATIC, unloaded=unloaded,
                           payloads=payloads)
