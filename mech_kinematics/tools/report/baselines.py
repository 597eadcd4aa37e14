# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Section 2 of the report: work-precision, our solver against the usual alternatives.

For each mechanism of :data:`~.common.WP_SCENES`, :func:`work_precision`
measures cost and error (against the 50-digit reference) of our solver (one
angle, arrays), batched Newton-Raphson on the loop-closure equations, central
differences of our positions in time, ``scipy.integrate.solve_ivp`` on the
velocity equations, and the textbook's printed answer
(:mod:`mech_kinematics.textbook`); :func:`headline` reduces them to ratios.
SciPy and mpmath are imported inside the functions.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
import math
import time
from typing import Any

import numpy as np

from .common import ERROR_FLOOR, Mode, quiet_solve, spread_time, WP_SCENES
from ...scene import load_scene
from ...solver import JointMotion, Scene, solve
from ...solver.graph import joint_type
from ...textbook import find_answer, PointNorm
from ...units import radians_from_degrees

__all__ = ['Configurations', 'HAND_TIME', 'NEWTON_TRACKING_STEP', 'WP_PRINTED', 'WP_RANGES',
           'ORDERS', 'WorkPoint', 'WorkPrecision', 'by_order', 'configurations', 'headline',
           'newton_positions',
           'work_precision']

#: Crank turn between a tracking Newton-Raphson solver's previous solution
#: (its start) and the configuration it solves, rad.
NEWTON_TRACKING_STEP = radians_from_degrees(1.0)
#: Crank angle range, rad, of each work-precision scene (None: a full turn
#: from the scene's angle). The Geneva pin is engaged within +-45 deg of the
#: line of centres only.
WP_RANGES: dict[str, tuple[float, float] | None] = {
    'four-bar': None, 'slider-crank': None, 'slotted lever': None,
    'Geneva': (radians_from_degrees(135.0), radians_from_degrees(225.0))}
#: The printed answer drawn on each work-precision diagram: a quantity of the
#: packaged textbook answers (:mod:`mech_kinematics.textbook`) for the
#: mechanism's scene, at the scene's own crank angle.
WP_PRINTED = {'four-bar': 'alpha_BC, |coupler angular acceleration|',
              'slider-crank': 'a_D (midpoint of the rod), |a_D|',
              'slotted lever': "alpha_lever = a^t_B'O / B'O = 6.4 / 0.52",
              'Geneva': 'alpha_S, wheel angular acceleration (signed, clockwise)'}
#: Where a hand-drawn answer is plotted on the time axis, s: not measured,
#: an assumption stated on the figure (a velocity and acceleration diagram
#: takes a practised hand about ten minutes).
HAND_TIME = 600.0


@dataclass(frozen=True)
class Configurations:
    """Instants along the crank's motion: ``theta(t) = theta0 + omega t + alpha t**2 / 2``."""

    theta0: float
    omega: float
    alpha: float
    times: Any     # ndarray, s
    thetas: Any    # ndarray, rad
    omegas: Any    # ndarray, rad/s


def configurations(scene: Scene, count: int, span: tuple[float, float] | None = None
                   ) -> Configurations:
    """Return ``count`` instants over one turn (or ``span``) at the scene's speed."""
    omega, alpha = scene.input.speed, scene.input.accel
    if span is None:
        start, length = scene.input.angle, 2 * math.pi
    else:
        length = span[1] - span[0]
        start = span[0] if omega > 0 else span[1]
    if alpha != 0:
        msg = 'Expected a constant crank speed for the work-precision instants'
        raise ValueError(msg)
    period = length / abs(omega)
    times = (np.arange(count) + 0.5) * period / count
    thetas = start + omega * times
    return Configurations(start, omega, alpha, times, thetas, np.full(count, omega))


class _State:
    """The parts of a solver State that :func:`reference.compare` reads, for the baselines."""

    def __init__(self, complex_points: dict[str, Any], joints: dict[str, JointMotion]) -> None:
        self.complex_points = complex_points
        self.joints = joints


def _coefficient(x: Any, k: int) -> Any:
    from ...verify.reference import Jet
    if isinstance(x, Jet):
        return (x.c0, x.c1, x.c2)[k]
    return x if k == 0 else 0 * x


def _linear_solve(columns: list[list[Any]], rhs: list[Any]) -> Any:
    """Solve the real 2n x 2n systems ``J x = b`` given as complex columns, batched."""
    n = len(columns)
    shape = np.broadcast_shapes(*(np.shape(c) for col in columns for c in col),
                                *(np.shape(r) for r in rhs))
    matrix = np.empty(shape + (n, n))
    vector = np.empty(shape + (n,))
    for j, column in enumerate(columns):
        for e, c in enumerate(column):
            matrix[..., 2 * e, j] = np.real(c)
            matrix[..., 2 * e + 1, j] = np.imag(c)
    for e, r in enumerate(rhs):
        vector[..., 2 * e] = np.real(r)
        vector[..., 2 * e + 1] = np.imag(r)
    return np.linalg.solve(matrix, vector[..., None])[..., 0]


def _float_kinematics(model: Any, q: list[Any], theta: Any, omega: Any, alpha: Any,
                      ) -> _State:
    """Velocities and accelerations from the linear systems, in double precision."""
    from ...verify.reference import Jet
    values = model.values
    columns = model.jacobian_columns(values, q, theta)
    theta_jet = Jet(theta, omega, alpha / 2)
    _, res = model.evaluate(values, q, theta_jet)
    qdot = -_linear_solve(columns, [_coefficient(r, 1) for r in res])
    qdot_list = [qdot[..., j] for j in range(model.n)]
    _, res = model.evaluate(values, [Jet(x, v) for x, v in zip(q, qdot_list, strict=True)],
                            theta_jet)
    qddot = -2 * _linear_solve(columns, [_coefficient(r, 2) for r in res])
    jets = [Jet(x, v, qddot[..., j] / 2) for j, (x, v) in enumerate(zip(q, qdot_list,
                                                                        strict=True))]
    points, _ = model.evaluate(values, jets, theta_jet)
    shape = np.shape(theta)
    out_points = {}
    for name, z in points.items():
        p, v, a = (z.c0, z.c1, 2 * z.c2) if isinstance(z, Jet) else (z, 0, 0)
        out_points[name] = tuple(np.broadcast_to(np.asarray(x, dtype=np.complex128), shape)
                                 for x in (p, v, a))

    def motion(kind: str, jet: Any) -> JointMotion:
        return JointMotion(kind, *(np.broadcast_to(np.asarray(x, dtype=float), shape)
                                   for x in (jet.c0, jet.c1, 2 * jet.c2)))

    joints = {}
    for name, index in model.links.items():
        joints[name] = motion(model.joint_types[name],
                              theta_jet if index is None else jets[index])
    for name, index in model.sliders.items():
        joints[name] = motion(model.joint_types[name], jets[index])
    return _State(out_points, joints)


def newton_positions(model: Any, thetas: Any, seed: list[Any], tol: float,
                     max_iter: int = 100) -> tuple[list[Any], int]:
    """Newton-Raphson on the loop-closure equations, batched over configurations.

    Stops when every configuration's step is below ``tol`` (rad for angles,
    ``tol * size`` for lengths). Returns the unknowns and the iterations.
    """
    q = [np.array(x, dtype=float) for x in seed]
    values = model.values
    scales = np.array([model.size if length else 1.0 for length in model.unknown_is_length])
    for iteration in range(1, max_iter + 1):
        _, res = model.evaluate(values, q, thetas)
        step = _linear_solve(model.jacobian_columns(values, q, thetas), [-r for r in res])
        q = [x + step[..., j] for j, x in enumerate(q)]
        if np.max(np.abs(step) / scales) <= tol:
            return q, iteration
    return q, max_iter


@dataclass
class WorkPoint:
    """One method's cost and error on one mechanism."""

    family: str
    label: str
    seconds: float            # time per configuration, s
    point_acc: float          # worst relative error of point accelerations
    angular_acc: float        # worst relative error of link angular accelerations
    note: str = ''
    #: Worst relative error per kind (position, angle, velocity, ... as
    #: :func:`mech_kinematics.verify.reference.compare`), where measured.
    errors: dict[str, float] = field(default_factory=dict)
    #: Min, median and max of the repeated timings, s per configuration.
    spread: tuple[float, float, float] | None = None


@dataclass
class WorkPrecision:
    """All methods on one mechanism."""

    mechanism: str
    scene: str
    configs: int
    points: list[WorkPoint] = field(default_factory=list)
    printed: dict[str, float] = field(default_factory=dict)


def _errors(states: Sequence[tuple[Any, int | None]], refs: Sequence[Any]) -> dict[str, float]:
    """Worst relative error per kind over the configurations."""
    from ...verify.reference import compare
    worst: dict[str, float] = {}
    for (state, index), ref in zip(states, refs, strict=True):
        for kind, value in compare(state, ref, index).items():
            worst[kind] = max(worst.get(kind, 0.0), value)
    return worst


def _point(family: str, label: str, spread: tuple[float, float, float],
           errors: dict[str, float], note: str = '') -> WorkPoint:
    """Return a work point from its timings (s per configuration) and errors per kind."""
    return WorkPoint(family, label, spread[1], errors['acceleration'],
                     errors['angular acceleration'], note, errors, spread)


def _scaled(spread: tuple[float, float, float], factor: float) -> tuple[float, float, float]:
    low, mid, high = spread
    return low * factor, mid * factor, high * factor


def work_precision(mechanism: str, mode: Mode,
                   tick: Callable[[], None] = lambda: None) -> WorkPrecision:
    """Cost and error of every method on one work-precision mechanism."""
    from scipy.integrate import solve_ivp

    from ...verify import reference as ref_mod
    scene = load_scene(WP_SCENES[mechanism])
    model = ref_mod.Model(scene)
    conf = configurations(scene, mode.wp_configs, WP_RANGES[mechanism])
    n = len(conf.thetas)
    refs = [ref_mod.reference(model, float(th)) for th in conf.thetas]
    result = WorkPrecision(mechanism, scene.name, n)
    tile = max(mode.wp_tile // n, 1)
    thetas_t = np.tile(conf.thetas, tile)
    omegas_t = np.tile(conf.omegas, tile)
    alpha = conf.alpha
    per = 1.0 / (n * tile)
    tick()

    # Our solver, one angle at a time and over arrays.
    def singles() -> list[Any]:
        return [solve(scene, float(th), float(w), alpha)
                for th, w in zip(conf.thetas, conf.omegas, strict=True)]

    states = singles()
    spread = _scaled(spread_time(singles, mode.repeat), 1.0 / n)
    result.points.append(_point('ours', 'ours, one angle', spread,
                                _errors([(s, None) for s in states], refs)))
    state = solve(scene, conf.thetas, conf.omegas, alpha)
    spread = _scaled(spread_time(lambda: solve(scene, thetas_t, omegas_t, alpha), mode.repeat),
                     per)
    result.points.append(_point('ours', 'ours, arrays', spread,
                                _errors([(state, k) for k in range(n)], refs)))
    tick()

    # Newton-Raphson from the solution one tracking step earlier.
    back = np.sign(conf.omega) * NEWTON_TRACKING_STEP
    seeds = [ref_mod.reference(model, float(th - back)).q for th in conf.thetas]
    seed = [np.array([float(s[j]) for s in seeds]) for j in range(model.n)]
    seed_t = [np.tile(x, tile) for x in seed]
    for tol in mode.newton_tols:
        q, iterations = newton_positions(model, conf.thetas, seed, tol)
        state = _float_kinematics(model, q, conf.thetas, conf.omegas, alpha)

        def newton(tol: float = tol) -> Any:
            q, _ = newton_positions(model, thetas_t, seed_t, tol)
            return _float_kinematics(model, q, thetas_t, omegas_t, alpha)

        spread = _scaled(spread_time(newton, mode.repeat), per)
        result.points.append(_point('newton', f'tol {tol:.0e}', spread,
                                    _errors([(state, k) for k in range(n)], refs),
                                    f'{iterations} iterations'))
    tick()

    # Central differences of our solver's positions in time.
    for step in mode.fd_steps:
        h = step / abs(conf.omega)

        def differences(thetas: Any, omegas: Any, h: float = h) -> _State:
            minus, mid, plus = (quiet_solve(scene, thetas + omegas * dt + alpha * dt * dt / 2,
                                            omegas, alpha) for dt in (-h, 0.0, h))
            points = {}
            for name, (p, _, _) in mid.complex_points.items():
                pm, pp = minus.complex_points[name][0], plus.complex_points[name][0]
                points[name] = (p, (pp - pm) / (2 * h), (pp - 2 * p + pm) / (h * h))
            joints = {}
            for name, joint in mid.joints.items():
                xm, x0, xp = (s.joints[name].position for s in (minus, mid, plus))
                if joint_type(joint.type).angular:
                    lo, hi = np.remainder(x0 - xm + np.pi, 2 * np.pi) - np.pi, \
                        np.remainder(xp - x0 + np.pi, 2 * np.pi) - np.pi
                else:
                    lo, hi = x0 - xm, xp - x0
                joints[name] = JointMotion(joint.type, x0, (lo + hi) / (2 * h),
                                           (hi - lo) / (h * h))
            return _State(points, joints)

        state = differences(conf.thetas, conf.omegas)
        spread = _scaled(spread_time(lambda h=h: differences(thetas_t, omegas_t, h),
                                     mode.repeat), per)
        result.points.append(_point('differences', f'step {step:.0e} rad', spread,
                                    _errors([(state, k) for k in range(n)], refs)))
    tick()

    # Integrating the velocity equations in time (positions), then the linear systems.
    q0 = [float(x) for x in ref_mod.reference(model, conf.theta0).q]
    scales = np.array([model.size if length else 1.0 for length in model.unknown_is_length])

    def rhs(t: float, y: Any) -> Any:
        theta = conf.theta0 + conf.omega * t + alpha * t * t / 2
        q = [float(x) for x in y]
        columns = model.jacobian_columns(model.values, q, theta)
        _, res = model.evaluate(model.values, q, ref_mod.Jet(theta, conf.omega + alpha * t))
        return -_linear_solve(columns, [_coefficient(r, 1) for r in res])

    for rtol in mode.ivp_rtols:
        def integrate(rtol: float = rtol) -> _State:
            sol = solve_ivp(rhs, (0.0, float(conf.times[-1])), q0, method='DOP853',
                            t_eval=conf.times, rtol=rtol, atol=rtol * scales)
            return _float_kinematics(model, list(sol.y), conf.thetas, conf.omegas, alpha)

        start = time.perf_counter()
        state = integrate()
        seconds = (time.perf_counter() - start) / n
        spread = (seconds, seconds, seconds)
        if mode.repeat > 2 and seconds < 0.05:
            spread = _scaled(spread_time(integrate, 3), 1.0 / n)
        result.points.append(_point('solve_ivp', f'rtol {rtol:.0e}', spread,
                                    _errors([(state, k) for k in range(n)], refs)))
    tick()

    # The textbook's printed answer at the scene's own angle.
    answer = find_answer(scene.name, WP_PRINTED[mechanism])
    value = answer.evaluate(ref_mod.as_float_dict(ref_mod.reference(model, scene.input.angle)))
    miss = abs(answer.printed - value) / abs(value)
    errors = (miss, math.nan) if isinstance(answer.accessor, PointNorm) else (math.nan, miss)
    result.points.append(WorkPoint('printed', answer.quantity, HAND_TIME, *errors,
                                   f'stated accuracy {answer.rel_tol:.1%}'))
    result.printed = {'printed': answer.printed, 'exact': value, 'miss': miss,
                      'stated': answer.rel_tol}
    return result


#: The kinds of :func:`mech_kinematics.verify.reference.compare` by order of derivative.
ORDERS = {'position': ('position', 'angle'), 'velocity': ('velocity', 'angular velocity'),
          'acceleration': ('acceleration', 'angular acceleration')}


def by_order(errors: dict[str, float]) -> dict[str, float]:
    """Return the worst relative error of positions, velocities and accelerations.

    Each is the worse of the points' (and sliders') and the links' errors.
    """
    return {order: max(errors.get(kind, 0.0) for kind in kinds)
            for order, kinds in ORDERS.items()}


def headline(results: Sequence[WorkPrecision]) -> dict[str, Any]:
    """Our error and cost against each alternative's best, as ratios measured in one run.

    For each mechanism and alternative family: its most accurate point (the
    worse of the two acceleration errors) and its cost, against our array
    path (``cost_ratio``) and our single-angle path (``cost_ratio_single``,
    what the node pays per tick); ours by order of derivative
    (``ours_by_order``, :func:`by_order`) and the timings' spreads.
    """
    out: dict[str, Any] = {}
    for result in results:
        ours = next(p for p in result.points if p.label == 'ours, arrays')
        single = next(p for p in result.points if p.label == 'ours, one angle')
        ours_err = max(ours.point_acc, ours.angular_acc)
        rows = {}
        for family in ('newton', 'differences', 'solve_ivp'):
            pts = [p for p in result.points if p.family == family]
            if not pts:
                continue
            best = min(pts, key=lambda p: (max(p.point_acc, p.angular_acc), p.seconds))
            err = max(best.point_acc, best.angular_acc)
            rows[family] = {'label': best.label, 'error': err, 'seconds': best.seconds,
                            'spread': best.spread,
                            'error_ratio': err / max(ours_err, ERROR_FLOOR),
                            'cost_ratio': best.seconds / ours.seconds,
                            'cost_ratio_single': best.seconds / single.seconds}
        out[result.mechanism] = {'ours_error': ours_err, 'ours_seconds': ours.seconds,
                                 'ours_spread': ours.spread, 'single_spread': single.spread,
                                 'single_seconds': single.seconds,
                                 'single_error': max(single.point_acc, single.angular_acc),
                                 'ours_by_order': by_order(ours.errors),
                                 'alternatives': rows}
    return out
