# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The context of one solve (the values known so far, with bounds) and the roundoff constants.

How the bounds are built (:mod:`mech_kinematics.bounds` says what they mean):
each step bounds the error of its outputs, first order, from the bounds of its
inputs and its own rounding (see the comment above ``_U2``).
"""

from __future__ import annotations

from fractions import Fraction
import math
from typing import Any


from ..bounds import ROUNDING_MARGIN, U
from ..errors import AssemblyError, UntrustedError

#: A dyad whose near-singularity measure falls below this is flagged as
#: near-singular (:class:`NearSingularWarning`); its velocities lose up to about
#: ``2 * -log10(measure)`` digits (near a toggle the condition number grows as
#: ``1 / measure**2``) and its accelerations up to three times ``-log10(measure)``.
NEAR_SINGULAR = 1e-3
#: At or below this measure a dyad is treated as singular and not solved.
SINGULAR = 1e-12


#: The empty table a solve's optional entries start from; replaced, never mutated.
_NOTHING: dict[str, Any] = {}


class _Context:
    """Values known so far in one solve; complex numbers or complex arrays.

    Every entry carries the error bounds of its values (see :mod:`.bounds`):
    ``points[name] = (p, v, a, bound p, bound v, bound a)``, likewise
    ``links[name] = (e, omega, alpha, ...)`` with ``e`` the unit vector along the
    link, and ``sliders[name] = (s, sd, sdd, ...)``.
    """

    __slots__ = ('angle', 'turns', 'shown', 'vector', 'points', 'links', 'sliders', 'measures',
                 'valid', 'failures', 'engagement', 'rubbing', 'notes', 'flip', 'jumps', 'sums')

    def __init__(self, angle: Any, vector: bool, turns: Any = 0, flip: bool = False) -> None:
        self.angle = angle
        self.turns = turns  # whole crank turns to add to angle (intermittent drives only)
        # The crank angle counted from the start, for messages (scalar path).
        self.shown = angle if vector or turns == 0 else angle + math.tau * turns
        self.vector = vector
        self.points: dict[str, tuple[Any, Any, Any, Any, Any, Any]] = {}
        self.links: dict[str, tuple[Any, Any, Any, Any, Any, Any]] = {}
        self.sliders: dict[str, tuple[Any, Any, Any, Any, Any, Any]] = {}
        self.measures: dict[str, Any] = {}
        self.valid: Any = True
        self.failures: dict[str, Any] = {}
        # Filled by the steps that have them (shared empty until then: never mutated).
        # lever -> (engaged, window, driven): see Engagement.
        self.engagement: dict[str, tuple[Any, Any, Any]] = _NOTHING
        self.rubbing: dict[str, tuple[Any, Any]] = _NOTHING  # pin -> (value, bound)
        self.notes: dict[str, str] = _NOTHING  # label -> why a bound is large (scalar path)
        # At a jump (an engagement instant) the steps answer the side after it; with
        # flip, the side before it. jumps: lever -> where it jumps (True, or a mask).
        self.flip = flip
        self.jumps: dict[str, Any] = _NOTHING
        # A compiled array solve's reported bounds summed per kind, for the quick judgement
        # (:class:`.compiler.Array`): the kinds, and a table of one row each; None
        # elsewhere.
        self.sums: tuple[tuple[str, ...], Any] | None = None

    def jump(self, lever: str, where: Any) -> None:
        """Record that ``lever``'s values jump at the instant (``where``: True, or a mask).

        The step answered the side after the jump (before it where ``flip``).
        """
        if self.jumps is _NOTHING:
            self.jumps = {}
        self.jumps[lever] = where

    def engage(self, lever: str, engaged: Any, window: Any, driven: Any) -> None:
        """Record where an intermittent lever is in its cycle (the tick drops it).

        ``engaged``: its pin is in a slot (a mouth included); ``driven``: the
        values answer the side where the pin drives it (else a lock holds it),
        ``engaged`` but at a jump, where it is the side answered.
        """
        if self.engagement is _NOTHING:
            self.engagement = {}
        self.engagement[lever] = (engaged, window, driven)

    def note(self, label: str, why: Any) -> None:
        """Record why a dyad's bound is large, for a refusal's message (the tick drops it).

        ``why`` is a callable returning the text, called at once: the scalar
        path only notes where it is near a limit.
        """
        if self.notes is _NOTHING:
            self.notes = {}
        self.notes[label] = why()

    def check(self, ok: Any, label: str, reason: Any, facts: Any = None) -> None:
        """Stop a scalar solve where ``ok`` fails; mask the entries of a vector solve.

        ``reason`` and ``facts`` are callables, called only to raise: the
        message and the failure's facts for :class:`AssemblyError`.
        """
        if not self.vector:
            if not ok:
                raise AssemblyError(label, self.shown, reason(),
                                    facts=None if facts is None else facts())
            return
        self.mask(ok, label)

    def mask(self, ok: Any, label: str) -> None:
        """Mark the entries of a vector solve where ``ok`` fails as failed under ``label``."""
        if not ok.all():
            failed = ~ok & self.valid
            self.valid = self.valid & ok
            if failed.any():
                previous = self.failures.get(label)
                self.failures[label] = failed if previous is None else previous | failed

    def check_margin(self, ok: Any, label: str, margin: Any, bound: Any, reason: Any,
                     facts: Any = None) -> None:
        """Like :meth:`check` for a dyad within rounding of an assembly limit (untrusted)."""
        if not self.vector:
            if not ok:
                raise UntrustedError(label, self.shown, reason(), 'margin', float(bound),
                                     float(margin) / ROUNDING_MARGIN,
                                     facts=None if facts is None else facts())
            return
        self.mask(ok, label)


def _dot(a: Any, b: Any) -> Any:
    return a.real * b.real + a.imag * b.imag


def _cross(a: Any, b: Any) -> Any:
    return a.real * b.imag - a.imag * b.real


def _sum_root(x: Fraction, square: Fraction) -> float:
    """Return ``x + sqrt(square)`` for an exact ``x`` without cancellation (to a few ulp)."""
    root = math.sqrt(square)
    if x >= 0:
        return float(x) + root
    return float(square - x * x) / (root - float(x))


# Multiples of the unit roundoff used by the bounds.
_U2, _U3, _U4, _U5, _U7, _U16 = (n * U for n in (2, 3, 4, 5, 7, 16))


# The motion of a point ``r`` from a point known as (p, v, a) with bounds (ep, ev, ea), fixed on a
# link turning at (omega, alpha) with rate bounds (ew, eal): the point with its bounds, ``er``
# bounding the error of ``r`` and ``radius`` its length. The sums round by U |p| (in ep), U |v|
# and 2 U |a| (and U |r| terms, in er). A carried point's, a hinge's tip and a fold's knee; a
# one-line helper, so the compiler writes it out in place.
def _fixed_on(p: Any, v: Any, a: Any, ep: Any, ev: Any, ea: Any, r: Any, er: Any, omega: Any,
              alpha: Any, ew: Any, eal: Any, radius: Any) -> tuple[Any, ...]:
    return (p + r, v + 1j * omega * r, a + 1j * alpha * r - omega * omega * r,
            2.0 * ep + er, ev + U * (abs(v.real) + abs(v.imag)) + ew * radius + abs(omega) * er,
            ea + _U2 * (abs(a.real) + abs(a.imag)) + (eal + (2.0 * abs(omega) + ew) * ew) * radius
            + (abs(alpha) + abs(omega) * abs(omega)) * er)

# How the bounds below are built (bounds.py says what they mean). Each step
# bounds the error of its outputs, first order, from the bounds of its inputs
# (the points it starts from, the scene's constants rounded to doubles) and
# its own rounding. A dyad's rounding is counted as a perturbation of its
# inputs (its closed forms are backward stable), amplified like an input's
# error by the dyad's sensitivity: ``1 / measure`` for an RRR's or RRP's
# positions and for the rows of its two-by-two velocity and acceleration
# systems, ``1 / s`` for an RPR. The rounding of the final sums and products
# adds a few ``U`` of their terms' magnitudes; a point's position bound is kept
# at least ``U |p|``, so a later sum's rounding is covered by its operand's
# bound without computing a norm; where a velocity's or acceleration's size is
# needed, ``|x| + |y| >= |z|`` stands for it. Every bound is a sum of products
# of real magnitudes, never a complex norm (NumPy's may differ from Python's by
# an ulp): the same bits on both paths.
