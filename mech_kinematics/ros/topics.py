# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The names of the node's topics: one home for the node, the recorder and the plots.

Pure constants, no ROS. The state topics are relative names, so namespaces
and remaps apply; ``/tf`` and ``/tf_static`` are absolute, as tf2 expects.
"""

from __future__ import annotations

__all__ = ['DIAGNOSTICS', 'IMU', 'IMU_TYPE', 'INPUT_JOINT_STATES', 'INPUT_TARGETS',
           'INPUT_TRAJECTORY',
           'JOINT_ACCELERATIONS', 'JOINT_STATES', 'MARKERS',
           'POINT_ACCELERATIONS', 'REACTIONS', 'ROBOT_DESCRIPTION', 'SCENE', 'SHAKING',
           'STATE_TOPICS', 'TF', 'TF_STATIC', 'TYPES', 'WRENCH_TYPE', 'imu_topic',
           'reaction_topic']

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
#: The targets (joints' values, points' coordinates) that drive the node with ``drive: target``.
INPUT_TARGETS = 'input_targets'
#: The trajectories (points of drivers or of targets) that drive the node with
#: ``drive: trajectory``.
INPUT_TRAJECTORY = 'input_trajectory'
#: The namespace of the inertial sensors' topics: ``imu/NAME``, one per entry of a scene's
#: ``imus``, each of type :data:`IMU_TYPE`.
IMU = 'imu'
IMU_TYPE = 'sensor_msgs/msg/Imu'

#: The namespace of the joints' reactions: ``reactions/JOINT``, one per joint of the
#: mechanism's graph (a scene with masses, gravity or loads), each of type :data:`WRENCH_TYPE`.
REACTIONS = 'reactions'
#: The shaking force and moment the mechanism puts on its frame, of type :data:`WRENCH_TYPE`.
SHAKING = 'shaking'
WRENCH_TYPE = 'geometry_msgs/msg/WrenchStamped'

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
    INPUT_TARGETS: 'sensor_msgs/msg/JointState',
    INPUT_TRAJECTORY: 'trajectory_msgs/msg/JointTrajectory',
    SHAKING: WRENCH_TYPE,
}


def imu_topic(name: str) -> str:
    """Return the topic of the scene's sensor ``name``: ``imu/NAME`` (relative)."""
    return f'{IMU}/{name}'


def reaction_topic(joint: str) -> str:
    """Return the topic of the reaction at the graph's joint ``joint``: ``reactions/JOINT``.

    A joint named ``POINT/BODY`` (several pins at one point) makes a
    sub-namespace, which ROS names allow.
    """
    return f'{REACTIONS}/{joint}'
