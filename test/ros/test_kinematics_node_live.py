# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The live view that ``make run`` starts (``python -m mech_kinematics run``): node plus view."""

import os
from pathlib import Path
import random
import re
import signal
import subprocess
import sys
import time

REPO = Path(__file__).resolve().parents[2]
STARTUP_S = 20.0


def test_run_shows_the_node_live_and_ctrl_c_stops_both(tmp_path):
    """The view prints the node's rate and status each second; SIGINT stops view and node, 0."""
    env = dict(os.environ)
    env['ROS_DOMAIN_ID'] = str(random.SystemRandom().randint(1, 100))
    env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    env['PYTHONPATH'] = os.pathsep.join(filter(None, [str(REPO), env.get('PYTHONPATH')]))
    namespace = f'/live_{os.getpid()}_{random.SystemRandom().randrange(16 ** 6):06x}'
    log = tmp_path / 'run.txt'
    with open(log, 'w') as out:
        proc = subprocess.Popen(
            [sys.executable, '-m', 'mech_kinematics.tools.run', '--ros-args', '-r',
             f'__ns:={namespace}', '-p', 'rate_hz:=50'],
            env=env, stdout=out, stderr=subprocess.STDOUT, cwd=tmp_path)
    try:
        deadline = time.monotonic() + STARTUP_S
        while 'solver ok' not in log.read_text():
            assert proc.poll() is None, log.read_text()
            assert time.monotonic() < deadline, f'no live line in {STARTUP_S} s:\n' + \
                log.read_text()
            time.sleep(0.1)
        node_pid = int(re.search(r'node started \(pid (\d+)\)', log.read_text()).group(1))
        proc.send_signal(signal.SIGINT)
        status = proc.wait(timeout=10)
    finally:
        if proc.poll() is None:
            proc.kill()
    output = log.read_text()
    assert status == 0, output
    assert 'Traceback' not in output
    assert re.search(r'^\s+\d+\.\d+ \|', output, re.MULTILINE), output   # a rate column
    # Each joint: its value at a drifting instant and its range over the second (issue 20).
    assert re.search(r'\| crank [+-]\d\.\d{4} \[[+-]\d\.\d{4} \.\. [+-]\d\.\d{4}\]',
                     output), output
    # The browser view is served beside it, on localhost (issue 20).
    assert re.search(r'browser view on http://127\.0\.0\.1:\d+/', output), output
    assert not Path(f'/proc/{node_pid}').exists() or \
        'zombie' in Path(f'/proc/{node_pid}/status').read_text(), 'the node is still running'
