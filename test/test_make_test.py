# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``make test``: a run that tests nothing fails (issue 33); one phase selecting nothing does not.

``make test`` runs pytest twice (the tests on two workers, then the node's tests,
marked serial, alone). pytest's status 5 says a run selected no test; it counted
as success in both phases, so ``PYTEST_ARGS='-k tpyo'`` passed having tested nothing.
"""

import os
from pathlib import Path
import subprocess

import pytest

REPO = Path(__file__).resolve().parent.parent
#: A file of serial tests only (test/ros/), quick and without ROS.
SERIAL_ONLY = 'test/ros/test_startup.py'


def make_test(pytest_args: str) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(('PYTEST_', 'MAKE')) and k != 'MFLAGS'}
    return subprocess.run(['make', 'test', f'PYTEST_ARGS={pytest_args}'], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=600)


@pytest.mark.parametrize('pytest_args, status', [
    (f'{SERIAL_ONLY} -k nothing_is_named_this', 2),     # neither phase: make's error status
    (f'-n 0 {SERIAL_ONLY}', 0),                         # the serial phase only
])
def test_make_test_fails_when_no_test_ran_in_either_phase(pytest_args, status):
    """No test selected in either phase fails with one line; in one phase only, it passes.

    The first case runs the first phase on its two workers as ``make test`` does (their
    pytest must say status 5 too); the second, whose first phase selects nothing as the
    first case's does, runs it without workers (``-n 0`` after ``-n 2``: two Pythons
    fewer to start).
    """
    result = make_test(pytest_args)
    output = result.stdout + result.stderr
    assert result.returncode == status, output
    said = 'make test: no test ran: PYTEST_ARGS selected none in either phase'
    assert (said in output) == (status != 0), output
    if status == 0:
        assert '7 passed' in output, output
