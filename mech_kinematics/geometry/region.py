# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Where a mechanism with several drivers assembles: a grid over two drivers, and slices.

A scene with several drivers (or driven by a linear actuator) has no single
crank turn to study: its positions form a region of the drivers' space.
:func:`region_from_scene` gives

- the *grid*: two drivers (the first two, or the two named) each sampled over
  its *domain* (a crank over a turn, ``[0, 2 pi)``; an actuator over its
  stroke, both limits included), the others at their start positions, and
  whether the mechanism assembles at each grid point (the solver's own
  answer: :func:`~mech_kinematics.solver.solve` on the array path);
- a *slice* per driver: its ranges where the mechanism assembles with every
  other driver at its start position, their ends exact. Each slice is
  sampled (:data:`SLICE_SAMPLES` positions over the domain) and every change
  between assembling and not is refined by bisection on the scalar solve's
  answer until the two positions are adjacent doubles: an end is the last
  position at which ``solve`` answers, the next double being refused (within
  an ulp of the margins' roots where they cross zero at a nonzero rate: the
  solver refuses only within rounding of them). A window where it assembles,
  or does not, narrower than a sample step and lying between two samples is
  not seen: the step is stated with the result (:attr:`Slice.step`).

An actuator without stroke limits is swept over lengths up to
:func:`free_length`, a length no closing position can exceed. Positions are
in rad (a crank) or m (an actuator). NumPy only: the solver does the geometry.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
import math
from typing import Any
import warnings

import numpy as np
import numpy.typing as npt

from ..errors import AssemblyError, NearSingularWarning, SceneError
from ..solver import Scene, SceneUnits, solve
from ..solver.graph import JointType

__all__ = ['GRID', 'Region', 'SLICE_SAMPLES', 'Slice', 'assembles_at', 'domain', 'free_length',
           'region_from_scene']

Array = npt.NDArray[np.float64]

#: Grid points per driver by default (a crank: every 2 deg).
GRID = 180
#: Positions sampled over a driver's domain for its slice, before refining the ends.
SLICE_SAMPLES = 3600
_TURN = 2.0 * math.pi


@dataclass(frozen=True)
class Slice:
    """Where the mechanism assembles as one driver moves, the others at ``at``.

    Attributes
    ----------
    driver : str
        The driver that moves.
    kind : str
        Its driver's joint type (a crank's positions rad, an actuator's m).
    domain : (float, float)
        What was swept: ``(0, 2 pi)`` for a crank; an actuator's stroke, or
        ``(0, free_length)`` for one without.
    at : dict of str to float
        The other drivers' positions (their start positions).
    ranges : tuple of (float, float)
        Where it assembles, ``start <= end``, each end the last position at
        which it does (an actuator's may be its stroke limit); a crank range
        through 0 starts below 0. ``((0, 2 pi),)`` for a crank that turns fully.
    ends : tuple of (str, str)
        What stops each range at each end: ``'stroke'`` (an actuator's
        limit), the label of the dyad that stops closing (``'RRR P'``), or
        ``'turn'`` (a full turn).
    step : float
        The sampling step (rad or m): narrower windows between samples are not seen.
    """

    driver: str
    kind: JointType
    domain: tuple[float, float]
    at: dict[str, float]
    ranges: tuple[tuple[float, float], ...]
    ends: tuple[tuple[str, str], ...]
    step: float

    @property
    def everywhere(self) -> bool:
        """Whether it assembles over the whole domain."""
        if not self.ranges:
            return False
        low, high = self.domain
        if self.kind.angular:
            return self.ranges[0][1] - self.ranges[0][0] >= _TURN
        return self.ranges == ((low, high),)


@dataclass(frozen=True)
class Region:
    """What :func:`region_from_scene` finds (rad, m).

    Attributes
    ----------
    scene : str
        Scene name.
    units : SceneUnits
        The scene's units, to show the numbers in.
    drivers : tuple of str
        Every driver, in scene order.
    grid : tuple of str
        The one or two drivers of the grid (the first is the rows').
    axes : tuple of ndarray
        Their sampled positions (rad or m).
    assembles : ndarray of bool
        Whether it assembles at each grid point, shape ``(len(axes[0]), ...)``.
    at : dict of str to float
        The start positions of the drivers not on the grid (held there).
    slices : tuple of Slice
        One per driver, in scene order.
    """

    scene: str
    units: SceneUnits
    drivers: tuple[str, ...]
    grid: tuple[str, ...]
    axes: tuple[Array, ...]
    assembles: npt.NDArray[np.bool_]
    at: dict[str, float]
    slices: tuple[Slice, ...]

    @property
    def fraction(self) -> float:
        """The fraction of the grid's points at which it assembles."""
        return float(np.mean(self.assembles))


def free_length(scene: Scene) -> float:
    """Return a length (m) no actuator's closing length can exceed: ``scene.free_length``."""
    return scene.free_length


def domain(scene: Scene, driver: Any) -> tuple[float, float]:
    """Return what a driver is swept over (its ``sweep``): a turn, its stroke or free lengths."""
    low, high = driver.sweep(scene.free_length)
    return (float(low), float(high))


def _samples(kind: str, low: float, high: float, count: int) -> Array:
    if kind.angular:
        return np.linspace(low, high, count, endpoint=False)
    values = np.linspace(low, high, count)
    if low == 0.0:  # a length must be positive: start one step in
        values = np.linspace(low, high, count + 1)[1:]
    return values


def _positions(scene: Scene, values: dict[str, Any]) -> list[Any]:
    return [values.get(d.name, d.start) for d in scene.drivers]


def _solve(scene: Scene, positions: list[Any]) -> Any:
    """Solve at the drivers' positions (zero rates), refusing only what does not assemble."""
    zeros = [0.0] * len(positions)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', NearSingularWarning)
        if len(positions) == 1:
            return solve(scene, positions[0], 0.0, 0.0, max_error=math.inf)
        return solve(scene, positions, zeros, zeros, max_error=math.inf)


def assembles_at(scene: Scene, values: dict[str, float]) -> AssemblyError | None:
    """Return why ``solve`` refuses the drivers at ``values`` (others at start), or None.

    ``values`` maps driver names to positions (rad or m).
    """
    try:
        _solve(scene, _positions(scene, values))
    except AssemblyError as error:
        return error
    return None


def _grid_valid(scene: Scene, values: dict[str, Array]) -> npt.NDArray[np.bool_]:
    """Return where it assembles, the drivers in ``values`` at the arrays' (1-D) positions."""
    shape = next(iter(values.values())).shape
    positions = [np.broadcast_to(p, shape) for p in _positions(scene, values)]
    state = _solve(scene, positions)
    return np.asarray(state.valid, dtype=bool)


def _end(scene: Scene, name: str, good: float, bad: float) -> tuple[float, str]:
    """Bisect between an assembling ``good`` and a refused ``bad`` to adjacent doubles.

    Return the last position that assembles and the label of the dyad that
    refuses the next.
    """
    error = assembles_at(scene, {name: bad})
    while True:
        middle = 0.5 * (good + bad)
        if middle in (good, bad):
            break
        failure = assembles_at(scene, {name: middle})
        if failure is None:
            good = middle
        else:
            bad, error = middle, failure
    return good, ('' if error is None else error.dyad)


def _slice(scene: Scene, driver: Any, samples: int) -> Slice:
    name, kind = driver.name, driver.joint_type
    low, high = domain(scene, driver)
    x = _samples(kind, low, high, samples)
    at = {d.name: float(d.start) for d in scene.drivers if d.name != name}
    ok = _grid_valid(scene, {name: x})
    step = float(x[1] - x[0])
    if kind.angular:
        return _crank_slice(scene, driver, x, ok, at, step)
    ranges: list[tuple[float, float]] = []
    ends: list[tuple[str, str]] = []
    first = None
    why_first = ''
    for index, good in enumerate(ok):
        if good and first is None:
            if index == 0 and driver.stroke is not None:
                first, why_first = float(x[0]), 'stroke'
            else:
                previous = float(x[index - 1]) if index else math.nextafter(float(x[0]), 0.0)
                first, why_first = _end(scene, name, float(x[index]), previous)
        if not good and first is not None:
            end, why = _end(scene, name, float(x[index - 1]), float(x[index]))
            ranges.append((first, end))
            ends.append((why_first, why))
            first = None
    if first is not None:
        ranges.append((first, float(x[-1])))
        ends.append((why_first, 'stroke' if driver.stroke is not None else ''))
    return Slice(name, kind, (low, high), at, tuple(ranges), tuple(ends), step)


def _crank_slice(scene: Scene, driver: Any, x: Array, ok: npt.NDArray[np.bool_],
                 at: dict[str, float], step: float) -> Slice:
    name = driver.name
    if ok.all():
        return Slice(name, driver.joint_type, (0.0, _TURN), at, ((0.0, _TURN),),
                     (('turn', 'turn'),), step)
    n = len(x)
    if not ok.any():
        return Slice(name, driver.joint_type, (0.0, _TURN), at, (), (), step)
    # Start at a refused sample so that every range has both ends in the loop; the ends
    # are bisected where they are reported (a range through 0 starting below 0), so that
    # each is the last double at which solve answers.
    origin = int(np.flatnonzero(~ok)[0])
    brackets: list[tuple[float, float, float, float]] = []  # (bad, good) at start, end
    start: tuple[float, float] | None = None
    for k in range(1, n + 1):
        i, j = (origin + k - 1) % n, (origin + k) % n
        a = float(x[i]) + (origin + k - 1) // n * _TURN
        b = float(x[j]) + (origin + k) // n * _TURN
        if not ok[i] and ok[j]:
            start = (a, b)
        elif ok[i] and not ok[j] and start is not None:
            brackets.append((*start, a, b))
            start = None
    pieces = []
    for before, first, last, after in brackets:
        offset = -_TURN if first >= _TURN else 0.0
        if last + offset > _TURN:  # it runs through 0: it starts below 0
            offset -= _TURN
        low, why_low = _end(scene, name, first + offset, before + offset)
        high, why_high = _end(scene, name, last + offset, after + offset)
        pieces.append(((low, high), (why_low, why_high)))
    pieces.sort()
    return Slice(name, driver.joint_type, (0.0, _TURN), at, tuple(r for r, _ in pieces),
                 tuple(w for _, w in pieces), step)


def region_from_scene(scene: Scene, grid: int = GRID, pair: Sequence[str] | None = None,
                      samples: int = SLICE_SAMPLES) -> Region:
    """Study where ``scene`` assembles over its drivers' space (see the module's docstring).

    Parameters
    ----------
    scene : Scene
        The mechanism.
    grid : int
        Grid points per driver (at least 2).
    pair : sequence of str, optional
        The two drivers of the grid (default: the first two; a scene with one
        driver has a grid of one).
    samples : int
        Positions sampled per slice before refining.

    Returns
    -------
    Region
    """
    drivers = scene.drivers
    names = tuple(d.name for d in drivers)
    if pair is None:
        pair = names[:2]
    pair = tuple(pair)
    unknown = [p for p in pair if p not in names]
    if unknown or len(set(pair)) != len(pair) or len(pair) != min(2, len(names)):
        msg = (f'Expected {min(2, len(names))} different drivers of {scene.name} for the grid '
               f'({", ".join(names)}), got {", ".join(pair) or "none"}')
        raise SceneError(msg)
    by_name = {d.name: d for d in drivers}
    axes = tuple(_samples(by_name[p].joint_type, *domain(scene, by_name[p]), grid) for p in pair)
    mesh = np.meshgrid(*axes, indexing='ij')
    valid = _grid_valid(scene, {p: m.ravel() for p, m in zip(pair, mesh, strict=True)})
    at = {d.name: float(d.start) for d in drivers if d.name not in pair}
    slices = tuple(_slice(scene, d, samples) for d in drivers)
    return Region(scene.name, scene.units, names, pair, axes,
                  valid.reshape(tuple(len(a) for a in axes)), at, slices)
