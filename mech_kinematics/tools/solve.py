# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``python -m mech_kinematics solve``: one instant of a scene as JSON."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
import json
import sys
from typing import Any
import warnings

from .cli import add_scene_argument, finite_float, positive_float, run_tool
from ..bounds import MAX_ERROR
from ..errors import AssemblyError, NearSingularWarning, SceneError, UntrustedError
from ..scene import load_scene
from ..solver import assembly_text, solve
from ..units import LENGTH_UNITS, rad_per_s_from_rpm, turns_from_degrees

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
limit, a value beyond the range of doubles), it prints a one-line error and
exits with status 2.
"""


def named_value(text: str) -> tuple[str | None, float]:
    """Parse ``NAME=VALUE`` (a driver's value) or a plain number, or tell argparse why not."""
    name, sep, value = text.rpartition('=')
    if not sep:
        return None, finite_float(text)
    if not name:
        msg = f'expected NAME=VALUE (a driver of the scene and a number), got {text!r}'
        raise argparse.ArgumentTypeError(msg)
    return name, finite_float(value)


def _by_driver(scene: Any, flag: str, given: list[tuple[str | None, float]] | None
               ) -> dict[str, float]:
    """Return ``{driver: value}`` of a repeatable ``--flag NAME=VALUE``; refuse unknown names."""
    names = [driver.name for driver in scene.drivers]
    out: dict[str, float] = {}
    for name, value in given or ():
        if name is None:
            if len(names) > 1:
                msg = (f'Expected {flag} NAME=VALUE with NAME one of the drivers '
                       f'({", ".join(names)}), got {flag} {value:g}')
                raise ValueError(msg)
            name = names[0]
        if name not in names:
            msg = (f'Expected {flag} NAME=VALUE with NAME one of the drivers '
                   f'({", ".join(names)}), got {name!r}')
            raise ValueError(msg)
        out[name] = value
    return out


def _drive(scene: Any, args: argparse.Namespace) -> tuple[Any, Any, Any, Any, str]:
    """Return solve's (positions, speeds, accels, turns) and the text of where it stands."""
    inputs = _by_driver(scene, '--input', args.input)
    speeds = _by_driver(scene, '--speed', args.speed)
    accels = _by_driver(scene, '--accel', args.accel)
    drivers = scene.drivers
    single = scene.input is not None and len(drivers) == 1
    if single:
        crank = drivers[0]
        if crank.name in inputs and args.angle_deg is not None:
            msg = f'Expected --angle-deg or --input {crank.name}=DEG, got both'
            raise ValueError(msg)
        if crank.name in speeds and args.speed_rpm is not None:
            msg = f'Expected --speed-rpm or --speed {crank.name}=RPM, got both'
            raise ValueError(msg)
        degrees = inputs.get(crank.name, args.angle_deg)
        rpm = speeds.get(crank.name, args.speed_rpm)
        if degrees is None:
            angle, turns = crank.angle, crank.turns
            shown = f'crank angle {scene.units.angle_text(crank.shown)}'
        else:
            angle, turns = turns_from_degrees(degrees)
            shown = f'crank angle {degrees:.15g} deg'
        speed = None if rpm is None else rad_per_s_from_rpm(rpm)
        return angle, speed, accels.get(crank.name), turns, shown
    for flag, used in (('--angle-deg', args.angle_deg), ('--speed-rpm', args.speed_rpm)):
        if used is not None:
            msg = (f'Expected --input, --speed and --accel NAME=VALUE for a scene with several '
                   f'drivers ({", ".join(d.name for d in drivers)}), got {flag}')
            raise ValueError(msg)
    per_metre = LENGTH_UNITS[scene.units.length]
    positions: list[Any] = []
    rates: list[Any] = []
    turns_list: list[int] = []
    words = []
    for driver in drivers:
        revolute = driver.joint_type == 'revolute'
        given = inputs.get(driver.name)
        whole = 0
        if given is None:
            position = driver.start
            text = driver.position_text(driver.start, scene.units)
        elif revolute:
            position, whole = turns_from_degrees(given)
            text = f'{given:.15g} deg'
        else:
            position = given / per_metre
            text = f'{given:.15g} {scene.units.length}'
        speed = speeds.get(driver.name)
        if speed is not None and revolute:
            speed = rad_per_s_from_rpm(speed)
        positions.append(position)
        rates.append(speed)
        turns_list.append(whole)
        words.append(f'{driver.name} = {text}')
    accel_list = [accels.get(driver.name) for driver in drivers]
    return positions, rates, accel_list, turns_list, ', '.join(words)


def _handle(args: argparse.Namespace) -> int:
    try:
        scene = load_scene(args.scene)
    except SceneError as error:
        print(f'error: {error}', file=sys.stderr)
        return 2
    try:
        angle, speed, accel, turns, shown = _drive(scene, args)
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
    result: dict[str, Any] = state.as_dict()
    if args.diagnostics:
        result['singularity'] = {key: float(m) for key, m in state.singularity.items()}
        result['relative_error_bound'] = float(state.relative_error_bound)
    print(json.dumps(result, indent=args.indent, allow_nan=False))
    return 0


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
    parser.add_argument('--accel', type=named_value, action='append', metavar='[NAME=]A',
                        help='crank angular acceleration in rad/s^2, + CCW; with several '
                             'drivers, NAME=A per driver: rad/s^2 for a crank, m/s^2 for an '
                             "actuator (repeatable; default: the scene's)")
    parser.add_argument('--input', type=named_value, action='append', metavar='NAME=VALUE',
                        help="a driver's position: a crank's angle in degrees (counted from "
                             "the start), an actuator's length in the scene's length unit "
                             "(repeatable, one per driver; default: the scene's)")
    parser.add_argument('--speed', type=named_value, action='append', metavar='NAME=VALUE',
                        help="a driver's speed: rpm for a crank (as --speed-rpm), m/s for an "
                             "actuator's extension rate (repeatable; default: the scene's)")
    parser.add_argument('--max-error', type=positive_float, default=MAX_ERROR, metavar='REL',
                        help="refuse (exit 2) where a value's error bound exceeds REL times "
                             "its kind's scale (the mechanism's size, its largest speed, its "
                             f'largest acceleration, ...; default {MAX_ERROR:g}; inf accepts '
                             'every finite answer)')
    parser.add_argument('--diagnostics', action='store_true',
                        help="also print each dyad's near-singularity measure "
                             '("singularity": 0 singular, 1 best) and the largest error '
                             'bound over its scale ("relative_error_bound")')
    parser.add_argument('--indent', type=int, default=1, metavar='N',
                        help='JSON indentation (default 1)')
    parser.set_defaults(handler=_handle)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``solve``; return the exit status."""
    return run_tool(add_parser, argv)


if __name__ == '__main__':
    sys.exit(main())
