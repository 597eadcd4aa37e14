# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The answers printed in the textbooks behind the shipped scenes: load and evaluate them.

The numbers live in one place, the package data file
``mech_kinematics/data/textbook_answers.yaml``; the golden tests
(``test/test_textbook_answers.py``) and the report's work-precision section
both read them through :func:`textbook_answers`. Pure: the standard library
and PyYAML only.

Each answer (:class:`TextbookAnswer`) has these keys in the file:

``scene``
    Scene name (``config/scenes/<scene>.yaml``); evaluate at the scene's own
    crank angle, speed and acceleration.
``source``
    Seed file of the course notes, problem name, and the book where known
    (the file writes the shared ones once, under ``sources``, as YAML anchors).
``quantity``
    What the book calls the value, and what it means.
``accessor``
    How to get the same quantity from ``mk.solve(...).as_dict()``, in SI:

    - ``{joint: NAME, field: FIELD, mode: abs | signed}``: ``joints[NAME][FIELD]``
      (:class:`JointValue`);
    - ``{point: NAME, field: FIELD}``: the length of ``points[NAME][FIELD]``
      (:class:`PointNorm`);
    - ``{factor: F, product: [[NAME, FIELD, POWER], ...]}``:
      ``F * prod(abs(joints[NAME][FIELD]) ** POWER)`` (:class:`Product`), e.g.
      ``omega**2 * length`` (radial acceleration), ``abs(omega) * length``
      (relative velocity), ``abs(alpha) * s`` (tangential acceleration of a
      slot point at ``s``), ``2 * abs(omega * ds/dt)`` (Coriolis).

    - ``{effort: NAME, factor: F, mode: abs | signed}``: ``F * efforts[NAME]``
      (:class:`EffortValue`), a driver's effort scaled, e.g. ``-1`` for the
      turning moment on a crankshaft (the effort holds the motion against it),
      ``-1 / r`` for the tangential force on its crank pin;
    - ``{reaction: NAME, field: force, component: x | y | norm, mode: abs |
      signed}`` or ``{reaction: NAME, field: normal | moment, mode: ...}``:
      a joint's reaction, ``reactions[NAME][field]``, one component of a
      pin's force or its length (:class:`ReactionValue`).

    FIELD is ``position``, ``velocity`` or ``acceleration`` (for a joint or
    a point). The forces' accessors read a scene with masses, gravity or
    loads (N, N m).
``printed``
    The printed value converted to SI (m, m/s, m/s^2, rad/s, rad/s^2), or in
    degrees where ``unit`` is ``deg`` (:meth:`TextbookAnswer.evaluate` then
    converts the accessor's radians with :mod:`mech_kinematics.units`).
``unit``
    The unit of ``printed``.
``rel_tol``
    Relative tolerance the printed number deserves, measured against the
    solver's value as in the reference JSON files (``rel_diff`` there is
    ``(printed - exact) / exact``): :meth:`TextbookAnswer.within_tolerance`
    checks ``abs(got - printed) <= rel_tol * abs(got)``. The file names three
    (under ``tolerances``): ``computed`` (0.5 %) for numbers the text computes
    from the data (wider where it prints fewer digits), ``measured`` (5 %) for
    values measured on a drawing or derived linearly from one,
    ``measured_squared`` (10 %) for squares, products or ratios of measured
    values; wider still where ``discrepancy`` is true.
``kind``
    ``computed``, ``measured`` or ``derived from measured``.

Optional keys: ``exact`` (the value of the same quantity for the scene as
written; given for the reference scenes and for every discrepancy),
``discrepancy`` (true: the source's number is known to be off; do not test it
tightly), ``unreliable`` (true: the source's diagram is inaccurate there),
``note``.

Scenes ``whitworth``, ``offset_slider_crank`` and ``six_link_slider`` have no
printed answers: their geometry is not a book's (see their descriptions).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache
from importlib import resources
import math
import os
from pathlib import Path
from typing import Any, Literal, NoReturn, TypeAlias

import yaml

from .units import degrees_from_radians

__all__ = ['Accessor', 'EffortValue', 'JointValue', 'PointNorm', 'Product', 'ReactionValue',
           'TextbookAnswer', 'find_answer', 'load_answers', 'textbook_answers']

Field: TypeAlias = Literal['position', 'velocity', 'acceleration']
#: The fields an accessor may read.
FIELDS: tuple[Field, ...] = ('position', 'velocity', 'acceleration')
#: The package data file, inside :mod:`mech_kinematics.data`.
DATA_FILE = 'textbook_answers.yaml'
_KINDS = ('computed', 'measured', 'derived from measured')


@dataclass(frozen=True)
class JointValue:
    """A joint's value: ``joints[name][field]``, signed or its magnitude."""

    name: str
    field: Field
    mode: Literal['abs', 'signed']

    def value(self, state: Mapping[str, Any]) -> float:
        """Return the value from ``state`` (a ``State.as_dict()``), SI."""
        value = float(state['joints'][self.name][self.field])
        return abs(value) if self.mode == 'abs' else value


@dataclass(frozen=True)
class PointNorm:
    """The length of a point's position, velocity or acceleration vector."""

    name: str
    field: Field

    def value(self, state: Mapping[str, Any]) -> float:
        """Return the length from ``state`` (a ``State.as_dict()``), SI."""
        x, y = state['points'][self.name][self.field]
        return math.hypot(x, y)


@dataclass(frozen=True)
class Product:
    """``factor * prod(abs(joints[name][field]) ** power)`` over ``terms``."""

    factor: float
    terms: tuple[tuple[str, Field, int], ...]

    def value(self, state: Mapping[str, Any]) -> float:
        """Return the product from ``state`` (a ``State.as_dict()``), SI."""
        value = self.factor
        for name, field, power in self.terms:
            value *= abs(float(state['joints'][name][field])) ** power
        return value


@dataclass(frozen=True)
class EffortValue:
    """A driver's effort times ``factor``: ``factor * efforts[name]``, signed or its magnitude."""

    name: str
    factor: float
    mode: Literal['abs', 'signed']

    def value(self, state: Mapping[str, Any]) -> float:
        """Return the value from ``state`` (a ``State.as_dict()``), SI."""
        value = self.factor * float(state['efforts'][self.name])
        return abs(value) if self.mode == 'abs' else value


#: The components of a pin's force an answer may read.
COMPONENTS = ('x', 'y', 'norm')


@dataclass(frozen=True)
class ReactionValue:
    """A joint's reaction: ``reactions[name][field]``, a force's component or its length."""

    name: str
    field: Literal['force', 'normal', 'moment']
    component: Literal['x', 'y', 'norm'] | None
    mode: Literal['abs', 'signed']

    def value(self, state: Mapping[str, Any]) -> float:
        """Return the value from ``state`` (a ``State.as_dict()``), SI."""
        raw = state['reactions'][self.name][self.field]
        if self.component == 'norm':
            return math.hypot(*raw)
        value = float(raw[COMPONENTS.index(self.component)]) if self.component else float(raw)
        return abs(value) if self.mode == 'abs' else value


Accessor: TypeAlias = JointValue | PointNorm | Product | EffortValue | ReactionValue


@dataclass(frozen=True)
class TextbookAnswer:
    """One printed answer, its source and the accuracy it deserves (see the module doc)."""

    scene: str
    source: str
    quantity: str
    accessor: Accessor
    printed: float          # in `unit`
    unit: str
    rel_tol: float          # relative, against the solver's value
    kind: str               # 'computed', 'measured' or 'derived from measured'
    exact: float | None = None
    discrepancy: bool = False
    unreliable: bool = False
    note: str | None = None

    def evaluate(self, state: Mapping[str, Any]) -> float:
        """Return the answer's quantity from ``state`` (a ``State.as_dict()``), in ``unit``."""
        value = self.accessor.value(state)
        return float(degrees_from_radians(value)) if self.unit == 'deg' else value

    def within_tolerance(self, got: float) -> bool:
        """Return True if the solver's value ``got`` matches :attr:`printed` within ``rel_tol``."""
        return abs(got - self.printed) <= self.rel_tol * abs(got)


class _Reader:
    """Checks one answer's keys and types; every message names the file and the entry."""

    def __init__(self, where: str) -> None:
        self.where = where

    def fail(self, key: str, expected: str, got: Any) -> NoReturn:
        msg = f'{self.where}{"." + key if key else ""}: expected {expected}, got {got!r}'
        raise ValueError(msg)

    def text(self, raw: Mapping[str, Any], key: str) -> str:
        value = raw.get(key)
        if not isinstance(value, str) or not value:
            self.fail(key, 'a non-empty string', value)
        return str(value)

    def number(self, raw: Mapping[str, Any], key: str) -> float:
        value = raw.get(key)
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or not math.isfinite(value):
            self.fail(key, 'a finite number', value)
        return float(value)

    def field(self, raw: Mapping[str, Any], key: str) -> Field:
        value = raw.get(key)
        for field in FIELDS:
            if value == field:
                return field
        self.fail(key, f'one of {", ".join(FIELDS)}', value)

    def accessor(self, raw: Any) -> Accessor:
        where = _Reader(f'{self.where}.accessor')
        if not isinstance(raw, dict):
            self.fail('accessor', 'a mapping', raw)
        if set(raw) == {'joint', 'field', 'mode'}:
            mode = raw['mode']
            if mode not in ('abs', 'signed'):
                where.fail('mode', 'abs or signed', mode)
            return JointValue(where.text(raw, 'joint'), where.field(raw, 'field'),
                              'abs' if mode == 'abs' else 'signed')
        if set(raw) == {'point', 'field'}:
            return PointNorm(where.text(raw, 'point'), where.field(raw, 'field'))
        if set(raw) == {'factor', 'product'}:
            terms = []
            for index, term in enumerate(raw['product'] or ()):
                if not (isinstance(term, list) and len(term) == 3
                        and isinstance(term[2], int) and not isinstance(term[2], bool)):
                    where.fail(f'product[{index}]', '[NAME, FIELD, POWER]', term)
                name, field, power = term
                item = {'name': name, 'field': field}
                inner = _Reader(f'{where.where}.product[{index}]')
                terms.append((inner.text(item, 'name'), inner.field(item, 'field'), power))
            if not terms:
                where.fail('product', 'at least one [NAME, FIELD, POWER]', raw['product'])
            return Product(where.number(raw, 'factor'), tuple(terms))
        if set(raw) == {'effort', 'factor', 'mode'}:
            return EffortValue(where.text(raw, 'effort'), where.number(raw, 'factor'),
                               where.mode(raw))
        if set(raw) in ({'reaction', 'field', 'component', 'mode'}, {'reaction', 'field', 'mode'}):
            field, component = raw['field'], raw.get('component')
            if field == 'force' and component not in COMPONENTS:
                where.fail('component', f'one of {", ".join(COMPONENTS)} for a force', component)
            if field in ('normal', 'moment') and component is not None:
                where.fail('component', f'none for a {field}', component)
            if field not in ('force', 'normal', 'moment'):
                where.fail('field', 'force, normal or moment', field)
            return ReactionValue(where.text(raw, 'reaction'), field, component,
                                 where.mode(raw))
        self.fail('accessor', 'keys joint/field/mode, point/field, factor/product, '
                  'effort/factor/mode or reaction/field/component/mode', sorted(raw))

    def mode(self, raw: Mapping[str, Any]) -> Literal['abs', 'signed']:
        value = raw.get('mode')
        if value not in ('abs', 'signed'):
            self.fail('mode', 'abs or signed', value)
        return 'abs' if value == 'abs' else 'signed'

    def flag(self, raw: Mapping[str, Any], key: str) -> bool:
        value = raw.get(key, False)
        if not isinstance(value, bool):
            self.fail(key, 'true or false', value)
        return bool(value)


_KEYS = {'scene', 'source', 'quantity', 'accessor', 'printed', 'unit', 'rel_tol', 'kind',
         'exact', 'discrepancy', 'unreliable', 'note'}


def _answer(raw: Any, where: str) -> TextbookAnswer:
    reader = _Reader(where)
    if not isinstance(raw, dict):
        reader.fail('', 'a mapping', raw)
    unknown = set(raw) - _KEYS
    if unknown:
        reader.fail('', f'keys among {sorted(_KEYS)}', sorted(unknown))
    kind = reader.text(raw, 'kind')
    if kind not in _KINDS:
        reader.fail('kind', f'one of {", ".join(_KINDS)}', kind)
    rel_tol = reader.number(raw, 'rel_tol')
    if not 0 < rel_tol < 1:
        reader.fail('rel_tol', 'a relative tolerance in (0, 1)', rel_tol)
    discrepancy = reader.flag(raw, 'discrepancy')
    exact = reader.number(raw, 'exact') if 'exact' in raw else None
    if discrepancy and exact is None:
        reader.fail('exact', 'the exact value beside a discrepancy', None)
    return TextbookAnswer(
        scene=reader.text(raw, 'scene'), source=reader.text(raw, 'source'),
        quantity=reader.text(raw, 'quantity'), accessor=reader.accessor(raw.get('accessor')),
        printed=reader.number(raw, 'printed'), unit=reader.text(raw, 'unit'), rel_tol=rel_tol,
        kind=kind, exact=exact, discrepancy=discrepancy,
        unreliable=reader.flag(raw, 'unreliable'),
        note=reader.text(raw, 'note') if 'note' in raw else None)


def load_answers(path: str | os.PathLike[str]) -> tuple[TextbookAnswer, ...]:
    """Read a textbook-answers file (the format of the packaged one).

    Raises
    ------
    ValueError
        Naming the file and the entry, if the file is not valid.
    """
    return _parse(Path(path).read_text(encoding='utf-8'), str(path))


def _parse(text: str, name: str) -> tuple[TextbookAnswer, ...]:
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as error:
        msg = f'{name}: invalid YAML: {error}'
        raise ValueError(msg) from None
    answers = data.get('answers') if isinstance(data, dict) else None
    if not isinstance(answers, list) or not answers:
        msg = f'{name}: expected a non-empty list under "answers", got {answers!r}'
        raise ValueError(msg)
    return tuple(_answer(raw, f'{name}: answers[{index}]') for index, raw in enumerate(answers))


@cache
def textbook_answers() -> tuple[TextbookAnswer, ...]:
    """Return the packaged printed answers, in the file's order (read once)."""
    resource = resources.files('mech_kinematics.data').joinpath(DATA_FILE)
    return _parse(resource.read_text(encoding='utf-8'), DATA_FILE)


def find_answer(scene: str, quantity: str) -> TextbookAnswer:
    """Return the packaged answer for ``scene`` whose quantity is ``quantity``.

    Raises
    ------
    KeyError
        If there is no such answer.
    """
    for answer in textbook_answers():
        if answer.scene == scene and answer.quantity == quantity:
            return answer
    msg = f'Expected a printed answer for scene {scene!r}, quantity {quantity!r}, got none'
    raise KeyError(msg)
