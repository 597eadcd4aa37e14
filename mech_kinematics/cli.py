# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Argument types shared by the ``python -m mech_kinematics`` subcommands."""

from __future__ import annotations

import argparse
import math


def finite_float(text: str) -> float:
    """Parse a finite number, or tell argparse why not."""
    value = float(text)
    if not math.isfinite(value):
        msg = f'expected a finite number, got {text!r}'
        raise argparse.ArgumentTypeError(msg)
    return value


def positive_int(text: str) -> int:
    """Parse a whole number of at least 1, or tell argparse why not."""
    value = int(text)
    if value < 1:
        msg = f'expected a positive integer, got {text!r}'
        raise argparse.ArgumentTypeError(msg)
    return value
