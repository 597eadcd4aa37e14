# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Tests of mech_kinematics.ros.timebase: the crank angle as an exact function of clock time."""

from decimal import Decimal, localcontext
from fractions import Fraction
import math
import random

from hypothesis import example, given, strategies as st
import pytest

from mech_kinematics.ros.timebase import (ActuatorSample, ActuatorTimebase, CrankTimebase,
                                          MAX_DENOMINATOR_BITS, POSITION_BITS, TWO_PI)

NS = 1_000_000_000
DAY_NS = 86_400 * NS
#: Largest error allowed on an angle, rad: a few ulp of pi.
ATOL_ANGLE = 4 * math.ulp(math.pi)  # rad
#: What the issue asks for after 30 days at 10,000 rpm, rad.
ATOL_LONG_RUN = 1e-9  # rad

# pi to 70 digits, typed in independently of the module's constant.
PI_70 = Decimal('3.141592653589793238462643383279502884197169399375105820974944592307816')


def exact_angle(angle0: float, speed_rpm: float, t_ns: int) -> float:
    """Return angle0 + speed * t wrapped to (-pi, pi], computed with 70-digit decimals."""
    with localcontext() as ctx:
        ctx.prec = 80
        two_pi = 2 * PI_70
        theta = Decimal(angle0) + two_pi * Decimal(speed_rpm) / 60 * Decimal(t_ns) / NS
        theta = theta % two_pi          # in (-2 pi, 2 pi), sign of theta
        if theta > PI_70:
            theta -= two_pi
        elif theta <= -PI_70:
            theta += two_pi
        return float(theta)


def angle_difference(a: float, b: float) -> float:
    """Return a - b wrapped to [-pi, pi]."""
    return math.remainder(a - b, 2 * math.pi)


def rpms():
    """Crank speeds, rpm: any finite value a user may set, and a few round ones."""
    return st.one_of(st.sampled_from([0.0, 1.0, -120.0, 10_000.0, -99_999.5]),
                     st.floats(-100_000, 100_000, allow_nan=False))


def instants():
    """Clock instants, ns: from the start up to a year."""
    return st.integers(0, 365 * DAY_NS)


def test_starts_at_the_initial_angle():
    """At its start instant the crank is at the given angle, wrapped to (-pi, pi]."""
    for angle in (0.0, 1.0, -1.0, math.pi, 3 * math.pi / 2, 100.0):
        tb = CrankTimebase(123_456, angle, 60.0, 0.0, 1000.0)
        expected = exact_angle(angle, 0.0, 0)
        assert abs(angle_difference(tb.sample(123_456).angle, expected)) <= ATOL_ANGLE
        assert -math.pi < tb.sample(123_456).angle <= math.pi


def test_thirty_days_at_ten_thousand_rpm():
    """After 30 days at 10,000 rpm the angle is within 1e-9 rad of exact (float seconds miss by ~1e-6)."""  # noqa: E501
    t_start = 1_780_000_000 * NS + 123_456_789      # a wall-clock epoch, ns
    tb = CrankTimebase(t_start, 1.0, 10_000.0, 0.0, 10_000.0)
    for extra in (0, 1, 999_999_999, 12_345_678_901):
        t = t_start + 30 * DAY_NS + extra
        got = tb.sample(t)
        expected = exact_angle(1.0, 10_000.0, t - t_start)
        assert abs(angle_difference(got.angle, expected)) < ATOL_LONG_RUN
        assert abs(angle_difference(got.angle, expected)) <= ATOL_ANGLE
        assert got.speed == 10_000.0 * math.pi / 30
    naive = 1.0 + 10_000.0 * math.pi / 30 * ((30 * DAY_NS) / NS)
    assert abs(angle_difference(naive, exact_angle(1.0, 10_000.0, 30 * DAY_NS))) > 1e-8


@given(angle0=st.floats(-10, 10), rpm=rpms(), t=instants())
@example(angle0=0.0, rpm=-99_999.5, t=365 * DAY_NS)
def test_constant_speed_is_exact(angle0, rpm, t):
    """At constant speed the angle is angle0 + omega * t, exact to a few ulp, at any instant."""
    tb = CrankTimebase(0, angle0, rpm, 0.0, 100_000.0)
    got = tb.sample(t)
    assert abs(angle_difference(got.angle, exact_angle(angle0, rpm, t))) <= ATOL_ANGLE
    assert -math.pi < got.angle <= math.pi
    assert got.accel == 0.0


@given(rpm=rpms(), t1=instants(), t2=instants())
def test_turns_advance_exactly(rpm, t1, t2):
    """The position in turns advances by exactly rpm / 60 * dt, modulo one turn."""
    tb = CrankTimebase(0, 0.25, rpm, 0.0, 100_000.0)
    advance = Fraction(rpm) / 60 * Fraction(t2 - t1, NS)
    assert (tb.turns(t2) - tb.turns(t1) - advance) % 1 == 0


@given(rpm1=rpms(), rpm2=rpms(), tc=instants(), dt=st.integers(1, 10 * NS))
def test_speed_change_keeps_the_angle_continuous(rpm1, rpm2, tc, dt):
    """Changing the speed at tc keeps the position there and turns at the new speed after."""
    tb = CrankTimebase(0, 0.5, rpm1, 0.0, 100_000.0)
    before = tb.turns(tc)
    tb.update(tc, speed_rpm=rpm2)
    assert tb.turns(tc) == before
    assert tb.turns(tc - 1) == (before - Fraction(rpm1) / 60 / NS) % 1   # old drive
    assert tb.turns(tc + dt) == (before + Fraction(rpm2) / 60 * Fraction(dt, NS)) % 1
    assert tb.speed(tc + dt) == Fraction(rpm2) / 60


def test_acceleration_then_hold_at_the_bound():
    """Accelerating from rest: angle = alpha t^2 / 2 until the bound, then constant speed."""
    alpha = 10.0                       # rad/s^2
    tb = CrankTimebase(0, 0.0, 0.0, alpha, 600.0)       # bound 600 rpm = 20 pi rad/s
    w_max = 600.0 * math.pi / 30
    t_hold = w_max / alpha                               # s, about 6.28
    for t in (0.1, 1.0, 3.0, 6.0):
        got = tb.sample(round(t * NS))
        expected = math.remainder(alpha * t * t / 2, 2 * math.pi)
        assert abs(angle_difference(got.angle, expected)) < 1e-12
        assert got.speed == pytest.approx(alpha * t, rel=1e-12)
        assert got.accel == alpha
    for t in (7.0, 100.0, 1e6):
        got = tb.sample(round(t * NS))
        expected = alpha * t_hold ** 2 / 2 + w_max * (t - t_hold)
        assert abs(angle_difference(got.angle, math.remainder(expected, 2 * math.pi))) < 1e-6
        assert got.speed == pytest.approx(w_max, rel=1e-15)
        assert got.accel == 0.0
    # The position is continuous through the hold instant.
    t_ns = math.ceil(t_hold * NS)
    step = tb.turns(t_ns) - tb.turns(t_ns - 1)
    assert 0 < step < Fraction(11, 10) * 10 / NS


def test_negative_acceleration_runs_to_the_negative_bound():
    """A negative acceleration slows the crank, reverses it and holds it at -max."""
    tb = CrankTimebase(0, 0.0, 300.0, -50.0, 1000.0)
    assert tb.sample(0).speed == pytest.approx(10 * math.pi)
    assert tb.sample(NS).speed == pytest.approx(10 * math.pi - 50.0)
    assert tb.sample(100 * NS).speed == pytest.approx(-1000.0 * math.pi / 30, rel=1e-15)
    assert tb.sample(100 * NS).accel == 0.0


def test_accel_change_starts_from_the_current_speed():
    """Setting the acceleration keeps the speed there: only its rate of change changes."""
    tb = CrankTimebase(0, 0.0, 60.0, 0.0, 1000.0)
    before = tb.turns(5 * NS)
    tb.update(5 * NS, accel=2 * math.pi)         # one turn/s^2
    assert tb.turns(5 * NS) == before
    assert tb.speed(6 * NS) == pytest.approx(2, rel=1e-15)      # turns/s
    assert tb.sample(6 * NS).accel == pytest.approx(2 * math.pi)


def test_lowering_the_bound_clamps_the_speed():
    """A bound below the current speed clamps it at once; the angle does not jump."""
    tb = CrankTimebase(0, 0.0, 600.0, 0.0, 1000.0)
    before = tb.turns(NS)
    tb.update(NS, max_speed_rpm=120.0)
    assert tb.turns(NS) == before
    assert tb.speed(2 * NS) == 2
    assert tb.max_speed_rpm == 120.0
    tb.update(3 * NS, speed_rpm=-500.0)
    assert tb.speed(4 * NS) == -2


def test_moved_continues_on_a_new_clock():
    """moved() gives a drive that at the new instant is where the old one was."""
    tb = CrankTimebase(10 * NS, 0.3, 90.0, 1.0, 1000.0)
    copy = tb.moved(20 * NS, 5)
    assert copy.turns(5) == tb.turns(20 * NS)
    assert copy.speed(5) == tb.speed(20 * NS)


@pytest.mark.parametrize('kwargs, match', [
    ({'angle': math.nan}, 'angle'),
    ({'speed_rpm': math.inf}, 'speed_rpm'),
    ({'accel': -math.inf}, 'accel'),
    ({'max_speed_rpm': -1.0}, 'max_speed_rpm'),
])
def test_bad_values_are_refused(kwargs, match):
    """Non-finite values and a negative bound raise ValueError naming the argument."""
    args = {'t0': 0, 'angle': 0.0, 'speed_rpm': 1.0, 'accel': 0.0, 'max_speed_rpm': 10.0}
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        CrankTimebase(**args)
    tb = CrankTimebase(0, 0.0, 1.0, 0.0, 10.0)
    if 'angle' not in kwargs:
        with pytest.raises(ValueError, match=match):
            tb.update(1, **kwargs)


@pytest.mark.parametrize('speed_rpm, speed', [(None, None), (60.0, 6.0)])
def test_a_speed_is_given_in_one_unit(speed_rpm, speed):
    """Exactly one of speed_rpm and speed (rad/s) gives the start speed; update takes one too."""
    with pytest.raises(ValueError, match=r'^Expected one of `speed_rpm` and `speed`, got '):
        CrankTimebase(0, 0.0, speed_rpm, 0.0, 100.0, speed=speed)
    if speed_rpm is not None:
        tb = CrankTimebase(0, 0.0, 1.0, 0.0, 100.0)
        with pytest.raises(ValueError, match=r'^Expected one of `speed_rpm` and `speed`, got '):
            tb.update(1, speed_rpm=speed_rpm, speed=speed)


def test_a_speed_in_rad_per_s_is_published_as_given_and_integrated_exactly():
    """speed=10.0 rad/s: published as 10.0, and the position is 10 t / (2 pi) turns exactly."""
    tb = CrankTimebase(0, 0.0, None, 0.0, 1000.0, speed=10.0)
    assert tb.sample(7 * NS).speed == 10.0
    assert tb.total_turns(7 * NS) == Fraction(70) / TWO_PI
    tb.update(8 * NS, accel=1.0)            # the speed goes on as the same float
    assert tb.sample(8 * NS).speed == 10.0


def test_two_pi_constant():
    """The rational 2*pi agrees with the float one to the last bit."""
    assert float(TWO_PI) == 2 * math.pi
    assert abs(TWO_PI - 2 * Fraction(str(PI_70))) < Fraction(1, 10 ** 58)


def test_size_stays_bounded_under_many_changes():
    """10,000 acceleration changes that reach the bound leave the integers bounded. See issue 12.

    Each change used to add about 21 bits to every denominator (the instant the
    bound is reached carries the acceleration's digits), so updates and samples
    slowed down without limit.
    """
    rng = random.Random(12)
    tb = CrankTimebase(0, 0.3, 100.0, 0.0, 3000.0)
    t = 0
    sizes = []
    for i in range(10_000):
        t += rng.randrange(1, 2 * NS)
        tb.update(t, accel=rng.choice((-1.0, 1.0)) * rng.uniform(100.0, 5000.0))
        if i % 1000 == 999:
            sample_t = t + rng.randrange(1, 5 * NS)
            sizes.append(max(tb._segment.ramp.den.bit_length(),
                             tb._segment.hold.den.bit_length(),
                             tb.turns(sample_t).denominator.bit_length()))
    assert max(sizes) <= MAX_DENOMINATOR_BITS
    assert max(sizes[5:]) <= max(sizes[:5]) + 16     # no growth with the history


def test_rounding_at_the_bound_keeps_the_drive_within_its_resolution():
    """A hold piece rounded to 2**-POSITION_BITS turn stays on the exact drive. See issue 12."""
    tb = CrankTimebase(0, 0.1, 0.0, 7.0, 1234.5)            # reaches the bound at a ragged instant
    w_max = Fraction(1234.5) / 60
    a = Fraction(7.0) / TWO_PI
    t_hold = w_max / a                                       # s, exact
    x_hold = Fraction(0.1) / TWO_PI + a * t_hold ** 2 / 2    # turns, exact
    for t in (int(t_hold * NS) + 1, 3600 * NS, 30 * DAY_NS):
        exact = (x_hold + w_max * (Fraction(t, NS) - t_hold)) % 1
        assert abs(tb.turns(t) - exact) <= Fraction(1, 2 ** POSITION_BITS)


@given(angle0=st.floats(-20.0, 20.0), rpm=rpms(), t=instants())
def test_whole_turns_and_angle_make_the_angle_counted_from_the_start(angle0, rpm, t):
    """The angle plus 2 pi times the whole turns is the exact position from the start."""
    tb = CrankTimebase(0, angle0, rpm, 0.0, 100_000.0)
    turns, sample = tb.sample_turns(t)
    exact = Fraction(angle0) / TWO_PI + Fraction(rpm) / 60 * Fraction(t, NS)
    assert exact == tb.total_turns(t)
    assert abs(exact - turns) <= Fraction(1, 2)
    assert abs(sample.angle - float((exact - turns) * TWO_PI)) <= ATOL_ANGLE
    assert sample == tb.sample(t)


def test_turns_count_every_turn_across_changes():
    """Whole turns keep counting through speed changes and reversals (issue 11)."""
    tb = CrankTimebase(0, 0.0, 60.0, 0.0, 1000.0)      # one turn a second
    assert tb.sample_turns(10 * NS)[0] == 10
    tb.update(10 * NS, speed_rpm=-120.0)                # two turns a second, backwards
    assert tb.sample_turns(15 * NS)[0] == 0
    assert tb.sample_turns(20 * NS)[0] == -10


# -- the actuator's time base (issue 18) ---------------------------------------------------

#: An actuator length within a few ulp of 2 m, m.
ATOL_LENGTH = 4 * math.ulp(2.0)  # m


def exact_length(length0: float, speed: float, accel: float, t_ns: int) -> float:
    """Return L0 + v t + a t**2 / 2 from the floats' exact values, rounded once."""
    t = Fraction(t_ns, NS)
    return float(Fraction(length0) + Fraction(speed) * t + Fraction(accel) * t * t / 2)


@given(st.floats(0.1, 5.0), st.floats(-1.0, 1.0), st.floats(-2.0, 2.0),
       st.integers(0, 30 * DAY_NS))
@example(1.2, 0.05, 0.0, 30 * DAY_NS)
@example(0.5, 1.0, 0.0, 30 * DAY_NS)
def test_actuator_length_is_exact(length0, speed, accel, t):
    """The length is L0 + v t + a t^2 / 2 correctly rounded, after any time (30 days too)."""
    base = ActuatorTimebase(7, length0, speed, accel)
    sample = base.sample(7 + t)
    assert sample.length == exact_length(length0, speed, accel, t)
    assert base.length(7 + t) == Fraction(length0) + Fraction(speed) * Fraction(t, NS) \
        + Fraction(accel) * Fraction(t, NS) ** 2 / 2
    assert sample.accel == accel
    assert sample.speed == pytest.approx(speed + accel * t / NS, rel=1e-15, abs=1e-15)


def test_actuator_starts_where_it_is_and_publishes_its_speed_as_given():
    """At t0 the sample is the start values, the float speed exactly as given; no turns."""
    base = ActuatorTimebase(5 * NS, 1.2, 0.05, 0.0)
    assert base.sample_turns(5 * NS) == (0, ActuatorSample(1.2, 0.05, 0.0))
    assert base.sample(5 * NS + 10 * NS) == ActuatorSample(exact_length(1.2, 0.05, 0, 10 * NS),
                                                           0.05, 0.0)
    assert ActuatorTimebase.CHANGES == ('speed', 'accel')


@given(st.floats(-0.5, 0.5), st.floats(-0.5, 0.5), st.floats(-1, 1), st.floats(-1, 1),
       st.integers(1, 10 * NS), st.integers(1, 10 * NS))
def test_actuator_changes_keep_the_length_continuous(v1, v2, a1, a2, tc, dt):
    """A change at tc keeps the exact length there; after it, the new drive from that length."""
    base = ActuatorTimebase(0, 1.5, v1, a1)
    at_change = base.length(tc)
    base.update(tc, speed=v2)
    assert base.length(tc) == at_change
    assert base.speed(tc) == Fraction(v2)
    t = Fraction(dt, NS)
    assert base.length(tc + dt) == at_change + Fraction(v2) * t + Fraction(a1) * t * t / 2
    base.update(tc + dt, accel=a2)      # the speed goes on from where it was
    assert base.speed(tc + dt) == Fraction(v2) + Fraction(a1) * t
    assert base.sample(tc + dt).accel == a2
    # An instant before the last change is still the drive before it.
    assert base.length(tc) == at_change


def test_actuator_moved_continues_on_a_new_clock():
    """A change of time source: the actuator goes on from its length and speed there."""
    base = ActuatorTimebase(0, 1.0, 0.1, 0.02)
    moved = base.moved(3 * NS, 1000 * NS)
    assert moved.length(1000 * NS) == base.length(3 * NS)
    assert moved.speed(1000 * NS) == base.speed(3 * NS)
    assert moved.sample(1001 * NS).accel == 0.02


@pytest.mark.parametrize('length0, speed, accel, at_s, expected', [
    (1.2, 0.05, 0.0, 0.0, 12.0),        # extends to 1.8 m in 12 s
    (1.2, -0.1, 0.0, 0.0, 2.0),         # retracts to 1.0 m in 2 s
    (1.2, 0.0, 0.0, 0.0, None),         # at rest: never
    (1.8, 0.05, 0.0, 0.0, 0.0),         # at the end and moving out: at once
    (1.8, 0.0, 0.1, 0.0, 0.0),          # at the end, accelerating out: at once
    (1.0, 0.0, 0.1, 0.0, math.sqrt(16)),  # 0.8 m at 0.1 m/s^2: 4 s
    (1.2, 0.05, 0.0, 13.0, 0.0),        # already outside
    (1.5, 0.1, -0.1, 0.0, 1 + math.sqrt(11)),   # up to 1.55 m, back down to 1.0 m
])
def test_actuator_says_when_it_leaves_its_stroke(length0, speed, accel, at_s, expected):
    """The time until the drive leaves [1.0, 1.8] m: the exact root, 0 at once, None never."""
    base = ActuatorTimebase(0, length0, speed, accel)
    got = base.leaves(round(at_s * NS), (1.0, 1.8))
    if expected is None:
        assert got is None
    else:
        assert got == pytest.approx(expected, rel=1e-12, abs=1e-12)


@pytest.mark.parametrize('kwargs, match', [
    ({'length': math.nan, 'speed': 0.0, 'accel': 0.0}, '`length` to be finite'),
    ({'length': 1.0, 'speed': math.inf, 'accel': 0.0}, '`speed` to be finite'),
    ({'length': 1.0, 'speed': 0.0, 'accel': -math.inf}, '`accel` to be finite'),
])
def test_actuator_bad_values_are_refused(kwargs, match):
    """A NaN or inf start value is refused, naming the value."""
    with pytest.raises(ValueError, match=match):
        ActuatorTimebase(0, **kwargs)
    with pytest.raises(ValueError, match='`speed` to be finite'):
        ActuatorTimebase(0, 1.0, 0.0, 0.0).update(5, speed=math.nan)


@pytest.mark.parametrize('length0, speed, accel, at_s, out', [
    (1.2, 0.05, 0.0, 0.0, False),       # inside: it leaves later, not at once
    (1.8, 0.05, 0.0, 0.0, True),        # at the end, moving out
    (1.8, 0.0, 0.1, 0.0, True),         # at the end, accelerating out from rest
    (1.8, 0.0, 0.0, 0.0, False),        # held still exactly at the end
    (1.8, -0.05, 0.0, 0.0, False),      # at the end, moving back in
    (1.0, -0.01, 0.0, 0.0, True),       # at the other end, moving out
    (1.2, 0.05, 0.0, 13.0, True),       # beyond the end, still moving out
    (1.9, 0.0, 0.0, 0.0, True),         # beyond the end, at rest
    (1.9, -0.05, 0.0, 0.0, False),      # beyond the end, coming back
])
def test_actuator_says_whether_a_drive_moves_out_at_once(length0, speed, accel, at_s, out):
    """At or beyond a limit and not moving back inside: out at once; inside: not yet."""
    base = ActuatorTimebase(0, length0, speed, accel)
    assert base.moves_out(round(at_s * NS), (1.0, 1.8)) is out
