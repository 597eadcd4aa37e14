# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The layers and their arrows: core <- geometry, verify <- ROS layer and tools. See issue 9.

- the solver core (errors, units, the solver package, scene, textbook) imports only NumPy,
  PyYAML and the standard library;
- geometry imports the core only, and never matplotlib;
- a robot described in URDF (``robot/``: reading it, mapping its loops onto the kinds)
  imports the core and geometry only, never rclpy; the node and the tools build on it;
- the verification room (``verify/``: the 50-digit reference, the extreme suite) sits
  beside geometry: it imports the core and geometry, never a tool or the ROS layer; the
  tools (the report) import it (issue 30);
- the ROS layer never imports a tool (drawing, report, recorder) nor matplotlib;
- the bag writer (``bag/``) imports the core only; the tools use it;
- building the command line for ``solve`` imports no heavy dependency.
"""

import ast
from pathlib import Path
import subprocess
import sys

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / 'mech_kinematics'
CORE = ('errors', 'units', 'linkage', 'solver', 'scene', 'textbook')
#: Subpackages that belong to the core (the solver, one module per concern and per step kind).
CORE_PACKAGES = ('solver',)
HEAVY = ('rclpy', 'matplotlib', 'mpmath', 'scipy', 'rosbags', 'tqdm')

#: Layer of each subpackage (modules at the top are the core), and what each may import.
LAYERS = {'core': set(), 'data': set(), 'geometry': {'core'}, 'robot': {'core', 'geometry'},
          'verify': {'core', 'geometry'}, 'ros': {'core', 'geometry', 'robot'}, 'bag': {'core'},
          'tools': {'core', 'geometry', 'robot', 'ros', 'data', 'bag', 'verify'}}


def _modules_after(code: str) -> set:
    """Return the top-level names in sys.modules after running ``code`` in a fresh Python."""
    result = subprocess.run(
        [sys.executable, '-c', f'{code}\nimport sys\nprint(" ".join(sorted(sys.modules)))'],
        capture_output=True, text=True, check=True, timeout=120)
    return {name.split('.')[0] for name in result.stdout.split()}


def test_core_imports_only_numpy_yaml_and_the_standard_library():
    """Importing the package and the solver core loads nothing but NumPy, PyYAML and stdlib."""
    imports = ', '.join(f'mech_kinematics.{m}' for m in CORE)
    # What the interpreter loads before any import of ours (site hooks of the venv).
    baseline = _modules_after('pass')
    loaded = _modules_after(f'import mech_kinematics, {imports}') - baseline
    # cython_runtime comes with NumPy's compiled extensions.
    allowed = set(sys.stdlib_module_names) | {'numpy', 'cython_runtime', 'yaml', 'mech_kinematics'}
    extra = {n for n in loaded - allowed if not n.startswith('_')}
    assert not extra, extra


def test_the_robot_layer_is_pure():
    """Reading a URDF robot and solving it loads neither rclpy nor matplotlib nor a tool."""
    loaded = _modules_after('import mech_kinematics.robot')
    assert not loaded & {'rclpy', 'matplotlib'}, loaded & {'rclpy', 'matplotlib'}


def test_the_node_imports_no_drawing_or_report_code():
    """Importing the node module loads neither matplotlib nor any tool module."""
    result = subprocess.run(
        [sys.executable, '-c', 'import mech_kinematics.ros.node, sys; '
         'print(" ".join(sorted(sys.modules)))'],
        capture_output=True, text=True, check=True, timeout=120)
    loaded = result.stdout.split()
    assert 'matplotlib' not in loaded
    assert not [m for m in loaded if m.startswith('mech_kinematics.tools')]


def test_solve_builds_its_command_line_without_heavy_imports():
    """Parsing `solve` arguments (every tool registered) imports none of the heavy packages."""
    loaded = _modules_after('from mech_kinematics.__main__ import build_parser\n'
                            "build_parser().parse_args(['solve', 'x'])")
    assert not loaded & set(HEAVY), loaded & set(HEAVY)


def _layer(path: Path) -> str:
    relative = path.relative_to(PACKAGE)
    if len(relative.parts) == 1 or relative.parts[0] in CORE_PACKAGES:
        return 'core'
    return relative.parts[0]


def _imported_layers(path: Path):
    """Yield (line, layer) of every import of a mech_kinematics module in ``path``."""
    tree = ast.parse(path.read_text(encoding='utf-8'))
    here = path.relative_to(PACKAGE).parent.parts
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = list(here[:len(here) - node.level + 1])
                parts = base + (node.module.split('.') if node.module else [])
            elif node.module and node.module.split('.')[0] == 'mech_kinematics':
                parts = node.module.split('.')[1:]
            else:
                continue
            names = [parts] if parts else [[alias.name] for alias in node.names]
        elif isinstance(node, ast.Import):
            names = [n.name.split('.')[1:] for n in node.names
                     if n.name.split('.')[0] == 'mech_kinematics']
        else:
            continue
        for parts in names:
            if parts:
                yield node.lineno, parts[0] if parts[0] in LAYERS else 'core'


#: The entry points sit above every layer: they may import anything.
ENTRY_POINTS = (PACKAGE / '__main__.py', PACKAGE / 'kinematics_node.py')


@pytest.mark.parametrize('path', [p for p in sorted(PACKAGE.rglob('*.py'))
                                  if p not in ENTRY_POINTS],
                         ids=lambda p: str(p.relative_to(PACKAGE)))
def test_arrows_run_one_way(path):
    """A module imports only from its own layer and the layers below it."""
    layer = _layer(path)
    for line, target in _imported_layers(path):
        assert target == layer or target in LAYERS[layer], \
            f'{path.relative_to(PACKAGE)}:{line} ({layer}) imports from {target}'


#: Private names a layer may use of objects it did not define: the standard library's.
STANDARD_PRIVATE = {'_exit'}


def _private_names_defined(paths) -> set:
    """Return the private names (``_x``) that ``paths`` define: functions, classes, attributes."""
    names = set()
    for path in paths:
        for node in ast.walk(ast.parse(path.read_text(encoding='utf-8'))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                names.add(node.name)
            elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store):
                names.add(node.attr)
            elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
                names.add(node.id)
            elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
                names.add(node.target.id)
    return {name for name in names if name.startswith('_') and not name.startswith('__')}


def _layer_paths(layer: str) -> list:
    if layer == 'core':
        return sorted(p for p in PACKAGE.rglob('*.py') if _layer(p) == 'core')
    return sorted((PACKAGE / layer).rglob('*.py'))


@pytest.mark.parametrize('layer', sorted(set(LAYERS) - {'core', 'data'}))
def test_a_layer_reads_and_writes_no_private_field_of_another(layer):
    """Above the core, a layer asks the layers below through public calls (issue 45).

    An attribute ``X._name`` on anything but ``self`` or ``cls`` names a private
    field: it must be one its own module defines, or one its layer defines and no
    layer below it does (the ROS layer once wrote ``scene._solver.compiled_single``,
    the core's; it now calls ``solver.keep_general_path``).
    """
    paths = _layer_paths(layer)
    below = set().union(*(_private_names_defined(_layer_paths(other)) for other in LAYERS[layer]))
    layer_own = _private_names_defined(paths) - below
    foreign = []
    for path in paths:
        own = _private_names_defined([path]) | layer_own | STANDARD_PRIVATE
        for node in ast.walk(ast.parse(path.read_text(encoding='utf-8'))):
            mine = isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) \
                and node.value.id in ('self', 'cls')
            if isinstance(node, ast.Attribute) and node.attr.startswith('_') and not mine \
                    and not node.attr.startswith('__') and node.attr not in own:
                foreign.append(f'{path.relative_to(PACKAGE)}:{node.lineno}: {ast.unparse(node)}')
    assert foreign == []


#: Facts with one home each: the literal, and the module that may spell it.
ONE_HOME = {
    '1_000_000_000': 'units.py',
    "'joint_states'": 'ros/topics.py',
    "'joint_accelerations'": 'ros/topics.py',
    "'point_accelerations'": 'ros/topics.py',
    "'diagnostics'": 'ros/topics.py',
    "'/tf'": 'ros/topics.py',
    "'/tf_static'": 'ros/topics.py',
}


@pytest.mark.parametrize('literal, home', ONE_HOME.items(), ids=list(ONE_HOME))
def test_each_fact_is_spelled_in_its_home_only(literal, home):
    """NS_PER_S and the node's topic names are written once; every other module imports them."""
    spelled = sorted(str(p.relative_to(PACKAGE)) for p in PACKAGE.rglob('*.py')
                     if literal in p.read_text(encoding='utf-8'))
    assert spelled == [home]


#: The step kinds and drivers: each is one module with a test file of its own.
KIND_MODULES = ('crank', 'actuator', 'rrr', 'rrp', 'rpr', 'rpp', 'geneva', 'carried')


def test_every_kind_module_has_its_own_test_file():
    """Tests mirror the package: each kind's module has test/solver/test_<kind>.py."""
    tests = Path(__file__).resolve().parent / 'solver'
    for kind in KIND_MODULES:
        assert (PACKAGE / 'solver' / f'{kind}.py').is_file(), kind
        assert (tests / f'test_{kind}.py').is_file(), f'no test/solver/test_{kind}.py'


def test_no_test_file_is_named_after_a_module_that_does_not_exist():
    """A test/solver/test_X*.py names an existing solver module X (or the solver's solve)."""
    modules = {path.stem for path in (PACKAGE / 'solver').glob('*.py')}
    for path in (Path(__file__).resolve().parent / 'solver').glob('test_*.py'):
        name = path.stem.removeprefix('test_')
        assert any(name == m or name.startswith(m + '_') for m in modules), path.name
