# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Remember which files a linter passed, by content, so that a rerun checks only the rest.

flake8 and pydocstyle judge each file on its own: the verdict on a file is a
function of its path, its bytes, the configuration, the linter's and its
plugins' versions and the Python running them. A file is remembered clean
under the SHA-256 of all of these (kept in pytest's cache, ``.pytest_cache``,
which ``make clean`` removes); a file changed, or any of the rest, is checked
again. A file with an error is never remembered, so it is reported on every
run. Without pytest's cache (``-p no:cacheprovider``) every file is checked.
"""

from __future__ import annotations

import hashlib
from importlib import metadata
from pathlib import Path
import sys
from typing import Callable, Iterable, Sequence


def tool_key(distributions: Iterable[str], *extra: bytes | str) -> str:
    """Return a digest of the named distributions' versions, Python's and ``extra``."""
    digest = hashlib.sha256(sys.version.encode())
    for name in sorted(set(distributions)):
        digest.update(f'\0{name}=={metadata.version(name)}'.encode())
    for item in extra:
        digest.update(b'\0' + (item.encode() if isinstance(item, str) else item))
    return digest.hexdigest()


def plugin_distributions(*groups: str) -> set[str]:
    """Return the distributions that register an entry point in one of ``groups``."""
    names = set()
    for distribution in metadata.distributions():
        if any(entry.group in groups for entry in distribution.entry_points):
            names.add(distribution.metadata['Name'])
    return names


def check_changed(cache, name: str, key: str, root: Path, files: Sequence[Path],
                  check: Callable[[list[Path]], tuple[bool, str]]) -> tuple[bool, str, int]:
    """Run ``check`` on the files of ``files`` not remembered clean; remember them if it passes.

    ``check(paths)`` returns (passed, report). Returns (passed, report, the
    number of files checked). ``cache`` is pytest's ``config.cache`` or ``None``.
    """
    digests = {}
    for path in files:
        digest = hashlib.sha256(key.encode())
        digest.update(b'\0' + path.relative_to(root).as_posix().encode() + b'\0')
        digest.update(path.read_bytes())
        digests[path] = digest.hexdigest()
    remembered = set(cache.get(name, [])) if cache is not None else set()
    todo = [path for path in files if digests[path] not in remembered]
    passed, report = check(todo) if todo else (True, '')
    if cache is not None:
        clean = {digests[path] for path in files if path not in todo or passed}
        cache.set(name, sorted(clean))
    return passed, report, len(todo)
