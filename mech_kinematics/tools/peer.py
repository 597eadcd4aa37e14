# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The solver side by side with pylinkage 1.3.0's numba path: ``bench --peer pylinkage``.

pylinkage (a development dependency, pinned in ``requirements-dev.txt`` with
the numba it runs on) steps a linkage through its crank angles in a
numba-compiled loop (``Linkage.step_fast`` for positions,
``step_fast_with_kinematics`` for positions, velocities and accelerations).
For the packaged four-bar and slider-crank this module builds the same
mechanism in pylinkage from the geometry of the hand-written forms
(:func:`.bench.hand_written`), checks that its answers equal ours
(:func:`check_same_answers`) before timing anything, and times, in one
process and interleaved (min / median / max of repeated runs): one angle per
call (ours: a full solve with bounds; theirs: one step of positions), 360
angles in one call and 100,000 angles in one call (both: positions,
velocities and accelerations). Their first call, which compiles (or loads
from numba's cache) the kernels, is timed apart as the cold start.

pylinkage is imported inside the functions: the package itself never needs it.
"""

from __future__ import annotations

from collections.abc import Callable
import math
import time
from typing import Any

import numpy as np

from ..scene import load_scene
from ..solver import solve

#: The peers there are, by the name ``bench --peer`` takes.
PEERS = ('pylinkage',)
#: The packaged scenes timed against the peer (each has a hand-written form).
PEER_SCENES = ('khurmi_four_bar_ad150', 'slider_crank_150_600')
#: The batch sizes timed, angles per call.
BATCHES = (360, 100_000)
#: Their answers against ours, relative to each quantity's scale (the mechanism's
#: size, times omega, times omega^2): their stepping drifts by about 1e-9 over 1e5 steps.
RTOL_PEER = 1e-8


def _pylinkage() -> Any:
    """Return the pylinkage module, or raise a ValueError saying how to install it."""
    try:
        import pylinkage
    except ImportError as error:
        msg = ('Expected pylinkage 1.3.0 installed for `bench --peer pylinkage` (a development '
               f'dependency: `make install`), got {error}')
        raise ValueError(msg) from error
    return pylinkage


def peer_linkage(kind: str, geometry: tuple[float, ...], theta0: float, speed: float,
                 steps: int, start: tuple[float, float]) -> tuple[Any, tuple[str, ...]]:
    """Return a pylinkage linkage of a four-bar or a slider-crank and its moving points' names.

    ``kind`` is ``'RRR'`` (a four-bar of :data:`.bench.FOUR_BAR_GEOMETRY`'s
    layout) or ``'RRP'`` (a slider-crank of
    :data:`.bench.SLIDER_CRANK_GEOMETRY`'s); the crank starts at ``theta0``
    (rad), turns ``2 pi / steps`` a step and ``speed`` rad/s; ``start`` is the
    output point's position at ``theta0`` (m), which picks the assembly branch.
    The names are those of the crank tip and the output point, in the order of
    the components (ground points first).
    """
    pl = _pylinkage()
    turn = math.tau / steps
    if kind == 'RRR':
        ox, oy, a, b, c, dx, dy, _ = geometry
        grounds = [pl.Ground(ox, oy, name='O'), pl.Ground(dx, dy, name='D')]
        crank = pl.Crank(anchor=grounds[0], radius=a, angular_velocity=turn,
                         initial_angle=theta0, name='B')
        out = pl.RRRDyad(anchor1=crank.output, anchor2=grounds[1], distance1=b, distance2=c,
                         x=start[0], y=start[1], name='C')
    else:
        ox, oy, r, rod, guide, _ = geometry
        grounds = [pl.Ground(ox, oy, name='O'), pl.Ground(ox, guide, name='G'),
                   pl.Ground(ox + 1.0, guide, name='H')]      # the horizontal guide
        crank = pl.Crank(anchor=grounds[0], radius=r, angular_velocity=turn,
                         initial_angle=theta0, name='B')
        out = pl.RRPDyad(revolute_anchor=crank.output, line_anchor1=grounds[1],
                         line_anchor2=grounds[2], distance=rod, x=start[0], y=start[1],
                         name='C')
    linkage = pl.Linkage([*grounds, crank, out], name=kind)
    linkage.set_input_velocity(crank, speed, 0.0)
    return linkage, ('B', 'C')


def _output(scene: Any) -> str:
    """Return the name of the point the scene's one dyad places."""
    return str(scene.dyads[0].key)


def check_same_answers(scene: Any, linkage: Any, steps: int) -> float:
    """Step ``linkage`` once round and compare with ours; return the largest relative difference.

    ``linkage`` comes from :func:`peer_linkage` for ``scene`` with ``steps``
    steps a turn. Positions, velocities and accelerations of the crank tip and
    the dyad's point are compared at every step, each relative to its scale
    (the mechanism's size, times ``|omega|``, times ``omega^2``). Raises a
    ValueError where a difference exceeds :data:`RTOL_PEER`.
    """
    theta0, speed = scene.input.angle, scene.input.speed
    angles = theta0 + math.tau / steps * np.arange(1, steps + 1)
    ours = solve(scene, angles)
    p, v, a = linkage.step_fast_with_kinematics(iterations=steps)
    count = p.shape[1]
    size = max(float(np.abs(ours.points[name].position).max())
               for name in (scene.input.point, _output(scene)))
    scales = (size, size * abs(speed), size * speed * speed)
    worst = 0.0
    for column, name in zip((count - 2, count - 1), (scene.input.point, _output(scene)),
                            strict=True):
        point = ours.points[name]
        for theirs, mine, scale, what in zip(
                (p, v, a), (point.position, point.velocity, point.acceleration), scales,
                ('position', 'velocity', 'acceleration'), strict=True):
            diff = float(np.nanmax(np.abs(theirs[:, column, :] - mine))) / scale
            if not diff <= RTOL_PEER:
                msg = (f'Expected the {what} of {name} from pylinkage on {scene.name} to '
                       f'equal ours within {RTOL_PEER:g} of its scale {scale:.3g}, got a '
                       f'difference of {diff:.3g} times it: not the same geometry')
                raise ValueError(msg)
            worst = max(worst, diff)
    return worst


def _times(funcs: list[Callable[[], Any]], number: list[int],
           repeat: int) -> list[list[float]]:
    """Return [min, median, max] seconds per call of each function, the repeats interleaved.

    Seconds of the process's CPU time, as :data:`.bench.CLOCK`: both sides run
    on one thread.
    """
    samples: list[list[float]] = [[] for _ in funcs]
    for _ in range(repeat):
        for func, count, times in zip(funcs, number, samples, strict=True):
            start = time.process_time()
            for _ in range(count):
                func()
            times.append((time.process_time() - start) / count)
    return [[min(s), float(np.median(s)), max(s)] for s in samples]


def available() -> bool:
    """Return whether the peer (pylinkage) is installed."""
    try:
        _pylinkage()
    except ValueError:
        return False
    return True


def work_items(batches: tuple[int, ...] = BATCHES) -> list[tuple[str, str]]:
    """Return (key, label) of each work item of a row: one angle, then each batch size."""
    return [('single', 'one angle per call (ours p+v+a+bounds; theirs positions)'),
            *((f'batch_{n}', f'{n:,} angles in one call, p+v+a, per configuration')
              for n in batches)]


def measure_peer(name: str, forms: Callable[[Any], Any], repeat: int,
                 batches: tuple[int, ...] = BATCHES) -> dict[str, Any]:
    """Time ``name``'s packaged scene against pylinkage; return one row of the table.

    ``forms(scene)`` returns ``(kind, geometry)`` for :func:`peer_linkage`
    (:func:`.bench.geometry_of`). The row holds ``cold_s`` (their first call),
    ``max_difference`` (:func:`check_same_answers`), and per work item
    (:func:`work_items`: ``single``, ``batch_<n>`` for each of ``batches``)
    ``ours_us`` and ``theirs_us``: [min, median, max] microseconds per
    configuration.
    """
    scene = load_scene(name)
    kind, geometry = forms(scene)
    theta0, speed = scene.input.angle, scene.input.speed
    start = tuple(float(x) for x in solve(scene, theta0).points[_output(scene)].position)
    built = {steps: peer_linkage(kind, geometry, theta0, speed, steps, start)[0]
             for steps in (1, *batches)}
    began = time.process_time()
    built[1].step_fast(iterations=1)
    built[1].step_fast_with_kinematics(iterations=1)
    cold = time.process_time() - began
    difference = check_same_answers(scene, peer_linkage(kind, geometry, theta0, speed, 360,
                                                        start)[0], 360)
    sweeps = {steps: theta0 + math.tau / steps * np.arange(1, steps + 1) for steps in batches}
    row: dict[str, Any] = {'scene': name, 'cold_s': cold, 'max_difference': difference}
    single = _times([lambda: solve(scene, theta0), lambda: built[1].step_fast(iterations=1)],
                    [1000, 1000], repeat)
    row['single'] = {'ours_us': [t * 1e6 for t in single[0]],
                     'theirs_us': [t * 1e6 for t in single[1]]}
    for steps in batches:
        sweep, linkage = sweeps[steps], built[steps]
        calls = max(1, 36_000 // steps)
        both = _times([lambda sweep=sweep: solve(scene, sweep),
                       lambda linkage=linkage, steps=steps:
                       linkage.step_fast_with_kinematics(iterations=steps)],
                      [calls, calls], repeat)
        row[f'batch_{steps}'] = {'ours_us': [t * 1e6 / steps for t in both[0]],
                                 'theirs_us': [t * 1e6 / steps for t in both[1]]}
    return row


def peer_table(rows: list[dict[str, Any]], repeat: int,
               batches: tuple[int, ...] = BATCHES) -> list[str]:
    """Return the lines ``bench --peer pylinkage`` prints for the rows of :func:`measure_peer`."""
    lines = [f'pylinkage 1.3.0 (numba) side by side, one process; min / median / max of '
             f'{repeat} runs, µs of CPU time; ratio: their median over ours (> 1: ours faster)']
    for row in rows:
        lines.append(f'{row["scene"]}: answers equal to {row["max_difference"]:.1e} of scale; '
                     f'their cold start (first calls: numba compile or cache load) '
                     f'{row["cold_s"]:.2f} s')
        lines.append(f'  {"work":58s} {"ours":>22s} {"pylinkage":>22s} {"ratio":>6s}')
        for key, label in work_items(batches):
            ours, theirs = row[key]['ours_us'], row[key]['theirs_us']
            lines.append(f'  {label:58s} {"/".join(f"{t:.3g}" for t in ours):>22s} '
                         f'{"/".join(f"{t:.3g}" for t in theirs):>22s} '
                         f'{theirs[1] / ours[1]:6.2f}')
    return lines
