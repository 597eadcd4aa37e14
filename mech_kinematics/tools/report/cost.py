# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Section 5 of the report: how the solver's cost grows with batch size and chain length.

:func:`cost_growth` times ``solve`` over batches of 1 .. 1e7 angles (in one
call and in calls of :data:`CHUNK` angles) and over chains of four-bar
stages (:func:`~mech_kinematics.verify.cases.chain_scene`), one angle and
arrays, and fits the growth.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
import math
from typing import Any

import numpy as np

from .common import median_time, Mode
from ...scene import load_scene
from ...solver import Scene, solve
from ...verify.cases import chain_scene

__all__ = ['CHUNK', 'CostGrowth', 'cost_growth']

#: Angles per call when a large batch is solved in chunks.
CHUNK = 4096


@dataclass
class CostGrowth:
    """Time per configuration against batch size and against chain length."""

    batch: list[tuple[int, float]]          # (angles, s per configuration), array path
    chunked: list[tuple[int, float]]        # the same angles solved CHUNK at a time
    single: float                           # one angle through the scalar path, s
    batch_slope: float                      # d log(total time) / d log(angles), large batches
    chain_array: list[tuple[int, float]]    # (dyads, s per configuration)
    chain_single: list[tuple[int, float]]
    chain_slope_array: float                # d log(time) / d log(dyads), 4 dyads and up
    chain_slope_single: float
    per_dyad_array: float                   # s per configuration per dyad (linear fit)
    per_dyad_single: float


def _slope(xs: Sequence[float], ys: Sequence[float]) -> float:
    return float(np.polyfit(np.log(xs), np.log(ys), 1)[0])


def _chunked(scene: Scene, angles: Any) -> None:
    for start in range(0, len(angles), CHUNK):
        solve(scene, angles[start:start + CHUNK])


def cost_growth(mode: Mode, tick: Callable[[], None] = lambda: None) -> CostGrowth:
    """Time the solver over batches of 1 .. 1e7 angles and chains of 1 .. 64 dyads.

    Each batch is solved once before timing, so that the first touch of fresh
    memory (page faults) is not counted; large batches are also timed in
    chunks of :data:`CHUNK` angles.
    """
    scene = load_scene('khurmi_four_bar_ad150')
    rng = np.random.default_rng(5)
    batch, chunked = [], []
    for n in mode.batch_sizes:
        angles = rng.uniform(-math.pi, math.pi, n)
        repeat = mode.repeat if n <= 100_000 else 3
        number = max(1, 1000 // n) if n < 1000 else 1
        solve(scene, angles)
        seconds = median_time(lambda a=angles: solve(scene, a), repeat, number)
        batch.append((n, seconds / n))
        if n > CHUNK:
            seconds = median_time(lambda a=angles: _chunked(scene, a), repeat)
            chunked.append((n, seconds / n))
        del angles
        tick()
    single = median_time(lambda: solve(scene, 1.0), mode.repeat, 2000)
    large = [(n, s * n) for n, s in batch if n >= 1000]
    if len(large) < 2:
        large = [(n, s * n) for n, s in batch][-2:]
    batch_slope = _slope([n for n, _ in large], [t for _, t in large]) if len(large) > 1 \
        else math.nan
    chain_array, chain_single = [], []
    angles = rng.uniform(-math.pi, math.pi, mode.chain_angles)
    for stages in mode.chain_lengths:
        chained = chain_scene(stages)
        seconds = median_time(lambda s=chained: solve(s, angles), mode.repeat)
        chain_array.append((stages, seconds / mode.chain_angles))
        once = median_time(lambda s=chained: solve(s, 1.0), 1, 5)
        number = max(10, int(0.02 / once))  # samples of about 20 ms
        chain_single.append((stages, median_time(lambda s=chained: solve(s, 1.0),
                                                 2 * mode.repeat + 1, number)))
        tick()
    tail = [(n, s) for n, s in chain_array if n >= 4]
    tail = tail if len(tail) > 1 else chain_array
    tail_single = [(n, s) for n, s in chain_single if n >= 4]
    tail_single = tail_single if len(tail_single) > 1 else chain_single

    def fit(rows: list[tuple[int, float]]) -> tuple[float, float]:
        if len(rows) < 2:
            return math.nan, math.nan
        slope = _slope([n for n, _ in rows], [s for _, s in rows])
        per = float(np.polyfit([n for n, _ in rows], [s for _, s in rows], 1)[0])
        return slope, per

    slope_a, per_a = fit(tail)
    slope_s, per_s = fit(tail_single)
    return CostGrowth(batch, chunked, single, batch_slope, chain_array, chain_single, slope_a,
                      slope_s, per_a, per_s)
