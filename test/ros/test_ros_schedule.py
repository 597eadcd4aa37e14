# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The tick grid: exact instants, catch-up up to a bound, skip mode, rate changes (issue 14)."""

from hypothesis import given, strategies as st
import pytest

from mech_kinematics.ros.schedule import period_ns_from_rate, TickGrid

MS = 1_000_000


def test_aligned_grid_starts_at_the_next_multiple_of_the_period():
    """TickGrid.aligned puts the first instant on the next multiple of the period."""
    assert TickGrid.aligned(1_234_567, MS).next_ns == 2 * MS
    assert TickGrid.aligned(3 * MS, MS).next_ns == 3 * MS
    assert TickGrid.aligned(-1, MS).next_ns == 0


def test_nothing_is_due_before_the_next_instant():
    """A wake-up before the next instant owes nothing and takes nothing."""
    grid = TickGrid(10 * MS, MS)
    due = grid.take(10 * MS - 1, 100 * MS)
    assert list(due.instants) == [] and due.skipped == 0 and grid.next_ns == 10 * MS


def test_a_late_wake_up_catches_up_every_missed_instant_in_order():
    """Waking 3.5 periods late publishes the 4 owed instants in order, skipping none."""
    grid = TickGrid(10 * MS, MS)
    due = grid.take(13 * MS + MS // 2, 100 * MS)
    assert list(due.instants) == [10 * MS, 11 * MS, 12 * MS, 13 * MS] and due.skipped == 0
    assert grid.next_ns == 14 * MS


def test_catch_up_is_bounded_and_the_oldest_are_skipped():
    """Beyond max_behind the oldest owed instants are skipped and counted."""
    grid = TickGrid(0, MS)
    due = grid.take(999 * MS, 100 * MS)
    assert list(due.instants) == [k * MS for k in range(899, 1000)]
    assert due.skipped == 899


def test_skip_mode_publishes_only_the_latest():
    """late_ticks: skip publishes the latest owed instant, stamped on the grid."""
    grid = TickGrid(0, MS)
    due = grid.take(5 * MS + 7, 100 * MS, catch_up=False)
    assert list(due.instants) == [5 * MS] and due.skipped == 5


def test_a_rate_change_starts_a_new_grid_at_the_next_instant():
    """set_period keeps the next instant and spaces the later ones by the new period."""
    grid = TickGrid(0, MS)
    grid.take(2 * MS, 100 * MS)
    grid.set_period(MS // 4)
    due = grid.take(4 * MS, 100 * MS)
    assert list(due.instants) == [3 * MS + k * MS // 4 for k in range(5)]


@given(start=st.integers(0, 10 ** 12), period=st.integers(100_000, 10 ** 8),
       wakes=st.lists(st.integers(0, 10 ** 8), min_size=1, max_size=30))
def test_catch_up_publishes_every_instant_exactly_once(start, period, wakes):
    """With a large enough bound, any wake-ups yield start + k * period, k = 0, 1, ... once."""
    grid = TickGrid(start, period)
    now = start
    published = []
    for step in wakes:
        now += step
        published.extend(grid.take(now, 10 ** 18).instants)
    count = (now - start) // period + 1
    assert published == [start + k * period for k in range(count)]


def test_period_from_rate():
    """Rates round to whole nanoseconds; a period is never 0."""
    assert period_ns_from_rate(1000.0) == MS
    assert period_ns_from_rate(3.0) == 333_333_333
    assert period_ns_from_rate(1e12) == 1
    with pytest.raises(ValueError, match='positive period'):
        TickGrid(0, 0)
