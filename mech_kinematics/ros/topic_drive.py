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

- a name is given twice, or a driver is missing;
- a name is not a driver of the scene, with ``extra_joints: refuse`` (the
  default; ``ignore`` drops such joints, ``pass`` passes them through);
- ``position`` is not one value per name, or a driver's position is NaN or
  infinite;
- ``velocity`` is neither empty nor one value per name, or a driver's holds
  NaN or inf; with ``extra_joints: pass``, ``effort`` likewise (neither empty
  nor one per name);
- an actuator's length is outside its stroke (inclusive limits);
- its stamp is zero, or not after the stamp of the last state published
  (an equal stamp too: two states at one instant would contradict each
  other, and tf2 drops the second as repeated data), unless it is earlier by
  more than ``jump_back_ns``.

A stamp earlier than the last published one by more than ``jump_back_ns``
is a jump of the sender's clock back (as tf2_ros clears its buffer when time
jumps back): the message is read, and once published its stamp is the new
bound, so that one message stamped far in the future (a bad clock) does not
end the stream. The :class:`TopicInput` says the stamp it jumped from
(:attr:`TopicInput.jumped_from_ns`), for the node to say on ``diagnostics``.

With ``extra_joints: pass`` the joints of the message that are not drivers
are published after the mechanism's in ``joint_states``, unchanged
(:meth:`TopicDrive.joint_state_arrays`); a name the node publishes itself (a
passive joint of the mechanism) is not passed twice: it is ignored, and the
mechanism's value is published.

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

__all__ = ['DEFAULT_JUMP_BACK_S', 'EXTRA_JOINTS', 'IGNORE', 'PASS', 'PassedJoints', 'REFUSE',
           'RefusedInput', 'TopicDrive', 'TopicInput']

#: How many names a reason lists before it says how many more there are.
SHOWN_NAMES = 5
#: Sets of names whose checks are kept (a robot's motors send one; all dropped past it).
LAYOUTS = 16
#: ``extra_joints`` values: what a message's joints that are not drivers do.
REFUSE = 'refuse'
IGNORE = 'ignore'
PASS = 'pass'
EXTRA_JOINTS = (REFUSE, IGNORE, PASS)
#: Default of ``stamp_jump_back_s``: a stamp earlier than the last published one by more
#: than this is a jump of the sender's clock back, s.
DEFAULT_JUMP_BACK_S = 1.0


class RefusedInput(ValueError):
    """An input message that is not published, with ``reason`` (one line)."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


@dataclass(frozen=True)
class PassedJoints:
    """The joints of an input message passed through to ``joint_states``, unchanged.

    Attributes
    ----------
    names : tuple of str
        Their names, in the message's order.
    positions : tuple of float
        Their ``position`` entries.
    velocities, efforts : tuple of float or None
        Their ``velocity`` and ``effort`` entries; None when the message has none.
    """

    names: tuple[str, ...]
    positions: tuple[float, ...]
    velocities: tuple[float, ...] | None
    efforts: tuple[float, ...] | None


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
    accels : tuple of float or None
        With ``drive: trajectory``, each driver's acceleration in scene order
        (rad/s^2, m/s^2); None otherwise (the accelerations are left out).
    jumped_from_ns : int or None
        The last published stamp, ns, when this one is earlier than it by more
        than the bound (the sender's clock jumped back); else None.
    ignored : tuple of str
        The message's joints that are neither drivers nor passed, in its order.
    passed : PassedJoints or None
        With ``extra_joints: pass``, the joints passed through (None if none).
    """

    stamp_ns: int
    positions: tuple[float, ...]
    speeds: tuple[float, ...] | None
    jumped_from_ns: int | None = None
    ignored: tuple[str, ...] = ()
    passed: PassedJoints | None = None
    accels: tuple[float, ...] | None = None


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
    extra_joints : {'refuse', 'ignore', 'pass'}, keyword-only
        What a message's joints that are not drivers do: refuse the message,
        are dropped, or are passed through (:class:`PassedJoints`).
    jump_back_ns : int, keyword-only
        A stamp earlier than the last published one by more than this, ns,
        is a jump of the sender's clock back: read, not refused.
    published_joints : sequence of str, keyword-only
        The joints the node publishes itself: with ``pass``, a message's joint
        of these names is ignored rather than passed (published twice).
    topic : str, keyword-only
        The input's topic, which every refusal names first (default
        ``input_joint_states``; :class:`~.target_drive.TargetDrive` reads
        drivers it found from ``input_targets``).

    Raises
    ------
    ValueError
        If ``extra_joints`` is none of :data:`EXTRA_JOINTS` or ``jump_back_ns`` is negative.
    """

    def __init__(self, drivers: Sequence[Any], *, extra_joints: str = REFUSE,
                 jump_back_ns: int = round(DEFAULT_JUMP_BACK_S * NS_PER_S),
                 published_joints: Sequence[str] = (),
                 topic: str = INPUT_JOINT_STATES) -> None:
        if extra_joints not in EXTRA_JOINTS:
            msg = f'Expected extra_joints in {EXTRA_JOINTS}, got {extra_joints!r}'
            raise ValueError(msg)
        if jump_back_ns < 0:
            msg = f'Expected jump_back_ns >= 0, got {jump_back_ns}'
            raise ValueError(msg)
        self.topic = topic
        self.names = tuple(d.name for d in drivers)
        self._index = {name: i for i, name in enumerate(self.names)}
        self._strokes = tuple(d.stroke for d in drivers)
        self.extra_joints = extra_joints
        self.jump_back_ns = int(jump_back_ns)
        self.published_joints = tuple(published_joints)
        self._published = frozenset(self.published_joints)
        self.last_stamp_ns: int | None = None
        #: Per set of names accepted: (driver order, other joints, passed ones, ignored names).
        self._layouts: dict[tuple[str, ...], tuple[Any, ...]] = {}

    def read(self, sec: int, nanosec: int, names: Sequence[str], positions: Sequence[float],
             velocities: Sequence[float], efforts: Sequence[float] = ()) -> TopicInput:
        """Return what the message with these fields gives the solver.

        Parameters
        ----------
        sec, nanosec : int
            The message's ``header.stamp``.
        names : sequence of str
            ``name``: the joints the message is about.
        positions, velocities, efforts : sequence of float
            ``position``, ``velocity`` and ``effort``, in the order of
            ``names`` (``velocities`` and ``efforts`` may be empty;
            ``efforts`` is read with ``extra_joints: pass`` only).

        Raises
        ------
        RefusedInput
            If the message is refused (see the module's docstring), with the reason.
        """
        stamp_ns = sec * NS_PER_S + nanosec
        jumped_from = self._check_stamp(stamp_ns)
        key = tuple(names)
        layout = self._layouts.get(key)
        if layout is None:      # a new set of names: checked once, then looked up
            order, extras = self._order(names)
            if len(self._layouts) >= LAYOUTS:
                self._layouts.clear()
            layout = self._layouts[key] = (order, extras, *self._split(names, extras))
        order, extras = layout[0], layout[1]
        if len(positions) != len(names):
            self._refuse(f'expected one position per name ({len(names)}), got '
                         f'{len(positions)}')
        ordered = tuple(float(positions[i]) for i in order)
        self._check_finite('position', ordered)
        for name, position, stroke in zip(self.names, ordered, self._strokes, strict=True):
            if stroke is not None and not stroke[0] <= position <= stroke[1]:
                self._refuse(f'expected {name!r} within its stroke [{stroke[0]:g}, '
                             f'{stroke[1]:g}] m, got {position!r} m')
        speeds = None
        if len(velocities):
            if len(velocities) != len(names):
                self._refuse(f'expected no velocity or one per name ({len(names)}), got '
                             f'{len(velocities)}')
            speeds = tuple(float(velocities[i]) for i in order)
            self._check_finite('velocity', speeds)
        if not extras:
            return TopicInput(stamp_ns, ordered, speeds, jumped_from)
        passed, ignored = self._extras(names, layout[2], layout[3], positions, velocities,
                                       efforts)
        return TopicInput(stamp_ns, ordered, speeds, jumped_from, ignored, passed)

    def joint_state_arrays(self, given: TopicInput, values: Sequence[float]) -> tuple[
            list[str], list[float], list[float], list[float]]:
        """Return ``joint_states``' (name, position, velocity, effort) with the passed joints.

        Parameters
        ----------
        given : TopicInput
            What :meth:`read` returned for the message.
        values : sequence of float
            The tick function's values: the joints' positions, then their
            velocities (:func:`mech_kinematics.ros.ticker.values_from_state`).

        Returns
        -------
        tuple of list
            The mechanism's joints (``published_joints``), then the passed
            ones. ``velocity`` is empty when the message has none (then no
            velocity is known); ``effort`` is empty unless the message has one
            per name: then it is NaN (unknown) for each of the mechanism's
            joints, as ros2_control's joint_state_broadcaster marks a value a
            joint does not have, and the message's for the passed ones.
        """
        joints = self.published_joints
        n = len(joints)
        names, positions = list(joints), [float(v) for v in values[:n]]
        velocities = [] if given.speeds is None else [float(v) for v in values[n:2 * n]]
        efforts: list[float] = []
        passed = given.passed
        if passed is not None:
            names += passed.names
            positions += passed.positions
            if passed.velocities is not None and velocities:
                velocities += passed.velocities
            if passed.efforts is not None:
                efforts = [math.nan] * n + list(passed.efforts)
        return names, positions, velocities, efforts

    def published(self, stamp_ns: int) -> None:
        """Note that the state at ``stamp_ns`` was published: later stamps must be after it."""
        self.last_stamp_ns = stamp_ns

    def _check_stamp(self, stamp_ns: int) -> int | None:
        """Refuse a stamp out of order; return the last stamp if this one jumped back from it."""
        if stamp_ns <= 0:
            self._refuse('expected header.stamp set to the instant of the positions, got '
                         f'{_seconds(stamp_ns)}')
        last = self.last_stamp_ns
        if last is None or stamp_ns > last:
            return None
        if last - stamp_ns > self.jump_back_ns:
            return last
        when = 'the same stamp again' if stamp_ns == last else \
            f'{_seconds(stamp_ns)}, {last - stamp_ns} ns earlier'
        self._refuse(f'expected a stamp after the last published one ({_seconds(last)}), '
                     f'got {when} (earlier by more than stamp_jump_back_s, '
                     f'{self.jump_back_ns / NS_PER_S:g} s, resets the order)')

    def _order(self, names: Sequence[str]) -> tuple[list[int], list[int]]:
        """Return the index in ``names`` of each driver in scene order, and of the others."""
        where: dict[str, int] = {}
        for i, name in enumerate(names):
            if name in where:
                self._refuse(f'expected each joint named once, got {name!r} twice')
            where[name] = i
        extras = [i for i, n in enumerate(names) if n not in self._index]
        if extras and self.extra_joints == REFUSE:
            unknown = [names[i] for i in extras]
            self._refuse(f'expected only the drivers ({_listed(self.names)}), got unknown '
                         f'joint(s) {_listed(unknown)} (extra_joints:=ignore|pass takes the '
                         'drivers and drops or passes the others)')
        missing = [n for n in self.names if n not in where]
        if missing:
            self._refuse(f'expected every driver ({_listed(self.names)}), got none for '
                         f'{_listed(missing)}')
        return [where[n] for n in self.names], extras

    def _split(self, names: Sequence[str], extras: list[int]) -> tuple[
            tuple[int, ...], tuple[str, ...]]:
        """Return which of ``extras`` (indices into ``names``) pass, and the names ignored."""
        if self.extra_joints == IGNORE:
            return (), tuple(names[i] for i in extras)
        return (tuple(i for i in extras if names[i] not in self._published),
                tuple(names[i] for i in extras if names[i] in self._published))

    def _extras(self, names: Sequence[str], kept: tuple[int, ...], ignored: tuple[str, ...],
                positions: Sequence[float], velocities: Sequence[float],
                efforts: Sequence[float]) -> tuple[PassedJoints | None, tuple[str, ...]]:
        """Return the joints ``kept`` (indices into ``names``) passed, and those ignored."""
        if self.extra_joints == IGNORE:
            return None, ignored
        if len(efforts) and len(efforts) != len(names):
            self._refuse(f'expected no effort or one per name ({len(names)}), got '
                         f'{len(efforts)} (extra_joints: pass passes them through)')
        if not kept:
            return None, ignored
        return PassedJoints(
            tuple(names[i] for i in kept), tuple(float(positions[i]) for i in kept),
            tuple(float(velocities[i]) for i in kept) if len(velocities) else None,
            tuple(float(efforts[i]) for i in kept) if len(efforts) else None), ignored

    def _check_finite(self, what: str, values: Sequence[float]) -> None:
        for name, value in zip(self.names, values, strict=True):
            if not math.isfinite(value):
                self._refuse(f'expected a finite {what} of {name!r}, got {value!r}')

    def _refuse(self, reason: str) -> NoReturn:
        raise RefusedInput(f'{self.topic}: {reason}')
