# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The hardened scene loader: its YAML dialect, its limits and hostile files (issue 12).

Every refusal is one :class:`mech_kinematics.SceneError` line naming the file;
no other exception escapes ``load_scene`` whatever the file holds. Hostile
files are loaded in a subprocess, which reports its time and its peak of
traced memory, so that a regression shows as a failed bound rather than a
hung or killed test run.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
import re
import socket
import stat
import subprocess
import sys
import warnings

from helpers import BASE_SCENE as BASE
import pytest
import yaml

import mech_kinematics as mk
from mech_kinematics import scene as scene_module
from mech_kinematics import yaml12
from mech_kinematics.__main__ import main
from mech_kinematics.scene import (MAX_CARRIED_POINTS, MAX_DEPTH, MAX_DYADS, MAX_FILE_BYTES,
                                   MAX_GROUND_POINTS, MAX_INTEGER_DIGITS, MAX_MESSAGE,
                                   MAX_YAML_NODES, SceneLoader)

ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT / 'config' / 'scenes'
#: Seconds a subprocess may take before the test fails (a hang, not a slow run: the largest
#: accepted scene took over 120 s beside seven busy processes on the 2-core machine).
TIMEOUT = 600
#: Peak traced memory allowed while loading any hostile file, bytes. The
#: largest accepted scene peaks near 50 MiB; before issue 12 a 762-byte file
#: reached 4 GiB.
MAX_PEAK_BYTES = 200 * 2**20


LOADERS = [pytest.param(SceneLoader, id='python')]
# The PyPI wheels of PyYAML have libyaml: then the fast loader must exist and is tested too.
assert hasattr(yaml12, 'CSceneLoader') == bool(getattr(yaml, '__with_libyaml__', False))
if hasattr(yaml12, 'CSceneLoader'):
    LOADERS.append(pytest.param(yaml12.CSceneLoader, id='libyaml'))


def write(tmp_path, text, name='scene.yaml'):
    path = tmp_path / name
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text, encoding='utf-8')
    return path


def refusal(path):
    """Return the message of the SceneError that loading ``path`` raises; check its shape."""
    with pytest.raises(mk.SceneError) as info:
        mk.load_scene(path)
    message = str(info.value)
    assert message.startswith(f'{path}: '), message
    assert '\n' not in message and len(message) <= MAX_MESSAGE, message
    return message


def load_in_subprocess(*paths, solve_point=None):
    """Load each of ``paths`` in a fresh interpreter; return its outcome, message, time and peak.

    One interpreter loads the paths in turn, :mod:`tracemalloc` started anew
    around each load (a peak counts that load alone). A dict per path, or the
    one dict of a single path; with ``solve_point``, a loaded scene is then
    solved at its start (tracing stopped) and the point's x given as ``x``.
    """
    code = (
        'import json, sys, time, tracemalloc\n'
        'import mech_kinematics as mk\n'
        'solve_point, results = sys.argv[1], []\n'
        'for path in sys.argv[2:]:\n'
        '    scene = None\n'
        '    tracemalloc.start()\n'
        '    start = time.perf_counter()\n'
        '    try:\n'
        '        scene = mk.load_scene(path)\n'
        "        outcome, message = 'Scene', ''\n"
        '    except mk.SceneError as error:\n'
        "        outcome, message = 'SceneError', str(error)\n"
        '    except BaseException as error:\n'
        '        outcome, message = type(error).__name__, str(error)[:500]\n'
        '    seconds = time.perf_counter() - start\n'
        '    peak = tracemalloc.get_traced_memory()[1]\n'
        '    tracemalloc.stop()\n'
        "    result = {'outcome': outcome, 'message': message, 'seconds': seconds,\n"
        "              'peak': peak}\n"
        '    if scene is not None:\n'
        "        result['counts'] = [len(scene.ground), len(scene.dyads), len(scene.points)]\n"
        '        if solve_point:\n'
        '            state = mk.solve(scene, scene.input.angle)\n'
        "            result['x'] = float(state.points[solve_point].position[0])\n"
        '    results.append(result)\n'
        'print(json.dumps(results))\n')
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    result = subprocess.run([sys.executable, '-c', code, solve_point or '', *map(str, paths)],
                            env=env, capture_output=True, text=True, timeout=TIMEOUT,
                            check=False)
    assert result.returncode == 0, result.stderr
    results = json.loads(result.stdout)
    assert len(results) == len(paths), result.stdout
    return results[0] if len(paths) == 1 else results


def solve_command(path):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, '-m', 'mech_kinematics', 'solve', str(path)],
                          env=env, capture_output=True, text=True, timeout=TIMEOUT, check=False)


# --- YAML 1.2 numbers ---------------------------------------------------------------------


@pytest.mark.parametrize('loader', LOADERS)
@pytest.mark.parametrize(('text', 'value'), [
    ('1.5e2', 150.0), ('1e-3', 0.001), ('-1E+3', -1000.0), ('1.0e5', 1e5), ('+.5', 0.5),
    ('1.', 1.0), ('.5', 0.5), ('-0.25', -0.25), ('150', 150), ('-7', -7), ('+7', 7), ('0', 0),
    ('0o17', 15), ('0x1F', 31), ('.inf', math.inf), ('-.Inf', -math.inf),
])
def test_numbers_resolve_as_yaml_1_2(loader, text, value):
    """Plain numbers resolve by YAML 1.2's core schema: 1.5e2 and 1e-3 are floats. See issue 12."""
    got = yaml.load(f'x: {text}\n', Loader=loader)['x']
    assert type(got) is type(value) and got == value


@pytest.mark.parametrize('loader', LOADERS)
@pytest.mark.parametrize(('text', 'value'), [
    ('~', None), ('null', None), ('', None), ('true', True), ('False', False), ('y', 'y'),
    ('n', 'n'), ('2001-12-14', '2001-12-14'), ("'on'", 'on'), ('"017"', '017'),
    ('!!str 12', '12'), ('!!float 1', 1.0), ('!!int 0x1F', 31), ('!!null ~', None),
    ('! 12', '12'), ('=', '='), ('coupler', 'coupler'),
])
def test_other_scalars_resolve_as_yaml_1_2(loader, text, value):
    """Nulls, booleans, quoted text and standard tags read as YAML 1.2 says."""
    got = yaml.load(f'x: {text}\n', Loader=loader)['x']
    assert type(got) is type(value) and got == value


def test_a_length_in_exponent_form_is_a_number(tmp_path):
    """`length: 1.5e2` is 150 (it was "expected a number, got str '1.5e2'"). See issue 12."""
    text = BASE.replace('rocker, from: D, length: 80', 'rocker, from: D, length: 8e1')
    text = text.replace('length: 40, angle: 60', 'length: 4.0E+1, angle: 6e1')
    scene = mk.load_scene(write(tmp_path, text))
    reference = mk.load_scene(write(tmp_path, BASE, 'reference.yaml'))
    assert scene == reference
    assert scene.input.length == 0.04


@pytest.mark.parametrize('text', ['.nan', '.inf', '-.inf', '1e400'])
def test_non_finite_numbers_are_still_refused(tmp_path, text):
    """.nan, .inf and an exponent beyond a double are refused as non-finite lengths."""
    path = write(tmp_path, BASE.replace('rocker, from: D, length: 80',
                                        f'rocker, from: D, length: {text}'))
    assert re.search(r'dyads\[0\]\.links\[1\]\.length: expected a finite number',
                     refusal(path))


@pytest.mark.parametrize('loader', LOADERS)
@pytest.mark.parametrize(('text', 'reason'), [
    ('on', 'a boolean in YAML 1.1'), ('Off', 'a boolean in YAML 1.1'),
    ('YES', 'a boolean in YAML 1.1'), ('no', 'a boolean in YAML 1.1'),
    ('1_000', 'a number in YAML 1.1 only'), ('1_000.5', 'a number in YAML 1.1 only'),
    ('1:30', 'a number in YAML 1.1 only'), ('1:30.5', 'a number in YAML 1.1 only'),
    ('0b101', 'a number in YAML 1.1 only'), ('017', 'octal in YAML 1.1'),
    ('-08', 'octal in YAML 1.1'), ('<<', 'merge key'),
])
def test_yaml_1_1_only_scalars_are_refused(loader, text, reason):
    """A plain scalar that YAML 1.1 and 1.2 read differently is refused, as a value or a key."""
    for document in (f'x: {text}\n', f'{text}: 1\n', f'[1, {text}]\n'):
        with pytest.raises(mk.SceneError) as info:
            yaml.load(document, Loader=loader)
        message = str(info.value)
        assert reason in message and repr(text) in message and 'line 1' in message, message


# --- keys ---------------------------------------------------------------------------------


@pytest.mark.parametrize('loader', LOADERS)
def test_duplicate_keys_are_refused_with_both_places(loader):
    """A key given twice is refused, naming both lines; the last no longer wins. See issue 12."""
    document = 'ground:\n  A: [0, 0]\n  D: [150, 0]\n  D: [100, 0]\n'
    with pytest.raises(mk.SceneError, match=r"^ground: expected each key once, got 'D' again "
                       r'at line 4, column 3 \(first at line 3, column 3\)$'):
        yaml.load(document, Loader=loader)


def test_a_second_input_block_is_refused(tmp_path):
    """A scene with two `input:` blocks is refused at the second. See issue 12."""
    path = write(tmp_path, BASE + 'input: {link: k, center: A, point: Q, length: 10}\n')
    assert re.search(r"scene: expected each key once, got 'input' again at line 24, column 1 "
                     r'\(first at line 7, column 1\)', refusal(path))


@pytest.mark.parametrize('loader', LOADERS)
@pytest.mark.parametrize(('key', 'what'), [
    ('~', "null '~' at line 2, column 3"), ('null', "null 'null' at line 2, column 3"),
    ('1', "a number '1' at line 2, column 3"), ('1.5', "a number '1.5' at line 2, column 3"),
    ('true', "a boolean 'true' at line 2, column 3"), ('[a]', 'a list at line 2, column 3'),
    ('{a: 1}', 'a mapping at line 2, column 3'), ('? [a, b]\n ', 'a list at line 2, column 5'),
])
def test_keys_must_be_text(loader, key, what):
    """`~:` no longer makes a point named "None", nor `1:` one named "1". See issue 12."""
    with pytest.raises(mk.SceneError) as info:
        yaml.load(f'ground:\n  {key}: [0, 0]\n', Loader=loader)
    assert str(info.value).startswith(f'ground: expected a text key, got {what}')


def test_a_quoted_key_is_text(tmp_path):
    """A quoted key is text: `'on': [0, 0]` names a ground point "on"."""
    path = write(tmp_path, BASE.replace('  G: [0, -100]', "  'on': [0, -100]")
                 .replace('through: G', 'through: "on"'))
    assert 'on' in mk.load_scene(path).ground


# --- tags and aliases ---------------------------------------------------------------------------


@pytest.mark.parametrize('loader', LOADERS)
@pytest.mark.parametrize('document', [
    'x: !!python/object/apply:os.system ["true"]\n', 'x: !!python/name:os.system\n',
    'x: !custom 1\n', 'x: !!binary aGk=\n', 'x: !!set {a: null}\n', 'x: !!omap [a: 1]\n',
    'x: !!timestamp 2001-12-14\n', 'x: !!int abc\n', 'x: !!float text\n',
    'x: !!map [1]\n', 'x: !!seq {a: 1}\n',
])
def test_unsupported_tags_are_refused(loader, document):
    """Only the standard tags are read; !!python and application tags are refused in one line."""
    with pytest.raises(mk.SceneError, match=r'^x: expected .* at line 1, column 4$'):
        yaml.load(document, Loader=loader)


def test_aliases_share_values(tmp_path):
    """Anchors and aliases are fine: the scene equals the one written out."""
    text = (BASE.replace('{name: coupler, from: B, length: 150}',
                         '{name: coupler, from: B, length: &long 150}')
            .replace('{name: rod, from: E, length: 150}', '{name: rod, from: E, length: *long}'))
    assert '*long' in text
    assert mk.load_scene(write(tmp_path, text)) == mk.load_scene(write(tmp_path, BASE, 'b.yaml'))


@pytest.mark.parametrize('loader', LOADERS)
@pytest.mark.parametrize(('document', 'reason'), [
    ('a: &a [*a]\n', r'^a\[0\]: .*recursive alias'),
    ('a: &a {b: *a}\n', r'^a\.b: .*recursive alias'),
    ('a: *nowhere\n', r'^a: .*undefined \*nowhere'),
    ('a: &x 1\nb: &x 2\n', r'^b: expected each anchor once, got &x again'),
])
def test_bad_aliases_are_refused(loader, document, reason):
    """A recursive, undefined or twice-defined anchor is refused in one line."""
    with pytest.raises(mk.SceneError, match=reason):
        yaml.load(document, Loader=loader)


def billion_laughs(levels=9, width=9):
    """Return the classic 'billion laughs' document: ``width**levels`` strings via aliases."""
    lines = ['a0: &a0 [' + ', '.join(['lol'] * width) + ']']
    lines += [f'a{k}: &a{k} [' + ', '.join([f'*a{k - 1}'] * width) + ']'
              for k in range(1, levels)]
    return '\n'.join(lines) + '\n'


@pytest.mark.parametrize('loader', LOADERS)
def test_alias_expansion_is_bounded(loader):
    """A document whose aliases expand beyond MAX_YAML_NODES is refused. See issue 12."""
    with pytest.raises(mk.SceneError, match=r'expected at most 500000 YAML nodes with aliases '
                       r'expanded \(MAX_YAML_NODES\)'):
        yaml.load(billion_laughs(), Loader=loader)
    small = billion_laughs(levels=3)  # 9 + 81 + 729 strings: fine
    assert len(yaml.load(small, Loader=loader)['a2']) == 9


@pytest.mark.parametrize('loader', LOADERS)
def test_nesting_is_bounded(loader):
    """Lists nested beyond MAX_DEPTH, directly or through aliases, are refused. See issue 12."""
    for document in ('[' * 100_000 + ']' * 100_000, '{a: ' * 1000 + '1' + '}' * 1000):
        with pytest.raises(mk.SceneError, match=r'nested at most 32 deep \(MAX_DEPTH\)'):
            yaml.load(document, Loader=loader)
    ok = '[' * MAX_DEPTH + ']' * MAX_DEPTH
    assert yaml.load(ok, Loader=loader) is not None
    chain = 'a0: &a0 [1]\n' + ''.join(f'a{k}: &a{k} [*a{k - 1}]\n' for k in range(1, 40))
    with pytest.raises(mk.SceneError, match=r'^a31\[0\]: .*MAX_DEPTH.*through alias \*a30'):
        yaml.load(chain, Loader=loader)


@pytest.mark.parametrize('loader', LOADERS)
def test_integer_size_is_bounded(loader):
    """An integer of more than MAX_INTEGER_DIGITS digits is refused (was OverflowError)."""
    largest = '9' * MAX_INTEGER_DIGITS
    assert yaml.load(f'x: {largest}', Loader=loader)['x'] == int(largest)
    for text in ('9' * (MAX_INTEGER_DIGITS + 1), '1' + '0' * MAX_INTEGER_DIGITS,
                 '-' + '9' * 401, '0x' + 'f' * 300, '0o' + '7' * 400):
        with pytest.raises(mk.SceneError, match=r'^x: expected an integer of at most 300 decimal'
                           r' digits \(MAX_INTEGER_DIGITS\)'):
            yaml.load(f'x: {text}', Loader=loader)


def test_a_401_digit_length_is_one_clear_line(tmp_path):
    """The issue's 401-digit integer gives a SceneError, not OverflowError. See issue 12."""
    path = write(tmp_path, BASE.replace('length: 40,', f'length: {"4" * 401},'))
    assert 'input.length: expected an integer of at most 300' in refusal(path)


@pytest.mark.parametrize('loader', LOADERS)
def test_one_document_only(loader):
    """A stream of two documents is refused, as yaml.safe_load does."""
    with pytest.raises(mk.SceneError, match='single document'):
        yaml.load('a: 1\n---\nb: 2\n', Loader=loader)
    assert yaml.load('', Loader=loader) is None


@pytest.mark.parametrize('path', sorted(SCENES.glob('*.yaml')), ids=lambda p: p.stem)
def test_both_parsers_read_packaged_scenes_as_yaml_safe_load(path):
    """On the packaged scenes the scene loader (libyaml or Python) reads what safe_load reads."""
    text = path.read_text(encoding='utf-8')
    expected = yaml.safe_load(text)
    for loader in LOADERS:
        assert yaml.load(text, Loader=loader.values[0]) == expected


# --- files ------------------------------------------------------------------------------------


@pytest.fixture(scope='module')
def small_loads(tmp_path_factory):
    """Return {name: load_in_subprocess's result} of the FIFO, hostile and 10,000-point files.

    One interpreter loads them all, each traced on its own.
    """
    folder = tmp_path_factory.mktemp('loads')
    files = {name: write(folder, text, f'{name}.yaml') for name, text in HOSTILE.items()}
    files['ten_thousand_ground_points'] = write(folder, chain(2, MAX_GROUND_POINTS),
                                                'ground.yaml')
    files['fifo'] = folder / 'scene.yaml'
    os.mkfifo(files['fifo'])
    results = load_in_subprocess(*files.values())
    return {name: dict(result, path=str(files[name]))
            for name, result in zip(files, results, strict=True)}


def test_a_fifo_is_refused_without_waiting(small_loads):
    """A FIFO as the scene is refused at once (it used to hang forever). See issue 12."""
    result = small_loads['fifo']
    fifo = result['path']
    assert result['outcome'] == 'SceneError'
    assert result['message'] == f'{fifo}: expected a regular file, got a FIFO (named pipe)'


def test_a_fifo_swapped_in_after_stat_is_refused_without_waiting(tmp_path, monkeypatch):
    """If the path turns into a FIFO after stat, the non-blocking open and fstat refuse it."""
    fifo = tmp_path / 'scene.yaml'
    os.mkfifo(fifo)
    regular = os.stat(write(tmp_path, BASE, 'regular.yaml'))
    real_stat = os.stat
    monkeypatch.setattr(scene_module.os, 'stat',
                        lambda path, *a, **k: regular if Path(path) == fifo else
                        real_stat(path, *a, **k))
    assert stat.S_ISREG(scene_module.os.stat(fifo).st_mode)
    # Nothing writes to the FIFO: a blocking open would wait here forever.
    assert refusal(fifo) == f'{fifo}: expected a regular file, got a FIFO (named pipe)'


@pytest.mark.parametrize(('path', 'kind'), [
    ('/dev/zero', 'a character device'), ('/dev/null', 'a character device'),
    ('/tmp', 'a directory'),
])
def test_only_regular_files_are_read(path, kind):
    """A device or a directory is refused before it is read (/dev/zero was a MemoryError)."""
    if not os.path.exists(path):
        pytest.skip(f'{path} does not exist on this system')
    assert refusal(Path(path)) == f'{path}: expected a regular file, got {kind}'


def test_a_socket_is_refused(tmp_path):
    """A UNIX socket is not a scene file."""
    path = tmp_path / 'scene.yaml'
    with socket.socket(socket.AF_UNIX) as server:
        server.bind(str(path))
        assert refusal(path) == f'{path}: expected a regular file, got a socket'


def test_file_size_is_bounded(tmp_path):
    """A file larger than MAX_FILE_BYTES is refused; one of exactly that size is read."""
    filler = b'#' * (MAX_FILE_BYTES - len(BASE) - 1) + b'\n'
    exact = write(tmp_path, BASE.encode() + filler, 'exact.yaml')
    assert exact.stat().st_size == MAX_FILE_BYTES
    assert mk.load_scene(exact).name == 'base_scene'
    over = write(tmp_path, BASE.encode() + filler + b'\n', 'over.yaml')
    assert refusal(over) == (f'{over}: expected a scene file of at most {MAX_FILE_BYTES} bytes '
                             f'(MAX_FILE_BYTES), got {MAX_FILE_BYTES + 1}')


@pytest.mark.parametrize(('data', 'where'), [
    ('name: café\n'.encode('latin-1'), 'byte 0xe9 at line 1, column 10 (byte 9)'),
    (BASE.encode() + b'description: \xff\n',
     f'byte 0xff at line 24, column 14 (byte {len(BASE) + 13})'),
    ('name: x\n'.encode('utf-16'), 'byte 0xff at line 1, column 1 (byte 0)'),
])
def test_non_utf8_is_one_clear_line(tmp_path, data, where):
    """A file that is not UTF-8 is refused naming the byte and its place. See issue 12."""
    path = write(tmp_path, data)
    assert refusal(path) == f'{path}: expected UTF-8 text, got {where}'


def test_a_utf8_byte_order_mark_is_fine(tmp_path):
    """A UTF-8 file that starts with a byte order mark loads."""
    path = write(tmp_path, b'\xef\xbb\xbf' + BASE.encode())
    assert mk.load_scene(path).name == 'base_scene'


@pytest.mark.parametrize('data', [b'name: x\x00\n', b'name: \x07\n', 'a: [\u2028'.encode()])
def test_control_characters_are_invalid_yaml(tmp_path, data):
    """Control characters in the text are invalid YAML, in one line."""
    assert 'invalid YAML' in refusal(write(tmp_path, data))


@pytest.mark.parametrize('source', [123, b'scene.yaml', 'a\x00b.yaml', 'x' * 5000,
                                    'no_such_dir/scene.yaml'])
def test_any_source_gives_a_scene_error(source):
    """Whatever is passed as the source, the only exception is SceneError."""
    with pytest.raises(mk.SceneError) as info:
        mk.load_scene(source)
    assert '\n' not in str(info.value)


def test_a_solver_failure_while_building_is_still_one_line(tmp_path, monkeypatch):
    """Should a solver step raise on extreme values, load_scene still gives one SceneError."""
    def fail(data):
        raise ZeroDivisionError('complex division by zero')
    monkeypatch.setattr(scene_module, 'parse_scene', fail)
    path = write(tmp_path, BASE)
    assert refusal(path) == (f'{path}: scene could not be built: ZeroDivisionError: complex '
                             'division by zero')


def test_long_names_are_shortened_in_messages(tmp_path):
    """A name of 5,000 characters in a message is shortened to keep the message one short line."""
    name = 'n' * 5000
    path = write(tmp_path, BASE.replace('name: base_scene', f'name: {name}-x'))
    message = refusal(path)
    assert "to be an identifier ([A-Za-z_][A-Za-z0-9_]*), got 'nnnnnnnn" in message
    assert '...' in message and message.endswith("nnn-x'")


# --- counts ---------------------------------------------------------------------------------


def chain(n_dyads, n_ground=1, n_points=0, reverse=True):
    """Return the text of a scene: ``n_dyads`` sliders in a chain, listed last first.

    Dyad k is an RRP placing P<k> on the x axis 20 mm beyond P<k-1>, so each
    needs the one before it: in reverse order an O(n^2) search for the next
    solvable dyad takes n^2/2 steps. Extra ground points and points carried on
    the rods fill the other limits.
    """
    out = ['# a chain of sliders', 'name: chain', 'units: {length: mm, angle: deg}', 'ground:',
           '  O: [0, 0]']
    out += [f'  G{k}: [{k}.5, -{k % 97}.25]' for k in range(1, n_ground)]
    out += ['input:', '  link: crank', '  center: O', '  point: P0', '  length: 10',
            '  angle: 60', '  speed_rpm: 120', 'dyads:']
    for k in range(n_dyads, 0, -1) if reverse else range(1, n_dyads + 1):
        out += [f'  # dyad {k}', '  - type: RRP', f'    point: P{k}',
                f'    link: {{name: r{k}, from: P{k - 1}, length: 20}}',
                '    guide: {through: O, angle: 0}', f'    slider: s{k}', '    branch: 1']
    if n_points:
        out.append('points:')
        out += [f'  E{k}: {{link: r{k % n_dyads + 1}, from: P{k % n_dyads}, '
                f'toward: P{k % n_dyads + 1}, distance: 5}}' for k in range(n_points)]
    return '\n'.join(out) + '\n'


def test_the_largest_accepted_scene_loads_in_bounded_memory(tmp_path):
    """A scene at every count limit loads: within MAX_FILE_BYTES, MAX_YAML_NODES and memory.

    Measured here: 2.5 MB, 370,000 nodes, 0.9 s (median of 5) and a 50 MiB peak. The
    subprocess that measures the load also counts the scene and solves it (once, after
    tracing stops).
    """
    path = write(tmp_path, chain(MAX_DYADS, MAX_GROUND_POINTS, MAX_CARRIED_POINTS))
    assert path.stat().st_size < MAX_FILE_BYTES
    result = load_in_subprocess(path, solve_point=f'P{MAX_DYADS}')
    assert result['outcome'] == 'Scene', result['message']
    assert result['peak'] < MAX_PEAK_BYTES
    print(f'largest accepted scene: {path.stat().st_size / 1e6:.2f} MB, '
          f'{result["seconds"]:.2f} s, peak {result["peak"] / 2**20:.0f} MiB')
    assert result['counts'] == [MAX_GROUND_POINTS, MAX_DYADS, MAX_CARRIED_POINTS]
    b = 0.01 * complex(math.cos(math.pi / 3), math.sin(math.pi / 3))
    first = b.real + math.sqrt(0.02**2 - b.imag**2)
    expected = first + 0.02 * (MAX_DYADS - 1)  # then 20 mm along the axis each
    assert math.isclose(result['x'], expected, rel_tol=1e-12)


@pytest.mark.parametrize(('what', 'text', 'limit', 'name'), [
    ('ground', lambda: chain(1, MAX_GROUND_POINTS + 1), MAX_GROUND_POINTS, 'MAX_GROUND_POINTS'),
    ('dyads', lambda: chain(MAX_DYADS + 1), MAX_DYADS, 'MAX_DYADS'),
    ('points', lambda: chain(1, 1, MAX_CARRIED_POINTS + 1), MAX_CARRIED_POINTS,
     'MAX_CARRIED_POINTS'),
])
def test_counts_are_bounded(tmp_path, what, text, limit, name):
    """One point or dyad beyond its limit is refused, naming the key and the limit."""
    path = write(tmp_path, text())
    kind = 'dyads' if what == 'dyads' else 'points'
    assert refusal(path) == (f'{path}: {what}: expected at most {limit} {kind} ({name}), got '
                             f'{limit + 1}')


def test_node_count_is_bounded_without_aliases(tmp_path):
    """A plain document of more than MAX_YAML_NODES nodes is refused."""
    path = write(tmp_path, 'name: x\ndescription: [' + '0, ' * MAX_YAML_NODES + '0]\n')
    assert 'description[499995]: expected at most 500000 YAML nodes' in refusal(path)


# --- hostile files: bounded memory, one line from the command ------------------------------


def test_ten_thousand_ground_points_load_in_bounded_memory(small_loads):
    """10,000 ground points took 4.75 GB (the size over all pairs); now well under 200 MiB."""
    result = small_loads['ten_thousand_ground_points']
    assert result['outcome'] == 'Scene', result['message']
    assert result['peak'] < MAX_PEAK_BYTES / 4


HOSTILE = {
    'billion_laughs': billion_laughs(),
    'nested_brackets': '[' * 100_000 + ']' * 100_000,
    'nested_mappings': '{a: ' * 100_000 + '}' * 100_000,
    'long_integer': 'name: x\nunits: {length: m, angle: deg}\nground: {A: [0, ' + '9' * 401 +
                    ']}\n',
    'latin1': 'name: café\n'.encode('latin-1'),
    'duplicate_key': BASE + 'input: {link: k, center: A, point: Q, length: 10}\n',
    'tilde_key': BASE.replace('  G: [0, -100]', '  G: [0, -100]\n  ~: [1, 1]'),
    'on_key': BASE.replace('  G: [0, -100]', '  G: [0, -100]\n  on: [1, 1]'),
    'python_tag': 'name: !!python/object/apply:os.system ["echo pwned"]\n',
    'no_units': BASE.replace('units: {length: mm, angle: deg}\n', ''),
}


@pytest.mark.parametrize('name', sorted(HOSTILE))
def test_hostile_files_are_refused_quickly_in_bounded_memory(small_loads, name):
    """Each hostile file of issue 12 gives one SceneError within the memory bound."""
    result = small_loads[name]
    assert result['outcome'] == 'SceneError', result
    assert result['peak'] < MAX_PEAK_BYTES / 10, result


#: The inputs `solve` reads in a process of its own; the other hostile files, in this one.
SOLVED_IN_A_SUBPROCESS = ('billion_laughs', '/dev/zero', 'fifo', 'directory')


@pytest.mark.parametrize('name', [*sorted(HOSTILE), '/dev/zero', 'fifo', 'directory'])
def test_solve_prints_one_line_and_exits_2_on_hostile_input(tmp_path, capsys, name):
    """`solve` on any hostile input prints one `error:` line naming it, exit 2. See issue 12.

    `python -m mech_kinematics solve` runs in a subprocess for a device, a FIFO,
    a directory and the billion laughs; the rest call the same ``main`` here,
    where a warning would be an error.
    """
    if name in HOSTILE:
        path = write(tmp_path, HOSTILE[name])
    elif name == 'fifo':
        path = tmp_path / 'fifo.yaml'
        os.mkfifo(path)
    elif name == 'directory':
        path = tmp_path
    else:
        path = Path(name)
    if name in SOLVED_IN_A_SUBPROCESS:
        result = solve_command(path)
        status, stdout, stderr = result.returncode, result.stdout, result.stderr
    else:
        capsys.readouterr()
        with warnings.catch_warnings():
            warnings.simplefilter('error')  # a warning would be a second line on stderr
            status = main(['solve', str(path)])
        stdout, stderr = capsys.readouterr()
    assert status == 2, stderr
    assert stdout == ''
    lines = stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f'error: {path}: '), stderr
