# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``python -m mech_kinematics COMMAND ...``: every tool, registered in one list."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
import sys

from .tools import bench, check, diagram, plot, record, reindex, report, run, solve, urdf, view
from .tools.cli import ArgumentParser, PROG, run_handler

__all__ = ['TOOLS', 'build_parser', 'main']

#: The subcommands, in the order ``--help`` lists them.
TOOLS = (solve, check, run, bench, diagram, plot, record, reindex, report, urdf, view)


def build_parser() -> argparse.ArgumentParser:
    """Return the parser of ``python -m mech_kinematics``."""
    parser = ArgumentParser(
        prog=PROG, description='Analytic kinematics of planar linkages (mech_kinematics).')
    commands = parser.add_subparsers(dest='command', required=True, metavar='COMMAND')
    for tool in TOOLS:
        tool.add_parser(commands)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ['run']:
        return run.main(argv[1:])   # everything after `run` goes to the node untouched
    if argv[:1] == ['view']:
        return view.main(argv[1:])  # --ros-args after `view` go to its node untouched
    return run_handler(build_parser().parse_args(argv))


if __name__ == '__main__':
    sys.exit(main())
