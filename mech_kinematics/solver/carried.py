# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A point carried rigidly by a link (one module per kind, like the dyads)."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
import math
from typing import Any

from .base import Item, Names, Placing, Step
from .context import _Context, _fixed_on, _U16, _U4
from .graph import Fragment, Motion
from .model import _check_finite, _check_name, _names, SceneUnits, Where
from ..errors import SceneError


@dataclass(frozen=True)
class CarriedPoint(Item):
    """A point carried rigidly by ``link``.

    It lies at ``local`` (m) in the frame with origin at ``origin`` and x-axis
    toward ``xaxis``, both points on that link. The scene format's
    ``{from: F, toward: T, distance: d}`` is ``origin=F, xaxis=T,
    local=(d, 0)``.
    """

    kind = 'point'

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

    @property
    def key(self) -> str:
        """Return the point's name."""
        return self.name

    def defined(self) -> Iterator[tuple[str, str, Where]]:
        """Yield the point."""
        yield self.name, 'point', (self, 'name')

    def prerequisites(self, names: Names) -> set[str]:
        """Return its link and the two points its frame is built on."""
        return {names.link(self.link, f'the link of point "{self.name}"', (self, 'link')),
                names.point(self.origin, f'the origin of point "{self.name}"', (self, 'origin')),
                names.point(self.xaxis, f'the x-axis point of point "{self.name}"',
                            (self, 'xaxis'))}

    def place(self, plan: Placing) -> Step:
        """Return its step; check its frame's points are on its link, and fix it there."""
        fixed = plan.local[self.link]
        if self.origin not in fixed:
            msg = (f'Expected the origin of point "{self.name}" to be a point fixed on link '
                   f'"{self.link}" (one of {_names(fixed)}), got "{self.origin}"')
            raise SceneError(msg, (self, 'origin'))
        if self.xaxis in fixed:
            axis = fixed[self.xaxis] - fixed[self.origin]
            if axis == 0:
                msg = (f'Expected the origin and x-axis points of point "{self.name}" to be '
                       f'apart, got "{self.origin}" and "{self.xaxis}" coinciding')
                raise SceneError(msg, (self, 'xaxis'))
            axis /= abs(axis)
        elif plan.slot.get(self.link) == (self.origin, self.xaxis):
            axis = 1 + 0j  # from the lever's pivot toward its slot pin
        else:
            msg = (f'Expected the x-axis point of point "{self.name}" to be a point on link '
                   f'"{self.link}", got "{self.xaxis}"')
            raise SceneError(msg, (self, 'xaxis'))
        offset = fixed[self.origin] + complex(*self.local) * axis
        base = next(iter(fixed))  # the link's start, at 0, comes first
        fixed[self.name] = offset
        return _CarryStep(self, base, offset)

    def scaled(self, scale: Callable[[float], float]) -> CarriedPoint:
        """Return it with its local coordinates scaled."""
        return replace(self, local=(scale(self.local[0]), scale(self.local[1])))

    def toggle(self) -> None:
        """Return ``None``: it has no measure (it cannot fail to close)."""
        return None

    def lengths(self) -> tuple[float, ...]:
        """Return no length: its place on its link counts in its link's, not in the size."""
        return ()

    @staticmethod
    def fact_texts() -> dict[str, Callable[[dict[str, Any], SceneUnits], str]]:
        """Return none: its errors carry no facts (their reason is their text)."""
        return {}

    def fragment(self) -> Fragment:
        """Return its part of the graph: the point fixed on its link, moving about its origin."""
        return Fragment(self.name, carried=((self.link, self.name),),
                        motions=(Motion(self.link, self.origin, self.name),))


class _CarryStep(Step):
    """A point fixed on a link, from the link's motion and its frame's origin."""

    def __init__(self, point: CarriedPoint, base: str, local: complex) -> None:
        self.point = point.name
        self.link = point.link
        self.base = base  # the origin of the link's frame
        self.along, self.across = local.real, local.imag
        self.uses = (base,)
        self.dyad = point
        self.owner = point.link
        self.defines = self.new_points = (point.name,)
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
        ctx.points[self.point] = _fixed_on(p, v, a, ep, ev, ea, r, er, omega, alpha, ew, eal,
                                           radius)
