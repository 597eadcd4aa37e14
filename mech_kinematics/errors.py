# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Errors and warnings raised by the scene loader and the solver."""

from __future__ import annotations

from typing import Any


class MechKinematicsError(ValueError):
    """Base class of every error this package raises on bad input."""


class SceneError(MechKinematicsError):
    """A scene file or scene description is invalid.

    The message names the file (when there is one), the key and the reason,
    e.g. ``four_bar.yaml: dyads[0].links[1].length: expected a positive
    length, got -80``.

    Attributes
    ----------
    where : tuple of (object, str) or None
        The scene element at fault and its field, when the error is raised on
        an element already built, so that a loader can name the file's key.
    """

    def __init__(self, msg: str, where: tuple[object, str] | None = None) -> None:
        super().__init__(msg)
        self.where = where


class UrdfError(SceneError):
    """A robot description (URDF, loop closures, actuated joints) we cannot read or solve.

    One line naming the source and what is wrong: a URDF that is not one, a
    closure or sidecar that does not fit it, a loop that is not planar, a
    zero pose that does not close, a loop that is no chain of our kinds.

    Attributes
    ----------
    joint : str or None
        The URDF joint (or closure) at fault, where there is one.
    """

    def __init__(self, msg: str, *, joint: str | None = None) -> None:
        super().__init__(msg)
        self.joint = joint


class AssemblyError(MechKinematicsError):
    """The mechanism cannot be solved at a given crank angle.

    Raised when a dyad cannot close (circles that do not meet, a guide out of
    reach) or is singular (its two links in line, a slider pin on its pivot).

    Attributes
    ----------
    dyad : str
        Label of the dyad that failed, e.g. ``RRR C``.
    angle : float
        The crank angle, rad.
    reason : str
        The violated condition (numbers to 6 significant digits, SI units).
    facts : dict or None
        The failure as data, for a message in a scene's own units: ``kind``
        (``'apart'``: an RRR's circles do not meet; ``'in line'``: its links
        are in line; ``'reach'``: an RRP's guide is out of reach; ``'pivot'``:
        an RPR pin on its pivot) and the names and SI values involved.
    """

    def __init__(self, dyad: str, angle: float, reason: str, *,
                 facts: dict[str, Any] | None = None) -> None:
        self.dyad = dyad
        self.angle = angle
        self.reason = reason
        self.facts = facts
        msg = f'{dyad} cannot be solved at crank angle {angle:.6g} rad: {reason}'
        super().__init__(msg)

    def located(self, where: str) -> AssemblyError:
        """Return a copy whose message says where the drivers stand (``where``).

        For a scene with several drivers (or an actuator), where no single
        crank angle says it: ``RRR C cannot be solved at crank = 0.5 rad,
        cyl = 1.2 m: ...``.
        """
        copy = type(self).__new__(type(self))
        copy.__dict__.update(self.__dict__)
        copy.args = (f'{self.dyad} cannot be solved at {where}: {self.reason}',)
        return copy


class UntrustedError(AssemblyError):
    """The mechanism's state at a given crank angle cannot be trusted, so it is refused.

    Raised when the error bound of a requested value exceeds the tolerance
    (``max_error`` times its kind's scale), when a dyad is within rounding of
    an assembly limit (an ulp's change of an input could make it unassemblable
    or flip its branch), or when the state overflows the range of doubles.

    Attributes
    ----------
    dyad : str
        Label of the dyad that produced the value, e.g. ``RRR C``.
    angle : float
        The crank angle, rad.
    reason : str
        What cannot be trusted, with the numbers.
    value : str
        The value refused, as its path in ``State.as_dict()`` (e.g.
        ``joints.rocker.acceleration``), or ``margin`` for a dyad within
        rounding of its assembly limit.
    bound : float
        Its error bound, SI units.
    tolerance : float
        The largest bound accepted, SI units (``max_error`` times the scale).
    """

    def __init__(self, dyad: str, angle: float, reason: str, value: str, bound: float,
                 tolerance: float, *, facts: dict[str, Any] | None = None) -> None:
        super().__init__(dyad, angle, reason, facts=facts)
        self.value = value
        self.bound = bound
        self.tolerance = tolerance


class TargetError(MechKinematicsError):
    """A loop cannot be driven to the targets asked (:mod:`.solver.inverse`).

    One line: a target the loop does not report, a count other than its
    drivers', a target out of reach (how far, per target, along the straight
    path from the start pose), or one near a singular point of the inverse
    map, where the drivers' values cannot be trusted.

    Attributes
    ----------
    reached : float or None
        For a target out of reach, the share of the straight path from the
        start pose (0 to 1) the loop follows before it can go no further.
    short : dict of str to float or None
        For a target out of reach, how far each target is left short (SI).
    """

    def __init__(self, msg: str, *, reached: float | None = None,
                 short: dict[str, float] | None = None) -> None:
        super().__init__(msg)
        self.reached = reached
        self.short = short


class NearSingularWarning(UserWarning):
    """The mechanism is close to a singular position; results lose accuracy."""
