# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The mechanisms the verification room builds: chains of four-bars, four-bars, slider-cranks.

Timings are never asserted here (the report's cost section times the chain
scene); the chain scene is checked to assemble everywhere and to meet the
error bound, and the four-bar, the slider-crank and the toggle angle to be
what their docstrings say.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.verify import cases
from mech_kinematics.verify import reference as ref
from mech_kinematics.verify.extreme import BOUND_FACTOR

EPS = float(np.finfo(float).eps)
#: The toggle angle's crank tip against the circles' meeting distance, relative (60 digits).
RTOL_TOGGLE = 1e-55


@pytest.mark.parametrize('stages', [1, 3, 10])
def test_chain_scene_assembles_everywhere(stages):
    """The chained four-bar assembles at every crank angle with one RRR per stage."""
    scene = cases.chain_scene(stages)
    assert len(scene.dyads) == stages
    state = mk.solve(scene, np.linspace(-math.pi, math.pi, 721))
    assert state.valid.all()


def test_chain_scene_against_reference():
    """The solver on a 3-stage chain meets the bound against the reference."""
    scene = cases.chain_scene(3)
    exact = ref.reference(scene, 0.3)
    kappa = ref.condition(scene, exact)
    for kind, error in ref.compare(mk.solve(scene, 0.3), exact).items():
        assert error <= BOUND_FACTOR * EPS * max(1.0, kappa[kind]), kind


def test_chain_scene_rejects_no_stages():
    """A chain needs a stage: the error names the count."""
    with pytest.raises(ValueError, match='got 0'):
        cases.chain_scene(0)


def test_four_bar_scales_every_length_and_carries_e():
    """four_bar's lengths are times ``scale``; E sits at (0.5 b, 0.3 b) in the coupler's frame."""
    scene = cases.four_bar('k', 0.04, 0.15, 0.08, 0.15, angle=1.0, scale=10.0)
    state = mk.solve(scene, 1.0)
    b, c, e = (state.complex_points[name][0] for name in 'BCE')
    assert scene.ground == {'A': (0.0, 0.0), 'D': (1.5, 0.0)}
    assert abs(b) == pytest.approx(0.4, rel=4 * EPS)
    assert abs(c - b) == pytest.approx(1.5, rel=4 * EPS)
    assert abs(c - 1.5) == pytest.approx(0.8, rel=4 * EPS)
    assert (e - b) / ((c - b) / abs(c - b)) == pytest.approx(0.75 + 0.45j, rel=8 * EPS)


def test_slider_crank_puts_the_piston_on_its_offset_guide():
    """slider_crank's piston P stays on y = offset, the rod's length from the crank tip."""
    scene = cases.slider_crank('s', 0.1, 0.4, offset=0.05)
    state = mk.solve(scene, np.linspace(-math.pi, math.pi, 9))
    b, p = (state.complex_points[name][0] for name in 'BP')
    np.testing.assert_allclose(p.imag, 0.05, rtol=0, atol=4 * EPS)
    np.testing.assert_allclose(np.abs(p - b), 0.4, rtol=4 * EPS)


def test_distance_angle_puts_the_tip_at_the_distance():
    """At distance_angle the crank tip is exactly ``distance`` from (d, 0) (60 digits)."""
    theta = cases.distance_angle(0.05, 0.1, 0.122)
    with mpmath.workdps(60):
        tip = mpmath.mpf(0.05) * mpmath.expj(theta)
        assert abs(abs(tip - mpmath.mpf(0.1)) / mpmath.mpf(0.122) - 1) <= RTOL_TOGGLE
