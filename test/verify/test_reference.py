# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The 50-digit reference: golden cases, its second route, and its own arithmetic.

The reference (``mech_kinematics.verify.reference``) solves the loop-closure
equations by Newton-Raphson in mpmath and differentiates them; the report's
errors are measured against it, so it is checked here against the published
golden files (50-digit values rounded to doubles), against finite
differences in time of its own 64-digit positions, and on its building
blocks.
"""

from __future__ import annotations

import ast
import math
from pathlib import Path
import re
import subprocess
import sys
import warnings

from helpers import crank_scene_names, reference_cases, SCENES
import mpmath
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.solver import RPP
from mech_kinematics.solver.registry import DRIVERS, KINDS
from mech_kinematics.units import rad_per_s_from_rpm, radians_from_degrees
from mech_kinematics.verify import reference as ref

EPS = float(np.finfo(float).eps)
#: From the decimal inputs as written, the reference rounded to double is the
#: published double to this many units in the last place (both are 50-digit
#: values rounded once; one file's carried point is given to 20 digits only).
MAX_ULPS_GOLDEN = 1
#: From the scene's double inputs (40 mm read as the double nearest 0.04 m), the
#: published values agree to ``RTOL_GOLDEN * (|value| + scale)``: the input
#: rounding times the mild conditioning of these textbook poses.
RTOL_GOLDEN = 1e-15
#: Route A (linear systems) against route B (five-point differences in time,
#: crank step 1e-12 rad: truncation ~1e-48, rounding ~1e-40), relative to the
#: kind's scale.
RTOL_ROUTES = 1e-30
#: Loop-closure residual over the mechanism's size.
ATOL_RESIDUAL = 1e-55
#: The solver on the packaged scenes: error per kind within this many
#: eps * max(1, kappa) (the report's BOUND_FACTOR).
SOLVER_BOUND = 4.0
#: Forward-mode derivatives of the Jet class against closed forms, 60 digits.
RTOL_JET = 1e-50
#: The NumPy evaluation of the constraints against the mpmath one, relative.
RTOL_FLOAT_MODEL = 1e-14


def _values(case: dict, got: dict):
    """Yield (expected, got, scale) for every published value of ``case``."""
    kinds = {'revolute': ('angle', 'angvel', 'angacc'), 'prismatic': ('length', 'vel', 'acc')}
    for name, joint in case['expected']['joints'].items():
        for quantity, kind in zip(('position', 'velocity', 'acceleration'),
                                  kinds[joint['type']], strict=True):
            value = got['joints'][name][quantity]
            if quantity == 'position' and joint['type'] == 'revolute':
                value = joint[quantity] + math.remainder(value - joint[quantity], 2 * math.pi)
            yield joint[quantity], value, case['scales'][kind]
    for name, point in case['expected']['points'].items():
        for quantity, kind in (('position', 'length'), ('velocity', 'vel'),
                               ('acceleration', 'acc')):
            for axis in range(2):
                yield (point[quantity][axis], got['points'][name][quantity][axis],
                       case['scales'][kind])


@pytest.mark.parametrize(('name', 'case'), reference_cases())
def test_golden_case_from_decimal_inputs(name, case):
    """From the inputs as written, every published value is matched to 1 ulp."""
    path = SCENES / f'{name}.yaml'
    model = ref.Model(mk.load_scene(path))
    with mpmath.workdps(ref.DPS):
        theta = radians_from_degrees(mpmath.mpf(case['angle_deg']), mpmath.pi)
        omega = rad_per_s_from_rpm(mpmath.mpf(case['speed_rpm']), mpmath.pi)
        alpha = mpmath.mpf(case['accel'])
    got = ref.as_float_dict(ref.reference(model, theta, omega, alpha,
                                          values=ref.decimal_values(path, model)))
    assert list(got['joints']) == list(case['expected']['joints'])
    assert list(got['points']) == list(case['expected']['points'])
    for expected, value, _ in _values(case, got):
        assert abs(value - expected) <= MAX_ULPS_GOLDEN * math.ulp(expected), (expected, value)


@pytest.mark.parametrize(('key', 'text'), [
    ('length', '{length: inch, angle: deg}'), ('angle', '{length: mm, angle: grad}')],
    ids=['length', 'angle'])
def test_decimal_values_refuse_an_unknown_unit(tmp_path, key, text):
    """A scene unit the loader does not know is a SceneError naming the key, not a KeyError.

    See issue 9.
    """
    source = (SCENES / 'khurmi_four_bar_ad150.yaml').read_text()
    assert 'units: {length: mm, angle: deg}' in source
    path = tmp_path / 'bad_units.yaml'
    path.write_text(source.replace('units: {length: mm, angle: deg}', f'units: {text}'))
    model = ref.Model(mk.load_scene('khurmi_four_bar_ad150'))
    with pytest.raises(mk.SceneError, match=rf'bad_units.yaml: units\.{key}: expected one of'):
        ref.decimal_values(path, model)


def test_decimal_values_read_metres_and_radians(tmp_path):
    """Lengths in m equal those in mm exactly; deg become exact radians, rad stay as written."""
    body = """
name: units
ground:
  O: [0, 0]
  E: [{e}, {e}]
input: {{link: crank, center: O, point: B, length: {crank}, angle: 45, speed_rpm: 600}}
dyads:
  - type: RRP
    point: P
    link: {{name: rod, from: B, length: {rod}}}
    guide: {{through: E, angle: {guide}}}
    slider: piston
"""
    mm_deg = tmp_path / 'mm_deg.yaml'
    mm_deg.write_text('units: {length: mm, angle: deg}'
                      + body.format(e=50, crank=100, rod=400, guide=30))
    m_rad = tmp_path / 'm_rad.yaml'
    m_rad.write_text('units: {length: m, angle: rad}'
                     + body.format(e='0.05', crank='0.1', rod='0.4', guide='0.5'))
    model = ref.Model(mk.load_scene(mm_deg))
    a, b = ref.decimal_values(mm_deg, model), ref.decimal_values(m_rad, model)
    assert a.keys() == b.keys() and 'guide.P.angle' in a
    with mpmath.workdps(ref.DPS):
        assert abs(a.pop('guide.P.angle') - mpmath.pi / 6) <= mpmath.mpf('1e-62')
        assert b.pop('guide.P.angle') == mpmath.mpf('0.5')
        assert a['crank.length'] == mpmath.mpf('0.1')
    assert a == b


def _khurmi_with(tmp_path, name, old, new):
    """Write khurmi_four_bar_ad150.yaml with ``old`` replaced by ``new``; return its path."""
    source = (SCENES / 'khurmi_four_bar_ad150.yaml').read_text()
    assert old in source
    path = tmp_path / f'{name}.yaml'
    path.write_text(source.replace(old, new, 1))
    return path


@pytest.mark.parametrize('spelling', ['1.5e2', '1.5E+2', '+150.', '0o226', '0x96'])
def test_decimal_values_read_numbers_as_the_scene_loader_does(tmp_path, spelling):
    """A YAML 1.2 number such as `length: 1.5e2` gives the reference of `length: 150.0`.

    The reference reads scene files with the scene loader's YAML reader, so
    both see the same numbers. See issue 10.
    """
    plain = _khurmi_with(tmp_path, 'plain', '[150, 0]', '[150.0, 0]')
    spelled = _khurmi_with(tmp_path, 'spelled', '[150, 0]', f'[{spelling}, 0]')
    scene = mk.load_scene(plain)
    assert mk.load_scene(spelled).ground == scene.ground
    model = ref.Model(scene)
    a, b = ref.decimal_values(plain, model), ref.decimal_values(spelled, model)
    assert a == b
    with mpmath.workdps(ref.DPS):
        assert a['ground.D.x'] == mpmath.mpf('0.15')
    got = [ref.as_float_dict(ref.reference(model, 1.0, values=v)) for v in (a, b)]
    assert got[0] == got[1]


def test_decimal_values_refuse_a_duplicate_key(tmp_path):
    """A key given twice is refused as the scene loader refuses it, not read as the last one."""
    path = _khurmi_with(tmp_path, 'twice', '  length: 40\n', '  length: 40\n  length: 45\n')
    with pytest.raises(mk.SceneError, match=r'twice.yaml: .*length'):
        mk.load_scene(path)
    model = ref.Model(mk.load_scene('khurmi_four_bar_ad150'))
    with pytest.raises(mk.SceneError, match=r'twice.yaml: input: expected each key once'):
        ref.decimal_values(path, model)


def test_decimal_values_keep_every_digit_written(tmp_path):
    """A length of more digits than a double holds keeps them all; the loader rounds it."""
    digits = '80.000000000000000000123'
    path = _khurmi_with(tmp_path, 'long', 'length: 80}', f'length: {digits}}}')
    model = ref.Model(mk.load_scene(path))
    assert model.values['link.rocker.length'] == 0.08
    with mpmath.workdps(ref.DPS):
        assert ref.decimal_values(path, model)['link.rocker.length'] == (
            mpmath.mpf(digits) / 1000)


@pytest.mark.parametrize('name', ['quick_return', 'whitworth', 'geneva'])
def test_decimal_values_of_scenes_with_sliding_levers(name):
    """Scenes with an RPR (no length of its own) are read; each value rounds to its double."""
    model = ref.Model(mk.load_scene(name))
    decimals = ref.decimal_values(SCENES / f'{name}.yaml', model)
    assert decimals.keys() == model.values.keys()
    for key, value in decimals.items():
        assert float(value) == pytest.approx(model.values[key], rel=4 * EPS, abs=0), key


@pytest.mark.parametrize('name', mk.scene_names())
def test_decimal_values_of_every_packaged_scene(name):
    """Every kind's values are read, drivers' of ``inputs:`` and RPP's angles too; each rounds.

    Which values are lengths and angles, and where each is written, the
    kind's model says: before it, an RPP fell into the RPR's case (no value
    read) and a scene of ``inputs:`` was not read at all. See issue 30.
    """
    model = ref.Model(mk.load_scene(name))
    decimals = ref.decimal_values(SCENES / f'{name}.yaml', model)
    assert decimals.keys() == model.values.keys()
    for key, value in decimals.items():
        assert float(value) == pytest.approx(model.values[key], rel=4 * EPS, abs=0), key


YOKE = """\
name: yoke_30
units: {length: mm, angle: deg}
ground:
  A: [0, 0]
input: {link: crank, center: A, point: B, length: 50, angle: 10, speed_rpm: 300}
dyads:
  - {type: RPP, point: Y, through: B, guide: {through: A, angle: 30}, slot_angle: 120,
     slider: yoke, slot_slider: pin_in_slot}
"""
#: The 50-digit reference against a closed form of the same decimal inputs, m.
ATOL_EXACT = 1e-50
#: What reading the yoke's angles as doubles (each within 1e-16 rad) moves it by, m, at least.
MOVED_BY_DOUBLES = 1e-20


def test_rpp_angles_are_read_as_exact_decimals(tmp_path):
    """An RPP's guide and slot angles (30 and 120 deg) are pi/6 and 2 pi/3, not their doubles.

    The yoke's slot is square to its guide, so ``yoke = r cos(theta - 30 deg)``
    and ``pin_in_slot = r sin(theta - 30 deg)`` for a crank of radius r: the
    reference from the decimals meets them to 50 digits; with the two angles
    taken as doubles it is 1e-19 away. See issue 30.
    """
    path = tmp_path / 'yoke_30.yaml'
    path.write_text(YOKE)
    model = ref.Model(mk.load_scene(path))
    decimals = ref.decimal_values(path, model)
    with mpmath.workdps(ref.DPS):
        assert abs(decimals['guide.Y.angle'] - mpmath.pi / 6) <= mpmath.mpf('1e-62')
        assert abs(decimals['slot.Y.angle'] - 2 * mpmath.pi / 3) <= mpmath.mpf('1e-62')
        theta = radians_from_degrees(mpmath.mpf(10), mpmath.pi)
        r, phase = mpmath.mpf('0.05'), theta - mpmath.pi / 6
    exact = ref.reference(model, theta, values=decimals)
    doubles = ref.reference(model, theta, values={
        **decimals, **{key: model.values[key] for key in ('guide.Y.angle', 'slot.Y.angle')}})
    with mpmath.workdps(ref.DPS):
        closed = {'yoke': r * mpmath.cos(phase), 'pin_in_slot': r * mpmath.sin(phase)}
        for name, value in closed.items():
            assert abs(exact.joints[name][0] - value) <= ATOL_EXACT, name
            assert abs(doubles.joints[name][0] - value) >= MOVED_BY_DOUBLES, name


def _lacking(kinds, drivers):
    """Return the kinds of item and of driver among these that the reference has no model for.

    The items: each kind of ``kinds``, the carried point and the Geneva
    wheel's RPR (an RPR whose graph fragment has an intermittent joint).
    """
    geneva = mk.RPR('wheel', 'S', 'P', 'pin_slot', slots=4)
    items = [*kinds, mk.CarriedPoint.kind, ref.model_key(geneva.kind, geneva.fragment())]
    return ([kind for kind in items if kind not in ref.MODELS]
            + [kind for kind in drivers if kind not in ref.DRIVER_MODELS])


def test_the_reference_has_equations_for_every_kind_of_the_registries():
    """Every kind of KINDS, the carried point, the Geneva RPR and every DRIVERS has a model.

    A kind added to the solver's registry alone fails here, named. See issue 30.
    """
    missing = _lacking(KINDS, DRIVERS)
    assert not missing, (f'kinds the reference has no equations for: {", ".join(missing)} '
                         '(add a model to MODELS or DRIVER_MODELS in '
                         'mech_kinematics/verify/reference.py)')
    assert _lacking([*KINDS, 'RRQ'], [*DRIVERS, 'servo']) == ['RRQ', 'servo']


def test_a_kind_without_equations_is_refused_naming_it():
    """An item or a driver of a kind with no model raises, naming it: never another kind's."""
    scene = mk.load_scene('scotch_yoke')

    class Yoke(RPP):
        kind = 'RPX'

    class Motor(mk.Crank):
        scene_key = 'servo'

    yoke = mk.Scene('yoke', scene.ground, scene.input, (Yoke(**vars(scene.dyads[0])),))
    with pytest.raises(ref.NoReferenceModel, match=r"Expected a kind of scene item .*got 'RPX'"):
        ref.Model(yoke)
    motor = mk.Scene('motor', scene.ground, Motor(**vars(scene.input)), scene.dyads)
    with pytest.raises(ref.NoReferenceModel, match=r"Expected a kind of driver .*got 'servo'"):
        ref.Model(motor)


def test_an_intermittent_variant_has_equations_of_its_own(monkeypatch):
    """A Geneva wheel's RPR takes the intermittent model, never falls back on the plain RPR's."""
    geneva = mk.load_scene('geneva')
    key = ref.model_key(mk.RPR.kind, geneva.dyads[0].fragment())
    assert key != mk.RPR.kind
    assert [element.equations for element in ref.Model(geneva).elements] == [ref.MODELS[key]]
    assert ref.MODELS[key] is not ref.MODELS[mk.RPR.kind]
    monkeypatch.delitem(ref.MODELS, key)
    with pytest.raises(ref.NoReferenceModel, match=re.escape(repr(key))):
        ref.Model(geneva)


@pytest.mark.parametrize(('name', 'case'), reference_cases())
def test_golden_case_from_double_inputs(name, case):
    """From the scene's doubles, the published values agree to 1e-15 of (value + scale)."""
    scene = mk.load_scene(SCENES / f'{name}.yaml')
    got = ref.as_float_dict(ref.reference(scene, math.radians(float(case['angle_deg'])),
                                          rad_per_s_from_rpm(float(case['speed_rpm'])),
                                          float(case['accel'])))
    for expected, value, scale in _values(case, got):
        assert abs(value - expected) <= RTOL_GOLDEN * (abs(expected) + scale)


@pytest.mark.parametrize('name', crank_scene_names())  # several drivers: test_solve_drivers
def test_second_route_agrees(name):
    """Velocities and accelerations match 64-digit differences in time to 1e-30."""
    scene = mk.load_scene(name)
    for angle in (scene.input.angle, scene.input.angle + 0.1):
        exact = ref.reference(scene, angle)
        assert float(exact.residual) <= ATOL_RESIDUAL
        differences = ref.check_by_differences(scene, exact)
        assert set(differences) == {'velocity', 'angular velocity', 'acceleration',
                                    'angular acceleration'}
        assert max(differences.values()) <= RTOL_ROUTES, differences


def test_second_route_with_crank_acceleration():
    """The crank's angular acceleration enters both routes the same way."""
    scene = mk.load_scene('four_bar_coupler_points')  # accel = -26 rad/s^2
    assert scene.input.accel != 0
    exact = ref.reference(scene, scene.input.angle, -3.0, 250.0)
    assert max(ref.check_by_differences(scene, exact).values()) <= RTOL_ROUTES


@pytest.mark.parametrize('name', crank_scene_names())  # several drivers: test_solve_drivers
def test_newton_sets_the_digits(name):
    """Positions come from Newton-Raphson on the constraints, not from the 20-digit start."""
    scene = mk.load_scene(name)
    exact = ref.reference(scene, scene.input.angle)
    assert exact.iterations >= 1
    assert float(exact.residual) <= ATOL_RESIDUAL


@pytest.mark.parametrize('name', crank_scene_names())  # several drivers: test_solve_drivers
def test_solver_within_conditioning_on_packaged_scenes(name):
    """The solver's error per kind is within 4 eps * max(1, kappa) on every packaged scene."""
    scene = mk.load_scene(name)
    exact = ref.reference(scene, scene.input.angle)
    kappa = ref.condition(scene, exact)
    errors = ref.compare(mk.solve(scene, scene.input.angle), exact)
    for kind, error in errors.items():
        assert error <= SOLVER_BOUND * EPS * max(1.0, kappa[kind]), (kind, error, kappa[kind])


def test_branch_follows_the_scene_format():
    """Branch -1 of an RRR gives the mirror pin, to the right of the line of centres."""
    scene = mk.load_scene('khurmi_four_bar_ad150')
    dyad = scene.dyads[0]
    mirrored = mk.Scene('mirrored', scene.ground, scene.input,
                        (mk.RRR(dyad.point, dyad.links, mk.Branch.MINUS),))
    plus = ref.reference(scene, scene.input.angle)
    minus = ref.reference(mirrored, scene.input.angle)
    b, d = plus.points['B'][0], plus.points['D'][0]
    side = [float((mpmath.conj(d - b) * (r.points['C'][0] - b)).imag) for r in (plus, minus)]
    assert side[0] > 0 > side[1]
    solved = mk.solve(mirrored, scene.input.angle).complex_points['C'][0]
    assert abs(complex(minus.points['C'][0]) - solved) <= 4 * EPS * abs(solved)


def test_no_assembly_is_reported():
    """Circles that miss each other raise NoAssembly instead of returning a pose."""
    scene = mk.load_scene('four_bar_coupler_points')
    with pytest.raises(ref.NoAssembly, match='RRR C'):
        ref.reference(scene, math.radians(120.0))


def test_singular_pose_has_positions_only():
    """At a change point's flat pose the reference gives positions and no velocities."""
    links = (mk.Link('coupler', 'B', 0.1), mk.Link('rocker', 'D', 0.04))
    crank = mk.Crank('crank', 'A', 'B', 0.04, 0.5, 1.0, 0.0)
    scene = mk.Scene('parallelogram', {'A': (0.0, 0.0), 'D': (0.1, 0.0)}, crank,
                     (mk.RRR('C', links),))
    exact = ref.reference(scene, 0.0)
    assert exact.singular
    assert exact.min_measure == 0
    assert exact.qdot is None and exact.points['C'][1] is None
    assert math.isinf(ref.condition(scene, exact)['velocity'])


def test_measures_match_the_solver():
    """The exact near-singularity measures are the solver's, to rounding."""
    for name in crank_scene_names():  # several drivers: test_solve_drivers
        scene = mk.load_scene(name)
        exact = ref.reference(scene, scene.input.angle)
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', mk.NearSingularWarning)
            state = mk.solve(scene, scene.input.angle)
        assert set(exact.measures) == set(state.singularity)
        for key, value in state.singularity.items():
            assert value == pytest.approx(float(exact.measures[key]), rel=1e-12)


#: What the reference may import from the solver: the scene, its items' and drivers'
#: dataclasses (whose kinds key its models) and the graph's types (no step, no solve).
SOLVER_NAMES = {'..solver': {'Actuator', 'CarriedPoint', 'Collar', 'Crank', 'Fold', 'Hinge',
                             'Motor',
                             'RPP', 'RPR', 'RRP', 'RRR', 'Scene', 'Slider', 'Triad'},
                '..solver.graph': {'Fragment', 'JointType', 'joint_type'}}


def test_reference_does_not_use_the_solver():
    """The reference module imports the solver's dataclasses only, never its steps."""
    tree = ast.parse(Path(ref.__file__).read_text())
    imported = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or '').startswith('solver'):
            module = '.' * node.level + node.module
            imported.setdefault(module, set()).update(alias.name for alias in node.names)
        assert not (isinstance(node, ast.Import)
                    and any('solver' in alias.name for alias in node.names)), ast.unparse(node)
    assert imported['..solver'] >= {'Scene'}
    for module, names in imported.items():
        assert names <= SOLVER_NAMES.get(module, set()), (module, names)
    for name in ('solve', '_RRRStep', '_RRPStep', '_RPRStep', '_RPPStep', '_CarryStep', '_run',
                 '_TriadStep', '_SlideStep', '_CollarStep', '_HingeStep', '_MotorStep',
                 '_FoldStep'):
        assert not hasattr(ref, name)
    assert '._solver' not in Path(ref.__file__).read_text()  # (a triad's branch: its own)


def test_jet_derivatives():
    """Jet arithmetic gives the first and second derivatives of a composite function."""
    with mpmath.workdps(60):
        t0 = mpmath.mpf('0.7')

        def f(t):
            z = ref.expi(t * t) * (3 + 1j * t) / (2 + t)
            return z + ref.norm(z) * t

        value, first, second = f(ref.Jet(t0, 1)).derivatives()
        expected = [mpmath.diff(lambda t: f(t), t0, n) for n in (0, 1, 2)]
        for got, want in zip((value, first, second), expected, strict=True):
            assert abs(got - want) <= RTOL_JET * abs(want)


def test_jet_works_on_arrays():
    """The same constraint code runs on NumPy arrays (the report's double baselines)."""
    scene = mk.load_scene('quick_return')
    model = ref.Model(scene)
    exact = ref.reference(model, scene.input.angle)
    q = [np.array([float(x)] * 3) for x in exact.q]
    points, residuals = model.evaluate(model.values, q, np.full(3, scene.input.angle))
    for name, (position, _, _) in exact.points.items():
        np.testing.assert_allclose(points[name], complex(position), rtol=RTOL_FLOAT_MODEL,
                                   atol=RTOL_FLOAT_MODEL * model.size)
    assert max(np.max(np.abs(r)) for r in residuals) <= RTOL_FLOAT_MODEL * model.size


def test_condition_number_of_a_toggle_grows_as_measure_squared():
    """Near a toggle the velocity condition number grows like 1 / measure**2."""
    scene = mk.load_scene('four_bar_coupler_points')
    with mpmath.workdps(60):
        toggle = mpmath.acos((mpmath.mpf(0.05) ** 2 + mpmath.mpf(0.1) ** 2
                              - (mpmath.mpf(0.066) + mpmath.mpf(0.056)) ** 2)
                             / (2 * mpmath.mpf(0.05) * mpmath.mpf(0.1)))
    products = []
    for delta in ('1e-4', '1e-8'):
        with mpmath.workdps(60):
            angle = float(toggle - mpmath.mpf(delta))
        exact = ref.reference(scene, angle)
        kappa = ref.condition(scene, exact)['velocity']
        products.append(kappa * float(exact.min_measure) ** 2)
    assert products[1] == pytest.approx(products[0], rel=0.1)


def test_import_needs_no_plotting():
    """Importing the reference pulls in mpmath but neither matplotlib nor SciPy."""
    code = ('import sys, mech_kinematics.verify.reference; '
            "assert 'matplotlib' not in sys.modules and 'scipy' not in sys.modules")
    subprocess.run([sys.executable, '-c', code], check=True, timeout=60)
