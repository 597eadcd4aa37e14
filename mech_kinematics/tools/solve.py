# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``python -m mech_kinematics solve``: one instant of a scene as JSON."""

from __future__ import annotations

import argparse
from collections.abc import Iterator, Sequence
from dataclasses import replace
import json
import math
import sys
from typing import Any
import warnings

from .cli import (add_branch_argument, add_driver_arguments, add_gravity_argument,
                  add_robot_arguments, add_scene_argument, add_units_argument, angle_unit,
                  angular_rate_given, branches_of, drive_from_args, finite_float, gravity_of,
                  is_urdf, link_loads_of, load_robot_argument, mimic_ruled, named_value,
                  positive_float, robot_angle_given, run_tool, targets_in_si,
                  values_by_driver)
from ..bounds import MAX_ERROR
from ..errors import AssemblyError, NearSingularWarning, SceneError, UntrustedError
from ..scene import load_scene
from ..solver import assembly_text, solve
from ..units import turns_from_degrees

__all__ = ['add_parser', 'main', 'turns_from_degrees']

SOLVE_HELP = """\
Solve a scene at one crank instant and print one JSON object: the input
(angle rad, speed rad/s, accel rad/s^2), every output joint (type, position,
velocity, acceleration: rad for revolute joints, m for sliders), every
output point (position, velocity, acceleration as [x, y]), "rubbing" (the
rubbing velocity at each of the scene's pins, m/s), "intermittent" (each
Geneva wheel: engaged or locked, its engagement window and where its
acceleration jumps), "imus" (each of the scene's inertial sensors: angular
velocity rad/s, linear acceleration [x, y] m/s^2 in the sensor's frame,
orientation rad) and "error_bound", the absolute error bound of each of
those values (one number per value; for a point or an acceleration, the
bound on the length of its error vector), all in SI units.
A scene with several drivers (inputs:) is driven with --input, --speed and
--accel NAME=VALUE, one per driver named (a crank's link or an actuator):
VALUE in degrees, rpm and rad/s^2 for a crank; in the scene's length unit,
m/s and m/s^2 for an actuator. Its JSON has "inputs": {NAME: {"position",
"speed", "accel"}} (rad, rad/s, rad/s^2 or m, m/s, m/s^2) instead of "input".
Options left out take the scene's own values. On a position that cannot be
solved, or whose answer cannot be trusted (a value's error bound above
--max-error times its kind's scale, a dyad within rounding of an assembly
limit, a value beyond the range of doubles, anywhere in the JSON: an IMU's
reading too), it prints a one-line error and exits with status 2.
A robot described in URDF (SCENE a path ending in .urdf, with --closures,
--actuated and --reference) is driven by its actuated joints, named as in
the URDF: --input J=VALUE in degrees (revolute) or m (prismatic), --speed
J=VALUE in rpm or m/s (with --units si: rad and rad/s, for a scene's drivers
too), --accel J=VALUE in rad/s^2 or m/s^2, each from the joint's zero and
positive about its axis as written. Its JSON has "robot",
"inputs" and "joints" keyed by URDF joint names (every joint of every loop,
the actuated ones and the mimic joints that follow them), the loops'
"points" in their plane, "mimic" (every joint whose value strays from its
<mimic> rule: a loop's joint, an actuated one) and "limits" (a joint outside
its <limit>, reported, not refused). A revolute joint given beyond a turn
is reduced exactly, as a scene's crank angle is.
Where the URDF's links carry <inertial>: "gravity" (m/s^2 in the root frame,
--gravity GX,GY,GZ, default 0,0,-9.80665) and "efforts": each actuated joint
that drives a loop (a mimic follower's load on its leader), N m or N,
positive along its <axis> (sum of effort x velocity is the power put in),
the forces of the motion given (static with no --speed and --accel; with
the forces and torques on links of --link-force and --link-torque, listed
under "link_loads"), their bounds under "error_bound"."efforts";
"reactions": each revolute joint and pin of every loop, the load its
parent puts on its child at its origin in
the child link's frame (the force in the loop's plane, N; the actuator's
torque about its axis, N m); or "forces_left_out" saying why not
(docs/urdf.md, "Forces").
Driven from the output (docs/targets.md): --target NAME=VALUE, as many as
the scene has drivers, each a joint it reports (degrees or its length unit)
or a point's POINT.x or POINT.y (its length unit), with --target-speed,
--target-accel and --target-force NAME=F; the answer is continued from the
start pose (or --input). The JSON adds "targets" (given and reached),
"jacobian" (d target / d driver and its inverse), "continued_from",
"target_efforts" (J^T F) and, under "error_bound", "targets" and "inverse".
"""


def _robot_drive(robot: Any, args: argparse.Namespace) -> tuple[
        dict[str, float], dict[str, float], dict[str, float], str, dict[str, float]]:
    """Return a robot's actuated joints' values (SI) from --input, --speed and --accel J=V.

    And, last, the revolute joints given beyond a turn, each reduced exactly
    to its direction in rad, as a scene's crank (``turns_from_degrees``):
    ``--input J=1e17`` turns the loops as ``J=-80`` does, to the bit, where
    ``math.radians(1e17)`` is a double of 1.7e15 rad whose direction is lost.
    A joint a ``<mimic>`` rule involves is taken as given (:func:`mimic_ruled`).
    """
    from types import SimpleNamespace

    names = SimpleNamespace(drivers=[SimpleNamespace(name=n) for n in robot.actuated])
    inputs = values_by_driver(names, '--input', args.input)
    speeds = values_by_driver(names, '--speed', args.speed)
    accels = values_by_driver(names, '--accel', args.accel)
    for flag, value, key, table in (('--angle-deg', args.angle_deg, '--input', inputs),
                                    ('--speed-rpm', args.speed_rpm, '--speed', speeds)):
        if value is None:
            continue
        single = len(robot.actuated) == 1 and robot.joint_type(robot.actuated[0]).angular
        if not single or robot.actuated[0] in table:
            msg = (f'Expected {key} J=VALUE for the actuated joints of {robot.name} '
                   f'({", ".join(robot.actuated)}), got {flag}')
            raise ValueError(msg)
        table[robot.actuated[0]] = value
    positions, rates, words, exact = {}, {}, [], {}
    ruled = mimic_ruled(robot.description)
    for name in robot.actuated:
        angular = robot.joint_type(name).angular
        if name in inputs:
            given = inputs[name]
            positions[name], direction = robot_angle_given(given, args, name in ruled) \
                if angular else (given, None)
            if direction is not None:
                exact[name] = direction
            words.append(f'{name} = {given:.15g} {angle_unit(args) if angular else "m"}')
        if name in speeds:
            rates[name] = angular_rate_given(speeds[name], args) if angular else speeds[name]
    shown = ', '.join(words) or 'the reference pose'
    return positions, rates, accels, shown, exact


def _handle_robot(args: argparse.Namespace) -> int:
    """Solve a robot described in URDF: its joints under their URDF names."""
    try:
        gravity = gravity_of(args)
        loads = link_loads_of(args)
        robot = load_robot_argument(args)
        if gravity is not None and robot.forces is None:
            msg = (f'--gravity: Expected a robot whose links carry <inertial> (their masses), '
                   f'got none in {args.scene}: gravity would move nothing')
            raise ValueError(msg)
        if loads and robot.forces is None:
            msg = (f'--link-force: Expected a robot whose links carry <inertial> (its forces '
                   f'are solved with its masses), got none in {args.scene}')
            raise ValueError(msg)
        if loads:
            robot.forces.check_loads(loads)
        positions, speeds, accels, shown, exact = _robot_drive(robot, args)
    except (SceneError, ValueError) as error:
        print(f'error: {error}', file=sys.stderr)
        return 2
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter('always', NearSingularWarning)
            answer = robot.solve({**positions, **exact}, speeds, accels,
                                 max_error=args.max_error, gravity=gravity, loads=loads)
        if exact:  # the loops at the exact direction; the joints echoed as given
            echoed = robot.joints_from_state(answer.state, {
                name: (positions.get(name, motion.position), motion.velocity,
                       motion.acceleration) for name, motion in answer.inputs.items()})
            answer = replace(answer, inputs=echoed.inputs, joints=echoed.joints,
                             bounds=echoed.bounds, mimic=echoed.mimic, limits=echoed.limits)
    except AssemblyError as error:
        reason = error.reason if isinstance(error, UntrustedError) or error.facts is None \
            else assembly_text(error, robot.scene.units)
        print(f'error: {error.dyad} cannot be solved at {shown}: {reason}', file=sys.stderr)
        return 2
    for warning in caught:
        print(f'warning: {warning.message}', file=sys.stderr)
    return _print_result(answer.as_dict(), answer.state, args, f' at {shown}')


_TARGET_FLAGS = ('--target', '--target-speed', '--target-accel', '--target-force')


def _targets_given(args: argparse.Namespace) -> bool:
    return any(getattr(args, flag[2:].replace('-', '_')) for flag in (*_TARGET_FLAGS, '--branch'))


def _target_tables(args: argparse.Namespace) -> dict[str, dict[str, float]]:
    """Return ``--target`` and its companions as given: flag -> {target: value}.

    Raises ValueError for ``--speed``, ``--accel``, ``--angle-deg`` or
    ``--speed-rpm`` beside them, a value without a name, or a companion for a
    target not given with ``--target``.
    """
    if args.speed or args.accel or args.angle_deg is not None or args.speed_rpm is not None:
        msg = ("Expected --target-speed and --target-accel with --target (the drivers' "
               "rates follow from the targets'), got --speed, --accel, --angle-deg or "
               '--speed-rpm')
        raise ValueError(msg)
    branches_of(args)       # --branch alone is refused before the targets are counted
    given: dict[str, dict[str, float]] = {}
    for flag in _TARGET_FLAGS:
        table = given.setdefault(flag, {})
        for name, value in getattr(args, flag[2:].replace('-', '_')) or ():
            if name is None:
                msg = (f'Expected {flag} NAME=VALUE (a joint, POINT.x|y or, for a URDF, '
                       f'FRAME.x|y|z), got {value:g}')
                raise ValueError(msg)
            table[name] = value
    names = tuple(given['--target'])
    for flag in _TARGET_FLAGS[1:]:
        stray = [name for name in given[flag] if name not in names]
        if stray:
            msg = (f'Expected {flag} for targets given with --target '
                   f'({", ".join(names) or "none"}), got {", ".join(stray)}')
            raise ValueError(msg)
    return given


def _print_inverse(inverse: Any, state: Any, args: argparse.Namespace) -> int:
    """Print the answer of an inverse solve: the forward answer's JSON and the inverse's."""
    result: dict[str, Any] = {**inverse.answer.as_dict(), **inverse.as_dict()}
    result['error_bound'] = {**result['error_bound'], **inverse.bound_dict()}
    return _print_result(result, state, args)


def _print_result(result: dict[str, Any], state: Any, args: argparse.Namespace,
                  where: str = '') -> int:
    """Print ``result`` as JSON (with ``--diagnostics``, ``state``'s measures); 2 if not finite."""
    if args.diagnostics:
        result['singularity'] = {key: float(m) for key, m in state.singularity.items()}
        result['relative_error_bound'] = float(state.relative_error_bound)
    path, value = next(_not_finite(result), ('', 0.0))
    if path:
        print(f'error: Expected every value of the state{where} to be finite, got {path} = '
              f'{value!r} (beyond the range of doubles)', file=sys.stderr)
        return 2
    print(json.dumps(result, indent=args.indent, allow_nan=False))
    return 0


def _handle_targets(scene: Any, args: argparse.Namespace) -> int:
    """Solve a scene driven from its targets (``--target NAME=VALUE``): docs/targets.md."""
    from ..errors import TargetError
    from ..solver.inverse import continue_to, scene_targets
    from ..units import LENGTH_UNITS

    try:
        given = _target_tables(args)
        tmap = scene_targets(scene, tuple(given['--target']))
        start, _, _, turns, _ = drive_from_args(scene, args)
        starts = [start] if len(scene.drivers) == 1 else list(start)
        whole = [turns] if len(scene.drivers) == 1 else list(turns)
        first = [d.start if x is None else x + math.tau * int(w)
                 for d, x, w in zip(scene.drivers, starts, whole, strict=True)]
        per_metre = 1.0 if args.units == 'si' else LENGTH_UNITS[scene.units.length]
        goal, speeds, accels = targets_in_si(given, tmap.target_angular, args, per_metre)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter('always', NearSingularWarning)
            inverse = continue_to(tmap, goal, first, speeds, accels, max_error=args.max_error,
                                  forces=given['--target-force'], branch=branches_of(args))
    except (TargetError, ValueError) as error:
        print(f'error: {error}', file=sys.stderr)
        return 2
    for warning in caught:
        print(f'warning: {warning.message}', file=sys.stderr)
    return _print_inverse(inverse, inverse.answer, args)


def _handle_robot_targets(args: argparse.Namespace) -> int:
    """Solve a URDF robot driven from its targets (joints, ``FRAME.x|y|z``): docs/targets.md."""
    from ..errors import TargetError
    from ..robot.targets import robot_targets

    try:
        given = _target_tables(args)
        gravity = gravity_of(args)
        loads = link_loads_of(args)
        robot = load_robot_argument(args)
        if (gravity is not None or loads) and robot.forces is None:
            msg = (f'--gravity, --link-force: Expected a robot whose links carry <inertial> '
                   f'(their masses), got none in {args.scene}')
            raise ValueError(msg)
        if loads:
            robot.forces.check_loads(loads)
        positions, _, _, _, _ = _robot_drive(robot, args)
        tmap = robot_targets(robot, tuple(given['--target']))
        goal, speeds, accels = targets_in_si(given, tmap.target_angular, args, 1.0)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter('always', NearSingularWarning)
            inverse = robot.solve_targets(
                dict(zip(tmap.targets, goal, strict=True)),
                dict(zip(tmap.targets, speeds, strict=True)),
                dict(zip(tmap.targets, accels, strict=True)), start=positions,
                max_error=args.max_error, forces=given['--target-force'], gravity=gravity,
                loads=loads, branch=branches_of(args))
    except (SceneError, TargetError, ValueError) as error:
        print(f'error: {error}', file=sys.stderr)
        return 2
    for warning in caught:
        print(f'warning: {warning.message}', file=sys.stderr)
    return _print_inverse(inverse, inverse.answer.state, args)


def _handle(args: argparse.Namespace) -> int:
    if is_urdf(args.scene):
        if _targets_given(args):
            return _handle_robot_targets(args)
        return _handle_robot(args)
    try:
        if args.closures or args.actuated or args.reference or args.gravity is not None \
                or args.payload or args.link_force or args.link_torque:
            msg = (f'Expected --closures, --actuated, --reference, --gravity, --payload, '
                   f'--link-force and --link-torque with a robot described in URDF (a path '
                   f"ending in .urdf; a scene's gravity, masses and loads are its gravity:, "
                   f'masses: and loads: keys), got scene {args.scene}')
            raise SceneError(msg)
        scene = load_scene(args.scene)
    except SceneError as error:
        print(f'error: {error}', file=sys.stderr)
        return 2
    if _targets_given(args):
        return _handle_targets(scene, args)
    try:
        angle, speed, accel, turns, shown = drive_from_args(scene, args)
    except ValueError as error:
        print(f'error: {error}', file=sys.stderr)
        return 2
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter('always', NearSingularWarning)
            state = solve(scene, angle, speed, accel, turns=turns, max_error=args.max_error)
    except AssemblyError as error:
        reason = error.reason if isinstance(error, UntrustedError) or error.facts is None \
            else assembly_text(error, scene.units)
        print(f'error: {error.dyad} cannot be solved at {shown}: {reason}', file=sys.stderr)
        return 2
    except ValueError as error:
        print(f'error: {error}', file=sys.stderr)
        return 2
    for warning in caught:  # one line each, without Python's source line
        if issubclass(warning.category, NearSingularWarning):
            print(f'warning: {warning.message}', file=sys.stderr)
        else:
            warnings.warn_explicit(warning.message, warning.category, warning.filename,
                                   warning.lineno)
    return _print_result(state.as_dict(), state, args, f' at {shown}')


def _not_finite(value: Any, path: str = '') -> Iterator[tuple[str, float]]:
    """Yield (path, value) of every number of the JSON ``value`` that is not finite."""
    if isinstance(value, dict):
        for key, item in value.items():
            yield from _not_finite(item, f'{path}.{key}' if path else str(key))
    elif isinstance(value, (list, tuple)):
        for index, item in enumerate(value):
            yield from _not_finite(item, f'{path}[{index}]')
    elif isinstance(value, float) and not math.isfinite(value):
        yield path, value


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register the ``solve`` command on ``subparsers``; return its parser."""
    parser: argparse.ArgumentParser = subparsers.add_parser(
        'solve', help='solve a scene at one instant, print JSON', description=SOLVE_HELP,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    add_scene_argument(parser)
    parser.add_argument('--angle-deg', type=finite_float, metavar='X',
                        help='crank angle in degrees CCW from +x, counted from the start: 450 '
                             'is a quarter turn into the second turn (it matters for an '
                             "intermittent drive; default: the scene's)")
    parser.add_argument('--speed-rpm', type=finite_float, metavar='N',
                        help="signed crank speed in rpm, + CCW (default: the scene's)")
    add_driver_arguments(parser)
    add_units_argument(parser)
    add_robot_arguments(parser)
    add_gravity_argument(parser)
    parser.add_argument('--max-error', type=positive_float, default=MAX_ERROR, metavar='REL',
                        help="refuse (exit 2) where a value's error bound exceeds REL times "
                             "its kind's scale (the mechanism's size, its largest speed, its "
                             f'largest acceleration, ...; default {MAX_ERROR:g}; inf accepts '
                             'every finite answer)')
    parser.add_argument('--diagnostics', action='store_true',
                        help="also print each dyad's near-singularity measure "
                             '("singularity": 0 singular, 1 best) and the largest error '
                             'bound over its scale ("relative_error_bound")')
    parser.add_argument('--target', type=named_value, action='append', metavar='NAME=VALUE',
                        help='drive the scene from its output (docs/targets.md): a joint it '
                             'reports (degrees, or the length unit; rad and m with --units si) '
                             "or a point's coordinate POINT.x, POINT.y (the length unit), as "
                             'many as it has drivers; for a URDF, a joint it answers (degrees '
                             "or m) or a link frame origin's coordinate in the root frame "
                             'FRAME.x, FRAME.y, FRAME.z (m), as many as it has actuated joints; '
                             '--input gives the pose to continue from')
    parser.add_argument('--target-speed', type=named_value, action='append',
                        metavar='NAME=V', help="a target's speed: rpm for an angle (rad/s with "
                                               '--units si), m/s for a length (default 0)')
    parser.add_argument('--target-accel', type=named_value, action='append',
                        metavar='NAME=A', help="a target's acceleration: rad/s^2 or m/s^2 "
                                               '(default 0)')
    parser.add_argument('--target-force', type=named_value, action='append',
                        metavar='NAME=F', help='a force (N) or torque (N m, an angle) the '
                                               "mechanism exerts along a target: the drivers' "
                                               'share, J^T F, under "target_efforts"')
    add_branch_argument(parser)
    parser.add_argument('--indent', type=int, default=1, metavar='N',
                        help='JSON indentation (default 1)')
    parser.set_defaults(handler=_handle)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``solve``; return the exit status."""
    return run_tool(add_parser, argv)


if __name__ == '__main__':
    sys.exit(main())
