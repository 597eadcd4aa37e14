# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Loads that depend on position (issue 44 item 6): a force given as a table over a joint.

A press on a slider-crank (the engine's geometry, no masses), its force a
table over the crank angle or over the slider's position; the values are held
to what does not come from the forces' code:

- power balance at every angle of a turn: the crank's effort times its speed
  plus the load's power (its force at the table's value times the piston's
  velocity, both from the kinematics) is 0;
- the turning-moment diagram's mean effort over a turn is the load's work over
  the turn (the force times the piston's travel while it acts, from the
  kinematics) over 2 pi, so that the flywheel sizes a press;
- one instant and an array give the same bits; the table's rows are met
  exactly and it is linear between them, a jump where two rows share a
  position; refusals name the key.
"""

import math

import numpy as np
import pytest
import yaml

import mech_kinematics as mk
from mech_kinematics.geometry.turning import turning_moment_from_scene
from mech_kinematics.solver.forces import Load

PRESS = {
    'name': 'press',
    'units': {'length': 'mm', 'angle': 'deg'},
    'ground': {'O': [0, 0]},
    'input': {'link': 'crank', 'center': 'O', 'point': 'C', 'length': 75, 'angle': 30,
              'speed_rpm': 60, 'accel': 0},
    'dyads': [{'type': 'RRP', 'point': 'P', 'link': {'name': 'rod', 'from': 'C', 'length': 225},
               'guide': {'through': 'O', 'angle': 90}, 'slider': 'piston', 'branch': 1}],
}
F = 5000.0


def _press(tmp_path, table):
    data = {**PRESS, 'loads': [{'name': 'press', 'point': 'P', 'table': table}]}
    path = tmp_path / 'press.yaml'
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return mk.load_scene(str(path))


def _acting(theta, low_deg, high_deg):
    """Where the press acts: crank angles in [low, high), as the table's jumps say."""
    return (theta >= math.radians(low_deg)) & (theta < math.radians(high_deg))


def test_a_working_stroke_over_the_crank_angle_balances_power_at_every_angle(tmp_path):
    """Power balances at 3600 angles (no masses): effort * omega + F . v_P = 0, F the table's."""
    rows = [[90, 0, 0], [90, 0, F], [200, 0, F], [200, 0, 0]]
    scene = _press(tmp_path, {'joint': 'crank', 'rows': rows})
    theta = np.linspace(0.0, 2 * math.pi, 3601)[:-1]
    state = mk.solve(scene, theta, max_error=math.inf)
    effort = state.forces.efforts['crank']
    force = np.where(_acting(theta, 90, 200), F, 0.0)
    power = force * state.complex_points['P'][1].imag
    # Within an ulp of a jump the two sides are both the table's (the crank's angle and the
    # row's position are each a rounding of the same degrees): those instants are left out.
    edge = np.min(np.abs(theta[:, None] - np.radians([90.0, 200.0])), axis=1) < 1e-12
    assert np.count_nonzero(edge) <= 2
    balance = np.abs(effort * scene.input.speed + power)[~edge]
    assert np.max(balance) <= 1e-9 * F * 0.075
    for index in range(0, theta.size, 97):      # one instant: the array's bits
        one = mk.solve(scene, float(theta[index]), max_error=math.inf)
        assert one.forces.efforts['crank'] == effort[index]


def test_the_mean_turning_moment_is_the_loads_work_over_a_turn(tmp_path):
    """The diagram of check: mean effort = -(F x the piston's rise while it acts) / 2 pi."""
    rows = [[90, 0, 0], [90, 0, F], [200, 0, F], [200, 0, 0]]
    scene = _press(tmp_path, {'joint': 'crank', 'rows': rows})
    study = turning_moment_from_scene(scene, samples=7200)
    rise = [mk.solve(scene, math.radians(d)).complex_points['P'][0].imag for d in (90, 200)]
    work = F * (rise[1] - rise[0])      # the press pushes up while the piston comes down
    assert work < 0.0
    mean = study.drivers['crank'].mean
    assert mean == pytest.approx(-work / (2 * math.pi), rel=1e-3)
    assert study.fluctuation > 0.0 and study.flywheel(0.05).inertia > 0.0


def test_a_table_over_the_sliders_position_in_the_scenes_unit(tmp_path):
    """Rows over the piston's position in mm: linear between them, clamped past the ends."""
    scene = _press(tmp_path, {'joint': 'piston', 'rows': [[180, 0, 0], [260, 0, -F]]})
    [load] = scene.loads
    assert load.table[1][0][0] == pytest.approx(0.18) and not load.periodic
    for angle in (0.3, 1.2, 1.57, 2.0, 4.0):
        state = mk.solve(scene, angle, max_error=math.inf)
        y = state.joints['piston'].position
        force = -F * min(1.0, max(0.0, (y - 0.18) / 0.08))
        power = force * state.complex_points['P'][1].imag
        assert state.forces.efforts['crank'] * scene.input.speed + power == pytest.approx(
            0.0, abs=1e-9 * F)


def test_the_table_is_met_at_its_rows_and_linear_between_them():
    """force_at: each row exactly; midway the mean; a jump; a turn's wrap; the slope."""
    rows = ((0.0, 0.0, 0.0), (1.0, 10.0, -4.0), (1.0, 20.0, 0.0), (3.0, 0.0, 0.0))
    load = Load('l', point='P', table=('piston', rows))
    assert [load.force_at(x)[0] for x in (0.0, 0.5, 0.999999, 1.0, 2.0, 3.0, 9.0)] == [
        0j, 5 - 2j, pytest.approx(10 - 4j, abs=1e-4), 20 + 0j, 10 + 0j, 0j, 0j]
    assert load.force_at(0.5)[1] == pytest.approx(math.hypot(10, 4))
    forces, _ = load.force_at(np.array([0.0, 0.5, 2.0]))
    assert list(forces) == [0j, 5 - 2j, 10 + 0j]
    turning = Load('t', point='P', table=('crank', ((0.0, 0.0, 0.0), (math.pi, 10.0, 0.0))),
                   periodic=True)
    assert turning.force_at(1.5 * math.pi)[0] == pytest.approx(5 + 0j)   # back to the first
    assert turning.force_at(-0.5 * math.pi)[0] == pytest.approx(5 + 0j)  # a turn on


@pytest.mark.parametrize('table, words', [
    ({'joint': 'crank', 'rows': [[10, 0, 0]]}, 'expected at least two rows'),
    ({'joint': 'crank', 'rows': [[10, 0, 0], [5, 0, 1]]}, 'in order, at most two rows'),
    ({'joint': 'crank', 'rows': [[10, 0, 0], [10, 0, 1], [10, 0, 2]]},
     'in order, at most two rows'),
    ({'joint': 'crank', 'rows': [[0, 0, 0], [400, 0, 1]]}, 'within one turn'),
    ({'joint': 'wheel', 'rows': [[0, 0, 0], [10, 0, 1]]}, 'over a joint of the scene'),
    ({'joint': 'crank', 'rows': [[0, 0], [10, 0, 1]]}, 'expected [position, fx, fy]'),
    ({'joint': 'crank', 'rows': [[0, 0, '.nan'], [10, 0, 1]]}, 'expected a number'),
    ({'rows': [[0, 0, 0], [10, 0, 1]]}, 'missing required key'),
])
def test_a_bad_table_is_refused_naming_the_load(tmp_path, table, words):
    """One line naming the load's key (loads[0] or loads[0].table...)."""
    with pytest.raises(mk.SceneError) as error:
        _press(tmp_path, table)
    message = str(error.value)
    assert words in message and 'loads[0]' in message and '\n' not in message, message


def test_a_table_and_a_force_together_are_refused(tmp_path):
    """A load is a force, a table or a torque: one of them."""
    data = {**PRESS, 'loads': [{'name': 'press', 'point': 'P', 'force': [0, 1],
                                'table': {'joint': 'crank', 'rows': [[0, 0, 0], [10, 0, 1]]}}]}
    path = tmp_path / 'both.yaml'
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(mk.SceneError, match='loads'):
        mk.load_scene(str(path))
