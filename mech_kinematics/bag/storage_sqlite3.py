# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""sqlite3 storage of a rosbag2 bag: one committed transaction per flush.

The database has rosbag2's schema version 4 (tables ``schema``, ``metadata``,
``topics``, ``message_definitions``, ``messages``), the schema rosbags writes
and reads. Messages wait in memory until :meth:`Sqlite3Storage.flush`, which
inserts them in one transaction and commits it. The journal is SQLite's
rollback journal (``journal_mode=DELETE``, ``synchronous=NORMAL``): a
transaction cut by ``kill -9``, a full disk or a power cut is rolled back
the next time the database is opened for writing, and every committed one
stays. Readers that open the file read-only and immutable (rosbags does)
would not roll it back: :class:`RecoveredSqlite3` (``reindex``, and
:class:`~.writer.BagWriter` after a write error) opens the database for
writing first, which does, and counts what the committed transactions hold.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterator
import contextlib
import os
from pathlib import Path
import sqlite3

from .metadata import (BagError, parse_qos, stored_version, Topic,
                       type_hash_from_definition)
from .salvage import new_copy_path, replace_keeping_original

__all__ = ['RecoveredSqlite3', 'Sqlite3Storage']

SCHEMA_VERSION = 4
SCHEMA = """
CREATE TABLE schema(
  schema_version INTEGER PRIMARY KEY,
  ros_distro TEXT NOT NULL
);
CREATE TABLE metadata(
  id INTEGER PRIMARY KEY,
  metadata_version INTEGER NOT NULL,
  metadata TEXT NOT NULL
);
CREATE TABLE topics(
  id INTEGER PRIMARY KEY,
  name TEXT NOT NULL,
  type TEXT NOT NULL,
  serialization_format TEXT NOT NULL,
  offered_qos_profiles TEXT NOT NULL,
  type_description_hash TEXT NOT NULL
);
CREATE TABLE message_definitions(
  id INTEGER PRIMARY KEY,
  topic_type TEXT NOT NULL,
  encoding TEXT NOT NULL,
  encoded_message_definition TEXT NOT NULL,
  type_description_hash TEXT NOT NULL
);
CREATE TABLE messages(
  id INTEGER PRIMARY KEY,
  topic_id INTEGER NOT NULL,
  timestamp INTEGER NOT NULL,
  data BLOB NOT NULL
);
CREATE INDEX timestamp_idx ON messages (timestamp ASC);
"""
_INSERT_MESSAGE = 'INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)'


def _connect(path: Path) -> sqlite3.Connection:
    # Autocommit: transactions are opened and committed explicitly, one per flush. Used by
    # one thread at a time, not always the one that opened it (QueuedWriter's writing thread).
    conn = sqlite3.connect(path, isolation_level=None, check_same_thread=False)
    conn.execute('PRAGMA journal_mode=DELETE')
    conn.execute('PRAGMA synchronous=NORMAL')
    return conn


def _write_metadata(conn: sqlite3.Connection, version: int, metadata: str) -> None:
    conn.execute('BEGIN')
    try:
        conn.execute('DELETE FROM metadata')
        conn.execute('INSERT INTO metadata (metadata_version, metadata) VALUES (?, ?)',
                     (version, metadata))
        conn.execute('COMMIT')
    except sqlite3.Error:
        with contextlib.suppress(sqlite3.Error):
            conn.execute('ROLLBACK')
        raise


class Sqlite3Storage:
    """A new rosbag2 sqlite3 database, written a transaction at a time.

    Parameters
    ----------
    path : Path
        The database to create; it must not exist.
    distro : str
        The ROS distribution, for the ``schema`` table.
    """

    #: Suffix of the storage file.
    suffix = '.db3'

    def __init__(self, path: Path, *, distro: str) -> None:
        self.path = path
        if path.exists():
            msg = f'Expected a new database file, got "{path}", which exists'
            raise BagError(msg)
        self.conn = _connect(path)
        self._rows: list[tuple[int, int, bytes]] = []
        self._pending_bytes = 0
        self._types: set[str] = set()
        self.counts: Counter[int] = Counter()
        self._start = 2**63 - 1
        self._end = 0
        try:
            self.conn.executescript(f'BEGIN; {SCHEMA} COMMIT;')
            self.conn.execute('INSERT INTO schema (schema_version, ros_distro) VALUES (?, ?)',
                              (SCHEMA_VERSION, distro))
        except BaseException:
            self.abort()
            raise

    @property
    def pending_bytes(self) -> int:
        """Bytes of messages waiting for the next flush."""
        return self._pending_bytes

    @property
    def time_range(self) -> tuple[int, int]:
        """Receive times of the first and last committed message, ns (0, 0 if none)."""
        return (self._start, self._end) if self.counts else (0, 0)

    def add_topic(self, topic: Topic, qos: str) -> None:
        """Insert ``topic`` (and its type's definition, once per type); committed at once."""
        self.conn.execute('BEGIN')
        try:
            if topic.type not in self._types:
                self.conn.execute(
                    'INSERT INTO message_definitions (topic_type, encoding, '
                    'encoded_message_definition, type_description_hash) VALUES (?, ?, ?, ?)',
                    (topic.type, topic.encoding, topic.definition, topic.type_hash))
            self.conn.execute('INSERT INTO topics VALUES (?, ?, ?, ?, ?, ?)',
                              (topic.id, topic.name, topic.type, topic.serialization_format, qos,
                               topic.type_hash))
            self.conn.execute('COMMIT')
        except sqlite3.Error:
            with contextlib.suppress(sqlite3.Error):
                self.conn.execute('ROLLBACK')
            raise
        self._types.add(topic.type)
        self.counts.setdefault(topic.id, 0)

    def write(self, topic_id: int, timestamp: int, data: bytes) -> None:
        """Add a message to the pending transaction (committed at the next :meth:`flush`)."""
        self._rows.append((topic_id, timestamp, data))
        self._pending_bytes += len(data)

    def flush(self) -> None:
        """Insert the pending messages in one transaction and commit it.

        Raises
        ------
        sqlite3.Error
            If the transaction fails (it is rolled back: the database keeps
            what the previous flushes committed).
        """
        if not self._rows:
            return
        rows, self._rows, self._pending_bytes = self._rows, [], 0
        self.conn.execute('BEGIN')
        try:
            self.conn.executemany(_INSERT_MESSAGE, rows)
            self.conn.execute('COMMIT')
        except sqlite3.Error:
            with contextlib.suppress(sqlite3.Error):
                self.conn.execute('ROLLBACK')
            raise
        self.counts.update(row[0] for row in rows)
        self._start = min(self._start, min(row[1] for row in rows))
        self._end = max(self._end, max(row[1] for row in rows))

    def close(self, version: int, metadata: str) -> None:
        """Flush, store ``metadata`` (rosbag2's ``metadata`` table) and close the database."""
        self.flush()
        _write_metadata(self.conn, version, metadata)
        self.conn.execute('PRAGMA optimize')
        self.conn.close()

    def abort(self) -> None:
        """Close the database, rolling back what is not committed."""
        with contextlib.suppress(sqlite3.Error):
            if self.conn.in_transaction:
                self.conn.execute('ROLLBACK')
        with contextlib.suppress(sqlite3.Error):
            self.conn.close()


class RecoveredSqlite3:
    """A rosbag2 sqlite3 database opened for writing: its committed content, and metadata.

    Opening it rolls back a transaction that was cut (rollback journal) and
    moves a write-ahead log into the database (bags of rosbag2's
    ``resilient`` preset), so that read-only readers see every committed
    message; then topics, counts and time range are read from the tables.

    Attributes
    ----------
    topics : tuple of Topic
    counts : dict of int to int
        Messages by topic id.
    start, end : int
        Receive times of the first and last message, ns (0 if none).
    stored_version : int or None
        Version in the ``metadata`` table, if the bag was closed.
    qos_texts : list of str
        The stored offered QoS profiles.
    notes : list of str
        What recovery did, for the user.
    """

    def __init__(self, path: Path) -> None:
        self.path = path
        self.notes: list[str] = []
        self._damaged = ''
        journal = path.with_name(path.name + '-journal')
        hot = journal.is_file() and journal.stat().st_size > 0
        wal = path.with_name(path.name + '-wal')
        had_wal = wal.is_file() and wal.stat().st_size > 0
        try:
            if not path.is_file():
                msg = f'Expected an sqlite3 database, got "{path}", which is not a file'
                raise BagError(msg)
            self.conn = sqlite3.connect(path, isolation_level=None)
        except sqlite3.Error as error:
            msg = f'Expected a readable sqlite3 database, got "{path}": {error}'
            raise BagError(msg) from None
        try:
            self._read(had_wal)
        except sqlite3.Error as error:
            self.close()
            msg = f'Expected a rosbag2 sqlite3 database, got "{path}": {error}'
            raise BagError(msg) from None
        except BaseException:
            self.close()
            raise
        if hot and not journal.exists():
            self.notes.append('rolled back the transaction that was being written when the '
                              'recording was interrupted')
        if had_wal:
            self.notes.append('moved the write-ahead log into the database')

    def _read(self, had_wal: bool) -> None:
        conn = self.conn
        tables = {row[0] for row in conn.execute(
            "SELECT name FROM sqlite_master WHERE type = 'table'")}
        if not {'topics', 'messages'} <= tables:
            msg = (f'Expected the tables "topics" and "messages" in "{self.path}", got '
                   f'{", ".join(sorted(tables)) or "no table"}')
            raise BagError(msg)
        if had_wal or conn.execute('PRAGMA journal_mode').fetchone()[0] == 'wal':
            conn.execute('PRAGMA journal_mode=DELETE')
        columns = {row[1] for row in conn.execute('PRAGMA table_info(topics)')}
        definitions: dict[str, tuple[str, str]] = {}
        if 'message_definitions' in tables:
            for type_name, encoding, text in conn.execute(
                    'SELECT topic_type, encoding, encoded_message_definition '
                    'FROM message_definitions ORDER BY id'):
                definitions.setdefault(type_name, (encoding, text))
        qos_column = 'offered_qos_profiles' if 'offered_qos_profiles' in columns else "''"
        hash_column = 'type_description_hash' if 'type_description_hash' in columns else "''"
        rows = conn.execute(f'SELECT id, name, type, serialization_format, {qos_column}, '
                            f'{hash_column} FROM topics ORDER BY id').fetchall()
        topics = []
        for tid, name, type_name, fmt, qos, type_hash in rows:
            encoding, text = definitions.get(type_name, ('', ''))
            if not type_hash and text:
                type_hash = type_hash_from_definition(type_name, text, encoding)
            topics.append(Topic(tid, name, type_name, text, encoding, type_hash, parse_qos(qos),
                                fmt))
        self.topics = tuple(topics)
        self.qos_texts = [row[4] for row in rows]
        known = {t.id for t in topics}
        self.counts = {t.id: 0 for t in topics}
        try:
            problems = [row[0] for row in conn.execute('PRAGMA quick_check')]
        except sqlite3.DatabaseError as error:
            problems = [str(error)]
        if problems != ['ok']:
            self._count_readable(known, problems[0])
        else:
            for tid, n in conn.execute(
                    'SELECT topic_id, COUNT(*) FROM messages GROUP BY topic_id'):
                if tid in known:
                    self.counts[tid] = n
            start, end = conn.execute(
                'SELECT MIN(timestamp), MAX(timestamp) FROM messages WHERE topic_id IN '
                '(SELECT id FROM topics)').fetchone()
            self.start, self.end = (start or 0), (end or 0)
        self.stored_version = None
        self._stored: tuple[int, str] | None = None
        if 'metadata' in tables:
            row = conn.execute('SELECT metadata_version, metadata FROM metadata '
                               'ORDER BY id DESC LIMIT 1').fetchone()
            if row is not None:
                self.stored_version = stored_version(row[1]) or row[0]
                self._stored = (row[0], row[1])

    def _count_readable(self, known: set[int], problem: str) -> None:
        """Count the readable rows of a damaged database, and note those that are not."""
        self._damaged = problem
        start, end = 2**63 - 1, 0
        gaps: list[tuple[int, int | None]] = []
        for _, tid, timestamp, _ in _readable_rows(self.conn, gaps):
            if tid in known:
                self.counts[tid] += 1
                start, end = min(start, timestamp), max(end, timestamp)
        self.start, self.end = (start, end) if end else (0, 0)
        for after, resume in gaps:
            first = max(after + 1, 1)
            rows = (f'every row of "messages" after id {after}' if resume is None else
                    f'the rows of "messages" with ids {first} to {resume - 1} (at most '
                    f'{resume - first} messages)')
            self.notes.append(f'dropped {rows}: unreadable ({problem})')
        if not gaps:
            self.notes.append(f'found damage that no message row is in ({problem})')

    def finish(self, version: int, metadata: Callable[[], str]) -> None:
        """Store ``metadata()`` in the ``metadata`` table (skipped, with a note, if it fails).

        The table is written in one transaction, and only if it holds
        something else: on a bag that is already whole nothing is written.

        A damaged database is not changed: its readable rows are copied to a
        new database, with the metadata, which takes its name; the original is
        kept as ``NAME.damaged`` (see :mod:`.salvage`).

        Raises
        ------
        OSError, sqlite3.Error
            If the copy of a damaged database cannot be written (the original
            is then unchanged).
        """
        if self._damaged:
            self._finish_copy(version, metadata)
            return
        text = metadata()
        if self._stored == (version, text):
            return
        try:
            _write_metadata(self.conn, version, text)
        except sqlite3.Error as error:
            self.notes.append(f'left the metadata table as it was ({error})')

    def _finish_copy(self, version: int, metadata: Callable[[], str]) -> None:
        copy = new_copy_path(self.path)
        try:
            new = _connect(copy)
            try:
                self._copy_into(new)
                _write_metadata(new, version, metadata())
            finally:
                new.close()
            with open(copy, 'rb+') as stream:
                os.fsync(stream.fileno())
            kept = replace_keeping_original(self.path, copy)
        except BaseException:
            with contextlib.suppress(OSError):
                copy.unlink()
            with contextlib.suppress(OSError):
                copy.with_name(copy.name + '-journal').unlink()
            raise
        self.notes.append(f'wrote every readable row to a new "{self.path.name}"; the original '
                          f'file is kept as "{kept.name}"')

    def _copy_into(self, new: sqlite3.Connection) -> None:
        old = self.conn
        schema = old.execute('SELECT type, name, sql FROM sqlite_master WHERE sql IS NOT NULL '
                             'AND name NOT LIKE ? ORDER BY type = ?, rowid',
                             ('sqlite_%', 'index')).fetchall()
        new.execute('BEGIN')
        for _, _, sql in schema:
            new.execute(sql)
        for kind, name, _ in schema:
            if kind != 'table' or name == 'messages':
                continue
            try:
                rows = old.execute(f'SELECT * FROM "{name}"').fetchall()
            except sqlite3.DatabaseError as error:
                msg = (f'Expected a readable table "{name}" in "{self.path}", got {error}; '
                       f'the file is unchanged')
                raise BagError(msg) from None
            if rows:
                marks = ', '.join('?' * len(rows[0]))
                new.executemany(f'INSERT INTO "{name}" VALUES ({marks})', rows)
        new.executemany('INSERT INTO messages (id, topic_id, timestamp, data) VALUES (?, ?, ?, ?)',
                        _readable_rows(old, None))
        new.execute('COMMIT')

    def close(self) -> None:
        """Close the database."""
        with contextlib.suppress(sqlite3.Error):
            self.conn.close()


_BATCH = 512
_LAST_ID = 2**63 - 1


def _rows_after(conn: sqlite3.Connection, after: int, limit: int) -> list | None:
    """Rows of ``messages`` with id > ``after``, in id order; None if a page is unreadable."""
    try:
        # id >= after + 1, not id > after: a seek to ``after`` would enter its (damaged) page
        return conn.execute('SELECT id, topic_id, timestamp, data FROM messages WHERE id >= ? '
                            'ORDER BY id LIMIT ?', (after + 1, limit)).fetchall()
    except sqlite3.DatabaseError:
        return None


def _first_id_from(conn: sqlite3.Connection, low: int) -> list | None:
    """``[(id,)]`` of the first row with id >= ``low`` ([] if none); None if unreadable."""
    try:
        return conn.execute('SELECT id FROM messages WHERE id >= ? ORDER BY id LIMIT 1',
                            (low,)).fetchall()
    except sqlite3.DatabaseError:
        return None


def _next_readable(conn: sqlite3.Connection, after: int) -> int | None:
    """Return the first id after the unreadable rows that follow id ``after``, if any.

    Finds the smallest id from which a seek into the table succeeds (the
    unreadable page ends before it), probing at doubling distances, then by
    bisection.
    """
    low, step = after + 1, 1
    while True:
        high = min(low + step, _LAST_ID)
        if _first_id_from(conn, high) is not None:
            break
        if high == _LAST_ID:
            return None
        step *= 2
    while high - low > 1:
        middle = (low + high) // 2
        if _first_id_from(conn, middle) is None:
            low = middle
        else:
            high = middle
    found = _first_id_from(conn, high)
    return found[0][0] if found else None


def _readable_rows(conn: sqlite3.Connection, gaps: list | None) -> Iterator[tuple]:
    """Yield every readable row ``(id, topic_id, timestamp, data)`` of ``messages`` in id order.

    Unreadable rows (a damaged page) are skipped; each skipped range is added
    to ``gaps`` as ``(last id read, next id read or None)``.
    """
    after = -_LAST_ID
    while True:
        rows = _rows_after(conn, after, _BATCH)
        if rows is None:
            rows = _rows_after(conn, after, 1)
        if rows is None:
            resume = _next_readable(conn, after)
            if gaps is not None:
                gaps.append((after, resume))
            if resume is None:
                return
            after = resume - 1
            continue
        if not rows:
            return
        yield from rows
        after = rows[-1][0]
