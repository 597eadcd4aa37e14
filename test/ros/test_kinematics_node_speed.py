# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The node publishes the crank speed that `solve` prints, to the bit (issue 17).

A scene's speed is kept in the unit it was given from the scene to the time
base; before, the packaged Geneva's 10 rad/s came out as 9.999999999996104.
"""

import contextlib
import io
import json
import signal
import subprocess
import sys

import pytest
from ros_helpers import NodeProcess, REPO, SESSION, STARTUP_S, wait_for
from sensor_msgs.msg import JointState


def solve_speed(*args: str, cli: bool = False) -> float:
    """Return the crank speed that `python -m mech_kinematics solve ARGS` prints (its JSON).

    In this process (the command's own ``main``), or with ``cli`` as a command.
    """
    if cli:
        out = subprocess.run([sys.executable, '-m', 'mech_kinematics', 'solve', *args],
                             cwd=REPO, check=True, capture_output=True, text=True).stdout
    else:
        from mech_kinematics.tools import solve

        with contextlib.redirect_stdout(io.StringIO()) as stdout:
            assert solve.main(list(args)) == 0
        out = stdout.getvalue()
    return json.loads(out)['input']['speed']


# khurmi_four_bar_ad150 at its scene's speed (-120 rpm): test_a_tiny_speed_set_at_run_time_...
# judges its node's states before it sets a speed.
@pytest.mark.parametrize('scene, crank, rpm', [
    ('geneva', 'driver', None),                  # 10 rad/s, given as 95.4929658551372 rpm
    ('geneva', 'driver', '600.0'),               # a speed set on the node, in rpm
])
def test_the_crank_speed_on_joint_states_is_what_solve_prints(ros, tmp_path, scene, crank, rpm):
    """joint_states' crank velocity == `solve`'s JSON speed, exactly, at every instant."""
    expected = solve_speed(scene, *(['--speed-rpm', rpm] if rpm else []), cli=rpm is None)
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


def test_a_tiny_speed_set_at_run_time_is_published(ros, tmp_path):
    """Issue 21, item 2: 1e-160 and 1e-300 rpm set on a running node are published.

    They used to be accepted and then nothing was published ("at most 1e-06 x 0
    m/s^2 ... got 9.88e-324"): each is now answered, its crank velocity what
    `solve --speed-rpm` prints. Before, every state is at the scene's speed
    (-120 rpm), what `solve` prints, to the bit.
    """
    from rclpy.parameter import Parameter
    from rclpy.parameter_client import AsyncParameterClient
    from ros_helpers import wait_for_parameters

    ns = f'{SESSION}/tiny_speed'
    js = ros.collect(JointState, f'{ns}/joint_states')
    proc = NodeProcess(tmp_path, '-r', f'__ns:={ns}', '-p', 'scene:=khurmi_four_bar_ad150')
    try:
        wait_for(lambda: len(js) > 20, STARTUP_S, 'joint_states')
        params = AsyncParameterClient(ros.node, f'{ns}/mech_kinematics')
        wait_for_parameters(params)
        before = len(js)
        speeds = {m.velocity[list(m.name).index('crank')] for m in js[:before]}
        assert speeds == {solve_speed('khurmi_four_bar_ad150')}, speeds
        for rpm in ('1e-160', '1e-300'):
            expected = solve_speed('khurmi_four_bar_ad150', '--speed-rpm', rpm)
            assert 0.0 < expected < 1e-158
            response = ros.call(params.set_parameters([Parameter('crank_speed_rpm',
                                                                 value=float(rpm))]))
            assert response.results[0].successful, response.results[0].reason
            wait_for(lambda expected=expected: any(
                m.velocity[list(m.name).index('crank')] == expected for m in js),
                STARTUP_S, f'a state at {rpm} rpm')
            seen = len(js)
            wait_for(lambda seen=seen: len(js) > seen + 10, STARTUP_S, f'states at {rpm} rpm')
            assert js[-1].velocity[list(js[-1].name).index('crank')] == expected
        assert proc.proc.poll() is None
    finally:
        status, _ = proc.stop(signal.SIGINT)
    assert status == 0, proc.output()
    assert 'cannot be trusted' not in proc.output()


def test_a_crank_speed_given_in_rad_per_s_is_published_as_given(ros, tmp_path):
    """Issue 33: a scene's `speed: 300` (rad/s) is driven at 300.0 rad/s exactly.

    The node's parameter stays `crank_speed_rpm`: it shows the speed in rpm
    (300 x 30 / pi, to 12 digits), and the time base runs on the scene's own
    rad/s, so joint_states carries what `solve` prints, to the bit.
    """
    from rclpy.parameter_client import AsyncParameterClient
    from ros_helpers import wait_for_parameters

    from mech_kinematics.scene import scene_text

    scene = tmp_path / 'piston_rad_s.yaml'
    scene.write_text(scene_text('piston_300').replace('speed_rpm: 2864.7889756541163',
                                                      'speed: 300'))
    assert solve_speed(str(scene)) == 300.0
    ns = f'{SESSION}/speed_rad_s'
    js = ros.collect(JointState, f'{ns}/joint_states')
    proc = NodeProcess(tmp_path / 'node', '-r', f'__ns:={ns}', '-p', f'scene:={scene}')
    try:
        wait_for(lambda: len(js) > 20, STARTUP_S, 'joint_states')
        params = AsyncParameterClient(ros.node, f'{ns}/mech_kinematics')
        wait_for_parameters(params)
        [rpm] = ros.call(params.get_parameters(['crank_speed_rpm'])).values
    finally:
        status, _ = proc.stop(signal.SIGINT)
    assert status == 0, proc.output()
    assert {m.velocity[list(m.name).index('crank')] for m in js} == {300.0}
    assert rpm.double_value == 2864.78897565
