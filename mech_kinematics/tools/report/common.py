# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""What every section of the report shares: run sizes, constants and timing.

:class:`Mode` and :data:`MODES` say how much a run does (``full``,
``--quick``, ``--smoke``); :data:`WP_SCENES` names the work-precision
mechanisms; :func:`spread_time` (min / median / max) and :func:`median_time`
are the timers and :func:`quiet_solve` the solver with its near-singularity
warning silenced. The mechanisms of the extreme sections are built by the
verification room (:mod:`mech_kinematics.verify.cases`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
import math
import statistics
import time
from typing import Any
import warnings

import numpy as np

from ...errors import NearSingularWarning
from ...solver import Scene, solve

__all__ = ['DURATIONS', 'EPS', 'ERROR_FLOOR', 'MODES', 'Mode', 'WP_SCENES', 'median_time',
           'quiet_solve', 'slug', 'spread_time']

EPS = float(np.finfo(np.float64).eps)
#: Relative errors below this are drawn at this floor on log axes.
ERROR_FLOOR = 1e-17

#: The work-precision mechanisms: label -> packaged scene.
WP_SCENES = {'four-bar': 'khurmi_four_bar_ad150', 'slider-crank': 'slider_crank_150_600',
             'slotted lever': 'quick_return', 'Geneva': 'geneva'}


@dataclass(frozen=True)
class Mode:
    """How much a run of the report does."""

    name: str
    wp_configs: int                    # configurations per work-precision mechanism
    wp_tile: int                       # configurations per timed array call
    newton_tols: tuple[float, ...]
    fd_steps: tuple[float, ...]        # crank turn per finite-difference step, rad
    ivp_rtols: tuple[float, ...]
    wp_mechanisms: tuple[str, ...]
    check_angles: int                  # instants per scene in the reference self-check
    check_scenes: tuple[str, ...] | None  # None: every packaged scene
    clock_durations: tuple[tuple[str, int], ...]   # (label, seconds)
    clock_rpms: tuple[float, ...]
    clock_brute_ticks: int             # exact numpy check of the closed form, ticks
    clock_wrapped_ticks: int           # exact simulation of the wrapped variant, ticks
    extreme_angles: int                # extra angles per multi-angle case
    batch_sizes: tuple[int, ...]
    chain_lengths: tuple[int, ...]
    chain_angles: int
    repeat: int
    bound_samples: int                 # angles per error-bound case without a singular position
    bound_grid: int                    # evenly spaced angles of the refused-fraction grid
    bench_angles: int = 100_000        # angles of the array path in ``bench``'s table
    bench_repeat: int = 7              # runs of ``bench``'s timings (its default)


#: The simulated run times of the node's clock: (label, seconds).
DURATIONS = (('1 s', 1), ('1 h', 3600), ('1 day', 86_400), ('30 days', 30 * 86_400),
             ('1 year', 365 * 86_400))

MODES = {
    'full': Mode('full', 72, 8192, (1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-14),
                 (1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7),
                 (1e-3, 1e-5, 1e-7, 1e-9, 1e-11, 1e-13), tuple(WP_SCENES), 3, None,
                 DURATIONS, (10.0, 1000.0, 100_000.0), 10_000_000, 3_600_000, 8,
                 tuple(10 ** k for k in range(8)), (1, 2, 4, 8, 16, 32, 64), 1000, 5, 4, 3600),
    'quick': Mode('quick', 16, 2048, (1e-3, 1e-6, 1e-9, 1e-12), (1e-2, 1e-4, 1e-6),
                  (1e-4, 1e-8, 1e-12), tuple(WP_SCENES), 1,
                  ('khurmi_four_bar_ad150', 'quick_return', 'geneva', 'six_link_slider'),
                  DURATIONS, (10.0, 1000.0, 100_000.0), 1_000_000, 200_000, 2,
                  tuple(10 ** k for k in range(7)), (1, 4, 16, 64), 1000, 3, 2, 720, 10_000, 3),
    'smoke': Mode('smoke', 6, 256, (1e-4, 1e-10), (1e-3,), (1e-6,), ('four-bar', 'Geneva'), 1,
                  ('khurmi_four_bar_ad150', 'geneva'), DURATIONS[:3] + DURATIONS[4:],
                  (1000.0,), 100_000, 20_000, 0, (1, 100, 10_000), (1, 8), 200, 2, 1, 180,
                  1000, 2),
}


def spread_time(fn: Callable[[], Any], repeat: int,
                number: int = 1) -> tuple[float, float, float]:
    """Min, median and max over ``repeat`` runs of the time of one call of ``fn``, s.

    Each run times ``number`` calls.
    """
    times = []
    for _ in range(max(repeat, 1)):
        start = time.perf_counter()
        for _ in range(number):
            fn()
        times.append((time.perf_counter() - start) / number)
    return min(times), statistics.median(times), max(times)


def median_time(fn: Callable[[], Any], repeat: int, number: int = 1) -> float:
    """Median over ``repeat`` runs of the time of ``number`` calls of ``fn``, s."""
    return spread_time(fn, repeat, number)[1]


def quiet_solve(scene: Scene, angle: Any, speed: Any = None, accel: Any = None) -> Any:
    """Return ``solve(scene, angle, speed, accel)`` without its NearSingularWarning.

    The report measures the solver's actual error, also where its bounds say
    the answer cannot be trusted: nothing is refused for its bound here.
    """
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', NearSingularWarning)
        return solve(scene, angle, speed, accel, max_error=math.inf)


def slug(text: str) -> str:
    """Return ``text`` as a file-name stem: lower case, ``_`` for anything not alphanumeric."""
    return ''.join(ch if ch.isalnum() else '_' for ch in text.lower()).strip('_')
