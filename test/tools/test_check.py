# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The ``check`` command: a scene's assembly ranges, toggles, dead centres, Grashof class.

See issue 11. The numbers are the hand values of ``test_assembly.py``'s cases,
shown in the scene's units (text) or SI (``--json``).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
import re
import subprocess
import sys

from helpers import BOOM_CYLINDER, FIVE_BAR_TWO_CRANKS, FORCES
import pytest
import yaml

import mech_kinematics as mk
from mech_kinematics.__main__ import build_parser, main, TOOLS
from mech_kinematics.geometry.turning import turning_moment_from_scene
from mech_kinematics.tools import check

REPO = Path(__file__).resolve().parents[2]
LIMIT = math.acos((50 ** 2 + 100 ** 2 - 122 ** 2) / (2 * 50 * 100))  # 103.792 deg


def test_text_report_of_the_triple_rocker(capsys):
    """four_bar_coupler_points: every line, in degrees and millimetres."""
    assert main(['check', 'four_bar_coupler_points']) == 0
    assert capsys.readouterr().out.splitlines() == [
        'four_bar_coupler_points: one turn of crank "crank" about A (angles in deg, CCW from '
        '+x; lengths in mm)',
        'assembles: for crank angles -103.792..103.792 deg',
        'does not assemble for crank angles 103.792..256.208 deg',
        'toggle positions: 103.792 deg (RRR C: coupler and rocker in line), 256.208 deg '
        '(RRR C: coupler and rocker in line)',
        'dead centres: 28.8528 deg (rocker reverses at 88.3628 deg; crank and coupler in line)',
        'minimum transmission angle: 0 deg at crank angle 103.792 deg (RRR C: coupler and '
        'rocker)',
        'four-bar loops: A-B-C-D (ground AD 100 mm, crank 50 mm, coupler 66 mm, rocker 56 mm): '
        'triple-rocker (non-Grashof: s + l = 150 mm > p + q = 122 mm)',
    ]


def test_json_report_is_si(capsys):
    """--json: ranges, gaps and angles in rad, lengths in m, the summary line as text."""
    assert main(['check', 'four_bar_coupler_points', '--json']) == 0
    data = json.loads(capsys.readouterr().out)
    assert data['assembles_everywhere'] is False
    (start, end), = data['ranges']
    assert start == pytest.approx(-LIMIT, abs=1e-11) and end == pytest.approx(LIMIT, abs=1e-11)
    assert data['gaps'][0] == pytest.approx([LIMIT, 2 * math.pi - LIMIT], abs=1e-11)
    assert data['summary'] == 'does not assemble for crank angles 103.792..256.208 deg'
    assert [t['dyad'] for t in data['toggles']] == ['RRR C', 'RRR C']
    (loop,) = data['loops']
    assert loop['class'] == 'triple-rocker'
    assert loop['lengths'] == pytest.approx({'ground': 0.1, 'input': 0.05, 'coupler': 0.066,
                                             'output': 0.056}, rel=1e-15)
    assert loop['names'] == {'ground': 'AD', 'input': 'crank', 'coupler': 'coupler',
                             'output': 'rocker'}
    (centre,) = data['dead_centres']
    assert centre['joint'] == 'rocker' and centre['in_line'] == ['crank', 'coupler']


def test_slider_crank_dead_centres_in_text(capsys):
    """piston_300: reversals at 0 and 180 deg, at s = 220 and 120 mm."""
    assert main(['check', 'piston_300']) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1] == 'assembles: at every crank angle'
    assert lines[2] == 'toggle positions: none'
    assert lines[3] == ('dead centres: 0 deg (piston reverses at s = 220 mm; crank and rod in '
                        'line), 180 deg (piston reverses at s = 120 mm; crank and rod in line)')
    assert lines[4] == ('minimum transmission angle: 72.8954 deg at crank angle 90 deg '
                        '(RRP C: rod)')
    assert lines[5] == 'four-bar loops: none'


def test_a_bad_scene_is_one_line_and_exit_2(tmp_path, capsys):
    """A scene that cannot be read: `error: ...` on one line, status 2."""
    path = tmp_path / 'bad.yaml'
    path.write_text('name: bad\n')
    assert main(['check', str(path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith('error: ') and err.count('\n') == 1 and 'units' in err


def test_registered_as_a_tool_and_a_console_script():
    """`check` is in TOOLS, parses its options and runs as `check` from setup.py."""
    assert check in TOOLS
    args = build_parser().parse_args(['check', 'geneva', '--json'])
    assert args.handler.__module__ == check.__name__ and args.json
    result = subprocess.run([sys.executable, '-m', 'mech_kinematics', 'check', '--help'],
                            capture_output=True, text=True, check=False, cwd=REPO)
    assert result.returncode == 0
    for word in ('toggle', 'dead centres', 'transmission', 'Grashof', '--json', 'SI'):
        assert word in result.stdout, word
    assert "'check = mech_kinematics.tools.check:main'" in (REPO / 'setup.py').read_text()


def test_quick_return_time_ratio_is_the_closed_form(capsys):
    """Crank and slotted lever: the return stroke takes 2 acos(r/d) of crank (Khurmi 15.3)."""
    assert main(['check', 'quick_return', '--json']) == 0
    data = json.loads(capsys.readouterr().out)
    beta = 2 * math.acos(150 / 400)  # crank AB = 150 mm, centres AO = 400 mm
    by_joint = {s['joint']: s for s in data['strokes']}
    assert set(by_joint) == {'lever', 'ram'}
    for output in by_joint.values():
        assert output['time_ratio'] == pytest.approx((2 * math.pi - beta) / beta, rel=1e-11)
        travels = sorted(s['crank_travel'] for s in output['strokes'])
        assert travels == pytest.approx([beta, 2 * math.pi - beta], abs=1e-11)
    lever = by_joint['lever']['strokes']
    assert lever[0]['to_position'] == lever[1]['from_position']
    assert abs(lever[0]['from_position'] - lever[0]['to_position']) == pytest.approx(
        2 * math.asin(150 / 400), abs=1e-11)  # the lever's swing


def test_offset_slider_crank_time_ratio(capsys):
    """Offset 50, rod 400, crank 100 mm: time ratio (pi + d) / (pi - d) from the in-line angles."""
    assert main(['check', 'offset_slider_crank', '--json']) == 0
    (piston,) = json.loads(capsys.readouterr().out)['strokes']
    delta = math.asin(50 / 300) - math.asin(50 / 500)
    assert piston['time_ratio'] == pytest.approx((math.pi + delta) / (math.pi - delta), rel=1e-11)
    assert abs(piston['strokes'][0]['from_position'] - piston['strokes'][0]['to_position']) \
        == pytest.approx(math.sqrt(0.5 ** 2 - 0.05 ** 2) - math.sqrt(0.3 ** 2 - 0.05 ** 2),
                         abs=1e-14)


def test_geneva_indexes_a_quarter_turn_in_a_quarter_of_the_crank_turn(capsys):
    """Four slots: the wheel indexes 90 deg over 90 deg of crank and is locked for 270 deg."""
    assert main(['check', 'geneva', '--json']) == 0
    (wheel,) = json.loads(capsys.readouterr().out)['intermittent']
    assert wheel['engaged_travel'] == pytest.approx(math.pi / 2, abs=1e-15)
    assert wheel['locked_travel'] == pytest.approx(3 * math.pi / 2, abs=1e-15)
    start, end = wheel['engaged']
    scene = mk.load_scene('geneva')
    before, after = (mk.solve(scene, start - 0.01).joints['wheel'].position,
                     mk.solve(scene, end + 0.01).joints['wheel'].position)
    assert math.remainder(after - before - wheel['index'], 2 * math.pi) == pytest.approx(
        0, abs=1e-14)
    assert abs(wheel['index']) == pytest.approx(math.pi / 2, abs=1e-15)
    assert main(['check', 'geneva']) == 0
    assert ('intermittent: wheel indexes -90 deg while the crank turns CCW from 135 to 225 deg '
            '(90 deg of each turn); locked for the other 270 deg') in capsys.readouterr().out


def test_a_crank_that_cannot_turn_has_no_strokes(capsys):
    """The triple rocker cannot make a whole turn: no strokes, no time ratio."""
    assert main(['check', 'four_bar_coupler_points', '--json']) == 0
    assert json.loads(capsys.readouterr().out)['strokes'] == []


# --- several drivers (issue 18): the assembly region ---------------------------------

OF = math.hypot(400, 1100)  # mm


def write_scene(tmp_path, text):
    """Write YAML ``text`` to a file in ``tmp_path``; return its path as text."""
    path = tmp_path / 'scene.yaml'
    path.write_text(text)
    return str(path)


def test_actuator_region_in_text(tmp_path, capsys):
    """The boom cylinder: its grid, its range from its stroke to the boom in line, its stroke."""
    assert main(['check', write_scene(tmp_path, BOOM_CYLINDER), '--grid', '31']) == 0
    assert capsys.readouterr().out.splitlines() == [
        'boom: 1 driver: cyl (actuator) (angles in deg, CCW from +x; lengths in mm)',
        'grid: cyl over its stroke 2000..5000 mm (31 points): assembles at 58.06% (18 of 31)',
        f'cyl: assembles for 2000..{2600 + OF:.6g} mm (from its stroke limit to RRR Q stops '
        'closing); sampled every 0.833565 mm, ends exact',
        'stroke limits: cyl 2000..5000 mm',
    ]


def test_five_bar_region_in_json_with_a_map(tmp_path, capsys):
    """Two cranks: the grid's counts, each slice in rad, the map's rows (--json --map)."""
    assert main(['check', write_scene(tmp_path, FIVE_BAR_TWO_CRANKS), '--json', '--map',
                 '--grid', '8']) == 0
    data = json.loads(capsys.readouterr().out)
    assert [d['name'] for d in data['drivers']] == ['left', 'right']
    assert data['drivers'][0]['start'] == pytest.approx(math.radians(120), rel=1e-15)
    grid = data['grid']
    assert grid['drivers'] == ['left', 'right'] and grid['points'] == [8, 8]
    assert grid['fraction'] == grid['assembling'] / 64
    left, right = data['slices']
    assert left['at'] == {'right': pytest.approx(math.radians(60), rel=1e-15)}
    assert left['ends'] == [['RRR P', 'RRR P']] and left['everywhere'] is False
    assert left['ranges'][0][0] < 0.0 < left['ranges'][0][1]  # through 0: starts below 0
    # right at 0: |BD|^2 = 0.0628 - 0.0528 cos(left) m^2 exceeds 0.28^2 beyond 107.2 deg
    assert data['map'][-1] == '###...##'
    assert len(data['map']) == 8 and ''.join(data['map']).count('#') == grid['assembling']


def test_map_and_png(tmp_path, capsys):
    """--map draws the grid in text, the first driver rightward; --png writes a picture."""
    png = tmp_path / 'region.png'
    assert main(['check', write_scene(tmp_path, FIVE_BAR_TWO_CRANKS), '--map', '--grid', '4',
                 '--png', str(png)]) == 0
    lines = capsys.readouterr().out.splitlines()
    start = lines.index('map (# assembles, . does not, + partly; left rightward, right '
                        'upward):')
    # Rows from right = 270 deg down to 0; columns left = 0, 90, 180, 270 deg: only
    # left = 180 deg, right = 0 puts B and D further apart (0.34 m) than 0.28 m.
    assert lines[start + 1:] == ['####', '####', '####', '##.#']
    assert png.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'


def test_region_flags_on_a_one_crank_scene_are_refused(capsys):
    """--map (or --grid, --pair, --png) on a scene with one crank: one line, exit 2."""
    assert main(['check', 'four_bar_coupler_points', '--map', '--grid', '10']) == 2
    err = capsys.readouterr().err
    assert err.strip().splitlines() == [
        'error: Expected a scene with several drivers or an actuator for --grid, --map, got '
        'four_bar_coupler_points, driven by one crank: drop --grid, --map']


@pytest.mark.parametrize('grid', ['1', 'x', '2001'])
def test_a_bad_grid_size_is_refused(grid, capsys):
    """--grid takes 2 to 2000 points per driver."""
    with pytest.raises(SystemExit):
        main(['check', 'four_bar_coupler_points', '--grid', grid])
    assert 'expected a whole number of grid points from 2 to 2000' in capsys.readouterr().err


@pytest.mark.parametrize('name', ['five_bar', 'excavator'])
def test_packaged_scenes_with_several_drivers(name, capsys):
    """The packaged five-bar and excavator: their region in text, every grid point counted."""
    assert main(['check', name, '--json', '--grid', '20']) == 0
    data = json.loads(capsys.readouterr().out)
    assert data['grid']['points'] == [20, 20]
    assert all(s['everywhere'] for s in data['slices'])
    if name == 'excavator':
        assert data['grid']['assembling'] == 400
        assert [d['stroke'] for d in data['drivers']] == [[2.0, 3.3], [2.5, 3.9]]
    else:
        assert 0 < data['grid']['assembling'] < 400


# --- forces (issue 32): the turning-moment diagram and the flywheel ---------------------

#: An error estimate as printed: 2 significant digits (its last bits depend on the BLAS).
ERROR = r'\(\+-[0-9.e+-]+\)'


def test_turning_moment_in_text(capsys):
    """The test four-bar with masses: its mean (the drag's 3 N m), extremes, dE, the flywheel."""
    assert main(['check', str(FORCES / 'four_bar_masses.yaml'), '--flywheel', '0.02']) == 0
    lines = capsys.readouterr().out.splitlines()
    head = lines.index('turning moment (crank "crank" turning at -120 rpm; efforts in N m for a '
                       'crank, N for an actuator, each +- its error):')
    patterns = [
        rf'  crank: mean 3 N m {ERROR}, largest 4\.37735 at 85\.1394 deg {ERROR}, least '
        rf'1\.33976 at 333\.235 deg {ERROR}',
        rf'fluctuation of energy \(crank\): 2\.70541 J {ERROR}; energy least at crank 21\.3506 '
        r'deg, most at 202\.86 deg \(2 crossings of the mean\)',
        r'flywheel for Cs = 0\.02 \(Cs = \(w_max - w_min\) / w_mean, w_mean = 12\.5664 rad/s\): '
        rf'I = dE / \(w_mean\^2 Cs\) = 0\.85661 kg m\^2 {ERROR}',
    ]
    assert len(lines) == head + 1 + len(patterns)
    for line, pattern in zip(lines[head + 1:], patterns, strict=True):
        assert re.fullmatch(pattern, line), line


def test_turning_moment_in_json_is_the_study(capsys):
    """--json: "turning_moment" in SI, equal to the study's figures; the flywheel's formula."""
    path = FORCES / 'scotch_yoke_mass.yaml'
    assert main(['check', str(path), '--json', '--flywheel', '0.05']) == 0
    data = json.loads(capsys.readouterr().out)['turning_moment']
    study = turning_moment_from_scene(mk.load_scene(str(path)))
    assert data['crank'] == 'crank' and data['held'] == {} and data['accel'] == 0.0
    assert data['fluctuation'] == study.fluctuation
    assert data['fluctuation_error'] == study.fluctuation_error
    assert data['crossings'] == list(study.crossings)
    effort = data['efforts']['crank']
    assert effort['unit'] == 'N m'
    assert effort['max']['value'] == study.drivers['crank'].maximum.value
    assert effort['max']['angle'] == pytest.approx(math.pi / 4, abs=1e-8)
    w = data['speed']
    assert data['flywheel']['inertia'] == data['fluctuation'] / (w * w * 0.05)
    assert data['flywheel']['inertia'] == pytest.approx(2.0 * 0.05 ** 2 / (2 * 0.05), rel=1e-13)
    assert [round(loop['area'] / data['fluctuation']) for loop in data['loops']] == [1, -1, 1, -1]


def test_several_drivers_turn_the_first_crank_and_hold_the_others(capsys):
    """The five-bar with masses: the region, then each crank's effort, the right one held."""
    assert main(['check', str(FORCES / 'five_bar_masses.yaml')]) == 0
    lines = capsys.readouterr().out.splitlines()
    head = next(i for i, line in enumerate(lines) if line.startswith('turning moment'))
    assert lines[head] == ('turning moment (crank "left_crank" turning at 30 rpm, right_crank '
                           'held at 60 deg; efforts in N m for a crank, N for an actuator, each '
                           '+- its error):')
    assert lines[head + 1].startswith('  left_crank: mean ')
    assert lines[head + 2].startswith('  right_crank: mean 0.195385 N m ')
    assert lines[head + 3].startswith('fluctuation of energy (left_crank): 1.41674 J ')


def test_an_actuator_alone_says_why_it_has_no_turning_moment(capsys):
    """The boom with masses: one line saying there is no crank; JSON says it as "refused"."""
    path = str(FORCES / 'boom_masses.yaml')
    assert main(['check', path, '--grid', '5']) == 0
    assert capsys.readouterr().out.splitlines()[-1] == (
        'turning moment: none (Expected a crank to turn for a turning-moment diagram, got '
        'boom_masses, driven by lift_cyl, none a crank)')
    assert main(['check', path, '--grid', '5', '--json']) == 0
    assert 'none a crank' in json.loads(capsys.readouterr().out)['turning_moment']['refused']


@pytest.mark.parametrize('name', ['khurmi_four_bar_ad150', 'geneva', 'five_bar'])
def test_a_scene_without_forces_prints_nothing_new(name, capsys):
    """No masses, gravity or loads: no turning-moment line, no "turning_moment" key."""
    assert main(['check', name, '--grid', '5'] if name == 'five_bar' else ['check', name]) == 0
    assert 'turning moment' not in capsys.readouterr().out
    assert main(['check', name, '--json'] + (['--grid', '5'] if name == 'five_bar' else [])) == 0
    assert 'turning_moment' not in json.loads(capsys.readouterr().out)


@pytest.mark.parametrize('args, message', [
    (['khurmi_four_bar_ad150', '--flywheel', '0.02'],
     'Expected a scene with masses, gravity or loads for --flywheel, got khurmi_four_bar_ad150 '
     'without'),
    ([str(FORCES / 'five_bar_masses.yaml'), '--flywheel', '0.02', '--grid', '5'],
     'Expected a scene driven by one crank for --flywheel, got five_bar_masses, driven by '
     'left_crank, right_crank'),
    ([str(FORCES / 'boom_masses.yaml'), '--flywheel', '0.02', '--grid', '5'],
     'Expected a scene driven by one crank for --flywheel, got boom_masses, driven by lift_cyl'),
])
def test_a_flywheel_it_cannot_give_is_one_line_and_exit_2(args, message, capsys):
    """--flywheel on a scene without forces or with several drivers: one line, status 2."""
    assert main(['check', *args]) == 2
    captured = capsys.readouterr()
    assert captured.err == f'error: {message}\n' and captured.out == ''


def test_a_crank_at_rest_is_given_its_speed_by_speed_rpm(tmp_path, capsys):
    """--speed-rpm turns the crank for the study: a scene at rest answers as if written so.

    The test four-bar written at 0 rpm (as a URDF's scene is): --flywheel is
    refused with the hint; with --speed-rpm -120 the whole report, text and
    JSON, is the one of the scene written at -120 rpm. Where there is no
    study to give it to, --speed-rpm is refused in one line, never ignored.
    """
    written = FORCES / 'four_bar_masses.yaml'
    data = yaml.safe_load(written.read_text())
    data['input']['speed_rpm'] = 0
    still = tmp_path / 'still.yaml'
    still.write_text(yaml.safe_dump(data))
    assert main(['check', str(still), '--flywheel', '0.02']) == 2
    assert capsys.readouterr().err == (
        'error: Expected crank "crank" turning (a mean speed above 0) for a flywheel, got 0 '
        'rad/s; give the crank a speed with --speed-rpm N\n')
    for extra in ([], ['--json']):
        assert main(['check', str(written), '--flywheel', '0.02', *extra]) == 0
        expected = capsys.readouterr().out
        assert main(['check', str(still), '--flywheel', '0.02', '--speed-rpm', '-120',
                     *extra]) == 0
        assert capsys.readouterr().out == expected
    for args, message in (
            (['khurmi_four_bar_ad150', '--speed-rpm', '10'], 'Expected a scene with masses, '
             'gravity or loads for --speed-rpm, got khurmi_four_bar_ad150 without'),
            ([str(FORCES / 'five_bar_masses.yaml'), '--speed-rpm', '10', '--grid', '5'],
             'Expected a scene driven by one crank for --speed-rpm, got five_bar_masses, driven '
             'by left_crank, right_crank')):
        assert main(['check', *args]) == 2
        assert capsys.readouterr().err == f'error: {message}\n'


def test_a_flywheel_for_a_crank_that_cannot_turn_is_refused(tmp_path, capsys):
    """A crank longer than its rocker cannot turn: --flywheel says where, in one line."""
    data = yaml.safe_load((FORCES / 'four_bar_masses.yaml').read_text())
    data['input']['length'] = 100
    path = tmp_path / 'stuck.yaml'
    path.write_text(yaml.safe_dump(data))
    assert main(['check', str(path), '--flywheel', '0.02']) == 2
    err = capsys.readouterr().err
    assert err.startswith('error: Expected four_bar_masses to turn a whole turn with its forces '
                          'bounded for a turning-moment diagram, got crank "crank" at ')
    assert err.count('\n') == 1
    assert main(['check', str(path)]) == 0       # without --flywheel: said, not refused
    assert capsys.readouterr().out.splitlines()[-1].startswith(
        'turning moment: none (Expected four_bar_masses to turn a whole turn')


@pytest.mark.parametrize('value', ['0', '2', '-0.1', 'abc', 'nan', 'inf'])
def test_a_bad_coefficient_is_refused(value, capsys):
    """--flywheel takes a coefficient above 0 and below 2: argparse's one line, status 2."""
    with pytest.raises(SystemExit) as caught:
        main(['check', str(FORCES / 'engine.yaml'), '--flywheel', value])
    assert caught.value.code == 2
    err = capsys.readouterr().err.splitlines()
    assert err[-1].endswith(f'expected a coefficient of fluctuation of speed (w_max - w_min) / '
                            f'w_mean above 0 and below 2 (e.g. 0.02), got {value!r}')


def test_the_commands_page_shows_what_check_prints():
    """docs/commands.md's turning-moment example is check's output (errors masked)."""
    text = (REPO / 'docs' / 'commands.md').read_text()
    block = text[text.index('$ python -m mech_kinematics check test/data/forces/'):]
    block = block[:block.index('```')].splitlines()
    command = block[0].removeprefix('$ python -m mech_kinematics ').split()
    result = subprocess.run([sys.executable, '-m', 'mech_kinematics', *command],
                            capture_output=True, text=True, check=True, cwd=REPO)
    shown = [line for line in block[1:] if line != '...']
    printed = result.stdout.splitlines()
    tail = printed[-len(shown):]

    def masked(line):
        return re.sub(ERROR, '(+-E)', line)

    assert [masked(line) for line in tail] == [masked(line) for line in shown]
