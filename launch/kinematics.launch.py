# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Start kinematics_node: ``ros2 launch mech_kinematics kinematics.launch.py``.

Arguments (``NAME:=VALUE``): ``scene`` (a packaged scene or a path to a
scene YAML), ``rate_hz``, ``crank_speed_rpm`` (empty: the scene's own speed),
``markers`` (true to publish RViz markers on ``markers``) and ``namespace``.
``ros2 launch mech_kinematics kinematics.launch.py --show-args`` lists them
with their defaults. ``kinematics.launch.xml`` is the same in XML.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

ARGUMENTS = (
    ('scene', 'khurmi_four_bar_ad150',
     'Scene: the name of a packaged scene (config/scenes/NAME.yaml) or a path to a scene YAML'),
    ('rate_hz', '100.0', 'Publish rate, Hz (1 .. 10000)'),
    ('crank_speed_rpm', '',
     "Crank speed, rpm, + CCW; empty for the scene's input.speed_rpm"),
    ('markers', 'false', 'true: also publish visualization_msgs/MarkerArray on markers'),
    ('namespace', '', 'Namespace of the node and its topics; empty for none'),
)


def _number(name: str, text: str) -> float:
    try:
        return float(text)
    except ValueError:
        msg = f'Expected a number for the launch argument {name}, got {text!r}'
        raise ValueError(msg) from None


def _boolean(name: str, text: str) -> bool:
    word = text.strip().lower()
    if word not in ('true', 'false'):
        msg = f'Expected true or false for the launch argument {name}, got {text!r}'
        raise ValueError(msg)
    return word == 'true'


def _node(context):
    """Return the node, with crank_speed_rpm set only when the argument is not empty."""
    value = {name: LaunchConfiguration(name).perform(context) for name, _, _ in ARGUMENTS}
    parameters = {
        'scene': value['scene'],
        'rate_hz': _number('rate_hz', value['rate_hz']),
        'markers': _boolean('markers', value['markers']),
    }
    if value['crank_speed_rpm'].strip():
        parameters['crank_speed_rpm'] = _number('crank_speed_rpm', value['crank_speed_rpm'])
    return [Node(
        package='mech_kinematics',
        executable='kinematics_node',
        name='mech_kinematics',
        namespace=value['namespace'],
        parameters=[parameters],
        output='screen',
        emulate_tty=True,
    )]


def generate_launch_description():
    """Return the launch description: the arguments, then the node."""
    return LaunchDescription([
        *(DeclareLaunchArgument(name, default_value=default, description=description)
          for name, default, description in ARGUMENTS),
        OpaqueFunction(function=_node),
    ])
