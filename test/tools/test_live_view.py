# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The console view's interval summary: a drifting sample and each joint's range. See issue 20."""

import math

import numpy as np
import pytest

from mech_kinematics.tools.live_view import GOLDEN_FRACTION, Interval, JointSummary

RATE_HZ = 100
RPM = 120.0                                 # two turns a second: the case of issue 20
OMEGA = 2 * math.pi * RPM / 60              # rad/s


def wrapped(angle):
    return math.remainder(angle, 2 * math.pi)


def intervals(seconds):
    """Yield an Interval per second of a 120 rpm crank and a rocker, received at 100 Hz."""
    for s in range(seconds):
        interval = Interval()
        for i in range(RATE_HZ):
            t = s + i / RATE_HZ
            interval.add(t, ['crank', 'rocker'], [wrapped(OMEGA * t), 0.3 * math.sin(OMEGA * t)])
        yield interval


def test_the_sampled_crank_angle_moves_from_line_to_line():
    """At 120 rpm the latest angle is the same each second; the drifting sample is not."""
    lines = list(intervals(8))
    latest = [wrapped(OMEGA * (s + (RATE_HZ - 1) / RATE_HZ)) for s in range(8)]
    assert np.ptp(latest) < 1e-9                       # what the old view printed: frozen
    shown = [interval.summary(k)[0][1] for k, interval in enumerate(lines)]
    steps = np.abs([wrapped(b - a) for a, b in zip(shown[:-1], shown[1:], strict=True)])
    assert steps.min() > 0.3, shown                   # rad: visibly different each line


def test_the_sample_is_at_the_golden_fraction_of_the_interval():
    """Line k shows the first state at or after frac(k * 0.618...) of its interval."""
    interval = next(intervals(1))
    for k in range(5):
        fraction = math.fmod(k * GOLDEN_FRACTION, 1.0)
        i = math.ceil(fraction * (RATE_HZ - 1) - 1e-9)
        crank = interval.summary(k)[0]
        assert crank[1] == pytest.approx(wrapped(OMEGA * i / RATE_HZ), abs=1e-12)


def test_the_range_is_the_minimum_and_maximum_over_the_interval():
    """Each joint's range is the exact minimum and maximum of the states received."""
    interval = next(intervals(1))
    t = np.arange(RATE_HZ) / RATE_HZ
    rocker = interval.summary(0)[1]
    assert rocker == JointSummary('rocker', 0.0, (0.3 * np.sin(OMEGA * t)).min(),
                                  (0.3 * np.sin(OMEGA * t)).max())
    # 50 samples a turn miss the peak at 1/8 turn: the nearest is 0.3 sin(0.48 pi) = 0.2994.
    assert str(rocker) == 'rocker +0.0000 [-0.2994 .. +0.2994]'


def test_an_empty_interval_has_no_summary_and_a_new_scene_restarts_it():
    """Nothing received: no joints; joint names that change drop the older states."""
    interval = Interval()
    assert interval.summary(3) == []
    interval.add(0.0, ['a'], [5.0])
    interval.add(0.1, ['b'], [1.0])
    assert interval.summary(0) == [JointSummary('b', 1.0, 1.0, 1.0)]
    assert interval.count == 2
