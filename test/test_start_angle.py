# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Start angles far out (issue 21, item 2): read exactly as whole turns plus an angle.

A scene whose crank starts at 1e308 deg used to be refused as a toggle, and a
Geneva wheel started at 1e17 deg blamed its pin for being on its pivot, while
``solve --angle-deg`` answered both. The scene reader now splits the angle
into whole turns and an angle within a turn, exactly, and the turns go with
the crank (``Crank.turns``) into the scene's check, ``solve``'s default, the
node's time base and ``check``.
"""

from __future__ import annotations

from fractions import Fraction
import json
import math
import os
from pathlib import Path
import subprocess
import sys

import mpmath
import pytest

import mech_kinematics as mk
from mech_kinematics.__main__ import main
from mech_kinematics.ros.timebase import CrankTimebase
from mech_kinematics.units import reduce_radians, turns_from_degrees

ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT / 'config' / 'scenes'
TIMEOUT = 60
#: 1e17 deg = 360 * 277777777777778 - 80 deg: the crank at -80 deg after that many turns.
GENEVA_TURNS = 277777777777778


def _scene(tmp_path: Path, name: str, angle: str, unit: str = 'deg') -> Path:
    """Write the packaged scene ``name`` with its crank starting at ``angle`` (text)."""
    lines = []
    for line in (SCENES / f'{name}.yaml').read_text().splitlines():
        if line.startswith('  angle:'):
            line = f'  angle: {angle}'
        if line.startswith('units:') and unit == 'rad':
            line = line.replace('angle: deg', 'angle: rad')
        lines.append(line)
    path = tmp_path / f'{name}_{unit}.yaml'
    path.write_text('\n'.join(lines) + '\n')
    return path


def _command(*args: object) -> dict:
    """Return the JSON that `python -m mech_kinematics ARGS` prints, run in a subprocess."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    result = subprocess.run([sys.executable, '-m', 'mech_kinematics', *map(str, args)],
                            cwd=ROOT, env=env, capture_output=True, text=True,
                            timeout=TIMEOUT, check=False)
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


def _in_process(capsys: pytest.CaptureFixture[str], *args: object) -> dict:
    """Return the JSON that the same command prints, called here (its ``main``)."""
    capsys.readouterr()
    status = main([str(arg) for arg in args])
    out, err = capsys.readouterr()
    assert status == 0, err
    return json.loads(out)


@pytest.mark.parametrize('name, degrees', [('khurmi_four_bar_ad150', 1e308),
                                           ('geneva', 1e17), ('geneva', -1e300)])
def test_a_scene_started_far_out_answers_what_solve_angle_deg_answers(tmp_path, capsys, name,
                                                                      degrees):
    """The scene loads, and `solve SCENE` prints what `solve --angle-deg X` prints.

    `solve SCENE` runs as a command; `solve --angle-deg` is called in this process.
    """
    path = _scene(tmp_path, name, repr(degrees))
    scene = mk.load_scene(path)
    angle, turns = turns_from_degrees(degrees)
    assert (scene.input.angle, scene.input.turns) == (angle, turns)
    assert Fraction(degrees) == 360 * turns + Fraction(math.remainder(degrees, 360.0))
    assert _command('solve', path) == _in_process(capsys, 'solve', SCENES / f'{name}.yaml',
                                                  '--angle-deg', repr(degrees))


def test_a_geneva_wheel_started_far_out_has_its_index_right(tmp_path):
    """1e17 deg is -80 deg after 277777777777778 turns: 2 turns mod the wheel's 4 slots."""
    scene = mk.load_scene(_scene(tmp_path, 'geneva', '1e17'))
    assert scene.input.turns == GENEVA_TURNS and GENEVA_TURNS % 4 == 2
    assert scene.input.angle == math.radians(-80.0)
    # The same crank position two turns in (640 deg): the wheel held at the same index.
    near = mk.solve(mk.load_scene('geneva'), math.radians(640.0 - 720.0), turns=2)
    far = mk.solve(scene, scene.input.angle, turns=scene.input.turns)
    assert far.joints['wheel'].position == near.joints['wheel'].position
    assert far.joints['wheel'].velocity == 0.0
    assert int(far.intermittent['wheel'].window) == GENEVA_TURNS - 1


def test_a_geneva_wheel_started_far_out_in_radians(tmp_path):
    """1e17 rad: reduced with 2 pi to 400 digits; the index from the exact whole turns."""
    scene = mk.load_scene(_scene(tmp_path, 'geneva', '1e17', unit='rad'))
    mpmath.mp.dps = 60
    turns = int(mpmath.nint(mpmath.mpf(1e17) / (2 * mpmath.pi)))
    rest = float(mpmath.mpf(1e17) - 2 * mpmath.pi * turns)
    mpmath.mp.dps = 15
    assert (scene.input.angle, scene.input.turns) == (rest, turns)
    assert reduce_radians(1e17) == (rest, turns)
    far = mk.solve(scene, scene.input.angle, turns=scene.input.turns)
    near = mk.solve(scene, rest, turns=turns % 4)
    assert far.joints['wheel'].position == near.joints['wheel'].position
    assert far.joints['wheel'].velocity == near.joints['wheel'].velocity


@pytest.mark.parametrize('angle', [1e308, -1e308, 1e22, 7.0, math.pi + 1e-15])
def test_reduce_radians_is_exact(angle):
    """``angle = rest + 2 pi turns`` with the float taken as exact, ``rest`` correctly rounded."""
    rest, turns = reduce_radians(angle)
    mpmath.mp.dps = 400
    try:
        exact = mpmath.mpf(angle) - 2 * mpmath.pi * turns
        assert rest == float(exact)
        assert abs(exact) <= mpmath.pi
    finally:
        mpmath.mp.dps = 15


def test_an_angle_within_a_turn_is_read_as_before(tmp_path):
    """Scenes within a turn keep their angle and no turns (225 deg stays 225 deg)."""
    for name in ('whitworth', 'geneva'):
        scene = mk.load_scene(name)
        assert scene.input.turns == 0
    assert mk.load_scene('whitworth').input.angle == math.radians(225.0)
    scene = mk.load_scene(_scene(tmp_path, 'geneva', '450'))
    assert (scene.input.angle, scene.input.turns) == (math.radians(90.0), 1)


def test_a_crank_turns_must_be_an_int():
    """``Crank.turns`` is a whole number."""
    with pytest.raises(mk.SceneError, match=r'whole turns to be an int, got 1\.5'):
        mk.Crank('crank', 'A', 'B', 1.0, turns=1.5)
    with pytest.raises(mk.SceneError, match='got True'):
        mk.Crank('crank', 'A', 'B', 1.0, turns=True)


def test_the_time_base_starts_at_the_whole_turns():
    """``CrankTimebase(..., turns=k)`` starts ``k`` whole turns on, exactly."""
    turns, sample = CrankTimebase(0, -1.0, 0.0, 0.0, 0.0, turns=GENEVA_TURNS).sample_turns(10)
    assert (turns, sample.angle) == (GENEVA_TURNS, -1.0)


def test_check_answers_a_scene_started_far_out(tmp_path, capsys):
    """`check` reports the scene started at 1e17 deg as it does the packaged one.

    `check` runs as a command on the scene started far out, in this process on the other.
    """
    far = _command('check', '--json', _scene(tmp_path, 'geneva', '1e17'))
    assert far == _in_process(capsys, 'check', '--json', SCENES / 'geneva.yaml')
