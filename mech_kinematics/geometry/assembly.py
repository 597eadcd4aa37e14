# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Where a mechanism assembles over one crank turn, and how well it moves there.

:func:`assembly_from_scene` studies one full turn of the crank (angles 0 to
2 pi, CCW from +x) from the exact solver:

- the crank-angle ranges where the mechanism assembles, however narrow: the
  roots of each step's assembly margins (:meth:`.solver.base.Step.margins`;
  closed forms in the crank angle for a dyad on the crank), found to an ulp
  of the angle (within :data:`TOLERANCE` rad);
- its toggle positions: where a dyad's two links come in line (an RRR's
  coupler and rocker, an RRP's rod square to its guide), at the ends of
  those ranges or, at a change point, inside one; the mechanism locks there;
- its dead centres: where an output (a link turning about a ground pivot
  other than the crank, or a slider on a fixed guide) reverses, its
  velocity zero (for a four-bar's rocker, the crank and coupler in line; for
  a slider-crank, the inner and outer dead centres);
- the minimum transmission angle of every RRR and RRP dyad and where it
  occurs (the angle between coupler and rocker folded to [0, 90] deg, 90
  best; for an RRP the angle between the rod and the guide's normal); the
  angle is exact, its place known to about 1e-8 rad where the minimum is a
  smooth one (the function is flat there), exactly where it is an end of a
  range;
- the Grashof class of every four-bar loop: an RRR dyad between a ground
  pivot and a point on a link that turns about another ground pivot.

:func:`assembly_summary` states the ranges where it does not assemble in one
short line, for ``plot --scene`` and the node's diagnostics. Angles here are
in rad and lengths in m; :class:`~mech_kinematics.solver.SceneUnits` shows them
in the scene's own units. NumPy only: the solver does the geometry.

What is guaranteed: each margin and its rate are sampled (:data:`SAMPLES`
per turn); a margin's extremum lies where its rate changes sign and is found
by a bracketing root finder on the rate, and a sign change of the margin on
either side of it likewise on the margin, so a range of any width around an
extremum is found, its ends exact (``solve`` refuses within rounding of
them). Only two
extrema of one margin within one sample step (its rate changing sign twice
between samples) can hide a range. Dead centres are the velocity's sign
changes, found the same way (the acceleration at unit crank speed being its
rate) in each range, sampled at the turn's step and at least
:data:`RANGE_SAMPLES` times. A toggle at an end of a range is that end; one
inside a range where a margin touches zero (a change point's) is that
margin's extremum, found exactly; others, and transmission minima, are
refined from the sampled minimum of the dyad's measure, so a second, equally
deep minimum within one step of the first is reported once.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
import itertools
import math
from typing import Any
import warnings

import numpy as np
import numpy.typing as npt

from .instant_centres import full_scene, one_driver
from ..errors import AssemblyError, NearSingularWarning
from ..solver import assembly_margins, JointMotion, Link, Scene, SceneUnits, solve

__all__ = [
    'Assembly', 'DeadCentre', 'FourBarLoop', 'SAMPLES', 'TOLERANCE', 'Toggle', 'Transmission',
    'angle_text', 'assembly_from_scene', 'assembly_ranges', 'assembly_summary',
    'grashof_class', 'summary_from_gaps',
]

Array = npt.NDArray[np.float64]

#: Crank angles sampled over the turn before refining (every 0.1 deg).
SAMPLES = 3600
#: Ends of ranges, toggles and dead centres are refined to this, rad.
TOLERANCE = 1e-12
#: A measure (sine of a transmission angle) below this inside a range is a toggle.
TOGGLE_MEASURE = 1e-6
#: A margin's extremum within this of 0 (relative to its largest sampled size: its
#: rounding) touches 0: a toggle inside a range (a change point's), not a gap.
TOUCH = 1e-14
#: Relative difference of ``s + l`` and ``p + q`` within which a loop is a change point.
CHANGE_POINT = 1e-9
#: Crank angles sampled at least in each range where it assembles, for dead centres.
RANGE_SAMPLES = 64
#: Angles times steps solved in one array at most (about 400 bytes each).
CELLS = 1_000_000
#: A local minimum of a sampled measure dips this much of its value below a neighbour.
DIP = 1e-12
_TURN = 2.0 * math.pi
#: Roots closer than this (a few ulp of 2 pi), found from either side of a sample, are one.
_SAME = 8 * math.ulp(_TURN)


@dataclass(frozen=True)
class Toggle:
    """A toggle position: the crank angle (rad) where ``dyad``'s links come in line."""

    angle: float
    dyad: str
    links: tuple[str, ...]


@dataclass(frozen=True)
class DeadCentre:
    """A dead centre: the crank angle (rad) where output ``joint`` reverses.

    ``position`` is the joint's value there (rad or m): an extreme of its
    travel. ``in_line`` names the crank and the link from its tip when the
    two are in line there (a four-bar's or a slider-crank's dead centre).
    """

    angle: float
    joint: str
    kind: str
    position: float
    in_line: tuple[str, str] | None


@dataclass(frozen=True)
class Transmission:
    """The smallest transmission angle (rad) of ``dyad`` over the turn, at crank ``angle``.

    ``constant``: the angle is the same, to rounding, wherever the dyad assembles (a
    rigid triangle's); ``angle`` is then one crank angle of the sampled turn.
    """

    dyad: str
    links: tuple[str, ...]
    minimum: float
    angle: float
    constant: bool = False


@dataclass(frozen=True)
class FourBarLoop:
    """A four-bar loop: ground pivots, the input link and its point, coupler and output.

    ``lengths`` are ground, input, coupler, output (m); ``names`` the same
    four (the ground named by its pivots, e.g. ``AD``); ``points`` the
    input's pivot, its moving point, the coupler-output pin and the output's
    pivot.
    """

    names: tuple[str, str, str, str]
    points: tuple[str, str, str, str]
    lengths: tuple[float, float, float, float]

    @property
    def grashof(self) -> str:
        """The Grashof class (:func:`grashof_class`)."""
        return grashof_class(*self.lengths)


@dataclass(frozen=True)
class Assembly:
    """What :func:`assembly_from_scene` finds over one crank turn (rad, m).

    Attributes
    ----------
    scene : str
        Scene name.
    units : SceneUnits
        The scene's units, to show the numbers in.
    ranges : tuple of (float, float)
        Crank-angle ranges where it assembles, ``start < end``; a range that
        runs through 0 starts below 0. ``((0, 2 pi),)`` everywhere.
    gaps : tuple of (float, float)
        The ranges in between, where it does not; likewise one that runs
        through 0 starts below 0.
    toggles, dead_centres : tuple
        As :class:`Toggle` and :class:`DeadCentre`, by crank angle.
    transmission : tuple of Transmission
        Per RRR and RRP dyad.
    loops : tuple of FourBarLoop
        Every four-bar loop.
    """

    scene: str
    units: SceneUnits
    ranges: tuple[tuple[float, float], ...]
    gaps: tuple[tuple[float, float], ...]
    toggles: tuple[Toggle, ...]
    dead_centres: tuple[DeadCentre, ...]
    transmission: tuple[Transmission, ...]
    loops: tuple[FourBarLoop, ...]

    @property
    def everywhere(self) -> bool:
        """Whether the mechanism assembles at every crank angle."""
        return not self.gaps

    def summary(self) -> str:
        """Return the ranges where it does not assemble as one short line (scene's units)."""
        return summary_from_gaps(self.gaps, self.units)


def grashof_class(ground: float, input_: float, coupler: float, output: float) -> str:
    """Return the Grashof class of a four-bar from its four lengths.

    With s and l the shortest and longest lengths and p, q the others:
    ``s + l < p + q`` (Grashof) gives a ``crank-rocker`` when the input is
    shortest, a ``rocker-crank`` when the output is, a ``double-crank`` when
    the ground is and a ``double-rocker`` when the coupler is; ``s + l = p + q``
    (to :data:`CHANGE_POINT`) a ``change point``; ``s + l > p + q`` a
    ``triple-rocker`` (non-Grashof).
    """
    lengths = (ground, input_, coupler, output)
    short, long = min(lengths), max(lengths)
    pq = sum(lengths) - short - long
    if abs((short + long) - pq) <= CHANGE_POINT * (short + long):
        return 'change point'
    if short + long > pq:
        return 'triple-rocker'
    shortest = lengths.index(short)
    return ('double-crank', 'crank-rocker', 'double-rocker', 'rocker-crank')[shortest]


def summary_from_gaps(gaps: Sequence[tuple[float, float]], units: SceneUnits) -> str:
    """Return :func:`assembly_summary`'s line for crank-angle ranges ``gaps`` (rad)."""
    if not gaps:
        return 'assembles at every crank angle'
    return f'does not assemble for crank angles {_ranges_text(gaps, units)}'


def assembly_summary(scene: Scene) -> str:
    """Return, in one short line, where ``scene`` does not assemble over a crank turn.

    E.g. ``does not assemble for crank angles 103.792..256.208 deg``, or
    ``assembles at every crank angle``; angles in the scene's unit, 6
    significant digits. Only the ranges are computed (a few ms).
    """
    return summary_from_gaps(assembly_ranges(scene)[1], scene.units)


def assembly_ranges(scene: Scene) -> tuple[tuple[tuple[float, float], ...],
                                           tuple[tuple[float, float], ...]]:
    """Return the crank-angle ranges (rad) where ``scene`` assembles and where it does not.

    As :attr:`Assembly.ranges` and :attr:`Assembly.gaps`; only these are
    computed.
    """
    ranges = _ranges(_Probe(scene))
    return ranges, _gaps(ranges)


def assembly_from_scene(scene: Scene, samples: int = SAMPLES) -> Assembly:
    """Study one full turn of ``scene``'s crank (see the module's docstring).

    Parameters
    ----------
    scene : Scene
        The mechanism (a scene pruned by ``outputs`` is studied in full).
    samples : int
        Crank angles sampled over the turn before refining.

    Returns
    -------
    Assembly
    """
    one_driver(scene, "assembly over one crank's turn")
    probe = _Probe(scene, samples)
    ranges = _ranges(probe)
    gaps = _gaps(ranges)
    toggles = _toggles(probe, ranges)
    return Assembly(scene.name, scene.units, ranges, gaps, toggles, _dead_centres(probe, ranges),
                    _transmission(probe, ranges, toggles), _loops(probe))


# --- sampling and refining ------------------------------------------------------------


class _Probe:
    """The scene solved over the sampled turn, and single angles on request."""

    def __init__(self, scene: Scene, samples: int = SAMPLES) -> None:
        self.scene = full_scene(scene)
        self.theta = np.linspace(0.0, _TURN, samples, endpoint=False)
        self.state = self.solve(self.theta)
        self.valid = np.asarray(self.state.valid, dtype=bool)
        self.margins = assembly_margins(self.scene)
        # Filled by _ranges: (angle, step label) of each margin's roots and of each
        # extremum where a margin touches 0.
        self.roots: list[tuple[float, str]] = []
        self.touches: list[tuple[float, str]] = []

    def solve(self, theta: float | Array) -> object:
        """Solve at crank speed 1 rad/s, refusing only what does not assemble.

        An array of more angles than :data:`CELLS` over the scene's steps is
        solved in parts of that many, and only what the study reads of the
        parts is joined (:class:`_Joined`): a long chain's whole state over a
        turn would take gigabytes (3 GB for 2,000 dyads at 3600 angles).
        """
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', NearSingularWarning)
            part = max(64, CELLS // max(1, len(self.scene.dyads) + len(self.scene.points)))
            if np.ndim(theta) == 0 or len(theta) <= part:
                return solve(self.scene, theta, 1.0, 0.0, max_error=math.inf)
            return _Joined(solve(self.scene, theta[i:i + part], 1.0, 0.0, max_error=math.inf)
                           for i in range(0, len(theta), part))

    def failure(self, theta: float) -> AssemblyError | None:
        try:
            self.solve(theta)
        except AssemblyError as error:
            return error
        return None


class _Joined:
    """What the study reads of an array state (``valid``, ``singularity``, ``joints``).

    Joined from the states of consecutive parts of the angles, each dropped once
    read (``parts`` is an iterator).
    """

    def __init__(self, parts: Iterable[Any]) -> None:
        valid: list[Array] = []
        singularity: dict[str, list[Array]] = {}
        joints: dict[str, tuple[str, list[Array], list[Array], list[Array]]] = {}
        for part in parts:
            valid.append(np.asarray(part.valid, dtype=bool))
            for key, measure in part.singularity.items():
                singularity.setdefault(key, []).append(np.asarray(measure))
            for name, joint in part.joints.items():
                kind, *fields = joints.setdefault(name, (joint.type, [], [], []))
                for field, value in zip(fields, (joint.position, joint.velocity,
                                                 joint.acceleration), strict=True):
                    field.append(np.asarray(value))
        self.valid = np.concatenate(valid)
        self.singularity = {key: np.concatenate(v) for key, v in singularity.items()}
        self.joints = {name: JointMotion(kind, *(np.concatenate(f) for f in fields))
                       for name, (kind, *fields) in joints.items()}


def _ranges(probe: _Probe) -> tuple[tuple[float, float], ...]:
    """Return where every step's margin is positive, its ends the margins' roots.

    Each margin and its rate are sampled over the turn; an extremum of a
    margin lies where its rate changes sign between two samples and is found
    by root finding on the rate, so a window where the margin is positive
    however narrow around an extremum is caught; between extrema a margin is
    monotonic, and where it changes sign its root is found (bracketed by
    sign), to an ulp of the angle. Between consecutive roots the
    mechanism assembles or not throughout (but where a margin touches zero,
    a toggle): two evaluations tell which.
    """
    margins = probe.margins
    theta = _turn_grid(len(probe.theta))
    sampled = margins(theta)
    roots = []
    seen: dict[str, int] = {}
    for label, margin, rate in sampled:
        order = seen[label] = seen.get(label, -1) + 1  # which of its step's margins

        def function(t: Array, name: str = label, k: int = order) -> tuple[Array, Array]:
            return margins(t, name)[k][1:]

        extrema: list[tuple[float, float]] = []
        touch = TOUCH * float(np.nanmax(np.abs(margin), initial=0.0))
        found = _crossings(function, theta, (margin, rate), extrema, touch)
        roots.extend(found)
        probe.roots.extend((root, label) for root in found)
        probe.touches.extend((angle, label) for angle, value in extrema  # a toggle inside
                             if abs(value) <= touch)
    roots = _distinct(roots)
    if not roots:
        return ((0.0, _TURN),) if _assembles(margins, np.array([0.0]))[0] else ()
    following = np.array(roots[1:] + [roots[0] + _TURN])
    # Two points of each piece: either tells (a margin may touch 0 at one angle, a toggle).
    width = following - np.array(roots)
    inside = (_assembles(margins, roots + 0.382 * width)
              | _assembles(margins, roots + 0.618 * width))
    pieces = [(start, float(end)) for start, end, ok in zip(roots, following, inside, strict=True)
              if ok]
    if len(pieces) == len(roots):
        return ((0.0, _TURN),)
    ranges: list[tuple[float, float]] = []
    for start, end in pieces:  # join pieces meeting at a root where nothing changes
        if ranges and ranges[-1][1] == start:
            ranges[-1] = (ranges[-1][0], end)
        else:
            ranges.append((start, end))
    if len(ranges) > 1 and ranges[-1][1] - _TURN == ranges[0][0]:
        ranges[0] = (ranges[-1][0] - _TURN, ranges[0][1])
        ranges.pop()
    elif ranges[-1][1] > _TURN:  # it runs through 0: it starts below 0
        last = ranges.pop()
        ranges.insert(0, (last[0] - _TURN, last[1] - _TURN))
    return tuple(ranges)


def _crossings(function: Callable[[Array], tuple[Array, Array]], theta: Array,
               sampled: tuple[Array, Array] | None = None,
               extrema: list[tuple[float, float]] | None = None,
               touch: float = -1.0) -> list[float]:
    """Return where ``function``'s value changes sign between the first and last of ``theta``.

    ``function`` gives (value, rate) at crank angles, NaN where unknown;
    ``sampled`` is its answer at ``theta`` if already known. Where the rate
    changes sign between two samples the extremum is found by root finding
    on the rate (:func:`_root`), so a sign change of the value on either side of it is caught
    however close together the two are (unless the value is further from zero
    than twice the step times the larger rate: it cannot get there, and the
    rate's rounding noise about a flat value is not chased); each sign change
    is then found, bracketed by the value's sign, to an ulp of the angle.
    Where the value is known at one end of a step only (an earlier dyad stops
    closing between), the step is cut where it stops being known. The
    extrema found are appended to ``extrema`` as (angle, value); one within
    ``touch`` of zero touches it (within rounding): no sign change is sought
    beside it. An interval where the rate changes sign twice (two extrema
    within one sample step) is seen as monotonic.
    """
    value, rate = function(theta) if sampled is None else sampled
    roots = []
    for i in _changes(value, rate):
        a, b = float(theta[i]), float(theta[i + 1])
        va, vb, ra, rb = float(value[i]), float(value[i + 1]), float(rate[i]), float(rate[i + 1])
        if not math.isfinite(va + ra):  # known from b on only: cut the step there
            a = _known_from(function, b, a)
            va, ra = (float(x[0]) for x in function(np.array([a])))
        elif not math.isfinite(vb + rb):
            b = _known_from(function, a, b)
            vb, rb = (float(x[0]) for x in function(np.array([b])))
        ends, values = [a, b], [va, vb]
        reach = 2.0 * (b - a) * max(abs(ra), abs(rb))  # of the value, at most
        if ra * rb < 0.0 and min(abs(va), abs(vb)) <= reach:
            # an extremum between that may cross 0: the value is monotonic either side
            extremum = _root(lambda t: function(t)[1], a, b)
            ends.insert(1, extremum)
            values.insert(1, float(function(np.array([extremum]))[0][0]))
            if extrema is not None:
                extrema.append((extremum, values[1]))
            if abs(values[1]) <= touch:
                continue
        for (low, v_low), (high, v_high) in itertools.pairwise(zip(ends, values, strict=True)):
            if v_low * v_high < 0.0:
                roots.append(_root(lambda t: function(t)[0], low, high))
            elif (v_high == 0.0 and high == float(theta[i + 1]) and i + 2 < len(theta)
                  and v_low * value[i + 2] < 0.0):
                roots.append(high)  # on a sample
    return roots


def _known_from(function: Callable[[Array], tuple[Array, Array]], known: float,
                unknown: float) -> float:
    """Return the angle nearest ``unknown`` from ``known`` at which ``function`` is known."""
    while True:
        middle = 0.5 * (known + unknown)
        if middle in (known, unknown):
            return known
        value, rate = (float(x[0]) for x in function(np.array([middle])))
        if math.isfinite(value + rate):
            known = middle
        else:
            unknown = middle


def _turn_grid(samples: int) -> Array:
    """Return ``samples`` steps over the turn, and one more each side (a sign change at 0)."""
    return np.arange(-1, samples + 2) * (_TURN / samples)


def _distinct(angles: Sequence[float]) -> list[float]:
    """Return the angles in [0, 2 pi), sorted; those within a few ulp (mod 2 pi) once."""
    result: list[float] = []
    for angle in sorted(a % _TURN for a in angles):
        if not result or angle - result[-1] > _SAME:
            result.append(angle)
    if len(result) > 1 and result[0] + _TURN - result[-1] <= _SAME:
        result.pop()
    return result


def _changes(value: Array, rate: Array) -> list[int]:
    """Return the sample intervals where a value or its rate changes sign, or stops being known.

    A value exactly zero at a sample between two of opposite signs gives the
    interval before it (its root finding ends on that sample).
    """
    known = np.isfinite(value) & np.isfinite(rate)
    both = known[:-1] | known[1:]  # known at one end only: cut where it stops being known
    flips = ((value[:-1] * value[1:] < 0.0) | (rate[:-1] * rate[1:] < 0.0)
             | (known[:-1] != known[1:]))
    zero = np.zeros_like(flips)
    zero[:-1] = (value[1:-1] == 0.0) & (value[:-2] * value[2:] < 0.0) & known[2:]
    return [int(i) for i in np.flatnonzero(both & (flips | zero))]


def _assembles(margins: Callable[..., list[tuple[str, Array, Array]]],
               theta: Array) -> Array:
    """Return whether every margin is positive at each crank angle."""
    ok = np.ones(theta.shape, dtype=bool)
    for _, margin, _ in margins(theta):
        ok &= margin > 0.0  # NaN (an earlier step does not close) is not
    return ok


def _root(function: Callable[[Array], Array], low: float, high: float) -> float:
    """Return where ``function`` (of one crank angle) changes sign in [low, high], to an ulp.

    Regula falsi, Illinois variant (a stale end's value halved), the bracket
    kept by sign; near the root a step of a few ulp past the estimate closes
    the bracket; a bisection step wherever the bracket did not halve twice
    running; until no double lies strictly inside the bracket.
    """
    def at(theta: float) -> float:
        return float(function(np.array([theta]))[0])

    f_low, f_high = at(low), at(high)
    keep = f_low > 0.0
    side = 0
    slow = 0
    while True:
        width = high - low
        middle = 0.5 * (low + high)
        if middle in (low, high):
            return middle
        t = middle
        if slow < 2 and math.isfinite(f_low) and math.isfinite(f_high) and f_low != f_high:
            guess = high - f_high * width / (f_high - f_low)
            if guess <= low:  # the root within rounding of an end: a few ulp inside it
                guess = low + 4.0 * math.ulp(low)
            elif guess >= high:
                guess = high - 4.0 * math.ulp(high)
            if low < guess < high:
                t = guess
        f = at(t)
        if f == 0.0:
            return t
        close = t != middle and abs(f) < abs(f_low) and abs(f) < abs(f_high)
        if (f > 0.0) == keep:
            low, f_low = t, f
            if side == -1:
                f_high *= 0.5
            side = -1
        else:
            high, f_high = t, f
            if side == 1:
                f_low *= 0.5
            side = 1
        if close:  # nearly there: a step of a few ulp toward the bracket's other end
            near = t + math.copysign(4.0 * math.ulp(t), (high if t == low else low) - t)
            if low < near < high:
                f_near = at(near)
                if (f_near > 0.0) == keep:
                    low, f_low = near, f_near
                else:
                    high, f_high = near, f_near
        slow = slow + 1 if high - low > 0.5 * width else 0


def _gaps(ranges: Sequence[tuple[float, float]]) -> tuple[tuple[float, float], ...]:
    if len(ranges) == 1 and ranges[0][1] - ranges[0][0] >= _TURN:
        return ()
    gaps = []
    for index, (_, end) in enumerate(ranges):
        following = ranges[(index + 1) % len(ranges)][0]
        turns = 0
        while following + turns * _TURN < end:
            turns += 1
        if turns and following + turns * _TURN > _TURN:  # it runs through 0: it starts
            gaps.append((end - _TURN, following + (turns - 1) * _TURN))  # below 0, as a range
        else:
            gaps.append((end, following + turns * _TURN))
    return tuple(sorted(gaps))


def _measure_keys(scene: Scene) -> dict[str, tuple[str, tuple[str, ...]]]:
    """Measure key -> (dyad label, its links) for the RRR and RRP dyads."""
    keys = {}
    for dyad in scene.dyads:
        toggle = dyad.toggle()
        if toggle is not None:
            key, label, links = toggle
            keys[key] = (label, links)
    return keys


def _toggles(probe: _Probe, ranges: Sequence[tuple[float, float]]) -> tuple[Toggle, ...]:
    keys = _measure_keys(probe.scene)
    labels = {label: (key, links) for key, (label, links) in keys.items()}
    exact = []  # the roots of margins: the ends of ranges and where a margin touches 0
    if len(ranges) != 1 or ranges[0][1] - ranges[0][0] < _TURN:
        for start, end in ranges:  # the dyad whose margin ends the range locks there
            for edge in (start, end):
                label = next((label for angle, label in probe.roots
                              if abs(math.remainder(angle - edge, _TURN)) <= _SAME), None)
                if label in labels:
                    exact.append(Toggle(edge % _TURN, label, labels[label][1]))
    exact.extend(Toggle(angle % _TURN, label, labels[label][1])
                 for angle, label in probe.touches if label in labels)
    toggles = []
    state = probe.state
    # A sample inside a range that the solver refuses is on a toggle (a margin touching 0).
    refused = _inside(probe.theta, ranges) & ~probe.valid
    for key, (label, links) in keys.items():
        measure = np.where(probe.valid, np.asarray(state.singularity[key]),
                           np.where(refused, 0.0, np.inf))
        for index in _local_minima(measure):
            angle, value = _golden(probe, key, float(probe.theta[index]))
            if value < TOGGLE_MEASURE:
                toggles.append(Toggle(angle % _TURN, label, links))
    unique: list[Toggle] = []
    for toggle in sorted(exact, key=lambda t: t.angle) + sorted(toggles, key=lambda t: t.angle):
        if not any(abs(math.remainder(toggle.angle - t.angle, _TURN)) < 1e-6
                   and t.dyad == toggle.dyad for t in unique):
            unique.append(toggle)
    return tuple(sorted(unique, key=lambda t: t.angle))


def _inside(theta: Array, ranges: Sequence[tuple[float, float]]) -> Array:
    """Return whether each crank angle in [0, 2 pi) lies inside one of the ranges."""
    inside = np.zeros(theta.shape, dtype=bool)
    for start, end in ranges:
        for shift in (0.0, _TURN):
            inside |= (theta + shift > start) & (theta + shift < end)
    return inside


def _local_minima(values: Array) -> list[int]:
    """Return the indices of the local minima of a cyclic sequence (finite ones only).

    A minimum is a dip beyond rounding: at least :data:`DIP` of its value below a
    neighbour. A measure that is constant (a rigid triangle's) has none, where its
    rounding would make a third of its samples minima, each refined by solves.
    """
    previous, following = np.roll(values, 1), np.roll(values, -1)
    finite = np.isfinite(values) & np.isfinite(previous) & np.isfinite(following)
    with np.errstate(invalid='ignore'):
        dip = np.maximum(previous, following) - values > DIP * np.abs(values)
    return [int(i) for i in np.flatnonzero(finite & (values <= previous) & (values < following)
                                           & dip)]


def _golden(probe: _Probe, key: str, centre: float) -> tuple[float, float]:
    """Refine a sampled minimum of a dyad's measure; return (angle, measure) there."""
    step = _TURN / len(probe.theta)

    def measure(theta: float) -> float:
        try:
            return float(probe.solve(theta).singularity[key])  # type: ignore[attr-defined]
        except AssemblyError:
            return math.inf  # beyond an end of a range: the ends are looked at apart

    low, high = centre - step, centre + step
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    a, b = high - ratio * (high - low), low + ratio * (high - low)
    fa, fb = measure(a), measure(b)
    while high - low > 1e-10:
        if fa <= fb:
            high, b, fb = b, a, fa
            a = high - ratio * (high - low)
            fa = measure(a)
        else:
            low, a, fa = a, b, fb
            b = low + ratio * (high - low)
            fb = measure(b)
    angle = 0.5 * (low + high)
    return angle, measure(angle)


def _outputs(scene: Scene) -> dict[str, str]:
    """Output joints that can have dead centres: name -> 'revolute' or 'prismatic'."""
    return dict(scene.graph.reversing())


def _dead_centres(probe: _Probe, ranges: Sequence[tuple[float, float]]
                  ) -> tuple[DeadCentre, ...]:
    """Return where an output's velocity changes sign, inside the ranges where it assembles.

    Each range is sampled at the turn's step (at least :data:`RANGE_SAMPLES`
    angles, so a narrow range is sampled too) and the reversals found as the
    ranges' ends are (:func:`_crossings`, the acceleration at unit crank speed
    being the velocity's rate).
    """
    scene = probe.scene
    crank = scene.input
    starting = {}  # link from the crank's tip -> the joints of its dyad
    for fragment in scene.graph.fragments:
        for body in fragment.bodies:
            frame = body.frame
            if frame is not None and frame.origin == crank.point and frame.angle_of == body.name:
                starting[body.name] = tuple(fragment.coordinates)
    step = _TURN / len(probe.theta)
    grids = []
    for start, end in ranges:
        if end - start >= _TURN:
            grids.append(_turn_grid(len(probe.theta)))
            continue
        count = max(RANGE_SAMPLES, math.ceil((end - start) / step) + 1)
        inward = 1e-6 * (end - start)  # the ends themselves are refused (toggles)
        grids.append(np.linspace(start + inward, end - inward, count))

    def motion(theta: Array, name: str, state: Any = None) -> tuple[Array, Array]:
        state = probe.solve(theta) if state is None else state
        valid = np.asarray(state.valid, dtype=bool)
        solved = state.joints[name]
        return (np.where(valid, solved.velocity, np.nan),
                np.where(valid, solved.acceleration, np.nan))

    states = [probe.solve(grid) for grid in grids]  # once for every joint
    centres = []
    for joint, kind in _outputs(scene).items():
        def function(theta: Array, name: str = joint) -> tuple[Array, Array]:
            return motion(theta, name)

        found = [a for grid, state in zip(grids, states, strict=True)
                 for a in _crossings(function, grid, motion(grid, joint, state))]
        for angle in _distinct(found):
            solved = probe.solve(angle)
            position = float(solved.joints[joint].position)  # type: ignore[attr-defined]
            in_line = None
            for link, names in starting.items():
                if joint in names or joint == link:
                    e1 = float(solved.joints[crank.link].position)  # type: ignore
                    e2 = float(solved.joints[link].position)  # type: ignore
                    if abs(math.sin(e1 - e2)) < 1e-6:
                        in_line = (crank.link, link)
            centres.append(DeadCentre(angle % _TURN, joint, kind, position, in_line))
    centres.sort(key=lambda c: c.angle)
    return tuple(centres)


def _transmission(probe: _Probe, ranges: Sequence[tuple[float, float]],
                  toggles: Sequence[Toggle]) -> tuple[Transmission, ...]:
    keys = _measure_keys(probe.scene)
    result = []
    everywhere = len(ranges) == 1 and ranges[0][1] - ranges[0][0] >= _TURN
    for key, (label, links) in keys.items():
        toggle = next((t for t in toggles if t.dyad == label), None)
        if toggle is not None:  # its links come in line: a transmission angle of 0
            result.append(Transmission(label, links, 0.0, toggle.angle))
            continue
        measure = np.where(probe.valid, np.asarray(probe.state.singularity[key]), np.inf)
        index = int(np.argmin(measure))
        angle, value = float(probe.theta[index]), float(measure[index])
        finite = measure[np.isfinite(measure)]
        constant = everywhere and finite.size > 0 and bool(
            finite.max() - finite.min() <= DIP * finite.max())
        if not constant:  # (a constant measure's every angle is its minimum)
            angle, value = _golden(probe, key, angle)
        if not everywhere:  # an end of a range may be lower (a toggle: 0)
            for start, end in ranges:
                for edge in (start, end):
                    if probe.failure(edge - 1e-9 if edge == end else edge + 1e-9) is None:
                        solved = probe.solve(edge - 1e-9 if edge == end else edge + 1e-9)
                        m = float(solved.singularity[key])  # type: ignore[attr-defined]
                        if m < value:
                            angle, value = edge, m
        result.append(Transmission(label, links, math.asin(min(1.0, max(0.0, value))),
                                   angle % _TURN, constant))
    return tuple(result)


def _loops(probe: _Probe) -> tuple[FourBarLoop, ...]:
    scene = probe.scene
    state = probe.solve(scene.input.angle)
    position = {name: complex(*p.position)  # type: ignore[attr-defined]
                for name, p in state.points.items()}  # type: ignore[attr-defined]
    graph = scene.graph
    pivot = graph.pivots()  # body turning about a ground pivot -> that pivot
    fixed_on: dict[str, str] = {}  # point -> the body it is fixed on (one that pivots, first)
    for body in graph.bodies.values():
        if body.name != graph.ground:
            for point in body.points:
                if point not in fixed_on or (body.name in pivot and fixed_on[point] not in pivot):
                    fixed_on[point] = body.name
    loops = []
    for fragment in graph.fragments:  # two links of fixed lengths meeting at a new pin
        pair = [Link(body.name, body.frame.origin, body.length) for body in fragment.bodies
                if body.length is not None and body.frame is not None
                and body.points[1:2] == (fragment.key,)]
        if len(pair) != 2:
            continue
        point, first, second = fragment.key, *pair
        for out, coupler in ((first, second), (second, first)):
            if out.start not in scene.ground or coupler.start in scene.ground:
                continue
            driver = fixed_on.get(coupler.start)
            if driver is None or driver not in pivot or driver in (out.name, coupler.name):
                continue
            o1, q, o2 = pivot[driver], coupler.start, out.start
            if o1 == o2:  # the output turns about the driver's own pivot: a rigid triangle
                continue
            ground = abs(position[o2] - position[o1])
            input_ = abs(position[q] - position[o1])
            loops.append(FourBarLoop((f'{o1}{o2}', driver, coupler.name, out.name),
                                     (o1, q, point, o2),
                                     (ground, input_, coupler.length, out.length)))
            break
    return tuple(loops)


# --- text --------------------------------------------------------------------------


def angle_text(units: SceneUnits, theta: float) -> str:
    """Return a crank angle (rad) in the scene's unit to 6 significant digits, without unit.

    A value within 5e-7 of a turn of 0 or of a full turn is shown as 0 (a
    refined dead centre at 0 deg is 2e-11 deg away, a transmission minimum
    at 0 is found to about 1e-8 rad: not numbers to print).
    """
    value = units.angle_value(theta)
    turn = units.angle_value(_TURN)
    if abs(value) < 5e-7 * turn or abs(abs(value) - turn) < 5e-7 * turn:
        value = 0.0
    return f'{value:.6g}'


_angle = angle_text


def _ranges_text(ranges: Sequence[tuple[float, float]], units: SceneUnits) -> str:
    parts = [f'{_angle(units, a)}..{_angle(units, b)}' for a, b in ranges]
    return f'{", ".join(parts)} {units.angle}'
