# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""What a solve returns: :class:`State` with its joints, points, bounds and engagements."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from functools import cached_property
import math
from typing import Any, TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from .model import Number, Vector
from .scaling import _LINEAR
from ..bounds import ErrorBound
from ..imu import imu_reading, ImuReading, ImuSpec

if TYPE_CHECKING:
    from .forces import Forces


class JointMotion:
    """Position, velocity and acceleration of one joint.

    ``position`` is the link's absolute angle (rad, wrapped to (-pi, pi]) for a
    revolute joint and the slider coordinate (m) for a prismatic one; floats
    for one crank angle, arrays of shape (n,) for n angles.
    """

    __slots__ = ('type', 'position', 'velocity', 'acceleration')

    def __init__(self, type: str, position: Number, velocity: Number,  # noqa: A002
                 acceleration: Number) -> None:
        self.type = type
        self.position = position
        self.velocity = velocity
        self.acceleration = acceleration

    def __repr__(self) -> str:
        """Show every field."""
        return (f'JointMotion(type={self.type!r}, position={self.position!r}, '
                f'velocity={self.velocity!r}, acceleration={self.acceleration!r})')


@dataclass(frozen=True)
class PointState:
    """Position (m), velocity (m/s), acceleration (m/s^2): arrays of shape (2,) or (n, 2)."""

    position: npt.NDArray[np.float64]
    velocity: npt.NDArray[np.float64]
    acceleration: npt.NDArray[np.float64]


def _xy(z: Any) -> npt.NDArray[np.float64]:
    if isinstance(z, complex):
        return np.array((z.real, z.imag))
    return np.stack((z.real, z.imag), axis=-1)


@dataclass(frozen=True)
class Engagement:
    """Where an intermittent (Geneva) lever is in its cycle, and its acceleration's jumps.

    The crank's engagement windows are numbered: window ``k`` is centred on the
    crank angle ``phi + 2 pi k`` (counted from the start) at which the pin
    points at the lever's centre, and spans ``pi / 2 - pi / n`` either side.
    Floats for one crank angle, arrays of shape (n,) for n angles.

    Attributes
    ----------
    engaged : bool or ndarray of bool
        Whether the pin is in a slot (the window's ends included).
    window : int or ndarray of int
        The number of the nearest window: the one the pin is in, or the
        nearest one it has left or will enter.
    entry, exit : float or ndarray
        Crank angles (rad, counted from the start) where that window begins
        and ends.
    entry_acceleration, exit_acceleration : (float, float) or (ndarray, ndarray)
        The lever's angular acceleration (rad/s^2) just before and just after
        the crank passes ``entry`` and ``exit`` (turning CCW) at the current
        crank speed omega: ``(0, -omega^2 tan(pi / n))`` and
        ``(omega^2 tan(pi / n), 0)``. The angular velocity is 0 at both ends
        (the pin enters and leaves tangentially); the acceleration jumps.
    driven : bool or ndarray of bool
        Whether the values answer the side where the pin drives the lever
        (False: the side where its lock holds it): ``engaged`` everywhere
        but at an engagement instant (an entry or exit, in ``State.jumps``),
        where it is the side answered, after the jump in the crank's sense
        of motion. The forces follow it (:mod:`.forces`: the slot carries
        the lever, or the lock does); the other side's are in ``jumps``.
    """

    engaged: bool | npt.NDArray[np.bool_]
    window: int | npt.NDArray[np.int64]
    entry: Number
    exit: Number
    entry_acceleration: tuple[Number, Number]
    exit_acceleration: tuple[Number, Number]
    driven: bool | npt.NDArray[np.bool_]

    def as_dict(self, vector: bool) -> dict[str, Any]:
        """Return the structure of ``State.as_dict()['intermittent'][LEVER]``."""
        def value(x: Any) -> Any:
            return x if vector else float(x)

        def pair(x: tuple[Any, Any]) -> Any:
            return np.stack(x, axis=-1) if vector else [float(x[0]), float(x[1])]

        return {'engaged': self.engaged if vector else bool(self.engaged),
                'window': self.window if vector else int(self.window),
                'entry': {'angle': value(self.entry),
                          'acceleration': pair(self.entry_acceleration)},
                'exit': {'angle': value(self.exit),
                         'acceleration': pair(self.exit_acceleration)}}


@dataclass(frozen=True)
class State:
    """The kinematic state of a scene at one crank angle or an array of them.

    Attributes
    ----------
    scene : str
        Scene name.
    angle, speed, accel : float or ndarray
        The crank's angle (rad, as given), angular velocity (rad/s) and
        angular acceleration (rad/s^2); with several drivers, the first
        driver's position (rad or m), speed and acceleration.
    joints : dict of str to JointMotion
        Every reported joint.
    complex_points : dict of str to (p, v, a)
        Every reported point as complex numbers ``x + iy`` (m, m/s, m/s^2).
    valid : bool or ndarray of bool
        Where the mechanism could be solved. Invalid entries of arrays are NaN.
    singularity : dict of str to float or ndarray
        Near-singularity measure of every solved dyad, keyed by its new point
        (RRR, RRP) or lever (RPR): for RRR the sine of the angle between its
        links, for RRP the sine of the rod's angle to the guide normal, for RPR
        the slider coordinate over the mechanism's size. 0 is singular.
    failures : dict of str to ndarray of bool
        For arrays: per reason, the angles that were refused. The reason is a
        dyad's label (``RRR C``: it cannot close, is singular or is within
        rounding of an assembly limit), that label followed by
        `` (untrusted)`` (a value's error bound exceeds the tolerance) or by
        `` (overflow)`` (a value is beyond the range of doubles).
    error_bound : ErrorBound
        Absolute error bound of every reported value, shaped like ``joints``
        and ``points`` (see :mod:`mech_kinematics.bounds`); ``rubbing`` too.
    turns : int or ndarray of int
        Whole crank turns added to ``angle`` (``solve(..., turns=)``): the crank
        angle counted from the start is ``angle + 2 pi turns``.
    rubbing : dict of str to float or ndarray
        Rubbing velocity (m/s) at every pin of the scene's ``pins``.
    intermittent : dict of str to Engagement
        Every intermittent (Geneva) lever solved: engaged or locked, and where
        its acceleration jumps.
    jumps : dict
        Empty unless some value jumps at the instant (a Geneva wheel's pin
        entering or leaving a slot, within rounding). There the state holds
        the value *after* the jump in the direction the crank turns (for a
        crank at rest, increasing angle), and ``jumps`` the value on the other
        side of every value that jumps (the wheel's acceleration and that of
        whatever is carried on it or solved from it):
        ``{'joints': {name: {'acceleration': x}}, 'points': {name:
        {'acceleration': ndarray, shape (2,)}}}``. For arrays, shapes (n,) and
        (n, 2), NaN at the angles where nothing jumps. A scene with forces
        adds ``'forces'``: the other side's :class:`~.forces.Forces`, whole
        (every effort, reaction and the shaking, with their bounds; the
        state's ``forces`` answer the side the kinematics do: at a Geneva
        wheel's mouth, the pin's slot carrying it or the lock holding it,
        ``Engagement.driven``); for arrays NaN where nothing jumps. In
        :meth:`as_dict`, its ``"efforts"``, ``"reactions"`` and ``"shaking"``
        sit in ``"jumps"`` beside ``"joints"`` and ``"points"``. A pin whose
        rubbing velocity changes side (a Geneva pin leaving or entering its
        slot: 0 in the dwell) adds ``'rubbing'``: pin -> the other side's value
        (for arrays NaN where it does not jump).
    drivers : dict of str to JointMotion
        Every driver's own motion, in scene order, as given to the solve
        (whether or not the scene's outputs report its joint): a crank's angle
        counted from the start (rad, not wrapped: ``angle + 2 pi turns``),
        speed and acceleration; an actuator's length (m), extension rate and
        its derivative.
    imu_specs : tuple of ImuSpec
        The scene's inertial sensors, whose readings :attr:`imus` gives.
    forces : Forces or None
        For a scene with masses, gravity or loads: every driver's effort,
        every joint's reaction and the shaking of the frame, bounded
        (:mod:`.forces`); ``None`` for a scene with none of them.
    """

    scene: str
    angle: Number
    speed: Number
    accel: Number
    joints: dict[str, JointMotion]
    complex_points: dict[str, tuple[Vector, Vector, Vector]]
    valid: bool | npt.NDArray[np.bool_]
    singularity: dict[str, Number]
    failures: dict[str, npt.NDArray[np.bool_]]
    error_bound: ErrorBound
    turns: int | npt.NDArray[np.int64] = 0
    rubbing: dict[str, Number] = field(default_factory=dict)
    intermittent: dict[str, Engagement] = field(default_factory=dict)
    jumps: dict[str, Any] = field(default_factory=dict)
    drivers: dict[str, JointMotion] = field(default_factory=dict)
    imu_specs: tuple[ImuSpec, ...] = ()
    forces: Forces | None = None

    @cached_property
    def imus(self) -> dict[str, ImuReading]:
        """What each of the scene's IMUs reads, with its bounds (:func:`.imu.imu_reading`)."""
        return {spec.name: imu_reading(self, spec) for spec in self.imu_specs}

    @cached_property
    def points(self) -> dict[str, PointState]:
        """Every reported point as 2-D vectors in the ground frame."""
        return {name: PointState(_xy(p), _xy(v), _xy(a))
                for name, (p, v, a) in self.complex_points.items()}

    @cached_property
    def scales(self) -> dict[str, Number]:
        """Per kind of value (:data:`mech_kinematics.bounds.KINDS`), its scale.

        ``position``: the mechanism's size; ``angle``: 1 rad; ``velocity``: the
        largest speed of a reported point or slider, at least the crank tip's
        ``a |omega|``; ``angular velocity``: the largest angular speed of a
        reported link, at least ``|omega|``; ``acceleration`` and ``angular
        acceleration`` likewise, at least ``a (omega^2 + |alpha|)`` and
        ``omega^2 + |alpha|``. A solve is refused where a value's error bound
        exceeds ``max_error`` times its kind's scale.
        """
        bound = self.error_bound
        vector = not isinstance(self.valid, bool)
        floors = bound.floors if bound.floors is not None else _crank_floors(
            bound.crank_length, self.speed, self.accel)
        return _scales(bound.size, floors,
                       [(v, a) for _, v, a in self.complex_points.values()],
                       [(j.velocity, j.acceleration) for j in self.joints.values()
                        if not j.type.angular],
                       [(j.velocity, j.acceleration) for j in self.joints.values()
                        if j.type.angular], vector)

    @cached_property
    def relative_error_bound(self) -> Number:
        """The largest error bound over its kind's scale, over every reported value.

        The smallest ``max_error`` at which this state would be answered (NaN
        where an array state is not valid).
        """
        scales = self.scales
        worst: Any = 0.0
        joints, points = self.error_bound.raw()
        records = [(b, _LINEAR) for b in points.values()]
        records += [(joints[name], j.type.quantities) for name, j in self.joints.items()]
        with np.errstate(divide='ignore', invalid='ignore'):
            for values, kinds in records:
                for value, kind in zip(values, kinds, strict=True):
                    scale = scales[kind]
                    ratio = np.where(value == 0.0, 0.0, np.asarray(value) / scale)
                    worst = np.fmax(worst, ratio)
        if isinstance(self.valid, bool):
            return float(worst)
        return np.where(self.valid, np.broadcast_to(worst, np.shape(self.valid)), np.nan)

    def as_dict(self) -> dict[str, Any]:
        """Return the structure the ``solve`` command prints (floats or arrays)."""
        vector = not isinstance(self.valid, bool)

        def value(x: Any) -> Any:
            return x if vector else float(x)

        def pair(x: npt.NDArray[np.float64]) -> Any:
            return x if vector else [float(x[0]), float(x[1])]

        turns = self.turns
        angle = self.angle if not np.any(turns) else self.angle + math.tau * turns
        # Several drivers, or an actuator (a length, not a crank's "angle"): by name.
        if len(self.drivers) > 1 or any(not j.type.angular for j in self.drivers.values()):
            driven: dict[str, Any] = {'inputs': {
                name: {'position': value(j.position), 'speed': value(j.velocity),
                       'accel': value(j.acceleration)} for name, j in self.drivers.items()}}
        else:
            driven = {'input': {'angle': value(angle), 'speed': value(self.speed),
                                'accel': value(self.accel)}}
        return {
            'scene': self.scene,
            **driven,
            'joints': {name: {'type': str(j.type), 'position': value(j.position),
                              'velocity': value(j.velocity),
                              'acceleration': value(j.acceleration)}
                       for name, j in self.joints.items()},
            'points': {name: {'position': pair(p.position), 'velocity': pair(p.velocity),
                              'acceleration': pair(p.acceleration)}
                       for name, p in self.points.items()},
            **({'rubbing': {name: value(x) for name, x in self.rubbing.items()}}
               if self.rubbing else {}),
            **({'intermittent': {name: e.as_dict(vector)
                                 for name, e in self.intermittent.items()}}
               if self.intermittent else {}),
            **({'jumps': {'joints': {name: {'acceleration': value(x['acceleration'])}
                                     for name, x in self.jumps['joints'].items()},
                          'points': {name: {'acceleration': pair(x['acceleration'])}
                                     for name, x in self.jumps['points'].items()},
                          **({'rubbing': {name: value(x) for name, x
                                          in self.jumps['rubbing'].items()}}
                             if 'rubbing' in self.jumps else {}),
                          **(self.jumps['forces'].as_dict(vector)
                             if 'forces' in self.jumps else {})}}
               if self.jumps else {}),
            **({'imus': {name: r.as_dict(vector) for name, r in self.imus.items()}}
               if self.imu_specs else {}),
            **(self.forces.as_dict(vector) if self.forces is not None else {}),
            'error_bound': {**self.error_bound.as_dict(vector),
                            **({'imus': {name: r.bounds_dict(vector)
                                         for name, r in self.imus.items()}}
                               if self.imu_specs else {}),
                            **(self.forces.bound_dict(vector)
                               if self.forces is not None else {})},
        }


def _crank_floors(crank_length: float, omega: Any, alpha: Any) -> tuple[Any, Any, Any, Any]:
    """Return the least scales of speed, acceleration and turning rates from one crank.

    ``a |omega|``, ``a (omega^2 + |alpha|)``, ``|omega|`` and
    ``omega^2 + |alpha|`` for the crank's length ``a``.
    """
    w = abs(omega)
    rate = w * w + abs(alpha)
    return crank_length * w, crank_length * rate, w, rate


def _scales(size: float, floors: tuple[Any, Any, Any, Any],
            points: Iterable[tuple[Any, Any]], sliders: Iterable[tuple[Any, Any]],
            links: Iterable[tuple[Any, Any]], vector: bool) -> dict[str, Any]:
    """Return each kind's scale (see :attr:`State.scales`) from the reported values.

    ``floors`` are the least scales of speed, acceleration, angular speed and
    angular acceleration that the drivers set (:func:`_crank_floors` for one
    crank).
    """
    biggest: Any = np.fmax if vector else max
    speed, accel, turn, turn_accel = floors
    for v, a in points:
        if vector:
            speed = biggest(speed, np.hypot(v.real, v.imag))
            accel = biggest(accel, np.hypot(a.real, a.imag))
        else:
            speed = biggest(speed, abs(v))
            accel = biggest(accel, abs(a))
    for v, a in sliders:
        speed = biggest(speed, abs(v))
        accel = biggest(accel, abs(a))
    for v, a in links:
        turn = biggest(turn, abs(v))
        turn_accel = biggest(turn_accel, abs(a))
    return {'position': size, 'angle': 1.0, 'velocity': speed, 'angular velocity': turn,
            'acceleration': accel, 'angular acceleration': turn_accel}
