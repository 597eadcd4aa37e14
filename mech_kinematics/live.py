# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``make run``: start the node and show what it publishes, one line a second.

``python -m mech_kinematics run [--ros-args ...]`` starts ``kinematics_node``
as a child process (the arguments go to it unchanged, e.g. ``--ros-args -p
scene:=slider_crank_150_600``) and subscribes to its ``joint_states`` and
``diagnostics`` with the same ROS arguments, so namespaces and remaps apply to
both. Ctrl-C (or SIGTERM) stops the view and then the node.
"""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys

from diagnostic_msgs.msg import DiagnosticArray
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import JointState

__all__ = ['main']

STOP_TIMEOUT_S = 3.0


class LiveView(Node):
    """Print the latest joint state and the node's diagnostics once a second."""

    def __init__(self) -> None:
        super().__init__('mech_kinematics_live')
        self._latest: JointState | None = None
        self._count = 0
        self._lines = 0
        self.create_subscription(JointState, 'joint_states', self._on_state,
                                 qos_profile_sensor_data)
        self.create_subscription(DiagnosticArray, 'diagnostics', self._on_diagnostics, 10)

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
        line.append(f'{float(speed) * 30 / math.pi:+9.2f}' if speed else '        ?')
        js = self._latest
        if js is not None:
            line.append('  '.join(f'{name} {position:+.4f}'
                                  for name, position in zip(js.name, js.position, strict=False)))
        line.append('; '.join(f'{s.name.split(": ")[-1]} {s.message}' for s in msg.status))
        print(' | '.join(line), flush=True)


def _stop_child(child: subprocess.Popen[bytes]) -> int:
    """Ask the node to stop (SIGINT), escalate if it does not; return its status."""
    if child.poll() is None:
        child.send_signal(signal.SIGINT)
    try:
        return child.wait(timeout=STOP_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        child.terminate()
        try:
            return child.wait(timeout=STOP_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            child.kill()
            return child.wait()


def main(argv: list[str] | None = None) -> int:
    """Run the node and the view until Ctrl-C; return the node's exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    command = [sys.executable, '-m', 'mech_kinematics.kinematics_node', *argv]
    # A session of its own: Ctrl-C reaches this process only, which then stops
    # the node exactly once.
    child = subprocess.Popen(command, start_new_session=True,
                             env=dict(os.environ, PYTHONUNBUFFERED='1'))
    ros_args = argv[argv.index('--ros-args'):] if '--ros-args' in argv else []
    rclpy.init(args=['live', *ros_args])
    view = None
    try:
        view = LiveView()
        print(f'mech_kinematics: node started (pid {child.pid}); Ctrl-C stops it.', flush=True)
        while child.poll() is None:
            rclpy.spin_once(view, timeout_sec=0.2)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass  # Ctrl-C: stop the node below
    finally:
        if view is not None:
            view.destroy_node()
        rclpy.try_shutdown()
        status = _stop_child(child)
    return status


if __name__ == '__main__':
    sys.exit(main())
