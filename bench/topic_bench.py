# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Latency and CPU of the node driven from a topic, against an rclpy floor (a script, not a test).

``drive:=topic``: the node solves and publishes one state per message on
``input_joint_states``. Each run starts one *driver* process and one relay:
the node (``drive:=topic``), or the *floor*, a bare rclpy process that takes
each input message (raw bytes) and publishes three pre-serialized messages of
the node's sizes with the input's stamp patched in (no decoding, no solving,
no rendering). The driver publishes ``JointState`` messages (the crank's
position and velocity, each with its own stamp) from a deadline thread at
``--rates`` Hz and subscribes, without decoding, to the three state topics;
for each input it notes the monotonic time just before ``publish`` and the
time the last of the three state messages with that stamp arrived, in the
same process, on the same clock. After ``--warmup`` s it measures for
``--seconds``:

- latency: arrival of the whole state minus the input's send time, median
  and 99th percentile over the run's inputs, µs;
- CPU: user + system time of the relay process (all threads, DDS included)
  over wall time, % of one core, from /proc;
- answered: inputs of the measured stretch whose three state messages all
  arrived, over the inputs sent.

Node and floor alternate, ``--repeat`` times each, in one run, so that both
meet the same machine: read the ratios of the medians. ``--out FILE`` writes
the figures as JSON, which ``python -m mech_kinematics report -o docs/report
--topic-drive FILE`` stores under the data file's ``topic_drive`` key (kept
from the previous data file by later reports).

Usage (with the package importable, e.g. ``make``'s .venv)::

    python bench/topic_bench.py [--rates 100 1000] [--seconds 20] [--repeat 3] [--out FILE]
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
from pathlib import Path
import random
import statistics
import sys
import tempfile

import ros_runs
from ros_runs import NS, quantile, relay_floor, relay_run, ros_env

STATE_TOPICS = ('joint_states', 'joint_accelerations', 'point_accelerations')
SCENE = 'khurmi_four_bar_ad150'
#: The crank's speed in the input messages, rad/s (the scene's -120 rpm).
SPEED = -4 * math.pi


# -- the floor: a bare relay ------------------------------------------------------------


def floor(namespace: str, scene_name: str) -> None:
    """Publish three pre-serialized state messages with each input message's stamp."""
    from sensor_msgs.msg import JointState
    from trajectory_msgs.msg import JointTrajectory, MultiDOFJointTrajectory

    import mech_kinematics as mk
    from mech_kinematics.ros.messages import TickMessages

    scene = mk.load_scene(scene_name)
    state = mk.solve(scene, scene.input.angle)
    payloads = TickMessages(scene.output_joints, scene.output_points, 'mechanism',
                            velocities=True, accelerations=False).render(state, 0, 0)
    types = (JointState, JointTrajectory, MultiDOFJointTrajectory)
    relay_floor(namespace, list(zip(types, STATE_TOPICS, strict=True)), payloads)


# -- the driver: inputs out, states in, one clock ----------------------------------------


def drive(namespace: str, rate: float, seconds: float, out: str) -> None:
    """Publish inputs at ``rate`` for ``seconds``; note send and arrival times; write them.

    The crank's position and speed: with ``drive:=target`` (``--target``) the
    same message is a target naming the crank, a joint the scene reports (the
    inverse answers it in one Newton step: what the target path costs beyond
    topic drive's).
    """
    from sensor_msgs.msg import JointState
    from trajectory_msgs.msg import JointTrajectory, MultiDOFJointTrajectory

    from mech_kinematics.ros.cdr import marker, MessageTemplate, STAMP_MARKER

    msg = JointState(name=['crank'], position=[marker(0)], velocity=[marker(1)])
    msg.header.stamp.sec, msg.header.stamp.nanosec = STAMP_MARKER
    template = MessageTemplate(msg, 2)

    def render(t: int) -> bytes:
        return template.render(*divmod(t, NS), (SPEED * (t % (10 * NS)) / NS, SPEED))

    types = (JointState, JointTrajectory, MultiDOFJointTrajectory)
    ros_runs.drive(namespace, 'topic_bench_driver', rate, seconds, out, render,
                   list(zip(types, STATE_TOPICS, strict=True)))


# -- one run, and the table ---------------------------------------------------------------


def measure(kind: str, rate: float, args: argparse.Namespace, env: dict[str, str],
            tmp: Path) -> dict[str, float]:
    """Run the node or the floor with a driver at ``rate``; return the run's figures."""
    namespace = f'/topic_bench_{os.getpid()}_{kind}_{int(rate)}_{random.randrange(10 ** 6)}'
    out = tmp / f'{namespace[1:]}.json'
    if kind == 'node':
        how = (['-p', 'drive:=target', '-r', 'input_targets:=input_joint_states']
               if args.target else ['-p', 'drive:=topic'])
        command = [sys.executable, '-m', 'mech_kinematics.kinematics_node', '--ros-args',
                   '-r', f'__ns:={namespace}', '-p', f'scene:={SCENE}', *how,
                   '--log-level', 'warn']
    else:
        command = [sys.executable, __file__, '--floor', namespace, SCENE]
    driver = [sys.executable, __file__, '--drive', namespace, str(rate),
              str(args.warmup + args.seconds), str(out)]
    cpu, wall0, wall1 = relay_run(command, driver, out, args.warmup, args.seconds, env)
    data = json.loads(out.read_text())
    sent = data['sent']
    measured = sent[int(len(sent) * args.warmup / (args.warmup + args.seconds)):]
    arrived: dict[int, int] = {}
    counts: dict[int, int] = {}
    for topic in STATE_TOPICS:
        for stamp, at in data['arrivals'][topic]:
            arrived[stamp] = max(arrived.get(stamp, 0), at)
            counts[stamp] = counts.get(stamp, 0) + 1
    latencies = [(arrived[t] - at) / 1e3 for t, at in measured
                 if counts.get(t) == len(STATE_TOPICS)]
    return {'kind': kind, 'rate': rate, 'cpu_pct': 100 * cpu / (wall1 - wall0),
            'latency_median_us': statistics.median(latencies),
            'latency_p99_us': quantile(latencies, 0.99),
            'answered': len(latencies) / len(measured), 'inputs': len(measured)}


def summary(rows: list[dict[str, float]], args: argparse.Namespace) -> dict:
    """Return the figures of the runs: per rate, medians of node and floor and their ratios."""
    out: dict = {'date': datetime.date.today().isoformat(), 'scene': SCENE,
                 'seconds': args.seconds, 'repeat': args.repeat, 'cpus': os.cpu_count(),
                 'load': os.getloadavg()[0], 'rates': {}}
    for rate in dict.fromkeys(r['rate'] for r in rows):
        entry: dict = {}
        for kind in ('floor', 'node'):
            runs = [r for r in rows if r['rate'] == rate and r['kind'] == kind]
            entry[kind] = {
                'cpu_pct': statistics.median(r['cpu_pct'] for r in runs),
                'latency_median_us': statistics.median(r['latency_median_us'] for r in runs),
                'latency_p99_us': statistics.median(r['latency_p99_us'] for r in runs),
                'answered_min': min(r['answered'] for r in runs),
                'runs': runs}
        entry['cpu_ratio'] = entry['node']['cpu_pct'] / entry['floor']['cpu_pct']
        entry['latency_ratio'] = (entry['node']['latency_median_us']
                                  / entry['floor']['latency_median_us'])
        entry['latency_extra_us'] = (entry['node']['latency_median_us']
                                     - entry['floor']['latency_median_us'])
        out['rates'][f'{rate:g}'] = entry
    return out


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark; print a Markdown table (and write JSON with ``--out``)."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--rates', type=float, nargs='+', default=[100.0, 1000.0])
    parser.add_argument('--seconds', type=float, default=20.0, help='measured time per run')
    parser.add_argument('--warmup', type=float, default=3.0, help='settling time per run')
    parser.add_argument('--repeat', type=int, default=3, help='runs of each, alternating')
    parser.add_argument('--out', help='write the figures as JSON to this file')
    parser.add_argument('--target', action='store_true',
                        help='the node in drive:=target, each input a target naming the crank')
    parser.add_argument('--drive', nargs=4, help=argparse.SUPPRESS)
    parser.add_argument('--floor', nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.drive:
        namespace, rate, seconds, out = args.drive
        drive(namespace, float(rate), float(seconds), out)
        return 0
    if args.floor:
        floor(*args.floor)
        return 0
    env = ros_env()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for rate in args.rates:
            for _ in range(args.repeat):
                for kind in ('floor', 'node'):
                    row = measure(kind, rate, args, env, Path(tmp))
                    rows.append(row)
                    print(f'{kind} {rate:g} Hz: CPU {row["cpu_pct"]:.1f} %, latency median '
                          f'{row["latency_median_us"]:.0f} us, p99 {row["latency_p99_us"]:.0f}'
                          f' us, answered {100 * row["answered"]:.2f} %', file=sys.stderr,
                          flush=True)
    result = summary(rows, args)
    print(f'{"target" if args.target else "topic"} drive vs the rclpy relay floor, '
          f'{args.seconds:g} s per run, {args.repeat} '
          f'runs each, alternating; {os.cpu_count()} cores, load average '
          f'{result["load"]:.1f}\n')
    print('| input rate | latency median, floor / node (µs) | node / floor | p99, floor / node '
          '(µs) | CPU, floor / node (%) | node / floor | answered, worst run |')
    print('|---:|---:|---:|---:|---:|---:|---:|')
    for rate, e in result['rates'].items():
        f, n = e['floor'], e['node']
        print(f'| {rate} Hz | {f["latency_median_us"]:.0f} / {n["latency_median_us"]:.0f} | '
              f'{e["latency_ratio"]:.2f} | {f["latency_p99_us"]:.0f} / '
              f'{n["latency_p99_us"]:.0f} | {f["cpu_pct"]:.1f} / {n["cpu_pct"]:.1f} | '
              f'{e["cpu_ratio"]:.2f} | {100 * min(f["answered_min"], n["answered_min"]):.2f} %'
              ' |')
    if args.out:
        Path(args.out).write_text(json.dumps(result, indent=1, sort_keys=True) + '\n')
    return 0


if __name__ == '__main__':
    sys.exit(main())
