# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The scene's IMUs as ``sensor_msgs/msg/Imu`` on ``imu/NAME``, seen from another process.

Issue 18: each sensor's message carries the readings ``solve`` prints for the
crank angle of the same stamp (read from ``joint_states``), stamped like the
state, in the link's frame (``angle: 0``) or a frame of its own on ``/tf``
(child of the link's frame, turned by ``angle``, its origin at the point).
"""

import math
from pathlib import Path
import signal
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from ros_helpers import (NodeProcess, SESSION, stamp_ns, STARTUP_S, wait_for,
                         wait_for_parameters)
from sensor_msgs.msg import Imu, JointState
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage    # built by make install (scripts/build_tf2_msgs.py)
from trajectory_msgs.msg import MultiDOFJointTrajectory
import yaml

import mech_kinematics as mk
from mech_kinematics.ros import topics

FRAME_ID = 'base'
#: The node's readings against `solve`'s at the same crank angle: the same formulas on the
#: same doubles up to the ulps of a compiled tick's sums, relative to each reading's scale.
RTOL_READINGS = 1e-12
SCENE = {
    'name': 'imu_node', 'units': {'length': 'mm', 'angle': 'deg'},
    'ground': {'A': [0, 0], 'D': [150, 0]},
    'input': {'link': 'crank', 'center': 'A', 'point': 'B', 'length': 40, 'angle': 60,
              'speed_rpm': -120, 'accel': 0},
    'dyads': [{'type': 'RRR', 'point': 'C',
               'links': [{'name': 'coupler', 'from': 'B', 'length': 150},
                         {'name': 'rocker', 'from': 'D', 'length': 80}]}],
    'points': {'E': {'link': 'coupler', 'origin': 'B', 'xaxis': 'C', 'local': [30, 20]}},
    'imus': {'tip': {'link': 'coupler', 'point': 'E', 'gravity': [0, -9.80665], 'angle': 30},
             'arm': {'link': 'rocker', 'point': 'C', 'gravity': [0, -9.80665]}},
}


def test_imu_topics_carry_the_readings_solve_prints(ros, tmp_path):
    """Each Imu equals solve's reading at its stamp's crank angle; frames and covariances."""
    path = tmp_path / 'imu_node.yaml'
    path.write_text(yaml.safe_dump(SCENE))
    scene = mk.load_scene(path)
    ns = f'{SESSION}/imu'
    qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
    imus = {name: ros.collect(Imu, f'{ns}/{topics.imu_topic(name)}', qos)
            for name in ('tip', 'arm')}
    joints = ros.collect(JointState, f'{ns}/joint_states', qos)
    points = ros.collect(MultiDOFJointTrajectory, f'{ns}/point_accelerations', qos)
    tf = ros.collect(TFMessage, f'{ns}/tf', qos)
    description = ros.collect(String, f'{ns}/robot_description', QoSProfile(
        depth=1, reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL))
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns}', '-r', f'/tf:={ns}/tf',
                       '-r', f'/tf_static:={ns}/tf_static', '-p', f'scene:={path}',
                       '-p', 'rate_hz:=100', '-p', 'tf_rate_hz:=100',
                       '-p', f'frame_id:={FRAME_ID}')
    try:
        wait_for(lambda: min(len(m) for m in imus.values()) >= 40 and len(tf) >= 40
                 and description, STARTUP_S, '40 Imu messages on each topic')
    finally:
        status, _ = proc.stop(signal.SIGINT)
    assert status == 0, proc.output()
    crank = {stamp_ns(m): m.position[m.name.index('crank')] for m in joints}
    checked = 0
    for name, received in imus.items():
        frame = f'{FRAME_ID}/tip' if name == 'tip' else f'{FRAME_ID}/rocker'
        for msg in received:
            stamp = stamp_ns(msg)
            if stamp not in crank:
                continue
            state = mk.solve(scene, crank[stamp])
            data = state.as_dict()['imus'][name]
            assert msg.header.frame_id == frame
            q = msg.orientation
            assert (q.x, q.y) == (0.0, 0.0)
            assert 2 * math.atan2(q.z, q.w) == pytest.approx(data['orientation'], abs=1e-12)
            assert (msg.angular_velocity.x, msg.angular_velocity.y) == (0.0, 0.0)
            assert msg.angular_velocity.z == pytest.approx(data['angular_velocity'],
                                                           rel=RTOL_READINGS)
            a = msg.linear_acceleration
            assert a.z == 0.0
            np.testing.assert_allclose([a.x, a.y], data['linear_acceleration'], rtol=0,
                                       atol=RTOL_READINGS * np.hypot(*data[
                                           'linear_acceleration']))
            for covariance in (msg.orientation_covariance, msg.angular_velocity_covariance,
                               msg.linear_acceleration_covariance):
                assert list(covariance) == [0.0] * 9
            checked += 1
    assert checked >= 60
    # The sensor turned on its link has its frame on /tf: a child of the coupler's frame,
    # turned by 30 deg, its origin at E (checked against the published E of the same stamp).
    own = [t for m in tf for t in m.transforms if t.child_frame_id == f'{FRAME_ID}/tip']
    assert own and {t.header.frame_id for t in own} == {f'{FRAME_ID}/coupler'}
    assert {stamp_ns(t) for t in own} <= {stamp_ns(t) for m in tf for t in m.transforms
                                          if t.child_frame_id == f'{FRAME_ID}/coupler'}
    t = own[0].transform
    assert 2 * math.atan2(t.rotation.z, t.rotation.w) == pytest.approx(math.radians(30),
                                                                       rel=1e-15)
    links = {stamp_ns(tr): tr.transform for m in tf for tr in m.transforms
             if tr.child_frame_id == f'{FRAME_ID}/coupler'}
    e_at = {stamp_ns(m): m.points[0].transforms[m.joint_names.index('E')].translation
            for m in points}
    composed = 0
    for stamp, link in links.items():
        if stamp not in e_at:
            continue
        angle = 2 * math.atan2(link.rotation.z, link.rotation.w)
        x = link.translation.x + math.cos(angle) * t.translation.x \
            - math.sin(angle) * t.translation.y
        y = link.translation.y + math.sin(angle) * t.translation.x \
            + math.cos(angle) * t.translation.y
        assert (x, y) == pytest.approx((e_at[stamp].x, e_at[stamp].y), abs=1e-15)
        composed += 1
    assert composed >= 30
    # robot_description has the sensor's frame as /tf has it: fixed to the coupler's.
    joints = {j.find('child').get('link'): j
              for j in ET.fromstring(description[-1].data).findall('joint')}
    joint = joints[f'{FRAME_ID}/tip']
    assert joint.find('parent').get('link') == f'{FRAME_ID}/coupler'
    xyz = [float(v) for v in joint.find('origin').get('xyz').split()]
    assert xyz == pytest.approx([t.translation.x, t.translation.y, 0.0], abs=1e-15)


def test_rendered_imu_bytes_are_the_canonical_cdr_of_the_message():
    """The template's bytes equal cdr_from_message of imu_from_values, stamp and all."""
    from rclpy.serialization import deserialize_message

    from mech_kinematics.ros.cdr import cdr_from_message
    from mech_kinematics.ros.imus import imu_from_values, ImuMessages
    from mech_kinematics.ros.ticker import values_from_state

    scene = mk.parse_scene(SCENE)
    messages = ImuMessages(scene.imus, scene.output_joints, scene.output_points, 'p')
    for angle in np.linspace(-3, 3, 5):
        state = mk.solve(scene, float(angle), 3.0, -20.0)
        values = values_from_state(state, scene.output_joints, scene.output_points)
        rendered = messages.render_values(values, 7, 123)
        data = state.as_dict()['imus']
        for spec, raw in zip(scene.imus, rendered, strict=True):
            p = state.points[spec.point].acceleration
            msg = imu_from_values(spec, 'p', 7, 123, state.joints[spec.link].position,
                                  state.joints[spec.link].velocity, p[0], p[1])
            assert raw == cdr_from_message(msg)
            back = deserialize_message(raw, Imu)
            assert back.header.frame_id == ('p/tip' if spec.name == 'tip' else 'p/rocker')
            assert (back.header.stamp.sec, back.header.stamp.nanosec) == (7, 123)
            assert [back.linear_acceleration.x, back.linear_acceleration.y] == pytest.approx(
                data[spec.name]['linear_acceleration'], rel=1e-14)
            assert back.angular_velocity.z == data[spec.name]['angular_velocity']


def test_a_reading_beyond_the_range_of_doubles_is_not_rendered():
    """Issue 33: a sensor whose a_P - g overflows gets no message (None), never an inf.

    The crank's tip accelerates at 1.44e308 m/s^2 toward A (a state the solver
    answers); gravity 8e307 upward (within MAX_GRAVITY) takes the reading beyond
    the doubles. A sensor beside it, without gravity, is rendered as usual. The
    node publishes nothing for the first that tick (a throttled warning says so).
    """
    from mech_kinematics.ros.imus import ImuMessages
    from mech_kinematics.ros.ticker import values_from_state

    scene = mk.parse_scene({
        'name': 'imu_overflow', 'units': {'length': 'm', 'angle': 'deg'},
        'ground': {'A': [0, 0]},
        'input': {'link': 'crank', 'center': 'A', 'point': 'B', 'length': 1, 'angle': 90,
                  'speed': 1.2e154},
        'imus': {'up': {'link': 'crank', 'point': 'B', 'gravity': [0, 8e307]},
                 'free': {'link': 'crank', 'point': 'B'}}})
    state = mk.solve(scene, scene.input.angle)
    values = values_from_state(state, scene.output_joints, scene.output_points)
    assert all(math.isfinite(v) for v in values)
    messages = ImuMessages(scene.imus, scene.output_joints, scene.output_points, 'p')
    up, free = messages.render_values(values, 7, 123)
    assert up is None
    assert isinstance(free, bytes)


def test_only_the_sensors_of_the_scenes_gravity_follow_a_new_gravity():
    """follow_gravity moves the sensors whose gravity is the scene's; others keep theirs.

    And a gravity the parameter accepts (finite, beyond a sensor's
    MAX_GRAVITY) makes an overflowing reading unpublished, not an error.
    """
    from mech_kinematics.ros.imus import _slots, ImuMessages
    from mech_kinematics.ros.ticker import values_from_state

    scene = mk.parse_scene({
        'name': 'imu_follow', 'units': {'length': 'm', 'angle': 'deg'},
        'ground': {'A': [0, 0]},
        'input': {'link': 'crank', 'center': 'A', 'point': 'B', 'length': 1, 'angle': 45,
                  'speed': 3.0},
        'gravity': [0, -9.81],
        'imus': {'tied': {'link': 'crank', 'point': 'B', 'gravity': [0, -9.81]},
                 'free': {'link': 'crank', 'point': 'B'}}})
    state = mk.solve(scene, scene.input.angle)
    values = values_from_state(state, scene.output_joints, scene.output_points)
    messages = ImuMessages(scene.imus, scene.output_joints, scene.output_points, 'p',
                           scene.gravity)
    assert messages.following == ('tied',)
    assert ImuMessages(scene.imus, scene.output_joints, scene.output_points, 'p').following \
        == ()
    tied, free = scene.imus
    messages.follow_gravity([1.0, 2.0])
    assert messages.gravity == ((1.0, 2.0), (0.0, 0.0))
    i, j, k, m = messages.indices[0]
    rendered = messages.render_values(values, 7, 123)
    assert rendered[0] == ImuMessages([tied], scene.output_joints, scene.output_points,
                                      'p')._templates[0].render(
        7, 123, _slots(values[i], values[j], values[k], values[m], tied, (1.0, 2.0)))
    assert rendered[1] == ImuMessages([free], scene.output_joints, scene.output_points,
                                      'p').render_values(values, 7, 123)[0]
    messages.follow_gravity([1.7e308, 1.7e308])    # turned 45 deg: beyond the doubles
    up, still = messages.render_values(values, 7, 123)
    assert up is None and still == rendered[1]


def test_the_gripper_runs_a_whole_turn_with_its_fingertip_imu(ros, tmp_path):
    """The packaged gripper at its own 30 rpm: one Imu per state over a turn, none refused.

    Every state the node publishes over a crank turn (2 s) has its fingertip
    reading, in the jaw's frame, equal to solve's at that stamp's crank angle;
    the jaw translates, so the gyro reads 0 to rounding and the orientation is
    the jaw's constant angle atan2(18, 24).
    """
    scene = mk.load_scene('gripper')
    ns = f'{SESSION}/gripper'
    qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
    imu = ros.collect(Imu, f'{ns}/imu/fingertip', qos)
    joints = ros.collect(JointState, f'{ns}/joint_states', qos)
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns}', '-r', f'/tf:={ns}/tf',
                       '-r', f'/tf_static:={ns}/tf_static', '-p', 'scene:=gripper',
                       '-p', 'rate_hz:=100')
    try:
        wait_for(lambda: len(imu) >= 230 and len(joints) >= 230, STARTUP_S + 5,
                 'a crank turn of Imu and joint_states messages')
    finally:
        status, _ = proc.stop(signal.SIGINT)
    assert status == 0, proc.output()
    assert 'no state published' not in proc.output()
    crank = {stamp_ns(m): m.position[m.name.index('crank')] for m in joints}
    stamps = [stamp_ns(m) for m in imu]
    assert stamps == sorted(stamps) and len(set(stamps)) == len(stamps)
    # Every state has its reading (the first few may precede this side's subscription).
    assert len(set(crank) - set(stamps)) <= 5 and len(set(stamps) - set(crank)) <= 5
    turned = np.unwrap(np.array([crank[s] for s in sorted(set(crank) & set(stamps))]))
    assert turned[-1] - turned[0] >= 2 * math.pi * 0.95
    for msg in imu:
        stamp = stamp_ns(msg)
        if stamp not in crank:
            continue
        data = mk.solve(scene, crank[stamp]).as_dict()['imus']['fingertip']
        assert msg.header.frame_id == 'mechanism/jaw'
        assert 2 * math.atan2(msg.orientation.z, msg.orientation.w) == pytest.approx(
            math.atan2(18, 24), abs=1e-14)
        assert abs(msg.angular_velocity.z) < 1e-14
        np.testing.assert_allclose([msg.linear_acceleration.x, msg.linear_acceleration.y],
                                   data['linear_acceleration'], rtol=0, atol=1e-12)


def test_an_imu_on_a_scene_of_several_drivers(ros, tmp_path):
    """The five-bar with a turned sensor at P on a distal link: readings equal solve's.

    The sensor's frame on its link is placed from the drivers' start positions
    (a scene of several drivers has no single crank angle to start from).
    """
    text = (Path(__file__).resolve().parents[2] / 'config' / 'scenes' / 'five_bar.yaml')
    data = yaml.safe_load(text.read_text())
    data['name'] = 'five_bar_imu'
    data['imus'] = {'wrist': {'link': 'left_distal', 'point': 'P', 'angle': 45,
                              'gravity': [0, -9.80665]}}
    path = tmp_path / 'five_bar_imu.yaml'
    path.write_text(yaml.safe_dump(data))
    scene = mk.load_scene(path)
    ns = f'{SESSION}/five_bar_imu'
    qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
    imu = ros.collect(Imu, f'{ns}/imu/wrist', qos)
    joints = ros.collect(JointState, f'{ns}/joint_states', qos)
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns}', '-r', f'/tf:={ns}/tf',
                       '-r', f'/tf_static:={ns}/tf_static', '-p', f'scene:={path}',
                       '-p', 'rate_hz:=100')
    try:
        wait_for(lambda: len(imu) >= 30 and len(joints) >= 30, STARTUP_S,
                 '30 Imu and joint_states messages')
    finally:
        status, _ = proc.stop(signal.SIGINT)
    assert status == 0, proc.output()
    at = {stamp_ns(m): [m.position[m.name.index(d.name)] for d in scene.drivers]
          for m in joints}
    speeds = [d.speed for d in scene.drivers]
    checked = 0
    for msg in imu:
        if stamp_ns(msg) not in at:
            continue
        data = mk.solve(scene, at[stamp_ns(msg)], speeds).as_dict()['imus']['wrist']
        assert msg.header.frame_id == 'mechanism/wrist'
        assert 2 * math.atan2(msg.orientation.z, msg.orientation.w) == pytest.approx(
            data['orientation'], abs=1e-12)
        assert msg.angular_velocity.z == pytest.approx(data['angular_velocity'],
                                                       rel=RTOL_READINGS)
        a = msg.linear_acceleration
        np.testing.assert_allclose([a.x, a.y], data['linear_acceleration'], rtol=0,
                                   atol=RTOL_READINGS * np.hypot(*data['linear_acceleration']))
        checked += 1
    assert checked >= 20


def test_a_sensor_of_the_scenes_gravity_follows_the_gravity_parameter(ros, tmp_path):
    """The engine with two sensors at its crank pin on the rod: one of the scene's gravity.

    ``rod_g`` gives the scene's gravity (both given must agree), ``rod_free``
    none (its v3 meaning: no gravity taken off). At the same stamp they read
    the same acceleration less ``rod_g``'s gravity: started with ``gravity:=[0,
    -1.62]`` from the command line, the two differ by 1.62 m/s^2; set to
    ``[0, 0]`` while running, they read the same from an instant on. Before
    the fix ``rod_g`` kept the scene's 9.81.
    """
    data = yaml.safe_load(
        (Path(__file__).resolve().parents[2] / 'config' / 'scenes' / 'engine.yaml').read_text())
    data['name'] = 'engine_imus'
    data['imus'] = {'rod_g': {'link': 'rod', 'point': 'C', 'gravity': [0, -9.81]},
                    'rod_free': {'link': 'rod', 'point': 'C'}}
    path = tmp_path / 'engine_imus.yaml'
    path.write_text(yaml.safe_dump(data))
    ns = f'{SESSION}/engine_imus'
    qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
    imus = {name: ros.collect(Imu, f'{ns}/imu/{name}', qos) for name in ('rod_g', 'rod_free')}
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns}', '-p', f'scene:={path}',
                       '-p', 'rate_hz:=100', '-p', 'gravity:=[0.0, -1.62]')
    params = AsyncParameterClient(ros.node, f'{ns}/mech_kinematics')

    def gaps():
        """Return per stamp both sensors read, |rod_g - rod_free| in order, m/s^2."""
        free = {stamp_ns(m): m.linear_acceleration for m in list(imus['rod_free'])}
        out = []
        for m in list(imus['rod_g']):
            other = free.get(stamp_ns(m))
            if other is not None:
                a = m.linear_acceleration
                out.append(math.hypot(a.x - other.x, a.y - other.y))
        return out
    try:
        wait_for_parameters(params)
        wait_for(lambda: len(gaps()) >= 10, STARTUP_S, '10 readings of both sensors')
        before = len(gaps())
        [result] = ros.call(params.set_parameters(
            [Parameter('gravity', value=[0.0, 0.0])])).results
        assert result.successful, result.reason
        wait_for(lambda: len(gaps()) > before + 10 and 0.0 in gaps()[before:], STARTUP_S,
                 'the sensors reading alike after gravity:=[0, 0]')
    finally:
        status, _ = proc.stop(signal.SIGINT)
    assert status == 0, proc.output()
    seen = gaps()
    first = seen.index(0.0)
    assert first >= 10
    # The readings are ~3,300 m/s^2 at 2000 rpm: a gap of 1.62 to their rounding.
    assert all(abs(g - 1.62) <= 1e-9 for g in seen[:first])
    assert all(g == 0.0 for g in seen[first:])
