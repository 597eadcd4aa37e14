# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node driven from its output (``drive: target``, issue 41), over real DDS.

This process publishes the five-bar's effector targets (``P.x``, ``P.y``, m)
on ``input_targets``; the node publishes one state per message with its
stamp, whose ``joint_states`` carries the motors' values: checked against the
forward solve of those values (P comes back) and against ``mk.solve_targets``.
A target out of reach is refused on diagnostics and the stream goes on. In
URDF mode the lift arm is driven by its tool frame's height (``tool_frame.z``,
the root frame): ``joint_states`` names the URDF's joints, checked against the
URDF's own kinematics (test/helpers.py's ``UrdfFk``) and ``Robot.solve_targets``.
"""

from pathlib import Path

from diagnostic_msgs.msg import DiagnosticStatus
from helpers import UrdfFk
import numpy as np
from ros_helpers import SESSION, stamp_ns, wait_for
from test_kinematics_node_topic import ANSWER_S, T0, TopicNode

import mech_kinematics as mk
from mech_kinematics.robot import load_robot

SCENE = 'five_bar'
FIVE = mk.load_scene(SCENE)
START = mk.solve(FIVE, [d.start for d in FIVE.drivers], [0.0, 0.0], [0.0, 0.0])
START_P = [float(c) for c in START.points['P'].position]


def target_node(ros, tmp_path, name, *args, greeting=START_P):
    return TopicNode(ros, tmp_path, name, *args, scene=SCENE, drive='target',
                     input_topic=f'{SESSION}/{name}/input_targets',
                     greeting=(['P.x', 'P.y'], greeting))


def _stream(node, stamps, points, speeds, accelerations=False):
    """Send P's targets (with speeds, or None) at ``stamps``; wait for every state; stop."""
    try:
        for stamp, p, v in zip(stamps, points, speeds, strict=True):
            node.send(stamp, ['P.x', 'P.y'], p, [] if v is None else v)
        wait_for(lambda: len(node.js) >= len(stamps), ANSWER_S, 'joint_states')
        if accelerations:
            wait_for(lambda: len(node.pt) >= len(stamps), ANSWER_S, 'point_accelerations')
        assert node.proc.proc.poll() is None
    finally:
        node.stop()


def test_one_state_per_target_message_with_the_motors_values(ros, tmp_path):
    """P moved along a line: each state puts P where the message says, at its speed."""
    node = target_node(ros, tmp_path, 'target_states')
    points = [(START_P[0] - 0.002 * i, START_P[1] - 0.001 * i) for i in range(20)]
    stamps = [T0 + 1_000_000 * i for i in range(len(points))]
    speeds = [(-0.2, -0.1) if i % 2 else None for i in range(len(points))]
    _stream(node, stamps, points, speeds, accelerations=True)
    assert [stamp_ns(m) for m in node.js] == stamps
    joints = FIVE.output_joints
    index = FIVE.output_points.index('P')
    for js, pt, p, v in zip(node.js, node.pt, points, speeds, strict=True):
        assert js.name == list(joints)
        motors = [js.position[joints.index(d.name)] for d in FIVE.drivers]
        state = mk.solve(FIVE, motors, [0.0, 0.0], [0.0, 0.0])
        np.testing.assert_allclose(state.points['P'].position, p, rtol=0, atol=1e-14)
        t = pt.points[0].transforms[index].translation
        np.testing.assert_allclose([t.x, t.y], p, rtol=0, atol=1e-14)
        if v is None:
            assert not js.velocity
        else:
            w = pt.points[0].velocities[index].linear
            np.testing.assert_allclose([w.x, w.y], v, rtol=0, atol=1e-13)


def test_target_branch_answers_in_the_working_mode_asked(ros, tmp_path):
    """target_branch B and D positive: each state's motors are solve_targets' in that mode."""
    branch = {'B': 1, 'D': 1}
    goal = [0.06, 0.22]
    node = target_node(ros, tmp_path, 'target_branch', '-p', 'target_branch:=[B=+1, D=+1]',
                       greeting=goal)
    points = [(goal[0] + 0.002 * i, goal[1]) for i in range(5)]
    stamps = [T0 + 1_000_000 * i for i in range(len(points))]
    _stream(node, stamps, points, [None] * len(points))
    assert [stamp_ns(m) for m in node.js] == stamps
    joints = FIVE.output_joints
    start = None
    for js, p in zip(node.js, points, strict=True):
        motors = [js.position[joints.index(d.name)] for d in FIVE.drivers]
        inverse = mk.solve_targets(FIVE, {'P.x': p[0], 'P.y': p[1]}, branch=branch,
                                   **({} if start is None else {'start': start}))
        if start is not None:
            np.testing.assert_allclose(motors, inverse.motion[:, 0], rtol=0, atol=1e-12)
        assert all(angle > 0 for angle in inverse.branch.values())
        start = motors


def test_a_target_out_of_reach_is_refused_and_the_stream_goes_on(ros, tmp_path):
    node = target_node(ros, tmp_path, 'target_refusal')
    try:
        node.send(T0, ['P.x', 'P.y'], [0.06, 0.22])
        wait_for(lambda: len(node.js) >= 1, ANSWER_S, 'the first state')
        seen = len(node.diag)
        node.send(T0 + 1_000_000, ['P.x', 'P.y'], [0.06, 0.42])
        status = wait_for(lambda: node.refusal(seen, 'out of reach'), ANSWER_S,
                          'diagnostics saying out of reach')
        assert status.level == DiagnosticStatus.ERROR
        last_error = {v.key: v.value for v in status.values}['last_error']
        assert last_error.startswith('input_targets: Expected targets within reach')
        node.send(T0 + 2_000_000, ['P.x', 'P.y'], [0.061, 0.22])
        wait_for(lambda: len(node.js) >= 2, ANSWER_S, 'the state after the refusal')
        assert node.proc.proc.poll() is None
    finally:
        node.stop()
    assert [stamp_ns(m) for m in node.js] == [T0, T0 + 2_000_000]
    inverse = mk.solve_targets(FIVE, {'P.x': 0.06, 'P.y': 0.22})
    joints = FIVE.output_joints
    first = [node.js[0].position[joints.index(d.name)] for d in FIVE.drivers]
    np.testing.assert_allclose(first, inverse.motion[:, 0], rtol=0, atol=1e-12)


LIFT = Path(__file__).resolve().parents[1] / 'data' / 'urdf' / 'lift_arm.urdf'


def test_a_urdf_robot_driven_by_its_tool_frame(ros, tmp_path):
    """The lift arm's tool raised along z: each state's joints put it there (the URDF's own FK)."""
    robot = load_robot(LIFT)
    fk = UrdfFk(LIFT.read_text())
    start = robot.solve(forces=False)
    z0 = float(fk.transforms({n: float(j.position) for n, j in start.joints.items()})[
        'tool_frame'][2, 3])
    node = TopicNode(ros, tmp_path, 'target_urdf', scene=str(LIFT), drive='target',
                     input_topic=f'{SESSION}/target_urdf/input_targets',
                     greeting=(['tool_frame.z'], [z0]))
    heights = [z0 + 0.005 * i for i in range(1, 8)]
    stamps = [T0 + 1_000_000 * i for i in range(len(heights))]
    try:
        for stamp, z in zip(stamps, heights, strict=True):
            node.send(stamp, ['tool_frame.z'], [z], [0.1])
        wait_for(lambda: len(node.js) >= len(stamps), ANSWER_S, 'joint_states')
        assert node.proc.proc.poll() is None
    finally:
        node.stop()
    assert [stamp_ns(m) for m in node.js] == stamps
    for js, z in zip(node.js, heights, strict=True):
        assert js.name == list(robot.joint_names)
        values = dict(zip(js.name, js.position, strict=True))
        tool = fk.transforms(values)['tool_frame']
        assert abs(tool[2, 3] - z) <= 1e-12 * start.state.error_bound.size
        inverse = robot.solve_targets({'tool_frame.z': z}, {'tool_frame.z': 0.1})
        assert abs(values['lift_joint'] - inverse.motion[0, 0]) <= 1e-12
        speed = dict(zip(js.name, js.velocity, strict=True))['lift_joint']
        assert abs(speed - inverse.motion[0, 1]) <= 1e-12
