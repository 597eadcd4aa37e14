# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node module is an adapter (issue 30): its concerns live in modules of their own.

``ros/node.py`` was 1,293 lines holding eight concerns (parameters,
configure, drivers, publishing, the tick thread, topic drive, diagnostics,
the single-instance check and ``main``). It wires them to one lifecycle node;
each concern is tested on its own (``test_node_parameters.py``,
``test_drive.py``, ``test_solver_path.py``, ``test_publishing.py``,
``test_tick_thread.py``, ``test_topic_input.py``, ``test_instance.py``), the
node over DDS by the ``test_kinematics_node_*`` files.
"""

import ast
from pathlib import Path

NODE = Path(__file__).resolve().parents[2] / 'mech_kinematics' / 'ros' / 'node.py'
#: Longest the node module may be, lines.
MAX_LINES = 400


def test_the_node_module_is_under_400_lines():
    """ros/node.py stays an adapter: under 400 lines."""
    lines = len(NODE.read_text().splitlines())
    assert lines < MAX_LINES, f'ros/node.py has {lines} lines, expected fewer than {MAX_LINES}'


def test_the_node_module_holds_the_node_and_its_start_error_only():
    """No thread, loop, subscription or main of its own: those are the concerns' modules."""
    tree = ast.parse(NODE.read_text())
    classes = [n.name for n in tree.body if isinstance(n, ast.ClassDef)]
    functions = [n.name for n in tree.body if isinstance(n, ast.FunctionDef)]
    assert classes == ['StartError', 'KinematicsNode'] and functions == ['one_line']
    imported = {a.name.split('.')[0] for n in ast.walk(tree) if isinstance(n, ast.Import)
                for a in n.names}
    assert not imported & {'threading', 'ctypes', 'random', 'gc'}, imported
