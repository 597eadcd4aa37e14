# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""What every section of the report shares: run sizes, constants and timing.

:class:`Mode` and :data:`MODES` say how much a run does (``full``,
``--quick``, ``--smoke``); :data:`WP_SCENES` names the work-precision
mechanisms; :func:`spread_time` (min / median / max) and :func:`median_time`
are the timers and :func:`quiet_solve` the solver with its near-singularity
warning silenced. :func:`four_bar`,
:func:`slider_crank` and :func:`distance_angle` build the mechanisms of the
extreme sections (:mod:`.extreme`, :mod:`.bounds`).
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
from ...solver import Branch, CarriedPoint, Crank, Link, RRP, RRR, Scene, solve

__all__ = ['DURATIONS', 'EPS', 'ERROR_FLOOR', 'MODES', 'Mode', 'WP_SCENES', 'distance_angle',
           'four_bar', 'median_time', 'quiet_solve', 'slider_crank', 'slug', 'spread_time']

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


# --- mechanisms of the extreme sections ------------------------------------------


def four_bar(name: str, a: float, b: float, c: float, d: float, angle: float = 0.0,
             branch: int = 1, speed: float = -4 * math.pi, scale: float = 1.0) -> Scene:
    """Return a four-bar: crank AB = a about A = 0, coupler BC = b, rocker DC = c, D = (d, 0).

    Every length is multiplied by ``scale``; the coupler carries a point E at
    (0.5 b, 0.3 b) in its frame. ``angle`` (rad) and ``speed`` (rad/s) are
    the crank's.
    """
    links = (Link('coupler', 'B', b * scale), Link('rocker', 'D', c * scale))
    crank = Crank('crank', 'A', 'B', a * scale, angle, speed, 0.0)
    return Scene(name, {'A': (0.0, 0.0), 'D': (d * scale, 0.0)}, crank,
                 (RRR('C', links, Branch(branch)),),
                 (CarriedPoint('E', 'coupler', 'B', 'C', (0.5 * b * scale, 0.3 * b * scale)),))


def slider_crank(name: str, crank_length: float, rod: float, offset: float = 0.0,
                 angle: float = 0.0, speed: float = 10 * math.pi) -> Scene:
    """Return a slider-crank: crank OB about O = 0, rod BP, piston P on the line y = ``offset``.

    The guide runs along +x (branch PLUS: the piston on the +x side); the rod
    carries its midpoint M. Lengths in m, ``angle`` in rad, ``speed`` in rad/s.
    """
    crank = Crank('crank', 'O', 'B', crank_length, angle, speed, 0.0)
    dyad = RRP('P', Link('rod', 'B', rod), 'E', 0.0, 'piston', Branch.PLUS)
    return Scene(name, {'O': (0.0, 0.0), 'E': (0.0, offset)}, crank, (dyad,),
                 (CarriedPoint('M', 'rod', 'B', 'P', (0.5 * rod, 0.0)),))


def distance_angle(a: float, d: float, distance: float) -> Any:
    """Return the crank angle (mpmath, 60 digits) at which the tip is ``distance`` from (d, 0).

    For a crank of length ``a`` about the origin: the position where the
    circles of a four-bar with ``b + c`` (or ``|b - c|``) equal to
    ``distance`` just meet, a toggle.
    """
    import mpmath
    with mpmath.workdps(60):
        a_, d_, r = (mpmath.mpf(x) for x in (a, d, distance))
        return mpmath.acos((a_ * a_ + d_ * d_ - r * r) / (2 * a_ * d_))
