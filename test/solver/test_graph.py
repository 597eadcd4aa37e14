# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The mechanism graph (solver/graph.py): bodies and joints that match the solved motion."""

from __future__ import annotations

import inspect
import math
import pickle
import warnings

from helpers import crank_scene_names, driver_scene_names
import numpy as np
import pytest

import mech_kinematics as mk
from mech_kinematics.solver import graph as g
from mech_kinematics.solver.base import Driver, Item
from mech_kinematics.solver.carried import CarriedPoint
from mech_kinematics.solver.registry import DRIVERS, KINDS

#: Relative tolerance of a point's place on its body over a cycle (the solver's bounds are far
#: tighter; this is rounding over many steps, relative to the mechanism's size).
RTOL_RIGID = 1e-9
SAMPLES = 60


def _states(scene):
    """Return the scene solved at SAMPLES instants spread around its start (the valid ones)."""
    drivers = scene.drivers
    spread = np.linspace(-0.3, 0.3, SAMPLES)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', mk.NearSingularWarning)
        if len(drivers) == 1 and drivers[0].joint_type.angular:
            state = mk.solve(scene, drivers[0].start + np.linspace(0, 2 * math.pi, SAMPLES))
        else:
            positions = [d.start + spread * (0.1 if not d.joint_type.angular else 1.0)
                         * (k + 1) for k, d in enumerate(drivers)]
            speeds = [0.3 * (k + 1) for k in range(len(drivers))]
            accels = [0.2] * len(drivers)
            state = (mk.solve(scene, positions[0], speeds[0], accels[0]) if len(drivers) == 1
                     else mk.solve(scene, positions, speeds, accels))
    return state


def _xy(state, name):
    return state.points[name].position


def test_every_kind_answers_every_method_of_its_protocol():
    """Each registered kind implements all of its protocol: no method left to a default."""
    kinds = [*KINDS.values(), CarriedPoint, *DRIVERS.values()]
    for kind in kinds:
        protocol = Driver if issubclass(kind, Driver) else Item
        assert issubclass(kind, protocol), kind
        missing = sorted(getattr(kind, '__abstractmethods__', ()))
        assert not missing, f'{kind.__name__} does not answer {", ".join(missing)}'
        # and nothing of the protocol is inherited as a body that means "nothing"
        for name, member in inspect.getmembers(protocol):
            if getattr(member, '__isabstractmethod__', False):
                assert name in vars(kind) or any(name in vars(c) for c in kind.__mro__[1:]
                                                 if c not in (protocol, object)), (kind, name)


def test_joint_types_are_their_names_and_carry_their_facts():
    """A JointType equals, prints and pickles as its name, and says where its values live."""
    assert g.REVOLUTE == 'revolute' and repr(g.PRISMATIC) == "'prismatic'"
    assert pickle.loads(pickle.dumps(g.REVOLUTE)) is g.REVOLUTE
    assert g.joint_type('prismatic') is g.PRISMATIC
    assert (g.REVOLUTE.table, g.PRISMATIC.table, g.LOCK.table) == ('links', 'sliders', None)
    assert g.REVOLUTE.angular and not g.PRISMATIC.angular
    units = mk.SceneUnits('mm', 'deg')
    assert g.REVOLUTE.text(math.pi / 2, units) == '90 deg'
    assert g.PRISMATIC.text(0.25, units) == '250 mm'
    assert g.PRISMATIC.scene_value(0.25, units) == 250.0
    assert g.REVOLUTE.reported(3 * math.pi / 2) == pytest.approx(-math.pi / 2)
    with pytest.raises(ValueError, match='joint type'):
        g.joint_type('spherical')


def test_the_four_bar_is_four_bodies_and_four_pins():
    """The textbook four-bar: ground, crank, coupler, rocker; the crank's pin is its driver."""
    graph = mk.load_scene('khurmi_four_bar_ad150').graph
    assert list(graph.bodies) == ['ground', 'crank', 'coupler', 'rocker']
    assert [(j.name, j.type, j.body, j.on, j.at, j.driver) for j in graph.joints] == [
        ('crank', 'revolute', 'crank', 'ground', 'A', True),
        ('B', 'revolute', 'coupler', 'crank', 'B', False),
        ('D', 'revolute', 'rocker', 'ground', 'D', False),
        ('C', 'revolute', 'rocker', 'coupler', 'C', False)]
    assert graph.reversing() == {'rocker': 'revolute'}
    assert graph.pivots() == {'crank': 'A', 'rocker': 'D'}


def test_a_cylinder_is_a_barrel_and_a_driven_rod():
    """An actuated RRR link is its barrel (pinned at its start) and a rod sliding in it."""
    graph = mk.load_scene('excavator').graph
    rod = graph.bodies['boom_cyl']
    assert rod.role is g.Role.SLIDER and rod.guide == 'boom_cyl_body' and rod.points == ('Q',)
    joint = graph.prismatic('boom_cyl')
    assert joint.driver and joint.on == 'boom_cyl_body'
    assert joint.line == g.Line('F', 'boom_cyl_body', 0.0)
    assert graph.bodies['boom_cyl_body'].length is None


def test_a_geneva_wheel_has_an_intermittent_slot_and_a_lock():
    """A Geneva wheel's slot (n copies) and lock act part of the cycle; it never reverses."""
    graph = mk.load_scene('geneva').graph
    slot = graph.prismatic('pin_slot')
    assert slot.intermittent and slot.copies == 4
    lock = next(j for j in graph.joints if j.type is g.LOCK)
    assert lock.intermittent and lock.on == graph.ground
    assert graph.reversing() == {}


def test_pins_sharing_a_point_are_named_by_point_and_body():
    """Where several pins share a point, each is named POINT/BODY (no scene name has a '/')."""
    scene = mk.Scene(
        'star', {'A': (0.0, 0.0), 'D': (0.1, 0.0), 'E': (0.0, -0.1)},
        mk.Crank('crank', 'A', 'B', 0.03, angle=1.0),
        (mk.RRR('C', (mk.Link('coupler', 'B', 0.1), mk.Link('rocker', 'D', 0.08))),
         mk.RRR('F', (mk.Link('second', 'B', 0.12), mk.Link('other', 'E', 0.1)))))
    names = [j.name for j in scene.graph.joints]
    assert 'B/coupler' in names and 'B/second' in names and 'B' not in names
    assert len(set(names)) == len(names)


@pytest.mark.parametrize('name', sorted(crank_scene_names() + driver_scene_names()))
def test_mobility_is_the_number_of_drivers(name):
    """Gruebler: 3 per moving body less 2 per pin or slide (one of two that alternate)."""
    graph = mk.load_scene(name).graph
    moving = len(graph.bodies) - 1
    joints = [j for j in graph.joints if j.type is not g.LOCK]  # the lock stands in for the slot
    assert 3 * moving - 2 * len(joints) == len(graph.drivers)
    assert set(mk.load_scene(name).joint_types) <= set(graph.coordinates)


@pytest.mark.parametrize('name', sorted(crank_scene_names() + driver_scene_names()))
def test_every_body_moves_rigidly_in_its_frame(name):
    """Each body's points keep their place in its frame, and move as omega x r about its origin."""
    scene = mk.load_scene(name)
    full = mk.Scene(**{f: getattr(scene, f) for f in (
        'name', 'ground', 'input', 'dyads', 'points', 'description', 'pins', 'units', 'inputs')})
    graph = full.graph
    state = _states(full)
    valid = np.asarray(state.valid)
    assert valid.sum() > SAMPLES // 4
    size = max(math.hypot(*xy) for xy in full.ground.values()) + 1.0
    for body in graph.bodies.values():
        frame = body.frame
        if frame is None:
            continue
        origin = state.points[frame.origin]
        angle = (np.full(valid.shape, frame.angle) if frame.angle_of is None
                 else state.joints[frame.angle_of].position)
        omega = (np.zeros(valid.shape) if frame.angle_of is None
                 else state.joints[frame.angle_of].velocity)
        assert frame.origin in body.points or body.role is g.Role.SLIDER, body
        c, s = np.cos(angle), np.sin(angle)
        for point in body.points:
            d = state.points[point].position - origin.position
            local = np.stack((c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]), axis=1)
            spread = np.ptp(local[valid], axis=0)
            assert (spread <= RTOL_RIGID * size).all(), (name, body.name, point, spread)
            dv = state.points[point].velocity - origin.velocity
            expected = np.stack((-omega * d[:, 1], omega * d[:, 0]), axis=1)
            np.testing.assert_allclose(dv[valid], expected[valid], atol=1e-9 * size,
                                       err_msg=f'{name} {body.name} {point}')


@pytest.mark.parametrize('name', sorted(crank_scene_names() + driver_scene_names()))
def test_every_slide_keeps_its_point_on_its_line(name):
    """A prismatic joint's point lies on its line, which turns with its body's frame."""
    scene = mk.load_scene(name)
    graph = scene.graph
    full = mk.Scene(**{f: getattr(scene, f) for f in (
        'name', 'ground', 'input', 'dyads', 'points', 'description', 'pins', 'units', 'inputs')})
    state = _states(full)
    valid = np.asarray(state.valid)
    for joint in graph.joints:
        line = joint.line
        if line is None:
            continue
        assert line.through in graph.bodies[joint.on].points, joint
        assert joint.at in graph.bodies[joint.body].points, joint
        angle = line.angle + (0.0 if line.angle_of is None
                              else state.joints[line.angle_of].position)
        d = state.points[joint.at].position - state.points[line.through].position
        across = -np.sin(angle) * d[:, 0] + np.cos(angle) * d[:, 1]
        mask = valid.copy()
        if joint.copies > 1:  # a Geneva slot: the pin is in one of n, and only while engaged
            engaged = np.asarray(state.intermittent[joint.on].engaged)
            mask &= engaged
            k = np.round((np.arctan2(d[:, 1], d[:, 0]) - angle) / (2 * math.pi / joint.copies))
            angle = angle + k * 2 * math.pi / joint.copies
            across = -np.sin(angle) * d[:, 0] + np.cos(angle) * d[:, 1]
        scale = np.hypot(d[:, 0], d[:, 1]).max() + 1.0
        assert (np.abs(across[mask]) <= 1e-9 * scale).all(), (name, joint.name)
