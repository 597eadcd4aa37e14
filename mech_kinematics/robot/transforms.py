# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Rigid transforms of a URDF: origins, joint motions and the tree's forward kinematics.

A URDF places each child link at ``T_child = T_parent @ origin @ motion(q)``:
``origin`` from the joint's ``<origin xyz rpy>`` (``rpy`` as fixed-axis roll,
pitch, yaw: ``R = Rz(yaw) Ry(pitch) Rx(roll)``; URDF 1.1's ``quat_xyzw`` instead
of ``rpy``: a quaternion ``x y z w``, normalised) and ``motion(q)`` a rotation
by ``q`` rad about the joint's unit ``<axis>`` (revolute, continuous) or a
translation of ``q`` m along it (prismatic). Every transform is a 4x4 NumPy
array in metres. Pure: NumPy only.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
import math

import numpy as np
import numpy.typing as npt

__all__ = ['Matrix', 'quaternion_matrix', 'rotation_about', 'rpy_matrix', 'transform',
           'translation']

Matrix = npt.NDArray[np.float64]


def rpy_matrix(roll: float, pitch: float, yaw: float) -> Matrix:
    """Return the 3x3 rotation of URDF fixed-axis angles: ``Rz(yaw) @ Ry(pitch) @ Rx(roll)``."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def quaternion_matrix(x: float, y: float, z: float, w: float) -> Matrix:
    """Return the 3x3 rotation of the quaternion ``x y z w`` (URDF 1.1's ``quat_xyzw``).

    The quaternion is normalised first, scaled by its largest component so that
    neither a tiny nor a huge one over- or underflows; a zero one raises ValueError.
    """
    big = max(abs(x), abs(y), abs(z), abs(w))
    if not big > 0.0 or not math.isfinite(big):
        raise ValueError(f'Expected a non-zero finite quaternion, got {x!r} {y!r} {z!r} {w!r}')
    x, y, z, w = x / big, y / big, z / big, w / big
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / norm, y / norm, z / norm, w / norm
    return np.array([[1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
                     [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
                     [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)]])


def transform(xyz: Sequence[float] = (0.0, 0.0, 0.0),
              rpy: Sequence[float] = (0.0, 0.0, 0.0),
              quat_xyzw: Sequence[float] | None = None) -> Matrix:
    """Return the 4x4 transform of an ``<origin xyz rpy>`` (or ``xyz quat_xyzw``)."""
    out = np.eye(4)
    out[:3, :3] = rpy_matrix(*rpy) if quat_xyzw is None else quaternion_matrix(*quat_xyzw)
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
