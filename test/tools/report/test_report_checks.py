# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The report's first section: the reference's self-checks and the published golden files."""

from __future__ import annotations

import json

from helpers import REFERENCE, REFERENCE_NAMES

from mech_kinematics.tools.report import checks
from mech_kinematics.tools.report.common import MODES

#: From the decimal inputs as written, the reference matches the published
#: doubles to this many units in the last place (see test_reference.py).
MAX_ULPS_GOLDEN = 1
#: From the scene's double inputs, agreement relative to (|value| + scale).
RTOL_GOLDEN = 1e-15
#: Loop-closure residual over the mechanism's size, and route A against route B.
ATOL_RESIDUAL = 1e-55
RTOL_ROUTES = 1e-30
#: The solver's worst relative error on the smoke scenes (mildly conditioned).
RTOL_SOLVER = 1e-14


def test_golden_checks_find_the_published_files():
    """From a source tree the report compares the reference with every golden file.

    See issue 9: after the move into tools/ the report looked for the golden
    files under the package and silently left their table out.
    """
    assert checks.golden_folder() == REFERENCE
    rows = {row.scene: row for row in checks.golden_checks()}
    assert set(rows) == set(REFERENCE_NAMES)
    for name, row in rows.items():
        data = json.loads((REFERENCE / f'{name}.json').read_text())
        expected = sum(3 * len(case['expected']['joints']) + 6 * len(case['expected']['points'])
                       for case in data['cases'])
        assert row.values == expected
        assert row.max_ulps_decimal <= MAX_ULPS_GOLDEN
        assert 0 < row.max_rel_double <= RTOL_GOLDEN


def test_golden_checks_without_golden_files(tmp_path):
    """An installed copy has no golden files: no rows, no error."""
    assert checks.golden_checks(tmp_path / 'absent') == []
    assert checks.golden_checks(tmp_path) == []


def test_reference_checks_on_the_smoke_scenes():
    """The reference closes its loops, its two routes agree, the solver is at rounding."""
    rows = checks.reference_checks(MODES['smoke'])
    assert [row.scene for row in rows] == list(MODES['smoke'].check_scenes)
    for row in rows:
        assert row.residual <= ATOL_RESIDUAL and row.iterations >= 1
        assert set(row.routes) == {'velocity', 'angular velocity', 'acceleration',
                                   'angular acceleration'}
        assert max(row.routes.values()) <= RTOL_ROUTES
        assert row.solver <= RTOL_SOLVER
