# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The fold: a loop re-rooted at a driven pin between two moving links (issue 41).

A four-bar driven at its coupler-to-rocker pin: the crank ``links[0]`` runs
from a known point ``A`` to the pin ``point`` (B), the rocker ``links[1]``
from a known point ``D`` to the driven pin ``pin`` (C), and the coupler
(``coupler``) joins C to B, turned relative to the rocker by a motor (a
driver of the scene's ``inputs``, ``motor: NAME``: the coupler's axis C->B
from the rocker's D->C, as a hinge's). Neither the coupler nor the rocker is
placed before the driven joint: the motor's value fixes the shape of the two
as one body, so the loop is solved from that joint (the Assur decomposition
of the same graph with another driver).

In the rocker's frame (origin D, x toward C) the fused body's far pin is at
``w = c + b exp(i q)`` (``b``, ``c`` the coupler's and the rocker's
lengths, ``q`` the motor's angle), so ``|DB| = d = |w|``: B is where the
circles about A (radius ``a``) and D (radius ``d``) meet, the actuated RRR's
closed form with ``d`` its variable length (:mod:`.rrr`), with
``d' = -b c sin(q) q' / d`` and ``d'' = (-b c (cos(q) q'^2 + sin(q) q'') -
d'^2) / d``. The rocker's angle is the fused direction D->B less ``psi =
arg(w)``, whose rates are ``psi' = f q'`` and ``psi'' = f q'' + f' q'^2``
with ``f = b (b + c cos q) / d^2`` and ``f' = b c sin(q) (b^2 - c^2) / d^4``;
the coupler's is the rocker's plus ``q``; C is ``D + c`` along the rocker.
The bounds follow each of these first-order (the inputs' bounds through the
derivatives above, and a few ulps of rounding), those of B and of the fused
direction the actuated RRR's, with ``d``'s bounds as its length's.

Where the coupler folds back onto the rocker with ``b = c`` (``d`` within
rounding of 0) the fused direction is undefined: refused in one line, as a
singular point. ``branch``: the side of the line A->D that B is on, an RRR's.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .base import Item, Names, Placing, Reading, Step
from .context import _Context, _fixed_on, _U2, _U4, _U7, SINGULAR
from .graph import Body, Fragment, Frame, Motion, pin, REVOLUTE, Role
from .model import _check_length, _check_name, Branch, Link, SceneUnits, Where
from .rrr import _ActuatedRRRStep, RRR
from ..bounds import U
from ..errors import SceneError

#: The scene keys of a fold in ``dyads:``.
KEYS = {'type', 'point', 'pin', 'links', 'coupler', 'motor', 'branch'}


@dataclass(frozen=True)
class Fold(Item):
    """A crank and a rocker from known points, joined by a coupler a motor turns on the rocker.

    Parameters
    ----------
    point : str
        The pin B of the crank and the coupler (new).
    pin : str
        The driven pin C of the rocker and the coupler (new): the motor's joint.
    links : (Link, Link)
        The crank (from a known point to ``point``) and the rocker (from a
        known point to ``pin``).
    coupler : str
        The coupler's name (a revolute output joint: its absolute angle).
    length : float
        The coupler's length, C to B, m.
    motor : str
        A motor of the scene's ``inputs``: the coupler's angle from the rocker's axis.
    branch : Branch
        The side of the line between the two starts that ``point`` is on.
    """

    kind = 'fold'

    point: str
    pin: str
    links: tuple[Link, Link]
    coupler: str
    length: float
    motor: str
    branch: Branch = Branch.PLUS

    def __post_init__(self) -> None:
        """Validate the fields."""
        what = f'fold "{self.point}"'
        _check_name(self.point, 'a fold point', (self, 'point'))
        _check_name(self.pin, f'the driven pin of {what}', (self, 'pin'))
        _check_name(self.coupler, f'the coupler of {what}', (self, 'coupler'))
        _check_name(self.motor, f'the motor of {what}', (self, 'motor'))
        _check_length(self.length, f'{what} coupler length', (self, 'length'))
        count = len(self.links)  # anything may be passed at run time
        if count != 2:
            msg = f'Expected {what} to have 2 links (a crank and a rocker), got {count}'
            raise SceneError(msg, (self, 'links'))
        object.__setattr__(self, 'branch', Branch(self.branch))

    @classmethod
    def from_scene(cls, read: Reading, raw: Any, where: str) -> Fold:
        """Return the fold at ``where``: point, pin, links (two), coupler, motor, branch.

        ``links[0]`` runs from a known point to ``point``, ``links[1]`` to
        ``pin``; ``coupler: {name, length}`` joins ``pin`` to ``point``.
        """
        read.check_keys(raw, KEYS, where)
        pair = read.links(raw, where, 2, 'a crank to the point and a rocker to the driven pin')
        coupler = read.get(raw, 'coupler', where)
        at = f'{where}.coupler'
        if not isinstance(coupler, dict):
            raise SceneError(f'{at}: expected a mapping {{name, length}}, got '
                             f'{read.brief(coupler)}')
        read.check_keys(coupler, {'name', 'length'}, at)
        built: Fold = read.build(
            where, {'coupler': 'coupler.name', 'length': 'coupler.length'}, cls,
            point=read.name(raw, 'point', where), pin=read.name(raw, 'pin', where),
            links=pair, coupler=read.name(coupler, 'name', at),
            length=read.length(coupler, 'length', at), motor=read.name(raw, 'motor', where),
            branch=read.branch(raw, where))
        return built

    @staticmethod
    def fact_texts() -> dict[str, Callable[[dict[str, Any], SceneUnits], str]]:
        """Return none of its own: the circles' texts are the RRR's (registered there)."""
        return {}

    @property
    def key(self) -> str:
        """Return its new point B."""
        return self.point

    def defined(self) -> Iterator[tuple[str, str, Where]]:
        """Yield its two pins and its three links."""
        yield self.point, 'point', (self, 'point')
        yield self.pin, 'point', (self, 'pin')
        for link in self.links:
            yield link.name, 'link', (link, 'name')
        yield self.coupler, 'link', (self, 'coupler')

    def prerequisites(self, names: Names) -> set[str]:
        """Check its links' starts and its motor; return them."""
        what = f'fold "{self.point}"'
        kind = names.kinds.get(self.motor)
        if kind != 'motor':
            got = f'unknown "{self.motor}"' if kind is None else f'{kind} "{self.motor}"'
            msg = f'Expected the motor of {what} to be a motor of inputs, got {got}'
            raise SceneError(msg, (self, 'motor'))
        return {*(names.point(link.start, f'the start of link "{link.name}"', (link, 'start'))
                  for link in self.links), self.motor}

    def place(self, plan: Placing) -> Step:
        """Return its step; each link carries its two pins."""
        crank, rocker = self.links
        plan.local[crank.name] = {crank.start: 0j, self.point: complex(crank.length)}
        plan.local[rocker.name] = {rocker.start: 0j, self.pin: complex(rocker.length)}
        plan.local[self.coupler] = {self.pin: 0j, self.point: complex(self.length)}
        return _FoldStep(self)

    def lengths(self) -> tuple[float, ...]:
        """Return the crank's, the rocker's and the coupler's lengths."""
        return (*(link.length for link in self.links), self.length)

    def scaled(self, scale: Callable[[float], float]) -> Fold:
        """Return it with every length scaled."""
        crank, rocker = (replace(link, length=scale(link.length)) for link in self.links)
        return replace(self, links=(crank, rocker), length=scale(self.length))

    def fragment(self) -> Fragment:
        """Return its part of the graph: three links, the coupler on the rocker by the motor."""
        crank, rocker = self.links
        bodies = (Body(crank.name, Role.LINK, (crank.start, self.point),
                       Frame(crank.start, crank.name), length=crank.length),
                  Body(rocker.name, Role.LINK, (rocker.start, self.pin),
                       Frame(rocker.start, rocker.name), length=rocker.length),
                  Body(self.coupler, Role.LINK, (self.pin, self.point),
                       Frame(self.pin, self.coupler), length=self.length))
        joints = (pin(crank.name, crank.start), pin(rocker.name, rocker.start),
                  pin(self.coupler, self.pin, on=rocker.name, driver=True, name=self.motor),
                  pin(self.coupler, self.point, on=crank.name))
        return Fragment(self.point, bodies, joints,
                        {crank.name: REVOLUTE, rocker.name: REVOLUTE, self.coupler: REVOLUTE},
                        (Motion(crank.name, crank.start, self.point),
                         Motion(rocker.name, rocker.start, self.pin),
                         Motion(self.coupler, self.pin, self.point)))

    def toggle(self) -> tuple[str, str, tuple[str, ...]]:
        """Return its measure (the sine of the angle between the crank and D->B) and links."""
        return self.point, f'fold {self.point}', tuple(link.name for link in self.links)


class _FoldStep(_ActuatedRRRStep):
    """The fold's kernel: ``|DB|`` from the motor, the actuated RRR, then rocker and coupler."""

    def __init__(self, fold: Fold) -> None:
        crank, rocker = fold.links
        # The RRR of the crank and the fused body D->B (its length |DB| the motor's
        # function, passed through ctx.sliders under a key no scene name can take).
        fused = RRR(fold.point, (crank, rocker), fold.branch, (None, fold.motor))
        super().__init__(fused)
        self.dyad = fold
        self.label = f'fold {fold.point}'
        self.act2: str = f'{fold.motor} |{rocker.start}{fold.point}|'
        self.motor, self.pin, self.coupler = fold.motor, fold.pin, fold.coupler
        self.rocker, self.rocker_start = rocker.name, rocker.start
        self.b, self.c = fold.length, rocker.length
        self.bc = fold.length * rocker.length
        self.b2_c2 = (fold.length - rocker.length) * (fold.length + rocker.length)
        self.folded = SINGULAR * (fold.length + rocker.length)
        self.e_w = _U2 * (fold.length + rocker.length)
        self.uses = (crank.start, rocker.start, fold.motor)
        self.defines = (fold.point, fold.pin, crank.name, rocker.name, fold.coupler)
        self.new_points = (fold.point, fold.pin)

    def facts_at(self, dist: float, l1: float, l2: float, touching: bool,
                 margin: float = 0.0, inputs: float = 0.0) -> dict[str, Any]:
        """Return why the circles do not meet: the second is the rocker and coupler as one."""
        facts = super().facts_at(dist, l1, l2, touching, margin, inputs)
        facts['links'] = (self.link1, f'{self.rocker} with {self.coupler}')
        return facts

    def run(self, ctx: _Context) -> None:
        m, qd, qdd, em, eqd, eqdd = ctx.links[self.motor]
        b, c, bc = self.b, self.c, self.bc
        w = c + b * m                    # D->B in the rocker's frame (x along D->C)
        d = np.hypot(w.real, w.imag) if ctx.vector else abs(w)
        ok = d > self.folded
        if ctx.vector or not ok:
            ctx.check(ok, self.label, lambda: (
                f'the coupler {self.coupler} folds onto the rocker {self.rocker} (singular: '
                f'|{self.rocker_start}{self.point}| = {d * self.unit:.3g} m, the direction '
                f'from {self.rocker_start} to {self.point} is not defined)'))
        d = np.where(ok, d, 1.0) if ctx.vector else d
        inv_d = 1.0 / d
        s, co = m.imag, m.real
        dd = -bc * s * qd * inv_d
        ddd = (-bc * (co * qd * qd + s * qdd) - dd * dd) * inv_d
        # d's bounds: w moves by b em and its rounding; the rates through their partials.
        ew = b * em + self.e_w
        ed = ew + U * d
        aqd, add = abs(qd), abs(dd)
        edd = (bc * (em * aqd + abs(s) * eqd) + add * ed) * inv_d + _U4 * add
        eddd = ((bc * (em * (qd * qd + abs(qdd)) + 2.0 * abs(co) * aqd * eqd + abs(s) * eqdd)
                 + 2.0 * add * edd + abs(ddd) * ed) * inv_d
                + _U7 * (abs(ddd) + (bc * (qd * qd + abs(qdd)) + dd * dd) * inv_d))
        ctx.sliders[self.act2] = (d, dd, ddd, ed, edd, eddd)
        self._actuated(ctx)
        e2, w2, al2, ee2, ew2, eal2 = ctx.links[self.rocker]   # the fused direction D->B
        # psi = arg(w): the rocker is D->B turned back by it.
        inv_d2 = inv_d * inv_d
        f = b * (b + c * co) * inv_d2
        df = bc * s * self.b2_c2 * inv_d2 * inv_d2
        psi_d = f * qd
        psi_dd = f * qdd + df * qd * qd
        u = w.conjugate() * inv_d
        er = e2 * u
        ef = (bc * em + 2.0 * abs(f) * d * ed) * inv_d2 + _U4 * abs(f)
        edf = (abs(bc * self.b2_c2) * (em + 4.0 * abs(s) * ed * inv_d) * inv_d2 * inv_d2
               + _U7 * abs(df))
        ee_r = ee2 + 2.0 * ew * inv_d + _U4
        omega = w2 - psi_d
        alpha = al2 - psi_dd
        ew_r = ew2 + aqd * ef + abs(f) * eqd + U * (abs(omega) + 2.0 * abs(psi_d))
        eal_r = (eal2 + abs(qdd) * ef + abs(f) * eqdd + qd * qd * edf + 2.0 * aqd * eqd * abs(df)
                 + U * (abs(alpha) + 4.0 * abs(psi_dd)))
        ctx.links[self.rocker] = (er, omega, alpha, ee_r, ew_r, eal_r)
        # The coupler's angle is the rocker's plus the motor's (e = er m, hinge.py's rule).
        ec = er * m.real + (1j * er) * m.imag
        wc, ac = omega + qd, alpha + qdd
        ctx.links[self.coupler] = (ec, wc, ac, ee_r + em + _U4, ew_r + eqd + U * abs(wc),
                                   eal_r + eqdd + U * abs(ac))
        p, v, a, ep, ev, ea = ctx.points[self.rocker_start]
        r = c * er
        er_c = c * ee_r + _U2 * c
        ctx.points[self.pin] = _fixed_on(p, v, a, ep, ev, ea, r, er_c, omega, alpha, ew_r, eal_r,
                                         c)
