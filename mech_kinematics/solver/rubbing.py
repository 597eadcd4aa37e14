# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Pins and their rubbing velocity ``|omega_a - omega_b| r`` (seed 001)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, TYPE_CHECKING

import numpy as np

from .context import _Context, _U4
from .model import _check_length, _check_name, _names
from ..errors import SceneError

if TYPE_CHECKING:
    from .graph import Graph
    from .mechanism import Scene


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


class _RubStep:
    """The rubbing velocity ``|omega_a - omega_b| r`` of a pin of radius ``r`` (seed 001).

    A body is ``('link', name)`` (a link's angular velocity), ``('still', name)``
    (the ground or an RRP slider block: omega 0) or ``('block', lever)`` (an
    RPR block, turning with its lever; an intermittent lever's block touches
    the pin only while engaged, so the rubbing is 0 in a dwell, and at a mouth
    on the side the kinematics answer: ``driven``; the other in ``State.jumps``).
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
                # The side the kinematics answer (at a mouth, after the jump).
                engaged = ctx.engagement[name][2]
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


def _rub_steps(scene: Scene, kinds: dict[str, str], graph: Graph) -> tuple[_RubStep, ...]:
    """Return the rubbing step of every pin of ``scene``, checking the bodies it joins.

    A pin joins the bodies its point is fixed on (:class:`~.graph.Graph`): a
    link turns at its own rate, a block turns with the body it rides (an RPR
    block with its lever, only while a Geneva wheel's pin is engaged), the
    ground and a translating block not at all.
    """
    pins: tuple[Pin, ...] = tuple(getattr(scene, 'pins', ()))
    if not pins:
        return ()
    at: dict[str, dict[str, tuple[str, str]]] = {}  # point -> body name -> body
    # The links first (each turning on its own), then the blocks, then the ground.
    ground = graph.bodies[graph.ground]
    moving = [body for body in graph.bodies.values() if body is not ground]
    for body in sorted(moving, key=lambda b: b.turns_with != b.name):
        turns = body.turns_with
        kind = 'still' if turns is None else 'link' if turns == body.name else 'block'
        for point in body.points:
            at.setdefault(point, {})[body.name] = (kind, turns or body.name)
    for point in ground.points:
        if point in at:  # a ground point that some link turns about
            at[point][ground.name] = ('still', ground.name)
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
