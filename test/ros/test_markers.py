# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""RViz markers: the message built from a solved scene, the throttle, and the running node.

The node tests reuse the subprocess helpers of ``test_kinematics_node_launch``
and with them its ROS domain and namespace of this test session.
"""

from __future__ import annotations

import bisect
import math
import signal
import subprocess
import sys
import time
import warnings

from builtin_interfaces.msg import Time
from helpers import BOOM_CYLINDER
import numpy as np
import pytest
from rclpy.serialization import deserialize_message
from ros_helpers import NodeProcess, Ros, SESSION, stamp_ns, STARTUP_S, wait_for
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import MultiDOFJointTrajectory
from visualization_msgs.msg import Marker, MarkerArray
import yaml

import mech_kinematics as mk
from mech_kinematics.geometry.diagrams import strokes_from_scene
from mech_kinematics.geometry.instant_centres import full_scene
from mech_kinematics.ros.markers import marker_array_from_state, MarkerThrottle, NAMESPACES

#: Marker positions against the solver's values (a product and a sum), m.
ATOL_POSITION = 1e-12
#: Published doubles against the solver's at the same stamp, m.
ATOL_PUBLISHED = 1e-12
NS = 1_000_000_000
MAX_RATE_HZ = 30.0
#: Per scene: the expected (ns, type) -> count of markers.
EXPECTED = {
    'khurmi_four_bar_ad150': {
        ('links', Marker.LINE_STRIP): 3, ('joints', Marker.SPHERE_LIST): 1,
        ('velocity', Marker.ARROW): 4, ('acceleration', Marker.ARROW): 4},
    'quick_return': {
        ('links', Marker.LINE_STRIP): 3, ('guides', Marker.LINE_LIST): 1,
        ('sliders', Marker.CUBE): 2, ('joints', Marker.SPHERE_LIST): 1,
        ('velocity', Marker.ARROW): 6, ('acceleration', Marker.ARROW): 6},
}
STAMP = Time(sec=1234, nanosec=567_890_123)


def _counts(array) -> dict[tuple[str, int], int]:
    counts: dict[tuple[str, int], int] = {}
    for m in array.markers:
        counts[m.ns, m.type] = counts.get((m.ns, m.type), 0) + 1
    return counts


def _xy(point) -> np.ndarray:
    return np.array([point.x, point.y])


def _markers(name: str, angle: float | None = None, **kwargs):
    """Return (scene, full scene, full state, markers) of a packaged scene at ``angle``."""
    scene = mk.load_scene(name)
    full = full_scene(scene)
    angle = scene.input.angle if angle is None else angle
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', mk.NearSingularWarning)
        state = mk.solve(full, angle)
    array = marker_array_from_state(full, state, frame_id='test_frame', stamp=STAMP,
                                    points=scene.output_points, **kwargs)
    return scene, full, state, array


@pytest.mark.parametrize('name', sorted(EXPECTED))
def test_count_and_types(name):
    """Links are line strips, joints one sphere list, one v and one a arrow per output point."""
    scene, _, _, array = _markers(name)
    assert _counts(array) == EXPECTED[name]
    assert len(scene.output_points) == EXPECTED[name]['velocity', Marker.ARROW]
    assert [m.ns for m in array.markers] == sorted(
        (m.ns for m in array.markers), key=NAMESPACES.index)
    for m in array.markers:
        assert m.header.frame_id == 'test_frame'
        assert m.header.stamp == STAMP
        assert m.action == Marker.ADD
        assert m.scale.x > 0.0
        assert m.color.a > 0.0
    ids = [(m.ns, m.id) for m in array.markers]
    assert len(set(ids)) == len(ids)


@pytest.mark.parametrize('name', sorted(EXPECTED))
def test_ids_do_not_depend_on_the_angle(name):
    """Every array of a scene has the same (ns, id, type), so each replaces the last in RViz."""
    arrays = [_markers(name, angle)[3] for angle in (0.4, 1.3, 2.9)]
    keys = [[(m.ns, m.id, m.type) for m in a.markers] for a in arrays]
    assert keys[0] == keys[1] == keys[2]


@pytest.mark.parametrize('name', sorted(EXPECTED))
@pytest.mark.parametrize('angle', [0.4, 1.3, 2.9])
def test_arrows_start_at_the_point_and_end_at_k_times_its_value(name, angle):
    """Arrow start = position; end = position + k_v v (velocity), + k_a a (acceleration)."""
    k_v, k_a = 0.25, 0.003
    scene, _, _, array = _markers(name, angle, velocity_scale=k_v, acceleration_scale=k_a)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', mk.NearSingularWarning)
        points = mk.solve(scene, angle).points
    for ns, k, value in (('velocity', k_v, 'velocity'), ('acceleration', k_a, 'acceleration')):
        arrows = [m for m in array.markers if m.ns == ns]
        for m, name_ in zip(arrows, scene.output_points, strict=True):
            p = points[name_]
            assert len(m.points) == 2
            np.testing.assert_allclose(_xy(m.points[0]), p.position, rtol=0,
                                       atol=ATOL_POSITION)
            np.testing.assert_allclose(_xy(m.points[1]), p.position + k * getattr(p, value),
                                       rtol=0, atol=ATOL_POSITION)
            assert m.points[0].z == m.points[1].z == 0.0


@pytest.mark.parametrize('name', sorted(EXPECTED))
def test_links_and_joints_are_at_the_solved_points(name):
    """Joint spheres are every point; link vertices are points of the link (levers: ends)."""
    _, full, state, array = _markers(name, 1.3)
    points = state.points
    joints = next(m for m in array.markers if m.ns == 'joints')
    assert len(joints.points) == len(joints.colors) == len(points)
    for m, p in zip(joints.points, points.values(), strict=True):
        np.testing.assert_allclose(_xy(m), p.position, rtol=0, atol=ATOL_POSITION)
    known = np.array([p.position for p in points.values()])
    for link in (m for m in array.markers if m.ns == 'links'):
        assert len(link.points) >= 2
        for vertex in link.points:
            assert np.min(np.hypot(*(known - _xy(vertex)).T)) <= ATOL_POSITION


def test_strokes_lengthen_the_guide_to_the_whole_stroke():
    """With the sliders' strokes the guide covers every position of the ram over a turn."""
    scene = mk.load_scene('quick_return')
    full = full_scene(scene)
    strokes = strokes_from_scene(full)
    _, _, _, array = _markers('quick_return', 1.3, strokes=strokes)
    guide = next(m for m in array.markers if m.ns == 'guides')
    xs = sorted(p.x for p in guide.points)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', mk.NearSingularWarning)
        ram = mk.solve(full, np.linspace(0.0, 2 * math.pi, 360)).points['D'].position
    assert xs[0] <= ram[:, 0].min() and ram[:, 0].max() <= xs[-1]


@pytest.mark.parametrize('bad', [{'velocity_scale': -1.0}, {'acceleration_scale': math.nan},
                                 {'size': 0.0}])
def test_bad_scales_are_refused(bad):
    """A negative or NaN scale, or a size of 0, raises ValueError naming it."""
    with pytest.raises(ValueError, match=next(iter(bad))):
        _markers('khurmi_four_bar_ad150', **bad)


def test_module_imports_without_ros():
    """mech_kinematics.ros.markers imports without rclpy or the message packages."""
    code = ('import sys, mech_kinematics.ros.markers; '
            "assert not {'rclpy', 'visualization_msgs'} & set(sys.modules)")
    subprocess.run([sys.executable, '-c', code], check=True, timeout=60)


def _throttled(rate_hz: float, seconds: float, wall_per_tick_ns: int | None = None):
    """Return the tick indices a throttle picks from ``seconds`` of ticks at ``rate_hz``."""
    throttle = MarkerThrottle()
    period = round(NS / rate_hz)
    step = period if wall_per_tick_ns is None else wall_per_tick_ns
    return [k for k in range(int(seconds * rate_hz)) if throttle.due(period, k * step)]


@pytest.mark.parametrize('rate_hz', [1.0, 29.0, 30.0, 31.0, 100.0, 200.0, 220.0, 10_000.0])
def test_throttle_publishes_at_most_30_hz(rate_hz):
    """Marker ticks are at least 1/30 s apart, and as close to 30 Hz as the ticks allow."""
    picked = _throttled(rate_hz, 4.0)
    period = 1.0 / rate_hz
    gaps = np.diff(picked) * period
    assert picked[0] == 0
    assert gaps.min() >= 1.0 / MAX_RATE_HZ - 1e-9
    every = math.ceil(round(1 / MAX_RATE_HZ / period, 9))
    assert gaps.max() == pytest.approx(every * period)


def test_throttle_holds_a_fast_simulated_clock():
    """Ticks of a simulated clock at 4x real time still give markers at most 30 Hz of wall time."""
    rate_hz = 200.0
    picked = _throttled(rate_hz, 8.0, wall_per_tick_ns=round(NS / rate_hz / 4))
    wall = np.diff(picked) * (1.0 / rate_hz / 4)
    assert wall.min() >= 1.0 / MAX_RATE_HZ - 1e-3


# -- the running node ---------------------------------------------------------


def _publisher_types(ros: Ros, topic: str) -> list[str]:
    return [info.topic_type for info in ros.node.get_publishers_info_by_topic(topic)]


def _gap_holds(stamp: int, stamps: list[int], period_ns: int) -> bool:
    """Return whether ``stamp`` falls in a hole of the sorted ``stamps`` (states lost here)."""
    i = bisect.bisect_left(stamps, stamp)
    return 0 < i < len(stamps) and stamps[i - 1] < stamp < stamps[i] \
        and stamps[i] - stamps[i - 1] > period_ns


def test_node_publishes_markers_at_most_30_hz_stamped_like_the_state(ros, tmp_path):
    """With markers:=true: MarkerArray on markers, <= 30 Hz at rate 200, joint_states stamps.

    Every marker of a 2 s window is stamped like a state of the same tick: its
    stamp is one of joint_states' and point_accelerations', and its velocity
    arrows are that tick's points and velocities. A reliable KEEP_LAST writer
    may still drop a state for a reader that falls behind (200 Hz on two
    topics, beside two CPU hogs: one run waited in vain for a marker's
    state): the states are taken raw (no decoding in the executor), and a
    marker whose state this process never received must fall in a hole of
    the states received (a lost one: the stream had passed it), never beside
    them; the arrows are judged on every marker whose point message arrived.
    """
    ns_topic = f'{SESSION}/markers_on'
    k_v = 0.2
    period_ns = NS // 200
    js_raw = ros.collect_raw(JointState, f'{ns_topic}/joint_states')
    md_raw = ros.collect_raw(MultiDOFJointTrajectory, f'{ns_topic}/point_accelerations')
    received = ros.collect_raw(MarkerArray, f'{ns_topic}/markers')

    def first_stamp(raw: bytes, msg_type=MarkerArray) -> int:
        msg = deserialize_message(raw, msg_type)
        return stamp_ns(msg.markers[0] if msg_type is MarkerArray else msg)

    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns_topic}', '-p', 'markers:=true',
                       '-p', 'rate_hz:=200.0', '-p', f'marker_velocity_scale:={k_v}')
    try:
        wait_for(lambda: received or proc.proc.poll() is not None, STARTUP_S, 'markers')
        assert proc.proc.poll() is None, proc.output()
        assert _publisher_types(ros, f'{ns_topic}/markers') == [
            'visualization_msgs/msg/MarkerArray']
        # From the first marker after both state readers have their first state: each
        # subscription matches the node's publisher in its own time (discovery), and the
        # states of markers from before that are never received here (one CI run).
        wait_for(lambda: js_raw and md_raw, STARTUP_S, 'the first states')
        origin = max(first_stamp(js_raw[0], JointState),
                     first_stamp(md_raw[0], MultiDOFJointTrajectory))
        wait_for(lambda: first_stamp(received[-1]) > origin, STARTUP_S,
                 'a marker after the first states')
        start = next(i for i, m in enumerate(received) if first_stamp(m) > origin)
        # 2 s of markers as stamped (on a loaded machine they arrive late, in order).
        first = first_stamp(received[start])
        wait_for(lambda: first_stamp(received[-1]) >= first + 2 * NS, 2 + STARTUP_S,
                 '2 s of markers')
        window = [msg for msg in (deserialize_message(m, MarkerArray)
                                  for m in received[start:])
                  if stamp_ns(msg.markers[0]) <= first + 2 * NS]
        stamps = [stamp_ns(msg.markers[0]) for msg in window]
        # The states of the markers' ticks are published before them, on topics of their
        # own, each in order: once a state past the last marker is here, the rest are
        # here or lost.
        wait_for(lambda: first_stamp(js_raw[-1], JointState) > stamps[-1]
                 and first_stamp(md_raw[-1], MultiDOFJointTrajectory) > stamps[-1],
                 STARTUP_S, "the states past the markers' ticks")
        status, _ = proc.stop(signal.SIGINT)
        assert status == 0, proc.output()
    finally:
        if proc.proc.poll() is None:
            proc.proc.kill()
    assert 40 <= len(window) <= 2.0 * MAX_RATE_HZ + 2
    assert stamps == sorted(stamps)
    assert min(np.diff(stamps)) >= NS / MAX_RATE_HZ - 2_000_000
    assert (len(stamps) - 1) / ((stamps[-1] - stamps[0]) / NS) <= MAX_RATE_HZ
    expected = EXPECTED['khurmi_four_bar_ad150']
    js_stamps = sorted({first_stamp(m, JointState) for m in js_raw})
    points = {stamp_ns(m): m for m in (deserialize_message(raw, MultiDOFJointTrajectory)
                                       for raw in md_raw)}
    md_stamps = sorted(points)
    matched = {'joint_states': 0, 'point_accelerations': 0}
    for msg in window:
        assert _counts(msg) == expected
        stamp = stamp_ns(msg.markers[0])
        assert all(stamp_ns(m) == stamp for m in msg.markers)
        assert all(m.header.frame_id == 'mechanism' for m in msg.markers)
        if stamp in set(js_stamps):
            matched['joint_states'] += 1
        else:
            assert _gap_holds(stamp, js_stamps, period_ns), (stamp, 'no joint_states there')
        if stamp not in points:
            assert _gap_holds(stamp, md_stamps, period_ns), (stamp, 'no points there')
            continue
        matched['point_accelerations'] += 1
        # The velocity arrows against the point message of the same tick.
        point = points[stamp].points[0]
        arrows = [m for m in msg.markers if m.ns == 'velocity']
        for m, t, v in zip(arrows, point.transforms, point.velocities, strict=True):
            p = np.array([t.translation.x, t.translation.y])
            np.testing.assert_allclose(_xy(m.points[0]), p, rtol=0, atol=ATOL_PUBLISHED)
            np.testing.assert_allclose(_xy(m.points[1]), p + k_v * np.array(
                [v.linear.x, v.linear.y]), rtol=0, atol=ATOL_PUBLISHED)
    print(f'of {len(window)} markers, the states of {matched} received')
    assert min(matched.values()) > 0, matched


def test_node_without_markers_has_no_markers_publisher(ros, tmp_path):
    """With markers false (the default) the node creates no publisher on markers."""
    ns_topic = f'{SESSION}/markers_off'
    js_list = ros.collect(JointState, f'{ns_topic}/joint_states')
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns_topic}', '-p', 'rate_hz:=200.0')
    try:
        wait_for(lambda: js_list or proc.proc.poll() is not None, STARTUP_S, 'joint_states')
        assert proc.proc.poll() is None, proc.output()
        # The node would create the markers publisher right after diagnostics:
        # once that one is discovered, give discovery a moment more.
        wait_for(lambda: _publisher_types(ros, f'{ns_topic}/diagnostics'), STARTUP_S,
                 'the diagnostics publisher')
        time.sleep(0.5)
        assert _publisher_types(ros, f'{ns_topic}/markers') == []
        assert 'markers=False' in proc.output()
        status, _ = proc.stop(signal.SIGINT)
        assert status == 0, proc.output()
    finally:
        if proc.proc.poll() is None:
            proc.proc.kill()


def test_an_actuator_is_a_cylinder_from_pin_to_pin():
    """The boom's cylinder (issue 18): a CYLINDER whose axis runs from F to Q, as long as it is."""
    scene = mk.parse_scene(yaml.safe_load(BOOM_CYLINDER))
    state = mk.solve(scene, 3.0)
    array = marker_array_from_state(scene, state, frame_id='test_frame')
    (cylinder,) = [m for m in array.markers if m.ns == 'actuators']
    assert (cylinder.id, cylinder.type) == (0, Marker.CYLINDER)
    f, q = state.points['F'].position, state.points['Q'].position
    np.testing.assert_allclose(_xy(cylinder.pose.position), (f + q) / 2, rtol=0,
                               atol=ATOL_POSITION)
    assert cylinder.scale.z == pytest.approx(3.0, rel=1e-15)
    assert cylinder.scale.x == cylinder.scale.y > 0.0
    o = cylinder.pose.orientation
    w, x, y, z = o.w, o.x, o.y, o.z
    assert w * w + x * x + y * y + z * z == pytest.approx(1.0, rel=1e-15)
    axis = [2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y)]  # R e_z
    np.testing.assert_allclose(axis, [*((q - f) / 3.0), 0.0], rtol=0, atol=1e-15)
    assert [m.ns for m in array.markers] == sorted(
        (m.ns for m in array.markers), key=NAMESPACES.index)
    assert not any(m.ns == 'actuators' for m in _markers('quick_return')[3].markers)


def test_a_cylinder_is_drawn_as_a_link_between_its_pins():
    """Excavator: each cylinder is a line strip between its two pins; the arm's points joints."""
    scene = mk.load_scene('excavator')
    full = full_scene(scene)
    state = mk.solve(full, [2.9, 3.4])
    array = marker_array_from_state(full, state, points=scene.output_points)
    strips = [[tuple(_xy(p)) for p in m.points] for m in array.markers if m.ns == 'links']
    points = state.points
    for start, pin in (('F', 'Q'), ('S', 'K')):
        ends = {tuple(points[start].position), tuple(points[pin].position)}
        assert any(set(strip) == ends for strip in strips), (start, pin)
    joints = next(m for m in array.markers if m.ns == 'joints')
    assert len(joints.points) == len(points)


def test_the_excavator_has_a_cylinder_per_actuator():
    """Both of the excavator's cylinders are CYLINDER markers as long as the actuators are."""
    scene = full_scene(mk.load_scene('excavator'))
    state = mk.solve(scene, [2.9, 3.4])
    array = marker_array_from_state(scene, state)
    cylinders = [m for m in array.markers if m.ns == 'actuators']
    assert [(m.id, m.type) for m in cylinders] == [(0, Marker.CYLINDER), (1, Marker.CYLINDER)]
    assert [m.scale.z for m in cylinders] == pytest.approx([2.9, 3.4], rel=1e-14)
