# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Record topics to a rosbag2 bag with no ROS install: ``python -m mech_kinematics record``.

The recorder subscribes with *raw* subscriptions (the serialized CDR bytes,
never decoded) and hands the bytes to :class:`~mech_kinematics.bag.BagWriter`, the way
``ros2 bag record`` hands them to rosbag2. What real ROS tools need to open
the bag comes from the ROS graph and the installed interface files, as
rosbag2 does it:

- the type name (``sensor_msgs/msg/JointState``) and the offered QoS
  profiles of the publishers (``get_publishers_info_by_topic``);
- the type hash (``RIHS01_...``) the publishers announce;
- the message definition: the ``.msg`` file of the type and of every type it
  uses, from the ament index, concatenated with rosbag2's delimiters
  (``rosbag2_cpp`` ``LocalMessageDefinitionSource``), encoding ``ros2msg``.

Bag format version 8 is the default: its metadata is readable by Humble and
later, while version 9 metadata is not readable by Humble (rosbag2#1895).
Ctrl-C, SIGTERM or the end of ``--duration`` stop the recording. What the
subscriptions have already received and not yet handed over is then taken:
each subscription's queue is taken directly, in order, up to the first
message published after the stop (its DDS source timestamp), which is left
out, for at most :data:`DRAIN_S` in all (a recorder starved of the CPU on a
loaded machine held the last 1.2 s of a 500 Hz topic there). Then the
subscriptions are destroyed and the bag is closed: every message published
before the stop and received is in it. A message published before its
topic's subscription matched (the topics are discovered one after another)
is not the recorder's to receive: the state topics are volatile, as rosbag2
records them.

Nothing is lost if the recorder itself dies: messages reach the storage file
every :data:`~mech_kinematics.bag.FLUSH_INTERVAL_S` (an MCAP chunk closed and synced,
an sqlite3 transaction committed; a flush that takes longer is warned of, and
each is logged at debug level), and ``python -m mech_kinematics reindex``
rebuilds ``metadata.yaml`` after ``kill -9``. A write error (a full disk) stops
the recording: the bag is closed with what it holds, its metadata counting
exactly that, and the command prints one ``error:`` line and exits with 1.

A slow disk delays the bag (its writing thread, :class:`~mech_kinematics.bag.QueuedWriter`)
while messages wait in memory, up to ``--max-queue-bytes``; beyond it, a message is
dropped and counted (a log line while recording says how many, a ``warning:`` line at
the end names them per topic, and the command exits with 3).

While no topic has a publisher, a log line says which topics it waits for
(every :data:`WAIT_REPORT_INTERVAL_S`); while recording, a line every
``--progress`` seconds gives the messages per topic and per second.

ROS is imported only when recording starts, so that the command line and the
solver stay importable without it.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence
import contextlib
from dataclasses import dataclass
import importlib
import math
import os
from pathlib import Path
import re
import signal
import sys
import threading
import time
from typing import Any

from .cli import positive_int, positive_seconds, run_tool, seconds_or_zero
from .. import bag
from ..errors import MechKinematicsError
from ..ros import topics
from ..units import NS_PER_S

__all__ = [
    'BAG_VERSIONS', 'BagRecorder', 'DEFAULT_BAG_VERSION', 'DEFAULT_EXECUTOR',
    'DEFAULT_NAMESPACES', 'DEFAULT_PROGRESS_S', 'DEFAULT_STORAGE', 'DEFAULT_TOPICS',
    'EXECUTORS', 'MAX_QUEUE_BYTES', 'RecorderError',
    'STORAGES', 'TopicStats', 'WAIT_REPORT_INTERVAL_S', 'add_parser', 'main',
    'message_definition', 'record', '_handle',
]

#: Everything the node publishes, so that a bag replays whole (issue 20): its state,
#: frames, diagnostics, markers (when on), URDF, scene and shaking force (a scene with
#: masses; its reactions come with DEFAULT_NAMESPACES). Relative names take the
#: recorder's namespace; /tf and /tf_static are absolute, as every TF broadcaster's.
DEFAULT_TOPICS = (*topics.STATE_TOPICS, topics.DIAGNOSTICS, topics.TF, topics.TF_STATIC,
                  topics.MARKERS, topics.ROBOT_DESCRIPTION, topics.SCENE, topics.SHAKING)
#: Namespaces whose every topic is recorded with the default topics, as each appears: the
#: scene's IMUs (``imu/NAME``, one per sensor, named by the scene) and the joints'
#: reactions (``reactions/JOINT``, named by the scene or the URDF, with forces).
DEFAULT_NAMESPACES = (topics.IMU, topics.REACTIONS)
#: Default topics the node publishes only with a parameter or a scene that asks for them:
#: their absence is no fault, and the summary says why they may be absent.
OPTIONAL_TOPICS = {topics.MARKERS: 'the node publishes it with markers:=true',
                   topics.SHAKING: 'the node publishes it for a scene whose links have masses'}
#: The bag writer's storages and versions (it checks them).
STORAGES = tuple(bag.STORAGES)
#: As ``ros2 bag record`` since Iron.
DEFAULT_STORAGE = 'mcap'
BAG_VERSIONS = bag.BAG_VERSIONS
DEFAULT_BAG_VERSION = bag.DEFAULT_VERSION
#: Most bytes of received messages waiting for the disk (``--max-queue-bytes``).
MAX_QUEUE_BYTES = bag.MAX_QUEUE_BYTES
#: Exit status of a recording that ended normally but dropped messages (the queue full).
DROPPED_STATUS = 3
NODE_NAME = 'mech_kinematics_recorder'
#: How often the graph is searched for topics not subscribed yet, and pending messages
#: are checked for a flush, s (rosbag2 searches every 100 ms).
POLL_INTERVAL_S = 0.1
#: How often the topics still without a publisher are named while nothing is recorded, s;
#: the first time FIRST_WAIT_REPORT_S after start.
WAIT_REPORT_INTERVAL_S = 5.0
FIRST_WAIT_REPORT_S = 1.0
#: How often, at most, a warning is repeated while its cause lasts (messages dropped because
#: the queue for the disk is full; flushes slower than their interval), s.
WARNING_INTERVAL_S = 5.0
#: Default interval of the progress lines (messages per topic and per second), s.
DEFAULT_PROGRESS_S = 5.0
#: Depth of each subscription's queue: 1 s of a 1 kHz topic.
QUEUE_DEPTH = 1000
#: Longest wait of one executor step, s: bounds the reaction to a signal or the deadline.
SPIN_STEP_S = 0.05
#: Longest time spent after the stop taking what the subscriptions hold (the messages
#: published before it), s: a bound on a recorder starved of the CPU, never reached by one
#: that keeps up (a queue's draining ends at its first message published after the stop).
DRAIN_S = 5.0

EXECUTORS = ('events', 'single')
DEFAULT_EXECUTOR = 'events'

_DELIMITER = '=' * 80 + '\n'
# rosbag2_cpp LocalMessageDefinitionSource: the field types of a .msg file.
_MSG_FIELD_TYPE = re.compile(r'(?:^|\n)\s*([a-zA-Z0-9_/]+)(?:\[[^\]]*\])?\s+')
_IDL_INCLUDE = re.compile(r'(?:^|\n)#include\s+(?:"|<)([a-zA-Z0-9_/]+)\.idl(?:"|>)')
_PRIMITIVE_TYPES = frozenset((
    'bool', 'byte', 'char', 'float32', 'float64', 'int8', 'uint8', 'int16', 'uint16', 'int32',
    'uint32', 'int64', 'uint64', 'string'))
_MAX_DEPTH = 50


class RecorderError(MechKinematicsError):
    """A recording cannot start or cannot continue (bad output path, options, type)."""


# -- message definitions ---------------------------------------------------------


def _share_directory(package: str) -> Path:
    """Return ``share/<package>`` of the first prefix whose ament index lists ``package``.

    The prefixes are those of ``AMENT_PREFIX_PATH`` (a sourced ROS install or
    workspace), then this Python environment's own prefix, where the ROS 2
    wheels from PyPI install ``share/`` without setting ``AMENT_PREFIX_PATH``.
    """
    prefixes = [p for p in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if p]
    prefixes.append(sys.prefix)
    for prefix in prefixes:
        marker = Path(prefix, 'share', 'ament_index', 'resource_index', 'packages', package)
        if marker.is_file():
            return Path(prefix, 'share', package)
    msg = (f'Expected package "{package}" in the ament index of one of {prefixes}, '
           f'got no such package')
    raise RecorderError(msg)


def _split_type(type_name: str) -> tuple[str, str, str]:
    parts = type_name.split('/')
    if len(parts) == 2:
        return parts[0], 'msg', parts[1]
    if len(parts) == 3:
        return parts[0], parts[1], parts[2]
    msg = f'Expected a type name such as "sensor_msgs/msg/JointState", got "{type_name}"'
    raise RecorderError(msg)


def message_definition(type_name: str) -> tuple[str, str]:
    """Return ``(encoding, text)``: the full definition of ``type_name`` as rosbag2 stores it.

    The text is the type's ``.msg`` file followed by the file of every type
    it depends on, each once, after a line of 80 ``=`` and ``MSG: pkg/Type``,
    dependencies in sorted order, depth first: the algorithm of rosbag2_cpp's
    ``LocalMessageDefinitionSource::get_full_text``. Where a ``.msg`` file is
    missing the ``.idl`` files are used (encoding ``ros2idl``).

    Parameters
    ----------
    type_name : str
        E.g. ``sensor_msgs/msg/JointState``.

    Returns
    -------
    encoding : str
        ``'ros2msg'`` or ``'ros2idl'``.
    text : str
        The definition.

    Raises
    ------
    RecorderError
        If the package or an interface file cannot be found.
    """
    try:
        return 'ros2msg', _full_text(type_name, 'msg')
    except RecorderError as msg_error:
        try:
            return 'ros2idl', _delimiter(type_name, 'idl') + _full_text(type_name, 'idl')
        except RecorderError:
            raise msg_error from None


def _delimiter(type_name: str, fmt: str) -> str:
    return f'{_DELIMITER}{fmt.upper()}: {type_name}\n'


def _full_text(root: str, fmt: str) -> str:
    texts: dict[str, tuple[str, list[str]]] = {}

    def load(type_name: str) -> tuple[str, list[str]]:
        if type_name not in texts:
            package, namespace, name = _split_type(type_name)
            path = _share_directory(package) / namespace / f'{name}.{fmt}'
            try:
                text = path.read_text(encoding='utf-8')
            except OSError as error:
                msg = (f'Expected the definition of {type_name} in {path}, got '
                       f'{error.strerror or error}')
                raise RecorderError(msg) from None
            if fmt == 'msg':
                deps = set()
                for match in _MSG_FIELD_TYPE.finditer(text):
                    dep = match.group(1)
                    if dep not in _PRIMITIVE_TYPES:
                        deps.add(dep if '/' in dep else f'{package}/{dep}')
            else:
                deps = {m.group(1) for m in _IDL_INCLUDE.finditer(text)}
            texts[type_name] = (text, sorted(deps))
        return texts[type_name]

    seen: set[str] = set()

    def append(type_name: str, depth: int) -> str:
        if depth <= 0:
            msg = f'Expected the definition of {root} to nest less deeply, got {_MAX_DEPTH} levels'
            raise RecorderError(msg)
        text, deps = load(type_name)
        out = [text]
        for dep in deps:
            if dep not in seen:
                seen.add(dep)
                out.append('\n' + _delimiter(dep, fmt) + append(dep, depth - 1))
        return ''.join(out)

    return append(root, _MAX_DEPTH)


# -- QoS -------------------------------------------------------------------------


def _qos_from_profile(profile: Any) -> Any:
    """Return the rosbags ``Qos`` of an rclpy ``QoSProfile``, durations as rmw reports them."""
    from rosbags.interfaces import (Qos, QosDurability, QosHistory, QosLiveliness,
                                    QosReliability, QosTime)

    def duration(value: Any) -> QosTime:
        # RMW_DURATION_INFINITE is {9223372036 s, 854775807 ns}, as rosbag2 writes it.
        return QosTime(*divmod(int(value.nanoseconds), NS_PER_S))

    return Qos(QosHistory(int(profile.history)), int(profile.depth),
               QosReliability(int(profile.reliability)), QosDurability(int(profile.durability)),
               duration(profile.deadline), duration(profile.lifespan),
               QosLiveliness(int(profile.liveliness)),
               duration(profile.liveliness_lease_duration),
               bool(profile.avoid_ros_namespace_conventions))


def _request_qos(offers: Sequence[Any]) -> Any:
    """Return the subscription QoS that matches every offer (rosbag2 ``adapt_request_to_offers``).

    Reliable if every publisher is reliable, transient-local if every
    publisher is; the queue is :data:`QUEUE_DEPTH` deep.
    """
    from rclpy.qos import (DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy)

    reliable = bool(offers) and all(p.reliability == ReliabilityPolicy.RELIABLE for p in offers)
    latched = bool(offers) and all(p.durability == DurabilityPolicy.TRANSIENT_LOCAL
                                   for p in offers)
    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST, depth=QUEUE_DEPTH,
        reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE)


def _make_executor(kind: str, context: Any) -> Any:
    from rclpy.executors import SingleThreadedExecutor

    if kind == 'events':
        try:
            from rclpy.experimental import EventsExecutor  # type: ignore[attr-defined]
        except ImportError:     # rclpy before the EventsExecutor (Jazzy and older)
            pass  # fall back to the SingleThreadedExecutor below
        else:
            return EventsExecutor(context=context)
    return SingleThreadedExecutor(context=context)


def _message_class(type_name: str) -> Any:
    package, namespace, name = _split_type(type_name)
    try:
        return getattr(importlib.import_module(f'{package}.{namespace}'), name)
    except (ImportError, AttributeError):
        msg = (f'Expected the Python message package of {type_name} to be installed, got no '
               f'module {package}.{namespace} with {name}')
        raise RecorderError(msg) from None


# -- the recorder ----------------------------------------------------------------


@dataclass
class TopicStats:
    """What happened to one requested topic."""

    name: str
    type: str = ''
    received: int = 0
    written: int = 0
    #: Received but dropped, the queue for the disk full (``max_queue_bytes``).
    dropped: int = 0
    error: str = ''


@dataclass
class _Topic:
    stats: TopicStats
    subscription: Any = None
    bag_topic: Any = None
    failed: bool = False
    #: ``stats.received`` at the previous progress line.
    reported: int = 0


class BagRecorder:
    """Subscribe to topics as they appear and write every message to a rosbag2 bag.

    Parameters
    ----------
    output : path-like
        The bag directory to create; it must not exist.
    topics : sequence of str
        Topic names; relative names are resolved in the recorder's namespace.
    storage : {'mcap', 'sqlite3'}
        Storage plugin.
    version : {8, 9}
        Bag format version.
    args : list of str, optional
        Command-line arguments for ``rclpy.init`` (``--ros-args ...``).
    executor : {'events', 'single'}
        ``'events'``: rclpy's ``EventsExecutor`` (about half the CPU of the
        other at 3 kHz of messages), or ``'single'``: ``SingleThreadedExecutor``,
        which is also used where this rclpy has no ``EventsExecutor``.
    progress : float
        Seconds between progress lines while recording; 0 for none.
    max_queue_bytes : int
        Most bytes of received messages waiting for the disk; a message that
        would pass it is dropped and counted (:attr:`TopicStats.dropped`).
    namespaces : sequence of str, optional
        Namespaces whose every topic is recorded too, as it appears (relative
        names resolved like ``topics``). Default: :data:`DEFAULT_NAMESPACES`
        with the default topics, none with topics of your choosing.

    Attributes
    ----------
    error : str
        Why the recording stopped early or the bag could not be closed
        normally (a write error); empty if all went well.
    bag : BagInfo or None
        What the closed bag holds (None before :meth:`close`, or if it could not be closed).

    Raises
    ------
    RecorderError
        If ``output`` exists or an option is out of range.
    """

    def __init__(self, output: str | os.PathLike[str], topics: Sequence[str] = DEFAULT_TOPICS,
                 *, storage: str = DEFAULT_STORAGE, version: int = DEFAULT_BAG_VERSION,
                 args: list[str] | None = None, executor: str = DEFAULT_EXECUTOR,
                 progress: float = DEFAULT_PROGRESS_S, max_queue_bytes: int = MAX_QUEUE_BYTES,
                 namespaces: Sequence[str] | None = None) -> None:
        self.output = Path(output)
        try:
            bag.check_new_bag(self.output)      # before ROS starts
            bag.check_options(storage, version)
        except bag.BagError as error:
            raise RecorderError(str(error)) from None
        if not topics:
            msg = 'Expected at least one topic to record, got none'
            raise RecorderError(msg)
        if executor not in EXECUTORS:
            msg = f'Expected executor to be one of {", ".join(EXECUTORS)}, got {executor!r}'
            raise RecorderError(msg)
        if not (math.isfinite(progress) and progress >= 0):
            msg = f'Expected a progress interval of 0 s or more, got {progress!r}'
            raise RecorderError(msg)
        if isinstance(max_queue_bytes, bool) or not (
                isinstance(max_queue_bytes, int) and max_queue_bytes > 0):
            msg = (f'Expected a positive number of bytes for max_queue_bytes, got '
                   f'{max_queue_bytes!r}')
            raise RecorderError(msg)
        self.max_queue_bytes = max_queue_bytes
        self.storage = storage
        self.version = version
        self.executor = executor
        self.progress = progress
        self._stop = threading.Event()
        self._rclpy_args = args
        self._requested = list(dict.fromkeys(topics))
        if namespaces is None:
            namespaces = DEFAULT_NAMESPACES if tuple(topics) == DEFAULT_TOPICS else ()
        self._namespaces = tuple(namespaces)
        #: The namespaces resolved, each ending in '/'.
        self._prefixes: tuple[str, ...] = ()
        self._topics: dict[str, _Topic] = {}
        self._node: Any = None
        self._context: Any = None
        self._executor: Any = None
        self._writer: Any = None
        #: time.monotonic() of the first subscription, None before.
        self.recording_since: float | None = None
        #: Seconds from the first subscription to close() (0 if nothing was subscribed).
        self.recorded_seconds = 0.0
        self.error = ''
        self.bag: Any = None
        self._next_wait_report = 0.0
        self._next_progress = math.inf
        self._last_progress = 0.0
        #: Messages dropped (the queue full) at the last report of drops, and when it was.
        self._dropped_reported = 0
        self._next_drop_report = 0.0
        #: The last flush logged; when a slow one may be warned of again, and the slowest
        #: flush longer than the interval since the last warning (0 if none).
        self._flush_reported = 0
        self._next_slow_report = 0.0
        self._slowest = 0.0

    # -- life cycle ---------------------------------------------------------------

    def open(self) -> None:
        """Start ROS, resolve the topic names and create the bag (empty until topics appear)."""
        import rclpy
        from rclpy.signals import SignalHandlerOptions

        from ..bag import BagError, BagWriter, QueuedWriter

        self._context = rclpy.Context()
        # The recorder handles SIGINT and SIGTERM itself (a flag, see run()), so that a
        # signal can never cut a write in half.
        rclpy.init(args=self._rclpy_args, context=self._context,
                   signal_handler_options=SignalHandlerOptions.NO)
        try:
            self._node = rclpy.create_node(NODE_NAME, context=self._context)
            for name in self._requested:
                try:
                    resolved = self._node.resolve_topic_name(name)
                except Exception as error:    # noqa: BLE001 - rclpy raises several kinds
                    msg = f'Expected a valid topic name, got {name!r}: {error}'
                    raise RecorderError(msg) from None
                self._topics.setdefault(resolved, _Topic(TopicStats(resolved)))
            self._prefixes = tuple(f'{self._node.resolve_topic_name(ns).rstrip("/")}/'
                                   for ns in self._namespaces)
            self._executor = _make_executor(self.executor, self._context)
            self._executor.add_node(self._node)
            writer = BagWriter(self.output, storage=self.storage, version=self.version)
            try:
                writer.open()
            except BagError as error:
                raise RecorderError(str(error)) from None
            # Written by a thread of its own: a flush's fsync, seconds on a loaded disk, never
            # holds up the executor while the middleware's queues fill and drop messages.
            self._writer = QueuedWriter(writer, self.max_queue_bytes)
            self._node.create_timer(POLL_INTERVAL_S, self._housekeeping)
        except BaseException:
            if self._writer is not None:
                writer, self._writer = self._writer, None
                with contextlib.suppress(BagError):
                    writer.close()      # an empty bag, but a whole one
            self._shutdown_ros()
            raise
        self._node.get_logger().info(
            f'recording to {self.output} ({self.storage}, bag version {self.version}); '
            f'topics: {", ".join(self._topics)}')
        self._discover()
        # Discovering a publisher that is already there takes a moment: wait before saying so.
        self._next_wait_report = time.monotonic() + FIRST_WAIT_REPORT_S

    def request_stop(self) -> None:
        """Ask :meth:`run` to return (safe from a signal handler or another thread)."""
        self._stop.set()

    def run(self, duration: float | None = None) -> None:
        """Record until :meth:`request_stop`, or ``duration`` s after the first subscription.

        The duration counts from the moment the first topic is subscribed, so
        that discovery (a few seconds for a node that is already running) and
        waiting for topics do not shorten the recording. A write error ends the
        recording too (see :attr:`error`).
        """
        assert self._executor is not None, 'call open() first'
        spin_once = self._executor.spin_once
        while not self._stop.is_set():
            step = SPIN_STEP_S
            if duration is not None and self.recording_since is not None:
                remaining = self.recording_since + duration - time.monotonic()
                if remaining <= 0:
                    break
                step = min(step, remaining)
            spin_once(timeout_sec=step)
        self._drain()

    def _drain(self) -> None:
        """Take what the subscriptions hold at the stop (not after a write error)."""
        if self._writer is None or self._writer.failure is not None:
            return
        stop_ns = time.time_ns()    # the clock of DDS source timestamps
        deadline = time.monotonic() + DRAIN_S
        for topic in self._topics.values():
            subscription = topic.subscription
            if subscription is None:
                continue
            # Taken from the queue itself, with each message's info (the executor's
            # callbacks get none: rclpy's EventsExecutor cannot give a raw one its info).
            while time.monotonic() < deadline and self._writer.failure is None:
                with subscription.handle:
                    taken = subscription.handle.take_message(subscription.msg_type, True)
                if taken is None or taken[1]['source_timestamp'] > stop_ns:
                    break
                subscription.callback(taken[0])

    def close(self) -> list[TopicStats]:
        """Stop receiving, close the bag (metadata.yaml included) and shut ROS down.

        After a write error the bag is closed with what its storage holds, and
        ``written`` counts exactly that; :attr:`error` says what happened.

        Returns
        -------
        list of TopicStats
            Per requested topic: type, messages received and written.
        """
        from ..bag import BagError

        if self.recording_since is not None:
            self.recorded_seconds = time.monotonic() - self.recording_since
        try:
            if self._node is not None:
                for topic in self._topics.values():
                    if topic.subscription is not None:
                        self._node.destroy_subscription(topic.subscription)
                        topic.subscription = None
            if self._writer is not None:
                writer, self._writer = self._writer, None
                for topic in self._topics.values():
                    topic.stats.dropped = writer.dropped.get(topic.stats.name, 0)
                try:
                    self.bag = writer.close()
                except BagError as error:
                    self.error = str(error)
                else:
                    for topic in self._topics.values():
                        if topic.bag_topic is not None:
                            topic.stats.written = self.bag.count(topic.stats.name)
                    if writer.failure is not None:
                        received = sum(t.stats.received for t in self._topics.values())
                        self.error = (f'{writer.failure}; the recording stopped and the bag '
                                      f'was closed with the {self.bag.message_count} messages '
                                      f'its storage holds ({received} received)')
        finally:
            self._shutdown_ros()
        return self.stats

    @property
    def stats(self) -> list[TopicStats]:
        """Per requested topic: type, messages received and written so far."""
        return [topic.stats for topic in self._topics.values()]

    def _shutdown_ros(self) -> None:
        import rclpy

        if self._executor is not None:
            self._executor.shutdown(timeout_sec=1.0)
            self._executor = None
        if self._node is not None:
            self._node.destroy_node()
            self._node = None
        if self._context is not None:
            rclpy.try_shutdown(context=self._context)
            self._context = None

    # -- housekeeping: failures, discovery, reports -----------------------------------

    def _housekeeping(self) -> None:
        """Stop on a failed write, poll the graph, and log drops, waiting or progress lines."""
        from ..bag import BagError

        if self._writer is None:
            return
        try:
            self._writer.check()
        except BagError:
            self.request_stop()
            return
        self._discover()
        now = time.monotonic()
        self._report_flush(now)
        if now >= self._next_drop_report:
            self._report_drops(now)
        if self.recording_since is None:
            if now >= self._next_wait_report:
                self._report_waiting(now)
        elif now >= self._next_progress:
            self._report_progress(now)

    def _pending(self) -> list[str]:
        return [name for name, t in self._topics.items() if t.subscription is None
                and not t.failed]

    def _report_waiting(self, now: float) -> None:
        """Name the topics that have no publisher yet (while nothing is recorded)."""
        if self.recording_since is not None:
            return
        self._next_wait_report = now + WAIT_REPORT_INTERVAL_S
        pending = self._pending()
        if pending:
            self._node.get_logger().info(
                f'waiting for publishers on {", ".join(pending)} (is the node running, in this '
                f'ROS_DOMAIN_ID and namespace?)')

    def _report_flush(self, now: float) -> None:
        """Log each new flush (debug); warn of one slower than the interval (a slow disk).

        The warning is repeated at most every WARNING_INTERVAL_S, with the
        slowest flush since the last one.
        """
        flush = self._writer.last_flush
        if flush is None or flush.number == self._flush_reported:
            return
        self._flush_reported = flush.number
        logger = self._node.get_logger()
        logger.debug(f'flush {flush.number}: {flush.messages} messages in {flush.seconds:.3f} s '
                     f'({flush.written} in the file), the newest received at {flush.newest_ns} ns')
        interval = self._writer.writer.flush_interval
        if flush.seconds > interval:
            self._slowest = max(self._slowest, flush.seconds)
        if not self._slowest or now < self._next_slow_report:
            return
        slowest, self._slowest = self._slowest, 0.0
        self._next_slow_report = now + WARNING_INTERVAL_S
        logger.warning(
            f'the disk is slow: a flush of the bag took {slowest:.2f} s, more than the '
            f'{interval:g} s interval; messages now reach the file up to '
            f'{interval + 2 * slowest:.1f} s after they are received (a crash loses them)')

    def _report_drops(self, now: float) -> None:
        """Warn, at most every WARNING_INTERVAL_S, while messages are being dropped."""
        dropped = self._writer.dropped
        total = sum(dropped.values())
        if total == self._dropped_reported:
            return
        self._dropped_reported = total
        self._next_drop_report = now + WARNING_INTERVAL_S
        self._node.get_logger().warning(
            f'the disk is behind by more than --max-queue-bytes ({self.max_queue_bytes} bytes '
            f'of messages): {total} messages dropped so far: {_per_topic(dropped)}')

    def _report_progress(self, now: float) -> None:
        """Log the messages received so far, per topic and per second, in one line."""
        elapsed = max(now - self._last_progress, 1e-9)
        parts = []
        total = rate = 0.0
        for name, topic in self._topics.items():
            if topic.bag_topic is None:
                continue
            received = topic.stats.received
            per_second = (received - topic.reported) / elapsed
            topic.reported = received
            total += received
            rate += per_second
            parts.append(f'{name} {received} ({per_second:.0f}/s)')
        line = (f'recorded {now - self.recording_since:.0f} s: {total:.0f} messages '
                f'({rate:.0f}/s): {", ".join(parts)}')
        # A default topic the node publishes only when asked (markers) is not waited for aloud.
        pending = [name for name in self._pending()
                   if name.rsplit('/', 1)[-1] not in OPTIONAL_TOPICS]
        if pending:
            line += f'; waiting for {", ".join(pending)}'
        self._node.get_logger().info(line)
        self._last_progress = now
        self._next_progress = now + self.progress

    # -- topics -------------------------------------------------------------------

    def _discover(self) -> None:
        """Subscribe to every requested topic that has publishers now (polled).

        A topic that appears in one of the recorded namespaces is requested too.
        """
        from ..bag import BagError

        types: dict[str, list[str]] | None = None
        if self._prefixes and self._writer is not None:
            types = dict(self._node.get_topic_names_and_types())
            for name in types:
                if name.startswith(self._prefixes) and name not in self._topics:
                    self._topics[name] = _Topic(TopicStats(name))
        pending = [t for t in self._topics.values() if t.subscription is None and not t.failed]
        if not pending or self._writer is None:
            return
        if types is None:
            types = dict(self._node.get_topic_names_and_types())
        for topic in pending:
            name = topic.stats.name
            offers = self._node.get_publishers_info_by_topic(name)
            if name not in types or not offers:
                continue
            try:
                self._subscribe(topic, types[name], offers)
            except RecorderError as error:
                topic.failed = True
                topic.stats.error = str(error)
                self._node.get_logger().error(f'not recording {name}: {error}')
            except BagError:
                self.request_stop()
                return

    def _subscribe(self, topic: _Topic, type_names: list[str], offers: list[Any]) -> None:
        name = topic.stats.name
        if len(type_names) != 1:
            msg = f'Expected one type on {name}, got {", ".join(type_names)}'
            raise RecorderError(msg)
        type_name = type_names[0]
        msg_class = _message_class(type_name)
        encoding, text = message_definition(type_name)
        hashes = {str(info.topic_type_hash) for info in offers
                  if info.topic_type == type_name and str(info.topic_type_hash)}
        # Every publisher of a type announces the same hash; take it rather than recompute.
        type_hash = min(hashes) if hashes else ''
        profiles = [info.qos_profile for info in offers if info.topic_type == type_name]
        if not type_hash:
            msg = f'Expected the publishers of {name} to announce a type hash, got none'
            raise RecorderError(msg)
        topic.bag_topic = self._writer.add_topic(
            name, type_name, definition=text, encoding=encoding, type_hash=type_hash,
            qos=[_qos_from_profile(p) for p in profiles])
        topic.stats.type = type_name
        topic.subscription = self._node.create_subscription(
            msg_class, name, self._callback(topic), _request_qos(profiles), raw=True)
        if self.recording_since is None:
            self.recording_since = self._last_progress = time.monotonic()
            if self.progress:
                self._next_progress = self.recording_since + self.progress
        self._node.get_logger().info(f'subscribed to {name} ({type_name})')

    def _callback(self, topic: _Topic) -> Callable[[bytes], None]:
        from ..bag import BagError

        write = self._writer.write
        bag_topic = topic.bag_topic
        stats = topic.stats
        now = self._node.get_clock().now
        stop = self.request_stop

        def on_message(data: bytes) -> None:
            # Stamped with the node clock on receipt, as rosbag2 does (sim time if enabled).
            stats.received += 1
            try:
                write(bag_topic, now().nanoseconds, data)
            except BagError:
                stop()      # the writer keeps the reason; close() reports it

        return on_message


def _per_topic(counts: dict[str, int]) -> str:
    return ', '.join(f'{name} {n}' for name, n in counts.items() if n)


# -- command line ----------------------------------------------------------------


def record(output: str | os.PathLike[str], topics: Sequence[str] = DEFAULT_TOPICS, *,
           duration: float | None = None, storage: str = DEFAULT_STORAGE,
           version: int = DEFAULT_BAG_VERSION, args: list[str] | None = None,
           executor: str = DEFAULT_EXECUTOR, progress: float = DEFAULT_PROGRESS_S,
           max_queue_bytes: int = MAX_QUEUE_BYTES) -> BagRecorder:
    """Record ``topics`` to the new bag ``output`` until Ctrl-C, SIGTERM or ``duration`` s.

    ``duration`` counts from the first subscription (see :meth:`BagRecorder.run`).

    SIGINT and SIGTERM are caught while recording (in the main thread) and
    end the recording cleanly; the bag is always closed.

    Returns
    -------
    BagRecorder
        Closed; its ``stats`` (per topic: type, messages received and written)
        and ``recorded_seconds`` tell what was recorded, its ``error`` what
        went wrong (a write error), if anything.
    """
    if duration is not None and not (math.isfinite(duration) and duration > 0):
        msg = f'Expected a positive duration in seconds, got {duration!r}'
        raise RecorderError(msg)
    recorder = BagRecorder(output, topics, storage=storage, version=version, args=args,
                           executor=executor, progress=progress,
                           max_queue_bytes=max_queue_bytes)
    previous: dict[signal.Signals, Any] = {}
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            previous[sig] = signal.signal(sig, lambda *_: recorder.request_stop())
    try:
        recorder.open()
        try:
            recorder.run(duration)
        finally:
            recorder.close()
    finally:
        # Restored only once the bag is closed: a second Ctrl-C cannot interrupt the close.
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    return recorder


def _print_summary(recorder: BagRecorder) -> None:
    stats = recorder.stats
    width = max([len(s.name) for s in stats] + [5])
    type_width = max([len(s.type) for s in stats] + [4])
    print(f'recorded {recorder.recorded_seconds:.1f} s to {recorder.output} '
          f'({recorder.storage}, bag version {recorder.version})')
    print(f'{"topic":<{width}}  {"type":<{type_width}}  {"received":>9}  {"written":>9}')
    for s in stats:
        if s.type:
            # Unknown if the bag could not be closed: reindex will count them.
            written = s.written if recorder.bag is not None else '?'
            print(f'{s.name:<{width}}  {s.type:<{type_width}}  {s.received:>9}  {written:>9}')
        else:
            optional = OPTIONAL_TOPICS.get(s.name.rsplit('/', 1)[-1])
            reason = s.error or (f'never appeared: {optional}' if optional else 'never appeared')
            print(f'{s.name:<{width}}  {"-":<{type_width}}  {"-":>9}  {"-":>9}  ({reason})')


def _handle(args: argparse.Namespace) -> int:
    """Handle ``record``: record, print a per-topic summary; return the exit status.

    0 after a normal stop, 1 after a write error (the bag holds what was
    written before it; one ``error:`` line says what happened), 2 if the
    recording could not start, 3 after a normal stop that dropped messages
    because the disk fell ``--max-queue-bytes`` behind (one ``warning:``
    line names them per topic; the bag is whole and holds the rest).
    """
    output = Path(args.output)
    rclpy_args = ['record', '--ros-args', *args.ros_args] if args.ros_args else ['record']
    try:
        recorder = record(output, args.topics, duration=args.duration, storage=args.storage,
                          version=args.bag_version, args=rclpy_args, executor=args.executor,
                          progress=args.progress, max_queue_bytes=args.max_queue_bytes)
    except RecorderError as error:
        print(f'error: {error}', file=sys.stderr)
        return 2
    _print_summary(recorder)
    dropped = {s.name: s.dropped for s in recorder.stats}
    if any(dropped.values()):
        received = sum(s.received for s in recorder.stats)
        print(f'warning: dropped {sum(dropped.values())} of the {received} messages received, '
              f'the disk behind by more than --max-queue-bytes ({recorder.max_queue_bytes} '
              f'bytes): {_per_topic(dropped)}', file=sys.stderr)
    if recorder.error:
        print(f'error: {recorder.error}', file=sys.stderr)
        return 1
    return DROPPED_STATUS if any(dropped.values()) else 0


RECORD_HELP = """\
Record the node's topics (by default everything it publishes: the state,
/tf, /tf_static, diagnostics, markers when on, robot_description, the
scene's text on `scene`, every imu/NAME of the scene's IMUs and, with forces,
every reactions/JOINT and shaking, so the bag replays whole) to a new
rosbag2 directory,
readable by `ros2 bag info`, `ros2 bag play` and Foxglove: metadata.yaml plus
one .mcap or .db3 file. Messages are stored as received (serialized CDR),
stamped with the receive time. Topics not published yet are waited for and
recorded from the moment they appear (discovering a node that is already
running takes a few seconds); while none has a publisher, a log line names
them every 5 s. While recording, a log line every --progress seconds gives
the messages per topic and per second. Ctrl-C, SIGTERM or the end of
--duration (counted from the first subscription) end the recording and close
the bag; a per-topic summary (received and written counts) is printed. An
existing output directory is refused.

Crash safety: messages reach the file every 0.5 s (an MCAP chunk closed and
synced, an sqlite3 transaction committed); a flush that takes longer (a slow
disk) is warned of, with what a crash would now lose. If the recorder is
killed, `python -m mech_kinematics reindex DIR` makes the bag readable again
with everything but the last half second (and the flush under way). Every
flush is logged at debug level (--ros-args --log-level
mech_kinematics_recorder:=debug). A write error (a full disk) ends
the recording with one `error:` line and exit status 1; the bag is closed
with what was written and its metadata counts exactly that.

A slow disk delays the bag, not the recording: received messages wait in
memory for the disk, up to --max-queue-bytes. A message that would pass it
is dropped and counted: a log line says so while recording, one `warning:`
line at the end names the dropped messages per topic, and the exit status
is 3 (the bag is whole and holds every other message).
"""


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register the ``record`` subcommand on ``subparsers``; return its parser."""
    parser: argparse.ArgumentParser = subparsers.add_parser(
        'record', help="record the node's topics to a rosbag2 bag (mcap or sqlite3)",
        description=RECORD_HELP, formatter_class=argparse.RawDescriptionHelpFormatter)
    _add_arguments(parser)
    parser.set_defaults(handler=_handle)
    return parser


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('-o', '--output', required=True, metavar='DIR',
                        help='bag directory to create (must not exist)')
    parser.add_argument('--topics', nargs='+', default=list(DEFAULT_TOPICS), metavar='T',
                        help="topics to record; relative names take the recorder's namespace "
                             f'(default: {" ".join(DEFAULT_TOPICS)})')
    parser.add_argument('--duration', type=positive_seconds, metavar='S',
                        help='stop S seconds after the first topic is subscribed '
                             '(default: at Ctrl-C or SIGTERM)')
    parser.add_argument('--storage', choices=STORAGES, default=DEFAULT_STORAGE,
                        help='storage plugin (default: %(default)s)')
    parser.add_argument('--bag-version', type=int, choices=BAG_VERSIONS,
                        default=DEFAULT_BAG_VERSION,
                        help='rosbag2 format version; 9 is not readable by Humble '
                             '(default: %(default)s)')
    parser.add_argument('--progress', type=seconds_or_zero, default=DEFAULT_PROGRESS_S,
                        metavar='S', help='log the messages per topic and per second every S '
                                          'seconds while recording; 0: never '
                                          '(default: %(default)s)')
    parser.add_argument('--max-queue-bytes', type=positive_int, default=MAX_QUEUE_BYTES,
                        metavar='N', help='most serialized bytes of received messages waiting '
                                          'for a slow disk; beyond, messages are dropped, '
                                          'counted and the exit status is 3 (default: '
                                          "%(default)s, 100 MiB as ros2 bag record's "
                                          '--max-cache-size)')
    parser.add_argument('--executor', choices=EXECUTORS, default=DEFAULT_EXECUTOR,
                        help='rclpy executor: events (EventsExecutor, the lighter) or single '
                             '(SingleThreadedExecutor, used anyway where rclpy has no '
                             'EventsExecutor) (default: %(default)s)')
    parser.add_argument('--ros-args', nargs=argparse.REMAINDER, default=[], dest='ros_args',
                        metavar='...', help='ROS arguments for the recorder node, e.g. '
                                            '--ros-args -r __ns:=/robot1')


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``record``; return the exit status."""
    return run_tool(add_parser, argv)


if __name__ == '__main__':
    sys.exit(main())
