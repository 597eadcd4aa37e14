# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Package data of mech_kinematics (no code).

``textbook_answers.yaml``
    The answers printed in the textbooks behind the shipped scenes, with
    their sources and tolerances; read it through :mod:`mech_kinematics.textbook`.
"""
