# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The live console view of ``make run``: what the node publishes, one line a second.

:class:`LiveView` subscribes to ``joint_states`` and ``diagnostics`` and, on
each diagnostics message (once a second), prints the achieved rate, the
messages received, the crank speed, each joint's value and range over the
second, and the statuses. :mod:`mech_kinematics.tools.run` starts it beside
the node.

A line a second of the latest state would look frozen whenever the crank
turns a whole number of times a second (120 rpm: two turns), so
:class:`Interval` shows, for each joint, the sample at a drifting instant of
the second (the fraction ``k * 0.618...`` modulo 1 of the k-th interval,
never commensurate with a turn) and the minimum and maximum over the second.
"""

from __future__ import annotations

from collections.abc import Sequence
import math

from diagnostic_msgs.msg import DiagnosticArray
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import JointState

from ..ros import topics
from ..units import rpm_from_rad_per_s

__all__ = ['GOLDEN_FRACTION', 'Interval', 'JointSummary', 'LiveView']

#: Where in the k-th interval its sample is taken: frac(k * GOLDEN_FRACTION).
GOLDEN_FRACTION = (math.sqrt(5.0) - 1.0) / 2.0

HEADER = ('rate (Hz) | received/s | crank speed (rpm) | joint: value at a drifting instant '
          '[min .. max over the second] (rad for revolute, m for prismatic) | status')


class JointSummary(tuple[str, float, float, float]):
    """One joint over an interval: (name, sampled value, minimum, maximum)."""

    __slots__ = ()

    def __new__(cls, name: str, value: float, low: float, high: float) -> JointSummary:
        """Make the summary of joint ``name``."""
        return super().__new__(cls, (name, value, low, high))

    def __str__(self) -> str:
        """Return ``name +value [min .. max]``, 4 decimals."""
        name, value, low, high = self
        return f'{name} {value:+.4f} [{low:+.4f} .. {high:+.4f}]'


class Interval:
    """The joint states received in one interval: a drifting sample and each joint's range."""

    def __init__(self) -> None:
        self.count = 0
        self._names: tuple[str, ...] = ()
        self._times: list[float] = []
        self._positions: list[Sequence[float]] = []

    def add(self, t: float, names: Sequence[str], positions: Sequence[float]) -> None:
        """Add the joint state received at ``t`` (seconds, any monotonic origin)."""
        names = tuple(names)
        if names != self._names:        # another scene: start the interval again
            self._names, self._times, self._positions = names, [], []
        self.count += 1
        self._times.append(t)
        self._positions.append(tuple(positions))

    def summary(self, k: int) -> list[JointSummary]:
        """Return each joint's summary, sampled at fraction frac(k * golden) of the interval.

        Empty if nothing was received. The interval's first and last
        receptions bound it.
        """
        if not self._times:
            return []
        t0, t1 = self._times[0], self._times[-1]
        at = t0 + math.fmod(k * GOLDEN_FRACTION, 1.0) * (t1 - t0)
        index = next(i for i, t in enumerate(self._times) if t >= at)
        columns = list(zip(*self._positions, strict=True))
        return [JointSummary(name, self._positions[index][j], min(columns[j]), max(columns[j]))
                for j, name in enumerate(self._names)]


class LiveView(Node):
    """Print the node's joint states and diagnostics once a second."""

    def __init__(self) -> None:
        super().__init__('mech_kinematics_live')
        self._interval = Interval()
        self._lines = 0
        self.create_subscription(JointState, topics.JOINT_STATES, self._on_state,
                                 qos_profile_sensor_data)
        self.create_subscription(DiagnosticArray, topics.DIAGNOSTICS, self._on_diagnostics, 10)

    def _on_state(self, msg: JointState) -> None:
        stamp = msg.header.stamp
        self._interval.add(stamp.sec + stamp.nanosec * 1e-9, msg.name, msg.position)

    def _on_diagnostics(self, msg: DiagnosticArray) -> None:
        values: dict[str, str] = {}
        for status in msg.status:
            values.update((kv.key, kv.value) for kv in status.values)
        if self._lines % 20 == 0:
            print(HEADER, flush=True)
        interval, self._interval = self._interval, Interval()
        line = [f'{values.get("achieved_rate_hz", "?"):>9}', f'{interval.count:10d}']
        speed = values.get('crank_speed')
        line.append(f'{rpm_from_rad_per_s(float(speed)):+17.2f}' if speed else f'{"?":>17}')
        joints = interval.summary(self._lines)
        if joints:
            line.append('  '.join(str(j) for j in joints))
        line.append('; '.join(f'{s.name.split(": ")[-1]} {s.message}' for s in msg.status))
        self._lines += 1
        print(' | '.join(line), flush=True)
