# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Command-line tools; each module has ``add_parser(subparsers)`` and ``main(argv=None)``."""
