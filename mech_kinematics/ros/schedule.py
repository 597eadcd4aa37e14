# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The instants the node publishes: an exact grid, and what a wake-up owes it.

Tick ``k`` of a grid is the instant ``t0 + k * period`` in integer
nanoseconds of the node's clock, so the stamps of a recording are exactly
evenly spaced. A wake-up at ``now`` owes every grid instant up to ``now`` not
taken yet: in *catch-up* mode all of them that lie within ``max_behind`` of
``now`` (older ones are skipped and counted), in *skip* mode only the latest.
A rate change starts a new grid at the next instant not taken.

Pure Python, no ROS: the driver (:mod:`~mech_kinematics.ros.driver`) owns one :class:`TickGrid`.
"""

from __future__ import annotations

from typing import NamedTuple

from ..units import NS_PER_S

__all__ = ['Due', 'TickGrid', 'period_ns_from_rate']


def period_ns_from_rate(rate_hz: float) -> int:
    """Return the period of ``rate_hz`` in whole nanoseconds (at least 1)."""
    return max(1, round(NS_PER_S / rate_hz))


class Due(NamedTuple):
    """What a wake-up publishes."""

    instants: range
    """The grid instants to publish, in order, ns."""
    skipped: int
    """Grid instants dropped (older than the catch-up bound, or all but one in skip mode)."""


class TickGrid:
    """Grid instants ``start + k * period`` (ns) and the next one not taken yet.

    Parameters
    ----------
    start_ns : int
        The first instant, ns.
    period_ns : int
        Spacing of the instants, ns (> 0).
    """

    def __init__(self, start_ns: int, period_ns: int) -> None:
        if period_ns <= 0:
            msg = f'Expected a positive period, got {period_ns} ns'
            raise ValueError(msg)
        self.next_ns = int(start_ns)
        self.period_ns = int(period_ns)

    @classmethod
    def aligned(cls, now_ns: int, period_ns: int) -> TickGrid:
        """Return the grid of multiples of ``period_ns`` whose first instant is >= ``now_ns``."""
        return cls(-(-now_ns // period_ns) * period_ns, period_ns)

    def set_period(self, period_ns: int) -> None:
        """Space the instants after the next one by ``period_ns`` (a new grid from there)."""
        if period_ns <= 0:
            msg = f'Expected a positive period, got {period_ns} ns'
            raise ValueError(msg)
        self.period_ns = int(period_ns)

    def take(self, now_ns: int, max_behind_ns: int, catch_up: bool = True) -> Due:
        """Return the instants owed at ``now_ns`` and mark them taken.

        Parameters
        ----------
        now_ns : int
            The clock now, ns.
        max_behind_ns : int
            Catch-up mode publishes the owed instants no older than
            ``now_ns - max_behind_ns`` (always at least the latest).
        catch_up : bool
            ``False``: publish only the latest owed instant.
        """
        period = self.period_ns
        first = self.next_ns
        if now_ns < first:
            return Due(range(0), 0)
        owed = (now_ns - first) // period + 1
        last = first + (owed - 1) * period
        keep = min(owed, max_behind_ns // period + 1) if catch_up else 1
        self.next_ns = last + period
        return Due(range(last - (keep - 1) * period, last + 1, period), owed - keep)
