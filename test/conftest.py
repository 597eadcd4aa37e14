# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Tests mirror the package: test/solver, geometry, ros, tools, verify and bag.

The shared helpers (``helpers``, ``ros_helpers``) live here, in ``test/``; this
file being here puts ``test/`` on ``sys.path`` for the test modules below it.
"""

from pathlib import Path

import pytest

_HERE = Path(__file__).resolve().parent
#: Test files outside test/ros/ that run the node or a browser against the clock.
SERIAL_FILES = ('tools/test_bag_recorder.py', 'tools/test_view.py')
#: Files in test/ros/ that start no node, open no DDS participant and time nothing (the
#: compiled tick, the messages, the node's pure parts): they run on the workers.
PURE_ROS_FILES = frozenset(f'ros/test_{name}.py' for name in (
    'drive', 'instance', 'node', 'publishing', 'robot_mode', 'ros_diagnostics',
    'robot_forces_tick', 'ros_parameters', 'ros_schedule', 'solver_path', 'ticker', 'timebase',
    'topic_drive', 'topic_input', 'wrenches'))


def pytest_collection_modifyitems(config, items):
    """Mark the tests that time the node (test/ros/, the recorder, the browser) ``serial``.

    The pure files of test/ros/ (:data:`PURE_ROS_FILES`) are not marked.

    ``make test`` runs the other tests on two workers, then these alone in one
    process: a node publishing at 1 kHz beside a worker's CPU-bound tests on a
    2-core machine misses its deadlines.
    """
    for item in items:
        path = Path(str(item.fspath)).resolve()
        try:
            relative = path.relative_to(_HERE).as_posix()
        except ValueError:
            continue
        if (relative.startswith('ros/') and relative not in PURE_ROS_FILES
                or relative in SERIAL_FILES):
            item.add_marker(pytest.mark.serial)
