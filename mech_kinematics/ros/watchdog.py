# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A publish that never returns ends the node, exit status 1, for a supervisor to restart it.

Fast DDS's shared-memory transport can block a publishing thread for good on
the port of a reader killed with SIGKILL (eProsima/Fast-DDS#6485,
docs/robustness.md). The node then publishes nothing and, as rclpy's
``publish`` keeps the GIL while it waits, no Python thread of it runs again
(SIGINT is not even seen). A node that no longer publishes must not look
alive: :class:`PublishWatchdog` ends it, so that launch's ``respawn`` or
systemd's ``Restart=`` starts it again.

The publishing threads pay a Python call, a clock read and three stores
per publish (0.55 us at load 10), no handoff to another thread:
:meth:`PublishWatch.wrap` returns a publish that stamps its :class:`Slot`
with ``time.monotonic_ns()`` and the topic before calling the publisher,
and clears the stamp after. A daemon thread looks at
the slots a few times per bound. It sees a publish stuck beyond the bound:

- while the stuck thread has released the GIL, the watchdog's thread logs
  one line naming the topic and ends the process with ``os._exit(1)``;
- while the stuck thread keeps the GIL (rclpy's publish, the Fast DDS hang),
  no Python runs: then :mod:`faulthandler`'s watchdog, a C thread that the
  watchdog's thread re-arms at every look, fires once it has not been
  re-armed for ``bound + interval``: it writes ``Timeout (0:00:02)!`` and
  every thread's stack, the stuck one ending in the frame ``publish on
  TOPIC``, and ends the process with status 1.

A process stopped as a whole (SIGSTOP, a debugger) is no stuck publish: the
watchdog's thread judges nothing on a look that came late by more than half
the bound (a stopped process resumed). faulthandler cannot tell: a stop
longer than ``bound + interval`` ends the node (``publish_timeout_s:=0``
turns the watchdog off).

No ROS is imported: the tests run it with stand-ins
(``test/ros/test_watchdog.py``).
"""

from __future__ import annotations

from collections.abc import Callable
import faulthandler
import os
import sys
import threading
import time
from typing import Any

__all__ = ['PublishWatch', 'PublishWatchdog', 'Slot', 'stuck_line']

#: The watchdog's thread looks at the slots at least this often, s.
LONGEST_LOOK_S = 0.5


class Slot:
    """One thread's publish in progress: since when (monotonic ns, 0: none) and on which topic."""

    __slots__ = ('since_ns', 'topic')

    def __init__(self) -> None:
        self.since_ns = 0
        self.topic = ''


class PublishWatch:
    """The slots of the node's publishing threads (one per thread that publishes)."""

    def __init__(self) -> None:
        self.slots: list[Slot] = []

    def slot(self) -> Slot:
        """Return a new slot, for the publishes of one thread."""
        slot = Slot()
        self.slots.append(slot)
        return slot

    def wrap(self, slot: Slot, topic: str,
             publish: Callable[[Any], None]) -> Callable[[Any], None]:
        """Return ``publish`` stamping ``slot`` with the time and ``topic`` while it runs.

        The function's own name is ``publish on TOPIC``: a stack dumped by
        faulthandler names the topic of the publish that does not return.
        """
        monotonic_ns = time.monotonic_ns

        def watched(message: Any) -> None:
            slot.since_ns = monotonic_ns()
            slot.topic = topic
            try:
                publish(message)
            finally:
                slot.since_ns = 0

        watched.__code__ = watched.__code__.replace(co_name=f'publish on {topic}')
        watched.__name__ = watched.__qualname__ = f'publish on {topic}'
        return watched

    def stuck(self, now_ns: int, bound_ns: int) -> tuple[str, int] | None:
        """Return (topic, ns stuck) of a publish running longer than ``bound_ns``, or None."""
        for slot in self.slots:
            since, topic = slot.since_ns, slot.topic
            if since and now_ns - since > bound_ns:
                return topic, now_ns - since
        return None


def stuck_line(topic: str, stuck_ns: int) -> str:
    """Return the one line said of a publish on ``topic`` stuck for ``stuck_ns``."""
    return (f'a publish on {topic} has not returned for {stuck_ns / 1e9:.1f} s (the Fast DDS '
            'shared-memory hang of a killed reader, docs/robustness.md?): exiting with status '
            '1 for a supervisor to restart the node')


class PublishWatchdog:
    """The thread that ends the process when a publish of ``watch`` is stuck beyond ``bound_s``.

    Parameters
    ----------
    watch : PublishWatch
        The slots it looks at.
    bound_s : float
        How long a publish may take, s (0: no watchdog).
    fatal : callable
        ``fatal(line)``: says the line (the node's logger's ``fatal``).
    exit : callable
        ``exit(status)``: ends the process (``os._exit``; the tests' stand-in).
    """

    def __init__(self, watch: PublishWatch, bound_s: float, fatal: Callable[[str], Any],
                 exit: Callable[[int], Any] = os._exit) -> None:
        self.watch, self.fatal, self.exit = watch, fatal, exit
        self.bound_s = bound_s
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    @property
    def interval_s(self) -> float:
        """The time between two looks, s."""
        return min(self.bound_s / 4, LONGEST_LOOK_S)

    def start(self) -> None:
        """Start looking (nothing with a bound of 0, or when started already)."""
        if self.bound_s <= 0 or self._thread is not None:
            return
        self._stop.clear()
        self._arm()
        self._thread = threading.Thread(target=self._run, name='mech_kinematics_watchdog',
                                        daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop looking, and disarm faulthandler's timer."""
        self._stop.set()
        thread, self._thread = self._thread, None
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=2.0)
        if thread is not None:
            faulthandler.cancel_dump_traceback_later()

    def _arm(self) -> None:
        # faulthandler's C thread: it fires if this thread does not run again in time
        # (a publish stuck with the GIL held).
        faulthandler.dump_traceback_later(self.bound_s + self.interval_s, exit=True,
                                          file=sys.__stderr__ or sys.stderr)

    def _run(self) -> None:
        bound_ns = round(self.bound_s * 1e9)
        interval = self.interval_s
        last = time.monotonic_ns()
        while not self._stop.wait(interval):
            now = time.monotonic_ns()
            late = now - last - interval * 1e9
            last = now
            self._arm()
            if late > bound_ns / 2:
                continue        # the process was stopped (SIGSTOP): no publish judged now
            found = self.watch.stuck(now, bound_ns)
            if found is not None:
                self.fatal(stuck_line(*found))
                self.exit(1)
                return
