# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``bench``: spreads of repeated timings and the ratios to the hand-written forms."""

import json
import math

import numpy as np
import pytest

from mech_kinematics.tools import bench


def test_rows_hold_min_median_max_and_median_ratios():
    rows = bench.measure(['khurmi_four_bar_ad150', 'geneva'], 64, 3)
    assert [r['scene'] for r in rows] == ['khurmi_four_bar_ad150',
                                          'khurmi_four_bar_ad150 (hand-written)', 'geneva']
    for row in rows:
        for key in ('single_us', 'array_us'):
            low, mid, high = row[key]
            assert 0 < low <= mid <= high
    solver, hand, geneva = rows
    assert solver['single_ratio'] == solver['single_us'][1] / hand['single_us'][1]
    assert solver['array_ratio'] == solver['array_us'][1] / hand['array_us'][1]
    assert 'single_ratio' not in geneva and hand['baseline_of'] == 'khurmi_four_bar_ad150'


def test_table_marks_each_ratio_against_its_target():
    rows = [{'scene': 's', 'single_us': [1.0, 2.0, 3.0], 'array_us': [0.1, 0.2, 0.3],
             'single_ratio': 7.5, 'array_ratio': 1.6},
            {'scene': 's (hand-written)', 'single_us': [1.0] * 3, 'array_us': [0.1] * 3,
             'baseline_of': 's'},
            {'scene': 't', 'single_us': [1.0] * 3, 'array_us': [0.1] * 3}]
    lines = bench.table(rows, 10, 3)
    assert lines[0].startswith('min / median / max of 3 runs')
    assert lines[3].split()[1:] == ['1.00/2.00/3.00', '7.50', 'ok', '0.100/0.200/0.300',
                                    '1.60', 'over']
    assert lines[5].split()[-3:] == ['-', '0.100/0.100/0.100', '-']


def test_json_output(capsys):
    assert bench.main(['--angles', '8', '--repeat', '1', '--json']) == 0
    data = json.loads(capsys.readouterr().out)
    assert data['angles'] == 8 and len(data['rows']) >= 11


@pytest.mark.parametrize('scalar, vector', [(bench.four_bar_math, bench.four_bar_numpy),
                                            (bench.slider_crank_math,
                                             bench.slider_crank_numpy)])
def test_hand_written_forms_agree(scalar, vector):
    angles = np.linspace(0.1, 2 * math.pi, 7, endpoint=False)
    arrays = vector(angles, -4.0, 3.0)
    for k, theta in enumerate(angles):
        values = scalar(float(theta), -4.0, 3.0)
        np.testing.assert_allclose(values, [a[k] for a in arrays], rtol=1e-13, atol=1e-15)
