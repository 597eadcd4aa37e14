# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The extreme suite: stiff and extreme cases, digits lost and formula audit (issue 5, part 4).

Extreme cases are asserted one by one: each either meets its error bound
(``BOUND_FACTOR * eps * max(1, kappa)`` against the 50-digit reference) or is
flagged by the solver.
"""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.verify import extreme

EPS = float(np.finfo(float).eps)
#: The formula audit: the solver's product form is within this factor of the
#: best textbook form of the RRR height near a toggle.
AUDIT_FACTOR = 3.0
#: Velocity digits lost over -log10(measure) 1e-6 .. 1e-12 rad from an RRR toggle:
#: the condition number grows as 1 / measure**2, so about 2.
LOSS_RATIO_RANGE = (1.8, 2.3)

#: Angles added around each multi-angle case: the report's quick run's.
EXTRA_ANGLES = 2
CASES = extreme.extreme_cases(EXTRA_ANGLES)


@pytest.mark.parametrize('case', CASES, ids=[c.name for c in CASES])
def test_extreme_case_meets_bound_or_is_flagged(case):
    """Every instant of the case meets BOUND_FACTOR * eps * kappa, or the solver flagged it."""
    result = extreme.evaluate_case(case)
    for angle in result.angles:
        if angle.verdict == 'meets bound':
            for kind, error in angle.errors.items():
                bound = extreme.BOUND_FACTOR * EPS * max(1.0, angle.kappa[kind])
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
    result = extreme.evaluate_case(case)
    assert result.reference == 'no assembly'
    assert result.verdict == 'refused (no assembly)'
    with pytest.raises(mk.AssemblyError, match='do not meet'):
        mk.solve(case.scene, case.angles[0])


def test_toggle_errors_track_conditioning():
    """Toward the toggle the error grows with kappa and stays under the bound (cases 1-4).

    The flag is what the default tolerance does: 1e-9 and 1e-12 rad from the
    toggle the solver refuses (UntrustedError), it does not merely warn.
    """
    results = [extreme.evaluate_case(c) for c in CASES if 'from toggle' in c.name]
    errors = [r.errors['velocity'] for r in results]
    assert errors == sorted(errors)
    assert all(r.verdict == 'meets bound' for r in results)
    assert [r.flag for r in results] == ['none', 'none', 'untrusted', 'untrusted']


def test_formula_audit_product_form_is_as_good():
    """Near the toggle the solver's product form is within 3x the best textbook form."""
    for row in extreme.formula_audit():
        best = min(v for k, v in row.errors.items() if k != 'product (solver)')
        assert row.errors['product (solver)'] <= AUDIT_FACTOR * best, row


def test_velocities_lose_twice_the_measure_digits_near_a_toggle():
    """Near an RRR toggle velocities lose about 2 x -log10(measure) digits (NEAR_SINGULAR doc)."""
    toggles = [c for c in CASES if 'from toggle' in c.name and '1e-3 rad' not in c.name]
    rows = extreme.digits_lost([extreme.evaluate_case(c) for c in toggles])
    assert len(rows) == len(toggles) == 3
    for result, measure, lost in rows:
        ratio = lost['velocity'] / -math.log10(measure)
        assert LOSS_RATIO_RANGE[0] <= ratio <= LOSS_RATIO_RANGE[1], (result.case.name, ratio)


def test_import_is_light():
    """Importing the room, its cases and the extreme suite loads no mpmath, tool or ROS code."""
    code = ('import sys, mech_kinematics.verify, mech_kinematics.verify.cases, '
            'mech_kinematics.verify.extreme; '
            "heavy = {'matplotlib', 'scipy', 'mpmath', 'rclpy'} & set(sys.modules); "
            "above = [m for m in sys.modules if m.startswith(('mech_kinematics.tools', "
            "'mech_kinematics.ros'))]; "
            'assert not heavy and not above, (heavy, above)')
    subprocess.run([sys.executable, '-c', code], check=True, timeout=60)
