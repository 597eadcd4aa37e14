# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``make run``: start the node and show what it publishes, one line a second.

``python -m mech_kinematics run [--ros-args ...]`` starts ``kinematics_node``
as a child process (the arguments go to it unchanged, e.g. ``--ros-args -p
scene:=slider_crank_150_600``) and subscribes to its ``joint_states`` and
``diagnostics`` with the same ROS arguments
(:class:`mech_kinematics.tools.live_view.LiveView`), so namespaces and remaps
apply to both. The same process serves the browser view
(:class:`mech_kinematics.tools.view.ViewServer`) and prints its URL. Ctrl-C
(or SIGTERM) stops the views and then the node.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
import os
import signal
import subprocess
import sys
from typing import Any

from .cli import run_tool

__all__ = ['add_parser', 'main']

STOP_TIMEOUT_S = 3.0

RUN_HELP = ('Start kinematics_node, a live console view of what it publishes and a browser '
            'view (its URL is printed). '
            'Arguments after `run` go to the node, e.g. '
            '`run --ros-args -p scene:=quick_return -p rate_hz:=200.0`.')


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


def _handle(args: argparse.Namespace) -> int:
    return main(args.node_args)


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register the ``run`` command on ``subparsers``; return its parser."""
    parser: argparse.ArgumentParser = subparsers.add_parser(
        'run', help='start the node with a live console view and a browser view (make run); '
                    'Ctrl-C stops both',
        description=RUN_HELP)
    parser.add_argument('node_args', nargs=argparse.REMAINDER, metavar='NODE_ARGS',
                        help='arguments for the node (--ros-args ...)')
    parser.set_defaults(handler=_handle)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the node and the view until Ctrl-C; return the node's exit status.

    Every argument goes to the node unchanged (``argparse`` would refuse
    ``--ros-args`` as a first argument), except a lone ``-h``/``--help``.
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv in (['-h'], ['--help']):
        return run_tool(add_parser, argv)
    import rclpy
    from rclpy.executors import ExternalShutdownException
    from rclpy.signals import SignalHandlerOptions

    from .live_view import LiveView
    from .view import DEFAULT_PORT, ViewServer

    command = [sys.executable, '-m', 'mech_kinematics.kinematics_node', *argv]
    # A session of its own: Ctrl-C reaches this process only, which then stops
    # the node exactly once.
    child = subprocess.Popen(command, start_new_session=True,
                             env=dict(os.environ, PYTHONUNBUFFERED='1'))
    ros_args = argv[argv.index('--ros-args'):] if '--ros-args' in argv else []
    # Ctrl-C only sets a flag, checked between spins: a KeyboardInterrupt raised
    # inside rclpy (taking a message) would come out as a RuntimeError instead.
    stopping: list[int] = []
    rclpy.init(args=['live', *ros_args], signal_handler_options=SignalHandlerOptions.NO)
    previous = signal.signal(signal.SIGINT, lambda number, frame: stopping.append(number))
    view = server = None
    try:
        view = LiveView()
        server = ViewServer(view, DEFAULT_PORT)
        print(f'mech_kinematics: node started (pid {child.pid}); Ctrl-C stops it.', flush=True)
        print(f'mech_kinematics: browser view on {server.url}', flush=True)
        while child.poll() is None and not stopping:
            rclpy.spin_once(view, timeout_sec=0.05)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass  # Ctrl-C: stop the node below
    finally:
        signal.signal(signal.SIGINT, previous)
        if server is not None:
            server.close()
        if view is not None:
            view.destroy_node()
        rclpy.try_shutdown()
        status = _stop_child(child)
    return status


if __name__ == '__main__':
    sys.exit(main())
