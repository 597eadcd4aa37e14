# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The public :class:`Scene`: a mechanism validated, compiled and checked to assemble.

Its solver (:class:`_Solver`) holds the compiled plan, the labels of what it
reports and the scaling; :func:`assembly_text` says why a mechanism cannot
assemble in the scene's own units.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
import math
from typing import Any, cast
import warnings

import numpy as np

from .base import Driver, Intermittent, Item
from .carried import CarriedPoint
from .crank import Crank
from .forces import Dynamics, Load, Mass
from .graph import Graph, JointType
from .model import _check_name, SceneUnits
from .plan import _compile, _Plan
from .registry import FACT_TEXTS
from .rubbing import Pin
from .scaling import _exponent, _LINEAR, _scaled, _size, _SIZE_RANGE
from .solve import _execute, _execute_drivers
from .trust import TRUST_TEST
from ..bounds import U
from ..errors import AssemblyError, NearSingularWarning, SceneError
from ..imu import imu_outputs, ImuSpec


class _Solver:
    """A compiled plan with what solving it with error bounds needs.

    ``run_plan`` is the plan the steps run: ``plan`` itself, or for a scene
    whose size is outside :data:`_SIZE_RANGE` the same scene compiled with
    every length times ``2**-shift``. ``outputs`` lists the reported values in
    solve order: (table of the context, name, path in ``as_dict()``, label of
    the dyad that produced it, the kinds of its three values).
    """

    def __init__(self, scene: Scene, plan: _Plan) -> None:
        self.plan = plan
        self.size = _size(scene)
        crank = scene.input
        # The first driver's length where it is a crank (0 in a scene driven by actuators
        # only): with the crank's rates, the least scale of the linear kinds.
        self.crank_length = 0.0 if crank is None else crank.length
        #: Whether the scene has one driver, a crank (the v1 path of solve).
        self.single = crank is not None and len(scene.drivers) == 1
        #: That crank's default speed and acceleration (the single path's, read once).
        self.defaults = (crank.speed, crank.accel) if crank is not None else (0.0, 0.0)
        # The same as read-only 0-d arrays, for array solves (one object each, every solve).
        self.default_arrays = tuple(_read_only_scalar(x) for x in self.defaults)
        self.shift = _exponent(self.size, *_SIZE_RANGE)
        run = plan
        if self.shift:
            try:
                run = _compile(_scaled(scene, self.shift), plan.output_joints,
                               plan.output_points)
            except SceneError:
                msg = (f"Expected every length within 2**1000 of the mechanism's size "
                       f'{self.size:.3g} m, got one that does not survive scaling to 1 m')
                raise SceneError(msg, (scene, 'ground')) from None
            unit = math.ldexp(1.0, self.shift)
            for step in run.steps:
                step.unit = unit
        self.run_plan = run
        # Ground points are inputs: known to U |g|.
        self.ground = {name: (z, 0j, 0j, U * abs(z), 0.0, 0.0) for name, z in run.ground.items()}
        labels: dict[str, str] = {}
        for driver in plan.drivers:
            labels.update(dict.fromkeys(driver.defines, driver.label))
        labels.update((name, f'ground {name}') for name in plan.ground)
        rank = dict.fromkeys(labels, 0)
        self.measure_keys: dict[str, str] = {}
        for index, step in enumerate(plan.steps, 1):
            if step.owner is not None:
                label = labels[step.owner]  # the dyad that moves its link
            else:
                label = step.label
                self.measure_keys[label] = step.key
            for name in step.defines:
                labels[name], rank[name] = label, index
        outputs = [(rank[name], 'points', name, f'points.{name}', labels[name], _LINEAR)
                   for name in plan.output_points]
        for name, kind in plan.joint_types.items():
            outputs.append((rank[name], kind.table, name, f'joints.{name}', labels[name],
                            kind.quantities))
        outputs.sort(key=lambda item: item[0])
        self.outputs = tuple(item[1:] for item in outputs)
        self.out_points = plan.output_points
        self.levers = {step.key: cast(Intermittent, step) for step in plan.steps
                       if step.intermittent}
        self.jumping = {lever: _jumping(plan, lever) for lever in self.levers}
        self.joint_names = tuple(plan.joint_types)
        self.out_links = tuple(n for n, k in plan.joint_types.items() if k.table == 'links')
        self.out_sliders = tuple(n for n, k in plan.joint_types.items() if k.table == 'sliders')
        # The quick trust test's groups (TRUST_TEST), with their names, the empty ones left out.
        self.trust = tuple((table, getattr(self, names), limits)
                           for table, names, limits in TRUST_TEST if getattr(self, names))
        # The drivers' steps (in the plan's units) and the names they report.
        self.drivers = run.drivers
        self.driver_names = tuple(driver.name for driver in run.drivers)
        self.driver_types = tuple(driver.joint_type for driver in run.drivers)
        # The compiled single-angle solve (:mod:`.compiler`): None until compiled, a falsy
        # NotCompiled (why) where the scene does not compile; and the single-angle solves
        # until then.
        self.compiled_single: Any = None
        self.single_solves = 0
        # Likewise the compiled array path, and the scene both compile from.
        self.compiled_array: Any = None
        # The array path compiled for the scene's own rates (solve._compile_usual), with the
        # floors of those rates.
        self.compiled_usual: Any = None
        self.usual_floors: Any = None
        self.array_solves = 0
        self.scene = scene
        # Per array shape, its read-only arrays of one value each (solve._Constants).
        self.constant_arrays: dict[tuple[int, ...], Any] = {}

    def floors(self, speeds: Any, accels: Any) -> tuple[Any, Any, Any, Any]:
        """Return the least scales of speed, acceleration and turning rates from the drivers.

        Each driver's floors (its step's ``floors``: a crank's tip speed and
        rates, an actuator's rate), the largest of each kind; SI units.
        ``speeds`` and ``accels`` are the drivers' rates, SI.
        """
        size = self.size
        result: list[Any] = []
        for step, speed, accel in zip(self.plan.drivers, speeds, accels, strict=True):
            floors = step.floors(speed, accel, size)
            if not result:
                result = list(floors)
                continue
            for index, value in enumerate(floors):
                if isinstance(value, np.ndarray) or isinstance(result[index], np.ndarray):
                    result[index] = np.fmax(result[index], value)
                else:
                    result[index] = max(result[index], value)
        return result[0], result[1], result[2], result[3]


def _jumping(plan: _Plan, lever: str) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """Return the reported joints and points whose acceleration jumps with ``lever``'s.

    The lever itself and every name solved from it: what is carried on it and
    the dyads downstream of those, in plan order.
    """
    moved = {lever}
    for step in plan.steps:
        if moved.intersection(step.requires):
            moved.update(step.defines)
    return (tuple(name for name in plan.joint_types if name in moved),
            tuple(name for name in plan.output_points if name in moved))


def assembly_text(error: AssemblyError, units: SceneUnits | None = None) -> str:
    """Return why a mechanism cannot assemble, naming links and lengths in ``units``.

    E.g. ``links coupler (150 mm) and rocker (80 mm) cannot reach from B to D
    (235 mm apart)``; the error's own reason where it carries no facts.
    """
    facts = error.facts
    if facts is None:
        return f'{error.dyad}: {error.reason}'
    units = SceneUnits() if units is None else units
    return FACT_TEXTS[facts['kind']](facts, units)


@dataclass(frozen=True)
class FollowedJoint:
    """The robot joint a scene driver follows.

    ``driver = reference + factor * (joint - joint_reference)``, in rad or m
    (SI whatever the scene's units). What ``urdf2scene`` (and the node in URDF
    mode, on its ``scene`` topic) writes under ``urdf_drivers`` for each driver
    of a robot's loops, so that a tool reading the robot's ``joint_states``
    (the browser view) knows each driver's value from the joint's, under its
    URDF name; ``factor`` (+1 or -1: the joint's sense against the scene's)
    scales its rate too. The solver never reads it.
    """

    driver: str
    joint: str
    joint_reference: float
    reference: float
    factor: float

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.joint, 'the joint a driver follows', (self, 'joint'))
        for key in ('joint_reference', 'reference', 'factor'):
            value = getattr(self, key)
            if not (isinstance(value, (int, float)) and math.isfinite(value)):
                msg = f'Expected a finite number, got {value!r}'
                raise SceneError(msg, (self, key))
        if self.factor == 0:
            raise SceneError('Expected a factor other than 0, got 0', (self, 'factor'))

    def driver_value(self, joint_value: float) -> float:
        """Return the driver's position at the joint's value (rad or m)."""
        return self.reference + self.factor * (joint_value - self.joint_reference)


@dataclass(frozen=True)
class RobotReaction:
    """Where a robot's ``reactions/JOINT`` acts in the scene of its loops, and how it turns.

    The node in URDF mode publishes each loop joint's reaction in its child
    link's axes (``frame``); in the scene it acts at point ``at`` on
    ``body``, and ``axes`` (2x3) takes a vector of the link's axes into the
    body's own frame (the one its masses' ``com`` is given in), which turns
    with the body. What ``urdf2scene`` (and the node's ``scene`` topic)
    writes under ``urdf_reactions`` for a robot with masses, so that a tool
    (the browser view) can draw those reactions in the scene's plane. The
    solver never reads it.
    """

    joint: str
    frame: str
    body: str
    at: str
    axes: tuple[tuple[float, float, float], tuple[float, float, float]]

    def __post_init__(self) -> None:
        """Validate the fields."""
        for key in ('frame', 'body', 'at'):
            value = getattr(self, key)
            if not isinstance(value, str) or not value:
                raise SceneError(f'Expected a name, got {value!r}', (self, key))
        rows = self.axes
        if not (isinstance(rows, (list, tuple)) and len(rows) == 2
                and all(isinstance(row, (list, tuple)) and len(row) == 3 for row in rows)
                and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                        and math.isfinite(v) for row in rows for v in row)):
            raise SceneError(f'Expected two rows of three finite numbers, got {rows!r}',
                             (self, 'axes'))
        object.__setattr__(self, 'axes', tuple(tuple(float(v) for v in row) for row in rows))

    def in_scene(self, force: tuple[float, float, float], angle: float) -> tuple[float, float]:
        """Return a force of the link's axes in the scene's plane, the body at ``angle`` (rad)."""
        (a, b, c), (d, e, f) = self.axes
        x = a * force[0] + b * force[1] + c * force[2]
        y = d * force[0] + e * force[1] + f * force[2]
        cos, sin = math.cos(angle), math.sin(angle)
        return cos * x - sin * y, sin * x + cos * y


@dataclass(frozen=True)
class Scene:
    """A planar mechanism: ground points, the driving crank, dyads, carried points.

    Construction validates names and dependencies and checks that the
    mechanism assembles at ``input.angle`` (plus ``input.turns``); a failure raises
    :class:`SceneError`.

    Parameters
    ----------
    name : str
        Identifier of the scene.
    ground : mapping of str to (float, float)
        Fixed points, m.
    input : Crank or None
        The driving crank of a scene with one crank (``inputs`` empty). Given
        ``inputs``, it is set to their first driver where that is a crank,
        else ``None``.
    dyads : tuple of RRR, RRP or RPR
        The dyads, solved in dependency order (file order where free).
    points : tuple of CarriedPoint
        Points carried rigidly by links.
    output_joints, output_points : tuple of str or None
        What to compute and report; ``None`` means everything.
    description : str
        Free text.
    pins : tuple of Pin
        Pins whose rubbing velocity is reported (``State.rubbing``).
    units : SceneUnits
        The units the scene was written in, for messages (its values are SI).
    imus : tuple of ImuSpec
        Inertial sensors on moving links (:mod:`mech_kinematics.imu`); the
        outputs always hold each one's link and point.
    inputs : tuple of Driver
        The drivers of a scene with several (or with an actuator or a
        slider), in order; a scene has ``input`` or ``inputs``, not both.
        Each is named by its crank link, its actuator or its slider, a name
        used once in the scene.
    urdf_drivers : tuple of FollowedJoint
        For a robot's loops: the URDF joint each driver follows (none or one
        per driver); the solver never reads it.
    urdf_reactions : tuple of RobotReaction
        For a robot's loops with masses: where each ``reactions/JOINT`` acts
        and how its link's axes turn into the plane; the solver never reads it.
    """

    name: str
    ground: Mapping[str, tuple[float, float]]
    input: Crank | None = None
    dyads: tuple[Item, ...] = ()
    points: tuple[CarriedPoint, ...] = ()
    outputs_joints: tuple[str, ...] | None = None
    outputs_points: tuple[str, ...] | None = None
    description: str = ''
    pins: tuple[Pin, ...] = ()
    units: SceneUnits = SceneUnits()
    imus: tuple[ImuSpec, ...] = ()
    inputs: tuple[Driver, ...] = ()
    gravity: tuple[float, float] | None = None
    masses: tuple[Mass, ...] = ()
    loads: tuple[Load, ...] = ()
    urdf_drivers: tuple[FollowedJoint, ...] = ()
    urdf_reactions: tuple[RobotReaction, ...] = ()
    _plan: _Plan = field(init=False, repr=False, compare=False)
    _solver: _Solver = field(init=False, repr=False, compare=False)
    #: The scene's inverse dynamics (:mod:`.forces`), ``None`` without masses, gravity, loads.
    dynamics: Dynamics | None = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.name, 'the scene name', (self, 'name'))
        inputs = tuple(self.inputs)
        object.__setattr__(self, 'inputs', inputs)
        first = inputs[0] if inputs else None
        if inputs and self.input is not None and self.input != first:
            msg = ('Expected a scene to have either input (one crank) or inputs (a list of '
                   'drivers), got both')
            raise SceneError(msg, (self, 'inputs'))
        if not inputs and self.input is None:
            msg = 'Expected a scene to have input (one crank) or inputs (a list of drivers)'
            raise SceneError(msg, (self, 'input'))
        if first is not None:
            # The v1 ``input`` is a crank (a motor turns too, but it is no crank).
            crank = cast(Crank, first) if first.v1_crank else None
            object.__setattr__(self, 'input', crank)
        object.__setattr__(self, 'dyads', tuple(self.dyads))
        object.__setattr__(self, 'points', tuple(self.points))
        object.__setattr__(self, 'pins', tuple(self.pins))
        full = _compile(self, None, None)
        solver = _Solver(self, full)
        drivers = self.drivers
        try:
            with warnings.catch_warnings():
                warnings.simplefilter('ignore', NearSingularWarning)
                if solver.single:
                    _execute(solver, drivers[0].start, 0.0, 0.0,  # positions only
                             cast(Crank, self.input).turns)
                else:
                    zeros = (0.0,) * len(drivers)
                    _execute_drivers(solver, tuple(d.start for d in drivers), zeros, zeros)
        except AssemblyError as error:
            dyad = next((step.dyad for step in full.steps
                         if step.owner is None and step.label == error.dyad), None)
            if solver.single:
                shown = cast(Crank, self.input).shown
                at = f'the initial crank angle {self.units.angle_text(shown)}'
            else:
                at = "the drivers' start positions " + ', '.join(
                    f'{d.name} = {d.position_text(d.start, self.units)}' for d in drivers)
            where = (drivers[0], 'angle' if solver.single else 'length')
            culprit = next((d for d in drivers if f'input {d.name}' == error.dyad), None)
            if culprit is not None:
                where = (culprit, culprit.position_key)
            msg = (f'Expected the mechanism to assemble at {at}, got '
                   f'{assembly_text(error, self.units)}')
            raise SceneError(msg, where if dyad is None else (dyad, '')) from None
        object.__setattr__(self, 'imus', tuple(self.imus))
        followed = tuple(self.urdf_drivers)
        object.__setattr__(self, 'urdf_drivers', followed)
        names = [d.name for d in self.drivers]
        for index, entry in enumerate(followed):
            if entry.driver not in names:
                msg = (f'Expected a driver of the scene ({", ".join(names)}), got '
                       f'{entry.driver!r}')
                raise SceneError(msg, (entry, 'driver'))
            if any(other.driver == entry.driver for other in followed[:index]):
                msg = f'Expected one joint per driver, got {entry.driver!r} twice'
                raise SceneError(msg, (entry, 'driver'))
        reactions = tuple(self.urdf_reactions)
        object.__setattr__(self, 'urdf_reactions', reactions)
        for entry in reactions:
            if entry.body not in full.graph.bodies or \
                    entry.at not in full.graph.bodies[entry.body].points:
                msg = (f'Expected a body of the scene and a point on it, got body '
                       f'{entry.body!r} and point {entry.at!r}')
                raise SceneError(msg, (entry, 'body'))
        object.__setattr__(self, '_plan', full)  # the graph, for the IMUs' links
        joints, points = imu_outputs(self, full.joint_types, self.outputs_joints,
                                     self.outputs_points)
        dynamics = self._dynamics_of(full)
        object.__setattr__(self, 'dynamics', dynamics)
        if dynamics is not None:  # what the forces read is computed and reported too
            needed_joints, needed_points = dynamics.needs()
            if joints is not None:
                joints = (*joints, *(n for n in full.joint_types
                                     if n in needed_joints and n not in joints))
            if points is not None:
                points = (*points, *(n for n in full.output_points
                                     if n in needed_points and n not in points))
        if joints is None and points is None:
            plan = full
        else:
            plan = _compile(self, joints, points)
            solver = _Solver(self, plan)
        object.__setattr__(self, '_plan', plan)
        object.__setattr__(self, '_solver', solver)

    def _dynamics_of(self, full: _Plan) -> Dynamics | None:
        """Return the scene's inverse dynamics, or None where it has no masses, gravity, loads."""
        object.__setattr__(self, 'masses', tuple(self.masses))
        object.__setattr__(self, 'loads', tuple(self.loads))
        if self.gravity is None and not self.masses and not self.loads:
            return None
        for items, kind in ((self.masses, Mass), (self.loads, Load)):
            for item in items:
                if not isinstance(item, kind):
                    what = 'masses' if kind is Mass else 'loads'
                    msg = f'Expected {what} as {kind.__name__} values, got {item!r}'
                    raise SceneError(msg, (self, what))
        gravity = (0.0, 0.0) if self.gravity is None else self.gravity
        if isinstance(gravity, (str, bytes)) or not isinstance(gravity, Sequence) \
                or len(gravity) != 2 or not all(isinstance(g, (int, float)) and not
                                                isinstance(g, bool) and math.isfinite(g)
                                                for g in gravity):
            msg = f'Expected gravity as [gx, gy] in m/s^2, finite, got {self.gravity!r}'
            raise SceneError(msg, (self, 'gravity'))
        g = (float(gravity[0]), float(gravity[1]))
        object.__setattr__(self, 'gravity', g)
        for imu in self.imus:   # an IMU's own gravity, where given, must be the scene's
            if tuple(imu.gravity) not in ((0.0, 0.0), g):
                msg = (f'Expected the gravity of IMU "{imu.name}" to be the scene\'s '
                       f'{list(g)} m/s^2 (both given must agree), got {list(imu.gravity)}')
                raise SceneError(msg, (imu, 'gravity'))
        return Dynamics(full.graph, self.masses, self.loads, g,
                        (*self.ground, *full.output_points), _size(self))

    @property
    def drivers(self) -> tuple[Driver, ...]:
        """The drivers in scene order (each has ``name``, ``joint_type``, ``start``, ...).

        A crank, an actuator or a slider each: ``name`` (its crank link,
        actuator or slider, also a joint of ``State.joints``), ``joint_type`` (``'revolute'`` or
        ``'prismatic'``), ``start`` (rad or m), ``speed`` and ``accel`` (the
        defaults: rad/s and rad/s^2, or m/s and m/s^2) and ``stroke``
        (inclusive limits, m, or ``None``).
        """
        if self.inputs:
            return self.inputs
        return (cast(Crank, self.input),)

    @property
    def graph(self) -> Graph:
        """The mechanism's bodies and joints (:mod:`.graph`): what every concern reads."""
        return self._plan.graph

    @property
    def free_length(self) -> float:
        """A length (m) that no actuator's closing length can exceed.

        Every driver's reach, every dyad's link lengths, every carried point's
        offset and the ground's diameter added up: no two points of the
        mechanism can be further apart, so an RRR link of that length cannot
        close. What a linear driver without stroke limits is swept over.
        """
        total = sum(driver.reach for driver in self.drivers)
        for dyad in self.dyads:
            total += sum(dyad.lengths())
        ground = [complex(x, y) for x, y in self.ground.values()]
        total += max((abs(a - b) for a in ground for b in ground), default=0.0)
        for point in self.points:
            total += math.hypot(*point.local)
        return float(total)

    @property
    def single_crank(self) -> bool:
        """Whether one crank drives it (``input:``, or ``inputs:`` of one crank)."""
        return self._solver.single

    @property
    def output_joints(self) -> tuple[str, ...]:
        """Names of the joints reported, in order."""
        return self._plan.output_joints

    @property
    def output_points(self) -> tuple[str, ...]:
        """Names of the points reported, in order."""
        return self._plan.output_points

    @property
    def joint_types(self) -> dict[str, JointType]:
        """Joint name -> ``'revolute'`` or ``'prismatic'``, for the reported joints."""
        return dict(self._plan.joint_types)

    @property
    def intermittent(self) -> tuple[str, ...]:
        """Its intermittent (Geneva) levers, whose accelerations jump (``State.jumps``)."""
        return tuple(self._solver.levers)

    def jumps_at(self, angle: float, *, turns: int = 0) -> bool:
        """Return whether a value jumps at crank ``angle`` (rad) plus ``turns`` whole turns.

        True within rounding of an intermittent (Geneva) wheel's engagement
        instant, where :func:`~.solve.solve` answers the side after the jump
        and gives the other in ``State.jumps``: the solve's own test, for one
        angle without solving (the node counts these instants).
        """
        return any(lever.jumps_at(angle, turns) for lever in self._solver.levers.values())

    @property
    def pin_bodies(self) -> dict[str, tuple[str, str]]:
        """Pin point -> the two bodies it joins (a link, ``ground`` or a slider block)."""
        return {rub.point: rub.names for rub in self._plan.rubs}


def _read_only_scalar(x: float) -> Any:
    """Return ``x`` as a read-only 0-d float64 array."""
    one = np.array(x, dtype=np.float64)
    one.flags.writeable = False
    return one
