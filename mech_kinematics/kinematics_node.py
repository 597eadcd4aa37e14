# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The ``kinematics_node`` executable (``python -m mech_kinematics.kinematics_node``).

The node itself is :class:`mech_kinematics.ros.node.KinematicsNode`; this
module keeps the documented path of the executable.
"""

import sys

from mech_kinematics.ros.node import main

__all__ = ['main']

if __name__ == '__main__':
    sys.exit(main())
