# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The fold (solver/fold.py): a four-bar re-rooted at its driven coupler-to-rocker pin.

Issue 41, item 1: a driven joint both of whose links are placed only through
it. Checked against what does not use the fold's formulas: the same four-bar
driven from its crank (an RRR, another kind's closed form) gives the same
pose at the knee angle it shows; the 50-digit reference (its own equations)
bounds every value at random motor angles, speeds and accelerations, both
branches; the loop's lengths and the knee angle hold; and the refusals name
the circles that miss and the fold that collapses.
"""

from __future__ import annotations

import cmath
import math

from helpers import assert_bounded, fold_scene
from hypothesis import given, settings
from hypothesis import strategies as st
import pytest

import mech_kinematics as mk

pytestmark = pytest.mark.filterwarnings('ignore::mech_kinematics.NearSingularWarning')

#: The fold's lengths (m): crank AB, coupler BC, rocker DC and |AD| (helpers.fold_scene).
A_LEN, B_LEN, C_LEN, AD = 0.04, 0.1, 0.07, 0.08
#: Where it assembles: |DB| = |c + b exp(iq)| between AD - a and AD + a (92 to 161.8 deg).
LOW, HIGH = math.radians(92.5), math.radians(161.0)


def _fold(branch=1, **inputs):
    data = fold_scene()
    data['dyads'][0]['branch'] = branch
    data['inputs'][0].update(inputs)
    return mk.parse_scene(data)


def _crank_four_bar(branch):
    """Return the same four-bar driven from its crank: an RRR places C from B and D."""
    return mk.parse_scene({
        'name': 'crank_driven', 'units': {'length': 'mm', 'angle': 'deg'},
        'ground': {'A': [0, 0], 'D': [80, 0]},
        'input': {'link': 'crank', 'center': 'A', 'point': 'B', 'length': 40, 'angle': 100,
                  'speed': 1.0},
        'dyads': [{'type': 'RRR', 'point': 'C', 'links': [
            {'name': 'coupler', 'from': 'B', 'length': 100},
            {'name': 'rocker', 'from': 'D', 'length': 70}], 'branch': branch}]})


@pytest.mark.parametrize('branch', [1, -1])
def test_driven_at_the_knee_it_takes_the_pose_the_crank_driven_four_bar_shows(branch):
    """Solve the crank-driven four-bar, read its knee angle; the fold at it puts B there."""
    fold = _fold(branch)
    checked = 0
    for rrr_branch in (1, -1):
        crank = _crank_four_bar(rrr_branch)
        for theta in [math.radians(t) for t in range(5, 360, 15)]:   # (B never on AD)
            try:
                state = mk.solve(crank, theta, 1.0, 0.0)
            except mk.AssemblyError:
                continue
            p = {n: v[0] for n, v in state.complex_points.items()}
            if ((p['D'] - p['A']).conjugate() * (p['B'] - p['A'])).imag * branch <= 0:
                continue    # B on the other side of A->D: the fold's other branch
            knee = cmath.phase((p['B'] - p['C']) / (p['C'] - p['D']))
            driven = mk.solve(fold, knee, 0.0, 0.0)
            q = {n: v[0] for n, v in driven.complex_points.items()}
            for name in ('B', 'C'):
                assert abs(q[name] - p[name]) <= 1e-12 * AD, (theta, name)
            crank_angle = driven.joints['crank'].position
            assert abs(math.remainder(crank_angle - theta, math.tau)) <= 1e-11
            checked += 1
    assert checked >= 10


def _rate(largest):
    """Draw 0 or a rate of 1e-6 to ``largest`` either way.

    (A rate whose products fall below the normal doubles rounds to a subnormal's ulp,
    which no relative bound covers: the solver's bounds have no underflow term, as
    test_forces.py's UNDERFLOW says.)
    """
    return st.one_of(st.just(0.0), st.floats(1e-6, largest), st.floats(-largest, -1e-6))


@settings(max_examples=60, deadline=None)
@given(q=st.floats(LOW, HIGH), sign=st.sampled_from([1.0, -1.0]),
       speed=_rate(20.0), accel=_rate(200.0), branch=st.sampled_from([1, -1]))
def test_every_value_is_within_its_bound_of_the_50_digit_reference(
        q, sign, speed, accel, branch):
    """Both halves of the knee's turn, both branches: the reference's own equations."""
    state, exact = assert_bounded(_fold(branch), sign * q, speed, accel)
    assert state is not None and exact is not None


@settings(max_examples=40, deadline=None)
@given(q=st.floats(LOW, HIGH), speed=st.floats(-5.0, 5.0), accel=st.floats(-20.0, 20.0))
def test_the_loop_closes_at_its_lengths_and_the_knee_turns_as_driven(q, speed, accel):
    """|AB| = a, |BC| = b, |DC| = c; the coupler's angle less the rocker's is the motor's."""
    state = mk.solve(_fold(), q, speed, accel)
    p = {n: v[0] for n, v in state.complex_points.items()}
    for (x, y), length in ((('A', 'B'), A_LEN), (('B', 'C'), B_LEN), (('D', 'C'), C_LEN)):
        assert abs(abs(p[y] - p[x]) - length) <= 1e-15 * 8
    joints = state.joints
    knee = joints['coupler'].position - joints['rocker'].position
    assert abs(math.remainder(knee - q, math.tau)) <= 1e-14
    assert joints['coupler'].velocity - joints['rocker'].velocity == pytest.approx(speed,
                                                                                   abs=1e-12)
    assert joints['knee'].position == pytest.approx(q, abs=1e-15)
    # The pins' velocities are the links' rotations about their starts.
    v = {n: s[1] for n, s in state.complex_points.items()}
    for link, start, end in (('crank', 'A', 'B'), ('rocker', 'D', 'C'), ('coupler', 'C', 'B')):
        w = joints[link].velocity
        assert abs(v[end] - v[start] - 1j * w * (p[end] - p[start])) <= 1e-12 * (1 + abs(w))


def test_out_of_reach_and_a_collapsed_fold_are_refused_in_one_line():
    """Below 92 deg |DB| > 120 mm: the circles miss; with b = c at 180 deg, |DB| = 0."""
    with pytest.raises(mk.AssemblyError, match=r'fold B cannot be solved at knee = 1\.0472 '
                       r'rad: the circles about A \(radius 0\.04 m\) and D \(radius 0\.147986 '
                       r'm\) do not meet') as error:     # |DB| = |70 + 100 exp(i 60 deg)| mm
        mk.solve(_fold(), math.radians(60), 0.0, 0.0)
    assert '\n' not in str(error.value)
    data = fold_scene()
    data['dyads'][0]['links'][1]['length'] = 100     # the rocker as long as the coupler
    data['ground']['D'] = [40, 0]
    data['inputs'][0]['angle'] = 170                   # |DB| = 200 cos(85 deg) = 17.4 mm
    equal = mk.parse_scene(data)
    with pytest.raises(mk.AssemblyError, match=r'fold B cannot be solved at knee = 3\.14159 '
                       r'rad: the coupler coupler folds onto the rocker rocker \(singular: '
                       r'\|DB\| = '):
        mk.solve(equal, math.pi, 0.0, 0.0)


def test_a_fold_needs_a_motor_and_a_motor_one_user():
    """A fold naming no motor of inputs, or a motor both a hinge and a fold use: one line."""
    data = fold_scene()
    data['dyads'][0]['motor'] = 'elbow'
    with pytest.raises(mk.SceneError, match=r'Expected the motor of fold "B" to be a motor of '
                       r'inputs, got unknown "elbow"'):
        mk.parse_scene(data)
