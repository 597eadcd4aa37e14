# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The report (issue 5): its numbers come from the functions tested here.

Extreme cases are asserted one by one: each either meets its error bound
(``BOUND_FACTOR * eps * max(1, kappa)`` against the 50-digit reference) or is
flagged by the solver. The clock simulation's closed form is checked bit for
bit against tick-by-tick accumulation. Timings are never asserted: only
their presence, since the machine is shared.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
import re
import subprocess
import sys

from hypothesis import example, given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.textbook import find_answer
from mech_kinematics.tools import reference as ref
from mech_kinematics.tools import report

EPS = float(np.finfo(float).eps)
#: Our solver's worst relative error of accelerations on the work-precision
#: mechanisms, against the reference (a few eps times their mild conditioning).
RTOL_OURS = 1e-14
#: Newton-Raphson at a step tolerance of 1e-10 is converged to rounding.
RTOL_NEWTON_TIGHT = 1e-13
#: The time base's crank angle after any simulated run: a few ulp of pi, rad.
ATOL_TIMEBASE = 4 * math.ulp(math.pi)
#: The naive accumulation after a year at 1000 rpm is off by at least this, rad.
MIN_NAIVE_YEAR_ERROR = 1e-3
#: The formula audit: the solver's product form is within this factor of the
#: best textbook form of the RRR height near a toggle.
AUDIT_FACTOR = 3.0
#: Velocity digits lost over -log10(measure) 1e-6 .. 1e-12 rad from an RRR toggle:
#: the condition number grows as 1 / measure**2, so about 2.
LOSS_RATIO_RANGE = (1.8, 2.3)
SECTIONS = ('## 1. The 50-digit reference', '## 2. Work-precision',
            '## 3. Error against run time of the node', '## 4. Stiff and extreme cases',
            '## 5. Cost growth')

QUICK = report.MODES['quick']
SMOKE = report.MODES['smoke']


# --- the clock ---------------------------------------------------------------


def steps():
    """Positive steps: the node's omega * dt at typical speeds, and arbitrary ones."""
    return st.one_of(st.sampled_from([r * math.pi / 30 * 1e-3 for r in (10, 1000, 100_000)]),
                     st.sampled_from([0.5, 1.5, 0.375, 2.0 ** -10, 3 * 2.0 ** -40]),
                     st.floats(1e-9, 30.0))


def starts():
    """Start angles, including ones just below a power of two."""
    return st.one_of(st.floats(-4.0, 4.0), st.sampled_from([0.0, 2.0 ** 52, 2.0 ** 53 - 7]))


@given(steps(), starts(), st.integers(0, 20_000))
@example(0.5, 2.0 ** 52, 1000)        # ties to even: stagnation
@example(1.5, 2.0 ** 52 + 1, 1000)    # ties to even: first step differs
@example(0.7, 2.0 ** 53 - 7, 1000)    # crosses a binade
@settings(max_examples=200, deadline=None, derandomize=True)
def test_closed_form_accumulation_is_exact(step, start, ticks):
    """The binade-by-binade closed form equals tick-by-tick float accumulation bit for bit."""
    assert report.naive_accumulate(start, step, ticks) == report.naive_cumsum(start, step, ticks)


def test_closed_form_accumulation_of_a_year_is_fast():
    """3e10 ticks in a few hundred rational steps, and it agrees with a million ticks too."""
    step = 1e5 * math.pi / 30 * 1e-3
    assert report.naive_accumulate(1.0, step, 10**6) == report.naive_cumsum(1.0, step, 10**6)
    year = report.naive_accumulate(1.0, step, 365 * 86_400 * 1000)
    assert math.isfinite(year) and year > 3e11


def test_wrapped_trace_matches_the_loop():
    """The traced wrapped accumulation ends where the plain loop does."""
    step = 1000 * math.pi / 30 * 1e-3
    trace = report.naive_wrapped_trace(0.3, step, 5000, 1000)
    assert [k for k, _ in trace] == [1000, 2000, 3000, 4000, 5000]
    assert trace[-1][1] == report.naive_wrapped(0.3, step, 5000)


@pytest.fixture(scope='module')
def clock():
    """Compute the clock section in smoke size (one speed, four run times)."""
    return report.clock_errors(SMOKE)


def test_timebase_stays_exact(clock):
    """After every run time the time base's crank angle is within a few ulp of pi."""
    rows, check = clock
    assert check['brute_equal']
    for row in rows:
        assert row.angle_error['timebase'] <= ATOL_TIMEBASE, row


def test_naive_accumulation_drifts(clock):
    """After a year the naive angle is off by radians-scale amounts, the wrapped one less."""
    rows, _ = clock
    year = next(r for r in rows if r.duration == '1 year')
    assert year.angle_error['naive'] >= MIN_NAIVE_YEAR_ERROR
    assert year.angle_error['timebase'] < year.angle_error['naive, wrapped'] \
        < year.angle_error['naive']
    errors = [r.angle_error['naive'] for r in rows]
    assert errors == sorted(errors)


# --- extreme cases ----------------------------------------------------------------


CASES = report.extreme_cases(QUICK)


@pytest.mark.parametrize('case', CASES, ids=[c.name for c in CASES])
def test_extreme_case_meets_bound_or_is_flagged(case):
    """Every instant of the case meets BOUND_FACTOR * eps * kappa, or the solver flagged it."""
    result = report.evaluate_case(case)
    for angle in result.angles:
        if angle.verdict == 'meets bound':
            for kind, error in angle.errors.items():
                bound = report.BOUND_FACTOR * EPS * max(1.0, angle.kappa[kind])
                assert error <= bound, (angle.angle, kind, error, bound)
        else:
            assert angle.flag in ('warned', 'refused'), angle
            assert angle.verdict in ('flagged', 'refused (no assembly)'), angle
        if angle.reference == 'no assembly':
            assert angle.flag == 'refused'
        if angle.reference == 'singular':
            assert angle.flag == 'refused'


def test_extreme_cases_cover_the_issue():
    """The cases are those issue 5 lists, toggles to the edge of assembly."""
    names = ' | '.join(c.name for c in CASES)
    for needle in ('1e-3 rad from toggle', '1e-6 rad from toggle', '1e-9 rad from toggle',
                   '1e-12 rad from toggle', 'change-point four-bar at flat',
                   'from flat', 'circles miss by 1e-9', 'rod/crank = 1.000001', 'rod/crank = 1e6',
                   'scaled to 1e-06 m', 'scaled to 1000 m', 'crank speed 1e-06 rpm',
                   'crank speed 100000 rpm', 'pin 1e-6 r from pivot', 'edge'):
        assert needle in names, needle


def test_missing_circles_are_refused():
    """Circles 1e-9 apart: no assembly in the reference, AssemblyError from the solver."""
    case = next(c for c in CASES if c.name.startswith('circles miss'))
    result = report.evaluate_case(case)
    assert result.reference == 'no assembly'
    assert result.verdict == 'refused (no assembly)'
    with pytest.raises(mk.AssemblyError, match='do not meet'):
        mk.solve(case.scene, case.angles[0])


def test_toggle_errors_track_conditioning():
    """Toward the toggle the error grows with kappa and stays under the bound (cases 1-4)."""
    results = [report.evaluate_case(c) for c in CASES if 'from toggle' in c.name]
    errors = [r.errors['velocity'] for r in results]
    assert errors == sorted(errors)
    assert all(r.verdict == 'meets bound' for r in results)
    assert [r.flag for r in results] == ['none', 'none', 'warned', 'warned']


def test_formula_audit_product_form_is_as_good():
    """Near the toggle the solver's product form is within 3x the best textbook form."""
    for row in report.formula_audit():
        best = min(v for k, v in row.errors.items() if k != 'product (solver)')
        assert row.errors['product (solver)'] <= AUDIT_FACTOR * best, row


# --- work-precision and cost --------------------------------------------------------


def test_printed_answers_are_the_packaged_ones():
    """Each work-precision mechanism draws a packaged textbook answer of its own scene."""
    for mechanism, quantity in report.WP_PRINTED.items():
        answer = find_answer(mk.load_scene(report.WP_SCENES[mechanism]).name, quantity)
        assert answer.kind in ('computed', 'measured', 'derived from measured')
        assert not answer.discrepancy, mechanism


def test_geneva_configurations_stay_engaged():
    """The Geneva instants lie within the engaged 135..225 deg."""
    scene = mk.load_scene('geneva')
    conf = report.configurations(scene, 12, report.WP_RANGES['Geneva'])
    degrees = np.degrees(conf.thetas)
    assert degrees.min() > 135 and degrees.max() < 225


@pytest.fixture(scope='module')
def four_bar_wp():
    """Compute the four-bar's work-precision points in smoke size."""
    return report.work_precision('four-bar', SMOKE)


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
    headline = report.headline([four_bar_wp])['four-bar']
    newton = headline['alternatives']['newton']
    assert newton['cost_ratio'] == pytest.approx(newton['seconds'] / headline['ours_seconds'])


@pytest.mark.parametrize('stages', [1, 3, 10])
def test_chain_scene_assembles_everywhere(stages):
    """The chained four-bar assembles at every crank angle with one RRR per stage."""
    scene = report.chain_scene(stages)
    assert len(scene.dyads) == stages
    state = mk.solve(scene, np.linspace(-math.pi, math.pi, 721))
    assert state.valid.all()


def test_chain_scene_against_reference():
    """The solver on a 3-stage chain meets the bound against the reference."""
    scene = report.chain_scene(3)
    exact = ref.reference(scene, 0.3)
    kappa = ref.condition(scene, exact)
    for kind, error in ref.compare(mk.solve(scene, 0.3), exact).items():
        assert error <= report.BOUND_FACTOR * EPS * max(1.0, kappa[kind]), kind


def test_chain_scene_rejects_no_stages():
    """A chain needs a stage: the error names the count."""
    with pytest.raises(ValueError, match='got 0'):
        report.chain_scene(0)


# --- the command and the whole report ---------------------------------------------


def test_add_parser_registers_report():
    """add_parser adds `report -o DIR [--quick | --smoke]` with a handler."""
    parser = argparse.ArgumentParser()
    report.add_parser(parser.add_subparsers(dest='command'))
    args = parser.parse_args(['report', '-o', 'out', '--quick'])
    assert args.mode == 'quick' and args.output == 'out' and callable(args.handler)
    assert parser.parse_args(['report', '-o', 'x']).mode == 'full'
    with pytest.raises(SystemExit):
        parser.parse_args(['report', '-o', 'x', '--quick', '--smoke'])


def test_import_is_light():
    """Importing the report module loads neither matplotlib, SciPy, mpmath nor tqdm."""
    code = ('import sys, mech_kinematics.tools.report; '
            "assert not {'matplotlib', 'scipy', 'mpmath', 'tqdm'} & set(sys.modules)")
    subprocess.run([sys.executable, '-c', code], check=True, timeout=60)


@pytest.fixture(scope='module')
def quick_report(tmp_path_factory):
    """`report --quick` in a temporary folder: its result and the folder."""
    out = tmp_path_factory.mktemp('report')
    status = report.main(['-o', str(out), '--quick', '--no-progress'])
    assert status == 0
    return out


def test_quick_report_has_every_section(quick_report):
    """REPORT.md has the five sections and every figure it links exists."""
    text = (quick_report / 'REPORT.md').read_text()
    for section in SECTIONS:
        assert section in text
    figures = re.findall(r'!\[[^\]]*\]\(([^)]+)\)', text)
    assert len(figures) >= 7
    for name in figures:
        assert (quick_report / name).stat().st_size > 10_000, name


def test_quick_report_has_no_failures(quick_report):
    """The extreme-case table has a verdict on every row and no FAIL."""
    text = (quick_report / 'REPORT.md').read_text()
    table = text.split('## 4.')[1].split('###')[0]
    rows = [line for line in table.splitlines() if re.match(r'\| \d+ \|', line)]
    assert len(rows) == len(CASES)
    assert all(re.search(r'\*\*(meets bound|flagged|refused \(no assembly\))\*\*', r)
               for r in rows)
    assert 'FAIL' not in text


def test_cli_main_writes_the_smoke_report(tmp_path):
    """`python -m mech_kinematics.tools.report -o DIR --smoke` exits 0 and prints the path."""
    result = subprocess.run([sys.executable, '-m', 'mech_kinematics.tools.report', '-o',
                             str(tmp_path), '--smoke', '--no-progress'],
                            capture_output=True, text=True, timeout=300, check=False)
    assert result.returncode == 0, result.stderr
    assert Path(result.stdout.strip()) == tmp_path / 'REPORT.md'
    assert '## 5. Cost growth' in (tmp_path / 'REPORT.md').read_text()


def test_velocities_lose_twice_the_measure_digits_near_a_toggle():
    """Near an RRR toggle velocities lose about 2 x -log10(measure) digits (NEAR_SINGULAR doc)."""
    toggles = [c for c in CASES if 'from toggle' in c.name and '1e-3 rad' not in c.name]
    rows = report.digits_lost([report.evaluate_case(c) for c in toggles])
    assert len(rows) == len(toggles) == 3
    for result, measure, lost in rows:
        ratio = lost['velocity'] / -math.log10(measure)
        assert LOSS_RATIO_RANGE[0] <= ratio <= LOSS_RATIO_RANGE[1], (result.case.name, ratio)
