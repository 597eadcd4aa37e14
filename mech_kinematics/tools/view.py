# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``python -m mech_kinematics view``: the running node's mechanism, live in a web browser.

Attaches to a running ``kinematics_node`` (its ``scene``, ``joint_states``,
``point_accelerations`` and ``diagnostics``, with the ROS arguments given, so
namespaces and remaps apply) and serves one page on ``http://127.0.0.1:PORT/``
(localhost only; nothing is fetched from the internet; ``/?w=800&h=500``
fixes the drawing's size in pixels): the mechanism drawn
to scale as it moves (links, ground pivots, slider blocks and guides, the
published points, their traces over the last turn, optional velocity and
acceleration arrows and, for a scene with masses, gravity or loads, optional
arrows of the reactions the node publishes on ``reactions/JOINT``, at the
joints, scaled so that the largest is a fifth of the drawing), the solver
and timing status of ``diagnostics``, and a speed control for each driver
that sets the node's parameter (``crank_speed_rpm`` for a first driver that is a crank, else
``inputs.NAME.speed_rpm`` or, for an actuator, ``inputs.NAME.speed``, through
``rcl_interfaces/srv/SetParameters``).

The page (:data:`PAGE`, plain HTML and a canvas) asks ``/state`` for a JSON
frame (:func:`frame_from_state`) 20 times a second. The links are drawn from
the scene the node publishes on ``scene``, solved at the positions of every
driver in the latest ``joint_states``; points, arrows and traces are the
published values. ``make run`` starts the view beside the node and prints
its URL.

The door (a control that moves a machine answers only the person at the
page): every request must name this server in ``Host`` (``127.0.0.1:PORT``,
``localhost:PORT`` or ``[::1]:PORT``, served where the machine has IPv6's
loopback: a DNS-rebinding name is refused), a
request from a browser must come from the page's own origin (``Origin`` and
``Sec-Fetch-Site``), and ``/state`` and ``/speed`` must carry this run's
secret token (:attr:`ViewServer.token`, in the page; header
``X-View-Token``). ``/speed`` takes only a JSON body (``Content-Type:
application/json``), which no cross-site form can send. Anything else is
refused with 403 and one line. Nothing from the ROS graph becomes HTML: the
page writes every string with ``textContent``, and its Content-Security-Policy
runs no script but its own.
"""

from __future__ import annotations

import argparse
import base64
from collections import deque
from collections.abc import Mapping, Sequence
from dataclasses import replace
import hashlib
import hmac
import http.server
import json
import math
import re
import secrets
import socket
import statistics
import sys
import threading
from typing import Any
from urllib.parse import urlparse
import warnings

from .cli import run_tool
from ..ros import topics
from ..ros.parameters import first_crank_aliases
from ..units import NS_PER_S, rate_from_si

__all__ = ['DEFAULT_PORT', 'PAGE', 'TOKEN_HEADER', 'ViewServer', 'add_parser',
           'frame_from_state', 'main', 'scene_bounds']

#: The port tried first (not foxglove_bridge's 8765); if it is taken, any free port.
DEFAULT_PORT = 8790
HOST = '127.0.0.1'
#: IPv6's loopback, served at the same port where the machine has it.
HOST6 = '::1'
#: Trace length per point: the published positions (and gaps) over at most this many messages.
TRACE_LENGTH = 600
#: Crank angles sampled for the drawing's fixed bounds (one crank's turn).
BOUNDS_SAMPLES = 144
#: At most this many configurations sampled for the bounds of a scene with several drivers
#: (a grid over the drivers: 144 x 144 for two).
BOUNDS_GRID = BOUNDS_SAMPLES ** 2
#: An actuator without stroke limits is sampled over these fractions of its start length.
FREE_STROKE = (0.5, 1.5)
#: A trace breaks where two published points are more than this many times the usual
#: interval apart (the median of the last :data:`CADENCE_WINDOW` intervals): a tick
#: that published nothing is a gap, not a chord.
GAP_FACTOR = 1.5
CADENCE_WINDOW = 9
#: The name of the view's own statuses among the node's.
VIEW_STATUS = 'mech_kinematics view'
#: Seconds to wait for the node's SetParameters answer.
SERVICE_TIMEOUT_S = 3.0
#: The header that carries the page's token on ``/state`` and ``/speed``.
TOKEN_HEADER = 'X-View-Token'
#: The largest ``/speed`` body accepted, bytes.
MAX_BODY = 1024
#: Seconds a connection may stay silent before the server closes it.
REQUEST_TIMEOUT_S = 10.0
#: Refusals kept (:attr:`ViewServer.refusals`).
REFUSALS_KEPT = 100
#: Diagnostic levels the page colours (OK, WARN, ERROR, STALE); any other shows as STALE.
LEVELS = (0, 1, 2, 3)


def _finite(value: Any) -> float | None:
    """Return ``value`` as a finite float, or None (text, NaN, infinity, anything else)."""
    try:
        number = float(value)
    except (TypeError, ValueError, OverflowError):
        return None
    return number if math.isfinite(number) else None


def _shown(rate: float) -> float:
    """Return a speed converted for display (rpm from rad/s) to 15 significant digits.

    The default -120 rpm is published as -12.566370614359172 rad/s, which
    converts back to -119.99999999999999 rpm: the conversion's last bit, not
    the node's speed. 15 digits drop it (at most 5e-16 relative) and nothing
    a double holds of a real speed. Only the display: a speed set is sent as given.
    """
    return float(f'{rate:.15g}')


def _driver_samples(driver: Any, count: int) -> Any:
    """Return ``count`` positions of ``driver`` to sample, with its start, rad or m.

    A crank over a turn; an actuator over its stroke, or over
    :data:`FREE_STROKE` of its start length when it has none.
    """
    import numpy as np

    start = float(driver.start)
    if driver.joint_type.angular:
        values = np.linspace(0.0, 2.0 * math.pi, count, endpoint=False)
    elif driver.stroke is not None:
        values = np.linspace(float(driver.stroke[0]), float(driver.stroke[1]), count)
    else:
        values = np.linspace(FREE_STROKE[0] * start, FREE_STROKE[1] * start, count)
    return np.unique(np.append(values, start))


def scene_bounds(scene: Any) -> tuple[float, float, float, float]:
    """Return (x_min, y_min, x_max, y_max) of every point the scene reaches, m, padded 10 %.

    One crank: over its turn. Several drivers (or an actuator): over a grid
    of the drivers' positions (each sampled by :func:`_driver_samples`, at
    most :data:`BOUNDS_GRID` configurations in all), wherever the scene
    assembles; the ground points and the start pose are always inside.
    """
    import numpy as np

    import mech_kinematics as mk
    from ..geometry.instant_centres import full_scene

    full = full_scene(scene)
    drivers = full.drivers
    count = BOUNDS_SAMPLES
    while count > 2 and count ** len(drivers) > BOUNDS_GRID:
        count -= 1
    axes = [_driver_samples(driver, count) for driver in drivers]
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', mk.NearSingularWarning)
        if len(drivers) == 1:
            state = mk.solve(full, axes[0], 0.0, 0.0)
        else:
            grid = [axis.ravel() for axis in np.meshgrid(*axes, indexing='ij')]
            zeros = [np.zeros_like(grid[0])] * len(drivers)
            state = mk.solve(full, grid, zeros, zeros)
    xy = [complex(x, y) for x, y in scene.ground.values()]
    for position, _, _ in state.complex_points.values():
        xy += list(np.asarray(position)[state.valid])
    return _padded(xy)


def _padded(xy: Sequence[complex]) -> tuple[float, float, float, float]:
    """Return the box around ``xy``, padded by 10 % of its larger side (at least 0.1 mm)."""
    xs, ys = [z.real for z in xy], [z.imag for z in xy]
    pad = 0.1 * max(max(xs) - min(xs), max(ys) - min(ys), 1e-3)
    return min(xs) - pad, min(ys) - pad, max(xs) + pad, max(ys) + pad


def frame_from_state(scene: Any, position: float | Sequence[float],
                     speed: float | Sequence[float],
                     strokes: Mapping[str, tuple[float, float]]) -> dict[str, Any]:
    """Return the mechanism at its drivers' positions as JSON-ready shapes, m.

    Parameters
    ----------
    scene : Scene
        The mechanism.
    position : float or sequence of float
        The crank angle (rad) of a one-driver scene, or one position per
        driver in ``scene.drivers`` order (rad for a crank, m for an actuator).
    speed : float or sequence of float
        The driver's speed, or one per driver (rad/s, m/s).
    strokes : mapping of str to (float, float)
        Range of each RRP slider's coordinate, m, over which its guide is drawn.

    Returns
    -------
    dict
        ``angle``: the first driver's position; ``positions``: every
        driver's; ``links``: name, kind and outline (a polyline) of every
        moving link; ``pivots``: ground pins; ``sliders``: block centre and
        direction; ``guides``: fixed slider guides; ``points``: every named
        point.

    Raises
    ------
    AssemblyError
        Where the scene cannot assemble.
    ValueError
        Where the positions are not one finite value per driver.
    """
    import mech_kinematics as mk
    from ..geometry.diagrams import space_from_state
    from ..geometry.instant_centres import full_scene

    full = full_scene(scene)
    if full.dynamics is not None:   # the motion alone: the forces drawn are the node's
        full = replace(full, gravity=None, masses=(), loads=())
    count = len(full.drivers)
    positions = [position] if isinstance(position, (int, float)) else list(position)
    speeds = [speed] if isinstance(speed, (int, float)) else list(speed)
    if len(positions) != count or len(speeds) != count:
        msg = (f'Expected one position and one speed per driver ({count}), got '
               f'{len(positions)} and {len(speeds)}')
        raise ValueError(msg)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', mk.NearSingularWarning)
        if count == 1:
            state = mk.solve(full, float(positions[0]), float(speeds[0]), 0.0)
        else:
            state = mk.solve(full, [float(p) for p in positions], [float(v) for v in speeds],
                             [0.0] * count)
    space = space_from_state(full, state, strokes)
    return {
        'angle': float(positions[0]),
        'positions': [float(p) for p in positions],
        'links': [{'name': link.name, 'kind': link.kind.value,
                   'outline': [[float(x), float(y)] for x, y in link.outline]}
                  for link in space.links],
        'pivots': [[float(p.xy[0]), float(p.xy[1])] for p in space.pivots],
        'sliders': [{'name': s.name, 'xy': [float(s.xy[0]), float(s.xy[1])],
                     'angle': float(s.angle)} for s in space.sliders],
        'guides': [[[float(g.start[0]), float(g.start[1])], [float(g.end[0]), float(g.end[1])]]
                   for g in space.guides],
        'points': {name: [float(v[0]), float(v[1])] for name, v in space.points.items()},
        # Each body's frame's angle, rad: what a robot's reactions turn into the plane by.
        'angles': {name: float(body.frame.angle if body.frame.angle_of is None
                               else state.joints[body.frame.angle_of].position)
                   for name, body in full.graph.bodies.items() if body.frame is not None},
    }


def _in_plane(force: list[float] | None, robot: Any,
              angles: Mapping[str, float]) -> list[float] | None:
    """Return a reaction's force as drawn, [fx, fy] N in the plane (None: not finite).

    A scene's is in the plane already; a robot's (``robot``: its
    :class:`~mech_kinematics.solver.mechanism.RobotReaction`) is in its child
    link's axes, turned into the plane by its body's angle now.
    """
    if force is None:
        return None
    if robot is None:
        return force[:2]
    return list(robot.in_scene((force[0], force[1], force[2]), angles[robot.body]))


def _frame_xy(frame: Mapping[str, Any]) -> list[complex]:
    """Return every position a frame draws (points, outlines, guides), m."""
    xy = [complex(*p) for p in frame['points'].values()]
    xy += [complex(*p) for link in frame['links'] for p in link['outline']]
    xy += [complex(*p) for guide in frame['guides'] for p in guide]
    return xy


class _Cadence:
    """Whether each published stamp follows the last at the stream's usual interval.

    The usual interval is the median of the last :data:`CADENCE_WINDOW`
    (one long gap does not move it; a new rate does, within a few messages).
    A stamp more than :data:`GAP_FACTOR` usual intervals after the last, or
    not after it (a clock set back), is a break: the traces do not join
    across it.
    """

    def __init__(self) -> None:
        self.last: int | None = None
        self.intervals: deque[int] = deque(maxlen=CADENCE_WINDOW)

    def broken(self, stamp_ns: int) -> bool:
        """Take the next stamp (ns); return whether the stream broke before it."""
        last, self.last = self.last, stamp_ns
        if last is None:
            return False
        interval = stamp_ns - last
        if interval <= 0:
            self.intervals.clear()
            return True
        usual = statistics.median(self.intervals) if self.intervals else None
        self.intervals.append(interval)
        return usual is not None and interval > GAP_FACTOR * usual


def _vector(items: Any, index: int, field: str) -> list[float] | None:
    """Return ``items[index].field``'s (x, y) if it is there and finite, else None."""
    try:
        vector = getattr(items[index], field)
        x, y = _finite(vector.x), _finite(vector.y)
    except (IndexError, AttributeError, TypeError):
        return None
    return None if x is None or y is None else [x, y]


def _stamp_ns(stamp: Any) -> int:
    return int(stamp.sec) * NS_PER_S + int(stamp.nanosec)


class _Latest:
    """What the node last published, shared by the ROS callbacks and the HTTP handlers."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.scene: Any = None
        self.scene_error = ''
        self.bounds: tuple[float, float, float, float] | None = None
        self.strokes: dict[str, tuple[float, float]] = {}
        #: joint name -> (position, velocity, effort), each a finite float or None.
        self.joints: dict[str, tuple[float | None, float | None, float | None]] | None = None
        self.points: dict[str, tuple[list[float], list[float] | None, list[float] | None]] = {}
        #: point name -> its published positions, None where the stream broke.
        self.traces: dict[str, deque[tuple[float, float] | None]] = {}
        self.cadence = _Cadence()
        self.statuses: list[dict[str, Any]] = []
        self.values: dict[str, str] = {}
        self.stamp = 0.0
        #: joint name -> (its point, [fx, fy] N) as last published on reactions/JOINT
        #: (None: not finite, not drawn); a robot's (URDF mode): [fx, fy, fz] in its child
        #: link's axes, turned into the plane where drawn (the scene's urdf_reactions).
        self.reactions: dict[str, tuple[str, list[float] | None]] = {}


class ViewServer:
    """The ROS side (a node attached to kinematics_node) and the HTTP server of the view.

    Parameters
    ----------
    node : rclpy.node.Node
        The node to subscribe with (spun by the caller).
    port : int
        The port to serve on (127.0.0.1); 0 or a taken port: any free one.

    Attributes
    ----------
    token : str
        This run's secret, in the page it serves: ``/state`` and ``/speed``
        answer only requests that carry it in ``X-View-Token``.
    hosts : tuple of str
        The ``Host`` values accepted: ``127.0.0.1:PORT``, ``localhost:PORT``,
        and ``[::1]:PORT`` where it listens on IPv6's loopback too (``httpd6``).
    refusals : deque of str
        The last :data:`REFUSALS_KEPT` refused requests, one line each (what
        was asked, and why it was refused); each is also logged as a warning,
        at most once a second.
    """

    def __init__(self, node: Any, port: int = DEFAULT_PORT) -> None:
        from diagnostic_msgs.msg import DiagnosticArray
        from rcl_interfaces.srv import SetParameters
        from rclpy.qos import (DurabilityPolicy, qos_profile_sensor_data, QoSProfile,
                               ReliabilityPolicy)
        from sensor_msgs.msg import JointState
        from std_msgs.msg import String
        from trajectory_msgs.msg import MultiDOFJointTrajectory

        self.node = node
        self.latest = _Latest()
        self._reaction_subscriptions: list[Any] = []
        self.token = secrets.token_urlsafe(32)
        self.refusals: deque[str] = deque(maxlen=REFUSALS_KEPT)
        latched = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)
        node.create_subscription(String, topics.SCENE, self._on_scene, latched)
        node.create_subscription(JointState, topics.JOINT_STATES, self._on_joints,
                                 qos_profile_sensor_data)
        node.create_subscription(MultiDOFJointTrajectory, topics.POINT_ACCELERATIONS,
                                 self._on_points, qos_profile_sensor_data)
        node.create_subscription(DiagnosticArray, topics.DIAGNOSTICS, self._on_diagnostics, 10)
        # The node's name is mech_kinematics in this node's namespace.
        namespace = node.get_namespace().rstrip('/')
        self._set_parameters = node.create_client(
            SetParameters, f'{namespace}/mech_kinematics/set_parameters')
        self.httpd = _bind(port, self)
        self.port = self.httpd.server_address[1]
        self.url = f'http://{HOST}:{self.port}/'
        # IPv6's loopback too, at the same port, where the machine has one (a browser may
        # try localhost there first); its Host name is let in only where it is served.
        self.httpd6 = _bind6(self.port, self)
        self.hosts: tuple[str, ...] = (f'{HOST}:{self.port}', f'localhost:{self.port}')
        if self.httpd6 is not None:
            self.hosts += (f'[{HOST6}]:{self.port}',)
        for server in self._servers():
            threading.Thread(target=server.serve_forever, name='view-http', daemon=True).start()

    def _servers(self) -> list[http.server.ThreadingHTTPServer]:
        return [self.httpd] + ([] if self.httpd6 is None else [self.httpd6])

    def close(self) -> None:
        """Stop serving."""
        for server in self._servers():
            server.shutdown()
            server.server_close()

    def refused(self, line: str) -> None:
        """Record a refused request (one line) and log it, at most once a second."""
        self.refusals.append(line)
        self.node.get_logger().warning(f'view refused {line}', throttle_duration_sec=1.0)

    # -- ROS callbacks ---------------------------------------------------------

    def _on_scene(self, msg: Any) -> None:
        import mech_kinematics as mk
        from ..geometry.diagrams import strokes_from_scene
        from ..scene import read_scene_yaml

        try:
            scene = mk.parse_scene(read_scene_yaml(msg.data))
            bounds, strokes = scene_bounds(scene), strokes_from_scene(scene)
        except ValueError as error:     # SceneError, or a scene the view cannot size
            line = str(error).splitlines()[0] if str(error) else repr(error)
            with self.latest.lock:
                self.latest.scene_error = f'the scene the node published cannot be read: {line}'
            return
        with self.latest.lock:
            self.latest.scene, self.latest.bounds, self.latest.strokes = scene, bounds, strokes
            self.latest.scene_error = ''
            self.latest.traces = {}
            self.latest.cadence = _Cadence()
            self.latest.reactions = {}
        self._subscribe_reactions(scene)

    def _subscribe_reactions(self, scene: Any) -> None:
        """Subscribe ``reactions/JOINT`` of each joint of a scene with forces (none else)."""
        from geometry_msgs.msg import WrenchStamped
        from rclpy.exceptions import InvalidTopicNameException
        from rclpy.qos import qos_profile_sensor_data
        from rclpy.validate_topic_name import validate_topic_name

        old, self._reaction_subscriptions = self._reaction_subscriptions, []
        for subscription in old:
            if subscription is not None:
                self.node.destroy_subscription(subscription)
        if scene.urdf_drivers:  # a robot's: its loop joints' reactions, in child links' axes
            joints = [(r.joint, r.at) for r in scene.urdf_reactions]
        elif scene.dynamics is not None:
            joints = [(j.name, j.at) for j in scene.dynamics.graph.joints]
        else:
            return
        for name, at in joints:
            topic = topics.reaction_topic(name)
            try:
                validate_topic_name(topic)
            except InvalidTopicNameException:
                continue    # no topic of that name (the node warns at its start)
            self._reaction_subscriptions.append(self.node.create_subscription(
                WrenchStamped, topic,
                lambda msg, name=name, at=at: self._on_reaction(name, at, msg),
                qos_profile_sensor_data))

    def _on_reaction(self, name: str, at: str, msg: Any) -> None:
        f = msg.wrench.force
        force = [_finite(f.x), _finite(f.y), _finite(f.z)]
        with self.latest.lock:
            # Not finite: None, not drawn, and the page says so.
            self.latest.reactions[name] = (at, None if None in force else force)

    def _on_joints(self, msg: Any) -> None:
        positions, velocities, efforts = list(msg.position), list(msg.velocity), list(msg.effort)
        joints = {}
        for i, name in enumerate(msg.name):
            joints[str(name)] = (_finite(positions[i]) if i < len(positions) else None,
                                 _finite(velocities[i]) if i < len(velocities) else None,
                                 _finite(efforts[i]) if i < len(efforts) else None)
        with self.latest.lock:
            self.latest.joints = joints
            self.latest.stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9

    def _on_points(self, msg: Any) -> None:
        out: dict[str, tuple[list[float], list[float] | None, list[float] | None]] = {}
        for point in msg.points[:1]:
            for i, name in enumerate(msg.joint_names):
                xy = _vector(point.transforms, i, 'translation')
                if xy is not None:  # a point not published, or not finite: a gap in its trace
                    out[str(name)] = (xy, _vector(point.velocities, i, 'linear'),
                                      _vector(point.accelerations, i, 'linear'))
        stamp = _stamp_ns(msg.header.stamp)
        with self.latest.lock:
            latest = self.latest
            latest.points = out
            broken = latest.cadence.broken(stamp)
            ground = latest.scene.ground if latest.scene is not None else {}
            for name, trace in latest.traces.items():
                if (broken or name not in out) and trace and trace[-1] is not None:
                    trace.append(None)
            for name, (xy, _, _) in out.items():
                if name in ground:
                    continue    # a fixed point: nothing to trace
                latest.traces.setdefault(name, deque(maxlen=TRACE_LENGTH)).append(
                    (xy[0], xy[1]))

    def _on_diagnostics(self, msg: Any) -> None:
        statuses = []
        values = {}
        for status in msg.status:
            level = status.level
            level = int.from_bytes(level, 'little') if isinstance(level, bytes) else level
            statuses.append({'name': str(status.name), 'message': str(status.message),
                             'level': level if level in LEVELS else LEVELS[-1]})
            values.update({str(kv.key): str(kv.value) for kv in status.values})
        with self.latest.lock:
            self.latest.statuses, self.latest.values = statuses, values

    # -- HTTP ------------------------------------------------------------------

    def state(self) -> dict[str, Any]:
        """Return the JSON of ``/state``: the frame to draw, the drivers, points, traces, statuses.

        Whatever another node published, the answer is finite JSON: a value
        that is not a finite number is left out (``None``), and a frame that
        cannot be drawn says why in ``error``.
        """
        with self.latest.lock:
            latest = self.latest
            scene, joints, strokes = latest.scene, latest.joints, dict(latest.strokes)
            out: dict[str, Any] = {
                'scene': scene.name if scene is not None else None,
                'scene_error': latest.scene_error, 'bounds': latest.bounds,
                'stamp': latest.stamp, 'points': dict(latest.points),
                'traces': {name: list(trace) for name, trace in latest.traces.items()},
                'statuses': list(latest.statuses), 'drivers': [],
                'crank_speed_rpm': None, 'frame': None, 'error': '', 'reactions': []}
            values = dict(latest.values)
            reactions = dict(latest.reactions)
        # Before joint_states: the node's own report of its crank's speed, where it is a number.
        reported = _finite(values.get('crank_speed'))
        if reported is not None:
            out['crank_speed_rpm'] = _shown(rate_from_si(reported, 'rpm'))
        if scene is None:
            return out
        joints = joints or {}
        positions: list[float] = []
        speeds: list[float] = []
        missing = []
        first_crank = bool(first_crank_aliases(scene.drivers))
        # A robot's loops (URDF mode): joint_states names the URDF's joints, each driver
        # following one (the scene's urdf_drivers).
        followed = {f.driver: f for f in scene.urdf_drivers}
        for index, driver in enumerate(scene.drivers):
            position, speed, effort = joints.get(driver.name, (None, None, None))
            effort_of = driver.name
            follows = followed.get(driver.name)
            if driver.name not in joints and follows is not None and follows.joint in joints:
                q, rate, effort = joints[follows.joint]     # the URDF joint's, its own sign
                effort_of = follows.joint
                position = None if q is None else _finite(follows.driver_value(q))
                speed = None if rate is None else _finite(follows.factor * rate)
            # The speed in the unit the node's parameter sets it in (rpm, m/s).
            unit = driver.rate_parameter.unit
            shown = None if speed is None else _shown(rate_from_si(speed, unit))
            out['drivers'].append({'name': driver.name, 'kind': type(driver).__name__.lower(),
                                   'unit': unit, 'position': position, 'speed': shown,
                                   'effort': None if effort is None else _shown(effort),
                                   'effort_of': effort_of,
                                   'effort_unit': 'N m' if driver.joint_type.angular else 'N'})
            if index == 0 and first_crank and shown is not None:
                out['crank_speed_rpm'] = shown
            if position is None:
                missing.append(driver.name if follows is None or driver.name in joints
                               else f'{follows.joint} (which {driver.name} follows)')
            else:
                positions.append(position)
            speeds.append(0.0 if speed is None else speed)
        if joints and missing:
            out['error'] = f'Expected a finite position of {", ".join(missing)} in joint_states'
        elif joints:
            try:
                out['frame'] = frame_from_state(scene, positions, speeds, strokes)
            except ValueError as error:     # AssemblyError too
                out['error'] = str(error).splitlines()[0] if str(error) else repr(error)
        if out['frame'] is not None:
            out['bounds'] = self._grown(scene, out['bounds'], _frame_xy(out['frame']))
            where = out['frame']['points']
            turned = {r.joint: r for r in scene.urdf_reactions} if scene.urdf_drivers else {}
            angles = out['frame']['angles']
            out['reactions'] = [{'name': name, 'at': where[at],
                                 'force': _in_plane(force, turned.get(name), angles)}
                                for name, (at, force) in reactions.items() if at in where]
        return out

    def _grown(self, scene: Any, bounds: tuple[float, float, float, float] | None,
               xy: list[complex]) -> tuple[float, float, float, float] | None:
        """Return ``bounds`` grown (and kept) to hold ``xy`` where a frame reaches past them."""
        if bounds is None or not xy:
            return bounds
        x0, y0, x1, y1 = bounds
        if all(x0 <= z.real <= x1 and y0 <= z.imag <= y1 for z in xy):
            return bounds
        grown = _padded([*xy, complex(x0, y0), complex(x1, y1)])
        with self.latest.lock:
            if self.latest.scene is scene:
                self.latest.bounds = grown
        return grown

    def parameter_of(self, driver: str | None) -> tuple[str, str]:
        """Return the node parameter that sets ``driver``'s speed, and its unit.

        ``crank_speed_rpm`` for the first driver when it is a crank (also
        ``driver=None``), ``inputs.NAME.speed_rpm`` for another crank,
        ``inputs.NAME.speed`` (m/s) for an actuator. Raises ValueError for a
        driver the scene does not have, or before the scene has come.
        """
        with self.latest.lock:
            scene = self.latest.scene
        if scene is None:
            msg = "Expected the node's scene before a speed, got none yet"
            raise ValueError(msg)
        drivers = list(scene.drivers)
        names = [d.name for d in drivers]
        if driver is None:
            driver = names[0]
        if driver not in names:
            msg = f'Expected a driver of the scene ({", ".join(names)}), got {driver!r}'
            raise ValueError(msg)
        index = names.index(driver)
        key, unit = drivers[index].rate_parameter
        if index == 0 and first_crank_aliases(drivers):
            return 'crank_speed_rpm', unit
        return f'inputs.{driver}.{key}', unit

    def set_speed(self, value: float, driver: str | None = None) -> dict[str, Any]:
        """Ask the node to set a driver's speed; return {'successful', 'reason'}.

        ``value`` is in rpm for a crank, m/s for an actuator; ``driver``
        defaults to the first (:meth:`parameter_of` names the parameter).
        """
        from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
        from rcl_interfaces.srv import SetParameters

        try:
            name, _ = self.parameter_of(driver)
        except ValueError as error:
            return {'successful': False, 'reason': str(error)}
        if not self._set_parameters.wait_for_service(timeout_sec=SERVICE_TIMEOUT_S):
            return {'successful': False, 'reason': 'the node does not answer set_parameters'}
        request = SetParameters.Request(parameters=[Parameter(
            name=name, value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE,
                                            double_value=float(value)))])
        done = threading.Event()
        future = self._set_parameters.call_async(request)
        future.add_done_callback(lambda _future: done.set())
        if not done.wait(SERVICE_TIMEOUT_S):
            return {'successful': False, 'reason': 'no answer from set_parameters in time'}
        results = future.result().results
        if len(results) != 1:
            return {'successful': False,
                    'reason': f'Expected one result from set_parameters, got {len(results)}'}
        return {'successful': bool(results[0].successful), 'reason': str(results[0].reason)}


def _bind(port: int, view: ViewServer) -> http.server.ThreadingHTTPServer:
    handler = type('Handler', (_Handler,), {'view': view})
    try:
        return http.server.ThreadingHTTPServer((HOST, port), handler)
    except OSError:
        return http.server.ThreadingHTTPServer((HOST, 0), handler)


class _Server6(http.server.ThreadingHTTPServer):
    address_family = socket.AF_INET6


def _bind6(port: int, view: ViewServer) -> http.server.ThreadingHTTPServer | None:
    """Return a server on ``[::1]:port``, or None without an IPv6 loopback (or it is taken)."""
    handler = type('Handler', (_Handler,), {'view': view})
    try:
        return _Server6((HOST6, port), handler)
    except OSError:
        return None


class _Refused(Exception):
    """A request the door does not let in: its status and one line saying why."""

    def __init__(self, status: int, line: str) -> None:
        super().__init__(line)
        self.status = status
        self.line = line


class _Handler(http.server.BaseHTTPRequestHandler):
    view: ViewServer
    timeout = REQUEST_TIMEOUT_S
    server_version = 'mech_kinematics-view'
    sys_version = ''

    def log_message(self, format: str, *args: Any) -> None:  # noqa: A002 - the base's name
        """Log nothing per request (the console belongs to the live view)."""

    def _send(self, body: bytes, content_type: str, status: int = 200,
              headers: Mapping[str, str] | None = None) -> None:
        self.send_response(status)
        self.send_header('Content-Type', content_type)
        self.send_header('Content-Length', str(len(body)))
        self.send_header('Cache-Control', 'no-store')
        self.send_header('X-Content-Type-Options', 'nosniff')
        self.send_header('Referrer-Policy', 'no-referrer')
        self.send_header('Cross-Origin-Resource-Policy', 'same-origin')
        for name, value in (headers or {}).items():
            self.send_header(name, value)
        self.end_headers()
        self.wfile.write(body)

    def _json(self, data: Any, status: int = 200) -> None:
        self._send(json.dumps(data, allow_nan=False).encode(), 'application/json', status)

    def _refuse(self, status: int, line: str) -> None:
        self.view.refused(f'{self.command} {urlparse(self.path).path}: {line}')
        self._send(f'{line}\n'.encode(), 'text/plain; charset=utf-8', status)

    def _door(self, api: bool) -> None:
        """Raise :class:`_Refused` unless the request may come in.

        ``Host`` must name this server; ``Origin`` and ``Sec-Fetch-Site``,
        where a browser sends them, must say the page's own origin; ``api``
        (``/state``, ``/speed``): the token must be in ``X-View-Token``.
        """
        host = self.headers.get('Host')
        if host is None or host.lower() not in self.view.hosts:
            line = (f'Expected Host {" or ".join(self.view.hosts)}, got '
                    f'{"none" if host is None else repr(host)}')
            raise _Refused(403, line)
        origin = self.headers.get('Origin')
        if origin is not None and origin.lower() != f'http://{host.lower()}':
            raise _Refused(403, f'Expected a request from the page of http://{host}, got one '
                                f'from Origin {origin!r}')
        site = self.headers.get('Sec-Fetch-Site')
        if api and site is not None and site != 'same-origin':
            raise _Refused(403, f'Expected a request from the page of http://{host} '
                                f'(Sec-Fetch-Site same-origin), got Sec-Fetch-Site {site!r}')
        if not api:
            return
        given = self.headers.get(TOKEN_HEADER)
        if given is None:
            raise _Refused(403, f"Expected this view's token in {TOKEN_HEADER} (the page "
                                'sends it), got none')
        if not hmac.compare_digest(given.encode('utf-8', 'replace'), self.view.token.encode()):
            raise _Refused(403, f"Expected this view's token in {TOKEN_HEADER}, got another "
                                '(a page of an earlier view? reload it)')

    def _answer(self, serve: Any) -> None:
        """Run ``serve``; a refusal is its line, any failure one line, never a dropped request."""
        try:
            serve()
        except _Refused as refused:
            self._refuse(refused.status, refused.line)
        except (BrokenPipeError, ConnectionResetError):
            pass    # the browser went away
        except Exception as error:  # noqa: BLE001 - the page gets one line, the server goes on
            line = f'view: {self.command} failed: {type(error).__name__}: {error}'
            self._json({'error': line.splitlines()[0]}, 500)

    def do_GET(self) -> None:
        """Serve the page and ``/state``."""
        self._answer(self._get)

    def do_POST(self) -> None:
        """``/speed``: set a driver's speed (a JSON body ``{"driver": NAME, "value": X}``)."""
        self._answer(self._post)

    def do_OPTIONS(self) -> None:
        """Refuse a CORS preflight: no other origin may call the view."""
        self._answer(self._preflight)

    def _preflight(self) -> None:
        self._door(api=False)
        raise _Refused(403, 'Expected no cross-origin request, got a CORS preflight')

    def _get(self) -> None:
        path = urlparse(self.path).path
        if path == '/':
            self._door(api=False)
            self._send(_page(self.view.token).encode(), 'text/html; charset=utf-8',
                       headers={'Content-Security-Policy': CSP, 'X-Frame-Options': 'DENY'})
        elif path == '/state':
            self._door(api=True)
            self._json(self.view.state())
        else:
            self._door(api=False)
            self._json({'error': f'Expected / or /state, got {path}'}, 404)

    def _post(self) -> None:
        path = urlparse(self.path).path
        self._door(api=path == '/speed')
        if path != '/speed':
            self._json({'error': f'Expected /speed, got {path}'}, 404)
            return
        if self.headers.get_content_type() != 'application/json':
            raise _Refused(415, f'Expected Content-Type application/json, got '
                                f'{self.headers.get("Content-Type")!r}')
        length = self.headers.get('Content-Length', '')
        if not length.isdigit() or not 0 < int(length) <= MAX_BODY:
            raise _Refused(400, f'Expected a body of 1 to {MAX_BODY} bytes with its '
                                f'Content-Length, got Content-Length {length!r}')
        text = self.rfile.read(int(length)).decode('utf-8', 'replace')
        try:
            body = json.loads(text)
        except ValueError:
            body = None
        value = body.get('value') if isinstance(body, dict) else None
        driver = body.get('driver') if isinstance(body, dict) else None
        if not isinstance(value, (int, float)) or isinstance(value, bool) \
                or not math.isfinite(value) or not isinstance(driver, (str, type(None))):
            shown = text if len(text) <= 80 else text[:77] + '...'
            self._json({'successful': False,
                        'reason': 'Expected {"driver": NAME, "value": a number (rpm for a crank, '
                                  f'm/s for an actuator)}}, got {shown!r}'}, 400)
            return
        try:
            self.view.parameter_of(driver)
        except ValueError as error:
            self._json({'successful': False, 'reason': str(error)}, 400)
            return
        self._json(self.view.set_speed(float(value), driver))


def _page(token: str) -> str:
    """Return :data:`PAGE` carrying ``token`` (URL-safe characters only)."""
    return PAGE.replace('VIEW_TOKEN', token, 1)


PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>mech_kinematics view</title>
<meta name="view-token" content="VIEW_TOKEN">
<style>
body { font: 14px sans-serif; margin: 0; display: flex; flex-direction: column; height: 100vh; }
header { padding: 6px 10px; background: #eee; display: flex; gap: 16px; align-items: center;
         flex-wrap: wrap; }
/* the canvas's box is set in pixels to its bitmap's size: one metre is as many pixels in x
   as in y whatever the window does between two drawings */
#frame { flex: 1; min-height: 0; position: relative; overflow: hidden; background: #fff; }
#c { position: absolute; left: 0; top: 0; }
/* two lines, always: a status whose text wraps differently must not move the drawing */
#status { flex-basis: 100%; line-height: 1.2em; height: 2.4em; overflow: hidden; }
#status span { margin-right: 12px; }
#controls label { margin-right: 10px; }
input.speed { width: 7em; }
.l0 { color: #1a7f37; } .l1 { color: #b35900; } .l2 { color: #c00; } .l3 { color: #777; }
#drawn { display: none; }
</style></head><body>
<header>
<b id="scene">waiting for the node's scene...</b>
<span id="controls"></span>
<label><input id="arrows" type="checkbox"> velocity and acceleration arrows</label>
<label><input id="forces" type="checkbox"> reactions</label>
<div id="status"></div>
</header>
<div id="frame"><canvas id="c"></canvas></div>
<pre id="drawn"></pre>
<script>
'use strict';
// Strings from the ROS graph (names, messages) are written with textContent or drawn on
// the canvas: none is ever parsed as HTML.
const TOKEN = document.querySelector('meta[name="view-token"]').content;
const COLOURS = {crank: '#d62728', link: '#1f77b4', lever: '#2ca02c'};
const frame = document.getElementById('frame');
const canvas = document.getElementById('c');
const ctx = canvas.getContext('2d');
let busy = false, last = null, controlsFor = null;

// ?w=800&h=500 fixes the drawing's size in pixels (default: the window's free space).
const query = new URLSearchParams(location.search);
const fixed = [query.get('w'), query.get('h')].map((v) => parseInt(v, 10));
if (fixed.every((v) => v > 0 && v <= 20000)) {
  frame.style.flex = 'none';
  frame.style.width = fixed[0] + 'px'; frame.style.height = fixed[1] + 'px';
}

function transform(bounds) {
  // The bitmap and the canvas's box are given the same size in pixels, so the drawing is
  // never stretched: one metre is k pixels in x and in y.
  const w = Math.max(1, frame.clientWidth), h = Math.max(1, frame.clientHeight);
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w; canvas.height = h;
    canvas.style.width = w + 'px'; canvas.style.height = h + 'px';
  }
  const [x0, y0, x1, y1] = bounds;
  const k = Math.min(w / (x1 - x0), h / (y1 - y0));   // pixels per metre, both axes: to scale
  const ox = (w - k * (x1 + x0)) / 2, oy = (h + k * (y1 + y0)) / 2;
  return {k: k, ox: ox, oy: oy, px: (p) => [ox + k * p[0], oy - k * p[1]]};
}

function line(t, a, b, colour, width) {
  ctx.strokeStyle = colour; ctx.lineWidth = width; ctx.lineCap = 'round';
  ctx.beginPath(); ctx.moveTo(...t.px(a)); ctx.lineTo(...t.px(b)); ctx.stroke();
}

function dot(t, p, r, colour) {
  ctx.fillStyle = colour; ctx.beginPath(); ctx.arc(...t.px(p), r, 0, 2 * Math.PI); ctx.fill();
}

function element(tag, text, className) {
  const e = document.createElement(tag);
  if (text !== undefined) e.textContent = text;
  if (className) e.className = className;
  return e;
}

async function setSpeed(driver, input, answer) {
  const value = Number(input.value);
  if (input.value.trim() === '' || !Number.isFinite(value)) {
    answer.textContent = 'Expected a number, got ' + JSON.stringify(input.value);
    return;
  }
  try {
    const r = await fetch('/speed', {method: 'POST', body: JSON.stringify(
      {driver: driver, value: value}), headers: {'X-View-Token': TOKEN,
                                                 'Content-Type': 'application/json'}});
    const text = await r.text();
    let said = text.trim();
    try { const j = JSON.parse(text); said = j.successful ? 'set' : j.reason || j.error; }
    catch (e) { }
    answer.textContent = said;
  } catch (e) {
    answer.textContent = 'the view does not answer: ' + e.message;
  }
}

// A speed control per driver (rpm or m/s), rebuilt when the drivers change; each shows
// the driver's speed and effort in the latest joint_states.
function controls(s) {
  const box = document.getElementById('controls');
  const key = JSON.stringify(s.drivers.map((d) => [d.name, d.unit]));
  if (key !== controlsFor) {
    controlsFor = key;
    box.replaceChildren();
    for (const d of s.drivers) {
      const label = element('label', d.name + ' speed ');
      const input = element('input', undefined, 'speed');
      input.type = 'number'; input.step = d.unit === 'rpm' ? '10' : '0.01';
      input.dataset.driver = d.name;
      const button = element('button', 'set');
      const answer = element('span', '', 'answer');
      button.onclick = () => setSpeed(d.name, input, answer);
      label.append(input, ' ' + d.unit + ' ', button, ' ', element('span', '', 'running'),
                   ' ', answer);
      box.append(label);
    }
  }
  s.drivers.forEach((d, i) => {
    box.children[i].querySelector('.running').textContent = (d.speed === null ? '' :
      '(running at ' + d.speed + ' ' + d.unit + ')') + (d.effort === null ? '' :
      ' ' + d.effort_of + ' ' + d.effort + ' ' + d.effort_unit);
  });
}

function draw(s) {
  last = s;
  document.getElementById('scene').textContent = s.scene ?
    s.scene + (s.error ? ': ' + s.error : '') : (s.scene_error || 'waiting for the node...');
  controls(s);
  document.getElementById('status').replaceChildren(...s.statuses.map(
    (x) => element('span', x.name.split(': ').pop() + ': ' + x.message, 'l' + x.level)));
  if (!s.bounds) return;
  const t = transform(s.bounds);
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  // Scale bar: a round length near a fifth of the width.
  const m = canvas.width / 5 / t.k, bar = Math.pow(10, Math.floor(Math.log10(m)));
  ctx.fillStyle = '#000'; ctx.fillRect(10, canvas.height - 14, bar * t.k, 3);
  ctx.fillText(String(+(bar * 1000).toPrecision(1)) + ' mm', 10, canvas.height - 18);
  // A trace is broken where the stream was (null): no chord across what was not published.
  ctx.strokeStyle = '#bbb'; ctx.lineWidth = 1;
  for (const trace of Object.values(s.traces)) {
    ctx.beginPath();
    let pen = false;
    for (const p of trace) {
      if (p === null) { pen = false; continue; }
      if (pen) ctx.lineTo(...t.px(p)); else ctx.moveTo(...t.px(p));
      pen = true;
    }
    ctx.stroke();
  }
  // What was drawn, in m and in pixels (read by the tests).
  const box = canvas.getBoundingClientRect();
  const f = s.frame, drawn = {angle: null, positions: null, k: t.k, ox: t.ox, oy: t.oy,
                              left: box.left, top: box.top, width: canvas.width,
                              height: canvas.height, links: [], arrows: [], reactions: []};
  if (f) {
    drawn.angle = f.angle; drawn.positions = f.positions;
    for (const g of f.guides) line(t, g[0], g[1], '#888', 2);
    for (const l of f.links) {
      const o = l.outline, colour = COLOURS[l.kind] || '#1f77b4';
      for (let i = 0; i + 1 < o.length; i++) line(t, o[i], o[i + 1], colour, 6);
      if (o.length > 2) line(t, o[o.length - 1], o[0], colour, 6);
      drawn.links.push({name: l.name, colour: colour, outline: o});
    }
    for (const sl of f.sliders) {
      const [x, y] = t.px(sl.xy);
      ctx.save(); ctx.translate(x, y); ctx.rotate(-sl.angle);
      ctx.fillStyle = '#ff7f0e'; ctx.fillRect(-16, -9, 32, 18); ctx.restore();
    }
    for (const p of f.pivots) dot(t, p, 7, '#444');
    for (const p of Object.values(f.points)) dot(t, p, 3, '#000');
  }
  // u / m first (m = max |u[i]|): Math.hypot(2e308, 0) is Infinity.
  const big = (u) => Math.max(Math.abs(u[0]), Math.abs(u[1])), no = [];
  const w = s.bounds[2] - s.bounds[0], arrow = (p, u, m, k, c, lw) => {
    const e = m ? [p[0] + u[0] / m * k, p[1] + u[1] / m * k] : p;
    line(t, p, e, c, lw); return {from: p, to: e};
  };
  if (document.getElementById('arrows').checked) {
    for (const [n, [p, ...va]] of Object.entries(s.points)) va.forEach((u, i) => {
      const m = u && big(u), what = ['velocity', 'acceleration'][i];
      if (!u) no.push(what + ' of ' + n);
      else if (m) drawn.arrows.push({name: n, what: what, ...arrow(
        p, u, m, w / 10 / Math.hypot(u[0] / m, u[1] / m), i ? '#8c564b' : '#9467bd', 2)});
    });
  }
  if (document.getElementById('forces').checked) {
    const fs = s.reactions.filter((r) => r.force || !no.push('reaction at ' + r.name));
    const m = Math.max(0, ...fs.map((r) => big(r.force)));
    const h = Math.max(...fs.map((r) => m && Math.hypot(r.force[0] / m, r.force[1] / m)));
    for (const r of fs) {
      drawn.reactions.push({name: r.name, ...arrow(r.at, r.force, m, w / 5 / h, '#e377c2', 3)});
    }
  }
  drawn.undrawn = no.length ? 'not drawn (not finite): ' + no.join(', ') : '';
  ctx.fillStyle = '#c00'; ctx.fillText(drawn.undrawn, 10, 14);
  ctx.fillStyle = '#000';
  for (const [name, [p]] of Object.entries(s.points)) ctx.fillText(name, ...t.px(p).map(
    (c) => c + 6));
  document.getElementById('drawn').textContent = JSON.stringify(drawn);
}

async function poll() {
  if (busy) return;
  busy = true;
  try {
    const r = await fetch('/state', {headers: {'X-View-Token': TOKEN}, cache: 'no-store'});
    if (r.ok) draw(await r.json());
    else document.getElementById('scene').textContent = (await r.text()).trim();
  } catch (e) {
    document.getElementById('scene').textContent = 'the view does not answer: ' + e.message;
  }
  busy = false;
}

// A new size of the window is drawn at once, from the last state.
new ResizeObserver(() => { if (last) draw(last); }).observe(frame);
setInterval(poll, 50);
poll();
</script></body></html>
"""


def _digest(tag: str) -> str:
    """Return the base64 SHA-256 of the text of :data:`PAGE`'s one ``<tag>`` element."""
    found = re.search(f'<{tag}>(.*?)</{tag}>', PAGE, re.DOTALL)
    assert found is not None, tag
    return base64.b64encode(hashlib.sha256(found[1].encode()).digest()).decode()


#: The page's Content-Security-Policy: its own script and style only (by their SHA-256),
#: requests to its own origin only, no image, form, base or frame.
CSP = (f"default-src 'none'; script-src 'sha256-{_digest('script')}'; "
       f"style-src 'sha256-{_digest('style')}'; connect-src 'self'; img-src 'none'; "
       "base-uri 'none'; form-action 'none'; frame-ancestors 'none'")


def _handle(args: argparse.Namespace) -> int:
    return main(args.view_args)


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register the ``view`` command on ``subparsers``; return its parser."""
    parser: argparse.ArgumentParser = subparsers.add_parser(
        'view', help='serve a live drawing of a running node on http://127.0.0.1 (browser)',
        description='Attach to a running kinematics_node and serve its mechanism, live, on '
                    f'http://{HOST}:{DEFAULT_PORT}/ (localhost only). Arguments: [--port N] '
                    '[--ros-args ...] (namespaces and remaps apply to the topics).')
    parser.add_argument('view_args', nargs=argparse.REMAINDER, metavar='ARGS',
                        help='[--port N] [--ros-args ...]')
    parser.set_defaults(handler=_handle)
    return parser


def _port(argv: list[str]) -> tuple[int, list[str]]:
    """Return the --port value (default :data:`DEFAULT_PORT`) and the other arguments."""
    if '--port' not in argv[:argv.index('--ros-args') if '--ros-args' in argv else None]:
        return DEFAULT_PORT, argv
    i = argv.index('--port')
    text = argv[i + 1] if i + 1 < len(argv) else ''
    if not text.isdigit() or not 0 <= int(text) <= 65535:
        msg = f'--port: expected a port number 0..65535, got {text!r}'
        raise ValueError(msg)
    return int(text), argv[:i] + argv[i + 2:]


def main(argv: Sequence[str] | None = None) -> int:
    """Serve the view until Ctrl-C; return the exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv in (['-h'], ['--help']):
        return run_tool(add_parser, argv)
    try:
        port, argv = _port(argv)
    except ValueError as error:
        print(f'error: {error}', file=sys.stderr)
        return 2
    import rclpy
    from rclpy.executors import ExternalShutdownException

    ros_args = argv[argv.index('--ros-args'):] if '--ros-args' in argv else []
    rclpy.init(args=['view', *ros_args])
    node = server = None
    try:
        node = rclpy.create_node('mech_kinematics_view')
        server = ViewServer(node, port)
        print(f'mech_kinematics view: {server.url} (Ctrl-C stops it)', flush=True)
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass    # Ctrl-C: stop serving below
    finally:
        if server is not None:
            server.close()
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
