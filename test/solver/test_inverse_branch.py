# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The working mode of an inverse answer: ``--branch JOINT=+1|-1`` (issue 41, item 2).

A five-bar reaches an effector position in four working modes, each leg's
elbow on either side of the line from its motor to the effector. Each leg's
inverse is written here by hand (the crank angle ``phi -+ gamma`` from the
triangle of the motor's pivot, the elbow and the effector, the cosine rule):
for every mode asked, the answer is that closed form's to 1e-11 rad, or,
where that mode puts the effector pin on the other side of the line BD than
the scene's own assembly (its RRR's ``branch: 1``, which a working mode does
not change), it is refused in one line. A URDF robot's mode is read from its
joints' values (Gepetto's five-bar: ``free1``, ``free2``), checked against
the URDF's own kinematics written apart from the package.
"""

from __future__ import annotations

import cmath
import json
import math
from pathlib import Path
import re

from helpers import gepetto_five_bar_reference, UrdfFk
from hypothesis import assume, given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.__main__ import main as cli_main
from mech_kinematics.robot import load_robot
from mech_kinematics.solver import inverse as inverse_module
from mech_kinematics.tools.cli import branch_sign

pytestmark = pytest.mark.filterwarnings('ignore::mech_kinematics.NearSingularWarning')

FIVE = mk.load_scene('five_bar')
START = [d.start for d in FIVE.drivers]
#: The packaged five-bar's ground pivots, cranks and distal links (m): its scene's numbers.
PIVOTS = {'B': 0j, 'D': 0.1 + 0j}
CRANK, DISTAL = 0.12, 0.16
DATA = Path(__file__).resolve().parents[1] / 'data' / 'urdf'
GEPETTO = DATA / 'gepetto_5bar_linkage.urdf'
GEPETTO_LOOP = DATA / 'gepetto_5bar_linkage.robot.yaml'


def _legs(p):
    """Return {elbow: {sign: crank angle}} of each leg reaching ``p`` (None out of reach).

    The elbow's sign is that of (B - A) x (P - B): with ``phi`` the direction
    of P from the pivot and ``gamma`` the angle at the pivot, ``phi + gamma``
    puts B to the left of AP (sign -1) and ``phi - gamma`` to its right (+1).
    """
    out = {}
    for elbow, pivot in PIVOTS.items():
        d = abs(p - pivot)
        c = (CRANK * CRANK + d * d - DISTAL * DISTAL) / (2.0 * CRANK * d)
        if abs(c) >= 1.0 - 1e-6:
            return None
        phi, gamma = cmath.phase(p - pivot), math.acos(c)
        out[elbow] = {-1: phi + gamma, 1: phi - gamma}
    return out


def _side(b, d, p):
    """Return the side of the effector pin P from the line BD: the sign of (P - B) x (P - D)."""
    return math.copysign(1.0, ((p - b).conjugate() * (p - d)).imag)


def _assembly():
    points = mk.solve(FIVE, START, [0.0, 0.0], [0.0, 0.0]).points
    return _side(*(complex(*points[n].position) for n in 'BDP'))


@settings(max_examples=30, deadline=None)
@given(st.floats(-0.15, 0.25), st.floats(0.02, 0.27), st.sampled_from([1, -1]),
       st.sampled_from([1, -1]))
def test_each_working_mode_is_the_legs_closed_form_or_refused(x, y, left, right):
    """Every mode asked: the hand-written leg inverses to 1e-11 rad, or one line refusing it."""
    p = complex(x, y)
    legs = _legs(p)
    assume(legs is not None)
    q = (legs['B'][left], legs['D'][right])
    b = PIVOTS['B'] + CRANK * cmath.exp(1j * q[0])
    d = PIVOTS['D'] + CRANK * cmath.exp(1j * q[1])
    assume(abs(b - d) > 1e-3)       # the distal links' pivots apart: the RRR at P defined
    reachable = _side(b, d, p) == _assembly()
    try:
        inverse = mk.solve_targets(FIVE, {'P.x': x, 'P.y': y}, branch={'B': left, 'D': right})
    except mk.TargetError as error:
        assert not reachable, str(error)
        assert 'working mode asked (B ' in str(error) and '\n' not in str(error)
        return
    assert reachable
    found = inverse.motion[:, 0]
    for got, want in zip(found, q, strict=True):
        assert abs(math.remainder(got - want, math.tau)) <= 1e-11
    assert {k: v['sign'] for k, v in inverse.as_dict()['branch'].items()} == \
        {'B': left, 'D': right}
    p_again = inverse.answer.points['P'].position
    assert np.max(np.abs(p_again - [x, y])) <= 1e-12 * inverse.answer.error_bound.size


def test_the_start_poses_mode_is_answered_when_it_is_the_one_asked():
    """Asking the start pose's own mode changes nothing: the same drivers as without --branch."""
    plain = mk.solve_targets(FIVE, {'P.x': 0.06, 'P.y': 0.22})
    signs = {k: int(math.copysign(1.0, a)) for k, a in
             mk.solve_targets(FIVE, {'P.x': 0.06, 'P.y': 0.22},
                              branch={'B': -1}).branch.items()}
    assert signs == {'B': -1}
    same = mk.solve_targets(FIVE, {'P.x': 0.06, 'P.y': 0.22}, branch={'B': -1, 'D': 1})
    np.testing.assert_array_equal(same.motion[:, 0], plain.motion[:, 0])
    np.testing.assert_array_equal(same.start, plain.start)


@pytest.mark.parametrize(('branch', 'words'), [
    ({'Q': 1}, 'Expected --branch to name joints between two moving bodies (B, D, P), got Q'),
    ({'B': 2}, 'Expected --branch JOINT=+1 or JOINT=-1, got B=2'),
])
def test_a_bad_branch_is_refused_in_one_line(branch, words):
    with pytest.raises(mk.TargetError, match=re.escape(words)):
        mk.solve_targets(FIVE, {'P.x': 0.06, 'P.y': 0.22}, branch=branch)


def test_solve_and_check_take_branch(capsys):
    """The commands: the mode in the JSON; --branch without --target or malformed: one line."""
    assert cli_main(['solve', 'five_bar', '--target', 'P.x=60', '--target', 'P.y=220',
                     '--branch', 'B=+1', '--branch', 'D=+1']) == 0
    out = json.loads(capsys.readouterr().out)
    assert {k: v['sign'] for k, v in out['branch'].items()} == {'B': 1, 'D': 1}
    legs = _legs(complex(0.06, 0.22))
    for name, elbow in (('left_crank', 'B'), ('right_crank', 'D')):
        got = out['inputs'][name]['position']      # rad: the JSON is SI
        assert abs(math.remainder(got - legs[elbow][1], math.tau)) <= 1e-11
    # B +, D -: the effector pin on the other side of BD than the scene's assembly.
    b = CRANK * cmath.exp(1j * legs['B'][1])
    d = PIVOTS['D'] + CRANK * cmath.exp(1j * legs['D'][-1])
    assert _side(b, d, complex(0.06, 0.22)) != _assembly()
    assert cli_main(['solve', 'five_bar', '--target', 'P.x=60', '--target', 'P.y=220',
                     '--branch', 'B=+1', '--branch', 'D=-1']) == 2
    err = capsys.readouterr().err
    assert err.startswith('error: Expected targets reached in the working mode asked (B +, D -)')
    assert err.count('\n') == 1
    # docs/targets.md quotes that line, and the grid's numbers.
    docs = (Path(__file__).resolve().parents[2] / 'docs' / 'targets.md').read_text()
    quoted = next(line for line in docs.splitlines() if 'working mode asked (B +, D -)' in line)
    assert err.startswith(quoted.rstrip('.').rstrip())
    assert f'about {inverse_module._MODE_GRID:,} poses' in ' '.join(docs.split())
    assert f'the first {inverse_module._MODE_TRIES} of them' in ' '.join(docs.split())
    assert cli_main(['solve', 'five_bar', '--branch', 'B=1']) == 2
    err = capsys.readouterr().err.strip()
    assert err == ('error: Expected --branch with --target (a working mode of the inverse), '
                   'got it alone')
    assert cli_main(['check', 'five_bar', '--target', 'P.x=60', '--target', 'P.y=220',
                     '--branch', 'B=1', '--json']) == 0
    report = json.loads(capsys.readouterr().out)
    assert report['drivers']
    # In text, an answer continued from another start pose than the scene's says which.
    assert cli_main(['check', 'five_bar', '--target', 'P.x=60', '--target', 'P.y=220',
                     '--branch', 'B=1', '--branch', 'D=1']) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert 'reached from the nearest start pose in the working mode asked (left_crank = ' in first
    assert cli_main(['check', 'five_bar', '--target', 'P.x=60', '--target', 'P.y=220']) == 0
    assert 'reached from the start pose in ' in capsys.readouterr().out.splitlines()[0]
    assert [branch_sign(text) for text in ('D=+', 'D=-', 'D=1', 'D=-1')] == \
        [('D', 1), ('D', -1), ('D', 1), ('D', -1)]
    assert 'solve five_bar --target P.x=60 --target P.y=220 --branch B=+1 --branch D=+1' in docs
    with pytest.raises(SystemExit):
        cli_main(['solve', 'five_bar', '--target', 'P.x=60', '--target', 'P.y=220',
                  '--branch', 'B=up'])
    assert 'expected JOINT=+1 or JOINT=-1' in capsys.readouterr().err


def test_a_urdf_robots_mode_is_read_from_its_joints_values():
    """Gepetto's five-bar: each leg's free joint's sign asked, the effector where asked."""
    robot = load_robot(GEPETTO, GEPETTO_LOOP, None, gepetto_five_bar_reference())
    fk = UrdfFk(GEPETTO.read_text(), GEPETTO_LOOP)
    zero = robot.solve(forces=False)
    p0 = fk.transforms({n: float(j.position) for n, j in zero.joints.items()})['effector'][:3, 3]
    goal = {'effector.y': float(p0[1]) + 0.02, 'effector.z': float(p0[2]) + 0.03}
    plain = robot.solve_targets(goal)
    modes = set()
    for name in ('free1', 'free2'):
        for sign in (1, -1):
            inverse = robot.solve_targets(goal, branch={name: sign})
            joints = inverse.answer.joints
            assert math.copysign(1.0, float(joints[name].position)) == sign
            p = fk.transforms({n: float(j.position) for n, j in joints.items()})['effector']
            np.testing.assert_allclose(p[1:3, 3], [goal['effector.y'], goal['effector.z']],
                                       rtol=0, atol=1e-12 * zero.state.error_bound.size)
            modes.add(tuple(np.round(inverse.motion[:, 0], 9)))
    # The reference pose's own mode and one leg flipped each way: three assemblies.
    assert tuple(np.round(plain.motion[:, 0], 9)) in modes
    assert len(modes) == 3
    # The joint closing the loop between two links the scene welds is always 0: not a mode.
    with pytest.raises(mk.TargetError,
                       match=r'\(free1, closedloop1_B, free2\), got closedloop1_A'):
        robot.solve_targets(goal, branch={'closedloop1_A': 1})
