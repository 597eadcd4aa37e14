# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Error against cost, and stability on stiff and extreme cases (issue 5).

``python -m mech_kinematics report -o DIR [--quick | --smoke]`` writes
``DIR/REPORT.md`` and its PNG figures:

1. the 50-digit reference (:mod:`mech_kinematics.reference`) and its checks;
2. work-precision diagrams: our solver against Newton-Raphson, finite
   differences, ``solve_ivp`` and the textbooks' printed answers;
3. the error of the node's crank angle against run time, for the exact time
   base and for naive ``angle += omega * dt`` accumulation;
4. stiff and extreme cases against the reference, with the solver's flags;
5. cost growth with the batch size and the number of dyads.

Every number in the report comes from the functions of this module, which the
tests call too. Times are medians of one run on a shared machine: compare
ratios, not absolute times. matplotlib, SciPy, mpmath and tqdm are imported
inside the functions that need them, so the solver and the command line stay
importable without them.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
import math
import os
from pathlib import Path
import platform
import statistics
import sys
import time
from typing import Any
import warnings

import numpy as np

from ..cli import run_tool
from ..errors import AssemblyError, NearSingularWarning
from ..linkage import (Branch, CarriedPoint, Crank, JointMotion, Link, NEAR_SINGULAR, RPR, RRP,
                       RRR, Scene, SINGULAR, solve)
from ..scene import load_scene
from ..textbook import find_answer, PointNorm
from ..units import rad_per_s_from_rpm

__all__ = ['Case', 'CaseResult', 'MODES', 'Mode', 'add_parser', 'chain_scene', 'clock_errors',
           'evaluate_case', 'extreme_cases', 'main', 'naive_accumulate', 'naive_cumsum',
           'naive_wrapped', 'run', 'work_precision']

EPS = float(np.finfo(np.float64).eps)
#: An extreme case meets its bound when, for every kind of value, the error
#: relative to that kind's largest magnitude is at most
#: ``BOUND_FACTOR * EPS * max(1, kappa)``, kappa the problem's condition number
#: (:func:`mech_kinematics.reference.condition`): the error that rounding the
#: inputs alone would cause, with room for the few roundings per dyad.
BOUND_FACTOR = 4.0
#: Tick rate of the simulated node, Hz.
TICK_HZ = 1000
#: Ticks ending at each run time over which the clock errors are the worst.
CLOCK_TICKS = 3
NS_PER_S = 1_000_000_000
#: Crank turn between a tracking Newton-Raphson solver's previous solution
#: (its start) and the configuration it solves, rad.
NEWTON_TRACKING_STEP = math.radians(1.0)
#: Angles per call when a large batch is solved in chunks (section 5).
CHUNK = 4096
#: Relative errors below this are drawn at this floor on log axes.
ERROR_FLOOR = 1e-17

#: The work-precision mechanisms: label -> packaged scene.
WP_SCENES = {'four-bar': 'khurmi_four_bar_ad150', 'slider-crank': 'slider_crank_150_600',
             'slotted lever': 'quick_return', 'Geneva': 'geneva'}
#: Crank angle range, rad, of each work-precision scene (None: a full turn
#: from the scene's angle). The Geneva pin is engaged within +-45 deg of the
#: line of centres only.
WP_RANGES: dict[str, tuple[float, float] | None] = {
    'four-bar': None, 'slider-crank': None, 'slotted lever': None,
    'Geneva': (math.radians(135.0), math.radians(225.0))}


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
class Mode:
    """How much a run of the report does."""

    name: str
    wp_configs: int                    # configurations per work-precision mechanism
    wp_tile: int                       # configurations per timed array call
    newton_tols: tuple[float, ...]
    fd_steps: tuple[float, ...]        # crank turn per finite-difference step, rad
    ivp_rtols: tuple[float, ...]
    wp_mechanisms: tuple[str, ...]
    check_angles: int                  # instants per scene in the reference self-check
    check_scenes: tuple[str, ...] | None  # None: every packaged scene
    clock_durations: tuple[tuple[str, int], ...]   # (label, seconds)
    clock_rpms: tuple[float, ...]
    clock_brute_ticks: int             # exact numpy check of the closed form, ticks
    clock_wrapped_ticks: int           # exact simulation of the wrapped variant, ticks
    extreme_angles: int                # extra angles per multi-angle case
    batch_sizes: tuple[int, ...]
    chain_lengths: tuple[int, ...]
    chain_angles: int
    repeat: int


_DURATIONS = (('1 s', 1), ('1 h', 3600), ('1 day', 86_400), ('30 days', 30 * 86_400),
              ('1 year', 365 * 86_400))

MODES = {
    'full': Mode('full', 72, 8192, (1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-14),
                 (1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7),
                 (1e-3, 1e-5, 1e-7, 1e-9, 1e-11, 1e-13), tuple(WP_SCENES), 3, None,
                 _DURATIONS, (10.0, 1000.0, 100_000.0), 10_000_000, 3_600_000, 8,
                 tuple(10 ** k for k in range(8)), (1, 2, 4, 8, 16, 32, 64), 1000, 5),
    'quick': Mode('quick', 16, 2048, (1e-3, 1e-6, 1e-9, 1e-12), (1e-2, 1e-4, 1e-6),
                  (1e-4, 1e-8, 1e-12), tuple(WP_SCENES), 1,
                  ('khurmi_four_bar_ad150', 'quick_return', 'geneva', 'six_link_slider'),
                  _DURATIONS, (10.0, 1000.0, 100_000.0), 1_000_000, 200_000, 2,
                  tuple(10 ** k for k in range(7)), (1, 4, 16, 64), 1000, 3),
    'smoke': Mode('smoke', 6, 256, (1e-4, 1e-10), (1e-3,), (1e-6,), ('four-bar', 'Geneva'), 1,
                  ('khurmi_four_bar_ad150', 'geneva'), _DURATIONS[:3] + _DURATIONS[4:],
                  (1000.0,), 100_000, 20_000, 0, (1, 100, 10_000), (1, 8), 200, 2),
}


def _progress(total: int, enabled: bool) -> Any:
    from tqdm import tqdm
    return tqdm(total=total, disable=not enabled, unit='task', file=sys.stderr,
                dynamic_ncols=True)


def _median_time(fn: Callable[[], Any], repeat: int, number: int = 1) -> float:
    """Median over ``repeat`` runs of the time of ``number`` calls of ``fn``, s."""
    times = []
    for _ in range(max(repeat, 1)):
        start = time.perf_counter()
        for _ in range(number):
            fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times) / number


def _quiet_solve(scene: Scene, angle: Any, speed: Any = None, accel: Any = None) -> Any:
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', NearSingularWarning)
        return solve(scene, angle, speed, accel)


# --- section 1: the reference and its checks -----------------------------------


@dataclass
class ReferenceCheck:
    """The reference's self-checks on one scene at one instant."""

    scene: str
    angle: float
    residual: float           # loop-closure residual / size
    iterations: int           # Newton-Raphson iterations from the 20-digit construction
    routes: dict[str, float]  # route A (linear systems) against route B (differences in time)
    solver: float             # the solver's worst relative error against the reference


def reference_checks(mode: Mode, tick: Callable[[], None] = lambda: None
                     ) -> list[ReferenceCheck]:
    """Check the reference on the packaged scenes: residual, second route, solver."""
    from . import reference as ref_mod
    from ..scene import scene_names
    rows = []
    names = mode.check_scenes or tuple(scene_names())
    for name in names:
        scene = load_scene(name)
        model = ref_mod.Model(scene)
        angles = [scene.input.angle + 2 * math.pi * k / (mode.check_angles + 1)
                  for k in range(mode.check_angles)]
        if name == 'geneva':
            angles = [scene.input.angle + math.radians(10.0) * k
                      for k in range(mode.check_angles)]
        for angle in angles:
            try:
                state = _quiet_solve(scene, angle)
            except AssemblyError:
                continue
            ref = ref_mod.reference(model, angle)
            routes = ref_mod.check_by_differences(model, ref)
            solver = max(ref_mod.compare(state, ref).values())
            rows.append(ReferenceCheck(name, angle, float(ref.residual), ref.iterations,
                                       routes, solver))
        tick()
    return rows


@dataclass
class GoldenCheck:
    """The reference against one published golden file (50-digit values as doubles)."""

    scene: str
    values: int
    max_ulps_decimal: float     # decimal (as written) inputs: difference in units of last place
    max_rel_double: float       # double inputs: |diff| / (|expected| + scale)


def golden_checks(folder: Path | None = None) -> list[GoldenCheck]:
    """Compare the reference with ``test/data/reference/*.json`` when present."""
    import json

    import mpmath

    from . import reference as ref_mod
    root = Path(__file__).resolve().parent.parent
    folder = folder or root / 'test' / 'data' / 'reference'
    rows = []
    for path in sorted(folder.glob('*.json')) if folder.is_dir() else []:
        data = json.loads(path.read_text(encoding='utf-8'))
        scene_path = root / 'config' / 'scenes' / f'{path.stem}.yaml'
        scene = load_scene(scene_path)
        model = ref_mod.Model(scene)
        exact = ref_mod.decimal_values(scene_path, model)
        count, ulps, rel = 0, 0.0, 0.0
        for case in data['cases']:
            with mpmath.workdps(ref_mod.DPS):
                theta = mpmath.radians(mpmath.mpf(case['angle_deg']))
                omega = rad_per_s_from_rpm(mpmath.mpf(case['speed_rpm']), mpmath.pi)
                alpha = mpmath.mpf(case['accel'])
            decimal = ref_mod.as_float_dict(ref_mod.reference(model, theta, omega, alpha,
                                                              values=exact))
            double = ref_mod.as_float_dict(ref_mod.reference(
                model, math.radians(float(case['angle_deg'])),
                rad_per_s_from_rpm(float(case['speed_rpm'])), float(case['accel'])))
            for expected, got_d, got_f, scale in _golden_values(case, decimal, double):
                count += 1
                if expected != got_d:
                    ulps = max(ulps, abs(got_d - expected) / math.ulp(expected))
                rel = max(rel, abs(got_f - expected) / (abs(expected) + scale))
        rows.append(GoldenCheck(path.stem, count, ulps, rel))
    return rows


def _golden_values(case: dict[str, Any], decimal: dict[str, Any],
                   double: dict[str, Any]) -> Iterable[tuple[float, float, float, float]]:
    """Yield (expected, reference from decimals, reference from doubles, scale)."""
    kinds = {'revolute': ('angle', 'angvel', 'angacc'), 'prismatic': ('length', 'vel', 'acc')}
    scales = case['scales']
    expected = case['expected']
    for name, joint in expected['joints'].items():
        for quantity, kind in zip(('position', 'velocity', 'acceleration'),
                                  kinds[joint['type']], strict=True):
            a, b = decimal['joints'][name][quantity], double['joints'][name][quantity]
            if quantity == 'position' and joint['type'] == 'revolute':
                a = joint[quantity] + math.remainder(a - joint[quantity], 2 * math.pi)
                b = joint[quantity] + math.remainder(b - joint[quantity], 2 * math.pi)
            yield joint[quantity], a, b, scales[kind]
    for name, point in expected['points'].items():
        for quantity, kind in (('position', 'length'), ('velocity', 'vel'),
                               ('acceleration', 'acc')):
            for axis in range(2):
                yield (point[quantity][axis], decimal['points'][name][quantity][axis],
                       double['points'][name][quantity][axis], scales[kind])


# --- section 2: work-precision -------------------------------------------------


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
    from .reference import Jet
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
    from .reference import Jet
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
    joints = {}
    for name, index in model.links.items():
        jet = theta_jet if index is None else jets[index]
        joints[name] = JointMotion('revolute', *(np.broadcast_to(np.asarray(x, dtype=float),
                                                                shape)
                                                for x in (jet.c0, jet.c1, 2 * jet.c2)))
    for name, index in model.sliders.items():
        jet = jets[index]
        joints[name] = JointMotion('prismatic', *(np.broadcast_to(np.asarray(x, dtype=float),
                                                                 shape)
                                                 for x in (jet.c0, jet.c1, 2 * jet.c2)))
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


@dataclass
class WorkPrecision:
    """All methods on one mechanism."""

    mechanism: str
    scene: str
    configs: int
    points: list[WorkPoint] = field(default_factory=list)
    printed: dict[str, float] = field(default_factory=dict)


def _errors(states: Sequence[tuple[Any, int | None]], refs: Sequence[Any]) -> tuple[float, float]:
    from .reference import compare
    worst_p = worst_a = 0.0
    for (state, index), ref in zip(states, refs, strict=True):
        err = compare(state, ref, index, kinds=('acceleration', 'angular acceleration'))
        worst_p = max(worst_p, err['acceleration'])
        worst_a = max(worst_a, err['angular acceleration'])
    return worst_p, worst_a


def work_precision(mechanism: str, mode: Mode,
                   tick: Callable[[], None] = lambda: None) -> WorkPrecision:
    """Cost and error of every method on one work-precision mechanism."""
    from scipy.integrate import solve_ivp

    from . import reference as ref_mod
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
    seconds = _median_time(singles, mode.repeat) / n
    result.points.append(WorkPoint('ours', 'ours, one angle', seconds,
                                   *_errors([(s, None) for s in states], refs)))
    state = solve(scene, conf.thetas, conf.omegas, alpha)
    seconds = _median_time(lambda: solve(scene, thetas_t, omegas_t, alpha), mode.repeat) * per
    result.points.append(WorkPoint('ours', 'ours, arrays', seconds,
                                   *_errors([(state, k) for k in range(n)], refs)))
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

        seconds = _median_time(newton, mode.repeat) * per
        result.points.append(WorkPoint('newton', f'tol {tol:.0e}', seconds,
                                       *_errors([(state, k) for k in range(n)], refs),
                                       f'{iterations} iterations'))
    tick()

    # Central differences of our solver's positions in time.
    for step in mode.fd_steps:
        h = step / abs(conf.omega)

        def differences(thetas: Any, omegas: Any, h: float = h) -> _State:
            minus, mid, plus = (_quiet_solve(scene, thetas + omegas * dt + alpha * dt * dt / 2,
                                             omegas, alpha) for dt in (-h, 0.0, h))
            points = {}
            for name, (p, _, _) in mid.complex_points.items():
                pm, pp = minus.complex_points[name][0], plus.complex_points[name][0]
                points[name] = (p, (pp - pm) / (2 * h), (pp - 2 * p + pm) / (h * h))
            joints = {}
            for name, joint in mid.joints.items():
                xm, x0, xp = (s.joints[name].position for s in (minus, mid, plus))
                if joint.type == 'revolute':
                    lo, hi = np.remainder(x0 - xm + np.pi, 2 * np.pi) - np.pi, \
                        np.remainder(xp - x0 + np.pi, 2 * np.pi) - np.pi
                else:
                    lo, hi = x0 - xm, xp - x0
                joints[name] = JointMotion(joint.type, x0, (lo + hi) / (2 * h), (hi - lo) / (h * h))
            return _State(points, joints)

        state = differences(conf.thetas, conf.omegas)
        seconds = _median_time(lambda h=h: differences(thetas_t, omegas_t, h), mode.repeat) * per
        result.points.append(WorkPoint('differences', f'step {step:.0e} rad', seconds,
                                       *_errors([(state, k) for k in range(n)], refs)))
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
        if mode.repeat > 2 and seconds < 0.05:
            seconds = _median_time(integrate, 3) / n
        result.points.append(WorkPoint('solve_ivp', f'rtol {rtol:.0e}', seconds,
                                       *_errors([(state, k) for k in range(n)], refs)))
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


# --- section 3: the node's crank angle against run time ------------------------


def naive_accumulate(angle0: float, step: float, ticks: int) -> float:
    """Return the double ``a`` after ``ticks`` repetitions of ``a += step`` (``step > 0``).

    Exact, in O(number of binades) operations instead of O(ticks): inside a
    binade ``[2**(e-1), 2**e)`` every double is a multiple of its ulp ``u``, so
    ``fl(a + step) = a + inc`` with a constant ``inc`` (``step`` rounded to a
    multiple of ``u``; after the binade's first addition also in the
    round-half-even tie case) for as long as ``a + step < 2**e``. The two
    first additions of each binade are done in floating point, the constant
    run in exact rational arithmetic. :func:`naive_cumsum` checks it.
    """
    if not step > 0:
        msg = f'Expected a positive step, got {step!r}'
        raise ValueError(msg)
    a = float(angle0)
    left = int(ticks)
    while left > 0:
        if not (a > 0 and a >= step):
            a += step
            left -= 1
            continue
        upper = math.ldexp(1.0, math.frexp(a)[1])
        first = a + step
        left -= 1
        if left == 0 or first >= upper:
            a = first
            continue
        second = first + step
        left -= 1
        inc = second - first  # exact (Sterbenz)
        a = second
        if inc == 0:
            return a          # stagnation: a + step rounds back to a, here and above
        if left == 0 or a >= upper:
            continue
        room = Fraction(upper) - Fraction(step) - Fraction(a)
        count = min(left, max(0, math.ceil(room / Fraction(inc))))
        a = float(Fraction(a) + count * Fraction(inc))
        left -= count
    return a


def naive_cumsum(angle0: float, step: float, ticks: int, chunk: int = 1 << 20) -> float:
    """Accumulate tick by tick instead: sequential ``np.add.accumulate`` in chunks."""
    a = float(angle0)
    left = int(ticks)
    while left > 0:
        n = min(left, chunk)
        buffer = np.full(n + 1, step)
        buffer[0] = a
        a = float(np.add.accumulate(buffer)[-1])
        left -= n
    return a


def naive_wrapped(angle0: float, step: float, ticks: int) -> float:
    """Repeat ``a = math.remainder(a + step, 2 * math.pi)`` ``ticks`` times, tick by tick."""
    a = float(angle0)
    two_pi = 2.0 * math.pi
    remainder = math.remainder
    for _ in range(int(ticks)):
        a = remainder(a + step, two_pi)
    return a


def naive_wrapped_trace(angle0: float, step: float, ticks: int,
                        every: int) -> list[tuple[int, float]]:
    """:func:`naive_wrapped`, returning ``(tick, angle)`` every ``every`` ticks."""
    a = float(angle0)
    two_pi = 2.0 * math.pi
    remainder = math.remainder
    out = []
    for k in range(1, int(ticks) + 1):
        a = remainder(a + step, two_pi)
        if k % every == 0:
            out.append((k, a))
    return out


def _drift_rate(trace: Sequence[tuple[int, Any]]) -> Any:
    """Least-squares slope through the origin of (tick, error), rad per tick."""
    return sum(k * e for k, e in trace) / sum(k * k for k, _ in trace)


@dataclass
class ClockRow:
    """The crank angle and the published state after one run time at one speed."""

    duration: str
    seconds: int
    rpm: float
    angle_error: dict[str, float]   # method -> |angle - exact| wrapped, rad
    state_error: dict[str, float]   # method -> worst relative error of the published state
    wrapped_model: bool             # the wrapped variant extrapolated, not simulated


def clock_errors(mode: Mode, scene_name: str = 'khurmi_four_bar_ad150',
                 tick: Callable[[], None] = lambda: None) -> tuple[list[ClockRow], dict[str, Any]]:
    """Error of the node's crank angle and state after long runs, three ways.

    ``timebase``: :class:`mech_kinematics.timebase.CrankTimebase` sampled at the
    integer-nanosecond instant; ``naive``: ``angle += omega * dt`` per tick
    at :data:`TICK_HZ` (:func:`naive_accumulate`, exact); ``naive, wrapped``:
    the same with the angle wrapped every tick (:func:`naive_wrapped`,
    simulated tick by tick up to ``mode.clock_wrapped_ticks`` ticks, beyond
    that extrapolated linearly from the rate fitted on the simulation: every
    turn rounds the same way binade by binade, so the error grows linearly;
    ``check['wrapped_fit']`` is the relative miss of a fit on the first fifth
    at the simulated end).
    """
    import mpmath

    from . import reference as ref_mod
    from ..ros.timebase import CrankTimebase
    scene = load_scene(scene_name)
    model = ref_mod.Model(scene)
    theta0 = scene.input.angle
    dt = 1.0 / TICK_HZ
    rows = []
    check: dict[str, Any] = {'brute_ticks': 0, 'brute_equal': True}
    with mpmath.workdps(60):
        two_pi = 2 * mpmath.pi
        for rpm in mode.clock_rpms:
            omega = rad_per_s_from_rpm(rpm)
            step = omega * dt
            # The closed form against tick-by-tick accumulation.
            brute = mode.clock_brute_ticks
            for ticks in (brute // 7, brute):
                equal = naive_accumulate(theta0, step, ticks) == naive_cumsum(theta0, step, ticks)
                check['brute_equal'] = check['brute_equal'] and equal
            check['brute_ticks'] = brute
            # The wrapped variant's error grows linearly (each turn rounds the same
            # way, binade by binade): fit its rate on the simulated ticks, and check
            # the fit of the first fifth against the simulated end.
            wrapped_ticks = mode.clock_wrapped_ticks
            every = max(wrapped_ticks // 200, 1)
            trace = [(k, _angle_difference(a, theta0, rpm, k))
                     for k, a in naive_wrapped_trace(theta0, step, wrapped_ticks, every)]
            rate = _drift_rate(trace)
            early = _drift_rate([(k, e) for k, e in trace if 5 * k <= wrapped_ticks])
            end = trace[-1][1]
            check.setdefault('wrapped_fit', {})[rpm] = float(abs(early * trace[-1][0] - end)
                                                             / abs(end)) if end else 0.0
            timebase = CrankTimebase(0, theta0, rpm, 0.0, abs(rpm))
            for label, seconds in mode.clock_durations:
                angle_error: dict[str, float] = {}
                state_error: dict[str, float] = {}
                model_used = seconds * TICK_HZ > wrapped_ticks
                # The last CLOCK_TICKS ticks up to the run time: at a whole number of
                # turns every method may land on the start angle by luck.
                for ticks in range(seconds * TICK_HZ - CLOCK_TICKS + 1, seconds * TICK_HZ + 1):
                    exact_turns = Fraction(rpm) * ticks / (60 * TICK_HZ)
                    exact = _wrap_mp(mpmath.mpf(theta0) + two_pi * _frac(exact_turns))
                    angles: dict[str, float] = {}
                    angles['timebase'] = timebase.sample(ticks * (NS_PER_S // TICK_HZ)).angle
                    angles['naive'] = naive_accumulate(theta0, step, ticks)
                    if not model_used:
                        angles['naive, wrapped'] = naive_wrapped(theta0, step, ticks)
                    else:
                        angles['naive, wrapped'] = float(_wrap_mp(exact + rate * ticks))
                    ref = ref_mod.reference(model, exact, omega, 0.0)
                    for method, angle in angles.items():
                        error = float(abs(_wrap_mp(mpmath.mpf(angle) - exact)))
                        angle_error[method] = max(angle_error.get(method, 0.0), error)
                        state = _quiet_solve(scene, angle, omega, 0.0)
                        error = max(ref_mod.compare(state, ref).values())
                        state_error[method] = max(state_error.get(method, 0.0), error)
                rows.append(ClockRow(label, seconds, rpm, angle_error, state_error, model_used))
            tick()
    return rows, check


def _frac(x: Fraction) -> Fraction:
    return x - math.floor(x)


def _wrap_mp(x: Any) -> Any:
    import mpmath
    two_pi = 2 * mpmath.pi
    y = x - two_pi * mpmath.floor(x / two_pi + mpmath.mpf(0.5))
    return y + two_pi if y <= -mpmath.pi else y


def _angle_difference(angle: float, theta0: float, rpm: float, ticks: int) -> Any:
    import mpmath
    exact = mpmath.mpf(theta0) + 2 * mpmath.pi * mpmath.mpf(rpm) / 60 * ticks / TICK_HZ
    return _wrap_mp(mpmath.mpf(angle) - exact)


# --- section 4: stiff and extreme cases ------------------------------------------


@dataclass(frozen=True)
class Case:
    """One stiff or extreme configuration: a scene and the crank instants to try."""

    name: str
    scene: Scene
    angles: tuple[float, ...]
    speed: float | None = None
    accel: float | None = None
    note: str = ''


def _four_bar(name: str, a: float, b: float, c: float, d: float, angle: float = 0.0,
              branch: int = 1, speed: float = -4 * math.pi, scale: float = 1.0) -> Scene:
    links = (Link('coupler', 'B', b * scale), Link('rocker', 'D', c * scale))
    crank = Crank('crank', 'A', 'B', a * scale, angle, speed, 0.0)
    return Scene(name, {'A': (0.0, 0.0), 'D': (d * scale, 0.0)}, crank,
                 (RRR('C', links, Branch(branch)),),
                 (CarriedPoint('E', 'coupler', 'B', 'C', (0.5 * b * scale, 0.3 * b * scale)),))


def _slider_crank(name: str, crank_length: float, rod: float, offset: float = 0.0,
                  angle: float = 0.0, speed: float = 10 * math.pi) -> Scene:
    crank = Crank('crank', 'O', 'B', crank_length, angle, speed, 0.0)
    dyad = RRP('P', Link('rod', 'B', rod), 'E', 0.0, 'piston', Branch.PLUS)
    return Scene(name, {'O': (0.0, 0.0), 'E': (0.0, offset)}, crank, (dyad,),
                 (CarriedPoint('M', 'rod', 'B', 'P', (0.5 * rod, 0.0)),))


def _distance_angle(a: float, d: float, distance: float) -> Any:
    """Crank angle (mpmath) at which the crank tip is ``distance`` from ``D = (d, 0)``."""
    import mpmath
    with mpmath.workdps(60):
        a_, d_, r = (mpmath.mpf(x) for x in (a, d, distance))
        return mpmath.acos((a_ * a_ + d_ * d_ - r * r) / (2 * a_ * d_))


def _spread(center: float, width: float, count: int) -> tuple[float, ...]:
    return tuple(center + width * (k / max(count - 1, 1) - 0.5) * 2 for k in range(count)) \
        if count > 1 else (center,)


def extreme_cases(mode: Mode | None = None) -> list[Case]:
    """Return the stiff and extreme configurations of issue 5, part 4."""
    import mpmath
    extra = (mode or MODES['full']).extreme_angles
    cases = []
    # A non-Grashof four-bar (seed 002 Problem 3) near its two toggle positions.
    toggle = load_scene('four_bar_coupler_points')
    t = _distance_angle(0.05, 0.1, 0.066 + 0.056)
    for delta in ('1e-3', '1e-6', '1e-9', '1e-12'):
        with mpmath.workdps(60):
            angles = (float(t - mpmath.mpf(delta)), float(-(t - mpmath.mpf(delta))))
        cases.append(Case(f'four-bar {delta} rad from toggle', toggle, angles,
                          note='four_bar_coupler_points; both toggles (+-103.79 deg)'))
    # Change-point four-bar a + d = b + c (a parallelogram): flat at crank angle 0.
    change = _four_bar('change_point', 0.04, 0.1, 0.04, 0.1, angle=0.5)
    cases.append(Case('change-point four-bar at flat', change, (0.0,),
                      note='a = c = 0.04, b = d = 0.1; crank angle 0: all pins in line'))
    for offset in (1e-3, 1e-6, 1e-9):
        cases.append(Case(f'change-point four-bar {offset:.0e} rad from flat', change,
                          (offset,), note='parallelogram branch'))
    # Circles that miss each other (or overlap) by 1e-9 of the coupler length.
    for sign, word in ((1, 'miss'), (-1, 'overlap')):
        beyond = float(_distance_angle(0.05, 0.1, 0.066 + 0.056 + sign * 1e-9 * 0.066))
        cases.append(Case(f'circles {word} by 1e-9 of the coupler', toggle, (beyond, -beyond),
                          note=f'four_bar_coupler_points where |BD| = BC + CD '
                               f'{"+" if sign > 0 else "-"} 1e-9 BC'))
    # Rod-to-crank ratios.
    for ratio, label in ((1.000001, '1.000001'), (1e6, '1e6')):
        scene = _slider_crank(f'rod_crank_{label.replace(".", "_")}', 0.1, 0.1 * ratio)
        cases.append(Case(f'rod/crank = {label}', scene,
                          (math.pi / 2, -math.pi / 2) + _spread(0.7, 0.6, extra),
                          note='in-line slider-crank, crank 0.1 m; worst at +-90 deg'))
    # The same four-bar scaled.
    base = load_scene('khurmi_four_bar_ad150')
    for size in (1e-6, 1e3):
        k = size / 0.15
        scene = _four_bar('khurmi_scaled', 0.04, 0.15, 0.08, 0.15, math.radians(60),
                          speed=base.input.speed, scale=k)
        cases.append(Case(f'four-bar scaled to {size:g} m', scene,
                          (math.radians(60),) + _spread(0.0, 3.0, extra),
                          note='khurmi_four_bar_ad150 with every length times '
                               f'{k:.3g}'))
    for rpm in (1e-6, 1e5):
        cases.append(Case(f'crank speed {rpm:g} rpm', base,
                          (math.radians(60),) + _spread(0.0, 3.0, extra),
                          speed=rad_per_s_from_rpm(rpm), accel=0.0,
                          note='khurmi_four_bar_ad150'))
    # A slotted lever whose pin passes within 1e-6 (of the crank) of the pivot.
    r = 0.15
    lever = Scene('pin_near_pivot', {'O': (0.0, 0.0), 'A': (0.0, r * (1 + 1e-6))},
                  Crank('crank', 'A', 'B', r, -math.pi / 2, 4 * math.pi, 0.0),
                  (RPR('lever', 'O', 'B', 'block'),),
                  (CarriedPoint('C', 'lever', 'O', 'B', (0.7, 0.0)),))
    cases.append(Case('slotted lever, pin 1e-6 r from pivot', lever,
                      (-math.pi / 2, -math.pi / 2 + 1e-3) + _spread(0.5, 1.0, extra),
                      note='|OA| = r (1 + 1e-6): closest approach at crank angle -90 deg'))
    # Offset slider-cranks at the edge of assembly (rod = crank + offset).
    edge = _slider_crank('offset_edge', 0.125, 0.1875, offset=0.0625)
    cases.append(Case('offset slider-crank exactly at the edge', edge, (-math.pi / 2,),
                      note='crank 0.125, offset 0.0625, rod 0.1875 (exact in binary): '
                           'rod perpendicular to the guide at -90 deg'))
    near_edge = _slider_crank('offset_near_edge', 0.125, 0.1875 * (1 + 1e-9), offset=0.0625)
    cases.append(Case('offset slider-crank 1e-9 inside the edge', near_edge,
                      (-math.pi / 2, -math.pi / 2 + 1e-6) + _spread(0.5, 1.0, extra),
                      note='rod = 0.1875 (1 + 1e-9)'))
    return cases


@dataclass
class AngleResult:
    """The solver against the reference at one crank instant of a case."""

    angle: float
    flag: str                   # 'refused', 'warned' or 'none'
    measure_solver: float       # the solver's smallest measure (nan: refused)
    measure_exact: float        # the same measure from the reference (nan: no assembly)
    reference: str              # 'regular', 'singular' or 'no assembly'
    errors: dict[str, float]    # per kind, relative error (empty: refused)
    kappa: dict[str, float]     # per kind, condition number
    ratio: float                # max over kinds of error / (EPS * max(1, kappa))
    verdict: str                # 'meets bound', 'flagged', 'refused (no assembly)' or 'FAIL'


@dataclass
class CaseResult:
    """A case's instants and their aggregate (worst over the instants)."""

    case: Case
    angles: list[AngleResult]

    @property
    def flag(self) -> str:
        """The strongest flag over the instants."""
        rank = {'none': 0, 'warned': 1, 'refused': 2}
        return max((a.flag for a in self.angles), key=rank.__getitem__)

    @property
    def measure_solver(self) -> float:
        """The solver's smallest measure over the solved instants (nan: none solved)."""
        values = [a.measure_solver for a in self.angles if math.isfinite(a.measure_solver)]
        return min(values, default=math.nan)

    @property
    def measure_exact(self) -> float:
        """The exact smallest measure over the instants that assemble."""
        values = [a.measure_exact for a in self.angles if math.isfinite(a.measure_exact)]
        return min(values, default=math.nan)

    @property
    def reference(self) -> str:
        """What the reference found: regular, singular, no assembly (or a mix)."""
        return ' / '.join(dict.fromkeys(a.reference for a in self.angles))

    @property
    def errors(self) -> dict[str, float]:
        """Per kind, the largest error over the solved instants."""
        out: dict[str, float] = {}
        for a in self.angles:
            for kind, value in a.errors.items():
                out[kind] = max(out.get(kind, 0.0), value)
        return out

    @property
    def kappa(self) -> dict[str, float]:
        """Per kind, the largest condition number over the instants."""
        out: dict[str, float] = {}
        for a in self.angles:
            for kind, value in a.kappa.items():
                out[kind] = max(out.get(kind, 0.0), value)
        return out

    @property
    def ratio(self) -> float:
        """The largest error / (eps kappa) over the solved instants."""
        values = [a.ratio for a in self.angles if math.isfinite(a.ratio)]
        return max(values, default=math.nan)

    @property
    def verdict(self) -> str:
        """FAIL if any instant fails, else flagged if any is, else meets bound / refused."""
        verdicts = {a.verdict for a in self.angles}
        for verdict in ('FAIL', 'flagged', 'meets bound'):
            if verdict in verdicts:
                return verdict
        return 'refused (no assembly)'


def _solve_flagged(scene: Scene, angle: float, speed: float | None,
                   accel: float | None) -> tuple[Any, str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        try:
            state = solve(scene, angle, speed, accel)
        except AssemblyError:
            return None, 'refused'
    warned = any(issubclass(w.category, NearSingularWarning) for w in caught)
    return state, 'warned' if warned else 'none'


def evaluate_angle(case: Case, angle: float, model: Any = None) -> AngleResult:
    """Solve ``case`` at ``angle``, compare with the reference and judge the bound.

    Verdicts: ``meets bound`` (every kind's error within
    ``BOUND_FACTOR * EPS * max(1, kappa)``); ``flagged`` (not within it, or
    refused, and the solver warned or refused); ``refused (no assembly)``
    (no real configuration, and the solver refused); ``FAIL`` otherwise.
    """
    from . import reference as ref_mod
    model = model or ref_mod.Model(case.scene)
    state, flag = _solve_flagged(case.scene, angle, case.speed, case.accel)
    measure_solver = min(state.singularity.values()) if state is not None else math.nan
    try:
        ref = ref_mod.reference(model, angle, case.speed, case.accel)
    except ref_mod.NoAssembly:
        verdict = 'refused (no assembly)' if state is None else 'FAIL'
        return AngleResult(angle, flag, measure_solver, math.nan, 'no assembly', {}, {},
                           math.nan, verdict)
    kappa = ref_mod.condition(model, ref)
    errors: dict[str, float] = {}
    ratio = math.nan
    if state is not None:
        errors = ref_mod.compare(state, ref)
        ratio = max(errors[k] / (EPS * max(1.0, kappa[k])) for k in errors)
    if state is not None and ratio <= BOUND_FACTOR:
        verdict = 'meets bound'
    elif flag != 'none':
        verdict = 'flagged'
    else:
        verdict = 'FAIL'
    return AngleResult(angle, flag, measure_solver, float(ref.min_measure),
                       'singular' if ref.singular else 'regular', errors, kappa, ratio, verdict)


def evaluate_case(case: Case) -> CaseResult:
    """Evaluate every instant of ``case``."""
    from . import reference as ref_mod
    model = ref_mod.Model(case.scene)
    return CaseResult(case, [evaluate_angle(case, angle, model) for angle in case.angles])


def digits_lost(results: Sequence[CaseResult], below: float = 0.1
                ) -> list[tuple[CaseResult, float, dict[str, float]]]:
    """Per case, digits lost (log10 of error / eps) at its instant losing most velocity digits.

    Only instants whose measure is below ``below`` count. Returns (case,
    the solver's measure there, digits lost per kind).
    """
    out = []
    for r in results:
        solved = [a for a in r.angles if a.errors and 0 < a.measure_solver < below]
        if not solved:
            continue
        worst = max(solved, key=lambda a: a.errors['velocity'])
        lost = {k: math.log10(max(v, EPS) / EPS) for k, v in worst.errors.items()}
        out.append((r, worst.measure_solver, lost))
    return out


@dataclass
class FormulaAudit:
    """A formula choice near a toggle: the textbook form against the solver's."""

    case: str
    measure: float
    errors: dict[str, float]    # formula -> relative error of the RRR height h (the pin's offset)


def formula_audit() -> list[FormulaAudit]:
    """Textbook forms of the RRR closure against the solver's, near the toggle (before/after).

    The pin's distance ``h`` from the line of centres decides every later
    value. The textbook computes it from ``cos(gamma)`` by the law of
    cosines (``h = l1 sin(acos(...))``: ``acos`` near +-1) or as
    ``sqrt(l1**2 - p**2)`` with ``p = (l1**2 - l2**2 + d**2) / (2 d)``
    (cancellation); the solver multiplies four factors, each exact or
    nearly so. Errors against the 50-digit value of the same double inputs.
    """
    import mpmath
    rows = []
    l1, l2, a, d = 0.066, 0.056, 0.05, 0.1
    t = _distance_angle(a, d, l1 + l2)
    for delta in ('1e-3', '1e-6', '1e-9', '1e-12'):
        with mpmath.workdps(60):
            theta = float(t - mpmath.mpf(delta))
        bx, by = a * math.cos(theta), a * math.sin(theta)
        dist = math.hypot(d - bx, -by)
        cos_gamma = (l1 * l1 + dist * dist - l2 * l2) / (2 * l1 * dist)
        p = (l1 * l1 - l2 * l2 + dist * dist) / (2 * dist)
        forms = {
            'acos (law of cosines)': l1 * math.sin(math.acos(max(-1.0, min(1.0, cos_gamma)))),
            'sqrt(l1^2 - p^2)': math.sqrt(max(l1 * l1 - p * p, 0.0)),
            'product (solver)': math.sqrt((l1 + l2 + dist) * (l1 + l2 - dist)
                                          * (dist + l1 - l2) * (dist - l1 + l2)) / (2 * dist),
        }
        with mpmath.workdps(60):
            th = mpmath.mpf(theta)
            bxm, bym = mpmath.mpf(a) * mpmath.cos(th), mpmath.mpf(a) * mpmath.sin(th)
            dm = mpmath.sqrt((mpmath.mpf(d) - bxm) ** 2 + bym ** 2)
            L1, L2 = mpmath.mpf(l1), mpmath.mpf(l2)
            k = (L1 + L2 + dm) * (L1 + L2 - dm) * (dm + L1 - L2) * (dm - L1 + L2)
            h = mpmath.sqrt(k) / (2 * dm)
            errors = {name: float(abs(mpmath.mpf(v) - h) / h) for name, v in forms.items()}
            measure = float(mpmath.sqrt(k) / (2 * L1 * L2))
        rows.append(FormulaAudit(f'four-bar {delta} rad from toggle', measure, errors))
    return rows


# --- section 5: cost growth --------------------------------------------------------


def chain_scene(stages: int) -> Scene:
    """Return a chain of ``stages`` four-bar stages, each driven by the previous rocker.

    Stage k is the Grashof crank-rocker of ``khurmi_four_bar_ad150`` (input
    40, coupler 150, rocker 80, ground 150 mm): its input is the point carried
    40 mm along the previous rocker from its pivot, so every stage assembles
    at every crank angle, on either branch. One RRR dyad and one carried
    point per stage.
    """
    if stages < 1:
        msg = f'Expected at least 1 stage, got {stages}'
        raise ValueError(msg)
    a, b, c, d = 0.04, 0.15, 0.08, 0.15
    ground = {f'G{k}': (k * d, 0.0) for k in range(stages + 1)}
    dyads = []
    points = []
    for k in range(1, stages + 1):
        dyads.append(RRR(f'C{k}', (Link(f'coupler{k}', f'P{k - 1}', b),
                                   Link(f'rocker{k}', f'G{k}', c)), Branch.PLUS))
        if k < stages:
            points.append(CarriedPoint(f'P{k}', f'rocker{k}', f'G{k}', f'C{k}', (a, 0.0)))
    crank = Crank('crank', 'G0', 'P0', a, math.radians(60.0), -4 * math.pi, 0.0)
    return Scene(f'chain_{stages}', ground, crank, tuple(dyads), tuple(points))


@dataclass
class CostGrowth:
    """Time per configuration against batch size and against chain length."""

    batch: list[tuple[int, float]]          # (angles, s per configuration), array path
    chunked: list[tuple[int, float]]        # the same angles solved CHUNK at a time
    single: float                           # one angle through the scalar path, s
    batch_slope: float                      # d log(total time) / d log(angles), large batches
    chain_array: list[tuple[int, float]]    # (dyads, s per configuration)
    chain_single: list[tuple[int, float]]
    chain_slope_array: float                # d log(time) / d log(dyads), 4 dyads and up
    chain_slope_single: float
    per_dyad_array: float                   # s per configuration per dyad (linear fit)
    per_dyad_single: float


def _slope(xs: Sequence[float], ys: Sequence[float]) -> float:
    return float(np.polyfit(np.log(xs), np.log(ys), 1)[0])


def _chunked(scene: Scene, angles: Any) -> None:
    for start in range(0, len(angles), CHUNK):
        solve(scene, angles[start:start + CHUNK])


def cost_growth(mode: Mode, tick: Callable[[], None] = lambda: None) -> CostGrowth:
    """Time the solver over batches of 1 .. 1e7 angles and chains of 1 .. 64 dyads.

    Each batch is solved once before timing, so that the first touch of fresh
    memory (page faults) is not counted; large batches are also timed in
    chunks of :data:`CHUNK` angles.
    """
    scene = load_scene('khurmi_four_bar_ad150')
    rng = np.random.default_rng(5)
    batch, chunked = [], []
    for n in mode.batch_sizes:
        angles = rng.uniform(-math.pi, math.pi, n)
        repeat = mode.repeat if n <= 100_000 else 3
        number = max(1, 1000 // n) if n < 1000 else 1
        solve(scene, angles)
        seconds = _median_time(lambda a=angles: solve(scene, a), repeat, number)
        batch.append((n, seconds / n))
        if n > CHUNK:
            seconds = _median_time(lambda a=angles: _chunked(scene, a), repeat)
            chunked.append((n, seconds / n))
        del angles
        tick()
    single = _median_time(lambda: solve(scene, 1.0), mode.repeat, 2000)
    large = [(n, s * n) for n, s in batch if n >= 1000]
    if len(large) < 2:
        large = [(n, s * n) for n, s in batch][-2:]
    batch_slope = _slope([n for n, _ in large], [t for _, t in large]) if len(large) > 1 \
        else math.nan
    chain_array, chain_single = [], []
    angles = rng.uniform(-math.pi, math.pi, mode.chain_angles)
    for stages in mode.chain_lengths:
        chained = chain_scene(stages)
        seconds = _median_time(lambda s=chained: solve(s, angles), mode.repeat)
        chain_array.append((stages, seconds / mode.chain_angles))
        once = _median_time(lambda s=chained: solve(s, 1.0), 1, 5)
        number = max(10, int(0.02 / once))  # samples of about 20 ms
        chain_single.append((stages, _median_time(lambda s=chained: solve(s, 1.0),
                                                  2 * mode.repeat + 1, number)))
        tick()
    tail = [(n, s) for n, s in chain_array if n >= 4]
    tail = tail if len(tail) > 1 else chain_array
    tail_single = [(n, s) for n, s in chain_single if n >= 4]
    tail_single = tail_single if len(tail_single) > 1 else chain_single

    def fit(rows: list[tuple[int, float]]) -> tuple[float, float]:
        if len(rows) < 2:
            return math.nan, math.nan
        slope = _slope([n for n, _ in rows], [s for _, s in rows])
        per = float(np.polyfit([n for n, _ in rows], [s for _, s in rows], 1)[0])
        return slope, per

    slope_a, per_a = fit(tail)
    slope_s, per_s = fit(tail_single)
    return CostGrowth(batch, chunked, single, batch_slope, chain_array, chain_single, slope_a,
                      slope_s, per_a, per_s)


# --- figures ----------------------------------------------------------------------


def _figure(path: Path, draw: Callable[[Any], None], size: tuple[float, float]) -> None:
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig = plt.figure(figsize=size, dpi=110)
    try:
        draw(fig)
        fig.savefig(path)
    finally:
        plt.close(fig)


_STYLE = {'ours': ('C0', 'o'), 'newton': ('C1', 's'), 'differences': ('C2', '^'),
          'solve_ivp': ('C3', 'D'), 'printed': ('k', '*')}
_FAMILY = {'ours': 'our solver (closed form)', 'newton': 'Newton-Raphson, tol on step',
           'differences': 'central differences of positions, step in crank angle',
           'solve_ivp': 'solve_ivp DOP853 on the velocity equations, rtol',
           'printed': "the seed's printed answer (own angle only)"}


def plot_work_precision(result: WorkPrecision, path: Path) -> None:
    """Draw the log-log error against time per configuration, two panels."""
    def draw(fig: Any) -> None:
        axes = fig.subplots(1, 2, sharex=True, sharey=True)
        for ax, attr, title in zip(axes, ('point_acc', 'angular_acc'),
                                   ('point accelerations', 'link angular accelerations'),
                                   strict=True):
            for family, (color, marker) in _STYLE.items():
                pts = [p for p in result.points if p.family == family
                       and math.isfinite(getattr(p, attr))]
                if not pts:
                    continue
                xs = [p.seconds for p in pts]
                ys = [max(getattr(p, attr), ERROR_FLOOR) for p in pts]
                if family == 'ours':
                    for p, x, y in zip(pts, xs, ys, strict=True):
                        ax.plot(x, y, marker=marker, color=color, ms=9, ls='none',
                                mfc='none' if 'one angle' in p.label else color,
                                label=p.label)
                    continue
                if family == 'printed':
                    stated = result.printed['stated']
                    ax.plot(xs, ys, marker=marker, color=color, ms=10, ls='none',
                            label="seed's printed answer: its miss (own angle only)")
                    ax.plot(xs, [stated], marker='_', color=color, ms=16, mew=2, ls='none',
                            label=f'  its stated accuracy ({pts[0].note.split()[-1]})')
                    ax.vlines(xs, ys, [stated], color=color, lw=0.8)
                    ax.annotate('drawing time\nassumed 10 min', (xs[0], ys[0]),
                                textcoords='offset points', xytext=(-62, -14), fontsize=6.5)
                    continue
                ax.plot(xs, ys, marker=marker, color=color, ms=6, ls='-', label=_FAMILY[family])
                placed: list[tuple[float, float]] = []
                for p, x, y in zip(pts, xs, ys, strict=True):
                    if any(abs(math.log10(x / u)) < 0.3 and abs(math.log10(y / v)) < 0.6
                           for u, v in placed):
                        continue  # a label is there already
                    placed.append((x, y))
                    ax.annotate(p.label.split(' ')[1], (x, y), textcoords='offset points',
                                xytext=(4, 3), fontsize=6.5, color=color)
            ax.axhline(EPS, color='0.6', lw=0.8, ls=':')
            ax.set_xscale('log')
            ax.set_yscale('log')
            ax.set_title(f'{result.mechanism}: {title}', fontsize=10)
            ax.set_xlabel('time per configuration [s]')
            ax.grid(True, which='major', alpha=0.3)
        axes[0].set_ylabel('worst relative error over the configurations [-]')
        axes[0].text(0.02, 0.02, f'dotted: machine epsilon {EPS:.1e}; errors below '
                     f'{ERROR_FLOOR:.0e} drawn at it', transform=axes[0].transAxes, fontsize=7)
        handles, labels = axes[1].get_legend_handles_labels()
        h0, l0 = axes[0].get_legend_handles_labels()
        merged = dict(zip(l0 + labels, h0 + handles, strict=True))
        fig.legend(merged.values(), merged.keys(), loc='lower center', ncol=2, fontsize=7.5,
                   frameon=False)
        fig.suptitle(f'Work-precision, {result.mechanism} ({result.scene}, '
                     f'{result.configs} configurations)', fontsize=11)
        fig.subplots_adjust(bottom=0.25, top=0.89, wspace=0.08, left=0.08, right=0.98)

    _figure(path, draw, (11.0, 5.4))


def plot_clock(rows: list[ClockRow], path: Path) -> None:
    """Draw angle error against run time per speed and method."""
    def draw(fig: Any) -> None:
        axes = fig.subplots(1, 2)
        rpms = sorted({r.rpm for r in rows})
        styles = {'timebase': '-', 'naive': '--', 'naive, wrapped': ':'}
        markers = {'timebase': 'o', 'naive': 's', 'naive, wrapped': '^'}
        for ax, attr, ylabel in zip(axes, ('angle_error', 'state_error'),
                                    ('crank angle error [rad]',
                                     'worst relative error of the published state [-]'),
                                    strict=True):
            for i, rpm in enumerate(rpms):
                sub = [r for r in rows if r.rpm == rpm]
                for method, ls in styles.items():
                    xs = [r.seconds for r in sub]
                    ys = [max(getattr(r, attr)[method], ERROR_FLOOR) for r in sub]
                    ax.plot(xs, ys, ls=ls, marker=markers[method], color=f'C{i}', ms=5,
                            label=f'{method}, {rpm:g} rpm')
            ax.set_xscale('log')
            ax.set_yscale('log')
            ax.set_xlabel('simulated run time [s]')
            ax.set_ylabel(ylabel)
            ax.grid(True, alpha=0.3)
            for label, seconds in _DURATIONS:
                ax.axvline(seconds, color='0.85', lw=0.6, zorder=0)
                ax.text(seconds, 1.02, label, transform=ax.get_xaxis_transform(),
                        fontsize=7, ha='center')
        handles, labels = axes[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc='lower center', ncol=3, fontsize=7.5, frameon=False)
        fig.suptitle(f'Crank angle from the clock, {TICK_HZ} Hz ticks: exact time base '
                     'against accumulation', fontsize=11, y=0.99)
        fig.subplots_adjust(wspace=0.3, left=0.08, right=0.98, top=0.86, bottom=0.25)

    _figure(path, draw, (11.0, 6.0))


def plot_extreme(results: list[CaseResult], path: Path) -> None:
    """Draw each case's error against eps * kappa, with the bound."""
    def draw(fig: Any) -> None:
        ax = fig.subplots()
        colors = {'none': 'C0', 'warned': 'C1', 'refused': 'C3'}
        seen = set()
        for i, r in enumerate(results):
            if not r.errors:
                continue
            kind = max(r.errors, key=lambda k: r.errors[k] / (EPS * max(1.0, r.kappa[k])))
            x = EPS * max(1.0, r.kappa[kind])
            y = max(r.errors[kind], ERROR_FLOOR)
            label = f'solver flag: {r.flag}' if r.flag not in seen else None
            seen.add(r.flag)
            ax.plot(x, y, 'o', color=colors[r.flag], ms=6, label=label)
            ax.annotate(str(i + 1), (x, y), textcoords='offset points', xytext=(4, 2),
                        fontsize=7)
        lo, hi = 1e-17, 1.0
        xs = np.array([lo, hi])
        ax.plot(xs, xs, color='0.5', lw=0.8, label='error = eps * kappa')
        ax.plot(xs, BOUND_FACTOR * xs, color='k', lw=1.0, ls='--',
                label=f'bound {BOUND_FACTOR:g} eps * kappa')
        ax.set_xscale('log')
        ax.set_yscale('log')
        ax.set_xlim(lo, hi)
        ax.set_ylim(lo, hi)
        ax.set_xlabel('machine epsilon x condition number, eps * kappa [-]')
        ax.set_ylabel('worst relative error against the 50-digit reference [-]')
        ax.set_title('Stiff and extreme cases (numbers: rows of the table; worst kind)',
                     fontsize=10)
        refused = [str(i + 1) for i, r in enumerate(results) if not r.errors]
        if refused:
            ax.text(0.98, 0.02, f'refused by the solver, not drawn: {", ".join(refused)}',
                    transform=ax.transAxes, ha='right', fontsize=8)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc='upper left')
        fig.subplots_adjust(left=0.13, right=0.97, bottom=0.11, top=0.93)

    _figure(path, draw, (6.4, 5.6))


def plot_cost(cost: CostGrowth, path: Path) -> None:
    """Draw time per configuration against batch size and against chain length."""
    def draw(fig: Any) -> None:
        left, right = fig.subplots(1, 2)
        ns = [n for n, _ in cost.batch]
        left.plot(ns, [s for _, s in cost.batch], 'o-', color='C0',
                  label='array path, one call')
        if cost.chunked:
            left.plot([n for n, _ in cost.chunked], [s for _, s in cost.chunked], 's--',
                      color='C2', label=f'array path, in calls of {CHUNK} angles')
        left.axhline(cost.single, color='C1', ls='--',
                     label=f'scalar path, one angle ({cost.single * 1e6:.1f} us)')
        left.set_xscale('log')
        left.set_yscale('log')
        left.set_xlabel('angles per call (batch size) [-]')
        left.set_ylabel('time per configuration [s]')
        left.set_title(f'khurmi four-bar; total time ~ N^{cost.batch_slope:.2f} '
                       '(N >= 1e3)', fontsize=10)
        left.grid(True, which='both', alpha=0.3)
        left.legend(fontsize=8)
        ds = [n for n, _ in cost.chain_array]
        right.plot(ds, [s for _, s in cost.chain_array], 'o-', color='C0',
                   label=f'array path (slope {cost.chain_slope_array:.2f})')
        right.plot(ds, [s for _, s in cost.chain_single], 's-', color='C1',
                   label=f'scalar path, one angle (slope {cost.chain_slope_single:.2f})')
        right.set_xscale('log')
        right.set_yscale('log')
        right.set_xticks(ds, [str(n) for n in ds])
        right.minorticks_off()
        right.set_xlabel('RRR dyads in the chain (four-bar stages) [-]')
        right.set_ylabel('time per configuration [s]')
        right.set_title('chained four-bars; slopes fitted from 4 dyads on', fontsize=10)
        right.grid(True, which='both', alpha=0.3)
        right.legend(fontsize=8)
        fig.subplots_adjust(wspace=0.3, left=0.08, right=0.98, top=0.9, bottom=0.12)

    _figure(path, draw, (11.0, 4.8))


# --- the report --------------------------------------------------------------------


def _e(x: float) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return '-'
    if math.isinf(x):
        return 'inf'
    if x == 0:
        return '0'
    return f'{x:.1e}'


def _t(seconds: float) -> str:
    if seconds >= 1:
        return f'{seconds:.3g} s'
    if seconds >= 1e-3:
        return f'{seconds * 1e3:.3g} ms'
    if seconds >= 1e-6:
        return f'{seconds * 1e6:.3g} us'
    return f'{seconds * 1e9:.3g} ns'


def headline(results: Sequence[WorkPrecision]) -> dict[str, Any]:
    """Our error and cost against each alternative's best, as ratios measured in one run.

    For each mechanism and alternative family: its most accurate point (the
    worse of the two errors) and its cost, against our array path.
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
                            'error_ratio': err / max(ours_err, ERROR_FLOOR),
                            'cost_ratio': best.seconds / ours.seconds,
                            'cost_ratio_single': best.seconds / single.seconds}
        out[result.mechanism] = {'ours_error': ours_err, 'ours_seconds': ours.seconds,
                                 'single_seconds': single.seconds,
                                 'single_error': max(single.point_acc, single.angular_acc),
                                 'alternatives': rows}
    return out


def write_report(outdir: Path, mode: Mode, checks: list[ReferenceCheck],
                 golden: list[GoldenCheck], wp: list[WorkPrecision], clock: list[ClockRow],
                 clock_check: dict[str, Any], extreme: list[CaseResult],
                 audit: list[FormulaAudit], cost: CostGrowth, elapsed: float) -> Path:
    """Write ``outdir/REPORT.md`` from the computed sections."""
    lines: list[str] = []
    w = lines.append
    w('# mech_kinematics: error against cost, and stability on stiff and extreme cases')
    w('')
    w(f'Generated by `python -m mech_kinematics report -o DIR'
      f'{"" if mode.name == "full" else " --" + mode.name}` in {elapsed:.0f} s '
      f'(Python {platform.python_version()}, NumPy {np.__version__}, '
      f'{os.cpu_count()} CPUs shared with other work). Times are medians of one run; '
      'compare ratios, not absolute times. Relative errors are per kind of value '
      '(point positions, velocities, accelerations; link angles, angular velocities, '
      "angular accelerations), over that kind's largest magnitude in the state.")
    w('')
    hl = headline(wp)
    w('## Headline')
    w('')
    w('| mechanism | our error | ours, arrays / one angle (per configuration) | '
      'alternative: most accurate setting | its error (x ours) | its cost (x our arrays) |')
    w('|---|---|---|---|---|---|')
    names = {'newton': 'Newton-Raphson', 'differences': 'finite differences',
             'solve_ivp': 'solve_ivp'}
    for mech, h in hl.items():
        for family, row in h['alternatives'].items():
            w(f'| {mech} | {_e(h["ours_error"])} | {_t(h["ours_seconds"])} / '
              f'{_t(h["single_seconds"])} | {names[family]} {row["label"]} | '
              f'{_e(row["error"])} ({row["error_ratio"]:.3g}x) | {_t(row["seconds"])} '
              f'({row["cost_ratio"]:.3g}x) |')
    w('')
    n_fail = sum(r.verdict == 'FAIL' for r in extreme)
    w(f'Extreme cases: {len(extreme)} cases, {n_fail} failures; every case either meets '
      f'{BOUND_FACTOR:g} x eps x its condition number or is flagged by the solver. '
      f'Worst error / (eps x kappa) among cases meeting the bound: '
      f'{max((r.ratio for r in extreme if r.verdict == "meets bound"), default=math.nan):.2g}.')
    long = [r for r in clock if r.duration == clock[-1].duration]
    if long:
        top = max(long, key=lambda r: r.rpm)
        w(f'Node clock after {top.duration} at {top.rpm:g} rpm: crank angle error '
          f'{_e(top.angle_error["timebase"])} rad with the time base, '
          f'{_e(top.angle_error["naive"])} rad with `angle += omega * dt`.')
    w(f'Cost: total time ~ N^{cost.batch_slope:.2f} in the batch size; '
      f'~ dyads^{cost.chain_slope_array:.2f} (arrays) and '
      f'^{cost.chain_slope_single:.2f} (one angle) in the chain length.')
    w('')

    # 1
    w('## 1. The 50-digit reference')
    w('')
    w('`mech_kinematics/reference.py` writes each scene as its loop-closure equations '
      '(two per dyad: RRR, the two link angles; RRP, link angle and slider coordinate; '
      'RPR, lever angle and slider coordinate; carried points as explicit functions of '
      'their frame points) and solves them in mpmath at 64 working digits, without '
      "any of the solver's formulas:")
    w('')
    w('- positions: a textbook construction done at only 20 digits (law of cosines, '
      'circle and line) starts Newton-Raphson on the whole system, which brings the '
      'residual below 1e-58 of the size; the assembly branch is then checked against its '
      'definition in SCENE_FORMAT.md;')
    w('- velocities and accelerations: the linear systems of the differentiated '
      'constraints, J qdot = -Phi_t and J qddot = -(d/dt)^2 Phi|qddot=0, derivatives by '
      'forward-mode Taylor arithmetic;')
    w('- second route: five-point central differences in time of 64-digit positions '
      '(crank step 1e-12 rad, so truncation ~1e-48 and rounding ~1e-40).')
    w('')
    w('Inputs are the exact binary values of the doubles the solver gets, so the '
      "difference is the solver's own error.")
    w('')
    w('| scene | crank angle [deg] | residual / size | Newton iterations | route A vs B: '
      'velocity | angular velocity | acceleration | angular acceleration | solver error |')
    w('|---|---|---|---|---|---|---|---|---|')
    for c in checks:
        kinds = ('velocity', 'angular velocity', 'acceleration', 'angular acceleration')
        routes = ' | '.join(_e(c.routes[k]) for k in kinds)
        w(f'| {c.scene} | {math.degrees(c.angle):.1f} | {_e(c.residual)} | {c.iterations} | '
          f'{routes} | {_e(c.solver)} |')
    w('')
    if golden:
        w('Against the published golden cases (`test/data/reference/*.json`, 50-digit values '
          'rounded to doubles):')
        w('')
        w('| golden file | values | from the decimal inputs as written: max difference '
          '[ulp] | from the double inputs: max abs difference / (abs value + scale) |')
        w('|---|---|---|---|')
        for g in golden:
            w(f'| {g.scene} | {g.values} | {g.max_ulps_decimal:g} | {_e(g.max_rel_double)} |')
        w('')

    # 2
    w('## 2. Work-precision')
    w('')
    w(f'{wp[0].configs if wp else 0} configurations per mechanism, evenly spaced in time '
      'over one turn at the scene speed (the Geneva wheel: its engaged 90 deg only). '
      'Error: worst over the configurations of the relative error of the point '
      'accelerations (left) and link angular accelerations (right) against the '
      f'50-digit reference. Time: per configuration; array methods timed on batches '
      f'of about {mode.wp_tile} configurations.')
    w('')
    w('- **ours**: `solve(scene, angle)` in a Python loop (one angle) and '
      '`solve(scene, angles)` (arrays).')
    w('- **Newton-Raphson** on the loop-closure equations, batched over configurations '
      '(NumPy, LU of the 2n x 2n Jacobian, Jacobian by forward differentiation of the same '
      'constraint functions as the reference), started from the solution 1 deg of crank '
      'earlier (a tracking solver); then velocities and accelerations from the linear '
      'systems. Tolerance: on the largest Newton step (rad, or of the size).')
    w("- **finite differences**: central differences in time of our solver's positions "
      '(three solves), step given as crank turn.')
    w('- **solve_ivp** (SciPy, DOP853) on the velocity equations qdot = -J^-1 Phi_t from '
      'the exact start over the turn, then accelerations from the linear system at the '
      'integrated positions. The time is the whole integration over the configurations.')
    w("- **printed answer**: the seed's printed acceleration at the scene's own angle, "
      'its relative miss against the exact value; drawn at an assumed 10 minutes of '
      'drawing time.')
    w('')
    for result in wp:
        slug = _slug(result.mechanism)
        w(f'### {result.mechanism} (`{result.scene}`)')
        w('')
        w(f'![work-precision {result.mechanism}](wp_{slug}.png)')
        w('')
        w('| method | setting | time per configuration | point accelerations | '
          'angular accelerations | note |')
        w('|---|---|---|---|---|---|')
        for p in result.points:
            label = p.label.replace('|', '\\|')
            w(f'| {p.family} | {label} | {_t(p.seconds) if p.family != "printed" else "-"} | '
              f'{_e(p.point_acc)} | {_e(p.angular_acc)} | {p.note} |')
        pr = result.printed
        w('')
        w(f"Printed: {pr['printed']:g} against exact {pr['exact']:.6g} "
          f"(miss {pr['miss']:.2%}, stated accuracy {pr['stated']:.1%}).")
        w('')

    # 3
    w('## 3. Error against run time of the node')
    w('')
    w(f'The node at {TICK_HZ} Hz from the scene angle of `khurmi_four_bar_ad150`; the exact '
      'angle is theta0 + 2 pi rpm/60 t, in 60-digit arithmetic. Methods:')
    w('')
    w('- **timebase**: `CrankTimebase(t0, angle, speed_rpm, accel, max_speed_rpm).sample(t_ns)` '
      '(`mech_kinematics/timebase.py`, what the node uses): integer nanoseconds, exact wrap.')
    w('- **naive**: `angle += omega * dt` with `omega = rpm * pi / 30`, `dt = 1e-3`, never '
      'wrapped. Computed exactly for every tick by `naive_accumulate` (inside a binade '
      'each addition adds the same rounded step, so a whole binade is one exact rational '
      'step); checked equal, bit for bit, to tick-by-tick `np.add.accumulate` over the '
      f"first {clock_check['brute_ticks']:,} ticks: "
      f"{'equal' if clock_check['brute_equal'] else 'NOT EQUAL'}.")
    w(f'- **naive, wrapped**: the same with `angle = math.remainder(angle + omega * dt, '
      f'2 * math.pi)`. Simulated tick by tick up to {mode.clock_wrapped_ticks:,} ticks; '
      'beyond (rows marked *) extrapolated linearly with the error rate fitted on the '
      'simulation (each turn rounds the same way, binade by binade, and every tick adds '
      'the rounding of omega * dt, so the error grows linearly; a rate fitted on the '
      'first fifth of the simulation misses its end by '
      + ', '.join(f'{100 * v:.2g} % at {k:g} rpm'
                  for k, v in clock_check['wrapped_fit'].items())
      + ').')
    w('')
    w('State error: worst relative error of everything published (joint angles, rates, '
      'accelerations, points) at that instant against the reference at the exact angle.')
    w('')
    w('![clock](clock.png)')
    w('')
    w('| run time | rpm | angle error, timebase [rad] | naive | naive, wrapped | '
      'state error, timebase | naive | naive, wrapped |')
    w('|---|---|---|---|---|---|---|---|')
    for row in clock:
        star = '*' if row.wrapped_model else ''
        w(f'| {row.duration} | {row.rpm:g} | {_e(row.angle_error["timebase"])} | '
          f'{_e(row.angle_error["naive"])} | {_e(row.angle_error["naive, wrapped"])}{star} | '
          f'{_e(row.state_error["timebase"])} | {_e(row.state_error["naive"])} | '
          f'{_e(row.state_error["naive, wrapped"])}{star} |')
    w('')

    # 4
    w('## 4. Stiff and extreme cases')
    w('')
    w('Per case, the worst of its crank instants: the relative error per kind against the '
      '50-digit reference; the condition number kappa of the problem (sensitivity of '
      'the state to relative perturbations of every input: lengths, ground coordinates, '
      'crank angle, speed, acceleration, computed with the reference); the measure '
      "(`state.singularity`, smallest over dyads: the solver's value, and the exact "
      f'one); the flag (`NearSingularWarning` below {NEAR_SINGULAR:g}, `AssemblyError` at '
      f'or below {SINGULAR:g} or when the mechanism cannot close). Bound: error <= '
      f'{BOUND_FACTOR:g} x eps x max(1, kappa) for every kind.')
    w('')
    w('![extreme cases](extreme.png)')
    w('')
    w('| # | case | instants | reference | measure (solver) | measure (exact) | flag | '
      'worst error: position / angle | velocity / angular | acceleration / angular | '
      'eps x kappa (worst kind) | error / (eps kappa) | verdict |')
    w('|---|---|---|---|---|---|---|---|---|---|---|---|---|')
    for i, r in enumerate(extreme):
        e, kappa = r.errors, r.kappa

        def pair(a: str, b: str, e: dict[str, float] = e) -> str:
            return f'{_e(e[a])} / {_e(e[b])}' if e else '-'

        worst_kind = max(e, key=lambda k: e[k] / (EPS * max(1.0, kappa[k]))) if e else None
        ek = _e(EPS * max(1.0, kappa[worst_kind])) if worst_kind else '-'
        w(f'| {i + 1} | {r.case.name} | {len(r.case.angles)} | {r.reference} | '
          f'{_e(r.measure_solver)} | {_e(r.measure_exact)} | {r.flag} | '
          f'{pair("position", "angle")} | {pair("velocity", "angular velocity")} | '
          f'{pair("acceleration", "angular acceleration")} | {ek} | {_e(r.ratio)} | '
          f'**{r.verdict}** |')
    w('')
    for i, r in enumerate(extreme):
        if r.case.note:
            w(f'{i + 1}. {r.case.name}: {r.case.note}.')
    w('')
    w('### Digits lost against the near-singularity measure')
    w('')
    w('`linkage.NEAR_SINGULAR` documents that velocities lose about -log10(measure) digits '
      'and accelerations up to three times that. Measured: log10 of error / eps, at the '
      'instant of each case that loses most velocity digits among those whose measure is '
      'below 0.1:')
    w('')
    w('| # | case | measure | -log10(measure) | digits lost: velocity | angular velocity | '
      'acceleration | angular acceleration | velocity / -log10(measure) |')
    w('|---|---|---|---|---|---|---|---|---|')
    ratios = {'velocity': 0.0, 'acceleration': 0.0}
    for r, mu, lost in digits_lost(extreme):
        for kind in ratios:
            ratios[kind] = max(ratios[kind], lost[kind] / -math.log10(mu))
        w(f'| {extreme.index(r) + 1} | {r.case.name} | {_e(mu)} | {-math.log10(mu):.2f} | '
          f'{lost["velocity"]:.1f} | {lost["angular velocity"]:.1f} | '
          f'{lost["acceleration"]:.1f} | {lost["angular acceleration"]:.1f} | '
          f'{lost["velocity"] / -math.log10(mu):.2f} |')
    w('')
    w(f'Velocities lose up to {ratios["velocity"]:.1f} x -log10(measure) digits and '
      f'accelerations up to {ratios["acceleration"]:.1f} x: near a toggle the condition '
      'number of the velocities grows as 1/measure^2 (kappa in the table above). That is '
      'the problem, not the formulas (the error stays at eps x kappa), but the docstring '
      'of `NEAR_SINGULAR` (velocities lose about -log10(measure) digits) understates the '
      'loss by about a factor of two.')
    w('')
    w('### Formula audit (before / after)')
    w('')
    w('Where could the closed forms lose more than the conditioning? The candidates are '
      'the ones the issue names: an `acos` near +-1, a difference of squares cancelling, '
      'an `atan` where `atan2` belongs. `linkage.py` takes every angle with `atan2` of a '
      "unit vector (no `atan`, no `acos` anywhere) and the RRR height h (the new pin's "
      'distance from the line of centres) as sqrt of a product of four factors. The table '
      'puts that product against the two textbook forms, `l1 sin(acos(cos gamma))` by the '
      'law of cosines and `sqrt(l1^2 - p^2)`, near the toggle of cases 1-4: relative error '
      'of h from the same doubles against its 50-digit value.')
    w('')
    w('| case | exact measure | ' + ' | '.join(audit[0].errors) + ' |')
    w('|---|---|' + '---|' * len(audit[0].errors))
    for a in audit:
        w(f'| {a.case} | {_e(a.measure)} | ' + ' | '.join(_e(v) for v in a.errors.values())
          + ' |')
    w('')
    w('All three are within a factor of about 3 of each other and of eps x kappa: at a '
      'toggle h is ill-conditioned in its inputs (kappa ~ 1/measure^2 for h), so the '
      'rounding of |BD| from the crank angle dominates whichever form is used. The '
      "product form's advantage (no cancellation of its own) is real but small here; "
      'no rewrite would lower these errors.')
    w('')
    fails = [r for r in extreme if r.verdict == 'FAIL']
    if fails:
        w('**Cases outside their bound without a flag:** '
          + ', '.join(r.case.name for r in fails) + '.')
    else:
        w('No case exceeds its bound unflagged, so no formula of `linkage.py` needs a '
          'change: where errors are large (toggles, the change point, the pin at the '
          "pivot) they match eps x kappa, i.e. the inputs' own rounding, and the solver "
          'flags them.')
    w('')

    # 5
    w('## 5. Cost growth')
    w('')
    w('![cost growth](cost.png)')
    w('')
    w(f'| angles N | time per configuration, one call | in calls of {CHUNK} angles |')
    w('|---|---|---|')
    chunked = dict(cost.chunked)
    for n, s in cost.batch:
        w(f'| {n:,} | {_t(s)} | {_t(chunked[n]) if n in chunked else "-"} |')
    w(f'| 1 (scalar path) | {_t(cost.single)} | - |')
    w('')
    best = min(s for _, s in cost.batch)
    w(f'Fitted: total time ~ N^{cost.batch_slope:.3f} for N >= 1e3. The array path has a '
      f'fixed cost of about {_t(cost.batch[0][1])} per call (Python and NumPy overhead of '
      f'the vector steps), so one angle is cheaper through the scalar path '
      f'({_t(cost.single)}). Per configuration it is cheapest around 1e4 angles '
      f'({_t(best)}); beyond, it grows again as the intermediate arrays outgrow the caches '
      f'(a 1e5-angle complex array is 1.6 MB; each batch is solved once before timing, so '
      f'first-touch page faults are not counted). Solving a large batch '
      f'in calls of {CHUNK} angles keeps the cost at the 1e4 level'
      + (f' ({_t(cost.chunked[-1][1])} against {_t(cost.batch[-1][1])} per configuration '
         f'at N = {cost.batch[-1][0]:,}).' if cost.chunked else '.'))
    w('')
    w('| dyads in the chain | array path, per configuration | one angle |')
    w('|---|---|---|')
    for (n, s), (_, s1) in zip(cost.chain_array, cost.chain_single, strict=True):
        w(f'| {n} | {_t(s)} | {_t(s1)} |')
    w('')
    w(f'{mode.chain_angles:,} angles per array call. Fitted from 4 dyads on: time ~ '
      f'dyads^{cost.chain_slope_array:.3f} (arrays), ^{cost.chain_slope_single:.3f} (one '
      f'angle); {_t(cost.per_dyad_array)} and {_t(cost.per_dyad_single)} per added dyad '
      '(with its carried point), from a straight-line fit. Each stage adds one RRR dyad, '
      'one carried point and their outputs, so linear growth is a slope of 1. The array '
      'batch is kept cache-sized: at 1e4 angles per call the long chains slow down '
      'further, as in the batch table above.')
    w('')
    path = outdir / 'REPORT.md'
    path.write_text('\n'.join(lines), encoding='utf-8')
    return path


def _slug(text: str) -> str:
    return ''.join(ch if ch.isalnum() else '_' for ch in text.lower()).strip('_')


def run(outdir: str | os.PathLike[str], mode: str | Mode = 'full',
        progress: bool = True) -> dict[str, Any]:
    """Compute every section, draw the figures and write ``outdir/REPORT.md``.

    Returns the computed sections (the tests read them).
    """
    mode = MODES[mode] if isinstance(mode, str) else mode
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    from ..scene import scene_names
    n_checks = len(mode.check_scenes or scene_names())
    total = (n_checks + 1 + 5 * len(mode.wp_mechanisms) + len(mode.clock_rpms) + 1
             + len(mode.batch_sizes) + len(mode.chain_lengths) + 1)
    with _progress(total, progress) as bar:
        def tick() -> None:
            bar.update(1)

        bar.set_description('reference')
        checks = reference_checks(mode, tick)
        golden = golden_checks()
        tick()
        wp = []
        for mechanism in mode.wp_mechanisms:
            bar.set_description(f'work-precision {mechanism}')
            wp.append(work_precision(mechanism, mode, tick))
        bar.set_description('clock')
        clock, clock_check = clock_errors(mode, tick=tick)
        bar.set_description('extreme cases')
        extreme = [evaluate_case(case) for case in extreme_cases(mode)]
        audit = formula_audit()
        tick()
        bar.set_description('cost growth')
        cost = cost_growth(mode, tick)
        bar.set_description('figures')
        for result in wp:
            plot_work_precision(result, out / f'wp_{_slug(result.mechanism)}.png')
        plot_clock(clock, out / 'clock.png')
        plot_extreme(extreme, out / 'extreme.png')
        plot_cost(cost, out / 'cost.png')
        tick()
    elapsed = time.perf_counter() - start
    write_report(out, mode, checks, golden, wp, clock, clock_check, extreme, audit, cost,
                 elapsed)
    return {'checks': checks, 'golden': golden, 'work_precision': wp, 'clock': clock,
            'clock_check': clock_check, 'extreme': extreme, 'audit': audit, 'cost': cost,
            'elapsed': elapsed}


# --- command line ------------------------------------------------------------------

REPORT_HELP = """\
Measure the solver's error against its cost and its stability on stiff and
extreme cases, and write DIR/REPORT.md with PNG figures: the 50-digit
reference and its checks, work-precision diagrams against Newton-Raphson,
finite differences and solve_ivp, the node's crank-angle error over long runs,
the extreme-case table, and cost growth. A few minutes; --quick in under one.
"""


def _handle(args: argparse.Namespace) -> int:
    run(args.output, args.mode, progress=not args.no_progress)
    print(Path(args.output) / 'REPORT.md')
    return 0


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register the ``report`` command on ``python -m mech_kinematics``'s subparsers."""
    parser = subparsers.add_parser('report', help='error against cost, extreme cases: '
                                                  'write DIR/REPORT.md and figures',
                                   description=REPORT_HELP,
                                   formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('-o', '--output', required=True, metavar='DIR',
                        help='folder for REPORT.md and the PNG figures (created)')
    size = parser.add_mutually_exclusive_group()
    size.add_argument('--quick', dest='mode', action='store_const', const='quick',
                      help='a subset, under a minute')
    size.add_argument('--smoke', dest='mode', action='store_const', const='smoke',
                      help='the smallest run that fills every section (for tests)')
    parser.add_argument('--no-progress', action='store_true', help='no progress bar')
    parser.set_defaults(handler=_handle, mode='full')
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``report``; return the exit status."""
    return run_tool(add_parser, argv)


if __name__ == '__main__':
    sys.exit(main())
