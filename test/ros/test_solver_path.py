# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Which function solves the node's ticks, and why (ros/solver_path.py), without a node.

Issue 30: where the tick does not compile, the node says why, in its log
and on ``diagnostics`` (``solver_path``); nothing catches the compiler's
exceptions. The node's side is tested from a subscriber in
``test_kinematics_node_launch.py``.
"""

import math

from helpers import equilateral_chain
import pytest

import mech_kinematics as mk
from mech_kinematics.ros import solver_path
from mech_kinematics.ros.solver_path import BACKGROUND_STEPS, COMPILED, FORCES, SolverPath
from mech_kinematics.ros.ticker import general_tick

#: The reason a scene with pins to bound is not compiled (the compiler's words).
PINS = "pins to bound: the rubbing velocities at C are the general path's"
#: Instants compared: (angle, speed, accel, turns).
INSTANTS = [(0.1 * k, -4.0 * math.pi, 1.5, k % 3) for k in range(-31, 32, 3)]


def _four_bar(**extra):
    """Return the Khurmi four-bar (mm, deg) with ``extra`` scene keys."""
    return mk.parse_scene({
        'name': 'four_bar', 'units': {'length': 'mm', 'angle': 'deg'},
        'ground': {'A': [0, 0], 'D': [150, 0]},
        'input': {'link': 'crank', 'center': 'A', 'point': 'B', 'length': 40, 'angle': 60,
                  'speed_rpm': -120},
        'dyads': [{'type': 'RRR', 'point': 'C', 'branch': 1, 'links': [
            {'name': 'coupler', 'from': 'B', 'length': 150},
            {'name': 'rocker', 'from': 'D', 'length': 80}]}], **extra})


def _answers(solve, scene):
    """Return ``solve``'s answers at INSTANTS (values and measure, or the error's text)."""
    answers = []
    for angle, speed, accel, turns in INSTANTS:
        try:
            answers.append(repr(solve(angle, speed, accel, 1e-6, turns)))
        except mk.AssemblyError as error:
            answers.append(str(error))
    return answers


def _setup(scene):
    """Return (SolverPath set up for ``scene``, the lines it logged, the thread or None)."""
    path, lines = SolverPath(1e-6), []
    thread = path.setup(scene, scene, (), lines.append)
    return path, lines, thread


def test_a_packaged_scene_is_compiled_and_says_so():
    """The packaged four-bar's tick compiles: path 'compiled', no fallback line."""
    scene = mk.load_scene('khurmi_four_bar_ad150')
    path, lines, thread = _setup(scene)
    assert (path.path, lines, thread) == (COMPILED, [], None)
    assert path.solve is not None and path.solve.__name__ != 'general'
    assert path.assembly == 'assembles at every crank angle'
    assert path.jumps_at is None
    assert _answers(path.solve, scene) == _answers(general_tick(scene, None, None, ()), scene)


def test_a_scene_that_does_not_compile_says_why_and_is_solved_alike():
    """Pins to bound: the general solver serves, the reason logged and kept for diagnostics."""
    scene = _four_bar(pins={'C': 5})
    path, lines, thread = _setup(scene)
    assert thread is None
    assert path.path == f'general: {PINS}'
    assert lines == [f'solved by the general solver: {PINS}']
    assert _answers(path.solve, scene) == _answers(general_tick(scene, None, None, ()), scene)


def test_a_rescaled_scene_says_why():
    """Lengths of 1e-300 m are solved scaled by a power of two: the general path, and why."""
    data = {'name': 'tiny', 'units': {'length': 'm', 'angle': 'rad'},
            'ground': {'A': [0, 0], 'D': [1.5e-298, 0]},
            'input': {'link': 'crank', 'center': 'A', 'point': 'B', 'length': 4e-299,
                      'angle': 1.0},
            'dyads': [{'type': 'RRR', 'point': 'C', 'branch': 1, 'links': [
                {'name': 'coupler', 'from': 'B', 'length': 1.5e-298},
                {'name': 'rocker', 'from': 'D', 'length': 8e-299}]}]}
    path, lines, _ = _setup(mk.parse_scene(data))
    assert path.path.startswith('general: scene rescaled: its size ')
    assert lines == [f'solved by the general solver: {path.path[len("general: "):]}']


def test_a_long_scene_is_served_while_its_tick_compiles():
    """More than 16 steps: the general solver at once, the compiled tick once the thread ends."""
    scene = equilateral_chain(BACKGROUND_STEPS + 1)
    path, lines, thread = _setup(scene)
    assert path.path == 'general: its tick compiles in the background'
    assert path.solve.__name__ == 'general' and path.assembly == ''
    assert lines == ['the scene has 17 dyads and points: the general solver serves while its '
                     'tick compiles in the background']
    general = _answers(path.solve, scene)
    thread.start()
    thread.join(timeout=120)
    assert path.path == COMPILED and path.solve.__name__ != 'general'
    assert lines[1].startswith('the compiled tick serves from now (compiled in ')
    assert path.assembly    # swept in the thread
    assert _answers(path.solve, scene) == general


def test_a_long_scene_that_does_not_compile_says_why_from_its_thread():
    """The thread's answer is the compiler's reason: on the log and in the path."""
    last = f'P{BACKGROUND_STEPS}'
    data = {'name': 'pinned_chain', 'units': {'length': 'm', 'angle': 'rad'},
            'ground': {'A': [0, 0]},
            'input': {'link': 'crank', 'center': 'A', 'point': 'B', 'length': 1, 'angle': 0.3},
            'dyads': [], 'pins': {last: 0.01}}
    previous, current = 'A', 'B'
    for k in range(BACKGROUND_STEPS + 1):     # equilateral_chain's strip, as a scene file
        data['dyads'].append({'type': 'RRR', 'point': f'P{k}', 'branch': 1 - 2 * (k % 2),
                              'links': [{'name': f'a{k}', 'from': previous, 'length': 1},
                                        {'name': f'b{k}', 'from': current, 'length': 1}]})
        previous, current = current, f'P{k}'
    path, lines, thread = _setup(mk.parse_scene(data))
    thread.start()
    thread.join(timeout=120)
    reason = f"pins to bound: the rubbing velocities at {last} are the general path's"
    assert path.path == f'general: {reason}'
    assert lines[1:] == [f'solved by the general solver: {reason}']


def test_a_dropped_scene_does_not_take_the_compiled_tick():
    """A compile that ends after clean-up (drop) installs nothing."""
    path, lines, thread = _setup(equilateral_chain(BACKGROUND_STEPS + 1))
    path.drop()
    thread.start()
    thread.join(timeout=120)
    assert path.solve.__name__ == 'general' and len(lines) == 1


def test_a_compiler_bug_is_not_a_silent_fallback(monkeypatch):
    """An exception of the compiler (not a reason) propagates: no broad except around it."""
    def broken(*args):
        raise RuntimeError('a bug in the specializer')

    monkeypatch.setattr(solver_path, 'compiled_tick', broken)
    with pytest.raises(RuntimeError, match='a bug in the specializer'):
        _setup(mk.load_scene('khurmi_four_bar_ad150'))


def test_a_scene_with_forces_solves_its_motion_compiled_and_says_so():
    """The forces tick's motion is mk.solve's compiled path where it compiles: its bits."""
    from mech_kinematics.ros.ticker import values_from_state
    from mech_kinematics.ros.wrenches import ForcesTick

    scene = mk.load_scene('engine')
    forces = ForcesTick(scene, scene.output_joints, scene.output_points, (), static=False)
    path, lines = SolverPath(1e-6), []
    assert path.setup(scene, scene, (), lines.append, forces) is None
    assert path.path == f'{COMPILED}: {FORCES}' and lines == [f'the forces tick serves: {FORCES}']
    assert mk.paths(forces.kinematics)['single'] == COMPILED
    fresh = mk.load_scene('engine')     # the general path (a fresh scene is not compiled)
    speed = scene.drivers[0].speed
    for theta in (0.0, 0.7, 2.5, 4.0):
        values, _ = forces(theta, speed, 3.0, 1e-6)
        want = mk.solve(fresh, theta, speed, 3.0)
        assert values[:forces.forces_first] == values_from_state(
            want, scene.output_joints, scene.output_points)
        assert values[forces.forces_first] == want.forces.efforts['crank']
    assert mk.paths(fresh)['single'].startswith('general (')
    two = mk.load_scene('five_bar_payload')
    forces = ForcesTick(two, two.output_joints, two.output_points, (), static=False)
    path, lines = SolverPath(1e-6), []
    path.setup(two, two, (), lines.append, forces)
    reason = forces.motion.reason
    assert reason.startswith('2 drivers (left_crank, right_crank)')
    assert path.path == f'general: {reason}'
    assert lines == [f'solved by the general solver (the motion the forces are solved at): '
                     f'{reason}']
