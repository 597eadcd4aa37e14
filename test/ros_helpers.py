# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Helpers shared by the tests that run the node over real DDS.

Kept apart from ``helpers.py`` (pure helpers), because importing this module
imports rclpy and gives the test session a ROS domain of its own (a random
``ROS_DOMAIN_ID``, discovery on localhost only) before any ``rclpy.init``, and a
namespace of its own (``SESSION``) for the nodes it starts. Never import one
test module from another: shared pieces live here.
"""

import contextlib
import math
import os
from pathlib import Path
import random
import signal
import subprocess
import sys
import threading
import time

from lifecycle_msgs.msg import Transition
from lifecycle_msgs.srv import ChangeState, GetState
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile, ReliabilityPolicy

REPO = Path(__file__).resolve().parents[1]

NS = 1_000_000_000
STARTUP_S = 20.0       # deadline for a node to come up and be discovered
RELIABLE = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)

# A domain of this test session's own (set before rclpy.init, inherited by the nodes);
# with pytest-xdist (`make test` runs two workers) each worker's differs from the others'.
_WORKER = os.environ.get('PYTEST_XDIST_WORKER', 'gw0')
_WORKERS = int(os.environ.get('PYTEST_XDIST_WORKER_COUNT', '1'))
os.environ['ROS_DOMAIN_ID'] = str(
    1 + random.SystemRandom().randrange(100 // _WORKERS) * _WORKERS
    + int(_WORKER[2:] if _WORKER[2:].isdigit() else 0) % _WORKERS)
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
# Only 100 domains: every node here also runs in a namespace of this session's own, so
# that another session that drew the same domain cannot mix its messages into ours.
SESSION = f'/kt_{os.getpid()}_{random.SystemRandom().randrange(16 ** 6):06x}'


def stamp_ns(msg) -> int:
    """Return a message's header stamp in integer nanoseconds."""
    return msg.header.stamp.sec * NS + msg.header.stamp.nanosec


def wrap(angle: float) -> float:
    """Return ``angle`` wrapped to [-pi, pi]."""
    return math.remainder(angle, 2 * math.pi)


def wait_for(predicate, timeout: float, what: str):
    """Poll ``predicate`` until it is true or ``timeout`` s pass (then fail naming ``what``)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.01)
    pytest.fail(f'timed out after {timeout} s waiting for {what}')


def send_until(send, predicate, timeout: float, what: str, every: float = 0.5):
    """Call ``send``, then again every ``every`` s, until ``predicate`` is true; return it.

    A message sent before the other side has matched this one is lost (each side
    discovers the other on its own; ``get_subscription_count`` says only that
    this side has): resend until answered. Fails naming ``what`` after ``timeout`` s.
    """
    deadline = time.monotonic() + timeout
    while True:
        send()
        again = min(deadline, time.monotonic() + every)
        while time.monotonic() < again:
            value = predicate()
            if value:
                return value
            time.sleep(0.01)
        if time.monotonic() >= deadline:
            pytest.fail(f'timed out after {timeout} s waiting for {what}')


def exited(proc: 'NodeProcess', timeout: float = STARTUP_S) -> tuple[int, str]:
    """Return a node's exit status and output, waited for up to ``timeout`` s (killed after).

    Processes started together share the machine while they start: give the first
    waited for ``STARTUP_S`` times their number.
    """
    try:
        status = proc.proc.wait(timeout=timeout)
    finally:
        if proc.proc.poll() is None:
            proc.proc.kill()
    return status, proc.output()


def cannot_start(output: str) -> list[str]:
    """Return the lines of a node's output that say it cannot start."""
    return [line for line in output.splitlines() if 'cannot start' in line]


def wait_for_parameters(params, timeout: float = STARTUP_S) -> None:
    """Wait until a node answers ``params`` (an AsyncParameterClient) on its services.

    ``wait_for_services`` says only that this side sees the node's services; a
    request sent before the node has matched this client is lost. A node
    publishes from its start, before it may have discovered this process.
    """
    assert params.wait_for_services(timeout_sec=timeout)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        future = params.get_parameters(['rate_hz'])
        retry = min(deadline, time.monotonic() + 0.5)
        while not future.done() and time.monotonic() < retry:
            time.sleep(0.01)
        if future.done():
            return
    pytest.fail(f'timed out after {timeout} s waiting for the parameter services to answer')


class Ros:
    """This process's side: one rclpy context, node and executor thread for the module."""

    def __init__(self) -> None:
        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.node = rclpy.create_node('kinematics_node_test', context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self._thread = threading.Thread(target=self._spin, daemon=True)
        self._thread.start()

    def _spin(self) -> None:
        with contextlib.suppress(Exception):    # the context goes away at teardown
            self.executor.spin()

    def collect(self, msg_type, topic: str, qos=RELIABLE) -> list:
        """Subscribe ``topic``; return the list its messages are appended to."""
        received: list = []
        self.node.create_subscription(msg_type, topic, received.append, qos)
        return received

    def collect_raw(self, msg_type, topic: str, qos=RELIABLE) -> list:
        """Subscribe ``topic`` without decoding (for high rates); return the list of CDR bytes.

        Decode later with ``rclpy.serialization.deserialize_message(data, msg_type)``.
        """
        received: list = []
        self.node.create_subscription(msg_type, topic, received.append, qos, raw=True)
        return received

    def call(self, future, timeout: float = 10.0):
        wait_for(future.done, timeout, 'a service response')
        return future.result()

    def close(self) -> None:
        self.executor.shutdown(timeout_sec=1.0)
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)
        self._thread.join(timeout=2.0)


class Lifecycle:
    """Clients of a managed node's lifecycle services, asking again what was not answered.

    A request sent before the node has matched this client is lost, and so is
    an answer sent before this client has matched the node: ``wait_for_service``
    says only that this side sees the service.
    """

    #: The state each transition leads to.
    GOALS = {Transition.TRANSITION_CONFIGURE: 'inactive',
             Transition.TRANSITION_CLEANUP: 'unconfigured',
             Transition.TRANSITION_ACTIVATE: 'active',
             Transition.TRANSITION_DEACTIVATE: 'inactive',
             Transition.TRANSITION_UNCONFIGURED_SHUTDOWN: 'finalized',
             Transition.TRANSITION_INACTIVE_SHUTDOWN: 'finalized',
             Transition.TRANSITION_ACTIVE_SHUTDOWN: 'finalized'}
    #: How long an unanswered request waits before it is sent again, s.
    AGAIN_S = 2.0

    def __init__(self, ros: 'Ros', node: str) -> None:
        self.ros = ros
        self.change = ros.node.create_client(ChangeState, f'{node}/change_state')
        self.get = ros.node.create_client(GetState, f'{node}/get_state')
        assert self.change.wait_for_service(timeout_sec=STARTUP_S)
        assert self.get.wait_for_service(timeout_sec=STARTUP_S)

    def state(self) -> str:
        """Return the node's state label (asking again until answered)."""
        futures: list = []
        send_until(lambda: futures.append(self.get.call_async(GetState.Request())),
                   lambda: any(f.done() for f in futures), STARTUP_S, 'get_state',
                   every=self.AGAIN_S)
        return next(f for f in futures if f.done()).result().current_state.label

    def transition(self, transition_id: int) -> bool:
        """Ask for a transition; return whether it succeeded.

        Unanswered after AGAIN_S, the request is sent again; a repeat of a
        transition that was made is refused by the node, so success is any
        answer's, or the node being in the transition's goal state.
        """
        request = ChangeState.Request(transition=Transition(id=transition_id))
        futures: list = []
        send_until(lambda: futures.append(self.change.call_async(request)),
                   lambda: any(f.done() for f in futures), STARTUP_S,
                   f'change_state {transition_id}', every=self.AGAIN_S)
        if any(f.result().success for f in futures if f.done()):
            return True
        return len(futures) > 1 and self.state() == self.GOALS[transition_id]


#: A minimal rclpy publisher: start rclpy, publish one JointState stamped with the clock on
#: ``NAMESPACE/joint_states`` (transient local), spin until stopped. What the first message of
#: any Python node costs on this machine (the interpreter, rclpy, the message package, DDS).
MINIMAL_PUBLISHER = """
import sys

import rclpy
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import JointState

rclpy.init()
node = rclpy.create_node('first_message', namespace=sys.argv[1])
publisher = node.create_publisher(JointState, 'joint_states', QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL))
msg = JointState()
msg.header.stamp = node.get_clock().now().to_msg()
publisher.publish(msg)
try:
    rclpy.spin(node)
except KeyboardInterrupt:
    pass
"""


def first_message_s(ros: 'Ros', namespace: str) -> float:
    """Return how long a minimal rclpy publisher process takes to stamp its first message, s.

    From the process's start to the stamp of the message it publishes at once
    (:data:`MINIMAL_PUBLISHER`), measured as a node's first state is: the floor,
    on this machine and at this moment, under any node's first message.
    """
    from rclpy.qos import DurabilityPolicy
    from sensor_msgs.msg import JointState

    received = ros.collect(JointState, f'{namespace}/joint_states', QoSProfile(
        depth=1, reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL))
    started_ns = time.time_ns()
    proc = subprocess.Popen([sys.executable, '-c', MINIMAL_PUBLISHER, namespace],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        wait_for(lambda: received or proc.poll() is not None, STARTUP_S,
                 'the minimal publisher')
        assert received, proc.stderr.read().decode() if proc.stderr else proc.returncode
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
        try:
            proc.communicate(timeout=STARTUP_S)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.communicate()
    return (stamp_ns(received[0]) - started_ns) / NS


class NodeProcess:
    """A kinematics_node subprocess with its output in files."""

    def __init__(self, tmp: Path, *ros_args: str) -> None:
        env = dict(os.environ)
        env['PYTHONPATH'] = os.pathsep.join(filter(None, [str(REPO), env.get('PYTHONPATH')]))
        env['PYTHONUNBUFFERED'] = '1'
        tmp.mkdir(parents=True, exist_ok=True)
        self.stdout_path, self.stderr_path = tmp / 'stdout.txt', tmp / 'stderr.txt'
        with open(self.stdout_path, 'w') as out, open(self.stderr_path, 'w') as err:
            self.proc = subprocess.Popen(
                [sys.executable, '-m', 'mech_kinematics.kinematics_node', '--ros-args',
                 *ros_args], env=env, stdout=out, stderr=err, cwd=tmp)

    def output(self) -> str:
        return self.stdout_path.read_text() + self.stderr_path.read_text()

    def stop(self, sig=signal.SIGINT, timeout: float = 5.0) -> tuple[int, float]:
        """Send ``sig``; return (exit status, seconds it took to exit)."""
        start = time.monotonic()
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
        try:
            status = self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
            pytest.fail(f'node did not exit within {timeout} s of {sig!r}:\n{self.output()}')
        return status, time.monotonic() - start


#: How many starts refused_starts runs at once (each CPU-bound: Python, rclpy, NumPy, a scene).
AT_ONCE = 3


def refused_starts(tmp, starts) -> list:
    """Run the node with each argument list of ``starts``; return each (status, output).

    At most AT_ONCE at a time, so that the starts, each one process that exits
    alone, wait on each other's imports rather than one by one; each in a
    namespace of its own (names are taken by age: two starts of one name must
    not meet). One still running 2 x STARTUP_S after its start (it shares the
    machine with AT_ONCE - 1 others) is killed: its status is then -9.
    """
    results: list = [None] * len(starts)
    running: dict = {}
    pending = list(enumerate(starts))
    try:
        while pending or running:
            while pending and len(running) < AT_ONCE:
                i, args = pending.pop(0)
                running[i] = (NodeProcess(tmp / str(i), *args), time.monotonic())
            for i, (proc, started) in list(running.items()):
                if proc.proc.poll() is None and time.monotonic() > started + 2 * STARTUP_S:
                    proc.proc.kill()
                    proc.proc.wait()
                if proc.proc.poll() is not None:
                    results[i] = (proc.proc.returncode, proc.output())
                    del running[i]
            time.sleep(0.01)    # polling the processes, as wait_for does
    finally:
        for proc, _ in running.values():
            proc.proc.kill()
            proc.proc.wait()
    return results
