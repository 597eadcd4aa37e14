# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node publishes the crank speed that `solve` prints, to the bit (issue 17).

A scene's speed is kept in the unit it was given from the scene to the time
base; before, the packaged Geneva's 10 rad/s came out as 9.999999999996104.
"""

import json
import signal
import subprocess
import sys

import pytest
from ros_helpers import NodeProcess, REPO, Ros, SESSION, STARTUP_S, wait_for
from sensor_msgs.msg import JointState


@pytest.fixture(scope='module')
def ros():
    ros = Ros()
    yield ros
    ros.close()


def solve_speed(*args: str) -> float:
    """Return the crank speed of `python -m mech_kinematics solve ARGS` (its JSON)."""
    out = subprocess.run([sys.executable, '-m', 'mech_kinematics', 'solve', *args],
                         cwd=REPO, check=True, capture_output=True, text=True).stdout
    return json.loads(out)['input']['speed']


@pytest.mark.parametrize('scene, crank, rpm', [
    ('geneva', 'driver', None),                  # 10 rad/s, given as 95.4929658551372 rpm
    ('khurmi_four_bar_ad150', 'crank', None),    # -120 rpm
    ('geneva', 'driver', '600.0'),               # a speed set on the node, in rpm
])
def test_the_crank_speed_on_joint_states_is_what_solve_prints(ros, tmp_path, scene, crank, rpm):
    """joint_states' crank velocity == `solve`'s JSON speed, exactly, at every instant."""
    expected = solve_speed(scene, *(['--speed-rpm', rpm] if rpm else []))
    ns = f'{SESSION}/speed_{scene}_{rpm or "scene"}'.replace('.', '_')
    js = ros.collect(JointState, f'{ns}/joint_states')
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns}', '-p', f'scene:={scene}',
                       *(['-p', f'crank_speed_rpm:={rpm}'] if rpm else []))
    try:
        wait_for(lambda: len(js) > 20, STARTUP_S, 'joint_states')
    finally:
        status, _ = proc.stop(signal.SIGINT)
    assert status == 0, proc.output()
    speeds = {m.velocity[list(m.name).index(crank)] for m in js}
    assert speeds == {expected}, (speeds, expected)
    if scene == 'geneva' and rpm is None:
        assert expected == 10.0
