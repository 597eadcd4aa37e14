# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The forces the node publishes (ros/wrenches.py), without a running node (issue 32).

The forces tick against ``mk.solve`` at the same instant, bit for bit; the
pre-serialized ``JointState`` with efforts and ``WrenchStamped`` against the
messages built field by field; the parameters of gravity and the loads; an
instant whose forces cannot be bounded keeps its kinematics.
"""

from dataclasses import replace
import math

from geometry_msgs.msg import WrenchStamped
import pytest
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import JointState

import mech_kinematics as mk
from mech_kinematics.ros.cdr import cdr_from_message, MessageTemplate
from mech_kinematics.ros.messages import joint_state_from_state, TickMessages
from mech_kinematics.ros.parameters import DYNAMIC, refusal, STATIC, TIME, TOPIC
from mech_kinematics.ros.ticker import compiled_tick
from mech_kinematics.ros.wrenches import (dynamics_with, effort_status, force_parameters,
                                          ForceMessages, forces_tick, forces_values,
                                          ForcesTick, reaction_wrench, wrench_stamped)
from mech_kinematics.solver import forces as mk_forces
from mech_kinematics.solver.forces import Forces

#: The packaged scenes with masses, gravity or loads.
LOADED = ('engine', 'shaper', 'five_bar_payload', 'excavator_loaded', 'khurmi_engine_15_7',
          'singh_petrol_engine_13_15')
TOL = 1e-6
#: A prismatic joint's force against its line, relative to the force (rounding of cos, sin).
RTOL_NORMAL = 1e-12


def _start(scene):
    drivers = scene.drivers
    if len(drivers) == 1:
        return drivers[0].start, drivers[0].speed, drivers[0].accel
    return ([d.start for d in drivers], [d.speed for d in drivers],
            [d.accel for d in drivers])


def _tick(scene, static=False):
    return ForcesTick(scene, scene.output_joints, scene.output_points, (), static=static)


@pytest.mark.parametrize('name', LOADED)
def test_forces_tick_is_solve_bit_for_bit(name):
    """The tick's motion is the compiled tick's and its forces mk.solve's, to the bit."""
    scene = mk.load_scene(name)
    args = _start(scene)
    tick = _tick(scene)
    values, measure = tick(*args, TOL, 0)
    motion, _ = compiled_tick(scene)(*args, TOL, 0)
    state = mk.solve(scene, *args, max_error=TOL)
    assert values[:tick.forces_first] == motion
    assert values[tick.forces_first:] == forces_values(state.forces, state, scene.output_joints,
                                                       tick.reactions)
    assert measure == min(state.singularity.values(), default=math.inf)


@pytest.mark.parametrize('name', LOADED)
def test_efforts_are_the_drivers_and_zero_for_passive_joints(name):
    """joint_states.effort: each driver's effort from the state, 0.0 for every other joint."""
    scene = mk.load_scene(name)
    state = mk.solve(scene, *_start(scene))
    values = forces_values(state.forces, state, scene.output_joints, ())
    drivers = {d.name for d in scene.drivers}
    for joint, effort in zip(scene.output_joints, values, strict=False):
        expected = state.forces.efforts[joint] if joint in drivers else 0.0
        assert effort == expected, joint
    assert any(values[:len(scene.output_joints)])


def test_a_prismatic_joints_force_is_its_normal_turned_onto_the_line():
    """The piston's reaction is normal * (its guide's direction + 90 deg), torque its moment."""
    scene = mk.load_scene('shaper')
    state = mk.solve(scene, *_start(scene))
    joints = {j.name: j for j in scene.dynamics.graph.joints}
    for name in ('ram', 'block'):
        r = state.forces.reactions[name]
        fx, fy, tz = reaction_wrench(joints[name], state.forces, state)
        assert math.hypot(fx, fy) == pytest.approx(abs(r.normal), rel=RTOL_NORMAL)
        assert tz == r.moment
        line = joints[name].line
        angle = line.angle if line.angle_of is None else \
            state.joints[line.angle_of].position + line.angle
        along = fx * math.cos(angle) + fy * math.sin(angle)
        assert abs(along) <= RTOL_NORMAL * abs(r.normal)
        assert (-fx * math.sin(angle) + fy * math.cos(angle)) * r.normal > 0
    pin = reaction_wrench(joints['C'], state.forces, state)
    assert pin == (state.forces.reactions['C'].force.real,
                   state.forces.reactions['C'].force.imag, 0.0)


def test_static_effort_is_the_statics_at_rest():
    """effort: static solves the forces at the same positions with no velocity, acceleration."""
    scene = mk.load_scene('five_bar_payload')
    angle, speed, accel = _start(scene)
    tick = _tick(scene, static=True)
    values, _ = tick(angle, [3.0, -2.0], [10.0, 5.0], TOL, [0, 0])
    rest = mk.solve(scene, angle, [0.0, 0.0], [0.0, 0.0], max_error=TOL)
    moving = mk.solve(scene, angle, [3.0, -2.0], [10.0, 5.0], max_error=TOL)
    assert values[tick.forces_first:] == forces_values(rest.forces, rest, scene.output_joints,
                                                       tick.reactions)
    assert values[tick.forces_first:] != forces_values(moving.forces, moving,
                                                       scene.output_joints, tick.reactions)
    n = len(scene.output_joints)
    assert values[n:2 * n] == [float(moving.joints[j].velocity) for j in scene.output_joints]


def test_a_new_gravity_or_load_is_the_scene_with_it():
    """dynamics_with: the forces of the scene written with the new gravity and load values."""
    scene = mk.load_scene('engine')
    args = _start(scene)
    [gas] = scene.loads
    changes = {'gravity': [1.5, -3.0], 'loads.gas.force': [0.0, -1000.0]}
    tick = _tick(scene)
    tick.dynamics = dynamics_with(scene.dynamics, changes)
    values, _ = tick(*args, TOL, 0)
    written = replace(scene, gravity=(1.5, -3.0), loads=(replace(gas, force=(0.0, -1000.0)),),
                      outputs_joints=scene.outputs_joints, outputs_points=scene.outputs_points)
    state = mk.solve(written, *args, max_error=TOL)
    assert values[tick.forces_first:] == forces_values(state.forces, state,
                                                       scene.output_joints, tick.reactions)
    assert tick.dynamics.graph is scene.dynamics.graph


def test_forces_left_out_keep_the_kinematics(monkeypatch):
    """An instant whose forces are not bounded publishes its motion, and says why not forces."""
    scene = mk.load_scene('engine')
    tick = _tick(scene)
    args = _start(scene)
    good, _ = tick(*args, TOL, 0)

    def unbounded(state, max_error):
        return Forces({}, {}, 0j, 0.0, {}, (math.inf, math.inf), False, 1.0,
                      {'rod (statics singular)': True}, None)

    monkeypatch.setattr(tick.dynamics, 'forces', unbounded)
    values, _ = tick(*args, TOL, 0)
    assert values == good[:tick.forces_first]
    assert tick.refused == 1
    assert tick.refusal == 'the forces cannot be bounded here (rod (statics singular))'


def test_joint_state_with_efforts_is_byte_exact():
    """The JointState template with efforts gives the bytes of the message built field by field."""
    scene = mk.load_scene('excavator_loaded')
    args = _start(scene)
    tick = _tick(scene)
    values, _ = tick(*args, TOL, 0)
    state = mk.solve(scene, *args, max_error=TOL)
    joints, points = scene.output_joints, scene.output_points
    messages = TickMessages(joints, points, 'base', efforts_first=tick.forces_first)
    rendered = messages.render_values(values, 12, 345)[0]
    built = joint_state_from_state(state, joints, 'base', 12, 345, efforts=True)
    assert rendered == cdr_from_message(built)
    assert list(deserialize_message(rendered, JointState).effort) == list(built.effort)
    # Forces left out: the effort is empty, the rest as before.
    short = messages.render_values(values[:tick.forces_first], 12, 345)[0]
    assert short == cdr_from_message(joint_state_from_state(state, joints, 'base', 12, 345))
    # Without velocities (drive: topic), the efforts still read their own values.
    topic = TickMessages(joints, points, 'base', velocities=False, accelerations=False,
                         efforts_first=tick.forces_first)
    message = deserialize_message(topic.render_values(values, 1, 2)[0], JointState)
    assert list(message.velocity) == []
    assert list(message.effort) == list(built.effort)


def test_wrenches_are_byte_exact():
    """Each reaction's and the shaking's WrenchStamped are the messages built field by field."""
    scene = mk.load_scene('shaper')
    args = _start(scene)
    tick = _tick(scene)
    values, _ = tick(*args, TOL, 0)
    state = mk.solve(scene, *args, max_error=TOL)
    n = len(scene.output_joints)
    rendered = ForceMessages('base', n, len(tick.reactions)).render(values, tick.forces_first,
                                                                    7, 8)
    expected = [reaction_wrench(j, state.forces, state) for j in tick.reactions]
    shaking = state.forces.shaking_force
    expected.append((shaking.real, shaking.imag, float(state.forces.shaking_moment)))
    assert len(rendered) == len(expected) == len(tick.reactions) + 1
    for data, wrench in zip(rendered, expected, strict=True):
        assert data == cdr_from_message(wrench_stamped(wrench, 'base', 7, 8))
        msg = deserialize_message(data, WrenchStamped)
        assert (msg.wrench.force.x, msg.wrench.force.y, msg.wrench.torque.z) == wrench
        assert msg.header.frame_id == 'base'


def test_message_template_where_must_name_each_slot():
    """A template given indices for its slots needs one per slot."""
    with pytest.raises(ValueError, match='Expected one index per slot'):
        MessageTemplate(WrenchStamped(), 0, where=[1])


def test_force_parameters_and_their_refusals():
    """Gravity and load parameters: the scene's values by default; wrong length, NaN refused."""
    scene = mk.load_scene('engine')
    specs = {p.name: p for p in force_parameters(scene.dynamics)}
    assert specs['gravity'].default == [0.0, -9.81]
    assert specs['loads.gas.force'].default == list(scene.loads[0].force)
    assert refusal('gravity', [0.0, -9.81], specs) is None
    assert refusal('gravity', [0, 1], specs) is None
    assert refusal('gravity', [0.0, 1.0, 2.0], specs) == \
        'gravity: expected [x, y], two numbers (m/s^2), got [0.0, 1.0, 2.0]'
    assert refusal('gravity', [math.nan, 1.0], specs) == \
        'gravity: expected two finite numbers (m/s^2), got [nan, 1.0]'
    assert refusal('loads.gas.force', 'up', specs) == \
        "loads.gas.force: expected [x, y] (N), got string 'up'"
    shaper = mk.load_scene('shaper')
    torques = [p for p in force_parameters(shaper.dynamics) if p.kind == 'double']
    for p in torques:
        assert refusal(p.name, math.inf, {p.name: p}) == \
            f'{p.name}: expected a finite number, got inf'


def test_which_scenes_and_drives_publish_forces():
    """No forces without masses, gravity or loads; topic drive only with effort: static."""
    plain, loaded = mk.load_scene('four_bar_coupler_points'), mk.load_scene('engine')
    assert forces_tick(plain, plain, (), drive=TIME, effort=DYNAMIC) is None
    assert effort_status(plain, TIME, DYNAMIC) == ''
    assert forces_tick(loaded, loaded, (), drive=TOPIC, effort=DYNAMIC) is None
    assert effort_status(loaded, TOPIC, DYNAMIC).startswith('left out')
    assert forces_tick(loaded, loaded, (), drive=TOPIC, effort=STATIC).static
    assert not forces_tick(loaded, loaded, (), drive=TIME, effort=DYNAMIC).static


@pytest.mark.parametrize('name', LOADED)
def test_warming_writes_the_forces_out_before_any_tick_and_changes_no_value(name):
    """warm(): the written-out forces exist before the first tick; ticks write nothing more.

    Writing one pivot sequence's function takes milliseconds: a tick thread at
    1 kHz that wrote them would stall. The values are the cold tick's, bit for bit.
    """
    scene = mk.load_scene(name)
    args = _start(scene)
    cold = _tick(mk.load_scene(name))     # a Dynamics of its own, on the general path
    warm = _tick(scene)
    assert cold.dynamics is not warm.dynamics
    dynamics = warm.warm()
    assert dynamics is warm.dynamics and dynamics._fast, dynamics.compiled_single
    written = list(dynamics._fast)
    one = len(scene.drivers) == 1
    for k in range(16):
        at = (args[0] + 0.37 * k if one else args[0], *args[1:])
        try:
            assert warm(*at, TOL, 0) == cold(*at, TOL, 0)
        except mk.AssemblyError:
            continue
    assert set(dynamics._fast) == set(written)


@pytest.mark.parametrize('speed', [10.0, -10.0])
@pytest.mark.parametrize('degrees', [135.0, 225.0])
def test_the_tick_publishes_a_geneva_mouths_forces_on_the_kinematics_side(degrees, speed):
    """At the pin's entry and exit the tick's forces are mk.solve's: the lock where it holds.

    Issue 43: the pin was published pushing where the wheel was at rest and
    locked (the exit turning CCW, the entry turning CW).
    """
    scene = replace(mk.load_scene('geneva'), masses=(mk_forces.Mass('wheel', 2.0, inertia=0.01),),
                    loads=(mk_forces.Load('brake', link='wheel', torque=0.3),))
    tick = _tick(scene)
    theta = math.radians(degrees)
    values, _ = tick(theta, speed, 0.0, TOL, 0)
    state = mk.solve(scene, theta, speed, 0.0, max_error=TOL)
    assert values[tick.forces_first:] == forces_values(state.forces, state, scene.output_joints,
                                                       tick.reactions)
    lock = [j.name for j in tick.reactions].index('wheel/lock')
    start = tick.forces_first + len(scene.output_joints) + 3 * lock
    holds = (degrees == 225.0) == (speed > 0.0)     # the wheel at rest after the mouth
    assert values[start:start + 3] == ([0.0, 0.0, pytest.approx(-0.3, rel=1e-14)] if holds
                                       else [0.0, 0.0, 0.0])
    assert (state.joints['wheel'].acceleration == 0.0) is holds


def test_a_forces_parameter_that_does_nothing_is_refused_at_start():
    """On a scene without masses, or in topic drive without effort: static: one line."""
    from mech_kinematics.ros.wrenches import scene_forces_refusal
    assert scene_forces_refusal(False, 'time', 'dynamic', ['speed_rpm']) is None
    assert scene_forces_refusal(False, 'time', 'static', []) == (
        'Expected no forces parameters for this scene (it has no masses, gravity or loads: '
        'there are no forces to publish), got effort:=static')
    assert scene_forces_refusal(False, 'time', 'dynamic', ['gravity', 'loads.push.force']) \
        .endswith('got gravity, loads.push.force')
    assert scene_forces_refusal(True, 'time', 'dynamic', ['gravity']) is None
    assert scene_forces_refusal(True, 'topic', 'static', ['gravity']) is None
    assert scene_forces_refusal(True, 'topic', 'dynamic', ['gravity']) == (
        'Expected effort:=static with drive: topic for gravity (the input gives no '
        'accelerations: the efforts are left out), got effort:=dynamic')
    # On a scene with inertial sensors, gravity moves the sensors of the scene's gravity.
    assert scene_forces_refusal(True, 'topic', 'dynamic', ['gravity'], sensors=True) is None
    assert scene_forces_refusal(True, 'topic', 'dynamic', ['gravity', 'loads.p.force'],
                                sensors=True).startswith(
        'Expected effort:=static with drive: topic for loads.p.force (')
