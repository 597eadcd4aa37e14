# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Robots described in URDF: their planar loops read, mapped onto the scene's kinds, solved.

- :mod:`.description`: the URDF as written (read by ``urdf_parser_py``), its
  loop closures in the three forms (``<constraint>``, onshape-to-robot's
  closing frames, scikit-robot's ``loop_closures.yaml``) and its actuated
  joints (``<transmission>``, ``<ros2_control>``);
- :mod:`.transforms`: the URDF's rigid transforms;
- :mod:`.planar`: the loops' bodies, plane and dyads: the scene they become,
  and how each URDF joint follows the scene's coordinates;
- :mod:`.robot`: :class:`Robot`, solved in the URDF's own names and signs;
- :mod:`.writer`: a scene as YAML (``urdf2scene``) and as a URDF with
  ``<constraint>`` elements (the round trip).

Pure: no ROS (lxml and urdf_parser_py read the XML).
"""

from .description import Closure, ClosureKind, Description, read_description
from .planar import GAP_TOLERANCE, Planar, PLANAR_TOLERANCE
from .robot import load_robot, MIMIC_TOLERANCE, Robot, RobotState

__all__ = ['Closure', 'ClosureKind', 'Description', 'GAP_TOLERANCE', 'MIMIC_TOLERANCE',
           'PLANAR_TOLERANCE', 'Planar', 'Robot', 'RobotState', 'load_robot',
           'read_description']
