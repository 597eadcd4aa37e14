# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""One node of a name: each says its start on ``~/_instance``, the newcomer of two stops.

Every node says its start instant (system time) and a random id on the
node-private, hidden, transient-local topic ``~/_instance``, and hears the
others of its fully qualified name there. Of the nodes that share a name, the
oldest (earliest start, then smallest id) goes on; a node that hears an older
one stops its tick thread and raises :class:`DuplicateNodeError` from its spin
(``main`` says why in one line, exit status 1). An older node ignores
younger ones, so it goes on without a gap.

A node here is anything with ``create_subscription``, ``create_publisher``,
``stop`` and ``get_fully_qualified_name``: the tests give a stand-in
(``test/ros/test_instance.py``).
"""

from __future__ import annotations

import random
from typing import Any

from rclpy.qos import QoSDurabilityPolicy, QoSProfile, QoSReliabilityPolicy
from std_msgs.msg import String

__all__ = ['DuplicateNodeError', 'INSTANCE_HISTORY', 'INSTANCE_TOPIC', 'Instance']

#: The node-private, hidden topic on which each node says when it started (transient local,
#: so that a newcomer of the same name hears an older node as soon as they are matched).
INSTANCE_TOPIC = '~/_instance'
#: How many nodes' words on ``~/_instance`` a node keeps until its first spin reads them.
INSTANCE_HISTORY = 100


class DuplicateNodeError(Exception):
    """An older node of the same fully qualified name is running: this one is the newcomer."""


class Instance:
    """A node's start instant and random id, said on and heard from ``~/_instance``.

    Of the nodes that share a fully qualified name, the oldest (earliest start, then smallest
    id) goes on; a node that hears an older one raises DuplicateNodeError from its spin after
    stopping its tick thread. An older node ignores younger ones.
    """

    def __init__(self, node: Any, start_ns: int) -> None:
        self.node = node
        self.key = start_ns, random.SystemRandom().getrandbits(64)
        qos = QoSProfile(depth=1, reliability=QoSReliabilityPolicy.RELIABLE,
                         durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
        # The node hears its own word too, and all of them may arrive before its first
        # spin (a slow start): a history of one would keep only the last, maybe its own.
        heard = QoSProfile(depth=INSTANCE_HISTORY, reliability=QoSReliabilityPolicy.RELIABLE,
                           durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
        node.create_subscription(String, INSTANCE_TOPIC, self._heard, heard)
        node.create_publisher(String, INSTANCE_TOPIC, qos).publish(
            String(data=f'{self.key[0]} {self.key[1]}'))

    def _heard(self, msg: String) -> None:
        try:
            start_ns, ident = (int(word) for word in msg.data.split())
        except ValueError:
            return      # not a node of ours: nothing to compare
        if (start_ns, ident) < self.key:
            self.node.stop()
            raise DuplicateNodeError(
                f'another node named {self.node.get_fully_qualified_name()} is running '
                '(remap the name with -r __node:=NAME or the namespace with -r __ns:=/NS)')
