# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node at a Geneva wheel's engagement instants: every tick published (issue 19).

At 50 rpm and 1 kHz the crank turns 0.3 deg a tick, so ticks land exactly on
the instants where the pin enters (135 deg) and leaves (225 deg) a slot and
the wheel's acceleration jumps. The node runs on a simulated clock driven from
here, so that every grid instant is owed and none can be lost to the load of
the machine: each of the three state topics must carry every instant, the
jump instants answered one-sided as mk.solve answers them, and diagnostics
must count them at level OK.
"""

import math
import signal

from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
import pytest
from ros_helpers import (NodeProcess, NS, RELIABLE, send_until, SESSION, stamp_ns, STARTUP_S,
                         wait_for)
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory, MultiDOFJointTrajectory

import mech_kinematics as mk

PERIOD_NS = 1_000_000           # 1 kHz
SPEED = 50.0 * math.pi / 30.0   # 50 rpm, rad/s
STEP_NS = 20 * PERIOD_NS        # the simulated clock advances by 20 ticks at a time
SPAN_NS = 4 * NS                # at least 4 s of simulated time
#: Published crank angles this close to 135 or 225 deg (mod 360) are engagement instants, rad.
ATOL_INSTANT = 1e-9


def _decode(raw, msg_type):
    from rclpy.serialization import deserialize_message

    return [deserialize_message(data, msg_type) for data in raw]


def _at_instant(angle):
    """Return 'entry' or 'exit' if crank ``angle`` (rad) is 135 or 225 deg mod 360, else ''."""
    for edge, degrees in (('entry', 135.0), ('exit', 225.0)):
        if abs(math.remainder(angle - math.radians(degrees), 2 * math.pi)) < ATOL_INSTANT:
            return edge
    return ''


def test_every_grid_instant_is_published_at_engagement_instants(ros, tmp_path):
    """50 rpm, 1 kHz, 4 s: all instants on all three topics; jumps one-sided, counted OK."""
    ns = f'{SESSION}/jumps'
    topics = {'joint_states': JointState, 'joint_accelerations': JointTrajectory,
              'point_accelerations': MultiDOFJointTrajectory}
    raw = {topic: ros.collect_raw(kind, f'{ns}/{topic}') for topic, kind in topics.items()}
    diagnostics = ros.collect(DiagnosticArray, f'{ns}/diagnostics')
    clock = ros.node.create_publisher(Clock, f'{ns}/clock', RELIABLE)
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns}', '-r', f'/clock:={ns}/clock',
                       '-p', 'use_sim_time:=true', '-p', 'scene:=geneva',
                       '-p', 'crank_speed_rpm:=50.0', '-p', 'rate_hz:=1000.0')

    def tick_to(t):
        clock.publish(Clock(clock=Time(sec=t // NS, nanosec=t % NS)))

    try:
        # Up, and matched both ways, before the first instant is owed.
        wait_for(lambda: all(ros.node.count_publishers(f'{ns}/{topic}') for topic in topics)
                 and clock.get_subscription_count() > 0, STARTUP_S, 'the node')
        wait_for(lambda: diagnostics, STARTUP_S, 'diagnostics (the node waiting for /clock)')
        t = 1000 * NS
        # Until heard: a /clock sent before the node's subscription has matched is lost
        # (the same instant again changes nothing).
        send_until(lambda: tick_to(t), lambda: all(raw.values()), STARTUP_S,
                   'the first instant on every topic')
        end = t + SPAN_NS
        while t < end:
            t += STEP_NS
            tick_to(t)
            owed = (t - 1000 * NS) // PERIOD_NS + 1
            wait_for(lambda owed=owed: all(len(r) >= owed for r in raw.values()), 10.0,
                     f'{owed} instants on every topic')
        published = len(diagnostics)
        wait_for(lambda: len(diagnostics) > published + 1, STARTUP_S, 'diagnostics after the run')
    finally:
        status, _ = proc.stop(signal.SIGINT)
        ros.node.destroy_publisher(clock)
    assert status == 0, proc.output()

    # Every grid instant from the first to the last, once, on every topic.
    expected = list(range(1000 * NS, end + 1, PERIOD_NS))
    assert len(expected) == 4001
    for topic, kind in topics.items():
        stamps = sorted(stamp_ns(m) for m in _decode(raw[topic], kind))
        assert stamps == expected, topic

    # The engagement instants are among them, answered one-sided as mk.solve does.
    scene = mk.load_scene('geneva')
    states = {stamp_ns(m): m for m in _decode(raw['joint_accelerations'], JointTrajectory)}
    names = states[expected[0]].joint_names
    driver, wheel = names.index('driver'), names.index('wheel')
    assert states[expected[0]].points[0].positions[driver] == pytest.approx(
        scene.input.angle, abs=ATOL_INSTANT)    # the crank starts at the scene's 150 deg
    instants = []
    for stamp in expected:
        point = states[stamp].points[0]
        edge = _at_instant(point.positions[driver])
        if edge:
            instants.append(stamp)
            solved = mk.solve(scene, point.positions[driver], point.velocities[driver],
                              point.accelerations[driver])
            assert solved.jumps
            assert point.accelerations[wheel] == solved.joints['wheel'].acceleration
            after = -SPEED ** 2 * math.tan(math.pi / 4) if edge == 'entry' else 0.0
            assert point.accelerations[wheel] == pytest.approx(after, rel=1e-9)
    # 225 deg at 0.25 s, 495 at 1.15 s, 585 at 1.45 s, ...: 4 exits and 3 entries in 4 s.
    assert [(s - expected[0]) // PERIOD_NS for s in instants] == [250, 1150, 1450, 2350, 2650,
                                                                  3550, 3850]

    # Diagnostics: the solver never in ERROR, the jump instants counted.
    solver = [s for m in diagnostics for s in m.status if s.name.endswith(': solver')]
    assert all(s.level != DiagnosticStatus.ERROR for s in solver), \
        [s.message for s in solver if s.level == DiagnosticStatus.ERROR]
    counted = [s for s in solver if {kv.key: kv.value for kv in s.values}['jump_instants'] != '0']
    assert counted and all(s.level == DiagnosticStatus.OK for s in counted)
    last = {kv.key: kv.value for kv in solver[-1].values}
    assert last['jump_instants_total'] == '7' and last['unsolved_ticks_total'] == '0'
