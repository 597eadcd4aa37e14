# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The report's error-bound section: bounds against actual errors, refused fractions (issue 10).

``mech_kinematics.tools.report.bounds`` checks the solver's error bounds
against the 50-digit reference over an extreme suite and measures the
fraction of a crank turn refused at each tolerance; these tests run it at the
smoke size and check its claims against independent samplings.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

from mech_kinematics.tools.report import bounds, figures
from mech_kinematics.tools.report.common import MODES

SMOKE = MODES['smoke']
CASES = bounds.bound_cases(SMOKE)
BY_NAME = {case.name: case for case in CASES}
#: Angles of the uniform sampling the refused fractions are checked against.
DENSE = 400_000


@pytest.fixture(scope='module')
def results():
    """Every smoke case's bounds against actual errors, and its refused fractions."""
    return ([bounds.bound_values(case) for case in CASES],
            [bounds.refused_fractions(case, SMOKE) for case in CASES])


def test_suite_covers_the_issue():
    """The suite has every kind of extreme case issue 10 lists, each checked somewhere."""
    names = ' | '.join(BY_NAME)
    for needle in ('toggle', 'change point', 'circles overlap', 'circles miss',
                   'guide at grazing reach', 'guide 1e-9 beyond reach', 'pin through the pivot',
                   'rod/crank = 1e6', 'crank/frame', 'scaled to 1e-300 m',
                   'scaled to 1e+300 m', '1e-06 rpm', '100000 rpm'):
        assert needle in names, needle
    assert all(case.singular or case.samples for case in CASES)


def test_angles_are_the_offsets_from_every_singular_position():
    """Each singular position is checked at itself and 1e-3, 1e-6, 1e-9 rad either side."""
    case = BY_NAME['change point (parallelogram)']
    angles = case.angles()
    assert len(angles) == len(case.singular) * 7
    for offset in (1e-3, 1e-6, 1e-9):
        for position in (0.0, math.pi):
            assert any(abs(a - position - side * offset) < 1e-15
                       for a in angles for side in (1, -1)), (position, offset)


def test_no_bound_is_below_its_actual_error(results):
    """Over the smoke suite every returned value's error is within its bound; none is wrong."""
    checked = 0
    for result in results[0]:
        assert not result.wrong, (result.case.name, result.wrong)
        for value in result.values:
            assert value.actual <= value.bound, (result.case.name, value)
        checked += len(result.values)
        assert result.answered, result.case.name
    stats = bounds.bound_statistics([v for r in results[0] for v in r.values])
    assert stats.below == 0 and stats.values == checked > 1000
    assert 1.0 <= stats.min <= stats.median <= stats.p90 <= stats.max


def test_bounds_are_tight_where_well_conditioned(results):
    """Where kappa <= 10 the bound is within 1e3 x (actual error + 1 ulp of scale)."""
    stats = bounds.bound_statistics([v for r in results[0] for v in r.values])
    assert stats.well > 0
    assert stats.tightness <= 1e3


def test_statistics_of_known_values():
    """bound_statistics: ratios over nonzero errors, zeros counted apart, below counted."""
    def value(actual, bound, well=False):
        return bounds.BoundValue(0.0, 'joints.a.position', 'angle', actual, bound, 1.0,
                                 True, well)

    stats = bounds.bound_statistics([value(1.0, 2.0), value(1.0, 4.0), value(1.0, 8.0),
                                     value(0.0, 1.0), value(2.0, 1.0, well=True)])
    assert (stats.values, stats.exact, stats.below, stats.well) == (5, 1, 1, 1)
    assert (stats.min, stats.median, stats.max) == (0.5, 3.0, 8.0)
    assert stats.tightness == pytest.approx(0.5)


def test_issue_cases_are_refused_by_default(results):
    """1e-6 from the change point, 1e-9 past the pivot: answered with inf, refused by default."""
    for name, offset in (('change point (parallelogram)', 1e-6),
                         ('pin through the pivot', 1e-9)):
        case = BY_NAME[name]
        result = results[0][CASES.index(case)]
        with mpmath.workdps(60):
            angle = float(case.singular[0] + mpmath.mpf(offset))
        near = [v for v in result.values if v.angle == angle]
        assert near and not any(v.accepted for v in near), name


def test_refused_fractions_are_monotone_in_the_tolerance(results):
    """A looser tolerance never refuses more of the turn; nothing exceeds the whole turn."""
    for fractions in results[1]:
        values = [fractions.refused[t] for t in sorted(bounds.TOLERANCES)]
        values.append(fractions.refused[math.inf])
        assert all(a >= b for a, b in zip(values, values[1:], strict=False)), (
            fractions.case.name, values)
        assert values[-1] >= 0 and fractions.no_assembly >= 0
        assert fractions.no_assembly + values[0] <= 1 + 1e-12


def test_refused_fractions_of_singular_cases(results):
    """Every case with a singular position is refused near it at 1e-9; the rest never."""
    for fractions in results[1]:
        refused = fractions.refused[min(bounds.TOLERANCES)]
        if fractions.case.singular:
            assert refused > 0, fractions.case.name
        else:
            assert refused == 0 and fractions.no_assembly == 0, fractions.case.name


@pytest.mark.parametrize('name', ['change point (parallelogram)', 'pin through the pivot'])
def test_refused_fractions_match_a_dense_sampling(results, name):
    """The grid-and-bisection fractions agree with 400,000 evenly spaced angles (array path)."""
    case = BY_NAME[name]
    fractions = results[1][CASES.index(case)]
    angles = -math.pi + 2 * math.pi * (np.arange(DENSE) + 0.5) / DENSE
    slack = (fractions.edges + 2) / DENSE
    for tol in (*bounds.TOLERANCES, math.inf):
        dense = float(np.mean(~case.solve(angles, tol).valid))
        assert abs(fractions.no_assembly + fractions.refused[tol] - dense) <= slack, tol


def test_refused_fractions_do_not_depend_on_the_grid():
    """Refused sets far narrower than a grid step are found on any grid (refinement)."""
    case = BY_NAME['pin 1e-6 r from the pivot']
    coarse = bounds.refused_fractions(case, SMOKE)
    fine = bounds.refused_fractions(case, MODES['quick'])
    for tol, value in coarse.refused.items():
        assert value == pytest.approx(fine.refused[tol], rel=1e-9, abs=1e-15), tol
    assert coarse.refused[bounds.MAX_ERROR] > 0  # narrower than 1e-8 of a turn, still found


def test_figures_are_written(results, tmp_path):
    """plot_bounds and plot_refused write non-empty PNG files."""
    figures.plot_bounds(results[0], tmp_path / 'bounds.png')
    figures.plot_refused(results[1], tmp_path / 'refused.png')
    for name in ('bounds.png', 'refused.png'):
        data = (tmp_path / name).read_bytes()
        assert data.startswith(b'\x89PNG') and len(data) > 10_000, name
