# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Plots of a mechanism's motion from a bag or the solver: ``python -m mech_kinematics plot``.

``plot BAG -o FILE.png`` reads a bag recorded from the node (by ``record``
or by ``ros2 bag record``; mcap or sqlite3) with :mod:`rosbags`;
``plot --scene SCENE -o FILE.png`` solves one crank cycle. Both draw, against
time or crank angle, in SI units:

- joint angles, angular velocities and angular accelerations (revolute joints);
- slider positions, velocities and accelerations (prismatic joints, if any);
- the paths of the points, and the magnitudes of their velocities and
  accelerations;
- what the scene's IMUs read (orientation, angular velocity, the x and y of
  the linear acceleration in each sensor's frame), if it has any: from a bag,
  its ``imu/NAME`` topics;
- for a scene with forces (``masses``, ``gravity`` or ``loads``), from the
  solver: the turning-moment diagram (every driver's effort, with the
  crank's mean over the turn, :mod:`mech_kinematics.geometry.turning`), the
  force each joint carries and the shaking force on the frame.

Figures are built with Matplotlib's object API (``Figure``, no pyplot), so no
display or backend choice is involved: PNG goes through Agg. Matplotlib and
rosbags are imported inside the functions, so importing this module is cheap.
"""

from __future__ import annotations

import argparse
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
import math
import os
from pathlib import Path
import stat
import sys
import textwrap
from typing import Any
import warnings

import numpy as np
import numpy.typing as npt

from .check import grid_size
from .cli import (add_robot_arguments, add_units_argument, angular_rate_given, is_urdf,
                  load_robot_argument, load_scene_argument, named_value, values_by_driver)
from .cli import finite_float, positive_float, PROG, run_tool
from ..errors import MechKinematicsError, SceneError
from ..geometry.region import GRID
from ..ros import topics
from ..ros.cdr import stamp_from_cdr
from ..solver.graph import REVOLUTE
from ..units import NS_PER_S, rad_per_s_from_rpm, rpm_from_rad_per_s

__all__ = [
    'DEFAULT_MAX_SAMPLES', 'DEFAULT_SAMPLES', 'ForceSeries', 'Motion', 'PlotError', 'add_parser',
    'drivers_period', 'figure_from_motion', 'main', 'motion_from_bag', 'motion_from_scene',
    'plot_bag', 'plot_scene', '_handle', 'save_figure',
]

Array = npt.NDArray[np.float64]

#: Samples over one crank cycle for a scene (every half degree).
DEFAULT_SAMPLES = 721
#: Most ticks decoded from a bag (a 1 kHz minute has 60 000); more draw no differently.
DEFAULT_MAX_SAMPLES = 20_000
#: Most crank angles per cycle for ``--samples`` (memory stays bounded; no figure shows more).
MAX_SAMPLES = 100_000
#: The largest magnitude a panel draws: matplotlib's axis margins and ticks overflow on values
#: near the largest double (gravity [1.2e308, 1.2e308] on a light scene: forces of 1.7e308 N
#: gave eight RuntimeWarnings and "arange: cannot compute length"); beyond it, one line.
MAX_DRAWN = 1e300
AXES = ('time', 'angle')
#: Panel titles, by column; tests and readers rely on them.
TITLES = {
    'joint_position': 'Joint angles',
    'joint_velocity': 'Joint angular velocities',
    'joint_acceleration': 'Joint angular accelerations',
    'point_path': 'Point paths',
    'point_speed': 'Point speeds |v|',
    'point_acceleration': 'Point accelerations |a|',
    'slider_position': 'Slider positions',
    'slider_velocity': 'Slider velocities',
    'slider_acceleration': 'Slider accelerations',
    'imu_orientation': 'IMU orientations',
    'imu_angular_velocity': 'IMU angular velocities',
    'imu_acceleration': 'IMU linear accelerations (sensor frame)',
    'effort': 'Turning moment (driver efforts)',
    'reaction': 'Joint reactions |F|',
    'shaking': 'Shaking force on the frame |F|',
}
YLABELS = {
    'joint_position': 'angle [rad]',
    'joint_velocity': 'angular velocity [rad/s]',
    'joint_acceleration': 'angular acceleration [rad/s²]',
    'point_path': 'y [m]',
    'point_speed': 'speed [m/s]',
    'point_acceleration': 'acceleration [m/s²]',
    'slider_position': 'position [m]',
    'slider_velocity': 'velocity [m/s]',
    'slider_acceleration': 'acceleration [m/s²]',
    'imu_orientation': 'angle [rad]',
    'imu_angular_velocity': 'angular velocity [rad/s]',
    'imu_acceleration': 'acceleration [m/s²]',
    'effort': 'effort [N m]',
    'reaction': 'force [N]',
    'shaking': 'force [N]',
}
#: The effort panel's label where some driver is an actuator (its effort a force).
EFFORT_LABELS = {(True,): 'effort [N m]', (False,): 'effort [N]',
                 (False, True): 'effort [N m; N for an actuator]'}
XLABELS = {'time': 'time [s]', 'angle': 'crank angle θ [rad]', 'path': 'x [m]'}
#: The node's topics, by message type.
_JOINT_STATE = topics.TYPES[topics.JOINT_STATES]
_JOINT_TRAJECTORY = topics.TYPES[topics.JOINT_ACCELERATIONS]
_POINT_TRAJECTORY = topics.TYPES[topics.POINT_ACCELERATIONS]
_DIAGNOSTICS = topics.TYPES[topics.DIAGNOSTICS]
_SCENE = topics.TYPES[topics.SCENE]  # the scene file's text, latched on `scene` (issue 20)
_TOPICS = {topics.TYPES[t]: t for t in (*topics.STATE_TOPICS, topics.DIAGNOSTICS, topics.SCENE)}


class PlotError(MechKinematicsError):
    """A plot cannot be made from the given bag or scene."""


@dataclass(frozen=True)
class ForceSeries:
    """The forces along a :class:`Motion`, from the solver (SI; NaN where not solved).

    Attributes
    ----------
    efforts : dict of str to ndarray, shape (n,)
        Every driver's effort: a crank's torque (N m), an actuator's force (N).
    angular : dict of str to bool
        Per driver, whether it is a crank (its effort a torque).
    reactions : dict of str to ndarray, shape (n,)
        The force each joint carries, N: a pin's ``|F|``, a prismatic joint's
        ``|normal|`` (labelled ``NAME (normal)``); a joint named otherwise
        than its point is labelled ``NAME at POINT``.
    shaking : ndarray, shape (n,), or None
        The magnitude of the shaking force on the frame, N (None: a recording
        without it).
    means : dict of str to float
        The crank's mean effort over its turn (the turning-moment diagram's
        mean line), where the motion is one turn of one crank.
    note : str
        Why there is no mean line, or ''.
    """

    efforts: Mapping[str, Array]
    angular: Mapping[str, bool]
    reactions: Mapping[str, Array]
    shaking: Array | None
    means: Mapping[str, float] = field(default_factory=dict)
    note: str = ''


@dataclass(frozen=True)
class Motion:
    """A mechanism's kinematic state at n instants (one crank cycle or a recording).

    Attributes
    ----------
    title : str
        What the data are, for the figure's title.
    crank_angle : ndarray, shape (n,)
        Crank angle, rad.
    time : ndarray, shape (n,) or None
        Time from the first sample, s; None where it means nothing.
    joint_types : dict of str to str
        ``'revolute'`` or ``'prismatic'`` per joint, in order.
    joints : dict of str to (ndarray, ndarray or None, ndarray or None)
        Position (rad or m), velocity and acceleration (None if not
        available; NaN at an instant without it), each of shape (n,).
    points : dict of str to (ndarray, ndarray or None, ndarray or None)
        Position (m), velocity (m/s) and acceleration (m/s²; None if not
        available, NaN at an instant without it), each of shape (n, 2).
    jumps : ndarray of bool, shape (n - 1,), or None
        Where an acceleration jumps between two samples (a Geneva wheel's pin
        entering or leaving a slot): no line is drawn across, so a jump is
        not smeared into a steep slope.
    note : str
        A line under the title: where the mechanism does not assemble.
    gaps : tuple of (float, float)
        Crank-angle ranges (rad) where it does not assemble, shaded.
    imus : dict of str to (ndarray, ndarray, ndarray)
        Per IMU of the scene: orientation (rad) and angular velocity (rad/s),
        shape (n,), linear acceleration in the sensor frame (m/s²), shape
        (n, 2); NaN where a recording has no reading.
    forces : ForceSeries or None
        A scene with forces, solved: efforts, reactions, shaking.
    """

    title: str
    crank_angle: Array
    time: Array | None
    joint_types: Mapping[str, str]
    joints: Mapping[str, tuple[Array, Array | None, Array | None]]
    points: Mapping[str, tuple[Array, Array | None, Array | None]]
    jumps: Array | None = None
    note: str = ''
    gaps: tuple[tuple[float, float], ...] = ()
    imus: Mapping[str, tuple[Array, Array, Array]] = field(default_factory=dict)
    forces: ForceSeries | None = None


def _forces_from_state(scene: Any, state: Any, means: Mapping[str, float] | None = None,
                       note: str = '') -> ForceSeries | None:
    """Return the forces of an array ``state`` of ``scene`` (NaN where it is not valid)."""
    forces = state.forces
    if forces is None:
        return None
    valid = np.asarray(state.valid, dtype=bool)

    def masked(values: Any) -> Array:
        return np.where(valid, np.asarray(values, dtype=np.float64), np.nan)

    reactions = {}
    for name, reaction in forces.reactions.items():
        label = name if name == reaction.at else f'{name} at {reaction.at}'
        if reaction.force is not None:
            reactions[label] = masked(np.abs(reaction.force))
        elif reaction.normal is not None:
            reactions[f'{label} (normal)'] = masked(np.abs(reaction.normal))
    return ForceSeries({d.name: masked(forces.efforts[d.name]) for d in scene.drivers},
                       {d.name: d.joint_type.angular for d in scene.drivers}, reactions,
                       masked(np.abs(forces.shaking_force)), dict(means or {}), note)


def _turn_means(scene: Any, speed: float, accel: float) -> tuple[dict[str, float], str]:
    """Return the turning crank's mean effort over its turn, or why there is none."""
    from ..geometry.turning import turning_moment_from_scene

    try:
        study = turning_moment_from_scene(scene, speed=speed, accel=accel)
    except SceneError as error:
        return {}, f'no mean line: {error}'
    return {study.crank: study.mean}, ''


# -- from the solver -------------------------------------------------------------


def motion_from_scene(scene: Any, *, samples: int = DEFAULT_SAMPLES,
                      speed: float | None = None, accel: float | None = None,
                      x: str = 'angle', duration: float | None = None,
                      speeds: Mapping[str, float] | None = None) -> Motion:
    """Solve ``scene`` over one crank cycle (several drivers: along a path in time).

    A scene with several drivers (or an actuator) is solved along the path
    each driver takes from its start at its default speed and acceleration,
    for the shortest of the drivers' periods (a crank's turn, an actuator's
    travel to the end of its stroke it moves toward; :func:`drivers_period`)
    or ``duration`` (s); against time only. A path that leaves the region where
    the mechanism assembles (or its answers cannot be trusted) is refused with
    where and why.

    Parameters
    ----------
    scene : Scene
        The mechanism.
    samples : int
        Number of crank angles.
    speed, accel : float, optional
        Crank speed (rad/s) and acceleration (rad/s²); the scene's by default.
    x : {'angle', 'time'}
        ``'angle'``: crank angles 0 to 2π. ``'time'``: one period 2π/|speed|
        from the scene's initial angle, turning at the constant ``speed``.

    duration : float, optional
        Several drivers: the time plotted, s (default: :func:`drivers_period`).
    speeds : mapping of str to float, optional
        Several drivers: speeds by driver name (rad/s, m/s) replacing the
        defaults.

    Returns
    -------
    Motion
        Positions where the mechanism cannot be assembled are NaN.
    """
    import mech_kinematics as mk

    if samples < 2:
        msg = f'Expected at least 2 samples, got {samples}'
        raise PlotError(msg)
    if not scene.single_crank:
        return _motion_of_drivers(scene, samples, speed, accel, x, duration, speeds)
    speed = scene.input.speed if speed is None else float(speed)
    accel = scene.input.accel if accel is None else float(accel)
    time = None
    if x == 'time':
        if speed == 0.0:
            msg = 'Expected a non-zero crank speed for a time axis, got 0 rad/s'
            raise PlotError(msg)
        time = np.linspace(0.0, 2.0 * math.pi / abs(speed), samples)
        angle = scene.input.angle + speed * time
    else:
        angle = np.linspace(0.0, 2.0 * math.pi, samples)
    from ..geometry.assembly import assembly_ranges, summary_from_gaps

    with warnings.catch_warnings():
        warnings.simplefilter('ignore', mk.NearSingularWarning)
        state = mk.solve(scene, angle, speed, accel)
    joints = {name: (j.position, j.velocity, j.acceleration) for name, j in state.joints.items()}
    points = {name: (p.position, p.velocity, p.acceleration) for name, p in state.points.items()}
    jumps = np.zeros(len(angle) - 1, dtype=bool)
    for engagement in state.intermittent.values():  # a Geneva wheel: engaged or locked
        engaged = np.asarray(engagement.engaged, dtype=bool)
        jumps |= engaged[1:] != engaged[:-1]
    rpm = rpm_from_rad_per_s(speed)
    title = (f'{scene.name}: solver, one crank cycle at {rpm:.6g} rpm'
             + (f', {accel:.6g} rad/s²' if accel else ''))
    _, gaps = assembly_ranges(scene)
    imus = {name: (r.orientation, r.angular_velocity, r.linear_acceleration)
            for name, r in state.imus.items()}
    forces = None
    if scene.dynamics is not None:
        forces = _forces_from_state(scene, state, *_turn_means(scene, speed, accel))
    return Motion(title, np.asarray(angle, dtype=np.float64), time, scene.joint_types, joints,
                  points, jumps, summary_from_gaps(gaps, scene.units), gaps, imus, forces)


def _first_time(v: float, a: float, distance: float) -> float:
    """Return the first t > 0 with v t + a t^2 / 2 = distance (s), or inf if never."""
    if a == 0.0:
        t = distance / v if v != 0.0 else math.inf
        return t if t > 0.0 else math.inf
    disc = v * v + 2.0 * a * distance
    if disc < 0.0:
        return math.inf
    root = math.sqrt(disc)
    times = [t for t in ((-v - root) / a, (-v + root) / a) if t > 0.0]
    return min(times, default=math.inf)


def drivers_period(scene: Any, speeds: Mapping[str, float] | None = None
                   ) -> tuple[float, str]:
    """Return the time (s) of the quickest driver's period, and which driver and what it does.

    A crank's period is the time it takes to turn once either way from its
    start at its default speed and acceleration; an actuator's, the time it
    takes to reach the end of its stroke it moves toward (one without stroke
    limits has none). The shortest of these keeps every actuator within its
    stroke. ``speeds`` (by driver name, rad/s or m/s) replace the defaults.
    """
    best, what = math.inf, ''
    for driver in scene.drivers:
        v, a = (speeds or {}).get(driver.name, driver.speed), driver.accel
        if driver.joint_type.angular:
            t = min(_first_time(v, a, 2.0 * math.pi), _first_time(v, a, -2.0 * math.pi))
            doing = f'{driver.name} turning once'
        elif driver.stroke is not None:
            low, high = driver.stroke
            t = min(_first_time(v, a, high - driver.start), _first_time(v, a, low - driver.start))
            doing = f'{driver.name} reaching the end of its stroke'
        else:
            t = math.inf
        if t < best:
            best, what = t, doing
    if not math.isfinite(best):
        msg = (f'Expected a driver of {scene.name} that turns or reaches the end of its stroke '
               f'at its speed and acceleration, got none: give --speed NAME=VALUE or '
               f'--duration SECONDS')
        raise PlotError(msg)
    return best, what


def _motion_of_drivers(scene: Any, samples: int, speed: float | None, accel: float | None,
                       x: str, duration: float | None,
                       given: Mapping[str, float] | None) -> Motion:
    """Solve a scene with several drivers (or an actuator) along its drivers' path.

    Each driver moves from its start at its speed (``given`` by name, SI, or
    its default) and its default acceleration.
    """
    import mech_kinematics as mk

    if x != 'time':
        msg = (f'Expected --x time for {scene.name}, which has several drivers or an actuator '
               f'(no one crank angle to plot against), got --x {x}')
        raise PlotError(msg)
    if speed is not None or accel is not None:
        msg = (f'Expected no --speed-rpm or --accel for {scene.name}: each of its drivers '
               f'moves at its own speed (--speed NAME=VALUE) and default acceleration')
        raise PlotError(msg)
    if duration is None:
        duration, what = drivers_period(scene, given)
        span = f'{duration:.6g} s ({what})'
    else:
        span = f'{duration:.6g} s'
    time = np.linspace(0.0, duration, samples)
    drivers = scene.drivers
    unknown = sorted(set(given or {}) - {d.name for d in drivers})
    if unknown:
        msg = (f'Expected --speed NAME=VALUE with NAME one of the drivers '
               f'({", ".join(d.name for d in drivers)}), got {", ".join(unknown)}')
        raise PlotError(msg)
    rate = {d.name: (given or {}).get(d.name, d.speed) for d in drivers}
    positions = [d.start + rate[d.name] * time + 0.5 * d.accel * time * time for d in drivers]
    speeds = [rate[d.name] + d.accel * time for d in drivers]
    accels = [np.full_like(time, d.accel) for d in drivers]
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', mk.NearSingularWarning)
        if len(drivers) == 1:
            state = mk.solve(scene, positions[0], speeds[0], accels[0])
        else:
            state = mk.solve(scene, positions, speeds, accels)
    valid = np.asarray(state.valid, dtype=bool)
    if not valid.all():
        index = int(np.flatnonzero(~valid)[0])
        where = ', '.join(f'{d.name} = {d.position_text(float(p[index]), scene.units)}'
                          for d, p in zip(drivers, positions, strict=True))
        reason = 'its answer cannot be trusted'
        try:
            with warnings.catch_warnings():
                warnings.simplefilter('ignore', mk.NearSingularWarning)
                at = [float(p[index]) for p in positions]
                rates = [float(v[index]) for v in speeds]
                rate2 = [float(a[index]) for a in accels]
                if len(drivers) == 1:
                    mk.solve(scene, at[0], rates[0], rate2[0])
                else:
                    mk.solve(scene, at, rates, rate2)
        except mk.AssemblyError as error:
            reason = error.reason
        msg = (f"Expected the drivers' path of {scene.name} to stay where it assembles, got it "
               f'leaving at t = {time[index]:.6g} s ({where}): {reason}; plot less with '
               f'--duration SECONDS (at most {time[max(index - 1, 0)]:.6g} s)')
        raise PlotError(msg)
    joints = {name: (j.position, j.velocity, j.acceleration) for name, j in state.joints.items()}
    points = {name: (p.position, p.velocity, p.acceleration) for name, p in state.points.items()}
    rates = ', '.join(
        f'{d.name} {rpm_from_rad_per_s(rate[d.name]):.6g} rpm' if d.joint_type.angular
        else f'{d.name} {rate[d.name]:.6g} m/s' for d in drivers)
    title = (f'{scene.name}: solver, every driver from its start at its speed ({rates}) for '
             f'{span}')
    jumps = np.zeros(samples - 1, dtype=bool)
    for engagement in state.intermittent.values():
        engaged = np.asarray(engagement.engaged, dtype=bool)
        jumps |= engaged[1:] != engaged[:-1]
    return Motion(title, np.asarray(positions[0], dtype=np.float64), time, scene.joint_types,
                  joints, points, jumps, 'the path stays where it assembles',
                  forces=_forces_from_state(scene, state))


# -- from a bag ------------------------------------------------------------------


def _decoder(typestore: Any, type_name: str) -> Any:
    """Return a function that decodes CDR bytes of ``type_name`` with ``typestore``.

    Unlike ``Typestore.deserialize_cdr`` it accepts bytes past the end of the
    message, as ``rclpy``, rosbag2 and Foxglove do: a bag from another publisher
    of pre-serialized bytes (rclpy's ``serialize_message`` on Fast DDS leaves a
    few) still plots. The node's own messages are canonical CDR.
    """
    msgdef = typestore.get_msgdef(type_name)
    cls = msgdef.cls

    def decode(raw: bytes | memoryview) -> Any:
        func = msgdef.deserialize_cdr_le if raw[1] & 1 else msgdef.deserialize_cdr_be
        return func(raw[4:], 0, cls, typestore)[0]

    return decode


def _pick(connections: Sequence[Any], type_name: str, namespace: str | None) -> Any | None:
    found = [c for c in connections if c.msgtype == type_name
             and c.topic.rsplit('/', 1)[-1] == _TOPICS[type_name]
             and (namespace is None or c.topic.rsplit('/', 1)[0] == namespace.rstrip('/'))]
    if len(found) > 1:
        topics = ', '.join(c.topic for c in found)
        msg = f'Expected one {_TOPICS[type_name]} topic, got {topics}: pass --namespace'
        raise PlotError(msg)
    return found[0] if found else None


def _imu_connections(connections: Sequence[Any], namespace: str | None) -> dict[str, Any]:
    """Return the node's IMU topics, ``<namespace>/imu/NAME``, by sensor name."""
    return _connections_in(connections, namespace, topics.IMU, topics.IMU_TYPE,
                           topics.imu_topic)


def _connections_in(connections: Sequence[Any], namespace: str | None, space: str,
                    type_name: str, topic_of: Any) -> dict[str, Any]:
    """Return the topics ``<namespace>/SPACE/NAME`` of ``type_name`` by NAME (one each)."""
    found: dict[str, Any] = {}
    for c in connections:
        parts = c.topic.rsplit('/', 2)
        if c.msgtype != type_name or len(parts) != 3 or parts[1] != space or (
                namespace is not None and parts[0] != namespace.rstrip('/')):
            continue
        if parts[2] in found:
            msg = (f'Expected one {topic_of(parts[2])} topic, got {found[parts[2]].topic}, '
                   f'{c.topic}: pass --namespace')
            raise PlotError(msg)
        found[parts[2]] = c
    return found


def _at_ticks(reader: Any, connection: Any, ticks: Sequence[int]) -> Iterator[tuple[int, Any]]:
    """Yield (index in ``ticks``, message) of each of ``connection``'s messages stamped there."""
    at = {stamp: i for i, stamp in enumerate(ticks)}
    decode = _decoder(reader.typestore, connection.msgtype)
    for _, _, raw in reader.messages(connections=[connection]):
        i = at.get(stamp_from_cdr(raw))
        if i is not None:
            yield i, decode(raw)


def _imu_arrays(reader: Any, connections: Mapping[str, Any],
                ticks: Sequence[int]) -> dict[str, tuple[Array, Array, Array]]:
    """Return each IMU's readings at ``ticks`` (header stamps, ns); NaN where it has none."""
    out = {}
    for name, connection in connections.items():
        values = np.full((len(ticks), 4), np.nan)
        for i, m in _at_ticks(reader, connection, ticks):
            q, a = m.orientation, m.linear_acceleration
            values[i] = (2.0 * math.atan2(q.z, q.w), m.angular_velocity.z, a.x, a.y)
        orientation = np.remainder(values[:, 0] + math.pi, 2.0 * math.pi) - math.pi
        out[name] = (orientation, values[:, 1], values[:, 2:4])
    return out


def _wrench_connections(connections: Sequence[Any], namespace: str | None
                        ) -> tuple[dict[str, Any], Any | None]:
    """Return the node's ``reactions/JOINT`` topics by joint, and its ``shaking`` topic."""
    reactions = _connections_in(connections, namespace, topics.REACTIONS, topics.WRENCH_TYPE,
                                topics.reaction_topic)

    def is_shaking(connection: Any) -> bool:
        head, _, name = connection.topic.rpartition('/')
        return connection.msgtype == topics.WRENCH_TYPE and name == topics.SHAKING and (
            namespace is None or head == namespace.rstrip('/'))

    shaking = [c for c in connections if is_shaking(c)]
    if len(shaking) > 1:
        msg = (f'Expected one {topics.SHAKING} topic, got {shaking[0].topic}, '
               f'{shaking[1].topic}: pass --namespace')
        raise PlotError(msg)
    return reactions, shaking[0] if shaking else None


def _wrench_magnitudes(reader: Any, connection: Any, ticks: Sequence[int]) -> Array:
    """Return the length of each message's force at ``ticks`` (header stamps), N; NaN if none."""
    out = np.full(len(ticks), np.nan)
    for i, m in _at_ticks(reader, connection, ticks):
        f = m.wrench.force
        out[i] = math.sqrt(f.x * f.x + f.y * f.y + f.z * f.z)
    return out


def _bag_efforts(reader: Any, connection: Any | None, ticks: Sequence[int]
                 ) -> dict[str, Array]:
    """Return every joint's ``joint_states`` effort at ``ticks``; NaN where a message has none.

    Only the joints with an effort somewhere: a message without efforts (a
    scene without forces, an instant whose forces are left out) has an empty
    ``effort``.
    """
    if connection is None:
        return {}
    columns: dict[str, Array] = {}
    for i, m in _at_ticks(reader, connection, ticks):
        if len(m.effort) != len(m.name):
            continue
        for name, value in zip(m.name, m.effort, strict=True):
            columns.setdefault(name, np.full(len(ticks), np.nan))[i] = value
    return columns


def _bag_forces(reader: Any, joint_states: Any | None, namespace: str | None,
                ticks: Sequence[int], scene: Any, path: Path) -> ForceSeries | None:
    """Return the recorded forces at ``ticks`` (efforts, reactions, shaking), or None if none.

    The efforts are those of the scene's drivers and of every joint whose
    effort is not 0 (a passive joint's is 0; a URDF's actuated joints carry
    the URDF's names), torques unless the scene says the joint is prismatic;
    a reaction is the length of its force (a prismatic joint's normal
    force). A part the bag does not
    hold is said in a warning and its panel says "not in the recording".
    """
    reactions, shaking = _wrench_connections(reader.connections, namespace)
    drivers = {d.name for d in scene.drivers} if scene is not None else set()
    efforts = {n: v for n, v in _bag_efforts(reader, joint_states, ticks).items()
               if n in drivers or np.nanmax(np.abs(v), initial=0.0) > 0.0}
    types = scene.joint_types if scene is not None else {}
    angular = {n: types[n].angular if n in types else True for n in efforts}
    if not efforts and not reactions and shaking is None:
        return None
    missing = [what for what, absent in (('efforts', not efforts),
                                         (f'{topics.REACTIONS}/*', not reactions),
                                         (topics.SHAKING, shaking is None)) if absent]
    if missing:
        warnings.warn(f'{path}: no {", ".join(missing)} in the recording: their panels say '
                      f'so', stacklevel=3)
    return ForceSeries(efforts, angular,
                       {n: _wrench_magnitudes(reader, c, ticks) for n, c in reactions.items()},
                       None if shaking is None else _wrench_magnitudes(reader, shaking, ticks))


def _stored_scene(reader: Any, connection: Any, path: Path) -> Any:
    """Return the scene of the bag's ``scene`` topic (its last message), or None if unreadable."""
    import mech_kinematics as mk

    from ..scene import read_scene_yaml

    decode = _decoder(reader.typestore, _SCENE)
    text = None
    for _, _, raw in reader.messages(connections=[connection]):
        text = decode(raw).data
    if text is None:
        return None
    try:
        return mk.parse_scene(read_scene_yaml(text))
    except mk.SceneError as error:
        warnings.warn(f'{path}: the scene stored on {connection.topic} cannot be read '
                      f'({error}); ignoring it', stacklevel=3)
        return None


def _check_bag_directory(path: Path) -> None:
    """Refuse what is not a bag directory whose files can be read without blocking.

    A FIFO or device named ``metadata.yaml`` or ``*.mcap`` would block or
    never end; a bag without ``metadata.yaml`` (its recorder was killed)
    needs ``reindex``.
    """
    if not path.exists():
        msg = f'Expected a bag directory, got "{path}", which does not exist'
        raise PlotError(msg)
    if not path.is_dir():
        msg = f'Expected a bag directory, got "{path}", which is not a directory'
        raise PlotError(msg)
    try:
        entries = [p for p in path.iterdir()
                   if p.name == 'metadata.yaml' or p.suffix in ('.mcap', '.db3')]
        for entry in entries:
            if not stat.S_ISREG(entry.stat().st_mode):
                msg = (f'Expected "{entry}" to be a regular file, got a '
                       f'{_file_kind(entry.stat().st_mode)}; replace it with the file itself')
                raise PlotError(msg)
    except OSError as error:
        msg = f'Expected a readable bag directory, got "{path}": {error.strerror or error}'
        raise PlotError(msg) from None
    if not any(p.name == 'metadata.yaml' for p in entries):
        msg = (f'Expected a bag directory with a metadata.yaml, got "{path}" without one (was '
               f'its recorder killed?); run `{PROG} reindex {path}` to rebuild it')
        raise PlotError(msg)


def _file_kind(mode: int) -> str:
    kinds = ((stat.S_ISFIFO, 'FIFO'), (stat.S_ISDIR, 'directory'), (stat.S_ISSOCK, 'socket'),
             (stat.S_ISCHR, 'character device'), (stat.S_ISBLK, 'block device'))
    return next((name for test, name in kinds if test(mode)), 'special file')


def motion_from_bag(path: str | os.PathLike[str], *, scene: Any = None,
                    namespace: str | None = None,
                    max_samples: int | None = DEFAULT_MAX_SAMPLES) -> Motion:
    """Read the node's topics from the bag at ``path``.

    Joint positions, velocities and accelerations come from
    ``joint_accelerations`` (``joint_states`` if that is missing: no
    accelerations then), points from ``point_accelerations``; time is the
    messages' ``header.stamp`` from the first one. Only the ticks found on
    both topics are kept (matched by stamp).

    Parameters
    ----------
    path : path-like
        A rosbag2 directory (mcap or sqlite3).
    scene : Scene, optional
        Tells revolute from prismatic joints and names the crank. By default
        the scene stored in the bag (the node's ``scene`` topic), else the
        scene named in the bag's ``diagnostics`` (``hardware_id``) if it is a
        packaged scene with the same joints; otherwise every joint is taken
        as revolute and the first joint as the crank, with a warning.
    namespace : str, optional
        Namespace of the node's topics, if the bag holds more than one node's.
    max_samples : int or None
        Keep every k-th tick so that at most this many are decoded (a figure
        shows no more); None keeps every tick.

    Raises
    ------
    PlotError
        If the bag cannot be read or holds none of the node's topics.
    """
    from rosbags.highlevel import AnyReader, AnyReaderError
    from rosbags.typesys import get_typestore, Stores

    import mech_kinematics as mk

    from rosbags.rosbag2 import ReaderError

    path = Path(path)
    _check_bag_directory(path)
    try:
        with AnyReader([path], default_typestore=get_typestore(Stores.LATEST)) as reader:
            picked = {t: _pick(reader.connections, t, namespace) for t in _TOPICS}
            joints_conn = picked[_JOINT_TRAJECTORY] or picked[_JOINT_STATE]
            points_conn = picked[_POINT_TRAJECTORY]
            if joints_conn is None and points_conn is None:
                topics = ', '.join(sorted({c.topic for c in reader.connections})) or 'none'
                msg = (f"Expected the node's joint_accelerations, joint_states or "
                       f'point_accelerations in {path}, got topics: {topics}')
                raise PlotError(msg)
            wanted = [c for c in (joints_conn, points_conn) if c is not None]
            # Pass 1: the header stamps only (no decoding); keep the ticks every topic has,
            # thinned to at most max_samples. Pass 2: decode just those.
            stamps: dict[int, set[int]] = {c.id: set() for c in wanted}
            for connection, _, raw in reader.messages(connections=wanted):
                stamps[connection.id].add(stamp_from_cdr(raw))
            common = sorted(set.intersection(*stamps.values()))
            step = max(1, math.ceil(len(common) / max_samples)) if max_samples else 1
            chosen = set(common[::step])
            decoders = {c.id: _decoder(reader.typestore, c.msgtype) for c in wanted}
            rows: dict[int, dict[int, Any]] = {c.id: {} for c in wanted}
            for connection, _, raw in reader.messages(connections=wanted):
                stamp = stamp_from_cdr(raw)
                if stamp in chosen and stamp not in rows[connection.id]:
                    rows[connection.id][stamp] = decoders[connection.id](raw)
            imus = _imu_arrays(reader, _imu_connections(reader.connections, namespace),
                               sorted(chosen))
            scene_name = ''
            stored = picked[_SCENE]
            if stored is not None and scene is None:
                scene = _stored_scene(reader, stored, path)
            forces = _bag_forces(reader, picked[_JOINT_STATE], namespace, sorted(chosen), scene,
                                 path)
            diagnostics = picked[_DIAGNOSTICS]
            if diagnostics is not None and scene is None:
                decode = _decoder(reader.typestore, _DIAGNOSTICS)
                for _, _, raw in reader.messages(connections=[diagnostics]):
                    statuses = decode(raw).status
                    scene_name = next((s.hardware_id for s in statuses if s.hardware_id), '')
                    break
    except (AnyReaderError, ReaderError, OSError, KeyError, ValueError) as error:
        if isinstance(error, PlotError):
            raise
        msg = (f'Expected a readable rosbag2 bag at "{path}", got {type(error).__name__}: '
               f'{error}; run `{PROG} reindex {path}` to keep every intact message')
        raise PlotError(msg) from None

    ticks = sorted(chosen)
    joints_msgs = [rows[joints_conn.id][t] for t in ticks] if joints_conn is not None else []
    points_msgs = [rows[points_conn.id][t] for t in ticks] if points_conn is not None else []
    names, joint_arrays = _joint_arrays(joints_msgs, joints_conn)
    point_names, point_arrays = _point_arrays(points_msgs)
    missing = _missing(joint_arrays, point_arrays, joints_conn)
    if missing:
        warnings.warn(f'{path}: no {missing} in the recording (empty in every message, as a '
                      f'node driven from a topic publishes them): their panels say so',
                      stacklevel=2)
    if scene is None and scene_name:
        try:
            candidate = mk.load_scene(scene_name)
        except mk.SceneError:
            candidate = None
        if candidate is not None and set(candidate.output_joints) == set(names):
            scene = candidate
    if scene is not None:
        types = {n: scene.joint_types.get(n, REVOLUTE) for n in names}
        drivers = scene.drivers
        # Several drivers (or an actuator): no one crank angle (NaN; --x angle is refused).
        crank = drivers[0].name if len(drivers) == 1 and drivers[0].joint_type.angular \
            else ''
    else:
        if any(names):
            warnings.warn(f'{path}: no scene given or named in the bag; plotting every joint '
                          f'as revolute and "{names[0]}" as the crank', stacklevel=2)
        types = dict.fromkeys(names, REVOLUTE)
        crank = names[0] if names else ''
    joints = {n: joint_arrays[i] for i, n in enumerate(names)}
    points = {n: point_arrays[i] for i, n in enumerate(point_names)}

    stamps_ns = np.array(ticks, dtype=np.int64)
    crank_angle = joints[crank][0] if crank in joints else np.full(len(ticks), np.nan)
    time = (stamps_ns - stamps_ns[0]) / NS_PER_S if len(ticks) else np.zeros(0)
    label = scene.name if scene is not None else (scene_name or 'unknown scene')
    title = f'{label}: recording {path.name}, {time[-1] if len(time) else 0:.3g} s'
    return Motion(title, crank_angle, time, types, joints, points, imus=imus, forces=forces)


def _rows(rows: Sequence[Sequence[float]], width: int) -> Array | None:
    """Return ``rows`` as an array of shape (n, width); None if no row has ``width`` values.

    A row of another length (a quantity a message leaves out: an empty array,
    as a node driven from a topic publishes its accelerations) is NaN.
    """
    if all(len(row) == width for row in rows):
        return np.array(rows, dtype=np.float64).reshape(len(rows), width)
    if not any(len(row) == width for row in rows):
        return None
    out = np.full((len(rows), width), np.nan)
    for i, row in enumerate(rows):
        if len(row) == width:
            out[i] = row
    return out


def _joint_arrays(msgs: list[Any], connection: Any) -> tuple[list[str], list[Any]]:
    """Return the joints' names and (position, velocity, acceleration) arrays, shape (n,).

    Velocity or acceleration is None where no message has it (``joint_states``
    has no accelerations).
    """
    if not msgs:
        return [], []
    if connection.msgtype == _JOINT_TRAJECTORY:
        names = list(msgs[0].joint_names)
        points = [m.points[0] for m in msgs]
        pos = _rows([p.positions for p in points], len(names))
        vel = _rows([p.velocities for p in points], len(names))
        acc = _rows([p.accelerations for p in points], len(names))
    else:
        names = list(msgs[0].name)
        pos = _rows([m.position for m in msgs], len(names))
        vel = _rows([m.velocity for m in msgs], len(names))
        acc = None
    if pos is None:
        msg = (f'Expected the {len(names)} positions of the joints in each message, got '
               f'messages of other lengths')
        raise PlotError(msg)
    arrays = [(pos[:, i], None if vel is None else vel[:, i], None if acc is None else acc[:, i])
              for i in range(len(names))]
    return names, arrays


def _point_arrays(msgs: list[Any]) -> tuple[list[str], list[Any]]:
    """Return the points' names and (position, velocity, acceleration) arrays, shape (n, 2).

    Velocity or acceleration is None where no message has it.
    """
    if not msgs:
        return [], []
    names = list(msgs[0].joint_names)
    width = 2 * len(names)
    points = [m.points[0] for m in msgs]
    pos = _rows([[x for t in p.transforms for x in (t.translation.x, t.translation.y)]
                 for p in points], width)
    vel, acc = (_rows([[x for v in vectors for x in (v.linear.x, v.linear.y)]
                       for vectors in column], width)
                for column in ([p.velocities for p in points], [p.accelerations for p in points]))
    if pos is None:
        msg = (f'Expected the positions of the {len(names)} points in each message, got '
               f'messages of other lengths')
        raise PlotError(msg)
    arrays = [tuple(None if a is None else a[:, 2 * i:2 * i + 2] for a in (pos, vel, acc))
              for i in range(len(names))]
    return names, arrays


def _missing(joints: Sequence[Any], points: Sequence[Any], connection: Any) -> str:
    """Say which quantities the recording leaves out ('' if none): 'velocities or accelerations'.

    A bag of ``joint_states`` alone has no accelerations by nature: not said.
    """
    series = [*joints, *points]
    if not series:
        return ''
    gone = [word for k, word in ((1, 'velocities'), (2, 'accelerations'))
            if all(values[k] is None for values in series)]
    if gone == ['accelerations'] and not points and connection is not None \
            and connection.msgtype == _JOINT_STATE:
        return ''
    return ' or '.join(gone)


# -- the figure ------------------------------------------------------------------


#: A step in time longer than this many typical steps is a gap in the data: no line across it.
GAP_FACTOR = 3.0


def _gaps(time: Array | None, n: int) -> Any:
    """Return a mask, shape (n - 1,): where the time step is a gap (ticks not published)."""
    if time is None or n < 3:
        return np.zeros(max(n - 1, 0), dtype=bool)
    steps = np.diff(time)
    typical = float(np.median(steps))
    return steps > GAP_FACTOR * typical if typical > 0 else np.zeros(len(steps), dtype=bool)


def _check_drawable(title: str, label: str, values: Array) -> None:
    """Refuse, in one line, a series with a value beyond :data:`MAX_DRAWN` in magnitude."""
    finite = np.abs(values[np.isfinite(values)])
    if finite.size and float(finite.max()) > MAX_DRAWN:
        msg = (f'Expected values a plot can draw (at most {MAX_DRAWN:g} in magnitude), got '
               f'{float(finite.max()):.4g} in {title!r}, {label} (smaller forces or speeds '
               f'plot)')
        raise PlotError(msg)


def _broken(x: Array, y: Array, gaps: Any, *, x_wraps: bool,
            y_wraps: bool) -> tuple[Array, Array]:
    """Insert NaN at ``gaps`` and where ``x`` or ``y`` jumps by more than π (an angle wrap).

    So that no line crosses a panel where there are no data.
    """
    jumps = np.array(gaps, dtype=bool, copy=True)
    if x_wraps:
        jumps |= np.abs(np.diff(x)) > math.pi
    if y_wraps:
        jumps |= np.abs(np.diff(y)) > math.pi
    if not jumps.any():
        return x, y
    at = np.flatnonzero(jumps) + 1
    return np.insert(x, at, np.nan), np.insert(y, at, np.nan)


def _angle_ticks(ax: Any) -> None:
    ticks = np.arange(5) * (math.pi / 2)
    ax.set_xticks(ticks, ['0', 'π/2', 'π', '3π/2', '2π'])
    ax.set_xlim(0.0, 2.0 * math.pi)


def figure_from_motion(motion: Motion, *, x: str = 'time') -> Any:
    """Return a matplotlib Figure of ``motion`` against ``x`` (``'time'`` or ``'angle'``).

    Columns: revolute joints (angle, angular velocity, angular acceleration),
    points (path, speed, acceleration magnitude) and, if the mechanism has
    any, prismatic joints (position, velocity, acceleration) and IMUs
    (orientation, angular velocity, linear acceleration's x and y). Every
    axis is labelled with its unit.
    """
    from matplotlib.figure import Figure

    if x not in AXES:
        msg = f'Expected x to be one of {", ".join(AXES)}, got {x!r}'
        raise PlotError(msg)
    if x == 'time' and motion.time is None:
        msg = f'Expected a time axis in {motion.title!r}, got none: use x="angle"'
        raise PlotError(msg)
    if x == 'time':
        xs = np.asarray(motion.time, dtype=np.float64)
    else:
        # Into [0, 2π]; an angle already there stays (a cycle's end is 2π, not 0).
        angle = np.asarray(motion.crank_angle, dtype=np.float64)
        inside = (angle >= 0.0) & (angle <= 2.0 * math.pi)
        xs = np.where(inside, angle, np.mod(angle, 2.0 * math.pi))
    revolute = [n for n, t in motion.joint_types.items() if t.angular and n in motion.joints]
    prismatic = [n for n, t in motion.joint_types.items()
                 if not t.angular and n in motion.joints]
    moving = [n for n, (p, v, a) in motion.points.items() if _moves(p, v, a)]
    columns = [('joint_position', 'joint_velocity', 'joint_acceleration'),
               ('point_path', 'point_speed', 'point_acceleration')]
    if prismatic:
        columns.append(('slider_position', 'slider_velocity', 'slider_acceleration'))
    if motion.imus:
        columns.append(('imu_orientation', 'imu_angular_velocity', 'imu_acceleration'))
    if motion.forces is not None:
        columns.append(('effort', 'reaction', 'shaking'))
    gaps = _gaps(motion.time, len(motion.crank_angle))
    if motion.jumps is not None:
        gaps = gaps | motion.jumps  # an acceleration's jump: no line across it
    fig = Figure(figsize=(6.0 * len(columns), 9.0), layout='constrained')
    grid = fig.subplots(3, len(columns), squeeze=False)
    fig.suptitle(motion.title + (f'\n{motion.note}' if motion.note else ''))

    def series(kind: str) -> list[tuple[str, Array | None, bool]]:
        """(label, values, values wrap at ±π) per line of a panel against ``x``."""
        if kind.startswith('imu'):
            return _imu_series(motion, kind)
        if kind in ('effort', 'reaction', 'shaking'):
            return _force_series(motion.forces, kind)
        if kind.startswith('joint') or kind.startswith('slider'):
            names = revolute if kind.startswith('joint') else prismatic
            k = ('position', 'velocity', 'acceleration').index(kind.split('_')[1])
            return [(n, motion.joints[n][k], k == 0 and kind.startswith('joint'))
                    for n in names]
        k = 1 if kind == 'point_speed' else 2
        out: list[tuple[str, Array | None, bool]] = []
        for n in moving:
            vector = motion.points[n][k]
            out.append((n, None if vector is None else np.hypot(vector[:, 0], vector[:, 1]),
                        False))
        return out

    for col, kinds in enumerate(columns):
        for row, kind in enumerate(kinds):
            ax = grid[row, col]
            ax.set_title(TITLES[kind])
            ax.set_ylabel(YLABELS[kind])
            if kind == 'effort' and motion.forces is not None:
                ax.set_ylabel(EFFORT_LABELS.get(tuple(sorted(set(motion.forces.angular.values()))),
                                                YLABELS['effort']))
            ax.grid(True, alpha=0.3)
            if kind == 'point_path':
                _draw_paths(ax, motion, gaps)
                continue
            ax.set_xlabel(XLABELS[x])
            if x == 'angle':
                _angle_ticks(ax)
                for start, end in motion.gaps:  # where it does not assemble, shaded
                    for shift in (-2.0 * math.pi, 0.0, 2.0 * math.pi):
                        ax.axvspan(start + shift, end + shift, color='0.9', zorder=0)
                _angle_ticks(ax)  # the spans must not widen the axis
            drawn = absent = 0
            for label, values, wraps in series(kind):
                if values is None:
                    absent += 1
                    continue
                _check_drawable(TITLES[kind], label, values)
                px, py = _broken(xs, values, gaps, x_wraps=x == 'angle', y_wraps=wraps)
                drawn_line = ax.plot(px, py, label=label, linewidth=1.0)[0]
                drawn += 1
                if kind == 'effort':
                    _mean_line(ax, motion.forces, label, drawn_line.get_color())
            if kind == 'effort' and motion.forces is not None and motion.forces.note:
                ax.text(0.02, 0.02, textwrap.fill(motion.forces.note, 60), transform=ax.transAxes,
                        fontsize='x-small', color='0.4', va='bottom')
            if drawn:
                _legend(ax)
            else:
                ax.text(0.5, 0.5, 'not in the recording' if absent else 'no data',
                        transform=ax.transAxes, ha='center', va='center', color='0.5')
    return fig


def _moves(p: Array, v: Array | None, a: Array | None) -> bool:
    """Return whether a point moves: a velocity or acceleration not 0 (without both, its path)."""
    if v is None and a is None:
        known = p[np.isfinite(p).all(axis=1)]
        return bool(len(known)) and bool((known.max(axis=0) - known.min(axis=0)).max() > 0.0)
    return any(x is not None and np.nanmax(np.abs(x), initial=0.0) > 0.0 for x in (v, a))


def _force_series(forces: ForceSeries | None, kind: str) -> list[tuple[str, Array | None, bool]]:
    """(label, values, wraps) of a forces panel: efforts, reactions or the shaking force."""
    if forces is None:
        return []
    if kind == 'effort':
        return [(name, values, False) for name, values in forces.efforts.items()] or [
            ('efforts', None, False)]       # a recording without them: "not in the recording"
    if kind == 'reaction':
        return [(name, values, False) for name, values in forces.reactions.items()] or [
            ('reactions', None, False)]
    return [('shaking', forces.shaking, False)]


def _mean_line(ax: Any, forces: ForceSeries | None, name: str, colour: str) -> None:
    """Draw a driver's mean effort over its turn as a dashed line, if it has one."""
    if forces is None or name not in forces.means:
        return
    from ..geometry.turning import effort_unit

    mean = forces.means[name]
    ax.axhline(mean, color=colour, linestyle='--', linewidth=0.9,
               label=f'{name} mean {mean:.4g} {effort_unit(forces.angular[name])}')


def _imu_series(motion: Motion, kind: str) -> list[tuple[str, Array | None, bool]]:
    """(label, values, wraps) of an IMU panel: one line per sensor, x and y for accelerations."""
    if kind == 'imu_acceleration':
        return [(f'{name} {axis}', readings[2][:, k], False)
                for name, readings in motion.imus.items() for k, axis in enumerate('xy')]
    k = 0 if kind == 'imu_orientation' else 1
    return [(name, readings[k], k == 0) for name, readings in motion.imus.items()]


def _draw_paths(ax: Any, motion: Motion, gaps: Any) -> None:
    ax.set_xlabel(XLABELS['path'])
    ax.set_aspect('equal', adjustable='datalim')
    for name, (p, v, a) in motion.points.items():
        fixed = not _moves(p, v, a)
        finite = np.isfinite(p).all(axis=1)
        if not finite.any():
            continue
        if fixed:
            x0, y0 = p[finite][0]
            ax.plot([x0], [y0], marker='^', color='0.3', linestyle='none')
            ax.annotate(name, (x0, y0), textcoords='offset points', xytext=(4, -12),
                        color='0.3')
        else:
            px, py = _broken(p[:, 0], p[:, 1], gaps, x_wraps=False, y_wraps=False)
            ax.plot(px, py, label=name, linewidth=1.0)
    if ax.get_legend_handles_labels()[0]:
        _legend(ax)


def _legend(ax: Any) -> None:
    """Put the legend beside the panel, where it hides no data."""
    ax.legend(fontsize='small', loc='upper left', bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
              frameon=False)


def save_figure(fig: Any, output: str | os.PathLike[str]) -> Path:
    """Write ``fig`` to ``output`` (format from the suffix, PNG at 120 dpi); return the path."""
    output = Path(output)
    fig.savefig(output, dpi=120)
    return output


def plot_bag(path: str | os.PathLike[str], output: str | os.PathLike[str], *,
             x: str = 'time', scene: Any = None, namespace: str | None = None,
             max_samples: int | None = DEFAULT_MAX_SAMPLES) -> Any:
    """Plot the recording at ``path`` to ``output``; return the Figure.

    A recording of a scene with several drivers (or an actuator) has no one
    crank angle: ``x='angle'`` is refused.
    """
    motion = motion_from_bag(path, scene=scene, namespace=namespace, max_samples=max_samples)
    if x == 'angle' and motion.joints and not np.isfinite(motion.crank_angle).any():
        msg = (f'Expected a recording of a scene driven by one crank to plot against crank '
               f'angle, got {motion.title.split(":")[0]}, with several drivers or an '
               f'actuator: use --x time')
        raise PlotError(msg)
    fig = figure_from_motion(motion, x=x)
    save_figure(fig, output)
    return fig


def plot_scene(scene: Any, output: str | os.PathLike[str], *, x: str | None = None,
               samples: int = DEFAULT_SAMPLES, speed: float | None = None,
               accel: float | None = None, duration: float | None = None) -> Any:
    """Plot one crank cycle of ``scene`` to ``output``; return the Figure.

    ``x`` defaults to ``'angle'``, or ``'time'`` for a scene with several
    drivers (or an actuator), which :func:`motion_from_scene` plots along its
    drivers' path.
    """
    if x is None:
        several = not scene.single_crank
        x = 'time' if several else 'angle'
    motion = motion_from_scene(scene, samples=samples, speed=speed, accel=accel, x=x,
                               duration=duration)
    fig = figure_from_motion(motion, x=x)
    save_figure(fig, output)
    return fig


# -- command line ----------------------------------------------------------------


PLOT_HELP = """\
Plot joint angles, angular velocities and accelerations, slider motion, point
paths and the magnitudes of point velocities and accelerations, in SI units,
against time or crank angle, to an image file (PNG; no display needed).

  plot BAG -o FILE.png             a bag recorded from the node (mcap or sqlite3)
  plot --scene SCENE -o FILE.png   the solver over one crank cycle; prints (and
                                   shades) the crank angles where the scene
                                   does not assemble, in one line
  plot BAG --scene SCENE ...       a bag, with the scene telling sliders from
                                   revolute joints (by default the scene named
                                   in the bag's diagnostics is used)
  plot --scene SCENE --workspace POINT -o FILE.png
                                   where a point of a two-driver scene (a URDF's
                                   link frame) reaches, with its singular curves,
                                   over the mechanism (check --workspace --png)

A scene with several drivers (or an actuator) is plotted against time along
the path its drivers take from their start positions at their default speeds,
for the quickest driver's period (a crank's turn, an actuator's travel to the
end of its stroke it moves toward; the title says which) or --duration
SECONDS; a path leaving the region where it assembles is refused, saying
where and why.
"""


def _handle(args: argparse.Namespace) -> int:
    """Handle ``plot``; return the exit status."""
    import mech_kinematics as mk

    if args.bag is None and args.scene is None:
        print('error: Expected a BAG or --scene SCENE, got neither', file=sys.stderr)
        return 2
    if args.workspace is not None and args.bag is not None:
        print(f'error: Expected --workspace with --scene SCENE alone (a map, not a recording), '
              f'got a BAG ({args.bag})', file=sys.stderr)
        return 2
    output = Path(args.output)
    if not output.parent.is_dir():
        print(f'error: Expected an existing folder for {output}, got none', file=sys.stderr)
        return 2
    problem = _output_problem(output)
    if problem:
        print(f'error: {problem}', file=sys.stderr)
        return 2
    if not 2 <= args.samples <= MAX_SAMPLES:
        print(f'error: Expected --samples from 2 to {MAX_SAMPLES}, got {args.samples}; a '
              f'figure shows no more', file=sys.stderr)
        return 2
    speed = None if args.speed_rpm is None else rad_per_s_from_rpm(args.speed_rpm)
    if args.workspace is not None:
        return _plot_workspace(args, output)
    try:
        scene = None if args.scene is None else load_scene_argument(args)
        if args.bag is not None:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter('always', UserWarning)
                plot_bag(args.bag, output, x=args.x or 'time', scene=scene,
                         namespace=args.namespace, max_samples=args.max_samples or None)
            for warning in caught:      # one line each, not Python's warning format
                print(f'warning: {warning.message}', file=sys.stderr)
        else:
            several = not scene.single_crank
            x = args.x or ('time' if several else 'angle')
            if (args.duration is not None or args.speed) and not several:
                msg = (f'Expected --duration and --speed NAME=VALUE only for a scene with '
                       f'several drivers or an actuator, got {scene.name}, driven by one crank: '
                       f'use --speed-rpm')
                raise PlotError(msg)
            try:
                rates = values_by_driver(scene, '--speed', args.speed)
            except ValueError as error:
                raise PlotError(str(error)) from None
            given = {d.name: angular_rate_given(rates[d.name], args) if d.joint_type.angular
                     else rates[d.name] for d in scene.drivers if d.name in rates}
            motion = motion_from_scene(scene, samples=args.samples, speed=speed,
                                       accel=args.accel, x=x, duration=args.duration,
                                       speeds=given)
            save_figure(figure_from_motion(motion, x=x), output)
            print(f'{scene.name}: {motion.note}')  # where it does not assemble, if anywhere
    except (PlotError, mk.SceneError) as error:
        print(f'error: {error}', file=sys.stderr)
        return 2
    print(f'wrote {output}')
    return 0


def _output_problem(output: Path) -> str:
    """Say why ``output`` cannot be the image written as named, or return ''."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    formats = sorted(FigureCanvasAgg.get_supported_filetypes())
    suffix = output.suffix.lower().lstrip('.')
    if suffix not in formats:
        got = f'"{output}", whose suffix is not one' if suffix else f'"{output}" without one'
        return (f'Expected -o FILE with an image suffix (.png, .svg, .pdf, or one of '
                f'{", ".join(formats)}), got {got}; e.g. -o {output.with_suffix(".png")}')
    if output.exists() and not output.is_file():
        return f'Expected -o to name a regular file, got "{output}", which exists and is not one'
    return ''


def _plot_workspace(args: argparse.Namespace, output: Path) -> int:
    """Draw ``--workspace`` over the mechanism, as ``check --workspace --png`` draws it."""
    from .check import draw_workspace, workspace_of

    robot = load_robot_argument(args) if is_urdf(args.scene) else None
    scene = load_scene_argument(args) if robot is None else robot.scene
    draw_workspace(workspace_of(scene, args.workspace, args.grid, robot), scene, output)
    print(f'wrote {output}')
    return 0


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('bag', nargs='?', metavar='BAG', help='rosbag2 directory to plot')
    parser.add_argument('-o', '--output', required=True, metavar='FILE.png',
                        help='image to write (format from the suffix: png, svg, pdf)')
    parser.add_argument('--scene', metavar='SCENE',
                        help='scene file or packaged scene name (or a URDF, .urdf: its loops as '
                             'a scene): plot the solver over one crank cycle, or (with BAG) name '
                             'the joint types')
    add_robot_arguments(parser)
    add_units_argument(parser, ('--speed', '--reference'))
    parser.add_argument('--x', choices=AXES,
                        help='horizontal axis (default: time for a bag, angle for a scene)')
    parser.add_argument('--namespace', metavar='NS',
                        help="namespace of the node's topics, if the bag has several")
    parser.add_argument('--max-samples', type=int, default=DEFAULT_MAX_SAMPLES, metavar='N',
                        help='BAG: decode at most N ticks, evenly spread; 0 for all '
                             '(default: %(default)s)')
    parser.add_argument('--samples', type=int, default=DEFAULT_SAMPLES, metavar='N',
                        help='crank angles per cycle for --scene (default: %(default)s)')
    parser.add_argument('--speed-rpm', type=finite_float, metavar='N',
                        help="crank speed for --scene, rpm (default: the scene's)")
    parser.add_argument('--accel', type=finite_float, metavar='A',
                        help="crank acceleration for --scene, rad/s^2 (default: the scene's)")
    parser.add_argument('--speed', type=named_value, action='append', metavar='NAME=VALUE',
                        help="--scene with several drivers: a driver's speed, as solve takes "
                             'it (rpm for a crank, rad/s with --units si; m/s for an actuator; '
                             "default: the scene's)")
    parser.add_argument('--duration', type=positive_float, metavar='SECONDS',
                        help='--scene with several drivers: the time plotted (default: the '
                             "quickest driver's turn or stroke)")
    parser.add_argument('--workspace', metavar='NAME',
                        help='--scene with two drivers: draw where point NAME (a URDF: a link '
                             "frame's origin) reaches over their grid, with both singular "
                             "curves, over the mechanism (check --workspace --png's picture)")
    parser.add_argument('--grid', type=grid_size, default=GRID, metavar='N',
                        help=f'--workspace: grid points per driver (default {GRID})')


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register the ``plot`` subcommand on ``subparsers``; return its parser."""
    parser: argparse.ArgumentParser = subparsers.add_parser(
        'plot', help='plot a bag or one crank cycle of a scene to a PNG',
        description=PLOT_HELP, formatter_class=argparse.RawDescriptionHelpFormatter)
    _add_arguments(parser)
    parser.set_defaults(handler=_handle)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``plot``; return the exit status."""
    return run_tool(add_parser, argv)


if __name__ == '__main__':
    sys.exit(main())
