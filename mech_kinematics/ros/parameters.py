# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's parameters: names, types, defaults, ranges and the rules a value must meet.

One table (:data:`PARAMETERS`) that the node declares from, the tests and the
launch files are checked against, and the README lists. :func:`refusal` says
why a value is refused (``None`` if it is accepted), without rclpy, so the
rules are tested on their own; :func:`joint_refusal` checks the rules that tie
two parameters together.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
import math
from typing import Any, TYPE_CHECKING

from .diagnostics import DEFAULT_MAX_LATENESS_MS
from .markers import DEFAULT_ACCELERATION_SCALE, DEFAULT_VELOCITY_SCALE
from .topic_drive import DEFAULT_JUMP_BACK_S, EXTRA_JOINTS, PASS, REFUSE
from ..bounds import MAX_ERROR
from ..scene import DEFAULT_SCENE, MAX_FILE_BYTES
from ..units import NS_PER_S, rate_from_si, si_from_rate

if TYPE_CHECKING:
    from ..solver.base import Driver

__all__ = ['CATCH_UP', 'DRIVE_MODES', 'DRIVER_RATES', 'DriverRates', 'DYNAMIC', 'EFFORT_MODES',
           'INPUT_DRIVES', 'LATE_TICKS',
           'MAX_NAME_CHARS', 'MAX_PATH_CHARS', 'PARAMETERS', 'ParameterSpec', 'SHOWN_CHARS',
           'SKIP', 'STATE_DEPTH', 'STATIC', 'SUBSCRIBED_DRIVES', 'TARGET', 'TIME', 'TOPIC',
           'TRAJECTORY',
           'bounded_by_max_crank_speed',
           'catch_up_window_ns', 'depth_refusal', 'driver_parameters', 'extra_joints_default',
           'first_crank_aliases', 'frame_refusal', 'joint_refusal', 'rate_default', 'refusal',
           'shown', 'spec']

#: ``late_ticks`` values: publish every missed grid instant, or only the latest.
CATCH_UP = 'catch_up'
SKIP = 'skip'
LATE_TICKS = (CATCH_UP, SKIP)
#: ``drive`` values: the drivers as exact functions of the clock, read from a topic, or
#: found from the targets read from a topic (driven from the output, docs/targets.md).
TIME = 'time'
TOPIC = 'topic'
TARGET = 'target'
#: Each point of a trajectory (drivers or targets with their rates), published at its time.
TRAJECTORY = 'trajectory'
DRIVE_MODES = (TIME, TOPIC, TARGET, TRAJECTORY)
#: The drives whose states answer messages without accelerations (no efforts of the motion).
INPUT_DRIVES = (TOPIC, TARGET)
#: The drives whose states answer messages: the node subscribes, the clock's grid does not run.
SUBSCRIBED_DRIVES = (TOPIC, TARGET, TRAJECTORY)
#: ``effort`` values: the forces of the motion the drive determines (inertia, gravity and
#: loads; left out where the drive gives no accelerations: ``drive: topic``), or the statics
#: (gravity and loads only, inertia neglected: velocities and accelerations taken as zero).
DYNAMIC = 'dynamic'
STATIC = 'static'
EFFORT_MODES = (DYNAMIC, STATIC)
#: Longest string parameter (a frame id, a prefix, a choice), characters.
MAX_NAME_CHARS = 256
#: Longest path parameter (``scene``), characters: Linux's PATH_MAX.
MAX_PATH_CHARS = 4096


@dataclass(frozen=True)
class ParameterSpec:
    """One parameter of the node.

    Attributes
    ----------
    name : str
        The ROS parameter name.
    kind : {'double', 'xy', 'xyz', 'string', 'bool', 'string_array'}
        Its type; an integer is accepted for a double (``-p rate_hz:=500``).
        ``xy``: a double array of two finite numbers ``[x, y]`` (integers accepted);
        ``xyz`` of three.
    default : float, str, bool or None
        The default; ``None`` where the scene (or another parameter) gives it.
    description : str
        What it means, for ``ros2 param describe``.
    unit : str
        Unit of a double ('' for none).
    low, high : float or None
        Allowed range of a double, inclusive.
    choices : tuple of str
        Allowed values of a string ('' for any non-empty string).
    read_only : bool
        Set at start only.
    may_be_empty : bool
        A string that may be empty.
    frame : bool
        A tf2 frame id (or a prefix of frame ids): see :func:`frame_refusal`.
    max_chars : int
        Longest value of a string, characters (a longer one is refused before
        anything else reads it).
    """

    name: str
    kind: str
    default: Any
    description: str
    unit: str = ''
    low: float | None = None
    high: float | None = None
    choices: tuple[str, ...] = ()
    read_only: bool = False
    may_be_empty: bool = False
    frame: bool = False
    max_chars: int = MAX_NAME_CHARS


PARAMETERS = (
    ParameterSpec('scene', 'string', DEFAULT_SCENE,
                  'Scene YAML: a path, or the name of a scene in config/scenes/; or a robot '
                  'described in URDF: a path ending in .urdf (URDF mode)',
                  read_only=True, max_chars=MAX_PATH_CHARS),
    ParameterSpec('robot_description', 'string', '',
                  "A robot's URDF text, as robot_state_publisher takes it (URDF mode, with "
                  'scene left at its default); published unchanged on robot_description',
                  read_only=True, may_be_empty=True, max_chars=MAX_FILE_BYTES),
    ParameterSpec('loop_closures', 'string', '',
                  "URDF mode: a file closing the robot's loops, told by content: a "
                  'loop_closures.yaml, a file of <constraint> elements, an Extended-URDF '
                  'robot.yaml or a fusion2URDF robot_data.yaml (<constraint>, <loop_joint>, '
                  '<loop> and closing_NAME_1/_2 frames are read from the URDF)',
                  read_only=True, may_be_empty=True, max_chars=MAX_PATH_CHARS),
    ParameterSpec('actuated_joints', 'string_array', None,
                  "URDF mode: the actuated joints. Defaults to the loop_closures' independent "
                  "joints, else the URDF's <transmission> and <ros2_control> joints",
                  read_only=True),
    ParameterSpec('reference_pose', 'string_array', None,
                  'URDF mode: a reference pose whose branches the loops keep, JOINT=VALUE '
                  "each (rad for a revolute joint, m for a prismatic one; default: the URDF's "
                  'zero pose), as the commands take --reference (there in degrees)',
                  read_only=True),
    ParameterSpec('payloads', 'string_array', None,
                  'URDF mode: point masses welded to links, LINK=KG or LINK=KG@X,Y,Z each '
                  "(kg, and m in the link's frame; default its origin), as the commands take "
                  '--payload; changeable while running where the node publishes the '
                  "robot's forces, from the next instant", may_be_empty=True),
    ParameterSpec('link_forces', 'string_array', None,
                  'URDF mode: forces on links, LINK=FX,FY,FZ or LINK=FX,FY,FZ@X,Y,Z each (N in '
                  "the URDF's root frame, at a point of the link's frame, m; default its "
                  'origin), as the commands take --link-force; changeable while running where '
                  "the node publishes the robot's forces, from the next instant",
                  may_be_empty=True),
    ParameterSpec('link_torques', 'string_array', None,
                  "URDF mode: torques on links, LINK=TX,TY,TZ each (N m in the URDF's root "
                  'frame), as the commands take --link-torque; changeable while running where '
                  "the node publishes the robot's forces, from the next instant",
                  may_be_empty=True),
    ParameterSpec('frame_id', 'string', 'mechanism',
                  'header.frame_id of every message: the ground frame of the scene',
                  read_only=True, frame=True),
    ParameterSpec('managed', 'bool', False,
                  'Follow the ROS 2 node lifecycle: configure loads the scene, activate '
                  'starts publishing (default: configure and activate at start)',
                  read_only=True),
    ParameterSpec('drive', 'string', TIME,
                  'Where the drivers come from: time (each an exact function of the clock, '
                  'on the rate_hz grid), topic (the positions, and velocities if given, of '
                  'each message on input_joint_states, published with its stamp) or target '
                  '(each message on input_targets names targets, as many as the scene has '
                  "drivers: a joint it reports or POINT.x|y; a URDF robot's joint or "
                  'FRAME.x|y|z; SI; the drivers that put them '
                  'there, continued from the last state, published with its stamp; '
                  'docs/targets.md) or trajectory (each point of a JointTrajectory on '
                  'input_trajectory, of the drivers or of targets, with velocities and '
                  'accelerations: its state and the efforts of that motion at the stamp '
                  'plus its time_from_start)',
                  choices=DRIVE_MODES, read_only=True),
    ParameterSpec('target_branch', 'string_array', None,
                  'With drive: target or trajectory, the working mode of every answer to '
                  "targets: JOINT=+1 or JOINT=-1 entries, the sign of a joint's angle in "
                  "(-pi, pi] (a scene's pin between two moving links, a URDF's revolute joint "
                  'of a loop; docs/targets.md), one per leg. Defaults to none: the mode '
                  'continued from the start pose', read_only=True),
    ParameterSpec('extra_joints', 'string', None,
                  "With drive: topic, what an input message's joints that are not drivers "
                  'do: refuse the message, ignore them (the drivers are taken), or pass them '
                  "through unchanged in joint_states after the mechanism's joints. Defaults "
                  'to refuse, and to pass in URDF mode',
                  choices=EXTRA_JOINTS, read_only=True),
    ParameterSpec('effort', 'string', DYNAMIC,
                  'For a scene with masses, gravity or loads (a URDF with <inertial>s), what '
                  'joint_states.effort, '
                  'reactions/* and shaking carry: dynamic (the forces of the motion: with '
                  'drive: topic, whose input gives no accelerations, they are left out) or '
                  'static (gravity and loads only, inertia neglected: every velocity and '
                  'acceleration taken as zero)', choices=EFFORT_MODES, read_only=True),
    ParameterSpec('stamp_jump_back_s', 'double', DEFAULT_JUMP_BACK_S,
                  'With drive: topic, an input stamped earlier than the last published state '
                  'by more than this is a jump of the clock back: it is published and the '
                  'order starts again from it (said on diagnostics); one earlier by less is '
                  'refused as out of order', 's', 0.0, 1e9),
    ParameterSpec('crank_speed_rpm', 'double', None,
                  'Crank speed, + CCW, from the tick at which it is applied (the crank angle '
                  "stays continuous). Defaults to the scene's input.speed_rpm",
                  'rpm', -100_000.0, 100_000.0),
    ParameterSpec('crank_accel', 'double', None,
                  'Crank angular acceleration, + CCW; the speed is held at '
                  "+-max_crank_speed_rpm. Defaults to the scene's input.accel",
                  'rad/s^2', -1.0e6, 1.0e6),
    ParameterSpec('max_crank_speed_rpm', 'double', None,
                  'Bound on |crank speed|: an accelerating drive holds its speed there; '
                  "crank_speed_rpm may not exceed it. Defaults to 10000 (or the scene's "
                  'speed if faster)', 'rpm', 0.0, 100_000.0),
    ParameterSpec('rate_hz', 'double', 100.0,
                  'Publish rate: tick k is stamped t0 + k / rate_hz exactly', 'Hz', 1.0,
                  10_000.0),
    ParameterSpec('late_ticks', 'string', CATCH_UP,
                  'A late wake-up publishes every grid instant it missed (catch_up, up to '
                  'max_catch_up_s) or only the latest (skip)', choices=LATE_TICKS),
    ParameterSpec('max_catch_up_s', 'double', 0.1,
                  'How far behind a late wake-up still publishes missed instants; older '
                  'ones are skipped and counted. Capped so that a burst is at most 1000 '
                  'messages (the history depth): (1000 - 1) / rate_hz', 's', 0.0, 10.0),
    ParameterSpec('publish_timeout_s', 'double', 2.0,
                  'A publish that has not returned after this long (Fast DDS shared memory '
                  'blocked on a killed reader) ends the node, naming the topic, with exit '
                  'status 1, for a supervisor (launch respawn, systemd) to restart it; '
                  '0: off', 's', 0.0, 3600.0, read_only=True),
    ParameterSpec('max_lateness_ms', 'double', DEFAULT_MAX_LATENESS_MS,
                  'Timing on diagnostics turns WARN when the p99 lateness of a second of '
                  'ticks exceeds this (or when an instant is skipped); caught-up late ticks '
                  'alone are OK', 'ms', 0.0, 10_000.0),
    ParameterSpec('max_relative_error', 'double', MAX_ERROR,
                  'A tick whose error bound on any published value exceeds this fraction of '
                  "its kind's scale publishes nothing (diagnostics say why)", 'of the scale',
                  1e-15, 1.0),
    ParameterSpec('tf_rate_hz', 'double', 100.0,
                  'Rate of the link and slider frames on /tf, stamped like the state of the '
                  'tick they show (at most rate_hz: every tick; 0: off)', 'Hz', 0.0, 10_000.0),
    ParameterSpec('tf_prefix', 'string', '',
                  "Prefix of the child frames on /tf and /tf_static, '<prefix>/<link>' "
                  "(default '': frame_id)", read_only=True, may_be_empty=True, frame=True),
    ParameterSpec('markers', 'bool', False,
                  'Also publish visualization_msgs/MarkerArray on markers, at most 30 Hz',
                  read_only=True),
    ParameterSpec('marker_velocity_scale', 'double', DEFAULT_VELOCITY_SCALE,
                  'Length of the velocity arrows on markers per unit velocity',
                  'm per m/s', 0.0, 1000.0),
    ParameterSpec('marker_acceleration_scale', 'double', DEFAULT_ACCELERATION_SCALE,
                  'Length of the acceleration arrows on markers per unit acceleration',
                  'm per m/s^2', 0.0, 1000.0),
    ParameterSpec('marker_force_scale', 'double', 0.0,
                  'Length of the reaction arrows on markers per newton (a scene with masses, '
                  "gravity or loads); 0: the largest drawn at 0.3 of the mechanism's size",
                  'm per N', 0.0, 1000.0),
)

_BY_NAME = {p.name: p for p in PARAMETERS}


def _range(name: str) -> tuple[float, float]:
    low, high = _BY_NAME[name].low, _BY_NAME[name].high
    assert low is not None and high is not None
    return low, high


@dataclass(frozen=True)
class DriverRates:
    """What a driver's two parameters (``inputs.NAME.<rate key>``, ``inputs.NAME.accel``) allow.

    Attributes
    ----------
    speed_range, accel_range : (float, float)
        Inclusive ranges of the rate (in the unit of the kind's
        ``rate_parameter``) and of the acceleration (its joint type's unit).
    speed_text, accel_text : str
        Their descriptions, ``{name}`` standing for the driver's.
    """

    speed_range: tuple[float, float]
    accel_range: tuple[float, float]
    speed_text: str
    accel_text: str


#: A driver's parameters by the unit its kind sets its rate in (``Driver.rate_parameter``):
#: a crank's or a motor's in rpm (the ranges of crank_speed_rpm and crank_accel), an
#: actuator's or a slider's in m/s.
DRIVER_RATES = {
    'rpm': DriverRates(
        _range('crank_speed_rpm'), _range('crank_accel'),
        'Speed of driver {name} (a crank, or a motor: relative), + CCW, from the tick at which '
        "it is applied. Defaults to the scene's",
        "Angular acceleration of driver {name}, + CCW. Defaults to the scene's"),
    'm/s': DriverRates(
        (-100.0, 100.0), (-10_000.0, 10_000.0),
        "Rate of driver {name} (an actuator's extension, a slider's along its guide), from "
        'the tick at which it is applied (its position stays continuous). Defaults to the '
        "scene's",
        "Acceleration of driver {name}'s position. Defaults to the scene's"),
}


def rate_default(driver: Driver) -> float:
    """Return the default of ``driver``'s rate parameter: the scene's rate in that unit.

    A rate given in the parameter's unit is kept as given, to the bit (a
    crank's ``speed_rpm: 7`` is 7.0 rpm); one given in another unit is
    converted and rounded to 12 significant digits (a crank's ``speed:`` of
    -4 pi rad/s is -120 rpm, not -119.99...).
    """
    rate, unit = driver.rate, driver.rate_parameter.unit
    if rate.unit == unit:
        return float(rate.value)
    return float(f'{rate_from_si(si_from_rate(rate.value, rate.unit), unit):.12g}')


def _driver_rates(driver: Driver) -> DriverRates:
    unit = driver.rate_parameter.unit
    try:
        return DRIVER_RATES[unit]
    except KeyError:
        msg = (f'Expected driver {driver.name} to set its rate in one of '
               f'{", ".join(DRIVER_RATES)}, got {unit!r}')
        raise ValueError(msg) from None


def driver_parameters(drivers: Sequence[Driver]) -> tuple[ParameterSpec, ...]:
    """Return the parameters of a scene's drivers, defaulting to the scene's values.

    For each driver NAME (``Scene.drivers``): ``inputs.NAME.<key>`` with the
    key and unit of its kind's ``rate_parameter`` (a crank's ``speed_rpm``,
    rpm; an actuator's ``speed``, m/s; :func:`rate_default`), and
    ``inputs.NAME.accel`` in its joint type's unit (rad/s^2, m/s^2), with the
    ranges and words of :data:`DRIVER_RATES`. The node declares them when it
    loads the scene.
    """
    specs = []
    for d in drivers:
        base, rates, (key, unit) = f'inputs.{d.name}.', _driver_rates(d), d.rate_parameter
        specs += [
            ParameterSpec(base + key, 'double', rate_default(d),
                          rates.speed_text.format(name=d.name), unit, *rates.speed_range),
            ParameterSpec(base + 'accel', 'double', float(d.accel),
                          rates.accel_text.format(name=d.name), d.joint_type.units[2],
                          *rates.accel_range)]
    return tuple(specs)


def bounded_by_max_crank_speed(driver: Driver) -> bool:
    """Return whether ``max_crank_speed_rpm`` bounds ``driver``: its rate is set in rpm."""
    return driver.rate_parameter.unit == spec('max_crank_speed_rpm').unit


def first_crank_aliases(drivers: Sequence[Driver]) -> dict[str, str]:
    """Return {``crank_speed_rpm``, ``crank_accel``: the first driver's names}, if it is a crank.

    The two v1 names stay the first crank's (a first driver whose rate is set
    in rpm): setting either name sets both.
    """
    if not drivers or not bounded_by_max_crank_speed(drivers[0]):
        return {}
    base = f'inputs.{drivers[0].name}.'
    return {'crank_speed_rpm': base + drivers[0].rate_parameter.key,
            'crank_accel': base + 'accel'}


def spec(name: str) -> ParameterSpec:
    """Return the :class:`ParameterSpec` of ``name`` (KeyError if the node has none)."""
    return _BY_NAME[name]


def _kind_of(value: Any) -> str:
    if isinstance(value, bool):
        return 'bool'
    if isinstance(value, (int, float)):
        return 'number'
    if isinstance(value, str):
        return 'string'
    return type(value).__name__


#: Longest text of a refused value shown in a message (a 1 MB string is not echoed whole).
SHOWN_CHARS = 60


def shown(value: Any) -> str:
    """Return ``repr(value)``, cut to about :data:`SHOWN_CHARS` characters with its length."""
    text = repr(value)
    if len(text) <= SHOWN_CHARS:
        return text
    size = f'{len(value)} characters' if isinstance(value, str) else f'{len(text)} characters'
    return f'{text[:SHOWN_CHARS]}... ({size})'


def frame_refusal(name: str, value: str) -> str | None:
    """Return why ``value`` is not a frame id as tf2 requires, or ``None``.

    tf2 refuses a frame id that starts with '/'; '<prefix>/<link>' must be
    one too, so no part may be empty, '.' or '..', and none may hold a space
    or a control character.
    """
    if not value:
        return None
    parts = value.split('/')
    bad = (value.startswith('/') or any(p in ('', '.', '..') for p in parts)
           or any(c.isspace() or not c.isprintable() for c in value))
    if not bad:
        return None
    return (f"{name}: expected a tf2 frame id (no leading '/', no empty, '.' or '..' part "
            f"between '/', no space), got {shown(value)}; e.g. 'mechanism' or 'robot/base'")


#: History depth of the state publishers: a catch-up burst never publishes more instants.
STATE_DEPTH = 1000


def catch_up_window_ns(max_catch_up_s: float, period_ns: int, depth: int = STATE_DEPTH) -> int:
    """Return how far behind a late wake-up still publishes missed instants, ns.

    ``max_catch_up_s``, capped so that one burst (the instants within the
    window, the latest included) is at most ``depth`` messages: a KEEP_LAST
    reader of that depth loses none of them. Older instants are skipped and
    counted, as beyond ``max_catch_up_s``.
    """
    return min(round(max_catch_up_s * NS_PER_S), (depth - 1) * period_ns)


#: Largest history depth a DDS implementation takes (its depth is a 32-bit signed integer).
MAX_DEPTH = 2**31 - 1


def depth_refusal(name: str, value: Any) -> str | None:
    """Return why ``value`` is not a QoS history depth, or ``None`` (rmw's text names files)."""
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= MAX_DEPTH:
        return (f'{name}: expected a whole number of messages from 0 to {MAX_DEPTH}, got '
                f'{_kind_of(value)} {shown(value)}')
    return None


def refusal(name: str, value: Any,
            drivers: Mapping[str, ParameterSpec] | None = None) -> str | None:
    """Return why ``value`` is refused for parameter ``name``, or ``None`` if it is accepted.

    ``drivers``: the scene's driver parameters (:func:`driver_parameters`) by
    name. An ``inputs.NAME.*`` name that is not among them is refused (no such
    driver, or not its kind of parameter). Names the node does not own
    (``use_sim_time``, ``qos_overrides.*``) are accepted here: rclpy checks
    them. An empty name is refused.
    """
    if not name:
        return f'expected a parameter name, got an empty one (with value {shown(value)})'
    if name.startswith('qos_overrides.') and name.endswith('.depth'):
        return depth_refusal(name, value)
    p = _BY_NAME.get(name) or (drivers or {}).get(name)
    if p is None and drivers is not None and name.startswith('inputs.'):
        known = ', '.join(sorted(drivers)) or 'none'
        return f'{name}: expected the parameter of a driver of the scene ({known}), got none'
    if p is None:
        return None
    if p.kind == 'double':
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return (f'{name}: expected a number ({p.unit or "no unit"}), got '
                    f'{_kind_of(value)} {shown(value)}')
        number = float(value)
        if not math.isfinite(number):
            return f'{name}: expected a finite number, got {number!r}'
        if p.low is not None and p.high is not None and not p.low <= number <= p.high:
            return (f'{name}: expected {p.low:g} <= value <= {p.high:g} {p.unit}, got '
                    f'{number!r}').rstrip()
        return None
    if p.kind in ('xy', 'xyz'):
        return _xy_refusal(name, value, p.unit, len(p.kind))
    if p.kind == 'bool':
        if not isinstance(value, bool):
            return f'{name}: expected true or false, got {_kind_of(value)} {shown(value)}'
        return None
    if p.kind == 'string_array':
        return None if p.may_be_empty and isinstance(value, (list, tuple)) and not value \
            else _names_refusal(name, value)
    if not isinstance(value, str):
        return f'{name}: expected a string, got {_kind_of(value)} {shown(value)}'
    if p.choices and value not in p.choices:
        return f'{name}: expected one of {", ".join(p.choices)}, got {shown(value)}'
    if len(value) > p.max_chars:
        return (f'{name}: expected at most {p.max_chars} characters, got {len(value)}: '
                f'{value[:SHOWN_CHARS // 2]!r}...')
    if not value and not p.may_be_empty:
        return f'{name}: expected a non-empty string, got {value!r}'
    if p.frame:
        return frame_refusal(name, value)
    return None


def _names_refusal(name: str, value: Any) -> str | None:
    """Return why ``value`` is not a list of distinct non-empty names, or ``None``."""
    if isinstance(value, str) or not isinstance(value, (list, tuple)) \
            or not all(isinstance(v, str) for v in value):
        return (f"{name}: expected a list of joint names (e.g. ['j1', 'j2']), got "
                f'{_kind_of(value)} {shown(value)}')
    if not value or not all(value) or len(set(value)) != len(value):
        return (f'{name}: expected one or more distinct non-empty joint names, got '
                f'{shown(list(value))}')
    return None


def extra_joints_default(urdf: bool) -> str:
    """Return ``extra_joints``' default: ``pass`` in URDF mode, else ``refuse``."""
    return PASS if urdf else REFUSE


def _xy_refusal(name: str, value: Any, unit: str, count: int = 2) -> str | None:
    """Return why ``value`` is not ``[x, y]`` (``count`` 3: ``[x, y, z]``) of finite numbers."""
    form, words = ('[x, y]', 'two') if count == 2 else ('[x, y, z]', 'three')
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence) and \
            type(value).__name__ != 'array':
        return (f'{name}: expected {form} ({unit}), got {_kind_of(value)} {shown(value)}')
    items = list(value)
    if len(items) != count or any(isinstance(v, bool) or not isinstance(v, (int, float))
                                  for v in items):
        return f'{name}: expected {form}, {words} numbers ({unit}), got {shown(items)}'
    if not all(math.isfinite(float(v)) for v in items):
        return f'{name}: expected {words} finite numbers ({unit}), got {shown(items)}'
    return None


def joint_refusal(values: Mapping[str, Any]) -> str | None:
    """Return why a set of values breaks a rule between parameters, or ``None``.

    ``values`` holds the values the parameters would have (new ones merged
    over current ones); missing names are not checked.
    """
    if values.get('drive') in INPUT_DRIVES and values.get('markers') is True:
        return (f'markers: expected false with drive: {values["drive"]} (the arrows would show '
                'velocities and accelerations the input does not give), got true')
    if values.get('drive') == TRAJECTORY and values.get('markers') is True:
        return ('markers: expected false with drive: trajectory (the markers follow the '
                "clock's grid, which does not run), got true")
    bound = values.get('max_crank_speed_rpm')
    if bound is None:
        return None
    # Every crank's speed: crank_speed_rpm (the first's) and inputs.NAME.speed_rpm.
    for name, speed in values.items():
        if (name == 'crank_speed_rpm' or name.endswith('.speed_rpm')) and speed is not None \
                and abs(float(speed)) > float(bound):
            return (f'{name}: expected |{name}| <= max_crank_speed_rpm ({float(bound):g} rpm), '
                    f'got {float(speed):g} rpm; set max_crank_speed_rpm (up to '
                    f'{spec("max_crank_speed_rpm").high:g}) first to go faster')
    return None
