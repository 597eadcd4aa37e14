# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The scene-side model shared by the step kinds: names, checks, units for messages, links.

Everything here is SI: metres, radians, seconds. Angles are counter-clockwise
from +x; angular velocities and accelerations are positive counter-clockwise.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from enum import IntEnum
import math
import re

import numpy as np
import numpy.typing as npt

from ..errors import SceneError
from ..units import ANGLE_UNITS, degrees_from_radians, LENGTH_UNITS

IDENTIFIER = re.compile(r'[A-Za-z_][A-Za-z0-9_]*\Z')

Number = float | npt.NDArray[np.float64]
Vector = complex | npt.NDArray[np.complex128]


class Branch(IntEnum):
    """Assembly branch of a dyad.

    For an RRR dyad ``PLUS`` takes the new pin to the left of the directed
    line from the first link's start to the second's; for an RRP dyad it takes
    the larger slider coordinate.
    """

    PLUS = 1
    MINUS = -1


Where = tuple[object, str] | None


def _check_name(name: str, what: str, where: Where = None) -> None:
    if not isinstance(name, str) or not IDENTIFIER.match(name):
        msg = f'Expected {what} to be an identifier ([A-Za-z_][A-Za-z0-9_]*), got {name!r}'
        raise SceneError(msg, where)


def _check_finite(value: float, what: str, where: Where = None) -> None:
    if not math.isfinite(value):
        msg = f'Expected {what} to be a finite number, got {value!r}'
        raise SceneError(msg, where)


def _check_length(value: float, what: str, where: Where = None) -> None:
    if not (math.isfinite(value) and value > 0.0):
        msg = f'Expected {what} to be a positive length, got {_g(value)} m'
        raise SceneError(msg, where)


def _g(value: float, *others: float) -> str:
    """Return ``value`` to 6 significant digits, or more where ``others`` would look equal."""
    digits = 6
    while digits < 17 and any(o != value and f'{o:.{digits}g}' == f'{value:.{digits}g}'
                              for o in others):
        digits += 1
    return f'{value:.{digits}g}'


@dataclass(frozen=True)
class SceneUnits:
    """The units a scene was written in, for messages: ``length`` m or mm, ``angle`` rad or deg.

    Everything the solver holds and returns is SI; these only say how to show
    a scene's own values back to the person who wrote them.
    """

    length: str = 'm'
    angle: str = 'rad'

    def __post_init__(self) -> None:
        """Validate the fields."""
        if self.length not in LENGTH_UNITS or self.angle not in ANGLE_UNITS:
            msg = (f'Expected units length in {", ".join(LENGTH_UNITS)} and angle in '
                   f'{", ".join(ANGLE_UNITS)}, got {self.length!r} and {self.angle!r}')
            raise SceneError(msg, (self, 'length'))

    def length_text(self, metres: float, *others: float) -> str:
        """Return a length given in m as text in the scene's unit, 6 significant digits."""
        per = LENGTH_UNITS[self.length]
        return f'{_g(metres * per, *(o * per for o in others))} {self.length}'

    def angle_value(self, radians: float) -> float:
        """Return an angle given in rad in the scene's unit."""
        return degrees_from_radians(radians) if self.angle == 'deg' else radians

    def angle_text(self, radians: float) -> str:
        """Return an angle given in rad as text in the scene's unit, 6 significant digits."""
        return f'{_g(self.angle_value(radians))} {self.angle}'


@dataclass(frozen=True)
class Link:
    """A binary link of a dyad, from a known point to the dyad's new point."""

    name: str
    start: str
    length: float

    def __post_init__(self) -> None:
        """Validate the fields."""
        _check_name(self.name, 'a link name', (self, 'name'))
        _check_name(self.start, f'the start point of link "{self.name}"', (self, 'start'))
        _check_length(self.length, f'link "{self.name}" length', (self, 'length'))


def _names(names: Iterable[str], most: int = 10) -> str:
    """Return ``A, B, C`` for a message: the first ``most`` names and how many more."""
    names = list(names)
    shown = ', '.join(names[:most])
    return shown if len(names) <= most else f'{shown} and {len(names) - most} more'
