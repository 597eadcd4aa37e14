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
acceleration arrows), the solver and timing status of ``diagnostics``, and a
control for the crank speed that sets the node's ``crank_speed_rpm``
(``rcl_interfaces/srv/SetParameters``).

The page (:data:`PAGE`, plain HTML and a canvas) asks ``/state`` for a JSON
frame (:func:`frame_from_state`) 20 times a second. The links are drawn from
the scene the node publishes on ``scene``, solved at the crank angle and
speed of the latest ``joint_states``; points, arrows and traces are the
published values. ``make run`` starts the view beside the node and prints
its URL.
"""

from __future__ import annotations

import argparse
from collections import deque
from collections.abc import Mapping, Sequence
import http.server
import json
import math
import sys
import threading
from typing import Any
from urllib.parse import parse_qs, urlparse
import warnings

from .cli import run_tool
from ..ros import topics

__all__ = ['DEFAULT_PORT', 'PAGE', 'ViewServer', 'add_parser', 'frame_from_state', 'main',
           'scene_bounds']

#: The port tried first (not foxglove_bridge's 8765); if it is taken, any free port.
DEFAULT_PORT = 8790
HOST = '127.0.0.1'
#: Trace length per point: the published positions over at most this many messages.
TRACE_LENGTH = 600
#: Crank angles sampled for the drawing's fixed bounds.
BOUNDS_SAMPLES = 144
#: Seconds to wait for the node's SetParameters answer.
SERVICE_TIMEOUT_S = 3.0


def scene_bounds(scene: Any) -> tuple[float, float, float, float]:
    """Return (x_min, y_min, x_max, y_max) of every point over a crank turn, m, padded 10 %."""
    import numpy as np

    import mech_kinematics as mk
    from ..geometry.instant_centres import full_scene

    full = full_scene(scene)
    angles = np.linspace(0.0, 2.0 * math.pi, BOUNDS_SAMPLES, endpoint=False)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', mk.NearSingularWarning)
        state = mk.solve(full, angles)
    xy = [complex(x, y) for x, y in scene.ground.values()]
    for position, _, _ in state.complex_points.values():
        xy += list(np.asarray(position)[state.valid])
    xs, ys = [z.real for z in xy], [z.imag for z in xy]
    pad = 0.1 * max(max(xs) - min(xs), max(ys) - min(ys), 1e-3)
    return min(xs) - pad, min(ys) - pad, max(xs) + pad, max(ys) + pad


def frame_from_state(scene: Any, angle: float, speed: float,
                     strokes: Mapping[str, tuple[float, float]]) -> dict[str, Any]:
    """Return the mechanism at crank ``angle`` (rad) as JSON-ready shapes, m.

    ``links``: name, kind and outline (a polyline) of every moving link;
    ``pivots``: ground pins; ``sliders``: block centre and direction;
    ``guides``: fixed slider guides over their stroke; ``points``: every
    named point. Raises :class:`~mech_kinematics.errors.AssemblyError` where
    the scene cannot assemble.
    """
    import mech_kinematics as mk
    from ..geometry.diagrams import space_from_state
    from ..geometry.instant_centres import full_scene

    full = full_scene(scene)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', mk.NearSingularWarning)
        state = mk.solve(full, angle, speed, 0.0)
    space = space_from_state(full, state, strokes)
    return {
        'angle': angle,
        'links': [{'name': link.name, 'kind': link.kind.value,
                   'outline': [[float(x), float(y)] for x, y in link.outline]}
                  for link in space.links],
        'pivots': [[float(p.xy[0]), float(p.xy[1])] for p in space.pivots],
        'sliders': [{'name': s.name, 'xy': [float(s.xy[0]), float(s.xy[1])],
                     'angle': float(s.angle)} for s in space.sliders],
        'guides': [[[float(g.start[0]), float(g.start[1])], [float(g.end[0]), float(g.end[1])]]
                   for g in space.guides],
        'points': {name: [float(v[0]), float(v[1])] for name, v in space.points.items()},
    }


class _Latest:
    """What the node last published, shared by the ROS callbacks and the HTTP handlers."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.scene: Any = None
        self.scene_error = ''
        self.bounds: tuple[float, float, float, float] | None = None
        self.strokes: dict[str, tuple[float, float]] = {}
        self.joints: tuple[Sequence[str], Sequence[float], Sequence[float]] | None = None
        self.points: dict[str, list[list[float]]] = {}
        self.traces: dict[str, deque[tuple[float, float]]] = {}
        self.statuses: list[dict[str, Any]] = []
        self.values: dict[str, str] = {}
        self.stamp = 0.0


class ViewServer:
    """The ROS side (a node attached to kinematics_node) and the HTTP server of the view.

    Parameters
    ----------
    node : rclpy.node.Node
        The node to subscribe with (spun by the caller).
    port : int
        The port to serve on (127.0.0.1); 0 or a taken port: any free one.
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
        self._thread = threading.Thread(target=self.httpd.serve_forever, name='view-http',
                                        daemon=True)
        self._thread.start()

    def close(self) -> None:
        """Stop serving."""
        self.httpd.shutdown()
        self.httpd.server_close()

    # -- ROS callbacks ---------------------------------------------------------

    def _on_scene(self, msg: Any) -> None:
        import mech_kinematics as mk
        from ..geometry.diagrams import strokes_from_scene
        from ..scene import read_scene_yaml

        try:
            scene = mk.parse_scene(read_scene_yaml(msg.data))
            bounds, strokes = scene_bounds(scene), strokes_from_scene(scene)
        except mk.MechKinematicsError as error:
            with self.latest.lock:
                self.latest.scene_error = f'the scene the node published cannot be read: {error}'
            return
        with self.latest.lock:
            self.latest.scene, self.latest.bounds, self.latest.strokes = scene, bounds, strokes
            self.latest.scene_error = ''
            self.latest.traces = {}

    def _on_joints(self, msg: Any) -> None:
        with self.latest.lock:
            self.latest.joints = (list(msg.name), list(msg.position), list(msg.velocity))
            self.latest.stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9

    def _on_points(self, msg: Any) -> None:
        if not msg.points:
            return
        point = msg.points[0]
        out = {}
        for i, name in enumerate(msg.joint_names):
            p, v = point.transforms[i].translation, point.velocities[i].linear
            a = point.accelerations[i].linear
            out[name] = [[p.x, p.y], [v.x, v.y], [a.x, a.y]]
        with self.latest.lock:
            self.latest.points = out
            ground = self.latest.scene.ground if self.latest.scene is not None else {}
            for name, (xy, _, _) in out.items():
                if name in ground:
                    continue    # a fixed point: nothing to trace
                self.latest.traces.setdefault(name, deque(maxlen=TRACE_LENGTH)).append(
                    (xy[0], xy[1]))

    def _on_diagnostics(self, msg: Any) -> None:
        statuses = [{'name': s.name, 'level': int.from_bytes(s.level, 'little')
                     if isinstance(s.level, bytes) else int(s.level), 'message': s.message}
                    for s in msg.status]
        values = {kv.key: kv.value for s in msg.status for kv in s.values}
        with self.latest.lock:
            self.latest.statuses, self.latest.values = statuses, values

    # -- HTTP ------------------------------------------------------------------

    def state(self) -> dict[str, Any]:
        """Return the JSON of ``/state``: the frame to draw, the points, traces and statuses."""
        import mech_kinematics as mk

        with self.latest.lock:
            latest = self.latest
            scene, joints, strokes = latest.scene, latest.joints, dict(latest.strokes)
            out: dict[str, Any] = {
                'scene': scene.name if scene is not None else None,
                'scene_error': latest.scene_error, 'bounds': latest.bounds,
                'stamp': latest.stamp, 'points': dict(latest.points),
                'traces': {name: list(trace) for name, trace in latest.traces.items()},
                'statuses': list(latest.statuses),
                'crank_speed_rpm': None, 'frame': None, 'error': ''}
            values = dict(latest.values)
        if 'crank_speed' in values:
            out['crank_speed_rpm'] = float(values['crank_speed']) * 60.0 / (2.0 * math.pi)
        if scene is not None and joints is not None:
            by_name = {n: (p, v) for n, p, v in zip(*joints, strict=False)}
            crank = scene.input.link
            if crank in by_name:
                angle, speed = by_name[crank]
                out['crank_speed_rpm'] = speed * 60.0 / (2.0 * math.pi)
                try:
                    out['frame'] = frame_from_state(scene, angle, speed, strokes)
                except mk.AssemblyError as error:
                    out['error'] = str(error)
        return out

    def set_speed(self, rpm: float) -> dict[str, Any]:
        """Ask the node to set ``crank_speed_rpm``; return {'successful', 'reason'}."""
        from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
        from rcl_interfaces.srv import SetParameters

        if not self._set_parameters.wait_for_service(timeout_sec=SERVICE_TIMEOUT_S):
            return {'successful': False, 'reason': 'the node does not answer set_parameters'}
        request = SetParameters.Request(parameters=[Parameter(
            name='crank_speed_rpm', value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE,
                                                         double_value=float(rpm)))])
        done = threading.Event()
        future = self._set_parameters.call_async(request)
        future.add_done_callback(lambda _future: done.set())
        if not done.wait(SERVICE_TIMEOUT_S):
            return {'successful': False, 'reason': 'no answer from set_parameters in time'}
        result = future.result().results[0]
        return {'successful': bool(result.successful), 'reason': result.reason}


def _bind(port: int, view: ViewServer) -> http.server.ThreadingHTTPServer:
    handler = type('Handler', (_Handler,), {'view': view})
    try:
        return http.server.ThreadingHTTPServer((HOST, port), handler)
    except OSError:
        return http.server.ThreadingHTTPServer((HOST, 0), handler)


class _Handler(http.server.BaseHTTPRequestHandler):
    view: ViewServer

    def log_message(self, format: str, *args: Any) -> None:  # noqa: A002 - the base's name
        """Log nothing per request (the console belongs to the live view)."""

    def _send(self, body: bytes, content_type: str, status: int = 200) -> None:
        self.send_response(status)
        self.send_header('Content-Type', content_type)
        self.send_header('Content-Length', str(len(body)))
        self.send_header('Cache-Control', 'no-store')
        self.end_headers()
        self.wfile.write(body)

    def _json(self, data: Any, status: int = 200) -> None:
        self._send(json.dumps(data, allow_nan=False).encode(), 'application/json', status)

    def do_GET(self) -> None:
        """Serve the page and ``/state``."""
        path = urlparse(self.path).path
        if path == '/':
            self._send(PAGE.encode(), 'text/html; charset=utf-8')
        elif path == '/state':
            self._json(self.view.state())
        else:
            self._json({'error': f'Expected / or /state, got {path}'}, 404)

    def do_POST(self) -> None:
        """``/speed?rpm=X``: set the node's crank speed."""
        url = urlparse(self.path)
        if url.path != '/speed':
            self._json({'error': f'Expected /speed, got {url.path}'}, 404)
            return
        text = parse_qs(url.query).get('rpm', [''])[0]
        try:
            rpm = float(text)
        except ValueError:
            rpm = math.nan
        if not math.isfinite(rpm):
            self._json({'successful': False,
                        'reason': f'Expected a number of rpm, got {text!r}'}, 400)
            return
        self._json(self.view.set_speed(rpm))


PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>mech_kinematics view</title>
<style>
body { font: 14px sans-serif; margin: 0; display: flex; flex-direction: column; height: 100vh; }
header { padding: 6px 10px; background: #eee; display: flex; gap: 16px; align-items: center;
         flex-wrap: wrap; }
canvas { flex: 1; width: 100%; min-height: 0; background: #fff; }
/* two lines, always: a status whose text wraps differently must not move the drawing */
#status { flex-basis: 100%; line-height: 1.2em; height: 2.4em; overflow: hidden; }
#status span { margin-right: 12px; }
.l0 { color: #1a7f37; } .l1 { color: #b35900; } .l2 { color: #c00; } .l3 { color: #777; }
#drawn { display: none; }
</style></head><body>
<header>
<b id="scene">waiting for the node's scene...</b>
<label>crank speed <input id="rpm" type="number" step="10" style="width: 7em"> rpm
<button id="set">set</button></label> <span id="answer"></span>
<label><input id="arrows" type="checkbox"> velocity and acceleration arrows</label>
<span id="speed"></span>
<div id="status"></div>
</header>
<canvas id="c"></canvas>
<pre id="drawn"></pre>
<script>
'use strict';
const COLOURS = {crank: '#d62728', link: '#1f77b4', lever: '#2ca02c'};
const canvas = document.getElementById('c');
const ctx = canvas.getContext('2d');
let busy = false;

// ?w=800&h=500 fixes the canvas size in pixels (default: the window's free space).
const query = new URLSearchParams(location.search);
if (query.get('w') && query.get('h')) {
  canvas.style.flex = 'none';
  canvas.style.width = query.get('w') + 'px'; canvas.style.height = query.get('h') + 'px';
}

function transform(bounds) {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  canvas.width = w; canvas.height = h;
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

function draw(s) {
  document.getElementById('scene').textContent = s.scene ?
    s.scene + (s.error ? ': ' + s.error : '') : (s.scene_error || 'waiting for the node...');
  document.getElementById('speed').textContent = s.crank_speed_rpm === null ? '' :
    'running at ' + s.crank_speed_rpm.toFixed(2) + ' rpm';
  document.getElementById('status').innerHTML = s.statuses.map(
    (x) => '<span class="l' + x.level + '">' + x.name.split(': ').pop() + ': ' +
           x.message.replace(/&/g, '&amp;').replace(/</g, '&lt;') + '</span>').join('');
  if (!s.bounds) return;
  const t = transform(s.bounds);
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  // Scale bar: a round length near a fifth of the width.
  const m = canvas.width / 5 / t.k, bar = Math.pow(10, Math.floor(Math.log10(m)));
  ctx.fillStyle = '#000'; ctx.fillRect(10, canvas.height - 14, bar * t.k, 3);
  ctx.fillText(String(+(bar * 1000).toPrecision(1)) + ' mm', 10, canvas.height - 18);
  for (const [name, trace] of Object.entries(s.traces)) {
    if (trace.length < 2) continue;
    ctx.strokeStyle = '#bbb'; ctx.lineWidth = 1; ctx.beginPath();
    ctx.moveTo(...t.px(trace[0]));
    for (const p of trace) ctx.lineTo(...t.px(p));
    ctx.stroke();
  }
  // What was drawn, in metres and as the canvas maps them to pixels (read by the tests).
  const box = canvas.getBoundingClientRect();
  const f = s.frame, drawn = {angle: null, k: t.k, ox: t.ox, oy: t.oy, left: box.left,
                              top: box.top, links: []};
  if (f) {
    drawn.angle = f.angle;
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
  if (document.getElementById('arrows').checked) {
    const size = (s.bounds[2] - s.bounds[0]) / 10;
    for (const [name, [p, v, a]] of Object.entries(s.points)) {
      const sv = Math.hypot(...v), sa = Math.hypot(...a);
      if (sv > 0) line(t, p, [p[0] + v[0] / sv * size, p[1] + v[1] / sv * size], '#9467bd', 2);
      if (sa > 0) line(t, p, [p[0] + a[0] / sa * size, p[1] + a[1] / sa * size], '#8c564b', 2);
    }
  }
  for (const [name, [p]] of Object.entries(s.points)) {
    ctx.fillStyle = '#000'; ctx.fillText(name, ...t.px(p).map((c) => c + 6));
  }
  document.getElementById('drawn').textContent = JSON.stringify(drawn);
}

async function poll() {
  if (busy) return;
  busy = true;
  try { draw(await (await fetch('/state')).json()); } catch (e) { }
  busy = false;
}

document.getElementById('set').onclick = async () => {
  const rpm = document.getElementById('rpm').value;
  const r = await (await fetch('/speed?rpm=' + encodeURIComponent(rpm), {method: 'POST'})).json();
  document.getElementById('answer').textContent = r.successful ? 'set' : r.reason;
};
setInterval(poll, 50);
poll();
</script></body></html>
"""


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
