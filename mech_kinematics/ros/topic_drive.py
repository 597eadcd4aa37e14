# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node driven from a topic: one input ``JointState`` in, what to solve or why not out.

With ``drive: topic`` the node subscribes to ``input_joint_states`` and
publishes, for each message, the mechanism's state stamped with that
message's stamp (see docs/node.md, "Driven from a topic"). This module holds
the per-message rules, without ROS: :meth:`TopicDrive.read` takes the
message's fields (stamp, names, positions, velocities) and returns a
:class:`TopicInput` (each driver's position and, when the message has them,
velocity, in the scene's driver order) or raises :class:`RefusedInput` with
the one-line reason the node puts on ``diagnostics``.

A message is refused, and nothing is published for it, when:

- a name is not a driver of the scene, is given twice, or a driver is missing;
- ``position`` is not one value per name, or a position is NaN or infinite;
- ``velocity`` is neither empty nor one value per name, or holds NaN or inf;
- an actuator's length is outside its stroke (inclusive limits);
- its stamp is zero, or not after the stamp of the last state published
  (an equal stamp too: two states at one instant would contradict each
  other, and tf2 drops the second as repeated data).

What the message does not determine is never guessed: the velocities are
known only when the message has one for every driver, the accelerations
never. A position where the mechanism cannot assemble is the solver's to
refuse (the node reports it like a refused message).

Thread use: one thread (the executor's, which runs the subscription) calls
:meth:`TopicDrive.read` and :meth:`TopicDrive.published`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
import math
from typing import Any, NoReturn

from .topics import INPUT_JOINT_STATES
from ..units import NS_PER_S

__all__ = ['RefusedInput', 'TopicDrive', 'TopicInput']

#: How many names a reason lists before it says how many more there are.
SHOWN_NAMES = 5


class RefusedInput(ValueError):
    """An input message that is not published, with ``reason`` (one line)."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


@dataclass(frozen=True)
class TopicInput:
    """What one accepted input message gives the solver.

    Attributes
    ----------
    stamp_ns : int
        The message's ``header.stamp``, ns: the stamp of every published message.
    positions : tuple of float
        Each driver's position in scene order: rad (a crank), m (an actuator).
    speeds : tuple of float or None
        Each driver's velocity in scene order (rad/s, m/s); None when the
        message has none: the published velocities are then left out.
    """

    stamp_ns: int
    positions: tuple[float, ...]
    speeds: tuple[float, ...] | None


def _listed(names: Sequence[str]) -> str:
    shown = ', '.join(repr(n) for n in names[:SHOWN_NAMES])
    more = len(names) - SHOWN_NAMES
    return f'{shown} and {more} more' if more > 0 else shown


def _seconds(stamp_ns: int) -> str:
    sec, nanosec = divmod(stamp_ns, NS_PER_S)
    return f'{sec}.{nanosec:09d} s'


class TopicDrive:
    """The rules of ``drive: topic`` for one scene's drivers, and the last stamp published.

    Parameters
    ----------
    drivers : sequence
        The scene's drivers (``Scene.drivers``), each with ``name`` and
        ``stroke`` (inclusive limits in m, or None).
    """

    def __init__(self, drivers: Sequence[Any]) -> None:
        self.names = tuple(d.name for d in drivers)
        self._index = {name: i for i, name in enumerate(self.names)}
        self._strokes = tuple(d.stroke for d in drivers)
        self.last_stamp_ns: int | None = None

    def read(self, sec: int, nanosec: int, names: Sequence[str], positions: Sequence[float],
             velocities: Sequence[float]) -> TopicInput:
        """Return what the message with these fields gives the solver.

        Parameters
        ----------
        sec, nanosec : int
            The message's ``header.stamp``.
        names : sequence of str
            ``name``: the joints the message is about.
        positions, velocities : sequence of float
            ``position`` and ``velocity``, in the order of ``names``
            (``velocities`` may be empty).

        Raises
        ------
        RefusedInput
            If the message is refused (see the module's docstring), with the reason.
        """
        stamp_ns = sec * NS_PER_S + nanosec
        self._check_stamp(stamp_ns)
        order = self._order(names)
        if len(positions) != len(names):
            self._refuse(f'expected one position per name ({len(names)}), got '
                         f'{len(positions)}')
        ordered = tuple(float(positions[i]) for i in order)
        self._check_finite('position', ordered)
        for name, position, stroke in zip(self.names, ordered, self._strokes, strict=True):
            if stroke is not None and not stroke[0] <= position <= stroke[1]:
                self._refuse(f'expected {name!r} within its stroke [{stroke[0]:g}, '
                             f'{stroke[1]:g}] m, got {position!r} m')
        if not len(velocities):
            return TopicInput(stamp_ns, ordered, None)
        if len(velocities) != len(names):
            self._refuse(f'expected no velocity or one per name ({len(names)}), got '
                         f'{len(velocities)}')
        speeds = tuple(float(velocities[i]) for i in order)
        self._check_finite('velocity', speeds)
        return TopicInput(stamp_ns, ordered, speeds)

    def published(self, stamp_ns: int) -> None:
        """Note that the state at ``stamp_ns`` was published: later stamps must be after it."""
        self.last_stamp_ns = stamp_ns

    def _check_stamp(self, stamp_ns: int) -> None:
        if stamp_ns <= 0:
            self._refuse('expected header.stamp set to the instant of the positions, got '
                         f'{_seconds(stamp_ns)}')
        last = self.last_stamp_ns
        if last is not None and stamp_ns <= last:
            when = 'the same stamp again' if stamp_ns == last else \
                f'{_seconds(stamp_ns)}, {last - stamp_ns} ns earlier'
            self._refuse(f'expected a stamp after the last published one ({_seconds(last)}), '
                         f'got {when}')

    def _order(self, names: Sequence[str]) -> list[int]:
        """Return, for each driver in scene order, the index of its entry in ``names``."""
        where: dict[str, int] = {}
        for i, name in enumerate(names):
            if name in where:
                self._refuse(f'expected each joint named once, got {name!r} twice')
            where[name] = i
        unknown = [n for n in names if n not in self._index]
        if unknown:
            self._refuse(f'expected only the drivers ({_listed(self.names)}), got unknown '
                         f'joint(s) {_listed(unknown)}')
        missing = [n for n in self.names if n not in where]
        if missing:
            self._refuse(f'expected every driver ({_listed(self.names)}), got none for '
                         f'{_listed(missing)}')
        return [where[n] for n in self.names]

    def _check_finite(self, what: str, values: Sequence[float]) -> None:
        for name, value in zip(self.names, values, strict=True):
            if not math.isfinite(value):
                self._refuse(f'expected a finite {what} of {name!r}, got {value!r}')

    @staticmethod
    def _refuse(reason: str) -> NoReturn:
        raise RefusedInput(f'{INPUT_JOINT_STATES}: {reason}')
