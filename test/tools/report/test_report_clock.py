# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The report's clock section: the node's crank angle over long runs, simulated exactly.

The closed form of naive accumulation is checked bit for bit against
tick-by-tick accumulation; the time base stays within a few ulp of the exact
angle after a simulated year, naive accumulation does not.
"""

from __future__ import annotations

import math

from hypothesis import example, given, settings
from hypothesis import strategies as st
import pytest

from mech_kinematics.tools.report import clock
from mech_kinematics.tools.report.common import MODES
from mech_kinematics.units import rad_per_s_from_rpm

#: The time base's crank angle after any simulated run: a few ulp of pi, rad.
ATOL_TIMEBASE = 4 * math.ulp(math.pi)
#: The naive accumulation after a year at 1000 rpm is off by at least this, rad.
MIN_NAIVE_YEAR_ERROR = 1e-3


def steps():
    """Positive steps: the node's omega * dt at typical speeds, and arbitrary ones."""
    return st.one_of(st.sampled_from([rad_per_s_from_rpm(r) * 1e-3 for r in (10, 1000, 100_000)]),
                     st.sampled_from([0.5, 1.5, 0.375, 2.0 ** -10, 3 * 2.0 ** -40]),
                     st.floats(1e-9, 30.0))


def starts():
    """Start angles, including ones just below a power of two."""
    return st.one_of(st.floats(-4.0, 4.0), st.sampled_from([0.0, 2.0 ** 52, 2.0 ** 53 - 7]))


@given(steps(), starts(), st.integers(0, 20_000))
@example(0.5, 2.0 ** 52, 1000)        # ties to even: stagnation
@example(1.5, 2.0 ** 52 + 1, 1000)    # ties to even: first step differs
@example(0.7, 2.0 ** 53 - 7, 1000)    # crosses a binade
@settings(max_examples=200, deadline=None, derandomize=True)
def test_closed_form_accumulation_is_exact(step, start, ticks):
    """The binade-by-binade closed form equals tick-by-tick float accumulation bit for bit."""
    assert clock.naive_accumulate(start, step, ticks) == clock.naive_cumsum(start, step, ticks)


def test_closed_form_accumulation_of_a_year_is_fast():
    """3e10 ticks in a few hundred rational steps, and it agrees with a million ticks too."""
    step = rad_per_s_from_rpm(1e5) * 1e-3
    assert clock.naive_accumulate(1.0, step, 10**6) == clock.naive_cumsum(1.0, step, 10**6)
    year = clock.naive_accumulate(1.0, step, 365 * 86_400 * 1000)
    assert math.isfinite(year) and year > 3e11


def test_wrapped_trace_matches_the_loop():
    """The traced wrapped accumulation ends where the plain loop does."""
    step = rad_per_s_from_rpm(1000) * 1e-3
    trace = clock.naive_wrapped_trace(0.3, step, 5000, 1000)
    assert [k for k, _ in trace] == [1000, 2000, 3000, 4000, 5000]
    assert trace[-1][1] == clock.naive_wrapped(0.3, step, 5000)


@pytest.fixture(scope='module')
def clock_rows():
    """Compute the clock section in smoke size (one speed, four run times)."""
    return clock.clock_errors(MODES['smoke'])


def test_timebase_stays_exact(clock_rows):
    """After every run time the time base's crank angle is within a few ulp of pi."""
    rows, check = clock_rows
    assert check['brute_equal']
    for row in rows:
        assert row.angle_error['timebase'] <= ATOL_TIMEBASE, row


def test_naive_accumulation_drifts(clock_rows):
    """After a year the naive angle is off by radians-scale amounts, the wrapped one less."""
    rows, _ = clock_rows
    year = next(r for r in rows if r.duration == '1 year')
    assert year.angle_error['naive'] >= MIN_NAIVE_YEAR_ERROR
    assert year.angle_error['timebase'] < year.angle_error['naive, wrapped'] \
        < year.angle_error['naive']
    errors = [r.angle_error['naive'] for r in rows]
    assert errors == sorted(errors)


def test_the_node_clock_path_from_a_wall_clock_epoch(clock_rows):
    """The grid owes the last CLOCK_TICKS instants at each run time; whole turns are exact."""
    _, check = clock_rows
    assert check['grid_instants'] == [clock.CLOCK_TICKS] * len(MODES['smoke'].clock_durations)
    assert check['turns_equal']
    grid, timebase = clock.node_clock(1000.0, 0.5)
    assert grid.next_ns >= clock.EPOCH_NS and grid.next_ns % grid.period_ns == 0
    assert timebase.sample(grid.next_ns).angle == 0.5
    turns, sample = timebase.sample_turns(grid.next_ns + 3600 * 10 ** 9)
    assert turns == 60_000 and sample.angle == 0.5     # 1000 rpm for an hour: whole turns


def test_naive_error_is_not_wrapped(clock_rows):
    """The naive angle is never wrapped: its error grows past pi instead of saturating."""
    rows, _ = clock_rows
    year = next(r for r in rows if r.duration == '1 year')
    assert year.angle_error['naive'] > math.pi
