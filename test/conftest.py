# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Tests mirror the package: test/solver, test/geometry, test/ros, test/tools, test/bag.

The shared helpers (``helpers``, ``ros_helpers``) live here, in ``test/``; this
file being here puts ``test/`` on ``sys.path`` for the test modules below it.
"""
