# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The browser view: its frames, its door and its page in a real browser (issues 20 and 33).

Two kinds of server are tested. A *real* one: a node and a ``view`` process
(quick_return, and five_bar for several drivers), reached over HTTP and in
Debian's chromium headless (its page read and shot over DevTools): the drawn
links lie where the solver puts them at the node's crank angle, in the
links' colours, and each driver's speed control sets the node's parameter.
A *fake* one: :class:`~mech_kinematics.tools.view.ViewServer` on a stand-in
node whose ``set_parameters`` client records what it is asked, fed real ROS
messages by hand: what any node on the graph may publish (HTML in a status
name, text where a number belongs, NaN, a gap in the points) and every
packaged scene. One chromium (:class:`_Chromium`, DevTools over a pipe) loads
those pages, and a hostile page on another port that tries every way a
browser has to drive ``/speed`` and read ``/state``. Without chromium the
browser tests are skipped, except under CI (``CI=true``), where they fail.
See issue 33 for the door, the escaping, the several drivers, the scale and
the gaps.
"""

import base64
import http.client
import http.server
import io
import json
import math
import os
from pathlib import Path
import random
import re
import select
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request

import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.geometry.diagrams import strokes_from_scene
from mech_kinematics.geometry.instant_centres import full_scene
from mech_kinematics.tools.view import (frame_from_state, PAGE, scene_bounds, TOKEN_HEADER,
                                        ViewServer)
from mech_kinematics.units import rad_per_s_from_rpm, rpm_from_rad_per_s

REPO = Path(__file__).resolve().parents[2]
SCENES = sorted(path.stem for path in (REPO / 'config' / 'scenes').glob('*.yaml'))
STARTUP_S = 30.0
#: How long a page in chromium may take to do what a test waits for, s.
PAGE_S = 20.0
#: Frames against the solver: the same computation, exact up to rounding, m.
ATOL_FRAME = 1e-12
#: Half the diagonal of a slider block as the page draws it (32 x 18 px), plus a margin.
BLOCK_HALF_DIAGONAL_PX = 22.0
#: A link (6 px wide) drawn over another hides it this far from its centre line, plus a margin.
LINK_COVER_PX = 6.0
#: A point's dot and its name (drawn 6 px right of and below it, over the links) hide a link
#: this far from the point, px.
POINT_COVER_PX = 20.0
#: A circle drawn to scale is as wide as it is tall, to the pixel grid and the line's width.
ATOL_ROUND_PX = 2.0
#: A pixel is background where every channel is at least this (a 1 px #bbb line is darker).
WHITE = 245
#: The published points' period in the fake streams, ns (100 Hz).
PERIOD_NS = 10_000_000
WINDOW = (900, 700)
COMMON_FLAGS = ('--headless', '--no-sandbox', '--disable-gpu', '--disable-quic',
                '--no-first-run', '--disable-background-networking',
                '--disable-component-update', '--disable-sync',
                f'--window-size={WINDOW[0]},{WINDOW[1]}')
CHROMIUM_FLAGS = (*COMMON_FLAGS, '--virtual-time-budget=8000')


@pytest.mark.parametrize('name', ['khurmi_four_bar_ad150', 'quick_return', 'six_link_slider'])
def test_frame_outlines_run_through_the_solved_points(name):
    """Every link's outline passes through its points where mk.solve puts them."""
    scene = mk.load_scene(name)
    angle = scene.input.angle + 0.7
    frame = frame_from_state(scene, angle, scene.input.speed, strokes_from_scene(scene))
    state = mk.solve(full_scene(scene), angle)
    for point, (p, _, _) in state.complex_points.items():
        np.testing.assert_allclose(frame['points'][point], [p.real, p.imag], rtol=0,
                                   atol=ATOL_FRAME)
    assert {link['name'] for link in frame['links']} >= {scene.input.link}
    crank = next(link for link in frame['links'] if link['name'] == scene.input.link)
    ends = {tuple(np.round(xy, 12)) for xy in crank['outline']}
    b = state.complex_points[scene.input.point][0]
    assert (round(b.real, 12), round(b.imag, 12)) in ends


def test_a_frame_of_several_drivers_is_solved_at_every_drivers_position():
    """five_bar's frame puts P where mk.solve puts it at both cranks' positions (issue 33)."""
    scene = mk.load_scene('five_bar')
    positions = [2.0, 0.9]
    frame = frame_from_state(scene, positions, [0.0, 0.0], {})
    state = mk.solve(full_scene(scene), positions, [0.0, 0.0], [0.0, 0.0])
    p = state.complex_points['P'][0]
    np.testing.assert_allclose(frame['points']['P'], [p.real, p.imag], rtol=0, atol=ATOL_FRAME)
    assert frame['positions'] == positions
    with pytest.raises(ValueError, match=r'Expected one position and one speed per driver '
                                         r'\(2\), got 1 and 2'):
        frame_from_state(scene, [2.0], [0.0, 0.0], {})


def test_bounds_hold_every_point_over_a_turn():
    """The drawing's fixed bounds hold every point at every crank angle."""
    scene = mk.load_scene('whitworth')
    x0, y0, x1, y1 = scene_bounds(scene)
    state = mk.solve(full_scene(scene), np.linspace(0, 2 * math.pi, 1000))
    for position, _, _ in state.complex_points.values():
        z = np.asarray(position)[state.valid]
        assert (x0 < z.real).all() and (z.real < x1).all()
        assert (y0 < z.imag).all() and (z.imag < y1).all()


@pytest.mark.parametrize('name', ['five_bar', 'excavator'])
def test_bounds_of_several_drivers_hold_every_point_they_reach(name):
    """Bounds of a scene of several drivers hold every point on a finer grid (issue 33).

    They raised "Expected `positions` to hold 2 values" (a crank turn solved
    as one driver), and the page never loaded.
    """
    scene = mk.load_scene(name)
    x0, y0, x1, y1 = scene_bounds(scene)
    axes = []
    for driver in scene.drivers:
        if driver.joint_type == 'revolute':
            axes.append(np.linspace(0, 2 * math.pi, 300))
        else:
            axes.append(np.linspace(*driver.stroke, 300))
    grid = [axis.ravel() for axis in np.meshgrid(*axes, indexing='ij')]
    zeros = [np.zeros_like(grid[0])] * len(grid)
    state = mk.solve(full_scene(scene), grid, zeros, zeros)
    assert state.valid.mean() > 0.9
    for position, _, _ in state.complex_points.values():
        z = np.asarray(position)[state.valid]
        assert (x0 < z.real).all() and (z.real < x1).all()
        assert (y0 < z.imag).all() and (z.imag < y1).all()


def test_the_page_fetches_nothing_from_the_internet():
    """The page loads no script, style, font or image from anywhere but its own server."""
    assert not re.search(r'(src|href)\s*=|https?://|@import|url\(', PAGE)


def test_the_page_is_one_document_under_10_kb():
    """The page served, its token in it, is under 10 kB (docs/view.md says so)."""
    from mech_kinematics.tools.view import _page

    assert len(_page('x' * 43).encode()) < 10_000


def test_the_page_puts_nothing_into_html():
    """The page's script never parses a string as HTML (issue 33: a status name ran script)."""
    assert not re.search(r'innerHTML|outerHTML|insertAdjacentHTML|document\.write|eval\(', PAGE)


def test_a_bad_port_is_one_line_and_status_2(capsys):
    """`view --port abc` says what it expected in one line, before ROS starts."""
    from mech_kinematics.tools import view

    assert view.main(['--port', 'abc', '--ros-args', '-r', '__ns:=/x']) == 2
    assert capsys.readouterr().err == "error: --port: expected a port number 0..65535, got 'abc'\n"


def _chromium():
    path = shutil.which('chromium') or shutil.which('chromium-browser')
    if path is None:
        if os.environ.get('CI') == 'true':
            pytest.fail('chromium is not installed: .ci/run installs it (apt-get install '
                        'chromium)')
        pytest.skip('chromium is not installed (apt-get install chromium)')
    return path


@pytest.mark.parametrize('ci, outcome', [('true', pytest.fail.Exception),
                                         ('', pytest.skip.Exception)])
def test_missing_chromium_fails_under_ci_and_skips_elsewhere(monkeypatch, ci, outcome):
    """With CI=true a missing chromium fails the browser test; elsewhere it is skipped."""
    monkeypatch.setattr(shutil, 'which', lambda name: None)
    monkeypatch.setenv('CI', ci)
    with pytest.raises(outcome, match='chromium is not installed'):
        _chromium()


def _until(predicate, timeout, what):
    """Return ``predicate()`` once it is true; fail naming ``what`` after ``timeout`` s."""
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            pytest.fail(f'timed out after {timeout} s waiting for {what}')
        time.sleep(0.02)


def _browse(chromium, url, *what):
    with tempfile.TemporaryDirectory() as profile:
        result = subprocess.run([chromium, *CHROMIUM_FLAGS, f'--user-data-dir={profile}',
                                 *what, url], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    return result.stdout


def _image(png):
    import matplotlib.image

    return (matplotlib.image.imread(io.BytesIO(png), format='png')[..., :3] * 255).round(
    ).astype(int)


class _Chromium:
    """One headless chromium driven over DevTools on a pipe (``--remote-debugging-pipe``).

    The protocol's JSON messages, each ended by a NUL byte, go to the
    browser's fd 3 and come back on its fd 4: no port, no websocket.
    """

    def __init__(self, path, profile):
        theirs_in, ours_out = os.pipe()
        ours_in, theirs_out = os.pipe()

        def pipes():    # in the child, before exec: the pipes as its fds 3 and 4
            a, b = os.dup(theirs_in), os.dup(theirs_out)
            os.dup2(a, 3)
            os.dup2(b, 4)
            os.set_inheritable(3, True)
            os.set_inheritable(4, True)

        self.proc = subprocess.Popen(
            [path, *COMMON_FLAGS, '--remote-debugging-pipe', f'--user-data-dir={profile}',
             'about:blank'], preexec_fn=pipes, close_fds=False,     # noqa: PLW1509
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        os.close(theirs_in)
        os.close(theirs_out)
        self.out, self.inp, self.buffer, self.sent = ours_out, ours_in, b'', 0

    def send(self, method, params=None, session=None):
        """Send one command; return its result (fail on the browser's error or silence)."""
        self.sent += 1
        message = {'id': self.sent, 'method': method, 'params': params or {}}
        if session is not None:
            message['sessionId'] = session
        os.write(self.out, json.dumps(message).encode() + b'\0')
        deadline = time.monotonic() + PAGE_S
        while True:
            while b'\0' not in self.buffer:
                left = max(0.0, deadline - time.monotonic())
                ready, _, _ = select.select([self.inp], [], [], left)
                chunk = os.read(self.inp, 1 << 20) if ready else b''
                assert chunk, f'chromium did not answer {method}'
                self.buffer += chunk
            raw, self.buffer = self.buffer.split(b'\0', 1)
            answer = json.loads(raw)
            if answer.get('id') == self.sent:
                assert 'error' not in answer, (method, answer['error'])
                return answer['result']

    def open(self, url):
        """Open ``url`` in a new tab; return (target, session)."""
        target = self.send('Target.createTarget', {'url': url})['targetId']
        session = self.send('Target.attachToTarget', {'targetId': target,
                                                      'flatten': True})['sessionId']
        return target, session

    def close_tab(self, target):
        """Close a tab."""
        self.send('Target.closeTarget', {'targetId': target})

    def evaluate(self, session, expression, *, loading=False):
        """Return the value of a JavaScript expression in the tab (promises awaited).

        ``loading``: an exception (the page not there yet) is None, not a failure.
        """
        result = self.send('Runtime.evaluate', {'expression': expression, 'returnByValue': True,
                                                'awaitPromise': True}, session)
        if 'exceptionDetails' in result and loading:
            return None
        assert 'exceptionDetails' not in result, result['exceptionDetails']
        return result['result'].get('value')

    def wait(self, session, expression, what):
        """Return the expression's value once it is truthy in the tab (loaded or not yet)."""
        return _until(lambda: self.evaluate(session, expression, loading=True), PAGE_S, what)

    def screenshot(self, session):
        """Return the tab's pixels (rows, columns, RGB 0-255)."""
        png = self.send('Page.captureScreenshot', {'format': 'png'}, session)['data']
        return _image(base64.b64decode(png))

    def close(self):
        """Close the browser."""
        try:
            self.send('Browser.close')
        finally:
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
            os.close(self.out)
            os.close(self.inp)


@pytest.fixture(scope='module')
def browser(tmp_path_factory):
    """One headless chromium for the module's pages (the fake server's and the real view's)."""
    chromium = _Chromium(_chromium(), tmp_path_factory.mktemp('chromium'))
    try:
        yield chromium
    finally:
        chromium.close()


# -- A fake server: the view on a stand-in node, fed real messages by hand ------------------

class _Logger:
    def __init__(self):
        self.warnings = []

    def warning(self, message, **_):
        self.warnings.append(message)


class _Done:
    def __init__(self, response):
        self.response = response

    def add_done_callback(self, callback):
        callback(self)

    def result(self):
        return self.response


class _Parameters:
    """A set_parameters client that records each request and accepts it."""

    def __init__(self):
        self.requests = []

    def wait_for_service(self, timeout_sec):
        return True

    def call_async(self, request):
        from rcl_interfaces.msg import SetParametersResult
        from rcl_interfaces.srv import SetParameters

        self.requests.append([(p.name, p.value.double_value) for p in request.parameters])
        return _Done(SetParameters.Response(results=[SetParametersResult(successful=True)]))


class _Node:
    """What ViewServer asks of its node; the set_parameters client records (a fake setter)."""

    def __init__(self):
        self.parameters = _Parameters()
        self.logger = _Logger()

    def create_subscription(self, *_args):
        return None

    def create_client(self, *_args):
        return self.parameters

    def get_namespace(self):
        return '/'

    def get_logger(self):
        return self.logger


@pytest.fixture
def fake():
    """Serve the view on a stand-in node (``fake.node.parameters.requests``: what was set)."""
    server = ViewServer(_Node(), 0)
    try:
        yield server
    finally:
        server.close()


def _scene(server, name):
    from std_msgs.msg import String

    server._on_scene(String(data=(REPO / 'config' / 'scenes' / f'{name}.yaml').read_text()))
    assert server.latest.scene is not None, server.latest.scene_error
    return server.latest.scene


def _joints(server, names, positions, velocities=(), efforts=()):
    from sensor_msgs.msg import JointState

    server._on_joints(JointState(name=list(names), position=list(positions),
                                 velocity=list(velocities), effort=list(efforts)))


def _points(server, stamp_ns, points):
    """Publish ``points`` ({name: (x, y)}) stamped ``stamp_ns``, as the node does."""
    from geometry_msgs.msg import Transform, Twist, Vector3
    from trajectory_msgs.msg import MultiDOFJointTrajectory, MultiDOFJointTrajectoryPoint

    msg = MultiDOFJointTrajectory(joint_names=list(points), points=[MultiDOFJointTrajectoryPoint(
        transforms=[Transform(translation=Vector3(x=float(x), y=float(y)))
                    for x, y in points.values()],
        velocities=[Twist() for _ in points], accelerations=[Twist() for _ in points])])
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp_ns, 1_000_000_000)
    server._on_points(msg)


def _diagnostics(server, *statuses):
    """Publish statuses (name, level, message, {key: value})."""
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

    server._on_diagnostics(DiagnosticArray(status=[DiagnosticStatus(
        name=name, level=bytes([level]), message=message,
        values=[KeyValue(key=k, value=v) for k, v in values.items()])
        for name, level, message, values in statuses]))


def _request(server, method, path, headers=None, body=None, address='127.0.0.1'):
    """Return (status, headers, body text) of a raw request; Host is the server's own."""
    connection = http.client.HTTPConnection(address, server.port, timeout=10)
    host = f'[{address}]' if ':' in address else address
    try:
        connection.request(method, path, body=body, headers={
            'Host': f'{host}:{server.port}', **(headers or {})})
        response = connection.getresponse()
        return response.status, dict(response.getheaders()), response.read().decode()
    finally:
        connection.close()


def _state(server):
    status, _, body = _request(server, 'GET', '/state', {TOKEN_HEADER: server.token})
    assert status == 200, body
    return json.loads(body)


def _speed(server, body, headers=None):
    status, _, text = _request(server, 'POST', '/speed', {
        TOKEN_HEADER: server.token, 'Content-Type': 'application/json', **(headers or {})},
        json.dumps(body))
    return status, text


# -- The door (issue 33) -------------------------------------------------------------------

@pytest.mark.parametrize('host', ['rebind.example:{port}', '127.0.0.1.nip.io:{port}',
                                  '127.0.0.1:1', '127.0.0.1', 'localhost:{port}.evil'])
def test_a_foreign_host_is_refused_with_one_line(fake, host):
    """A Host that is not this server (a DNS-rebinding name) gets 403 and one line, no token."""
    _scene(fake, 'khurmi_four_bar_ad150')
    host = host.format(port=fake.port)
    for method, path, body in (('GET', '/', None), ('GET', '/state', None),
                               ('POST', '/speed', json.dumps({'value': 4242}))):
        status, _, text = _request(fake, method, path, {
            'Host': host, TOKEN_HEADER: fake.token, 'Content-Type': 'application/json'}, body)
        assert status == 403, (method, path, text)
        assert text == (f'Expected Host 127.0.0.1:{fake.port} or localhost:{fake.port} or '
                        f'[::1]:{fake.port}, got {host!r}\n')
        assert fake.token not in text
    assert fake.node.parameters.requests == []
    assert len(fake.refusals) == 3


def _has_ipv6_loopback():
    try:
        with socket.socket(socket.AF_INET6) as probe:
            probe.bind(('::1', 0))
    except OSError:
        return False
    return True


def test_the_view_answers_on_ipv6s_loopback_too(fake):
    """The docs let `Host: [::1]:PORT` in: something listens there (nothing did, issue 42)."""
    if not _has_ipv6_loopback():
        assert f'[::1]:{fake.port}' not in fake.hosts    # not let in where it is not served
        pytest.skip('no IPv6 loopback on this machine')
    _scene(fake, 'khurmi_four_bar_ad150')
    status, _, page = _request(fake, 'GET', '/', address='::1')
    assert status == 200 and f'content="{fake.token}"' in page
    status, _, body = _request(fake, 'GET', '/state', {TOKEN_HEADER: fake.token}, address='::1')
    assert status == 200 and json.loads(body)['scene'] == 'khurmi_four_bar_ad150'


def test_a_speed_is_shown_without_the_conversions_last_bit(fake):
    """The default -120 rpm, published as rad/s, is shown as -120 rpm (not -119.99999999999999)."""
    _scene(fake, 'khurmi_four_bar_ad150')
    speed = rad_per_s_from_rpm(-120.0)
    assert rpm_from_rad_per_s(speed) == -119.99999999999999     # the conversion's last bit
    _joints(fake, ['crank'], [0.5], [speed])
    state = _state(fake)
    assert state['crank_speed_rpm'] == -120.0 and state['drivers'][0]['speed'] == -120.0
    _joints(fake, ['crank'], [0.5], [rad_per_s_from_rpm(1e-160)])
    assert _state(fake)['crank_speed_rpm'] == pytest.approx(1e-160, rel=1e-15)


@pytest.mark.parametrize('host', ['127.0.0.1:{port}', 'LOCALHOST:{port}', '[::1]:{port}'])
def test_the_servers_own_host_names_are_let_in(fake, host):
    """127.0.0.1, localhost and [::1] at the server's port get the page, with this run's token."""
    status, headers, page = _request(fake, 'GET', '/', {'Host': host.format(port=fake.port)})
    assert status == 200
    assert f'<meta name="view-token" content="{fake.token}">' in page
    assert "frame-ancestors 'none'" in headers['Content-Security-Policy']


def test_state_and_speed_need_this_runs_token(fake):
    """/state and /speed answer only with the page's token (403 and one line otherwise)."""
    _scene(fake, 'khurmi_four_bar_ad150')
    for headers, said in (({}, 'got none'), ({TOKEN_HEADER: 'guess'}, 'got another'),
                          ({TOKEN_HEADER: fake.token[:-1]}, 'got another')):
        status, _, text = _request(fake, 'GET', '/state', headers)
        assert (status, text.count('\n')) == (403, 1) and said in text, text
        status, _, text = _request(fake, 'POST', '/speed', {
            **headers, 'Content-Type': 'application/json'}, json.dumps({'value': 4242}))
        assert (status, text.count('\n')) == (403, 1) and said in text, text
    assert fake.node.parameters.requests == []
    assert _state(fake)['scene'] == 'khurmi_four_bar_ad150'


def test_a_post_from_another_origin_is_refused_even_with_the_token(fake):
    """Origin or Sec-Fetch-Site of another page refuses a POST; none (a script here) is let in."""
    _scene(fake, 'khurmi_four_bar_ad150')
    for headers in ({'Origin': 'http://127.0.0.1:1'}, {'Origin': 'null'},
                    {'Origin': f'http://localhost:{fake.port}'},
                    {'Sec-Fetch-Site': 'same-site'}, {'Sec-Fetch-Site': 'cross-site'}):
        status, text = _speed(fake, {'value': 4242}, headers)
        assert status == 403 and text.startswith('Expected a request from the page of '
                                                 f'http://127.0.0.1:{fake.port}'), text
    assert fake.node.parameters.requests == []
    # The page's own origin, or no Origin at all (not a browser): the token is the door.
    assert _speed(fake, {'value': -45}, {'Origin': f'http://127.0.0.1:{fake.port}',
                                         'Sec-Fetch-Site': 'same-origin'}) == (
        200, '{"successful": true, "reason": ""}')
    assert _speed(fake, {'value': -46})[0] == 200
    assert fake.node.parameters.requests == [[('crank_speed_rpm', -45.0)],
                                             [('crank_speed_rpm', -46.0)]]


def test_speed_takes_only_a_json_body(fake):
    """/speed refuses a form's or text's body (what a cross-site form can send) and bad values."""
    _scene(fake, 'khurmi_four_bar_ad150')
    token = {TOKEN_HEADER: fake.token}
    for content_type in ('text/plain', 'application/x-www-form-urlencoded',
                         'multipart/form-data; boundary=x'):
        status, _, text = _request(fake, 'POST', '/speed', {
            **token, 'Content-Type': content_type}, '{"value": 4242}')
        assert (status, text) == (415, 'Expected Content-Type application/json, got '
                                       f'{content_type!r}\n')
    status, _, text = _request(fake, 'POST', '/speed?rpm=4242', token)
    assert status == 415
    for body, reason in (('{"value": "fast"}', 'Expected {"driver": NAME, "value": a number'),
                         ('{"value": NaN}', 'Expected {"driver": NAME, "value": a number'),
                         ('[4242]', 'Expected {"driver": NAME, "value": a number'),
                         ('{"value": 1e999}', 'Expected {"driver": NAME, "value": a number'),
                         ('{"driver": "rocker", "value": 5}',
                          "Expected a driver of the scene (crank), got 'rocker'")):
        status, _, text = _request(fake, 'POST', '/speed', {
            **token, 'Content-Type': 'application/json'}, body)
        assert json.loads(text)['reason'].startswith(reason), text
        assert json.loads(text)['successful'] is False
    assert fake.node.parameters.requests == []


@pytest.mark.parametrize('name, driver, value, parameter', [
    ('five_bar', 'left_crank', 12.0, 'crank_speed_rpm'),
    ('five_bar', 'right_crank', -7.5, 'inputs.right_crank.speed_rpm'),
    ('excavator', 'boom_cyl', 0.05, 'inputs.boom_cyl.speed'),
    ('excavator', 'stick_cyl', -0.1, 'inputs.stick_cyl.speed')])
def test_each_driver_has_its_speed_control(fake, name, driver, value, parameter):
    """/speed sets the named driver's parameter: rpm for a crank, m/s for an actuator."""
    _scene(fake, name)
    assert _speed(fake, {'driver': driver, 'value': value}) == (
        200, '{"successful": true, "reason": ""}')
    assert fake.node.parameters.requests == [[(parameter, value)]]


# -- What the graph publishes (issue 33) ---------------------------------------------------

def test_state_answers_whatever_the_graph_publishes(fake):
    """Text, NaN or missing values from another node: /state answers finite JSON, left out."""
    scene = _scene(fake, 'khurmi_four_bar_ad150')
    for value in ('fast', 'nan', 'inf', '', '1e999'):
        _diagnostics(fake, ('other: thing', 7, 'm', {'crank_speed': value}))
        state = _state(fake)
        assert state['crank_speed_rpm'] is None
        assert state['statuses'] == [{'name': 'other: thing', 'message': 'm', 'level': 3}]
    _diagnostics(fake, ('mech_kinematics: solver', 0, 'ok', {'crank_speed': '-1.0'}))
    assert _state(fake)['crank_speed_rpm'] == pytest.approx(-60 / (2 * math.pi), rel=1e-12)
    _points(fake, PERIOD_NS, {'B': (math.nan, 0.0), 'C': (0.1, math.inf), 'D': (0.15, 0.0)})
    assert _state(fake)['points'] == {'D': [[0.15, 0.0], [0.0, 0.0], [0.0, 0.0]]}
    _joints(fake, [scene.input.link], [math.nan], [1.0])
    state = _state(fake)
    assert (state['frame'], state['error']) == (
        None, 'Expected a finite position of crank in joint_states')
    _joints(fake, [scene.input.link, 'coupler'], [0.5])    # no velocity, a short position list
    state = _state(fake)
    assert state['frame']['positions'] == [0.5] and state['error'] == ''
    assert state['drivers'] == [{'name': 'crank', 'kind': 'crank', 'unit': 'rpm',
                                 'position': 0.5, 'speed': None, 'effort': None,
                                 'effort_of': 'crank', 'effort_unit': 'N m'}]
    _joints(fake, [scene.input.link], [0.5], [1.0], [math.nan])     # not finite: left out
    assert _state(fake)['drivers'][0]['effort'] is None


def _reactions(server, scene, angle):
    """Publish, as the node does, each joint's reaction at ``angle``; return mk.solve's forces."""
    from geometry_msgs.msg import WrenchStamped

    from mech_kinematics.ros.wrenches import reaction_wrench

    state = mk.solve(scene, angle, scene.drivers[0].speed, 0.0)
    for joint in scene.dynamics.graph.joints:
        fx, fy, tz = reaction_wrench(joint, state.forces, state)
        msg = WrenchStamped()
        msg.wrench.force.x, msg.wrench.force.y, msg.wrench.torque.z = fx, fy, tz
        server._on_reaction(joint.name, joint.at, msg)
    return state


def test_state_has_the_published_reactions_at_their_joints(fake):
    """A scene with forces: /state gives each published reaction at its joint's drawn point."""
    from geometry_msgs.msg import WrenchStamped

    scene = _scene(fake, 'engine')
    _joints(fake, ['crank'], [0.5], [1.0])
    state = _reactions(fake, scene, 0.5)
    answer = _state(fake)
    joints = {j.name: j for j in scene.dynamics.graph.joints}
    assert {r['name'] for r in answer['reactions']} == set(joints)
    for r in answer['reactions']:
        assert r['at'] == answer['frame']['points'][joints[r['name']].at]
        assert r['at'] == pytest.approx(list(_xy_of(state, joints[r['name']].at)), abs=1e-12)
    bad = WrenchStamped()
    bad.wrench.force.x = math.nan
    fake._on_reaction('C', 'C', bad)      # not finite: not drawn, and the page says so
    [c] = [r for r in _state(fake)['reactions'] if r['name'] == 'C']
    assert c['force'] is None
    _scene(fake, 'khurmi_four_bar_ad150')     # a scene without forces: none
    _joints(fake, ['crank'], [0.5], [1.0])
    assert _state(fake)['reactions'] == []


def test_state_draws_a_urdf_robot_from_its_joint_states(fake):
    """URDF mode: ``joint_states`` names the URDF's joints; each driver follows one (issue 44).

    The node's ``scene`` for the lift arm carries ``urdf_drivers`` (lower_arm
    follows lift_joint, the other way round); the frame is solved where
    ``Robot.solve`` puts every point. Its reactions, published in their child
    links' axes, are drawn in the plane through the scene's ``urdf_reactions``:
    each arrow, lifted back into the root frame by the loop's plane axes, is
    the published force turned by the child link's rotation in the test's own
    forward kinematics. A missing joint is named.
    """
    from geometry_msgs.msg import WrenchStamped
    from helpers import UrdfFk
    from std_msgs.msg import String

    from mech_kinematics.ros.robot_mode import load_source

    urdf = REPO / 'test' / 'data' / 'urdf' / 'lift_arm.urdf'
    source = load_source(str(urdf))
    fake._on_scene(String(data=source.text))
    assert fake.latest.scene is not None, fake.latest.scene_error
    answer = source.robot.solve({'lift_joint': 0.4}, {'lift_joint': 0.7})
    names = list(answer.joints)
    efforts = [answer.efforts.efforts.get(n, 0.0) for n in names]
    _joints(fake, names, [answer.joints[n].position for n in names],
            [answer.joints[n].velocity for n in names], efforts)
    at = {r.joint: r.at for r in fake.latest.scene.urdf_reactions}
    assert set(at) == set(answer.reactions) and len(fake._reaction_subscriptions) == len(at)
    for name, reaction in answer.reactions.items():
        msg = WrenchStamped()
        msg.wrench.force.x, msg.wrench.force.y, msg.wrench.force.z = reaction.force
        fake._on_reaction(name, at[name], msg)
    state = _state(fake)
    assert state['error'] == '' and state['frame'] is not None
    # The driver's effort is the URDF joint's it follows, in the URDF's sign (issue 44).
    assert state['drivers'] == [{'name': 'lower_arm', 'kind': 'crank', 'unit': 'rpm',
                                 'position': -0.4, 'speed': pytest.approx(
                                     -0.7 * 60 / (2 * math.pi), rel=1e-12),
                                 'effort': pytest.approx(answer.efforts.efforts['lift_joint'],
                                                         rel=1e-14),
                                 'effort_of': 'lift_joint', 'effort_unit': 'N m'}]
    for point, xy in state['frame']['points'].items():
        assert xy == pytest.approx(list(_xy_of(answer.state, point)), abs=1e-12), point
    assert state['statuses'] == []
    frames = UrdfFk(urdf.read_text()).transforms({n: j.position for n, j in answer.joints.items()})
    [m] = source.robot.planar.mechanisms     # its ground is the root: the plane's axes in it
    drawn = {r['name']: r for r in state['reactions']}
    assert set(drawn) == set(answer.reactions)
    for name, reaction in answer.reactions.items():
        fx, fy = drawn[name]['force']
        lifted = fx * np.asarray(m['x']) + fy * np.asarray(m['y'])
        expected = frames[reaction.frame][:3, :3] @ np.asarray(reaction.force)
        assert np.allclose(lifted, expected, rtol=0, atol=1e-12 * np.linalg.norm(expected)), name
        assert drawn[name]['at'] == state['frame']['points'][at[name]]
    assert max(np.linalg.norm(r.force) for r in answer.reactions.values()) > 10.0
    _joints(fake, ['elbow'], [0.1])
    assert _state(fake)['error'] == (
        'Expected a finite position of lift_joint (which lower_arm follows) in joint_states')
    _scene(fake, 'engine')      # a scene of its own: its reactions, in its plane
    assert _state(fake)['statuses'] == [] and fake._reaction_subscriptions


def _xy_of(state, point):
    z = state.complex_points[point][0]
    return z.real, z.imag


def test_a_frame_past_the_bounds_grows_them(fake):
    """Bounds grow to hold a frame that reaches past them: nothing is drawn off the canvas."""
    scene = _scene(fake, 'khurmi_four_bar_ad150')
    fake.latest.bounds = (0.0, 0.0, 1e-3, 1e-3)
    _joints(fake, [scene.input.link], [2.0], [0.0])
    state = _state(fake)
    x0, y0, x1, y1 = state['bounds']
    xy = np.array([*state['frame']['points'].values()])
    assert (x0 < xy[:, 0]).all() and (xy[:, 0] < x1).all()
    assert (y0 < xy[:, 1]).all() and (xy[:, 1] < y1).all()
    assert tuple(fake.latest.bounds) == (x0, y0, x1, y1)


def test_traces_break_where_the_stream_did(fake):
    """A gap in the stamps, a point missing, a clock set back: the trace holds a break (None)."""
    _scene(fake, 'khurmi_four_bar_ad150')
    for tick in [*range(0, 10), *range(30, 40)]:        # ticks 10 to 29 never published
        _points(fake, tick * PERIOD_NS, {'B': (tick, 0.0), 'C': (0.0, tick)})
    _points(fake, 40 * PERIOD_NS, {'B': (40, 0.0)})     # C not in this message
    _points(fake, 41 * PERIOD_NS, {'B': (41, 0.0), 'C': (0.0, 41)})
    _points(fake, 5 * PERIOD_NS, {'B': (5, 0.0), 'C': (0.0, 5)})   # the clock set back
    traces = _state(fake)['traces']
    b = [[t, 0.0] for t in range(10)] + [None] + [[t, 0.0] for t in range(30, 42)] + [
        None, [5, 0.0]]
    assert traces['B'] == b
    assert traces['C'] == [[0.0, t] for t in range(10)] + [None] + [
        [0.0, t] for t in range(30, 40)] + [None, [0.0, 41], None, [0.0, 5]]
    for tick in range(6, 16):       # a steady stream again: no break
        _points(fake, tick * PERIOD_NS, {'B': (tick, 0.0)})
    assert _state(fake)['traces']['B'][len(b):] == [[t, 0.0] for t in range(6, 16)]


# -- In chromium (issue 33) ----------------------------------------------------------------

def _drawn(chromium, session, what):
    """Return the page's record of what it drew once it has drawn a frame."""
    text = chromium.wait(session, "(() => { const d = document.getElementById('drawn')"
                                  '.textContent; return d && JSON.parse(d).angle !== null && d; '
                                  '})()', what)
    return json.loads(text)


def _edges(outline):
    """Return the edges the page draws of an outline: a closed polygon, or one segment."""
    outline = np.array(outline)
    ends = np.roll(outline, -1, axis=0)[:len(outline) if len(outline) > 2 else 1]
    return list(zip(outline, ends, strict=False))


def _distance(xy, a, b):
    """Return the distance from point ``xy`` to segment ``ab``."""
    span = b - a
    f = np.clip(np.dot(xy - a, span) / max(np.dot(span, span), 1e-300), 0.0, 1.0)
    return np.hypot(*(xy - (a + f * span)))


def _link_pixels(image, drawn, sliders=(), dots=()):
    """Return each link's (name, pixels sampled along its edges' middles, how many match).

    A pixel matches when it has the link's colour. Samples under something
    drawn over the link are left out: within a slider block's half-diagonal
    of its centre, within :data:`LINK_COVER_PX` of a link drawn after it
    (a crank that lies along its slotted lever at that instant), or within
    :data:`POINT_COVER_PX` of a point ``dots`` (its dot and name: quick
    return's E on its link CD).
    """
    k, ox, oy, top, left = (drawn[key] for key in ('k', 'ox', 'oy', 'top', 'left'))
    found = []
    links = drawn['links']
    for index, link in enumerate(links):
        count = hits = 0
        colour = [int(link['colour'][i:i + 2], 16) for i in (1, 3, 5)]
        over = [edge for later in links[index + 1:] for edge in _edges(later['outline'])]
        for a, b in _edges(link['outline']):
            for f in np.linspace(0.35, 0.65, 7):
                xy = a + f * (b - a)
                if any(k * np.hypot(*(xy - s)) <= BLOCK_HALF_DIAGONAL_PX for s in sliders) or \
                        any(k * _distance(xy, *edge) <= LINK_COVER_PX for edge in over) or \
                        any(k * np.hypot(*(xy - d)) <= POINT_COVER_PX for d in dots):
                    continue
                pixel = image[round(top + oy - k * xy[1]), round(left + ox + k * xy[0])]
                count += 1
                hits += int(np.abs(pixel - colour).max() <= 8)
        found.append((link['name'], count, hits))
    return found


def _assert_links_drawn(found, what):
    """Assert each link's visible samples have its colour, and that most samples were seen."""
    for link, count, hits in found:
        assert hits >= 0.8 * count, (what, link, count, hits)
    assert sum(count for _, count, _ in found) >= 3 * len(found), (what, found)


def test_chromium_draws_every_packaged_scene(fake, browser):
    """Each packaged scene, several drivers too, is drawn at its drivers' start positions.

    With the node on five_bar or excavator the view raised while sizing the
    drawing and the page never loaded (issue 33).
    """
    for name in SCENES:
        scene = _scene(fake, name)
        drivers = scene.drivers
        starts = [float(d.start) for d in drivers]
        _joints(fake, [d.name for d in drivers], starts, [0.0] * len(drivers))
        target, session = browser.open(fake.url)
        try:
            drawn = _drawn(browser, session, f'{name} drawn')
            image = browser.screenshot(session)
            controls = browser.evaluate(session, "[...document.querySelectorAll('input.speed')]"
                                                 '.map((e) => e.dataset.driver)')
        finally:
            browser.close_tab(target)
        assert drawn['positions'] == starts, name
        frame = frame_from_state(scene, starts, [0.0] * len(drivers), fake.latest.strokes)
        assert [link['name'] for link in drawn['links']] == [
            link['name'] for link in frame['links']], name
        _assert_links_drawn(_link_pixels(image, drawn, [np.array(s['xy'])
                                                        for s in frame['sliders']]), name)
        assert controls == [d.name for d in drivers], name


def test_chromium_draws_the_reactions_scaled_at_their_joints(fake, browser):
    """With "reactions" ticked, an arrow per joint along its force, the largest 1/5 of the view."""
    scene = _scene(fake, 'shaper')
    _joints(fake, ['crank'], [0.5], [1.0], [12.25])
    _reactions(fake, scene, 0.5)
    answer = _state(fake)
    target, session = browser.open(fake.url)
    try:
        _drawn(browser, session, 'shaper drawn')
        browser.evaluate(session, "document.getElementById('forces').click()")
        text = browser.wait(session, '(() => { const d = JSON.parse(document.getElementById('
                                     '"drawn").textContent); return d.reactions.length && '
                                     'JSON.stringify(d.reactions); })()', 'reactions drawn')
        # The driver's effort in joint_states, beside its speed (issue 44).
        running = browser.wait(session, "document.querySelector('.running').textContent",
                               'the running speed')
    finally:
        browser.close_tab(target)
    assert running.endswith(' crank 12.25 N m'), running
    drawn = {r['name']: r for r in json.loads(text)}
    published = {r['name']: r for r in answer['reactions']}
    assert set(drawn) == set(published)
    width = answer['bounds'][2] - answer['bounds'][0]
    largest = max(math.hypot(*r['force']) for r in published.values())
    for name, r in published.items():
        start, end = np.array(drawn[name]['from']), np.array(drawn[name]['to'])
        assert list(start) == r['at']
        np.testing.assert_allclose(end - start, np.array(r['force']) * width / 5 / largest,
                                   rtol=1e-9, atol=1e-12)


def _huge_points(server, stamp_ns, points):
    """Publish points ({name: ((x, y), velocity or None, acceleration)}) as the node does."""
    from geometry_msgs.msg import Transform, Twist, Vector3
    from trajectory_msgs.msg import MultiDOFJointTrajectory, MultiDOFJointTrajectoryPoint

    def twist(v):
        return Twist(linear=Vector3(x=math.nan, y=0.0) if v is None else
                     Vector3(x=float(v[0]), y=float(v[1])))

    msg = MultiDOFJointTrajectory(joint_names=list(points), points=[MultiDOFJointTrajectoryPoint(
        transforms=[Transform(translation=Vector3(x=float(p[0][0]), y=float(p[0][1])))
                    for p in points.values()],
        velocities=[twist(p[1]) for p in points.values()],
        accelerations=[twist(p[2]) for p in points.values()])])
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp_ns, 1_000_000_000)
    server._on_points(msg)


def test_chromium_draws_huge_forces_and_velocities_to_scale_and_says_what_it_cannot(
        fake, browser):
    """Reactions of 1.5e308 N draw to scale; a value not finite is named on the drawing.

    Math.hypot of [1.5e308, 1.5e308] is Infinity: every reaction arrow was drawn
    0 long, and a velocity that large too, with no word (issue 42).
    """
    from geometry_msgs.msg import WrenchStamped

    scene = _scene(fake, 'shaper')
    _joints(fake, ['crank'], [0.5], [1.0])
    forces = {}
    for joint, force in zip(scene.dynamics.graph.joints,
                            [(1.5e308, 1.5e308), (-1e308, 0.0), (3.0, -4.0), (math.inf, 0.0)],
                            strict=False):
        msg = WrenchStamped()
        msg.wrench.force.x, msg.wrench.force.y = force
        fake._on_reaction(joint.name, joint.at, msg)
        forces[joint.name] = force
    points = {name: (xy, [1.5e308, -1.5e308], None) for name, xy in
              ((n, _xy_of(mk.solve(scene, 0.5), n)) for n in scene.output_points)}
    _huge_points(fake, 1, points)
    answer = _state(fake)
    target, session = browser.open(fake.url)
    try:
        _drawn(browser, session, 'shaper drawn')
        browser.evaluate(session, "document.getElementById('forces').click()")
        browser.evaluate(session, "document.getElementById('arrows').click()")
        text = browser.wait(session, '(() => { const d = JSON.parse(document.getElementById('
                                     '"drawn").textContent); return d.reactions.length && '
                                     'd.arrows.length && JSON.stringify(d); })()', 'arrows drawn')
    finally:
        browser.close_tab(target)
    drawn = json.loads(text)
    width = answer['bounds'][2] - answer['bounds'][0]
    reactions = {r['name']: r for r in drawn['reactions']}
    finite = {name: f for name, f in forces.items() if math.isfinite(f[0])}
    assert set(reactions) == set(finite)
    # One scale: the largest, |[1.5e308, 1.5e308]| = 2.1e308 (beyond doubles), a fifth wide.
    largest = math.sqrt(2) * (1.5e308 / 1e300)
    for name, force in finite.items():
        r = reactions[name]
        expected = np.array(force) / 1e300 * width / 5 / largest
        np.testing.assert_allclose(np.array(r['to']) - np.array(r['from']), expected,
                                   rtol=1e-9, atol=1e-300)
    # Each velocity a tenth of the drawing wide along [1, -1]; no acceleration (not finite).
    velocities = [a for a in drawn['arrows'] if a['what'] == 'velocity']
    assert len(velocities) == len(points) and all(a['what'] == 'velocity' for a in drawn['arrows'])
    for a in velocities:
        np.testing.assert_allclose(np.array(a['to']) - np.array(a['from']),
                                   np.array([1.0, -1.0]) / math.sqrt(2) * width / 10, rtol=1e-9)
    [infinite] = [name for name, f in forces.items() if not math.isfinite(f[0])]
    assert drawn['undrawn'].startswith('not drawn (not finite): ')
    assert f'reaction at {infinite}' in drawn['undrawn']
    assert all(f'acceleration of {name}' in drawn['undrawn'] for name in points)


def test_chromium_shows_html_from_the_graph_as_text(fake, browser):
    """A status name holding an <img onerror> runs no script: the page shows it as text."""
    _scene(fake, 'khurmi_four_bar_ad150')
    name = ("<img src=x onerror=\"document.body.appendChild(document.createElement('hr'))"
            ".id='pwned'\">")
    _diagnostics(fake, (name, 2, '<b>bold</b> & co', {}))
    target, session = browser.open(fake.url)
    try:
        text = browser.wait(session, "document.getElementById('status').textContent",
                            'the status line')
        elements = browser.evaluate(session, "document.querySelectorAll('#status *').length")
        tags = browser.evaluate(session, "[...document.querySelectorAll('#status *')]"
                                         '.map((e) => e.tagName)')
        pwned = browser.evaluate(session, "document.getElementById('pwned') !== null")
    finally:
        browser.close_tab(target)
    assert text == f'{name}: <b>bold</b> & co'
    assert (elements, tags, pwned) == (1, ['SPAN'], False)


def test_chromium_traces_break_across_missing_samples(fake, browser):
    """A quarter turn not published leaves a gap in the trace, no chord across it."""
    _scene(fake, 'khurmi_four_bar_ad150')
    centre, radius = np.array([0.1, 0.03]), 0.03
    ticks = [t for t in range(400) if not 100 <= t < 200]      # 100 to 199 not published
    for t in ticks:
        angle = 2 * math.pi * t / 400
        _points(fake, t * PERIOD_NS, {'C': tuple(centre + radius * np.array(
            [math.cos(angle), math.sin(angle)]))})
    target, session = browser.open(fake.url)
    try:
        drawn = json.loads(browser.wait(session, "document.getElementById('drawn').textContent",
                                        'the traces drawn'))
        image = browser.screenshot(session)
    finally:
        browser.close_tab(target)
    k, ox, oy, top, left = (drawn[key] for key in ('k', 'ox', 'oy', 'top', 'left'))

    def pixel_at(xy):
        row, column = round(top + oy - k * xy[1]), round(left + ox + k * xy[0])
        return image[row - 1:row + 2, column - 1:column + 2].min()

    # The chord from the last sample before the gap to the first after it: background.
    a, b = (centre + radius * np.array([math.cos(2 * math.pi * t / 400),
                                        math.sin(2 * math.pi * t / 400)]) for t in (99, 200))
    chord = [pixel_at(a + f * (b - a)) for f in np.linspace(0.2, 0.8, 13)]
    assert min(chord) >= WHITE, chord
    # The trace itself is drawn, on both sides of the gap.
    arc = [pixel_at(centre + radius * np.array([math.cos(angle), math.sin(angle)]))
           for angle in (math.pi / 4 + 0.3, math.pi, 1.5 * math.pi)]
    assert max(arc) < WHITE, arc


def test_chromium_draws_to_equal_scale_at_the_default_size(fake):
    """At the window's own size a 40 mm circle is as wide as it is tall in the screenshot.

    The canvas's bitmap was sized for one layout and shown in another (a 40
    mm crank circle 359 x 402 px, issue 33): one metre must be as many
    pixels in x as in y.
    """
    chromium = _chromium()
    _scene(fake, 'khurmi_four_bar_ad150')
    for t in range(400):
        angle = 2 * math.pi * t / 400
        _points(fake, t * PERIOD_NS, {'B': (0.04 * math.cos(angle), 0.04 * math.sin(angle))})
    _points(fake, 400 * PERIOD_NS, {})     # no point now: no label beside the circle
    shot = Path(tempfile.mkdtemp()) / 'view.png'
    _browse(chromium, fake.url, f'--screenshot={shot}')
    image = _image(shot.read_bytes())
    import scipy.ndimage

    # The circle is the largest 8-connected set of the trace's greys (text is in pieces;
    # the header's #eee is lighter).
    grey = (np.abs(image - 0xbb) <= 40).all(axis=2) & (image < WHITE).any(axis=2)
    labels, _ = scipy.ndimage.label(grey, structure=np.ones((3, 3)))
    sizes = np.bincount(labels.ravel())
    sizes[0] = 0
    rows, columns = np.nonzero(labels == sizes.argmax())
    assert len(rows) > 100, ('no trace drawn', shot)
    height, width = np.ptp(rows) + 1, np.ptp(columns) + 1
    assert abs(width - height) <= ATOL_ROUND_PX, (width, height, shot)


def _hostile(view_url):
    """Return a page (another origin) that tries every way to drive /speed and read /state."""
    return f"""<!DOCTYPE html><html><body>
<iframe name="sink1"></iframe><iframe name="sink2"></iframe>
<form id="f1" method="POST" enctype="text/plain" target="sink1" action="{view_url}speed">
<input name='{{"driver": "crank", "value": 4242, "x": "' value='"}}'></form>
<form id="f2" method="POST" target="sink2" action="{view_url}speed?rpm=4242">
<input name="rpm" value="4242"></form>
<script>
const V = {json.dumps(view_url)}, results = {{}};
const body = JSON.stringify({{driver: 'crank', value: 4242}});
function attempt(name, promise) {{
  return promise.then((r) => r && r.text ? r.text() : String(r))
    .then((t) => {{ results[name] = 'read: ' + t; }}, (e) => {{ results[name] = 'error'; }});
}}
function xhr() {{
  return new Promise((resolve, reject) => {{
    const x = new XMLHttpRequest();
    x.open('POST', V + 'speed'); x.setRequestHeader('Content-Type', 'text/plain');
    x.onload = () => resolve(x.responseText); x.onerror = () => reject(new Error('xhr'));
    x.send(body);
  }});
}}
const forms = new Promise((resolve) => {{
  let loaded = 0;
  for (const sink of document.querySelectorAll('iframe'))
    sink.onload = () => {{ if (++loaded === 2) resolve('forms posted'); }};
  document.getElementById('f1').submit(); document.getElementById('f2').submit();
}});
Promise.all([
  attempt('old api', fetch(V + 'speed?rpm=4242', {{method: 'POST', mode: 'no-cors'}})),
  attempt('no-cors', fetch(V + 'speed', {{method: 'POST', mode: 'no-cors', body: body,
                                         headers: {{'Content-Type': 'text/plain'}}}})),
  attempt('json', fetch(V + 'speed', {{method: 'POST', body: body, headers: {{
    'Content-Type': 'application/json', 'X-View-Token': 'guess'}}}})),
  attempt('xhr', xhr()),
  attempt('state', fetch(V + 'state')),
  attempt('state no-cors', fetch(V + 'state', {{mode: 'no-cors'}})),
  attempt('forms', forms),
]).then(() => {{ window.done = JSON.stringify(results); }});
</script></body></html>"""


def test_chromium_refuses_a_hostile_page_and_lets_the_view_page_in(fake, browser):
    """A page on another origin cannot move the speed or read /state; the view's page can.

    It tries a form POST (text/plain, and the former ``?rpm=``), fetch
    (no-cors, and with JSON and a guessed token), XMLHttpRequest and reads
    of /state: a chromium page of another port moved a running node to 4242
    rpm (issue 33). Every request that reached the server was refused.
    """
    _scene(fake, 'khurmi_four_bar_ad150')
    page = _hostile(fake.url).encode()

    class Hostile(http.server.BaseHTTPRequestHandler):
        def do_GET(self):   # noqa: N802 - the base's name
            self.send_response(200)
            self.send_header('Content-Type', 'text/html')
            self.send_header('Content-Length', str(len(page)))
            self.end_headers()
            self.wfile.write(page)

        def log_message(self, *_args):
            pass

    hostile = http.server.ThreadingHTTPServer(('127.0.0.1', 0), Hostile)
    threading.Thread(target=hostile.serve_forever, daemon=True).start()
    try:
        target, session = browser.open(f'http://127.0.0.1:{hostile.server_address[1]}/')
        try:
            results = json.loads(browser.wait(session, 'window.done', 'the hostile attempts'))
        finally:
            browser.close_tab(target)
    finally:
        hostile.shutdown()
        hostile.server_close()
    assert results['state'] == 'error' and results['json'] == 'error', results
    assert not any('crank' in text or fake.token in text for text in results.values()), results
    # The no-cors fetches, the XHR and both forms reach the server, and are refused; the
    # JSON fetch is stopped at its preflight, the reads of /state at the door.
    refused = _until(lambda: [*fake.refusals] if sum(
        line.startswith('POST /speed: Expected a request from the page')
        for line in fake.refusals) == 5 else None, PAGE_S, 'the five POSTs to /speed')
    assert fake.node.parameters.requests == []
    assert any(line.startswith('OPTIONS /speed') for line in refused), refused
    assert any(line.startswith('GET /state: Expected a request from the page') for line in
               refused), refused
    assert all(line.count('\n') == 0 for line in refused)
    # The view's own page, in the same browser: its control sets the node's speed.
    target, session = browser.open(fake.url)
    try:
        browser.wait(session, "document.querySelector('input.speed') !== null",
                     'the speed control')
        browser.evaluate(session, "(() => { const i = document.querySelector('input.speed'); "
                                  "i.value = '-45'; i.parentElement.querySelector('button')"
                                  '.click(); })()')
        answer = browser.wait(session, "document.querySelector('.answer').textContent",
                              'the answer')
    finally:
        browser.close_tab(target)
    assert answer == 'set'
    assert fake.node.parameters.requests == [[('crank_speed_rpm', -45.0)]]


# -- A real node and a real view ------------------------------------------------------------

def _env():
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1',
               ROS_DOMAIN_ID=str(random.SystemRandom().randint(201, 230)))
    env['PYTHONPATH'] = os.pathsep.join(filter(None, [str(REPO), env.get('PYTHONPATH')]))
    return env


def _token(url):
    """Return the token the view's page carries (as a script on this machine may read it)."""
    with urllib.request.urlopen(url, timeout=10) as response:
        return re.search(r'<meta name="view-token" content="([^"]+)">', response.read().decode(
        ))[1]


def _post(url, body):
    request = urllib.request.Request(url + 'speed', data=json.dumps(body).encode(), method='POST',
                                     headers={TOKEN_HEADER: _token(url),
                                              'Content-Type': 'application/json'})
    try:
        with urllib.request.urlopen(request, timeout=10) as response:
            return json.load(response)
    except urllib.error.HTTPError as error:
        return json.load(error)


def _get(url):
    request = urllib.request.Request(url + 'state', headers={TOKEN_HEADER: _token(url)})
    with urllib.request.urlopen(request, timeout=10) as response:
        return json.load(response)


def _serve(tmp, scene):
    """Start a node on ``scene`` and a view attached to it; yield the view's URL."""
    env = _env()
    ns = f'/view_{os.getpid()}_{scene}'
    procs = []
    try:
        for name, argv in (('node', ['-m', 'mech_kinematics.kinematics_node']),
                           ('view', ['-m', 'mech_kinematics', 'view', '--port', '0'])):
            out = open(tmp / f'{name}.txt', 'w')     # noqa: SIM115 - closed with the process
            procs.append((subprocess.Popen(
                [sys.executable, *argv, '--ros-args', '-r', f'__ns:={ns}', '-p',
                 f'scene:={scene}'], env=env, stdout=out, stderr=subprocess.STDOUT),
                out, tmp / f'{name}.txt'))
        deadline = time.monotonic() + STARTUP_S
        log = procs[1][2]
        while not re.search(r'http://127\.0\.0\.1:\d+/', log.read_text()):
            assert time.monotonic() < deadline and procs[1][0].poll() is None, log.read_text()
            time.sleep(0.1)
        url = re.search(r'http://127\.0\.0\.1:\d+/', log.read_text())[0]
        while _get(url)['frame'] is None:
            assert time.monotonic() < deadline, ('no frame from the node', _get(url)['error'])
            time.sleep(0.2)
        yield url
    finally:
        for proc, out, _ in reversed(procs):
            if proc.poll() is None:
                proc.send_signal(signal.SIGINT)
                try:
                    proc.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    proc.wait()
            out.close()


@pytest.fixture(scope='module')
def running(tmp_path_factory):
    """Start a node (quick_return) and a view attached to it; yield (view URL, scene)."""
    yield from ((url, mk.load_scene('quick_return')) for url in _serve(
        tmp_path_factory.mktemp('view'), 'quick_return'))


def test_speed_control_sets_the_nodes_parameter(running):
    """POST /speed sets crank_speed_rpm on the node; a refused value comes back with its reason."""
    url, _ = running
    refused = _post(url, {'value': 1e9})
    assert refused == {'successful': False, 'reason': 'crank_speed_rpm: expected -100000 <= '
                       'value <= 100000 rpm, got 1000000000.0'}
    assert _post(url, {'value': 'abc'})['reason'].startswith(
        'Expected {"driver": NAME, "value": a number')
    assert _post(url, {'value': -45}) == {'successful': True, 'reason': ''}
    deadline = time.monotonic() + 10
    while _get(url)['crank_speed_rpm'] != pytest.approx(-45.0, rel=1e-12):
        assert time.monotonic() < deadline, _get(url)['crank_speed_rpm']
        time.sleep(0.1)


def test_speed_control_sets_each_driver_of_a_running_five_bar(tmp_path):
    """On a node with two cranks the view draws both and each control sets its own crank."""
    for url in _serve(tmp_path, 'five_bar'):
        state = _get(url)
        assert len(state['frame']['positions']) == 2
        assert [d['name'] for d in state['drivers']] == ['left_crank', 'right_crank']
        assert _post(url, {'driver': 'right_crank', 'value': 12}) == {'successful': True,
                                                                      'reason': ''}
        assert _post(url, {'driver': 'left_crank', 'value': -6}) == {'successful': True,
                                                                     'reason': ''}
        _until(lambda url=url: [d['speed'] for d in _get(url)['drivers']] == [
            pytest.approx(-6.0, rel=1e-12), pytest.approx(12.0, rel=1e-12)], 10,
            'both cranks at their new speeds')


def test_chromium_draws_the_links_where_the_solver_puts_them(running, browser):
    """In headless chromium the page draws each link, to scale, at the solver's positions."""
    url, scene = running
    assert _post(url, {'value': 0}) == {'successful': True, 'reason': ''}
    _until(lambda: _get(url)['crank_speed_rpm'] == 0.0, 10, 'the crank stopped')
    # The page's record of what it drew and the screenshot show one instant when the drawn
    # angle is the same before and after the screenshot (on a loaded machine the node may
    # still be taking the speed change, and the page draws each state it polls).
    target, session = browser.open(url + '?w=800&h=480')
    try:
        def one_instant():
            drawn = _drawn(browser, session, 'quick_return drawn')
            image = browser.screenshot(session)
            return (drawn, image) if _drawn(browser, session, 'quick_return drawn')[
                'angle'] == drawn['angle'] else None

        drawn, image = _until(one_instant, PAGE_S, 'one instant drawn and shot')
    finally:
        browser.close_tab(target)
    state = mk.solve(full_scene(scene), drawn['angle'])
    points = {n: np.array([p.real, p.imag]) for n, (p, _, _) in state.complex_points.items()}
    # The page's transform is to scale: one k (px/m) for both axes.
    assert drawn['k'] > 0
    levers = {d.link for d in scene.dyads if isinstance(d, mk.RPR)}
    for link in drawn['links']:
        for xy in link['outline']:
            # Every corner is a solved point (a slotted lever also reaches past its pin).
            gap = min(np.hypot(*(p - xy)) for p in points.values())
            assert gap <= ATOL_FRAME or link['name'] in levers, (link, gap)
    assert {link['name'] for link in drawn['links']} == {scene.input.link, *levers, 'link_CD'}
    # Slider blocks (32 x 18 px) are drawn over the links: a sample under one shows the
    # block, so samples within a block's half-diagonal of its centre are not counted.
    frame = frame_from_state(scene, drawn['angle'], 0.0, strokes_from_scene(scene))
    _assert_links_drawn(_link_pixels(image, drawn,
                                     [np.array(s['xy']) for s in frame['sliders']],
                                     list(points.values())), 'quick_return')
