# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The extreme suite: stiff and extreme cases, digits lost, and the formula audit.

:func:`extreme_cases` builds the configurations of issue 5 (toggles, a
change point, circles that just miss, extreme ratios, scales and speeds, a
slotted-lever pin at its pivot, the edge of assembly); :func:`evaluate_case`
judges the solver at each instant against the 50-digit reference
(:mod:`.reference`) and the bound ``BOUND_FACTOR * EPS * max(1, kappa)``;
:func:`digits_lost` and :func:`formula_audit` explain the errors near a
toggle. The report's section 4 shows them; the tests hold them. mpmath is
imported inside the functions.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
import math
import sys
from typing import Any
import warnings

from .cases import distance_angle, four_bar, slider_crank
from ..errors import AssemblyError, NearSingularWarning, UntrustedError
from ..scene import load_scene
from ..solver import CarriedPoint, Crank, RPR, Scene, solve
from ..units import rad_per_s_from_rpm, radians_from_degrees

__all__ = ['AngleResult', 'BOUND_FACTOR', 'Case', 'CaseResult', 'EXTRA_ANGLES', 'FormulaAudit',
           'digits_lost', 'evaluate_angle', 'evaluate_case', 'extreme_cases', 'formula_audit']

#: The machine epsilon of a double.
EPS = sys.float_info.epsilon
#: Angles added around each multi-angle case by default (the report's full run).
EXTRA_ANGLES = 8

#: An extreme case meets its bound when, for every kind of value, the error
#: relative to that kind's largest magnitude is at most
#: ``BOUND_FACTOR * EPS * max(1, kappa)``, kappa the problem's condition number
#: (:func:`mech_kinematics.verify.reference.condition`): the error that rounding
#: the inputs alone would cause, with room for the few roundings per dyad.
BOUND_FACTOR = 4.0


@dataclass(frozen=True)
class Case:
    """One stiff or extreme configuration: a scene and the crank instants to try."""

    name: str
    scene: Scene
    angles: tuple[float, ...]
    speed: float | None = None
    accel: float | None = None
    note: str = ''


def _spread(center: float, width: float, count: int) -> tuple[float, ...]:
    return tuple(center + width * (k / max(count - 1, 1) - 0.5) * 2 for k in range(count)) \
        if count > 1 else (center,)


def extreme_cases(extra_angles: int = EXTRA_ANGLES) -> list[Case]:
    """Return the stiff and extreme configurations of issue 5, part 4.

    ``extra_angles`` angles are spread around each case of several instants
    (none: only the instants that define the case).
    """
    import mpmath
    extra = extra_angles
    cases = []
    # A non-Grashof four-bar (seed 002 Problem 3) near its two toggle positions.
    toggle = load_scene('four_bar_coupler_points')
    t = distance_angle(0.05, 0.1, 0.066 + 0.056)
    for delta in ('1e-3', '1e-6', '1e-9', '1e-12'):
        with mpmath.workdps(60):
            angles = (float(t - mpmath.mpf(delta)), float(-(t - mpmath.mpf(delta))))
        cases.append(Case(f'four-bar {delta} rad from toggle', toggle, angles,
                          note='four_bar_coupler_points; both toggles (+-103.79 deg)'))
    # Change-point four-bar a + d = b + c (a parallelogram): flat at crank angle 0.
    change = four_bar('change_point', 0.04, 0.1, 0.04, 0.1, angle=0.5)
    cases.append(Case('change-point four-bar at flat', change, (0.0,),
                      note='a = c = 0.04, b = d = 0.1; crank angle 0: all pins in line'))
    for offset in (1e-3, 1e-6, 1e-9):
        cases.append(Case(f'change-point four-bar {offset:.0e} rad from flat', change,
                          (offset,), note='parallelogram branch'))
    # Circles that miss each other (or overlap) by 1e-9 of the coupler length.
    for sign, word in ((1, 'miss'), (-1, 'overlap')):
        beyond = float(distance_angle(0.05, 0.1, 0.066 + 0.056 + sign * 1e-9 * 0.066))
        cases.append(Case(f'circles {word} by 1e-9 of the coupler', toggle, (beyond, -beyond),
                          note=f'four_bar_coupler_points where |BD| = BC + CD '
                               f'{"+" if sign > 0 else "-"} 1e-9 BC'))
    # Rod-to-crank ratios.
    for ratio, label in ((1.000001, '1.000001'), (1e6, '1e6')):
        scene = slider_crank(f'rod_crank_{label.replace(".", "_")}', 0.1, 0.1 * ratio)
        cases.append(Case(f'rod/crank = {label}', scene,
                          (math.pi / 2, -math.pi / 2) + _spread(0.7, 0.6, extra),
                          note='in-line slider-crank, crank 0.1 m; worst at +-90 deg'))
    # The same four-bar scaled.
    base = load_scene('khurmi_four_bar_ad150')
    for size in (1e-6, 1e3):
        k = size / 0.15
        scene = four_bar('khurmi_scaled', 0.04, 0.15, 0.08, 0.15, radians_from_degrees(60),
                         speed=base.input.speed, scale=k)
        cases.append(Case(f'four-bar scaled to {size:g} m', scene,
                          (radians_from_degrees(60),) + _spread(0.0, 3.0, extra),
                          note='khurmi_four_bar_ad150 with every length times '
                               f'{k:.3g}'))
    for rpm in (1e-6, 1e5):
        cases.append(Case(f'crank speed {rpm:g} rpm', base,
                          (radians_from_degrees(60),) + _spread(0.0, 3.0, extra),
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
    edge = slider_crank('offset_edge', 0.125, 0.1875, offset=0.0625)
    cases.append(Case('offset slider-crank exactly at the edge', edge, (-math.pi / 2,),
                      note='crank 0.125, offset 0.0625, rod 0.1875 (exact in binary): '
                           'rod perpendicular to the guide at -90 deg'))
    near_edge = slider_crank('offset_near_edge', 0.125, 0.1875 * (1 + 1e-9), offset=0.0625)
    cases.append(Case('offset slider-crank 1e-9 inside the edge', near_edge,
                      (-math.pi / 2, -math.pi / 2 + 1e-6) + _spread(0.5, 1.0, extra),
                      note='rod = 0.1875 (1 + 1e-9)'))
    return cases


@dataclass
class AngleResult:
    """The solver against the reference at one crank instant of a case."""

    angle: float
    flag: str                   # 'refused', 'untrusted', 'warned' or 'none'
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
        rank = {'none': 0, 'warned': 1, 'untrusted': 2, 'refused': 3}
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
            state = solve(scene, angle, speed, accel, max_error=math.inf)
        except AssemblyError:
            return None, 'refused'
    # What a user gets at the default tolerance: the solver refuses where its bounds
    # exceed max_error times the scale (UntrustedError), before any warning.
    try:
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', NearSingularWarning)
            solve(scene, angle, speed, accel)
    except UntrustedError:
        return state, 'untrusted'
    except AssemblyError:
        return state, 'refused'
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
    t = distance_angle(a, d, l1 + l2)
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
