# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The RRR dyad: two links from known points meeting at a new pin (one module per kind)."""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, replace
from fractions import Fraction
import math
from typing import Any

import numpy as np

from .base import Item, Names, Placing, Reading, Step
from .context import _Context, _dot, _sum_root, _U16, _U2, _U3, _U4, _U7, SINGULAR
from .graph import Body, Fragment, Frame, Line, Motion, pin, REVOLUTE, Role, slide
from .model import _check_name, _g, Branch, Link, SceneUnits, Where
from ..bounds import ROUNDING_MARGIN, U
from ..errors import SceneError


@dataclass(frozen=True)
class RRR(Item):
    """Two links meeting at a new pin ``point``."""

    kind = 'RRR'

    point: str
    links: tuple[Link, Link]
    branch: Branch = Branch.PLUS
    #: Per link, the actuator whose length it has (``None``: its fixed ``length``). An
    #: actuated link's ``length`` is its nominal length (the actuator's at time zero), which
    #: counts in the mechanism's size only.
    actuators: tuple[str | None, str | None] = (None, None)

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.point, 'an RRR point', (self, 'point'))
        count = len(self.links)  # anything may be passed at run time
        if count != 2:
            msg = f'Expected RRR "{self.point}" to have 2 links, got {count}'
            raise SceneError(msg, (self, 'links'))
        object.__setattr__(self, 'branch', Branch(self.branch))
        actuators = tuple(self.actuators)
        if len(actuators) != 2:
            msg = f'Expected RRR "{self.point}" to name 2 actuators or None, got {actuators!r}'
            raise SceneError(msg, (self, 'actuators'))
        for name in actuators:
            if name is not None:
                _check_name(name, f'the actuator of a link of RRR "{self.point}"',
                            (self, 'actuators'))
        if actuators[0] is not None and actuators[0] == actuators[1]:
            msg = (f'Expected the two links of RRR "{self.point}" to have different actuators, '
                   f'got "{actuators[0]}" twice')
            raise SceneError(msg, (self, 'actuators'))
        object.__setattr__(self, 'actuators', actuators)

    @classmethod
    def from_scene(cls, read: Reading, raw: Any, where: str) -> RRR:
        """Return the RRR at ``where``: ``point``, ``links`` (two), ``branch``.

        A link may say ``actuator: NAME`` instead of ``length:``: its length is
        that actuator's (a driver of the scene's ``inputs``).
        """
        read.check_keys(raw, {'type', 'point', 'links', 'branch'}, where)
        links = read.get(raw, 'links', where)
        if not isinstance(links, list) or len(links) != 2:
            raise SceneError(f'{where}.links: expected a list of 2 links, got '
                             f'{read.brief(links)}')
        pair: list[Link] = []
        actuators: list[str | None] = []
        for i, raw_link in enumerate(links):
            at = f'{where}.links[{i}]'
            if isinstance(raw_link, dict) and 'actuator' in raw_link:
                read.check_keys(raw_link, {'name', 'from', 'actuator'}, at)
                actuator = read.name(raw_link, 'actuator', at)
                nominal = read.actuator_length(actuator, f'{at}.actuator')
                pair.append(read.build(at, {'start': 'from', 'length': 'actuator'}, Link,
                                       name=read.name(raw_link, 'name', at),
                                       start=read.name(raw_link, 'from', at), length=nominal))
                actuators.append(actuator)
            else:
                pair.append(read.link(raw_link, at))
                actuators.append(None)
        built: RRR = read.build(where, {'actuators': 'links'}, cls,
                                point=read.name(raw, 'point', where), links=(pair[0], pair[1]),
                                branch=read.branch(raw, where),
                                actuators=(actuators[0], actuators[1]))
        return built

    @staticmethod
    def fact_texts() -> dict[str, Callable[[dict[str, Any], SceneUnits], str]]:
        """Return the texts of circles apart and of links in line."""
        return {'apart': _pair_text, 'in line': _pair_text}

    @property
    def key(self) -> str:
        """Return the dyad's new point."""
        return self.point

    def defined(self) -> Iterator[tuple[str, str, Where]]:
        """Yield its new point and its two links."""
        yield self.point, 'point', (self, 'point')
        for link in self.links:
            yield link.name, 'link', (link, 'name')

    def prerequisites(self, names: Names) -> set[str]:
        """Return the start points of its links (and the actuators of actuated links)."""
        needed = {names.point(link.start, f'the start of link "{link.name}"', (link, 'start'))
                  for link in self.links}
        for link, actuator in zip(self.links, self.actuators, strict=True):
            if actuator is not None:
                if names.kinds.get(actuator) != 'actuator':
                    kind = names.kinds.get(actuator)
                    got = f'unknown "{actuator}"' if kind is None else f'{kind} "{actuator}"'
                    msg = (f'Expected the actuator of link "{link.name}" to be an actuator of '
                           f'inputs, got {got}')
                    raise SceneError(msg, (self, 'actuators'))
                needed.add(actuator)
        return needed

    def place(self, plan: Placing) -> Step:
        """Return its step; its links carry their start and the new point.

        An actuated link's length varies: its start is fixed on it, and the new
        point lies along it (as a slotted lever's pin, :attr:`~.base.Placing.slot`).
        Where both starts are fixed on one link already placed, the dyad closes a
        rigid triangle on it (:func:`_rigid_base`).
        """
        base = _rigid_base(plan.local, plan.carriers, self.links)
        for link, actuator in zip(self.links, self.actuators, strict=True):
            if actuator is None:
                plan.local[link.name] = {link.start: 0j, self.point: complex(link.length)}
            else:
                plan.local[link.name] = {link.start: 0j}
                plan.slot[link.name] = (link.start, self.point)
        if self.actuators == (None, None):
            return _RRRStep(self, base)
        return _ActuatedRRRStep(self)

    def lengths(self) -> tuple[float, ...]:
        """Return its two link lengths."""
        return tuple(link.length for link in self.links)

    def scaled(self, scale: Callable[[float], float]) -> RRR:
        """Return it with both link lengths scaled."""
        first, second = (replace(link, length=scale(link.length)) for link in self.links)
        return replace(self, links=(first, second))

    def fragment(self) -> Fragment:
        """Return its part of the graph: two links pinned at their starts and at the new pin.

        An actuated link is a cylinder: its barrel (the link, pinned at its
        start) and its rod (the actuator, carrying the new pin), which slides
        along the barrel, driven.
        """
        bodies, joints, carrying = [], [], []
        for link, actuator in zip(self.links, self.actuators, strict=True):
            frame = Frame(link.start, link.name)
            joints.append(pin(link.name, link.start))
            if actuator is None:
                bodies.append(Body(link.name, Role.LINK, (link.start, self.point), frame,
                                   length=link.length))
                carrying.append(link.name)
            else:
                bodies += [Body(link.name, Role.LINK, (link.start,), frame),
                           Body(actuator, Role.SLIDER, (self.point,),
                                Frame(self.point, link.name), guide=link.name)]
                joints.append(slide(actuator, self.point, actuator,
                                    Line(link.start, link.name), on=link.name, driver=True))
                carrying.append(actuator)
        joints.append(pin(carrying[1], self.point, on=carrying[0]))
        return Fragment(self.point, tuple(bodies), tuple(joints),
                        {link.name: REVOLUTE for link in self.links},
                        tuple(Motion(link.name, link.start, self.point) for link in self.links))

    def toggle(self) -> tuple[str, str, tuple[str, ...]] | None:
        """Return its measure (the sine of the angle between its links), label and links."""
        return self.point, f'RRR {self.point}', tuple(link.name for link in self.links)


def _pair_text(facts: dict[str, Any], units: SceneUnits) -> str:
    """Return why an RRR's two links cannot close, in the scene's units."""
    text = units.length_text
    (a, b), (la, lb), (p, q) = facts['links'], facts['lengths'], facts['points']
    distance = facts['distance']
    pair = f'links {a} ({text(la)}) and {b} ({text(lb)})'
    if 'inputs' in facts:
        inputs = text(facts['inputs'])
        blamed = (f'the error of |{p}{q}| ({inputs}) exceeds' if facts.get('rigid') else
                  f'the error bounds of {p} and {q} ({inputs} together) exceed')
        return (f'{pair} between {p} and {q} ({text(distance)} apart) are '
                f'{text(facts["margin"])} in |{p}{q}| from being in line, but {blamed} '
                f'1/{ROUNDING_MARGIN:g} of that: their position cannot be trusted')
    if facts['kind'] == 'in line':
        return (f'{pair} in line between {p} and {q} ({text(distance)} apart): a toggle '
                f'position, where the mechanism locks')
    if distance >= la + lb:
        return (f'{pair} cannot reach from {p} to {q} '
                f'({text(distance, la + lb)} apart, more than {text(la + lb, distance)})')
    return (f'{pair} cannot meet: {p} and {q} are {text(distance, abs(la - lb))} apart, less '
            f'than the difference of their lengths ({text(abs(la - lb), distance)})')


def _rigid_base(local: Mapping[str, Mapping[str, complex]],
                carriers: Mapping[str, list[str]],
                links: tuple[Link, Link]) -> tuple[str, complex, complex, float] | None:
    """Return a placed link carrying both starts, their places on it and its extent; else None.

    ``carriers`` lists the links each point is fixed on (:class:`~.base.Placing`).
    The extent is the largest distance from the link's start of a point fixed on it.

    A dyad whose two starts are fixed on one link closes a rigid triangle on it
    (a truss, as a strip of triangles): its pin and links move with that link.
    """
    first, second = (link.start for link in links)
    for name in carriers.get(first, ()):
        fixed = local[name]
        if second in fixed and first != second:
            return name, fixed[first], fixed[second], max(abs(q) for q in fixed.values())
    return None


class _RRRStep(Step):

    def __init__(self, dyad: RRR,
                 base: tuple[str, complex, complex, float] | None = None) -> None:
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
        self.defines = (dyad.point, first.name, second.name)
        self.new_points = (dyad.point,)
        try:
            self.rigid = base is not None and self._on(*base)
        except (OverflowError, ZeroDivisionError):   # starts beyond doubles' range apart
            self.rigid = False

    def _on(self, base: str, q1: complex, q2: complex, extent: float) -> bool:
        """Fix the triangle on link ``base``, its starts at ``q1`` and ``q2``; say if it closes.

        The pin's place on the link relative to each start (``c1``, ``c2``, of
        lengths l1 and l2) comes from the exact distance of the starts, to a
        few ulps: a triangle that does not close (or is flat) is left to
        ``run``, which refuses it. ``e_c`` bounds the error of ``c1`` and
        ``c2``, with the starts' own places on the link known to 16 ulps of
        its ``extent`` (a carried point's rounding) moving the pin by that
        over the triangle's measure.
        """
        dx = Fraction(q2.real) - Fraction(q1.real)
        dy = Fraction(q2.imag) - Fraction(q1.imag)
        d2 = dx * dx + dy * dy
        f1, f2 = Fraction(self.l1), Fraction(self.l2)
        k = ((f1 + f2) ** 2 - d2) * (d2 - (f1 - f2) ** 2)  # 4 d^2 h^2
        if k <= 0:
            return False
        dist = math.hypot(float(dx), float(dy))
        along = float((f1 * f1 - f2 * f2 + d2) / (2 * d2)) * dist
        height = self.branch * math.sqrt(float(k / (4 * d2 * d2))) * dist
        ux, uy = float(dx) / dist, float(dy) / dist
        c1 = complex(along * ux - height * uy, along * uy + height * ux)
        c2 = c1 - (q2 - q1)
        measure = (abs(height) / self.l1) * (dist / self.l2)  # (no product of lengths)
        self.base = base
        self.uses = (*self.uses, base)
        self.c1r, self.c1i, self.c2r, self.c2i = c1.real, c1.imag, c2.real, c2.imag
        self.dist0 = dist
        e_q = _U16 * extent
        self.e_dist = _U2 * dist + 2.0 * e_q
        e_c = _U16 * (self.l1 + self.l2 + dist) + 2.0 * e_q * (
            1.0 / measure + max(self.l1, self.l2) / dist)
        # The rigid forms' products and the measured differences round by a few U more.
        self.e_c1, self.e_c2 = e_c + _U4 * self.l1, e_c + _U4 * self.l2
        return True

    def facts(self, dist: float, touching: bool, margin: float = 0.0,
              inputs: float = 0.0) -> dict[str, Any]:
        """Return why the circles do not meet, for a message in the scene's units.

        ``margin`` and ``inputs`` (the error bounds of the links' starts) are
        given where the circles meet but within rounding of a limit: where the
        starts' bounds alone make it so, the message blames them, not a toggle.
        """
        m = self.unit
        facts = {'kind': 'in line' if touching else 'apart', 'links': (self.link1, self.link2),
                 'lengths': (self.l1 * m, self.l2 * m), 'points': (self.start1, self.start2),
                 'distance': float(dist) * m}
        # A margin above 1e-6 of the lengths is not a toggle (the links are 0.1 deg or
        # more from in line): only its starts' bounds (1e7 times this step's own
        # rounding at least) can have brought it within rounding of the limit.
        if margin > 1e-6 * (self.l1 + self.l2):
            # (a rigid triangle's inputs are the error of its starts' distance)
            facts.update(margin=float(margin) * m, inputs=float(inputs) * m, rigid=self.rigid)
        return facts

    def margins(self, points: Mapping[str, tuple[Any, ...]]) -> tuple[tuple[Any, Any], ...]:
        """Return the circles' margins ``l1 + l2 - d`` and ``d - |l1 - l2|`` and their rates.

        ``d`` is the distance between the links' starts.
        """
        p1, v1 = points[self.start1][:2]
        p2, v2 = points[self.start2][:2]
        d = p2 - p1
        dist = np.hypot(d.real, d.imag)
        rate = _dot(d, v2 - v1) / dist
        return ((self.l1 + self.l2 - dist, -rate), (dist - abs(self.l1 - self.l2), rate))

    def crank_margins(self, tip: str, center: complex, radius: float,
                      ground: Mapping[str, complex]
                      ) -> Callable[[Any], tuple[tuple[Any, Any], ...]] | None:
        """Return its margins in closed form when it joins the crank's tip to a ground point.

        With ``r`` the crank, ``g`` and ``phi`` the distance and direction of
        the ground point from the crank's pivot and ``psi = theta - phi``:
        ``d^2 = (r - g)^2 + 4 r g sin^2(psi / 2) = (r + g)^2 - 4 r g cos^2(psi / 2)``,
        so ``(l1 + l2)^2 - d^2`` and ``d^2 - (l1 - l2)^2`` are each a constant
        plus a smooth term, taken in the form whose term is the smaller (near
        ``psi = 0`` or ``pi``); the constants are formed exactly from the
        doubles given (:func:`._sum_root`), so the margins keep their accuracy
        where the circles barely meet (or barely fail to), and their roots
        come out to an ulp of the angle.
        """
        starts = (self.start1, self.start2)
        if tip not in starts:
            return None
        other = starts[1] if starts[0] == tip else starts[0]
        if other not in ground:
            return None
        where = ground[other]
        dx = Fraction(where.real) - Fraction(center.real)
        dy = Fraction(where.imag) - Fraction(center.imag)
        g2 = dx * dx + dy * dy
        phi = math.atan2(float(dy), float(dx))
        r = Fraction(radius)
        lsum = Fraction(self.l1) + Fraction(self.l2)
        ldiff = abs(Fraction(self.l1) - Fraction(self.l2))
        # Near psi = 0 (d = |r - g|) and near psi = pi (d = r + g):
        outer_0 = _sum_root(lsum - r, g2) * -_sum_root(-(lsum + r), g2)  # lsum^2 - (r - g)^2
        outer_pi = -_sum_root(r - lsum, g2) * _sum_root(lsum + r, g2)  # lsum^2 - (r + g)^2
        inner_0 = _sum_root(ldiff - r, g2) * _sum_root(-(r + ldiff), g2)  # (r - g)^2 - ldiff^2
        inner_pi = _sum_root(r - ldiff, g2) * _sum_root(r + ldiff, g2)  # (r + g)^2 - ldiff^2
        rg4 = 4.0 * radius * math.sqrt(g2)

        def margins(theta: Any) -> tuple[tuple[Any, Any], ...]:
            half = 0.5 * (theta - phi)
            s, c = np.sin(half), np.cos(half)
            s2, c2 = rg4 * s * s, rg4 * c * c
            near_0 = s * s < 0.5
            rate = rg4 * s * c  # 2 r g sin(psi): the rate of d^2
            return ((np.where(near_0, outer_0 - s2, outer_pi + c2), -rate),
                    (np.where(near_0, inner_0 + s2, inner_pi - c2), rate))

        return margins

    def facts_at(self, dist: float, l1: float, l2: float, touching: bool,
                 margin: float = 0.0, inputs: float = 0.0) -> dict[str, Any]:
        """Return why the circles do not meet (:meth:`facts`; ``l1``, ``l2`` are its own)."""
        return self.facts(dist, touching, margin, inputs)

    def _meet(self, ctx: _Context, d: Any, dist: Any, l1: Any, l2: Any, lsum: Any,
              inputs: Any, lengths: Any) -> tuple[Any, Any, Any, Any, Any]:
        """Return where circles of radii ``l1`` and ``l2`` about two starts meet; check they do.

        The kernel both RRR kinds share (a helper the compiler writes out in
        their ``run``): ``d`` is the second start less the first, ``dist`` its
        length, ``lsum`` ``l1 + l2``; ``inputs`` and ``lengths`` the error of
        ``dist`` from the starts and from the lengths. Returns ``(r1, r2, root,
        measure, spread)``: the pin less each start, ``4 dist^2 h^2``'s square
        root, the sine of the angle between the links, and the error of
        ``dist`` and the lengths together.
        """
        ldiff = l1 - l2
        # 4 * dist^2 * h^2 as a product of factors: no cancellation near toggle.
        k = (lsum + dist) * (lsum - dist) * (dist + ldiff) * (dist - ldiff)
        # The circles meet (k > 0) where the margin min(lsum - dist, dist - |ldiff|)
        # is positive. The error of dist, l1 and l2 (spread) is the inputs' and this
        # step's rounding of d and dist (2 U dist) and of lsum and ldiff. The margin
        # is linear in them: beyond ROUNDING_MARGIN spreads of the limit no input
        # within its error can cross it; nearer, either way, it is not trusted.
        spread = inputs + lengths + _U2 * dist
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
                f'{_g(dist * m, lsum * m, abs(ldiff) * m)} m'),
                lambda: self.facts_at(dist, l1, l2, False))
        if ctx.vector or not ok:
            ctx.check_margin(ok, self.label, margin * m, spread * m, lambda: (
                f'the circles about {self.start1} and {self.start2} are within rounding of '
                f'meeting at one point: expected the margin min({_g(lsum * m)} m - '
                f'|{self.start1}{self.start2}|, |{self.start1}{self.start2}| - '
                f'{_g(abs(ldiff) * m)} m) = {margin * m:.3g} m to exceed '
                f'{ROUNDING_MARGIN:g} times its error bound {spread * m:.3g} m'),
                lambda: self.facts_at(dist, l1, l2, True, margin, inputs))
        root = np.sqrt(k) if ctx.vector else math.sqrt(k)
        # sin of the angle between the two links (the transmission angle).
        measure = root / (2.0 * l1 * l2)
        ok = measure > SINGULAR
        if ctx.vector or not ok:
            ctx.check(ok, self.label, lambda: (
                f'links {self.link1} and {self.link2} are in line (singular): expected the '
                f'sine of the angle between them > {SINGULAR:g}, got {measure:.3g}'),
                lambda: self.facts_at(dist, l1, l2, True))
        ctx.measures[self.key] = measure
        half = 0.5 / dist
        shared = ldiff * lsum
        height = self.branch * root * half
        u = d * (1.0 / dist)
        across = 1j * height * u
        r1 = (shared + dist * dist) * half * u + across
        r2 = (shared - dist * dist) * half * u + across
        return r1, r2, root, measure, spread

    def run(self, ctx: _Context) -> None:
        l1, l2 = self.l1, self.l2
        p1, v1, a1, ep1, ev1, ea1 = ctx.points[self.start1]
        p2, v2, a2, ep2, ev2, ea2 = ctx.points[self.start2]
        d = p2 - p1
        dist = np.hypot(d.real, d.imag) if ctx.vector else abs(d)
        lsum = l1 + l2
        if self.rigid:  # noqa: SIM108 (the tick folds an ``if`` on self, not an if-else value)
            inputs = abs(dist - self.dist0) + self.e_dist   # only the starts' distance's error
        else:
            inputs = ep1 + ep2
        r1, r2, root, measure, spread = self._meet(ctx, d, dist, l1, l2, lsum, inputs,
                                                   self.e_lengths)
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
        inv_l1, inv_l2 = self.inv_l1, self.inv_l2
        aw1 = abs(w1)
        aa1 = abs(al1)
        if self.rigid:
            # A rigid triangle on link base (see _on): the truth moves with the base, the
            # pin at c1 from start 1 and c2 from start 2 on it, both links at the base's
            # rates. Each bound is the base's (its bounds carried over) plus how far the
            # solved value lies from the base's motion so carried (measured here), plus
            # rounding: no input's bound is divided by the measure, so a strip of such
            # triangles keeps bounds that grow as its errors do (docs/robustness.md).
            eb, wb, ab, eeb, ewb, eab = ctx.links[self.base]
            awb = abs(wb)
            aab = abs(ab)
            rr1 = abs(r1 - (eb * self.c1r + 1j * eb * self.c1i)) + l1 * eeb + self.e_c1
            rr2 = abs(r2 - (eb * self.c2r + 1j * eb * self.c2i)) + l2 * eeb + self.e_c2
            rw1 = abs(w1 - wb) + ewb + _U2 * (aw1 + awb)
            rw2 = abs(w2 - wb) + ewb + _U2 * (abs(w2) + awb)
            ra1 = abs(al1 - ab) + eab + _U2 * (aa1 + aab)
            ra2 = abs(al2 - ab) + eab + _U2 * (abs(al2) + aab)
            reach = l1 + rr1  # |r1| at most
            wt = awb + ewb  # the true |wb| at most
            bp = ep1 + rr1 + U * (abs(p1.real) + abs(p1.imag))
            bv = (ev1 + U * (abs(v1.real) + abs(v1.imag)) + _U2 * aw1 * l1 + rw1 * reach
                  + wt * rr1)
            ba = (ea1 + _U2 * (abs(a1.real) + abs(a1.imag)) + _U4 * (aa1 + w1sq) * l1
                  + (ra1 + rw1 * (2.0 * aw1 + rw1)) * reach + (aab + eab + wt * wt) * rr1)
            be1, bw1, bal1 = rr1 * inv_l1 + _U7, rw1, ra1
            be2, bw2, bal2 = rr2 * inv_l2 + _U7, rw2, ra2
        else:
            inv_m = 1.0 / measure
            er = spread * inv_m + self.e_forward
            erp = er + self.e_round
            aws = aw1 + abs(w2)
            t = (ev1 + ev2 + aws * erp) * inv_m
            ta = (ea1 + ea2 + (2.0 * aws + t * self.inv_sum) * t
                  + (w1sq + w2sq + aa1 + abs(al2)) * erp) * inv_m
            ew1 = t * inv_l1
            # The pin C = p1 + r1(p2 - p1) moves with its starts as J1 dp1 + J2 dp2, where
            # J2 is r1's derivative and J1 = I - J2: each of norm 1 / measure (moving one
            # start, the pin turns about the other), so the starts' bounds over the measure,
            # in er, bound both terms (ep1 + er would count p1 twice). Its velocity and
            # acceleration move likewise with (v1, v2) and (a1, a2), in t and ta.
            # The sums p1 + r1 etc. round by U |p1| + U l1 (U l1 in er),
            # U |v1| + U |w1| l1 and 2 U |a1| + a few U (|al1| + w1^2) l1 (in erp).
            bp = er + U * (abs(p1.real) + abs(p1.imag))
            bv = U * (abs(v1.real) + abs(v1.imag)) + t + aw1 * erp
            ba = (_U2 * (abs(a1.real) + abs(a1.imag)) + ta + (2.0 * aw1 + ew1) * t
                  + (aa1 + w1sq) * erp)
            be1, bw1, bal1 = er * inv_l1 + _U7, ew1, ta * inv_l1
            be2, bw2, bal2 = er * inv_l2 + _U7, t * inv_l2, ta * inv_l2
        ctx.points[self.point] = (
            p1 + r1, v1 + 1j * w1 * r1, a1 + 1j * al1 * r1 - w1 * w1 * r1, bp, bv, ba)
        ctx.links[self.link1] = (r1 * (1.0 / l1), w1, al1, be1, bw1, bal1)
        ctx.links[self.link2] = (r2 * (1.0 / l2), w2, al2, be2, bw2, bal2)


class _ActuatedRRRStep(_RRRStep):
    """An RRR with one or both link lengths an actuator's: the variable-length closed form.

    The position is the fixed RRR's closed form on the current lengths. With
    ``e1 = r1 / l1`` the unit vector along a link and ``l1'``, ``l1''`` its
    length's rates, the pin moves as ``v1 + l1' e1 + i w1 r1`` and
    ``a1 + l1'' e1 + 2 i w1 l1' e1 + i al1 r1 - w1^2 r1`` (the extension
    rate, Coriolis and extension-acceleration terms), so the right sides of
    the velocity and acceleration systems gain ``l2' e2 - l1' e1`` and
    ``l2'' e2 + 2 i w2 l2' e2 - l1'' e1 - 2 i w1 l1' e1``. A fixed link has
    rates 0 and the fixed RRR's kernel (:class:`_RRRStep`) is kept for
    dyads with no actuator, bit for bit.
    """

    def __init__(self, dyad: RRR) -> None:
        super().__init__(dyad)
        self.act1, self.act2 = dyad.actuators
        # A fixed link's length, known to half an ulp (the actuators' come with their bounds).
        self.fixed1 = (self.l1, 0.0, 0.0, U * self.l1, 0.0, 0.0)
        self.fixed2 = (self.l2, 0.0, 0.0, U * self.l2, 0.0, 0.0)
        self.uses = (*self.uses, *(name for name in dyad.actuators if name is not None))

    def facts_at(self, dist: float, l1: float, l2: float, touching: bool,
                 margin: float = 0.0, inputs: float = 0.0) -> dict[str, Any]:
        """Return why the circles do not meet at the current lengths, in SI (see ``facts``).

        The starts are never blamed for a margin within rounding (``margin``
        and ``inputs`` are not read): the actuators' bounds are in its spread.
        """
        facts = self.facts(dist, touching)
        m = self.unit
        facts['lengths'] = (float(l1) * m, float(l2) * m)
        return facts

    def margins(self, points: Mapping[str, tuple[Any, ...]]) -> tuple[tuple[Any, Any], ...]:
        """Return no margins in one crank's angle: its lengths are other drivers' inputs."""
        return ()

    def crank_margins(self, tip: str, center: complex, radius: float,
                      ground: Mapping[str, complex]
                      ) -> Callable[[Any], tuple[tuple[Any, Any], ...]] | None:
        """Return none (see :meth:`margins`)."""
        return None

    def run(self, ctx: _Context) -> None:
        self._actuated(ctx)

    def _actuated(self, ctx: _Context) -> None:
        """Solve the dyad on its current lengths (a helper the fold's kernel calls too)."""
        l1, ld1, ldd1, el1, eld1, eldd1 = (self.fixed1 if self.act1 is None
                                           else ctx.sliders[self.act1])
        l2, ld2, ldd2, el2, eld2, eldd2 = (self.fixed2 if self.act2 is None
                                           else ctx.sliders[self.act2])
        p1, v1, a1, ep1, ev1, ea1 = ctx.points[self.start1]
        p2, v2, a2, ep2, ev2, ea2 = ctx.points[self.start2]
        d = p2 - p1
        dist = np.hypot(d.real, d.imag) if ctx.vector else abs(d)
        lsum = l1 + l2
        # As the fixed RRR's (the same kernel, _meet), the lengths' errors being the
        # actuators' bounds (or half an ulp of a fixed length) and the rounding of lsum
        # and ldiff.
        r1, r2, root, measure, spread = self._meet(ctx, d, dist, l1, l2, lsum,
                                                   ep1 + ep2 + el1 + el2, _U2 * lsum)
        inv_l1, inv_l2 = 1.0 / l1, 1.0 / l2
        e1, e2 = r1 * inv_l1, r2 * inv_l2
        inv = 2.0 * self.branch / root  # 1 / cross(r1, r2)
        dv = v2 - v1 + ld2 * e2 - ld1 * e1
        w1 = _dot(dv, r2) * inv
        w2 = _dot(dv, r1) * inv
        w1sq, w2sq = w1 * w1, w2 * w2
        c1, c2 = 1j * (2.0 * w1 * ld1) * e1, 1j * (2.0 * w2 * ld2) * e2  # Coriolis
        da = a2 - a1 + w1sq * r1 - w2sq * r2 + ldd2 * e2 + c2 - ldd1 * e1 - c1
        al1 = _dot(da, r2) * inv
        al2 = _dot(da, r1) * inv
        # Bounds, as the fixed RRR's (see _RRRStep.run), with the lengths' rates: the
        # right side of the velocity system moves by their bounds and by |l'| times the
        # error of the unit vectors (erp / l); that of the acceleration system likewise
        # by the bounds of l'' and by the Coriolis terms' (2 |w| |l'|, with all three's).
        inv_m = 1.0 / measure
        er = spread * inv_m + _U16 * lsum
        erp = er + 8.0 * U * lsum
        ee1, ee2 = erp * inv_l1 + _U4, erp * inv_l2 + _U4
        ald1, ald2 = abs(ld1), abs(ld2)
        aw1 = abs(w1)
        aw2 = abs(w2)
        aws = aw1 + aw2
        t = (ev1 + ev2 + eld1 + eld2 + ald1 * ee1 + ald2 * ee2 + aws * erp) * inv_m
        ew1, ew2 = t * inv_l1, t * inv_l2
        aa1 = abs(al1)
        grow1 = eldd1 + abs(ldd1) * ee1 + 2.0 * (aw1 * eld1 + ald1 * ew1 + aw1 * ald1 * ee1)
        grow2 = eldd2 + abs(ldd2) * ee2 + 2.0 * (aw2 * eld2 + ald2 * ew2 + aw2 * ald2 * ee2)
        ta = (ea1 + ea2 + grow1 + grow2 + (2.0 * aws + t * (inv_l1 + inv_l2)) * t
              + (w1sq + w2sq + aa1 + abs(al2)) * erp) * inv_m
        ctx.points[self.point] = (
            p1 + r1, v1 + ld1 * e1 + 1j * w1 * r1,
            a1 + ldd1 * e1 + c1 + 1j * al1 * r1 - w1 * w1 * r1, er + ep1,
            ev1 + U * (abs(v1.real) + abs(v1.imag)) + t + aw1 * erp + eld1 + ald1 * ee1
            + _U2 * ald1,
            ea1 + _U2 * (abs(a1.real) + abs(a1.imag)) + ta + (2.0 * aw1 + ew1) * t
            + (aa1 + w1sq) * erp + grow1 + _U4 * (abs(ldd1) + 2.0 * aw1 * ald1))
        ctx.links[self.link1] = (e1, w1, al1, er * inv_l1 + _U7, ew1, ta * inv_l1)
        ctx.links[self.link2] = (e2, w2, al2, er * inv_l2 + _U7, ew2, ta * inv_l2)
