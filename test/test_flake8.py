# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Flake8 with ament_flake8's settings (the repo's .flake8) over code and tests."""

from pathlib import Path
import subprocess
import sys

import pytest

ROOT = Path(__file__).resolve().parent.parent
CONFIG = ROOT / '.flake8'
TARGETS = ('mech_kinematics', 'test', 'setup.py', 'scripts', 'launch')
PLUGINS = ('flake8-docstrings', 'flake8-quotes', 'flake8_import_order')


#: A guard against a hang only, never a bound on the time: the whole tree takes about a
#: minute of CPU, and beside two CPU hogs a worker gets half a core (120 s ran out).
TIMEOUT_S = 900


def _flake8(*args, cwd=ROOT):
    return subprocess.run(
        [sys.executable, '-m', 'flake8', f'--config={CONFIG}', *args],
        cwd=cwd, capture_output=True, text=True, timeout=TIMEOUT_S, check=False,
    )


@pytest.mark.linter
@pytest.mark.flake8
def test_flake8():
    """The package, the tests, setup.py, scripts/ and launch/ have no flake8 errors."""
    targets = [t for t in TARGETS if (ROOT / t).exists()]
    assert 'test' in targets and 'setup.py' in targets
    result = _flake8(*targets)
    assert result.returncode == 0, (
        f'flake8 found errors:\n{result.stdout}{result.stderr}'
    )


@pytest.mark.linter
@pytest.mark.flake8
def test_flake8_settings_are_active(tmp_path):
    """The plugins load and the ament settings (quotes, 99 columns, imports) apply."""
    version = _flake8('--version')
    assert version.returncode == 0, version.stderr
    for plugin in PLUGINS:
        assert plugin in version.stdout, f'flake8 plugin {plugin} is not installed'
    bad = tmp_path / 'bad_style.py'
    bad.write_text(
        '"""Module."""\n\n'
        'import sys\n'
        'import os\n\n'
        'NAME = "double"\n'
        f"LONG = '{'x' * 92}'\n"
        'print(os, sys, NAME, LONG)\n'
    )
    result = _flake8(str(bad), cwd=tmp_path)
    codes = {line.split(':')[3].split()[0] for line in result.stdout.splitlines()
             if line.startswith(str(bad))}
    assert {'I100', 'Q000', 'E501'} <= codes, result.stdout
