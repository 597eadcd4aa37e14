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

:func:`run_handler` is the one place that turns a failure into what a
person reads: an error of this package is one line (``error: ...``, exit 2),
a file that cannot be read or written is one line naming it (exit 2), a
broken pipe (``solve ... | head``) exits quietly, Ctrl-C exits 130, running
out of memory is one line saying to ask for less (exit 2), and an
unexpected exception is one line too (never empty, never several), with its traceback only when
``MECH_KINEMATICS_TRACEBACK=1`` is set.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence
import math
import os
import re
import sys
import traceback
from typing import Any

from ..errors import MechKinematicsError

__all__ = ['ArgumentParser', 'PROG', 'add_scene_argument', 'finite_float', 'positive_float',
           'positive_int', 'positive_seconds', 'run_handler', 'run_tool', 'seconds_or_zero']

#: The program name shown in usage lines.
PROG = 'python -m mech_kinematics'
#: Exit status of a command whose output pipe was closed (128 + SIGPIPE), as `yes | head`.
BROKEN_PIPE_STATUS = 141
#: Set this environment variable to 1 to see the traceback of an unexpected error.
TRACEBACK_VARIABLE = 'MECH_KINEMATICS_TRACEBACK'


class ArgumentParser(argparse.ArgumentParser):
    """An ``argparse.ArgumentParser`` that reads ``-1e3`` as a number, not as an option.

    argparse takes an argument that starts with ``-`` for an option unless it
    looks like ``-1`` or ``-1.5``: ``--speed-rpm -1e3`` failed with "expected
    one argument" (issue 12). No option of ours looks like a number, so every
    float literal is a value. Subcommand parsers inherit the class.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(
            r'^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|infinity|nan)$', re.IGNORECASE)


def add_scene_argument(parser: argparse.ArgumentParser) -> None:
    """Add the positional ``SCENE`` every scene command takes: a path or a packaged name."""
    parser.add_argument('scene', metavar='SCENE',
                        help='path to a scene YAML, or the name of a packaged scene '
                             '(e.g. khurmi_four_bar_ad150)')


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


def _number(text: str, ok: Callable[[float], bool], expected: str) -> float:
    """Parse a number that ``ok`` accepts, or tell argparse ``expected ..., got TEXT``."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not ok(value):
        msg = f'expected {expected}, got {text!r}'
        raise argparse.ArgumentTypeError(msg)
    return value


def positive_float(text: str) -> float:
    """Parse a number above 0 (``inf`` allowed: no bound), or tell argparse why not."""
    return _number(text, lambda value: value > 0.0, 'a positive number')


def positive_seconds(text: str) -> float:
    """Parse a finite number of seconds above 0, or tell argparse why not."""
    return _number(text, lambda value: math.isfinite(value) and value > 0.0,
                   'a positive number of seconds')


def seconds_or_zero(text: str) -> float:
    """Parse a finite number of seconds, 0 or more, or tell argparse why not."""
    return _number(text, lambda value: math.isfinite(value) and value >= 0.0,
                   'a number of seconds >= 0')


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


def run_handler(args: argparse.Namespace) -> int:
    """Run ``args.handler(args)``; return its exit status, turning failures into one line."""
    try:
        status = int(args.handler(args) or 0)
        sys.stdout.flush()
    except BrokenPipeError:
        # The reader went away (`solve ... | head`): nothing more to say, to anyone.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return BROKEN_PIPE_STATUS
    except KeyboardInterrupt:
        return 130
    except MechKinematicsError as error:
        print(f'error: {error}', file=sys.stderr)
        return 2
    except OSError as error:    # a file that cannot be read or written: name it
        where = f'{error.filename}: ' if error.filename else ''
        print(f'error: {where}{error.strerror or error}', file=sys.stderr)
        return 2
    except MemoryError:
        print('error: Expected a request that fits in memory, got one that does not; ask for '
              'less (fewer samples, a smaller indent or scene)', file=sys.stderr)
        return 2
    except Exception as error:  # noqa: BLE001 - the last resort: one line, not a traceback
        if os.environ.get(TRACEBACK_VARIABLE) == '1':
            traceback.print_exc()
        text = ' '.join(str(error).split())     # one line, and never an empty one
        what = f'{type(error).__name__}: {text}' if text else type(error).__name__
        print(f'error: unexpected {what} (set {TRACEBACK_VARIABLE}=1 for the traceback)',
              file=sys.stderr)
        return 1
    return status


def run_tool(add_parser: Callable[[Any], argparse.ArgumentParser],
             argv: Sequence[str] | None = None) -> int:
    """Parse ``argv`` (default ``sys.argv[1:]``) with one tool's parser and run its handler.

    This is every tool's ``main``: the tool runs the same whether it is
    called as ``python -m mech_kinematics NAME``, as the console script
    ``NAME`` (``ros2 run mech_kinematics NAME``) or from Python.
    """
    root = ArgumentParser(prog=PROG)
    parser = add_parser(root.add_subparsers(dest='command', required=True))
    return run_handler(parser.parse_args(sys.argv[1:] if argv is None else list(argv)))
