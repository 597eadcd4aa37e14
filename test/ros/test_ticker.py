# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The compiled tick against the general solver: the same bits, the same refusals (issue 14)."""

import dataclasses
import importlib
import math
from pathlib import Path
import warnings

from helpers import (crank_scene_names, driver_scene_names, general_tick_outcome, strip_scene,
                     tick_outcome)
import numpy as np
import pytest
import yaml

import mech_kinematics as mk
from mech_kinematics.ros.ticker import (compile_tick, compiled_tick, general_tick,
                                        NOT_IN_THE_TICK, tick_function, values_from_state)
from mech_kinematics.solver.compiler import NotCompiled, scene_plan
from mech_kinematics.verify.cases import chain_scene
from mech_kinematics.verify.extreme import extreme_cases

#: Crank angles over two turns and a bit, both signs.
ANGLES = np.linspace(-7.0, 7.0, 351)
TOLERANCES = (1e-6, 1e-12, math.inf)


def _motion(scene):
    """Return the scene a tick answers for: with masses, its motion alone (issue 32).

    The node's tick reports the motion, not the forces (not yet published), so
    it is held to the solve of the same scene without masses, loads and
    gravity: an instant is not refused for forces the tick does not report.
    """
    if scene.dynamics is None:
        return scene
    return dataclasses.replace(scene, gravity=None, masses=(), loads=(),
                               outputs_joints=scene.output_joints,
                               outputs_points=scene.output_points)


def _assert_same(scene, tick, angles, speeds=(None,), turns=(0,), **kwargs):
    """Every instant: identical values (bit for bit), measure, or error and message."""
    refused = 0
    for theta in angles:
        for speed in speeds:
            omega = scene.input.speed if speed is None else speed
            for tol in TOLERANCES:
                for k in turns:
                    expected = general_tick_outcome(_motion(scene), float(theta), omega,
                                                    scene.input.accel, tol, k, **kwargs)
                    got = tick_outcome(tick, float(theta), omega, scene.input.accel, tol, k)
                    assert repr(got) == repr(expected), (scene.name, theta, tol, k)
                    refused += isinstance(expected[0], type)
    return refused


@pytest.mark.parametrize('name', crank_scene_names())
def test_every_packaged_scene_compiles_to_the_same_bits(name):
    """Over two turns, at three tolerances, the compiled tick answers as mk.solve does.

    Each of 351 angles at the scene's speed, and every fifth angle at two other
    speeds (-3.5 rad/s, 1e4 rad/s) and 3 and -40 turns away. Every packaged
    scene compiles: a step whose kernels leave the subset the tick understands
    (``solver/base.py``) would fall back to the general solver and fail here
    (issue 17). The Geneva wheel's crank turns are passed on.
    """
    scene = mk.load_scene(name)
    tick, compiled = tick_function(scene)
    # A triad's kernel loops over its roots (solver/triad.py): its scene's tick is the
    # general one, which must answer alike all the same.
    assert compiled == (name != 'stephenson_iii'), f'{name}: a step falls back to the general path'
    # Every angle at the scene's speed; every fifth at the other speeds and turns.
    refused = _assert_same(scene, tick, ANGLES)
    refused += _assert_same(scene, tick, ANGLES[::5], speeds=(-3.5, 1e4), turns=(0, 3, -40))
    refused += _assert_same(scene, tick, ANGLES[::5], turns=(3, -40))
    if name == 'four_bar_coupler_points':
        assert refused > 0      # the triple rocker's unassemblable angles, refused alike


@pytest.mark.parametrize('name', driver_scene_names())
def test_several_driver_scenes_compile_to_the_same_bits(name):
    """A scene with several drivers compiles (issue 18): the same bits and refusals as mk.solve.

    Its tick takes one value per driver (sequences, as mk.solve; bare values for
    one driver, an actuator alone, as the node and mk.solve take them): over a
    grid of the drivers, at three tolerances and three sets of rates (one at
    rest, one beyond 2**40 /s that the general solver rescales), values,
    measure, or the error and its message (naming every driver's position) are
    mk.solve's.
    """
    scene = mk.load_scene(name)
    tick, compiled = tick_function(scene)
    # A triad's kernel loops over its roots (solver/triad.py): its scene's tick is the
    # general one, which must answer alike all the same.
    assert compiled == (name != 'stephenson_iii'), f'{name}: a step falls back to the general path'
    alone = len(scene.drivers) == 1
    if alone:   # the boom's cylinder, within its stroke and beyond both ends
        low, high = scene.drivers[0].stroke
        grid = [(x,) for x in np.linspace(low - 0.2, high + 0.2, 13)]
        rates = [([0.0], [0.0]), ([0.1], [0.05]), ([1e13], [0.0])]
    elif name in ('five_bar', 'five_bar_payload'):
        grid = [(a, b) for a in np.linspace(0.0, 2 * math.pi, 9) for b in np.linspace(0, 6, 7)]
        rates = [([0.0, 0.0], [0.0, 0.0]), ([3.0, -1.5], [2.0, 0.5]), ([1e13, 1.0], [0.0, 0.0])]
    else:
        grid = [(a, b) for a in np.linspace(1.9, 3.4, 7) for b in np.linspace(2.4, 4.0, 7)]
        rates = [([0.0, 0.0], [0.0, 0.0]), ([0.1, -0.3], [0.05, 0.2]), ([1e13, 0.0], [0.0, 0.0])]
    refused = 0
    for x in grid:
        positions = [float(value) for value in x]
        for speeds, accels in rates:
            drive = (positions[0], speeds[0], accels[0]) if alone else (positions, speeds, accels)
            for tol in TOLERANCES:
                with warnings.catch_warnings():
                    warnings.simplefilter('ignore', mk.NearSingularWarning)
                    try:
                        state = mk.solve(_motion(scene), *drive, max_error=tol)
                        expected = (values_from_state(state, scene.output_joints,
                                                      scene.output_points),
                                    min(state.singularity.values()))
                    except mk.AssemblyError as error:
                        expected = (type(error), str(error))
                    try:
                        got = tick(*drive, tol, 0)
                    except mk.AssemblyError as error:
                        got = (type(error), str(error))
                assert repr(got) == repr(expected), (name, positions, speeds, tol)
                refused += isinstance(expected[0], type)
    assert refused > 0  # cranks apart, cylinders beyond their strokes: refused alike


def test_a_step_outside_the_kernel_subset_falls_back(monkeypatch):
    """A kernel with a loop is not compiled: the scene falls back, saying why in one line."""
    scene = mk.load_scene('khurmi_four_bar_ad150')
    step = type(scene_plan(scene).steps[0])

    def looping(self, ctx):
        for _ in range(1):
            ctx.measures[self.key] = 1.0

    assert tick_function(scene)[1]
    monkeypatch.setattr(step, 'kernels', classmethod(lambda cls: (looping,)))
    assert not tick_function(scene)[1]
    assert compiled_tick(scene) == NotCompiled(
        'step RRR C: kernel uses `for` (not in the kernel subset)')


def test_the_extreme_suite_refuses_and_answers_alike():
    """Toggles, change points, grazing guides, a pin at the pivot: same answers and refusals."""
    cases = extreme_cases(extra_angles=0)  # each case's own instants (the report's smoke run)
    compiled = 0
    for case in cases:
        tick, is_compiled = tick_function(case.scene)
        compiled += is_compiled
        speed = case.speed if case.speed is not None else case.scene.input.speed
        _assert_same(case.scene, tick, case.angles, speeds=(speed,))
    assert compiled >= len(cases) - 3     # only the rescaled sizes fall back


def test_a_chain_of_sixty_four_dyads_and_its_frames():
    """A large scene with frames of every link: values and frame poses as the solver's."""
    scene = chain_scene(64)
    frames = [(f'G{i}', f'rocker{i}', 0.0) for i in range(1, 65)] + [('P0', None, 0.25)]
    tick = compile_tick(scene, scene.output_joints[:5], scene.output_points[-3:], frames)
    assert tick is not None
    _assert_same(scene, tick, ANGLES[::7], joints=scene.output_joints[:5],
                 points=scene.output_points[-3:], frames=frames)


def test_a_strip_of_rigid_triangles_compiles_to_the_same_bits():
    """Dyads whose starts are fixed on one link (bounded as carried by it) compile alike."""
    scene = strip_scene()
    tick, compiled = tick_function(scene)
    assert compiled, 'a rigid triangle falls back to the general solver'
    _assert_same(scene, tick, ANGLES)
    _assert_same(scene, tick, ANGLES[::5], speeds=(None, -3.5), turns=(3,))
    _assert_same(scene, tick, ANGLES[::5], speeds=(-3.5,))


def _tiny_four_bar(tmp_path):
    """Return the packaged four-bar with every length 1e-300 m (the solver rescales it)."""
    source = Path(__file__).resolve().parents[2] / 'config' / 'scenes' / \
        'khurmi_four_bar_ad150.yaml'
    doc = yaml.safe_load(source.read_text())
    doc['units'] = {'length': 'm', 'angle': 'deg'}
    doc['ground'] = {k: [v[0] * 1e-300, v[1] * 1e-300] for k, v in doc['ground'].items()}
    doc['input']['length'] *= 1e-300
    for dyad in doc['dyads']:
        for link in dyad['links']:
            link['length'] *= 1e-300
    path = tmp_path / 'tiny.yaml'
    path.write_text(yaml.safe_dump(doc))
    return mk.load_scene(path)


def test_a_scene_the_solver_rescales_is_served_by_the_general_solver(tmp_path):
    """Lengths of 1e-300 m are not compiled; tick_function falls back with the same answers."""
    scene = _tiny_four_bar(tmp_path)
    assert compile_tick(scene) is None
    assert compiled_tick(scene).reason == (
        'scene rescaled: its size 1.5e-298 m is beyond 2**60 of 1 m (its lengths are solved '
        'scaled by a power of two)')
    tick, compiled = tick_function(scene)
    assert not compiled
    _assert_same(scene, tick, ANGLES[::10])


def test_the_array_path_solves_a_rescaled_scene(tmp_path):
    """Lengths of 1e-300 m over an array of angles: answered as one angle at a time.

    The array path failed ('bool' object has no attribute 'all') for a scene
    the solver rescales, on its ground points' constant values.
    """
    scene = _tiny_four_bar(tmp_path)
    angles = np.linspace(0.0, 2 * np.pi, 9)
    cycle = mk.solve(scene, angles)
    assert cycle.valid.all()
    for i, theta in enumerate(angles):
        single = mk.solve(scene, float(theta))
        assert cycle.points['C'].position[i].tolist() == single.points['C'].position.tolist()


@pytest.mark.parametrize('kind', [np.float64, np.float32, int])
def test_any_real_angle_is_ticked_as_the_float_it_equals(kind):
    """An np.float64, np.float32 or int crank angle (and np.int64 turns) give the float's values.

    NumPy scalars are converted once on entry: every operation on them would
    be slower (issue 19: an np.float64 angle got 1.4x from the compiled tick
    where a Python float got 2x).
    """
    scene = mk.load_scene('geneva')
    tick = compile_tick(scene)
    for theta in (1, 2, -3):
        angle = kind(theta)
        expected = tick(float(angle), scene.input.speed, 0.0, 1e-6, 2)
        got = tick(angle, np.float64(scene.input.speed), np.float64(0.0), 1e-6, np.int64(2))
        assert repr(got) == repr(expected)
        assert all(type(value) is float for value in got[0])


def test_the_general_tick_never_compiles_in_its_callers_thread(monkeypatch):
    """Asked past mk.solve's COMPILE_AFTER, the general tick compiles nothing; same answers.

    mk.solve compiles a scene solved often in its caller's thread. The node's tick thread,
    serving a 100-dyad strip on the general tick while the tick compiled in the background,
    compiled that scene's single-angle path itself at its 256th instant and published
    nothing until done (14 to 21 s beside two CPU hogs); a crank at rest, whose every
    instant the compiled tick hands over, did the same. A scene already compiled keeps it.
    """
    solve_module = importlib.import_module('mech_kinematics.solver.solve')
    compiles = []
    real = solve_module.compile_scene
    monkeypatch.setattr(solve_module, 'compile_scene',
                        lambda *args: compiles.append(args) or real(*args))
    scene = mk.load_scene('khurmi_four_bar_ad150')
    general = general_tick(scene, None, None, ())
    angles = np.linspace(0.0, 2 * np.pi, solve_module.COMPILE_AFTER + 10)
    answers = [general(float(theta), scene.input.speed, scene.input.accel, 1e-6)
               for theta in angles]
    assert compiles == []
    assert scene._solver.compiled_single == NotCompiled(NOT_IN_THE_TICK)
    for theta, answer in list(zip(angles, answers, strict=True))[::25]:
        assert repr(answer) == repr(general_tick_outcome(scene, float(theta), scene.input.speed,
                                                         scene.input.accel, 1e-6))
    compiled = mk.load_scene('khurmi_four_bar_ad150')
    for theta in angles:
        mk.solve(compiled, float(theta))
    assert len(compiles) == 1
    fast = compiled._solver.compiled_single
    general_tick(compiled, None, None, ())
    assert callable(fast) and compiled._solver.compiled_single is fast
