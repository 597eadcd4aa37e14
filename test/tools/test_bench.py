# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``bench``: spreads of repeated timings and the ratios to the hand-written forms."""

from dataclasses import replace
import json
import math

import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.scene import load_scene
from mech_kinematics.solver.carried import CarriedPoint
from mech_kinematics.tools import bench


def test_rows_hold_min_median_max_and_median_ratios():
    rows = bench.measure(['khurmi_four_bar_ad150', 'geneva', 'steam_engine_500_2000'], 64, 3)
    assert [r['scene'] for r in rows] == ['khurmi_four_bar_ad150',
                                          'khurmi_four_bar_ad150 (hand-written)', 'geneva',
                                          'steam_engine_500_2000',
                                          'steam_engine_500_2000 (hand-written)']
    for row in rows:
        for key in ('single_us', 'array_us'):
            low, mid, high = row[key]
            assert 0 < low <= mid <= high
    solver, hand, geneva = rows[:3]
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
                                             bench.slider_crank_numpy),
                                            (bench.scotch_yoke_math, bench.scotch_yoke_numpy)])
def test_hand_written_forms_agree(scalar, vector):
    angles = np.linspace(0.1, 2 * math.pi, 7, endpoint=False)
    arrays = vector(angles, -4.0, 3.0)
    for k, theta in enumerate(angles):
        values = scalar(float(theta), -4.0, 3.0)
        np.testing.assert_allclose(values, [a[k] for a in arrays], rtol=1e-13, atol=1e-15)


HAND_WRITTEN = ('four_bar_coupler_points', 'khurmi_engine_15_7', 'khurmi_four_bar_ad150',
                'offset_slider_crank', 'piston_300', 'rocking_lever', 'scotch_yoke',
                'slider_crank_150_600', 'steam_engine_500_2000')


def test_which_scenes_have_hand_written_forms():
    """One crank and one RRR, one RRP on a horizontal guide, or a Scotch yoke; not the others."""
    from mech_kinematics.scene import scene_names
    have = tuple(n for n in scene_names() if bench.hand_written(load_scene(n)) is not None)
    assert have == HAND_WRITTEN


@pytest.mark.parametrize('name', HAND_WRITTEN)
def test_hand_written_forms_give_the_solvers_answer(name):
    """The hand-written forms compute the same motion as mk.solve, to rounding."""
    scene = load_scene(name)
    scalar, _ = bench.hand_written(scene)
    w, al = scene.input.speed, scene.input.accel
    for theta in scene.input.angle + np.array([0.0, 0.05, -0.05]):
        state = mk.solve(scene, float(theta))
        values = scalar(float(theta), w, al)
        dyad = scene.dyads[0]
        if dyad.kind == 'RRR':      # four-bar: coupler and rocker, B and C
            coupler, rocker = (state.joints[link.name] for link in dyad.links)
            got = values[:6] + values[12:18]
            point = state.points[dyad.point]
            want = (coupler.position, rocker.position, coupler.velocity, rocker.velocity,
                    coupler.acceleration, rocker.acceleration, *point.position,
                    *point.velocity, *point.acceleration)
        elif dyad.kind == 'RPP':    # Scotch yoke: the yoke's x, the pin's height, rates
            yoke, pin = state.joints[dyad.slider], state.joints[dyad.slot_slider]
            got = values
            b = state.points[scene.input.point]
            want = (yoke.position, pin.position, yoke.velocity, pin.velocity,
                    yoke.acceleration, pin.acceleration, *b.position, *b.velocity,
                    *b.acceleration)
        else:                       # slider-crank: piston x, rod angle, rates
            rod = state.joints[dyad.link.name]
            point = state.points[dyad.point]
            got = values[:6]
            want = (point.position[0], rod.position, point.velocity[0], rod.velocity,
                    point.acceleration[0], rod.acceleration)
        scale = [max(abs(x) for x in want[i::2]) for i in range(2)]
        for k, (g, x) in enumerate(zip(got, want, strict=True)):
            if k < 2 and dyad.kind == 'RRR' or k == 1 and dyad.kind == 'RRP':
                g, x = math.remainder(g - x, 2 * math.pi), 0.0     # angles modulo 2 pi
            assert g == pytest.approx(x, abs=1e-12 * max(scale) + 1e-12), (name, k)
        # Then every reported carried point, as the solver reports it.
        carried = [p.name for p in scene.points if p.name in scene.output_points]
        rest = values[18 if dyad.kind == 'RRR' else 12:]
        assert len(rest) == 6 * len(carried)
        for k, point in enumerate(carried):
            p = state.points[point]
            want = (*p.position, *p.velocity, *p.acceleration)
            scale = max(np.abs(p.position).max(), np.abs(p.velocity).max(),
                        np.abs(p.acceleration).max())
            np.testing.assert_allclose(rest[6 * k:6 * k + 6], want, rtol=0,
                                       atol=1e-13 * scale, err_msg=f'{name} {point}')


def test_hand_written_forms_carry_the_reported_points_on_the_dyads_links():
    """Coupler points on both links, either end as origin; a point elsewhere: no form."""
    scene = load_scene('four_bar_coupler_points')
    assert bench.carried_of(scene, scene.dyads[0].links) == (
        (0, True, 0.04, 0.0), (0, True, 0.04, -0.03), (1, True, 0.03, -0.02))
    steam = load_scene('steam_engine_500_2000')
    assert [c[:2] for c in bench.carried_of(steam, (steam.dyads[0].link,))] == [(0, False)] * 2
    on_e = CarriedPoint('H', 'coupler', 'E', 'C', (0.01, 0.0))   # its frame starts at E
    moved = replace(scene, points=(*scene.points, on_e), outputs_points=None)
    assert 'H' in moved.output_points and bench.hand_written(moved) is None
    # Not reported: computed by neither the solver nor the hand-written form.
    quiet = replace(moved, outputs_points=('A', 'B', 'C'))
    assert bench.hand_written(quiet)[0].keywords == {
        'geometry': bench.geometry_of(scene)[1]}
