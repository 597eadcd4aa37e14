# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node driven by a trajectory (``drive: trajectory``, issue 41, item 3), over real DDS.

This process publishes ``trajectory_msgs/JointTrajectory`` messages on the
node's ``input_trajectory``: points of the packaged five-bar with a payload
(masses), either of its motors or of its effector P (``P.x``, ``P.y``), each
with positions, velocities and accelerations. The node publishes one state per
point stamped at the header's stamp plus the point's ``time_from_start``, its
accelerations and the motors' efforts of that motion (the feed-forward torques)
in ``joint_states.effort``: checked against ``mk.solve`` and
``mk.solve_targets`` at the same motion. A point without accelerations is
refused on diagnostics while the points after it are answered. The packaged
gripper's fingertip IMU publishes each point's reading. In URDF mode the lift
arm (``<inertial>``s) is driven by points of its motor and of its tool frame's
height: ``joint_states`` names the URDF's joints, checked against
``Robot.solve`` and ``Robot.solve_targets`` at the same motion, the motor's
effort (gravity in the root frame and inertia) included.
"""

from pathlib import Path

from diagnostic_msgs.msg import DiagnosticStatus
from helpers import UrdfFk
import numpy as np
import pytest
from rclpy.qos import QoSProfile, ReliabilityPolicy
from ros_helpers import SESSION, stamp_ns, wait_for
from sensor_msgs.msg import Imu
from test_kinematics_node_topic import ANSWER_S, T0, TopicNode
from trajectory_msgs.msg import JointTrajectory

import mech_kinematics as mk
from mech_kinematics.robot import load_robot

SCENE = 'five_bar_payload'
FIVE = mk.load_scene(SCENE)
MOTORS = [d.name for d in FIVE.drivers]
START = [d.start for d in FIVE.drivers]
MS = 1_000_000
#: Published against the general solver's values (the node serves forces from it too).
ATOL = 1e-12


def trajectory_node(ros, tmp_path, name):
    return TopicNode(ros, tmp_path, name, scene=SCENE, drive='trajectory',
                     input_topic=f'{SESSION}/{name}/input_trajectory',
                     input_type=JointTrajectory, greeting=(MOTORS, START))


def motion(t):
    """Return the motors' (positions, speeds, accelerations) at ``t`` s: a smooth swing."""
    w = 3.0
    q = [START[0] + 0.1 * np.sin(w * t), START[1] - 0.05 * np.sin(2 * w * t)]
    qd = [0.1 * w * np.cos(w * t), -0.1 * w * np.cos(2 * w * t)]
    qdd = [-0.1 * w * w * np.sin(w * t), 0.2 * w * w * np.sin(2 * w * t)]
    return [float(x) for x in q], [float(x) for x in qd], [float(x) for x in qdd]


def test_each_point_of_the_motors_is_published_at_its_time_with_its_efforts(ros, tmp_path):
    node = trajectory_node(ros, tmp_path, 'trajectory_motors')
    times = [5 * MS * i for i in range(1, 9)]
    points = [(at, *motion(at / 1e9)) for at in times]
    try:
        node.send_points(T0, MOTORS, points)
        wait_for(lambda: len(node.js) >= len(points), ANSWER_S, 'joint_states')
        wait_for(lambda: len(node.jt) >= len(points), ANSWER_S, 'joint_accelerations')
        assert node.proc.proc.poll() is None
    finally:
        node.stop()
    assert [stamp_ns(m) for m in node.js] == [T0 + at for at in times]
    joints = list(FIVE.output_joints)
    for js, jt, (_, q, qd, qdd) in zip(node.js, node.jt, points, strict=True):
        state = mk.solve(FIVE, q, qd, qdd)
        assert js.name == joints
        np.testing.assert_allclose(js.position, [state.joints[n].position for n in joints],
                                   rtol=0, atol=ATOL)
        np.testing.assert_allclose(jt.points[0].accelerations,
                                   [state.joints[n].acceleration for n in joints],
                                   rtol=0, atol=1e-9)
        efforts = [state.forces.efforts.get(n, 0.0) for n in joints]
        np.testing.assert_allclose(js.effort, efforts, rtol=1e-9, atol=1e-9)


def test_points_of_the_effector_and_a_point_refused(ros, tmp_path):
    """P's path with its rates: the motors' motion is solve_targets'; a bad point is refused."""
    node = trajectory_node(ros, tmp_path, 'trajectory_targets')
    base = mk.solve(FIVE, START, [0.0, 0.0], [0.0, 0.0]).points['P'].position
    goals = [([float(base[0]) + 0.002 * i, float(base[1]) - 0.001 * i], [0.2, -0.1], [1.0, 0.5])
             for i in range(1, 6)]
    points = [(5 * MS * i, p, v, a) for i, (p, v, a) in enumerate(goals, start=1)]
    bad = (27 * MS, goals[-1][0], goals[-1][1], [])       # no accelerations
    try:
        seen = len(node.diag)
        node.send_points(T0, ['P.x', 'P.y'], [*points[:3], bad, *points[3:]])
        wait_for(lambda: len(node.js) >= len(points), ANSWER_S, 'joint_states')
        status = wait_for(lambda: node.refusal(seen, 'refused input'), ANSWER_S,
                          'diagnostics saying refused input')
        assert status.level == DiagnosticStatus.ERROR
        last_error = {v.key: v.value for v in status.values}['last_error']
        assert last_error.startswith('input_trajectory: expected one velocity and one '
                                     'acceleration per name')
        assert node.proc.proc.poll() is None
    finally:
        node.stop()
    assert [stamp_ns(m) for m in node.js] == [T0 + at for at, *_ in points]
    joints = list(FIVE.output_joints)
    start = START
    for js, (_, p, v, a) in zip(node.js, points, strict=True):
        inverse = mk.solve_targets(FIVE, {'P.x': p[0], 'P.y': p[1]}, {'P.x': v[0], 'P.y': v[1]},
                                   {'P.x': a[0], 'P.y': a[1]}, start=start)
        start = list(inverse.motion[:, 0])
        motors = [js.position[joints.index(n)] for n in MOTORS]
        np.testing.assert_allclose(motors, inverse.motion[:, 0], rtol=0, atol=1e-12)
        speeds = [js.velocity[joints.index(n)] for n in MOTORS]
        np.testing.assert_allclose(speeds, inverse.motion[:, 1], rtol=0, atol=1e-12)
        forward = mk.solve(FIVE, *(list(inverse.motion[:, k]) for k in range(3)))
        np.testing.assert_allclose(forward.points['P'].acceleration, a, atol=1e-9)
        efforts = [forward.forces.efforts.get(n, 0.0) for n in joints]
        np.testing.assert_allclose(js.effort, efforts, rtol=1e-9, atol=1e-9)


def test_each_point_gives_the_imus_readings(ros, tmp_path):
    """The gripper's fingertip IMU: each point's reading is solve's at that motion, stamped so."""
    gripper = mk.load_scene('gripper')
    crank = gripper.drivers[0].name
    [sensor] = [spec.name for spec in gripper.imus]
    ns_name = 'trajectory_imu'
    imus = ros.collect(Imu, f'{SESSION}/{ns_name}/imu/{sensor}',
                       QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE))
    node = TopicNode(ros, tmp_path, ns_name, scene='gripper', drive='trajectory',
                     input_topic=f'{SESSION}/{ns_name}/input_trajectory',
                     input_type=JointTrajectory, greeting=([crank], [gripper.drivers[0].start]))
    start = gripper.drivers[0].start
    points = [(5 * MS * i, [start + 0.02 * i], [1.5 - 0.1 * i], [4.0 * (-1) ** i])
              for i in range(1, 7)]
    stamps = [T0 + at for at, *_ in points]
    try:
        node.send_points(T0, [crank], points)
        wait_for(lambda: len([m for m in imus if stamp_ns(m) in stamps]) >= len(points),
                 ANSWER_S, f'imu/{sensor}')
        assert node.proc.proc.poll() is None
    finally:
        node.stop()
    got = {stamp_ns(m): m for m in imus if stamp_ns(m) in stamps}
    for (at, q, qd, qdd) in points:
        reading = mk.solve(gripper, q[0], qd[0], qdd[0]).as_dict()['imus'][sensor]
        msg = got[T0 + at]
        assert msg.angular_velocity.z == pytest.approx(reading['angular_velocity'], rel=1e-12)
        a = msg.linear_acceleration
        np.testing.assert_allclose([a.x, a.y], reading['linear_acceleration'], rtol=0,
                                   atol=1e-12 * np.hypot(*reading['linear_acceleration']))


LIFT = Path(__file__).resolve().parents[1] / 'data' / 'urdf' / 'lift_arm.urdf'


def test_a_urdf_robot_by_its_motor_and_by_its_tool_frame_with_its_efforts(ros, tmp_path):
    """The lift arm's points: the URDF's joints, their accelerations and the motor's effort."""
    robot = load_robot(LIFT)
    fk = UrdfFk(LIFT.read_text())
    start = robot.start('lift_joint')
    name = 'trajectory_urdf'
    node = TopicNode(ros, tmp_path, name, scene=str(LIFT), drive='trajectory',
                     input_topic=f'{SESSION}/{name}/input_trajectory',
                     input_type=JointTrajectory, greeting=(['lift_joint'], [start]))
    motor = [(5 * MS * i, [start + 0.01 * i], [0.3 - 0.05 * i], [2.0 * (-1) ** i])
             for i in range(1, 6)]
    last = robot.solve({'lift_joint': motor[-1][1][0]}, forces=False)
    z0 = float(fk.transforms({n: float(j.position) for n, j in last.joints.items()})[
        'tool_frame'][2, 3])
    tool = [(5 * MS * i, [z0 + 0.004 * (i - 5)], [0.05], [0.2]) for i in range(6, 10)]
    try:
        node.send_points(T0, ['lift_joint'], motor)
        wait_for(lambda: len(node.js) >= len(motor), ANSWER_S, 'joint_states')
        node.send_points(T0, ['tool_frame.z'], tool)
        wait_for(lambda: len(node.js) >= len(motor) + len(tool), ANSWER_S, 'joint_states')
        wait_for(lambda: len(node.jt) >= len(motor) + len(tool), ANSWER_S,
                 'joint_accelerations')
        assert node.proc.proc.poll() is None
    finally:
        node.stop()
    assert [stamp_ns(m) for m in node.js] == [T0 + at for at, *_ in [*motor, *tool]]
    names = list(robot.joint_names)
    lift = names.index('lift_joint')
    previous = {'lift_joint': motor[-1][1][0]}
    for k, (js, jt) in enumerate(zip(node.js, node.jt, strict=True)):
        assert js.name == names
        if k < len(motor):
            _, q, qd, qdd = motor[k]
            answer = robot.solve({'lift_joint': q[0]}, {'lift_joint': qd[0]},
                                 {'lift_joint': qdd[0]})
        else:
            _, z, v, a = tool[k - len(motor)]
            inverse = robot.solve_targets({'tool_frame.z': z[0]}, {'tool_frame.z': v[0]},
                                          {'tool_frame.z': a[0]}, start=previous)
            previous = {'lift_joint': float(inverse.motion[0, 0])}
            answer = inverse.answer
            values = dict(zip(names, js.position, strict=True))
            assert abs(fk.transforms(values)['tool_frame'][2, 3] - z[0]) <= 1e-12
        np.testing.assert_allclose(js.position, [answer.joints[n].position for n in names],
                                   rtol=0, atol=1e-12)
        np.testing.assert_allclose(js.velocity, [answer.joints[n].velocity for n in names],
                                   rtol=0, atol=1e-12)
        np.testing.assert_allclose(jt.points[0].accelerations,
                                   [answer.joints[n].acceleration for n in names],
                                   rtol=0, atol=1e-9)
        effort = answer.efforts.efforts['lift_joint']
        assert js.effort[lift] == pytest.approx(effort, rel=1e-9, abs=1e-9)
