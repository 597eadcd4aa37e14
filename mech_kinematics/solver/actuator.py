# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The linear actuator: a driver whose input is a length (a hydraulic cylinder, a lead screw).

An actuator is one of a scene's drivers (``inputs:``), beside cranks. Its
position is its length between its two pins (m), its velocity the extension
rate and its acceleration the rate's derivative; it is reported as a
prismatic joint named after it. An ``RRR`` link that says ``actuator: NAME``
instead of ``length:`` has that length (:mod:`.rrr`). Optional stroke limits
are inclusive: a length outside them is refused like a position at which the
mechanism cannot assemble.

This module owns everything about it: its scene keys (:meth:`Actuator.from_scene`),
its validation, its step (which writes its length, rate and acceleration with
their error bounds into the context's ``sliders``), its joint type, the floors
it adds to the scales of a state, and the text of its refusal.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
import math
from typing import Any, TYPE_CHECKING

from .base import Driver, Rate, RateParameter
from .context import _Context
from .graph import Fragment, JointType, PRISMATIC
from .model import _check_finite, _check_length, _check_name, _g, SceneUnits
from ..bounds import U
from ..errors import SceneError

if TYPE_CHECKING:
    from .base import Item

#: The scene keys of an actuator in ``inputs:``.
KEYS = {'actuator', 'length', 'speed', 'accel', 'stroke'}


@dataclass(frozen=True)
class Actuator(Driver):
    """A linear actuator driving the mechanism: its length is an input.

    Parameters
    ----------
    actuator : str
        Its name: a prismatic joint in the output, and the name an ``RRR``
        link's ``actuator:`` refers to.
    length : float
        Its length at time zero, m (> 0).
    speed : float
        Default extension rate, m/s, signed.
    accel : float
        Default acceleration of its length, m/s^2, signed.
    stroke : (float, float) or None
        Inclusive limits ``(shortest, longest)`` of its length, m; ``None``: any
        positive length.
    """

    position_key = 'length'
    v1_crank = False
    scene_key = 'actuator'

    actuator: str
    length: float
    speed: float = 0.0
    accel: float = 0.0
    stroke: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.actuator, 'the actuator name', (self, 'actuator'))
        _check_length(self.length, f'actuator "{self.actuator}" length', (self, 'length'))
        _check_finite(self.speed, f'actuator "{self.actuator}" speed', (self, 'speed'))
        _check_finite(self.accel, f'actuator "{self.actuator}" acceleration', (self, 'accel'))
        if self.stroke is not None:
            low, high = self.stroke
            _check_length(low, f'actuator "{self.actuator}" shortest length', (self, 'stroke'))
            _check_length(high, f'actuator "{self.actuator}" longest length', (self, 'stroke'))
            if not low <= high:
                msg = (f'Expected the stroke of actuator "{self.actuator}" as [shortest, '
                       f'longest], got [{_g(low)}, {_g(high)}] m')
                raise SceneError(msg, (self, 'stroke'))
            if not low <= self.length <= high:
                msg = (f'Expected the length of actuator "{self.actuator}" at time zero within '
                       f'its stroke [{_g(low)}, {_g(high)}] m, got {_g(self.length)} m')
                raise SceneError(msg, (self, 'length'))

    @classmethod
    def from_scene(cls, read: Any, raw: Any, where: str) -> Actuator:
        """Return the actuator written at ``where`` (an entry of ``inputs:``), its keys checked.

        ``read`` is the scene reader (:class:`~.base.Reading`): ``length`` and
        ``stroke`` are in the scene's length unit; ``speed`` and ``accel``
        always in m/s and m/s^2.
        """
        read.check_keys(raw, KEYS, where)
        stroke = read.get(raw, 'stroke', where, None)
        limits = None
        if stroke is not None:
            if not isinstance(stroke, list) or len(stroke) != 2:
                msg = (f'{where}.stroke: expected [shortest, longest] lengths, got '
                       f'{read.brief(stroke)}')
                raise SceneError(msg)
            low, high = (read.length({f'stroke[{i}]': value}, f'stroke[{i}]', where)
                         for i, value in enumerate(stroke))
            limits = (low, high)
        number = read.number
        built: Actuator = read.build(
            where, {}, cls, actuator=read.name(raw, 'actuator', where),
            length=read.length(raw, 'length', where),
            speed=number(raw, 'speed', where, 0.0), accel=number(raw, 'accel', where, 0.0),
            stroke=limits)
        return built

    @property
    def link_length(self) -> float:
        """Its length at time zero, m: the nominal length of the RRR link it sets."""
        return self.length

    @property
    def name(self) -> str:
        """The driver's name: the actuator (its prismatic joint)."""
        return self.actuator

    @property
    def joint_type(self) -> JointType:
        """The driver's joint type: prismatic."""
        return PRISMATIC

    @property
    def start(self) -> float:
        """The driver's position at time zero: its length, m."""
        return self.length

    @property
    def turns(self) -> int:
        """0: an actuator does not turn."""
        return 0

    @property
    def rate(self) -> Rate:
        """Its extension rate as the scene gives it: ``speed``, m/s."""
        return Rate('speed', self.speed, 'm/s')

    @property
    def rate_parameter(self) -> RateParameter:
        """Its extension rate is set in m/s, as ``speed``."""
        return RateParameter('speed', 'm/s')

    @property
    def reach(self) -> float:
        """Its longest length, m: what it adds to the mechanism's size."""
        return self.length if self.stroke is None else max(self.length, self.stroke[1])

    @property
    def described(self) -> str:
        """What it is: an actuator."""
        return 'actuator'

    def sweep(self, free: float) -> tuple[float, float]:
        """Return its stroke, or lengths up to ``free``, m (a length is positive)."""
        return (0.0, free) if self.stroke is None else self.stroke

    def position_text(self, value: float, units: SceneUnits) -> str:
        """Return a length (m) of it as text in the scene's unit."""
        return units.length_text(value)

    def scaled(self, scale: Callable[[float], float]) -> Actuator:
        """Return it with its lengths scaled (its rates are scaled at run time)."""
        stroke = None if self.stroke is None else (scale(self.stroke[0]), scale(self.stroke[1]))
        return replace(self, length=scale(self.length), stroke=stroke)

    def fragment(self) -> Fragment:
        """Return its part of the graph: its coordinate (its barrel and rod are an RRR's)."""
        return Fragment(self.actuator, coordinates={self.actuator: PRISMATIC})

    def check_used(self, users: Sequence[Item]) -> None:
        """Refuse it unless exactly one item uses it (an RRR link's length, a collar's)."""
        name = self.actuator
        if not users:
            msg = (f'Expected actuator "{name}" to be the length of an RRR link '
                   f'(actuator: {name} in place of length:) or the distance of a collar '
                   f'(actuator: {name}), got no link or collar using it')
            raise SceneError(msg, (self, 'actuator'))
        if len(users) > 1:
            first, again = users[:2]
            msg = (f'Expected each actuator to be the length of one link, got "{name}" in '
                   f'{first.kind} {first.key} and again in {again.kind} {again.key}')
            raise SceneError(msg, (again, ''))

    def defined(self) -> tuple[tuple[str, str], ...]:
        """Return (name, kind) of the names it defines: its prismatic joint."""
        return ((self.actuator, 'actuator'),)

    def local(self, ground: Any) -> dict[str, dict[str, complex]]:
        """Return the points fixed on links it moves: none (its pins are a dyad's)."""
        return {}

    def step(self, ground: Any) -> _ActuatorStep:
        """Return its step."""
        return _ActuatorStep(self)

    @staticmethod
    def fact_texts() -> dict[str, Callable[[dict[str, Any], SceneUnits], str]]:
        """Return the text of a length outside the stroke (or not positive)."""
        return {'stroke': _stroke_text}


def _stroke_text(facts: dict[str, Any], units: SceneUnits) -> str:
    """Return why an actuator's length is refused, in the scene's units."""
    text = units.length_text
    name, length, stroke = facts['actuator'], facts['length'], facts['stroke']
    if stroke is None:
        return f'actuator {name}: expected a positive length, got {text(length)}'
    low, high = stroke
    return (f'actuator {name}: expected a length within its stroke [{text(low, length)}, '
            f'{text(high, length)}], got {text(length, low, high)}')


class _ActuatorStep:
    """The actuator's kernel: its length, rate and acceleration into ``ctx.sliders``."""

    joint_type = PRISMATIC

    def __init__(self, actuator: Actuator) -> None:
        self.name = actuator.actuator
        self.label = f'input {actuator.actuator}'
        self.point = None
        self.length = 1.0
        self.stroke = actuator.stroke
        self.low, self.high = (0.0, math.inf) if actuator.stroke is None else actuator.stroke
        self.unit = 1.0
        self.uses: tuple[str, ...] = ()
        self.defines = (actuator.actuator,)

    def facts(self, length: float) -> dict[str, Any]:
        """Return why the length is refused, for a message in the scene's units."""
        m = self.unit
        stroke = None if self.stroke is None else (self.low * m, self.high * m)
        return {'kind': 'stroke', 'actuator': self.name, 'stroke': stroke,
                'length': float(length) * m}

    def reason(self, length: float) -> str:
        """Return why the length is refused, SI units."""
        m = self.unit
        if self.stroke is None:
            return f'expected a positive length of actuator {self.name}, got {_g(length * m)} m'
        return (f'expected the length of actuator {self.name} within its stroke '
                f'[{_g(self.low * m)}, {_g(self.high * m)}] m, got {_g(length * m)} m')

    def run(self, ctx: _Context, s: Any, sd: Any, sdd: Any) -> None:
        # The stroke is inclusive; a length is positive whatever its stroke.
        ok = (s >= self.low) & (s <= self.high) & (s > 0.0)
        if ctx.vector or not ok:
            ctx.check(ok, self.label, lambda: self.reason(s), lambda: self.facts(s))
        # The inputs are known to half an ulp each.
        ctx.sliders[self.name] = (s, sd, sdd, U * abs(s), U * abs(sd), U * abs(sdd))

    def floors(self, speed: Any, accel: Any, size: float) -> tuple[Any, Any, Any, Any]:
        """Return what it adds to the least scales: those of a linear driver."""
        return linear_floors(speed, accel, size)


def linear_floors(speed: Any, accel: Any, size: float) -> tuple[Any, Any, Any, Any]:
    """Return what a linear driver adds to the least scales: speed, acceleration, turning rates.

    Its rate ``|v|`` (m/s) and ``|a| + v^2 / size`` (m/s^2, the acceleration
    of a link of the mechanism's size turned by it), and those over the size
    for the angular kinds. An actuator's and a driven slider's.
    """
    v = abs(speed)
    a = abs(accel) + v * v / size
    return v, a, v / size, a / size
