# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""What the forces cost the node, and the array path over a turn (a script, not a test).

Issue 32's goals, measured against the same scene without its forces, both
sides in the same run, alternating, medians of ``--repeat`` runs:

- ``tick``: the node's tick of every packaged scene with masses, gravity or
  loads (:class:`~mech_kinematics.ros.wrenches.ForcesTick`: the motion by the
  general solver, then the forces) against the kinematics-only tick of the
  same scene (the compiled tick the node serves without forces, and the
  general tick); goal at most 1.5x. Per tick, µs; with ``--profile``, where
  a forces tick's time goes (cProfile, the top functions by own time);
- ``array``: ``mk.solve`` over a turn of 360 crank angles (or each driver's
  start with the positions swept) with the forces against the same scene's
  motion alone; goal within 2x;
- ``node`` (``--node``): the node on a scene with forces at 1 kHz (``--rate``) against
  the rclpy floor of ``node_bench.py`` publishing the same messages (the
  three state messages and one WrenchStamped per reaction and the shaking),
  CPU of the publishing process; goal within 1.3x.

Usage (with the package importable, e.g. ``make``'s .venv)::

    python bench/node_forces_bench.py [--repeat 5] [--profile]
    python bench/node_forces_bench.py --node [--scene engine] [--seconds 20]
"""

from __future__ import annotations

import argparse
import cProfile
from dataclasses import replace
import io
import math
import os
from pathlib import Path
import pstats
import random
import statistics
import sys
import tempfile
import time

sys.path.insert(0, str(Path(__file__).resolve().parent))
import node_bench  # noqa: E402
import numpy as np  # noqa: E402
from ros_runs import publish_on_grid, ros_env  # noqa: E402

import mech_kinematics as mk  # noqa: E402
from mech_kinematics.ros.ticker import compiled_tick, general_tick  # noqa: E402
from mech_kinematics.ros.wrenches import ForcesTick  # noqa: E402

#: The packaged scenes with masses, gravity or loads.
LOADED = ('engine', 'shaper', 'five_bar_payload', 'excavator_loaded', 'khurmi_engine_15_7',
          'singh_petrol_engine_13_15')
TOL = 1e-6


def _drivers(scene: mk.Scene) -> tuple:
    d = scene.drivers
    if len(d) == 1:
        return d[0].start, d[0].speed, d[0].accel
    return [x.start for x in d], [x.speed for x in d], [x.accel for x in d]


def _motion(scene: mk.Scene) -> mk.Scene:
    return replace(scene, gravity=None, masses=(), loads=(), outputs_joints=scene.output_joints,
                   outputs_points=scene.output_points)


def _per_call_us(call, count: int) -> float:
    start = time.perf_counter()
    for _ in range(count):
        call()
    return (time.perf_counter() - start) / count * 1e6


def tick_rows(repeat: int, count: int) -> list[dict]:
    """Return per scene the µs of a forces tick and of the kinematics-only ticks (medians)."""
    rows = []
    for name in LOADED:
        scene = mk.load_scene(name)
        joints, points = scene.output_joints, scene.output_points
        forces = ForcesTick(scene, joints, points, (), static=False)
        compiled = compiled_tick(scene, joints, points)
        general = general_tick(scene, joints, points, ())
        theta, omega, alpha = _drivers(scene)
        turns = 0 if len(scene.drivers) == 1 else [0] * len(scene.drivers)
        given = (theta, omega, alpha, TOL, turns)
        calls = {'forces': lambda f=forces, a=given: f(*a),
                 'compiled': lambda f=compiled, a=given: f(*a),
                 'general': lambda f=general, a=given: f(*a)}
        times: dict[str, list[float]] = {k: [] for k in calls}
        for call in calls.values():
            call()      # warm
        for _ in range(repeat):
            for key, call in calls.items():
                times[key].append(_per_call_us(call, count))
        medians = {k: statistics.median(v) for k, v in times.items()}
        rows.append({'scene': name, **medians,
                     'vs_compiled': medians['forces'] / medians['compiled'],
                     'vs_general': medians['forces'] / medians['general']})
    return rows


def array_rows(repeat: int) -> list[dict]:
    """Return per scene the ms of a 360-instant array solve with and without the forces."""
    rows = []
    for name in LOADED:
        scene = mk.load_scene(name)
        motion = _motion(scene)
        theta, omega, alpha = _drivers(scene)
        if len(scene.drivers) == 1:
            angles = np.linspace(0.0, 2 * math.pi, 360, endpoint=False)
            args = (angles, omega, alpha)
        else:   # the first driver swept over a small range about its start, others held
            first = np.full(360, theta[0]) + np.linspace(-0.01, 0.01, 360) * (
                1.0 if scene.drivers[0].joint_type.angular else 0.1)
            positions = [first] + [np.full(360, t) for t in theta[1:]]
            args = (positions, [np.full(360, w) for w in omega],
                    [np.full(360, a) for a in alpha])
        times: dict[str, list[float]] = {'forces': [], 'motion': []}
        for _ in range(repeat):
            for key, s in (('forces', scene), ('motion', motion)):
                start = time.perf_counter()
                mk.solve(s, *args, max_error=TOL)
                times[key].append((time.perf_counter() - start) * 1e3)
        medians = {k: statistics.median(v) for k, v in times.items()}
        rows.append({'scene': name, **medians, 'ratio': medians['forces'] / medians['motion']})
    return rows


def profile(name: str, count: int) -> str:
    """Return the top functions of a forces tick of ``name`` by own time (cProfile)."""
    scene = mk.load_scene(name)
    tick = ForcesTick(scene, scene.output_joints, scene.output_points, (), static=False)
    args = (*_drivers(scene), TOL, 0 if len(scene.drivers) == 1 else [0] * len(scene.drivers))
    tick(*args)
    profiler = cProfile.Profile()
    profiler.enable()
    for _ in range(count):
        tick(*args)
    profiler.disable()
    out = io.StringIO()
    pstats.Stats(profiler, stream=out).sort_stats('tottime').print_stats(15)
    return out.getvalue()


# -- the node against the floor ----------------------------------------------------------


def floor(namespace: str, rate: float, scene_name: str) -> None:
    """Publish a forces tick's messages of ``scene_name``, pre-serialized, on an exact grid."""
    from geometry_msgs.msg import WrenchStamped
    from sensor_msgs.msg import JointState
    from trajectory_msgs.msg import JointTrajectory, MultiDOFJointTrajectory

    from mech_kinematics.ros import topics
    from mech_kinematics.ros.messages import TickMessages
    from mech_kinematics.ros.wrenches import ForceMessages

    scene = mk.load_scene(scene_name)
    joints, points = scene.output_joints, scene.output_points
    tick = ForcesTick(scene, joints, points, (), static=False)
    values, _ = tick(*_drivers(scene), TOL, 0)
    payloads = [*TickMessages(joints, points, 'mechanism',
                              efforts_first=tick.forces_first).render_values(values, 0, 0),
                *ForceMessages('mechanism', len(joints), len(tick.reactions)).render(
                    values, tick.forces_first, 0, 0)]
    types = [(JointState, topics.JOINT_STATES), (JointTrajectory, topics.JOINT_ACCELERATIONS),
             (MultiDOFJointTrajectory, topics.POINT_ACCELERATIONS)]
    types += [(WrenchStamped, topics.reaction_topic(j.name)) for j in tick.reactions]
    types.append((WrenchStamped, topics.SHAKING))
    publish_on_grid(namespace, rate, types, payloads)


def measure(kind: str, scene: str, args: argparse.Namespace, env: dict[str, str],
            tmp: Path) -> dict[str, float]:
    """Run the node or the floor at ``--rate`` on ``scene`` with a subscriber; CPU, delivered."""
    namespace = f'/fbench_{os.getpid()}_{kind}_{random.randrange(10 ** 6)}'
    command = (node_bench.node_command(namespace, scene, args.rate) if kind == 'node' else
               [sys.executable, __file__, '--floor', namespace, str(args.rate), scene])
    return {'kind': kind, **node_bench.run_publisher(command, namespace, args.rate, args, env,
                                                     tmp)}


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and print Markdown tables."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--repeat', type=int, default=5, help='runs of each, alternating')
    parser.add_argument('--count', type=int, default=500, help='ticks per timed run')
    parser.add_argument('--profile', action='store_true', help="profile engine's forces tick")
    parser.add_argument('--node', action='store_true', help='the node at 1 kHz vs the floor')
    parser.add_argument('--scene', default='engine', help='the scene of --node')
    parser.add_argument('--rate', type=float, default=1000.0, help='--node: rate_hz')
    parser.add_argument('--seconds', type=float, default=20.0, help='--node: time per run')
    parser.add_argument('--warmup', type=float, default=5.0, help='--node: settling time')
    parser.add_argument('--floor', nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.floor:
        namespace, rate, scene = args.floor
        floor(namespace, float(rate), scene)
        return 0
    load = os.getloadavg()[0]
    print(f'{os.cpu_count()} cores, load average {load:.1f} at the start\n')
    if args.node:
        env = ros_env()
        rows = []
        with tempfile.TemporaryDirectory() as tmp:
            for _ in range(args.repeat):
                for kind in ('floor', 'node'):
                    row = measure(kind, args.scene, args, env, Path(tmp))
                    rows.append(row)
                    print(f'{kind}: {row["cpu"]:.1f} %, delivered '
                          f'{100 * row["delivered"]:.3f} %', file=sys.stderr, flush=True)
        f_cpu = [r['cpu'] for r in rows if r['kind'] == 'floor']
        n_cpu = [r['cpu'] for r in rows if r['kind'] == 'node']
        print(f'node on {args.scene} (forces) vs the floor publishing the same messages, '
              f'{args.rate:g} Hz, {args.seconds:g} s per run; load average '
              f'{os.getloadavg()[0]:.1f} at the end\n')
        print('| floor CPU % (runs) | node CPU % (runs) | node / floor (medians) | '
              'delivered floor / node (worst) |\n|---:|---:|---:|---:|')
        print(f'| {" / ".join(f"{c:.1f}" for c in f_cpu)} | '
              f'{" / ".join(f"{c:.1f}" for c in n_cpu)} | '
              f'{statistics.median(n_cpu) / statistics.median(f_cpu):.2f} | '
              f'{100 * min(r["delivered"] for r in rows if r["kind"] == "floor"):.3f} % / '
              f'{100 * min(r["delivered"] for r in rows if r["kind"] == "node"):.3f} % |')
        return 0
    print(f'The tick, µs (medians of {args.repeat} runs of {args.count} ticks, alternating)\n')
    print('| scene | forces tick | compiled tick (no forces) | general tick (no forces) | '
          'forces / compiled | forces / general |\n|---|---:|---:|---:|---:|---:|')
    for r in tick_rows(args.repeat, args.count):
        print(f'| {r["scene"]} | {r["forces"]:.1f} | {r["compiled"]:.1f} | '
              f'{r["general"]:.1f} | {r["vs_compiled"]:.1f} | {r["vs_general"]:.1f} |')
    print(f'\nThe array path over 360 instants, ms (medians of {args.repeat} runs)\n')
    print('| scene | with forces | motion alone | ratio |\n|---|---:|---:|---:|')
    for r in array_rows(args.repeat):
        print(f'| {r["scene"]} | {r["forces"]:.2f} | {r["motion"]:.2f} | {r["ratio"]:.2f} |')
    print(f'\nload average {os.getloadavg()[0]:.1f} at the end')
    if args.profile:
        print('\nengine forces tick, by own time:\n')
        print(profile('engine', args.count))
    return 0


if __name__ == '__main__':
    sys.exit(main())
