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
write error) scans a file record by record, keeps every intact chunk (length,
CRC and each message checked), truncates what follows the last one (a chunk
cut short, a partial message index, an old summary), rewrites the message
indexes of the last chunk if they were cut, and appends the summary that a
normal close writes, built by the same function. If the file system has no
room for the summary, the last chunks are dropped until it fits.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
import errno
import os
from pathlib import Path
import struct
from typing import BinaryIO, NamedTuple
import zlib

from .metadata import (BagError, parse_qos, stored_version, Topic,
                       type_hash_from_definition)

__all__ = ['MAGIC', 'McapStorage', 'RecoveredMcap']

MAGIC = b'\x89MCAP0\r\n'
PROFILE = 'ros2'

# Record opcodes (MCAP specification).
HEADER, FOOTER, SCHEMA, CHANNEL, MESSAGE, CHUNK, MESSAGE_INDEX, CHUNK_INDEX = range(1, 9)
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
        """Write the pending chunk and its message indexes; flush and sync the file."""
        if self._chunk:
            self._write_chunk()
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
        try:
            self._file.close()
        except OSError:
            pass    # the buffered rest may not fit; the scan drops a partial record

    def _write(self, data: bytes | bytearray) -> None:
        self._file.write(data)
        self._offset += len(data)

    def _sync(self) -> None:
        self._file.flush()
        os.fsync(self._file.fileno())

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


def _parse_chunk(body: memoryview, offset: int) -> _ParsedChunk:
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
    if crc and zlib.crc32(records) != crc:
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


class RecoveredMcap:
    """An MCAP file scanned to its last intact chunk, to be finished with a summary.

    Opening scans the file (nothing is written); :meth:`finish` truncates what
    follows the data section and appends the metadata record, the summary and
    the footer. A file that was closed normally keeps every message: only
    its summary is rewritten.

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
        self._unindexed: _ParsedChunk | None = None
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
        self.data_end = pos
        pending: _ParsedChunk | None = None
        missing: set[int] = set()
        tail = ''
        closed = False
        while pos + _RECORD.size <= size:
            op, length = _RECORD.unpack(stream.read(_RECORD.size))
            end = pos + _RECORD.size + length
            if end > size:
                tail = 'a record cut short'
                break
            if op == 0:
                tail = 'zeroes where a record should start'
                break
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
                if op != MESSAGE_INDEX:
                    msg = (f'Expected message indexes after the chunk at offset '
                           f'{pending.chunk.offset} of "{path}", got a record of opcode '
                           f'{op:#04x}; files without message indexes are not supported')
                    raise BagError(msg)
                tail = 'a message index that does not match its chunk'
                break
            if op == CHUNK:
                try:
                    parsed = _parse_chunk(body, pos)
                except _Corrupt as error:
                    tail = f'a damaged chunk ({error})'
                    break
                if parsed.chunk.counts:
                    pending, missing = parsed, set(parsed.chunk.counts)
                else:
                    self._keep(parsed, end)
            elif op in (SCHEMA, CHANNEL):
                try:
                    fields = _Fields(body)
                    record = fields.schema(pos) if op == SCHEMA else fields.channel(pos)
                except _Corrupt as error:
                    tail = f'a damaged record ({error})'
                    break
                (self._schemas if op == SCHEMA else self._channels)[record.id] = record
                self.data_end = end
            elif op == MESSAGE:
                msg = f'Expected the messages of "{path}" in chunks, got one at offset {pos}'
                raise BagError(msg)
            elif op == METADATA:
                try:
                    fields = _Fields(body)
                    name, values = fields.string(), fields.string_map()
                except _Corrupt as error:
                    tail = f'a damaged record ({error})'
                    break
                if name == _ROSBAG2:
                    self.stored_version = stored_version(values.get('serialized_metadata', ''))
                    closed = True
                    break
                self.data_end = end
            elif op in (DATA_END, FOOTER, CHUNK_INDEX, STATISTICS, METADATA_INDEX,
                        SUMMARY_OFFSET):
                closed = True
                break
            else:
                self.data_end = end     # attachments or unknown records stay as they are
            pos = end
        if pending is not None:     # a chunk whose message indexes were cut: written again
            self.data_end = pending.chunk.offset + pending.chunk.length
            self._unindexed = pending
            tail = tail or 'message indexes cut short'
        if not closed and size > self.data_end:
            self.notes.append(f'dropped {size - self.data_end} bytes from offset '
                              f'{self.data_end}: {tail or "a record cut short"} '
                              f'(the recording was interrupted)')

    def _index_matches(self, body: memoryview, pending: _ParsedChunk, missing: set[int]) -> bool:
        if len(body) < 6:
            return False
        cid, nbytes = struct.unpack_from('<HI', body)
        return (cid in missing and nbytes + 6 == len(body)
                and nbytes == _INDEX_ENTRY.size * pending.chunk.counts[cid])

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

    def finish(self, metadata: Callable[[], str]) -> None:
        """Truncate after the data section and append the summary; sync the file.

        ``metadata()`` is the rosbag2 metadata to embed; it is called again
        whenever a chunk had to be dropped for lack of space.

        Raises
        ------
        OSError
            If even a summary of no chunk at all cannot be written.
        """
        fd = os.open(self.path, os.O_RDWR)
        try:
            if self._unindexed is not None:
                self._write_indexes(fd, self._unindexed)
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

    def _write_indexes(self, fd: int, parsed: _ParsedChunk) -> None:
        chunk = parsed.chunk
        offset = chunk.offset + chunk.length
        records = _message_indexes(parsed.entries)
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
            self.data_end = chunk.offset
            self.notes.append(f'dropped the last chunk ({sum(chunk.counts.values())} messages): '
                              f'no room for its message indexes')
            return
        self._keep(parsed, offset + chunk.index_length)
        self.notes.append(f'rewrote the message indexes of the last chunk (offset {chunk.offset})')


def _pwrite_all(fd: int, data: bytes, offset: int) -> None:
    view = memoryview(data)
    while view:
        written = os.pwrite(fd, view, offset)
        view, offset = view[written:], offset + written
