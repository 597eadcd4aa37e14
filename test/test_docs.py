# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The scene format reference (docs/scene_format.md) says what the program does. See issue 11.

Its scene examples load, its worked example's printed output is what the
program prints, every error message it quotes is what the loader says for
the mistake it names, its links resolve, and nothing shipped points outside
the repository.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
from pathlib import Path
import re

import pytest

import mech_kinematics as mk
from mech_kinematics.__main__ import main
from mech_kinematics.scene import read_scene_yaml

ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / 'docs' / 'scene_format.md'
README = ROOT / 'README.md'
#: README and every page of docs/, the repository's own reference.
DOCUMENTS = [README, *sorted(ROOT.joinpath('docs').rglob('*.md'))]

#: The four-bar the error table of the reference breaks, one thing at a time.
BASE = """\
name: four_bar
units: {length: mm, angle: deg}
ground:
  A: [0, 0]
  D: [150, 0]
input: {link: crank, center: A, point: B, length: 40, angle: 60, speed_rpm: -120}
dyads:
  - type: RRR
    point: C
    links:
      - {name: coupler, from: B, length: 150}
      - {name: rocker, from: D, length: 80}
    branch: 1
"""
GENEVA = """\
name: geneva_five
units: {length: mm, angle: deg}
ground: {D: [0, 0], S: [0, 100]}
input: {link: driver, center: D, point: P, length: 50, angle: 80, speed_rpm: 60}
dyads:
  - {type: RPR, link: wheel, center: S, through: P, slider: pin_slot, slots: 5}
"""
COMPOUND = BASE.replace('D: [150, 0]\n', 'D: [150, 0]\n  F: [300, 100]\n') + """\
  - type: RRR
    point: E
    links:
      - {name: link_CE, from: C, length: 120}
      - {name: link_FE, from: F, length: 100}
pins: {C: 5}
"""
YOKE = """\
name: yoke
units: {length: mm, angle: deg}
ground: {A: [0, 0]}
input: {link: crank, center: A, point: B, length: 50, angle: 30, speed_rpm: 300}
dyads:
  - {type: RPP, point: Y, through: B, guide: {through: A, angle: 0}, slot_angle: 90,
     slider: yoke, slot_slider: pin_in_slot}
"""
#: The packaged excavator (two cylinders), whose actuators the table names wrongly twice.
EXCAVATOR = (ROOT / 'config' / 'scenes' / 'excavator.yaml').read_text()
#: The four-bar with gravity, masses and loads (the reference's forces example).
LOADED = BASE + """\
gravity: [0, -9.81]
masses:
  coupler: {mass: 0.5, com: [75, 10], inertia: 6.0e-4}
  rocker: {mass: 0.3, com: [40, 0]}
loads:
  - {name: brake, link: rocker, torque: -2.0}
  - {name: push, point: C, force: [10, -5]}
"""
#: Each mistake of the reference's error table, as the scene text that makes it.
MISTAKES = {
    'no_units': BASE.replace('units: {length: mm, angle: deg}\n', ''),
    'bad_unit': BASE.replace('length: mm', 'length: inch'),
    'negative': BASE.replace('length: 80', 'length: -80'),
    'typo': BASE.replace('length: 80}', 'lenght: 80}'),
    'string': BASE.replace('length: 80', 'length: 80 mm'),
    'yes': BASE.replace('branch: 1', 'branch: yes'),
    'branch0': BASE.replace('branch: 1', 'branch: 0'),
    'leading0': BASE.replace('length: 40', 'length: 040'),
    'duplicate_key': BASE.replace('  D: [150, 0]\n', '  D: [150, 0]\n  D: [160, 0]\n'),
    'twice': BASE.replace('name: rocker', 'name: coupler'),
    'unknown_point': BASE.replace('  D: [150, 0]\n', '').replace('from: D', 'from: Q'),
    'cycle': BASE.replace('from: B', 'from: C'),
    'type': BASE.replace('type: RRR', 'type: PPP'),
    'reach': BASE.replace('length: 150}', 'length: 50}'),
    'meet': BASE.replace('length: 80}', 'length: 10}'),
    'guide': (ROOT / 'docs' / 'toggle_press.yaml').read_text().replace(
        'G: [300, 20]', 'G: [300, -60]'),
    'slots': GENEVA,
    'pin_off_crank': GENEVA.replace('slots: 5', 'slots: 6').replace('through: P', 'through: S'),
    'compound': COMPOUND,
    'parallel_slot': YOKE.replace('slot_angle: 90', 'slot_angle: 180'),
    'speed_twice': BASE.replace('speed_rpm: -120', 'speed_rpm: -120, speed: -12.566'),
    'gravity': BASE + 'imus:\n  tip: {link: coupler, point: C, gravity: [0, 1e308]}\n',
    'actuator_twice': EXCAVATOR.replace('actuator: stick_cyl\n    length: 3.0',
                                        'actuator: boom_cyl\n    length: 3.0'),
    'actuator_two_links': EXCAVATOR.replace('{name: stick_cyl_body, from: S, actuator: stick_cyl}',
                                            '{name: stick_cyl_body, from: S, actuator: boom_cyl}'),
    'negative_mass': LOADED.replace('mass: 0.5', 'mass: -0.5'),
    'mass_of_no_body': LOADED.replace('rocker: {mass', 'rockr: {mass'),
    'mass_on_ground': LOADED.replace('rocker: {mass: 0.3, com: [40, 0]}', 'ground: {mass: 0.3}'),
    'load_at_no_point': LOADED.replace('point: C, force', 'point: Q, force'),
    'load_on_ground': LOADED.replace('point: C, force', 'point: D, force'),
    'force_and_torque': LOADED.replace('force: [10, -5]}', 'force: [10, -5], link: rocker, '
                                                           'torque: 1}'),
    'gravity_shape': LOADED.replace('gravity: [0, -9.81]', 'gravity: [0, -9.81, 0]'),
    'imu_gravity': LOADED + 'imus:\n  tip: {link: coupler, point: C, gravity: [0, -9.80665]}\n',
    'free_block': (ROOT / 'config' / 'scenes' / 'geneva.yaml').read_text()
    + 'masses:\n  pin_slot: {mass: 0.1, com: [5, 0]}\n',
}


def blocks(text, language):
    """Return the fenced code blocks of ``text`` in ``language``."""
    return re.findall(rf'```{language}\n(.*?)```', text, flags=re.DOTALL)


def run(*args):
    """Return what `python -m mech_kinematics ARGS` prints and its status."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        status = main([str(a) for a in args])
    return status, out.getvalue()


@pytest.mark.parametrize('path', [DOC, README], ids=['scene_format.md', 'README.md'])
def test_scene_examples_load(path):
    """Every YAML block that is a whole scene (it starts with `name:`) loads."""
    scenes = [b for b in blocks(path.read_text(), 'yaml') if b.startswith('name:')]
    assert scenes
    for text in scenes:
        scene = mk.parse_scene(read_scene_yaml(text))
        mk.solve(scene, scene.input.angle)


def test_worked_example_is_the_file_and_prints_what_it_says(capsys):
    """docs/toggle_press.yaml is the page's example; `check` and `solve` print the quoted text."""
    path = ROOT / 'docs' / 'toggle_press.yaml'
    text = DOC.read_text()
    assert path.read_text() in [b for b in blocks(text, 'yaml') if b.startswith('name:')]
    console = next(b for b in blocks(text, 'console') if 'check docs/toggle_press.yaml' in b)
    status, out = run('check', path)
    assert status == 0
    assert out.splitlines() == console.splitlines()[1:]
    status, out = run('solve', path)
    data = json.loads(out)
    excerpt = next(b for b in blocks(text, 'json') if '"rubbing"' in b and '"ram"' in b)
    for name, value in data['rubbing'].items():
        assert f'"{name}": {value!r}' in excerpt, name
    for joint in ('rocker', 'ram'):
        for quantity in ('position', 'velocity', 'acceleration'):
            assert f'"{quantity}": {data["joints"][joint][quantity]!r}' in excerpt


def test_the_quoted_jump_is_what_solve_prints():
    """The Geneva section's excerpt at 135 deg is `solve`'s JSON: one-sided, with "jumps"."""
    excerpt = json.loads(next(b for b in blocks(DOC.read_text(), 'json') if '"jumps"' in b))
    status, out = run('solve', 'geneva', '--angle-deg', '135')
    assert status == 0
    data = json.loads(out)
    assert excerpt == {'joints': {'wheel': data['joints']['wheel']}, 'jumps': data['jumps']}
    assert excerpt['jumps']['joints']['wheel']['acceleration'] == 0.0  # the side before
    status, out = run('solve', 'geneva', '--angle-deg', '135', '--speed-rpm', '-60')
    data = json.loads(out)
    assert data['joints']['wheel']['acceleration'] == 0.0
    assert data['jumps']['joints']['wheel']['acceleration'] == pytest.approx(
        -(2 * math.pi) ** 2, rel=1e-14)


@pytest.mark.parametrize('mistake', sorted(MISTAKES))
def test_quoted_error_messages_are_the_real_ones(mistake, tmp_path):
    """Each message in the table "Errors you will meet" is the loader's, word for word."""
    path = tmp_path / f'{mistake}.yaml'
    path.write_text(MISTAKES[mistake])
    with pytest.raises(mk.SceneError) as caught:
        mk.load_scene(path)
    message = str(caught.value)
    assert message.startswith(f'{path}: ')
    assert f'`{message[len(str(path)) + 2:]}`' in DOC.read_text(), message


def test_quoted_solve_errors_are_the_real_ones():
    """The errors `solve` prints in the reference and the README are the program's."""
    quoted = [line for text in map(Path.read_text, DOCUMENTS)
              for block in blocks(text, 'console') for line in block.splitlines()
              if line.startswith('error: ') and 'cannot be solved' in line]
    assert len(quoted) >= 3
    commands = {
        'RRR C cannot be solved at crank angle 150 deg': ('four_bar_coupler_points',
                                                          '--angle-deg', '150'),
        'input crank cannot be solved at crank angle 60 deg': ('khurmi_four_bar_ad150',
                                                               '--speed-rpm', '1e160'),
        'input stick_cyl cannot be solved at boom_cyl = 2.6 m, stick_cyl = 4.2 m': (
            'excavator', '--input', 'stick_cyl=4.2'),
    }
    for line in quoted:
        args = next((a for key, a in commands.items() if key in line), None)
        assert args is not None, f'quoted, but no longer what `solve` says: {line}'
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            assert main(['solve', *args]) == 2
        assert err.getvalue() == f'{line}\n'


def anchors(text):
    """Return the GitHub anchors of a Markdown text's headings (outside code blocks)."""
    found, fenced = set(), False
    for line in text.splitlines():
        if line.startswith('```'):
            fenced = not fenced
        elif not fenced and line.startswith('#'):
            title = line.lstrip('#').strip().lower()
            found.add(re.sub(r'[^\w\- ]', '', title).replace(' ', '-'))
    return found


@pytest.mark.parametrize('path', DOCUMENTS, ids=lambda p: str(p.relative_to(ROOT)))
def test_links_and_anchors_resolve(path):
    """Every relative link and image of README and docs/ exists, and so does its anchor."""
    text = path.read_text()
    links = re.findall(r'\]\(([^)\s:#]*)(?:#([^)\s]*))?\)', text)
    for target, anchor in links:
        file = (path.parent / target).resolve() if target else path
        assert file.exists(), (path.name, target)
        if anchor:
            assert anchor in anchors(file.read_text()), (path.name, target, anchor)


def test_readme_is_a_front_door():
    """README is short, has contents, the two commands, and links every document in docs/."""
    text = README.read_text()
    assert len(text.splitlines()) < 400
    assert '## Contents' in text and 'make run' in text and 'make test' in text
    for doc in ROOT.joinpath('docs').glob('*.md'):
        assert f'(docs/{doc.name})' in text, doc.name


def test_nothing_shipped_points_outside_the_repository():
    """No path to the shared folders or the seed files in the package, docs, scenes, README."""
    files = [README, *ROOT.joinpath('docs').glob('*.md'), *ROOT.joinpath('config').rglob('*'),
             *ROOT.joinpath('mech_kinematics').rglob('*.py'),
             *ROOT.joinpath('mech_kinematics').rglob('*.yaml')]
    for path in files:
        if path.is_file():
            text = path.read_text(errors='replace')
            for needle in ('../shared', '/shared/', 'seeds/', '/work/'):
                assert needle not in text, (path, needle)


def test_nothing_names_a_file_the_repository_lacks():
    """No code, test or page names the contracts' files, which users who clone do not have."""
    contracts = [name + '.md' for name in ('SCENE_FORMAT', 'INTERFACE', 'STYLE')]
    files = [README, *ROOT.joinpath('docs').rglob('*.md'), *ROOT.joinpath('config').rglob('*'),
             *ROOT.joinpath('mech_kinematics').rglob('*.py'), *ROOT.joinpath('test').rglob('*.py'),
             *ROOT.joinpath('bench').glob('*')]
    for path in files:
        if path.is_file():
            text = path.read_text(errors='replace')
            for name in contracts:
                assert name not in text, (path, name)


def test_readme_lists_every_executable():
    """The README's executables table has a row for every console script of setup.py."""
    scripts = re.findall(r"^\s+'(\w+) = mech_kinematics", ROOT.joinpath('setup.py').read_text(),
                         re.MULTILINE)
    assert 'kinematics_node' in scripts and 'check' in scripts
    table = README.read_text().split('## Executables', 1)[1].split('\n## ', 1)[0]
    rows = set(re.findall(r'^\| `(\w+)` \|', table, re.MULTILINE))
    assert rows == set(scripts)


def _python_block(text: str, heading: str) -> str:
    """Return the first ```python block after ``heading`` in ``text``."""
    start = text.index(heading)
    match = re.search(r'```python\n(.*?)```', text[start:], re.S)
    assert match is not None, heading
    return match.group(1)


def test_readme_python_example_prints_what_its_comments_say():
    """The Python API example of README runs, and every value its comments give is returned.

    A line ``expr  # 1.5 rad/s`` or ``expr  # [1.5, 2.5] m/s`` (a number or a list
    of numbers first in the comment) is evaluated and compared to the digits given.
    """
    block = _python_block(README.read_text(encoding='utf-8'), '## The Python API')
    namespace: dict[str, object] = {}
    checked = 0
    number = r'-?\d+(?:\.\d+)?(?:e-?\d+)?'
    for line in block.splitlines():
        code, _, comment = line.partition('#')
        code = code.strip()
        if not code:
            continue
        values = re.match(rf'\s*(\[\s*{number}(?:,\s*{number})*\s*\]|{number})(?=\s|$)',
                          comment)
        if values is None or '=' in code.split('(')[0]:
            exec(code, namespace)  # noqa: S102 - README's own example
            continue
        written = re.findall(number, values.group(1))
        got = [float(v) for v in __import__('numpy').ravel(eval(code, namespace))]  # noqa: S307
        assert len(got) == len(written), line
        for value, text in zip(got, written, strict=True):
            digits = len(text.split('.')[1]) if '.' in text else 0
            assert abs(value - float(text)) <= 0.5 * 10.0 ** -digits, line
        checked += 1
    assert checked >= 2


def _run_commented(block: str, namespace: dict) -> int:
    """Run a Python block; each expression whose comment starts with a number must give it.

    The numbers are compared to the digits written (as README's example is);
    statements may span lines. Returns how many values were checked.
    """
    import ast
    import numpy as np

    lines = block.splitlines()
    number = r'-?\d+(?:\.\d+)?(?:e-?\d+)?'
    checked = 0
    for node in ast.parse(block).body:
        code = ast.get_source_segment(block, node)
        comment = lines[node.end_lineno - 1].partition('#')[2]
        values = re.match(rf'\s*({number})(?=\s|$|:)', comment)
        if values is None or not isinstance(node, ast.Expr):
            exec(code, namespace)  # noqa: S102 - the docs' own example
            continue
        got = float(np.ravel(eval(code, namespace))[0])  # noqa: S307
        text = values.group(1)
        digits = len(text.split('.')[1]) if '.' in text else 0
        assert abs(got - float(text)) <= 0.5 * 10.0 ** -digits, (code, got, text)
        checked += 1
    return checked


def test_the_apis_forces_examples_give_what_their_comments_say():
    """docs/api.md's forces examples run, and every value their comments give is returned."""
    text = (ROOT / 'docs' / 'api.md').read_text(encoding='utf-8')
    section = text.split('## Forces: efforts, reactions, shaking', 1)[1].split('\n## ', 1)[0]
    namespace: dict = {'mk': mk, 'np': __import__('numpy')}
    checked = sum(_run_commented(block, namespace) for block in blocks(section, 'python'))
    assert checked >= 5
    assert namespace['cycle'].forces.efforts['crank'].shape == (360,)


def test_the_apis_target_examples_give_what_their_comments_say():
    """docs/api.md's "Driven from the output" examples run and give their comments' values."""
    text = (ROOT / 'docs' / 'api.md').read_text(encoding='utf-8')
    section = text.split('## Driven from the output', 1)[1].split('\n## ', 1)[0]
    namespace: dict = {'mk': mk, 'np': __import__('numpy')}
    checked = sum(_run_commented(block, namespace) for block in blocks(section, 'python'))
    assert checked >= 6
    assert list(namespace['inverse'].answer.points['P'].position) == [0.06, 0.22] or \
        max(abs(namespace['inverse'].answer.points['P'].position - [0.06, 0.22])) < 1e-15


def test_the_forces_excerpt_is_what_solve_prints(tmp_path):
    """The reference's forces example prints the quoted efforts, reaction and shaking."""
    text = DOC.read_text()
    scene = next(b for b in blocks(text, 'yaml') if b.startswith('name: four_bar_loaded'))
    path = tmp_path / 'four_bar_loaded.yaml'
    path.write_text(scene)
    status, out = run('solve', path)
    assert status == 0
    data = json.loads(out)
    excerpt = json.loads(next(b for b in blocks(text, 'json') if '"efforts"' in b))
    assert excerpt['efforts'] == data['efforts']
    assert excerpt['shaking'] == data['shaking']
    for name, reaction in excerpt['reactions'].items():
        assert reaction == data['reactions'][name]
