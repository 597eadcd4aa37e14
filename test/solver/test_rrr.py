# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The RRR kind (solver/rrr.py): two links meeting at a new pin, fixed or set by an actuator."""

from __future__ import annotations

import cmath
import math

import pytest

import mech_kinematics as mk
from mech_kinematics.solver import graph as g

#: Closed forms against the law of cosines computed here: a few ulps of the size, m.
ATOL_POSITION = 1e-15


def four_bar(branch: int = 1, angle: float = 1.0) -> mk.Scene:
    """Return a four-bar: crank 0.04 m about A, coupler 0.15, rocker 0.08 about D (0.15 away)."""
    return mk.Scene('four_bar', {'A': (0.0, 0.0), 'D': (0.15, 0.0)},
                    mk.Crank('crank', 'A', 'B', 0.04, angle=angle, speed=-4.0 * math.pi),
                    (mk.RRR('C', (mk.Link('coupler', 'B', 0.15), mk.Link('rocker', 'D', 0.08)),
                            mk.Branch(branch)),))


@pytest.mark.parametrize('branch', [1, -1])
def test_the_new_pin_is_where_the_two_circles_meet_on_its_branch(branch):
    """C is 0.15 m from B and 0.08 m from D, left of B->D on branch +1, right on -1."""
    scene = four_bar(branch)
    state = mk.solve(scene, 1.0)
    b = 0.04 * cmath.exp(1j)
    d = 0.15 + 0j
    # The law of cosines, written here: the foot of C on BD and its height.
    dist = abs(d - b)
    along = (0.15 ** 2 - 0.08 ** 2 + dist ** 2) / (2 * dist)
    height = math.sqrt(0.15 ** 2 - along ** 2)
    u = (d - b) / dist
    expected = b + along * u + branch * height * 1j * u
    x, y = state.points['C'].position
    assert abs(complex(x, y) - expected) <= ATOL_POSITION
    coupler = state.joints['coupler'].position
    assert coupler == pytest.approx(cmath.phase(expected - b), abs=1e-14)


def test_its_fragment_is_two_links_pinned_at_their_starts_and_at_the_new_pin():
    """The graph: coupler on the crank at B, rocker on the ground at D, pinned together at C."""
    graph = four_bar().graph
    assert [(j.name, j.body, j.on) for j in graph.joints[1:]] == [
        ('B', 'coupler', 'crank'), ('D', 'rocker', 'ground'), ('C', 'rocker', 'coupler')]
    assert graph.bodies['coupler'].length == 0.15
    assert graph.coordinates['rocker'] is g.REVOLUTE


def test_an_actuated_link_is_a_barrel_and_a_driven_rod():
    """A link that says actuator: is a cylinder: its barrel pinned at its start, its rod driven."""
    scene = mk.load_scene('boom')
    graph = scene.graph
    slide = next(j for j in graph.joints if j.driver and j.line is not None)
    barrel, rod = graph.bodies[slide.on], graph.bodies[slide.body]
    assert barrel.length is None and rod.guide == barrel.name
    assert rod.frame.angle_of == barrel.name


def test_circles_that_do_not_meet_are_refused_naming_both_links():
    """A non-Grashof four-bar past its toggle: refused naming both circles and the gap, in m."""
    scene = mk.Scene('toggling', {'A': (0.0, 0.0), 'D': (0.1, 0.0)},
                     mk.Crank('crank', 'A', 'B', 0.05, angle=0.5),
                     (mk.RRR('C', (mk.Link('coupler', 'B', 0.066),
                                   mk.Link('rocker', 'D', 0.056))),))
    with pytest.raises(mk.AssemblyError, match=r'circles about B \(radius 0\.066 m\) and D '
                                               r'\(radius 0\.056 m\) do not meet.*0\.15 m'):
        mk.solve(scene, math.pi)


def test_a_link_needs_two_and_two_actuators_must_differ():
    """An RRR of one link, or of two links on one actuator, is refused naming the dyad."""
    with pytest.raises(mk.SceneError, match='to have 2 links, got 1'):
        mk.RRR('C', (mk.Link('coupler', 'B', 0.15),))
    with pytest.raises(mk.SceneError, match='different actuators'):
        mk.RRR('C', (mk.Link('a', 'B', 1.0), mk.Link('b', 'D', 1.0)),
               actuators=('cyl', 'cyl'))
