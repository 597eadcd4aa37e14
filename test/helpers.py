# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Helpers shared by several test modules.

A test module never imports another test module: what two of them need lives
here (or in ``conftest.py``), one section per concern, each headed by a
comment naming the modules that use it.
"""

from __future__ import annotations

import functools
import json
import math
import os
from pathlib import Path
import runpy
from typing import Any
from unittest import mock

import mpmath
import pytest
import setuptools

import mech_kinematics as mk
from mech_kinematics.ros.parameters import PARAMETERS
from mech_kinematics.verify import reference as ref

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
#: The shipped scenes, in the source tree.
SCENES = HERE.parent / 'config' / 'scenes'


# --- the packaged scenes by their drivers ----------------------------------------------
# Tests that sweep one crank's angle (geometry, diagrams, the reference's time
# differences) take the scenes driven by one crank; test/solver/test_solve_drivers.py
# and the several-driver tests of each tool take the others (issue 18).


def crank_scene_names() -> list[str]:
    """Return the packaged scenes driven by one crank (``input:``), sorted."""
    return [name for name in mk.scene_names() if len(mk.load_scene(name).drivers) == 1
            and mk.load_scene(name).input is not None]


def start_positions(scene: Any) -> Any:
    """Return where ``scene``'s drivers start: the crank angle, or one position per driver."""
    drivers = scene.drivers
    return drivers[0].start if len(drivers) == 1 else [d.start for d in drivers]


def driver_scene_names() -> list[str]:
    """Return the packaged scenes with several drivers or an actuator (``inputs:``), sorted."""
    return sorted(set(mk.scene_names()) - set(crank_scene_names()))


# --- the published 50-digit reference cases ------------------------------------
# Used by test_solve_golden.py (the solver against them) and test_reference.py
# (the mpmath reference against them).

#: Verbatim copies of the published golden cases (``<scene>.json``).
REFERENCE = HERE / 'data' / 'reference'
#: The scenes that have a published reference file.
REFERENCE_NAMES = ('khurmi_four_bar_ad150', 'slider_crank_150_600', 'steam_engine_500_2000')


def reference_cases() -> list[Any]:
    """Return one pytest param (scene name, case) per published reference instant."""
    params = []
    for name in REFERENCE_NAMES:
        data = json.loads((REFERENCE / f'{name}.json').read_text())
        for index, case in enumerate(data['cases']):
            params.append(pytest.param(name, case, id=f'{name}-{index}'))
    return params


# --- a scene using every construct -----------------------------------------------
# Used by test_scene.py and test_scene_loader.py, which edit it.

#: A valid scene using every construct: an RRR four-bar, points carried in both
#: forms, an RRP from a carried point, a second ground point on the guide.
BASE_SCENE = """\
name: base_scene
units: {length: mm, angle: deg}
ground:
  A: [0, 0]
  D: [150, 0]
  G: [0, -100]
input: {link: crank, center: A, point: B, length: 40, angle: 60, speed_rpm: -120, accel: 0}
dyads:
  - type: RRR
    point: C
    links:
      - {name: coupler, from: B, length: 150}
      - {name: rocker, from: D, length: 80}
    branch: 1
  - type: RRP
    point: P
    link: {name: rod, from: E, length: 150}
    guide: {through: G, angle: 0}
    slider: piston
    branch: 1
points:
  E: {link: coupler, from: B, toward: C, distance: 50}
  F: {link: coupler, origin: B, xaxis: C, local: [40, -30]}
"""

# --- small scenes with several drivers (issue 18) ---------------------------------
# Used by geometry/test_region.py and tools/test_check.py (and the plot and diagram tests).
#: A five-bar with two cranks whose distal links straighten (|BD| = 0.28 m) within a turn.
FIVE_BAR_TWO_CRANKS = """\
name: five
units: {length: m, angle: deg}
ground: {A: [0, 0], E: [0.1, 0]}
inputs:
  - {link: left, center: A, point: B, length: 0.12, angle: 120, speed_rpm: 10}
  - {link: right, center: E, point: D, length: 0.12, angle: 60, speed_rpm: -10}
dyads:
  - type: RRR
    point: P
    links: [{name: ldist, from: B, length: 0.14}, {name: rdist, from: D, length: 0.14}]
    branch: 1
"""

#: A cylinder (an actuator on an RRR link) lifting a boom; its stroke reaches past
#: where the boom and cylinder come in line (L = 2600 mm + |OF|).
BOOM_CYLINDER = """\
name: boom
units: {length: mm, angle: deg}
ground: {O: [0, 0], F: [400, -1100]}
inputs:
  - {actuator: cyl, length: 2600, speed: 0.05, stroke: [2000, 5000]}
dyads:
  - type: RRR
    point: Q
    links: [{name: boom, from: O, length: 2600}, {name: body, from: F, actuator: cyl}]
    branch: 1
points:
  T: {link: boom, origin: O, xaxis: Q, local: [5680, 550]}
"""

# --- test scenes with forces (issue 32) -------------------------------------------
# Used by geometry/test_turning.py, geometry/test_force_polygon.py and the check, plot
# and diagram tests: the turning-moment diagram, the flywheel and the force polygon.
#: Scenes with masses, gravity and loads written for the tests (not packaged), each
#: with what is known of it in its description: ``test/data/forces/NAME.yaml``.
FORCES = HERE / 'data' / 'forces'


def flat_forces(forces: Any, vector: bool = False) -> dict[str, Any]:
    """Return every value and bound of a ``Forces`` answer as one flat dict (``value.*`` ...).

    One instant: each pair's components apart; arrays (``vector``): each value whole.
    """
    out: dict[str, Any] = {}

    def walk(prefix: str, value: Any) -> None:
        if isinstance(value, dict):
            for key, item in value.items():
                walk(f'{prefix}.{key}', item)
        elif isinstance(value, list) and not vector:
            for i, item in enumerate(value):
                walk(f'{prefix}[{i}]', item)
        else:
            out[prefix] = value

    walk('value', forces.as_dict(vector))
    walk('bound', forces.bound_dict(vector))
    return out


def forces_scene(name: str) -> Any:
    """Return the test scene with forces ``test/data/forces/NAME.yaml``."""
    return mk.load_scene(str(FORCES / f'{name}.yaml'))


# --- what setup.py installs and which parameters the node declares ---------------
# Used by test_launch.py and test_packaging.py.
#: Parameters every rclpy node declares itself.
STANDARD_PARAMETERS = frozenset({'use_sim_time'})


def setup_keywords() -> dict:
    """Return the keyword arguments setup.py passes to ``setuptools.setup``."""
    captured: dict = {}
    cwd = os.getcwd()
    try:
        os.chdir(ROOT)      # setup.py globs its data files relative to the repository
        with mock.patch.object(setuptools, 'setup', lambda **kw: captured.update(kw)):
            runpy.run_path(str(ROOT / 'setup.py'), run_name='__main__')
    finally:
        os.chdir(cwd)
    return captured


def console_scripts() -> dict:
    """Return setup.py's console scripts as {name: 'module:function'}."""
    scripts = {}
    for entry in setup_keywords()['entry_points']['console_scripts']:
        name, target = (part.strip() for part in entry.split('='))
        scripts[name] = target
    return scripts


def installed_files() -> dict:
    """Return setup.py's data files as {installed path: repository path}."""
    files = {}
    for folder, sources in setup_keywords()['data_files']:
        for source in sources:
            files[f'{folder}/{Path(source).name}'] = source
    return files


def node_parameters() -> frozenset:
    """Return the names of the parameters kinematics_node declares.

    The node declares every entry of ``mech_kinematics.ros.parameters.PARAMETERS``,
    and rclpy declares the standard ones for every node.
    """
    return frozenset({p.name for p in PARAMETERS} | STANDARD_PARAMETERS)


def equilateral_chain(n, angle=0.3):
    """Return a strip of ``n`` equilateral RRR dyads driven by a 1 m crank (issue 21, item 2).

    Each dyad's links equal its base (the distance between its starts), 1 m: every
    dyad's near-singularity measure is sin(60 deg) = 0.866, far from any toggle.
    """
    dyads = []
    previous, current = 'A', 'B'
    for k in range(n):
        dyads.append(mk.RRR(f'P{k}', (mk.Link(f'a{k}', previous, 1.0),
                                      mk.Link(f'b{k}', current, 1.0)), 1 - 2 * (k % 2)))
        previous, current = current, f'P{k}'
    crank = mk.Crank('crank', 'A', 'B', 1.0, angle, 2.0, 0.5)
    return mk.Scene(f'chain{n}', {'A': (0.0, 0.0)}, crank, tuple(dyads))


def strip_scene():
    """Return a strip of six rigid triangles on a four-bar's coupler (RRRs on one link).

    Each RRR after the four-bar's starts from two points fixed on one link: the
    solver bounds it as carried by that link (docs/robustness.md, "Long chains").
    """
    dyads = [mk.RRR('C', (mk.Link('coupler', 'B', 2.0), mk.Link('rocker', 'D', 2.5)), 1)]
    previous, current = 'B', 'C'
    for k in range(6):
        dyads.append(mk.RRR(f'P{k}', (mk.Link(f'a{k}', previous, 2.0),
                                      mk.Link(f'b{k}', current, 1.7)), 1 - 2 * (k % 2)))
        previous, current = current, f'P{k}'
    return mk.Scene('strip', {'A': (0.0, 0.0), 'D': (3.0, 0.0)},
                    mk.Crank('crank', 'A', 'B', 1.0, 0.4, 3.0, 0.7), tuple(dyads))


# --- error bounds against the 50-digit reference ----------------------------------


def actual_errors(state, exact):
    """Yield (path, kind, actual error, bound, scale) for every value ``state`` reports.

    ``exact`` is the reference at the same instant; errors of points are the
    lengths of the error vectors, angles compare modulo 2 pi. Values the
    reference leaves undefined (velocities at a singular pose) are skipped.
    """
    joint_bounds, point_bounds = state.error_bound.raw()
    scales = state.scales
    with mpmath.workdps(ref.DPS):
        for name, values in state.complex_points.items():
            for index, (quantity, kind) in enumerate(zip(
                    ('position', 'velocity', 'acceleration'),
                    ('position', 'velocity', 'acceleration'), strict=True)):
                truth = exact.points[name][index]
                if truth is None:
                    continue
                error = abs(mpmath.mpc(values[index]) - truth)
                yield (f'points.{name}.{quantity}', kind, float(error),
                       float(point_bounds[name][index]), float(scales[kind]))
        for name, joint in state.joints.items():
            kinds = (('angle', 'angular velocity', 'angular acceleration')
                     if joint.type == 'revolute' else ('position', 'velocity', 'acceleration'))
            for index, quantity in enumerate(('position', 'velocity', 'acceleration')):
                truth = exact.joints[name][index]
                if truth is None:
                    continue
                error = mpmath.mpf(getattr(joint, quantity)) - truth
                if index == 0 and joint.type == 'revolute':
                    error = ref._wrap(error)
                yield (f'joints.{name}.{quantity}', kinds[index], float(abs(error)),
                       float(joint_bounds[name][index]), float(scales[kinds[index]]))


def assert_bounded(scene, angle, speed=None, accel=None):
    """Assert every value the solver answers is within its bound; return (state, exact).

    The solver is asked with an infinite tolerance, so that every answer it
    can give is checked; ``state`` is None where it refuses (it must then be
    refused with the default tolerance too) and ``exact`` is None where the
    mechanism does not assemble (the solver must refuse).
    """
    try:
        exact = ref.reference(scene, angle, speed, accel)
    except ref.NoAssembly:
        with pytest.raises(mk.AssemblyError):
            mk.solve(scene, angle, speed, accel, max_error=math.inf)
        return None, None
    try:
        state = mk.solve(scene, angle, speed, accel, max_error=math.inf)
    except mk.AssemblyError:
        with pytest.raises(mk.AssemblyError):
            mk.solve(scene, angle, speed, accel)
        return None, exact
    for path, _, error, bound, _ in actual_errors(state, exact):
        assert error <= bound, (scene.name, angle, path, error, bound)
    return state, exact


def first_order_spreads(scene, angle, speed=None, accel=None, exact=None):
    """Return, per value ``actual_errors`` names, what a 1-ulp change of every input moves it.

    ``U * sum over inputs |d value / d x| |x|``: every geometry value and the
    crank's angle, speed and acceleration changed by half an ulp (relative
    ``U``), first order, from the 50-digit reference (``exact`` if given).
    """
    model = ref.Model(scene)
    base = ref.reference(model, angle, speed, accel) if exact is None else exact
    eta = mpmath.mpf('1e-25')
    unit = 2.0 ** -53

    def flat(r):
        out = {}
        for table, prefix in ((r.points, 'points'), (r.joints, 'joints')):
            for name, values in table.items():
                for index, quantity in enumerate(('position', 'velocity', 'acceleration')):
                    if values[index] is not None:
                        out[f'{prefix}.{name}.{quantity}'] = values[index]
        return out

    with mpmath.workdps(ref.DPS):
        values = flat(base)
        totals = dict.fromkeys(values, mpmath.mpf(0))
        inputs = [*base.inputs.items(), ('@theta', base.theta), ('@omega', base.omega),
                  ('@alpha', base.alpha)]
        for key, value in inputs:
            if value == 0:
                continue
            given = dict(base.inputs)
            theta, omega, alpha = base.theta, base.omega, base.alpha
            delta = value * eta
            if key == '@theta':
                theta += delta
            elif key == '@omega':
                omega += delta
            elif key == '@alpha':
                alpha += delta
            else:
                given[key] = value + delta
            moved = flat(ref.reference(model, theta, omega, alpha, values=given, seed=base.q))
            for path, x in values.items():
                diff = moved[path] - x
                if path.startswith('joints.') and path.endswith('.position') \
                        and not isinstance(diff, mpmath.mpc):
                    diff = ref._wrap(diff)
                totals[path] += abs(diff) / eta
        return {path: float(total) * unit for path, total in totals.items()}


# --- an array solve against single-angle solves -------------------------------
# Used by test_triad.py and test_one_answer.py.

@functools.cache
def numpy_is_libm() -> bool:
    """Whether NumPy's array ``arctan2`` and ``hypot`` give the C library's bits on this machine.

    The single-angle path calls the C library (``math.atan2``, ``abs`` of a
    complex), the array path NumPy. Where NumPy dispatches its own AVX-512 loop
    for ``arctan2`` (NumPy 2.4 on an AVX-512 Xeon: some of these random pairs
    one ulp off ``math.atan2``; none with
    ``NPY_DISABLE_CPU_FEATURES="X86_V4 AVX512_ICL AVX512_SPR"``), the two paths
    agree within their error bounds, not to the bit.
    """
    import numpy as np
    x, y = np.random.default_rng(0).uniform(-4.0, 4.0, (2, 4096))
    pairs = list(zip(x.tolist(), y.tolist(), strict=True))
    return bool(np.array_equal(np.arctan2(y, x), [math.atan2(b, a) for a, b in pairs])
                and np.array_equal(np.hypot(x, y), [abs(complex(a, b)) for a, b in pairs]))


def assert_entry_is_the_single_answer(single: mk.State, many: mk.State, index: int) -> None:
    """Assert that entry ``index`` of the array state ``many`` is the single-angle ``single``.

    Bit for bit, values and bounds, where :func:`numpy_is_libm`; elsewhere every
    value within the sum of the two states' error bounds of the other (both bound
    the error against the exact value) and every bound within 1e-6 of the other,
    relative.
    """
    import numpy as np
    pairs = [(single.joints, many.joints, single.error_bound.joints, many.error_bound.joints),
             (single.points, many.points, single.error_bound.points, many.error_bound.points)]
    for one, other, one_bound, other_bound in pairs:
        assert one.keys() == other.keys()
        for name in one:
            for quantity in ('position', 'velocity', 'acceleration'):
                a = np.asarray(getattr(one[name], quantity), dtype=float)
                b = np.asarray(getattr(other[name], quantity), dtype=float)
                b = np.broadcast_to(b, (len(many.valid), *a.shape))[index]
                ea = float(getattr(one_bound[name], quantity))
                eb = float(np.broadcast_to(getattr(other_bound[name], quantity),
                                           many.valid.shape)[index])
                where = f'{name} {quantity}'
                if numpy_is_libm():
                    assert a.tolist() == b.tolist() and ea == eb, where
                else:
                    assert float(np.linalg.norm(a - b)) <= ea + eb, (where, a, b, ea, eb)
                    assert abs(ea - eb) <= 1e-6 * max(ea, eb), (where, ea, eb)


# --- the solver's compiled paths against its general one ----------------------
# Used by test_compiler_solve.py (the compiled single-angle and array solves),
# test_ticker.py (the node's tick against the general solver) and
# test_compiler.py (every registered kind, compiled for every target).

def general_only(scene: mk.Scene) -> mk.Scene:
    """Return ``scene`` set never to use the solver's compiled paths (its general solve)."""
    scene._solver.compiled_single = False
    scene._solver.compiled_array = False
    return scene


def _facts(value: Any) -> Any:
    """Return ``value`` as nested plain data in which equal means the same bits and types."""
    import numpy as np

    if isinstance(value, np.ndarray):
        return ('ndarray', value.dtype.str, value.shape, value.tobytes())
    if isinstance(value, dict):
        return ('dict', tuple((key, _facts(item)) for key, item in value.items()))
    if isinstance(value, (tuple, list)):
        return (type(value).__name__, tuple(_facts(item) for item in value))
    if isinstance(value, mk.Engagement) or hasattr(value, '__slots__'):
        names = getattr(value, '__slots__', None) or vars(value)
        return (type(value).__name__, tuple((name, _facts(getattr(value, name)))
                                            for name in names if not name.startswith('_')))
    return (type(value).__name__, repr(value))


def state_facts(state: mk.State) -> Any:
    """Return every field of a solved state, bounds included, for a bit-for-bit comparison."""
    bound = state.error_bound
    return _facts({'scene': state.scene, 'angle': state.angle, 'speed': state.speed,
                   'accel': state.accel, 'turns': state.turns, 'valid': state.valid,
                   'joints': state.joints, 'points': state.complex_points,
                   'singularity': state.singularity, 'failures': state.failures,
                   'bounds': (bound.joints, bound.points, bound.rubbing, bound.size,
                              bound.crank_length),
                   'rubbing': state.rubbing, 'intermittent': state.intermittent,
                   'jumps': state.jumps, 'drivers': state.drivers,
                   'imus': state.__dict__.get('imu_specs')})


def solve_outcome(scene: mk.Scene, *args: Any, **kwargs: Any) -> Any:
    """Return mk.solve's state facts and warnings, or the error's type, text and facts."""
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        try:
            state = mk.solve(scene, *args, **kwargs)
        except mk.AssemblyError as error:
            return (type(error), str(error), error.dyad, repr(error.angle),
                    getattr(error, 'facts', None), getattr(error, 'quantity', None))
    return state_facts(state), [(w.category, str(w.message), w.filename) for w in caught]


def array_outcome(scene: mk.Scene, *args: Any, **kwargs: Any) -> Any:
    """Return an array solve's state facts and warnings."""
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        state = mk.solve(scene, *args, **kwargs)
    return state_facts(state), [(w.category, str(w.message), w.filename) for w in caught]


def general_tick_outcome(scene: mk.Scene, theta: Any, omega: Any, alpha: Any, tol: float,
                         turns: int = 0, joints: Any = None, points: Any = None,
                         frames: Any = ()) -> Any:
    """Return what the general solver answers, in a tick function's terms, or its error.

    The solver's own compiled path is turned off (:func:`general_only`): a tick is
    held to the general solve, not to code compiled the same way. ``theta``,
    ``omega`` and ``alpha`` are one value each, or lists of one per driver.
    """
    import warnings

    from mech_kinematics.ros.ticker import values_from_state

    general_only(scene)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', mk.NearSingularWarning)
        try:
            if isinstance(theta, list):
                state = mk.solve(scene, theta, omega, alpha, max_error=tol)
            else:
                state = mk.solve(scene, theta, omega, alpha, turns=turns, max_error=tol)
        except mk.AssemblyError as error:
            return type(error), str(error)
    measures = state.singularity.values()
    joints = scene.output_joints if joints is None else joints
    points = scene.output_points if points is None else points
    return (values_from_state(state, joints, points, frames),
            min(measures) if measures else math.inf)


def tick_outcome(tick: Any, theta: Any, omega: Any, alpha: Any, tol: float,
                 turns: int = 0) -> Any:
    """Return what a tick function answers, or its error's type and text."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter('ignore', mk.NearSingularWarning)
        try:
            return tick(theta, omega, alpha, tol, turns)
        except mk.AssemblyError as error:
            return type(error), str(error)


# --- an independent forward kinematics of a URDF ---------------------------------------
# test/robot/test_robot_*.py and bench/urdf_bench.py check what mech_kinematics.robot
# answers with the URDF's own kinematics, written here once and apart from the package:
# xml.etree for the XML, 4x4 transforms from each joint's origin, axis and value, the
# loop closures read again from the text (issue 31).


def _rpy(r: float, p: float, y: float) -> Any:
    import numpy as np
    rx = np.array([[1, 0, 0], [0, math.cos(r), -math.sin(r)], [0, math.sin(r), math.cos(r)]])
    ry = np.array([[math.cos(p), 0, math.sin(p)], [0, 1, 0], [-math.sin(p), 0, math.cos(p)]])
    rz = np.array([[math.cos(y), -math.sin(y), 0], [math.sin(y), math.cos(y), 0], [0, 0, 1]])
    return rz @ ry @ rx


def _pose(element: Any, xyz_key: str = 'xyz', rpy_key: str = 'rpy') -> Any:
    """Return an ``<origin>``'s 4x4: ``rpy``, or URDF 1.1's ``quat_xyzw`` (through SciPy)."""
    import numpy as np
    out = np.eye(4)
    if element is not None:
        quat = element.get('quat_xyzw')
        if quat is None:
            out[:3, :3] = _rpy(*(float(v) for v in element.get(rpy_key, '0 0 0').split()))
        else:
            from scipy.spatial.transform import Rotation
            out[:3, :3] = Rotation.from_quat([float(v) for v in quat.split()]).as_matrix()
        out[:3, 3] = [float(v) for v in element.get(xyz_key, '0 0 0').split()]
    return out


class UrdfFk:
    """A URDF's forward kinematics and its loop closures, read with xml.etree.

    ``joints``: name -> (type, parent, child, origin 4x4, unit axis, mimic or None).
    ``closures``: (name, weld, link_a, frame_a 4x4, link_b, frame_b 4x4), from
    ``<constraint>`` elements, Isaac Sim's ``<loop_joint>`` and URDF+'s
    ``<loop>``, ``closing_NAME_1/2`` frames and a sidecar: a scikit-robot
    ``loop_closures.yaml`` (its point in the root frame at the zero pose), a
    file of ``<constraint>`` elements, an Extended-URDF ``robot.yaml`` (a
    frame: a link, or a joint's child link; ``6d`` a weld) or a fusion2URDF
    ``robot_data.yaml`` (the closing joint's frame in its parent, met by its
    child at the zero pose). ``slides``: closure name -> its axis in frame_a
    (a prismatic closure: the frames parallel, their origins on that line).
    """

    def __init__(self, text: str, sidecar: str | os.PathLike | None = None) -> None:
        import xml.etree.ElementTree as ET
        import numpy as np
        import yaml
        root = ET.fromstring(text)
        self.links = [link.get('name') for link in root.findall('link')]
        self.joints = {}
        for j in root.findall('joint'):
            axis = j.find('axis')
            vector = np.array([float(v) for v in (axis.get('xyz') if axis is not None
                                                  else '1 0 0').split()])
            mimic = j.find('mimic')
            rule = None if mimic is None else (mimic.get('joint'),
                                               float(mimic.get('multiplier', 1)),
                                               float(mimic.get('offset', 0)))
            self.joints[j.get('name')] = (j.get('type'), j.find('parent').get('link'),
                                          j.find('child').get('link'), _pose(j.find('origin')),
                                          vector / (np.linalg.norm(vector) or 1.0), rule)
        children = {j[2] for j in self.joints.values()}
        self.root = next(link for link in self.links if link not in children)
        self.closures = []
        self.slides = {}
        self._constraints(root)
        for tag, one, two in (('loop_joint', 'link1', 'link2'),
                              ('loop', 'predecessor', 'successor')):
            for c in root.findall(tag):
                ends = [c.find(one), c.find(two)]
                frames = [_pose(e) if e.get('xyz') is not None else _pose(e.find('origin'))
                          for e in ends]
                self._add(c.get('name'), c.get('type'), ends[0].get('link'), frames[0],
                          ends[1].get('link'), frames[1], c.find('axis'))
        for link in self.links:
            if link.startswith('closing_') and link.endswith('_1'):
                other = link[:-1] + '2'
                self.closures.append((link[:-2], False, link, np.eye(4), other, np.eye(4)))
        if sidecar is not None and Path(sidecar).read_text().lstrip().startswith('<'):
            self._constraints(ET.fromstring(Path(sidecar).read_text()))
        elif sidecar is not None:
            data = yaml.safe_load(Path(sidecar).read_text())
            zero = self.transforms({})
            for (a, b), kind in zip(data.get('closed_loop', []),   # Extended URDF
                                    data.get('type', ['6d'] * len(data.get('closed_loop', []))),
                                    strict=True):
                self.closures.append((f'{a}C{b}', kind.lower() == '6d', self._frame_link(a),
                                      np.eye(4), self._frame_link(b), np.eye(4)))
            for c in data.get('closing_joints', []):     # fusion2URDF
                frame = np.eye(4)
                frame[:3, :3] = _rpy(*c['origin_rpy_rad'])
                frame[:3, 3] = c['origin_xyz_m']
                on_child = np.linalg.inv(zero[c['child']]) @ zero[c['parent']] @ frame
                self.closures.append((c['name'], c['type'] == 'fixed', c['parent'], frame,
                                      c['child'], on_child))
                if c['type'] == 'prismatic':
                    self.slides[c['name']] = np.array(c['axis'], dtype=float)
            for i, c in enumerate(data.get('closures', [])):
                point = np.eye(4)
                point[:3, 3] = c['point']
                self.closures.append((f'closure_{i}', False, c['link_a'],
                                      np.linalg.inv(zero[c['link_a']]) @ point, c['link_b'],
                                      np.linalg.inv(zero[c['link_b']]) @ point))

    def _constraints(self, root: Any) -> None:
        for c in root.findall('constraint'):
            self._add(c.get('name'), c.get('type'), c.find('parent').get('link'),
                      _pose(c.find('parent_origin')), c.find('child').get('link'),
                      _pose(c.find('child_origin')), c.find('parent_axis'))

    def _add(self, name: str, kind: str, a: str, fa: Any, b: str, fb: Any, axis: Any) -> None:
        import numpy as np
        self.closures.append((name, kind in ('link', 'fixed'), a, fa, b, fb))
        if kind == 'prismatic':
            self.slides[name] = np.array([float(v) for v in (
                axis.get('xyz') if axis is not None else '1 0 0').split()])

    def _frame_link(self, name: str) -> str:
        """Return the link of a Pinocchio frame name: a joint's child, or the link."""
        return self.joints[name][2] if name in self.joints else name

    def transforms(self, values: dict) -> dict:
        """Return every link's 4x4 frame in the root's at ``values`` (0 where not given)."""
        import numpy as np
        out = {self.root: np.eye(4)}
        parent_of = {j[2]: (name, j) for name, j in self.joints.items()}

        def value(name: str) -> float:
            if name in values:
                return values[name]
            rule = self.joints[name][5]
            return 0.0 if rule is None else rule[1] * value(rule[0]) + rule[2]

        def frame(link: str) -> Any:
            if link not in out:
                name, (kind, parent, _, origin, axis, _) = parent_of[link]
                motion = np.eye(4)
                q = value(name) if kind in ('revolute', 'continuous', 'prismatic') else 0.0
                if kind in ('revolute', 'continuous'):
                    x, y, z = axis
                    c, s, v = math.cos(q), math.sin(q), 1 - math.cos(q)
                    motion[:3, :3] = [[c + x * x * v, x * y * v - z * s, x * z * v + y * s],
                                      [y * x * v + z * s, c + y * y * v, y * z * v - x * s],
                                      [z * x * v - y * s, z * y * v + x * s, c + z * z * v]]
                elif kind == 'prismatic':
                    motion[:3, 3] = axis * q
                out[link] = frame(parent) @ origin @ motion
            return out[link]

        for link in self.links:
            frame(link)
        return out

    def gaps(self, values: dict) -> dict:
        """Return each closure's gap (m) at ``values``.

        Its frames' origins apart; for a weld, its rotation too, times the loop's size.
        """
        import numpy as np
        frames = self.transforms(values)
        out = {}
        for name, weld, a, fa, b, fb in self.closures:
            ta, tb = frames[a] @ fa, frames[b] @ fb
            d = tb[:3, 3] - ta[:3, 3]
            if name in self.slides:     # off the slide's line, and turned
                u = ta[:3, :3] @ self.slides[name]
                u = u / np.linalg.norm(u)
                d = d - (d @ u) * u
                weld = True
            gap = float(np.linalg.norm(d))
            if weld:
                gap += float(np.linalg.norm(ta[:3, :3] - tb[:3, :3])) * self.loop_size(name)
            out[name] = gap
        return out

    def loop_size(self, name: str) -> float:
        """Return the size of a closure's loop at the zero pose (m).

        The largest distance between the frames of the links on its path
        through the tree, and the closure's point.
        """
        import numpy as np
        closure = next(c for c in self.closures if c[0] == name)
        frames = self.transforms({})
        parent_of = {j[2]: j[1] for j in self.joints.values()}

        def up(link: str) -> list:
            out = [link]
            while link in parent_of:
                link = parent_of[link]
                out.append(link)
            return out

        path_a, path_b = up(closure[2]), up(closure[4])
        common = next(link for link in path_a if link in path_b)
        links = path_a[:path_a.index(common) + 1] + path_b[:path_b.index(common)]
        points = [frames[link][:3, 3] for link in links]
        points.append((frames[closure[2]] @ closure[3])[:3, 3])
        return max(float(np.linalg.norm(p - q)) for p in points for q in points)


# --- Khurmi's four-bar as a URDF -------------------------------------------------------
# test/robot/test_robot.py and test_refusals.py: the packaged khurmi_four_bar_ad150 written
# by hand as a robot (crank "motor", coupler "elbow", rocker "rocker_pivot" about -z),
# closed at C in either closure form (issue 31).


KHURMI = """<?xml version="1.0"?>
<robot name="khurmi">
  <link name="frame"/><link name="crank"/><link name="coupler"/><link name="rocker"/>
  <joint name="motor" type="revolute">
    <parent link="frame"/><child link="crank"/>
    <origin xyz="0 0 0" rpy="0 0 1.0471975511965976"/><axis xyz="0 0 1"/>
    <limit lower="-3.2" upper="3.2" effort="1" velocity="1"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="crank"/><child link="coupler"/>
    <origin xyz="0.04 0 {dz}" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="rocker_pivot" type="continuous">
    <parent link="frame"/><child link="rocker"/>
    <origin xyz="0.15 0 0" rpy="0 0 0"/><axis xyz="0 0 -1"/>
  </joint>
  {closure}
  <transmission name="t"><type>transmission_interface/SimpleTransmission</type>
    <joint name="motor"><hardwareInterface>EffortJointInterface</hardwareInterface></joint>
    <actuator name="m"/></transmission>
</robot>
"""


def solve_urdf_text(tmp_path, capsys, text, *args):
    """Return ``solve ROBOT.urdf ARGS``'s (status, stdout, stderr) for a URDF's ``text``."""
    from mech_kinematics.__main__ import main as cli_main
    path = tmp_path / 'robot.urdf'
    path.write_text(text)
    status = cli_main(['solve', str(path), *args])
    out, err = capsys.readouterr()
    return status, out, err


def khurmi_pin():
    """Return pin C of Khurmi's four-bar in the coupler's and the rocker's frames (m)."""
    scene = mk.load_scene('khurmi_four_bar_ad150')
    state = mk.solve(scene, scene.input.angle)
    b, c = state.complex_points['B'][0], state.complex_points['C'][0]
    on_coupler = (c - b) * complex(math.cos(-math.pi / 3), math.sin(-math.pi / 3))
    return on_coupler, c - 0.15


def khurmi_urdf(form='constraint', dz=0.0):
    """Return Khurmi's four-bar (AB 40, BC 150, CD 80, AD 150 mm) in URDF, closed in ``form``."""
    coupler, rocker = khurmi_pin()
    if form == 'constraint':
        closure = (f'<constraint name="pin_C" type="revolute">'
                   f'<parent link="coupler"/><parent_origin xyz="{coupler.real!r} '
                   f'{coupler.imag!r} {-dz!r}" rpy="0 0 0"/><parent_axis xyz="0 0 1"/>'
                   f'<child link="rocker"/><child_origin xyz="{rocker.real!r} {rocker.imag!r} '
                   f'0" rpy="0 0 0"/><child_axis xyz="0 0 -1"/></constraint>')
    else:
        closure = ''.join(
            f'<link name="closing_C_{i}"/><joint name="closing_C_{i}_frame" type="fixed">'
            f'<parent link="{link}"/><child link="closing_C_{i}"/>'
            f'<origin xyz="{z.real!r} {z.imag!r} {oz!r}" rpy="0.3 0.1 0.2"/></joint>'
            for i, link, z, oz in ((1, 'coupler', coupler, -dz), (2, 'rocker', rocker, 0.0)))
    return KHURMI.format(closure=closure, dz=dz)


def khurmi_chain_urdf(count):
    """Return Khurmi's four-bar with a chain of ``count`` fixed links hanging from its frame.

    Issue 42: a URDF of 40,000 fixed joints (5.8 MB) read in quadratic time; each link is
    ``c<i>``, 1 mm from the one before.
    """
    links = ''.join(f'<link name="c{i}"/><joint name="f{i}" type="fixed"><parent link='
                    f'"{"frame" if i == 0 else f"c{i - 1}"}"/><child link="c{i}"/><origin '
                    f'xyz="0.001 0 0" rpy="0 0 0"/></joint>\n' for i in range(count))
    return khurmi_urdf().replace('</robot>', links + '</robot>')


def khurmi_closures_yaml(count):
    """Return a loop_closures.yaml closing Khurmi's open four-bar (no closure in its URDF) at C.

    ``count`` times over (issue 42: 5000 closures read in quadratic time); ``independent``:
    the motor.
    """
    _, rocker = khurmi_pin()
    c = rocker + 0.15
    line = (f'- {{link_a: coupler, link_b: rocker, point: [{c.real!r}, {c.imag!r}, 0.0], '
            f'axis: [0, 0, 1]}}\n')
    return 'closures:\n' + line * count + 'independent: [motor]\n'


#: Khurmi's four-bar with no closure (a loop_closures.yaml closes it).
KHURMI_OPEN = KHURMI.format(closure='', dz=0.0)


#: The units of the generated scenes (test_compiler, test_forces).
MM_DEG = {'length': 'mm', 'angle': 'deg'}


def crank_entry(length=50.0, angle=30.0, rpm=120.0, accel=-3.0, center='A', point='B'):
    """Return a crank's scene entry (a link ``crank``)."""
    return {'link': 'crank', 'center': center, 'point': point, 'length': length,
            'angle': angle, 'speed_rpm': rpm, 'accel': accel}


def scene_mapping(name, ground, dyads=(), points=None, **drivers):
    """Return the scene of these entries (mm and deg), as a scene file's mapping."""
    data = {'name': name, 'units': MM_DEG, 'ground': ground, 'dyads': list(dyads), **drivers}
    if points:
        data['points'] = points
    return data


def slider_scene():
    """Return a slider-crank driven from its piston: its crank pin an RRR from O and the pin."""
    return scene_mapping(
        'slider', {'O': [0, 0]},
        inputs=[{'slider': 'piston', 'point': 'P', 'guide': {'through': 'O', 'angle': 0},
                 'position': -696.6166, 'speed': 1.5, 'accel': -4.0}],
        dyads=[{'type': 'RRR', 'point': 'B', 'links': [
            {'name': 'crank', 'from': 'O', 'length': 150},
            {'name': 'rod', 'from': 'P', 'length': 600}], 'branch': -1}])


def hinge_scene():
    """Return a five-bar whose second motor sits on the crank (an elbow): a hinge, an RRR."""
    return scene_mapping(
        'hinge', {'A': [0, 0], 'D': [150, 0]},
        inputs=[crank_entry(50, 30, 20, 1.0),
                {'motor': 'elbow', 'angle': 45, 'speed': -2.0, 'accel': 1.0}],
        dyads=[{'type': 'hinge', 'link': 'fore', 'parent': 'crank', 'center': 'B',
                'point': 'C', 'length': 60, 'motor': 'elbow'},
               {'type': 'RRR', 'point': 'E', 'links': [
                   {'name': 'left', 'from': 'C', 'length': 150},
                   {'name': 'right', 'from': 'D', 'length': 150}], 'branch': 1}])


def fold_scene():
    """Return a four-bar driven at its coupler-to-rocker pin C (a fold): no crank at all.

    Crank A-B 40 mm, coupler B-C 100 mm, rocker D-C 70 mm, |AD| = 80 mm; the
    motor's angle (the coupler's from the rocker's axis) assembles from 92 to
    161.8 deg, where |DB| = |70 + 100 exp(i q)| mm lies between 40 and 120 mm.
    """
    return scene_mapping(
        'fold', {'A': [0, 0], 'D': [80, 0]},
        inputs=[{'motor': 'knee', 'angle': 120, 'speed': 2.0, 'accel': 1.0}],
        dyads=[{'type': 'fold', 'point': 'B', 'pin': 'C', 'links': [
            {'name': 'crank', 'from': 'A', 'length': 40},
            {'name': 'rocker', 'from': 'D', 'length': 70}],
            'coupler': {'name': 'coupler', 'length': 100}, 'motor': 'knee', 'branch': 1}])


def collar_scene():
    """Return a collar driven along a crank by an actuator, a link from it to a guided block."""
    return scene_mapping(
        'collar', {'O': [0, 0], 'G': [0, -300]},
        inputs=[crank_entry(500, 60, 30, 2.0, 'O', 'T'),
                {'actuator': 'x', 'length': 200, 'speed': 2, 'accel': 3, 'stroke': [100, 300]}],
        dyads=[{'type': 'collar', 'point': 'C', 'link': 'crank', 'from': 'O', 'toward': 'T',
                'actuator': 'x'},
               {'type': 'RRP', 'point': 'P', 'link': {'name': 'arm', 'from': 'C', 'length': 700},
                'guide': {'through': 'G', 'angle': 0}, 'slider': 'block', 'branch': 1}])


def triad_scene():
    """Return a scene with one triad (class III): a crank, a ternary coupler, three arms."""
    return scene_mapping(
        'triad', {'A': [0, 0], 'D': [81, 27]}, input=crank_entry(25, 30, 60, 0.0),
        points={'C': {'link': 'crank', 'origin': 'A', 'xaxis': 'B', 'local': [25, -43]}},
        dyads=[{'type': 'triad', 'link': {'name': 'coupler', 'pins': ['E', 'F', 'G'],
                                          'length': 74, 'local': [41, 32]},
                'links': [{'name': 'link_e', 'from': 'B', 'length': 75},
                          {'name': 'link_f', 'from': 'C', 'length': 92},
                          {'name': 'rocker', 'from': 'D', 'length': 82}], 'angle': -111}])


def gepetto_five_bar_reference(closures: Any = None) -> dict:
    """Return a pose of Gepetto's five-bar that closes it (its zero pose is 0.3 m open).

    The motors at 0 and closedloop1_A at 0; free1, closedloop1_B and free2 by
    SciPy's least squares on ``UrdfFk``'s 6d gap (our own kinematics).
    """
    import numpy as np
    from scipy.optimize import least_squares

    data = Path(__file__).resolve().parent / 'data' / 'urdf'
    closures = closures or data / 'gepetto_5bar_linkage.robot.yaml'

    fk = UrdfFk((data / 'gepetto_5bar_linkage.urdf').read_text(), closures)
    _, _, a, fa, b, fb = fk.closures[0]
    names = ('free1', 'closedloop1_B', 'free2')

    def residual(x):
        frames = fk.transforms(dict(zip(names, x, strict=True)))
        ta, tb = frames[a] @ fa, frames[b] @ fb
        return np.concatenate([ta[:3, 3] - tb[:3, 3], (ta[:3, :3] - tb[:3, :3]).ravel()])

    fit = least_squares(residual, [0.5, 0.5, -0.5], xtol=1e-15, ftol=1e-15, gtol=1e-15)
    assert np.abs(fit.fun).max() <= 1e-15
    return {'mot1': 0.0, 'mot2': 0.0, **dict(zip(names, map(float, fit.x), strict=True))}
