# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A scene's single-angle solve compiled into one straight-line Python function.

A node solving one crank angle per tick at kilohertz rates pays for every
dictionary lookup, attribute read and object the general solver makes, and,
waking from a sleep each tick with cold caches, for the size of the code it
runs. :func:`compile_tick` removes that overhead without writing the
kinematics a second time: it specializes the solver's own step code (the
kernels of the step kinds of :mod:`mech_kinematics.solver`, written in the
subset that :mod:`mech_kinematics.solver.base` states) to the scalar path of
one scene by partial evaluation of their syntax trees
(:mod:`mech_kinematics.solver.specialize`, with ``ctx.vector`` false: only
the single-angle arithmetic is left), and takes the rest from the solver's
public hooks (:mod:`mech_kinematics.solver.tick`). It is the node's, so it
lives in the ROS layer (it imports only the solver). The function ends by
packing the values the caller asked for into one flat list.

The same operations run in the same order on the same doubles, so the
function returns the same bits as :func:`mech_kinematics.solve` (a test
checks every packaged scene and the extreme suite over a cycle), and raises
the same errors: a failed assembly check runs the step's own failure code,
and a bound beyond the quick trust test sends the instant to the general
solver, which refuses it with the full reason or answers it. Scenes or rates
the general solver rescales (sizes beyond 2**60, rates beyond 2**40), and any
step whose code uses something this compiler does not know, are not compiled:
:func:`compile_tick` returns ``None`` and the caller uses the general solver.

A scene with several drivers (or an actuator, issue 18) compiles the same
way, each driver's kernel on its own value: its tick takes one value per
driver (sequences, as :func:`mech_kinematics.solve` does), and an instant
that fails a check is handed to the general solver for its reason (the
message names every driver's position).
"""

from __future__ import annotations

import ast
from collections.abc import Callable, Sequence
import math
from typing import Any

from .. import solver as lk
from ..solver import tick as hooks
from ..solver.specialize import plan_body, propagate, TABLES, Unsupported

__all__ = ['TickFunction', 'compile_tick', 'tick_function', 'values_from_state']

#: ``tick(theta, omega, alpha, max_error, turns) -> (values, smallest near-singularity
#: measure)``; ``theta + 2 pi turns`` is the crank angle counted from the start.
TickFunction = Callable[[float, float, float, float, int], tuple[list[float], float]]


def values_from_state(state: lk.State, joints: Sequence[str], points: Sequence[str],
                      frames: Sequence[tuple[str, str | None, float]] = ()) -> list[float]:
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


def tick_function(scene: lk.Scene, joints: Sequence[str] | None = None,
                  points: Sequence[str] | None = None,
                  frames: Sequence[tuple[str, str | None, float]] = ()
                  ) -> tuple[TickFunction, bool]:
    """Return (the tick function of ``scene``, whether it is compiled).

    The compiled function of :func:`compile_tick` where the scene compiles,
    else one with the same signature around :func:`mech_kinematics.solve`.
    """
    tick = compile_tick(scene, joints, points, frames)
    if tick is not None:
        return tick, True
    return general_tick(scene, joints, points, frames), False


def general_tick(scene: lk.Scene, joints: Sequence[str] | None,
                 points: Sequence[str] | None,
                 frames: Sequence[tuple[str, str | None, float]]) -> TickFunction:
    """Return a tick function around the general solver (same signature, same answers)."""
    joints = tuple(scene.output_joints if joints is None else joints)
    points = tuple(scene.output_points if points is None else points)
    frames = tuple(frames)

    def general(theta: float, omega: float, alpha: float, tol: float,
                turns: int = 0) -> tuple[list[float], float]:
        state = lk.solve(scene, theta, omega, alpha, turns=turns, max_error=tol)
        measures = state.singularity.values()
        return (values_from_state(state, joints, points, frames),
                float(min(measures)) if measures else math.inf)

    return general


def _return_line(plan: hooks.TickPlan, names: dict[str, str], joints: tuple[str, ...],
                 points: tuple[str, ...],
                 frames: tuple[tuple[str, str | None, float], ...]) -> str:
    """Return the tick's ``return [values...], measure`` line (:func:`compile_tick`'s order)."""
    kinds = dict(plan.joint_types)
    values = []
    for index in range(3):
        for name in joints:
            e = names[f'{TABLES[kinds[name].table]}_{name}']
            values.append(f'_wrapped_angle({e}[0])' if index == 0 and kinds[name].angular
                          else f'{e}[{index}]')
    for index in range(3):
        for name in points:
            e = names[f'P_{name}']
            values += [f'{e}[{index}].real', f'{e}[{index}].imag']
    for origin, angle_of, angle in frames:
        e = names[f'P_{origin}']
        values += [f'{e}[0].real', f'{e}[0].imag']
        values.append(repr(angle) if angle_of is None
                      else f'_wrapped_angle({names[f"L_{angle_of}"]}[0])')
    measures = [names[key] for key in names if key.startswith('M_')]
    measure = f'min({", ".join(measures)})' if len(measures) > 1 else (
        measures[0] if measures else 'inf')
    return f'return [{", ".join(values)}], {measure}'


class _Refused(Exception):
    """A step of a several-driver tick found it cannot close: the general solver says why."""


def _refuse(theta: Any, turns: Any, ok: Any, *args: Any, **kwargs: Any) -> None:
    """Stand in for ``ctx.check`` in a several-driver tick: hand a failure to the solver."""
    if not ok:
        raise _Refused


def _compile_drivers(scene: lk.Scene, plan: hooks.TickPlan, joints: tuple[str, ...],
                     points: tuple[str, ...],
                     frames: tuple[tuple[str, str | None, float], ...]) -> TickFunction | None:
    """Return the tick of a scene with several drivers (or an actuator), or ``None``.

    The same specialized kernels as :func:`compile_tick`'s, each driver's on
    its own value: ``tick(positions, speeds, accels, max_error, turns=0)``
    takes one value per driver (sequences, as :func:`mech_kinematics.solve`).
    An instant the general solver would rescale in time, refuse (a failed
    check raises inside, and the general solver is asked for its reason, so
    the message names every driver's position) or judge beyond the quick
    trust test is handed to the general solver.
    """
    count = len(plan.drivers)
    namespace: dict[str, Any] = {
        '_ctx_check': _refuse, '_ctx_check_margin': _refuse, '_Refused': _Refused,
        '_shown': hooks.shown, '_slow': general_tick(scene, joints, points, frames),
        '_driver_limits': plan.driver_limits, '_rates_shift': hooks.rates_shift,
        'inf': math.inf, '_float': float, '_SEQUENCE': (list, tuple),
    }
    names: dict[str, str] = {}
    lines = [f'{", ".join(f"{x}_{k}" for k in range(count))}, = '
             f'({", ".join(f"_float({arg}[{k}])" for k in range(count))},)'
             for x, arg in (('x', 'theta'), ('v', 'omega'), ('a', 'alpha'))]
    body: list[ast.stmt] = ast.parse('\n'.join(lines)).body
    try:
        body += plan_body(plan, names, namespace, driver_values=[
            (f'x_{k}', f'v_{k}', f'a_{k}') for k in range(count)], propagated=False)
    except (Unsupported, ValueError):
        return None     # the general solver serves this scene
    namespace['_wrapped_angle'] = hooks.wrapped_angle
    tail = hooks.trust_lines(
        plan, names, f'_driver_limits(tol, [{", ".join(f"v_{k}" for k in range(count))}], '
        f'[{", ".join(f"a_{k}" for k in range(count))}])',
        'return _slow(theta, omega, alpha, tol, turns)')
    tail.append(_return_line(plan, names, joints, points, frames))
    signature = ast.arguments(posonlyargs=[], args=[ast.arg(a) for a in (
        'theta', 'omega', 'alpha', 'tol', 'turns')], kwonlyargs=[], kw_defaults=[],
        defaults=[ast.Constant(0)])
    inner = ast.FunctionDef(name='_tick', args=signature,
                            body=propagate(body + ast.parse('\n'.join(tail)).body, namespace,
                                           set(), vector=False),
                            decorator_list=[], returns=None)
    outer = ast.parse(
        'def tick(theta, omega, alpha, tol, turns=0):\n'
        '    if not (isinstance(theta, _SEQUENCE) and isinstance(omega, _SEQUENCE) '
        'and isinstance(alpha, _SEQUENCE)) or '
        f'len(theta) != {count} or len(omega) != {count} or len(alpha) != {count} or '
        '_rates_shift(omega, alpha):\n'
        '        return _slow(theta, omega, alpha, tol, turns)\n'
        '    try:\n'
        '        return _tick(theta, omega, alpha, tol, turns)\n'
        '    except _Refused:\n'
        '        return _slow(theta, omega, alpha, tol, turns)\n').body[0]
    module = ast.fix_missing_locations(ast.Module(body=[inner, outer], type_ignores=[]))
    exec(compile(module, f'<compiled tick of {scene.name}>', 'exec'), namespace)  # noqa: S102
    tick: TickFunction = namespace['tick']
    return tick


def compile_tick(scene: lk.Scene, joints: Sequence[str] | None = None,
                 points: Sequence[str] | None = None,
                 frames: Sequence[tuple[str, str | None, float]] = ()) -> TickFunction | None:
    """Return ``scene``'s single-angle solve as one straight-line function, or ``None``.

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
    callable or None
        ``tick(theta, omega, alpha, max_error, turns=0) -> (values, measure)``
        (``theta + 2 pi turns`` is the crank angle counted from the start):
        ``values`` is the flat list ``[positions of joints..., their velocities...,
        their accelerations..., x, y of every point's position..., of every
        velocity..., of every acceleration..., x, y, angle of every frame...]`` and
        ``measure`` the smallest near-singularity measure (inf if none). It
        raises exactly as :func:`mech_kinematics.solve` does, which it calls for
        an instant it cannot settle itself. ``None`` where the scene cannot be
        compiled (see the module's notes).
    """
    plan = hooks.tick_plan(scene)
    joints = tuple(scene.output_joints if joints is None else joints)
    points = tuple(scene.output_points if points is None else points)
    frames = tuple(frames)

    if not plan.compilable:
        return None     # rescaled units, or rubbing to bound: the general solver's work
    if plan.driver_limits is not None:
        return _compile_drivers(scene, plan, joints, points, frames)
    namespace: dict[str, Any] = {
        '_ctx_check': hooks.check, '_ctx_check_margin': hooks.check_margin,
        '_shown': hooks.shown,
        '_slow': general_tick(scene, joints, points, frames),
        '_trust_limits': hooks.trust_limits,
        'inf': math.inf,
    }
    names: dict[str, str] = {}
    try:
        body = plan_body(plan, names, namespace, propagated=False)
    except Unsupported:
        return None     # the general solver serves this scene
    namespace['_wrapped_angle'] = hooks.wrapped_angle

    # The general solver's quick trust test (hooks.trust_limits and hooks.TRUST_TEST, the
    # one source of both), on the reported values.
    lines = hooks.trust_lines(plan, names, f'_trust_limits(tol, omega, alpha, {plan.size!r}, '
                              f'{plan.crank_length!r})',
                              'return _slow(theta, omega, alpha, tol, turns)')
    lines.append(_return_line(plan, names, joints, points, frames))
    tail = ast.parse('\n'.join(lines)).body
    low, high, accel_high = hooks.RATES
    guard = ast.parse(
        # Any real number in (an np.float64, an int) is solved as the float it equals,
        # as the general solver does: NumPy's scalars would slow every operation.
        'if not (theta.__class__ is float and omega.__class__ is float\n'
        '        and alpha.__class__ is float and turns.__class__ is int):\n'
        '    theta, omega, alpha, turns = float(theta), float(omega), float(alpha), '
        'int(turns)\n'
        f'if not ({low!r} <= abs(omega) <= {high!r} '
        f'and abs(alpha) <= {accel_high!r}):\n'
        '    return _slow(theta, omega, alpha, tol, turns)').body
    function = ast.FunctionDef(
        name='tick', args=ast.arguments(
            posonlyargs=[],
            args=[ast.arg(a) for a in ('theta', 'omega', 'alpha', 'tol', 'turns')],
            kwonlyargs=[], kw_defaults=[], defaults=[ast.Constant(0)]),
        body=guard + propagate(body + tail, namespace, set(), vector=False), decorator_list=[],
        returns=None)
    module = ast.fix_missing_locations(ast.Module(body=[function], type_ignores=[]))
    exec(compile(module, f'<compiled tick of {scene.name}>', 'exec'), namespace)  # noqa: S102
    tick: TickFunction = namespace['tick']
    return tick
