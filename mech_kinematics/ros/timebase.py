# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Each driver's position as an exact function of clock time (no ROS needed).

:class:`CrankTimebase` drives a crank (below); :class:`ActuatorTimebase` a
linear actuator, whose length ``L0 + v t + a t**2 / 2`` is kept the same way
(exact rationals in integer nanoseconds, one rounding at the end), without a
wrap or a speed bound.

The drive is a sequence of *segments*. A segment starts at a clock instant
(integer nanoseconds) with an exact crank position, a speed and an angular
acceleration; the speed is clamped to ``+-max_speed`` and then held. Changing
the speed, the acceleration or the bound starts a new segment at that instant
from the exact position there, so the angle never jumps.

Positions are kept in *turns* as exact rationals. Speeds given in rpm are
exact rationals in turns/s already (``rpm / 60``); quantities given in
radians are divided by a rational 2*pi good to 60 digits. A speed is kept in
the unit it was given: while it is held, the published float is the one its
own unit gives (``rpm * pi / 30`` for rpm, as the scene reader computes it;
the value itself for rad/s), so a scene's 10 rad/s is published as 10.0, not
as the nearest float to the exact rational. Inside a segment the
position in turns is ``(n0 + n1*tau + n2*tau**2) / den`` with integers
``n0, n1, n2, den`` and ``tau`` the integer nanoseconds since the segment
start, so the wrap to one turn is an exact integer remainder and the only
rounding is the final conversion of the fraction of a turn to a float angle.
After 30 days at 10,000 rpm the angle is still within a few 1e-16 rad of the
exact value; float seconds would have lost 1e-6 rad.

The size of those integers stays bounded whatever the history. The instant
the speed reaches its bound is a rational with the acceleration's digits in
it; the piece that holds the speed there starts from its position rounded to
a multiple of ``2**-POSITION_BITS`` turn, so those digits go no further.
Without that rounding every acceleration change that reaches the bound would
add about 21 bits to every later denominator, and the node would slow down
without limit (issue 12). Every other denominator divides a fixed number (the
floats' powers of two, 60, 1e9 and the digits of ``TWO_PI``); as a safety
net, a segment start whose denominator exceeds ``2**MAX_DENOMINATOR_BITS`` is
rounded the same way. A rounding moves the crank by at most ``2**-257`` turn
(9e-78 rad): a billion changes stay far below any float's resolution.
"""

from __future__ import annotations

import copy
from fractions import Fraction
import math
from typing import NamedTuple

from ..units import NS_PER_S, rad_per_s_from_rpm

__all__ = ['ActuatorSample', 'ActuatorTimebase', 'CrankSample', 'CrankTimebase',
           'MAX_DENOMINATOR_BITS', 'POSITION_BITS', 'TWO_PI', 'turns_from_radians']

#: Rounded positions are multiples of ``2**-POSITION_BITS`` turn.
POSITION_BITS = 256
_POSITION_DEN = 1 << POSITION_BITS
#: A segment start whose denominator has more bits than this is rounded.
MAX_DENOMINATOR_BITS = 2048

#: 2*pi as an exact rational, to 60 significant digits.
TWO_PI = 2 * Fraction('3.14159265358979323846264338327950288419716939937510582097494')

_TWO_PI_FLOAT = 2.0 * math.pi


def turns_from_radians(value: float) -> Fraction:
    """Return the exact float ``value`` (rad) in turns, as a rational."""
    return Fraction(value) / TWO_PI


def _rounded(turns: Fraction) -> Fraction:
    """Return ``turns`` rounded to the nearest multiple of ``2**-POSITION_BITS``."""
    return Fraction(round(turns * _POSITION_DEN), _POSITION_DEN)


def _radians(turns_per: Fraction) -> float:
    """Return a rate in turns (per s or per s^2) as a correctly rounded float in rad."""
    return float(turns_per * TWO_PI)


class CrankSample(NamedTuple):
    """The crank's state at one instant."""

    angle: float
    """Angle, rad, wrapped to (-pi, pi]."""
    speed: float
    """Angular velocity, rad/s, + CCW."""
    accel: float
    """Angular acceleration, rad/s^2 (0 while the speed is held at the bound)."""


class _Piece:
    """Position in turns over one stretch of a segment, as an integer polynomial in tau (ns)."""

    __slots__ = ('den', 'n0', 'n1', 'n2', 'speed', 'speed_slope', 'accel')

    def __init__(self, c0: Fraction, c1: Fraction, c2: Fraction,
                 w0: Fraction, a: Fraction, w0_float: float | None = None) -> None:
        # turns(tau) = c0 + c1*tau + c2*tau**2 with tau in ns.
        den = math.lcm(c0.denominator, c1.denominator, c2.denominator)
        self.den = den
        self.n0 = c0.numerator * (den // c0.denominator)
        self.n1 = c1.numerator * (den // c1.denominator)
        self.n2 = c2.numerator * (den // c2.denominator)
        # speed(tau) = w0 + a * tau / 1e9 in rad/s, as floats; w0 as given when it was.
        self.speed = _radians(w0) if w0_float is None else w0_float
        self.speed_slope = _radians(a) / NS_PER_S
        self.accel = _radians(a)

    def turns(self, tau: int) -> Fraction:
        return Fraction(self.n0 + tau * (self.n1 + tau * self.n2), self.den)

    def sample(self, tau: int) -> tuple[int, CrankSample]:
        den = self.den
        whole, r = divmod(self.n0 + tau * (self.n1 + tau * self.n2), den)
        if 2 * r > den:         # wrap the fraction of a turn to (-1/2, 1/2]
            r -= den
            whole += 1
        return whole, CrankSample((r / den) * _TWO_PI_FLOAT,
                                  self.speed + self.speed_slope * tau, self.accel)


class _Segment:
    """The drive from instant ``t0`` on: accelerate at ``a``, then hold at the bound."""

    __slots__ = ('t0', 'turns0', 'w0', 'a', 'w_max', 't_hold', 'ramp', 'hold', 'prev', '_ceil',
                 'w_max_float')

    def __init__(self, t0: int, turns0: Fraction, w0: Fraction, a: Fraction,
                 w_max: Fraction, prev: _Segment | None, w0_float: float | None = None,
                 w_max_float: float | None = None) -> None:
        # The floats (rad/s) of w0 and w_max in the units they were given, if known.
        if w_max_float is None:
            w_max_float = _radians(w_max)
        if w0 > w_max or w0 < -w_max:
            w0 = w_max if w0 > 0 else -w_max
            w0_float = w_max_float if w0 > 0 else -w_max_float
        self.w_max_float = w_max_float
        if turns0.denominator.bit_length() > MAX_DENOMINATOR_BITS:
            turns0 = _rounded(turns0)
        self.t0, self.turns0, self.w0, self.a, self.w_max = t0, turns0, w0, a, w_max
        self.prev = prev
        zero = Fraction(0)
        per_ns = Fraction(1, NS_PER_S)
        # Time (ns, exact) at which the speed reaches the bound; None: never.
        target = w_max if a > 0 else -w_max
        t_hold: Fraction | None = None
        if a != 0:
            t_hold = (target - w0) / a * NS_PER_S
        self.t_hold = t_hold
        self.ramp = _Piece(turns0, w0 * per_ns, a * per_ns * per_ns / 2, w0, a, w0_float)
        if t_hold is None:
            self.hold = self.ramp
        else:
            # Position at the bound, then straight on at the bound speed.
            th = t_hold
            at_hold = turns0 + w0 * th * per_ns + a * (th * per_ns) ** 2 / 2
            c1 = target * per_ns
            self.hold = _Piece(_rounded(at_hold - c1 * th), c1, zero, target, zero,
                               w_max_float if a > 0 else -w_max_float)
        # First integer instant (ns) on the hold piece.
        self._ceil: int | None = None if t_hold is None else math.ceil(t_hold)

    def piece(self, tau: int) -> _Piece:
        if self._ceil is None or tau < self._ceil:
            return self.ramp
        return self.hold

    def speed(self, tau: int) -> Fraction:
        """Exact speed, turns/s."""
        if self._ceil is None or tau < self._ceil:
            return self.w0 + self.a * Fraction(tau, NS_PER_S)
        return self.w_max if self.a > 0 else -self.w_max

    def speed_float(self, tau: int) -> float | None:
        """Return the float speed (rad/s) held at ``tau``, or None while it changes."""
        piece = self.piece(tau)
        return piece.speed if piece.speed_slope == 0.0 and piece.accel == 0.0 else None


def _speed_given(speed_rpm: float | None, speed: float | None) -> tuple[Fraction, float]:
    """Return a speed given in rpm or in rad/s as (exact turns/s, float rad/s)."""
    if speed is not None:
        return turns_from_radians(speed), float(speed)
    assert speed_rpm is not None
    return Fraction(speed_rpm) / 60, float(rad_per_s_from_rpm(speed_rpm))


class CrankTimebase:
    """Crank angle, speed and acceleration as exact functions of clock time.

    Parameters
    ----------
    t0 : int
        Clock instant of the start, ns. The crank is at ``angle`` there.
    angle : float
        Crank angle at ``t0``, rad.
    speed_rpm : float or None
        Crank speed at ``t0``, rpm, + CCW (None: ``speed`` gives it).
    accel : float
        Crank angular acceleration, rad/s^2.
    max_speed_rpm : float
        Bound on the magnitude of the speed, rpm (>= 0). An accelerating drive
        holds its speed once it reaches ``+-max_speed_rpm``; a ``speed_rpm``
        beyond it is clamped.
    speed : float, optional
        Crank speed at ``t0`` in rad/s instead of ``speed_rpm`` (a scene's own
        speed, kept in the unit the scene holds it in).
    turns : int, optional
        Whole turns to add to ``angle`` (a scene's start far out: its crank's
        ``turns``), added exactly. Default 0.

    Notes
    -----
    :meth:`sample` is safe to call from one thread while another calls the
    setters: a setter builds a new segment and swaps it in with one
    assignment. Instants before the current segment's start use the segment
    before it (one level is kept), so a sample taken just before a change is
    still the old drive.
    """

    #: The keyword arguments :meth:`update` takes.
    CHANGES = ('speed_rpm', 'speed', 'accel', 'max_speed_rpm')
    #: The keywords that each give the speed, in their own unit (rpm, rad/s): one at a time,
    #: and one given replaces the other (the keys of a crank's :class:`~mech_kinematics.
    #: solver.base.Rate`).
    RATES = ('speed_rpm', 'speed')
    #: The keyword of the position at ``t0`` (rad).
    POSITION = 'angle'

    def __init__(self, t0: int, angle: float, speed_rpm: float | None, accel: float,
                 max_speed_rpm: float, *, speed: float | None = None, turns: int = 0) -> None:
        if (speed_rpm is None) == (speed is None):
            msg = f'Expected one of `speed_rpm` and `speed`, got {speed_rpm!r} and {speed!r}'
            raise ValueError(msg)
        for value, what in ((angle, 'angle'), (speed_rpm, 'speed_rpm'), (speed, 'speed'),
                            (accel, 'accel'), (max_speed_rpm, 'max_speed_rpm')):
            if value is not None and not math.isfinite(value):
                msg = f'Expected `{what}` to be finite, got {value!r}'
                raise ValueError(msg)
        if max_speed_rpm < 0:
            msg = f'Expected `max_speed_rpm` >= 0, got {max_speed_rpm!r}'
            raise ValueError(msg)
        w0, w0_float = _speed_given(speed_rpm, speed)
        w_max, w_max_float = _speed_given(max_speed_rpm, None)
        self._segment = _Segment(int(t0), turns_from_radians(angle) + int(turns), w0,
                                 turns_from_radians(accel), w_max, None, w0_float, w_max_float)

    def _at(self, t: int) -> tuple[_Segment, int]:
        seg = self._segment
        if t < seg.t0 and seg.prev is not None:
            seg = seg.prev
        return seg, t - seg.t0

    def sample(self, t: int) -> CrankSample:
        """Return the crank's angle (wrapped to (-pi, pi]), speed and acceleration at ``t`` ns."""
        return self.sample_turns(t)[1]

    def sample_turns(self, t: int) -> tuple[int, CrankSample]:
        """Return (whole turns, the crank's state) at ``t`` ns.

        The crank's angle counted from the start (not wrapped) is
        ``angle + 2 pi * turns``, with ``angle`` in (-pi, pi] and ``turns`` an
        exact integer: the pair keeps every digit of an angle that a single
        float would lose after many turns.
        """
        seg = self._segment
        if t < seg.t0 and seg.prev is not None:
            seg = seg.prev
        tau = t - seg.t0
        ceil = seg._ceil
        if ceil is None or tau < ceil:
            return seg.ramp.sample(tau)
        return seg.hold.sample(tau)

    def total_turns(self, t: int) -> Fraction:
        """Return the exact crank position at ``t`` ns in turns, counted from the start.

        That is ``angle / (2 pi)`` of the initial angle plus every turn since.
        """
        seg, tau = self._at(t)
        return seg.piece(tau).turns(tau)

    def turns(self, t: int) -> Fraction:
        """Return the exact crank position at ``t`` ns, in turns, modulo 1."""
        seg, tau = self._at(t)
        return seg.piece(tau).turns(tau) % 1

    def speed(self, t: int) -> Fraction:
        """Return the exact crank speed at ``t`` ns, in turns/s."""
        seg, tau = self._at(t)
        return seg.speed(tau)

    @property
    def accel(self) -> float:
        """The commanded angular acceleration, rad/s^2."""
        return _radians(self._segment.a)

    @property
    def max_speed_rpm(self) -> float:
        """The speed bound, rpm."""
        return float(self._segment.w_max * 60)

    def _restart(self, t: int, w0: tuple[Fraction, float] | None, a: Fraction | None,
                 w_max: tuple[Fraction, float] | None) -> None:
        t = int(t)
        old = self._segment
        seg, tau = self._at(t)
        turns0 = seg.piece(tau).turns(tau)
        if w0 is None:      # go on at the speed there, as the float it was published as
            w0 = seg.speed(tau), seg.speed_float(tau)
        # Keep one level of history, without touching the segment that a
        # concurrent sample() may be reading.
        before = copy.copy(old)
        before.prev = None
        if w_max is None:
            w_max = old.w_max, old.w_max_float
        self._segment = _Segment(t, turns0, w0[0], old.a if a is None else a, w_max[0], before,
                                 w0[1], w_max[1])

    def update(self, t: int, speed_rpm: float | None = None, accel: float | None = None,
               max_speed_rpm: float | None = None, *, speed: float | None = None) -> None:
        """From instant ``t`` (ns) on, drive with the given values; ``None`` keeps one.

        The position at ``t`` is kept exactly. ``speed_rpm`` is the speed at
        ``t`` (without it the drive goes on from its speed there); ``accel``
        (rad/s^2) applies from ``t``; ``max_speed_rpm`` bounds the speed from
        ``t`` on, clamping it at once if it is faster. ``speed`` gives the speed
        in rad/s instead of ``speed_rpm``.
        """
        if speed_rpm is not None and speed is not None:
            msg = f'Expected one of `speed_rpm` and `speed`, got {speed_rpm!r} and {speed!r}'
            raise ValueError(msg)
        for value, what in ((speed_rpm, 'speed_rpm'), (speed, 'speed'), (accel, 'accel'),
                            (max_speed_rpm, 'max_speed_rpm')):
            if value is not None and not math.isfinite(value):
                msg = f'Expected `{what}` to be finite, got {value!r}'
                raise ValueError(msg)
        if max_speed_rpm is not None and max_speed_rpm < 0:
            msg = f'Expected `max_speed_rpm` >= 0, got {max_speed_rpm!r}'
            raise ValueError(msg)
        given = None if speed_rpm is None and speed is None else _speed_given(speed_rpm, speed)
        self._restart(t, given, None if accel is None else turns_from_radians(accel),
                      None if max_speed_rpm is None else _speed_given(max_speed_rpm, None))

    def moved(self, t_from: int, t_to: int) -> CrankTimebase:
        """Return a copy whose drive at ``t_to`` continues this one's at ``t_from``.

        For a change of time source (ROS time switched on or off), whose epoch
        has nothing to do with the old one: the crank goes on from where it was.
        """
        seg, tau = self._at(int(t_from))
        copy = object.__new__(CrankTimebase)
        copy._segment = _Segment(int(t_to), seg.piece(tau).turns(tau), seg.speed(tau),
                                 self._segment.a, self._segment.w_max, None,
                                 seg.speed_float(tau), self._segment.w_max_float)
        return copy


class ActuatorSample(NamedTuple):
    """A linear actuator's state at one instant."""

    length: float
    """Length, m."""
    speed: float
    """Extension rate, m/s (+ extending)."""
    accel: float
    """Extension acceleration, m/s^2."""


class _Stretch:
    """An actuator's drive from instant ``t0`` (ns): length in m as an integer polynomial.

    ``length(tau) = (n0 + n1*tau + n2*tau**2) / den`` with ``tau`` the integer
    nanoseconds since ``t0``: exact, one correctly rounded division per sample.
    """

    __slots__ = ('t0', 'v', 'a', 'den', 'n0', 'n1', 'n2', 'speed', 'speed_slope', 'accel',
                 'prev')

    def __init__(self, t0: int, length: Fraction, v: Fraction, a: Fraction,
                 v_float: float | None, prev: _Stretch | None) -> None:
        per_ns = Fraction(1, NS_PER_S)
        c0, c1, c2 = length, v * per_ns, a * per_ns * per_ns / 2
        if c0.denominator.bit_length() > MAX_DENOMINATOR_BITS:
            c0 = _rounded(c0)
        den = math.lcm(c0.denominator, c1.denominator, c2.denominator)
        self.t0, self.v, self.a, self.den, self.prev = t0, v, a, den, prev
        self.n0 = c0.numerator * (den // c0.denominator)
        self.n1 = c1.numerator * (den // c1.denominator)
        self.n2 = c2.numerator * (den // c2.denominator)
        # speed(tau) = v + a * tau / 1e9 in m/s, as floats; v as it was given when it was.
        self.speed = float(v) if v_float is None else v_float
        self.accel = float(a)
        self.speed_slope = self.accel / NS_PER_S

    def length(self, tau: int) -> Fraction:
        return Fraction(self.n0 + tau * (self.n1 + tau * self.n2), self.den)

    def exact_speed(self, tau: int) -> Fraction:
        return self.v + self.a * Fraction(tau, NS_PER_S)


class ActuatorTimebase:
    """A linear actuator's length, extension rate and acceleration as exact functions of time.

    Parameters
    ----------
    t0 : int
        Clock instant of the start, ns. The actuator has ``length`` there.
    length : float
        Length at ``t0``, m.
    speed : float
        Extension rate at ``t0``, m/s (+ extending).
    accel : float
        Extension acceleration, m/s^2.

    Notes
    -----
    The length is ``length + speed * t + accel * t**2 / 2`` computed from the
    floats' exact values in integer nanoseconds, so it does not drift however
    long the node runs; an actuator has no wrap and no speed bound (its
    stroke is the solver's to refuse). Thread safety is argued as for
    :class:`CrankTimebase`: :meth:`update` builds a new stretch and swaps it
    in with one assignment, keeping the one before for earlier instants.
    """

    #: The keyword arguments :meth:`update` takes.
    CHANGES = ('speed', 'accel')
    #: The keyword that gives the extension rate (m/s).
    RATES = ('speed',)
    #: The keyword of the position at ``t0`` (m: an actuator's length, a slider's position).
    POSITION = 'length'

    def __init__(self, t0: int, length: float, speed: float, accel: float) -> None:
        _check_finite(length=length, speed=speed, accel=accel)
        self._stretch = _Stretch(int(t0), Fraction(length), Fraction(speed), Fraction(accel),
                                 float(speed), None)

    def _at(self, t: int) -> tuple[_Stretch, int]:
        stretch = self._stretch
        if t < stretch.t0 and stretch.prev is not None:
            stretch = stretch.prev
        return stretch, t - stretch.t0

    def sample(self, t: int) -> ActuatorSample:
        """Return the length (m), extension rate (m/s) and acceleration (m/s^2) at ``t`` ns."""
        stretch, tau = self._at(t)
        return ActuatorSample(
            (stretch.n0 + tau * (stretch.n1 + tau * stretch.n2)) / stretch.den,
            stretch.speed + stretch.speed_slope * tau, stretch.accel)

    def sample_turns(self, t: int) -> tuple[int, ActuatorSample]:
        """Return (0, the actuator's state) at ``t`` ns: an actuator makes no turns."""
        return 0, self.sample(t)

    def length(self, t: int) -> Fraction:
        """Return the exact length at ``t`` ns, m."""
        stretch, tau = self._at(t)
        return stretch.length(tau)

    def speed(self, t: int) -> Fraction:
        """Return the exact extension rate at ``t`` ns, m/s."""
        stretch, tau = self._at(t)
        return stretch.exact_speed(tau)

    def leaves(self, t: int, stroke: tuple[float, float]) -> float | None:
        """Return the time from ``t`` (ns) until the length leaves ``stroke`` (s), or None.

        0.0 when it is outside, or at a limit and moving out, at ``t``; None
        when the drive stays within the inclusive limits for ever (at rest).
        """
        stretch, tau = self._at(t)
        low, high = (Fraction(x) for x in stroke)
        x, v, a = stretch.length(tau), stretch.exact_speed(tau), stretch.a
        if not low <= x <= high or (x == high and (v > 0 or v == 0 and a > 0)) \
                or (x == low and (v < 0 or v == 0 and a < 0)):
            return 0.0
        times = [root for limit in (low, high) for root in _roots(a / 2, v, x - limit)
                 if root > 0]
        return float(min(times)) if times else None

    def moves_out(self, t: int, stroke: tuple[float, float]) -> bool:
        """Return whether the drive takes the length out of ``stroke`` at ``t`` (ns) at once.

        True at or beyond a limit unless the drive moves it back inside (or
        holds it still exactly at the limit); False within the stroke, even if
        it reaches a limit later (:meth:`leaves` says when).
        """
        stretch, tau = self._at(t)
        low, high = (Fraction(x) for x in stroke)
        x, v, a = stretch.length(tau), stretch.exact_speed(tau), stretch.a
        if low < x < high:
            return False
        # The sign of the motion at t: the speed's, or the acceleration's from rest.
        motion = v if v != 0 else a
        if x >= high:
            return motion > 0 or (x > high and motion == 0)
        return motion < 0 or (x < low and motion == 0)

    def update(self, t: int, speed: float | None = None, accel: float | None = None) -> None:
        """From instant ``t`` (ns) on, drive with the given values; ``None`` keeps one.

        The length at ``t`` is kept exactly; without ``speed`` the drive goes on
        from its extension rate there.
        """
        _check_finite(speed=speed, accel=accel)
        t = int(t)
        old = self._stretch
        stretch, tau = self._at(t)
        before = copy.copy(old)
        before.prev = None
        if speed is None:
            v, v_float = stretch.exact_speed(tau), None
            if stretch.a == 0:
                v_float = stretch.speed     # held: the float it was given as
        else:
            v, v_float = Fraction(speed), float(speed)
        self._stretch = _Stretch(t, stretch.length(tau), v,
                                 old.a if accel is None else Fraction(accel), v_float, before)

    def moved(self, t_from: int, t_to: int) -> ActuatorTimebase:
        """Return a copy whose drive at ``t_to`` continues this one's at ``t_from``."""
        stretch, tau = self._at(int(t_from))
        copy_ = object.__new__(ActuatorTimebase)
        copy_._stretch = _Stretch(int(t_to), stretch.length(tau), stretch.exact_speed(tau),
                                  stretch.a, stretch.speed if stretch.a == 0 else None, None)
        return copy_


def _check_finite(**values: float | None) -> None:
    for what, value in values.items():
        if value is not None and not math.isfinite(value):
            msg = f'Expected `{what}` to be finite, got {value!r}'
            raise ValueError(msg)


def _roots(a: Fraction, b: Fraction, c: Fraction) -> list[float]:
    """Return the real roots of ``a x**2 + b x + c`` (s), as floats."""
    if a == 0:
        return [] if b == 0 else [float(-c / b)]
    disc = b * b - 4 * a * c
    if disc < 0:
        return []
    root = math.sqrt(float(disc))
    return [(-float(b) - root) / float(2 * a), (-float(b) + root) / float(2 * a)]
