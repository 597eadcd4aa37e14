# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""One instant's forces written out as one straight-line function per scene, or why not.

:meth:`.forces.Dynamics.forces` builds each group's statics from dictionaries
of the graph at every instant and solves it with a loop over a list of
lists: at one instant, 300 to 1,400 us where the compiled kinematic tick
takes 10 (``bench/forces_bench.py``). Almost all of that does not depend on
the instant: which bodies and joints a group holds, which unknowns each
equation touches (every other entry is a structural zero), the arms, the
units of pins, the order of the groups. :func:`compile_single` writes, at
build time, the statements that remain: the bodies' inertia wrenches, each
group's nonzero entries, its Gauss-Jordan elimination with the fill-in known
(no loop, no zero touched), the a-posteriori bound of every unknown, what
each joint carries, the shaking and the tolerance tests, in plain Python
floats (for 2 to 9 unknowns they beat NumPy's per-call cost many times).

Partial pivoting picks its rows by value; a function is written for one
*pivot sequence* (the rows the general solve picked at an instant, recorded
by :func:`.forces._bounded_solve`) and checks at every step that the
general solve would pick the same row (``|pivot| >`` every earlier candidate,
``>=`` every later one). The same operations then run in the same order on
the same values as the general path (``_solve_config``, ``_bounded_solve``,
``_result``), so the answer has its bits (up to the sign of a zero: an entry
known to be zero is left out, where the general path adds ``+0.0``) and its
bounds (``test_forces_compiled``). A function returns:

- the :class:`.forces.Forces` of a valid instant;
- ``False`` where a pivot differs (the caller tries another sequence);
- ``None`` where the general path must decide: a singular or unbounded
  group, a value beyond the doubles (also where ``abs()`` of a complex
  raises ``OverflowError``, which the caller takes as None), a bound beyond
  the tolerance (the general path refuses with its reason), or NumPy
  scalars in the state.

Where a scene cannot be written out, :func:`compile_single` returns a
:class:`.compiler.NotCompiled` with the reason, one line: an intermittent
drive (its phase picks each instant's system; both are solved by the
general path). Bounds are computed with every value, never dropped.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
import math
import re
from typing import Any, cast, TYPE_CHECKING

import numpy as np

from .compiler import NotCompiled
from ..bounds import magnitude, U

if TYPE_CHECKING:
    from .forces import _Group, Dynamics

__all__ = ['SingleForces', 'compile_single']

#: The function :func:`compile_single` returns: ``(state, max_error) -> Forces | False | None``.
SingleForces = Callable[[Any, float], Any]


def _gamma(k: int) -> float:
    return k * U / (1.0 - k * U)


class _Writer:
    """The statements of one function, its temporaries and its constants."""

    def __init__(self, vector: bool) -> None:
        self.vector = vector
        self.lines: list[str] = []
        self.namespace: dict[str, Any] = {}
        self.count = 0
        self.memo: dict[Any, str] = {}
        # The functions of the target's own path: math on floats, NumPy on arrays (the
        # general path's _expi and _expi_array), constants folded with them.
        self.functions = ({'cos': np.cos, 'sin': np.sin, 'fmax': np.fmax} if vector
                          else {'cos': math.cos, 'sin': math.sin})

    def const(self, value: Any) -> str:
        """Return the name of a constant bound in the function's globals."""
        key = ('const', type(value), repr(value))
        if key not in self.memo:
            name = f'K{len(self.namespace)}'
            self.namespace[name] = value
            self.memo[key] = name
        return self.memo[key]

    def fold(self, expr: str) -> Any:
        """Return the value of ``expr`` if it reads constants only (the same operations, now)."""
        if _READS_INSTANT.search(expr):     # a temporary or the state: not worth an eval
            return _RUNTIME
        try:
            return eval(expr, {'__builtins__': {}, 'abs': abs, 'complex': complex,  # noqa: S307
                               **self.functions, **self.namespace})
        except NameError:   # it reads a value of the instant
            return _RUNTIME
        except ArithmeticError:     # left to the instant (a refusal guards it)
            return _RUNTIME

    def let(self, expr: str) -> str:
        """Emit ``tN = expr`` and return ``tN`` (or the constant it folds to)."""
        if expr.isidentifier():
            return expr
        value = self.fold(expr)
        if value is not _RUNTIME:
            if value.__class__ is float and value in (1.0, -1.0):
                return repr(value)
            return self.const(value)
        self.count += 1
        name = f't{self.count}'
        self.lines.append(f'{name} = {expr}')
        return name

    def emit(self, line: str) -> None:
        self.lines.append(line)

    def once(self, key: Any, expr: str) -> str:
        """Return a temporary holding ``expr``, emitted the first time ``key`` is asked."""
        if key not in self.memo:
            self.memo[key] = self.let(expr)
        return self.memo[key]

    def abs(self, value: str) -> str:
        """Return a temporary holding ``abs(value)``, computed once per value."""
        if value in ('1.0', '-1.0'):
            return '1.0'
        if value in ('0.0', '0j'):
            return '0.0'
        return self.once(('abs', value), f'abs({value})')

    def mul(self, a: str, b: str) -> str:
        """Return ``a * b`` written with no product by 1 or -1 (the same bits)."""
        if a in ('1.0', '-1.0'):
            a, b = b, a
        if b == '1.0':
            return a
        if b == '-1.0':
            return _neg(a)
        return f'{a} * {b}'

    def maximum(self, var: str, terms: Sequence[str], start: float | None = None) -> None:
        """Emit ``var = max(var, term)`` for each term (``var = start`` first if given).

        The constant terms are folded into one (a maximum of numbers is one of
        them whatever the order; no NaN enters: ``max`` keeps the first).
        """
        values = [self.fold(term) for term in terms]
        constants = [v for v in values if v is not _RUNTIME]
        if self.vector:     # np.fmax, in the same order
            if start is not None:
                self.emit(f'{var} = {self.const(start)}')
            for term in terms:
                self.emit(f'{var} = fmax({var}, {term})')
            return
        if start is not None:
            self.emit(f'{var} = {self.const(max([start, *constants]))}')
        elif constants:
            self.emit(f'if {self.const(max(constants))} > {var}: {var} = '
                      f'{self.const(max(constants))}')
        for term, value in zip(terms, values, strict=True):
            if value is _RUNTIME:
                if not term.isidentifier():
                    self.emit(f'a = {term}')
                    term = 'a'
                self.emit(f'if {term} > {var}: {var} = {term}')

    def refuse_unless(self, conditions: Sequence[str], answer: str = 'None') -> None:
        """Emit a return of ``answer`` unless every condition holds (arrays: mask ``ok``)."""
        conditions = [c for c in conditions if self.fold(c) is not True]
        if conditions and self.vector:
            self.emit(f'ok = ok & {" & ".join(f"({c})" for c in conditions)}')
        elif conditions:
            self.emit(f'if not ({" and ".join(conditions)}): return {answer}')

    def expi(self, angle: str) -> str:
        """Return a temporary holding the unit complex number at ``angle`` (rad)."""
        if self.vector:
            return self.let(f'cos({angle}) + 1j * sin({angle})')
        return self.let(f'complex(cos({angle}), sin({angle}))')


#: What :meth:`_Writer.fold` returns for an expression that reads the instant.
_RUNTIME = object()
#: A name only the instant defines: a temporary, the state's tables, the running maxima.
_READS_INSTANT = re.compile(r'\b(t\d+|P|PB|J|JB|S_a|S_alpha|scale|a_norm|x_norm|condition|'
                            r'force_limit|moment_limit|max_error)\b')


def _neg(expr: str) -> str:
    """Return ``-expr`` (the same bits as ``-1.0 * expr``)."""
    if expr.startswith('(-') and expr.endswith(')') and expr[2:-1].isidentifier():
        return expr[2:-1]
    return f'(-{expr})' if expr.isidentifier() else f'(-({expr}))'


def _plus(a: str, b: str) -> str:
    """Return ``a + b``; ``b`` where ``a`` is a literal zero (up to the sign of a zero)."""
    return b if a in ('0.0', '0j') else f'{a} + {b}'


def _sum(terms: Sequence[str]) -> str:
    """Return the left-to-right sum of ``terms`` (Python's ``sum`` of floats, in order)."""
    return ' + '.join(terms) if terms else '0.0'


def compile_single(dynamics: Dynamics, pivots: Mapping[str, Sequence[int]],
                   forces_type: type, reaction_type: type, tiny: float,
                   vector: bool = False) -> SingleForces | NotCompiled:
    """Return one instant's forces of ``dynamics`` as one function, or why not.

    Parameters
    ----------
    dynamics : Dynamics
        The scene's masses, loads and gravity over its graph.
    pivots : mapping of str to sequence of int
        For each group (by key), the row offset partial pivoting picked at
        each step of its elimination (:func:`.forces._bounded_solve`).
    forces_type, reaction_type : type
        :class:`.forces.Forces` and :class:`.forces.Reaction`, which the
        function builds (passed in: :mod:`.forces` imports this module).
    tiny : float
        The least force scale (``forces._TINY``), N.
    vector : bool
        Write the array path instead: the same statements on arrays (every
        instant computed), returning ``(forces, ok)`` with ``ok`` the mask of
        the instants it settles (where a pivot differs or a test fails, the
        caller asks the general path); ``Forces.valid`` is left to the caller.

    Returns
    -------
    callable or NotCompiled
        ``fn(state, max_error)``: see the module's docstring.
    """
    tabled = next((load.name for load in dynamics.loads if load.table is not None), None)
    if tabled is not None:
        return NotCompiled(f'load "{tabled}" depends on where its joint stands (a table): not '
                           f'written out, the general path serves it')
    placed = next((load.name for load in dynamics.loads if load.at is not None), None)
    if placed is not None:
        return NotCompiled(f'load "{placed}" acts at a point of its body\'s frame (a URDF '
                           f"link's force): not written out, the general path serves it")
    for group in dynamics.groups:
        if group.levers:
            return NotCompiled(f'{group.key}: an intermittent drive (its phase picks the '
                               f'statics of each instant)')
        if group.key not in pivots:
            return NotCompiled(f'{group.key}: no pivot sequence recorded')
    graph = dynamics.graph
    w = _Writer(vector)
    ab = w.abs
    size = dynamics.size
    K_U = w.const(U)
    K_2U, K_3U, K_4U = w.const(2 * U), w.const(3 * U), w.const(4 * U)

    def pos(point: str) -> str:
        return w.once(('pos', point), f'P[{point!r}][0]')

    def acc(point: str) -> str:
        return w.once(('acc', point), f'P[{point!r}][2]')

    def pos_bound(point: str) -> str:
        return w.once(('pb', point), f'PB[{point!r}].position')

    def acc_bound(point: str) -> str:
        return w.once(('ab', point), f'PB[{point!r}].acceleration')

    def joint_value(name: str, field: str) -> str:
        return w.once(('j', name, field), f'J[{name!r}].{field}')

    def joint_bound(name: str, field: str) -> str:
        return w.once(('jb', name, field), f'JB[{name!r}].{field}')

    # --- the frames (forces._Kinematics) --------------------------------------------
    frames: dict[str, tuple[str, str, str, str, tuple[str, str, str]]] = {}
    for name, graph_body in graph.bodies.items():
        frame = graph_body.frame
        if frame is None:
            continue
        if frame.angle_of is None:
            frames[name] = (frame.origin, w.const(frame.angle), '0.0', '0.0',
                            (w.const(U * abs(frame.angle)), '0.0', '0.0'))
            continue
        theta = w.let(f'{joint_value(frame.angle_of, "position")} + {w.const(frame.angle)}')
        frames[name] = (frame.origin, theta, joint_value(frame.angle_of, 'velocity'),
                        joint_value(frame.angle_of, 'acceleration'),
                        (joint_bound(frame.angle_of, 'position'),
                         joint_bound(frame.angle_of, 'velocity'),
                         joint_bound(frame.angle_of, 'acceleration')))
    first = next(iter(graph.drivers))
    # --- the inertia wrenches (Dynamics._inertial) ----------------------------------
    inertial: dict[str, tuple[str, str, str, str]] = {}
    gravity = w.const(dynamics.gravity)
    for name in frames:
        origin, theta, omega, alpha, e = frames[name]
        F, M, eF, eM = '0j', '0.0', '0.0', '0.0'
        mass = dynamics.masses.get(name)
        if mass is not None:
            m, com = w.const(mass.mass), complex(*mass.com)
            K_com, K_abs_com = w.const(com), w.const(magnitude(com))
            r = w.let(f'{K_com} * {w.expi(theta)}') if com else '0j'
            spin = w.let(f'1j * {alpha} - {omega} * {omega}')
            a_c = w.let(f'{acc(origin)} + {spin} * {r}')
            F = w.let(f'{m} * ({a_c} - {gravity})')
            M = w.let(f'{w.const(mass.inertia)} * {alpha} + ({r}.real * {F}.imag - '
                      f'{r}.imag * {F}.real)')
            e_theta, e_omega, e_alpha = e
            e_r = w.let(f'{K_abs_com} * ({e_theta} + {K_4U})')
            aspin = ab(spin)
            e_spin = w.let(f'{e_alpha} + 2 * {ab(omega)} * {e_omega} + {K_2U} * {aspin}')
            e_ac = w.let(f'({acc_bound(origin)} + {e_spin} * {K_abs_com} + {aspin} * {e_r} '
                         f'+ {K_4U} * {ab(a_c)})')
            aF = ab(F)
            eF = w.let(f'{m} * {e_ac} + {K_2U} * {aF}')
            eM = w.let(f'({w.const(mass.inertia)} * ({e_alpha} + {K_U} * {ab(alpha)}) + '
                       f'{e_r} * {aF} + {K_abs_com} * {eF} + {K_4U} * ({ab(M)} + '
                       f'{K_abs_com} * {aF}))')
        for load in dynamics.point_loads.get(name, ()):
            load_force = complex(*load.force)  # type: ignore[misc]
            K_f, K_af = w.const(load_force), w.const(magnitude(load_force))
            point = load.point
            assert point is not None
            d = w.let(f'{pos(point)} - {pos(origin)}')
            F = w.let(f'{F} - {K_f}')
            M = w.let(f'{M} - ({d}.real * {K_f}.imag - {d}.imag * {K_f}.real)')
            e_d = w.let(f'{pos_bound(point)} + {pos_bound(origin)} + {K_U} * {ab(d)}')
            eF = w.let(f'{eF} + {K_U} * ({ab(F)} + {K_af})')
            eM = w.let(f'{eM} + {e_d} * {K_af} + {K_3U} * ({ab(d)} * {K_af} + {ab(M)})')
        for load in dynamics.torque_loads.get(name, ()):
            M = w.let(f'{M} - {w.const(float(load.torque))}')  # type: ignore[arg-type]
            eM = w.let(f'{eM} + {K_U} * {ab(M)}')
        inertial[name] = (F, M, eF, eM)
    # --- the scale (Dynamics.forces) ------------------------------------------------
    w.maximum('scale', [ab(F) for F, _, _, _ in inertial.values()], 0.0)
    w.refuse_unless([c for F, M, _, _ in inertial.values()
                     for c in (f'{F} - {F} == 0', f'{M} - {M} == 0.0')])
    gravity_size = magnitude(dynamics.gravity)
    w.maximum('scale', [f'{w.const(mass.mass)} * ({w.const(gravity_size)} + S_a) + '
                        f'{w.const(mass.inertia)} * S_alpha / {w.const(size)}'
                        for mass in dynamics.masses.values()]
              + [w.const(magnitude(complex(*load.force))) if load.force is not None
                 else w.const(abs(load.torque or 0.0) / size) for load in dynamics.loads])
    # --- the groups (Dynamics._solve_config, _bounded_solve) ------------------------
    arms: dict[tuple[str, str], tuple[str, str] | None] = {}

    def arm(at: str, body: str) -> tuple[str, str] | None:
        key = (at, body)
        if key not in arms:
            origin = frames[body][0]
            if at == origin:
                arms[key] = None
            else:
                d = w.let(f'{pos(at)} - {pos(origin)}')
                arms[key] = d, w.let(f'{pos_bound(at)} + {pos_bound(origin)} + '
                                     f'{K_U} * {ab(d)}')
        return arms[key]

    # What each solved joint carries: (joint, force, force bound, couple, couple bound,
    # {component: (value, bound)}), in the general path's order.
    done: list[tuple[Any, str, str, str, str, dict[str, tuple[str, str]]]] = []
    for group in dynamics.groups:
        config = next(iter(group.configs.values()))
        k = len(config.rows)
        row_of = {row: index for index, row in enumerate(config.rows)}
        index_of = {body: b for b, body in enumerate(group.bodies)}
        A: list[list[str | None]] = [[None] * k for _ in range(k)]
        EA: list[list[str | None]] = [[None] * k for _ in range(k)]
        units: list[tuple[str | None, str | None, str | None]] = []
        lines: dict[Any, tuple[str, str]] = {}
        for column, (i, component) in enumerate(config.columns):
            joint = group.joints[i]
            # forces._unit: (unit, its bound or None where exact, its point or None).
            if component in ('x', 'y'):
                unit, e_unit, at = w.const(1.0 + 0j if component == 'x' else 1j), None, joint.at
            elif component == 'moment' or (component == 'effort' and joint.line is None):
                unit, e_unit, at = None, None, None
            else:
                line = joint.line
                assert line is not None
                if joint.name not in lines:
                    if joint.copies > 1:
                        d = w.let(f'{pos(joint.at)} - {pos(line.through)}')
                        length = ab(d)
                        u = w.let(f'{d} / {length}')
                        e_u = w.let(f'({pos_bound(joint.at)} + {pos_bound(line.through)}) * 2 '
                                    f'/ {length} + {K_4U}')
                    else:
                        if line.angle_of is None:
                            angle = w.const(line.angle)
                            e_angle = w.const(U * abs(line.angle))
                        else:
                            angle = w.let(f'{joint_value(line.angle_of, "position")} + '
                                          f'{w.const(line.angle)}')
                            e_angle = w.let(f'{joint_bound(line.angle_of, "position")} + '
                                            f'{w.const(U * abs(line.angle))}')
                        u = w.expi(angle)
                        e_u = w.let(f'{e_angle} + {K_2U}')
                    lines[joint.name] = u, e_u
                u, e_u = lines[joint.name]
                unit = w.let(f'1j * {u}') if component == 'normal' else u
                e_unit, at = e_u, joint.at
            units.append((unit, e_unit, at))
            exact = e_unit is None
            for body, sign in ((joint.body, ''), (joint.on, '-')):
                bi = index_of.get(body)
                if bi is None:
                    continue
                moment_row = row_of.get((bi, 2))
                if at is None:
                    if moment_row is not None:
                        A[moment_row][column] = f'{sign}1.0'
                    continue
                fx, fy = row_of[(bi, 0)], row_of[(bi, 1)]
                assert A[fx][column] is None and A[fy][column] is None
                if exact:   # a pin's x or y: one entry is 1, the other 0 (left out)
                    A[fx if component == 'x' else fy][column] = f'{sign}1.0'
                else:
                    A[fx][column] = w.let(f'{sign}{unit}.real')
                    A[fy][column] = w.let(f'{sign}{unit}.imag')
                    EA[fx][column] = EA[fy][column] = e_unit
                if moment_row is not None:
                    lever = arm(at, body)
                    if lever is not None:
                        d, e_d = lever
                        if exact:
                            cross = (f'{d}.imag' if component == 'x' else f'-{d}.real') \
                                if sign else (f'-{d}.imag' if component == 'x'
                                              else f'{d}.real')
                            A[moment_row][column] = w.let(cross)
                            EA[moment_row][column] = w.let(f'{ab(d)} * {K_3U} + {e_d}')
                        else:
                            A[moment_row][column] = w.let(
                                f'{sign}({d}.real * {unit}.imag - {d}.imag * {unit}.real)')
                            EA[moment_row][column] = w.let(
                                f'{ab(d)} * ({e_unit} + {K_3U}) + {e_d}')
        b: list[str] = [''] * k
        Eb: list[str] = [''] * k
        for (bi, part), row in row_of.items():
            F, M, eF, eM = inertial[group.bodies[bi]]
            b[row], Eb[row] = ((f'{F}.real', eF), (f'{F}.imag', eF), (M, eM))[part]
            b[row] = w.let(b[row])
        for joint, force, force_bound, couple, couple_bound, _ in done:
            bi = index_of.get(joint.on)
            if bi is None:
                continue
            e_force = w.let(f'{force_bound} + {K_U} * {ab(force)}')
            fx, fy = row_of[(bi, 0)], row_of[(bi, 1)]
            b[fx] = w.let(f'{b[fx]} + {force}.real')
            b[fy] = w.let(f'{b[fy]} + {force}.imag')
            Eb[fx] = w.let(f'{Eb[fx]} + {e_force}')
            Eb[fy] = w.let(f'{Eb[fy]} + {e_force}')
            moment_row = row_of.get((bi, 2))
            if moment_row is not None:
                lever = arm(joint.at, joint.on)
                d, e_d = lever if lever is not None else ('0j', '0.0')
                turn = w.let(f'({d}.real * {force}.imag - {d}.imag * {force}.real) + {couple}')
                b[moment_row] = w.let(f'{b[moment_row]} + {turn}')
                e_turn = (f'({ab(d)} * {force_bound} + {e_d} * {ab(force)} + {couple_bound} + '
                          f'{K_4U} * ({ab(d)} * {ab(force)} + {ab(turn)}))')
                Eb[moment_row] = w.let(f'{Eb[moment_row]} + {e_turn}')
        x, e_x = _solve(w, group, A, EA, b, Eb, pivots[group.key])
        # What each joint carries (Dynamics._solve_config's end).
        for i, joint in enumerate(group.joints):
            force, e_force, couple, e_couple = '0j', '0.0', '0.0', '0.0'
            parts: dict[str, tuple[str, str]] = {}
            for column, (j, component) in enumerate(config.columns):
                if j != i:
                    continue
                value, bound = x[column], e_x[column]
                parts[component] = (value, bound)
                unit, e_unit, at = units[column]
                if at is None:
                    couple = w.let(_plus(couple, value))
                    e_couple = w.let(_plus(e_couple, f'{bound} + {K_U} * {ab(couple)}'))
                elif component == 'x':
                    # A pin: 0j + x (1 + 0j) is x, its abs |x|; adding y 1j gives x + iy.
                    e_force = w.let(f'{bound} + {K_2U} * {ab(value)}')
                    force = value
                elif component == 'y':
                    force = w.let(f'{force} + 1j * {value}' if w.vector
                                  else f'complex({force}, {value})')
                    e_force = w.let(f'{e_force} + {bound} + {K_2U} * {ab(force)}')
                else:
                    force = w.let(_plus(force, f'{value} * {unit}'))
                    more = f' + {ab(value)} * {e_unit}' if e_unit is not None else ''
                    e_force = w.let(_plus(e_force, f'{bound}{more} + {K_2U} * {ab(force)}'))
            done.append((joint, force, e_force, couple, e_couple, parts))
    w.maximum('scale', [term for _, force, _, couple, _, _ in done
                        for term in (ab(force), f'{ab(couple)} / {w.const(size)}')])
    # --- the result (Dynamics._result) ----------------------------------------------
    w.emit(f'force_limit = max_error * {"fmax" if w.vector else "max"}(scale, '
           f'{w.const(tiny)})')
    w.emit(f'moment_limit = force_limit * {w.const(size)}')
    checks: list[str] = []
    efforts: list[str] = []
    effort_bounds: list[str] = []
    reactions: list[str] = []
    shaking, e_shaking, turning, e_turning = '0j', '0.0', '0.0', '0.0'
    by_name = {joint.name: (joint, *rest) for joint, *rest in done}
    for joint in graph.joints:
        if joint.name not in by_name:
            continue
        _, force, force_bound, couple, couple_bound, parts = by_name[joint.name]
        zero = ('0.0', '0.0')
        if joint.driver:
            value, bound = parts.get('effort', zero)
            efforts.append(f'{joint.name!r}: {value}')
            effort_bounds.append(f'{joint.name!r}: {bound}')
            checks.append(f'{bound} <= ' + ('force_limit' if joint.line is not None
                                            else 'moment_limit'))
        fields = {'at': repr(joint.at), 'on': repr(joint.body), 'by': repr(joint.on),
                  'force': 'None', 'normal': 'None', 'moment': 'None', 'force_bound': 'None',
                  'normal_bound': 'None', 'moment_bound': 'None'}
        if joint.type.table is None:
            value, bound = parts.get('moment', zero)
            fields.update(moment=value, moment_bound=bound)
            checks.append(f'{bound} <= moment_limit')
        elif joint.line is None:
            (_, e_px), (_, e_py) = parts.get('x', zero), parts.get('y', zero)
            bound = w.let(f'{e_px} + {e_py}')
            fields.update(force=force, force_bound=bound)
            checks.append(f'{bound} <= force_limit')
        else:
            (normal, e_normal), (turn, e_turn) = parts.get('normal', zero), parts.get(
                'moment', zero)
            fields.update(normal=normal, moment=turn, normal_bound=e_normal, moment_bound=e_turn)
            checks += [f'{e_normal} <= force_limit', f'{e_turn} <= moment_limit']
        reaction = w.let('new(Reaction)')
        w.emit(f'{reaction}.__dict__.update(' + ', '.join(
            f'{key}={value}' for key, value in fields.items()) + ')')
        reactions.append(f'{joint.name!r}: {reaction}')
        if joint.on == graph.ground:
            at = pos(joint.at)
            shaking = w.let(_neg(force) if shaking == '0j' else f'{shaking} - {force}')
            e_shaking = w.let(_plus(e_shaking, f'{force_bound} + {K_U} * {ab(shaking)}'))
            turn = w.let(f'({at}.real * {force}.imag - {at}.imag * {force}.real) + {couple}')
            turning = w.let(_neg(turn) if turning == '0.0' else f'{turning} - {turn}')
            e_turn = (f'({ab(at)} * {force_bound} + {pos_bound(joint.at)} * {ab(force)} + '
                      f'{couple_bound} + {K_4U} * ({ab(at)} * {ab(force)} + {ab(turning)}))')
            e_turning = w.let(_plus(e_turning, e_turn))
    checks += [f'{e_shaking} <= force_limit', f'{e_turning} <= moment_limit']
    w.refuse_unless(checks)
    if w.vector:
        efforts = [f'{e.split(": ")[0]}: broadcast_to({e.split(": ")[1]}, shape)'
                   for e in efforts]
    w.emit('result = new(Forces)')
    w.emit(f'result.__dict__.update(efforts={{{", ".join(efforts)}}}, reactions={{'
           f'{", ".join(reactions)}}}, shaking_force={shaking}, shaking_moment={turning}, '
           f'effort_bounds={{{", ".join(effort_bounds)}}}, shaking_bounds=({e_shaking}, '
           f'{e_turning}), valid=True, scale=scale, failures={{}}, worst=None)')
    w.emit('return (result, ok)' if w.vector else 'return result')
    head = ['def forces(state, max_error):']
    if w.vector:
        head += ['    ok = True', '    shape = state.valid.shape']
    else:
        head += [f'    if state.valid is not True or state.joints[{first!r}].position.__class__ '
                 f'is not float: return None']
    head += [
            '    S_a = state.scales["acceleration"]',
            '    S_alpha = state.scales["angular acceleration"]',
            '    P = state.complex_points',
            '    B = state.error_bound',
            '    PB = B.points',
            '    JB = B.joints',
            '    J = state.joints']
    source = '\n'.join(head + ['    ' + line for line in w.lines]) + '\n'
    namespace = dict(w.namespace)
    namespace.update(w.functions, new=object.__new__, Reaction=reaction_type,
                     Forces=forces_type, broadcast_to=np.broadcast_to)
    exec(compile(source, f'<forces of {graph.ground}>', 'exec'), namespace)  # noqa: S102
    function = namespace['forces']
    function.source = source
    return cast(SingleForces, function)


def _solve(w: _Writer, group: _Group, A: list[list[str | None]], EA: list[list[str | None]],
           b: list[str], Eb: list[str], pivots: Sequence[int]) -> tuple[list[str], list[str]]:
    """Emit ``_bounded_solve`` for one pivot sequence; return the unknowns and their bounds.

    ``None`` entries are structural zeros: never read, never written. A pivot
    that partial pivoting would not pick makes the function return ``False``.
    """
    k = len(b)
    ab, mul = w.abs, w.mul
    M: list[list[str | None]] = [list(row) + ['1.0' if c == r else None for c in range(k)]
                                 for r, row in enumerate(A)]
    if len(pivots) != k:
        raise ValueError(f'{group.key}: expected {k} pivots, got {len(pivots)}')
    for j in range(k):
        p = j + pivots[j]
        pivot = M[p][j]
        if pivot is None:
            raise ValueError(f'{group.key}: pivot {j} on a structural zero')
        magnitude = ab(pivot)
        tests = []
        for r in range(j, k):
            other = M[r][j]
            if r != p and other is not None:
                tests.append(f'{magnitude} {">" if r < p else ">="} {ab(other)}')
        w.refuse_unless(tests, 'False')
        w.refuse_unless([f'{magnitude} != 0.0'])
        M[j], M[p] = M[p], M[j]
        inverse = w.let(f'1.0 / {M[j][j]}')
        row: list[str | None] = []
        for c, v in enumerate(M[j]):
            if v is None or c == j:
                row.append(None if v is None else '1.0')
            elif v == '1.0':
                row.append(inverse)
            else:
                row.append(w.let(mul(v, inverse)))
        M[j] = row
        for r in range(k):
            factor = M[r][j]
            if r == j or factor is None:
                continue
            target = M[r]
            new: list[str | None] = []
            for c, (old, v) in enumerate(zip(target, row, strict=True)):
                if c == j:
                    new.append(None)
                elif v is None:
                    new.append(old)
                elif old is None:
                    new.append(w.let(_neg(mul(v, factor))))
                else:
                    new.append(w.let(f'{old} - {mul(v, factor)}'))
            M[r] = new
    X = [row[k:] for row in M]
    x = [w.let(_sum([mul(v, b[c]) for c, v in enumerate(row) if v is not None])) for row in X]
    absx = [ab(value) for value in x]
    t = []
    a_norm: list[str] = []
    for r, row in enumerate(A):
        entries = [(v, c) for c, v in enumerate(row) if v is not None]
        products = [mul(v, x[c]) for v, c in entries]
        products = [p if p.isidentifier() else w.let(p) for p in products]
        residual = w.let(f'{b[r]} - ({_sum(products)})')
        size = w.let(f'({_sum([f"{ab(p)}" for p in products])}) + {ab(b[r])}')
        a_norm.append(_sum([f'{ab(v)}' for v, _ in entries]))
        errors = [f'{EA[r][c]} * {absx[c]}' for _, c in entries if EA[r][c] is not None]
        error = f'(({_sum(errors)}) + {Eb[r]})' if errors else Eb[r]
        t.append(w.let(f'{ab(residual)} + {w.const(_gamma(k + 1))} * {size} + {error}'))
    w.maximum('a_norm', a_norm, 0.0)
    x_norm: list[str] = []
    e_x = []
    for row in X:
        magnitudes = [(ab(v), c) for c, v in enumerate(row) if v is not None]
        x_norm.append(_sum([m for m, _ in magnitudes]))
        e_x.append(_sum([mul(m, t[c]) for m, c in magnitudes]))
    w.maximum('x_norm', x_norm, 0.0)
    w.emit('condition = a_norm * x_norm')
    w.refuse_unless([f'condition * {w.const(64 * k * U)} < 1.0'])
    grow = w.let(f'1.0 / (1.0 - {w.const(k * U)} * condition)')
    e_x = [w.let(f'({e}) * {grow}') for e in e_x]
    w.refuse_unless([f'{v} - {v} == 0.0' for v in x] + [f'{e} < INF' for e in e_x])
    w.namespace['INF'] = float('inf')
    return x, e_x
