# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The RRP dyad: a link from a known point ending in a slider on a fixed guide."""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, replace
from fractions import Fraction
import math
from typing import Any

import numpy as np

from .base import Item, Names, Placing, Reading, Step
from .context import _Context, _cross, _dot, _sum_root, _U2, _U3, _U5, _U7, SINGULAR
from .graph import (Body, Fragment, Frame, Line, Motion, pin, PRISMATIC, REVOLUTE, Role, slide,
                    THE_GROUND)
from .model import _check_finite, _check_name, _g, Branch, Link, SceneUnits, Where
from ..bounds import ROUNDING_MARGIN, U


@dataclass(frozen=True)
class RRP(Item):
    """A link ending in a slider ``point`` on a fixed straight guide."""

    kind = 'RRP'

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

    @classmethod
    def from_scene(cls, read: Reading, raw: Any, where: str) -> RRP:
        """Return the RRP at ``where``: ``point``, ``link``, ``guide``, ``slider``, ``branch``."""
        read.check_keys(raw, {'type', 'point', 'link', 'guide', 'slider', 'branch'}, where)
        link = read.link(read.get(raw, 'link', where), f'{where}.link')
        guide = read.get(raw, 'guide', where)
        if isinstance(guide, dict):
            read.check_keys(guide, {'through', 'angle'}, f'{where}.guide')
        built: RRP = read.build(
            where, {'through': 'guide.through', 'guide_angle': 'guide.angle'}, cls,
            point=read.name(raw, 'point', where),
            link=link, through=read.name(guide, 'through', f'{where}.guide'),
            guide_angle=read.angle(guide, 'angle', f'{where}.guide', 0.0),
            slider=read.name(raw, 'slider', where), branch=read.branch(raw, where))
        return built

    @staticmethod
    def fact_texts() -> dict[str, Callable[[dict[str, Any], SceneUnits], str]]:
        """Return the text of a guide out of reach."""
        return {'reach': _reach_text}

    @property
    def key(self) -> str:
        """Return the dyad's new point (the slider's pin)."""
        return self.point

    def defined(self) -> Iterator[tuple[str, str, Where]]:
        """Yield its new point, its link and its slider."""
        yield self.point, 'point', (self, 'point')
        yield self.link.name, 'link', (self.link, 'name')
        yield self.slider, 'slider', (self, 'slider')

    def prerequisites(self, names: Names) -> set[str]:
        """Check the guide's ground point; return the start of its link."""
        names.ground(self.through, f'the guide point of RRP "{self.point}"', (self, 'through'))
        return {names.point(self.link.start, f'the start of link "{self.link.name}"',
                            (self.link, 'start'))}

    def place(self, plan: Placing) -> Step:
        """Return its step; its link carries its start and the new point."""
        plan.local[self.link.name] = {self.link.start: 0j, self.point: complex(self.link.length)}
        return _RRPStep(self, plan.ground[self.through])

    def lengths(self) -> tuple[float, ...]:
        """Return its link's length."""
        return (self.link.length,)

    def scaled(self, scale: Callable[[float], float]) -> RRP:
        """Return it with its link's length scaled."""
        return replace(self, link=replace(self.link, length=scale(self.link.length)))

    def fragment(self) -> Fragment:
        """Return its part of the graph: its link, pinned to a block on the fixed guide."""
        link = self.link
        block = Frame(self.point, None, self.guide_angle)
        return Fragment(
            self.point,
            (Body(link.name, Role.LINK, (link.start, self.point), Frame(link.start, link.name),
                  length=link.length),
             Body(self.slider, Role.SLIDER, (self.point,), block, guide=THE_GROUND)),
            (pin(link.name, link.start), pin(self.slider, self.point, on=link.name),
             slide(self.slider, self.point, self.slider,
                   Line(self.through, None, self.guide_angle), on=THE_GROUND)),
            {link.name: REVOLUTE, self.slider: PRISMATIC}, (Motion(link.name, link.start,
                                                                   self.point),))

    def toggle(self) -> tuple[str, str, tuple[str, ...]] | None:
        """Return its measure (the sine of the rod's angle to the guide normal), label, link."""
        return self.point, f'RRP {self.point}', (self.link.name,)


def _reach_text(facts: dict[str, Any], units: SceneUnits) -> str:
    """Return why an RRP's link cannot reach its guide, in the scene's units."""
    text = units.length_text
    links, lengths, points = facts['links'], facts['lengths'], facts['points']
    distance = facts['distance']
    return (f'link {links[0]} ({text(lengths[0], distance)}) cannot reach the guide through '
            f'{points[1]} at {units.angle_text(facts["guide_angle"])} from {points[0]} '
            f'({text(distance, lengths[0])} from the guide)')


class _RRPStep(Step):

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
        self.defines = (dyad.point, dyad.link.name, dyad.slider)
        self.new_points = (dyad.point,)
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

    def margins(self, points: Mapping[str, tuple[Any, ...]]) -> tuple[tuple[Any, Any], ...]:
        """Return the reach margins ``l - o`` and ``l + o`` and their rates.

        ``o`` is the signed distance of the link's start from the guide.
        """
        q, vq = points[self.start][:2]
        offset = _cross(self.u, q - self.through)
        rate = _cross(self.u, vq)
        return ((self.length - offset, -rate), (self.length + offset, rate))

    def crank_margins(self, tip: str, center: complex, radius: float,
                      ground: Mapping[str, complex]
                      ) -> Callable[[Any], tuple[tuple[Any, Any], ...]] | None:
        """Return its reach margins in closed form when its link starts at the crank's tip.

        The tip's signed distance from the guide is ``o = c + r k sin(psi)``,
        ``psi = theta - gamma``, with ``c`` that of the crank's pivot and
        ``k``, ``gamma`` the length and angle of the (rounded) guide direction.
        With ``f = psi / 2 - pi / 4``, ``l - o = (l - c - r k) + 2 r k sin^2 f
        = (l - c + r k) - 2 r k cos^2 f`` and ``l + o = (l + c + r k) - 2 r k
        sin^2 f = (l + c - r k) + 2 r k cos^2 f``: each is taken in the form
        whose varying term is the smaller, its constant formed exactly from the
        doubles, so no cancellation where the guide is barely in (or out of)
        reach.
        """
        if self.start != tip:
            return None
        ux, uy = Fraction(self.u.real), Fraction(self.u.imag)
        offset = (ux * (Fraction(center.imag) - Fraction(self.through.imag))
                  - uy * (Fraction(center.real) - Fraction(self.through.real)))
        r = Fraction(radius)
        rk2 = r * r * (ux * ux + uy * uy)  # (r k)^2, exact
        rk = math.sqrt(rk2)
        length = Fraction(self.length)
        # l - o and l + o near sin(psi) = 1 (from sin^2) and near -1 (from cos^2).
        below_up, below_down = -_sum_root(offset - length, rk2), _sum_root(length - offset, rk2)
        above_up, above_down = _sum_root(length + offset, rk2), -_sum_root(-(length + offset), rk2)
        gamma = math.atan2(self.u.imag, self.u.real)

        def margins(theta: Any) -> tuple[tuple[Any, Any], ...]:
            half = 0.5 * (theta - gamma) - 0.25 * math.pi
            s, c = np.sin(half), np.cos(half)
            s2, c2 = 2.0 * rk * s * s, 2.0 * rk * c * c
            up = s * s < 0.5
            rate = rk * np.cos(theta - gamma)  # the rate of o
            return ((np.where(up, below_up + s2, below_down - c2), -rate),
                    (np.where(up, above_up - s2, above_down + c2), rate))

        return margins

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
