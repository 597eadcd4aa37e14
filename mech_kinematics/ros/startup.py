# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""What the node checks before ``rclpy.init``, and a stop asked for while it starts.

``rclpy.init`` hands the ROS arguments to rcl, which reads every
``--params-file`` (and ``--log-config-file``) with a blocking ``fopen``: a
FIFO there hangs the process before any of our code runs again, a 10 MB file
takes seconds to parse. :func:`start_refusal` looks at those paths first,
without opening them: a path that is missing, not a regular file (a FIFO, a
directory, a device) or larger than :data:`MAX_ARGUMENT_FILE_BYTES` is
refused in one line naming the option and the file. (The scene file is ours:
:func:`mech_kinematics.load_scene` refuses the same way.) A path that turns
into a FIFO between this look and rcl's open is not caught.

A SIGINT or SIGTERM while the node starts must end it cleanly (status 0, no
traceback), wherever it lands. :func:`catch_stop_signals` replaces Python's
handlers (SIGINT's raises KeyboardInterrupt wherever the main thread is,
SIGTERM's kills the process) by one that only notes the signal
(:func:`stop_asked`); the starting code looks at that note between its steps
(``rclpy.init`` is told to install no handler of its own). rclpy's handler,
which shuts the context down from another thread, is installed only when the
node is about to spin: shutting the context down under a step of the start
made that step fail ("cannot start"), leave a half-built executor (a
traceback), or crash the process (SIGSEGV). rclpy's handler calls the one it
replaced, this one, so the note stays true once a stop is asked. A step
that may run long in our own code, reading the scene or the robot (a URDF
of 40,000 joints reads for tens of seconds), runs within
:func:`stop_raises`: there a signal raises :class:`StopRequested` at once,
ending the step, and the start ends with status 0 (a step of rclpy's never
runs within it: raising under rclpy's calls is what left half-built objects
behind). Before
:func:`catch_stop_signals` runs (Python importing the package, NumPy among
it), a SIGTERM ends the process by its default action (killed by the signal,
no output).

Thread use: the main thread only (signal handlers run there).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from contextlib import contextmanager
import os
import signal
import stat
from types import FrameType

from ..scene import MAX_FILE_BYTES

__all__ = ['FILE_OPTIONS', 'MAX_ARGUMENT_FILE_BYTES', 'StopRequested', 'argument_files',
           'catch_stop_signals', 'file_refusal', 'start_refusal', 'stop_asked', 'stop_raises']

#: The ROS arguments that name a file rcl reads at ``rclpy.init``.
FILE_OPTIONS = ('--params-file', '--log-config-file')
#: ROS arguments followed by a value (the value is not an option even if it looks like one).
_WITH_VALUE = (*FILE_OPTIONS, '-p', '--param', '-r', '--remap', '-e', '--enclave',
               '--log-level', '--log-file-name')
#: Largest file an argument may name, bytes: twice :data:`~mech_kinematics.scene.MAX_FILE_BYTES`
#: (16 MiB), room for a parameters file holding the largest ``robot_description`` (8 MiB) in
#: YAML, its quotes escaped and its lines indented (``yaml.safe_dump`` wrote a 5.8 MB URDF in
#: 6.4 MB). rcl reads it in C, which no signal interrupts: 2.5 s for those 6.4 MB on a
#: loaded machine.
MAX_ARGUMENT_FILE_BYTES = 2 * MAX_FILE_BYTES

_FILE_KINDS = ((stat.S_ISDIR, 'a directory'), (stat.S_ISFIFO, 'a FIFO (named pipe)'),
               (stat.S_ISCHR, 'a character device'), (stat.S_ISBLK, 'a block device'),
               (stat.S_ISSOCK, 'a socket'))

_STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
_asked: list[int] = []
_raising: list[bool] = []   # non-empty within stop_raises()


class StopRequested(BaseException):
    """A SIGINT or SIGTERM within :func:`stop_raises`: the start ends, status 0.

    A ``BaseException``, as ``KeyboardInterrupt`` is: a step's ``except
    Exception`` (a refusal in one line) does not take it for a failure.
    """


def argument_files(argv: Sequence[str]) -> Iterator[tuple[str, str]]:
    """Yield (option, path) for each file option within the ROS arguments of ``argv``.

    ROS arguments follow ``--ros-args`` up to ``--`` (or the end); the same
    option outside them is the program's, not rcl's. Both ``--params-file
    PATH`` and ``--params-file=PATH`` are read.
    """
    ros = False
    args = iter(argv)
    for arg in args:
        if arg == '--ros-args':
            ros = True
        elif arg == '--':
            ros = False
        elif ros:
            option, equals, value = arg.partition('=')
            if option in FILE_OPTIONS and equals:
                yield option, value
            elif arg in _WITH_VALUE:
                value = next(args, None)
                if arg in FILE_OPTIONS and value is not None:
                    yield arg, value


def file_refusal(option: str, path: str) -> str | None:
    """Return why ``path`` (given to ``option``) may not be read at start, or ``None``.

    Only ``stat`` looks at it: a FIFO is never opened.
    """
    try:
        info = os.stat(path)
    except OSError as error:
        return f'{option} {path}: expected a readable file, got {_lower(error)}'
    except ValueError as error:     # an embedded null byte
        return f'{option} {path!r}: expected a file path, got {error}'
    if not stat.S_ISREG(info.st_mode):
        kind = next((name for test, name in _FILE_KINDS if test(info.st_mode)),
                    'not a regular file')
        return f'{option} {path}: expected a regular file, got {kind}'
    if info.st_size > MAX_ARGUMENT_FILE_BYTES:
        return (f'{option} {path}: expected a file of at most {MAX_ARGUMENT_FILE_BYTES} bytes '
                f'({MAX_ARGUMENT_FILE_BYTES >> 20} MiB), got {info.st_size} bytes')
    if not os.access(path, os.R_OK):
        return f'{option} {path}: expected a readable file, got permission denied'
    return None


def _lower(error: OSError) -> str:
    text = error.strerror or str(error)
    return text[:1].lower() + text[1:]


def start_refusal(argv: Sequence[str]) -> str | None:
    """Return why the node may not start with the arguments ``argv`` (the first reason)."""
    for option, path in argument_files(argv):
        reason = file_refusal(option, path)
        if reason is not None:
            return reason
    return None


def _note(signum: int, frame: FrameType | None) -> None:
    _asked.append(signum)
    if _raising:
        _raising.clear()    # once: the step's own clean-up runs undisturbed
        raise StopRequested(signal.Signals(signum).name)


@contextmanager
def stop_raises() -> Iterator[None]:
    """Run a step of the start that a SIGINT or SIGTERM ends at once (:class:`StopRequested`).

    For our own code only (reading a scene or a robot): no rclpy call may run
    within it. A stop already asked raises on entry.

    Raises
    ------
    StopRequested
        A stop asked for before or during the step.
    """
    if _asked:
        raise StopRequested(signal.Signals(_asked[0]).name)
    _raising.append(True)
    try:
        yield
    finally:
        _raising.clear()


def catch_stop_signals() -> None:
    """Note SIGINT and SIGTERM (:func:`stop_asked`) instead of Python's default actions.

    Call it from the main thread as early as possible; calling it again
    keeps the note.
    """
    for signum in _STOP_SIGNALS:
        if signal.getsignal(signum) is not _note:
            signal.signal(signum, _note)


def stop_asked() -> bool:
    """Return whether a SIGINT or SIGTERM came since :func:`catch_stop_signals`."""
    return bool(_asked)
