# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The intermittent (Geneva) lever: an RPR whose wheel has ``slots``, driven only while engaged.

Its item is :class:`~.rpr.RPR` with ``slots``; this module holds its step,
the check of its tangential entry, and its :class:`~.state.Engagement`.
"""

from __future__ import annotations

from collections.abc import Callable
import math
from typing import Any, cast

import numpy as np

from .base import Placing
from .context import _Context, _U2, _U4, _U7
from .model import _names, SceneUnits
from .rpr import _RPRStep, RPR
from .state import Engagement
from ..bounds import ROUNDING_MARGIN, U
from ..errors import SceneError
from ..units import LENGTH_UNITS

#: An intermittent lever's pin must enter its slots tangentially: the crank
#: radius R of the pin and the centre distance l must satisfy
#: ``|R / l - sin(pi / n)| <= TANGENCY_TOLERANCE * sin(pi / n)``.
TANGENCY_TOLERANCE = 1e-9


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

    Within rounding of a slot's mouth (an engagement instant, where the
    wheel's angular acceleration jumps between 0 and ``-+omega^2 tan(pi /
    n)``) the answer is the side *after* the jump in the direction the crank
    turns (increasing angle for a crank at rest): engaged or held, its
    acceleration the one-sided limit with its own bound; position and
    velocity, continuous there, keep bounds that cover both sides. The
    instant is recorded (``ctx.jump``); a context with ``flip`` set
    answers the side before the jump instead (how :func:`~.solve.solve`
    finds the other side of every value that jumps). Which side is
    answered is recorded too (``ctx.engage``'s ``driven``,
    ``Engagement.driven``): the forces read it to let the slot carry the
    wheel or the lock hold it, so at the exit turning forward the lock
    holds, as the wheel is at rest.
    """

    intermittent = True

    def __init__(self, dyad: RPR, center: complex, size: float, crank: str,
                 crank_center: complex, pin: complex) -> None:
        super().__init__(dyad, center, size)
        n = cast(int, dyad.slots)
        self.slots = n
        self.crank = crank  # the driving crank's link: its speed says which side is after
        toward = center - crank_center  # from the crank's centre to the wheel's
        distance = abs(toward)
        # Window 0 is centred on the crank angle that points the pin at the wheel.
        beta = math.atan2(pin.imag, pin.real)
        self.phase0 = math.atan2(toward.imag, toward.real) - beta
        self.half = math.pi / 2 - math.pi / n  # half the crank's engaged angle
        self.tan = math.tan(math.pi / n)  # R / (slot mouth): the acceleration's jump / omega^2
        # The jump omega^2 tan(pi / n), relative: pi / n's rounding (2 U) through tan's
        # slope, tan to an ulp (2 U), omega to U (the crank's bound) squared, two products.
        x = math.pi / n
        self.e_jump = U * (2.0 * x * (1.0 + self.tan * self.tan) / self.tan + 2.0) + _U4
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

    def mouth(self, r: Any, er: Any) -> Any:
        """Return whether an offset ``r`` in a window (bound ``er``) is within rounding of a mouth.

        There the wheel's angular acceleration jumps: an engagement instant.
        """
        return abs(abs(r) - self.half) <= ROUNDING_MARGIN * (er + self.e_half)

    def run(self, ctx: _Context) -> None:
        """Run the plain RPR's kernel, then index its motion by the crank's window."""
        _RPRStep.run(self, ctx)
        if ctx.vector:
            self.run_array(ctx)
        else:
            self.run_one(ctx)

    @classmethod
    def kernels(cls) -> tuple[Callable[..., None], ...]:
        """Return the plain RPR's kernel and :meth:`run_one`: ``run`` on one crank angle."""
        return (_RPRStep.run, cls.run_one)

    def run_array(self, ctx: _Context) -> None:
        """Index the lever's engaged motion by the crank's window, for an array of angles."""
        n = self.slots
        engaged, window, r, er = self.window(ctx.angle, ctx.turns, ctx.vector)
        near = self.mouth(r, er)
        e, w, al, ee, ew, eal = ctx.links[self.link]
        m = np.mod(window, n)
        side = np.mod(2 * window + np.where(r > 0.0, 1, -1), 2 * n)
        t = self.turn_array[m]
        held = self.held_array[side]
        # The engaged direction turned back by 2 pi m / n, in real arithmetic (same bits).
        turned = (e.real * t.real - e.imag * t.imag) + 1j * (e.real * t.imag + e.imag * t.real)
        e_turn, e_held = self.e_turn_array[m], self.e_held_array[side]
        if near.any():
            # An engagement instant: the side after the jump in the crank's sense of
            # motion (the pin entering at r = -half when it turns forward), or before
            # it for a flipped context; the acceleration its one-sided limit.
            crank = ctx.links[self.crank][1]
            after = (r < 0.0) == (crank >= 0.0)
            inside = np.where(near, after != ctx.flip, engaged)
            jump = crank * crank * self.tan
            limit = np.where(r < 0.0, -jump, jump)
            diff = turned - held
            gap = abs(diff.real) + abs(diff.imag)
            entry: tuple[Any, ...] = (
                np.where(inside, turned, held), np.where(inside, w, 0.0),
                np.where(inside, np.where(near, limit, al), 0.0),
                np.where(near, ee + e_turn + e_held + gap,
                         np.where(inside, ee + e_turn, e_held)),
                np.where(near, ew + abs(w), np.where(inside, ew, 0.0)),
                np.where(inside, np.where(near, self.e_jump * jump, eal), 0.0))
            ctx.jump(self.link, near)
            ctx.engage(self.link, engaged | near, window, inside)
        else:
            ctx.engage(self.link, engaged, window, engaged)
            entry = (
                np.where(engaged, turned, held), np.where(engaged, w, 0.0),
                np.where(engaged, al, 0.0), np.where(engaged, ee + e_turn, e_held),
                np.where(engaged, ew, 0.0), np.where(engaged, eal, 0.0))
        ctx.links[self.link] = entry

    def offset(self, angle: float, turns: int) -> tuple[int, float, float]:
        """Return (window, offset in the window, its error bound) at one crank angle."""
        d = angle - self.phase0
        q = round(d / math.tau)  # an int: q * tau and abs(q) * e_q round as the float's would
        r = d - q * math.tau
        er = U * (abs(angle) + abs(d) + abs(r)) + self.e_phase + abs(q) * self.e_q
        return turns + q, r, er

    def jumps_at(self, angle: float, turns: int) -> bool:
        """Return whether one crank angle is an engagement instant (see :meth:`mouth`)."""
        _, r, er = self.offset(angle, turns)
        return bool(self.mouth(r, er))

    def jumps_over(self, angle: Any, turns: Any) -> Any:
        """Return where an array of crank angles are engagement instants (``ctx.jump``'s mask)."""
        _, _, r, er = self.window(angle, turns, True)
        return self.mouth(r, er)

    def run_one(self, ctx: _Context) -> None:
        """Do :meth:`run_array` for one crank angle: the same operations, only those it needs."""
        window, r, er = self.offset(ctx.angle, ctx.turns)
        engaged = abs(r) <= self.half
        near = self.mouth(r, er)
        n = self.slots
        e, w, al, ee, ew, eal = ctx.links[self.link]
        if near:
            # An engagement instant (see run): the side after the jump, or before it.
            crank = ctx.links[self.crank][1]
            engaged = ((r < 0.0) == (crank >= 0.0)) != ctx.flip
            jump = crank * crank * self.tan
            ctx.jump(self.link, True)
        # In the slot (its mouth included), and whether the pin drives the wheel on the
        # side answered (else the lock holds it): what the forces act on.
        ctx.engage(self.link, engaged or near, window, engaged)
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
            # Position and velocity are continuous: their bounds cover both sides.
            side = (2 * window + (1 if r > 0.0 else -1)) % (2 * n)
            diff = turned - self.held[side]
            gap = abs(diff.real) + abs(diff.imag)
            limit = -jump if r < 0.0 else jump
            entry = (entry[0], entry[1], limit if engaged else 0.0,
                     ee + self.e_turn[m] + self.e_held[side] + gap, ew + abs(w),
                     self.e_jump * jump if engaged else 0.0)
        ctx.links[self.link] = entry

    def engagement(self, ctx: _Context, omega: Any, finish: Any) -> Engagement:
        """Return where the lever is in its cycle (see :class:`Engagement`)."""
        engaged, window, driven = ctx.engagement[self.link]
        centre = self.phase0 + (window.astype(np.float64) if ctx.vector
                                else float(window)) * math.tau
        entry, exit_ = centre - self.half, centre + self.half
        jump = omega * omega * self.tan
        zero = 0.0 * jump
        if finish is not None:
            entry, exit_, jump, zero = finish(entry), finish(exit_), finish(jump), finish(zero)
            engaged = np.broadcast_to(engaged, np.shape(entry))
            driven = np.broadcast_to(driven, np.shape(entry))
        # The fields go straight in, as in _new_state: a frozen dataclass's __init__ costs 1 us.
        record = object.__new__(Engagement)
        record.__dict__.update(engaged=engaged, window=window, entry=entry, exit=exit_,
                               entry_acceleration=(zero, -jump), exit_acceleration=(jump, zero),
                               driven=driven)
        return record


def _index_step(plan: Placing, item: RPR) -> _IndexStep:
    """Return the step of an intermittent lever; check its pin and its tangential entry."""
    scene, ground, size = plan.scene, plan.ground, plan.size
    crank = scene.input
    if crank is None or len(scene.drivers) != 1:
        msg = (f'Expected the intermittent RPR "{item.link}" in a scene driven by one crank, '
               f'got {len(scene.drivers)} drivers')
        raise SceneError(msg, (item, 'slots'))
    crank_local = plan.local[crank.link]
    units: SceneUnits = getattr(scene, 'units', SceneUnits())
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
    return _IndexStep(item, wheel, size, crank.link, centre, pin)
