# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Fuzzing the scene loader: any file gives a Scene or one clean SceneError, quickly (issue 12).

Hypothesis feeds ``load_scene`` random YAML documents (nested mappings,
lists and scalars, YAML 1.1 look-alikes, anchors, tags), random text and
bytes, and random mutations of the packaged scenes (keys deleted, duplicated
or renamed, values retyped, numbers perturbed to extremes, names swapped,
lines cut or repeated). For every input the loader must return a
:class:`mech_kinematics.Scene` or raise one :class:`mech_kinematics.SceneError`
of one line naming the file, and nothing else (no other exception, no
warning), within a time bound and a bound on the peak of memory traced by
:mod:`tracemalloc` around the call.
"""

from __future__ import annotations

import copy
import math
from pathlib import Path
import time
import tracemalloc
import warnings

from hypothesis import given, HealthCheck, settings, strategies as st
import pytest
import yaml

import mech_kinematics as mk
from mech_kinematics.scene import MAX_MESSAGE

ROOT = Path(__file__).resolve().parent.parent
PACKAGED = sorted((ROOT / 'config' / 'scenes').glob('*.yaml'))
#: Seconds one load may take (a hang or a quadratic blow-up, not a slow machine:
#: the inputs here are below 10 kB and load in milliseconds).
MAX_SECONDS = 5.0
#: Peak traced memory of one load, bytes (the inputs load in well under 1 MiB).
MAX_PEAK_BYTES = 32 * 2**20


def fuzz_settings(examples):
    """Return the settings of one fuzz test (the module: 61 s at load 7 to 8 on 2 cores).

    The examples are fixed (``derandomize``): 400 documents, 600 texts and 400
    mutated scenes (1,000, 1,500 and 1,200 until 2026-12-02: 158 s at that load, 63 s in
    a suite run); test_scene_loader.py holds each limit and hostile file on its own.
    """
    return settings(max_examples=examples, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


SCENE_WORDS = [
    'name', 'description', 'units', 'length', 'angle', 'm', 'mm', 'deg', 'rad', 'ground',
    'input', 'link', 'center', 'point', 'speed_rpm', 'accel', 'dyads', 'type', 'RRR', 'RRP',
    'RPR', 'links', 'from', 'branch', 'guide', 'through', 'slider', 'points', 'toward',
    'distance', 'origin', 'xaxis', 'local', 'outputs', 'joints', 'A', 'B', 'C', 'D', 'O', 'crank',
]
YAML_WORDS = [
    'on', 'off', 'yes', 'No', 'y', '~', 'null', 'true', '<<', '017', '08', '1_000', '1:30',
    '0b101', '0o17', '0x1F', '1.5e2', '1e-3', '-1E+3', '.inf', '-.inf', '.nan', '1e400',
    '9' * 320, '2001-12-14', '=',
]
TOKENS = [
    *SCENE_WORDS, *YAML_WORDS, ': ', '- ', '? ', '\n', '\n  ', '\n    ', ', ', '{', '}', '[', ']',
    '&a ', '*a', '&b ', '*b', '!!str ', '!!int ', '!!float ', '!!python/object:os.system ',
    '!tag ', '|\n  ', '>\n  ', "'", '"', '#', '---\n', '...\n', '%YAML 1.2\n', '\t', '\\',
    '\x00', '\ufeff', '\u2028', 'é', '\U0001f600', '0', '1', '-7', '150', '0.5',
]

scalars = st.one_of(
    st.none(), st.booleans(), st.integers(-10**320, 10**320), st.floats(),
    st.text(max_size=12), st.sampled_from(SCENE_WORDS + YAML_WORDS))
keys = st.one_of(st.sampled_from(SCENE_WORDS), st.text(max_size=8), st.sampled_from(YAML_WORDS),
                 st.integers(-5, 5), st.none(), st.booleans())
values = st.recursive(
    scalars, lambda children: st.lists(children, max_size=5)
    | st.dictionaries(keys, children, max_size=5), max_leaves=30)


def dump(value, flow):
    return yaml.safe_dump(value, default_flow_style=flow, allow_unicode=True, sort_keys=False)


@st.composite
def yaml_documents(draw):
    """Draw a random value, or a scene-shaped mapping of random values, as YAML text."""
    if draw(st.booleans()):
        value = draw(values)
    else:  # the top-level keys of a scene, each with a random value
        value = draw(st.dictionaries(st.sampled_from(SCENE_WORDS), values, max_size=8))
        if draw(st.booleans()):
            value['units'] = draw(st.sampled_from([{'length': 'mm', 'angle': 'deg'},
                                                   {'length': 'm', 'angle': 'rad'}]))
    return dump(value, draw(st.sampled_from([None, True, False])))


texts = st.one_of(
    st.lists(st.sampled_from(TOKENS), max_size=60).map(''.join),
    st.text(max_size=300),
    st.binary(max_size=300),
)


def leaves(data, path=()):
    """Yield ``(container, key, path)`` for every entry of nested mappings and lists."""
    items = data.items() if isinstance(data, dict) else enumerate(data) \
        if isinstance(data, list) else ()
    for key, value in items:
        yield data, key, (*path, key)
        yield from leaves(value, (*path, key))


PERTURBATIONS = [0, -1, 1e-300, 1e300, 1e-9, 1 + 1e-12, 1000, -1e-3, 10**400, math.inf,
                 math.nan]


@st.composite
def mutated_scenes(draw):
    """Draw a packaged scene with a few random mutations, as YAML text."""
    path = draw(st.sampled_from(PACKAGED))
    data = yaml.safe_load(path.read_text(encoding='utf-8'))
    for _ in range(draw(st.integers(1, 4))):
        entries = list(leaves(data))
        if not entries:
            break
        container, key, _ = draw(st.sampled_from(entries))
        action = draw(st.sampled_from(['delete', 'retype', 'perturb', 'swap', 'rename']))
        value = container[key]
        if action == 'delete':
            del container[key]
        elif action == 'retype':
            container[key] = draw(values)
        elif action == 'perturb' and isinstance(value, (int, float)) \
                and not isinstance(value, bool):
            factor = draw(st.sampled_from(PERTURBATIONS))
            try:
                container[key] = value * factor if draw(st.booleans()) else factor
            except OverflowError:  # an integer beyond a double times a float
                container[key] = factor
        elif action == 'swap':
            names = [(c, k) for c, k, _ in entries if isinstance(c[k], str)]
            if len(names) >= 2:
                (c1, k1), (c2, k2) = draw(st.permutations(names))[:2]
                c1[k1], c2[k2] = c2[k2], c1[k1]
        elif action == 'rename' and isinstance(container, dict):
            new = draw(st.sampled_from(SCENE_WORDS + YAML_WORDS))
            container[new] = container.pop(key)
    lines = dump(copy.deepcopy(data), draw(st.sampled_from([None, False]))).splitlines()
    for _ in range(draw(st.integers(0, 2))):  # duplicate keys, lost or extra lines
        if not lines:
            break
        index = draw(st.integers(0, len(lines) - 1))
        action = draw(st.sampled_from(['repeat', 'cut', 'insert']))
        if action == 'repeat':
            lines.insert(index, lines[index])
        elif action == 'cut':
            del lines[index]
        else:
            lines[index] += draw(st.sampled_from(TOKENS))
    return '\n'.join(lines) + '\n'


@pytest.fixture(scope='module')
def folder(tmp_path_factory):
    return tmp_path_factory.mktemp('fuzz')


def check_load(folder, content):
    """Load ``content`` from a file: a Scene or one clean SceneError, within the bounds."""
    path = folder / 'scene.yaml'
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content, encoding='utf-8', errors='surrogatepass')
    error = None
    tracemalloc.start()
    start = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter('error')  # a warning would be a second line on stderr
            scene = mk.load_scene(path)
    except mk.SceneError as refusal:
        error = refusal
    finally:
        seconds = time.perf_counter() - start
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    if error is None:
        assert isinstance(scene, mk.Scene)
    else:
        message = str(error)
        assert message.startswith(f'{path}: '), message
        assert '\n' not in message and '\r' not in message, message
        assert len(message) <= MAX_MESSAGE, message
        assert 'could not be built' not in message, message  # the safety net is never needed
    assert seconds < MAX_SECONDS, (seconds, content)
    assert peak < MAX_PEAK_BYTES, (peak, content)


@fuzz_settings(400)
@given(document=yaml_documents())
def test_random_yaml_documents(folder, document):
    """Random YAML documents give a Scene or one clean SceneError, in bounded time and memory."""
    check_load(folder, document)


@fuzz_settings(600)
@given(text=texts)
def test_random_text(folder, text):
    """Random text and bytes give a Scene or one clean SceneError, in bounded time and memory."""
    check_load(folder, text)


@fuzz_settings(400)
@given(document=mutated_scenes())
def test_mutated_packaged_scenes(folder, document):
    """Mutated packaged scenes give a Scene or one clean SceneError, in bounded time and memory."""
    check_load(folder, document)


def test_the_packaged_scenes_load_within_the_bounds(folder):
    """The unmutated packaged scenes pass the same check (the fuzz starts from valid scenes)."""
    for path in PACKAGED:
        check_load(folder, path.read_text(encoding='utf-8'))
