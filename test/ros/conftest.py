# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node's tests share one fixture: ``ros``, this process's side, one per module."""

import pytest
from ros_helpers import Ros


@pytest.fixture(scope='module')
def ros():
    ros = Ros()
    yield ros
    ros.close()
