# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Error bounds of a solve: what they mean, the scales they are judged on, the tolerance.

Every value the solver returns comes with an absolute error bound in SI
units: a first-order forward bound on the difference between the returned
double and the exact value, counting

- the rounding of the inputs: every scene length and coordinate, the guide
  angles and the crank's angle, speed and acceleration are taken as known only
  to half an ulp (``U |x|``), so the bound also covers the decimal numbers the
  doubles were rounded from;
- the rounding of every step of the closed forms, each dyad's own arithmetic
  counted as a perturbation of its inputs (the formulas are backward stable:
  the factored square roots of the dyads see to that) plus the rounding of the
  final sums and products;

propagated through the chain of dyads with each dyad's sensitivity to its
inputs: ``1 / measure`` for positions and the two-by-two velocity and
acceleration systems (the loss near a toggle, a change point, a guide at
grazing reach), ``1 / s`` for a slotted lever whose pin is ``s`` from its
pivot. The formulas live beside the values they bound, in the steps of
:mod:`mech_kinematics.linkage`; they are plain products and sums of
magnitudes, cheap enough for every tick.

A point's bound is one number, the bound on the Euclidean norm of its error
vector (m, m/s, m/s^2). An angle's bound is in rad, modulo 2 pi.

The tolerance ``max_error`` is relative to the *scale* of each kind of value
in the state (:data:`KINDS`, ``State.scales``): a solve is refused when the
bound of any requested value exceeds ``max_error`` times its kind's scale.
Whatever the tolerance, a dyad within :data:`ROUNDING_MARGIN` times the
rounding of its inputs of an assembly limit (where changing an input by an
ulp could make it unassemblable or flip its branch) is refused too.
"""

from __future__ import annotations

from collections.abc import Callable
import math
from typing import Any

import numpy as np
import numpy.typing as npt

__all__ = ['Bounds', 'ErrorBound', 'KINDS', 'LARGEST', 'MAX_ERROR', 'ROUNDING_MARGIN', 'U',
           'limit', 'magnitude']

#: Unit roundoff of IEEE doubles, 2**-53: the largest relative rounding error of one
#: correctly rounded operation.
U = 2.0 ** -53
#: Default tolerance of :func:`mech_kinematics.solve` and ``solve --max-error``: the
#: largest error bound accepted, relative to the kind's scale.
MAX_ERROR = 1e-6
#: A dyad is refused, whatever the tolerance, when its distance to an assembly limit
#: (the circles' margin of an RRR, the guide's of an RRP, the pin's distance from the
#: pivot of an RPR) is at most this many times that distance's own error bound. Beyond
#: it the first-order bounds hold to within a few per cent of their slack.
ROUNDING_MARGIN = 16.0
#: The largest finite double.
LARGEST = float(np.finfo(np.float64).max)
#: The smallest positive normal float64 (2.2e-308): the least scale a bound is judged on.
SMALLEST_NORMAL = float(np.finfo(np.float64).tiny)

#: The kinds of values a state holds, each judged on its own scale. Points and
#: sliders share the linear kinds; revolute joints have the angular ones.
KINDS = ('position', 'angle', 'velocity', 'angular velocity', 'acceleration',
         'angular acceleration')
#: Units of each kind.
UNITS = {'position': 'm', 'angle': 'rad', 'velocity': 'm/s', 'angular velocity': 'rad/s',
         'acceleration': 'm/s^2', 'angular acceleration': 'rad/s^2'}
#: What each kind's scale is, for messages and the README.
SCALE_MEANINGS = {
    'position': "the mechanism's size",
    'angle': '1 rad',
    'velocity': 'the largest speed of a point or slider, at least the crank tip speed',
    'angular velocity': "the largest angular speed of a link, at least the crank's",
    'acceleration': 'the largest acceleration of a point or slider, at least '
                    "a (omega^2 + |alpha|) for the crank's length a",
    'angular acceleration': 'the largest angular acceleration of a link, at least '
                            'omega^2 + |alpha|',
}

Number = float | npt.NDArray[np.float64]
Table = dict[str, tuple[Any, Any, Any]]
#: ``ErrorBound.rubbing`` of a scene without pins (replaced, never mutated).
_NO_PINS: dict[str, Any] = {}


def limit(max_error: Any, scale: Any) -> Any:
    """Return the largest bound accepted: ``max_error * scale``, capped at :data:`LARGEST`.

    The scale counts as at least :data:`SMALLEST_NORMAL`: below it floats are
    subnormal and hold no relative precision, so a speed of 1e-160 rpm (whose
    accelerations underflow to a few 1e-324) is answered with errors within
    ``max_error * SMALLEST_NORMAL`` instead of refused. The cap makes an
    infinite tolerance still refuse a bound that overflowed.
    """
    if isinstance(scale, np.ndarray) or isinstance(max_error, np.ndarray):
        lim = max_error * np.fmax(scale, SMALLEST_NORMAL)
        return np.fmin(lim, LARGEST)
    lim = max_error * max(scale, SMALLEST_NORMAL)
    return lim if lim <= LARGEST else LARGEST


def magnitude(z: Any) -> Any:
    """Return ``abs(z)``, or ``inf`` where the modulus of a finite complex overflows a double.

    Python's ``abs`` of such a complex raises ``OverflowError`` ("absolute value
    too large": ``abs(1.5e308 + 1.5e308j)``) where NumPy's gives ``inf``: the
    same bits otherwise, so a value that overflows is refused as non-finite
    (``forces (overflow)``) by the code that reads it, never raised.
    """
    try:
        return abs(z)
    except OverflowError:
        return math.inf


class Bounds:
    """Absolute error bounds of one joint or point, SI units.

    ``position`` (m, or rad for a revolute joint), ``velocity`` and
    ``acceleration``: floats for one crank angle, arrays of shape (n,) for n
    angles (NaN where the state is not valid). A point's bounds bound the
    Euclidean norm of its error vector.
    """

    __slots__ = ('position', 'velocity', 'acceleration')

    def __init__(self, position: Number, velocity: Number, acceleration: Number) -> None:
        self.position = position
        self.velocity = velocity
        self.acceleration = acceleration

    def __repr__(self) -> str:
        """Show every field."""
        return (f'Bounds(position={self.position!r}, velocity={self.velocity!r}, '
                f'acceleration={self.acceleration!r})')


class ErrorBound:
    """The error bounds of a state, shaped like its ``joints`` and ``points``.

    Built on first use from ``build(*args)``, which returns the joints' and the
    points' bounds as ``{name: (position, velocity, acceleration)}``: the
    single-angle path hands over its solve and pays nothing until they are read.

    Attributes
    ----------
    joints : dict of str to Bounds
        Per reported joint: angle (rad) or slider coordinate (m) and their
        first and second time derivatives.
    points : dict of str to Bounds
        Per reported point: norms of the position (m), velocity (m/s) and
        acceleration (m/s^2) errors.
    size : float
        The mechanism's size, m: the scale of positions.
    crank_length : float
        The crank's length, m: with the crank's rates, the least scale of the
        linear velocities and accelerations.
    rubbing : dict of str to float or ndarray
        Per pin of the scene's ``pins``: the bound of its rubbing velocity, m/s
        (judged on the velocity scale).
    floors : tuple or None
        With several drivers (or an actuator): the least scales of speed
        (m/s), acceleration (m/s^2), angular speed (rad/s) and angular
        acceleration (rad/s^2) that the drivers set; ``None`` for one crank,
        whose ``crank_length`` and rates set them.
    """

    __slots__ = ('_build', '_args', '_raw', '_records', 'size', 'crank_length', 'rubbing',
                 'floors')

    def __init__(self, build: Callable[..., tuple[Table, Table]], args: tuple[Any, ...],
                 size: float, crank_length: float,
                 floors: tuple[Any, Any, Any, Any] | None = None) -> None:
        self._build = build
        self._args = args
        self._raw: tuple[Table, Table] | None = None
        self._records: tuple[dict[str, Bounds], dict[str, Bounds]] | None = None
        self.size = size
        self.crank_length = crank_length
        self.rubbing: dict[str, Any] = _NO_PINS
        self.floors = floors

    def raw(self) -> tuple[Table, Table]:
        """Return the joints' and the points' bounds: (position, velocity, acceleration)."""
        if self._raw is None:
            self._raw = self._build(*self._args)
        return self._raw

    def _records_(self) -> tuple[dict[str, Bounds], dict[str, Bounds]]:
        if self._records is None:
            joints, points = self.raw()
            self._records = ({name: Bounds(*b) for name, b in joints.items()},
                             {name: Bounds(*b) for name, b in points.items()})
        return self._records

    @property
    def joints(self) -> dict[str, Bounds]:
        """Bounds of every reported joint."""
        return self._records_()[0]

    @property
    def points(self) -> dict[str, Bounds]:
        """Bounds of every reported point."""
        return self._records_()[1]

    def as_dict(self, vector: bool) -> dict[str, Any]:
        """Return ``{"joints": ..., "points": ...}`` and ``"rubbing"``, as ``State.as_dict()``."""
        def value(x: Any) -> Any:
            return x if vector else float(x)

        def record(b: tuple[Any, Any, Any]) -> dict[str, Any]:
            return {'position': value(b[0]), 'velocity': value(b[1]),
                    'acceleration': value(b[2])}

        joints, points = self.raw()
        data = {'joints': {name: record(b) for name, b in joints.items()},
                'points': {name: record(b) for name, b in points.items()}}
        if self.rubbing:  # a scene with pins
            data['rubbing'] = {name: value(b) for name, b in self.rubbing.items()}
        return data
