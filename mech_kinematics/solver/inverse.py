# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Driven from the output: a scene solved for targets instead of its drivers' values.

A *target* is a reported joint's value (a link's absolute angle, rad, or a
slider's position, m: any joint the scene reports, a driver's own included)
or one coordinate of a reported point (``P.x``, ``P.y``, m in the ground
frame). A scene with ``n`` drivers takes ``n`` targets; :func:`solve_targets`
returns the drivers' values (and rates) that put the targets there, with
the whole forward state at them.

How. The forward solve is closed form; its velocities at a unit speed of
driver ``j`` (every other driver at rest) are column ``j`` of the Jacobian
``J = d target / d driver``, exact to their bounds, because a linkage's
velocities are linear in its drivers' speeds. The drivers' values are found
by Newton's method on the forward solve, ``q <- q - J^-1 (f(q) - t)``,
*continued* from a start pose (the scene's start positions, or the caller's)
along the straight path in target space from the targets there to the ones
given: each step is taken only if Newton converges from the last pose
without a jump of the drivers (so the assembly answered, the working mode of
a five-bar say, is the one continued from the start pose; another start pose
chooses another), and a step that fails is halved. When the steps shrink
below a millionth of the path, the rest is out of reach: the refusal says how
far, per target. The rates follow in closed form: ``J qd = td``, and with
``a0`` the targets' accelerations at ``(q, qd, 0)`` (the velocity-product
terms), ``J qdd = tdd - a0``.

Bounds. The returned state is the forward solve at the drivers' values
answered, with its own bounds (exact drivers). What the inverse adds is
bounded beside it, to first order: the drivers' values' error against the
exact inverse, ``|J^-1| (|f(q) - t| + b)`` with ``b`` the targets' forward
bounds (and likewise for the rates, with ``J``'s bounds); the targets reached
with their bounds. An answer whose drivers' bound exceeds ``max_error`` of
its scale (near a singular point of the map, where the drivers lose control
of the targets) is refused, as a forward solve refuses its values.

Forces along targets (``forces=``): the efforts the drivers must apply for
the mechanism to exert a force (or torque) ``F`` along each target,
``tau = J^T F`` (virtual work: ``tau . dq = F . dt``).

Not re-rooted: the inverse is iterative over the closed-form forward solve
(3 to 5 forward solves per Newton iteration's worth of columns), not a
closed-form re-rooting of the loop's Assur groups; docs/targets.md says so.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
import itertools
import math
from typing import Any, TYPE_CHECKING
import warnings

import numpy as np
import numpy.typing as npt

from ..bounds import MAX_ERROR
from ..errors import AssemblyError, NearSingularWarning, TargetError

if TYPE_CHECKING:
    from .mechanism import Scene
    from .state import State

__all__ = ['Inverse', 'TargetMap', 'check_branch', 'continue_to', 'in_mode', 'parse_branch',
           'scene_targets', 'solve_targets']

#: Newton iterations tried per continuation step before the step is halved.
_ITERATIONS = 12
#: The smallest continuation step, as a share of the path, before the rest is out of reach.
_SMALLEST_STEP = 2.0 ** -20
#: The largest Newton correction of a driver (rad, or this share of the size for a length).
_LARGEST_CHANGE = 1.0
#: How close an intermediate step's targets must come (share of each target's scale).
_ON_THE_WAY = 1e-9
#: About how many start poses a working mode is sought among (:func:`in_mode`), and how
#: many of those in the mode asked are continued from before the mode is refused.
_MODE_GRID = 1728
_MODE_TRIES = 8
#: The residual (share of each target's scale) below which the answer is taken whatever the
#: bounds say: the contract's 1e-12 of the loop size, with room.
_ARRIVED = 1e-13


@dataclass(frozen=True)
class TargetMap:
    """What a forward map exposes to the inverse: names, kinds and one evaluation.

    ``evaluate(q, qd, qdd, max_error)`` returns ``(answer, values, bounds)``:
    the forward answer at the drivers' values ``q`` (SI floats, one per
    driver), speeds ``qd`` and accelerations ``qdd``, and for each target its
    (position, velocity, acceleration) and their bounds, arrays of shape (m, 3);
    it raises :class:`~mech_kinematics.errors.AssemblyError` where the loop
    cannot be solved. ``angular`` says which targets and which drivers are
    angles (a residual of an angle is taken modulo a turn); ``scales`` are
    the targets' and drivers' position scales (1 rad, the size in m); ``text``
    writes a target's value for a message (in a scene's units).
    """

    targets: tuple[str, ...]
    drivers: tuple[str, ...]
    target_angular: tuple[bool, ...]
    driver_angular: tuple[bool, ...]
    target_scales: tuple[float, ...]
    driver_scales: tuple[float, ...]
    evaluate: Callable[[Sequence[float], Sequence[float], Sequence[float], float],
                       tuple[Any, npt.NDArray[np.float64], npt.NDArray[np.float64]]]
    text: Callable[[int, float], str]     # (target index, SI value) -> text, for messages
    #: What a working mode is read from (``branch=``): the revolute joints between two
    #: moving bodies whose sign a caller may ask, and each one's angle in an answer
    #: (``elbow(answer, joint)``, rad wrapped to (-pi, pi]).
    elbows: tuple[str, ...]
    elbow: Callable[[Any, str], float]
    #: Each driver's sweep (rad or m: a turn, or its stroke): where start poses are sought.
    driver_domains: tuple[tuple[float, float], ...]


@dataclass(frozen=True)
class Inverse:
    """A loop solved for its targets: the drivers' motion, the forward answer, the Jacobian.

    Attributes
    ----------
    answer : State or RobotState
        The forward solve at the drivers' values found, with their rates.
    targets, drivers : tuple of str
        The targets' names (rows) and the drivers' (columns).
    given : ndarray, shape (m, 3)
        The targets' position, velocity and acceleration asked (SI).
    reached : ndarray, shape (m, 3)
        The targets' position, velocity and acceleration in ``answer``.
    reached_bound : ndarray, shape (m, 3)
        Bounds of ``reached`` against the exact forward values.
    motion : ndarray, shape (n, 3)
        The drivers' position, speed and acceleration answered (SI).
    motion_bound : ndarray, shape (n, 3)
        First-order bounds of ``motion`` against the exact inverse.
    jacobian : ndarray, shape (m, n)
        ``d target / d driver`` at the answer (SI).
    inverse : ndarray, shape (n, m)
        Its inverse: ``d driver / d target``.
    start : ndarray, shape (n,)
        The drivers' values the answer was continued from.
    steps : int
        Continuation steps taken.
    target_efforts : dict of str to float
        With ``forces=``: each driver's effort ``(J^T F)`` for the forces along targets.
    target_forces : dict of str to float
        The forces along targets given (N, or N m along an angle).
    columns : tuple
        The drivers' values answered with the targets and the Jacobian there:
        what :func:`continue_to` takes as ``known`` to continue from them.
    branch : dict of str to float
        With ``branch=``: the angle (rad, wrapped to (-pi, pi]) at the answer of
        each joint whose sign was asked.
    """

    answer: Any
    targets: tuple[str, ...]
    drivers: tuple[str, ...]
    given: npt.NDArray[np.float64]
    reached: npt.NDArray[np.float64]
    reached_bound: npt.NDArray[np.float64]
    motion: npt.NDArray[np.float64]
    motion_bound: npt.NDArray[np.float64]
    jacobian: npt.NDArray[np.float64]
    inverse: npt.NDArray[np.float64]
    start: npt.NDArray[np.float64]
    steps: int
    target_forces: dict[str, float]
    target_efforts: dict[str, float]
    columns: Any = None
    branch: dict[str, float] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        """Return what ``solve --target`` adds to the forward answer's JSON."""
        def rows(x: npt.NDArray[np.float64], names: tuple[str, ...]) -> dict[str, Any]:
            return {name: {'position': float(r[0]), 'velocity': float(r[1]),
                           'acceleration': float(r[2])} for name, r in zip(names, x, strict=True)}

        return {
            'targets': {name: {'given': {'position': float(g[0]), 'velocity': float(g[1]),
                                         'acceleration': float(g[2])},
                               'reached': {'position': float(r[0]), 'velocity': float(r[1]),
                                           'acceleration': float(r[2])}}
                        for name, g, r in zip(self.targets, self.given, self.reached,
                                              strict=True)},
            'jacobian': {'rows': list(self.targets), 'columns': list(self.drivers),
                         'matrix': self.jacobian.tolist(), 'inverse': self.inverse.tolist()},
            'continued_from': {name: float(x)
                               for name, x in zip(self.drivers, self.start, strict=True)},
            **({'target_forces': dict(self.target_forces),
                'target_efforts': dict(self.target_efforts)} if self.target_forces else {}),
            **({'branch': {name: {'sign': int(math.copysign(1.0, angle)), 'angle': angle}
                           for name, angle in self.branch.items()}} if self.branch else {}),
        }

    def bound_dict(self) -> dict[str, Any]:
        """Return what ``solve --target`` adds under ``"error_bound"``."""
        return {'targets': {name: [float(x) for x in b]
                            for name, b in zip(self.targets, self.reached_bound, strict=True)},
                'inverse': {name: [float(x) for x in b]
                            for name, b in zip(self.drivers, self.motion_bound, strict=True)}}


def _residual(values: npt.NDArray[np.float64], goal: npt.NDArray[np.float64],
              angular: npt.NDArray[np.bool_]) -> npt.NDArray[np.float64]:
    """Return ``values - goal``, an angle's difference taken modulo a turn."""
    diff = values - goal
    return np.where(angular, np.remainder(diff + math.pi, math.tau) - math.pi, diff)


def continue_to(tmap: TargetMap, goal: Sequence[float], start: Sequence[float],
                speeds: Sequence[float] | None = None, accels: Sequence[float] | None = None,
                *, max_error: float = MAX_ERROR,
                forces: Mapping[str, float] | None = None, known: Any = None,
                answer: bool = True, branch: Mapping[str, int] | None = None) -> Inverse:
    """Return the drivers' motion putting ``tmap``'s targets at ``goal``, continued from ``start``.

    ``goal``, ``speeds`` and ``accels``: the targets' positions, velocities and
    accelerations (SI, default at rest); ``start``: the drivers' values to
    continue from. Raises :class:`~mech_kinematics.errors.TargetError` for a
    goal out of reach or one whose answer cannot be trusted.

    ``known``: a former answer's :attr:`Inverse.columns` (the targets and the
    Jacobian at its drivers' values), not solved again where ``start`` is
    those values: a stream of targets continues from its last answer.
    ``answer=False``: for a caller that solves the state itself (the node),
    the forward answer and the accelerations are not solved (``answer`` None,
    the accelerations and their bounds NaN); the drivers' values and speeds,
    their bounds and the singular-point refusal are the same.
    ``branch``: the working mode asked, joint -> +1 or -1 (:func:`in_mode`).
    """
    if branch:
        return in_mode(tmap, goal, start, speeds, accels, branch, max_error=max_error,
                       forces=forces, answer=answer)
    m, n = len(tmap.targets), len(tmap.drivers)
    t_ang = np.array(tmap.target_angular, dtype=bool)
    t_scale = np.array(tmap.target_scales)
    q_scale = np.array(tmap.driver_scales)
    goal_a = np.array(goal, dtype=np.float64)
    td = np.zeros(m) if speeds is None else np.array(speeds, dtype=np.float64)
    tdd = np.zeros(m) if accels is None else np.array(accels, dtype=np.float64)
    q = np.array(start, dtype=np.float64)
    zeros = [0.0] * n
    #: The last drivers' values columns() solved at, and its answer: a Newton start (the
    #: start pose, the last point reached) is where the path or the last step solved.
    last: list[Any] = [None, None]
    if known is not None and np.array_equal(known[0], q):
        last[:] = [np.array(known[0], dtype=np.float64), known[1]]

    def columns(x: npt.NDArray[np.float64]) -> tuple[Any, Any, Any]:
        """Return the targets' values and bounds at ``x`` and the Jacobian with its bounds."""
        if last[0] is not None and np.array_equal(last[0], x):
            return last[1]
        jac = np.empty((m, n))
        jac_b = np.empty((m, n))
        values = bounds = None
        for j in range(n):
            unit = [0.0] * n
            unit[j] = 1.0
            _, vals, bnds = tmap.evaluate(list(x), unit, zeros, math.inf)
            jac[:, j], jac_b[:, j] = vals[:, 1], bnds[:, 1]
            if values is None:
                values, bounds = vals[:, 0], bnds[:, 0]
        last[:] = [x.copy(), (values, bounds, (jac, jac_b))]
        return values, bounds, (jac, jac_b)

    def newton(x0: npt.NDArray[np.float64], target: npt.NDArray[np.float64],
               tol: float) -> tuple[Any, Any] | None:
        """Return (x, its columns) converged from ``x0`` onto ``target``, or None.

        None where the loop cannot be solved on the way, where the corrections
        do not shrink by half each time (a jump towards another assembly, or
        beyond reach), or where ``det J`` changes sign (a singular point crossed).
        """
        x = x0.copy()
        last = math.inf
        sign = 0.0
        for _ in range(_ITERATIONS):
            try:
                values, bounds, (jac, jac_b) = columns(x)
            except AssemblyError:
                return None
            det = float(np.linalg.det(jac))
            if sign == 0.0:
                sign = math.copysign(1.0, det)
            elif det * sign <= 0.0:
                return None
            r = _residual(values, target, t_ang)
            if float(np.max(np.abs(r) / t_scale)) <= tol or np.all(np.abs(r) <= bounds):
                return x, (values, bounds, jac, jac_b)
            try:
                dx = np.linalg.solve(jac, r)
            except np.linalg.LinAlgError:
                return None
            change = float(np.max(np.abs(dx) / q_scale))
            if not math.isfinite(change) or change > _LARGEST_CHANGE or change > last / 2.0:
                return None
            last = change
            x = x - dx
        return None

    with warnings.catch_warnings():
        warnings.simplefilter('ignore', NearSingularWarning)
        try:
            here, _, _ = columns(q)
        except AssemblyError as error:
            msg = f'Expected a start pose at which the loop closes, got one where {error}'
            raise TargetError(msg) from None
        path = _residual(goal_a, here, t_ang)          # goal - here, angles the short way
        origin = here
        done, step, steps = 0.0, 1.0, 0
        found = None
        while found is None:
            s = min(1.0, done + step)
            final = s >= 1.0
            target = goal_a if final else origin + s * path
            got = newton(q, target, _ARRIVED if final else _ON_THE_WAY)
            if got is None:
                step /= 2.0
                if step < _SMALLEST_STEP:
                    short = (1.0 - done) * path
                    words = ', '.join(f'{name} by {_shown(short[i], tmap, i)}'
                                      for i, name in enumerate(tmap.targets) if short[i] != 0.0)
                    msg = (f'Expected targets within reach, got {_goal_text(tmap, goal_a)} out of '
                           f'reach: the loop follows the straight path from the start pose only '
                           f'{100.0 * done:.4g} % of the way, short of it {words}')
                    raise TargetError(msg, reached=done, short=dict(zip(
                        tmap.targets, (float(x) for x in short), strict=True)))
                continue
            q, steps = got[0], steps + 1
            done = s
            step = min(1.0, 2.0 * step)
            if final:
                found = got[1]
        values, bounds, jac, jac_b = found
        inv = np.linalg.inv(jac)
        residual = np.abs(_residual(values, goal_a, t_ang))
        q_bound = np.abs(inv) @ (residual + bounds)
        qd = inv @ td
        if answer:
            _, vals, bnds = tmap.evaluate(list(q), list(qd), zeros, math.inf)
            qdd = inv @ (tdd - vals[:, 2])
        else:
            qdd = np.full(n, math.nan)
            bnds = np.full((m, 3), math.nan)
    # First order: J's bounds times the rates, and a0's bounds (the rates' own error in a0
    # and J's change with q's error are of second order).
    qd_bound = np.abs(inv) @ (jac_b @ np.abs(qd))
    qdd_bound = np.abs(inv) @ (jac_b @ np.abs(qdd) + bnds[:, 2])
    relative = q_bound / q_scale
    if np.any(relative > max_error):
        worst = int(np.argmax(relative))
        msg = (f'Expected targets the drivers control, got {_goal_text(tmap, goal_a)} near a '
               f"singular point of the inverse map: driver {tmap.drivers[worst]}'s value has "
               f'an error bound of {relative[worst]:.3g} of its scale (max_error {max_error:g}; '
               f'det J = {np.linalg.det(jac):.3g})')
        raise TargetError(msg)
    state = None
    if answer:
        try:
            state, vals, bnds = tmap.evaluate(list(q), list(qd), list(qdd), max_error)
        except AssemblyError as error:
            msg = f'Expected an answer that can be trusted, got {error}'
            raise TargetError(msg) from None
    else:       # what the columns at the answer give: positions, and velocities J qd
        vals = np.stack((values, jac @ qd, np.full(m, math.nan)), axis=1)
        bnds = np.stack((bounds, jac_b @ np.abs(qd), np.full(m, math.nan)), axis=1)
    force_list = dict(forces or {})
    unknown = [name for name in force_list if name not in tmap.targets]
    if unknown:
        msg = (f'Expected forces along targets ({", ".join(tmap.targets)}), got '
               f'{", ".join(unknown)}')
        raise TargetError(msg)
    f_vec = np.array([force_list.get(name, 0.0) for name in tmap.targets])
    efforts = jac.T @ f_vec
    return Inverse(
        answer=state, targets=tmap.targets, drivers=tmap.drivers,
        given=np.stack((goal_a, td, tdd), axis=1), reached=vals,
        reached_bound=bnds,
        motion=np.stack((q, qd, qdd), axis=1),
        motion_bound=np.stack((q_bound, qd_bound, qdd_bound), axis=1),
        jacobian=jac, inverse=inv, start=np.array(start, dtype=np.float64), steps=steps,
        target_forces=force_list,
        target_efforts={name: float(e) for name, e in zip(tmap.drivers, efforts, strict=True)}
        if force_list else {}, columns=(q.copy(), (values, bounds, (jac, jac_b))))


def _mode_of(tmap: TargetMap, q: Sequence[float], joints: Sequence[str]
             ) -> tuple[tuple[int, ...], tuple[float, ...]] | None:
    """Return the signs (+1, -1; 0 stretched or folded) and angles of ``joints`` at ``q``."""
    zeros = [0.0] * len(tmap.drivers)
    try:
        state, _, _ = tmap.evaluate(list(q), zeros, zeros, math.inf)
    except AssemblyError:
        return None
    angles = tuple(float(tmap.elbow(state, joint)) for joint in joints)
    return tuple(int(np.sign(a)) if abs(a) < math.pi else 0 for a in angles), angles


def _starts(tmap: TargetMap, start: Sequence[float]) -> list[npt.NDArray[np.float64]]:
    """Return start poses to seek a working mode from: ``start``, then a grid nearest first.

    Each angular driver at ``start`` plus whole twelfths of a turn (within half a
    turn either way), each linear one at points of its sweep; at most about
    :data:`_MODE_GRID` poses.
    """
    n = len(tmap.drivers)
    first = np.array(start, dtype=np.float64)
    count = max(3, round(_MODE_GRID ** (1.0 / n)))
    axes = []
    for x, angular, (low, high) in zip(first, tmap.driver_angular, tmap.driver_domains,
                                       strict=True):
        if angular:
            turns = min(12, count)
            axes.append([float(x) + math.tau * k / turns
                         for k in range(-(turns // 2), turns - turns // 2)])
        else:
            axes.append([float(v) for v in np.linspace(low, high, count + 2)[1:-1]])
    scales = np.array(tmap.driver_scales)
    angular = np.array(tmap.driver_angular, dtype=bool)

    def distance(q: npt.NDArray[np.float64]) -> float:
        return float(np.sum((_residual(q, first, angular) / scales) ** 2))

    grid = sorted((np.array(q) for q in itertools.product(*axes)), key=distance)
    return [first] + [q for q in grid if not np.array_equal(q, first)]


def parse_branch(text: str) -> tuple[str, int]:
    """Return ``JOINT=+1|-1`` (or ``+``, ``-``) as (joint, sign); ValueError says why not."""
    name, sep, value = text.rpartition('=')
    signs = {'+1': 1, '+': 1, '1': 1, '-1': -1, '-': -1}
    if not sep or not name or value.strip() not in signs:
        msg = f"expected JOINT=+1 or JOINT=-1 (the sign of the joint's angle), got {text!r}"
        raise ValueError(msg)
    return name, signs[value.strip()]


def check_branch(tmap: TargetMap, branch: Mapping[str, int], flag: str = '--branch') -> None:
    """Refuse (TargetError) a working mode naming a joint ``tmap`` cannot read, or a bad sign."""
    unknown = [j for j in branch if j not in tmap.elbows]
    if unknown:
        msg = (f'Expected {flag} to name joints between two moving bodies '
               f'({", ".join(tmap.elbows) or "none"}), got {", ".join(unknown)}')
        raise TargetError(msg)
    bad = [f'{j}={branch[j]}' for j in branch if branch[j] not in (1, -1)]
    if bad:
        msg = f'Expected {flag} JOINT=+1 or JOINT=-1, got {", ".join(bad)}'
        raise TargetError(msg)


def in_mode(tmap: TargetMap, goal: Sequence[float], start: Sequence[float],
            speeds: Sequence[float] | None, accels: Sequence[float] | None,
            branch: Mapping[str, int], *, max_error: float = MAX_ERROR,
            forces: Mapping[str, float] | None = None, answer: bool = True) -> Inverse:
    """Return the answer of :func:`continue_to` in the working mode ``branch`` asks.

    A *working mode* is read from joints between two moving bodies (an elbow of
    a five-bar's leg): ``branch`` maps each joint named to the sign asked of
    its angle (wrapped to (-pi, pi]; a scene's pin: the angle of its body's
    frame from its parent's; a URDF joint: its value). The answer is continued
    from ``start`` where ``start`` is in that mode and reaches the goal in it;
    otherwise from the nearest start pose in that mode on a grid of the
    drivers (:func:`_starts`) that does, the first :data:`_MODE_TRIES` of them
    tried. Continuation keeps a working mode (it crosses no ``det J = 0``),
    and the signs are checked at the answer.
    """
    joints = tuple(branch)
    check_branch(tmap, branch)
    wanted = tuple(int(branch[j]) for j in joints)
    asked = ', '.join(f'{j} {"+" if s > 0 else "-"}' for j, s in zip(joints, wanted, strict=True))
    tried = 0
    reason = ''
    for q0 in _starts(tmap, start):
        here = _mode_of(tmap, q0, joints)
        if here is None or here[0] != wanted:
            continue
        tried += 1
        try:
            found = continue_to(tmap, goal, q0, speeds, accels, max_error=max_error,
                                forces=forces, answer=answer)
        except TargetError as error:
            reason = str(error)
        else:
            there = _mode_of(tmap, found.motion[:, 0], joints)
            if there is not None and there[0] == wanted:
                return replace(found, branch=dict(zip(joints, there[1], strict=True)))
            reason = 'the continuation left that mode'
        if tried >= _MODE_TRIES:
            break
    where = (f'{tried} start pose{"s" if tried != 1 else ""} in it tried, the last: {reason}'
             if tried else 'no start pose on the grid of the drivers is in it')
    msg = (f'Expected targets reached in the working mode asked ({asked}), got '
           f'{_goal_text(tmap, np.array(goal, dtype=np.float64))} not reached in it: {where}')
    raise TargetError(msg)


def _shown(value: float, tmap: TargetMap, index: int) -> str:
    """Return a target's value (SI) as text in the map's units."""
    return tmap.text(index, value)


def _goal_text(tmap: TargetMap, goal: npt.NDArray[np.float64]) -> str:
    """Return the targets asked as text: ``P.x = 0.02 m, P.y = 0.2 m``."""
    return ', '.join(f'{name} = {_shown(float(g), tmap, i)}'
                     for i, (name, g) in enumerate(zip(tmap.targets, goal, strict=True)))


def scene_targets(scene: Scene, names: Sequence[str]) -> TargetMap:
    """Return the target map of ``scene`` for the targets ``names`` (joints and ``POINT.x|y``).

    Raises :class:`~mech_kinematics.errors.TargetError` for a name the scene
    does not report, or a count other than its drivers'.
    """
    from .solve import solve

    drivers = scene.drivers
    driver_names = tuple(d.name for d in drivers)
    if len(names) != len(drivers):
        msg = (f'Expected as many targets as the scene has drivers ({len(drivers)}: '
               f'{", ".join(driver_names)}), got {len(names)}: {", ".join(names) or "none"}')
        raise TargetError(msg)
    if len(set(names)) != len(names):
        msg = f'Expected each target once, got {", ".join(names)}'
        raise TargetError(msg)
    probe = solve(scene, *_driver_args(scene, [d.start for d in drivers], [0.0] * len(drivers),
                                       [0.0] * len(drivers)), max_error=math.inf)
    size = probe.error_bound.size
    readers: list[tuple[str, str, int]] = []    # (table, name, axis)
    angular: list[bool] = []
    for name in names:
        point, dot, axis = name.rpartition('.')
        if name in probe.joints:
            readers.append(('joint', name, 0))
            angular.append(probe.joints[name].type.angular)
        elif dot and point in probe.complex_points and axis in ('x', 'y'):
            readers.append(('point', point, 'xy'.index(axis)))
            angular.append(False)
        else:
            msg = (f'Expected a target to be a joint the scene reports '
                   f'({", ".join(probe.joints)}) or a coordinate of a point '
                   f'(POINT.x, POINT.y: {", ".join(probe.complex_points)}), got {name!r}')
            raise TargetError(msg)
    units = scene.units

    def evaluate(q: Sequence[float], qd: Sequence[float], qdd: Sequence[float],
                 max_error: float) -> tuple[State, Any, Any]:
        state = solve(scene, *_driver_args(scene, q, qd, qdd), max_error=max_error)
        joints, points = state.error_bound.raw()
        values = np.empty((len(readers), 3))
        bounds = np.empty((len(readers), 3))
        for i, (table, key, axis) in enumerate(readers):
            if table == 'joint':
                j = state.joints[key]
                values[i] = (j.position, j.velocity, j.acceleration)
                bounds[i] = joints[key]
            else:
                p, v, a = state.complex_points[key]
                values[i] = [(z.real, z.imag)[axis] for z in (p, v, a)]
                bounds[i] = points[key]
        return state, values, bounds

    def text(index: int, value: float) -> str:
        return units.angle_text(value) if angular[index] else units.length_text(value)

    graph = scene.graph
    pins = {joint.name: joint for joint in graph.joints
            if joint.type.angular and not joint.driver and joint.line is None
            and graph.bodies[joint.body].turns_with and graph.bodies[joint.on].turns_with}

    def elbow(state: State, name: str) -> float:
        """Return the angle of pin ``name``'s body's frame from its parent's, rad."""
        joint = pins[name]
        body, on = (graph.bodies[b].frame for b in (joint.body, joint.on))
        assert body is not None and on is not None and body.angle_of and on.angle_of
        turn = (float(state.joints[body.angle_of].position) + body.angle
                - float(state.joints[on.angle_of].position) - on.angle)
        return float(math.remainder(turn, math.tau))

    free = scene.free_length
    return TargetMap(
        targets=tuple(names), drivers=driver_names, target_angular=tuple(angular),
        driver_angular=tuple(d.joint_type.angular for d in drivers),
        target_scales=tuple(1.0 if a else size for a in angular),
        driver_scales=tuple(1.0 if d.joint_type.angular else size for d in drivers),
        evaluate=evaluate, text=text, elbows=tuple(pins), elbow=elbow,
        driver_domains=tuple(tuple(float(x) for x in d.sweep(free)) for d in drivers))


def _driver_args(scene: Scene, q: Sequence[float], qd: Sequence[float],
                 qdd: Sequence[float]) -> tuple[Any, Any, Any]:
    """Return :func:`~.solve.solve`'s positional driver arguments: bare for one driver."""
    if len(scene.drivers) == 1:
        return float(q[0]), float(qd[0]), float(qdd[0])
    return [float(x) for x in q], [float(x) for x in qd], [float(x) for x in qdd]


def solve_targets(scene: Scene, targets: Mapping[str, float],
                  speeds: Mapping[str, float] | None = None,
                  accels: Mapping[str, float] | None = None, *,
                  start: Sequence[float] | None = None, max_error: float = MAX_ERROR,
                  forces: Mapping[str, float] | None = None,
                  branch: Mapping[str, int] | None = None) -> Inverse:
    """Solve ``scene`` driven from its targets (see the module's text).

    Parameters
    ----------
    scene : Scene
        The mechanism.
    targets : mapping of str to float
        One per driver: a reported joint's value (rad or m) or a point's
        coordinate ``'P.x'``, ``'P.y'`` (m, ground frame).
    speeds, accels : mapping of str to float, optional
        The targets' velocities and accelerations (SI); a target left out is at rest.
    start : sequence of float, optional
        The drivers' values (SI, a crank's counted from the start) the answer
        is continued from; default the scene's start pose.
    max_error : float, optional
        As :func:`~.solve.solve`'s; also the largest bound of a driver's value
        over its scale (1 rad, or the size).
    forces : mapping of str to float, optional
        Forces (N) or torques (N m) the mechanism exerts along targets: the
        answer's ``target_efforts`` hold the drivers' share, ``J^T F``.
    branch : mapping of str to int, optional
        The working mode: pin joints between two moving links (``'B'``), each
        with the sign (+1 or -1) asked of the angle of its link from the
        link it is pinned on (:func:`in_mode`; docs/targets.md).

    Returns
    -------
    Inverse
    """
    names = tuple(targets)
    tmap = scene_targets(scene, names)
    for what, given in (('speeds', speeds), ('accels', accels)):
        unknown = [name for name in given or () if name not in names]
        if unknown:
            msg = f'Expected {what} of the targets ({", ".join(names)}), got {", ".join(unknown)}'
            raise TargetError(msg)
    first = start if start is not None else [d.start for d in scene.drivers]
    if len(first) != len(names):
        msg = f"Expected a start of {len(names)} drivers' values, got {len(first)}"
        raise TargetError(msg)
    return continue_to(tmap, [targets[n] for n in names], first,
                       [(speeds or {}).get(n, 0.0) for n in names],
                       [(accels or {}).get(n, 0.0) for n in names],
                       max_error=max_error, forces=forces, branch=branch)
