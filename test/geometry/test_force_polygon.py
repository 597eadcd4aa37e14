# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The force polygon of one body at one instant (issue 32).

The polygon takes the joints' reactions and the drivers' efforts from the
solver and computes the weight and the inertia force from the body's own
motion: that it closes (and that the moments balance) within the bounds it
states checks the solver's reactions against each body's kinematics. The
bounds are held to rounding's size, so a polygon that closed only loosely
would fail.
"""

from __future__ import annotations

import math

from helpers import forces_scene
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.geometry.force_polygon import (force_polygon_from_state, ForceKind,
                                                    moving_bodies)

pytestmark = pytest.mark.filterwarnings('ignore::mech_kinematics.NearSingularWarning')

#: A polygon's closing and moment bounds stay below this fraction of its largest force (or
#: couple over the mechanism's size; times the size, for moments): rounding's size.
RTOL_CLOSING = 1e-10

#: Instants of each test scene: a crank angle (rad) or each driver's position, speed and
#: acceleration (rad, rad/s, rad/s^2; m, m/s, m/s^2).
INSTANTS = {
    'four_bar_masses': [(0.3, None, None), (2.5, -20.0, 35.0), (4.0, None, None)],
    'engine': [(0.2, None, None), (math.pi / 2, None, None), (3.9, 40.0, -100.0)],
    'geneva_wheel': [(2.0, None, None), (2.9, None, None), (3.5, 10.0, 5.0)],
    'scotch_yoke_mass': [(0.4, None, None), (2.0, None, 50.0)],
    'five_bar_masses': [([1.2, 0.9], [2.0, -1.0], [0.0, 3.0]),
                        ([2.5, 1.5], [0.0, 0.0], [0.0, 0.0])],
    'boom_masses': [(1.6, 0.05, 0.0), (2.2, -0.1, 0.4)],
}


def cases():
    """Yield a pytest param per test scene, instant and moving body."""
    for name, instants in INSTANTS.items():
        scene = forces_scene(name)
        for k, instant in enumerate(instants):
            for body in moving_bodies(scene):
                yield pytest.param(name, instant, body, id=f'{name}-{k}-{body}')


@pytest.mark.parametrize('name, instant, body', list(cases()))
def test_every_body_closes_and_balances(name, instant, body):
    """Sum of forces and of moments about the frame's origin: 0 within their small bounds."""
    scene = forces_scene(name)
    state = mk.solve(scene, *instant)
    polygon = force_polygon_from_state(scene, state, body)
    size = scene.dynamics.size
    largest = max([f.magnitude for f in polygon.forces]
                  + [abs(c.moment) / size for c in polygon.couples])   # a couple's force scale
    assert polygon.closure <= polygon.closure_bound <= RTOL_CLOSING * largest
    assert abs(polygon.moment) <= polygon.moment_bound <= RTOL_CLOSING * largest * size
    np.testing.assert_allclose(polygon.vertices[-1], polygon.vertices[0], rtol=0,
                               atol=polygon.closure_bound)
    np.testing.assert_allclose(np.diff(polygon.vertices, axis=0),   # head to tail
                               [f.force for f in polygon.forces], rtol=0,
                               atol=4 * np.finfo(float).eps * largest * len(polygon.forces))


def test_the_forces_are_what_the_course_draws():
    """The coupler: weight and inertia at G, the push at C, the pins B and C; its -I alpha couple.

    The weight is m g; the inertia force -m a_G with a_G from a central
    difference of G's position over time (h = 1e-5 s: O(h^2), 1e-7 of it).
    """
    scene = forces_scene('four_bar_masses')
    state = mk.solve(scene, 1.0)
    polygon = force_polygon_from_state(scene, state, 'coupler')
    kinds = [(f.label, f.kind, f.at) for f in polygon.forces]
    assert kinds == [('W', ForceKind.WEIGHT, None), ('-ma', ForceKind.INERTIA, None),
                     ('push', ForceKind.LOAD, 'C'), ('B', ForceKind.JOINT, 'B'),
                     ('C', ForceKind.JOINT, 'C')]
    np.testing.assert_array_equal(polygon.forces[0].force, [0.0, -0.5 * 9.81])
    w = scene.input.speed
    h = 1e-5

    def g_at(t):
        s = mk.solve(scene, 1.0 + w * t, w, 0.0)
        b = complex(s.complex_points['B'][0])
        c = complex(s.complex_points['C'][0])
        return b + complex(0.075, 0.010) * (c - b) / abs(c - b)

    a_g = (g_at(h) - 2 * g_at(0.0) + g_at(-h)) / h ** 2
    np.testing.assert_allclose(polygon.forces[1].force, [-0.5 * a_g.real, -0.5 * a_g.imag],
                               rtol=1e-6)
    reactions = state.forces.reactions
    np.testing.assert_array_equal(polygon.forces[3].force, [reactions['B'].force.real,
                                                            reactions['B'].force.imag])
    np.testing.assert_array_equal(polygon.forces[4].force, [-reactions['C'].force.real,
                                                            -reactions['C'].force.imag])
    (couple,) = polygon.couples
    assert couple.kind is ForceKind.INERTIA
    assert couple.moment == pytest.approx(-6.0e-4 * float(state.joints['coupler'].acceleration),
                                          rel=1e-15)


def test_a_crank_carries_its_driving_torque_and_an_actuator_its_force():
    """The crank's effort is a couple on it; the cylinder's is a force along it, on both parts."""
    scene = forces_scene('engine')
    state = mk.solve(scene, 0.7)
    crank = force_polygon_from_state(scene, state, 'crank')
    torque = next(c for c in crank.couples if c.kind is ForceKind.EFFORT)
    assert torque.moment == float(state.forces.efforts['crank'])
    assert [c.label for c in crank.couples] == ['drag', 'crank']
    boom = forces_scene('boom_masses')
    state = mk.solve(boom, 2.0, 0.05, 0.0)
    rod = force_polygon_from_state(boom, state, 'lift_cyl')
    barrel = force_polygon_from_state(boom, state, 'lift_cyl_body')
    on_rod = next(f for f in rod.forces if f.label == 'lift_cyl')
    on_barrel = next(f for f in barrel.forces if f.label == 'lift_cyl')
    np.testing.assert_array_equal(on_rod.force, -on_barrel.force)
    angle = float(state.joints['lift_cyl_body'].position)
    along = on_rod.force @ [math.cos(angle), math.sin(angle)]
    assert along == pytest.approx(float(state.forces.efforts['lift_cyl']), rel=1e-12)


def test_no_weight_without_gravity_and_a_zero_force_has_no_direction():
    """The Geneva wheel (no gravity): no W; its inertia force at its centre is 0, direction NaN."""
    scene = forces_scene('geneva_wheel')
    polygon = force_polygon_from_state(scene, mk.solve(scene, 2.5), 'wheel')
    assert 'W' not in [f.label for f in polygon.forces]
    inertia = next(f for f in polygon.forces if f.kind is ForceKind.INERTIA)
    assert inertia.magnitude == 0.0 and math.isnan(inertia.direction)


def test_bodies_it_cannot_draw_are_refused():
    """The ground, an unknown body, a scene without forces: SceneError naming what is wrong."""
    scene = forces_scene('four_bar_masses')
    state = mk.solve(scene, 1.0)
    with pytest.raises(mk.SceneError, match=r'moving body .*\(crank, coupler, rocker\), got the '
                                            r'ground'):
        force_polygon_from_state(scene, state, 'ground')
    with pytest.raises(mk.SceneError, match='got "link9"'):
        force_polygon_from_state(scene, state, 'link9')
    plain = mk.load_scene('khurmi_four_bar_ad150')
    with pytest.raises(mk.SceneError, match='masses, gravity or loads'):
        force_polygon_from_state(plain, mk.solve(plain, 1.0), 'coupler')
