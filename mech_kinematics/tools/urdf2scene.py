# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``python -m mech_kinematics urdf2scene ROBOT.urdf``: the scene a robot's planar loops become.

Reads a URDF, its loop closures (``<constraint>`` elements, closing frames,
``--closures loop_closures.yaml``) and its actuated joints, finds its planar
loops and writes the equivalent scene (:mod:`mech_kinematics.robot.planar`):
drivers, dyads and carried points with the URDF's names, in SI units, with a
header saying how each URDF joint follows the scene. ``solve``, ``check``,
``diagram`` and ``plot`` read the URDF itself as well.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path
import sys
from typing import Any

from .cli import add_robot_arguments, add_units_argument, load_robot_argument, run_tool

__all__ = ['add_parser', 'main']

URDF2SCENE_HELP = """\
Write the scene a robot described in URDF becomes: its planar loops (closed
by <constraint>, <loop_joint> or <loop> elements, onshape-to-robot
closing_NAME_1/_2 frames or a closures file given with --closures: a
loop_closures.yaml, a file of <constraint> elements, an Extended-URDF
robot.yaml or a fusion2URDF robot_data.yaml) as drivers (each
actuated revolute joint on a loop's ground a crank, each actuated cylinder
an actuator), dyads (RRR, RRP, RPR, RPP, each on the branch of the URDF's
zero pose or of --reference) and carried points, named after the URDF's
links and joints, in m and rad. A robot that is not planar, whose zero pose
does not close, or whose loops are not chains of our kinds is refused in
one line naming the joint. Masses from <inertial> are not written: this
version of the scene format has no masses.
"""


def _handle(args: argparse.Namespace) -> int:
    from ..robot.forces import reaction_maps
    from ..robot.writer import scene_yaml

    robot = load_robot_argument(args)  # a UrdfError is one line, exit 2 (cli.run_handler)
    reactions = None if robot.forces is None else reaction_maps(robot)
    text = scene_yaml(robot.planar, str(args.scene), reactions)
    if args.output is None:
        sys.stdout.write(text)
    else:
        Path(args.output).write_text(text, encoding='utf-8')
        print(f'wrote {args.output} ({len(robot.scene.dyads)} dyads, '
              f'{len(robot.scene.drivers)} drivers)', file=sys.stderr)
    return 0


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register the ``urdf2scene`` command on ``subparsers``; return its parser."""
    parser: argparse.ArgumentParser = subparsers.add_parser(
        'urdf2scene', help="write the scene of a URDF robot's planar loops",
        description=URDF2SCENE_HELP, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('scene', metavar='ROBOT.urdf', help='the robot description')
    add_robot_arguments(parser)
    add_units_argument(parser, ('--reference',))
    parser.add_argument('-o', '--output', metavar='FILE',
                        help='write to FILE (default: standard output)')
    parser.set_defaults(handler=_handle)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``urdf2scene``; return the exit status."""
    return run_tool(add_parser, argv)


if __name__ == '__main__':
    sys.exit(main())
