# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""`python -m mech_kinematics kinematics_node ...` is the node's executable (issue 33).

README says each executable runs as ``python -m mech_kinematics NAME``; the
node's did not (argparse refused ``kinematics_node`` as an unknown command).
It now starts the node with its arguments untouched, as ``run`` passes them.
"""

import os
import signal
import subprocess
import sys

from ros_helpers import REPO, SESSION, STARTUP_S, wait_for
from sensor_msgs.msg import JointState


def test_python_m_starts_the_node_with_its_arguments_untouched(ros, tmp_path):
    """The node comes up in the namespace and on the scene its --ros-args name; SIGINT: exit 0.

    The packaged boom (one actuator, its only driver) is published at its
    cylinder's start length, 1.9 m.
    """
    ns = f'{SESSION}/python_m'
    received = ros.collect(JointState, f'{ns}/joint_states')
    env = dict(os.environ, PYTHONUNBUFFERED='1',
               PYTHONPATH=os.pathsep.join(filter(None, [str(REPO), os.environ.get('PYTHONPATH')])))
    output = tmp_path / 'output.txt'
    with open(output, 'w') as out:
        proc = subprocess.Popen(
            [sys.executable, '-m', 'mech_kinematics', 'kinematics_node', '--ros-args',
             '-r', f'__ns:={ns}', '-p', 'scene:=boom', '-p', 'rate_hz:=50.0'],
            env=env, stdout=out, stderr=subprocess.STDOUT, cwd=tmp_path)
    try:
        wait_for(lambda: received or proc.poll() is not None, STARTUP_S, 'joint_states')
        assert proc.poll() is None, output.read_text()
        first = received[0]
        assert list(first.name)[0] == 'lift_cyl' and first.position[0] >= 1.9
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
        try:
            status = proc.wait(timeout=10.0)
        except subprocess.TimeoutExpired:
            proc.kill()
            raise
    assert status == 0, output.read_text()
    assert 'unrecognized' not in output.read_text()
