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
from mech_kinematics.ros import topics
from mech_kinematics.ros.parameters import spec

ROOT = Path(__file__).resolve().parent.parent
LAUNCH_PY = ROOT / 'launch' / 'kinematics.launch.py'
LAUNCH_XML = ROOT / 'launch' / 'kinematics.launch.xml'
#: The five-line example of docs/node.md: a node driven by the motors' joint_states (issue 18).
CLOSED_CHAIN = ROOT / 'launch' / 'closed_chain.launch.py'
RVIZ = ROOT / 'config' / 'mech_kinematics.rviz'
PUBLISHING_SOURCE = ROOT / 'mech_kinematics' / 'ros' / 'publishing.py'
PACKAGE = 'mech_kinematics'
#: Launch arguments -> the node parameter each sets ('namespace' sets the namespace,
#: 'params_file' the parameters file, 'rviz' starts RViz).
ARGUMENTS = {'scene': 'scene', 'rate_hz': 'rate_hz', 'crank_speed_rpm': 'crank_speed_rpm',
             'markers': 'markers', 'namespace': None, 'frame_id': 'frame_id',
             'tf_prefix': 'tf_prefix', 'use_sim_time': 'use_sim_time', 'params_file': None,
             'rviz': None}
#: Parameters set whether or not a params_file is given (issue 20).
COMMON = {'frame_id', 'tf_prefix', 'use_sim_time'}
KINEMATICS_NODE_YAML = ROOT / 'config' / 'kinematics_node.yaml'


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
    """Return the keys of the ``parameters`` and ``common`` dicts the .py file builds."""
    names = set()
    for node in ast.walk(_py_tree()):
        if isinstance(node, ast.Assign):
            for target in node.targets:
                if getattr(target, 'id', '') in ('parameters', 'common') \
                        and isinstance(node.value, ast.Dict):
                    names |= {key.value for key in node.value.keys}
                if (isinstance(target, ast.Subscript)
                        and getattr(target.value, 'id', '') == 'parameters'):
                    names.add(target.slice.value)
    return names


def _xml_root() -> ET.Element:
    return ET.parse(LAUNCH_XML).getroot()


def test_py_launch_declares_the_arguments():
    """kinematics.launch.py declares the arguments of issues 13 and 20."""
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
    assert defaults['frame_id'] == spec('frame_id').default
    assert defaults['tf_prefix'] == spec('tf_prefix').default == ''
    assert (defaults['use_sim_time'], defaults['params_file'], defaults['rviz']) == \
        ('false', '', 'false')


def test_py_launch_starts_an_installed_executable():
    """The .py starts kinematics_node of this package (a console script), and RViz."""
    calls = _py_node_calls()
    assert len(calls) == 2
    by_executable = {ast.literal_eval({kw.arg: kw.value for kw in c.keywords}['executable']): c
                     for c in calls}
    assert set(by_executable) == {'kinematics_node', 'rviz2'}
    rviz = {kw.arg: kw.value for kw in by_executable['rviz2'].keywords}
    assert ast.literal_eval(rviz['package']) == 'rviz2'
    assert ast.unparse(rviz['namespace']) == "value['namespace']"    # the node's namespace
    keywords = {kw.arg: kw.value for kw in by_executable['kinematics_node'].keywords}
    assert ast.literal_eval(keywords['package']) == PACKAGE
    executable = ast.literal_eval(keywords['executable'])
    assert executable == 'kinematics_node'
    assert executable in console_scripts()
    assert 'namespace' in keywords and 'parameters' in keywords


def test_xml_launch_starts_an_installed_executable():
    """Every node in the .xml but RViz is kinematics_node of this package, a console script."""
    nodes = [node for node in _xml_root().iter('node') if node.get('exec') != 'rviz2']
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
    with_speed = with_file = 0
    for node in _xml_root().iter('node'):
        if node.get('exec') == 'rviz2':
            continue
        params = {p.get('name'): p.get('value') for p in node.iter('param') if p.get('name')}
        files = [p.get('from') for p in node.iter('param') if p.get('from')]
        assert set(params) <= node_parameters(), set(params) - node_parameters()
        assert set(params) >= COMMON
        if files:
            assert files == ['$(var params_file)'] and set(params) == COMMON
            with_file += 1
        else:
            assert {'scene', 'rate_hz', 'markers'} <= set(params)
        for name, value in params.items():
            assert value == f'$(var {name})'
        with_speed += 'crank_speed_rpm' in params
    assert with_speed == 1     # exactly one of the alternatives passes the speed
    assert with_file == 1


def test_xml_launch_refers_to_declared_arguments_only():
    """Every $(var NAME) in the .xml names a declared argument, and every argument is used."""
    text = LAUNCH_XML.read_text(encoding='utf-8')
    used = set(re.findall(r'\$\(var (\w+)\)', text))
    declared = {arg.get('name') for arg in _xml_root().iter('arg')}
    assert used == declared
    # The one file it finds is this package's RViz config, which setup.py installs.
    assert re.findall(r'\$\((find-pkg-share|find-exec|find-pkg-prefix|dirname)[^)]*\)[^ "]*',
                      text) == ['find-pkg-share']
    assert '$(find-pkg-share mech_kinematics)/config/mech_kinematics.rviz' in text
    assert installed_files()[f'share/{PACKAGE}/config/mech_kinematics.rviz'] == \
        'config/mech_kinematics.rviz'


def test_xml_speed_alternatives_exclude_each_other():
    """The three node groups are guarded by conditions of which exactly one holds."""
    conditions = [group.get('if') for group in _xml_root().iter('group')]
    assert len(conditions) == 3
    for params_file in ('', 'p.yaml'):
        for speed in ('', '30'):
            holding = 0
            for condition in conditions:
                expression = re.fullmatch(r'\$\(eval "(.*)"\)', condition)[1]
                expression = expression.replace('$(var params_file)', params_file).replace(
                    '$(var crank_speed_rpm)', speed)
                holding += eval(expression)     # noqa: S307 - the file's own expressions
            assert holding == 1, (params_file, speed)


def test_xml_rviz_follows_the_namespace_and_frame():
    """rviz:=true starts rviz2 in the node's namespace, with the config and fixed frame."""
    rviz = [node for node in _xml_root().iter('node') if node.get('exec') == 'rviz2']
    assert len(rviz) == 1
    assert rviz[0].get('if') == '$(var rviz)' and rviz[0].get('pkg') == 'rviz2'
    assert rviz[0].get('namespace') == '$(var namespace)'
    assert rviz[0].get('args') == ('-d $(find-pkg-share mech_kinematics)/config/'
                                   'mech_kinematics.rviz -f $(var frame_id)')


def test_parameters_file_points_to_files_that_exist():
    """config/kinematics_node.yaml names docs/scene_format.md, not a contract file users lack."""
    text = KINEMATICS_NODE_YAML.read_text(encoding='utf-8')
    assert 'SCENE_FORMAT' + '.md' not in text
    for path in re.findall(r'\b((?:docs|config)/[\w./*-]+\.(?:md|yaml))', text):
        assert list(ROOT.glob(path)), path
    assert 'docs/scene_format.md' in text
    values = yaml.safe_load(text)['/**']['ros__parameters']
    assert set(values) <= node_parameters()


@pytest.mark.parametrize('path', [LAUNCH_PY, LAUNCH_XML, CLOSED_CHAIN, RVIZ],
                         ids=lambda p: p.name)
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
    # Relative names, as the node publishes them: RViz in the node's namespace sees its
    # topics (issue 20); nothing hard-codes /markers.
    assert markers['Topic']['Value'] == 'markers'
    source = PUBLISHING_SOURCE.read_text(encoding='utf-8')
    assert topics.MARKERS == 'markers'
    assert 'create_publisher(MarkerArray, topics.MARKERS' in source
    model = displays['rviz_default_plugins/RobotModel']
    assert model['Enabled'] is True and model['Description Source'] == 'Topic'
    assert model['Description Topic']['Value'] == 'robot_description'
    assert model['Description Topic']['Durability Policy'] == 'Transient Local'
    assert topics.ROBOT_DESCRIPTION == 'robot_description'
    assert '_publisher(String, topics.ROBOT_DESCRIPTION' in source
    assert 'Value: /' not in RVIZ.read_text(encoding='utf-8')     # no absolute topic


def test_closed_chain_launch_drives_the_node_from_the_motors_topic():
    """closed_chain.launch.py: kinematics_node, drive: topic, input remapped (issue 18).

    It compiles, names a packaged scene and declared parameters only, and is
    what docs/node.md shows.
    """
    source = CLOSED_CHAIN.read_text(encoding='utf-8')
    tree = ast.parse(source)
    compile(tree, str(CLOSED_CHAIN), 'exec')
    [call] = [node for node in ast.walk(tree)
              if isinstance(node, ast.Call) and getattr(node.func, 'id', '') == 'Node']
    keywords = {kw.arg: ast.literal_eval(kw.value) for kw in call.keywords}
    assert keywords['package'] == PACKAGE
    assert keywords['executable'] == 'kinematics_node' in console_scripts()
    [parameters] = keywords['parameters']
    assert set(parameters) <= node_parameters()
    assert parameters['drive'] == 'topic' and 'topic' in spec('drive').choices
    assert parameters['scene'] in mk.scene_names()
    assert keywords['remappings'] == [(topics.INPUT_JOINT_STATES, '/motors/joint_states')]
    # docs/node.md shows this file's function, without its docstring: five lines.
    function = tree.body[-1]
    lines = ast.get_source_segment(source, function).splitlines()
    shown = [lines[0], *lines[2:]]
    assert len(shown) == 5
    assert '\n'.join(shown) in (ROOT / 'docs' / 'node.md').read_text(encoding='utf-8')
