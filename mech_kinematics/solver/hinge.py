# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The driven hinge: a motor between two moving links, its relative angle an input.

A robot's elbow, a motor carried by a crank: a link (``link``) pinned at
``center`` to a link already placed (``parent``), turned relative to it by a
motor (a driver of the scene's ``inputs``, ``motor: NAME``). Its angle is
the parent's plus the motor's: ``theta = theta_on + q``, its rates likewise,
and its tip ``point`` lies ``length`` from the pin along it. The motor's
position is the relative angle (a revolute joint named after it, the
parent's axis to the link's), its effort the torque between the two links.
This is the revolute joint between two moving links of issue 41 as a driver,
where the parent is placed before the link it turns (a loop whose driven
joint joins two links neither of which the rest places first is re-rooted
at it: :mod:`.fold`, which the same motor drives).

This module owns both halves: the motor (:class:`Motor`, a driver: its
scene keys and its step, which writes the relative angle as a unit complex
number with its rates into ``ctx.links``) and the hinge (:class:`Hinge`, the
item: its keys, its part of the graph and its step).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, replace
import math
from typing import Any

import numpy as np

from .base import Driver, Item, Names, Placing, Rate, RateParameter, Reading, Step
from .context import _Context, _fixed_on, _U2, _U4
from .crank import read_turning_speed
from .graph import Body, Fragment, Frame, JointType, Motion, pin, REVOLUTE, Role
from .model import _check_finite, _check_length, _check_name, _names, SceneUnits, Where
from ..bounds import U
from ..errors import SceneError
from ..units import rad_per_s_from_rpm

#: The scene keys of a motor in ``inputs:`` and of a hinge in ``dyads:``.
MOTOR_KEYS = {'motor', 'angle', 'speed', 'speed_rpm', 'accel'}
HINGE_KEYS = {'type', 'link', 'parent', 'center', 'point', 'length', 'motor'}


@dataclass(frozen=True)
class Motor(Driver):
    """A motor between two moving links: the relative angle of a hinge is an input.

    Parameters
    ----------
    motor : str
        Its name: a revolute joint in the output (the relative angle).
    angle : float
        The relative angle at time zero, rad (the parent's axis to the link's).
    speed : float
        Default relative angular velocity, rad/s, + CCW.
    accel : float
        Default relative angular acceleration, rad/s^2, + CCW.
    rpm : float or None
        The speed as the scene gave it in rpm (``speed_rpm``), as a crank's; ``None``
        where it was given in rad/s (``speed``).
    """

    position_key = 'angle'
    v1_crank = False
    scene_key = 'motor'

    motor: str
    angle: float = 0.0
    speed: float = 0.0
    accel: float = 0.0
    rpm: float | None = None

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.motor, 'the motor name', (self, 'motor'))
        _check_finite(self.angle, f'the angle of motor "{self.motor}"', (self, 'angle'))
        _check_finite(self.speed, f'the speed of motor "{self.motor}"', (self, 'speed'))
        _check_finite(self.accel, f'the acceleration of motor "{self.motor}"', (self, 'accel'))
        if self.rpm is not None and self.speed != rad_per_s_from_rpm(self.rpm):
            msg = (f'Expected the speed of motor "{self.motor}" to be its rpm ({self.rpm!r}) in '
                   f'rad/s, {rad_per_s_from_rpm(self.rpm)!r}, got {self.speed!r}')
            raise SceneError(msg, (self, 'speed'))

    @classmethod
    def from_scene(cls, read: Reading, raw: Any, where: str) -> Motor:
        """Return the motor at ``where`` (an entry of ``inputs:``): ``angle`` in the scene's unit.

        Its speed is a crank's: ``speed`` (rad/s) or ``speed_rpm``; ``accel`` is in rad/s^2.
        """
        read.check_keys(raw, MOTOR_KEYS, where)
        speed, rpm, key = read_turning_speed(read, raw, where, 'motor')
        built: Motor = read.build(
            where, {'speed': key, 'rpm': key}, cls, motor=read.name(raw, 'motor', where),
            angle=read.angle(raw, 'angle', where, 0.0), speed=speed, rpm=rpm,
            accel=read.number(raw, 'accel', where, 0.0))
        return built

    @property
    def link_length(self) -> None:
        """None: a motor sets no dyad link's length."""
        return None

    @property
    def name(self) -> str:
        """The driver's name: the motor (its revolute joint)."""
        return self.motor

    @property
    def joint_type(self) -> JointType:
        """The driver's joint type: revolute."""
        return REVOLUTE

    @property
    def start(self) -> float:
        """The relative angle at time zero, rad."""
        return self.angle

    @property
    def stroke(self) -> None:
        """A motor has no stroke limits."""
        return None

    @property
    def turns(self) -> int:
        """0: its start is read within a turn."""
        return 0

    @property
    def rate(self) -> Rate:
        """Its speed as the scene gave it: ``speed_rpm`` in rpm, or ``speed`` in rad/s."""
        if self.rpm is not None:
            return Rate('speed_rpm', self.rpm, 'rpm')
        return Rate('speed', self.speed, 'rad/s')

    @property
    def rate_parameter(self) -> RateParameter:
        """Its speed is set in rpm, as ``speed_rpm`` (a crank's)."""
        return RateParameter('speed_rpm', 'rpm')

    @property
    def reach(self) -> float:
        """0: the link it turns counts its own length."""
        return 0.0

    @property
    def described(self) -> str:
        """What it is: a motor between two links."""
        return 'motor between two moving links'

    def sweep(self, free: float) -> tuple[float, float]:
        """Return a turn, rad."""
        return (0.0, math.tau)

    def position_text(self, value: float, units: SceneUnits) -> str:
        """Return an angle (rad) of it as text in the scene's unit."""
        return units.angle_text(value)

    def scaled(self, scale: Callable[[float], float]) -> Motor:
        """Return it (it has no length)."""
        return self

    def fragment(self) -> Fragment:
        """Return its part of the graph: its coordinate (its joint is the hinge's pin)."""
        return Fragment(self.motor, coordinates={self.motor: REVOLUTE})

    def check_used(self, users: Sequence[Item]) -> None:
        """Refuse it unless exactly one hinge or fold turns its link."""
        if len(users) != 1:
            got = 'none' if not users else ', '.join(f'{u.kind} {u.key}' for u in users)
            msg = (f'Expected motor "{self.motor}" to turn one hinge or fold (a dyad of type '
                   f'hinge or fold with motor: {self.motor}), got {got}')
            raise SceneError(msg, (self, 'motor'))

    def defined(self) -> tuple[tuple[str, str], ...]:
        """Return (name, kind) of the names it defines: its joint."""
        return ((self.motor, 'motor'),)

    def local(self, ground: Mapping[str, complex]) -> dict[str, dict[str, complex]]:
        """Return the points fixed on links it moves: none (its link is the hinge's)."""
        return {}

    def step(self, ground: Mapping[str, complex]) -> _MotorStep:
        """Return its step."""
        return _MotorStep(self)

    @staticmethod
    def fact_texts() -> dict[str, Callable[[dict[str, Any], SceneUnits], str]]:
        """Return none: every relative angle is allowed."""
        return {}


class _MotorStep:
    """The motor's kernel: the relative angle as a unit complex number into ``ctx.links``."""

    joint_type = REVOLUTE

    def __init__(self, motor: Motor) -> None:
        self.name = motor.motor
        self.label = f'input {motor.motor}'
        self.point = None
        self.length = 1.0
        self.unit = 1.0
        self.uses: tuple[str, ...] = ()
        self.defines = (motor.motor,)

    def run(self, ctx: _Context, q: Any, qd: Any, qdd: Any) -> None:
        e: Any
        if ctx.vector:
            e = np.empty(np.shape(q), dtype=np.complex128)
            np.cos(q, out=e.real)
            np.sin(q, out=e.imag)
        else:
            e = complex(math.cos(q), math.sin(q))
        # q known to U |q|, cos and sin to an ulp; the rates are inputs (half an ulp).
        ctx.links[self.name] = (e, qd, qdd, U * abs(q) + _U2 + _U4, U * abs(qd), U * abs(qdd))

    def floors(self, speed: Any, accel: Any, size: float) -> tuple[Any, Any, Any, Any]:
        """Return what it adds to the least scales: a link of the mechanism's size turned by it."""
        w = abs(speed)
        rate = w * w + abs(accel)
        return size * w, size * rate, w, rate


@dataclass(frozen=True)
class Hinge(Item):
    """A link pinned to a moving link and turned relative to it by a motor.

    Parameters
    ----------
    link : str
        The link it adds (a revolute output joint: its absolute angle).
    parent : str
        The link it is pinned to, placed before it.
    center : str
        The pin: a point fixed on ``parent``.
    point : str
        Its tip, a new point ``length`` from the pin along the link.
    length : float
        Pin to tip, m (> 0).
    motor : str
        A motor of the scene's ``inputs``: the link's angle relative to ``parent``'s axis.
    """

    kind = 'hinge'

    link: str
    parent: str
    center: str
    point: str
    length: float
    motor: str

    def __post_init__(self) -> None:
        """Validate the fields."""
        what = f'hinge "{self.link}"'
        _check_name(self.link, 'a hinge link', (self, 'link'))
        _check_name(self.parent, f'the link {what} is pinned to', (self, 'parent'))
        _check_name(self.center, f'the pin of {what}', (self, 'center'))
        _check_name(self.point, f'the tip of {what}', (self, 'point'))
        _check_name(self.motor, f'the motor of {what}', (self, 'motor'))
        _check_length(self.length, f'{what} length', (self, 'length'))

    @classmethod
    def from_scene(cls, read: Reading, raw: Any, where: str) -> Hinge:
        """Return the hinge at ``where``: link, parent, center, point, length, motor."""
        read.check_keys(raw, HINGE_KEYS, where)
        built: Hinge = read.build(
            where, {}, cls, link=read.name(raw, 'link', where),
            parent=read.name(raw, 'parent', where), center=read.name(raw, 'center', where),
            point=read.name(raw, 'point', where),
            length=read.length(raw, 'length', where), motor=read.name(raw, 'motor', where))
        return built

    @property
    def key(self) -> str:
        """Return its link."""
        return self.link

    def defined(self) -> Iterator[tuple[str, str, Where]]:
        """Yield its link and its tip."""
        yield self.link, 'link', (self, 'link')
        yield self.point, 'point', (self, 'point')

    def prerequisites(self, names: Names) -> set[str]:
        """Check its parent link, pin and motor; return them."""
        what = f'hinge "{self.link}"'
        kind = names.kinds.get(self.motor)
        if kind != 'motor':
            got = f'unknown "{self.motor}"' if kind is None else f'{kind} "{self.motor}"'
            msg = f'Expected the motor of {what} to be a motor of inputs, got {got}'
            raise SceneError(msg, (self, 'motor'))
        return {names.link(self.parent, f'the link {what} is pinned to', (self, 'parent')),
                names.point(self.center, f'the pin of {what}', (self, 'center')), self.motor}

    def place(self, plan: Placing) -> Step:
        """Return its step; its pin must be fixed on its parent, and it carries its tip."""
        fixed = plan.local[self.parent]
        if self.center not in fixed:
            msg = (f'Expected the pin of hinge "{self.link}" to be a point fixed on link '
                   f'"{self.parent}" (one of {_names(fixed)}), got "{self.center}"')
            raise SceneError(msg, (self, 'center'))
        plan.local[self.link] = {self.center: 0j, self.point: complex(self.length)}
        return _HingeStep(self)

    def scaled(self, scale: Callable[[float], float]) -> Hinge:
        """Return it with its length scaled."""
        return replace(self, length=scale(self.length))

    def lengths(self) -> tuple[float, ...]:
        """Return its link's length."""
        return (self.length,)

    @staticmethod
    def fact_texts() -> dict[str, Callable[[dict[str, Any], SceneUnits], str]]:
        """Return none: it closes at every angle."""
        return {}

    def toggle(self) -> None:
        """Return ``None``: it has no measure (it cannot fail to close)."""
        return None

    def fragment(self) -> Fragment:
        """Return its part of the graph: its link, pinned to its parent by the motor's joint."""
        body = Body(self.link, Role.LINK, (self.center, self.point),
                    Frame(self.center, self.link), length=self.length)
        return Fragment(self.link, (body,),
                        (pin(self.link, self.center, on=self.parent, driver=True,
                             name=self.motor),),
                        {self.link: REVOLUTE}, (Motion(self.link, self.center, self.point),))


class _HingeStep(Step):
    """The hinge's kernel: its link's angle and rates, the parent's plus the motor's; its tip."""

    def __init__(self, hinge: Hinge) -> None:
        self.link, self.parent, self.motor = hinge.link, hinge.parent, hinge.motor
        self.center, self.point = hinge.center, hinge.point
        self.length = hinge.length
        self.label = f'hinge {hinge.link}'
        self.key = hinge.link
        self.dyad = hinge
        self.owner = hinge.parent
        self.uses = (hinge.center, hinge.motor)
        self.defines = (hinge.link, hinge.point)
        self.new_points = (hinge.point,)
        self.e_length = _U2 * hinge.length

    def run(self, ctx: _Context) -> None:
        ep, wp, ap, eep, ewp, eap = ctx.links[self.parent]
        m, wm, am, em, ewm, eam = ctx.links[self.motor]
        # e = ep m as two products with a real factor (crank.py's rule for the same bits).
        e = ep * m.real + (1j * ep) * m.imag
        omega, alpha = wp + wm, ap + am
        ee = eep + em + _U4
        ew = ewp + ewm + U * abs(omega)
        eal = eap + eam + U * abs(alpha)
        ctx.links[self.link] = (e, omega, alpha, ee, ew, eal)
        p, v, a, e_p, ev, ea = ctx.points[self.center]
        length = self.length
        r = length * e
        er = length * ee + self.e_length
        ctx.points[self.point] = _fixed_on(p, v, a, e_p, ev, ea, r, er, omega, alpha, ew, eal,
                                           length)
