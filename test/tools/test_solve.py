# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The ``solve`` command with several drivers: --input, --speed, --accel NAME=VALUE (issue 18).

The one-crank flags are tested with the scene reader (test/test_scene.py).
"""

from __future__ import annotations

import contextlib
import io
import json
import math

from helpers import SCENES
import pytest

import mech_kinematics as mk
from mech_kinematics.__main__ import main
from mech_kinematics.units import rad_per_s_from_rpm


def run(*args):
    """Return (status, stdout, stderr) of ``python -m mech_kinematics solve ARGS``."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = main(['solve', *args])
    return status, out.getvalue(), err.getvalue()


def test_drivers_by_name_in_their_units():
    """--input in degrees or the scene's length unit, --speed in rpm or m/s, --accel SI."""
    status, out, _ = run('five_bar', '--input', 'left_crank=120', '--input', 'right_crank=420',
                         '--speed', 'left_crank=60', '--accel', 'right_crank=-2')
    assert status == 0
    data = json.loads(out)
    assert 'input' not in data
    left, right = data['inputs']['left_crank'], data['inputs']['right_crank']
    assert left == {'position': math.radians(120), 'speed': rad_per_s_from_rpm(60.0),
                    'accel': 0.0}
    assert right['position'] == pytest.approx(math.radians(420), rel=1e-15)
    assert (right['speed'], right['accel']) == (rad_per_s_from_rpm(30.0), -2.0)  # the scene's
    scene = mk.load_scene('five_bar')
    expected = mk.solve(scene, [math.radians(120), math.radians(60)],
                        [rad_per_s_from_rpm(60.0), None],
                        [None, -2.0], turns=[0, 1]).as_dict()
    assert data['points']['P'] == {key: list(value) for key, value in
                                   expected['points']['P'].items()}
    status, out, _ = run('excavator', '--input', 'boom_cyl=2.8', '--speed', 'stick_cyl=-0.05',
                         '--accel', 'stick_cyl=0.1')
    cylinder = json.loads(out)['inputs']['stick_cyl']
    assert (status, cylinder) == (0, {'position': 3.0, 'speed': -0.05, 'accel': 0.1})


def test_an_actuator_length_is_in_the_scenes_unit(tmp_path):
    """In a scene written in mm, --input cyl=2800 is 2.8 m."""
    text = mk.scene.scene_text('excavator').replace('units: {length: m, angle: deg}',
                                                    'units: {length: mm, angle: deg}')
    for old, new in (('2.6', '2600'), ('3.0', '3000'), ('[2.0, 3.3]', '[2000, 3300]'),
                     ('[2.5, 3.9]', '[2500, 3900]'), ('0.4', '400'), ('-1.1', '-1100'),
                     ('length: 0.9', 'length: 900'), ('5.68, 0.55', '5680, 550'),
                     ('2.5, 0.9', '2500, 900'), ('-2.9, 0.0', '-2900, 0'),
                     ('-4.0, 0.5', '-4000, 500')):
        text = text.replace(old, new)
    path = tmp_path / 'excavator_mm.yaml'
    path.write_text(text)
    status, out, _ = run(str(path), '--input', 'boom_cyl=2800')
    assert status == 0 and json.loads(out)['inputs']['boom_cyl']['position'] == 2.8


@pytest.mark.parametrize(('args', 'message'), [
    (('--input', 'boom=3'), 'error: Expected --input NAME=VALUE with NAME one of the drivers '
                            "(boom_cyl, stick_cyl), got 'boom'\n"),
    (('--speed', 'arm=3'), 'error: Expected --speed NAME=VALUE with NAME one of the drivers '
                           "(boom_cyl, stick_cyl), got 'arm'\n"),
    (('--angle-deg', '30'), 'error: Expected --input, --speed and --accel NAME=VALUE for a '
                            'scene with several drivers (boom_cyl, stick_cyl), got '
                            '--angle-deg\n'),
    (('--accel', '3'), 'error: Expected --accel NAME=VALUE with NAME one of the drivers '
                       '(boom_cyl, stick_cyl), got --accel 3\n'),
    (('--input', 'stick_cyl=3.95'), 'error: input stick_cyl cannot be solved at boom_cyl = '
                                    '2.6 m, stick_cyl = 3.95 m: actuator stick_cyl: expected '
                                    'a length within its stroke [2.5 m, 3.9 m], got 3.95 m\n'),
])
def test_bad_driver_flags_are_refused_in_one_line(args, message):
    """An unknown driver, a one-crank flag or a length beyond the stroke: one line, exit 2."""
    status, out, err = run('excavator', *args)
    assert (status, out, err) == (2, '', message)


def test_one_crank_usage_is_unchanged_and_takes_its_name_too():
    """--angle-deg, --speed-rpm, --accel A as before; --input crank=DEG says the same."""
    _, plain, _ = run('khurmi_four_bar_ad150', '--angle-deg', '400', '--speed-rpm', '90',
                      '--accel', '2')
    _, named, _ = run('khurmi_four_bar_ad150', '--input', 'crank=400', '--speed', 'crank=90',
                      '--accel', 'crank=2')
    assert plain == named
    data = json.loads(plain)
    assert data['input'] == {'angle': math.radians(40) + 2 * math.pi,
                             'speed': rad_per_s_from_rpm(90.0), 'accel': 2.0}
    status, _, err = run('khurmi_four_bar_ad150', '--angle-deg', '40', '--input', 'crank=40')
    assert (status, err) == (2, 'error: Expected --angle-deg or --input crank=DEG, got both\n')


# --- the edges (issue 33) ----------------------------------------------------------------


def test_an_actuator_alone_is_driven_by_name_and_by_the_scenes_values():
    """The packaged boom (one cylinder, its only driver): `solve` answers what mk.solve does.

    `--input lift_cyl=2 --speed lift_cyl=0 --accel lift_cyl=0` failed with
    "unexpected TypeError: Object of type ndarray is not JSON serializable" (the
    values were passed on as a list of one, an array of one configuration), and
    the scene's own values with "Expected the positions, speeds and accels of the
    drivers to be finite" (a list [None] for the speed).
    """
    scene = mk.load_scene('boom')
    status, out, err = run('boom', '--input', 'lift_cyl=2', '--speed', 'lift_cyl=0',
                           '--accel', 'lift_cyl=0')
    assert (status, err) == (0, '')
    assert json.loads(out) == json.loads(json.dumps(mk.solve(scene, 2.0, 0.0, 0.0).as_dict()))
    assert json.loads(out)['inputs'] == {'lift_cyl': {'position': 2.0, 'speed': 0.0,
                                                      'accel': 0.0}}
    status, out, err = run('boom')
    assert (status, err) == (0, '')
    assert json.loads(out) == json.loads(json.dumps(mk.solve(scene, 1.9).as_dict()))
    status, out, err = run('boom', '--input', 'lift_cyl=0.85', '--speed', 'lift_cyl=0')
    assert (status, out) == (2, '')
    assert err == ('error: input lift_cyl cannot be solved at lift_cyl = 0.85 m: actuator '
                   'lift_cyl: expected a length within its stroke [1.45 m, 2.35 m], got 0.85 m\n')


@pytest.mark.parametrize('args, expected', [
    (['check', 'boom'], 'lift_cyl: assembles over its whole stroke 1.45..2.35 m'),
    (['urdf', 'boom'], '<robot name="boom">'),
    (['diagram', 'boom', '--input', 'lift_cyl=2.2', '-o', '{tmp}/boom.png'], 'wrote'),
    (['diagram', 'boom', '-o', '{tmp}/boom.svg'], 'wrote'),
    (['plot', '--scene', 'boom', '-o', '{tmp}/plot.png'], 'the path stays where it assembles'),
])
def test_every_command_answers_the_boom(tmp_path, args, expected):
    """check, urdf, diagram and plot answer a scene whose only driver is an actuator.

    `urdf` failed with "unexpected ValueError: Expected the state of one crank
    angle, got an array of shape (1,)".
    """
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = main([arg.format(tmp=tmp_path) for arg in args])
    assert (status, err.getvalue()) == (0, '')
    assert expected in out.getvalue()
    for arg in args:
        if arg.startswith('{tmp}'):
            assert (tmp_path / arg.split('/', 1)[1]).stat().st_size > 1000


IMU_OVERFLOW = """\
name: imu_overflow
units: {length: m, angle: deg}
ground: {A: [0, 0]}
input: {link: crank, center: A, point: B, length: 1, angle: 90, speed: 1.2e154}
imus:
  tip: {link: crank, point: B, gravity: [0, 8e307]}
"""


def test_a_value_beyond_the_range_of_doubles_is_refused_in_one_line(tmp_path):
    """Issue 33: a reading that overflows is one line and exit 2, never "unexpected ValueError".

    The crank's tip accelerates at 1.44e308 m/s^2 toward A, the sensor's
    gravity is 8e307 upward (within MAX_GRAVITY): a_B - g is beyond the
    doubles. `solve` printed "unexpected ValueError: Out of range float values
    are not JSON compliant".
    """
    path = tmp_path / 'imu_overflow.yaml'
    path.write_text(IMU_OVERFLOW)
    status, out, err = run(str(path))
    assert (status, out) == (2, '')
    assert err == ('error: Expected every value of the state at crank angle 90 deg to be '
                   'finite, got imus.tip.linear_acceleration[0] = -inf (beyond the range of '
                   'doubles)\n')
    status, out, err = run(str(path), '--speed-rpm', '1e150')   # slower: answered
    assert (status, err) == (0, '')
    assert all(math.isfinite(x) for x in json.loads(out)['imus']['tip']['linear_acceleration'])


@pytest.mark.parametrize(('old', 'new', 'message'), [
    ('gravity: [0, -9.81]', 'gravity: [1.5e308, 1.5e308]',
     'gravity: expected [gx, gy] whose weight on the moving bodies (24 kg) is a finite force '
     '(at most 1.798e+308 N), got [1.5e+308, 1.5e+308] m/s^2'),
    ('gravity: [0, -9.81]', 'gravity: [1e308, 1e308]',
     'gravity: expected [gx, gy] whose weight on the moving bodies (24 kg) is a finite force '
     '(at most 1.798e+308 N), got [1e+308, 1e+308] m/s^2'),
    ('force: [0, -17892.35190989812]', 'force: [1.7e308, -1.7e308]',
     "loads[0].force: expected the loads' forces and the weights (235.4 N) to add up to a "
     'finite force (at most 1.798e+308 N), got [1.7e+308, -1.7e+308] N'),
])
def test_gravity_or_a_load_whose_forces_overflow_is_one_line(tmp_path, old, new, message):
    """Issue 42: finite numbers whose forces overflow name the key, exit 2 (was OverflowError).

    ``solve`` printed "unexpected OverflowError: absolute value too large" (abs() of the
    complex gravity or force) and exited 1.
    """
    text = (SCENES / 'engine.yaml').read_text()
    assert old in text
    path = tmp_path / 'engine.yaml'
    path.write_text(text.replace(old, new))
    status, out, err = run(str(path))
    assert (status, out) == (2, '')
    assert err == f'error: {path}: {message}\n'


def test_the_five_bar_driven_by_its_effector():
    """--target P.x=MM --target P.y=MM: P reached, the motors' values, the Jacobian, J^T F."""
    status, out, err = run('five_bar', '--target', 'P.x=60', '--target', 'P.y=220',
                           '--target-speed', 'P.x=0.1', '--target-force', 'P.y=-10')
    assert (status, err) == (0, '')
    data = json.loads(out)
    assert data['points']['P']['position'] == pytest.approx([0.06, 0.22], abs=1e-15)
    assert data['points']['P']['velocity'] == pytest.approx([0.1, 0.0], abs=1e-15)
    inverse = mk.solve_targets(mk.load_scene('five_bar'), {'P.x': 0.06, 'P.y': 0.22},
                               {'P.x': 0.1}, forces={'P.y': -10.0})
    for name, row in zip(inverse.drivers, inverse.motion, strict=True):
        assert data['inputs'][name] == {'position': row[0], 'speed': row[1], 'accel': row[2]}
    jacobian = data['jacobian']
    assert (jacobian['rows'], jacobian['columns']) == (['P.x', 'P.y'],
                                                       ['left_crank', 'right_crank'])
    assert jacobian['matrix'] == inverse.jacobian.tolist()
    assert data['target_efforts'] == pytest.approx(
        {name: -10.0 * inverse.jacobian[1, j] for j, name in enumerate(inverse.drivers)})
    assert set(data['error_bound']['inverse']) == {'left_crank', 'right_crank'}
    # --units si: the same answer from metres; --input: the pose continued from.
    status, si, _ = run('five_bar', '--units', 'si', '--target', 'P.x=0.06', '--target',
                        'P.y=0.22', '--target-speed', 'P.x=0.1', '--target-force', 'P.y=-10')
    assert json.loads(si)['inputs'] == data['inputs']
    status, out, _ = run('five_bar', '--target', 'left_distal=45', '--target',
                         'right_distal=130', '--input', 'left_crank=100')
    assert status == 0
    data = json.loads(out)
    assert data['joints']['left_distal']['position'] == pytest.approx(math.radians(45), abs=1e-13)
    assert data['continued_from']['left_crank'] == math.radians(100)


@pytest.mark.parametrize(('args', 'message'), [
    (('--target', 'P.x=60', '--target', 'P.y=420'), 'out of reach'),
    (('--target', 'P.x=60'), 'as many targets as the scene has drivers'),
    (('--target', 'P.x=60', '--target', 'P.y=220', '--speed', 'left_crank=3'),
     'Expected --target-speed'),
    (('--target', 'P.x=60', '--target', 'P.y=220', '--target-speed', 'B.x=1'),
     'Expected --target-speed for targets given with --target'),
    (('--target', '60', '--target', 'P.y=220'), 'Expected --target NAME=VALUE'),
])
def test_bad_targets_are_one_line(args, message):
    status, out, err = run('five_bar', *args)
    assert (status, out) == (2, '')
    assert message in err
    assert err.count('\n') == 1


def test_the_targets_reference_says_what_solve_does():
    """docs/targets.md: its commands run, its refusal is the program's, its two half-turns hold."""
    from helpers import ROOT

    text = (ROOT / 'docs' / 'targets.md').read_text()
    block = text.split('```sh\n', 1)[1].split('```', 1)[0]
    for line in block.splitlines():
        words = line.split()
        assert words[:3] == ['python', '-m', 'mech_kinematics']
        status, _, err = run(*words[4:])
        assert (status, err) == (0, ''), line
    quoted = next(block.split('```', 1)[0] for block in text.split('```text\n')[1:]
                  if 'out of reach' in block.split('```', 1)[0])
    status, _, err = run('five_bar', '--target', 'P.x=60', '--target', 'P.y=420')
    assert (status, err) == (2, quoted)
    assert 'piston at -696.6166 mm is reached with the crank at\n135° from `--input crank=150` ' \
        'and at 225° from `--input crank=210`' in text
    for start, angle in (('150', 135.0), ('210', 225.0)):
        status, out, _ = run('slider_crank_150_600', '--target', 'piston=-696.6166', '--input',
                             f'crank={start}')
        assert math.degrees(json.loads(out)['input']['angle']) == pytest.approx(angle, abs=1e-3)


def test_the_readme_five_bar_driven_by_its_effector():
    """The README's three commands: the motors' angles, speeds and torques it quotes."""
    from helpers import ROOT

    text = (ROOT / 'README.md').read_text().split('## Driven from its output', 1)[1]
    text = text.split('\n## ', 1)[0]
    block = text.split('```sh\n', 1)[1].split('```', 1)[0]
    outputs = []
    for line in block.splitlines():
        status, out, err = run(*line.split()[4:])
        assert (status, err) == (0, ''), line
        outputs.append(json.loads(out))
    prose = ' '.join(text.split('```', 2)[2].split())
    angles = [math.degrees(outputs[0]['inputs'][m]['position']) for m in ('left_crank',
                                                                          'right_crank')]
    assert f'motors at {angles[0]:.3f}° and {angles[1]:.3f}°' in prose
    speeds = [outputs[1]['inputs'][m]['speed'] for m in ('left_crank', 'right_crank')]
    assert f'motors at {speeds[0]:.5f} and {speeds[1]:.5f} rad/s' in prose
    torques = [outputs[2]['target_efforts'][m] for m in ('left_crank', 'right_crank')]
    assert f"motors' share {torques[0]:.5f} and {torques[1]:.5f} N m" in prose
