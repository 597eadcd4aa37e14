# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node in URDF mode publishes a robot's efforts and reactions, over real DDS (issue 44).

One node, started once for the module: the four-bar lift arm of
test/data/urdf/lift_arm.urdf (its links carry ``<inertial>``s) with a 2 kg
payload on its platform (``payloads``), driven from a topic with ``effort:
static`` and ``tf_prefix: arm1``. The motor's messages are sent from this
process until answered; each answer is judged against values that do not come
from the node:

- the hand check of the parallelogram: both arms turn by the motor's angle q
  and the platform (payload included) translates with the lower arm's tip, so
  the holding torque is ``g cos q (m1 r1 + M L + m3 r3)``, one ``m g r cos q``
  per link, positive along lift_joint's axis (it lifts);
- ``Robot.solve`` of the same robot and payload at the same input: the same
  effort within its error bound, the same reactions within theirs;
- the reactions turned into the root's frame by the test's own 4x4 forward
  kinematics (``UrdfFk``) from each message's child link: the ground pins
  carry the whole weight, the platform's pins the platform's.

Then ``gravity`` set while running (the effort follows the hand check with
the new gravity), and refused through the parameter service where it is no
gravity (the node answers the next input as before).
"""

import math
from pathlib import Path

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import WrenchStamped
from helpers import UrdfFk
import numpy as np
import pytest
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from ros_helpers import (NodeProcess, NS, RELIABLE, send_until, SESSION, stamp_ns, STARTUP_S,
                         wait_for, wait_for_parameters)
from sensor_msgs.msg import JointState

from mech_kinematics.robot import load_robot
from mech_kinematics.ros import topics

LIFT = Path(__file__).resolve().parents[1] / 'data' / 'urdf' / 'lift_arm.urdf'
G = 9.80665
#: The lift arm's masses (kg) and lengths (m), as its URDF writes them, and the payload.
M_LOWER, R_LOWER = 2.0, 0.25
M_UPPER, R_UPPER = 1.2, 0.25
M_PLATFORM = 0.8 + 3.0 + 1e-9      # the platform, the payload link and the dummy tool frame
L_ARM = 0.5
PAYLOAD_KG = 2.0
PAYLOAD = f'platform={PAYLOAD_KG!r}@0.1,0,0.05'
PREFIX = 'arm1'
#: Each reaction's child link (its message's frame_id, after the prefix).
CHILDREN = {'lift_joint': 'lower_arm', 'upper_pivot': 'upper_arm', 'elbow': 'platform',
            'pin_C': 'upper_arm'}
T0 = 1_700_000_000 * NS


def _hand_torque(q, g=G, payload=PAYLOAD_KG):
    """Return the static motor torque by hand: ``g cos q (m1 r1 + M L + m3 r3)``."""
    platform = M_PLATFORM + payload
    return g * math.cos(q) * (M_LOWER * R_LOWER + platform * L_ARM + M_UPPER * R_UPPER)


class LiftNode:
    """The lift arm's node in a namespace of its own, and what it publishes by stamp."""

    def __init__(self, ros, tmp):
        self.ros = ros
        self.ns = f'{SESSION}/urdf_forces'
        self.sent = {}
        self.stamp = T0
        self.js = {}
        ros.node.create_subscription(JointState, f'{self.ns}/joint_states',
                                     lambda m: self.js.setdefault(stamp_ns(m), m), RELIABLE)
        self.wrenches = {name: {} for name in CHILDREN}
        for name, got in self.wrenches.items():
            ros.node.create_subscription(
                WrenchStamped, f'{self.ns}/{topics.reaction_topic(name)}',
                lambda m, got=got: got.setdefault(stamp_ns(m), m), RELIABLE)
        self.diag = ros.collect(DiagnosticArray, f'{self.ns}/diagnostics')
        self.input = ros.node.create_publisher(JointState, f'{self.ns}/input_joint_states',
                                               RELIABLE)
        self.proc = NodeProcess(tmp, '-r', f'__ns:={self.ns}', '-p', f'scene:={LIFT}', '-p',
                                'drive:=topic', '-p', 'effort:=static', '-p',
                                f"payloads:=['{PAYLOAD}']", '-p', f'tf_prefix:={PREFIX}')
        self.params = AsyncParameterClient(ros.node, f'{self.ns}/mech_kinematics')
        wait_for_parameters(self.params)

    def answer(self, q):
        """Send lift_joint = q (again, each with a new stamp) until answered; return the answer.

        The answer: the joint_states message and each reaction's wrench of one stamp
        sent by this call (an earlier call's answer at the same q had other parameters).
        """
        first = self.stamp

        def send():
            self.stamp += NS // 100
            msg = JointState(name=['lift_joint'], position=[q], velocity=[0.5])
            msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(self.stamp, NS)
            self.sent[self.stamp] = q
            self.input.publish(msg)

        def answered():
            for stamp, value in list(self.sent.items()):
                if stamp > first and value == q and stamp in self.js and all(
                        stamp in got for got in self.wrenches.values()):
                    return self.js[stamp], {n: got[stamp] for n, got in self.wrenches.items()}
            return None
        assert self.proc.proc.poll() is None, self.proc.output()
        return send_until(send, answered, STARTUP_S, f'the state and reactions at q = {q}')

    def set(self, name, value):
        [result] = self.ros.call(self.params.set_parameters(
            [Parameter(name, value=value)])).results
        return result

    def diagnostics(self, key):
        return [v.value for m in list(self.diag) for s in m.status for v in s.values
                if v.key == key]


@pytest.fixture(scope='module')
def node(ros, tmp_path_factory):
    node = LiftNode(ros, tmp_path_factory.mktemp('urdf_forces'))
    yield node
    status, _ = node.proc.stop()
    assert status == 0, node.proc.output()


@pytest.fixture(scope='module')
def robot():
    return load_robot(LIFT, payloads={'platform': (PAYLOAD_KG, (0.1, 0.0, 0.05))})


def _wrench(msg):
    w = msg.wrench
    return (np.array([w.force.x, w.force.y, w.force.z]),
            np.array([w.torque.x, w.torque.y, w.torque.z]))


def test_the_motor_torque_is_robot_solves_and_the_hand_check(node, robot):
    """effort: static under lift_joint: Robot.solve's within its bound, g cos q sum m r; 0 else."""
    for q in (-0.9, 0.0, 0.35, 1.1):
        msg, _ = node.answer(q)
        assert msg.name == ['lift_joint', 'upper_pivot', 'elbow']
        answer = robot.solve({'lift_joint': q})      # static: at rest, the default gravity
        expected = answer.efforts.efforts['lift_joint']
        bound = answer.efforts.bounds['lift_joint']
        assert abs(msg.effort[0] - expected) <= bound, (msg.effort[0], expected, bound)
        assert msg.effort[0] == pytest.approx(_hand_torque(q), rel=1e-12)
        assert msg.effort[0] > 0.0       # holding the arm up: along lift_joint's <axis>
        assert list(msg.effort[1:]) == [0.0, 0.0]    # passive pins, frictionless
        assert list(msg.velocity)[0] == 0.5          # the input's, echoed (inertia neglected)
    assert 'gravity=[0.0, 0.0, -9.80665]' in node.proc.output()     # the start line
    assert f"payloads=['{PAYLOAD}']" in node.proc.output()


def test_reactions_arrive_in_the_child_links_frames_and_carry_the_weights(node, robot):
    """reactions/JOINT: frame_id PREFIX/child link, stamped like the state; weights balance."""
    fk = UrdfFk(LIFT.read_text())
    total = M_LOWER + M_UPPER + M_PLATFORM + PAYLOAD_KG
    for q in (-0.5, 0.8):
        msg, wrenches = node.answer(q)
        answer = robot.solve({'lift_joint': q})
        frames = fk.transforms(dict(zip(msg.name, msg.position, strict=True)))
        root = {}
        for name, wrench in wrenches.items():
            assert wrench.header.frame_id == f'{PREFIX}/{CHILDREN[name]}'
            assert stamp_ns(wrench) == stamp_ns(msg)
            force, torque = _wrench(wrench)
            expected = answer.reactions[name]
            assert np.abs(force - expected.force).max() <= expected.force_bound
            assert np.abs(torque - expected.torque).max() <= expected.torque_bound
            root[name] = frames[CHILDREN[name]][:3, :3] @ force
        weight = np.array([0.0, 0.0, G])        # what the pins hold up
        np.testing.assert_allclose(root['lift_joint'] + root['upper_pivot'], total * weight,
                                   rtol=0, atol=1e-12 * total * G)
        np.testing.assert_allclose(root['elbow'] - root['pin_C'],
                                   (M_PLATFORM + PAYLOAD_KG) * weight, rtol=0,
                                   atol=1e-12 * total * G)
        # The motor's torque about its axis (-y): its effort; a passive pin's none.
        _, torque = _wrench(wrenches['lift_joint'])
        assert tuple(torque) == (0.0, -msg.effort[0], 0.0)
        assert tuple(_wrench(wrenches['elbow'])[1]) == (0.0, 0.0, 0.0)


def test_gravity_changed_while_running_changes_the_effort(node, robot):
    """Gravity [gx, gy, gz] in the root frame: set, refused where it is no gravity, kept."""
    for value, reason in (([0.0, 0.0, math.nan], 'gravity: expected three finite numbers'),
                          ([0.0, 0.0, 1e308], 'gravity: Expected gravity as [gx, gy, gz]'),
                          ([0.0, -9.8], 'gravity: expected [x, y, z], three numbers'),
                          ('down', 'gravity: expected [x, y, z] (m/s^2), got string')):
        result = node.set('gravity', value)
        assert not result.successful
        assert result.reason.startswith(reason), result.reason
    msg, _ = node.answer(0.2)        # still answering, with the gravity it had
    assert msg.effort[0] == pytest.approx(_hand_torque(0.2), rel=1e-12)
    assert node.set('gravity', [0, 0, -2]).successful       # integers, as -p gives them
    msg, _ = node.answer(0.6)
    assert msg.effort[0] == pytest.approx(_hand_torque(0.6, 2.0), rel=1e-12)
    answer = robot.solve({'lift_joint': 0.6}, gravity=(0.0, 0.0, -2.0))
    assert abs(msg.effort[0] - answer.efforts.efforts['lift_joint']) <= \
        answer.efforts.bounds['lift_joint']
    # Along the root's +x: the torque is g sin q times the same sum (PE = -g x).
    assert node.set('gravity', [G, 0.0, 0.0]).successful
    msg, _ = node.answer(0.4)
    assert msg.effort[0] == pytest.approx(_hand_torque(0.4) * math.tan(0.4), rel=1e-12)
    # None: no effort, no reaction.
    assert node.set('gravity', [0.0, 0.0, 0.0]).successful
    msg, wrenches = node.answer(0.3)
    assert list(msg.effort) == [0.0, 0.0, 0.0]
    assert all(not _wrench(w)[0].any() for w in wrenches.values())
    wait_for(lambda: '[0.0, 0.0, 0.0]' in node.diagnostics('gravity'), STARTUP_S,
             'diagnostics saying the gravity used')
    assert node.diagnostics('effort')[-1] == 'static: gravity and loads only, inertia neglected'
    assert node.proc.proc.poll() is None, node.proc.output()


def test_payloads_changed_while_running_change_the_effort(node):
    """``payloads`` set while running: the hand torque with the new mass; a bad one refused."""
    assert node.set('gravity', [0.0, 0.0, -G]).successful
    assert node.set('payloads', ['platform=3.5@0.1,0,0.05']).successful
    msg, _ = node.answer(0.25)
    assert msg.effort[0] == pytest.approx(_hand_torque(0.25, payload=3.5), rel=1e-12)
    for value, words in ((['wing=1'], 'payload on link "wing": Expected a link of the robot'),
                         (['platform'], 'payloads: Expected LINK=KG or LINK=KG@X,Y,Z')):
        result = node.set('payloads', value)
        assert not result.successful and words in result.reason, result.reason
    msg, _ = node.answer(0.35)         # the masses it had
    assert msg.effort[0] == pytest.approx(_hand_torque(0.35, payload=3.5), rel=1e-12)
    assert node.set('payloads', [PAYLOAD]).successful
    msg, _ = node.answer(0.45)
    assert msg.effort[0] == pytest.approx(_hand_torque(0.45), rel=1e-12)
    assert node.proc.proc.poll() is None, node.proc.output()


def test_link_forces_changed_while_running_change_the_effort(node):
    """``link_forces`` set while running: a weight-like force is a payload's torque by hand."""
    assert node.set('gravity', [0.0, 0.0, -G]).successful
    assert node.set('link_forces', [f'platform=0,0,{-1.5 * G!r}@0.1,0,0.05']).successful
    msg, _ = node.answer(0.55)
    assert msg.effort[0] == pytest.approx(_hand_torque(0.55, payload=PAYLOAD_KG + 1.5),
                                          rel=1e-12)
    result = node.set('link_forces', ['base_link=0,0,1'])
    assert not result.successful and 'Expected a link a loop moves' in result.reason
    assert node.set('link_forces', []).successful
    msg, _ = node.answer(0.65)
    assert msg.effort[0] == pytest.approx(_hand_torque(0.65), rel=1e-12)
    assert node.proc.proc.poll() is None, node.proc.output()
