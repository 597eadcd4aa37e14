# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The RPR dyad: a slotted lever turning about a ground pivot, through a known pin."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from .base import Item, Names, Placing, Reading, Step
from .context import _Context, _cross, _dot, _U2, _U4, _U7, SINGULAR
from .graph import (Body, Fragment, Frame, Joint, Line, LOCK, Motion, pin, PRISMATIC, REVOLUTE,
                    Role, slide, THE_GROUND)
from .model import _check_name, SceneUnits, Where
from ..bounds import ROUNDING_MARGIN, U
from ..errors import SceneError

#: Most slots of an intermittent (Geneva) lever.
MAX_SLOTS = 1000


@dataclass(frozen=True)
class RPR(Item):
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

    kind = 'RPR'

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

    @classmethod
    def from_scene(cls, read: Reading, raw: Any, where: str) -> RPR:
        """Return the RPR at ``where``: its link, center, through, slider and slots."""
        read.check_keys(raw, {'type', 'link', 'center', 'through', 'slider', 'slots'}, where)
        slots = raw.get('slots')
        if slots is not None and (isinstance(slots, bool) or not isinstance(slots, int)
                                  or not 3 <= slots <= MAX_SLOTS):
            raise SceneError(f'{where}.slots: expected a whole number of slots from 3 to '
                             f'{MAX_SLOTS}, got {read.brief(slots)}')
        built: RPR = read.build(
            where, {}, cls, link=read.name(raw, 'link', where),
            center=read.name(raw, 'center', where), through=read.name(raw, 'through', where),
            slider=read.name(raw, 'slider', where), slots=slots)
        return built

    @staticmethod
    def fact_texts() -> dict[str, Callable[[dict[str, Any], SceneUnits], str]]:
        """Return the text of a pin on the lever's pivot."""
        return {'pivot': _pivot_text}

    @property
    def key(self) -> str:
        """Return the lever."""
        return self.link

    def defined(self) -> Iterator[tuple[str, str, Where]]:
        """Yield its lever and its slider."""
        yield self.link, 'link', (self, 'link')
        yield self.slider, 'slider', (self, 'slider')

    def prerequisites(self, names: Names) -> set[str]:
        """Check its ground pivot; return its pin."""
        names.ground(self.center, f'the center of RPR "{self.link}"', (self, 'center'))
        return {names.point(self.through, f'the pin of RPR "{self.link}"', (self, 'through'))}

    def place(self, plan: Placing) -> Step:
        """Return its step (an intermittent one with ``slots``); its lever carries its pivot."""
        step: Step
        if self.slots is None:
            step = _RPRStep(self, plan.ground[self.center], plan.size)
        else:
            step = plan.intermittent(plan, self)     # the Geneva kind's (it builds on this one)
        plan.local[self.link] = {self.center: 0j}
        plan.slot[self.link] = (self.center, self.through)
        return step

    def scaled(self, scale: Callable[[float], float]) -> RPR:
        """Return it unchanged: it holds no length."""
        return self

    def toggle(self) -> None:
        """Return ``None``: its measure is its pin's distance from the pivot (over the size)."""
        return None

    def lengths(self) -> tuple[float, ...]:
        """Return no length: its lever's length (pivot to pin) varies."""
        return ()

    def fragment(self) -> Fragment:
        """Return its part of the graph: a lever on its pivot, a block on the pin in its slot.

        A Geneva wheel's slot (``slots``: that many, evenly spaced) holds the
        pin only while it is engaged, and a lock holds the wheel while it is
        not: both joints are intermittent.
        """
        geneva = self.slots is not None
        joints = [pin(self.link, self.center), pin(self.slider, self.through),
                  slide(self.slider, self.through, self.slider, Line(self.center, self.link),
                        on=self.link, intermittent=geneva, copies=self.slots or 1)]
        if geneva:
            joints.append(Joint(f'{self.link}/lock', LOCK, self.link, THE_GROUND, self.center,
                                intermittent=True))
        return Fragment(
            self.link,
            (Body(self.link, Role.LEVER, (self.center,), Frame(self.center, self.link)),
             Body(self.slider, Role.SLIDER, (self.through,), Frame(self.through, self.link),
                  guide=self.link)),
            tuple(joints), {self.link: REVOLUTE, self.slider: PRISMATIC},
            (Motion(self.link, self.center, self.through, self.slider),))


def _pivot_text(facts: dict[str, Any], units: SceneUnits) -> str:
    """Return why an RPR's lever has no direction, in the scene's units."""
    links, points = facts['links'], facts['points']
    return (f'the pin {points[0]} of slotted link {links[0]} on its pivot {points[1]} '
            f'({units.length_text(facts["distance"])} from it)')


class _RPRStep(Step):

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
        self.defines = (dyad.link, dyad.slider)
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
