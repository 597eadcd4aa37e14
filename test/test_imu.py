# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""IMU readings from a solved state (issue 18, the scene format's version 3 ``imus``).

The readings are checked three ways: against time derivatives of the
solver's own positions (the definition of what an accelerometer and a gyro
read), at rest (gravity alone), and against the 50-digit reference, whose
error must stay within the readings' bounds.
"""

from __future__ import annotations

import json
import math

from helpers import BOOM_CYLINDER
from hypothesis import example, given, settings, strategies as st
import mpmath
import numpy as np
import pytest
import yaml

import mech_kinematics as mk
from mech_kinematics.__main__ import main
from mech_kinematics.imu import imu_reading, ImuSpec
from mech_kinematics.verify import reference as ref

G = (0.0, -9.80665)  # m/s^2, standard gravity along -y
SCENE = mk.load_scene('khurmi_four_bar_ad150')
SPEC = ImuSpec('tip', 'coupler', 'C', G, 0.3)
#: Central differences in time with step H (s): truncation ~H^2 |f'''| ~ 3e-8 relative,
#: rounding of the second difference ~eps |p| / H^2 ~ 1e-7 relative.
H = 1e-5
RTOL_DIFFERENCE = 1e-6


def reading_at(t, accel):
    """Return the reading and the state at time t from the scene's initial angle."""
    omega = SCENE.input.speed
    state = mk.solve(SCENE, SCENE.input.angle + omega * t + accel * t * t / 2,
                     omega + accel * t, accel)
    return imu_reading(state, SPEC), state


@pytest.mark.parametrize('accel', [0.0, 30.0])
@pytest.mark.parametrize('t', [0.0, 0.07, 0.19, 0.33])
def test_readings_are_the_time_derivatives_in_the_sensor_frame(t, accel):
    """Gyro = d(orientation)/dt; accelerometer = R(-phi) (d2p/dt2 - g); phi = theta + angle."""
    (now, state), (ahead, s_ahead), (behind, s_behind) = (
        reading_at(t, accel), reading_at(t + H, accel), reading_at(t - H, accel))
    coupler = state.joints['coupler'].position
    assert now.orientation == pytest.approx(math.remainder(coupler + 0.3, 2 * math.pi), abs=1e-15)
    turn = math.remainder(ahead.orientation - behind.orientation, 2 * math.pi)
    assert now.angular_velocity == pytest.approx(turn / (2 * H), rel=RTOL_DIFFERENCE)
    p = [s.points['C'].position for s in (s_behind, state, s_ahead)]
    a = (p[2] - 2 * p[1] + p[0]) / H ** 2 - np.array(G)
    c, s = math.cos(now.orientation), math.sin(now.orientation)
    expected = np.array([c * a[0] + s * a[1], -s * a[0] + c * a[1]])
    np.testing.assert_allclose(now.linear_acceleration, expected,
                               atol=RTOL_DIFFERENCE * np.linalg.norm(expected))


def test_at_rest_the_accelerometer_reads_gravity_upward():
    """Speed and acceleration 0: the reading is -g turned into the sensor frame, |9.80665|."""
    state = mk.solve(SCENE, SCENE.input.angle, 0.0, 0.0)
    reading = imu_reading(state, SPEC)
    assert reading.angular_velocity == 0.0
    assert np.linalg.norm(reading.linear_acceleration) == pytest.approx(9.80665, rel=1e-15)
    phi = reading.orientation
    world = (math.cos(phi) * reading.linear_acceleration[0]
             - math.sin(phi) * reading.linear_acceleration[1],
             math.sin(phi) * reading.linear_acceleration[0]
             + math.cos(phi) * reading.linear_acceleration[1])
    assert world == pytest.approx((0.0, 9.80665), abs=1e-14)


@pytest.mark.parametrize('name,link,point', [('khurmi_four_bar_ad150', 'coupler', 'C'),
                                             ('quick_return', 'lever', 'C'),
                                             ('steam_engine_500_2000', 'rod', 'E')])
def test_bounds_cover_the_error_against_the_50_digit_reference(name, link, point):
    """At eight angles, each reading is within its bound of the exact reading."""
    scene = mk.load_scene(name)
    spec = ImuSpec('s', link, point, G, -1.1)
    for angle in scene.input.angle + np.linspace(0, 2 * np.pi, 8, endpoint=False):
        state = mk.solve(scene, angle)
        reading = imu_reading(state, spec)
        exact = ref.reference(scene, angle)
        with mpmath.workdps(ref.DPS):
            theta, omega, _ = exact.joints[link]
            phi = theta + mpmath.mpf(spec.angle)
            a = exact.points[point][2] - mpmath.mpc(*G)
            rotated = a * mpmath.expj(-phi)
            assert abs(float(ref._wrap(mpmath.mpf(reading.orientation) - phi))) \
                <= reading.orientation_bound
            assert abs(float(mpmath.mpf(reading.angular_velocity) - omega)) \
                <= reading.angular_velocity_bound
            error = abs(mpmath.mpc(*reading.linear_acceleration) - rotated)
            assert float(error) <= reading.linear_acceleration_bound
            assert reading.linear_acceleration_bound < 1e-12 * float(abs(rotated)) + 1e-12


def test_the_array_path_gives_the_scalar_readings():
    """Readings over an array of angles are the single-angle ones, to the ulp of an angle."""
    angles = SCENE.input.angle + np.linspace(0, 2 * np.pi, 16, endpoint=False)
    many = imu_reading(mk.solve(SCENE, angles), SPEC)
    for i, angle in enumerate(angles):
        one = imu_reading(mk.solve(SCENE, float(angle)), SPEC)
        assert many.angular_velocity[i] == one.angular_velocity
        # The link angles of the two paths may differ by an ulp (atan2 of math and
        # of NumPy), and the readings turned by them likewise.
        assert many.orientation[i] == pytest.approx(one.orientation, rel=4 * mk.bounds.U)
        np.testing.assert_allclose(many.linear_acceleration[i], one.linear_acceleration,
                                   rtol=0, atol=8 * mk.bounds.U * 9.80665 * 10)
        assert many.linear_acceleration_bound[i] == pytest.approx(
            one.linear_acceleration_bound, rel=1e-12)


def test_gravity_and_angle_must_be_finite():
    """A NaN or infinite gravity or mounting angle is refused, naming the key."""
    with pytest.raises(ValueError, match=r'imus\.tip\.gravity\[1\]: expected a finite number'):
        ImuSpec('tip', 'coupler', 'C', (0.0, math.inf))
    with pytest.raises(ValueError, match=r'imus\.tip\.angle'):
        ImuSpec('tip', 'coupler', 'C', G, math.nan)


# -- the scene's ``imus:`` (read and checked by scene.py) ------------------------------------

IMU_SCENE = {
    'name': 'imu_test', 'units': {'length': 'mm', 'angle': 'deg'},
    'ground': {'A': [0, 0], 'D': [150, 0]},
    'input': {'link': 'crank', 'center': 'A', 'point': 'B', 'length': 40, 'angle': 60,
              'speed_rpm': -120},
    'dyads': [{'type': 'RRR', 'point': 'C',
               'links': [{'name': 'coupler', 'from': 'B', 'length': 150},
                         {'name': 'rocker', 'from': 'D', 'length': 80}]}],
    'points': {'E': {'link': 'coupler', 'origin': 'B', 'xaxis': 'C', 'local': [30, 20]}},
    'outputs': {'joints': ['rocker'], 'points': ['C']},
}


def imu_scene(imus):
    """Return the test scene (mm, deg) with ``imus``."""
    return mk.parse_scene({**IMU_SCENE, 'imus': imus})


def test_the_scene_reads_imus_in_its_angle_unit_and_gravity_in_si():
    """``angle`` in the scene's unit (deg here), gravity in m/s^2; defaults 0 and [0, 0]."""
    scene = imu_scene({'tip': {'link': 'coupler', 'point': 'E', 'gravity': [0, -9.80665],
                               'angle': 30},
                       'bare': {'link': 'rocker', 'point': 'C'}})
    assert scene.imus == (ImuSpec('tip', 'coupler', 'E', (0.0, -9.80665), math.radians(30)),
                          ImuSpec('bare', 'rocker', 'C', (0.0, 0.0), 0.0))


def test_outputs_keep_what_each_imu_needs_after_what_they_list():
    """outputs: lists rocker and C only; the sensor's link and point are added after them."""
    scene = imu_scene({'tip': {'link': 'coupler', 'point': 'E'}})
    assert scene.output_joints == ('rocker', 'coupler')
    assert scene.output_points == ('C', 'E')
    state = mk.solve(scene, scene.input.angle)
    reading = imu_reading(state, scene.imus[0])
    assert reading.orientation == state.joints['coupler'].position
    # Without the sensor the outputs stay as listed (nothing more is solved).
    plain = mk.parse_scene(IMU_SCENE)
    assert (plain.output_joints, plain.output_points) == (('rocker',), ('C',))


@pytest.mark.parametrize('imus, message', [
    ({'tip': {'link': 'nope', 'point': 'E'}},
     r'imus\.tip\.link: Expected a moving link \(crank, coupler, rocker\), got unknown "nope"'),
    ({'tip': {'link': 'A', 'point': 'E'}},
     r'imus\.tip\.link: .* got ground point "A", which does not move'),
    ({'tip': {'link': 'rocker', 'point': 'E'}},
     r'imus\.tip\.point: Expected a point carried by or lying on link "rocker" \(D, C\), '
     r'got "E"'),
    ({'tip': {'link': 'coupler', 'point': 'E', 'gravity': [0, math.nan]}},
     r'imus\.tip\.gravity\[1\]: expected a finite number, got nan'),
    ({'tip': {'link': 'coupler', 'point': 'E', 'gravity': [0]}},
     r'imus\.tip\.gravity: expected \[gx, gy\] in m/s\^2'),
    ({'tip': {'link': 'coupler', 'point': 'E', 'angle': math.inf}},
     r'imus\.tip\.angle: expected a finite number, got inf'),
    ({'tip': {'link': 'coupler', 'point': 'E', 'mass': 1}},
     r"imus\.tip: unknown key\(s\) \['mass'\]"),
    ({'tip': {'point': 'E'}}, r'imus\.tip\.link: missing required key'),
    ({'C': {'link': 'coupler', 'point': 'E'}},
     r'imus\.C: Expected a sensor name not used for a point, link or slider, got "C"'),
    ({'tip': 3}, r'imus\.tip: expected a mapping'),
    ([1], r'imus: expected a mapping'),
])
def test_a_bad_imu_is_refused_in_one_line_naming_its_key(imus, message):
    """Unknown or still link, a point not on it, non-finite numbers, unknown keys."""
    with pytest.raises(mk.SceneError, match=message) as caught:
        imu_scene(imus)
    assert '\n' not in str(caught.value)


def test_an_imu_on_a_slider_is_refused():
    """A slider (a prismatic joint) does not turn: no sensor frame on it."""
    scene = mk.load_scene('slider_crank_150_600')
    slider = next(n for n, t in scene.joint_types.items() if t == 'prismatic')
    data = mk.scene.read_scene_yaml(mk.scene.scene_text('slider_crank_150_600'))
    data['imus'] = {'s': {'link': slider, 'point': scene.input.point}}
    with pytest.raises(mk.SceneError, match=f'imus.s.link: .*got slider "{slider}", which '
                                            f'does not turn'):
        mk.parse_scene(data)


# -- ``solve`` prints the readings (tools/solve.py) ------------------------------------------

#: Five-point central differences in time with step h = H_TURN / (|omega| + sqrt|alpha|) s:
#: truncation ~h^4 |f^(5)|, rounding ~eps |p| / h^2, both below 1e-9 of the scale here.
H_TURN = 2e-3
RTOL_FIVE_POINT = 1e-7
IMU_TIP = {'tip': {'link': 'coupler', 'point': 'E', 'gravity': [0.0, -9.80665], 'angle': 30}}


def solve_json(scene, angle, speed, accel):
    """Return ``State.as_dict()`` (the ``solve`` JSON) of ``scene`` at one instant."""
    state = mk.solve(scene, angle, speed, accel)
    return state.as_dict()


def five_point(f, h):
    """Return (f'(0), f''(0)) of ``f`` (a function of time) by five-point central differences."""
    m2, m1, p1, p2 = (np.asarray(f(k * h), dtype=float) for k in (-2, -1, 1, 2))
    zero = np.asarray(f(0.0), dtype=float)
    first = (m2 - 8 * m1 + 8 * p1 - p2) / (12 * h)
    second = (-m2 + 16 * m1 - 30 * zero + 16 * p1 - p2) / (12 * h * h)
    return first, second


@settings(max_examples=40, deadline=None)
@given(angle=st.floats(-math.pi, math.pi),
       speed=st.one_of(st.floats(0.5, 60.0), st.floats(-60.0, -0.5)),
       accel=st.floats(-200.0, 200.0))
@example(angle=0.0, speed=-12.566370614359172, accel=0.0)
def test_json_readings_are_derivatives_of_the_solved_link_and_point(angle, speed, accel):
    """Gyro = d(theta_link)/dt; accelerometer = R(-phi) (d2(p)/dt2 - g), from the JSON."""
    scene = imu_scene(IMU_TIP)
    data = solve_json(scene, angle, speed, accel)['imus']['tip']

    def at(t):
        state = mk.solve(scene, angle + speed * t + accel * t * t / 2, speed + accel * t, accel)
        return state

    h = H_TURN / (abs(speed) + math.sqrt(abs(accel)))
    base = at(0.0).joints['coupler'].position
    omega, _ = five_point(lambda t: base + math.remainder(
        at(t).joints['coupler'].position - base, 2 * math.pi), h)
    _, a = five_point(lambda t: at(t).points['E'].position, h)
    phi = math.remainder(base + math.radians(30), 2 * math.pi)
    assert data['orientation'] == pytest.approx(phi, abs=4e-16)
    scale = abs(speed) + math.sqrt(abs(accel))
    assert data['angular_velocity'] == pytest.approx(float(omega), abs=RTOL_FIVE_POINT * scale)
    specific = a - np.array([0.0, -9.80665])
    expected = [math.cos(phi) * specific[0] + math.sin(phi) * specific[1],
                -math.sin(phi) * specific[0] + math.cos(phi) * specific[1]]
    np.testing.assert_allclose(data['linear_acceleration'], expected, rtol=0,
                               atol=RTOL_FIVE_POINT * (0.2 * scale ** 2 + 9.80665))


def test_json_at_rest_reads_minus_gravity_in_the_sensor_frame():
    """Speed 0, accel 0: gyro 0, accelerometer R(-phi) [0, +9.80665], phi = theta + 30 deg."""
    scene = imu_scene(IMU_TIP)
    data = solve_json(scene, 1.0, 0.0, 0.0)
    phi = data['imus']['tip']['orientation']
    assert phi == pytest.approx(data['joints']['coupler']['position'] + math.radians(30),
                                abs=4e-16)
    assert data['imus']['tip']['angular_velocity'] == 0.0
    np.testing.assert_allclose(data['imus']['tip']['linear_acceleration'],
                               [9.80665 * math.sin(phi), 9.80665 * math.cos(phi)],
                               rtol=0, atol=1e-14)


@pytest.mark.parametrize('angle', np.linspace(-math.pi, math.pi, 7, endpoint=False))
def test_json_bounds_cover_the_error_against_the_50_digit_reference(angle):
    """Each printed reading is within its printed bound of the exact (50-digit) reading."""
    scene = imu_scene(IMU_TIP)
    data = solve_json(scene, float(angle), -7.5, 40.0)
    reading, bound = data['imus']['tip'], data['error_bound']['imus']['tip']
    exact = ref.reference(scene, float(angle), -7.5, 40.0)
    with mpmath.workdps(ref.DPS):
        theta, omega, _ = exact.joints['coupler']
        phi = theta + mpmath.mpf(math.radians(30))
        rotated = (exact.points['E'][2] - mpmath.mpc(0, -9.80665)) * mpmath.expj(-phi)
        assert abs(float(ref._wrap(mpmath.mpf(reading['orientation']) - phi))) \
            <= bound['orientation']
        assert abs(float(mpmath.mpf(reading['angular_velocity']) - omega)) \
            <= bound['angular_velocity']
        assert float(abs(mpmath.mpc(*reading['linear_acceleration']) - rotated)) \
            <= bound['linear_acceleration']
    assert 0.0 < bound['linear_acceleration'] < 1e-12 * abs(complex(*reading[
        'linear_acceleration']))


def test_solve_prints_imus_before_error_bound_and_only_for_a_scene_with_imus(tmp_path, capsys):
    """The command's JSON has "imus" and "error_bound"."imus"; a scene without sensors neither."""
    path = tmp_path / 'imu.yaml'
    path.write_text(yaml.safe_dump({**IMU_SCENE, 'imus': IMU_TIP}))
    assert main(['solve', str(path), '--angle-deg', '75', '--speed-rpm', '30']) == 0
    data = json.loads(capsys.readouterr().out)
    assert list(data)[-2:] == ['imus', 'error_bound']
    assert set(data['imus']['tip']) == {'angular_velocity', 'linear_acceleration',
                                        'orientation'}
    assert set(data['error_bound']) == {'joints', 'points', 'imus'}
    assert data == json.loads(json.dumps(solve_json(
        imu_scene(IMU_TIP), math.radians(75), 30 * math.pi / 30, None)))
    assert main(['solve', 'khurmi_four_bar_ad150']) == 0
    data = json.loads(capsys.readouterr().out)
    assert 'imus' not in data and set(data['error_bound']) == {'joints', 'points'}
    assert mk.solve(mk.load_scene('khurmi_four_bar_ad150'), 1.0).imus == {}


def test_state_imus_are_the_readings_of_the_scenes_sensors():
    """``State.imus`` holds each sensor's :func:`imu_reading` of that state, in scene order."""
    scene = imu_scene({**IMU_TIP, 'rock': {'link': 'rocker', 'point': 'C'}})
    state = mk.solve(scene, 0.4, 2.0, -3.0)
    assert list(state.imus) == ['tip', 'rock']
    for spec in scene.imus:
        got, expected = state.imus[spec.name], imu_reading(state, spec)
        assert got.as_dict(False) == expected.as_dict(False)
        assert got.bounds_dict(False) == expected.bounds_dict(False)


def test_as_dict_on_the_array_path_gives_the_single_instant_readings():
    """Over an array of angles the readings and bounds are arrays of the single-angle ones."""
    scene = imu_scene(IMU_TIP)
    angles = np.linspace(-3, 3, 9)
    state = mk.solve(scene, angles)
    many = state.as_dict()
    for i, angle in enumerate(angles):
        one = solve_json(scene, float(angle), None, None)
        assert many['imus']['tip']['angular_velocity'][i] == \
            one['imus']['tip']['angular_velocity']
        np.testing.assert_allclose(many['imus']['tip']['linear_acceleration'][i],
                                   one['imus']['tip']['linear_acceleration'], rtol=1e-13)
        assert many['error_bound']['imus']['tip']['linear_acceleration'][i] == pytest.approx(
            one['error_bound']['imus']['tip']['linear_acceleration'], rel=1e-12)


def test_the_number_of_imus_is_bounded(monkeypatch):
    """More sensors than MAX_IMUS are refused in one line naming the limit."""
    monkeypatch.setattr(mk.scene, 'MAX_IMUS', 1)
    with pytest.raises(mk.SceneError, match=r'imus: expected at most 1 sensors \(MAX_IMUS\), '
                                            r'got 2'):
        imu_scene({'a': {'link': 'coupler', 'point': 'E'}, 'b': {'link': 'rocker',
                                                                 'point': 'C'}})


# -- the edges of the format (issue 33) -----------------------------------------------------

#: Whole turns of the angle written in rad beyond which reduce_radians' 2 pi to 400
#: digits is needed (a float 2 pi is off by 2.4e-16 rad a turn).
FAR_RAD = 1e17


def gripper_with(**fingertip):
    """Return the packaged gripper with its fingertip sensor's keys replaced by ``fingertip``."""
    data = mk.scene.read_scene_yaml(mk.scene.scene_text('gripper'))
    data['imus']['fingertip'].update(fingertip)
    return mk.parse_scene(data)


@pytest.mark.parametrize('far, near', [(1e17, -80.0), (360.0 * 2 ** 40 + 30, 30.0),
                                       (-725.5, -5.5)])
def test_an_imu_angle_beyond_a_turn_is_the_direction_it_names(far, near):
    """Issue 33: 1e17 deg is the direction -80 deg; the readings are -80 deg's, to the bit.

    It was read as 1.7e15 rad: orientation 1.7e15 rad, the acceleration 7.5 deg
    off, bounds of 0.39 rad, all published at level OK.
    """
    assert math.remainder(far, 360.0) == near
    far_state, near_state = (mk.solve(scene, scene.input.angle)
                             for scene in (gripper_with(angle=far), gripper_with(angle=near)))
    assert far_state.as_dict()['imus'] == near_state.as_dict()['imus']
    assert far_state.as_dict()['error_bound'] == near_state.as_dict()['error_bound']
    orientation = far_state.imus['fingertip'].orientation
    assert -math.pi < orientation <= math.pi
    assert far_state.imus['fingertip'].orientation_bound < 1e-13


def test_an_imu_angle_in_rad_beyond_a_turn_is_reduced_exactly():
    """1e17 rad (a spec of the API, or a scene in rad) is reduced with 2 pi to 50 digits here.

    The orientation is the link's angle plus 1e17 mod 2 pi, wrapped: checked
    against mpmath at 60 digits, within the reading's own bound.
    """
    spec = ImuSpec('far', 'coupler', 'C', G, FAR_RAD)
    assert -math.pi <= spec.angle <= math.pi
    with mpmath.workdps(60):
        turn = 2 * mpmath.pi
        exact = mpmath.mpf(FAR_RAD) - turn * mpmath.nint(mpmath.mpf(FAR_RAD) / turn)
        assert spec.angle == float(exact)
        state = mk.solve(SCENE, SCENE.input.angle)
        reading = imu_reading(state, spec)
        theta = mpmath.mpf(state.joints['coupler'].position) + exact
        expected = float(theta - 2 * mpmath.pi * mpmath.nint(theta / (2 * mpmath.pi)))
    assert abs(reading.orientation - expected) <= reading.orientation_bound
    assert reading.orientation_bound < 1e-14
    data = mk.scene.read_scene_yaml(mk.scene.scene_text('gripper'))
    data['units']['angle'] = 'rad'
    data['input']['angle'] = math.radians(data['input']['angle'])
    data['imus']['fingertip']['angle'] = FAR_RAD
    assert mk.parse_scene(data).imus[0].angle == spec.angle


def test_a_gravity_whose_readings_would_overflow_is_refused_at_load():
    """Issue 33: gravity [0, 1e308] crashed `solve` (inf in its JSON); now one line at load.

    At the limit (|gx| + |gy| = MAX_GRAVITY, half the largest double) the
    readings at rest and their bounds are finite.
    """
    from mech_kinematics.imu import MAX_GRAVITY

    with pytest.raises(mk.SceneError) as caught:
        gripper_with(gravity=[0.0, 1e308])
    message = str(caught.value)
    assert message.startswith('imus.fingertip.gravity: Expected a gravity whose readings stay '
                              'within the range of doubles (abs(gx) + abs(gy) at most '
                              '8.98847e+307 m/s^2), got [0, 1e+308] m/s^2')
    assert '\n' not in message
    with pytest.raises(mk.SceneError, match='imus.fingertip.gravity: Expected a gravity'):
        gripper_with(gravity=[-6e307, 6e307])
    scene = gripper_with(gravity=[MAX_GRAVITY / 2, -MAX_GRAVITY / 2])
    state = mk.solve(scene, scene.input.angle, 0.0, 0.0)
    data = state.as_dict()
    json.dumps(data, allow_nan=False)   # every reading and bound finite
    assert math.hypot(*data['imus']['fingertip']['linear_acceleration']) == pytest.approx(
        math.hypot(MAX_GRAVITY / 2, MAX_GRAVITY / 2), rel=1e-15)


def test_imus_on_a_scene_of_drivers_are_read_on_every_crank_and_link():
    """A sensor on a boom (one actuator, no crank): read; on a five-bar's second crank.

    ``imu_links`` asked ``scene.input`` for the crank: a scene of actuators
    alone raised AttributeError at load, and a second crank carried no point.
    """
    data = yaml.safe_load(BOOM_CYLINDER)
    data['imus'] = {'boom_head': {'link': 'boom', 'point': 'T', 'gravity': [0, -9.80665]}}
    boom = mk.parse_scene(data)
    state = mk.solve(boom, 3.1, 0.0, 0.0)
    reading = state.imus['boom_head']
    assert reading.orientation == state.joints['boom'].position
    np.testing.assert_allclose(reading.linear_acceleration,
                               [9.80665 * math.sin(reading.orientation),
                                9.80665 * math.cos(reading.orientation)], rtol=0, atol=1e-14)
    data = mk.scene.read_scene_yaml(mk.scene.scene_text('five_bar'))
    second = data['inputs'][1]
    data['imus'] = {'wrist': {'link': second['link'], 'point': second['point']}}
    arm = mk.parse_scene(data)
    assert mk.solve(arm, [d.start for d in arm.drivers]).imus['wrist'].orientation == \
        pytest.approx(arm.drivers[1].start, abs=1e-15)
