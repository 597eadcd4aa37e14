# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``python -m mech_kinematics solve``: one instant of a scene as JSON."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
import json
import sys
from typing import Any

from ..cli import finite_float, run_tool
from ..errors import AssemblyError, SceneError
from ..linkage import solve
from ..scene import load_scene
from ..units import rad_per_s_from_rpm, radians_from_degrees

__all__ = ['add_parser', 'main']

SOLVE_HELP = """\
Solve a scene at one crank instant and print one JSON object: the input
(angle rad, speed rad/s, accel rad/s^2), every output joint (type, position,
velocity, acceleration: rad for revolute joints, m for sliders) and every
output point (position, velocity, acceleration as [x, y]), all in SI units.
Options left out take the scene's own values. On a position that cannot be
solved it prints a one-line error and exits with status 2.
"""


def _handle(args: argparse.Namespace) -> int:
    try:
        scene = load_scene(args.scene)
    except SceneError as error:
        print(f'error: {error}', file=sys.stderr)
        return 2
    angle = scene.input.angle if args.angle_deg is None else radians_from_degrees(args.angle_deg)
    speed = None if args.speed_rpm is None else rad_per_s_from_rpm(args.speed_rpm)
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


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register the ``solve`` command on ``subparsers``; return its parser."""
    parser: argparse.ArgumentParser = subparsers.add_parser(
        'solve', help='solve a scene at one instant, print JSON', description=SOLVE_HELP,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('scene', metavar='SCENE',
                        help='path to a scene YAML, or the name of a packaged scene '
                             '(e.g. khurmi_four_bar_ad150)')
    parser.add_argument('--angle-deg', type=finite_float, metavar='X',
                        help="crank angle in degrees CCW from +x (default: the scene's)")
    parser.add_argument('--speed-rpm', type=finite_float, metavar='N',
                        help="signed crank speed in rpm, + CCW (default: the scene's)")
    parser.add_argument('--accel', type=finite_float, metavar='A',
                        help='crank angular acceleration in rad/s^2, + CCW (default: the '
                             "scene's)")
    parser.add_argument('--diagnostics', action='store_true',
                        help="also print each dyad's near-singularity measure "
                             '("singularity": 0 singular, 1 best)')
    parser.add_argument('--indent', type=int, default=1, metavar='N',
                        help='JSON indentation (default 1)')
    parser.set_defaults(handler=_handle)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``solve``; return the exit status."""
    return run_tool(add_parser, argv)


if __name__ == '__main__':
    sys.exit(main())
