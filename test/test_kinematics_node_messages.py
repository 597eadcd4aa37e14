# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The CDR bytes the node publishes decode to exactly the messages built the ordinary way."""

import math
import struct

from hypothesis import assume, given, settings, strategies as st
import pytest
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import JointState

import mech_kinematics as mk
from mech_kinematics.cdr import marker, MessageTemplate, STAMP_MARKER
from mech_kinematics.messages import (joint_state_from_state, joint_trajectory_from_state,
                                      multi_dof_trajectory_from_state, TickMessages)

SCENES = mk.scene_names()
FRAME_ID = 'mechanism'


def float_bits(values):
    """Return the exact bit patterns of ``values`` (so -0.0 and 0.0 differ)."""
    return struct.pack(f'<{len(values)}d', *values)


def assert_identical(got, expected):
    """Assert two messages are equal field by field, floats to the bit."""
    assert got == expected
    if isinstance(expected, JointState):
        assert float_bits(got.position) == float_bits(expected.position)
        assert float_bits(got.velocity) == float_bits(expected.velocity)
    elif hasattr(expected.points[0], 'positions'):
        for name in ('positions', 'velocities', 'accelerations'):
            assert float_bits(getattr(got.points[0], name)) == \
                float_bits(getattr(expected.points[0], name))
    else:
        for got_t, exp_t in zip(got.points[0].transforms, expected.points[0].transforms,
                                strict=True):
            assert float_bits([got_t.translation.x, got_t.translation.y]) == \
                float_bits([exp_t.translation.x, exp_t.translation.y])


def solve_or_skip(scene, angle, speed, accel):
    """Solve, or tell hypothesis to skip an angle where the scene cannot assemble."""
    try:
        return mk.solve(scene, angle, speed, accel)
    except mk.AssemblyError:
        assume(False)


@settings(max_examples=60, deadline=None)
@given(name=st.sampled_from(SCENES), angle=st.floats(-math.pi, math.pi),
       speed=st.floats(-2000, 2000), accel=st.floats(-1e4, 1e4),
       sec=st.integers(0, 2 ** 31 - 1), nanosec=st.integers(0, 999_999_999))
def test_rendered_bytes_decode_to_the_messages(name, angle, speed, accel, sec, nanosec):
    """Every rendered message deserializes to exactly the message built from the same state."""
    scene = mk.load_scene(name)
    state = solve_or_skip(scene, angle, speed, accel)
    joints, points = scene.output_joints, scene.output_points
    messages = TickMessages(joints, points, FRAME_ID)
    # Render an unrelated state first: nothing of it may survive into the next render.
    messages.render(mk.solve(scene, scene.input.angle), 1, 2)
    rendered = messages.render(state, sec, nanosec)
    expected = (joint_state_from_state(state, joints, FRAME_ID, sec, nanosec),
                joint_trajectory_from_state(state, joints, FRAME_ID, sec, nanosec),
                multi_dof_trajectory_from_state(state, points, FRAME_ID, sec, nanosec))
    for data, msg in zip(rendered, expected, strict=True):
        assert isinstance(data, bytes)
        assert_identical(deserialize_message(data, type(msg)), msg)


@pytest.mark.parametrize('name', SCENES)
def test_messages_follow_the_contract(name):
    """Names, array lengths, frame, z = 0 and identity rotations are as INTERFACE.md says."""
    scene = mk.load_scene(name)
    state = mk.solve(scene, scene.input.angle)
    joints, points = scene.output_joints, scene.output_points
    js = joint_state_from_state(state, joints, FRAME_ID, 5, 6)
    assert js.name == list(joints)
    assert len(js.position) == len(js.velocity) == len(joints) and not js.effort
    jt = joint_trajectory_from_state(state, joints, FRAME_ID, 5, 6)
    assert jt.joint_names == list(joints) and len(jt.points) == 1
    assert list(jt.points[0].accelerations) == [state.joints[n].acceleration for n in joints]
    md = multi_dof_trajectory_from_state(state, points, FRAME_ID, 5, 6)
    assert md.joint_names == list(points) and len(md.points) == 1
    for i, n in enumerate(points):
        p, v, a = (state.points[n].position, state.points[n].velocity,
                   state.points[n].acceleration)
        t = md.points[0].transforms[i]
        assert (t.translation.x, t.translation.y, t.translation.z) == (p[0], p[1], 0.0)
        assert (t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w) == (0, 0, 0, 1)
        lin = md.points[0].velocities[i].linear
        assert (lin.x, lin.y, lin.z) == (v[0], v[1], 0.0)
        lin = md.points[0].accelerations[i].linear
        assert (lin.x, lin.y, lin.z) == (a[0], a[1], 0.0)
    for msg in (js, jt, md):
        assert msg.header.frame_id == FRAME_ID
        assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (5, 6)


def test_template_refuses_a_missing_marker():
    """A message without the markers it promises is refused, naming what is missing."""
    msg = JointState(name=['a'], position=[1.0])
    msg.header.stamp.sec, msg.header.stamp.nanosec = STAMP_MARKER
    with pytest.raises(ValueError, match='slot 0'):
        MessageTemplate(msg, 1)
    msg.position = [marker(0)]
    msg.header.stamp.sec = 0
    with pytest.raises(ValueError, match='stamp'):
        MessageTemplate(msg, 1)
