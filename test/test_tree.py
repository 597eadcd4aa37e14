# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A fresh machine: nothing the repository tracks points outside it (issue 40).

A ``.venv`` symlink to another checkout's virtualenv was committed (``.gitignore``
had ``/.venv/``, which matches a directory only): every clone then failed ``make``
at once, except on the machine where the link's target existed, where CI passed
with another checkout's environment. ``scripts/check_tree.py`` (run first by
``.ci/run``) refuses a tracked symlink that leaves the tree and a tracked file
that ``.gitignore`` ignores; these tests hold it to that on this repository and
on a repository built here with each fault.
"""

import os
from pathlib import Path
import shutil
import subprocess
import sys

import pytest

REPO = Path(__file__).resolve().parent.parent
CHECK = REPO / 'scripts' / 'check_tree.py'


def git(repo: Path, *args: str) -> str:
    return subprocess.run(['git', '-C', str(repo), *args], check=True,
                          capture_output=True, text=True).stdout


def check(repo: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(CHECK), str(repo)], capture_output=True,
                          text=True, timeout=60)


@pytest.fixture
def repo(tmp_path: Path) -> Path:
    """Make a git repository with this one's .gitignore and a file, nothing wrong yet."""
    root = tmp_path / 'clone'
    root.mkdir()
    git(root, 'init', '-q')
    shutil.copy(REPO / '.gitignore', root / '.gitignore')
    (root / 'docs').mkdir()
    (root / 'README.md').write_text('front door\n')
    git(root, 'add', '.gitignore', 'README.md')
    return root


def test_this_repository_tracks_nothing_that_points_outside_it():
    """This checkout's index holds no symlink out of the tree and no ignored file."""
    if not (REPO / '.git').exists():
        if os.environ.get('CI') == 'true':
            pytest.fail(f'{REPO} is not a git checkout: CI runs in a clone')
        pytest.skip(f'{REPO} is not a git checkout (an unpacked sdist): nothing to check')
    result = check(REPO)
    assert result.returncode == 0, result.stderr
    assert result.stderr == ''


def test_a_clean_repository_passes(repo):
    """A symlink that stays inside the tree is fine."""
    (repo / 'docs' / 'front.md').symlink_to('../README.md')
    git(repo, 'add', 'docs/front.md')
    result = check(repo)
    assert (result.returncode, result.stderr) == (0, '')


@pytest.mark.parametrize('link, target', [
    ('python', '/work/wt/i30/.venv/bin/python'),  # absolute
    ('docs/env', '../../elsewhere/.venv'),       # `..` out of the tree
    ('docs/deep', './../docs/../../x'),          # out, then nowhere back in
])
def test_a_symlink_out_of_the_tree_fails_naming_it(repo, link, target):
    """Absolute or climbing out with ``..``: one line naming the path and its target."""
    (repo / link).symlink_to(target)
    git(repo, 'add', '-f', link)
    result = check(repo)
    assert result.returncode == 1, result.stderr
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith(f'check_tree: {link}: a tracked symlink to {target!r}, '
                               'outside the repository')


def test_the_committed_venv_link_of_issue_40_fails_twice(repo):
    """The link that was committed: out of the tree, and ignored by its name."""
    (repo / '.venv').symlink_to('/work/wt/i30/.venv')
    git(repo, 'add', '-f', '.venv')
    result = check(repo)
    assert result.returncode == 1, result.stderr
    assert [line.split(': ')[2] for line in result.stderr.splitlines()] == [
        "a tracked symlink to '/work/wt/i30/.venv', outside the repository (remove it",
        'tracked, but .gitignore ignores it (remove it']


@pytest.mark.parametrize('path', ['.venv', 'venv', 'mech_kinematics/__pycache__/x.pyc',
                                  'build', 'node_modules'])
def test_a_tracked_file_that_gitignore_ignores_fails_naming_it(repo, path):
    """Forced in with ``git add -f``: one line naming it."""
    (repo / path).parent.mkdir(parents=True, exist_ok=True)
    (repo / path).write_text('one machine only\n')
    git(repo, 'add', '-f', path)
    result = check(repo)
    assert result.returncode == 1, result.stderr
    assert result.stderr.splitlines() == [
        f'check_tree: {path}: tracked, but .gitignore ignores it '
        f'(remove it: git rm --cached {path}, or change .gitignore)']


@pytest.mark.parametrize('name', ['.venv', 'venv', '.tox', 'node_modules', 'build',
                                  'install', 'log', 'dist'])
def test_gitignore_ignores_a_link_by_its_name(repo, name):
    """A worktree's or tool's link is ignored as a name, not only as a directory.

    ``/.venv/`` (with the slash) does not match a symlink: ``git add -A`` took it.
    """
    (repo / name).symlink_to('/nowhere/at/all')
    status = git(repo, 'status', '--porcelain', '--untracked-files=all').splitlines()
    assert [line for line in status if not line.startswith('A ')] == [], name
    git(repo, 'add', '-A')
    assert name not in git(repo, 'ls-files').split()


def test_ci_checks_the_tree_before_building():
    """``.ci/run`` runs the check before ``make`` and refuses a linked ``.venv``."""
    ci = (REPO / '.ci' / 'run').read_text()
    assert 'scripts/check_tree.py' in ci
    assert ci.index('scripts/check_tree.py') < ci.index('make test')
    assert '-L .venv' in ci


def test_make_refuses_a_linked_venv(tmp_path):
    """``make`` refuses to build or run through a ``.venv`` that is a link, in one line."""
    shutil.copy(REPO / 'Makefile', tmp_path / 'Makefile')
    (tmp_path / '.venv').symlink_to(tmp_path / 'other-checkout' / '.venv')
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(('PYTEST_', 'MAKE')) and k != 'MFLAGS'}
    for target in ('run', 'test'):
        result = subprocess.run(['make', '--no-print-directory', target], cwd=tmp_path,
                                env=env, capture_output=True, text=True, timeout=120)
        assert result.returncode == 2, result.stderr
        assert result.stderr.startswith('Makefile:'), result.stderr
        assert '.venv is a symlink (to ' in result.stderr, result.stderr
        assert len(result.stderr.splitlines()) == 1, result.stderr
    assert not (tmp_path / 'other-checkout').exists()


def test_no_two_test_modules_share_a_name():
    """Two test files of one name in two folders stop the whole run at collection.

    The test folders have no ``__init__.py`` (pytest's rootdir-relative import
    mode): ``test/ros/test_x.py`` beside ``test/robot/test_x.py`` is "import
    file mismatch" when both are collected, though each passes alone.
    """
    by_name: dict[str, list[str]] = {}
    for path in sorted((REPO / 'test').rglob('test_*.py')):
        by_name.setdefault(path.name, []).append(path.relative_to(REPO).as_posix())
    assert {name: paths for name, paths in by_name.items() if len(paths) > 1} == {}
