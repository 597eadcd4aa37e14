# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's tick: a scene's solve at one instant, as the flat list of its messages' values.

A node solving one instant per tick at kilohertz rates pays for every
dictionary lookup, attribute read and object the general solver makes, and,
waking from a sleep each tick with cold caches, for the size of the code it
runs. The solver's one compiler (:func:`mech_kinematics.solver.compiler.compile_scene`,
target :class:`~mech_kinematics.solver.compiler.Tick`) writes the scene's
kernels out as one straight-line function returning the values the node's
message templates take; this module asks it for that function
(:func:`compiled_tick`), with :func:`general_tick` (the same answers from
:func:`mech_kinematics.solve`) as its fallback for the instants it hands over
and as what the node serves where the scene does not compile. The order of
the values is :func:`values_from_state`'s.

The compiled function returns the same bits as :func:`mech_kinematics.solve`
and raises the same errors (``test_ticker`` checks every packaged scene and
the extreme suite over a cycle). Where the scene does not compile,
:func:`compiled_tick` says why (:class:`~mech_kinematics.solver.compiler.NotCompiled`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
import math

from .. import solver as lk
from ..solver.compiler import compile_scene, FrameSpec, NotCompiled, Tick, TickFunction

__all__ = ['NOT_IN_THE_TICK', 'TickFunction', 'compile_tick', 'compiled_tick', 'general_tick',
           'tick_function', 'values_from_state']

#: Why a scene the general tick solves is not compiled by ``mk.solve`` (:func:`general_tick`).
NOT_IN_THE_TICK = ("the node's tick never compiles in its own thread (ros.ticker.general_tick): "
                   'it compiles through compiled_tick')


def values_from_state(state: lk.State, joints: Sequence[str], points: Sequence[str],
                      frames: Sequence[FrameSpec] = ()) -> list[float]:
    """Return the values of a single-angle state in the order of a tick function.

    That order, ``[positions of joints..., their velocities..., their
    accelerations..., x, y of every point's position..., of every velocity...,
    of every acceleration..., x, y, angle of every frame...]``, is the order of
    the float slots of the node's message templates.
    """
    motions = [state.joints[name] for name in joints]
    values = [float(m.position) for m in motions]
    values += [float(m.velocity) for m in motions]
    values += [float(m.acceleration) for m in motions]
    for index in range(3):
        for name in points:
            z = state.complex_points[name][index]
            values += (float(z.real), float(z.imag))
    for origin, angle_of, angle in frames:
        p = state.complex_points[origin][0]
        values += (float(p.real), float(p.imag), angle if angle_of is None
                   else float(state.joints[angle_of].position))
    return values


def general_tick(scene: lk.Scene, joints: Sequence[str] | None,
                 points: Sequence[str] | None,
                 frames: Sequence[FrameSpec]) -> TickFunction:
    """Return a tick function around the general solver (same signature, same answers).

    It never compiles in the thread that calls it. :func:`mech_kinematics.solve`
    compiles a scene's single-angle path in its caller's thread once it has
    solved it :data:`~mech_kinematics.solver.solve.COMPILE_AFTER` times; in the
    node's tick thread that compile was a stall of the stream: a 100-dyad strip,
    served by this function while its tick compiled in the background, published
    nothing from its 256th instant until that compile was done (about 3 s on an
    idle machine, 14 to 21 s beside two CPU hogs); a crank at rest, whose every
    instant the compiled tick hands over here, stalled likewise. So ``scene``'s
    single-angle path is settled as not compiled (:data:`NOT_IN_THE_TICK`) unless
    it already is; ``mk.solve`` then answers ``scene`` by its general path, the
    same bits (``test_compiler_solve``).
    """
    lk.keep_general_path(scene, NOT_IN_THE_TICK)
    joints = tuple(scene.output_joints if joints is None else joints)
    points = tuple(scene.output_points if points is None else points)
    frames = tuple(frames)
    if scene.dynamics is not None:
        # The tick reports the motion, as the compiled tick does: solved alone, an instant is
        # never refused for forces it does not report (the node's forces are issue 32's).
        scene = replace(scene, gravity=None, masses=(), loads=(),
                        outputs_joints=scene.output_joints, outputs_points=scene.output_points)

    def general(theta: float, omega: float, alpha: float, tol: float,
                turns: int = 0) -> tuple[list[float], float]:
        state = lk.solve(scene, theta, omega, alpha, turns=turns, max_error=tol)
        measures = state.singularity.values()
        return (values_from_state(state, joints, points, frames),
                float(min(measures)) if measures else math.inf)

    return general


def compiled_tick(scene: lk.Scene, joints: Sequence[str] | None = None,
                  points: Sequence[str] | None = None,
                  frames: Sequence[FrameSpec] = ()) -> TickFunction | NotCompiled:
    """Return ``scene``'s tick compiled into one straight-line function, or why it is not.

    Parameters
    ----------
    scene : Scene
        The mechanism. Its outputs must include ``joints``, ``points``, and the
        origins and angle joints of ``frames``.
    joints, points : sequence of str, optional
        The joints and points whose values the function returns, in order
        (default: the scene's outputs).
    frames : sequence of (origin point, angle joint or None, fixed angle)
        Frames whose pose (x, y of the origin, angle) follows the values.

    Returns
    -------
    callable or NotCompiled
        ``tick(theta, omega, alpha, max_error, turns=0) -> (values, measure)``
        (``theta + 2 pi turns`` is the crank angle counted from the start; a
        scene of several drivers takes one value per driver): ``values`` in
        :func:`values_from_state`'s order, ``measure`` the smallest
        near-singularity measure (inf if none). It raises exactly as
        :func:`mech_kinematics.solve` does, which it calls (:func:`general_tick`)
        for an instant it cannot settle itself. Where the scene does not
        compile, a falsy :class:`~mech_kinematics.solver.compiler.NotCompiled`
        with the reason.
    """
    joints = tuple(scene.output_joints if joints is None else joints)
    points = tuple(scene.output_points if points is None else points)
    frames = tuple(frames)
    return compile_scene(scene, Tick(joints, points, frames,
                                     general_tick(scene, joints, points, frames)))


def compile_tick(scene: lk.Scene, joints: Sequence[str] | None = None,
                 points: Sequence[str] | None = None,
                 frames: Sequence[FrameSpec] = ()) -> TickFunction | None:
    """Return :func:`compiled_tick`'s function, or ``None`` where the scene does not compile."""
    tick = compiled_tick(scene, joints, points, frames)
    return None if isinstance(tick, NotCompiled) else tick


def tick_function(scene: lk.Scene, joints: Sequence[str] | None = None,
                  points: Sequence[str] | None = None,
                  frames: Sequence[FrameSpec] = ()) -> tuple[TickFunction, bool]:
    """Return (the tick function of ``scene``, whether it is compiled).

    The compiled function of :func:`compiled_tick` where the scene compiles,
    else :func:`general_tick`'s, with the same signature and answers.
    """
    tick = compiled_tick(scene, joints, points, frames)
    if isinstance(tick, NotCompiled):
        return general_tick(scene, joints, points, frames), False
    return tick, True
