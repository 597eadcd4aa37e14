# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The assembly region of a scene with several drivers (issue 18; issue 19's "over a grid").

The scenes are written here: a five-bar with two cranks whose distal links
straighten inside a turn, and a cylinder lifting a boom (one actuator on an RRR
link) whose stroke reaches past where the boom and cylinder come in line. Both
have closed-form boundaries: the distal links straight (|BD| = l1 + l2) and
the cylinder in line with the boom (L = boom + |OF|).
"""

from __future__ import annotations

import cmath
import math
import warnings

from helpers import BOOM_CYLINDER as BOOM, driver_scene_names, FIVE_BAR_TWO_CRANKS as FIVE_BAR
import numpy as np
import pytest
import yaml

import mech_kinematics as mk
from mech_kinematics.geometry.region import free_length, region_from_scene

#: The ends are refined to adjacent doubles; the solver refuses within rounding of
#: the margins' roots: both well inside this, rad or m.
ATOL_END = 1e-12

OF = math.hypot(0.4, 1.1)  # m

pytestmark = pytest.mark.filterwarnings('ignore::mech_kinematics.NearSingularWarning')


def scene(text):
    """Return the scene of YAML ``text``."""
    return mk.parse_scene(yaml.safe_load(text))


def straight(pivot, other):
    """Return the crank angles (rad) about ``pivot`` (crank 0.12 m) with B 0.28 m from ``other``.

    |B - other|^2 = r^2 + c^2 - 2 r c cos(theta - phi) with c = other - pivot.
    """
    c = other - pivot
    cosine = (0.12 ** 2 + abs(c) ** 2 - 0.28 ** 2) / (2 * 0.12 * abs(c))
    phi = cmath.phase(c)
    return phi - math.acos(cosine), phi + math.acos(cosine)


def brute_force(sc, names, axes):
    """Return where scalar solves at every grid point answer (others at start)."""
    result = np.zeros(tuple(len(a) for a in axes), dtype=bool)
    starts = {d.name: d.start for d in sc.drivers}
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', mk.NearSingularWarning)
        for index in np.ndindex(result.shape):
            values = dict(starts)
            values.update({n: float(a[i]) for n, a, i in zip(names, axes, index, strict=True)})
            positions = [values[d.name] for d in sc.drivers]
            try:
                if len(positions) == 1:
                    mk.solve(sc, positions[0], 0.0, 0.0, max_error=math.inf)
                else:
                    mk.solve(sc, positions, [0.0] * len(positions), [0.0] * len(positions),
                             max_error=math.inf)
            except mk.AssemblyError:
                continue
            result[index] = True
    return result


def test_five_bar_slices_end_where_the_distal_links_are_straight():
    """Each crank's range, the other at its start, ends where |BD| = 0.28 m: closed form."""
    region = region_from_scene(scene(FIVE_BAR), grid=12)
    left, right = region.slices
    d = 0.1 + 0.12 * cmath.exp(1j * math.radians(60))
    ((start, end),) = left.ranges
    assert (start, end) == pytest.approx(straight(0j, d), abs=ATOL_END)
    assert left.ends == (('RRR P', 'RRR P'),) and left.at == {'right': math.radians(60)}
    b = 0.12 * cmath.exp(1j * math.radians(120))
    ((start, end),) = right.ranges
    assert (start, end) == pytest.approx(straight(0.1 + 0j, b), abs=ATOL_END)
    assert not left.everywhere and not right.everywhere


def test_slice_ends_are_where_solve_stops_answering():
    """The scalar solve answers at each end and refuses the next double outward."""
    sc = scene(FIVE_BAR)
    for piece in region_from_scene(sc, grid=12).slices:
        for start, end in piece.ranges:
            for edge, outward in ((start, -math.inf), (end, math.inf)):
                values = {piece.driver: edge, **piece.at}
                positions = [values[d.name] for d in sc.drivers]
                mk.solve(sc, positions, max_error=math.inf)
                positions[[d.name for d in sc.drivers].index(piece.driver)] = math.nextafter(
                    edge, outward)
                with pytest.raises(mk.AssemblyError):
                    mk.solve(sc, positions, max_error=math.inf)


def test_actuator_range_from_its_stroke_to_the_boom_in_line():
    """The cylinder assembles from its shortest stroke to boom + |OF|, where RRR Q stops."""
    region = region_from_scene(scene(BOOM))
    (piece,) = region.slices
    assert piece.domain == (2.0, 5.0) and piece.kind == 'prismatic'
    ((start, end),) = piece.ranges
    assert start == 2.0
    assert end == pytest.approx(2.6 + OF, abs=ATOL_END)
    assert piece.ends == (('stroke', 'RRR Q'),)
    assert region.grid == ('cyl',) and region.assembles.shape == (180,)
    inside = (region.axes[0] <= end)
    assert np.array_equal(region.assembles, inside)


def test_actuator_without_stroke_closes_between_difference_and_sum():
    """No stroke: it assembles for boom - |OF| <= L <= boom + |OF|, both ends the RRR's."""
    sc = scene(BOOM.replace(', stroke: [2000, 5000]', ''))
    (piece,) = region_from_scene(sc, grid=8).slices
    assert piece.domain == (0.0, free_length(sc))
    ((start, end),) = piece.ranges
    assert (start, end) == pytest.approx((2.6 - OF, 2.6 + OF), abs=ATOL_END)
    assert piece.ends == (('RRR Q', 'RRR Q'),)


def test_free_length_bounds_every_distance():
    """free_length is at least every reach, link, offset and the ground's diameter added."""
    sc = scene(BOOM.replace(', stroke: [2000, 5000]', ''))
    assert free_length(sc) >= 2.6 + 2.6 + math.hypot(5.68, 0.55) + OF


@pytest.mark.parametrize('text', [FIVE_BAR, BOOM], ids=['five_bar', 'boom'])
def test_grid_agrees_with_a_brute_force_solve(text):
    """The grid's answers are a scalar solve's at every grid point."""
    sc = scene(text)
    region = region_from_scene(sc, grid=30)
    assert np.array_equal(region.assembles, brute_force(sc, region.grid, region.axes))
    assert 0.0 < region.fraction < 1.0


def test_grid_axes_and_pair():
    """A crank's axis is a turn without its end; --pair swaps the grid's axes."""
    sc = scene(FIVE_BAR)
    region = region_from_scene(sc, grid=36)
    assert region.grid == ('left', 'right') and region.at == {}
    np.testing.assert_array_equal(region.axes[0], np.arange(36) * (2 * math.pi / 36))
    swapped = region_from_scene(sc, grid=36, pair=['right', 'left'])
    assert np.array_equal(swapped.assembles, region.assembles.T)
    # Where the distal links cannot reach: both cranks pointing away from each other.
    assert not region.assembles[18, 0] and region.assembles[9, 9]


@pytest.mark.parametrize('pair', [['left'], ['left', 'left'], ['left', 'x']])
def test_a_bad_pair_is_refused_in_one_line(pair):
    """The grid's drivers must be two different drivers of the scene."""
    with pytest.raises(mk.SceneError, match=r'Expected 2 different drivers of five for the '
                       r'grid \(left, right\), got'):
        region_from_scene(scene(FIVE_BAR), grid=4, pair=pair)


# --- the packaged scenes with several drivers ----------------------------------------


@pytest.mark.parametrize('name', driver_scene_names())
def test_packaged_grid_agrees_with_a_brute_force_solve(name):
    """Every packaged scene with several drivers: the grid is a scalar solve's answer."""
    sc = mk.load_scene(name)
    region = region_from_scene(sc, grid=24)
    assert np.array_equal(region.assembles, brute_force(sc, region.grid, region.axes))
    assert region.grid == tuple(d.name for d in sc.drivers[:2])


def test_packaged_five_bar_grid_is_where_the_distal_links_reach():
    """five_bar: it assembles exactly where |BD| < 320 mm (the distal links' sum), by hand."""
    region = region_from_scene(mk.load_scene('five_bar'), grid=60)
    left, right = np.meshgrid(*region.axes, indexing='ij')
    bd = np.abs(0.1 + 0.12 * np.exp(1j * right) - 0.12 * np.exp(1j * left))
    assert np.array_equal(region.assembles, bd < 0.32)
    for piece in region.slices:  # at the other's start the cranks turn fully
        assert piece.everywhere and piece.ends == (('turn', 'turn'),)


def test_packaged_excavator_closes_over_both_strokes():
    """Excavator: each cylinder closes within [|l - d|, l + d], wider than its stroke."""
    sc = mk.load_scene('excavator')
    region = region_from_scene(sc, grid=12)
    assert region.fraction == 1.0
    boom, stick = region.slices
    assert boom.ranges == ((2.0, 3.3),) and stick.ranges == ((2.5, 3.9),)
    assert boom.ends == stick.ends == (('stroke', 'stroke'),)
    # The boom cylinder's dyad: boom 2.6 m from O, the cylinder from F, |OF| = 1.17 m.
    assert 2.6 - OF < 2.0 and 2.6 + OF > 3.3
    # The stick cylinder's dyad: stick 0.9 m from T, the cylinder from S, both on the boom.
    ts = math.hypot(5.68 - 2.5, 0.55 - 0.9)
    assert ts - 0.9 < 2.5 and ts + 0.9 > 3.9
