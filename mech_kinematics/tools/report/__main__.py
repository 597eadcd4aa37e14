# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``python -m mech_kinematics.tools.report -o DIR``: the ``report`` command on its own."""

import sys

from . import main

sys.exit(main())
