# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``check`` is exact: region ends, dead centres and toggles by root finding. See issue 19.

A four-bar that assembles only within 0.005 deg of 180.05 deg (between two
0.1-deg samples, at both of which ``solve`` refuses) is reported with its
range, its ends within 1e-12 rad of the closed form computed to 50 digits;
for every packaged scene, ``check``'s ranges and dead centres agree with a
sweep of +-1e-4 deg at 1e-6 deg around each end and a 0.01-deg sweep of the
whole turn.
"""

from __future__ import annotations

import json
import math
import warnings

from helpers import crank_scene_names
from hypothesis import assume, given, settings
from hypothesis import strategies as st
import mpmath
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.__main__ import main
from mech_kinematics.errors import AssemblyError
from mech_kinematics.geometry import assembly as asm
from mech_kinematics.solver import assembly_margins

TURN = 2 * math.pi
#: The narrow four-bar (mm): crank 50 about A, D at 100 mm and 0.05 deg from +x,
#: rocker 50, coupler such that it assembles for |crank - 180.05 deg| <= 0.005 deg.
PHI, HALF_WIDTH = math.radians(0.05), math.radians(0.005)
CRANK, GROUND, ROCKER = 50.0, 100.0, 50.0
COUPLER = ROCKER + math.sqrt((CRANK + GROUND) ** 2
                             - 4 * CRANK * GROUND * math.sin(HALF_WIDTH / 2) ** 2)
NARROW = f"""\
name: narrow_window
units: {{length: mm, angle: deg}}
ground:
  A: [0, 0]
  D: [{GROUND * math.cos(PHI)!r}, {GROUND * math.sin(PHI)!r}]
input: {{link: crank, center: A, point: B, length: {CRANK!r}, angle: 180.05, speed_rpm: 60}}
dyads:
  - type: RRR
    point: C
    links:
      - {{name: coupler, from: B, length: {COUPLER!r}}}
      - {{name: rocker, from: D, length: {ROCKER!r}}}
"""
#: The sweep around each end: +-1e-4 deg at 1e-6 deg.
NEAR = np.radians(np.arange(-100, 101) * 1e-6)


@pytest.fixture(name='narrow')
def fixture_narrow(tmp_path):
    """Return the path of the narrow four-bar's scene file."""
    path = tmp_path / 'narrow_window.yaml'
    path.write_text(NARROW)
    return path


def window_by_hand(scene):
    """Return the narrow four-bar's range (rad), from the scene's doubles, to 50 digits.

    |BD|^2 = (r + g)^2 - 4 r g cos^2(psi / 2), psi = theta - phi: it reaches
    coupler - rocker for psi = pi +- delta, sin(delta / 2)^2 =
    ((r + g)^2 - (coupler - rocker)^2) / (4 r g).
    """
    with mpmath.workdps(50):
        dx, dy = (mpmath.mpf(v) for v in scene.ground['D'])
        g, phi = mpmath.sqrt(dx * dx + dy * dy), mpmath.atan2(dy, dx)
        r = mpmath.mpf(scene.input.length)
        coupler, rocker = (mpmath.mpf(link.length) for link in scene.dyads[0].links)
        delta = 2 * mpmath.asin(mpmath.sqrt(((r + g) ** 2 - (coupler - rocker) ** 2)
                                            / (4 * r * g)))
        return phi + mpmath.pi - delta, phi + mpmath.pi + delta


def solved(scene, theta):
    """Solve an array of crank angles at 1 rad/s, accepting every finite answer."""
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return mk.solve(scene, np.asarray(theta, dtype=float), 1.0, 0.0, max_error=math.inf)


def inside(theta, ranges):
    """Return whether each angle lies strictly inside one of the ranges (mod 2 pi)."""
    theta = np.asarray(theta) % TURN
    result = np.zeros(theta.shape, dtype=bool)
    for start, end in ranges:
        for shift in (-TURN, 0.0, TURN):
            result |= (theta + shift > start) & (theta + shift < end)
    return result


def test_the_narrow_window_lies_between_two_samples_that_solve_refuses(narrow):
    """At 180.0 and 180.1 deg and every other 0.1-deg sample solve refuses: sampling sees none."""
    scene = mk.load_scene(str(narrow))
    for deg in (180.0, 180.1):
        with pytest.raises(AssemblyError, match='do not meet'):
            mk.solve(scene, math.radians(deg))
    assert not solved(scene, np.radians(np.arange(3600) / 10)).valid.any()


def test_check_reports_the_narrow_range_to_1e12_rad(narrow, capsys):
    """check: the range 180.045..180.055 deg, ends within 1e-12 rad of the closed form."""
    scene = mk.load_scene(str(narrow))
    low, high = window_by_hand(scene)
    result = asm.assembly_from_scene(scene)
    (start, end), = result.ranges
    assert abs(start - low) <= 1e-12 and abs(end - high) <= 1e-12
    assert not result.everywhere
    # Its links are in line at both ends (toggles): the transmission angle there is 0.
    assert [t.angle for t in result.toggles] == pytest.approx([start, end], abs=1e-12)
    assert result.transmission[0].minimum == 0.0
    assert main(['check', str(narrow), '--json']) == 0
    data = json.loads(capsys.readouterr().out)
    assert data['assembles_everywhere'] is False
    (json_start, json_end), = data['ranges']
    assert (json_start, json_end) == (start, end)
    assert main(['check', str(narrow)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1:3] == ['assembles: for crank angles 180.045..180.055 deg',
                          'does not assemble for crank angles -179.945..180.045 deg']
    assert data['gaps'] == [[end - TURN, start]]


def test_the_rocker_reverses_inside_the_narrow_range(narrow):
    """The dead centre inside the 0.01-deg range is found (no 0.1-deg sample lies in it)."""
    scene = mk.load_scene(str(narrow))
    result = asm.assembly_from_scene(scene)
    (start, end), = result.ranges
    (centre,) = result.dead_centres
    assert centre.joint == 'rocker' and start < centre.angle < end
    velocity = solved(scene, centre.angle + np.array([-1e-9, 1e-9])).joints['rocker'].velocity
    assert velocity[0] * velocity[1] < 0.0


def test_closed_form_margins_match_the_solved_positions():
    """An RRR on the crank: its closed-form margins are the positional ones times a sum.

    (l1 + l2 + d) and (d + |l1 - l2|) times the margins from the solved
    positions; their rates likewise, 2 d times the distance's rate.
    """
    scene = mk.load_scene('khurmi_four_bar_ad150')
    solver = scene._solver
    step = solver.run_plan.steps[0]
    crank = solver.run_plan.crank
    ground = {name: entry[0] for name, entry in solver.ground.items()}
    form = step.crank_margins(crank.point, crank.center, crank.length, ground)
    assert form is not None
    theta = np.linspace(0.0, TURN, 37)
    state = solved(scene, theta)
    b = state.points['B'].position[:, 0] + 1j * state.points['B'].position[:, 1]
    d = np.abs(b - complex(*scene.ground['D']))
    lsum, ldiff = 0.15 + 0.08, 0.15 - 0.08
    (outer, outer_rate), (inner, inner_rate) = form(theta)
    assert outer == pytest.approx((lsum - d) * (lsum + d), rel=1e-12, abs=1e-17)
    assert inner == pytest.approx((d - ldiff) * (d + ldiff), rel=1e-12, abs=1e-17)
    vb = state.points['B'].velocity[:, 0] + 1j * state.points['B'].velocity[:, 1]
    table = {'B': (b, vb), 'D': (complex(*scene.ground['D']), 0j)}
    (p_outer, p_outer_rate), (p_inner, p_inner_rate) = step.margins(table)
    assert p_outer == pytest.approx(lsum - d, rel=1e-12)
    assert p_inner == pytest.approx(d - ldiff, rel=1e-12)
    assert outer_rate == pytest.approx(-inner_rate, rel=1e-15)
    assert inner_rate == pytest.approx(2 * d * p_inner_rate, rel=1e-9, abs=1e-15)
    assert outer_rate == pytest.approx(2 * d * p_outer_rate, rel=1e-9, abs=1e-15)
    # assembly_margins gives the closed forms for it.
    (_, outer2, _), (_, inner2, rate2) = assembly_margins(scene)(theta)
    assert (outer2 == outer).all() and (inner2 == inner).all() and (rate2 == inner_rate).all()


def test_one_steps_margins_are_those_of_the_whole_plan():
    """margins(theta, label) gives that step's margins alone, the same bits as the whole list."""
    scene = mk.load_scene('six_link_slider')
    margins = assembly_margins(scene)
    theta = np.linspace(0.0, TURN, 73)
    whole = margins(theta)
    assert [label for label, _, _ in whole] == ['RRR B', 'RRR B', 'RRP D', 'RRP D']
    for label in ('RRR B', 'RRP D'):
        alone = margins(theta, label)
        mine = [entry for entry in whole if entry[0] == label]
        assert len(alone) == 2
        for (_, m1, r1), (_, m2, r2) in zip(alone, mine, strict=True):
            assert np.array_equal(m1, m2) and np.array_equal(r1, r2)


@pytest.mark.parametrize('name', [*crank_scene_names(), 'narrow'])  # one crank's sweep
def test_check_agrees_with_a_fine_sweep_at_every_end_and_a_coarse_one_elsewhere(name, narrow):
    """Every range end is where assembly changes (1e-6 deg each side); nothing else changes.

    The dead centres likewise: each output's velocity changes sign across each
    of its dead centres, and the whole-turn sweep sees no other reversal (and,
    where no range is too narrow for it, sees every one).
    """
    scene = mk.load_scene(str(narrow) if name == 'narrow' else name)
    result = asm.assembly_from_scene(scene)
    ends = [a for r in result.ranges for a in r] if not result.everywhere else []
    for end in ends:
        theta = end + NEAR
        valid = solved(scene, theta).valid
        expected = inside(theta, result.ranges)
        assert (valid == expected)[NEAR != 0].all(), (name, end)
        assert expected[NEAR < 0].any() != expected[NEAR > 0].any()
    coarse = np.arange(36000) * (TURN / 36000) + 1e-7  # 0.01 deg, off the round angles
    state = solved(scene, coarse)
    expected = inside(coarse, result.ranges) if not result.everywhere else np.ones(36000, bool)
    assert (state.valid == expected).all(), name
    outputs = set(scene.graph.reversing())
    for joint in outputs | {c.joint for c in result.dead_centres}:
        centres = [c.angle for c in result.dead_centres if c.joint == joint]
        for angle in centres:
            velocity = solved(scene, angle + NEAR[[0, -1]]).joints[joint].velocity
            assert velocity[0] * velocity[1] < 0.0, (name, joint, angle)
        velocity = np.where(state.valid, state.joints[joint].velocity, np.nan)
        signs = np.sign(velocity)
        following = np.roll(signs, -1)
        reversals = np.flatnonzero(signs * following < 0)
        step = TURN / 36000
        for i in reversals:  # each reversal the sweep sees is a dead centre found
            assert any((c - coarse[i]) % TURN < step for c in centres), (name, joint, i)
        if all(end - start > 10 * step for start, end in result.ranges):
            assert len(reversals) == len(centres), (name, joint)


def test_solve_inside_the_narrow_range_is_one_clean_line_or_an_answer(narrow, capsys):
    """At 180.05 deg, solve prints one `error:` line (exit 2).

    With --max-error inf, the answer and one `warning:` line: never Python's
    warning with its source line.
    """
    assert main(['solve', str(narrow), '--angle-deg', '180.05']) == 2
    captured = capsys.readouterr()
    assert captured.out == '' and captured.err.count('\n') == 1
    assert captured.err.startswith('error: RRR C cannot be solved at crank angle 180.05 deg: ')
    assert main(['solve', str(narrow), '--angle-deg', '180.05', '--max-error', 'inf']) == 0
    captured = capsys.readouterr()
    assert captured.err == ('warning: dyad at "C" is near-singular (measure below 0.001): its '
                            'velocities and accelerations lose accuracy\n')
    assert json.loads(captured.out)['scene'] == 'narrow_window'


def test_a_change_points_toggles_are_exact_and_no_gap():
    """A parallelogram's margins touch 0 at 0 and 180 deg: toggles there to 1e-12 rad, no gap.

    Its outer margin (l1 + l2)^2 - |BD|^2 is 0 at 180 deg in exact arithmetic and
    within rounding of it in doubles: a touch, not a range where it does not assemble.
    """
    links = (mk.Link('coupler', 'B', 0.1), mk.Link('rocker', 'D', 0.04))
    scene = mk.Scene('parallelogram', {'A': (0.0, 0.0), 'D': (0.1, 0.0)},
                     mk.Crank('crank', 'A', 'B', 0.04, 0.5, 1.0), (mk.RRR('C', links),))
    result = asm.assembly_from_scene(scene)
    assert result.everywhere and result.gaps == ()
    assert [t.angle for t in result.toggles] == pytest.approx([0.0, math.pi], abs=1e-12)
    assert {t.dyad for t in result.toggles} == {'RRR C'}


def test_a_sign_change_just_before_an_earlier_dyad_stops_closing_is_found():
    """A margin known only up to 0.3001 rad (NaN beyond) crossing 0 at 0.30005 rad.

    Both lie inside one sample step (0.300..0.301): the step is cut where
    the margin stops being known and the root is still found, to an ulp.
    """
    root, limit = 0.30005, 0.3001

    def function(theta):
        theta = np.asarray(theta, dtype=float)
        known = theta <= limit
        return np.where(known, theta - root, np.nan), np.where(known, 1.0, np.nan)

    grid = np.arange(1001) * 0.001
    (found,) = asm._crossings(function, grid)
    assert abs(found - root) <= math.ulp(root)


def slider_window_scene(gamma, half_width, crank=0.05, rod=0.12):
    """Return an RRP whose guide (through T, at ``gamma``) is in reach only near 90 deg + gamma.

    T = (0, t) with cos(gamma) t = rod + crank (1 - 2 sin^2(half_width / 2)): the
    tip's distance from the guide is within the rod for |theta - gamma - 90 deg|
    <= half_width (to the rounding of the doubles; the closed form below uses them).
    """
    t = (rod + crank * (1 - 2 * math.sin(half_width / 2) ** 2)) / math.cos(gamma)
    rrp = mk.RRP('C', mk.Link('rod', 'B', rod), 'T', gamma, 'block')
    return mk.Scene('slider_window', {'A': (0.0, 0.0), 'T': (0.0, t)},
                    mk.Crank('crank', 'A', 'B', crank, gamma + math.pi / 2, 1.0), (rrp,),
                    units=mk.Units('mm', 'deg'))


def slider_window_by_hand(scene):
    """Return the RRP window's range (rad) from the scene's doubles, to 50 digits.

    The guide direction is the rounded u = (cos gamma, sin gamma), of length k
    and angle g; the tip's signed distance is o = c + r k sin(theta - g),
    c = cross(u, A - T); l + o >= 0 within acos(-(l + c) / (r k)) of g + 90 deg.
    """
    (rrp,) = scene.dyads
    with mpmath.workdps(50):
        ux, uy = mpmath.mpf(math.cos(rrp.guide_angle)), mpmath.mpf(math.sin(rrp.guide_angle))
        tx, ty = (mpmath.mpf(v) for v in scene.ground[rrp.through])
        c = ux * (0 - ty) - uy * (0 - tx)
        rk = mpmath.mpf(scene.input.length) * mpmath.sqrt(ux * ux + uy * uy)
        x = (mpmath.mpf(rrp.link.length) + c + rk) / rk  # 1 - cos(delta)
        delta = 2 * mpmath.asin(mpmath.sqrt(x / 2))
        centre = mpmath.atan2(uy, ux) + mpmath.pi / 2
        return centre - delta, centre + delta


def test_a_slider_cranks_narrow_range_is_found_to_1e12_rad():
    """A guide in the crank tip's reach only within 0.005 deg of 90.05 deg: that range, exactly."""
    scene = slider_window_scene(math.radians(0.05), math.radians(0.005))
    assert not solved(scene, np.radians(np.arange(3600) / 10)).valid.any()
    low, high = slider_window_by_hand(scene)
    (start, end), = asm.assembly_from_scene(scene).ranges
    assert abs(start - low) <= 1e-12 and abs(end - high) <= 1e-12
    assert math.degrees(start) == pytest.approx(90.045, abs=1e-6)


@pytest.mark.parametrize('name', ['piston_300', 'offset_slider_crank', 'slider_crank_150_600'])
def test_an_rrp_on_the_cranks_closed_forms_match_its_solved_positions(name):
    """An RRP whose rod starts at the crank's tip: closed-form margins = positional ones."""
    scene = mk.load_scene(name)
    solver = scene._solver
    plan = solver.run_plan
    step = plan.steps[0]
    ground = {name: entry[0] for name, entry in solver.ground.items()}
    form = step.crank_margins(plan.crank.point, plan.crank.center, plan.crank.length, ground)
    assert form is not None
    theta = np.linspace(0.0, TURN, 37)
    state = solved(scene, theta)
    tip = plan.crank.point
    position = state.points[tip].position[:, 0] + 1j * state.points[tip].position[:, 1]
    velocity = state.points[tip].velocity[:, 0] + 1j * state.points[tip].velocity[:, 1]
    for (m1, r1), (m2, r2) in zip(form(theta), step.margins({tip: (position, velocity)}),
                                  strict=True):
        assert m1 == pytest.approx(m2, rel=1e-12, abs=1e-16)
        assert r1 == pytest.approx(r2, rel=1e-12, abs=1e-16)


def test_a_narrow_gap_is_found_to_1e12_rad():
    """A four-bar that does not assemble only within 0.005 deg of 0.05 deg: that gap, exactly.

    |BD| is least, g - r, at theta = phi; with coupler - rocker just above it the
    links fail to reach there: sin(delta / 2)^2 = ((l1 - l2)^2 - (g - r)^2) / (4 r g).
    """
    r, g, rocker = 0.05, 0.1, 0.05
    coupler = rocker + math.sqrt((g - r) ** 2 + 4 * r * g * math.sin(HALF_WIDTH / 2) ** 2)
    links = (mk.Link('coupler', 'B', coupler), mk.Link('rocker', 'D', rocker))
    scene = mk.Scene('narrow_gap', {'A': (0.0, 0.0), 'D': (g * math.cos(PHI), g * math.sin(PHI))},
                     mk.Crank('crank', 'A', 'B', r, math.pi, 1.0), (mk.RRR('C', links),))
    assert solved(scene, np.radians(np.arange(3600) / 10)).valid.all()
    with mpmath.workdps(50):
        dx, dy = (mpmath.mpf(v) for v in scene.ground['D'])
        gg, phi = mpmath.sqrt(dx * dx + dy * dy), mpmath.atan2(dy, dx)
        ldiff = mpmath.mpf(coupler) - mpmath.mpf(rocker)
        delta = 2 * mpmath.asin(mpmath.sqrt((ldiff ** 2 - (gg - mpmath.mpf(r)) ** 2)
                                            / (4 * mpmath.mpf(r) * gg)))
        low, high = phi - delta, phi + delta
    result = asm.assembly_from_scene(scene)
    (gap_start, gap_end), = result.gaps
    assert abs(gap_start - low) <= 1e-12 and abs(gap_end - high) <= 1e-12


@settings(max_examples=150, deadline=None, derandomize=True)
@given(st.floats(0.01, 0.2), st.floats(0.01, 0.3), st.floats(0.01, 0.4), st.floats(0.01, 0.4),
       st.floats(-math.pi, math.pi))
def test_every_four_bars_ranges_are_the_closed_forms(r, g, coupler, rocker, phi):
    """Any four-bar: its ranges' ends within 1e-12 rad of the law of cosines, to 50 digits.

    |BD|^2 = r^2 + g^2 - 2 r g cos(theta - phi) lies within (|l1 - l2|, l1 + l2)
    for |theta - phi| in (psi_low, psi_high): one range, two, or the whole turn.
    """
    d_x, d_y = g * math.cos(phi), g * math.sin(phi)
    with mpmath.workdps(50):
        gg = mpmath.sqrt(mpmath.mpf(d_x) ** 2 + mpmath.mpf(d_y) ** 2)
        centre = mpmath.atan2(d_y, d_x)
        rr, l1, l2 = mpmath.mpf(r), mpmath.mpf(coupler), mpmath.mpf(rocker)

        def psi(length):
            return mpmath.acos((rr ** 2 + gg ** 2 - length ** 2) / (2 * rr * gg))

        lsum, ldiff = l1 + l2, abs(l1 - l2)
        for limit in (ldiff, lsum):  # no tangency within rounding: a touch is no range end
            assume(min(abs(limit - abs(rr - gg)), abs(limit - (rr + gg))) > 1e-9)
        assume(ldiff < rr + gg and lsum > abs(rr - gg))  # it assembles somewhere
        low = mpmath.mpf(0) if ldiff <= abs(rr - gg) else psi(ldiff)
        high = mpmath.pi if lsum >= rr + gg else psi(lsum)
        assume(high - low > 1e-6)
        ends = ([centre - low, centre + low] if low > 0 else []) + (
            [centre - high, centre + high] if high < mpmath.pi else [])
    links = (mk.Link('coupler', 'B', coupler), mk.Link('rocker', 'D', rocker))
    scene = mk.Scene('any', {'A': (0.0, 0.0), 'D': (d_x, d_y)},
                     mk.Crank('crank', 'A', 'B', r, float(centre + (low + high) / 2), 1.0),
                     (mk.RRR('C', links),))
    ranges, _ = asm.assembly_ranges(scene)
    found = [a for span in ranges for a in span] if ranges != ((0.0, TURN),) else []
    assert len(found) == len(ends)
    for end in ends:
        assert min(abs(math.remainder(float(end - a), TURN)) for a in found) <= 1e-12


@settings(max_examples=150, deadline=None, derandomize=True)
@given(st.floats(0.01, 0.2), st.floats(0.01, 0.4), st.floats(-0.4, 0.4), st.floats(-0.4, 0.4),
       st.floats(-math.pi, math.pi))
def test_every_slider_cranks_ranges_are_the_closed_forms(r, rod, t_x, t_y, gamma):
    """Any slider-crank: its ranges' ends within 1e-12 rad of the closed form, to 50 digits.

    The tip's signed distance from the guide (through T, direction the rounded
    u = (cos gamma, sin gamma), of length k and angle g) is o = c + r k sin(psi),
    psi = theta - g, c = cross(u, A - T); the rod reaches the guide where
    (-rod - c) / (r k) < sin(psi) < (rod - c) / (r k).
    """
    with mpmath.workdps(50):
        ux, uy = mpmath.mpf(math.cos(gamma)), mpmath.mpf(math.sin(gamma))
        c = ux * (0 - mpmath.mpf(t_y)) - uy * (0 - mpmath.mpf(t_x))
        rk = mpmath.mpf(r) * mpmath.sqrt(ux * ux + uy * uy)
        g = mpmath.atan2(uy, ux)
        lower, upper = (-mpmath.mpf(rod) - c) / rk, (mpmath.mpf(rod) - c) / rk
        for x in (lower, upper):  # no tangency within rounding: a touch is no range end
            assume(abs(abs(x) - 1) > 1e-9)
        assume(lower < 1 and upper > -1)  # it reaches the guide somewhere
        ends, inside = [], mpmath.mpf(0)
        if abs(lower) < 1:
            ends += [g + mpmath.asin(lower), g + mpmath.pi - mpmath.asin(lower)]
            inside = mpmath.pi / 2
        if abs(upper) < 1:
            ends += [g + mpmath.asin(upper), g + mpmath.pi - mpmath.asin(upper)]
            inside = -mpmath.pi / 2
        if len(ends) == 4:
            inside = (mpmath.asin(lower) + mpmath.asin(upper)) / 2
            assume(mpmath.asin(upper) - mpmath.asin(lower) > 1e-6)
    rrp = mk.RRP('C', mk.Link('rod', 'B', rod), 'T', gamma, 'block')
    scene = mk.Scene('any', {'A': (0.0, 0.0), 'T': (t_x, t_y)},
                     mk.Crank('crank', 'A', 'B', r, float(g + inside), 1.0), (rrp,))
    ranges, _ = asm.assembly_ranges(scene)
    found = [a for span in ranges for a in span] if ranges != ((0.0, TURN),) else []
    assert len(found) == len(ends)
    for end in ends:
        assert min(abs(math.remainder(float(end - a), TURN)) for a in found) <= 1e-12
