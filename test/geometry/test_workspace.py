# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A point's workspace and singular curves (``check --workspace``), and ``check --target``.

The packaged five-bar (cranks AB and ED of 120 mm about A and E, 100 mm
apart; distal links BP and DP of 160 mm) in closed form: P reaches the ring
``40 mm <= |PA| <= 280 mm`` (and the same about E), the drivers lose control
(``det J = 0``) where a leg is stretched or folded (``|PA|`` or ``|PE|`` is
280 or 40 mm: the four circles), and the loop locks where the distal links
are in line (``|BD| = 320 mm``, the edge of where it assembles).
"""

import json
import math
from pathlib import Path

import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.__main__ import main as cli_main
from mech_kinematics.geometry.workspace import workspace_from_scene

DOCS = Path(__file__).resolve().parents[2] / 'docs' / 'commands.md'
FIVE = mk.load_scene('five_bar')
START = mk.solve(FIVE, [d.start for d in FIVE.drivers], [0.0, 0.0], [0.0, 0.0])
A, E, B, P = (np.asarray(START.points[n].position) for n in ('A', 'E', 'B', 'P'))
CRANK = float(np.hypot(*(B - A)))
DISTAL = float(np.hypot(*(P - B)))
GRID = 180
STEP = 2 * math.pi / GRID
WS = workspace_from_scene(FIVE, 'P', GRID)


def test_the_five_bar_is_the_one_described():
    assert (CRANK, DISTAL) == pytest.approx((0.12, 0.16), abs=1e-15)
    assert np.allclose(E - A, [0.1, 0.0], atol=1e-15)


def test_every_position_reached_is_in_both_rings():
    p = WS.positions[WS.assembles]
    for pivot in (A, E):
        r = np.hypot(*(p - pivot).T)
        assert r.min() >= DISTAL - CRANK - 1e-12 and r.max() <= DISTAL + CRANK + 1e-12
    (x0, x1), (y0, y1) = WS.extent
    # The stretched legs along the x axis bound x; the grid reaches them within a step.
    assert E[0] - (CRANK + DISTAL) - 1e-12 <= x0 <= E[0] - (CRANK + DISTAL) + 1e-3
    assert A[0] + CRANK + DISTAL - 1e-3 <= x1 <= A[0] + CRANK + DISTAL + 1e-12


def test_where_the_drivers_lose_control_a_leg_is_stretched_or_folded():
    """Each det J = 0 point on one of the four circles; each circle found."""
    q = WS.inverse_singular
    radii = {(name, r): np.abs(np.hypot(*(q - pivot).T) - r)
             for name, pivot in (('A', A), ('E', E))
             for r in (DISTAL + CRANK, DISTAL - CRANK)}
    nearest = np.min(np.stack(list(radii.values())), axis=0)
    # Solved where det J interpolated along a 2-degree edge is zero: within 1 mm.
    assert nearest.max() <= 1e-3, nearest.max()
    for key, distance in radii.items():
        assert (distance <= 1e-6).sum() >= 10, key
    # Where det J is zero the leg's crank and distal link are in line, by its drivers too.
    for (left, right), p in zip(WS.singular_drivers, q, strict=True):
        b = A + CRANK * np.array([math.cos(left), math.sin(left)])
        d = E + CRANK * np.array([math.cos(right), math.sin(right)])
        assert abs(np.hypot(*(p - b)) - DISTAL) <= 1e-9
        assert abs(np.hypot(*(p - d)) - DISTAL) <= 1e-9


def test_where_the_loop_locks_the_distal_links_are_in_line():
    """At the edge of where it assembles |BD| is within a grid step of 320 mm."""
    assert len(WS.locks) > 0
    for left, right in WS.lock_drivers:
        b = A + CRANK * np.array([math.cos(left), math.sin(left)])
        d = E + CRANK * np.array([math.cos(right), math.sin(right)])
        bd = float(np.hypot(*(d - b)))
        assert 2 * DISTAL - 2 * CRANK * STEP <= bd <= 2 * DISTAL + 1e-12, bd


def test_check_prints_it_and_refuses_what_it_cannot_map(capsys, tmp_path):
    png = tmp_path / 'ws.png'
    assert cli_main(['check', 'five_bar', '--workspace', 'P', '--png', str(png)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith('five_bar: workspace of P over left_crank x right_crank '
                             '(180 x 180 points; assembles at 95.02%')
    assert out[1] == ('P: x from -179.988 mm to 279.988 mm, y from -267.834 mm to 275.497 mm')
    assert out[2].startswith(f'the drivers lose control (det J = 0): '
                             f'{len(WS.inverse_singular)} points')
    assert png.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
    quoted = DOCS.read_text().split('$ python -m mech_kinematics check five_bar --workspace P\n',
                                    1)[1].split('```', 1)[0]
    assert quoted.splitlines() == out, 'docs/commands.md quotes another answer'
    assert cli_main(['check', 'five_bar', '--workspace', 'P', '--json', '--grid', '36']) == 0
    data = json.loads(capsys.readouterr().out)
    small = workspace_from_scene(FIVE, 'P', 36)
    assert data['extent'] == {'x': list(small.extent[0]), 'y': list(small.extent[1])}
    assert data['inverse_singular']['positions'] == small.inverse_singular.tolist()
    for argv, words in ((['check', 'engine', '--workspace', 'P'], 'two drivers'),
                        (['check', 'five_bar', '--workspace', 'Q'], "got 'Q'"),
                        (['check', 'five_bar', '--workspace', 'P', '--map'], 'without --map')):
        assert cli_main(argv) == 2
        err = capsys.readouterr().err
        assert err.startswith('error: ') and words in err and err.count('\n') == 1


def test_check_target_says_how_well_the_drivers_control_the_targets(capsys):
    """At a target: the drivers solve_targets gives, det J, the scaled condition number."""
    inverse = mk.solve_targets(FIVE, {'P.x': 0.06, 'P.y': 0.22})
    assert cli_main(['check', 'five_bar', '--target', 'P.x=60', '--target', 'P.y=220',
                     '--json']) == 0
    data = json.loads(capsys.readouterr().out)
    assert list(data['drivers'].values()) == [float(x) for x in inverse.motion[:, 0]]
    assert data['det_jacobian'] == float(np.linalg.det(inverse.jacobian))
    # Scaled by the five-bar's size (its targets and the cranks' 1 rad): J / size.
    size = inverse.answer.error_bound.size
    sigma = np.linalg.svd(inverse.jacobian / size, compute_uv=False)
    assert data['scaled_singular_values'] == pytest.approx(list(sigma), rel=1e-12)
    assert data['condition'] == pytest.approx(sigma[0] / sigma[1], rel=1e-12)
    assert data['least_singularity']['dyad'] == 'P'
    # Towards a stretched leg (|PA| -> 280 mm, a fold of the map) the smallest singular value
    # goes as the square root of the distance: 10 times closer, sqrt(10) times the condition.
    conditions = []
    for gap in (1e-4, 1e-5):
        far = (CRANK + DISTAL - gap) / math.sqrt(2) * 1000
        assert cli_main(['check', 'five_bar', '--target', f'P.x={far!r}', '--target',
                         f'P.y={far!r}', '--json']) == 0
        conditions.append(json.loads(capsys.readouterr().out)['condition'])
    assert conditions[0] > 20 * data['condition']
    assert conditions[1] / conditions[0] == pytest.approx(math.sqrt(10), rel=0.05)
    assert cli_main(['check', 'five_bar', '--target', 'P.x=60', '--target', 'P.y=220']) == 0
    quoted = DOCS.read_text().split('$ python -m mech_kinematics check five_bar --target P.x=60 '
                                    '--target P.y=220\n', 1)[1].split('```', 1)[0]
    assert quoted == capsys.readouterr().out, 'docs/commands.md quotes another answer'
    assert cli_main(['check', 'five_bar', '--target', 'P.x=60', '--target', 'P.y=420']) == 2
    err = capsys.readouterr().err
    assert err.startswith('error: Expected targets within reach') and err.count('\n') == 1
    assert cli_main(['check', str(Path(__file__).resolve().parents[1] / 'data' / 'urdf' /
                                  'lift_arm.urdf'), '--target', 'tool_frame.z=0.45']) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].endswith('lift_arm.urdf: tool_frame.z = 0.45 m: reached from the start '
                           'pose in 1 step')


def test_plot_draws_the_workspace_check_draws(capsys, tmp_path):
    """``plot --scene five_bar --workspace P``: the picture of check --png, byte for byte."""
    drawn, checked = tmp_path / 'plot.png', tmp_path / 'check.png'
    assert cli_main(['plot', '--scene', 'five_bar', '--workspace', 'P', '-o', str(drawn)]) == 0
    assert capsys.readouterr().out == f'wrote {drawn}\n'
    assert cli_main(['check', 'five_bar', '--workspace', 'P', '--png', str(checked)]) == 0
    assert drawn.read_bytes() == checked.read_bytes()
    # A recording has no map; a name that is no point of the scene is refused, one line each.
    assert cli_main(['plot', str(tmp_path), '--workspace', 'P', '-o', str(drawn)]) == 2
    assert 'Expected --workspace with --scene SCENE alone' in capsys.readouterr().err
    assert cli_main(['plot', '--scene', 'five_bar', '--workspace', 'Q', '-o', str(drawn)]) == 2
    err = capsys.readouterr().err
    assert err == ('error: Expected --workspace to name a point five_bar reports (A, E, B, D, '
                   "P), got 'Q'\n")
