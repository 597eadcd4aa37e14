# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Golden values: the answers printed in the course notes, at the accuracy they deserve.

The entries live in ``test/textbook_answers.py`` with their source, their
tolerance (0.5 % for numbers the text computes, 5 % for values measured on a
drawing, 10 % for squares and products of measured values) and, for known-bad
printed numbers, the exact value beside them.
"""

from __future__ import annotations

import math
from typing import Any

import pytest
from textbook_answers import evaluate, TEXTBOOK_ANSWERS, within_tolerance

import mech_kinematics as mk

#: Agreement of the solver with an entry's stored exact (50-digit) value.
RTOL_EXACT = 1e-12

_STATES: dict[str, dict[str, Any]] = {}


def _state(scene_name: str) -> dict[str, Any]:
    if scene_name not in _STATES:
        scene = mk.load_scene(scene_name)
        _STATES[scene_name] = mk.solve(scene, scene.input.angle).as_dict()
    return _STATES[scene_name]


def _id(entry: dict[str, Any]) -> str:
    return f"{entry['scene']}:{entry['quantity'].split(' ')[0]}"


@pytest.mark.parametrize('entry', [e for e in TEXTBOOK_ANSWERS if not e.get('discrepancy')],
                         ids=_id)
def test_printed_answer_within_drawing_accuracy(entry: dict[str, Any]) -> None:
    """The solver's value is within the printed answer's stated tolerance."""
    got = evaluate(entry['accessor'], _state(entry['scene']))
    assert within_tolerance(entry, got), (entry['quantity'], got, entry['printed'])
    if 'exact' in entry:
        assert math.isclose(got, entry['exact'], rel_tol=RTOL_EXACT, abs_tol=1e-15)


@pytest.mark.parametrize('entry', [e for e in TEXTBOOK_ANSWERS if e.get('discrepancy')],
                         ids=_id)
def test_documented_discrepancy_keeps_the_exact_value(entry: dict[str, Any]) -> None:
    """A printed answer known to be off: the solver gives the exact value, not the book's."""
    got = evaluate(entry['accessor'], _state(entry['scene']))
    assert math.isclose(got, entry['exact'], rel_tol=RTOL_EXACT)
    miss = abs(entry['printed'] - got) / abs(got)
    assert miss > mk.NEAR_SINGULAR, 'no longer a discrepancy: move it to the tight tests'
    assert miss <= entry['rel_tol'], 'the documented tolerance no longer covers the miss'


def test_every_seed_scene_has_answers() -> None:
    """Each scene taken from the seeds' worked problems is checked against printed numbers."""
    covered = {entry['scene'] for entry in TEXTBOOK_ANSWERS}
    assert covered >= {'khurmi_four_bar_ad150', 'slider_crank_150_600', 'steam_engine_500_2000',
                       'quick_return', 'geneva', 'rocking_lever', 'piston_300',
                       'four_bar_coupler_points'}
