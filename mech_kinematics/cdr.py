# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Pre-serialized ROS messages whose stamp and float64 fields are patched in place.

Serializing a message object costs far more than the numbers in it change.
:class:`MessageTemplate` serializes a message once, with a marker value in
the header stamp and in every float64 field that changes, finds where each
marker sits in the CDR bytes, and from then on writes new values at those
offsets with :mod:`struct`. ``rclpy`` publishes the resulting ``bytes`` as
they are (``Publisher.publish`` accepts serialized data).

This relies on nothing but the fact that CDR stores a fixed-size field at a
fixed offset once the lengths of every sequence and string are fixed, which
they are here: the names and the number of joints and points never change
while the node runs. ``test/test_kinematics_node_cdr.py`` checks that the bytes
decode with ``rclpy.serialization.deserialize_message`` to exactly the
message built the ordinary way.
"""

from __future__ import annotations

from collections.abc import Sequence
import struct
from typing import Any

from rclpy.serialization import serialize_message

__all__ = ['MessageTemplate', 'STAMP_MARKER', 'marker']

#: Header stamp (sec, nanosec) that marks where the stamp is serialized.
STAMP_MARKER = (0x5EC04D17, 0x2C5A7E31)

_MARKER_BASE = 0x7FE5A5C35A3C0000   # a large finite float64; slot index in the low bits


def marker(index: int) -> float:
    """Return the float64 that marks slot ``index`` (0 <= index < 65536)."""
    if not 0 <= index < 0x10000:
        msg = f'Expected a slot index in [0, 65536), got {index}'
        raise ValueError(msg)
    value: float = struct.unpack('<d', struct.pack('<Q', _MARKER_BASE + index))[0]
    return value


def _find_once(data: bytes, pattern: bytes, what: str) -> int:
    offset = data.find(pattern)
    if offset < 0 or data.find(pattern, offset + 1) >= 0:
        msg = f'Expected {what} exactly once in the serialized message'
        raise ValueError(msg)
    return offset


class MessageTemplate:
    """A serialized message with its header stamp and ``n_slots`` float64 fields patchable.

    Parameters
    ----------
    msg : ROS message
        A message with ``header.stamp`` set to :data:`STAMP_MARKER` and the
        fields to patch set to ``marker(0)``, ``marker(1)``, ...,
        ``marker(n_slots - 1)``; every other field holds its final value.
    n_slots : int
        Number of float64 slots.

    Raises
    ------
    ValueError
        If a marker is not found exactly once in the serialized bytes.
    """

    def __init__(self, msg: Any, n_slots: int) -> None:
        data = serialize_message(msg)
        # Encapsulation header: 0x00 0x01 is little-endian CDR, 0x00 0x00 big-endian.
        order = '<' if data[1] & 1 else '>'
        self._stamp = struct.Struct(order + 'iI')
        self._stamp_offset = _find_once(data, self._stamp.pack(*STAMP_MARKER),
                                        'the header stamp marker')
        offsets = [_find_once(data, struct.pack(order + 'd', marker(i)), f'slot {i}')
                   for i in range(n_slots)]
        buffer = bytearray(data)
        for offset in offsets:
            buffer[offset:offset + 8] = bytes(8)
        self._buffer = buffer
        self.n_slots = n_slots
        # Group the slots into runs written by one struct each. Slots next to
        # each other share a run, and so do slots separated only by zero bytes
        # (the z and angular parts of a Twist): the run writes those zeros again.
        runs: list[tuple[Any, int, int, int]] = []
        start = 0
        fmt = ''
        for i in range(n_slots):
            fmt += 'd'
            last = i == n_slots - 1
            gap = 0 if last else offsets[i + 1] - offsets[i] - 8
            if not last and gap >= 0 and not any(buffer[offsets[i] + 8:offsets[i + 1]]):
                if gap:
                    fmt += f'{gap}x'
                continue
            runs.append((struct.Struct(order + fmt).pack_into, offsets[start], start, i + 1))
            start, fmt = i + 1, ''
        self._runs = tuple(runs)

    def render(self, sec: int, nanosec: int, values: Sequence[float]) -> bytes:
        """Return the serialized message with this stamp and slot values (in slot order)."""
        buffer = self._buffer
        self._stamp.pack_into(buffer, self._stamp_offset, sec, nanosec)
        for pack_into, offset, start, stop in self._runs:
            pack_into(buffer, offset, *values[start:stop])
        return bytes(buffer)
