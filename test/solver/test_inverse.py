# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Driven from the output (issue 41): targets, the inverse map, its Jacobian and forces.

Every check is against something the inverse does not compute: the forward
solve of the answer (the targets come back), central differences of the
forward solve (the Jacobian), finite differences of the inverse itself along
a target's path (the drivers' rates), the statics of :mod:`.forces` (the
drivers' share of a force along a target, virtual work), and a slider-crank's
hand formula for its piston (the 150 / 600 mm engine of Khurmi & Gupta run
backwards: the crank found from the piston's position, speed and
acceleration).
"""

from __future__ import annotations

import math

from hypothesis import assume, given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

import mech_kinematics as mk

pytestmark = pytest.mark.filterwarnings('ignore::mech_kinematics.NearSingularWarning')

FIVE = mk.load_scene('five_bar')
START = [d.start for d in FIVE.drivers]


def _effector(q, qd=(0.0, 0.0), qdd=(0.0, 0.0)):
    """Return P's (position, velocity, acceleration) from the forward solve at ``q``."""
    state = mk.solve(FIVE, list(q), list(qd), list(qdd))
    return state.points['P']


def _size():
    return mk.solve(FIVE, START, [0.0, 0.0], [0.0, 0.0]).error_bound.size


@settings(max_examples=60, deadline=None)
@given(st.floats(-0.5, 0.5), st.floats(-0.5, 0.5))
def test_the_forward_solve_of_the_answer_gives_the_targets_back(d1, d2):
    """Targets drawn inside the workspace (drivers near the start) come back to 1e-12 of size.

    The answer keeps the start pose's working mode (each leg's elbow on the
    side it starts on: the sign of (B - A) x (P - B), and of (D - E) x (P - D));
    where the drivers drawn are in that mode, they are the ones found.
    """
    q = [START[0] + d1, START[1] + d2]
    try:
        p = _effector(q).position
    except mk.AssemblyError:
        assume(False)
    inverse = mk.solve_targets(FIVE, {'P.x': float(p[0]), 'P.y': float(p[1])})
    found = inverse.motion[:, 0]
    again = _effector(found).position
    size = _size()
    assert np.max(np.abs(again - p)) <= 1e-12 * size
    assert _modes(found) == _modes(START)
    if _modes(q) == _modes(START):
        assert np.max(np.abs(found - q)) <= 1e-9
    assert np.all(inverse.motion_bound[:, 0] <= 1e-9)


def _modes(q):
    """Return the working mode at drivers ``q``: the side of each leg's elbow."""
    points = mk.solve(FIVE, list(q), [0.0, 0.0], [0.0, 0.0]).points

    def side(ground, elbow):
        a, b, p = (points[name].position for name in (ground, elbow, 'P'))
        return math.copysign(1.0, (b - a)[0] * (p - b)[1] - (b - a)[1] * (p - b)[0])

    return side('A', 'B'), side('E', 'D')


def test_the_jacobian_is_the_central_differences_of_the_forward_solve():
    """The Jacobian d P / d q at the answer against central differences of the forward solve."""
    inverse = mk.solve_targets(FIVE, {'P.x': 0.06, 'P.y': 0.22})
    q = inverse.motion[:, 0]
    h = 1e-6
    for j in range(2):
        dq = np.zeros(2)
        dq[j] = h
        column = (_effector(q + dq).position - _effector(q - dq).position) / (2 * h)
        np.testing.assert_allclose(inverse.jacobian[:, j], column, rtol=1e-8, atol=1e-12)
    np.testing.assert_allclose(inverse.inverse @ inverse.jacobian, np.eye(2), atol=1e-12)


def test_the_rates_are_the_derivatives_of_the_inverse_along_the_path():
    """The rates qd and qdd against finite differences of the inverse positions along t(s)."""
    t0, td, tdd = np.array([0.06, 0.22]), np.array([0.1, -0.05]), np.array([-0.3, 0.2])

    def at(s):
        goal = t0 + td * s + tdd * s * s / 2
        return mk.solve_targets(FIVE, {'P.x': goal[0], 'P.y': goal[1]}).motion[:, 0]

    answer = mk.solve_targets(FIVE, {'P.x': t0[0], 'P.y': t0[1]},
                              {'P.x': td[0], 'P.y': td[1]}, {'P.x': tdd[0], 'P.y': tdd[1]})
    h = 1e-4
    before, now, after = at(-h), at(0.0), at(h)
    np.testing.assert_allclose(answer.motion[:, 1], (after - before) / (2 * h), rtol=1e-6)
    np.testing.assert_allclose(answer.motion[:, 2], (after - 2 * now + before) / h ** 2,
                               rtol=1e-4, atol=1e-6)
    p = _effector(answer.motion[:, 0], answer.motion[:, 1], answer.motion[:, 2])
    np.testing.assert_allclose(p.velocity, td, atol=1e-14)
    np.testing.assert_allclose(p.acceleration, tdd, atol=1e-13)
    np.testing.assert_allclose(answer.reached, answer.given, atol=1e-13)


def test_a_force_along_targets_is_what_the_statics_give_for_the_opposite_load():
    """J^T F against the forces of the loop: the effort holding a load -F at P (virtual work)."""
    force = [3.0, -7.0]
    loaded = _loaded_five_bar(force)
    inverse = mk.solve_targets(loaded, {'P.x': 0.05, 'P.y': 0.21},
                               forces={'P.x': force[0], 'P.y': force[1]})
    efforts = inverse.answer.forces.efforts
    for name in ('left_crank', 'right_crank'):
        assert inverse.target_efforts[name] == pytest.approx(efforts[name], rel=1e-12, abs=1e-14)


def _loaded_five_bar(force):
    """Return the packaged five-bar with a load ``-force`` (N) at P."""
    import yaml
    from mech_kinematics.scene import scene_dirs

    path = next(d / 'five_bar.yaml' for d in scene_dirs() if (d / 'five_bar.yaml').exists())
    data = yaml.safe_load(path.read_text())
    data['loads'] = [{'name': 'push', 'point': 'P', 'force': [-force[0], -force[1]]}]
    return mk.parse_scene(data)


def test_a_slider_crank_driven_from_its_piston():
    """The 150 / 600 mm engine at 300 rpm CW, 45 deg past inner dead centre, found from its piston.

    Khurmi & Gupta's slider-crank (the course notes' "Accelerations in a
    Slider-crank Linkage", scene slider_crank_150_600) run backwards: the
    piston's position, velocity and acceleration from the hand formula
    ``x = r cos t - sqrt(l^2 - r^2 sin^2 t)`` (the piston left of the crank
    centre) at t = 135 deg, omega = -10 pi rad/s, alpha = 0; the crank's
    angle, speed and acceleration come back, continued from 150 deg.
    """
    scene = mk.load_scene('slider_crank_150_600')
    r, rod, t, w = 0.15, 0.6, 3 * math.pi / 4, -10 * math.pi
    root = math.sqrt(rod ** 2 - (r * math.sin(t)) ** 2)
    x = r * math.cos(t) - root
    dx = -r * math.sin(t) + r * r * math.sin(t) * math.cos(t) / root
    ddx = (-r * math.cos(t) + r * r * math.cos(2 * t) / root
           + (r * r * math.sin(t) * math.cos(t)) ** 2 / root ** 3)
    inverse = mk.solve_targets(scene, {'piston': x}, {'piston': dx * w}, {'piston': ddx * w * w},
                               start=[math.radians(150)])
    angle, speed, accel = inverse.motion[0]
    assert angle == pytest.approx(t, abs=1e-12)
    assert speed == pytest.approx(w, rel=1e-12)
    assert accel == pytest.approx(0.0, abs=1e-9)
    assert inverse.answer.drivers['crank'].velocity == pytest.approx(w, rel=1e-12)
    # The other half of the turn reaches the same piston position: continued from 210 deg.
    other = mk.solve_targets(scene, {'piston': x}, start=[math.radians(210)])
    assert other.motion[0, 0] == pytest.approx(2 * math.pi - t, abs=1e-12)


def test_joint_targets():
    """The distal links' absolute angles as targets: the forward solve gives them back."""
    state = mk.solve(FIVE, [START[0] + 0.2, START[1] - 0.1], [0.0, 0.0], [0.0, 0.0])
    goal = {name: state.joints[name].position for name in ('left_distal', 'right_distal')}
    inverse = mk.solve_targets(FIVE, goal)
    for name, value in goal.items():
        assert inverse.answer.joints[name].position == pytest.approx(value, abs=1e-13)
    np.testing.assert_allclose(inverse.motion[:, 0], [START[0] + 0.2, START[1] - 0.1],
                               atol=1e-12)


def test_out_of_reach_says_how_far_and_stops_at_the_boundary():
    """Beyond the arm's reach: one line; where it stops a leg is stretched (280 mm) or folded."""
    with pytest.raises(mk.TargetError, match='out of reach') as caught:
        mk.solve_targets(FIVE, {'P.x': 0.06, 'P.y': 0.4})
    error = caught.value
    assert '\n' not in str(error)
    assert 0.0 < error.reached < 1.0
    here = _effector(START).position
    stop = here + error.reached * (np.array([0.06, 0.4]) - here)
    assert stop + np.array([error.short['P.x'], error.short['P.y']]) == pytest.approx(
        [0.06, 0.4], abs=1e-12)
    reach = max(np.hypot(*(stop - [0.0, 0.0])), np.hypot(*(stop - [0.1, 0.0])))
    assert reach == pytest.approx(0.28, abs=1e-6)


@pytest.mark.parametrize(('targets', 'words'), [
    ({'P.x': 0.06}, 'as many targets as the scene has drivers'),
    ({'P.x': 0.06, 'P.z': 0.2}, "got 'P.z'"),
    ({'P.x': 0.06, 'Q.y': 0.2}, "got 'Q.y'"),
])
def test_bad_targets_are_refused_in_one_line(targets, words):
    with pytest.raises(mk.TargetError, match=words) as caught:
        mk.solve_targets(FIVE, targets)
    assert '\n' not in str(caught.value)


def test_a_target_on_the_boundary_is_refused():
    """P at full stretch of the left leg: the drivers lose control there (det J = 0)."""
    p = 0.28 * np.array([math.cos(math.radians(70)), math.sin(math.radians(70))])
    with pytest.raises(mk.TargetError):
        mk.solve_targets(FIVE, {'P.x': float(p[0]), 'P.y': float(p[1])})
