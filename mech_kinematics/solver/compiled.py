# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The solver's own compiled paths: a scene's solve as one straight-line function.

:func:`mech_kinematics.solve` runs every step's kernel through the
dictionaries of a context. Once a scene has been solved :data:`COMPILE_AFTER`
times at single angles (:data:`ARRAY_COMPILE_AFTER` times on arrays), it
compiles the scene's kernels for that path instead
(by :mod:`.specialize`, as the node's tick is compiled):

- the single-angle path (:func:`compile_single`) into one function that
  returns what a :class:`.State` holds: the reported joints, points,
  measures and the entries their bounds come from;
- the array path (:func:`compile_array`) into one function of NumPy
  operations that fills a vector context as the steps would.

The same operations run in the same order on the same values, so the
answers, their bounds and the errors raised are those of the general path
(``test_compiled`` compares them on every packaged scene and the extreme
suite). The single-angle function answers ``None`` where the general path
must decide: a bound beyond the quick trust test (:func:`.solve.trust_limits`:
the general path refuses with the full reason, or answers), a crank rate it
would rescale. Scenes neither path compiles (rescaled lengths, pins to bound,
an intermittent lever whose engagement the state reports, a kernel outside the
subset, more than :data:`COMPILE_STEPS` steps) keep the general path.

Large array solves also keep freed memory for the next one
(:func:`keep_freed_memory`).
"""

from __future__ import annotations

import ast
from collections.abc import Callable
import ctypes
import os
import platform
from typing import Any, cast, TYPE_CHECKING

from .specialize import plan_body, propagate, TABLES, Unsupported
from .state import JointMotion

if TYPE_CHECKING:
    from .mechanism import Scene

__all__ = ['ARRAY_COMPILE_AFTER', 'ArrayFunction', 'COMPILE_AFTER', 'COMPILE_STEPS', 'KEEP_FREED',
           'LARGE_BATCH', 'SingleFunction', 'compile_array', 'compile_single',
           'keep_freed_memory']

#: Single-angle solves of one scene on the general path before it is compiled: a
#: compilation (constants folded) costs about as much as a few thousand single-angle
#: solves, so a scene solved a few hundred times or less
#: (most scenes a test builds) is never compiled.
COMPILE_AFTER = 256
#: Array solves of one scene before its array path is compiled: an array solve costs
#: what a few dozen single angles do, or more.
ARRAY_COMPILE_AFTER = 16

#: Scenes of more steps than this keep the general path here: compiling grows faster
#: than the steps (100 dyads about 3 s, 1,000 about 50 s), more than a scene solved a
#: few thousand times saves. The node's tick compiles them in the background.
COMPILE_STEPS = 128

#: ``array(theta, omega, alpha, turns, ctx) -> None``; see :func:`compile_array`.
ArrayFunction = Callable[[Any, Any, Any, Any, Any], None]

#: ``single(theta, omega, alpha, max_error, turns) -> (joints, points, measures, entries)``
#: or ``None``; see :func:`compile_single`.
SingleFunction = Callable[[float, float, float, float, int],
                          tuple[dict[str, JointMotion], dict[str, tuple[complex, ...]],
                                dict[str, float], tuple[Any, ...]] | None]


def bounds_from_entries(joints: tuple[str, ...], points: tuple[str, ...],
                        entries: tuple[Any, ...]) -> tuple[dict[str, Any], dict[str, Any]]:
    """Return the joints' and points' bounds from the entries a compiled solve returned.

    ``entries`` holds the context entry of each joint, then of each point, in
    the order of the names: the bounds are their last three values, as
    :func:`.solve._table_bounds` takes them from a context.
    """
    count = len(joints)
    return ({name: entry[3:] for name, entry in zip(joints, entries[:count], strict=True)},
            {name: entry[3:] for name, entry in zip(points, entries[count:], strict=True)})


def compile_single(scene: Scene) -> SingleFunction | None:
    """Return ``scene``'s single-angle solve as one straight-line function, or ``None``.

    The function takes the crank angle, speed and acceleration (floats, rad,
    rad/s, rad/s^2), the tolerance ``max_error`` and whole turns (an int), and
    returns ``(joints, points, measures, entries)``: the state's
    :class:`.JointMotion` of every reported joint, (position, velocity,
    acceleration) of every reported point as complex numbers, the
    near-singularity measures, and the context entries of the reported joints
    then points (:func:`bounds_from_entries`). It raises as the general path
    does where a step cannot close, and returns ``None`` for the general path
    to decide (see the module).
    """
    from . import tick as hooks     # the tick's hooks import the solve this serves

    plan = hooks.tick_plan(scene)
    solver = scene._solver
    if not plan.compilable or solver.levers or plan.driver_limits is not None \
            or len(plan.steps) > COMPILE_STEPS:
        # An intermittent lever's state, several drivers' (the node's tick compiles those),
        # or a scene too long to be worth compiling here
        return None
    namespace: dict[str, Any] = {
        '_ctx_check': hooks.check, '_ctx_check_margin': hooks.check_margin,
        '_shown': hooks.shown, '_trust_limits': hooks.trust_limits, '_JM': JointMotion,
    }
    names: dict[str, str] = {}
    try:
        body = plan_body(plan, names, namespace, propagated=False)
    except Unsupported:
        return None
    namespace['_wrapped_angle'] = hooks.wrapped_angle

    def var(table: str, name: str) -> str:
        return names[f'{table}_{name}']

    lines = hooks.trust_lines(plan, names, f'_trust_limits(tol, omega, alpha, {plan.size!r}, '
                              f'{plan.crank_length!r})', 'return None')
    joints, entries = [], []
    for name, kind in plan.joint_types.items():
        namespace[f'_{kind}'] = kind  # (the JointType itself: a constant cannot be one)
        e = var(TABLES[kind.table], name)
        position = f'_wrapped_angle({e}[0])' if kind.angular else f'{e}[0]'
        joints.append(f'{name!r}: _JM(_{kind}, {position}, {e}[1], {e}[2])')
        entries.append(e)
    points = []
    for name in solver.plan.output_points:
        e = var('P', name)
        points.append(f'{name!r}: {e}[:3]')
        entries.append(e)
    measures = [f'{key[2:]!r}: {local}' for key, local in names.items() if key.startswith('M_')]
    lines.append(f'return ({{{", ".join(joints)}}}, {{{", ".join(points)}}}, '
                 f'{{{", ".join(measures)}}}, ({", ".join(entries)}{"," if entries else ""}))')
    low, high, accel_high = hooks.RATES
    guard = ast.parse(f'if not ({low!r} <= abs(omega) <= {high!r} '
                      f'and abs(alpha) <= {accel_high!r}):\n'
                      '    return None').body
    function = ast.FunctionDef(
        name='single', args=ast.arguments(
            posonlyargs=[], args=[ast.arg(a) for a in ('theta', 'omega', 'alpha', 'tol',
                                                       'turns')],
            kwonlyargs=[], kw_defaults=[], defaults=[]),
        body=guard + propagate(body + ast.parse('\n'.join(lines)).body, namespace, set(),
                               vector=False), decorator_list=[],
        returns=None)
    module = ast.fix_missing_locations(ast.Module(body=[function], type_ignores=[]))
    exec(compile(module, f'<compiled solve of {scene.name}>', 'exec'), namespace)  # noqa: S102
    single: SingleFunction = namespace['single']
    return single


class _ScalarRates(ast.NodeTransformer):
    """``omega.ndim`` and ``alpha.ndim`` as 0: the rates are numbers (:func:`compile_array`)."""

    def visit_Attribute(self, node: ast.Attribute) -> ast.AST:
        self.generic_visit(node)
        if (node.attr == 'ndim' and isinstance(node.value, ast.Name)
                and node.value.id in ('omega', 'alpha')):
            return ast.copy_location(ast.Constant(0), node)
        return node


def compile_array(scene: Scene, rates: tuple[float, float] | None = None
                  ) -> ArrayFunction | None:
    """Return the steps of ``scene``'s array path as one straight-line function, or ``None``.

    The function ``array(theta, omega, alpha, turns, ctx)`` does what running
    the crank's and every step's ``run`` on ``ctx`` (a vector
    :class:`._Context`) does: the same NumPy operations in the same order,
    without the dispatch, the dictionaries and the attribute reads between
    them; it masks and records failures on ``ctx`` as the steps do, and leaves
    every value in ``ctx``'s tables. ``None`` for the scenes
    :func:`compile_single` leaves out.

    With ``rates`` (the crank's speed and acceleration, floats: the scene's
    own, :func:`.solve.solve`'s usual array call), the function is for those
    rates alone: it ignores its ``omega`` and ``alpha`` (the same values as
    0-d arrays) and folds what they make into constants, the same numbers
    (a product of two floats is the same as of two 0-d arrays of them).
    """
    from . import tick as hooks     # the tick's hooks import the solve this serves

    plan = hooks.tick_plan(scene)
    if not plan.compilable or scene._solver.levers or plan.driver_limits is not None \
            or len(plan.steps) > COMPILE_STEPS:
        return None
    namespace: dict[str, Any] = {}
    names: dict[str, str] = {}
    try:
        body = plan_body(plan, names, namespace, vector=True, propagated=False)
    except Unsupported:
        return None
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
    function = ast.FunctionDef(
        name='array', args=ast.arguments(
            posonlyargs=[], args=[ast.arg(a) for a in parameters],
            kwonlyargs=[], kw_defaults=[], defaults=[]),
        body=propagate(body + ast.parse('\n'.join(lines)).body, namespace, set()),
        decorator_list=[], returns=None)
    module = ast.fix_missing_locations(ast.Module(body=[function], type_ignores=[]))
    exec(compile(module, f'<compiled array solve of {scene.name}>', 'exec'),  # noqa: S102
         namespace)
    array: ArrayFunction = namespace['array']
    return array


#: An array solve of at least this many angles keeps freed memory for the next
#: (:func:`keep_freed_memory`).
LARGE_BATCH = 4096
#: The C library's settings for that: (``M_TRIM_THRESHOLD``, bytes of free memory kept
#: at the top of the heap), (``M_MMAP_THRESHOLD``, the size from which a block is mapped
#: on its own, returned to the system when freed: glibc's own upper limit, 32 MiB).
KEEP_FREED = ((-1, 256 << 20), (-3, 32 << 20))
_kept: list[bool] = []


def keep_freed_memory() -> bool:
    """Let the C library keep freed memory for reuse, once per process; return whether it does.

    An array solve over many angles makes a few hundred temporary arrays of
    the batch's size, and glibc by default maps each large one on its own and
    trims the heap once they are freed, so the next solve of the same size
    pays a page fault on every 4 KiB of every temporary again: at 100,000
    angles that is most of its time. With :data:`KEEP_FREED` the freed blocks
    stay in the heap and the next solve's temporaries reuse them, as buffers
    reused across calls would, and no returned array ever shares memory with
    another call's (each is still a fresh allocation). The process keeps up to
    256 MiB of freed memory. Elsewhere than glibc (``platform.libc_ver``), or
    with the environment variable ``MECH_KINEMATICS_KEEP_FREED_MEMORY=0`` (for a
    process whose allocator settings are its own), it does nothing and returns
    False.
    """
    if not _kept:
        done = False
        if (platform.libc_ver()[0] == 'glibc'
                and os.environ.get('MECH_KINEMATICS_KEEP_FREED_MEMORY', '1') != '0'):
            try:
                libc = ctypes.CDLL(None)
                done = all(libc.mallopt(param, value) == 1 for param, value in KEEP_FREED)
            except (OSError, AttributeError):
                done = False
        _kept.append(done)
    return _kept[0]
