# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's diagnostics as a pure summary: counters, windows, levels and messages."""

import math

from mech_kinematics.ros.diagnostics import (DEFAULT_MAX_LATENESS_MS, ERROR, lateness_p99_ns,
                                             OK, solver_status, STALE, TickStats,
                                             timing_status, WARN)

NS = 1_000_000_000
NAME = {'name': 'mech_kinematics', 'hardware_id': 'four_bar'}


def window(published=1000, late=0, skipped=0, refused=0, near=0, jumps=0,
           late_by_ns=20_000_000):
    stats = TickStats()
    for k in range(published):
        stats.record(k, late_by_ns if k < late else 5_000, k < late, measure=0.5,
                     near_singular=k < near, sample=(0.1, 2.0, 0.0))
    for k in range(refused):
        stats.record(k, 5_000, False, error='RRR C cannot be solved', sample=(0.1, 2.0, 0.0))
    stats.skip(skipped)
    for _ in range(jumps):
        stats.clock_jump()
    return stats.take_window(stats._start + NS)


def test_ok_when_everything_is_published():
    """A window of 1000 published ticks on time is OK for both statuses."""
    w = window()
    assert solver_status(w, near_singular=1e-3, **NAME).level == OK
    timing = timing_status(w, rate_hz=1000.0, **NAME)
    assert timing.level == OK
    assert timing.message == ('ok: 0 late (caught up) and 0 skipped of 1000 ticks in 1.00 s; '
                              'p99 lateness 0.0 ms (WARN on a skipped instant or p99 above '
                              '100 ms)')
    assert timing.value('achieved_rate_hz') == '1000.000'
    assert timing.value('max_lateness_ms') == '100'


def test_caught_up_late_ticks_do_not_warn():
    """A burst of late ticks, all caught up and within max_lateness_ms, stays OK (issue 20).

    The case of the issue: 20 late and 0 skipped of 100 ticks on a loaded machine.
    """
    w = window(published=100, late=20, late_by_ns=40_000_000)
    timing = timing_status(w, rate_hz=100.0, **NAME)
    assert timing.level == OK
    assert '20 late (caught up) and 0 skipped of 100 ticks' in timing.message
    assert timing.value('lateness_p99_us') == '40000.0'


def test_one_skipped_instant_warns():
    """A single instant skipped (a subscriber misses it) is WARN, and the message says so."""
    timing = timing_status(window(skipped=1), rate_hz=1000.0, **NAME)
    assert timing.level == WARN
    assert timing.message == ('1 instant(s) skipped: 0 late (caught up) and 1 skipped of 1001 '
                              'ticks in 1.00 s')


def test_p99_lateness_above_the_bound_warns():
    """p99 lateness above max_lateness_ms is WARN; at or below it, OK."""
    w = window(late=20, late_by_ns=30_000_000)        # 2 % of ticks 30 ms late: p99 = 30 ms
    assert lateness_p99_ns(w) == 30_000_000
    below = timing_status(w, rate_hz=1000.0, max_lateness_ms=30.0, **NAME)
    assert below.level == OK
    above = timing_status(w, rate_hz=1000.0, max_lateness_ms=29.9, **NAME)
    assert above.level == WARN
    assert above.message.startswith('p99 lateness 30.0 ms above max_lateness_ms (29.9 ms)')
    assert above.value('max_lateness_ms') == '29.9'


def test_under_one_percent_of_late_ticks_is_below_p99():
    """Nine late ticks in 1000 do not move p99: a single stall in a second does not warn."""
    w = window(late=9, late_by_ns=500_000_000)
    assert lateness_p99_ns(w) == 5_000
    assert timing_status(w, rate_hz=1000.0, max_lateness_ms=1.0, **NAME).level == OK


def test_default_bound_is_the_catch_up_horizon():
    """By default the bound is 100 ms, max_catch_up_s's default: only skips warn."""
    assert DEFAULT_MAX_LATENESS_MS == 100.0


def test_a_clock_jump_warns():
    """A jump of the clock restarts the grid and warns."""
    timing = timing_status(window(jumps=1), rate_hz=1000.0, **NAME)
    assert timing.level == WARN and 'clock jumped 1 time' in timing.message


def test_refused_ticks_are_an_error_naming_the_reason():
    """Ticks that could not be solved make the solver status ERROR with the last reason."""
    solver = solver_status(window(refused=3), near_singular=1e-3, **NAME)
    assert solver.level == ERROR
    assert solver.message == 'cannot assemble at 3 of 1003 ticks: RRR C cannot be solved'
    assert solver.value('unsolved_ticks') == '3' and solver.value('crank_speed') == '2.0'


def test_near_singular_warns_and_waiting_says_for_what():
    """Near-singular ticks warn; a node waiting for /clock says so; an empty window is stale."""
    assert solver_status(window(near=2), near_singular=1e-3, **NAME).level == WARN
    waiting = solver_status(window(published=0), near_singular=1e-3, waiting_for='/clock',
                            **NAME)
    assert waiting.level == WARN and waiting.message == 'waiting for /clock: nothing published'
    assert solver_status(window(published=0), near_singular=1e-3, **NAME).level == STALE


def test_totals_accumulate_over_windows():
    """Totals add up across windows while window counts start again."""
    stats = TickStats()
    for k in range(3):
        stats.record(k, 0, False)
    first = stats.take_window()
    stats.record(3, 0, False)
    stats.skip(2)
    second = stats.take_window()
    assert (first.instants, second.instants) == (3, 1)
    assert second.totals['published'] == 4 and second.totals['skipped'] == 2
    assert second.last_published_stamp_ns == 3
    assert math.isinf(second.worst_measure)


def test_the_ticks_own_count_equals_record():
    """TickStats.published (the tick thread's call) counts as record without a refusal."""
    a, b = TickStats(near_singular=1e-3), TickStats(near_singular=1e-3)
    for k, measure in enumerate((0.5, 1e-4, 0.2)):
        a.record(k, 10 * k, k == 1, measure=measure, near_singular=measure < 1e-3,
                 sample=(0.1, 2.0, 0.0), jump=k == 2)
        b.published(k, 10 * k, k == 1, measure, (0.1, 2.0, 0.0), jump=k == 2)
    a.record(3, 30, False, measure=0.5, sample=(0.1, 2.0, 0.0), jump=True)
    b.published(3, 30, False, 0.5, (0.1, 2.0, 0.0), True)
    wa, wb = a.take_window(a._start + NS), b.take_window(b._start + NS)
    assert (wa.instants, wa.published, wa.late, wa.near_singular, wa.worst_measure,
            wa.lateness_ns, wa.last_published_stamp_ns, wa.jump_instants) == \
        (wb.instants, wb.published, wb.late, wb.near_singular, wb.worst_measure,
         wb.lateness_ns, wb.last_published_stamp_ns, wb.jump_instants) == \
        (4, 4, 1, 1, 1e-4, [0, 10, 20, 30], 3, 2)


def test_jump_instants_are_counted_at_level_ok():
    """Instants published one-sided at a jump (a Geneva wheel's) are counted, the level OK.

    See issue 19: they are answered, not refused.
    """
    stats = TickStats(near_singular=1e-3)
    for k in range(1000):
        stats.published(k, 5_000, False, 0.5, (0.1, 2.0, 0.0), k in (250, 750))
    first = stats.take_window(stats._start + NS)
    stats.published(1000, 5_000, False, 0.5, (0.1, 2.0, 0.0), True)
    second = stats.take_window(stats._start + NS)
    solver = solver_status(first, near_singular=1e-3, **NAME)
    assert solver.level == OK and solver.message == 'ok'
    assert solver.value('jump_instants') == '2' == solver.value('jump_instants_total')
    later = solver_status(second, near_singular=1e-3, **NAME)
    assert later.value('jump_instants') == '1' and later.value('jump_instants_total') == '3'


def test_several_drivers_are_listed_each_in_scene_order():
    """A sample of several drivers: their positions, speeds, accels, not a crank's (issue 18)."""
    stats = TickStats()
    stats.published(1, 5_000, False, 0.5, ((1.5, 2.75), (0.5, -0.25), (0.0, 0.0)))
    solver = solver_status(stats.take_window(stats._start + NS), near_singular=1e-3, **NAME)
    assert solver.value('driver_positions') == '1.5, 2.75'
    assert solver.value('driver_speeds') == '0.5, -0.25'
    assert solver.value('driver_accels') == '0.0, 0.0'
    assert 'crank_angle' not in dict(solver.values)


def test_a_stamp_jumping_back_warns_once_and_is_counted():
    """Topic drive: a jump of the input's stamp back is WARN in its window, counted (issue 33).

    The next window is OK again; the total and the last jump stay.
    """
    stats = TickStats(near_singular=1e-3)
    far, back = (2**31 - 1) * NS, 1_700_000_000 * NS
    for stamp, jumped_from in ((far, None), (back, far), (back + 1, None)):
        stats.record(stamp, 5_000, False, measure=0.5)
        stats.topic_input(stamp, jumped_from, (), ())
    first = solver_status(stats.take_window(stats._start + NS), near_singular=1e-3,
                          extra_joints='refuse', **NAME)
    assert first.level == WARN
    jump = 'from 2147483647.000000000 s to 1700000000.000000000 s, 447483647 s back'
    assert first.message == f'input stamp jumped back 1 time(s) (the order reset), last {jump}'
    assert first.value('stamp_jumps_back') == '1' == first.value('stamp_jumps_back_total')
    assert first.value('last_stamp_jump_back') == jump
    stats.record(back + 2, 5_000, False, measure=0.5)
    stats.topic_input(back + 2, None, (), ())
    second = solver_status(stats.take_window(stats._start + NS), near_singular=1e-3,
                           extra_joints='refuse', **NAME)
    assert second.level == OK and second.message == 'ok'
    assert (second.value('stamp_jumps_back'), second.value('stamp_jumps_back_total')) == ('0', '1')
    assert second.value('last_stamp_jump_back') == jump


def test_the_joints_ignored_and_passed_are_said_in_topic_drive_only():
    """The last input's joints ignored and passed are values of the status; time drive has none."""
    stats = TickStats()
    stats.record(1, 5_000, False, measure=0.5)
    stats.topic_input(1, None, ('coupler',), tuple(f'j{k}' for k in range(25)))
    window = stats.take_window(stats._start + NS)
    solver = solver_status(window, near_singular=1e-3, extra_joints='pass', **NAME)
    assert solver.level == OK
    assert solver.value('extra_joints') == 'pass'
    assert solver.value('ignored_joints') == 'coupler'
    assert solver.value('passed_joints') == ', '.join(f'j{k}' for k in range(20)) + ' and 5 more'
    keys = dict(solver_status(window, near_singular=1e-3, **NAME).values)
    assert not {'extra_joints', 'passed_joints', 'stamp_jumps_back'} & set(keys)
