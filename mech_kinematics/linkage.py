# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Analytic position, velocity and acceleration of planar linkages.

A mechanism is a driving crank followed by dyads (RRR, RRP, RPR) and points
carried rigidly by links, solved one after another in closed form: no
iteration anywhere. Points are complex numbers ``x + iy`` internally, so a
rigid rotation is a product and every formula is the same for one crank angle
(Python ``complex`` and :mod:`math`, cheap enough for a node's tick) and for
an array of crank angles (NumPy, for cycles and plots).

Everything here is SI: metres, radians, seconds. Angles are counter-clockwise
from +x; angular velocities and accelerations are positive counter-clockwise.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from enum import IntEnum
from functools import cached_property
import heapq
import math
import re
from typing import Any
import warnings

import numpy as np
import numpy.typing as npt

from .errors import AssemblyError, NearSingularWarning, SceneError

__all__ = [
    'Branch', 'CarriedPoint', 'Crank', 'JointMotion', 'Link', 'NEAR_SINGULAR', 'PointState',
    'RPR', 'RRP', 'RRR', 'SINGULAR', 'Scene', 'State', 'solve',
]

#: A dyad whose near-singularity measure falls below this is flagged as
#: near-singular (:class:`NearSingularWarning`); its velocities lose up to about
#: ``2 * -log10(measure)`` digits (near a toggle the condition number grows as
#: ``1 / measure**2``) and its accelerations up to three times ``-log10(measure)``.
NEAR_SINGULAR = 1e-3
#: At or below this measure a dyad is treated as singular and not solved.
SINGULAR = 1e-12

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
        msg = f'Expected {what} to be a positive length, got {value!r} m'
        raise SceneError(msg, where)


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
    """A slotted ``link`` turning about ground point ``center``, through pin ``through``."""

    link: str
    center: str
    through: str
    slider: str

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.link, 'an RPR link', (self, 'link'))
        _check_name(self.center, f'the center of RPR "{self.link}"', (self, 'center'))
        _check_name(self.through, f'the pin of RPR "{self.link}"', (self, 'through'))
        _check_name(self.slider, f'the slider of RPR "{self.link}"', (self, 'slider'))


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


class _Context:
    """Values known so far in one solve; complex numbers or complex arrays."""

    __slots__ = ('angle', 'vector', 'points', 'links', 'sliders', 'measures', 'valid',
                 'failures')

    def __init__(self, angle: Any, vector: bool) -> None:
        self.angle = angle
        self.vector = vector
        self.points: dict[str, tuple[Any, Any, Any]] = {}
        self.links: dict[str, tuple[Any, Any, Any]] = {}
        self.sliders: dict[str, tuple[Any, Any, Any]] = {}
        self.measures: dict[str, Any] = {}
        self.valid: Any = True
        self.failures: dict[str, Any] = {}

    def check(self, ok: Any, label: str, reason: Any) -> None:
        """Stop a scalar solve where ``ok`` fails; mask the entries of a vector solve."""
        if not self.vector:
            if not ok:
                raise AssemblyError(label, self.angle, reason())
            return
        if not ok.all():
            failed = ~ok & self.valid
            self.valid = self.valid & ok
            if failed.any():
                previous = self.failures.get(label)
                self.failures[label] = failed if previous is None else previous | failed


def _dot(a: Any, b: Any) -> Any:
    return a.real * b.real + a.imag * b.imag


def _cross(a: Any, b: Any) -> Any:
    return a.real * b.imag - a.imag * b.real


class _CrankStep:
    def __init__(self, crank: Crank, center: complex) -> None:
        self.link = crank.link
        self.point = crank.point
        self.center = center
        self.length = crank.length
        self.uses: tuple[str, ...] = (crank.center,)

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
        ctx.points[self.point] = (self.center + r, 1j * omega * r, acceleration)
        ctx.links[self.link] = (e, omega, alpha)


# Every complex product below has one real factor or a purely imaginary one
# (``1j * x``): such products round the same way in Python's complex type and
# in NumPy's (whose general complex product may use fused multiply-adds), so
# the single-angle and array paths give the same bits. Norms use hypot for the
# same reason.


class _RRRStep:
    def __init__(self, dyad: RRR) -> None:
        first, second = dyad.links
        self.label = f'RRR {dyad.point}'
        self.key = dyad.point
        self.point = dyad.point
        self.start1, self.start2 = first.start, second.start
        self.link1, self.link2 = first.name, second.name
        self.l1, self.l2 = first.length, second.length
        self.branch = int(dyad.branch)
        self.uses = (first.start, second.start)

    def run(self, ctx: _Context) -> None:
        l1, l2 = self.l1, self.l2
        p1, v1, a1 = ctx.points[self.start1]
        p2, v2, a2 = ctx.points[self.start2]
        d = p2 - p1
        dist = np.hypot(d.real, d.imag) if ctx.vector else abs(d)
        lsum = l1 + l2
        ldiff = l1 - l2
        # 4 * dist^2 * h^2 as a product of factors: no cancellation near toggle.
        k = (lsum + dist) * (lsum - dist) * (dist + ldiff) * (dist - ldiff)
        if not ctx.vector:  # a vector solve catches k <= 0 in the measure's check below
            ctx.check(k > 0.0, self.label, lambda: (
                f'the circles about {self.start1} (radius {l1:.17g} m) and {self.start2} '
                f'(radius {l2:.17g} m) do not meet: expected |{ldiff:.17g}| < |{self.start1}'
                f'{self.start2}| < {lsum:.17g} m, got |{self.start1}{self.start2}| = '
                f'{dist:.17g} m'))
        root = np.sqrt(k) if ctx.vector else math.sqrt(k)
        # sin of the angle between the two links (the transmission angle).
        measure = root / (2.0 * l1 * l2)
        ctx.check(measure > SINGULAR, self.label, lambda: (
            f'links {self.link1} and {self.link2} are in line (singular): expected the sine '
            f'of the angle between them > {SINGULAR:g}, got {measure:.3g}'))
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
        da = a2 - a1 + w1 * w1 * r1 - w2 * w2 * r2
        al1 = _dot(da, r2) * inv
        al2 = _dot(da, r1) * inv
        ctx.points[self.point] = (p1 + r1, v1 + 1j * w1 * r1, a1 + 1j * al1 * r1 - w1 * w1 * r1)
        ctx.links[self.link1] = (r1 * (1.0 / l1), w1, al1)
        ctx.links[self.link2] = (r2 * (1.0 / l2), w2, al2)


class _RRPStep:
    def __init__(self, dyad: RRP, through: complex) -> None:
        self.label = f'RRP {dyad.point}'
        self.key = dyad.point
        self.point = dyad.point
        self.start = dyad.link.start
        self.link = dyad.link.name
        self.length = dyad.link.length
        self.slider = dyad.slider
        self.through = through
        self.u = complex(math.cos(dyad.guide_angle), math.sin(dyad.guide_angle))
        self.normal = 1j * self.u
        self.branch = int(dyad.branch)
        self.uses = (dyad.link.start,)

    def run(self, ctx: _Context) -> None:
        length, u = self.length, self.u
        q, vq, aq = ctx.points[self.start]
        w = q - self.through
        along = _dot(w, u)
        offset = _cross(u, w)  # signed distance of the start point from the guide
        k = (length - offset) * (length + offset)
        if not ctx.vector:  # a vector solve catches k <= 0 in the measure's check below
            ctx.check(k > 0.0, self.label, lambda: (
                f'the guide is out of reach of link {self.link}: expected the distance of '
                f'{self.start} from the guide < {length:.17g} m, got {abs(offset):.17g} m'))
        root = np.sqrt(k) if ctx.vector else math.sqrt(k)
        # sin of the angle between the rod and the guide's normal.
        measure = root / length
        ctx.check(measure > SINGULAR, self.label, lambda: (
            f'link {self.link} is perpendicular to the guide (singular): expected the sine of '
            f'its angle to the guide normal > {SINGULAR:g}, got {measure:.3g}'))
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
        ctx.points[self.point] = (self.through + s * u, sd * u, sdd * u)
        ctx.links[self.link] = (r * (1.0 / length), omega, alpha)
        ctx.sliders[self.slider] = (s, sd, sdd)


class _RPRStep:
    def __init__(self, dyad: RPR, center: complex, size: float) -> None:
        self.label = f'RPR {dyad.link}'
        self.key = dyad.link
        self.link = dyad.link
        self.through = dyad.through
        self.slider = dyad.slider
        self.center = center
        self.size = size
        self.uses = (dyad.through,)

    def run(self, ctx: _Context) -> None:
        b, vb, ab = ctx.points[self.through]
        d = b - self.center
        s = np.hypot(d.real, d.imag) if ctx.vector else abs(d)
        # the slider coordinate relative to the mechanism's size.
        measure = s / self.size
        ctx.check(measure > SINGULAR, self.label, lambda: (
            f'the pin {self.through} is on the pivot (singular): expected its distance '
            f'from the pivot > {SINGULAR * self.size:.3g} m, got {s:.3g} m'))
        ctx.measures[self.key] = measure
        e = d * (1.0 / s)
        sd = _dot(vb, e)
        omega = _cross(e, vb) / s
        sdd = _dot(ab, e) + s * omega * omega
        # the Coriolis component 2 * omega * sd sits in the transverse balance.
        alpha = (_cross(e, ab) - 2.0 * sd * omega) / s
        ctx.links[self.link] = (e, omega, alpha)
        ctx.sliders[self.slider] = (s, sd, sdd)


class _CarryStep:
    def __init__(self, point: CarriedPoint, base: str, local: complex) -> None:
        self.point = point.name
        self.link = point.link
        self.base = base  # the origin of the link's frame
        self.along, self.across = local.real, local.imag
        self.uses = (base,)

    def run(self, ctx: _Context) -> None:
        e, omega, alpha = ctx.links[self.link]
        p, v, a = ctx.points[self.base]
        r = e * self.along
        if self.across:
            r = r + 1j * e * self.across
        ctx.points[self.point] = (p + r, v + 1j * omega * r,
                                  a + 1j * alpha * r - omega * omega * r)


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
            steps.append(_RPRStep(item, ground[item.center], size))
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

    # Keep only the steps that the outputs depend on.
    needed: set[int] = set()
    todo = [produces[name] for name in (*out_joints, *out_points) if name in produces]
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
                 {name: joint_types[name] for name in out_joints}, out_joints, out_points)


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
    """

    name: str
    ground: Mapping[str, tuple[float, float]]
    input: Crank
    dyads: tuple[Dyad, ...] = ()
    points: tuple[CarriedPoint, ...] = ()
    outputs_joints: tuple[str, ...] | None = None
    outputs_points: tuple[str, ...] | None = None
    description: str = ''
    _plan: _Plan = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.name, 'the scene name', (self, 'name'))
        object.__setattr__(self, 'dyads', tuple(self.dyads))
        object.__setattr__(self, 'points', tuple(self.points))
        full = _compile(self, None, None)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter('ignore', NearSingularWarning)
                _run(full, self.input.angle, self.input.speed, self.input.accel)
        except AssemblyError as error:
            msg = (f'Expected the mechanism to assemble at the initial crank angle '
                   f'{math.degrees(self.input.angle):.6g} deg, got {error.dyad}: {error.reason}')
            raise SceneError(msg, (self.input, 'angle')) from None
        if self.outputs_joints is None and self.outputs_points is None:
            plan = full
        else:
            plan = _compile(self, self.outputs_joints, self.outputs_points)
        object.__setattr__(self, '_plan', plan)

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
        For arrays: per dyad label, the angles at which it could not be solved.
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

    @cached_property
    def points(self) -> dict[str, PointState]:
        """Every reported point as 2-D vectors in the ground frame."""
        return {name: PointState(_xy(p), _xy(v), _xy(a))
                for name, (p, v, a) in self.complex_points.items()}

    def as_dict(self) -> dict[str, Any]:
        """Return the structure the ``solve`` command prints (floats or arrays)."""
        vector = not isinstance(self.valid, bool)

        def value(x: Any) -> Any:
            return x if vector else float(x)

        def pair(x: npt.NDArray[np.float64]) -> Any:
            return x if vector else [float(x[0]), float(x[1])]

        return {
            'scene': self.scene,
            'input': {'angle': value(self.angle), 'speed': value(self.speed),
                      'accel': value(self.accel)},
            'joints': {name: {'type': j.type, 'position': value(j.position),
                              'velocity': value(j.velocity),
                              'acceleration': value(j.acceleration)}
                       for name, j in self.joints.items()},
            'points': {name: {'position': pair(p.position), 'velocity': pair(p.velocity),
                              'acceleration': pair(p.acceleration)}
                       for name, p in self.points.items()},
        }


def _run(plan: _Plan, angle: Any, speed: Any, accel: Any) -> _Context:
    """Run every step of ``plan``; the caller chose scalar or vector inputs."""
    ctx = _Context(angle, not isinstance(angle, float))
    # Ground points stay complex scalars in both paths: NumPy broadcasts them.
    for name, position in plan.ground.items():
        ctx.points[name] = (position, 0j, 0j)
    plan.crank.run(ctx, angle, speed, accel)
    for step in plan.steps:
        step.run(ctx)
    return ctx


def _angle(e: Any, vector: bool) -> Any:
    """Angle of unit complex ``e``, wrapped to (-pi, pi]."""
    if vector:
        theta = np.arctan2(e.imag, e.real)
        theta[theta == -np.pi] = np.pi
        return theta
    theta = math.atan2(e.imag, e.real)
    return math.pi if theta == -math.pi else theta


def solve(scene: Scene, angle: npt.ArrayLike, speed: npt.ArrayLike | None = None,
          accel: npt.ArrayLike | None = None) -> State:
    """Solve ``scene`` for position, velocity and acceleration at crank ``angle``.

    Parameters
    ----------
    scene : Scene
        The mechanism.
    angle : float or array_like, shape (n,)
        Crank angle(s), rad, CCW from +x.
    speed : float or array_like, optional
        Crank angular velocity, rad/s, + CCW. Defaults to the scene's.
    accel : float or array_like, optional
        Crank angular acceleration, rad/s^2, + CCW. Defaults to the scene's.

    Returns
    -------
    State
        Floats for a scalar ``angle``; arrays (with ``valid`` as a mask) for an
        array.

    Raises
    ------
    AssemblyError
        For a scalar ``angle`` at which a dyad cannot close or is singular.
    """
    theta: Any
    omega: Any
    alpha: Any
    plan = scene._plan
    speed = scene.input.speed if speed is None else speed
    accel = scene.input.accel if accel is None else accel
    if _is_scalar(angle) and _is_scalar(speed) and _is_scalar(accel):
        theta, omega, alpha = float(angle), float(speed), float(accel)  # type: ignore[arg-type]
        if not (math.isfinite(theta) and math.isfinite(omega) and math.isfinite(alpha)):
            msg = (f'Expected `angle`, `speed` and `accel` to be finite, got {theta!r}, '
                   f'{omega!r}, {alpha!r}')
            raise ValueError(msg)
        ctx = _run(plan, theta, omega, alpha)
        valid: Any = True
    else:
        theta, omega, alpha = (np.asarray(x, dtype=np.float64) for x in (angle, speed, accel))
        shape = np.broadcast_shapes(theta.shape, omega.shape, alpha.shape)
        if len(shape) != 1:
            msg = f'Expected `angle` to be a float or a 1-D array, got shape {shape}'
            raise ValueError(msg)
        if not (np.isfinite(theta).all() and np.isfinite(omega).all()
                and np.isfinite(alpha).all()):
            msg = 'Expected `angle`, `speed` and `accel` to be finite'
            raise ValueError(msg)
        theta = np.broadcast_to(theta, shape)
        with np.errstate(all='ignore'):
            # A constant speed or acceleration stays a scalar through the steps.
            ctx = _run(plan, theta, omega, alpha)
        omega, alpha = np.broadcast_to(omega, shape), np.broadcast_to(alpha, shape)
        valid = np.broadcast_to(np.asarray(ctx.valid, dtype=bool), shape).copy()
    _warn_near_singular(ctx)
    return _state(scene, plan, ctx, theta, omega, alpha, valid)


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


def _state(scene: Scene, plan: _Plan, ctx: _Context, theta: Any, omega: Any, alpha: Any,
           valid: Any) -> State:
    vector = ctx.vector
    joints = {}
    for name, kind in plan.joint_types.items():
        if kind == 'revolute':
            e, w, al = ctx.links[name]
            joints[name] = JointMotion(kind, _angle(e, vector), w, al)
        else:
            joints[name] = JointMotion(kind, *ctx.sliders[name])
    points = {name: ctx.points[name] for name in plan.output_points}
    measures = ctx.measures
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
    return State(scene.name, theta, omega, alpha, joints, points, valid, dict(measures),
                 dict(ctx.failures))
