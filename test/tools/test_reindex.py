# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The ``reindex`` command: ``python -m mech_kinematics reindex BAG`` (see issue 12).

Its recovery is tested in ``test_bag_storage.py`` (in-process) and
``test_bag_recorder.py`` (after ``kill -9`` of a real recording); here: the
command line, its output and its errors.
"""

from pathlib import Path
import subprocess
import sys

import pytest
import yaml

from mech_kinematics.__main__ import build_parser, TOOLS
from mech_kinematics.bag import BagWriter
from mech_kinematics.tools import reindex

REPO = Path(__file__).resolve().parents[2]


def unclosed_bag(path: Path, storage: str, messages: int):
    """Write a bag of ``messages`` flushed messages on /chatter; return the open writer."""
    writer = BagWriter(path, storage=storage, flush_interval=3600.0)
    writer.open()
    text = 'string data\n'
    topic = writer.add_topic('/chatter', 'std_msgs/msg/String', definition=text,
                             encoding='ros2msg', type_hash=_string_hash(text))
    for i in range(messages):
        data = f'hello {i}'.encode() + b'\0'
        cdr = b'\x00\x01\x00\x00' + len(data).to_bytes(4, 'little') + data
        writer.write(topic, 1_000_000_000 + i * 1_000_000, cdr)
    writer.flush()
    return writer


def _string_hash(text: str) -> str:
    from mech_kinematics.bag.metadata import type_hash_from_definition

    return type_hash_from_definition('std_msgs/msg/String', text, 'ros2msg')


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_reindex_prints_what_the_bag_holds(tmp_path, capsys, storage):
    """Exit 0; a line with storage, version and count, then a table of the topics."""
    writer = unclosed_bag(tmp_path / 'bag', storage, 25)
    assert reindex.main([str(tmp_path / 'bag')]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == f'reindexed {tmp_path / "bag"} ({storage}, bag version 8): 25 messages ' \
                     f'over 0.0 s'
    assert out[-2].split() == ['topic', 'type', 'messages']
    assert out[-1].split() == ['/chatter', 'std_msgs/msg/String', '25']
    meta = yaml.safe_load((tmp_path / 'bag' / 'metadata.yaml').read_text())
    assert meta['rosbag2_bagfile_information']['message_count'] == 25
    from rosbags.highlevel import AnyReader
    with AnyReader([tmp_path / 'bag']) as bag:
        texts = [bag.deserialize(raw, c.msgtype).data for c, _, raw in bag.messages()]
    assert texts == [f'hello {i}' for i in range(25)]
    writer.close()


def test_reindex_takes_the_bag_version(tmp_path, capsys):
    """--bag-version 9 writes version 9 metadata (QoS by name)."""
    writer = unclosed_bag(tmp_path / 'bag', 'mcap', 3)
    assert reindex.main([str(tmp_path / 'bag'), '--bag-version', '9']) == 0
    assert '(mcap, bag version 9)' in capsys.readouterr().out
    meta = yaml.safe_load((tmp_path / 'bag' / 'metadata.yaml').read_text())
    assert meta['rosbag2_bagfile_information']['version'] == 9
    writer.close()


def bad_bags(tmp: Path) -> dict:
    """Name -> (path, the message expected) of things that are not a bag reindex can read."""
    (tmp / 'empty').mkdir()
    (tmp / 'two').mkdir()
    (tmp / 'two' / 'a.mcap').write_bytes(b'')
    (tmp / 'two' / 'b.db3').write_bytes(b'')
    (tmp / 'file').write_text('not a directory')
    (tmp / 'not_mcap').mkdir()
    (tmp / 'not_mcap' / 'x.mcap').write_bytes(b'PK\x03\x04 a zip file' * 10)
    (tmp / 'not_db').mkdir()
    (tmp / 'not_db' / 'x.db3').write_bytes(b'SQLite format 2\0' + bytes(100))
    (tmp / 'empty_mcap').mkdir()
    (tmp / 'empty_mcap' / 'x.mcap').write_bytes(b'')
    return {
        'missing': (tmp / 'missing', 'which does not exist'),
        'file': (tmp / 'file', 'which is not a directory'),
        'empty': (tmp / 'empty', 'Expected one storage file (.mcap or .db3)'),
        'two': (tmp / 'two', 'got a.mcap, b.db3 (split bags are not supported)'),
        'not_mcap': (tmp / 'not_mcap', 'Expected an MCAP file'),
        'empty_mcap': (tmp / 'empty_mcap', 'an empty file'),
        'not_db': (tmp / 'not_db', 'Expected a'),
    }


@pytest.mark.parametrize('name', ['missing', 'file', 'empty', 'two', 'not_mcap', 'empty_mcap',
                                  'not_db'])
def test_what_is_not_a_bag_is_one_error_line(tmp_path, name):
    """Not a bag directory, no or two storage files, not a storage: exit 2, one error: line."""
    path, expected = bad_bags(tmp_path)[name]
    result = subprocess.run([sys.executable, '-m', 'mech_kinematics', 'reindex', str(path)],
                            cwd=REPO, capture_output=True, text=True)
    assert result.returncode == 2
    assert result.stdout == ''
    assert result.stderr.count('\n') == 1 and result.stderr.startswith('error: ')
    assert expected in result.stderr
    assert not (path / 'metadata.yaml').exists() if path.is_dir() else True


def test_reindex_is_a_registered_tool():
    """The command `reindex BAG` parses; the tool module has the shape of every tool."""
    assert reindex in TOOLS
    args = build_parser().parse_args(['reindex', 'some_bag', '--bag-version', '9'])
    assert (args.bag, args.bag_version, args.handler) == ('some_bag', 9, reindex._handle)


def test_importing_reindex_and_the_bag_writer_pulls_in_no_ros():
    """The reindex command and the bag package import rosbags and rclpy only when they run."""
    code = ('import sys, mech_kinematics.__main__, mech_kinematics.bag; '
            'heavy = {"rclpy", "rosbags"} & set(sys.modules); assert not heavy, heavy')
    subprocess.run([sys.executable, '-c', code], check=True, cwd=REPO)
