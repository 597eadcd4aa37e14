# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The ``reindex`` command: ``python -m mech_kinematics reindex BAG`` (see issues 12 and 33).

Its recovery is tested in ``test_bag_storage.py`` (in-process) and
``test_bag_recorder.py`` (after ``kill -9`` of a real recording, and while a
real recording runs); here: the command line, its output and its errors, and
what it does with a bag that another process holds or that it cannot write.
"""

import ctypes
import inspect
import os
from pathlib import Path
import resource
import shutil
import signal
import subprocess
import sys

import pytest
import yaml

from mech_kinematics.__main__ import build_parser, TOOLS
from mech_kinematics.bag import BagError, BagWriter, reindex as reindex_bag
from mech_kinematics.bag.writer import RESERVE_FILE, STORAGES
from mech_kinematics.tools import reindex

REPO = Path(__file__).resolve().parents[2]

#: A bag written by a BagWriter in another process, flushed, then held open until killed.
#: (``unclosed_bag`` and ``_string_hash`` are pasted in: importing this module would
#: load every command, as ``mech_kinematics.__main__`` does.)
WRITER = """
import sys
from pathlib import Path
from mech_kinematics.bag import BagWriter
{functions}
writer = unclosed_bag(Path(sys.argv[1]), sys.argv[2], int(sys.argv[3]))
print('holding', flush=True)
sys.stdin.read()
"""
#: A process that holds the storage file ``sys.argv[1]`` open, as ``sys.argv[2]`` says.
HOLDER = """
import ctypes, os, sqlite3, sys
path, how = sys.argv[1], sys.argv[2]
if how == 'sqlite3':
    held = sqlite3.connect(path)
    held.execute('SELECT COUNT(*) FROM messages').fetchone()
elif how == 'open':
    held = open(path, 'rb')
else:       # mapped, its descriptor closed (Python's mmap would keep a duplicate open)
    libc = ctypes.CDLL(None, use_errno=True)
    libc.mmap.restype = ctypes.c_void_p
    libc.mmap.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int, ctypes.c_int,
                          ctypes.c_int, ctypes.c_long]
    fd = os.open(path, os.O_RDONLY)
    assert libc.mmap(None, os.fstat(fd).st_size, 1, 1, fd, 0) not in (None, 2**64 - 1)
    os.close(fd)
print('holding', flush=True)
sys.stdin.read()
"""


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


def killed_bag(path: Path, storage: str, messages: int) -> Path:
    """Return ``path``: a bag of ``messages`` messages as kill -9 of its writer leaves it."""
    writer = unclosed_bag(path.with_name(path.name + '_source'), storage, messages)
    shutil.copytree(writer.path, path)
    writer.close()
    return path


def storage_file(path: Path, storage: str) -> Path:
    """Return the storage file of the bag ``path`` (named after the bag it was copied from)."""
    (file,) = path.glob(f'*{STORAGES[storage]}')
    return file


def run_reindex(path: Path, **popen) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mech_kinematics', 'reindex', str(path)],
                          cwd=REPO, capture_output=True, text=True, **popen)


def reindex_here(path: Path, capsys) -> subprocess.CompletedProcess:
    """Run ``reindex PATH`` as its ``main`` in this process: its status and output.

    For every question but the command's own end-to-end calls (``run_reindex``:
    a bag this process holds, a reindex that cannot write, a missing bag).
    """
    capsys.readouterr()
    status = reindex.main([str(path)])
    out, err = capsys.readouterr()
    return subprocess.CompletedProcess(['reindex', str(path)], status, out, err)


def assert_one_error_line(result: subprocess.CompletedProcess, *parts: str) -> None:
    """Exit 2, nothing on stdout, one ``error:`` line holding every one of ``parts``."""
    assert result.returncode == 2, result.stdout + result.stderr
    assert result.stdout == ''
    assert result.stderr.count('\n') == 1 and result.stderr.startswith('error: ')
    for part in parts:
        assert part in result.stderr


def _string_hash(text: str) -> str:
    from mech_kinematics.bag.metadata import type_hash_from_definition

    return type_hash_from_definition('std_msgs/msg/String', text, 'ros2msg')


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_reindex_prints_what_the_bag_holds(tmp_path, capsys, storage):
    """Exit 0; a line with storage, version and count, then a table of the topics."""
    killed_bag(tmp_path / 'bag', storage, 25)
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


def test_reindex_takes_the_bag_version(tmp_path, capsys):
    """--bag-version 9 writes version 9 metadata (QoS by name)."""
    killed_bag(tmp_path / 'bag', 'mcap', 3)
    assert reindex.main([str(tmp_path / 'bag'), '--bag-version', '9']) == 0
    assert '(mcap, bag version 9)' in capsys.readouterr().out
    meta = yaml.safe_load((tmp_path / 'bag' / 'metadata.yaml').read_text())
    assert meta['rosbag2_bagfile_information']['version'] == 9


# -- a bag that another process holds (issue 33) ----------------------------------------


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_a_bag_being_written_is_refused(tmp_path, storage):
    """An open BagWriter (of this test) locks its bag: reindex exits 2, the bag untouched."""
    writer = unclosed_bag(tmp_path / 'bag', storage, 40)
    file = storage_file(tmp_path / 'bag', storage)
    before = file.read_bytes()
    result = run_reindex(tmp_path / 'bag')
    assert_one_error_line(result, f'Expected a bag that no other process holds open, got '
                                  f'"{tmp_path / "bag"}": its storage file {file.name} is locked: '
                                  f'process {os.getpid()} (', ') has it locked and open (a '
                                  'recording still running?); run reindex once it has ended')
    with pytest.raises(BagError, match=rf'is locked: this process \({os.getpid()}\) has it '
                                       rf'locked \(a recording still running\?\)'):
        reindex_bag(tmp_path / 'bag')
    assert file.read_bytes() == before
    assert sorted(p.name for p in (tmp_path / 'bag').iterdir()) == sorted([file.name,
                                                                           RESERVE_FILE])
    info = writer.close()
    assert info.count('/chatter') == 40 and info.notes == ()


def hold(argv: list, tmp: Path) -> subprocess.Popen:
    """Start ``python -c argv...`` and return it once it says it holds the file."""
    process = subprocess.Popen([sys.executable, '-c', *argv], cwd=tmp, stdin=subprocess.PIPE,
                               stdout=subprocess.PIPE, text=True)
    said = process.stdout.readline()
    if said != 'holding\n':
        process.kill()
        process.communicate()
        pytest.fail(f'expected the holder to say "holding", got {said!r}')
    return process


@pytest.mark.parametrize('how', ['writer', 'open', 'mapped', 'sqlite3'])
def test_a_bag_another_process_holds_is_refused_until_it_ends(tmp_path, capsys, how):
    """Locked, open or mapped by another process: exit 2 naming it; once it is killed, reindexed.

    ``writer``: our BagWriter in another process (its lock); ``open`` and
    ``mapped``: a reader that takes no lock; ``sqlite3``: an idle connection.
    The reindex runs in this process (the holder is the other one).
    """
    storage = 'sqlite3' if how == 'sqlite3' else 'mcap'
    bag = tmp_path / 'bag'
    if how == 'writer':
        functions = '\n'.join(inspect.getsource(f) for f in (unclosed_bag, _string_hash))
        code = WRITER.format(functions=functions)
        holder = hold([code, str(bag), storage, '30'], tmp_path)
        file = storage_file(bag, storage)
        said = 'has it locked and open'
    else:
        file = storage_file(killed_bag(bag, storage, 30), storage)
        holder = hold([HOLDER, str(file), how], tmp_path)
        said = 'has it mapped' if how == 'mapped' else 'has it open'
    try:
        before = file.read_bytes()
        result = reindex_here(bag, capsys)
        assert_one_error_line(result, f'got "{bag}": its storage file {file.name} ',
                              f'process {holder.pid} ({Path(sys.executable).name} -c ', said)
        assert file.read_bytes() == before
        assert not (bag / 'metadata.yaml').exists()
    finally:
        holder.kill()
        holder.communicate()
    assert holder.returncode == -signal.SIGKILL
    result = reindex_here(bag, capsys)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith(f'reindexed {bag} ({storage}, bag version 8): 30 messages')


# -- reindex twice, and a reindex that cannot write -------------------------------------


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_reindex_twice_changes_nothing_the_second_time(tmp_path, capsys, storage):
    """The second reindex of a killed recording: the same messages, not a byte written."""
    bag = killed_bag(tmp_path / 'bag', storage, 500)
    assert reindex_here(bag, capsys).returncode == 0
    files = {p.name: p.read_bytes() for p in bag.iterdir()}
    result = reindex_here(bag, capsys)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith(f'reindexed {bag} ({storage}, bag version 8): 500 messages')
    assert {p.name: p.read_bytes() for p in bag.iterdir()} == files


def _cannot_write(cause: str, limit: int):
    """Return the preexec_fn of a reindex that cannot write: a file size limit, or no rights."""
    def preexec() -> None:
        if cause == 'file size limit':
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
        elif os.geteuid() == 0:     # root writes into a read-only directory unless it drops
            libc = ctypes.CDLL(None, use_errno=True)
            for capability in (1, 2):       # CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH
                if libc.prctl(24, capability, 0, 0, 0) != 0:     # PR_CAPBSET_DROP
                    raise OSError(ctypes.get_errno(), 'prctl(PR_CAPBSET_DROP)')
    return preexec


@pytest.mark.parametrize('cause', ['read-only directory', 'file size limit'])
@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_a_reindex_that_cannot_write_leaves_the_bag_as_it_was(tmp_path, storage, cause):
    """No rights in the directory, or no room (RLIMIT_FSIZE of 4 KiB): the file unchanged.

    The storage file of a killed recording keeps every byte, no copy or
    ``.damaged`` file is left; if reindex cannot finish, it says why in one
    line (exit 2).
    """
    bag = killed_bag(tmp_path / 'bag', storage, 3000)
    file = storage_file(bag, storage)
    before = file.read_bytes()
    if cause == 'read-only directory':
        bag.chmod(0o555)
    try:
        result = run_reindex(bag, preexec_fn=_cannot_write(cause, 4096))
    finally:
        bag.chmod(0o755)
    assert file.read_bytes() == before
    assert {p.name for p in bag.iterdir()} <= {file.name, 'metadata.yaml', RESERVE_FILE}
    if storage == 'mcap' or cause == 'read-only directory':
        reason = 'File too large' if cause == 'file size limit' else 'Permission denied'
        assert_one_error_line(result, reason)
    else:       # sqlite3: the metadata table left as it was, metadata.yaml written
        assert result.returncode == 0, result.stderr
        assert 'left the metadata table as it was' in result.stdout


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
def test_what_is_not_a_bag_is_one_error_line(tmp_path, capsys, name):
    """Not a bag directory, no or two storage files, not a storage: exit 2, one error: line.

    ``missing`` runs the command end to end (a subprocess); the others in this process.
    """
    path, expected = bad_bags(tmp_path)[name]
    result = run_reindex(path) if name == 'missing' else reindex_here(path, capsys)
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
