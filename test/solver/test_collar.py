# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The driven collar (solver/collar.py): a block slid along a moving link by an actuator.

Issue 41, item 1: a slide along a moving link as a driver. Checked against
Hibbeler's collar on a rotating rod (the Coriolis acceleration), against the
50-digit reference, by differences in time, and with a mass on the collar by
the power balance of both drivers.
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

#: Hibbeler, Engineering Mechanics: Dynamics, Example 16.19 (13th ed.; numbering varies by
#: edition; section 16.8, relative motion using rotating axes): the rod at theta = 60 deg
#: turns at 3 rad/s and 2 rad/s^2; the collar C, x = 0.2 m out along it, travels outward
#: at 2 m/s and 3 m/s^2 relative to the rod. Printed, in the rod's axes (x along it):
#: a_Cor = 12 j m/s^2, v_C = 2 i + 0.6 j m/s, a_C = 1.20 i + 12.4 j m/s^2.
COLLAR = """\
name: collar_on_rod
units: {length: m, angle: deg}
ground: {O: [0, 0]}
inputs:
  - {link: rod, center: O, point: T, length: 0.5, angle: 60, speed: 3, accel: 2}
  - {actuator: x, length: 0.2, speed: 2, accel: 3, stroke: [0.01, 0.5]}
dyads:
  - {type: collar, point: C, link: rod, from: O, toward: T, actuator: x}
"""


def collar_scene(**changes):
    """Return the collar scene, top-level keys replaced by ``changes``."""
    data = yaml.safe_load(COLLAR)
    data.update(changes)
    return mk.parse_scene(data)


def in_rod_axes(vector, theta):
    """Return a vector of the ground's axes in the rod's (x along it), as (along, across)."""
    z = complex(*vector) * complex(math.cos(theta), -math.sin(theta))
    return z.real, z.imag


def test_hibbeler_collar_on_a_rotating_rod_with_coriolis():
    """v_C = 2 i + 0.6 j, a_C = 1.2 i + 12.4 j (rod axes), Coriolis 2 omega x' = 12: as printed."""
    scene = collar_scene()
    theta = math.radians(60.0)
    state = mk.solve(scene, [theta, 0.2], [3.0, 2.0], [2.0, 3.0])
    c = state.points['C']
    along, across = in_rod_axes(c.position, theta)
    assert (along, across) == pytest.approx((0.2, 0.0), abs=1e-15)
    v = in_rod_axes(c.velocity, theta)
    a = in_rod_axes(c.acceleration, theta)
    # The hand forms: v = x' + omega x j; a = (x'' - omega^2 x) i + (alpha x + 2 omega x') j.
    assert v == pytest.approx((2.0, 3.0 * 0.2), rel=1e-14)
    assert a == pytest.approx((3.0 - 9.0 * 0.2, 2.0 * 0.2 + 2.0 * 3.0 * 2.0), rel=1e-14)
    for got, printed in ((v[0], 2.0), (v[1], 0.6), (a[0], 1.20), (a[1], 12.4)):
        assert abs(got - printed) <= 0.005 * abs(got), (got, printed)
    # Its Coriolis part: what the sliding adds across the rod beyond alpha x.
    assert a[1] - 2.0 * 0.2 == pytest.approx(12.0, rel=1e-14)
    assert state.joints['x'].velocity == 2.0 and state.joints['x'].type == 'prismatic'


def test_a_dyad_may_start_from_the_collars_pin():
    """A link from the collar's pin to a block on a fixed guide: placed, and closing."""
    data = yaml.safe_load(COLLAR)
    data['ground']['G'] = [1.0, 0.0]
    arm = {'name': 'arm', 'from': 'C', 'length': 0.6}
    data['dyads'].append({'type': 'RRP', 'point': 'P', 'link': arm, 'slider': 'block',
                          'guide': {'through': 'G', 'angle': 0}, 'branch': 1})
    scene = mk.parse_scene(data)
    state = mk.solve(scene, [1.0, 0.3], [2.0, -0.5], [0.0, 1.0])
    gap = abs(complex(*state.points['P'].position) - complex(*state.points['C'].position))
    assert gap == pytest.approx(0.6, rel=1e-14)
    assert state.points['P'].position[1] == pytest.approx(0.0, abs=1e-15)


@given(theta=st.floats(-math.pi, math.pi), x=st.floats(0.02, 0.49),
       omega=st.floats(-20.0, 20.0), xd=st.floats(-3.0, 3.0),
       alpha=st.floats(-100.0, 100.0), xdd=st.floats(-30.0, 30.0))
@settings(max_examples=15, deadline=None, derandomize=True)
def test_bounds_hold_against_the_50_digit_reference(theta, x, omega, xd, alpha, xdd):
    """Every value within its bound of the mpmath reference (its own collar model)."""
    state, exact = assert_bounded(collar_scene(), [theta, x], [omega, xd], [alpha, xdd])
    assert state is not None and exact is not None


#: Central differences in time with step H (s).
H = 1e-5


@given(theta=st.floats(-math.pi, math.pi), x=st.floats(0.05, 0.45),
       omega=st.floats(-5.0, 5.0), xd=st.floats(-1.0, 1.0),
       alpha=st.floats(-10.0, 10.0), xdd=st.floats(-5.0, 5.0))
@settings(max_examples=25, deadline=None, derandomize=True)
def test_rates_are_the_derivatives_of_position(theta, x, omega, xd, alpha, xdd):
    """Both drivers moving at constant accelerations: central differences of C's motion."""
    scene = collar_scene()

    def at(t):
        positions = [theta + omega * t + alpha * t * t / 2, x + xd * t + xdd * t * t / 2]
        return mk.solve(scene, positions, [omega + alpha * t, xd + xdd * t], [alpha, xdd])

    before, now, after = at(-H), at(0.0), at(H)
    p0, p1 = (np.array(s.points['C'].position) for s in (before, after))
    v0, v1 = (np.array(s.points['C'].velocity) for s in (before, after))
    scale_v = np.abs(now.points['C'].velocity).max() + 1.0
    scale_a = np.abs(now.points['C'].acceleration).max() + 1.0
    assert np.allclose((p1 - p0) / (2 * H), now.points['C'].velocity, rtol=0,
                       atol=1e-6 * scale_v)
    assert np.allclose((v1 - v0) / (2 * H), now.points['C'].acceleration, rtol=0,
                       atol=1e-6 * scale_a)


def test_the_array_path_gives_the_single_solves_values():
    """Both drivers as arrays: each instant the single solve's values (to an ulp)."""
    scene = collar_scene()
    rng = np.random.default_rng(3)
    theta, x = rng.uniform(-3, 3, 30), rng.uniform(0.02, 0.49, 30)
    omega, xd = rng.uniform(-5, 5, 30), rng.uniform(-2, 2, 30)
    many = mk.solve(scene, [theta, x], [omega, xd], [0.5, -1.0])
    assert many.valid.all()
    for i in range(30):
        one = mk.solve(scene, [theta[i], x[i]], [omega[i], xd[i]], [0.5, -1.0])
        for field in ('position', 'velocity', 'acceleration'):
            np.testing.assert_allclose(np.array(getattr(many.points['C'], field))[i],
                                       getattr(one.points['C'], field), rtol=1e-15, atol=1e-16)


MASSES = {'masses': {'rod': {'mass': 2.0, 'com': [0.25, 0.0], 'inertia': 0.05},
                     'x': {'mass': 1.5}},
          'gravity': [0.0, -9.81]}


@given(theta=st.floats(-math.pi, math.pi), x=st.floats(0.05, 0.45),
       omega=st.floats(-10.0, 10.0), xd=st.floats(-2.0, 2.0),
       alpha=st.floats(-50.0, 50.0), xdd=st.floats(-20.0, 20.0))
@settings(max_examples=25, deadline=None, derandomize=True)
def test_the_drivers_put_in_the_power_the_motion_takes(theta, x, omega, xd, alpha, xdd):
    """T omega + F x' = d(kinetic energy)/dt + (weights' power taken), from the solved motion.

    The rod (2 kg, centre 0.25 m out, 0.05 kg m^2 about it) and a 1.5 kg collar
    under gravity: the power balance of the efforts, not the statics' own terms.
    """
    scene = collar_scene(**MASSES)
    state = mk.solve(scene, [theta, x], [omega, xd], [alpha, xdd])
    efforts = state.forces.efforts
    put_in = efforts['rod'] * omega + efforts['x'] * xd
    g = np.array([0.0, -9.81])
    u = np.array([math.cos(theta), math.sin(theta)])
    n = np.array([-u[1], u[0]])
    # The rod's centre G: 0.25 u; v_G = 0.25 omega n; a_G = 0.25 (alpha n - omega^2 u).
    v_g, a_g = 0.25 * omega * n, 0.25 * (alpha * n - omega * omega * u)
    v_c, a_c = np.array(state.points['C'].velocity), np.array(state.points['C'].acceleration)
    taken = (2.0 * v_g @ a_g + 0.05 * omega * alpha + 1.5 * v_c @ a_c
             - 2.0 * g @ v_g - 1.5 * g @ v_c)
    scale = 2.0 * abs(v_g @ a_g) + 0.05 * abs(omega * alpha) + 1.5 * abs(v_c @ a_c) \
        + 9.81 * (2.0 * np.abs(v_g).sum() + 1.5 * np.abs(v_c).sum()) + 1e-9
    allowed = state.forces.effort_bounds['rod'] * abs(omega) \
        + state.forces.effort_bounds['x'] * abs(xd) + 1e-12 * scale
    assert abs(put_in - taken) <= allowed, (put_in, taken)


@pytest.mark.parametrize(('dyad', 'match'), [
    ({'type': 'collar', 'point': 'C', 'link': 'rod', 'from': 'O', 'toward': 'T',
      'actuator': 'rod'}, r'Expected the actuator of collar "C" to be an actuator of inputs, '
                          r'got link "rod"'),
    ({'type': 'collar', 'point': 'C', 'link': 'rod', 'from': 'T', 'toward': 'O',
      'actuator': 'x'}, r'Expected collar "C" to slide along the axis of link "rod"'),
    ({'type': 'collar', 'point': 'C', 'link': 'rod', 'from': 'O', 'toward': 'Z',
      'actuator': 'x'}, r'Expected the direction point of collar "C" to be a known point, '
                        r'got unknown "Z"'),
    ({'type': 'collar', 'point': 'C', 'link': 'rod', 'from': 'O', 'toward': 'T',
      'actuator': 'x', 'speed': 1}, r"unknown key\(s\) \['speed'\]"),
])
def test_bad_collars_are_refused_in_one_line(dyad, match):
    """Each mistake in a collar's keys is one line naming it."""
    with pytest.raises(mk.SceneError, match=match) as info:
        collar_scene(dyads=[dyad])
    assert '\n' not in str(info.value)


def test_its_part_of_the_graph_is_a_driven_block_on_the_rod():
    """The collar slides on the rod by the actuator's driven prismatic joint; no cylinder."""
    graph = collar_scene().graph
    joint = graph.prismatic('x')
    assert (joint.on, joint.driver, joint.at, joint.line.angle_of) == ('rod', True, 'C', 'rod')
    assert graph.bodies['x'].guide == 'rod' and graph.bodies['x'].turns_with == 'rod'
    assert list(graph.cylinders()) == []
