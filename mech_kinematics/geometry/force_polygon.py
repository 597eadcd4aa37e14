# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The force polygon of one body at one instant: its forces head to tail, closing.

The course draws, for each link of a mechanism in motion, the forces on it
as a free body (d'Alembert's principle): what its joints put on it, its
weight, its inertia force ``-m a_G`` at its centre of mass, and the loads;
laid head to tail they close, because the body is in (dynamic) equilibrium.
:func:`force_polygon_from_state` gathers them from a solved state with
forces (:attr:`.State.forces`): the joints' reactions and the drivers'
efforts are the solver's, with their bounds; the weight and the inertia
force are computed here from the body's own motion (its frame's origin's
acceleration and its angular velocity and acceleration), so the polygon's
closing is a check of the solver's reactions against the body's kinematics
(:attr:`ForcePolygon.closure`, with its bound).

Couples are no side of the polygon: a crank's driving torque, a prismatic
joint's moment, a Geneva lock's holding moment, the inertia couple ``-I
alpha`` and the torque loads are listed apart (:attr:`ForcePolygon.couples`);
with the forces' moments they balance too (:attr:`ForcePolygon.moment`, about
the body's frame origin).

A joint's force on the body is the reaction on it from the other body: the
reported reaction where the body is its ``on``, its opposite where it is
its ``by``; a prismatic joint's is its normal force (along the line's
direction turned +90 deg) plus, for an actuator, its effort along the line.

Pure: SI units (N, N m, m), vectors as ``ndarray`` of shape (2,).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
import math
from typing import Any

import numpy as np
import numpy.typing as npt

from ..bounds import U
from ..errors import SceneError
from ..solver import Scene

__all__ = ['BodyCouple', 'BodyForce', 'ForceKind', 'ForcePolygon', 'force_polygon_from_state',
           'moving_bodies']

Array = npt.NDArray[np.float64]


class ForceKind(Enum):
    """What a force or couple on a body is."""

    JOINT = 'joint'         # a joint's reaction from the other body
    EFFORT = 'effort'       # a driver's effort: an actuator's force, a crank's torque
    WEIGHT = 'weight'       # m g at the centre of mass
    INERTIA = 'inertia'     # -m a_G at the centre of mass; the couple -I alpha
    LOAD = 'load'           # a scene's load


@dataclass(frozen=True)
class BodyForce:
    """One force on the body.

    Attributes
    ----------
    label : str
        Short, for drawings: the joint's name, ``W``, ``-ma``, the load's name.
    kind : ForceKind
        What it is.
    text : str
        What it is, in words (``pin C, from rocker``).
    at : str or None
        The named point it acts at; None for the centre of mass.
    xy : ndarray, shape (2,)
        Where it acts, m.
    force : ndarray, shape (2,)
        N, in the scene's frame.
    bound : float
        Its error bound (a norm), N.
    """

    label: str
    kind: ForceKind
    text: str
    at: str | None
    xy: Array
    force: Array
    bound: float

    @property
    def magnitude(self) -> float:
        """|force|, N."""
        return float(math.hypot(*self.force))

    @property
    def direction(self) -> float:
        """Its direction, rad, CCW from +x; NaN for a zero force, which has none."""
        if not self.force.any():
            return math.nan
        return float(math.atan2(self.force[1], self.force[0]))


@dataclass(frozen=True)
class BodyCouple:
    """One couple on the body: ``moment`` (N m, + CCW) with its ``bound``."""

    label: str
    kind: ForceKind
    text: str
    moment: float
    bound: float


@dataclass(frozen=True)
class ForcePolygon:
    """The forces on one body at one instant, head to tail.

    The weight is left out in a scene without gravity.

    Attributes
    ----------
    scene, body : str
        The scene's and the body's names.
    forces : tuple of BodyForce
        In the polygon's order: the weight, the inertia force, the loads, then
        the joints (with the actuators' efforts) in the graph's order.
    couples : tuple of BodyCouple
        The couples on it.
    vertices : ndarray, shape (len(forces) + 1, 2)
        The polygon's corners, N: 0, then each force's head.
    closure : float
        ``|sum of the forces|``, N: the gap between the last head and the
        first tail.
    closure_bound : float
        What the forces' bounds and the sums' rounding allow it to be, N.
    moment : float
        The sum of the forces' moments about the body's frame origin and the
        couples, N m (0 in equilibrium).
    moment_bound : float
        Its bound, N m.
    origin : str
        The body's frame origin (the point moments are taken about).
    """

    scene: str
    body: str
    forces: tuple[BodyForce, ...]
    couples: tuple[BodyCouple, ...]
    vertices: Array
    closure: float
    closure_bound: float
    moment: float
    moment_bound: float
    origin: str


def moving_bodies(scene: Scene) -> tuple[str, ...]:
    """Return the names of the scene's moving bodies (links, sliders), in the graph's order."""
    graph = scene.graph
    return tuple(name for name in graph.bodies if name != graph.ground)


def _scalar(x: Any) -> float:
    return float(np.asarray(x, dtype=np.float64))


def force_polygon_from_state(scene: Scene, state: Any, body: str) -> ForcePolygon:
    """Return the force polygon of ``body`` at a solved single-instant ``state`` of ``scene``.

    Raises
    ------
    SceneError
        If ``body`` is not a moving body of the scene, or the state has no
        forces (the scene has no masses, gravity or loads).
    """
    graph = scene.graph
    moving = moving_bodies(scene)
    if body not in moving:
        got = 'the ground' if body == graph.ground else f'"{body}"'
        msg = f'Expected a moving body of {scene.name} ({", ".join(moving)}), got {got}'
        raise SceneError(msg)
    forces = state.forces
    dynamics = scene.dynamics
    if forces is None or dynamics is None:
        msg = (f'Expected a scene with masses, gravity or loads for a force polygon, got '
               f'{scene.name} without')
        raise SceneError(msg)
    points = state.complex_points
    point_bounds = state.error_bound.points

    def where(point: str) -> complex:
        return complex(np.asarray(points[point][0]))

    frame = graph.bodies[body].frame
    assert frame is not None
    origin = where(frame.origin)
    if frame.angle_of is None:
        theta, omega, alpha = frame.angle, 0.0, 0.0
        e_theta = e_omega = e_alpha = U * abs(frame.angle)
    else:
        joint = state.joints[frame.angle_of]
        bound = state.error_bound.joints[frame.angle_of]
        theta = _scalar(joint.position) + frame.angle
        omega, alpha = _scalar(joint.velocity), _scalar(joint.acceleration)
        e_theta = _scalar(bound.position) + U * abs(frame.angle)
        e_omega, e_alpha = _scalar(bound.velocity), _scalar(bound.acceleration)
    found: list[tuple[BodyForce, complex]] = []
    couples: list[BodyCouple] = []

    def add(label: str, kind: ForceKind, text: str, at: str | None, xy: complex, force: complex,
            bound: float) -> None:
        found.append((BodyForce(label, kind, text, at, np.array([xy.real, xy.imag]),
                                np.array([force.real, force.imag]), float(bound)), xy))

    mass = dynamics.masses.get(body)
    if mass is not None:
        r = complex(*mass.com) * complex(math.cos(theta), math.sin(theta))
        spin = complex(-omega * omega, alpha)
        a_g = complex(np.asarray(points[frame.origin][2])) + spin * r
        e_r = abs(r) * (e_theta + 4 * U)
        e_a = (_scalar(point_bounds[frame.origin].acceleration)
               + abs(r) * (e_alpha + 2 * abs(omega) * e_omega) + abs(spin) * e_r
               + 4 * U * abs(a_g))
        weight = mass.mass * dynamics.gravity
        centre = origin + r
        if weight:      # a scene without gravity: no weight to draw
            add('W', ForceKind.WEIGHT, f'weight m g ({mass.mass:g} kg)', None, centre, weight,
                2 * U * abs(weight))
        add('-ma', ForceKind.INERTIA, 'inertia force -m a_G', None, centre, -mass.mass * a_g,
            mass.mass * e_a + 2 * U * mass.mass * abs(a_g))
        if mass.inertia:
            couples.append(BodyCouple('-Iα', ForceKind.INERTIA, 'inertia couple -I alpha',
                                      -mass.inertia * alpha,
                                      mass.inertia * e_alpha + 2 * U * mass.inertia * abs(alpha)))
    for load in dynamics.point_loads.get(body, ()):
        if load.point is None:      # at a point of the body's frame (a URDF link's force)
            assert load.at is not None and load.force is not None
            at = origin + complex(*load.at) * complex(math.cos(theta), math.sin(theta))
            add(load.name, ForceKind.LOAD, f'load {load.name}', None, at,
                complex(*load.force), 0.0)
            continue
        if load.table is not None:  # where its joint stands at this instant
            joint = load.table[0]
            force, slope = load.force_at(_scalar(state.joints[joint].position))
            error = slope * _scalar(state.error_bound.joints[joint].position)
        else:
            assert load.force is not None
            force, error = complex(*load.force), 0.0
        add(load.name, ForceKind.LOAD, f'load {load.name}', load.point, where(load.point),
            force, error)
    for load in dynamics.torque_loads.get(body, ()):
        couples.append(BodyCouple(load.name, ForceKind.LOAD, f'load {load.name}',
                                  float(load.torque or 0.0), 0.0))
    for joint in graph.joints:
        if body not in (joint.body, joint.on):
            continue
        sign = 1.0 if joint.body == body else -1.0
        other = joint.on if sign > 0 else joint.body
        reaction = forces.reactions[joint.name]
        xy = where(joint.at)
        if reaction.force is not None:
            force = complex(np.asarray(reaction.force))
            add(joint.name, ForceKind.JOINT, f'pin {joint.at}, from {other}', joint.at, xy,
                sign * force, _scalar(reaction.force_bound))
        elif reaction.normal is not None:
            line = joint.line
            assert line is not None
            angle = line.angle + (0.0 if line.angle_of is None
                                  else _scalar(state.joints[line.angle_of].position))
            e_angle = U * abs(line.angle) + (
                0.0 if line.angle_of is None
                else _scalar(state.error_bound.joints[line.angle_of].position))
            u = complex(math.cos(angle), math.sin(angle))
            normal = _scalar(reaction.normal)
            force = normal * 1j * u
            bound = _scalar(reaction.normal_bound) + abs(normal) * (e_angle + 2 * U)
            text = f'slide {joint.name}, from {other}' if joint.name != other \
                else f'slide, from {other}'
            if joint.driver:
                effort = _scalar(forces.efforts[joint.name])
                force += effort * u
                bound += (_scalar(forces.effort_bounds[joint.name])
                          + abs(effort) * (e_angle + 2 * U))
                text += f' (its effort {effort:.4g} N along it)'
            add(joint.name, ForceKind.JOINT, text, joint.at, xy, sign * force, bound)
        if reaction.moment is not None:
            kind = 'lock' if reaction.force is None and reaction.normal is None else 'slide'
            couples.append(BodyCouple(joint.name, ForceKind.JOINT,
                                      f'{kind} {joint.name}, from {other}' if joint.name != other
                                      else f'{kind}, from {other}',
                                      sign * _scalar(reaction.moment),
                                      _scalar(reaction.moment_bound)))
        if joint.driver and joint.line is None:
            couples.append(BodyCouple(joint.name, ForceKind.EFFORT,
                                      f'driving torque of {joint.name}',
                                      sign * _scalar(forces.efforts[joint.name]),
                                      _scalar(forces.effort_bounds[joint.name])))
    order = {ForceKind.WEIGHT: 0, ForceKind.INERTIA: 1, ForceKind.LOAD: 2, ForceKind.JOINT: 3}
    found.sort(key=lambda item: order[item[0].kind])
    vectors = [complex(*f.force) for f, _ in found]
    heads = np.cumsum([0j, *vectors])
    vertices = np.stack((heads.real, heads.imag), axis=-1)
    total = complex(heads[-1])
    n = len(found)
    size = sum(abs(v) for v in vectors)
    closure_bound = sum(f.bound for f, _ in found) + 2 * n * U * size
    moment = 0.0
    moment_bound = 0.0
    terms = 0.0         # the sum of |each term|, for the rounding of the sum
    arm_bound = _scalar(point_bounds[frame.origin].position)
    for f, xy in found:
        d = xy - origin
        v = complex(*f.force)
        moment += d.real * v.imag - d.imag * v.real
        arm = abs(d)
        e_d = arm_bound + (_scalar(point_bounds[f.at].position) if f.at
                           else arm * (e_theta + 4 * U))
        moment_bound += arm * f.bound + e_d * abs(v) + 4 * U * arm * abs(v)
        terms += arm * abs(v)
    for c in couples:
        moment += c.moment
        moment_bound += c.bound
        terms += abs(c.moment)
    moment_bound += (n + len(couples) + 1) * U * terms
    return ForcePolygon(scene.name, body, tuple(f for f, _ in found), tuple(couples), vertices,
                        abs(total), float(closure_bound), float(moment), float(moment_bound),
                        frame.origin)
