# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Partial evaluation of the steps' kernels: a scene's solve as straight-line code.

A solve runs the kernel of every step (:meth:`.base.Step.kernels`, written in
the subset that :mod:`.base` states) through dictionaries of a context, with
attribute reads and calls at every turn. :func:`plan_body` writes the same
kernels out for one scene instead, as the statements of one function:

- ``ctx.vector`` becomes a constant (``False`` for the single-angle path,
  ``True`` for the array path) and every branch it decides is folded away;
- ``self.<attribute>`` of each step becomes the step's value, and a name
  of a number the kernel's module defines (``U``, ``ROUNDING_MARGIN``) its
  value: constants;
- ``ctx.points[name]``, ``ctx.links[name]``, ``ctx.sliders[name]`` and
  ``ctx.measures[name]`` become local variables (:data:`TABLES`);
- one-line helpers of the solver package are written out in place;
- each step's local names get the step's number as a suffix, and the steps
  are laid out one after another in plan order.

The same operations run in the same order on the same values, so the code
gives the same bits as the solve it replaces. What the caller does with the
statements (which values the function returns, how a failed check is
reported) is the caller's: the node's tick (:mod:`mech_kinematics.ros.ticker`)
and the solver's own compiled paths (:mod:`.compiled`). A step whose code uses
something this module does not know raises :class:`Unsupported`, and the
caller falls back to the general solver.
"""

from __future__ import annotations

import ast
from collections.abc import Callable, Sequence
import functools
import inspect
import itertools
import sys
import textwrap
from typing import Any, cast

__all__ = ['DROPPED', 'TABLES', 'Unsupported', 'fold', 'plan_body']

_SOLVER = __name__.rsplit('.', 1)[0] + '.'
#: The context's methods that record side facts (an intermittent lever's window, why a
#: bound is large, a jump): the compiled paths report none, so their calls are dropped.
DROPPED = ('engage', 'note', 'jump')
#: The context's tables, and the prefix of their entries' local variables.
TABLES = {'points': 'P', 'links': 'L', 'sliders': 'S', 'measures': 'M'}


class Unsupported(Exception):
    """A step's code holds something the specializer does not handle."""


def fold(node: ast.AST) -> ast.AST:
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
    """Rewrite one step's ``run`` body for one path of one scene (see the module).

    On the scalar path (``vector`` false) the context disappears: its tables
    become locals, a check calls ``_ctx_check(theta, turns, ...)`` (the
    general context's failure path at that angle) and the side facts are
    dropped. On the array path the tables become locals too, and everything
    else of the context stays a call on a real context named ``ctx``.
    """

    def __init__(self, step: Any, suffix: str, names: dict[str, str],
                 namespace: dict[str, Any], arguments: dict[str, str],
                 vector: bool = False) -> None:
        self.step = step
        self.vector = vector
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
                and value.value.id == 'ctx' and value.attr in TABLES):
            return None
        key = node.slice
        if not (isinstance(key, ast.Attribute) and isinstance(key.value, ast.Name)
                and key.value.id == 'self'):
            raise Unsupported('a table read with a key that is not a step attribute')
        name = getattr(self.step, key.attr)
        entry = f'{TABLES[value.attr]}_{name}'
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
                if node.attr == 'vector':
                    return ast.Constant(self.vector)
                if node.attr == 'flip':     # compiled, the side after a jump is answered
                    return ast.Constant(False)
                if node.attr == 'angle':
                    return ast.Name('theta', ast.Load())
                if node.attr == 'turns':
                    return ast.Name('turns', ast.Load())
                if self.vector:
                    return node             # the real context's
                if node.attr == 'shown':    # the angle counted from the start, for messages
                    return ast.Call(ast.Name('_shown', ast.Load()),
                                    [ast.Name('theta', ast.Load()),
                                     ast.Name('turns', ast.Load())], [])
                raise Unsupported(f'ctx.{node.attr}')
        return self.generic_visit(node)

    def visit_If(self, node: ast.If) -> Any:
        # A branch ``ctx.vector`` decides is dropped before it is specialized: the
        # array path may use what the tick does not (``ctx`` as a value, loops).
        test = fold(self.visit(node.test))
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
                and value.func.attr in DROPPED and not self.vector):
            return ast.Pass()       # a side fact the scalar path does not report
        return self.generic_visit(node)

    def visit_Call(self, node: ast.Call) -> ast.AST:
        func = node.func
        if any(isinstance(arg, ast.Name) and arg.id in ('ctx', 'self')
               for arg in (*node.args, *(k.value for k in node.keywords))):
            raise Unsupported('the context or the step passed as a value')
        inlined = _inline(func, node.args, self.namespace) if not node.keywords else None
        if inlined is not None:
            result: ast.AST = self.visit(ast.copy_location(inlined, node))
            return result
        if (isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name)
                and func.value.id == 'ctx' and func.attr in ('check', 'check_margin')
                and not self.vector):
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
        value = self.namespace.get(node.id)
        if type(value) in (float, int, complex) and isinstance(node.ctx, ast.Load):
            return ast.copy_location(ast.Constant(value), node)     # a module's constant
        if node.id == 'ctx' and self.vector and isinstance(node.ctx, ast.Load):
            return node         # the receiver of a real context's attribute or method
        if node.id in ('ctx', 'self'):
            raise Unsupported(f'{node.id} used as a value')
        return node


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
    definition = ast.parse(_source(helper)).body[0]
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


@functools.cache
def _source(function: Callable[..., Any]) -> str:
    """Return the source of a kernel or helper, dedented (read once per process)."""
    return textwrap.dedent(inspect.getsource(function))


def _body(step: Any, method: Callable[..., Any], suffix: str, names: dict[str, str],
          namespace: dict[str, Any], arguments: dict[str, str],
          vector: bool = False) -> list[ast.stmt]:
    """Return the statements of ``method`` (a step's ``run``) specialized to ``step``."""
    tree = ast.parse(_source(method))
    function = tree.body[0]
    if not isinstance(function, ast.FunctionDef):
        raise Unsupported('run is not a plain function')
    specializer = _Specializer(step, suffix, names, namespace, arguments, vector)
    parameters = {a.arg for a in function.args.args}
    specializer.locals = {n.id for n in ast.walk(function)
                          if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)
                          } - parameters - set(arguments)
    for n in itertools.chain.from_iterable(ast.walk(stmt) for stmt in function.body):
        if isinstance(n, ast.Lambda) and (n.args.args or n.args.vararg or n.args.kwarg):
            raise Unsupported('a lambda with arguments')
        if isinstance(n, (ast.Global, ast.Nonlocal, ast.Return, ast.Yield, ast.For,
                          ast.While, ast.Try, ast.With, ast.FunctionDef)):
            raise Unsupported(type(n).__name__)
    module = ast.Module(body=[stmt for stmt in function.body if not (
        isinstance(stmt, ast.Expr) and isinstance(stmt.value, ast.Constant))], type_ignores=[])
    module = cast(ast.Module, fold(specializer.visit(module)))
    return [stmt for stmt in module.body if not isinstance(stmt, ast.Pass)]


def plan_body(plan: Any, names: dict[str, str], namespace: dict[str, Any],
              vector: bool = False,
              driver_values: Sequence[tuple[str, str, str]] | None = None) -> list[ast.stmt]:
    """Return the statements solving ``plan`` (a :class:`.tick.TickPlan`) in one function.

    The function's arguments are ``theta, omega, alpha, turns`` (and, on the
    array path, ``ctx``: a context for the checks and side facts); the
    statements leave every table entry in a local variable, ``names`` mapping
    ``'<table prefix>_<name>'`` (:data:`TABLES`) to it. ``namespace`` gets the
    globals the statements read (the kernels' modules', and the constants).
    With ``driver_values`` (one (position, speed, accel) triple of names per
    driver, a scalar tick of several drivers), each driver's kernel runs on its
    own names instead of the crank's on ``theta, omega, alpha``.
    Raises :class:`Unsupported` where a kernel is outside the subset.
    """
    drivers = (plan.crank,) if driver_values is None else plan.drivers
    values = (('theta', 'omega', 'alpha'),) if driver_values is None else driver_values
    for step in (*drivers, *plan.steps):
        for cls in type(step).__mro__:
            home = sys.modules[cls.__module__]
            if home.__name__.startswith(_SOLVER):
                namespace.update((k, v) for k, v in vars(home).items()
                                 if not k.startswith('__'))
    body: list[ast.stmt] = []
    try:
        for name, entry in plan.ground.items():
            local = names.setdefault(f'P_{name}', f'P_{name}_{len(names)}')
            namespace[f'_ground_{local}'] = entry
            body.append(ast.parse(f'{local} = _ground_{local}').body[0])
        for k, (driver, given) in enumerate(zip(drivers, values, strict=True)):
            run = type(driver).run
            parameters = list(inspect.signature(run).parameters)[2:]   # after self, ctx
            arguments = dict(zip(parameters, given, strict=True))
            body += _body(driver, run, f'_d{k}' if driver_values else '_0', names, namespace,
                          arguments, vector)
        for index, step in enumerate(plan.steps, 1):
            # Step.kernels names the single-angle path; the array path is ``run`` itself.
            kernels = (type(step).run,) if vector else step.kernels()
            for part, kernel in enumerate(kernels):
                body += _body(step, kernel, f'_{index}_{part}', names, namespace, {}, vector)
    except (OSError, TypeError) as error:
        raise Unsupported(str(error)) from error
    return body
