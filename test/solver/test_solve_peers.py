# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Correctness where the peer packages fail (issue 2, "Correctness where the peers fail").

* pylinkage 1.3.0 drops half of the Coriolis term ``2 * omega * v_slip`` for a
  slider on a rotating guide. Here the slotted lever (RPR) is checked against
  a 50-digit finite difference of an independent position formula.
* ``mechanism`` returns loops that do not close, with only a warning, on a
  linkage that cannot assemble over part of its cycle. Here a non-Grashof
  four-bar (and a slider-crank and a quick return whose guides go out of
  reach) are solved over a full cycle: every angle that cannot assemble is
  reported, and every other angle closes.
"""

from __future__ import annotations

import math
import re

import mpmath
import numpy as np
import pytest

import mech_kinematics as mk

#: Working precision of the reference, decimal digits.
DIGITS = 50
#: Time steps of the reference central differences, s, at DIGITS digits:
#: (f(t+h) - f(t-h)) / 2h has truncation ~h^2 f''' ~ 1e-40 and rounding
#: ~1e-50 / h = 1e-30; (f(t+h) - 2 f(t) + f(t-h)) / h^2 with h = 1e-15 has
#: truncation ~1e-30 and rounding ~1e-50 / h^2 = 1e-20. Both far below double
#: precision, so the reference is exact to the last bit of a double.
H_FIRST = mpmath.mpf('1e-20')
H_SECOND = mpmath.mpf('1e-15')
#: Double-precision solver against the exact reference, relative to
#: ``|reference| + typical`` (typical: omega^2 for rad/s^2, crank * omega^2
#: for m/s^2 and so on).
RTOL_REFERENCE = 1e-12
#: A half-Coriolis formula must miss by at least this many tolerances.
HALF_CORIOLIS_MARGIN = 1e6
#: Loop closure over a cycle, m per m of mechanism size.
RTOL_CLOSURE = 1e-12

# --- the slotted lever against a 50-digit reference -------------------------------

#: (name, pivot O, crank centre A, crank length, lever point distance), m:
#: Khurmi & Gupta Ex. 8.10 (config/scenes/quick_return: OA = 400, AB = 150,
#: OC = 700 mm) and a Whitworth (crank longer than the centre distance).
LEVERS = {
    'crank_and_slotted_lever': ((0.0, 0.0), (0.0, 0.4), 0.15, 0.7),
    'whitworth': ((0.0, 0.0), (0.05, 0.1), 0.3, 0.45),
}
#: Crank angles (deg), speed (rad/s) and acceleration (rad/s^2) of each check:
#: away from the dead centres, where omega * v_slip vanishes.
MOTIONS = [(20.0, 4 * math.pi, 0.0), (75.0, 4 * math.pi, 9.0), (130.0, -7.0, -30.0),
           (200.0, 12.0, 50.0), (290.0, -4 * math.pi, 2.5)]


def lever_scene(name):
    pivot, centre, crank, carried = LEVERS[name]
    return mk.Scene(
        name=name, ground={'O': pivot, 'A': centre},
        input=mk.Crank('crank', 'A', 'B', crank, 0.0),
        dyads=(mk.RPR('lever', 'O', 'B', 'block'),),
        points=(mk.CarriedPoint('C', 'lever', 'O', 'B', (carried, 0.0)),))


def lever_reference(name, angle, speed, accel):
    """Return exact (phi, phi', phi'', s, s', s'', C'', as mpf) at t = 0 by 50-digit FD.

    Independent of the solver: the pin B is on the crank, the lever angle is
    atan2 of B - O and the slider coordinate is |B - O|, with the crank angle
    theta(t) = angle + speed * t + accel * t^2 / 2.
    """
    pivot, centre, crank, carried = LEVERS[name]
    mp = mpmath.mp
    with mpmath.workdps(DIGITS):
        ox, oy = (mp.mpf(v) for v in pivot)
        ax, ay = (mp.mpf(v) for v in centre)
        a, length = mp.mpf(crank), mp.mpf(carried)
        theta0, w0, al = mp.mpf(angle), mp.mpf(speed), mp.mpf(accel)

        def pin(t):
            theta = theta0 + w0 * t + al * t * t / 2
            return ax + a * mp.cos(theta) - ox, ay + a * mp.sin(theta) - oy

        def phi(t):
            x, y = pin(t)
            return mp.atan2(y, x)

        def s(t):
            x, y = pin(t)
            return mp.sqrt(x * x + y * y)

        def point_c(t):
            return length * mp.cos(phi(t)), length * mp.sin(phi(t))

        def first(f):
            return (f(H_FIRST) - f(-H_FIRST)) / (2 * H_FIRST)

        def second(f):
            return (f(H_SECOND) - 2 * f(0) + f(-H_SECOND)) / H_SECOND ** 2

        c_acc = tuple(second(lambda t, i=i: point_c(t)[i]) for i in (0, 1))
        return (phi(0), first(phi), second(phi), s(0), first(s), second(s), c_acc)


def assert_close(got, exact, typical, what):
    error = abs(mpmath.mpf(got) - exact)
    bound = RTOL_REFERENCE * (abs(exact) + typical)
    assert error <= bound, f'{what}: got {got!r}, exact {mpmath.nstr(exact, 20)}'


@pytest.mark.parametrize('name', sorted(LEVERS))
@pytest.mark.parametrize(('angle_deg', 'speed', 'accel'), MOTIONS)
def test_slotted_lever_has_the_full_coriolis_term(name, angle_deg, speed, accel):
    """The lever's alpha and the block's s'' match a 50-digit FD, Coriolis 2 omega s' in full.

    pylinkage 1.3.0 drops half of the Coriolis term here; the error a
    half-Coriolis formula would make is asserted to be far above the tolerance.
    """
    scene = lever_scene(name)
    angle = math.radians(angle_deg)
    state = mk.solve(scene, angle, speed, accel)
    phi, omega, alpha, s, sd, sdd, c_acc = lever_reference(name, angle, speed, accel)
    crank = scene.input.length
    w2 = speed * speed + abs(accel)  # rad/s^2, the typical angular acceleration
    lever, block = state.joints['lever'], state.joints['block']
    assert lever.type == 'revolute' and block.type == 'prismatic'
    assert_close(lever.position, phi, math.pi, 'lever angle')
    assert_close(lever.velocity, omega, abs(speed), 'lever omega')
    assert_close(lever.acceleration, alpha, w2, 'lever alpha')
    assert_close(block.position, s, crank, 'block s')
    assert_close(block.velocity, sd, crank * abs(speed), "block s'")
    assert_close(block.acceleration, sdd, crank * w2, "block s''")
    for axis in (0, 1):
        assert_close(state.points['C'].acceleration[axis], c_acc[axis],
                     LEVERS[name][3] * w2, f'C acceleration[{axis}]')
    # A formula with half the Coriolis term, alpha = (a_t - omega * s') / s, misses by
    # omega * s' / s: assert the test above would catch it by a wide margin.
    half_coriolis_error = abs(omega * sd / s)
    assert half_coriolis_error > HALF_CORIOLIS_MARGIN * RTOL_REFERENCE * (abs(alpha) + w2)


# --- a linkage that cannot assemble over part of its cycle ---------------------------

CYCLE = 2 * np.pi * np.arange(3600) / 3600
#: Four-bars (ground d, crank a, coupler b, rocker c), m, that cannot assemble
#: over part of the crank's cycle.
FOUR_BARS = {
    # Non-Grashof: s + l = 0.5 + 1.0 > p + q = 0.6 + 0.7; |BD| > b + c near 180 deg.
    'non_grashof': (1.0, 0.6, 0.5, 0.7),
    # Grashof with the coupler shortest (a double rocker): the crank meets both limits,
    # |BD| < |b - c| near 0 deg and |BD| > b + c near 180 deg.
    'double_rocker': (1.0, 0.8, 0.3, 0.9),
}


def four_bar(name):
    d, a, b, c = FOUR_BARS[name]
    return mk.Scene(
        name=name, ground={'A': (0.0, 0.0), 'D': (d, 0.0)},
        input=mk.Crank('crank', 'A', 'B', a, math.pi / 3),
        dyads=(mk.RRR('C', (mk.Link('coupler', 'B', b), mk.Link('rocker', 'D', c)), 1),))


def values_of(state):
    """Every output value of an array state, as 1-D or 2-D arrays."""
    for point in state.points.values():
        yield from (point.position, point.velocity, point.acceleration)
    for joint in state.joints.values():
        yield from (joint.position, joint.velocity, joint.acceleration)


def test_four_bars_cannot_assemble_over_part_of_the_cycle():
    """The test four-bars are what they claim: non-Grashof / both limits, partly unassemblable."""
    shortest, *middle, longest = sorted(FOUR_BARS['non_grashof'])
    assert shortest + longest > sum(middle)
    for name, (d, a, b, c) in FOUR_BARS.items():
        bd = np.abs(d - a * np.exp(1j * CYCLE))
        outside = (bd <= abs(b - c)) | (bd >= b + c)
        assert 0 < outside.sum() < CYCLE.size, name
    d, a, b, c = FOUR_BARS['double_rocker']
    bd = np.abs(d - a * np.exp(1j * CYCLE))
    assert (bd < abs(b - c)).any() and (bd > b + c).any()


@pytest.mark.parametrize('name', sorted(FOUR_BARS))
def test_non_grashof_cycle_reports_every_unassemblable_angle(name):
    """Over 3600 angles, valid == (|b - c| < |BD| < b + c); the rest close their loops."""
    d, a, b, c = FOUR_BARS[name]
    state = mk.solve(four_bar(name), CYCLE, 3.0, -2.0)
    # Independent criterion: the circles about B (radius b) and D (radius c) meet.
    bd = np.abs(d - a * np.exp(1j * CYCLE))
    assert np.min(np.abs(bd - (b + c))) > 1e-9 and np.min(np.abs(bd - abs(b - c))) > 1e-9
    expected = (abs(b - c) < bd) & (bd < b + c)
    assert state.valid.dtype == bool and state.valid.shape == CYCLE.shape
    np.testing.assert_array_equal(state.valid, expected)
    assert list(state.failures) == ['RRR C']
    np.testing.assert_array_equal(state.failures['RRR C'], ~expected)
    for value in values_of(state):
        assert np.all(np.isfinite(value[state.valid]))
    pb, pc = state.points['B'].position, state.points['C'].position
    pd = np.array([d, 0.0])
    valid = state.valid
    size = max(d, a, b, c)
    assert np.max(np.abs(np.hypot(*(pc - pb)[valid].T) - b)) <= RTOL_CLOSURE * size
    assert np.max(np.abs(np.hypot(*(pc - pd)[valid].T) - c)) <= RTOL_CLOSURE * size
    assert np.max(np.abs(np.hypot(*pb[valid].T) - a)) <= RTOL_CLOSURE * size


@pytest.mark.parametrize('name', sorted(FOUR_BARS))
def test_scalar_solve_raises_assembly_error_naming_dyad_point_and_angle(name):
    """At an unassemblable angle a scalar solve raises AssemblyError naming dyad, point, angle."""
    d, a, b, c = FOUR_BARS[name]
    angle = math.pi  # B farthest from D: |BD| = d + a > b + c for both four-bars
    assert d + a > b + c
    with pytest.raises(mk.AssemblyError, match=re.escape(f'crank angle {angle:.6g} rad')) as info:
        mk.solve(four_bar(name), angle)
    message = str(info.value)
    assert 'RRR C' in message  # the dyad and its point
    assert 'B' in message and 'D' in message and 'do not meet' in message
    assert info.value.dyad == 'RRR C'
    assert info.value.angle == angle
    assert '\n' not in message


def test_slider_crank_reports_guide_out_of_reach():
    """An offset slider-crank whose guide leaves the rod's reach is masked there, never NaN."""
    a, rod, offset = 1.0, 0.8, 0.5
    scene = mk.Scene(
        name='short_rod', ground={'A': (0.0, 0.0), 'G': (0.0, offset)},
        input=mk.Crank('crank', 'A', 'B', a, math.pi / 2),
        dyads=(mk.RRP('P', mk.Link('rod', 'B', rod), 'G', 0.0, 'piston', 1),))
    state = mk.solve(scene, CYCLE, 2.0, 1.0)
    reach = np.abs(a * np.sin(CYCLE) - offset)  # distance of B from the guide
    assert np.min(np.abs(reach - rod)) > 1e-9
    expected = reach < rod
    np.testing.assert_array_equal(state.valid, expected)
    assert list(state.failures) == ['RRP P']
    np.testing.assert_array_equal(state.failures['RRP P'], ~expected)
    for value in values_of(state):
        assert np.all(np.isfinite(value[state.valid]))
    p, b = state.points['P'].position[expected], state.points['B'].position[expected]
    assert np.max(np.abs(p[:, 1] - offset)) <= RTOL_CLOSURE * a
    assert np.max(np.abs(np.hypot(*(p - b).T) - rod)) <= RTOL_CLOSURE * a
    with pytest.raises(mk.AssemblyError, match=r'RRP P .*out of reach'):
        mk.solve(scene, -math.pi / 2)


def test_quick_return_ram_out_of_reach_names_the_ram_dyad():
    """When only the ram's guide goes out of reach, failures names the ram dyad alone."""
    pivot, centre, crank, carried = LEVERS['crank_and_slotted_lever']
    rod, height = 0.16, 0.52  # out of reach while the lever is within 13.7 deg of vertical
    scene = mk.Scene(
        name='ram_out_of_reach', ground={'O': pivot, 'A': centre, 'E': (0.0, height)},
        input=mk.Crank('crank', 'A', 'B', crank, 0.0),
        dyads=(mk.RPR('lever', 'O', 'B', 'block'),
               mk.RRP('D', mk.Link('link_CD', 'C', rod), 'E', 0.0, 'ram', -1)),
        points=(mk.CarriedPoint('C', 'lever', 'O', 'B', (carried, 0.0)),))
    state = mk.solve(scene, CYCLE, 4 * math.pi, 0.0)
    pin = centre[0] + crank * np.cos(CYCLE) + 1j * (centre[1] + crank * np.sin(CYCLE))
    point_c = carried * pin / np.abs(pin)
    expected = np.abs(point_c.imag - height) < rod
    assert np.min(np.abs(np.abs(point_c.imag - height) - rod)) > 1e-9
    assert 0 < expected.sum() < CYCLE.size
    np.testing.assert_array_equal(state.valid, expected)
    assert list(state.failures) == ['RRP D']
    for value in values_of(state):
        assert np.all(np.isfinite(value[state.valid]))
    # The lever and block are still solved everywhere, but reported with the mask.
    c = state.points['C'].position[expected]
    np.testing.assert_allclose(c[:, 0] + 1j * c[:, 1], point_c[expected], rtol=0,
                               atol=RTOL_CLOSURE * carried)
