# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""What the node checks before rclpy.init, without ROS (issue 33: a FIFO hung the start)."""

import os
import signal

import pytest

from mech_kinematics.ros import startup
from mech_kinematics.ros.startup import (argument_files, file_refusal, MAX_ARGUMENT_FILE_BYTES,
                                         start_refusal)


@pytest.mark.parametrize('argv, files', [
    (['node', '--ros-args', '--params-file', 'a.yaml', '-p', 'x:=1', '--params-file', 'b.yaml'],
     [('--params-file', 'a.yaml'), ('--params-file', 'b.yaml')]),
    (['node', '--ros-args', '--params-file=c.yaml', '--log-config-file', 'log.cfg'],
     [('--params-file', 'c.yaml'), ('--log-config-file', 'log.cfg')]),
    # Outside --ros-args ... -- the option is the program's, not rcl's.
    (['node', '--params-file', 'mine.yaml', '--ros-args', '-r', 'a:=b', '--', '--params-file',
      'x'], []),
    (['node', '--ros-args', '-p', '--params-file', '--ros-args', '--params-file', 'd'],
     [('--params-file', 'd')]),                        # a -p value is not an option
    (['node', '--ros-args', '--params-file'], []),      # no path: rcl says what is wrong
])
def test_the_files_rcl_reads_are_found_in_the_ros_arguments(argv, files):
    """Every --params-file and --log-config-file within the ROS arguments, and only those."""
    assert list(argument_files(argv)) == files


def test_what_may_not_be_read_is_refused_naming_the_file(tmp_path):
    """A FIFO, a directory, a device, a missing or too large file: one line, never opened."""
    fifo = tmp_path / 'fifo'
    os.mkfifo(fifo)
    big = tmp_path / 'big.yaml'
    big.write_bytes(b'#' * (MAX_ARGUMENT_FILE_BYTES + 1))
    ok = tmp_path / 'ok.yaml'
    ok.write_bytes(b'#' * MAX_ARGUMENT_FILE_BYTES)
    option = '--params-file'
    assert file_refusal(option, str(fifo)) == \
        f'--params-file {fifo}: expected a regular file, got a FIFO (named pipe)'
    assert file_refusal(option, str(tmp_path)) == \
        f'--params-file {tmp_path}: expected a regular file, got a directory'
    assert file_refusal(option, '/dev/null') == \
        '--params-file /dev/null: expected a regular file, got a character device'
    assert file_refusal(option, str(tmp_path / 'none.yaml')) == \
        f'--params-file {tmp_path}/none.yaml: expected a readable file, got no such file or ' \
        'directory'
    assert file_refusal(option, str(big)) == \
        f'--params-file {big}: expected a file of at most 16777216 bytes (16 MiB), got ' \
        '16777217 bytes'
    assert file_refusal(option, str(ok)) is None
    assert file_refusal(option, 'a\0b') == \
        "--params-file 'a\\x00b': expected a file path, got embedded null byte"
    assert start_refusal(['n', '--ros-args', '--params-file', str(ok), '--params-file',
                          str(fifo)]) == file_refusal(option, str(fifo))
    assert start_refusal(['n', '--ros-args', '--params-file', str(ok)]) is None


def test_a_stop_signal_is_noted_not_acted_on(monkeypatch):
    """catch_stop_signals: SIGINT and SIGTERM are noted (no KeyboardInterrupt, no kill)."""
    monkeypatch.setattr(startup, '_asked', [])
    previous = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        startup.catch_stop_signals()
        startup.catch_stop_signals()        # again: the note is kept
        assert not startup.stop_asked()
        signal.raise_signal(signal.SIGINT)
        signal.raise_signal(signal.SIGTERM)
        assert startup.stop_asked()
        assert startup._asked == [signal.SIGINT, signal.SIGTERM]
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
