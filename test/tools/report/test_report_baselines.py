# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The report's work-precision section: our solver against the usual alternatives.

Timings are never asserted, only their presence, since the machine is
shared; errors are asserted against the 50-digit reference.
"""

from __future__ import annotations

import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.textbook import find_answer
from mech_kinematics.tools.report import baselines
from mech_kinematics.tools.report.common import MODES, WP_SCENES

#: Our solver's worst relative error of accelerations on the work-precision
#: mechanisms, against the reference (a few eps times their mild conditioning).
RTOL_OURS = 1e-14
#: Newton-Raphson at a step tolerance of 1e-10 is converged to rounding.
RTOL_NEWTON_TIGHT = 1e-13


def test_printed_answers_are_the_packaged_ones():
    """Each work-precision mechanism draws a packaged textbook answer of its own scene."""
    for mechanism, quantity in baselines.WP_PRINTED.items():
        answer = find_answer(mk.load_scene(WP_SCENES[mechanism]).name, quantity)
        assert answer.kind in ('computed', 'measured', 'derived from measured')
        assert not answer.discrepancy, mechanism


def test_geneva_configurations_stay_engaged():
    """The Geneva instants lie within the engaged 135..225 deg."""
    scene = mk.load_scene('geneva')
    conf = baselines.configurations(scene, 12, baselines.WP_RANGES['Geneva'])
    degrees = np.degrees(conf.thetas)
    assert degrees.min() > 135 and degrees.max() < 225


@pytest.fixture(scope='module')
def four_bar_wp():
    """Compute the four-bar's work-precision points in smoke size."""
    return baselines.work_precision('four-bar', MODES['smoke'])


def test_work_precision_ours_at_machine_precision(four_bar_wp):
    """Our solver's accelerations are within 1e-14 of the reference, both paths."""
    ours = [p for p in four_bar_wp.points if p.family == 'ours']
    assert {p.label for p in ours} == {'ours, one angle', 'ours, arrays'}
    for p in ours:
        assert max(p.point_acc, p.angular_acc) <= RTOL_OURS
        assert p.seconds > 0


def test_work_precision_alternatives(four_bar_wp):
    """Tight Newton converges to rounding; differences and solve_ivp are far less accurate."""
    points = {p.label: p for p in four_bar_wp.points}
    assert max(points['tol 1e-10'].point_acc, points['tol 1e-10'].angular_acc) \
        <= RTOL_NEWTON_TIGHT
    ours = max(points['ours, arrays'].point_acc, points['ours, arrays'].angular_acc)
    for family in ('differences', 'solve_ivp'):
        for p in (p for p in four_bar_wp.points if p.family == family):
            assert min(p.point_acc, p.angular_acc) > 100 * ours, p
    printed = four_bar_wp.printed
    assert printed['miss'] <= printed['stated']


def test_headline_ratios(four_bar_wp):
    """The headline ratios are the table's numbers divided, one run."""
    headline = baselines.headline([four_bar_wp])['four-bar']
    newton = headline['alternatives']['newton']
    assert newton['cost_ratio'] == pytest.approx(newton['seconds'] / headline['ours_seconds'])


def test_work_points_hold_every_order_and_their_timing_spread(four_bar_wp):
    """Positions, velocities and accelerations are measured; timings as min <= median <= max."""
    for p in four_bar_wp.points:
        if p.family == 'printed':
            continue
        assert set(p.errors) == {'position', 'angle', 'velocity', 'angular velocity',
                                 'acceleration', 'angular acceleration'}, p
        low, mid, high = p.spread
        assert 0 < low <= mid <= high and mid == p.seconds
        assert p.point_acc == p.errors['acceleration']
        assert p.angular_acc == p.errors['angular acceleration']
    ours = baselines.headline([four_bar_wp])['four-bar']['ours_by_order']
    assert set(ours) == {'position', 'velocity', 'acceleration'}
    assert 0 < max(ours.values()) <= RTOL_OURS
    # Differences of positions: exact positions, velocities far off, accelerations worse.
    diff = next(p for p in four_bar_wp.points if p.label == 'step 1e-03 rad')
    orders = baselines.by_order(diff.errors)
    assert orders['position'] <= RTOL_OURS < 100 * RTOL_OURS < orders['velocity']


def test_by_order_takes_the_worse_of_points_and_links():
    errors = {'position': 1.0, 'angle': 2.0, 'velocity': 5.0, 'angular velocity': 3.0,
              'acceleration': 7.0}
    assert baselines.by_order(errors) == {'position': 2.0, 'velocity': 5.0,
                                          'acceleration': 7.0}
