# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""What the node says on ``diagnostics``: the tick thread's counters, and statuses from them.

:class:`TickStats` is filled by the tick thread and emptied once a second
into a :class:`Window`; :func:`solver_status` and :func:`timing_status` turn a
window into :class:`Status` records (level, message, key/values), which the
node copies into ``diagnostic_msgs/DiagnosticStatus``. Nothing here imports
ROS, so every message and threshold is tested on its own.

Levels are those of ``diagnostic_msgs/DiagnosticStatus``: :data:`OK`,
:data:`WARN`, :data:`ERROR`, :data:`STALE`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
import math
import statistics
import threading
import time

from ..units import NS_PER_S

__all__ = ['DEFAULT_MAX_LATENESS_MS', 'ERROR', 'OK', 'STALE', 'Status', 'TickStats', 'WARN',
           'Window', 'lateness_p99_ns', 'solver_status', 'timing_status', 'waiting_for']

OK, WARN, ERROR, STALE = 0, 1, 2, 3

#: Timing turns WARN when a window's p99 lateness exceeds this (ms), the default of the
#: node's ``max_lateness_ms``: as far back as ``max_catch_up_s`` (0.1 s) still catches up, so
#: by default only skipped instants (and clock jumps) warn.
DEFAULT_MAX_LATENESS_MS = 100.0


@dataclass(frozen=True)
class Status:
    """One diagnostic status, ready to copy into ``diagnostic_msgs/DiagnosticStatus``."""

    level: int
    name: str
    message: str
    hardware_id: str
    values: tuple[tuple[str, str], ...] = ()

    def value(self, key: str) -> str:
        """Return the value of ``key`` (KeyError if absent)."""
        return dict(self.values)[key]


@dataclass
class Window:
    """Counts of one diagnostics window (about a second), and totals since the start."""

    elapsed_s: float = 0.0
    instants: int = 0           # grid instants solved (published or refused)
    published: int = 0
    unsolved: int = 0           # refused: cannot assemble, or not trusted
    near_singular: int = 0
    jump_instants: int = 0      # published one-sided: a value jumps there (a Geneva wheel's)
    late: int = 0
    skipped: int = 0            # grid instants dropped
    clock_jumps: int = 0
    publish_failures: int = 0   # instants the middleware refused to publish (not delivered)
    last_publish_failure: str = ''
    lateness_ns: list[int] = field(default_factory=list)   # sorted
    worst_measure: float = math.inf
    last_error: str = ''
    last_refusal: str = ''      # 'cannot assemble' or 'not trusted'
    last_sample: tuple[float, float, float] | None = None   # crank angle, speed, accel
    last_published_stamp_ns: int = 0
    totals: dict[str, int] = field(default_factory=dict)
    # Driven from a topic (carried over windows but the count): the last input message's
    # joints ignored and passed through, and the stamps' jumps back.
    stamp_jumps_back: int = 0
    last_stamp_jump_back: str = ''
    ignored_joints: tuple[str, ...] = ()
    passed_joints: tuple[str, ...] = ()


_TOTALS = ('instants', 'published', 'unsolved', 'late', 'skipped', 'clock_jumps',
           'jump_instants', 'stamp_jumps_back', 'publish_failures')
#: How many joint names a diagnostics value lists before it says how many more there are.
SHOWN_JOINTS = 20


def _seconds(stamp_ns: int) -> str:
    sec, nanosec = divmod(stamp_ns, NS_PER_S)
    return f'{sec}.{nanosec:09d} s'


def _joint_list(names: Sequence[str]) -> str:
    shown = ', '.join(names[:SHOWN_JOINTS])
    more = len(names) - SHOWN_JOINTS
    return f'{shown} and {more} more' if more > 0 else shown


class TickStats:
    """Counters the tick thread fills and the diagnostics timer empties (thread-safe)."""

    def __init__(self, near_singular: float = 0.0) -> None:
        #: A published instant whose measure is below this counts as near-singular.
        self.near_singular = near_singular
        self._lock = threading.Lock()
        self._totals = dict.fromkeys(_TOTALS, 0)
        self._last_published_stamp_ns = 0
        self._window = Window()
        self._reset(time.monotonic_ns())

    def _reset(self, now_mono_ns: int) -> None:
        self._start = now_mono_ns
        last = self._window
        self._window = Window(last_stamp_jump_back=last.last_stamp_jump_back,
                              ignored_joints=last.ignored_joints,
                              passed_joints=last.passed_joints)

    def record(self, stamp_ns: int, lateness_ns: int, late: bool, *, error: str | None = None,
               refusal: str = 'cannot assemble', measure: float = math.inf,
               near_singular: bool = False,
               sample: tuple[float, float, float] | None = None, jump: bool = False) -> None:
        """Count one grid instant: published (``error`` None) or refused with ``error``.

        ``refusal`` names the kind of refusal: ``'cannot assemble'`` or
        ``'not trusted'`` (an error bound above the tolerance); ``jump``: a
        value jumps at the published instant (published one-sided).
        """
        with self._lock:
            w = self._window
            w.instants += 1
            w.lateness_ns.append(lateness_ns)
            w.last_sample = sample
            if late:
                w.late += 1
            if error is None:
                w.published += 1
                self._last_published_stamp_ns = stamp_ns
                w.worst_measure = min(w.worst_measure, measure)
                if near_singular:
                    w.near_singular += 1
                if jump:
                    w.jump_instants += 1
            else:
                w.unsolved += 1
                w.last_error = error
                w.last_refusal = refusal

    def published(self, stamp_ns: int, lateness_ns: int, late: bool, measure: float,
                  sample: tuple[float, float, float], jump: bool = False) -> None:
        """Count one grid instant published: :meth:`record` without a refusal, the tick's way.

        ``jump``: a value jumps at the instant (published one-sided).
        """
        with self._lock:
            w = self._window
            w.instants += 1
            w.published += 1
            w.lateness_ns.append(lateness_ns)
            w.last_sample = sample
            self._last_published_stamp_ns = stamp_ns
            if late:
                w.late += 1
            if measure < w.worst_measure:
                w.worst_measure = measure
            if measure < self.near_singular:
                w.near_singular += 1
            if jump:
                w.jump_instants += 1

    def topic_input(self, stamp_ns: int, jumped_from_ns: int | None, ignored: Sequence[str],
                    passed: Sequence[str]) -> None:
        """Note what a published input message (``drive: topic``) did beside its drivers.

        ``jumped_from_ns``: the last published stamp, when ``stamp_ns`` jumped
        back from it (the order reset); ``ignored`` and ``passed``: the
        message's other joints, dropped or passed through.
        """
        with self._lock:
            w = self._window
            if jumped_from_ns is not None:
                w.stamp_jumps_back += 1
                w.last_stamp_jump_back = (
                    f'from {_seconds(jumped_from_ns)} to {_seconds(stamp_ns)}, '
                    f'{(jumped_from_ns - stamp_ns) / NS_PER_S:.9g} s back')
            w.ignored_joints = tuple(ignored)
            w.passed_joints = tuple(passed)

    def publish_failed(self, stamp_ns: int, lateness_ns: int, late: bool, reason: str) -> None:
        """Count one grid instant solved whose publish the middleware refused (not delivered)."""
        with self._lock:
            w = self._window
            w.instants += 1
            w.lateness_ns.append(lateness_ns)
            if late:
                w.late += 1
            w.publish_failures += 1
            w.last_publish_failure = f'at {_seconds(stamp_ns)}: {reason}'

    def skip(self, count: int) -> None:
        """Count ``count`` grid instants dropped."""
        if count:
            with self._lock:
                self._window.skipped += count

    def clock_jump(self) -> None:
        """Count a jump of the clock (the grid started again)."""
        with self._lock:
            self._window.clock_jumps += 1

    def take_window(self, now_mono_ns: int | None = None) -> Window:
        """Return the window since the last call (with totals) and start a new one."""
        now = time.monotonic_ns() if now_mono_ns is None else now_mono_ns
        with self._lock:
            w = self._window
            w.elapsed_s = (now - self._start) / NS_PER_S
            for key in _TOTALS:
                self._totals[key] += getattr(w, key)
            w.totals = dict(self._totals)
            w.last_published_stamp_ns = self._last_published_stamp_ns
            self._reset(now)
        w.lateness_ns.sort()
        return w


def _quantile_ns(sorted_ns: Sequence[int], q: float) -> int | None:
    if not sorted_ns:
        return None
    return sorted_ns[min(len(sorted_ns) - 1, int(q * len(sorted_ns)))]


def _quantile_us(sorted_ns: Sequence[int], q: float) -> str:
    value = _quantile_ns(sorted_ns, q)
    return 'n/a' if value is None else f'{value / 1e3:.1f}'


def lateness_p99_ns(window: Window) -> int | None:
    """Return the 99th percentile of the window's lateness in ns (None if it has no ticks)."""
    return _quantile_ns(window.lateness_ns, 0.99)


def waiting_for(*, configured: bool, publishing: bool, managed: bool, clock: bool) -> str:
    """Return what the node waits for before it publishes ('' for nothing).

    ``configured``: a scene is loaded; ``publishing``: the tick thread runs
    or the input is active; ``managed``: it follows the lifecycle;
    ``clock``: simulated time has no ``/clock`` yet.
    """
    if not configured:
        return 'configure (lifecycle)'
    if not publishing:
        return 'activate (lifecycle)' if managed else 'the start'
    return '/clock' if clock else ''


def solver_status(window: Window, *, name: str, hardware_id: str, near_singular: float,
                  waiting_for: str = '', assembly: str = '', extra_joints: str = '',
                  solver_path: str = '',
                  forces: Sequence[tuple[str, str]] = ()) -> Status:
    """Return the solver status of ``window``.

    ERROR if any instant could not be solved or was refused (with the last
    reason), WARN if an input's stamp jumped back (the order reset), if any
    was near-singular or the node is ``waiting_for`` something (e.g.
    ``'/clock'``), STALE if there was nothing to solve, else OK.
    ``extra_joints``: the node's ``extra_joints`` when it is driven from a
    topic ('' otherwise), which adds the keys ``extra_joints``,
    ``ignored_joints`` and ``passed_joints`` (the last input's),
    ``stamp_jumps_back``, ``stamp_jumps_back_total`` and
    ``last_stamp_jump_back``.
    Instants at which a value jumps, published one-sided (a Geneva wheel's
    engagement instants), are counted (keys ``jump_instants``,
    ``jump_instants_total``) and do not change the level.
    ``assembly`` says in one line where the scene cannot assemble (key
    ``assembly``). ``solver_path`` says which function solves the ticks (key
    ``solver_path``): ``compiled``, or ``general: REASON`` where the tick
    does not compile (:mod:`~mech_kinematics.ros.solver_path`). ``forces``:
    the keys of a scene with forces (``effort``: what the efforts are, and
    how many instants' forces were left out, ``forces_left_out_total``, and
    why the last was, ``last_forces_left_out``; which path solves the statics,
    ``forces_path``: :func:`~mech_kinematics.solver.solve.paths`), added as
    they are.
    """
    w = window
    if waiting_for:
        level, message = WARN, f'waiting for {waiting_for}: nothing published'
    elif w.instants == 0:
        level, message = STALE, 'no ticks'
    elif w.unsolved:
        level = ERROR
        message = f'{w.last_refusal} at {w.unsolved} of {w.instants} ticks: {w.last_error}'
    elif w.stamp_jumps_back:
        level = WARN
        message = (f'input stamp jumped back {w.stamp_jumps_back} time(s) (the order reset), '
                   f'last {w.last_stamp_jump_back}')
    elif w.near_singular:
        level, message = WARN, f'near-singular at {w.near_singular} of {w.instants} ticks'
    else:
        level, message = OK, 'ok'
    values = [
        ('worst_singularity_measure',
         f'{w.worst_measure:.6g}' if math.isfinite(w.worst_measure) else 'n/a'),
        ('near_singular_threshold', f'{near_singular:g}'),
        ('unsolved_ticks', str(w.unsolved)),
        ('unsolved_ticks_total', str(w.totals.get('unsolved', 0))),
        ('jump_instants', str(w.jump_instants)),
        ('jump_instants_total', str(w.totals.get('jump_instants', 0))),
        ('last_error', w.last_error),
    ]
    if solver_path:
        values.append(('solver_path', solver_path))
    if assembly:
        values.append(('assembly', assembly))
    values += forces
    if extra_joints:
        values += [('extra_joints', extra_joints),
                   ('ignored_joints', _joint_list(w.ignored_joints)),
                   ('passed_joints', _joint_list(w.passed_joints)),
                   ('stamp_jumps_back', str(w.stamp_jumps_back)),
                   ('stamp_jumps_back_total', str(w.totals.get('stamp_jumps_back', 0))),
                   ('last_stamp_jump_back', w.last_stamp_jump_back)]
    if w.last_sample is not None and isinstance(w.last_sample[0], tuple):
        # Several drivers: each one's position, speed and acceleration, in scene order.
        values += [(f'driver_{key}', ', '.join(map(repr, column)))
                   for key, column in zip(('positions', 'speeds', 'accels'), w.last_sample,
                                          strict=True)]
    elif w.last_sample is not None:
        values += [('crank_angle', repr(w.last_sample[0])),
                   ('crank_speed', repr(w.last_sample[1])),
                   ('crank_accel', repr(w.last_sample[2]))]
    return Status(level, f'{name}: solver', message, hardware_id, tuple(values))


def timing_status(window: Window, *, name: str, hardware_id: str, rate_hz: float,
                  max_lateness_ms: float = DEFAULT_MAX_LATENESS_MS) -> Status:
    """Return the timing status of ``window``.

    WARN only when a subscriber sees something wrong: the middleware refused
    to publish an instant's state (a reliable subscriber too slow for the
    rate, shared memory full: counted, the node goes on), a grid instant was
    skipped (never published), the window's p99 lateness exceeds
    ``max_lateness_ms``, or a clock jump restarted the grid. Late ticks that
    were caught up (a burst after a stall) are OK: every instant was published
    with its own stamp. The message says the counts and the bound.
    """
    w = window
    owed = w.instants + w.skipped
    achieved = w.instants / w.elapsed_s if w.elapsed_s > 0 else 0.0
    counts = (f'{w.late} late (caught up) and {w.skipped} skipped of {owed} ticks in '
              f'{w.elapsed_s:.2f} s')
    p99 = lateness_p99_ns(w)
    p99_ms = 'n/a' if p99 is None else f'{p99 / 1e6:.1f} ms'
    bound = f'{max_lateness_ms:g} ms'
    if w.clock_jumps:
        level, message = WARN, f'clock jumped {w.clock_jumps} time(s): grid restarted; {counts}'
    elif w.publish_failures:
        level = WARN
        message = (f'{w.publish_failures} state(s) not delivered: the middleware refused the '
                   f'publish (last {w.last_publish_failure}); {counts}')
    elif w.skipped:
        level, message = WARN, f'{w.skipped} instant(s) skipped: {counts}'
    elif p99 is not None and p99 > max_lateness_ms * 1e6:
        level = WARN
        message = f'p99 lateness {p99_ms} above max_lateness_ms ({bound}): {counts}'
    else:
        level = OK
        message = (f'ok: {counts}; p99 lateness {p99_ms} (WARN on a skipped instant or p99 '
                   f'above {bound})')
    lateness = w.lateness_ns
    values = (
        ('rate_hz', f'{rate_hz:g}'),
        ('achieved_rate_hz', f'{achieved:.3f}'),
        ('late_ticks', str(w.late)),
        ('skipped_ticks', str(w.skipped)),
        ('max_lateness_ms', f'{max_lateness_ms:g}'),
        ('lateness_median_us',
         f'{statistics.median(lateness) / 1e3:.1f}' if lateness else 'n/a'),
        ('lateness_p99_us', _quantile_us(lateness, 0.99)),
        ('lateness_max_us', f'{lateness[-1] / 1e3:.1f}' if lateness else 'n/a'),
        ('ticks_total', str(w.totals.get('instants', 0))),
        ('published_total', str(w.totals.get('published', 0))),
        ('last_published_stamp_ns', str(w.last_published_stamp_ns)),
        ('late_ticks_total', str(w.totals.get('late', 0))),
        ('skipped_ticks_total', str(w.totals.get('skipped', 0))),
        ('clock_jumps_total', str(w.totals.get('clock_jumps', 0))),
        ('publish_failures', str(w.publish_failures)),
        ('publish_failures_total', str(w.totals.get('publish_failures', 0))),
        ('last_publish_failure', w.last_publish_failure),
    )
    return Status(level, f'{name}: timing', message, hardware_id, values)
