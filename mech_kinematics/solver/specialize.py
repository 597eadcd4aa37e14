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
- one-line helpers of the solver package are written out in place, and so
  are the step's methods a kernel calls as ``self.<helper>(ctx, ...)`` in a
  statement (their locals get a suffix of their own, their arguments are
  bound in order, their final ``return`` assigns the statement's targets);
- each step's local names get the step's number as a suffix, and the steps
  are laid out one after another in plan order.

The same operations run in the same order on the same values, so the code
gives the same bits as the solve it replaces.

Then :func:`propagate` removes the work whose result is known when the code
is written (issues 19 and 22). A local bound once, at the top level, to a
constant (a number, a tuple of numbers, a ground point's tuple of Python
numbers) or to another local is read as that constant or local; ``.real``,
``.imag``, ``abs()``, a unary operation, a binary operation or a comparison
whose operands are all constants is computed now by the same Python
arithmetic the code would run (the operands are Python numbers at run time
on both paths), and a fold that raises is left to raise where it was. A
binding nothing reads any more goes if its value is a constant or a name;
every call, every expression statement and every value that may raise stays.
A tuple's computed entries are bound to locals first, in the same order, so
that an entry read (``P[3]``, ``P[:3]``, ``a, b, c = P``) reads the local.
The callers run :func:`propagate` over the whole function they build (the
trust test and the returned values included).

Last, an operation that gives back its operand bit for bit is removed, where
what the operand is (:class:`_Kinds`: a real float, any real, a complex;
never assumed of a name whose bindings disagree or of an argument) makes it
exact for every value it can hold, Python or NumPy, signed zeros, NaN and
infinities included:

- ``x * 1.0``, ``1.0 * x``, ``x / 1.0`` (and with the int ``1``), for ``x`` a
  real float only: IEEE multiplication and division by one are exact and
  keep a NaN. Not for a complex ``x`` (Python and NumPy turn ``1.0`` into
  ``1+0j`` and multiply out: ``-0.0 - 0.0 * y`` can flip a zero's sign, and
  ``inf * 0`` is NaN), nor for an int (``3 * 1.0`` is a float);
- ``x - 0.0`` (or ``x - 0``), for a real float or complex ``x``:
  ``-0.0 - 0.0`` is ``-0.0`` and each part of a complex is subtracted apart.
  Not ``x + 0.0`` (``-0.0 + 0.0`` is ``0.0``), nor ``x + -0.0`` for a complex
  ``x`` (the ``-0.0`` becomes ``-0.0+0j``, and its ``+0j`` flips an imaginary
  ``-0.0``), nor ``x - -0.0``, nor ``0.0 * x``;
- ``x - 0j``, for a complex ``x`` only (from a real it makes a complex).

On the array path an operation is removed only where its value is an
operand of another operation: the result is then a fresh array either way,
and no two names come to share one array that used to be two.

On the array path, a float or complex constant meeting an array of the
angles (:class:`_Arrays`) is read from a 0-d array of the namespace
(:class:`_ZeroD`): the same dtype and bits by NEP 50, a third less time. A
constant meeting ``omega``, ``alpha`` or a value made of them alone stays a
Python number: those are 0-d arrays whose products are NumPy scalars, for
which a 0-d array operand is about eight times slower than a Python number
(0.54 against 0.06 µs) and turns ``1j * x`` from a Python complex into a
``np.complex128``. What the caller does with the
statements (which values the function returns, how a failed check is
reported) is the caller's: the one compiler (:mod:`.compiler`), whose targets
are ``mk.solve``'s paths and the node's tick. A step whose code uses
something this module does not know raises :class:`Unsupported` with the
reason (naming the step), which the compiler returns as why it did not
compile the scene; the caller keeps the general solver.
"""

from __future__ import annotations

import ast
from collections import Counter
from collections.abc import Callable, Sequence
import functools
import inspect
import itertools
import math
import operator
import sys
import textwrap
from typing import Any, cast

import numpy as np

__all__ = ['DROPPED', 'TABLES', 'Unsupported', 'fold', 'plan_body', 'propagate']

_SOLVER = __name__.rsplit('.', 1)[0] + '.'
#: The context's methods that record side facts (an intermittent lever's window, why a
#: bound is large, a jump): the compiled paths report none, so their calls are dropped.
DROPPED = ('engage', 'note', 'jump')
#: The context's tables, and the prefix of their entries' local variables.
TABLES = {'points': 'P', 'links': 'L', 'sliders': 'S', 'measures': 'M'}


class Unsupported(Exception):
    """A step's code holds something the specializer does not handle; ``reason`` says what.

    The one exception the compiler turns into a reason (:class:`.compiler.NotCompiled`):
    ``reason`` is one line, e.g. ``'step RRR C: kernel uses `for` (not in the kernel
    subset)'`` (:func:`plan_body` names the step).
    """

    def __init__(self, reason: str) -> None:
        """Hold ``reason``, one line."""
        super().__init__(reason)
        self.reason = reason


class _Folder(ast.NodeTransformer):
    """The folds of :func:`fold`."""

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


_FOLDER = _Folder()


def fold(node: ast.AST) -> ast.AST:
    """Fold the constants a substitution left: ``x if False else y``, ``False or x``..."""
    folded: ast.AST = _FOLDER.visit(node)
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
        self.depth = 0                  # helpers written out around this code
        self.inlined = 0                # helpers written out in this code so far

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
            raise Unsupported('a table of ctx read with a key that is not a step attribute '
                              '(not in the kernel subset)')
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
                raise Unsupported(f'uses `ctx.{node.attr}` (not in the kernel subset)')
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
        helper = self.helper(value)
        if helper is not None:
            return self.inline(*helper, None, node)
        return self.generic_visit(node)

    def visit_Assign(self, node: ast.Assign) -> Any:
        helper = self.helper(node.value)
        if helper is None:
            return self.generic_visit(node)
        if len(node.targets) != 1:
            raise Unsupported(f'the result of helper {helper[0].__name__} assigned to '
                              f'{len(node.targets)} targets at once')
        target = cast(ast.expr, self.visit(node.targets[0]))
        return self.inline(*helper, target, node)

    def helper(self, value: ast.expr) -> tuple[Callable[..., Any], list[ast.expr]] | None:
        """Return (the method, its arguments after ``ctx``) of ``self.<method>(ctx, ...)``.

        ``None`` for any other expression (a call of a step's method without
        the context is a call of a constant, the bound method).
        """
        if not (isinstance(value, ast.Call) and isinstance(value.func, ast.Attribute)
                and isinstance(value.func.value, ast.Name) and value.func.value.id == 'self'
                and value.args and isinstance(value.args[0], ast.Name)
                and value.args[0].id == 'ctx'):
            return None
        name = value.func.attr
        if value.keywords or any(isinstance(a, ast.Starred) for a in value.args):
            raise Unsupported(f'helper {name} called with keywords or *args')
        method = getattr(type(self.step), name, None)
        if not inspect.isfunction(method):
            raise Unsupported(f'self.{name}(ctx, ...) is not a method written in Python')
        return method, value.args[1:]

    def inline(self, method: Callable[..., Any], args: list[ast.expr],
               target: ast.expr | None, call: ast.stmt) -> list[ast.stmt]:
        """Return the statements of the helper ``method`` called on ``args``, written out.

        A helper is a method of the step taking ``(self, ctx, ...)``, in the
        kernel subset, that may end with one ``return``. Its locals get a
        suffix of their own (a caller's names are never touched); an argument
        that is a name is read for its parameter where the helper never binds
        it, any other is bound to the parameter first, in order; the final
        ``return`` value is assigned to ``target`` (the calling statement's,
        ``call``). The same operations in the same order as the call: the
        same bits.
        """
        name = method.__name__
        if self.depth >= _HELPER_DEPTH:
            raise Unsupported(f'helper {name} called {_HELPER_DEPTH} helpers deep')
        definition = ast.parse(_source(method)).body[0]
        if not isinstance(definition, ast.FunctionDef):
            raise Unsupported(f'helper {name} is not a plain function')
        signature = definition.args
        if (signature.posonlyargs or signature.vararg or signature.kwonlyargs
                or signature.kwarg or signature.defaults or len(signature.args) < 2
                or signature.args[1].arg != 'ctx'):
            raise Unsupported(f'helper {name} is not a function of (self, ctx, ...) without '
                              'defaults')
        parameters = [a.arg for a in signature.args[2:]]
        if len(parameters) != len(args):
            raise Unsupported(f'helper {name} takes {len(parameters)} arguments after ctx, '
                              f'got {len(args)}')
        body = _checked(definition, f'helper {name}', returns=True)
        final = body[-1] if body and isinstance(body[-1], ast.Return) else None
        if final is not None:
            body = body[:-1]
        suffix = f'{self.suffix}h{self.inlined}'
        self.inlined += 1
        stored = _stored(definition)
        arguments: dict[str, str] = {}
        bindings: list[ast.stmt] = []
        for parameter, arg in zip(parameters, args, strict=True):
            value = cast(ast.expr, self.visit(arg))
            if isinstance(value, ast.Name) and parameter not in stored:
                arguments[parameter] = value.id
            else:
                stored.add(parameter)
                bindings.append(ast.copy_location(ast.Assign(
                    [ast.Name(f'{parameter}{suffix}', ast.Store())], value), call))
        inner = _Specializer(self.step, suffix, self.names, self.namespace, arguments,
                             self.vector)
        inner.depth = self.depth + 1
        inner.locals = stored - {'self', 'ctx'} - set(arguments)
        out = bindings + inner.statements(body)
        if final is not None and final.value is not None:
            value = cast(ast.expr, inner.visit(final.value))
            if target is not None:
                out.append(ast.copy_location(ast.Assign([target], value), call))
            elif not _inert(value):
                out.append(ast.copy_location(ast.Expr(value), call))
        elif target is not None:
            out.append(ast.copy_location(ast.Assign([target], ast.Constant(None)), call))
        return out

    def visit_Call(self, node: ast.Call) -> ast.AST:
        func = node.func
        if any(isinstance(arg, ast.Name) and arg.id in ('ctx', 'self')
               for arg in (*node.args, *(k.value for k in node.keywords))):
            called = ast.unparse(func)
            raise Unsupported(f'the context or the step passed as a value (to {called}; a '
                              'helper is called as a statement: `x = self.helper(ctx, ...)`)')
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
        if (isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name)
                and func.value.id == 'ctx' and func.attr in ('check', 'check_margin')
                and self.vector and len(node.args) >= 2 and not node.keywords):
            # A vector context's check only masks (``_Context.check``): the message's
            # values and callables it would not read are not computed.
            call = ast.Call(ast.Attribute(ast.Name('ctx', ast.Load()), 'mask', ast.Load()),
                            node.args[:2], [])
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
            raise Unsupported(f'`{node.id}` used as a value (not in the kernel subset)')
        return node


def _inline(func: ast.expr, args: list[ast.expr],
            namespace: dict[str, Any]) -> ast.expr | None:
    """Return the call of a one-line helper of the solver package written out, or None.

    A module function whose body is ``return <expression>`` (``_dot``,
    ``_cross``, ``_fixed_on``), called with plain names or constants, becomes
    its expression with the arguments put in, and the numbers its own module
    names (``U``, ``_U2``) as their values: the same operations, without the
    call.
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
    own = helper.__globals__

    class Substitute(ast.NodeTransformer):
        def visit_Name(self, node: ast.Name) -> ast.AST:
            if node.id in bound:
                return bound[node.id]
            value = own.get(node.id)
            if isinstance(value, float):    # a number of the helper's module: its value
                return ast.copy_location(ast.Constant(value), node)
            return node

    expression: ast.expr = Substitute().visit(definition.body[0].value)
    return expression


#: How deep helpers may call helpers (:meth:`_Specializer.inline`).
_HELPER_DEPTH = 8
#: The statements and expressions outside the kernel subset, and their keyword.
_OUTSIDE = {ast.Global: 'global', ast.Nonlocal: 'nonlocal', ast.Return: 'return',
            ast.Yield: 'yield', ast.YieldFrom: 'yield from', ast.Await: 'await',
            ast.For: 'for', ast.AsyncFor: 'async for', ast.While: 'while', ast.Try: 'try',
            ast.With: 'with', ast.AsyncWith: 'async with', ast.FunctionDef: 'def',
            ast.AsyncFunctionDef: 'async def', ast.ClassDef: 'class'}


@functools.cache
def _source(function: Callable[..., Any]) -> str:
    """Return the source of a kernel or helper, dedented (read once per process)."""
    try:
        source = inspect.getsource(function)
    except (OSError, TypeError) as error:   # no source file (defined at a prompt, built in)
        name = getattr(function, '__qualname__', repr(function))
        raise Unsupported(f'the source of {name} cannot be read ({error})') from None
    return textwrap.dedent(source)


def _stored(function: ast.FunctionDef) -> set[str]:
    """Return the names ``function``'s body binds."""
    return {n.id for n in ast.walk(function)
            if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)}


def _checked(function: ast.FunctionDef, what: str, returns: bool = False) -> list[ast.stmt]:
    """Return ``function``'s statements after its docstring; refuse what is outside the subset.

    With ``returns`` (a helper), one ``return`` is allowed, as the last statement.
    """
    body = [stmt for stmt in function.body
            if not (isinstance(stmt, ast.Expr) and isinstance(stmt.value, ast.Constant))]
    last = body[-1] if returns and body and isinstance(body[-1], ast.Return) else None
    for n in itertools.chain.from_iterable(ast.walk(stmt) for stmt in body):
        if isinstance(n, ast.Lambda) and (n.args.args or n.args.vararg or n.args.kwarg):
            raise Unsupported(f'{what} uses a lambda with arguments (not in the kernel subset)')
        if type(n) in _OUTSIDE and n is not last:
            where = ' before its end' if isinstance(n, ast.Return) and returns else ''
            raise Unsupported(f'{what} uses `{_OUTSIDE[type(n)]}`{where} (not in the kernel '
                              'subset)')
    return body


def _body(step: Any, method: Callable[..., Any], suffix: str, names: dict[str, str],
          namespace: dict[str, Any], arguments: dict[str, str],
          vector: bool = False) -> list[ast.stmt]:
    """Return the statements of ``method`` (a step's ``run``) specialized to ``step``."""
    tree = ast.parse(_source(method))
    function = tree.body[0]
    if not isinstance(function, ast.FunctionDef):
        raise Unsupported('kernel is not a plain function')
    specializer = _Specializer(step, suffix, names, namespace, arguments, vector)
    parameters = {a.arg for a in function.args.args}
    specializer.locals = _stored(function) - parameters - set(arguments)
    module = ast.Module(body=_checked(function, 'kernel'), type_ignores=[])
    module = cast(ast.Module, fold(specializer.visit(module)))
    return [stmt for stmt in module.body if not isinstance(stmt, ast.Pass)]


def _step_body(step: Any, method: Callable[..., Any], suffix: str, names: dict[str, str],
               namespace: dict[str, Any], arguments: dict[str, str],
               vector: bool) -> list[ast.stmt]:
    """Return :func:`_body`'s statements; an :class:`Unsupported` names the step."""
    try:
        return _body(step, method, suffix, names, namespace, arguments, vector)
    except Unsupported as unsupported:
        label = getattr(step, 'label', '') or type(step).__name__
        raise Unsupported(f'step {label}: {unsupported.reason}') from None


def plan_body(plan: Any, names: dict[str, str], namespace: dict[str, Any],
              vector: bool = False,
              driver_values: Sequence[tuple[str, str, str]] | None = None,
              propagated: bool = True) -> list[ast.stmt]:
    """Return the statements solving ``plan`` (a :class:`.compiler.ScenePlan`) in one function.

    The function's arguments are ``theta, omega, alpha, turns`` (and, on the
    array path, ``ctx``: a context for the checks and side facts); the
    statements leave every table entry in a local variable, ``names`` mapping
    ``'<table prefix>_<name>'`` (:data:`TABLES`) to it. ``namespace`` gets the
    globals the statements read (the kernels' modules', and the constants).
    With ``driver_values`` (one (position, speed, accel) triple of names per
    driver, a scalar tick of several drivers), each driver's kernel runs on its
    own names instead of the crank's on ``theta, omega, alpha``. The
    statements are :func:`propagate`'d, every table entry's local kept; with
    ``propagated`` false they are not, for a caller that runs
    :func:`propagate` over the whole function it makes of them.
    Raises :class:`Unsupported` where a kernel is outside the subset (its
    reason names the step).
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
    for name, entry in plan.ground.items():
        local = names.setdefault(f'P_{name}', f'P_{name}_{len(names)}')
        namespace[f'_ground_{local}'] = entry
        body.append(ast.parse(f'{local} = _ground_{local}').body[0])
    for k, (driver, given) in enumerate(zip(drivers, values, strict=True)):
        run = type(driver).run
        parameters = list(inspect.signature(run).parameters)[2:]   # after self, ctx
        if len(parameters) != len(given):
            raise Unsupported(f"step {driver.label}: a driver's run takes (self, ctx, "
                              f'position, speed, accel), got {len(parameters)} after ctx')
        arguments = dict(zip(parameters, given, strict=True))
        body += _step_body(driver, run, f'_d{k}' if driver_values else '_0', names, namespace,
                           arguments, vector)
    for index, step in enumerate(plan.steps, 1):
        # Step.kernels names the single-angle path; the array path is ``run`` itself.
        kernels = (type(step).run,) if vector else step.kernels()
        for part, kernel in enumerate(kernels):
            body += _step_body(step, kernel, f'_{index}_{part}', names, namespace, {}, vector)
    return propagate(body, namespace, set(names.values()), vector) if propagated else body


#: The numbers a folded constant may hold: what the runtime computes with Python's own
#: arithmetic when both operands are such constants.
_NUMBERS = (bool, int, float, complex)
_BINARY: dict[type[ast.operator], Callable[[Any, Any], Any]] = {
    ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
    ast.Div: operator.truediv, ast.FloorDiv: operator.floordiv, ast.Mod: operator.mod,
    ast.Pow: operator.pow,
}
_UNARY: dict[type[ast.unaryop], Callable[[Any], Any]] = {
    ast.USub: operator.neg, ast.UAdd: operator.pos, ast.Not: operator.not_,
}
_COMPARE: dict[type[ast.cmpop], Callable[[Any, Any], Any]] = {
    ast.Eq: operator.eq, ast.NotEq: operator.ne, ast.Lt: operator.lt, ast.LtE: operator.le,
    ast.Gt: operator.gt, ast.GtE: operator.ge,
}


def _is_constant(value: Any) -> bool:
    """Return whether ``value`` is a number, or a tuple of numbers, folding may use."""
    if isinstance(value, tuple):
        return all(type(v) in _NUMBERS for v in value)
    return type(value) in _NUMBERS


def _evaluated(function: Callable[..., Any], *operands: Any) -> ast.Constant | None:
    """Return ``function(*operands)`` as a constant, or None where it raises or is no number."""
    try:
        value = function(*operands)
    except (ArithmeticError, TypeError, ValueError):
        return None
    return ast.Constant(value) if type(value) in _NUMBERS else None


class _Propagator(_Folder):
    """Put in the constants of :func:`propagate`, and fold what they make constant."""

    def __init__(self, known: dict[str, Any], copies: dict[str, str],
                 tuples: dict[str, list[ast.expr | None]], shadowed: set[str]) -> None:
        self.known = known          # a local assigned once, from a constant -> its value
        self.copies = copies        # a local assigned once, from a name -> that name
        self.tuples = tuples        # a local assigned once, from a tuple display -> entries
        self.shadowed = shadowed    # builtins a local or the namespace redefines

    def visit_Name(self, node: ast.Name) -> ast.AST:
        if isinstance(node.ctx, ast.Load) and node.id in self.known:
            return ast.copy_location(ast.Constant(self.known[node.id]), node)
        if isinstance(node.ctx, ast.Load) and node.id in self.copies:
            return ast.copy_location(ast.Name(self.copies[node.id], ast.Load()), node)
        return node

    def visit_Attribute(self, node: ast.Attribute) -> ast.AST:
        self.generic_visit(node)
        value = node.value
        if (isinstance(value, ast.Constant) and type(value.value) in _NUMBERS
                and node.attr in ('real', 'imag') and isinstance(node.ctx, ast.Load)):
            folded = _evaluated(getattr, value.value, node.attr)
            if folded is not None:
                return ast.copy_location(folded, node)
        return node

    def visit_Subscript(self, node: ast.Subscript) -> ast.AST:
        node.slice = self.visit(node.slice)
        value, index = node.value, node.slice
        if (isinstance(value, ast.Name) and value.id in self.tuples
                and isinstance(index, ast.Constant) and type(index.value) is int
                and isinstance(node.ctx, ast.Load)
                and -len(self.tuples[value.id]) <= index.value < len(self.tuples[value.id])):
            # An entry of a tuple bound once, that is a constant or a name bound once.
            entry = self.tuples[value.id][index.value]
            if entry is not None:
                read: ast.AST = self.visit(ast.copy_location(_copy(entry), node))
                return read
        if (isinstance(value, ast.Name) and value.id in self.tuples
                and isinstance(index, ast.Slice) and isinstance(node.ctx, ast.Load)
                and index.step is None and all(
                    part is None or (isinstance(part, ast.Constant) and type(part.value) is int)
                    for part in (index.lower, index.upper))):
            # ``P[:3]`` of ``P = (a, b, c, ...)``: the tuple ``(a, b, c)``.
            lower, upper = (None if part is None else cast(ast.Constant, part).value
                            for part in (index.lower, index.upper))
            slice_of = self.tuples[value.id][slice(cast(Any, lower), cast(Any, upper))]
            if None not in slice_of:
                built: ast.AST = self.visit(ast.copy_location(ast.Tuple(
                    [_copy(cast(ast.expr, e)) for e in slice_of], ast.Load()), node))
                return built
        self.generic_visit(node)
        value, index = node.value, node.slice
        entries: Any = value.value if isinstance(value, ast.Constant) else None
        if not (isinstance(entries, tuple) and isinstance(node.ctx, ast.Load)):
            return node
        if isinstance(index, ast.Constant) and type(index.value) is int:
            folded = _evaluated(operator.getitem, entries, index.value)
            if folded is not None:
                return ast.copy_location(folded, node)
        if isinstance(index, ast.Slice) and all(
                part is None or (isinstance(part, ast.Constant) and type(part.value) is int)
                for part in (index.lower, index.upper, index.step)):
            bounds: list[Any] = [None if part is None else cast(ast.Constant, part).value
                                 for part in (index.lower, index.upper, index.step)]
            if bounds[2] != 0:
                part_of: Any = entries[slice(*bounds)]
                return ast.copy_location(ast.Constant(part_of), node)
        return node

    def visit_Call(self, node: ast.Call) -> ast.AST:
        self.generic_visit(node)
        if (isinstance(node.func, ast.Name) and node.func.id == 'abs'
                and 'abs' not in self.shadowed and len(node.args) == 1 and not node.keywords
                and isinstance(node.args[0], ast.Constant)
                and type(node.args[0].value) in _NUMBERS):
            folded = _evaluated(abs, node.args[0].value)
            if folded is not None:
                return ast.copy_location(folded, node)
        return node

    def visit_UnaryOp(self, node: ast.UnaryOp) -> ast.AST:
        self.generic_visit(node)
        operand = node.operand
        function = _UNARY.get(type(node.op))
        if (function is not None and isinstance(operand, ast.Constant)
                and type(operand.value) in _NUMBERS):
            folded = _evaluated(function, operand.value)
            if folded is not None:
                return ast.copy_location(folded, node)
        if isinstance(node.op, ast.Not) and isinstance(operand, ast.Constant):
            return ast.Constant(not operand.value)
        return node

    def visit_BinOp(self, node: ast.BinOp) -> ast.AST:
        self.generic_visit(node)
        left, right = node.left, node.right
        function = _BINARY.get(type(node.op))
        if isinstance(node.op, ast.Pow) and not isinstance(getattr(right, 'value', 0), float):
            function = None                         # an integer power could be huge
        if (function is not None and isinstance(left, ast.Constant)
                and isinstance(right, ast.Constant) and type(left.value) in _NUMBERS
                and type(right.value) in _NUMBERS):
            folded = _evaluated(function, left.value, right.value)
            if folded is not None:
                return ast.copy_location(folded, node)
        return node

    def visit_Compare(self, node: ast.Compare) -> ast.AST:
        self.generic_visit(node)
        operands = [node.left, *node.comparators]
        functions = [_COMPARE.get(type(op)) for op in node.ops]
        if not all(isinstance(o, ast.Constant) and type(o.value) in _NUMBERS
                   for o in operands) or None in functions:
            folded: ast.AST = super().visit_Compare(node)   # ``None is None``
            return folded
        values = [cast(ast.Constant, o).value for o in operands]
        result = True
        for function, left, right in zip(functions, values, values[1:], strict=False):
            compared = _evaluated(cast(Callable[[Any, Any], Any], function), left, right)
            if compared is None:
                return node
            if not compared.value:
                result = False
                break                               # a chain stops at its first false
        return ast.copy_location(ast.Constant(result), node)


def _copy(node: ast.expr) -> ast.expr:
    """Return a fresh node for a constant or a name read (one node is never in two places)."""
    if isinstance(node, ast.Constant):
        return ast.Constant(node.value)
    return ast.Name(cast(ast.Name, node).id, ast.Load())


def _stores(body: Sequence[ast.AST]) -> dict[str, int]:
    """Return how many times each name is bound anywhere in ``body`` (statements or targets)."""
    counts: dict[str, int] = {}
    for stmt in body:
        for n in ast.walk(stmt):
            if isinstance(n, ast.Name) and not isinstance(n.ctx, ast.Load):
                counts[n.id] = counts.get(n.id, 0) + 1
            elif isinstance(n, ast.arg):
                counts[n.arg] = counts.get(n.arg, 0) + 2    # never a constant
            elif (isinstance(n, ast.AnnAssign) and n.value is None
                  and isinstance(n.target, ast.Name)):
                counts[n.target.id] = counts.get(n.target.id, 0) - 1   # ``e: Any`` binds none
    return counts


def _targets(stmt: ast.stmt) -> list[tuple[str, ast.expr | None]] | None:
    """Return the (name, value) pairs a plain assignment binds, or None for any other.

    ``a = x`` gives ``[('a', x)]``, ``a, b = (x, y)`` gives ``[('a', x), ('b', y)]``
    and ``a, b = t`` gives ``[('a', None), ('b', None)]`` (or the entries of ``t``
    where it is a constant tuple).
    """
    if not (isinstance(stmt, ast.Assign) and len(stmt.targets) == 1):
        return None
    target, value = stmt.targets[0], stmt.value
    if isinstance(target, ast.Name):
        return [(target.id, value)]
    if not (isinstance(target, ast.Tuple)
            and all(isinstance(t, ast.Name) for t in target.elts)):
        return None
    names = [cast(ast.Name, t).id for t in target.elts]
    if isinstance(value, ast.Tuple) and len(value.elts) == len(names) and not any(
            isinstance(v, ast.Starred) for v in value.elts):
        return list(zip(names, value.elts, strict=True))
    entries: Any = value.value if isinstance(value, ast.Constant) else None
    if isinstance(entries, tuple) and len(entries) == len(names):
        return [(n, ast.Constant(v)) for n, v in zip(names, entries, strict=True)]
    return [(n, None) for n in names]


def _reads(body: list[ast.stmt]) -> Counter[str]:
    """Return how often each name is read in ``body`` (lambdas and f-strings included)."""
    return Counter(n.id for stmt in body for n in ast.walk(stmt)
                   if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load))


def _inert(value: ast.expr | None) -> bool:
    """Return whether computing ``value`` can neither raise nor act: names and constants."""
    if isinstance(value, ast.Tuple):
        return all(_inert(e) for e in value.elts)
    return isinstance(value, (ast.Constant, ast.Name))


def _pruned(stmt: ast.stmt, dead: set[str]) -> ast.stmt | None:
    """Return ``stmt`` without the bindings of ``dead`` names to inert values (:func:`_inert`).

    Only a binding whose value cannot raise or act (a constant, a name the
    code has bound) is removed: any other value is still computed.
    """
    pairs = _targets(stmt)
    if pairs is None:
        return stmt
    idle = [name in dead and _inert(value) for name, value in pairs]
    if not any(idle):
        return stmt
    if all(idle):
        return None
    if any(value is None for _, value in pairs):
        return stmt                                  # an unpacking of a tuple stays whole
    kept = [(name, cast(ast.expr, value)) for (name, value), i in zip(pairs, idle, strict=True)
            if not i]
    if len(kept) == 1:
        new: ast.stmt = ast.Assign([ast.Name(kept[0][0], ast.Store())], kept[0][1])
    else:
        new = ast.Assign([ast.Tuple([ast.Name(n, ast.Store()) for n, _ in kept], ast.Store())],
                         ast.Tuple([v for _, v in kept], ast.Load()))
    return ast.copy_location(new, stmt)


def _substituted(body: list[ast.stmt], namespace: dict[str, Any], counts: dict[str, int],
                 shadowed: set[str]) -> list[ast.stmt]:
    """Return ``body`` with its constants and copies put in where read, and folded.

    A copy ``a = b`` (``a`` bound once, ``b`` bound once before it or never
    in ``body``) has ``b`` read for ``a``: the same object.
    """
    known: dict[str, Any] = {}
    copies: dict[str, str] = {}
    tuples: dict[str, list[ast.expr | None]] = {}
    propagator = _Propagator(known, copies, tuples, shadowed)
    passed: Counter[str] = Counter()     # the bindings of each name before this point

    def stable(entry: ast.expr) -> bool:
        """Return whether ``entry`` reads the same anywhere after this point.

        A constant does, and a local all of whose bindings are behind, or an
        argument (a global reads slower than the local it would replace).
        """
        if isinstance(entry, ast.Constant):
            return True
        return isinstance(entry, ast.Name) and (
            passed[entry.id] == counts[entry.id] if entry.id in counts
            else entry.id not in namespace)

    out: list[ast.stmt] = []
    pending = list(reversed(body))
    while pending:
        stmt = pending.pop()
        if (isinstance(stmt, ast.Assign) and isinstance(stmt.value, ast.Name)
                and stmt.value.id.startswith('_ground_') and stmt.value.id not in counts
                and _is_constant(namespace.get(stmt.value.id))):
            stmt.value = ast.copy_location(ast.Constant(namespace[stmt.value.id]), stmt.value)
        visited = propagator.visit(stmt)
        if isinstance(visited, list):       # an ``if`` whose test folded: its branch's
            pending.extend(reversed(visited))   # statements, in turn (visited again: the same)
            continue
        stmt = cast(ast.stmt, visited)
        if isinstance(stmt, ast.Pass):
            continue
        if (isinstance(stmt, ast.Assign) and isinstance(stmt.value, ast.Name)
                and isinstance(stmt.targets[0], ast.Tuple) and len(stmt.targets) == 1
                and None not in tuples.get(stmt.value.id, [None])
                and len(tuples[stmt.value.id]) == len(stmt.targets[0].elts)):
            # ``a, b = P`` of ``P = (x, y)``: ``a, b = (x, y)``, the same objects.
            stmt.value = ast.copy_location(ast.Tuple(
                [_copy(cast(ast.expr, e)) for e in tuples[stmt.value.id]], ast.Load()),
                stmt.value)
        for name, value in _targets(stmt) or ():
            if counts.get(name) != 1:
                continue
            if isinstance(value, ast.Constant) and _is_constant(value.value):
                known[name] = value.value
            elif isinstance(value, ast.Tuple) and all(
                    isinstance(e, ast.Constant) for e in value.elts) and _is_constant(
                        entries := tuple(cast(ast.Constant, e).value for e in value.elts)):
                known[name] = entries
            elif isinstance(value, ast.Name) and stable(value):
                copies[name] = value.id
            elif isinstance(value, ast.Tuple):
                tuples[name] = [_copy(e) if stable(e) else None for e in value.elts]
        # (An assignment's targets alone: a comprehension's variable, left uncounted,
        # only keeps its name from ever being stable.)
        passed.update(_stores(stmt.targets if isinstance(stmt, ast.Assign) else [stmt]))
        out.append(stmt)
    return out


def _hoisted(body: list[ast.stmt], counts: dict[str, int],
             namespace: dict[str, Any]) -> list[ast.stmt]:
    """Return ``body`` with the computed entries of its tuples bound to locals first.

    ``P = (e0, n, e2)`` (``P`` bound once at the top level) becomes
    ``_e0 = e0; _e1 = e2; P = (_e0, n, _e1)``: the entries are computed in the
    same order (a name the code has bound, or a constant, reads the same
    before or after them; a tuple with a starred entry or a walrus stays), and
    ``P[2]`` or ``a, b, c = P`` then read locals instead of indexing or
    unpacking the tuple. ``counts`` gets the new locals.
    """
    used = {n.id for stmt in body for n in ast.walk(stmt) if isinstance(n, ast.Name)}
    fresh = (f'_e{k}' for k in itertools.count())
    out: list[ast.stmt] = []
    for stmt in body:
        pairs = _targets(stmt)
        if (pairs is not None and len(pairs) == 1 and counts.get(pairs[0][0]) == 1
                and isinstance(pairs[0][1], ast.Tuple) and not any(
                    isinstance(n, (ast.Starred, ast.NamedExpr))
                    for n in ast.walk(pairs[0][1]))):
            entries: list[ast.expr] = []
            for entry in pairs[0][1].elts:
                if isinstance(entry, (ast.Constant, ast.Name)):
                    entries.append(entry)
                    continue
                name = next(n for n in fresh if n not in used and n not in namespace)
                counts[name] = 1
                out.append(ast.copy_location(ast.Assign([ast.Name(name, ast.Store())], entry),
                                             stmt))
                entries.append(ast.Name(name, ast.Load()))
            pairs[0][1].elts = entries
        out.append(stmt)
    return out


def propagate(body: list[ast.stmt], namespace: dict[str, Any], live: set[str],
              vector: bool = True) -> list[ast.stmt]:
    """Return ``body`` with its constants propagated and folded, and its idle constants dropped.

    A local bound exactly once, at the top level of ``body``, to a constant
    (a number, a tuple of numbers unpacked, or a ``_ground_*`` tuple of
    ``namespace`` whose entries are Python numbers) is replaced by that
    constant where it is read. ``.real`` and ``.imag`` of a constant,
    ``abs()`` of one, a unary operation, and a binary operation or a
    comparison whose operands are all constants are computed now, by the
    same Python arithmetic the function would run (the operands are Python
    numbers at run time too, so the result has the same bits and type); a fold
    whose evaluation raises is not made, and the error stays where it was.
    Then every binding of a local that is never read and not in ``live``
    (the names the caller reads after ``body``) whose value is a constant or
    a name is dropped: a value that calls, computes or may raise stays.
    """
    counts = _stores(body)
    shadowed = {name for name in ('abs',) if name in namespace or name in counts}
    out = _substituted(body, namespace, counts, shadowed)
    identities = _Identities(_Kinds(out, namespace), vector)
    out = [cast(ast.stmt, identities.visit(stmt)) for stmt in out]
    # Copies made by the identities (``d = b - 0j``), entries of the tuples hoisted.
    out = _substituted(_hoisted(out, counts, namespace), namespace, counts, shadowed)
    if vector:
        zero_d = _ZeroD(_Arrays(out, namespace), namespace)
        out = [cast(ast.stmt, zero_d.visit(stmt)) for stmt in out]
    reads = _reads(out)
    while True:
        dead = {name for name in counts if name not in live and not reads[name]}
        pruned: list[ast.stmt] = []
        for stmt in out:
            kept = _pruned(stmt, dead)
            if kept is not stmt:
                reads.subtract(_reads([stmt]))
                if kept is not None:
                    reads.update(_reads([kept]))
            if kept is not None:
                pruned.append(kept)
        if len(pruned) == len(out) and all(
                a is b for a, b in zip(pruned, out, strict=True)):
            if vector:
                ufuncs = _Ufuncs(_Arrays(pruned, namespace), namespace, pruned)
                pruned = [cast(ast.stmt, ufuncs.visit(stmt)) for stmt in pruned]
            return pruned
        out = pruned


#: What a value is known to be at run time, whatever the inputs: a real floating-point
#: number (a Python float, a NumPy floating scalar or array), any real number (an int or a
#: bool too), or a complex one.
FLOAT, REAL, COMPLEX = 'float', 'real', 'complex'
_Kind = str | tuple[Any, ...] | None
#: Calls whose result is a real float for any arguments they accept: (module, name).
_REAL_CALLS = {('math', n) for n in ('sqrt', 'cos', 'sin', 'atan2', 'hypot', 'fabs', 'exp',
                                     'log', 'tan', 'asin', 'acos', 'atan')}
#: NumPy functions whose result is floating point for real arguments (ints give float64).
_NUMPY_REAL = ('sqrt', 'hypot', 'cos', 'sin', 'arctan2', 'exp', 'log')


class _Kinds:
    """The kinds (:data:`FLOAT`, :data:`COMPLEX`) of the names a body binds, where known.

    A name's kind is the kind every one of its bindings gives (any read sees
    one of them). It is unknown (``None``) where a binding is not a plain
    assignment or where the bindings disagree. The code computes on Python
    numbers and on NumPy numeric arrays (never object arrays): an operation
    with a complex operand then gives a complex value or raises.
    """

    def __init__(self, body: list[ast.stmt], namespace: dict[str, Any]) -> None:
        self.namespace = namespace
        self.bindings: dict[str, list[tuple[ast.expr, int | None]]] = {}
        self.opaque: set[str] = set()       # names bound otherwise than by a plain assignment
        self.memo: dict[str, _Kind] = {}
        for stmt in body:
            for node in ast.walk(stmt):
                if isinstance(node, ast.Assign):
                    self.bind(node)
                elif isinstance(node, (ast.AugAssign, ast.NamedExpr, ast.For,
                                       ast.comprehension)) or (
                        isinstance(node, ast.AnnAssign) and node.value is not None):
                    self.opaque.update(n.id for n in ast.walk(node.target)
                                       if isinstance(n, ast.Name))
                elif isinstance(node, ast.arg):
                    self.opaque.add(node.arg)

    def bind(self, node: ast.Assign) -> None:
        """Record the bindings of one assignment."""
        for target in node.targets:
            if isinstance(target, ast.Name):
                self.bindings.setdefault(target.id, []).append((node.value, None))
            elif isinstance(target, ast.Tuple) and all(isinstance(t, ast.Name)
                                                       for t in target.elts):
                for index, t in enumerate(target.elts):
                    self.bindings.setdefault(cast(ast.Name, t).id, []).append(
                        (node.value, index))
            else:
                self.opaque.update(n.id for n in ast.walk(target) if isinstance(n, ast.Name))

    def name(self, name: str) -> _Kind:
        """Return the kind of a name: the kind all its bindings agree on, or None."""
        if name in self.memo:
            return self.memo[name]
        self.memo[name] = None                      # a binding that reads the name itself
        if name in self.opaque or name not in self.bindings:
            return None
        kinds = {self.entry(value, index) for value, index in self.bindings[name]}
        kind = kinds.pop() if len(kinds) == 1 else None
        self.memo[name] = kind
        return kind

    def entry(self, value: ast.expr, index: int | None) -> _Kind:
        """Return the kind of ``value``, or of its entry ``index`` where it is unpacked."""
        kind = self.of(value)
        if index is None:
            return kind
        return kind[index] if isinstance(kind, tuple) and index < len(kind) else None

    def of(self, node: ast.expr) -> _Kind:
        """Return the kind of an expression, or None where it is not known."""
        if isinstance(node, ast.Constant):
            value: Any = node.value
            if isinstance(value, tuple):
                return tuple(self.of(ast.Constant(v)) for v in value)
            return {float: FLOAT, int: REAL, bool: REAL, complex: COMPLEX}.get(type(value))
        if isinstance(node, ast.Name):
            return self.name(node.id)
        if isinstance(node, ast.Tuple):
            return tuple(self.of(e) for e in node.elts)
        if isinstance(node, ast.Attribute):
            if node.attr in ('real', 'imag'):
                return FLOAT if self.of(node.value) in (FLOAT, COMPLEX) else REAL
            return None
        if isinstance(node, ast.UnaryOp):
            return self.of(node.operand) if isinstance(node.op, (ast.USub, ast.UAdd)) else None
        arithmetic = (ast.Add, ast.Sub, ast.Mult, ast.Div)
        if isinstance(node, ast.BinOp) and isinstance(node.op, arithmetic):
            kinds = (self.of(node.left), self.of(node.right))
            if COMPLEX in kinds:
                return COMPLEX
            if not set(kinds) <= {FLOAT, REAL}:
                return None
            return FLOAT if FLOAT in kinds or isinstance(node.op, ast.Div) else REAL
        if isinstance(node, ast.IfExp):
            body, orelse = self.of(node.body), self.of(node.orelse)
            return body if body == orelse else None
        if isinstance(node, ast.Call):
            return self.call(node)
        return None

    def call(self, node: ast.Call) -> _Kind:
        """Return the kind of a call's result, for the calls whose kind is known."""
        func = node.func
        if isinstance(func, ast.Name) and func.id not in self.namespace and not self.bindings.get(
                func.id):
            if func.id == 'abs' and len(node.args) == 1:
                return FLOAT if self.of(node.args[0]) in (FLOAT, COMPLEX) else REAL
            if func.id == 'complex' and node.args:
                return COMPLEX
            return None
        if (isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name)
                and func.value.id not in self.bindings):
            module = getattr(self.namespace.get(func.value.id), '__name__', None)
            if (module, func.attr) in _REAL_CALLS:
                return FLOAT
            if module == 'numpy' and func.attr in _NUMPY_REAL and all(
                    self.of(a) in (FLOAT, REAL) for a in node.args) and not node.keywords:
                return FLOAT
            if module == 'numpy' and func.attr in ('empty', 'zeros', 'ones') and any(
                    k.arg == 'dtype' and isinstance(k.value, ast.Attribute)
                    and k.value.attr in ('complex128', 'complex64') for k in node.keywords):
                return COMPLEX
        return None


class _Identities(ast.NodeTransformer):
    """Remove the operations that give back their operand, bit for bit (see the module).

    On the array path an operation is removed only where its value is used
    by another operation and never bound: removing ``x * 1.0`` there must not
    leave two names on one array (a fresh array before).
    """

    def __init__(self, kinds: _Kinds, vector: bool) -> None:
        self.kinds = kinds
        self.vector = vector
        self.consumed = False           # whether the node visited is an arithmetic operand
        self.removed = 0

    def generic_visit(self, node: ast.AST) -> ast.AST:
        consumed = self.consumed
        self.consumed = isinstance(node, (ast.BinOp, ast.UnaryOp, ast.Compare))
        try:
            return super().generic_visit(node)
        finally:
            self.consumed = consumed

    def visit_BinOp(self, node: ast.BinOp) -> ast.AST:
        consumed = self.consumed
        self.generic_visit(node)
        kept = _identity(node, self.kinds)
        if kept is None:
            return node
        fresh = not isinstance(kept, (ast.Name, ast.Attribute, ast.Subscript, ast.Constant))
        if self.vector and not (consumed or fresh):
            return node
        self.removed += 1
        return kept


def _is_zero(value: Any) -> bool:
    """Return whether ``value`` is an int 0, or a float or complex zero of positive sign."""
    if type(value) is int:
        return value == 0
    if type(value) is float:
        return value == 0.0 and math.copysign(1.0, value) > 0
    if type(value) is complex:
        return _is_zero(value.real) and _is_zero(value.imag)
    return False


def _identity(node: ast.BinOp, kinds: _Kinds) -> ast.expr | None:
    """Return the operand ``node`` gives back unchanged for every input, or None."""
    left, right = node.left, node.right
    right_value = right.value if isinstance(right, ast.Constant) else None
    left_value = left.value if isinstance(left, ast.Constant) else None

    def one(value: Any) -> bool:
        return type(value) in (int, float) and value == 1

    if isinstance(node.op, ast.Sub) and _is_zero(right_value):
        wanted = (COMPLEX,) if type(right_value) is complex else (FLOAT, COMPLEX)
        return left if kinds.of(left) in wanted else None
    if isinstance(node.op, (ast.Mult, ast.Div)) and one(right_value):
        return left if kinds.of(left) == FLOAT else None
    if isinstance(node.op, ast.Mult) and one(left_value):
        return right if kinds.of(right) == FLOAT else None
    return None


#: What :class:`_Arrays` knows of a value: an array of one dimension or more.
ARRAY = 'array'
#: NumPy functions that give an array of the broadcast shape of their arguments.
_NUMPY_ELEMENTWISE = ('sqrt', 'hypot', 'cos', 'sin', 'arctan2', 'exp', 'log', 'minimum',
                      'maximum', 'fmin', 'fmax', 'where', 'abs', 'absolute', 'copysign')


class _Arrays(_Kinds):
    """The values of the array path's code that are arrays of one dimension or more.

    ``theta`` is one (the array path's angles, a 1-D float64 array), and so
    is what an arithmetic operation, ``abs``, ``.real`` or ``.imag``, or an
    element-wise NumPy function makes of one. ``omega`` and ``alpha`` (0-d
    arrays or arrays) and what is made of them alone are not known: an
    operation on two 0-d arrays gives a NumPy scalar.
    """

    def of(self, node: ast.expr) -> _Kind:
        """Return :data:`ARRAY` where ``node`` is an array at run time, a tuple's per entry."""
        if isinstance(node, ast.Name):
            return ARRAY if node.id == 'theta' and node.id not in self.bindings else self.name(
                node.id)
        if isinstance(node, ast.Tuple):
            return tuple(self.of(e) for e in node.elts)
        if isinstance(node, ast.Attribute):
            parts = node.attr in ('real', 'imag')
            return ARRAY if parts and self.of(node.value) == ARRAY else None
        if isinstance(node, ast.UnaryOp):
            return self.of(node.operand) if isinstance(node.op, (ast.USub, ast.UAdd)) else None
        arithmetic = (ast.Add, ast.Sub, ast.Mult, ast.Div)
        if isinstance(node, ast.BinOp) and isinstance(node.op, arithmetic):
            return ARRAY if ARRAY in (self.of(node.left), self.of(node.right)) else None
        if isinstance(node, ast.IfExp):
            body = self.of(node.body)
            return body if body == self.of(node.orelse) else None
        if isinstance(node, ast.Call):
            return self.call(node)
        return None

    def call(self, node: ast.Call) -> _Kind:
        """Return :data:`ARRAY` for ``abs`` and NumPy's element-wise functions of an array."""
        func = node.func
        arrays = any(self.of(a) == ARRAY for a in node.args)
        if isinstance(func, ast.Name) and func.id == 'abs' and func.id not in self.namespace:
            return ARRAY if arrays else None
        if (isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name)
                and func.value.id not in self.bindings
                and self.namespace.get(func.value.id) is np):
            if func.attr in _NUMPY_ELEMENTWISE and arrays:
                return ARRAY
            shape = node.args[0] if node.args else None
            if (func.attr in ('empty', 'zeros', 'ones') and isinstance(shape, ast.Call)
                    and ast.unparse(shape) == 'np.shape(theta)'):
                return ARRAY
        return None


class _ZeroD(ast.NodeTransformer):
    """Give the array path's array operations their float and complex constants as 0-d arrays.

    NumPy 2 spends about a third less on ``array * c`` with ``c`` a 0-d
    float64 array than with ``c`` the Python float (it converts a Python
    number on every call), and NEP 50 gives both the same dtype and bits on the
    path's float64 and complex128 arrays: a Python float or complex is cast to
    float64 or complex128 for the operation, as the 0-d array is. Not where
    the other operand may be a scalar: a 0-d array there is slower than the
    Python number and changes the result's type.
    """

    def __init__(self, arrays: _Arrays, namespace: dict[str, Any]) -> None:
        self.arrays = arrays
        self.namespace = namespace
        self.made: dict[tuple[type, str], str] = {}

    def zero_d(self, node: ast.Constant) -> ast.expr:
        """Return a read of the 0-d array holding the constant ``node``."""
        key = (type(node.value), repr(node.value))
        name = self.made.get(key)
        if name is None:
            name = next(n for n in (f'_z{k}' for k in itertools.count(len(self.namespace)))
                        if n not in self.namespace)
            self.made[key] = name
            value = np.array(node.value)
            value.setflags(write=False)
            self.namespace[name] = value
        return ast.copy_location(ast.Name(name, ast.Load()), node)

    def visit_BinOp(self, node: ast.BinOp) -> ast.AST:
        self.generic_visit(node)
        if isinstance(node.op, (ast.Add, ast.Sub, ast.Mult, ast.Div)):
            left, right = node.left, node.right
            if (isinstance(left, ast.Constant) and type(left.value) in (float, complex)
                    and self.arrays.of(right) == ARRAY):
                node.left = self.zero_d(left)
            elif (isinstance(right, ast.Constant) and type(right.value) in (float, complex)
                    and self.arrays.of(left) == ARRAY):
                node.right = self.zero_d(right)
        return node

    def visit_Compare(self, node: ast.Compare) -> ast.AST:
        # ``array > 1e-12``: an ordering against a float, the same bool array.
        self.generic_visit(node)
        if len(node.ops) == 1 and isinstance(node.ops[0], (ast.Lt, ast.LtE, ast.Gt, ast.GtE)):
            left, right = node.left, node.comparators[0]
            if (isinstance(left, ast.Constant) and type(left.value) is float
                    and self.arrays.of(right) == ARRAY):
                node.left = self.zero_d(left)
            elif (isinstance(right, ast.Constant) and type(right.value) is float
                    and self.arrays.of(left) == ARRAY):
                node.comparators = [self.zero_d(right)]
        return node


class _Ufuncs(ast.NodeTransformer):
    """Call the array path's array arithmetic's NumPy functions directly.

    ``a + b`` with an array operand is ``np.add(a, b)`` (the array's
    operator calls it, the other operand being a Python number, a NumPy
    scalar or an array), with the same result; the call spares the
    operator's dispatch, about a tenth of an operation on a few hundred
    angles. Likewise ``-``, ``*``, ``/``, the orderings, unary minus and
    ``abs``. Only where :class:`_Arrays` knows an operand is an array: on
    two scalars the function would give a NumPy scalar where the operator
    gives a Python number.
    """

    BINARY = {ast.Add: 'add', ast.Sub: 'subtract', ast.Mult: 'multiply', ast.Div: 'true_divide'}
    ORDER = {ast.Lt: 'less', ast.LtE: 'less_equal', ast.Gt: 'greater', ast.GtE: 'greater_equal'}

    def __init__(self, arrays: _Arrays, namespace: dict[str, Any],
                 body: list[ast.stmt]) -> None:
        self.namespace = namespace
        # The operations to rewrite, judged on the whole body before any is rewritten
        # (the kinds are read from the statements as they are).
        self.marked = {id(node) for stmt in body for node in ast.walk(stmt)
                       if self.on_array(node, arrays)}

    def on_array(self, node: ast.AST, arrays: _Arrays) -> bool:
        """Return whether ``node`` is an operation to call NumPy's function for."""
        if isinstance(node, ast.BinOp):
            return type(node.op) in self.BINARY and arrays.of(node) == ARRAY
        if isinstance(node, ast.Compare):
            return (len(node.ops) == 1 and type(node.ops[0]) in self.ORDER
                    and ARRAY in (arrays.of(node.left), arrays.of(node.comparators[0])))
        if isinstance(node, ast.UnaryOp):
            return isinstance(node.op, ast.USub) and arrays.of(node.operand) == ARRAY
        if isinstance(node, ast.Call):
            return (isinstance(node.func, ast.Name) and node.func.id == 'abs'
                    and 'abs' not in self.namespace and len(node.args) == 1
                    and not node.keywords and arrays.of(node.args[0]) == ARRAY)
        return False

    def function(self, name: str, node: ast.expr, args: list[ast.expr]) -> ast.expr:
        local = f'_np_{name}'
        self.namespace.setdefault(local, getattr(np, name))
        return ast.copy_location(ast.Call(ast.Name(local, ast.Load()), args, []), node)

    def visit_BinOp(self, node: ast.BinOp) -> ast.AST:
        self.generic_visit(node)
        if id(node) not in self.marked:
            return node
        return self.function(self.BINARY[type(node.op)], node, [node.left, node.right])

    def visit_Compare(self, node: ast.Compare) -> ast.AST:
        self.generic_visit(node)
        if id(node) not in self.marked:
            return node
        return self.function(self.ORDER[type(node.ops[0])], node,
                             [node.left, node.comparators[0]])

    def visit_UnaryOp(self, node: ast.UnaryOp) -> ast.AST:
        self.generic_visit(node)
        return self.function('negative', node, [node.operand]) if id(node) in self.marked \
            else node

    def visit_Call(self, node: ast.Call) -> ast.AST:
        self.generic_visit(node)
        return self.function('absolute', node, node.args) if id(node) in self.marked else node
