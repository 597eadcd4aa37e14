# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Read scene YAML files (docs/scene_format.md) into :class:`Scene` objects.

The file is read by a hardened YAML reader (:class:`SceneLoader`), not by
``yaml.safe_load``: YAML 1.2 scalars, no duplicate or non-text keys, and every
resource bounded, so that any file, however hostile, gives a :class:`Scene`
or one :class:`SceneError` line, quickly and in bounded memory.

Limits
------
Each limit is a module constant named in the refusal: :data:`MAX_FILE_BYTES`,
:data:`MAX_YAML_NODES` (counted with aliases expanded, so a "billion laughs"
file is refused), :data:`MAX_DEPTH`, :data:`MAX_INTEGER_DIGITS`,
:data:`MAX_GROUND_POINTS`, :data:`MAX_DYADS`, :data:`MAX_CARRIED_POINTS`,
:data:`MAX_PINS` and :data:`MAX_IMUS`.
Only regular files are read: a FIFO, a device or a directory is refused
before anything is read from it, and the read stops one byte past
:data:`MAX_FILE_BYTES`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
import math
import os
from pathlib import Path
import re
import stat
import sys
from typing import Any, TypedDict, TypeVar


from .errors import SceneError
from .imu import ImuSpec
from .solver import Branch, CarriedPoint, Crank, Link, Pin, Scene, SceneUnits
from .solver.base import Driver, Item
from .solver.crank import CrankDict
from .solver.forces import Load, Mass
from .solver.mechanism import FollowedJoint, RobotReaction
from .solver.model import IDENTIFIER
from .solver.registry import DRIVERS, KINDS
from .units import (ANGLE_UNITS, LENGTH_UNITS, reduce_radians,
                    turns_from_degrees)
from .yaml12 import (_brief, _join, MAX_DEPTH, MAX_INTEGER_DIGITS, MAX_YAML_NODES,
                     read_scene_yaml, SceneLoader)

__all__ = [
    'DEFAULT_SCENE', 'MAX_CARRIED_POINTS', 'MAX_DEPTH', 'MAX_DRIVERS', 'MAX_DYADS',
    'MAX_FILE_BYTES', 'MAX_GROUND_POINTS', 'MAX_IMUS', 'MAX_INTEGER_DIGITS', 'MAX_MESSAGE',
    'MAX_PINS', 'MAX_YAML_NODES',
    'SceneLoader',
    'load_scene', 'parse_scene', 'read_scene_yaml', 'scene_dirs', 'scene_names', 'scene_text',
]

#: The packaged scene that the node and ``make run`` use by default.
DEFAULT_SCENE = 'khurmi_four_bar_ad150'

#: Largest scene file read, bytes (8 MiB: room for comments; a scene at all
#: the count limits below, one dyad key per line, is about 2.5 MB).
MAX_FILE_BYTES = 8 * 1024 * 1024
#: Most ground points in a scene.
MAX_GROUND_POINTS = 10_000
#: Most dyads in a scene.
MAX_DYADS = 10_000
#: Most carried points (``points:``) in a scene.
MAX_CARRIED_POINTS = 10_000
#: Most pins (``pins:``) in a scene.
MAX_PINS = 10_000
#: Most inertial sensors (``imus:``) in a scene.
MAX_IMUS = 10_000
#: Most drivers (``inputs:``) in a scene.
MAX_DRIVERS = 100
#: Most bodies with a mass (``masses:``) and most loads (``loads:``) in a scene.
MAX_MASSES = MAX_LOADS = 10_000
#: Most rows in one load's ``table``.
MAX_TABLE_ROWS = 10_000

#: The two spellings of ``units`` every refusal of a missing or bad one shows.
UNITS_EXAMPLES = 'units: {length: mm, angle: deg} or units: {length: m, angle: rad}'

T = TypeVar('T')


class LinkDict(TypedDict):
    """A link of a dyad: ``{name, from, length}``."""

    name: str
    length: float


class SceneDict(TypedDict, total=False):
    """A scene file's top level."""

    name: str
    description: str
    units: dict[str, str]
    ground: dict[str, list[float]]
    input: CrankDict
    inputs: list[dict[str, Any]]
    dyads: list[dict[str, Any]]
    points: dict[str, dict[str, Any]]
    outputs: dict[str, list[str]]
    pins: dict[str, Any]
    imus: dict[str, dict[str, Any]]
    gravity: list[float]
    masses: dict[str, dict[str, Any]]
    loads: list[dict[str, Any]]
    urdf_drivers: dict[str, dict[str, Any]]
    urdf_reactions: dict[str, dict[str, Any]]


class ImuDict(TypedDict, total=False):
    """An entry of ``imus``: a sensor on a moving link (``gravity`` m/s^2, ``angle``)."""

    link: str
    point: str
    gravity: list[float]
    angle: float


class _Reader:
    """Typed access to a scene mapping, naming the key in every error."""

    def __init__(self, data: dict[str, Any]) -> None:
        self.data = data
        if 'units' not in data:
            raise SceneError(f'units: missing required key: write {UNITS_EXAMPLES}')
        units = data['units']
        if not isinstance(units, dict):
            msg = f'units: expected a mapping such as {UNITS_EXAMPLES}, got {_kind(units)}'
            raise SceneError(msg)
        unknown = set(units) - {'length', 'angle'}
        if unknown:
            raise SceneError(f'units: expected keys length and angle, got '
                             f'{_brief(sorted(unknown))}')
        for key, table in (('length', LENGTH_UNITS), ('angle', ANGLE_UNITS)):
            if key not in units:
                raise SceneError(f'units.{key}: missing required key ({", ".join(table)}): '
                                 f'write {UNITS_EXAMPLES}')
            if not isinstance(units[key], str) or units[key] not in table:
                raise SceneError(f'units.{key}: expected one of {", ".join(table)}, got '
                                 f'{_brief(units[key])}')
        length, angle = units['length'], units['angle']
        self.per_metre = LENGTH_UNITS[length]
        self.degrees = angle == 'deg'
        self.units = SceneUnits(length, angle)

    @staticmethod
    def get(mapping: Any, key: str, where: str, default: Any = ...) -> Any:
        if not isinstance(mapping, dict):
            raise SceneError(f'{where}: expected a mapping, got {_kind(mapping)}')
        if key not in mapping:
            if default is ...:
                raise SceneError(f'{_join(where, key)}: missing required key')
            return default
        return mapping[key]

    def number(self, mapping: Any, key: str, where: str, default: Any = ...) -> float:
        value = self.get(mapping, key, where, default)
        path = _join(where, key)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise SceneError(f'{path}: expected a number, got {_kind(value)} {_brief(value)}')
        value = float(value)
        if not math.isfinite(value):
            raise SceneError(f'{path}: expected a finite number, got {value!r}')
        return value

    def length(self, mapping: Any, key: str, where: str, positive: bool = True) -> float:
        value = self.number(mapping, key, where)
        if positive and value <= 0.0:
            raise SceneError(f'{_join(where, key)}: expected a positive length, got {value!r}')
        return value / self.per_metre

    def angle(self, mapping: Any, key: str, where: str, default: Any = ...) -> float:
        """Return the direction at ``key``, rad: beyond a turn, reduced exactly to within one.

        Every angle key but the crank's start (:meth:`start_angle`) is a
        direction (a guide's, a slot's, a sensor's axis), which whole turns do
        not change: ``angle: 1e17`` (deg) is the direction -80 deg, read as
        ``angle: -80`` is, to the bit (``math.radians(1e17)`` would be an
        angle of 1.7e15 rad whose cosine has nothing to do with -80 deg).
        """
        return self._split(self.number(mapping, key, where, default))[0]

    def start_angle(self, mapping: Any, key: str, where: str) -> tuple[float, int]:
        """Return the crank angle at ``key`` as (rad within a turn, whole turns).

        An angle beyond a turn is reduced exactly (in degrees as written, or
        in rad with 2 pi to 400 digits), so that 1e308 deg is the same crank
        position as ``solve --angle-deg 1e308``; within a turn it is read as
        written, with no turns.
        """
        return self._split(self.number(mapping, key, where, 0.0))

    def _split(self, value: float) -> tuple[float, int]:
        """Return an angle in the scene's unit as (rad within a turn, whole turns), exactly."""
        if self.degrees:
            return turns_from_degrees(value) if abs(value) > 360.0 else (math.radians(value), 0)
        return reduce_radians(value) if abs(value) > math.tau else (value, 0)

    def name(self, mapping: Any, key: str, where: str) -> str:
        value = self.get(mapping, key, where)
        if not isinstance(value, str):
            raise SceneError(f'{_join(where, key)}: expected a name, got {_kind(value)} '
                             f'{_brief(value)}')
        return value

    def branch(self, mapping: Any, where: str) -> Branch:
        value = self.get(mapping, 'branch', where, 1)
        if isinstance(value, bool) or value not in (1, -1):
            raise SceneError(f'{_join(where, "branch")}: expected +1 or -1, got {_brief(value)}')
        return Branch(int(value))

    def point_xy(self, value: Any, where: str) -> tuple[float, float]:
        if not isinstance(value, list) or len(value) != 2:
            raise SceneError(f'{where}: expected [x, y], got {_brief(value)}')
        x, y = (self.number({f'[{i}]': v}, f'[{i}]', where) for i, v in enumerate(value))
        return x / self.per_metre, y / self.per_metre


def _kind(value: Any) -> str:
    return 'nothing' if value is None else type(value).__name__


def _check_keys(mapping: dict[str, Any], allowed: set[str], where: str) -> None:
    unknown = set(mapping) - allowed
    if unknown:
        raise SceneError(f'{where}: unknown key(s) {_brief(sorted(unknown))}, expected some of '
                         f'{sorted(allowed)}')


def _check_count(where: str, items: Any, limit: int, name: str, what: str) -> None:
    if len(items) > limit:
        msg = f'{where}: expected at most {limit} {what} ({name}), got {len(items)}'
        raise SceneError(msg)


class _Keys:
    """Where each built scene element came from in the file, to name keys in errors."""

    def __init__(self) -> None:
        self.paths: dict[int, tuple[str, dict[str, str]]] = {}

    def build(self, where: str, fields: dict[str, str], factory: Callable[..., T],
              **kwargs: Any) -> T:
        """Build ``factory(**kwargs)`` from the file's key ``where``."""
        try:
            element = factory(**kwargs)
        except SceneError as error:
            field = error.where[1] if error.where is not None else ''
            key = _join(where, fields.get(field, field))
            raise SceneError(f'{key}: {error}') from None
        self.paths[id(element)] = (where, fields)
        return element

    def key(self, error: SceneError) -> str:
        """Return the file key of the element an error names, or ``scene``."""
        if error.where is None:
            return 'scene'
        element, field = error.where
        if id(element) not in self.paths:
            return field or 'scene'
        where, fields = self.paths[id(element)]
        return _join(where, fields.get(field, field))


def parse_scene(data: Any) -> Scene:
    """Build a :class:`Scene` from the mapping of a scene file.

    The mapping is what :func:`read_scene_yaml` returns; ``units`` is required
    and the counts are bounded (:data:`MAX_GROUND_POINTS`, :data:`MAX_DYADS`,
    :data:`MAX_CARRIED_POINTS`).

    Raises
    ------
    SceneError
        Naming the key and the reason.
    """
    if not isinstance(data, dict):
        raise SceneError(f'expected a mapping at the top level, got {_kind(data)}')
    _check_keys(data, set(SceneDict.__annotations__), 'scene')
    reader = _Reader(data)
    name = reader.name(data, 'name', '')
    description = data.get('description', '') or ''
    if not isinstance(description, str):
        raise SceneError(f'description: expected text, got {_kind(description)}')

    ground_data = reader.get(data, 'ground', '')
    if not isinstance(ground_data, dict) or not ground_data:
        raise SceneError(f'ground: expected a mapping of at least one point, got '
                         f'{_brief(ground_data)}')
    _check_count('ground', ground_data, MAX_GROUND_POINTS, 'MAX_GROUND_POINTS', 'points')
    ground = {str(key): reader.point_xy(value, f'ground.{key}')
              for key, value in ground_data.items()}

    keys = _Keys()
    if 'input' in data and 'inputs' in data:
        raise SceneError('inputs: expected either input (one crank) or inputs (a list of '
                         'drivers), got both')
    if 'input' not in data and 'inputs' not in data:
        raise SceneError('input: missing required key (or inputs: a list of drivers)')
    crank: Crank | None = None
    drivers: tuple[Driver, ...] = ()
    reading = _Reading(reader, keys)
    if 'input' in data:
        crank = Crank.from_scene(reading, data['input'], 'input')
    else:
        drivers = _drivers(reading, data['inputs'])
        reading.drivers = {d.name: d for d in drivers}

    dyads_data = data.get('dyads', []) or []
    if not isinstance(dyads_data, list):
        raise SceneError(f'dyads: expected a list, got {_kind(dyads_data)}')
    _check_count('dyads', dyads_data, MAX_DYADS, 'MAX_DYADS', 'dyads')
    dyads = [_dyad(reading, item, f'dyads[{index}]') for index, item in enumerate(dyads_data)]

    points_data = data.get('points', {}) or {}
    if not isinstance(points_data, dict):
        raise SceneError(f'points: expected a mapping, got {_kind(points_data)}')
    _check_count('points', points_data, MAX_CARRIED_POINTS, 'MAX_CARRIED_POINTS', 'points')
    points = [_carried(reader, keys, str(key), value, f'points.{key}')
              for key, value in points_data.items()]

    pins_data = data.get('pins', {}) or {}
    if not isinstance(pins_data, dict):
        raise SceneError(f'pins: expected a mapping of point names to radii, got '
                         f'{_kind(pins_data)}')
    _check_count('pins', pins_data, MAX_PINS, 'MAX_PINS', 'pins')
    pins = [_pin(reader, keys, str(key), value, f'pins.{key}')
            for key, value in pins_data.items()]
    imus = _imus(reader, keys, data.get('imus', {}))
    gravity = None
    if 'gravity' in data:
        gravity = _xy_pair(reader, data['gravity'], 'gravity', 'm/s^2')
        for key, value in (data.get('imus') or {}).items():
            if isinstance(value, dict) and 'gravity' in value:
                given = _xy_pair(reader, value['gravity'], f'imus.{key}.gravity', 'm/s^2')
                if given != gravity:
                    raise SceneError(f"imus.{key}.gravity: expected the scene's gravity "
                                     f'{list(gravity)} m/s^2 (both given must agree), got '
                                     f'{list(given)}')
    masses = _masses(reader, keys, data.get('masses'))
    loads = _loads(reader, keys, data.get('loads'))
    followed = _urdf_drivers(reader, keys, data.get('urdf_drivers'))
    reactions = _urdf_reactions(keys, data.get('urdf_reactions'))

    outputs = data.get('outputs', {}) or {}
    if not isinstance(outputs, dict):
        raise SceneError(f'outputs: expected a mapping, got {_kind(outputs)}')
    _check_keys(outputs, {'points', 'joints'}, 'outputs')
    selected: dict[str, tuple[str, ...] | None] = {}
    for key in ('points', 'joints'):
        value = outputs.get(key)
        if value is not None and (not isinstance(value, list)
                                  or not all(isinstance(v, str) for v in value)):
            raise SceneError(f'outputs.{key}: expected a list of names, got {_brief(value)}')
        selected[key] = None if value is None else tuple(value)

    def build(given: tuple[Load, ...]) -> Scene:
        return Scene(name=name, ground=ground, input=crank, dyads=tuple(dyads),
                     points=tuple(points), outputs_joints=selected['joints'],
                     outputs_points=selected['points'], description=description,
                     pins=tuple(pins), units=reader.units, imus=imus, inputs=drivers,
                     gravity=gravity, masses=masses, loads=given, urdf_drivers=followed,
                     urdf_reactions=reactions)

    try:
        if any(load.table is not None for load in loads):
            loads = _tables_in_si(build(()).joint_types, reader.units, loads, keys)
        return build(loads)
    except SceneError as error:
        raise SceneError(f'{keys.key(error)}: {error}') from None


def _tables_in_si(kinds: Mapping[str, Any], units: Any, loads: tuple[Load, ...],
                  keys: _Keys) -> tuple[Load, ...]:
    """Return ``loads`` with each table's positions in rad (a revolute joint) or m."""
    from dataclasses import replace

    from .units import LENGTH_UNITS, radians_from_degrees

    out = []
    for load in loads:
        if load.table is None or load.table[0] not in kinds:
            out.append(load)    # a joint the scene lacks: the Dynamics says so, naming it
            continue
        joint, rows = load.table
        if kinds[joint].angular:
            convert = radians_from_degrees if units.angle == 'deg' else float
        else:
            per_metre = LENGTH_UNITS[units.length]
            convert = (lambda x: x / per_metre) if per_metre != 1.0 else float
        table = (joint, tuple((convert(x), fx, fy) for x, fx, fy in rows))
        converted = replace(load, table=table)
        keys.paths[id(converted)] = keys.paths.get(id(load), ('', {}))
        out.append(converted)
    return tuple(out)


def _link(reader: _Reader, keys: _Keys, raw: Any, where: str) -> Link:
    if isinstance(raw, dict):
        _check_keys(raw, {'name', 'from', 'length'}, where)
    return keys.build(where, {'start': 'from'}, Link, name=reader.name(raw, 'name', where),
                      start=reader.name(raw, 'from', where),
                      length=reader.length(raw, 'length', where))


def _drivers(reading: _Reading, raw: Any) -> tuple[Driver, ...]:
    """Return the drivers of ``inputs``, each read by the kind its key names (``DRIVERS``)."""
    kinds = ' or '.join(f'{_article(kind.__name__)} {kind.__name__.lower()} (with {key}:)'
                        for key, kind in DRIVERS.items())
    if not isinstance(raw, list) or not raw:
        raise SceneError(f'inputs: expected a list of at least one driver ({kinds}), got '
                         f'{_brief(raw)}')
    _check_count('inputs', raw, MAX_DRIVERS, 'MAX_DRIVERS', 'drivers')
    drivers: list[Driver] = []
    for index, item in enumerate(raw):
        where = f'inputs[{index}]'
        named = [kind for key, kind in DRIVERS.items() if isinstance(item, dict) and key in item]
        if len(named) != 1:
            raise SceneError(f'{where}: expected {kinds}, got {_brief(item)}')
        drivers.append(named[0].from_scene(reading, item, where))
        first = next((i for i, d in enumerate(drivers[:-1]) if d.name == drivers[-1].name), None)
        if first is not None:
            msg = (f'{where}.{drivers[-1].scene_key}: Expected every driver to have a name of its '
                   f'own, got "{drivers[-1].name}" again (the name of inputs[{first}])')
            raise SceneError(msg)
    return tuple(drivers)


def _article(word: str) -> str:
    return 'an' if word[:1].lower() in 'aeiou' else 'a'


def _dyad(reading: _Reading, raw: Any, where: str) -> Item:
    kind = reading.get(raw, 'type', where)
    item = KINDS.get(kind) if isinstance(kind, str) else None
    if item is None:
        *first, last = KINDS
        raise SceneError(f'{where}.type: expected {", ".join(first)} or {last}, got '
                         f'{_brief(kind)}')
    return item.from_scene(reading, raw, where)


class _Reading:
    """The scene reader as a kind reads its keys with it (:class:`~.solver.base.Reading`)."""

    def __init__(self, reader: _Reader, keys: _Keys) -> None:
        self.reader, self.keys = reader, keys
        self.get, self.name, self.length = reader.get, reader.name, reader.length
        self.number = reader.number
        self.angle, self.branch = reader.angle, reader.branch
        self.build = keys.build
        self.start_angle = reader.start_angle
        #: The scene's drivers by name (what a link's ``actuator:`` may name).
        self.drivers: dict[str, Driver] = {}
        #: The key of the link each actuator drives, as the dyads name them.
        self.driven: dict[str, str] = {}

    def actuator_length(self, name: str, where: str) -> float:
        """Return the length at time zero, m, of the scene's actuator ``name``.

        Each actuator is the length of one link: a second link naming it is
        refused at its own key (``where``).
        """
        lengths = {n: d.link_length for n, d in self.drivers.items() if d.link_length is not None}
        if name not in lengths:
            known = ', '.join(lengths) or 'none'
            raise SceneError(f'{where}: expected the name of an actuator of inputs ({known}), '
                             f'got {_brief(name)}')
        if name in self.driven:
            msg = (f'{where}: Expected each actuator to be the length of one link, got '
                   f'"{name}" again (the actuator of {self.driven[name]})')
            raise SceneError(msg)
        self.driven[name] = where.removesuffix('.actuator')
        return lengths[name]

    @staticmethod
    def check_keys(mapping: Any, allowed: set[str], where: str) -> None:
        """Refuse any key of ``mapping`` outside ``allowed``."""
        _check_keys(mapping, allowed, where)

    @staticmethod
    def brief(value: Any) -> str:
        """Return ``value`` shortened for a message."""
        return _brief(value)

    def link(self, raw: Any, where: str) -> Link:
        """Return the link ``{name, from, length}`` at ``where``."""
        return _link(self.reader, self.keys, raw, where)

    def links(self, raw: Any, where: str, count: int, what: str) -> tuple[Link, ...]:
        """Return ``raw['links']``: ``count`` links (``what`` they are, for a refusal)."""
        links = self.reader.get(raw, 'links', where)
        if not isinstance(links, list) or len(links) != count:
            raise SceneError(f'{where}.links: expected a list of {count} links ({what}), got '
                             f'{_brief(links)}')
        return tuple(self.link(item, f'{where}.links[{i}]') for i, item in enumerate(links))


def _carried(reader: _Reader, keys: _Keys, name: str, raw: Any, where: str) -> CarriedPoint:
    if not isinstance(raw, dict):
        raise SceneError(f'{where}: expected a mapping, got {_kind(raw)}')
    link = reader.name(raw, 'link', where)
    if 'from' in raw or 'toward' in raw or 'distance' in raw:
        fields = {'name': '', 'origin': 'from', 'xaxis': 'toward', 'local': 'distance'}
        _check_keys(raw, {'link', 'from', 'toward', 'distance'}, where)
        origin = reader.name(raw, 'from', where)
        xaxis = reader.name(raw, 'toward', where)
        local = (reader.length(raw, 'distance', where, positive=False), 0.0)
    elif 'origin' in raw or 'xaxis' in raw or 'local' in raw:
        fields = {'name': ''}
        _check_keys(raw, {'link', 'origin', 'xaxis', 'local'}, where)
        origin = reader.name(raw, 'origin', where)
        xaxis = reader.name(raw, 'xaxis', where)
        local = reader.point_xy(reader.get(raw, 'local', where), f'{where}.local')
    else:
        raise SceneError(f'{where}: expected either from/toward/distance or '
                         f'origin/xaxis/local, got keys {_brief(sorted(raw))}')
    return keys.build(where, fields, CarriedPoint, name=name, link=link, origin=origin,
                      xaxis=xaxis, local=local)


def _pin(reader: _Reader, keys: _Keys, name: str, raw: Any, where: str) -> Pin:
    bodies = None
    if isinstance(raw, dict):
        _check_keys(raw, {'radius', 'between'}, where)
        radius = reader.length(raw, 'radius', where)
        between = reader.get(raw, 'between', where, None)
        if between is not None:
            if not isinstance(between, list) or len(between) != 2 or not all(
                    isinstance(b, str) for b in between):
                raise SceneError(f'{where}.between: expected the names of the two bodies the '
                                 f'pin joins, e.g. [coupler, rocker], got {_brief(between)}')
            bodies = (between[0], between[1])
    else:
        radius = reader.length({name: raw}, name, 'pins')
    return keys.build(where, {'radius': 'radius', 'bodies': 'between', 'point': ''}, Pin,
                      point=name, radius=radius, bodies=bodies)


def _imus(reader: _Reader, keys: _Keys, raw: Any) -> tuple[ImuSpec, ...]:
    """Read ``imus:``: name -> {link, point, gravity (m/s^2), angle (scene unit)}."""
    raw = raw or {}
    if not isinstance(raw, dict):
        raise SceneError(f'imus: expected a mapping of sensor names to {{link, point}}, got '
                         f'{_kind(raw)}')
    _check_count('imus', raw, MAX_IMUS, 'MAX_IMUS', 'sensors')
    specs = []
    for key, value in raw.items():
        where = f'imus.{key}'
        if not isinstance(value, dict):
            raise SceneError(f'{where}: expected a mapping such as {{link: coupler, point: C, '
                             f'gravity: [0, -9.80665]}}, got {_kind(value)} {_brief(value)}')
        _check_keys(value, set(ImuDict.__annotations__), where)
        gravity = reader.get(value, 'gravity', where, [0.0, 0.0])
        if not isinstance(gravity, list) or len(gravity) != 2:
            raise SceneError(f'{where}.gravity: expected [gx, gy] in m/s^2, got '
                             f'{_brief(gravity)}')
        gx, gy = (reader.number({f'[{i}]': g}, f'[{i}]', f'{where}.gravity')
                  for i, g in enumerate(gravity))
        name = str(key)
        if not IDENTIFIER.match(name):
            raise SceneError(f'{where}: expected a sensor name ([A-Za-z_][A-Za-z0-9_]*), got '
                             f'{_brief(key)}')
        specs.append(keys.build(where, {'name': ''}, ImuSpec, name=name,
                                link=reader.name(value, 'link', where),
                                point=reader.name(value, 'point', where), gravity=(gx, gy),
                                angle=reader.angle(value, 'angle', where, 0.0)))
    return tuple(specs)


def _xy_pair(reader: _Reader, raw: Any, where: str, unit: str,
             length: bool = False) -> tuple[float, float]:
    """Return ``[x, y]`` at ``where`` as two finite numbers (lengths in m where ``length``)."""
    if not isinstance(raw, list) or len(raw) != 2:
        raise SceneError(f'{where}: expected [x, y] in {unit}, got {_brief(raw)}')
    read = reader.length if length else reader.number
    x, y = (read({f'[{i}]': v}, f'[{i}]', where, **({'positive': False} if length else {}))
            for i, v in enumerate(raw))
    return x, y


def _masses(reader: _Reader, keys: _Keys, raw: Any) -> tuple[Mass, ...]:
    """Read ``masses:``: body -> {mass (kg), com ([x, y], scene length), inertia (kg m^2)}."""
    if raw is None:
        return ()
    if not isinstance(raw, dict):
        raise SceneError(f'masses: expected a mapping of bodies to {{mass, com, inertia}}, got '
                         f'{_kind(raw)}')
    _check_count('masses', raw, MAX_MASSES, 'MAX_MASSES', 'bodies')
    masses = []
    for key, value in raw.items():
        where = f'masses.{key}'
        if not isinstance(value, dict):
            raise SceneError(f'{where}: expected a mapping such as {{mass: 0.35, com: [75, 0], '
                             f'inertia: 6.6e-4}}, got {_kind(value)} {_brief(value)}')
        _check_keys(value, {'mass', 'com', 'inertia'}, where)
        com = (_xy_pair(reader, value['com'], f'{where}.com', "the scene's length unit",
                        length=True) if 'com' in value else (0.0, 0.0))
        masses.append(keys.build(where, {'body': ''}, Mass, body=str(key),
                                 mass=reader.number(value, 'mass', where), com=com,
                                 inertia=reader.number(value, 'inertia', where, 0.0)))
    return tuple(masses)


def _urdf_drivers(reader: _Reader, keys: _Keys, raw: Any) -> tuple[FollowedJoint, ...]:
    """Read ``urdf_drivers:``: driver -> {joint, joint_reference, reference, factor} (SI)."""
    if raw is None:
        return ()
    if not isinstance(raw, dict):
        raise SceneError(f'urdf_drivers: expected a mapping of drivers to {{joint, '
                         f'joint_reference, reference, factor}}, got {_kind(raw)}')
    _check_count('urdf_drivers', raw, MAX_DRIVERS, 'MAX_DRIVERS', 'drivers')
    out = []
    fields = ('joint', 'joint_reference', 'reference', 'factor')
    for key, value in raw.items():
        where = f'urdf_drivers.{key}'
        if not isinstance(value, dict):
            raise SceneError(f'{where}: expected a mapping such as {{joint: lift_joint, '
                             f'joint_reference: 0.0, reference: 0.0, factor: -1}}, got '
                             f'{_kind(value)} {_brief(value)}')
        _check_keys(value, set(fields), where)
        joint = reader.get(value, 'joint', where)
        if not isinstance(joint, str):
            raise SceneError(f'{where}.joint: expected a joint name, got {_kind(joint)} '
                             f'{_brief(joint)}')
        out.append(keys.build(where, {'driver': ''}, FollowedJoint, driver=str(key),
                              joint=joint,
                              joint_reference=reader.number(value, 'joint_reference', where),
                              reference=reader.number(value, 'reference', where),
                              factor=reader.number(value, 'factor', where)))
    return tuple(out)


def _urdf_reactions(keys: _Keys, raw: Any) -> tuple[RobotReaction, ...]:
    """Read ``urdf_reactions:``: joint -> {frame, body, at, axes} (a robot's, the writer's)."""
    if raw is None:
        return ()
    if not isinstance(raw, dict):
        raise SceneError(f'urdf_reactions: expected a mapping of joints to {{frame, body, at, '
                         f'axes}}, got {_kind(raw)}')
    _check_count('urdf_reactions', raw, MAX_DRIVERS * 64, 'MAX_DRIVERS * 64', 'joints')
    out = []
    for key, value in raw.items():
        where = f'urdf_reactions.{key}'
        if not isinstance(value, dict):
            raise SceneError(f'{where}: expected a mapping such as {{frame: lower_arm, body: '
                             f'lower_arm, at: lift_joint, axes: [[1, 0, 0], [0, 0, 1]]}}, got '
                             f'{_kind(value)} {_brief(value)}')
        _check_keys(value, {'frame', 'body', 'at', 'axes'}, where)
        missing = [k for k in ('frame', 'body', 'at', 'axes') if k not in value]
        if missing:
            raise SceneError(f'{where}: expected {", ".join(missing)}, got none')
        out.append(keys.build(where, {'joint': ''}, RobotReaction, joint=str(key),
                              frame=value['frame'], body=value['body'], at=value['at'],
                              axes=value['axes']))
    return tuple(out)


def _loads(reader: _Reader, keys: _Keys, raw: Any) -> tuple[Load, ...]:
    """Read ``loads:``: a list of {name, point, force ([fx, fy], N)} or {name, link, torque}."""
    if raw is None:
        return ()
    if not isinstance(raw, list):
        raise SceneError(f'loads: expected a list of loads ({{name, point, force}} or {{name, '
                         f'link, torque}}), got {_kind(raw)}')
    _check_count('loads', raw, MAX_LOADS, 'MAX_LOADS', 'loads')
    loads = []
    for index, value in enumerate(raw):
        where = f'loads[{index}]'
        if not isinstance(value, dict):
            raise SceneError(f'{where}: expected {{name, point, force}} or {{name, link, '
                             f'torque}}, got {_kind(value)} {_brief(value)}')
        _check_keys(value, {'name', 'point', 'force', 'link', 'torque', 'table'}, where)
        force = (_xy_pair(reader, value['force'], f'{where}.force', 'N')
                 if 'force' in value else None)
        table = _load_table(reader, value['table'], f'{where}.table') \
            if 'table' in value else None
        loads.append(keys.build(
            where, {}, Load, name=reader.name(value, 'name', where),
            point=reader.name(value, 'point', where) if 'point' in value else None,
            force=force,
            link=reader.name(value, 'link', where) if 'link' in value else None,
            torque=reader.number(value, 'torque', where) if 'torque' in value else None,
            table=table))
    return tuple(loads)


def _load_table(reader: _Reader, raw: Any, where: str
                ) -> tuple[str, tuple[tuple[float, float, float], ...]]:
    """Read a load's ``table: {joint, rows: [[position, fx, fy], ...]}``, as written.

    Positions in the scene's angle unit for a revolute joint (a link's angle,
    a crank's) and its length unit for a slider (:func:`_tables_in_si` turns
    them into rad or m once the joint's kind is known); forces in N.
    """
    if not isinstance(raw, dict):
        raise SceneError(f'{where}: expected {{joint, rows: [[position, fx, fy], ...]}}, got '
                         f'{_kind(raw)} {_brief(raw)}')
    _check_keys(raw, {'joint', 'rows'}, where)
    joint = reader.name(raw, 'joint', where)
    rows = reader.get(raw, 'rows', where)
    if not isinstance(rows, list) or len(rows) < 2:
        raise SceneError(f'{where}.rows: expected at least two rows [position, fx, fy], got '
                         f'{_brief(rows)}')
    _check_count(f'{where}.rows', rows, MAX_TABLE_ROWS, 'MAX_TABLE_ROWS', 'rows')
    out = []
    for index, row in enumerate(rows):
        at = f'{where}.rows[{index}]'
        if not isinstance(row, list) or len(row) != 3:
            raise SceneError(f'{at}: expected [position, fx, fy], got {_brief(row)}')
        values = [reader.number({'v': v}, 'v', at) for v in row]
        out.append((values[0], values[1], values[2]))
    return joint, tuple(out)


def scene_dirs() -> list[Path]:
    """Folders searched for packaged scenes, first match wins."""
    here = Path(__file__).resolve().parent
    dirs = [here / 'scenes',  # a copy inside the installed package
            here.parent / 'config' / 'scenes',  # the source tree (editable installs)
            Path(sys.prefix) / 'share' / 'mech_kinematics' / 'config' / 'scenes']
    for prefix in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep):
        if prefix:
            dirs.append(Path(prefix) / 'share' / 'mech_kinematics' / 'config' / 'scenes')
    return [d for d in dirs if d.is_dir()]


def scene_names() -> list[str]:
    """Names of the packaged scenes."""
    names: set[str] = set()
    for folder in scene_dirs():
        names.update(path.stem for path in folder.glob('*.yaml'))
    return sorted(names)


def _resolve(source: str | os.PathLike[str]) -> Path:
    path = Path(source)
    if path.suffix in ('.yaml', '.yml') or path.exists() or os.sep in str(source):
        return path
    for folder in scene_dirs():
        candidate = folder / f'{source}.yaml'
        if candidate.is_file():
            return candidate
    msg = (f'{source}: expected a scene file path or a packaged scene name '
           f'({", ".join(scene_names()) or "none found"}), got neither')
    raise SceneError(msg)


_FILE_KINDS = ((stat.S_ISDIR, 'a directory'), (stat.S_ISFIFO, 'a FIFO (named pipe)'),
               (stat.S_ISCHR, 'a character device'), (stat.S_ISBLK, 'a block device'),
               (stat.S_ISSOCK, 'a socket'))


def _file_kind(mode: int) -> str | None:
    """Return what a non-regular file is, or ``None`` for a regular file."""
    if stat.S_ISREG(mode):
        return None
    return next((name for test, name in _FILE_KINDS if test(mode)), 'not a regular file')


def _read_bytes(path: Path) -> bytes:
    """Read a regular file of at most :data:`MAX_FILE_BYTES` without ever blocking.

    ``stat`` refuses a FIFO or a device before it is opened; ``O_NONBLOCK``
    keeps the open from waiting for a writer should the path become a FIFO in
    between, and ``fstat`` on the opened descriptor checks again.
    """
    too_big = f'expected a scene file of at most {MAX_FILE_BYTES} bytes (MAX_FILE_BYTES)'
    try:
        kind = _file_kind(os.stat(path).st_mode)
        if kind is not None:
            raise SceneError(f'{path}: expected a regular file, got {kind}')
        flags = (os.O_RDONLY | getattr(os, 'O_NONBLOCK', 0) | getattr(os, 'O_NOCTTY', 0)
                 | getattr(os, 'O_CLOEXEC', 0))
        fd = os.open(path, flags)
        try:
            info = os.fstat(fd)
            kind = _file_kind(info.st_mode)
            if kind is not None:
                raise SceneError(f'{path}: expected a regular file, got {kind}')
            if info.st_size > MAX_FILE_BYTES:
                raise SceneError(f'{path}: {too_big}, got {info.st_size}')
            chunks = []
            left = MAX_FILE_BYTES + 1  # a file that grows is caught too
            while left > 0:
                chunk = os.read(fd, min(left, 1 << 20))
                if not chunk:
                    break
                chunks.append(chunk)
                left -= len(chunk)
        finally:
            os.close(fd)
    except SceneError:
        raise
    except OSError as error:
        raise SceneError(f'{path}: cannot read: {error.strerror or error}') from None
    except ValueError as error:  # e.g. an embedded null byte in the path
        raise SceneError(f'{str(path)!r}: cannot read: {error}') from None
    data = b''.join(chunks)
    if len(data) > MAX_FILE_BYTES:
        raise SceneError(f'{path}: {too_big}, got more')
    return data


def _decode(path: Path, data: bytes) -> str:
    """Return the file's text, refusing anything but UTF-8 in one line."""
    try:
        text = data.decode('utf-8')
    except UnicodeDecodeError as error:
        line = data.count(b'\n', 0, error.start) + 1
        column = error.start - (data.rfind(b'\n', 0, error.start) + 1) + 1
        msg = (f'{path}: expected UTF-8 text, got byte 0x{data[error.start]:02x} at line '
               f'{line}, column {column} (byte {error.start})')
        raise SceneError(msg) from None
    return text[1:] if text.startswith('\ufeff') else text


#: Longest message :func:`load_scene` gives, characters; a longer one (a
#: long name quoted in it) is shortened in the middle.
MAX_MESSAGE = 400
_LONG_QUOTED = re.compile(r'([\'"])([^\'"]{64,})\1')


def _one_line(message: str) -> str:
    """Return ``message`` on one line of at most :data:`MAX_MESSAGE` characters."""
    message = message.replace('\r', '\\r').replace('\n', '\\n')
    if len(message) > MAX_MESSAGE:  # first shorten long quoted names and values
        message = _LONG_QUOTED.sub(lambda m: f'{m[1]}{m[2][:40]}...{m[2][-16:]}{m[1]}',
                                   message)
    if len(message) > MAX_MESSAGE:
        message = f'{message[:MAX_MESSAGE - 125]} ... {message[-120:]}'
    return message


def scene_text(source: str | os.PathLike[str]) -> str:
    """Return the text of the scene file ``source`` names (a path or a packaged scene name).

    What :func:`load_scene` reads, for a copy (the node publishes it on
    ``scene`` so that a bag holds the scene it was recorded from). Raises
    :class:`SceneError` as :func:`load_scene` does.
    """
    path = _resolve(os.fspath(source))
    return _decode(path, _read_bytes(path))


def load_scene(source: str | os.PathLike[str]) -> Scene:
    """Load a scene from a YAML file or by the name of a packaged scene.

    The file must be a regular file of UTF-8 text within the limits of this
    module (``MAX_*``), in the YAML dialect of :class:`SceneLoader`.

    Parameters
    ----------
    source : str or path
        A path to a scene YAML file, or the name of a scene shipped in
        ``config/scenes/`` (e.g. ``'khurmi_four_bar_ad150'``).

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        With one message naming the file, the key and the reason. No other
        exception escapes, whatever the file holds.
    """
    try:
        path = _resolve(os.fspath(source))
    except SceneError:
        raise
    except (TypeError, ValueError, OSError) as error:
        msg = (f'{_brief(source)}: expected a scene file path or a packaged scene name, got '
               f'neither ({error})')
        raise SceneError(msg) from None
    text = _decode(path, _read_bytes(path))
    try:
        return parse_scene(read_scene_yaml(text))
    except SceneError as error:
        raise SceneError(_one_line(f'{path}: {error}')) from None
    except (ArithmeticError, ValueError) as error:
        # Not expected (the fuzz test checks it never happens), but a solver
        # step failing on extreme values must still give one line.
        msg = f'{path}: scene could not be built: {type(error).__name__}: {error}'
        raise SceneError(_one_line(msg)) from None
