# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Section 6 of the report: the solver's error bounds against the truth, and what they refuse.

Every value the solver returns carries an absolute error bound
(``State.error_bound``, :mod:`mech_kinematics.bounds`), and a state whose
bound exceeds ``max_error`` times its kind's scale is refused (issue 10).
This section checks both claims over an extreme suite (:func:`bound_cases`:
toggles, change points, circles and guides at the edge of assembly, a pin
passing through its pivot, extreme ratios, scales and speeds):

- :func:`bound_values` solves each case with an infinite tolerance at
  :data:`OFFSETS` from every singular position, and puts every value's bound
  beside its actual error against the 50-digit reference
  (:func:`mech_kinematics.verify.reference.value_errors`);
  :func:`bound_statistics` sums them up: no bound may be below its error;
- :func:`refused_fractions` measures, for each case, the fraction of a full
  crank turn refused at each of :data:`TOLERANCES` (and the part that cannot
  assemble, apart): the refused set is sampled on a grid refined around the
  singular positions and each of its edges located by bisection.

mpmath is imported inside the functions (through the reference).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
import math
import statistics
from typing import Any
import warnings

import numpy as np

from .common import Mode, MODES
from ...bounds import MAX_ERROR
from ...errors import AssemblyError, NearSingularWarning, UntrustedError
from ...scene import load_scene
from ...solver import CarriedPoint, Crank, Link, RPR, RRP, Scene, solve
from ...units import rad_per_s_from_rpm, radians_from_degrees
from ...verify.cases import distance_angle, four_bar, slider_crank

__all__ = ['BoundCase', 'BoundStats', 'BoundValue', 'CaseBounds', 'KAPPA_WELL', 'OFFSETS',
           'RefusedFractions', 'TOLERANCES', 'bound_cases', 'bound_statistics', 'bound_values',
           'refused_fractions']

#: Crank turns from every singular position at which the bounds are checked, rad, as
#: decimal strings taken exactly (issue 10).
OFFSETS = ('1e-3', '1e-6', '1e-9')
#: The tolerances (``max_error``) whose refused fractions are measured, loosest last.
TOLERANCES = (1e-9, MAX_ERROR, 1e-3)
#: Offsets of the extra grid angles either side of every singular position, rad:
#: the refused set near a singular position is far narrower than a grid step.
REFINE = tuple(10.0 ** (-k / 20) for k in range(20, 301))
#: Each edge of a refused interval is located to this crank angle, rad.
EDGE = 1e-14
#: An instant is well-conditioned when the reference's condition number of every kind
#: of value is at most this (``reference.condition``; issue 10, test_solve_bounds):
#: there the bound must be within 1e3 x (actual error + 1 ulp of the scale).
KAPPA_WELL = 10.0
#: Below this near-singularity measure kappa exceeds KAPPA_WELL anyway: not computed.
WELL_MEASURE = 0.05
#: Status of a crank angle: answered, refused as untrusted, or no assembly.
ANSWERED, UNTRUSTED, NO_ASSEMBLY = 0, 1, 2


@dataclass(frozen=True, eq=False)
class BoundCase:
    """One mechanism of the extreme suite and where it is checked.

    ``singular`` holds the crank angles (mpmath numbers, rad) of its singular
    positions, or of its nearest approach to one; the bounds are checked
    there and :data:`OFFSETS` either side, and at the ``samples`` (rad).
    """

    name: str
    scene: Scene
    singular: tuple[Any, ...] = ()
    samples: tuple[float, ...] = ()
    speed: float | None = None
    accel: float | None = None
    note: str = ''

    def angles(self) -> list[float]:
        """Return the angles checked: each singular position, OFFSETS either side, samples."""
        import mpmath
        out = []
        with mpmath.workdps(60):
            for position in self.singular:
                out.append(float(position))
                for offset in OFFSETS:
                    out += [float(position - mpmath.mpf(offset)),
                            float(position + mpmath.mpf(offset))]
        return out + list(self.samples)

    def solve(self, angle: Any, max_error: float) -> Any:
        """Solve the case's scene at ``angle`` (float or array), its speed, silently."""
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', NearSingularWarning)
            return solve(self.scene, angle, self.speed, self.accel, max_error=max_error)


def slotted_lever(name: str, pivot_height: float, crank: float = 0.15,
                  speed: float = 4 * math.pi, ram: bool = True) -> Scene:
    """Return a slotted lever about O = 0 driven by a crank about (0, ``pivot_height``).

    The lever carries C, 0.7 m out; with ``ram`` an RRP ram (link 0.3 m) runs
    from C to a guide along y = 0.1. The pin passes closest to the pivot at
    crank angle -90 deg, through it when ``pivot_height == crank``.
    """
    dyads: list[Any] = [RPR('lever', 'O', 'B', 'block')]
    if ram:
        dyads.append(RRP('R', Link('ram_link', 'C', 0.3), 'G', 0.0, 'ram', 1))
    return Scene(name, {'O': (0.0, 0.0), 'A': (0.0, pivot_height), 'G': (0.0, 0.1)},
                 Crank('crank', 'A', 'B', crank, -1.0, speed, 1.0), tuple(dyads),
                 (CarriedPoint('C', 'lever', 'O', 'B', (0.7, 0.0)),))


def _spaced(count: int, start: float = 0.3) -> tuple[float, ...]:
    """Return ``count`` crank angles evenly spaced over a turn from ``start``, rad."""
    return tuple(math.remainder(start + 2 * math.pi * k / count, 2 * math.pi)
                 for k in range(count))


def bound_cases(mode: Mode | None = None) -> list[BoundCase]:
    """Return the extreme suite of issue 10: every kind of singular position, ratio, scale, speed.

    The mechanisms follow ``test/solver/test_solve_bounds.py``'s suite and the
    extreme cases of section 4; every length is in m, every angle in rad.
    """
    import mpmath
    samples = _spaced((mode or MODES['full']).bound_samples)
    with mpmath.workdps(60):
        pi = mpmath.pi
        extended = distance_angle(0.05, 0.1, 0.066 + 0.056)
        inner, outer = distance_angle(0.05, 0.1, 0.06), distance_angle(0.05, 0.1, 0.14)
        # Circles that overlap / miss by 1e-9 at their closest approach (crank angle pi).
        c_overlap, c_miss = 0.15 * (1 + 1e-9) - 0.066, 0.15 * (1 - 1e-9) - 0.066
        meet = distance_angle(0.05, 0.1, 0.066 + c_miss)
        # A guide 1e-9 beyond the rod's reach near crank angle -pi/2: its two edges.
        short = 0.1875 * (1 - 1e-9)
        edge = mpmath.asin((mpmath.mpf(0.0625) - mpmath.mpf(short)) / mpmath.mpf(0.125))
    khurmi = load_scene('khurmi_four_bar_ad150')
    cases = [
        BoundCase('toggle, extended (non-Grashof)', four_bar('toggle', 0.05, 0.066, 0.056, 0.1),
                  (extended, -extended),
                  note='a, b, c, d = 0.05, 0.066, 0.056, 0.1 (four_bar_coupler_points): the '
                       'crank rocks between the two toggles at +-103.8 deg'),
        BoundCase('toggles, folded and extended', four_bar('folded', 0.05, 0.1, 0.04, 0.1, 1.0),
                  (inner, -inner, outer, -outer),
                  note='a, b, c, d = 0.05, 0.1, 0.04, 0.1: |BD| reaches b - c and b + c'),
        BoundCase('change point (parallelogram)', four_bar('change_point', 0.04, 0.1, 0.04, 0.1,
                                                           0.5), (mpmath.mpf(0), pi),
                  note='a = c = 0.04, b = d = 0.1: all pins in line at 0 and 180 deg'),
        BoundCase('circles overlap by 1e-9 at closest', four_bar('overlap', 0.05, 0.066,
                                                                 c_overlap, 0.1), (pi,),
                  note='b + c = (a + d)(1 + 1e-9): the circles nearly miss at 180 deg'),
        BoundCase('circles miss by 1e-9 at closest', four_bar('miss', 0.05, 0.066, c_miss, 0.1),
                  (meet, -meet), note='b + c = (a + d)(1 - 1e-9): no assembly close to '
                                      '180 deg, toggles at its two ends'),
        BoundCase('guide at grazing reach', slider_crank('grazing', 0.125, 0.1875, 0.0625),
                  (-pi / 2,),
                  note='crank 0.125, offset 0.0625, rod 0.1875 (exact in binary): the rod is '
                       'perpendicular to the guide at -90 deg'),
        BoundCase('guide 1e-9 inside reach', slider_crank('inside', 0.125, 0.1875 * (1 + 1e-9),
                                                          0.0625), (-pi / 2,),
                  note='rod 0.1875 (1 + 1e-9)'),
        BoundCase('guide 1e-9 beyond reach', slider_crank('beyond', 0.125, short, 0.0625),
                  (edge, -pi - edge),
                  note='rod 0.1875 (1 - 1e-9): no assembly close to -90 deg, toggles at '
                       'its two ends'),
        BoundCase('pin through the pivot', slotted_lever('through_pivot', 0.15), (-pi / 2,),
                  note='slotted lever, |OA| = crank = 0.15, with a ram: the pin passes '
                       'through O at -90 deg'),
        BoundCase('pin 1e-6 r from the pivot', slotted_lever('near_pivot', 0.15 * (1 + 1e-6),
                                                             ram=False), (-pi / 2,),
                  note='|OA| = 0.15 (1 + 1e-6), no ram (the lever turns half a turn within '
                       '1e-6 rad)'),
        BoundCase('rod/crank = 1.000001', slider_crank('short_rod', 0.1, 0.1000001),
                  (pi / 2, -pi / 2), note='in-line slider-crank, crank 0.1 m; worst at +-90 deg'),
        BoundCase('rod/crank = 1e6', slider_crank('long_rod', 0.1, 1e5), samples=samples,
                  note='in-line slider-crank, crank 0.1 m, rod 1e5 m'),
        BoundCase('crank/frame = 1e-6', four_bar('tiny_crank', 1e-7, 0.15, 0.08, 0.1),
                  samples=samples, note='a = 1e-7, b, c, d = 0.15, 0.08, 0.1'),
    ]
    for size in (1e-300, 1e-6, 1e3, 1e300):
        cases.append(BoundCase(f'four-bar scaled to {size:g} m', four_bar(
            'scaled', 0.04, 0.15, 0.08, 0.15, radians_from_degrees(60),
            speed=khurmi.input.speed, scale=size / 0.15), samples=samples,
            note='khurmi_four_bar_ad150, every length scaled'))
    for rpm in (1e-6, 1e5):
        cases.append(BoundCase(f'crank at {rpm:g} rpm', khurmi, samples=samples,
                               speed=rad_per_s_from_rpm(rpm), accel=1.0,
                               note='khurmi_four_bar_ad150, crank acceleration 1 rad/s^2'))
    return cases


# --- bounds against actual errors ----------------------------------------------------


@dataclass(frozen=True)
class BoundValue:
    """One returned value: its error bound beside its actual error (SI units)."""

    angle: float     # crank angle, rad
    path: str        # the value's path in State.as_dict(), e.g. joints.rocker.velocity
    kind: str        # its kind (mech_kinematics.bounds.KINDS)
    actual: float    # |solver - exact|, against the 50-digit reference
    bound: float     # state.error_bound's value
    scale: float     # state.scales[kind]
    accepted: bool   # the default tolerance answers this instant
    well: bool       # the instant is well-conditioned (kappa <= KAPPA_WELL)


@dataclass
class CaseBounds:
    """A case's values, and what happened at its instants."""

    case: BoundCase
    values: list[BoundValue] = field(default_factory=list)
    answered: int = 0        # instants answered with an infinite tolerance
    refused: int = 0         # instants refused whatever the tolerance
    no_assembly: int = 0     # instants without a real configuration (and refused)
    refused_default: int = 0  # answered instants the default tolerance refuses
    wrong: list[str] = field(default_factory=list)  # answered where nothing assembles


def bound_values(case: BoundCase) -> CaseBounds:
    """Solve ``case`` at each of its angles and compare every bound with the actual error.

    The solver is asked with an infinite tolerance, so that every answer it
    can give is measured; an instant it refuses even then (within rounding of
    an assembly limit) counts as refused. Where the reference finds no
    assembly, the solver must refuse; an answer there is recorded in ``wrong``.
    """
    from ...verify import reference as ref_mod
    model = ref_mod.Model(case.scene)
    result = CaseBounds(case)
    for angle in case.angles():
        try:
            exact = ref_mod.reference(model, angle, case.speed, case.accel)
        except ref_mod.NoAssembly:
            exact = None
        try:
            state = case.solve(angle, math.inf)
        except AssemblyError:
            if exact is None:
                result.no_assembly += 1
            else:
                result.refused += 1
            continue
        if exact is None:
            result.wrong.append(f'answered at {angle!r} rad, where nothing assembles')
            continue
        result.answered += 1
        try:
            case.solve(angle, MAX_ERROR)
            accepted = True
        except UntrustedError:
            accepted = False
            result.refused_default += 1
        well = False
        if accepted and min(state.singularity.values(), default=1.0) >= WELL_MEASURE:
            well = max(ref_mod.condition(model, exact).values()) <= KAPPA_WELL
        joint_bounds, point_bounds = state.error_bound.raw()
        scales = state.scales
        for path, (kind, actual) in ref_mod.value_errors(state, exact).items():
            group, name, quantity = path.split('.')
            table = joint_bounds if group == 'joints' else point_bounds
            bound = float(table[name][('position', 'velocity', 'acceleration').index(quantity)])
            result.values.append(BoundValue(angle, path, kind, actual, bound,
                                            float(scales[kind]), accepted, well))
    return result


@dataclass(frozen=True)
class BoundStats:
    """Bound against actual error over a set of values."""

    values: int      # values compared
    exact: int       # of which the actual error is 0 (no ratio)
    below: int       # values whose bound is below the actual error: must be 0
    min: float       # of bound / actual, over the values with an actual error
    median: float
    p90: float
    max: float
    well: int         # values at well-conditioned instants
    tightness: float  # max of bound / (actual + 1 ulp of its scale) over those


def bound_statistics(values: Sequence[BoundValue]) -> BoundStats:
    """Return the statistics of bound / actual error over ``values``."""
    ratios = np.array([v.bound / v.actual for v in values if v.actual > 0])
    tight = [v.bound / (v.actual + float(np.spacing(v.scale))) for v in values if v.well]
    below = sum(v.bound < v.actual for v in values)
    if not len(ratios):
        return BoundStats(len(values), len(values), below, *(math.nan,) * 4, len(tight),
                          max(tight, default=math.nan))
    return BoundStats(len(values), len(values) - len(ratios), below, float(ratios.min()),
                      float(statistics.median(ratios)), float(np.percentile(ratios, 90)),
                      float(ratios.max()), len(tight), max(tight, default=math.nan))


# --- refused fractions of a turn --------------------------------------------------


@dataclass
class RefusedFractions:
    """Fractions of a full crank turn that a case's solver refuses.

    ``no_assembly`` is where the mechanism cannot assemble (the solver says
    so); ``refused`` maps each tolerance to the fraction refused although it
    assembles (its bounds exceed the tolerance, or it lies within rounding of
    an assembly limit); ``refused[math.inf]`` is the part refused whatever the
    tolerance. ``angles`` is the number of grid angles, ``edges`` the number of
    edges located by bisection.
    """

    case: BoundCase
    no_assembly: float
    refused: dict[float, float]
    angles: int
    edges: int


def _status(case: BoundCase, angle: float, max_error: float) -> int:
    try:
        case.solve(angle, max_error)
    except UntrustedError:
        return UNTRUSTED
    except AssemblyError:
        return NO_ASSEMBLY
    return ANSWERED


def _grid(count: int, positions: Sequence[Any]) -> np.ndarray:
    """Return sorted angles over [-pi, pi): ``count`` evenly, and REFINE about ``positions``."""
    import mpmath
    angles = [-math.pi + 2 * math.pi * k / count for k in range(count)]
    with mpmath.workdps(60):
        for position in positions:
            angles.append(float(position))
            for offset in REFINE:
                angles += [float(position - offset), float(position + offset)]
    grid = np.unique(np.remainder(np.array(angles) + math.pi, 2 * math.pi) - math.pi)
    return grid[grid < math.pi]


def _measure(grid: np.ndarray, flags: np.ndarray,
             inside: Callable[[float], bool]) -> tuple[float, list[float]]:
    """Return the length (rad) of the set where ``inside`` holds over a turn, and its edges.

    ``flags`` is ``inside`` at the sorted ``grid`` angles; between two grid
    angles that agree the set is taken to hold (or not) throughout, and where
    they differ the edge is located by bisection to :data:`EDGE`.
    """
    ends = np.append(grid, grid[0] + 2 * math.pi)
    held = np.append(flags, flags[0])
    lengths = np.diff(ends)
    total = float(lengths[held[:-1] & held[1:]].sum())
    edges = []
    for i in np.flatnonzero(held[:-1] != held[1:]):
        lo, hi, first = float(ends[i]), float(ends[i + 1]), bool(held[i])
        while hi - lo > EDGE:
            mid = 0.5 * (lo + hi)
            if not lo < mid < hi:
                break
            if inside(mid) == first:
                lo = mid
            else:
                hi = mid
        edge = 0.5 * (lo + hi)
        total += (edge - float(ends[i])) if first else (float(ends[i + 1]) - edge)
        edges.append(edge)
    return total, edges


def refused_fractions(case: BoundCase, mode: Mode | None = None,
                      tolerances: Sequence[float] = TOLERANCES) -> RefusedFractions:
    """Return the fractions of a full crank turn refused at each tolerance, and not assembled.

    Every angle is solved by the single-angle path, as the node solves its
    ticks. The set that cannot assemble is found first, on ``mode.bound_grid``
    evenly spaced angles and :data:`REFINE` offsets either side of every
    singular position of the case; each of its edges is a singular position
    too (a dyad at the limit of its reach), so the grid of the refused sets
    is refined about those edges as well.
    """
    count = (mode or MODES['full']).bound_grid
    grid = _grid(count, case.singular)
    at_inf = np.array([_status(case, float(x), math.inf) for x in grid])
    no_assembly, limits = _measure(grid, at_inf == NO_ASSEMBLY,
                                   lambda x: _status(case, x, math.inf) == NO_ASSEMBLY)
    if limits:
        grid = _grid(count, (*case.singular, *limits))
        at_inf = np.array([_status(case, float(x), math.inf) for x in grid])
    edges = len(limits)
    fractions = {}
    for tol in (*tolerances, math.inf):
        status = at_inf.copy()
        if tol != math.inf:
            for i in np.flatnonzero(at_inf == ANSWERED):
                status[i] = _status(case, float(grid[i]), tol)
        length, found = _measure(grid, status == UNTRUSTED,
                                 lambda x, t=tol: _status(case, x, t) == UNTRUSTED)
        fractions[tol] = length / (2 * math.pi)
        edges += len(found)
    return RefusedFractions(case, no_assembly / (2 * math.pi), fractions, len(grid), edges)
