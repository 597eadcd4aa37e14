# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The driven collar: a block slid along a moving link by an actuator (Coriolis's textbook case).

A collar on a rotating rod, driven outward along it: the rod is a link
already placed (a crank, a dyad's link), the collar's pin ``point`` lies on
the rod's line from ``from`` toward ``toward`` (two points fixed on the rod)
at the distance an actuator of the scene's ``inputs`` gives (its length: its
position, extension rate and acceleration). The collar's motion is the rod's
at that point plus its sliding:

    p = p_from + s u,   v = v_from + s' u + omega s (i u),
    a = a_from + s'' u + (2 omega s' + alpha s) (i u) - omega^2 s u,

``2 omega s'`` being the Coriolis term. It is the driven slide along a moving
link of issue 41: the actuator is the prismatic joint between the rod and the
collar (reported under the actuator's name), and every dyad may start from
the collar's pin. This module owns its scene keys, its validation, its part
of the graph and its step with their error bounds.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

from .base import Item, Names, Placing, Reading, Step
from .context import _Context
from .graph import Body, Fragment, Frame, Line, Motion, Role, slide
from .model import _check_name, _names, SceneUnits, Where
from ..bounds import U
from ..errors import SceneError

#: The scene keys of a collar.
KEYS = {'type', 'point', 'link', 'from', 'toward', 'actuator'}


@dataclass(frozen=True)
class Collar(Item):
    """A collar slid along ``link`` by ``actuator``: its pin ``point`` at that distance.

    Parameters
    ----------
    point : str
        The collar's pin (a new point).
    link : str
        The link it slides along, placed before it.
    start : str
        A point fixed on the link: where the distance is measured from (``from:``).
    toward : str
        Another point fixed on the link: the direction the collar slides in.
    actuator : str
        An actuator of the scene's ``inputs``: its length is the distance (> 0).
        The collar (its block) is named after it.
    """

    kind = 'collar'

    point: str
    link: str
    start: str
    toward: str
    actuator: str

    def __post_init__(self) -> None:
        """Validate the fields."""
        what = f'collar "{self.point}"'
        _check_name(self.point, 'a collar point', (self, 'point'))
        _check_name(self.link, f'the link of {what}', (self, 'link'))
        _check_name(self.start, f'the start of {what}', (self, 'start'))
        _check_name(self.toward, f'the direction point of {what}', (self, 'toward'))
        _check_name(self.actuator, f'the actuator of {what}', (self, 'actuator'))

    @classmethod
    def from_scene(cls, read: Reading, raw: Any, where: str) -> Collar:
        """Return the collar at ``where``: its point, link, from, toward and actuator."""
        read.check_keys(raw, KEYS, where)
        built: Collar = read.build(
            where, {'start': 'from'}, cls, point=read.name(raw, 'point', where),
            link=read.name(raw, 'link', where), start=read.name(raw, 'from', where),
            toward=read.name(raw, 'toward', where), actuator=read.name(raw, 'actuator', where))
        return built

    @property
    def key(self) -> str:
        """Return its pin."""
        return self.point

    def defined(self) -> Iterator[tuple[str, str, Where]]:
        """Yield its pin (its block is the actuator's, named by it)."""
        yield self.point, 'point', (self, 'point')

    def prerequisites(self, names: Names) -> set[str]:
        """Check its link, its two points and its actuator; return them."""
        what = f'collar "{self.point}"'
        kinds = names.kinds
        if kinds.get(self.actuator) != 'actuator':
            kind = kinds.get(self.actuator)
            got = f'unknown "{self.actuator}"' if kind is None else f'{kind} "{self.actuator}"'
            msg = f'Expected the actuator of {what} to be an actuator of inputs, got {got}'
            raise SceneError(msg, (self, 'actuator'))
        return {names.link(self.link, f'the link of {what}', (self, 'link')),
                names.point(self.start, f'the start of {what}', (self, 'start')),
                names.point(self.toward, f'the direction point of {what}', (self, 'toward')),
                self.actuator}

    def place(self, plan: Placing) -> Step:
        """Return its step; its two points must lie on its link's axis, ``toward`` beyond ``from``.

        The collar slides along the link's own axis (a crank's centre to its
        tip, a link's start to its pin): the line the graph gives its slide.
        """
        fixed = plan.local[self.link]
        for name, key in ((self.start, 'start'), (self.toward, 'toward')):
            if name not in fixed:
                msg = (f'Expected the {"start" if key == "start" else "direction point"} of '
                       f'collar "{self.point}" to be a point fixed on link "{self.link}" (one of '
                       f'{_names(fixed)}), got "{name}"')
                raise SceneError(msg, (self, key))
        axis = fixed[self.toward] - fixed[self.start]
        if not (axis.imag == 0.0 and axis.real > 0.0 and fixed[self.start].imag == 0.0):
            msg = (f'Expected collar "{self.point}" to slide along the axis of link '
                   f'"{self.link}" (from "{self.start}" toward "{self.toward}", both on it, in '
                   f'the order of its points), got "{self.start}" and "{self.toward}" off it')
            raise SceneError(msg, (self, 'toward'))
        return _CollarStep(self)

    def scaled(self, scale: Callable[[float], float]) -> Collar:
        """Return it (its distance is its actuator's, scaled with it)."""
        return self

    def lengths(self) -> tuple[float, ...]:
        """Return none: its distance is its actuator's (in the actuator's reach)."""
        return ()

    @staticmethod
    def fact_texts() -> dict[str, Callable[[dict[str, Any], SceneUnits], str]]:
        """Return none: it closes wherever its actuator's length is allowed."""
        return {}

    def toggle(self) -> None:
        """Return ``None``: it has no measure (it cannot fail to close)."""
        return None

    def fragment(self) -> Fragment:
        """Return its part of the graph: the collar, slid along its link by the actuator.

        The slide's line is the link's axis through ``from`` (:meth:`place`
        holds the collar's two points to it).
        """
        collar = Body(self.actuator, Role.SLIDER, (self.point,), Frame(self.point, self.link),
                      guide=self.link)
        joint = slide(self.actuator, self.point, self.actuator, Line(self.start, self.link),
                      on=self.link, driver=True)
        return Fragment(self.point, (collar,), (joint,), {},
                        (Motion(self.link, self.start, self.point, slider=self.actuator),))


class _CollarStep(Step):
    """The collar's kernel: its pin from the link's motion, the point's and the actuator's."""

    def __init__(self, collar: Collar) -> None:
        self.point = collar.point
        self.link = collar.link
        self.start = collar.start
        self.actuator = collar.actuator
        self.label = f'collar {collar.point}'
        self.key = collar.point
        self.dyad = collar
        self.owner = collar.link
        self.uses = (collar.start, collar.actuator)
        self.defines = self.new_points = (collar.point,)

    def run(self, ctx: _Context) -> None:
        e, omega, alpha, ee, ew, eal = ctx.links[self.link]
        p, v, a, ep, ev, ea = ctx.points[self.start]
        s, sd, sdd, es, esd, esdd = ctx.sliders[self.actuator]
        u, iu = e, 1j * e   # the link's direction is the slide's
        turn = 2.0 * omega * sd + alpha * s
        spin = omega * omega * s
        # Each product has one real factor or an imaginary one (crank.py's rule).
        ctx.points[self.point] = (p + s * u, v + sd * u + (omega * s) * iu,
                                  a + sdd * u + turn * iu - spin * u,
                                  *self._bounds(ee, ew, eal, ep, ev, ea, omega, alpha, s, sd,
                                                sdd, es, esd, esdd, p, v, a, turn, spin))

    def _bounds(self, ee: Any, ew: Any, eal: Any, ep: Any, ev: Any, ea: Any, omega: Any,
                alpha: Any, s: Any, sd: Any, sdd: Any, es: Any, esd: Any, esdd: Any, p: Any,
                v: Any, a: Any, turn: Any, spin: Any) -> tuple[Any, Any, Any]:
        """Return the bounds of its pin's position, velocity and acceleration (first order).

        Each product's inputs' errors (the direction's, the link's rates', the
        actuator's) and a few ulps of each term and of the sums.
        """
        eu = ee
        w, al, rs, rsd, rsdd = abs(omega), abs(alpha), abs(s), abs(sd), abs(sdd)
        e_pos = ep + es + rs * eu + 2.0 * U * (abs(p.real) + abs(p.imag) + 2.0 * rs)
        e_vel = (ev + esd + rsd * eu + ew * rs + w * es + w * rs * eu
                 + 2.0 * U * (abs(v.real) + abs(v.imag) + 2.0 * rsd + 3.0 * w * rs))
        e_turn = 2.0 * (ew * rsd + w * esd) + eal * rs + al * es
        e_spin = 2.0 * w * ew * rs + w * w * es
        e_acc = (ea + esdd + rsdd * eu + e_turn + abs(turn) * eu + e_spin + abs(spin) * eu
                 + 3.0 * U * (abs(a.real) + abs(a.imag) + 2.0 * rsdd + 3.0 * abs(turn)
                              + 3.0 * abs(spin)))
        return e_pos, e_vel, e_acc
