# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Rigid transforms of a URDF: origins, joint motions and the tree's forward kinematics.

A URDF places each child link at ``T_child = T_parent @ origin @ motion(q)``:
``origin`` from the joint's ``<origin xyz rpy>`` (``rpy`` as fixed-axis roll,
pitch, yaw: ``R = Rz(yaw) Ry(pitch) Rx(roll)``) and ``motion(q)`` a rotation
by ``q`` rad about the joint's unit ``<axis>`` (revolute, continuous) or a
translation of ``q`` m along it (prismatic). Every transform is a 4x4 NumPy
array in metres. Pure: NumPy only.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
import math

import numpy as np
import numpy.typing as npt

__all__ = ['Matrix', 'rotation_about', 'rpy_matrix', 'transform', 'translation']

Matrix = npt.NDArray[np.float64]


def rpy_matrix(roll: float, pitch: float, yaw: float) -> Matrix:
    """Return the 3x3 rotation of URDF fixed-axis angles: ``Rz(yaw) @ Ry(pitch) @ Rx(roll)``."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def transform(xyz: Sequence[float] = (0.0, 0.0, 0.0),
              rpy: Sequence[float] = (0.0, 0.0, 0.0)) -> Matrix:
    """Return the 4x4 transform of an ``<origin xyz rpy>``."""
    out = np.eye(4)
    out[:3, :3] = rpy_matrix(*rpy)
    out[:3, 3] = xyz
    return out


def rotation_about(axis: Iterable[float], angle: float) -> Matrix:
    """Return the 4x4 rotation by ``angle`` rad about the unit vector ``axis`` (Rodrigues)."""
    x, y, z = axis
    c, s = math.cos(angle), math.sin(angle)
    v = 1.0 - c
    out = np.eye(4)
    out[:3, :3] = [[c + x * x * v, x * y * v - z * s, x * z * v + y * s],
                   [y * x * v + z * s, c + y * y * v, y * z * v - x * s],
                   [z * x * v - y * s, z * y * v + x * s, c + z * z * v]]
    return out


def translation(vector: Iterable[float]) -> Matrix:
    """Return the 4x4 translation by ``vector`` (m)."""
    out = np.eye(4)
    out[:3, 3] = tuple(vector)
    return out
