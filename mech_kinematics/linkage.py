# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The solver's public names under their old home; the solver is :mod:`mech_kinematics.solver`."""

from .solver import (assembly_text, Branch, CarriedPoint, Crank, Engagement, JointMotion, Link,
                     MAX_SLOTS, NEAR_SINGULAR, Pin, PointState, RPR, RRP, RRR, Scene, SINGULAR,
                     solve, State, TANGENCY_TOLERANCE, Units)

__all__ = [
    'Branch', 'CarriedPoint', 'Crank', 'Engagement', 'JointMotion', 'Link', 'MAX_SLOTS',
    'NEAR_SINGULAR', 'Pin', 'PointState', 'RPR', 'RRP', 'RRR', 'SINGULAR', 'Scene', 'State',
    'TANGENCY_TOLERANCE', 'Units', 'assembly_text', 'solve',
]
