# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Analytic kinematics of planar linkages, and a ROS 2 node that publishes it.

The solver (:mod:`mech_kinematics.linkage`, :mod:`mech_kinematics.scene`) needs
NumPy and PyYAML only; nothing here imports rclpy.

>>> import mech_kinematics as mk
>>> scene = mk.load_scene('khurmi_four_bar_ad150')
>>> state = mk.solve(scene, scene.input.angle)
>>> round(state.joints['rocker'].velocity, 4)
-4.7846
"""

from .bounds import Bounds, ErrorBound, MAX_ERROR
from .errors import (AssemblyError, MechKinematicsError, NearSingularWarning, SceneError,
                     TargetError, UntrustedError)
from .scene import DEFAULT_SCENE, load_scene, parse_scene, scene_names
from .solver import (Actuator, assembly_text, Branch, CarriedPoint, Crank, Engagement,
                     Inverse, JointMotion, Link, MAX_SLOTS, NEAR_SINGULAR, paths, Pin,
                     PointState, RPR, RRP, RRR, Scene, SceneUnits, SINGULAR, Slider, solve,
                     solve_targets, State, TANGENCY_TOLERANCE)

#: The former name of :class:`SceneUnits` (the units a scene was written in), kept working.
Units = SceneUnits

__all__ = [
    'Actuator', 'AssemblyError', 'Bounds', 'Branch', 'CarriedPoint', 'Crank', 'DEFAULT_SCENE',
    'Engagement',
    'ErrorBound', 'Inverse', 'JointMotion', 'Link', 'MAX_ERROR', 'MAX_SLOTS',
    'MechKinematicsError',
    'NEAR_SINGULAR', 'NearSingularWarning', 'Pin', 'PointState', 'RPR', 'RRP', 'RRR', 'SINGULAR',
    'Scene', 'SceneError', 'SceneUnits', 'Slider', 'State', 'TANGENCY_TOLERANCE', 'TargetError',
    'Units',
    'UntrustedError', 'assembly_text', 'load_scene', 'parse_scene', 'paths', 'scene_names',
    'solve',
    'solve_targets',
]
