# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The ROS 2 layer: the node, its messages and their CDR templates, markers, time base."""
