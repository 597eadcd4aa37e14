# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A damaged storage file replaced by its repaired copy, the original kept beside it.

When ``reindex`` must change a storage file (an MCAP file with no summary or
with damage, an unreadable page of an sqlite3 database), it never repairs the
file in place: it writes what is readable to a new file in the same
directory (:func:`new_copy_path`), syncs it, and
:func:`replace_keeping_original` then keeps the original under the name
``NAME.damaged`` (a hard link, so it is never absent) and atomically puts the
copy in its place. At every moment the storage file's name holds either the
untouched original or the complete copy, and the original bytes are kept:
nothing that was readable is ever lost, even if ``reindex`` is interrupted.
"""

from __future__ import annotations

import contextlib
import os
from pathlib import Path
import shutil

__all__ = ['DAMAGED_SUFFIX', 'new_copy_path', 'replace_keeping_original']

#: Suffix of the original of a repaired storage file (no reader takes it for a storage file).
DAMAGED_SUFFIX = '.damaged'
_COPY_SUFFIX = '.recovering'


def new_copy_path(path: Path) -> Path:
    """Return the name for the repaired copy of ``path`` (a stale one is removed)."""
    copy = path.with_name(path.name + _COPY_SUFFIX)
    with contextlib.suppress(FileNotFoundError):
        copy.unlink()
    return copy


def _kept_name(path: Path) -> Path:
    kept = path.with_name(path.name + DAMAGED_SUFFIX)
    n = 1
    while kept.exists() and not kept.samefile(path):
        kept = path.with_name(f'{path.name}{DAMAGED_SUFFIX}.{n}')
        n += 1
    return kept


def replace_keeping_original(path: Path, copy: Path) -> Path:
    """Keep ``path`` as ``path.damaged``, move the synced ``copy`` to ``path``; return the former.

    Raises
    ------
    OSError
        If the original cannot be kept or the copy cannot take its name (then
        nothing was changed).
    """
    kept = _kept_name(path)
    made = not kept.exists()
    if made:
        try:
            os.link(path, kept)
        except OSError:
            shutil.copyfile(path, kept)     # a file system without hard links
    try:
        os.replace(copy, path)
    except OSError:
        if made:        # nothing changed: the directory as it was
            with contextlib.suppress(OSError):
                kept.unlink()
        raise
    directory = os.open(path.parent, os.O_RDONLY)
    try:
        os.fsync(directory)
    finally:
        os.close(directory)
    return kept
