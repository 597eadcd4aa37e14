# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Helpers shared by several test modules.

A test module never imports another test module: what two of them need lives
here (or in ``conftest.py``), one section per concern, each headed by a
comment naming the modules that use it.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
import runpy
from typing import Any
from unittest import mock

import pytest
import setuptools

from mech_kinematics.ros.parameters import PARAMETERS

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
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


# --- a scene using every construct -----------------------------------------------
# Used by test_scene.py and test_scene_loader.py, which edit it.

#: A valid scene using every construct: an RRR four-bar, points carried in both
#: forms, an RRP from a carried point, a second ground point on the guide.
BASE_SCENE = """\
name: base_scene
units: {length: mm, angle: deg}
ground:
  A: [0, 0]
  D: [150, 0]
  G: [0, -100]
input: {link: crank, center: A, point: B, length: 40, angle: 60, speed_rpm: -120, accel: 0}
dyads:
  - type: RRR
    point: C
    links:
      - {name: coupler, from: B, length: 150}
      - {name: rocker, from: D, length: 80}
    branch: 1
  - type: RRP
    point: P
    link: {name: rod, from: E, length: 150}
    guide: {through: G, angle: 0}
    slider: piston
    branch: 1
points:
  E: {link: coupler, from: B, toward: C, distance: 50}
  F: {link: coupler, origin: B, xaxis: C, local: [40, -30]}
"""

# --- what setup.py installs and which parameters the node declares ---------------
# Used by test_launch.py and test_packaging.py.
#: Parameters every rclpy node declares itself.
STANDARD_PARAMETERS = frozenset({'use_sim_time'})


def setup_keywords() -> dict:
    """Return the keyword arguments setup.py passes to ``setuptools.setup``."""
    captured: dict = {}
    cwd = os.getcwd()
    try:
        os.chdir(ROOT)      # setup.py globs its data files relative to the repository
        with mock.patch.object(setuptools, 'setup', lambda **kw: captured.update(kw)):
            runpy.run_path(str(ROOT / 'setup.py'), run_name='__main__')
    finally:
        os.chdir(cwd)
    return captured


def console_scripts() -> dict:
    """Return setup.py's console scripts as {name: 'module:function'}."""
    scripts = {}
    for entry in setup_keywords()['entry_points']['console_scripts']:
        name, target = (part.strip() for part in entry.split('='))
        scripts[name] = target
    return scripts


def installed_files() -> dict:
    """Return setup.py's data files as {installed path: repository path}."""
    files = {}
    for folder, sources in setup_keywords()['data_files']:
        for source in sources:
            files[f'{folder}/{Path(source).name}'] = source
    return files


def node_parameters() -> frozenset:
    """Return the names of the parameters kinematics_node declares.

    The node declares every entry of ``mech_kinematics.ros.parameters.PARAMETERS``,
    and rclpy declares the standard ones for every node.
    """
    return frozenset({p.name for p in PARAMETERS} | STANDARD_PARAMETERS)
