# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A :class:`~.writer.BagWriter` written by a thread of its own: receiving never waits on the disk.

A recorder takes each message in its executor's thread; the ``resilient``
writer flushes and syncs the storage file every half second, and on a
loaded machine one ``fsync`` can take seconds. While the executor waits on
it, the middleware's queue of each subscription (``QUEUE_DEPTH``, 2 s of a
500 Hz topic) fills and drops the oldest messages: the bag loses what was
published (``test_a_slow_disk_delays_the_bag_and_loses_nothing``).

:class:`QueuedWriter` takes the same calls. :meth:`QueuedWriter.add_topic`
and :meth:`QueuedWriter.write` only append to a queue in memory (a topic's
id is given at once, its record written in order before its messages); a
thread of its own writes the queue to the :class:`BagWriter` and flushes
it when the writer says a flush is due (:meth:`BagWriter.flush_due`), each
time after writing everything queued, so the writer is used by one thread and
a message reaches the file within an interval and two flushes
(:attr:`last_flush` says what the last one wrote, and how long it took).
:meth:`QueuedWriter.close` writes everything queued before it closes the
bag: what was received is written, however slow the disk.

The queue is bounded: while the messages waiting in it hold ``max_bytes``
(their serialized bytes; :data:`MAX_QUEUE_BYTES` by default, 100 MiB as
``ros2 bag record``'s ``--max-cache-size``), a message that would pass the
bound is dropped and counted per topic in :attr:`QueuedWriter.dropped`, as
rosbag2's cache drops and counts what overflows it. A disk stalled for a
minute can no longer fill the memory with a minute of messages; the bag
keeps what came before the stall and what came once the disk caught up.
"""

from __future__ import annotations

from collections import deque
import threading
from typing import Any

from .metadata import BagError, BagInfo, Topic
from .writer import BagWriter, Flush

__all__ = ['MAX_QUEUE_BYTES', 'QueuedWriter', 'WRITE_POLL_S']

#: Longest wait of a received message before the writing thread takes it, s.
WRITE_POLL_S = 0.02
#: Default bound of the messages waiting for the writing thread, bytes (rosbag2's default
#: ``max_cache_size``).
MAX_QUEUE_BYTES = 100 * 1024 * 1024


class QueuedWriter:
    """Queue topics and messages for ``writer`` (open); a thread of its own writes them.

    Parameters
    ----------
    writer : BagWriter
        Open. From now on used only through this object.
    max_bytes : int
        Most bytes of messages waiting to be written; a message that would
        pass it is dropped (:attr:`dropped`).

    Attributes
    ----------
    dropped : dict of str to int
        Messages dropped because the queue was full, by topic name (only
        topics that lost one). Written by the thread that calls :meth:`write`.
    """

    def __init__(self, writer: BagWriter, max_bytes: int = MAX_QUEUE_BYTES) -> None:
        if isinstance(max_bytes, bool) or not (isinstance(max_bytes, int) and max_bytes > 0):
            msg = f'Expected a positive number of bytes for the queue, got {max_bytes!r}'
            raise BagError(msg)
        self.writer = writer
        self.max_bytes = max_bytes
        self.dropped: dict[str, int] = {}
        self._queue: deque[tuple[Any, ...]] = deque()
        # Bytes queued and bytes taken, each counted by one thread only: their difference is
        # what waits, without a lock.
        self._queued_bytes = 0
        self._taken_bytes = 0
        self._closing = threading.Event()
        self._thread = threading.Thread(target=self._run, name='bag writer', daemon=True)
        self._thread.start()

    @property
    def failure(self) -> str | None:
        """Return the writer's failure (None while writing goes well)."""
        return self.writer.failure

    @property
    def last_flush(self) -> Flush | None:
        """Return the writer's last flush that wrote messages (:attr:`BagWriter.last_flush`)."""
        return self.writer.last_flush

    def add_topic(self, name: str, type_name: str, **kwargs: Any) -> Topic:
        """As :meth:`BagWriter.add_topic`; its record is written by the thread, in order."""
        topic = self.writer.new_topic(name, type_name, **kwargs)
        self._queue.append((topic,))
        return topic

    @property
    def dropped_total(self) -> int:
        """Return the messages dropped so far because the queue was full."""
        return sum(self.dropped.values())

    def write(self, topic: Topic, timestamp: int, data: bytes) -> bool:
        """Queue one message; return False if it was dropped (the queue full).

        Raises
        ------
        BagError
            If writing has failed.
        """
        self.check()
        size = len(data)
        if self._queued_bytes - self._taken_bytes + size > self.max_bytes:
            self.dropped[topic.name] = self.dropped.get(topic.name, 0) + 1
            return False
        self._queued_bytes += size
        self._queue.append((topic, timestamp, data))
        return True

    def check(self) -> None:
        """Raise :class:`BagError` if writing has failed (the thread writes and flushes)."""
        failure = self.writer.failure
        if failure is not None:
            raise BagError(failure)

    def close(self) -> BagInfo:
        """Write what is queued, stop the thread and close the bag (:meth:`BagWriter.close`)."""
        self._closing.set()
        self._thread.join()
        self._drain()
        return self.writer.close()

    def _run(self) -> None:
        writer = self.writer
        while not self._closing.wait(WRITE_POLL_S):
            self._drain()
            if writer.failure is None and writer.flush_due():
                try:
                    writer.flush()
                except BagError:
                    pass        # kept in writer.failure: the next write() raises it

    def _drain(self) -> None:
        """Write every queued topic and message (after a failure, drop them: close() says)."""
        queue, writer = self._queue, self.writer
        try:
            while queue and writer.failure is None:
                item = queue.popleft()
                if len(item) == 1:
                    writer.add(item[0])
                else:
                    self._taken_bytes += len(item[2])
                    writer.append(*item)
        except BagError:
            pass            # kept in writer.failure
        if writer.failure is not None:
            queue.clear()
