# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""One node of a name (issue 20, item 5): who said what on ``~/_instance``, without a node.

Every node says its start instant and a random id on ``~/_instance``; a node
that hears an older one of its name stops (and exits 1), the older one goes
on. The node's side of it is tested from a subscriber in
``test_kinematics_node_start.py``.
"""

import pytest
from rclpy.qos import DurabilityPolicy
from std_msgs.msg import String

from mech_kinematics.ros.instance import DuplicateNodeError, Instance, INSTANCE_TOPIC


class FakeNode:
    """What Instance uses of a node: a subscription, a publisher, stop() and the name."""

    def __init__(self) -> None:
        self.heard = None
        self.said: list[str] = []
        self.stopped = 0

    def create_subscription(self, msg_type, topic, callback, qos):
        assert (msg_type, topic, qos.durability) == (String, INSTANCE_TOPIC,
                                                     DurabilityPolicy.TRANSIENT_LOCAL)
        self.heard = callback

    def create_publisher(self, msg_type, topic, qos):
        assert (msg_type, topic, qos.durability) == (String, INSTANCE_TOPIC,
                                                     DurabilityPolicy.TRANSIENT_LOCAL)
        return self

    def publish(self, msg: String) -> None:
        self.said.append(msg.data)

    def stop(self) -> None:
        self.stopped += 1

    def get_fully_qualified_name(self) -> str:
        return '/robot1/mech_kinematics'


def test_an_instance_says_its_start_and_id():
    """A node says its start instant and a random 64-bit id, another id for another node."""
    node = FakeNode()
    instance = Instance(node, 1_700_000_000_123_456_789)
    assert node.said == [f'1700000000123456789 {instance.key[1]}']
    assert 0 <= instance.key[1] < 2 ** 64
    assert Instance(FakeNode(), 5).key[1] != instance.key[1]


@pytest.mark.parametrize('start, ident_offset, older', [
    (999, 0, True),         # started earlier: this node is the newcomer
    (999, 7, True),
    (1000, -1, True),       # the same instant, a smaller id
    (1000, 0, False),       # its own message
    (1000, 1, False),       # the same instant, a larger id
    (1001, -5, False),      # started later: a newcomer, ignored
])
def test_only_an_older_node_stops_this_one(start, ident_offset, older):
    """An earlier start (or the same with a smaller id) stops this node; others are ignored."""
    node = FakeNode()
    instance = Instance(node, 1000)
    instance.key = 1000, 2 ** 32
    msg = String(data=f'{start} {2 ** 32 + ident_offset}')
    if older:
        with pytest.raises(DuplicateNodeError,
                           match='^another node named /robot1/mech_kinematics is running'):
            node.heard(msg)
        assert node.stopped == 1
    else:
        node.heard(msg)
        assert node.stopped == 0


@pytest.mark.parametrize('data', ['', 'hello', '12', '1 2 3', '0.5 3'])
def test_a_message_not_of_ours_is_ignored(data):
    """Words on the topic that are not a start and an id stop nothing."""
    node = FakeNode()
    Instance(node, 10 ** 18)
    node.heard(String(data=data))
    assert node.stopped == 0
