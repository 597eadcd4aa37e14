# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The report's cost section: the chained four-bars it times.

Timings are never asserted (the machine is shared); the chain scene is
checked to assemble everywhere and to meet the error bound.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.tools.report import cost
from mech_kinematics.tools.report import reference as ref
from mech_kinematics.tools.report.extreme import BOUND_FACTOR

EPS = float(np.finfo(float).eps)


@pytest.mark.parametrize('stages', [1, 3, 10])
def test_chain_scene_assembles_everywhere(stages):
    """The chained four-bar assembles at every crank angle with one RRR per stage."""
    scene = cost.chain_scene(stages)
    assert len(scene.dyads) == stages
    state = mk.solve(scene, np.linspace(-math.pi, math.pi, 721))
    assert state.valid.all()


def test_chain_scene_against_reference():
    """The solver on a 3-stage chain meets the bound against the reference."""
    scene = cost.chain_scene(3)
    exact = ref.reference(scene, 0.3)
    kappa = ref.condition(scene, exact)
    for kind, error in ref.compare(mk.solve(scene, 0.3), exact).items():
        assert error <= BOUND_FACTOR * EPS * max(1.0, kappa[kind]), kind


def test_chain_scene_rejects_no_stages():
    """A chain needs a stage: the error names the count."""
    with pytest.raises(ValueError, match='got 0'):
        cost.chain_scene(0)
