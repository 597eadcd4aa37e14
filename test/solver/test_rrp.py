# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The RRP kind (solver/rrp.py): a link ending in a slider on a fixed straight guide."""

from __future__ import annotations

import cmath
import math

import pytest

import mech_kinematics as mk
from mech_kinematics.solver import graph as g

#: The closed form against the slider-crank's own formula, written here: m.
ATOL_POSITION = 1e-15


def slider_crank(branch: int = 1, offset: float = 0.02) -> mk.Scene:
    """Return a slider-crank: crank 0.05 m, rod 0.2 m, guide along x at height ``offset``."""
    return mk.Scene('slider_crank', {'A': (0.0, 0.0), 'G': (0.0, offset)},
                    mk.Crank('crank', 'A', 'B', 0.05, angle=0.7, speed=10.0),
                    (mk.RRP('P', mk.Link('rod', 'B', 0.2), 'G', 0.0, 'piston',
                            mk.Branch(branch)),))


@pytest.mark.parametrize('branch', [1, -1])
def test_the_slider_is_where_the_rod_reaches_the_guide(branch):
    """The slider s = b_x +- sqrt(l^2 - (e - b_y)^2): larger on branch +1, smaller on -1."""
    state = mk.solve(slider_crank(branch), 0.7)
    b = 0.05 * cmath.exp(0.7j)
    s = b.real + branch * math.sqrt(0.2 ** 2 - (0.02 - b.imag) ** 2)
    assert state.joints['piston'].position == pytest.approx(s, abs=ATOL_POSITION)
    x, y = state.points['P'].position
    assert (x, y) == pytest.approx((s, 0.02), abs=ATOL_POSITION)


def test_its_fragment_is_a_link_pinned_to_a_block_on_the_fixed_guide():
    """The rod turns on the crank at B; the piston, pinned to it at P, slides on the ground."""
    graph = slider_crank().graph
    slide = graph.prismatic('piston')
    assert (slide.on, slide.line) == ('ground', g.Line('G', None, 0.0))
    assert graph.bodies['piston'].frame == g.Frame('P', None, 0.0)
    assert graph.reversing() == {'piston': 'prismatic'}


def test_a_guide_out_of_reach_is_refused_naming_link_and_guide():
    """A rod too short for the guide is refused with its length and the distance, in m."""
    scene = slider_crank(offset=0.2)
    with pytest.raises(mk.AssemblyError, match='the guide is out of reach of link rod'):
        mk.solve(scene, -1.5)
    assert 'cannot reach the guide through G' in mk.assembly_text(
        mk.AssemblyError('RRP P', 0.0, 'x', facts={
            'kind': 'reach', 'links': ('rod',), 'lengths': (0.2,), 'points': ('B', 'G'),
            'distance': 0.25, 'guide_angle': 0.0}))
