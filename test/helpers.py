# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Shared test helpers: what setup.py installs and which parameters the node declares."""

import ast
import os
from pathlib import Path
import runpy
from unittest import mock

import setuptools

ROOT = Path(__file__).resolve().parent.parent
NODE_SOURCES = ROOT / 'mech_kinematics' / 'ros'
#: Parameters every rclpy node declares itself.
STANDARD_PARAMETERS = frozenset({'use_sim_time'})
#: Methods whose first argument is the name of a parameter the node declares.
DECLARING_CALLS = frozenset({'declare_parameter', '_declare_number'})


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
    """Return the names of the parameters kinematics_node declares, read from its source.

    Every call ``<x>.declare_parameter('name', ...)`` or ``<x>._declare_number('name', ...)``
    in mech_kinematics/ros/, plus the parameters rclpy declares for every node.
    """
    names = set(STANDARD_PARAMETERS)
    for path in sorted(NODE_SOURCES.rglob('*.py')):
        for node in ast.walk(ast.parse(path.read_text(encoding='utf-8'))):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                    and node.func.attr in DECLARING_CALLS and node.args
                    and isinstance(node.args[0], ast.Constant)
                    and isinstance(node.args[0].value, str)):
                names.add(node.args[0].value)
    return frozenset(names)
