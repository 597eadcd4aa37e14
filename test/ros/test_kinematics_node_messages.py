# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The CDR bytes the node publishes are canonical and decode to exactly the meant messages.

"Canonical" is what ``rosbags`` writes: exactly the length of the message and
zero alignment padding, so that its strict ``deserialize_cdr`` accepts the
bytes. ``rclpy.serialization.serialize_message`` on the Kilted wheels adds
bytes past the end and leaves uninitialized memory in the padding, which is
why :func:`mech_kinematics.ros.cdr.cdr_from_message` exists.
"""

import importlib
import math
import numbers
import struct
import subprocess
import sys

from helpers import start_positions
from hypothesis import assume, given, settings, strategies as st
import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message
from rosbags.interfaces import Nodetype
from rosbags.typesys import get_typestore, Stores
from sensor_msgs.msg import JointState

import mech_kinematics as mk
from mech_kinematics.ros.cdr import (cdr_from_message, marker, MessageTemplate,
                                     padding_from_message, stamp_from_cdr, STAMP_MARKER)
from mech_kinematics.ros.messages import (joint_state_from_state, joint_trajectory_from_state,
                                          multi_dof_trajectory_from_state, TickMessages)

SCENES = mk.scene_names()
FRAME_ID = 'mechanism'
#: rosbags' definitions of the Kilted messages (checked against the installed ones below).
STORE = get_typestore(Stores.ROS2_KILTED)
#: The types the node publishes or will publish, then others that use every other encoding
#: (bounded sequences and strings, fixed arrays, octet, char, 8- to 64-bit integers, float32,
#: an empty structure).
NODE_TYPES = [
    'sensor_msgs/msg/JointState', 'trajectory_msgs/msg/JointTrajectory',
    'trajectory_msgs/msg/MultiDOFJointTrajectory', 'diagnostic_msgs/msg/DiagnosticArray',
    'visualization_msgs/msg/MarkerArray',
]
OTHER_TYPES = [
    'std_msgs/msg/Empty', 'std_msgs/msg/Char', 'std_msgs/msg/ByteMultiArray',
    'std_msgs/msg/Int8MultiArray', 'std_msgs/msg/Int16MultiArray',
    'std_msgs/msg/UInt64MultiArray', 'sensor_msgs/msg/NavSatFix', 'sensor_msgs/msg/BatteryState',
    'geometry_msgs/msg/PolygonInstance', 'rcl_interfaces/msg/ParameterDescriptor',
    'rmw_dds_common/msg/NodeEntitiesInfo',
]
TYPES = NODE_TYPES + OTHER_TYPES
#: rosbags base type -> NumPy dtype of its arrays.
DTYPES = {'bool': np.bool_, 'byte': np.uint8, 'char': np.uint8}
#: Field rosidl leaves out of an empty message and rosbags spells out.
EMPTY_MEMBER = 'structure_needs_at_least_one_member'


def message_class(typename):
    """Return the rclpy class of ``pkg/msg/Name``."""
    package, _, name = typename.split('/')
    return getattr(importlib.import_module(f'{package}.msg'), name)


def typename_of(msg):
    """Return ``pkg/msg/Name`` of an rclpy message."""
    cls = type(msg)
    return f'{cls.__module__.split(".")[0]}/msg/{cls.__name__}'


def nested_types(typenames):
    """Return ``typenames`` and every message type their fields use, recursively."""
    seen, todo = set(), list(typenames)
    while todo:
        typename = todo.pop()
        if typename not in seen:
            seen.add(typename)
            for slot_type in message_class(typename).SLOT_TYPES:
                slot_type = getattr(slot_type, 'value_type', slot_type)
                if type(slot_type).__name__ == 'NamespacedType':
                    todo.append('/'.join([*slot_type.namespaces, slot_type.name]))
    return sorted(seen)


# -- rclpy <-> rosbags ---------------------------------------------------------


def to_rosbags(msg):
    """Return the rosbags message (of :data:`STORE`) equal to the rclpy message ``msg``."""
    msgdef = STORE.get_msgdef(typename_of(msg))
    if not type(msg).get_fields_and_field_types():
        return msgdef.cls(**{EMPTY_MEMBER: 0})
    return msgdef.cls(**{name: _to_rosbags_field(desc, getattr(msg, name))
                         for name, desc in msgdef.fields})


def _scalar(value):
    return value[0] if isinstance(value, bytes) else value


def _to_rosbags_field(desc, value):
    nodetype, detail = desc
    if nodetype == Nodetype.NAME:
        return to_rosbags(value)
    if nodetype == Nodetype.BASE:
        if detail[0] == 'byte':     # rosbags holds a byte as int8
            return int(np.uint8(_scalar(value)).view(np.int8))
        return _scalar(value)
    (sub_nodetype, sub_detail), _ = detail
    if sub_nodetype == Nodetype.BASE and sub_detail[0] != 'string':
        dtype = DTYPES.get(sub_detail[0], sub_detail[0])
        array = np.array([_scalar(v) for v in value], dtype=dtype)
        return array.view(np.int8) if sub_detail[0] == 'byte' else array
    return [_to_rosbags_field((sub_nodetype, sub_detail), v) for v in value]


def _from_rosbags_field(desc, value):
    """Return a rosbags field value, with its ``byte`` values unsigned as in rclpy."""
    nodetype, detail = desc
    if nodetype == Nodetype.BASE and detail[0] == 'byte':
        return int(value) % 256
    if nodetype in (Nodetype.ARRAY, Nodetype.SEQUENCE) and \
            detail[0] == (Nodetype.BASE, ('byte', 0)):
        return [int(v) % 256 for v in value]    # rosbags decodes byte[] as int8
    return value


def tree(value):
    """Return ``value`` (rclpy or rosbags message, or field) as nested tuples, floats as bits."""
    if hasattr(type(value), 'get_fields_and_field_types'):
        return tuple(tree(getattr(value, name)) for name in value.get_fields_and_field_types())
    if hasattr(value, '__msgtype__'):
        return tuple(tree(_from_rosbags_field(desc, getattr(value, name))) for name, desc in
                     STORE.get_msgdef(value.__msgtype__).fields if name != EMPTY_MEMBER)
    if isinstance(value, str):
        return value
    if isinstance(value, bytes):
        assert len(value) == 1, 'rclpy holds an octet as bytes of length 1'
        return value[0]
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, float | np.floating):
        return struct.pack('<d', float(value))  # the bits: -0.0 and 0.0 differ
    return tuple(tree(v) for v in value)


# -- random messages of any type -----------------------------------------------

_INTEGERS = {f'{s}int{n}': (0 if s else -2 ** (n - 1), 2 ** n - 1 if s else 2 ** (n - 1) - 1)
             for s in ('', 'u') for n in (8, 16, 32, 64)}
_PRIMITIVES = {
    'boolean': st.booleans(), 'octet': st.binary(min_size=1, max_size=1),
    'float': st.floats(width=32, allow_nan=False), 'double': st.floats(allow_nan=False),
    **{name: st.integers(low, high) for name, (low, high) in _INTEGERS.items()},
}
#: Longest generated sequence or string (short: deep messages stay small).
MAX_ITEMS = 3


def _values(slot_type):
    kind = type(slot_type).__name__
    if kind == 'BasicType':
        return _PRIMITIVES[slot_type.typename]
    if kind in ('UnboundedString', 'BoundedString'):
        size = min(getattr(slot_type, 'maximum_size', MAX_ITEMS * 3), MAX_ITEMS * 3)
        return st.text(st.characters(codec='utf-8', exclude_characters='\x00'), max_size=size)
    if kind == 'NamespacedType':
        return messages(message_class('/'.join([*slot_type.namespaces, slot_type.name])))
    items = _values(slot_type.value_type)
    if kind == 'Array':
        return st.lists(items, min_size=slot_type.size, max_size=slot_type.size)
    return st.lists(items, max_size=min(getattr(slot_type, 'maximum_size', MAX_ITEMS),
                                        MAX_ITEMS))


def messages(cls):
    """Return a strategy for messages of the rclpy class ``cls`` with random field values."""
    fields = cls.get_fields_and_field_types()
    return st.fixed_dictionaries({name: _values(slot_type) for name, slot_type in
                                  zip(fields, cls.SLOT_TYPES, strict=True)}).map(
        lambda kwargs: cls(**kwargs))


# -- the serializer ------------------------------------------------------------


def test_rosbags_store_has_the_installed_definitions():
    """The rosbags store's field names are the installed rclpy classes' ones, for every type."""
    for typename in nested_types(TYPES):
        fields = [name for name, _ in STORE.get_msgdef(typename).fields if name != EMPTY_MEMBER]
        assert fields == list(message_class(typename).get_fields_and_field_types()), typename


@pytest.mark.parametrize('typename', TYPES)
@settings(max_examples=25, deadline=None)
@given(data=st.data())
def test_cdr_is_rosbags_canonical_cdr(typename, data):
    """The bytes equal rosbags' serialization and decode strictly (rosbags, rclpy) to the msg."""
    msg = data.draw(messages(message_class(typename)))
    raw = cdr_from_message(msg)
    assert raw[:4] == b'\x00\x01\x00\x00'
    assert raw == bytes(STORE.serialize_cdr(to_rosbags(msg), typename))
    assert tree(STORE.deserialize_cdr(raw, typename)) == tree(msg)
    assert tree(deserialize_message(raw, type(msg))) == tree(msg)


@pytest.mark.parametrize('typename', TYPES)
@settings(max_examples=25, deadline=None)
@given(data=st.data())
def test_cdr_is_rclpys_content(typename, data):
    """The bytes rclpy writes, cut to the canonical length, are ours except in the padding."""
    msg = data.draw(messages(message_class(typename)))
    raw = cdr_from_message(msg)
    theirs = bytearray(serialize_message(msg))
    assert len(theirs) >= len(raw)
    del theirs[len(raw):]
    for pad in padding_from_message(msg):
        assert not any(raw[pad.start:pad.stop]), 'padding is zero'
        theirs[pad.start:pad.stop] = bytes(len(pad))
    assert bytes(theirs) == raw


def test_cdr_of_a_joint_state():
    """A JointState of three joints, written out by hand: zero padding and no tail."""
    msg = JointState(name=['a', 'bc', 'def'], position=[1.0, 2.0, -0.0], velocity=[4.0] * 3)
    msg.header.stamp.sec, msg.header.stamp.nanosec = 1, 2
    msg.header.frame_id = 'mechanism'
    expected = b''.join([
        b'\x00\x01\x00\x00', struct.pack('<iI', 1, 2), struct.pack('<I', 10), b'mechanism\0',
        bytes(2), struct.pack('<II', 3, 2), b'a\0', bytes(2), struct.pack('<I', 3), b'bc\0',
        bytes(1), struct.pack('<I', 4), b'def\0', struct.pack('<I', 3),
        struct.pack('<3d', 1.0, 2.0, -0.0), struct.pack('<I', 3), bytes(4),
        struct.pack('<3d', 4.0, 4.0, 4.0), struct.pack('<I', 0)])
    assert cdr_from_message(msg) == expected
    assert [(r.start, r.stop) for r in padding_from_message(msg)] == [
        (26, 28), (38, 40), (47, 48), (88, 92)]
    assert len(cdr_from_message(JointState())) == 36


def test_cdr_refuses_a_type_it_cannot_encode():
    """A wstring field is refused with its name (its encoding cannot be checked here)."""
    from rosidl_parser.definition import UnboundedWString

    class Wide:
        SLOT_TYPES = (UnboundedWString(),)

        @staticmethod
        def get_fields_and_field_types():
            return {'text': 'wstring'}

        text = 'x'

    with pytest.raises(ValueError, match="UnboundedWString for field 'text' of Wide"):
        cdr_from_message(Wide())


def test_cdr_module_needs_no_ros():
    """``mech_kinematics.ros.cdr`` imports neither rclpy nor rosidl_parser."""
    code = ('import sys, mech_kinematics.ros.cdr; '
            "assert not {'rclpy', 'rosidl_parser'} & set(sys.modules), sys.modules")
    subprocess.run([sys.executable, '-c', code], check=True, timeout=60)


# -- the node's messages -------------------------------------------------------


def solve_or_skip(scene, angle, speed, accel):
    """Solve, or tell hypothesis to skip an angle where the scene cannot assemble.

    Several drivers (issue 18) move all at once from their start: a crank by
    ``angle``, an actuator by ``angle`` cm, each at ``speed`` and ``accel``; so
    does an actuator alone (the packaged boom), with the one-driver signature's
    bare values.
    """
    drivers = scene.drivers
    if len(drivers) > 1:
        angle = [d.start + (angle if d.joint_type == 'revolute' else 0.01 * angle)
                 for d in drivers]
        speed, accel = [speed] * len(drivers), [accel] * len(drivers)
    elif drivers[0].joint_type != 'revolute':
        angle = drivers[0].start + 0.01 * angle
    try:
        return mk.solve(scene, angle, speed, accel)
    except mk.AssemblyError:
        assume(False)


@pytest.mark.parametrize('name', SCENES)
@settings(max_examples=20, deadline=None)
@given(angle=st.floats(-math.pi, math.pi), speed=st.floats(-2000, 2000),
       accel=st.floats(-1e4, 1e4), sec=st.integers(0, 2 ** 31 - 1),
       nanosec=st.integers(0, 999_999_999))
def test_rendered_bytes_are_the_canonical_cdr_of_the_messages(name, angle, speed, accel, sec,
                                                              nanosec):
    """Each tick's bytes are rosbags' CDR of the meant message and decode strictly to it."""
    scene = mk.load_scene(name)
    state = solve_or_skip(scene, angle, speed, accel)
    joints, points = scene.output_joints, scene.output_points
    messages = TickMessages(joints, points, FRAME_ID)
    # Render an unrelated state first: nothing of it may survive into the next render.
    messages.render(mk.solve(scene, start_positions(scene)), 1, 2)
    rendered = messages.render(state, sec, nanosec)
    expected = (joint_state_from_state(state, joints, FRAME_ID, sec, nanosec),
                joint_trajectory_from_state(state, joints, FRAME_ID, sec, nanosec),
                multi_dof_trajectory_from_state(state, points, FRAME_ID, sec, nanosec))
    for raw, msg in zip(rendered, expected, strict=True):
        typename = typename_of(msg)
        canonical = bytes(STORE.serialize_cdr(to_rosbags(msg), typename))
        assert isinstance(raw, bytes)
        assert len(raw) == len(canonical)
        assert raw == canonical
        assert tree(STORE.deserialize_cdr(raw, typename)) == tree(msg)
        assert tree(deserialize_message(raw, type(msg))) == tree(msg)
    # The same state renders to the same bytes from templates built anew.
    assert TickMessages(joints, points, FRAME_ID).render(state, sec, nanosec) == rendered


@pytest.mark.parametrize('name', SCENES)
def test_messages_follow_the_contract(name):
    """Names, array lengths, frame, z = 0 and identity rotations are as docs/node.md says."""
    scene = mk.load_scene(name)
    state = mk.solve(scene, start_positions(scene))
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


@pytest.mark.parametrize('velocities', [True, False])
@pytest.mark.parametrize('name', SCENES)
def test_messages_leave_out_what_the_input_does_not_determine(name, velocities):
    """Without velocities or accelerations the arrays are empty, the rest as in a full tick.

    What a node driven from a topic publishes (issue 18): its input never gives the
    accelerations, and the velocities only when the input message has them.
    """
    scene = mk.load_scene(name)
    state = mk.solve(scene, start_positions(scene))
    joints, points = scene.output_joints, scene.output_points
    rendered = TickMessages(joints, points, FRAME_ID, velocities=velocities,
                            accelerations=False).render(state, 11, 12)
    js = joint_state_from_state(state, joints, FRAME_ID, 11, 12)
    jt = joint_trajectory_from_state(state, joints, FRAME_ID, 11, 12)
    md = multi_dof_trajectory_from_state(state, points, FRAME_ID, 11, 12)
    jt.points[0].accelerations = []
    md.points[0].accelerations = []
    if not velocities:
        js.velocity = []
        jt.points[0].velocities = []
        md.points[0].velocities = []
    for raw, msg in zip(rendered, (js, jt, md), strict=True):
        typename = typename_of(msg)
        assert raw == bytes(STORE.serialize_cdr(to_rosbags(msg), typename))
        assert tree(deserialize_message(raw, type(msg))) == tree(msg)
    decoded = deserialize_message(rendered[0], JointState)
    assert list(decoded.position) == [state.joints[n].position for n in joints]
    assert len(decoded.velocity) == (len(joints) if velocities else 0)


def test_messages_refuse_accelerations_without_velocities():
    """A template keeps a prefix of the slots: accelerations without velocities is refused."""
    with pytest.raises(ValueError, match='velocities with accelerations'):
        TickMessages(['a'], ['P'], FRAME_ID, velocities=False)


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


def test_stamp_is_read_from_the_bytes_in_either_byte_order():
    """stamp_from_cdr reads header.stamp of little- and big-endian CDR without decoding."""
    scene = mk.load_scene(SCENES[0])
    state = mk.solve(scene, start_positions(scene))
    rendered = TickMessages(scene.output_joints, scene.output_points, 'f').render(
        state, 1_795_000_000, 123_456_789)
    for data in rendered:
        assert stamp_from_cdr(data) == 1_795_000_000_123_456_789
    big_endian = b'\x00\x00\x00\x00' + struct.pack('>iI', 12, 34) + b'\x00\x00\x00\x00'
    assert stamp_from_cdr(big_endian) == 12 * 1_000_000_000 + 34


def test_templates_of_a_large_scene_keep_every_value():
    """12,000 points (72,000 float slots, beyond 16 bits of slot index) render exactly.

    See issue 12: a node on a scene of thousands of dyads failed with a ValueError.
    """
    from rclpy.serialization import deserialize_message
    from trajectory_msgs.msg import MultiDOFJointTrajectory

    names = [f'P{i}' for i in range(12_000)]
    template = TickMessages(['crank'], names, 'f')
    zs = [complex(i, -i) for i in range(len(names))]
    state = type('State', (), {
        'joints': {'crank': mk.JointMotion('revolute', 0.5, 1.5, 2.5)},
        'complex_points': {n: (z, 2 * z, 3 * z) for n, z in zip(names, zs, strict=True)}})()
    _, _, points = template.render(state, 7, 8)
    msg = deserialize_message(points, MultiDOFJointTrajectory)
    last = msg.points[0]
    assert msg.joint_names[-1] == 'P11999'
    assert last.transforms[-1].translation.x == 11999.0
    assert last.accelerations[-1].linear.y == -3 * 11999.0
