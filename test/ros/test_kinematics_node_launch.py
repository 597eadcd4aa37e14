# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The running node over real DDS, done by hand the way launch_testing would.

The node runs as a subprocess (``python -m mech_kinematics.kinematics_node
--ros-args ...``); this process talks to it with rclpy on a ROS domain of its
own (a random ``ROS_DOMAIN_ID``, discovery on localhost only). One node
process is shared by the tests of the running node; the time-source, partial
cycle, start-up and signal tests start their own.
"""

from decimal import Decimal, localcontext
from fractions import Fraction
import math
import os
from pathlib import Path
import signal
import subprocess
import sys
import time

from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
import numpy as np
import pytest
from rcl_interfaces.msg import Parameter as ParameterMsg
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from rclpy.qos import qos_profile_sensor_data
from ros_helpers import (NodeProcess, NS, RELIABLE, REPO, Ros, send_until, SESSION, stamp_ns,
                         STARTUP_S, wait_for, wait_for_parameters, wrap)
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory, MultiDOFJointTrajectory

import mech_kinematics as mk
from mech_kinematics.geometry.assembly import assembly_summary

PARAMS_FILE = REPO / 'config' / 'kinematics_node.yaml'
#: Relative tolerance between the published values and the solver's.
RTOL = 1e-12
#: Tolerance of an angle that the time base fixes exactly, rad.
ATOL_TIMEBASE = 1e-9  # rad
RATE_HZ = 200.0
FRAME_ID = 'test_frame'
SCENE = mk.load_scene(mk.DEFAULT_SCENE)


class Running:
    """The shared node and what this process has received from it."""

    def __init__(self, ros: Ros, tmp: Path) -> None:
        self.ros = ros
        self.joint_states = ros.collect(JointState, f'{SESSION}/joint_states')
        self.sensor_joint_states = ros.collect(JointState, f'{SESSION}/joint_states',
                                               qos_profile_sensor_data)
        self.joint_accel = ros.collect(JointTrajectory, f'{SESSION}/joint_accelerations')
        self.point_accel = ros.collect(MultiDOFJointTrajectory,
                                       f'{SESSION}/point_accelerations')
        self.diagnostics = ros.collect(DiagnosticArray, f'{SESSION}/diagnostics')
        # Integers for doubles on purpose (rclcpp#979), after the packaged params file.
        self.process = NodeProcess(
            tmp, '--params-file', str(PARAMS_FILE), '-r', f'__ns:={SESSION}',
            '-p', 'rate_hz:=200', '-p', 'crank_speed_rpm:=120', '-p', f'frame_id:={FRAME_ID}')
        self.params = AsyncParameterClient(ros.node, f'{SESSION}/mech_kinematics')
        topics = (self.joint_states, self.sensor_joint_states, self.joint_accel,
                  self.point_accel, self.diagnostics)
        wait_for(lambda: all(topics) or self.process.proc.poll() is not None, STARTUP_S,
                 'the first message on every topic')
        assert self.process.proc.poll() is None, self.process.output()
        wait_for_parameters(self.params)

    def set(self, *parameters: Parameter):
        """Set parameters one by one; return the results."""
        response = self.ros.call(self.params.set_parameters(list(parameters)))
        return response.results

    def get(self, *names: str):
        response = self.ros.call(self.params.get_parameters(list(names)))
        return [Parameter.from_parameter_msg(ParameterMsg(name=n, value=v))
                for n, v in zip(names, response.values, strict=True)]

    def set_ok(self, **values: float) -> int:
        """Set doubles, assert they were accepted; return the clock after, ns.

        The node's stamps are this machine's clock: an instant stamped later than
        this (and later than the catch-up window) is published with the new values.
        """
        results = self.set(*(Parameter(k, Parameter.Type.DOUBLE, float(v))
                             for k, v in values.items()))
        assert all(r.successful for r in results), [r.reason for r in results]
        return time.time_ns()

    def window(self, seconds: float, since_ns: int | None = None):
        """Return the messages stamped in ``seconds`` from 0.1 s after ``since_ns`` (or now).

        By stamp, not by arrival: on a loaded machine states arrive late, and a
        window of arrival time would hold fewer, or ones from before a change
        (0.1 s: how far back a late wake-up catches up). Each topic has one
        publisher, in order: once a state stamped after the window is here, the
        window is whole.
        """
        start = (time.time_ns() if since_ns is None else since_ns) + NS // 10
        end = start + round(seconds * NS)
        lists = (self.joint_states, self.joint_accel, self.point_accel)
        wait_for(lambda: all(x and stamp_ns(x[-1]) > end for x in lists), seconds + STARTUP_S,
                 f'{seconds} s of states on every topic')
        return tuple([m for m in x if start < stamp_ns(m) <= end] for x in lists)


@pytest.fixture(scope='module')
def node(ros, tmp_path_factory):
    running = Running(ros, tmp_path_factory.mktemp('node'))
    yield running
    status, _ = running.process.stop(signal.SIGINT)
    assert status == 0, running.process.output()


def crank_index() -> int:
    return SCENE.output_joints.index(SCENE.input.link)


def assert_agrees_with_solver(scene, js, jt, md):
    """One tick's three messages agree with mk.solve at the published crank angle."""
    ci = scene.output_joints.index(scene.input.link)
    angle, speed = js.position[ci], js.velocity[ci]
    accel = jt.points[0].accelerations[ci]
    state = mk.solve(scene, angle, speed, accel)
    joints, points = scene.output_joints, scene.output_points
    assert list(js.name) == list(joints) == list(jt.joint_names)
    assert list(md.joint_names) == list(points)
    expected = [state.joints[n] for n in joints]
    got_positions = np.array(js.position)
    exp_positions = np.array([j.position for j in expected])
    revolute = np.array([scene.joint_types[n] == 'revolute' for n in joints])
    # Revolute positions are angles: compare modulo 2 pi.
    diff = np.where(revolute, np.remainder(got_positions - exp_positions + np.pi, 2 * np.pi)
                    - np.pi, got_positions - exp_positions)
    assert np.all(np.abs(diff) <= RTOL * np.maximum(np.abs(exp_positions), 1.0))
    for got, attr in ((js.velocity, 'velocity'), (jt.points[0].velocities, 'velocity'),
                      (jt.points[0].accelerations, 'acceleration')):
        exp = np.array([getattr(j, attr) for j in expected])
        np.testing.assert_allclose(got, exp, rtol=RTOL, atol=RTOL * np.abs(exp).max())
    assert list(jt.points[0].positions) == list(js.position)
    point = md.points[0]
    for kind, got_xyz in (
            ('position', [(t.translation.x, t.translation.y, t.translation.z)
                          for t in point.transforms]),
            ('velocity', [(v.linear.x, v.linear.y, v.linear.z) for v in point.velocities]),
            ('acceleration', [(a.linear.x, a.linear.y, a.linear.z)
                              for a in point.accelerations])):
        exp = np.array([getattr(state.points[n], kind) for n in points])
        got = np.array(got_xyz)
        assert np.all(got[:, 2] == 0.0)
        np.testing.assert_allclose(got[:, :2], exp, rtol=RTOL, atol=RTOL * np.abs(exp).max())
    for t in point.transforms:
        assert (t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w) == (0, 0, 0, 1)


def ticks(js_list, jt_list, md_list):
    """Group messages by stamp: stamp -> (js, jt, md) for the stamps seen on all three topics."""
    jt_by = {stamp_ns(m): m for m in jt_list}
    md_by = {stamp_ns(m): m for m in md_list}
    return {stamp_ns(m): (m, jt_by[stamp_ns(m)], md_by[stamp_ns(m)]) for m in js_list
            if stamp_ns(m) in jt_by and stamp_ns(m) in md_by}


def test_every_message_agrees_with_the_solver(node):
    """Over 2 s every tick's messages agree with mk.solve to 1e-12 and share one stamp."""
    since = node.set_ok(crank_speed_rpm=120, crank_accel=0)
    js_list, jt_list, md_list = node.window(2.0, since)
    by_stamp = ticks(js_list, jt_list, md_list)
    assert len(by_stamp) >= 0.5 * 2.0 * RATE_HZ, 'too few complete ticks received'
    # Every stamp is on all three topics, but for the ones cut off at the window's ends.
    stamps = [sorted(stamp_ns(m) for m in x) for x in (js_list, jt_list, md_list)]
    inner = (max(s[0] for s in stamps), min(s[-1] for s in stamps))
    for s in stamps:
        assert {t for t in s if inner[0] <= t <= inner[1]} <= set(by_stamp)
    for js, jt, md in by_stamp.values():
        for msg in (js, jt, md):
            assert msg.header.frame_id == FRAME_ID
        assert len(js.name) == len(js.position) == len(js.velocity)
        assert_agrees_with_solver(SCENE, js, jt, md)
    # The crank follows the stamps: angle difference = omega * time difference.
    ordered = [by_stamp[t][0] for t in sorted(by_stamp)]
    ci = crank_index()
    omega = 120 * math.pi / 30
    for a, b in zip(ordered, ordered[1:], strict=False):
        assert a.velocity[ci] == pytest.approx(omega, rel=1e-15)
        predicted = a.position[ci] + omega * (stamp_ns(b) - stamp_ns(a)) / NS
        assert abs(wrap(b.position[ci] - predicted)) < ATOL_TIMEBASE, (
            f'stamps {stamp_ns(a)} {stamp_ns(b)}: angles {a.position[ci]!r} '
            f'{b.position[ci]!r}, speeds {a.velocity[ci]!r} {b.velocity[ci]!r}')
    spacing = np.median(np.diff(sorted(by_stamp))) / NS
    assert spacing == pytest.approx(1 / RATE_HZ, rel=0.1)


def test_sensor_data_subscriber_receives_joint_states(node):
    """A best-effort SensorDataQoS subscriber gets joint_states from the reliable publisher."""
    start = len(node.sensor_joint_states)
    wait_for(lambda: len(node.sensor_joint_states) >= start + 20, STARTUP_S,
             'joint_states on a SensorDataQoS subscription')


def test_integers_are_accepted_for_doubles(node):
    """-p crank_speed_rpm:=120 and setting rate_hz to an integer work and store doubles."""
    speed, rate = node.get('crank_speed_rpm', 'rate_hz')
    assert speed.type_ == Parameter.Type.DOUBLE and speed.value == 120.0
    assert rate.type_ == Parameter.Type.DOUBLE and rate.value == 200.0
    results = node.set(Parameter('rate_hz', Parameter.Type.INTEGER, 250))
    assert results[0].successful, results[0].reason
    (rate,) = node.get('rate_hz')
    assert rate.type_ == Parameter.Type.DOUBLE and rate.value == 250.0
    node.set_ok(rate_hz=RATE_HZ)


def test_speed_change_keeps_the_angle_continuous(node):
    """Setting crank_speed_rpm while running changes the speed; the angle does not jump."""
    since = node.set_ok(crank_speed_rpm=120, crank_accel=0) + NS // 10
    node.window(0.05, since)                # a few ticks at 120 rpm, before the change
    results = node.set(Parameter('crank_speed_rpm', Parameter.Type.INTEGER, -300))
    assert results[0].successful, results[0].reason
    node.window(0.4)                        # and after it
    msgs = sorted((m for m in node.joint_states if stamp_ns(m) > since), key=stamp_ns)
    ci = crank_index()
    w1, w2 = 120 * math.pi / 30, -300 * math.pi / 30
    speeds = [m.velocity[ci] for m in msgs]
    assert speeds[0] == pytest.approx(w1) and speeds[-1] == pytest.approx(w2)
    changes = [i for i in range(1, len(msgs)) if speeds[i] != speeds[i - 1]]
    assert len(changes) == 1, 'the speed changed more than once'
    for a, b in zip(msgs, msgs[1:], strict=False):
        dt = (stamp_ns(b) - stamp_ns(a)) / NS
        if a.velocity[ci] == b.velocity[ci]:
            predicted = a.position[ci] + a.velocity[ci] * dt
            assert abs(wrap(b.position[ci] - predicted)) < ATOL_TIMEBASE
        else:
            # theta2 = theta1 + w1 (tc - t1) + w2 (t2 - tc): the change instant tc is in [t1, t2].
            d = wrap(b.position[ci] - a.position[ci] - w2 * dt)
            tc = d / (w1 - w2)          # s after t1
            assert -1e-9 <= tc <= dt + 1e-9, 'the angle jumped at the speed change'
    node.set_ok(crank_speed_rpm=120)


BAD_VALUES = [
    Parameter('crank_speed_rpm', Parameter.Type.DOUBLE, math.nan),
    Parameter('crank_speed_rpm', Parameter.Type.DOUBLE, math.inf),
    Parameter('crank_speed_rpm', Parameter.Type.STRING, 'fast'),
    Parameter('crank_speed_rpm', Parameter.Type.BOOL, True),
    Parameter('crank_speed_rpm', Parameter.Type.NOT_SET, None),
    Parameter('crank_speed_rpm', Parameter.Type.DOUBLE, 20_000.0),   # above max_crank_speed_rpm
    Parameter('crank_accel', Parameter.Type.DOUBLE, -math.inf),
    Parameter('crank_accel', Parameter.Type.DOUBLE_ARRAY, [1.0]),
    Parameter('rate_hz', Parameter.Type.INTEGER, 0),
    Parameter('rate_hz', Parameter.Type.DOUBLE, 0.0),
    Parameter('rate_hz', Parameter.Type.DOUBLE, -5.0),
    Parameter('rate_hz', Parameter.Type.DOUBLE, 1e6),
    Parameter('rate_hz', Parameter.Type.DOUBLE, math.nan),
    Parameter('max_crank_speed_rpm', Parameter.Type.DOUBLE, -1.0),
    Parameter('max_crank_speed_rpm', Parameter.Type.DOUBLE, 50.0),   # below |crank_speed_rpm|
    Parameter('scene', Parameter.Type.STRING, 'slider_crank_150_600'),    # read-only
    Parameter('frame_id', Parameter.Type.STRING, 'elsewhere'),            # read-only
]


def test_bad_values_are_refused_and_publishing_goes_on(node):
    """Each bad value is refused with a reason; the parameters keep their values."""
    names = ('crank_speed_rpm', 'crank_accel', 'rate_hz', 'max_crank_speed_rpm', 'scene',
             'frame_id')
    before = [p.value for p in node.get(*names)]
    results = node.set(*BAD_VALUES)
    for param, result in zip(BAD_VALUES, results, strict=True):
        assert not result.successful, f'{param.name}={param.value!r} was accepted'
        assert param.name in result.reason, result.reason
    assert [p.value for p in node.get(*names)] == before
    # Every refusal is logged once with its reason (issue 13).
    refused = [line for line in node.process.output().splitlines()
               if 'parameter refused: ' in line]
    for param, result in zip(BAD_VALUES, results, strict=True):
        if param.name in ('scene', 'frame_id'):
            assert any(f'{param.name}: read-only' in line for line in refused), refused
        else:
            assert sum(result.reason in line for line in refused) >= 1, (result.reason, refused)
    start = len(node.joint_states)
    wait_for(lambda: len(node.joint_states) >= start + 20, STARTUP_S,
             'joint_states after refusals')


def test_rate_change(node):
    """Setting rate_hz while running changes the stamp spacing."""
    since = node.set_ok(rate_hz=50)
    js_list, _, _ = node.window(1.0, since)
    spacing = np.median(np.diff(sorted(stamp_ns(m) for m in js_list))) / NS
    assert spacing == pytest.approx(1 / 50, rel=0.1)
    node.set_ok(rate_hz=RATE_HZ)


def test_acceleration_is_held_at_the_bound(node):
    """A positive crank_accel ramps the speed up to max_crank_speed_rpm and holds it there."""
    since = node.set_ok(max_crank_speed_rpm=600, crank_speed_rpm=120) + NS // 10
    ramping = node.set_ok(crank_accel=200)   # 12.6 -> 62.8 rad/s in 0.25 s
    js_list, jt_list, md_list = node.window(0.3, ramping + 4 * NS // 10)
    ci = crank_index()
    w_max = 600 * math.pi / 30
    ramp = sorted((m for m in node.joint_states if stamp_ns(m) > since), key=stamp_ns)
    speeds = [m.velocity[ci] for m in ramp]
    assert all(a <= b for a, b in zip(speeds, speeds[1:], strict=False)), 'the speed went down'
    assert max(speeds) == pytest.approx(w_max, rel=1e-12)
    assert any(12.6 < s < w_max - 1 for s in speeds), 'no ramp seen'
    by_stamp = ticks(js_list, jt_list, md_list)
    assert by_stamp
    for js, jt, md in by_stamp.values():
        assert js.velocity[ci] == pytest.approx(w_max, rel=1e-12)
        assert jt.points[0].accelerations[ci] == 0.0
        assert_agrees_with_solver(SCENE, js, jt, md)
    # While ramping, the accelerations are the commanded one, and agree with the solver.
    jt_by = {stamp_ns(m): m for m in node.joint_accel}
    md_by = {stamp_ns(m): m for m in node.point_accel}
    ramping = [m for m in ramp if 12.6 < m.velocity[ci] < w_max - 1
               and stamp_ns(m) in jt_by and stamp_ns(m) in md_by]
    assert ramping
    for js in ramping:
        jt = jt_by[stamp_ns(js)]
        assert jt.points[0].accelerations[ci] == pytest.approx(200.0, rel=1e-15)
        assert_agrees_with_solver(SCENE, js, jt, md_by[stamp_ns(js)])
    node.set_ok(crank_accel=0)
    node.set_ok(crank_speed_rpm=120)
    node.set_ok(max_crank_speed_rpm=10_000)


def test_diagnostics_report_status_and_timing(node):
    """The diagnostics carry solver status ok, the achieved rate and the late-tick counts."""
    start = len(node.diagnostics)
    wait_for(lambda: len(node.diagnostics) >= start + 2, STARTUP_S, 'diagnostics')
    msg = node.diagnostics[-1]
    status = {s.name: s for s in msg.status}
    solver = status['mech_kinematics: solver']
    timing = status['mech_kinematics: timing']
    assert solver.level == DiagnosticStatus.OK and solver.message == 'ok'
    solver_values = {kv.key: kv.value for kv in solver.values}
    assert 0 < float(solver_values['worst_singularity_measure']) <= 1
    assert solver_values['assembly'] == 'assembles at every crank angle'      # issue 11
    values = {kv.key: kv.value for kv in timing.values}
    assert float(values['achieved_rate_hz']) == pytest.approx(RATE_HZ, rel=0.3)
    for key in ('late_ticks', 'skipped_ticks', 'late_ticks_total', 'skipped_ticks_total'):
        assert int(values[key]) >= 0
    assert msg.header.frame_id == FRAME_ID


# -- nodes of their own ------------------------------------------------------------------


def exact_angle_difference(rpm: int, dt_ns: int) -> float:
    """Return 2 pi * rpm / 60 * dt wrapped to [-pi, pi], with exact arithmetic."""
    turns = Fraction(rpm, 60) * Fraction(dt_ns, NS) % 1
    with localcontext() as ctx:
        ctx.prec = 50
        two_pi = 2 * Decimal('3.14159265358979323846264338327950288419716939937510')
        return wrap(float(two_pi * Decimal(turns.numerator) / Decimal(turns.denominator)))


def test_sim_time_drives_the_angle_exactly(ros, tmp_path):
    """With use_sim_time the grid follows a published /clock and the angle follows it exactly.

    Stamps are the instants of the grid (multiples of the period) that the
    clock has reached; a jump of 30 days catches up max_catch_up_s of them and
    counts the rest as skipped. See issue 14.
    """
    rpm = 600
    period = 10_000_000
    ns_topic = f'{SESSION}/sim'
    js_list = ros.collect(JointState, f'{ns_topic}/joint_states')
    diag = ros.collect(DiagnosticArray, f'{ns_topic}/diagnostics')
    # /clock remapped too, so that no other test session can drive this node's clock.
    clock_pub = ros.node.create_publisher(Clock, f'{ns_topic}/clock', RELIABLE)
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns_topic}', '-r', f'/clock:={ns_topic}/clock',
                       '-p', 'use_sim_time:=true',
                       '-p', f'crank_speed_rpm:={rpm}', '-p', 'rate_hz:=100')
    try:
        # No clock yet: no ticks, and diagnostics say what the node waits for (issue 13).
        wait_for(lambda: any('waiting for /clock' in m.status[0].message for m in diag),
                 STARTUP_S, 'diagnostics saying the node waits for /clock')
        assert not js_list
        solver = diag[-1].status[0]
        assert solver.level == DiagnosticStatus.WARN and 'waiting for /clock' in solver.message
        wait_for(lambda: clock_pub.get_subscription_count() > 0, STARTUP_S, 'the /clock match')
        t0 = 1_000 * NS + 123_456_789
        # The first /clock until the node has it (one sent before its subscription has
        # matched is lost): it says on diagnostics that it no longer waits for /clock.
        seen = len(diag)
        send_until(lambda: clock_pub.publish(Clock(clock=Time(sec=t0 // NS,
                                                              nanosec=t0 % NS))),
                   lambda: any('waiting for /clock' not in m.status[0].message
                               for m in diag[seen:]), STARTUP_S, 'the node hearing /clock',
                   every=0.2)
        assert not js_list
        for k in range(120):
            t = t0 + k * period             # 10 ms of sim time per 5 ms of wall time
            clock_pub.publish(Clock(clock=Time(sec=t // NS, nanosec=t % NS)))
            time.sleep(0.005)
        last_clock = t0 + 119 * period
        wait_for(lambda: js_list and stamp_ns(js_list[-1]) == last_clock // period * period,
                 5.0, 'joint_states up to the last /clock')
        stamps = [stamp_ns(msg) for msg in js_list]
        assert all(s % period == 0 for s in stamps)
        assert stamps == list(range(stamps[0], stamps[-1] + 1, period))    # none missing
        assert t0 <= stamps[0] <= t0 + period
        # Thirty days later, in one jump: max_catch_up_s (0.1 s) of instants, in order.
        big = t0 + 30 * 86_400 * NS + 7
        count = len(js_list)
        clock_pub.publish(Clock(clock=Time(sec=big // NS, nanosec=big % NS)))
        last = big // period * period
        wait_for(lambda: js_list and stamp_ns(js_list[-1]) == last, STARTUP_S,
                 'the ticks after the 30-day jump')
        time.sleep(0.3)
        assert len(js_list) == count + 11, 'ticked without the clock moving'
        caught_up = [stamp_ns(m) for m in js_list[count:]]
        assert caught_up == list(range(last - 10 * period, last + 1, period))
        ci = crank_index()
        first = js_list[0]
        for msg in js_list:
            assert msg.velocity[ci] == pytest.approx(rpm * math.pi / 30, rel=1e-15)
            expected = first.position[ci] + exact_angle_difference(
                rpm, stamp_ns(msg) - stamp_ns(first))
            assert abs(wrap(msg.position[ci] - expected)) < ATOL_TIMEBASE
        status, _ = proc.stop(signal.SIGINT)
        assert status == 0, proc.output()
    finally:
        if proc.proc.poll() is None:
            proc.proc.kill()
        ros.node.destroy_publisher(clock_pub)


PARTIAL_SCENE = """\
name: partial_four_bar
description: Crank 40, coupler 60, rocker 80, ground 150 mm, assembles only near 0 deg.
units: {length: mm, angle: deg}
ground:
  A: [0, 0]
  D: [150, 0]
input: {link: crank, center: A, point: B, length: 40, angle: 0, speed_rpm: 120}
dyads:
  - type: RRR
    point: C
    links:
      - {name: coupler, from: B, length: 60}
      - {name: rocker, from: D, length: 80}
    branch: 1
"""


def test_unsolvable_ticks_publish_nothing_and_the_node_carries_on(ros, tmp_path):
    """Where the scene cannot assemble no state is published, diagnostics say why; remaps apply."""
    scene_path = tmp_path / 'partial_four_bar.yaml'
    scene_path.write_text(PARTIAL_SCENE)
    scene = mk.load_scene(scene_path)
    ns_topic = f'{SESSION}/partial'
    remapped = ros.collect(JointState, f'{ns_topic}/remapped_states')
    not_remapped = ros.collect(JointState, f'{ns_topic}/joint_states')
    jt_list = ros.collect(JointTrajectory, f'{ns_topic}/joint_accelerations')
    md_list = ros.collect(MultiDOFJointTrajectory, f'{ns_topic}/point_accelerations')
    diag = ros.collect(DiagnosticArray, f'{ns_topic}/diagnostics')
    proc = NodeProcess(tmp_path, '-p', f'scene:={scene_path}', '-p', 'rate_hz:=100',
                       '-r', f'__ns:={ns_topic}', '-r', 'joint_states:=remapped_states')
    try:
        def saw_error():
            return any(s.level == DiagnosticStatus.ERROR for m in diag for s in m.status)
        wait_for(saw_error, STARTUP_S, 'a cannot-assemble status on diagnostics')
        start = len(remapped)
        wait_for(lambda: len(remapped) >= start + 30, STARTUP_S,
                 'states after an unsolvable stretch')
        # The same ticks on the other two topics (each topic arrives on its own).
        wait_for(lambda: len(ticks(remapped[start:], jt_list, md_list)) >= 30, STARTUP_S,
                 'the same 30 ticks on joint_accelerations and point_accelerations')
        solver = [s for m in diag for s in m.status if s.level == DiagnosticStatus.ERROR][0]
        assert 'cannot assemble' in solver.message and 'RRR' in solver.message
        # Where it cannot, in one line (issue 11): the same as `check` finds.
        assembly = {kv.key: kv.value for kv in solver.values}['assembly']
        assert assembly.startswith('does not assemble for crank angles ')
        assert assembly == assembly_summary(scene)
        assert not not_remapped, 'published on joint_states despite the remap'
        stamps = sorted(stamp_ns(m) for m in remapped)
        assert max(np.diff(stamps)) > 0.1 * NS, 'no gap where the scene cannot assemble'
        for js, jt, md in list(ticks(remapped, jt_list, md_list).values())[-30:]:
            assert_agrees_with_solver(scene, js, jt, md)
        status, _ = proc.stop(signal.SIGTERM)
        assert status == 0, proc.output()
    finally:
        if proc.proc.poll() is None:
            proc.proc.kill()


BROKEN_SCENE = PARTIAL_SCENE.replace('angle: 0,', 'angle: 180,').replace(
    'partial_four_bar', 'broken_four_bar')


@pytest.mark.parametrize('case', ['unassemblable scene', 'missing scene', 'rate 0'])
def test_bad_start_exits_non_zero_with_a_clear_message(tmp_path, case):
    """A scene that cannot assemble (or is missing, or a bad -p) stops the node with status 1."""
    scene_path = tmp_path / 'broken_four_bar.yaml'
    scene_path.write_text(BROKEN_SCENE)
    args, words = {
        'unassemblable scene': (['-p', f'scene:={scene_path}'], ['assemble', 'broken_four_bar']),
        'missing scene': (['-p', 'scene:=no_such_scene'], ['no_such_scene']),
        'rate 0': (['-p', 'rate_hz:=0'], ['rate_hz']),
    }[case]
    proc = NodeProcess(tmp_path, *args)
    try:
        status = proc.proc.wait(timeout=STARTUP_S)
    finally:
        if proc.proc.poll() is None:
            proc.proc.kill()
    output = proc.output()
    assert status == 1, output
    assert 'Traceback' not in output
    for word in words:
        assert word in output


@pytest.mark.parametrize('sig', [signal.SIGINT, signal.SIGTERM])
def test_signal_exits_zero_within_a_second(ros, tmp_path, sig):
    """SIGINT and SIGTERM stop the node within 1 s with status 0 and no traceback."""
    ns_topic = f'{SESSION}/signal_{sig.name.lower()}'
    js_list = ros.collect(JointState, f'{ns_topic}/joint_states')
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns_topic}', '-p', 'rate_hz:=1000')
    try:
        wait_for(lambda: js_list, STARTUP_S, 'the first joint_states')
        status, took = proc.stop(sig)
    finally:
        if proc.proc.poll() is None:
            proc.proc.kill()
    output = proc.output()
    assert status == 0, output
    assert 'Traceback' not in output
    assert took < 1.0


SIGNAL_BEFORE_SPIN = """\
import sys
import rclpy
import rclpy.executors
import mech_kinematics.ros.node as kn
native = rclpy.executors._rclpy
class Late:
    def __getattr__(self, name):
        return getattr(native, name)
    def WaitSet(self, *args):
        rclpy.shutdown()    # as rclpy's SIGTERM handler does, just before the wait set is made
        return native.WaitSet(*args)
rclpy.executors._rclpy = Late()
sys.exit(kn.main())
"""


def test_a_signal_while_the_node_starts_is_a_clean_exit(tmp_path):
    """SIGTERM between the first tick and the executor's first wait: status 0, no FATAL.

    rclpy's signal handler shuts the context down; the executor then fails to
    make its wait set ("the given context is not valid"), which the node used to
    report as "cannot start" with status 1.
    """
    env = dict(os.environ)
    env['PYTHONPATH'] = os.pathsep.join(filter(None, [str(REPO), env.get('PYTHONPATH')]))
    result = subprocess.run(
        [sys.executable, '-c', SIGNAL_BEFORE_SPIN, '--ros-args', '-r',
         f'__ns:={SESSION}/signal_before_spin'],
        env=env, capture_output=True, text=True, timeout=STARTUP_S, cwd=tmp_path)
    assert result.returncode == 0, result.stdout + result.stderr
    assert 'FATAL' not in result.stderr and 'Traceback' not in result.stderr, result.stderr


FAILING_TICK = """\
import sys
import mech_kinematics.ros.node as kn
def fail(self, *args):
    raise RuntimeError('injected failure')
kn.KinematicsNode._tick = fail
sys.exit(kn.main())
"""


def test_tick_thread_failure_stops_the_node_with_status_1(tmp_path):
    """A node whose tick thread died does not linger: it logs the error and exits 1."""
    env = dict(os.environ)
    env['PYTHONPATH'] = os.pathsep.join(filter(None, [str(REPO), env.get('PYTHONPATH')]))
    result = subprocess.run(
        [sys.executable, '-c', FAILING_TICK, '--ros-args', '-r', f'__ns:={SESSION}/failing'],
        env=env, capture_output=True, text=True, timeout=STARTUP_S, cwd=tmp_path)
    assert result.returncode == 1, result.stdout + result.stderr
    assert 'tick thread failed' in result.stderr and 'injected failure' in result.stderr
