# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""package.xml follows package format 3, and every XML file is well formed.

The format 3 XSD is only online, so its structure is checked here in Python:
element order, required elements and attributes, and value patterns.
"""

import ast
from pathlib import Path
import re
import shutil
import subprocess
import xml.etree.ElementTree as ET

import pytest

ROOT = Path(__file__).resolve().parent.parent
PACKAGE_XML = ROOT / 'package.xml'
SKIP_DIRS = {'.git', '.venv', 'build', 'install', 'log', '.hypothesis', '.pytest_cache'}

# package_format3.xsd: a sequence of these groups, in this order.
HEAD = ('name', 'version', 'description')
REPEATED = ('maintainer', 'license', 'url', 'author')
DEPENDS = {
    'build_depend', 'build_export_depend', 'buildtool_depend', 'buildtool_export_depend',
    'exec_depend', 'depend', 'doc_depend', 'test_depend', 'conflict', 'replace',
    'group_depend', 'member_of_group',
}
EXEC_DEPENDS = {
    'rclpy', 'sensor_msgs', 'trajectory_msgs', 'diagnostic_msgs', 'visualization_msgs',
    'rcl_interfaces', 'builtin_interfaces', 'python3-numpy', 'python3-yaml',
}
TEST_DEPENDS = {
    'ament_copyright', 'ament_flake8', 'ament_pep257', 'ament_xmllint', 'python3-pytest',
}


def _xml_files():
    for path in sorted(ROOT.rglob('*.xml')):
        if not SKIP_DIRS.intersection(path.relative_to(ROOT).parts):
            yield path


def _setup_py_value(keyword):
    """Return the literal value given to ``setup(keyword=...)`` or a module constant."""
    tree = ast.parse((ROOT / 'setup.py').read_text(encoding='utf-8'))
    constants = {
        node.targets[0].id: node.value for node in tree.body
        if isinstance(node, ast.Assign) and isinstance(node.targets[0], ast.Name)
    }
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and getattr(node.func, 'id', '') == 'setup':
            for kw in node.keywords:
                if kw.arg == keyword:
                    value = constants.get(getattr(kw.value, 'id', ''), kw.value)
                    return ast.literal_eval(value)
    raise AssertionError(f'setup.py does not pass {keyword}=')


@pytest.mark.linter
@pytest.mark.xmllint
def test_xml_well_formed():
    """Every XML file in the repository parses (and passes xmllint if installed)."""
    files = list(_xml_files())
    assert PACKAGE_XML in files
    for path in files:
        ET.parse(path)
    xmllint = shutil.which('xmllint')
    if xmllint:
        result = subprocess.run([xmllint, '--noout', *map(str, files)],
                                capture_output=True, text=True, timeout=60, check=False)
        assert result.returncode == 0, result.stderr


@pytest.mark.linter
@pytest.mark.xmllint
def test_package_xml_format3():
    """package.xml has format 3's elements, in order, with valid values."""
    text = PACKAGE_XML.read_text(encoding='utf-8')
    assert 'package_format3.xsd' in text
    root = ET.fromstring(text)
    assert root.tag == 'package' and root.get('format') == '3'
    tags = [child.tag for child in root]
    assert tuple(tags[:3]) == HEAD, tags

    # Remaining order: maintainer+ license+ url* author* (depends)* export?
    rest = tags[3:]
    for group in REPEATED:
        count = 0
        while rest and rest[0] == group:
            rest.pop(0)
            count += 1
        if group in ('maintainer', 'license'):
            assert count >= 1, f'package.xml needs at least one <{group}>'
    while rest and rest[0] in DEPENDS:
        rest.pop(0)
    if rest and rest[0] == 'export':
        rest.pop(0)
    assert not rest, f'unexpected or misplaced elements: {rest}'

    assert re.fullmatch(r'[a-z][a-z0-9_]*', root.findtext('name'))
    assert re.fullmatch(r'(0|[1-9]\d*)\.(0|[1-9]\d*)\.(0|[1-9]\d*)', root.findtext('version'))
    assert root.findtext('description').strip()
    for maintainer in root.iter('maintainer'):
        assert maintainer.text.strip() and '@' in maintainer.get('email', '')
    assert [lic.text for lic in root.iter('license')] == ['Apache-2.0']
    assert root.findtext('export/build_type') == 'ament_python'


@pytest.mark.linter
@pytest.mark.xmllint
def test_package_xml_matches_setup_py():
    """Name, version and dependencies agree between package.xml and setup.py."""
    root = ET.parse(PACKAGE_XML).getroot()
    assert root.findtext('name') == _setup_py_value('name') == 'mech_kinematics'
    assert root.findtext('version') == _setup_py_value('version')
    assert _setup_py_value('license') == root.findtext('license')
    exec_depends = {e.text for tag in ('exec_depend', 'depend') for e in root.iter(tag)}
    test_depends = {e.text for e in root.iter('test_depend')}
    assert not EXEC_DEPENDS - exec_depends, f'missing exec_depend: {EXEC_DEPENDS - exec_depends}'
    assert not TEST_DEPENDS - test_depends, f'missing test_depend: {TEST_DEPENDS - test_depends}'
