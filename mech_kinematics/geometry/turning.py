# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The turning-moment diagram of a crank, its fluctuation of energy, and the flywheel.

For a scene with forces (``masses``, ``gravity`` or ``loads``),
:func:`turning_moment_from_scene` turns a crank once (crank angles 0 to
2 pi, CCW from +x) at a constant speed and gives the **turning-moment
diagram**: every driver's effort (:attr:`.Forces.efforts`: a crank's torque,
N m; an actuator's force, N) over the turn, with

- its **mean** over the turn (the crank's mean torque; times the speed, the
  mean power the driver gives);
- its **extremes** and the crank angles where they occur;
- for the turning crank, the **fluctuation of energy** ``dE``: the energy
  the driver gives beyond the mean, ``E(theta) = int_0^theta (T - T_mean)``,
  swings between its largest and its least value over the turn, and ``dE``
  is their difference (Khurmi & Gupta, *Theory of Machines*, "maximum
  fluctuation of energy": the largest and least energy are where the curve
  crosses its mean; with several loops ``dE`` is not always one loop's area,
  it is the largest sum of consecutive ones). The areas between crossings
  are given too (:attr:`TurningMoment.loops`);
- and, for one crank, :meth:`TurningMoment.flywheel`: the moment of inertia
  a flywheel needs for a coefficient of fluctuation of speed
  ``Cs = (w_max - w_min) / w_mean``, ``I = dE / (w_mean^2 Cs)`` (the
  textbook formula; ``w_mean`` the crank's speed).

The crank turns at a constant speed (the scene's, or ``speed``) and, unless
``accel`` is given, no angular acceleration: the textbook's diagram, drawn
at the mean speed, as the flywheel formula assumes. The direction it turns
changes nothing here: the energy curve is the same function of the angle,
run the other way.

A scene with several drivers: the first crank among them turns once at its
speed, every other driver held at rest at its start position (``check``'s
slices hold them so too); each driver's effort over that turn is given
(the held ones' is what holds them), the fluctuation of energy only for the
turning crank. The flywheel is for a scene of one crank.

How accurate each figure is (each carries its own bound or estimate):

- every effort computed has the solver's error bound (:mod:`.solver.forces`);
- an extreme's value is one the solver computed, with that bound; its place
  is refined by golden-section search to about 1e-9 rad (the curve is flat
  there, so the value's error from the place is of order ``T'' 1e-18``,
  added to the bound);
- integrals are composite 8-point Gauss-Legendre sums on the pieces of the
  turn between the points where an effort jumps (a Geneva pin entering or
  leaving a slot) and the crossings of the mean, at two resolutions, the
  panels doubled until they agree within :data:`QUADRATURE_TOLERANCE` of the
  integral of ``|T|`` (at most :data:`MOST_PANELS` panels a turn). The error
  estimate of each integral is the two resolutions' difference plus the
  weighted error bounds of the efforts and the sums' rounding; it is an
  estimate, not a bound (a feature narrower than a panel at both resolutions
  could escape it);
- the crossings of the mean are found where the sampled ``T - T_mean``
  changes sign beyond its bound (:data:`SAMPLES` angles a turn plus the
  quadrature's nodes), then bisected to adjacent doubles; ``E`` is
  stationary there, so a crossing's place enters ``dE`` at second order. Two
  crossings within one sample step are not seen: a loop narrower than the
  step is missed (its area is then at most the step times ``|T - T_mean|``
  there);
- ``dE``'s error sums those of the integrals up to the two crossings and of
  the mean times the angles; the flywheel's is ``dE``'s over ``w^2 Cs``.

Pure: the solver and NumPy, no drawing. Angles in rad, efforts in N m or N,
energies in J, inertias in kg m^2.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
import math
from typing import Any
import warnings

import numpy as np
import numpy.typing as npt

from ..bounds import U
from ..errors import AssemblyError, NearSingularWarning, SceneError
from ..solver import Scene, solve

__all__ = ['Extreme', 'Flywheel', 'Loop', 'MOST_PANELS', 'NODES', 'PANELS',
           'QUADRATURE_TOLERANCE', 'SAMPLES', 'Effort', 'TurningMoment',
           'effort_unit', 'turning_crank', 'turning_moment_from_scene']

Array = npt.NDArray[np.float64]

_TURN = 2.0 * math.pi
#: Angles sampled over the turn, both ends, to find crossings and extremes: every 0.5 deg.
SAMPLES = 721
#: Gauss-Legendre nodes per panel.
NODES = 8
#: Panels a turn at the first (coarser) resolution; doubled until the two agree.
PANELS = 32
#: The most panels a turn at the finer resolution.
MOST_PANELS = 4096
#: The two resolutions agree when they differ by at most this times the integral of |T|.
QUADRATURE_TOLERANCE = 1e-13
#: Golden-section search stops when the bracket is narrower than this, rad.
EXTREME_TOLERANCE = 1e-9

_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


def effort_unit(angular: bool) -> str:
    """Return the unit of a driver's effort: ``'N m'`` for a crank (``angular``), else ``'N'``."""
    return 'N m' if angular else 'N'


@dataclass(frozen=True)
class Extreme:
    """The largest or least value of an effort over the turn.

    Attributes
    ----------
    value : float
        N m or N, as the solver computed it at ``angle``.
    angle : float
        The turning crank's angle, rad in [0, 2 pi), to about
        :data:`EXTREME_TOLERANCE`.
    bound : float
        The value's error bound (the solver's, plus the effect of the place).
    """

    value: float
    angle: float
    bound: float


@dataclass(frozen=True)
class Effort:
    """One driver's effort over the turn: its mean and extremes.

    Attributes
    ----------
    driver : str
        The driver's name.
    angular : bool
        Whether it is a crank (torque, N m) rather than an actuator (force, N).
    mean : float
        The mean over the turn (of the turning crank's angle), N m or N.
    mean_error : float
        The estimate of the mean's error.
    maximum, minimum : Extreme
        The extremes and where.
    """

    driver: str
    angular: bool
    mean: float
    mean_error: float
    maximum: Extreme
    minimum: Extreme

    @property
    def unit(self) -> str:
        """``'N m'`` or ``'N'``."""
        return effort_unit(self.angular)


@dataclass(frozen=True)
class Loop:
    """The area between the turning-moment curve and its mean from one crossing to the next.

    ``area`` (J) is positive where the effort is above the mean (the driver
    gives more than its mean: the crank would speed up), negative below;
    ``start`` and ``end`` are crank angles (rad, CCW, ``end`` may exceed 2 pi
    for the loop that wraps past 0); ``error`` its estimate.
    """

    start: float
    end: float
    area: float
    error: float


@dataclass(frozen=True)
class Flywheel:
    """The flywheel for a coefficient of fluctuation of speed.

    ``inertia`` (kg m^2) ``= dE / (speed^2 cs)``, with ``cs = (w_max - w_min)
    / w_mean`` and ``speed`` the mean speed ``w_mean`` (rad/s, > 0);
    ``error`` its estimate (from ``dE``'s and the rounding).
    """

    cs: float
    speed: float
    inertia: float
    error: float


@dataclass(frozen=True)
class TurningMoment:
    """A crank's turn with forces: every driver's effort, the fluctuation of energy.

    Attributes
    ----------
    scene : str
        The scene's name.
    crank : str
        The driver that turns.
    speed, accel : float
        Its speed (rad/s, signed) and acceleration (rad/s^2) over the turn.
    held : dict of str to float
        The other drivers, at rest at these positions (rad or m).
    single : bool
        Whether the crank is the scene's only driver (the flywheel needs it).
    angles : ndarray, shape (n,)
        The angles the diagram is drawn at, rad, 0 to 2 pi.
    efforts : dict of str to ndarray, shape (n,)
        Every driver's effort there, N m or N.
    drivers : dict of str to Effort
        Every driver's mean and extremes.
    crossings : tuple of float
        Where the crank's effort crosses its mean, rad in [0, 2 pi), in order.
    loops : tuple of Loop
        The areas between consecutive crossings (the last wraps past 0).
    energy_max, energy_min : float or None
        Where the energy ``E`` is largest and least (crossings, rad); None
        without crossings.
    fluctuation : float
        ``dE``, J: the largest minus the least ``E`` over the turn.
    fluctuation_error : float
        Its error estimate, J.
    panels : int
        Gauss-Legendre panels a turn at the finer resolution used.
    """

    scene: str
    crank: str
    speed: float
    accel: float
    held: dict[str, float]
    single: bool
    angles: Array
    efforts: dict[str, Array]
    drivers: dict[str, Effort]
    crossings: tuple[float, ...]
    loops: tuple[Loop, ...]
    energy_max: float | None
    energy_min: float | None
    fluctuation: float
    fluctuation_error: float
    panels: int

    @property
    def mean(self) -> float:
        """The turning crank's mean effort over the turn, N m."""
        return self.drivers[self.crank].mean

    @property
    def power(self) -> float:
        """The mean power the turning crank's driver gives, W: mean torque times speed."""
        return self.mean * self.speed

    def flywheel(self, cs: float) -> Flywheel:
        """Return the flywheel for the coefficient of fluctuation of speed ``cs``.

        ``cs = (w_max - w_min) / w_mean``, in (0, 2); ``I = dE / (w_mean^2
        cs)`` with ``w_mean`` the crank's speed.

        Raises
        ------
        ValueError
            If ``cs`` is not in (0, 2), the crank does not turn (speed 0), or
            it is not the scene's only driver.
        """
        cs = float(cs)
        if not (0.0 < cs < 2.0):
            msg = (f'Expected a coefficient of fluctuation of speed (w_max - w_min) / w_mean '
                   f'above 0 and below 2, got {cs!r}')
            raise ValueError(msg)
        if not self.single:
            msg = (f'Expected a scene driven by one crank for a flywheel, got {self.scene}, '
                   f'with several drivers ({", ".join(self.drivers)})')
            raise ValueError(msg)
        speed = abs(self.speed)
        if speed == 0.0:
            msg = (f'Expected crank "{self.crank}" turning (a mean speed above 0) for a '
                   f'flywheel, got 0 rad/s')
            raise ValueError(msg)
        inertia = self.fluctuation / (speed * speed * cs)
        error = self.fluctuation_error / (speed * speed * cs) + 4.0 * U * inertia
        return Flywheel(cs, speed, inertia, error)


def turning_crank(scene: Scene) -> str | None:
    """Return the name of the crank a turn turns: the scene's first crank, or None."""
    return next((d.name for d in scene.drivers if d.joint_type.angular), None)


def turning_moment_from_scene(scene: Scene, *, speed: float | None = None,
                              accel: float = 0.0, samples: int = SAMPLES,
                              max_error: float = math.inf) -> TurningMoment:
    """Turn the scene's crank once and return its turning-moment diagram and ``dE``.

    Parameters
    ----------
    scene : Scene
        A scene with forces (``masses``, ``gravity`` or ``loads``) and a crank.
    speed : float, optional, keyword-only
        The crank's speed, rad/s, signed; default the scene's.
    accel : float, keyword-only
        The crank's angular acceleration, rad/s^2, the same at every angle;
        default 0 (uniform turning, the textbook's diagram).
    samples : int, keyword-only
        Angles of the diagram (:attr:`TurningMoment.angles`) and of the search
        for crossings and extremes, at least 8.
    max_error : float, keyword-only
        The solver's tolerance (:func:`mech_kinematics.solve`); default
        ``inf``: every finite answer is taken, its bound carried into the
        figures' errors (a value refused for its bound alone, as where every
        force vanishes and its scale with it, would stop the turn).

    Raises
    ------
    SceneError
        If the scene has no forces, no crank, or the crank cannot turn fully
        (the mechanism does not assemble, or its forces cannot be bounded, at
        some angle; named).
    """
    if scene.dynamics is None:
        msg = (f'Expected a scene with masses, gravity or loads for a turning-moment '
               f'diagram, got {scene.name} without')
        raise SceneError(msg)
    crank = turning_crank(scene)
    if crank is None:
        msg = (f'Expected a crank to turn for a turning-moment diagram, got {scene.name}, '
               f'driven by {", ".join(d.name for d in scene.drivers)}, none a crank')
        raise SceneError(msg)
    if samples < 8:
        msg = f'Expected at least 8 samples, got {samples}'
        raise ValueError(msg)
    drivers = scene.drivers
    index = next(i for i, d in enumerate(drivers) if d.name == crank)
    omega = float(drivers[index].speed if speed is None else speed)
    alpha = float(accel)
    held = {d.name: float(d.start) for d in drivers if d.name != crank}
    study = _Study(scene, index, omega, alpha, held, max_error)
    return study.run(samples)


@dataclass(frozen=True)
class _Piece:
    """One piece of the turn integrated: per driver its sum and error, and its nodes' values."""

    sums: dict[str, float]
    errors: dict[str, float]
    nodes: Array
    values: dict[str, Array]
    bounds: dict[str, Array]


class _Study:
    """One turn of one crank: the solver as a function of the crank's angle."""

    def __init__(self, scene: Scene, index: int, omega: float, alpha: float,
                 held: Mapping[str, float], max_error: float) -> None:
        self.scene = scene
        self.index = index
        self.drivers = scene.drivers
        self.crank = self.drivers[index].name
        self.omega, self.alpha = omega, alpha
        self.held = dict(held)
        self.max_error = max_error
        self.names = [d.name for d in self.drivers]

    # --- the solver ------------------------------------------------------------------

    def _arguments(self, theta: Any) -> tuple[Any, Any, Any]:
        """Return ``solve``'s positions, speeds and accelerations at crank angles ``theta``."""
        if len(self.drivers) == 1:
            return theta, self.omega, self.alpha
        n = np.shape(theta)
        positions, speeds, accels = [], [], []
        for i, driver in enumerate(self.drivers):
            if i == self.index:
                positions.append(theta)
                speeds.append(np.full(n, self.omega) if n else self.omega)
                accels.append(np.full(n, self.alpha) if n else self.alpha)
            else:
                positions.append(np.full(n, self.held[driver.name]) if n
                                 else self.held[driver.name])
                speeds.append(np.zeros(n) if n else 0.0)
                accels.append(np.zeros(n) if n else 0.0)
        return positions, speeds, accels

    def efforts(self, theta: Array) -> tuple[dict[str, Array], dict[str, Array]]:
        """Return every driver's effort and its bound at crank angles ``theta``.

        The angles are taken within the first turn (the efforts repeat every
        turn; an intermittent drive's wheel, which indexes once a turn, is
        then where it is in the first).
        """
        theta = np.mod(np.asarray(theta, dtype=np.float64), _TURN)
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', NearSingularWarning)
            state = solve(self.scene, *self._arguments(theta), max_error=self.max_error)
        valid = np.asarray(state.valid, dtype=bool)
        if not valid.all():
            self._refuse(float(theta[int(np.flatnonzero(~valid)[0])]))
        forces = state.forces
        assert forces is not None
        values = {name: np.asarray(forces.efforts[name], dtype=np.float64) + np.zeros(theta.shape)
                  for name in self.names}
        bounds = {name: np.asarray(forces.effort_bounds[name], dtype=np.float64)
                  + np.zeros(theta.shape) for name in self.names}
        return values, bounds

    def _refuse(self, theta: float) -> None:
        """Raise the one-line reason the crank cannot turn through ``theta``."""
        units = self.scene.units
        where = f'crank "{self.crank}" at {units.angle_text(theta % _TURN)}'
        if self.held:
            where += ' (' + ', '.join(
                f'{d.name} held at {d.position_text(self.held[d.name], units)}'
                for d in self.drivers if d.name in self.held) + ')'
        reason = 'its answer cannot be trusted'
        try:
            with warnings.catch_warnings():
                warnings.simplefilter('ignore', NearSingularWarning)
                solve(self.scene, *self._arguments(theta), max_error=self.max_error)
        except AssemblyError as error:
            reason = error.reason
        msg = (f'Expected {self.scene.name} to turn a whole turn with its forces bounded for a '
               f'turning-moment diagram, got {where}: {reason}')
        raise SceneError(msg)

    def jumps(self) -> list[float]:
        """Return where an effort may jump in [0, 2 pi): the intermittent windows' ends."""
        if not self.scene.intermittent:
            return []
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', NearSingularWarning)
            state = solve(self.scene, *self._arguments(0.0), max_error=math.inf)
        ends: set[float] = set()
        for engagement in state.intermittent.values():
            ends.update((float(engagement.entry) % _TURN, float(engagement.exit) % _TURN))
        return sorted(ends)

    # --- the study ---------------------------------------------------------------------

    def run(self, samples: int) -> TurningMoment:
        """Return the study of the turn, the diagram drawn at ``samples`` angles."""
        crank = self.crank
        edges = sorted({0.0, *self.jumps(), _TURN})
        # The mean: integrals over the smooth pieces, resolutions doubled until they agree.
        pieces, panels = self._integrate(edges, PANELS)
        mean = {name: sum(p.sums[name] for p in pieces) / _TURN for name in self.names}
        mean_error = {name: sum(p.errors[name] for p in pieces) / _TURN for name in self.names}
        # The diagram, and the samples searched for crossings and extremes (with the nodes).
        angles = np.linspace(0.0, _TURN, samples)
        values, bounds = self.efforts(angles)
        grid = np.concatenate([angles[:-1], *(p.nodes for p in pieces)])
        order = np.argsort(grid, kind='stable')
        grid = grid[order]
        grid_values = {name: np.concatenate([values[name][:-1], *(p.values[name] for p in pieces)]
                                            )[order] for name in self.names}
        grid_bounds = {name: np.concatenate([bounds[name][:-1], *(p.bounds[name] for p in pieces)]
                                            )[order] for name in self.names}
        extremes = self._extremes(grid, grid_values, grid_bounds, edges)
        # Crossings of the crank's mean, then the areas between them.
        crossings = self._crossings(grid, grid_values[crank] - mean[crank],
                                    grid_bounds[crank] + mean_error[crank], mean[crank])
        cut = sorted({*edges, *crossings})
        segments, used = self._integrate(cut, panels // 2)
        mean = {name: sum(p.sums[name] for p in segments) / _TURN for name in self.names}
        mean_error = {name: sum(p.errors[name] for p in segments) / _TURN
                      + 2.0 * U * abs(mean[name]) for name in self.names}
        loops, fluctuation, error, e_max, e_min = self._energy(
            cut, [p.sums[crank] for p in segments], [p.errors[crank] for p in segments],
            crossings, mean[crank], mean_error[crank])
        drivers = {name: Effort(name, d.joint_type.angular, mean[name], mean_error[name],
                                *extremes[name])
                   for name, d in zip(self.names, self.drivers, strict=True)}
        return TurningMoment(self.scene.name, crank, self.omega, self.alpha, self.held,
                             len(self.drivers) == 1, angles, values, drivers,
                             tuple(crossings), loops, e_max, e_min, fluctuation, error,
                             max(panels, used))

    def _nodes(self, edges: list[float], panels: int) -> tuple[Array, Array, list[int]]:
        """Return the Gauss-Legendre nodes and weights on each piece between ``edges``."""
        x, w = np.polynomial.legendre.leggauss(NODES)
        nodes, weights, counts = [], [], []
        for a, b in zip(edges[:-1], edges[1:], strict=True):
            count = max(1, math.ceil(panels * (b - a) / _TURN))
            ends = np.linspace(a, b, count + 1)
            half = 0.5 * np.diff(ends)[:, None]
            middle = 0.5 * (ends[:-1] + ends[1:])[:, None]
            nodes.append((middle + half * x).ravel())
            weights.append((half * w).ravel())
            counts.append(count * NODES)
        return np.concatenate(nodes), np.concatenate(weights), counts

    def _sums(self, edges: list[float], panels: int) -> list[_Piece]:
        """Return each piece's Gauss-Legendre sums (its error: their bounds and rounding)."""
        nodes, weights, counts = self._nodes(edges, panels)
        values, bounds = self.efforts(nodes)
        pieces = []
        start = 0
        for count in counts:
            part = slice(start, start + count)
            start += count
            w = weights[part]
            v = {name: values[name][part] for name in self.names}
            b = {name: bounds[name][part] for name in self.names}
            sums = {name: float(np.sum(w * v[name])) for name in self.names}
            spread = {name: float(np.sum(w * b[name]))
                      + (count + 2) * U * float(np.sum(w * np.abs(v[name])))
                      for name in self.names}
            pieces.append(_Piece(sums, spread, nodes[part], v, b))
        return pieces

    def _integrate(self, edges: list[float], panels: int) -> tuple[list[_Piece], int]:
        """Return each piece between ``edges`` integrated, and the panels a turn used.

        Two resolutions, ``panels`` and twice as many, doubled until every
        driver's two sums agree within :data:`QUADRATURE_TOLERANCE` of the
        integral of its ``|T|``, or the finer reaches :data:`MOST_PANELS`.
        A piece's error is the two sums' difference plus the finer's bounds
        and rounding; its sums, nodes and values are the finer's.
        """
        coarse = self._sums(edges, panels)
        while True:
            fine = self._sums(edges, 2 * panels)
            agreed = True
            for name in self.names:
                size = sum(abs(p.sums[name]) + p.errors[name] for p in fine)
                gap = sum(abs(f.sums[name] - c.sums[name])
                          for f, c in zip(fine, coarse, strict=True))
                agreed &= gap <= QUADRATURE_TOLERANCE * size
            if agreed or 2 * panels >= MOST_PANELS:
                break
            coarse, panels = fine, 2 * panels
        pieces = [_Piece(f.sums, {name: abs(f.sums[name] - c.sums[name]) + f.errors[name]
                                  for name in self.names}, f.nodes, f.values, f.bounds)
                  for f, c in zip(fine, coarse, strict=True)]
        return pieces, 2 * panels

    def _extremes(self, grid: Array, values: Mapping[str, Array], bounds: Mapping[str, Array],
                  edges: list[float]) -> dict[str, tuple[Extreme, Extreme]]:
        """Return each driver's largest and least effort, refined by golden-section search."""
        wanted = []    # (driver, sign, low, high) of each search: sign +1 for a maximum
        for name in self.names:
            for sign in (1.0, -1.0):
                i = int(np.argmax(sign * values[name]))
                low, high = _bracket(grid, i, edges)
                wanted.append((name, sign, low, high, float(grid[i])))
        names = [w[0] for w in wanted]
        signs = np.array([w[1] for w in wanted])
        lows = np.array([w[2] for w in wanted])
        highs = np.array([w[3] for w in wanted])

        def measure(theta: Array) -> tuple[Array, Array]:
            v, b = self.efforts(theta)
            return (np.array([signs[k] * v[n][k] for k, n in enumerate(names)]),
                    np.array([b[n][k] for k, n in enumerate(names)]))

        best, at, bound, curvature = _golden(measure, lows, highs)
        # The sampled values themselves, should the search have found less (flat, noisy).
        result: dict[str, list[Extreme]] = {name: [] for name in self.names}
        for k, (name, sign, _, _, sampled) in enumerate(wanted):
            i = int(np.argmax(sign * values[name]))
            value, angle, e = sign * best[k], at[k], bound[k]
            if sign * values[name][i] > best[k]:
                value, angle, e = float(values[name][i]), sampled, float(bounds[name][i])
            e += 0.5 * curvature[k] * EXTREME_TOLERANCE ** 2
            result[name].append(Extreme(float(value), float(angle % _TURN), float(e)))
        return {name: (pair[0], pair[1]) for name, pair in result.items()}

    def _crossings(self, grid: Array, excess: Array, bound: Array, mean: float) -> list[float]:
        """Return where ``T - mean`` changes sign beyond its bound, bisected to adjacent floats."""
        sign = np.where(excess > bound, 1, np.where(excess < -bound, -1, 0))
        kept = np.flatnonzero(sign)
        if len(kept) < 2:
            return []
        low, high, below = [], [], []
        for a, b in zip(kept, np.roll(kept, -1), strict=True):
            if sign[a] != sign[b]:
                low.append(float(grid[a]))
                high.append(float(grid[b]) + (_TURN if b <= a else 0.0))
                below.append(sign[a] < 0)
        if not low:
            return []
        lo, hi, rising = np.array(low), np.array(high), np.array(below)

        def above(theta: Array) -> npt.NDArray[np.bool_]:
            v, _ = self.efforts(theta)
            return v[self.crank] - mean > 0.0

        while True:
            middle = 0.5 * (lo + hi)
            open_ = (middle > lo) & (middle < hi)
            if not open_.any():
                break
            m = middle[open_]
            up = above(m)
            # Rising (below the mean, then above): the crossing is below a point above.
            to_high = up == rising[open_]
            lo_open, hi_open = lo[open_], hi[open_]
            hi_open = np.where(to_high, m, hi_open)
            lo_open = np.where(to_high, lo_open, m)
            lo[open_], hi[open_] = lo_open, hi_open
        return sorted(float((0.5 * (a + b)) % _TURN) for a, b in zip(lo, hi, strict=True))

    @staticmethod
    def _energy(cut: list[float], sums: list[float], errors: list[float],
                crossings: list[float], mean: float, mean_error: float
                ) -> tuple[tuple[Loop, ...], float, float, float | None, float | None]:
        """Return the loops, ``dE``, its error, and where ``E`` is largest and least."""
        if not crossings:
            # The effort stays within its bounds of the mean: E within their integral of 0.
            return (), 0.0, sum(errors) + _TURN * mean_error, None, None
        # E at every edge, from 0: the integral less the mean times the angle.
        energy = [0.0]
        spent = [0.0]
        for a, b, q, e in zip(cut[:-1], cut[1:], sums, errors, strict=True):
            energy.append(energy[-1] + q - mean * (b - a))
            spent.append(spent[-1] + e + U * abs(energy[-1]))
        at = {edge: k for k, edge in enumerate(cut)}
        values = [(energy[at[c]], c) for c in crossings]
        errors_at = [spent[at[c]] + c * mean_error for c in crossings]
        top = max(range(len(values)), key=lambda k: values[k][0])
        low = min(range(len(values)), key=lambda k: values[k][0])
        fluctuation = values[top][0] - values[low][0]
        error = errors_at[top] + errors_at[low] + 2.0 * U * abs(fluctuation)
        loops = []
        for k, (e, c) in enumerate(values):
            e_next, c_next = values[(k + 1) % len(values)]
            end = c_next if c_next > c else c_next + _TURN
            area = e_next - e if c_next > c else e_next + (energy[-1] - e)
            loops.append(Loop(c, end, area, errors_at[k] + errors_at[(k + 1) % len(values)]))
        return tuple(loops), fluctuation, error, values[top][1], values[low][1]


def _bracket(grid: Array, i: int, edges: list[float]) -> tuple[float, float]:
    """Return the neighbours of sample ``i`` (periodic), clipped to its smooth piece."""
    n = len(grid)
    low = float(grid[i - 1]) - (_TURN if i == 0 else 0.0)
    high = float(grid[(i + 1) % n]) + (_TURN if i == n - 1 else 0.0)
    x = float(grid[i])
    for edge in edges:
        for e in (edge - _TURN, edge, edge + _TURN):
            if low < e <= x:
                low = e
            if x <= e < high:
                high = e
    if high <= low:
        high = low + 1e-12
    return low, high


def _golden(measure: Callable[[Array], tuple[Array, Array]], low: Array, high: Array
            ) -> tuple[Array, Array, Array, Array]:
    """Return the largest ``measure`` in each [low, high], where, its bound, and |curvature|.

    Golden-section search on all brackets at once (``measure`` returns one
    value and bound per bracket), to :data:`EXTREME_TOLERANCE`; the
    curvature is a central second difference 1e-3 rad either side.
    """
    a, b = low.copy(), high.copy()
    c = b - _GOLDEN * (b - a)
    d = a + _GOLDEN * (b - a)
    fc, _ = measure(c)
    fd, _ = measure(d)
    while np.max(b - a) > EXTREME_TOLERANCE:
        left = fc >= fd                      # the largest lies in [a, d]
        a, b = np.where(left, a, c), np.where(left, d, b)
        new_c, new_d = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
        probe = np.where(left, new_c, new_d)
        fp, _ = measure(probe)
        c, d = np.where(left, new_c, d), np.where(left, c, new_d)
        fc, fd = np.where(left, fp, fd), np.where(left, fc, fp)
    middle = 0.5 * (a + b)
    f_mid, bound = measure(middle)
    h = 1e-3
    f_left, _ = measure(middle - h)
    f_right, _ = measure(middle + h)
    curvature = np.abs(f_left - 2.0 * f_mid + f_right) / (h * h)
    return f_mid, middle, bound, curvature
