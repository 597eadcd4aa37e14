# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The turning-moment diagram, the fluctuation of energy and the flywheel (issue 32).

Checked against computations that share nothing with the study's quadrature
and root finding:

- closed forms: a Scotch yoke's reciprocating mass (``T = m r^2 w^2 sin(2
  theta) / 2``) and a Geneva wheel's inertia (its largest kinetic energy);
- the energy: at constant crank speed the crank's effort is the rate of the
  mechanism's kinetic and potential energy with the angle, less the torque
  loads on the crank, so ``E(theta)`` is that energy and ``dE`` its swing over
  the turn, computed here from the kinematics alone (the scene solved without
  its masses) on a fine grid;
- a fine trapezoid sum of the effort (error O(h^2), h stated);
- the solver itself at the study's angles (the diagram's values are its).
"""

from __future__ import annotations

from dataclasses import replace
import math

from helpers import FORCES, forces_scene
import numpy as np
import pytest
import yaml

import mech_kinematics as mk
from mech_kinematics.geometry.turning import (QUADRATURE_TOLERANCE, turning_crank,
                                              turning_moment_from_scene)
from mech_kinematics.units import rad_per_s_from_rpm

pytestmark = pytest.mark.filterwarnings('ignore::mech_kinematics.NearSingularWarning')

#: Grid of the energy's own extremes: 2^17 + 1 angles over the turn, h = 4.8e-5 rad; each
#: extreme refined to the vertex of the parabola through it and its neighbours, whose
#: error O(h^3 T'') is below this fraction of dE in these scenes.
ENERGY_SAMPLES = 2 ** 17 + 1
RTOL_ENERGY = 1e-12
#: The study's error estimates are at most this fraction of the values they qualify.
RTOL_ESTIMATE = 1e-11
#: Extremes of E are crossings of the mean: their places agree within this, rad (E is
#: flat there: the grid's vertex places it to about sqrt(rounding / E'') ~ 1e-8 rad).
ATOL_PLACE = 1e-6

YOKE_MASS, YOKE_R = 2.0, 0.05                       # kg, m
GENEVA_INERTIA, GENEVA_SPEED = 0.002, 10.0          # kg m^2, rad/s


@pytest.fixture(scope='module')
def studies():
    """Return the study of every test scene with a crank, by name (each is costly)."""
    names = ('four_bar_masses', 'scotch_yoke_mass', 'geneva_wheel', 'engine', 'five_bar_masses')
    return {name: turning_moment_from_scene(forces_scene(name)) for name in names}


def turn_arguments(scene, crank, angles, speed):
    """Return ``solve``'s drivers for the turning ``crank`` at ``angles``, the others held."""
    drivers = scene.drivers
    if len(drivers) == 1:
        return angles, speed, 0.0
    n = np.shape(angles)
    positions = [angles if d.name == crank else np.full(n, d.start) for d in drivers]
    speeds = [np.full(n, speed if d.name == crank else 0.0) for d in drivers]
    return positions, speeds, [np.zeros(n) for _ in drivers]


def energy(scene, angles):
    """Return the kinetic plus potential energy (J) over crank ``angles``, from kinematics alone.

    The potential of gravity, of the constant point loads and of the torque
    loads on bodies other than the turning crank (whose work the mean
    absorbs), the angles of those bodies unwrapped over the turn.
    """
    crank = turning_crank(scene)
    speed = next(d.speed for d in scene.drivers if d.name == crank)
    bare = replace(scene, masses=(), loads=(), gravity=None)
    state = mk.solve(bare, *turn_arguments(bare, crank, angles, speed), max_error=math.inf)
    assert np.all(state.valid)
    graph = scene.graph
    g = complex(*scene.gravity) if scene.gravity is not None else 0j
    total = np.zeros(len(angles))

    def frame(body):
        f = graph.bodies[body].frame
        if f.angle_of is None:
            return f.origin, np.full(len(angles), f.angle), np.zeros(len(angles))
        joint = state.joints[f.angle_of]
        return f.origin, np.unwrap(joint.position) + f.angle, joint.velocity

    for mass in scene.masses:
        origin, theta, omega = frame(mass.body)
        r = complex(*mass.com) * np.exp(1j * theta)
        position, velocity, _ = state.complex_points[origin]
        v_g = velocity + 1j * omega * r
        x_g = position + r
        total += (0.5 * mass.mass * np.abs(v_g) ** 2 + 0.5 * mass.inertia * omega ** 2
                  - mass.mass * (g.real * x_g.real + g.imag * x_g.imag))
    for load in scene.loads:
        if load.point is not None:
            x = state.complex_points[load.point][0]
            total -= load.force[0] * x.real + load.force[1] * x.imag
        elif load.link != crank:
            _, theta, _ = frame(load.link)
            total -= load.torque * theta
    return total


def swing(values):
    """Return max - min of a function sampled over a turn (the last sample the first's again).

    Each refined to the vertex of the parabola through it and its neighbours.
    """
    values = values[:-1]
    n = len(values)

    def vertex(i):
        y0, y1, y2 = values[i - 1], values[i], values[(i + 1) % n]
        curve = y2 - 2.0 * y1 + y0
        return y1 - (y2 - y0) ** 2 / (8.0 * curve) if curve else y1
    return vertex(int(np.argmax(values))) - vertex(int(np.argmin(values)))


def test_scotch_yoke_is_its_closed_form(studies):
    """A yoke of mass m: T = m r^2 w^2 sin(2 theta) / 2; dE, extremes, crossings, flywheel."""
    study = studies['scotch_yoke_mass']
    w = rad_per_s_from_rpm(300.0)
    peak = 0.5 * YOKE_MASS * YOKE_R ** 2 * w ** 2     # 2.4674011 J
    effort = study.drivers['crank']
    assert abs(study.fluctuation - peak) <= study.fluctuation_error <= RTOL_ESTIMATE * peak
    assert abs(effort.mean) <= effort.mean_error <= RTOL_ESTIMATE * peak
    assert abs(effort.maximum.value - peak) <= effort.maximum.bound
    assert abs(effort.minimum.value + peak) <= effort.minimum.bound
    assert min(abs(effort.maximum.angle - a) for a in (math.pi / 4, 5 * math.pi / 4)) < 1e-8
    assert min(abs(effort.minimum.angle - a) for a in (3 * math.pi / 4, 7 * math.pi / 4)) < 1e-8
    np.testing.assert_allclose(study.crossings, np.arange(4) * math.pi / 2, rtol=0, atol=1e-12)
    assert [round(loop.area / peak) for loop in study.loops] == [1, -1, 1, -1]
    flywheel = study.flywheel(0.02)
    exact = 0.5 * YOKE_MASS * YOKE_R ** 2 / 0.02     # I = m r^2 / (2 Cs): 0.125 kg m^2
    assert abs(flywheel.inertia - exact) <= flywheel.error <= RTOL_ESTIMATE * exact


def test_a_yoke_accelerating_has_the_mean_of_its_closed_form():
    """With accel a: T = m r^2 (w^2 sin(2 theta) / 2 + a sin^2 theta), mean m r^2 a / 2."""
    scene = forces_scene('scotch_yoke_mass')
    study = turning_moment_from_scene(scene, speed=-5.0, accel=40.0)
    effort = study.drivers['crank']
    exact = 0.5 * YOKE_MASS * YOKE_R ** 2 * 40.0
    assert study.speed == -5.0 and study.accel == 40.0
    assert abs(effort.mean - exact) <= effort.mean_error <= RTOL_ESTIMATE * exact
    np.testing.assert_allclose(
        study.efforts['crank'],
        YOKE_MASS * YOKE_R ** 2 * (12.5 * np.sin(2 * study.angles)
                                   + 40.0 * np.sin(study.angles) ** 2), rtol=0, atol=1e-13)


def test_geneva_wheel_across_its_jumps(studies):
    """The effort's slope jumps where the pin enters and leaves a slot; the integrals split there.

    Six slots, the wheel's centre at twice the pin's radius: dE is the
    wheel's largest kinetic energy, I (w R / (l - R))^2 / 2 = 0.1 J, the mean
    the drag's 0.5 N m: both to their estimates, which stay at rounding (Gauss
    sums across a kink at 120 deg, off every panel's end, converge as h^2
    only, and never agree at two resolutions to 1e-13).
    """
    study = studies['geneva_wheel']
    exact = 0.5 * GENEVA_INERTIA * GENEVA_SPEED ** 2
    assert abs(study.fluctuation - exact) <= study.fluctuation_error <= RTOL_ESTIMATE * exact
    effort = study.drivers['driver']
    assert abs(effort.mean - 0.5) <= effort.mean_error <= RTOL_ESTIMATE
    assert study.energy_max == pytest.approx(math.pi, abs=ATOL_PLACE)
    assert study.panels < 4096


@pytest.mark.parametrize('name, mean', [('four_bar_masses', 3.0), ('engine', -150.0),
                                        ('geneva_wheel', 0.5), ('scotch_yoke_mass', 0.0),
                                        ('five_bar_masses', 0.0)])
def test_the_mean_is_what_the_drag_takes(studies, name, mean):
    """Every load but a torque on the turning crank is conservative: the mean balances it."""
    effort = studies[name].drivers[studies[name].crank]
    scale = max(abs(effort.maximum.value), abs(effort.minimum.value))
    assert abs(effort.mean - mean) <= effort.mean_error <= RTOL_ESTIMATE * scale
    assert studies[name].power == pytest.approx(effort.mean * studies[name].speed, rel=1e-15)


@pytest.mark.parametrize('name', ['four_bar_masses', 'engine', 'five_bar_masses',
                                  'scotch_yoke_mass'])
def test_the_fluctuation_is_the_swing_of_the_energy(studies, name):
    """The fluctuation is the swing of kinetic plus potential energy (by kinematics), and where."""
    scene = forces_scene(name)
    study = studies[name]
    angles = np.linspace(0.0, 2.0 * math.pi, ENERGY_SAMPLES)
    e = energy(scene, angles)
    expected = swing(e)
    allowed = study.fluctuation_error + RTOL_ENERGY * expected
    assert abs(study.fluctuation - expected) <= allowed
    assert study.fluctuation_error <= RTOL_ESTIMATE * expected
    top = angles[int(np.argmax(e))]
    low = angles[int(np.argmin(e))]
    if name != 'scotch_yoke_mass':     # the yoke's energy peaks twice a turn
        assert abs(math.remainder(study.energy_max - top, 2 * math.pi)) < ATOL_PLACE * 100
        assert abs(math.remainder(study.energy_min - low, 2 * math.pi)) < ATOL_PLACE * 100
    # The loops add up to nothing over the turn, and dE is their largest run.
    assert abs(sum(loop.area for loop in study.loops)) <= 10 * study.fluctuation_error


def test_against_a_fine_trapezoid_sum():
    """The engine's dE against the cumulative trapezoid sum of T on 2^16 steps (O(h^2)).

    The trapezoid's error on any partial integral is at most ``2 pi h^2 max|T''|
    / 12``, ``T''`` bounded by the grid's second differences (with a margin of 2).
    """
    scene = forces_scene('engine')
    study = turning_moment_from_scene(scene)
    angles = np.linspace(0.0, 2.0 * math.pi, 2 ** 16 + 1)
    h = angles[1] - angles[0]
    t = np.asarray(mk.solve(scene, angles, scene.input.speed, 0.0).forces.efforts['crank'])
    cumulative = np.concatenate(([0.0], np.cumsum(0.5 * (t[1:] + t[:-1]) * h)))
    mean = cumulative[-1] / (2.0 * math.pi)
    e = cumulative - mean * angles
    curvature = np.max(np.abs(np.diff(t, 2))) / h ** 2
    tolerance = 2.0 * (2.0 * math.pi * h ** 2 * curvature / 12.0) * 2.0
    assert abs(study.mean - mean) <= tolerance
    assert abs(study.fluctuation - (e.max() - e.min())) <= tolerance + h * np.max(np.abs(t))


@pytest.mark.parametrize('name', ['four_bar_masses', 'engine', 'five_bar_masses'])
def test_extremes_are_the_largest_and_least(studies, name):
    """No effort on a fine grid beats an extreme by more than its bound; each is the solver's."""
    scene = forces_scene(name)
    study = studies[name]
    angles = np.linspace(0.0, 2.0 * math.pi, 20001)
    speed = next(d.speed for d in scene.drivers if d.name == study.crank)
    state = mk.solve(scene, *turn_arguments(scene, study.crank, angles, speed))
    for driver, effort in study.drivers.items():
        values = np.asarray(state.forces.efforts[driver])
        assert values.max() <= effort.maximum.value + effort.maximum.bound
        assert values.min() >= effort.minimum.value - effort.minimum.bound
        for extreme in (effort.maximum, effort.minimum):
            at = mk.solve(scene, *turn_arguments(scene, study.crank, np.array([extreme.angle]),
                                                 speed))
            assert float(at.forces.efforts[driver][0]) == pytest.approx(extreme.value,
                                                                        abs=extreme.bound)


def test_the_diagram_is_the_solvers_and_holds_the_other_drivers(studies):
    """The five-bar: the left crank turns, the right held at its start at rest; both efforts."""
    scene = forces_scene('five_bar_masses')
    study = studies['five_bar_masses']
    assert study.crank == 'left_crank' and not study.single
    assert study.held == {'right_crank': pytest.approx(math.radians(60.0), abs=1e-15)}
    state = mk.solve(scene, [study.angles, np.full(len(study.angles), math.radians(60.0))],
                     [np.full(len(study.angles), rad_per_s_from_rpm(30.0)),
                      np.zeros(len(study.angles))], [np.zeros(len(study.angles))] * 2)
    for name in ('left_crank', 'right_crank'):   # the end of the turn solved at 0 rad
        np.testing.assert_array_equal(study.efforts[name][:-1], state.forces.efforts[name][:-1])
        assert study.efforts[name][-1] == pytest.approx(study.efforts[name][0], abs=1e-15)
    with pytest.raises(ValueError, match='one crank for a flywheel'):
        study.flywheel(0.02)


def test_flywheel_is_the_textbook_formula(studies):
    """I = dE / (w^2 Cs), w the mean speed (|scene's|), with its error; bad Cs refused."""
    study = studies['engine']
    w = rad_per_s_from_rpm(300.0)
    for cs in (0.01, 0.02, 0.5):
        flywheel = study.flywheel(cs)
        assert flywheel.speed == w and flywheel.cs == cs
        assert flywheel.inertia == pytest.approx(study.fluctuation / (w * w * cs), rel=1e-15)
        assert flywheel.error == pytest.approx(study.fluctuation_error / (w * w * cs),
                                               rel=1e-3)
    for cs in (0.0, -0.1, 2.0, math.nan, math.inf):
        with pytest.raises(ValueError, match='above 0 and below 2'):
            study.flywheel(cs)
    resting = turning_moment_from_scene(forces_scene('engine'), speed=0.0)
    with pytest.raises(ValueError, match='a mean speed above 0'):
        resting.flywheel(0.02)


def test_scenes_it_cannot_study_are_refused():
    """No forces, no crank, or a crank that cannot turn fully: SceneError, one line, naming it."""
    with pytest.raises(mk.SceneError, match='masses, gravity or loads.*khurmi'):
        turning_moment_from_scene(mk.load_scene('khurmi_four_bar_ad150'))
    with pytest.raises(mk.SceneError, match='driven by lift_cyl, none a crank'):
        turning_moment_from_scene(forces_scene('boom_masses'))
    data = yaml.safe_load((FORCES / 'four_bar_masses.yaml').read_text())
    data['input']['length'] = 100      # the crank longer than the rocker: it cannot turn
    with pytest.raises(mk.SceneError, match=r'to turn a whole turn.*crank "crank" at') as caught:
        turning_moment_from_scene(mk.parse_scene(data))
    assert '\n' not in str(caught.value)


def test_quadrature_tolerance_is_met(studies):
    """Each study stops doubling its panels once the two resolutions agree (or at the most)."""
    for study in studies.values():
        assert study.panels <= 4096
        for effort in study.drivers.values():
            scale = max(abs(effort.maximum.value), abs(effort.minimum.value))
            assert effort.mean_error <= max(1e3 * QUADRATURE_TOLERANCE, 1e-12) * scale
