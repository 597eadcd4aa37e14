# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's clock as a pure driver, run on a fake clock with no ROS (issue 17).

A test plays the node: it reads a clock of its own, calls ``step`` and takes
each driver's state at the instants it gets back.
"""

from fractions import Fraction
import math
import sys

from hypothesis import given, strategies as st
import pytest

from mech_kinematics.ros.driver import CLOCK_JUMP_NS, TickDriver
from mech_kinematics.ros.timebase import (ActuatorSample, ActuatorTimebase, turns_from_radians,
                                          TWO_PI)
from mech_kinematics.units import NS_PER_S, rad_per_s_from_rpm

MS = 1_000_000
#: A wall-clock epoch (ns) and a monotonic reading that goes with it.
EPOCH = 1_780_000_000 * NS_PER_S + 123_456_789
MONO = 5_000 * NS_PER_S


def crank_driver(period_ns=MS, max_behind_ns=100 * MS, catch_up=True, **start):
    """Return a driver of one crank, at angle 0, 60 rpm unless ``start`` says otherwise."""
    driver = TickDriver(period_ns, max_behind_ns, catch_up)
    values = {'angle': 0.0, 'accel': 0.0, 'max_speed_rpm': 10_000.0}
    values.update(start if 'speed' in start or 'speed_rpm' in start else
                  dict(start, speed_rpm=60.0))
    driver.add_drive('crank', **values)
    return driver


def publish(driver, wake):
    """Return [(stamp, whole turns, sample)] of a wake-up, as the node publishes them."""
    return [(t, *driver.state_at(t)[0]) for t in wake.instants]


def exact_turns(driver, stamp):
    """Return the crank's exact position in turns at ``stamp``."""
    return driver.drives['crank'].timebase.total_turns(stamp)


def test_the_first_wake_up_waits_for_the_next_multiple_of_the_period():
    """System time: the grid is the multiples of the period, the first one at or after now."""
    driver = crank_driver(period_ns=10 * MS)
    wake = driver.step(EPOCH, monotonic_ns=MONO)
    first = -(-EPOCH // (10 * MS)) * 10 * MS
    assert list(wake.instants) == [] and wake.wait_ns == first - EPOCH and wake.jump_ns is None
    wake = driver.step(first + 3, monotonic_ns=MONO + first + 3 - EPOCH)
    assert list(wake.instants) == [first] and wake.wait_ns == 0


@given(rate=st.sampled_from([1.0, 30.0, 100.0, 333.0, 1000.0]),
       lags=st.lists(st.integers(0, 3 * MS), min_size=1, max_size=40))
def test_every_grid_instant_is_published_once_and_exactly_on_the_grid(rate, lags):
    """Whatever the wake-ups' lateness (within the catch-up bound), the stamps are k * period."""
    period = max(1, round(NS_PER_S / rate))
    driver = crank_driver(period_ns=period, max_behind_ns=NS_PER_S)
    now = EPOCH
    stamps = []
    for lag in lags:
        wake = driver.step(now, monotonic_ns=now - EPOCH + MONO)
        stamps += [t for t, _, _ in publish(driver, wake)]
        now += max(wake.wait_ns, 1) + lag
    if stamps:
        assert all(t % period == 0 for t in stamps)
        assert stamps == list(range(stamps[0], stamps[-1] + 1, period))


def test_a_late_wake_up_catches_up_up_to_max_catch_up_and_counts_the_rest():
    """Waking 1 s late at 1 kHz with a 0.1 s bound publishes the last 101 instants, skips 899."""
    driver = crank_driver(period_ns=MS, max_behind_ns=100 * MS)
    start = 10 * NS_PER_S
    assert [t for t, _, _ in publish(driver, driver.step(start, monotonic_ns=start))] == [start]
    wake = driver.step(start + NS_PER_S, monotonic_ns=start + NS_PER_S)
    assert list(wake.instants) == [start + k * MS for k in range(900, 1001)]
    assert wake.skipped == 899


def test_skip_mode_publishes_only_the_latest_owed_instant():
    """late_ticks: skip: one instant, the latest on the grid."""
    driver = crank_driver(period_ns=MS, catch_up=False)
    publish(driver, driver.step(0, monotonic_ns=0))
    wake = driver.step(5 * MS + 7, monotonic_ns=5 * MS + 7)
    assert list(wake.instants) == [5 * MS] and wake.skipped == 4


@pytest.mark.parametrize('jump', [-3_600 * NS_PER_S, -CLOCK_JUMP_NS - MS, CLOCK_JUMP_NS + MS,
                                  86_400 * NS_PER_S])
def test_a_system_clock_jump_starts_a_new_grid_and_the_crank_goes_on(jump):
    """A jump of the system clock against the monotonic one is reported; the grid restarts.

    The crank is a function of the clock: after the jump it is where that
    clock says, with no instant published twice and no catch-up burst.
    """
    driver = crank_driver(period_ns=MS)
    now, mono = EPOCH - EPOCH % MS, MONO
    publish(driver, driver.step(now, monotonic_ns=mono))
    before = exact_turns(driver, now)
    now, mono = now + jump + MS, mono + MS
    wake = driver.step(now, monotonic_ns=mono)
    assert wake.jump_ns == jump
    assert list(wake.instants) == [now] and wake.skipped == 0
    [(t, _, _)] = publish(driver, wake)
    assert exact_turns(driver, t) - before == Fraction(jump + MS, NS_PER_S)    # 60 rpm
    wake = driver.step(now + MS, monotonic_ns=mono + MS)
    assert wake.jump_ns is None and list(wake.instants) == [now + MS]


def test_a_small_clock_adjustment_is_not_a_jump():
    """A change of the offset within CLOCK_JUMP_NS keeps the grid."""
    driver = crank_driver(period_ns=MS)
    publish(driver, driver.step(0, monotonic_ns=0))
    wake = driver.step(MS + CLOCK_JUMP_NS, monotonic_ns=MS)
    assert wake.jump_ns is None
    assert list(wake.instants) == [k * MS for k in range(1, 12)]


def test_a_deschedule_between_the_clock_reads_is_not_a_jump():
    """A thread away between its clock reads sees no jump; a real one is seen through the bracket.

    The node warned "the system clock jumped by +0.010 s" about every 2 s
    under load (issue 42): it read the system clock, was descheduled, then
    read the monotonic clock, and took the time away for a change of offset.
    """
    driver = crank_driver(period_ns=MS)
    publish(driver, driver.step(0, monotonic_ns=0, monotonic_after_ns=0))
    # The system clock read at 5 ms, then 15 ms away before the monotonic clock's second read.
    wake = driver.step(5 * MS, monotonic_ns=5 * MS, monotonic_after_ns=20 * MS)
    assert wake.jump_ns is None
    assert list(wake.instants) == [k * MS for k in range(1, 6)]
    assert driver.step(21 * MS, monotonic_ns=21 * MS).jump_ns is None
    # Set 30 ms ahead, read with the same 15 ms away: 15 ms at least, a jump.
    wake = driver.step(52 * MS, monotonic_ns=22 * MS, monotonic_after_ns=37 * MS)
    assert wake.jump_ns == 52 * MS - (22 * MS + 37 * MS) // 2
    # Only the bracket can hide a change: the same 15 ms away read the other way is no jump.
    driver = crank_driver(period_ns=MS)
    driver.step(0, monotonic_ns=0, monotonic_after_ns=15 * MS)
    assert driver.step(16 * MS, monotonic_ns=16 * MS).jump_ns is None


def test_the_sharpest_reading_of_the_offset_is_kept():
    """A wide first reading gives way to a sharp one: the bracket does not hide jumps for ever."""
    driver = crank_driver(period_ns=MS)
    driver.step(0, monotonic_ns=0, monotonic_after_ns=40 * MS)
    assert driver.step(41 * MS, monotonic_ns=41 * MS).jump_ns is None
    wake = driver.step(42 * MS + CLOCK_JUMP_NS + MS, monotonic_ns=42 * MS)
    assert wake.jump_ns == CLOCK_JUMP_NS + MS


def test_sim_time_waits_for_a_clock_then_follows_it():
    """Simulated time: nothing before the first /clock; then the instants up to each reading."""
    driver = crank_driver(period_ns=10 * MS)
    assert driver.step(0, sim=True).waiting_for_clock
    wake = driver.step(25 * MS, sim=True)
    assert not wake.waiting_for_clock and list(wake.instants) == []
    assert list(driver.step(30 * MS, sim=True).instants) == [30 * MS]
    assert list(driver.step(65 * MS, sim=True).instants) == [40 * MS, 50 * MS, 60 * MS]
    assert list(driver.step(66 * MS, sim=True).instants) == []


def test_sim_time_going_back_is_a_jump_and_a_new_grid():
    """A simulated clock set back (a bag replayed again) restarts the grid, counted as a jump."""
    driver = crank_driver(period_ns=10 * MS)
    publish(driver, driver.step(100 * MS, sim=True))
    wake = driver.step(20 * MS, sim=True)
    assert wake.jump_ns == 20 * MS - 100 * MS
    assert list(wake.instants) == [20 * MS]


def test_sim_time_jumping_forward_catches_up_within_the_bound():
    """A simulated clock that leaps a day publishes max_catch_up of instants, in order."""
    driver = crank_driver(period_ns=10 * MS, max_behind_ns=100 * MS)
    publish(driver, driver.step(10 * MS, sim=True))
    day = 86_400 * NS_PER_S
    wake = driver.step(day, sim=True)
    assert list(wake.instants) == [day - k * 10 * MS for k in range(10, -1, -1)]
    assert wake.skipped == day // (10 * MS) - 1 - 11


def test_switching_the_time_source_keeps_the_crank_where_it_was():
    """System -> sim time: the crank goes on from its last instant, not from the new epoch."""
    driver = crank_driver(period_ns=MS, speed_rpm=60.0)
    publish(driver, driver.step(EPOCH - EPOCH % MS, monotonic_ns=MONO))
    last = driver.last_stamp
    before = exact_turns(driver, last)
    [(t, _, _)] = publish(driver, driver.step(7 * MS, sim=True))
    assert t == 7 * MS and exact_turns(driver, t) == before
    [(t2, _, _)] = publish(driver, driver.step(8 * MS, sim=True))
    assert exact_turns(driver, t2) - before == Fraction(MS, NS_PER_S)


def test_a_rate_change_starts_a_new_grid_at_the_next_instant():
    """A new period spaces the instants after the next unpublished one by the new period."""
    driver = crank_driver(period_ns=MS)
    publish(driver, driver.step(0, monotonic_ns=0))
    publish(driver, driver.step(2 * MS, monotonic_ns=2 * MS))
    driver.period_ns = MS // 4
    wake = driver.step(4 * MS, monotonic_ns=4 * MS)
    assert list(wake.instants) == [3 * MS + k * MS // 4 for k in range(5)]


def test_a_speed_change_applies_at_the_next_instant_and_keeps_the_angle_continuous():
    """A requested speed takes over at the next unpublished instant, from the exact angle."""
    driver = crank_driver(period_ns=MS, speed_rpm=60.0)
    publish(driver, driver.step(0, monotonic_ns=0))
    publish(driver, driver.step(10 * MS, monotonic_ns=10 * MS))
    driver.request('crank', speed_rpm=-120.0)
    samples = publish(driver, driver.step(12 * MS, monotonic_ns=12 * MS))
    (t11, _, s11), (t12, _, s12) = samples
    # Up to 11 ms at 1 turn/s, the new speed (-2 turns/s) applies from 11 ms on.
    assert exact_turns(driver, t11) == Fraction(11, 1000)
    assert exact_turns(driver, t12) == Fraction(11, 1000) - Fraction(2, 1000)
    assert s11.speed == s12.speed == rad_per_s_from_rpm(-120.0)


def test_an_acceleration_change_goes_on_from_the_speed_there():
    """crank_accel alone keeps the speed at the instant it applies."""
    driver = crank_driver(period_ns=MS, speed_rpm=60.0)
    publish(driver, driver.step(0, monotonic_ns=0))
    driver.request('crank', accel=float(2 * math.pi))
    [(t, _, sample)] = publish(driver, driver.step(MS, monotonic_ns=MS))
    # The speed goes on as the float it was published as (60 rpm = 60 * pi / 30 rad/s).
    assert t == MS and sample.speed == rad_per_s_from_rpm(60.0)
    assert sample.accel == 2 * math.pi
    [(_, _, later)] = publish(driver, driver.step(2 * MS, monotonic_ns=2 * MS))
    assert later.speed == pytest.approx(2 * math.pi * 1.001, rel=1e-15)
    turns_per_s = driver.drives['crank'].timebase.speed(2 * MS)
    assert turns_per_s == 1 + turns_from_radians(2 * math.pi) / 1000


def test_changes_before_the_first_instant_are_its_start_values():
    """A change requested before anything is published becomes the drive's start."""
    driver = crank_driver(speed_rpm=60.0)
    driver.request('crank', speed_rpm=30.0)
    driver.apply_now(5)
    assert driver.drives['crank'].start['speed_rpm'] == 30.0
    [(t, _, sample)] = publish(driver, driver.step(0, monotonic_ns=0))
    assert sample.speed == rad_per_s_from_rpm(30.0) and exact_turns(driver, t) == 0


def test_changes_while_not_ticking_apply_after_the_last_published_instant():
    """apply_now never moves a published instant: it applies one ns after the last one."""
    driver = crank_driver(period_ns=MS, speed_rpm=60.0)
    publish(driver, driver.step(0, monotonic_ns=0))
    publish(driver, driver.step(MS, monotonic_ns=MS))
    driver.request('crank', speed_rpm=0.0)
    driver.apply_now(0)        # a clock behind the last stamp
    assert exact_turns(driver, MS) == Fraction(1, 1000)
    assert exact_turns(driver, 5 * MS) == Fraction(1, 1000) + Fraction(1, NS_PER_S)


def test_an_unknown_drive_change_is_refused():
    """Only speed_rpm, speed, accel and max_speed_rpm are drive changes."""
    driver = crank_driver()
    with pytest.raises(ValueError, match=r"^Expected drive changes among .*got \['rpm'\]$"):
        driver.request('crank', rpm=1.0)


@pytest.mark.parametrize('start, published', [
    ({'speed': 10.0}, 10.0),
    ({'speed': -12.56637061435917}, -12.56637061435917),
    ({'speed_rpm': 95.4929658551372}, rad_per_s_from_rpm(95.4929658551372)),
    ({'speed_rpm': -120.0}, -120.0 * math.pi / 30),
])
def test_a_speed_is_published_as_the_float_of_the_unit_it_was_given_in(start, published):
    """rad/s stay the float given; rpm become rpm * pi / 30, as the scene reader computes them.

    Before issue 17, 10 rad/s went through 12-digit rpm and came out as
    9.999999999996104, and -120 rpm as float(-4 pi) = -12.566370614359172.
    """
    driver = crank_driver(**start)
    for now in (0, MS, NS_PER_S, 3_600 * NS_PER_S):
        for _, _, sample in publish(driver, driver.step(now, monotonic_ns=now)):
            assert sample.speed == published
            assert math.copysign(1.0, sample.speed) == math.copysign(1.0, published)


def test_a_speed_given_in_rad_per_s_is_exact_and_drift_free():
    """10 rad/s for a day: the position is exactly 10 * t / (2 pi) turns of the rational 2 pi."""
    driver = crank_driver(period_ns=MS, speed=10.0)
    publish(driver, driver.step(0, monotonic_ns=0))
    day = 86_400 * NS_PER_S
    driver.max_behind_ns = 0
    [(t, turns, sample)] = publish(driver, driver.step(day, monotonic_ns=day))
    exact = Fraction(10 * 86_400) / TWO_PI
    assert exact_turns(driver, t) == exact
    assert turns == round(exact)
    assert sample.angle == pytest.approx(float((exact - round(exact)) * TWO_PI), abs=1e-15)


def test_each_driver_has_its_own_time_base():
    """Two drivers, each from its own start values, change independently."""
    driver = TickDriver(MS, 100 * MS)
    driver.add_drive('left', angle=0.0, speed_rpm=60.0, accel=0.0, max_speed_rpm=1000.0)
    driver.add_drive('right', angle=math.pi / 2, speed=-1.0, accel=0.0, max_speed_rpm=1000.0)
    driver.step(0, monotonic_ns=0)
    driver.state_at(0)
    driver.request('right', speed=2.0)
    (_, left), (_, right) = driver.state_at(MS)
    assert left.speed == rad_per_s_from_rpm(60.0) and right.speed == 2.0
    assert driver.drives['left'].timebase.total_turns(MS) == Fraction(1, 1000)
    assert right.angle == pytest.approx(math.pi / 2 - 1e-3, abs=1e-15)


def test_the_driver_imports_no_ros():
    """The driver and what it imports load without rclpy (the node is its only adapter)."""
    import subprocess
    code = ('import sys; sys.modules["rclpy"] = None; import mech_kinematics.ros.driver; '
            'assert not any(m.startswith(("rclpy", "rosidl")) for m in sys.modules '
            'if sys.modules[m] is not None)')
    subprocess.run([sys.executable, '-c', code], check=True)


def test_resuming_owes_nothing_from_the_pause():
    """After resume() (the node activated again) the grid starts anew: no catch-up burst."""
    driver = crank_driver(period_ns=MS, max_behind_ns=100 * MS)
    publish(driver, driver.step(0, monotonic_ns=0))
    driver.resume()
    wake = driver.step(5 * NS_PER_S + MS // 2, monotonic_ns=5 * NS_PER_S + MS // 2)
    assert list(wake.instants) == [] and wake.wait_ns == MS // 2 and wake.skipped == 0
    assert list(driver.step(5 * NS_PER_S + MS, monotonic_ns=5 * NS_PER_S + MS).instants) == [
        5 * NS_PER_S + MS]


class LinearTimebase:
    """A stand-in actuator time base (m, m/s): what a driver that does not turn provides."""

    CHANGES = ('speed',)
    RATES = ('speed',)

    def __init__(self, t0, position, speed):
        self.t0, self.position, self.speed = t0, Fraction(position), Fraction(speed)

    def at(self, t):
        return self.position + self.speed * Fraction(t - self.t0, NS_PER_S)

    def update(self, t, speed):
        self.t0, self.position, self.speed = t, self.at(t), Fraction(speed)

    def moved(self, t_from, t_to):
        return LinearTimebase(t_to, self.at(t_from), self.speed)

    def sample_turns(self, t):
        return 0, (float(self.at(t)), float(self.speed))


def test_a_driver_that_does_not_turn_has_a_time_base_of_its_own():
    """A linear actuator beside the crank: its own kind, start values and changes (issue 18)."""
    driver = crank_driver(period_ns=MS)
    driver.add_drive('ram', LinearTimebase, position=0.25, speed=0.5)
    publish(driver, driver.step(0, monotonic_ns=0))
    driver.request('ram', speed=-0.5)
    (_, crank), (turns, ram) = driver.state_at(2 * MS)
    assert crank.speed == rad_per_s_from_rpm(60.0)
    assert turns == 0 and ram == (0.251, -0.5)      # out at 0.5 m/s, back from 2 ms on
    (_, _), (_, ram) = driver.state_at(4 * MS)
    assert ram == (0.25, -0.5)
    with pytest.raises(ValueError, match=r"^Expected drive changes among speed, got \['accel'\]$"):
        driver.request('ram', accel=1.0)


def test_the_actuator_time_base_drives_an_actuator_beside_the_crank():
    """The actuator time base in the driver: start values, changes at the next instant."""
    driver = crank_driver(period_ns=MS)
    driver.add_drive('boom_cyl', ActuatorTimebase, length=1.2, speed=0.05, accel=0.0)
    publish(driver, driver.step(0, monotonic_ns=0))
    driver.request('boom_cyl', speed=-0.05, accel=0.5)
    (_, _), (turns, cyl) = driver.state_at(2 * MS)
    assert turns == 0 and cyl == ActuatorSample(1.2 + 0.05 * 0.002, -0.05, 0.5)
    (_, _), (_, cyl) = driver.state_at(4 * MS)
    t = Fraction(2, 1000)
    exact = Fraction(1.2) + Fraction(0.05) * t - Fraction(0.05) * t + Fraction(0.5) * t * t / 2
    assert cyl.length == float(exact)
