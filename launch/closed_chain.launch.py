# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""TF for every passive link of a closed chain whose motors publish joint_states.

``ros2 launch mech_kinematics closed_chain.launch.py``: kinematics_node driven
from a topic (``drive: topic``), its input remapped to the motors' topic. Put
your scene's path in ``scene`` and your motors' topic in the remapping; the
joint names the motors publish must be the scene's driver names. See
docs/node.md, "My robot's motors publish joint_states; I want TF for every
passive link".
"""

from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    """Return the node, driven by /motors/joint_states."""
    return LaunchDescription([Node(
        package='mech_kinematics', executable='kinematics_node',
        parameters=[{'scene': 'five_bar', 'drive': 'topic'}],
        remappings=[('input_joint_states', '/motors/joint_states')])])
