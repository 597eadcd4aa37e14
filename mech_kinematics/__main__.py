# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Command line: ``python -m mech_kinematics {solve,bench,run,...}``."""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any

from .cli import finite_float

SOLVE_HELP = """\
Solve a scene at one crank instant and print one JSON object: the input
(angle rad, speed rad/s, accel rad/s^2), every output joint (type, position,
velocity, acceleration: rad for revolute joints, m for sliders) and every
output point (position, velocity, acceleration as [x, y]), all in SI units.
Options left out take the scene's own values. On a position that cannot be
solved it prints a one-line error and exits with status 2.
"""


def _solve(args: argparse.Namespace) -> int:
    from .errors import AssemblyError, SceneError
    from .linkage import solve
    from .scene import load_scene

    try:
        scene = load_scene(args.scene)
    except SceneError as error:
        print(f'error: {error}', file=sys.stderr)
        return 2
    angle = scene.input.angle if args.angle_deg is None else math.radians(args.angle_deg)
    speed = None if args.speed_rpm is None else args.speed_rpm * math.pi / 30.0
    try:
        state = solve(scene, angle, speed, args.accel)
    except (AssemblyError, ValueError) as error:
        print(f'error: {error}', file=sys.stderr)
        return 2
    result: dict[str, Any] = state.as_dict()
    if args.diagnostics:
        result['singularity'] = {key: float(m) for key, m in state.singularity.items()}
    print(json.dumps(result, indent=args.indent))
    return 0


def build_parser() -> argparse.ArgumentParser:
    """Return the parser of ``python -m mech_kinematics``."""
    parser = argparse.ArgumentParser(
        prog='python -m mech_kinematics',
        description='Analytic kinematics of planar linkages (mech_kinematics).')
    commands = parser.add_subparsers(dest='command', required=True, metavar='COMMAND')

    solve = commands.add_parser('solve', help='solve a scene at one instant, print JSON',
                                description=SOLVE_HELP,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    solve.add_argument('scene', metavar='SCENE',
                       help='path to a scene YAML, or the name of a packaged scene '
                            '(e.g. khurmi_four_bar_ad150)')
    solve.add_argument('--angle-deg', type=finite_float, metavar='X',
                       help="crank angle in degrees CCW from +x (default: the scene's)")
    solve.add_argument('--speed-rpm', type=finite_float, metavar='N',
                       help="signed crank speed in rpm, + CCW (default: the scene's)")
    solve.add_argument('--accel', type=finite_float, metavar='A',
                       help="crank angular acceleration in rad/s^2, + CCW (default: the scene's)")
    solve.add_argument('--diagnostics', action='store_true',
                       help="also print each dyad's near-singularity measure "
                            '("singularity": 0 singular, 1 best)')
    solve.add_argument('--indent', type=int, default=1, metavar='N',
                       help='JSON indentation (default 1)')
    solve.set_defaults(handler=_solve)

    bench = commands.add_parser('bench', help='time the solver on every packaged scene')
    bench.add_argument('--angles', type=int, default=100_000,
                       help='angles in the array path (default 1e5)')
    bench.add_argument('--repeat', type=int, default=7, help='repeats for medians')
    bench.set_defaults(handler=lambda args: _module('bench').main(args))

    run = commands.add_parser(
        'run', help='start the node with a live console view (make run); Ctrl-C stops both',
        description='Start kinematics_node and a live console view of what it publishes. '
                    'Arguments after `run` go to the node, e.g. '
                    '`run --ros-args -p scene:=quick_return -p rate_hz:=200.0`.')
    run.set_defaults(handler=lambda args: _module('live').main(args.rest))
    run.add_argument('rest', nargs=argparse.REMAINDER, metavar='NODE_ARGS',
                     help='arguments for the node (--ros-args ...)')
    _module('diagram').add_parser(commands)
    _module('report').add_parser(commands)
    _module('bag_recorder').add_parser(commands)
    _module('plot').add_parser(commands)
    return parser


def _module(name: str) -> Any:
    import importlib
    return importlib.import_module(f'mech_kinematics.{name}')


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit status."""
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ['run'] and argv[1:2] != ['-h'] and argv[1:2] != ['--help']:
        # Everything after `run` goes to the node untouched (`--ros-args -p ...`),
        # which argparse's REMAINDER refuses when it starts with a dash.
        return int(_module('live').main(argv[1:]) or 0)
    args = build_parser().parse_args(argv)
    return int(args.handler(args) or 0)


if __name__ == '__main__':
    sys.exit(main())
