# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A driver's rate in the unit it was given, and its one conversion to SI (units.py, issue 30)."""

import math

import pytest

from mech_kinematics.units import (rad_per_s_from_rpm, rate_from_si, RATE_UNITS,
                                   rpm_from_rad_per_s, si_from_rate)


def test_only_rpm_is_converted_to_si():
    """Only rpm is converted (as rad_per_s_from_rpm does); rad/s and m/s are kept to the bit."""
    assert si_from_rate(7.0, 'rpm') == rad_per_s_from_rpm(7.0) == 7.0 * math.pi / 30
    assert rate_from_si(math.pi, 'rpm') == rpm_from_rad_per_s(math.pi) == math.pi * 30 / math.pi
    for unit in ('rad/s', 'm/s'):
        assert si_from_rate(0.1, unit) == rate_from_si(0.1, unit) == 0.1
    assert set(RATE_UNITS) == {'rpm', 'rad/s', 'm/s'}


def test_a_unit_that_is_no_rate_is_refused_in_one_line():
    """A rate unit outside RATE_UNITS names the units allowed."""
    with pytest.raises(ValueError, match=r"^Expected a rate unit in rpm, rad/s, m/s, got 'deg/s"):
        si_from_rate(1.0, 'deg/s')
    with pytest.raises(ValueError, match='got .Hz.'):
        rate_from_si(1.0, 'Hz')
