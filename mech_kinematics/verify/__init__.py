# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The verification room: the independent 50-digit solver and the extreme suite.

What the tests and the report measure the solver against, kept apart from
both (the report, ``tools/report/``, and the tests import it; it imports the
solver core and geometry only, never a tool or the ROS layer):

- :mod:`.reference`: every scene written as its loop-closure equations and
  solved at 64 digits in mpmath, one model of equations per kind of the
  registries, none of the solver's formulas;
- :mod:`.extreme`: the stiff and extreme configurations of issue 5 and the
  solver judged against the reference on them;
- :mod:`.cases`: the mechanisms both build (four-bars, slider-cranks, chains)
  and the crank angle of a toggle.

Importing this package imports none of them (and so no mpmath).
"""
