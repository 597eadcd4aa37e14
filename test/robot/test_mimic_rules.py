# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Contradictory <mimic> rules: a cycle refused in one line, every broken rule reported.

Issue 42, item 3.
"""

import json
import math

from helpers import khurmi_urdf, solve_urdf_text
import pytest

from mech_kinematics.errors import UrdfError
from mech_kinematics.robot import load_robot

#: Two joints outside the loop, on the frame: w1 mimics {l1}, w2 mimics {l2}.
EXTRA = """<link name="e1"/><link name="e2"/>
  <joint name="w1" type="revolute"><parent link="frame"/><child link="e1"/><axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/><mimic joint="{l1}" multiplier="2"/>
  </joint>
  <joint name="w2" type="revolute"><parent link="frame"/><child link="e2"/><axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/><mimic joint="{l2}" multiplier="0.5"/>
  </joint>
</robot>"""


def _with(l1, l2):
    return khurmi_urdf().replace('</robot>', EXTRA.format(l1=l1, l2=l2))


@pytest.mark.parametrize(('l1', 'l2', 'cycle'), [
    ('w2', 'w1', 'w1 mimics w2 mimics w1'),
    ('w1', 'motor', 'w1 mimics w1'),
])
def test_a_mimic_cycle_is_refused_in_one_line_naming_its_joints(tmp_path, capsys, l1, l2, cycle):
    """w1 -> w2 -> w1, or w1 -> w1: solve exited 0 with w1 and w2 left out of the answer."""
    with pytest.raises(UrdfError) as caught:
        load_robot(_with(l1, l2))
    assert caught.value.joint == 'w1'
    assert '\n' not in str(caught.value)
    assert str(caught.value).endswith(
        'joint "w1": Expected its <mimic> rule to lead to a joint that mimics none, got a '
        f'cycle: {cycle}')
    status, out, err = solve_urdf_text(tmp_path, capsys, _with(l1, l2), '--input', 'motor=20')
    assert (status, out) == (2, '')
    assert len(err.splitlines()) == 1 and cycle in err


def test_a_chain_of_mimics_is_no_cycle_and_follows_its_leader():
    """w1 mimics w2 mimics motor: both answered by their rules, nothing reported."""
    answer = load_robot(_with('w2', 'motor')).solve({'motor': 0.3})
    assert answer.joints['w2'].position == 0.5 * 0.3
    assert answer.joints['w1'].position == 2 * (0.5 * 0.3)
    assert answer.mimic == {}


def test_an_actuated_joint_that_breaks_its_own_mimic_rule_is_reported(tmp_path, capsys):
    """The crank given, its <mimic> of the loop's elbow broken: listed under mimic, by how much.

    It was answered with nothing under ``mimic`` (only passive loop joints were
    checked).
    """
    text = khurmi_urdf().replace(
        '<axis xyz="0 0 1"/>\n    <limit lower="-3.2"',
        '<axis xyz="0 0 1"/><mimic joint="elbow" multiplier="1" offset="0"/>\n'
        '    <limit lower="-3.2"', 1)
    assert text.count('<mimic') == 1
    answer = load_robot(text).solve({'motor': math.radians(20)})
    elbow = answer.joints['elbow'].position
    expected = elbow
    assert answer.mimic == {'motor': {
        'leader': 'elbow', 'rule': expected,
        'stray': math.remainder(math.radians(20) - expected, math.tau)}}
    assert abs(answer.mimic['motor']['stray']) > 0.1
    status, out, _ = solve_urdf_text(tmp_path, capsys, text, '--input', 'motor=20')
    assert status == 0
    assert json.loads(out)['mimic']['motor']['stray'] == answer.mimic['motor']['stray']


def test_every_broken_rule_is_reported_and_a_kept_one_is_not():
    """The crank breaks its rule (a mimic of the elbow), w2 keeps its (a mimic of the crank).

    Every answered joint's rule is checked: only the broken one is listed.
    """
    text = _with('w2', 'motor').replace(
        '<axis xyz="0 0 1"/>\n    <limit lower="-3.2"',
        '<axis xyz="0 0 1"/><mimic joint="elbow" multiplier="-1"/>\n    <limit lower="-3.2"', 1)
    answer = load_robot(text).solve({'motor': 0.4})
    assert set(answer.mimic) == {'motor'}
    assert answer.mimic['motor']['rule'] == -answer.joints['elbow'].position
