# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Check that nothing the repository tracks points outside it (run by ``.ci/run``).

Two things make a clone work on the machine that committed it and nowhere else:

* a tracked symlink whose target leaves the tree (an absolute path, or one whose
  ``..`` climb out of the repository), such as a ``.venv`` linked to another
  checkout's virtualenv: the clone then builds and runs through that link;
* a tracked file that ``.gitignore`` ignores: it was committed by accident
  (``git add -f``, or an ignore rule added after it), and what ignores it says it
  belongs to one machine.

``python3 scripts/check_tree.py [REPO]`` prints one line per offending path and
exits 1, or exits 0 in silence. It reads git's index (``git ls-files``), so it
judges what is committed or staged, not the work tree. Standard library only: it
runs before anything is installed.
"""

from __future__ import annotations

import os
from pathlib import Path, PurePosixPath
import subprocess
import sys

#: git's mode for a symlink in the index.
SYMLINK_MODE = '120000'


def _git(repo: Path, *args: str) -> bytes:
    return subprocess.run(['git', '-C', str(repo), *args], check=True,
                          capture_output=True).stdout


def _leaves_tree(link: str, target: str) -> bool:
    """Tell whether ``target``, read from the directory of ``link``, leaves the tree."""
    if target.startswith('/') or PurePosixPath(target).is_absolute():
        return True
    depth = len(PurePosixPath(link).parts) - 1      # directories above the link
    for part in PurePosixPath(target).parts:
        if part == '..':
            depth -= 1
            if depth < 0:
                return True
        elif part != '.':
            depth += 1
    return False


def problems(repo: Path) -> list[str]:
    """One line for each tracked path that points outside ``repo`` or is ignored."""
    found = []
    for entry in _git(repo, 'ls-files', '-s', '-z').split(b'\0'):
        if not entry:
            continue
        meta, path_bytes = entry.split(b'\t', 1)
        mode, blob, _stage = meta.decode().split()
        if mode != SYMLINK_MODE:
            continue
        path = os.fsdecode(path_bytes)
        target = os.fsdecode(_git(repo, 'cat-file', 'blob', blob))
        if _leaves_tree(path, target):
            found.append(f'{path}: a tracked symlink to {target!r}, outside the repository '
                         f'(remove it: git rm --cached {path})')
    ignored = _git(repo, 'ls-files', '-z', '--cached', '--ignored', '--exclude-standard')
    for path_bytes in ignored.split(b'\0'):
        if path_bytes:
            path = os.fsdecode(path_bytes)
            found.append(f'{path}: tracked, but .gitignore ignores it '
                         f'(remove it: git rm --cached {path}, or change .gitignore)')
    return found


def main(argv: list[str]) -> int:
    """Print each problem of the repository ``argv[1]`` (default: this one); 1 if any."""
    repo = Path(argv[1]) if len(argv) > 1 else Path(__file__).resolve().parent.parent
    try:
        found = problems(repo)
    except (OSError, subprocess.CalledProcessError) as exc:
        stderr = getattr(exc, 'stderr', b'') or b''
        print(f'check_tree: cannot read the git index of {repo}: '
              f'{stderr.decode(errors="replace").strip() or exc}', file=sys.stderr)
        return 2
    for line in found:
        print(f'check_tree: {line}', file=sys.stderr)
    return 1 if found else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
