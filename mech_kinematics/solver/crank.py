# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The driving crank: a link turning about a ground point, at the head of every plan."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
import math
from typing import Any, TYPE_CHECKING, TypedDict

import numpy as np

from .base import Driver, Rate, RateParameter
from .context import _Context, _U2, _U4
from .graph import Body, Fragment, Frame, JointType, Motion, pin, REVOLUTE, Role
from .model import _check_finite, _check_length, _check_name, SceneUnits
from ..bounds import U
from ..errors import SceneError
from ..units import rad_per_s_from_rpm

if TYPE_CHECKING:
    from .base import Item, Reading


class CrankDict(TypedDict, total=False):
    """A crank's scene keys (``input:``, or an entry of ``inputs:`` with ``link:``).

    Its speed is ``speed_rpm`` (rpm) or ``speed`` (rad/s), at most one; its
    ``accel`` is in rad/s^2; ``length`` and ``angle`` in the scene's units.
    """

    link: str
    center: str
    point: str
    length: float
    angle: float
    speed_rpm: float
    speed: float
    accel: float


@dataclass(frozen=True)
class Crank(Driver):
    """The driving crank: a link turning about a ground point.

    Parameters
    ----------
    link : str
        Name of the crank link (a revolute joint).
    center : str
        Ground point it turns about.
    point : str
        The point at its tip.
    length : float
        Crank length, m.
    angle : float
        Crank angle at time zero, rad (within its turn when ``turns`` is not 0).
    speed : float
        Default angular velocity, rad/s, + CCW.
    accel : float
        Default angular acceleration, rad/s^2, + CCW.
    turns : int
        Whole turns to add to ``angle``: the crank angle at time zero is
        ``angle + 2 pi turns``, the sum never formed in floating point (a scene
        file's angle far out, as 1e17 deg, is read as an angle within a turn
        plus whole turns; only an intermittent drive tells the turns apart).
    rpm : float or None
        The speed as the scene gave it in rpm (``speed_rpm``), kept as written;
        ``speed`` is then ``rad_per_s_from_rpm(rpm)``. ``None`` where the speed
        was given in rad/s (``speed``).
    """

    position_key = 'angle'
    v1_crank = True
    scene_key = 'link'

    link: str
    center: str
    point: str
    length: float
    angle: float = 0.0
    speed: float = 0.0
    accel: float = 0.0
    turns: int = 0
    rpm: float | None = None

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.link, 'the crank link name', (self, 'link'))
        _check_name(self.center, 'the crank center', (self, 'center'))
        _check_name(self.point, 'the crank point', (self, 'point'))
        _check_length(self.length, f'crank "{self.link}" length', (self, 'length'))
        _check_finite(self.angle, 'the crank angle', (self, 'angle'))
        _check_finite(self.speed, 'the crank speed', (self, 'speed'))
        _check_finite(self.accel, 'the crank acceleration', (self, 'accel'))
        if not isinstance(self.turns, int) or isinstance(self.turns, bool):
            msg = f'Expected the crank whole turns to be an int, got {self.turns!r}'
            raise SceneError(msg, (self, 'turns'))
        if self.rpm is not None and self.speed != rad_per_s_from_rpm(self.rpm):
            msg = (f'Expected the crank speed to be its rpm ({self.rpm!r}) in rad/s, '
                   f'{rad_per_s_from_rpm(self.rpm)!r}, got {self.speed!r}')
            raise SceneError(msg, (self, 'speed'))

    @classmethod
    def from_scene(cls, read: Reading, raw: Any, where: str) -> Crank:
        """Return the crank written at ``where`` (``input``, or an entry of ``inputs``).

        Its speed is read as written: ``speed`` (rad/s) to the bit, ``speed_rpm``
        converted (``rpm * pi / 30``); at most one of the two, neither is 0.
        """
        read.check_keys(raw if isinstance(raw, dict) else {}, set(CrankDict.__annotations__),
                        where)
        speed, rpm, key = read_turning_speed(read, raw, where, 'crank')
        angle, turns = read.start_angle(raw, 'angle', where)
        built: Crank = read.build(
            where, {'speed': key, 'rpm': key}, cls,
            link=read.name(raw, 'link', where), center=read.name(raw, 'center', where),
            point=read.name(raw, 'point', where), length=read.length(raw, 'length', where),
            angle=angle, turns=turns, speed=speed, accel=read.number(raw, 'accel', where, 0.0),
            rpm=rpm)
        return built

    @property
    def link_length(self) -> None:
        """None: a crank sets no dyad link's length."""
        return None

    @property
    def name(self) -> str:
        """The driver's name: the crank link (its revolute joint)."""
        return self.link

    @property
    def joint_type(self) -> JointType:
        """The driver's joint type: revolute."""
        return REVOLUTE

    @property
    def start(self) -> float:
        """The driver's position at time zero: the crank angle, rad."""
        return self.angle

    @property
    def shown(self) -> float:
        """The crank angle at time zero as one float, rad, for messages only."""
        return self.angle + math.tau * self.turns

    @property
    def stroke(self) -> tuple[float, float] | None:
        """A crank has no stroke limits."""
        return None

    @property
    def rate(self) -> Rate:
        """Its speed as the scene gave it: ``speed_rpm`` in rpm, or ``speed`` in rad/s."""
        if self.rpm is not None:
            return Rate('speed_rpm', self.rpm, 'rpm')
        return Rate('speed', self.speed, 'rad/s')

    @property
    def rate_parameter(self) -> RateParameter:
        """Its speed is set in rpm, as ``speed_rpm``."""
        return RateParameter('speed_rpm', 'rpm')

    @property
    def reach(self) -> float:
        """Its length, m: what it adds to the mechanism's size."""
        return self.length

    @property
    def described(self) -> str:
        """What it is: a crank about its centre."""
        return f'crank about {self.center}'

    def sweep(self, free: float) -> tuple[float, float]:
        """Return a turn, rad."""
        return (0.0, math.tau)

    def position_text(self, value: float, units: SceneUnits) -> str:
        """Return an angle (rad) of it as text in the scene's unit."""
        return units.angle_text(value)

    def scaled(self, scale: Callable[[float], float]) -> Crank:
        """Return it with its length scaled."""
        return replace(self, length=scale(self.length))

    def fragment(self) -> Fragment:
        """Return its part of the graph: the crank, turned by its motor about its centre."""
        crank = Body(self.link, Role.CRANK, (self.center, self.point),
                     Frame(self.center, self.link), length=self.length)
        return Fragment(self.link, bodies=(crank,),
                        joints=(pin(self.link, self.center, driver=True, name=self.link),),
                        coordinates={self.link: REVOLUTE},
                        motions=(Motion(self.link, self.center, self.point),))

    @staticmethod
    def fact_texts() -> dict[str, Callable[[dict[str, Any], SceneUnits], str]]:
        """Return none: a crank's step cannot fail (every angle places its tip)."""
        return {}

    def check_used(self, users: Sequence[Item]) -> None:
        """Accept it: a crank moves its own link, whatever reads it."""

    def defined(self) -> tuple[tuple[str, str], ...]:
        """Return (name, kind) of the names it defines: its link and its tip."""
        return (self.link, 'link'), (self.point, 'point')

    def local(self, ground: Mapping[str, complex]) -> dict[str, dict[str, complex]]:
        """Return the points fixed on its link: its centre and its tip."""
        return {self.link: {self.center: 0j, self.point: complex(self.length)}}

    def step(self, ground: Mapping[str, complex]) -> _CrankStep:
        """Return its step; its centre must be a ground point."""
        if self.center not in ground:
            msg = f'Expected the crank center to be a ground point, got "{self.center}"'
            raise SceneError(msg, (self, 'center'))
        return _CrankStep(self, ground[self.center])


def read_turning_speed(read: Reading, raw: Any, where: str,
                       what: str) -> tuple[float, float | None, str]:
    """Return a turning driver's speed as written: (rad/s, rpm or ``None``, its key).

    ``speed`` (rad/s) to the bit, or ``speed_rpm`` converted (``rpm * pi / 30``;
    default 0 rpm); at most one of the two. ``what`` names the driver in the refusal.
    """
    given = [key for key in ('speed', 'speed_rpm') if isinstance(raw, dict) and key in raw]
    if len(given) == 2:
        msg = (f'{where}.speed: expected the {what} speed once, as speed (rad/s) or '
               f'speed_rpm (rpm), got both (speed: {read.brief(raw["speed"])}, speed_rpm: '
               f'{read.brief(raw["speed_rpm"])})')
        raise SceneError(msg)
    if given == ['speed']:
        return read.number(raw, 'speed', where), None, 'speed'
    rpm = read.number(raw, 'speed_rpm', where, 0.0)
    return rad_per_s_from_rpm(rpm), rpm, 'speed_rpm'


class _CrankStep:
    joint_type = REVOLUTE

    def __init__(self, crank: Crank, center: complex) -> None:
        self.name = crank.link
        self.label = f'input {crank.link}'
        self.unit = 1.0
        self.link = crank.link
        self.point = crank.point
        self.center = center
        self.length = crank.length
        self.uses: tuple[str, ...] = (crank.center,)
        self.defines = (crank.link, crank.point)
        # The tip's sum ``center + r``: the centre's rounding and the sum's.
        self.e_center = U * (2.0 * abs(center) + crank.length)
        # r = length * e: the length's rounding and the product's; then those of
        # v = i omega r and of a = i alpha r - omega^2 r.
        self.e_r, self.e_v, self.e_a = (n * U * crank.length for n in (2, 4, 7))

    def run(self, ctx: _Context, theta: Any, omega: Any, alpha: Any) -> None:
        e: Any
        if ctx.vector:
            e = np.empty(np.shape(theta), dtype=np.complex128)
            np.cos(theta, out=e.real)
            np.sin(theta, out=e.imag)
        else:
            e = complex(math.cos(theta), math.sin(theta))
        r = self.length * e
        if (not ctx.vector or alpha.ndim == 0) and alpha == 0.0:  # a constant crank speed
            acceleration = -(omega * omega) * r
        else:
            acceleration = 1j * alpha * r - omega * omega * r
        # Bounds: theta known to U |theta|, cos and sin to an ulp; r = length * e.
        ee = U * abs(theta) + _U2
        re = self.length * ee
        w = abs(omega)
        ctx.points[self.point] = (self.center + r, 1j * omega * r, acceleration,
                                  re + self.e_r + self.e_center, w * (re + self.e_v),
                                  (abs(alpha) + w * w) * (re + self.e_a))
        ctx.links[self.link] = (e, omega, alpha, ee + _U4, U * w, U * abs(alpha))

    def floors(self, speed: Any, accel: Any, size: float) -> tuple[Any, Any, Any, Any]:
        """Return what it adds to the least scales: its tip's speed and acceleration, its rates.

        ``a |omega|``, ``a (omega^2 + |alpha|)``, ``|omega|`` and
        ``omega^2 + |alpha|`` for its length ``a``.
        """
        w = abs(speed)
        rate = w * w + abs(accel)
        return self.length * w, self.length * rate, w, rate


# Every complex product below has one real factor or a purely imaginary one
# (``1j * x``): such products round the same way in Python's complex type and
# in NumPy's (whose general complex product may use fused multiply-adds), so
# the single-angle and array paths give the same bits. Norms use hypot for the
# same reason.
