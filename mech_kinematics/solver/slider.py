# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The driven slider: a block on a fixed straight guide whose position is an input.

A slider is one of a scene's drivers (``inputs:``), beside cranks and
actuators: a slider-crank driven from its piston, a double slider (an
elliptic trammel) driven by one of its blocks. Its position is the signed
distance of its pin from a ground point along the guide (m, + along the
guide's direction), its velocity and acceleration that distance's rates; it
is reported as a prismatic joint named after it. The pin is a point every
dyad may start from, as a crank's tip is, so the loop it drives is solved in
closed form by the dyads that follow it (an RRR from the pin and a ground
point is a slider-crank driven from its piston). Optional stroke limits are
inclusive: a position outside them is refused like a position at which the
mechanism cannot assemble.

This module owns everything about it: its scene keys (:meth:`Slider.from_scene`),
its validation, its part of the graph (the block, its driven prismatic joint
on the ground), its step (the pin's position, velocity and acceleration with
their error bounds, and its coordinate), the floors it adds to the scales of
a state, and the text of its refusal.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
import math
from typing import Any, TYPE_CHECKING

from .actuator import linear_floors
from .base import Driver, Rate, RateParameter
from .context import _Context, _U2
from .graph import Body, Fragment, Frame, JointType, Line, PRISMATIC, Role, slide, THE_GROUND
from .model import _check_finite, _check_name, _g, SceneUnits
from ..bounds import U
from ..errors import SceneError

if TYPE_CHECKING:
    from .base import Item, Reading

#: The scene keys of a driven slider in ``inputs:``.
KEYS = {'slider', 'point', 'guide', 'position', 'speed', 'accel', 'stroke'}


@dataclass(frozen=True)
class Slider(Driver):
    """A block on a fixed guide driving the mechanism: its position is an input.

    Parameters
    ----------
    slider : str
        Its name: the block, and its prismatic joint in the output.
    point : str
        Its pin: the point it places, which dyads may start from.
    through : str
        The ground point its position is measured from, on the guide.
    guide_angle : float
        The guide's direction, rad CCW from +x: positions grow along it.
    position : float
        The pin's signed distance from ``through`` along the guide at time zero, m.
    speed : float
        Default velocity along the guide, m/s, signed.
    accel : float
        Default acceleration along the guide, m/s^2, signed.
    stroke : (float, float) or None
        Inclusive limits ``(lowest, highest)`` of its position, m; ``None``: any.
    """

    position_key = 'position'
    v1_crank = False
    scene_key = 'slider'

    slider: str
    point: str
    through: str
    guide_angle: float
    position: float
    speed: float = 0.0
    accel: float = 0.0
    stroke: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.slider, 'the slider name', (self, 'slider'))
        _check_name(self.point, f'the pin of slider "{self.slider}"', (self, 'point'))
        _check_name(self.through, f'the guide point of slider "{self.slider}"',
                    (self, 'through'))
        what = f'slider "{self.slider}"'
        _check_finite(self.guide_angle, f'the guide angle of {what}', (self, 'guide_angle'))
        _check_finite(self.position, f'the position of {what}', (self, 'position'))
        _check_finite(self.speed, f'the speed of {what}', (self, 'speed'))
        _check_finite(self.accel, f'the acceleration of {what}', (self, 'accel'))
        if self.point == self.through:
            msg = (f'Expected the pin of {what} to be a point of its own, got its guide point '
                   f'"{self.through}"')
            raise SceneError(msg, (self, 'point'))
        if self.stroke is not None:
            low, high = self.stroke
            _check_finite(low, f'the lowest position of {what}', (self, 'stroke'))
            _check_finite(high, f'the highest position of {what}', (self, 'stroke'))
            if not low <= high:
                msg = (f'Expected the stroke of {what} as [lowest, highest], got '
                       f'[{_g(low)}, {_g(high)}] m')
                raise SceneError(msg, (self, 'stroke'))
            if not low <= self.position <= high:
                msg = (f'Expected the position of {what} at time zero within its stroke '
                       f'[{_g(low)}, {_g(high)}] m, got {_g(self.position)} m')
                raise SceneError(msg, (self, 'position'))

    @classmethod
    def from_scene(cls, read: Reading, raw: Any, where: str) -> Slider:
        """Return the slider written at ``where`` (an entry of ``inputs:``), its keys checked.

        ``position`` and ``stroke`` are in the scene's length unit, ``guide.angle``
        in its angle unit; ``speed`` and ``accel`` always in m/s and m/s^2.
        """
        read.check_keys(raw, KEYS, where)
        guide = read.get(raw, 'guide', where)
        if isinstance(guide, dict):
            read.check_keys(guide, {'through', 'angle'}, f'{where}.guide')
        stroke = read.get(raw, 'stroke', where, None)
        limits = None
        if stroke is not None:
            if not isinstance(stroke, list) or len(stroke) != 2:
                msg = (f'{where}.stroke: expected [lowest, highest] positions, got '
                       f'{read.brief(stroke)}')
                raise SceneError(msg)
            low, high = (read.length({f'stroke[{i}]': value}, f'stroke[{i}]', where, False)
                         for i, value in enumerate(stroke))
            limits = (low, high)
        number = read.number
        built: Slider = read.build(
            where, {'through': 'guide.through', 'guide_angle': 'guide.angle'}, cls,
            slider=read.name(raw, 'slider', where), point=read.name(raw, 'point', where),
            through=read.name(guide, 'through', f'{where}.guide'),
            guide_angle=read.angle(guide, 'angle', f'{where}.guide', 0.0),
            position=read.length(raw, 'position', where, False),
            speed=number(raw, 'speed', where, 0.0), accel=number(raw, 'accel', where, 0.0),
            stroke=limits)
        return built

    @property
    def link_length(self) -> None:
        """None: a slider sets no dyad link's length."""
        return None

    @property
    def name(self) -> str:
        """The driver's name: the slider (its prismatic joint)."""
        return self.slider

    @property
    def joint_type(self) -> JointType:
        """The driver's joint type: prismatic."""
        return PRISMATIC

    @property
    def start(self) -> float:
        """The driver's position at time zero, m."""
        return self.position

    @property
    def turns(self) -> int:
        """0: a slider does not turn."""
        return 0

    @property
    def rate(self) -> Rate:
        """Its velocity as the scene gives it: ``speed``, m/s."""
        return Rate('speed', self.speed, 'm/s')

    @property
    def rate_parameter(self) -> RateParameter:
        """Its velocity is set in m/s, as ``speed``."""
        return RateParameter('speed', 'm/s')

    @property
    def reach(self) -> float:
        """The farthest its pin is from its guide point, m: what it adds to the size."""
        ends = () if self.stroke is None else self.stroke
        return max(abs(x) for x in (self.position, *ends))

    @property
    def described(self) -> str:
        """What it is: a slider on its guide."""
        return f'slider on the guide through {self.through}'

    def sweep(self, free: float) -> tuple[float, float]:
        """Return its stroke, or positions within ``free`` of its guide point either way, m."""
        return (-free, free) if self.stroke is None else self.stroke

    def position_text(self, value: float, units: SceneUnits) -> str:
        """Return a position (m) of it as text in the scene's unit."""
        return units.length_text(value)

    def scaled(self, scale: Callable[[float], float]) -> Slider:
        """Return it with its lengths scaled (its rates are scaled at run time)."""
        stroke = None if self.stroke is None else (scale(self.stroke[0]), scale(self.stroke[1]))
        return replace(self, position=scale(self.position), stroke=stroke)

    def fragment(self) -> Fragment:
        """Return its part of the graph: the block, driven along its fixed guide."""
        block = Body(self.slider, Role.SLIDER, (self.point,),
                     Frame(self.point, None, self.guide_angle), guide=THE_GROUND)
        joint = slide(self.slider, self.point, self.slider,
                      Line(self.through, None, self.guide_angle), on=THE_GROUND, driver=True)
        return Fragment(self.slider, bodies=(block,), joints=(joint,),
                        coordinates={self.slider: PRISMATIC})

    @staticmethod
    def fact_texts() -> dict[str, Callable[[dict[str, Any], SceneUnits], str]]:
        """Return the text of a position outside the stroke."""
        return {'travel': _travel_text}

    def check_used(self, users: Sequence[Item]) -> None:
        """Accept it: a slider places its own pin, whatever reads it."""

    def defined(self) -> tuple[tuple[str, str], ...]:
        """Return (name, kind) of the names it defines: its block and its pin."""
        return (self.slider, 'slider'), (self.point, 'point')

    def local(self, ground: Mapping[str, complex]) -> dict[str, dict[str, complex]]:
        """Return the points fixed on links it moves: none (its block is no link)."""
        return {}

    def step(self, ground: Mapping[str, complex]) -> _SlideStep:
        """Return its step; its guide point must be a ground point."""
        if self.through not in ground:
            msg = (f'Expected the guide point of slider "{self.slider}" to be a ground point, '
                   f'got "{self.through}"')
            raise SceneError(msg, (self, 'through'))
        return _SlideStep(self, ground[self.through])


def _travel_text(facts: dict[str, Any], units: SceneUnits) -> str:
    """Return why a slider's position is refused, in the scene's units."""
    text = units.length_text
    name, position, (low, high) = facts['slider'], facts['position'], facts['stroke']
    return (f'slider {name}: expected a position within its stroke [{text(low, position)}, '
            f'{text(high, position)}], got {text(position, low, high)}')


class _SlideStep:
    """The slider's kernel: its pin's motion into ``ctx.points``, its position into ``sliders``."""

    joint_type = PRISMATIC

    def __init__(self, driver: Slider, through: complex) -> None:
        self.name = driver.slider
        self.label = f'input {driver.slider}'
        self.point = driver.point
        self.length = 1.0
        self.unit = 1.0
        self.stroke = driver.stroke
        self.low, self.high = (-math.inf, math.inf) if driver.stroke is None else driver.stroke
        self.through = through
        self.u = complex(math.cos(driver.guide_angle), math.sin(driver.guide_angle))
        self.uses: tuple[str, ...] = (driver.through,)
        self.defines = (driver.slider, driver.point)
        # The guide's direction known to the angle's rounding and an ulp of cos and
        # sin; the guide point to U |through|, and the sum's rounding takes another.
        self.e_u = U * abs(driver.guide_angle) + _U2
        self.e_through = 2.0 * U * abs(through)

    def facts(self, position: float) -> dict[str, Any]:
        """Return why the position is refused, for a message in the scene's units."""
        m = self.unit
        return {'kind': 'travel', 'slider': self.name, 'stroke': (self.low * m, self.high * m),
                'position': float(position) * m}

    def reason(self, position: float) -> str:
        """Return why the position is refused, SI units."""
        m = self.unit
        return (f'expected the position of slider {self.name} within its stroke '
                f'[{_g(self.low * m)}, {_g(self.high * m)}] m, got {_g(position * m)} m')

    def run(self, ctx: _Context, s: Any, sd: Any, sdd: Any) -> None:
        if self.stroke is not None:
            ok = (s >= self.low) & (s <= self.high)
            if ctx.vector or not ok:
                ctx.check(ok, self.label, lambda: self.reason(s), lambda: self.facts(s))
        u = self.u
        # Each product has one real factor (the rule of crank.py's kernels): the
        # same bits in Python's complex type and NumPy's. The inputs are known to
        # half an ulp each; a product adds the direction's error and its rounding.
        eu = self.e_u + 2.0 * U
        ctx.points[self.point] = (self.through + s * u, sd * u, sdd * u,
                                  abs(s) * (eu + U) + self.e_through, abs(sd) * eu,
                                  abs(sdd) * eu)
        ctx.sliders[self.name] = (s, sd, sdd, U * abs(s), U * abs(sd), U * abs(sdd))

    def floors(self, speed: Any, accel: Any, size: float) -> tuple[Any, Any, Any, Any]:
        """Return what it adds to the least scales: those of a linear driver (an actuator's)."""
        return linear_floors(speed, accel, size)
