# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's forces tick in URDF mode without a node (issue 44): ros/robot_forces.py.

The tick's efforts and reactions are ``Robot.solve``'s at the same input, to
the bit (static, from a motor's message) or within their bounds (on the
clock, where the URDF's rates come back from the scene's); an actuated joint
outside every loop has no effort (NaN), a passive pin 0. The refusals of the
forces' parameters in URDF mode, the ``payloads`` parameter, and the
six-component wrench messages in each child link's frame.
"""

import math
from pathlib import Path

import numpy as np
import pytest

from mech_kinematics.errors import SceneError, UrdfError
from mech_kinematics.robot import load_robot
from mech_kinematics.robot.forces import reaction_names
from mech_kinematics.ros.cdr import cdr_from_message
from mech_kinematics.ros.parameters import DYNAMIC, refusal, STATIC, TIME, TOPIC
from mech_kinematics.ros.robot_forces import robot_forces_note, robot_forces_tick
from mech_kinematics.ros.robot_mode import (load_source, payloads_from_parameter,
                                            robot_forces_refusal)
from mech_kinematics.ros.wrenches import ForceMessages, wrench_stamped

DATA = Path(__file__).resolve().parents[1] / 'data' / 'urdf'
LIFT = DATA / 'lift_arm.urdf'
ABB = DATA / 'abb_irb2400_12_155.urdf'
ABB_CLOSURES = DATA / 'abb_irb2400_12_155.loop_closures.yaml'
TOL = 1e-6


def _tick(source, effort=STATIC, drive=TOPIC):
    tick = robot_forces_tick(source.robot, source.scene, drive=drive, effort=effort)
    tick.apply({'gravity': [0.0, 0.0, -9.80665]})
    return tick


def _from_input(tick, positions, speeds=None):
    """Return the published values (the URDF's layout) of a motor's message."""
    tick.inputs = (positions, speeds)
    p, v = tick.values.scene_inputs(positions, speeds)
    n = len(p)
    v = [0.0] * n if v is None else v
    values, _ = tick(p[0], v[0], 0.0, TOL, 0) if n == 1 else tick(p, v, [0.0] * n, TOL, [0] * n)
    return tick.values.values(values, (positions, speeds))


def test_a_motors_message_gets_robot_solves_efforts_and_reactions_to_the_bit():
    """effort: static with a payload: the tail is Robot.solve's efforts, then each reaction's."""
    source = load_source(str(LIFT), payloads=['platform=2.0@0.1,0,0.05'])
    robot = load_robot(LIFT, payloads={'platform': (2.0, (0.1, 0.0, 0.05))})
    tick = _tick(source)
    assert tick.reactions == ('lift_joint', 'upper_pivot', 'elbow', 'pin_C')
    assert tick.links == ('lower_arm', 'upper_arm', 'platform', 'upper_arm')
    assert tick.topics() == [f'reactions/{n}' for n in tick.reactions]
    first = tick.forces_first
    for q in (-1.0, 0.0, 0.4, 1.15):
        out = _from_input(tick, [q], [0.7])     # static: the speed is not in the forces
        answer = robot.solve({'lift_joint': q})
        assert out[first:first + 3] == [answer.efforts.efforts['lift_joint'], 0.0, 0.0]
        rest = out[first + 3:]
        assert len(rest) == 6 * len(tick.reactions)
        for k, name in enumerate(tick.reactions):
            r = answer.reactions[name]
            assert rest[6 * k:6 * k + 6] == [*r.force, *r.torque]
    assert tick.refused == 0


def test_on_the_clock_the_efforts_are_those_of_the_motion():
    """drive: time, effort: dynamic: Robot.solve's at the tick's URDF motion, within bounds."""
    source = load_source(str(LIFT))
    tick = _tick(source, DYNAMIC, TIME)
    n, first = len(tick.names), tick.forces_first
    for theta, omega, alpha in ((0.3, 2.0, -5.0), (-0.6, -1.0, 8.0)):
        values, _ = tick(theta, omega, alpha, TOL, 0)
        out = tick.values.values(values)
        q, v, a = out[0], out[n], out[2 * n]
        assert v != 0.0 and a != 0.0
        answer = source.robot.solve({'lift_joint': q}, {'lift_joint': v}, {'lift_joint': a})
        effort = answer.efforts.efforts['lift_joint']
        assert abs(out[first] - effort) <= 2 * answer.efforts.bounds['lift_joint'] + \
            1e-15 * abs(effort)
        static = source.robot.solve({'lift_joint': q}).efforts.efforts['lift_joint']
        assert abs(out[first] - static) > 1e-3 * abs(static)    # inertia counts


def test_a_joint_outside_every_loop_has_no_effort_and_a_passive_pin_zero(tmp_path):
    """The ABB with a mass on link_3: joint_3's effort, NaN for joint_1 (no loop), 0 passive."""
    path = tmp_path / 'abb.urdf'
    path.write_text(ABB.read_text().replace(
        '<link name="link_3"/>', '<link name="link_3"><inertial><mass value="10.0"/>'
        '<origin xyz="0.3 0 0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" '
        'izz="0.01"/></inertial></link>'))
    source = load_source(str(path), loop_closures=str(ABB_CLOSURES))
    robot = source.robot
    tick = _tick(source)
    positions = [0.1, -0.2, 0.3, 0.0, 0.5, 0.0]
    out = _from_input(tick, positions)
    efforts = dict(zip(tick.names, out[tick.forces_first:], strict=False))
    answer = robot.solve(dict(zip(robot.actuated, positions, strict=True)))
    assert efforts['joint_3'] == answer.efforts.efforts['joint_3'] != 0.0
    assert all(math.isnan(efforts[n]) for n in ('joint_1', 'joint_2', 'joint_4'))
    assert efforts['joint_lever_a'] == 0.0


def test_a_closures_reaction_is_in_its_child_links_axes_however_its_frame_is_turned(tmp_path):
    """pin_C's child frame turned about the pin's axis: the same force, in upper_arm's axes.

    The node and Robot.solve alike (one home for the rule: RobotForces.reactions).
    """
    plain = _tick(load_source(str(LIFT)))
    text = LIFT.read_text().replace('<child_origin xyz="0.5 0 0" rpy="0 0 0"/>',
                                    '<child_origin xyz="0.5 0 0" rpy="0 0.7 0"/>')
    assert text != LIFT.read_text()
    path = tmp_path / 'turned.urdf'
    path.write_text(text)
    source = load_source(str(path))
    robot = source.robot
    turned = _tick(source)
    [(_, link)] = [item for item in reaction_names(robot) if item[0] == 'pin_C']
    assert link == 'upper_arm'
    k = 6 * turned.reactions.index('pin_C')
    for q in (-0.4, 0.5):
        a = _from_input(plain, [q])[plain.forces_first + 3:]
        b = _from_input(turned, [q])[turned.forces_first + 3:]
        np.testing.assert_allclose(b[k:k + 6], a[k:k + 6], rtol=0, atol=1e-12 * 100)
        answer = robot.solve({'lift_joint': q}).reactions['pin_C']
        assert answer.frame == 'upper_arm'
        assert list(answer.force) == b[k:k + 3] and max(map(abs, answer.force)) > 1.0


def test_gravity_is_three_components_refused_beyond_the_doubles():
    """The gravity parameter: three finite numbers, at most MAX_GRAVITY; [0, 0, 0] none."""
    tick = _tick(load_source(str(LIFT)))
    spec, *_ = tick.parameters()
    assert (spec.name, spec.kind, spec.default) == ('gravity', 'xyz', [0.0, 0.0, -9.80665])
    specs = {'gravity': spec}
    assert refusal('gravity', [0.0, math.inf, 0.0], specs) == \
        'gravity: expected three finite numbers (m/s^2), got [0.0, inf, 0.0]'
    assert refusal('gravity', [0.0, -9.8], specs).startswith(
        'gravity: expected [x, y, z], three numbers')
    assert refusal('gravity', [0, 0, -2], specs) is None
    assert tick.parameters_refusal({'gravity': [0.0, 0.0, 1e308]}).startswith(
        "gravity: Expected gravity as [gx, gy, gz] in the URDF's root frame")
    assert tick.parameters_refusal({'gravity': [0.0, 0.0, 0.0]}) is None
    tick.apply({'gravity': [0.0, 0.0, 0.0]})
    assert tick.gravity() == [0.0, 0.0, 0.0]
    out = _from_input(tick, [0.3])
    assert out[tick.forces_first:] == [0.0] * (3 + 6 * len(tick.reactions))


def test_the_reactions_messages_are_whole_wrenches_in_each_child_links_frame():
    """Six values a message, one frame each: the message wrench_stamped makes."""
    tick = _tick(load_source(str(LIFT)))
    messages = tick.messages('mechanism', 'arm1')
    out = _from_input(tick, [0.25])
    rendered = messages.render(out, tick.forces_first, 7, 8)
    assert len(rendered) == len(tick.reactions)      # no shaking in URDF mode
    for k, (data, link) in enumerate(zip(rendered, tick.links, strict=True)):
        start = tick.forces_first + 3 + 6 * k
        expected = wrench_stamped(out[start:start + 6], f'arm1/{link}', 7, 8)
        assert data == cdr_from_message(expected)
    # Without a prefix the links' own names, as robot_state_publisher's frames.
    assert cdr_from_message(wrench_stamped([1.0] * 6, 'lower_arm', 0, 0)) == \
        ForceMessages(['lower_arm'], 0, 1, width=6, shaking=False).render([1.0] * 6, 0, 0, 0)[0]


def test_payloads_are_parsed_as_the_commands_take_them():
    """LINK=KG[@X,Y,Z]; a bad entry, a link twice or one the robot lacks: one line."""
    assert payloads_from_parameter(['platform=2.5@0.1,0,0.05', 'lower_arm=1']) == {
        'platform': (2.5, (0.1, 0.0, 0.05)), 'lower_arm': (1.0, (0.0, 0.0, 0.0))}
    for entries, message in ((['platform'], 'payloads: Expected LINK=KG or LINK=KG@X,Y,Z, got '
                                            "'platform'"),
                             (['platform=1@0,0'], 'payloads: Expected LINK=KG or'),
                             (['a=1', 'a=2'], 'payloads: Expected each link once, got "a"')):
        with pytest.raises(UrdfError) as error:
            payloads_from_parameter(entries)
        assert str(error.value).startswith(message)
    with pytest.raises(UrdfError, match='payload on link "wing": Expected a link of the robot'):
        load_source(str(LIFT), payloads=['wing=1'])
    with pytest.raises(UrdfError, match='payload on link "platform": Expected a mass above 0'):
        load_source(str(LIFT), payloads=['platform=-1'])
    with pytest.raises(SceneError, match='Expected payloads with a robot described in URDF'):
        load_source('four_bar', payloads=['platform=1'])
    # A payload is a mass: 2 kg on the platform at L raises the holding torque by 2 g L cos q.
    plain, loaded = _tick(load_source(str(LIFT))), _tick(load_source(str(LIFT),
                                                                     payloads=['platform=2']))
    q = 0.3
    gain = _from_input(loaded, [q])[loaded.forces_first] - _from_input(plain, [q])[
        plain.forces_first]
    assert gain == pytest.approx(2.0 * 9.80665 * 0.5 * math.cos(q), rel=1e-12)


def test_payloads_change_while_running_from_the_next_instant():
    """With the description before its payloads, ``payloads`` is the tick's: judged, then swapped.

    From none to 2 kg on the platform the efforts and reactions become those
    of ``Robot.solve`` of the robot built with it, to the bit; back to none,
    those without; a link the robot lacks, a bad entry or a mass not above 0
    is refused in one line naming the parameter, the masses kept. A tick built
    without the unloaded description does not list the parameter.
    """
    source = load_source(str(LIFT))
    tick = robot_forces_tick(source.robot, source.scene, drive=TOPIC, effort=STATIC,
                             unloaded=source.unloaded)
    tick.apply({'gravity': [0.0, 0.0, -9.80665], 'payloads': []})
    names = ['gravity', 'link_forces', 'link_torques', 'payloads']
    assert [p.name for p in tick.parameters()] == names
    first, q = tick.forces_first, 0.4
    plain = _from_input(tick, [q])[first:]
    entry = 'platform=2.0@0.1,0,0.05'
    values = {'gravity': [0.0, 0.0, -9.80665], 'payloads': [entry]}
    assert tick.parameters_refusal(values) is None
    tick.apply({'payloads': [entry]})       # what changed, as the node hands it over
    loaded = _from_input(tick, [q])[first:]
    answer = load_robot(LIFT, payloads={'platform': (2.0, (0.1, 0.0, 0.05))}).solve(
        {'lift_joint': q})
    assert loaded[0] == answer.efforts.efforts['lift_joint'] != plain[0]
    for k, name in enumerate(tick.reactions):
        r = answer.reactions[name]
        assert loaded[3 + 6 * k:3 + 6 * k + 6] == [*r.force, *r.torque]
    for entries, reason in ((['wing=1'], 'payloads: '), (['platform'], 'payloads: Expected LINK'),
                            (['platform=-1'], 'payloads: ')):
        refused = tick.parameters_refusal({**values, 'payloads': entries})
        assert refused is not None and refused.startswith(reason) and '\n' not in refused, refused
    assert 'payload on link "wing": Expected a link of the robot' in tick.parameters_refusal(
        {**values, 'payloads': ['wing=1']})
    assert _from_input(tick, [q])[first:] == loaded       # the masses kept
    tick.apply({'payloads': []})
    assert _from_input(tick, [q])[first:] == plain
    assert [p.name for p in _tick(source).parameters()] == ['gravity', 'link_forces',
                                                            'link_torques']


def test_link_loads_are_parameters_of_the_tick_judged_then_applied():
    """link_forces and link_torques: the efforts of Robot.solve with those loads, to the bit.

    Set as the node hands them over (what changed), refused in one line (a
    link the loops do not move, an entry not in the form), the loads kept.
    """
    from mech_kinematics.robot.forces import LinkLoad

    source = load_source(str(LIFT))
    tick = _tick(source)
    robot = load_robot(LIFT)
    first, q = tick.forces_first, 0.4
    forces, torques = ['platform=0,0,-30@0.1,0,0.05'], ['lower_arm=0,2.5,0']
    values = {'gravity': [0.0, 0.0, -9.80665], 'link_forces': forces, 'link_torques': torques}
    assert tick.parameters_refusal(values) is None
    tick.apply({'link_forces': forces, 'link_torques': torques})
    loads = [LinkLoad('platform', (0.0, 0.0, -30.0), (0.1, 0.0, 0.05), (0.0, 0.0, 0.0)),
             LinkLoad('lower_arm', torque=(0.0, 2.5, 0.0))]
    answer = robot.solve({'lift_joint': q}, loads=loads)
    out = _from_input(tick, [q])[first:]
    assert out[0] == answer.efforts.efforts['lift_joint']
    for k, name in enumerate(tick.reactions):
        r = answer.reactions[name]
        assert out[3 + 6 * k:3 + 6 * k + 6] == [*r.force, *r.torque]
    for key, entries, words in (
            ('link_forces', ['base_link=0,0,1'], 'link_forces: load on link "base_link": '
             'Expected a link a loop moves'),
            ('link_forces', ['platform=0,0'], 'link_forces: Expected LINK=FX,FY,FZ or'),
            ('link_torques', ['platform=1,2'], 'link_torques: Expected LINK=TX,TY,TZ')):
        refused = tick.parameters_refusal({**values, key: entries})
        assert refused is not None and refused.startswith(words), refused
    assert _from_input(tick, [q])[first:] == out
    tick.apply({'link_forces': [], 'link_torques': []})
    assert _from_input(tick, [q])[first] == robot.solve({'lift_joint': q}).efforts.efforts[
        'lift_joint']


def test_a_forces_parameter_that_does_not_apply_is_refused():
    """loads.* always; effort, gravity, payloads without masses; gravity with topic, dynamic."""
    lift = load_source(str(LIFT)).robot
    gripper = load_source(str(DATA / 'robotiq_2f_85.urdf'),
                          loop_closures=str(DATA / 'robotiq_2f_85.loop_closures.yaml')).robot
    assert robot_forces_note(lift) is None and robot_forces_note(gripper) == ''
    assert robot_forces_refusal(None, TIME, DYNAMIC, DYNAMIC, ['loads.a.force']).startswith(
        'Expected no loads.* in URDF mode')
    assert robot_forces_refusal(None, TIME, STATIC, DYNAMIC, ['gravity', 'payloads']) is None
    assert robot_forces_refusal(None, TOPIC, STATIC, DYNAMIC, ['gravity']) is None
    assert robot_forces_refusal(None, TOPIC, DYNAMIC, DYNAMIC, ['gravity']) == (
        'Expected effort:=static with drive: topic for gravity (the input gives no '
        'accelerations: the efforts are left out), got effort:=dynamic')
    assert robot_forces_refusal('', TIME, STATIC, DYNAMIC, ['gravity']) == (
        "Expected no forces parameters for this robot (the URDF's links carry no <inertial>: "
        'there are no forces to publish), got effort:=static, gravity')
    assert robot_forces_refusal('link "x": a reason', TIME, DYNAMIC, DYNAMIC, ['payloads']) == \
        'Expected no forces parameters for this robot (link "x": a reason), got payloads'
    assert robot_forces_refusal('', TIME, DYNAMIC, DYNAMIC, ['rate_hz']) is None
    assert robot_forces_tick(gripper, load_source(
        str(DATA / 'robotiq_2f_85.urdf'),
        loop_closures=str(DATA / 'robotiq_2f_85.loop_closures.yaml')).scene, drive=TIME,
        effort=STATIC) is None
    assert robot_forces_tick(lift, load_source(str(LIFT)).scene, drive=TOPIC,
                             effort=DYNAMIC) is None
