# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Power-of-two rescaling: a scene far from 1 m, or a crank far from 1 rad/s, solved in range.

Scaling by a power of two is exact, so the answers are the same bits as if
every product had stayed in range. Each item scales its own lengths
(:meth:`~.base.Item.scaled`).
"""

from __future__ import annotations

import cmath
from dataclasses import replace
import math
from types import SimpleNamespace
from typing import Any, cast, TYPE_CHECKING

import numpy as np

from .context import _Context
from ..bounds import LARGEST
from ..errors import UntrustedError

if TYPE_CHECKING:
    from .mechanism import _Solver, Scene

#: Mechanism sizes (m) solved as they are; a scene outside is solved with every
#: length scaled by a power of two (exactly), so that no product of lengths
#: overflows or underflows, and its answers scaled back.
_SIZE_RANGE = (2.0 ** -60, 2.0 ** 60)
#: Crank rates ``max(|omega|, sqrt|alpha|)`` (1/s) solved as they are; outside,
#: time is scaled by a power of two the same way.
_RATE_LOW, _RATE_HIGH = 2.0 ** -40, 2.0 ** 40
_ACCEL_HIGH = _RATE_HIGH * _RATE_HIGH
#: What scaling a result back by a power of two can lose (a subnormal result
#: rounds by half the smallest subnormal, its bound by as much again).
_TINY = 2.0 ** -1073
#: The kinds of a point's (or slider's) values and of a revolute joint's.
_LINEAR = ('position', 'velocity', 'acceleration')
_ANGULAR = ('angle', 'angular velocity', 'angular acceleration')
_QUANTITIES = ('position', 'velocity', 'acceleration')


def _size(scene: Scene) -> float:
    """Return the mechanism's size, m: the scale its positions are judged on.

    The largest of the crank length (every driver's reach: a crank's length,
    an actuator's longest length), the RRR and RRP link lengths, the
    distances of the ground points from the crank's centre (the first ground
    point's, in a scene driven by actuators only) and the lengths of the
    carried points' local offsets.
    """
    crank = scene.input
    drivers = scene.drivers
    centre = complex(*(scene.ground[crank.center] if crank is not None
                       else next(iter(scene.ground.values()))))
    size = max(driver.reach for driver in drivers) if len(drivers) > 1 else drivers[0].reach
    for x, y in scene.ground.values():
        size = max(size, abs(complex(x, y) - centre))
    for dyad in scene.dyads:
        lengths = dyad.lengths()
        if lengths:
            size = max(size, *lengths)
    for point in scene.points:
        size = max(size, math.hypot(*point.local))
    return size


def _exponent(x: float, low: float, high: float) -> int:
    """Return 0 if ``x`` is 0 or in [low, high], else ``e`` with ``x * 2**-e`` in [0.5, 2).

    At most 1023, so that ``2**e`` is a float: ``x`` of 2**1023 or more (up
    to the largest float) is scaled into [1, 2).
    """
    if x == 0.0 or low <= x <= high:
        return 0
    return min(math.frexp(x)[1], 1023)


def _scaled(scene: Scene, shift: int) -> Scene:
    """Return ``scene``'s geometry with every length times ``2**-shift`` (exact), to compile."""
    def scale(x: float) -> float:
        return math.ldexp(x, -shift)

    dyads = [dyad.scaled(scale) for dyad in scene.dyads]
    drivers = tuple(driver.scaled(scale) for driver in scene.drivers)
    return cast('Scene', SimpleNamespace(
        name=scene.name,
        ground={name: (scale(x), scale(y)) for name, (x, y) in scene.ground.items()},
        input=None if scene.input is None else drivers[0], drivers=drivers,
        dyads=tuple(dyads),
        points=tuple(p.scaled(scale) for p in scene.points),
        pins=tuple(replace(p, radius=scale(p.radius)) for p in scene.pins), units=scene.units))


def _rates_exponent(speeds: Any, accels: Any) -> int:
    """Return the exponent of time's scaling for several drivers: the same for every one.

    ``speeds`` and ``accels`` are the drivers' rates in the plan's units (an
    actuator's divided by the scene's length scale): 1/s and 1/s^2.
    """
    w = a = 0.0
    for speed, accel in zip(speeds, accels, strict=True):
        ws, as_ = abs(speed), abs(accel)
        if isinstance(ws, np.ndarray):
            ws = float(np.max(ws, initial=0.0))
        if isinstance(as_, np.ndarray):
            as_ = float(np.max(as_, initial=0.0))
        w, a = max(w, float(ws)), max(a, float(as_))
    return _rate_exponent(w, a)


def _rate_exponent(omega: Any, alpha: Any) -> int:
    w, a = abs(omega), abs(alpha)
    if isinstance(w, np.ndarray):   # each alone: a constant speed with an array of accels
        w = float(np.max(w, initial=0.0))
    if isinstance(a, np.ndarray):
        a = float(np.max(a, initial=0.0))
    if _RATE_LOW <= w <= _RATE_HIGH and a <= _ACCEL_HIGH:
        return 0
    return _exponent(max(w, math.sqrt(a)), _RATE_LOW, _RATE_HIGH)


def _ldexp(x: Any, exponent: int) -> Any:
    """Return ``x * 2**exponent`` (inf on overflow) for floats, complex numbers and arrays."""
    if isinstance(x, complex):
        return complex(_ldexp(x.real, exponent), _ldexp(x.imag, exponent))
    if isinstance(x, float):
        try:
            return math.ldexp(x, exponent)
        except OverflowError:
            return math.copysign(math.inf, x)
    if np.iscomplexobj(x):
        out = np.empty(np.shape(x), dtype=np.complex128)
        out.real = np.ldexp(x.real, exponent)
        out.imag = np.ldexp(x.imag, exponent)
        return out
    return np.ldexp(x, exponent)


def _finite(x: Any) -> Any:
    if isinstance(x, (float, complex)):
        return cmath.isfinite(x)
    return np.isfinite(x)


def _rescale(solver: _Solver, ctx: _Context, shift: int) -> None:
    """Scale the reported values of a solve in scaled units back to SI; refuse what overflows."""
    s = solver.shift
    linear = (s, s + shift, s + 2 * shift)
    angular = (0, shift, 2 * shift)
    for table, name, path, label, _ in solver.outputs:
        store = getattr(ctx, table)
        x, dx, ddx, ex, edx, eddx = store[name]
        k0, k1, k2 = angular if table == 'links' else linear
        entry = (x if table == 'links' else _ldexp(x, k0), _ldexp(dx, k1), _ldexp(ddx, k2),
                 ex if table == 'links' else _ldexp(ex, k0) + _TINY,
                 _ldexp(edx, k1) + _TINY, _ldexp(eddx, k2) + _TINY)
        store[name] = entry
        if ctx.vector:
            ok = _finite(entry[0])
            for x in entry[1:]:
                ok = ok & _finite(x)
            # A constant (a ground point) is a plain bool here: mask takes arrays.
            ctx.mask(np.asarray(ok), f'{label} (overflow)')
            continue
        for index, quantity in enumerate(_QUANTITIES):
            if not (_finite(entry[index]) and _finite(entry[index + 3])):
                what = 'its error bound' if _finite(entry[index]) else 'it'
                reason = (f'the state overflows: the {quantity} of {path} is beyond the range '
                          f'of doubles (scaled back to SI, {what} exceeds {LARGEST:.3g})')
                raise UntrustedError(label, ctx.shown, reason, f'{path}.{quantity}', math.inf,
                                     LARGEST)
    k = s + shift
    for name, (value, bound) in ctx.rubbing.items():
        value, bound = _ldexp(value, k), _ldexp(bound, k) + _TINY
        ctx.rubbing[name] = (value, bound)
        if ctx.vector:
            ctx.mask(_finite(value) & _finite(bound), f'pin {name} (overflow)')
        elif not (_finite(value) and _finite(bound)):
            reason = (f'the state overflows: the rubbing velocity at pin {name} is beyond the '
                      f'range of doubles (scaled back to SI, it exceeds {LARGEST:.3g})')
            raise UntrustedError(f'pin {name}', ctx.shown, reason, f'rubbing.{name}', math.inf,
                                 LARGEST)
