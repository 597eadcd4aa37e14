# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``python -m mech_kinematics COMMAND ...``: every tool, registered in one list."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
import sys

from .tools import (bench, check, diagram, plot, record, reindex, report, run, solve, urdf,
                    urdf2scene, view)
from .tools.cli import ArgumentParser, PROG, run_handler

__all__ = ['TOOLS', 'build_parser', 'main']

#: The subcommands, in the order ``--help`` lists them.
TOOLS = (solve, check, run, bench, diagram, plot, record, reindex, report, urdf, urdf2scene,
         view)
#: The node's executable, listed after the tools: ``python -m mech_kinematics NODE ...`` is
#: the console script ``kinematics_node ...`` (``ros2 run mech_kinematics kinematics_node``).
NODE = 'kinematics_node'


def build_parser() -> argparse.ArgumentParser:
    """Return the parser of ``python -m mech_kinematics``."""
    parser = ArgumentParser(
        prog=PROG, description='Analytic kinematics of planar linkages (mech_kinematics).')
    commands = parser.add_subparsers(dest='command', required=True, metavar='COMMAND')
    for tool in TOOLS:
        tool.add_parser(commands)
    node = commands.add_parser(
        NODE, help='the node itself, as the kinematics_node executable (ros2 run '
                   'mech_kinematics kinematics_node); every argument goes to it untouched',
        description=f'Start the node. Every argument after {NODE} goes to it untouched, e.g. '
                    f'`{NODE} --ros-args -p scene:=quick_return`.')
    node.add_argument('node_args', nargs=argparse.REMAINDER, metavar='NODE_ARGS',
                      help='arguments for the node (--ros-args ...)')
    node.set_defaults(handler=lambda args: _node(args.node_args))
    return parser


def _node(argv: Sequence[str]) -> int:
    """Run the node as its console script does, with ``argv`` after the program's name."""
    from .kinematics_node import main as node_main

    return node_main([NODE, *argv])


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ['run']:
        return run.main(argv[1:])   # everything after `run` goes to the node untouched
    if argv[:1] == ['view']:
        return view.main(argv[1:])  # --ros-args after `view` go to its node untouched
    if argv[:1] == [NODE]:
        return _node(argv[1:])      # every argument goes to the node untouched, --help too
    return run_handler(build_parser().parse_args(argv))


if __name__ == '__main__':
    sys.exit(main())
