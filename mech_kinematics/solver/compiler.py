# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The one compiler: a scene's solve written out as one straight-line function, or why not.

:func:`mech_kinematics.solve` runs every step's kernel through the
dictionaries of a context; a node solving one instant per tick, and a scene
solved often, pay for every lookup and call around the arithmetic.
:func:`compile_scene` writes the kernels of one scene (:meth:`.base.Step.kernels`,
in the subset :mod:`.base` states) out as the statements of one function, by
partial evaluation of their syntax trees (:mod:`.specialize`), for one
*target*:

- :class:`Single`: ``mk.solve``'s single-angle path, a function returning what
  a :class:`.State` holds (the reported joints, points, measures and the entries
  their bounds come from), or ``None`` where the general path must decide (a
  bound beyond the quick trust test: the general path refuses with the full
  reason, or answers; a crank rate it would rescale);
- :class:`Array`: ``mk.solve``'s array path, a function of NumPy operations
  filling a vector context as the steps would, optionally for one pair of
  crank rates (the scene's own: the usual call);
- :class:`Tick`: the node's tick, a function returning the flat list of
  values the node's messages take (the joints, points and frames it names)
  and the smallest near-singularity measure; an instant it cannot settle
  itself goes to the target's ``fallback`` (the general solver).

The same operations run in the same order on the same values, so each
function gives the bits, bounds and errors of the general path
(``test_compiler_solve``, ``test_ticker`` and ``test_compile_every_kind`` compare
them). Where a scene cannot be compiled for a target, :func:`compile_scene`
returns a :class:`NotCompiled` carrying the reason, one line: its lengths are
rescaled (a size beyond 2**60 of 1 m), it has pins to bound, a kernel is
outside the subset (the specializer's :class:`.specialize.Unsupported`, with
the step), or, for ``mk.solve``'s paths, an intermittent lever's engagement is
reported, it has several drivers (the tick compiles those) or more steps than
the target's ``max_steps``. Any other exception is a bug and propagates.

The compiler imports only what lies below the solve (:mod:`.trust`,
:mod:`.context`, :mod:`.scaling`, :mod:`.state`): the solve imports it, never
the other way (``test_imports``).
"""

from __future__ import annotations

import ast
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
import marshal
import math
import subprocess
import sys
from types import CodeType
from typing import Any, cast, overload, TYPE_CHECKING

from .base import Step
from .context import _Context
from .scaling import _ACCEL_HIGH, _RATE_HIGH, _RATE_LOW, _rates_exponent
from .specialize import plan_body, propagate, TABLES, Unsupported
from .state import JointMotion
from .trust import floor_limits, trust_limits, TRUST_TEST, wrapped_angle

if TYPE_CHECKING:
    from .graph import JointType
    from .mechanism import Scene

__all__ = ['ARRAY', 'Array', 'ArrayFunction', 'COMPILE_STEPS', 'NotCompiled', 'RATES', 'SINGLE',
           'ScenePlan', 'Single', 'SingleFunction', 'Tick', 'TickFunction',
           'bounds_from_entries', 'compile_scene', 'refusal', 'scene_plan']

#: Scenes of more steps than this are not compiled for ``mk.solve``'s paths (the default
#: ``max_steps`` of :class:`Single` and :class:`Array`): compiling grows faster than the
#: steps (100 dyads about 3 s, 1,000 about 50 s), more than a scene solved a few thousand
#: times saves. The node's tick compiles them (in the background).
COMPILE_STEPS = 128

#: Crank rates solved unscaled: ``low <= |omega| <= high`` and ``|alpha| <= accel_high``
#: (1/s, 1/s^2); outside, the general solver rescales time.
RATES = (_RATE_LOW, _RATE_HIGH, _ACCEL_HIGH)

#: ``single(theta, omega, alpha, max_error, turns) -> (joints, points, measures, entries)``
#: or ``None``; see :class:`Single`.
SingleFunction = Callable[[float, float, float, float, int],
                          tuple[dict[str, JointMotion], dict[str, tuple[complex, ...]],
                                dict[str, float], tuple[Any, ...]] | None]
#: ``array(theta, omega, alpha, turns, ctx) -> None``; see :class:`Array`.
ArrayFunction = Callable[[Any, Any, Any, Any, Any], None]
#: ``tick(theta, omega, alpha, max_error, turns) -> (values, smallest near-singularity
#: measure)``; ``theta + 2 pi turns`` is the crank angle counted from the start. See
#: :class:`Tick`.
TickFunction = Callable[[Any, Any, Any, float, int], tuple[list[float], float]]
#: A point's frame for the tick: (origin point, joint whose angle it takes or ``None``,
#: the fixed angle in rad where that is ``None``).
FrameSpec = tuple[str, str | None, float]


@dataclass(frozen=True)
class NotCompiled:
    """Why a scene was not compiled for a target: the caller keeps the general path.

    Falsy, so that ``if compiled:`` reads "a function was compiled".

    Attributes
    ----------
    reason : str
        One line, e.g. ``'step RRR C: kernel uses `for` (not in the kernel subset)'``.
    """

    reason: str

    def __bool__(self) -> bool:
        """Return False: nothing was compiled."""
        return False

    def __str__(self) -> str:
        """Return the reason."""
        return self.reason


@dataclass(frozen=True)
class Single:
    """``mk.solve``'s single-angle path: one crank at a float angle.

    The function ``single(theta, omega, alpha, max_error, turns)`` takes the
    crank angle, speed and acceleration (floats: rad, rad/s, rad/s^2), the
    tolerance and whole turns (an int), and returns ``(joints, points,
    measures, entries)``: the :class:`.JointMotion` of every reported joint,
    (position, velocity, acceleration) of every reported point as complex
    numbers, the near-singularity measures, and the context entries of the
    reported joints then points (:func:`bounds_from_entries`). It raises as the
    general path does where a step cannot close, and returns ``None`` for the
    general path to decide: a bound beyond the quick trust test, or rates the
    general path rescales.

    Attributes
    ----------
    max_steps : int or None
        More steps than this are not compiled (``None``: any number).
    """

    max_steps: int | None = COMPILE_STEPS


@dataclass(frozen=True)
class Array:
    """``mk.solve``'s array path: one crank at an array of angles.

    The function ``array(theta, omega, alpha, turns, ctx)`` does what running
    the crank's and every step's ``run`` on ``ctx`` (a vector
    :class:`._Context`) does: the same NumPy operations in the same order,
    without the dispatch, the dictionaries and the attribute reads between
    them; it masks and records failures on ``ctx`` as the steps do, leaves
    every value in ``ctx``'s tables and each kind's sum of the reported bounds
    in ``ctx.sums`` (one row a kind, for the quick judgement).

    Attributes
    ----------
    rates : (float, float) or None
        The crank's speed and acceleration (rad/s, rad/s^2) the function is
        for alone, or ``None`` for any. With rates, it ignores its ``omega`` and
        ``alpha`` arguments (the same values as 0-d arrays) and folds what they
        make into constants: the same numbers (a product of two floats is that
        of two 0-d arrays of them).
    max_steps : int or None
        More steps than this are not compiled (``None``: any number).
    """

    rates: tuple[float, float] | None = None
    max_steps: int | None = COMPILE_STEPS


@dataclass(frozen=True)
class Tick:
    """The node's tick: the values of its messages at one instant, in one flat list.

    The function ``tick(theta, omega, alpha, max_error, turns=0)`` returns
    ``(values, measure)``: ``values`` is ``[positions of the joints..., their
    velocities..., their accelerations..., x, y of every point's position...,
    of every velocity..., of every acceleration..., x, y, angle of every
    frame...]`` and ``measure`` the smallest near-singularity measure (inf if
    none). A scene of several drivers (or an actuator) takes one value per
    driver in ``theta``, ``omega`` and ``alpha`` (sequences, as ``mk.solve``).
    It raises as ``mk.solve`` does; an instant it cannot settle itself (rates
    the general solver rescales, a bound beyond the quick trust test, a
    several-driver instant that fails a check) is answered by ``fallback``.

    Attributes
    ----------
    joints, points : tuple of str
        The joints and points whose values the function returns, in order
        (among the scene's outputs).
    frames : tuple of (origin point, angle joint or None, fixed angle)
        Frames whose pose (x, y of the origin, angle) follows the values.
    fallback : callable
        A function of the same signature and answers (the general solver's),
        called for the instants the compiled function hands over.
    """

    joints: tuple[str, ...]
    points: tuple[str, ...]
    frames: tuple[FrameSpec, ...]
    fallback: TickFunction


#: The targets with their defaults.
SINGLE = Single()
ARRAY = Array()


@dataclass(frozen=True)
class ScenePlan:
    """A scene's compiled plan as the compiler sees it.

    Attributes
    ----------
    ground : mapping of str to tuple
        Every ground point's context entry ``(p, v, a, bounds...)``.
    crank : object
        The first driver's step; ``run(ctx, theta, omega, alpha)``.
    steps : tuple of Step
        The steps in solve order.
    joint_types : dict of str to str
        The reported joints and their types (:class:`~.graph.JointType`).
    reported : dict of str to tuple of str
        Per context table (``points``, ``links``, ``sliders``), the reported
        names the trust test judges (:data:`.trust.TRUST_TEST`).
    size, crank_length : float
        The mechanism's size and the crank's length, m (the trust test's scales).
    drivers : tuple
        Every driver's step, in scene order (``crank`` is the first); a scene
        with several (or an actuator) takes one value per driver.
    driver_limits : callable or None
        For several drivers: ``(tol, speeds, accels) ->`` the quick trust
        test's six limits from every driver's floors
        (:func:`.trust.trust_limits`' order); ``None`` for one crank.
    """

    ground: Mapping[str, tuple[Any, ...]]
    crank: Any
    steps: tuple[Step, ...]
    joint_types: dict[str, JointType]
    reported: dict[str, tuple[str, ...]]
    size: float
    crank_length: float
    drivers: tuple[Any, ...] = ()
    driver_limits: Callable[[float, Any, Any], tuple[float, ...]] | None = None


def scene_plan(scene: Scene) -> ScenePlan:
    """Return ``scene``'s compiled plan as the compiler sees it."""
    solver = scene._solver
    plan = solver.run_plan

    def driver_limits(tol: float, speeds: Any, accels: Any) -> tuple[float, ...]:
        return floor_limits(tol, solver.size, solver.floors(speeds, accels))

    return ScenePlan(dict(solver.ground), plan.crank, plan.steps, dict(plan.joint_types),
                     {'points': solver.out_points, 'links': solver.out_links,
                      'sliders': solver.out_sliders}, solver.size, solver.crank_length,
                     plan.drivers, None if solver.single else driver_limits)


@overload
def compile_scene(scene: Scene, target: Single) -> SingleFunction | NotCompiled: ...


@overload
def compile_scene(scene: Scene, target: Array) -> ArrayFunction | NotCompiled: ...


@overload
def compile_scene(scene: Scene, target: Tick) -> TickFunction | NotCompiled: ...


def compile_scene(scene: Scene, target: Single | Array | Tick
                  ) -> SingleFunction | ArrayFunction | TickFunction | NotCompiled:
    """Return ``scene``'s solve compiled for ``target``, or why it is not.

    Parameters
    ----------
    scene : Scene
        The mechanism.
    target : Single, Array or Tick
        What the function is for (see each); :data:`SINGLE` and :data:`ARRAY`
        are ``mk.solve``'s two paths with their defaults.

    Returns
    -------
    callable or NotCompiled
        The compiled function, or a :class:`NotCompiled` whose ``reason`` says
        in one line why the caller keeps the general path.
    """
    reason = refusal(scene, target)
    if reason is not None:
        return NotCompiled(reason)
    plan = scene_plan(scene)
    try:
        if isinstance(target, Single):
            return _single(scene, plan)
        if isinstance(target, Array):
            return _array(scene, plan, target.rates)
        if plan.driver_limits is not None:
            return _tick_drivers(scene, plan, target)
        return _tick(scene, plan, target)
    except Unsupported as unsupported:
        return NotCompiled(unsupported.reason)


def refusal(scene: Scene, target: Single | Array | Tick) -> str | None:
    """Return why ``scene`` is not compiled for ``target`` before its kernels are read, or None."""
    solver = scene._solver
    if solver.shift:
        return (f'scene rescaled: its size {solver.size:.3g} m is beyond 2**60 of 1 m (its '
                'lengths are solved scaled by a power of two)')
    rubs = solver.run_plan.rubs
    if rubs:
        return (f'pins to bound: the rubbing velocities at {", ".join(r.point for r in rubs)} '
                "are the general path's")
    if isinstance(target, Tick):
        return None
    if solver.levers:
        return (f"an intermittent lever's engagement is reported "
                f'({", ".join(solver.levers)}): the general path\'s')
    if not solver.single:
        names = solver.driver_names
        drivers = (f'its driver {names[0]} is not a crank' if len(names) == 1
                   else f'{len(names)} drivers ({", ".join(names)})')
        return (f"{drivers}: mk.solve compiles one crank's paths alone (the node's tick "
                'compiles any drivers)')
    steps = len(solver.run_plan.steps)
    if target.max_steps is not None and steps > target.max_steps:
        return (f'more than {target.max_steps} steps ({steps}): compiling would cost more '
                'than the solves it speeds up')
    return None


def bounds_from_entries(joints: tuple[str, ...], points: tuple[str, ...],
                        entries: tuple[Any, ...]) -> tuple[dict[str, Any], dict[str, Any]]:
    """Return the joints' and points' bounds from the entries a compiled single solve returned.

    ``entries`` holds the context entry of each joint, then of each point, in
    the order of the names: the bounds are their last three values, as the
    solve takes them from a context.
    """
    count = len(joints)
    return ({name: entry[3:] for name, entry in zip(joints, entries[:count], strict=True)},
            {name: entry[3:] for name, entry in zip(points, entries[count:], strict=True)})


def check(theta: float, turns: int, *args: Any, **kwargs: Any) -> None:
    """Raise as a step's ``ctx.check`` does on one crank angle (its failure path)."""
    _Context(theta, False, turns).check(*args, **kwargs)


def check_margin(theta: float, turns: int, *args: Any, **kwargs: Any) -> None:
    """Raise as a step's ``ctx.check_margin`` does on one crank angle."""
    _Context(theta, False, turns).check_margin(*args, **kwargs)


def shown(theta: float, turns: int) -> Any:
    """Return the crank angle counted from the start, as messages show it (``ctx.shown``)."""
    return _Context(theta, False, turns).shown


def trust_lines(plan: ScenePlan, names: Mapping[str, str], limits: str,
                otherwise: str) -> list[str]:
    """Return the source lines of the quick trust test on a compiled plan's reported values.

    ``limits`` is the expression giving the six limits (:func:`.trust.trust_limits`,
    or the several drivers' own); ``otherwise`` the statement run where a
    reported bound is beyond them. ``names`` maps each table entry to its local
    variable (:func:`.specialize.plan_body`). The one source of the test for
    every target, with :data:`.trust.TRUST_TEST`.
    """
    lines = [f'_l0, _l1, _l2, _l3, _l4, _l5 = {limits}']
    checks = []
    for table, _, (i, j, k) in TRUST_TEST:
        for name in plan.reported[table]:
            e = names[f'{TABLES[table]}_{name}']
            checks.append(f'{e}[3] <= _l{i} and {e}[4] <= _l{j} and {e}[5] <= _l{k}')
    if checks:
        lines.append(f'if not ({" and ".join(checks)}):')
        lines.append(f'    {otherwise}')
    return lines


def _function(name: str, parameters: Sequence[str], body: list[ast.stmt],
              defaults: Sequence[Any] = ()) -> ast.FunctionDef:
    """Return ``def name(parameters): body`` (the last parameters with ``defaults``)."""
    return ast.FunctionDef(
        name=name, args=ast.arguments(
            posonlyargs=[], args=[ast.arg(a) for a in parameters], kwonlyargs=[],
            kw_defaults=[], defaults=[ast.Constant(d) for d in defaults]),
        body=body, decorator_list=[], returns=None)


def _made(functions: list[ast.stmt], label: str, namespace: dict[str, Any], name: str) -> Any:
    """Return the function ``name`` defined by ``functions`` in ``namespace``."""
    module = ast.fix_missing_locations(ast.Module(body=functions, type_ignores=[]))
    exec(module_code(module, label), namespace)  # noqa: S102
    return namespace[name]


# --- compiling off this process's GIL --------------------------------------------
# Python's compile() is one C call that holds the GIL throughout: 0.26 s for a 100-dyad
# strip's tick (110,000 nodes) on an idle 2-core machine, 0.36 to 0.47 s beside two CPU
# hogs. The node compiles such a tick in a background thread while its tick thread
# publishes; for that long, the tick thread could not run a line. So a large module is
# compiled by a child process (the same interpreter, ``sys.executable``) from its syntax
# tree sent as marshal data: one record a statement, each encoded in Python here (which
# lets other threads run between bytecodes), and the code object comes back marshalled.
# The same tree compiled with the same flags by the same interpreter is the same code
# object (``test_compiler`` compares them); where the child cannot answer, this process
# compiles the tree itself.

#: Modules whose functions hold more statements than this are compiled in a child process
#: (:func:`module_code`). A statement of the compiled kernels is about 22 syntax-tree nodes
#: and compile() takes about 2.4 us a node on an idle machine, so a module this size holds
#: the GIL about 25 ms, about what starting the child costs. (The packaged scenes' ticks
#: hold 43 to 184 statements; a 100-dyad strip's, 5,017.)
APART_STATEMENTS = 500
#: The compiler flags of every compiled module: this module's own ``from __future__ import
#: annotations`` (what compile() inherited here before modules were compiled apart), given
#: explicitly to both compiles.
COMPILE_FLAGS = annotations.compiler_flag

#: The child's program: read the header and each function's statements (marshal records),
#: rebuild the tree, compile it, write (version, marshalled code). Started with -I -S:
#: it imports nothing but ast and marshal.
_CHILD = """
import ast, marshal, sys
def node(data):
    if isinstance(data, list):
        return [node(item) for item in data]
    if not isinstance(data, tuple):
        return data
    name, fields, attributes = data
    cls = getattr(ast, name)
    made = cls()
    if cls is ast.Constant:
        made.value, made.kind = fields
    else:
        for field, value in zip(cls._fields, fields, strict=True):
            setattr(made, field, node(value))
    for attribute, value in zip(cls._attributes, attributes, strict=True):
        setattr(made, attribute, value)
    return made
source = sys.stdin.buffer
version, label, flags, count = marshal.load(source)
functions = []
for _ in range(count):
    function, statements = marshal.load(source)
    function = node(function)
    function.body = [node(marshal.load(source)) for _ in range(statements)]
    functions.append(function)
module = ast.Module(body=functions, type_ignores=[])
code = compile(module, label, 'exec', flags, True)
sys.stdout.buffer.write(marshal.dumps((sys.hexversion, code)))
"""


def module_code(module: ast.Module, label: str) -> Any:
    """Return ``module`` compiled (named ``label``), by a child process when it is large.

    A module whose functions hold more than :data:`APART_STATEMENTS` statements
    is compiled by :func:`compiled_apart`, so that this process's other threads
    run meanwhile; where that answers ``None``, and for a smaller module, by
    compile() here. Both give the same code object.
    """
    statements = sum(len(f.body) for f in module.body if isinstance(f, ast.FunctionDef))
    if statements > APART_STATEMENTS:
        code = compiled_apart(module, label)
        if code is not None:
            return code
    return compile(module, label, 'exec', COMPILE_FLAGS, True)


def _encoded(node: Any) -> Any:
    """Return a syntax tree as marshal data: a node as (class name, fields, attributes)."""
    if isinstance(node, ast.AST):
        attributes = tuple(getattr(node, a, None) for a in node._attributes)
        if isinstance(node, ast.Constant):     # its value is data, never a node
            return 'Constant', (node.value, node.kind), attributes
        return (type(node).__name__, tuple(_encoded(getattr(node, f, None)) for f in node._fields),
                attributes)
    if isinstance(node, list):
        return [_encoded(item) for item in node]
    return node


def compiled_apart(module: ast.Module, label: str) -> Any:
    """Return ``module`` compiled by a child process, or ``None`` where it cannot answer.

    The module holds function definitions (what the compiler makes). Each
    statement of their bodies is one marshal record, so that no single step
    here holds the GIL for long; waiting for the child releases it. ``None``
    (the caller compiles here) where the child cannot be started, fails, or is
    not this interpreter's version; a tree compile() refuses then raises here,
    as it would have.
    """
    functions = [f for f in module.body if isinstance(f, ast.FunctionDef)]
    if not sys.executable or len(functions) != len(module.body):
        return None
    records = [marshal.dumps((sys.hexversion, label, COMPILE_FLAGS, len(functions)))]
    for function in functions:
        head = ('FunctionDef', tuple([] if f == 'body' else _encoded(getattr(function, f, None))
                                     for f in function._fields),
                tuple(getattr(function, a, None) for a in function._attributes))
        records.append(marshal.dumps((head, len(function.body))))
        records += [marshal.dumps(_encoded(statement)) for statement in function.body]
    try:
        # A session of its own: a Ctrl-C meant for this process's group is not its.
        child = subprocess.run([sys.executable, '-I', '-S', '-c', _CHILD],
                               input=b''.join(records), capture_output=True, check=False,
                               start_new_session=True)
    except (OSError, ValueError):     # no such interpreter, out of processes: compiled here
        return None
    if child.returncode != 0:
        return None
    try:
        version, code = marshal.loads(child.stdout)
    except (EOFError, ValueError, TypeError):
        return None
    return code if version == sys.hexversion and isinstance(code, CodeType) else None


def _single(scene: Scene, plan: ScenePlan) -> SingleFunction:
    """Return ``scene``'s single-angle solve (:class:`Single`)."""
    namespace: dict[str, Any] = {
        '_ctx_check': check, '_ctx_check_margin': check_margin,
        '_shown': shown, '_trust_limits': trust_limits, '_JM': JointMotion,
    }
    names: dict[str, str] = {}
    body = plan_body(plan, names, namespace, propagated=False)
    namespace['_wrapped_angle'] = wrapped_angle

    def var(table: str, name: str) -> str:
        return names[f'{table}_{name}']

    lines = trust_lines(plan, names, f'_trust_limits(tol, omega, alpha, {plan.size!r}, '
                        f'{plan.crank_length!r})', 'return None')
    joints, entries = [], []
    for name, kind in plan.joint_types.items():
        namespace[f'_{kind}'] = kind  # (the JointType itself: a constant cannot be one)
        e = var(TABLES[kind.table], name)
        position = f'_wrapped_angle({e}[0])' if kind.angular else f'{e}[0]'
        joints.append(f'{name!r}: _JM(_{kind}, {position}, {e}[1], {e}[2])')
        entries.append(e)
    points = []
    for name in scene._solver.plan.output_points:
        e = var('P', name)
        points.append(f'{name!r}: {e}[:3]')
        entries.append(e)
    measures = [f'{key[2:]!r}: {local}' for key, local in names.items() if key.startswith('M_')]
    lines.append(f'return ({{{", ".join(joints)}}}, {{{", ".join(points)}}}, '
                 f'{{{", ".join(measures)}}}, ({", ".join(entries)}{"," if entries else ""}))')
    low, high, accel_high = RATES
    guard = ast.parse(f'if not ({low!r} <= abs(omega) <= {high!r} '
                      f'and abs(alpha) <= {accel_high!r}):\n'
                      '    return None').body
    function = _function('single', ('theta', 'omega', 'alpha', 'tol', 'turns'), guard + propagate(
        body + ast.parse('\n'.join(lines)).body, namespace, set(), vector=False))
    single: SingleFunction = _made([function], f'<compiled solve of {scene.name}>', namespace,
                                   'single')
    return single


class _ScalarRates(ast.NodeTransformer):
    """``omega.ndim`` and ``alpha.ndim`` as 0: the rates are numbers (:class:`Array` ``rates``)."""

    def visit_Attribute(self, node: ast.Attribute) -> ast.AST:
        self.generic_visit(node)
        if (node.attr == 'ndim' and isinstance(node.value, ast.Name)
                and node.value.id in ('omega', 'alpha')):
            return ast.copy_location(ast.Constant(0), node)
        return node


def _array(scene: Scene, plan: ScenePlan, rates: tuple[float, float] | None) -> ArrayFunction:
    """Return ``scene``'s array path (:class:`Array`), for ``rates`` alone where given."""
    namespace: dict[str, Any] = {}
    names: dict[str, str] = {}
    body = plan_body(plan, names, namespace, vector=True, propagated=False)
    parameters = ('theta', 'omega', 'alpha', 'turns', 'ctx')
    if rates is not None:
        speed, accel = (float(x) for x in rates)
        parameters = ('theta', '_omega', '_alpha', 'turns', 'ctx')
        body = [*ast.parse(f'omega = {speed!r}\nalpha = {accel!r}').body,
                *(cast(ast.stmt, _ScalarRates().visit(stmt)) for stmt in body)]
    tables: dict[str, list[str]] = {prefix: [] for prefix in TABLES.values()}
    for key, local in names.items():
        prefix, name = key.split('_', 1)
        tables[prefix].append(f'{name!r}: {local}')
    lines = [f'ctx.{table} = {{{", ".join(tables[prefix])}}}'
             for table, prefix in TABLES.items()]
    sums: dict[str, list[str]] = {}
    for table, name, _, _, kinds in scene._solver.outputs:
        local = names[f'{TABLES[table]}_{name}']
        for index, kind in enumerate(kinds, 3):
            sums.setdefault(kind, []).append(f'{local}[{index}]')
    # Each kind's sum written into its row of one table (its last addition's ``out``), so
    # that one reduction gives every kind's largest sum (solve._within).
    lines.append(f'_sums = np.empty(({len(sums)}, *np.shape(theta)))')
    for row, terms in enumerate(sums.values()):
        if len(terms) == 1:
            lines.append(f'_sums[{row}] = {terms[0]}')
        else:
            lines.append(f'np.add({" + ".join(terms[:-1])}, {terms[-1]}, out=_sums[{row}])')
    lines.append(f'ctx.sums = ({tuple(sums)!r}, _sums)')
    function = _function('array', parameters, propagate(
        body + ast.parse('\n'.join(lines)).body, namespace, set()))
    array: ArrayFunction = _made([function], f'<compiled array solve of {scene.name}>',
                                 namespace, 'array')
    return array


def _values_line(plan: ScenePlan, names: dict[str, str], target: Tick) -> str:
    """Return the tick's ``return [values...], measure`` line (:class:`Tick`'s order)."""
    kinds = dict(plan.joint_types)
    values = []
    for index in range(3):
        for name in target.joints:
            e = names[f'{TABLES[kinds[name].table]}_{name}']
            values.append(f'_wrapped_angle({e}[0])' if index == 0 and kinds[name].angular
                          else f'{e}[{index}]')
    for index in range(3):
        for name in target.points:
            e = names[f'P_{name}']
            values += [f'{e}[{index}].real', f'{e}[{index}].imag']
    for origin, angle_of, angle in target.frames:
        e = names[f'P_{origin}']
        values += [f'{e}[0].real', f'{e}[0].imag']
        values.append(repr(angle) if angle_of is None
                      else f'_wrapped_angle({names[f"L_{angle_of}"]}[0])')
    measures = [names[key] for key in names if key.startswith('M_')]
    measure = f'min({", ".join(measures)})' if len(measures) > 1 else (
        measures[0] if measures else 'inf')
    return f'return [{", ".join(values)}], {measure}'


def _tick(scene: Scene, plan: ScenePlan, target: Tick) -> TickFunction:
    """Return the tick of a scene driven by one crank (:class:`Tick`)."""
    namespace: dict[str, Any] = {
        '_ctx_check': check, '_ctx_check_margin': check_margin,
        '_shown': shown,
        '_slow': target.fallback,
        '_trust_limits': trust_limits,
        'inf': math.inf,
    }
    names: dict[str, str] = {}
    body = plan_body(plan, names, namespace, propagated=False)
    namespace['_wrapped_angle'] = wrapped_angle
    # The general solver's quick trust test (trust.trust_limits and trust.TRUST_TEST, the
    # one source of both), on the reported values.
    lines = trust_lines(plan, names, f'_trust_limits(tol, omega, alpha, {plan.size!r}, '
                        f'{plan.crank_length!r})',
                        'return _slow(theta, omega, alpha, tol, turns)')
    lines.append(_values_line(plan, names, target))
    tail = ast.parse('\n'.join(lines)).body
    low, high, accel_high = RATES
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
    function = _function('tick', ('theta', 'omega', 'alpha', 'tol', 'turns'),
                         guard + propagate(body + tail, namespace, set(), vector=False), (0,))
    tick: TickFunction = _made([function], f'<compiled tick of {scene.name}>', namespace,
                               'tick')
    return tick


class _Refused(Exception):
    """A step of a several-driver tick found it cannot close: the general solver says why."""


def _refuse(theta: Any, turns: Any, ok: Any, *args: Any, **kwargs: Any) -> None:
    """Stand in for ``ctx.check`` in a several-driver tick: hand a failure to the solver."""
    if not ok:
        raise _Refused


def _rates_shift(speeds: Any, accels: Any) -> int:
    """Return the power of two by which the general solver scales time for several drivers.

    0 where it solves them unscaled (what the compiled tick may answer).
    """
    return _rates_exponent(speeds, accels)


def _tick_drivers(scene: Scene, plan: ScenePlan, target: Tick) -> TickFunction:
    """Return the tick of a scene with several drivers (or an actuator).

    The same specialized kernels as :func:`_tick`'s, each driver's on its own
    value: ``tick(positions, speeds, accels, max_error, turns=0)`` takes one
    value per driver (sequences, as :func:`mech_kinematics.solve`), and a
    scene of one driver (an actuator) its bare values, as ``mk.solve`` and
    the node give them (a sequence there is handed to the fallback). An
    instant the general solver would rescale in time, refuse (a failed check
    raises inside, and the fallback is asked for its reason, so the message
    names every driver's position) or judge beyond the quick trust test is
    handed to the fallback.
    """
    count = len(plan.drivers)
    one = count == 1
    namespace: dict[str, Any] = {
        '_ctx_check': _refuse, '_ctx_check_margin': _refuse, '_Refused': _Refused,
        '_shown': shown, '_slow': target.fallback,
        '_driver_limits': plan.driver_limits, '_rates_shift': _rates_shift,
        'inf': math.inf, '_float': float, '_SEQUENCE': (list, tuple),
    }
    names: dict[str, str] = {}
    lines = [f'{x}_0 = _float({arg})' if one else
             f'{", ".join(f"{x}_{k}" for k in range(count))}, = '
             f'({", ".join(f"_float({arg}[{k}])" for k in range(count))},)'
             for x, arg in (('x', 'theta'), ('v', 'omega'), ('a', 'alpha'))]
    body: list[ast.stmt] = ast.parse('\n'.join(lines)).body
    body += plan_body(plan, names, namespace, driver_values=[
        (f'x_{k}', f'v_{k}', f'a_{k}') for k in range(count)], propagated=False)
    namespace['_wrapped_angle'] = wrapped_angle
    tail = trust_lines(
        plan, names, f'_driver_limits(tol, [{", ".join(f"v_{k}" for k in range(count))}], '
        f'[{", ".join(f"a_{k}" for k in range(count))}])',
        'return _slow(theta, omega, alpha, tol, turns)')
    tail.append(_values_line(plan, names, target))
    parameters = ('theta', 'omega', 'alpha', 'tol', 'turns')
    inner = _function('_tick', parameters, propagate(
        body + ast.parse('\n'.join(tail)).body, namespace, set(), vector=False), (0,))
    served = (  # the instants the fallback serves
        'isinstance(theta, _SEQUENCE) or isinstance(omega, _SEQUENCE) or '
        'isinstance(alpha, _SEQUENCE) or _rates_shift((omega,), (alpha,))' if one else
        'not (isinstance(theta, _SEQUENCE) and isinstance(omega, _SEQUENCE) '
        'and isinstance(alpha, _SEQUENCE)) or '
        f'len(theta) != {count} or len(omega) != {count} or len(alpha) != {count} or '
        '_rates_shift(omega, alpha)')
    outer = ast.parse(
        'def tick(theta, omega, alpha, tol, turns=0):\n'
        f'    if {served}:\n'
        '        return _slow(theta, omega, alpha, tol, turns)\n'
        '    try:\n'
        '        return _tick(theta, omega, alpha, tol, turns)\n'
        '    except _Refused:\n'
        '        return _slow(theta, omega, alpha, tol, turns)\n').body[0]
    tick: TickFunction = _made([inner, outer], f'<compiled tick of {scene.name}>', namespace,
                               'tick')
    return tick
