# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The one compiler: every registered kind compiles to the bit of the general path, or says why.

Only the packaged scenes were compiled before (issue 30): a new kind could
ship with a kernel the compiler falls back on, or gets wrong, unseen. Here a
scene is generated for every kind the registry holds (``solver/registry.py``
``KINDS``), for both drivers (a crank, an actuator) and for the variants that
run kernels of their own (carried points, a Geneva wheel's RPR, an actuated
RRR), and each is compiled for every target of
:func:`mech_kinematics.solver.compiler.compile_scene`: ``mk.solve``'s
single-angle path, its array path (any rates, and the scene's own) and the
node's tick. Each compiled function must answer as the general path does at
many instants (values, bounds, warnings, refusals with the same message),
or the compiler must give the reason this test expects. A kind with no
generator here fails, named.
"""

import importlib
import math

from helpers import (array_outcome, collar_scene, crank_entry, equilateral_chain, fold_scene,
                     general_only, general_tick_outcome, hinge_scene, scene_mapping,
                     slider_scene, solve_outcome, tick_outcome, triad_scene)
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.ros.ticker import general_tick
from mech_kinematics.solver import compiler
from mech_kinematics.solver.compiler import (ARRAY, Array, compile_scene, NotCompiled, SINGLE,
                                             Tick)
from mech_kinematics.solver.registry import KINDS

#: The module (``mech_kinematics.solver.solve`` is also the name of its function).
solve_module = importlib.import_module('mech_kinematics.solver.solve')

#: The drivers (``inputs:`` entries: the registry's DRIVERS, by the key each has).
DRIVERS = ('crank', 'actuator', 'slider', 'motor')
#: Variants of registered kinds that run kernels of their own.
VARIANTS = ('carried point', 'Geneva RPR', 'actuated RRR')


#: A scene for each kind: a mapping of a scene file, that exercises the kind's kernel over
#: a range where it assembles and one where it refuses (most of them).
GENERATORS = {
    'crank': lambda: scene_mapping(
        'crank', {'A': [0, 0]}, input=crank_entry(),
        points={'P': {'link': 'crank', 'origin': 'A', 'xaxis': 'B', 'local': [20, 10]}}),
    # A triple rocker: the crank turns only part of the way.
    'RRR': lambda: scene_mapping(
        'RRR', {'A': [0, 0], 'D': [100, 0]}, input=crank_entry(angle=61),
        dyads=[{'type': 'RRR', 'point': 'C', 'links': [
            {'name': 'coupler', 'from': 'B', 'length': 66},
            {'name': 'rocker', 'from': 'D', 'length': 56}], 'branch': 1}]),
    # An offset slider-crank whose rod cannot reach the guide at the bottom of the turn.
    'RRP': lambda: scene_mapping(
        'RRP', {'O': [0, 0], 'E': [0, 40]}, input=crank_entry(150, 135, -300, 5.0, 'O'),
        dyads=[{'type': 'RRP', 'point': 'P',
                'link': {'name': 'rod', 'from': 'B', 'length': 160},
                'guide': {'through': 'E', 'angle': 0}, 'slider': 'piston', 'branch': -1}]),
    'RPR': lambda: scene_mapping(
        'RPR', {'O': [0, 0], 'A': [0, 400]}, input=crank_entry(150, 45, 120, 2.0),
        dyads=[{'type': 'RPR', 'link': 'lever', 'center': 'O', 'through': 'B',
                'slider': 'block'}]),
    'RPP': lambda: scene_mapping(
        'RPP', {'A': [0, 0]}, input=crank_entry(50, 30, 300, 0.0),
        dyads=[{'type': 'RPP', 'point': 'Y', 'through': 'B',
                'guide': {'through': 'A', 'angle': 0}, 'slot_angle': 90, 'slider': 'yoke',
                'slot_slider': 'pin_in_slot'}]),
    'triad': triad_scene,
    'motor': hinge_scene,
    'slider': slider_scene,
    'hinge': hinge_scene,
    'fold': fold_scene,
    'collar': collar_scene,
    'actuator': lambda: scene_mapping(
        'actuator', {'O': [0, 0], 'F': [400, -1100]},
        inputs=[{'actuator': 'cyl', 'length': 2600, 'speed': 100, 'stroke': [2000, 3300]}],
        dyads=[{'type': 'RRR', 'point': 'Q', 'links': [
            {'name': 'boom', 'from': 'O', 'length': 2600},
            {'name': 'barrel', 'from': 'F', 'actuator': 'cyl'}], 'branch': 1}]),
    'carried point': lambda: scene_mapping(
        'carried', {'A': [0, 0], 'D': [100, 0]}, input=crank_entry(angle=61),
        dyads=[{'type': 'RRR', 'point': 'C', 'links': [
            {'name': 'coupler', 'from': 'B', 'length': 66},
            {'name': 'rocker', 'from': 'D', 'length': 56}], 'branch': 1}],
        points={'E': {'link': 'coupler', 'from': 'B', 'toward': 'C', 'distance': 40},
                'F': {'link': 'coupler', 'origin': 'B', 'xaxis': 'C', 'local': [40, -30]}}),
    'Geneva RPR': lambda: scene_mapping(
        'geneva', {'D': [0, 0], 'S': [-70.71067811865476, 0]},
        input={'link': 'driver', 'center': 'D', 'point': 'P', 'length': 50, 'angle': 150,
               'speed_rpm': 95.4929658551372, 'accel': 0},
        dyads=[{'type': 'RPR', 'link': 'wheel', 'center': 'S', 'through': 'P',
                'slider': 'pin_slot', 'slots': 4}]),
    # A crank and a cylinder: the RRR's second link is the cylinder's.
    'actuated RRR': lambda: scene_mapping(
        'actuated', {'A': [0, 0], 'F': [300, -100]},
        inputs=[crank_entry(60, 40, 30, 0.0),
                {'actuator': 'cyl', 'length': 280, 'speed': 20, 'stroke': [200, 360]}],
        dyads=[{'type': 'RRR', 'point': 'C', 'links': [
            {'name': 'arm', 'from': 'B', 'length': 250},
            {'name': 'barrel', 'from': 'F', 'actuator': 'cyl'}], 'branch': 1}]),
}

#: The reasons the compiler is expected to give, per (kind, target); every other compiles.
NOT_COMPILED = {
    # The triad's kernel loops over its polynomial's roots and Newton's steps.
    ('triad', 'single'): 'step triad coupler: kernel uses `try` (not in the kernel subset)',
    ('triad', 'array'): 'step triad coupler: kernel uses `try` (not in the kernel subset)',
    ('triad', 'tick'): 'step triad coupler: kernel uses `try` (not in the kernel subset)',
    ('Geneva RPR', 'single'): "an intermittent lever's engagement is reported (wheel): "
                              "the general path's",
    ('Geneva RPR', 'array'): "an intermittent lever's engagement is reported (wheel): "
                             "the general path's",
    ('actuator', 'single'): "its driver cyl is not a crank: mk.solve compiles one crank's "
                            "paths alone (the node's tick compiles any drivers)",
    ('actuator', 'array'): "its driver cyl is not a crank: mk.solve compiles one crank's "
                           "paths alone (the node's tick compiles any drivers)",
    ('slider', 'single'): "its driver piston is not a crank: mk.solve compiles one crank's "
                          "paths alone (the node's tick compiles any drivers)",
    ('slider', 'array'): "its driver piston is not a crank: mk.solve compiles one crank's "
                         "paths alone (the node's tick compiles any drivers)",
    ('fold', 'single'): "its driver knee is not a crank: mk.solve compiles one crank's "
                        "paths alone (the node's tick compiles any drivers)",
    ('fold', 'array'): "its driver knee is not a crank: mk.solve compiles one crank's "
                       "paths alone (the node's tick compiles any drivers)",
    ('hinge', 'single'): "2 drivers (crank, elbow): mk.solve compiles one crank's paths "
                         "alone (the node's tick compiles any drivers)",
    ('hinge', 'array'): "2 drivers (crank, elbow): mk.solve compiles one crank's paths "
                        "alone (the node's tick compiles any drivers)",
    ('motor', 'single'): "2 drivers (crank, elbow): mk.solve compiles one crank's paths "
                         "alone (the node's tick compiles any drivers)",
    ('motor', 'array'): "2 drivers (crank, elbow): mk.solve compiles one crank's paths "
                        "alone (the node's tick compiles any drivers)",
    ('collar', 'single'): "2 drivers (crank, x): mk.solve compiles one crank's paths "
                          "alone (the node's tick compiles any drivers)",
    ('collar', 'array'): "2 drivers (crank, x): mk.solve compiles one crank's paths "
                         "alone (the node's tick compiles any drivers)",
    ('actuated RRR', 'single'): "2 drivers (crank, cyl): mk.solve compiles one crank's paths "
                                "alone (the node's tick compiles any drivers)",
    ('actuated RRR', 'array'): "2 drivers (crank, cyl): mk.solve compiles one crank's paths "
                               "alone (the node's tick compiles any drivers)",
}

#: Crank angles over two turns and a bit, both signs (rad); tolerances (1e-17: every
#: instant refused as untrusted, by the quick trust test and the full one).
ANGLES = np.linspace(-7.0, 7.0, 61)
TOLERANCES = (1e-6, 1e-12, 1e-17, math.inf)


def _kinds():
    """Return every kind to prove: the registry's, the drivers and the variants."""
    return [*sorted(KINDS), *DRIVERS, *VARIANTS]


def _scene_of(kind):
    """Return the generated scene of ``kind``, or fail naming the kind that has none."""
    generator = GENERATORS.get(kind)
    assert generator is not None, (
        f'no scene is generated for the kind {kind!r}: add one to GENERATORS in '
        'test/solver/test_compiler.py (and its expected reasons to NOT_COMPILED)')
    return mk.parse_scene(generator())


def _expect(kind, target, compiled):
    """Assert ``compiled`` is a function, or the reason NOT_COMPILED holds for it; say which."""
    reason = NOT_COMPILED.get((kind, target))
    if reason is None:
        assert callable(compiled), f'{kind}, {target}: {compiled}'
        return True
    assert compiled == NotCompiled(reason), (kind, target)
    return False


def test_every_kind_of_the_registry_has_a_generated_scene():
    """The registry's kinds are all generated here: a new kind fails until it is."""
    missing = [kind for kind in _kinds() if kind not in GENERATORS]
    assert not missing, f'kinds with no generated scene: {", ".join(missing)}'


@pytest.mark.parametrize('kind', _kinds())
def test_every_kind_compiles_mk_solves_paths_to_the_same_bits(kind):
    """The single-angle and array paths, compiled: mk.solve's states, bounds and refusals."""
    fast, slow = _scene_of(kind), general_only(_scene_of(kind))
    single = compile_scene(fast, SINGLE)
    array = compile_scene(fast, ARRAY)
    compiles = _expect(kind, 'single', single) & _expect(kind, 'array', array)
    if not compiles:
        return
    fast._solver.compiled_single, fast._solver.compiled_array = single, array
    # The usual call (the scene's own rates), compiled for them as mk.solve does.
    fast._solver.compiled_usual = solve_module._compile_usual(fast._solver)
    assert callable(fast._solver.compiled_usual), fast._solver.compiled_usual
    refused = 0
    for theta in ANGLES:
        for tol in TOLERANCES:
            for args, turns in (((float(theta),), 0), ((float(theta), -3.5, 7.0), 3)):
                expected = solve_outcome(slow, *args, turns=turns, max_error=tol)
                assert solve_outcome(fast, *args, turns=turns, max_error=tol) == expected, (
                    kind, theta, tol, args)
                refused += isinstance(expected[0], type)
    speeds = np.linspace(-20.0, 30.0, ANGLES.size)
    for kwargs in ({}, {'speed': speeds}, {'speed': 3.0, 'accel': speeds},
                   {'turns': np.arange(ANGLES.size) % 3}, {'max_error': 1e-12}):
        assert array_outcome(fast, ANGLES, **kwargs) == array_outcome(slow, ANGLES, **kwargs), (
            kind, kwargs)
    assert refused > 0, f'{kind}: no instant refused, at 1e-12 or where it cannot assemble'


@pytest.mark.parametrize('kind', _kinds())
def test_every_kind_compiles_the_nodes_tick_to_the_same_bits(kind):
    """The node's tick, compiled: mk.solve's values, measure, or error and its message.

    The compiled function must answer some instants itself: the fallback (the
    general solver, for the instants it hands over) is counted.
    """
    scene = _scene_of(kind)
    general = general_tick(scene, None, None, ())
    handed = []

    def fallback(*args):
        handed.append(args)
        return general(*args)

    tick = compile_scene(scene, Tick(scene.output_joints, scene.output_points, (), fallback))
    if not _expect(kind, 'tick', tick):
        return  # its reason, as NOT_COMPILED expects: the node serves the general tick
    drivers = scene.drivers
    refused = instants = 0
    if scene.input is not None and len(drivers) == 1:
        for theta in ANGLES:
            for omega, alpha, turns in ((scene.input.speed, scene.input.accel, 0),
                                        (-3.5, 7.0, 3), (1e13, 0.0, 0)):
                for tol in TOLERANCES:
                    expected = general_tick_outcome(scene, float(theta), omega, alpha, tol,
                                                    turns)
                    got = tick_outcome(tick, float(theta), omega, alpha, tol, turns)
                    assert repr(got) == repr(expected), (kind, theta, omega, tol)
                    refused += isinstance(expected[0], type)
                    instants += 1
    else:
        # One value per driver; one driver's bare (as mk.solve and the node give them).
        count = len(drivers)
        shape = (lambda values: values[0]) if count == 1 else list
        starts = [driver.start for driver in drivers]
        for step in np.linspace(-1.0, 1.0, 41):
            positions = shape([x + step * (0.6 if k == 0 and count > 1 else 0.12)
                               for k, x in enumerate(starts)])
            for speeds, accels in ((shape([0.0] * count), shape([0.0] * count)),
                                   (shape([0.3] * count), shape([-0.2] * count)),
                                   (shape([1e13] * count), shape([0.0] * count))):
                for tol in TOLERANCES:
                    expected = general_tick_outcome(scene, positions, speeds, accels, tol)
                    got = tick_outcome(tick, positions, speeds, accels, tol)
                    assert repr(got) == repr(expected), (kind, positions, speeds, tol)
                    refused += isinstance(expected[0], type)
                    instants += 1
    assert refused > 0, f'{kind}: no instant refused, at 1e-12 or where it cannot assemble'
    assert len(handed) < instants, f'{kind}: the fallback served every answer'


def test_the_reasons_a_scene_is_not_compiled_are_one_line_each():
    """Pins to bound, more steps than allowed: the compiler's reason, not a silent None."""
    data = GENERATORS['RRR']()
    data['pins'] = {'C': 5}
    scene = mk.parse_scene(data)
    why = NotCompiled("pins to bound: the rubbing velocities at C are the general path's")
    assert compile_scene(scene, SINGLE) == why
    assert compile_scene(scene, Tick((), (), (), lambda *args: ([], math.inf))) == why
    scene = mk.parse_scene(GENERATORS['RRR']())
    assert compile_scene(scene, Array(max_steps=0)) == NotCompiled(
        'more than 0 steps (1): compiling would cost more than the solves it speeds up')
    for compiled in (why, compile_scene(scene, Array(max_steps=0))):
        assert not compiled and '\n' not in compiled.reason and str(compiled) == compiled.reason


#: A chain whose tick holds more than compiler.APART_STATEMENTS statements (about 50 a dyad).
APART_DYADS = 12


def _compiled_apart(monkeypatch):
    """Record each (module, label, code or None) compiler.compiled_apart answers."""
    seen = []
    real = compiler.compiled_apart

    def recording(module, label):
        code = real(module, label)
        seen.append((module, label, code))
        return code

    monkeypatch.setattr(compiler, 'compiled_apart', recording)
    return seen


def _assert_tick_answers_as_the_general_path(scene, tick):
    """At angles over two turns and every tolerance: the general path's values or refusal."""
    for theta in ANGLES[::4]:
        for tol in TOLERANCES:
            expected = general_tick_outcome(scene, float(theta), scene.input.speed,
                                            scene.input.accel, tol)
            got = tick_outcome(tick, float(theta), scene.input.speed, scene.input.accel, tol)
            assert repr(got) == repr(expected), (theta, tol)


def test_a_large_module_is_compiled_apart_to_the_same_code(monkeypatch):
    """A 12-dyad chain's tick is compiled by a child process: compile()'s code object here.

    compile() holds the GIL for the whole call (0.26 s for a 100-dyad strip's tick, 0.36 to
    0.47 s beside two CPU hogs), and the node compiles a long chain's tick in a thread beside
    its tick thread; so a large module is compiled in a child process from its syntax tree.
    The code object that comes back is the one compiled here, equal field by field (its
    bytecode, constants, names, line table), and the tick answers as the general path does.
    """
    scene = equilateral_chain(APART_DYADS)
    seen = _compiled_apart(monkeypatch)
    tick = compile_scene(scene, Tick(scene.output_joints, scene.output_points, (),
                                     general_tick(scene, None, None, ())))
    [(module, label, code)] = seen
    assert sum(len(f.body) for f in module.body) > compiler.APART_STATEMENTS
    assert code is not None, 'the child process did not answer'
    assert code == compile(module, label, 'exec', compiler.COMPILE_FLAGS, True)
    _assert_tick_answers_as_the_general_path(scene, tick)


def test_a_small_module_is_compiled_here(monkeypatch):
    """Every packaged scene's tick is below the size compiled apart: no child process starts."""
    seen = _compiled_apart(monkeypatch)
    for name in mk.scene_names():
        scene = mk.load_scene(name)
        compile_scene(scene, Tick(scene.output_joints, scene.output_points, (),
                                  general_tick(scene, None, None, ())))
    assert seen == []


@pytest.mark.parametrize('executable', ['', '/nonexistent/python', '/bin/false'])
def test_where_no_child_can_compile_the_module_this_process_does(monkeypatch, executable):
    """No interpreter, one that cannot start, or one that fails: compiled here, same answers."""
    monkeypatch.setattr(compiler.sys, 'executable', executable)
    scene = equilateral_chain(APART_DYADS)
    seen = _compiled_apart(monkeypatch)
    tick = compile_scene(scene, Tick(scene.output_joints, scene.output_points, (),
                                     general_tick(scene, None, None, ())))
    assert [code for _, _, code in seen] == [None]
    assert callable(tick)
    _assert_tick_answers_as_the_general_path(scene, tick)
