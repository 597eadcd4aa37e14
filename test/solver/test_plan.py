# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Compiling a scene in O(n log n): dependency order and the mechanism's size (issue 12).

``Scene`` orders its dyads and carried points by dependency (the earliest in
the file first wherever the order is free) and measures the mechanism's size,
the length scale of the RPR near-singularity measure: the largest of the
crank, the dyad links and the distance between the two farthest ground
points. Both used to be O(n^2) (10,000 dyads listed in reverse took 76 s;
10,000 ground points took 4.75 GB); these tests check that they give the
same answers as the quadratic definitions, and scale linearly.
"""

from __future__ import annotations

import math
import time

from hypothesis import example, given, settings, strategies as st
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.solver.plan import diameter

SETTINGS = settings(max_examples=300, deadline=None, derandomize=True)
#: Relative tolerance of the diameter from the hull against all pairs, for
#: float coordinates (orientation tests round near collinear points).
RTOL_DIAMETER = 1e-12
#: Timing ratio that separates linear from quadratic: 3,000 dyads in reverse
#: order against the same in file order. Linear is ~1x; the quadratic order took
#: 76 s for 10,000 in reverse, so ~7 s for 3,000 against ~0.7 s to build them: ~10x.
MAX_ORDER_RATIO = 5.0


def brute_diameter(points):
    """Return the largest distance between two points, over all pairs."""
    points = list(points)
    return max((abs(a - b) for a in points for b in points), default=0.0)


integer_points = st.lists(st.builds(complex, st.integers(-50, 50), st.integers(-50, 50)),
                          min_size=1, max_size=40)
float_points = st.lists(st.builds(complex, st.floats(-1e6, 1e6), st.floats(-1e6, 1e6)),
                        min_size=1, max_size=40)


@SETTINGS
@given(integer_points)
@example([0j])
@example([0j, 0j])
@example([0j, 1 + 0j, 2 + 0j, 3 + 0j])  # collinear
@example([0j, 1 + 1j, 2 + 2j, 1 + 1j])  # collinear, repeated
@example([complex(x, y) for x in range(4) for y in range(4)])  # a grid: parallel edges
def test_diameter_on_a_grid_is_exactly_the_farthest_pair(points):
    """On integer points (exact orientation tests) the hull's diameter is all pairs' maximum."""
    assert diameter(points) == brute_diameter(points)


@SETTINGS
@given(float_points)
def test_diameter_of_float_points_is_the_farthest_pair(points):
    """On float points the hull's diameter is all pairs' maximum to rounding."""
    expected = brute_diameter(points)
    assert diameter(points) == pytest.approx(expected, rel=RTOL_DIAMETER, abs=0.0)


@pytest.mark.parametrize('points', [
    [1e308 + 0j, -1e308 + 0j, 1e308j, 5 + 5j],  # the farthest pair is further than a double
    [1e300 + 1e300j, -1e300 - 1e300j, 1e-300j, -1e300 + 1e300j, 1e300 - 1e300j],
    [1e-300 + 0j, 0j, 1e-300j, 2e-300 + 2e-300j],
])
def test_diameter_at_extreme_scales_is_the_farthest_pair(points):
    """Coordinates near the limits of a double give all pairs' maximum, and terminate."""
    assert diameter(points) == brute_diameter(points)


def test_diameter_of_points_on_a_circle():
    """2,000 points on a circle (every point on the hull): the diameter is all pairs' maximum."""
    rng = np.random.default_rng(12)
    z = 3.0 * np.exp(1j * np.sort(rng.uniform(0, 2 * np.pi, 2000))) + (1 - 2j)
    expected = float(np.max(np.abs(z[:, None] - z[None, :])))
    assert diameter(z.tolist()) == pytest.approx(expected, rel=RTOL_DIAMETER, abs=0.0)


def test_size_of_the_packaged_scenes_is_unchanged():
    """The RPR measure's scale of the quick return (three ground points in line) is 700 mm."""
    scene = mk.load_scene('quick_return')
    state = mk.solve(scene, scene.input.angle)
    b = state.points['B'].position
    assert state.singularity['lever'] == pytest.approx(math.hypot(*b) / 0.7, rel=1e-15)


# --- dependency order ------------------------------------------------------------------


def greedy_order(items, known):
    """Return the names of ``items`` (name, needs) in the quadratic reference order.

    Repeatedly place the first item in the list whose needs are all known:
    the definition the linear-time compiler must reproduce.
    """
    known, pending, order = set(known), list(items), []
    while pending:
        index = next(i for i, (_, needs) in enumerate(pending) if needs <= known)
        name, _ = pending.pop(index)
        order.append(name)
        known.add(name)
    return order


@st.composite
def slider_forests(draw):
    """Draw RRP sliders on the x axis, each from an earlier point, listed in any order."""
    n = draw(st.integers(1, 25))
    parents = [draw(st.integers(0, k - 1)) for k in range(1, n + 1)]  # index 0 is the crank tip
    order = draw(st.permutations(range(1, n + 1)))
    return parents, order


@SETTINGS
@given(slider_forests())
def test_steps_run_in_the_earliest_solvable_order(forest):
    """Dyads are placed as the quadratic search placed them: the first solvable one first."""
    parents, order = forest
    names = ['B'] + [f'P{k}' for k in range(1, len(parents) + 1)]
    dyads = [mk.RRP(point=names[k], link=mk.Link(f'r{k}', names[parents[k - 1]], 0.5),
                    through='O', guide_angle=0.0, slider=f's{k}') for k in order]
    scene = mk.Scene('forest', {'O': (0.0, 0.0)}, mk.Crank('crank', 'O', 'B', 0.1, angle=1.0),
                     tuple(dyads))
    expected = greedy_order([(names[k], {names[parents[k - 1]]}) for k in order], {'B'})
    assert scene.output_points == ('O', 'B', *expected)
    # Each slider lies 0.5 m beyond its parent along the axis, whatever the order.
    state = mk.solve(scene, 1.0)
    tip = 0.1 * complex(math.cos(1.0), math.sin(1.0))
    first = tip.real + math.sqrt(0.5**2 - tip.imag**2)  # a slider placed from the crank tip
    depth = {'B': 0}
    for k in range(1, len(parents) + 1):
        depth[names[k]] = depth[names[parents[k - 1]]] + 1
    for name in names[1:]:
        assert state.points[name].position[0] == pytest.approx(first + 0.5 * (depth[name] - 1),
                                                               rel=1e-12)


def chain_scene(n, reverse):
    """Return a Scene of ``n`` sliders in a chain, each 20 mm beyond the one before."""
    links = [mk.RRP(point=f'P{k}', link=mk.Link(f'r{k}', f'P{k - 1}', 0.02), through='O',
                    guide_angle=0.0, slider=f's{k}') for k in range(1, n + 1)]
    return mk.Scene('chain', {'O': (0.0, 0.0)}, mk.Crank('crank', 'O', 'P0', 0.01, angle=1.0),
                    tuple(links[::-1] if reverse else links))


def best_time(build, repeat=3):
    """Return the shortest of ``repeat`` runs of ``build`` (s), and what its last run built."""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        built = build()
        times.append(time.perf_counter() - start)
    return min(times), built


def test_reverse_order_costs_what_file_order_costs():
    """3,000 dyads listed last first compile as fast as in order. See issue 12.

    The quadratic order took 76 s for 10,000 dyads in reverse: for 3,000, about
    ten times what building them costs (:data:`MAX_ORDER_RATIO` is 5).
    """
    n = 3_000
    forward, in_order = best_time(lambda: chain_scene(n, reverse=False))
    backward, reversed_ = best_time(lambda: chain_scene(n, reverse=True))
    print(f'3,000 dyads: in order {forward:.3f} s, in reverse {backward:.3f} s')
    assert backward / forward < MAX_ORDER_RATIO
    assert reversed_.output_points == in_order.output_points


def test_a_cycle_among_many_names_a_few():
    """A cycle among 10,000 dyads is one short line: the first ten names and how many more."""
    n = 10_000
    links = [mk.RRP(point=f'P{k}', link=mk.Link(f'r{k}', f'P{(k + 1) % n}', 0.02), through='O',
                    guide_angle=0.0, slider=f's{k}') for k in range(n)]
    with pytest.raises(mk.SceneError) as info:
        mk.Scene('cycle', {'O': (0.0, 0.0)}, mk.Crank('crank', 'O', 'B', 0.01), tuple(links))
    message = str(info.value)
    assert message.endswith('got a cycle among [P0, P1, P2, P3, P4, P5, P6, P7, P8, P9 and '
                            '9990 more]')
