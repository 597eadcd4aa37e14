# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node as a ROS user meets it: lifecycle, QoS overrides, names, start-up errors.

See issues 12 and 13.

Each test starts its own node in a namespace of this session and drives it
from this process with rclpy (services, subscriptions, the graph).
"""

import math
import signal
import time

from lifecycle_msgs.msg import State, Transition
import pytest
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from rclpy.qos import QoSProfile, ReliabilityPolicy
from ros_helpers import (cannot_start, exited, Lifecycle, NodeProcess, NS, refused_starts,
                         send_until, SESSION, stamp_ns, STARTUP_S, wait_for,
                         wait_for_parameters, wrap)
from sensor_msgs.msg import JointState

#: Tolerance of an angle that the time base fixes exactly, rad.
ATOL_TIMEBASE = 1e-9


#: Bad -p at start: (arguments, words of the one line that refuses them).
BAD_PARAMETERS = [
    (['-p', 'scene:=123'], ['scene: expected a string, got number 123']),
    (['-p', 'frame_id:=5'], ['frame_id: expected a string, got number 5']),
    (['-p', 'scene:='], ["Couldn't parse parameter override rule: '-p scene:='"]),
    (['-p', 'rate_hz:=fast'], ["rate_hz: expected a number (Hz), got string 'fast'"]),
    (['-p', 'late_ticks:=later'], ["late_ticks: expected one of catch_up, skip, got 'later'"]),
    (['-p', 'use_sim_time:=abc'], ['use_sim_time']),
    (['-p', 'managed:=3'], ['managed: expected true or false']),
    (['-p', 'qos_overrides./x/joint_states.publisher.reliability:=sometimes'],
     ['reliability', 'sometimes']),
]


@pytest.fixture(scope='module')
def bad_parameters(tmp_path_factory):
    """(status, output) of each start of BAD_PARAMETERS, by its arguments."""
    starts = []
    for i, (args, _) in enumerate(BAD_PARAMETERS):
        ns = f'{SESSION}/bad_start{i}'
        starts.append(['-r', f'__ns:={ns}', *(a.replace('/x/', f'{ns}/') for a in args)])
    results = refused_starts(tmp_path_factory.mktemp('bad_start'), starts)
    return {tuple(args): result
            for (args, _), result in zip(BAD_PARAMETERS, results, strict=True)}


@pytest.mark.parametrize('args, words', BAD_PARAMETERS)
def test_bad_start_parameters_are_one_line_and_exit_1(bad_parameters, args, words):
    """Any bad -p at start stops the node with status 1 and one line naming it. See issue 12.

    The starts run a few at once (:func:`refused_starts`).
    """
    status, output = bad_parameters[tuple(args)]
    assert status == 1, output
    assert 'Traceback' not in output
    fatal = cannot_start(output)
    assert len(fatal) == 1, output
    for word in words:
        assert word in fatal[0], output


def test_a_second_node_of_the_same_name_exits_1(ros, tmp_path):
    """A node whose fully qualified name is taken says so and exits 1; the first goes on."""
    ns = f'{SESSION}/twice'
    js = ros.collect(JointState, f'{ns}/joint_states')
    first = NodeProcess(tmp_path / 'first', '-r', f'__ns:={ns}')
    try:
        wait_for(lambda: js, STARTUP_S, 'the first node publishing')
        status, output = exited(NodeProcess(tmp_path / 'second', '-r', f'__ns:={ns}'))
        assert status == 1, output
        assert f'another node named {ns}/mech_kinematics is running' in output
        count = len(js)
        wait_for(lambda: len(js) > count + 50, STARTUP_S, 'the first node still publishing')
    finally:
        status, _ = first.stop(signal.SIGINT)
    assert status == 0, first.output()


def test_qos_override_makes_joint_states_best_effort(ros, tmp_path):
    """qos_overrides./NS/joint_states.publisher.reliability:=best_effort is what a subscriber sees.

    See issue 13.
    """
    ns = f'{SESSION}/qos'
    topic = f'{ns}/joint_states'
    js = ros.collect(JointState, topic,
                     QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT))
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns}',
                       '-p', f'qos_overrides.{topic}.publisher.reliability:=best_effort',
                       '-p', f'qos_overrides.{topic}.publisher.depth:=3')
    try:
        wait_for(lambda: js, STARTUP_S, 'joint_states on a best-effort subscription')
        offers = ros.node.get_publishers_info_by_topic(topic)
        assert [o.qos_profile.reliability for o in offers] == [ReliabilityPolicy.BEST_EFFORT]
        params = AsyncParameterClient(ros.node, f'{ns}/mech_kinematics')
        wait_for_parameters(params)
        response = ros.call(params.get_parameters([f'qos_overrides.{topic}.publisher.depth']))
        assert response.values[0].integer_value == 3
        others = ros.node.get_publishers_info_by_topic(f'{ns}/joint_accelerations')
        assert [o.qos_profile.reliability for o in others] == [ReliabilityPolicy.RELIABLE]
    finally:
        status, _ = proc.stop(signal.SIGINT)
    assert status == 0, proc.output()


def test_managed_node_follows_the_lifecycle(ros, tmp_path):
    """managed:=true publishes only when active; deactivating keeps the angle a function of time.

    Driven through lifecycle_msgs services. See issue 13.
    """
    ns = f'{SESSION}/managed'
    js = ros.collect(JointState, f'{ns}/joint_states')
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns}', '-p', 'managed:=true',
                       '-p', 'rate_hz:=200', '-p', 'crank_speed_rpm:=60')
    try:
        life = Lifecycle(ros, f'{ns}/mech_kinematics')
        assert life.state() == 'unconfigured'
        time.sleep(1.0)
        assert not js, 'published before activation'
        assert life.transition(Transition.TRANSITION_CONFIGURE) and life.state() == 'inactive'
        time.sleep(0.5)
        assert not js, 'published while inactive'
        assert life.transition(Transition.TRANSITION_ACTIVATE) and life.state() == 'active'
        wait_for(lambda: len(js) > 50, STARTUP_S, 'joint_states once active')
        assert life.transition(Transition.TRANSITION_DEACTIVATE) and life.state() == 'inactive'
        # Stamps are the node's clock (this machine's): the tick thread has stopped once the
        # transition is answered, so every state stamped before now was published before.
        deactivated = time.time_ns()
        time.sleep(1.0)
        # While inactive the speed changes: it applies from that instant, as time goes on.
        params = AsyncParameterClient(ros.node, f'{ns}/mech_kinematics')
        wait_for_parameters(params)
        response = ros.call(params.set_parameters([Parameter('crank_speed_rpm', value=120.0)]))
        assert response.results[0].successful
        activated = time.time_ns()
        assert life.transition(Transition.TRANSITION_ACTIVATE)
        wait_for(lambda: sum(stamp_ns(m) > activated for m in js) > 20, STARTUP_S,
                 'joint_states again')
        assert not [m for m in js if deactivated < stamp_ns(m) <= activated], \
            'published while inactive'
        before = [m for m in js if stamp_ns(m) <= deactivated]
        after = [m for m in js if stamp_ns(m) > activated]
        last, again = before[-1], after[0]
        gap = (stamp_ns(again) - stamp_ns(last)) / NS
        assert gap > 1.0
        ci = list(last.name).index('crank')
        assert again.velocity[ci] == pytest.approx(4 * math.pi, rel=1e-15)
        # The angle went on at 60 rpm, then at 120 rpm from the change: between the two.
        moved = wrap(again.position[ci] - last.position[ci])
        low, high = sorted((wrap(2 * math.pi * gap), wrap(4 * math.pi * gap)))
        assert low - ATOL_TIMEBASE <= moved <= high + ATOL_TIMEBASE or high - low > math.pi
        for a, b in zip(after, after[1:], strict=False):
            dt = (stamp_ns(b) - stamp_ns(a)) / NS
            assert abs(wrap(b.position[ci] - a.position[ci] - 4 * math.pi * dt)) < ATOL_TIMEBASE
        assert life.transition(Transition.TRANSITION_DEACTIVATE)
        assert life.transition(Transition.TRANSITION_CLEANUP) and life.state() == 'unconfigured'
        assert life.transition(Transition.TRANSITION_UNCONFIGURED_SHUTDOWN)
        assert life.state() == 'finalized'
        assert State.PRIMARY_STATE_FINALIZED == 4
    finally:
        status, _ = proc.stop(signal.SIGINT)
    assert status == 0, proc.output()


def test_managed_node_with_a_bad_scene_fails_to_configure(ros, tmp_path):
    """Configuring a managed node on a missing scene fails with the reason; the node lives on."""
    ns = f'{SESSION}/managed_bad'
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns}', '-p', 'managed:=true',
                       '-p', 'scene:=no_such_scene')
    try:
        life = Lifecycle(ros, f'{ns}/mech_kinematics')
        assert not life.transition(Transition.TRANSITION_CONFIGURE)
        assert life.state() == 'unconfigured'
        wait_for(lambda: 'cannot configure' in proc.output(), STARTUP_S, 'the reason in the log')
        assert 'no_such_scene' in proc.output()
    finally:
        status, _ = proc.stop(signal.SIGINT)
    assert status == 0, proc.output()


def test_untrusted_ticks_publish_nothing_and_say_why(ros, tmp_path):
    """max_relative_error too tight for the bounds: nothing published, diagnostics say why.

    Changed while running, both ways. See issue 10.
    """
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus

    ns = f'{SESSION}/untrusted'
    js = ros.collect(JointState, f'{ns}/joint_states')
    diag = ros.collect(DiagnosticArray, f'{ns}/diagnostics')
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns}', '-p', 'rate_hz:=200')
    try:
        wait_for(lambda: js, STARTUP_S, 'joint_states')
        params = AsyncParameterClient(ros.node, f'{ns}/mech_kinematics')
        wait_for_parameters(params)
        response = ros.call(params.set_parameters(
            [Parameter('max_relative_error', value=1e-15)]))
        assert response.results[0].successful, response.results[0].reason
        # Applied before the answer: no instant after it is published (stamps are this
        # machine's clock, as the node's).
        changed = time.time_ns()
        start = len(diag)
        wait_for(lambda: len(diag) > start + 1, STARTUP_S, 'diagnostics after the change')
        count = len(js)
        assert not [m for m in js if stamp_ns(m) > changed], \
            'published while every tick is untrusted'
        solver = diag[-1].status[0]
        assert solver.level == DiagnosticStatus.ERROR
        assert solver.message.startswith('not trusted at ')
        assert 'cannot be trusted: expected its error bound to be at most 1e-15' in \
            solver.message
        response = ros.call(params.set_parameters(
            [Parameter('max_relative_error', value=1e-6)]))
        assert response.results[0].successful
        wait_for(lambda: len(js) > count + 50, STARTUP_S, 'joint_states again')
    finally:
        status, _ = proc.stop(signal.SIGINT)
    assert status == 0, proc.output()


def test_geneva_wheel_dwells_and_indexes_over_ten_turns(ros, tmp_path):
    """The node's Geneva wheel: exactly still between engagements, 2 pi / 4 per crank turn.

    Over ten crank turns, from a subscriber; the node passes the crank's whole
    turns to the solver. See issue 11.
    """
    from rclpy.serialization import deserialize_message
    from trajectory_msgs.msg import JointTrajectory

    ns = f'{SESSION}/geneva'
    raw = ros.collect_raw(JointTrajectory, f'{ns}/joint_accelerations')
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns}', '-p', 'scene:=geneva',
                       '-p', 'rate_hz:=1000', '-p', 'crank_speed_rpm:=600')
    try:
        wait_for(lambda: len(raw) > 100, STARTUP_S, 'joint_accelerations')
        start = len(raw)
        wait_for(lambda: len(raw) > start + 1200, 10.0, 'ten crank turns')
    finally:
        status, _ = proc.stop(signal.SIGINT)
    assert status == 0, proc.output()
    msgs = [deserialize_message(data, JointTrajectory) for data in raw[start:]]
    wheel = msgs[0].joint_names.index('wheel')
    driver = msgs[0].joint_names.index('driver')
    samples = sorted((stamp_ns(m), m.points[0].positions[driver],
                      m.points[0].positions[wheel], m.points[0].velocities[wheel],
                      m.points[0].accelerations[wheel]) for m in msgs)
    dwells = []         # (first stamp, wheel angle) of every run of locked samples
    for t, _, angle, w, alpha in samples:
        locked = w == 0.0 and alpha == 0.0
        if locked and dwells and dwells[-1][2] and t - dwells[-1][3] <= 2_000_000:
            assert angle == dwells[-1][1], 'the wheel moved while locked'
            dwells[-1][3] = t
        elif locked and dwells and dwells[-1][2] and angle == dwells[-1][1]:
            dwells[-1][3] = t   # samples lost within a dwell (a loaded machine): one dwell
        elif locked:
            dwells.append([t, angle, True, t])
        elif dwells:
            dwells[-1][2] = False
    assert len(dwells) >= 10
    steps = [wrap(b[1] - a[1]) for a, b in zip(dwells, dwells[1:], strict=False)]
    for step in steps:
        assert abs(abs(step) - math.pi / 2) <= 1e-12, steps
    assert len({math.copysign(1.0, s) for s in steps}) == 1, 'indexed back and forth'
    moving = [w for _, _, _, w, _ in samples if w != 0.0]
    assert moving and len(moving) < 0.5 * len(samples)     # engaged a quarter of each turn


def test_switching_to_sim_time_and_back_keeps_the_crank_where_it_was(ros, tmp_path):
    """use_sim_time set while running: the crank goes on from its last published angle.

    The simulated epoch means nothing to the wall clock's: the first instant on
    the new clock continues the last one on the old, both ways.
    """
    from builtin_interfaces.msg import Time
    from rosgraph_msgs.msg import Clock

    ns = f'{SESSION}/switch'
    js = ros.collect(JointState, f'{ns}/joint_states')
    clock_pub = ros.node.create_publisher(Clock, f'{ns}/clock', 10)
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns}', '-r', f'/clock:={ns}/clock',
                       '-p', 'rate_hz:=100', '-p', 'crank_speed_rpm:=60')
    try:
        wait_for(lambda: len(js) > 20, STARTUP_S, 'joint_states on the wall clock')
        params = AsyncParameterClient(ros.node, f'{ns}/mech_kinematics')
        wait_for_parameters(params)
        assert ros.call(params.set_parameters(
            [Parameter('use_sim_time', value=True)])).results[0].successful
        count = len(js) - 1         # a state on the wall clock, before the switch
        clock = [5_000 * NS]

        def tick():
            # The node subscribes to /clock when use_sim_time turns true: a /clock sent
            # before that subscription has matched is lost; the clock goes on until heard.
            clock[0] += 10_000_000
            clock_pub.publish(Clock(clock=Time(sec=clock[0] // NS, nanosec=clock[0] % NS)))

        send_until(tick, lambda: sum(stamp_ns(m) < 100_000 * NS for m in js[count:]) > 10,
                   STARTUP_S, 'joint_states on sim time', every=0.01)
        # The last state on the wall clock is the one received before the first on sim time
        # (one publisher: in the order published).
        first_sim = next(i for i in range(count, len(js)) if stamp_ns(js[i]) < 100_000 * NS)
        wall_last = js[first_sim - 1]
        sim = [m for m in js[count:] if stamp_ns(m) < 100_000 * NS]
        ci = list(wall_last.name).index('crank')
        assert abs(wrap(sim[0].position[ci] - wall_last.position[ci])) < ATOL_TIMEBASE
        for a, b in zip(sim, sim[1:], strict=False):
            dt = (stamp_ns(b) - stamp_ns(a)) / NS
            assert abs(wrap(b.position[ci] - a.position[ci] - 2 * math.pi * dt)) < ATOL_TIMEBASE
        assert ros.call(params.set_parameters(
            [Parameter('use_sim_time', value=False)])).results[0].successful
        wait_for(lambda: any(stamp_ns(m) > 100_000 * NS for m in js[first_sim:]), STARTUP_S,
                 'joint_states on the wall clock again')
        last_sim = [m for m in js[first_sim:] if stamp_ns(m) < 100_000 * NS][-1]
        first_wall = next(m for m in js[first_sim:] if stamp_ns(m) > 100_000 * NS)
        assert abs(wrap(first_wall.position[ci] - last_sim.position[ci])) < ATOL_TIMEBASE
    finally:
        status, _ = proc.stop(signal.SIGINT)
        ros.node.destroy_publisher(clock_pub)
    assert status == 0, proc.output()


#: Refused starts: (arguments, the reason the one line gives, /x/ the namespace).
REFUSED = [
    (['-p', 'frame_id:=/'], "frame_id: expected a tf2 frame id (no leading '/', no empty, '.' "
                            "or '..' part between '/', no space), got '/'"),
    (['-p', 'tf_prefix:=../..'], 'tf_prefix: expected a tf2 frame id'),
    (['-p', 'rate_hz:=abc'], "rate_hz: expected a number (Hz), got string 'abc'"),
    (['-p', 'scene:=no_such_scene'], 'no_such_scene: expected a scene file path'),
    (['-p', 'max_relative_error:=1e-15'],   # what solve refuses, the node does not start with
     'khurmi_four_bar_ad150: input crank cannot be solved at crank angle 1.0472 rad: the '
     'acceleration of points.B cannot be trusted: expected its error bound to be at most 1e-15'),
    (['-p', 'qos_overrides./x/joint_states.publisher.depth:=-1'],
     'qos_overrides./x/joint_states.publisher.depth: expected a whole number of messages from 0 '
     'to 2147483647, got number -1'),
]


@pytest.fixture(scope='module')
def refused(tmp_path_factory):
    """(namespace, status, output) of each start of REFUSED (-r __node:=renamed), by arguments."""
    starts, spaces = [], []
    for i, (args, _) in enumerate(REFUSED):
        ns = f'{SESSION}/one_line{i}'
        spaces.append(ns)
        starts.append(['-r', f'__ns:={ns}', '-r', '__node:=renamed',
                       *(a.replace('/x/', f'{ns}/') for a in args)])
    results = refused_starts(tmp_path_factory.mktemp('one_line'), starts)
    return {tuple(args): (ns, *result) for (args, _), ns, result in zip(
        REFUSED, spaces, results, strict=True)}


@pytest.mark.parametrize('args, reason', REFUSED)
def test_a_bad_start_is_one_line_with_the_nodes_own_name(refused, args, reason):
    """Every refused start is exactly one FATAL line, naming the node as renamed (issue 21).

    It was 2-3 lines (a WARN or ERROR, then FATAL with the same text, or rmw's
    text with a build path) and named [mech_kinematics] after -r __node:=NAME.
    """
    ns, status, output = refused[tuple(args)]
    reason = reason.replace('/x/', f'{ns}/')
    assert status == 1, output
    lines = output.strip().splitlines()
    assert len(lines) == 1, output
    assert lines[0].startswith('[FATAL]'), output
    logger = ns.strip('/').replace('/', '.') + '.renamed'
    assert f'[{logger}]: cannot start: {reason}' in lines[0], output
    assert '.cpp' not in lines[0] and '.c:' not in lines[0]


SUBNORMAL_SCENE = """\
name: subnormal_four_bar
units: {length: mm, angle: deg}
ground: {A: [0, 0], D: [1.5e-319, 0]}
input: {link: crank, center: A, point: B, length: 4e-320, angle: 60, speed_rpm: -120}
dyads:
  - type: RRR
    point: C
    links:
      - {name: coupler, from: B, length: 1.5e-319}
      - {name: rocker, from: D, length: 8e-320}
    branch: 1
"""


def test_a_scene_of_subnormal_lengths_is_published_as_solve_answers_it(ros, tmp_path):
    """Subnormal lengths started a node that published nothing and warned forever (issue 21).

    ``solve`` answers the scene (errors within max_relative_error of the
    smallest normal float); the node publishes the same angles.
    """
    import mech_kinematics as mk

    scene_file = tmp_path / 'subnormal.yaml'
    scene_file.write_text(SUBNORMAL_SCENE)
    scene = mk.load_scene(str(scene_file))
    ns = f'{SESSION}/subnormal'
    js = ros.collect(JointState, f'{ns}/joint_states')
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns}', '-p', f'scene:={scene_file}')
    try:
        wait_for(lambda: len(js) >= 5, STARTUP_S, 'joint_states from the subnormal scene')
        msg = js[-1]
        crank = msg.position[list(msg.name).index('crank')]
        state = mk.solve(scene, crank)
        coupler = msg.position[list(msg.name).index('coupler')]
        assert coupler == pytest.approx(wrap(state.joints['coupler'].position), abs=1e-9)
    finally:
        status, _ = proc.stop(signal.SIGINT)
    assert status == 0, proc.output()
    assert 'no state published' not in proc.output()
