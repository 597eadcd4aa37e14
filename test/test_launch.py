# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The launch files and the RViz configuration name only things that exist.

``launch`` and ``launch_ros`` are not on PyPI, so the launch files are parsed,
not run: the .py with :mod:`ast`, the .xml with ElementTree. Each must start
installed executables of this package (console scripts in setup.py), set
parameters the node declares (read from mech_kinematics/ros/ by
:func:`helpers.node_parameters`), declare the arguments of issue 13 with the
same defaults in both formats, and be installed by setup.py. See issue 13.
"""

import ast
from pathlib import Path
import re
import xml.etree.ElementTree as ET

from helpers import console_scripts, installed_files, node_parameters
import pytest
import yaml

import mech_kinematics as mk
from mech_kinematics.ros.parameters import spec

ROOT = Path(__file__).resolve().parent.parent
LAUNCH_PY = ROOT / 'launch' / 'kinematics.launch.py'
LAUNCH_XML = ROOT / 'launch' / 'kinematics.launch.xml'
RVIZ = ROOT / 'config' / 'mech_kinematics.rviz'
NODE_SOURCE = ROOT / 'mech_kinematics' / 'ros' / 'node.py'
PACKAGE = 'mech_kinematics'
#: Launch arguments -> the node parameter each sets ('namespace' sets the namespace).
ARGUMENTS = {'scene': 'scene', 'rate_hz': 'rate_hz', 'crank_speed_rpm': 'crank_speed_rpm',
             'markers': 'markers', 'namespace': None}


def _py_tree() -> ast.Module:
    return ast.parse(LAUNCH_PY.read_text(encoding='utf-8'))


def _py_arguments() -> dict:
    """Return {name: default} of the ARGUMENTS table of the .py launch file."""
    for node in _py_tree().body:
        if isinstance(node, ast.Assign) and getattr(node.targets[0], 'id', '') == 'ARGUMENTS':
            return {name: default for name, default, _ in ast.literal_eval(node.value)}
    raise AssertionError('kinematics.launch.py has no ARGUMENTS table')


def _py_node_calls() -> list:
    return [node for node in ast.walk(_py_tree())
            if isinstance(node, ast.Call) and getattr(node.func, 'id', '') == 'Node']


def _py_parameter_names() -> set:
    """Return the keys of the ``parameters`` dict the .py file builds for the node."""
    names = set()
    for node in ast.walk(_py_tree()):
        if isinstance(node, ast.Assign):
            for target in node.targets:
                if getattr(target, 'id', '') == 'parameters' and isinstance(node.value, ast.Dict):
                    names |= {key.value for key in node.value.keys}
                if (isinstance(target, ast.Subscript)
                        and getattr(target.value, 'id', '') == 'parameters'):
                    names.add(target.slice.value)
    return names


def _xml_root() -> ET.Element:
    return ET.parse(LAUNCH_XML).getroot()


def test_py_launch_declares_the_arguments():
    """kinematics.launch.py declares scene, rate_hz, crank_speed_rpm, markers and namespace."""
    assert set(_py_arguments()) == set(ARGUMENTS)
    calls = [node for node in ast.walk(_py_tree()) if isinstance(node, ast.Call)
             and getattr(node.func, 'id', '') == 'DeclareLaunchArgument']
    assert calls, 'no DeclareLaunchArgument'


def test_xml_launch_declares_the_same_arguments_and_defaults():
    """The .xml declares the same arguments as the .py, with the same defaults."""
    xml_arguments = {arg.get('name'): arg.get('default') for arg in _xml_root().iter('arg')}
    assert xml_arguments == _py_arguments()


def test_defaults_are_the_nodes():
    """The default scene is the node's (a packaged scene file) and so is the default rate."""
    defaults = _py_arguments()
    assert defaults['scene'] == mk.DEFAULT_SCENE
    assert (ROOT / 'config' / 'scenes' / f'{defaults["scene"]}.yaml').is_file()
    assert float(defaults['rate_hz']) == spec('rate_hz').default
    assert defaults['crank_speed_rpm'] == ''      # empty: the scene's own speed
    assert defaults['markers'] == 'false'
    assert defaults['namespace'] == ''


def test_py_launch_starts_an_installed_executable():
    """Every Node in the .py is kinematics_node of this package, a console script."""
    calls = _py_node_calls()
    assert len(calls) == 1
    keywords = {kw.arg: kw.value for kw in calls[0].keywords}
    assert ast.literal_eval(keywords['package']) == PACKAGE
    executable = ast.literal_eval(keywords['executable'])
    assert executable == 'kinematics_node'
    assert executable in console_scripts()
    assert 'namespace' in keywords and 'parameters' in keywords


def test_xml_launch_starts_an_installed_executable():
    """Every node in the .xml is kinematics_node of this package, a console script."""
    nodes = list(_xml_root().iter('node'))
    assert nodes
    for node in nodes:
        assert node.get('pkg') == PACKAGE
        assert node.get('exec') == 'kinematics_node'
        assert node.get('exec') in console_scripts()
        assert node.get('namespace') == '$(var namespace)'


def test_py_launch_sets_declared_parameters_only():
    """The .py sets exactly the parameters of its arguments, each declared by the node."""
    names = _py_parameter_names()
    assert names == {p for p in ARGUMENTS.values() if p}
    assert names <= node_parameters(), names - node_parameters()


def test_xml_launch_sets_declared_parameters_only():
    """Each .xml node sets declared parameters from the argument of the same name."""
    with_speed = 0
    for node in _xml_root().iter('node'):
        params = {p.get('name'): p.get('value') for p in node.iter('param')}
        assert set(params) <= node_parameters(), set(params) - node_parameters()
        assert {'scene', 'rate_hz', 'markers'} <= set(params)
        for name, value in params.items():
            assert value == f'$(var {name})'
        with_speed += 'crank_speed_rpm' in params
    assert with_speed == 1     # exactly one of the two alternatives passes the speed


def test_xml_launch_refers_to_declared_arguments_only():
    """Every $(var NAME) in the .xml names a declared argument, and every argument is used."""
    text = LAUNCH_XML.read_text(encoding='utf-8')
    used = set(re.findall(r'\$\(var (\w+)\)', text))
    declared = {arg.get('name') for arg in _xml_root().iter('arg')}
    assert used == declared
    assert not re.search(r'\$\((find-pkg-share|find-exec|find-pkg-prefix|dirname)', text)


def test_xml_speed_alternatives_exclude_each_other():
    """The two node groups are guarded by complementary conditions on crank_speed_rpm."""
    conditions = sorted(group.get('if') for group in _xml_root().iter('group'))
    assert conditions == [
        "$(eval \"'$(var crank_speed_rpm)' != ''\")",
        "$(eval \"'$(var crank_speed_rpm)' == ''\")",
    ]


@pytest.mark.parametrize('path', [LAUNCH_PY, LAUNCH_XML, RVIZ], ids=lambda p: p.name)
def test_installed_by_setup_py(path):
    """setup.py installs the launch files to share/mech_kinematics/launch and the rviz config."""
    relative = path.relative_to(ROOT).as_posix()
    folder = 'launch' if path.parent.name == 'launch' else 'config'
    assert installed_files().get(f'share/{PACKAGE}/{folder}/{path.name}') == relative


def test_rviz_config_shows_the_nodes_frame_tf_and_markers():
    """The RViz config's fixed frame is the node's frame_id; it shows TF and the markers."""
    config = yaml.safe_load(RVIZ.read_text(encoding='utf-8'))
    manager = config['Visualization Manager']
    assert manager['Global Options']['Fixed Frame'] == spec('frame_id').default
    displays = {display['Class']: display for display in manager['Displays']}
    assert displays['rviz_default_plugins/TF']['Enabled'] is True
    markers = displays['rviz_default_plugins/MarkerArray']
    assert markers['Enabled'] is True
    assert markers['Topic']['Value'] == '/markers'
    # The node publishes on the relative name 'markers' (so /markers without a namespace).
    assert "create_publisher(MarkerArray, 'markers'" in NODE_SOURCE.read_text(encoding='utf-8')
