# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""One process at a time on a bag's storage file: the writer's lock, and who else holds it.

:class:`~.writer.BagWriter` holds an exclusive advisory lock (``flock``) on
its storage file from the moment it creates it until the bag is closed. The
kernel drops the lock when the writer's process ends, however it ends
(``kill -9`` included), so a killed recording is never left locked.
:func:`~.writer.reindex` takes the same lock before it reads a bag: it never
repairs a bag that is being recorded, or that another ``reindex`` repairs.
Then, holding the lock, it refuses a storage file that any other process
has open (:func:`holders`), which on Linux ``/proc`` tells:

- a process holding an ``flock`` or a POSIX (``fcntl``) lock on the file,
  whatever its user (``/proc/locks``): our writers, sqlite3 inside a
  transaction, ``flock(1)``;
- a process that has the file open (``/proc/PID/fd``) or mapped
  (``/proc/PID/maps``): ``ros2 bag record`` and other writers that take no
  lock, readers such as ``ros2 bag play``, Foxglove or an ``sqlite3`` shell.
  Only the processes whose ``/proc`` entries this process may read: those of
  its own user, or every process when run as root.

Not detected: a process of another user that has the file open without a
lock (unless run as root), a process on another machine sharing the file
system (NFS), a process that opens the file after the check (the lock keeps
out our writers and ``reindex``, not programs that do not take it), and,
without ``/proc`` (not Linux), anything but the lock.
"""

from __future__ import annotations

from dataclasses import dataclass
import fcntl
import os
from pathlib import Path

__all__ = ['Holder', 'describe', 'hold', 'holders']

_PROC = Path('/proc')
#: Characters of a holder's command line that a message quotes.
_COMMAND_CHARS = 72


@dataclass(frozen=True)
class Holder:
    """A process that holds a file.

    Attributes
    ----------
    pid : int
        Its process id.
    command : str
        Its command line (shortened; empty if unreadable).
    how : tuple of str
        What it does with the file, among ``'locked'``, ``'open'`` and ``'mapped'``.
    """

    pid: int
    command: str
    how: tuple[str, ...]


def hold(path: Path) -> int:
    """Return a descriptor of ``path`` that holds the file's exclusive lock (close to release).

    Raises
    ------
    BlockingIOError
        If another open file (of any process, this one included) holds the lock.
    OSError
        If the file cannot be opened.
    """
    fd = os.open(path, os.O_RDONLY | os.O_CLOEXEC)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BaseException:
        os.close(fd)
        raise
    return fd


def holders(path: Path, *, include_self: bool = False) -> list[Holder]:
    """Return the processes that lock, have open or map ``path`` (Linux ``/proc``), by pid.

    This process is left out unless ``include_self`` (its own descriptors are
    never listed as open: only its locks, which another of its open files may hold).
    """
    try:
        stat = os.stat(path)
    except OSError:
        return []
    me = os.getpid()
    found: dict[int, set[str]] = {}
    for pid in _locking(stat):
        if pid != me or include_self:
            found.setdefault(pid, set()).add('locked')
    try:
        pids = [int(entry.name) for entry in os.scandir(_PROC) if entry.name.isdigit()]
    except OSError:
        pids = []
    for pid in pids:
        if pid == me:
            continue
        if _has_open(pid, stat):
            found.setdefault(pid, set()).add('open')
        if _maps(pid, stat, str(path.resolve())):
            found.setdefault(pid, set()).add('mapped')
    order = ('locked', 'open', 'mapped')
    return [Holder(pid, _command(pid), tuple(h for h in order if h in how))
            for pid, how in sorted(found.items())]


def describe(found: list[Holder]) -> str:
    """Say who holds a file: ``process 42 (python3 -m mech_kinematics record ...) has it open``."""
    parts = []
    for holder in found:
        how = ' and '.join(holder.how)
        if holder.pid == os.getpid():
            who = f'this process ({holder.pid})'
        else:
            who = f'process {holder.pid}' + (f' ({holder.command})' if holder.command else '')
        parts.append(f'{who} has it {how}')
    return '; '.join(parts)


def _locking(stat: os.stat_result) -> list[int]:
    """Pids of the processes holding a lock on the file of ``stat`` (``/proc/locks``)."""
    device = f'{os.major(stat.st_dev):02x}:{os.minor(stat.st_dev):02x}:{stat.st_ino}'
    pids = []
    try:
        with open(_PROC / 'locks', encoding='ascii', errors='replace') as stream:
            for line in stream:
                fields = line.split()
                if '->' in fields:      # waiting for a lock, not holding one
                    continue
                # "1: FLOCK  ADVISORY  WRITE 4242 fe:00:2146330 0 EOF"
                if len(fields) >= 6 and fields[5] == device and fields[4].isdigit():
                    pids.append(int(fields[4]))
    except OSError:     # /proc/locks unreadable: the holders read so far
        return pids
    return pids


def _has_open(pid: int, stat: os.stat_result) -> bool:
    directory = _PROC / str(pid) / 'fd'
    try:
        descriptors = os.listdir(directory)
    except OSError:         # another user's process, or it ended
        return False
    for fd in descriptors:
        link = directory / fd
        try:
            if not os.readlink(link).startswith('/'):     # a pipe, a socket, ...
                continue
            other = os.stat(link)
        except OSError:
            continue
        if (other.st_dev, other.st_ino) == (stat.st_dev, stat.st_ino):
            return True
    return False


def _maps(pid: int, stat: os.stat_result, resolved: str) -> bool:
    try:
        with open(_PROC / str(pid) / 'maps', encoding='utf-8', errors='replace') as stream:
            for line in stream:
                # "7f..-7f.. r--s 00000000 fe:00 2146330   /path/bag.mcap"
                fields = line.split(maxsplit=5)
                if (len(fields) == 6 and fields[4] == str(stat.st_ino)
                        and fields[5].rstrip('\n') == resolved):
                    return True
    except OSError:     # the process ended, or is another user's: it maps nothing we see
        return False
    return False


def _command(pid: int) -> str:
    try:
        raw = (_PROC / str(pid) / 'cmdline').read_bytes()
    except OSError:
        return ''
    args = [a.decode(errors='replace') for a in raw.split(b'\0') if a]
    if not args:
        return ''
    args[0] = os.path.basename(args[0])
    text = ' '.join(' '.join(args).split())      # one line: no newline of a `python -c` script
    text = text.encode('ascii', 'backslashreplace').decode()
    return text if len(text) <= _COMMAND_CHARS else text[:_COMMAND_CHARS - 3] + '...'
