# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Forces against kinematics: the cost of one instant's forces and of an array's (issue 32).

For every packaged scene with masses, in the same run and interleaved so
both meet the same machine:

- **single**: ``mk.solve``'s kinematics alone at one instant (``_kinematics``,
  the path ``mk.solve`` takes: compiled where the scene compiles, warmed past
  ``COMPILE_AFTER``), the forces alone at that state
  (``scene.dynamics.forces``: written out once warmed, ``Dynamics._write``),
  the general path's forces (``Dynamics._forces``, the dense solve every
  instant took before) and the whole ``mk.solve`` (kinematics, forces and the
  state rebuilt with them), in microseconds per instant, over a turn of
  instants (each driver swept over its range);
- **array**: the same for arrays of 360 and 100,000 configurations (the array
  path, warmed past ``ARRAY_COMPILE_AFTER``), in microseconds per
  configuration.

Each figure is the median of ``--repeat`` runs; the load average is printed
with them. ``--profile SCENE`` runs cProfile over the single path's forces
and prints where the time goes. Not a timed test (a shared 2-core machine
is too noisy to assert on). Run:
``.venv/bin/python bench/forces_bench.py [--repeat 7] [--json]``.
"""

from __future__ import annotations

import argparse
import cProfile
import json
import math
import os
import pstats
import statistics
import time

import numpy as np

import mech_kinematics as mk
from mech_kinematics.bounds import MAX_ERROR
from mech_kinematics.solver.forces import ARRAY_COMPILE_AFTER
from mech_kinematics.solver.solve import _kinematics

SIZES = (360, 100_000)


def _scenes():
    """Return the packaged scenes with masses, by name."""
    return {name: mk.load_scene(name) for name in mk.scene_names()
            if mk.load_scene(name).dynamics is not None}


def _sweep(scene, n):
    """Return ``n`` configurations of ``scene``: each driver over its turn or stroke."""
    columns = []
    for driver in scene.drivers:
        if driver.joint_type.angular:
            columns.append(driver.start + np.linspace(0.0, 2 * math.pi, n, endpoint=False))
        else:
            low, high = driver.stroke
            columns.append(np.linspace(low, high, n + 2)[1:-1])
    return columns


def _args(scene, columns, i=None):
    """Return ``mk.solve``'s positional angle: one driver's bare, several as a list."""
    values = [c if i is None else float(c[i]) for c in columns]
    return values[0] if len(values) == 1 else values


def _per_call(fn, calls):
    """Return the time of ``fn(i)`` over ``calls`` calls, us per call."""
    start = time.perf_counter_ns()
    for i in range(calls):
        fn(i)
    return (time.perf_counter_ns() - start) / calls / 1e3


def single(scene, repeat, calls=360):
    """Return median us per instant: kinematics, forces, general forces, the whole ``mk.solve``.

    The forces are timed at a state fresh from the kinematics (as ``mk.solve``
    and the node meet it): they include building the kinematic bounds and
    scales the state builds on first use, which the kinematics alone never ask.
    """
    columns = _sweep(scene, calls)
    angles = [_args(scene, columns, i) for i in range(calls)]
    for _ in range(2):      # past COMPILE_AFTER: the compiled tick where the scene compiles
        for a in angles:
            _kinematics(scene, a)
    dynamics = scene.dynamics
    for a in angles:
        mk.solve(scene, a)
    clock = time.perf_counter_ns
    runs = {'kinematics': [], 'forces': [], 'general': [], 'solve': []}
    for _ in range(repeat):
        spent = {'kinematics': 0, 'forces': 0, 'general': 0}
        for a in angles:
            start = clock()
            state = _kinematics(scene, a)
            middle = clock()
            dynamics.forces(state, MAX_ERROR)
            end = clock()
            spent['kinematics'] += middle - start
            spent['forces'] += end - middle
        for a in angles:
            state = _kinematics(scene, a)
            start = clock()
            dynamics._forces(state, MAX_ERROR)
            spent['general'] += clock() - start
        for key, ns in spent.items():
            runs[key].append(ns / calls / 1e3)
        runs['solve'].append(_per_call(lambda i: mk.solve(scene, angles[i]), calls))
    return {k: statistics.median(v) for k, v in runs.items()}


def array(scene, n, repeat):
    """Return median us per configuration of an array of ``n``: kinematics, forces, solve."""
    angle = _args(scene, _sweep(scene, n))
    for _ in range(20):     # past ARRAY_COMPILE_AFTER
        state = _kinematics(scene, angle)
    dynamics = scene.dynamics
    for _ in range(ARRAY_COMPILE_AFTER + 2):    # written out
        dynamics.forces(state, MAX_ERROR)
    runs = {'kinematics': [], 'forces': [], 'general': [], 'solve': []}
    calls = max(1, 3600 // n)
    for _ in range(repeat):
        runs['kinematics'].append(_per_call(lambda i: _kinematics(scene, angle), calls) / n)
        runs['forces'].append(_per_call(lambda i: dynamics.forces(state, MAX_ERROR),
                                        calls) / n)
        runs['general'].append(_per_call(lambda i: dynamics._forces(state, MAX_ERROR),
                                         calls) / n)
        runs['solve'].append(_per_call(lambda i: mk.solve(scene, angle), calls) / n)
    return {k: statistics.median(v) for k, v in runs.items()}


def profile(scene, calls=2000):
    """Print cProfile's view of ``calls`` single-instant forces of ``scene``."""
    columns = _sweep(scene, calls)
    states = [_kinematics(scene, _args(scene, columns, i)) for i in range(calls)]
    dynamics = scene.dynamics
    profiler = cProfile.Profile()
    profiler.enable()
    for state in states:
        dynamics.forces(state, MAX_ERROR)
    profiler.disable()
    pstats.Stats(profiler).sort_stats('tottime').print_stats(18)
    if dynamics._fast:
        print(f'written out: {len(dynamics._fast)} function(s), the first '
              f'{dynamics._fast[0].source.count(chr(10))} lines')


def main(argv=None):
    """Run the bench; print a table (or JSON)."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--repeat', type=int, default=7)
    parser.add_argument('--scenes', nargs='*')
    parser.add_argument('--sizes', nargs='*', type=int, default=list(SIZES))
    parser.add_argument('--json', action='store_true')
    parser.add_argument('--profile', metavar='SCENE')
    args = parser.parse_args(argv)
    if args.profile:
        profile(mk.load_scene(args.profile))
        return
    scenes = _scenes()
    names = args.scenes or sorted(scenes)
    load = os.getloadavg()[0]
    results = {}
    for name in names:
        scene = scenes[name]
        results[name] = {'single': single(scene, args.repeat)}
        for n in args.sizes:
            results[name][f'array_{n}'] = array(scene, n, max(3, args.repeat // 2))
    results['load'] = [load, os.getloadavg()[0]]
    if args.json:
        print(json.dumps(results, indent=1))
        return
    print(f'load average {load:.1f} before, {results["load"][1]:.1f} after; medians of '
          f'{args.repeat} runs; us per instant (arrays: per configuration)')
    print(f'{"scene":26s} {"path":12s} {"kinematics":>10s} {"forces":>8s} {"ratio":>6s} '
          f'{"general":>8s} {"ratio":>6s} {"solve":>8s}')
    for name in names:
        for path, r in results[name].items():
            print(f'{name:26s} {path:12s} {r["kinematics"]:10.2f} {r["forces"]:8.2f} '
                  f'{r["forces"] / r["kinematics"]:6.2f} {r["general"]:8.2f} '
                  f'{r["general"] / r["kinematics"]:6.2f} {r["solve"]:8.2f}')


if __name__ == '__main__':
    main()
