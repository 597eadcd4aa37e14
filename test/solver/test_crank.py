# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The crank (solver/crank.py): a driver turning a link about a ground point."""

from __future__ import annotations

import cmath
import math

import pytest

import mech_kinematics as mk
from mech_kinematics.scene import parse_scene
from mech_kinematics.solver import graph as g

ATOL = 1e-15


def crank() -> mk.Scene:
    """Return a crank of 0.05 m about A = (0.1, 0.2)."""
    return mk.Scene('crank', {'A': (0.1, 0.2)},
                    mk.Crank('crank', 'A', 'B', 0.05, speed=3.0, accel=-2.0))


def test_its_tip_turns_about_its_centre():
    """B = A + r e^(i theta), v = i omega r, a = (i alpha - omega^2) r."""
    state = mk.solve(crank(), 1.2)
    r = 0.05 * cmath.exp(1.2j)
    tip = state.points['B']
    assert tuple(tip.position) == pytest.approx((0.1 + r.real, 0.2 + r.imag), abs=ATOL)
    a = (-2j - 9.0) * r
    assert tuple(tip.acceleration) == pytest.approx((a.real, a.imag), abs=ATOL)


def test_its_fragment_is_its_link_on_a_driven_pin():
    """The crank is a body on the ground, by a revolute joint its motor drives."""
    graph = crank().graph
    joint = graph.joints[0]
    assert (joint.name, joint.type, joint.on, joint.at, joint.driver) == (
        'crank', g.REVOLUTE, 'ground', 'A', True)
    assert crank().drivers[0].joint_type is g.REVOLUTE


def test_its_speed_is_given_once_in_rpm_or_rad_per_s():
    """A speed in rad/s is read to the bit, speed_rpm converted; both given is one line."""
    base = {'name': 's', 'units': {'length': 'm', 'angle': 'rad'}, 'ground': {'A': [0, 0]},
            'input': {'link': 'crank', 'center': 'A', 'point': 'B', 'length': 0.05}}
    assert parse_scene({**base, 'input': {**base['input'], 'speed': 300}}).input.speed == 300.0
    assert parse_scene({**base, 'input': {**base['input'], 'speed_rpm': 60}}).input.speed \
        == pytest.approx(2 * math.pi)
    with pytest.raises(mk.SceneError, match='input.speed: expected the crank speed once'):
        parse_scene({**base, 'input': {**base['input'], 'speed': 1, 'speed_rpm': 1}})


def test_its_centre_must_be_on_the_ground():
    """A crank about a moving point is refused naming the point."""
    with pytest.raises(mk.SceneError, match='crank center to be a ground point'):
        mk.Scene('c', {'A': (0.0, 0.0)}, mk.Crank('crank', 'Z', 'B', 0.05))
