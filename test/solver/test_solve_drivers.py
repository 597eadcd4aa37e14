# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Several drivers and linear actuators (issue 18): scene keys, solve, refusals, bounds.

The scenes here are written inline: a five-bar (two cranks) and a cylinder
lifting a boom (one actuator on an RRR link), small enough to check by hand.
"""

from __future__ import annotations

import math

from helpers import assert_bounded
from hypothesis import assume, given, settings
from hypothesis import strategies as st
import numpy as np
import pytest
import yaml

import mech_kinematics as mk
from mech_kinematics.scene import scene_text
from mech_kinematics.verify import reference as ref

pytestmark = pytest.mark.filterwarnings('ignore::mech_kinematics.NearSingularWarning')

FIVE_BAR = """\
name: five
units: {length: m, angle: deg}
ground: {A: [0, 0], E: [0.1, 0]}
inputs:
  - {link: left, center: A, point: B, length: 0.12, angle: 120, speed_rpm: 10}
  - {link: right, center: E, point: D, length: 0.12, angle: 60, speed_rpm: -10}
dyads:
  - type: RRR
    point: P
    links: [{name: ldist, from: B, length: 0.16}, {name: rdist, from: D, length: 0.16}]
    branch: 1
"""

BOOM = """\
name: boom
units: {length: mm, angle: deg}
ground: {O: [0, 0], F: [400, -1100]}
inputs:
  - {actuator: cyl, length: 2600, speed: 0.05, stroke: [2000, 3300]}
dyads:
  - type: RRR
    point: Q
    links: [{name: boom, from: O, length: 2600}, {name: body, from: F, actuator: cyl}]
    branch: 1
points:
  T: {link: boom, origin: O, xaxis: Q, local: [5680, 550]}
"""


def scene(text, **changes):
    """Return the scene of YAML ``text`` with top-level keys replaced by ``changes``."""
    data = yaml.safe_load(text)
    data.update(changes)
    return mk.parse_scene(data)


def test_inputs_list_drivers_in_order_with_their_facts():
    """inputs: gives Scene.drivers (name, joint type, start, speed, stroke) in file order."""
    five = scene(FIVE_BAR)
    assert [d.name for d in five.drivers] == ['left', 'right']
    assert [d.joint_type for d in five.drivers] == ['revolute', 'revolute']
    assert five.drivers[0].start == pytest.approx(math.radians(120), rel=1e-15)
    assert five.input is five.drivers[0]
    boom = scene(BOOM)
    (cyl,) = boom.drivers
    assert (cyl.name, cyl.joint_type, cyl.start, cyl.speed, cyl.stroke) == (
        'cyl', 'prismatic', 2.6, 0.05, (2.0, 3.3))
    assert boom.input is None
    assert boom.joint_types['cyl'] == 'prismatic'


def test_input_means_inputs_of_one_crank():
    """A 1-crank scene written with inputs: solves to the same bits as with input:."""
    data = yaml.safe_load(FIVE_BAR)
    one = mk.load_scene('khurmi_four_bar_ad150')
    text = scene_text('khurmi_four_bar_ad150')
    raw = yaml.safe_load(text)
    raw['inputs'] = [raw.pop('input')]
    listed = mk.parse_scene(raw)
    assert data  # the module's YAML parses
    for theta in (0.3, 1.0, 2.5):
        a, b = mk.solve(one, theta, 3.0, 1.0), mk.solve(listed, theta, 3.0, 1.0)
        for name in a.joints:
            assert a.joints[name].acceleration == b.joints[name].acceleration
        assert a.as_dict() == b.as_dict()


@pytest.mark.parametrize(('changes', 'match'), [
    ({'input': {'link': 'c', 'center': 'A', 'point': 'B', 'length': 1}},
     r'inputs: expected either input \(one crank\) or inputs'),
    ({'inputs': []}, r'inputs: expected a list of at least one driver'),
    ({'inputs': [{'center': 'A'}]},
     r'inputs\[0\]: expected a crank \(with link:\) or an actuator'),
    ({'inputs': [{'actuator': 'cyl', 'length': 2600, 'stroke': [2000]}]},
     r'inputs\[0\]\.stroke: expected \[shortest, longest\]'),
    ({'inputs': [{'actuator': 'cyl', 'length': 2600, 'stroke': [3000, 2000]}]},
     r'inputs\[0\]\.stroke: Expected the stroke of actuator "cyl"'),
    ({'inputs': [{'actuator': 'cyl', 'length': 3600, 'stroke': [2000, 3300]}]},
     r'inputs\[0\]\.length: Expected the length of actuator "cyl" at time zero within its '
     r'stroke'),
    ({'inputs': [{'actuator': 'cyl', 'length': 2600, 'rate': 1}]}, r"unknown key\(s\) \['rate'\]"),
    ({'inputs': [{'actuator': 'cyl', 'length': 2600}, {'actuator': 'O', 'length': 1}]},
     r'"O" twice'),
])
def test_bad_drivers_are_refused_in_one_line(changes, match):
    """Both input and inputs, an empty list, a bad stroke or a duplicate name: one SceneError."""
    with pytest.raises(mk.SceneError, match=match) as info:
        scene(BOOM, **changes)
    assert '\n' not in str(info.value)


def test_an_actuator_no_link_uses_is_refused():
    """An actuator must be the length of an RRR link: else one line saying so."""
    with pytest.raises(mk.SceneError, match=r'inputs\[1\]\.actuator: Expected actuator "ram" '
                       r'to be the length of an RRR link'):
        scene(BOOM, inputs=[{'actuator': 'cyl', 'length': 2600},
                            {'actuator': 'ram', 'length': 100}])


def test_an_unknown_actuator_is_refused():
    """An RRR link naming no actuator of inputs is refused, naming the known ones."""
    text = BOOM.replace('actuator: cyl}', 'actuator: ram}')
    with pytest.raises(mk.SceneError, match=r'dyads\[0\]\.links\[1\]\.actuator: expected the '
                       r"name of an actuator of inputs \(cyl\), got 'ram'"):
        scene(text)


def test_a_scene_that_cannot_assemble_names_the_drivers_start_positions():
    """The initial-assembly refusal says where every driver starts, in the scene's units."""
    text = FIVE_BAR.replace('length: 0.16}, {name: rdist, from: D, length: 0.16}',
                            'length: 0.06}, {name: rdist, from: D, length: 0.06}')
    with pytest.raises(mk.SceneError, match=r"at the drivers' start positions left = 120 deg, "
                       r'right = 60 deg, got links ldist'):
        scene(text)


def test_stroke_is_inclusive_and_refused_outside_naming_actuator_stroke_and_length():
    """A length at a stroke end is answered; beyond it, AssemblyError with a one-line reason."""
    boom = scene(BOOM)
    for length in (2.0, 3.3):
        assert mk.solve(boom, length).drivers['cyl'].position == length
    with pytest.raises(mk.AssemblyError, match=r'input cyl cannot be solved at cyl = 3\.30001 m: '
                       r'expected the length of actuator cyl within its stroke \[2, 3\.3\] m, '
                       r'got 3\.30001 m') as info:
        mk.solve(boom, 3.30001)
    assert mk.assembly_text(info.value, boom.units) == (
        'actuator cyl: expected a length within its stroke [2000 mm, 3300 mm], got 3300.01 mm')
    state = mk.solve(boom, np.array([1.9, 2.0, 3.3, 3.4]))
    np.testing.assert_array_equal(state.valid, [False, True, True, False])
    np.testing.assert_array_equal(state.failures['input cyl'], [True, False, False, True])


def test_boom_angle_is_the_law_of_cosines():
    """Golden: the boom's angle from the triangle O, F, Q of sides 2.6, |OF|, the cylinder."""
    boom = scene(BOOM)
    of = math.hypot(0.4, 1.1)
    for length in (2.0, 2.45, 3.3):
        gamma = math.acos((2.6**2 + of**2 - length**2) / (2 * 2.6 * of))
        expected = math.atan2(-1.1, 0.4) + gamma
        state = mk.solve(boom, length, 0.0, 0.0)
        assert state.joints['boom'].position == pytest.approx(expected, abs=1e-15)


def test_five_bar_end_effector_at_a_symmetric_pose():
    """Golden: cranks at 120 and 60 deg put P on the mirror line, sqrt(.16^2 - .11^2) above BD."""
    five = scene(FIVE_BAR)
    state = mk.solve(five, [math.radians(120), math.radians(60)], [0.0, 0.0], [0.0, 0.0])
    expected = (0.05, 0.12 * math.sin(math.radians(60)) + math.sqrt(0.16**2 - 0.11**2))
    np.testing.assert_allclose(state.points['P'].position, expected, rtol=0, atol=1e-16)
    # Mirrored speeds keep P on the mirror line: its x velocity is 0.
    state = mk.solve(five, [math.radians(120), math.radians(60)], [1.5, -1.5], [0.0, 0.0])
    assert state.points['P'].velocity[0] == pytest.approx(0.0, abs=1e-16)


def test_drivers_default_to_the_scene_and_are_reported_in_state_drivers():
    """None takes the scene's speeds; State.drivers holds each driver's motion as given."""
    five = scene(FIVE_BAR)
    state = mk.solve(five, [2.0, 1.0], turns=[1, 0])
    left, right = state.drivers['left'], state.drivers['right']
    assert (left.position, left.velocity) == (2.0 + math.tau, 10 * math.tau / 60)
    assert (right.position, right.velocity) == (1.0, -10 * math.tau / 60)
    data = state.as_dict()
    assert 'input' not in data
    assert data['inputs']['left'] == {'position': 2.0 + math.tau, 'speed': left.velocity,
                                      'accel': 0.0}


@pytest.mark.parametrize(('args', 'match'), [
    (([1.0],), r'Expected `positions` to hold 2 values'),
    ((1.0,), r'Expected `positions` to be a sequence of 2 values'),
    (([1.0, math.nan],), r'to be finite'),
    (([np.zeros(3), np.zeros(2)],), r'1-D arrays of one length'),
])
def test_bad_driver_values_are_refused(args, match):
    """One value per driver, finite, of one shape: else a ValueError saying what was expected."""
    with pytest.raises(ValueError, match=match):
        mk.solve(scene(FIVE_BAR), *args)


def test_array_path_gives_the_scalar_paths_bits():
    """Actuators' arrays give, entry by entry, the single-instant bits (values and bounds).

    Angles to an ulp: they are atan2 of the same bits (NumPy's and the math module's).
    """
    boom = scene(BOOM)
    rng = np.random.default_rng(18)
    lengths = rng.uniform(1.95, 3.35, 40)
    speeds = rng.uniform(-0.5, 0.5, 40)
    given = lengths.copy(), speeds.copy()
    many = mk.solve(boom, lengths, speeds, 0.25)
    np.testing.assert_array_equal(given, (lengths, speeds))  # the caller's arrays untouched
    joints, points = many.error_bound.raw()
    assert 30 < many.valid.sum() < 40
    for i, length in enumerate(lengths):
        if not many.valid[i]:
            with pytest.raises(mk.AssemblyError, match='stroke'):
                mk.solve(boom, length, speeds[i], 0.25)
            continue
        one = mk.solve(boom, length, speeds[i], 0.25)
        for name, joint in one.joints.items():
            got = many.joints[name]
            # An angle is atan2 of the same bits: NumPy's and the math module's within an ulp.
            assert abs(got.position[i] - joint.position) <= np.spacing(abs(joint.position))
            assert (got.velocity[i], got.acceleration[i]) == (
                joint.velocity, joint.acceleration), name
            assert tuple(b[i] for b in joints[name]) == one.error_bound.raw()[0][name]
        for name, (p, v, a) in one.complex_points.items():
            q = many.complex_points[name]
            assert (np.broadcast_to(q[0], lengths.shape)[i], q[1][i], q[2][i]) == (p, v, a)
            assert tuple(np.broadcast_to(b, lengths.shape)[i] for b in points[name]) == \
                one.error_bound.raw()[1][name]


def test_array_path_agrees_with_the_scalar_path_for_two_cranks():
    """Two cranks' arrays agree with single instants to 1e-14 (cos and sin may differ an ulp)."""
    five = scene(FIVE_BAR)
    rng = np.random.default_rng(18)
    left = rng.uniform(1.5, 2.5, 40)
    right = rng.uniform(0.7, 1.5, 40)
    speeds = [rng.uniform(-5, 5, 40), 2.0]
    accels = [1.0, rng.uniform(-5, 5, 40)]
    many = mk.solve(five, [left, right], speeds, accels)
    assert many.valid.sum() > 30
    for i in np.flatnonzero(many.valid):
        one = mk.solve(five, [left[i], right[i]], [speeds[0][i], 2.0], [1.0, accels[1][i]])
        for name, joint in one.joints.items():
            got = many.joints[name]
            np.testing.assert_allclose(
                (got.position[i], got.velocity[i], got.acceleration[i]),
                (joint.position, joint.velocity, joint.acceleration), rtol=1e-14, atol=1e-14)


def test_time_is_rescaled_for_every_driver_at_once():
    """At rates beyond 2**40 /s the answer is the exactly scaled one (powers of two)."""
    boom = scene(BOOM)
    slow = mk.solve(boom, 2.5, 0.25, 0.5)
    k = 2.0 ** 50
    fast = mk.solve(boom, 2.5, 0.25 * k, 0.5 * k * k)
    for name, joint in slow.joints.items():
        assert fast.joints[name].velocity == joint.velocity * k
        assert fast.joints[name].acceleration == joint.acceleration * k * k


# --- the packaged several-driver scenes: five_bar and excavator -----------------------

EPS = np.finfo(float).eps
#: Constraint closure: a few ulps of the mechanism's size (m).
RTOL_CLOSURE = 8 * EPS
#: Central differences in time with step H (s): error O(H^2) of the scale, well below this.
H = 1e-5
RTOL_DIFFERENCE = 1e-6
SETTINGS = settings(max_examples=40, deadline=None, derandomize=True)


def closure_residuals(scene, state):
    """Yield (link, |pin - start| - its length) of every RRR link, in m, and each crank's."""
    points = state.complex_points
    for driver in scene.drivers:
        if driver.joint_type == 'revolute':
            yield driver.name, abs(points[driver.point][0] - points[driver.center][0]) \
                - driver.length
    for dyad in scene.dyads:
        for link, actuator in zip(dyad.links, dyad.actuators, strict=True):
            length = link.length if actuator is None else state.drivers[actuator].position
            yield link.name, abs(points[dyad.point][0] - points[link.start][0]) - length


def motion_at(positions, speeds, accels, t):
    """Return every driver's position, speed and acceleration at time t (constant accel)."""
    return ([x + v * t + a * t * t / 2 for x, v, a in zip(positions, speeds, accels,
                                                          strict=True)],
            [v + a * t for v, a in zip(speeds, accels, strict=True)], list(accels))


five_bar_poses = st.tuples(st.floats(math.radians(60), math.radians(150)),
                           st.floats(math.radians(30), math.radians(120)),
                           st.floats(-6.0, 6.0), st.floats(-6.0, 6.0),
                           st.floats(-20.0, 20.0), st.floats(-20.0, 20.0))
excavator_poses = st.tuples(st.floats(2.01, 3.29), st.floats(2.51, 3.89),
                            st.floats(-0.3, 0.3), st.floats(-0.3, 0.3),
                            st.floats(-0.5, 0.5), st.floats(-0.5, 0.5))


def split(pose):
    """Return (positions, speeds, accels) of a two-driver pose."""
    return list(pose[:2]), list(pose[2:4]), list(pose[4:])


@pytest.mark.parametrize(('name', 'poses'), [('five_bar', five_bar_poses),
                                             ('excavator', excavator_poses)])
@given(data=st.data())
@SETTINGS
def test_constraints_close_and_rates_are_the_derivatives_of_positions(name, poses, data):
    """Both drivers moving at once: lengths closed to rounding, v and a = differences of p."""
    scene = mk.load_scene(name)
    positions, speeds, accels = split(data.draw(poses))
    try:
        states = [mk.solve(scene, *motion_at(positions, speeds, accels, t))
                  for t in (-H, 0.0, H)]
    except mk.AssemblyError:
        assume(False)
    before, now, after = states
    size = now.error_bound.size
    for link, residual in closure_residuals(scene, now):
        assert abs(residual) <= RTOL_CLOSURE * size, (link, residual)
    scales = now.scales
    # What the differences' own rounding can be: an ulp of a position (or velocity) over H.
    rounding = {'velocity': 4 * EPS * size / H,
                'acceleration': 4 * EPS * scales['velocity'] / H,
                'angular velocity': 4 * EPS * math.pi / H,
                'angular acceleration': 4 * EPS * scales['angular velocity'] / H}
    tol = {kind: RTOL_DIFFERENCE * scales[kind] + rounding[kind] for kind in rounding}
    for name_, (_, v, a) in now.complex_points.items():
        dp = (after.complex_points[name_][0] - before.complex_points[name_][0]) / (2 * H)
        dv = (after.complex_points[name_][1] - before.complex_points[name_][1]) / (2 * H)
        assert abs(dp - v) <= tol['velocity'], name_
        assert abs(dv - a) <= tol['acceleration'], name_
    for joint, motion in now.joints.items():
        angular = motion.type == 'revolute'
        dp = after.joints[joint].position - before.joints[joint].position
        if angular:
            dp = math.remainder(dp, math.tau)
        dv = after.joints[joint].velocity - before.joints[joint].velocity
        kinds = ('angular velocity', 'angular acceleration') if angular else (
            'velocity', 'acceleration')
        assert abs(dp / (2 * H) - motion.velocity) <= tol[kinds[0]], joint
        assert abs(dv / (2 * H) - motion.acceleration) <= tol[kinds[1]], joint


@pytest.mark.parametrize(('name', 'poses'), [('five_bar', five_bar_poses),
                                             ('excavator', excavator_poses)])
@given(data=st.data())
@settings(max_examples=15, deadline=None, derandomize=True)
def test_bounds_are_never_below_the_error_against_the_50_digit_reference(name, poses, data):
    """Every value is within its bound of the independent mpmath reference (both moving)."""
    scene = mk.load_scene(name)
    state, exact = assert_bounded(scene, *split(data.draw(poses)))
    assume(state is not None)


@pytest.mark.parametrize('name', ['five_bar', 'excavator'])
def test_packaged_scene_is_answered_wherever_it_assembles(name):
    """Over a grid of both drivers, nothing is untrusted; refusals are where nothing assembles."""
    scene = mk.load_scene(name)
    first, second = scene.drivers
    if name == 'five_bar':
        a, b = np.meshgrid(np.linspace(0, math.tau, 60), np.linspace(0, math.tau, 60))
    else:
        a, b = np.meshgrid(np.linspace(1.9, 3.4, 40), np.linspace(2.4, 4.0, 40))
    state = mk.solve(scene, [a.ravel(), b.ravel()], [1.0, -0.5], [0.3, 0.2])
    assert all(' (' not in key for key in state.failures), state.failures  # none untrusted
    # The grid passes close to where the distal links (or a cylinder and its link) fall
    # in line, where the bounds grow as 1 / measure^2: still far within the tolerance.
    assert np.nanmax(state.relative_error_bound) < 1e-7
    assert 0.2 < state.valid.mean() < 1.0
    for index in np.flatnonzero(~state.valid)[::37]:
        x = [float(a.ravel()[index]), float(b.ravel()[index])]
        inside = all(d.stroke is None or d.stroke[0] <= v <= d.stroke[1]
                     for d, v in zip(scene.drivers, x, strict=True))
        if inside:  # not a stroke refusal: the reference finds no configuration either
            with pytest.raises(ref.NoAssembly):
                ref.reference(scene, x)


def test_five_bar_golden_end_effector():
    """Golden (by hand): cranks at 120, 60 deg put P at (50, 120 sin 60 + sqrt(160^2 - 110^2)) mm.

    B = (-60, 103.92) and D = (160, 103.92) mm are 220 mm apart, so P is
    sqrt(160^2 - 110^2) = 116.19 mm above their midpoint.
    """
    scene = mk.load_scene('five_bar')
    state = mk.solve(scene, [math.radians(120), math.radians(60)], [0.0, 0.0], [0.0, 0.0])
    expected = (0.05, 0.12 * math.sin(math.radians(60)) + math.sqrt(0.16**2 - 0.11**2))
    np.testing.assert_allclose(state.points['P'].position, expected, rtol=0, atol=1e-16)
    assert expected[1] == pytest.approx(0.2201125, abs=1e-7)


def test_five_bar_default_drive_stays_assembled():
    """Both motors at 30 rpm, 30 deg apart: assembled over a whole turn (the node's default)."""
    scene = mk.load_scene('five_bar')
    t = np.linspace(0.0, 2.0, 721)  # one turn at 30 rpm
    starts = [d.start + d.speed * t for d in scene.drivers]
    state = mk.solve(scene, starts)
    assert state.valid.all()
    assert np.min(np.abs(state.singularity['P'])) > 0.2


def test_excavator_golden_boom_angle():
    """Golden: the boom's angle from the law of cosines in the triangle O, F, Q."""
    scene = mk.load_scene('excavator')
    of = math.hypot(0.4, 1.1)
    for length in (2.0, 2.6, 3.3):
        gamma = math.acos((2.6**2 + of**2 - length**2) / (2 * 2.6 * of))
        state = mk.solve(scene, [length, 3.0], [0.0, 0.0], [0.0, 0.0])
        boom = state.joints['boom'].position
        assert boom == pytest.approx(math.atan2(-1.1, 0.4) + gamma, abs=4e-16)
    # Half-way out, the boom stands 6.97 deg above the horizon (printed to 2 decimals).
    assert math.degrees(mk.solve(scene, [2.6, 3.0]).joints['boom'].position) == \
        pytest.approx(6.97, abs=0.005)


def test_excavator_strokes_are_refused_outside():
    """Each cylinder's stroke ends are answered; beyond them, one line naming it and its stroke."""
    scene = mk.load_scene('excavator')
    for lengths in ([2.0, 2.5], [3.3, 3.9]):
        mk.solve(scene, lengths)
    with pytest.raises(mk.AssemblyError, match=r'expected the length of actuator stick_cyl '
                       r'within its stroke \[2\.5, 3\.9\] m, got 3\.95 m'):
        mk.solve(scene, [2.6, 3.95])


def test_five_bar_assembly_refusal_names_the_drivers():
    """Cranks pointing apart: the distal links cannot reach; the message says where both are."""
    scene = mk.load_scene('five_bar')
    with pytest.raises(mk.AssemblyError, match=r'RRR P cannot be solved at left_crank = '
                       r'3\.14159 rad, right_crank = 0 rad: the circles about B') as info:
        mk.solve(scene, [math.pi, 0.0])
    assert mk.assembly_text(info.value, scene.units) == (
        'links left_distal (160 mm) and right_distal (160 mm) cannot reach from B to D '
        '(340 mm apart, more than 320 mm)')


@pytest.mark.parametrize('name', ['five_bar', 'excavator'])
def test_packaged_array_path_equals_the_scalar_path(name):
    """On a grid, the array path's values equal single solves (bits for the cylinders)."""
    scene = mk.load_scene(name)
    rng = np.random.default_rng(7)
    if name == 'five_bar':
        x = [rng.uniform(1.2, 2.4, 30), rng.uniform(0.6, 1.6, 30)]
    else:
        x = [rng.uniform(2.0, 3.3, 30), rng.uniform(2.5, 3.9, 30)]
    speeds, accels = [0.2, rng.uniform(-0.2, 0.2, 30)], [rng.uniform(-1, 1, 30), 0.1]
    many = mk.solve(scene, x, speeds, accels)
    for i in np.flatnonzero(many.valid):
        one = mk.solve(scene, [x[0][i], x[1][i]], [0.2, speeds[1][i]], [accels[0][i], 0.1])
        for joint, motion in one.joints.items():
            got = many.joints[joint]
            if name == 'excavator':  # no cos or sin: the same bits (angles to an ulp of atan2)
                assert (got.velocity[i], got.acceleration[i]) == (motion.velocity,
                                                                  motion.acceleration)
                assert abs(got.position[i] - motion.position) <= np.spacing(abs(motion.position))
            else:
                np.testing.assert_allclose((got.position[i], got.velocity[i],
                                            got.acceleration[i]),
                                           (motion.position, motion.velocity,
                                            motion.acceleration), rtol=1e-13, atol=1e-15)
    assert many.valid.sum() >= 25


def test_a_plain_dyad_downstream_of_an_actuator_is_bounded_against_the_reference():
    """One cylinder, the stick's cylinder held at 3.2 m (a plain RRR on the boom): bounded."""
    data = yaml.safe_load(scene_text('excavator'))
    data['inputs'] = data['inputs'][:1]
    data['dyads'][1]['links'][1] = {'name': 'stick_cyl_body', 'from': 'S', 'length': 3.2}
    held = mk.parse_scene(data)
    for length in (2.05, 2.6, 3.25):
        state, exact = assert_bounded(held, length, 0.2, -0.1)
        assert state is not None and exact is not None
        moving = mk.solve(mk.load_scene('excavator'), [length, 3.2], [0.2, 0.0], [-0.1, 0.0])
        np.testing.assert_allclose(state.points['bucket_tip'].velocity,
                                   moving.points['bucket_tip'].velocity, rtol=1e-13)


@pytest.mark.parametrize(('name', 'positions'), [('five_bar', [1.6, 1.0]),
                                                 ('excavator', [2.6, 3.0])])
def test_errors_relative_to_the_scales_are_a_few_ulps(name, positions):
    """Against the reference, every kind's worst error is within 20 ulps of its scale."""
    scene = mk.load_scene(name)
    speeds, accels = [0.1, 0.2], [0.0, 0.1]
    exact = ref.reference(scene, positions, speeds, accels)
    errors = ref.compare(mk.solve(scene, positions, speeds, accels), exact)
    assert set(errors) == set(ref.KINDS)
    assert max(errors.values()) <= 20 * EPS, errors
    # Backward stable: within a few eps times the condition number in every input
    # (each driver's position, speed and acceleration perturbed on its own).
    kappa = ref.condition(scene, exact)
    for kind, error in errors.items():
        assert 1.0 <= kappa[kind] < 100.0, (kind, kappa)
        assert error <= 4 * EPS * kappa[kind], (kind, error, kappa[kind])


# --- the packaged boom: one actuator, its only driver (issue 33) ------------------------

#: The packaged boom's geometry, m: boom OQ, cylinder base F (scene file).
BOOM_OQ, BOOM_F, BOOM_HEAD = 1.5, (0.35, -1.1), 5.0


def boom_closed_form(length, rate, accel):
    """Return the boom's angle, rate and acceleration by hand (law of cosines), rad.

    In the triangle O, F, Q: L^2 = a^2 + d^2 - 2 a d cos(gamma), the boom at
    angle(F - O) + gamma (Q left of O -> F: branch +1). Differentiating,
    gamma' = L L' / (a d sin gamma) and gamma'' = (L'^2 + L L'' - a d cos(gamma)
    gamma'^2) / (a d sin gamma).
    """
    a, d = BOOM_OQ, math.hypot(*BOOM_F)
    gamma = math.acos((a * a + d * d - length * length) / (2 * a * d))
    s = a * d * math.sin(gamma)
    w = length * rate / s
    alpha = (rate * rate + length * accel - a * d * math.cos(gamma) * w * w) / s
    return math.atan2(BOOM_F[1], BOOM_F[0]) + gamma, w, alpha


@pytest.mark.parametrize('length, rate, accel', [(1.45, 0.0, 0.0), (1.9, 0.05, 0.0),
                                                 (2.1, -0.08, 0.3), (2.35, 0.0, 0.0)])
def test_packaged_boom_is_the_law_of_cosines_through_the_api(length, rate, accel):
    """Golden: the boom's angle, rate and acceleration by hand, at the stroke's ends and within.

    One actuator, its only driver: ``solve(scene, length, speed, accel)`` (the
    one-driver signature) answers floats, the boom head moving with the boom.
    """
    scene = mk.load_scene('boom')
    assert scene.input is None and [d.name for d in scene.drivers] == ['lift_cyl']
    state = mk.solve(scene, length, rate, accel)
    theta, w, alpha = boom_closed_form(length, rate, accel)
    boom = state.joints['boom']
    assert boom.position == pytest.approx(theta, abs=4e-16)
    assert boom.velocity == pytest.approx(w, rel=1e-13, abs=1e-17)
    assert boom.acceleration == pytest.approx(alpha, rel=1e-12, abs=1e-16)
    head = state.points['T']
    np.testing.assert_allclose(head.position, [BOOM_HEAD * math.cos(theta),
                                               BOOM_HEAD * math.sin(theta)], rtol=0, atol=4e-15)
    np.testing.assert_allclose(head.velocity, [-BOOM_HEAD * w * math.sin(theta),
                                               BOOM_HEAD * w * math.cos(theta)],
                               rtol=0, atol=1e-14)
    motion = state.drivers['lift_cyl']
    assert (motion.type, motion.position, motion.velocity, motion.acceleration) == (
        'prismatic', length, rate, accel)
    data = state.as_dict()
    assert data['inputs'] == {'lift_cyl': {'position': length, 'speed': rate, 'accel': accel}}
    assert 'input' not in data  # a length is no crank "angle"


def test_packaged_boom_figures_of_its_description():
    """The boom swings from -7.65 to 51.7 deg over the stroke, transmission 46 deg down to 24.

    The figures of config/scenes/boom.yaml and the README; at time zero the
    cylinder is 1.9 m (the boom at 18.1 deg) and reaches 2.35 m in 9 s.
    """
    scene = mk.load_scene('boom')
    (cylinder,) = scene.drivers
    assert (cylinder.start, cylinder.speed, cylinder.accel) == (1.9, 0.05, 0.0)
    assert (cylinder.stroke[1] - cylinder.start) / cylinder.speed == pytest.approx(9.0)

    def pose(length):
        state = mk.solve(scene, length, 0.0, 0.0)
        theta = state.joints['boom'].position
        between = theta - state.joints['lift_cyl_body'].position
        return math.degrees(theta), abs(math.degrees(math.remainder(between, math.tau)))

    low, high = (pose(x) for x in cylinder.stroke)
    assert (round(low[0], 2), round(high[0], 1)) == (-7.65, 51.7)
    assert (round(low[1]), round(high[1])) == (46, 24)
    assert round(pose(1.9)[0], 1) == 18.1
    with pytest.raises(mk.AssemblyError, match=r'expected the length of actuator lift_cyl '
                       r'within its stroke \[1\.45, 2\.35\] m, got 2\.4 m'):
        mk.solve(scene, 2.4)


def test_packaged_boom_array_path_gives_the_scalar_bits():
    """A sweep of the cylinder (the one-driver signature's array) is the single solves' bits."""
    scene = mk.load_scene('boom')
    lengths = np.linspace(1.3, 2.5, 25)
    many = mk.solve(scene, lengths, 0.04, -0.01)
    assert list(many.valid) == [1.45 <= x <= 2.35 for x in lengths]
    for i in np.flatnonzero(many.valid):
        one = mk.solve(scene, float(lengths[i]), 0.04, -0.01)
        assert many.joints['boom'].velocity[i] == one.joints['boom'].velocity
        assert abs(many.joints['boom'].position[i] - one.joints['boom'].position) <= \
            np.spacing(abs(one.joints['boom'].position))
