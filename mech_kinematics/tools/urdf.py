# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``python -m mech_kinematics urdf SCENE``: the URDF the node publishes on ``robot_description``.

Writes :func:`mech_kinematics.geometry.urdf.urdf_from_scene` to standard
output or to ``-o FILE``: one link per frame the node puts on ``/tf`` and
``/tf_static`` (named ``<tf_prefix>/<name>``, under ``frame_id``), for
RViz's RobotModel display or Foxglove's URDF layer when no node publishes
``robot_description`` (e.g. a bag from before it did).
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path
import sys
from typing import Any

from .cli import add_scene_argument, run_tool

__all__ = ['add_parser', 'main']

URDF_HELP = """\
Write the URDF of a scene's bodies on the frames kinematics_node puts on /tf:
the root link FRAME_ID, a fixed link at every ground point and a floating
link per moving link or slider (posed by /tf), each drawn as bars between
its points, pins and slider blocks, to scale (m). --frame-id and --tf-prefix
must match the node's parameters of the same names.
With --robot it writes the scene as a real robot description instead: a
tree of revolute and prismatic joints from the ground (the drivers' and the
prismatic joints first), each loop closed by a <constraint type="revolute">
element (ros/urdfdom#264) and a <transmission> per driver, its zero pose
the drivers' start; `solve` and `urdf2scene` read it back as the same
mechanism. robot_state_publisher draws it from joint_states in its joint
names (docs/node.md says what publishes those). A Geneva wheel's
intermittent slot has no such form: refused.
"""


def _handle(args: argparse.Namespace) -> int:
    from ..errors import AssemblyError, UntrustedError
    from ..geometry.urdf import urdf_from_scene
    from ..scene import load_scene
    from ..solver import assembly_text

    from ..robot.writer import robot_urdf_from_scene

    scene = load_scene(args.scene)  # a SceneError is one line, exit 2 (cli.run_handler)
    write = robot_urdf_from_scene if args.robot else urdf_from_scene
    try:
        text = write(scene, frame_id=args.frame_id, prefix=args.tf_prefix)
    except AssemblyError as error:  # no pose to draw it in: why, in the scene's units
        crank = scene.input
        where = (f'crank angle {scene.units.angle_text(crank.shown)}, nor at any of a turn'
                 if crank is not None and len(scene.drivers) == 1
                 else "its drivers' start positions")
        reason = error.reason if isinstance(error, UntrustedError) or error.facts is None \
            else assembly_text(error, scene.units)
        print(f'error: {scene.name}: Expected a pose to draw its URDF in, got none: '
              f'{error.dyad} cannot be solved at its {where}: {reason}', file=sys.stderr)
        return 2
    if args.output is None:
        sys.stdout.write(text)
    else:
        Path(args.output).write_text(text, encoding='utf-8')
        print(f'wrote {args.output} ({len(text)} bytes)', file=sys.stderr)
    return 0


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register the ``urdf`` command on ``subparsers``; return its parser."""
    parser: argparse.ArgumentParser = subparsers.add_parser(
        'urdf', help="write the URDF of a scene (the node's robot_description)",
        description=URDF_HELP, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_scene_argument(parser)
    parser.add_argument('-o', '--output', metavar='FILE',
                        help='write to FILE (default: standard output)')
    parser.add_argument('--frame-id', default='mechanism',
                        help="the node's frame_id: the root link (default: %(default)s)")
    parser.add_argument('--tf-prefix', default='',
                        help="the node's tf_prefix (default: '', meaning FRAME_ID)")
    parser.add_argument('--robot', action='store_true',
                        help='write a robot description: a tree of joints, each loop closed by '
                             'a <constraint> (default: the floating links posed by /tf)')
    parser.set_defaults(handler=_handle)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``urdf``; return the exit status."""
    return run_tool(add_parser, argv)


if __name__ == '__main__':
    sys.exit(main())
