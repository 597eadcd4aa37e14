# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Helpers shared by several test modules.

A test module never imports another test module: what two of them need lives
here (or in ``conftest.py``), one section per concern, each headed by a
comment naming the modules that use it.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

HERE = Path(__file__).resolve().parent
#: The shipped scenes, in the source tree.
SCENES = HERE.parent / 'config' / 'scenes'


# --- the published 50-digit reference cases ------------------------------------
# Used by test_linkage_golden.py (the solver against them) and test_reference.py
# (the mpmath reference against them).

#: Verbatim copies of the published golden cases (``<scene>.json``).
REFERENCE = HERE / 'data' / 'reference'
#: The scenes that have a published reference file.
REFERENCE_NAMES = ('khurmi_four_bar_ad150', 'slider_crank_150_600', 'steam_engine_500_2000')


def reference_cases() -> list[Any]:
    """Return one pytest param (scene name, case) per published reference instant."""
    params = []
    for name in REFERENCE_NAMES:
        data = json.loads((REFERENCE / f'{name}.json').read_text())
        for index, case in enumerate(data['cases']):
            params.append(pytest.param(name, case, id=f'{name}-{index}'))
    return params
