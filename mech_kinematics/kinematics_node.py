# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The ``kinematics_node`` executable (``python -m mech_kinematics.kinematics_node``).

The node itself is :class:`mech_kinematics.ros.node.KinematicsNode`; this
module keeps the documented path of the executable, and notes a SIGINT or
SIGTERM from before rclpy is imported, so that a stop asked while the node
loads is a clean exit too (:mod:`mech_kinematics.ros.startup`).
"""

import sys

from mech_kinematics.ros.startup import catch_stop_signals

__all__ = ['main']


def main(args: list[str] | None = None) -> int:
    """Run the node (:func:`mech_kinematics.ros.node.main`); return the exit status."""
    catch_stop_signals()
    from mech_kinematics.ros.node import main as run    # rclpy and the rest: ~0.6 s

    return run(args)


if __name__ == '__main__':
    sys.exit(main())
