# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The mechanisms the extreme suite, the error-bound suite and the tests build.

:func:`four_bar`, :func:`slider_crank` and :func:`chain_scene` return scenes
of given proportions; :func:`distance_angle` the crank angle at which a
four-bar's circles just meet (a toggle). mpmath is imported inside the
function that needs it.
"""

from __future__ import annotations

import math
from typing import Any

from ..solver import Branch, CarriedPoint, Crank, Link, RRP, RRR, Scene
from ..units import radians_from_degrees

__all__ = ['chain_scene', 'distance_angle', 'four_bar', 'slider_crank']


def four_bar(name: str, a: float, b: float, c: float, d: float, angle: float = 0.0,
             branch: int = 1, speed: float = -4 * math.pi, scale: float = 1.0) -> Scene:
    """Return a four-bar: crank AB = a about A = 0, coupler BC = b, rocker DC = c, D = (d, 0).

    Every length is multiplied by ``scale``; the coupler carries a point E at
    (0.5 b, 0.3 b) in its frame. ``angle`` (rad) and ``speed`` (rad/s) are
    the crank's.
    """
    links = (Link('coupler', 'B', b * scale), Link('rocker', 'D', c * scale))
    crank = Crank('crank', 'A', 'B', a * scale, angle, speed, 0.0)
    return Scene(name, {'A': (0.0, 0.0), 'D': (d * scale, 0.0)}, crank,
                 (RRR('C', links, Branch(branch)),),
                 (CarriedPoint('E', 'coupler', 'B', 'C', (0.5 * b * scale, 0.3 * b * scale)),))


def slider_crank(name: str, crank_length: float, rod: float, offset: float = 0.0,
                 angle: float = 0.0, speed: float = 10 * math.pi) -> Scene:
    """Return a slider-crank: crank OB about O = 0, rod BP, piston P on the line y = ``offset``.

    The guide runs along +x (branch PLUS: the piston on the +x side); the rod
    carries its midpoint M. Lengths in m, ``angle`` in rad, ``speed`` in rad/s.
    """
    crank = Crank('crank', 'O', 'B', crank_length, angle, speed, 0.0)
    dyad = RRP('P', Link('rod', 'B', rod), 'E', 0.0, 'piston', Branch.PLUS)
    return Scene(name, {'O': (0.0, 0.0), 'E': (0.0, offset)}, crank, (dyad,),
                 (CarriedPoint('M', 'rod', 'B', 'P', (0.5 * rod, 0.0)),))


def distance_angle(a: float, d: float, distance: float) -> Any:
    """Return the crank angle (mpmath, 60 digits) at which the tip is ``distance`` from (d, 0).

    For a crank of length ``a`` about the origin: the position where the
    circles of a four-bar with ``b + c`` (or ``|b - c|``) equal to
    ``distance`` just meet, a toggle.
    """
    import mpmath
    with mpmath.workdps(60):
        a_, d_, r = (mpmath.mpf(x) for x in (a, d, distance))
        return mpmath.acos((a_ * a_ + d_ * d_ - r * r) / (2 * a_ * d_))


def chain_scene(stages: int) -> Scene:
    """Return a chain of ``stages`` four-bar stages, each driven by the previous rocker.

    Stage k is the Grashof crank-rocker of ``khurmi_four_bar_ad150`` (input
    40, coupler 150, rocker 80, ground 150 mm): its input is the point carried
    40 mm along the previous rocker from its pivot, so every stage assembles
    at every crank angle, on either branch. One RRR dyad and one carried
    point per stage.
    """
    if stages < 1:
        msg = f'Expected at least 1 stage, got {stages}'
        raise ValueError(msg)
    a, b, c, d = 0.04, 0.15, 0.08, 0.15
    ground = {f'G{k}': (k * d, 0.0) for k in range(stages + 1)}
    dyads = []
    points = []
    for k in range(1, stages + 1):
        dyads.append(RRR(f'C{k}', (Link(f'coupler{k}', f'P{k - 1}', b),
                                   Link(f'rocker{k}', f'G{k}', c)), Branch.PLUS))
        if k < stages:
            points.append(CarriedPoint(f'P{k}', f'rocker{k}', f'G{k}', f'C{k}', (a, 0.0)))
    crank = Crank('crank', 'G0', 'P0', a, radians_from_degrees(60.0), -4 * math.pi, 0.0)
    return Scene(f'chain_{stages}', ground, crank, tuple(dyads), tuple(points))
