# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Section 3 of the report: the node's crank angle against run time, simulated exactly.

Three ways to get the crank angle at a :data:`TICK_HZ` tick: the node's own
clock path (its tick grid, :class:`mech_kinematics.ros.schedule.TickGrid`,
aligned at a wall-clock epoch :data:`EPOCH_NS`, each instant sampled by
:meth:`mech_kinematics.ros.timebase.CrankTimebase.sample_turns` as the node's
tick does), naive
``angle += omega * dt`` (:func:`naive_accumulate`, exact in a few hundred
rational steps per year, checked bit for bit by :func:`naive_cumsum`) and the
same wrapped every tick (:func:`naive_wrapped`); :func:`clock_errors`
compares them with the exact angle in 60-digit arithmetic. mpmath is
imported inside the functions.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from fractions import Fraction
import math
from typing import Any

import numpy as np

from .common import Mode, quiet_solve
from ...scene import load_scene
from ...units import NS_PER_S, rad_per_s_from_rpm

__all__ = ['CLOCK_TICKS', 'ClockRow', 'EPOCH_NS', 'TICK_HZ', 'clock_errors', 'naive_accumulate',
           'naive_cumsum', 'naive_wrapped', 'naive_wrapped_trace', 'node_clock']

#: Tick rate of the simulated node, Hz.
TICK_HZ = 1000
#: Ticks ending at each run time over which the clock errors are the worst.
CLOCK_TICKS = 3
#: The simulated node's start, ns since 1970 (2026-11-17, not a round number): the
#: node's stamps are wall-clock nanoseconds, about 1.8e18, not counted from zero.
EPOCH_NS = 1_795_398_123_456_789_012


def naive_accumulate(angle0: float, step: float, ticks: int) -> float:
    """Return the double ``a`` after ``ticks`` repetitions of ``a += step`` (``step > 0``).

    Exact, in O(number of binades) operations instead of O(ticks): inside a
    binade ``[2**(e-1), 2**e)`` every double is a multiple of its ulp ``u``, so
    ``fl(a + step) = a + inc`` with a constant ``inc`` (``step`` rounded to a
    multiple of ``u``; after the binade's first addition also in the
    round-half-even tie case) for as long as ``a + step < 2**e``. The two
    first additions of each binade are done in floating point, the constant
    run in exact rational arithmetic. :func:`naive_cumsum` checks it.
    """
    if not step > 0:
        msg = f'Expected a positive step, got {step!r}'
        raise ValueError(msg)
    a = float(angle0)
    left = int(ticks)
    while left > 0:
        if not (a > 0 and a >= step):
            a += step
            left -= 1
            continue
        upper = math.ldexp(1.0, math.frexp(a)[1])
        first = a + step
        left -= 1
        if left == 0 or first >= upper:
            a = first
            continue
        second = first + step
        left -= 1
        inc = second - first  # exact (Sterbenz)
        a = second
        if inc == 0:
            return a          # stagnation: a + step rounds back to a, here and above
        if left == 0 or a >= upper:
            continue
        room = Fraction(upper) - Fraction(step) - Fraction(a)
        count = min(left, max(0, math.ceil(room / Fraction(inc))))
        a = float(Fraction(a) + count * Fraction(inc))
        left -= count
    return a


def naive_cumsum(angle0: float, step: float, ticks: int, chunk: int = 1 << 20) -> float:
    """Accumulate tick by tick instead: sequential ``np.add.accumulate`` in chunks."""
    a = float(angle0)
    left = int(ticks)
    while left > 0:
        n = min(left, chunk)
        buffer = np.full(n + 1, step)
        buffer[0] = a
        a = float(np.add.accumulate(buffer)[-1])
        left -= n
    return a


def naive_wrapped(angle0: float, step: float, ticks: int) -> float:
    """Repeat ``a = math.remainder(a + step, 2 * math.pi)`` ``ticks`` times, tick by tick."""
    a = float(angle0)
    two_pi = 2.0 * math.pi
    remainder = math.remainder
    for _ in range(int(ticks)):
        a = remainder(a + step, two_pi)
    return a


def naive_wrapped_trace(angle0: float, step: float, ticks: int,
                        every: int) -> list[tuple[int, float]]:
    """:func:`naive_wrapped`, returning ``(tick, angle)`` every ``every`` ticks."""
    a = float(angle0)
    two_pi = 2.0 * math.pi
    remainder = math.remainder
    out = []
    for k in range(1, int(ticks) + 1):
        a = remainder(a + step, two_pi)
        if k % every == 0:
            out.append((k, a))
    return out


def _drift_rate(trace: Sequence[tuple[int, Any]]) -> Any:
    """Least-squares slope through the origin of (tick, error), rad per tick."""
    return sum(k * e for k, e in trace) / sum(k * k for k, _ in trace)


def node_clock(rpm: float, theta0: float) -> tuple[Any, Any]:
    """Return the node's tick grid at :data:`TICK_HZ` and its time base, started at EPOCH_NS.

    As the node's tick thread does: the grid aligned at the first wake-up,
    the time base started at the grid's first instant with the scene angle.
    """
    from ...ros.schedule import period_ns_from_rate, TickGrid
    from ...ros.timebase import CrankTimebase
    grid = TickGrid.aligned(EPOCH_NS, period_ns_from_rate(TICK_HZ))
    return grid, CrankTimebase(grid.next_ns, theta0, rpm, 0.0, abs(rpm))


@dataclass
class ClockRow:
    """The crank angle and the published state after one run time at one speed."""

    duration: str
    seconds: int
    rpm: float
    #: method -> angle error, rad: ``timebase`` and ``naive, wrapped`` against the
    #: exact angle modulo 2 pi (what they publish), ``naive`` against the exact angle
    #: counted from the start, never wrapped (its own angle is never wrapped).
    angle_error: dict[str, float]
    state_error: dict[str, float]   # method -> worst relative error of the published state
    wrapped_model: bool             # the wrapped variant extrapolated, not simulated


def clock_errors(mode: Mode, scene_name: str = 'khurmi_four_bar_ad150',
                 tick: Callable[[], None] = lambda: None) -> tuple[list[ClockRow], dict[str, Any]]:
    """Error of the node's crank angle and state after long runs, three ways.

    ``timebase``: the node's clock path (:func:`node_clock`): its grid's
    instants after the run time, taken by :meth:`TickGrid.take` as a wake-up
    then does, each sampled by ``CrankTimebase.sample_turns``; ``naive``:
    ``angle += omega * dt`` per tick at :data:`TICK_HZ` (:func:`naive_accumulate`,
    exact); ``naive, wrapped``: the same with the angle wrapped every tick (:func:`naive_wrapped`,
    simulated tick by tick up to ``mode.clock_wrapped_ticks`` ticks, beyond
    that extrapolated linearly from the rate fitted on the simulation: every
    turn rounds the same way binade by binade, so the error grows linearly;
    ``check['wrapped_fit']`` is the relative miss of a fit on the first fifth
    at the simulated end).
    """
    import mpmath

    from ...verify import reference as ref_mod
    scene = load_scene(scene_name)
    model = ref_mod.Model(scene)
    theta0 = scene.input.angle
    dt = 1.0 / TICK_HZ
    rows = []
    check: dict[str, Any] = {'brute_ticks': 0, 'brute_equal': True, 'turns_equal': True}
    with mpmath.workdps(60):
        two_pi = 2 * mpmath.pi
        for rpm in mode.clock_rpms:
            omega = rad_per_s_from_rpm(rpm)
            step = omega * dt
            # The closed form against tick-by-tick accumulation.
            brute = mode.clock_brute_ticks
            for ticks in (brute // 7, brute):
                equal = naive_accumulate(theta0, step, ticks) == naive_cumsum(theta0, step, ticks)
                check['brute_equal'] = check['brute_equal'] and equal
            check['brute_ticks'] = brute
            # The wrapped variant's error grows linearly (each turn rounds the same
            # way, binade by binade): fit its rate on the simulated ticks, and check
            # the fit of the first fifth against the simulated end.
            wrapped_ticks = mode.clock_wrapped_ticks
            every = max(wrapped_ticks // 200, 1)
            trace = [(k, _angle_difference(a, theta0, rpm, k))
                     for k, a in naive_wrapped_trace(theta0, step, wrapped_ticks, every)]
            rate = _drift_rate(trace)
            early = _drift_rate([(k, e) for k, e in trace if 5 * k <= wrapped_ticks])
            end = trace[-1][1]
            check.setdefault('wrapped_fit', {})[rpm] = float(abs(early * trace[-1][0] - end)
                                                             / abs(end)) if end else 0.0
            grid, timebase = node_clock(rpm, theta0)
            t0 = grid.next_ns
            for label, seconds in mode.clock_durations:
                angle_error: dict[str, float] = {}
                state_error: dict[str, float] = {}
                model_used = seconds * TICK_HZ > wrapped_ticks
                # The last CLOCK_TICKS ticks up to the run time: at a whole number of
                # turns every method may land on the start angle by luck. The node's grid
                # owes them at the run time's instant (one wake-up after a long sleep).
                period = grid.period_ns
                due = grid.take(t0 + seconds * TICK_HZ * period, (CLOCK_TICKS - 1) * period)
                stamps = list(due.instants)
                check.setdefault('grid_instants', []).append(len(stamps))
                for ticks, stamp in zip(range(seconds * TICK_HZ - CLOCK_TICKS + 1,
                                              seconds * TICK_HZ + 1), stamps, strict=True):
                    exact_turns = Fraction(rpm) * (stamp - t0) / (60 * NS_PER_S)
                    unwrapped = mpmath.mpf(theta0) + two_pi * mpmath.mpf(exact_turns)
                    exact = _wrap_mp(mpmath.mpf(theta0) + two_pi * _frac(exact_turns))
                    angles: dict[str, float] = {}
                    turns, sample = timebase.sample_turns(stamp)
                    angles['timebase'] = sample.angle
                    whole = int(mpmath.nint((unwrapped - sample.angle) / two_pi))
                    check['turns_equal'] = check.get('turns_equal', True) and turns == whole
                    angles['naive'] = naive_accumulate(theta0, step, ticks)
                    if not model_used:
                        angles['naive, wrapped'] = naive_wrapped(theta0, step, ticks)
                    else:
                        angles['naive, wrapped'] = float(_wrap_mp(exact + rate * ticks))
                    ref = ref_mod.reference(model, exact, omega, 0.0)
                    for method, angle in angles.items():
                        if method == 'naive':
                            error = float(abs(mpmath.mpf(angle) - unwrapped))
                        else:
                            error = float(abs(_wrap_mp(mpmath.mpf(angle) - exact)))
                        angle_error[method] = max(angle_error.get(method, 0.0), error)
                        state = quiet_solve(scene, angle, omega, 0.0)
                        error = max(ref_mod.compare(state, ref).values())
                        state_error[method] = max(state_error.get(method, 0.0), error)
                rows.append(ClockRow(label, seconds, rpm, angle_error, state_error, model_used))
            tick()
    return rows, check


def _frac(x: Fraction) -> Fraction:
    return x - math.floor(x)


def _wrap_mp(x: Any) -> Any:
    import mpmath
    two_pi = 2 * mpmath.pi
    y = x - two_pi * mpmath.floor(x / two_pi + mpmath.mpf(0.5))
    return y + two_pi if y <= -mpmath.pi else y


def _angle_difference(angle: float, theta0: float, rpm: float, ticks: int) -> Any:
    import mpmath
    omega = rad_per_s_from_rpm(mpmath.mpf(rpm), mpmath.pi)
    exact = mpmath.mpf(theta0) + omega * ticks / TICK_HZ
    return _wrap_mp(mpmath.mpf(angle) - exact)
