# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""What the node's compiled tick (:mod:`mech_kinematics.ros.ticker`) uses of the solver: hooks.

The ticker partially evaluates the steps' kernels (:meth:`.base.Step.kernels`,
written in the kernel subset that :mod:`.base` states) into one straight-line
function. Everything else it needs comes from here: the compiled plan as the
tick sees it (:func:`tick_plan`), the range of crank rates solved unscaled,
the failure paths of one crank angle, and the quick trust test, whose one
source is :func:`trust_limits` with :data:`TRUST_TEST` (the general solver's
single-angle path uses the same two).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, TYPE_CHECKING

from .base import Step
from .context import _Context
from .scaling import _ACCEL_HIGH, _RATE_HIGH, _RATE_LOW, _rates_exponent
from .solve import _limits, _wrapped_angle, trust_limits, TRUST_TEST
from .specialize import TABLES

if TYPE_CHECKING:
    from .mechanism import Scene

__all__ = ['RATES', 'TRUST_TEST', 'TickPlan', 'check', 'check_margin', 'rates_shift', 'shown',
           'trust_lines',
           'tick_plan', 'trust_limits', 'wrapped_angle']

#: Crank rates solved unscaled: ``low <= |omega| <= high`` and ``|alpha| <= accel_high``
#: (1/s, 1/s^2); outside, the general solver rescales time.
RATES = (_RATE_LOW, _RATE_HIGH, _ACCEL_HIGH)

#: The angle of a unit complex number wrapped to (-pi, pi], as a revolute joint's position.
wrapped_angle: Callable[[complex], float] = _wrapped_angle


@dataclass(frozen=True)
class TickPlan:
    """A scene's compiled plan as the tick sees it.

    Attributes
    ----------
    compilable : bool
        False where the general solver must serve the scene: its lengths are
        rescaled (a size beyond 2**60 of 1 m) or it has pins to bound.
    ground : mapping of str to tuple
        Every ground point's context entry ``(p, v, a, bounds...)``.
    crank : object
        The crank's step; ``run(ctx, theta, omega, alpha)``.
    steps : tuple of Step
        The steps in solve order.
    joint_types : dict of str to str
        The reported joints: ``'revolute'`` or ``'prismatic'``.
    reported : dict of str to tuple of str
        Per context table (``points``, ``links``, ``sliders``), the reported
        names the trust test judges (:data:`TRUST_TEST`).
    size, crank_length : float
        The mechanism's size and the crank's length, m (the trust test's scales).
    drivers : tuple
        Every driver's step, in scene order (``crank`` is the first); a scene
        with several (or an actuator) takes one value per driver.
    driver_limits : callable or None
        For several drivers: ``(tol, speeds, accels) -> `` the quick trust
        test's six limits from every driver's floors (:func:`trust_limits`'
        order); ``None`` for one crank.
    """

    compilable: bool
    ground: Mapping[str, tuple[Any, ...]]
    crank: Any
    steps: tuple[Step, ...]
    joint_types: dict[str, str]
    reported: dict[str, tuple[str, ...]]
    size: float
    crank_length: float
    drivers: tuple[Any, ...] = ()
    driver_limits: Callable[[float, Any, Any], tuple[float, ...]] | None = None


def tick_plan(scene: Scene) -> TickPlan:
    """Return ``scene``'s compiled plan as the tick sees it."""
    solver = scene._solver
    plan = solver.run_plan

    def driver_limits(tol: float, speeds: Any, accels: Any) -> tuple[float, ...]:
        return _limits(tol, solver.size, solver.floors(speeds, accels))

    return TickPlan(not (solver.shift or plan.rubs), dict(solver.ground), plan.crank,
                    plan.steps, dict(plan.joint_types),
                    {'points': solver.out_points, 'links': solver.out_links,
                     'sliders': solver.out_sliders}, solver.size, solver.crank_length,
                    plan.drivers, None if solver.single else driver_limits)


def rates_shift(speeds: Any, accels: Any) -> int:
    """Return the power of two by which the general solver scales time for several drivers.

    0 where it solves them unscaled (what the compiled tick may answer).
    """
    return _rates_exponent(speeds, accels)


def check(theta: float, turns: int, *args: Any, **kwargs: Any) -> None:
    """Raise as a step's ``ctx.check`` does on one crank angle (its failure path)."""
    _Context(theta, False, turns).check(*args, **kwargs)


def check_margin(theta: float, turns: int, *args: Any, **kwargs: Any) -> None:
    """Raise as a step's ``ctx.check_margin`` does on one crank angle."""
    _Context(theta, False, turns).check_margin(*args, **kwargs)


def shown(theta: float, turns: int) -> Any:
    """Return the crank angle counted from the start, as messages show it (``ctx.shown``)."""
    return _Context(theta, False, turns).shown


def trust_lines(plan: TickPlan, names: Mapping[str, str], limits: str,
                otherwise: str) -> list[str]:
    """Return the source lines of the quick trust test on a compiled plan's reported values.

    ``limits`` is the expression giving the six limits (:func:`trust_limits`,
    or the several drivers' own); ``otherwise`` the statement run where a
    reported bound is beyond them. ``names`` maps each table entry to its local
    variable (:func:`.specialize.plan_body`). The one source of the test for
    the node's tick and ``mk.solve``'s compiled path, with :data:`TRUST_TEST`.
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
