# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A rosbag2 bag that survives its writer: :class:`BagWriter` and :func:`reindex`.

:class:`BagWriter` writes a bag directory (one ``.mcap`` or ``.db3`` file, then
``metadata.yaml`` at close) as rosbag2 does, with the durability of rosbag2's
``resilient`` storage preset: messages are flushed to the storage file at
least every :data:`FLUSH_INTERVAL_S` (and whenever :data:`FLUSH_BYTES` are
pending) -- an MCAP chunk closed and synced, an sqlite3 transaction committed.
If the writer dies (``kill -9``, a crash, a power cut), everything flushed is
in the file, and :func:`reindex` (``python -m mech_kinematics reindex BAG``,
the counterpart of ``ros2 bag reindex``) rebuilds ``metadata.yaml`` from it.

The writer holds an exclusive lock on its storage file until it has closed
the bag (:mod:`.lock`); :func:`reindex` refuses a bag whose storage file is
locked or open in another process, and never changes a storage file in
place: what it repairs is written whole to a new file, which takes the
storage file's name, the original being kept as ``NAME.damaged``
(:mod:`.salvage`). A bag that is already whole is left as it is.

A write error (a full disk, a file size limit, an I/O error) does not lose
the bag either: the writer stops accepting messages, and :meth:`BagWriter.close`
closes the storage with what it holds -- recovering it as :func:`reindex`
does, but in place, still holding the lock: only the writer itself, which
knows that nothing else writes the file, cuts its own unfinished last chunk
and appends the summary (there may be no room for a copy) -- so that
``metadata.yaml`` counts exactly the messages that can be read. So
that a full disk still has room for ``metadata.yaml`` (and the MCAP summary,
and sqlite3's last journal), the writer fills a file of :data:`RESERVE_BYTES`
(:data:`RESERVE_FILE`) at open and deletes it before it closes the bag;
:func:`reindex` deletes it too.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
import contextlib
from dataclasses import dataclass
import os
from pathlib import Path
import sqlite3
import time
from typing import Any

import yaml

from . import lock
from .metadata import (bag_version_of_qos, BAG_VERSIONS, BagError, BagInfo, METADATA_FILE,
                       metadata_text, qos_text, ros_distro, Topic, write_metadata_yaml)
from .storage_mcap import McapStorage, RecoveredMcap
from .storage_sqlite3 import RecoveredSqlite3, Sqlite3Storage

__all__ = ['BagWriter', 'DEFAULT_VERSION', 'FLUSH_BYTES', 'FLUSH_INTERVAL_S', 'Flush',
           'RESERVE_BYTES', 'RESERVE_FILE', 'STORAGES', 'check_new_bag', 'check_options',
           'reindex']

#: rosbag2 storage identifiers, and the suffix of their files.
STORAGES = {'mcap': '.mcap', 'sqlite3': '.db3'}
#: Version 9 metadata is not readable by Humble (rosbag2#1895).
DEFAULT_VERSION = 8
#: Longest time a message waits in memory before it is flushed to the storage file, s.
FLUSH_INTERVAL_S = 0.5
#: Pending bytes that trigger a flush before FLUSH_INTERVAL_S (rosbags' chunk size).
FLUSH_BYTES = 1 << 20
#: Space set aside at open, in a hidden file of the bag directory, released to close the bag.
RESERVE_BYTES = 256 * 1024
RESERVE_FILE = '.reserve'
#: What the MCAP Header names as the writer.
LIBRARY = 'mech_kinematics bag writer'

_WRITE_ERRORS = (OSError, sqlite3.Error)


def _reason(error: BaseException) -> str:
    if isinstance(error, OSError) and error.strerror:
        return error.strerror
    return str(error) or type(error).__name__


def check_options(storage: str, version: int) -> None:
    """Raise :class:`BagError` unless ``storage`` and ``version`` are ones a bag can have."""
    if storage not in STORAGES:
        msg = f'Expected storage to be one of {", ".join(STORAGES)}, got {storage!r}'
        raise BagError(msg)
    if version not in BAG_VERSIONS:
        msg = f'Expected bag version to be one of {BAG_VERSIONS}, got {version!r}'
        raise BagError(msg)


def check_new_bag(path: Path) -> None:
    """Raise :class:`BagError` unless ``path`` does not exist yet (a bag never overwrites)."""
    if path.exists() or path.is_symlink():
        kind = 'directory' if path.is_dir() else 'file'
        msg = (f'Expected a new bag directory, got "{path}", an existing {kind} '
               f'(refusing to overwrite it; choose another name or remove it)')
        raise BagError(msg)


@dataclass(frozen=True)
class Flush:
    """One flush of a :class:`BagWriter` that wrote messages: what reached the file, how fast."""

    #: 1 for the first flush that wrote messages, then 2, 3...
    number: int
    #: Messages it wrote to the file.
    messages: int
    #: Messages in the file after it (every flush's).
    written: int
    #: Receive time of the newest of them, ns: every message written before it is in the file.
    newest_ns: int
    #: How long it took (writing and syncing), s.
    seconds: float


class BagWriter:
    """Write a new rosbag2 bag directory, flushed about every ``flush_interval`` s.

    A flush is due an interval after the previous one started, or, if that
    one took longer than the interval (a slow disk), an interval after it
    ended; and whenever ``flush_bytes`` are pending (:meth:`flush_due`). A
    message therefore reaches the file within an interval and two flushes
    of being written, and a slow disk is never synced back to back.

    Parameters
    ----------
    path : path-like
        The bag directory to create; it must not exist.
    storage : {'mcap', 'sqlite3'}
        Storage plugin.
    version : {8, 9}
        Bag format version.
    flush_interval : float
        Longest wait of a message before it is flushed to the file, s.
    flush_bytes : int
        Pending message bytes that trigger a flush sooner.

    Attributes
    ----------
    topics : list of Topic
        The topics added, in id order.
    failure : str or None
        Why writing stopped (a write error), None while all is well.
    last_flush : Flush or None
        The last flush that wrote messages (None before the first).

    Notes
    -----
    Not thread safe: call its methods from one thread at a time (the
    recorder's :class:`~.queued.QueuedWriter` writes from a thread of its
    own, so that receiving never waits on a flush). From :meth:`open` to :meth:`close` the
    storage file is locked (:func:`.lock.hold`): ``reindex`` refuses it.
    """

    def __init__(self, path: str | Path, *, storage: str = 'mcap',
                 version: int = DEFAULT_VERSION, flush_interval: float = FLUSH_INTERVAL_S,
                 flush_bytes: int = FLUSH_BYTES) -> None:
        check_options(storage, version)
        self.path = Path(path)
        self.storage = storage
        self.version = version
        self.flush_interval = flush_interval
        self.flush_bytes = flush_bytes
        self.file = self.path / f'{self.path.name}{STORAGES[storage]}'
        self.topics: list[Topic] = []
        self._ids = 0
        self.failure: str | None = None
        self._storage: Any = None
        self._lock: int | None = None
        self.last_flush: Flush | None = None
        #: When the next flush is due (time.monotonic()), and what waits for it.
        self._due = 0.0
        self._waiting = 0
        self._newest_ns = 0

    def open(self) -> None:
        """Create the directory and the storage file (a valid, empty bag file at once)."""
        check_new_bag(self.path)
        try:
            self.path.mkdir(mode=0o755, parents=True)
        except FileExistsError:
            msg = f'Expected a new bag directory, got "{self.path}", which exists'
            raise BagError(msg) from None
        except OSError as error:
            msg = f'Could not create "{self.path}": {_reason(error)}'
            raise BagError(msg) from None
        try:
            if self.storage == 'mcap':
                self._storage = McapStorage(self.file, library=LIBRARY)
            else:
                self._storage = Sqlite3Storage(self.file, distro=ros_distro())
            self._lock = lock.hold(self.file)
            _reserve(self.path / RESERVE_FILE)
        except _WRITE_ERRORS as error:
            if self._storage is not None:
                self._storage.abort()
                self._storage = None
            self._unlock()
            msg = f'Could not create "{self.file}": {_reason(error)}'
            raise BagError(msg) from None
        self._due = time.monotonic() + self.flush_interval

    def add_topic(self, name: str, type_name: str, *, definition: str, encoding: str,
                  type_hash: str, qos: Sequence[Any] = ()) -> Topic:
        """Add a topic (written to the storage at once); return it for :meth:`write`.

        Parameters
        ----------
        name, type_name : str
            Absolute topic name and type name.
        definition, encoding : str
            Full message definition and its format (``'ros2msg'`` or ``'ros2idl'``).
        type_hash : str
            ``RIHS01_...``.
        qos : sequence of rosbags.interfaces.Qos
            Offered QoS profiles of the publishers.
        """
        topic = self.new_topic(name, type_name, definition=definition, encoding=encoding,
                               type_hash=type_hash, qos=qos)
        self.add(topic)
        return topic

    def new_topic(self, name: str, type_name: str, *, definition: str, encoding: str,
                  type_hash: str, qos: Sequence[Any] = ()) -> Topic:
        """Return a topic of the next id, for :meth:`add` (nothing written yet)."""
        self._check()
        self._ids += 1
        return Topic(self._ids, name, type_name, definition, encoding, type_hash, tuple(qos))

    def add(self, topic: Topic) -> None:
        """Write a topic of :meth:`new_topic` to the storage; its messages may follow."""
        self._check()
        try:
            self._storage.add_topic(topic, qos_text(topic.qos, self.version))
        except _WRITE_ERRORS as error:
            self._fail(error)
        self.topics.append(topic)

    def write(self, topic: Topic, timestamp: int, data: bytes) -> None:
        """Write one serialized message of ``topic`` received at ``timestamp`` ns.

        Raises
        ------
        BagError
            If writing has failed (now or before): see :attr:`failure`.
        """
        self.append(topic, timestamp, data)
        if self.flush_due():
            self.flush()

    def append(self, topic: Topic, timestamp: int, data: bytes) -> None:
        """Add one message to what is pending, never flushing (the caller flushes)."""
        if self.failure is not None:
            raise BagError(self.failure)
        self._storage.write(topic.id, timestamp, data)
        self._waiting += 1
        self._newest_ns = max(self._newest_ns, timestamp)

    @property
    def pending_bytes(self) -> int:
        """Bytes of messages waiting for the next flush."""
        return self._storage.pending_bytes

    def flush_due(self) -> bool:
        """Return whether a flush is due: the interval has passed, or ``flush_bytes`` wait."""
        return self._storage.pending_bytes >= self.flush_bytes or time.monotonic() >= self._due

    def flush(self) -> None:
        """Write what is pending to the storage file and sync it (:attr:`last_flush`)."""
        self._check()
        start = time.monotonic()
        try:
            self._storage.flush()
        except _WRITE_ERRORS as error:
            self._fail(error)
        end = time.monotonic()
        # An interval after this flush started; after it ended if it took longer (a slow
        # disk): never synced back to back, nor, for a caller that writes and flushes in
        # one thread, a flush at every write.
        self._due = (end if end - start > self.flush_interval else start) + self.flush_interval
        if self._waiting:
            last = self.last_flush or Flush(0, 0, 0, 0, 0.0)
            self.last_flush = Flush(last.number + 1, self._waiting, last.written + self._waiting,
                                    self._newest_ns, end - start)
            self._waiting = 0

    def close(self) -> BagInfo:
        """Close the storage and write ``metadata.yaml``; return what the bag holds.

        After a write error the storage is closed with what it holds
        (:func:`reindex`); :attr:`failure` says what went wrong.

        Raises
        ------
        BagError
            If even that is impossible (the message says to run ``reindex``
            once the cause is removed).
        """
        storage, self._storage = self._storage, None
        if storage is None:
            msg = f'Expected an open bag, got "{self.path}", which is not open'
            raise BagError(msg)
        try:
            return self._close(storage)
        finally:
            self._unlock()      # after the storage is closed: sqlite3's own locks stay whole

    def _close(self, storage: Any) -> BagInfo:
        _release(self.path / RESERVE_FILE)
        if self.failure is None:
            try:
                storage.flush()
                info = BagInfo(self.path, self.storage, self.version, self.file.name,
                               tuple(self.topics), dict(storage.counts), *storage.time_range)
                storage.close(self.version, metadata_text(info))
            except _WRITE_ERRORS as error:
                self.failure = f'Could not write "{self.file}": {_reason(error)}'
            else:
                try:
                    write_metadata_yaml(info)
                except OSError as error:
                    self.failure = (f'Could not write "{self.path / METADATA_FILE}": '
                                    f'{_reason(error)}')
                    msg = (f'{self.failure}; remove the cause and run '
                           f'`python -m mech_kinematics reindex {self.path}`')
                    raise BagError(msg) from None
                return info
        storage.abort()
        try:
            return _rebuild(self.path, self.file, self.version, in_place=True)
        except BagError as error:
            msg = (f'{self.failure}; closing the bag failed too ({error}); remove the cause '
                   f'and run `python -m mech_kinematics reindex {self.path}`')
            raise BagError(msg) from None

    def _unlock(self) -> None:
        fd, self._lock = self._lock, None
        if fd is not None:
            os.close(fd)

    def _check(self) -> None:
        if self.failure is not None:
            raise BagError(self.failure)
        if self._storage is None:
            msg = f'Expected an open bag, got "{self.path}", which is not open'
            raise BagError(msg)

    def _fail(self, error: BaseException) -> None:
        self.failure = f'Could not write "{self.file}": {_reason(error)}'
        raise BagError(self.failure) from None


def _reserve(path: Path) -> None:
    with open(path, 'xb') as stream:
        stream.write(bytes(RESERVE_BYTES))
        stream.flush()
        os.fsync(stream.fileno())


def _release(path: Path) -> None:
    # If it cannot be deleted, its space stays taken; closing may still fit.
    with contextlib.suppress(OSError):
        path.unlink(missing_ok=True)


def _storage_file(path: Path) -> Path:
    if not path.is_dir():
        what = 'is not a directory' if path.exists() else 'does not exist'
        msg = f'Expected a bag directory, got "{path}", which {what}'
        raise BagError(msg)
    suffixes = set(STORAGES.values())
    files = sorted(p for p in path.iterdir() if p.suffix in suffixes and p.is_file())
    if len(files) != 1:
        found = ', '.join(p.name for p in files) or 'none'
        msg = (f'Expected one storage file (.mcap or .db3) in "{path}", got {found}'
               + (' (split bags are not supported)' if files else ''))
        raise BagError(msg)
    return files[0]


def _version_in_metadata_yaml(path: Path) -> int | None:
    try:
        info = yaml.safe_load((path / METADATA_FILE).read_text(encoding='utf-8'))
        version = info['rosbag2_bagfile_information']['version']
    except (OSError, yaml.YAMLError, TypeError, KeyError):
        return None
    return version if version in BAG_VERSIONS else None


def reindex(path: str | Path, *, version: int | None = None) -> BagInfo:
    """Rebuild ``metadata.yaml`` of the bag ``path`` from its storage file; return it.

    The storage is made readable first, never in place: if it must change (an
    MCAP file with no summary or with damage, an sqlite3 database with
    unreadable pages), what it holds is written whole to a new file, synced,
    and renamed over it, the original being kept as ``NAME.damaged``
    (:mod:`.salvage`); a storage file that is already whole is not written.
    An sqlite3 database has a cut transaction rolled back (by SQLite, from its
    journal) and its ``metadata`` table rewritten in one transaction if it
    differs. The bag version is ``version`` if given, else the one stored in
    the file (a closed bag), in an existing ``metadata.yaml``, or told by the
    stored QoS format, else 8.

    Raises
    ------
    BagError
        If ``path`` is not a bag directory with one storage file, the file is
        locked or open in another process (a recorder still writing it,
        :mod:`.lock`), it is not a rosbag2 storage, or the result cannot be
        written (then the storage file is as it was).
    """
    path = Path(path)
    if version is not None and version not in BAG_VERSIONS:
        msg = f'Expected bag version to be one of {BAG_VERSIONS}, got {version!r}'
        raise BagError(msg)
    file = _storage_file(path)
    with _alone(path, file):
        _release(path / RESERVE_FILE)     # left by a writer that was killed
        return _rebuild(path, file, version, in_place=False)


@contextlib.contextmanager
def _alone(path: Path, file: Path) -> Iterator[None]:
    """Hold the lock of the storage ``file``; raise :class:`BagError` if another process has it."""
    refused = (f'Expected a bag that no other process holds open, got "{path}": its storage '
               f'file {file.name}')
    try:
        fd = lock.hold(file)
    except BlockingIOError:
        who = lock.describe(lock.holders(file, include_self=True))
        msg = (f'{refused} is locked: {who or "another process has it locked"} (a recording '
               f'still running?); run reindex once it has ended')
        raise BagError(msg) from None
    except OSError as error:
        msg = f'Could not open "{file}": {_reason(error)}'
        raise BagError(msg) from None
    try:
        others = lock.holders(file)
        if others:
            msg = (f'{refused} is in use: {lock.describe(others)}; run reindex once it is '
                   f'closed')
            raise BagError(msg)
        yield
    finally:
        os.close(fd)


def _rebuild(path: Path, file: Path, version: int | None, *, in_place: bool) -> BagInfo:
    """Make the storage ``file`` of the bag ``path`` readable, write ``metadata.yaml``; return it.

    ``in_place``: the caller is the writer of ``file`` (it holds the lock),
    which may cut an unfinished end of its own MCAP file instead of copying it.
    """
    storage = 'mcap' if file.suffix == STORAGES['mcap'] else 'sqlite3'
    recovered: Any = RecoveredMcap(file) if storage == 'mcap' else RecoveredSqlite3(file)

    def info() -> BagInfo:
        return BagInfo(path, storage, chosen, file.name, recovered.topics,
                       dict(recovered.counts), recovered.start, recovered.end,
                       tuple(recovered.notes))

    chosen = (version or recovered.stored_version or _version_in_metadata_yaml(path)
              or bag_version_of_qos(recovered.qos_texts) or DEFAULT_VERSION)
    try:
        if storage == 'mcap':
            recovered.finish(lambda: metadata_text(info()), in_place=in_place)
            if recovered.whole and recovered.stored_version not in (None, chosen):
                recovered.notes.append(
                    f'left {file.name} as it is, whole, with its stored metadata of bag '
                    f'version {recovered.stored_version}; metadata.yaml is version {chosen}')
        else:
            recovered.finish(chosen, lambda: metadata_text(info()))
    except (OSError, sqlite3.Error) as error:
        kept = '' if in_place else '; the file is as it was'
        msg = f'Could not finish "{file}": {_reason(error)}{kept}'
        raise BagError(msg) from None
    finally:
        if storage == 'sqlite3':
            recovered.close()
    result = info()
    try:
        write_metadata_yaml(result)
    except OSError as error:
        msg = f'Could not write "{path / METADATA_FILE}": {_reason(error)}'
        raise BagError(msg) from None
    return result
