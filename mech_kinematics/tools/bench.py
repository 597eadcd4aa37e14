# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Solver speed: ``python -m mech_kinematics bench`` (``make bench``).

For every packaged scene it times one full single-angle solve and the array
path per configuration over many angles (min / median / max of repeated
runs), beside hand-written closed forms of the same mechanism timed in the
same run where the scene is one crank and one dyad (:func:`hand_written`:
a four-bar, or a slider-crank on a horizontal guide), and prints the ratios
to them against issue 19's targets (:data:`SINGLE_TARGET`, :data:`ARRAY_TARGET`). The
machine is shared and noisy, so what matters is the ratios of one run.

``bench --peer pylinkage`` times the packaged four-bar and slider-crank side
by side with pylinkage 1.3.0's numba path instead (:mod:`.peer`, issue 22).
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence
from functools import partial
import json
import math
import statistics
import sys
import time
from typing import Any, NamedTuple

import numpy as np

from .cli import positive_int, run_tool
from .peer import available, BATCHES, measure_peer, PEER_SCENES, peer_table, PEERS
from ..memory import keep_freed_memory
from ..scene import load_scene, scene_names
from ..solver import solve


#: The carried points of a hand-written form, in order: (link, from its start, u, v) each,
#: the point at ``u + i v`` (m) in the frame with origin at one end of the link and
#: x-axis toward the other: its start (from its start) or its end (the dyad's new point).
Carried = tuple[tuple[int, bool, float, float], ...]


def carry(carried: Carried, links: Sequence[tuple[Any, ...]],
          ends: tuple[Any, ...]) -> tuple[Any, ...]:
    """Return the position, velocity and acceleration (x, y each) of every carried point.

    ``links[k]`` holds link k's start (x, y), its velocity and acceleration,
    a vector from its start toward its end and that vector's length, its
    angular velocity and acceleration; ``ends`` the end's position, velocity
    and acceleration (the same for every link: the dyad's new point). Plain
    arithmetic, the local coordinates scaled by the length once: floats or
    arrays alike.
    """
    out: tuple[Any, ...] = ()
    for link, forward, u, v in carried:
        sx, sy, vsx, vsy, asx, asy, ux, uy, length, w, al = links[link]
        if forward:
            ox, oy, vox, voy, aox, aoy = sx, sy, vsx, vsy, asx, asy
            u, v = u / length, v / length
        else:
            (ox, oy, vox, voy, aox, aoy), u, v = ends, -u / length, -v / length
        dx, dy = u * ux - v * uy, u * uy + v * ux
        out += (ox + dx, oy + dy, vox - w * dy, voy + w * dx,
                aox - al * dy - w * w * dx, aoy + al * dx - w * w * dy)
    return out


#: A four-bar's geometry for the hand-written forms: crank centre (x, y), crank,
#: coupler and rocker lengths, rocker pivot (x, y), branch sign (+1: C to the left
#: of B -> D). The default is the packaged four-bar (AD = 150, AB = 40, BC = 150,
#: CD = 80 mm).
FOUR_BAR_GEOMETRY = (0.0, 0.0, 0.04, 0.15, 0.08, 0.15, 0.0, 1.0)
#: A slider-crank's: crank centre (x, y), crank and rod lengths, the height of the
#: horizontal guide, side of the piston (+1: larger x). The default is the packaged
#: slider-crank (crank 150, rod 600 mm, piston on the left).
SLIDER_CRANK_GEOMETRY = (0.0, 0.0, 0.15, 0.6, 0.0, -1.0)


def four_bar_math(theta: float, w: float, al: float,
                  geometry: tuple[float, ...] = FOUR_BAR_GEOMETRY,
                  carried: Carried = ()) -> tuple[float, ...]:
    """Hand-written four-bar with :mod:`math`: link angles, rates, accelerations; B and C.

    Then each ``carried`` point's position, velocity and acceleration (x, y
    each; :func:`carry`): link 0 is the coupler B -> C, link 1 the rocker D -> C.
    """
    ox, oy, a, b, c, dx, dy, side = geometry
    bx, by = ox + a * math.cos(theta), oy + a * math.sin(theta)
    vbx, vby = -w * (by - oy), w * (bx - ox)
    abx, aby = -al * (by - oy) - w * w * (bx - ox), al * (bx - ox) - w * w * (by - oy)
    ex, ey = dx - bx, dy - by
    f = math.hypot(ex, ey)
    p = (b * b - c * c + f * f) / (2 * f)
    h = side * math.sqrt(b * b - p * p)
    cx = bx + (p * ex - h * ey) / f
    cy = by + (p * ey + h * ex) / f
    r1x, r1y, r2x, r2y = cx - bx, cy - by, cx - dx, cy - dy
    den = r1x * r2y - r1y * r2x
    w1 = (-vbx * r2x - vby * r2y) / den
    w2 = (-vbx * r1x - vby * r1y) / den
    qx = -abx + w1 * w1 * r1x - w2 * w2 * r2x
    qy = -aby + w1 * w1 * r1y - w2 * w2 * r2y
    a1 = (qx * r2x + qy * r2y) / den
    a2 = (qx * r1x + qy * r1y) / den
    vcx, vcy = vbx - w1 * r1y, vby + w1 * r1x
    acx = abx - a1 * r1y - w1 * w1 * r1x
    acy = aby + a1 * r1x - w1 * w1 * r1y
    values = (math.atan2(r1y, r1x), math.atan2(r2y, r2x), w1, w2, a1, a2,
              bx, by, vbx, vby, abx, aby, cx, cy, vcx, vcy, acx, acy)
    if not carried:
        return values
    return values + _four_bar_carried(values, (r1x, r1y, r2x, r2y), geometry, carried)


def _four_bar_carried(values: tuple[Any, ...], links: tuple[Any, ...],
                      geometry: tuple[float, ...], carried: Carried) -> tuple[Any, ...]:
    """Return the ``carried`` points of a four-bar of these ``values`` (:func:`carry`).

    ``links`` are the coupler's and the rocker's vectors toward C, (x, y) each.
    """
    w1, w2, a1, a2, bx, by, vbx, vby, abx, aby = values[2:12]
    r1x, r1y, r2x, r2y = links
    b, c, dx, dy = geometry[3:7]
    return carry(carried, ((bx, by, vbx, vby, abx, aby, r1x, r1y, b, w1, a1),
                           (dx, dy, 0.0, 0.0, 0.0, 0.0, r2x, r2y, c, w2, a2)), values[12:])


def four_bar_numpy(theta: Any, w: float, al: float,
                   geometry: tuple[float, ...] = FOUR_BAR_GEOMETRY,
                   carried: Carried = ()) -> tuple[Any, ...]:
    """Solve the same four-bar with NumPy over an array of crank angles."""
    ox, oy, a, b, c, dx, dy, side = geometry
    cos, sin = np.cos(theta), np.sin(theta)
    rx, ry = a * cos, a * sin
    bx, by = ox + rx, oy + ry
    vbx, vby = -w * ry, w * rx
    abx, aby = -al * ry - w * w * rx, al * rx - w * w * ry
    ex, ey = dx - bx, dy - by
    f = np.hypot(ex, ey)
    p = (b * b - c * c + f * f) / (2 * f)
    h = side * np.sqrt(b * b - p * p)
    cx = bx + (p * ex - h * ey) / f
    cy = by + (p * ey + h * ex) / f
    r1x, r1y, r2x, r2y = cx - bx, cy - by, cx - dx, cy - dy
    den = r1x * r2y - r1y * r2x
    w1 = (-vbx * r2x - vby * r2y) / den
    w2 = (-vbx * r1x - vby * r1y) / den
    qx = -abx + w1 * w1 * r1x - w2 * w2 * r2x
    qy = -aby + w1 * w1 * r1y - w2 * w2 * r2y
    a1 = (qx * r2x + qy * r2y) / den
    a2 = (qx * r1x + qy * r1y) / den
    vcx, vcy = vbx - w1 * r1y, vby + w1 * r1x
    acx = abx - a1 * r1y - w1 * w1 * r1x
    acy = aby + a1 * r1x - w1 * w1 * r1y
    values = (np.arctan2(r1y, r1x), np.arctan2(r2y, r2x), w1, w2, a1, a2,
              bx, by, vbx, vby, abx, aby, cx, cy, vcx, vcy, acx, acy)
    if not carried:
        return values
    return values + _four_bar_carried(values, (r1x, r1y, r2x, r2y), geometry, carried)


def slider_crank_math(theta: float, w: float, al: float,
                      geometry: tuple[float, ...] = SLIDER_CRANK_GEOMETRY,
                      carried: Carried = ()) -> tuple[float, ...]:
    """Hand-written slider-crank on a horizontal guide with :mod:`math`.

    Returns the piston's x, the rod's angle, their rates and accelerations,
    B's position, velocity and acceleration, then each ``carried`` point's
    (:func:`carry`; link 0 is the rod B -> piston).
    """
    ox, oy, r, rod, guide, side = geometry
    s, c = math.sin(theta), math.cos(theta)
    e = guide - oy - r * s              # the rod's rise from B to the piston
    k = math.sqrt(rod * rod - e * e)
    x = ox + r * c + side * k
    phi = math.atan2(e, side * k)
    cp, sp = math.cos(phi), math.sin(phi)
    wr = -r * c * w / (rod * cp)
    v = -r * s * w - rod * sp * wr
    ar = (r * s * w * w - r * c * al + rod * sp * wr * wr) / (rod * cp)
    a = -r * c * w * w - r * s * al - rod * cp * wr * wr - rod * sp * ar
    bx, by = ox + r * c, oy + r * s
    vbx, vby = -w * r * s, w * r * c
    abx, aby = -al * r * s - w * w * r * c, al * r * c - w * w * r * s
    values = (x, phi, v, wr, a, ar, bx, by, vbx, vby, abx, aby)
    if not carried:
        return values
    links = ((bx, by, vbx, vby, abx, aby, cp, sp, 1.0, wr, ar),)
    return values + carry(carried, links, (x, guide, v, 0.0, a, 0.0))


def slider_crank_numpy(theta: Any, w: float, al: float,
                       geometry: tuple[float, ...] = SLIDER_CRANK_GEOMETRY,
                       carried: Carried = ()) -> tuple[Any, ...]:
    """Solve the same slider-crank with NumPy over an array of crank angles."""
    ox, oy, r, rod, guide, side = geometry
    s, c = np.sin(theta), np.cos(theta)
    e = guide - oy - r * s
    k = np.sqrt(rod * rod - e * e)
    x = ox + r * c + side * k
    phi = np.arctan2(e, side * k)
    cp, sp = np.cos(phi), np.sin(phi)
    wr = -r * c * w / (rod * cp)
    v = -r * s * w - rod * sp * wr
    ar = (r * s * w * w - r * c * al + rod * sp * wr * wr) / (rod * cp)
    a = -r * c * w * w - r * s * al - rod * cp * wr * wr - rod * sp * ar
    bx, by = ox + r * c, oy + r * s
    vbx, vby = -w * r * s, w * r * c
    abx, aby = -al * r * s - w * w * r * c, al * r * c - w * w * r * s
    values = (x, phi, v, wr, a, ar, bx, by, vbx, vby, abx, aby)
    if not carried:
        return values
    links = ((bx, by, vbx, vby, abx, aby, cp, sp, 1.0, wr, ar),)
    return values + carry(carried, links, (x, guide, v, 0.0, a, 0.0))


#: A Scotch yoke's: crank centre (x, y) on the yoke's horizontal guide, crank length. The
#: default is the packaged one (crank 50 mm).
SCOTCH_YOKE_GEOMETRY = (0.0, 0.0, 0.05)


def scotch_yoke_math(theta: float, w: float, al: float,
                     geometry: tuple[float, ...] = SCOTCH_YOKE_GEOMETRY) -> tuple[float, ...]:
    """Hand-written Scotch yoke (horizontal guide through the crank centre, vertical slot).

    Returns the yoke's x and the pin's height in the slot with their rates and
    accelerations, then B's position, velocity and acceleration.
    """
    ox, oy, r = geometry
    c, s = math.cos(theta), math.sin(theta)
    x, y = r * c, r * s
    vx, vy = -w * y, w * x
    ax, ay = -al * y - w * w * x, al * x - w * w * y
    return x, y, vx, vy, ax, ay, ox + x, oy + y, vx, vy, ax, ay


def scotch_yoke_numpy(theta: Any, w: float, al: float,
                      geometry: tuple[float, ...] = SCOTCH_YOKE_GEOMETRY) -> tuple[Any, ...]:
    """Solve the same Scotch yoke with NumPy over an array of crank angles."""
    ox, oy, r = geometry
    c, s = np.cos(theta), np.sin(theta)
    x, y = r * c, r * s
    vx, vy = -w * y, w * x
    ax, ay = -al * y - w * w * x, al * x - w * w * y
    return x, y, vx, vy, ax, ay, ox + x, oy + y, vx, vy, ax, ay


def geometry_of(scene: Any) -> tuple[str, tuple[float, ...]] | None:
    """Return (dyad kind, geometry) of a scene with hand-written forms, or None.

    A scene has them when it is one crank driving one dyad: an RRR on the
    crank's tip and a ground pivot (a four-bar, :data:`FOUR_BAR_GEOMETRY`'s
    layout), an RRP on the crank's tip and a horizontal guide (a
    slider-crank, :data:`SLIDER_CRANK_GEOMETRY`'s), or an RPP of a vertical
    slot on a horizontal guide through the crank centre (a Scotch yoke,
    :data:`SCOTCH_YOKE_GEOMETRY`'s).
    """
    if len(scene.dyads) != 1:
        return None
    dyad, crank = scene.dyads[0], scene.input
    baseline = _BASELINES.get(dyad.kind)
    if baseline is None or crank is None or len(scene.drivers) > 1:
        return None
    geometry = baseline.geometry(scene, dyad, crank)
    return None if geometry is None else (dyad.kind, geometry)


def hand_written(scene: Any) -> tuple[partial[Any], partial[Any]] | None:
    """Return the hand-written scalar and NumPy forms of ``scene``, or None.

    See :func:`geometry_of` for the scenes that have them; they also compute
    every reported carried point (:func:`carried_of`), as the solver does.
    Each is a partial of its form with the keywords ``geometry`` and, where
    the scene has carried points, ``carried``.
    """
    found = _forms(scene)
    if found is None:
        return None
    scalar, vector, args = found
    given = dict(zip(('geometry', 'carried'), args, strict=False))
    return partial(scalar, **given), partial(vector, **given)


def _forms(scene: Any) -> tuple[Callable[..., Any], Callable[..., Any], tuple[Any, ...]] | None:
    """Return the scalar and NumPy forms of ``scene`` and their arguments after the crank's.

    The arguments are the geometry, then the carried points where there are any;
    None for a scene without forms (:func:`hand_written`).
    """
    found = geometry_of(scene)
    if found is None:
        return None
    kind, geometry = found
    baseline = _BASELINES[kind]
    carried = carried_of(scene, baseline.links(scene.dyads[0]))
    if carried is None:
        return None
    return baseline.scalar, baseline.vector, (geometry, carried) if carried else (geometry,)


def carried_of(scene: Any, links: Sequence[Any]) -> Carried | None:
    """Return the reported carried points of ``scene`` as :data:`Carried`, or None.

    ``links`` are the dyad's links, in the order of the hand-written form's;
    each ends at the dyad's new point. None where a reported carried point
    is not on one of them with its frame along it (origin and x-axis its two
    ends).
    """
    end = scene.dyads[0].point
    reported = set(scene.output_points)
    found = []
    for point in scene.points:
        if point.name not in reported:
            continue
        where = [k for k, link in enumerate(links) if link.name == point.link]
        if not where or {point.origin, point.xaxis} != {links[where[0]].start, end}:
            return None
        found.append((where[0], point.origin != end, *point.local))
    return tuple(found)


def _four_bar(scene: Any, dyad: Any, crank: Any) -> tuple[float, ...] | None:
    """Return the four-bar's geometry, for an RRR on the crank's tip and a ground pivot."""
    first, second = dyad.links
    if first.start != crank.point or second.start not in scene.ground:
        return None
    ox, oy = scene.ground[crank.center]
    dx, dy = scene.ground[second.start]
    return (ox, oy, crank.length, first.length, second.length, dx, dy,
            float(dyad.branch.value))


def _slider_crank(scene: Any, dyad: Any, crank: Any) -> tuple[float, ...] | None:
    """Return the slider-crank's geometry, for an RRP on the crank's tip and a horizontal guide."""
    if dyad.guide_angle != 0.0 or dyad.link.start != crank.point \
            or dyad.through not in scene.ground:
        return None
    ox, oy = scene.ground[crank.center]
    guide = scene.ground[dyad.through][1]
    return (ox, oy, crank.length, dyad.link.length, guide, float(dyad.branch.value))


def _scotch_yoke(scene: Any, dyad: Any, crank: Any) -> tuple[float, ...] | None:
    """Return the Scotch yoke's geometry, for an RPP of a vertical slot on the crank's tip.

    Its guide is horizontal, through the crank centre.
    """
    if dyad.guide_angle != 0.0 or dyad.slot_angle != 0.5 * math.pi \
            or dyad.through != crank.point or dyad.guide_through != crank.center:
        return None
    ox, oy = scene.ground[crank.center]
    return (ox, oy, crank.length)


class _Baseline(NamedTuple):
    """A kind of dyad's hand-written forms: its geometry's reader, links and forms."""

    geometry: Callable[[Any, Any, Any], tuple[float, ...] | None]
    #: The dyad's links that carry points, in the order of the forms' ``links``.
    links: Callable[[Any], tuple[Any, ...]]
    scalar: Callable[..., Any]
    vector: Callable[..., Any]


#: The hand-written baselines there are, by the scene's dyad ``type:``.
_BASELINES: dict[str, _Baseline] = {
    'RRR': _Baseline(_four_bar, lambda dyad: tuple(dyad.links), four_bar_math, four_bar_numpy),
    'RRP': _Baseline(_slider_crank, lambda dyad: (dyad.link,), slider_crank_math,
                     slider_crank_numpy),
    'RPP': _Baseline(_scotch_yoke, lambda dyad: (), scotch_yoke_math, scotch_yoke_numpy)}


#: The clock of every timing: the process's CPU time. On the shared machine the wall
#: clock also counts the time other processes hold the cores; every solve timed here
#: (ours, the hand-written forms, pylinkage's numba kernels) runs on one thread.
CLOCK = time.process_time

#: Issue 19's targets, bounds included: the array path per configuration over the
#: hand-written NumPy closed form, the single angle over the hand-written scalar one.
ARRAY_TARGET = 1.5
SINGLE_TARGET = 8.0


def _spread_times(funcs: list[Callable[[], Any]], number: int,
                  repeat: int) -> list[tuple[float, float, float]]:
    """Min, median and max over ``repeat`` runs of the time of one call of each function.

    The functions are timed in turn: interleaving the repeats makes a load
    change on the shared machine hit every function alike, so their ratios
    stay meaningful. Times are the process's CPU time (:data:`CLOCK`).
    """
    times: list[list[float]] = [[] for _ in funcs]
    for _ in range(repeat):
        for func, samples in zip(funcs, times, strict=True):
            start = CLOCK()
            for _ in range(number):
                func()
            samples.append((CLOCK() - start) / number)
    return [(min(s), statistics.median(s), max(s)) for s in times]


def measure(names: list[str], angles: int, repeat: int) -> list[dict[str, Any]]:
    """Time every scene, and the hand-written baselines beside theirs; one row each.

    Each row holds ``single_us`` and ``array_us`` (per configuration) as
    ``[min, median, max]`` over ``repeat`` runs, microseconds; a row of a
    scene with a hand-written form also holds the median ratios
    ``single_ratio`` and ``array_ratio`` to it. The process keeps freed memory
    for reuse (:func:`~mech_kinematics.memory.keep_freed_memory`), for ours and
    the hand-written forms alike.
    """
    keep_freed_memory()
    sweep = np.linspace(0.0, 2.0 * math.pi, angles, endpoint=False)
    rows = []
    for name in names:
        scene = load_scene(name)
        drivers = scene.drivers
        if scene.input is None or len(drivers) > 1:
            # Several drivers: one configuration, their start, and the array path over
            # as many copies of it as a crank's sweep has angles.
            starts: Any = [driver.start for driver in drivers]
            many: Any = [np.full(angles, x) for x in starts]
            if len(drivers) == 1:   # an actuator alone: solve's one-driver signature
                starts, many = starts[0], many[0]
            singles = [partial(solve, scene, starts)]
            arrays = [partial(solve, scene, many)]
            forms = None
        else:
            theta, w, al = scene.input.angle, scene.input.speed, scene.input.accel
            singles = [partial(solve, scene, theta)]
            arrays = [partial(solve, scene, sweep)]
            forms = _forms(scene)
        if forms is not None:
            # Each form's geometry (and carried points) bound by position after the
            # crank's, as ``solve``'s arguments are: no keywords merged at each call.
            scalar, vector, given = forms
            # Where a scene does not assemble at every angle, the array path is timed
            # over the angles where it does (the hand-written forms cannot refuse).
            with np.errstate(invalid='ignore'):
                ok = np.isfinite(vector(sweep, w, al, *given)[0])
            if not ok.all():
                arrays = [partial(solve, scene, sweep[ok])]
            singles.append(partial(scalar, theta, w, al, *given))
            arrays.append(partial(vector, sweep[ok], w, al, *given))
        count = len(sweep) if forms is None else int(ok.sum())
        one = [[t * 1e6 for t in spread] for spread in _spread_times(singles, 1000, repeat)]
        many = [[t * 1e6 / count for t in spread] for spread in _spread_times(arrays, 3, repeat)]
        row: dict[str, Any] = {'scene': name, 'single_us': one[0], 'array_us': many[0]}
        rows.append(row)
        if forms is not None:
            row['single_ratio'] = one[0][1] / one[1][1]
            row['array_ratio'] = many[0][1] / many[1][1]
            rows.append({'scene': f'{name} (hand-written)', 'single_us': one[1],
                         'array_us': many[1], 'baseline_of': name})
    return rows


def _ratio(row: dict[str, Any], key: str, target: float) -> str:
    if key not in row:
        return ''
    verdict = 'ok' if row[key] <= target else 'over'
    return f'{row[key]:.2f} {verdict}'


def table(rows: list[dict[str, Any]], angles: int, repeat: int) -> list[str]:
    """Return the lines ``make bench`` prints for the rows of :func:`measure`."""
    lines = [f'min / median / max of {repeat} runs (CPU time of this process); array path '
             f'over {angles} angles, per configuration; position, velocity and acceleration of '
             'every output, bounds included',
             f'ratio: median over the hand-written closed form of the same scene (targets: '
             f'single <= {SINGLE_TARGET:g}x, array <= {ARRAY_TARGET:g}x); "-": no '
             'hand-written form of that scene',
             f'{"scene":40s} {"single µs":>20s} {"ratio":>9s} {"array µs/cfg":>23s} '
             f'{"ratio":>9s}']
    for row in rows:
        single = '/'.join(f'{t:.2f}' for t in row['single_us'])
        array = '/'.join(f'{t:.3f}' for t in row['array_us'])
        if 'baseline_of' in row:
            ratio1 = ratio2 = '1'
        elif 'single_ratio' in row:
            ratio1 = _ratio(row, 'single_ratio', SINGLE_TARGET)
            ratio2 = _ratio(row, 'array_ratio', ARRAY_TARGET)
        else:
            ratio1 = ratio2 = '-'
        lines.append(f'{row["scene"]:40s} {single:>20s} {ratio1:>9s} {array:>23s} {ratio2:>9s}')
    return lines


def _handle(args: argparse.Namespace) -> int:
    """Print the table of ``measure`` with the ratios to the hand-written baselines."""
    if args.peer is not None:
        return _handle_peer(args)
    rows = measure(scene_names(), args.angles, args.repeat)
    if args.json:
        print(json.dumps({'angles': args.angles, 'repeat': args.repeat, 'rows': rows},
                         indent=1))
    else:
        print('\n'.join(table(rows, args.angles, args.repeat)))
    return 0


def _handle_peer(args: argparse.Namespace) -> int:
    """Print the side-by-side table against a peer package (:mod:`.peer`)."""
    if not available():
        print('bench: expected pylinkage 1.3.0 installed for --peer pylinkage (a development '
              'dependency: `make install`), got none', file=sys.stderr)
        return 2
    rows = measure_peers(args.repeat)
    if args.json:
        print(json.dumps({'peer': args.peer, 'repeat': args.repeat, 'rows': rows}, indent=1))
    else:
        print('\n'.join(peer_table(rows, args.repeat)))
    return 0


def measure_peers(repeat: int, names: Sequence[str] = PEER_SCENES,
                  batches: tuple[int, ...] = BATCHES) -> list[dict[str, Any]]:
    """Return :func:`.peer.measure_peer`'s row of every scene timed against pylinkage.

    The process keeps freed memory for reuse, as in :func:`measure`.
    """
    keep_freed_memory()

    def forms(scene: Any) -> tuple[str, tuple[float, ...]]:
        found = geometry_of(scene)
        if found is None or found[0] not in ('RRR', 'RRP'):
            msg = f'Expected a four-bar or a slider-crank for the peer, got scene {scene.name}'
            raise ValueError(msg)
        return found

    return [measure_peer(name, forms, repeat, batches) for name in names]


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register the ``bench`` command on ``subparsers``; return its parser."""
    parser: argparse.ArgumentParser = subparsers.add_parser(
        'bench', help='time the solver on every packaged scene',
        description='Time the single-angle and array paths of the solver on every packaged '
                    'scene, beside hand-written closed forms of the four-bar and the '
                    'slider-crank.')
    parser.add_argument('--angles', type=positive_int, default=100_000,
                        help='angles in the array path (default 1e5)')
    parser.add_argument('--repeat', type=positive_int, default=7,
                        help='runs for the min / median / max (default 7)')
    parser.add_argument('--peer', choices=PEERS, default=None,
                        help='time the packaged four-bar and slider-crank side by side with '
                             'a peer package instead (pylinkage 1.3.0: a development '
                             'dependency), after checking its answers equal ours')
    parser.add_argument('--json', action='store_true',
                        help='print the rows as JSON (times as [min, median, max] µs)')
    parser.set_defaults(handler=_handle)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``bench``; return the exit status."""
    return run_tool(add_parser, argv)
