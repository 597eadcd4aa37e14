# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The actuator (solver/actuator.py): a driver whose input is the length of an RRR link."""

from __future__ import annotations

import math

import pytest

import mech_kinematics as mk
from mech_kinematics.solver import graph as g


def boom(stroke=(1.0, 1.8)) -> mk.Scene:
    """Return a boom pivoted at O, raised by a cylinder from F to its pin Q."""
    return mk.Scene('boom', {'O': (0.0, 0.0), 'F': (0.5, -0.3)}, None,
                    (mk.RRR('Q', (mk.Link('boom', 'O', 1.2), mk.Link('barrel', 'F', 1.4)),
                            actuators=(None, 'cyl')),),
                    inputs=(mk.Actuator('cyl', 1.4, 0.1, 0.0, stroke),))


def test_the_link_is_as_long_as_the_actuator():
    """|FQ| is the actuator's length, and its rate is the cylinder's extension rate."""
    state = mk.solve(boom(), 1.5, 0.2, 0.0)
    q = complex(*state.points['Q'].position)
    f = 0.5 - 0.3j
    assert abs(q - f) == pytest.approx(1.5, abs=1e-15)
    assert abs(q) == pytest.approx(1.2, abs=1e-15)
    v = complex(*state.points['Q'].velocity)
    assert ((q - f).conjugate() * v).real / abs(q - f) == pytest.approx(0.2, abs=1e-14)
    assert boom().drivers[0].joint_type is g.PRISMATIC


def test_its_rate_is_its_extension_rate_in_m_per_s():
    """Its rate as the scene gives it, set as speed in m/s; it does not turn (issue 30)."""
    cyl = mk.Actuator('cyl', 1.5, -0.25, 0.5)
    assert cyl.rate == ('speed', -0.25, 'm/s') and cyl.rate_parameter == ('speed', 'm/s')
    assert cyl.turns == 0


def test_a_length_outside_the_stroke_is_refused_with_the_stroke():
    """A length beyond the stroke is refused like a position that cannot assemble."""
    with pytest.raises(mk.AssemblyError, match=r'within its stroke'):
        mk.solve(boom(), 1.9, 0.0, 0.0)


def test_it_must_set_the_length_of_exactly_one_link():
    """No link using it, or two, is refused naming the actuator."""
    with pytest.raises(mk.SceneError, match='got no link or collar using it'):
        mk.Scene('b', {'O': (0.0, 0.0), 'F': (0.5, -0.3)}, None,
                 (mk.RRR('Q', (mk.Link('boom', 'O', 1.2), mk.Link('barrel', 'F', 1.4))),),
                 inputs=(mk.Crank('crank', 'O', 'B', 0.1), mk.Actuator('cyl', 1.4)))
    with pytest.raises(mk.SceneError, match='Expected a stroke|length of actuator'):
        mk.Actuator('cyl', 2.0, stroke=(1.0, 1.8))
    assert math.isfinite(boom().drivers[0].reach)
