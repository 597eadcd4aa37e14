# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Rubbing velocities at pins (``pins:``), as seed 001 defines them. See issue 11.

Seed 001 (a Q&A page on acceleration diagrams), "Relative Velocity and
Acceleration", *Rubbing Velocity*: for a pin B of radius r_b joining links 2
and 3, the rubbing velocity is ``r_b * omega_2/3``, the pin's radius times the
relative angular velocity of the two links. The hand calculations here use
that definition on the same notes' "Example-1" (piston, rod and crank: crank
AB 50 mm at 300 rad/s, rod BC 170 mm; the packaged ``piston_300`` scene, at
61 deg), with the slider-crank's closed form for the rod's angular velocity.
"""

from __future__ import annotations

import dataclasses
import json
import math

import mpmath
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.__main__ import main
from mech_kinematics.geometry import diagrams as geo
from mech_kinematics.verify import reference as ref

#: Closed-form hand values against the solver, relative.
RTOL_HAND = 1e-12

PISTON = """\
name: piston_pins
units: {length: mm, angle: deg}
ground: {A: [0, 0]}
input: {link: crank, center: A, point: B, length: 50, angle: 61, speed_rpm: 2864.7889756541163}
dyads:
  - type: RRP
    point: C
    link: {name: rod, from: B, length: 170}
    guide: {through: A, angle: 0}
    slider: piston
pins: {A: 12, B: 10, C: {radius: 8}}
"""


def load(tmp_path, text, name='scene.yaml'):
    """Write ``text`` to a scene file and load it."""
    path = tmp_path / name
    path.write_text(text)
    return mk.load_scene(path)


def hand_rod_omega(theta, omega=300.0, a=0.05, length=0.17):
    """Return the rod's angular velocity of an in-line slider-crank (rad/s), by hand.

    sin(phi) = -a sin(theta) / l for the rod's angle phi (piston on +x), so
    omega_rod = d(phi)/dt = -a omega cos(theta) / (l cos(phi)).
    """
    phi = math.asin(-a * math.sin(theta) / length)
    return -a * omega * math.cos(theta) / (length * math.cos(phi))


def test_piston_example_by_hand(tmp_path):
    """Seed 001 Example-1 at 61 deg: A 300 r_A, B |300 - omega_BC| r_B, C |omega_BC| r_C."""
    scene = load(tmp_path, PISTON)
    state = mk.solve(scene, math.radians(61.0))
    omega_bc = hand_rod_omega(math.radians(61.0))
    assert omega_bc == pytest.approx(-44.27, abs=0.01)  # CW while the crank turns CCW
    expected = {'A': 300.0 * 0.012, 'B': abs(300.0 - omega_bc) * 0.010,
                'C': abs(omega_bc - 0.0) * 0.008}  # the piston block does not turn
    assert set(state.rubbing) == set(expected)
    for pin, value in expected.items():
        assert state.rubbing[pin] == pytest.approx(value, rel=RTOL_HAND), pin
    assert state.rubbing['B'] == pytest.approx(3.4427, abs=1e-4)  # 344.27 rad/s x 10 mm
    assert scene.pin_bodies == {'A': ('crank', 'ground'), 'B': ('crank', 'rod'),
                                'C': ('rod', 'piston')}


def test_rubbing_bounds_cover_the_exact_values(tmp_path):
    """|rubbing - exact| <= its bound, exact from the 50-digit reference's angular velocities."""
    scene = load(tmp_path, PISTON)
    radii = {'A': 0.012, 'B': 0.010, 'C': 0.008}
    for degrees in (0.5, 61.0, 100.0, 200.0, 300.0):
        theta = math.radians(degrees)
        state = mk.solve(scene, theta)
        exact = ref.reference(scene, theta)
        omega = {name: exact.joints[name][1] for name in ('crank', 'rod')}
        with mpmath.workdps(60):
            truth = {'A': abs(omega['crank']) * mpmath.mpf(radii['A']),
                     'B': abs(omega['crank'] - omega['rod']) * mpmath.mpf(radii['B']),
                     'C': abs(omega['rod']) * mpmath.mpf(radii['C'])}
        for pin, value in truth.items():
            error = abs(state.rubbing[pin] - float(value))
            assert error <= state.error_bound.rubbing[pin], (degrees, pin)
            assert 0.0 < state.error_bound.rubbing[pin] < 1e-13


def test_array_path_gives_the_same_bits(tmp_path):
    """Over a cycle the array path's rubbing values and bounds are the single-angle ones."""
    scene = load(tmp_path, PISTON)
    theta = np.linspace(0.0, 2 * np.pi, 37)
    vector = mk.solve(scene, theta)
    for index, angle in enumerate(theta):
        single = mk.solve(scene, float(angle))
        for pin, value in single.rubbing.items():
            assert vector.rubbing[pin][index] == value
            assert vector.error_bound.rubbing[pin][index] == single.error_bound.rubbing[pin]


def test_json_carries_rubbing_and_its_bound(tmp_path, capsys):
    """`solve` prints "rubbing": {POINT: m/s} and "error_bound"."rubbing" beside joints, points."""
    path = tmp_path / 'piston.yaml'
    path.write_text(PISTON)
    assert main(['solve', str(path), '--angle-deg', '61']) == 0
    data = json.loads(capsys.readouterr().out)
    assert list(data['rubbing']) == ['A', 'B', 'C']
    assert data['rubbing']['B'] == pytest.approx(abs(300.0 - hand_rod_omega(
        math.radians(61.0))) * 0.010, rel=RTOL_HAND)
    assert set(data['error_bound']) == {'joints', 'points', 'rubbing'}
    assert all(0.0 < b < 1e-12 for b in data['error_bound']['rubbing'].values())
    # A scene without pins has neither key (the contract's shape is unchanged).
    assert main(['solve', 'khurmi_four_bar_ad150']) == 0
    data = json.loads(capsys.readouterr().out)
    assert 'rubbing' not in data and set(data['error_bound']) == {'joints', 'points'}


def test_slotted_lever_pin_rubs_at_the_relative_speed():
    """The quick return's pin B turns in a block turning with the lever: |w_crank - w_lever| r."""
    base = mk.load_scene('quick_return')
    scene = dataclasses.replace(base, pins=(mk.Pin('B', 0.01), mk.Pin('O', 0.02)))
    state = mk.solve(scene, 0.7)
    omega = {name: state.joints[name].velocity for name in ('crank', 'lever')}
    assert state.rubbing['B'] == pytest.approx(abs(omega['crank'] - omega['lever']) * 0.01,
                                               rel=1e-15)
    assert state.rubbing['O'] == pytest.approx(abs(omega['lever']) * 0.02, rel=1e-15)
    assert scene.pin_bodies['B'] == ('crank', 'block')


def test_geneva_pin_rubs_only_while_in_a_slot():
    """The Geneva pin rubs at |w_driver - w_wheel| r while engaged, exactly 0 in a dwell."""
    base = mk.load_scene('geneva')
    scene = dataclasses.replace(base, pins=(mk.Pin('P', 0.004),))
    engaged, locked = mk.solve(scene, math.radians(150.0)), mk.solve(scene, math.radians(300.0))
    assert engaged.rubbing['P'] == pytest.approx((10.0 + 4.082482904638631) * 0.004, rel=1e-14)
    assert locked.rubbing['P'] == 0.0 and locked.error_bound.rubbing['P'] == 0.0


def test_geneva_pin_rubs_at_a_mouth_on_the_side_the_kinematics_answer():
    """At 135 and 225 deg, both senses: the rubbing follows ``driven``, the other side in jumps.

    At a mouth the wheel is at rest on both sides, so the pin rubs at
    ``|w_driver| r`` where it is in the slot and 0 where the lock holds; the
    side answered is the kinematics' (``intermittent['wheel'].driven``).
    """
    base = mk.load_scene('geneva')
    scene = dataclasses.replace(base, pins=(mk.Pin('P', 0.004),))
    seen = set()
    for degrees in (135.0, 225.0):
        for omega in (10.0, -10.0):
            state = mk.solve(scene, math.radians(degrees), omega)
            driven = bool(state.intermittent['wheel'].driven)
            seen.add(driven)
            in_slot = abs(omega) * 0.004
            assert state.rubbing['P'] == pytest.approx(in_slot if driven else 0.0, abs=1e-15)
            assert state.jumps['rubbing']['P'] == pytest.approx(0.0 if driven else in_slot,
                                                                abs=1e-15)
            assert state.as_dict()['jumps']['rubbing']['P'] == state.jumps['rubbing']['P']
            angles = np.radians([degrees, 150.0, degrees])
            array = mk.solve(scene, angles, omega)
            assert array.rubbing['P'][0] == state.rubbing['P']
            assert array.jumps['rubbing']['P'][2] == state.jumps['rubbing']['P']
            assert math.isnan(array.jumps['rubbing']['P'][1])
    assert seen == {True, False}


def test_diagram_table_lists_the_pins(tmp_path):
    """The space table has a row per pin: bodies, radius, relative angular speed, rubbing."""
    scene = load(tmp_path, PISTON)
    diagram = geo.diagram_from_scene(scene, 61.0, degrees=True)
    rows = {row[0]: row for row in geo.tables_from_diagram(diagram)['space'].rows}
    assert rows['pin B'][1:3] == ('crank/rod', 'r = 0.01')
    assert rows['pin B'][5] == f'rubbing {geo.fmt_value(diagram.pins[1].rubbing)} m/s'
    assert diagram.pins[1].rubbing == pytest.approx(3.4427, abs=1e-4)


COMPOUND = """\
name: compound
units: {length: mm, angle: deg}
ground: {A: [0, 0], D: [150, 0], F: [300, 100]}
input: {link: crank, center: A, point: B, length: 40, angle: 60, speed_rpm: -120}
dyads:
  - type: RRR
    point: C
    links:
      - {name: coupler, from: B, length: 150}
      - {name: rocker, from: D, length: 80}
  - type: RRR
    point: E
    links:
      - {name: link_CE, from: C, length: 120}
      - {name: link_FE, from: F, length: 100}
"""


def test_a_compound_pin_names_its_two_bodies(tmp_path):
    """Three links at C: refused naming them, accepted with `between`. See issue 11."""
    with pytest.raises(mk.SceneError, match=(
            r'pins\.C\.between: Expected pin "C" to join two bodies, got 3 at C \(coupler, '
            r'rocker, link_CE\): name the two it joins, e\.g\. C: \{radius: R, between: '
            r'\[coupler, rocker\]\}')):
        load(tmp_path, COMPOUND + 'pins: {C: 5}\n')
    scene = load(tmp_path, COMPOUND + 'pins: {C: {radius: 5, between: [rocker, link_CE]}}\n')
    state = mk.solve(scene, scene.input.angle)
    assert state.rubbing['C'] == pytest.approx(abs(
        state.joints['rocker'].velocity - state.joints['link_CE'].velocity) * 0.005, rel=1e-15)


@pytest.mark.parametrize(('pins', 'message'), [
    ('{Q: 5}', r'pins\.Q: Expected pins to name points, got unknown "Q"'),
    ('{rocker: 5}', r'pins\.rocker: Expected pins to name points, got link "rocker"'),
    ('{G: 5}\npoints: {G: {link: coupler, from: B, toward: C, distance: 30}}',
     r'pins\.G: Expected pin "G" where two bodies turn on each other, got only coupler at G'),
    ('{C: -5}', r'pins\.C: expected a positive length, got -5'),
    ('{C: {radius: 5, between: [coupler, crank]}}',
     r'pins\.C\.between: Expected the bodies of pin "C" to be among those at C \(coupler, '
     r'rocker, link_CE\), got "crank"'),
    ('{C: {radius: 5, between: [coupler]}}', r'pins\.C\.between: expected the names of the two'),
    ('{C: {radius: 5, at: coupler}}', r"pins\.C: unknown key\(s\) \['at'\]"),
    ('[C]', r'pins: expected a mapping of point names to radii, got list'),
])
def test_bad_pins_are_refused_in_one_line(tmp_path, pins, message):
    """An unknown point, a point with one body, a bad radius or pair: one SceneError line."""
    with pytest.raises(mk.SceneError, match=message):
        load(tmp_path, COMPOUND + f'pins: {pins}\n')
