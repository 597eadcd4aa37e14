# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node in URDF mode: what it loads from its parameters, and the URDF's joints of a tick.

The node's ``scene`` parameter names a scene (YAML) or, in *URDF mode*, a
robot: a path ending in ``.urdf``, or the URDF's text given as the parameter
``robot_description`` (as robot_state_publisher takes it), with
``loop_closures`` (a closures file in any form ``read_closure_file`` reads) and
``actuated_joints`` (default: the URDF's ``<transmission>`` and
``<ros2_control>`` joints) and ``reference_pose`` (``JOINT=VALUE`` each, rad or
m: the pose whose branches the loops keep, for a URDF exported open at its
zero pose; default the zero pose) and ``payloads`` (``LINK=KG[@X,Y,Z]`` each, welded to the links:
:func:`payloads_from_parameter`). :func:`load_source` reads what the parameters
name, or refuses in one line (:class:`~mech_kinematics.errors.SceneError`,
the one ``solve`` prints); the robot's loops become a scene
(:class:`~mech_kinematics.robot.Robot`), which the node solves as any other,
compiled tick included.

:class:`RobotValues` turns a tick's values (the scene's coordinates, in the
order of :func:`~mech_kinematics.ros.ticker.values_from_state`) into the
URDF's joints in the same layout (positions, velocities, accelerations of
:attr:`Robot.joint_names <mech_kinematics.robot.Robot.joint_names>`, then the
scene's points), so that the node's message templates publish them
unchanged: relative to each joint's zero, positive about its axis as
written, exactly as :meth:`Robot.joints_from_state
<mech_kinematics.robot.Robot.joints_from_state>` answers them (``test/ros/
test_robot_mode.py`` checks the two agree). In topic drive the input names
the actuated joints by their URDF names and values (:attr:`RobotValues.drivers`
for :class:`~mech_kinematics.ros.topic_drive.TopicDrive`), turned into the
scene's drivers by :meth:`RobotValues.scene_inputs`; the actuated joints are
echoed as given. On the clock (``drive: time``) the scene's drivers move
each on its own, every joint of a loop follows the scene's coordinates, and
an actuated joint outside every loop stays at its reference value, at rest.

Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
import math
from typing import Any

from ..errors import AssemblyError, SceneError
from ..robot.assembly import wrap_revolute
from ..scene import DEFAULT_SCENE, load_scene, scene_text
from ..solver.mechanism import Scene

__all__ = ['RobotDriver', 'RobotValues', 'Source', 'URDF_SUFFIX', 'is_urdf', 'load_source',
           'payloads_from_parameter', 'reference_from_parameter', 'robot_forces_refusal']

#: A ``scene`` parameter ending so names a robot described in URDF.
URDF_SUFFIX = '.urdf'


def robot_forces_refusal(note: str | None, drive: str, effort: str, default_effort: str,
                         given: Sequence[str]) -> str | None:
    """Return why a forces parameter given to the node in URDF mode is refused, or None.

    ``note``: why the robot has no forces to publish ('' for a URDF without
    ``<inertial>``, a reason for masses its loops do not carry), or None where
    it has (:func:`~mech_kinematics.ros.robot_forces.robot_forces_note`).
    ``given``: the parameters given at start. Refused in one line, rather than
    accepted and ignored: ``loads.*`` always (a robot's loads are its
    ``payloads``, ``link_forces`` and ``link_torques``); ``effort`` other than
    its default, ``gravity``, ``payloads`` and the link loads where the robot
    has no forces to publish; those where its efforts are left out (``drive:
    topic`` without ``effort: static``).
    """
    loads = [name for name in given if name.startswith('loads.')]
    if loads:
        return (f"Expected no loads.* in URDF mode (a robot's loads are point masses on its "
                f'links, payloads:=["LINK=KG@X,Y,Z"], and forces and torques on its links, '
                f'link_forces:=["LINK=FX,FY,FZ@X,Y,Z"] and link_torques), got '
                f'{", ".join(loads)}')
    named = [name for name in given if name in ('gravity', 'payloads', 'link_forces',
                                                'link_torques')]
    if note is not None:
        if effort != default_effort:
            named.insert(0, f'effort:={effort}')
        if not named:
            return None
        why = note or "the URDF's links carry no <inertial>: there are no forces to publish"
        return f'Expected no forces parameters for this robot ({why}), got {", ".join(named)}'
    from .parameters import INPUT_DRIVES

    if named and drive in INPUT_DRIVES and effort == default_effort:
        return (f'Expected effort:=static with drive: {drive} for {", ".join(named)} (the input '
                f'gives no accelerations: the efforts are left out), got effort:={effort}')
    return None


def payloads_from_parameter(entries: Sequence[str]) -> dict[str, tuple[float, tuple[float, ...]]]:
    """Return the ``payloads`` parameter as ``{LINK: (kg, (x, y, z))}`` (the commands' form).

    ``LINK=KG`` or ``LINK=KG@X,Y,Z`` each (kg; m in the link's frame, default
    its origin), as ``--payload`` takes them.

    Raises
    ------
    UrdfError
        One line naming the parameter: an entry not in that form, a link given
        twice. (A link the robot lacks, or a mass not above 0, is refused by
        :func:`~mech_kinematics.robot.forces.with_payloads`, naming the link.)
    """
    from ..errors import UrdfError
    from ..robot.forces import parse_payloads

    try:
        return parse_payloads(entries, 'payloads')
    except ValueError as error:
        raise UrdfError(str(error)) from None


def is_urdf(scene: str) -> bool:
    """Return whether the ``scene`` parameter names a robot described in URDF."""
    return scene.lower().endswith(URDF_SUFFIX)


@dataclass(frozen=True)
class Source:
    """What the node loads from ``scene`` (or ``robot_description``).

    Attributes
    ----------
    scene : Scene
        The scene the node solves (a robot's: its loops, outputting every
        coordinate :class:`RobotValues` reads).
    text : str
        Published on ``scene``: the scene file's text, or the scene a robot's
        loops become (``urdf2scene``'s YAML).
    robot : Robot or None
        The robot, in URDF mode.
    origin : str
        Where it came from, for the start's log line (a path, or
        ``robot_description``).
    unloaded : Description or None
        In URDF mode, the robot's description before its ``payloads``: what a
        change of ``payloads`` while running builds on.
    """

    scene: Scene
    text: str
    robot: Any = None
    origin: str = ''
    unloaded: Any = None


def load_source(scene: str, robot_description: str = '', loop_closures: str = '',
                actuated_joints: Sequence[str] | None = None,
                reference_pose: Sequence[str] | None = None,
                payloads: Sequence[str] | None = None,
                link_loads: Sequence[str] | None = None) -> Source:
    """Load the scene or robot the node's parameters name.

    Parameters
    ----------
    scene : str
        The ``scene`` parameter: a scene path or packaged name, or a path
        ending in ``.urdf``.
    robot_description : str
        The URDF's text ('' for none); then ``scene`` must be left at its
        default.
    loop_closures : str
        A closures file beside the URDF, in any form ``read_closure_file`` reads ('' for
        none).
    actuated_joints : sequence of str or None
        The actuated joints (None: the URDF's).
    reference_pose : sequence of str or None
        ``JOINT=VALUE`` each (rad or m): the pose whose branches the loops keep
        (None: the URDF's zero pose); :func:`reference_from_parameter`.
    payloads : sequence of str or None
        ``LINK=KG[@X,Y,Z]`` each: point masses welded to links
        (:func:`payloads_from_parameter`).
    link_loads : sequence of str or None
        The names of the link-load parameters given (``link_forces``,
        ``link_torques``): refused with a scene; the forces tick reads them.

    Raises
    ------
    SceneError
        One line: a scene that cannot be loaded, a robot refused
        (:class:`~mech_kinematics.errors.UrdfError`, naming the joint), or
        parameters that do not go together.
    """
    urdf = robot_description or (scene if is_urdf(scene) else '')
    if robot_description and scene != DEFAULT_SCENE:
        msg = ('Expected the robot in one parameter, scene:=ROBOT.urdf or robot_description, '
               f'got both (scene {scene})')
        raise SceneError(msg)
    if not urdf:
        given = [name for name, value in (('loop_closures', loop_closures),
                                          ('actuated_joints', actuated_joints),
                                          ('reference_pose', reference_pose),
                                          ('payloads', payloads)) if value]
        given += list(link_loads or ())
        if given:
            msg = (f'Expected {", ".join(given)} with a robot described in URDF (scene:=PATH.urdf '
                   f'or robot_description), got scene {scene}')
            raise SceneError(msg)
        return Source(load_scene(scene), scene_text(scene), origin=scene)
    from ..robot import Robot
    from ..robot.description import read_description
    from ..robot.forces import reaction_maps
    from ..robot.writer import scene_yaml

    origin = 'robot_description' if robot_description else scene
    description = read_description(urdf, loop_closures or None)
    unloaded = description
    if payloads:
        from ..robot.forces import with_payloads
        description = with_payloads(description, payloads_from_parameter(payloads))
    robot = Robot(description, actuated_joints or None,
                  reference_from_parameter(description, reference_pose or ()))
    needed = RobotValues.coordinates(robot)
    built = robot.scene
    missing = tuple(n for n in needed if n not in built.output_joints)
    if missing:
        built = replace(built, outputs_joints=(*built.output_joints, *missing))
    reactions = None if robot.forces is None else reaction_maps(robot)
    return Source(built, scene_yaml(robot.planar, origin, reactions), robot, origin, unloaded)


def reference_from_parameter(description: Any, entries: Sequence[str]) -> dict[str, float]:
    """Return the ``reference_pose`` parameter's pose: ``JOINT=VALUE`` each, rad or m.

    Raises
    ------
    UrdfError
        One line naming the parameter: an entry not ``JOINT=VALUE``, a joint that
        is not a moving joint of the robot, a value that is not a finite number.
    """
    from ..errors import UrdfError

    out: dict[str, float] = {}
    for entry in entries:
        name, sep, text = entry.partition('=')
        name = name.strip()
        joint = description.joints.get(name)
        if not sep or joint is None or joint.type is None:
            moving = ', '.join(n for n, j in description.joints.items() if j.type is not None)
            msg = (f'reference_pose: Expected JOINT=VALUE with JOINT a moving joint of the '
                   f'robot ({moving}), got {entry!r}')
            raise UrdfError(msg)
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not math.isfinite(value):
            unit = 'rad' if joint.type.angular else 'm'
            msg = (f'reference_pose: Expected {name}=VALUE a finite number ({unit}), got '
                   f'{entry!r}')
            raise UrdfError(msg)
        out[name] = value
    return out


@dataclass(frozen=True)
class RobotDriver:
    """An actuated joint as :class:`~mech_kinematics.ros.topic_drive.TopicDrive` reads it.

    ``stroke``: a prismatic joint's limits in its own values (m, inclusive)
    where it moves a cylinder of a stroke, else None.
    """

    name: str
    stroke: tuple[float, float] | None = None


class RobotValues:
    """The URDF's joints of a tick's values, and the scene's drivers of the actuated joints.

    Parameters
    ----------
    robot : Robot
        The robot.
    joints, points : sequence of str
        The scene's output joints and points, in the tick's order.

    Attributes
    ----------
    names : tuple of str
        The joints published (:attr:`Robot.joint_names`), in order.
    drivers : tuple of RobotDriver
        The actuated joints, in :attr:`Robot.actuated`'s order.
    clock_note : str
        With ``drive: time``, the warning the node logs where a mimic joint
        drives a loop ('' for none).
    """

    def __init__(self, robot: Any, joints: Sequence[str], points: Sequence[str]) -> None:
        self.names = tuple(robot.joint_names)
        #: Where the actuated joints stand, for a refusal (:meth:`Robot.where
        #: <mech_kinematics.robot.Robot.where>`): the URDF's names, not the scene's drivers.
        self.where = robot.where
        self._n = len(joints)
        index = {name: i for i, name in enumerate(joints)}
        actuated = {name: k for k, name in enumerate(robot.actuated)}
        position = {name: k for k, name in enumerate(self.names)}
        scene_drivers = {d.name: d for d in robot.scene.drivers}
        # The scene's drivers from the actuated joints: (joint, multiplier, offset, sigma,
        # reference, scene_ref) each, scene = scene_ref + sigma * (m * urdf + o - reference).
        self._inputs = []
        strokes: dict[str, tuple[float, float]] = {}
        for d in robot.planar.drivers:
            rule = d.mimic
            leader, m, o = (d.name, 1.0, 0.0) if rule is None else \
                (rule.joint, rule.multiplier, rule.offset)
            self._inputs.append((actuated[leader], m, o, d.sigma, d.reference, d.scene_ref))
            stroke = scene_drivers[d.scene].stroke
            if rule is None and stroke is not None:
                ends = sorted(d.joint_value(s) for s in stroke)
                strokes[d.name] = (ends[0], ends[1])
        self.drivers = tuple(RobotDriver(name, strokes.get(name)) for name in robot.actuated)
        mimics = [f'{d.scene} ({d.name} mimics {d.mimic.joint})' for d in robot.planar.drivers
                  if d.mimic is not None]
        #: What ``drive: time`` does not do as the URDF says ('' where it does all of it).
        self.clock_note = '' if not mimics else (
            'URDF mode with drive: time: the scene drivers ' + ', '.join(mimics) + ' move on '
            'their own (inputs.NAME.*), so a mimic rule holds while their speeds keep it; '
            'drive: topic takes the actuated joints by their URDF names')
        by_urdf = {d.name: d for d in robot.planar.drivers}
        maps = robot.planar.joints
        # Per joint, in order, how the clock's tick gives it and how an input's does.
        self._time: list[tuple[Any, ...]] = []
        self._topic: list[tuple[Any, ...]] = []
        for name in self.names:
            item = maps.get(name)
            driver = by_urdf.get(name)
            if item is not None:
                recipe: tuple[Any, ...] = self._map(item, index)
            elif driver is not None:
                recipe = ('driver', index[driver.scene], driver.scene_ref, driver.sigma,
                          driver.reference)
            elif name in actuated:    # outside every loop: on the clock, at its reference
                recipe = ('rest', robot.start(name))
            else:
                rule = robot.description.joints[name].mimic
                recipe = ('mimic', position[rule.joint], rule.multiplier, rule.offset)
            self._time.append(recipe)
            if name in actuated:
                self._topic.append(('given', actuated[name]))
            elif driver is not None and driver.mimic is not None:
                rule = driver.mimic
                self._topic.append(('mimic', position[rule.joint], rule.multiplier,
                                    rule.offset))
            else:
                self._topic.append(recipe)
        self._on_clock = self._compile(self._time, 'on_clock')
        self._on_input = self._compile(self._topic, 'on_input')
        self.assemblies = robot.assemblies

    @staticmethod
    def coordinates(robot: Any) -> tuple[str, ...]:
        """Return the scene's coordinates the robot's joints follow (the tick must output them)."""
        out: list[str] = []
        for item in robot.planar.joints.values():
            out += [c for c in (item.child, item.parent, item.slider) if c is not None]
        out += [d.scene for d in robot.planar.drivers]
        return tuple(dict.fromkeys(out))

    @staticmethod
    def _map(item: Any, index: dict[str, int]) -> tuple[Any, ...]:
        if item.type.angular:
            terms = tuple((sign, index[c], ref) for sign, c, ref in
                          ((1.0, item.child, item.child_ref), (-1.0, item.parent, item.parent_ref))
                          if c is not None)
            return ('map', terms, item.reference, item.sigma, item.center)
        return ('map', ((1.0, index[item.slider], item.slider_ref),), item.reference,
                item.sigma, None)

    def scene_inputs(self, positions: Sequence[float], speeds: Sequence[float] | None
                     ) -> tuple[list[float], list[float] | None]:
        """Return the scene's drivers' positions and speeds of the actuated joints' (in order)."""
        p_out = [scene_ref + sigma * (m * positions[k] + o - reference)
                 for k, m, o, sigma, reference, scene_ref in self._inputs]
        return p_out, self.scene_rates(speeds)

    def scene_rates(self, rates: Sequence[float] | None) -> list[float] | None:
        """Return the scene's drivers' speeds (or accelerations) of the actuated joints'."""
        if rates is None:
            return None
        return [sigma * m * rates[k] for k, m, _o, sigma, _r, _s in self._inputs]

    def values(self, values: Sequence[float], given: tuple[Sequence[float] | None, ...] | None
               = None) -> list[float]:
        """Return the URDF joints' values of a tick's ``values``, then the scene's points'.

        Then the rest of ``values`` unchanged: the forces a forces tick appends
        (:class:`~mech_kinematics.ros.robot_forces.RobotForcesTick`).

        ``given``: the actuated joints' (positions, speeds or None[,
        accelerations or None]) of an input message or a trajectory's point,
        echoed as given (None: the clock's tick, every joint from the scene's
        coordinates).
        """
        if given is None:
            return self._on_clock(values, None, None, None)
        return self._on_input(values, given[0], given[1], given[2] if len(given) > 2 else None)

    def answer(self, first: tuple[Sequence[float], float],
               given: tuple[Sequence[float] | None, ...],
               solve: Any) -> tuple[list[float], float]:
        """Return an input's URDF joints (:meth:`values`) and measure, in the assembly answered.

        ``first``: the tick's (values, measure) in the reference assembly;
        ``solve(combo)`` those of the scene in assembly ``combo``
        (:class:`~mech_kinematics.robot.assembly.Assemblies`, the rule
        :meth:`Robot.solve <mech_kinematics.robot.Robot.solve>` applies to
        the same bits: the node answers what it answers).
        """
        assemblies = self.assemblies
        out = self.values(first[0], given)
        if not assemblies:
            return out, first[1]
        m = len(self.names)
        answers = {assemblies.zero: (out, first[1])}

        def at(combo: tuple[int, ...]) -> dict[str, float] | None:
            if combo not in answers:
                try:
                    values, measure = solve(combo)
                except AssemblyError:
                    return None
                answers[combo] = (self.values(values, given), measure)
            return dict(zip(self.names, answers[combo][0][:m], strict=True))

        (combo,) = assemblies.choose(at)
        return answers[combo] if at(combo) is not None else answers[assemblies.zero]

    def _compile(self, recipes: Sequence[tuple[Any, ...]], what: str) -> Any:
        """Return the recipes written out as one function ``f(values, positions, speeds, accels)``.

        Straight-line code, as the node's message templates are (a message of
        the motors at kilohertz rates pays for every loop and lookup); the
        same operations in the same order as :meth:`Robot.joints_from_state
        <mech_kinematics.robot.Robot.joints_from_state>`, so the same bits
        (``test_robot_mode``).
        """
        n = self._n
        lines = [f'def {what}(x, gp, gs, ga):']
        for j, recipe in enumerate(recipes):
            kind = recipe[0]
            if kind == 'map':
                _kind, terms, reference, sigma, centre = recipe
                dp = ' + '.join(['0.0', *(f'{sign!r} * (x[{i}] - {ref!r})'
                                          for sign, i, ref in terms)])
                dv = ' + '.join(['0.0', *(f'{sign!r} * x[{n + i}]' for sign, i, _ in terms)])
                da = ' + '.join(['0.0', *(f'{sign!r} * x[{2 * n + i}]'
                                          for sign, i, _ in terms)])
                value = f'{reference!r} + {sigma!r} * ({dp})'
                if centre is not None:
                    value = f'_wrap({value}, {centre!r})'
                lines += [f'    p{j} = {value}', f'    v{j} = {sigma!r} * ({dv})',
                          f'    a{j} = {sigma!r} * ({da})']
            elif kind == 'given':
                k = recipe[1]
                lines += [f'    p{j} = float(gp[{k}])',
                          f'    v{j} = 0.0 if gs is None else float(gs[{k}])',
                          f'    a{j} = 0.0 if ga is None else float(ga[{k}])']
            elif kind == 'driver':
                _kind, i, scene_ref, sigma, reference = recipe
                lines += [f'    p{j} = {reference!r} + (x[{i}] - {scene_ref!r}) / {sigma!r}',
                          f'    v{j} = x[{n + i}] / {sigma!r}',
                          f'    a{j} = x[{2 * n + i}] / {sigma!r}']
            elif kind == 'rest':
                lines += [f'    p{j} = {recipe[1]!r}', f'    v{j} = 0.0', f'    a{j} = 0.0']
            else:
                _kind, leader, m, o = recipe
                lines += [f'    p{j} = {m!r} * p{leader} + {o!r}', f'    v{j} = {m!r} * v{leader}',
                          f'    a{j} = {m!r} * a{leader}']
        joints = ', '.join(f'{q}{j}' for q in 'pva' for j in range(len(recipes)))
        # The scene's points, and what a forces tick appends after them (robot_forces.py).
        lines.append(f'    return [{joints}, *x[{3 * n}:]]')
        namespace: dict[str, Any] = {'_wrap': wrap_revolute}   # Robot.solve's, the one wrap
        exec(compile('\n'.join(lines) + '\n', f'<URDF joints {what}>', 'exec'),  # noqa: S102
             namespace)
        return namespace[what]
