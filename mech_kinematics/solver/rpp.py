# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The RPP dyad, the Scotch yoke: a yoke on a fixed straight guide, a known pin in its slot.

The yoke slides on the guide through ground point O at ``guide.angle``; its
straight slot keeps the absolute direction ``slot_angle`` (the yoke only
translates), and the pin B (a known moving point) slides in it. The new
point Y is where the slot's line crosses the guide's line:
``Y = O + s u = B - t w`` with ``u``, ``w`` the unit vectors of the guide and
the slot, ``s`` the yoke's coordinate (prismatic joint ``slider``) and ``t``
the pin's along the slot from Y (prismatic joint ``slot_slider``). With
``c = cross(u, w) = sin(slot_angle - guide.angle)`` and ``d = B - O``::

    s = cross(d, w) / c        t = cross(u, d) / c

and the same with d's derivatives (the pin's velocity and acceleration) for
the rates: the map from B to (s, t) is linear with constant coefficients, so
the yoke always assembles, and is singular only for a slot parallel to the
guide (``c = 0``), which is refused when the scene is loaded. The
near-singularity measure is ``|c|``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
import math
from typing import Any

import numpy as np

from .base import Item, Names, Placing, Reading, Step
from .context import _Context, _cross, _U2, SINGULAR
from .graph import Body, Fragment, Frame, Line, pin, PRISMATIC, Role, slide, THE_GROUND
from .model import _check_finite, _check_name, SceneUnits, Where
from ..bounds import U
from ..errors import SceneError


@dataclass(frozen=True)
class RPP(Item):
    """A Scotch yoke: new point ``point`` where the slot through pin ``through`` meets the guide.

    Parameters
    ----------
    point : str
        The new point Y, on the yoke, where the slot's line crosses the guide's.
    through : str
        The pin B in the slot (a known moving point).
    guide_through : str
        The ground point O the yoke's fixed guide passes through.
    guide_angle : float
        The guide's direction, rad.
    slot_angle : float
        The slot's direction, absolute (the yoke only translates), rad.
    slider : str
        Prismatic joint: the signed distance of Y from O along the guide, m.
    slot_slider : str
        Prismatic joint: the signed distance of B from Y along the slot, m.
    """

    kind = 'RPP'

    point: str
    through: str
    guide_through: str
    guide_angle: float
    slot_angle: float
    slider: str
    slot_slider: str

    def __post_init__(self) -> None:
        """Validate the fields; refuse a slot parallel to the guide."""
        _check_name(self.point, 'an RPP point', (self, 'point'))
        _check_name(self.through, f'the pin of RPP "{self.point}"', (self, 'through'))
        _check_name(self.guide_through, f'the guide point of RPP "{self.point}"',
                    (self, 'guide_through'))
        _check_name(self.slider, f'the slider of RPP "{self.point}"', (self, 'slider'))
        _check_name(self.slot_slider, f'the slot slider of RPP "{self.point}"',
                    (self, 'slot_slider'))
        _check_finite(self.guide_angle, f'the guide angle of RPP "{self.point}"',
                      (self, 'guide_angle'))
        _check_finite(self.slot_angle, f'the slot angle of RPP "{self.point}"',
                      (self, 'slot_angle'))
        sine = abs(math.sin(self.slot_angle - self.guide_angle))
        if not sine > SINGULAR:
            msg = (f'Expected the slot of RPP "{self.point}" to cross its guide (the sine of '
                   f'the angle between them > {SINGULAR:g}), got a slot parallel to the guide '
                   f'(sine {sine:.3g}): turn slot_angle away from guide.angle')
            raise SceneError(msg, (self, 'slot_angle'))

    @classmethod
    def from_scene(cls, read: Reading, raw: Any, where: str) -> RPP:
        """Return the RPP at ``where``: point, through, guide, slot_angle, slider, slot_slider."""
        read.check_keys(raw, {'type', 'point', 'through', 'guide', 'slot_angle', 'slider',
                              'slot_slider'}, where)
        guide = read.get(raw, 'guide', where)
        if isinstance(guide, dict):
            read.check_keys(guide, {'through', 'angle'}, f'{where}.guide')
        built: RPP = read.build(
            where, {'guide_through': 'guide.through', 'guide_angle': 'guide.angle'}, cls,
            point=read.name(raw, 'point', where), through=read.name(raw, 'through', where),
            guide_through=read.name(guide, 'through', f'{where}.guide'),
            guide_angle=read.angle(guide, 'angle', f'{where}.guide', 0.0),
            slot_angle=read.angle(raw, 'slot_angle', where),
            slider=read.name(raw, 'slider', where),
            slot_slider=read.name(raw, 'slot_slider', where))
        return built

    @property
    def key(self) -> str:
        """Return the new point Y."""
        return self.point

    def defined(self) -> Iterator[tuple[str, str, Where]]:
        """Yield its new point and its two sliders."""
        yield self.point, 'point', (self, 'point')
        yield self.slider, 'slider', (self, 'slider')
        yield self.slot_slider, 'slider', (self, 'slot_slider')

    def prerequisites(self, names: Names) -> set[str]:
        """Check the guide's ground point; return the pin."""
        names.ground(self.guide_through, f'the guide point of RPP "{self.point}"',
                     (self, 'guide_through'))
        return {names.point(self.through, f'the pin of RPP "{self.point}"', (self, 'through'))}

    def place(self, plan: Placing) -> Step:
        """Return its step (the yoke carries no link)."""
        return _RPPStep(self, plan.ground[self.guide_through])

    def scaled(self, scale: Callable[[float], float]) -> RPP:
        """Return it unchanged: it holds no length."""
        return self

    def toggle(self) -> None:
        """Return ``None``: its measure is the sine of the slot's angle to the guide."""
        return None

    def lengths(self) -> tuple[float, ...]:
        """Return no length: the yoke holds no length."""
        return ()

    @staticmethod
    def fact_texts() -> dict[str, Callable[[dict[str, Any], SceneUnits], str]]:
        """Return none: its errors carry no facts (their reason is their text)."""
        return {}

    def fragment(self) -> Fragment:
        """Return its part of the graph: the yoke on its guide, a block on the pin in its slot.

        Neither turns: the yoke's frame keeps the guide's angle, the block's
        the slot's.
        """
        return Fragment(
            self.point,
            (Body(self.slider, Role.SLIDER, (self.point,),
                  Frame(self.point, None, self.guide_angle), guide=THE_GROUND),
             Body(self.slot_slider, Role.SLIDER, (self.through,),
                  Frame(self.through, None, self.slot_angle), guide=self.slider)),
            (slide(self.slider, self.point, self.slider,
                   Line(self.guide_through, None, self.guide_angle), on=THE_GROUND),
             pin(self.slot_slider, self.through),
             slide(self.slot_slider, self.through, self.slot_slider,
                   Line(self.point, None, self.slot_angle), on=self.slider)),
            {self.slider: PRISMATIC, self.slot_slider: PRISMATIC})


class _RPPStep(Step):
    """The yoke's closed forms (see the module) with their error bounds."""

    def __init__(self, dyad: RPP, through: complex) -> None:
        self.dyad = dyad
        self.label = f'RPP {dyad.point}'
        self.key = dyad.point
        self.point = dyad.point
        self.pin = dyad.through
        self.slider = dyad.slider
        self.slot_slider = dyad.slot_slider
        self.through = through
        self.uses = (dyad.through,)
        self.defines = (dyad.point, dyad.slider, dyad.slot_slider)
        self.new_points = (dyad.point,)
        self.u = complex(math.cos(dyad.guide_angle), math.sin(dyad.guide_angle))
        self.w = complex(math.cos(dyad.slot_angle), math.sin(dyad.slot_angle))
        c = _cross(self.u, self.w)
        self.inv_c = 1.0 / c
        self.measure = abs(c)
        inv = abs(self.inv_c)
        self.inv = inv
        # The guide's point known to U |O|; each direction to its angle's rounding
        # and an ulp of cos and sin; c to both and its own two products and
        # difference; 1 / c to c's relative error and its own rounding.
        self.e_through = U * abs(through)
        self.e_u = U * abs(dyad.guide_angle) + _U2
        self.e_w = U * abs(dyad.slot_angle) + _U2
        self.e_inv = (self.e_u + self.e_w + 3.0 * U) * inv + U
        # The rounding of a cross product with a unit vector (two products and a
        # difference), on top of its inputs' errors, per unit of |x| + |y|.
        self.e_su = self.e_w + _U2
        self.e_tu = self.e_u + _U2

    def run(self, ctx: _Context) -> None:
        b, vb, ab, eb, evb, eab = ctx.points[self.pin]
        u, w, inv_c, inv = self.u, self.w, self.inv_c, self.inv
        d = b - self.through
        s = _cross(d, w) * inv_c
        t = _cross(u, d) * inv_c
        sd = _cross(vb, w) * inv_c
        td = _cross(u, vb) * inv_c
        sdd = _cross(ab, w) * inv_c
        tdd = _cross(u, ab) * inv_c
        ctx.measures[self.key] = (np.full(np.shape(d), self.measure) if ctx.vector
                                  else self.measure)
        # Bounds. The map from the pin's values to (s, t) is linear with the
        # constant coefficients w / c and u / c: each coordinate moves by its
        # input's bound and the directions' (times |x| + |y| of the input) over
        # |c|, and by its own size times the relative error of 1 / c. Y = O + s u
        # adds O's bound, u's direction error times |s| and the sum's and
        # product's rounding.
        nd = abs(d.real) + abs(d.imag)
        nv = abs(vb.real) + abs(vb.imag)
        na = abs(ab.real) + abs(ab.imag)
        e_inv = self.e_inv
        ed = eb + self.e_through + U * nd
        a_s, a_sd, a_sdd = abs(s), abs(sd), abs(sdd)
        es = (ed + nd * self.e_su) * inv + a_s * e_inv
        et = (ed + nd * self.e_tu) * inv + abs(t) * e_inv
        esd = (evb + nv * self.e_su) * inv + a_sd * e_inv
        etd = (evb + nv * self.e_tu) * inv + abs(td) * e_inv
        esdd = (eab + na * self.e_su) * inv + a_sdd * e_inv
        etdd = (eab + na * self.e_tu) * inv + abs(tdd) * e_inv
        e_u = self.e_u + _U2
        ctx.points[self.point] = (self.through + s * u, sd * u, sdd * u,
                                  es + a_s * e_u + 2.0 * self.e_through + U * a_s,
                                  esd + a_sd * e_u, esdd + a_sdd * e_u)
        ctx.sliders[self.slider] = (s, sd, sdd, es, esd, esdd)
        ctx.sliders[self.slot_slider] = (t, td, tdd, et, etd, etdd)
