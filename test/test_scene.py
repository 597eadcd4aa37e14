# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Scene loading (docs/scene_format.md): bad scenes, packaged scenes, units, outputs, the CLI.

Every bad scene is written to a file and must be rejected with one
:class:`mech_kinematics.SceneError` whose message reads ``FILE: KEY: reason``
(docs/scene_format.md, "Errors you will meet").
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import math
import os
from pathlib import Path
import re
import subprocess
import sys

from helpers import BASE_SCENE as BASE, start_positions
import numpy as np
import pytest
import yaml

import mech_kinematics as mk
from mech_kinematics.__main__ import build_parser, main
from mech_kinematics.tools.solve import turns_from_degrees

ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT / 'config' / 'scenes'
#: Seconds a `python -m mech_kinematics` subprocess may take.
TIMEOUT = 60
#: The same scene in mm and in m: inputs differ by the rounding of x / 1000.
RTOL_UNITS = 1e-12


def base():
    return yaml.safe_load(BASE)


def write(tmp_path, data, name='scene.yaml'):
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else yaml.safe_dump(data, sort_keys=False))
    return path


def test_base_scene_is_valid(tmp_path):
    """The base scene that the bad scenes below break loads and solves."""
    scene = mk.load_scene(write(tmp_path, BASE))
    state = mk.solve(scene, scene.input.angle)
    assert set(state.points) == {'A', 'D', 'G', 'B', 'C', 'P', 'E', 'F'}
    assert list(state.joints) == ['crank', 'coupler', 'rocker', 'rod', 'piston']


# --- bad scenes --------------------------------------------------------------------


def edit(change):
    """Return the base scene's mapping after ``change(data)``."""
    data = base()
    change(data)
    return data


def setitem(path, value):
    """Return a change that sets ``data[path...] = value``."""
    def change(data):
        *parents, last = path
        for key in parents:
            data = data[key]
        data[last] = value
    return change


def delitem(path):
    def change(data):
        *parents, last = path
        for key in parents:
            data = data[key]
        del data[last]
    return change


def add_cycle(data):
    data['dyads'] += [
        {'type': 'RRR', 'point': 'K',
         'links': [{'name': 'k1', 'from': 'M', 'length': 100},
                   {'name': 'k2', 'from': 'D', 'length': 100}]},
        {'type': 'RRR', 'point': 'M',
         'links': [{'name': 'm1', 'from': 'K', 'length': 100},
                   {'name': 'm2', 'from': 'A', 'length': 100}]}]


LINK1 = ('dyads', 0, 'links', 1)
#: (id, file content or mapping, the key the message must name (or a tuple of
#: acceptable spellings), the reason as a regex). Unknown keys are reported at
#: their parent mapping, which is named ``scene`` at the top level.
BAD_SCENES = [
    ('invalid_yaml', BASE.replace('D: [150, 0]', 'D: [150, 0'), 'line 6', r'invalid YAML'),
    ('tab_indented_yaml', BASE.replace('  A: [0, 0]', '\tA: [0, 0]'), 'line 4',
     r'invalid YAML'),
    ('top_level_list', '- name: x\n', 'top level', r'expected a mapping.*list'),
    ('missing_name', edit(delitem(['name'])), 'name', r'missing required key'),
    ('missing_ground', edit(delitem(['ground'])), 'ground', r'missing required key'),
    ('missing_input', edit(delitem(['input'])), 'input', r'missing required key'),
    # `dyads` is optional in docs/scene_format.md; without it the points lose their links.
    ('missing_dyads', edit(delitem(['dyads'])), 'points.E.link', r'unknown "coupler"'),
    ('missing_link_length', edit(delitem([*LINK1, 'length'])), 'dyads[0].links[1].length',
     r'missing required key'),
    ('missing_crank_length', edit(delitem(['input', 'length'])), 'input.length',
     r'missing required key'),
    ('unknown_point', edit(setitem([*LINK1, 'from'], 'Z')), 'dyads[0].links[1].from',
     r'unknown "Z"'),
    ('duplicate_point_and_link', edit(setitem([*LINK1, 'name'], 'C')),
     'dyads[0].links[1].name', r'"C" twice'),
    ('duplicate_points_carried_and_ground', edit(setitem(['points', 'D'], {
        'link': 'coupler', 'from': 'B', 'toward': 'C', 'distance': 10})), 'points.D',
     r'"D" twice'),
    ('duplicate_points_crank_and_ground', edit(setitem(['input', 'point'], 'D')),
     'input.point', r'"D" twice'),
    ('duplicate_links', edit(setitem(['dyads', 1, 'link', 'name'], 'coupler')),
     'dyads[1].link.name', r'"coupler" twice'),
    ('zero_length', edit(setitem(['dyads', 0, 'links', 0, 'length'], 0)),
     'dyads[0].links[0].length', r'positive length, got 0'),
    ('negative_length', edit(setitem(['input', 'length'], -40)), 'input.length',
     r'positive length, got -40'),
    ('nan_length', BASE.replace('rocker, from: D, length: 80', 'rocker, from: D, length: .nan'),
     'dyads[0].links[1].length', r'finite.*nan'),
    ('inf_length', BASE.replace('rod, from: E, length: 150', 'rod, from: E, length: .inf'),
     'dyads[1].link.length', r'finite.*inf'),
    ('string_length', edit(setitem([*LINK1, 'length'], '80 mm')), 'dyads[0].links[1].length',
     r"expected a number, got str '80 mm'"),
    ('boolean_length', edit(setitem([*LINK1, 'length'], True)), 'dyads[0].links[1].length',
     r'expected a number'),
    ('negative_distance_is_fine_but_string_is_not',
     edit(setitem(['points', 'E', 'distance'], 'far')), 'points.E.distance',
     r'expected a number'),
    ('branch_zero', edit(setitem(['dyads', 0, 'branch'], 0)), 'dyads[0].branch',
     r'expected \+1 or -1, got 0'),
    ('branch_two', edit(setitem(['dyads', 1, 'branch'], 2)), 'dyads[1].branch',
     r'expected \+1 or -1, got 2'),
    ('unknown_dyad_type', edit(setitem(['dyads', 1, 'type'], 'PPP')), 'dyads[1].type',
     r"expected RRR, RRP, RPR, RPP, triad, collar, hinge or fold, got 'PPP'"),
    ('unknown_top_level_key', edit(setitem(['colour'], 'red')), 'scene',
     r"unknown key.*'colour'"),
    ('unknown_link_key', edit(setitem([*LINK1, 'lenght'], 80)), 'dyads[0].links[1]',
     r"unknown key.*'lenght'"),
    ('unknown_input_key', edit(setitem(['input', 'speed_rps'], 3)), 'input',
     r"unknown key.*'speed_rps'"),
    ('crank_speed_in_two_units', edit(setitem(['input', 'speed'], 3)), 'input.speed',
     r'expected the crank speed once, as speed \(rad/s\) or speed_rpm \(rpm\), got both'),
    ('guide_through_moving_point', edit(setitem(['dyads', 1, 'guide', 'through'], 'B')),
     'dyads[1].guide.through', r'ground point.*moving point "B"'),
    ('crank_center_moving', edit(setitem(['input', 'center'], 'C')), 'input.center',
     r'ground point'),
    ('carried_on_unknown_link', edit(setitem(['points', 'F', 'link'], 'bogus')),
     'points.F.link', r'unknown "bogus"'),
    ('carried_on_a_point', edit(setitem(['points', 'F', 'link'], 'D')), 'points.F.link',
     r'Expected .*to be a link, got point "D"'),
    ('carried_from_point_not_on_link', edit(setitem(['points', 'E', 'from'], 'D')),
     'points.E.from', r'fixed on link "coupler"'),
    ('carried_toward_point_not_on_link', edit(setitem(['points', 'F', 'xaxis'], 'D')),
     'points.F.xaxis', r'point on link "coupler".*"D"'),
    ('carried_mixed_forms', edit(setitem(['points', 'E', 'local'], [1, 2])), 'points.E',
     r'unknown key'),
    ('dependency_cycle', edit(add_cycle), 'dyads[2]', r'cycle'),
    ('outputs_unknown_joint', edit(setitem(['outputs'], {'joints': ['bogus']})),
     'outputs.joints', r'unknown "bogus"'),
    ('outputs_point_is_a_link', edit(setitem(['outputs'], {'points': ['rocker']})),
     'outputs.points', r'link "rocker"'),
    # See issue 11: the links whose lengths prevent assembly are named, in the scene's units.
    ('cannot_assemble_at_initial_angle', edit(setitem([*LINK1, 'length'], 10)), 'dyads[0]',
     r'assemble at the initial crank angle 60 deg, got links coupler \(150 mm\) and rocker '
     r'\(10 mm\) cannot meet: B and D are 134\.536 mm apart, less than the difference of '
     r'their lengths \(140 mm\)$'),
    ('cannot_reach_at_initial_angle', edit(setitem(['dyads', 0, 'links', 0, 'length'], 50)),
     'dyads[0]', r'assemble at the initial crank angle 60 deg, got links coupler \(50 mm\) and '
     r'rocker \(80 mm\) cannot reach from B to D \(134\.536 mm apart, more than 130 mm\)$'),
    ('guide_out_of_reach_at_initial_angle', edit(setitem(['dyads', 1, 'link', 'length'], 20)),
     'dyads[1]', r'assemble at the initial crank angle 60 deg, got link rod \(20 mm\) cannot '
     r'reach the guide through G at 0 deg from E \([0-9.]+ mm from the guide\)$'),
    # See issue 11: units are explicit; a scene without them is refused, never read as metres.
    ('missing_units', edit(delitem(['units'])), 'units',
     r'missing required key: write units: \{length: mm, angle: deg\} or '
     r'units: \{length: m, angle: rad\}'),
    ('missing_length_unit', edit(delitem(['units', 'length'])), 'units.length',
     r'missing required key \(m, mm\).*units: \{length: m, angle: rad\}'),
    ('missing_angle_unit', edit(delitem(['units', 'angle'])), 'units.angle',
     r'missing required key \(deg, rad\).*units: \{length: mm, angle: deg\}'),
    ('empty_units', edit(setitem(['units'], None)), 'units',
     r'expected a mapping such as units: \{length: mm.*got nothing'),
    ('units_as_text', edit(setitem(['units'], 'mm')), 'units', r'expected a mapping.*got str'),
    ('length_unit_not_text', edit(setitem(['units', 'length'], [1])), 'units.length',
     r'expected one of m, mm, got \[1\]'),
    ('wrong_length_unit', edit(setitem(['units', 'length'], 'inch')), 'units.length',
     r"expected one of m, mm, got 'inch'"),
    ('wrong_angle_unit', edit(setitem(['units', 'angle'], 'grad')), 'units.angle',
     r"expected one of deg, rad, got 'grad'"),
    ('ground_point_one_coordinate', edit(setitem(['ground', 'D'], [150])), 'ground.D',
     r'expected \[x, y\]'),
    ('ground_point_nan', BASE.replace('D: [150, 0]', 'D: [150, .nan]'),
     ('ground.D', 'ground.D[1]'), r'finite'),
    ('rrr_with_one_link', edit(setitem(['dyads', 0, 'links'], [{
        'name': 'coupler', 'from': 'B', 'length': 150}])), 'dyads[0].links',
     r'list of 2 links'),
    ('speed_not_a_number', edit(setitem(['input', 'speed_rpm'], 'fast')), 'input.speed_rpm',
     r'expected a number'),
    ('scene_name_not_an_identifier', edit(setitem(['name'], 'base scene')), 'name',
     r'identifier'),
    ('link_name_not_an_identifier', edit(setitem([*LINK1, 'name'], 'the rocker')),
     'dyads[0].links[1].name', r'identifier'),
    ('ground_name_not_an_identifier', edit(setitem(['ground', '2D'], [1, 1])), 'ground.2D',
     r'identifier'),
    # urdf_drivers: a robot's loops, the URDF joint each driver follows (the view reads it).
    ('urdf_drivers_not_a_driver', edit(setitem(['urdf_drivers'], {'wheel': {
        'joint': 'j', 'joint_reference': 0.0, 'reference': 0.0, 'factor': 1.0}})),
     'urdf_drivers.wheel', r'Expected a driver of the scene \(crank\)'),
    ('urdf_drivers_unknown_key', edit(setitem(['urdf_drivers'], {'crank': {
        'joint': 'j', 'joint_reference': 0.0, 'reference': 0.0, 'factor': 1.0, 'sign': 1}})),
     'urdf_drivers.crank', r"unknown key\(s\) \['sign'\]"),
    ('urdf_drivers_factor_zero', edit(setitem(['urdf_drivers'], {'crank': {
        'joint': 'j', 'joint_reference': 0.0, 'reference': 0.0, 'factor': 0}})),
     'urdf_drivers.crank.factor', r'a factor other than 0'),
    ('urdf_drivers_not_finite', edit(setitem(['urdf_drivers'], {'crank': {
        'joint': 'j', 'joint_reference': float('inf'), 'reference': 0.0, 'factor': 1.0}})),
     'urdf_drivers.crank.joint_reference', r'finite'),
    ('urdf_drivers_joint_not_a_name', edit(setitem(['urdf_drivers'], {'crank': {
        'joint': 3, 'joint_reference': 0.0, 'reference': 0.0, 'factor': 1.0}})),
     'urdf_drivers.crank.joint', r'expected a joint name'),
    # urdf_reactions: where a robot's reactions act in the plane (the view reads it).
    ('urdf_reactions_axes_not_2x3', edit(setitem(['urdf_reactions'], {'pin': {
        'frame': 'rocker', 'body': 'rocker', 'at': 'C', 'axes': [[1, 0], [0, 1]]}})),
     'urdf_reactions.pin.axes', r'two rows of three finite numbers'),
    ('urdf_reactions_not_finite', edit(setitem(['urdf_reactions'], {'pin': {
        'frame': 'rocker', 'body': 'rocker', 'at': 'C',
        'axes': [[1, 0, float('nan')], [0, 1, 0]]}})),
     'urdf_reactions.pin.axes', r'two rows of three finite numbers'),
    ('urdf_reactions_point_off_the_body', edit(setitem(['urdf_reactions'], {'pin': {
        'frame': 'rocker', 'body': 'rocker', 'at': 'A', 'axes': [[1, 0, 0], [0, 1, 0]]}})),
     'urdf_reactions.pin.body', r"got body 'rocker' and point 'A'"),
    ('urdf_reactions_key_missing', edit(setitem(['urdf_reactions'], {'pin': {
        'frame': 'rocker', 'body': 'rocker', 'axes': [[1, 0, 0], [0, 1, 0]]}})),
     'urdf_reactions.pin', r'expected at, got none'),
]


def key_of(message, path):
    """Return the key that a ``FILE: KEY: reason`` message names."""
    assert message.startswith(f'{path}: '), message
    return message[len(f'{path}: '):].split(': ')[0]


@pytest.mark.parametrize(('content', 'key', 'reason'),
                         [pytest.param(*case[1:], id=case[0]) for case in BAD_SCENES])
def test_bad_scene_is_rejected_naming_file_key_and_reason(tmp_path, content, key, reason):
    """A bad scene raises one SceneError: ``FILE: KEY: reason``, on one line."""
    path = write(tmp_path, content, 'bad_scene.yaml')
    with pytest.raises(mk.SceneError, match=re.escape(str(path))) as info:
        mk.load_scene(path)
    message = str(info.value)
    assert re.search(reason, message), message
    assert '\n' not in message
    if 'YAML' in reason or key == 'top level':
        assert key in message
    else:
        assert key_of(message, path) in ((key,) if isinstance(key, str) else key), message


def test_a_scene_in_mm_without_units_is_refused_not_read_as_metres(tmp_path):
    """Without `units:` the scene is refused in one line showing both forms. See issue 11."""
    path = write(tmp_path, BASE.replace('units: {length: mm, angle: deg}\n', ''))
    with pytest.raises(mk.SceneError) as info:
        mk.load_scene(path)
    assert str(info.value) == (f'{path}: units: missing required key: write units: '
                               '{length: mm, angle: deg} or units: {length: m, angle: rad}')
    result = run_command('solve', path)
    assert result.returncode == 2 and result.stderr == f'error: {info.value}\n'


def test_there_are_at_least_twenty_bad_scenes():
    """Issue 2 asks for at least 15 bad scenes; the brief for this file at least 20."""
    assert len({case[0] for case in BAD_SCENES}) == len(BAD_SCENES) >= 20


def test_missing_file_is_a_scene_error(tmp_path):
    """A scene path that does not exist raises SceneError naming the path."""
    path = tmp_path / 'absent.yaml'
    with pytest.raises(mk.SceneError, match=re.escape(str(path))):
        mk.load_scene(path)


def test_unknown_packaged_name_lists_the_packaged_scenes():
    """An unknown scene name raises SceneError that lists the packaged names."""
    with pytest.raises(mk.SceneError, match=mk.DEFAULT_SCENE):
        mk.load_scene('no_such_scene_name')


def test_scene_without_dyads_is_a_bare_crank(tmp_path):
    """`dyads` is optional (docs/scene_format.md marks only name, ground and input required)."""
    data = edit(delitem(['dyads']))
    del data['points']
    scene = mk.load_scene(write(tmp_path, data))
    state = mk.solve(scene, 0.5)
    np.testing.assert_allclose(state.points['B'].position,
                               [0.04 * math.cos(0.5), 0.04 * math.sin(0.5)], rtol=1e-15)


# --- packaged scenes ------------------------------------------------------------------

PACKAGED = sorted(SCENES.glob('*.yaml'))


def test_scenes_are_packaged():
    """config/scenes/ holds scenes, and the default scene is one of them."""
    assert PACKAGED
    assert mk.DEFAULT_SCENE in {path.stem for path in PACKAGED}
    assert {path.stem for path in PACKAGED} <= set(mk.scene_names())


@pytest.mark.parametrize('path', PACKAGED, ids=[path.stem for path in PACKAGED])
def test_packaged_scene_loads_and_solves(path):
    """Every packaged scene loads by path and by name and solves at its initial angle."""
    scene = mk.load_scene(path)
    assert mk.load_scene(path.stem) == scene
    state = mk.solve(scene, start_positions(scene))
    for point in state.points.values():
        for value in (point.position, point.velocity, point.acceleration):
            assert np.all(np.isfinite(value))
    for joint in state.joints.values():
        assert math.isfinite(joint.position + joint.velocity + joint.acceleration)
    json.dumps(state.as_dict())


@pytest.mark.parametrize('path', PACKAGED, ids=[path.stem for path in PACKAGED])
def test_packaged_scene_states_both_units(path):
    """Every packaged scene names its length and angle units (required). See issue 11."""
    units = yaml.safe_load(path.read_text(encoding='utf-8'))['units']
    assert units in ({'length': 'mm', 'angle': 'deg'}, {'length': 'm', 'angle': 'deg'})


@pytest.mark.parametrize(('name', 'crank', 'angle_deg'), [
    ('steam_engine_500_2000', 0.5, 135.0), ('slider_crank_150_600', 0.15, 135.0),
    ('khurmi_four_bar_ad150', 0.04, 60.0),
])
def test_packaged_scene_units_keep_their_meaning(name, crank, angle_deg):
    """The packaged scenes read as before units became required: the crank in metres, the angle."""
    scene = mk.load_scene(name)
    assert scene.input.length == pytest.approx(crank, rel=1e-15)
    assert scene.input.angle == pytest.approx(math.radians(angle_deg), rel=1e-15)


@pytest.mark.parametrize('path', PACKAGED, ids=[path.stem for path in PACKAGED])
def test_solve_command_answers_every_packaged_scene(path):
    """`python -m mech_kinematics solve NAME` prints the scene's state as JSON."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        status = main(['solve', path.stem])
    assert status == 0
    scene = mk.load_scene(path)
    assert_same(json.loads(out.getvalue()), mk.solve(scene, start_positions(scene)).as_dict())


# --- units and outputs ----------------------------------------------------------------


def si_scene(data):
    """Return the mapping rewritten in m and rad (the same mechanism)."""
    data = copy.deepcopy(data)
    k = 1000.0

    def metres(d, key):
        d[key] = d[key] / k
    data['units'] = {'length': 'm', 'angle': 'rad'}
    data['ground'] = {n: [x / k, y / k] for n, (x, y) in data['ground'].items()}
    metres(data['input'], 'length')
    data['input']['angle'] = math.radians(data['input']['angle'])
    for dyad in data['dyads']:
        for link in dyad.get('links', []):
            metres(link, 'length')
        if 'link' in dyad:
            metres(dyad['link'], 'length')
            dyad['guide']['angle'] = math.radians(dyad['guide']['angle'])
    for point in data.get('points', {}).values():
        if 'distance' in point:
            metres(point, 'distance')
        else:
            point['local'] = [v / k for v in point['local']]
    return data


def test_mm_and_m_scene_files_give_the_same_si_answer(tmp_path):
    """The base scene in mm/deg and in m/rad solve to the same SI values."""
    in_mm = mk.load_scene(write(tmp_path, BASE, 'mm.yaml'))
    in_m = mk.load_scene(write(tmp_path, si_scene(base()), 'm.yaml'))
    assert in_mm.input.length == pytest.approx(0.04, rel=1e-15)
    assert in_mm.input.angle == pytest.approx(math.pi / 3, rel=1e-15)
    angles = np.radians(np.arange(0.0, 360.0, 5.0))
    a, b = mk.solve(in_mm, angles, 2.0, 3.0), mk.solve(in_m, angles, 2.0, 3.0)
    np.testing.assert_array_equal(a.valid, b.valid)
    assert a.valid.any()
    for name, point in a.points.items():
        for quantity in ('position', 'velocity', 'acceleration'):
            expected = getattr(b.points[name], quantity)[b.valid]
            scale = np.max(np.abs(expected))
            np.testing.assert_allclose(getattr(point, quantity)[a.valid], expected, rtol=0,
                                       atol=RTOL_UNITS * scale, err_msg=f'{name} {quantity}')


def test_outputs_report_exactly_the_listed_names_in_order(tmp_path):
    """`outputs` lists what is reported, in the listed order, with the full scene's values."""
    data = base()
    data['outputs'] = {'points': ['C', 'B'], 'joints': ['rocker', 'coupler']}
    pruned = mk.load_scene(write(tmp_path, data, 'pruned.yaml'))
    full = mk.load_scene(write(tmp_path, BASE, 'full.yaml'))
    assert pruned.output_points == ('C', 'B')
    assert pruned.output_joints == ('rocker', 'coupler')
    for angle in (0.3, 1.0, 2.0):
        got, expected = mk.solve(pruned, angle), mk.solve(full, angle)
        assert list(got.points) == ['C', 'B']
        assert list(got.joints) == ['rocker', 'coupler']
        assert list(got.as_dict()['points']) == ['C', 'B']
        for name, point in got.points.items():
            for quantity in ('position', 'velocity', 'acceleration'):
                np.testing.assert_array_equal(getattr(point, quantity),
                                              getattr(expected.points[name], quantity))
        for name, joint in got.joints.items():
            for quantity in ('type', 'position', 'velocity', 'acceleration'):
                assert getattr(joint, quantity) == getattr(expected.joints[name], quantity)


def test_outputs_skip_what_is_not_asked_for(tmp_path):
    """A dyad the outputs do not need is not solved: its failure does not stop the rest."""
    data = base()
    data['outputs'] = {'points': ['C'], 'joints': ['rocker']}
    pruned = mk.load_scene(write(tmp_path, data, 'pruned.yaml'))
    full = mk.load_scene(write(tmp_path, BASE, 'full.yaml'))
    angles = np.radians(np.arange(0.0, 360.0, 1.0))
    everything = mk.solve(full, angles)
    only_c = mk.solve(pruned, angles)
    # The ram (RRP P, rod 150 mm from E to the guide 100 mm below A) loses reach over part
    # of the cycle; the four-bar alone assembles everywhere.
    assert set(everything.failures) == {'RRP P'}
    assert only_c.valid.all() and not only_c.failures
    assert set(only_c.singularity) == {'C'}
    unreachable = float(angles[~everything.valid][0])
    with pytest.raises(mk.AssemblyError, match='RRP P'):
        mk.solve(full, unreachable)
    state = mk.solve(pruned, unreachable)
    pc = state.points['C'].position
    pb = 0.04 * np.array([math.cos(unreachable), math.sin(unreachable)])
    assert math.isclose(math.dist(pc, (0.15, 0.0)), 0.08, rel_tol=1e-12)
    assert math.isclose(math.dist(pc, pb), 0.15, rel_tol=1e-12)


# --- no ROS in the solver -----------------------------------------------------------------


def test_solver_modules_do_not_import_rclpy(tmp_path):
    """Importing the solver, scene and errors modules and the package loads no ROS module.

    A stand-in ``rclpy`` on the path makes an import of it succeed, and so show up in
    ``sys.modules``, whether or not ROS is installed.
    """
    for name in ('rclpy', 'rosidl_runtime_py', 'sensor_msgs', 'trajectory_msgs'):
        (tmp_path / name).mkdir()
        (tmp_path / name / '__init__.py').write_text('')
    code = ('import sys, importlib.util\n'
            f'assert importlib.util.find_spec("rclpy").origin.startswith({str(tmp_path)!r})\n'
            'import mech_kinematics.linkage, mech_kinematics.scene, mech_kinematics.errors\n'
            'import mech_kinematics\n'
            'ros = sorted(m for m in sys.modules if m.split(".")[0] in\n'
            '             ("rclpy", "rosidl_runtime_py", "sensor_msgs", "trajectory_msgs"))\n'
            'assert not ros, ros\n')
    env = dict(os.environ, PYTHONPATH=os.pathsep.join((str(tmp_path), str(ROOT))))
    result = subprocess.run([sys.executable, '-c', code], cwd=tmp_path, env=env,
                            capture_output=True, text=True, timeout=TIMEOUT, check=False)
    assert result.returncode == 0, result.stderr


# --- the solve command ----------------------------------------------------------------------


def run_command(*args):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, '-m', 'mech_kinematics', *map(str, args)],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=TIMEOUT,
                          check=False)


def assert_same(got, expected, path='', rel=1e-14):
    """Assert two JSON-like structures are equal, numbers to ``rel`` relative."""
    if isinstance(expected, dict):
        assert isinstance(got, dict) and list(got) == list(expected), path
        for key in expected:
            assert_same(got[key], expected[key], f'{path}.{key}', rel)
    elif isinstance(expected, (list, tuple)):
        assert isinstance(got, list) and len(got) == len(expected), path
        for index, (g, e) in enumerate(zip(got, expected, strict=True)):
            assert_same(g, e, f'{path}[{index}]', rel)
    elif isinstance(expected, (str, bool)):
        assert got == expected and type(got) is type(expected), path
    else:
        assert isinstance(got, (int, float)) and not isinstance(got, bool), path
        assert math.isclose(got, expected, rel_tol=rel, abs_tol=1e-300), (path, got, expected)


def test_solve_command_prints_the_api_state(tmp_path):
    """`solve SCENE --angle-deg X --speed-rpm N --accel A` prints solve(...).as_dict() as JSON."""
    path = write(tmp_path, BASE)
    result = run_command('solve', path, '--angle-deg', 200, '--speed-rpm', 30, '--accel', 2.5)
    assert result.returncode == 0, result.stderr
    # 200 deg is -160 deg in turn 1 (issue 11: the crank angle is counted from the start).
    angle, turns = turns_from_degrees(200.0)
    assert turns == 1 and angle == math.radians(-160.0)
    expected = mk.solve(mk.load_scene(path), angle, 30 * math.pi / 30, 2.5, turns=turns)
    assert_same(json.loads(result.stdout), expected.as_dict())


def run_in_process(capsys, *args):
    """Return (status, stdout, stderr) of ``main(ARGS)``: the command, called here."""
    capsys.readouterr()
    try:
        status = main([str(arg) for arg in args])
    except SystemExit as exit_:     # --help
        status = exit_.code
    out, err = capsys.readouterr()
    return status, out, err


def test_solve_command_defaults_to_the_scene(tmp_path, capsys):
    """Without options `solve` uses the scene's angle, speed and acceleration (called here)."""
    path = write(tmp_path, BASE)
    status, out, err = run_in_process(capsys, 'solve', path)
    assert status == 0, err
    scene = mk.load_scene(path)
    got = json.loads(out)
    assert_same(got, mk.solve(scene, scene.input.angle).as_dict())
    assert math.isclose(got['input']['speed'], -4 * math.pi, rel_tol=1e-15)


def test_solve_help_mentions_every_option(capsys):
    """`solve --help` explains SCENE and every option, with units.

    Called here: test_packaging.py runs the `solve` console script's --help.
    """
    status, text, _ = run_in_process(capsys, 'solve', '--help')
    assert status == 0
    for word in ('SCENE', '--angle-deg', '--speed-rpm', '--accel', 'degrees', 'rpm',
                 'rad/s^2', 'status 2'):
        assert word in text, word
    parser = build_parser()
    commands = next(a for a in parser._actions if a.dest == 'command')
    for action in commands.choices['solve']._actions:
        for option in action.option_strings:
            assert option in text, option


def test_solve_command_exits_2_on_an_unsolvable_angle(tmp_path):
    """At an angle where the mechanism cannot assemble, `solve` prints one line and exits 2."""
    d, a, b, c = 1.0, 0.6, 0.5, 0.7  # non-Grashof: s + l = 1.5 > p + q = 1.3
    data = {'name': 'non_grashof', 'units': {'length': 'm', 'angle': 'deg'},
            'ground': {'A': [0, 0], 'D': [d, 0]},
            'input': {'link': 'crank', 'center': 'A', 'point': 'B', 'length': a, 'angle': 0},
            'dyads': [{'type': 'RRR', 'point': 'C',
                       'links': [{'name': 'coupler', 'from': 'B', 'length': b},
                                 {'name': 'rocker', 'from': 'D', 'length': c}]}]}
    path = write(tmp_path, data)
    angle = 180.0
    bd = abs(d - a * complex(math.cos(math.radians(angle)), math.sin(math.radians(angle))))
    assert not abs(b - c) < bd < b + c  # independent: the circles about B and D do not meet
    result = run_command('solve', path, '--angle-deg', angle)
    assert result.returncode == 2
    assert result.stdout == ''
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert 'RRR C' in lines[0] and 'Traceback' not in result.stderr


def test_solve_command_rejects_a_bad_scene_in_one_line(tmp_path, capsys):
    """A bad scene file makes `solve` print one line naming the file and fail.

    Called here: test_scene_loader.py runs `solve` on hostile files as a command.
    """
    path = write(tmp_path, edit(setitem([*LINK1, 'length'], -80)))
    status, _, err = run_in_process(capsys, 'solve', path)
    assert status != 0
    lines = err.strip().splitlines()
    assert len(lines) == 1 and str(path) in lines[0], err


# --- the edges of the format (issue 33) -----------------------------------------------


def packaged_data(name):
    """Return the mapping of the packaged scene ``name``, as read from its file."""
    return mk.scene.read_scene_yaml(mk.scene.scene_text(name))


def at(data, path, value):
    """Return a copy of ``data`` with the key at ``path`` (a list of keys) set to ``value``."""
    data = copy.deepcopy(data)
    node = data
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return data


@pytest.mark.parametrize('name, path, far, near', [
    ('offset_slider_crank', ['dyads', 0, 'guide', 'angle'], 1e17, -80.0),    # RRP's guide
    ('scotch_yoke', ['dyads', 0, 'guide', 'angle'], 1e17, -80.0),            # RPP's guide
    ('scotch_yoke', ['dyads', 0, 'slot_angle'], 360.0 * 2 ** 40 + 90, 90.0),  # RPP's slot
    ('gripper', ['imus', 'fingertip', 'angle'], -1e17, 80.0),                # a sensor's axis
])
def test_a_direction_beyond_a_turn_is_read_as_the_direction_it_names(name, path, far, near):
    """Issue 33: every angle key but the crank's start is a direction, reduced exactly.

    1e17 deg is -80 deg (IEEE remainder): the scene solves to the bits of the
    one written -80. A guide at 1e17 deg was read as 1.7e15 rad, whose cosine has
    nothing to do with -80 deg (the slider crank's rod then could not reach it).
    """
    assert math.remainder(far, 360.0) == near
    data = packaged_data(name)
    far_scene, near_scene = (mk.parse_scene(at(data, path, value)) for value in (far, near))
    assert far_scene == near_scene
    far_state, near_state = (mk.solve(scene, scene.input.angle)
                             for scene in (far_scene, near_scene))
    assert far_state.as_dict() == near_state.as_dict()


def test_a_direction_in_rad_beyond_a_turn_is_reduced_with_2_pi_to_400_digits():
    """A guide at 1e17 rad (a scene in rad) is 1e17 mod 2 pi correctly rounded (mpmath, 60 digits).

    A float 2 pi is off by 2.4e-16 rad a turn: 1.6e16 turns would put it 4 rad off.
    """
    import mpmath

    data = si_scene(base())
    data['dyads'][1]['guide']['angle'] = 1e17
    with mpmath.workdps(60):
        turn = 2 * mpmath.pi
        exact = float(mpmath.mpf(1e17) - turn * mpmath.nint(mpmath.mpf(1e17) / turn))
    assert mk.parse_scene(data).dyads[1].guide_angle == exact


def test_a_crank_speed_in_rad_per_s_is_taken_as_written():
    """Issue 33: `speed: 300` (rad/s, signed) on a crank, as the course gives it; exact.

    speed_rpm stays; `speed` is its alternative (both given: refused, see the
    bad scenes). The value is kept in rad/s to the bit, for `solve` and the API.
    """
    data = base()
    del data['input']['speed_rpm']
    for value in (300, -300.0, 1e-300, 0):
        data['input']['speed'] = value
        scene = mk.parse_scene(data)
        assert scene.input.speed == float(value)
        assert mk.solve(scene, scene.input.angle).as_dict()['input']['speed'] == float(value)
    five = packaged_data('five_bar')
    del five['inputs'][1]['speed_rpm']
    five['inputs'][1]['speed'] = -2.5
    assert mk.parse_scene(five).drivers[1].speed == -2.5
    five['inputs'][1]['speed_rpm'] = 10
    with pytest.raises(mk.SceneError, match=r'^inputs\[1\]\.speed: expected the crank speed '
                                            r'once, .* got both \(speed: -2\.5, speed_rpm: 10\)'):
        mk.parse_scene(five)
    data['input']['speed'] = 'fast'
    with pytest.raises(mk.SceneError, match=r"^input\.speed: expected a number, got str 'fast'"):
        mk.parse_scene(data)


def test_an_actuator_named_twice_is_refused_at_its_second_name():
    """Issue 33: the second `actuator: boom_cyl` of inputs is named, not the dyad using the first.

    It said `dyads[1].links[1].actuator: expected the name of an actuator of
    inputs (boom_cyl), got 'stick_cyl'`: the wrong key and the wrong actuator.
    """
    data = at(packaged_data('excavator'), ['inputs', 1, 'actuator'], 'boom_cyl')
    with pytest.raises(mk.SceneError) as caught:
        mk.parse_scene(data)
    assert str(caught.value) == ('inputs[1].actuator: Expected every driver to have a name of '
                                 'its own, got "boom_cyl" again (the name of inputs[0])')
    five = at(packaged_data('five_bar'), ['inputs', 1, 'link'], 'left_crank')
    with pytest.raises(mk.SceneError, match=r'^inputs\[1\]\.link: Expected every driver to have '
                                            r'a name of its own, got "left_crank" again'):
        mk.parse_scene(five)


def test_an_actuator_used_by_two_links_is_refused_at_the_second_link():
    """Issue 33: the second link naming boom_cyl is blamed, not the actuator left unused.

    It said `inputs[1].actuator: Expected actuator "stick_cyl" to be the length
    of an RRR link ..., got no link using it`. Built through the API, the scene
    names both dyads.
    """
    data = at(packaged_data('excavator'), ['dyads', 1, 'links', 1, 'actuator'], 'boom_cyl')
    with pytest.raises(mk.SceneError) as caught:
        mk.parse_scene(data)
    assert str(caught.value) == (
        'dyads[1].links[1].actuator: Expected each actuator to be the length of one link, got '
        '"boom_cyl" again (the actuator of dyads[0].links[1])')
    excavator = mk.load_scene('excavator')
    stick = excavator.dyads[1]
    from dataclasses import replace

    with pytest.raises(mk.SceneError) as caught:
        mk.Scene(name='x', ground=excavator.ground, inputs=excavator.drivers,
                 dyads=(excavator.dyads[0], replace(stick, actuators=(None, 'boom_cyl'))),
                 points=excavator.points, units=excavator.units)
    assert str(caught.value) == ('Expected each actuator to be the length of one link, got '
                                 '"boom_cyl" in RRR Q and again in RRR K')


def test_the_readme_describes_every_packaged_scene():
    """Each packaged scene has its row in the README's table of packaged scenes."""
    table = (ROOT / 'README.md').read_text(encoding='utf-8').split(
        'Packaged scenes (`config/scenes/`)', 1)[1].split('\n\n', 2)[1]
    listed = set(re.findall(r'^\| `(\w+)`', table, flags=re.MULTILINE))
    assert listed == {path.stem for path in PACKAGED}
