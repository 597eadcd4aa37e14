# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The live console view of ``make run``: what the node publishes, one line a second.

:class:`LiveView` subscribes to ``joint_states`` and ``diagnostics`` and prints
the achieved rate, the messages received, the crank speed, the joint positions
and the statuses. :mod:`mech_kinematics.tools.run` starts it beside the node.
"""

from __future__ import annotations


from diagnostic_msgs.msg import DiagnosticArray
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import JointState

from . import topics
from ..units import rpm_from_rad_per_s

__all__ = ['LiveView']


class LiveView(Node):
    """Print the latest joint state and the node's diagnostics once a second."""

    def __init__(self) -> None:
        super().__init__('mech_kinematics_live')
        self._latest: JointState | None = None
        self._count = 0
        self._lines = 0
        self.create_subscription(JointState, topics.JOINT_STATES, self._on_state,
                                 qos_profile_sensor_data)
        self.create_subscription(DiagnosticArray, topics.DIAGNOSTICS, self._on_diagnostics, 10)

    def _on_state(self, msg: JointState) -> None:
        self._latest = msg
        self._count += 1

    def _on_diagnostics(self, msg: DiagnosticArray) -> None:
        values: dict[str, str] = {}
        for status in msg.status:
            values.update((kv.key, kv.value) for kv in status.values)
        if self._lines % 20 == 0:
            print('rate (Hz) | received/s | crank speed (rpm) | joint positions (rad for '
                  'revolute, m for prismatic) | status', flush=True)
        self._lines += 1
        line = [f'{values.get("achieved_rate_hz", "?"):>9}', f'{self._count:5d}']
        self._count = 0
        speed = values.get('crank_speed')
        line.append(f'{rpm_from_rad_per_s(float(speed)):+9.2f}' if speed else '        ?')
        js = self._latest
        if js is not None:
            line.append('  '.join(f'{name} {position:+.4f}'
                                  for name, position in zip(js.name, js.position, strict=False)))
        line.append('; '.join(f'{s.name.split(": ")[-1]} {s.message}' for s in msg.status))
        print(' | '.join(line), flush=True)
