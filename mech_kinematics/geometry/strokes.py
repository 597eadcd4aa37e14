# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Strokes and time ratios of reciprocating outputs; index and dwell of intermittent drives.

A quick-return mechanism is one whose output goes out and back over unequal
arcs of a crank turning at constant speed: the *time ratio* is the slower
stroke's crank arc over the quicker one's (Khurmi & Gupta's "ratio of the
time of cutting stroke to the time of return stroke"). :func:`strokes_from_assembly`
reads the strokes of every output that reverses off the dead centres that
:func:`mech_kinematics.geometry.assembly.assembly_from_scene` found (their
crank angles refined to its ``TOLERANCE``), in the order the crank meets
them turning at the scene's own speed (counter-clockwise at rest).

:func:`intermittent_from_scene` gives, for every intermittent (Geneva) lever,
the arc of each crank turn during which it indexes and the arc during which
it is locked, from the solver's own engagement windows; the index per turn
follows from the window: a pin entering and leaving an n-slot wheel
tangentially is in a slot for pi - 2 pi / n of the crank's turn.

Angles are in rad, counted counter-clockwise from +x; positions in rad or m.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
import warnings

from .assembly import Assembly
from ..errors import NearSingularWarning
from ..solver import Scene, solve

__all__ = ['Intermittent', 'Stroke', 'Strokes', 'intermittent_from_scene',
           'strokes_from_assembly']

_TURN = 2.0 * math.pi


@dataclass(frozen=True)
class Stroke:
    """One stroke of an output: from the crank angle ``start`` to ``end`` (rad, in [0, 2 pi)).

    The output goes from ``start_position`` to ``end_position`` (rad or m)
    while the crank turns through ``crank_travel`` (rad, > 0) in its own
    direction.
    """

    start: float
    end: float
    crank_travel: float
    start_position: float
    end_position: float


@dataclass(frozen=True)
class Strokes:
    """The strokes of one output ``joint`` (``kind`` revolute or prismatic) over a crank turn.

    ``time_ratio`` is the slower stroke's crank travel over the quicker's when
    there are exactly two strokes a turn (the output goes out and back once),
    None otherwise.
    """

    joint: str
    kind: str
    strokes: tuple[Stroke, ...]
    time_ratio: float | None


@dataclass(frozen=True)
class Intermittent:
    """An intermittent lever's cycle over one crank turn (crank angles in rad, in [0, 2 pi)).

    The lever indexes by ``index`` (rad, signed as it turns when the crank turns
    counter-clockwise) while the crank goes from ``engaged[0]`` to
    ``engaged[1]`` (CCW), and is locked for the rest of the turn.
    """

    lever: str
    engaged: tuple[float, float]
    index: float

    @property
    def engaged_travel(self) -> float:
        """The crank's travel (rad) during which the lever indexes."""
        return (self.engaged[1] - self.engaged[0]) % _TURN

    @property
    def locked_travel(self) -> float:
        """The crank's travel (rad) during which the lever is locked."""
        return _TURN - self.engaged_travel


def strokes_from_assembly(scene: Scene, assembly: Assembly) -> tuple[Strokes, ...]:
    """Return the strokes of every output that reverses, where the crank turns fully.

    A crank that cannot make a whole turn has no strokes (empty tuple): its
    output's motion then depends on how it is driven back and forth.
    """
    if not assembly.everywhere:
        return ()
    forward = scene.input.speed >= 0.0
    by_joint: dict[str, list[tuple[float, float, str]]] = {}
    for centre in assembly.dead_centres:
        by_joint.setdefault(centre.joint, []).append(
            (centre.angle % _TURN, centre.position, centre.kind))
    result = []
    for joint, centres in by_joint.items():
        centres.sort()
        if not forward:
            centres.reverse()
        kind = centres[0][2]
        strokes = []
        for (a, p, _), (b, q, _) in zip(centres, centres[1:] + centres[:1], strict=True):
            travel = (b - a) % _TURN if forward else (a - b) % _TURN
            strokes.append(Stroke(a, b, travel or _TURN, p, q))
        ratio = None
        if len(strokes) == 2:
            slow, quick = sorted((s.crank_travel for s in strokes), reverse=True)
            ratio = slow / quick
        result.append(Strokes(joint, kind, tuple(strokes), ratio))
    return tuple(result)


def intermittent_from_scene(scene: Scene) -> tuple[Intermittent, ...]:
    """Return the index and locked arcs of every intermittent lever of ``scene``."""
    if not scene.intermittent:
        return ()
    result = []
    with warnings.catch_warnings():
        # The windows do not depend on how well conditioned the rest of the scene is.
        warnings.simplefilter('ignore', NearSingularWarning)
        state = solve(scene, scene.input.angle, max_error=math.inf)
        for lever, engagement in state.intermittent.items():
            entry, exit_ = float(engagement.entry), float(engagement.exit)
            # The direction of indexing: the lever's angular velocity mid-window
            # with the crank turning counter-clockwise.
            middle = solve(scene, (entry + exit_) / 2.0, 1.0, 0.0, max_error=math.inf)
            sign = math.copysign(1.0, middle.joints[lever].velocity)
            result.append(Intermittent(lever, (entry % _TURN, exit_ % _TURN),
                                       sign * (math.pi - (exit_ - entry))))
    return tuple(result)
