# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Forces at a Geneva wheel's mouths follow the side the kinematics answer (issue 43, item 6).

At an engagement instant (the pin entering or leaving a slot) the
kinematics answer the side after the jump in the crank's sense: turning
CCW, the pin enters at 135 deg (the slot drives the wheel after) and leaves
at 225 deg (the lock holds it after); turning CW the other way round. The
forces are those of that side (``Engagement.driven``), the other side's in
``jumps['forces']``. Checked against a hand statics of the wheel (moments
about its centre S: the slot's normal force at the pin, the lock's moment,
the brake, the wheel's inertia) and a power balance of the driver (the
wheel is at rest at a mouth on both sides, so the effort is the driver's
own), never by the solver's formulas.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.solver.forces import Load, Mass

OMEGA = 10.0            # rad/s, the packaged wheel's crank speed
SLOTS = 4
JUMP = OMEGA ** 2 * math.tan(math.pi / SLOTS)   # the engaged side's |alpha| at a mouth
INERTIA, BRAKE = 0.01, 0.3      # the wheel's kg m^2 and the brake's N m on it
DRIVER_MASS, DRIVER_COM = 1.0, 0.02     # kg, m along the crank from D
WHEEL_MASS = 2.0
G = -9.81
#: The mouths: (crank angle, deg; the engaged side's wheel acceleration, rad/s^2).
MOUTHS = {'entry': (135.0, -JUMP), 'exit': (225.0, JUMP)}


@pytest.fixture(scope='module')
def scene():
    """Return the packaged Geneva wheel with masses, gravity and a brake on the wheel."""
    return dataclasses.replace(
        mk.load_scene('geneva'),
        masses=(Mass('driver', DRIVER_MASS, (DRIVER_COM, 0.0)),
                Mass('wheel', WHEEL_MASS, (0.0, 0.0), INERTIA)),
        loads=(Load('brake', link='wheel', torque=BRAKE),), gravity=(0.0, G))


def engaged_after(mouth, speed):
    """Return whether the slot drives the wheel on the side after the mouth, turning ``speed``."""
    return (mouth == 'entry') == (speed > 0.0)


def hand_statics(state, driven, alpha):
    """Return the forces of one side by hand: the wheel's moments about S, the bodies' forces.

    The pin's block is massless: the wheel pushes it with ``N i u`` (``u`` the
    slot's direction, S to P) and the driver holds it with the opposite. On
    the wheel, about S: ``I alpha = M_lock - N |SP| + brake``; the slot acts
    (lock 0) or the lock does (N 0). The effort from the driver's power:
    the wheel does not move at a mouth, so ``effort omega = m (a_c - g) . v_c``.
    """
    p, s = state.complex_points['P'][0], state.complex_points['S'][0]
    arm = abs(p - s)
    u = (p - s) / arm
    if driven:
        lock, normal = 0.0, (BRAKE - INERTIA * alpha) / arm
    else:
        lock, normal = -BRAKE, 0.0
    on_block = normal * 1j * u
    g = complex(0.0, G)
    phi, omega = float(state.angle), float(state.speed)
    r_c = DRIVER_COM * complex(math.cos(phi), math.sin(phi))
    v_c, a_c = 1j * omega * r_c, -omega * omega * r_c
    inertia = DRIVER_MASS * (a_c - g)
    effort = (inertia.real * v_c.real + inertia.imag * v_c.imag) / omega
    pivot_s = on_block - WHEEL_MASS * g
    pivot_d = inertia - on_block        # the driver: F_D + N i u + m g = m a_c
    return {'lock': lock, 'normal': normal, 'P': -on_block, 'S': pivot_s, 'D': pivot_d,
            'effort': effort, 'shaking': -(pivot_s + pivot_d)}


def assert_side(forces, expected, scale=30.0):
    """Assert one side's forces equal the hand statics to 1e-12 of the force scale (N)."""
    tol = 1e-12 * scale
    reactions = forces.reactions
    assert reactions['wheel/lock'].moment == pytest.approx(expected['lock'], abs=tol)
    assert reactions['pin_slot'].normal == pytest.approx(expected['normal'], abs=tol)
    assert reactions['pin_slot'].moment == pytest.approx(0.0, abs=tol)
    for name in ('P', 'S'):
        assert abs(reactions[name].force - expected[name]) <= tol, name
    assert abs(reactions['driver'].force - expected['D']) <= tol
    assert forces.efforts['driver'] == pytest.approx(expected['effort'], abs=tol * 0.05)
    assert abs(forces.shaking_force - expected['shaking']) <= tol
    # The joint out of action carries exactly nothing: the lock, or the slot.
    if expected['lock'] == 0.0:
        assert reactions['wheel/lock'].moment == 0.0
    else:
        assert reactions['pin_slot'].normal == 0.0 and reactions['P'].force == 0j


@pytest.mark.parametrize('speed', [OMEGA, -OMEGA])
@pytest.mark.parametrize('mouth', list(MOUTHS))
def test_forces_at_a_mouth_are_the_kinematics_side_and_the_other_is_under_jumps(
        scene, mouth, speed):
    """At entry and exit, CCW and CW: the answered side's forces, the other in "jumps".

    Turning CCW the pin leaves at 225 deg with the wheel at rest after: the
    lock holds the brake's 0.3 N m and the pin pushes nothing; the "jumps"
    side is the pin's last push, N = (0.3 - I 100) / 50 mm = -14 N.
    """
    degrees, engaged_alpha = MOUTHS[mouth]
    state = mk.solve(scene, math.radians(degrees), speed)
    driven = engaged_after(mouth, speed)
    alpha, other_alpha = (engaged_alpha, 0.0) if driven else (0.0, engaged_alpha)
    # The kinematics' side, and the engagement's record of it.
    assert state.joints['wheel'].acceleration == pytest.approx(alpha, abs=1e-12)
    other_side = state.jumps['joints']['wheel']['acceleration']
    assert other_side == pytest.approx(other_alpha, abs=1e-12)
    engagement = state.intermittent['wheel']
    assert engagement.engaged is True and engagement.driven is driven
    assert_side(state.forces, hand_statics(state, driven, alpha))
    other = state.jumps['forces']
    assert other.valid is True
    assert_side(other, hand_statics(state, not driven, other_alpha))
    # The figures of the exit turning CCW (the docs' example).
    if mouth == 'exit' and speed > 0.0:
        assert state.forces.reactions['wheel/lock'].moment == pytest.approx(-0.3, rel=1e-14)
        assert other.reactions['pin_slot'].normal == pytest.approx(-14.0, rel=1e-12)
    # JSON: the other side's efforts, reactions and shaking beside the joints' and points'.
    data = state.as_dict()
    jumps = data['jumps']
    assert set(jumps) == {'joints', 'points', 'efforts', 'reactions', 'shaking'}
    assert jumps['reactions'] == other.as_dict(False)['reactions']
    assert jumps['efforts'] == {'driver': other.efforts['driver']}
    assert data['reactions']['wheel/lock']['moment'] == state.forces.reactions[
        'wheel/lock'].moment
    # The other side's bounds are those of its own solve, small.
    assert max(other.bound_dict(False)['reactions']['pin_slot'].values()) <= 1e-12


def test_away_from_the_mouths_no_forces_jump(scene):
    """Inside a window and in a dwell nothing jumps: no "jumps", the side is the engagement."""
    for degrees, driven in ((150.0, True), (300.0, False), (134.9, False), (225.1, False)):
        state = mk.solve(scene, math.radians(degrees))
        assert state.jumps == {} and 'jumps' not in state.as_dict()
        assert state.intermittent['wheel'].driven is driven
        assert (state.forces.reactions['wheel/lock'].moment == 0.0) is driven


def _forces_values(forces, index=None):
    """Return every value of a Forces (one instant, or ``index`` of an array) as floats."""
    def at(x):
        return x if index is None else x[index]

    values = [at(forces.efforts['driver']), at(forces.shaking_force),
              at(forces.shaking_moment)]
    for r in forces.reactions.values():
        values += [at(x) for x in (r.force, r.normal, r.moment) if x is not None]
    return [complex(x) for x in values]


@pytest.mark.parametrize('speed', [OMEGA, -OMEGA])
def test_an_arrays_forces_at_the_mouths_are_the_single_instants(scene, speed):
    """Over an array the mouths' forces, both sides, are those of single solves; NaN elsewhere."""
    degrees = np.array([135.0, 225.0, 150.0, 300.0, 135.0, 225.0])
    turns = np.array([0, 0, 0, 0, 3, 3])
    vector = mk.solve(scene, np.radians(degrees), speed, turns=turns)
    assert vector.valid.all()
    other = vector.jumps['forces']
    mouth = np.array([True, True, False, False, True, True])
    np.testing.assert_array_equal(other.valid, mouth)
    np.testing.assert_array_equal(vector.intermittent['wheel'].driven,
                                  [speed > 0, speed < 0, True, False, speed > 0, speed < 0])
    for index, (deg, k) in enumerate(zip(degrees, turns, strict=True)):
        single = mk.solve(scene, math.radians(deg), speed, turns=int(k))
        np.testing.assert_allclose(_forces_values(vector.forces, index),
                                   _forces_values(single.forces), rtol=0, atol=1e-13)
        if mouth[index]:
            np.testing.assert_allclose(_forces_values(other, index),
                                       _forces_values(single.jumps['forces']), rtol=0,
                                       atol=1e-13)
        else:
            assert np.isnan(_forces_values(other, index)).all()
    data = vector.as_dict()['jumps']
    assert data['reactions']['wheel/lock']['moment'].shape == (6,)
    assert data['reactions']['P']['force'].shape == (6, 2)


@pytest.mark.parametrize('speed', [OMEGA, -OMEGA])
def test_a_sweep_of_twenty_mouths_never_mixes_sides(scene, speed):
    """Ten turns' entries and exits (20 instants): forces and kinematics on one side at each.

    Before, the forces took the engaged side at every mouth: 10 of these 20
    instants in either sense had the pin pushing while the wheel was at rest
    and locked. The kinematics' side is read from the wheel's acceleration
    (the engaged side's is -+100 rad/s^2, the dwell's 0); the lock acts
    exactly where the wheel is held, the slot exactly where it is driven,
    and "jumps" the other way round.
    """
    turns = np.repeat(np.arange(10), 2)
    degrees = np.tile([135.0, 225.0], 10)
    state = mk.solve(scene, np.radians(degrees), speed, turns=turns)
    assert state.valid.all()
    driven = state.joints['wheel'].acceleration != 0.0
    np.testing.assert_allclose(np.abs(state.joints['wheel'].acceleration[driven]), JUMP,
                               rtol=1e-14)
    assert driven.sum() == 10
    for forces, side in ((state.forces, driven), (state.jumps['forces'], ~driven)):
        lock = forces.reactions['wheel/lock'].moment
        normal = forces.reactions['pin_slot'].normal
        np.testing.assert_array_equal(lock == 0.0, side)
        np.testing.assert_array_equal(normal == 0.0, ~side)
        np.testing.assert_allclose(lock[~side], -BRAKE, rtol=1e-14)
