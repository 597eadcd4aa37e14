# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Which function solves the node's ticks: the compiled tick, or the general solver and why.

The one compiler (:func:`~mech_kinematics.ros.ticker.compiled_tick`) answers
the scene's tick as one straight-line function, or a
:class:`~mech_kinematics.solver.compiler.NotCompiled` with its reason (pins
to bound, a rescaled scene). :class:`SolverPath` keeps the function that
serves and says which path it is (:attr:`SolverPath.path`: ``'compiled'`` or
``'general: REASON'``, the key ``solver_path`` of the solver status on
``diagnostics``); where the tick does not compile the node logs, at info,
``solved by the general solver: REASON``. Nothing catches an exception of the
compiler: a reason is an answer, anything else is a bug and shows.

Compiling takes about 25 ms a step and the assembly sweep about 3 ms a step.
A scene of more than :data:`BACKGROUND_STEPS` dyads and points starts on the
general solver (the same answers, bit for bit) and a thread sweeps and
compiles it (:meth:`SolverPath.setup` returns it, for the node to start once
its set-up is done); the compiled function takes over the next tick after it
is made, so a long chain is published from the start instead of after
minutes.

On a scene whose forces the node publishes (a :class:`~mech_kinematics.ros.wrenches.ForcesTick`
handed to :meth:`SolverPath.setup`), the forces tick serves: the forces are
solved at a solved state, which the compiled tick does not make. Its motion
is ``mk.solve``'s compiled single-angle path where the scene compiles (one
crank, at most :data:`BACKGROUND_STEPS` dyads and points, compiled before
the ticks), then the statics written out: the path is ``compiled: `` and
:data:`FORCES`; else ``general: `` and why the motion does not compile.

No ROS: the node hands over its logger's ``info``. Tested in
``test/ros/test_solver_path.py``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
import contextlib
import threading
import time
from typing import TYPE_CHECKING

from .ticker import compiled_tick, general_tick
from ..geometry.assembly import assembly_summary
from ..solver.compiler import NotCompiled

if TYPE_CHECKING:
    from ..solver.compiler import FrameSpec, TickFunction
    from ..solver.mechanism import Scene

__all__ = ['BACKGROUND_STEPS', 'COMPILED', 'COMPILING', 'FORCES', 'GENERAL', 'SolverPath']

#: A scene of more dyads and points than this compiles its tick in the background.
BACKGROUND_STEPS = 16
#: The path of a compiled tick (``solver_path`` on ``diagnostics``).
COMPILED = 'compiled'
#: What the log says of a tick served by the general solver, before its reason.
GENERAL = 'solved by the general solver'
#: The general path's reason while the tick compiles in the background.
COMPILING = 'its tick compiles in the background'
#: What serves the ticks where the node publishes forces and their motion compiles.
FORCES = ("the motion by mk.solve's compiled path, then the forces at its state "
          '(solver/forces.py: the compiled tick makes no state)')


class SolverPath:
    """The function that solves the node's ticks, its path, and where the scene cannot assemble.

    Parameters
    ----------
    max_error : float
        The tolerance the ticks are solved to (``max_relative_error``; the node
        sets :attr:`max_error` when it changes).

    Attributes
    ----------
    solve : callable or None
        The tick function, ``solve(position, speed, accel, max_error, turns)``
        (:mod:`~mech_kinematics.ros.ticker`), once :meth:`setup` has run.
    path : str
        ``'compiled'``, or ``'general: REASON'`` where the general solver serves.
    assembly : str
        Where the scene cannot assemble over its crank's turn, one line (''
        for a scene of several drivers or an actuator, or until swept).
    jumps_at : callable or None
        ``jumps_at(angle, turns=...)``: whether a value jumps at a crank
        position (a Geneva wheel's engagement), for a scene that has such.
    """

    def __init__(self, max_error: float) -> None:
        self.max_error = max_error
        self.solve: TickFunction | None = None
        self.path = ''
        self.assembly = ''
        self.jumps_at: Callable[..., bool] | None = None
        self._token: object | None = None

    def setup(self, tick_scene: Scene, scene: Scene, frames: Sequence[FrameSpec],
              log: Callable[[str], None],
              forces: TickFunction | None = None) -> threading.Thread | None:
        """Set the tick function of ``tick_scene``; return a thread to start, or ``None``.

        ``tick_scene`` is ``scene`` outputting what ``frames`` (origin, angle
        joint, fixed angle) need too; the function returns the values of
        ``scene``'s outputs and of the frames. ``log`` takes the info lines.
        ``forces``: the forces tick, which then serves (nothing is compiled).
        The thread (not started: started once the rest of the set-up is done,
        as a thread holding the GIL slows every release and re-acquisition of
        it by the node's) sweeps and compiles a long scene in the background.
        """
        outputs = (tick_scene, scene.output_joints, scene.output_points, tuple(frames))
        steps = len(scene.dyads) + len(scene.points)
        sweep = len(scene.drivers) == 1 and scene.input is not None
        self._token = token = object()     # a later set-up or drop() makes this one stale
        self.jumps_at = tick_scene.jumps_at if tick_scene.intermittent else None
        self.assembly = ''
        if forces is not None:
            if sweep and steps <= BACKGROUND_STEPS:
                self.assembly = assembly_summary(scene)
            self.solve = forces
            why = forces.motion  # type: ignore[attr-defined]  (a ForcesTick's)
            if why is None:
                self.path = f'{COMPILED}: {FORCES}'
                log(f'the forces tick serves: {FORCES}')
            else:
                self.path = f'general: {why.reason}'
                log(f'{GENERAL} (the motion the forces are solved at): {why.reason}')
            return None
        if steps <= BACKGROUND_STEPS:
            if sweep:
                self.assembly = assembly_summary(scene)
            tick = compiled_tick(*outputs)
            self.solve = general_tick(*outputs) if isinstance(tick, NotCompiled) else tick
            line = self._took(tick)
            if line:
                log(line)
            return None
        self.solve = general_tick(*outputs)
        self.path = f'general: {COMPILING}'
        log(f'the scene has {steps} dyads and points: the general solver serves while its '
            'tick compiles in the background')

        def compile_in_background() -> None:
            started = time.monotonic()
            if sweep:
                summary = assembly_summary(scene)
                if self._token is token:
                    self.assembly = summary
            tick = compiled_tick(*outputs)
            if self._token is not token:
                return
            if not isinstance(tick, NotCompiled):
                self.solve = tick
            line = self._took(tick) or (f'the compiled tick serves from now (compiled in '
                                        f'{time.monotonic() - started:.1f} s)')
            # (the node may be shutting down: a log it cannot write is no error)
            with contextlib.suppress(Exception):
                log(line)

        return threading.Thread(target=compile_in_background, name='compile the tick',
                                daemon=True)

    def _took(self, tick: TickFunction | NotCompiled) -> str:
        """Set :attr:`path` from the compiler's answer; return what to log of a fallback."""
        if isinstance(tick, NotCompiled):
            self.path = f'general: {tick.reason}'
            return f'{GENERAL}: {tick.reason}'
        self.path = COMPILED
        return ''

    def drop(self) -> None:
        """Forget the scene: a compile still running is not installed."""
        self._token = None
