# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""ROS 2 node ``mech_kinematics``: the kinematic state of a linkage on an exact time grid.

The node is an adapter around the pure solver. It declares the parameters of
:mod:`~mech_kinematics.ros.parameters`, and follows the ROS 2 node lifecycle
(configure loads the scene and creates the publishers, activate starts the
tick thread, deactivate stops it, cleanup drops the scene); with
``managed: false`` (the default) it configures and activates itself at start.

The tick thread reads the clock and asks the pure driver
(:mod:`~mech_kinematics.ros.driver`) what to publish: every instant of an
exact grid (tick k is stamped ``t0 + k * period`` in integer nanoseconds; a
late wake-up catches up the instants it missed or, with ``late_ticks: skip``,
only the latest), and the crank at each of them from its exact time base. For
each instant it solves and publishes three messages rendered from
pre-serialized templates (:mod:`~mech_kinematics.ros.messages`). Drive
parameter changes are handed to the driver, which applies them at the next
instant not published, so a published stamp is never rewritten.
The executor serves the parameter and lifecycle services, ``/clock``, the
1 Hz diagnostics (:mod:`~mech_kinematics.ros.diagnostics`) and, with
``markers: true``, the RViz markers (at most 30 a second, built in the
executor's thread from samples the tick thread hands over).

Run it with ``ros2 run mech_kinematics kinematics_node`` or
``python -m mech_kinematics.kinematics_node [--ros-args ...]``.
"""

from __future__ import annotations

import contextlib
import copy
import ctypes
from dataclasses import replace
import gc
import math
import random
import sys
import threading
import time
import traceback
from typing import Any, NamedTuple
import warnings

from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rcl_interfaces.msg import ParameterDescriptor, SetParametersResult
import rclpy
from rclpy.clock import Clock, ClockType, JumpThreshold
from rclpy.duration import Duration
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn
from rclpy.logging import get_logger
from rclpy.parameter import Parameter
from rclpy.qos import QoSDurabilityPolicy, QoSHistoryPolicy, QoSProfile, QoSReliabilityPolicy
from rclpy.qos_overriding_options import QoSOverridingOptions, QoSPolicyKind
from rclpy.signals import install_signal_handlers, SignalHandlerOptions
from sensor_msgs.msg import Imu, JointState
from std_msgs.msg import String
from trajectory_msgs.msg import JointTrajectory, MultiDOFJointTrajectory
from visualization_msgs.msg import MarkerArray

import mech_kinematics as mk
from . import topics
from .diagnostics import solver_status, Status, TickStats, timing_status
from .driver import TickDriver
from .imus import ImuFrames, ImuMessages
from .markers import marker_array_from_state, marker_size_from_space, MarkerThrottle
from .messages import TickMessages
from .parameters import (CATCH_UP, catch_up_window_ns, driver_parameters, first_crank_aliases,
                         joint_refusal, PARAMETERS, ParameterSpec, refusal, rpm_parameter, spec,
                         STATE_DEPTH, TOPIC)
from .schedule import period_ns_from_rate
from .startup import catch_stop_signals, start_refusal, stop_asked
from .tf import static_tf_message, TfMessages
from .ticker import compile_tick, general_tick, tick_function
from .timebase import ActuatorTimebase, CrankSample, CrankTimebase
from .topic_drive import RefusedInput, TopicDrive, TopicInput
from ..geometry.assembly import assembly_summary
from ..geometry.diagrams import space_from_state, strokes_from_scene
from ..geometry.frames import angle_joints, frames_from_scene, origin_points, sensor_offsets
from ..geometry.instant_centres import full_scene
from ..geometry.urdf import urdf_from_scene
from ..scene import scene_text
from ..units import NS_PER_S, rad_per_s_from_rpm

__all__ = ['KinematicsNode', 'NODE_NAME', 'TickThreadError', 'main']

NODE_NAME = 'mech_kinematics'

#: Default bound on the crank speed (raised to the scene's speed if that is faster).
DEFAULT_MAX_CRANK_SPEED_RPM = 10_000.0
#: An instant published more than min(period / 2, LATE_NS) after it is counted late.
LATE_NS = 1_000_000
#: Longest single sleep of the tick thread, so that a stop is seen quickly.
MAX_SLEEP_NS = 50_000_000
#: Longest time another thread may hold the GIL before the tick thread gets it, s.
SWITCH_INTERVAL_S = 0.0005
#: A scene of more dyads and points than this compiles its tick in the background (about
#: 25 ms a step) while the general solver serves (:meth:`KinematicsNode._setup_solve`).
BACKGROUND_STEPS = 16
#: What the node logs of a scene whose tick does not compile.
GENERAL_SOLVER = 'the scene is solved by the general solver (not compiled)'
#: The node-private, hidden topic on which each node says when it started (transient local,
#: so that a newcomer of the same name hears an older node as soon as they are matched).
INSTANCE_TOPIC = '~/_instance'
#: The drive parameters, applied by the tick thread at an instant it has not published
#: (with each driver's ``inputs.NAME.*``, declared when the scene is loaded).
DRIVE = ('crank_speed_rpm', 'crank_accel', 'max_crank_speed_rpm')
#: What the bound on the crank speed sets in each crank's time base.
MAX_SPEED_KEY = 'max_speed_rpm'
#: A crank's joint type (``Driver.joint_type``); an actuator's is prismatic.
REVOLUTE = 'revolute'
#: Parameters whose values one rule ties together (parameters.joint_refusal).
JOINT_RULES = (*DRIVE, 'drive', 'markers')
#: History depth of the input_joint_states subscription (a second of input at 1 kHz, as the
#: state publishers keep: a stall of the executor loses no message).
INPUT_DEPTH = 1000
#: Input messages one call of the subscription's callback takes from its queue at most.
INPUT_BURST = 100
DOUBLES = frozenset(p.name for p in PARAMETERS if p.kind == 'double')
READ_ONLY = frozenset(p.name for p in PARAMETERS if p.read_only)

#: /tf and /tf_static as tf2's broadcasters offer them.
TF_DEPTH = 100
#: Every publisher accepts ``qos_overrides./TOPIC.publisher.POLICY`` for these policies.
QOS_OVERRIDES = QoSPolicyKind.HISTORY, QoSPolicyKind.DEPTH, QoSPolicyKind.RELIABILITY, \
    QoSPolicyKind.DURABILITY

_LEVELS = {0: DiagnosticStatus.OK, 1: DiagnosticStatus.WARN, 2: DiagnosticStatus.ERROR,
           3: DiagnosticStatus.STALE}


def _set_timer_slack(ns: int) -> None:
    """Ask Linux for a tight wake-up of this thread (the default slack is 50 us)."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(29, ctypes.c_ulong(ns), 0, 0, 0)   # PR_SET_TIMERSLACK
    except (OSError, AttributeError):
        pass  # no prctl here: keep the default timer slack


def _description(p: ParameterSpec) -> str:
    """Return the parameter's description with its unit and range, for ``ros2 param describe``."""
    if p.low is not None and p.high is not None:
        return f'{p.description} [{p.unit}, {p.low:g} to {p.high:g}]'
    if p.choices:
        return f'{p.description} [{" | ".join(p.choices)}]'
    return p.description


def _qos_options() -> QoSOverridingOptions:
    return QoSOverridingOptions(policy_kinds=QOS_OVERRIDES)


def _tf_qos(static: bool) -> QoSProfile:
    """Return the profile of ``/tf`` (volatile) or ``/tf_static`` (transient local, depth 1)."""
    return QoSProfile(history=QoSHistoryPolicy.KEEP_LAST, depth=1 if static else TF_DEPTH,
                      reliability=QoSReliabilityPolicy.RELIABLE,
                      durability=QoSDurabilityPolicy.TRANSIENT_LOCAL if static
                      else QoSDurabilityPolicy.VOLATILE)


def _state_qos() -> QoSProfile:
    """Return a new profile of the state publishers (overrides change the profile they get)."""
    return QoSProfile(history=QoSHistoryPolicy.KEEP_LAST, depth=STATE_DEPTH,
                      reliability=QoSReliabilityPolicy.RELIABLE,
                      durability=QoSDurabilityPolicy.VOLATILE)


def diagnostic_status_from(status: Status) -> DiagnosticStatus:
    """Return ``status`` as a ``diagnostic_msgs/DiagnosticStatus``."""
    return DiagnosticStatus(level=_LEVELS[status.level], name=status.name,
                            message=status.message, hardware_id=status.hardware_id,
                            values=[KeyValue(key=k, value=v) for k, v in status.values])


class TickThreadError(RuntimeError):
    """The tick thread stopped on an unexpected error (logged where it happened)."""


class KinematicsNode(LifecycleNode):
    """Publish the kinematic state of a scene on ``joint_states`` and friends at ``rate_hz``.

    Raises
    ------
    rclpy.exceptions.ParameterException
        If a parameter given at start is refused.
    """

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(NODE_NAME, **kwargs)
        #: While True (until main() has started the node), refusals are not logged here:
        #: main() says the one line of a refused start.
        self.starting = True
        self.start_refusal = ''
        try:
            self._declare()
        except BaseException as error:
            logger_name = self.get_logger().name
            reason = self.start_refusal or ' '.join(str(error).split()) or type(error).__name__
            self.destroy_node()
            if isinstance(error, Exception):
                raise StartError(reason, logger_name) from None
            raise

    # -- parameters -----------------------------------------------------------

    def _declare(self) -> None:
        self.scene: mk.Scene | None = None
        self._assembly = ''
        self.configure_error = ''
        self.failed = False
        self._stop = threading.Event()
        self._clock_event = threading.Event()
        self._thread: threading.Thread | None = None
        self._stats = TickStats(mk.NEAR_SINGULAR)
        self._waiting_for_clock = False
        # The clock as a pure driver, at the parameters' defaults until they are declared.
        self._driver = TickDriver(period_ns_from_rate(spec('rate_hz').default),
                                  round(spec('max_catch_up_s').default * NS_PER_S),
                                  spec('late_ticks').default == CATCH_UP)
        self._state_publishers: list[Any] = []
        self._pub_markers: Any = None
        self._compiling: object | None = None     # the scene whose tick compiles in the background
        self._compile_later: threading.Thread | None = None
        self._imus: ImuMessages | None = None
        self._imu_frames: ImuFrames | None = None
        self._topic: TopicDrive | None = None
        self._input: Any = None
        self._input_active = False
        # The scene's drivers' parameters, set at configure (parameters.driver_parameters).
        self._driver_specs: dict[str, ParameterSpec] = {}
        self._aliases: dict[str, str] = {}
        self._drive_keys: dict[str, list[tuple[str, str]]] = {}
        self._drivers_by_name: dict[str, Any] = {}
        self._declaring = False
        self._failure_guard = self.create_guard_condition(self._on_failure)
        self.add_pre_set_parameters_callback(self._pre_set)
        self.add_on_set_parameters_callback(self._validate)
        for p in PARAMETERS:
            # The range is in the description, not in floating_point_range: rclpy would
            # check that before _validate and answer with a reason of its own.
            descriptor = ParameterDescriptor(description=_description(p),
                                             read_only=p.read_only, dynamic_typing=True)
            # A default of None leaves the parameter unset until the scene gives it.
            value = self.declare_parameter(p.name, p.default, descriptor).value
            if p.kind == 'double' and type(value) is int:
                # -p rate_hz:=500 (rclcpp#979): store the double the parameter is.
                self.set_parameters([Parameter(p.name, Parameter.Type.DOUBLE, float(value))])
        self.add_post_set_parameters_callback(self._apply)
        self.managed = bool(self.get_parameter('managed').value)
        self.frame_id = self.get_parameter('frame_id').value
        rate_period_ns = period_ns_from_rate(self.get_parameter('rate_hz').value)
        self._driver.period_ns = rate_period_ns
        self._driver.max_behind_ns = catch_up_window_ns(
            self.get_parameter('max_catch_up_s').value, rate_period_ns)
        self._driver.catch_up = self.get_parameter('late_ticks').value == CATCH_UP
        self._tf_period_ns = self._tf_period(self.get_parameter('tf_rate_hz').value)
        self._max_error = float(self.get_parameter('max_relative_error').value)
        self._tf: TfMessages | None = None
        self._next_tf = 0
        self._pub_diagnostics = self.create_publisher(
            DiagnosticArray, topics.DIAGNOSTICS, 10, qos_overriding_options=_qos_options())
        self._diagnostics_timer = self.create_timer(
            1.0, self._publish_diagnostics, clock=Clock(clock_type=ClockType.STEADY_TIME))
        self._jump_handle = self.get_clock().create_jump_callback(
            JumpThreshold(min_forward=Duration(nanoseconds=1), min_backward=None,
                          on_clock_change=True),
            post_callback=lambda _jump: self._clock_event.set())

    @staticmethod
    def _tf_period(rate_hz: float) -> int | None:
        return None if rate_hz <= 0.0 else period_ns_from_rate(rate_hz)

    def _value(self, name: str) -> Any:
        return self.get_parameter(name).value

    def _declared(self, name: str, default: float) -> float:
        """Return parameter ``name``'s value, or ``default`` while it is not declared yet."""
        return float(self._value(name)) if self.has_parameter(name) else float(default)

    def _is_double(self, name: str) -> bool:
        return name in DOUBLES or name in self._driver_specs

    def _pre_set(self, parameters: list[Parameter]) -> list[Parameter]:
        """Turn an integer given for a double into a double (rclcpp#979); log read-only sets.

        rclpy refuses a read-only parameter before the validation callback
        sees it; it is logged here, so that every refusal is.
        """
        for p in parameters:
            if p.name in READ_ONLY and not self.starting:
                self.get_logger().warning(
                    f'parameter refused: {p.name}: read-only (set it at start), got {p.value!r}')
        parameters = [Parameter(p.name, Parameter.Type.DOUBLE, float(p.value))
                      if self._is_double(p.name) and p.type_ == Parameter.Type.INTEGER else p
                      for p in parameters]
        return self._with_aliases(parameters)

    def _with_aliases(self, parameters: list[Parameter]) -> list[Parameter]:
        """Add the other name of the first crank's speed or acceleration, set to the same value.

        ``crank_speed_rpm`` and ``inputs.FIRST.speed_rpm`` (and ``crank_accel``
        and ``inputs.FIRST.accel``) are one value: setting either sets both,
        atomically. Given both with different values, the second is refused.
        """
        if not self._aliases or self._declaring:
            return parameters
        names = {p.name for p in parameters}
        added = []
        for old, new in self._aliases.items():
            for given, other in ((old, new), (new, old)):
                if given in names and other not in names:
                    value = next(p for p in parameters if p.name == given).value
                    added.append(Parameter(other, Parameter.Type.DOUBLE, value)
                                 if isinstance(value, float) else Parameter(other, value=value))
        return [*parameters, *added]

    def _validate(self, parameters: list[Parameter]) -> SetParametersResult:
        """Refuse a value of the wrong type or out of range, or one that breaks a joint rule."""
        reason = None
        for p in parameters:
            if p.type_ == Parameter.Type.NOT_SET and not self.has_parameter(p.name) \
                    and spec_default_is_none(p.name):
                continue    # declared unset: the scene gives it at configure
            reason = refusal(p.name, p.value, self._driver_specs or None)
            if reason is not None:
                break
        if reason is None:
            rules = (*JOINT_RULES, *self._driver_specs)
            # The values being set first, so that a refusal names what was set.
            current = {p.name: p.value for p in parameters if p.name in rules}
            current.update((name, self._value(name)) for name in rules
                           if name not in current and self.has_parameter(name))
            reason = joint_refusal({k: v for k, v in current.items() if v is not None})
        if reason is None:
            reason = self._stroke_refusal(parameters)
        if reason is None:
            return SetParametersResult(successful=True)
        # Every refusal is logged once, with its reason, besides the service's answer
        # (at start, main() says it in its one line).
        if self.starting:
            self.start_refusal = self.start_refusal or reason
        else:
            self.get_logger().warning(f'parameter refused: {reason}')
        return SetParametersResult(successful=False, reason=reason)

    def _apply(self, parameters: list[Parameter]) -> None:
        """Hand accepted values to the tick thread; it applies them at its next instant."""
        changes = {p.name: p.value for p in parameters if p.type_ != Parameter.Type.NOT_SET}
        driver = self._driver
        if 'rate_hz' in changes:
            driver.period_ns = period_ns_from_rate(changes['rate_hz'])
        if 'late_ticks' in changes:
            driver.catch_up = changes['late_ticks'] == CATCH_UP
        if 'max_catch_up_s' in changes or 'rate_hz' in changes:
            # At most one history's depth of instants a burst (issue 21, item 7).
            driver.max_behind_ns = catch_up_window_ns(
                changes.get('max_catch_up_s', self._value('max_catch_up_s')),
                period_ns_from_rate(changes.get('rate_hz', self._value('rate_hz'))))
        if 'tf_rate_hz' in changes:
            self._tf_period_ns = self._tf_period(changes['tf_rate_hz'])
        if 'max_relative_error' in changes:
            self._max_error = float(changes['max_relative_error'])
        if 'stamp_jump_back_s' in changes and self._topic is not None:
            self._topic.jump_back_ns = round(changes['stamp_jump_back_s'] * NS_PER_S)
        requests: dict[str, dict[str, float]] = {}
        for name, value in changes.items():
            for drive, key in self._drive_keys.get(name, ()):
                requests.setdefault(drive, {})[key] = float(value)
        for drive, request in requests.items():
            if drive in driver.drives:
                driver.request(drive, **request)
        if requests and self._thread is None:
            self._apply_now()   # not ticking: from the current instant
        logged = ', '.join(f'{p.name}={p.value!r}' for p in parameters)
        if self.scene is not None:
            self.get_logger().info(f'parameters set: {logged}')

    def _apply_now(self) -> None:
        """Apply the pending drive changes from the clock now (after the last instant)."""
        self._driver.apply_now(self.get_clock().now().nanoseconds)

    # -- lifecycle ------------------------------------------------------------

    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Load the scene, fill the scene's defaults, create the publishers."""
        try:
            self._configure()
        except Exception as error:     # noqa: BLE001 - a scene or a QoS override: one line
            self._teardown()
            self.configure_error = ((self.starting and self.start_refusal)
                                    or ' '.join(str(error).split()) or type(error).__name__)
            if not self.starting or self.managed:
                self.get_logger().error(f'cannot configure: {self.configure_error}')
            return TransitionCallbackReturn.FAILURE
        return TransitionCallbackReturn.SUCCESS

    def _configure(self) -> None:
        scene = mk.load_scene(self._value('scene'))
        drivers = scene.drivers
        first = drivers[0] if drivers[0].joint_type == REVOLUTE else None
        crank_rpms = [rpm_parameter(d.speed) for d in drivers if d.joint_type == REVOLUTE]
        given_rpm = self._value('crank_speed_rpm')      # a speed set at start raises the bound
        given = {name for name in DRIVE[:2] if self._value(name) is not None}
        defaults = {'max_crank_speed_rpm': max([DEFAULT_MAX_CRANK_SPEED_RPM, abs(given_rpm or 0.0),
                                                *map(abs, crank_rpms)])}
        if first is not None:
            defaults.update(crank_speed_rpm=rpm_parameter(first.speed), crank_accel=first.accel)
        unset = [Parameter(name, Parameter.Type.DOUBLE, float(value))
                 for name, value in defaults.items() if self._value(name) is None]
        if unset:
            result = self.set_parameters_atomically(unset)
            if not result.successful:
                raise mk.SceneError(f'{scene.name}: {result.reason}')
        self._declare_drivers(scene, given)
        starts = [self._drive_start(d, d is not first or given_rpm is None) for d in drivers]
        try:    # what `solve` refuses at the start, the node refuses to start with
            if len(drivers) == 1:
                [(_, position, speed, accel, turns)] = starts
                mk.solve(scene, position, speed, accel, turns=turns, max_error=self._max_error)
            else:
                _, positions, speeds, accels, turns = zip(*starts, strict=True)
                mk.solve(scene, positions, speeds, accels, turns=turns,
                         max_error=self._max_error)
        except mk.AssemblyError as error:
            msg = f'{scene.name}: {error}'
            raise mk.SceneError(msg) from None
        for d, (timebase, *_) in zip(drivers, starts, strict=True):
            self._driver.add_drive(d.name, timebase.kind, **timebase.start)
        self._messages = TickMessages(scene.output_joints, scene.output_points, self.frame_id)
        self._pub_joint_states = self.create_publisher(
            JointState, topics.JOINT_STATES, _state_qos(), qos_overriding_options=_qos_options())
        self._pub_joint_accel = self.create_publisher(
            JointTrajectory, topics.JOINT_ACCELERATIONS, _state_qos(),
            qos_overriding_options=_qos_options())
        self._pub_point_accel = self.create_publisher(
            MultiDOFJointTrajectory, topics.POINT_ACCELERATIONS, _state_qos(),
            qos_overriding_options=_qos_options())
        self._state_publishers = [self._pub_joint_states, self._pub_joint_accel,
                                  self._pub_point_accel]
        self._publish_state = tuple(p.publish for p in self._state_publishers)
        tick_scene = self._setup_tf(scene)
        self._setup_imus(scene, tick_scene)
        self._publish_descriptions(scene)
        self._setup_solve(tick_scene, scene)
        self._tf_first = 3 * len(scene.output_joints) + 6 * len(scene.output_points)
        # Instants where a value jumps (a Geneva wheel's) are published one-sided and counted.
        self._jumps_at = tick_scene.jumps_at if tick_scene.intermittent else None
        if self._value('markers'):
            self._setup_markers(scene)
        self._setup_topic_drive(scene)
        self.scene = scene
        self._log_start()
        if self._compile_later is not None:
            self._compile_later.start()
            self._compile_later = None

    def _setup_solve(self, tick_scene: mk.Scene, scene: mk.Scene) -> None:
        """Set the tick's solve (compiled into one straight-line function) and the sweep.

        The sweep is where the scene cannot assemble over a crank's turn, in one
        line for the diagnostics (a scene of several drivers, or an actuator, has
        none). Compiling takes about 25 ms a step (ros/ticker.py) and the sweep
        about 3 ms a step. A scene of more than :data:`BACKGROUND_STEPS` dyads and
        points starts on the general solver (the same answers, bit for bit) and a
        daemon thread sweeps and compiles it; the compiled function takes over the
        next tick after it is made, so a long chain is published from the start
        instead of after minutes.
        """
        frames = [(f.origin, f.angle_of, f.angle) for f in self._tf_frames]
        outputs = (tick_scene, scene.output_joints, scene.output_points, frames)
        steps = len(scene.dyads) + len(scene.points)
        sweep = len(scene.drivers) == 1 and scene.input is not None
        self._compiling = token = object()     # a later scene's setup makes this one stale
        self._compile_later = None
        self._assembly = ''
        if steps <= BACKGROUND_STEPS:
            if sweep:
                self._assembly = assembly_summary(scene)
            self._solve, compiled = tick_function(*outputs)
            if not compiled:
                self.get_logger().info(GENERAL_SOLVER)
            return
        self._solve = general_tick(*outputs)
        self.get_logger().info(
            f'the scene has {steps} dyads and points: the general solver serves while its '
            'tick compiles in the background')

        def compile_in_background() -> None:
            started = time.monotonic()
            if sweep:
                summary = assembly_summary(scene)
                if self._compiling is token:
                    self._assembly = summary
            try:
                tick = compile_tick(*outputs)
            except Exception as error:  # noqa: BLE001 (the general solver goes on)
                tick, why = None, f' ({type(error).__name__}: {error})'
            else:
                why = ''
            if self._compiling is not token:
                return
            if tick is not None:
                self._solve = tick
            # (the node may be shutting down: a log it cannot write is no error)
            with contextlib.suppress(Exception):
                self.get_logger().info(
                    f'{GENERAL_SOLVER}{why}' if tick is None else
                    f'the compiled tick serves from now (compiled in '
                    f'{time.monotonic() - started:.1f} s)')

        # Started once the rest of the set-up is done: a thread holding the GIL slows
        # every release and re-acquisition of it by this one (the assembly sweep's NumPy).
        self._compile_later = threading.Thread(target=compile_in_background,
                                               name='compile the tick', daemon=True)

    def _declare_drivers(self, scene: mk.Scene, given: set[str]) -> None:
        """Declare each driver's ``inputs.NAME.*`` (the scene's defaults); note what they set.

        The first crank's take ``crank_speed_rpm`` and ``crank_accel`` as their
        defaults (the two are one value each, see :meth:`_with_aliases`); given
        both names at start (``given``: the v1 names given) with different
        values, the node refuses to start.
        """
        specs = driver_parameters(scene.drivers)
        self._aliases = first_crank_aliases(scene.drivers)
        self._driver_specs = {p.name: p for p in specs}
        self._drivers_by_name = {d.name: d for d in scene.drivers}
        aliased = {new: old for old, new in self._aliases.items()}
        keys: dict[str, list[tuple[str, str]]] = {}
        for d in scene.drivers:
            for p in specs:
                if p.name.startswith(f'inputs.{d.name}.'):
                    keys[p.name] = [(d.name, p.name.rsplit('.', 1)[1])]
        for old, new in self._aliases.items():
            keys[old] = keys[new]
        keys[DRIVE[2]] = [(d.name, MAX_SPEED_KEY) for d in scene.drivers
                          if d.joint_type == REVOLUTE]
        self._drive_keys = keys
        self._declaring = True
        try:
            for p in specs:
                if self.has_parameter(p.name):
                    continue
                default = self._value(aliased[p.name]) if p.name in aliased else p.default
                descriptor = ParameterDescriptor(description=_description(p),
                                                 dynamic_typing=True)
                value = self.declare_parameter(p.name, default, descriptor).value
                if type(value) is int:
                    self.set_parameters([Parameter(p.name, Parameter.Type.DOUBLE, float(value))])
            for old, new in self._aliases.items():
                if self._value(old) == self._value(new):
                    continue
                if old in given:
                    msg = (f'{old} and {new} are the same value: expected one of them or equal '
                           f'values, got {self._value(old)!r} and {self._value(new)!r}')
                    raise mk.SceneError(msg)
                result = self.set_parameters_atomically(
                    [Parameter(old, Parameter.Type.DOUBLE, float(self._value(new)))])
                if not result.successful:
                    raise mk.SceneError(f'{scene.name}: {result.reason}')
        finally:
            self._declaring = False

    def _drive_start(self, d: Any, own_speed: bool) -> tuple[Any, float, float, float, int]:
        """Return driver ``d``'s time base start, and its (position, speed, accel, turns) then.

        The scene's own crank speed is driven in its own unit (rad/s), so that
        the node publishes what ``solve`` prints to the bit; the parameter shows
        it in rpm. ``own_speed``: its speed was not given as ``crank_speed_rpm``
        (the scene's, unless ``inputs.NAME.speed_rpm`` differs from it).
        """
        base = f'inputs.{d.name}.'
        accel = float(self._value(base + 'accel'))
        if d.joint_type != REVOLUTE:
            speed = float(self._value(base + 'speed'))
            return (_Start(ActuatorTimebase, {'length': d.start, 'speed': speed, 'accel': accel}),
                    d.start, speed, accel, 0)
        rpm = float(self._value(base + 'speed_rpm'))
        own_speed = own_speed and rpm == rpm_parameter(d.speed) \
            and abs(rpm) < DEFAULT_MAX_CRANK_SPEED_RPM
        # A start angle beyond a turn is whole turns plus an angle within one (Crank.turns).
        turns = d.turns
        start = {'angle': d.start, 'turns': turns, 'accel': accel,
                 'max_speed_rpm': self._value('max_crank_speed_rpm')}
        if own_speed:
            start['speed'] = d.speed
            return _Start(CrankTimebase, start), d.start, d.speed, accel, turns
        start['speed_rpm'] = rpm
        return _Start(CrankTimebase, start), d.start, rad_per_s_from_rpm(rpm), accel, turns

    def _stroke_refusal(self, parameters: list[Parameter]) -> str | None:
        """Return why a change of an actuator's drive is refused: it leaves the stroke at once.

        The length now is exactly known; a drive that takes it out of its
        stroke from there (at or beyond a limit, not moving back) is refused.
        Later exits are the ticks' to report (the solver refuses them, and
        ``diagnostics`` says so); a drive that brings the length back is taken.
        """
        changes = {}
        for p in parameters:
            for drive, key in self._drive_keys.get(p.name, ()):
                if key in ActuatorTimebase.CHANGES and isinstance(p.value, (int, float)):
                    changes.setdefault(drive, {})[key] = (p.name, float(p.value))
        for name, change in changes.items():
            d = self._drivers_by_name[name]
            if d.stroke is None or d.joint_type == REVOLUTE:
                continue
            current = self._driver.drives.get(name)
            timebase = current.timebase if current is not None else None
            now = self.get_clock().now().nanoseconds
            if timebase is None:    # not started: from the start values
                start = {'length': d.start,
                         'speed': self._declared(f'inputs.{name}.speed', d.speed),
                         'accel': self._declared(f'inputs.{name}.accel', d.accel)}
                timebase, now = ActuatorTimebase(0, **start), 0
            trial = copy.deepcopy(timebase)
            trial.update(now, **{key: value for key, (_, value) in change.items()})
            if trial.moves_out(now, d.stroke):
                length = float(trial.length(now))
                given = ', '.join(f'{n} = {v!r}' for n, v in change.values())
                return (f'{given}: expected a drive that keeps actuator {name} within its '
                        f'stroke [{d.stroke[0]:g}, {d.stroke[1]:g}] m, got one that leaves it '
                        f'at once (at {length:.6g} m)')
        return None

    def _setup_tf(self, scene: mk.Scene) -> mk.Scene:
        """Create the /tf and /tf_static publishers; return the scene the ticks solve.

        The frames' origins and angles may be points and joints the scene does
        not output: the ticks solve a copy that outputs them too (only the
        scene's own outputs are published on the state topics).
        """
        self._tf = None
        self._tf_frames: tuple[Any, ...] = ()
        try:
            from tf2_msgs.msg import TFMessage
        except ImportError:
            self.get_logger().warning(
                'tf2_msgs is not installed (make install builds it): no frames on /tf')
            return scene
        frames = frames_from_scene(scene)
        prefix = self._value('tf_prefix') or self.frame_id
        self._tf = TfMessages(frames, self.frame_id, prefix)
        self._tf_frames = frames
        self._pub_tf = self.create_publisher(TFMessage, topics.TF, _tf_qos(False),
                                             qos_overriding_options=_qos_options())
        self._pub_tf_static = self.create_publisher(TFMessage, topics.TF_STATIC, _tf_qos(True),
                                                    qos_overriding_options=_qos_options())
        self._state_publishers += [self._pub_tf, self._pub_tf_static]
        self._pub_tf_static.publish(static_tf_message(
            scene.ground, self.frame_id, prefix, self.get_clock().now().to_msg()))
        points = [p for p in origin_points(frames) if p not in scene.output_points]
        joints = [j for j in angle_joints(frames) if j not in scene.output_joints]
        if not points and not joints:
            return scene
        return replace(scene, outputs_points=(*scene.output_points, *points),
                       outputs_joints=(*scene.output_joints, *joints))

    def _setup_imus(self, scene: mk.Scene, tick_scene: mk.Scene) -> None:
        """Create a publisher on ``imu/NAME`` for each of the scene's sensors, and their frames.

        A sensor turned on its link (``angle`` not 0) has a frame of its own,
        published on ``/tf`` with the link frames (when ``/tf`` is on).
        """
        self._imus = self._imu_frames = None
        if not scene.imus:
            return
        prefix = self._value('tf_prefix') or self.frame_id
        self._imus = ImuMessages(scene.imus, scene.output_joints, scene.output_points, prefix)
        publishers = [self.create_publisher(Imu, topics.imu_topic(spec.name), _state_qos(),
                                            qos_overriding_options=_qos_options())
                      for spec in scene.imus]
        self._state_publishers += publishers
        self._publish_imu = tuple(p.publish for p in publishers)
        if self._tf is not None:
            # The sensors' offsets on their links, from any pose: the drivers' starts.
            starts = [driver.start for driver in scene.drivers]
            rest = [0.0] * len(starts)
            state = (mk.solve(tick_scene, starts[0], 0.0, 0.0, max_error=math.inf)
                     if len(starts) == 1 else
                     mk.solve(tick_scene, starts, rest, rest, max_error=math.inf))
            frames = {f.joint: f for f in self._tf_frames}
            transforms = self._imus.frame_transforms(sensor_offsets(scene.imus, frames, state))
            if transforms:
                self._imu_frames = ImuFrames(transforms)

    def _publish_imus(self, values: list[float], sec: int, nanosec: int) -> None:
        """Publish every sensor's ``Imu`` of a tick's values (none whose reading overflows)."""
        assert self._imus is not None
        for publish, data, sensor in zip(self._publish_imu,
                                         self._imus.render_values(values, sec, nanosec),
                                         self._imus.specs, strict=True):
            if data is None:
                self.get_logger().warning(f'imu/{sensor.name}: no reading published: beyond '
                                          f'the range of doubles', throttle_duration_sec=1.0)
            else:
                publish(data)

    def _publish_descriptions(self, scene: mk.Scene) -> None:
        """Publish the URDF on ``robot_description`` and the scene's text on ``scene``, latched.

        Transient local, depth 1: a late subscriber (RViz, the recorder) gets them.
        """
        latched = _tf_qos(True)
        self._pub_description = self.create_publisher(String, topics.ROBOT_DESCRIPTION, latched)
        self._pub_scene = self.create_publisher(String, topics.SCENE, latched)
        self._state_publishers += [self._pub_description, self._pub_scene]
        self._pub_scene.publish(String(data=scene_text(self._value('scene'))))
        try:
            urdf = urdf_from_scene(scene, self.frame_id, self._value('tf_prefix'))
        except mk.AssemblyError as error:
            self.get_logger().warning(f'no robot_description: {error}')
            return
        self._pub_description.publish(String(data=urdf))

    def _log_start(self) -> None:
        scene = self.scene
        assert scene is not None
        names = ('scene', 'drive', 'crank_speed_rpm', 'crank_accel', 'max_crank_speed_rpm',
                 'rate_hz', 'late_ticks', 'max_catch_up_s', 'max_lateness_ms',
                 'max_relative_error', 'frame_id', 'tf_rate_hz', 'tf_prefix',
                 'use_sim_time', 'markers', 'managed', 'extra_joints', 'stamp_jump_back_s')
        names += tuple(self._driver_specs)
        settings = ', '.join(f'{name}={self._value(name)!r}' for name in names[1:])
        self.get_logger().info(
            f'scene {scene.name!r} ({self._value("scene")}): joints {list(scene.output_joints)}, '
            f'points {list(scene.output_points)}; {settings}')

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Start the tick thread."""
        self.start()
        return TransitionCallbackReturn.SUCCESS

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Stop the tick thread; the crank angle stays a function of the clock."""
        self.stop()
        return TransitionCallbackReturn.SUCCESS

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Drop the scene and the publishers."""
        self._teardown()
        return TransitionCallbackReturn.SUCCESS

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Stop ticking and drop everything."""
        self.stop()
        self._teardown()
        return TransitionCallbackReturn.SUCCESS

    def _teardown(self) -> None:
        for publisher in [*self._state_publishers, self._pub_markers]:
            if publisher is not None:
                self.destroy_publisher(publisher)
        self._state_publishers = []
        self._pub_markers = None
        self._drop_topic_drive()
        self._compiling = None      # a compile still running is not installed
        self.scene = None

    def _setup_markers(self, scene: mk.Scene) -> None:
        """Prepare the markers: the whole scene, its strokes and size, the publisher."""
        self._marker_scene = full_scene(scene)
        self._marker_strokes = strokes_from_scene(self._marker_scene)
        try:
            self._marker_size: float | None = marker_size_from_space(space_from_state(
                self._marker_scene, _solve_at_start(self._marker_scene)))
        except mk.AssemblyError:
            self._marker_size = None    # the part beyond the outputs cannot assemble here
        self._marker_throttle = MarkerThrottle()
        self._marker_lock = threading.Lock()
        self._marker_request: tuple[int, int, float, float, float] | None = None
        self._marker_guard = self.create_guard_condition(self._publish_markers)
        self._pub_markers = self.create_publisher(MarkerArray, topics.MARKERS, 10,
                                                  qos_overriding_options=_qos_options())

    # -- the tick thread ------------------------------------------------------

    def start(self) -> None:
        """Start the tick thread (with ``drive: topic``, the input subscription instead)."""
        if self._topic is not None:
            self._start_topic_drive()
            return
        self._stop.clear()
        self._driver.resume()
        self._thread = threading.Thread(target=self._run, name='mech_kinematics_tick',
                                        daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop the tick thread and wait for it; apply what it left pending."""
        self._stop_topic_drive()
        self._stop.set()
        self._clock_event.set()
        thread, self._thread = self._thread, None
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=2.0)
        self._apply_now()

    def destroy_node(self) -> None:
        """Stop the tick thread, then destroy the node."""
        if hasattr(self, '_stop'):
            self.stop()
        handle = getattr(self, '_jump_handle', None)
        if handle is not None:
            handle.unregister()
            self._jump_handle = None
        super().destroy_node()

    def _run(self) -> None:
        _set_timer_slack(1000)
        try:
            self._loop()
        except Exception:
            if self._stop.is_set() or not self.context.ok():
                return      # shutting down: the context went away under a publish
            # A node that no longer ticks must not look alive: stop the process.
            self.failed = True
            self.get_logger().fatal(f'tick thread failed:\n{traceback.format_exc()}')
            self._failure_guard.trigger()

    def _on_failure(self) -> None:
        raise TickThreadError('the tick thread failed (see the log above)')

    def _loop(self) -> None:
        clock, driver = self.get_clock(), self._driver
        stop, stats = self._stop, self._stats
        monotonic_ns, time_ns, sleep = time.monotonic_ns, time.time_ns, time.sleep
        while not stop.is_set():
            # The time source can only change with a clock jump (on_clock_change): ask
            # the clock then, not every loop (the property takes the clock's lock).
            if driver.sim is None or self._clock_event.is_set():
                sim = clock.ros_time_is_active
                if not sim:
                    self._clock_event.clear()
            else:
                sim = driver.sim
            if sim:
                # Instants follow the simulated clock: wake on every /clock update.
                self._clock_event.wait(MAX_SLEEP_NS / NS_PER_S)
                self._clock_event.clear()
                if not clock.ros_time_is_active:
                    self._clock_event.set()     # switched off: the loop's top sees it
                    continue
                now = clock.now().nanoseconds
                if stop.is_set():
                    break
                wake = driver.step(now, sim=True)
                if wake.waiting_for_clock:
                    self._wait_for_clock()
                    continue
                self._waiting_for_clock = False
                if wake.jump_ns is not None:
                    stats.clock_jump()      # the simulated clock went back
                self._publish(wake.instants, wake.skipped, now)
                continue
            now = time_ns()
            wake = driver.step(now, monotonic_ns=monotonic_ns())
            if wake.jump_ns is not None:
                stats.clock_jump()
                self.get_logger().warning(
                    f'the system clock jumped by {wake.jump_ns / NS_PER_S:+.3f} s: '
                    'the tick grid starts again', throttle_duration_sec=1.0)
            if wake.wait_ns > 0:
                sleep(min(wake.wait_ns, MAX_SLEEP_NS) / NS_PER_S)
                continue
            self._publish(wake.instants, wake.skipped, driver.woke_ns(monotonic_ns()))

    def _wait_for_clock(self) -> None:
        if not self._waiting_for_clock:
            self._waiting_for_clock = True
            self.get_logger().warning(
                'use_sim_time is true and no /clock has been received: nothing is published '
                'until one arrives')

    def _publish(self, instants: range, skipped: int, woke: int) -> None:
        """Publish ``instants`` (``skipped`` were dropped; ``woke``: when this wake-up began)."""
        self._stats.skip(skipped)
        late_ns = min(self._driver.period_ns // 2, LATE_NS)
        for stamp in instants:
            states = self._driver.state_at(stamp)
            if len(states) == 1:
                [(turns, sample)] = states
            else:   # several drivers: their positions, speeds, accels and turns, in scene order
                turns, sample = _transposed(states)
            lateness = woke - stamp
            self._tick(stamp, lateness, lateness > late_ns, turns, sample)

    def _tick(self, stamp: int, lateness: int, late: bool, turns: int,
              sample: CrankSample) -> None:
        # The crank as whole turns plus an angle in one turn: an intermittent drive
        # (a Geneva wheel) indexes by the turns, never formed as a float sum.
        angle, speed, accel = sample
        try:
            values, measure = self._solve(angle, speed, accel, self._max_error, turns)
        except mk.AssemblyError as exc:
            refusal = 'not trusted' if isinstance(exc, mk.UntrustedError) else \
                'cannot assemble'
            self._stats.record(stamp, lateness, late, error=str(exc), refusal=refusal,
                               sample=sample)
            self.get_logger().warning(f'no state published: {exc}', throttle_duration_sec=1.0)
            return
        sec, nanosec = divmod(stamp, NS_PER_S)
        joint_states, joint_accel, point_accel = self._messages.render_values(
            values, sec, nanosec)
        publish_js, publish_jt, publish_pt = self._publish_state
        publish_js(joint_states)
        publish_jt(joint_accel)
        publish_pt(point_accel)
        if self._imus is not None:
            self._publish_imus(values, sec, nanosec)
        if stamp >= self._next_tf:
            tf_period = self._tf_period_ns
            if self._tf is not None and tf_period is not None:
                self._pub_tf.publish(self._tf.render_values(values, self._tf_first, sec,
                                                            nanosec))
                if self._imu_frames is not None:
                    self._pub_tf.publish(self._imu_frames.render(sec, nanosec))
                self._next_tf = stamp + tf_period
            else:
                self._next_tf = stamp + NS_PER_S    # off: look again in a second
        if self._pub_markers is not None and self._marker_throttle.due(
                self._driver.period_ns, time.monotonic_ns()):
            # Built in the executor's thread, so that this thread keeps its deadlines.
            with self._marker_lock:
                self._marker_request = (sec, nanosec, angle, speed, accel)
            self._marker_guard.trigger()
        self._stats.published(stamp, lateness, late, measure, sample,
                              self._jumps_at is not None and self._jumps_at(angle, turns=turns))
        if measure < mk.NEAR_SINGULAR:
            self.get_logger().warning(
                f'near-singular pose at {_position(angle)}: measure {measure:.3g}',
                throttle_duration_sec=1.0)

    # -- driven from a topic --------------------------------------------------

    def _setup_topic_drive(self, scene: mk.Scene) -> None:
        """With ``drive: topic``, prepare the rules and the messages without accelerations."""
        self._topic = None
        if self._value('drive') != TOPIC:
            return
        joints, points = scene.output_joints, scene.output_points
        # What the input determines: positions always, velocities when a message has them.
        self._topic_messages = {
            known: TickMessages(joints, points, self.frame_id, velocities=known,
                                accelerations=False) for known in (True, False)}
        self._topic = TopicDrive(
            scene.drivers, extra_joints=self._value('extra_joints'),
            jump_back_ns=round(self._value('stamp_jump_back_s') * NS_PER_S),
            published_joints=joints)
        # Subscribed at configure (its QoS overrides are declared with the others); a
        # message is published only while active.
        qos = QoSProfile(history=QoSHistoryPolicy.KEEP_LAST, depth=INPUT_DEPTH,
                         reliability=QoSReliabilityPolicy.RELIABLE,
                         durability=QoSDurabilityPolicy.VOLATILE)
        self._input = self.create_subscription(
            JointState, topics.INPUT_JOINT_STATES, self._on_input, qos,
            qos_overriding_options=_qos_options())

    def _start_topic_drive(self) -> None:
        """Publish a state for each message on ``input_joint_states`` from now on."""
        self._input_active = True

    def _stop_topic_drive(self) -> None:
        self._input_active = False

    def _drop_topic_drive(self) -> None:
        self._input_active = False
        self._topic = None
        subscription, self._input = self._input, None
        if subscription is not None:
            self.destroy_subscription(subscription)

    def _on_input(self, msg: JointState) -> None:
        """Publish the state of each input message waiting, from ``msg`` on, with its stamp.

        rclpy's executor rebuilds its wait set of every service, timer and
        subscription of the node for each message it hands over: behind by a
        burst, the node would pay that per message. Each call takes up to
        :data:`INPUT_BURST` more messages waiting in the subscription's queue
        (as the executor takes them), then lets the executor serve the rest.
        """
        self._input_message(msg)
        subscription = self._input
        for _ in range(INPUT_BURST):
            if subscription is None or self._input is not subscription:
                return
            with subscription.handle:
                taken = subscription.handle.take_message(subscription.msg_type,
                                                         subscription.raw)
            if taken is None:
                return
            self._input_message(taken[0])

    def _input_message(self, msg: JointState) -> None:
        """Publish the state of one input message with its stamp, or say why not."""
        received = time.monotonic_ns()
        topic = self._topic
        if topic is None or not self._input_active:
            return      # inactive (lifecycle), or cleaned up while the message waited
        stamp = msg.header.stamp
        stamp_ns = stamp.sec * NS_PER_S + stamp.nanosec
        try:
            given = topic.read(stamp.sec, stamp.nanosec, msg.name, msg.position, msg.velocity,
                               msg.effort)
            values, measure = self._solve_input(given)
        except (RefusedInput, mk.AssemblyError) as exc:
            kind = 'refused input' if isinstance(exc, RefusedInput) else \
                'not trusted' if isinstance(exc, mk.UntrustedError) else 'cannot assemble'
            self._stats.record(stamp_ns, time.monotonic_ns() - received, False, error=str(exc),
                               refusal=kind)
            self.get_logger().warning(f'no state published: {exc}', throttle_duration_sec=1.0)
            return
        sec, nanosec = divmod(given.stamp_ns, NS_PER_S)
        messages = self._topic_messages[given.speeds is not None]
        rendered = messages.render_values(values, sec, nanosec)
        if given.passed is not None:    # extra_joints: pass: names that change per message
            rendered = (self._joint_state_passed(topic, given, values, sec, nanosec),
                        *rendered[1:])
        for publish, data in zip(self._publish_state, rendered, strict=True):
            publish(data)
        if given.jumped_from_ns is not None:
            self._next_tf = 0   # /tf's rate counts from the new order
            self.get_logger().warning(
                f'{topics.INPUT_JOINT_STATES}: the stamp jumped back '
                f'{(given.jumped_from_ns - given.stamp_ns) / NS_PER_S:.9g} s (more than '
                'stamp_jump_back_s): published, the order starts again from it',
                throttle_duration_sec=1.0)
        if self._tf is not None and self._tf_period_ns is not None \
                and given.stamp_ns >= self._next_tf:
            self._pub_tf.publish(self._tf.render_values(values, self._tf_first, sec, nanosec))
            if self._imu_frames is not None:    # a sensor's frame is a position: known here
                self._pub_tf.publish(self._imu_frames.render(sec, nanosec))
            self._next_tf = given.stamp_ns + self._tf_period_ns
        topic.published(given.stamp_ns)
        self._stats.record(given.stamp_ns, time.monotonic_ns() - received, False,
                           measure=measure, near_singular=measure < mk.NEAR_SINGULAR)
        self._stats.topic_input(given.stamp_ns, given.jumped_from_ns, given.ignored,
                                given.passed.names if given.passed is not None else ())

    def _joint_state_passed(self, topic: TopicDrive, given: TopicInput, values: Any, sec: int,
                            nanosec: int) -> JointState:
        """Return ``joint_states`` with the input's other joints after the mechanism's."""
        name, position, velocity, effort = topic.joint_state_arrays(given, values)
        msg = JointState(name=name, position=position, velocity=velocity, effort=effort)
        msg.header.stamp = Time(sec=sec, nanosec=nanosec)
        msg.header.frame_id = self.frame_id
        return msg

    def _solve_input(self, given: TopicInput) -> tuple[Any, float]:
        """Return (the tick function's values, the singularity measure) for one input.

        Unknown velocities are solved as zero and left out of what is published;
        the accelerations are never published.
        """
        n = len(given.positions)
        speeds = (0.0,) * n if given.speeds is None else given.speeds
        if n == 1:
            return self._solve(given.positions[0], speeds[0], 0.0, self._max_error, 0)
        return self._solve(given.positions, speeds, (0.0,) * n, self._max_error, (0,) * n)

    # -- markers --------------------------------------------------------------

    def _publish_markers(self) -> None:
        """Publish the markers of the last sample the tick thread handed over, if any."""
        with self._marker_lock:
            request, self._marker_request = self._marker_request, None
        if request is None or self._pub_markers is None or self.scene is None:
            return
        sec, nanosec, angle, speed, accel = request
        try:
            state = mk.solve(self._marker_scene, angle, speed, accel)
        except mk.AssemblyError:
            return      # a part beyond the outputs cannot assemble: no markers this time
        self._pub_markers.publish(marker_array_from_state(
            self._marker_scene, state, frame_id=self.frame_id,
            stamp=Time(sec=sec, nanosec=nanosec),
            velocity_scale=self._value('marker_velocity_scale'),
            acceleration_scale=self._value('marker_acceleration_scale'),
            points=self.scene.output_points, size=self._marker_size,
            strokes=self._marker_strokes))

    # -- diagnostics ----------------------------------------------------------

    def _publish_diagnostics(self) -> None:
        window = self._stats.take_window()
        name = self.get_name()
        hardware_id = self.scene.name if self.scene is not None else self._value('scene')
        if self.scene is None:
            waiting = 'configure (lifecycle)'
        elif self._thread is None and not self._input_active:
            waiting = 'activate (lifecycle)' if self.managed else 'the start'
        elif self._waiting_for_clock:
            waiting = '/clock'
        else:
            waiting = ''
        statuses = [
            solver_status(window, name=name, hardware_id=hardware_id,
                          near_singular=mk.NEAR_SINGULAR, waiting_for=waiting,
                          assembly=self._assembly,
                          extra_joints=self._value('extra_joints') if self._topic else ''),
            timing_status(window, name=name, hardware_id=hardware_id,
                          rate_hz=self._value('rate_hz'),
                          max_lateness_ms=self._value('max_lateness_ms')),
        ]
        msg = DiagnosticArray(status=[diagnostic_status_from(s) for s in statuses])
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = self.frame_id
        self._pub_diagnostics.publish(msg)


def _solve_at_start(scene: mk.Scene) -> Any:
    """Return ``scene`` solved with its drivers at their start (a crank with its whole turns)."""
    drivers = scene.drivers
    turns = [getattr(d, 'turns', 0) for d in drivers]
    if len(drivers) == 1:
        return mk.solve(scene, drivers[0].start, turns=turns[0])
    return mk.solve(scene, [d.start for d in drivers], turns=turns)


def _transposed(states: list[tuple[int, Any]]) -> tuple[tuple[int, ...], Any]:
    """Return the drivers' (turns, state) as (turns, (positions, speeds, accels)), in order."""
    turns = tuple(t for t, _ in states)
    return turns, tuple(zip(*(state for _, state in states), strict=True))


def _position(angle: Any) -> str:
    """Return the drivers' position for a log line: one crank's angle, or every driver's."""
    if isinstance(angle, tuple):
        return f'driver positions {", ".join(f"{a:.6f}" for a in angle)}'
    return f'crank angle {angle:.6f} rad'


class _Start(NamedTuple):
    """A driver's time base class and its start values (``TickDriver.add_drive``)."""

    kind: Any
    start: dict[str, Any]


def spec_default_is_none(name: str) -> bool:
    """Return whether parameter ``name`` stays unset until the scene gives it."""
    try:
        return spec(name).default is None
    except KeyError:
        return False


class StartError(Exception):
    """The node refused to start: ``reason`` (one line), for the logger named ``logger_name``."""

    def __init__(self, reason: str, logger_name: str) -> None:
        super().__init__(reason)
        self.reason = reason
        self.logger_name = logger_name


class DuplicateNodeError(Exception):
    """An older node of the same fully qualified name is running: this one is the newcomer."""


#: How many nodes' words on ``~/_instance`` a node keeps until its first spin reads them.
INSTANCE_HISTORY = 100


class Instance:
    """A node's start instant and random id, said on and heard from ``~/_instance``.

    Of the nodes that share a fully qualified name, the oldest (earliest start, then smallest
    id) goes on; a node that hears an older one raises DuplicateNodeError from its spin after
    stopping its tick thread. An older node ignores younger ones.
    """

    def __init__(self, node: KinematicsNode, start_ns: int) -> None:
        self.node = node
        self.key = start_ns, random.SystemRandom().getrandbits(64)
        qos = QoSProfile(depth=1, reliability=QoSReliabilityPolicy.RELIABLE,
                         durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
        # The node hears its own word too, and all of them may arrive before its first
        # spin (a slow start): a history of one would keep only the last, maybe its own.
        heard = QoSProfile(depth=INSTANCE_HISTORY, reliability=QoSReliabilityPolicy.RELIABLE,
                           durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
        node.create_subscription(String, INSTANCE_TOPIC, self._heard, heard)
        node.create_publisher(String, INSTANCE_TOPIC, qos).publish(
            String(data=f'{self.key[0]} {self.key[1]}'))

    def _heard(self, msg: String) -> None:
        try:
            start_ns, ident = (int(word) for word in msg.data.split())
        except ValueError:
            return      # not a node of ours: nothing to compare
        if (start_ns, ident) < self.key:
            self.node.stop()
            raise DuplicateNodeError(
                f'another node named {self.node.get_fully_qualified_name()} is running '
                '(remap the name with -r __node:=NAME or the namespace with -r __ns:=/NS)')


class _Executor(SingleThreadedExecutor):
    """rclpy's executor; one half built (a signal shut its context down) deletes quietly."""

    # Executor.__del__ reads it: without this, an executor whose __init__ failed prints
    # "Exception ignored ... AttributeError" when it is collected.
    _sigint_gc = None


def main(args: list[str] | None = None) -> int:
    """Run the node until Ctrl-C or SIGTERM; return the exit status.

    0 when stopped (a SIGINT or SIGTERM at any point of the start included), 1 if
    it cannot start, 2 if a file its arguments name may not be read
    (:mod:`~mech_kinematics.ros.startup`).
    """
    catch_stop_signals()
    # The node reports near-singular poses on diagnostics and in its log.
    warnings.filterwarnings('ignore', category=mk.NearSingularWarning)
    # The tick thread must not wait long for the GIL when it wakes (default 5 ms).
    sys.setswitchinterval(SWITCH_INTERVAL_S)
    logger = get_logger(NODE_NAME)
    start_ns = time.time_ns()
    refused = start_refusal(sys.argv if args is None else args)
    if refused is not None:
        logger.fatal(f'cannot start: {refused}')
        return 2
    if stop_asked():
        return 0
    try:
        # Until the spin a signal is only noted (startup.catch_stop_signals), and the start
        # stops at its next step: rclpy's handler would shut the context down under the
        # step running (a SIGINT while configuring crashed the process with SIGSEGV).
        rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    except Exception as exc:     # noqa: BLE001 - rclpy's argument errors come in several kinds
        logger.fatal(f'cannot start: bad arguments: {_one_line(exc)}')
        return 1
    node = None
    status = 0
    try:
        if stop_asked():
            return 0
        node = KinematicsNode()
        logger = node.get_logger()
        Instance(node, start_ns)
        if not node.managed and not stop_asked():
            node.trigger_configure()
            if node.scene is None and not stop_asked():
                logger.fatal(f'cannot start: {node.configure_error}')
                return 1
        node.starting = False
        if not node.managed and not stop_asked():
            node.trigger_activate()
        # Everything built so far lives as long as the node: keep it out of the
        # garbage collector's full passes, which would otherwise delay ticks.
        gc.freeze()
        # From now on rclpy's handler ends the spin on a signal (and calls ours); a signal
        # noted before it was installed is seen here.
        install_signal_handlers(SignalHandlerOptions.ALL)
        if stop_asked():
            return 0
        executor = _Executor()
        executor.add_node(node)
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass  # Ctrl-C or shutdown: a clean exit, status 0
    except TickThreadError:
        status = 1
    except DuplicateNodeError as exc:
        logger.fatal(f'cannot start: {exc}')
        status = 1
    except StartError as exc:
        if not stop_asked():
            get_logger(exc.logger_name).fatal(f'cannot start: {exc.reason}')
            status = 1
    except Exception as exc:     # noqa: BLE001 - a start-up failure: one line, no traceback
        if rclpy.ok() and not stop_asked():
            logger.fatal(f'cannot start: {_one_line(exc)}')
            status = 1
        # else a signal shut the context down while the node started (rclpy's own
        # handler): what failed then is the shutdown asked for, a clean exit, status 0
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return status


def _one_line(error: BaseException) -> str:
    return ' '.join(str(error).split()) or type(error).__name__


if __name__ == '__main__':
    sys.exit(main())
