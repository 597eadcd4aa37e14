# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Every command fails with one line and a non-zero status, never a traceback (issue 12)."""

import argparse
import math
from pathlib import Path
import subprocess
import sys

import pytest

from mech_kinematics.tools.cli import (BROKEN_PIPE_STATUS, positive_float, positive_seconds,
                                       seconds_or_zero)

TIMEOUT = 120


def run(*args: str, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mech_kinematics', *args], text=True,
                          capture_output=True, timeout=TIMEOUT, **kwargs)


def in_process(capsys, *args: str) -> subprocess.CompletedProcess:
    """Run ``python -m mech_kinematics ARGS`` as its ``main`` in this process: status, output.

    For the questions after each command's one end-to-end call (``run``): an
    argparse refusal's SystemExit is its status.
    """
    from mech_kinematics.__main__ import main

    try:
        status = main(list(args))
    except SystemExit as exit_:
        status = exit_.code
    out, err = capsys.readouterr()
    return subprocess.CompletedProcess(list(args), status, out, err)


#: One failing call per command, each run end to end (a subprocess).
FAILING = [
    (['solve', 'no_such_scene'], ['no_such_scene', 'packaged scene name']),
    (['diagram', 'no_such_scene', '-o', 'x.png'], ['no_such_scene']),
    (['plot', '--scene', 'no_such_scene', '-o', 'x.png'], ['no_such_scene']),
    (['reindex', '/no/such/bag'], ['/no/such/bag', 'does not exist']),
    (['record', '-o', '/proc/no/bag', '--duration', '1'], ['/proc/no/bag']),
    (['report', '-o', '/proc/no/report', '--smoke', '--no-progress'], ['/proc/no']),
    (['solve', '/dev/null'], ['/dev/null']),
]


@pytest.mark.parametrize('args, words', FAILING)
def test_a_failing_command_says_one_line(tmp_path, capsys, monkeypatch, args, words):
    """A missing scene, bag or output folder: one `error:` line naming it, status 2.

    The first call of each command runs in a subprocess; a command's further
    calls (solve's second) in this process, as its ``main``.
    """
    if [a for a, _ in FAILING].index(args) == [a[0] for a, _ in FAILING].index(args[0]):
        result = run(*args, cwd=tmp_path)
    else:
        monkeypatch.chdir(tmp_path)
        result = in_process(capsys, *args)
    assert result.returncode == 2, result.stderr
    assert 'Traceback' not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith('error: '), result.stderr
    for word in words:
        assert word in lines[0]


def test_a_negative_number_in_exponent_form_is_a_value(capsys):
    """`--speed-rpm -1e3` and `--angle-deg -.5e1` are numbers, not options (issue 12)."""
    result = in_process(capsys, 'solve', 'khurmi_four_bar_ad150', '--speed-rpm', '-1e3',
                        '--angle-deg', '-.5e1', '--indent', '0')
    assert result.returncode == 0, result.stderr
    assert '"speed": -104.7197551196597' in result.stdout


def test_a_closed_pipe_ends_the_command_quietly():
    """`solve ... | head -1` exits without a word on stderr (the README's own example)."""
    proc = subprocess.Popen([sys.executable, '-m', 'mech_kinematics', 'solve', 'whitworth',
                             '--indent', '4'], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    proc.stdout.readline()
    proc.stdout.close()          # as `head -1` does after its line
    status = proc.wait(timeout=TIMEOUT)
    stderr = proc.stderr.read()
    proc.stderr.close()
    assert stderr == '', stderr
    assert status in (0, BROKEN_PIPE_STATUS)


@pytest.mark.parametrize('parse, text, value', [
    (positive_float, '1e-9', 1e-9), (positive_float, 'inf', math.inf),
    (positive_seconds, '0.5', 0.5), (seconds_or_zero, '0', 0.0), (seconds_or_zero, '2', 2.0),
])
def test_number_types_accept(parse, text, value):
    """The shared argparse number types return the number given."""
    assert parse(text) == value


@pytest.mark.parametrize('parse, text, message', [
    (positive_float, '0', "expected a positive number, got '0'"),
    (positive_float, 'nan', "expected a positive number, got 'nan'"),
    (positive_float, 'tight', "expected a positive number, got 'tight'"),
    (positive_seconds, 'inf', "expected a positive number of seconds, got 'inf'"),
    (positive_seconds, '-1', "expected a positive number of seconds, got '-1'"),
    (seconds_or_zero, '-0.1', "expected a number of seconds >= 0, got '-0.1'"),
    (seconds_or_zero, 'soon', "expected a number of seconds >= 0, got 'soon'"),
])
def test_number_types_refuse_with_one_reason(parse, text, message):
    """A refused number names what was expected and what was given."""
    with pytest.raises(argparse.ArgumentTypeError) as caught:
        parse(text)
    assert str(caught.value) == message


@pytest.mark.parametrize('argv, words', [
    (['solve', 'geneva', '--max-error', '0'],
     ["--max-error: expected a positive number, got '0'"]),
    (['record', '-o', 'x', '--duration', '0'],
     ["--duration: expected a positive number of seconds, got '0'"]),
    (['record', '-o', 'x', '--progress', '-1'],
     ["--progress: expected a number of seconds >= 0, got '-1'"]),
    (['record', '-o', 'x', '--max-queue-bytes', '0'],
     ["--max-queue-bytes: expected a positive integer, got '0'"]),
    (['record', '-o', 'x', '--max-queue-bytes', '1e6'],
     ["--max-queue-bytes: expected a positive integer, got '1e6'"]),
])
def test_solve_and_record_use_the_shared_number_types(capsys, argv, words):
    """The number options of solve and record refuse with the shared types' reasons.

    In this process (``main``): each command's end-to-end call is above.
    """
    result = in_process(capsys, *argv)
    assert result.returncode == 2
    for word in words:
        assert word in result.stderr


def _handler_raising(error: BaseException):
    import argparse

    def handler(args):
        raise error

    return argparse.Namespace(handler=handler)


def test_running_out_of_memory_is_one_line_saying_what_to_do(capsys):
    """``--indent 10000000`` said "unexpected MemoryError:" and nothing else (issue 21)."""
    from mech_kinematics.tools.cli import run_handler

    assert run_handler(_handler_raising(MemoryError())) == 2
    err = capsys.readouterr().err
    assert err == ('error: Expected a request that fits in memory, got one that does not; ask '
                   'for less (fewer samples, a smaller indent or scene)\n')


@pytest.mark.parametrize('error, line', [
    (ValueError(''), 'error: unexpected ValueError (set MECH_KINEMATICS_TRACEBACK=1 for the '
                     'traceback)\n'),
    (RuntimeError('first\nsecond\n'), 'error: unexpected RuntimeError: first second (set '
                                      'MECH_KINEMATICS_TRACEBACK=1 for the traceback)\n'),
])
def test_an_unexpected_error_is_one_nonempty_line(capsys, monkeypatch, error, line):
    """An exception with no text or with several lines still makes exactly one full line."""
    from mech_kinematics.tools.cli import run_handler

    monkeypatch.delenv('MECH_KINEMATICS_TRACEBACK', raising=False)
    assert run_handler(_handler_raising(error)) == 1
    assert capsys.readouterr().err == line


# --- --units si: the values of --input, --speed and --reference in rad, rad/s and m --------

def _json(capsys, *args: str) -> dict:
    import json

    result = in_process(capsys, *args)
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


@pytest.mark.parametrize('scene, driver', [('khurmi_four_bar_ad150', 'crank'),
                                           ('five_bar', 'left_crank')])
def test_units_si_takes_a_scenes_angles_in_rad_and_speeds_in_rad_per_s(capsys, scene, driver):
    """``--units si --input C=RAD --speed C=RAD/S`` is ``--input C=DEG --speed C=RPM``, to the bit.

    The radians are the double the degrees become (``radians_from_degrees``);
    ``--angle-deg`` stays degrees with ``--units si``; a reduction beyond a turn is
    exact both ways (450 deg and 5 pi / 2 rad: the same quarter turn into turn 1).
    """
    from mech_kinematics.units import rad_per_s_from_rpm, radians_from_degrees

    rad, rad_per_s = repr(radians_from_degrees(30.0)), repr(rad_per_s_from_rpm(60.0))
    degrees = _json(capsys, 'solve', scene, '--input', f'{driver}=30', '--speed', f'{driver}=60')
    si = _json(capsys, 'solve', scene, '--units', 'si', '--input', f'{driver}={rad}',
               '--speed', f'{driver}={rad_per_s}')
    assert si == degrees
    if scene == 'khurmi_four_bar_ad150':
        assert _json(capsys, 'solve', scene, '--units', 'si', '--angle-deg', '30',
                     '--speed', f'crank={rad_per_s}') == degrees
        quarter = _json(capsys, 'solve', scene, '--units', 'si', '--input',
                        f'crank={5 * math.pi / 2!r}')
        assert quarter['input']['angle'] == pytest.approx(5 * math.pi / 2, abs=1e-15)
        assert math.isclose(quarter['joints']['rocker']['position'],
                            _json(capsys, 'solve', scene, '--input',
                                  'crank=450')['joints']['rocker']['position'], abs_tol=1e-14)


def test_units_si_takes_an_actuators_length_in_m_whatever_the_scenes_unit():
    """In a scene written in mm, ``--units si --input A=1.5`` is ``--input A=1500``: 1.5 m."""
    from types import SimpleNamespace

    import mech_kinematics as mk
    from mech_kinematics.tools.cli import drive_from_args

    boom = mk.load_scene('boom')
    in_mm = SimpleNamespace(drivers=boom.drivers, input=None,
                            units=SimpleNamespace(length='mm'))
    args = dict(angle_deg=None, speed_rpm=None, accel=None, speed=[('lift_cyl', 0.25)])
    mm = drive_from_args(in_mm, argparse.Namespace(**args, input=[('lift_cyl', 1500.0)]))
    si = drive_from_args(in_mm, argparse.Namespace(**args, input=[('lift_cyl', 1.5)], units='si'))
    assert mm[:4] == si[:4] == (1.5, 0.25, None, 0)
    assert (mm[4], si[4]) == ('lift_cyl = 1500 mm', 'lift_cyl = 1.5 m')


def test_units_si_takes_a_robots_joints_and_reference_in_rad(capsys):
    """A URDF's ``--input``, ``--speed`` and ``--reference`` in rad and rad/s: the same answer.

    ``solve`` on the lift arm (its efforts included), and ``urdf2scene``'s
    scene from a reference pose, which only ``--reference`` feeds; a bad
    ``--units`` is argparse's one line.
    """
    from mech_kinematics.units import rad_per_s_from_rpm

    urdf = str(Path(__file__).resolve().parents[1] / 'data' / 'urdf' / 'lift_arm.urdf')
    rad, rad_per_s = repr(math.radians(30.0)), repr(rad_per_s_from_rpm(60.0))
    degrees = _json(capsys, 'solve', urdf, '--input', 'lift_joint=30', '--speed', 'lift_joint=60')
    si = _json(capsys, 'solve', urdf, '--units', 'si', '--input', f'lift_joint={rad}',
               '--speed', f'lift_joint={rad_per_s}')
    assert si == degrees and si['efforts']
    pose = {name: joint['position'] for name, joint in degrees['joints'].items()}
    by_degrees = in_process(capsys, 'urdf2scene', urdf, *(
        f'--reference={name}={math.degrees(value)!r}' for name, value in pose.items()))
    by_rad = in_process(capsys, 'urdf2scene', urdf, '--units', 'si', *(
        f'--reference={name}={value!r}' for name, value in pose.items()))
    assert by_degrees.returncode == by_rad.returncode == 0, (by_degrees.stderr, by_rad.stderr)
    assert by_degrees.stdout == by_rad.stdout and 'angle' in by_rad.stdout
    refused = in_process(capsys, 'solve', urdf, '--units', 'grad')
    assert refused.returncode == 2 and "invalid choice: 'grad'" in refused.stderr
