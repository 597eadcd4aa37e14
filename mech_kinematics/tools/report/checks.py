# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Section 1 of the report: the 50-digit reference checks itself and meets the golden files.

:func:`reference_checks` runs the reference's own checks on the packaged
scenes (loop-closure residual, the second route by differences in time, the
solver's error); :func:`golden_checks` compares it with the published golden
cases in ``test/data/reference/`` when the source tree is at hand.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
import math
from pathlib import Path
from typing import Any

from .common import Mode, quiet_solve
from ...errors import AssemblyError
from ...scene import load_scene, scene_dirs
from ...solver.graph import joint_type
from ...units import rad_per_s_from_rpm, radians_from_degrees

__all__ = ['GoldenCheck', 'ReferenceCheck', 'golden_checks', 'golden_folder',
           'reference_checks']


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
    from ...verify import reference as ref_mod
    from ...scene import scene_names
    rows = []
    # The packaged scenes driven by one crank (its angle swept); several drivers:
    # test/solver/test_solve_drivers.py checks them against the reference.
    names = mode.check_scenes or tuple(name for name in scene_names()
                                       if load_scene(name).input is not None
                                       and len(load_scene(name).drivers) == 1)
    for name in names:
        scene = load_scene(name)
        model = ref_mod.Model(scene)
        angles = [scene.input.angle + 2 * math.pi * k / (mode.check_angles + 1)
                  for k in range(mode.check_angles)]
        if name == 'geneva':
            angles = [scene.input.angle + radians_from_degrees(10.0) * k
                      for k in range(mode.check_angles)]
        for angle in angles:
            try:
                state = quiet_solve(scene, angle)
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


def golden_folder() -> Path:
    """Return where the published golden cases are in a source tree (``test/data/reference``).

    Found from the package's own location, so it exists for a source tree or an
    editable install only; an installed copy has no golden files.
    """
    import mech_kinematics
    package = Path(mech_kinematics.__file__).resolve().parent
    return package.parent / 'test' / 'data' / 'reference'


def _scene_path(name: str) -> Path:
    """Return the file of the packaged scene ``name`` (the scene loader's search order)."""
    for folder in scene_dirs():
        path = folder / f'{name}.yaml'
        if path.is_file():
            return path
    msg = f'Expected a packaged scene for the golden file {name}.json, got none'
    raise FileNotFoundError(msg)


def golden_checks(folder: Path | None = None) -> list[GoldenCheck]:
    """Compare the reference with ``folder/*.json`` (default :func:`golden_folder`) if present."""
    import json

    import mpmath

    from ...verify import reference as ref_mod
    folder = folder or golden_folder()
    rows = []
    for path in sorted(folder.glob('*.json')) if folder.is_dir() else []:
        data = json.loads(path.read_text(encoding='utf-8'))
        scene_path = _scene_path(path.stem)
        scene = load_scene(scene_path)
        model = ref_mod.Model(scene)
        exact = ref_mod.decimal_values(scene_path, model)
        count, ulps, rel = 0, 0.0, 0.0
        for case in data['cases']:
            with mpmath.workdps(ref_mod.DPS):
                theta = radians_from_degrees(mpmath.mpf(case['angle_deg']), mpmath.pi)
                omega = rad_per_s_from_rpm(mpmath.mpf(case['speed_rpm']), mpmath.pi)
                alpha = mpmath.mpf(case['accel'])
            decimal = ref_mod.as_float_dict(ref_mod.reference(model, theta, omega, alpha,
                                                              values=exact))
            double = ref_mod.as_float_dict(ref_mod.reference(
                model, radians_from_degrees(float(case['angle_deg'])),
                rad_per_s_from_rpm(float(case['speed_rpm'])), float(case['accel'])))
            for expected, got_d, got_f, scale in _golden_values(case, decimal, double):
                count += 1
                if expected != got_d:
                    ulps = max(ulps, abs(got_d - expected) / math.ulp(expected))
                rel = max(rel, abs(got_f - expected) / (abs(expected) + scale))
        rows.append(GoldenCheck(path.stem, count, ulps, rel))
    return rows


#: The golden files' name of each kind of value's scale (``case['scales']``), by the
#: kind a joint type's values are (:attr:`~mech_kinematics.solver.graph.JointType.quantities`).
_GOLDEN_SCALES = {'angle': 'angle', 'angular velocity': 'angvel',
                  'angular acceleration': 'angacc', 'position': 'length', 'velocity': 'vel',
                  'acceleration': 'acc'}


def _golden_values(case: dict[str, Any], decimal: dict[str, Any],
                   double: dict[str, Any]) -> Iterable[tuple[float, float, float, float]]:
    """Yield (expected, reference from decimals, reference from doubles, scale)."""
    scales = case['scales']
    expected = case['expected']
    for name, joint in expected['joints'].items():
        kind_of = joint_type(joint['type'])
        for quantity, kind in zip(('position', 'velocity', 'acceleration'),
                                  kind_of.quantities, strict=True):
            a, b = decimal['joints'][name][quantity], double['joints'][name][quantity]
            if quantity == 'position' and kind_of.angular:
                a = joint[quantity] + math.remainder(a - joint[quantity], 2 * math.pi)
                b = joint[quantity] + math.remainder(b - joint[quantity], 2 * math.pi)
            yield joint[quantity], a, b, scales[_GOLDEN_SCALES[kind]]
    for name, point in expected['points'].items():
        for quantity in ('position', 'velocity', 'acceleration'):
            kind = _GOLDEN_SCALES[quantity]
            for axis in range(2):
                yield (point[quantity][axis], decimal['points'][name][quantity][axis],
                       double['points'][name][quantity][axis], scales[kind])
