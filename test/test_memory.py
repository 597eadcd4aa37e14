# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Keeping freed memory: the process's owner turns it on, the library never does (issue 30).

``solver/compiled.py`` called glibc's ``mallopt`` the first time an array of
4,096 angles was solved, so a node or a notebook that imported the package got
its allocator changed. Each check runs in a fresh Python whose
``ctypes.CDLL`` records every ``mallopt`` asked of it.
"""

import json
import os
import platform
import subprocess
import sys

import pytest

from mech_kinematics.memory import KEEP_FREED

#: Run first in each subprocess: ``CALLS`` holds the (param, value) of every mallopt call.
RECORDER = """
import ctypes, json
CALLS = []
_real = ctypes.CDLL
class _Recording(_real):
    def __getattr__(self, name):
        found = super().__getattr__(name)
        if name != 'mallopt':
            return found
        def mallopt(param, value):
            CALLS.append((param, value))
            return found(param, value)
        setattr(self, name, mallopt)    # (CDLL keeps the function it found as an attribute)
        return mallopt
ctypes.CDLL = _Recording
"""

GLIBC = platform.libc_ver()[0] == 'glibc'


def _calls(code: str, **env: str) -> list:
    """Return the mallopt calls made by ``code`` run in a fresh Python after the recorder."""
    result = subprocess.run(
        [sys.executable, '-c', f'{RECORDER}\n{code}\nprint(json.dumps(CALLS))'],
        capture_output=True, text=True, check=True, timeout=300, env={**os.environ, **env})
    return [tuple(call) for call in json.loads(result.stdout.splitlines()[-1])]


def test_solving_large_arrays_leaves_the_allocator_alone():
    """mk.solve of 100,000 angles (one crank, and a five-bar's two drivers) calls no mallopt."""
    code = """
import numpy as np
import mech_kinematics as mk
scene = mk.load_scene('khurmi_four_bar_ad150')
for _ in range(20):     # compiled after a few: both paths
    mk.solve(scene, np.linspace(0.0, 6.0, 100_000))
five_bar = mk.load_scene('five_bar')
mk.solve(five_bar, [np.full(100_000, d.start) for d in five_bar.drivers])
import mech_kinematics.memory as memory
assert memory._kept == [], memory._kept
"""
    assert _calls(code) == []


@pytest.mark.parametrize('code', [
    "from mech_kinematics.__main__ import main\nmain(['solve', 'khurmi_four_bar_ad150'])",
    "from mech_kinematics.tools.solve import main\nmain(['khurmi_four_bar_ad150'])",
    "from mech_kinematics.tools.bench import measure\nmeasure(['khurmi_four_bar_ad150'], 8, 1)",
], ids=['python -m mech_kinematics', 'a console script', 'bench'])
def test_the_command_line_and_the_benchmark_keep_freed_memory(code):
    """A command (any tool, however started) and the benchmark set both settings, once."""
    assert _calls(f'{code}\n{code}') == (list(KEEP_FREED) if GLIBC else [])


def test_keeping_freed_memory_is_set_once_on_glibc():
    """On glibc the two settings are accepted, and asking again changes nothing."""
    code = ('from mech_kinematics.memory import keep_freed_memory as k\n'
            'assert k() == k() == ' + repr(GLIBC))
    assert _calls(code) == (list(KEEP_FREED) if GLIBC else [])


def test_keeping_freed_memory_can_be_declined():
    """MECH_KINEMATICS_KEEP_FREED_MEMORY=0: the process's allocator settings are left alone."""
    code = ('from mech_kinematics.memory import keep_freed_memory as k\n'
            'assert k() is False')
    assert _calls(code, MECH_KINEMATICS_KEEP_FREED_MEMORY='0') == []
    code = "from mech_kinematics.__main__ import main\nmain(['solve', 'khurmi_four_bar_ad150'])"
    assert _calls(code, MECH_KINEMATICS_KEEP_FREED_MEMORY='0') == []
