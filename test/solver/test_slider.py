# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The driven slider (solver/slider.py): a block on a fixed guide whose position is an input.

Issue 41, item 1: a slider-crank driven from its piston and a double slider
driven by one block, solved in closed form by the dyads that follow the
block's pin. Checked against a textbook's printed answers (Hibbeler), against
the crank-driven solve of the same linkage (an RRR placed from the piston
against an RRP placed from the crank: other closed forms), against the
50-digit reference, and, with masses, by the power both drivers put in.
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
from mech_kinematics.scene import scene_text
from mech_kinematics.solver import graph as g

pytestmark = pytest.mark.filterwarnings('ignore::mech_kinematics.NearSingularWarning')

EPS = np.finfo(float).eps

#: Hibbeler, Engineering Mechanics: Dynamics (13th ed.), the example of rod AB, 10 m,
#: confined to two planes inclined at 45 deg (section 16.7, relative-motion analysis of
#: accelerations; numbering varies by edition): A moves down its plane at 2 m/s and
#: 3 m/s^2 with the rod horizontal. Printed: omega = 0.283 rad/s, alpha = 0.344 rad/s^2
#: (both CCW), a_B = 1.87 m/s^2.
INCLINED = """\
name: inclined_planes
units: {length: m, angle: deg}
ground: {A0: [0, 0], B0: [10, 0]}
inputs:
  - {slider: block_a, point: A, guide: {through: A0, angle: -45}, position: 0,
     speed: 2, accel: 3}
dyads:
  - type: RRP
    point: B
    link: {name: rod, from: A, length: 10}
    guide: {through: B0, angle: 45}
    slider: block_b
    branch: 1
"""

#: The packaged slider_crank_150_600 (crank 150 mm, rod 600 mm, the piston on the line
#: through O) driven from its piston: the crank pin B is an RRR from O and the piston pin.
FROM_PISTON = """\
name: piston_driven
units: {length: mm, angle: deg}
ground: {O: [0, 0]}
inputs:
  - {slider: piston, point: P, guide: {through: O, angle: 0}, position: -696.6166}
dyads:
  - type: RRR
    point: B
    links: [{name: crank, from: O, length: 150}, {name: rod, from: P, length: 600}]
    branch: BRANCH
"""


def from_piston(branch):
    """Return the piston-driven slider-crank, the crank pin below (1) or above (-1) the line."""
    return mk.parse_scene(yaml.safe_load(FROM_PISTON.replace('BRANCH', str(branch))))


def test_hibbeler_inclined_planes_printed_answers_and_their_hand_forms():
    """Printed omega = 0.283 rad/s, alpha = 0.344 rad/s^2, a_B = 1.87 m/s^2; hand forms exactly.

    With the rod horizontal (r = 10 m along x) and u_A = (1, -1)/sqrt 2, u_B = (1, 1)/sqrt 2:
    v_B = v_A + omega k x r along u_B gives omega = 2 v_A / (sqrt 2 r) and v_B = v_A; then
    a_B = a_A + alpha k x r - omega^2 r along u_B gives
    alpha = (2 a_A / sqrt 2 - omega^2 r) / r and a_B = sqrt 2 (a_A / sqrt 2 - omega^2 r).
    """
    scene = mk.parse_scene(yaml.safe_load(INCLINED))
    state = mk.solve(scene, 0.0, 2.0, 3.0)
    rod, block_b = state.joints['rod'], state.joints['block_b']
    root2, r = math.sqrt(2.0), 10.0
    omega = 2 * 2.0 / (root2 * r)
    alpha = (2 * 3.0 / root2 - omega * omega * r) / r
    a_b = root2 * (3.0 / root2 - omega * omega * r)
    assert rod.position == pytest.approx(0.0, abs=1e-15)
    assert rod.velocity == pytest.approx(omega, rel=1e-14)
    assert rod.acceleration == pytest.approx(alpha, rel=1e-14)
    assert block_b.velocity == pytest.approx(2.0, rel=1e-14)
    assert block_b.acceleration == pytest.approx(a_b, rel=1e-14)
    for got, printed in ((rod.velocity, 0.283), (rod.acceleration, 0.344),
                         (block_b.acceleration, 1.87)):
        assert abs(got - printed) <= 0.005 * abs(got), (got, printed)


def test_the_double_slider_has_the_hand_form_of_hibbeler_16_6():
    """Packaged double_slider: omega = v_A / (L cos 45 deg) CCW, v_B = v_A (printed 14.1, 2)."""
    scene = mk.load_scene('double_slider')
    state = mk.solve(scene, scene.drivers[0].start)
    omega = 2.0 / (0.2 * math.cos(math.pi / 4))
    assert state.joints['link'].velocity == pytest.approx(omega, rel=1e-14)
    assert state.joints['block_b'].velocity == pytest.approx(2.0, rel=1e-14)
    assert np.allclose(state.points['A'].velocity, (0.0, -2.0), rtol=0, atol=1e-15)


@given(theta=st.floats(0.2, math.pi - 0.2), omega=st.floats(-40.0, 40.0),
       alpha=st.floats(-500.0, 500.0), below=st.booleans())
@settings(max_examples=60, deadline=None, derandomize=True)
def test_the_piston_driven_crank_is_the_crank_driven_answer(theta, omega, alpha, below):
    """Drive the crank, read the piston; drive the piston so: the crank's motion comes back.

    The two solves share no closed form (an RRP placed from the crank pin, an
    RRR placed from the piston pin), so each checks the other, within the sum
    of their bounds (at most 1e-9 of each value's scale here).
    """
    angle = -theta if below else theta
    by_crank = mk.solve(mk.load_scene('slider_crank_150_600'), angle, omega, alpha)
    piston = by_crank.joints['piston']
    scene = from_piston(1 if below else -1)
    by_piston = mk.solve(scene, piston.position, piston.velocity, piston.acceleration)
    bounds_a, bounds_b = by_crank.error_bound.joints, by_piston.error_bound.joints
    crank = by_piston.joints['crank']
    for field in ('position', 'velocity', 'acceleration'):
        got = getattr(crank, field)
        want = angle if field == 'position' else omega if field == 'velocity' else alpha
        # The piston's own error moves the crank by it over d piston / d crank.
        lever = abs(piston.velocity / omega) if omega else None
        allowed = getattr(bounds_b['crank'], field) + getattr(bounds_a['piston'], field) * (
            1.0 / lever if lever else 0.0) + 1e-9 * max(1.0, abs(want))
        assert abs(got - want) <= allowed, (field, got, want)
    for point in ('B', 'P'):
        assert np.allclose(by_piston.points[point].position, by_crank.points[point].position,
                           rtol=0, atol=1e-12)


@pytest.mark.parametrize(('position', 'speed', 'accel'), [
    (0.1414213562373095, -2.0, 0.0), (0.05, 1.3, -7.0), (-0.19, 0.4, 3.0), (0.0, 2.0, 1.0),
    (0.199999, 0.1, 0.0)])
def test_double_slider_bounds_hold_against_the_50_digit_reference(position, speed, accel):
    """Every value within its bound of the mpmath reference (which has its own slider model)."""
    state, exact = assert_bounded(mk.load_scene('double_slider'), position, speed, accel)
    assert state is not None and exact is not None


@given(position=st.floats(-696.0, -451.0), speed=st.floats(-5.0, 5.0),
       accel=st.floats(-50.0, 50.0))
@settings(max_examples=20, deadline=None, derandomize=True)
def test_piston_driven_bounds_hold_against_the_50_digit_reference(position, speed, accel):
    """Over the piston's stroke (mm in the scene, m here): bounded by the reference."""
    state, exact = assert_bounded(from_piston(1), position / 1000, speed, accel)
    assert exact is not None


def test_a_position_outside_the_stroke_is_refused_naming_the_slider_and_its_stroke():
    """One line: the slider, its stroke and the position, in the scene's units."""
    scene = mk.load_scene('double_slider')
    with pytest.raises(mk.AssemblyError) as info:
        mk.solve(scene, 0.25)
    assert 'within its stroke' in str(info.value)
    assert mk.assembly_text(info.value, scene.units) == (
        'slider block_a: expected a position within its stroke [-0.2 m, 0.2 m], got 0.25 m')


def test_where_the_link_cannot_reach_the_other_slot_it_is_refused():
    """At |s| = L (the stroke's end) the link is square to B's slot: a dead centre, refused."""
    scene = mk.load_scene('double_slider')
    with pytest.raises(mk.AssemblyError, match='RRP B'):
        mk.solve(scene, 0.2)


@pytest.mark.parametrize(('entry', 'match'), [
    ({'slider': 'blk', 'point': 'A', 'guide': {'through': 'O'}, 'position': 0.1,
      'stroke': [0.2]}, r'inputs\[0\]\.stroke: expected \[lowest, highest\] positions'),
    ({'slider': 'blk', 'point': 'A', 'guide': {'through': 'O'}, 'position': 0.1,
      'stroke': [0.2, -0.2]}, r'inputs\[0\]\.stroke: Expected the stroke of slider "blk"'),
    ({'slider': 'blk', 'point': 'A', 'guide': {'through': 'O'}, 'position': 0.3,
      'stroke': [-0.2, 0.2]}, r'inputs\[0\]\.position: Expected the position of slider "blk" '
                              r'at time zero within its stroke'),
    ({'slider': 'blk', 'point': 'A', 'guide': {'through': 'Q'}, 'position': 0.1},
     r'inputs\[0\]\.guide\.through: Expected the guide point of slider "blk" to be a ground'),
    ({'slider': 'blk', 'point': 'O', 'guide': {'through': 'O'}, 'position': 0.1},
     r'Expected the pin of slider "blk" to be a point of its own'),
    ({'slider': 'blk', 'point': 'A', 'guide': {'through': 'O', 'dir': 3}, 'position': 0.1},
     r"inputs\[0\]\.guide: unknown key\(s\) \['dir'\]"),
    ({'slider': 'blk', 'point': 'A', 'guide': {'through': 'O'}, 'position': 0.1,
      'rate': 1}, r"unknown key\(s\) \['rate'\]"),
])
def test_bad_sliders_are_refused_in_one_line(entry, match):
    """Each mistake in a slider's keys is one line naming where it is."""
    data = yaml.safe_load(scene_text('double_slider'))
    data['inputs'] = [entry]
    data['dyads'][0]['link']['from'] = entry['point']
    with pytest.raises(mk.SceneError, match=match) as info:
        mk.parse_scene(data)
    assert '\n' not in str(info.value)


def test_its_part_of_the_graph_is_a_driven_block_on_the_ground_not_a_cylinder():
    """The block slides on the ground by a driven prismatic joint; no cylinder, no varying link."""
    graph = mk.load_scene('double_slider').graph
    joint = graph.prismatic('block_a')
    assert (joint.type, joint.on, joint.driver, joint.at) == (g.PRISMATIC, graph.ground, True, 'A')
    assert graph.bodies['block_a'].role is g.Role.SLIDER
    assert graph.bodies['block_a'].guide == graph.ground
    assert list(graph.cylinders()) == []
    assert graph.drivers == ('block_a',)
    excavator = mk.load_scene('excavator').graph
    assert {j.name for j in excavator.cylinders()} == set(excavator.drivers)


def test_the_array_path_gives_the_single_solves_bits():
    """Positions over the stroke as one array: each the single solve's values."""
    scene = mk.load_scene('double_slider')
    s = np.linspace(-0.19, 0.19, 41)
    v, a = np.linspace(-2, 2, 41), np.linspace(3, -3, 41)
    many = mk.solve(scene, s, v, a)
    assert many.valid.all()
    for i in range(0, 41, 5):
        one = mk.solve(scene, float(s[i]), float(v[i]), float(a[i]))
        for name, motion in one.joints.items():
            got = many.joints[name]
            assert (got.velocity[i], got.acceleration[i]) == pytest.approx(
                (motion.velocity, motion.acceleration), rel=1e-13, abs=1e-13)
            assert got.position[i] == pytest.approx(motion.position, rel=1e-15, abs=1e-16)


ENGINE_FROM_PISTON = """\
name: engine_from_piston
units: {length: mm, angle: deg}
ground: {O: [0, 0]}
inputs:
  - {slider: piston, point: P, guide: {through: O, angle: 90}, position: 280}
dyads:
  - type: RRR
    point: C
    links: [{name: crank, from: O, length: 75}, {name: rod, from: P, length: 225}]
    branch: 1
gravity: [0, -9.81]
masses:
  crank: {mass: 20, inertia: 0.5}
  rod: {mass: 1.6, com: [150, 0], inertia: 0.01225}   # 75 mm from the crank pin C
  piston: {mass: 2.4}
loads:
  - {name: gas, point: P, force: [0, -17892.35190989812]}
"""


@pytest.mark.parametrize('angle', [130.0, 100.0, 60.0, -60.0])
def test_the_engine_driven_from_its_piston_takes_the_power_its_crank_gives(angle):
    """The packaged engine's motion driven from the piston: F v = T omega (the same loads).

    The crank-driven engine's torque T at (theta, omega, alpha); the piston
    driven through the same motion needs the force F with F v_P = T omega:
    the same inertias, gravity and gas force, each drive's power the rest's.
    Two statics (the crank's group against the piston block's), within their
    bounds' share of the power.
    """
    engine = mk.load_scene('engine')
    theta, omega, alpha = math.radians(angle), 209.44, 35.0
    by_crank = mk.solve(engine, theta, omega, alpha)
    piston = by_crank.joints['piston']
    data = yaml.safe_load(ENGINE_FROM_PISTON)
    data['dyads'][0]['branch'] = 1 if math.cos(theta) < 0 else -1   # C left (1) or right of OP
    scene = mk.parse_scene(data)
    by_piston = mk.solve(scene, piston.position, piston.velocity, piston.acceleration)
    assert by_piston.joints['crank'].velocity == pytest.approx(omega, rel=1e-9)
    assert by_piston.joints['crank'].acceleration == pytest.approx(alpha, rel=1e-6)
    torque = by_crank.forces.efforts['crank']
    force = by_piston.forces.efforts['piston']
    power = torque * omega
    allowed = (by_crank.forces.effort_bounds['crank'] * abs(omega)
               + by_piston.forces.effort_bounds['piston'] * abs(piston.velocity)
               + 1e-9 * abs(power))
    assert abs(force * piston.velocity - power) <= allowed, (force, torque)


@pytest.mark.parametrize('b', [0.1, 0.15, 0.05])
def test_the_double_slider_driven_by_block_b_as_a_target(b):
    """Block B's position and speed as targets: s_A^2 + s_B^2 = L^2, so s_A s_A' = -s_B s_B'."""
    inverse = mk.solve_targets(mk.load_scene('double_slider'), {'block_b': b}, {'block_b': 1.0})
    a = inverse.answer.joints['block_a']
    assert a.position == pytest.approx(math.sqrt(0.2 ** 2 - b * b), rel=1e-13)
    assert a.velocity == pytest.approx(-b * 1.0 / a.position, rel=1e-12)
    assert inverse.jacobian[0, 0] == pytest.approx(-a.position / b, rel=1e-12)
