# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's clock as a pure driver: which instants to publish, and each driver's state there.

:class:`TickDriver` holds everything about time that the node used to hold in
its tick loop: the time source (system or simulated time), clock jumps, the
exact grid of :mod:`~mech_kinematics.ros.schedule`, the drive changes waiting
for the next unpublished instant, and one exact time base
(:mod:`~mech_kinematics.ros.timebase`) per driver. It imports no ROS: the node
reads its clock, calls :meth:`TickDriver.step` with the time it read, and
publishes the instants it gets back, taking each driver's state at each of them
from :meth:`TickDriver.state_at`.

Each driver is named and keeps its own time base and start values, so a scene
with several drivers gets one entry per driver. A driver's time base is a
class given with it (:class:`~mech_kinematics.ros.timebase.CrankTimebase` for
a crank, the default): anything built as ``kind(t0, **start)`` with
``update(t, **changes)``, ``moved(t_from, t_to)`` and ``sample_turns(t)``
(whole turns, or 0 for a driver that does not turn, and its state) will do.

Thread use: the tick thread calls :meth:`~TickDriver.step` and
:meth:`~TickDriver.state_at`; any thread may call :meth:`~TickDriver.request`
(guarded by a lock). :meth:`~TickDriver.apply_now` is for when nothing ticks.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import threading
from typing import Any, NamedTuple, Protocol

from .schedule import TickGrid
from .timebase import CrankTimebase

__all__ = ['Drive', 'TickDriver', 'Timebase', 'Wake']

#: A change of the system clock against the monotonic clock beyond this is a jump, ns.
CLOCK_JUMP_NS = 10_000_000


class Wake(NamedTuple):
    """What one :meth:`TickDriver.step` found."""

    instants: range
    """Grid instants to publish now, in order, ns (empty when none is due)."""
    skipped: int = 0
    """Grid instants dropped (older than the catch-up bound, or all but one in skip mode)."""
    jump_ns: int | None = None
    """The clock jumped by this much, ns (its grid starts again); None: no jump."""
    wait_ns: int = 0
    """Time until the next instant is due (system time only), ns; 0: now or unknown."""
    waiting_for_clock: bool = False
    """Simulated time has not started (no ``/clock`` yet): nothing can be published."""


class Timebase(Protocol):
    """What the driver asks of a driver's time base (``CrankTimebase`` is one)."""

    #: The keyword arguments ``update`` takes.
    CHANGES: tuple[str, ...]
    #: The keywords that each give its speed (in their own units): one given replaces another.
    RATES: tuple[str, ...]
    #: The keyword of its position at the start (``angle``, ``length``): the time base's own,
    #: whatever its driver's scene key.
    POSITION: str

    def update(self, t: int, **changes: Any) -> None:
        """From instant ``t`` (ns) on, drive with ``changes``, keeping the position there."""

    def moved(self, t_from: int, t_to: int) -> Timebase:
        """Return a copy whose drive at ``t_to`` continues this one's at ``t_from``."""

    def sample_turns(self, t: int) -> tuple[int, Any]:
        """Return (whole turns, the driver's state) at ``t`` ns."""


@dataclass
class Drive:
    """One driver: its start values, then its exact time base from its first published instant.

    ``start`` holds the keyword arguments of ``CrankTimebase`` other than
    ``t0``: ``angle`` (rad), ``speed_rpm`` (rpm) or ``speed`` (rad/s),
    ``accel`` (rad/s^2) and ``max_speed_rpm`` (rpm).
    """

    name: str
    start: dict[str, Any]
    kind: Any = CrankTimebase
    timebase: Timebase | None = None
    pending: dict[str, float] = field(default_factory=dict)

    def fold(self) -> None:
        """Take the pending changes into the start values (no instant published yet)."""
        changes, self.pending = self.pending, {}
        rates = self.kind.RATES
        if any(key in changes for key in rates):
            self.start.update((key, None) for key in rates if key in self.start)
        self.start.update(changes)

    def apply(self, at_ns: int) -> None:
        """Apply the pending changes from instant ``at_ns`` on."""
        changes, self.pending = self.pending, {}
        if changes and self.timebase is not None:
            self.timebase.update(at_ns, **changes)


class TickDriver:
    """The instants to publish on the node's clock, and each driver's state there.

    Parameters
    ----------
    period_ns : int
        Spacing of the instants, ns.
    max_behind_ns : int
        Catch-up bound: owed instants older than this before now are skipped.
    catch_up : bool
        ``False``: a late wake-up publishes only the latest owed instant.
    """

    def __init__(self, period_ns: int, max_behind_ns: int, catch_up: bool = True) -> None:
        self.period_ns = period_ns
        self.max_behind_ns = max_behind_ns
        self.catch_up = catch_up
        self.drives: dict[str, Drive] = {}
        self.grid: TickGrid | None = None
        self.last_stamp: int | None = None
        self.sim: bool | None = None
        self._offset = 0            # system clock minus monotonic clock, ns
        self._known = (0, 0)        # ... known to lie in this range (its reading's bracket), ns
        self._rebase_from: int | None = None
        self._lock = threading.Lock()

    # -- drivers --------------------------------------------------------------

    def add_drive(self, name: str, kind: Any = CrankTimebase, **start: Any) -> None:
        """Add driver ``name``: its time base ``kind`` and its start values (kept if it is there).

        The time base is built at the driver's first published instant ``t0``
        as ``kind(t0, **start)``.
        """
        start = {**dict.fromkeys(kind.RATES), **start}
        with self._lock:
            if name not in self.drives:
                self.drives[name] = Drive(name, start, kind)

    def request(self, name: str, **changes: float) -> None:
        """Drive ``name`` with ``changes`` from the next instant not published (any thread)."""
        drive = self.drives[name]
        unknown = set(changes) - set(drive.kind.CHANGES)
        if unknown:
            msg = (f'Expected drive changes among {", ".join(drive.kind.CHANGES)}, '
                   f'got {sorted(unknown)}')
            raise ValueError(msg)
        rates = drive.kind.RATES
        with self._lock:
            if any(key in changes for key in rates):
                for key in rates:
                    drive.pending.pop(key, None)
            drive.pending.update(changes)

    def apply_now(self, now_ns: int) -> None:
        """Apply the pending changes at ``now_ns`` (after the last published instant)."""
        at_ns = now_ns if self.last_stamp is None else max(now_ns, self.last_stamp + 1)
        with self._lock:
            for drive in self.drives.values():
                if drive.timebase is None:
                    drive.fold()
                else:
                    drive.apply(at_ns)

    # -- the clock ------------------------------------------------------------

    def resume(self) -> None:
        """Start a new grid at the next step: the instants while nothing ticked are not owed."""
        self.grid = None

    def step(self, now_ns: int, sim: bool = False, monotonic_ns: int | None = None,
             monotonic_after_ns: int | None = None) -> Wake:
        """Return the instants owed at ``now_ns`` and mark them taken.

        Parameters
        ----------
        now_ns : int
            The node's clock now, ns.
        sim : bool
            Whether the clock is simulated time (``use_sim_time`` with a
            ``/clock``). A change of time source starts a new grid, and the
            drivers go on from where they were at the next instant.
        monotonic_ns : int, optional
            A monotonic clock read just before ``now_ns`` (system time): a
            change of ``now_ns - monotonic_ns`` beyond ``CLOCK_JUMP_NS`` is a jump.
        monotonic_after_ns : int, optional
            The monotonic clock read again just after ``now_ns`` (default:
            ``monotonic_ns``). A thread descheduled between its reads (a
            loaded machine, another thread holding the GIL) cannot tell when
            in the bracket it read the system clock: the offset is then only
            known to within ``monotonic_after_ns - monotonic_ns``, and only a
            change beyond ``CLOCK_JUMP_NS`` plus the brackets of both readings
            is a jump.
        """
        if sim != self.sim:
            if self.sim is not None and self.last_stamp is not None:
                # The new time source's epoch means nothing to the old one.
                self._rebase_from = self.last_stamp
            self.sim = sim
            self.grid = None
        if sim:
            return self._step_sim(now_ns)
        before = now_ns if monotonic_ns is None else monotonic_ns
        return self._step_system(now_ns, before,
                                 before if monotonic_after_ns is None else monotonic_after_ns)

    def _step_sim(self, now_ns: int) -> Wake:
        if now_ns <= 0:
            return Wake(range(0), waiting_for_clock=True)
        grid, jump = self.grid, None
        if grid is not None and now_ns < grid.next_ns - grid.period_ns:
            jump = now_ns - (grid.next_ns - grid.period_ns)     # the simulated clock went back
            grid = None
        if grid is None:
            grid = self.grid = TickGrid.aligned(now_ns, self.period_ns)
        grid.set_period(self.period_ns)
        due = grid.take(now_ns, self.max_behind_ns, self.catch_up)
        return Wake(due.instants, due.skipped, jump)

    def _step_system(self, now_ns: int, before_ns: int, after_ns: int) -> Wake:
        # The offset (system minus monotonic) is somewhere in [now - after, now - before]:
        # a jump is a change beyond the bound that the brackets of the readings cannot explain.
        low, high = now_ns - max(after_ns, before_ns), now_ns - before_ns
        grid, jump = self.grid, None
        known_low, known_high = self._known
        if grid is None or max(low - known_high, known_low - high) > CLOCK_JUMP_NS:
            if grid is not None:
                jump = (low + high) // 2 - self._offset
            self._known = low, high
            grid = self.grid = TickGrid.aligned(now_ns, self.period_ns)
        elif high - low < known_high - known_low:
            self._known = low, high         # a sharper reading of the same offset
        self._offset = sum(self._known) // 2
        grid.set_period(self.period_ns)
        remaining = grid.next_ns - now_ns
        if remaining > 0:
            return Wake(range(0), 0, jump, remaining)
        due = grid.take(now_ns, self.max_behind_ns, self.catch_up)
        return Wake(due.instants, due.skipped, jump)

    def woke_ns(self, monotonic_ns: int) -> int:
        """Return a monotonic reading as system time (for the lateness of system-time ticks)."""
        return monotonic_ns + self._offset

    # -- the drivers at an instant -------------------------------------------

    def state_at(self, stamp: int) -> list[tuple[int, Any]]:
        """Return each driver's (whole turns, state) at ``stamp`` and mark ``stamp`` published.

        Call it for the instants :meth:`step` returned, in order: the pending
        changes apply from the first of them, a new time source takes over
        there, and a driver's time base starts at its first.
        """
        with self._lock:
            for drive in self.drives.values():
                if drive.timebase is None:
                    drive.fold()
                    drive.timebase = drive.kind(stamp, **drive.start)
                if self._rebase_from is not None:
                    drive.timebase = drive.timebase.moved(self._rebase_from, stamp)
                if drive.pending:
                    drive.apply(stamp)
            self._rebase_from = None
            self.last_stamp = stamp
            return [drive.timebase.sample_turns(stamp)  # type: ignore[union-attr]
                    for drive in self.drives.values()]
