# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's side of its parameters: declared, checked when set, applied to the clock.

:mod:`~mech_kinematics.ros.parameters` holds the table and the rules (pure);
this module puts them on a node. :class:`DriverParameters` (pure) is what a
scene's drivers add: their ``inputs.NAME.*`` parameters, the first crank's
two v1 names (``crank_speed_rpm`` and ``crank_accel``, one value each with
``inputs.FIRST.speed_rpm`` and ``inputs.FIRST.accel``), and which drive
change each parameter asks of which driver's time base. :class:`NodeParameters`
declares them on the node with their descriptors and runs rclpy's three
callbacks: before a set (an integer given for a double becomes a double,
rclcpp#979; the other name of an aliased value is added; a read-only set is
logged), the validation (a value refused with its reason, a rule between
parameters, a drive that leaves an actuator's stroke at once) and after it
(the clock's settings and the drive changes handed to the tick thread's
driver, which applies them at its next instant not published).

Every refusal is logged once with its reason, besides the service's answer;
while the node starts, the first one is kept (:attr:`NodeParameters.start_refusal`)
for ``main`` to say in its one line.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any, TYPE_CHECKING

from rcl_interfaces.msg import ParameterDescriptor, SetParametersResult
from rclpy.parameter import Parameter

from .drive import (DEFAULT_MAX_CRANK_SPEED_RPM, drive_start, DriveStart,
                    max_crank_speed_default, MAX_SPEED_KEY, stroke_refusal, timebase_kind)
from .parameters import (CATCH_UP, catch_up_window_ns, driver_parameters, first_crank_aliases,
                         joint_refusal, PARAMETERS, ParameterSpec, rate_default, refusal, spec)
from .schedule import period_ns_from_rate
from ..errors import SceneError

if TYPE_CHECKING:
    from rclpy.node import Node

    from .driver import TickDriver
    from .wrenches import ForcesTick
    from ..solver.base import Driver
    from ..solver.mechanism import Scene

__all__ = ['DOUBLES', 'DRIVE', 'DriverParameters', 'JOINT_RULES', 'NodeParameters', 'READ_ONLY',
           'START_LOGGED', 'description', 'spec_default_is_none']

#: The drive parameters, applied by the tick thread at an instant it has not published
#: (with each driver's ``inputs.NAME.*``, declared when the scene is loaded).
DRIVE = ('crank_speed_rpm', 'crank_accel', 'max_crank_speed_rpm')
#: Parameters whose values one rule ties together (parameters.joint_refusal).
JOINT_RULES = (*DRIVE, 'drive', 'markers')
DOUBLES = frozenset(p.name for p in PARAMETERS if p.kind == 'double')
READ_ONLY = frozenset(p.name for p in PARAMETERS if p.read_only)
#: The node's parameters that change while running only through its forces tick (which
#: lists them among its own, :meth:`RobotForcesTick.parameters
#: <mech_kinematics.ros.robot_forces.RobotForcesTick.parameters>`); refused elsewhere.
CHANGED_BY_FORCES = frozenset({'payloads', 'link_forces', 'link_torques'})
#: The parameters of the start's log line, in order (the scene's own first), before the drivers'.
START_LOGGED = ('scene', 'drive', 'crank_speed_rpm', 'crank_accel', 'max_crank_speed_rpm',
                'rate_hz', 'late_ticks', 'max_catch_up_s', 'max_lateness_ms',
                'max_relative_error', 'frame_id', 'tf_rate_hz', 'tf_prefix', 'use_sim_time',
                'markers', 'managed', 'extra_joints', 'effort', 'stamp_jump_back_s')


def description(p: ParameterSpec) -> str:
    """Return the parameter's description with its unit and range, for ``ros2 param describe``."""
    if p.low is not None and p.high is not None:
        return f'{p.description} [{p.unit}, {p.low:g} to {p.high:g}]'
    if p.choices:
        return f'{p.description} [{" | ".join(p.choices)}]'
    return p.description


def spec_default_is_none(name: str) -> bool:
    """Return whether parameter ``name`` stays unset until the scene gives it."""
    try:
        return spec(name).default is None
    except KeyError:
        return False


class DriverParameters:
    """The parameters a scene's drivers add, and what setting each one asks of the drive.

    Parameters
    ----------
    drivers : sequence of Driver
        The scene's drivers, in order (none: before a scene is loaded).

    Attributes
    ----------
    specs : dict of str to ParameterSpec
        Every driver's ``inputs.NAME.*`` by name (:func:`~.parameters.driver_parameters`).
    aliases : dict of str to str
        ``crank_speed_rpm`` and ``crank_accel`` to the first crank's names
        (empty when the first driver is not a crank).
    drivers : dict of str to Driver
        The drivers by name.
    keys : dict of str to list of (str, str)
        For each parameter that drives, the (driver, time base keyword) pairs
        it sets: ``inputs.NAME.<key>`` its driver's, the aliases the first
        crank's, ``max_crank_speed_rpm`` every time base's bound that takes one.
    """

    def __init__(self, drivers: Sequence[Driver] = ()) -> None:
        self.aliases = first_crank_aliases(drivers)
        self.drivers = {d.name: d for d in drivers}
        self.specs: dict[str, ParameterSpec] = {}
        self.keys: dict[str, list[tuple[str, str]]] = {}
        for d in drivers:
            for p in driver_parameters([d]):
                self.specs[p.name] = p
                self.keys[p.name] = [(d.name, p.name.rsplit('.', 1)[1])]
        for old, new in self.aliases.items():
            self.keys[old] = self.keys[new]
        self.keys[DRIVE[2]] = [(d.name, MAX_SPEED_KEY) for d in drivers
                               if MAX_SPEED_KEY in timebase_kind(d).CHANGES]

    def of(self, driver: Driver) -> list[ParameterSpec]:
        """Return the parameters of ``driver``."""
        base = f'inputs.{driver.name}.'
        return [p for name, p in self.specs.items() if name.startswith(base)]

    def with_aliases(self, parameters: list[Parameter]) -> list[Parameter]:
        """Add the other name of the first crank's speed or acceleration, set to the same value.

        ``crank_speed_rpm`` and ``inputs.FIRST.speed_rpm`` (and ``crank_accel``
        and ``inputs.FIRST.accel``) are one value: setting either sets both,
        atomically. Given both with different values, the second is refused.
        """
        names = {p.name for p in parameters}
        added = []
        for old, new in self.aliases.items():
            for given, other in ((old, new), (new, old)):
                if given in names and other not in names:
                    value = next(p for p in parameters if p.name == given).value
                    added.append(Parameter(other, Parameter.Type.DOUBLE, value)
                                 if isinstance(value, float) else Parameter(other, value=value))
        return [*parameters, *added]

    def requests(self, changes: Mapping[str, Any]) -> dict[str, dict[str, float]]:
        """Return the drive changes asked by accepted ``changes``: {driver: {keyword: value}}."""
        requests: dict[str, dict[str, float]] = {}
        for name, value in changes.items():
            for drive, key in self.keys.get(name, ()):
                requests.setdefault(drive, {})[key] = float(value)
        return requests

    def stroke_changes(self, parameters: Sequence[Parameter]
                       ) -> dict[str, dict[str, tuple[str, float]]]:
        """Return the changes to a driver with a stroke: {driver: {keyword: (name, value)}}."""
        changes: dict[str, dict[str, tuple[str, float]]] = {}
        for p in parameters:
            for drive, key in self.keys.get(p.name, ()):
                if self.drivers[drive].stroke is not None and isinstance(p.value, (int, float)):
                    changes.setdefault(drive, {})[key] = (p.name, float(p.value))
        return changes


class NodeParameters:
    """The node's parameters on ``node``: declared at once, checked and applied when set.

    Parameters
    ----------
    node : rclpy.node.Node
        The node they are declared on.
    driver : TickDriver
        The tick thread's clock driver: the clock's settings and the drive
        changes go to it.
    on_change : callable
        ``on_change(changes, requested)`` after every accepted set, with the
        values set by name and whether a drive change was asked (for what
        the node applies itself: ``/tf``'s rate, the tolerance, ...).
    """

    def __init__(self, node: Node, driver: TickDriver,
                 on_change: Callable[[dict[str, Any], bool], None]) -> None:
        self.node = node
        self.driver = driver
        self.on_change = on_change
        #: While True (until main() has started the node), refusals are not logged here:
        #: main() says the one line of a refused start.
        self.starting = True
        self.start_refusal = ''
        #: Whether a scene is loaded (a set is logged then).
        self.loaded = False
        self.drivers = DriverParameters()
        #: A scene's forces' parameters (``gravity``, ``loads.NAME.*``) by name, once declared.
        self.forces: dict[str, ParameterSpec] = {}
        #: The forces tick (the forces' parameters are checked against its masses).
        self._forces_tick: ForcesTick | None = None
        self._own: dict[str, bool] = {}
        self._declaring = False
        node.add_pre_set_parameters_callback(self._pre_set)
        node.add_on_set_parameters_callback(self._validate)

    def declare(self) -> None:
        """Declare every parameter of the table; give the clock driver their values.

        Raises
        ------
        rclpy.exceptions.ParameterException
            If a value given at start is refused (:attr:`start_refusal` says why).
        """
        node, driver = self.node, self.driver
        for p in PARAMETERS:
            # The range is in the description, not in floating_point_range: rclpy would
            # check that before _validate and answer with a reason of its own.
            descriptor = ParameterDescriptor(description=description(p),
                                             read_only=p.read_only, dynamic_typing=True)
            # A default of None leaves the parameter unset until the scene gives it.
            value = node.declare_parameter(p.name, p.default, descriptor).value
            if p.kind == 'double' and type(value) is int:
                # -p rate_hz:=500 (rclcpp#979): store the double the parameter is.
                node.set_parameters([Parameter(p.name, Parameter.Type.DOUBLE, float(value))])
        node.add_post_set_parameters_callback(self._apply)
        period_ns = period_ns_from_rate(self.value('rate_hz'))
        driver.period_ns = period_ns
        driver.max_behind_ns = catch_up_window_ns(self.value('max_catch_up_s'), period_ns)
        driver.catch_up = self.value('late_ticks') == CATCH_UP

    def value(self, name: str) -> Any:
        """Return parameter ``name``'s value."""
        return self.node.get_parameter(name).value

    def declared(self, name: str, default: float) -> float:
        """Return parameter ``name``'s value, or ``default`` while it is not declared yet."""
        return float(self.value(name)) if self.node.has_parameter(name) else float(default)

    # -- a scene's drivers ----------------------------------------------------

    def declare_drivers(self, scene: Scene) -> list[DriveStart]:
        """Fill the scene's defaults, declare each driver's ``inputs.NAME.*``; return the starts.

        The first crank's take ``crank_speed_rpm`` and ``crank_accel`` as their
        defaults (the two are one value each, see :meth:`DriverParameters.with_aliases`);
        given both names at start with different values, the node refuses to
        start (a ``SceneError``).
        """
        drivers = scene.drivers
        params = DriverParameters(drivers)
        first = drivers[0] if params.aliases else None
        given_rpm = self.value('crank_speed_rpm')      # a speed set at start raises the bound
        given = {name for name in DRIVE[:2] if self.value(name) is not None}
        defaults = {'max_crank_speed_rpm': max_crank_speed_default(drivers, given_rpm)}
        if first is not None:
            defaults.update(crank_speed_rpm=rate_default(first), crank_accel=first.accel)
        unset = [Parameter(name, Parameter.Type.DOUBLE, float(value))
                 for name, value in defaults.items() if self.value(name) is None]
        if unset:
            self._set_atomically(scene, unset)
        self.drivers = params
        self._own = {d.name: d is not first or given_rpm is None for d in drivers}
        aliased = {new: old for old, new in params.aliases.items()}
        self._declaring = True
        try:
            for p in params.specs.values():
                if self.node.has_parameter(p.name):
                    continue
                default = self.value(aliased[p.name]) if p.name in aliased else p.default
                descriptor = ParameterDescriptor(description=description(p),
                                                 dynamic_typing=True)
                value = self.node.declare_parameter(p.name, default, descriptor).value
                if type(value) is int:
                    self.node.set_parameters(
                        [Parameter(p.name, Parameter.Type.DOUBLE, float(value))])
            for old, new in params.aliases.items():
                if self.value(old) == self.value(new):
                    continue
                if old in given:
                    msg = (f'{old} and {new} are the same value: expected one of them or equal '
                           f'values, got {self.value(old)!r} and {self.value(new)!r}')
                    raise SceneError(msg)
                self._set_atomically(
                    scene, [Parameter(old, Parameter.Type.DOUBLE, float(self.value(new)))])
        finally:
            self._declaring = False
        return [drive_start(d, self.driver_values(d), self._own[d.name]) for d in drivers]

    # -- a scene's forces ------------------------------------------------------

    def declare_forces(self, forces: ForcesTick) -> dict[str, Any]:
        """Declare the forces' parameters (``gravity``, each load's ``loads.NAME.*``); return them.

        The parameters are the forces tick's (:meth:`ForcesTick.parameters
        <mech_kinematics.ros.wrenches.ForcesTick.parameters>`: a scene's, or a
        robot's three-component ``gravity``), with its defaults; a value given
        at start is checked like one set later (refused: the node does not start).
        """
        self.forces = {p.name: p for p in forces.parameters()}
        self._forces_tick = forces
        self._declaring = True
        try:
            for p in self.forces.values():
                if not self.node.has_parameter(p.name):
                    descriptor = ParameterDescriptor(description=description(p),
                                                     dynamic_typing=True)
                    self.node.declare_parameter(p.name, p.default, descriptor)
                value = self.value(p.name)
                if p.kind in ('xy', 'xyz') and not isinstance(value, str) and \
                        any(type(v) is int for v in value):
                    self.node.set_parameters([Parameter(
                        p.name, Parameter.Type.DOUBLE_ARRAY, [float(v) for v in value])])
                elif type(value) is int:
                    self.node.set_parameters(
                        [Parameter(p.name, Parameter.Type.DOUBLE, float(value))])
        finally:
            self._declaring = False
        return {name: self.value(name) for name in self.forces}

    def force_changes(self, changes: Mapping[str, Any]) -> dict[str, Any]:
        """Return the accepted ``changes`` that are the forces' parameters."""
        return {name: value for name, value in changes.items() if name in self.forces}

    def _set_atomically(self, scene: Scene, parameters: list[Parameter]) -> None:
        result = self.node.set_parameters_atomically(parameters)
        if not result.successful:
            raise SceneError(f'{scene.name}: {result.reason}')

    def driver_values(self, driver: Driver) -> dict[str, float]:
        """Return ``driver``'s parameters by their last part, and the speed bound's value."""
        values = {p.name.rsplit('.', 1)[1]: self.declared(p.name, p.default)
                  for p in self.drivers.of(driver)}
        values[MAX_SPEED_KEY] = self.declared(DRIVE[2], DEFAULT_MAX_CRANK_SPEED_RPM)
        return values

    def start_line(self, scene: Scene, effective: Mapping[str, Any] | None = None,
                   robot: Any = None) -> str:
        """Return the start's log line: the scene, its outputs and the effective parameters.

        ``effective``: values the node resolved for parameters left unset
        (``extra_joints``); ``robot``: in URDF mode, the robot (its joints
        are the ones published).
        """
        names = (*START_LOGGED, *self.drivers.specs, *self.forces)
        effective = effective or {}
        settings = ', '.join(f'{name}={effective.get(name, self.value(name))!r}'
                             for name in names[1:])
        if robot is not None:
            origin = 'robot_description' if self.value('robot_description') else \
                self.value('scene')
            return (f'robot {robot.name!r} ({origin}; its loops: scene {scene.name!r}): '
                    f'joints {list(robot.joint_names)}, actuated {list(robot.actuated)}; '
                    f'loop_closures={self.value("loop_closures")!r}, '
                    f'reference_pose={list(self.value("reference_pose") or [])!r}, '
                    f'payloads={list(self.value("payloads") or [])!r}, {settings}')
        return (f'scene {scene.name!r} ({self.value("scene")}): joints '
                f'{list(scene.output_joints)}, points {list(scene.output_points)}; {settings}')

    # -- rclpy's callbacks ----------------------------------------------------

    def _is_double(self, name: str) -> bool:
        return name in DOUBLES or name in self.drivers.specs or (
            name in self.forces and self.forces[name].kind == 'double')

    def _pre_set(self, parameters: list[Parameter]) -> list[Parameter]:
        """Turn an integer given for a double into a double (rclcpp#979); log read-only sets.

        rclpy refuses a read-only parameter before the validation callback
        sees it; it is logged here, so that every refusal is.
        """
        for p in parameters:
            if p.name in READ_ONLY and not self.starting:
                self.node.get_logger().warning(
                    f'parameter refused: {p.name}: read-only (set it at start), got {p.value!r}')
        parameters = [Parameter(p.name, Parameter.Type.DOUBLE, float(p.value))
                      if self._is_double(p.name) and p.type_ == Parameter.Type.INTEGER else
                      Parameter(p.name, Parameter.Type.DOUBLE_ARRAY, [float(v) for v in p.value])
                      if p.name in self.forces and p.type_ == Parameter.Type.INTEGER_ARRAY
                      else p for p in parameters]
        if self._declaring:
            return parameters
        return self.drivers.with_aliases(parameters)

    def _validate(self, parameters: list[Parameter]) -> SetParametersResult:
        """Refuse a value of the wrong type or out of range, or one that breaks a joint rule."""
        reason = None
        specs = self.drivers.specs
        known = {**specs, **self.forces} if self.forces else specs
        for p in parameters:
            if p.type_ == Parameter.Type.NOT_SET and not self.node.has_parameter(p.name) \
                    and spec_default_is_none(p.name):
                continue    # declared unset: the scene gives it at configure
            reason = refusal(p.name, p.value, known or None)
            if reason is None and p.name in CHANGED_BY_FORCES and not self.starting \
                    and p.name not in self.forces:
                reason = (f'{p.name}: Expected a robot whose forces the node publishes (URDF '
                          f'mode, its links carrying <inertial>) to change it while running, '
                          f'got {p.value!r}: set it at start')
            if reason is not None:
                break
        if reason is None:
            rules = (*JOINT_RULES, *specs)
            # The values being set first, so that a refusal names what was set.
            current = {p.name: p.value for p in parameters if p.name in rules}
            current.update((name, self.value(name)) for name in rules
                           if name not in current and self.node.has_parameter(name))
            reason = joint_refusal({k: v for k, v in current.items() if v is not None})
        if reason is None:
            reason = self._stroke_refusal(parameters)
        if reason is None:
            reason = self._forces_refusal(parameters)
        if reason is None:
            return SetParametersResult(successful=True)
        # Every refusal is logged once, with its reason, besides the service's answer
        # (at start, main() says it in its one line).
        if self.starting:
            self.start_refusal = self.start_refusal or reason
        else:
            self.node.get_logger().warning(f'parameter refused: {reason}')
        return SetParametersResult(successful=False, reason=reason)

    def _forces_refusal(self, parameters: list[Parameter]) -> str | None:
        """Return why a new ``gravity`` or load gives forces beyond the doubles, or None."""
        changes = {p.name: p.value for p in parameters if p.name in self.forces}
        if not changes or self._forces_tick is None:
            return None
        values = {name: self.value(name) if self.node.has_parameter(name) else spec.default
                  for name, spec in self.forces.items()}
        values.update(changes)
        return self._forces_tick.parameters_refusal(values)

    def _stroke_refusal(self, parameters: list[Parameter]) -> str | None:
        """Return why an actuator's drive change is refused (:func:`.drive.stroke_refusal`)."""
        for name, change in self.drivers.stroke_changes(parameters).items():
            driver = self.drivers.drivers[name]
            current = self.driver.drives.get(name)
            timebase = current.timebase if current is not None else None
            now = self.node.get_clock().now().nanoseconds if timebase is not None else 0
            reason = stroke_refusal(driver, timebase, now, change, self.driver_values(driver))
            if reason is not None:
                return reason
        return None

    def _apply(self, parameters: list[Parameter]) -> None:
        """Hand accepted values to the tick thread's driver: it applies them at its next tick."""
        changes = {p.name: p.value for p in parameters if p.type_ != Parameter.Type.NOT_SET}
        driver = self.driver
        if 'rate_hz' in changes:
            driver.period_ns = period_ns_from_rate(changes['rate_hz'])
        if 'late_ticks' in changes:
            driver.catch_up = changes['late_ticks'] == CATCH_UP
        if 'max_catch_up_s' in changes or 'rate_hz' in changes:
            # At most one history's depth of instants a burst (issue 21, item 7).
            driver.max_behind_ns = catch_up_window_ns(
                changes.get('max_catch_up_s', self.value('max_catch_up_s')),
                period_ns_from_rate(changes.get('rate_hz', self.value('rate_hz'))))
        requests = self.drivers.requests(changes)
        for drive, request in requests.items():
            if drive in driver.drives:
                driver.request(drive, **request)
        self.on_change(changes, bool(requests))
        logged = ', '.join(f'{p.name}={p.value!r}' for p in parameters)
        if self.loaded:
            self.node.get_logger().info(f'parameters set: {logged}')
