# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The solver's compiled single-angle path against its general one: the same state, bit for bit.

``solve(scene, angle)`` compiles a scene it has solved at single angles often
enough (``solver/compiler.py``'s ``Single`` and ``Array`` targets, issue 19's
"bounds that cost little"): its states, bounds, warnings and refusals must be
the general path's exactly. Where a scene does not compile, the compiler says
why (issue 30).
"""

import importlib
import math

from helpers import (array_outcome, crank_scene_names, driver_scene_names, general_only,
                     solve_outcome, state_facts, strip_scene)
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics import solver as lk
from mech_kinematics.solver.compiler import (ARRAY, Array, compile_scene, COMPILE_STEPS,
                                             NotCompiled, SINGLE, Single)
from mech_kinematics.verify.extreme import extreme_cases

#: The module (``mech_kinematics.solver.solve`` is also the name of its function).
solve_module = importlib.import_module('mech_kinematics.solver.solve')
COMPILE_AFTER, ARRAY_COMPILE_AFTER = solve_module.COMPILE_AFTER, solve_module.ARRAY_COMPILE_AFTER

#: Crank angles over two turns and a bit, both signs.
ANGLES = np.linspace(-7.0, 7.0, 141)
#: Every other one (0.2 rad apart, both ends) for the packaged scenes' single-angle solves,
#: each at three speeds, three tolerances and two turn counts (18 solves a path an angle).
SINGLE_ANGLES = ANGLES[::2]
TOLERANCES = (1e-6, 1e-12, math.inf)


def _pair(scene_of):
    """Return the same scene twice: compiled now, and never compiled."""
    fast, slow = scene_of(), general_only(scene_of())
    fast._solver.compiled_single = compile_scene(fast, SINGLE)
    fast._solver.compiled_array = compile_scene(fast, ARRAY)
    fast._solver.compiled_usual = solve_module._compile_usual(fast._solver)
    return fast, slow


#: The pairs compiled so far, by scene name: a test of the single-angle path and one of
#: the array path share one compile of a scene (solving neither scene changes it).
_PAIRS = {}


def _shared_pair(name, scene_of):
    """Return :func:`_pair` of ``scene_of``, compiled once for every test here asking ``name``."""
    if name not in _PAIRS:
        _PAIRS[name] = _pair(scene_of)
    return _PAIRS[name]


def _assert_same(fast, slow, angles, speeds=(None,), turns=(0,)):
    refused = 0
    for theta in angles:
        for speed in speeds:
            for tol in TOLERANCES:
                for k in turns:
                    args = (float(theta), speed)
                    expected = solve_outcome(slow, *args, turns=k, max_error=tol)
                    assert solve_outcome(fast, *args, turns=k, max_error=tol) == expected, (
                        fast.name, theta, speed, tol, k)
                    refused += isinstance(expected[0], type)
    return refused


@pytest.mark.parametrize('name', crank_scene_names())
def test_every_packaged_scene_solves_alike_compiled(name):
    """Over two turns (71 angles), three speeds, three tolerances: the same states and refusals."""
    fast, slow = _shared_pair(name, lambda: mk.load_scene(name))
    if name == 'geneva':    # its state reports the lever's engagement: the general path's
        assert fast._solver.compiled_single == NotCompiled(
            "an intermittent lever's engagement is reported (wheel): the general path's")
    elif name == 'stephenson_iii':  # a triad's kernel loops over its roots: the general path's
        assert fast._solver.compiled_single == NotCompiled(
            'step triad coupler: kernel uses `try` (not in the kernel subset)')
    else:
        assert fast._solver.compiled_single, f'{name} does not compile'
    refused = _assert_same(fast, slow, SINGLE_ANGLES, speeds=(None, -3.5, 1e4), turns=(0, 3))
    if name == 'four_bar_coupler_points':
        assert refused > 0      # the triple rocker's unassemblable angles, refused alike


def test_the_extreme_suite_refuses_and_answers_alike():
    """Toggles, change points, grazing guides, a pin at the pivot: same states and refusals."""
    compiled = 0
    for case in extreme_cases(extra_angles=0):
        fast, slow = _shared_pair(f'extreme {case.name}', lambda case=case: case.scene)
        compiled += bool(fast._solver.compiled_single)
        speed = case.speed if case.speed is not None else case.scene.input.speed
        _assert_same(fast, slow, case.angles, speeds=(speed,))
    assert compiled > 0


@pytest.mark.parametrize('name', crank_scene_names())
def test_every_packaged_scene_solves_arrays_alike_compiled(name):
    """Arrays of angles, speeds and turns, three tolerances: identical states, masks, bounds."""
    fast, slow = _shared_pair(name, lambda: mk.load_scene(name))
    if name == 'stephenson_iii':  # a triad's kernel loops over its roots: the general path's
        assert fast._solver.compiled_array == NotCompiled(
            'step triad coupler: kernel uses `try` (not in the kernel subset)')
    elif name != 'geneva':
        assert fast._solver.compiled_array, f'{name} does not compile'
        # ({} below: the usual call, at the scene's own rates, compiled for them)
        assert fast._solver.compiled_usual, f'{name} has no compiled usual call'
    speeds = np.linspace(-20.0, 30.0, ANGLES.size)
    for kwargs in ({}, {'speed': speeds}, {'speed': 3.0, 'accel': speeds},
                   {'turns': np.arange(ANGLES.size) % 3}, {'max_error': 1e-12},
                   {'max_error': math.inf}):
        for angles in (ANGLES, ANGLES[:1], ANGLES[::-7]):
            cut = {key: value[:angles.size] if np.ndim(value) else value
                   for key, value in kwargs.items()}
            if 'speed' in cut and np.ndim(cut['speed']):
                cut['speed'] = speeds[:angles.size]
            assert array_outcome(fast, angles, **cut) == array_outcome(slow, angles, **cut), (
                name, angles.size, kwargs)


def test_rigid_triangles_compile_and_solve_alike():
    """Dyads whose starts are fixed on one link (a strip on a coupler): compiled alike."""
    fast, slow = _pair(strip_scene)
    assert fast._solver.compiled_single and fast._solver.compiled_array
    assert fast._solver.compiled_usual
    _assert_same(fast, slow, ANGLES, speeds=(None, -3.5), turns=(0, 3))
    for kwargs in ({}, {'speed': np.linspace(-20.0, 30.0, ANGLES.size)}, {'max_error': 1e-12}):
        assert array_outcome(fast, ANGLES, **kwargs) == array_outcome(slow, ANGLES, **kwargs)


def test_the_extreme_suite_solves_arrays_alike():
    """The extreme cases over their angles as one array: same states, masks and bounds."""
    for case in extreme_cases(extra_angles=0):
        fast, slow = _shared_pair(f'extreme {case.name}', lambda case=case: case.scene)
        speed = case.speed if case.speed is not None else case.scene.input.speed
        angles = np.asarray(case.angles, dtype=float)
        assert array_outcome(fast, angles, speed) == array_outcome(slow, angles, speed)
        if case.speed is None:      # at the scene's own rates: the usual call's compiled path
            assert array_outcome(fast, angles) == array_outcome(slow, angles), case.name


@pytest.mark.parametrize('angle', [np.float64(1.25), np.float32(1.25), 1, np.int64(-2)])
def test_any_real_angle_gives_the_state_of_the_float_it_equals(angle):
    """An np.float64, np.float32 or int angle is solved as float(angle), compiled or not."""
    fast, slow = _pair(lambda: mk.load_scene('khurmi_four_bar_ad150'))
    expected = state_facts(mk.solve(slow, float(angle)))
    assert state_facts(mk.solve(fast, angle)) == expected
    assert state_facts(mk.solve(slow, angle)) == expected


def test_a_scene_is_compiled_after_its_first_single_angle_solves():
    """The first COMPILE_AFTER - 1 solves run the general path; the next compiles the scene."""
    scene = mk.load_scene('slider_crank_150_600')
    for _ in range(COMPILE_AFTER - 1):
        mk.solve(scene, 0.5)
        assert scene._solver.compiled_single is None
    mk.solve(scene, 0.5)
    assert callable(scene._solver.compiled_single)
    mk.solve(scene, np.linspace(0.0, 1.0, 5))       # the array path counts apart
    assert callable(scene._solver.compiled_single) and scene._solver.compiled_array is None
    for _ in range(ARRAY_COMPILE_AFTER - 2):
        mk.solve(scene, np.linspace(0.0, 1.0, 5))
        assert scene._solver.compiled_array is None
    mk.solve(scene, np.linspace(0.0, 1.0, 5))
    assert callable(scene._solver.compiled_array)


def test_a_scene_kept_on_the_general_path_never_compiles_and_answers_alike():
    """``keep_general_path``: the public call a thread that must not stall makes (the node's tick).

    After it, solves past COMPILE_AFTER keep the general path, with the reason
    given, and answer the bits of a scene that compiled; a scene compiled
    already stays compiled; an empty reason is refused.
    """
    kept = mk.load_scene('slider_crank_150_600')
    lk.keep_general_path(kept, 'a reason of the caller')
    fast, _ = _pair(lambda: mk.load_scene('slider_crank_150_600'))
    for angle in np.linspace(0.0, 6.0, COMPILE_AFTER + 3):
        assert state_facts(mk.solve(kept, float(angle))) == \
            state_facts(mk.solve(fast, float(angle)))
    path = kept._solver.compiled_single
    assert not path and path.reason == 'a reason of the caller'
    compiled = fast._solver.compiled_single
    assert callable(compiled)
    lk.keep_general_path(fast, 'too late')
    assert fast._solver.compiled_single is compiled
    with pytest.raises(ValueError, match='the reason the general path serves'):
        lk.keep_general_path(mk.load_scene('slider_crank_150_600'), '')


def test_a_held_state_is_not_changed_by_later_solves():
    """A state from the compiled path keeps its values when the scene is solved again."""
    fast, _ = _pair(lambda: mk.load_scene('khurmi_four_bar_ad150'))
    for one, other in ((0.3, 2.0), (np.linspace(0, 1, 50), np.linspace(2, 3, 50))):
        first = mk.solve(fast, one)
        facts = state_facts(first)
        mk.solve(fast, other)
        assert state_facts(first) == facts


@pytest.mark.parametrize('compiled', [False, True])
def test_the_callers_arrays_are_never_written(compiled):
    """Angles, speeds and accelerations given as arrays keep their values, some angles refused.

    The array path wrote NaN into the caller's speed array at the refused
    angles (it masked the crank's rate in place), and failed for an array of
    accelerations with a constant speed.
    """
    scene = mk.load_scene('four_bar_coupler_points')
    if compiled:
        scene._solver.compiled_array = compile_scene(scene, ARRAY)
    else:
        general_only(scene)
    angles, speeds = ANGLES.copy(), np.linspace(-20.0, 30.0, ANGLES.size)
    for args in ((angles, speeds), (angles, 3.0, speeds.copy()), (angles, speeds, speeds)):
        before = [np.array(x) for x in args]
        state = mk.solve(scene, *args)
        assert not state.valid.all() and state.valid.any()
        for x, was in zip(args, before, strict=True):
            assert np.array_equal(x, was)
        for index in (5, 60):
            one = mk.solve(scene, *(float(np.broadcast_to(x, angles.shape)[index])
                                    for x in args))
            assert state.joints['crank'].acceleration[index] == one.joints['crank'].acceleration


@pytest.mark.parametrize('args, kwargs', [((math.nan,), {}), ((math.inf,), {}),
                                          ((0.5,), {'max_error': 0.0}),
                                          ((0.5,), {'max_error': -1e-6}),
                                          ((0.5,), {'turns': 1.5})])
def test_bad_input_is_refused_alike_compiled(args, kwargs):
    """A non-finite angle, a tolerance that is not positive, fractional turns: the same error."""
    fast, slow = _pair(lambda: mk.load_scene('khurmi_four_bar_ad150'))
    errors = []
    for scene in (fast, slow):
        with pytest.raises(ValueError) as caught:
            mk.solve(scene, *args, **kwargs)
        errors.append(str(caught.value))
    assert errors[0] == errors[1] and errors[0].startswith('Expected')


def test_the_array_path_compiles_run_and_the_single_angle_path_the_kernels(monkeypatch):
    """Step.kernels names the single-angle path only: the array path compiles ``run``.

    A kernel outside the subset (a loop) makes the single-angle path fall back
    (``None``) while the array path, compiled from ``run``, still compiles.
    """
    scene = mk.load_scene('khurmi_four_bar_ad150')
    step = type(scene._solver.run_plan.steps[0])

    def looping(self, ctx):
        for _ in range(1):
            ctx.measures[self.key] = 1.0

    monkeypatch.setattr(step, 'kernels', classmethod(lambda cls: (looping,)))
    assert compile_scene(scene, SINGLE) == NotCompiled(
        'step RRR C: kernel uses `for` (not in the kernel subset)')
    assert callable(compile_scene(scene, ARRAY))


@pytest.mark.parametrize('name', driver_scene_names())
def test_a_scene_of_several_drivers_keeps_the_general_path(name):
    """Several drivers or an actuator: neither path compiles, and solving often changes nothing."""
    scene = mk.load_scene(name)
    names = ', '.join(driver.name for driver in scene.drivers)
    drivers = (f'its driver {names} is not a crank' if len(scene.drivers) == 1
               else f'{len(scene.drivers)} drivers ({names})')
    why = NotCompiled(f"{drivers}: mk.solve compiles one crank's paths alone (the node's tick "
                      'compiles any drivers)')
    assert compile_scene(scene, SINGLE) == why and compile_scene(scene, ARRAY) == why
    positions = [driver.start for driver in scene.drivers]
    many = [np.full(3, x) for x in positions]
    if len(positions) == 1:     # an actuator alone: the one-driver signature, bare values
        positions, many = positions[0], many[0]
    first = state_facts(mk.solve(scene, positions))
    for _ in range(COMPILE_AFTER + 1):
        mk.solve(scene, positions)
        mk.solve(scene, many)
    assert state_facts(mk.solve(scene, positions)) == first
    assert scene._solver.compiled_single in (None, why)
    assert scene._solver.compiled_array in (None, why)


def test_bounds_summed_over_a_limit_are_still_judged_one_by_one():
    """The quick judgement adds each kind's bounds; a sum over the limit is not a refusal.

    The tolerance is set so that the largest acceleration bound of one point is
    within its limit while the sum of the points' acceleration bounds is not:
    every angle must still be answered, as the general path answers it.
    """
    fast, slow = _pair(lambda: mk.load_scene('khurmi_four_bar_ad150'))
    angles = np.linspace(0.0, 2 * math.pi, 360, endpoint=False)
    loose = mk.solve(fast, angles, max_error=math.inf)
    point_bounds = [loose.error_bound.points[name].acceleration for name in ('B', 'C')]
    largest, summed = max(b.max() for b in point_bounds), (point_bounds[0] + point_bounds[1]).max()
    floor = fast.input.length * fast.input.speed ** 2      # the acceleration's floor (no accel)
    assert largest < summed
    tol = (largest + summed) / 2 / floor
    assert fast._solver.compiled_array
    state = mk.solve(fast, angles, max_error=tol)
    assert fast._solver.compiled_array and state.valid.all()
    assert state_facts(state) == state_facts(mk.solve(slow, angles, max_error=tol))


def test_a_constant_speed_keeps_its_sign_of_zero_in_an_array_state():
    """The read-only arrays made once per value tell -0.0 from 0.0 (equal as numbers)."""
    scene = mk.load_scene('khurmi_four_bar_ad150')
    angles = np.linspace(0.0, 1.0, 7)
    for speed in (0.0, -0.0, 0.0, -0.0):
        state = mk.solve(scene, angles, speed)
        assert not state.speed.flags.writeable
        assert (np.signbit(state.speed) == np.signbit(speed)).all()


def test_a_scene_of_more_steps_than_compile_steps_keeps_the_general_path():
    """A strip of COMPILE_STEPS + 1 dyads is never compiled by solve (it would take seconds).

    The refusal is the step count's alone: a strip of 3 dyads (3 steps) is
    refused alike on both paths under a limit of 2, and compiles under a limit
    of 3, none, or the default (compiling the 129-dyad strip itself took 30 s).
    """
    from helpers import equilateral_chain

    long = equilateral_chain(COMPILE_STEPS + 1)
    why = NotCompiled(f'more than {COMPILE_STEPS} steps ({COMPILE_STEPS + 1}): compiling would '
                      'cost more than the solves it speeds up')
    assert compile_scene(long, SINGLE) == why and compile_scene(long, ARRAY) == why
    short = equilateral_chain(3)
    why = NotCompiled('more than 2 steps (3): compiling would cost more than the solves it '
                      'speeds up')
    assert compile_scene(short, Single(max_steps=2)) == why
    assert compile_scene(short, Array(max_steps=2)) == why
    assert callable(compile_scene(short, Array(max_steps=3)))
    assert callable(compile_scene(short, Single(max_steps=None)))
    assert callable(compile_scene(short, SINGLE))
