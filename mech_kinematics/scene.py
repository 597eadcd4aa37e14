# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Read scene YAML files (SCENE_FORMAT.md, version 2) into :class:`Scene` objects."""

from __future__ import annotations

from collections.abc import Callable
import math
import os
from pathlib import Path
import sys
from typing import Any, TypedDict, TypeVar

import yaml

from .errors import SceneError
from .linkage import Branch, CarriedPoint, Crank, Link, RPR, RRP, RRR, Scene
from .units import ANGLE_UNITS, LENGTH_UNITS, rad_per_s_from_rpm

__all__ = ['load_scene', 'parse_scene', 'scene_dirs', 'scene_names', 'DEFAULT_SCENE']

#: The packaged scene that the node and ``make run`` use by default.
DEFAULT_SCENE = 'khurmi_four_bar_ad150'

#: The two spellings of ``units`` every refusal of a missing or bad one shows.
UNITS_EXAMPLES = 'units: {length: mm, angle: deg} or units: {length: m, angle: rad}'

T = TypeVar('T')


class LinkDict(TypedDict):
    """A link of a dyad: ``{name, from, length}``."""

    name: str
    length: float


class InputDict(TypedDict, total=False):
    """The ``input`` key: the driving crank."""

    link: str
    center: str
    point: str
    length: float
    angle: float
    speed_rpm: float
    accel: float


class SceneDict(TypedDict, total=False):
    """A scene file's top level."""

    name: str
    description: str
    units: dict[str, str]
    ground: dict[str, list[float]]
    input: InputDict
    dyads: list[dict[str, Any]]
    points: dict[str, dict[str, Any]]
    outputs: dict[str, list[str]]


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
            raise SceneError(f'units: expected keys length and angle, got {sorted(unknown)}')
        for key, table in (('length', LENGTH_UNITS), ('angle', ANGLE_UNITS)):
            if key not in units:
                raise SceneError(f'units.{key}: missing required key ({", ".join(table)}): '
                                 f'write {UNITS_EXAMPLES}')
            if not isinstance(units[key], str) or units[key] not in table:
                raise SceneError(f'units.{key}: expected one of {", ".join(table)}, got '
                                 f'{units[key]!r}')
        length, angle = units['length'], units['angle']
        self.per_metre = LENGTH_UNITS[length]
        self.degrees = angle == 'deg'

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
            raise SceneError(f'{path}: expected a number, got {_kind(value)} {value!r}')
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
        value = self.number(mapping, key, where, default)
        return math.radians(value) if self.degrees else value

    def name(self, mapping: Any, key: str, where: str) -> str:
        value = self.get(mapping, key, where)
        if not isinstance(value, str):
            raise SceneError(f'{_join(where, key)}: expected a name, got {_kind(value)} '
                             f'{value!r}')
        return value

    def branch(self, mapping: Any, where: str) -> Branch:
        value = self.get(mapping, 'branch', where, 1)
        if isinstance(value, bool) or value not in (1, -1):
            raise SceneError(f'{_join(where, "branch")}: expected +1 or -1, got {value!r}')
        return Branch(int(value))

    def point_xy(self, value: Any, where: str) -> tuple[float, float]:
        if not isinstance(value, list) or len(value) != 2:
            raise SceneError(f'{where}: expected [x, y], got {value!r}')
        x, y = (self.number({f'[{i}]': v}, f'[{i}]', where) for i, v in enumerate(value))
        return x / self.per_metre, y / self.per_metre


def _kind(value: Any) -> str:
    return 'nothing' if value is None else type(value).__name__


def _join(where: str, key: str) -> str:
    if not where or not key:
        return where or key
    return f'{where}{key}' if key.startswith('[') else f'{where}.{key}'


def _check_keys(mapping: dict[str, Any], allowed: set[str], where: str) -> None:
    unknown = set(mapping) - allowed
    if unknown:
        raise SceneError(f'{where}: unknown key(s) {sorted(unknown)}, expected some of '
                         f'{sorted(allowed)}')


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
                         f'{ground_data!r}')
    ground = {str(key): reader.point_xy(value, f'ground.{key}')
              for key, value in ground_data.items()}

    keys = _Keys()
    raw = reader.get(data, 'input', '')
    _check_keys(raw if isinstance(raw, dict) else {}, set(InputDict.__annotations__), 'input')
    rpm = reader.number(raw, 'speed_rpm', 'input', 0.0)
    crank = keys.build(
        'input', {'speed': 'speed_rpm'}, Crank,
        link=reader.name(raw, 'link', 'input'), center=reader.name(raw, 'center', 'input'),
        point=reader.name(raw, 'point', 'input'), length=reader.length(raw, 'length', 'input'),
        angle=reader.angle(raw, 'angle', 'input', 0.0), speed=rad_per_s_from_rpm(rpm),
        accel=reader.number(raw, 'accel', 'input', 0.0))

    dyads_data = data.get('dyads', []) or []
    if not isinstance(dyads_data, list):
        raise SceneError(f'dyads: expected a list, got {_kind(dyads_data)}')
    dyads = [_dyad(reader, keys, item, f'dyads[{index}]')
             for index, item in enumerate(dyads_data)]

    points_data = data.get('points', {}) or {}
    if not isinstance(points_data, dict):
        raise SceneError(f'points: expected a mapping, got {_kind(points_data)}')
    points = [_carried(reader, keys, str(key), value, f'points.{key}')
              for key, value in points_data.items()]

    outputs = data.get('outputs', {}) or {}
    if not isinstance(outputs, dict):
        raise SceneError(f'outputs: expected a mapping, got {_kind(outputs)}')
    _check_keys(outputs, {'points', 'joints'}, 'outputs')
    selected: dict[str, tuple[str, ...] | None] = {}
    for key in ('points', 'joints'):
        value = outputs.get(key)
        if value is not None and (not isinstance(value, list)
                                  or not all(isinstance(v, str) for v in value)):
            raise SceneError(f'outputs.{key}: expected a list of names, got {value!r}')
        selected[key] = None if value is None else tuple(value)

    try:
        return Scene(name=name, ground=ground, input=crank, dyads=tuple(dyads),
                     points=tuple(points), outputs_joints=selected['joints'],
                     outputs_points=selected['points'], description=description)
    except SceneError as error:
        raise SceneError(f'{keys.key(error)}: {error}') from None


def _link(reader: _Reader, keys: _Keys, raw: Any, where: str) -> Link:
    if isinstance(raw, dict):
        _check_keys(raw, {'name', 'from', 'length'}, where)
    return keys.build(where, {'start': 'from'}, Link, name=reader.name(raw, 'name', where),
                      start=reader.name(raw, 'from', where),
                      length=reader.length(raw, 'length', where))


def _dyad(reader: _Reader, keys: _Keys, raw: Any, where: str) -> RRR | RRP | RPR:
    kind = reader.get(raw, 'type', where)
    if kind == 'RRR':
        _check_keys(raw, {'type', 'point', 'links', 'branch'}, where)
        links = reader.get(raw, 'links', where)
        if not isinstance(links, list) or len(links) != 2:
            raise SceneError(f'{where}.links: expected a list of 2 links, got {links!r}')
        first, second = (_link(reader, keys, link, f'{where}.links[{i}]')
                         for i, link in enumerate(links))
        return keys.build(where, {}, RRR, point=reader.name(raw, 'point', where),
                          links=(first, second), branch=reader.branch(raw, where))
    if kind == 'RRP':
        _check_keys(raw, {'type', 'point', 'link', 'guide', 'slider', 'branch'}, where)
        link = _link(reader, keys, reader.get(raw, 'link', where), f'{where}.link')
        guide = reader.get(raw, 'guide', where)
        if isinstance(guide, dict):
            _check_keys(guide, {'through', 'angle'}, f'{where}.guide')
        return keys.build(
            where, {'through': 'guide.through', 'guide_angle': 'guide.angle'}, RRP,
            point=reader.name(raw, 'point', where),
            link=link, through=reader.name(guide, 'through', f'{where}.guide'),
            guide_angle=reader.angle(guide, 'angle', f'{where}.guide', 0.0),
            slider=reader.name(raw, 'slider', where), branch=reader.branch(raw, where))
    if kind == 'RPR':
        _check_keys(raw, {'type', 'link', 'center', 'through', 'slider'}, where)
        return keys.build(
            where, {}, RPR, link=reader.name(raw, 'link', where),
            center=reader.name(raw, 'center', where), through=reader.name(raw, 'through', where),
            slider=reader.name(raw, 'slider', where))
    raise SceneError(f'{where}.type: expected RRR, RRP or RPR, got {kind!r}')


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
                         f'origin/xaxis/local, got keys {sorted(raw)}')
    return keys.build(where, fields, CarriedPoint, name=name, link=link, origin=origin,
                      xaxis=xaxis, local=local)


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


def load_scene(source: str | os.PathLike[str]) -> Scene:
    """Load a scene from a YAML file or by the name of a packaged scene.

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
        With one message naming the file, the key and the reason.
    """
    path = _resolve(source)
    try:
        text = path.read_text(encoding='utf-8')
    except OSError as error:
        raise SceneError(f'{path}: cannot read: {error.strerror or error}') from None
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as error:
        mark = getattr(error, 'problem_mark', None)
        at = f' at line {mark.line + 1}, column {mark.column + 1}' if mark else ''
        problem = getattr(error, 'problem', None) or str(error)
        raise SceneError(f'{path}: invalid YAML{at}: {problem}') from None
    try:
        return parse_scene(data)
    except SceneError as error:
        raise SceneError(f'{path}: {error}') from None
