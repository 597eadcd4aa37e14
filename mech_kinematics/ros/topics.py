# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The names of the node's topics: one home for the node, the recorder and the plots.

Pure constants, no ROS. The state topics are relative names, so namespaces
and remaps apply; ``/tf`` and ``/tf_static`` are absolute, as tf2 expects.
"""

from __future__ import annotations

__all__ = ['DIAGNOSTICS', 'IMU', 'IMU_TYPE', 'INPUT_JOINT_STATES', 'JOINT_ACCELERATIONS',
           'JOINT_STATES', 'MARKERS',
           'POINT_ACCELERATIONS', 'ROBOT_DESCRIPTION', 'SCENE', 'STATE_TOPICS', 'TF',
           'TF_STATIC', 'TYPES', 'imu_topic']

JOINT_STATES = 'joint_states'
JOINT_ACCELERATIONS = 'joint_accelerations'
POINT_ACCELERATIONS = 'point_accelerations'
DIAGNOSTICS = 'diagnostics'
MARKERS = 'markers'
TF = '/tf'
TF_STATIC = '/tf_static'
#: The scene's URDF, latched (transient local).
ROBOT_DESCRIPTION = 'robot_description'
#: The scene file's text, latched, so that a bag carries its own scene.
SCENE = 'scene'

#: The drivers' positions (and velocities) that drive the node with ``drive: topic``.
INPUT_JOINT_STATES = 'input_joint_states'
#: The namespace of the inertial sensors' topics: ``imu/NAME``, one per entry of a scene's
#: ``imus``, each of type :data:`IMU_TYPE`.
IMU = 'imu'
IMU_TYPE = 'sensor_msgs/msg/Imu'

#: The topics of the kinematic state, published together at every instant.
STATE_TOPICS = (JOINT_STATES, JOINT_ACCELERATIONS, POINT_ACCELERATIONS)

#: The message type of each topic (ROS 2 type names).
TYPES = {
    JOINT_STATES: 'sensor_msgs/msg/JointState',
    JOINT_ACCELERATIONS: 'trajectory_msgs/msg/JointTrajectory',
    POINT_ACCELERATIONS: 'trajectory_msgs/msg/MultiDOFJointTrajectory',
    DIAGNOSTICS: 'diagnostic_msgs/msg/DiagnosticArray',
    MARKERS: 'visualization_msgs/msg/MarkerArray',
    TF: 'tf2_msgs/msg/TFMessage',
    TF_STATIC: 'tf2_msgs/msg/TFMessage',
    ROBOT_DESCRIPTION: 'std_msgs/msg/String',
    SCENE: 'std_msgs/msg/String',
    INPUT_JOINT_STATES: 'sensor_msgs/msg/JointState',
}


def imu_topic(name: str) -> str:
    """Return the topic of the scene's sensor ``name``: ``imu/NAME`` (relative)."""
    return f'{IMU}/{name}'
