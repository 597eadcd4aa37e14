# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Flake8 with ament_flake8's settings (the repo's .flake8) over code and tests.

Every ``.py`` file of the package, the tests, ``setup.py``, ``scripts/`` and
``launch/`` is checked, in one flake8 run on its own processes (``--jobs``
auto). A file passed before with the same bytes, configuration and versions
is not checked again (:mod:`lint_cache`: the whole tree is about a minute of
CPU, a rerun after editing a few files a second or two).
"""

import configparser
from pathlib import Path
import subprocess
import sys

from lint_cache import check_changed, plugin_distributions, tool_key
import pytest

ROOT = Path(__file__).resolve().parent.parent
CONFIG = ROOT / '.flake8'
TARGETS = ('mech_kinematics', 'test', 'setup.py', 'scripts', 'launch')


#: A guard against a hang only, never a bound on the time: the whole tree takes about a
#: minute of CPU, and beside two CPU hogs a worker gets half a core (120 s ran out).
TIMEOUT_S = 900


def _flake8(*args, cwd=ROOT):
    return subprocess.run(
        [sys.executable, '-m', 'flake8', f'--config={CONFIG}', *args],
        cwd=cwd, capture_output=True, text=True, timeout=TIMEOUT_S, check=False,
    )


def _sources():
    """Return every .py file of the targets, but those under a directory .flake8 excludes."""
    config = configparser.ConfigParser()
    config.read(CONFIG)
    excluded = {name.strip() for name in config['flake8']['exclude'].split(',')}
    files = []
    for target in TARGETS:
        path = ROOT / target
        if path.is_file():
            files.append(path)
        elif path.is_dir():
            files += sorted(p for p in path.rglob('*.py')
                            if not excluded & set(p.relative_to(ROOT).parts))
    return files


def _check(paths):
    result = _flake8(*(path.relative_to(ROOT).as_posix() for path in paths))
    return result.returncode == 0, result.stdout + result.stderr


@pytest.mark.linter
@pytest.mark.flake8
def test_flake8(request):
    """The package, the tests, setup.py, scripts/ and launch/ have no flake8 errors."""
    sources = _sources()
    folders = {path.relative_to(ROOT).parts[0] for path in sources}
    assert {'mech_kinematics', 'test', 'setup.py', 'scripts', 'launch'} <= folders
    assert ROOT / 'test' / 'test_flake8.py' in sources
    key = tool_key({'flake8', 'pyflakes', 'pycodestyle', 'pydocstyle',
                    *plugin_distributions('flake8.extension')},
                   CONFIG.read_bytes())
    passed, report, _ = check_changed(getattr(request.config, 'cache', None), 'lint/flake8',
                                      key, ROOT, sources, _check)
    assert passed, f'flake8 found errors:\n{report}'


@pytest.mark.linter
@pytest.mark.flake8
def test_flake8_settings_are_active(tmp_path):
    """The plugins load and the ament settings (quotes, 99 columns, imports) apply.

    Each plugin shows by a code of its own: D400 flake8-docstrings, Q000
    flake8-quotes, I100 flake8_import_order.
    """
    bad = tmp_path / 'bad_style.py'
    bad.write_text(
        '"""Module without a period"""\n\n'
        'import sys\n'
        'import os\n\n'
        'NAME = "double"\n'
        f"LONG = '{'x' * 92}'\n"
        'print(os, sys, NAME, LONG)\n'
    )
    result = _flake8(str(bad), cwd=tmp_path)
    codes = {line.split(':')[3].split()[0] for line in result.stdout.splitlines()
             if line.startswith(str(bad))}
    assert {'D400', 'I100', 'Q000', 'E501'} <= codes, result.stdout


class _Cache(dict):
    """pytest's ``config.cache``, in memory."""

    def get(self, key, default):
        return super().get(key, default)

    def set(self, key, value):
        self[key] = value


def test_a_file_is_checked_again_when_its_bytes_or_the_tools_change(tmp_path):
    """Only files never passed as they are now are checked; a file with errors, every time."""
    a, b = tmp_path / 'a.py', tmp_path / 'b.py'
    a.write_text('A = 1\n')
    b.write_text('B = 2\n')
    checked = []

    def check(paths):
        checked.append(sorted(path.name for path in paths))
        bad = [path.name for path in paths if 'bad' in path.read_text()]
        return not bad, ' '.join(bad)

    cache = _Cache()
    runs = [check_changed(cache, 'lint', key, tmp_path, [a, b], check)
            for key in ('k1', 'k1', 'k2')]
    assert [run[2] for run in runs] == [2, 0, 2] and all(run[0] for run in runs)
    b.write_text('B = 2  # bad\n')
    assert check_changed(cache, 'lint', 'k2', tmp_path, [a, b], check) == (False, 'b.py', 1)
    assert check_changed(cache, 'lint', 'k2', tmp_path, [a, b], check) == (False, 'b.py', 1)
    b.write_text('B = 3\n')
    assert check_changed(cache, 'lint', 'k2', tmp_path, [a, b], check) == (True, '', 1)
    assert checked == [['a.py', 'b.py'], ['a.py', 'b.py'], ['b.py'], ['b.py'], ['b.py']]
    assert check_changed(None, 'lint', 'k2', tmp_path, [a, b], check)[2] == 2
