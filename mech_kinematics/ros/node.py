# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""ROS 2 node ``mech_kinematics``: the kinematic state of a linkage on an exact time grid.

The node is an adapter around the pure solver: each of its concerns is a
module of its own, and :class:`KinematicsNode` wires them to one
``LifecycleNode``:

- its parameters (:mod:`~mech_kinematics.ros.node_parameters` on the table of
  :mod:`~mech_kinematics.ros.parameters`), declared at once;
- the drivers on the clock (:mod:`~mech_kinematics.ros.drive`: each one's
  exact time base and start; :mod:`~mech_kinematics.ros.driver`: the grid);
- the function that solves a tick (:mod:`~mech_kinematics.ros.solver_path`:
  compiled, or the general solver and why);
- what it publishes (:mod:`~mech_kinematics.ros.publishing`: the state topics,
  ``/tf``, the IMUs, markers, the descriptions; on a scene with masses, gravity
  or loads the forces, :mod:`~mech_kinematics.ros.wrenches`);
- the tick thread (:mod:`~mech_kinematics.ros.tick_thread`) with ``drive:
  time``, or the input subscription (:mod:`~mech_kinematics.ros.topic_input`)
  with ``drive: topic``;
- the 1 Hz ``diagnostics`` (:mod:`~mech_kinematics.ros.diagnostics`).

It follows the ROS 2 node lifecycle (configure loads the scene and creates
the publishers, activate starts the tick thread, deactivate stops it, cleanup
drops the scene); with ``managed: false`` (the default) :func:`~mech_kinematics.ros.main.main`
configures and activates it at start, and :mod:`~mech_kinematics.ros.instance`
keeps one node of a name.

Run it with ``ros2 run mech_kinematics kinematics_node`` or
``python -m mech_kinematics.kinematics_node [--ros-args ...]``.
"""

from __future__ import annotations

from contextlib import nullcontext
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray
from rclpy.clock import Clock, ClockType, JumpThreshold
from rclpy.duration import Duration
from rclpy.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn

from . import topics
from .diagnostics import solver_status, TickStats, timing_status, waiting_for
from .drive import check_start
from .driver import TickDriver
from .node_parameters import NodeParameters
from .parameters import (CATCH_UP, extra_joints_default, spec, SUBSCRIBED_DRIVES, TARGET,
                         TRAJECTORY)
from .publishing import diagnostic_array, Markers, Publishing, qos_options, tf_period_ns
from .robot_forces import robot_forces_note, robot_forces_tick
from .robot_mode import load_source, robot_forces_refusal
from .schedule import period_ns_from_rate
from .solver_path import SolverPath
from .startup import stop_raises
from .target_drive import target_branch
from .tick_thread import TickThread, TickThreadError
from .topic_input import InputSubscription
from .watchdog import PublishWatch, PublishWatchdog
from .wrenches import effort_status, forces_tick, ForcesTick, scene_forces_refusal
from ..errors import SceneError
from ..solver.context import NEAR_SINGULAR
from ..units import NS_PER_S

__all__ = ['KinematicsNode', 'NODE_NAME', 'StartError', 'one_line']

NODE_NAME = 'mech_kinematics'


def one_line(error: BaseException) -> str:
    """Return ``error``'s text on one line (its type's name if it has none)."""
    return ' '.join(str(error).split()) or type(error).__name__


class StartError(Exception):
    """The node refused to start: ``reason`` (one line), for the logger named ``logger_name``."""

    def __init__(self, reason: str, logger_name: str) -> None:
        super().__init__(reason)
        self.reason = reason
        self.logger_name = logger_name


class KinematicsNode(LifecycleNode):
    """Publish the kinematic state of a scene on ``joint_states`` and friends at ``rate_hz``.

    Raises
    ------
    StartError
        If a parameter given at start is refused (its reason, one line).
    """

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(NODE_NAME, **kwargs)
        self.params: NodeParameters | None = None
        try:
            self._declare()
        except BaseException as error:
            logger_name = self.get_logger().name
            reason = (self.params.start_refusal if self.params is not None else '') \
                or one_line(error)
            self.destroy_node()
            if isinstance(error, Exception):
                raise StartError(reason, logger_name) from None
            raise

    def _declare(self) -> None:
        self.scene: Any = None
        self.extra_joints = ''
        self.configure_error = ''
        self._stats = TickStats(NEAR_SINGULAR)
        # The clock as a pure driver, at the parameters' defaults until they are declared.
        self._driver = TickDriver(period_ns_from_rate(spec('rate_hz').default),
                                  round(spec('max_catch_up_s').default * NS_PER_S),
                                  spec('late_ticks').default == CATCH_UP)
        self._solver = SolverPath(spec('max_relative_error').default)
        self._publishing: Publishing | None = None
        self._markers: Markers | None = None
        self._input: InputSubscription | None = None
        self._forces: ForcesTick | None = None
        self._has_forces = False
        self._watchdog: PublishWatchdog | None = None    # once the parameters are declared
        failure = self.create_guard_condition(self._on_failure)
        self._ticks = TickThread(self.get_clock(), self._driver, self._stats, self.get_logger(),
                                 failure.trigger, lambda: not self.context.ok())
        self.params = NodeParameters(self, self._driver, self._on_change)
        self.params.declare()
        self._solver.max_error = float(self._value('max_relative_error'))
        self.managed = bool(self._value('managed'))
        self.frame_id = self._value('frame_id')
        # A publish that never returns (Fast DDS's shared-memory hang) ends the process.
        self._watch = PublishWatch()
        self._watchdog = PublishWatchdog(self._watch, float(self._value('publish_timeout_s')),
                                         self.get_logger().fatal)
        pub_diagnostics = self.create_publisher(
            DiagnosticArray, topics.DIAGNOSTICS, 10, qos_overriding_options=qos_options())
        self._publish_diagnostic_array = self._watch.wrap(
            self._watch.slot(), topics.DIAGNOSTICS, pub_diagnostics.publish)
        self._diagnostics_timer = self.create_timer(
            1.0, self._publish_diagnostics, clock=Clock(clock_type=ClockType.STEADY_TIME))
        self._jump_handle = self.get_clock().create_jump_callback(
            JumpThreshold(min_forward=Duration(nanoseconds=1), min_backward=None,
                          on_clock_change=True),
            post_callback=lambda _jump: self._ticks.clock_event.set())

    @property
    def failed(self) -> bool:
        """Whether the tick thread stopped on an unexpected error."""
        return self._ticks.failed

    def _value(self, name: str) -> Any:
        return self.get_parameter(name).value

    def _on_change(self, changes: dict[str, Any], requested: bool) -> None:
        """Apply accepted values to what runs (the clock's driver has its own)."""
        if 'tf_rate_hz' in changes and self._publishing is not None:
            self._publishing.tf_period_ns = tf_period_ns(changes['tf_rate_hz'])
        if 'max_relative_error' in changes:
            self._solver.max_error = float(changes['max_relative_error'])
        if 'stamp_jump_back_s' in changes and self._input is not None:
            self._input.topic.jump_back_ns = round(changes['stamp_jump_back_s'] * NS_PER_S)
        forces = self.params.force_changes(changes) if self.params is not None else {}
        if forces and self._forces is not None:
            # The forces' new model, its code written out here, read by the tick at its next
            # instant.
            self._forces.apply(forces)
            imus = self._publishing.imus if self._publishing is not None else None
            if 'gravity' in forces and imus is not None:
                imus.follow_gravity(forces['gravity'])    # the sensors of the scene's gravity
        if requested and not self._ticks.running:
            self._apply_now()   # not ticking: from the current instant

    def _apply_now(self) -> None:
        """Apply the pending drive changes from the clock now (after the last instant)."""
        self._driver.apply_now(self.get_clock().now().nanoseconds)

    # -- lifecycle ------------------------------------------------------------

    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Load the scene, fill the scene's defaults, create the publishers."""
        assert self.params is not None
        try:
            self._configure()
        except Exception as error:     # noqa: BLE001 - a scene or a QoS override: one line
            self._teardown()
            self.configure_error = ((self.params.starting and self.params.start_refusal)
                                    or one_line(error))
            if not self.params.starting or self.managed:
                self.get_logger().error(f'cannot configure: {self.configure_error}')
            return TransitionCallbackReturn.FAILURE
        return TransitionCallbackReturn.SUCCESS

    def _configure(self) -> None:
        assert self.params is not None
        # A scene, or a robot described in URDF (URDF mode: robot_mode.py).
        self.get_logger().debug('reading the scene or robot')
        # At the start (the spin not begun) a signal ends the read at once (startup.py).
        with stop_raises() if self.params.starting and not self.managed else nullcontext():
            source = load_source(self._value('scene'), self._value('robot_description'),
                                 self._value('loop_closures'), self._value('actuated_joints'),
                                 self._value('reference_pose'), self._value('payloads'),
                                 [name for name in ('link_forces', 'link_torques')
                                  if self._value(name)])
        scene = source.scene
        if self._value('drive') in (TARGET, TRAJECTORY) and any(
                name == 'extra_joints' for name in self._parameter_overrides):
            raise SceneError(f'extra_joints: Expected drive: {self._value("drive")} without '
                             'extra_joints (a message names targets or drivers only), got '
                             'extra_joints')
        branch = target_branch(self._value('target_branch'), self._value('drive'))
        if source.robot is not None:     # what would be accepted and ignored is refused
            note = robot_forces_note(source.robot)
            refusal = robot_forces_refusal(note, self._value('drive'), self._value('effort'),
                                           spec('effort').default,
                                           list(self._parameter_overrides))
            if refusal is not None:
                raise SceneError(refusal)
            if note:
                self.get_logger().warning(f'no efforts or reactions of the robot: {note}')
        else:
            refusal = scene_forces_refusal(scene.dynamics is not None, self._value('drive'),
                                           self._value('effort'),
                                           list(self._parameter_overrides), bool(scene.imus))
            if refusal is not None:
                raise SceneError(refusal)
        self.extra_joints = self._value('extra_joints') or \
            extra_joints_default(source.robot is not None)
        starts = self.params.declare_drivers(scene)
        # What `solve` refuses at the start, the node refuses to start with.
        check_start(scene, starts, self._solver.max_error)
        for d, start in zip(scene.drivers, starts, strict=True):
            self._driver.add_drive(d.name, start.kind, **start.start)
        self._publishing = publishing = Publishing(
            self, scene, frame_id=self.frame_id, tf_prefix=self._value('tf_prefix'),
            tf_rate_hz=self._value('tf_rate_hz'), scene_path=self._value('scene'),
            source=source, watch=self._watch)
        frames = [(f.origin, f.angle_of, f.angle) for f in publishing.frames]
        drive, effort = self._value('drive'), self._value('effort')
        self._forces = forces = forces_tick(scene, publishing.tick_scene, frames, drive=drive,
                                            effort=effort) if source.robot is None else \
            robot_forces_tick(source.robot, scene, drive=drive, effort=effort,
                              unloaded=source.unloaded, payloads=self._value('payloads') or ())
        self._has_forces = scene.dynamics is not None or (
            source.robot is not None and robot_forces_note(source.robot) is None)
        if forces is not None:
            values = self.params.declare_forces(forces)
            forces.apply(values)
            if publishing.imus is not None:    # a params file's gravity, from the start
                publishing.imus.follow_gravity(values['gravity'])
            publishing.add_forces(forces)
        compile_later = self._solver.setup(publishing.tick_scene, scene, frames,
                                           self.get_logger().info, forces)
        if self._value('markers'):
            self._markers = Markers(self, scene, self.frame_id, lambda: (
                self._value('marker_velocity_scale'), self._value('marker_acceleration_scale'),
                self._value('marker_force_scale')), forces)
        if self._value('drive') in SUBSCRIBED_DRIVES:
            self._input = InputSubscription(
                self, scene, self._solver, publishing, self._stats, frame_id=self.frame_id,
                extra_joints=self.extra_joints, jump_back_s=self._value('stamp_jump_back_s'),
                robot=publishing.robot_values, drive=self._value('drive'),
                target_robot=source.robot, branch=branch)
        elif publishing.robot_values is not None and publishing.robot_values.clock_note:
            self.get_logger().warning(publishing.robot_values.clock_note)
        self.scene = scene
        self.params.loaded = True
        self.get_logger().info(self.params.start_line(
            scene, {'extra_joints': self.extra_joints}, source.robot))
        if compile_later is not None:
            # Started once the rest of the set-up is done: a thread holding the GIL slows
            # every release and re-acquisition of it by this one (the assembly sweep's NumPy).
            compile_later.start()

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
        for part in (self._publishing, self._markers, self._input):
            if part is not None:
                part.close()
        self._publishing = self._markers = self._input = self._forces = None
        self._solver.drop()      # a compile still running is not installed
        self.scene = None
        if self.params is not None:
            self.params.loaded = False

    # -- the tick thread ------------------------------------------------------

    def start(self) -> None:
        """Start the tick thread (with ``drive: topic``, the input subscription instead)."""
        assert self._watchdog is not None
        self._watchdog.start()
        if self._input is not None:
            self._input.active = True     # a state for each message from now on
            return
        assert self._publishing is not None
        self._ticks.start(self._solver, self._publishing, self._markers)

    def stop(self) -> None:
        """Stop the tick thread and wait for it; apply what it left pending."""
        if self._input is not None:
            self._input.active = False
        self._ticks.stop()
        if self._watchdog is not None:     # None: a parameter refused while declaring
            self._watchdog.stop()
        self._apply_now()

    def destroy_node(self) -> None:
        """Stop the tick thread, then destroy the node."""
        if getattr(self, '_ticks', None) is not None:
            self.stop()
        handle = getattr(self, '_jump_handle', None)
        if handle is not None:
            handle.unregister()
            self._jump_handle = None
        super().destroy_node()

    def _on_failure(self) -> None:
        raise TickThreadError('the tick thread failed (see the log above)')

    # -- diagnostics ----------------------------------------------------------

    def _forces_status(self) -> list[tuple[str, str]]:
        """Return the forces' keys of the solver status (none for a scene without forces)."""
        if self.scene is None:
            return []
        effort = effort_status(self._has_forces, self._value('drive'), self._value('effort'))
        if not effort:
            return []
        forces = self._forces
        gravity = ([('gravity', repr(forces.gravity())), ('forces_path', forces.path())]
                   if forces is not None else [])
        return [('effort', effort), *gravity,
                ('forces_left_out_total', str(forces.refused if forces else 0)),
                ('last_forces_left_out', forces.refusal if forces else '')]

    def _publish_diagnostics(self) -> None:
        window = self._stats.take_window()
        name = self.get_name()
        hardware_id = self.scene.name if self.scene is not None else self._value('scene')
        publishing = self._ticks.running or (self._input is not None and self._input.active)
        waiting = waiting_for(configured=self.scene is not None, publishing=publishing,
                              managed=self.managed, clock=self._ticks.waiting_for_clock)
        statuses = [
            solver_status(window, name=name, hardware_id=hardware_id,
                          near_singular=NEAR_SINGULAR, waiting_for=waiting,
                          assembly=self._solver.assembly,
                          extra_joints=self.extra_joints if self._input else '',
                          solver_path=self._solver.path, forces=self._forces_status()),
            timing_status(window, name=name, hardware_id=hardware_id,
                          rate_hz=self._value('rate_hz'),
                          max_lateness_ms=self._value('max_lateness_ms')),
        ]
        self._publish_diagnostic_array(diagnostic_array(
            statuses, self.get_clock().now().to_msg(), self.frame_id))
