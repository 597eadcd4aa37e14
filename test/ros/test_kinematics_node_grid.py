# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's stream over real DDS: an exact grid, catch-up, phase continuity (issues 12, 14).

Each test starts its own node (``python -m mech_kinematics.kinematics_node``)
in a namespace of this session and watches it from a subscriber in this
process, as launch_testing would.
"""

import math
import random
import signal
import time

from diagnostic_msgs.msg import DiagnosticArray
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from rclpy.qos import QoSProfile, ReliabilityPolicy
from ros_helpers import (NodeProcess, NS, Ros, SESSION, stamp_ns, STARTUP_S, wait_for,
                         wait_for_parameters, wrap)
from sensor_msgs.msg import JointState

#: Largest jump of the published crank angle allowed across a drive change, rad.
ATOL_CONTINUITY = 1e-9


def diagnostic_value(msgs, key):
    """Return ``key`` of the timing status of the last diagnostics message, as an int."""
    values = {kv.key: kv.value for status in msgs[-1].status for kv in status.values}
    return int(values[key])


def stamps_of(raw) -> list:
    """Return the header stamps of serialized joint_states messages, ns, in order received."""
    from rclpy.serialization import deserialize_message

    return [stamp_ns(deserialize_message(data, JointState)) for data in raw]


#: History of this process's joint_states readers: 10 s at 1 kHz, so that a reader late on a
#: loaded machine (the node's history is 1000) loses nothing the node published.
READER_DEPTH = 10_000


class Stream:
    """A node of its own and its joint_states (serialized) and diagnostics, as received here."""

    def __init__(self, ros: Ros, tmp, name: str, *args: str, depth: int = READER_DEPTH) -> None:
        self.ros = ros
        self.ns = f'{SESSION}/{name}'
        self.js = ros.collect_raw(JointState, f'{self.ns}/joint_states',
                                  QoSProfile(depth=depth, reliability=ReliabilityPolicy.RELIABLE))
        self.diag = ros.collect(DiagnosticArray, f'{self.ns}/diagnostics')
        self.process = NodeProcess(tmp, '-r', f'__ns:={self.ns}', *args)
        self.params = AsyncParameterClient(ros.node, f'{self.ns}/mech_kinematics')
        wait_for(lambda: len(self.js) > 50 or self.process.proc.poll() is not None, STARTUP_S,
                 'the node publishing')
        assert self.process.proc.poll() is None, self.process.output()
        wait_for_parameters(self.params)

    def set(self, **values) -> None:
        """Set parameters (one call), asserting they were accepted."""
        parameters = [Parameter(k, value=v) for k, v in values.items()]
        response = self.ros.call(self.params.set_parameters(parameters))
        assert all(r.successful for r in response.results), [r.reason for r in response.results]

    def stop(self) -> None:
        status, _ = self.process.stop(signal.SIGINT)
        assert status == 0, self.process.output()


def _holes(stamps, period):
    """Return the grid instants missing between the first and the last stamp."""
    return sum((b - a) // period - 1 for a, b in zip(stamps, stamps[1:], strict=False))


def test_stamps_are_an_exact_grid_without_holes(ros, tmp_path):
    """At 1 kHz every stamp is a multiple of 1 ms and none is missing over 2 s. See issue 14."""
    stream = Stream(ros, tmp_path, 'grid', '-p', 'rate_hz:=1000')
    try:
        start = len(stream.js) - 1
        # 2 s of instants as stamped (received late or not, on a loaded machine).
        first = stamps_of(stream.js[start:start + 1])[0]
        wait_for(lambda: stamps_of(stream.js[-1:])[0] >= first + 2 * NS, 2 + STARTUP_S,
                 '2 s of states')
        stamps = [t for t in stamps_of(stream.js[start:]) if t <= first + 2 * NS]
        wait_for(lambda: len(stream.diag) >= 2, STARTUP_S, 'diagnostics')
        skipped = diagnostic_value(stream.diag, 'skipped_ticks_total')
    finally:
        stream.stop()
    assert len(stamps) >= 1500
    assert all(s % 1_000_000 == 0 for s in stamps)
    assert stamps == sorted(set(stamps))
    # Only instants beyond max_catch_up_s of a stall may be missing, and they are counted.
    assert _holes(stamps, 1_000_000) <= skipped


def _largest_jump(samples, period, w_max):
    """Return the largest deviation of consecutive crank samples from the drive's integral, rad.

    ``samples`` are (stamp ns, angle, speed, accel) in stamp order; pairs one
    ``period`` apart are checked (a subscriber on a busy machine may miss a
    message). Between two instants the drive is the one published at the
    first (a change applies at an instant not yet published): speed w,
    acceleration a, held at +-w_max once reached.
    """
    worst = 0.0
    for (t0, theta, w, a), (t1, theta1, _, _) in zip(samples, samples[1:], strict=False):
        if t1 - t0 != period:
            continue
        dt = period / NS
        if a == 0.0:
            moved = w * dt
        else:
            bound = math.copysign(w_max, a)
            t_hold = (bound - w) / a
            if t_hold >= dt:
                moved = w * dt + a * dt * dt / 2
            else:
                moved = w * t_hold + a * t_hold * t_hold / 2 + bound * (dt - t_hold)
        worst = max(worst, abs(wrap(theta1 - theta - moved)))
    return worst


def _crank_samples(raw):
    """Return (stamp, angle, speed, accel) of the crank (joint 0), in stamp order."""
    from rclpy.serialization import deserialize_message
    from trajectory_msgs.msg import JointTrajectory

    samples = []
    for data in raw:
        m = deserialize_message(data, JointTrajectory)
        p = m.points[0]
        samples.append((stamp_ns(m), p.positions[0], p.velocities[0], p.accelerations[0]))
    return sorted(samples)


def test_a_burst_of_drive_changes_keeps_the_angle_continuous(ros, tmp_path):
    """60 speed/accel changes in a burst at 1 and 5 kHz: no published angle jumps. See issue 12.

    The published crank angle between any two consecutive instants moves by
    exactly the integral of the drive published at the first, to 1e-9 rad.
    """
    from trajectory_msgs.msg import JointTrajectory

    rng = random.Random(12)
    w_max = 3000.0 * math.pi / 30
    worst = {}
    for rate in (1000, 5000):
        stream = Stream(ros, tmp_path / str(rate), f'burst_{rate}', '-p', f'rate_hz:={rate}',
                        '-p', 'max_crank_speed_rpm:=3000.0', '-p', 'crank_speed_rpm:=300.0')
        trajectories = ros.collect_raw(JointTrajectory, f'{stream.ns}/joint_accelerations')
        try:
            wait_for(lambda t=trajectories: len(t) > 50, STARTUP_S, 'joint_accelerations')
            start = len(trajectories)
            sets = []
            for k in range(60):
                if k % 2:
                    sets.append(stream.params.set_parameters([Parameter(
                        'crank_speed_rpm', value=rng.uniform(-3000.0, 3000.0))]))
                else:
                    sets.append(stream.params.set_parameters([Parameter(
                        'crank_accel', value=rng.choice((-1.0, 1.0)) * rng.uniform(1e2, 1e4))]))
                time.sleep(rng.uniform(0.0, 0.02))
            wait_for(lambda sets=sets: all(f.done() for f in sets), STARTUP_S,
                     'the 60 changes answered')
            assert all(r.successful for f in sets for r in f.result().results)
            # Every change is applied by now: wait for the states stamped after it (the
            # stamps are this machine's clock), however late they arrive.
            done = time.time_ns() + NS // 10
            wait_for(lambda t=trajectories, done=done: _crank_samples(t[-1:])[0][0] > done,
                     STARTUP_S, 'the states after the burst')
            samples = _crank_samples(trajectories[start:])
        finally:
            stream.stop()
        stamps = [s[0] for s in samples]
        adjacent = sum(b - a == NS // rate for a, b in zip(stamps, stamps[1:], strict=False))
        # About 2 s of instants are owed; a Python subscriber on a loaded machine keeps up
        # with only part of them at 5 kHz (one CI run: 1,057 adjacent pairs of 10,000).
        # A tenth of a second's worth of adjacent pairs, spread over the burst's 30-odd
        # drives (checked next), still tests every change.
        assert adjacent > 0.1 * rate, adjacent
        assert len({s[2] for s in samples}) > 30, 'the burst did not change the drive'
        worst[rate] = _largest_jump(samples, NS // rate, w_max)
    print(f'largest angle jump across the burst, rad: {worst}')
    assert max(worst.values()) <= ATOL_CONTINUITY, worst


def _stall(stream, seconds):
    """Stop the node's process for ``seconds`` (SIGSTOP, SIGCONT): every wake-up is late."""
    stream.process.proc.send_signal(signal.SIGSTOP)
    time.sleep(seconds)
    stream.process.proc.send_signal(signal.SIGCONT)


def _states_until(raw, stamp):
    """Wait until a state stamped after ``stamp`` (ns) is received on ``raw``.

    After a stall, every state before it (the catch-up burst) has arrived then:
    one publisher, in order. A sleep instead would be too short on a loaded machine.
    """
    wait_for(lambda: stamps_of(raw[-1:])[0] > stamp, STARTUP_S, 'the states after the stall')


def test_a_stall_is_caught_up_to_the_bound_and_the_rest_counted(ros, tmp_path):
    """After a 0.5 s stall the last 0.1 s of instants are published, the rest skipped and counted.

    With late_ticks: skip, only the latest instant is published. See issue 14.
    """
    period = 1_000_000
    stream = Stream(ros, tmp_path, 'stall', '-p', 'rate_hz:=1000', '-p', 'max_catch_up_s:=0.1')
    try:
        results = {}
        for mode in ('catch_up', 'skip'):
            stream.set(late_ticks=mode)
            time.sleep(1.0)
            count = len(stream.diag)
            wait_for(lambda n=count: len(stream.diag) > n, 3.0, 'fresh diagnostics')
            skipped_before = diagnostic_value(stream.diag, 'skipped_ticks_total')
            start = max(0, len(stream.js) - 20)     # from before the stall
            _stall(stream, 0.5)
            _states_until(stream.js, time.time_ns() + NS // 2)
            count = len(stream.diag)
            wait_for(lambda n=count: len(stream.diag) > n + 1, STARTUP_S,
                     'diagnostics after the stall')
            skipped = diagnostic_value(stream.diag, 'skipped_ticks_total') - skipped_before
            stamps = sorted(stamps_of(stream.js[start:]))
            gaps = sorted(b - a for a, b in zip(stamps, stamps[1:], strict=False) if b > a)
            results[mode] = (skipped, _holes(stamps, period), gaps[-1], gaps[-2])
    finally:
        stream.stop()
    skipped, holes, stall_gap, next_gap = results['catch_up']
    # Every instant but those of the stall older than 0.1 s arrived, and those are counted.
    assert 0.38e9 <= stall_gap <= 0.45e9, results
    assert next_gap == period, results
    assert holes == stall_gap // period - 1 <= skipped, results
    # Skip mode: the stall leaves a hole of its whole length, counted too.
    skipped, holes, stall_gap, _ = results['skip']
    assert 0.49e9 <= stall_gap <= 0.6e9, results
    assert skipped >= stall_gap // period - 1, results


def test_a_long_stop_at_1_khz_is_one_burst_a_keep_last_1000_reader_gets_whole(ros, tmp_path):
    """Issue 21, item 7, with a real SIGSTOP: 4 s at 1 kHz with max_catch_up_s:=10.

    A 10 s stop made a burst of 10,001 instants and a KEEP_LAST 1000 reader lost 1,712
    of them; any stop longer than the history (here 4,000 instants owed) is the case.
    The burst is now capped at the history's 1000 messages (docs/robustness.md): the
    reader gets every instant from the burst's first on, and the older ones are skipped
    and counted on diagnostics.
    """
    period = 1_000_000
    stream = Stream(ros, tmp_path, 'stop_10s', '-p', 'rate_hz:=1000', '-p',
                    'max_catch_up_s:=10.0', depth=1000)
    # The stream's own subscription is the reader: reliable, KEEP_LAST 1000 (a second one at
    # 1 kHz would halve what this process keeps up with on a loaded machine).
    reader = stream.js
    try:
        wait_for(lambda: len(reader) > 100, STARTUP_S, 'the KEEP_LAST 1000 reader')
        wait_for(lambda: len(stream.diag) >= 2, STARTUP_S, 'diagnostics')
        skipped_before = diagnostic_value(stream.diag, 'skipped_ticks_total')
        start = len(reader) - 1
        _stall(stream, 4.0)
        _states_until(reader, time.time_ns() + NS)
        count = len(stream.diag)
        wait_for(lambda: len(stream.diag) > count + 1, STARTUP_S, 'diagnostics after the stop')
        skipped = diagnostic_value(stream.diag, 'skipped_ticks_total') - skipped_before
        stamps = sorted(set(stamps_of(reader[start:])))
    finally:
        stream.stop()
    gaps = [(b - a, i) for i, (a, b) in enumerate(zip(stamps, stamps[1:], strict=False))]
    stop_gap, at = max(gaps)
    # The stop: older instants skipped (counted), then 1000 instants in one burst at most
    # (uncapped, the burst would have left no gap at all; a late wake-up widens it).
    assert 2.5e9 <= stop_gap <= 6e9, stop_gap
    assert stop_gap // period - 1 <= skipped
    after = stamps[at + 1:]
    assert len(after) >= 1000 + 500
    # Nothing lost by the reader from the burst on: every instant, none missing.
    assert _holes(after, period) == 0, [b - a for a, b in zip(after, after[1:], strict=False)
                                        if b - a != period][:10]
