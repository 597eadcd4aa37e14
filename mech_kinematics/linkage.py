# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Analytic position, velocity and acceleration of planar linkages.

A mechanism is a driving crank followed by dyads (RRR, RRP, RPR) and points
carried rigidly by links, solved one after another in closed form: no
iteration anywhere. Points are complex numbers ``x + iy`` internally, so a
rigid rotation is a product and every formula is the same for one crank angle
(Python ``complex`` and :mod:`math`, cheap enough for a node's tick) and for
an array of crank angles (NumPy, for cycles and plots).

Every step also bounds the error of what it computes (plain sums and products
of magnitudes beside the values, see :mod:`mech_kinematics.bounds`), and
:func:`solve` refuses a state whose bounds exceed a tolerance relative to each
kind's scale, or that lies within rounding of an assembly limit. A scene far
from 1 m in size, or a crank far from 1 rad/s, is solved scaled by a power of
two and scaled back (exactly), so no product overflows or underflows.

Everything here is SI: metres, radians, seconds. Angles are counter-clockwise
from +x; angular velocities and accelerations are positive counter-clockwise.
"""

from __future__ import annotations

import cmath
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from enum import IntEnum
from functools import cached_property
import heapq
import math
import re
from types import SimpleNamespace
from typing import Any, cast
import warnings

import numpy as np
import numpy.typing as npt

from .bounds import (ErrorBound, LARGEST, limit, MAX_ERROR, ROUNDING_MARGIN, SCALE_MEANINGS,
                     Table, U, UNITS)
from .errors import AssemblyError, NearSingularWarning, SceneError, UntrustedError
from .units import ANGLE_UNITS, degrees_from_radians, LENGTH_UNITS

__all__ = [
    'Branch', 'CarriedPoint', 'Crank', 'Engagement', 'JointMotion', 'Link', 'MAX_SLOTS',
    'NEAR_SINGULAR', 'Pin', 'PointState', 'RPR', 'RRP', 'RRR', 'SINGULAR', 'Scene', 'State',
    'TANGENCY_TOLERANCE', 'Units', 'assembly_text', 'solve',
]

#: A dyad whose near-singularity measure falls below this is flagged as
#: near-singular (:class:`NearSingularWarning`); its velocities lose up to about
#: ``2 * -log10(measure)`` digits (near a toggle the condition number grows as
#: ``1 / measure**2``) and its accelerations up to three times ``-log10(measure)``.
NEAR_SINGULAR = 1e-3
#: At or below this measure a dyad is treated as singular and not solved.
SINGULAR = 1e-12
#: Most slots of an intermittent (Geneva) lever.
MAX_SLOTS = 1000
#: An intermittent lever's pin must enter its slots tangentially: the crank
#: radius R of the pin and the centre distance l must satisfy
#: ``|R / l - sin(pi / n)| <= TANGENCY_TOLERANCE * sin(pi / n)``.
TANGENCY_TOLERANCE = 1e-9

IDENTIFIER = re.compile(r'[A-Za-z_][A-Za-z0-9_]*\Z')

Number = float | npt.NDArray[np.float64]
Vector = complex | npt.NDArray[np.complex128]


class Branch(IntEnum):
    """Assembly branch of a dyad.

    For an RRR dyad ``PLUS`` takes the new pin to the left of the directed
    line from the first link's start to the second's; for an RRP dyad it takes
    the larger slider coordinate.
    """

    PLUS = 1
    MINUS = -1


Where = tuple[object, str] | None


def _check_name(name: str, what: str, where: Where = None) -> None:
    if not isinstance(name, str) or not IDENTIFIER.match(name):
        msg = f'Expected {what} to be an identifier ([A-Za-z_][A-Za-z0-9_]*), got {name!r}'
        raise SceneError(msg, where)


def _check_finite(value: float, what: str, where: Where = None) -> None:
    if not math.isfinite(value):
        msg = f'Expected {what} to be a finite number, got {value!r}'
        raise SceneError(msg, where)


def _check_length(value: float, what: str, where: Where = None) -> None:
    if not (math.isfinite(value) and value > 0.0):
        msg = f'Expected {what} to be a positive length, got {_g(value)} m'
        raise SceneError(msg, where)


def _g(value: float, *others: float) -> str:
    """Return ``value`` to 6 significant digits, or more where ``others`` would look equal."""
    digits = 6
    while digits < 17 and any(o != value and f'{o:.{digits}g}' == f'{value:.{digits}g}'
                              for o in others):
        digits += 1
    return f'{value:.{digits}g}'


@dataclass(frozen=True)
class Units:
    """The units a scene was written in, for messages: ``length`` m or mm, ``angle`` rad or deg.

    Everything the solver holds and returns is SI; these only say how to show
    a scene's own values back to the person who wrote them.
    """

    length: str = 'm'
    angle: str = 'rad'

    def __post_init__(self) -> None:
        """Validate the fields."""
        if self.length not in LENGTH_UNITS or self.angle not in ANGLE_UNITS:
            msg = (f'Expected units length in {", ".join(LENGTH_UNITS)} and angle in '
                   f'{", ".join(ANGLE_UNITS)}, got {self.length!r} and {self.angle!r}')
            raise SceneError(msg, (self, 'length'))

    def length_text(self, metres: float, *others: float) -> str:
        """Return a length given in m as text in the scene's unit, 6 significant digits."""
        per = LENGTH_UNITS[self.length]
        return f'{_g(metres * per, *(o * per for o in others))} {self.length}'

    def angle_value(self, radians: float) -> float:
        """Return an angle given in rad in the scene's unit."""
        return degrees_from_radians(radians) if self.angle == 'deg' else radians

    def angle_text(self, radians: float) -> str:
        """Return an angle given in rad as text in the scene's unit, 6 significant digits."""
        return f'{_g(self.angle_value(radians))} {self.angle}'


@dataclass(frozen=True)
class Crank:
    """The driving crank: a link turning about a ground point.

    Parameters
    ----------
    link : str
        Name of the crank link (a revolute joint).
    center : str
        Ground point it turns about.
    point : str
        The point at its tip.
    length : float
        Crank length, m.
    angle : float
        Crank angle at time zero, rad.
    speed : float
        Default angular velocity, rad/s, + CCW.
    accel : float
        Default angular acceleration, rad/s^2, + CCW.
    """

    link: str
    center: str
    point: str
    length: float
    angle: float = 0.0
    speed: float = 0.0
    accel: float = 0.0

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.link, 'the crank link name', (self, 'link'))
        _check_name(self.center, 'the crank center', (self, 'center'))
        _check_name(self.point, 'the crank point', (self, 'point'))
        _check_length(self.length, f'crank "{self.link}" length', (self, 'length'))
        _check_finite(self.angle, 'the crank angle', (self, 'angle'))
        _check_finite(self.speed, 'the crank speed', (self, 'speed'))
        _check_finite(self.accel, 'the crank acceleration', (self, 'accel'))


@dataclass(frozen=True)
class Link:
    """A binary link of a dyad, from a known point to the dyad's new point."""

    name: str
    start: str
    length: float

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.name, 'a link name', (self, 'name'))
        _check_name(self.start, f'the start point of link "{self.name}"', (self, 'start'))
        _check_length(self.length, f'link "{self.name}" length', (self, 'length'))


@dataclass(frozen=True)
class RRR:
    """Two links meeting at a new pin ``point``."""

    point: str
    links: tuple[Link, Link]
    branch: Branch = Branch.PLUS

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.point, 'an RRR point', (self, 'point'))
        count = len(self.links)  # anything may be passed at run time
        if count != 2:
            msg = f'Expected RRR "{self.point}" to have 2 links, got {count}'
            raise SceneError(msg, (self, 'links'))
        object.__setattr__(self, 'branch', Branch(self.branch))


@dataclass(frozen=True)
class RRP:
    """A link ending in a slider ``point`` on a fixed straight guide."""

    point: str
    link: Link
    through: str
    guide_angle: float
    slider: str
    branch: Branch = Branch.PLUS

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.point, 'an RRP point', (self, 'point'))
        _check_name(self.through, f'the guide point of RRP "{self.point}"', (self, 'through'))
        _check_name(self.slider, f'the slider of RRP "{self.point}"', (self, 'slider'))
        _check_finite(self.guide_angle, f'the guide angle of RRP "{self.point}"',
                      (self, 'guide_angle'))
        object.__setattr__(self, 'branch', Branch(self.branch))


@dataclass(frozen=True)
class RPR:
    """A slotted ``link`` turning about ground point ``center``, through pin ``through``.

    With ``slots`` (an integer n >= 3) the link is an intermittent (Geneva)
    wheel: n slots evenly spaced, driven by the pin only while it is in one.
    The pin must be a point fixed on the crank, entering the slots
    tangentially (crank radius of the pin ``R = l sin(pi / n)`` for the
    distance ``l`` between the crank's centre and ``center``, within
    :data:`TANGENCY_TOLERANCE`); between engagements the wheel is locked, and
    each engagement indexes it by ``2 pi / n`` against the crank's sense. The
    link's angle is that of its slot 0: the slot the pin is in during the
    engagement centred on the crank angle that points the pin at ``center``
    in the crank's turn 0 (so in that engagement the angle is the plain RPR
    one, from ``center`` toward the pin).
    """

    link: str
    center: str
    through: str
    slider: str
    slots: int | None = None

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.link, 'an RPR link', (self, 'link'))
        _check_name(self.center, f'the center of RPR "{self.link}"', (self, 'center'))
        _check_name(self.through, f'the pin of RPR "{self.link}"', (self, 'through'))
        _check_name(self.slider, f'the slider of RPR "{self.link}"', (self, 'slider'))
        n = self.slots
        if n is not None and (isinstance(n, bool) or not isinstance(n, int)
                              or not 3 <= n <= MAX_SLOTS):
            msg = (f'Expected the slots of RPR "{self.link}" to be an integer from 3 to '
                   f'{MAX_SLOTS}, got {n!r}')
            raise SceneError(msg, (self, 'slots'))


@dataclass(frozen=True)
class Pin:
    """A pin of radius ``radius`` (m) at ``point``, whose rubbing velocity is reported.

    The rubbing velocity is ``|omega_a - omega_b| * radius`` for the two bodies
    the pin joins (the ground counts as a body with omega 0, an RRP slider
    block too, an RPR block turns with its lever). ``bodies`` names the two
    where more than two meet at ``point`` (a compound pin); ``None`` takes
    the only two there are.
    """

    point: str
    radius: float
    bodies: tuple[str, str] | None = None

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.point, 'a pin point', (self, 'point'))
        _check_length(self.radius, f'the radius of pin "{self.point}"', (self, 'radius'))
        if self.bodies is not None:
            bodies = tuple(self.bodies)
            if len(bodies) != 2 or bodies[0] == bodies[1]:
                msg = (f'Expected two different bodies for pin "{self.point}", got '
                       f'{list(bodies)!r}')
                raise SceneError(msg, (self, 'bodies'))
            for body in bodies:
                _check_name(body, f'a body of pin "{self.point}"', (self, 'bodies'))
            object.__setattr__(self, 'bodies', bodies)


@dataclass(frozen=True)
class CarriedPoint:
    """A point carried rigidly by ``link``.

    It lies at ``local`` (m) in the frame with origin at ``origin`` and x-axis
    toward ``xaxis``, both points on that link. The scene format's
    ``{from: F, toward: T, distance: d}`` is ``origin=F, xaxis=T,
    local=(d, 0)``.
    """

    name: str
    link: str
    origin: str
    xaxis: str
    local: tuple[float, float]

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.name, 'a carried point name', (self, 'name'))
        _check_name(self.link, f'the link of point "{self.name}"', (self, 'link'))
        _check_name(self.origin, f'the origin of point "{self.name}"', (self, 'origin'))
        _check_name(self.xaxis, f'the x-axis point of point "{self.name}"', (self, 'xaxis'))
        for value in self.local:
            _check_finite(value, f'the local coordinates of point "{self.name}"',
                          (self, 'local'))


Dyad = RRR | RRP | RPR


# --- the steps of a solve -------------------------------------------------


#: The empty table a solve's optional entries start from; replaced, never mutated.
_NOTHING: dict[str, Any] = {}


class _Context:
    """Values known so far in one solve; complex numbers or complex arrays.

    Every entry carries the error bounds of its values (see :mod:`.bounds`):
    ``points[name] = (p, v, a, bound p, bound v, bound a)``, likewise
    ``links[name] = (e, omega, alpha, ...)`` with ``e`` the unit vector along the
    link, and ``sliders[name] = (s, sd, sdd, ...)``.
    """

    __slots__ = ('angle', 'turns', 'shown', 'vector', 'points', 'links', 'sliders', 'measures',
                 'valid', 'failures', 'engagement', 'rubbing', 'notes')

    def __init__(self, angle: Any, vector: bool, turns: Any = 0) -> None:
        self.angle = angle
        self.turns = turns  # whole crank turns to add to angle (intermittent drives only)
        # The crank angle counted from the start, for messages (scalar path).
        self.shown = angle if vector or turns == 0 else angle + math.tau * turns
        self.vector = vector
        self.points: dict[str, tuple[Any, Any, Any, Any, Any, Any]] = {}
        self.links: dict[str, tuple[Any, Any, Any, Any, Any, Any]] = {}
        self.sliders: dict[str, tuple[Any, Any, Any, Any, Any, Any]] = {}
        self.measures: dict[str, Any] = {}
        self.valid: Any = True
        self.failures: dict[str, Any] = {}
        # Filled by the steps that have them (shared empty until then: never mutated).
        self.engagement: dict[str, tuple[Any, Any]] = _NOTHING  # lever -> (engaged, window)
        self.rubbing: dict[str, tuple[Any, Any]] = _NOTHING  # pin -> (value, bound)
        self.notes: dict[str, str] = _NOTHING  # label -> why a bound is large (scalar path)

    def check(self, ok: Any, label: str, reason: Any, facts: Any = None) -> None:
        """Stop a scalar solve where ``ok`` fails; mask the entries of a vector solve.

        ``reason`` and ``facts`` are callables, called only to raise: the
        message and the failure's facts for :class:`AssemblyError`.
        """
        if not self.vector:
            if not ok:
                raise AssemblyError(label, self.shown, reason(),
                                    facts=None if facts is None else facts())
            return
        self.mask(ok, label)

    def mask(self, ok: Any, label: str) -> None:
        """Mark the entries of a vector solve where ``ok`` fails as failed under ``label``."""
        if not ok.all():
            failed = ~ok & self.valid
            self.valid = self.valid & ok
            if failed.any():
                previous = self.failures.get(label)
                self.failures[label] = failed if previous is None else previous | failed

    def check_margin(self, ok: Any, label: str, margin: Any, bound: Any, reason: Any,
                     facts: Any = None) -> None:
        """Like :meth:`check` for a dyad within rounding of an assembly limit (untrusted)."""
        if not self.vector:
            if not ok:
                raise UntrustedError(label, self.shown, reason(), 'margin', float(bound),
                                     float(margin) / ROUNDING_MARGIN,
                                     facts=None if facts is None else facts())
            return
        self.mask(ok, label)


def _dot(a: Any, b: Any) -> Any:
    return a.real * b.real + a.imag * b.imag


def _cross(a: Any, b: Any) -> Any:
    return a.real * b.imag - a.imag * b.real


# Multiples of the unit roundoff used by the bounds.
_U2, _U3, _U4, _U5, _U7, _U16 = (n * U for n in (2, 3, 4, 5, 7, 16))

# How the bounds below are built (bounds.py says what they mean). Each step
# bounds the error of its outputs, first order, from the bounds of its inputs
# (the points it starts from, the scene's constants rounded to doubles) and
# its own rounding. A dyad's rounding is counted as a perturbation of its
# inputs (its closed forms are backward stable), amplified like an input's
# error by the dyad's sensitivity: ``1 / measure`` for an RRR's or RRP's
# positions and for the rows of its two-by-two velocity and acceleration
# systems, ``1 / s`` for an RPR. The rounding of the final sums and products
# adds a few ``U`` of their terms' magnitudes; a point's position bound is kept
# at least ``U |p|``, so a later sum's rounding is covered by its operand's
# bound without computing a norm; where a velocity's or acceleration's size is
# needed, ``|x| + |y| >= |z|`` stands for it. Every bound is a sum of products
# of real magnitudes, never a complex norm (NumPy's may differ from Python's by
# an ulp): the same bits on both paths.


class _CrankStep:
    def __init__(self, crank: Crank, center: complex) -> None:
        self.link = crank.link
        self.point = crank.point
        self.center = center
        self.length = crank.length
        self.uses: tuple[str, ...] = (crank.center,)
        # The tip's sum ``center + r``: the centre's rounding and the sum's.
        self.e_center = U * (2.0 * abs(center) + crank.length)
        # r = length * e: the length's rounding and the product's; then those of
        # v = i omega r and of a = i alpha r - omega^2 r.
        self.e_r, self.e_v, self.e_a = (n * U * crank.length for n in (2, 4, 7))

    def run(self, ctx: _Context, theta: Any, omega: Any, alpha: Any) -> None:
        e: Any
        if ctx.vector:
            e = np.empty(np.shape(theta), dtype=np.complex128)
            np.cos(theta, out=e.real)
            np.sin(theta, out=e.imag)
        else:
            e = complex(math.cos(theta), math.sin(theta))
        r = self.length * e
        if (not ctx.vector or alpha.ndim == 0) and alpha == 0.0:  # a constant crank speed
            acceleration = -(omega * omega) * r
        else:
            acceleration = 1j * alpha * r - omega * omega * r
        # Bounds: theta known to U |theta|, cos and sin to an ulp; r = length * e.
        ee = U * abs(theta) + _U2
        re = self.length * ee
        w = abs(omega)
        ctx.points[self.point] = (self.center + r, 1j * omega * r, acceleration,
                                  re + self.e_r + self.e_center, w * (re + self.e_v),
                                  (abs(alpha) + w * w) * (re + self.e_a))
        ctx.links[self.link] = (e, omega, alpha, ee + _U4, U * w, U * abs(alpha))


# Every complex product below has one real factor or a purely imaginary one
# (``1j * x``): such products round the same way in Python's complex type and
# in NumPy's (whose general complex product may use fused multiply-adds), so
# the single-angle and array paths give the same bits. Norms use hypot for the
# same reason.


class _RRRStep:
    unit = 1.0  # metres per length unit of the plan, for messages (see _Solver)

    def __init__(self, dyad: RRR) -> None:
        first, second = dyad.links
        self.dyad = dyad
        self.label = f'RRR {dyad.point}'
        self.key = dyad.point
        self.point = dyad.point
        self.start1, self.start2 = first.start, second.start
        self.link1, self.link2 = first.name, second.name
        self.l1, self.l2 = first.length, second.length
        self.inv_l1, self.inv_l2 = 1.0 / first.length, 1.0 / second.length
        self.inv_sum = self.inv_l1 + self.inv_l2
        lsum = first.length + second.length
        # The input lengths' rounding (U each), and this step's as more of it:
        # lsum and ldiff are those of lengths within U lsum of the true ones.
        self.e_lengths = _U3 * lsum
        # The rounding of r1 and r2 from the rounded data (not amplified: the
        # height's root, the unit vector, the final sums), and of the products
        # of the velocity and acceleration systems.
        self.e_forward = _U16 * lsum
        self.e_round = 8.0 * U * max(first.length, second.length)
        self.branch = int(dyad.branch)
        self.uses = (first.start, second.start)

    def facts(self, dist: float, touching: bool) -> dict[str, Any]:
        """Return why the circles do not meet, for a message in the scene's units."""
        m = self.unit
        return {'kind': 'in line' if touching else 'apart', 'links': (self.link1, self.link2),
                'lengths': (self.l1 * m, self.l2 * m), 'points': (self.start1, self.start2),
                'distance': float(dist) * m}

    def run(self, ctx: _Context) -> None:
        l1, l2 = self.l1, self.l2
        p1, v1, a1, ep1, ev1, ea1 = ctx.points[self.start1]
        p2, v2, a2, ep2, ev2, ea2 = ctx.points[self.start2]
        d = p2 - p1
        dist = np.hypot(d.real, d.imag) if ctx.vector else abs(d)
        lsum = l1 + l2
        ldiff = l1 - l2
        # 4 * dist^2 * h^2 as a product of factors: no cancellation near toggle.
        k = (lsum + dist) * (lsum - dist) * (dist + ldiff) * (dist - ldiff)
        # The circles meet (k > 0) where the margin min(lsum - dist, dist - |ldiff|)
        # is positive. The error of dist, l1 and l2 (spread) is the inputs' and this
        # step's rounding of d and dist (2 U dist) and of lsum and ldiff. The margin
        # is linear in them: beyond ROUNDING_MARGIN spreads of the limit no input
        # within its error can cross it; nearer, either way, it is not trusted.
        spread = ep1 + ep2 + self.e_lengths + _U2 * dist
        outer = lsum - dist
        inner = dist - abs(ldiff)
        margin = np.minimum(outer, inner) if ctx.vector else (
            outer if outer < inner else inner)
        ok = margin > ROUNDING_MARGIN * spread
        m = self.unit
        if not (ctx.vector or ok or margin > -ROUNDING_MARGIN * spread):
            ctx.check(False, self.label, lambda: (
                f'the circles about {self.start1} (radius {_g(l1 * m)} m) and {self.start2} '
                f'(radius {_g(l2 * m)} m) do not meet: expected '
                f'|{_g(ldiff * m, dist * m)}| < |{self.start1}{self.start2}| < '
                f'{_g(lsum * m, dist * m)} m, got |{self.start1}{self.start2}| = '
                f'{_g(dist * m, lsum * m, abs(ldiff) * m)} m'), lambda: self.facts(dist, False))
        if ctx.vector or not ok:
            ctx.check_margin(ok, self.label, margin * m, spread * m, lambda: (
                f'the circles about {self.start1} and {self.start2} are within rounding of '
                f'meeting at one point: expected the margin min({_g(lsum * m)} m - '
                f'|{self.start1}{self.start2}|, |{self.start1}{self.start2}| - '
                f'{_g(abs(ldiff) * m)} m) = {margin * m:.3g} m to exceed '
                f'{ROUNDING_MARGIN:g} times its error bound {spread * m:.3g} m'),
                lambda: self.facts(dist, True))
        root = np.sqrt(k) if ctx.vector else math.sqrt(k)
        # sin of the angle between the two links (the transmission angle).
        measure = root / (2.0 * l1 * l2)
        ok = measure > SINGULAR
        if ctx.vector or not ok:
            ctx.check(ok, self.label, lambda: (
                f'links {self.link1} and {self.link2} are in line (singular): expected the '
                f'sine of the angle between them > {SINGULAR:g}, got {measure:.3g}'),
                lambda: self.facts(dist, True))
        ctx.measures[self.key] = measure
        half = 0.5 / dist
        shared = ldiff * lsum
        height = self.branch * root * half
        u = d * (1.0 / dist)
        across = 1j * height * u
        r1 = (shared + dist * dist) * half * u + across
        r2 = (shared - dist * dist) * half * u + across
        inv = 2.0 * self.branch / root  # 1 / cross(r1, r2)
        dv = v2 - v1
        w1 = _dot(dv, r2) * inv
        w2 = _dot(dv, r1) * inv
        w1sq, w2sq = w1 * w1, w2 * w2
        da = a2 - a1 + w1sq * r1 - w2sq * r2
        al1 = _dot(da, r2) * inv
        al2 = _dot(da, r1) * inv
        # Bounds. r1 and r2 (and the pin) move by at most er: spread / measure
        # and their own rounding.
        # The velocity system i w1 r1 - i w2 r2 = dv has rows of norm
        # 1 / (l1 measure) and 1 / (l2 measure), its matrix moves by er and its
        # right side by the inputs' bounds: w1 and w2 move by t / l1 and t / l2
        # (t also holds the rounding of the dot products and of w = dot * inv).
        # Likewise the acceleration system, whose right side
        # da = a2 - a1 + w1^2 r1 - w2^2 r2 moves with the w's.
        inv_m = 1.0 / measure
        er = spread * inv_m + self.e_forward
        erp = er + self.e_round
        inv_l1, inv_l2 = self.inv_l1, self.inv_l2
        aw1 = abs(w1)
        aws = aw1 + abs(w2)
        t = (ev1 + ev2 + aws * erp) * inv_m
        aa1 = abs(al1)
        ta = (ea1 + ea2 + (2.0 * aws + t * self.inv_sum) * t
              + (w1sq + w2sq + aa1 + abs(al2)) * erp) * inv_m
        ew1 = t * inv_l1
        # The pin's sums p1 + r1 etc. round by U |p1| + U l1 (in ep1 and er),
        # U |v1| + U |w1| l1 and 2 U |a1| + a few U (|al1| + w1^2) l1 (in erp).
        ctx.points[self.point] = (
            p1 + r1, v1 + 1j * w1 * r1, a1 + 1j * al1 * r1 - w1 * w1 * r1, er + ep1,
            ev1 + U * (abs(v1.real) + abs(v1.imag)) + t + aw1 * erp,
            ea1 + _U2 * (abs(a1.real) + abs(a1.imag)) + ta + (2.0 * aw1 + ew1) * t
            + (aa1 + w1sq) * erp)
        ctx.links[self.link1] = (r1 * (1.0 / l1), w1, al1, er * inv_l1 + _U7, ew1, ta * inv_l1)
        ctx.links[self.link2] = (r2 * (1.0 / l2), w2, al2, er * inv_l2 + _U7, t * inv_l2,
                                 ta * inv_l2)


class _RRPStep:
    unit = 1.0  # metres per length unit of the plan, for messages (see _Solver)

    def __init__(self, dyad: RRP, through: complex) -> None:
        self.dyad = dyad
        self.label = f'RRP {dyad.point}'
        self.key = dyad.point
        self.point = dyad.point
        self.start = dyad.link.start
        self.link = dyad.link.name
        self.length = dyad.link.length
        self.inv_length = 1.0 / dyad.link.length
        self.slider = dyad.slider
        self.through = through
        self.through_name = dyad.through
        self.guide_angle = dyad.guide_angle
        self.u = complex(math.cos(dyad.guide_angle), math.sin(dyad.guide_angle))
        self.normal = 1j * self.u
        self.branch = int(dyad.branch)
        self.uses = (dyad.link.start,)
        # The guide: its point known to U |through|, its direction to the angle's
        # rounding and an ulp of cos and sin.
        self.e_through = U * abs(through)
        self.e_guide = U * abs(dyad.guide_angle) + _U2
        # The rounding of w = q - through, of its components along and across
        # the guide and of k's factors, as errors of the start point.
        self.e_turn = self.e_guide + _U5
        self.e_fixed = self.e_through + _U2 * dyad.link.length
        self.e_round = _U3 * dyad.link.length  # of the final forms
        self.e_round2 = 2.0 * self.e_round

    def facts(self, offset: float) -> dict[str, Any]:
        """Return why the guide is out of reach, for a message in the scene's units."""
        m = self.unit
        return {'kind': 'reach', 'links': (self.link,), 'lengths': (self.length * m,),
                'points': (self.start, self.through_name), 'distance': abs(float(offset)) * m,
                'guide_angle': self.guide_angle}

    def run(self, ctx: _Context) -> None:
        length, u = self.length, self.u
        q, vq, aq, eq, evq, eaq = ctx.points[self.start]
        w = q - self.through
        along = _dot(w, u)
        offset = _cross(u, w)  # signed distance of the start point from the guide
        k = (length - offset) * (length + offset)
        # The guide is in reach (k > 0) where the margin length - |offset| is
        # positive. The error of the start point relative to the guide (the
        # inputs' and this step's rounding; spread) also bounds that of the
        # slider coordinate's data. Within ROUNDING_MARGIN spreads of the limit,
        # either way, the answer is not trusted.
        ek = self.e_turn
        spread = eq + (abs(along) + length) * ek + self.e_fixed
        margin = length - abs(offset)
        ok = margin > ROUNDING_MARGIN * spread
        m = self.unit
        if not (ctx.vector or ok or margin > -ROUNDING_MARGIN * spread):
            ctx.check(False, self.label, lambda: (
                f'the guide is out of reach of link {self.link}: expected the distance of '
                f'{self.start} from the guide < {_g(length * m, abs(offset) * m)} m, got '
                f'{_g(abs(offset) * m, length * m)} m'), lambda: self.facts(offset))
        if ctx.vector or not ok:
            ctx.check_margin(ok, self.label, margin * m, spread * m, lambda: (
                f'the guide is within rounding of the reach of link {self.link}: expected '
                f'the margin {_g(length * m)} m - (distance of {self.start} from the guide) '
                f'= {margin * m:.3g} m to exceed {ROUNDING_MARGIN:g} times its error bound '
                f'{spread * m:.3g} m'), lambda: self.facts(offset))
        root = np.sqrt(k) if ctx.vector else math.sqrt(k)
        # sin of the angle between the rod and the guide's normal.
        measure = root / length
        ok = measure > SINGULAR
        if ctx.vector or not ok:
            ctx.check(ok, self.label, lambda: (
                f'link {self.link} is perpendicular to the guide (singular): expected the '
                f'sine of its angle to the guide normal > {SINGULAR:g}, got {measure:.3g}'),
                lambda: self.facts(offset))
        ctx.measures[self.key] = measure
        den = self.branch * root  # dot(u, r)
        inv = 1.0 / den
        s = along + den
        r = den * u - offset * self.normal
        sd = _dot(vq, r) * inv
        omega = _cross(vq, u) * inv
        rest = aq - omega * omega * r
        sdd = _dot(rest, r) * inv
        alpha = _cross(rest, u) * inv
        # Bounds. The slider coordinate moves by at most spread / measure and the
        # rod r by that and spread. The velocity system sd u - i omega r = vq has
        # rows of norm 1 / measure (for sd) and 1 / (length measure) (for omega),
        # its matrix moves by the guide's and the rod's bounds and its right side
        # by the start point's: sd moves by t and omega by t / length (t also
        # holds the rounding of the products, 2 U |vq| <= 2 U (|sd| + |omega| length)).
        # Likewise for accelerations, whose right side aq - omega^2 r moves with omega.
        inv_m = 1.0 / measure
        a_s = abs(s)
        es = spread * inv_m + U * a_s + self.e_round
        er = es + spread + self.e_round
        erp = er + self.e_round2
        asd, aw = abs(sd), abs(omega)
        t = (evq + asd * ek + aw * erp) * inv_m
        ew = t * self.inv_length
        asdd, aal = abs(sdd), abs(alpha)
        ta = (eaq + (2.0 * aw + ew) * t + aw * aw * erp + asdd * ek + aal * erp) * inv_m
        ctx.points[self.point] = (self.through + s * u, sd * u, sdd * u,
                                  es + a_s * ek + 3.0 * self.e_through, t + asd * ek,
                                  ta + asdd * ek)
        ctx.links[self.link] = (r * (1.0 / length), omega, alpha, er * self.inv_length + _U7,
                                ew, ta * self.inv_length)
        ctx.sliders[self.slider] = (s, sd, sdd, es, t, ta)


class _RPRStep:
    unit = 1.0  # metres per length unit of the plan, for messages (see _Solver)

    def __init__(self, dyad: RPR, center: complex, size: float) -> None:
        self.dyad = dyad
        self.label = f'RPR {dyad.link}'
        self.key = dyad.link
        self.link = dyad.link
        self.through = dyad.through
        self.slider = dyad.slider
        self.center = center
        self.center_name = dyad.center
        self.size = size
        self.uses = (dyad.through,)
        self.e_center = U * abs(center)

    def facts(self, s: float) -> dict[str, Any]:
        """Return why the lever is singular, for a message in the scene's units."""
        return {'kind': 'pivot', 'links': (self.link,), 'lengths': (),
                'points': (self.through, self.center_name), 'distance': float(s) * self.unit}

    def run(self, ctx: _Context) -> None:
        b, vb, ab, eb, evb, eab = ctx.points[self.through]
        d = b - self.center
        s = np.hypot(d.real, d.imag) if ctx.vector else abs(d)
        m = self.unit
        # the slider coordinate relative to the mechanism's size.
        measure = s / self.size
        ok = measure > SINGULAR
        if ctx.vector or not ok:
            ctx.check(ok, self.label, lambda: (
                f'the pin {self.through} is on the pivot (singular): expected its distance '
                f'from the pivot > {SINGULAR * self.size * m:.3g} m, got {s * m:.3g} m'),
                lambda: self.facts(s))
        # The error of the pin relative to the pivot (and of s = |d|): within it of
        # the pivot the lever's direction is not known at all.
        ed = eb + self.e_center + _U2 * s
        ok = s > ROUNDING_MARGIN * ed
        if ctx.vector or not ok:
            ctx.check_margin(ok, self.label, s * m, ed * m, lambda: (
                f'the pin {self.through} is within rounding of the pivot: expected its '
                f'distance from the pivot {s * m:.3g} m to exceed {ROUNDING_MARGIN:g} times '
                f'its error bound {ed * m:.3g} m'), lambda: self.facts(s))
        ctx.measures[self.key] = measure
        inv_s = 1.0 / s
        e = d * inv_s
        sd = _dot(vb, e)
        omega = _cross(e, vb) / s
        sdd = _dot(ab, e) + s * omega * omega
        # the Coriolis component 2 * omega * sd sits in the transverse balance.
        alpha = (_cross(e, ab) - 2.0 * sd * omega) / s
        # Bounds: the lever's direction is known to ed / s, and the pin's velocity
        # and acceleration, whose components along and across it these are, to
        # their bounds; |vb| <= |sd| + s |omega| and |ab| likewise. Since
        # ed >= 2 U s, the terms in ed also hold the rounding of the last products.
        ee = ed * inv_s + _U7
        ee4 = ee + _U4
        asd, aw = abs(sd), abs(omega)
        esd = evb + (asd + s * aw) * ee4
        ew = (esd + 2.0 * aw * ed) * inv_s
        asdd, aal = abs(sdd), abs(alpha)
        tab = eab + (asdd + s * (aw * aw + aal) + 2.0 * asd * aw) * ee4
        ctx.links[self.link] = (e, omega, alpha, ee, ew,
                                (tab + 2.0 * (asd * ew + aw * esd + aal * ed)) * inv_s)
        ctx.sliders[self.slider] = (s, sd, sdd, ed, esd,
                                    tab + 2.0 * aw * aw * ed + s * (2.0 * aw + ew) * ew)


class _IndexStep(_RPRStep):
    """An RPR whose lever is an intermittent (Geneva) wheel of ``n`` slots (see :class:`RPR`).

    The engaged motion is the plain RPR's, turned back by ``2 pi k / n`` in
    the crank's engagement window ``k``; between windows the wheel is held at
    ``c - j pi / n`` (``c`` the direction from the wheel's centre to the
    crank's, ``j = 2k +- 1``), velocity and acceleration exactly 0. The
    window comes from the crank angle counted from the start (``angle`` plus
    ``turns`` whole turns, the turns never added in floating point), so the
    wheel's index is exact over any number of turns; both tables are
    computed once, so both paths read the same bits.
    """

    def __init__(self, dyad: RPR, center: complex, size: float, crank_center: complex,
                 pin: complex) -> None:
        super().__init__(dyad, center, size)
        n = cast(int, dyad.slots)
        self.slots = n
        toward = center - crank_center  # from the crank's centre to the wheel's
        distance = abs(toward)
        # Window 0 is centred on the crank angle that points the pin at the wheel.
        beta = math.atan2(pin.imag, pin.real)
        self.phase0 = math.atan2(toward.imag, toward.real) - beta
        self.half = math.pi / 2 - math.pi / n  # half the crank's engaged angle
        self.tan = math.tan(math.pi / n)  # R / (slot mouth): the acceleration's jump / omega^2
        c = math.atan2(-toward.imag, -toward.real)
        step = math.pi / n
        held = [c - j * step for j in range(2 * n)]
        turn = [-2.0 * step * m for m in range(n)]
        self.held = [complex(math.cos(x), math.sin(x)) for x in held]
        self.turn = [complex(math.cos(x), math.sin(x)) for x in turn]
        self.held_array = np.array(self.held, dtype=np.complex128)
        self.turn_array = np.array(self.turn, dtype=np.complex128)
        # Bounds: the line of centres' direction from the rounded ground points
        # and the atan2; each table angle's own rounding; cos and sin to an ulp;
        # the final angle's atan2 (as _U7 elsewhere); the rotation's products.
        ec = U * (abs(center) + abs(crank_center) + distance) / distance + _U2
        self.e_held = [ec + U * (abs(x) + 2.0 * j * step) + _U7 for j, x in enumerate(held)]
        self.e_turn = [U * 2.0 * abs(x) + _U4 + _U4 for x in turn]
        self.e_held_array = np.array(self.e_held)
        self.e_turn_array = np.array(self.e_turn)
        self.e_phase = ec + U * (abs(beta) + math.pi + abs(self.phase0)) + _U2
        self.e_q = 4.0 * U * math.tau  # per whole turn reduced: 2 pi's rounding and the product's
        self.e_half = U * self.half

    def window(self, angle: Any, turns: Any, vector: bool) -> tuple[Any, Any, Any, Any]:
        """Return (engaged, window, offset in the window, its error bound) at a crank angle."""
        d = angle - self.phase0
        if vector:
            q = np.rint(d / math.tau)
            window = np.asarray(turns, dtype=np.int64) + q.astype(np.int64)
        else:
            q = float(round(d / math.tau))
            window = turns + int(q)
        r = d - q * math.tau
        er = U * (abs(angle) + abs(d) + abs(r)) + self.e_phase + abs(q) * self.e_q
        return abs(r) <= self.half, window, r, er

    def run(self, ctx: _Context) -> None:
        super().run(ctx)
        if not ctx.vector:
            self._run_one(ctx)
            return
        n = self.slots
        engaged, window, r, er = self.window(ctx.angle, ctx.turns, ctx.vector)
        near = abs(abs(r) - self.half) <= ROUNDING_MARGIN * (er + self.e_half)
        e, w, al, ee, ew, eal = ctx.links[self.link]
        if ctx.engagement is _NOTHING:
            ctx.engagement = {}
        ctx.engagement[self.link] = (engaged, window)
        m = np.mod(window, n)
        side = np.mod(2 * window + np.where(r > 0.0, 1, -1), 2 * n)
        t = self.turn_array[m]
        held = self.held_array[side]
        # The engaged direction turned back by 2 pi m / n, in real arithmetic (same bits).
        turned = (e.real * t.real - e.imag * t.imag) + 1j * (e.real * t.imag + e.imag * t.real)
        e_turn, e_held = self.e_turn_array[m], self.e_held_array[side]
        entry: tuple[Any, ...] = (
            np.where(engaged, turned, held), np.where(engaged, w, 0.0),
            np.where(engaged, al, 0.0), np.where(engaged, ee + e_turn, e_held),
            np.where(engaged, ew, 0.0), np.where(engaged, eal, 0.0))
        if near.any():
            # Within rounding of a slot's mouth either side may be the true one: the
            # bounds cover both (the acceleration jumps there).
            diff = turned - held
            gap = abs(diff.real) + abs(diff.imag)
            entry = (entry[0], entry[1], entry[2],
                     np.where(near, ee + e_turn + e_held + gap, entry[3]),
                     np.where(near, ew + abs(w), entry[4]),
                     np.where(near, eal + abs(al), entry[5]))
        ctx.links[self.link] = entry

    def _run_one(self, ctx: _Context) -> None:
        """Do :meth:`run` for one crank angle: the same operations, only those it needs."""
        angle = ctx.angle
        d = angle - self.phase0
        q = round(d / math.tau)  # an int: q * tau and abs(q) * e_q round as the float's would
        r = d - q * math.tau
        window = ctx.turns + q
        ar = abs(r)
        half = self.half
        engaged = ar <= half
        if ctx.engagement is _NOTHING:
            ctx.engagement = {}
        ctx.engagement[self.link] = (engaged, window)
        er = U * (abs(angle) + abs(d) + ar) + self.e_phase + abs(q) * self.e_q
        near = abs(ar - half) <= ROUNDING_MARGIN * (er + self.e_half)
        n = self.slots
        e, w, al, ee, ew, eal = ctx.links[self.link]
        if engaged or near:
            m = window % n
            t = self.turn[m]
            turned = (e.real * t.real - e.imag * t.imag) + 1j * (e.real * t.imag
                                                                 + e.imag * t.real)
        if engaged:
            entry: tuple[Any, ...] = (turned, w, al, ee + self.e_turn[m], ew, eal)
        else:
            side = (2 * window + (1 if r > 0.0 else -1)) % (2 * n)
            entry = (self.held[side], 0.0, 0.0, self.e_held[side], 0.0, 0.0)
        if near:
            # Within rounding of a slot's mouth either side may be the true one: the
            # bounds cover both (the acceleration jumps there).
            side = (2 * window + (1 if r > 0.0 else -1)) % (2 * n)
            held = self.held[side]
            diff = turned - held
            gap = abs(diff.real) + abs(diff.imag)
            entry = (entry[0], entry[1], entry[2],
                     ee + self.e_turn[m] + self.e_held[side] + gap, ew + abs(w), eal + abs(al))
            if ctx.notes is _NOTHING:
                ctx.notes = {}
            ctx.notes[self.label] = (
                f'the pin {self.through} is within rounding of the mouth of a slot of '
                f'{self.link}, where its angular acceleration jumps from or to 0 (an '
                f'engagement instant: ask for a crank angle either side of it)')
        ctx.links[self.link] = entry


class _CarryStep:
    def __init__(self, point: CarriedPoint, base: str, local: complex) -> None:
        self.point = point.name
        self.link = point.link
        self.base = base  # the origin of the link's frame
        self.along, self.across = local.real, local.imag
        self.uses = (base,)
        # |local| and the error of the offset: the scene's numbers and the
        # frame's construction, each to a few ulps.
        # The extra 4 U |local| holds the rounding of the final sums and products.
        self.radius = abs(local)
        self.e_local = _U16 * (self.radius + math.hypot(*point.local)) + _U4 * self.radius

    def run(self, ctx: _Context) -> None:
        e, omega, alpha, ee, ew, eal = ctx.links[self.link]
        p, v, a, ep, ev, ea = ctx.points[self.base]
        r = e * self.along
        if self.across:
            r = r + 1j * e * self.across
        radius = self.radius
        er = radius * ee + self.e_local
        aw = abs(omega)
        # The sums round by U |p| (in ep) and U |v|, 2 U |a| (and U |r| terms, in er).
        ctx.points[self.point] = (
            p + r, v + 1j * omega * r, a + 1j * alpha * r - omega * omega * r,
            2.0 * ep + er, ev + U * (abs(v.real) + abs(v.imag)) + ew * radius + aw * er,
            ea + _U2 * (abs(a.real) + abs(a.imag)) + (eal + (2.0 * aw + ew) * ew) * radius
            + (abs(alpha) + aw * aw) * er)


class _RubStep:
    """The rubbing velocity ``|omega_a - omega_b| r`` of a pin of radius ``r`` (seed 001).

    A body is ``('link', name)`` (a link's angular velocity), ``('still', name)``
    (the ground or an RRP slider block: omega 0) or ``('block', lever)`` (an
    RPR block, turning with its lever; an intermittent lever's block touches
    the pin only while engaged, so the rubbing is 0 in a dwell).
    """

    def __init__(self, pin: Pin, bodies: tuple[tuple[str, str], tuple[str, str]],
                 names: tuple[str, str]) -> None:
        self.point = pin.point
        self.radius = pin.radius
        self.bodies = bodies
        self.names = names  # the two bodies' names, as the scene writes them
        self.uses = tuple(name for kind, name in bodies if kind != 'still')

    def run(self, ctx: _Context) -> None:
        (wa, ea), (wb, eb) = (self._omega(ctx, body) for body in self.bodies)
        r = self.radius
        value = abs(wa - wb) * r
        # The inputs' bounds, the difference's and the two products' rounding.
        bound = (ea + eb) * r + _U4 * value
        for kind, name in self.bodies:
            if kind == 'block' and name in ctx.engagement:  # an intermittent lever
                engaged = ctx.engagement[name][0]
                if ctx.vector:
                    value, bound = np.where(engaged, value, 0.0), np.where(engaged, bound, 0.0)
                elif not engaged:
                    value, bound = 0.0, 0.0
        ctx.rubbing[self.point] = (value, bound)

    @staticmethod
    def _omega(ctx: _Context, body: tuple[str, str]) -> tuple[Any, Any]:
        kind, name = body
        if kind == 'still':
            return 0.0, 0.0
        entry = ctx.links[name]
        return entry[1], entry[4]


Step = _RRRStep | _RRPStep | _RPRStep | _CarryStep


@dataclass(frozen=True)
class _Plan:
    """A scene compiled to an ordered list of steps."""

    crank: _CrankStep
    steps: tuple[Step, ...]
    ground: dict[str, complex]
    joint_types: dict[str, str]
    output_joints: tuple[str, ...]
    output_points: tuple[str, ...]
    rubs: tuple[_RubStep, ...] = ()


def _compile(scene: Scene, joints: tuple[str, ...] | None,
             points: tuple[str, ...] | None) -> _Plan:
    """Order the scene's steps by dependency and keep those the outputs need."""
    kinds: dict[str, str] = {}

    def define(name: str, kind: str, where: tuple[object, str]) -> None:
        if name in kinds:
            msg = f'Expected every name to be used once, got "{name}" twice'
            raise SceneError(msg, where)
        kinds[name] = kind

    ground = {}
    for name, (x, y) in scene.ground.items():
        _check_name(name, 'a ground point name', (scene, f'ground.{name}'))
        _check_finite(x, f'ground point "{name}" x', (scene, f'ground.{name}'))
        _check_finite(y, f'ground point "{name}" y', (scene, f'ground.{name}'))
        define(name, 'point', (scene, f'ground.{name}'))
        ground[name] = complex(x, y)
    crank = scene.input
    if crank.center not in ground:
        msg = f'Expected the crank center to be a ground point, got "{crank.center}"'
        raise SceneError(msg, (crank, 'center'))
    define(crank.link, 'link', (crank, 'link'))
    define(crank.point, 'point', (crank, 'point'))
    joint_types = {crank.link: 'revolute'}
    for dyad in scene.dyads:
        if isinstance(dyad, RRR):
            define(dyad.point, 'point', (dyad, 'point'))
            for link in dyad.links:
                define(link.name, 'link', (link, 'name'))
                joint_types[link.name] = 'revolute'
        elif isinstance(dyad, RRP):
            define(dyad.point, 'point', (dyad, 'point'))
            define(dyad.link.name, 'link', (dyad.link, 'name'))
            define(dyad.slider, 'slider', (dyad, 'slider'))
            joint_types[dyad.link.name] = 'revolute'
            joint_types[dyad.slider] = 'prismatic'
        else:
            define(dyad.link, 'link', (dyad, 'link'))
            define(dyad.slider, 'slider', (dyad, 'slider'))
            joint_types[dyad.link] = 'revolute'
            joint_types[dyad.slider] = 'prismatic'
    for carried in scene.points:
        define(carried.name, 'point', (carried, 'name'))

    size = max([crank.length, _diameter(ground.values())]
               + [link.length for d in scene.dyads if isinstance(d, RRR) for link in d.links]
               + [d.link.length for d in scene.dyads if isinstance(d, RRP)])

    # Local coordinates of the points fixed on each link, in the frame at the
    # link's start with x along the link; and the slot pin of each RPR lever.
    local: dict[str, dict[str, complex]] = {
        crank.link: {crank.center: 0j, crank.point: complex(crank.length)}}
    slot: dict[str, tuple[str, str]] = {}
    steps: list[Step] = []
    produces: dict[str, int] = {}  # point, link or slider -> index of its step

    def need_point(name: str, what: str, where: tuple[object, str]) -> str:
        if name not in kinds:
            msg = f'Expected {what} to be a known point, got unknown "{name}"'
            raise SceneError(msg, where)
        if kinds[name] != 'point':
            msg = f'Expected {what} to be a point, got {kinds[name]} "{name}"'
            raise SceneError(msg, where)
        return name

    def need_ground(name: str, what: str, where: tuple[object, str]) -> None:
        need_point(name, what, where)
        if name not in ground:
            msg = f'Expected {what} to be a ground point, got moving point "{name}"'
            raise SceneError(msg, where)

    def prerequisites(item: Dyad | CarriedPoint) -> set[str]:
        """Check the names ``item`` refers to; return those it must wait for."""
        if isinstance(item, RRR):
            return {need_point(link.start, f'the start of link "{link.name}"', (link, 'start'))
                    for link in item.links}
        if isinstance(item, RRP):
            need_ground(item.through, f'the guide point of RRP "{item.point}"',
                        (item, 'through'))
            return {need_point(item.link.start, f'the start of link "{item.link.name}"',
                               (item.link, 'start'))}
        if isinstance(item, RPR):
            need_ground(item.center, f'the center of RPR "{item.link}"', (item, 'center'))
            return {need_point(item.through, f'the pin of RPR "{item.link}"',
                               (item, 'through'))}
        what = f'the link of point "{item.name}"'
        if item.link not in kinds or kinds[item.link] != 'link':
            got = f'unknown "{item.link}"' if item.link not in kinds else \
                f'{kinds[item.link]} "{item.link}"'
            msg = f'Expected {what} to be a link, got {got}'
            raise SceneError(msg, (item, 'link'))
        return {item.link,
                need_point(item.origin, f'the origin of point "{item.name}"', (item, 'origin')),
                need_point(item.xaxis, f'the x-axis point of point "{item.name}"',
                           (item, 'xaxis'))}

    def place(item: Dyad | CarriedPoint) -> tuple[str, ...]:
        """Append the step of ``item``, whose prerequisites are known; return what it adds."""
        index = len(steps)
        if isinstance(item, RRR):
            steps.append(_RRRStep(item))
            for link in item.links:
                local[link.name] = {link.start: 0j, item.point: complex(link.length)}
            added: tuple[str, ...] = (item.point, *(link.name for link in item.links))
        elif isinstance(item, RRP):
            steps.append(_RRPStep(item, ground[item.through]))
            local[item.link.name] = {item.link.start: 0j, item.point: complex(item.link.length)}
            added = (item.point, item.link.name, item.slider)
        elif isinstance(item, RPR):
            if item.slots is None:
                steps.append(_RPRStep(item, ground[item.center], size))
            else:
                steps.append(_index_step(scene, item, ground, local[crank.link], size))
            local[item.link] = {item.center: 0j}
            slot[item.link] = (item.center, item.through)
            added = (item.link, item.slider)
        else:
            fixed = local[item.link]
            if item.origin not in fixed:
                msg = (f'Expected the origin of point "{item.name}" to be a point fixed on link '
                       f'"{item.link}" (one of {_names(fixed)}), got "{item.origin}"')
                raise SceneError(msg, (item, 'origin'))
            if item.xaxis in fixed:
                axis = fixed[item.xaxis] - fixed[item.origin]
                if axis == 0:
                    msg = (f'Expected the origin and x-axis points of point "{item.name}" to be '
                           f'apart, got "{item.origin}" and "{item.xaxis}" coinciding')
                    raise SceneError(msg, (item, 'xaxis'))
                axis /= abs(axis)
            elif slot.get(item.link) == (item.origin, item.xaxis):
                axis = 1 + 0j  # from the lever's pivot toward its slot pin
            else:
                msg = (f'Expected the x-axis point of point "{item.name}" to be a point on link '
                       f'"{item.link}", got "{item.xaxis}"')
                raise SceneError(msg, (item, 'xaxis'))
            offset = fixed[item.origin] + complex(*item.local) * axis
            base = next(iter(fixed))  # the link's start, at 0, comes first
            fixed[item.name] = offset
            steps.append(_CarryStep(item, base, offset))
            added = (item.name,)
        for name in added:
            produces[name] = index
        return added

    # Place each item as soon as what it starts from is known, the earliest in
    # the file first (file order wherever it is free): a heap of the ready
    # items and, per name, the items waiting for it. O(n log n) in all.
    pending: list[Dyad | CarriedPoint] = [*scene.dyads, *scene.points]
    known = {*ground, crank.point, crank.link}
    waiting: dict[str, list[int]] = {}
    missing = [0] * len(pending)
    for index, item in enumerate(pending):
        for name in prerequisites(item) - known:
            waiting.setdefault(name, []).append(index)
            missing[index] += 1
    ready = [index for index, count in enumerate(missing) if count == 0]  # sorted: a heap
    placed = 0
    while ready:
        for name in place(pending[heapq.heappop(ready)]):
            known.add(name)
            for index in waiting.pop(name, ()):
                missing[index] -= 1
                if missing[index] == 0:
                    heapq.heappush(ready, index)
        placed += 1
    if placed < len(pending):
        left = [item for index, item in enumerate(pending) if missing[index]]
        names = [item.point if isinstance(item, (RRR, RRP)) else
                 item.link if isinstance(item, RPR) else item.name for item in left]
        msg = f'Expected dyads and points solvable in order, got a cycle among [{_names(names)}]'
        raise SceneError(msg, (left[0], ''))

    order = [*ground, crank.point, *(name for step in steps
                                     for name in _step_points(step))]
    all_joints = tuple(joint_types)
    out_joints = all_joints if joints is None else tuple(joints)
    out_points = tuple(order) if points is None else tuple(points)
    for name in out_joints:
        if kinds.get(name) not in ('link', 'slider'):
            got = f'unknown "{name}"' if name not in kinds else f'{kinds[name]} "{name}"'
            msg = f'Expected outputs.joints to list links and sliders, got {got}'
            raise SceneError(msg, (scene, 'outputs.joints'))
    for name in out_points:
        if kinds.get(name) != 'point':
            got = f'unknown "{name}"' if name not in kinds else f'{kinds[name]} "{name}"'
            msg = f'Expected outputs.points to list points, got {got}'
            raise SceneError(msg, (scene, 'outputs.points'))

    rubs = _rub_steps(scene, kinds, local)

    # Keep only the steps that the outputs (and the pins' rubbing) depend on.
    needed: set[int] = set()
    todo = [produces[name] for name in (*out_joints, *out_points) if name in produces]
    todo += [produces[name] for rub in rubs for name in rub.uses if name in produces]
    while todo:
        index = todo.pop()
        if index in needed:
            continue
        needed.add(index)
        step = steps[index]
        todo.extend(produces[name] for name in step.uses if name in produces)
        if isinstance(step, _CarryStep) and step.link in produces:  # the crank is no step
            todo.append(produces[step.link])
    kept = tuple(step for index, step in enumerate(steps) if index in needed)
    return _Plan(_CrankStep(crank, ground[crank.center]), kept, ground,
                 {name: joint_types[name] for name in out_joints}, out_joints, out_points,
                 rubs)


def _index_step(scene: Scene, item: RPR, ground: dict[str, complex],
                crank_local: dict[str, complex], size: float) -> _IndexStep:
    """Return the step of an intermittent lever; check its pin and its tangential entry."""
    crank = scene.input
    units: Units = getattr(scene, 'units', Units())
    n = cast(int, item.slots)
    if item.through not in crank_local or item.through == crank.center:
        on_crank = _names(p for p in crank_local if p != crank.center)
        msg = (f'Expected the pin of intermittent RPR "{item.link}" (slots: {n}) to be a point '
               f'fixed on the crank "{crank.link}" ({on_crank}), got "{item.through}"')
        raise SceneError(msg, (item, 'through'))
    pin = crank_local[item.through]
    radius = abs(pin)
    centre, wheel = ground[crank.center], ground[item.center]
    distance = abs(wheel - centre)
    sine = math.sin(math.pi / n)
    if not (radius > 0.0 and abs(radius - distance * sine) <= TANGENCY_TOLERANCE * sine
            * distance):
        per = LENGTH_UNITS[units.length]
        msg = (f'Expected the pin {item.through} to enter the {n} slots of "{item.link}" '
               f'tangentially: {crank.center} and {item.center} '
               f'{radius / sine * per:.10g} {units.length} apart (pin radius '
               f'{units.length_text(radius)} / sin(180 deg / {n})) or a pin radius of '
               f'{distance * sine * per:.10g} {units.length}, to 1e-9, got '
               f'{units.length_text(distance)} apart')
        raise SceneError(msg, (item, 'slots'))
    return _IndexStep(item, wheel, size, centre, pin)


def _rub_steps(scene: Scene, kinds: dict[str, str],
               local: dict[str, dict[str, complex]]) -> tuple[_RubStep, ...]:
    """Return the rubbing step of every pin of ``scene``, checking the bodies it joins."""
    pins: tuple[Pin, ...] = tuple(getattr(scene, 'pins', ()))
    if not pins:
        return ()
    ground_body = 'ground' if 'ground' not in kinds else '_ground'
    at: dict[str, dict[str, tuple[str, str]]] = {}  # point -> body name -> body

    def put(point: str, name: str, body: tuple[str, str]) -> None:
        at.setdefault(point, {})[name] = body

    for link, fixed in local.items():
        for point in fixed:
            put(point, link, ('link', link))
    for dyad in scene.dyads:
        if isinstance(dyad, RRP):
            put(dyad.point, dyad.slider, ('still', dyad.slider))
        elif isinstance(dyad, RPR):
            put(dyad.through, dyad.slider, ('block', dyad.link))
    for point in scene.ground:
        if point in at:  # a ground point that some link turns about
            put(point, ground_body, ('still', ground_body))
    steps = []
    seen: set[str] = set()
    for pin in pins:
        point = pin.point
        if kinds.get(point) != 'point':
            got = f'unknown "{point}"' if point not in kinds else f'{kinds[point]} "{point}"'
            msg = f'Expected pins to name points, got {got}'
            raise SceneError(msg, (pin, 'point'))
        if point in seen:
            msg = f'Expected each pin once, got "{point}" twice'
            raise SceneError(msg, (pin, 'point'))
        seen.add(point)
        bodies = at.get(point, {})
        names = list(bodies)
        if len(names) < 2:
            msg = (f'Expected pin "{point}" where two bodies turn on each other, got '
                   f'{"only " + _names(names) if names else "no link"} at {point}')
            raise SceneError(msg, (pin, 'point'))
        if pin.bodies is None:
            if len(names) > 2:
                msg = (f'Expected pin "{point}" to join two bodies, got {len(names)} at {point} '
                       f'({_names(names)}): name the two it joins, e.g. {point}: '
                       f'{{radius: R, between: [{names[0]}, {names[1]}]}}')
                raise SceneError(msg, (pin, 'bodies'))
            pair = (names[0], names[1])
        else:
            pair = pin.bodies
            for name in pair:
                if name not in bodies:
                    msg = (f'Expected the bodies of pin "{point}" to be among those at {point} '
                           f'({_names(names)}), got "{name}"')
                    raise SceneError(msg, (pin, 'bodies'))
        steps.append(_RubStep(pin, (bodies[pair[0]], bodies[pair[1]]), pair))
    return tuple(steps)


def _diameter(points: Iterable[complex]) -> float:
    """Return the largest distance between two of ``points``, m (0 for fewer than two).

    The farthest pair is a pair of vertices of the convex hull (Andrew's
    monotone chain), found among its antipodal pairs (rotating calipers, as in
    KACTL's ``hullDiameter``): O(n log n) instead of all n^2 pairs, and the
    same value, each candidate being the same ``abs(a - b)``. The orientation
    tests run on the points scaled by a power of two (exact) to at most 2**500,
    so that their products cannot overflow.
    """
    unique = sorted({(z.real, z.imag) for z in points})
    if len(unique) < 2:
        return 0.0
    largest = max(max(abs(x), abs(y)) for x, y in unique)
    scale = 2.0 ** (500 - math.frexp(largest)[1]) if largest > 2.0**500 else 1.0
    scaled = [(x * scale, y * scale) for x, y in unique]

    def turn(o: int, a: int, b: int) -> float:
        (ox, oy), (ax, ay), (bx, by) = scaled[o], scaled[a], scaled[b]
        return (ax - ox) * (by - oy) - (ay - oy) * (bx - ox)

    hull: list[int] = []  # indices into unique, counter-clockwise
    for run in (range(len(unique)), range(len(unique) - 1, -1, -1)):
        chain: list[int] = []
        for k in run:
            while len(chain) >= 2 and turn(chain[-2], chain[-1], k) <= 0:
                chain.pop()
            chain.append(k)
        hull += chain[:-1]
    at = [complex(*unique[k]) for k in hull]
    edge = [complex(*scaled[k]) for k in hull]
    n = len(hull)
    if n < 3:  # all on one line: its two ends
        return abs(at[0] - at[-1])
    best, i, j = 0.0, 0, 1
    while i < j:
        for _ in range(n):  # advance j while the edge from it turns away from edge i
            best = max(best, abs(at[i] - at[j]))
            u, v = edge[i + 1] - edge[i], edge[(j + 1) % n] - edge[j]
            if v.real * u.imag - v.imag * u.real >= 0:
                break
            j = (j + 1) % n
        i += 1
    return best


def _names(names: Iterable[str], most: int = 10) -> str:
    """Return ``A, B, C`` for a message: the first ``most`` names and how many more."""
    names = list(names)
    shown = ', '.join(names[:most])
    return shown if len(names) <= most else f'{shown} and {len(names) - most} more'


def _step_points(step: Step) -> tuple[str, ...]:
    return () if isinstance(step, _RPRStep) else (step.point,)


# --- solving with error bounds ----------------------------------------------

#: Mechanism sizes (m) solved as they are; a scene outside is solved with every
#: length scaled by a power of two (exactly), so that no product of lengths
#: overflows or underflows, and its answers scaled back.
_SIZE_RANGE = (2.0 ** -60, 2.0 ** 60)
#: Crank rates ``max(|omega|, sqrt|alpha|)`` (1/s) solved as they are; outside,
#: time is scaled by a power of two the same way.
_RATE_LOW, _RATE_HIGH = 2.0 ** -40, 2.0 ** 40
_ACCEL_HIGH = _RATE_HIGH * _RATE_HIGH
#: What scaling a result back by a power of two can lose (a subnormal result
#: rounds by half the smallest subnormal, its bound by as much again).
_TINY = 2.0 ** -1073
#: The kinds of a point's (or slider's) values and of a revolute joint's.
_LINEAR = ('position', 'velocity', 'acceleration')
_ANGULAR = ('angle', 'angular velocity', 'angular acceleration')
_QUANTITIES = ('position', 'velocity', 'acceleration')


def _size(scene: Scene) -> float:
    """Return the mechanism's size, m: the scale its positions are judged on.

    The largest of the crank length, the RRR and RRP link lengths, the
    distances of the ground points from the crank's centre and the lengths of
    the carried points' local offsets.
    """
    crank = scene.input
    centre = complex(*scene.ground[crank.center])
    size = crank.length
    for x, y in scene.ground.values():
        size = max(size, abs(complex(x, y) - centre))
    for dyad in scene.dyads:
        if isinstance(dyad, RRR):
            size = max(size, *(link.length for link in dyad.links))
        elif isinstance(dyad, RRP):
            size = max(size, dyad.link.length)
    for point in scene.points:
        size = max(size, math.hypot(*point.local))
    return size


def _exponent(x: float, low: float, high: float) -> int:
    """Return 0 if ``x`` is 0 or in [low, high], else ``e`` with ``x * 2**-e`` in [0.5, 2).

    At most 1023, so that ``2**e`` is a float: ``x`` of 2**1023 or more (up
    to the largest float) is scaled into [1, 2).
    """
    if x == 0.0 or low <= x <= high:
        return 0
    return min(math.frexp(x)[1], 1023)


def _scaled(scene: Scene, shift: int) -> Scene:
    """Return ``scene``'s geometry with every length times ``2**-shift`` (exact), to compile."""
    def scale(x: float) -> float:
        return math.ldexp(x, -shift)

    dyads: list[Dyad] = []
    for dyad in scene.dyads:
        if isinstance(dyad, RRR):
            first, second = (replace(link, length=scale(link.length)) for link in dyad.links)
            dyads.append(replace(dyad, links=(first, second)))
        elif isinstance(dyad, RRP):
            dyads.append(replace(dyad, link=replace(dyad.link, length=scale(dyad.link.length))))
        else:
            dyads.append(dyad)
    return cast(Scene, SimpleNamespace(
        name=scene.name,
        ground={name: (scale(x), scale(y)) for name, (x, y) in scene.ground.items()},
        input=replace(scene.input, length=scale(scene.input.length)), dyads=tuple(dyads),
        points=tuple(replace(p, local=(scale(p.local[0]), scale(p.local[1])))
                     for p in scene.points),
        pins=tuple(replace(p, radius=scale(p.radius)) for p in scene.pins), units=scene.units))


class _Solver:
    """A compiled plan with what solving it with error bounds needs.

    ``run_plan`` is the plan the steps run: ``plan`` itself, or for a scene
    whose size is outside :data:`_SIZE_RANGE` the same scene compiled with
    every length times ``2**-shift``. ``outputs`` lists the reported values in
    solve order: (table of the context, name, path in ``as_dict()``, label of
    the dyad that produced it, the kinds of its three values).
    """

    def __init__(self, scene: Scene, plan: _Plan) -> None:
        self.plan = plan
        self.size = _size(scene)
        self.crank_length = scene.input.length
        self.shift = _exponent(self.size, *_SIZE_RANGE)
        run = plan
        if self.shift:
            try:
                run = _compile(_scaled(scene, self.shift), plan.output_joints,
                               plan.output_points)
            except SceneError:
                msg = (f"Expected every length within 2**1000 of the mechanism's size "
                       f'{self.size:.3g} m, got one that does not survive scaling to 1 m')
                raise SceneError(msg, (scene, 'ground')) from None
            unit = math.ldexp(1.0, self.shift)
            for step in run.steps:
                if not isinstance(step, _CarryStep):
                    step.unit = unit
        self.run_plan = run
        # Ground points are inputs: known to U |g|.
        self.ground = {name: (z, 0j, 0j, U * abs(z), 0.0, 0.0) for name, z in run.ground.items()}
        crank = scene.input
        labels = dict.fromkeys((crank.link, crank.point), f'input {crank.link}')
        labels.update((name, f'ground {name}') for name in plan.ground)
        rank = dict.fromkeys(labels, 0)
        self.measure_keys: dict[str, str] = {}
        for index, step in enumerate(plan.steps, 1):
            if isinstance(step, _CarryStep):
                names: tuple[str, ...] = (step.point,)
                label = labels[step.link]  # the dyad that moves its link
            else:
                label = step.label
                self.measure_keys[label] = step.key
                if isinstance(step, _RRRStep):
                    names = (step.point, step.link1, step.link2)
                elif isinstance(step, _RRPStep):
                    names = (step.point, step.link, step.slider)
                else:
                    names = (step.link, step.slider)
            for name in names:
                labels[name], rank[name] = label, index
        outputs = [(rank[name], 'points', name, f'points.{name}', labels[name], _LINEAR)
                   for name in plan.output_points]
        for name, kind in plan.joint_types.items():
            revolute = kind == 'revolute'
            outputs.append((rank[name], 'links' if revolute else 'sliders', name,
                            f'joints.{name}', labels[name], _ANGULAR if revolute else _LINEAR))
        outputs.sort(key=lambda item: item[0])
        self.outputs = tuple(item[1:] for item in outputs)
        self.out_points = plan.output_points
        self.levers = {step.link: step for step in plan.steps if isinstance(step, _IndexStep)}
        self.out_links = tuple(n for n, k in plan.joint_types.items() if k == 'revolute')
        self.out_sliders = tuple(n for n, k in plan.joint_types.items() if k == 'prismatic')


def assembly_text(error: AssemblyError, units: Units | None = None) -> str:
    """Return why a mechanism cannot assemble, naming links and lengths in ``units``.

    E.g. ``links coupler (150 mm) and rocker (80 mm) cannot reach from B to D
    (235 mm apart)``; the error's own reason where it carries no facts.
    """
    facts = error.facts
    if facts is None:
        return f'{error.dyad}: {error.reason}'
    units = Units() if units is None else units
    text = units.length_text
    kind, links, lengths, points = facts['kind'], facts['links'], facts['lengths'], \
        facts['points']
    distance = facts['distance']
    if kind == 'pivot':
        return (f'the pin {points[0]} of slotted link {links[0]} on its pivot {points[1]} '
                f'({text(distance)} from it)')
    if kind == 'reach':
        return (f'link {links[0]} ({text(lengths[0], distance)}) cannot reach the guide through '
                f'{points[1]} at {units.angle_text(facts["guide_angle"])} from {points[0]} '
                f'({text(distance, lengths[0])} from the guide)')
    (a, b), (la, lb), (p, q) = links, lengths, points
    pair = f'links {a} ({text(la)}) and {b} ({text(lb)})'
    if kind == 'in line':
        return (f'{pair} in line between {p} and {q} ({text(distance)} apart): a toggle '
                f'position, where the mechanism locks')
    if distance >= la + lb:
        return (f'{pair} cannot reach from {p} to {q} '
                f'({text(distance, la + lb)} apart, more than {text(la + lb, distance)})')
    return (f'{pair} cannot meet: {p} and {q} are {text(distance, abs(la - lb))} apart, less '
            f'than the difference of their lengths ({text(abs(la - lb), distance)})')


@dataclass(frozen=True)
class Scene:
    """A planar mechanism: ground points, the driving crank, dyads, carried points.

    Construction validates names and dependencies and checks that the
    mechanism assembles at ``input.angle``; a failure raises
    :class:`SceneError`.

    Parameters
    ----------
    name : str
        Identifier of the scene.
    ground : mapping of str to (float, float)
        Fixed points, m.
    input : Crank
        The driving crank.
    dyads : tuple of RRR, RRP or RPR
        The dyads, solved in dependency order (file order where free).
    points : tuple of CarriedPoint
        Points carried rigidly by links.
    output_joints, output_points : tuple of str or None
        What to compute and report; ``None`` means everything.
    description : str
        Free text.
    pins : tuple of Pin
        Pins whose rubbing velocity is reported (``State.rubbing``).
    units : Units
        The units the scene was written in, for messages (its values are SI).
    """

    name: str
    ground: Mapping[str, tuple[float, float]]
    input: Crank
    dyads: tuple[Dyad, ...] = ()
    points: tuple[CarriedPoint, ...] = ()
    outputs_joints: tuple[str, ...] | None = None
    outputs_points: tuple[str, ...] | None = None
    description: str = ''
    pins: tuple[Pin, ...] = ()
    units: Units = Units()
    _plan: _Plan = field(init=False, repr=False, compare=False)
    _solver: _Solver = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.name, 'the scene name', (self, 'name'))
        object.__setattr__(self, 'dyads', tuple(self.dyads))
        object.__setattr__(self, 'points', tuple(self.points))
        object.__setattr__(self, 'pins', tuple(self.pins))
        full = _compile(self, None, None)
        solver = _Solver(self, full)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter('ignore', NearSingularWarning)
                _execute(solver, self.input.angle, 0.0, 0.0)  # positions only
        except AssemblyError as error:
            dyad = next((step.dyad for step in full.steps
                         if not isinstance(step, _CarryStep) and step.label == error.dyad), None)
            msg = (f'Expected the mechanism to assemble at the initial crank angle '
                   f'{self.units.angle_text(self.input.angle)}, got '
                   f'{assembly_text(error, self.units)}')
            raise SceneError(msg, (self.input, 'angle') if dyad is None else (dyad, '')) from None
        if self.outputs_joints is None and self.outputs_points is None:
            plan = full
        else:
            plan = _compile(self, self.outputs_joints, self.outputs_points)
            solver = _Solver(self, plan)
        object.__setattr__(self, '_plan', plan)
        object.__setattr__(self, '_solver', solver)

    @property
    def output_joints(self) -> tuple[str, ...]:
        """Names of the joints reported, in order."""
        return self._plan.output_joints

    @property
    def output_points(self) -> tuple[str, ...]:
        """Names of the points reported, in order."""
        return self._plan.output_points

    @property
    def joint_types(self) -> dict[str, str]:
        """Joint name -> ``'revolute'`` or ``'prismatic'``, for the reported joints."""
        return dict(self._plan.joint_types)

    @property
    def pin_bodies(self) -> dict[str, tuple[str, str]]:
        """Pin point -> the two bodies it joins (a link, ``ground`` or a slider block)."""
        return {rub.point: rub.names for rub in self._plan.rubs}


class JointMotion:
    """Position, velocity and acceleration of one joint.

    ``position`` is the link's absolute angle (rad, wrapped to (-pi, pi]) for a
    revolute joint and the slider coordinate (m) for a prismatic one; floats
    for one crank angle, arrays of shape (n,) for n angles.
    """

    __slots__ = ('type', 'position', 'velocity', 'acceleration')

    def __init__(self, type: str, position: Number, velocity: Number,  # noqa: A002
                 acceleration: Number) -> None:
        self.type = type
        self.position = position
        self.velocity = velocity
        self.acceleration = acceleration

    def __repr__(self) -> str:
        """Show every field."""
        return (f'JointMotion(type={self.type!r}, position={self.position!r}, '
                f'velocity={self.velocity!r}, acceleration={self.acceleration!r})')


@dataclass(frozen=True)
class PointState:
    """Position (m), velocity (m/s), acceleration (m/s^2): arrays of shape (2,) or (n, 2)."""

    position: npt.NDArray[np.float64]
    velocity: npt.NDArray[np.float64]
    acceleration: npt.NDArray[np.float64]


def _xy(z: Any) -> npt.NDArray[np.float64]:
    if isinstance(z, complex):
        return np.array((z.real, z.imag))
    return np.stack((z.real, z.imag), axis=-1)


@dataclass(frozen=True)
class Engagement:
    """Where an intermittent (Geneva) lever is in its cycle, and its acceleration's jumps.

    The crank's engagement windows are numbered: window ``k`` is centred on the
    crank angle ``phi + 2 pi k`` (counted from the start) at which the pin
    points at the lever's centre, and spans ``pi / 2 - pi / n`` either side.
    Floats for one crank angle, arrays of shape (n,) for n angles.

    Attributes
    ----------
    engaged : bool or ndarray of bool
        Whether the pin is in a slot (the window's ends included).
    window : int or ndarray of int
        The number of the nearest window: the one the pin is in, or the
        nearest one it has left or will enter.
    entry, exit : float or ndarray
        Crank angles (rad, counted from the start) where that window begins
        and ends.
    entry_acceleration, exit_acceleration : (float, float) or (ndarray, ndarray)
        The lever's angular acceleration (rad/s^2) just before and just after
        the crank passes ``entry`` and ``exit`` (turning CCW) at the current
        crank speed omega: ``(0, -omega^2 tan(pi / n))`` and
        ``(omega^2 tan(pi / n), 0)``. The angular velocity is 0 at both ends
        (the pin enters and leaves tangentially); the acceleration jumps.
    """

    engaged: bool | npt.NDArray[np.bool_]
    window: int | npt.NDArray[np.int64]
    entry: Number
    exit: Number
    entry_acceleration: tuple[Number, Number]
    exit_acceleration: tuple[Number, Number]

    def as_dict(self, vector: bool) -> dict[str, Any]:
        """Return the structure of ``State.as_dict()['intermittent'][LEVER]``."""
        def value(x: Any) -> Any:
            return x if vector else float(x)

        def pair(x: tuple[Any, Any]) -> Any:
            return np.stack(x, axis=-1) if vector else [float(x[0]), float(x[1])]

        return {'engaged': self.engaged if vector else bool(self.engaged),
                'window': self.window if vector else int(self.window),
                'entry': {'angle': value(self.entry),
                          'acceleration': pair(self.entry_acceleration)},
                'exit': {'angle': value(self.exit),
                         'acceleration': pair(self.exit_acceleration)}}


@dataclass(frozen=True)
class State:
    """The kinematic state of a scene at one crank angle or an array of them.

    Attributes
    ----------
    scene : str
        Scene name.
    angle, speed, accel : float or ndarray
        The crank's angle (rad, as given), angular velocity (rad/s) and
        angular acceleration (rad/s^2).
    joints : dict of str to JointMotion
        Every reported joint.
    complex_points : dict of str to (p, v, a)
        Every reported point as complex numbers ``x + iy`` (m, m/s, m/s^2).
    valid : bool or ndarray of bool
        Where the mechanism could be solved. Invalid entries of arrays are NaN.
    singularity : dict of str to float or ndarray
        Near-singularity measure of every solved dyad, keyed by its new point
        (RRR, RRP) or lever (RPR): for RRR the sine of the angle between its
        links, for RRP the sine of the rod's angle to the guide normal, for RPR
        the slider coordinate over the mechanism's size. 0 is singular.
    failures : dict of str to ndarray of bool
        For arrays: per reason, the angles that were refused. The reason is a
        dyad's label (``RRR C``: it cannot close, is singular or is within
        rounding of an assembly limit), that label followed by
        `` (untrusted)`` (a value's error bound exceeds the tolerance) or by
        `` (overflow)`` (a value is beyond the range of doubles).
    error_bound : ErrorBound
        Absolute error bound of every reported value, shaped like ``joints``
        and ``points`` (see :mod:`mech_kinematics.bounds`); ``rubbing`` too.
    turns : int or ndarray of int
        Whole crank turns added to ``angle`` (``solve(..., turns=)``): the crank
        angle counted from the start is ``angle + 2 pi turns``.
    rubbing : dict of str to float or ndarray
        Rubbing velocity (m/s) at every pin of the scene's ``pins``.
    intermittent : dict of str to Engagement
        Every intermittent (Geneva) lever solved: engaged or locked, and where
        its acceleration jumps.
    """

    scene: str
    angle: Number
    speed: Number
    accel: Number
    joints: dict[str, JointMotion]
    complex_points: dict[str, tuple[Vector, Vector, Vector]]
    valid: bool | npt.NDArray[np.bool_]
    singularity: dict[str, Number]
    failures: dict[str, npt.NDArray[np.bool_]]
    error_bound: ErrorBound
    turns: int | npt.NDArray[np.int64] = 0
    rubbing: dict[str, Number] = field(default_factory=dict)
    intermittent: dict[str, Engagement] = field(default_factory=dict)

    @cached_property
    def points(self) -> dict[str, PointState]:
        """Every reported point as 2-D vectors in the ground frame."""
        return {name: PointState(_xy(p), _xy(v), _xy(a))
                for name, (p, v, a) in self.complex_points.items()}

    @cached_property
    def scales(self) -> dict[str, Number]:
        """Per kind of value (:data:`mech_kinematics.bounds.KINDS`), its scale.

        ``position``: the mechanism's size; ``angle``: 1 rad; ``velocity``: the
        largest speed of a reported point or slider, at least the crank tip's
        ``a |omega|``; ``angular velocity``: the largest angular speed of a
        reported link, at least ``|omega|``; ``acceleration`` and ``angular
        acceleration`` likewise, at least ``a (omega^2 + |alpha|)`` and
        ``omega^2 + |alpha|``. A solve is refused where a value's error bound
        exceeds ``max_error`` times its kind's scale.
        """
        bound = self.error_bound
        vector = not isinstance(self.valid, bool)
        return _scales(bound.size, bound.crank_length, self.speed, self.accel,
                       [(v, a) for _, v, a in self.complex_points.values()],
                       [(j.velocity, j.acceleration) for j in self.joints.values()
                        if j.type == 'prismatic'],
                       [(j.velocity, j.acceleration) for j in self.joints.values()
                        if j.type == 'revolute'], vector)

    @cached_property
    def relative_error_bound(self) -> Number:
        """The largest error bound over its kind's scale, over every reported value.

        The smallest ``max_error`` at which this state would be answered (NaN
        where an array state is not valid).
        """
        scales = self.scales
        worst: Any = 0.0
        joints, points = self.error_bound.raw()
        records = [(b, _LINEAR) for b in points.values()]
        records += [(joints[name], _ANGULAR if j.type == 'revolute' else _LINEAR)
                    for name, j in self.joints.items()]
        with np.errstate(divide='ignore', invalid='ignore'):
            for values, kinds in records:
                for value, kind in zip(values, kinds, strict=True):
                    scale = scales[kind]
                    ratio = np.where(value == 0.0, 0.0, np.asarray(value) / scale)
                    worst = np.fmax(worst, ratio)
        if isinstance(self.valid, bool):
            return float(worst)
        return np.where(self.valid, np.broadcast_to(worst, np.shape(self.valid)), np.nan)

    def as_dict(self) -> dict[str, Any]:
        """Return the structure the ``solve`` command prints (floats or arrays)."""
        vector = not isinstance(self.valid, bool)

        def value(x: Any) -> Any:
            return x if vector else float(x)

        def pair(x: npt.NDArray[np.float64]) -> Any:
            return x if vector else [float(x[0]), float(x[1])]

        turns = self.turns
        angle = self.angle if not np.any(turns) else self.angle + math.tau * turns
        return {
            'scene': self.scene,
            'input': {'angle': value(angle), 'speed': value(self.speed),
                      'accel': value(self.accel)},
            'joints': {name: {'type': j.type, 'position': value(j.position),
                              'velocity': value(j.velocity),
                              'acceleration': value(j.acceleration)}
                       for name, j in self.joints.items()},
            'points': {name: {'position': pair(p.position), 'velocity': pair(p.velocity),
                              'acceleration': pair(p.acceleration)}
                       for name, p in self.points.items()},
            **({'rubbing': {name: value(x) for name, x in self.rubbing.items()}}
               if self.rubbing else {}),
            **({'intermittent': {name: e.as_dict(vector)
                                 for name, e in self.intermittent.items()}}
               if self.intermittent else {}),
            'error_bound': self.error_bound.as_dict(vector),
        }


def _run(solver: _Solver, angle: Any, speed: Any, accel: Any, turns: Any) -> _Context:
    """Run every step of the solver's plan; the caller chose scalar or vector inputs."""
    ctx = _Context(angle, not isinstance(angle, float), turns)
    # Ground points stay complex scalars in both paths: NumPy broadcasts them.
    ctx.points.update(solver.ground)
    plan = solver.run_plan
    plan.crank.run(ctx, angle, speed, accel)
    for step in plan.steps:
        step.run(ctx)
    if plan.rubs:
        ctx.rubbing = {}
        for rub in plan.rubs:
            rub.run(ctx)
    return ctx


def _execute(solver: _Solver, theta: Any, omega: Any, alpha: Any, turns: Any = 0) -> _Context:
    """Run the solver in units that keep every product in range; reported values in SI.

    A crank rate outside [_RATE_LOW, _RATE_HIGH] is solved with time scaled by a
    power of two, as a scene's size outside :data:`_SIZE_RANGE` is with its
    lengths (:class:`_Solver`); both are exact, so the answers are the same
    bits as if every product had stayed in range.
    """
    w = abs(omega)
    if isinstance(w, float) and _RATE_LOW <= w <= _RATE_HIGH and abs(alpha) <= _ACCEL_HIGH:
        shift = 0  # the single-angle path's usual case, decided without a call
    else:
        shift = _rate_exponent(omega, alpha)
    if shift:
        omega, alpha = _ldexp(omega, -shift), _ldexp(alpha, -2 * shift)
    ctx = _run(solver, theta, omega, alpha, turns)
    if solver.shift or shift:
        _rescale(solver, ctx, shift)
    return ctx


def _rate_exponent(omega: Any, alpha: Any) -> int:
    w, a = abs(omega), abs(alpha)
    if isinstance(w, np.ndarray):
        w, a = float(np.max(w, initial=0.0)), float(np.max(a, initial=0.0))
    if _RATE_LOW <= w <= _RATE_HIGH and a <= _ACCEL_HIGH:
        return 0
    return _exponent(max(w, math.sqrt(a)), _RATE_LOW, _RATE_HIGH)


def _ldexp(x: Any, exponent: int) -> Any:
    """Return ``x * 2**exponent`` (inf on overflow) for floats, complex numbers and arrays."""
    if isinstance(x, complex):
        return complex(_ldexp(x.real, exponent), _ldexp(x.imag, exponent))
    if isinstance(x, float):
        try:
            return math.ldexp(x, exponent)
        except OverflowError:
            return math.copysign(math.inf, x)
    if np.iscomplexobj(x):
        out = np.empty(np.shape(x), dtype=np.complex128)
        out.real = np.ldexp(x.real, exponent)
        out.imag = np.ldexp(x.imag, exponent)
        return out
    return np.ldexp(x, exponent)


def _finite(x: Any) -> Any:
    if isinstance(x, (float, complex)):
        return cmath.isfinite(x)
    return np.isfinite(x)


def _rescale(solver: _Solver, ctx: _Context, shift: int) -> None:
    """Scale the reported values of a solve in scaled units back to SI; refuse what overflows."""
    s = solver.shift
    linear = (s, s + shift, s + 2 * shift)
    angular = (0, shift, 2 * shift)
    for table, name, path, label, _ in solver.outputs:
        store = getattr(ctx, table)
        x, dx, ddx, ex, edx, eddx = store[name]
        k0, k1, k2 = angular if table == 'links' else linear
        entry = (x if table == 'links' else _ldexp(x, k0), _ldexp(dx, k1), _ldexp(ddx, k2),
                 ex if table == 'links' else _ldexp(ex, k0) + _TINY,
                 _ldexp(edx, k1) + _TINY, _ldexp(eddx, k2) + _TINY)
        store[name] = entry
        if ctx.vector:
            ok = _finite(entry[0])
            for x in entry[1:]:
                ok = ok & _finite(x)
            # A constant (a ground point) is a plain bool here: mask takes arrays.
            ctx.mask(np.asarray(ok), f'{label} (overflow)')
            continue
        for index, quantity in enumerate(_QUANTITIES):
            if not (_finite(entry[index]) and _finite(entry[index + 3])):
                what = 'its error bound' if _finite(entry[index]) else 'it'
                reason = (f'the state overflows: the {quantity} of {path} is beyond the range '
                          f'of doubles (scaled back to SI, {what} exceeds {LARGEST:.3g})')
                raise UntrustedError(label, ctx.shown, reason, f'{path}.{quantity}', math.inf,
                                     LARGEST)
    k = s + shift
    for name, (value, bound) in ctx.rubbing.items():
        value, bound = _ldexp(value, k), _ldexp(bound, k) + _TINY
        ctx.rubbing[name] = (value, bound)
        if ctx.vector:
            ctx.mask(_finite(value) & _finite(bound), f'pin {name} (overflow)')
        elif not (_finite(value) and _finite(bound)):
            reason = (f'the state overflows: the rubbing velocity at pin {name} is beyond the '
                      f'range of doubles (scaled back to SI, it exceeds {LARGEST:.3g})')
            raise UntrustedError(f'pin {name}', ctx.shown, reason, f'rubbing.{name}', math.inf,
                                 LARGEST)


def _scales(size: float, crank_length: float, omega: Any, alpha: Any,
            points: Iterable[tuple[Any, Any]], sliders: Iterable[tuple[Any, Any]],
            links: Iterable[tuple[Any, Any]], vector: bool) -> dict[str, Any]:
    """Return each kind's scale (see :attr:`State.scales`) from the reported values."""
    biggest: Any = np.fmax if vector else max
    w = abs(omega)
    rate = w * w + abs(alpha)
    speed, accel = crank_length * w, crank_length * rate
    turn, turn_accel = w, rate
    for v, a in points:
        if vector:
            speed = biggest(speed, np.hypot(v.real, v.imag))
            accel = biggest(accel, np.hypot(a.real, a.imag))
        else:
            speed = biggest(speed, abs(v))
            accel = biggest(accel, abs(a))
    for v, a in sliders:
        speed = biggest(speed, abs(v))
        accel = biggest(accel, abs(a))
    for v, a in links:
        turn = biggest(turn, abs(v))
        turn_accel = biggest(turn_accel, abs(a))
    return {'position': size, 'angle': 1.0, 'velocity': speed, 'angular velocity': turn,
            'acceleration': accel, 'angular acceleration': turn_accel}


def _context_scales(solver: _Solver, ctx: _Context, omega: Any, alpha: Any) -> dict[str, Any]:
    return _scales(solver.size, solver.crank_length, omega, alpha,
                   [ctx.points[name][1:3] for name in solver.out_points],
                   [ctx.sliders[name][1:3] for name in solver.out_sliders],
                   [ctx.links[name][1:3] for name in solver.out_links], ctx.vector)


def _trusted(solver: _Solver, ctx: _Context, omega: float, alpha: float, tol: float) -> bool:
    """Return True if every reported bound is within ``tol`` of its kind's smallest scale.

    A quick sufficient test for the single-angle path: the scales' floors (the
    mechanism's size, the crank's own rates) are at most the scales, so a pass
    here is a pass of :func:`_refuse`'s exact test; NaN fails.
    """
    w = abs(omega)
    rate = w * w + abs(alpha)
    a = solver.crank_length
    lp, lv, la = tol * solver.size, tol * (a * w), tol * (a * rate)
    points = ctx.points
    for name in solver.out_points:
        e = points[name]
        if not (e[3] <= lp and e[4] <= lv and e[5] <= la):
            return False
    links = ctx.links
    lw, lal = tol * w, tol * rate
    for name in solver.out_links:
        e = links[name]
        if not (e[3] <= tol and e[4] <= lw and e[5] <= lal):
            return False
    sliders = ctx.sliders
    for name in solver.out_sliders:
        e = sliders[name]
        if not (e[3] <= lp and e[4] <= lv and e[5] <= la):
            return False
    if ctx.rubbing:
        return all(bound <= lv for _, bound in ctx.rubbing.values())
    return True


def _refuse(solver: _Solver, ctx: _Context, omega: float, alpha: float, tol: float) -> None:
    """Raise :class:`UntrustedError` for the first reported value whose bound exceeds ``tol``."""
    scales = _context_scales(solver, ctx, omega, alpha)
    for table, name, path, label, kinds in solver.outputs:
        entry = getattr(ctx, table)[name]
        for index, kind in enumerate(kinds):
            bound, scale = entry[3 + index], scales[kind]
            lim = limit(tol, scale)
            if bound <= lim:
                continue
            quantity = _QUANTITIES[index]
            unit = UNITS[kind]
            reason = (f'the {quantity} of {path} cannot be trusted: expected its error bound '
                      f'to be at most {tol:g} x {scale:.3g} {unit} ({SCALE_MEANINGS[kind]}), '
                      f'got {bound:.3g} {unit}')
            key = solver.measure_keys.get(label)
            if label in ctx.notes:
                reason += f'; {ctx.notes[label]}'
            elif key is not None:
                reason += f'; near-singularity measure of {label}: {ctx.measures[key]:.3g}'
            raise UntrustedError(label, ctx.shown, reason, f'{path}.{quantity}', float(bound),
                                 float(lim))
    lim = limit(tol, scales['velocity'])
    for name, (_, bound) in ctx.rubbing.items():
        if not bound <= lim:
            reason = (f'the rubbing velocity at pin {name} cannot be trusted: expected its '
                      f'error bound to be at most {tol:g} x {scales["velocity"]:.3g} m/s '
                      f'({SCALE_MEANINGS["velocity"]}), got {bound:.3g} m/s')
            raise UntrustedError(f'pin {name}', ctx.shown, reason, f'rubbing.{name}',
                                 float(bound), float(lim))


def _judge(solver: _Solver, ctx: _Context, omega: Any, alpha: Any, tol: float,
           shape: tuple[int, ...]) -> None:
    """Mask the angles of a vector solve where a reported bound exceeds ``tol``."""
    w = abs(omega)
    rate = w * w + abs(alpha)
    a = solver.crank_length
    floors = {'position': solver.size, 'angle': 1.0, 'velocity': a * w, 'angular velocity': w,
              'acceleration': a * rate, 'angular acceleration': rate}
    lims = {kind: tol * floor for kind, floor in floors.items()}
    failed = np.logical_not(ctx.valid)  # already refused: not judged again
    if all(bool(((entry[3] <= lims[kinds[0]]) & (entry[4] <= lims[kinds[1]])
                 & (entry[5] <= lims[kinds[2]]) | failed).all())
           for table, name, _, _, kinds in solver.outputs
           for entry in (getattr(ctx, table)[name],)) and all(
               bool(((bound <= lims['velocity']) | failed).all())
               for _, bound in ctx.rubbing.values()):
        return  # within the floors of the scales (as _trusted): no norms needed
    scales = _context_scales(solver, ctx, omega, alpha)
    lims = {kind: limit(tol, scale) for kind, scale in scales.items()}
    for table, name, _, label, kinds in solver.outputs:
        entry = getattr(ctx, table)[name]
        ok = ((entry[3] <= lims[kinds[0]]) & (entry[4] <= lims[kinds[1]])
              & (entry[5] <= lims[kinds[2]]))
        ctx.mask(np.broadcast_to(ok, shape), f'{label} (untrusted)')
    for name, (_, bound) in ctx.rubbing.items():
        ctx.mask(np.broadcast_to(bound <= lims['velocity'], shape), f'pin {name} (untrusted)')


def _angle(e: Any, vector: bool) -> Any:
    """Angle of unit complex ``e``, wrapped to (-pi, pi]."""
    if vector:
        theta = np.arctan2(e.imag, e.real)
        theta[theta == -np.pi] = np.pi
        return theta
    return _wrapped_angle(e)


def _wrapped_angle(e: complex) -> float:
    """Angle of unit complex ``e`` (one value), wrapped to (-pi, pi]."""
    theta = math.atan2(e.imag, e.real)
    return math.pi if theta == -math.pi else theta


def solve(scene: Scene, angle: npt.ArrayLike, speed: npt.ArrayLike | None = None,
          accel: npt.ArrayLike | None = None, *, turns: npt.ArrayLike = 0,
          max_error: float = MAX_ERROR) -> State:
    """Solve ``scene`` for position, velocity and acceleration at crank ``angle``.

    Every value comes with an absolute error bound (``State.error_bound``,
    :mod:`mech_kinematics.bounds`); a state in which a reported value's bound
    exceeds ``max_error`` times its kind's scale (``State.scales``) is refused.

    Parameters
    ----------
    scene : Scene
        The mechanism.
    angle : float or array_like, shape (n,)
        Crank angle(s), rad, CCW from +x, counted from the start: ``2.5 pi``
        is a quarter turn into the crank's second turn. Only an intermittent
        (Geneva) drive tells the turns apart (its wheel indexes once a turn).
    speed : float or array_like, optional
        Crank angular velocity, rad/s, + CCW. Defaults to the scene's.
    accel : float or array_like, optional
        Crank angular acceleration, rad/s^2, + CCW. Defaults to the scene's.
    turns : int or array_like of int, keyword-only
        Whole crank turns to add to ``angle``: the crank angle counted from
        the start is ``angle + 2 pi turns``, the sum never formed in floating
        point, so a crank kept as whole turns plus an angle within one turn
        (as the node keeps it) loses nothing however many turns it has made.
        Default 0.
    max_error : float, optional
        Tolerance: the largest error bound accepted, relative to its kind's
        scale. Default 1e-6; ``math.inf`` accepts every finite answer. Whatever
        it is, a dyad within rounding of an assembly limit is refused.

    Returns
    -------
    State
        Floats for a scalar ``angle``; arrays (with ``valid`` as a mask) for an
        array.

    Raises
    ------
    AssemblyError
        For a scalar ``angle`` at which a dyad cannot close or is singular;
        its subclass :class:`UntrustedError` where the answer cannot be
        trusted (a bound above the tolerance, a dyad within rounding of an
        assembly limit, a value beyond the range of doubles).
    """
    theta: Any
    omega: Any
    alpha: Any
    solver = scene._solver
    speed = scene.input.speed if speed is None else speed
    accel = scene.input.accel if accel is None else accel
    if not (isinstance(max_error, (float, int)) and max_error > 0.0):
        msg = f'Expected `max_error` to be a positive number, got {max_error!r}'
        raise ValueError(msg)
    tol = float(max_error)
    whole: Any = turns
    if whole.__class__ is not int:  # an int is the usual case, decided without a call
        whole = _turns(whole)
    if _is_scalar(angle) and _is_scalar(speed) and _is_scalar(accel) and (
            whole.__class__ is int or _is_scalar(whole)):
        theta, omega, alpha = float(angle), float(speed), float(accel)  # type: ignore[arg-type]
        if not (math.isfinite(theta) and math.isfinite(omega) and math.isfinite(alpha)):
            msg = (f'Expected `angle`, `speed` and `accel` to be finite, got {theta!r}, '
                   f'{omega!r}, {alpha!r}')
            raise ValueError(msg)
        whole = int(whole)
        ctx = _execute(solver, theta, omega, alpha, whole)
        if not _trusted(solver, ctx, omega, alpha, tol):
            _refuse(solver, ctx, omega, alpha, tol)
        valid: Any = True
    else:
        theta, omega, alpha = (np.asarray(x, dtype=np.float64) for x in (angle, speed, accel))
        shape = np.broadcast_shapes(theta.shape, omega.shape, alpha.shape, np.shape(whole))
        if len(shape) != 1:
            msg = f'Expected `angle` to be a float or a 1-D array, got shape {shape}'
            raise ValueError(msg)
        if not (np.isfinite(theta).all() and np.isfinite(omega).all()
                and np.isfinite(alpha).all()):
            msg = 'Expected `angle`, `speed` and `accel` to be finite'
            raise ValueError(msg)
        theta = np.broadcast_to(theta, shape)
        whole = np.broadcast_to(np.asarray(whole, dtype=np.int64), shape)
        with np.errstate(all='ignore'):
            # A constant speed or acceleration stays a scalar through the steps.
            ctx = _execute(solver, theta, omega, alpha, whole)
            _judge(solver, ctx, omega, alpha, tol, shape)
        omega, alpha = np.broadcast_to(omega, shape), np.broadcast_to(alpha, shape)
        valid = np.broadcast_to(np.asarray(ctx.valid, dtype=bool), shape).copy()
    _warn_near_singular(ctx)
    return _state(scene, solver, ctx, theta, omega, alpha, valid, whole)


def _turns(turns: Any) -> Any:
    """Return ``turns`` as an int or an int64 array, or raise a ValueError saying why not."""
    if isinstance(turns, (int, np.integer)) and not isinstance(turns, (bool, np.bool_)):
        return int(turns)
    try:
        array = np.asarray(turns)
    except (TypeError, ValueError, OverflowError):
        array = np.asarray(None)
    if array.dtype.kind in 'iu':
        if array.dtype.kind == 'u' and array.size and int(array.max()) >= 2 ** 63:
            array = np.asarray(None)
        else:
            return array.astype(np.int64) if array.ndim else int(array)
    msg = (f'Expected `turns` to be a whole number of crank turns (an int, or an array of '
           f'ints within 2**63 for the array path), got {turns!r}')
    raise ValueError(msg)


def _is_scalar(x: Any) -> bool:
    # The cheap test first: the node's tick passes plain floats.
    return isinstance(x, (float, int)) or np.ndim(x) == 0


def _warn_near_singular(ctx: _Context) -> None:
    for key, measure in ctx.measures.items():
        low = measure < NEAR_SINGULAR
        if low if not ctx.vector else (low & ctx.valid).any():
            msg = (f'dyad at "{key}" is near-singular (measure below {NEAR_SINGULAR:g}): '
                   f'its velocities and accelerations lose accuracy')
            warnings.warn(msg, NearSingularWarning, stacklevel=3)


def _state(scene: Scene, solver: _Solver, ctx: _Context, theta: Any, omega: Any, alpha: Any,
           valid: Any, turns: Any) -> State:
    vector = ctx.vector
    plan = solver.plan
    joints = {}
    for name, kind in plan.joint_types.items():
        if kind == 'revolute':
            e, w, al = ctx.links[name][:3]
            joints[name] = JointMotion(kind, _angle(e, vector), w, al)
        else:
            joints[name] = JointMotion(kind, *ctx.sliders[name][:3])
    table = ctx.points
    points = {name: table[name][:3] for name in plan.output_points}
    measures = ctx.measures
    bound = ErrorBound(_table_bounds, (plan, ctx), solver.size, solver.crank_length)
    if vector:
        shape = theta.shape
        bad = None if valid.all() else ~valid
        inputs = (id(theta), id(omega), id(alpha))

        def finish(x: Any) -> Any:
            # A constant (a ground point, a constant crank speed) becomes a
            # read-only broadcast view; a copy only where NaN must go in, and
            # never the caller's own input arrays.
            if id(x) in inputs:
                x = np.array(x)
            elif np.shape(x) != shape:
                x = np.broadcast_to(x, shape)
                if bad is None:
                    return x
                x = np.array(x)
            if bad is not None:
                x[bad] = np.nan
            return x

        for name, joint in joints.items():
            joints[name] = JointMotion(joint.type, finish(joint.position),
                                       finish(joint.velocity), finish(joint.acceleration))
        points = {name: (finish(p), finish(v), finish(a)) for name, (p, v, a) in points.items()}
        measures = {key: finish(m) for key, m in measures.items()}
        joint_bounds, point_bounds = _table_bounds(plan, ctx)
        bound = ErrorBound(_given, ({name: (finish(a), finish(b), finish(c))
                                     for name, (a, b, c) in joint_bounds.items()},
                                    {name: (finish(a), finish(b), finish(c))
                                     for name, (a, b, c) in point_bounds.items()}),
                           solver.size, solver.crank_length)
        rubbing = {name: finish(value) for name, (value, _) in ctx.rubbing.items()}
        bound.rubbing = {name: finish(b) for name, (_, b) in ctx.rubbing.items()}
        intermittent = {name: _engagement(step, ctx, omega, finish)
                        for name, step in solver.levers.items()}
    else:
        rubbing = intermittent = {}
        if ctx.rubbing:
            rubbing = {name: value for name, (value, _) in ctx.rubbing.items()}
            bound.rubbing = {name: b for name, (_, b) in ctx.rubbing.items()}
        if solver.levers:
            intermittent = {name: _engagement(step, ctx, omega, None)
                            for name, step in solver.levers.items()}
    return _new_state(scene.name, theta, omega, alpha, joints, points, valid, dict(measures),
                      dict(ctx.failures), bound, turns, rubbing, intermittent)


def _engagement(step: _IndexStep, ctx: _Context, omega: Any, finish: Any) -> Engagement:
    """Return where an intermittent lever is in its cycle (see :class:`Engagement`)."""
    engaged, window = ctx.engagement[step.link]
    centre = step.phase0 + (window.astype(np.float64) if ctx.vector else float(window)) * math.tau
    entry, exit_ = centre - step.half, centre + step.half
    jump = omega * omega * step.tan
    zero = 0.0 * jump
    if finish is not None:
        entry, exit_, jump, zero = finish(entry), finish(exit_), finish(jump), finish(zero)
        engaged = np.broadcast_to(engaged, np.shape(entry))
    # The fields go straight in, as in _new_state: a frozen dataclass's __init__ costs 1 us.
    record = object.__new__(Engagement)
    record.__dict__.update(engaged=engaged, window=window, entry=entry, exit=exit_,
                           entry_acceleration=(zero, -jump), exit_acceleration=(jump, zero))
    return record


def _new_state(scene: str, angle: Any, speed: Any, accel: Any, joints: dict[str, JointMotion],
               points: dict[str, Any], valid: Any, singularity: dict[str, Any],
               failures: dict[str, Any], error_bound: ErrorBound, turns: Any,
               rubbing: dict[str, Any], intermittent: dict[str, Engagement]) -> State:
    """Return ``State(...)`` of these fields, built without the dataclass's ``__init__``.

    A frozen dataclass's ``__init__`` sets each field through
    ``object.__setattr__``: about 1 us of a 7 us single-angle solve. The fields
    go straight into the new instance's ``__dict__`` instead (there is no
    ``__post_init__`` to run); ``test_linkage_bounds`` checks the result equals
    the dataclass's own construction.
    """
    state = object.__new__(State)
    fields = state.__dict__
    fields['scene'], fields['angle'], fields['speed'], fields['accel'] = scene, angle, speed, accel
    fields['joints'], fields['complex_points'], fields['valid'] = joints, points, valid
    fields['singularity'], fields['failures'] = singularity, failures
    fields['error_bound'], fields['turns'] = error_bound, turns
    fields['rubbing'], fields['intermittent'] = rubbing, intermittent
    return state


def _table_bounds(plan: _Plan, ctx: _Context) -> tuple[Table, Table]:
    """Return the reported joints' and points' bounds from a solve's context."""
    joints = {name: (ctx.links if kind == 'revolute' else ctx.sliders)[name][3:]
              for name, kind in plan.joint_types.items()}
    table = ctx.points
    return joints, {name: table[name][3:] for name in plan.output_points}


def _given(joints: Table, points: Table) -> tuple[Table, Table]:
    return joints, points
