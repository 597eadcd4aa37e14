# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""One instant's forces written out from the general path (``Dynamics._write``), issues 32, 45.

The reference is the general path (``Dynamics._forces``: each group's
statics built from the graph at the instant and solved by the dense
Gauss-Jordan loop of ``_bounded_solve``). The written-out function is that
path run once on recorded values (:mod:`mech_kinematics.solver.recording`);
it must give its values and bounds (the same operations in the same order:
equal as floats, ``0.0 == -0.0``), so within every reported bound, at
instants drawn over every packaged scene with masses; refuse what the
general path refuses, with its reason; and hand an instant of another pivot
sequence back.
"""

from __future__ import annotations

import dataclasses
import math

from helpers import flat_forces
from hypothesis import assume, given, HealthCheck, settings
from hypothesis import strategies as st
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.solver import forces as forces_module
from mech_kinematics.solver.compiler import NotCompiled
from mech_kinematics.solver.solve import _with_forces

PACKAGED = [name for name in mk.scene_names() if mk.load_scene(name).dynamics is not None]
MAX_ERROR = 1e-6

HYPOTHESIS = settings(max_examples=60, deadline=None,
                      suppress_health_check=[HealthCheck.too_slow])


def _angle(scene, fractions):
    """Return ``mk.solve``'s positions at these fractions of each driver's turn or stroke."""
    values = []
    for driver, f in zip(scene.drivers, fractions, strict=True):
        if driver.joint_type.angular:
            values.append(driver.start + 2 * math.pi * f)
        else:
            low, high = driver.stroke
            values.append(low + (high - low) * (0.02 + 0.96 * f))
    return values[0] if len(values) == 1 else values


def _state(scene, fractions, speed=None, accel=None):
    """Return the solved state at ``fractions`` (rates: the scene's, or these for every driver)."""
    angle = _angle(scene, fractions)
    if speed is None:
        return mk.solve(scene, angle)
    n = len(scene.drivers)
    speeds = speed if n == 1 else [speed] * n
    accels = accel if n == 1 else [accel] * n
    return mk.solve(scene, angle, speeds, accels)


def _compile(dynamics, state):
    """Return ``dynamics`` written out from ``state`` (as Dynamics.forces asks it)."""
    return dynamics._write(state, MAX_ERROR, vector=False)


def _reference(scene, state):
    """Return the general path's forces at ``state`` and the pivots each group took."""
    pivots = {}
    return scene.dynamics._forces(state, MAX_ERROR, pivots), pivots


def _assert_same(got, want):
    """Assert two single-instant Forces hold the same values and bounds (as floats)."""
    assert got.valid is True and want.valid is True
    assert flat_forces(got) == flat_forces(want)
    assert got.scale == want.scale and got.failures == {} and got.worst is None
    for name, reaction in want.reactions.items():
        assert dataclasses.asdict(got.reactions[name]) == dataclasses.asdict(reaction)


@pytest.mark.parametrize('name', PACKAGED)
@HYPOTHESIS
@given(data=st.data())
def test_the_written_out_forces_are_the_general_paths_at_any_instant(name, data):
    """At instants drawn over a packaged scene, the function gives the general path's answer."""
    scene = mk.load_scene(name)
    fractions = data.draw(st.lists(st.floats(0.0, 1.0, exclude_max=True),
                                   min_size=len(scene.drivers), max_size=len(scene.drivers)))
    moving = data.draw(st.booleans())
    speed = data.draw(st.floats(-30.0, 30.0)) if moving else None
    accel = data.draw(st.floats(-100.0, 100.0)) if moving else None
    try:
        state = _state(scene, fractions, speed, accel)
    except mk.AssemblyError:
        assume(False)
    want, pivots = _reference(scene, state)
    assert want.valid is True
    function = _compile(scene.dynamics, state)
    got = function(state, MAX_ERROR)
    _assert_same(got, want)
    values = flat_forces(want)
    for key, value in flat_forces(got).items():   # within the bound, a fortiori
        if key.startswith('value') and isinstance(value, float):
            assert abs(value - values[key]) == 0.0


@pytest.mark.parametrize('name', PACKAGED)
def test_mk_solve_answers_from_the_written_out_function_over_a_turn(name):
    """Past COMPILE_AFTER instants mk.solve's forces come written out, the general path's."""
    scene = mk.load_scene(name)
    dynamics = scene.dynamics
    sweep = np.linspace(0.0, 1.0, 97, endpoint=False)
    served = 0
    for f in sweep:
        state = _state(scene, [f] * len(scene.drivers))
        want, _ = _reference(scene, state)
        fast = list(dynamics._fast)
        answered = next((a for a in (fn(state, MAX_ERROR) for fn in fast) if a), None)
        if answered is not None:
            served += 1
            _assert_same(answered, want)
        _assert_same(state.forces, want)
    assert dynamics.compiled_single is None, dynamics.compiled_single
    assert 1 <= len(dynamics._fast) <= forces_module.MAX_SEQUENCES
    n = len(dynamics._fast)     # the public record says so
    assert mk.paths(scene)['forces single'] == \
        f'written out ({n} pivot sequence{"s" if n > 1 else ""})'
    assert served >= len(sweep) - 2 * forces_module.COMPILE_AFTER


def test_an_instant_of_another_pivot_sequence_is_handed_back():
    """A function written for one pivot sequence returns False where partial pivoting differs."""
    scene = mk.load_scene('excavator_loaded')
    sequences = {}
    for f in np.linspace(0.0, 1.0, 60, endpoint=False):
        state = _state(scene, [f, 1.0 - f])
        want, pivots = _reference(scene, state)
        sequences.setdefault(tuple(map(tuple, pivots.values())), (pivots, state, want))
    assert len(sequences) >= 2
    (p1, s1, w1), (p2, s2, w2) = list(sequences.values())[:2]
    first, second = _compile(scene.dynamics, s1), _compile(scene.dynamics, s2)
    assert first(s2, MAX_ERROR) is False and second(s1, MAX_ERROR) is False
    _assert_same(first(s1, MAX_ERROR), w1)
    _assert_same(second(s2, MAX_ERROR), w2)


def _warm(scene):
    """Solve ``scene`` at enough instants that its forces run written out; return the dynamics."""
    for f in np.linspace(0.0, 1.0, 2 * forces_module.COMPILE_AFTER + 2, endpoint=False):
        _state(scene, [f] * len(scene.drivers))
    assert scene.dynamics._fast
    return scene.dynamics


def test_the_record_of_paths_says_what_serves_before_and_after_writing_out():
    """mk.paths: the general path until COMPILE_AFTER instants, then the written functions."""
    scene = mk.load_scene('engine')
    assert mk.paths(scene) == {
        'single': 'general (compiled after 256 solves)',
        'array': 'general (compiled after 16 solves)',
        'forces single': f'general (written out after {forces_module.COMPILE_AFTER} instants)',
        'forces array': (f'general (written out after {forces_module.ARRAY_COMPILE_AFTER} '
                         f'arrays)')}
    _warm(scene)
    assert mk.paths(scene)['forces single'].startswith('written out (')
    two = mk.load_scene('five_bar_payload')
    assert mk.paths(two)['single'].startswith('general: 2 drivers (left_crank, right_crank)')


def test_a_singular_group_is_still_refused_with_its_reason():
    """Where a group's statics are singular the function defers; the general path names it."""
    scene = mk.load_scene('engine')
    dynamics = _warm(scene)
    state = _state(scene, [0.3])
    points = dict(state.complex_points)
    points['C'] = points['P']   # the rod of no length: its moment row is all zero
    singular = dataclasses.replace(state, complex_points=points)
    assert all(fn(singular, MAX_ERROR) is False for fn in dynamics._fast)
    forces = dynamics.forces(singular, MAX_ERROR)
    assert forces.valid is False and forces.worst is None
    assert next(iter(forces.failures)) == 'P (statics singular)'
    with pytest.raises(mk.UntrustedError, match=r'cannot be bounded here \(P \(statics '
                       r'singular\)\)'):
        _with_forces(scene, singular, MAX_ERROR)


def test_a_bound_beyond_the_tolerance_is_refused_as_the_general_path_refuses():
    """With a tolerance no bound meets, the forces are refused in the general path's one line."""
    fresh, warm = mk.load_scene('shaper'), mk.load_scene('shaper')
    _warm(warm)
    state = _state(warm, [0.4])
    assert all(fn(state, 1e-300) is False for fn in warm.dynamics._fast)
    with pytest.raises(mk.UntrustedError) as general:
        _with_forces(fresh, state, 1e-300)
    assert not fresh.dynamics._fast
    with pytest.raises(mk.UntrustedError) as written:
        _with_forces(warm, state, 1e-300)
    assert str(written.value) == str(general.value) and '\n' not in str(written.value)
    assert written.value.dyad == 'forces' and 'exceeds max_error' in str(written.value)


def test_an_intermittent_drive_is_not_written_out_and_says_why():
    """A Geneva wheel with masses keeps the general path; compiled_single gives the reason."""
    data = {'name': 'geneva', 'units': {'length': 'mm', 'angle': 'deg'},
            'ground': {'D': [0, 0], 'S': [-70.71067811865476, 0]},
            'input': {'link': 'driver', 'center': 'D', 'point': 'P', 'length': 50,
                      'angle': 150, 'speed_rpm': 95.4929658551372, 'accel': 0},
            'dyads': [{'type': 'RPR', 'link': 'wheel', 'center': 'S', 'through': 'P',
                       'slider': 'pin_slot', 'slots': 4}],
            'masses': {'driver': {'mass': 1.0, 'com': [20, 0]},
                       'wheel': {'mass': 2.0, 'inertia': 0.01}},
            'gravity': [0, -9.81]}
    scene = mk.parse_scene(data)
    function = _compile(scene.dynamics, mk.solve(scene, math.radians(160.0)))
    assert isinstance(function, NotCompiled) and 'intermittent drive' in str(function)
    for f in np.linspace(0.0, 0.2, 2 * forces_module.COMPILE_AFTER + 2):
        mk.solve(scene, math.radians(160.0) + f)
    assert isinstance(scene.dynamics.compiled_single, NotCompiled)
    assert not scene.dynamics._fast
    assert mk.paths(scene)['forces single'] == f'general: {function.reason}'


# --- arrays ---------------------------------------------------------------------------

def _sweep(scene, n, moving=False):
    """Return an array state of ``scene``: ``n`` configurations over each driver's range."""
    fractions = np.linspace(0.0, 1.0, n, endpoint=False)
    angle = _angle(scene, [fractions] * len(scene.drivers))
    if not moving:
        return mk.solve(scene, angle)
    k = len(scene.drivers)
    speed, accel = 2.0 + np.sin(7 * fractions), -3.0 * np.cos(5 * fractions)
    return mk.solve(scene, angle, speed if k == 1 else [speed] * k,
                    accel if k == 1 else [accel] * k)


def _warm_arrays(scene):
    """Solve ``scene`` at arrays until its arrays' forces run written out; return its dynamics."""
    for _ in range(forces_module.ARRAY_COMPILE_AFTER + 1):
        state = _sweep(scene, 40)
    scene.dynamics.forces(state, MAX_ERROR)
    assert scene.dynamics._fast_array
    return scene.dynamics


def _assert_same_arrays(got, want):
    """Assert two array Forces agree: valid, failures, and every value and bound where valid."""
    valid = np.asarray(want.valid, dtype=bool)
    np.testing.assert_array_equal(got.valid, valid)
    assert got.failures.keys() == want.failures.keys()
    for reason, mask in want.failures.items():
        np.testing.assert_array_equal(got.failures[reason], mask)

    def same(a, b):
        a, b = np.broadcast_to(a, valid.shape), np.broadcast_to(b, valid.shape)
        np.testing.assert_array_equal(a[valid], b[valid])

    for name, value in want.efforts.items():
        same(got.efforts[name], value)
        same(got.effort_bounds[name], want.effort_bounds[name])
    for name, reaction in want.reactions.items():
        for field in dataclasses.fields(reaction):
            mine, theirs = getattr(got.reactions[name], field.name), getattr(reaction, field.name)
            if isinstance(theirs, str) or theirs is None:
                assert mine == theirs
            else:
                same(mine, theirs)
    same(got.shaking_force, want.shaking_force)
    same(got.shaking_moment, want.shaking_moment)
    same(got.shaking_bounds[0], want.shaking_bounds[0])
    same(got.shaking_bounds[1], want.shaking_bounds[1])
    same(got.scale, want.scale)


@pytest.mark.parametrize('name', PACKAGED)
@pytest.mark.parametrize('moving', [False, True])
def test_arrays_written_out_are_the_general_paths(name, moving):
    """An array's forces written out (one function a pivot sequence) are the general path's."""
    scene = mk.load_scene(name)
    dynamics = _warm_arrays(scene)
    state = _sweep(scene, 720, moving)
    _assert_same_arrays(state.forces, dynamics._forces(state, MAX_ERROR))
    assert 1 <= len(dynamics._fast_array) <= forces_module.ARRAY_SEQUENCES
    if name == 'excavator_loaded':     # 6 pivot sequences: its arrays take the general path
        assert 'more than 2 pivot sequences' in str(dynamics.compiled_array)
    else:
        assert dynamics.compiled_array is None


def test_an_arrays_refused_instants_are_refused_with_the_general_paths_reasons():
    """Instants beyond the tolerance and singular ones keep the general path's failures."""
    scene = mk.load_scene('engine')
    dynamics = _warm_arrays(scene)
    state = _sweep(scene, 90)
    points = dict(state.complex_points)
    singular = np.arange(90) % 7 == 3
    points['C'] = (np.where(singular, points['P'][0], points['C'][0]), *points['C'][1:])
    tampered = dataclasses.replace(state, complex_points=points)
    want = dynamics._forces(tampered, MAX_ERROR)
    assert 'P (statics singular)' in want.failures
    _assert_same_arrays(dynamics.forces(tampered, MAX_ERROR), want)
    strict = 6.5e-15   # between the bounds of the instants (46 of 90 beyond it)
    want = dynamics._forces(state, strict)
    assert 0 < np.count_nonzero(want.failures['forces (untrusted)']) < 90
    _assert_same_arrays(dynamics.forces(state, strict), want)


def test_refused_instants_beyond_the_last_sequence_leave_the_arrays_written_out():
    """A scene at its last array sequence sends refused instants to the general path, and stays."""
    scene = mk.load_scene('five_bar_payload')      # two pivot sequences over a turn
    dynamics = _warm_arrays(scene)
    _sweep(scene, 360)
    assert len(dynamics._fast_array) == forces_module.ARRAY_SEQUENCES
    state = _sweep(scene, 90)
    strict = 3e-13     # about a third of the instants beyond it
    want = dynamics._forces(state, strict)
    assert 0 < np.count_nonzero(want.failures['forces (untrusted)']) < 90
    _assert_same_arrays(dynamics.forces(state, strict), want)
    assert dynamics.compiled_array is None


def test_a_long_array_runs_in_blocks_with_the_general_paths_answer(monkeypatch):
    """An array longer than ARRAY_CHUNK runs block by block; put together, the general path's."""
    scene = mk.load_scene('engine')
    dynamics = _warm_arrays(scene)
    monkeypatch.setattr(forces_module, 'ARRAY_CHUNK', 17)
    state = _sweep(scene, 90)
    points = dict(state.complex_points)
    singular = np.arange(90) % 11 == 5
    points['C'] = (np.where(singular, points['P'][0], points['C'][0]), *points['C'][1:])
    tampered = dataclasses.replace(state, complex_points=points)
    for strict in (MAX_ERROR, 6.5e-15):
        want = dynamics._forces(tampered, strict)
        assert want.failures and not want.valid.all()
        _assert_same_arrays(dynamics.forces(tampered, strict), want)
