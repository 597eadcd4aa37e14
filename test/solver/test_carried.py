# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The carried point (solver/carried.py): a point fixed on a link, in that link's frame."""

from __future__ import annotations

import cmath

import pytest

import mech_kinematics as mk

ATOL = 1e-15


def crank_with_point(local=(0.03, 0.01)) -> mk.Scene:
    """Return a crank of 0.05 m carrying E at ``local`` in the frame at A toward B."""
    return mk.Scene('carried', {'A': (0.0, 0.0)},
                    mk.Crank('crank', 'A', 'B', 0.05, angle=0.3, speed=2.0, accel=1.0),
                    points=(mk.CarriedPoint('E', 'crank', 'A', 'B', local),))


def test_the_point_moves_rigidly_with_its_link():
    """E = A + local e^(i theta); its velocity i omega r, its acceleration (i alpha - w^2) r."""
    state = mk.solve(crank_with_point(), 0.3)
    r = complex(0.03, 0.01) * cmath.exp(0.3j)
    point = state.points['E']
    assert tuple(point.position) == pytest.approx((r.real, r.imag), abs=ATOL)
    v, a = 2j * r, (1j - 4.0) * r
    assert tuple(point.velocity) == pytest.approx((v.real, v.imag), abs=ATOL)
    assert tuple(point.acceleration) == pytest.approx((a.real, a.imag), abs=ATOL)


def test_its_fragment_fixes_it_on_its_link_and_moves_it_about_its_origin():
    """The graph carries E on the crank, and the polygons move it from A."""
    graph = crank_with_point().graph
    assert graph.bodies['crank'].points == ('A', 'B', 'E')
    assert graph.motions[-1] == mk.solver.graph.Motion('crank', 'A', 'E')


def test_its_x_axis_point_must_be_on_its_link():
    """A frame toward a point off the link is refused naming the point."""
    with pytest.raises(mk.SceneError, match='x-axis point of point "E"'):
        mk.Scene('carried', {'A': (0.0, 0.0), 'Z': (1.0, 0.0)},
                 mk.Crank('crank', 'A', 'B', 0.05),
                 points=(mk.CarriedPoint('E', 'crank', 'A', 'Z', (0.1, 0.0)),))
