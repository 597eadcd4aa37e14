# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Theo Jansen's leg, the packaged `jansen_leg` scene (issue 18).

The scene is built from Jansen's published proportions (the "holy numbers"):
every one of them must hold as a distance between two joints at every crank
angle, velocities and accelerations must be the time derivatives of the
positions, and the foot must trace the leg's known flat-bottomed path.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

import mech_kinematics as mk

#: Jansen's lengths, mm, as the pairs of joints they join.
HOLY_NUMBERS = {
    ('O', 'M'): 15.0,    # m, the crank
    ('M', 'J1'): 50.0,   # j
    ('B', 'J1'): 41.5,   # b
    ('M', 'J2'): 61.9,   # k
    ('B', 'J2'): 39.3,   # c
    ('B', 'J3'): 40.1,   # d
    ('J1', 'J3'): 55.8,  # e
    ('J3', 'J4'): 39.4,  # f
    ('J2', 'J4'): 36.7,  # g
    ('J4', 'F'): 65.7,   # h
    ('J2', 'F'): 49.0,   # i
}
#: Fixed pivot B relative to the crank's centre O, mm: (-a, -l).
PIVOT = (-38.0, -7.8)
#: Loop closure: lengths hold to a few ulps of the mechanism's size (0.13 m).
ATOL_LENGTH = 1e-15  # m
#: Central differences in time with step H: truncation ~H^2 |f'''|, rounding ~eps |f| / H.
H = 1e-5  # s
RTOL_DIFFERENCE = 1e-7

SCENE_FILE = Path(__file__).resolve().parents[2] / 'config' / 'scenes' / 'jansen_leg.yaml'
SCENE = mk.load_scene(SCENE_FILE)
ANGLES = np.linspace(0.0, 2 * np.pi, 3600, endpoint=False)


def test_published_proportions_hold_over_a_whole_turn():
    """Every holy number is the distance between its two joints at 3600 crank angles."""
    state = mk.solve(SCENE, ANGLES)
    assert state.valid.all()
    position = {name: state.points[name].position for name in state.points}
    np.testing.assert_allclose(position['B'] - position['O'], np.tile(PIVOT, (3600, 1)) / 1e3,
                               atol=ATOL_LENGTH)
    for (a, b), length in HOLY_NUMBERS.items():
        distance = np.linalg.norm(position[b] - position[a], axis=1)
        np.testing.assert_allclose(distance, length / 1e3, rtol=0, atol=ATOL_LENGTH,
                                   err_msg=f'{a}{b}')


def test_it_has_one_degree_of_freedom_and_only_rrr_dyads():
    """One crank, RRR dyads, and the two rigid triangles' third joints as carried points."""
    text = yaml.safe_load(SCENE_FILE.read_text())
    assert 'link' in text['input']
    assert [dyad['type'] for dyad in text['dyads']] == ['RRR'] * 3
    assert set(text['points']) == {'J3', 'F'}


@pytest.mark.parametrize('accel', [0.0, -7.5])
def test_velocity_and_acceleration_are_time_derivatives(accel):
    """At 24 instants, v and a equal central differences of the positions in time."""
    omega = SCENE.input.speed
    t = np.linspace(0.0, 1.0, 24, endpoint=False)

    def at(time):
        angle = SCENE.input.angle + omega * time + accel * time ** 2 / 2
        return mk.solve(SCENE, angle, omega + accel * time, accel)

    now, ahead, behind = at(t), at(t + H), at(t - H)
    for name in ('J1', 'J2', 'J3', 'J4', 'F'):
        p = [s.points[name].position for s in (behind, now, ahead)]
        v = [s.points[name].velocity for s in (behind, now, ahead)]
        scale_v = np.abs(now.points[name].velocity).max()
        scale_a = np.abs(now.points[name].acceleration).max()
        np.testing.assert_allclose(now.points[name].velocity, (p[2] - p[0]) / (2 * H),
                                   atol=RTOL_DIFFERENCE * scale_v, err_msg=name)
        np.testing.assert_allclose(now.points[name].acceleration, (v[2] - v[0]) / (2 * H),
                                   atol=RTOL_DIFFERENCE * scale_a, err_msg=name)


def test_the_foot_traces_a_flat_bottomed_stride():
    """The foot's stride is 68 mm and it stays within 2 mm of its lowest for half the turn."""
    foot = mk.solve(SCENE, ANGLES).points['F'].position * 1e3
    stride = foot[:, 0].max() - foot[:, 0].min()
    assert 67.5 < stride < 68.5
    ground = foot[:, 1] < foot[:, 1].min() + 2.0
    assert ground.mean() > 0.5
    assert foot[ground, 0].max() - foot[ground, 0].min() > 0.95 * stride
