# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Where a mechanism assembles over a crank turn, and how it moves there. See issue 11.

Every expected value is a hand calculation from the link lengths (law of
cosines), never the solver's own numbers.
"""

from __future__ import annotations

import math

from helpers import equilateral_chain
import pytest

import mech_kinematics as mk
from mech_kinematics.geometry import assembly as asm

#: Ends of ranges, toggles and dead centres are refined to 1e-12 rad; hand values
#: from acos and atan2 are good to a few 1e-16: this leaves room for both.
ATOL_ANGLE = 1e-11  # rad
TURN = 2 * math.pi


def four_bar(name, ground, crank, coupler, rocker, angle=0.0, branch=mk.Branch.PLUS):
    """Return a four-bar ABCD (m): A at the origin, D on +x, crank AB, coupler BC, rocker DC."""
    links = (mk.Link('coupler', 'B', coupler), mk.Link('rocker', 'D', rocker))
    return mk.Scene(name, {'A': (0.0, 0.0), 'D': (ground, 0.0)},
                    mk.Crank('crank', 'A', 'B', crank, angle, 1.0),
                    (mk.RRR('C', links, branch),), units=mk.SceneUnits('mm', 'deg'))


def test_triple_rocker_assembles_within_its_limits():
    """four_bar_coupler_points (d 100, a 50, b 66, c 56 mm) assembles for |theta| <= 103.79 deg.

    |BD| = b + c at the limit: cos(theta) = (a^2 + d^2 - (b + c)^2) / (2 a d).
    """
    scene = mk.load_scene('four_bar_coupler_points')
    limit = math.acos((50 ** 2 + 100 ** 2 - 122 ** 2) / (2 * 50 * 100))
    assert math.degrees(limit) == pytest.approx(103.79, abs=0.01)
    result = asm.assembly_from_scene(scene)
    (start, end), = result.ranges
    assert start == pytest.approx(-limit, abs=ATOL_ANGLE)
    assert end == pytest.approx(limit, abs=ATOL_ANGLE)
    (gap_start, gap_end), = result.gaps
    assert gap_start == pytest.approx(limit, abs=ATOL_ANGLE)
    assert gap_end == pytest.approx(TURN - limit, abs=ATOL_ANGLE)
    assert [t.dyad for t in result.toggles] == ['RRR C', 'RRR C']
    assert [t.angle for t in result.toggles] == pytest.approx([limit, TURN - limit],
                                                              abs=ATOL_ANGLE)
    assert result.toggles[0].links == ('coupler', 'rocker')
    (transmission,) = result.transmission
    assert transmission.minimum == 0.0 and transmission.angle == result.toggles[0].angle
    (loop,) = result.loops
    assert loop.grashof == 'triple-rocker'
    assert loop.lengths == pytest.approx((0.1, 0.05, 0.066, 0.056), rel=1e-15)
    assert loop.names == ('AD', 'crank', 'coupler', 'rocker')
    assert result.summary() == 'does not assemble for crank angles 103.792..256.208 deg'
    assert asm.assembly_summary(scene) == result.summary()


def test_slider_crank_dead_centres_at_0_and_180_deg():
    """An in-line slider-crank (piston_300) reverses at 0 and 180 deg, s = l + r and l - r."""
    result = asm.assembly_from_scene(mk.load_scene('piston_300'))
    assert result.everywhere and result.ranges == ((0.0, TURN),) and result.gaps == ()
    assert result.toggles == ()
    first, second = result.dead_centres
    assert abs(math.remainder(first.angle, TURN)) <= ATOL_ANGLE
    assert second.angle == pytest.approx(math.pi, abs=ATOL_ANGLE)
    assert (first.joint, first.kind, first.in_line) == ('piston', 'prismatic', ('crank', 'rod'))
    assert first.position == pytest.approx(0.17 + 0.05, rel=1e-12)
    assert second.position == pytest.approx(0.17 - 0.05, rel=1e-12)
    # The rod is furthest from the line of stroke at 90 deg: asin(r / l) off it.
    (transmission,) = result.transmission
    assert transmission.minimum == pytest.approx(math.acos(0.05 / 0.17), rel=1e-12)
    assert transmission.angle == pytest.approx(math.pi / 2, abs=1e-7)
    assert asm.assembly_summary(mk.load_scene('piston_300')) == 'assembles at every crank angle'


def test_crank_rocker_dead_centres_and_transmission_by_hand():
    """Khurmi's four-bar: the rocker reverses with crank and coupler in line; mu_min = acos 0.7.

    Extended, AC = b + a = 190 mm: cos(CAD) = (AC^2 + AD^2 - DC^2) / (2 AC AD); folded,
    AC = b - a = 110 mm, the crank points away from C. At theta = 0, BD = d - a and
    cos(mu) = (b^2 + c^2 - BD^2) / (2 b c) = 0.7.
    """
    result = asm.assembly_from_scene(mk.load_scene('khurmi_four_bar_ad150'))
    extended = math.acos((190 ** 2 + 150 ** 2 - 80 ** 2) / (2 * 190 * 150))
    folded = math.pi + math.acos((110 ** 2 + 150 ** 2 - 80 ** 2) / (2 * 110 * 150))
    angles = [c.angle for c in result.dead_centres]
    assert angles == pytest.approx([extended, folded], abs=ATOL_ANGLE)
    assert all(c.joint == 'rocker' and c.in_line == ('crank', 'coupler')
               for c in result.dead_centres)
    (transmission,) = result.transmission
    assert transmission.minimum == pytest.approx(math.acos(0.7), rel=1e-12)
    assert abs(math.remainder(transmission.angle, TURN)) < 1e-6  # flat minimum at 0
    (loop,) = result.loops
    assert loop.grashof == 'crank-rocker' and loop.points == ('A', 'B', 'C', 'D')


@pytest.mark.parametrize(('lengths', 'expected'), [
    ((150, 40, 150, 80), 'crank-rocker'),      # s = input
    ((20, 60, 70, 80), 'double-crank'),        # s = ground
    ((60, 70, 20, 80), 'double-rocker'),       # s = coupler
    ((70, 80, 60, 20), 'rocker-crank'),        # s = output
    ((100, 40, 100, 40), 'change point'),      # s + l = p + q (a parallelogram)
    ((100, 50, 66, 56), 'triple-rocker'),      # s + l > p + q
])
def test_grashof_classes(lengths, expected):
    """Grashof: s + l against p + q, and which link is shortest."""
    assert asm.grashof_class(*lengths) == expected


def test_double_crank_assembles_everywhere_and_is_classed():
    """A double crank (ground shortest) assembles at every angle and has no dead centre."""
    result = asm.assembly_from_scene(four_bar('drag_link', 0.02, 0.06, 0.07, 0.08))
    assert result.everywhere and result.dead_centres == ()
    assert [loop.grashof for loop in result.loops] == ['double-crank']


def test_change_point_toggles_inside_the_range():
    """A parallelogram's links all come in line at 0 and 180 deg: toggles within the turn."""
    result = asm.assembly_from_scene(four_bar('parallelogram', 0.1, 0.04, 0.1, 0.04, 0.5))
    assert [loop.grashof for loop in result.loops] == ['change point']
    angles = sorted(math.remainder(t.angle, TURN) for t in result.toggles)
    assert angles == pytest.approx([0.0, math.pi], abs=1e-6)
    assert {t.dyad for t in result.toggles} == {'RRR C'}
    # Within rounding of the fold the solver refuses: the only "gaps" are that narrow.
    assert all(end - start < 1e-6 for start, end in result.gaps)


def test_six_link_has_one_four_bar_loop():
    """six_link_slider: the crank-rocker O-A-B-Q (350, 100, 300, 250 mm); the RRP is no loop."""
    result = asm.assembly_from_scene(mk.load_scene('six_link_slider'))
    (loop,) = result.loops
    assert loop.points == ('O', 'A', 'B', 'Q') and loop.grashof == 'crank-rocker'
    assert loop.lengths == pytest.approx((0.35, 0.1, 0.3, 0.25), rel=1e-15)
    assert {t.dyad for t in result.transmission} == {'RRR B', 'RRP D'}


def test_summary_speaks_the_scene_units():
    """The one-line summary is in the scene's angle unit: rad for a scene in rad."""
    scene = mk.load_scene('four_bar_coupler_points')
    in_rad = mk.Scene(scene.name, scene.ground, scene.input, scene.dyads, scene.points,
                      units=mk.SceneUnits('m', 'rad'))
    limit = math.acos((50 ** 2 + 100 ** 2 - 122 ** 2) / (2 * 50 * 100))
    assert asm.assembly_summary(in_rad) == (
        f'does not assemble for crank angles {limit:.6g}..{TURN - limit:.6g} rad')


def test_a_pruned_scene_is_studied_in_full():
    """Scene outputs do not hide a dyad that stops the mechanism from assembling."""
    scene = mk.load_scene('four_bar_coupler_points')
    pruned = mk.Scene(scene.name, scene.ground, scene.input, scene.dyads, scene.points,
                      outputs_joints=('crank',), outputs_points=('B',), units=scene.units)
    assert asm.assembly_summary(pruned) == asm.assembly_summary(scene)


def test_geneva_assembles_everywhere_without_dead_centres():
    """The Geneva wheel's dwell is no reversal: no dead centre, no loop, no RRR or RRP."""
    result = asm.assembly_from_scene(mk.load_scene('geneva'))
    assert result.everywhere
    assert (result.toggles, result.dead_centres, result.transmission, result.loops) == \
        ((), (), (), ())


def test_a_strip_of_rigid_triangles_is_checked_without_refining_its_constant_measures(
        monkeypatch):
    """40 triangles: their transmission angles are constant, no loop is a four-bar.

    The rounding of a constant measure made a third of its samples local minima, each
    refined by golden-section solves: a 20-triangle strip took 84 s, 2,000 triangles
    more than five minutes; and the first triangle, on the crank, was called a
    double-crank four-bar with a ground link of 0 m.
    """
    solves = []
    original = asm._Probe.solve

    def counted(self, theta):
        solves.append(theta)
        return original(self, theta)

    monkeypatch.setattr(asm._Probe, 'solve', counted)
    result = asm.assembly_from_scene(equilateral_chain(40))
    assert len(solves) < 50, len(solves)
    assert result.toggles == () and result.dead_centres == () and result.loops == ()
    assert len(result.transmission) == 40
    for t in result.transmission:
        assert t.constant
        assert t.minimum == pytest.approx(math.pi / 3, rel=1e-12)


def test_check_says_a_constant_transmission_angle_holds_at_every_crank_angle():
    """The check's text and JSON of a strip: "at every crank angle", ``constant`` true."""
    from mech_kinematics.tools.check import report_json, report_text

    scene = equilateral_chain(3)
    result = asm.assembly_from_scene(scene)
    text = report_text(result, scene)
    assert 'minimum transmission angle: 1.0472 rad at every crank angle (RRR P' in text
    assert '  RRR P1: 1.0472 rad at every crank angle' in text
    assert 'four-bar loops: none' in text
    assert [t['constant'] for t in report_json(result, scene)['transmission']] == [True] * 3


@pytest.mark.parametrize('name', ['four_bar_coupler_points', 'quick_return', 'whitworth'])
def test_the_study_in_parts_of_the_angles_is_the_study_in_one(monkeypatch, name):
    """Solved in parts of 64 angles (as a long chain's turn is), every finding is the same."""
    scene = mk.load_scene(name)
    whole = asm.assembly_from_scene(scene)
    monkeypatch.setattr(asm, 'CELLS', 1)
    assert asm.assembly_from_scene(mk.load_scene(name)) == whole
