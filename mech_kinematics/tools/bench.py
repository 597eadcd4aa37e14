# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Solver speed: ``python -m mech_kinematics bench`` (``make bench``).

For every packaged scene it times one full single-angle solve (median) and
the array path per configuration over many angles, beside hand-written closed
forms of the same four-bar and slider-crank timed in the same run. The machine
is shared and noisy, so what matters is the ratios of one run.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence
from functools import partial
import math
import statistics
import time
from typing import Any

import numpy as np

from ..cli import positive_int, run_tool
from ..scene import load_scene, scene_names
from ..solver import solve

# The hand-written baselines solve the packaged scenes' own geometry.
FOUR_BAR = 'khurmi_four_bar_ad150'  # AD = 150, AB = 40, BC = 150, CD = 80 mm
SLIDER_CRANK = 'slider_crank_150_600'  # crank 150, rod 600 mm, piston on the left


def four_bar_math(theta: float, w: float, al: float) -> tuple[float, ...]:
    """Hand-written four-bar with :mod:`math`: link angles, rates, accelerations; B and C."""
    a, b, c, d = 0.04, 0.15, 0.08, 0.15
    bx, by = a * math.cos(theta), a * math.sin(theta)
    vbx, vby = -w * by, w * bx
    abx, aby = -al * by - w * w * bx, al * bx - w * w * by
    ex, ey = d - bx, -by
    f = math.hypot(ex, ey)
    p = (b * b - c * c + f * f) / (2 * f)
    h = math.sqrt(b * b - p * p)
    cx = bx + (p * ex - h * ey) / f
    cy = by + (p * ey + h * ex) / f
    r1x, r1y, r2x, r2y = cx - bx, cy - by, cx - d, cy
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
    return (math.atan2(r1y, r1x), math.atan2(r2y, r2x), w1, w2, a1, a2,
            bx, by, vbx, vby, abx, aby, cx, cy, vcx, vcy, acx, acy)


def four_bar_numpy(theta: Any, w: float, al: float) -> tuple[Any, ...]:
    """Solve the same four-bar with NumPy over an array of crank angles."""
    a, b, c, d = 0.04, 0.15, 0.08, 0.15
    cos, sin = np.cos(theta), np.sin(theta)
    bx, by = a * cos, a * sin
    vbx, vby = -w * by, w * bx
    abx, aby = -al * by - w * w * bx, al * bx - w * w * by
    ex, ey = d - bx, -by
    f = np.hypot(ex, ey)
    p = (b * b - c * c + f * f) / (2 * f)
    h = np.sqrt(b * b - p * p)
    cx = bx + (p * ex - h * ey) / f
    cy = by + (p * ey + h * ex) / f
    r1x, r1y, r2x, r2y = cx - bx, cy - by, cx - d, cy
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
    return (np.arctan2(r1y, r1x), np.arctan2(r2y, r2x), w1, w2, a1, a2,
            bx, by, vbx, vby, abx, aby, cx, cy, vcx, vcy, acx, acy)


def slider_crank_math(theta: float, w: float, al: float) -> tuple[float, ...]:
    """Hand-written in-line slider-crank (piston at negative x) with :mod:`math`."""
    r, rod = 0.15, 0.6
    s, c = math.sin(theta), math.cos(theta)
    k = math.sqrt(rod * rod - r * r * s * s)
    x = r * c - k
    phi = math.atan2(-r * s, x - r * c)
    wr = -r * c * w / (rod * math.cos(phi))
    v = -r * s * w - rod * math.sin(phi) * wr
    ar = (r * s * w * w - r * c * al + rod * math.sin(phi) * wr * wr) / (rod * math.cos(phi))
    a = -r * c * w * w - r * s * al - rod * math.cos(phi) * wr * wr - rod * math.sin(phi) * ar
    bx, by = r * c, r * s
    vbx, vby = -w * by, w * bx
    abx, aby = -al * by - w * w * bx, al * bx - w * w * by
    return x, phi, v, wr, a, ar, bx, by, vbx, vby, abx, aby


def slider_crank_numpy(theta: Any, w: float, al: float) -> tuple[Any, ...]:
    """Solve the same slider-crank with NumPy over an array of crank angles."""
    r, rod = 0.15, 0.6
    s, c = np.sin(theta), np.cos(theta)
    k = np.sqrt(rod * rod - r * r * s * s)
    x = r * c - k
    phi = np.arctan2(-r * s, x - r * c)
    cp, sp = np.cos(phi), np.sin(phi)
    wr = -r * c * w / (rod * cp)
    v = -r * s * w - rod * sp * wr
    ar = (r * s * w * w - r * c * al + rod * sp * wr * wr) / (rod * cp)
    a = -r * c * w * w - r * s * al - rod * cp * wr * wr - rod * sp * ar
    bx, by = r * c, r * s
    vbx, vby = -w * by, w * bx
    abx, aby = -al * by - w * w * bx, al * bx - w * w * by
    return x, phi, v, wr, a, ar, bx, by, vbx, vby, abx, aby


def _median_times(funcs: list[Callable[[], Any]], number: int,
                  repeat: int) -> list[float]:
    """Median time of one call of each function, the functions timed in turn.

    Interleaving the repeats makes a load change on the shared machine hit
    every function alike, so their ratios stay meaningful.
    """
    times: list[list[float]] = [[] for _ in funcs]
    for _ in range(repeat):
        for func, samples in zip(funcs, times, strict=True):
            start = time.perf_counter()
            for _ in range(number):
                func()
            samples.append((time.perf_counter() - start) / number)
    return [statistics.median(samples) for samples in times]


def measure(names: list[str], angles: int, repeat: int) -> list[dict[str, Any]]:
    """Time every scene, and the hand-written baselines beside theirs; one row each."""
    sweep = np.linspace(0.0, 2.0 * math.pi, angles, endpoint=False)
    baselines = {
        FOUR_BAR: (four_bar_math, four_bar_numpy),
        SLIDER_CRANK: (slider_crank_math, slider_crank_numpy),
    }
    rows = []
    for name in names:
        scene = load_scene(name)
        theta, w, al = scene.input.angle, scene.input.speed, scene.input.accel
        singles = [partial(solve, scene, theta)]
        arrays = [partial(solve, scene, sweep)]
        if name in baselines:
            scalar, vector = baselines[name]
            singles.append(partial(scalar, theta, w, al))
            arrays.append(partial(vector, sweep, w, al))
        one = _median_times(singles, 1000, repeat)
        many = [t / angles for t in _median_times(arrays, 3, repeat)]
        rows.append({'scene': name, 'single_us': one[0] * 1e6, 'array_us': many[0] * 1e6})
        if name in baselines:
            rows.append({'scene': f'{name} (hand-written)', 'single_us': one[1] * 1e6,
                         'array_us': many[1] * 1e6, 'baseline_of': name})
    return rows


def _handle(args: argparse.Namespace) -> int:
    """Print the table of ``measure`` with the ratios to the hand-written baselines."""
    angles, repeat = args.angles, args.repeat
    rows = measure(scene_names(), angles, repeat)
    baseline = {row['baseline_of']: row for row in rows if 'baseline_of' in row}
    print(f'median of {repeat} runs; array path over {angles} angles; position, velocity '
          f'and acceleration of every output')
    print(f'{"scene":44s} {"single µs":>10s} {"ratio":>6s} {"array µs/cfg":>13s} {"ratio":>6s}')
    for row in rows:
        ref = baseline.get(row['scene'])
        ratio1 = f'{row["single_us"] / ref["single_us"]:6.2f}' if ref else ''
        ratio2 = f'{row["array_us"] / ref["array_us"]:6.2f}' if ref else ''
        print(f'{row["scene"]:44s} {row["single_us"]:10.2f} {ratio1:>6s} '
              f'{row["array_us"]:13.4f} {ratio2:>6s}')
    return 0


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register the ``bench`` command on ``subparsers``; return its parser."""
    parser: argparse.ArgumentParser = subparsers.add_parser(
        'bench', help='time the solver on every packaged scene',
        description='Time the single-angle and array paths of the solver on every packaged '
                    'scene, beside hand-written closed forms of the four-bar and the '
                    'slider-crank.')
    parser.add_argument('--angles', type=positive_int, default=100_000,
                        help='angles in the array path (default 1e5)')
    parser.add_argument('--repeat', type=positive_int, default=7, help='repeats for medians')
    parser.set_defaults(handler=_handle)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``bench``; return the exit status."""
    return run_tool(add_parser, argv)
