# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's drivers on the clock: each one's time base, its start, and its parameters' effects.

Each driver of a scene gets an exact time base
(:mod:`~mech_kinematics.ros.timebase`): a driver whose position is an angle
(its joint type's ``angular``) a :class:`~.timebase.CrankTimebase`, which
counts whole turns and wraps; one whose position is a length an
:class:`~.timebase.ActuatorTimebase`. :func:`drive_start` builds its start
values from the scene and from the driver's parameters
(``inputs.NAME.<rate key>``, ``inputs.NAME.accel``, ``max_crank_speed_rpm``),
asking the driver's kind, never testing which kind it is.

A rate keeps the unit it was given (:class:`~mech_kinematics.solver.base.Rate`)
from the scene to the time base: a crank written ``speed_rpm: 7`` starts its
time base at exactly 7 rpm, one written ``speed: 10`` (rad/s) at 10 rad/s, so
the node publishes the speed ``solve`` prints, to the bit. The time base
converts it once, exactly (rpm / 60 turns/s). A rate set by a parameter is
in the parameter's unit (rpm for a crank, m/s for an actuator).

Pure: no ROS. Tested in ``test/ros/test_drive.py``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
import copy
from typing import Any, NamedTuple, TYPE_CHECKING

from .parameters import bounded_by_max_crank_speed, rate_default
from .timebase import ActuatorTimebase, CrankTimebase
from ..errors import AssemblyError, SceneError
from ..solver.base import Rate
from ..solver.solve import solve
from ..units import si_from_rate

if TYPE_CHECKING:
    from .driver import Timebase
    from ..solver.base import Driver
    from ..solver.mechanism import Scene

__all__ = ['DEFAULT_MAX_CRANK_SPEED_RPM', 'DriveStart', 'MAX_SPEED_KEY', 'check_start',
           'drive_start', 'driven_rate', 'max_crank_speed_default', 'position_text',
           'solve_at_start', 'stroke_refusal', 'timebase_kind', 'transposed']

#: Default bound on the crank speed, rpm (raised to the scene's speed if that is faster).
DEFAULT_MAX_CRANK_SPEED_RPM = 10_000.0
#: What the bound on the crank speed (``max_crank_speed_rpm``) sets in a time base.
MAX_SPEED_KEY = 'max_speed_rpm'


class DriveStart(NamedTuple):
    """A driver's time base class and start values, and its state at the start (SI)."""

    kind: Any
    """The time base class (``TickDriver.add_drive``)."""
    start: dict[str, Any]
    """Its start values: ``kind(t0, **start)``."""
    position: float
    """The driver's position at the start, rad or m."""
    speed: float
    """Its speed at the start, rad/s or m/s."""
    accel: float
    """Its acceleration, rad/s^2 or m/s^2."""
    turns: int
    """Whole turns of its start position."""


def timebase_kind(driver: Driver) -> type[Timebase]:
    """Return the time base class of ``driver``: one that turns for an angle, else a length's."""
    return CrankTimebase if driver.joint_type.angular else ActuatorTimebase


def driven_rate(driver: Driver, parameter: float, own: bool = True) -> Rate:
    """Return the rate ``driver``'s time base starts at, in the unit it was given in.

    ``parameter`` is the value of its rate parameter (in the unit of its
    kind's ``rate_parameter``). Where that is still the scene's own rate
    (:func:`~.parameters.rate_default`) and ``own`` (not given as
    ``crank_speed_rpm`` at start), the scene's rate as it was written
    (:attr:`Driver.rate`); else the parameter's. A scene's crank speed written
    in rad/s whose rpm reaches :data:`DEFAULT_MAX_CRANK_SPEED_RPM` is driven in
    rpm: the bound, which then defaults to that rpm, holds it exactly.
    """
    rate, (key, unit) = driver.rate, driver.rate_parameter
    if own and parameter == rate_default(driver) and (
            rate.unit == unit or abs(parameter) < DEFAULT_MAX_CRANK_SPEED_RPM):
        return rate
    return Rate(key, float(parameter), unit)


def drive_start(driver: Driver, values: Mapping[str, float], own: bool = True) -> DriveStart:
    """Return the time base and start of ``driver``, from its parameters' ``values``.

    ``values`` holds the values of its parameters by their last part (its
    rate key, ``accel``) and, for a driver the bound applies to,
    :data:`MAX_SPEED_KEY` (``max_crank_speed_rpm``'s value). ``own``: see
    :func:`driven_rate`.
    """
    kind = timebase_kind(driver)
    rate = driven_rate(driver, values[driver.rate_parameter.key], own)
    accel = float(values['accel'])
    # One of the time base's rates (a crank's speed_rpm or speed) given, the other None.
    start: dict[str, Any] = {kind.POSITION: driver.start, **dict.fromkeys(kind.RATES),
                             rate.key: rate.value, 'accel': accel}
    if MAX_SPEED_KEY in kind.CHANGES:
        start[MAX_SPEED_KEY] = values[MAX_SPEED_KEY]
    if driver.turns:
        # A start angle beyond a turn is whole turns plus an angle within one (Crank.turns).
        start['turns'] = driver.turns
    return DriveStart(kind, start, driver.start, si_from_rate(rate.value, rate.unit), accel,
                      driver.turns)


def max_crank_speed_default(drivers: Sequence[Driver], given_rpm: float | None) -> float:
    """Return the default of ``max_crank_speed_rpm``: 10000 rpm, or a faster crank's speed.

    ``given_rpm``: ``crank_speed_rpm`` given at start (it raises the bound too).
    """
    return max([DEFAULT_MAX_CRANK_SPEED_RPM, abs(given_rpm or 0.0),
                *(abs(rate_default(d)) for d in drivers if bounded_by_max_crank_speed(d))])


def check_start(scene: Scene, starts: Sequence[DriveStart], max_error: float) -> None:
    """Refuse to start where ``solve`` refuses the drivers' start (a ``SceneError``, one line)."""
    try:
        if len(starts) == 1:
            [(_, _, position, speed, accel, turns)] = starts
            solve(scene, position, speed, accel, turns=turns, max_error=max_error)
        else:
            _, _, positions, speeds, accels, turns = zip(*starts, strict=True)
            solve(scene, positions, speeds, accels, turns=turns, max_error=max_error)
    except AssemblyError as error:
        msg = f'{scene.name}: {error}'
        raise SceneError(msg) from None


def solve_at_start(scene: Scene) -> Any:
    """Return ``scene`` solved with its drivers at their start (a crank with its whole turns)."""
    drivers = scene.drivers
    turns = [d.turns for d in drivers]
    if len(drivers) == 1:
        return solve(scene, drivers[0].start, turns=turns[0])
    return solve(scene, [d.start for d in drivers], turns=turns)


def transposed(states: list[tuple[int, Any]]) -> tuple[tuple[int, ...], Any]:
    """Return the drivers' (turns, state) as (turns, (positions, speeds, accels)), in order."""
    turns = tuple(t for t, _ in states)
    return turns, tuple(zip(*(state for _, state in states), strict=True))


def position_text(angle: Any) -> str:
    """Return the drivers' position for a log line: one crank's angle, or every driver's."""
    if isinstance(angle, tuple):
        return f'driver positions {", ".join(f"{a:.6f}" for a in angle)}'
    return f'crank angle {angle:.6f} rad'


def stroke_refusal(driver: Driver, timebase: Any, now_ns: int,
                   changes: Mapping[str, tuple[str, float]],
                   values: Mapping[str, float] | None = None) -> str | None:
    """Return why a change of ``driver``'s drive is refused: it leaves the stroke at once.

    ``timebase``: the driver's time base (an :class:`~.timebase.ActuatorTimebase`)
    at ``now_ns``, or ``None`` before its first instant: then its start, from
    its parameters' ``values`` (as :func:`drive_start` takes them).
    ``changes``: its changes (``speed``, ``accel``) as (the parameter set, the
    value). The length now is exactly known; a drive that takes it out of its
    stroke from there (at or beyond a limit, not moving back) is refused.
    Later exits are the ticks' to report (the solver refuses them, and
    ``diagnostics`` says so); a drive that brings the length back is taken.
    ``None`` for a driver without a stroke.
    """
    if driver.stroke is None:
        return None
    if timebase is None:
        start = drive_start(driver, values or {})
        timebase, now_ns = start.kind(0, **start.start), 0
    trial = copy.deepcopy(timebase)
    trial.update(now_ns, **{key: value for key, (_, value) in changes.items()})
    if not trial.moves_out(now_ns, driver.stroke):
        return None
    length = float(trial.length(now_ns))
    given = ', '.join(f'{n} = {v!r}' for n, v in changes.values())
    low, high = driver.stroke
    return (f'{given}: expected a drive that keeps actuator {driver.name} within its '
            f'stroke [{low:g}, {high:g}] m, got one that leaves it at once (at {length:.6g} m)')
