# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Start kinematics_node: ``ros2 launch mech_kinematics kinematics.launch.py``.

Arguments (``NAME:=VALUE``): ``scene`` (a packaged scene or a path to a
scene YAML), ``rate_hz``, ``crank_speed_rpm`` (empty: the scene's own speed),
``markers`` (true to publish RViz markers on ``markers``), ``namespace``,
``frame_id``, ``tf_prefix`` (empty: frame_id), ``use_sim_time``,
``params_file`` (a parameters YAML such as config/kinematics_node.yaml: when
given, the node takes its parameters from it, and scene, rate_hz,
crank_speed_rpm and markers are not used; the file's values win over
frame_id, tf_prefix and use_sim_time) and ``rviz`` (true: also start RViz
with config/mech_kinematics.rviz in the same namespace, fixed frame
frame_id). ``ros2 launch mech_kinematics kinematics.launch.py --show-args``
lists them with their defaults. ``kinematics.launch.xml`` is the same in XML.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare

ARGUMENTS = (
    ('scene', 'khurmi_four_bar_ad150',
     'Scene: the name of a packaged scene (config/scenes/NAME.yaml) or a path to a scene YAML'),
    ('rate_hz', '100.0', 'Publish rate, Hz (1 .. 10000)'),
    ('crank_speed_rpm', '',
     "Crank speed, rpm, + CCW; empty for the scene's input.speed_rpm"),
    ('markers', 'false', 'true: also publish visualization_msgs/MarkerArray on markers'),
    ('namespace', '', 'Namespace of the node and its topics; empty for none'),
    ('frame_id', 'mechanism', 'The ground frame: header.frame_id of every message'),
    ('tf_prefix', '', 'Prefix of the frames on /tf and /tf_static; empty for frame_id'),
    ('use_sim_time', 'false', 'true: follow /clock'),
    ('params_file', '',
     'A parameters YAML; when given, scene, rate_hz, crank_speed_rpm and markers are not '
     'used and its values win over frame_id, tf_prefix and use_sim_time'),
    ('rviz', 'false', 'true: also start RViz with config/mech_kinematics.rviz'),
)
RVIZ_CONFIG = 'mech_kinematics.rviz'


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
    """Return the node (and RViz), with crank_speed_rpm set only when the argument is given."""
    value = {name: LaunchConfiguration(name).perform(context) for name, _, _ in ARGUMENTS}
    common = {
        'frame_id': value['frame_id'],
        'tf_prefix': value['tf_prefix'],
        'use_sim_time': _boolean('use_sim_time', value['use_sim_time']),
    }
    if value['params_file'].strip():
        parameters = [common, value['params_file']]     # later entries win
    else:
        parameters = {
            'scene': value['scene'],
            'rate_hz': _number('rate_hz', value['rate_hz']),
            'markers': _boolean('markers', value['markers']),
        }
        if value['crank_speed_rpm'].strip():
            parameters['crank_speed_rpm'] = _number('crank_speed_rpm', value['crank_speed_rpm'])
        parameters = [{**common, **parameters}]
    actions = [Node(
        package='mech_kinematics',
        executable='kinematics_node',
        name='mech_kinematics',
        namespace=value['namespace'],
        parameters=parameters,
        output='screen',
        emulate_tty=True,
    )]
    if _boolean('rviz', value['rviz']):
        # In the node's namespace: the config's relative topics (markers,
        # robot_description) resolve to the node's.
        config = FindPackageShare('mech_kinematics').perform(context) + '/config/' + RVIZ_CONFIG
        actions.append(Node(
            package='rviz2',
            executable='rviz2',
            namespace=value['namespace'],
            arguments=['-d', config, '-f', value['frame_id']],
            parameters=[{'use_sim_time': common['use_sim_time']}],
            output='screen',
        ))
    return actions


def generate_launch_description():
    """Return the launch description: the arguments, then the node (and RViz)."""
    return LaunchDescription([
        *(DeclareLaunchArgument(name, default_value=default, description=description)
          for name, default, description in ARGUMENTS),
        OpaqueFunction(function=_node),
    ])
