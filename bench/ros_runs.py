# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""What the node benchmarks share (a module of the bench scripts, not a script).

- :func:`ros_env`: the environment of the processes a run starts (a domain
  of the run's own, discovery on this machine, the package importable);
- :func:`cpu_seconds`: user + system time of a process, from /proc;
- :func:`on_grid`: a deadline loop on an exact grid of instants, the floors'
  and the drivers' (the node's own schedule, ``mech_kinematics.ros.schedule``);
- :func:`publish_on_grid`: the *floor* of ``node_bench.py`` and
  ``node_forces_bench.py``, a bare rclpy process publishing pre-serialized
  messages with each instant's stamp patched in;
- :func:`relay_floor`, :func:`drive` and :func:`relay_run`: the relay floor
  of ``topic_bench.py`` and ``urdf_node_bench.py`` (pre-serialized messages
  with each input's stamp), the driver that sends the inputs and notes the
  answers, and one run of a relay with its driver.

Every script imports this module from its own folder (``sys.path[0]``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
import json
import os
from pathlib import Path
import random
import signal
import struct
import subprocess
import sys
import threading
import time
from typing import Any

NS = 1_000_000_000
REPO = Path(__file__).resolve().parents[1]
#: The topic the relays take their input from (the node's in ``drive:=topic``).
INPUT = 'input_joint_states'
#: The stamp of a serialized message with a Header first: after the 4-byte CDR header.
_STAMP = struct.Struct('<iI')


def ros_env() -> dict[str, str]:
    """Return the environment for a run's processes: its own domain, this machine, the package."""
    env = dict(os.environ)
    env.setdefault('ROS_DOMAIN_ID', str(random.SystemRandom().randint(101, 200)))
    env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    env['PYTHONPATH'] = os.pathsep.join(filter(None, [str(REPO), env.get('PYTHONPATH')]))
    return env


def cpu_seconds(pid: int) -> float:
    """Return user + system CPU seconds of process ``pid`` (all its threads)."""
    fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def qos(depth: int = 1000) -> Any:
    """Return a reliable QoS profile of ``depth``."""
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    return QoSProfile(depth=depth, reliability=ReliabilityPolicy.RELIABLE)


def quantile(values: Sequence[float], q: float) -> float:
    """Return the ``q`` quantile of ``values`` (the nearest rank below)."""
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


def on_grid(rate: float, going: Callable[[], bool], send: Callable[[int], None], *,
            catch_up: bool) -> None:
    """Call ``send(t)`` for the instants ``t`` (ns) of an exact ``rate`` Hz grid while ``going()``.

    ``catch_up``: after a stall, send every owed instant of the last 0.1 s
    (the node's default); otherwise the latest only.
    """
    from mech_kinematics.ros.schedule import period_ns_from_rate, TickGrid

    grid = TickGrid.aligned(time.time_ns(), period_ns_from_rate(rate))
    sys.setswitchinterval(0.0005)
    while going():
        now = time.time_ns()
        if now < grid.next_ns:
            time.sleep(min(grid.next_ns - now, 50_000_000) / NS)
            continue
        for t in grid.take(now, NS // 10, catch_up=catch_up).instants:
            send(t)


class _Stopped(Exception):
    """The context ended under a publish: the run is over."""


def publish_on_grid(namespace: str, rate: float, topics: Sequence[tuple[Any, str]],
                    payloads: Sequence[bytes]) -> None:
    """Publish ``payloads``, one per ``(type, topic)``, on a ``rate`` Hz grid until stopped.

    A deadline thread publishes; the main thread spins until SIGINT or SIGTERM.
    """
    import rclpy
    from rclpy.executors import ExternalShutdownException

    buffers = [bytearray(p) for p in payloads]
    rclpy.init()
    node = rclpy.create_node('floor_publisher', namespace=namespace)
    publishers = [node.create_publisher(t, topic, qos()) for t, topic in topics]
    stop = threading.Event()

    def send(t: int) -> None:
        sec, nanosec = divmod(t, NS)
        for publisher, payload in zip(publishers, buffers, strict=True):
            _STAMP.pack_into(payload, 4, sec, nanosec)
            try:
                publisher.publish(bytes(payload))
            except Exception:       # noqa: BLE001 - the context ends under a publish
                if stop.is_set() or not rclpy.ok():
                    raise _Stopped from None
                raise

    def loop() -> None:
        try:
            on_grid(rate, lambda: not stop.is_set(), send, catch_up=True)
        except _Stopped:
            pass

    thread = threading.Thread(target=loop, daemon=True)
    thread.start()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    try:
        while not stop.is_set():
            rclpy.spin_once(node, timeout_sec=0.1)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    stop.set()
    thread.join(timeout=1.0)
    node.destroy_node()
    rclpy.try_shutdown()


def relay_floor(namespace: str, topics: Sequence[tuple[Any, str]],
                payloads: Sequence[bytes]) -> None:
    """Answer each raw message on :data:`INPUT` with ``payloads``, its stamp patched in."""
    import rclpy
    from rclpy.executors import ExternalShutdownException
    from sensor_msgs.msg import JointState

    from mech_kinematics.ros.topic_input import INPUT_DEPTH

    buffers = [bytearray(p) for p in payloads]
    rclpy.init()
    node = rclpy.create_node('floor_relay', namespace=namespace)
    publishers = [node.create_publisher(t, topic, qos()) for t, topic in topics]

    def relay(data: bytes) -> None:
        stamp = data[4:12]
        for publisher, payload in zip(publishers, buffers, strict=True):
            payload[4:12] = stamp
            publisher.publish(bytes(payload))

    # The node's input depth: behind by a burst, neither loses one.
    node.create_subscription(JointState, INPUT, relay, qos(INPUT_DEPTH), raw=True)
    signal.signal(signal.SIGTERM, lambda *_: rclpy.try_shutdown())
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


def relay_run(relay: list[str], driver: list[str], out: Path, warmup: float, seconds: float,
              env: dict[str, str]) -> tuple[float, float, float]:
    """Run the ``relay`` command with the ``driver`` command; return its CPU over a stretch.

    The driver writes ``OUT.started`` once its publisher has matched, then
    sends for ``warmup + seconds`` and writes ``out``. Returns the relay's
    CPU seconds, and the monotonic start and end (s) of the measured stretch.
    """
    process = subprocess.Popen(relay, env=env)
    time.sleep(2.0)     # the relay is up before the driver starts sending
    sender = subprocess.Popen(driver, env=env)
    try:
        started = Path(f'{out}.started')
        while not started.exists() and sender.poll() is None:
            time.sleep(0.05)
        time.sleep(warmup)
        cpu0, wall0 = cpu_seconds(process.pid), time.monotonic()
        time.sleep(seconds - 0.5)
        cpu1, wall1 = cpu_seconds(process.pid), time.monotonic()
        sender.wait(timeout=warmup + seconds + 60)
    finally:
        process.send_signal(signal.SIGINT)
        process.wait(timeout=10)
    return cpu1 - cpu0, wall0, wall1


def drive(namespace: str, node_name: str, rate: float, seconds: float, out: str,
          render: Callable[[int], bytes], answers: Sequence[tuple[Any, str]]) -> None:
    """Publish ``render(t)`` on the input topic at ``rate`` Hz for ``seconds``; note the answers.

    The relay's driver: once the relay's subscription has matched, writes
    ``OUT.started`` (its CPU is measured from then on), sends from a
    deadline loop, noting each input's send time, and receives the raw
    ``answers`` (``(type, topic)``), noting each one's stamp and arrival
    time, on one monotonic clock. Writes ``{'sent': [(stamp, ns)],
    'arrivals': {topic: [(stamp, ns)]}}`` as JSON to ``out``.
    """
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from sensor_msgs.msg import JointState

    from mech_kinematics.ros.cdr import stamp_from_cdr

    rclpy.init()
    node = rclpy.create_node(node_name, namespace=namespace)
    publisher = node.create_publisher(JointState, INPUT, qos(100))
    arrivals: dict[str, list[tuple[int, int]]] = {topic: [] for _, topic in answers}
    for msg_type, topic in answers:
        sink = arrivals[topic].append
        node.create_subscription(
            msg_type, topic,
            lambda data, sink=sink: sink((stamp_from_cdr(data), time.monotonic_ns())),
            qos(), raw=True)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    deadline = time.monotonic() + 30.0
    while publisher.get_subscription_count() == 0 and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(1.0)     # the relay's subscription has matched this publisher too
    Path(f'{out}.started').touch()
    sent: list[tuple[int, int]] = []

    def send(t: int) -> None:
        data = render(t)
        sent.append((t, time.monotonic_ns()))
        publisher.publish(data)

    end = time.monotonic() + seconds
    on_grid(rate, lambda: time.monotonic() < end, send, catch_up=False)
    time.sleep(1.0)     # the last answers arrive
    executor.shutdown(timeout_sec=1.0)
    node.destroy_node()
    rclpy.try_shutdown()
    Path(out).write_text(json.dumps({'sent': sent, 'arrivals': arrivals}))
