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
``MECH_KINEMATICS_TRACEBACK=1`` is set. It also lets the C library keep freed
memory for reuse (:func:`mech_kinematics.memory.keep_freed_memory`): a
command's process is its own, the library never changes a host's allocator.
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

from ..errors import MechKinematicsError, TargetError
from ..memory import keep_freed_memory
from ..units import LENGTH_UNITS, rad_per_s_from_rpm, reduce_radians, turns_from_degrees

__all__ = ['ArgumentParser', 'PROG', 'UNIT_SYSTEMS', 'add_branch_argument',
           'add_driver_arguments', 'add_gravity_argument', 'add_robot_arguments',
           'add_scene_argument', 'add_units_argument', 'angle_given', 'angle_unit',
           'angular_rate_given', 'branch_sign', 'branches_of', 'robot_angle_given',
           'drive_from_args', 'finite_float', 'gravity_of', 'is_urdf', 'joint_list',
           'link_loads_of', 'load_robot_argument', 'load_scene_argument', 'mimic_ruled',
           'named_value', 'payloads_of', 'positive_float', 'positive_int', 'positive_seconds',
           'run_handler', 'run_tool', 'seconds_or_zero', 'targets_in_si', 'values_by_driver']

#: What ``--units`` takes: ``deg`` (the default: a revolute joint's or a crank's
#: values in degrees and rpm) or ``si`` (rad and rad/s; an actuator's length in m).
UNIT_SYSTEMS = ('deg', 'si')
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


def is_urdf(source: Any) -> bool:
    """Return whether a SCENE argument names a robot description: a path ending in .urdf."""
    return source is not None and str(source).lower().endswith('.urdf')


def joint_list(text: str) -> tuple[str, ...]:
    """Parse ``J1,J2,...`` (joint names), or tell argparse why not."""
    names = tuple(name.strip() for name in text.split(','))
    if not names or not all(names):
        msg = f'expected joint names separated by commas, got {text!r}'
        raise argparse.ArgumentTypeError(msg)
    return names


def add_robot_arguments(parser: argparse.ArgumentParser) -> None:
    """Add what a robot in URDF takes: ``--closures``, ``--actuated`` and ``--reference``."""
    group = parser.add_argument_group('a robot described in URDF (a SCENE path ending in .urdf)')
    group.add_argument('--closures', metavar='FILE',
                       help='the closures beside the URDF, told by content: a loop_closures.yaml, '
                            'a file of <constraint> elements, an Extended-URDF robot.yaml or a '
                            'fusion2URDF robot_data.yaml (its <constraint>, <loop_joint>, <loop> '
                            'and closing_NAME_1/_2 frames are read from the URDF)')
    group.add_argument('--actuated', type=joint_list, metavar='J1,J2,...',
                       help="the actuated joints (default: the closures file's independent "
                            "joints, else the URDF's <transmission> and <ros2_control> joints)")
    group.add_argument('--reference', type=named_value, action='append', metavar='J=VALUE',
                       help='a reference pose whose branches the loops keep (degrees for a '
                            'revolute joint, rad with --units si; m for a prismatic one; '
                            "repeatable; default: the URDF's zero pose)")


def add_units_argument(parser: argparse.ArgumentParser,
                       flags: tuple[str, ...] = ('--input', '--speed', '--reference')) -> None:
    """Add ``--units deg|si``: the units of the values of ``flags`` (the command's own)."""
    named = ', '.join(flags[:-1]) + f' and {flags[-1]}' if len(flags) > 1 else flags[0]
    rates = ' and rpm' if '--speed' in flags else ''
    parser.add_argument('--units', choices=UNIT_SYSTEMS, default=None,
                        help=f'the units of the values of {named}: deg (the default: degrees'
                             f'{rates} for a crank or a revolute joint, m for a prismatic '
                             "joint, the scene's length unit for an actuator) or si (rad"
                             f'{" and rad/s" if rates else ""}; m)'
                             + ('; --angle-deg and --speed-rpm stay degrees and rpm'
                                if '--input' in flags else '') + '; the answer is SI either way')


def _si(args: argparse.Namespace) -> bool:
    return getattr(args, 'units', None) == 'si'


def angle_unit(args: argparse.Namespace) -> str:
    """Return the unit of an angle given on the command line (``--units``): ``deg`` or ``rad``."""
    return 'rad' if _si(args) else 'deg'


def angle_given(value: float, args: argparse.Namespace) -> tuple[float, int]:
    """Return an angle given on the command line as (rad within a turn, whole turns).

    In degrees (``turns_from_degrees``) or, with ``--units si``, in rad
    (``reduce_radians``); either reduction is exact.
    """
    return reduce_radians(value) if _si(args) else turns_from_degrees(value)


def robot_angle_given(value: float, args: argparse.Namespace, ruled: bool
                      ) -> tuple[float, float | None]:
    """Return a robot's revolute joint value given on the command line, in rad.

    ``(rad, exact)``: the double the value is in rad, and, beyond a turn and
    for a joint no ``<mimic>`` rule involves (``ruled``: a rule applies to a
    joint's value, not its direction), its direction reduced exactly
    (:func:`angle_given`), else None.
    """
    beyond = abs(value) > (math.tau if _si(args) else 360.0)
    exact = angle_given(value, args)[0] if beyond and not ruled else None
    return (float(value) if _si(args) else math.radians(value)), exact


def angular_rate_given(value: float, args: argparse.Namespace) -> float:
    """Return an angular speed given on the command line in rad/s (rpm, or rad/s with si)."""
    return float(value) if _si(args) else rad_per_s_from_rpm(value)


def add_gravity_argument(parser: argparse.ArgumentParser) -> None:
    """Add ``--gravity GX,GY,GZ``: a robot's gravity in its URDF's root frame."""
    parser.add_argument('--gravity', metavar='GX,GY,GZ',
                        help="for a robot described in URDF: gravity in the URDF's root frame, "
                             'm/s^2 (default 0,0,-9.80665: REP 103, z up; 0,0,0 for none); the '
                             "part along a loop's pivots is carried by its bearings")
    parser.add_argument('--payload', action='append', metavar='LINK=KG[@X,Y,Z]',
                        help='for a robot described in URDF: a point mass welded to a link, '
                             "at a point of the link's frame (m; default its origin), e.g. "
                             'platform=2.5@0.1,0,0.05 (repeatable)')
    parser.add_argument('--link-force', action='append', metavar='LINK=FX,FY,FZ[@X,Y,Z]',
                        help="for a robot described in URDF: a force on a link, N in the URDF's "
                             "root frame, at a point of the link's frame (m; default its "
                             'origin), e.g. tool=0,0,-20@0.1,0,0 (repeatable, a link once)')
    parser.add_argument('--link-torque', action='append', metavar='LINK=TX,TY,TZ',
                        help='for a robot described in URDF: a torque on a link, N m in the '
                             "URDF's root frame (repeatable, a link once)")


def link_loads_of(args: argparse.Namespace) -> tuple[Any, ...]:
    """Return ``--link-force`` and ``--link-torque`` as link loads, or a one-line ValueError."""
    from ..robot.forces import parse_link_loads

    return parse_link_loads(getattr(args, 'link_force', None) or (),
                            getattr(args, 'link_torque', None) or (), '--link-force',
                            '--link-torque')


def payloads_of(args: argparse.Namespace) -> dict[str, tuple[float, tuple[float, ...]]]:
    """Return ``--payload LINK=KG[@X,Y,Z]`` as ``{LINK: (kg, (x, y, z))}``, or a ValueError."""
    from ..robot.forces import parse_payloads

    return parse_payloads(getattr(args, 'payload', None) or (), '--payload')


def gravity_of(args: argparse.Namespace) -> tuple[float, float, float] | None:
    """Return ``--gravity`` as three numbers (``None`` if not given), or a one-line ValueError."""
    from ..robot.forces import check_gravity

    text = getattr(args, 'gravity', None)
    if text is None:
        return None
    try:
        values = [float(v) for v in text.split(',')]
    except ValueError:
        values = []
    if len(values) != 3:
        msg = f'--gravity: Expected GX,GY,GZ (three numbers, m/s^2), got {text!r}'
        raise ValueError(msg)
    try:
        return check_gravity(values)
    except ValueError as error:
        raise ValueError(f'--gravity: {error}') from None


def load_robot_argument(args: argparse.Namespace) -> Any:
    """Return the :class:`~mech_kinematics.robot.Robot` of a URDF SCENE and its options."""
    from ..robot import Robot
    from ..robot.description import read_description

    description = read_description(args.scene, getattr(args, 'closures', None))
    reference = {}
    for name, value in getattr(args, 'reference', None) or ():
        joint = description.joints.get(name or '')
        if joint is None or joint.type is None:
            from ..errors import UrdfError
            moving = ', '.join(n for n, j in description.joints.items() if j.type is not None)
            msg = (f'{args.scene}: Expected --reference J=VALUE with J a moving joint of the '
                   f'robot ({moving}), got {name!r}')
            raise UrdfError(msg)
        if not joint.type.angular:
            reference[name] = value
        else:
            radians, exact = robot_angle_given(value, args, name in mimic_ruled(description))
            reference[name] = radians if exact is None else exact  # beyond a turn: exactly
    payloads = payloads_of(args)
    if payloads:
        from ..robot.forces import with_payloads
        description = with_payloads(description, payloads)
    return Robot(description, getattr(args, 'actuated', None), reference)


def mimic_ruled(description: Any) -> set[str]:
    """Return the joints a ``<mimic>`` rule involves (they have one, or lead one).

    A revolute joint given beyond a turn is reduced exactly to its direction
    (``turns_from_degrees``), as a scene's crank angle is, except these: a
    rule applies to a joint's value, not to its direction.
    """
    rules = [j.mimic for j in description.joints.values() if j.mimic is not None]
    return {j.name for j in description.joints.values() if j.mimic is not None} | {
        rule.joint for rule in rules}


def load_scene_argument(args: argparse.Namespace, source: Any = None) -> Any:
    """Return the scene a SCENE argument names: a scene file, a packaged name or a URDF.

    A URDF (a path ending in ``.urdf``) gives the scene its planar loops
    become (``urdf2scene``'s); ``--closures``, ``--actuated`` and
    ``--reference`` are refused for anything else.
    """
    from ..errors import SceneError
    from ..scene import load_scene

    source = args.scene if source is None else source
    if is_urdf(source):
        return load_robot_argument(args).scene
    given = [flag for flag, key in (('--closures', 'closures'), ('--actuated', 'actuated'),
                                    ('--reference', 'reference')) if getattr(args, key, None)]
    if given:
        msg = (f'Expected {", ".join(given)} with a robot described in URDF (a path ending in '
               f'.urdf), got scene {source}')
        raise SceneError(msg)
    return load_scene(source)


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
    """Run ``args.handler(args)``; return its exit status, turning failures into one line.

    The command's process keeps freed memory for its large array solves
    (:func:`~mech_kinematics.memory.keep_freed_memory`).
    """
    keep_freed_memory()
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


def targets_in_si(given: dict[str, dict[str, float]], angular: Sequence[bool],
                  args: argparse.Namespace, per_metre: float) -> tuple[
                      list[float], list[float], list[float]]:
    """Return targets' positions, speeds and accelerations in SI, in ``given``'s order.

    ``given`` maps ``--target``, ``--target-speed`` and ``--target-accel`` to
    {target: value}; an angle is in the units of ``--input`` (deg, or rad with
    ``--units si``), its speed as ``--speed``'s (rpm, or rad/s); a length is
    over ``per_metre`` (the scene's length unit per metre).
    """
    goal, speeds, accels = [], [], []
    for name, is_angle in zip(given['--target'], angular, strict=True):
        value = given['--target'][name]
        speed = given.get('--target-speed', {}).get(name, 0.0)
        goal.append((value if _si(args) else math.radians(value)) if is_angle
                    else value / per_metre)
        speeds.append(angular_rate_given(speed, args) if is_angle else speed)
        accels.append(given.get('--target-accel', {}).get(name, 0.0))
    return goal, speeds, accels


def named_value(text: str) -> tuple[str | None, float]:
    """Parse ``NAME=VALUE`` (a driver's value) or a plain number, or tell argparse why not."""
    name, sep, value = text.rpartition('=')
    if not sep:
        return None, finite_float(text)
    if not name:
        msg = f'expected NAME=VALUE (a driver of the scene and a number), got {text!r}'
        raise argparse.ArgumentTypeError(msg)
    return name, finite_float(value)


def branch_sign(text: str) -> tuple[str, int]:
    """Parse ``--branch JOINT=+1|-1`` (or ``+``, ``-``), or tell argparse why not."""
    from ..solver.inverse import parse_branch

    try:
        return parse_branch(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def add_branch_argument(parser: argparse.ArgumentParser) -> None:
    """Add ``--branch JOINT=+1|-1``, the working mode of an answer to ``--target``."""
    parser.add_argument('--branch', type=branch_sign, action='append', metavar='JOINT=+1|-1',
                        help='with --target: the working mode (docs/targets.md), the sign of '
                             "a joint's angle in (-180, 180] deg: a scene's pin between two "
                             "moving links (its link's angle from the link it is pinned on), a "
                             "URDF's revolute joint of a loop (its value); repeatable, one per "
                             'leg (default: the mode continued from the start pose)')


def branches_of(args: argparse.Namespace) -> dict[str, int] | None:
    """Return ``--branch`` as {joint: sign}; refuse (TargetError) a joint twice, or no --target."""
    given = getattr(args, 'branch', None) or []
    if not given:
        return None
    if not getattr(args, 'target', None):
        msg = 'Expected --branch with --target (a working mode of the inverse), got it alone'
        raise TargetError(msg)
    out: dict[str, int] = {}
    for name, sign in given:
        if name in out:
            msg = f'Expected each --branch joint once, got {name} twice'
            raise TargetError(msg)
        out[name] = sign
    return out


def values_by_driver(scene: Any, flag: str, given: list[tuple[str | None, float]] | None
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


def add_driver_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``--accel``, ``--input`` and ``--speed NAME=VALUE``: what :func:`drive_from_args` reads.

    ``solve`` and ``diagram`` take a scene's drivers the same way (with
    ``--angle-deg`` and ``--speed-rpm`` of their own for one crank).
    """
    parser.add_argument('--accel', type=named_value, action='append', metavar='[NAME=]A',
                        help='crank angular acceleration in rad/s^2, + CCW; with several '
                             'drivers, NAME=A per driver: rad/s^2 for a crank, m/s^2 for an '
                             "actuator (repeatable; default: the scene's)")
    parser.add_argument('--input', type=named_value, action='append', metavar='NAME=VALUE',
                        help="a driver's position: a crank's angle in degrees (counted from "
                             "the start), an actuator's length in the scene's length unit; "
                             'rad and m with --units si (repeatable, one per driver; default: '
                             "the scene's)")
    parser.add_argument('--speed', type=named_value, action='append', metavar='NAME=VALUE',
                        help="a driver's speed: rpm for a crank (as --speed-rpm), m/s for an "
                             "actuator's extension rate; rad/s and m/s with --units si "
                             "(repeatable; default: the scene's)")


def drive_from_args(scene: Any, args: argparse.Namespace) -> tuple[Any, Any, Any, Any, str]:
    """Return solve's (positions, speeds, accels, turns) and the text of where it stands.

    From the ``--input``, ``--speed`` and ``--accel NAME=VALUE`` options (and,
    for one crank, ``--angle-deg`` and ``--speed-rpm``) that ``solve``,
    ``diagram`` and ``plot`` share; a ValueError says what is wrong. A scene
    of one driver (a crank or an actuator) gets one value each (``None``:
    the scene's), as ``solve`` takes them; a scene of several, one list each.
    """
    inputs = values_by_driver(scene, '--input', args.input)
    speeds = values_by_driver(scene, '--speed', args.speed)
    accels = values_by_driver(scene, '--accel', args.accel)
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
        if crank.name in inputs:
            angle, turns = angle_given(inputs[crank.name], args)
            shown = f'crank angle {inputs[crank.name]:.15g} {angle_unit(args)}'
        elif args.angle_deg is not None:
            angle, turns = turns_from_degrees(args.angle_deg)
            shown = f'crank angle {args.angle_deg:.15g} deg'
        else:
            angle, turns = crank.angle, crank.turns
            shown = f'crank angle {scene.units.angle_text(crank.shown)}'
        speed = (angular_rate_given(speeds[crank.name], args) if crank.name in speeds
                 else None if args.speed_rpm is None else rad_per_s_from_rpm(args.speed_rpm))
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
        revolute = driver.joint_type.angular
        given = inputs.get(driver.name)
        whole = 0
        if given is None:
            position = driver.start
            text = driver.position_text(driver.start, scene.units)
        elif revolute:
            position, whole = angle_given(given, args)
            text = f'{given:.15g} {angle_unit(args)}'
        elif _si(args):
            position = given
            text = f'{given:.15g} m'
        else:
            position = given / per_metre
            text = f'{given:.15g} {scene.units.length}'
        speed = speeds.get(driver.name)
        if speed is not None and revolute:
            speed = angular_rate_given(speed, args)
        positions.append(position)
        rates.append(speed)
        turns_list.append(whole)
        words.append(f'{driver.name} = {text}')
    accel_list = [accels.get(driver.name) for driver in drivers]
    if len(drivers) == 1:   # one actuator: solve's one-driver signature takes its values bare
        return positions[0], rates[0], accel_list[0], turns_list[0], words[0]
    return positions, rates, accel_list, turns_list, ', '.join(words)
