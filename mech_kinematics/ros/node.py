# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""ROS 2 node ``mech_kinematics``: the kinematic state of a linkage at a fixed rate.

The node is an adapter around the pure solver. ``__init__`` declares the
parameters, loads the scene once and creates the publishers; a tick thread
wakes on absolute deadlines, takes the crank angle from the node's clock
(:mod:`mech_kinematics.timebase`), solves, and publishes three messages
rendered from pre-serialized templates (:mod:`mech_kinematics.messages`).
The executor only serves the parameter services, ``/clock``, the 1 Hz
diagnostics and, with ``markers: true``, the RViz markers: the tick thread
hands at most 30 samples a second to the executor, which solves the whole
scene and publishes a ``MarkerArray`` (:mod:`mech_kinematics.markers`).

Run it with ``ros2 run mech_kinematics kinematics_node`` or
``python -m mech_kinematics.kinematics_node [--ros-args ...]``.
"""

from __future__ import annotations

import ctypes
import gc
import math
import statistics
import sys
import threading
import time
import traceback
from typing import Any
import warnings

from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor, SetParametersResult
import rclpy
from rclpy.clock import Clock, ClockType, JumpThreshold
from rclpy.duration import Duration
from rclpy.exceptions import InvalidParameterValueException
from rclpy.executors import ExternalShutdownException
from rclpy.logging import get_logger
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSDurabilityPolicy, QoSHistoryPolicy, QoSProfile, QoSReliabilityPolicy
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory, MultiDOFJointTrajectory
from visualization_msgs.msg import MarkerArray

import mech_kinematics as mk
from .markers import (DEFAULT_ACCELERATION_SCALE, DEFAULT_VELOCITY_SCALE,
                      marker_array_from_state, marker_size_from_space, MarkerThrottle)
from .messages import TickMessages
from .timebase import CrankTimebase
from ..geometry.diagrams import space_from_state, strokes_from_scene
from ..geometry.instant_centres import full_scene
from ..units import rpm_from_rad_per_s

__all__ = ['KinematicsNode', 'TickThreadError', 'main']

NODE_NAME = 'mech_kinematics'

#: Allowed ranges of the numeric parameters: name -> (low, high, unit).
RANGES = {
    'crank_speed_rpm': (-100_000.0, 100_000.0, 'rpm'),
    'crank_accel': (-1.0e6, 1.0e6, 'rad/s^2'),
    'rate_hz': (1.0, 10_000.0, 'Hz'),
    'max_crank_speed_rpm': (0.0, 100_000.0, 'rpm'),
    'marker_velocity_scale': (0.0, 1000.0, 'm per m/s'),
    'marker_acceleration_scale': (0.0, 1000.0, 'm per m/s^2'),
}
NUMERIC = tuple(RANGES)
DEFAULT_RATE_HZ = 100.0
DEFAULT_FRAME_ID = 'mechanism'
#: Default bound on the crank speed (raised to the scene's speed if that is faster).
DEFAULT_MAX_CRANK_SPEED_RPM = 10_000.0
#: A tick that starts later than min(period / 2, LATE_NS) after its deadline is late.
LATE_NS = 1_000_000
#: Longest single sleep of the tick thread, so that a stop is seen quickly.
MAX_SLEEP_NS = 50_000_000
NS_PER_S = 1_000_000_000
#: Longest time another thread may hold the GIL before the tick thread gets it, s.
SWITCH_INTERVAL_S = 0.0005

STATE_QOS = QoSProfile(history=QoSHistoryPolicy.KEEP_LAST, depth=10,
                       reliability=QoSReliabilityPolicy.RELIABLE,
                       durability=QoSDurabilityPolicy.VOLATILE)


def rpm_parameter(speed: float) -> float:
    """Return ``speed`` (rad/s) in rpm, rounded to 12 significant digits (-120, not -119.99...)."""
    return float(f'{rpm_from_rad_per_s(speed):.12g}')


def _set_timer_slack(ns: int) -> None:
    """Ask Linux for a tight wake-up of this thread (the default slack is 50 us)."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(29, ctypes.c_ulong(ns), 0, 0, 0)   # PR_SET_TIMERSLACK
    except (OSError, AttributeError):
        pass  # no prctl here: keep the default timer slack


class TickThreadError(RuntimeError):
    """The tick thread stopped on an unexpected error (logged where it happened)."""


class _Stats:
    """Counters of the tick thread, read by the diagnostics timer (guarded by ``lock``)."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.ticks = self.published = self.late = self.skipped = self.unsolved = 0
        self.near_singular = 0
        self.window_start_ns = time.monotonic_ns()
        self.window_ticks = self.window_unsolved = self.window_near = 0
        self.window_late = self.window_skipped = 0
        self.lateness: list[int] = []
        self.worst_measure = math.inf
        self.last_error = ''
        self.last_sample: tuple[float, float, float] | None = None
        self.last_published_stamp = 0


class KinematicsNode(Node):
    """Publish the kinematic state of a scene on ``joint_states`` and friends at ``rate_hz``.

    Raises
    ------
    mech_kinematics.SceneError
        If the scene cannot be loaded or does not assemble.
    rclpy.exceptions.InvalidParameterValueException
        If a parameter given at start is refused.
    """

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(NODE_NAME, **kwargs)
        try:
            self._setup()
        except BaseException:
            self.destroy_node()
            raise

    # -- set-up -------------------------------------------------------------

    def _setup(self) -> None:
        self._stop = threading.Event()
        self._clock_event = threading.Event()
        self.failed = False
        self._thread: threading.Thread | None = None
        self._stats = _Stats()
        self._timebase: CrankTimebase | None = None
        self._timebase_lock = threading.Lock()
        self._failure_guard = self.create_guard_condition(self._on_failure)
        self.add_pre_set_parameters_callback(self._coerce_numbers)
        self.add_on_set_parameters_callback(self._validate)

        scene_name = self.declare_parameter('scene', mk.DEFAULT_SCENE, ParameterDescriptor(
            description='Scene YAML: a path, or the name of a scene in config/scenes/',
            read_only=True)).value
        # Loading checks that the whole mechanism assembles at its initial angle.
        self.scene = mk.load_scene(scene_name)
        self.frame_id = self.declare_parameter('frame_id', DEFAULT_FRAME_ID, ParameterDescriptor(
            description='header.frame_id of every message (the ground frame of the scene)',
            read_only=True)).value
        scene_rpm = rpm_parameter(self.scene.input.speed)
        self._declare_number(
            'max_crank_speed_rpm', max(DEFAULT_MAX_CRANK_SPEED_RPM, abs(scene_rpm)),
            'Bound on |crank speed|, rpm: an accelerating drive holds its speed there; '
            'crank_speed_rpm may not exceed it')
        self._declare_number(
            'crank_speed_rpm', scene_rpm,
            'Crank speed, rpm, + CCW, from the moment it is set (the crank angle stays '
            "continuous). Defaults to the scene's input.speed_rpm")
        self._declare_number(
            'crank_accel', self.scene.input.accel,
            'Crank angular acceleration, rad/s^2, + CCW, from the moment it is set; the speed '
            "is held at +-max_crank_speed_rpm. Defaults to the scene's input.accel")
        self._declare_number('rate_hz', DEFAULT_RATE_HZ, 'Publish rate, Hz')
        markers = self.declare_parameter('markers', False, ParameterDescriptor(
            description='Also publish visualization_msgs/MarkerArray on markers, at most 30 Hz',
            read_only=True, dynamic_typing=True)).value
        self._declare_number('marker_velocity_scale', DEFAULT_VELOCITY_SCALE,
                             'Length of the velocity arrows on markers per unit velocity')
        self._declare_number('marker_acceleration_scale', DEFAULT_ACCELERATION_SCALE,
                             'Length of the acceleration arrows on markers per unit acceleration')
        self.add_post_set_parameters_callback(self._apply)
        self._period_ns = round(NS_PER_S / self.get_parameter('rate_hz').value)

        self._messages = TickMessages(self.scene.output_joints, self.scene.output_points,
                                      self.frame_id)
        self._pub_joint_states = self.create_publisher(JointState, 'joint_states', STATE_QOS)
        self._pub_joint_accel = self.create_publisher(
            JointTrajectory, 'joint_accelerations', STATE_QOS)
        self._pub_point_accel = self.create_publisher(
            MultiDOFJointTrajectory, 'point_accelerations', STATE_QOS)
        self._pub_diagnostics = self.create_publisher(DiagnosticArray, 'diagnostics', 10)
        self._pub_markers = None
        if markers:
            self._setup_markers()
        self._diagnostics_timer = self.create_timer(
            1.0, self._publish_diagnostics, clock=Clock(clock_type=ClockType.STEADY_TIME))
        self._jump_handle = self.get_clock().create_jump_callback(
            JumpThreshold(min_forward=Duration(nanoseconds=1), min_backward=None,
                          on_clock_change=True),
            post_callback=lambda _jump: self._clock_event.set())

        p = {name: self.get_parameter(name).value for name in
             ('scene', 'crank_speed_rpm', 'crank_accel', 'max_crank_speed_rpm', 'rate_hz',
              'frame_id', 'use_sim_time', 'markers')}
        self.get_logger().info(
            f'scene {self.scene.name!r} ({p["scene"]}): joints {list(self.scene.output_joints)}, '
            f'points {list(self.scene.output_points)}; crank_speed_rpm={p["crank_speed_rpm"]}, '
            f'crank_accel={p["crank_accel"]}, max_crank_speed_rpm={p["max_crank_speed_rpm"]}, '
            f'rate_hz={p["rate_hz"]}, frame_id={p["frame_id"]!r}, '
            f'use_sim_time={p["use_sim_time"]}, markers={p["markers"]}')

    def _setup_markers(self) -> None:
        """Prepare the markers: the whole scene, its strokes and size, the publisher."""
        self._marker_scene = full_scene(self.scene)
        self._marker_strokes = strokes_from_scene(self._marker_scene)
        try:
            self._marker_size: float | None = marker_size_from_space(space_from_state(
                self._marker_scene, mk.solve(self._marker_scene, self.scene.input.angle)))
        except mk.AssemblyError:
            self._marker_size = None    # the part beyond the outputs cannot assemble here
        self._marker_throttle = MarkerThrottle()
        self._marker_lock = threading.Lock()
        self._marker_request: tuple[int, int, float, float, float] | None = None
        self._marker_guard = self.create_guard_condition(self._publish_markers)
        self._pub_markers = self.create_publisher(MarkerArray, 'markers', 10)

    def _declare_number(self, name: str, default: float, description: str) -> None:
        low, high, unit = RANGES[name]
        # dynamic_typing lets an integer through (-p rate_hz:=500, rclcpp#979);
        # _validate refuses anything that is not a number and the value is
        # stored as a double.
        descriptor = ParameterDescriptor(
            description=f'{description} [{unit}]', dynamic_typing=True,
            floating_point_range=[FloatingPointRange(from_value=low, to_value=high)])
        value = self.declare_parameter(name, float(default), descriptor).value
        if type(value) is int:
            self.set_parameters([Parameter(name, Parameter.Type.DOUBLE, float(value))])

    # -- parameters ---------------------------------------------------------

    @staticmethod
    def _coerce_numbers(parameters: list[Parameter]) -> list[Parameter]:
        """Turn an integer given for a numeric parameter into a double (rclcpp#979)."""
        return [Parameter(p.name, Parameter.Type.DOUBLE, float(p.value))
                if p.name in NUMERIC and p.type_ == Parameter.Type.INTEGER else p
                for p in parameters]

    def _current(self, name: str) -> Any:
        return self.get_parameter(name).value if self.has_parameter(name) else None

    def _validate(self, parameters: list[Parameter]) -> SetParametersResult:
        """Refuse a value that is not a finite number in range, or breaks the speed bound."""
        new = {p.name: p for p in parameters}
        for p in parameters:
            if p.name in NUMERIC:
                low, high, unit = RANGES[p.name]
                if p.type_ not in (Parameter.Type.DOUBLE, Parameter.Type.INTEGER):
                    return SetParametersResult(successful=False, reason=(
                        f'{p.name}: expected a number ({unit}), got {p.type_.name.lower()} '
                        f'{p.value!r}'))
                value = float(p.value)
                if not math.isfinite(value):
                    return SetParametersResult(successful=False, reason=(
                        f'{p.name}: expected a finite number, got {value!r}'))
                if not low <= value <= high:
                    return SetParametersResult(successful=False, reason=(
                        f'{p.name}: expected {low:g} <= value <= {high:g} {unit}, got {value!r}'))
            elif p.name in ('scene', 'frame_id') and (
                    p.type_ != Parameter.Type.STRING or not p.value):
                return SetParametersResult(successful=False, reason=(
                    f'{p.name}: expected a non-empty string, got {p.value!r}'))
            elif p.name == 'markers' and p.type_ != Parameter.Type.BOOL:
                return SetParametersResult(successful=False, reason=(
                    f'markers: expected true or false, got {p.type_.name.lower()} {p.value!r}'))
        if 'crank_speed_rpm' in new or 'max_crank_speed_rpm' in new:
            speed = new['crank_speed_rpm'].value if 'crank_speed_rpm' in new else \
                self._current('crank_speed_rpm')
            bound = new['max_crank_speed_rpm'].value if 'max_crank_speed_rpm' in new else \
                self._current('max_crank_speed_rpm')
            if speed is not None and bound is not None and abs(speed) > bound:
                return SetParametersResult(successful=False, reason=(
                    f'crank_speed_rpm: expected |crank_speed_rpm| <= max_crank_speed_rpm '
                    f'({float(bound):g} rpm), got {float(speed):g} rpm'))
        return SetParametersResult(successful=True)

    def _apply(self, parameters: list[Parameter]) -> None:
        """Apply accepted values: the drive changes at the current instant, the rate at once."""
        changes = {p.name: float(p.value) for p in parameters if p.name in NUMERIC}
        if 'rate_hz' in changes:
            self._period_ns = round(NS_PER_S / changes['rate_hz'])
        drive = {key: changes.get(name) for key, name in (
            ('speed_rpm', 'crank_speed_rpm'), ('accel', 'crank_accel'),
            ('max_speed_rpm', 'max_crank_speed_rpm'))}
        if any(v is not None for v in drive.values()):
            with self._timebase_lock:
                if self._timebase is not None:
                    self._timebase.update(self.get_clock().now().nanoseconds, **drive)
        changed = ', '.join(f'{p.name}={p.value!r}' for p in parameters)
        self.get_logger().info(f'parameters set: {changed}')

    # -- the tick thread ----------------------------------------------------

    def start(self) -> None:
        """Start the tick thread."""
        self._thread = threading.Thread(target=self._run, name='mech_kinematics_tick',
                                        daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop the tick thread and wait for it."""
        self._stop.set()
        self._clock_event.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=2.0)
            self._thread = None

    def destroy_node(self) -> None:
        """Stop the tick thread, then destroy the node."""
        if hasattr(self, '_stop'):
            self.stop()
        handle = getattr(self, '_jump_handle', None)
        if handle is not None:
            handle.unregister()
            self._jump_handle = None
        super().destroy_node()

    def _new_timebase(self, t: int) -> CrankTimebase:
        get = self.get_parameter
        return CrankTimebase(t, self.scene.input.angle, get('crank_speed_rpm').value,
                             get('crank_accel').value, get('max_crank_speed_rpm').value)

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
        clock = self.get_clock()
        stop = self._stop
        monotonic_ns, time_ns, sleep = time.monotonic_ns, time.time_ns, time.sleep
        sim = False
        previous = monotonic_ns() - self._period_ns     # deadline of the last tick
        sim_previous: int | None = None                 # the same on the simulated clock
        last_stamp: int | None = None
        rebase_from: int | None = None
        while not stop.is_set():
            if clock.ros_time_is_active != sim:
                # The time source changed and its epoch means nothing to the old
                # one: the crank goes on from where it was, at the next tick.
                sim = clock.ros_time_is_active
                sim_previous = None
                previous = monotonic_ns() - self._period_ns
                rebase_from = last_stamp
            period = self._period_ns
            if sim:
                # Ticks follow the simulated clock: wake on every /clock update.
                self._clock_event.wait(MAX_SLEEP_NS / NS_PER_S)
                self._clock_event.clear()
                now = clock.now().nanoseconds
                if now <= 0 or stop.is_set():
                    continue        # no /clock received yet
                if sim_previous is None or now < sim_previous:
                    sim_previous = now - period     # first tick, or the clock went back
                deadline = sim_previous + period
                if now < deadline:
                    continue
                missed = (now - deadline) // period
                sim_previous = deadline + missed * period
                if rebase_from is not None:
                    self._rebase(rebase_from, now)
                    rebase_from = None
                self._tick(now, 0, missed)
                last_stamp = now
                continue
            # The rate may change while waiting: the deadline is always one
            # period (the current one) after the last.
            deadline = previous + period
            remaining = deadline - monotonic_ns()
            if remaining > 0:
                sleep(min(remaining, MAX_SLEEP_NS) / NS_PER_S)
                continue
            woke = monotonic_ns()
            # ROS time with use_sim_time off is the system clock; time_ns() reads
            # the same CLOCK_REALTIME several microseconds faster than clock.now().
            stamp = time_ns()
            lateness = woke - deadline
            # Whole periods that went by are skipped: no catch-up burst.
            missed = lateness // period
            previous = deadline + missed * period
            if rebase_from is not None:
                self._rebase(rebase_from, stamp)
                rebase_from = None
            self._tick(stamp, lateness, missed)
            last_stamp = stamp

    def _rebase(self, old: int, new: int) -> None:
        with self._timebase_lock:
            if self._timebase is not None:
                self._timebase = self._timebase.moved(old, new)

    def _tick(self, stamp: int, lateness: int, missed: int) -> None:
        timebase = self._timebase
        if timebase is None:
            with self._timebase_lock:
                if self._timebase is None:
                    self._timebase = self._new_timebase(stamp)
                timebase = self._timebase
        angle, speed, accel = timebase.sample(stamp)
        error = None
        measure = math.inf
        try:
            state = mk.solve(self.scene, angle, speed, accel)
        except mk.AssemblyError as exc:
            error = str(exc)
        else:
            sec, nanosec = divmod(stamp, NS_PER_S)
            joint_states, joint_accel, point_accel = self._messages.render(state, sec, nanosec)
            self._pub_joint_states.publish(joint_states)
            self._pub_joint_accel.publish(joint_accel)
            self._pub_point_accel.publish(point_accel)
            if self._pub_markers is not None and self._marker_throttle.due(
                    self._period_ns, time.monotonic_ns()):
                # Built in the executor's thread, so that this thread keeps its deadlines.
                with self._marker_lock:
                    self._marker_request = (sec, nanosec, angle, speed, accel)
                self._marker_guard.trigger()
            if state.singularity:
                measure = min(state.singularity.values())
        late = lateness > min(self._period_ns // 2, LATE_NS)
        stats = self._stats
        with stats.lock:
            stats.ticks += 1
            stats.window_ticks += 1
            stats.lateness.append(lateness)
            stats.last_sample = (angle, speed, accel)
            if late:
                stats.late += 1
                stats.window_late += 1
            if missed:
                stats.skipped += missed
                stats.window_skipped += missed
            if error is None:
                stats.published += 1
                stats.last_published_stamp = stamp
                if measure < stats.worst_measure:
                    stats.worst_measure = measure
                if measure < mk.NEAR_SINGULAR:
                    stats.near_singular += 1
                    stats.window_near += 1
            else:
                stats.unsolved += 1
                stats.window_unsolved += 1
                stats.last_error = error
        if error is not None:
            self.get_logger().warning(f'no state published: {error}',
                                      throttle_duration_sec=1.0)
        elif measure < mk.NEAR_SINGULAR:
            self.get_logger().warning(
                f'near-singular pose at crank angle {angle:.6f} rad: measure {measure:.3g}',
                throttle_duration_sec=1.0)

    # -- markers ----------------------------------------------------------------

    def _publish_markers(self) -> None:
        """Publish the markers of the last sample the tick thread handed over, if any."""
        with self._marker_lock:
            request, self._marker_request = self._marker_request, None
        if request is None or self._pub_markers is None:
            return
        sec, nanosec, angle, speed, accel = request
        try:
            state = mk.solve(self._marker_scene, angle, speed, accel)
        except mk.AssemblyError:
            return      # a part beyond the outputs cannot assemble: no markers this time
        self._pub_markers.publish(marker_array_from_state(
            self._marker_scene, state, frame_id=self.frame_id,
            stamp=Time(sec=sec, nanosec=nanosec),
            velocity_scale=self.get_parameter('marker_velocity_scale').value,
            acceleration_scale=self.get_parameter('marker_acceleration_scale').value,
            points=self.scene.output_points, size=self._marker_size,
            strokes=self._marker_strokes))

    # -- diagnostics --------------------------------------------------------

    def _publish_diagnostics(self) -> None:
        stats = self._stats
        now_mono = time.monotonic_ns()
        with stats.lock:
            elapsed = (now_mono - stats.window_start_ns) / NS_PER_S
            ticks, unsolved, near = stats.window_ticks, stats.window_unsolved, stats.window_near
            late, skipped = stats.window_late, stats.window_skipped
            lateness = stats.lateness
            worst, error, sample = stats.worst_measure, stats.last_error, stats.last_sample
            totals = (stats.ticks, stats.published, stats.late, stats.skipped, stats.unsolved)
            last_published_stamp = stats.last_published_stamp
            stamp = self.get_clock().now().to_msg()
            stats.window_start_ns = now_mono
            stats.window_ticks = stats.window_unsolved = stats.window_near = 0
            stats.window_late = stats.window_skipped = 0
            stats.lateness = []
            stats.worst_measure = math.inf
        rate = self.get_parameter('rate_hz').value
        achieved = ticks / elapsed if elapsed > 0 else 0.0
        lateness.sort()

        def quantile(q: float) -> float:
            return lateness[min(len(lateness) - 1, int(q * len(lateness)))] / 1e3

        solver = DiagnosticStatus(name=f'{self.get_name()}: solver',
                                  hardware_id=self.scene.name)
        if ticks == 0:
            solver.level, solver.message = DiagnosticStatus.STALE, 'no ticks (waiting for clock)'
        elif unsolved:
            solver.level = DiagnosticStatus.ERROR
            solver.message = f'cannot assemble at {unsolved} of {ticks} ticks: {error}'
        elif near:
            solver.level = DiagnosticStatus.WARN
            solver.message = f'near-singular at {near} of {ticks} ticks'
        else:
            solver.level, solver.message = DiagnosticStatus.OK, 'ok'
        solver.values = [
            KeyValue(key='worst_singularity_measure',
                     value=f'{worst:.6g}' if math.isfinite(worst) else 'n/a'),
            KeyValue(key='near_singular_threshold', value=f'{mk.NEAR_SINGULAR:g}'),
            KeyValue(key='unsolved_ticks', value=str(unsolved)),
            KeyValue(key='unsolved_ticks_total', value=str(totals[4])),
            KeyValue(key='last_error', value=error),
        ]
        if sample is not None:
            solver.values += [KeyValue(key='crank_angle', value=repr(sample[0])),
                              KeyValue(key='crank_speed', value=repr(sample[1])),
                              KeyValue(key='crank_accel', value=repr(sample[2]))]
        timing = DiagnosticStatus(name=f'{self.get_name()}: timing', hardware_id=self.scene.name)
        if ticks and (late or skipped or achieved < 0.9 * rate):
            timing.level = DiagnosticStatus.WARN
            timing.message = f'{late} late and {skipped} skipped ticks in {elapsed:.2f} s'
        else:
            timing.level, timing.message = DiagnosticStatus.OK, 'ok'
        timing.values = [
            KeyValue(key='rate_hz', value=f'{rate:g}'),
            KeyValue(key='achieved_rate_hz', value=f'{achieved:.3f}'),
            KeyValue(key='late_ticks', value=str(late)),
            KeyValue(key='skipped_ticks', value=str(skipped)),
            KeyValue(key='lateness_median_us',
                     value=f'{statistics.median(lateness) / 1e3:.1f}' if lateness else 'n/a'),
            KeyValue(key='lateness_p99_us', value=f'{quantile(0.99):.1f}' if lateness else 'n/a'),
            KeyValue(key='lateness_max_us', value=f'{lateness[-1] / 1e3:.1f}' if lateness
                     else 'n/a'),
            KeyValue(key='ticks_total', value=str(totals[0])),
            KeyValue(key='published_total', value=str(totals[1])),
            KeyValue(key='last_published_stamp_ns', value=str(last_published_stamp)),
            KeyValue(key='late_ticks_total', value=str(totals[2])),
            KeyValue(key='skipped_ticks_total', value=str(totals[3])),
        ]
        msg = DiagnosticArray(status=[solver, timing])
        msg.header.stamp = stamp
        msg.header.frame_id = self.frame_id
        self._pub_diagnostics.publish(msg)


def main(args: list[str] | None = None) -> int:
    """Run the node until Ctrl-C or SIGTERM; return the exit status."""
    # The node reports near-singular poses on diagnostics and in its log.
    warnings.filterwarnings('ignore', category=mk.NearSingularWarning)
    # The tick thread must not wait long for the GIL when it wakes (default 5 ms).
    sys.setswitchinterval(SWITCH_INTERVAL_S)
    rclpy.init(args=args)
    node = None
    status = 0
    try:
        node = KinematicsNode()
        # Everything built so far lives as long as the node: keep it out of the
        # garbage collector's full passes, which would otherwise delay ticks.
        gc.freeze()
        node.start()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass  # Ctrl-C or shutdown: a clean exit, status 0
    except (mk.MechKinematicsError, InvalidParameterValueException) as exc:
        get_logger(NODE_NAME).fatal(f'cannot start: {exc}')
        status = 1
    except TickThreadError:
        status = 1
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return status


if __name__ == '__main__':
    sys.exit(main())
