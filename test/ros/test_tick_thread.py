# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's tick thread (ros/tick_thread.py) on stand-ins: a clock, a solver, a publisher.

What one instant does (solve, publish, count; or count and say why not), and
the thread's life: it ticks on the clock, stops when asked, waits for a
simulated clock's first ``/clock``, and a failure stops it loudly. The node's
stamps and timing seen from a subscriber are ``test_kinematics_node_grid.py``'s.
"""

import math
import time

import pytest

import mech_kinematics as mk
from mech_kinematics.ros.diagnostics import TickStats, timing_status, WARN
from mech_kinematics.ros.driver import TickDriver
from mech_kinematics.ros.publishing import RCLError
from mech_kinematics.ros.tick_thread import (CLOCK_READ_NS, LATE_NS, read_system_clock,
                                             TickThread)
from mech_kinematics.ros.timebase import CrankTimebase
from mech_kinematics.units import NS_PER_S, rad_per_s_from_rpm

MS = 1_000_000
#: The deadline of a thread's event here, s.
DEADLINE_S = 20.0


class Clock:
    """A stand-in clock: system time unless ``sim``, at ``ns`` when simulated."""

    def __init__(self, sim=False, ns=0):
        self.ros_time_is_active, self.ns = sim, ns

    def now(self):
        return self

    @property
    def nanoseconds(self):
        return self.ns


class Logger:
    def __init__(self):
        self.lines = []

    def warning(self, text, **kwargs):
        self.lines.append(('warning', text))

    def fatal(self, text):
        self.lines.append(('fatal', text))


class Solver:
    """A stand-in SolverPath: the angle back as the values; a refusal or a failure if asked."""

    def __init__(self, error=None, measure=1.0):
        self.max_error, self.error, self.measure = 1e-6, error, measure
        self.jumps_at = None
        self.asked = []

    def solve(self, angle, speed, accel, tol, turns):
        self.asked.append((angle, speed, accel, tol, turns))
        if self.error is not None:
            raise self.error
        return [angle, speed], self.measure


class Publishing:
    def __init__(self):
        self.ticks = []

    def tick(self, values, stamp, sec, nanosec):
        self.ticks.append((values, stamp, sec, nanosec))


def _thread(clock=None, solver=None, period_ns=MS, drivers=('crank',)):
    """Return (a TickThread set for one or more cranks at 60 rpm, its parts)."""
    driver = TickDriver(period_ns, 100 * MS)
    for name in drivers:
        driver.add_drive(name, CrankTimebase, angle=0.0, speed_rpm=60.0, accel=0.0,
                         max_speed_rpm=1000.0)
    stats, logger, failures = TickStats(mk.NEAR_SINGULAR), Logger(), []
    ticks = TickThread(clock or Clock(), driver, stats, logger, lambda: failures.append(1),
                       lambda: False)
    ticks.solver, ticks.publishing = solver or Solver(), Publishing()
    return ticks, stats, logger, failures


def test_each_owed_instant_is_solved_published_and_counted_with_its_lateness():
    """Instants in order, each with its drivers' state; late beyond min(period / 2, 1 ms)."""
    ticks, stats, _, _ = _thread()
    ticks.publish(range(0, 4 * MS, MS), skipped=2, woke=3 * MS + min(MS // 2, LATE_NS))
    assert [stamp for _, stamp, _, _ in ticks.publishing.ticks] == [0, MS, 2 * MS, 3 * MS]
    assert ticks.publishing.ticks[1][2:] == (0, MS)
    angle, speed, accel, tol, turns = ticks.solver.asked[1]
    assert (speed, accel, tol, turns) == (rad_per_s_from_rpm(60.0), 0.0, 1e-6, 0)
    assert angle == pytest.approx(2 * math.pi * 1e-3, rel=1e-15)
    window = stats.take_window()
    assert (window.instants, window.published, window.skipped) == (4, 4, 2)
    assert window.late == 3       # all but the last, published half a period after it


def test_several_drivers_are_solved_together_in_scene_order():
    """Each driver's position, speed and acceleration, and whole turns, as one call."""
    ticks, _, _, _ = _thread(drivers=('left', 'right'))
    ticks.publish(range(0, 1), skipped=0, woke=0)
    [(angles, speeds, accels, _, turns)] = ticks.solver.asked
    assert angles == (0.0, 0.0) and speeds == (rad_per_s_from_rpm(60.0),) * 2
    assert turns == (0, 0)


@pytest.mark.parametrize('error, kind', [
    (mk.AssemblyError('C', 1.0, 'apart'), 'cannot assemble'),
    (mk.UntrustedError('C', 1.0, 'its bound is 1e-3', 'joints.rocker.acceleration', 1e-3,
                       1e-6), 'not trusted')])
def test_an_instant_that_cannot_be_solved_publishes_nothing_and_says_why(error, kind):
    """Refused: nothing published, counted with its reason, one warning."""
    ticks, stats, logger, _ = _thread(solver=Solver(error=error))
    ticks.publish(range(0, 2 * MS, MS), skipped=0, woke=MS)
    assert ticks.publishing.ticks == []
    window = stats.take_window()
    assert (window.unsolved, window.last_refusal, window.last_error) == (2, kind, str(error))
    assert logger.lines[0] == ('warning', f'no state published: {error}')


def test_a_near_singular_pose_is_published_and_warned_about():
    """A measure below NEAR_SINGULAR: published, counted and logged with the crank angle."""
    ticks, stats, logger, _ = _thread(solver=Solver(measure=mk.NEAR_SINGULAR / 2))
    ticks.publish(range(1), skipped=0, woke=0)
    assert len(ticks.publishing.ticks) == 1 and stats.take_window().near_singular == 1
    assert logger.lines == [('warning', 'near-singular pose at crank angle 0.000000 rad: '
                                        f'measure {mk.NEAR_SINGULAR / 2:.3g}')]


def _wait(predicate, what):
    deadline = time.monotonic() + DEADLINE_S
    while not predicate():
        assert time.monotonic() < deadline, f'timed out waiting for {what}'
        time.sleep(0.001)


def test_the_thread_ticks_on_the_system_clock_until_stopped():
    """Started: every 1 ms instant published in order; stopped: it ends and publishes no more."""
    ticks, _, _, _ = _thread()
    solver, publishing = ticks.solver, ticks.publishing
    ticks.start(solver, publishing, None)
    assert ticks.running
    _wait(lambda: len(publishing.ticks) >= 5, 'five ticks')
    ticks.stop()
    assert not ticks.running
    count = len(publishing.ticks)
    stamps = [stamp for _, stamp, _, _ in publishing.ticks]
    assert all(b - a == MS for a, b in zip(stamps, stamps[1:], strict=False))
    assert stamps[0] % MS == 0
    time.sleep(0.01)
    assert len(publishing.ticks) == count


class Descheduling:
    """System and monotonic clocks of one virtual time, the thread away between their reads.

    Virtual time is the real monotonic clock plus ``away``; every ``every``-th
    read of the system clock is followed by ``gap_ns`` away (both clocks move
    on, as when the thread is descheduled), and ``jump_ns`` once sets the
    system clock alone ahead (a real jump).
    """

    def __init__(self, every, gap_ns):
        self.every, self.gap_ns, self.reads, self.away = every, gap_ns, 0, 0
        self.epoch, self.jump_ns = 1_780_000_000 * NS_PER_S, 0

    def monotonic_ns(self):
        return time.monotonic_ns() + self.away

    def time_ns(self):
        self.reads += 1
        now = self.monotonic_ns() + self.epoch + self.jump_ns
        if self.reads % self.every == 0:
            self.away += self.gap_ns
        return now


@pytest.mark.parametrize('jump_ns', [0, 50 * MS])
def test_a_thread_descheduled_between_its_clock_reads_sees_no_jump(jump_ns):
    """15 ms away between the reads of system and monotonic clocks, 20 times: no jump counted.

    The same loop still counts a real jump of the system clock (50 ms).
    """
    ticks, stats, logger, _ = _thread()
    clocks = Descheduling(every=7, gap_ns=15 * MS)
    ticks.time_ns, ticks.monotonic_ns = clocks.time_ns, clocks.monotonic_ns
    ticks.start(ticks.solver, ticks.publishing, None)
    _wait(lambda: clocks.reads >= 70, 'ten deschedules')
    clocks.jump_ns = jump_ns
    _wait(lambda: clocks.reads >= 140, 'ten more')
    ticks.stop()
    jumps = stats.take_window().totals['clock_jumps']
    warned = [text for _, text in logger.lines if 'jumped' in text]
    if jump_ns:
        assert jumps == 1 and warned == ['the system clock jumped by +0.050 s: the tick grid '
                                         'starts again']
    else:
        assert (jumps, warned) == (0, [])


def test_the_clocks_are_read_again_while_the_bracket_is_wide():
    """The narrowest of the tries: a read away 15 ms is read again, the sharp one is taken."""
    clocks = Descheduling(every=1, gap_ns=15 * MS)
    _, before, after = read_system_clock(clocks.time_ns, clocks.monotonic_ns)
    assert after - before >= 15 * MS        # away after every read: no sharp one to be had
    clocks.every = 2
    clocks.reads = 1        # the next read of the system clock is followed by time away
    now, before, after = read_system_clock(clocks.time_ns, clocks.monotonic_ns)
    assert after - before <= CLOCK_READ_NS and clocks.reads == 3
    assert before <= now - clocks.epoch <= after


def test_a_simulated_clock_before_its_first_message_waits_and_says_so_once():
    """use_sim_time with no /clock (time 0): nothing published, one warning, waiting_for_clock."""
    clock = Clock(sim=True, ns=0)
    ticks, _, logger, _ = _thread(clock=clock)
    ticks.start(ticks.solver, ticks.publishing, None)
    _wait(lambda: ticks.waiting_for_clock, 'waiting for /clock')
    clock.ns = 5 * NS_PER_S
    ticks.clock_event.set()
    _wait(lambda: ticks.publishing.ticks, 'a tick on the simulated clock')
    ticks.stop()
    assert not ticks.waiting_for_clock
    assert ticks.publishing.ticks[0][1] == 5 * NS_PER_S
    assert [line for line in logger.lines if 'no /clock' in line[1]] == [
        ('warning', 'use_sim_time is true and no /clock has been received: nothing is '
                    'published until one arrives')]


def test_an_unexpected_error_stops_the_thread_loudly():
    """A bug in a tick: the thread ends, logs the traceback as fatal and calls on_failure."""
    ticks, _, logger, failures = _thread(solver=Solver(error=RuntimeError('injected')))
    ticks.start(ticks.solver, ticks.publishing, None)
    _wait(lambda: failures, 'the failure')
    assert ticks.failed
    [(level, text)] = logger.lines
    assert level == 'fatal' and text.startswith('tick thread failed:\nTraceback')
    assert 'RuntimeError: injected' in text
    ticks.stop()
    assert not ticks.running


class RefusingPublishing(Publishing):
    """A publisher the middleware refuses at the stamps given (rclpy's RCLError)."""

    def __init__(self, refused):
        super().__init__()
        self.refused = set(refused)

    def tick(self, values, stamp, sec, nanosec):
        if stamp in self.refused:
            raise RCLError('Failed to publish: cannot publish data, at '
                           '/project/src/rmw_publish.cpp:120')
        super().tick(values, stamp, sec, nanosec)


def test_a_publish_the_middleware_refuses_loses_that_state_not_the_node():
    """A publish the middleware refuses (RCLError): counted, said, the next ones published.

    A reliable subscriber too slow for 5 kHz made Fast DDS refuse a publish in
    one CI run, and the node stopped (the tick thread's fatal error).
    """
    ticks, stats, logger, failures = _thread()
    ticks.publishing = RefusingPublishing({MS})
    ticks.publish(range(0, 3 * MS, MS), skipped=0, woke=2 * MS)
    assert [stamp for _, stamp, _, _ in ticks.publishing.ticks] == [0, 2 * MS]
    assert failures == [] and not ticks.failed
    window = stats.take_window()
    assert (window.instants, window.published, window.publish_failures) == (3, 2, 1)
    assert window.last_publish_failure == ('at 0.001000000 s: Failed to publish: cannot '
                                           'publish data')
    assert window.totals['publish_failures'] == 1
    [(level, text)] = logger.lines
    assert level == 'warning' and text.startswith(
        'a state was not delivered (Failed to publish: cannot publish data)')
    status = timing_status(window, name='n', hardware_id='h', rate_hz=1000.0)
    values = dict(status.values)
    assert status.level == WARN and status.message.startswith('1 state(s) not delivered')
    assert (values['publish_failures'], values['publish_failures_total']) == ('1', '1')


def test_a_refused_publish_while_stopping_ends_the_loop_quietly():
    """The context going away under a publish is the stop, not a state lost."""
    ticks, stats, logger, _ = _thread()
    ticks.publishing = RefusingPublishing({0})
    ticks._stop.set()
    with pytest.raises(RCLError):
        ticks.publish(range(1), skipped=0, woke=0)
    assert stats.take_window().publish_failures == 0 and logger.lines == []
