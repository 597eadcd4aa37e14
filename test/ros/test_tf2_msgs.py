# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""tf2_msgs, built into .venv at set-up time (scripts/build_tf2_msgs.py), works as ROS's.

A publisher of ``tf2_msgs/msg/TFMessage`` in one subprocess and a subscriber in
another exchange a message over DDS on a ROS domain of this test's own; the
type hash the publisher announces is real ROS 2 Kilted's, pinned here. See
issue 13.
"""

import json
import math
import os
from pathlib import Path
import random
import subprocess
import sys

import pytest

ROOT = Path(__file__).resolve().parents[2]
BUILD_SCRIPT = ROOT / 'scripts' / 'build_tf2_msgs.py'
#: RIHS01 hash of tf2_msgs/msg/TFMessage as ROS 2 Kilted (and Jazzy) announce it
#: (`ros2 topic info -v /tf`); rosbags' Kilted type store computes the same.
KILTED_TFMESSAGE_HASH = 'RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087'
TIMEOUT_S = 60.0

os.environ['ROS_DOMAIN_ID'] = str(random.SystemRandom().randint(1, 100))
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'

#: (parent, child, x, y, z, qx, qy, qz, qw, sec, nanosec): values only an exact CDR keeps.
TRANSFORMS = [
    ('mechanism', 'mechanism/crank', 0.0, 0.0, 0.0,
     0.0, 0.0, math.sin(math.pi / 6), math.cos(math.pi / 6), 1_700_000_000, 123_456_789),
    ('mechanism', 'mechanism/coupler', 0.04 * math.cos(1.0), 0.04 * math.sin(1.0), 0.0,
     0.0, 0.0, -math.sin(0.1), math.cos(0.1), 1_700_000_000, 123_456_789),
    ('mechanism', 'mechanism/ram', 1 / 3, -2e-17, 0.0, 0.0, 0.0, 0.0, 1.0, 0, 999_999_999),
]

PUBLISHER = """\
import json, sys, time
import rclpy
from geometry_msgs.msg import TransformStamped
from tf2_msgs.msg import TFMessage

topic, rows = sys.argv[1], json.loads(sys.argv[2])
rclpy.init()
node = rclpy.create_node('tf2_msgs_test_publisher')
publisher = node.create_publisher(TFMessage, topic, 10)
msg = TFMessage()
for parent, child, x, y, z, qx, qy, qz, qw, sec, nanosec in rows:
    t = TransformStamped(child_frame_id=child)
    t.header.frame_id = parent
    t.header.stamp.sec, t.header.stamp.nanosec = sec, nanosec
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = x, y, z
    r = t.transform.rotation
    r.x, r.y, r.z, r.w = qx, qy, qz, qw
    msg.transforms.append(t)
deadline = time.monotonic() + float(sys.argv[3])
while time.monotonic() < deadline:
    publisher.publish(msg)
    time.sleep(0.05)
"""

SUBSCRIBER = """\
import json, sys, time
import rclpy
from tf2_msgs.msg import TFMessage

topic = sys.argv[1]
rclpy.init()
node = rclpy.create_node('tf2_msgs_test_subscriber')
received = []
node.create_subscription(TFMessage, topic, received.append, 10)
deadline = time.monotonic() + float(sys.argv[2])
while not received and time.monotonic() < deadline:
    rclpy.spin_once(node, timeout_sec=0.1)
if not received:
    sys.exit('no TFMessage received on ' + topic)
msg = received[0]
rows = [[t.header.frame_id, t.child_frame_id, t.transform.translation.x,
         t.transform.translation.y, t.transform.translation.z, t.transform.rotation.x,
         t.transform.rotation.y, t.transform.rotation.z, t.transform.rotation.w,
         t.header.stamp.sec, t.header.stamp.nanosec] for t in msg.transforms]
publishers = node.get_publishers_info_by_topic(topic)
print(json.dumps({
    'rows': rows,
    'types': [p.topic_type for p in publishers],
    'hashes': [str(p.topic_type_hash) for p in publishers],
}))
"""


def _run_build_script(*args, env=None):
    return subprocess.run([sys.executable, str(BUILD_SCRIPT), *args], capture_output=True,
                          text=True, timeout=300, env=env, check=False)


@pytest.fixture(scope='module')
def exchanged():
    """Publish in one process, subscribe in another; return what the subscriber saw."""
    topic = f'/tf2_msgs_test_{os.getpid()}_{random.SystemRandom().randrange(16 ** 6):06x}'
    publisher = subprocess.Popen(
        [sys.executable, '-c', PUBLISHER, topic, json.dumps(TRANSFORMS), str(TIMEOUT_S)],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        subscriber = subprocess.run(
            [sys.executable, '-c', SUBSCRIBER, topic, str(TIMEOUT_S - 10)],
            capture_output=True, text=True, timeout=TIMEOUT_S, check=False)
    finally:
        publisher.kill()
        publisher_output = publisher.communicate()[0]
    assert subscriber.returncode == 0, (
        f'subscriber:\n{subscriber.stdout}{subscriber.stderr}\npublisher:\n{publisher_output}')
    return json.loads(subscriber.stdout.strip().splitlines()[-1])


def test_tfmessage_crosses_processes_bit_exactly(exchanged):
    """A TFMessage published in one process arrives in another with every value exact."""
    assert [tuple(row) for row in exchanged['rows']] == TRANSFORMS


def test_announced_type_is_kilted_tf2_msgs(exchanged):
    """The publisher announces tf2_msgs/msg/TFMessage with real Kilted's type hash."""
    assert exchanged['types'] == ['tf2_msgs/msg/TFMessage']
    assert exchanged['hashes'] == [KILTED_TFMESSAGE_HASH]


def test_pinned_hash_is_kilteds_by_an_independent_route():
    """The ROS 2 Kilted type store of rosbags hashes TFMessage to the pinned value."""
    from rosbags.typesys import get_typestore, Stores

    store = get_typestore(Stores.ROS2_KILTED)
    assert store.hash_rihs01('tf2_msgs/msg/TFMessage') == KILTED_TFMESSAGE_HASH


def test_build_script_and_installed_description_agree_with_the_pin():
    """The build script's own check and the installed type description use the pinned hash."""
    import tf2_msgs

    assert f"TYPE_HASH = '{KILTED_TFMESSAGE_HASH}'" in BUILD_SCRIPT.read_text(encoding='utf-8')
    package = Path(tf2_msgs.__file__).resolve().parent
    if not (package / 'BUILT_BY_MECH_KINEMATICS.json').is_file():
        pytest.skip(f'tf2_msgs comes from a ROS install ({package}), not from the build script')
    description = json.loads(
        (Path(sys.prefix) / 'share' / 'tf2_msgs' / 'msg' / 'TFMessage.json').read_text())
    hashes = {h['type_name']: h['hash_string'] for h in description['type_hashes']}
    assert hashes['tf2_msgs/msg/TFMessage'] == KILTED_TFMESSAGE_HASH


def test_build_is_idempotent_and_quiet():
    """Run again on an up-to-date venv, the build script does nothing and prints nothing."""
    import tf2_msgs

    library = Path(sys.prefix) / 'lib' / 'libtf2_msgs__rosidl_typesupport_fastrtps_c.so'
    if not library.is_file():
        pytest.skip(f'tf2_msgs comes from a ROS install ({tf2_msgs.__file__})')
    before = library.stat().st_mtime_ns
    result = _run_build_script()
    assert (result.returncode, result.stdout, result.stderr) == (0, '', '')
    assert library.stat().st_mtime_ns == before


def test_build_failure_is_loud_and_leaves_the_install_alone(tmp_path):
    """Without a compiler the build fails with one error naming it; tf2_msgs still works."""
    env = dict(os.environ)
    env['PATH'] = str(tmp_path)     # no gcc, no g++
    result = _run_build_script('--force', env=env)
    assert result.returncode == 1
    assert result.stdout == ''
    assert result.stderr.startswith('error: building tf2_msgs into ')
    assert 'Expected a C and C++ compiler on PATH, got no gcc and no g++' in result.stderr
    check = subprocess.run([sys.executable, '-c', 'from tf2_msgs.msg import TFMessage; '
                            'TFMessage.__class__.__import_type_support__(); '
                            'assert TFMessage._TYPE_SUPPORT is not None'],
                           capture_output=True, text=True, timeout=60, check=False)
    assert check.returncode == 0, check.stderr


def test_an_installed_tf2_msgs_is_used_not_rebuilt(tmp_path):
    """With another tf2_msgs on the path (a sourced ROS install), nothing is built."""
    (tmp_path / 'tf2_msgs').mkdir()
    (tmp_path / 'tf2_msgs' / '__init__.py').write_text('')
    env = dict(os.environ)
    env['PYTHONPATH'] = os.pathsep.join(filter(None, [str(tmp_path), env.get('PYTHONPATH')]))
    library = Path(sys.prefix) / 'lib' / 'libtf2_msgs__rosidl_generator_c.so'
    before = library.stat().st_mtime_ns if library.is_file() else None
    result = _run_build_script('--force', env=env)
    assert result.returncode == 0, result.stderr
    assert result.stdout == (f'tf2_msgs: using the installed package at {tmp_path / "tf2_msgs"};'
                             ' not building it\n')
    assert (library.stat().st_mtime_ns if library.is_file() else None) == before
