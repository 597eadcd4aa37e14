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
one scene by partial evaluation of their syntax trees, and takes the rest from
the solver's public hooks (:mod:`mech_kinematics.solver.tick`). It is the
node's, so it lives in the ROS layer (it imports only the solver).

- ``ctx.vector`` becomes ``False`` and every branch it decides is folded
  away, so only the single-angle arithmetic is left;
- ``self.<attribute>`` of each step becomes the step's value (a constant);
- ``ctx.points[name]``, ``ctx.links[name]``, ``ctx.sliders[name]`` and
  ``ctx.measures[name]`` become local variables;
- each step's local names get the step's number as a suffix, and the steps
  are laid out one after another in plan order in a single function, which
  ends by packing the values the caller asked for into one flat list.

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
import inspect
import itertools
import math
import sys
import textwrap
from typing import Any, cast

from .. import solver as lk
from ..solver import tick as hooks

__all__ = ['TickFunction', 'compile_tick', 'tick_function', 'values_from_state']

#: ``tick(theta, omega, alpha, max_error, turns) -> (values, smallest near-singularity
#: measure)``; ``theta + 2 pi turns`` is the crank angle counted from the start.
TickFunction = Callable[[float, float, float, float, int], tuple[list[float], float]]

_SOLVER = lk.__name__ + '.'
#: The context's methods that record side facts (an intermittent lever's window, why a
#: bound is large, a jump): the tick reports none, so their calls are dropped.
_DROPPED = ('engage', 'note', 'jump')
_TABLES = {'points': 'P', 'links': 'L', 'sliders': 'S', 'measures': 'M'}


class _Unsupported(Exception):
    """A step's code holds something the specializer does not handle."""


def _fold(node: ast.AST) -> ast.AST:
    """Fold the constants a substitution left: ``x if False else y``, ``False or x``..."""

    class Folder(ast.NodeTransformer):
        def visit_IfExp(self, node: ast.IfExp) -> ast.AST:
            self.generic_visit(node)
            if isinstance(node.test, ast.Constant):
                return node.body if node.test.value else node.orelse
            return node

        def visit_BoolOp(self, node: ast.BoolOp) -> ast.AST:
            self.generic_visit(node)
            absorbing = isinstance(node.op, ast.Or)     # True absorbs an or, False an and
            values = []
            for value in node.values:
                if isinstance(value, ast.Constant):
                    if bool(value.value) == absorbing:
                        return ast.Constant(absorbing)
                    continue                              # the neutral constant drops out
                values.append(value)
            if not values:
                return ast.Constant(not absorbing)
            if len(values) == 1:
                return values[0]
            node.values = values
            return node

        def visit_Compare(self, node: ast.Compare) -> ast.AST:
            # ``None is None``, ``'cyl' is None``: a step attribute against a constant.
            self.generic_visit(node)
            if (len(node.ops) == 1 and isinstance(node.ops[0], (ast.Is, ast.IsNot))
                    and isinstance(node.left, ast.Constant)
                    and isinstance(node.comparators[0], ast.Constant)):
                same = node.left.value is node.comparators[0].value
                return ast.Constant(same if isinstance(node.ops[0], ast.Is) else not same)
            return node

        def visit_UnaryOp(self, node: ast.UnaryOp) -> ast.AST:
            self.generic_visit(node)
            if isinstance(node.op, ast.Not) and isinstance(node.operand, ast.Constant):
                return ast.Constant(not node.operand.value)
            return node

        def visit_If(self, node: ast.If) -> Any:
            self.generic_visit(node)
            if isinstance(node.test, ast.Constant):
                return (node.body if node.test.value else node.orelse) or ast.Pass()
            return node

    folded: ast.AST = Folder().visit(node)
    return folded


class _Specializer(ast.NodeTransformer):
    """Rewrite one step's ``run`` body for the scalar path of one scene (see the module)."""

    def __init__(self, step: Any, suffix: str, names: dict[str, str],
                 namespace: dict[str, Any], arguments: dict[str, str]) -> None:
        self.step = step
        self.suffix = suffix
        self.names = names              # table entry -> local variable
        self.namespace = namespace
        self.arguments = arguments      # run() argument -> tick argument
        self.locals: set[str] = set()

    def constant(self, value: Any) -> ast.expr:
        if value is None or isinstance(value, (bool, int, float, complex, str)):
            return ast.Constant(value)
        name = f'_k{len(self.namespace)}'
        self.namespace[name] = value
        return ast.Name(name, ast.Load())

    def table_entry(self, node: ast.Subscript) -> str | None:
        """Return the local variable of ``ctx.<table>[self.<attr>]``, or None."""
        value = node.value
        if not (isinstance(value, ast.Attribute) and isinstance(value.value, ast.Name)
                and value.value.id == 'ctx' and value.attr in _TABLES):
            return None
        key = node.slice
        if not (isinstance(key, ast.Attribute) and isinstance(key.value, ast.Name)
                and key.value.id == 'self'):
            raise _Unsupported('a table read with a key that is not a step attribute')
        name = getattr(self.step, key.attr)
        entry = f'{_TABLES[value.attr]}_{name}'
        return self.names.setdefault(entry, f'{entry}_{len(self.names)}')

    def visit_Subscript(self, node: ast.Subscript) -> ast.AST:
        local = self.table_entry(node)
        if local is not None:
            return ast.copy_location(ast.Name(local, node.ctx), node)
        return self.generic_visit(node)

    def visit_Attribute(self, node: ast.Attribute) -> ast.AST:
        if isinstance(node.value, ast.Name):
            if node.value.id == 'self':
                return ast.copy_location(self.constant(getattr(self.step, node.attr)), node)
            if node.value.id == 'ctx':
                if node.attr in ('vector', 'flip'):   # the tick answers the side after a jump
                    return ast.Constant(False)
                if node.attr == 'angle':
                    return ast.Name('theta', ast.Load())
                if node.attr == 'turns':
                    return ast.Name('turns', ast.Load())
                if node.attr == 'shown':    # the angle counted from the start, for messages
                    return ast.Call(ast.Name('_shown', ast.Load()),
                                    [ast.Name('theta', ast.Load()),
                                     ast.Name('turns', ast.Load())], [])
                raise _Unsupported(f'ctx.{node.attr}')
        return self.generic_visit(node)

    def visit_If(self, node: ast.If) -> Any:
        # A branch ``ctx.vector`` decides is dropped before it is specialized: the
        # array path may use what the tick does not (``ctx`` as a value, loops).
        test = _fold(self.visit(node.test))
        if isinstance(test, ast.Constant):
            taken = node.body if test.value else node.orelse
            return self.statements(taken) or ast.Pass()
        node.test = cast(ast.expr, test)
        node.body = self.statements(node.body) or [ast.Pass()]
        node.orelse = self.statements(node.orelse)
        return node

    def statements(self, stmts: list[ast.stmt]) -> list[ast.stmt]:
        """Return ``stmts`` specialized, a statement that became several spliced in."""
        out: list[ast.stmt] = []
        for stmt in stmts:
            result = self.visit(stmt)
            out.extend(result if isinstance(result, list) else [result])
        return out

    def visit_Expr(self, node: ast.Expr) -> Any:
        value = node.value
        if (isinstance(value, ast.Call) and isinstance(value.func, ast.Attribute)
                and isinstance(value.func.value, ast.Name) and value.func.value.id == 'ctx'
                and value.func.attr in _DROPPED):
            return ast.Pass()       # a side fact the tick does not report
        return self.generic_visit(node)

    def visit_Call(self, node: ast.Call) -> ast.AST:
        func = node.func
        inlined = _inline(func, node.args, self.namespace) if not node.keywords else None
        if inlined is not None:
            result: ast.AST = self.visit(ast.copy_location(inlined, node))
            return result
        if (isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name)
                and func.value.id == 'ctx' and func.attr in ('check', 'check_margin')):
            # The failure path: the general context's own check, at this angle.
            call = ast.Call(ast.Name(f'_ctx_{func.attr}', ast.Load()),
                            [ast.Name('theta', ast.Load()), ast.Name('turns', ast.Load()),
                             *node.args], node.keywords)
            return self.generic_visit(ast.copy_location(call, node))
        return self.generic_visit(node)

    def visit_Name(self, node: ast.Name) -> ast.AST:
        if node.id in self.arguments:
            return ast.copy_location(ast.Name(self.arguments[node.id], node.ctx), node)
        if node.id in self.locals:
            return ast.copy_location(ast.Name(f'{node.id}{self.suffix}', node.ctx), node)
        if node.id in ('ctx', 'self'):
            raise _Unsupported(f'{node.id} used as a value')
        return node


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
        '_shown': hooks.shown, '_slow': _general(scene, joints, points, frames),
        '_driver_limits': plan.driver_limits, '_rates_shift': hooks.rates_shift,
        'inf': math.inf, '_float': float, '_SEQUENCE': (list, tuple),
    }
    for step in (*plan.drivers, *plan.steps):
        for cls in type(step).__mro__:
            home = sys.modules[cls.__module__]
            if home.__name__.startswith(_SOLVER):
                namespace.update((k, v) for k, v in vars(home).items()
                                 if not k.startswith('__'))
    namespace['_wrapped_angle'] = hooks.wrapped_angle
    names: dict[str, str] = {}
    lines = [f'{", ".join(f"{x}_{k}" for k in range(count))}, = '
             f'({", ".join(f"_float({arg}[{k}])" for k in range(count))},)'
             for x, arg in (('x', 'theta'), ('v', 'omega'), ('a', 'alpha'))]
    body: list[ast.stmt] = ast.parse('\n'.join(lines)).body
    try:
        for name, entry in plan.ground.items():
            local = names.setdefault(f'P_{name}', f'P_{name}_{len(names)}')
            namespace[f'_ground_{local}'] = entry
            body.append(ast.parse(f'{local} = _ground_{local}').body[0])
        for k, driver in enumerate(plan.drivers):
            run = type(driver).run
            parameters = list(inspect.signature(run).parameters)[2:]  # after self, ctx
            arguments = dict(zip(parameters, (f'x_{k}', f'v_{k}', f'a_{k}'), strict=True))
            body += _body(driver, run, f'_d{k}', names, namespace, arguments)
        for index, step in enumerate(plan.steps, 1):
            for part, kernel in enumerate(step.kernels()):
                body += _body(step, kernel, f'_{index}_{part}', names, namespace, {})
    except (_Unsupported, OSError, TypeError, ValueError) as error:
        del error   # the general solver serves this scene
        return None
    kinds = dict(plan.joint_types)
    tail = [f'_l0, _l1, _l2, _l3, _l4, _l5 = _driver_limits(tol, '
            f'[{", ".join(f"v_{k}" for k in range(count))}], '
            f'[{", ".join(f"a_{k}" for k in range(count))}])']
    checks = []
    for table, _, (i, j, k) in hooks.TRUST_TEST:
        for name in plan.reported[table]:
            e = names[f'{_TABLES[table]}_{name}']
            checks.append(f'{e}[3] <= _l{i} and {e}[4] <= _l{j} and {e}[5] <= _l{k}')
    if checks:
        tail.append(f'if not ({" and ".join(checks)}):')
        tail.append('    return _slow(theta, omega, alpha, tol, turns)')
    values = []
    for index in range(3):
        for name in joints:
            if kinds[name] == 'revolute':
                e = names[f'L_{name}']
                values.append(f'_wrapped_angle({e}[0])' if index == 0 else f'{e}[{index}]')
            else:
                values.append(f'{names[f"S_{name}"]}[{index}]')
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
    tail.append(f'return [{", ".join(values)}], {measure}')
    signature = ast.arguments(posonlyargs=[], args=[ast.arg(a) for a in (
        'theta', 'omega', 'alpha', 'tol', 'turns')], kwonlyargs=[], kw_defaults=[],
        defaults=[ast.Constant(0)])
    inner = ast.FunctionDef(name='_tick', args=signature,
                            body=body + ast.parse('\n'.join(tail)).body, decorator_list=[],
                            returns=None)
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


def _inline(func: ast.expr, args: list[ast.expr],
            namespace: dict[str, Any]) -> ast.expr | None:
    """Return the call of a one-line helper of the solver package written out, or None.

    A module function whose body is ``return <expression>`` (``_dot``,
    ``_cross``), called with plain names or constants, becomes its expression
    with the arguments put in: the same operations, without the call.
    """
    simple = all(isinstance(a, (ast.Name, ast.Constant)) for a in args)
    if not (isinstance(func, ast.Name) and simple):
        return None
    helper = namespace.get(func.id)
    if not inspect.isfunction(helper) or not helper.__module__.startswith(_SOLVER):
        return None
    definition = ast.parse(textwrap.dedent(inspect.getsource(helper))).body[0]
    if not (isinstance(definition, ast.FunctionDef) and len(definition.body) == 1
            and isinstance(definition.body[0], ast.Return) and definition.body[0].value
            and len(definition.args.args) == len(args) and not definition.args.defaults):
        return None
    bound = {p.arg: a for p, a in zip(definition.args.args, args, strict=True)}

    class Substitute(ast.NodeTransformer):
        def visit_Name(self, node: ast.Name) -> ast.AST:
            return bound.get(node.id, node)

    expression: ast.expr = Substitute().visit(definition.body[0].value)
    return expression


def _body(step: Any, method: Callable[..., Any], suffix: str, names: dict[str, str],
          namespace: dict[str, Any], arguments: dict[str, str]) -> list[ast.stmt]:
    """Return the statements of ``method`` (a step's ``run``) specialized to ``step``."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(method)))
    function = tree.body[0]
    if not isinstance(function, ast.FunctionDef):
        raise _Unsupported('run is not a plain function')
    specializer = _Specializer(step, suffix, names, namespace, arguments)
    parameters = {a.arg for a in function.args.args}
    specializer.locals = {n.id for n in ast.walk(function)
                          if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)
                          } - parameters - set(arguments)
    for n in itertools.chain.from_iterable(ast.walk(stmt) for stmt in function.body):
        if isinstance(n, ast.Lambda) and (n.args.args or n.args.vararg or n.args.kwarg):
            raise _Unsupported('a lambda with arguments')
        if isinstance(n, (ast.Global, ast.Nonlocal, ast.Return, ast.Yield, ast.For,
                          ast.While, ast.Try, ast.With, ast.FunctionDef)):
            raise _Unsupported(type(n).__name__)
    module = ast.Module(body=[stmt for stmt in function.body if not (
        isinstance(stmt, ast.Expr) and isinstance(stmt.value, ast.Constant))], type_ignores=[])
    module = cast(ast.Module, _fold(specializer.visit(module)))
    return [stmt for stmt in module.body if not isinstance(stmt, ast.Pass)]


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
    return _general(scene, joints, points, frames), False


def _general(scene: lk.Scene, joints: Sequence[str] | None, points: Sequence[str] | None,
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
        '_slow': _general(scene, joints, points, frames),
        '_trust_limits': hooks.trust_limits,
        'inf': math.inf,
    }
    for step in (plan.crank, *plan.steps):
        for cls in type(step).__mro__:
            home = sys.modules[cls.__module__]
            if home.__name__.startswith(_SOLVER):
                namespace.update((k, v) for k, v in vars(home).items()
                                 if not k.startswith('__'))
    namespace['_wrapped_angle'] = hooks.wrapped_angle
    names: dict[str, str] = {}
    body: list[ast.stmt] = []
    try:
        for name, entry in plan.ground.items():
            local = names.setdefault(f'P_{name}', f'P_{name}_{len(names)}')
            namespace[f'_ground_{local}'] = entry
            body.append(ast.parse(f'{local} = _ground_{local}').body[0])
        arguments = {'theta': 'theta', 'omega': 'omega', 'alpha': 'alpha'}
        body += _body(plan.crank, type(plan.crank).run, '_0', names, namespace, arguments)
        for index, step in enumerate(plan.steps, 1):
            for part, kernel in enumerate(step.kernels()):
                body += _body(step, kernel, f'_{index}_{part}', names, namespace, {})
    except (_Unsupported, OSError, TypeError) as error:
        del error   # the general solver serves this scene
        return None

    def var(table: str, name: str) -> str:
        return names[f'{table}_{name}']

    kinds = dict(plan.joint_types)
    lines = []
    # The general solver's quick trust test (hooks.trust_limits and hooks.TRUST_TEST, the
    # one source of both), on the reported values.
    lines.append(f'_l0, _l1, _l2, _l3, _l4, _l5 = _trust_limits(tol, omega, alpha, '
                 f'{plan.size!r}, {plan.crank_length!r})')
    checks = []
    for table, _, (i, j, k) in hooks.TRUST_TEST:
        for name in plan.reported[table]:
            e = var(_TABLES[table], name)
            checks.append(f'{e}[3] <= _l{i} and {e}[4] <= _l{j} and {e}[5] <= _l{k}')
    if checks:
        lines.append(f'if not ({" and ".join(checks)}):')
        lines.append('    return _slow(theta, omega, alpha, tol, turns)')
    values = []
    for index in range(3):
        for name in joints:
            if kinds[name] == 'revolute':
                e = var('L', name)
                values.append(f'_wrapped_angle({e}[0])' if index == 0 else f'{e}[{index}]')
            else:
                values.append(f'{var("S", name)}[{index}]')
    for index in range(3):
        for name in points:
            e = var('P', name)
            values += [f'{e}[{index}].real', f'{e}[{index}].imag']
    for origin, angle_of, angle in frames:
        e = var('P', origin)
        values += [f'{e}[0].real', f'{e}[0].imag']
        values.append(repr(angle) if angle_of is None
                      else f'_wrapped_angle({var("L", angle_of)}[0])')
    measures = [names[key] for key in names if key.startswith('M_')]
    measure = f'min({", ".join(measures)})' if len(measures) > 1 else (
        measures[0] if measures else 'inf')
    lines.append(f'return [{", ".join(values)}], {measure}')
    tail = ast.parse('\n'.join(lines)).body
    low, high, accel_high = hooks.RATES
    guard = ast.parse(
        f'if not ({low!r} <= abs(omega) <= {high!r} '
        f'and abs(alpha) <= {accel_high!r}):\n'
        '    return _slow(theta, omega, alpha, tol, turns)').body
    function = ast.FunctionDef(
        name='tick', args=ast.arguments(
            posonlyargs=[],
            args=[ast.arg(a) for a in ('theta', 'omega', 'alpha', 'tol', 'turns')],
            kwonlyargs=[], kw_defaults=[], defaults=[ast.Constant(0)]),
        body=guard + body + tail, decorator_list=[],
        returns=None)
    module = ast.fix_missing_locations(ast.Module(body=[function], type_ignores=[]))
    exec(compile(module, f'<compiled tick of {scene.name}>', 'exec'), namespace)  # noqa: S102
    tick: TickFunction = namespace['tick']
    return tick
