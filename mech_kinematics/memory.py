# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Keeping freed memory for reuse: a process-wide setting that the process's owner turns on.

An array solve over many angles makes a few hundred temporary arrays of the
batch's size, and glibc by default maps each large one on its own and trims
the heap once they are freed, so the next solve of the same size pays a page
fault on every 4 KiB of every temporary again: at 100,000 angles that is most
of its time. :func:`keep_freed_memory` tells the C library to keep freed
blocks in the heap instead, so the next solve's temporaries reuse them.

It changes the allocator of the whole process, so the library never calls it
(neither on import nor in :func:`mech_kinematics.solve`): the command-line
tools (every command, through :func:`mech_kinematics.tools.cli.run_handler`)
and the benchmark turn it on, and a program of its own that solves large
arrays often may call it once (docs/api.md); ``test_memory`` checks both.
"""

from __future__ import annotations

import ctypes
import os
import platform

__all__ = ['KEEP_FREED', 'keep_freed_memory']

#: The C library's settings: (``M_TRIM_THRESHOLD``, bytes of free memory kept at the top
#: of the heap), (``M_MMAP_THRESHOLD``, the size from which a block is mapped on its own,
#: returned to the system when freed: glibc's own upper limit, 32 MiB).
KEEP_FREED = ((-1, 256 << 20), (-3, 32 << 20))
#: Whether the settings were made, once asked (empty until then).
_kept: list[bool] = []


def keep_freed_memory() -> bool:
    """Let the C library keep freed memory for reuse, once per process; return whether it does.

    With :data:`KEEP_FREED` the freed blocks stay in the heap and the next
    array solve's temporaries reuse them, as buffers reused across calls
    would, and no returned array ever shares memory with another call's (each
    is still a fresh allocation). The process keeps up to 256 MiB of freed
    memory. Elsewhere than glibc (``platform.libc_ver``), or with the
    environment variable ``MECH_KINEMATICS_KEEP_FREED_MEMORY=0`` (for a
    process whose allocator settings are its own), it does nothing and
    returns False. Asking again changes nothing.
    """
    if not _kept:
        done = False
        if (platform.libc_ver()[0] == 'glibc'
                and os.environ.get('MECH_KINEMATICS_KEEP_FREED_MEMORY', '1') != '0'):
            try:
                libc = ctypes.CDLL(None)
                done = all(libc.mallopt(param, value) == 1 for param, value in KEEP_FREED)
            except (OSError, AttributeError):
                done = False
        _kept.append(done)
    return _kept[0]
