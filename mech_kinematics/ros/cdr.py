# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Canonical CDR bytes of ROS messages, and templates whose float64 fields are patched in place.

:func:`cdr_from_message` serializes a ``rosidl`` Python message (plain CDR,
XCDR1, little-endian, encapsulation header ``00 01 00 00``) from the type
information the generated class carries (``get_fields_and_field_types()`` and
``SLOT_TYPES``). Unlike ``rclpy.serialization.serialize_message``, whose bytes
on the Kilted wheels run past the end of the message and hold uninitialized
memory in the alignment padding and the tail, the result has exactly the
length of the message and zero padding: the bytes ``rosbags`` writes, which
its strict ``deserialize_cdr`` accepts.

Serializing a message object costs far more than the numbers in it change.
:class:`MessageTemplate` serializes a message once, with a marker value in
the header stamp and in every float64 field that changes, finds where each
marker sits in the CDR bytes, and from then on makes the message's bytes with
one :mod:`struct` pack: the fixed bytes between the markers as constant
fields, the stamp and the new values in their places (a function written for
the template makes that one call). ``rclpy`` publishes the resulting
``bytes`` as they are (``Publisher.publish`` accepts serialized data).

This relies on nothing but the fact that CDR stores a fixed-size field at a
fixed offset once the lengths of every sequence and string are fixed, which
they are here: the names and the number of joints and points never change
while the node runs. ``test/test_kinematics_node_messages.py`` checks the
bytes against ``rosbags`` and ``rclpy``.

The module imports neither ``rclpy`` nor ``rosidl_parser``: it reads the
message classes it is given.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
import struct
from typing import Any

from ..units import NS_PER_S

__all__ = ['MAX_SLOTS', 'MessageTemplate', 'STAMP_MARKER', 'cdr_from_message', 'marker',
           'padding_from_message', 'stamp_from_cdr']

#: Encapsulation header of plain CDR, little-endian (CDR_LE).
ENCAPSULATION = b'\x00\x01\x00\x00'

#: Header stamp (sec, nanosec) that marks where the stamp is serialized.
STAMP_MARKER = (0x5EC04D17, 0x2C5A7E31)

_MARKER_BASE = 0x7FE5A5C35A000000   # a large finite float64; slot index in the low 24 bits
_MARKER_BITS = 24
#: How many float64 slots a template can have.
MAX_SLOTS = 1 << _MARKER_BITS

#: rosidl ``BasicType.typename`` -> struct format character (its size is its alignment).
_PRIMITIVES = {
    'boolean': '?', 'octet': 'B', 'char': 'B', 'int8': 'b', 'uint8': 'B',
    'int16': 'h', 'uint16': 'H', 'short': 'h', 'unsigned short': 'H',
    'int32': 'i', 'uint32': 'I', 'long': 'i', 'unsigned long': 'I',
    'int64': 'q', 'uint64': 'Q', 'long long': 'q', 'unsigned long long': 'Q',
    'float': 'f', 'double': 'd',
}
_UINT32 = struct.Struct('<I')
#: ``builtin_interfaces/Time`` (int32 sec, uint32 nanosec) in each byte order.
_STAMP = {True: struct.Struct('<iI'), False: struct.Struct('>iI')}


def stamp_from_cdr(data: bytes | bytearray | memoryview) -> int:
    """Return ``header.stamp`` in ns from the CDR bytes of a message whose first field is a Header.

    The stamp sits right after the 4-byte encapsulation header, whose second
    byte's low bit says the byte order; nothing else is decoded, so recorders,
    plots and benchmarks read stamps at the cost of one ``struct`` call.
    """
    sec, nanosec = _STAMP[bool(data[1] & 1)].unpack_from(data, 4)
    return int(sec) * NS_PER_S + int(nanosec)


def marker(index: int) -> float:
    """Return the float64 that marks slot ``index`` (0 <= index < MAX_SLOTS)."""
    if not 0 <= index < MAX_SLOTS:
        msg = f'Expected a slot index in [0, {MAX_SLOTS}), got {index}'
        raise ValueError(msg)
    value: float = struct.unpack('<d', struct.pack('<Q', _MARKER_BASE + index))[0]
    return value


class _Writer:
    """Append CDR to ``buffer``; alignment counts from the end of the encapsulation header."""

    def __init__(self) -> None:
        self.buffer = bytearray(ENCAPSULATION)
        self.padding: list[range] = []

    def align(self, size: int) -> None:
        pad = -(len(self.buffer) - len(ENCAPSULATION)) % size
        if pad:
            start = len(self.buffer)
            self.buffer += bytes(pad)
            self.padding.append(range(start, start + pad))

    def primitives(self, typename: str, values: Sequence[Any], where: str) -> None:
        """Write ``values`` of one primitive type, aligned to its size (nothing if empty)."""
        if not values:
            return
        code = _PRIMITIVES.get(typename)
        if code is None:
            msg = (f'Expected a field type with a CDR encoding here, got {typename!r} '
                   f'for {where}')
            raise ValueError(msg)
        if typename in ('octet', 'char'):
            # octet is bytes of length 1 in Python, IDL char a str of length 1.
            values = [v[0] if isinstance(v, bytes | bytearray) else
                      ord(v) if isinstance(v, str) else v for v in values]
        fmt = struct.Struct(f'<{len(values)}{code}')
        self.align(struct.calcsize(code))
        self.buffer += fmt.pack(*values)

    def string(self, value: str) -> None:
        data = value.encode()
        self.align(4)
        self.buffer += _UINT32.pack(len(data) + 1)
        self.buffer += data
        self.buffer.append(0)

    def message(self, msg: Any) -> None:
        cls = type(msg)
        fields = cls.get_fields_and_field_types()
        if not fields:
            # An empty structure has one uint8 member (rosidl's
            # structure_needs_at_least_one_member).
            self.buffer.append(0)
            return
        for name, slot_type in zip(fields, cls.SLOT_TYPES, strict=True):
            self.field(slot_type, getattr(msg, name), f'field {name!r} of {cls.__name__}')

    def field(self, slot_type: Any, value: Any, where: str) -> None:
        kind = type(slot_type).__name__
        if kind in ('UnboundedSequence', 'BoundedSequence'):
            self.align(4)
            self.buffer += _UINT32.pack(len(value))
            self.items(slot_type.value_type, value, where)
        elif kind == 'Array':
            self.items(slot_type.value_type, value, where)
        else:
            self.items(slot_type, (value,), where)

    def items(self, value_type: Any, values: Iterable[Any], where: str) -> None:
        """Write the elements of a sequence or array, or one value in a 1-tuple."""
        kind = type(value_type).__name__
        if kind == 'BasicType':
            self.primitives(value_type.typename, list(values), where)
        elif kind in ('UnboundedString', 'BoundedString'):
            for value in values:
                self.string(value)
        elif kind == 'NamespacedType':
            for value in values:
                self.message(value)
        else:
            # wstring (and anything newer): its encoding cannot be checked against
            # rclpy with the message packages installed here, so it is refused.
            msg = f'Expected a field type with a CDR encoding here, got {kind} for {where}'
            raise ValueError(msg)


def cdr_from_message(msg: Any) -> bytes:
    """Return the canonical CDR bytes of a ROS message (XCDR1, little-endian).

    Parameters
    ----------
    msg : ROS message
        An instance of a ``rosidl`` generated Python message class.

    Returns
    -------
    bytes
        Encapsulation header ``00 01 00 00`` and the message, with zero bytes
        as alignment padding (each primitive aligned to its size, counted
        from the end of the header) and nothing after the last member.

    Raises
    ------
    ValueError
        If the message has a field with no encoding here (``wstring``,
        ``wchar``, ``long double``).
    """
    writer = _Writer()
    writer.message(msg)
    return bytes(writer.buffer)


def padding_from_message(msg: Any) -> tuple[range, ...]:
    """Return where :func:`cdr_from_message` put alignment padding, as ranges of byte offsets."""
    writer = _Writer()
    writer.message(msg)
    return tuple(writer.padding)


def _slot_offsets(data: bytes, n_slots: int) -> list[int]:
    """Return the offset of every slot marker ``marker(0..n_slots-1)``, in one pass.

    The markers share their five high bytes (little-endian: the last five,
    which no UTF-8 text holds), so one scan finds every slot whatever their
    number: a scene of 10,000 dyads builds its templates in milliseconds.
    """
    low = _MARKER_BITS // 8
    suffix = struct.pack('<Q', _MARKER_BASE)[low:]
    found: dict[int, int] = {}
    at = data.find(suffix, low)
    while at >= 0:
        index = int.from_bytes(data[at - low:at], 'little')
        if index in found:
            msg = f'Expected slot {index} exactly once in the serialized message'
            raise ValueError(msg)
        found[index] = at - low
        at = data.find(suffix, at + len(suffix))
    missing = [i for i in range(n_slots) if i not in found]
    if missing or len(found) != n_slots:
        listed = ', '.join(f'slot {i}' for i in missing[:5])
        msg = (f'Expected {n_slots} slot markers exactly once in the serialized message, got '
               f'{len(found)}; missing {listed}')
        raise ValueError(msg)
    return [found[i] for i in range(n_slots)]


#: Templates with at most this many slots render through a function written for them.
INLINE_SLOTS = 4096


def _render_function(pack: Callable[..., bytes],
                     arguments: Sequence[Any]) -> Callable[[int, int, Sequence[float], int],
                                                           bytes]:
    """Return ``render(sec, nanosec, values, first)`` calling ``pack`` with ``arguments``.

    ``arguments`` lists the packed fields in order: a bytes constant, ``'sec'``,
    ``'nanosec'``, or the index of a slot (``values[first + index]``). Up to
    :data:`INLINE_SLOTS` slots the function is written out for this template
    (one call, no loop); beyond, a loop fills a copy of the argument list.
    """
    slots = [a for a in arguments if isinstance(a, int)]
    if len(slots) <= INLINE_SLOTS:
        namespace: dict[str, Any] = {'_pack': pack}
        parts = []
        for k, a in enumerate(arguments):
            if isinstance(a, bytes):
                namespace[f'_c{k}'] = a
                parts.append(f'_c{k}')
            elif isinstance(a, str):
                parts.append(a)
            else:
                parts.append(f'values[first + {a}]')
        source = (f'def render(sec, nanosec, values, first=0):\n'
                  f'    return _pack({", ".join(parts)})\n')
        exec(compile(source, '<message template>', 'exec'), namespace)  # noqa: S102
        rendered: Callable[[int, int, Sequence[float], int], bytes] = namespace['render']
        return rendered
    positions = [(k, a) for k, a in enumerate(arguments) if isinstance(a, int)]
    sec_at = [k for k, a in enumerate(arguments) if a == 'sec']
    nanosec_at = [k for k, a in enumerate(arguments) if a == 'nanosec']

    def render(sec: int, nanosec: int, values: Sequence[float], first: int = 0) -> bytes:
        args = list(arguments)
        for k in sec_at:
            args[k] = sec
        for k in nanosec_at:
            args[k] = nanosec
        for k, index in positions:
            args[k] = values[first + index]
        return pack(*args)

    return render


def _find_all(data: bytes, pattern: bytes, what: str) -> tuple[int, ...]:
    offsets = []
    offset = data.find(pattern)
    while offset >= 0:
        offsets.append(offset)
        offset = data.find(pattern, offset + len(pattern))
    if not offsets:
        msg = f'Expected {what} in the serialized message, got none'
        raise ValueError(msg)
    return tuple(offsets)


class MessageTemplate:
    """A serialized message with its header stamp and ``n_slots`` float64 fields patchable.

    Parameters
    ----------
    msg : ROS message
        A message with every header stamp set to :data:`STAMP_MARKER` and the
        fields to patch set to ``marker(0)``, ``marker(1)``, ...,
        ``marker(n_slots - 1)``; every other field holds its final value.
    n_slots : int
        Number of float64 slots.
    where : sequence of int, optional
        For each slot, the index of its value in the ``values`` of a render
        (before ``first`` is added); by default slot ``i`` takes index ``i``. A
        message whose values are not one run of a tick's values (a
        ``JointState`` with positions, velocities and the efforts kept after
        the frames) reads them where they are, without a copy.

    Raises
    ------
    ValueError
        If a marker is not found exactly once in the serialized bytes.
    """

    def __init__(self, msg: Any, n_slots: int, where: Sequence[int] | None = None) -> None:
        if where is not None and len(where) != n_slots:
            text = f'Expected one index per slot ({n_slots}), got {len(where)}'
            raise ValueError(text)
        data = cdr_from_message(msg)
        self._stamp = struct.Struct('<iI')
        # One stamp, or several (a TFMessage has one per transform), all patched alike.
        stamp = self._stamp.pack(*STAMP_MARKER)
        self._stamp_offsets = _find_all(data, stamp, 'the header stamp marker')
        offsets = _slot_offsets(data, n_slots)
        buffer = bytearray(data)
        for offset in offsets:
            buffer[offset:offset + 8] = bytes(8)
        self.n_slots = n_slots
        # The whole message as one struct: its fixed bytes as constant byte-string
        # fields, the stamps and the slots as the fields that change. One pack
        # makes the message's bytes; the fields of a render are laid out in
        # offset order by _render_function.
        fields: list[tuple[int, str, int]] = sorted(
            [(offset, 'stamp', 0) for offset in self._stamp_offsets]
            + [(offset, 'slot', i) for i, offset in enumerate(offsets)])
        fmt = '<'
        self._arguments: list[Any] = []       # a constant, 'sec', 'nanosec' or a slot index
        at = 0
        for offset, kind, index in fields:
            if offset > at:
                fmt += f'{offset - at}s'
                self._arguments.append(bytes(buffer[at:offset]))
            if kind == 'stamp':
                fmt += 'iI'
                self._arguments += ['sec', 'nanosec']
            else:
                fmt += 'd'
                self._arguments.append(index if where is None else int(where[index]))
            at = offset + 8
        if at < len(buffer):
            fmt += f'{len(buffer) - at}s'
            self._arguments.append(bytes(buffer[at:]))
        self._struct = struct.Struct(fmt)
        self._render = _render_function(self._struct.pack, self._arguments)

    def render(self, sec: int, nanosec: int, values: Sequence[float], first: int = 0) -> bytes:
        """Return the serialized message with this stamp and slot values.

        Slot ``i`` takes ``values[first + i]`` (``values[first + where[i]]`` given ``where``).
        """
        return self._render(sec, nanosec, values, first)
