# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Benchmark of the running kinematics_node (a script, not a test).

For each rate it starts the node on the four-bar scene and one subscriber in
another process, lets them settle, then measures for ``--seconds``:

- achieved rate: ticks published per second (the node's own counter, from
  ``diagnostics``);
- received / sent: state messages the subscriber got over those the node
  published in the same stretch of stamps, per topic;
- node CPU: user + system time of the whole node process over wall time, in %
  of one core (from /proc);
- tick lateness: how late the tick thread woke for its deadline, median and
  p99 (the node's own numbers on ``diagnostics``, per 1 s window: the median
  of the medians and the largest p99);
- latency: receive time minus ``header.stamp`` at the subscriber, median and
  p99.

The subscriber uses ``raw=True`` subscriptions and reads the stamp straight
from the CDR bytes (a decoding Python subscriber tops out at 2-3 k msg/s).

Usage: ``python bench/node_bench.py [--rates 100 1000 5000] [--seconds 10]``
(with the package importable, e.g. from ``make`` 's .venv). Prints a Markdown
table.
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path
import random
import signal
import statistics
import struct
import subprocess
import sys
import tempfile
import time

NS = 1_000_000_000
STATE_TOPICS = ('joint_states', 'joint_accelerations', 'point_accelerations')
SCENE = 'khurmi_four_bar_ad150'
_STAMP = struct.Struct('<iI')   # header.stamp right after the 4-byte CDR encapsulation


def _cpu_seconds(pid: int) -> float:
    fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def _quantile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


# -- the subscriber process ----------------------------------------------------------


def subscribe(namespace: str, warmup: float, seconds: float, out: str) -> None:
    """Record (receive ns, stamp ns) of every state message, and the diagnostics."""
    import rclpy
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from diagnostic_msgs.msg import DiagnosticArray
    from sensor_msgs.msg import JointState
    from trajectory_msgs.msg import JointTrajectory, MultiDOFJointTrajectory

    rclpy.init()
    node = rclpy.create_node('node_bench_subscriber', namespace=namespace)
    qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
    received: dict[str, list[tuple[int, bytes]]] = {t: [] for t in STATE_TOPICS}
    now = time.time_ns
    for topic, msg_type in zip(STATE_TOPICS,
                               (JointState, JointTrajectory, MultiDOFJointTrajectory),
                               strict=True):
        sink = received[topic]
        node.create_subscription(msg_type, topic,
                                 lambda data, sink=sink: sink.append((now(), data[4:12])),
                                 qos, raw=True)
    diagnostics: list[dict[str, object]] = []

    def on_diagnostics(msg: DiagnosticArray) -> None:
        values = {kv.key: kv.value for s in msg.status for kv in s.values}
        values['stamp'] = msg.header.stamp.sec * NS + msg.header.stamp.nanosec
        diagnostics.append(values)

    node.create_subscription(DiagnosticArray, 'diagnostics', on_diagnostics, 10)
    end = time.monotonic() + warmup + seconds + 1.5
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.1)
    node.destroy_node()
    rclpy.try_shutdown()
    result = {'diagnostics': diagnostics, 'warmup_end_ns': 0,
              'received': {t: [(r, _STAMP.unpack(s)) for r, s in v]
                           for t, v in received.items()}}
    Path(out).write_text(json.dumps(result))


# -- the driver ----------------------------------------------------------------------


def measure(rate: float, warmup: float, seconds: float, env: dict[str, str],
            tmp: Path) -> dict[str, float]:
    """Run node + subscriber at ``rate``; return the row of the table."""
    namespace = f'/bench_{os.getpid()}_{int(rate)}'
    out = tmp / f'sub_{int(rate)}.json'
    sub = subprocess.Popen([sys.executable, __file__, '--subscribe', namespace,
                            str(warmup), str(seconds), str(out)], env=env)
    time.sleep(1.0)     # the subscriber is there before the first message
    node = subprocess.Popen(
        [sys.executable, '-m', 'mech_kinematics.kinematics_node', '--ros-args',
         '-r', f'__ns:={namespace}', '-p', f'scene:={SCENE}', '-p', f'rate_hz:={rate}',
         '--log-level', 'warn'], env=env)
    try:
        time.sleep(warmup)
        cpu0, wall0, stamp0 = _cpu_seconds(node.pid), time.monotonic(), time.time_ns()
        time.sleep(seconds)
        cpu1, wall1, stamp1 = _cpu_seconds(node.pid), time.monotonic(), time.time_ns()
    finally:
        node.send_signal(signal.SIGINT)
        node.wait(timeout=10)
        sub.wait(timeout=30)
    data = json.loads(out.read_text())
    # The node's diagnostics in the window: published totals and lateness per 1 s window.
    diags = [d for d in data['diagnostics'] if stamp0 <= d['stamp'] <= stamp1]
    first, last = diags[0], diags[-1]
    sent = int(last['published_total']) - int(first['published_total'])
    span_s = (last['stamp'] - first['stamp']) / NS
    row = {'rate': rate, 'achieved': sent / span_s, 'cpu': 100 * (cpu1 - cpu0) / (wall1 - wall0),
           'late_median_us': statistics.median(float(d['lateness_median_us']) for d in diags[1:]),
           'late_p99_us': max(float(d['lateness_p99_us']) for d in diags[1:]),
           'late_ticks': sum(int(d['late_ticks']) for d in diags[1:]),
           'skipped_ticks': sum(int(d['skipped_ticks']) for d in diags[1:])}
    latencies: list[float] = []
    for topic in STATE_TOPICS:
        got = [(r, s * NS + n) for r, (s, n) in data['received'][topic]]
        lo, hi = int(first['last_published_stamp_ns']), int(last['last_published_stamp_ns'])
        in_window = [(r, t) for r, t in got if lo < t <= hi]
        row[f'received_{topic}'] = len(in_window) / sent
        latencies += [(r - t) / 1e3 for r, t in in_window]
    row['latency_median_us'] = statistics.median(latencies)
    row['latency_p99_us'] = _quantile(latencies, 0.99)
    return row


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and print the table."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--rates', type=float, nargs='+', default=[100.0, 1000.0, 5000.0])
    parser.add_argument('--seconds', type=float, default=10.0, help='measured time per rate')
    parser.add_argument('--warmup', type=float, default=3.0, help='settling time per rate')
    parser.add_argument('--json', action='store_true', help='also print the rows as JSON')
    parser.add_argument('--subscribe', nargs=4, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.subscribe:
        namespace, warmup, seconds, out = args.subscribe
        subscribe(namespace, float(warmup), float(seconds), out)
        return 0
    env = dict(os.environ)
    env.setdefault('ROS_DOMAIN_ID', str(random.SystemRandom().randint(101, 200)))
    env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    repo = str(Path(__file__).resolve().parents[1])
    env['PYTHONPATH'] = os.pathsep.join(filter(None, [repo, env.get('PYTHONPATH')]))
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for rate in args.rates:
            rows.append(measure(rate, args.warmup, args.seconds, env, Path(tmp)))
            print(f'measured {rate:g} Hz', file=sys.stderr, flush=True)
    print(f'kinematics_node, scene {SCENE}, {args.seconds:g} s per rate, '
          f'{os.cpu_count()} cores\n')
    print('| rate Hz | achieved Hz | received/sent js / jt / pt | node CPU % of a core | '
          'lateness median / p99 us | late / skipped ticks | latency median / p99 us |')
    print('|---:|---:|---:|---:|---:|---:|---:|')
    for r in rows:
        print(f'| {r["rate"]:g} | {r["achieved"]:.1f} | '
              f'{100 * r["received_joint_states"]:.2f} % / '
              f'{100 * r["received_joint_accelerations"]:.2f} % / '
              f'{100 * r["received_point_accelerations"]:.2f} % | {r["cpu"]:.1f} | '
              f'{r["late_median_us"]:.0f} / {r["late_p99_us"]:.0f} | '
              f'{r["late_ticks"]} / {r["skipped_ticks"]} | '
              f'{r["latency_median_us"]:.0f} / {r["latency_p99_us"]:.0f} |')
    if args.json:
        print(json.dumps(rows, indent=1))
    return 0


if __name__ == '__main__':
    sys.exit(main())
