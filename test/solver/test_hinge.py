# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The driven hinge (solver/hinge.py): a motor between two moving links, its angle an input.

Issue 41, item 1: a revolute joint between two moving links as a driver. A
two-link arm with its elbow motor on the upper arm: its tip by the textbook
forms of a planar 2R arm (position, the Jacobian's velocity, the
acceleration), bounded by the 50-digit reference, the motors' torques holding
a payload by statics done by hand, and a closed loop through the hinge.
"""

from __future__ import annotations

import math

from helpers import assert_bounded
from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest
import yaml

import mech_kinematics as mk

pytestmark = pytest.mark.filterwarnings('ignore::mech_kinematics.NearSingularWarning')

L1, L2 = 0.4, 0.3
ARM = f"""\
name: elbow_arm
units: {{length: m, angle: deg}}
ground: {{A: [0, 0]}}
inputs:
  - {{link: upper, center: A, point: B, length: {L1}, angle: 30, speed: 1.0}}
  - {{motor: elbow, angle: 45, speed: -2.0, accel: 1.0}}
dyads:
  - {{type: hinge, link: fore, parent: upper, center: B, point: C, length: {L2}, motor: elbow}}
"""


def arm(**changes):
    """Return the two-link arm, top-level keys replaced by ``changes``."""
    data = yaml.safe_load(ARM)
    data.update(changes)
    return mk.parse_scene(data)


def two_link(t1, t2, w1, w2, a1, a2):
    """Return the tip's position, velocity and acceleration of a planar 2R arm (textbook)."""
    t12, w12, a12 = t1 + t2, w1 + w2, a1 + a2
    c1, s1, c12, s12 = math.cos(t1), math.sin(t1), math.cos(t12), math.sin(t12)
    p = (L1 * c1 + L2 * c12, L1 * s1 + L2 * s12)
    # v = J qdot, J = [[-L1 s1 - L2 s12, -L2 s12], [L1 c1 + L2 c12, L2 c12]].
    v = (-L1 * s1 * w1 - L2 * s12 * w12, L1 * c1 * w1 + L2 * c12 * w12)
    a = (-L1 * (c1 * w1 * w1 + s1 * a1) - L2 * (c12 * w12 * w12 + s12 * a12),
         -L1 * (s1 * w1 * w1 - c1 * a1) - L2 * (s12 * w12 * w12 - c12 * a12))
    return p, v, a


@given(t1=st.floats(-math.pi, math.pi), t2=st.floats(-math.pi, math.pi),
       w1=st.floats(-10, 10), w2=st.floats(-10, 10), a1=st.floats(-50, 50),
       a2=st.floats(-50, 50))
@settings(max_examples=60, deadline=None, derandomize=True)
def test_the_tip_is_the_planar_two_link_arms(t1, t2, w1, w2, a1, a2):
    """The tip's position, velocity (J qdot) and acceleration are the 2R arm's.

    The fore link's angle is the sum of the two joints'.
    """
    state = mk.solve(arm(), [t1, t2], [w1, w2], [a1, a2])
    p, v, a = two_link(t1, t2, w1, w2, a1, a2)
    tip = state.points['C']
    assert np.allclose(tip.position, p, rtol=0, atol=1e-15)
    assert np.allclose(tip.velocity, v, rtol=0, atol=1e-14 * (abs(w1) + abs(w2) + 1))
    assert np.allclose(tip.acceleration, a, rtol=0,
                       atol=1e-13 * ((abs(w1) + abs(w2)) ** 2 + abs(a1) + abs(a2) + 1))
    fore = state.joints['fore']
    assert math.remainder(fore.position - (t1 + t2), math.tau) == pytest.approx(0.0, abs=1e-15)
    assert (fore.velocity, fore.acceleration) == (w1 + w2, a1 + a2)
    assert state.joints['elbow'].type == 'revolute'


@given(t1=st.floats(-math.pi, math.pi), t2=st.floats(-math.pi, math.pi),
       w1=st.floats(-10, 10), w2=st.floats(-10, 10), a1=st.floats(-50, 50),
       a2=st.floats(-50, 50))
@settings(max_examples=15, deadline=None, derandomize=True)
def test_bounds_hold_against_the_50_digit_reference(t1, t2, w1, w2, a1, a2):
    """Every value within its bound of the mpmath reference (its own motor and hinge models)."""
    state, exact = assert_bounded(arm(), [t1, t2], [w1, w2], [a1, a2])
    assert state is not None and exact is not None


@pytest.mark.parametrize(('t1', 't2'), [(30.0, 45.0), (100.0, -60.0), (-20.0, 170.0)])
def test_the_motors_hold_a_payload_as_statics_by_hand_says(t1, t2):
    """A 2 kg payload at the tip, gravity -9.81 y, the links massless, at rest.

    The elbow holds the payload's moment about B, the shoulder about A (the
    elbow's torque passes through the pin): tau_elbow = m g (x_C - x_B),
    tau_shoulder = m g x_C, + CCW.
    """
    scene = arm(masses={'fore': {'mass': 2.0, 'com': [L2, 0.0]}}, gravity=[0.0, -9.81])
    a, b = math.radians(t1), math.radians(t2)
    state = mk.solve(scene, [a, b], [0.0, 0.0], [0.0, 0.0])
    x_b, x_c = L1 * math.cos(a), L1 * math.cos(a) + L2 * math.cos(a + b)
    weight = 2.0 * 9.81
    assert state.forces.efforts['elbow'] == pytest.approx(weight * (x_c - x_b), abs=1e-12)
    assert state.forces.efforts['upper'] == pytest.approx(weight * x_c, abs=1e-12)


def test_a_loop_may_close_through_the_hinge():
    """A five-bar whose second motor rides on the first crank: the RRR closes the loop."""
    data = yaml.safe_load(ARM)
    data['ground']['D'] = [0.5, 0.0]
    data['dyads'].append({'type': 'RRR', 'point': 'E', 'links': [
        {'name': 'left', 'from': 'C', 'length': 0.35},
        {'name': 'right', 'from': 'D', 'length': 0.35}], 'branch': 1})
    state = mk.solve(mk.parse_scene(data), [0.5, 0.8], [1.0, -1.0], [0.0, 2.0])
    e = complex(*state.points['E'].position)
    assert abs(e - complex(*state.points['C'].position)) == pytest.approx(0.35, rel=1e-14)
    assert abs(e - 0.5) == pytest.approx(0.35, rel=1e-14)


@pytest.mark.parametrize(('change', 'match'), [
    ({'dyads': [{'type': 'hinge', 'link': 'fore', 'parent': 'upper', 'center': 'B', 'point': 'C',
                 'length': 0.3, 'motor': 'upper'}]},
     r'Expected the motor of hinge "fore" to be a motor of inputs, got link "upper"'),
    ({'dyads': [{'type': 'hinge', 'link': 'fore', 'parent': 'upper', 'center': 'A', 'point': 'C',
                 'length': 0.3, 'motor': 'elbow'}],
      'ground': {'A': [0, 0], 'Q': [1, 1]},
      'points': {'R': {'link': 'upper', 'from': 'A', 'toward': 'B', 'distance': 0.1}}},
     None),
    ({'dyads': []}, r'Expected motor "elbow" to turn one hinge .*got none'),
    ({'dyads': [{'type': 'hinge', 'link': 'fore', 'parent': 'upper', 'center': 'B', 'point': 'C',
                 'length': -0.3, 'motor': 'elbow'}]}, r'expected a positive length'),
])
def test_bad_hinges_are_refused_in_one_line(change, match):
    """Each mistake is one line naming it (a pin at the parent's own start is allowed)."""
    if match is None:
        assert arm(**change).graph.bodies['fore'].points == ('A', 'C')
        return
    with pytest.raises(mk.SceneError, match=match) as info:
        arm(**change)
    assert '\n' not in str(info.value)


def test_its_part_of_the_graph_is_a_driven_pin_between_two_moving_links():
    """The motor's joint is the fore link's pin on the upper arm, driven, named after it."""
    graph = arm().graph
    joint = next(j for j in graph.joints if j.name == 'elbow')
    assert (joint.body, joint.on, joint.at, joint.driver) == ('fore', 'upper', 'B', True)
    assert graph.drivers == ('upper', 'elbow')
    assert graph.bodies['fore'].turns_with == 'fore'


@pytest.mark.parametrize(('x', 'y', 'vx', 'vy'), [(0.06, 0.22, 0.1, 0.0), (0.03, 0.2, -0.05, 0.2)])
def test_five_bar_elbow_driven_by_its_effector_is_the_five_bars_inverse(x, y, vx, vy):
    """The same arm, two sets of drivers: P's targets give the same links and the same rates.

    five_bar (both motors on the ground) and five_bar_elbow (the left motor and the left
    elbow) are one linkage: the left crank's motion is the same, and the elbow's is the
    left distal link's less the left crank's.
    """
    targets, speeds = {'P.x': x, 'P.y': y}, {'P.x': vx, 'P.y': vy}
    ground = mk.solve_targets(mk.load_scene('five_bar'), targets, speeds).answer.joints
    elbow = mk.solve_targets(mk.load_scene('five_bar_elbow'), targets, speeds).answer.joints
    for name in ('left_crank', 'left_distal', 'right_distal', 'right_crank'):
        # five_bar_elbow's right distal link runs from P to D, five_bar's from D to P.
        turn = math.pi if name == 'right_distal' else 0.0
        gap = elbow[name].position - ground[name].position - turn
        assert math.remainder(gap, math.tau) == pytest.approx(0.0, abs=1e-9), name
        for field in ('velocity', 'acceleration'):
            assert getattr(elbow[name], field) == pytest.approx(getattr(ground[name], field),
                                                                rel=1e-9, abs=1e-12), name
    relative = ground['left_distal'].position - ground['left_crank'].position
    assert math.remainder(elbow['elbow'].position - relative, math.tau) == pytest.approx(
        0.0, abs=1e-12)
    assert elbow['elbow'].velocity == pytest.approx(
        ground['left_distal'].velocity - ground['left_crank'].velocity, rel=1e-9, abs=1e-12)


def test_a_motor_listed_first_is_no_crank():
    """The motor before the crank in inputs: the same arm (a motor is never taken for a crank)."""
    data = yaml.safe_load(ARM)
    data['inputs'] = data['inputs'][::-1]
    swapped = mk.parse_scene(data)
    assert swapped.input is None and [d.name for d in swapped.drivers] == ['elbow', 'upper']
    one = mk.solve(arm(), [0.5, 0.7], [1.0, -2.0], [0.5, 1.0])
    other = mk.solve(swapped, [0.7, 0.5], [-2.0, 1.0], [1.0, 0.5])
    for field in ('position', 'velocity', 'acceleration'):
        np.testing.assert_array_equal(getattr(other.points['C'], field),
                                      getattr(one.points['C'], field))
