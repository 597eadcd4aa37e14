# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node driven from its output (``drive: target``, issue 41), over real DDS.

This process publishes the five-bar's effector targets (``P.x``, ``P.y``, m)
on ``input_targets``; the node publishes one state per message with its
stamp, whose ``joint_states`` carries the motors' values: checked against the
forward solve of those values (P comes back) and against ``mk.solve_targets``.
A target out of reach is refused on diagnostics and the stream goes on.
"""

from diagnostic_msgs.msg import DiagnosticStatus
import numpy as np
from ros_helpers import SESSION, stamp_ns, wait_for
from test_kinematics_node_topic import ANSWER_S, T0, TopicNode

import mech_kinematics as mk

SCENE = 'five_bar'
FIVE = mk.load_scene(SCENE)
START = mk.solve(FIVE, [d.start for d in FIVE.drivers], [0.0, 0.0], [0.0, 0.0])
START_P = [float(c) for c in START.points['P'].position]


def target_node(ros, tmp_path, name, *args):
    return TopicNode(ros, tmp_path, name, *args, scene=SCENE, drive='target',
                     input_topic=f'{SESSION}/{name}/input_targets',
                     greeting=(['P.x', 'P.y'], START_P))


def test_one_state_per_target_message_with_the_motors_values(ros, tmp_path):
    """P moved along a line: each state puts P where the message says, at its speed."""
    node = target_node(ros, tmp_path, 'target_states')
    points = [(START_P[0] - 0.002 * i, START_P[1] - 0.001 * i) for i in range(20)]
    stamps = [T0 + 1_000_000 * i for i in range(len(points))]
    speeds = [(-0.2, -0.1) if i % 2 else None for i in range(len(points))]
    try:
        for stamp, p, v in zip(stamps, points, speeds, strict=True):
            node.send(stamp, ['P.x', 'P.y'], p, [] if v is None else v)
        wait_for(lambda: len(node.js) >= len(stamps), ANSWER_S, 'joint_states')
        wait_for(lambda: len(node.pt) >= len(stamps), ANSWER_S, 'point_accelerations')
        assert node.proc.proc.poll() is None
    finally:
        node.stop()
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
