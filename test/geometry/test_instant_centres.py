# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Instant centres: from the velocities, by Kennedy's theorem, and the velocity check."""

from __future__ import annotations

from dataclasses import replace
import itertools
import math
import re
import warnings

from helpers import crank_scene_names
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.geometry.instant_centres import (bodies_from_scene, BodyKind, Centre,
                                                      full_scene, instant_centres_from_kennedy,
                                                      instant_centres_from_state,
                                                      REL_TRANSLATION)

#: Homogeneous centres are unit 3-vectors in units of the mechanism's size.
ATOL_HOMOGENEOUS = 1e-9
#: Determinant of three unit homogeneous centres (collinearity).
ATOL_COLLINEAR = 1e-9
#: Velocity of a point against omega x (P - I), relative to the largest speed.
RTOL_VELOCITY = 1e-9

SCENES = tuple(crank_scene_names())  # Kennedy's polygons are one crank's (issue 18)
#: Crank angles tried besides each scene's own, degrees.
ANGLES_DEG = (0.0, 37.0, 95.0, 160.0, 215.0, 290.0)


def _states():
    cases = []
    for name in SCENES:
        scene = full_scene(mk.load_scene(name))
        angles = np.array([scene.input.angle, *(math.radians(a) for a in ANGLES_DEG)])
        # Only angles at which the scene assembles (the array path's mask says which).
        for index, angle in enumerate(angles[mk.solve(scene, angles).valid]):
            cases.append(pytest.param(name, float(angle), id=f'{name}-{index}'))
    return cases


def _solve(name, angle):
    scene = full_scene(mk.load_scene(name))
    try:
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', mk.NearSingularWarning)
            return scene, mk.solve(scene, angle)
    except mk.AssemblyError as error:
        pytest.fail(f'expected {name} to assemble at {angle} rad: {error}')


def _same(h1, h2):
    return min(np.linalg.norm(h1 - h2), np.linalg.norm(h1 + h2))


@pytest.mark.parametrize('name', SCENES)
def test_every_pair_has_a_centre(name):
    """The velocity method gives n (n - 1) / 2 centres, one per pair of bodies."""
    scene, state = _solve(name, mk.load_scene(name).input.angle)
    centres = instant_centres_from_state(scene, state)
    n = len(centres.topology.bodies)
    assert len(centres) == n * (n - 1) // 2
    assert all(c.method is Centre.VELOCITY for c in centres)


@pytest.mark.parametrize(('name', 'angle'), _states())
def test_kennedy_agrees_with_velocities(name, angle):
    """Kennedy's construction from positions finds every centre, equal to the velocity one."""
    scene, state = _solve(name, angle)
    by_velocity = instant_centres_from_state(scene, state)
    by_kennedy = instant_centres_from_kennedy(scene, state)
    assert len(by_kennedy) == len(by_velocity)
    for centre in by_kennedy:
        other = by_velocity[centre.bodies]
        assert _same(centre.homogeneous(by_velocity.size),
                     other.homogeneous(by_velocity.size)) < ATOL_HOMOGENEOUS, \
            by_velocity.label(centre)


@pytest.mark.parametrize(('name', 'angle'), _states())
def test_three_centres_of_three_links_are_collinear(name, angle):
    """Kennedy's theorem: the three centres of any three bodies lie on one line."""
    scene, state = _solve(name, angle)
    centres = instant_centres_from_state(scene, state)
    for a, b, c in itertools.combinations(centres.topology.bodies, 3):
        h = np.array([centres[pair].homogeneous(centres.size)
                      for pair in ((a, b), (b, c), (a, c))])
        assert abs(np.linalg.det(h)) < ATOL_COLLINEAR, (a, b, c)


def _body_omega(topology, state, name):
    """Return a body's angular velocity: a slider block turns with what it slides on."""
    body = topology.bodies[name]
    if body.kind is BodyKind.GROUND:
        return 0.0
    if body.kind is BodyKind.SLIDER:
        return _body_omega(topology, state, body.guide)
    return state.joints[name].velocity


@pytest.mark.parametrize(('name', 'angle'), _states())
def test_point_velocity_is_omega_times_distance_from_ground_centre(name, angle):
    """Every point P of every link moves as omega x (P - I): |v_P| = |omega| |PI|, normal to PI."""
    scene, state = _solve(name, angle)
    centres = instant_centres_from_state(scene, state)
    topology = centres.topology
    speeds = [abs(complex(v)) for _, v, _ in state.complex_points.values()]
    atol = RTOL_VELOCITY * max(speeds)
    for body in topology.bodies.values():
        if body.kind is BodyKind.GROUND:
            continue
        centre = centres[(topology.ground, body.name)]
        omega = _body_omega(topology, state, body.name)
        for point in body.points:
            p, v, _ = (complex(x) for x in state.complex_points[point])
            if centre.point is None:
                # translation: every point has the same velocity, normal to the direction;
                # omega is 0: a slider's exactly, a link's to the rounding the centres are
                # found with (the gripper's parallelogram jaw, -2.2e-16 rad/s at its start)
                if body.kind is BodyKind.SLIDER:
                    assert omega == 0.0
                else:
                    assert abs(omega) * centres.size <= REL_TRANSLATION * abs(v)
                d = complex(*centre.direction)
                assert abs((v * d.conjugate()).real) <= atol
            else:
                i = complex(*centre.point)
                np.testing.assert_allclose(abs(v), abs(omega) * abs(p - i), atol=atol)
                np.testing.assert_allclose([v.real, v.imag],
                                           [(1j * omega * (p - i)).real,
                                            (1j * omega * (p - i)).imag], atol=atol)


def test_four_bar_centres():
    """Four-bar ABCD: I12 = A, I23 = B, I34 = C, I14 = D, I13 = AB x DC, I24 = BC x AD."""
    scene, state = _solve('khurmi_four_bar_ad150', mk.load_scene('khurmi_four_bar_ad150')
                          .input.angle)
    centres = instant_centres_from_kennedy(scene, state)
    p = {name: complex(x[0]) for name, x in state.complex_points.items()}

    def meet(a, b, c, d):
        t = ((c - a).real * (d - c).imag - (c - a).imag * (d - c).real) / \
            ((b - a).real * (d - c).imag - (b - a).imag * (d - c).real)
        return a + t * (b - a)

    expected = {('ground', 'crank'): p['A'], ('crank', 'coupler'): p['B'],
                ('coupler', 'rocker'): p['C'], ('ground', 'rocker'): p['D'],
                ('ground', 'coupler'): meet(p['A'], p['B'], p['D'], p['C']),
                ('crank', 'rocker'): meet(p['B'], p['C'], p['A'], p['D'])}
    assert [centres.label(c) for c in centres] == ['I12', 'I13', 'I14', 'I23', 'I24', 'I34']
    for pair, z in expected.items():
        np.testing.assert_allclose(centres[pair].point, [z.real, z.imag],
                                   atol=ATOL_HOMOGENEOUS * centres.size)
    assert centres[('ground', 'crank')].method is Centre.PIN
    assert centres[('ground', 'coupler')].method is Centre.KENNEDY


def test_slider_on_fixed_guide_has_ground_centre_at_infinity():
    """A slider on a horizontal guide has its centre with the ground at infinity, vertically."""
    scene, state = _solve('quick_return', mk.load_scene('quick_return').input.angle)
    for centres in (instant_centres_from_state(scene, state),
                    instant_centres_from_kennedy(scene, state)):
        centre = centres[('ram', 'ground')]
        assert centre.at_infinity and centre.point is None
        np.testing.assert_allclose(abs(centre.direction[1]), 1.0, atol=ATOL_HOMOGENEOUS)
        # the block in the slot translates relative to the lever: normal to the slot
        slot = centres[('block', 'lever')]
        angle = state.joints['lever'].position
        assert slot.at_infinity
        np.testing.assert_allclose(slot.direction @ [math.cos(angle), math.sin(angle)], 0.0,
                                   atol=ATOL_HOMOGENEOUS)


def test_bodies_of_the_quick_return():
    """Bodies are numbered ground first; sliders are bodies; pins join bodies sharing a point."""
    topology = bodies_from_scene(mk.load_scene('quick_return'))
    assert list(topology.bodies) == ['ground', 'crank', 'lever', 'block', 'link_CD', 'ram']
    assert [b.number for b in topology.bodies.values()] == [1, 2, 3, 4, 5, 6]
    assert set(topology.pins) == {('ground', 'crank', 'A'), ('ground', 'lever', 'O'),
                                  ('crank', 'block', 'B'), ('lever', 'link_CD', 'C'),
                                  ('link_CD', 'ram', 'D')}
    assert set(topology.slides) == {('block', 'lever'), ('ram', 'ground')}


def test_state_of_an_array_is_refused():
    """A state over an array of angles is refused with an "Expected ..." message."""
    scene = mk.load_scene('khurmi_four_bar_ad150')
    state = mk.solve(scene, np.array([1.0, 1.1]))
    with pytest.raises(ValueError, match='Expected the state of one crank angle'):
        instant_centres_from_state(scene, state)


def test_pruned_state_is_refused():
    """A state pruned by outputs misses points: the message says to solve full_scene."""
    scene = replace(mk.load_scene('quick_return'), outputs_points=('D',), outputs_joints=())
    state = mk.solve(scene, scene.input.angle)
    with pytest.raises(ValueError, match='full_scene'):
        instant_centres_from_kennedy(scene, state)
    full = full_scene(scene)
    assert len(instant_centres_from_state(full, mk.solve(full, scene.input.angle))) == 15


@pytest.mark.parametrize('name', ['five_bar', 'excavator'])
def test_kennedy_is_one_drivers_and_refuses_several_in_one_line(name):
    """Kennedy's construction is one driver's (issue 18): a clear SceneError, not a crash."""
    scene = full_scene(mk.load_scene(name))
    state = mk.solve(scene, [d.start for d in scene.drivers])
    names = ', '.join(d.name for d in scene.drivers)
    with pytest.raises(mk.SceneError, match=re.escape(
            f"Expected a scene driven by one crank for instant centres (one driver's), got "
            f'scene "{name}" with 2 drivers ({names})')):
        instant_centres_from_kennedy(scene, state)
    assert {body.name for body in bodies_from_scene(scene).bodies.values()} >= {
        d.name for d in scene.drivers if d.joint_type == 'revolute'}


def test_five_bar_centres_from_velocities_with_both_cranks_moving():
    """Two cranks at their own speeds: every centre's relative velocity is zero there."""
    scene = full_scene(mk.load_scene('five_bar'))
    state = mk.solve(scene, [1.9, 0.8], [2.0, -3.0], [0.0, 0.0])
    centres = instant_centres_from_state(scene, state)
    assert len(centres) == 10  # ground, two cranks, two distal links: 5 bodies
    crank = next(c for c in centres if c.bodies == ('left_crank', 'right_crank'))
    # on AE, dividing it as w2 / (w2 - w1) = -3 / -5
    np.testing.assert_allclose(crank.point, [0.1 * 3 / 5, 0.0], atol=1e-15)


def test_a_link_that_changes_length_has_no_instant_centres():
    """The excavator's cylinders are not rigid bodies: refused in one line."""
    scene = full_scene(mk.load_scene('excavator'))
    state = mk.solve(scene, [d.start for d in scene.drivers])
    with pytest.raises(mk.SceneError, match=re.escape(
            'Expected rigid links for instant centres, got scene "excavator" whose link '
            "boom_cyl_body, stick_cyl_body changes length (an actuator's")):
        instant_centres_from_state(scene, state)
