# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Benchmark of the running kinematics_node against the rclpy floor (a script, not a test).

The *floor* is a bare rclpy process that only publishes three pre-serialized
messages of the node's sizes from a deadline thread on the same exact grid
(no solving, no rendering: it patches the stamp and publishes). Each run
starts one publisher (the node or the floor) and one subscriber in another
process, lets them settle, then measures for ``--seconds``:

- CPU: user + system time of the whole publishing process (all threads, DDS
  included) over wall time, % of one core, from /proc;
- delivered: grid instants the subscriber received on every state topic over
  the grid instants in the same stretch of stamps (the subscriber uses
  ``raw=True`` subscriptions and reads ``header.stamp`` from the bytes with
  :func:`mech_kinematics.ros.cdr.stamp_from_cdr`);
- skipped: instants the node counted as skipped (beyond ``max_catch_up_s``),
  from its ``diagnostics``.

The node and the floor alternate, ``--repeat`` times each, in one run, so
that both meet the same machine: read the ratio, not the times.

``--chains`` measures a scene that grows: one crank driving 1, 4, 16 and 64
four-bar dyads (a machine's main shaft), node and floor (messages of the same
sizes) at 1 kHz.

Usage (with the package importable, e.g. ``make``'s .venv)::

    python bench/node_bench.py [--rates 1000 5000] [--seconds 60] [--repeat 3]
    python bench/node_bench.py --chains [--seconds 20]
    python bench/node_bench.py --udp --rates 1000   # the node on UDPv4 against its default

``--data docs/report/data.json`` stores the figures in the report's data file
(under ``node_rates``, or ``node_chains`` with ``--chains``; the report keeps
them), from which docs/accuracy.md quotes them.
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
from pathlib import Path
import random
import signal
import statistics
import subprocess
import sys
import tempfile
import time

from ros_runs import cpu_seconds, NS, publish_on_grid, qos, ros_env

STATE_TOPICS = ('joint_states', 'joint_accelerations', 'point_accelerations')
SCENE = 'khurmi_four_bar_ad150'
CHAIN_SIZES = (1, 4, 16, 64)


def shaft_scene(dyads: int) -> str:
    """Return the YAML of one crank driving ``dyads`` four-bar dyads about one shaft.

    Each dyad is the packaged four-bar (AB 40, BC 150, CD 80, AD 150 mm, a
    Grashof crank-rocker that assembles at every angle) turned about A.
    """
    lines = [f'name: chain_{dyads}', 'units: {length: mm, angle: deg}', 'ground:',
             '  A: [0, 0]']
    for i in range(dyads):
        turn = 2 * math.pi * i / dyads
        lines.append(f'  D{i}: [{150 * math.cos(turn):.6f}, {150 * math.sin(turn):.6f}]')
    lines += ['input: {link: crank, center: A, point: B, length: 40, angle: 60, '
              'speed_rpm: -120}', 'dyads:']
    for i in range(dyads):
        lines.append(f'  - {{type: RRR, point: C{i}, links: [{{name: coupler{i}, from: B, '
                     f'length: 150}}, {{name: rocker{i}, from: D{i}, length: 80}}], '
                     'branch: 1}')
    return '\n'.join(lines) + '\n'


# -- the floor: a bare publisher on the same grid ------------------------------------


def floor(namespace: str, rate: float, scene_name: str) -> None:
    """Publish the three state messages of ``scene_name``, pre-serialized, on an exact grid."""
    from sensor_msgs.msg import JointState
    from trajectory_msgs.msg import JointTrajectory, MultiDOFJointTrajectory

    import mech_kinematics as mk
    from mech_kinematics.ros.messages import TickMessages

    scene = mk.load_scene(scene_name)
    state = mk.solve(scene, scene.input.angle)
    payloads = TickMessages(scene.output_joints, scene.output_points, 'mechanism').render(
        state, 0, 0)
    types = (JointState, JointTrajectory, MultiDOFJointTrajectory)
    publish_on_grid(namespace, rate, list(zip(types, STATE_TOPICS, strict=True)), payloads)


# -- the subscriber -------------------------------------------------------------------


def subscribe(namespace: str, seconds: float, out: str) -> None:
    """Record the stamps of every state message and the diagnostics, then write them out."""
    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray
    from sensor_msgs.msg import JointState
    from trajectory_msgs.msg import JointTrajectory, MultiDOFJointTrajectory

    from mech_kinematics.ros.cdr import stamp_from_cdr

    rclpy.init()
    node = rclpy.create_node('node_bench_subscriber', namespace=namespace)
    received: dict[str, list[bytes]] = {t: [] for t in STATE_TOPICS}
    for topic, msg_type in zip(STATE_TOPICS,
                               (JointState, JointTrajectory, MultiDOFJointTrajectory),
                               strict=True):
        sink = received[topic]
        node.create_subscription(msg_type, topic, lambda data, sink=sink: sink.append(data[:12]),
                                 qos(), raw=True)
    diagnostics: list[dict[str, str]] = []

    def on_diagnostics(msg: DiagnosticArray) -> None:
        diagnostics.append({kv.key: kv.value for s in msg.status for kv in s.values})

    node.create_subscription(DiagnosticArray, 'diagnostics', on_diagnostics, 10)
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.1)
    node.destroy_node()
    rclpy.try_shutdown()
    Path(out).write_text(json.dumps({
        'diagnostics': diagnostics,
        'stamps': {t: [stamp_from_cdr(d) for d in v] for t, v in received.items()}}))


# -- the driver ----------------------------------------------------------------------


def _delivered(stamps: dict[str, list[int]], period: int, lo: int, hi: int) -> float:
    """Return the least, over the topics, of grid instants in [lo, hi] received over owed."""
    owed = (hi - lo) // period + 1
    return min(len({s for s in v if lo <= s <= hi}) / owed for v in stamps.values())


def run_publisher(command: list[str], namespace: str, rate: float, args: argparse.Namespace,
                  env: dict[str, str], tmp: Path,
                  publisher_env: dict[str, str] | None = None) -> dict[str, float]:
    """Run ``command`` (the node or a floor) publishing in ``namespace`` at ``rate``, measured.

    A subscriber in another process records every state message's stamp and
    the diagnostics. Returns the publisher's ``cpu`` (% of a core over
    ``args.seconds`` after ``args.warmup``), the ``delivered`` fraction of
    grid instants and, from the node's diagnostics, ``skipped`` instants.
    ``publisher_env``: the publisher's own environment (default ``env``).
    """
    out = tmp / f'{namespace[1:]}.json'
    listen = args.warmup + args.seconds + 2.0
    sub = subprocess.Popen([sys.executable, __file__, '--subscribe', namespace, str(listen),
                            str(out)], env=env)
    time.sleep(1.0)     # the subscriber is there before the first message
    publisher = subprocess.Popen(command, env=env if publisher_env is None else publisher_env)
    try:
        time.sleep(args.warmup)
        cpu0, wall0, stamp0 = cpu_seconds(publisher.pid), time.monotonic(), time.time_ns()
        time.sleep(args.seconds)
        cpu1, wall1, stamp1 = cpu_seconds(publisher.pid), time.monotonic(), time.time_ns()
    finally:
        publisher.send_signal(signal.SIGINT)
        publisher.wait(timeout=10)
        sub.wait(timeout=60)
    data = json.loads(out.read_text())
    period = round(NS / rate)
    lo = -(-stamp0 // period) * period
    hi = stamp1 // period * period
    row = {'cpu': 100 * (cpu1 - cpu0) / (wall1 - wall0),
           'delivered': _delivered(data['stamps'], period, lo, hi)}
    if data['diagnostics']:
        last = data['diagnostics'][-1]
        row['skipped'] = int(last.get('skipped_ticks_total', 0))
    return row


def node_command(namespace: str, scene: str, rate: float) -> list[str]:
    """Return the command of the node on ``scene`` at ``rate`` in ``namespace``."""
    return [sys.executable, '-m', 'mech_kinematics.kinematics_node', '--ros-args',
            '-r', f'__ns:={namespace}', '-p', f'scene:={scene}', '-p', f'rate_hz:={rate}',
            '--log-level', 'warn']


def measure(kind: str, rate: float, scene: str, args: argparse.Namespace,
            env: dict[str, str], tmp: Path) -> dict[str, float]:
    """Run the node or the floor at ``rate`` with a subscriber; return the row of the table."""
    namespace = f'/bench_{os.getpid()}_{kind}_{int(rate)}_{random.randrange(10 ** 6)}'
    command = (node_command(namespace, scene, rate) if kind.startswith('node') else
               [sys.executable, __file__, '--floor', namespace, str(rate), scene])
    # 'node_udp': the node alone on Fast DDS's UDPv4 transport (no shared memory).
    publisher_env = {**env, 'FASTDDS_BUILTIN_TRANSPORTS': 'UDPv4'} if kind == 'node_udp' else None
    return {'kind': kind, 'rate': rate,
            **run_publisher(command, namespace, rate, args, env, tmp, publisher_env)}


def _table(rows: list[dict[str, float]], key: str) -> list[str]:
    lines = [f'| {key} | floor CPU % (runs) | node CPU % (runs) | node / floor (medians) | '
             'delivered floor / node (worst run) |', '|---:|---:|---:|---:|---:|']
    for value in dict.fromkeys(r[key] for r in rows):
        floor = [r for r in rows if r[key] == value and r['kind'] == 'floor']
        node = [r for r in rows if r[key] == value and r['kind'] == 'node']
        f_cpu = [r['cpu'] for r in floor]
        n_cpu = [r['cpu'] for r in node]
        ratio = statistics.median(n_cpu) / statistics.median(f_cpu)
        lines.append(
            f'| {value:g} | {" / ".join(f"{c:.1f}" for c in f_cpu)} | '
            f'{" / ".join(f"{c:.1f}" for c in n_cpu)} | {ratio:.2f} | '
            f'{100 * min(r["delivered"] for r in floor):.3f} % / '
            f'{100 * min(r["delivered"] for r in node):.3f} % |')
    return lines


def _udp_table(rows: list[dict[str, float]]) -> list[str]:
    lines = ['| rate Hz | node CPU % default (runs) | node CPU % UDPv4 (runs) | UDPv4 / default '
             '(medians) | delivered default / UDPv4 (worst run) |', '|---:|---:|---:|---:|---:|']
    for rate in dict.fromkeys(r['rate'] for r in rows):
        shm = [r for r in rows if r['rate'] == rate and r['kind'] == 'node']
        udp = [r for r in rows if r['rate'] == rate and r['kind'] == 'node_udp']
        ratio = statistics.median(r['cpu'] for r in udp) / statistics.median(r['cpu'] for r in shm)
        runs = [' / '.join(f'{r["cpu"]:.1f}' for r in side) for side in (shm, udp)]
        lines.append(
            f'| {rate:g} | {runs[0]} | {runs[1]} | {ratio:.2f} | '
            f'{100 * min(r["delivered"] for r in shm):.3f} % / '
            f'{100 * min(r["delivered"] for r in udp):.3f} % |')
    return lines


def _fit_slope(xs: list[float], ys: list[float]) -> float:
    """Return the least-squares slope of ``ys`` against ``xs``."""
    mx, my = statistics.fmean(xs), statistics.fmean(ys)
    return (sum((x - mx) * (y - my) for x, y in zip(xs, ys, strict=True))
            / sum((x - mx) ** 2 for x in xs))


def section(rows: list[dict[str, float]], key: str, args: argparse.Namespace) -> dict:
    """Return the figures of ``rows`` for the data file: per ``key`` value, both kinds' runs.

    Each entry: CPU % of every run of the floor and the node, the ratio of
    their medians, and the worst run's delivered fraction (%) of each. With
    ``key`` ``'dyads'`` also the growth per dyad (least squares over the
    medians): % of a core, and µs per tick at 1 kHz.
    """
    entries: dict[str, dict[str, object]] = {}
    medians: dict[str, list[float]] = {'floor': [], 'node': []}
    for value in dict.fromkeys(r[key] for r in rows):
        entry: dict[str, object] = {}
        for kind in ('floor', 'node'):
            runs = [r for r in rows if r[key] == value and r['kind'] == kind]
            cpu = [r['cpu'] for r in runs]
            medians[kind].append(statistics.median(cpu))
            entry[f'{kind}_cpu_pct'] = cpu
            entry[f'{kind}_delivered_pct'] = 100 * min(r['delivered'] for r in runs)
        entry['ratio'] = medians['node'][-1] / medians['floor'][-1]
        entries[f'{value:g}'] = entry
    out: dict[str, object] = {
        'date': datetime.date.today().isoformat(), 'seconds': args.seconds,
        'warmup': args.warmup, 'repeat': args.repeat, 'cpus': os.cpu_count(),
        'load': os.getloadavg()[0], 'scene': SCENE if key == 'rate' else 'chain_N',
        'rows': entries}
    if key == 'dyads':
        sizes = [float(v) for v in entries]
        for kind in ('floor', 'node'):
            out[f'{kind}_pct_per_dyad'] = _fit_slope(sizes, medians[kind])
        # % of a core at 1 kHz -> µs a tick: 1 % of 1 s over 1000 ticks is 10 µs
        out['node_us_per_dyad_tick'] = 10.0 * _fit_slope(sizes, medians['node'])
    return out


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and print Markdown tables."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--rates', type=float, nargs='+', default=[1000.0, 5000.0])
    parser.add_argument('--seconds', type=float, default=60.0, help='measured time per run')
    parser.add_argument('--warmup', type=float, default=5.0, help='settling time per run')
    parser.add_argument('--repeat', type=int, default=3, help='runs of each, alternating')
    parser.add_argument('--chains', action='store_true',
                        help=f'scenes of {", ".join(map(str, CHAIN_SIZES))} dyads at 1 kHz')
    parser.add_argument('--udp', action='store_true',
                        help='the node on its default transports against the node with '
                             'FASTDDS_BUILTIN_TRANSPORTS=UDPv4 (no floor), alternating')
    parser.add_argument('--json', action='store_true', help='also print the rows as JSON')
    parser.add_argument('--data', metavar='FILE',
                        help='store the figures in this data file (docs/report/data.json) '
                             'under node_rates, or node_chains with --chains')
    parser.add_argument('--subscribe', nargs=3, help=argparse.SUPPRESS)
    parser.add_argument('--floor', nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.udp and (args.chains or args.data):
        parser.error('--udp compares the node with itself: without --chains and --data')
    if args.subscribe:
        namespace, seconds, out = args.subscribe
        subscribe(namespace, float(seconds), out)
        return 0
    if args.floor:
        namespace, rate, scene = args.floor
        floor(namespace, float(rate), scene)
        return 0
    env = ros_env()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        if args.chains:
            for dyads in CHAIN_SIZES:
                path = Path(tmp) / f'chain_{dyads}.yaml'
                path.write_text(shaft_scene(dyads))
                for _ in range(args.repeat):
                    for kind in ('floor', 'node'):
                        row = measure(kind, 1000.0, str(path), args, env, Path(tmp))
                        row['dyads'] = dyads
                        rows.append(row)
                        print(f'{kind} {dyads} dyads: {row["cpu"]:.1f} %', file=sys.stderr,
                              flush=True)
            key = 'dyads'
        else:
            kinds = ('node', 'node_udp') if args.udp else ('floor', 'node')
            for rate in args.rates:
                for _ in range(args.repeat):
                    for kind in kinds:
                        row = measure(kind, rate, SCENE, args, env, Path(tmp))
                        rows.append(row)
                        print(f'{kind} {rate:g} Hz: {row["cpu"]:.1f} %, delivered '
                              f'{100 * row["delivered"]:.3f} %', file=sys.stderr, flush=True)
            key = 'rate'
    against = 'itself on UDPv4 only' if args.udp else 'the rclpy floor'
    print(f'kinematics_node vs {against}, {args.seconds:g} s per run, '
          f'{args.repeat} runs each, alternating; {os.cpu_count()} cores, load average '
          f'{os.getloadavg()[0]:.1f}\n')
    if args.udp:
        print('\n'.join(_udp_table(rows)))
    else:
        print('\n'.join(_table(rows, key)))
    if args.json:
        print(json.dumps(rows, indent=1))
    if args.data:
        from mech_kinematics.tools.report.data import store_section
        name = 'node_chains' if args.chains else 'node_rates'
        store_section(args.data, name, section(rows, key, args))
        print(f'stored under {name} in {args.data}', file=sys.stderr)
    return 0


if __name__ == '__main__':
    sys.exit(main())
