# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""MCAP storage of a rosbag2 bag that a crash cannot spoil: a chunk per flush, recovery by scan.

The file follows the MCAP specification with the ``ros2`` profile, laid out
as rosbag2's mcap plugin and rosbags lay it out::

    magic  Header                                  written and synced at creation
    Schema, Channel                                when a topic is added
    Chunk  MessageIndex (one per channel in it)    at every flush
    ...
    Metadata "rosbag2"  DataEnd                    at close: the end of the data section
    Schema... Channel... ChunkIndex... MetadataIndex Statistics SummaryOffset...
    Footer  magic                                  the summary, which indexed readers need

Messages wait in memory in the pending chunk; :meth:`McapStorage.flush` writes
it as one uncompressed Chunk record (with the CRC-32 of its records) followed
by its message indexes, then flushes and syncs the file. So everything up to
the last flush is a complete data section, whatever happens next (``kill
-9``, a full disk, a power cut). Schema and Channel records are written
outside the chunks, so that a topic is in the data section as soon as it is
added, and a chunk is never empty.

:class:`RecoveredMcap` (``reindex``, and :class:`~.writer.BagWriter` after a
write error) scans a file record by record and keeps every intact chunk
(length, CRC and each message checked). After a damaged record (a flipped
byte, a length that runs past the file, an unknown opcode) it searches the
following bytes for the next intact chunk (its CRC matches) or Schema or
Channel record and goes on from there, so every intact chunk after a damaged
one is kept. Closing records (metadata, data end, summary, footer) end the
scan only if they are the file's own: they end the file with its footer and
index exactly the chunks before them. Closing records with data after them (a
summary written into a file that was still being written) or that do not
match are dropped like damage, and the scan goes on. Then:

- a file closed normally, whole, is left as it is;
- otherwise ``reindex`` never changes the file: the kept records are copied
  to a new file with their message indexes and a summary, synced, which takes
  the original's name, and the original is kept as ``NAME.damaged``
  (:mod:`.salvage`). If the copy cannot be written whole (no room, a
  read-only directory), the original is left as it was;
- only the writer of the file, after its own write error and while it holds
  the file's lock (``in_place``), finishes it in place when what is dropped
  is just the end of its recording (a record cut short, message indexes cut
  short): it truncates the file after its last intact chunk, rewrites that
  chunk's message indexes if they were cut, and appends the summary that a
  normal close writes (built by the same function), dropping its last chunks
  if the file system has no room for it.

Each dropped range is noted: its offsets, why, and how many messages of which
topics a dropped chunk held if its records can still be parsed.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
import contextlib
from dataclasses import dataclass, field
import errno
import os
from pathlib import Path
import re
import struct
from typing import BinaryIO, NamedTuple
import zlib

from .metadata import (BagError, parse_qos, stored_version, Topic,
                       type_hash_from_definition)
from .salvage import new_copy_path, replace_keeping_original

__all__ = ['MAGIC', 'McapStorage', 'RecoveredMcap']

MAGIC = b'\x89MCAP0\r\n'
PROFILE = 'ros2'

# Record opcodes (MCAP specification).
HEADER, FOOTER, SCHEMA, CHANNEL, MESSAGE, CHUNK, MESSAGE_INDEX, CHUNK_INDEX = range(1, 9)
ATTACHMENT, ATTACHMENT_INDEX = 0x09, 0x0A
STATISTICS, METADATA, METADATA_INDEX, SUMMARY_OFFSET, DATA_END = range(0x0B, 0x10)

_U16 = struct.Struct('<H')
_U32 = struct.Struct('<I')
_U64 = struct.Struct('<Q')
_RECORD = struct.Struct('<BQ')                   # opcode, length of the body
_MESSAGE = struct.Struct('<BQHIQQ')              # record head, channel, sequence, log, publish
_MESSAGE_BODY = struct.Struct('<HIQQ')
_INDEX_ENTRY = struct.Struct('<QQ')              # log time, offset in the chunk's records
_INDEX_HEAD = struct.Struct('<BQHI')             # record head, channel, bytes of entries
_CHUNK_HEAD = struct.Struct('<QQQI')             # start, end, uncompressed size, CRC-32
_CHUNK_INDEX = struct.Struct('<QQQQ')            # start, end, chunk offset, chunk length
_CHANNEL_U64 = struct.Struct('<HQ')
_STATISTICS = struct.Struct('<QHIIIIQQ')
_SUMMARY_OFFSET = struct.Struct('<BQQ')
_FOOTER = struct.Struct('<BQQQ')                 # record head, summary start, offsets start
_MESSAGE_HEAD_BYTES = _MESSAGE.size - _RECORD.size   # 22
#: Errors of a full file system, a quota or the file size limit: recovery makes room.
_NO_SPACE = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG})
#: Room kept under a file size limit for the rosbag2 metadata record a closing embeds:
#: this, and :data:`_TOPIC_ROOM` a channel more (its text takes about 550 bytes a topic).
_METADATA_ROOM = 16 * 1024
_TOPIC_ROOM = 2 * 1024
_ROSBAG2 = 'rosbag2'


class Schema(NamedTuple):
    """A Schema record, and where the data section has it."""

    id: int
    name: str
    encoding: str
    data: str
    offset: int


class Channel(NamedTuple):
    """A Channel record, and where the data section has it."""

    id: int
    schema_id: int
    topic: str
    message_encoding: str
    metadata: Mapping[str, str]
    offset: int


@dataclass
class Chunk:
    """A chunk of the data section, with what its ChunkIndex record says."""

    offset: int
    length: int
    start: int
    end: int
    size: int
    counts: dict[int, int]
    index_offsets: dict[int, int] = field(default_factory=dict)
    index_length: int = 0


# -- encoding --------------------------------------------------------------------


def _string(text: str) -> bytes:
    data = text.encode()
    return _U32.pack(len(data)) + data


def _string_map(mapping: Mapping[str, str]) -> bytes:
    body = b''.join(_string(k) + _string(v) for k, v in mapping.items())
    return _U32.pack(len(body)) + body


def _record(op: int, body: bytes) -> bytes:
    return _RECORD.pack(op, len(body)) + body


def _schema_record(schema: Schema) -> bytes:
    return _record(SCHEMA, _U16.pack(schema.id) + _string(schema.name)
                   + _string(schema.encoding) + _string(schema.data))


def _channel_record(channel: Channel) -> bytes:
    return _record(CHANNEL, _U16.pack(channel.id) + _U16.pack(channel.schema_id)
                   + _string(channel.topic) + _string(channel.message_encoding)
                   + _string_map(channel.metadata))


def _chunk_index_record(chunk: Chunk) -> bytes:
    offsets = b''.join(_CHANNEL_U64.pack(c, o) for c, o in sorted(chunk.index_offsets.items()))
    return _record(CHUNK_INDEX, _CHUNK_INDEX.pack(chunk.start, chunk.end, chunk.offset,
                                                  chunk.length)
                   + _U32.pack(len(offsets)) + offsets + _U64.pack(chunk.index_length)
                   + _string('') + _U64.pack(chunk.size) + _U64.pack(chunk.size))


def _message_indexes(entries: Mapping[int, bytes | bytearray]) -> list[tuple[int, bytes]]:
    """Return ``(channel, MessageIndex record)`` for each channel, in channel order."""
    return [(cid, _INDEX_HEAD.pack(MESSAGE_INDEX, 6 + len(entries[cid]), cid, len(entries[cid]))
             + bytes(entries[cid])) for cid in sorted(entries)]


def closing_records(schemas: Sequence[Schema], channels: Sequence[Channel],
                    chunks: Sequence[Chunk], data_end: int, metadata: str) -> bytes:
    """Return what follows the data section ending at ``data_end``: metadata, summary, footer.

    The layout of rosbags' writer, with the rosbag2 metadata record (the bag's
    ``metadata.yaml`` content, as rosbag2 embeds it), a summary CRC and
    statistics that count only the messages of ``chunks``.
    """
    out = bytearray(_record(METADATA, _string(_ROSBAG2)
                            + _string_map({'serialized_metadata': metadata})))
    metadata_length = len(out)
    out += _record(DATA_END, _U32.pack(0))
    summary_start = data_end + len(out)
    groups: list[tuple[int, int, int]] = []

    def group(op: int, records: list[bytes]) -> None:
        if records:
            groups.append((op, data_end + len(out), sum(len(r) for r in records)))
            out.extend(b''.join(records))

    counts = {c.id: 0 for c in channels}
    for chunk in chunks:
        for cid, n in chunk.counts.items():
            counts[cid] = counts.get(cid, 0) + n
    timed = [c for c in chunks if c.counts]
    start = min((c.start for c in timed), default=0)
    end = max((c.end for c in timed), default=0)
    per_channel = b''.join(_CHANNEL_U64.pack(cid, n) for cid, n in sorted(counts.items()))
    group(SCHEMA, [_schema_record(s) for s in schemas])
    group(CHANNEL, [_channel_record(c) for c in channels])
    group(CHUNK_INDEX, [_chunk_index_record(c) for c in chunks])
    group(METADATA_INDEX, [_record(METADATA_INDEX, _U64.pack(data_end) + _U64.pack(metadata_length)
                                   + _string(_ROSBAG2))])
    group(STATISTICS, [_record(STATISTICS, _STATISTICS.pack(
        sum(counts.values()), len(schemas), len(channels), 0, 1, len(chunks), start, end)
        + _U32.pack(len(per_channel)) + per_channel)])
    summary_offset_start = data_end + len(out)
    for op, offset, length in groups:
        out += _record(SUMMARY_OFFSET, _SUMMARY_OFFSET.pack(op, offset, length))
    footer = _FOOTER.pack(FOOTER, 20, summary_start, summary_offset_start)
    crc = zlib.crc32(footer, zlib.crc32(out[summary_start - data_end:]))
    out += footer + _U32.pack(crc) + MAGIC
    return bytes(out)


def _topics(schemas: Mapping[int, Schema], channels: Mapping[int, Channel]) -> tuple[Topic, ...]:
    topics = []
    for channel in sorted(channels.values(), key=lambda c: c.id):
        schema = schemas.get(channel.schema_id)
        if schema is None:
            msg = (f'Expected a schema for the channel of {channel.topic} (id {channel.id}), '
                   f'got schema id {channel.schema_id}, which the file does not define')
            raise BagError(msg)
        type_hash = channel.metadata.get('topic_type_hash', '') or type_hash_from_definition(
            schema.name, schema.data, schema.encoding)
        topics.append(Topic(channel.id, channel.topic, schema.name, schema.data, schema.encoding,
                            type_hash, parse_qos(channel.metadata.get('offered_qos_profiles', '')),
                            channel.message_encoding))
    return tuple(topics)


# -- writing ---------------------------------------------------------------------


class McapStorage:
    """A new MCAP file, written a chunk at a time.

    Parameters
    ----------
    path : Path
        The file to create; it must not exist.
    library : str
        What the Header record names as the writer.
    """

    #: Suffix of the storage file.
    suffix = '.mcap'

    def __init__(self, path: Path, *, library: str) -> None:
        self.path = path
        self._file: BinaryIO = open(path, 'xb')   # noqa: SIM115 - closed by close()/abort()
        self._offset = 0
        #: ``_offset`` at the last sync.
        self._synced = -1
        self.schemas: dict[int, Schema] = {}
        self.channels: dict[int, Channel] = {}
        self._schema_ids: dict[str, int] = {}
        self.chunks: list[Chunk] = []
        self._chunk = bytearray()
        self._entries: dict[int, bytearray] = {}
        try:
            self._write(MAGIC + _record(HEADER, _string(PROFILE) + _string(library)))
            self._sync()
        except BaseException:
            self.abort()
            raise

    @property
    def pending_bytes(self) -> int:
        """Bytes of messages waiting for the next flush."""
        return len(self._chunk)

    @property
    def counts(self) -> dict[int, int]:
        """Messages on disk (in flushed chunks), by channel id."""
        counts = dict.fromkeys(self.channels, 0)
        for chunk in self.chunks:
            for cid, n in chunk.counts.items():
                counts[cid] += n
        return counts

    @property
    def time_range(self) -> tuple[int, int]:
        """Log times of the first and last message on disk, ns (0, 0 if none)."""
        if not self.chunks:
            return 0, 0
        return min(c.start for c in self.chunks), max(c.end for c in self.chunks)

    def add_topic(self, topic: Topic, qos: str) -> None:
        """Write the Schema of ``topic``'s type (once per type) and its Channel record."""
        schema_id = self._schema_ids.get(topic.type)
        if schema_id is None:
            schema_id = len(self.schemas) + 1
            schema = Schema(schema_id, topic.type, topic.encoding, topic.definition, self._offset)
            self._write(_schema_record(schema))
            self.schemas[schema_id] = schema
            self._schema_ids[topic.type] = schema_id
        channel = Channel(topic.id, schema_id, topic.name, topic.serialization_format,
                          {'offered_qos_profiles': qos, 'topic_type_hash': topic.type_hash},
                          self._offset)
        self._write(_channel_record(channel))
        self.channels[topic.id] = channel

    def write(self, channel_id: int, timestamp: int, data: bytes) -> None:
        """Add a message to the pending chunk (written at the next :meth:`flush`)."""
        chunk = self._chunk
        entries = self._entries.get(channel_id)
        if entries is None:
            entries = self._entries[channel_id] = bytearray()
        entries += _INDEX_ENTRY.pack(timestamp, len(chunk))
        chunk += _MESSAGE.pack(MESSAGE, _MESSAGE_HEAD_BYTES + len(data), channel_id, 0, timestamp,
                               timestamp)
        chunk += data

    def flush(self) -> None:
        """Write the pending chunk and its message indexes; flush and sync the file.

        Nothing is synced when nothing was written since the last sync (an idle topic's
        flushes cost no disk time). Under a file size limit (``RLIMIT_FSIZE``) a
        chunk after which the closing (metadata, summary, footer) would not fit
        is not written: ``OSError`` ``EFBIG``, the file left with every chunk
        before it, room to close it after them (else closing would drop the
        last chunk written, one a flush had said was in the file).
        """
        if self._chunk:
            self._check_room()
            self._write_chunk()
        if self._offset != self._synced:
            self._sync()

    def close(self, version: int, metadata: str) -> None:
        """Flush, write the metadata record, the summary and the footer; close the file.

        ``metadata`` is the bag's rosbag2 metadata (its version is ``version``).
        """
        if self._chunk:
            self._write_chunk()
        self._write(closing_records(list(self.schemas.values()), list(self.channels.values()),
                                    self.chunks, self._offset, metadata))
        self._sync()
        self._file.close()

    def abort(self) -> None:
        """Close the file as it is (after an error; :class:`RecoveredMcap` finishes it)."""
        # The buffered rest may not fit; the scan drops a partial record.
        with contextlib.suppress(OSError):
            self._file.close()

    def _write(self, data: bytes | bytearray) -> None:
        self._file.write(data)
        self._offset += len(data)

    def _sync(self) -> None:
        self._file.flush()
        os.fsync(self._file.fileno())
        self._synced = self._offset

    def _check_room(self) -> None:
        """Refuse (EFBIG) the pending chunk where it and the closing after it pass the limit."""
        limit = _file_size_limit()
        if limit is None:
            return
        # The chunk, its message indexes (at most a record per channel) and the closing.
        chunk = 40 + _RECORD.size + len(self._chunk) + sum(
            len(e) + 32 for e in self._entries.values())
        probe = Chunk(0, 0, 0, 0, 0, {cid: 0 for cid in self._entries})
        probe.index_offsets = {cid: 0 for cid in self._entries}
        closing = len(closing_records(list(self.schemas.values()),
                                      list(self.channels.values()), [*self.chunks, probe],
                                      self._offset + chunk, ''))
        room = _METADATA_ROOM + _TOPIC_ROOM * len(self.channels)
        if self._offset + chunk + closing + room > limit:
            raise OSError(errno.EFBIG, os.strerror(errno.EFBIG))

    def _write_chunk(self) -> None:
        records, entries = self._chunk, self._entries
        self._chunk, self._entries = bytearray(), {}
        times = [t for e in entries.values() for t, _ in _INDEX_ENTRY.iter_unpack(e)]
        offset = self._offset
        head = (_RECORD.pack(CHUNK, 40 + len(records))
                + _CHUNK_HEAD.pack(min(times), max(times), len(records), zlib.crc32(records))
                + _string('') + _U64.pack(len(records)))
        self._write(head)
        self._write(records)
        chunk = Chunk(offset, len(head) + len(records), min(times), max(times), len(records),
                      {cid: len(e) // _INDEX_ENTRY.size for cid, e in entries.items()})
        for cid, record in _message_indexes(entries):
            chunk.index_offsets[cid] = self._offset
            chunk.index_length += len(record)
            self._write(record)
        self.chunks.append(chunk)


def _file_size_limit() -> int | None:
    """Return this process's file size limit (soft ``RLIMIT_FSIZE``), bytes; None if none."""
    try:
        import resource
    except ImportError:     # not a Unix
        return None
    soft = resource.getrlimit(resource.RLIMIT_FSIZE)[0]
    return None if soft == resource.RLIM_INFINITY else int(soft)


# -- recovery --------------------------------------------------------------------


class _Corrupt(Exception):
    """A record that is not what it claims to be (cut short, wrong CRC, out of bounds)."""


class _Fields:
    """Little-endian fields read one after another from a record body."""

    def __init__(self, data: memoryview) -> None:
        self.data = data
        self.pos = 0

    def take(self, n: int) -> memoryview:
        if n < 0 or self.pos + n > len(self.data):
            msg = f'a field of {n} bytes at {self.pos} runs past the record ({len(self.data)})'
            raise _Corrupt(msg)
        self.pos += n
        return self.data[self.pos - n:self.pos]

    def unpack(self, fmt: struct.Struct) -> tuple[int, ...]:
        return fmt.unpack(self.take(fmt.size))

    def string(self) -> str:
        (n,) = self.unpack(_U32)
        try:
            return str(self.take(n), 'utf-8')
        except UnicodeDecodeError as error:
            raise _Corrupt(str(error)) from None

    def string_map(self) -> dict[str, str]:
        (n,) = self.unpack(_U32)
        inner = _Fields(self.take(n))
        out = {}
        while inner.pos < len(inner.data):
            key = inner.string()
            out[key] = inner.string()
        return out

    def schema(self, offset: int) -> Schema:
        (sid,) = self.unpack(_U16)
        return Schema(sid, self.string(), self.string(), self.string(), offset)

    def channel(self, offset: int) -> Channel:
        cid, sid = self.unpack(_U16) + self.unpack(_U16)
        return Channel(cid, sid, self.string(), self.string(), self.string_map(), offset)


@dataclass
class _ParsedChunk:
    chunk: Chunk
    schemas: list[Schema]
    channels: list[Channel]
    entries: dict[int, bytearray]


def _parse_chunk(body: memoryview, offset: int, *, check_crc: bool = True) -> _ParsedChunk:
    """Parse and check the Chunk record at ``offset`` (body ``body``)."""
    fields = _Fields(body)
    start, end, size, crc = fields.unpack(_CHUNK_HEAD)
    compression = fields.string()
    if compression:
        msg = f'Expected uncompressed chunks, got {compression!r} compression at offset {offset}'
        raise BagError(msg)
    (stored,) = fields.unpack(_U64)
    records = fields.take(stored)
    if stored != size or fields.pos != len(body):
        msg = f'sizes disagree ({stored} stored, {size} uncompressed, record {len(body)})'
        raise _Corrupt(msg)
    if check_crc and crc and zlib.crc32(records) != crc:
        raise _Corrupt('CRC-32 mismatch')
    parsed = _ParsedChunk(Chunk(offset, _RECORD.size + len(body), start, end, size, {}), [], [],
                          {})
    pos = 0
    while pos < size:
        if pos + _RECORD.size > size:
            raise _Corrupt('a record head runs past the chunk')
        op, length = _RECORD.unpack_from(records, pos)
        if pos + _RECORD.size + length > size:
            raise _Corrupt('a record runs past the chunk')
        inner = _Fields(records[pos + _RECORD.size:pos + _RECORD.size + length])
        if op == MESSAGE:
            cid, _, log_time, _ = inner.unpack(_MESSAGE_BODY)
            if not start <= log_time <= end:
                raise _Corrupt(f'a message at {log_time} ns outside the chunk [{start}, {end}]')
            parsed.entries.setdefault(cid, bytearray()).extend(_INDEX_ENTRY.pack(log_time, pos))
        elif op == SCHEMA:
            parsed.schemas.append(inner.schema(offset))
        elif op == CHANNEL:
            parsed.channels.append(inner.channel(offset))
        pos += _RECORD.size + length
    parsed.chunk.counts = {cid: len(e) // _INDEX_ENTRY.size for cid, e in parsed.entries.items()}
    return parsed


@dataclass
class _Drop:
    """Bytes of the file that recovery drops, and why."""

    start: int
    end: int
    reason: str
    cut: bool = False       # the end of an interrupted recording: nothing intact follows
    messages: str = ''      # what a dropped chunk held


def _describe(body: memoryview, channels: Mapping[int, Channel]) -> str:
    """Say how many messages of which topics a damaged chunk holds, if its records parse."""
    try:
        parsed = _parse_chunk(body, 0, check_crc=False)
    except (_Corrupt, BagError, struct.error):
        return ''
    chunk = parsed.chunk
    topics = ', '.join(f'{channels[cid].topic if cid in channels else f"channel {cid}"}: {n}'
                       for cid, n in sorted(chunk.counts.items()))
    return (f'{sum(chunk.counts.values())} messages ({topics or "none"}) logged from '
            f'{chunk.start} to {chunk.end} ns, which cannot be told from damaged ones')


_WINDOW = 1 << 22
_RESYNC_OPCODES = re.compile(b'[\x03\x04\x06]')


def _next_record(stream: BinaryIO, start: int, size: int) -> int | None:
    """Return the offset of the first intact Chunk, Schema or Channel record after ``start``.

    A chunk is intact if its sizes agree and its CRC-32 matches; a Schema or
    Channel record if its fields fill it exactly. None if there is none.
    """
    pos = start
    while pos < size:
        stream.seek(pos)
        window = stream.read(_WINDOW + 64)
        for match in _RESYNC_OPCODES.finditer(window, 0, _WINDOW):
            at = pos + match.start()
            if _intact_at(stream, window, match.start(), at, size):
                return at
        pos += _WINDOW
    return None


def _whole_chunk_at(stream: BinaryIO, pos: int, size: int) -> bool:
    """Tell whether the chunk at ``pos`` is whole by its inner sizes and CRC (not its length)."""
    stream.seek(pos + _RECORD.size)
    head = stream.read(_CHUNK_HEAD.size + 4)
    if len(head) < _CHUNK_HEAD.size + 4:
        return False
    _, _, uncompressed, _ = _CHUNK_HEAD.unpack_from(head)
    (compression,) = _U32.unpack_from(head, _CHUNK_HEAD.size)
    if compression or pos + _RECORD.size + 40 + uncompressed > size:
        return False
    stream.seek(pos + _RECORD.size)
    try:
        _parse_chunk(memoryview(stream.read(40 + uncompressed)), pos)
    except (_Corrupt, BagError, struct.error):
        return False
    return True


def _intact_at(stream: BinaryIO, window: bytes, i: int, at: int, size: int) -> bool:
    if i + _RECORD.size + _CHUNK_HEAD.size + 4 > len(window):
        return False
    op, length = _RECORD.unpack_from(window, i)
    end = at + _RECORD.size + length
    if end > size:
        return False
    if op == CHUNK:
        _, _, uncompressed, _ = _CHUNK_HEAD.unpack_from(window, i + _RECORD.size)
        (compression,) = _U32.unpack_from(window, i + _RECORD.size + _CHUNK_HEAD.size)
        if compression or length != 40 + uncompressed:
            return False
    elif length > _WINDOW:
        return False
    stream.seek(at + _RECORD.size)
    body = memoryview(stream.read(length))
    try:
        if op == CHUNK:
            _parse_chunk(body, at)
            return True
        fields = _Fields(body)
        record = fields.schema(at) if op == SCHEMA else fields.channel(at)
    except (_Corrupt, BagError, struct.error):
        return False
    if fields.pos != len(body):
        return False
    if isinstance(record, Channel):
        return record.topic.startswith('/') and bool(record.message_encoding)
    return bool(record.name) and bool(record.encoding)


class RecoveredMcap:
    """An MCAP file scanned to its last intact chunk, to be finished with a summary.

    Opening scans the file (nothing is written); :meth:`finish` writes the
    kept records, the metadata record, the summary and the footer to a new
    file that replaces it (the original kept as ``NAME.damaged``). A file that
    was closed normally and is whole is left as it is.

    Attributes
    ----------
    topics : tuple of Topic
        The channels of the data section kept.
    counts : dict of int to int
        Messages in the chunks kept, by channel id.
    start, end : int
        Log times of the first and last of them, ns (0 if none).
    stored_version : int or None
        Bag version of the embedded rosbag2 metadata, if the file was closed.
    whole : bool
        The file was closed normally and nothing is dropped: :meth:`finish`
        leaves it as it is.
    qos_texts : list of str
        The stored offered QoS profiles (their format tells the bag version).
    notes : list of str
        What recovery did, for the user.
    """

    def __init__(self, path: Path) -> None:
        self.path = path
        self.notes: list[str] = []
        self.stored_version: int | None = None
        self._schemas: dict[int, Schema] = {}
        self._channels: dict[int, Channel] = {}
        self.chunks: list[Chunk] = []
        self._unindexed: list[Chunk] = []
        self._entries: dict[int, dict[int, bytearray]] = {}
        self._drops: list[_Drop] = []
        self._records: list[tuple[int, int]] = []
        self._damaged = False
        self._stale_summary: tuple[int, str] | None = None
        self.whole = False
        try:
            with open(path, 'rb') as stream:
                size = os.fstat(stream.fileno()).st_size
                if size == 0:
                    msg = f'Expected an MCAP file, got "{path}", an empty file'
                    raise BagError(msg)
                self._scan(stream, size)
        except OSError as error:
            msg = f'Expected a readable MCAP file, got "{path}": {error.strerror or error}'
            raise BagError(msg) from None

    @property
    def topics(self) -> tuple[Topic, ...]:
        """The channels kept, as topics."""
        return _topics(self._schemas, self._channels)

    @property
    def qos_texts(self) -> list[str]:
        """The offered QoS profiles as stored, one per channel."""
        return [c.metadata.get('offered_qos_profiles', '') for c in self._channels.values()]

    @property
    def counts(self) -> dict[int, int]:
        """Messages kept, by channel id."""
        counts = dict.fromkeys(self._channels, 0)
        for chunk in self.chunks:
            for cid, n in chunk.counts.items():
                counts[cid] = counts.get(cid, 0) + n
        return counts

    @property
    def start(self) -> int:
        """Log time of the first message kept, ns (0 if none)."""
        return min((c.start for c in self.chunks if c.counts), default=0)

    @property
    def end(self) -> int:
        """Log time of the last message kept, ns (0 if none)."""
        return max((c.end for c in self.chunks if c.counts), default=0)

    def _scan(self, stream: BinaryIO, size: int) -> None:
        path = self.path
        head = stream.read(len(MAGIC) + _RECORD.size)
        if len(head) < len(MAGIC) + _RECORD.size or head[:len(MAGIC)] != MAGIC:
            msg = f'Expected an MCAP file, got "{path}", which does not start as one'
            raise BagError(msg)
        op, length = _RECORD.unpack_from(head, len(MAGIC))
        pos = len(head) + length
        if op != HEADER or pos > size:
            msg = f'Expected an MCAP Header record after the magic of "{path}", got none'
            raise BagError(msg)
        try:
            profile = _Fields(memoryview(stream.read(length))).string()
        except _Corrupt:
            profile = '?'
        if profile != PROFILE:
            msg = f'Expected the MCAP profile "{PROFILE}" in "{path}", got "{profile}"'
            raise BagError(msg)
        self.header_end = self.data_end = pos
        pending: _ParsedChunk | None = None
        missing: set[int] = set()
        closed = False
        while pos + _RECORD.size <= size:
            stream.seek(pos)
            op, length = _RECORD.unpack(stream.read(_RECORD.size))
            end = pos + _RECORD.size + length
            damage = ''
            if end > size:
                damage = 'a record cut short'
            elif op == 0:
                damage = 'zeroes where a record should start'
            if damage:
                if pending is not None:
                    self._keep_unindexed(pending)
                    pending = None
                whole = op == CHUNK and _whole_chunk_at(stream, pos, size)
                if whole:
                    damage = 'a chunk whose length field is damaged'
                resume = self._drop(stream, pos, size, damage, cut=not whole)
                if resume is None:
                    break
                pos = resume
                continue
            body = memoryview(stream.read(length))
            if pending is not None:
                if op == MESSAGE_INDEX and self._index_matches(body, pending, missing):
                    (cid,) = _U16.unpack_from(body)
                    pending.chunk.index_offsets[cid] = pos
                    pending.chunk.index_length += end - pos
                    missing.discard(cid)
                    if not missing:
                        self._keep(pending, end)
                        pending = None
                    pos = end
                    continue
                self._keep_unindexed(pending)
                pending = None
                if op == MESSAGE_INDEX:
                    resume = self._drop(stream, pos, size,
                                        'a message index that does not match its chunk')
                    if resume is None:
                        break
                    pos = resume
                    continue
            if op == CHUNK:
                try:
                    parsed = _parse_chunk(body, pos)
                except _Corrupt as error:
                    resume = self._drop(stream, pos, size, f'a damaged chunk ({error})',
                                        body=body)
                    if resume is None:
                        break
                    pos = resume
                    continue
                if parsed.chunk.counts:
                    pending, missing = parsed, set(parsed.chunk.counts)
                else:
                    self._keep(parsed, end)
            elif op in (SCHEMA, CHANNEL):
                try:
                    fields = _Fields(body)
                    record = fields.schema(pos) if op == SCHEMA else fields.channel(pos)
                except _Corrupt as error:
                    resume = self._drop(stream, pos, size, f'a damaged record ({error})')
                    if resume is None:
                        break
                    pos = resume
                    continue
                known = self._schemas if op == SCHEMA else self._channels
                if record.id not in known:      # the summary repeats them after a resync
                    known[record.id] = record
                    self._records.append((pos, end))
                self.data_end = end
            elif op == MESSAGE:
                msg = f'Expected the messages of "{path}" in chunks, got one at offset {pos}'
                raise BagError(msg)
            elif op == METADATA:
                try:
                    fields = _Fields(body)
                    name, values = fields.string(), fields.string_map()
                except _Corrupt as error:
                    resume = self._drop(stream, pos, size, f'a damaged record ({error})')
                    if resume is None:
                        break
                    pos = resume
                    continue
                if name == _ROSBAG2:
                    closed, resume = self._closing(stream, pos, size)
                    if closed:
                        self.stored_version = stored_version(
                            values.get('serialized_metadata', ''))
                    if closed or resume is None:
                        break
                    pos = resume
                    continue
                self._records.append((pos, end))
                self.data_end = end
            elif op in (DATA_END, FOOTER, CHUNK_INDEX, STATISTICS, METADATA_INDEX,
                        SUMMARY_OFFSET):
                closed, resume = self._closing(stream, pos, size)
                if closed or resume is None:
                    break
                pos = resume
                continue
            elif op in (ATTACHMENT, ATTACHMENT_INDEX):
                self._records.append((pos, end))    # attachments stay as they are
                self.data_end = end
            else:
                resume = self._drop(stream, pos, size, f'a record of unknown opcode {op:#04x}',
                                    body=body, counted=False)
                if resume is None:
                    break
                pos = resume
                continue
            pos = end
        if pending is not None:     # a chunk whose message indexes were cut: written again
            self._keep_unindexed(pending)
            if not closed and size > self.data_end:
                self._drops.append(_Drop(self.data_end, size, 'message indexes cut short',
                                         cut=True))
        # Its writer may finish it in place if what is dropped is the end of its recording.
        self._damaged = (any(not d.cut for d in self._drops) or self._stale_summary is not None
                         or any(u is not self.chunks[-1] for u in self._unindexed))
        self.whole = (closed and not self._drops and not self._unindexed
                      and self._stale_summary is None)
        self._note_drops(closed, size)
        if self._stale_summary is not None and not self._drops:
            at, problem = self._stale_summary
            self.notes.append(f'replaced the closing records {problem} (from offset {at} to '
                              f'the end)')

    def _note_drops(self, closed: bool, size: int) -> None:
        for drop in self._drops:
            what = f'{drop.end - drop.start} bytes from offset {drop.start}: {drop.reason}'
            if drop.messages:
                what += f' holding {drop.messages}'
            if drop.cut and drop.end == size:
                what += ' (the recording was interrupted)'
            self.notes.append(f'dropped {what}')
        if not self._drops and not closed and size > self.data_end:
            self.notes.append(f'dropped {size - self.data_end} bytes from offset '
                              f'{self.data_end}: a record cut short '
                              f'(the recording was interrupted)')

    def _closing(self, stream: BinaryIO, pos: int, size: int) -> tuple[bool, int | None]:
        """Judge the closing records that start at ``pos``; return (closed, where to go on).

        They close the file if they end it (a footer and the magic at its
        end); if they do not index exactly the chunks kept before them, the
        file is not whole (they are written anew). Closing records followed by
        more data (written into a file that was still being written) are
        dropped as far as they go, and the scan goes on after them; closing
        records that are cut short, up to the next intact record, if any.
        """
        stop, complete = _walk_closing(stream, pos, size)
        if complete and stop == size:
            problem = self._summary_problem(stream, pos, size)
            if problem:
                self._stale_summary = (pos, problem)
            return True, None
        if complete:
            self._drops.append(_Drop(pos, stop, 'closing records with more data after them '
                                                '(a summary written before the recording '
                                                'went on)'))
            return False, stop
        return False, self._drop(stream, pos, size, 'closing records cut short', cut=True,
                                 search_from=stop)

    def _summary_problem(self, stream: BinaryIO, pos: int, size: int) -> str:
        """Say why the closing records from ``pos`` to the end are not the file's ('' if they are).

        They must be Metadata records and a DataEnd, then the summary the
        footer points to, whose CRC (if any) matches, whose chunk indexes are
        the chunks kept (offsets, lengths, message index offsets) and whose
        statistics count their messages.
        """
        footer_at = size - len(MAGIC) - _FOOTER.size - 4
        stream.seek(footer_at)
        tail = stream.read(_FOOTER.size + 4)
        _, _, summary_start, offsets_start = _FOOTER.unpack_from(tail)
        (crc,) = _U32.unpack_from(tail, _FOOTER.size)
        if not pos < summary_start <= footer_at:
            return 'with no summary that the footer points to'
        if not (offsets_start == 0 or summary_start <= offsets_start <= footer_at):
            return 'whose footer points outside the summary'
        stream.seek(pos)
        before = stream.read(summary_start - pos)
        ops = [op for op, _ in _records_in(before)]
        if not ops or ops[-1] != DATA_END or set(ops) - {METADATA, DATA_END} \
                or sum(_RECORD.size + n for _, n in _records_in(before)) != len(before):
            return 'with no data end before the summary'
        stream.seek(summary_start)
        summary = stream.read(footer_at + _FOOTER.size - summary_start)
        if crc and zlib.crc32(summary) != crc:
            return 'whose summary CRC does not match'
        end = (offsets_start or footer_at) - summary_start
        indexed, channels, counted = [], set(), None
        walked = 0
        try:
            for op, body in _bodies_in(memoryview(summary)[:end]):
                walked += _RECORD.size + len(body)
                fields = _Fields(body)
                if op == CHUNK_INDEX:
                    _, _, offset, length = fields.unpack(_CHUNK_INDEX)
                    entries = _Fields(fields.take(fields.unpack(_U32)[0]))
                    offsets = {}
                    while entries.pos < len(entries.data):
                        cid, at = entries.unpack(_CHANNEL_U64)
                        offsets[cid] = at
                    indexed.append((offset, length, offsets))
                elif op == CHANNEL:
                    channels.add(fields.unpack(_U16)[0])
                elif op == STATISTICS:
                    counted = fields.unpack(_U64)[0]
        except _Corrupt as error:
            return f'with a damaged summary ({error})'
        if walked != end:
            return 'with a damaged summary (a record runs past it)'
        kept = [(c.offset, c.length, c.index_offsets) for c in self.chunks]
        if sorted(indexed, key=lambda i: i[0]) != kept:
            return 'that do not index the chunks before them'
        if not set(self._channels) <= channels:
            return 'that do not list the channels before them'
        if counted is not None and counted != sum(sum(c.counts.values()) for c in self.chunks):
            return 'whose statistics do not count the messages before them'
        return ''

    def _drop(self, stream: BinaryIO, pos: int, size: int, reason: str, *, cut: bool = False,
              body: memoryview | None = None, counted: bool = True,
              search_from: int | None = None) -> int | None:
        """Record that the bytes from ``pos`` are dropped; return where the next record starts.

        The next record is the next intact chunk (its CRC checked) or Schema or
        Channel record after ``pos`` (from ``search_from`` if given); None if
        there is none (the rest is dropped).
        """
        resume = _next_record(stream, pos + 1 if search_from is None else search_from, size)
        end = size if resume is None else resume
        messages = _describe(body, self._channels) if body is not None else ''
        if body is not None and counted and not messages:
            messages = 'messages that cannot be counted'
        self._drops.append(_Drop(pos, end, reason, cut=cut and resume is None,
                                 messages=messages))
        return resume

    def _keep_unindexed(self, parsed: _ParsedChunk) -> None:
        """Keep a chunk (its CRC checked) whose message indexes are missing or damaged."""
        chunk = parsed.chunk
        self._keep(parsed, chunk.offset + chunk.length)
        self._unindexed.append(chunk)
        self._entries[chunk.offset] = parsed.entries

    def _index_matches(self, body: memoryview, pending: _ParsedChunk, missing: set[int]) -> bool:
        """Tell whether ``body`` is a message index of ``pending`` holding its chunk's entries."""
        if len(body) < 6:
            return False
        cid, nbytes = struct.unpack_from('<HI', body)
        if not (cid in missing and nbytes + 6 == len(body)
                and nbytes == _INDEX_ENTRY.size * pending.chunk.counts[cid]):
            return False
        expected = pending.entries[cid]
        return (body[6:] == expected      # as written here; other writers may sort by time
                or sorted(_INDEX_ENTRY.iter_unpack(body[6:]))
                == sorted(_INDEX_ENTRY.iter_unpack(expected)))

    def _keep(self, parsed: _ParsedChunk, end: int) -> None:
        for schema in parsed.schemas:
            self._schemas.setdefault(schema.id, schema)
        for channel in parsed.channels:
            self._channels.setdefault(channel.id, channel)
        self.chunks.append(parsed.chunk)
        self.data_end = end

    def _drop_last_chunk(self) -> None:
        chunk = self.chunks.pop()
        self.data_end = chunk.offset
        self._schemas = {k: s for k, s in self._schemas.items() if s.offset < chunk.offset}
        self._channels = {k: c for k, c in self._channels.items() if c.offset < chunk.offset}
        self.notes.append(f'dropped the last chunk ({sum(chunk.counts.values())} messages) '
                          f'to make room for the summary')

    def finish(self, metadata: Callable[[], str], *, in_place: bool = False) -> None:
        """Make the file readable with every chunk kept, a summary at its end; sync it.

        A whole file (:attr:`whole`) is left as it is. Otherwise the kept
        records are copied to a new file, synced, which replaces the original;
        the original is kept as ``NAME.damaged`` (see :mod:`.salvage`).
        ``metadata()`` is the rosbag2 metadata to embed.

        ``in_place`` is for the file's own writer, which holds its lock: if
        only the end of its recording is dropped, the file is truncated after
        its data section and the summary appended, and ``metadata()`` is
        called again whenever a chunk had to be dropped for lack of space.

        Raises
        ------
        OSError
            If the copy cannot be written whole (then the original is
            unchanged and no copy is left), or in place, if even a summary of
            no chunk at all cannot be written.
        """
        if self.whole:
            return
        if self._damaged or not in_place:
            self._finish_copy(metadata)
            return
        fd = os.open(self.path, os.O_RDWR)
        try:
            if self._unindexed:
                self._write_indexes(fd, self._unindexed[-1])
            while True:
                closing = closing_records(list(self._schemas.values()),
                                          list(self._channels.values()), self.chunks,
                                          self.data_end, metadata())
                try:
                    os.ftruncate(fd, self.data_end)
                    _pwrite_all(fd, closing, self.data_end)
                    os.fsync(fd)
                    return
                except OSError as error:
                    if error.errno not in _NO_SPACE or not self.chunks:
                        raise
                self._drop_last_chunk()
        finally:
            os.close(fd)

    def _write_indexes(self, fd: int, chunk: Chunk) -> None:
        offset = chunk.offset + chunk.length
        records = _message_indexes(self._entries[chunk.offset])
        chunk.index_offsets, chunk.index_length = {}, 0
        for cid, record in records:
            chunk.index_offsets[cid] = offset + chunk.index_length
            chunk.index_length += len(record)
        try:
            os.ftruncate(fd, offset)
            _pwrite_all(fd, b''.join(r for _, r in records), offset)
        except OSError as error:
            if error.errno not in _NO_SPACE:
                raise
            self.chunks.pop()
            self.data_end = chunk.offset
            self.notes.append(f'dropped the last chunk ({sum(chunk.counts.values())} messages): '
                              f'no room for its message indexes')
            return
        self.data_end = offset + chunk.index_length
        self.notes.append(f'rewrote the message indexes of the last chunk (offset {chunk.offset})')

    def _finish_copy(self, metadata: Callable[[], str]) -> None:
        """Copy the kept records to a new file, with a summary; it replaces the original.

        A chunk's message indexes, checked entry by entry by the scan, are
        copied as they are (their entries are offsets inside the chunk); those
        of a chunk whose indexes were missing or damaged are built again.
        """
        copy = new_copy_path(self.path)
        rebuilt = {c.offset for c in self._unindexed}
        try:
            with open(self.path, 'rb') as source, open(copy, 'xb') as out:
                source.seek(0)
                out.write(source.read(self.header_end))
                offset = self.header_end
                chunks: list[Chunk] = []
                kept = sorted([(c.offset, c.length, c) for c in self.chunks]
                              + [(start, end - start, None) for start, end in self._records],
                              key=lambda item: item[0])
                for start, length, chunk in kept:
                    source.seek(start)
                    if chunk is None:
                        out.write(source.read(length))
                        offset += length
                        continue
                    new = Chunk(offset, chunk.length, chunk.start, chunk.end, chunk.size,
                                dict(chunk.counts))
                    if start in rebuilt:
                        out.write(source.read(length))
                        position = offset + length
                        for cid, record in _message_indexes(self._entries[start]):
                            new.index_offsets[cid] = position + new.index_length
                            new.index_length += len(record)
                            out.write(record)
                    else:       # the chunk and its message indexes, which follow it
                        out.write(source.read(length + chunk.index_length))
                        new.index_offsets = {cid: at - start + offset
                                             for cid, at in chunk.index_offsets.items()}
                        new.index_length = chunk.index_length
                    chunks.append(new)
                    offset += length + new.index_length
                self.chunks = chunks
                out.write(closing_records(list(self._schemas.values()),
                                          list(self._channels.values()), chunks, offset,
                                          metadata()))
                out.flush()
                os.fsync(out.fileno())
            kept_as = replace_keeping_original(self.path, copy)
        except BaseException:
            with contextlib.suppress(OSError):
                copy.unlink()
            raise
        again = f' (built again for {len(rebuilt)} of them)' if rebuilt else ''
        self.notes.append(f'wrote the {len(chunks)} intact chunks and their message indexes'
                          f'{again} to a new "{self.path.name}"; the original file is kept as '
                          f'"{kept_as.name}"')


_CLOSING_OPS = frozenset({METADATA, DATA_END, SCHEMA, CHANNEL, CHUNK_INDEX, METADATA_INDEX,
                          STATISTICS, SUMMARY_OFFSET, ATTACHMENT_INDEX})


def _walk_closing(stream: BinaryIO, pos: int, size: int) -> tuple[int, bool]:
    """Walk the closing records from ``pos``; return where they stop and if they are complete.

    Complete: they end with a Footer record and the magic (the position
    returned is after the magic). Otherwise the position is that of the first
    record that is cut short or is not a closing record.
    """
    while pos + _RECORD.size <= size:
        stream.seek(pos)
        op, length = _RECORD.unpack(stream.read(_RECORD.size))
        end = pos + _RECORD.size + length
        if end > size:
            break
        if op == FOOTER:
            stream.seek(end)
            if length == _FOOTER.size - _RECORD.size + 4 and stream.read(len(MAGIC)) == MAGIC:
                return end + len(MAGIC), True
            break
        if op not in _CLOSING_OPS:
            break
        pos = end
    return pos, False


def _bodies_in(data: memoryview) -> Iterator[tuple[int, memoryview]]:
    """Yield (opcode, body) of the records that fill ``data`` one after another (as many fit)."""
    pos = 0
    while pos + _RECORD.size <= len(data):
        op, length = _RECORD.unpack_from(data, pos)
        end = pos + _RECORD.size + length
        if end > len(data):
            return
        yield op, data[pos + _RECORD.size:end]
        pos = end


def _records_in(data: bytes) -> list[tuple[int, int]]:
    """Return (opcode, body length) of the records that fill ``data`` (as many fit)."""
    return [(op, len(body)) for op, body in _bodies_in(memoryview(data))]


def _pwrite_all(fd: int, data: bytes, offset: int) -> None:
    view = memoryview(data)
    while view:
        written = os.pwrite(fd, view, offset)
        view, offset = view[written:], offset + written
