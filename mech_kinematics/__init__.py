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
                     UntrustedError)
from .linkage import (Branch, CarriedPoint, Crank, JointMotion, Link, NEAR_SINGULAR,
                      PointState, RPR, RRP, RRR, Scene, SINGULAR, solve, State)
from .scene import DEFAULT_SCENE, load_scene, parse_scene, scene_names

__all__ = [
    'AssemblyError', 'Bounds', 'Branch', 'CarriedPoint', 'Crank', 'DEFAULT_SCENE', 'ErrorBound',
    'JointMotion', 'Link', 'MAX_ERROR', 'MechKinematicsError', 'NEAR_SINGULAR',
    'NearSingularWarning', 'PointState', 'RPR', 'RRP', 'RRR', 'SINGULAR', 'Scene', 'SceneError',
    'State', 'UntrustedError', 'load_scene', 'parse_scene', 'scene_names', 'solve',
]
