# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Solving a scene with error bounds: run the plan, judge the bounds, build the :class:`State`.

Every value comes with an absolute error bound; :func:`solve` refuses a state
whose bounds exceed a tolerance relative to each kind's scale, or that lies
within rounding of an assembly limit.

A scene solved often runs compiled: after :data:`COMPILE_AFTER` single-angle
solves (:data:`ARRAY_COMPILE_AFTER` array solves) its kernels are compiled for
that path (:func:`.compiler.compile_scene`), with the same bits, bounds and
refusals; where the scene does not compile, the solver keeps the reason
(``scene._solver.compiled_single.reason``) and the general path. A caller
that must never stall for a compile settles the general path first
(:func:`keep_general_path`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import replace
import math
from typing import Any, cast, TYPE_CHECKING
import warnings

import numpy as np
import numpy.typing as npt

from .compiler import (ARRAY, Array, bounds_from_entries, compile_scene, NotCompiled, refusal,
                       SINGLE)
from .context import _Context, NEAR_SINGULAR
from .graph import REVOLUTE
from .scaling import (_ACCEL_HIGH, _ldexp, _QUANTITIES, _rate_exponent, _RATE_HIGH, _RATE_LOW,
                      _rates_exponent, _rescale)
from .state import _crank_floors, _scales, _xy, Engagement, JointMotion, State
from .trust import floor_limits, trust_limits, wrapped_angle, wrapped_angles
from ..bounds import ErrorBound, limit, MAX_ERROR, SCALE_MEANINGS, Table, UNITS
from ..errors import AssemblyError, NearSingularWarning, UntrustedError

if TYPE_CHECKING:
    from .mechanism import _Solver, Scene
    from .plan import _Plan

#: Single-angle solves of one scene on the general path before it is compiled
#: (:func:`.compiler.compile_scene`): a compilation (constants folded) costs about as much
#: as a few thousand single-angle solves, so a scene solved a few hundred times or less
#: (most scenes a test builds) is never compiled.
COMPILE_AFTER = 256
#: Array solves of one scene before its array path is compiled: an array solve costs
#: what a few dozen single angles do, or more.
ARRAY_COMPILE_AFTER = 16


def _run(solver: _Solver, angle: Any, speed: Any, accel: Any, turns: Any,
         flip: bool = False, extra: tuple[tuple[Any, Any, Any], ...] = ()) -> _Context:
    """Run every step of the solver's plan; the caller chose scalar or vector inputs.

    With ``flip``, a value that jumps at the instant takes its side before the
    jump (see :func:`solve`). ``angle``, ``speed`` and ``accel`` drive the
    first driver, ``extra`` holds (position, speed, accel) of each other one.
    """
    ctx = _Context(angle, not isinstance(angle, float), turns, flip)
    if ctx.vector and not (flip or extra):
        fast = solver.compiled_array
        if fast is None:
            fast = _compiled_array(solver)
        if fast:
            fast(angle, speed, accel, turns, ctx)
            return ctx
    # Ground points stay complex scalars in both paths: NumPy broadcasts them.
    ctx.points.update(solver.ground)
    plan = solver.run_plan
    plan.crank.run(ctx, angle, speed, accel)
    if extra:
        for driver, (x, v, a) in zip(plan.extra, extra, strict=True):
            driver.run(ctx, x, v, a)
    for step in plan.steps:
        step.run(ctx)
    if plan.rubs:
        ctx.rubbing = {}
        for rub in plan.rubs:
            rub.run(ctx)
    return ctx


def _execute(solver: _Solver, theta: Any, omega: Any, alpha: Any, turns: Any = 0,
             flip: bool = False) -> _Context:
    """Run the solver in units that keep every product in range; reported values in SI.

    A crank rate outside [_RATE_LOW, _RATE_HIGH] is solved with time scaled by a
    power of two, as a scene's size outside :data:`_SIZE_RANGE` is with its
    lengths (:class:`_Solver`); both are exact, so the answers are the same
    bits as if every product had stayed in range.
    """
    w, a = abs(omega), abs(alpha)
    # (an array's abs is not a float: an array of rates is judged by _rate_exponent)
    if isinstance(w, float) and isinstance(a, float) and _RATE_LOW <= w <= _RATE_HIGH \
            and a <= _ACCEL_HIGH:
        shift = 0  # the single-angle path's usual case, decided without a call
    else:
        shift = _rate_exponent(omega, alpha)
    if shift:
        omega, alpha = _ldexp(omega, -shift), _ldexp(alpha, -2 * shift)
    ctx = _run(solver, theta, omega, alpha, turns, flip)
    if solver.shift or shift:
        _rescale(solver, ctx, shift)
        ctx.sums = None     # summed before the rescaling
    return ctx


def _execute_drivers(solver: _Solver, positions: tuple[Any, ...], speeds: tuple[Any, ...],
                     accels: tuple[Any, ...], flip: bool = False) -> _Context:
    """Run the solver on several drivers' values (SI), as :func:`_execute` on one crank's.

    An actuator's length and rates are scaled with the scene's lengths
    (``solver.shift``); then time is scaled by one power of two for every
    driver where the fastest rate is out of range (:func:`_rates_exponent`).
    """
    xs, vs, accs = list(positions), list(speeds), list(accels)
    s = solver.shift
    if s:
        for index, kind in enumerate(solver.driver_types):
            if not kind.angular:  # a length, scaled with the mechanism
                xs[index], vs[index], accs[index] = (
                    _ldexp(x, -s) for x in (xs[index], vs[index], accs[index]))
    shift = _rates_exponent(vs, accs)
    if shift:
        vs = [_ldexp(v, -shift) for v in vs]
        accs = [_ldexp(a, -2 * shift) for a in accs]
    extra = tuple(zip(xs[1:], vs[1:], accs[1:], strict=True))
    ctx = _run(solver, xs[0], vs[0], accs[0], 0, flip, extra)
    if s or shift:
        _rescale(solver, ctx, shift)
    return ctx


def _context_scales(solver: _Solver, ctx: _Context, floors: tuple[Any, Any, Any, Any],
                    pick: Callable[[Any], Any] | None = None) -> dict[str, Any]:
    """Return each kind's scale from the reported values; ``pick`` takes some angles of each."""
    def chosen(values: Any) -> Any:
        return values if pick is None else tuple(map(pick, values))

    return _scales(solver.size, chosen(floors),
                   [chosen(ctx.points[name][1:3]) for name in solver.out_points],
                   [chosen(ctx.sliders[name][1:3]) for name in solver.out_sliders],
                   [chosen(ctx.links[name][1:3]) for name in solver.out_links], ctx.vector)


def _reported_bounds(solver: _Solver, ctx: _Context) -> Iterator[tuple[str, Any]]:
    """Yield (kind, bound) of every reported value's bound, in the outputs' order."""
    for table, name, _, _, kinds in solver.outputs:
        yield from zip(kinds, getattr(ctx, table)[name][3:], strict=True)


def _trusted(solver: _Solver, ctx: _Context,
             lim: tuple[float, float, float, float, float, float]) -> bool:
    """Return True if every reported bound is within its limit ``lim`` (:mod:`.trust`).

    A quick sufficient test for the single-angle path; NaN fails.
    """
    for table, names, (i, j, k) in solver.trust:
        entries = getattr(ctx, table)
        li, lj, lk = lim[i], lim[j], lim[k]
        for name in names:
            e = entries[name]
            if not (e[3] <= li and e[4] <= lj and e[5] <= lk):
                return False
    if ctx.rubbing:
        lv = lim[1]
        return all(bound <= lv for _, bound in ctx.rubbing.values())
    return True


def _refuse(solver: _Solver, ctx: _Context, floors: tuple[Any, Any, Any, Any],
            tol: float) -> None:
    """Raise :class:`UntrustedError` for the first reported value whose bound exceeds ``tol``."""
    scales = _context_scales(solver, ctx, floors)
    for table, name, path, label, kinds in solver.outputs:
        entry = getattr(ctx, table)[name]
        for index, kind in enumerate(kinds):
            bound, scale = entry[3 + index], scales[kind]
            lim = limit(tol, scale)
            if bound <= lim:
                continue
            quantity = _QUANTITIES[index]
            unit = UNITS[kind]
            reason = (f'the {quantity} of {path} cannot be trusted: expected its error bound '
                      f'to be at most {tol:g} x {scale:.3g} {unit} ({SCALE_MEANINGS[kind]}), '
                      f'got {bound:.3g} {unit}')
            key = solver.measure_keys.get(label)
            if label in ctx.notes:
                reason += f'; {ctx.notes[label]}'
            elif key is not None:
                reason += f'; near-singularity measure of {label}: {ctx.measures[key]:.3g}'
            raise UntrustedError(label, ctx.shown, reason, f'{path}.{quantity}', float(bound),
                                 float(lim))
    lim = limit(tol, scales['velocity'])
    for name, (_, bound) in ctx.rubbing.items():
        if not bound <= lim:
            reason = (f'the rubbing velocity at pin {name} cannot be trusted: expected its '
                      f'error bound to be at most {tol:g} x {scales["velocity"]:.3g} m/s '
                      f'({SCALE_MEANINGS["velocity"]}), got {bound:.3g} m/s')
            raise UntrustedError(f'pin {name}', ctx.shown, reason, f'rubbing.{name}',
                                 float(bound), float(lim))


def _judge(solver: _Solver, ctx: _Context, floors: tuple[Any, Any, Any, Any], tol: float,
           shape: tuple[int, ...]) -> None:
    """Mask the angles of a vector solve where a reported bound exceeds ``tol``.

    Each kind's scale (:attr:`State.scales`) is at least its floor, and
    :func:`.bounds.limit` grows with the scale, so an angle whose every bound
    is within ``limit(tol, floor)`` passes; only the other angles (the
    suspects) need the scales, which are norms of every reported value, and
    they are judged there alone: the same masks as judging every angle, at
    the cost of the few near a singular position.
    """
    speed, accel, turn, turn_accel = floors
    least = {'position': solver.size, 'angle': 1.0, 'velocity': speed, 'angular velocity': turn,
             'acceleration': accel, 'angular acceleration': turn_accel}
    if ctx.valid is True and getattr(speed, 'ndim', 0) == 0 and getattr(accel, 'ndim', 0) == 0 \
            and getattr(turn, 'ndim', 0) == 0 and getattr(turn_accel, 'ndim', 0) == 0 \
            and _within(solver, ctx, {kind: tol * x for kind, x in least.items()}):
        return  # nothing refused, one rate, the largest bounds within the floors: as below
    floor_lims = {kind: limit(tol, x) for kind, x in least.items()}
    suspect = np.zeros(shape, dtype=bool)
    pairs = (zip(*ctx.sums, strict=True) if ctx.sums is not None  # the compiled sums, each
             else _reported_bounds(solver, ctx))  # at least every bound it adds
    for kind, bound in pairs:
        suspect |= ~np.less_equal(bound, floor_lims[kind])
    for _, bound in ctx.rubbing.values():
        suspect |= ~np.less_equal(bound, floor_lims['velocity'])
    if ctx.valid is not True:
        suspect &= ctx.valid    # already refused: not judged again
    at = np.flatnonzero(suspect)
    if not at.size:
        return

    def there(x: Any) -> Any:
        return x if np.ndim(x) == 0 else np.broadcast_to(x, shape)[at]

    lims = {kind: limit(tol, scale)
            for kind, scale in _context_scales(solver, ctx, floors, there).items()}

    def mask(ok: Any, label: str) -> None:
        if not ok.all():
            full = np.ones(shape, dtype=bool)
            full[at] = ok
            ctx.mask(full, label)

    for table_name, name, _, label, kinds in solver.outputs:
        entry = getattr(ctx, table_name)[name]
        ok = ((there(entry[3]) <= lims[kinds[0]]) & (there(entry[4]) <= lims[kinds[1]])
              & (there(entry[5]) <= lims[kinds[2]]))
        mask(np.broadcast_to(ok, at.shape), f'{label} (untrusted)')
    for name, (_, bound) in ctx.rubbing.items():
        ok = there(bound) <= lims['velocity']
        mask(np.broadcast_to(ok, at.shape), f'pin {name} (untrusted)')


def _within(solver: _Solver, ctx: _Context, lims: dict[str, float]) -> bool:
    """Return whether every reported bound of a vector solve is within its kind's floor.

    ``lims``: the floors times the tolerance, one number each (one crank rate).

    A sufficient test, cheaper than one reduction per bound: the bounds of
    each kind are added element by element (by the compiled solve itself,
    ``ctx.sums``, where it ran), and the largest sum (``np.maximum.reduce``)
    is compared with the kind's limit. Bounds are never negative, and a
    rounded sum of numbers that are not negative is at least each of them,
    so a sum within the limit holds every bound of the kind within it; NaN
    makes its sum NaN, the largest, and fails. Where a sum exceeds the
    limit, :func:`_judge` tests each bound.
    """
    largest = np.maximum.reduce
    if ctx.sums is not None:    # summed by the compiled array solve, one row a kind
        kinds, table = ctx.sums
        for kind, most in zip(kinds, largest(table, axis=1).tolist(), strict=True):
            if not most <= lims[kind]:
                return False
    else:
        sums: dict[str, Any] = {}
        for kind, bound in _reported_bounds(solver, ctx):
            sums[kind] = sums[kind] + bound if kind in sums else bound
        if not all(largest(total, axis=None) <= lims[kind] for kind, total in sums.items()):
            return False
    lim = lims['velocity']
    return all(bool(largest(bound, axis=None) <= lim) for _, bound in ctx.rubbing.values())


def solve(scene: Scene, angle: npt.ArrayLike, speed: npt.ArrayLike | None = None,
          accel: npt.ArrayLike | None = None, *, turns: npt.ArrayLike = 0,
          max_error: float = MAX_ERROR) -> State:
    """Solve ``scene`` for position, velocity and acceleration at crank ``angle``.

    Every value comes with an absolute error bound (``State.error_bound``,
    :mod:`mech_kinematics.bounds`); a state in which a reported value's bound
    exceeds ``max_error`` times its kind's scale (``State.scales``) is refused.

    Parameters
    ----------
    scene : Scene
        The mechanism.
    angle : float or array_like, shape (n,)
        Crank angle(s), rad, CCW from +x, counted from the start: ``2.5 pi``
        is a quarter turn into the crank's second turn. Only an intermittent
        (Geneva) drive tells the turns apart (its wheel indexes once a turn).
    speed : float or array_like, optional
        Crank angular velocity, rad/s, + CCW. Defaults to the scene's.
    accel : float or array_like, optional
        Crank angular acceleration, rad/s^2, + CCW. Defaults to the scene's.
    turns : int or array_like of int, keyword-only
        Whole crank turns to add to ``angle``: the crank angle counted from
        the start is ``angle + 2 pi turns``, the sum never formed in floating
        point, so a crank kept as whole turns plus an angle within one turn
        (as the node keeps it) loses nothing however many turns it has made.
        Default 0.
    max_error : float, optional
        Tolerance: the largest error bound accepted, relative to its kind's
        scale. Default 1e-6; ``math.inf`` accepts every finite answer. Whatever
        it is, a dyad within rounding of an assembly limit is refused.

    Returns
    -------
    State
        Floats for a scalar ``angle``; arrays (with ``valid`` as a mask) for an
        array.

    Raises
    ------
    AssemblyError
        For a scalar ``angle`` at which a dyad cannot close or is singular;
        its subclass :class:`UntrustedError` where the answer cannot be
        trusted (a bound above the tolerance, a dyad within rounding of an
        assembly limit, a value beyond the range of doubles).
    """
    state = _kinematics(scene, angle, speed, accel, turns=turns, max_error=max_error)
    if scene.dynamics is None:
        return state
    return _with_forces(scene, state, max_error)


def _with_forces(scene: Scene, state: State, max_error: Any) -> State:
    """Return ``state`` with its forces (:mod:`.forces`); refuse an instant they cannot bound.

    The forces answer the side the kinematics answer (``Engagement.driven``
    picks what acts: a Geneva slot or its lock); where a value jumps, the
    other side's forces go to ``jumps['forces']`` (:func:`_other_side`), an
    instant whose other side they cannot bound refused as its own would be.
    """
    dynamics = scene.dynamics
    assert dynamics is not None
    forces = dynamics.forces(state, float(max_error))
    other = _other_side(scene, state) if state.jumps else None
    if isinstance(state.valid, np.ndarray):
        failures = dict(state.failures)
        failures.update(forces.failures)
        valid = state.valid & np.asarray(forces.valid, dtype=bool)
        if other is None:
            return replace(state, forces=forces, valid=valid, failures=failures)
        before, at = other
        part = dynamics.forces(before, float(max_error))
        for reason, mask in part.failures.items():
            full = np.zeros(valid.shape, dtype=bool)
            full[at] = mask
            failures[reason] = failures[reason] | full if reason in failures else full
        valid[at] &= np.asarray(part.valid, dtype=bool)
        jumps = {**state.jumps, 'forces': part.spread(at, valid.shape)}
        return replace(state, forces=forces, valid=valid, failures=failures, jumps=jumps)
    if not forces.valid:
        refuse_forces(state, forces, max_error)
    if other is None:
        return replace(state, forces=forces)
    part = dynamics.forces(other[0], float(max_error))
    if not part.valid:
        refuse_forces(other[0], part, max_error)
    return replace(state, forces=forces, jumps={**state.jumps, 'forces': part})


def _other_side(scene: Scene, state: State) -> tuple[State, Any] | None:
    """Return the kinematic state on the other side of ``state``'s jumps, and its instants.

    Solved with ``flip`` as :func:`_jumps` solves the other side of the
    values: for one instant, that instant (``at`` None); for an array, the
    instants where a value jumps (``at``, their indices), None where none
    does. Its forces are the other side's (:func:`_with_forces`).
    """
    solver = scene._solver
    theta, omega, alpha, turns = state.angle, state.speed, state.accel, state.turns
    if not isinstance(state.valid, np.ndarray):
        ctx = _execute(solver, theta, omega, alpha, turns, flip=True)
        return _state(scene, solver, ctx, theta, omega, alpha, True, turns, {},
                      state.drivers), None
    shape = state.valid.shape
    near = np.zeros(shape, dtype=bool)
    for lever in solver.levers.values():
        near |= lever.jumps_over(theta, turns)
    at = np.flatnonzero(near & state.valid)
    if not at.size:
        return None

    def subset(x: Any) -> Any:
        return np.broadcast_to(x, shape)[at]

    theta, omega, alpha, turns = subset(theta), subset(omega), subset(alpha), subset(turns)
    with np.errstate(all='ignore'):
        ctx = _execute(solver, theta, omega, alpha, turns, flip=True)
    valid = np.broadcast_to(np.asarray(ctx.valid, dtype=bool), at.shape).copy()
    drivers = {name: JointMotion(j.type, subset(j.position), subset(j.velocity),
                                 subset(j.acceleration)) for name, j in state.drivers.items()}
    return _state(scene, solver, ctx, theta, omega, alpha, valid, turns, {}, drivers), at


def refuse_forces(state: State, forces: Any, max_error: Any) -> None:
    """Raise the UntrustedError of one instant whose forces (``Forces``) are not valid."""
    if forces.worst is None:   # the statics degenerate: no bound at all
        reason = next(iter(forces.failures), 'forces')
        raise UntrustedError('forces', float(state.angle),
                             f'the forces cannot be bounded here ({reason})', 'forces',
                             math.inf, float(max_error))
    name, bound, limit = forces.worst
    raise UntrustedError('forces', float(state.angle),
                         f'the error bound of {name} ({bound:.3g}) exceeds max_error '
                         f'{float(max_error):g} of its scale ({limit / float(max_error):.6g})',
                         name, bound, float(max_error))


def _kinematics(scene: Scene, angle: npt.ArrayLike, speed: npt.ArrayLike | None = None,
                accel: npt.ArrayLike | None = None, *, turns: npt.ArrayLike = 0,
                max_error: float = MAX_ERROR) -> State:
    """Return the kinematic state of :func:`solve` (its arguments, its refusals)."""
    theta: Any
    omega: Any
    alpha: Any
    solver = scene._solver
    fast = solver.compiled_single
    first: Any = angle
    count: Any = turns
    tolerance: Any = max_error
    if fast and first.__class__ is float and speed is None and accel is None \
            and count.__class__ is int and tolerance.__class__ is float and tolerance > 0.0 \
            and math.isfinite(first):
        # The usual call of a compiled scene (one crank: a float angle at the scene's
        # rates): the checks below would pass; its answer, or the general path's.
        crank: Any = scene.input     # a crank: a scene that compiles has one driver, a crank
        parts = fast(first, crank.speed, crank.accel, tolerance, count)
        if parts is not None:
            return _compiled_state(scene, solver, first, crank.speed, crank.accel, count, parts)
    if not (isinstance(max_error, (float, int)) and max_error > 0.0):
        msg = f'Expected `max_error` to be a positive number, got {max_error!r}'
        raise ValueError(msg)
    tol = float(max_error)
    if not solver.single:
        return _solve_drivers(scene, solver, angle, speed, accel, turns, tol)
    if speed is None:
        speed = solver.defaults[0]
        if angle.__class__ is np.ndarray:   # the same object every array solve
            speed = solver.default_arrays[0]
    if accel is None:
        accel = solver.defaults[1]
        if angle.__class__ is np.ndarray:
            accel = solver.default_arrays[1]
    whole: Any = turns
    if whole.__class__ is not int:  # an int is the usual case, decided without a call
        whole = _turns(whole)
    if _is_scalar(angle) and _is_scalar(speed) and _is_scalar(accel) and (
            whole.__class__ is int or _is_scalar(whole)):
        theta, omega, alpha = float(angle), float(speed), float(accel)  # type: ignore[arg-type]
        if not (math.isfinite(theta) and math.isfinite(omega) and math.isfinite(alpha)):
            msg = (f'Expected `angle`, `speed` and `accel` to be finite, got {theta!r}, '
                   f'{omega!r}, {alpha!r}')
            raise ValueError(msg)
        whole = int(whole)
        fast = solver.compiled_single
        if fast is None:
            fast = _compiled(scene, solver)
        if fast:
            parts = fast(theta, omega, alpha, tol, whole)
            if parts is not None:
                return _compiled_state(scene, solver, theta, omega, alpha, whole, parts)
        ctx = _execute(solver, theta, omega, alpha, whole)
        if not _trusted(solver, ctx, trust_limits(tol, omega, alpha, solver.size,
                                                  solver.crank_length)):
            _refuse(solver, ctx, _crank_floors(solver.crank_length, omega, alpha), tol)
        valid: Any = True
        jumps = _jumps(solver, ctx, theta, omega, alpha, whole, None) if ctx.jumps else {}
        counted: Any = theta + math.tau * whole if whole else theta
    else:
        some = whole.__class__ is not int or whole != 0    # turns other than the usual 0
        if not some and speed is solver.default_arrays[0] and accel is solver.default_arrays[1] \
                and angle.__class__ is np.ndarray and angle.dtype == _FLOAT and angle.ndim == 1:
            # The usual array call: float angles at the scene's rates (finite, 0-d).
            theta, omega, alpha = angle, speed, accel
            shape = theta.shape
            if not np.isfinite(theta).all():
                msg = 'Expected `angle`, `speed` and `accel` to be finite'
                raise ValueError(msg)
        else:
            theta, omega, alpha = (np.asarray(x, dtype=np.float64) for x in (angle, speed, accel))
            if omega.ndim == 0 and alpha.ndim == 0 and whole.__class__ is int:
                shape = theta.shape     # one rate, whole turns an int
            else:
                shape = np.broadcast_shapes(theta.shape, omega.shape, alpha.shape,
                                            np.shape(whole))
            if len(shape) != 1:
                msg = f'Expected `angle` to be a float or a 1-D array, got shape {shape}'
                raise ValueError(msg)
            if not (np.isfinite(theta).all() and _finite(omega) and _finite(alpha)):
                msg = 'Expected `angle`, `speed` and `accel` to be finite'
                raise ValueError(msg)
        given = (theta, omega, alpha)       # maybe the caller's own arrays
        constant = _constants(solver, shape)
        theta = _read_only(theta, shape, constant)
        whole = constant(_NO_TURNS) if not some else _read_only(
            np.asarray(whole, dtype=np.int64), shape, constant)
        usual = solver.compiled_usual if speed is solver.default_arrays[0] \
            and accel is solver.default_arrays[1] else None
        with np.errstate(all='ignore'):
            if usual:   # compiled for the scene's own rates
                ctx = _Context(theta, True, whole)
                usual(theta, omega, alpha, whole, ctx)
                floors = solver.usual_floors
            else:
                # A constant speed or acceleration stays a scalar through the steps.
                ctx = _execute(solver, theta, omega, alpha, whole)
                floors = _crank_floors(solver.crank_length, omega, alpha)
            _judge(solver, ctx, floors, tol, shape)
        omega, alpha = _read_only(omega, shape, constant), _read_only(alpha, shape, constant)
        valid = (np.ones(shape, dtype=bool) if ctx.valid is True
                 else np.broadcast_to(np.asarray(ctx.valid, dtype=bool), shape).copy())
        jumps = _jumps(solver, ctx, theta, omega, alpha, whole, valid) if ctx.jumps else {}
        counted = theta + math.tau * whole if some and whole.any() else np.array(theta)
    _warn_near_singular(ctx.measures, ctx.vector, ctx.valid)
    drivers = {solver.driver_names[0]: JointMotion(REVOLUTE, counted, omega, alpha)}
    return _state(scene, solver, ctx, theta, omega, alpha, valid, whole, jumps, drivers,
                  given=given if ctx.vector else ())


_FLOAT = np.dtype(np.float64)
#: Whole turns 0, one object (:class:`_Constants` finds it by identity).
_NO_TURNS = np.zeros((), dtype=np.int64)
_NO_TURNS.flags.writeable = False


def _per_driver(values: Any, defaults: tuple[float, ...], what: str) -> list[Any]:
    """Return one value per driver from a sequence (or an array of shape (n, ...)).

    ``None`` (the whole argument or one entry) takes the scene's default.
    """
    n = len(defaults)
    if values is None:
        return list(defaults)
    if n == 1:
        return [defaults[0] if values is None else values]
    if isinstance(values, (str, bytes, float, int)) or (
            isinstance(values, np.ndarray) and values.ndim == 0) or not hasattr(
                values, '__len__'):
        msg = f'Expected `{what}` to be a sequence of {n} values (one per driver), got {values!r}'
        raise ValueError(msg)
    items = list(values)
    if len(items) != n:
        msg = (f'Expected `{what}` to hold {n} values (one per driver), got {len(items)}')
        raise ValueError(msg)
    pairs = zip(items, defaults, strict=True)
    return [default if item is None else item for item, default in pairs]


def _solve_drivers(scene: Scene, solver: _Solver, positions: Any, speeds: Any, accels: Any,
                   turns: Any, tol: float) -> State:
    """Solve a scene with several drivers (or an actuator): :func:`solve`'s general path."""
    drivers = scene.drivers
    names = solver.driver_names
    xs = _per_driver(positions, tuple(d.start for d in drivers), 'positions')
    vs = _per_driver(speeds, tuple(d.speed for d in drivers), 'speeds')
    accs = _per_driver(accels, tuple(d.accel for d in drivers), 'accels')
    count = len(drivers)
    if isinstance(turns, (int, np.integer)):  # one number: every crank's
        listed: list[Any] = [turns if kind.angular else 0 for kind in solver.driver_types]
    else:
        listed = _per_driver(turns, (0,) * count, 'turns')
    wholes = [_turns(t) for t in listed]
    for whole, kind, name in zip(wholes, solver.driver_types, names, strict=True):
        if not kind.angular and np.any(whole):
            msg = f'Expected no whole turns for actuator {name}, got {whole!r}'
            raise ValueError(msg)
    values = [*xs, *vs, *accs]
    if all(_is_scalar(x) for x in values) and all(_is_scalar(t) for t in wholes):
        floats = [float(x) for x in values]
        if not all(math.isfinite(x) for x in floats):
            msg = (f'Expected the positions, speeds and accels of the drivers to be finite, got '
                   f'{floats!r}')
            raise ValueError(msg)
        n = len(drivers)
        xs, vs, accs = floats[:n], floats[n:2 * n], floats[2 * n:]
        try:
            ctx = _execute_drivers(solver, tuple(xs), tuple(vs), tuple(accs))
            floors = solver.floors(vs, accs)
            if not _trusted(solver, ctx, floor_limits(tol, solver.size, floors)):
                _refuse(solver, ctx, floors, tol)
        except AssemblyError as error:
            raise error.located(_where(drivers, xs)) from None
        valid: Any = True
        counted: list[Any] = [x + math.tau * int(w) if w else x
                              for x, w in zip(xs, wholes, strict=True)]
    else:
        arrays = [np.asarray(x, dtype=np.float64) for x in values]
        try:
            shape = np.broadcast_shapes(*(a.shape for a in arrays),
                                        *(np.shape(w) for w in wholes))
        except ValueError:
            shape = ()
        if len(shape) != 1:
            msg = (f'Expected the positions, speeds and accels of the drivers to be floats or '
                   f'1-D arrays of one length, got shapes {[a.shape for a in arrays]}')
            raise ValueError(msg)
        if not all(np.isfinite(a).all() for a in arrays):
            msg = 'Expected the positions, speeds and accels of the drivers to be finite'
            raise ValueError(msg)
        n = len(drivers)
        # Copies: the state's arrays get NaN where refused, never the caller's own.
        xs = [np.array(np.broadcast_to(a, shape)) for a in arrays[:n]]
        vs, accs = [np.array(a) for a in arrays[n:2 * n]], [np.array(a) for a in arrays[2 * n:]]
        with np.errstate(all='ignore'):
            ctx = _execute_drivers(solver, tuple(xs), tuple(vs), tuple(accs))
            floors = solver.floors(vs, accs)
            _judge(solver, ctx, floors, tol, shape)
        vs = [np.broadcast_to(a, shape) for a in vs]
        accs = [np.broadcast_to(a, shape) for a in accs]
        valid = np.broadcast_to(np.asarray(ctx.valid, dtype=bool), shape).copy()
        counted = [np.array(x) + math.tau * np.asarray(w) if np.any(w) else np.array(x)
                   for x, w in zip(xs, wholes, strict=True)]
        vs = [np.array(v) for v in vs]
        accs = [np.array(a) for a in accs]
    _warn_near_singular(ctx.measures, ctx.vector, ctx.valid)
    motions = {name: JointMotion(kind, x, v, a) for name, kind, x, v, a
               in zip(names, solver.driver_types, counted, vs, accs, strict=True)}
    whole = wholes[0]
    return _state(scene, solver, ctx, xs[0], vs[0], accs[0], valid, whole, {}, motions, floors)


def _where(drivers: Any, positions: list[float]) -> str:
    """Return where several drivers stand, for a message: ``crank = 0.5 rad, cyl = 1.2 m``."""
    return ', '.join(f'{d.name} = {x:.6g} {d.joint_type.units[0]}'
                     for d, x in zip(drivers, positions, strict=True))


def _jumps(solver: _Solver, ctx: _Context, theta: Any, omega: Any, alpha: Any, turns: Any,
           valid: Any) -> dict[str, Any]:
    """Return ``State.jumps``: the other side of every reported value that jumps at the instant.

    ``ctx`` holds the side after each jump (``ctx.jumps``: lever -> where it
    jumps); the instants where something jumps are solved again with
    ``flip``, which answers the side before. ``valid`` is None for one
    instant, else the array solve's mask: there the values are arrays, NaN
    where nothing jumps.
    """
    joints: dict[str, Any] = {}
    points: dict[str, Any] = {}
    kinds = solver.plan.joint_types
    if valid is None:
        other = _execute(solver, theta, omega, alpha, turns, flip=True)
        for lever in ctx.jumps:
            names, carried = solver.jumping[lever]
            for name in names:
                table = getattr(other, kinds[name].table)
                joints[name] = {'acceleration': table[name][2]}
            for name in carried:
                points[name] = {'acceleration': _xy(other.points[name][2])}
        rubbing = {name: value for name, (value, _) in other.rubbing.items()
                   if value != ctx.rubbing[name][0]}
        return {'joints': joints, 'points': points, **({'rubbing': rubbing} if rubbing else {})}
    shape = valid.shape
    where = {lever: np.broadcast_to(near, shape) & valid for lever, near in ctx.jumps.items()}
    at = np.flatnonzero(np.logical_or.reduce(list(where.values())))
    if not at.size:
        return {}

    def subset(x: Any) -> Any:
        return x if x.ndim == 0 else np.broadcast_to(x, shape)[at]

    with np.errstate(all='ignore'):
        other = _execute(solver, theta[at], subset(omega), subset(alpha), turns[at], flip=True)
    for lever, near in where.items():
        names, carried = solver.jumping[lever]
        mine = near[at]
        for name in names:
            table = getattr(other, kinds[name].table)
            value = joints.setdefault(name, {'acceleration': np.full(shape, np.nan)})
            value['acceleration'][at[mine]] = np.broadcast_to(table[name][2], at.shape)[mine]
        for name in carried:
            value = points.setdefault(name, {'acceleration': np.full((*shape, 2), np.nan)})
            a = np.broadcast_to(other.points[name][2], at.shape)[mine]
            value['acceleration'][at[mine]] = np.stack((a.real, a.imag), axis=-1)
    rubbing = {}
    for name, (value, _) in other.rubbing.items():
        mine = np.broadcast_to(value, at.shape)
        differs = mine != np.broadcast_to(ctx.rubbing[name][0], shape)[at]
        if differs.any():
            rubbing[name] = np.full(shape, np.nan)
            rubbing[name][at[differs]] = mine[differs]
    return {'joints': joints, 'points': points, **({'rubbing': rubbing} if rubbing else {})}


def assembly_margins(scene: Scene) -> Callable[..., list[tuple[str, Any, Any]]]:
    """Return the function giving every step's assembly margins at crank angles (rad).

    The function takes crank angles (an array) and returns, for each margin of
    each step in order (:meth:`.base.Step.margins`), ``(label, margin,
    rate)``: arrays of the margin (positive where the step closes) and of its
    derivative per radian of crank angle; NaN where the step's inputs are not
    known (an earlier step does not close). With ``label=`` a step's label, it
    returns that step's margins only (the plan run only as far as it needs). A
    step fed by the crank's tip and ground points gives its closed forms
    (:meth:`.base.Step.crank_margins`). The mechanism assembles where every
    margin is positive; ``solve`` refuses there too within rounding of a zero.
    Margins are in the plan's units (a scene rescaled for range keeps their
    signs and roots).
    """
    solver = scene._solver
    plan = solver.run_plan
    crank = plan.crank
    ground = {name: entry[0] for name, entry in solver.ground.items()}
    forms = [step.crank_margins(crank.point, crank.center, crank.length, ground)
             for step in plan.steps]
    position: dict[str, int] = {}
    for index, step in enumerate(plan.steps):  # a carried point may share its owner's label
        position.setdefault(step.label, index)

    def margins(angle: npt.ArrayLike, label: str | None = None) -> list[tuple[str, Any, Any]]:
        theta = np.atleast_1d(np.asarray(angle, dtype=float))
        chosen = range(len(plan.steps)) if label is None else (position[label],)
        result = []
        with np.errstate(all='ignore'):
            ctx = _Context(theta, True)
            ctx.points.update(solver.ground)
            if any(forms[index] is None for index in chosen):
                plan.crank.run(ctx, theta, np.float64(1.0), np.float64(0.0))
            ran = 0
            for index in chosen:
                step, form = plan.steps[index], forms[index]
                if form is None:
                    for earlier in plan.steps[ran:index]:
                        earlier.run(ctx)
                    ran = index
                    pairs = step.margins(ctx.points)
                else:
                    pairs = form(theta)
                for margin, rate in pairs:
                    result.append((step.label, np.broadcast_to(margin, theta.shape),
                                   np.broadcast_to(rate, theta.shape)))
        return result

    return margins


def _turns(turns: Any) -> Any:
    """Return ``turns`` as an int or an int64 array, or raise a ValueError saying why not."""
    if isinstance(turns, (int, np.integer)) and not isinstance(turns, (bool, np.bool_)):
        return int(turns)
    try:
        array = np.asarray(turns)
    except (TypeError, ValueError, OverflowError):
        array = np.asarray(None)
    if array.dtype.kind in 'iu':
        if array.dtype.kind == 'u' and array.size and int(array.max()) >= 2 ** 63:
            array = np.asarray(None)
        else:
            return array.astype(np.int64) if array.ndim else int(array)
    msg = (f'Expected `turns` to be a whole number of crank turns (an int, or an array of '
           f'ints within 2**63 for the array path), got {turns!r}')
    raise ValueError(msg)


def _finite(x: Any) -> bool:
    """Return whether every value of ``x`` (an array of doubles) is finite."""
    return math.isfinite(x) if x.ndim == 0 else bool(np.isfinite(x).all())


def _read_only(x: Any, shape: tuple[int, ...], constant: Callable[[Any], Any]) -> Any:
    """Return ``x`` broadcast to ``shape`` as a read-only view (``np.broadcast_to``'s result).

    ``constant`` (:class:`_Constants` of ``shape``) makes the view of one value.
    """
    if x.ndim == 0:
        return constant(x)
    if x.shape != shape:
        return np.broadcast_to(x, shape)
    view = x.view()
    view.flags.writeable = False
    return view


def _is_scalar(x: Any) -> bool:
    # The cheap test first: the node's tick passes plain floats.
    return isinstance(x, (float, int)) or np.ndim(x) == 0


def _compiled_state(scene: Scene, solver: _Solver, theta: float, omega: float, alpha: float,
                    turns: int, parts: Any) -> State:
    """Return the state of one crank angle from what the compiled solve returned.

    What :func:`_state` makes of the general path's context for a scene of one
    crank with no pins nor intermittent levers (the scenes that compile).
    """
    joints, points, measures, entries = parts
    _warn_near_singular(measures, False, True)
    bound = ErrorBound(bounds_from_entries, (solver.joint_names, solver.out_points, entries),
                       solver.size, solver.crank_length)
    counted = theta + math.tau * turns if turns else theta
    drivers = {solver.driver_names[0]: JointMotion(REVOLUTE, counted, omega, alpha)}
    state = _new_state(scene.name, theta, omega, alpha, joints, points, True, measures, {},
                       bound, turns, {}, {}, {}, drivers)
    if scene.imus:  # read from the state when asked (State.imus), as _state does
        state.__dict__['imu_specs'] = scene.imus
    return state


def keep_general_path(scene: Scene, reason: str) -> None:
    """Keep :func:`solve` from compiling ``scene``'s single-angle path in its caller's thread.

    Unless that path is compiled already, it is settled as not compiled, with
    ``reason`` as why (a :class:`.compiler.NotCompiled`): :func:`solve` then
    answers ``scene`` by its general path, the same bits, and never stalls its
    caller for a compile (seconds on a large scene). For a caller whose thread
    must not stall, such as the node's tick, which compiles elsewhere.
    """
    if not reason:
        msg = 'Expected the reason the general path serves, got an empty string'
        raise ValueError(msg)
    solver = scene._solver
    if solver.compiled_single is None:
        solver.compiled_single = NotCompiled(reason)


def paths(scene: Scene) -> dict[str, str]:
    """Return which path serves each of ``scene``'s solves now, and why: one line each.

    ``single`` and ``array``: :func:`solve`'s kinematics of one instant and of
    arrays (``compiled``, ``general: REASON``, or ``general (compiled after N
    solves)`` until then); with forces, ``forces single`` and ``forces
    array`` (:meth:`.forces.Dynamics.path`). The compile policy's one record:
    the node's ``diagnostics`` and ``check --json`` read it here.
    """
    solver = scene._solver

    def one(compiled: Any, target: Any, after: str) -> str:
        if compiled:
            return 'compiled'
        if compiled is not None:
            return f'general: {compiled.reason}'
        why = refusal(scene, target)
        return f'general: {why}' if why is not None else f'general (compiled after {after})'

    answer = {'single': one(solver.compiled_single, SINGLE, f'{COMPILE_AFTER} solves'),
              'array': one(solver.compiled_array, ARRAY, f'{ARRAY_COMPILE_AFTER} solves')}
    if scene.dynamics is not None:
        forces = scene.dynamics.path()
        answer.update({'forces single': forces['single'], 'forces array': forces['array']})
    return answer


def compile_now(scene: Scene) -> NotCompiled | None:
    """Compile ``scene``'s single-angle path now, in the caller's thread; None, or why not.

    Unless it is settled already (compiled, or the general path kept): then
    :func:`solve` serves ``scene`` from it, the same bits. For a caller that
    compiles before its ticks start (the node's forces tick), so that no tick
    waits for it.
    """
    solver = scene._solver
    if solver.compiled_single is None:
        solver.compiled_single = compile_scene(scene, SINGLE)
    compiled = solver.compiled_single
    return None if compiled else cast(NotCompiled, compiled)


def _compiled(scene: Scene, solver: _Solver) -> Any:
    """Return the scene's compiled single-angle solve once it is worth it, else None or why not.

    Compiled (:mod:`.compiler`, :data:`.compiler.SINGLE`) after
    :data:`COMPILE_AFTER` single-angle solves; a :class:`.compiler.NotCompiled`
    (falsy, with its reason) where the scene does not compile.
    """
    solver.single_solves += 1
    if solver.single_solves < COMPILE_AFTER:
        return None
    solver.compiled_single = compile_scene(scene, SINGLE)
    return solver.compiled_single


def _compiled_array(solver: _Solver) -> Any:
    """Return the scene's compiled array path once it is worth it, else None or why not.

    Compiled (:data:`.compiler.ARRAY`) after :data:`ARRAY_COMPILE_AFTER` array
    solves; a :class:`.compiler.NotCompiled` where the scene does not compile.
    """
    solver.array_solves += 1
    if solver.array_solves < ARRAY_COMPILE_AFTER:
        return None
    solver.compiled_array = compile_scene(solver.scene, ARRAY)
    solver.compiled_usual = (_compile_usual(solver) if solver.compiled_array
                             else solver.compiled_array)
    return solver.compiled_array


def _compile_usual(solver: _Solver) -> Any:
    """Return the scene's array path compiled for its own rates (the usual call), or why not.

    Not where those rates are solved with time rescaled (:func:`_execute`),
    which the compiled function does not do. Sets ``solver.usual_floors``.
    """
    omega, alpha = solver.default_arrays
    if _rate_exponent(omega, alpha) or solver.shift:
        return NotCompiled("the scene's own crank rates are solved with time rescaled")
    solver.usual_floors = _crank_floors(solver.crank_length, omega, alpha)
    return compile_scene(solver.scene, Array(solver.defaults))


def _warn_near_singular(measures: dict[str, Any], vector: bool, valid: Any) -> None:
    for key, measure in measures.items():
        if not vector:
            low = measure < NEAR_SINGULAR
        elif valid is True:     # nothing refused: the least measure (NaN left out) decides
            low = np.fmin.reduce(measure, axis=None) < NEAR_SINGULAR
        else:
            low = (np.less(measure, NEAR_SINGULAR) & valid).any()
        if low:
            msg = (f'dyad at "{key}" is near-singular (measure below {NEAR_SINGULAR:g}): '
                   f'its velocities and accelerations lose accuracy')
            warnings.warn(msg, NearSingularWarning, stacklevel=3)


def _state(scene: Scene, solver: _Solver, ctx: _Context, theta: Any, omega: Any, alpha: Any,
           valid: Any, turns: Any, jumps: dict[str, Any], drivers: dict[str, JointMotion],
           floors: tuple[Any, Any, Any, Any] | None = None,
           given: tuple[Any, ...] = ()) -> State:
    vector = ctx.vector
    plan = solver.plan
    table = ctx.points
    measures = ctx.measures
    if vector:
        shape = theta.shape
        bad = None if ctx.valid is True or valid.all() else ~valid
        inputs = (id(theta), id(omega), id(alpha), *map(id, given))

        constant = _constants(solver, shape)
        if bad is None:
            def finish(x: Any) -> Any:
                # An array of the shape is the state's own, unless it is the caller's
                # input (a copy then); a constant becomes a read-only broadcast view.
                if getattr(x, 'shape', ()) == shape:
                    return np.array(x) if id(x) in inputs else x
                return constant(x)
        else:
            def finish(x: Any) -> Any:
                # As above, with NaN where refused: a copy of a constant or an input.
                if getattr(x, 'shape', ()) != shape:
                    x = np.array(constant(x))
                elif id(x) in inputs:
                    x = np.array(x)
                x[bad] = np.nan
                return x

        joints = {}
        for name, kind in plan.joint_types.items():
            if kind.angular:  # a unit complex number, its angle reported
                e, w, al = ctx.links[name][:3]
                joints[name] = JointMotion(kind, finish(wrapped_angles(e)), finish(w),
                                           finish(al))
            else:
                x, v, a = ctx.sliders[name][:3]
                joints[name] = JointMotion(kind, finish(x), finish(v), finish(a))
        points = {}
        for name in plan.output_points:
            entry = table[name]
            # A ground point's entry is the same tuple every solve: its views, made once.
            known = constant.entries.get(id(entry)) if bad is None else None
            if known is not None and known[0] is entry:
                points[name] = known[1]
            else:
                points[name] = (finish(entry[0]), finish(entry[1]), finish(entry[2]))
                if bad is None and entry[0].__class__ is not np.ndarray \
                        and entry[1].__class__ is not np.ndarray \
                        and entry[2].__class__ is not np.ndarray \
                        and len(constant.entries) < 64:
                    constant.entries[id(entry)] = (entry, points[name])
        measures = {key: finish(m) for key, m in measures.items()}
        if bad is None:     # nothing to write NaN into: finished when first read
            bound = ErrorBound(_finished_bounds, (plan, ctx, finish), solver.size,
                               solver.crank_length, floors)
        else:
            bound = ErrorBound(_given, _finished_bounds(plan, ctx, finish), solver.size,
                               solver.crank_length, floors)
        rubbing = {name: finish(value) for name, (value, _) in ctx.rubbing.items()}
        bound.rubbing = {name: finish(b) for name, (_, b) in ctx.rubbing.items()}
        intermittent = {name: step.engagement(ctx, omega, finish)
                        for name, step in solver.levers.items()}
        drivers = {name: JointMotion(joint.type, finish(joint.position),
                                     finish(joint.velocity), finish(joint.acceleration))
                   for name, joint in drivers.items()}
    else:
        joints = {}
        for name, kind in plan.joint_types.items():
            if kind.angular:  # a unit complex number, its angle reported
                e, w, al = ctx.links[name][:3]
                joints[name] = JointMotion(kind, wrapped_angle(e), w, al)
            else:
                joints[name] = JointMotion(kind, *ctx.sliders[name][:3])
        points = {name: table[name][:3] for name in plan.output_points}
        bound = ErrorBound(_table_bounds, (plan, ctx), solver.size, solver.crank_length, floors)
        rubbing = intermittent = {}
        if ctx.rubbing:
            rubbing = {name: value for name, (value, _) in ctx.rubbing.items()}
            bound.rubbing = {name: b for name, (_, b) in ctx.rubbing.items()}
        if solver.levers:
            intermittent = {name: step.engagement(ctx, omega, None)
                            for name, step in solver.levers.items()}
    state = _new_state(scene.name, theta, omega, alpha, joints, points, valid, dict(measures),
                       dict(ctx.failures), bound, turns, rubbing, intermittent, jumps, drivers)
    if scene.imus:  # read from the state when asked (State.imus)
        state.__dict__['imu_specs'] = scene.imus
    return state


def _new_state(scene: str, angle: Any, speed: Any, accel: Any, joints: dict[str, JointMotion],
               points: dict[str, Any], valid: Any, singularity: dict[str, Any],
               failures: dict[str, Any], error_bound: ErrorBound, turns: Any,
               rubbing: dict[str, Any], intermittent: dict[str, Engagement],
               jumps: dict[str, Any], drivers: dict[str, JointMotion]) -> State:
    """Return ``State(...)`` of these fields, built without the dataclass's ``__init__``.

    A frozen dataclass's ``__init__`` sets each field through
    ``object.__setattr__``: about 1 us of a 7 us single-angle solve. The fields
    go straight into the new instance's ``__dict__`` instead (there is no
    ``__post_init__`` to run); ``test_solve_bounds`` checks the result equals
    the dataclass's own construction.
    """
    state = object.__new__(State)
    fields = state.__dict__
    fields['scene'], fields['angle'], fields['speed'], fields['accel'] = scene, angle, speed, accel
    fields['joints'], fields['complex_points'], fields['valid'] = joints, points, valid
    fields['singularity'], fields['failures'] = singularity, failures
    fields['error_bound'], fields['turns'] = error_bound, turns
    fields['rubbing'], fields['intermittent'] = rubbing, intermittent
    fields['jumps'], fields['drivers'] = jumps, drivers
    return state


class _Constants:
    """Read-only arrays of one shape whose elements are one value, made once per value.

    A vector state holds a dozen such arrays (the ground points' values, a
    constant crank speed, its bounds, the whole turns); a solver keeps one of
    these per shape it was solved at (``solver.constant_arrays``), so the
    next solve of that shape reuses them. They are read-only, so states may
    share them. The ground points' values are the same objects every solve
    and are found by identity; any other value by its type and bytes (not by
    equality, which would take -0.0 for 0.0).
    """

    __slots__ = ('shape', 'known', 'seen', 'entries')

    def __init__(self, solver: _Solver, shape: tuple[int, ...]) -> None:
        self.shape = shape
        # By identity: (the object, kept alive so that its id stays its own, its view).
        self.known = {id(x): (x, _constant(x, shape)) for entry in solver.ground.values()
                      for x in entry}
        self.seen: dict[tuple[str, bytes], Any] = {}
        # A point's (value, velocity, acceleration) of constants, by the entry's identity.
        self.entries: dict[int, tuple[Any, Any]] = {}

    def __call__(self, x: Any) -> Any:
        """Return ``x`` (a number or a 0-d array) as a read-only array of the shape."""
        hit = self.known.get(id(x))
        if hit is not None and hit[0] is x:
            return hit[1]
        one = np.asarray(x)
        key = (one.dtype.char, one.tobytes())
        view = self.seen.get(key)
        if view is None:
            if len(self.seen) >= 64:
                self.seen.clear()
            view = self.seen[key] = _constant(one, self.shape)
        if len(self.known) < 256:   # a compiled solve's constants: the same objects each time
            self.known[id(x)] = (x, view)
        return view


def _constants(solver: _Solver, shape: tuple[int, ...]) -> _Constants:
    """Return the solver's :class:`_Constants` of ``shape`` (made at most once per shape)."""
    constants = solver.constant_arrays.get(shape)
    if constants is None:
        if len(solver.constant_arrays) >= 8:
            solver.constant_arrays.clear()
        constants = solver.constant_arrays[shape] = _Constants(solver, shape)
    return constants


def _constant(x: Any, shape: tuple[int, ...]) -> Any:
    """Return one value (a number or a 0-d array) as a read-only array of ``shape``.

    What ``np.broadcast_to`` returns (every element the one value, no copy),
    built directly: a state holds a dozen of them, and ``broadcast_to`` costs
    several times this.
    """
    one = np.array(x)
    view: Any = np.ndarray(shape, one.dtype, one, 0, (0,) * len(shape))
    view.flags.writeable = False
    return view


def _table_bounds(plan: _Plan, ctx: _Context) -> tuple[Table, Table]:
    """Return the reported joints' and points' bounds from a solve's context."""
    joints = {name: getattr(ctx, kind.table)[name][3:] for name, kind in plan.joint_types.items()}
    table = ctx.points
    return joints, {name: table[name][3:] for name in plan.output_points}


def _finished_bounds(plan: _Plan, ctx: _Context,
                     finish: Callable[[Any], Any]) -> tuple[Table, Table]:
    """Return the reported bounds of a vector solve, each value passed through ``finish``."""
    joints, points = _table_bounds(plan, ctx)
    return ({name: (finish(a), finish(b), finish(c)) for name, (a, b, c) in joints.items()},
            {name: (finish(a), finish(b), finish(c)) for name, (a, b, c) in points.items()})


def _given(joints: Table, points: Table) -> tuple[Table, Table]:
    return joints, points
