# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""What a ROS user and a fresh clone get: executables, declared dependencies, pinned wheels.

- every tool of ``python -m mech_kinematics`` is a console script (``ros2 run
  mech_kinematics NAME``), installed and answering ``--help``;
- every module the package, its launch files and its tests import is declared
  in package.xml under its rosdep key (an explicit table maps module names to
  keys; an unmapped module fails);
- requirements.txt (running) and requirements-dev.txt (test and lint) pin a
  complete set each, split so that ``make run`` installs no test tool.

See issue 13.
"""

import ast
import configparser
import functools
from importlib import metadata
from pathlib import Path
import re
import subprocess
import sys
import xml.etree.ElementTree as ET

from helpers import console_scripts
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name
import pytest
import yaml

from mech_kinematics.__main__ import TOOLS

ROOT = Path(__file__).resolve().parent.parent
PACKAGE_XML = ROOT / 'package.xml'
REQUIREMENTS = ROOT / 'requirements.txt'
REQUIREMENTS_DEV = ROOT / 'requirements-dev.txt'
ROSDEP_SOURCE = ROOT / 'rosdep' / 'mech_kinematics.yaml'

#: Tools of `python -m mech_kinematics` that are not ROS executables, and why.
NOT_EXECUTABLES = {'run': "make run's wrapper (node + console view); ros2 launch is ROS's"}

#: Top-level module -> its rosdep key. A module imported and not listed here fails the test.
ROSDEP_KEYS = {
    # ROS packages (the key is the package name)
    'rclpy': 'rclpy',
    'ament_index_python': 'ament_index_python',
    'builtin_interfaces': 'builtin_interfaces',
    'std_msgs': 'std_msgs',
    'geometry_msgs': 'geometry_msgs',
    'sensor_msgs': 'sensor_msgs',
    'trajectory_msgs': 'trajectory_msgs',
    'diagnostic_msgs': 'diagnostic_msgs',
    'visualization_msgs': 'visualization_msgs',
    'tf2_msgs': 'tf2_msgs',
    'rcl_interfaces': 'rcl_interfaces',
    'rosgraph_msgs': 'rosgraph_msgs',
    'lifecycle_msgs': 'lifecycle_msgs',
    'rosidl_parser': 'rosidl_parser',
    'launch': 'launch',
    'launch_ros': 'launch_ros',
    # ROS's Python URDF reader (the urdfdom_py package) reads a robot's links and joints
    'urdf_parser_py': 'urdfdom_py',
    # Python packages (rosdistro's rosdep/python.yaml and base.yaml keys)
    'numpy': 'python3-numpy',
    'yaml': 'python3-yaml',
    'matplotlib': 'python3-matplotlib',
    'scipy': 'python3-scipy',
    'mpmath': 'python3-mpmath',
    'tqdm': 'python3-tqdm',
    'PIL': 'python3-pil',
    'pytest': 'python3-pytest',
    'hypothesis': 'python3-hypothesis',
    'packaging': 'python3-packaging',
    'lxml': 'python3-lxml',
    'setuptools': 'python3-setuptools',
    # On PyPI only: -pip keys, defined in rosdep/mech_kinematics.yaml
    'rosbags': 'python3-rosbags-pip',
    'mcap': 'python3-mcap-pip',
    'mcap_ros2': 'python3-mcap-ros2-support-pip',
}
#: Modules the package imports only inside the functions of one development command, and
#: the requirements-dev.txt pin that brings them: the peer of ``bench --peer`` (issue 22).
DEV_PEERS = {'pylinkage': 'pylinkage'}
#: Modules the venv gets from no wheel: built by scripts/build_tf2_msgs.py at set-up.
BUILT_AT_SETUP = {'tf2_msgs'}
#: Test and lint tools: requirements-dev.txt only, never requirements.txt.
DEV_TOOLS = {'pytest', 'hypothesis', 'mcap', 'mcap-ros2-support', 'flake8', 'flake8-docstrings',
             'flake8-import-order', 'flake8-quotes', 'pydocstyle', 'ruff', 'mypy',
             'types-pyyaml'}


@functools.lru_cache(maxsize=None)
def _import_statements(path: Path) -> tuple:
    """Return ``(names, level, top_level)`` of each import statement of the file, in order.

    Each file is parsed once for all the tests of this module.
    """
    tree = ast.parse(path.read_text(encoding='utf-8'))
    top = {id(node) for node in tree.body}
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.append((tuple(alias.name for alias in node.names), 0, id(node) in top))
        elif isinstance(node, ast.ImportFrom):
            found.append(((node.module,), node.level, id(node) in top))
    return tuple(found)


def _imports(folder: Path, peers: bool = False) -> dict:
    """Return {top-level module: first file importing it} for absolute imports under ``folder``.

    The :data:`DEV_PEERS` are left out unless ``peers``.
    """
    # test/ imports its own helpers, and a test module its folder's (pytest puts it on the path)
    local = {path.stem for path in folder.rglob('*.py')}
    found: dict = {}
    for path in sorted(folder.rglob('*.py')):
        for names, level, _ in _import_statements(path):
            if level != 0:
                continue
            for name in names:
                top = name.split('.')[0]
                if top in DEV_PEERS and not peers:
                    continue
                if top not in sys.stdlib_module_names and top not in local | {'mech_kinematics'}:
                    found.setdefault(top, path.relative_to(ROOT).as_posix())
    return found


def _depends(*tags: str) -> set:
    root = ET.parse(PACKAGE_XML).getroot()
    return {element.text.strip() for tag in tags for element in root.iter(tag)}


def _pins(path: Path) -> dict:
    """Return {canonical name: version} of a requirements file, following ``-r``."""
    pins = {}
    for raw in path.read_text(encoding='utf-8').splitlines():
        line = raw.split('#')[0].strip()
        if line.startswith('-r '):
            pins.update(_pins(path.parent / line[3:].strip()))
        elif line:
            assert '==' in line, f'{path.name}: expected NAME==VERSION, got {raw!r}'
            name, version = line.split('==')
            pins[canonicalize_name(name)] = version.strip()
    return pins


@pytest.mark.parametrize('folder, tags', [
    ('mech_kinematics', ('exec_depend', 'depend')),
    ('launch', ('exec_depend', 'depend')),
    ('test', ('exec_depend', 'depend', 'test_depend')),
])
def test_every_import_is_declared_in_package_xml(folder, tags):
    """Each module imported under the folder maps to a rosdep key that package.xml declares."""
    imported = _imports(ROOT / folder)
    unmapped = {module: path for module, path in imported.items() if module not in ROSDEP_KEYS}
    assert not unmapped, f'imports with no rosdep key in ROSDEP_KEYS: {unmapped}'
    declared = _depends(*tags)
    missing = {ROSDEP_KEYS[module]: path for module, path in imported.items()
               if ROSDEP_KEYS[module] not in declared}
    assert not missing, f'package.xml lacks <{tags[0]}> for {missing}'


def test_package_xml_declares_what_issue_13_lists():
    """The message packages of TF, lifecycle and sim time, and the launch packages, are there."""
    exec_depends = _depends('exec_depend', 'depend')
    assert {'tf2_msgs', 'lifecycle_msgs', 'rosgraph_msgs', 'geometry_msgs', 'launch',
            'launch_ros', 'launch_xml', 'python3-rosbags-pip'} <= exec_depends
    description = ET.parse(PACKAGE_XML).getroot().findtext('description')
    for word in ('four-bar', 'slider-crank', 'quick return', 'Whitworth', 'Geneva',
                 'six-link', 'kinematics_node', 'solve', 'record', 'plot', 'diagram', 'report',
                 'bench'):
        assert word in description, word


def test_rosdep_source_defines_the_pip_keys():
    """rosdep/mech_kinematics.yaml defines every -pip key of package.xml, and no unused key."""
    keys = set(yaml.safe_load(ROSDEP_SOURCE.read_text(encoding='utf-8')))
    declared = _depends('exec_depend', 'depend', 'test_depend')
    assert {key for key in declared if key.endswith('-pip')} <= keys
    assert keys <= declared


def test_runtime_imports_are_installed_by_requirements_txt():
    """Each module the package imports comes from a wheel pinned in requirements.txt."""
    runtime = _pins(REQUIREMENTS)
    distributions = metadata.packages_distributions()
    for module, path in _imports(ROOT / 'mech_kinematics').items():
        if module in BUILT_AT_SETUP:
            assert (ROOT / 'scripts' / f'build_{module}.py').is_file()
            continue
        names = {canonicalize_name(name) for name in distributions.get(module, ())}
        assert names & set(runtime), (
            f'{path} imports {module} (from {sorted(names) or "no distribution"}), '
            'which requirements.txt does not pin')


def test_dev_peers_are_pinned_for_development_and_imported_only_inside_functions():
    """A peer package (bench --peer) comes from requirements-dev.txt and never loads on import."""
    for distribution in DEV_PEERS.values():
        assert distribution in _pins(REQUIREMENTS_DEV) and distribution not in _pins(REQUIREMENTS)
    found = _imports(ROOT / 'mech_kinematics', peers=True)
    assert set(DEV_PEERS) <= set(found), 'a peer no longer imported: drop it from DEV_PEERS'
    for path in sorted((ROOT / 'mech_kinematics').rglob('*.py')):
        for names, _, top_level in _import_statements(path):
            if top_level:       # top-level statements only: imports run on import
                assert not {name.split('.')[0] for name in names if name} & set(DEV_PEERS), path


def test_requirements_txt_holds_no_test_or_lint_tool():
    """`make run` installs no test or lint tool; requirements-dev.txt adds them."""
    assert not DEV_TOOLS & set(_pins(REQUIREMENTS))
    assert set(_pins(REQUIREMENTS_DEV)) >= DEV_TOOLS
    assert '-r requirements.txt' in REQUIREMENTS_DEV.read_text(encoding='utf-8').splitlines()


@pytest.mark.parametrize('path', [REQUIREMENTS, REQUIREMENTS_DEV], ids=lambda p: p.name)
def test_pins_are_complete_and_installed(path):
    """Every dependency of every pinned wheel is pinned in the same file, at a version it accepts.

    Checked against the metadata of the installed wheels, which must be the pinned versions.
    """
    pins = _pins(path)
    problems = []
    for name, version in sorted(pins.items()):
        try:
            installed = metadata.distribution(name)
        except metadata.PackageNotFoundError:
            problems.append(f'{name}=={version} is not installed')
            continue
        if installed.version != version:
            problems.append(f'{name}: pinned {version}, installed {installed.version}')
        for text in installed.requires or ():
            requirement = Requirement(text)
            if requirement.marker and not requirement.marker.evaluate({'extra': ''}):
                continue
            needed = canonicalize_name(requirement.name)
            if needed not in pins:
                problems.append(f'{name} needs {requirement}, not pinned in {path.name}')
            elif not requirement.specifier.contains(pins[needed], prereleases=True):
                problems.append(f'{name} needs {requirement}, pinned {pins[needed]}')
    assert not problems, '\n'.join(problems)


def test_every_tool_is_a_console_script():
    """Each tool but run is a console script `NAME = mech_kinematics.tools.NAME:main`."""
    scripts = console_scripts()
    assert scripts.pop('kinematics_node') == 'mech_kinematics.kinematics_node:main'
    tools = {module.__name__.rsplit('.', 1)[1]: module for module in TOOLS}
    expected = {name: f'mech_kinematics.tools.{name}:main'
                for name in tools if name not in NOT_EXECUTABLES}
    missing = [f"'{name} = {target}'" for name, target in expected.items()
               if scripts.get(name) != target]
    assert not missing, f'add to console_scripts in setup.py: {", ".join(missing)}'
    assert set(scripts) == set(expected), set(scripts) ^ set(expected)
    for name in scripts:
        assert callable(tools[name].main)
    assert {'solve', 'record', 'plot', 'diagram', 'report', 'bench'} <= set(scripts)


def test_scripts_install_to_lib_for_ros2_run():
    """setup.cfg puts the console scripts in lib/mech_kinematics, where ros2 run looks."""
    config = configparser.ConfigParser()
    config.read(ROOT / 'setup.cfg')
    assert config['develop']['script_dir'] == '$base/lib/mech_kinematics'
    assert config['install']['install_scripts'] == '$base/lib/mech_kinematics'


@pytest.mark.parametrize('name', sorted(set(console_scripts()) - {'kinematics_node'}))
def test_console_script_is_installed_and_answers_help(name):
    """After make install, .venv/bin/NAME exists and `NAME --help` prints its usage, status 0."""
    script = Path(sys.prefix) / 'bin' / name
    assert script.is_file(), f'{script} missing: run make install'
    result = subprocess.run([str(script), '--help'], capture_output=True, text=True, timeout=120,
                            check=False)
    assert result.returncode == 0, result.stderr
    assert re.match(rf'usage: .*\b{name}\b', result.stdout), result.stdout[:200]
