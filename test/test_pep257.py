# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Docstring conventions (pydocstyle, numpy convention) over the package.

As in ament_pep257, magic methods (D105) need no docstring. A file passed
before with the same bytes and versions is not checked again (:mod:`lint_cache`).
"""

from pathlib import Path
import subprocess
import sys

from lint_cache import check_changed, tool_key
import pytest

ROOT = Path(__file__).resolve().parent.parent
OPTIONS = ('--convention=numpy', '--add-ignore=D105')


def _pydocstyle(*paths, cwd=ROOT):
    return subprocess.run(
        [sys.executable, '-m', 'pydocstyle', *OPTIONS, *map(str, paths)],
        cwd=cwd, capture_output=True, text=True, timeout=120, check=False,
    )


def _sources():
    files = []
    for folder in ('mech_kinematics', 'scripts', 'launch'):
        if (ROOT / folder).is_dir():
            files += sorted((ROOT / folder).rglob('*.py'))
    return [ROOT / 'setup.py', *files]


@pytest.mark.linter
@pytest.mark.pep257
def test_pep257(request):
    """Every module, class and function in the package has a numpy-style docstring."""
    sources = _sources()
    assert all(path.is_file() for path in sources)
    assert ROOT / 'mech_kinematics' / '__init__.py' in sources

    def check(paths):
        result = _pydocstyle(*paths)
        return result.returncode == 0, result.stdout + result.stderr

    passed, report, _ = check_changed(getattr(request.config, 'cache', None), 'lint/pep257',
                                      tool_key({'pydocstyle'}, *OPTIONS), ROOT, sources, check)
    assert passed, f'pydocstyle found errors:\n{report}'


@pytest.mark.linter
@pytest.mark.pep257
def test_pep257_checker_is_active(tmp_path):
    """The checker reports a missing and a malformed docstring."""
    bad = tmp_path / 'bad_doc.py'
    bad.write_text('"""module docstring without a period"""\n\n\ndef f():\n    return 1\n')
    result = _pydocstyle(bad, cwd=tmp_path)
    assert result.returncode != 0
    for code in ('D400', 'D103'):
        assert code in result.stdout, result.stdout
