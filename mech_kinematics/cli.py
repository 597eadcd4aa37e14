# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The shape every command-line tool shares: argument types and the standalone ``main``.

Each tool module in :mod:`mech_kinematics.tools` defines
``add_parser(subparsers)``, which registers its subcommand with a ``handler``
default (a function of the parsed arguments returning the exit status), and
``main(argv=None)``, which is :func:`run_tool` on its own ``add_parser``.
``python -m mech_kinematics`` (:mod:`mech_kinematics.__main__`) registers all
of them statically. Tool modules import heavy dependencies (matplotlib,
rclpy, mpmath, scipy) inside their functions, so building the parser is
cheap.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence
import math
import sys
from typing import Any

__all__ = ['PROG', 'finite_float', 'positive_int', 'run_tool']

#: The program name shown in usage lines.
PROG = 'python -m mech_kinematics'


def finite_float(text: str) -> float:
    """Parse a finite number, or tell argparse why not."""
    try:
        value = float(text)
    except ValueError:
        msg = f'expected a number, got {text!r}'
        raise argparse.ArgumentTypeError(msg) from None
    if not math.isfinite(value):
        msg = f'expected a finite number, got {text!r}'
        raise argparse.ArgumentTypeError(msg)
    return value


def positive_int(text: str) -> int:
    """Parse a whole number of at least 1, or tell argparse why not."""
    try:
        value = int(text)
    except ValueError:
        msg = f'expected a positive integer, got {text!r}'
        raise argparse.ArgumentTypeError(msg) from None
    if value < 1:
        msg = f'expected a positive integer, got {text!r}'
        raise argparse.ArgumentTypeError(msg)
    return value


def run_tool(add_parser: Callable[[Any], argparse.ArgumentParser],
             argv: Sequence[str] | None = None) -> int:
    """Parse ``argv`` (default ``sys.argv[1:]``) with one tool's parser and run its handler.

    This is every tool's ``main``: the tool runs the same whether it is
    called as ``python -m mech_kinematics NAME``, as the console script
    ``NAME`` (``ros2 run mech_kinematics NAME``) or from Python.
    """
    root = argparse.ArgumentParser(prog=PROG)
    parser = add_parser(root.add_subparsers(dest='command', required=True))
    args = parser.parse_args(sys.argv[1:] if argv is None else list(argv))
    return int(args.handler(args) or 0)
