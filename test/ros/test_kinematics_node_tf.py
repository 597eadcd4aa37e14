# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Link frames on /tf and ground points on /tf_static, seen from another process (issue 13).

The frames are checked against the published points of the same tick, built
from the scene's own definitions (not from the module that makes the
frames): a link's frame carries the link's far end at (length, 0), a slider's
frame sits at its block, a slotted lever's frame carries the pin at (s, 0).
"""

import math
import signal
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from ros_helpers import NodeProcess, SESSION, stamp_ns, STARTUP_S, wait_for
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage    # built by make install (scripts/build_tf2_msgs.py)
from trajectory_msgs.msg import MultiDOFJointTrajectory

import mech_kinematics as mk

#: Transforms composed against the published points, m (relative to the mechanism's size).
RTOL_FRAMES = 1e-12
FRAME_ID = 'base'


def _apply(transform, local):
    """Return the ground position of ``local`` (x, y) in a TransformStamped's child frame."""
    t, q = transform.translation, transform.rotation
    assert q.x == 0.0 and q.y == 0.0 and t.z == 0.0
    angle = 2.0 * math.atan2(q.z, q.w)
    c, s = math.cos(angle), math.sin(angle)
    return np.array([t.x + c * local[0] - s * local[1], t.y + s * local[0] + c * local[1]])


def _expected(scene, points, sliders):
    """Child frame -> (local point, ground point it must land on), from the scene's data."""
    crank = scene.input
    out = {crank.link: ((crank.length, 0.0), points[crank.point])}
    for dyad in scene.dyads:
        if isinstance(dyad, mk.RRR):
            for link in dyad.links:
                out[link.name] = ((link.length, 0.0), points[dyad.point])
        elif isinstance(dyad, mk.RRP):
            out[dyad.link.name] = ((dyad.link.length, 0.0), points[dyad.point])
            out[dyad.slider] = ((0.0, 0.0), points[dyad.point])
        else:
            out[dyad.link] = ((sliders[dyad.slider], 0.0), points[dyad.through])
            out[dyad.slider] = ((0.0, 0.0), points[dyad.through])
    origins = {crank.link: crank.center}
    for dyad in scene.dyads:
        if isinstance(dyad, mk.RRR):
            origins.update((link.name, link.start) for link in dyad.links)
        elif isinstance(dyad, mk.RRP):
            origins[dyad.link.name] = dyad.link.start
        else:
            origins[dyad.link] = dyad.center
    return out, {name: points[p] for name, p in origins.items()}


@pytest.mark.parametrize('scene_name', ['khurmi_four_bar_ad150', 'quick_return'])
def test_link_frames_compose_to_the_published_points(ros, tmp_path, scene_name):
    """Every link and slider frame on /tf puts the scene's points where the node publishes them."""
    scene = mk.load_scene(scene_name)
    ns = f'{SESSION}/tf_{scene_name}'
    qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
    static_qos = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                            durability=DurabilityPolicy.TRANSIENT_LOCAL)
    tf = ros.collect(TFMessage, f'{ns}/tf', qos)
    points_msgs = ros.collect(MultiDOFJointTrajectory, f'{ns}/point_accelerations', qos)
    joint_msgs = ros.collect(JointState, f'{ns}/joint_states', qos)
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns}', '-r', f'/tf:={ns}/tf',
                       '-r', f'/tf_static:={ns}/tf_static', '-p', f'scene:={scene_name}',
                       '-p', 'rate_hz:=200', '-p', 'tf_rate_hz:=50',
                       '-p', f'frame_id:={FRAME_ID}')
    try:
        wait_for(lambda: len(tf) >= 40, STARTUP_S, '40 /tf messages')
        static = []
        # A late subscriber still gets the static frames (transient local).
        ros.node.create_subscription(TFMessage, f'{ns}/tf_static', static.append,
                                     static_qos)
        wait_for(lambda: static, STARTUP_S, '/tf_static')

        def complete():
            # /tf messages whose tick's points and joints have arrived too (each topic
            # arrives on its own, later on a loaded machine).
            stamps = {stamp_ns(m) for m in points_msgs} & {stamp_ns(m) for m in joint_msgs}
            return sum(stamp_ns(m.transforms[0]) in stamps for m in tf) >= 30
        wait_for(complete, STARTUP_S, '30 /tf messages with the states of their ticks')
    finally:
        status, _ = proc.stop(signal.SIGINT)
    assert status == 0, proc.output()
    size = max(abs(v) for xy in scene.ground.values() for v in xy) + scene.input.length
    by_stamp = {stamp_ns(m): m for m in points_msgs}
    joints_by_stamp = {stamp_ns(m): m for m in joint_msgs}
    checked = 0
    for msg in tf:
        stamps = {stamp_ns(t) for t in msg.transforms}
        assert len(stamps) == 1, 'the transforms of one message share one stamp'
        stamp = stamps.pop()
        if stamp not in by_stamp or stamp not in joints_by_stamp:
            continue
        pm, jm = by_stamp[stamp], joints_by_stamp[stamp]
        points = {name: np.array([t.translation.x, t.translation.y])
                  for name, t in zip(pm.joint_names, pm.points[0].transforms, strict=True)}
        sliders = dict(zip(jm.name, jm.position, strict=True))
        expected, origins = _expected(scene, points, sliders)
        frames = {t.child_frame_id: t for t in msg.transforms}
        assert set(frames) == {f'{FRAME_ID}/{j}' for j in scene.output_joints}
        for transform in msg.transforms:
            assert transform.header.frame_id == FRAME_ID
            joint = transform.child_frame_id.split('/', 1)[1]
            local, target = expected[joint]
            np.testing.assert_allclose(_apply(transform.transform, local), target,
                                       rtol=0, atol=RTOL_FRAMES * size)
            if joint in origins:
                np.testing.assert_allclose(_apply(transform.transform, (0.0, 0.0)),
                                           origins[joint], rtol=0, atol=RTOL_FRAMES * size)
        checked += 1
    assert checked >= 30
    # 50 Hz of a 200 Hz grid: every fourth instant, or (where a stall on a loaded machine
    # skipped instants) the first instant published 20 ms or more after the last /tf.
    tf_stamps = sorted(stamp_ns(m.transforms[0]) for m in tf)
    published = sorted(joints_by_stamp)
    gaps = set()
    for a, b in zip(tf_stamps, tf_stamps[1:], strict=False):
        if b > published[-1]:
            break       # the states of the last ticks may not have arrived when it stopped
        assert b == next(t for t in published if t >= a + 20_000_000), (a, b)
        gaps.add(b - a)
    assert 20_000_000 in gaps and all(g % 5_000_000 == 0 for g in gaps)
    ground = {t.child_frame_id: t.transform for t in static[-1].transforms}
    assert set(ground) == {f'{FRAME_ID}/{name}' for name in scene.ground}
    for name, (x, y) in scene.ground.items():
        t = ground[f'{FRAME_ID}/{name}']
        assert (t.translation.x, t.translation.y, t.rotation.w) == (x, y, 1.0)


def test_robot_description_and_scene_reach_a_late_subscriber(ros, tmp_path):
    """robot_description's links are the /tf and /tf_static frames; scene is the file (issue 20).

    Both are transient local: subscribed after the node has published them,
    they still arrive. Every URDF joint's parent is the parent /tf gives its
    child, and the scene's text loads to the scene the node runs.
    """
    name = 'quick_return'
    ns = f'{SESSION}/description'
    latched = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
    tf = ros.collect(TFMessage, f'{ns}/tf', QoSProfile(depth=100))
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns}', '-r', f'/tf:={ns}/tf',
                       '-r', f'/tf_static:={ns}/tf_static', '-p', f'scene:={name}',
                       '-p', f'frame_id:={FRAME_ID}', '-p', 'tf_prefix:=qr')
    try:
        wait_for(lambda: tf, STARTUP_S, '/tf')
        description = ros.collect(String, f'{ns}/robot_description', latched)
        scene_text = ros.collect(String, f'{ns}/scene', latched)
        static = ros.collect(TFMessage, f'{ns}/tf_static', latched)
        # (three new subscriptions to discover: the start-up deadline, as for any discovery)
        wait_for(lambda: description and scene_text and static, STARTUP_S,
                 'robot_description, scene and /tf_static')
    finally:
        status, _ = proc.stop(signal.SIGINT)
    assert status == 0, proc.output()
    robot = ET.fromstring(description[-1].data)
    links = {link.get('name') for link in robot.findall('link')}
    parents = {j.find('child').get('link'): j.find('parent').get('link')
               for j in robot.findall('joint')}
    on_tf = {t.child_frame_id: t.header.frame_id
             for msg in [tf[-1], static[-1]] for t in msg.transforms}
    assert links == {FRAME_ID} | set(on_tf)
    assert parents == on_tf
    scene = mk.load_scene(name)
    assert mk.parse_scene(mk.scene.read_scene_yaml(scene_text[-1].data)) == scene
