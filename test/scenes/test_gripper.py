# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The parallel-jaw gripper, the packaged `gripper` scene, and its fingertip IMU (issue 18).

A motor crank drives a crank-rocker four-bar whose rocker is one side of a
parallelogram: the jaw, the parallelogram's coupler, keeps its angle, so the
fingertip's IMU reads no rotation and the acceleration of a translating
body. Checked: every link length at every crank angle (closure), the jaw's
constant angle, velocities and accelerations as time derivatives, assembly
far from toggles and change points over the whole turn, the IMU's readings
(at rest, by hand at the start, against the 50-digit reference within their
bounds).
"""

from __future__ import annotations

import cmath
import math
from pathlib import Path

import mpmath
import numpy as np
import pytest
import yaml

import mech_kinematics as mk
from mech_kinematics.geometry.assembly import assembly_summary
from mech_kinematics.imu import imu_reading
from mech_kinematics.verify import reference as ref

SCENE_FILE = Path(__file__).resolve().parents[2] / 'config' / 'scenes' / 'gripper.yaml'
SCENE = mk.load_scene(SCENE_FILE)
SPEC = SCENE.imus[0]
G0 = (0.0, -9.80665)  # m/s^2
#: The scene's lengths, mm, as the pairs of joints they join; DF is a 3-4-5 triangle's 30.
LENGTHS = {('A', 'B'): 15.0, ('B', 'C'): 55.0, ('D', 'C'): 45.0, ('D', 'G'): 70.0,
           ('G', 'H'): 30.0, ('F', 'H'): 70.0, ('D', 'F'): 30.0}
#: The jaw's angle: the direction of DF, atan2(18, 24) (cos 0.8, sin 0.6).
JAW = math.atan2(18.0, 24.0)
#: Loop closure: lengths hold to a few ulps of the mechanism's size (0.12 m).
ATOL_LENGTH = 1e-15  # m
#: The jaw's angle and rate: rounding of atan2 of the solved points, and of its rate.
ATOL_JAW = 8e-15  # rad
ATOL_JAW_RATE = 1e-14  # rad/s at 30 rpm (pi rad/s)
H = 1e-5  # s, central differences: truncation ~H^2 |f'''|, rounding ~eps |f| / H
RTOL_DIFFERENCE = 1e-7
ANGLES = np.linspace(0.0, 2 * np.pi, 3600, endpoint=False)


def test_every_length_holds_and_the_jaw_keeps_its_angle_over_a_turn():
    """At 3600 crank angles: each link's length, and the jaw parallel to DF (angle, rate 0)."""
    state = mk.solve(SCENE, ANGLES)
    assert state.valid.all()
    position = {name: state.points[name].position for name in state.points}
    for (a, b), length in LENGTHS.items():
        distance = np.linalg.norm(position[b] - position[a], axis=1)
        np.testing.assert_allclose(distance, length / 1e3, rtol=0, atol=ATOL_LENGTH,
                                   err_msg=f'{a}{b}')
    jaw = state.joints['jaw']
    np.testing.assert_allclose(jaw.position, JAW, rtol=0, atol=ATOL_JAW)
    np.testing.assert_allclose(jaw.velocity, 0.0, rtol=0, atol=ATOL_JAW_RATE)
    # The parallelogram: G - D = H - F, the follower parallel to the rocker.
    np.testing.assert_allclose(position['G'] - position['D'], position['H'] - position['F'],
                               rtol=0, atol=4 * ATOL_LENGTH)
    np.testing.assert_allclose(state.joints['follower'].position,
                               state.joints['rocker'].position, rtol=0, atol=ATOL_JAW)


def test_one_degree_of_freedom_rrr_dyads_and_a_fingertip_imu():
    """One crank, two RRR dyads, carried points G and T, the IMU fingertip on the jaw at T."""
    text = yaml.safe_load(SCENE_FILE.read_text())
    assert 'link' in text['input']
    assert [dyad['type'] for dyad in text['dyads']] == ['RRR', 'RRR']
    assert set(text['points']) == {'G', 'T'}
    assert SCENE.imus == (mk.imu.ImuSpec('fingertip', 'jaw', 'T', G0, 0.0),)


def test_it_assembles_far_from_toggles_and_change_points_at_every_angle():
    """Assembled over the whole turn; each RRR's links at least 52 deg from being in line."""
    assert assembly_summary(SCENE) == 'assembles at every crank angle'
    state = mk.solve(SCENE, ANGLES)
    # The near-singularity measure of an RRR is the sine of the angle between its links.
    assert state.singularity['C'].min() > math.sin(math.radians(52.3))
    assert state.singularity['H'].min() > math.sin(math.radians(60.8))
    # What the node refuses beyond (max_relative_error 1e-6) is far away.
    assert np.nanmax(state.relative_error_bound) < 1e-11


@pytest.mark.parametrize('accel', [0.0, 12.5])
def test_velocity_and_acceleration_are_time_derivatives(accel):
    """At 24 instants, v and a of every moving point equal central differences in time."""
    omega = SCENE.input.speed
    t = np.linspace(0.0, 2.0, 24, endpoint=False)

    def at(time):
        angle = SCENE.input.angle + omega * time + accel * time ** 2 / 2
        return mk.solve(SCENE, angle, omega + accel * time, accel)

    now, ahead, behind = at(t), at(t + H), at(t - H)
    for name in ('B', 'C', 'G', 'H', 'T'):
        p = [s.points[name].position for s in (behind, now, ahead)]
        v = [s.points[name].velocity for s in (behind, now, ahead)]
        scale_v = np.abs(now.points[name].velocity).max()
        scale_a = np.abs(now.points[name].acceleration).max()
        np.testing.assert_allclose(now.points[name].velocity, (p[2] - p[0]) / (2 * H),
                                   atol=RTOL_DIFFERENCE * scale_v, err_msg=name)
        np.testing.assert_allclose(now.points[name].acceleration, (v[2] - v[0]) / (2 * H),
                                   atol=RTOL_DIFFERENCE * scale_a, err_msg=name)
    # A translating jaw: every point of it moves alike.
    np.testing.assert_allclose(now.points['T'].acceleration, now.points['G'].acceleration,
                               rtol=0, atol=1e-13)


def test_the_fingertip_imu_at_rest_reads_gravity_on_the_jaws_axes():
    """Still, the IMU reads R(-phi) (0, +9.80665) with cos phi = 0.8, sin phi = 0.6: (0.6, 0.8) g.

    By hand: the jaw lies along DF, a 3-4-5 triangle (24, 18); specific force
    at rest is -g = (0, 9.80665) m/s^2, turned by -phi: (9.80665 sin phi,
    9.80665 cos phi) = (5.88399, 7.84532) m/s^2.
    """
    for angle in np.linspace(0.0, 2 * np.pi, 12, endpoint=False):
        reading = imu_reading(mk.solve(SCENE, float(angle), 0.0, 0.0), SPEC)
        assert reading.angular_velocity == 0.0
        assert reading.orientation == pytest.approx(JAW, abs=ATOL_JAW)
        np.testing.assert_allclose(reading.linear_acceleration, [5.88399, 7.84532], rtol=0,
                                   atol=1e-14 + 5e-6)


def test_the_fingertip_imu_at_the_start_matches_a_hand_calculation():
    """Crank at 90 deg, 30 rpm: the four-bar solved by hand gives the IMU reading to 1e-9.

    By hand (mm, rad/s): B = (0, 15); C from the law of cosines in triangle
    BCD, left of B->D: C = (47.2471118, 43.1551137); vB + w2 x BC = w3 x DC
    gives the rocker's w3 = 0.928463367; aB + a2 x BC - w2^2 BC = a3 x DC -
    w3^2 DC gives a3 = 1.59723095; G = D + (70/45) DC; the jaw translates, so
    a_T = a_G = a3 x DG - w3^2 DG = (-0.0901213130, -0.0895547712) m/s^2; the
    IMU reads R(-phi) (a_T - g) = (5.758160087, 7.827748971) m/s^2, gyro 0.
    """
    state = mk.solve(SCENE, SCENE.input.angle)
    reading = imu_reading(state, SPEC)
    np.testing.assert_allclose(state.points['C'].position * 1e3, [47.2471118, 43.1551137],
                               rtol=0, atol=1e-7)
    assert state.joints['rocker'].velocity == pytest.approx(0.928463367, abs=1e-9)
    assert state.joints['rocker'].acceleration == pytest.approx(1.59723095, abs=1e-8)
    np.testing.assert_allclose(state.points['T'].acceleration, [-0.0901213130, -0.0895547712],
                               rtol=0, atol=1e-10)
    np.testing.assert_allclose(reading.linear_acceleration, [5.758160087, 7.827748971],
                               rtol=0, atol=1e-9)
    assert reading.angular_velocity == pytest.approx(0.0, abs=ATOL_JAW_RATE)
    # The same from first principles, in complex numbers (no solver code).
    w1 = math.pi  # 30 rpm
    b, d = 15j, 60 + 0j
    bd = d - b
    delta = math.acos((55 ** 2 + abs(bd) ** 2 - 45 ** 2) / (2 * 55 * abs(bd)))
    c = b + 55 * cmath.exp(1j * (cmath.phase(bd) + delta))
    m = np.array([[(1j * (c - b)).real, (-1j * (c - d)).real],
                  [(1j * (c - b)).imag, (-1j * (c - d)).imag]])
    w2, w3 = np.linalg.solve(m, [(-1j * w1 * b).real, (-1j * w1 * b).imag])
    rhs = w1 * w1 * b + w2 * w2 * (c - b) - w3 * w3 * (c - d)
    _, a3 = np.linalg.solve(m, [rhs.real, rhs.imag])
    dg = (70 / 45) * (c - d)
    specific = ((1j * a3 - w3 * w3) * dg / 1e3 - complex(*G0)) * complex(0.8, -0.6)
    np.testing.assert_allclose(reading.linear_acceleration, [specific.real, specific.imag],
                               rtol=0, atol=1e-13)


@pytest.mark.parametrize('angle', np.linspace(0.0, 2 * np.pi, 8, endpoint=False))
def test_imu_bounds_cover_the_error_against_the_50_digit_reference(angle):
    """Each reading of the fingertip IMU is within its bound of the exact (50-digit) reading."""
    state = mk.solve(SCENE, float(angle), -4.0, 9.0)
    reading = imu_reading(state, SPEC)
    exact = ref.reference(SCENE, float(angle), -4.0, 9.0)
    with mpmath.workdps(ref.DPS):
        theta, omega, _ = exact.joints['jaw']
        rotated = (exact.points['T'][2] - mpmath.mpc(*G0)) * mpmath.expj(-theta)
        assert abs(float(ref._wrap(mpmath.mpf(reading.orientation) - theta))) \
            <= reading.orientation_bound
        assert abs(float(mpmath.mpf(reading.angular_velocity) - omega)) \
            <= reading.angular_velocity_bound
        assert float(abs(mpmath.mpc(*reading.linear_acceleration) - rotated)) \
            <= reading.linear_acceleration_bound
        # The exact jaw keeps DF's angle, rate 0, to the rounding of the scene's millimetres
        # into doubles of metres (the reference solves those doubles exactly).
        assert abs(float(theta - mpmath.atan2(18, 24))) < 1e-15
        assert abs(float(omega)) < 1e-14
    assert reading.linear_acceleration_bound < 1e-12 * np.linalg.norm(
        reading.linear_acceleration)
