# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node in URDF mode, driven from a topic, against an rclpy relay floor (a script, not a test).

Issue 31: the node between a robot's motors and robot_state_publisher. A
*driver* process publishes the motors' ``JointState`` (the actuated joints of
a two-loop robot, the Robotiq 2F-85 of test/data/urdf, and one joint it does
not have, each with a velocity) at ``--rate`` Hz (1 kHz by default) from a
deadline thread, and subscribes without decoding to ``joint_states``. The
relay is either:

- the node: ``scene:=ROBOT.urdf``, ``loop_closures``, ``drive:=topic``
  (``extra_joints`` is ``pass`` in URDF mode): it solves both loops, answers
  every joint under the URDF's names, passes the other joint through and
  publishes ``joint_states``, ``joint_accelerations`` and
  ``point_accelerations``;
- the *floor*: a bare rclpy process that receives each message (raw bytes)
  and publishes one pre-serialized ``joint_states`` of the node's size with
  the input's stamp patched in (no decoding, no solving, no rendering).

After ``--warmup`` s each run measures, for ``--seconds``:

- CPU: user + system time of the relay process (all threads, DDS included)
  over wall time, % of one core, from /proc; and per input sent in that
  time, µs (the fairer figure where the driver, on a loaded machine, sends
  fewer than the rate asks);
- answered: inputs of the measured stretch whose ``joint_states`` arrived,
  over the inputs sent;
- latency: ``joint_states``' arrival minus the input's send time, median, µs.

Node and floor alternate, ``--repeat`` times each. The goal (issue 31): the
node's CPU within 1.3x of the floor's, every message answered.

Usage (with the package importable, e.g. ``make``'s .venv)::

    python bench/urdf_node_bench.py [--rate 1000] [--seconds 20] [--repeat 3] [--out FILE]
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

DATA = Path(__file__).resolve().parents[1] / 'test' / 'data' / 'urdf'
ROBOT = 'robotiq_2f_85'
#: A joint of the motors' message that the robot does not have (passed through).
OTHER = 'wrist_3_joint'


def _paths(robot: str) -> tuple[Path, Path]:
    return DATA / f'{robot}.urdf', DATA / f'{robot}.loop_closures.yaml'


def _template(names: list[str]) -> object:
    """Return a JointState template of ``names``' positions and velocities."""
    from sensor_msgs.msg import JointState

    from mech_kinematics.ros.cdr import marker, MessageTemplate, STAMP_MARKER

    n = len(names)
    msg = JointState(name=names, position=[marker(i) for i in range(n)],
                     velocity=[marker(n + i) for i in range(n)])
    msg.header.stamp.sec, msg.header.stamp.nanosec = STAMP_MARKER
    msg.header.frame_id = 'mechanism'
    return MessageTemplate(msg, 2 * n)


def floor(namespace: str, robot: str) -> None:
    """Publish one pre-serialized joint_states of the node's size per input, its stamp patched."""
    from sensor_msgs.msg import JointState

    from mech_kinematics.robot import load_robot

    names = [*load_robot(*_paths(robot)).joint_names, OTHER]
    payload = _template(names).render(0, 0, [0.1] * (2 * len(names)))
    relay_floor(namespace, [(JointState, 'joint_states')], [payload])


def drive(namespace: str, robot: str, rate: float, seconds: float, out: str) -> None:
    """Publish the motors at ``rate`` for ``seconds``; note send and arrival times; write them."""
    from sensor_msgs.msg import JointState

    from mech_kinematics.robot import load_robot

    model = load_robot(*_paths(robot))
    template = _template([*model.actuated, OTHER])
    starts = [model.start(name) for name in model.actuated]

    def render(t: int) -> bytes:
        phase = 2.0 * (t % (10 * NS)) / NS
        positions = [s + 0.3 * math.sin(phase) for s in starts]
        speeds = [0.6 * math.cos(phase) for _ in starts]
        return template.render(*divmod(t, NS), (*positions, 0.25, *speeds, -1.5))

    ros_runs.drive(namespace, 'urdf_bench_driver', rate, seconds, out, render,
                   [(JointState, 'joint_states')])


def measure(kind: str, args: argparse.Namespace, env: dict[str, str],
            tmp: Path) -> dict[str, float]:
    """Run the node or the floor with a driver; return the run's figures."""
    namespace = f'/urdf_bench_{os.getpid()}_{kind}_{random.randrange(10 ** 6)}'
    out = tmp / f'{namespace[1:]}.json'
    urdf, closures = _paths(args.robot)
    if kind == 'node':
        command = [sys.executable, '-m', 'mech_kinematics.kinematics_node', '--ros-args',
                   '-r', f'__ns:={namespace}', '-p', f'scene:={urdf}', '-p',
                   f'loop_closures:={closures}', '-p', 'drive:=topic', '--log-level', 'warn']
    else:
        command = [sys.executable, __file__, '--floor', namespace, args.robot]
    total = args.warmup + args.seconds
    driver = [sys.executable, __file__, '--drive', namespace, args.robot, str(args.rate),
              str(total), str(out)]
    cpu, wall0, wall1 = relay_run(command, driver, out, args.warmup, args.seconds, env)
    data = json.loads(out.read_text())
    sent = data['sent']
    measured = sent[int(len(sent) * args.warmup / total):]
    arrived = dict(data['arrivals']['joint_states'])
    latencies = [(arrived[t] - at) / 1e3 for t, at in measured if t in arrived]
    # The inputs sent while the CPU was measured (one monotonic clock for all processes).
    within = sum(1 for _, at in sent if wall0 * NS <= at <= wall1 * NS)
    return {'kind': kind, 'cpu_pct': 100 * cpu / (wall1 - wall0),
            'cpu_us_per_input': 1e6 * cpu / max(within, 1),
            'latency_median_us': statistics.median(latencies) if latencies else math.nan,
            'latency_p99_us': quantile(latencies, 0.99) if latencies else math.nan,
            'answered': len(latencies) / len(measured), 'inputs': len(measured)}


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark; print a Markdown table (and write JSON with ``--out``)."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--rate', type=float, default=1000.0, help='input rate, Hz')
    parser.add_argument('--robot', default=ROBOT, help='a robot of test/data/urdf')
    parser.add_argument('--seconds', type=float, default=20.0, help='measured time per run')
    parser.add_argument('--warmup', type=float, default=3.0, help='settling time per run')
    parser.add_argument('--repeat', type=int, default=3, help='runs of each, alternating')
    parser.add_argument('--out', help='write the figures as JSON to this file')
    parser.add_argument('--drive', nargs=5, help=argparse.SUPPRESS)
    parser.add_argument('--floor', nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.drive:
        namespace, robot, rate, seconds, out = args.drive
        drive(namespace, robot, float(rate), float(seconds), out)
        return 0
    if args.floor:
        floor(*args.floor)
        return 0
    env = ros_env()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.repeat):
            for kind in ('floor', 'node'):
                row = measure(kind, args, env, Path(tmp))
                rows.append(row)
                print(f'{kind}: CPU {row["cpu_pct"]:.1f} %, latency median '
                      f'{row["latency_median_us"]:.0f} us, answered '
                      f'{100 * row["answered"]:.2f} % of {row["inputs"]}', file=sys.stderr,
                      flush=True)
    result: dict = {'date': datetime.date.today().isoformat(), 'robot': args.robot,
                    'rate': args.rate, 'seconds': args.seconds, 'repeat': args.repeat,
                    'cpus': os.cpu_count(), 'load': os.getloadavg()[0]}
    for kind in ('floor', 'node'):
        runs = [r for r in rows if r['kind'] == kind]
        result[kind] = {'cpu_pct': statistics.median(r['cpu_pct'] for r in runs),
                        'cpu_us_per_input': statistics.median(r['cpu_us_per_input']
                                                              for r in runs),
                        'latency_median_us': statistics.median(r['latency_median_us']
                                                               for r in runs),
                        'answered_min': min(r['answered'] for r in runs), 'runs': runs}
    result['cpu_ratio'] = result['node']['cpu_pct'] / result['floor']['cpu_pct']
    result['cpu_per_input_ratio'] = (result['node']['cpu_us_per_input']
                                     / result['floor']['cpu_us_per_input'])
    f, n = result['floor'], result['node']
    print(f'URDF mode ({args.robot}, two loops) in topic drive at {args.rate:g} Hz vs the rclpy '
          f'relay floor, {args.seconds:g} s per run, {args.repeat} runs each, alternating; '
          f'{os.cpu_count()} cores, load average {result["load"]:.1f}\n')
    print('| CPU, floor / node (%) | node / floor | CPU per input, floor / node (µs) | '
          'node / floor | latency median, floor / node (µs) | answered, floor / node '
          '(worst run) |')
    print('|---:|---:|---:|---:|---:|---:|')
    print(f'| {f["cpu_pct"]:.1f} / {n["cpu_pct"]:.1f} | {result["cpu_ratio"]:.2f} | '
          f'{f["cpu_us_per_input"]:.0f} / {n["cpu_us_per_input"]:.0f} | '
          f'{result["cpu_per_input_ratio"]:.2f} | '
          f'{f["latency_median_us"]:.0f} / {n["latency_median_us"]:.0f} | '
          f'{100 * f["answered_min"]:.2f} / {100 * n["answered_min"]:.2f} % |')
    if args.out:
        Path(args.out).write_text(json.dumps(result, indent=1, sort_keys=True) + '\n')
    return 0


if __name__ == '__main__':
    sys.exit(main())
