# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Analytic position, velocity and acceleration of planar linkages.

A mechanism is a driving crank followed by dyads (RRR, RRP, RPR, RPP), triads and points
carried rigidly by links, solved one after another in closed form: no
iteration anywhere. Points are complex numbers ``x + iy`` internally, so a
rigid rotation is a product and every formula is the same for one crank angle
(Python ``complex`` and :mod:`math`, cheap enough for a node's tick) and for
an array of crank angles (NumPy, for cycles and plots).

Every step also bounds the error of what it computes (plain sums and products
of magnitudes beside the values, see :mod:`mech_kinematics.bounds`), and
:func:`solve` refuses a state whose bounds exceed a tolerance relative to each
kind's scale, or that lies within rounding of an assembly limit. A scene far
from 1 m in size, or a crank far from 1 rad/s, is solved scaled by a power of
two and scaled back (exactly), so no product overflows or underflows.

Everything here is SI: metres, radians, seconds. Angles are counter-clockwise
from +x; angular velocities and accelerations are positive counter-clockwise.

The package holds one module per concern and one per step kind:

- :mod:`.model`: names, checks, the scene's units for messages, links;
- :mod:`.base`: the protocol every step kind follows (and the kernel subset
  of a step's ``run`` the node's tick compiles); :mod:`.registry` maps the
  scene's ``type:`` to the kind;
- :mod:`.crank`, :mod:`.actuator`, :mod:`.rrr`, :mod:`.rrp`, :mod:`.rpr`,
  :mod:`.geneva`, :mod:`.rpp`, :mod:`.carried`, :mod:`.rubbing`: the kinds, each with its item, its
  validation and its step (kernel and error bounds);
- :mod:`.context`: one solve's values and the roundoff constants;
- :mod:`.plan`: the plan compiler; :mod:`.scaling`: power-of-two rescaling;
- :mod:`.mechanism`: :class:`Scene`; :mod:`.solve`: :func:`solve`;
  :mod:`.inverse`: :func:`solve_targets` (driven from the output);
  :mod:`.state`: :class:`State` and what it holds; :mod:`.trust`: the quick
  trust test and a revolute joint's angle, below :func:`solve`;
- :mod:`.compiler`: the one compiler (``mk.solve``'s compiled paths and the
  node's tick, or the reason a scene is not compiled), over the partial
  evaluator :mod:`.specialize`.
"""

from .actuator import Actuator
from .carried import CarriedPoint
from .collar import Collar
from .context import NEAR_SINGULAR, SINGULAR
from .crank import Crank
from .fold import Fold
from .geneva import TANGENCY_TOLERANCE
from .hinge import Hinge, Motor
from .inverse import Inverse, solve_targets
from .mechanism import assembly_text, Scene
from .model import Branch, Link, SceneUnits
from .rpp import RPP
from .rpr import MAX_SLOTS, RPR
from .rrp import RRP
from .rrr import RRR
from .rubbing import Pin
from .slider import Slider
from .solve import assembly_margins, compile_now, keep_general_path, paths, solve
from .state import Engagement, JointMotion, PointState, State
from .triad import Triad

__all__ = [
    'Actuator', 'Branch', 'CarriedPoint', 'Collar', 'Crank', 'Engagement', 'Fold', 'Hinge',
    'Inverse',
    'JointMotion', 'Link', 'Motor',
    'MAX_SLOTS',
    'NEAR_SINGULAR', 'Pin', 'PointState', 'RPP', 'RPR', 'RRP', 'RRR', 'SINGULAR', 'Scene', 'State',
    'SceneUnits', 'Slider', 'Triad', 'TANGENCY_TOLERANCE', 'assembly_margins', 'assembly_text',
    'compile_now', 'keep_general_path', 'paths', 'solve', 'solve_targets',
]
