# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""One answer from every door: the wrap of a revolute value, and the assembly the loops answer.

Every door (``Robot.solve``, ``solve ROBOT.urdf``, the node in URDF mode)
answers through this module, so that the same actuated values give the same
joint values, bit for bit (docs/urdf.md, "Names and signs" and "Which
assembly").

**The wrap.** A revolute joint's value solved by a loop is known up to whole
turns; :func:`wrap_revolute` is the one place it is reduced: to ``(c - pi,
c + pi]`` with ``c`` the middle of the joint's ``<limit>``
(:func:`revolute_centre`; 0 for a continuous joint or one without limits),
so that the value reported is within the limits wherever an equivalent one
is. The reduction is exact (``fmod``, then one exact step of a turn), the
same bits for a float and for an array.

**The assembly.** Each dyad of a loop keeps the reference pose's branch
(the continuation of the zero pose, or of the reference pose given), except
where the URDF's ``<mimic>`` rules relate the loop's joints: there the
assembly answered is the one whose joints keep their rules (a parallelogram
stays a parallelogram through its change points, where the branch that
keeps it changes sign). :class:`Assemblies` says, for one instant (or each
of an array of them), which assembly that is: the reference branches unless
a loop's rules stray from them, else the branches of the loop, among the
reference's and each flip of up to :data:`MAX_FLIPS` of its dyads, whose
joints are nearest their rules (by more than ``MIMIC_TOLERANCE``, else the
earlier: the reference first). Pure: NumPy and the solver's scenes only.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
import copy
from dataclasses import fields, is_dataclass, replace
from itertools import combinations
import math
from typing import Any

import numpy as np

__all__ = ['Assemblies', 'MAX_FLIPS', 'pick', 'revolute_centre', 'wrap_revolute']

#: A loop whose rules pick its assembly tries every flip of up to this many of its dyads.
MAX_FLIPS = 3
_PI = math.pi
_TAU = math.tau


def wrap_revolute(value: Any, centre: float = 0.0) -> Any:
    """Return the angle equivalent to ``value`` in ``(centre - pi, centre + pi]`` (rad).

    The one wrap of every revolute value answered (a loop's passive joint, a
    mimic's stray): ``value - centre`` reduced exactly by ``fmod`` and one
    exact step of ``tau`` (Sterbenz), then ``centre`` added back; a float
    for a float, an array for an array, the same bits for each. A value
    that is not finite gives NaN.
    """
    if isinstance(value, np.ndarray):
        with np.errstate(invalid='ignore'):
            r = np.fmod(value - centre, _TAU)
        r = np.where(r > _PI, r - _TAU, np.where(r <= -_PI, r + _TAU, r))
        return centre + r
    x = value - centre
    if not math.isfinite(x):
        return math.nan
    r = math.fmod(x, _TAU)
    if r > _PI:
        r -= _TAU
    elif r <= -_PI:
        r += _TAU
    return centre + r


def revolute_centre(joint: Any) -> float:
    """Return the middle of a revolute joint's ``<limit>``: 0 for a continuous joint or none."""
    if joint.limits is None or joint.urdf_type == 'continuous':
        return 0.0
    return 0.5 * (joint.limits[0] + joint.limits[1])


def _names_in(item: Any) -> set[str]:
    """Return every string in a scene mapping's item (its links' names among them)."""
    if isinstance(item, str):
        return {item}
    if isinstance(item, Mapping):
        return set().union(*(_names_in(v) for v in item.values()))
    if isinstance(item, (list, tuple)):
        return set().union(*(_names_in(v) for v in item))
    return set()


class Assemblies:
    """Which assembly a robot's loops answer at an instant (see the module's docstring).

    Parameters
    ----------
    robot : Robot
        Its planar loops (``planar``), its rules (``_rules``: every answered
        joint's ``<mimic>`` whose leader is answered) and its joint types.
    tolerance : float
        A loop's rules are kept within this (rad or m): ``MIMIC_TOLERANCE``.

    Attributes
    ----------
    ruled : tuple of dict
        The loops whose rules pick their assembly: per loop its
        ``mechanism`` index, its ``rules`` (joint -> rule) and its
        ``patterns`` (the sets of its dyads' points flipped; the first empty).
    zero : tuple of int
        The reference assembly: pattern 0 of every ruled loop.
    """

    def __init__(self, robot: Any, tolerance: float) -> None:
        self.tolerance = tolerance
        self._types = {n: robot.joint_type(n) for n in robot.joint_names}
        planar = robot.planar
        given = set(robot.actuated) | {d.name for d in planar.drivers}
        solved = {n: item.mechanism for n, item in planar.joints.items() if n not in given}
        bodies = [set(m['bodies']) for m in planar.mechanisms]
        flippable: dict[int, list[str]] = {}
        for dyad in planar.data.get('dyads', ()):
            if 'branch' not in dyad:
                continue
            names = _names_in(dyad)
            for index, members in enumerate(bodies):
                if names & members:
                    flippable.setdefault(index, []).append(dyad['point'])
                    break
        rules: dict[int, dict[str, Any]] = {}
        for name, rule in robot._rules.items():
            sides = {solved[n] for n in (name, rule.joint) if n in solved}
            if len(sides) == 1:     # within one loop (the other side given, or of it too)
                rules.setdefault(sides.pop(), {})[name] = rule
        ruled = []
        for index in sorted(rules):
            points = flippable.get(index, [])
            if not points or len(points) > MAX_FLIPS:
                continue
            patterns = [frozenset()] + [frozenset(c) for k in range(1, len(points) + 1)
                                        for c in combinations(points, k)]
            ruled.append({'mechanism': index, 'rules': rules[index], 'patterns': patterns})
        self.ruled: tuple[dict[str, Any], ...] = tuple(ruled)
        self.zero: tuple[int, ...] = (0,) * len(ruled)
        self._scenes: dict[tuple[int, tuple[int, ...]], tuple[Any, Any]] = {}

    def __bool__(self) -> bool:
        """Return whether any loop's rules pick its assembly."""
        return bool(self.ruled)

    def scene(self, combo: tuple[int, ...], base: Any) -> Any:
        """Return ``base`` (the robot's scene, or one outputting more) in assembly ``combo``."""
        if combo == self.zero:
            return base
        key = (id(base), combo)
        if key not in self._scenes:
            flipped = set().union(*(loop['patterns'][j] for loop, j in zip(self.ruled, combo,
                                                                           strict=True)))
            dyads = tuple(replace(d, branch=-int(d.branch)) if getattr(d, 'point', None)
                          in flipped and hasattr(d, 'branch') else d for d in base.dyads)
            self._scenes[key] = (base, replace(base, dyads=dyads))   # base kept: its id holds
        return self._scenes[key][1]

    def stray(self, k: int, positions: Mapping[str, Any]) -> Any:
        """Return the largest stray of ruled loop ``k``'s rules (abs, rad or m; NaN unsolved)."""
        worst: Any = 0.0
        for name, rule in self.ruled[k]['rules'].items():
            off = positions[name] - (rule.multiplier * positions[rule.joint] + rule.offset)
            if self._types[name].angular:
                off = wrap_revolute(off)
            worst = np.fmax(worst, np.abs(off)) if isinstance(off, np.ndarray) or \
                isinstance(worst, np.ndarray) else (math.nan if math.isnan(off) else
                                                    max(worst, abs(off)))
        return worst

    def choose(self, at: Callable[[tuple[int, ...]], Mapping[str, Any] | None]
               ) -> dict[tuple[int, ...], Any]:
        """Return the assembly answered: ``{combo: mask}`` (``True`` for one instant).

        ``at(combo)`` returns the joints' positions (by name) in assembly
        ``combo``, or ``None`` where it does not assemble; it is asked for
        :attr:`zero` first, then for one assembly per pattern index where a
        loop strays, each at most once. For arrays each instant has its own
        assembly: the masks cover every instant once.
        """
        first = at(self.zero)
        assert first is not None
        best_s = {}
        for k in range(len(self.ruled)):
            s = self.stray(k, first)
            if np.any(np.asarray(s) > self.tolerance):
                best_s[k] = s
        if not best_s:
            return {self.zero: True}
        best_j: dict[int, Any] = {k: 0 for k in best_s}
        layers = max(len(self.ruled[k]['patterns']) for k in best_s)
        for j in range(1, layers):
            combo = tuple(j if k in best_s and j < len(loop['patterns']) else 0
                          for k, loop in enumerate(self.ruled))
            got = at(combo)
            if got is None:
                continue
            for k in best_s:
                if j >= len(self.ruled[k]['patterns']):
                    continue
                s = self.stray(k, got)
                better = s < best_s[k] - self.tolerance   # NaN: never better
                best_j[k] = np.where(better, j, best_j[k])
                best_s[k] = np.where(better, s, best_s[k])
        picks = [best_j.get(k, 0) for k in range(len(self.ruled))]
        if all(np.ndim(p) == 0 for p in picks):
            return {tuple(int(p) for p in picks): True}
        shape = np.broadcast_shapes(*(np.shape(p) for p in picks))
        table = np.stack([np.broadcast_to(p, shape) for p in picks], axis=-1)
        out: dict[tuple[int, ...], Any] = {}
        for row in np.unique(table.reshape(-1, len(picks)), axis=0):
            combo = tuple(int(j) for j in row)
            out[combo] = np.all(table == row, axis=-1)
        return out


def pick(mask: Any, chosen: Any, other: Any) -> Any:
    """Return ``chosen`` where ``mask`` holds and ``other`` elsewhere, through a solved state.

    Arrays (of instants first) by ``np.where``; dataclasses, objects of
    slots, dicts and tuples field by field (an :class:`~mech_kinematics.bounds.ErrorBound`
    by its built bounds); anything else (a name, a spec) as ``chosen``'s.
    """
    from ..bounds import ErrorBound

    if chosen is other:
        return chosen
    if isinstance(chosen, ErrorBound) and isinstance(other, ErrorBound):
        raw = pick(mask, chosen.raw(), other.raw())
        out = ErrorBound(lambda: raw, (), chosen.size, chosen.crank_length, chosen.floors)
        out.rubbing = pick(mask, chosen.rubbing, other.rubbing)
        return out
    if isinstance(chosen, dict) and isinstance(other, dict):
        merged = {}
        for key in {**other, **chosen}:
            a, b = chosen.get(key), other.get(key)
            if a is None or b is None:   # a failure mask one assembly has: none in the other
                present = b if a is None else a
                if not (isinstance(present, np.ndarray) and present.dtype == np.bool_):
                    merged[key] = present
                    continue
                a, b = (np.zeros_like(present) if x is None else x for x in (a, b))
            merged[key] = pick(mask, a, b)
        return merged
    if isinstance(chosen, tuple) and isinstance(other, tuple) and len(chosen) == len(other):
        items = [pick(mask, a, b) for a, b in zip(chosen, other, strict=True)]
        return type(chosen)(*items) if hasattr(chosen, '_fields') else tuple(items)
    if type(chosen) is not type(other):
        return chosen
    if is_dataclass(chosen):
        return replace(chosen, **{f.name: pick(mask, getattr(chosen, f.name),
                                               getattr(other, f.name))
                                  for f in fields(chosen) if f.init})
    if hasattr(type(chosen), '__slots__') and not isinstance(chosen, (np.ndarray, np.generic)):
        out = copy.copy(chosen)
        for name in type(chosen).__slots__:
            setattr(out, name, pick(mask, getattr(chosen, name), getattr(other, name)))
        return out
    if isinstance(chosen, (np.ndarray, float, int, complex, np.generic)):
        a, b = np.asarray(chosen), np.asarray(other)
        if a.shape == b.shape and a.ndim == 0 and a == b:
            return chosen
        m = np.asarray(mask)
        m = m.reshape(m.shape + (1,) * max(0, max(a.ndim, b.ndim) - m.ndim))
        return np.where(m, a, b)
    return chosen
