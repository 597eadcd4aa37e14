# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's tick thread: it reads the clock, and publishes the state at every instant owed.

:class:`TickThread` runs the loop the node's ``drive: time`` publishes from.
It reads the clock (system time, or simulated time with ``use_sim_time`` and
a ``/clock``), asks the pure driver (:class:`~mech_kinematics.ros.driver.TickDriver`)
which grid instants are owed and each driver's state there, solves each
instant with the function that serves (:class:`~mech_kinematics.ros.solver_path.SolverPath`)
and publishes it (:class:`~mech_kinematics.ros.publishing.Publishing`),
counting everything in the diagnostics' :class:`~mech_kinematics.ros.diagnostics.TickStats`.
A tick that cannot be solved publishes nothing and says why (a warning, at
most one a second, and ``diagnostics``). A publish the middleware refuses
(``RCLError``: a reliable subscriber too slow for the rate filled the
writer's history, its shared memory is full) loses that instant's state,
not the node: it is counted (``publish_failures`` on ``diagnostics``, timing
WARN) and said (a warning, at most one a second), and the next instant is
published as usual.

Thread use: :meth:`TickThread.start` and :meth:`TickThread.stop` from the
executor's thread; the loop in its own daemon thread. A jump of the node's
clock (or a change of its time source) sets :attr:`TickThread.clock_event`
from rclpy's jump callback. An unexpected error in the loop stops the
thread, is logged with its traceback, and ``on_failure`` is called (the node
then ends its spin with :class:`TickThreadError`, exit status 1).

The clock is anything with ``now()`` and ``ros_time_is_active``; the tests
drive the loop with a stand-in clock, publisher and solver
(``test/ros/test_tick_thread.py``).
"""

from __future__ import annotations

from collections.abc import Callable
import ctypes
import threading
import time
import traceback
from typing import Any, TYPE_CHECKING

from .drive import position_text, transposed
from .publishing import RCLError
from ..errors import AssemblyError, UntrustedError
from ..solver.context import NEAR_SINGULAR
from ..units import NS_PER_S

if TYPE_CHECKING:
    from .diagnostics import TickStats
    from .driver import TickDriver
    from .publishing import Markers, Publishing
    from .solver_path import SolverPath
    from .timebase import CrankSample

__all__ = ['CLOCK_READ_NS', 'CLOCK_READ_TRIES', 'LATE_NS', 'MAX_SLEEP_NS', 'TickThread',
           'TickThreadError', 'read_system_clock', 'set_timer_slack']

#: An instant published more than min(period / 2, LATE_NS) after it is counted late.
LATE_NS = 1_000_000
#: Longest single sleep of the tick thread, so that a stop is seen quickly.
MAX_SLEEP_NS = 50_000_000
#: A bracket of monotonic reads around the system clock's wider than this was interrupted.
CLOCK_READ_NS = 200_000
#: Tries of :func:`read_system_clock` for a bracket no wider than ``CLOCK_READ_NS``.
CLOCK_READ_TRIES = 3


class TickThreadError(RuntimeError):
    """The tick thread stopped on an unexpected error (logged where it happened)."""


def set_timer_slack(ns: int) -> None:
    """Ask Linux for a tight wake-up of this thread (the default slack is 50 us)."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(29, ctypes.c_ulong(ns), 0, 0, 0)   # PR_SET_TIMERSLACK
    except (OSError, AttributeError):
        pass  # no prctl here: keep the default timer slack


def read_system_clock(time_ns: Callable[[], int],
                      monotonic_ns: Callable[[], int]) -> tuple[int, int, int]:
    """Return (system time, monotonic before, monotonic after), ns: the narrowest bracket.

    A thread descheduled between its clock reads (a loaded machine, or
    another thread holding the GIL for its switch interval, 5 ms) would see
    the system clock move against the monotonic one by the time it was away.
    The system clock is read between two monotonic reads, again up to
    ``CLOCK_READ_TRIES`` times while the bracket is wider than
    ``CLOCK_READ_NS``; the driver judges a jump against the bracket it gets.
    """
    best: tuple[int, int, int] | None = None
    for _ in range(CLOCK_READ_TRIES):
        before = monotonic_ns()
        now = time_ns()
        after = monotonic_ns()
        if best is None or after - before < best[2] - best[1]:
            best = now, before, after
        if after - before <= CLOCK_READ_NS:
            break
    assert best is not None
    return best


class TickThread:
    """The thread that publishes every owed grid instant of the node's clock.

    Parameters
    ----------
    clock : rclpy.clock.Clock
        The node's clock.
    driver : TickDriver
        The instants and the drivers' states.
    stats : TickStats
        The diagnostics' counters.
    logger : rclpy logger
        Where warnings and the failure go.
    on_failure : callable
        Called from the thread when it failed (after logging).
    shutting_down : callable
        ``shutting_down()``: whether the node's context is going away (an
        error then is no failure).

    Attributes
    ----------
    clock_event : threading.Event
        Set on a jump of the clock; the loop asks the time source then.
    waiting_for_clock : bool
        Simulated time is on and no ``/clock`` has come yet.
    failed : bool
        The loop stopped on an unexpected error.
    """

    def __init__(self, clock: Any, driver: TickDriver, stats: TickStats, logger: Any,
                 on_failure: Callable[[], None], shutting_down: Callable[[], bool]) -> None:
        self.clock, self.driver, self.stats, self.logger = clock, driver, stats, logger
        self.on_failure = on_failure
        self.shutting_down = shutting_down
        self.clock_event = threading.Event()
        self.waiting_for_clock = False
        self.failed = False
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        # The clocks the loop reads (the tests' stand-ins replace them).
        self.time_ns: Callable[[], int] = time.time_ns
        self.monotonic_ns: Callable[[], int] = time.monotonic_ns
        # What start() hands over (none before: the loop runs only after it).
        self.solver: SolverPath = None  # type: ignore[assignment]
        self.publishing: Publishing = None  # type: ignore[assignment]
        self.markers: Markers | None = None

    @property
    def running(self) -> bool:
        """Whether the thread is started (and not stopped)."""
        return self._thread is not None

    def start(self, solver: SolverPath, publishing: Publishing, markers: Markers | None) -> None:
        """Start ticking: solve with ``solver``, publish with ``publishing`` (and ``markers``)."""
        self.solver, self.publishing, self.markers = solver, publishing, markers
        self._stop.clear()
        self.driver.resume()
        self._thread = threading.Thread(target=self._run, name='mech_kinematics_tick',
                                        daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop the thread and wait for it (up to 2 s)."""
        self._stop.set()
        self.clock_event.set()
        thread, self._thread = self._thread, None
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=2.0)

    def _run(self) -> None:
        set_timer_slack(1000)
        try:
            self._loop()
        except Exception:
            if self._stop.is_set() or self.shutting_down():
                return      # shutting down: the context went away under a publish
            # A node that no longer ticks must not look alive: stop the process.
            self.failed = True
            self.logger.fatal(f'tick thread failed:\n{traceback.format_exc()}')
            self.on_failure()

    def _loop(self) -> None:
        clock, driver = self.clock, self.driver
        stop, stats = self._stop, self.stats
        monotonic_ns, time_ns, sleep = self.monotonic_ns, self.time_ns, time.sleep
        while not stop.is_set():
            # The time source can only change with a clock jump (on_clock_change): ask
            # the clock then, not every loop (the property takes the clock's lock).
            if driver.sim is None or self.clock_event.is_set():
                sim = clock.ros_time_is_active
                if not sim:
                    self.clock_event.clear()
            else:
                sim = driver.sim
            if sim:
                # Instants follow the simulated clock: wake on every /clock update.
                self.clock_event.wait(MAX_SLEEP_NS / NS_PER_S)
                self.clock_event.clear()
                if not clock.ros_time_is_active:
                    self.clock_event.set()     # switched off: the loop's top sees it
                    continue
                now = clock.now().nanoseconds
                if stop.is_set():
                    break
                wake = driver.step(now, sim=True)
                if wake.waiting_for_clock:
                    self._wait_for_clock()
                    continue
                self.waiting_for_clock = False
                if wake.jump_ns is not None:
                    stats.clock_jump()      # the simulated clock went back
                self.publish(wake.instants, wake.skipped, now)
                continue
            now, before, after = read_system_clock(time_ns, monotonic_ns)
            wake = driver.step(now, monotonic_ns=before, monotonic_after_ns=after)
            if wake.jump_ns is not None:
                stats.clock_jump()
                self.logger.warning(
                    f'the system clock jumped by {wake.jump_ns / NS_PER_S:+.3f} s: '
                    'the tick grid starts again', throttle_duration_sec=1.0)
            if wake.wait_ns > 0:
                sleep(min(wake.wait_ns, MAX_SLEEP_NS) / NS_PER_S)
                continue
            self.publish(wake.instants, wake.skipped, driver.woke_ns(monotonic_ns()))

    def _wait_for_clock(self) -> None:
        if not self.waiting_for_clock:
            self.waiting_for_clock = True
            self.logger.warning(
                'use_sim_time is true and no /clock has been received: nothing is published '
                'until one arrives')

    def publish(self, instants: range, skipped: int, woke: int) -> None:
        """Publish ``instants`` (``skipped`` were dropped; ``woke``: when this wake-up began)."""
        self.stats.skip(skipped)
        late_ns = min(self.driver.period_ns // 2, LATE_NS)
        for stamp in instants:
            states = self.driver.state_at(stamp)
            if len(states) == 1:
                [(turns, sample)] = states
            else:   # several drivers: their positions, speeds, accels and turns, in scene order
                turns, sample = transposed(states)
            lateness = woke - stamp
            self.tick(stamp, lateness, lateness > late_ns, turns, sample)

    def tick(self, stamp: int, lateness: int, late: bool, turns: Any,
             sample: CrankSample) -> None:
        """Solve and publish one instant, or count and say why it publishes nothing."""
        # The crank as whole turns plus an angle in one turn: an intermittent drive
        # (a Geneva wheel) indexes by the turns, never formed as a float sum.
        solver = self.solver
        angle, speed, accel = sample
        try:
            values, measure = solver.solve(angle, speed, accel, solver.max_error, turns)
        except AssemblyError as exc:
            refusal = 'not trusted' if isinstance(exc, UntrustedError) else 'cannot assemble'
            self.stats.record(stamp, lateness, late, error=str(exc), refusal=refusal,
                              sample=sample)
            self.logger.warning(f'no state published: {exc}', throttle_duration_sec=1.0)
            return
        sec, nanosec = divmod(stamp, NS_PER_S)
        try:
            self.publishing.tick(values, stamp, sec, nanosec)
        except RCLError as exc:
            if self._stop.is_set() or self.shutting_down():
                raise       # the context went away under a publish: the loop ends
            reason = str(exc).split(',', 1)[0]
            self.stats.publish_failed(stamp, lateness, late, reason)
            self.logger.warning(f'a state was not delivered ({reason}): a reliable subscriber '
                                'may be too slow for rate_hz; counted on diagnostics '
                                '(publish_failures)', throttle_duration_sec=1.0)
            return
        if self.markers is not None:
            # Built in the executor's thread, so that this thread keeps its deadlines.
            self.markers.request(self.driver.period_ns, sec, nanosec, angle, speed, accel)
        jumps_at = solver.jumps_at
        self.stats.published(stamp, lateness, late, measure, sample,
                             jumps_at is not None and jumps_at(angle, turns=turns))
        if measure < NEAR_SINGULAR:
            self.logger.warning(
                f'near-singular pose at {position_text(angle)}: measure {measure:.3g}',
                throttle_duration_sec=1.0)
