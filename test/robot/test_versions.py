# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""URDF 1.0, 1.1 and 1.2 are read (issue 43, item 1); the version gate is ours.

urdf_parser_py refuses any ``<robot version>`` but 1.0 ("Invalid version; only 1.0
is supported"), though urdfdom 6 writes 1.1 (``<origin quat_xyzw>``, capsules)
and 1.2 (a ``<limit>``'s acceleration, deceleration and jerk). What a loop does not
use is ignored; a ``quat_xyzw`` origin of a joint or a constraint moves the loop
and is read exactly: the tests check the loop closed in this test's own forward
kinematics, whose quaternions SciPy turns into matrices
(``helpers.UrdfFk``).
"""

import math

from helpers import khurmi_urdf, UrdfFk
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mech_kinematics.errors import UrdfError
from mech_kinematics.robot import load_robot

MOTOR = 0.5


def versioned(text: str, version: str | None) -> str:
    """Return ``text`` with ``<robot ... version="V">`` (none: as it is)."""
    if version is None:
        return text
    return text.replace('<robot name="khurmi">', f'<robot name="khurmi" version="{version}">')


def joints(text: str) -> dict[str, float]:
    answer = load_robot(text).solve({'motor': MOTOR})
    return {name: joint.position for name, joint in answer.joints.items()}


def closes(text: str, values: dict[str, float]) -> float:
    """Return pin C's gap over the loop's size in the test's own forward kinematics."""
    fk = UrdfFk(text)
    return fk.gaps(values)['pin_C'] / fk.loop_size('pin_C')


def quat(rotation: Rotation) -> str:
    return ' '.join(repr(float(v)) for v in rotation.as_quat())


@pytest.mark.parametrize('version', ['1.0', '1.1', '1.2', ' 1.2 ', '01.1'])
def test_every_version_read_gives_the_answer_of_a_urdf_without_one(version):
    """``version="1.0"``, ``"1.1"``, ``"1.2"``: the same joints, to the bit."""
    plain = khurmi_urdf()
    assert joints(versioned(plain, version)) == joints(plain)


def test_what_1_1_and_1_2_add_that_a_loop_does_not_use_is_ignored():
    """A capsule visual (1.1) and a limit's acceleration, deceleration, jerk (1.2)."""
    plain = khurmi_urdf()
    text = versioned(plain, '1.2').replace(
        '<limit lower="-3" upper="3" effort="1" velocity="1"/>',
        '<limit lower="-3" upper="3" effort="1" velocity="1" acceleration="5" '
        'deceleration="6" jerk="100"/>').replace(
        '<link name="rocker"/>', '<link name="rocker"><visual><geometry><capsule radius="0.01" '
        'length="0.08"/></geometry></visual></link>')
    assert 'jerk="100"' in text and '<capsule' in text
    assert joints(text) == joints(plain)


def test_a_quaternion_origin_places_the_joint_as_its_rpy_does():
    """The motor's ``rpy="0 0 pi/3"`` as ``quat_xyzw``, scaled by 3: the same joints."""
    plain = khurmi_urdf()
    q = Rotation.from_euler('z', math.pi / 3).as_quat() * 3.0
    text = versioned(plain, '1.1').replace(
        'rpy="0 0 1.0471975511965976"', f'quat_xyzw="{" ".join(repr(float(v)) for v in q)}"')
    assert 'quat_xyzw' in text
    got, expected = joints(text), joints(plain)
    assert got.keys() == expected.keys()
    for name in got:
        assert got[name] == pytest.approx(expected[name], abs=1e-14), name
    assert closes(text, got) <= 1e-12


@pytest.mark.parametrize('seed', range(4))
def test_quaternion_constraint_origins_close_the_loop_in_the_tests_own_kinematics(seed):
    """Random frames at pin C (about z, the loop's normal) written as ``quat_xyzw``."""
    rng = np.random.default_rng(seed)
    plain = khurmi_urdf()
    text = versioned(plain, '1.2')
    for end in ('parent', 'child'):  # rotate the pin's frame and its axis with it
        angle = float(rng.uniform(-math.pi, math.pi))
        flip = Rotation.from_euler('z', angle)
        start = text.index(f'<{end}_origin')
        stop = text.index('/>', start)
        element = text[start:stop].replace(' rpy="0 0 0"', f' quat_xyzw="{quat(flip)}"')
        text = text[:start] + element + text[stop:]
    got = joints(text)
    assert closes(text, got) <= 1e-12
    expected = joints(plain)
    for name in got:
        assert got[name] == pytest.approx(expected[name], abs=1e-12), name


def _refused(text: str) -> str:
    with pytest.raises(UrdfError) as caught:
        load_robot(text)
    message = str(caught.value)
    assert '\n' not in message
    return message


@pytest.mark.parametrize('version, said', [
    ('2.0', "Expected <robot version> 1.0, 1.1, 1.2, got '2.0'"),
    ('1.3', "Expected <robot version> 1.0, 1.1, 1.2, got '1.3'"),
    ('one', "Expected <robot version> 1.0, 1.1, 1.2 (the form MAJOR.MINOR), got 'one'"),
    ('1', "Expected <robot version> 1.0, 1.1, 1.2 (the form MAJOR.MINOR), got '1'"),
])
def test_a_version_not_read_is_refused_in_one_line(version, said):
    """Not one of ours, or not MAJOR.MINOR: one line, the version as written."""
    assert _refused(versioned(khurmi_urdf(), version)).endswith(said)


@pytest.mark.parametrize('version, origin, said', [
    (None, 'quat_xyzw="0 0 0.5 0.8660254037844386"',
     'joint "motor" <origin>: Expected quat_xyzw only in a URDF of version 1.1 or later '
     '(<robot version="1.1">), got it in version 1.0'),
    ('1.1', 'rpy="0 0 1.0471975511965976" quat_xyzw="0 0 0.5 0.8660254037844386"',
     'joint "motor" <origin>: Expected rpy or quat_xyzw, got both'),
    ('1.1', 'quat_xyzw="0 0 0 0"',
     "Expected joint \"motor\" <origin> quat_xyzw to be a non-zero quaternion, got '0 0 0 0'"),
    ('1.1', 'quat_xyzw="0 0 0.5"',
     "Expected joint \"motor\" <origin> quat_xyzw to be 4 finite numbers, got '0 0 0.5'"),
])
def test_a_bad_quaternion_origin_is_refused_in_one_line_naming_the_joint(version, origin, said):
    """Before 1.1, beside an rpy, zero, or not four numbers: one line."""
    text = versioned(khurmi_urdf(), version).replace('rpy="0 0 1.0471975511965976"', origin)
    assert _refused(text).endswith(said)
