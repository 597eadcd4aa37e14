# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The solver's public names under their old home; the solver is :mod:`mech_kinematics.solver`."""

from .solver import (assembly_text, Branch, CarriedPoint, Crank, Engagement, JointMotion, Link,
                     MAX_SLOTS, NEAR_SINGULAR, Pin, PointState, RPR, RRP, RRR, Scene, SceneUnits,
                     SINGULAR, solve, State, TANGENCY_TOLERANCE)

#: The former name of :class:`SceneUnits`.
Units = SceneUnits

__all__ = [
    'Branch', 'CarriedPoint', 'Crank', 'Engagement', 'JointMotion', 'Link', 'MAX_SLOTS',
    'NEAR_SINGULAR', 'Pin', 'PointState', 'RPR', 'RRP', 'RRR', 'SINGULAR', 'Scene', 'State',
    'SceneUnits', 'TANGENCY_TOLERANCE', 'Units', 'assembly_text', 'solve',
]
