# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The RPR kind (solver/rpr.py): a slotted lever about a ground pivot, through a moving pin."""

from __future__ import annotations

import cmath
import math

import pytest

import mech_kinematics as mk
from mech_kinematics.solver import graph as g

#: The closed forms against the motion computed here from the crank pin's: rad, m, per s.
ATOL = 1e-12


def crank_and_slotted_lever() -> mk.Scene:
    """Return a crank of 0.1 m about A driving a lever slotted about O, 0.3 m below A."""
    return mk.Scene('slotted', {'A': (0.0, 0.3), 'O': (0.0, 0.0)},
                    mk.Crank('crank', 'A', 'B', 0.1, angle=0.5, speed=3.0, accel=2.0),
                    (mk.RPR('lever', 'O', 'B', 'block'),))


def test_the_lever_points_at_the_pin_and_the_block_slides_with_coriolis():
    """Angle and slide from B - O; omega, alpha from the pin's velocity and acceleration."""
    state = mk.solve(crank_and_slotted_lever(), 0.5)
    w, a = 3.0, 2.0
    r = 0.1 * cmath.exp(0.5j)
    p = 0.3j + r
    v = 1j * w * r
    acc = (1j * a - w * w) * r
    s = abs(p)
    e = p / s
    omega = (e.conjugate() * v).imag / s
    sdot = (e.conjugate() * v).real
    # The pin's acceleration along and across the slot: the slide and Coriolis terms.
    alpha = ((e.conjugate() * acc).imag - 2 * sdot * omega) / s
    sddot = (e.conjugate() * acc).real + s * omega * omega
    lever, block = state.joints['lever'], state.joints['block']
    assert lever.position == pytest.approx(cmath.phase(p), abs=ATOL)
    assert (lever.velocity, lever.acceleration) == pytest.approx((omega, alpha), abs=ATOL)
    assert (block.position, block.velocity, block.acceleration) == pytest.approx(
        (s, sdot, sddot), abs=ATOL)


def test_its_fragment_is_a_lever_on_its_pivot_and_a_block_in_its_slot():
    """The lever turns about O; the block rides the pin and slides along the lever."""
    graph = crank_and_slotted_lever().graph
    slide = graph.prismatic('block')
    assert (slide.body, slide.on, slide.line) == ('block', 'lever', g.Line('O', 'lever', 0.0))
    assert graph.bodies['block'].frame.angle_of == 'lever'
    assert graph.reversing() == {'lever': 'revolute'}


def test_a_pin_on_the_pivot_is_refused_naming_both():
    """A lever whose pin passes over its pivot has no direction: refused, pin and pivot named."""
    scene = mk.Scene('through', {'A': (0.0, 0.1), 'O': (0.0, 0.0)},
                     mk.Crank('crank', 'A', 'B', 0.1, angle=1.0),
                     (mk.RPR('lever', 'O', 'B', 'block'),))
    with pytest.raises(mk.AssemblyError, match='pin B .*pivot'):
        mk.solve(scene, -math.pi / 2)


def test_slots_must_be_a_whole_number_from_three():
    """A Geneva wheel of 2 slots is refused naming the key."""
    with pytest.raises(mk.SceneError, match='slots of RPR "lever"'):
        mk.RPR('lever', 'O', 'B', 'block', slots=2)
