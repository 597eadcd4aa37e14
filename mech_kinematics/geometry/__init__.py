# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Pure geometry built on the solver: diagrams and instant centres (NumPy only, no drawing)."""
