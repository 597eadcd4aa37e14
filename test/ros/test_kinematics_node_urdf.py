# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node in URDF mode over real DDS: between the motors' joint_states and robot_state_publisher.

See issue 31. A motor publisher in this process sends the actuated joints
(and a joint the robot does not have) at 200 Hz to a node started with
``scene:=ROBOT.urdf`` and ``drive:=topic``; every message must be answered
with complete joint states under the URDF's names (the actuated joints as
given, every joint of every loop, the other joint passed through unchanged),
and every answered state must close every loop of the URDF in the
independent 4x4 forward kinematics of test/helpers.py (``UrdfFk``) within
1e-12 of the loop's size. The node publishes the user's URDF on
``robot_description``, latched, byte for byte, and none of its own frames on
``/tf``.

Every node is first greeted: messages stamped before :data:`T0` are sent
until one is answered (a message sent before the subscription matched is
lost); their answers are not kept.
"""

from pathlib import Path
import signal
import time

from helpers import gepetto_five_bar_reference, khurmi_chain_urdf, UrdfFk
import numpy as np
import pytest
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from ros_helpers import (cannot_start, exited, NodeProcess, NS, RELIABLE, send_until, SESSION,
                         stamp_ns, STARTUP_S, wait_for)
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage
from trajectory_msgs.msg import JointTrajectory
import yaml

import mech_kinematics as mk
from mech_kinematics.robot import load_robot
from mech_kinematics.ros.startup import MAX_ARGUMENT_FILE_BYTES
from mech_kinematics.scene import MAX_FILE_BYTES

DATA = Path(__file__).resolve().parents[1] / 'data' / 'urdf'
#: The motors' rate, Hz, and how long they send, s.
MOTOR_HZ = 200
MOTOR_S = 2.0
#: A loop closes within this, over its size (the contract's exactness).
RTOL_CLOSURE = 1e-12
#: Published joints against Robot.solve at the same input (rad, m, /s): the same bits.
ATOL = 0.0
#: Deadline for the answers to arrive once the motors stop, s.
ANSWER_S = 20.0
T0 = 1_700_000_000 * NS
HELLO = T0 - 100 * NS
#: A joint of the input that the robot does not have (a wrist before the gripper).
OTHER = 'wrist_3_joint'
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)


class UrdfNode:
    """A node in URDF mode with drive: topic in a namespace of its own, and what it publishes."""

    def __init__(self, ros, tmp_path, name, robot, *args, closures=None, reference=None):
        self.ns = f'{SESSION}/{name}'
        self.urdf = DATA / f'{robot}.urdf'
        self.closures = closures or DATA / f'{robot}.loop_closures.yaml'
        self.robot = load_robot(self.urdf, self.closures, None, reference)
        self.greeted = []
        self.js = []
        self.jt_all = ros.collect(JointTrajectory, f'{self.ns}/joint_accelerations')
        self.description = ros.collect(String, f'{self.ns}/robot_description', LATCHED)
        self.tf = ros.collect(TFMessage, '/tf')
        self.tf_static = ros.collect(TFMessage, '/tf_static', LATCHED)

        def keep(msg):
            (self.js if stamp_ns(msg) >= T0 else self.greeted).append(msg)
        ros.node.create_subscription(JointState, f'{self.ns}/joint_states', keep, RELIABLE)
        self.input = ros.node.create_publisher(JointState, f'{self.ns}/input_joint_states',
                                               RELIABLE)
        self.proc = NodeProcess(tmp_path, '-r', f'__ns:={self.ns}', '-p', 'drive:=topic',
                                *args)

    @property
    def jt(self):
        return [msg for msg in self.jt_all if stamp_ns(msg) >= T0]

    def start(self):
        wait_for(lambda: self.input.get_subscription_count() > 0 or self.proc.proc.poll(),
                 STARTUP_S, 'the node subscribing to input_joint_states')
        assert self.proc.proc.poll() is None, self.proc.output()
        hello = [HELLO]

        def greet():
            self.send(hello[0], [self.robot.start(n) for n in self.robot.actuated], None)
            hello[0] += 1_000_000
        send_until(greet, lambda: self.greeted or self.proc.proc.poll() is not None,
                   STARTUP_S, 'the node answering a greeting', every=0.2)
        assert self.proc.proc.poll() is None, self.proc.output()

    def send(self, stamp, positions, speeds, other=(0.25, -1.5)):
        msg = JointState(name=[*self.robot.actuated, OTHER], position=[*positions, other[0]],
                         velocity=[] if speeds is None else [*speeds, other[1]])
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp, NS)
        self.input.publish(msg)

    def motors(self, count):
        """Send ``count`` messages at MOTOR_HZ on a deadline; return what was sent."""
        rng = np.random.default_rng(31)
        sent = []
        period = 1.0 / MOTOR_HZ
        start = time.monotonic()
        for i in range(count):
            t = i * period
            positions = [self.robot.start(n) + 0.3 * np.sin(2.0 * t + k)
                         for k, n in enumerate(self.robot.actuated)]
            speeds = [0.6 * np.cos(2.0 * t + k) for k in range(len(positions))]
            other = (float(rng.uniform(-3, 3)), float(rng.uniform(-3, 3)))
            stamp = T0 + round(t * NS)
            self.send(stamp, positions, speeds, other)
            sent.append((stamp, positions, speeds, other))
            delay = start + (i + 1) * period - time.monotonic()
            if delay > 0:
                time.sleep(delay)
        return sent

    def stop(self):
        status, _ = self.proc.stop()
        assert status == 0, self.proc.output()


@pytest.mark.parametrize('robot', ['robotiq_2f_85', 'abb_irb2400_12_155'])
def test_motors_at_200_hz_get_every_joint_of_the_urdf_closing_every_loop(ros, tmp_path, robot):
    """Each motor message: one joint_states, URDF names, loops closed to 1e-12, others passed."""
    node = UrdfNode(ros, tmp_path, f'urdf_{robot}', robot, '-p',
                    f'scene:={DATA / f"{robot}.urdf"}', '-p',
                    f'loop_closures:={DATA / f"{robot}.loop_closures.yaml"}')
    try:
        node.start()
        sent = node.motors(round(MOTOR_HZ * MOTOR_S))
        wait_for(lambda: len(node.js) >= len(sent) and len(node.jt) >= len(sent)
                 or node.proc.proc.poll() is not None, ANSWER_S, 'every motor message answered')
        wait_for(lambda: node.description, STARTUP_S, 'robot_description')
    finally:
        node.stop()
    robot_ = node.robot
    names = [*robot_.joint_names, OTHER]
    fk = UrdfFk(node.urdf.read_text(), node.closures)
    m = len(robot_.joint_names)
    assert [stamp_ns(msg) for msg in node.js] == [s[0] for s in sent]
    assert [stamp_ns(msg) for msg in node.jt] == [s[0] for s in sent]
    worst = 0.0
    for msg, jt, (_, positions, speeds, other) in zip(node.js, node.jt, sent, strict=True):
        assert msg.name == names
        assert (msg.position[m], msg.velocity[m]) == other      # passed through unchanged
        assert list(msg.position[:len(positions)]) == [float(p) for p in positions]
        answer = robot_.solve(dict(zip(robot_.actuated, positions, strict=True)),
                              dict(zip(robot_.actuated, speeds, strict=True)))
        np.testing.assert_allclose(msg.position[:m], [answer.joints[n].position
                                                      for n in robot_.joint_names],
                                   rtol=0, atol=ATOL)
        np.testing.assert_allclose(msg.velocity[:m], [answer.joints[n].velocity
                                                      for n in robot_.joint_names],
                                   rtol=0, atol=ATOL)
        assert jt.joint_names == list(robot_.joint_names) and not jt.points[0].accelerations
        gaps = fk.gaps(dict(zip(names, msg.position, strict=True)))
        worst = max(worst, *(gap / fk.loop_size(c) for c, gap in gaps.items()))
    assert worst <= RTOL_CLOSURE
    # robot_state_publisher needs a value for every moving joint of the URDF: here all.
    assert {n for n, j in fk.joints.items() if j[0] != 'fixed'} <= set(names)
    assert node.description[0].data == node.urdf.read_text()
    assert not node.tf and not node.tf_static      # robot_state_publisher draws the links


def test_the_urdf_text_as_robot_description_and_a_velocity_left_out(ros, tmp_path):
    """robot_description:=TEXT (a params file) runs the same robot; no velocity in, none out."""
    urdf = DATA / 'robotiq_2f_85.urdf'
    params = tmp_path / 'params.yaml'
    literal = '\n'.join('      ' + line for line in urdf.read_text().splitlines())
    params.write_text(f'/**:\n  ros__parameters:\n    robot_description: |-\n{literal}\n'
                      f'    loop_closures: {DATA / "robotiq_2f_85.loop_closures.yaml"}\n'
                      '    extra_joints: ignore\n')
    node = UrdfNode(ros, tmp_path, 'urdf_text', 'robotiq_2f_85', '--params-file', str(params))
    try:
        node.start()
        node.send(T0, [0.2], None)
        wait_for(lambda: node.js and node.description, ANSWER_S, 'the state and the URDF')
    finally:
        node.stop()
    msg = node.js[0]
    assert msg.name == list(node.robot.joint_names)     # extra_joints: ignore drops the wrist
    answer = node.robot.solve({'finger_joint': 0.2})
    assert list(msg.position) == [answer.joints[n].position for n in node.robot.joint_names]
    assert not msg.velocity
    assert node.description[0].data == urdf.read_text().rstrip('\n')


def test_a_urdf_exported_open_runs_from_its_reference_pose(ros, tmp_path):
    """Gepetto's five-bar, 0.3 m open at zero: reference_pose (rad) runs it as solve does.

    Issue 43, item 4: without it the node refuses the open pose in one line; with
    it, every motor message is answered with the joints of ``Robot.solve`` from the
    same reference, to the bit, closing the 6d closure in the test's own kinematics.
    """
    urdf = DATA / 'gepetto_5bar_linkage.urdf'
    closures = DATA / 'gepetto_5bar_linkage.robot.yaml'
    refused = NodeProcess(tmp_path / 'open', '-p', f'scene:={urdf}', '-p',
                          f'loop_closures:={closures}')
    status, output = exited(refused)
    lines = cannot_start(output)
    assert status != 0 and len(lines) == 1 and 'give a reference pose that closes it' in \
        lines[0], output
    reference = gepetto_five_bar_reference()
    pose = '[' + ', '.join(f'{n}={v!r}' for n, v in reference.items()) + ']'
    node = UrdfNode(ros, tmp_path, 'urdf_reference', 'gepetto_5bar_linkage', '-p',
                    f'scene:={urdf}', '-p', f'loop_closures:={closures}', '-p',
                    f'reference_pose:={pose}', '-p', 'extra_joints:=ignore',
                    closures=closures, reference=reference)
    robot = node.robot
    sent = [[0.1, -0.2], [0.3, -0.1], [-0.2, 0.25]]
    try:
        node.start()
        for i, positions in enumerate(sent):
            node.send(T0 + i * NS, [robot.start(n) + p for n, p in
                                    zip(robot.actuated, positions, strict=True)], None)
        wait_for(lambda: len(node.js) >= len(sent) or node.proc.proc.poll() is not None,
                 ANSWER_S, 'every motor message answered')
    finally:
        node.stop()
    assert 'reference_pose=' in node.proc.output()     # the start line says it
    fk = UrdfFk(urdf.read_text(), closures)
    for msg, positions in zip(node.js, sent, strict=True):
        given = {n: robot.start(n) + p for n, p in zip(robot.actuated, positions, strict=True)}
        answer = robot.solve(given)
        assert msg.name == list(robot.joint_names)
        assert list(msg.position) == [answer.joints[n].position for n in robot.joint_names]
        gaps = fk.gaps(dict(zip(msg.name, msg.position, strict=True)))
        assert max(gap / fk.loop_size(c) for c, gap in gaps.items()) <= RTOL_CLOSURE


#: Motor states (finger_joint rad, rad/s) sent to the gripper: through both change points of
#: its parallelograms (near 1.94 and 5.08 rad), a jump of more than pi, 40 rad, back.
ONE_ANSWER = [(0.3, 0.5), (1.0, -1.0), (2.5, 2.0), (-1.5, 0.0), (3.6, 1.5), (5.5, -0.7),
              (40.0, 3.0), (-3.0, 0.1), (12.0, -2.0), (0.2, 0.0)]


def test_the_node_answers_what_robot_solve_answers_to_the_bit(ros, tmp_path):
    """Issue 43, item 5: every published joint == Robot.solve's for the same motor state.

    The Robotiq 2F-85 in topic drive, its <mimic> rules picking the parallel
    assembly wherever the reference branch alone answered the crossed one;
    each state, whatever the one before (a jump of 3.7 rad, 40 rad after
    5.5), is answered as Robot.solve answers it: positions and velocities
    equal (==), no mimic stray, loops closed in the test's own kinematics.
    """
    robot = 'robotiq_2f_85'
    node = UrdfNode(ros, tmp_path, 'urdf_one_answer', robot, '-p',
                    f'scene:={DATA / f"{robot}.urdf"}', '-p',
                    f'loop_closures:={DATA / f"{robot}.loop_closures.yaml"}', '-p',
                    'extra_joints:=ignore')
    try:
        node.start()
        for i, (q, w) in enumerate(ONE_ANSWER):
            node.send(T0 + i * NS, [q], [w])
        wait_for(lambda: len(node.js) >= len(ONE_ANSWER) or node.proc.proc.poll() is not None,
                 ANSWER_S, 'every motor state answered')
    finally:
        node.stop()
    robot_ = node.robot
    fk = UrdfFk(node.urdf.read_text(), node.closures)
    assert [stamp_ns(msg) for msg in node.js] == [T0 + i * NS for i in range(len(ONE_ANSWER))]
    crossed = []
    for i, (msg, (q, w)) in enumerate(zip(node.js, ONE_ANSWER, strict=True)):
        answer = robot_.solve({'finger_joint': q}, {'finger_joint': w})
        assert answer.mimic == {}
        assert msg.name == list(robot_.joint_names)
        assert list(msg.position) == [answer.joints[n].position for n in robot_.joint_names]
        assert list(msg.velocity) == [answer.joints[n].velocity for n in robot_.joint_names]
        gaps = fk.gaps(dict(zip(msg.name, msg.position, strict=True)))
        assert max(gap / fk.loop_size(c) for c, gap in gaps.items()) <= RTOL_CLOSURE
        # The zero pose's branches alone (robot.scene) answer the crossed assembly here.
        inputs = {'finger_joint': (q, w, 0.0)}
        p, v, a = robot_.scene_inputs(inputs)
        alone = robot_.joints_from_state(mk.solve(robot_.scene, p, v, a), inputs)
        if alone.mimic:
            crossed.append(i)
    assert crossed == [2, 3, 4, 6, 7]     # 2.5, 4.78 less a turn, 3.6, 40 and 3.28 less a turn


def test_a_robot_description_over_1_mib_is_taken_from_a_params_file(ros, tmp_path):
    """Issue 42: a params file over 1 MiB was refused, though robot_description may be 8 MiB.

    The gripper's URDF padded by a comment to 4 MiB, in a params file as launch_ros writes
    one (a double-quoted YAML string): the node starts and publishes the text unchanged.
    The largest robot_description fits in the largest params file.
    """
    urdf = DATA / 'robotiq_2f_85.urdf'
    text = urdf.read_text().replace('<robot ', f'<!-- {"x" * (4 << 20)} -->\n<robot ', 1)
    assert 1 << 20 < len(text.encode()) < MAX_FILE_BYTES
    params = tmp_path / 'params.yaml'
    params.write_text(yaml.safe_dump({'/**': {'ros__parameters': {
        'robot_description': text,
        'loop_closures': str(DATA / 'robotiq_2f_85.loop_closures.yaml')}}}, width=1 << 30))
    assert params.stat().st_size > 1 << 20
    node = UrdfNode(ros, tmp_path, 'urdf_4mib', 'robotiq_2f_85', '--params-file', str(params))
    try:
        node.start()
        node.send(T0, [0.2], None)
        wait_for(lambda: node.js and node.description, ANSWER_S, 'the state and the URDF')
    finally:
        node.stop()
    answer = node.robot.solve({'finger_joint': 0.2})
    assert list(node.js[0].position)[:len(node.robot.joint_names)] == \
        [answer.joints[n].position for n in node.robot.joint_names]
    assert node.description[0].data == text
    assert MAX_ARGUMENT_FILE_BYTES >= 2 * MAX_FILE_BYTES


def test_a_stop_while_the_start_reads_a_large_urdf_ends_it_at_once(ros, tmp_path):
    """Issue 42: SIGTERM while a 40,000-joint URDF was read took 19-26 s to end the node.

    The node is signalled once it logs (at debug) that it reads; it ends with status 0,
    no traceback, its start line never logged, in less time than it took to come up to
    the read (Python, rclpy, the node: seconds), where it used to finish the read first.
    """
    path = tmp_path / 'chain.urdf'
    path.write_text(khurmi_chain_urdf(40_000))
    assert path.stat().st_size < MAX_FILE_BYTES
    ns = f'{SESSION}/urdf_stop'
    logger = f'{ns.strip("/").replace("/", ".")}.mech_kinematics'
    started = time.monotonic()
    proc = NodeProcess(tmp_path / 'node', '-r', f'__ns:={ns}', '-p', f'scene:={path}',
                       '--log-level', f'{logger}:=debug')
    try:
        wait_for(lambda: 'reading the scene or robot' in proc.output()
                 or proc.proc.poll() is not None, STARTUP_S, 'the node reading')
        up_s = time.monotonic() - started
        assert proc.proc.poll() is None, proc.output()
        status, took_s = proc.stop(signal.SIGTERM, timeout=120.0)
    finally:
        if proc.proc.poll() is None:
            proc.proc.kill()
    output = proc.output()
    assert "robot 'khurmi'" not in output, output        # stopped within the read
    assert status == 0 and 'Traceback' not in output and not cannot_start(output), output
    assert took_s < up_s, (took_s, up_s)


@pytest.mark.parametrize('args, line', [
    (('-p', 'loop_closures:=x.yaml'), 'cannot start: Expected loop_closures with a robot '
     'described in URDF (scene:=PATH.urdf or robot_description), got scene'),
    (('-p', f'scene:={DATA / "robotiq_2f_85.urdf"}', '-p', 'actuated_joints:=[finger_joint]'),
     'Expected a robot with a closed loop'),
    (('-p', 'actuated_joints:=[a, a]'), 'cannot start: actuated_joints: expected one or more '
     "distinct non-empty joint names, got ['a', 'a']"),
    # Issue 44: forces parameters that do not apply in URDF mode, and bad ones.
    (('-p', f'scene:={DATA / "lift_arm.urdf"}', '-p', 'loads.tool.force:=[1.0, 0.0]'),
     "cannot start: Expected no loads.* in URDF mode (a robot's loads are point masses on "
     'its links, payloads:=["LINK=KG@X,Y,Z"], and forces and torques on its links, '
     'link_forces:=["LINK=FX,FY,FZ@X,Y,Z"] and link_torques), got loads.tool.force'),
    (('-p', f'scene:={DATA / "lift_arm.urdf"}', '-p', "link_forces:=['base_link=0,0,1']"),
     'link_forces: load on link "base_link": Expected a link a loop moves'),
    (('-p', "link_torques:=['crank=0,0,1']"), 'cannot start: Expected link_torques with a robot '
     'described in URDF'),
    (('-p', f'scene:={DATA / "lift_arm.urdf"}', '-p', "payloads:=['wing=1.5@0,0,0.1']"),
     'payload on link "wing": Expected a link of the robot (base_link, lower_arm'),
    (('-p', f'scene:={DATA / "lift_arm.urdf"}', '-p', 'gravity:=[0.0, 0.0, 1e308]'),
     "cannot start: gravity: Expected gravity as [gx, gy, gz] in the URDF's root frame"),
    (('-p', f'scene:={DATA / "lift_arm.urdf"}', '-p', 'drive:=topic', '-p',
      'gravity:=[0.0, 0.0, -1.62]'),
     'cannot start: Expected effort:=static with drive: topic for gravity'),
    # Issue 41: a target message names targets only.
    (('-p', 'scene:=five_bar', '-p', 'drive:=target', '-p', 'extra_joints:=ignore'),
     'cannot start: extra_joints: Expected drive: target without extra_joints (a message names '
     'targets or drivers only), got extra_joints'),
    (('-p', 'scene:=five_bar', '-p', 'target_branch:=[B=+1]'),
     'cannot start: target_branch: Expected drive: target or trajectory with target_branch'),
    (('-p', 'scene:=five_bar', '-p', 'drive:=target', '-p', 'target_branch:=[A=+1]'),
     'cannot start: Expected target_branch to name joints between two moving bodies'),
    (('-p', f'scene:={DATA / "lift_arm.urdf"}', '-p', 'drive:=trajectory', '-p',
      'extra_joints:=pass'),
     'cannot start: extra_joints: Expected drive: trajectory without extra_joints (a message '
     'names targets or drivers only), got extra_joints'),
    (('-p', f'scene:={DATA / "robotiq_2f_85.urdf"}', '-p',
      f'loop_closures:={DATA / "robotiq_2f_85.loop_closures.yaml"}', '-p', 'effort:=static'),
     "cannot start: Expected no forces parameters for this robot (the URDF's links carry no "
     '<inertial>: there are no forces to publish), got effort:=static'),
])
def test_a_robot_the_node_cannot_take_is_refused_in_one_line(tmp_path, args, line):
    """A URDF parameter that does not fit: the node does not start and says why in one line."""
    proc = NodeProcess(tmp_path, *args)
    status, output = exited(proc)
    lines = cannot_start(output)
    assert status != 0 and len(lines) == 1 and line in lines[0], output


def test_on_the_clock_a_robots_loops_move_with_the_scenes_drivers(ros, tmp_path):
    """drive: time (make run): URDF joints on the grid, loops closed, the mimic driver warned."""
    urdf, closures = DATA / 'robotiq_2f_85.urdf', DATA / 'robotiq_2f_85.loop_closures.yaml'
    robot = load_robot(urdf, closures)
    ns = f'{SESSION}/urdf_clock'
    received = ros.collect(JointState, f'{ns}/joint_states')
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns}', '-p', f'scene:={urdf}', '-p',
                       f'loop_closures:={closures}', '-p', 'rate_hz:=50.0', '-p',
                       'inputs.left_outer_knuckle.speed_rpm:=0.5')
    try:
        wait_for(lambda: len(received) >= 10 or proc.proc.poll() is not None, STARTUP_S,
                 'ten states on the clock')
    finally:
        status, _ = proc.stop()
    assert status == 0, proc.output()
    fk = UrdfFk(urdf.read_text(), closures)
    m = len(robot.joint_names)
    for msg in received[:10]:
        assert msg.name == list(robot.joint_names) and len(msg.velocity) == m
        gaps = fk.gaps(dict(zip(msg.name, msg.position, strict=True)))
        assert max(gap / fk.loop_size(c) for c, gap in gaps.items()) <= RTOL_CLOSURE
    # The left finger turns at 0.5 rpm about -z of its scene link (finger_joint's sigma -1).
    assert received[0].velocity[0] == -0.5 * 2 * np.pi / 60
    assert 'right_outer_knuckle (right_outer_knuckle_joint mimics finger_joint) move on ' \
        'their own' in proc.output()
