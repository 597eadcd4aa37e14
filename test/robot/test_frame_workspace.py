# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The workspace of a URDF link frame's origin: ``check ROBOT.urdf --workspace FRAME`` (issue 41).

Gepetto's five-bar (example-parallel-robots, test/data/urdf) and its
``effector``: a frame fixed on a distal link by a fixed joint, off every pin
of the loop. Every value is held against the URDF's own forward kinematics
written apart from the package (``UrdfFk`` in test/helpers.py, read with
xml.etree) at the joints the robot answers: the frame's origin in the root
frame at the grid points, ``det J`` in the loop's plane against central
differences of that kinematics, the drivers' values of the singular points
in the URDF's joints (solved there, the frame is where the map says), and
at every ``det J = 0`` point one leg stretched or folded (its crank and
distal link in line: the five-bar's serial singularity, whatever point of
a distal link is mapped).
"""

from dataclasses import replace
import json
import math
from pathlib import Path

from helpers import gepetto_five_bar_reference, UrdfFk
import numpy as np
import pytest

from mech_kinematics.__main__ import main as cli_main
from mech_kinematics.errors import SceneError
from mech_kinematics.robot import load_robot
from mech_kinematics.robot.targets import frame_workspace

DATA = Path(__file__).resolve().parents[1] / 'data' / 'urdf'
GEPETTO = DATA / 'gepetto_5bar_linkage.urdf'
GEPETTO_LOOP = DATA / 'gepetto_5bar_linkage.robot.yaml'
DOCS = Path(__file__).resolve().parents[2] / 'docs' / 'commands.md'
REFERENCE = gepetto_five_bar_reference()
ROBOT = load_robot(GEPETTO, GEPETTO_LOOP, reference=REFERENCE)
FK = UrdfFk(GEPETTO.read_text(), GEPETTO_LOOP)
WS = frame_workspace(ROBOT, 'effector', 60)
SIZE = float(ROBOT.solve(forces=False).state.error_bound.size)
MOTORS = ('mot1', 'mot2')
#: Central differences' step (rad) for det J.
H = 1e-6


def _solved(q):
    """Return the robot's answer at the motors' values ``q`` (rad)."""
    return ROBOT.solve(dict(zip(MOTORS, map(float, q), strict=True)), max_error=math.inf,
                       forces=False)


def _effector(q):
    """Return the effector's origin in the root frame by the URDF's own kinematics, m."""
    answer = _solved(q)
    values = {n: float(j.position) for n, j in answer.joints.items()}
    return FK.transforms(values)['effector'][:3, 3]


def test_the_grid_is_the_urdfs_own_kinematics():
    """The origin at 40 grid points, and det J in the plane, as UrdfFk gives them."""
    assert WS.drivers == MOTORS and WS.lift is not None
    e, _ = WS.lift
    assert np.allclose(e.T @ e, np.eye(2), atol=1e-15)
    cells = np.argwhere(WS.assembles)
    assert len(cells) > 0.6 * WS.assembles.size
    for i, j in cells[np.random.default_rng(7).choice(len(cells), 40, replace=False)]:
        q = np.array([WS.axes[0][i], WS.axes[1][j]])
        assert np.abs(WS.told(WS.positions[i, j])[0] - _effector(q)).max() <= 1e-12 * SIZE
        columns = [(_effector(q + h) - _effector(q - h)) / (2 * H)
                   for h in (np.array([H, 0.0]), np.array([0.0, H]))]
        det = float(np.linalg.det(e.T @ np.array(columns).T))
        scale = max(float(np.linalg.norm(c)) for c in columns) ** 2
        assert det == pytest.approx(WS.det[i, j], abs=1e-7 * scale)
    # The plane of the loop is the root frame's x = 0.1 m; the effector never leaves it.
    (x0, x1), _, _ = WS.extent
    assert x0 == pytest.approx(0.1, abs=1e-15) and x1 == pytest.approx(0.1, abs=1e-15)
    assert np.abs(WS.told(WS.start)[0] - _effector([0.0, 0.0])).max() <= 1e-12 * SIZE


def test_where_the_drivers_lose_control_a_leg_is_in_line():
    """Each det J = 0 point: the frame there, and a crank in line with its distal link."""
    assert len(WS.inverse_singular) > 50
    told = WS.told(WS.inverse_singular)
    worst = 0.0
    for k in np.random.default_rng(3).choice(len(told), 30, replace=False):
        q = WS.singular_drivers[k]
        assert np.abs(told[k] - _effector(q)).max() <= 1e-12 * SIZE
        points = _solved(q).state.complex_points
        sines = []
        for motor, elbow in (('mot1', 'free1'), ('mot2', 'free2')):
            crank = points[elbow][0] - points[motor][0]
            distal = points['closedloop1_B'][0] - points[elbow][0]
            sines.append(abs((crank.conjugate() * distal).imag) / abs(crank) / abs(distal))
        worst = max(worst, min(sines))
    # Interpolated on 6-degree grid edges: in line within a few hundredths.
    assert worst <= 0.06, worst


def test_check_prints_it_in_the_root_frame_and_refuses_what_it_cannot_map(capsys, tmp_path):
    argv = ['check', str(GEPETTO), '--closures', str(GEPETTO_LOOP), '--units', 'si']
    argv += [f'--reference={n}={v!r}' for n, v in REFERENCE.items() if v]
    png = tmp_path / 'ws.png'
    assert cli_main([*argv, '--workspace', 'effector', '--png', str(png)]) == 0
    out = capsys.readouterr().out
    assert png.stat().st_size > 10_000
    quoted = DOCS.read_text().split('--workspace effector\n', 1)[1].split('```', 1)[0]
    assert out == quoted
    assert cli_main([*argv, '--workspace', 'effector', '--json', '--grid', '36']) == 0
    data = json.loads(capsys.readouterr().out)
    assert data['frame'] == 'root' and data['drivers'] == list(MOTORS)
    assert set(data['extent']) == {'x', 'y', 'z'}
    assert all(len(p) == 3 for p in data['inverse_singular']['positions'])
    assert np.allclose(data['start'], _effector([0.0, 0.0]), rtol=0, atol=1e-12 * SIZE)
    for link, words in (('built', 'which its loops do not move'),
                        ('nowhere', 'which is not one of its links')):
        assert cli_main([*argv, '--workspace', link]) == 2
        err = capsys.readouterr().err
        assert err.count('\n') == 1 and words in err and f"got '{link}'" in err
    with pytest.raises(SceneError, match='two actuated joints'):
        frame_workspace(load_robot(DATA / 'lift_arm.urdf'), 'tool_frame')
    gripper = load_robot(DATA / 'robotiq_2f_85.urdf', DATA / 'robotiq_2f_85.loop_closures.yaml')
    with pytest.raises(SceneError, match=r'two actuated joints .* \(mimic\)'):
        frame_workspace(gripper, 'left_inner_finger')


def test_a_link_frame_is_the_same_found_with_masses_or_when_asked():
    """The lift arm's links (masses: read at load) found again from its scene when asked."""
    planar = load_robot(DATA / 'lift_arm.urdf').planar
    assert planar.links and set(planar.links) == set(planar.planes)
    asked = replace(planar, links={})
    for link, (body, a, b) in planar.links.items():
        again = asked.link_frame(link)
        assert again[0] == body
        assert np.allclose(again[1], a, rtol=0, atol=1e-15)
        assert np.allclose(again[2], b, rtol=0, atol=1e-15)
