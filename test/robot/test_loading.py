# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Reading a robot takes time linear in its size (issue 42: it was quadratic).

Judged against the same run: a robot eight times larger reads in far less than
64 times the time of the smaller one (what a quadratic reader takes; a linear
one takes about 8 times). CPU time of this process, so that other jobs on the
machine count less.
"""

import time

from helpers import khurmi_chain_urdf, khurmi_closures_yaml, KHURMI_OPEN
import pytest

from mech_kinematics.errors import UrdfError
from mech_kinematics.robot import load_robot

#: The most a reading eight times larger may take, in multiples of the smaller one's time:
#: linear measured 8 to 14 (n log n sorts, a loaded machine); quadratic is 64.
RATIO = 24


def _cpu_s(read):
    start = time.process_time()
    result = read()
    return time.process_time() - start, result


def test_a_chain_of_16000_fixed_joints_reads_in_linear_time(tmp_path):
    """16,000 fixed joints (2.3 MB) against 2,000: eight times as many, as 40,000 against 5,000.

    40,000 and 5,000 took 483 s and 2 s before issue 42 was fixed; docs/urdf.md gives
    the times at every size up to 40,000 (5.8 MB, under the 8 MiB cap).
    """
    times = {}
    for count in (2_000, 16_000):
        path = tmp_path / f'chain_{count}.urdf'
        path.write_text(khurmi_chain_urdf(count))
        times[count], robot = _cpu_s(lambda path=path: load_robot(path))
        assert len(robot.description.joints) == count + 3
        assert robot.description.depth(f'c{count - 1}') == count
    assert times[16_000] < RATIO * times[2_000], times


def test_a_sidecar_of_8000_closures_reads_in_linear_time(tmp_path):
    """8,000 closures against 1,000: every pair of their points was compared (41 s and 1 s).

    The copies of one closure are refused as a pin written twice (issue 42, item 5) once
    every closure is read and placed on its bodies; the hull that sizes a loop of many pins
    (``planar._diameter``) is held to brute force on its own.
    """
    urdf = tmp_path / 'open.urdf'
    urdf.write_text(KHURMI_OPEN)
    times = {}
    for count in (1_000, 8_000):
        path = tmp_path / f'closures_{count}.yaml'
        path.write_text(khurmi_closures_yaml(count))

        def read(path=path):
            with pytest.raises(UrdfError, match='pinned together once') as refused:
                load_robot(urdf, path)
            return refused

        times[count], _ = _cpu_s(read)
    assert times[8_000] < RATIO * times[1_000], times
