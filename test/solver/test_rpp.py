# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The RPP dyad, the Scotch yoke (docs/scene_format.md; issue 17): closed forms, bounds, scene.

The packaged ``scotch_yoke`` has a crank of radius r about A on the yoke's
horizontal guide and a vertical slot, so the yoke's point Y is at
``x = r cos(theta)``: simple harmonic motion, the golden values below.
"""

from __future__ import annotations

import math

from helpers import assert_bounded, SCENES
from hypothesis import assume, given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.geometry.diagrams import (acceleration_polygon_from_state, diagram_from_scene,
                                               VectorKind, velocity_polygon_from_state)
from mech_kinematics.geometry.frames import frames_from_scene, poses_from_state
from mech_kinematics.ros.ticker import tick_function
from mech_kinematics.solver import RPP

pytestmark = pytest.mark.filterwarnings('ignore::mech_kinematics.NearSingularWarning')

#: The packaged yoke's crank radius, m (50 mm).
R = 0.05
ATOL_POSITION = 1e-16           # m: a few ulps of r
ATOL_VELOCITY = 1e-14           # m/s, at omega up to 31.4 rad/s
ATOL_ACCELERATION = 1e-12       # m/s^2
#: Central differences with step H (rad of crank angle): error O(H^2) of the
#: scale (|omega|^3 r H^2 / 6 for a velocity), well below this relative tolerance.
H = 1e-5
RTOL_DIFFERENCE = 1e-7


def _yoke(r=R, guide=0.0, slot=math.pi / 2, offset=(0.0, 0.0), angle=0.3, speed=2.0,
          accel=0.0):
    """Return a Scotch yoke: crank r about A, guide through O = A + offset at ``guide``."""
    return mk.Scene('yoke', {'A': (0.0, 0.0), 'O': offset},
                    mk.Crank('crank', 'A', 'B', r, angle, speed, accel),
                    (RPP('Y', 'B', 'O', guide, slot, 'yoke', 'pin_in_slot'),))


@pytest.mark.parametrize('theta', np.linspace(-7.0, 7.0, 29))
@pytest.mark.parametrize(('omega', 'alpha'), [(10 * math.pi, 0.0), (-3.0, 2.5), (0.0, 1.0)])
def test_packaged_yoke_is_simple_harmonic(theta, omega, alpha):
    """x_Y = r cos, v = -r w sin, a = -r w^2 cos - r alpha sin; the pin's slot coordinate r sin."""
    scene = mk.load_scene('scotch_yoke')
    state = mk.solve(scene, theta, omega, alpha)
    yoke, slot = state.joints['yoke'], state.joints['pin_in_slot']
    c, s = math.cos(theta), math.sin(theta)
    np.testing.assert_allclose(yoke.position, R * c, rtol=0, atol=ATOL_POSITION)
    np.testing.assert_allclose(yoke.velocity, -R * omega * s, rtol=0, atol=ATOL_VELOCITY)
    np.testing.assert_allclose(yoke.acceleration, -R * omega**2 * c - R * alpha * s, rtol=0,
                               atol=ATOL_ACCELERATION)
    np.testing.assert_allclose(slot.position, R * s, rtol=0, atol=ATOL_POSITION)
    np.testing.assert_allclose(slot.velocity, R * omega * c, rtol=0, atol=ATOL_VELOCITY)
    np.testing.assert_allclose(slot.acceleration, -R * omega**2 * s + R * alpha * c, rtol=0,
                               atol=ATOL_ACCELERATION)
    y = state.points['Y']
    np.testing.assert_allclose(y.position, [R * c, 0.0], rtol=0, atol=ATOL_POSITION)
    assert yoke.type == slot.type == 'prismatic'
    assert state.singularity['Y'] == 1.0


def test_packaged_yoke_at_its_own_speed():
    """At the scene's 300 rpm and 30 deg: x = r cos 30 deg, v = -r (10 pi) sin 30 deg."""
    scene = mk.load_scene('scotch_yoke')
    assert scene.input.speed == 10 * math.pi
    state = mk.solve(scene, scene.input.angle)
    theta = math.radians(30)
    np.testing.assert_allclose(state.joints['yoke'].position, R * math.cos(theta), rtol=1e-15)
    np.testing.assert_allclose(state.joints['yoke'].velocity, -R * 10 * math.pi * 0.5,
                               rtol=1e-14)


def _closure(state, scene, index=None):
    """Return the residuals of Y on the guide and of B - Y along the slot (m), and s and t."""
    (dyad,) = scene.dyads
    u = complex(math.cos(dyad.guide_angle), math.sin(dyad.guide_angle))
    w = complex(math.cos(dyad.slot_angle), math.sin(dyad.slot_angle))
    o = complex(*scene.ground[dyad.guide_through])
    y = complex(state.complex_points['Y'][0])
    b = complex(state.complex_points['B'][0])
    on_guide = ((y - o) * u.conjugate()).imag
    in_slot = ((b - y) * w.conjugate()).imag
    s = ((y - o) * u.conjugate()).real
    t = ((b - y) * w.conjugate()).real
    return on_guide, in_slot, s, t


def _yoke_across(r, guide, across, offset, speed, accel):
    """Return a yoke whose slot is turned by ``across`` (rad) from its guide."""
    return _yoke(r, guide, guide + across, offset, 0.3, speed, accel)


yokes = st.builds(
    _yoke_across, r=st.floats(0.01, 2.0), guide=st.floats(-math.pi, math.pi),
    across=st.floats(0.05, math.pi - 0.05),
    offset=st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)),
    speed=st.one_of(st.just(0.0), st.floats(0.1, 20.0), st.floats(-20.0, -0.1)),
    accel=st.one_of(st.just(0.0), st.floats(0.1, 50.0), st.floats(-50.0, -0.1)))


@settings(max_examples=200, deadline=None, derandomize=True)
@given(yokes, st.floats(-10.0, 10.0))
def test_loop_closes_and_coordinates_are_the_joints(scene, theta):
    """Y lies on the guide, B - Y along the slot, and s, t are the joints' positions."""
    (dyad,) = scene.dyads
    state = mk.solve(scene, theta)
    on_guide, in_slot, s, t = _closure(state, scene)
    size = scene.input.length + math.hypot(*scene.ground['O'])
    assert abs(on_guide) <= 1e-14 * size
    assert abs(in_slot) <= 1e-14 * size / abs(math.sin(dyad.slot_angle - dyad.guide_angle))
    gain = 1.0 / abs(math.sin(dyad.slot_angle - dyad.guide_angle))
    np.testing.assert_allclose(state.joints['yoke'].position, s, rtol=0, atol=1e-13 * size * gain)
    np.testing.assert_allclose(state.joints['pin_in_slot'].position, t, rtol=0,
                               atol=1e-13 * size * gain)


@settings(max_examples=100, deadline=None, derandomize=True)
@given(yokes, st.floats(-10.0, 10.0))
def test_velocity_and_acceleration_are_central_differences(scene, theta):
    """At a constant crank speed, v = omega dx/dtheta and a = omega dv/dtheta, to O(H^2)."""
    (dyad,) = scene.dyads
    omega = scene.input.speed
    assume(abs(omega) > 1e-3)
    angles = np.array([theta - H, theta, theta + H])
    state = mk.solve(scene, angles, omega, 0.0)
    gain = 1.0 / abs(math.sin(dyad.slot_angle - dyad.guide_angle))
    for name in ('yoke', 'pin_in_slot'):
        joint = state.joints[name]
        scale = scene.input.length * gain * omega * omega
        dx = (joint.position[2] - joint.position[0]) / (2 * H) * omega
        dv = (joint.velocity[2] - joint.velocity[0]) / (2 * H) * omega
        np.testing.assert_allclose(joint.velocity[1], dx, rtol=0,
                                   atol=RTOL_DIFFERENCE * scale / abs(omega) + 1e-9 * gain)
        np.testing.assert_allclose(joint.acceleration[1], dv, rtol=0,
                                   atol=RTOL_DIFFERENCE * scale + 1e-9 * gain * abs(omega))


@settings(max_examples=60, deadline=None, derandomize=True)
@given(yokes, st.floats(-10.0, 10.0))
def test_bounds_cover_the_actual_error_against_the_50_digit_reference(scene, theta):
    """Every value the yoke's solve returns is within its error bound of the exact state."""
    state, exact = assert_bounded(scene, theta)
    assert state is not None and exact is not None


@pytest.mark.parametrize('slot', [0.0, math.pi, -math.pi, 1e-13])
def test_slot_parallel_to_the_guide_is_refused_at_load(slot):
    """A slot parallel to its guide never meets it: refused when the scene is built."""
    with pytest.raises(mk.SceneError, match=r'Expected the slot of RPP "Y" to cross its guide'):
        _yoke(slot=slot)


def _yaml(tmp_path, dyad_text):
    text = (SCENES / 'scotch_yoke.yaml').read_text()
    head = text[:text.index('dyads:')]
    path = tmp_path / 'yoke.yaml'
    path.write_text(head + 'dyads:\n' + dyad_text)
    return path


@pytest.mark.parametrize(('dyad', 'message'), [
    ('  - {type: RPP, point: Y, through: B, guide: {through: A, angle: 0}, slot_angle: 180,\n'
     '     slider: yoke, slot_slider: pin_in_slot}\n',
     r'dyads\[0\]\.slot_angle: Expected the slot of RPP "Y" to cross its guide'),
    ('  - {type: RPP, point: Y, through: B, guide: {through: A, angle: 0},\n'
     '     slider: yoke, slot_slider: pin_in_slot}\n',
     r'dyads\[0\]\.slot_angle: missing required key'),
    ('  - {type: RPP, point: Y, through: B, guide: {through: B, angle: 0}, slot_angle: 90,\n'
     '     slider: yoke, slot_slider: pin_in_slot}\n',
     r'dyads\[0\]\.guide\.through: Expected the guide point of RPP "Y" to be a ground point'),
    ('  - {type: RPP, point: Y, through: B, guide: {through: A, angle: 0}, slot_angle: 90,\n'
     '     slider: yoke, slot_slider: pin_in_slot, branch: 1}\n',
     r"dyads\[0\]: unknown key\(s\) \['branch'\]"),
    ('  - {type: RPP, point: Y, through: B, guide: {through: A, angle: 0}, slot_angle: 90,\n'
     '     slider: yoke, slot_slider: yoke}\n',
     r'Expected every name to be used once, got "yoke" twice'),
])
def test_scene_errors_name_the_key(tmp_path, dyad, message):
    """Bad RPP keys are refused with one line naming the file key."""
    with pytest.raises(mk.SceneError, match=message) as error:
        mk.load_scene(_yaml(tmp_path, dyad))
    assert '\n' not in str(error.value)


def test_the_tick_compiles_the_yoke_to_the_same_bits():
    """The node's compiled tick runs the yoke's step and answers as mk.solve does, bit for bit."""
    scene = mk.load_scene('scotch_yoke')
    tick, compiled = tick_function(scene)
    assert compiled
    for theta in np.linspace(-7.0, 7.0, 57):
        values, measure = tick(float(theta), 3.0, -2.0, 1e-6, 0)
        state = mk.solve(scene, float(theta), 3.0, -2.0)
        names = scene.output_joints
        assert values[:len(names)] == [float(state.joints[n].position) for n in names]
        assert measure == 1.0


def test_frames_of_the_yoke_only_translate():
    """The yoke's /tf frame sits at Y along the guide, the pin's block at B along the slot."""
    scene = mk.load_scene('scotch_yoke')
    frames = {f.joint: f for f in frames_from_scene(scene)}
    state = mk.solve(scene, 1.0)
    poses = {p.joint: p for p in poses_from_state(list(frames.values()), state)}
    assert poses['yoke'].angle == 0.0
    assert poses['pin_in_slot'].angle == math.pi / 2
    np.testing.assert_allclose((poses['yoke'].x, poses['yoke'].y), (R * math.cos(1.0), 0.0),
                               atol=ATOL_POSITION)


@pytest.mark.parametrize('theta', [0.3, 2.0, 4.0])
def test_polygons_draw_the_slip_and_close(theta):
    """Velocity and acceleration polygons: o->b (crank), o->y, and the slip y->b along the slot."""
    scene = mk.load_scene('scotch_yoke')
    state = mk.solve(scene, theta, 3.0, 1.5)
    for polygon, rate in ((velocity_polygon_from_state(scene, state), 'velocity'),
                          (acceleration_polygon_from_state(scene, state), 'acceleration')):
        slips = [v for v in polygon.vectors if v.kind is VectorKind.SLIP]
        assert [(v.tail, v.head, v.body) for v in slips] == [('y', 'b', 'pin_in_slot')]
        (slip,) = slips
        np.testing.assert_allclose(slip.start, polygon.letters['y'], atol=1e-15)
        np.testing.assert_allclose(slip.end, polygon.letters['b'], atol=1e-14)
        value = float(getattr(state.joints['pin_in_slot'], rate))
        np.testing.assert_allclose(slip.end - slip.start, [0.0, value], atol=1e-15)


def test_diagram_draws_the_yoke():
    """The space diagram has the yoke's block on its guide and the pin's block in the slot."""
    diagram = diagram_from_scene(mk.load_scene('scotch_yoke'), instant_centres=True)
    blocks = {s.name: s for s in diagram.space.sliders}
    assert blocks['yoke'].angle == 0.0 and blocks['yoke'].guide == 'ground'
    assert blocks['pin_in_slot'].angle == math.pi / 2 and blocks['pin_in_slot'].guide == 'yoke'
    assert [g.slider for g in diagram.space.guides] == ['yoke']
