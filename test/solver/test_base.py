# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The step-kind protocol (issue 17): the rest of the package asks a kind, never tests for one."""

from __future__ import annotations

import ast
from pathlib import Path
import re

import pytest

import mech_kinematics as mk
from mech_kinematics.solver.base import Item
from mech_kinematics.solver.registry import FACT_TEXTS, KINDS

PACKAGE = Path(__file__).resolve().parents[2] / 'mech_kinematics'
#: A test of which kind an object is: what the protocol replaces.
KIND_TEST = re.compile(r'(isinstance\(|type\(.*\) +is |^\s*case ).*\b(RRR|RRP|RPR|RPP|_\w+Step|'
                       r'Crank|CarriedPoint)\b')
#: Where a kind may test for itself: its own module.
OWN = {'rrr.py', 'rrp.py', 'rpr.py', 'rpp.py', 'geneva.py', 'crank.py', 'carried.py'}


def test_no_module_tests_which_kind_a_step_is():
    """Outside the kinds' own modules, no isinstance / type() is / case against a dyad or step."""
    found = []
    for path in sorted(PACKAGE.rglob('*.py')):
        if path.parent.name == 'solver' and path.name in OWN:
            continue
        for number, line in enumerate(path.read_text().splitlines(), 1):
            if KIND_TEST.search(line):
                found.append(f'{path.relative_to(PACKAGE)}:{number}: {line.strip()}')
    assert not found, found


#: The joint types' names and constants (solver/graph.py): what a switch on a joint type tests.
JOINT_TYPES = {'revolute', 'prismatic', 'lock'}
JOINT_CONSTANTS = {'REVOLUTE', 'PRISMATIC', 'LOCK'}
#: Where a joint type may be compared: its home and the kinds that declare joints.
TYPE_HOMES = OWN | {'graph.py', 'actuator.py'}


def _compares_a_joint_type(node: ast.AST) -> bool:
    """Whether ``node`` compares something with a joint type's name or constant."""
    if not isinstance(node, ast.Compare):
        return False
    for side in (node.left, *node.comparators):
        if isinstance(side, ast.Constant) and side.value in JOINT_TYPES:
            return True
        if isinstance(side, (ast.Tuple, ast.List, ast.Set)) and any(
                isinstance(e, ast.Constant) and e.value in JOINT_TYPES for e in side.elts):
            return True
        name = side.attr if isinstance(side, ast.Attribute) else getattr(side, 'id', None)
        if name in JOINT_CONSTANTS:
            return True
    return False


def test_no_module_switches_on_a_joint_type():
    """Outside solver/graph.py and the kinds, nothing compares a joint type: it asks the type."""
    found = []
    for path in sorted(PACKAGE.rglob('*.py')):
        if path.parent.name == 'solver' and path.name in TYPE_HOMES:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if _compares_a_joint_type(node):
                found.append(f'{path.relative_to(PACKAGE)}:{node.lineno}: '
                             f'{ast.unparse(node)}')
    assert not found, found


def test_the_joint_type_test_finds_a_switch():
    """The test above sees the forms a switch takes (a check that the check can fail)."""
    for source in ("kind == 'revolute'", "'prismatic' != j.type", "t in ('revolute', 'x')",
                   'kind is REVOLUTE', 'kind is graph.PRISMATIC'):
        assert _compares_a_joint_type(ast.parse(source).body[0].value), source
    for source in ('kind.angular', "name == 'crank'", 'table == kind.table'):
        assert not _compares_a_joint_type(ast.parse(source).body[0].value), source


def test_the_registry_holds_every_dyad_type_of_the_scene_format():
    """The scene's type: names its kind, which is an Item of that kind."""
    assert set(KINDS) == {'RRR', 'RRP', 'RPR', 'RPP', 'triad', 'collar', 'hinge', 'fold'}
    for name, kind in KINDS.items():
        assert issubclass(kind, Item) and kind.kind == name


FACTS = {
    'pivot': ({'kind': 'pivot', 'links': ('lever',), 'lengths': (), 'points': ('B', 'O'),
               'distance': 0.0}, 'the pin B of slotted link lever on its pivot O (0 mm from it)'),
    'in line': ({'kind': 'in line', 'links': ('coupler', 'rocker'), 'lengths': (0.15, 0.08),
                 'points': ('B', 'D'), 'distance': 0.23},
                'links coupler (150 mm) and rocker (80 mm) in line between B and D (230 mm '
                'apart): a toggle position, where the mechanism locks'),
    'apart': ({'kind': 'apart', 'links': ('coupler', 'rocker'), 'lengths': (0.15, 0.08),
               'points': ('B', 'D'), 'distance': 0.25},
              'links coupler (150 mm) and rocker (80 mm) cannot reach from B to D (250 mm apart, '
              'more than 230 mm)'),
    'reach': ({'kind': 'reach', 'links': ('rod',), 'lengths': (0.1,), 'points': ('B', 'E'),
               'distance': 0.2, 'guide_angle': 0.0},
              'link rod (100 mm) cannot reach the guide through E at 0 deg from B (200 mm from '
              'the guide)'),
    'stroke': ({'kind': 'stroke', 'actuator': 'boom_cyl', 'stroke': (1.9, 3.2), 'length': 3.5},
               'actuator boom_cyl: expected a length within its stroke [1900 mm, 3200 mm], '
               'got 3500 mm'),
    'travel': ({'kind': 'travel', 'slider': 'block_a', 'stroke': (-0.2, 0.2), 'position': 0.25},
               'slider block_a: expected a position within its stroke [-200 mm, 200 mm], '
               'got 250 mm'),
}


@pytest.mark.parametrize('kind', sorted(FACTS))
def test_each_kind_words_its_own_failure(kind):
    """assembly_text asks the kind that made the facts for their text, in the scene's units."""
    facts, text = FACTS[kind]
    error = mk.AssemblyError('X', 0.0, 'reason', facts=facts)
    assert mk.assembly_text(error, mk.SceneUnits('mm', 'deg')) == text


def test_every_fact_kind_has_a_text():
    """The kinds' facts (errors.py's kinds) all have their words."""
    assert set(FACT_TEXTS) == set(FACTS)
