# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A 50-digit reference for any scene, computed without the solver's closed forms.

The scene is written as its loop-closure constraints ``Phi(q, theta) = 0``,
two real equations per dyad in two unknowns (RRR: the angles of both links;
RRP: the link angle and the slider coordinate; RPR: the lever angle and the
slider coordinate; RPP: the yoke's and the pin's slider coordinates), with the
points carried by links as explicit functions of the points that define their
link's frame, and each driver placing what its position moves (a crank's
tip, an actuator's link lengths). Nothing here uses the solver's formulas:

positions
    a textbook construction (law of cosines, circle and line) gives a start,
    then Newton-Raphson on the whole constraint system at :data:`DPS` digits
    brings the residual below ``10**-(DPS - 6)`` of the mechanism's size; the
    assembly branch is then checked against its definition in docs/scene_format.md;
velocities and accelerations
    from the differentiated constraint equations, ``J qdot = -Phi_t`` and
    ``J qddot = -(d/dt)^2 Phi`` at ``qddot = 0``, two linear systems solved in
    mpmath; the derivatives are taken by forward-mode Taylor arithmetic
    (:class:`Jet`), not by hand.

Each kind's equations are a model of their own, looked up by the kind in
:data:`MODELS` (every kind of the solver's registry, the carried point, the
Geneva wheel's RPR) and :data:`DRIVER_MODELS` (every driver): a scene holding
a kind with no model is refused, naming it (:class:`NoReferenceModel`),
never solved as another kind. Each model also says which scene values its
equations read, lengths or angles, and where a scene file writes them
(:class:`Parameter`), which is how :func:`decimal_values` reads every one as
the decimal written. What is structure, not equations (the type of each
output joint, the links an actuator drives, which items are intermittent), is
read from the scene's graph of bodies and joints.

A second route, :func:`check_by_differences`, differentiates 50-digit
positions in time with five-point central differences and must agree with the
first to about 1e-30.

Inputs are taken as the exact binary values of the scene's doubles, so the
difference between the solver and the reference is the solver's own rounding
error. The :class:`Jet` arithmetic and :meth:`Model.evaluate` work on mpmath
numbers and on NumPy arrays alike; the report reuses them in double precision
for its Newton-Raphson and ODE baselines.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
import cmath
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
import math
import os
from pathlib import Path
import re
from typing import Any

import mpmath
import numpy as np
import yaml

from ..errors import SceneError
from ..scene import read_scene_yaml
from ..solver import (Actuator, CarriedPoint, Collar, Crank, Fold, Hinge, Motor, RPP, RPR, RRP,
                      RRR, Scene, Slider, Triad)
from ..solver.graph import Fragment, joint_type, JointType
from ..units import ANGLE_UNITS, LENGTH_UNITS, radians_from_degrees

__all__ = ['DIGITS', 'DPS', 'DRIVER_MODELS', 'INTERMITTENT', 'Jet', 'MODELS', 'Model',
           'NoAssembly', 'NoReferenceModel', 'Parameter', 'Reference', 'as_float_dict',
           'check_by_differences', 'compare', 'condition', 'decimal_values', 'model_key',
           'reference', 'value_errors']

#: Digits the reference values are good to.
DIGITS = 50
#: Working precision, decimal digits.
DPS = 64
#: Crank turn per step of the finite-difference check, rad.
FD_STEP_ANGLE = mpmath.mpf('1e-12')
#: Below this exact near-singularity measure a pose is treated as singular:
#: positions exist, velocities do not (the Jacobian is rank deficient).
SINGULAR_MEASURE = mpmath.mpf('1e-30')
#: Digits of the construction that starts Newton-Raphson.
SEED_DPS = 20

KINDS = ('position', 'angle', 'velocity', 'angular velocity', 'acceleration',
         'angular acceleration')


class NoAssembly(ValueError):
    """The mechanism has no real configuration at this crank angle."""


@contextmanager
def _precision(dps: int = DPS) -> Iterator[None]:
    with mpmath.workdps(dps):
        yield


# --- truncated Taylor series -------------------------------------------------


def _is_mp(x: Any) -> bool:
    return isinstance(x, (mpmath.mpf, mpmath.mpc))


def _sqrt(x: Any) -> Any:
    if isinstance(x, Jet):
        return x.sqrt()
    if _is_mp(x):
        return mpmath.sqrt(x)
    return np.sqrt(x)


def expi(x: Any) -> Any:
    """Return ``exp(i x)`` for a real ``x``: an mpf, a float, an array or a :class:`Jet`."""
    if isinstance(x, Jet):
        return x.expi()
    if _is_mp(x):
        return mpmath.expj(x)
    if isinstance(x, np.ndarray):
        out = np.empty(x.shape, dtype=np.complex128)
        np.cos(x, out=out.real)
        np.sin(x, out=out.imag)
        return out
    return cmath.exp(1j * x)


def norm(z: Any) -> Any:
    """Return ``|z|`` for a complex value or a complex :class:`Jet`."""
    if isinstance(z, Jet):
        re, im = z.real, z.imag
        return (re * re + im * im).sqrt()
    return abs(z)


class Jet:
    """A truncated Taylor series ``c0 + c1 t + c2 t**2`` in time (forward-mode derivatives).

    The coefficients may be mpmath numbers, Python numbers or NumPy arrays
    (never mixed). Arithmetic drops terms of order ``t**3``, so evaluating a
    function on ``Jet(x, xdot, xddot / 2)`` gives its value, its first
    derivative and half its second.
    """

    __slots__ = ('c0', 'c1', 'c2')
    #: Make NumPy arrays defer to the reflected operators instead of building
    #: object arrays of jets.
    __array_ufunc__ = None

    def __init__(self, c0: Any, c1: Any = 0, c2: Any = 0) -> None:
        self.c0, self.c1, self.c2 = c0, c1, c2

    def __repr__(self) -> str:
        """Show the coefficients."""
        return f'Jet({self.c0!r}, {self.c1!r}, {self.c2!r})'

    def __add__(self, other: Any) -> Jet:
        if isinstance(other, Jet):
            return Jet(self.c0 + other.c0, self.c1 + other.c1, self.c2 + other.c2)
        return Jet(self.c0 + other, self.c1, self.c2)

    __radd__ = __add__

    def __neg__(self) -> Jet:
        return Jet(-self.c0, -self.c1, -self.c2)

    def __sub__(self, other: Any) -> Jet:
        if isinstance(other, Jet):
            return Jet(self.c0 - other.c0, self.c1 - other.c1, self.c2 - other.c2)
        return Jet(self.c0 - other, self.c1, self.c2)

    def __rsub__(self, other: Any) -> Jet:
        return Jet(other - self.c0, -self.c1, -self.c2)

    def __mul__(self, other: Any) -> Jet:
        if isinstance(other, Jet):
            a0, a1, a2 = self.c0, self.c1, self.c2
            b0, b1, b2 = other.c0, other.c1, other.c2
            return Jet(a0 * b0, a0 * b1 + a1 * b0, a0 * b2 + a1 * b1 + a2 * b0)
        return Jet(self.c0 * other, self.c1 * other, self.c2 * other)

    __rmul__ = __mul__

    def __truediv__(self, other: Any) -> Jet:
        if not isinstance(other, Jet):
            inv = 1 / other
            return Jet(self.c0 * inv, self.c1 * inv, self.c2 * inv)
        b0, b1, b2 = other.c0, other.c1, other.c2
        q0 = self.c0 / b0
        q1 = (self.c1 - q0 * b1) / b0
        q2 = (self.c2 - q0 * b2 - q1 * b1) / b0
        return Jet(q0, q1, q2)

    def __rtruediv__(self, other: Any) -> Jet:
        return Jet(other) / self

    @property
    def real(self) -> Jet:
        """Real part, coefficient by coefficient."""
        return Jet(*(_part(c, 'real') for c in (self.c0, self.c1, self.c2)))

    @property
    def imag(self) -> Jet:
        """Imaginary part, coefficient by coefficient."""
        return Jet(*(_part(c, 'imag') for c in (self.c0, self.c1, self.c2)))

    def expi(self) -> Jet:
        """Return ``exp(i self)`` for a real jet."""
        e0 = expi(self.c0)
        x1, x2 = self.c1, self.c2
        return Jet(e0, e0 * (1j * x1), e0 * (1j * x2 - x1 * x1 / 2))

    def sqrt(self) -> Jet:
        """Return the square root of a positive real jet."""
        s0 = _sqrt(self.c0)
        s1 = self.c1 / (2 * s0)
        return Jet(s0, s1, (self.c2 - s1 * s1) / (2 * s0))

    def derivatives(self) -> tuple[Any, Any, Any]:
        """Return value, first and second derivative."""
        return self.c0, self.c1, 2 * self.c2


def _part(c: Any, which: str) -> Any:
    if isinstance(c, int):
        return c if which == 'real' else 0
    return getattr(c, which)


def _value(x: Any) -> Any:
    return x.c0 if isinstance(x, Jet) else x


# --- the constraint model ------------------------------------------------------


class NoReferenceModel(TypeError):
    """A scene holds a kind of item or driver the reference has no equations for."""


@dataclass(frozen=True)
class Parameter:
    """A number of the scene that a kind's equations read.

    Attributes
    ----------
    key : str
        Its key in :attr:`Model.values` (``link.coupler.length``,
        ``guide.P.angle``, ``point.E.local.x``, ...).
    value : float
        The scene's double: m for a length, rad for an angle.
    angle : bool
        Whether it is an angle (written in the scene's angle unit), else a
        length (written in its length unit).
    paths : tuple of tuple
        Where its number may be written in a scene file, as keys and list
        indices (``('dyads', 0, 'links', 1, 'length')``): the first present
        is read (a kind's model gives them within its item's entry, the
        :class:`Model` prefixes the entry's own path).
    default : int or None
        Its value where none of ``paths`` is written (a guide's angle: 0);
        ``None`` where one must be.
    """

    key: str
    value: float
    angle: bool
    paths: tuple[tuple[str | int, ...], ...]
    default: int | None = None

    def within(self, entry: tuple[str | int, ...]) -> Parameter:
        """Return it with each path prefixed by its entry's path in the scene file."""
        return replace(self, paths=tuple((*entry, *path) for path in self.paths))


def _length(key: str, value: float, *paths: tuple[str | int, ...],
            default: int | None = None) -> Parameter:
    return Parameter(key, value, False, paths, default)


def _angle(key: str, value: float, *paths: tuple[str | int, ...],
           default: int | None = None) -> Parameter:
    return Parameter(key, value, True, paths, default)


#: What marks the key of an item whose fragment has an intermittent joint (a Geneva wheel's
#: RPR): its equations are looked up apart from its kind's (:func:`model_key`).
INTERMITTENT = ' (intermittent)'


def model_key(kind: str, fragment: Fragment) -> str:
    """Return the key of an item's equations in :data:`MODELS`.

    Its kind (the scene's ``type:``, ``point`` for a carried point), marked
    :data:`INTERMITTENT` where its part of the mechanism's graph has an
    intermittent joint: a variant that moves otherwise (a Geneva wheel's RPR,
    or any such variant a kind may grow) is never taken for its base kind.
    """
    return kind + INTERMITTENT if any(joint.intermittent for joint in fragment.joints) else kind


def _equations(key: str) -> _Equations:
    try:
        return MODELS[key]
    except KeyError:
        msg = (f'Expected a kind of scene item the reference has equations for '
               f'({", ".join(MODELS)}), got {key!r}')
        raise NoReferenceModel(msg) from None


def _driver_equations(key: str) -> _DriverEquations:
    try:
        return DRIVER_MODELS[key]
    except KeyError:
        msg = (f'Expected a kind of driver the reference has equations for '
               f'({", ".join(DRIVER_MODELS)}), got {key!r}')
        raise NoReferenceModel(msg) from None


@dataclass(frozen=True)
class _Element:
    equations: _Equations  # its kind's (MODELS)
    item: Any              # the scene's dyad or carried point
    index: int = -1        # first of the element's unknowns, -1 where it has none

    @property
    def label(self) -> str:
        """Return the item as messages name it, e.g. ``'RRR C'``."""
        return f'{self.item.kind} {self.item.key}'


class Model:
    """The loop-closure constraints of a scene, generic over its drivers, dyads and points.

    Each driver's, dyad's and carried point's equations are its kind's model
    (:data:`DRIVER_MODELS`, :data:`MODELS`), looked up by its kind: a kind
    with none is refused (:class:`NoReferenceModel`), never solved as
    another. What is structure rather than equations is read from the
    scene's graph (:attr:`~mech_kinematics.solver.Scene.graph`): the type of
    every output joint, the links an actuator drives, which items are
    intermittent variants.

    Parameters
    ----------
    scene : Scene
        Any scene; its outputs selection is ignored (everything is computed).

    Attributes
    ----------
    values : dict of str to float
        Every numeric input of the geometry, by name (``ground.A.x``,
        ``crank.length``, ``link.coupler.length``, ``guide.P.angle``,
        ``point.E.local.x``, ...), as the scene's doubles.
    parameters : dict of str to Parameter
        The same, each with whether it is a length or an angle and where a
        scene file writes it (:func:`decimal_values`).
    size : float
        The mechanism's size, m, defined as the solver defines it (the largest
        crank, link or ground distance): the RPR near-singularity measure is
        the slider coordinate over it.

    Raises
    ------
    NoReferenceModel
        Naming a kind of the scene that has no equations here.
    """

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        graph = scene.graph
        self.graph = graph
        drivers = scene.drivers
        items: list[Any] = [*scene.dyads, *scene.points]
        fragments = graph.fragments[len(drivers):]
        equations = [_equations(model_key(item.kind, fragment))
                     for item, fragment in zip(items, fragments, strict=True)]
        driver_equations = [_driver_equations(driver.scene_key) for driver in drivers]
        #: One crank (the v1 scene): ``theta`` is its angle; else a sequence, one per driver.
        self.single = scene.single_crank
        self.values: dict[str, float] = {}
        self.parameters: dict[str, Parameter] = {}
        for name, (x, y) in scene.ground.items():
            self._parameter(_length(f'ground.{name}.x', float(x), (0,)), ('ground', name))
            self._parameter(_length(f'ground.{name}.y', float(y), (1,)), ('ground', name))
        self.links: dict[str, Any] = {}   # angle coordinate -> unknown index, None for a crank's
        self.sliders: dict[str, int] = {}  # length coordinate -> unknown index
        self.joint_types: dict[str, JointType] = {}
        #: Per actuator, the links whose length is its length.
        self.actuated: dict[str, list[str]] = {}
        #: Per motor, the two points of its parent's axis; per hinge link, (parent, motor):
        #: its angle is the parent's plus the motor's.
        self.axes: dict[str, tuple[str, str]] = {}
        self.derived: dict[str, tuple[str, str]] = {}
        known = set(scene.ground)
        self.drivers = tuple(zip(drivers, driver_equations, strict=True))
        for k, (driver, moves) in enumerate(self.drivers):
            entry: tuple[str | int, ...] = ('inputs', k) if scene.inputs else ('input',)
            for parameter in moves.parameters(self, driver):
                self._parameter(parameter, entry)
            self.joint_types[driver.name] = graph.coordinates[driver.name]
            moves.place(self, driver, known)
        self.unknown_names: list[str] = []
        self.unknown_is_length: list[bool] = []
        #: The points of the last :meth:`construct` stopped before an element (``upto``).
        self.partial: dict[str, Any] = {}
        entries = [('dyads', k) for k in range(len(scene.dyads))] + [
            ('points', point.name) for point in scene.points]
        pending = list(zip(items, equations, entries, strict=True))
        elements: list[_Element] = []
        while pending:
            for position, (item, kind, entry) in enumerate(pending):
                if kind.ready(self, item, known):
                    elements.append(self._place(item, kind, entry, known))
                    del pending[position]
                    break
            else:
                left = [entry[0] for entry in pending]
                msg = f'Expected the scene to be solvable in order, got {left!r}'
                raise ValueError(msg)
        self.elements = tuple(elements)
        lengths = [driver.reach for driver in drivers] + [
            v for k, v in self.values.items() if k.startswith('link.') and k.endswith('.length')]
        ground = [complex(x, y) for x, y in scene.ground.values()]
        self.size = max(lengths + [abs(a - b) for a in ground for b in ground])

    def _parameter(self, parameter: Parameter, entry: tuple[str | int, ...]) -> None:
        self.values[parameter.key] = parameter.value
        self.parameters[parameter.key] = parameter.within(entry)

    def _place(self, item: Any, model: _Equations, entry: tuple[str | int, ...],
               known: set[str]) -> _Element:
        """Record a ready item's parameters and unknowns (their types from the graph)."""
        for parameter in model.parameters(item):
            self._parameter(parameter, entry)
        index = len(self.unknown_names)
        unknowns = model.unknowns(item)
        for offset, name in enumerate(unknowns):
            kind = self.graph.coordinates[name]
            self.joint_types[name] = kind
            if kind.angular:
                self.links[name] = index + offset
                self._unknowns((f'{name} angle', False))
            else:
                self.sliders[name] = index + offset
                self._unknowns((name, True))
        known.update(model.new_points(item))
        return _Element(model, item, index if unknowns else -1)

    def placed(self, link: str) -> bool:
        """Return whether ``link``'s angle is known: a crank's, an unknown's or a hinge's."""
        return link in self.links or link in self.derived

    def crank_key(self, name: str) -> str:
        """Return the key of crank ``name``'s length in :attr:`values`."""
        return 'crank.length' if self.single else f'crank.{name}.length'

    def driven(self, p: Mapping[str, Any],
               theta: Any) -> tuple[Mapping[str, Any], dict[str, Any]]:
        """Return the parameters with every actuated link's length, and the cranks' tips.

        ``theta`` is the crank angle of a 1-crank scene, else one value per
        driver (a crank's angle, an actuator's length): numbers or jets.
        """
        scene = self.scene
        points: dict[str, Any] = {name: p[f'ground.{name}.x'] + 1j * p[f'ground.{name}.y']
                                  for name in scene.ground}
        values = (theta,) if self.single else tuple(theta) if isinstance(
            theta, (list, tuple)) else (theta,)
        lengths: dict[str, Any] = {}
        for (driver, model), value in zip(self.drivers, values, strict=True):
            model.drive(self, driver, p, value, points, lengths)
        return ({**p, **lengths} if lengths else p), points

    def _unknowns(self, *names: tuple[str, bool]) -> None:
        for name, is_length in names:
            self.unknown_names.append(name)
            self.unknown_is_length.append(is_length)

    @property
    def n(self) -> int:
        """Number of unknowns (and of real constraint equations)."""
        return len(self.unknown_names)

    def mp_values(self) -> dict[str, Any]:
        """Return :attr:`values` as exact mpmath numbers."""
        return {key: mpmath.mpf(value) for key, value in self.values.items()}

    def evaluate(self, p: Mapping[str, Any], q: list[Any],
                 theta: Any) -> tuple[dict[str, Any], list[Any]]:
        """Return every point's position and the complex residuals ``Phi``, one per dyad.

        ``p`` are the parameters (:attr:`values` or :meth:`mp_values`), ``q``
        the unknowns and ``theta`` the crank angle: numbers, arrays or jets.
        """
        p, points = self.driven(p, theta)
        residuals: list[Any] = []
        for element in self.elements:
            element.equations.evaluate(element.item, element.index, p, q, points, residuals)
        return points, residuals

    def construct(self, p: Mapping[str, Any], theta: Any, upto: int | None = None) -> list[Any]:
        """Return a first estimate of the unknowns by textbook constructions (mpmath).

        Law of cosines for RRR, circle and line for RRP, the pin's polar
        coordinates for RPR, two lines crossing for RPP, the branch taken
        from its definition.

        Raises
        ------
        NoAssembly
            Where circles do not meet or a guide is out of reach.
        """
        p, pts = self.driven(p, theta)
        pts = {name: mpmath.mpc(z) for name, z in pts.items()}
        q: list[Any] = [None] * self.n
        tiny = mpmath.mpf(10) ** (-(mpmath.mp.dps - 8))
        for element in self.elements[:upto]:
            element.equations.prepare(self, element.item, theta, pts)
            element.equations.construct(element.item, element.index, p, q, pts, tiny)
        if upto is not None:
            self.partial = pts
        return q

    def jacobian_columns(self, p: Mapping[str, Any], q: list[Any], theta: Any) -> list[list[Any]]:
        """Return ``d Phi / d q_j`` for every j, each as a list of complex residual derivatives."""
        columns = []
        for j in range(self.n):
            seeded = list(q)
            seeded[j] = Jet(q[j], 1)
            _, res = self.evaluate(p, seeded, theta)
            columns.append([r.c1 if isinstance(r, Jet) else 0 * _value(r) for r in res])
        return columns


# --- each driver's equations -----------------------------------------------------


class _DriverEquations(ABC):
    """One kind of driver as the constraints see it: what it moves, given its position.

    ``parameters`` names the scene values it reads; ``place`` records what
    its position makes known; ``drive`` puts, for a position (number or jet),
    the points it places and the link lengths it sets; ``floors`` gives, for
    its speed and acceleration, the scales below which no error is measured
    (:func:`scales`).
    """

    @staticmethod
    @abstractmethod
    def parameters(model: Model, driver: Any) -> tuple[Parameter, ...]:
        """Return the scene values it reads, each where its entry writes it."""

    @staticmethod
    @abstractmethod
    def place(model: Model, driver: Any, known: set[str]) -> None:
        """Record in ``model`` what its position makes known."""

    @staticmethod
    @abstractmethod
    def drive(model: Model, driver: Any, p: Mapping[str, Any], value: Any,
              points: dict[str, Any], lengths: dict[str, Any]) -> None:
        """Put the points it places and the link lengths it sets at position ``value``."""

    @staticmethod
    @abstractmethod
    def floors(model: Model, driver: Any, p: Mapping[str, Any], speed: Any,
               accel: Any) -> dict[str, Any]:
        """Return, per kind of value, the least scale it sets (``|speed|``, ``|accel|``)."""


class _Crank(_DriverEquations):
    """A crank of fixed length turning about a ground point: its tip."""

    @staticmethod
    def parameters(model: Model, driver: Any) -> tuple[Parameter, ...]:
        """Return its length."""
        return (_length(model.crank_key(driver.name), driver.length, ('length',)),)

    @staticmethod
    def place(model: Model, driver: Any, known: set[str]) -> None:
        """Its angle is given (no unknown); its tip is known."""
        model.links[driver.name] = None
        known.add(driver.point)

    @staticmethod
    def drive(model: Model, driver: Any, p: Mapping[str, Any], value: Any,
              points: dict[str, Any], lengths: dict[str, Any]) -> None:
        """Put its tip at its angle."""
        tip = p[model.crank_key(driver.name)] * expi(value)
        points[driver.point] = points[driver.center] + tip

    @staticmethod
    def floors(model: Model, driver: Any, p: Mapping[str, Any], speed: Any,
               accel: Any) -> dict[str, Any]:
        """Its length ``a`` for positions, ``a |omega|``, ``a (omega**2 + |alpha|)``, ..."""
        a = abs(p[model.crank_key(driver.name)])
        return {'position': a, 'velocity': a * speed, 'angular velocity': speed,
                'acceleration': a * (speed * speed + accel),
                'angular acceleration': speed * speed + accel}


class _Actuator(_DriverEquations):
    """A linear actuator: its position is the length of the links it drives."""

    @staticmethod
    def parameters(model: Model, driver: Any) -> tuple[Parameter, ...]:
        """Return none: its length is its position."""
        return ()

    @staticmethod
    def place(model: Model, driver: Any, known: set[str]) -> None:
        """Record the links it drives: the barrels its rod slides along (the graph's cylinders)."""
        model.actuated[driver.name] = [joint.on for joint in model.graph.cylinders()
                                       if joint.body == driver.name]

    @staticmethod
    def drive(model: Model, driver: Any, p: Mapping[str, Any], value: Any,
              points: dict[str, Any], lengths: dict[str, Any]) -> None:
        """Set each driven link's length to its position, and its own value (a collar's)."""
        for link in model.actuated[driver.name]:
            lengths[f'link.{link}.length'] = value
        lengths[f'actuator.{driver.name}'] = value

    @staticmethod
    def floors(model: Model, driver: Any, p: Mapping[str, Any], speed: Any,
               accel: Any) -> dict[str, Any]:
        """Its rates ``|v|`` and ``|a|``."""
        return {'velocity': speed, 'acceleration': accel}


class _Slider(_DriverEquations):
    """A block on a fixed guide: its pin at its position along the guide."""

    @staticmethod
    def parameters(model: Model, driver: Any) -> tuple[Parameter, ...]:
        """Return the guide's angle (0 where not written)."""
        return (_angle(f'slider.{driver.name}.angle', driver.guide_angle, ('guide', 'angle'),
                       default=0),)

    @staticmethod
    def place(model: Model, driver: Any, known: set[str]) -> None:
        """Its position is given (no unknown); its pin is known."""
        known.add(driver.point)

    @staticmethod
    def drive(model: Model, driver: Any, p: Mapping[str, Any], value: Any,
              points: dict[str, Any], lengths: dict[str, Any]) -> None:
        """Put its pin at its position along the guide."""
        points[driver.point] = (points[driver.through]
                                + value * expi(p[f'slider.{driver.name}.angle']))

    @staticmethod
    def floors(model: Model, driver: Any, p: Mapping[str, Any], speed: Any,
               accel: Any) -> dict[str, Any]:
        """Its rates ``|v|`` and ``|a|``."""
        return {'velocity': speed, 'acceleration': accel}


class _Motor(_DriverEquations):
    """A motor between two moving links: the relative angle of the hinge it turns."""

    @staticmethod
    def parameters(model: Model, driver: Any) -> tuple[Parameter, ...]:
        """Return none: its angle is its position."""
        return ()

    @staticmethod
    def place(model: Model, driver: Any, known: set[str]) -> None:
        """Record the parent's axis (two of its points) its angle is measured from."""
        joint = next(j for j in model.graph.joints if j.driver and j.name == driver.name)
        body = model.graph.bodies[joint.on]
        origin = body.frame.origin  # type: ignore[union-attr]
        model.axes[driver.name] = (origin, next(p for p in body.points if p != origin))

    @staticmethod
    def drive(model: Model, driver: Any, p: Mapping[str, Any], value: Any,
              points: dict[str, Any], lengths: dict[str, Any]) -> None:
        """Give its hinge its angle and the parent's axis."""
        lengths[f'motor.{driver.name}'] = value
        lengths[f'motor.{driver.name}.axis'] = model.axes[driver.name]

    @staticmethod
    def floors(model: Model, driver: Any, p: Mapping[str, Any], speed: Any,
               accel: Any) -> dict[str, Any]:
        """Its rates ``|omega|`` and ``|alpha|``."""
        return {'angular velocity': speed, 'angular acceleration': accel}


# --- each kind's constraint equations ------------------------------------------------


class _Equations(ABC):
    """One kind's loop-closure equations, written here, apart from the solver's forms.

    ``parameters`` names the scene values they read (lengths and angles, and
    where its entry writes each); ``ready`` says whether what the item starts
    from is known; ``unknowns`` names its coordinates solved for (output
    joints of the graph, whose types say angle or length) and
    ``new_points`` the points it places; ``evaluate`` appends its complex
    residual and puts its new point; ``construct`` estimates its unknowns by
    a textbook construction (mpmath); ``measure`` gives its near-singularity
    measure as the solver defines it; ``branch_ok`` checks the assembly
    branch against its definition in the scene format. Every method is
    abstract: a model that leaves one out cannot be built.
    """

    @staticmethod
    @abstractmethod
    def parameters(item: Any) -> tuple[Parameter, ...]:
        """Return the scene values its equations read, each where its entry writes it."""

    @staticmethod
    @abstractmethod
    def ready(model: Model, item: Any, known: set[str]) -> bool:
        """Return whether what the item starts from is known (``known`` points, placed links)."""

    @staticmethod
    @abstractmethod
    def unknowns(item: Any) -> tuple[str, ...]:
        """Return the coordinates it solves for, in the order of its unknowns."""

    @staticmethod
    @abstractmethod
    def new_points(item: Any) -> tuple[str, ...]:
        """Return the points it places."""

    @staticmethod
    @abstractmethod
    def evaluate(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                 points: dict[str, Any], residuals: list[Any]) -> None:
        """Append the item's residual (numbers, arrays or jets) and put its new point."""

    @staticmethod
    @abstractmethod
    def construct(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                  pts: dict[str, Any], tiny: Any) -> None:
        """Estimate the item's unknowns into ``q`` and put its new point (mpmath)."""

    @staticmethod
    @abstractmethod
    def measure(model: Model, item: Any, i: int, p: Mapping[str, Any],
                points: Mapping[str, Any], q: list[Any], measures: dict[str, Any]) -> None:
        """Put the item's near-singularity measure, if it has one."""

    @staticmethod
    @abstractmethod
    def prepare(model: Model, item: Any, theta: Any, pts: dict[str, Any]) -> None:
        """Put in ``pts`` what its construction reads of the whole model (most: nothing)."""

    @staticmethod
    @abstractmethod
    def branch_ok(item: Any, i: int, p: Mapping[str, Any], points: Mapping[str, Any],
                  q: list[Any]) -> bool:
        """Return whether the item is on its assembly branch."""


class _RRR(_Equations):
    """Two links from known points meeting at the new pin: unknowns, the two link angles.

    A link whose ``actuator`` is a driver has that driver's position as its
    length (:meth:`Model.driven`): no length of its own.
    """

    @staticmethod
    def parameters(item: Any) -> tuple[Parameter, ...]:
        """Return the length of each link of fixed length."""
        return tuple(_length(f'link.{link.name}.length', link.length, ('links', k, 'length'))
                     for k, (link, actuator) in enumerate(zip(item.links, item.actuators,
                                                              strict=True))
                     if actuator is None)

    @staticmethod
    def ready(model: Model, item: Any, known: set[str]) -> bool:
        """Return whether both links' starts are known."""
        first, second = item.links
        return first.start in known and second.start in known

    @staticmethod
    def unknowns(item: Any) -> tuple[str, ...]:
        """Return both links (their angles)."""
        first, second = item.links
        return first.name, second.name

    @staticmethod
    def new_points(item: Any) -> tuple[str, ...]:
        """Return the pin."""
        return (item.point,)

    @staticmethod
    def evaluate(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                 points: dict[str, Any], residuals: list[Any]) -> None:
        """Each link's end: the two must meet."""
        first, second = item.links
        at = points[first.start] + p[f'link.{first.name}.length'] * expi(q[i])
        other = points[second.start] + p[f'link.{second.name}.length'] * expi(q[i + 1])
        residuals.append(at - other)
        points[item.point] = at

    @staticmethod
    def construct(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                  pts: dict[str, Any], tiny: Any) -> None:
        """Solve by the law of cosines, the branch from its definition."""
        first, second = item.links
        q[i], at = _RRR.cosines(item, pts, p[f'link.{first.name}.length'],
                                p[f'link.{second.name}.length'], tiny, f'RRR {item.point}')
        q[i + 1] = mpmath.arg(at - pts[second.start])
        pts[item.point] = at

    @staticmethod
    def cosines(item: Any, pts: Mapping[str, Any], l1: Any, l2: Any, tiny: Any,
                label: str) -> tuple[Any, Any]:
        """Return the first link's angle and end where circles of ``l1``, ``l2`` meet (mpmath).

        About the two links' starts, by the law of cosines, on the side of the
        line between them that ``item.branch`` names; refused (NoAssembly) where
        they do not meet.
        """
        first, second = item.links
        d = pts[second.start] - pts[first.start]
        dist = abs(d)
        cos_gamma = (l1 * l1 + dist * dist - l2 * l2) / (2 * l1 * dist)
        if abs(cos_gamma) > 1 + tiny:
            msg = f'{label}: the circles do not meet'
            raise NoAssembly(msg)
        angle = mpmath.arg(d) + int(item.branch) * mpmath.acos(max(-1, min(1, cos_gamma)))
        return angle, pts[first.start] + l1 * mpmath.expj(angle)

    @staticmethod
    def measure(model: Model, item: Any, i: int, p: Mapping[str, Any],
                points: Mapping[str, Any], q: list[Any], measures: dict[str, Any]) -> None:
        """Put the sine of the angle between the links."""
        first, second = item.links
        r1 = points[item.point] - points[first.start]
        r2 = points[item.point] - points[second.start]
        cross = (mpmath.conj(r1) * r2).imag
        measures[item.point] = abs(cross) / (p[f'link.{first.name}.length']
                                             * p[f'link.{second.name}.length'])

    @staticmethod
    def prepare(model: Model, item: Any, theta: Any, pts: dict[str, Any]) -> None:
        """Put nothing: its construction reads only its own starts."""

    @staticmethod
    def branch_ok(item: Any, i: int, p: Mapping[str, Any], points: Mapping[str, Any],
                  q: list[Any]) -> bool:
        """Check the pin is on the side of the line between the starts the branch names."""
        first, second = item.links
        d = points[second.start] - points[first.start]
        side = (mpmath.conj(d) * (points[item.point] - points[first.start])).imag
        return bool(side * int(item.branch) >= 0)


class _RRP(_Equations):
    """A link from a known point ending on a fixed guide: unknowns, its angle and the slider."""

    @staticmethod
    def parameters(item: Any) -> tuple[Parameter, ...]:
        """Return the link's length and the guide's angle (0 where not written)."""
        return (_length(f'link.{item.link.name}.length', item.link.length, ('link', 'length')),
                _angle(f'guide.{item.point}.angle', item.guide_angle, ('guide', 'angle'),
                       default=0))

    @staticmethod
    def ready(model: Model, item: Any, known: set[str]) -> bool:
        """Return whether the link's start is known."""
        return bool(item.link.start in known)

    @staticmethod
    def unknowns(item: Any) -> tuple[str, ...]:
        """Return the link (its angle) and the slider."""
        return item.link.name, item.slider

    @staticmethod
    def new_points(item: Any) -> tuple[str, ...]:
        """Return the slider's pin."""
        return (item.point,)

    @staticmethod
    def evaluate(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                 points: dict[str, Any], residuals: list[Any]) -> None:
        """Require the link's end to be the slider's point on the guide."""
        u = expi(p[f'guide.{item.point}.angle'])
        at = points[item.through] + q[i + 1] * u
        start = points[item.link.start]
        residuals.append(start + p[f'link.{item.link.name}.length'] * expi(q[i]) - at)
        points[item.point] = at

    @staticmethod
    def construct(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                  pts: dict[str, Any], tiny: Any) -> None:
        """Cut the guide with a circle, the branch from its definition."""
        length = p[f'link.{item.link.name}.length']
        u = mpmath.expj(p[f'guide.{item.point}.angle'])
        w = pts[item.link.start] - pts[item.through]
        along = (w * mpmath.conj(u)).real
        offset = (w * mpmath.conj(u)).imag
        square = length * length - offset * offset
        if square < -tiny * length * length:
            msg = f'RRP {item.point}: the guide is out of reach'
            raise NoAssembly(msg)
        s = along + int(item.branch) * mpmath.sqrt(max(square, 0))
        at = pts[item.through] + s * u
        q[i], q[i + 1] = mpmath.arg(at - pts[item.link.start]), s
        pts[item.point] = at

    @staticmethod
    def measure(model: Model, item: Any, i: int, p: Mapping[str, Any],
                points: Mapping[str, Any], q: list[Any], measures: dict[str, Any]) -> None:
        """Put the sine of the rod's angle to the guide's normal."""
        u = mpmath.expj(p[f'guide.{item.point}.angle'])
        r = points[item.point] - points[item.link.start]
        measures[item.point] = abs((mpmath.conj(u) * r).real) / p[
            f'link.{item.link.name}.length']

    @staticmethod
    def prepare(model: Model, item: Any, theta: Any, pts: dict[str, Any]) -> None:
        """Put nothing: its construction reads only its own starts."""

    @staticmethod
    def branch_ok(item: Any, i: int, p: Mapping[str, Any], points: Mapping[str, Any],
                  q: list[Any]) -> bool:
        """Check the slider is beyond (branch +1) or before (-1) the foot of the start."""
        u = mpmath.expj(p[f'guide.{item.point}.angle'])
        along = ((points[item.link.start] - points[item.through]) * mpmath.conj(u)).real
        return bool((q[i + 1] - along) * int(item.branch) >= 0)


class _RPR(_Equations):
    """A slotted lever about a ground pivot through a known pin: its angle and the slider."""

    @staticmethod
    def parameters(item: Any) -> tuple[Parameter, ...]:
        """Return none: the lever's length (pivot to pin) is an unknown."""
        return ()

    @staticmethod
    def ready(model: Model, item: Any, known: set[str]) -> bool:
        """Return whether the pin is known."""
        return bool(item.through in known)

    @staticmethod
    def unknowns(item: Any) -> tuple[str, ...]:
        """Return the lever (its angle) and the slider."""
        return item.link, item.slider

    @staticmethod
    def new_points(item: Any) -> tuple[str, ...]:
        """Return none: the pin was known, the pivot is on the ground."""
        return ()

    @staticmethod
    def evaluate(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                 points: dict[str, Any], residuals: list[Any]) -> None:
        """Require the slot's point at the slider coordinate to be the pin."""
        residuals.append(points[item.center] + q[i + 1] * expi(q[i]) - points[item.through])

    @staticmethod
    def construct(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                  pts: dict[str, Any], tiny: Any) -> None:
        """Take the pin's polar coordinates about the pivot."""
        d = pts[item.through] - pts[item.center]
        q[i], q[i + 1] = mpmath.arg(d), abs(d)

    @staticmethod
    def measure(model: Model, item: Any, i: int, p: Mapping[str, Any],
                points: Mapping[str, Any], q: list[Any], measures: dict[str, Any]) -> None:
        """Put the slider coordinate over the mechanism's size."""
        measures[item.link] = abs(q[i + 1]) / model.size

    @staticmethod
    def prepare(model: Model, item: Any, theta: Any, pts: dict[str, Any]) -> None:
        """Put nothing: its construction reads only its own starts."""

    @staticmethod
    def branch_ok(item: Any, i: int, p: Mapping[str, Any], points: Mapping[str, Any],
                  q: list[Any]) -> bool:
        """Check the pin is on the slot's positive side."""
        return bool(q[i + 1] >= 0)


class _Geneva(_RPR):
    """An intermittent (Geneva) wheel's RPR: the engaged motion, slot 0's, at every angle.

    The reference solves the wheel as the plain slotted lever through the
    pin (its slot 0, continued beyond the engagement window): the engaged
    values of every window follow by turning it back ``2 pi k / n``, and the
    dwell between windows is held exactly still (the solver's closed forms,
    checked against this in ``test/solver/test_geneva.py``).
    """


class _RPP(_Equations):
    """The Scotch yoke: unknowns, the yoke's coordinate on its guide and the pin's in the slot."""

    @staticmethod
    def parameters(item: Any) -> tuple[Parameter, ...]:
        """Return the guide's angle (0 where not written) and the slot's."""
        return (_angle(f'guide.{item.point}.angle', item.guide_angle, ('guide', 'angle'),
                       default=0),
                _angle(f'slot.{item.point}.angle', item.slot_angle, ('slot_angle',)))

    @staticmethod
    def ready(model: Model, item: Any, known: set[str]) -> bool:
        """Return whether the pin is known."""
        return bool(item.through in known)

    @staticmethod
    def unknowns(item: Any) -> tuple[str, ...]:
        """Return both sliders: the yoke on its guide, the pin in the slot."""
        return item.slider, item.slot_slider

    @staticmethod
    def new_points(item: Any) -> tuple[str, ...]:
        """Return the yoke's point on the guide."""
        return (item.point,)

    @staticmethod
    def evaluate(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                 points: dict[str, Any], residuals: list[Any]) -> None:
        """Y = O + s u on the guide; B = Y + t w in the slot."""
        at = points[item.guide_through] + q[i] * expi(p[f'guide.{item.point}.angle'])
        residuals.append(at + q[i + 1] * expi(p[f'slot.{item.point}.angle'])
                         - points[item.through])
        points[item.point] = at

    @staticmethod
    def construct(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                  pts: dict[str, Any], tiny: Any) -> None:
        """Intersect the two lines by Cramer's rule."""
        u = mpmath.expj(p[f'guide.{item.point}.angle'])
        w = mpmath.expj(p[f'slot.{item.point}.angle'])
        d = pts[item.through] - pts[item.guide_through]
        c = (mpmath.conj(u) * w).imag
        q[i] = (mpmath.conj(d) * w).imag / c
        q[i + 1] = (mpmath.conj(u) * d).imag / c
        pts[item.point] = pts[item.guide_through] + q[i] * u

    @staticmethod
    def measure(model: Model, item: Any, i: int, p: Mapping[str, Any],
                points: Mapping[str, Any], q: list[Any], measures: dict[str, Any]) -> None:
        """Put the sine of the angle between the slot and the guide."""
        u = mpmath.expj(p[f'guide.{item.point}.angle'])
        w = mpmath.expj(p[f'slot.{item.point}.angle'])
        measures[item.point] = abs((mpmath.conj(u) * w).imag)

    @staticmethod
    def prepare(model: Model, item: Any, theta: Any, pts: dict[str, Any]) -> None:
        """Put nothing: its construction reads only its own starts."""

    @staticmethod
    def branch_ok(item: Any, i: int, p: Mapping[str, Any], points: Mapping[str, Any],
                  q: list[Any]) -> bool:
        """Return True: the two lines cross once (one configuration)."""
        return True


class _Triad(_Equations):
    """A ternary link held by three binary links: unknowns, the three links' and its angle.

    Each binary link's end ``Pi + li exp(i thi)`` is the ternary's pin
    ``E1 + exp(i phi) di``: two complex residuals (``E2 - E1`` and ``E3 - E1``
    against the ternary's sides) in the four angles. The start is found here,
    apart from the solver's polynomial: for each ternary angle on a grid, the
    first two links close as a law-of-cosines dyad on both branches, and the
    third link's gap changes sign at an assembly (the grid's 2 x 2049 signs
    in doubles); each sign change is refined by bisection (in mpmath).
    Which assembly is the branch is the solver's definition, continuity from
    the drawn pose along the crank's turn, followed here by its own
    continuation (:meth:`prepare`).
    """

    @staticmethod
    def parameters(item: Any) -> tuple[Parameter, ...]:
        """Return the binary links' lengths and the ternary's side and third pin."""
        links = tuple(_length(f'link.{link.name}.length', link.length, ('links', k, 'length'))
                      for k, link in enumerate(item.links))
        name = item.link
        return (*links, _length(f'triad.{name}.length', item.local[1].real, ('link', 'length')),
                _length(f'triad.{name}.local.x', item.local[2].real, ('link', 'local', 0)),
                _length(f'triad.{name}.local.y', item.local[2].imag, ('link', 'local', 1)))

    @staticmethod
    def ready(model: Model, item: Any, known: set[str]) -> bool:
        """Return whether the three links' starts are known."""
        return all(link.start in known for link in item.links)

    @staticmethod
    def unknowns(item: Any) -> tuple[str, ...]:
        """Return the three binary links and the ternary (their angles)."""
        return (*(link.name for link in item.links), item.link)

    @staticmethod
    def new_points(item: Any) -> tuple[str, ...]:
        """Return its three pins."""
        return tuple(item.pins)

    @staticmethod
    def _sides(item: Any, p: Mapping[str, Any]) -> tuple[Any, Any]:
        name = item.link
        return (p[f'triad.{name}.length'],
                p[f'triad.{name}.local.x'] + 1j * p[f'triad.{name}.local.y'])

    @staticmethod
    def evaluate(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                 points: dict[str, Any], residuals: list[Any]) -> None:
        """Each link's end is its pin on the ternary: two residuals."""
        ends = [points[link.start] + p[f'link.{link.name}.length'] * expi(q[i + k])
                for k, link in enumerate(item.links)]
        d2, d3 = _Triad._sides(item, p)
        turn = expi(q[i + 3])
        residuals.append(ends[1] - ends[0] - turn * d2)
        residuals.append(ends[2] - ends[0] - turn * d3)
        for name, end in zip(item.pins, ends, strict=True):
            points[name] = end

    @staticmethod
    def prepare(model: Model, item: Any, theta: Any, pts: dict[str, Any]) -> None:
        """Put the ternary angle on its branch, followed here from the drawn pose to ``theta``.

        The branch is the assembly nearest the written ``angle`` at the
        crank's start, continued along the crank (within half a turn of the
        start either way, as the solver): steps of 0.01 rad, each a Newton
        solve (floats) of the four closure equations from the last, the
        triad's starts at each step from this model's own construction.
        """
        index = next(k for k, e in enumerate(model.elements) if e.item is item)
        p = model.mp_values()
        start = model.scene.drivers[0].start  # (a triad's scene has one crank)
        target = start + math.remainder(float(_value(theta)) - start, math.tau)
        links = item.links
        lengths = [float(p[f'link.{link.name}.length']) for link in links]
        d2, d3 = (complex(x) for x in _Triad._sides(item, p))

        def starts(t: float) -> list[complex]:
            with _precision(20):
                model.construct(p, mpmath.mpf(t), upto=index)
                return [complex(model.partial[link.start]) for link in links]

        first = starts(start)
        with _precision(20):
            found = _Triad._scan(item, p, [mpmath.mpc(z) for z in first])
        if not found:
            pts[f'{item.link}/followed'] = math.nan
            return
        phi, sign = min(found, key=lambda f: abs(math.remainder(float(f[0]) - item.angle,
                                                                math.tau)))
        q = _Triad._closed(item, p, [mpmath.mpc(z) for z in first], phi, sign)
        x = np.array([float(v) for v in q])
        steps = max(1, math.ceil(abs(target - start) / 0.01))
        for k in range(1, steps + 1):
            at = starts(start + (target - start) * k / steps)
            for _ in range(30):
                e = np.exp(1j * x)
                ends = [at[j] + lengths[j] * e[j] for j in range(3)]
                res = [ends[1] - ends[0] - e[3] * d2, ends[2] - ends[0] - e[3] * d3]
                jac = np.zeros((4, 4))
                cols = [(-1j * lengths[0] * e[0], -1j * lengths[0] * e[0]),
                        (1j * lengths[1] * e[1], 0j), (0j, 1j * lengths[2] * e[2]),
                        (-1j * e[3] * d2, -1j * e[3] * d3)]
                for c, (r1, r2) in enumerate(cols):
                    jac[:, c] = (r1.real, r1.imag, r2.real, r2.imag)
                rhs = np.array([res[0].real, res[0].imag, res[1].real, res[1].imag])
                dx = np.linalg.solve(jac, -rhs)
                x = x + dx
                if np.abs(dx).max() < 1e-13:
                    break
            else:
                pts[f'{item.link}/followed'] = math.nan
                return
        pts[f'{item.link}/followed'] = float(x[3])

    @staticmethod
    def _scan(item: Any, p: Mapping[str, Any], starts: list[Any]) -> list[tuple[Any, int]]:
        """Return (ternary angle, branch sign of E1) of every assembly (mpmath)."""
        la, lb, lc = (p[f'link.{link.name}.length'] for link in item.links)
        d2, d3 = _Triad._sides(item, p)
        pa, pb, pc = starts

        def gap(phi: Any, sign: int) -> Any:
            # E1 on the circle about pa (la) and on the circle about pb - R d2 (lb).
            centre = pb - mpmath.expj(phi) * d2
            d = centre - pa
            dist = abs(d)
            cos_g = (la * la + dist * dist - lb * lb) / (2 * la * dist)
            if abs(cos_g) > 1:
                return None
            e1 = pa + la * mpmath.expj(mpmath.arg(d) + sign * mpmath.acos(cos_g))
            return abs(e1 + mpmath.expj(phi) * d3 - pc) - lc

        # The grid's signs in doubles (a sign change within rounding of a grid point is
        # no assembly a drawing could tell), each bracket then bisected in mpmath.
        la_f, lb_f, lc_f = float(la), float(lb), float(lc)
        d2_f, d3_f = complex(d2), complex(d3)
        pa_f, pb_f, pc_f = complex(pa), complex(pb), complex(pc)
        grid_f = np.arange(2049) * (2 * math.pi / 2048)
        turn_f = np.exp(1j * grid_f)
        d_f = pb_f - turn_f * d2_f - pa_f
        dist_f = np.abs(d_f)
        with np.errstate(all='ignore'):
            cos_f = (la_f * la_f + dist_f * dist_f - lb_f * lb_f) / (2 * la_f * dist_f)
            reach = np.abs(cos_f) <= 1
            spread = np.arccos(np.clip(cos_f, -1.0, 1.0))
        found = []
        grid = [2 * mpmath.pi * k / 2048 for k in range(2049)]
        for sign in (1, -1):
            e1_f = pa_f + la_f * np.exp(1j * (np.angle(d_f) + sign * spread))
            values = np.where(reach, np.abs(e1_f + turn_f * d3_f - pc_f) - lc_f, np.nan)
            for k in range(2048):
                g0, g1 = values[k], values[k + 1]
                if not (math.isfinite(g0) and math.isfinite(g1)) or (g0 > 0) == (g1 > 0):
                    continue
                lo, hi = grid[k], grid[k + 1]
                for _ in range(60):
                    mid = (lo + hi) / 2
                    gm = gap(mid, sign)
                    if gm is None:
                        break
                    if (gm > 0) == (g0 > 0):
                        lo = mid
                    else:
                        hi = mid
                found.append(((lo + hi) / 2, sign))
        return found

    @staticmethod
    def _closed(item: Any, p: Mapping[str, Any], starts: list[Any], phi: Any,
                sign: int) -> list[Any]:
        """Return the four angles of the assembly at ternary angle ``phi`` (mpmath)."""
        la, lb = (p[f'link.{link.name}.length'] for link in item.links[:2])
        d2, d3 = _Triad._sides(item, p)
        pa, pb, pc = starts
        centre = pb - mpmath.expj(phi) * d2
        dd = centre - pa
        cos_g = (la * la + abs(dd) ** 2 - lb * lb) / (2 * la * abs(dd))
        first = mpmath.arg(dd) + sign * mpmath.acos(max(-1, min(1, cos_g)))
        e1 = pa + la * mpmath.expj(first)
        turn = mpmath.expj(phi)
        return [first, mpmath.arg(e1 + turn * d2 - pb), mpmath.arg(e1 + turn * d3 - pc), phi]

    @staticmethod
    def construct(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                  pts: dict[str, Any], tiny: Any) -> None:
        """Scan the ternary's angle for assemblies; take the one nearest the followed branch."""
        followed = pts[f'{item.link}/followed']
        if not math.isfinite(followed):
            msg = f'triad {item.link}: its branch does not reach this crank angle'
            raise NoAssembly(msg)
        starts = [pts[link.start] for link in item.links]
        with _precision(20):
            found = _Triad._scan(item, p, starts)
        if not found:
            msg = f'triad {item.link}: its links cannot reach its pins'
            raise NoAssembly(msg)
        phi, sign = min(found, key=lambda f: abs(math.remainder(float(f[0]) - followed,
                                                                math.tau)))
        angles = _Triad._closed(item, p, starts, mpmath.mpf(phi), sign)
        angles[3] = angles[3] + 2 * mpmath.pi * round((followed - float(phi)) / math.tau)
        q[i:i + 4] = angles
        d2, d3 = _Triad._sides(item, p)
        e1 = starts[0] + p[f'link.{item.links[0].name}.length'] * mpmath.expj(angles[0])
        turn = mpmath.expj(angles[3])
        for name, end in zip(item.pins, (e1, e1 + turn * d2, e1 + turn * d3), strict=True):
            pts[name] = end

    @staticmethod
    def measure(model: Model, item: Any, i: int, p: Mapping[str, Any],
                points: Mapping[str, Any], q: list[Any], measures: dict[str, Any]) -> None:
        """Put |det M| over its rows' norms (the solver's definition, docs/scene_format.md)."""
        d2, d3 = _Triad._sides(item, p)
        turn = mpmath.expj(q[i + 3])
        ds = (0, d2, d3)
        size = max(abs(d2), abs(d3))
        rows = []
        for k, link in enumerate(item.links):
            u = points[item.pins[k]] - points[link.start]
            t = 1j * turn * ds[k]
            rows.append((u.real, u.imag, u.real * t.real + u.imag * t.imag,
                         p[f'link.{link.name}.length']))
        det = mpmath.det(mpmath.matrix([row[:3] for row in rows]))
        scale = size
        for x, y, z, length in rows:
            scale *= mpmath.sqrt(x * x + y * y) * mpmath.sqrt(1 + (z / (length * size)) ** 2)
        measures[item.link] = abs(det) / scale

    @staticmethod
    def branch_ok(item: Any, i: int, p: Mapping[str, Any], points: Mapping[str, Any],
                  q: list[Any]) -> bool:
        """Return True: the branch was taken by its definition when constructed."""
        return True


class _Explicit(_Equations):
    """A kind placed explicitly from known points (no unknowns): never singular, one branch."""

    @staticmethod
    def unknowns(item: Any) -> tuple[str, ...]:
        """Return none: it is an explicit function of known points (and drivers)."""
        return ()

    @staticmethod
    def measure(model: Model, item: Any, i: int, p: Mapping[str, Any],
                points: Mapping[str, Any], q: list[Any], measures: dict[str, Any]) -> None:
        """Put none: it has no singular position."""

    @staticmethod
    def prepare(model: Model, item: Any, theta: Any, pts: dict[str, Any]) -> None:
        """Put nothing: its construction reads only its own starts."""

    @staticmethod
    def branch_ok(item: Any, i: int, p: Mapping[str, Any], points: Mapping[str, Any],
                  q: list[Any]) -> bool:
        """Return True: it has one position."""
        return True


class _Carry(_Explicit):
    """A point carried by a link: an explicit function of its frame's two points."""

    @staticmethod
    def parameters(item: Any) -> tuple[Parameter, ...]:
        """Return its local coordinates (``local: [x, y]``, or ``distance:`` along x)."""
        x, y = item.local
        return (_length(f'point.{item.name}.local.x', x, ('local', 0), ('distance',)),
                _length(f'point.{item.name}.local.y', y, ('local', 1), default=0))

    @staticmethod
    def ready(model: Model, item: Any, known: set[str]) -> bool:
        """Return whether its frame's points are known and its link is placed."""
        return item.origin in known and item.xaxis in known and model.placed(item.link)

    @staticmethod
    def new_points(item: Any) -> tuple[str, ...]:
        """Return the point."""
        return (item.name,)

    @staticmethod
    def evaluate(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                 points: dict[str, Any], residuals: list[Any]) -> None:
        """Its position in its frame."""
        origin = points[item.origin]
        axis = points[item.xaxis] - origin
        local = p[f'point.{item.name}.local.x'] + 1j * p[f'point.{item.name}.local.y']
        points[item.name] = origin + local * axis / norm(axis)

    @staticmethod
    def construct(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                  pts: dict[str, Any], tiny: Any) -> None:
        """Its position in its frame (mpmath)."""
        origin = pts[item.origin]
        axis = pts[item.xaxis] - origin
        local = mpmath.mpc(p[f'point.{item.name}.local.x'], p[f'point.{item.name}.local.y'])
        pts[item.name] = origin + local * axis / abs(axis)


class _Collar(_Explicit):
    """A collar on a link: its pin at its actuator's distance along the link's axis."""

    @staticmethod
    def parameters(item: Any) -> tuple[Parameter, ...]:
        """Return none: its distance is its actuator's position, its line two known points."""
        return ()

    @staticmethod
    def ready(model: Model, item: Any, known: set[str]) -> bool:
        """Return whether its two points are known and its link is placed."""
        return item.start in known and item.toward in known and model.placed(item.link)

    @staticmethod
    def new_points(item: Any) -> tuple[str, ...]:
        """Return its pin."""
        return (item.point,)

    @staticmethod
    def evaluate(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                 points: dict[str, Any], residuals: list[Any]) -> None:
        """Its pin along the line from ``from`` toward ``toward``."""
        origin = points[item.start]
        axis = points[item.toward] - origin
        points[item.point] = origin + p[f'actuator.{item.actuator}'] * axis / norm(axis)

    @staticmethod
    def construct(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                  pts: dict[str, Any], tiny: Any) -> None:
        """Its pin along its line (mpmath)."""
        origin = pts[item.start]
        axis = pts[item.toward] - origin
        pts[item.point] = origin + p[f'actuator.{item.actuator}'] * axis / abs(axis)


class _Hinge(_Explicit):
    """A link pinned to a moving one, turned by a motor: its angle the parent's plus its own."""

    @staticmethod
    def parameters(item: Any) -> tuple[Parameter, ...]:
        """Return its length."""
        return (_length(f'hinge.{item.link}.length', item.length, ('length',)),)

    @staticmethod
    def ready(model: Model, item: Any, known: set[str]) -> bool:
        """Return whether its pin is known and its parent placed (then its link is, derived)."""
        if item.center in known and model.placed(item.parent):
            model.derived[item.link] = (item.parent, item.motor)
            return True
        return False

    @staticmethod
    def new_points(item: Any) -> tuple[str, ...]:
        """Return its tip."""
        return (item.point,)

    @staticmethod
    def evaluate(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                 points: dict[str, Any], residuals: list[Any]) -> None:
        """Its tip: the parent's axis turned by the motor's angle, from the pin."""
        origin, xaxis = p[f'motor.{item.motor}.axis']
        axis = points[xaxis] - points[origin]
        turned = axis / norm(axis) * expi(p[f'motor.{item.motor}'])
        points[item.point] = points[item.center] + p[f'hinge.{item.link}.length'] * turned

    @staticmethod
    def construct(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                  pts: dict[str, Any], tiny: Any) -> None:
        """Its tip (mpmath)."""
        origin, xaxis = p[f'motor.{item.motor}.axis']
        axis = pts[xaxis] - pts[origin]
        turned = axis / abs(axis) * mpmath.expj(p[f'motor.{item.motor}'])
        pts[item.point] = pts[item.center] + p[f'hinge.{item.link}.length'] * turned


class _Fold(_RRR):
    """A crank and a rocker from known points, joined by a coupler a motor turns on the rocker.

    Unknowns: the crank's and the rocker's angles; the coupler's is the
    rocker's plus the motor's (derived, as a hinge's). One complex residual:
    the crank's end is the coupler's end ``C + b exp(i (th_rocker + q))``,
    ``C`` the rocker's end. The start: ``|DB| = |c + b exp(i q)|`` by the
    law of cosines (in the rocker's frame), then B on the circles about A and
    D by the law of cosines again, its side of A->D the branch (checked as an
    RRR's, whose pin and links it names alike).
    """

    @staticmethod
    def parameters(item: Any) -> tuple[Parameter, ...]:
        """Return the crank's, the rocker's and the coupler's lengths."""
        return (*(_length(f'link.{link.name}.length', link.length, ('links', k, 'length'))
                  for k, link in enumerate(item.links)),
                _length(f'fold.{item.coupler}.length', item.length, ('coupler', 'length')))

    @staticmethod
    def ready(model: Model, item: Any, known: set[str]) -> bool:
        """Return whether both starts are known (the coupler's angle is then derived)."""
        if all(link.start in known for link in item.links):
            model.derived[item.coupler] = (item.links[1].name, item.motor)
            return True
        return False

    @staticmethod
    def unknowns(item: Any) -> tuple[str, ...]:
        """Return the crank and the rocker (their angles)."""
        return tuple(link.name for link in item.links)

    @staticmethod
    def new_points(item: Any) -> tuple[str, ...]:
        """Return its two pins."""
        return (item.point, item.pin)

    @staticmethod
    def evaluate(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                 points: dict[str, Any], residuals: list[Any]) -> None:
        """Require the crank's end to be the coupler's, from the rocker's end."""
        crank, rocker = item.links
        at = points[crank.start] + p[f'link.{crank.name}.length'] * expi(q[i])
        knee = points[rocker.start] + p[f'link.{rocker.name}.length'] * expi(q[i + 1])
        other = knee + p[f'fold.{item.coupler}.length'] * expi(q[i + 1] + p[f'motor.{item.motor}'])
        residuals.append(at - other)
        points[item.point] = at
        points[item.pin] = knee

    @staticmethod
    def construct(item: Any, i: int, p: Mapping[str, Any], q: list[Any],
                  pts: dict[str, Any], tiny: Any) -> None:
        """Solve by the law of cosines twice, the branch from its definition (mpmath)."""
        crank, rocker = item.links
        c = p[f'link.{rocker.name}.length']
        w = c + p[f'fold.{item.coupler}.length'] * mpmath.expj(p[f'motor.{item.motor}'])
        q[i], at = _RRR.cosines(item, pts, p[f'link.{crank.name}.length'], abs(w), tiny,
                                f'fold {item.point}')
        q[i + 1] = mpmath.arg(at - pts[rocker.start]) - mpmath.arg(w)
        pts[item.point] = at
        pts[item.pin] = pts[rocker.start] + c * mpmath.expj(q[i + 1])

    @staticmethod
    def measure(model: Model, item: Any, i: int, p: Mapping[str, Any],
                points: Mapping[str, Any], q: list[Any], measures: dict[str, Any]) -> None:
        """Put the sine of the angle between the crank and D->B (the solver's definition)."""
        crank, rocker = item.links
        r1 = points[item.point] - points[crank.start]
        r2 = points[item.point] - points[rocker.start]
        cross = (mpmath.conj(r1) * r2).imag
        measures[item.point] = abs(cross) / (p[f'link.{crank.name}.length'] * abs(r2))


#: The equations of every kind of scene item, by :func:`model_key`: each kind of the
#: registry (``solver/registry.py`` ``KINDS``), the carried point and the Geneva wheel's
#: RPR. A kind missing here is refused by :class:`Model`, never solved as another.
MODELS: dict[str, _Equations] = {
    RRR.kind: _RRR(), RRP.kind: _RRP(), RPR.kind: _RPR(), RPP.kind: _RPP(),
    Triad.kind: _Triad(), CarriedPoint.kind: _Carry(), RPR.kind + INTERMITTENT: _Geneva(),
    Collar.kind: _Collar(), Hinge.kind: _Hinge(), Fold.kind: _Fold()}

#: The equations of every kind of driver, by its key in a scene's ``inputs:`` (``DRIVERS``).
DRIVER_MODELS: dict[str, _DriverEquations] = {Crank.scene_key: _Crank(),
                                              Actuator.scene_key: _Actuator(),
                                              Slider.scene_key: _Slider(),
                                              Motor.scene_key: _Motor()}


def _real_vector(residuals: list[Any]) -> list[Any]:
    out = []
    for r in residuals:
        out.extend((r.real, r.imag))
    return out


def _mp_solve(columns: list[list[Any]], rhs: list[Any]) -> list[Any]:
    n = len(columns)
    matrix = mpmath.matrix(n, n)
    for j, column in enumerate(columns):
        for k, value in enumerate(_real_vector(column)):
            matrix[k, j] = value
    solution = mpmath.lu_solve(matrix, mpmath.matrix(_real_vector(rhs)))
    return [solution[k] for k in range(n)]


# --- the reference state -------------------------------------------------------


@dataclass
class Reference:
    """The exact kinematic state of a scene at one instant (mpmath numbers).

    Attributes
    ----------
    points : dict of str to (mpc, mpc, mpc) or (mpc, None, None)
        Position (m), velocity (m/s), acceleration (m/s^2) of every point.
    joints : dict of str to (mpf, mpf, mpf)
        Angle (rad, wrapped to (-pi, pi]) or slider coordinate (m), and its
        first and second time derivatives; ``None`` for the derivatives at a
        singular pose.
    measures : dict of str to mpf
        The solver's near-singularity measures, computed exactly from the
        reference positions: RRR, ``|sin|`` of the angle between its links;
        RRP, ``|sin|`` of the rod's angle to the guide normal; RPR, the slider
        coordinate over the mechanism's size; RPP, ``|sin|`` of the angle
        between the slot and the guide.
    joint_types : dict of str to JointType
        The type of every joint of ``joints`` (the graph's), the drivers' first.
    singular : bool
        A measure is below :data:`SINGULAR_MEASURE`: velocities are undefined.
    residual : mpf
        Largest constraint residual over the mechanism's size.
    model : Model
        The constraints it solves (whose drivers set the least scales of
        :func:`scales`).
    """

    scene: str
    theta: Any
    omega: Any
    alpha: Any
    q: list[Any]
    qdot: list[Any] | None
    qddot: list[Any] | None
    points: dict[str, tuple[Any, Any, Any]]
    joints: dict[str, tuple[Any, Any, Any]]
    joint_types: dict[str, JointType]
    measures: dict[str, Any]
    singular: bool
    residual: Any
    iterations: int = 0
    inputs: dict[str, Any] = field(default_factory=dict)
    model: Model | None = field(default=None, repr=False, compare=False)

    @property
    def min_measure(self) -> Any:
        """The smallest near-singularity measure (1 if there are no dyads)."""
        return min(self.measures.values(), default=mpmath.mpf(1))


def _wrap(angle: Any) -> Any:
    two_pi = 2 * mpmath.pi
    wrapped = angle - two_pi * mpmath.floor(angle / two_pi + mpmath.mpf(0.5))
    return wrapped + two_pi if wrapped <= -mpmath.pi else wrapped


def _newton(model: Model, p: Mapping[str, Any], q: list[Any], theta: Any,
            max_iter: int = 60) -> tuple[list[Any], int]:
    """Polish ``q`` by Newton-Raphson until the step is below 1e-(DPS-6) of the size."""
    size = mpmath.mpf(model.size)
    tol = mpmath.mpf(10) ** (-(mpmath.mp.dps - 6))
    scales = [size if is_length else 1 for is_length in model.unknown_is_length]
    for iteration in range(1, max_iter + 1):
        _, res = model.evaluate(p, q, theta)
        if max((abs(r) for r in res), default=0) <= tol * size * mpmath.mpf('1e-3'):
            return q, iteration - 1
        step = _mp_solve(model.jacobian_columns(p, q, theta), [-r for r in res])
        q = [x + dx for x, dx in zip(q, step, strict=True)]
        if max(abs(dx) / s for dx, s in zip(step, scales, strict=True)) <= tol:
            return q, iteration
    msg = f'Newton-Raphson did not converge in {max_iter} iterations'
    raise ArithmeticError(msg)


def _solve_positions(model: Model, p: Mapping[str, Any], theta: Any,
                     seed: list[Any] | None) -> tuple[list[Any], int]:
    """Newton-Raphson from ``seed`` or from a construction done at only 20 digits.

    Starting from a deliberately rough construction makes Newton-Raphson on
    the constraints, not the construction's formulas, set the digits. At a
    singular pose (a double root) Newton converges only linearly; there the
    construction is redone at full precision and polished as far as it goes.
    """
    if seed is not None:
        return _newton(model, p, [mpmath.mpf(x) for x in seed], theta)
    with mpmath.workdps(SEED_DPS):
        rough = model.construct(p, theta)
    try:
        return _newton(model, p, [+x for x in rough], theta)
    except (ArithmeticError, ZeroDivisionError):
        q = model.construct(p, theta)
        try:
            return _newton(model, p, q, theta, max_iter=8)
        except (ArithmeticError, ZeroDivisionError):
            return q, -1


def _measures(model: Model, p: Mapping[str, Any], points: Mapping[str, Any],
              q: list[Any]) -> dict[str, Any]:
    measures: dict[str, Any] = {}
    for element in model.elements:
        element.equations.measure(model, element.item, element.index, p, points, q, measures)
    return measures


def _check_branch(model: Model, p: Mapping[str, Any], points: Mapping[str, Any],
                  q: list[Any]) -> None:
    """Raise if Newton left the branch that docs/scene_format.md defines."""
    for element in model.elements:
        if not element.equations.branch_ok(element.item, element.index, p, points, q):
            msg = f'{element.label}: wrong branch'
            raise ArithmeticError(msg)


def reference(scene: Scene | Model, theta: Any, omega: Any | None = None,
              alpha: Any | None = None, *, values: Mapping[str, Any] | None = None,
              seed: list[Any] | None = None, dps: int = DPS) -> Reference:
    """Return the exact state of ``scene`` at crank angle ``theta``.

    Parameters
    ----------
    scene : Scene or Model
        The mechanism.
    theta, omega, alpha : float or mpf
        Crank angle (rad), speed (rad/s), acceleration (rad/s^2); speed and
        acceleration default to the scene's. Floats are taken exactly.
    values : mapping, optional
        Geometry overriding :attr:`Model.values` (for perturbations).
    seed : list, optional
        Start for Newton-Raphson instead of the construction (same branch).
    dps : int
        Working digits.

    Raises
    ------
    NoAssembly
        If the mechanism has no real configuration there.
    """
    model = scene if isinstance(scene, Model) else Model(scene)
    drivers = model.scene.drivers
    th: Any
    om: Any
    al: Any
    with _precision(dps):
        p = model.mp_values() if values is None else {k: mpmath.mpf(v) for k, v in values.items()}
        if model.single:
            th = mpmath.mpf(theta)
            om = mpmath.mpf(drivers[0].speed if omega is None else omega)
            al = mpmath.mpf(drivers[0].accel if alpha is None else alpha)
        else:
            th, om, al = (tuple(mpmath.mpf(getattr(d, attr) if x is None else x)
                                for d, x in zip(drivers, _each(given, len(drivers)),
                                                strict=True))
                          for given, attr in ((theta, 'start'), (omega, 'speed'),
                                              (alpha, 'accel')))
        q, iterations = _solve_positions(model, p, th, seed)
        points, res = model.evaluate(p, q, th)
        _check_branch(model, p, points, q)
        measures = _measures(model, model.driven(p, th)[0], points, q)
        residual = max((abs(r) for r in res), default=mpmath.mpf(0)) / model.size
        singular = bool(measures) and min(measures.values()) < SINGULAR_MEASURE
        qdot = qddot = None
        if not singular:
            columns = model.jacobian_columns(p, q, th)
            theta_jet = _jet(th, om, al)
            _, res = model.evaluate(p, q, theta_jet)
            # (a dyad no driver moves directly has a plain residual: rate 0)
            qdot = [-x for x in _mp_solve(columns, [r.c1 if isinstance(r, Jet) else 0 * r
                                                    for r in res])]
            _, res = model.evaluate(p, [Jet(x, v) for x, v in zip(q, qdot, strict=True)],
                                    theta_jet)
            qddot = [-2 * x for x in _mp_solve(columns, [r.c2 if isinstance(r, Jet) else 0 * r
                                                         for r in res])]
        state = _state(model, p, q, qdot, qddot, th, om, al)
        return Reference(model.scene.name, th, om, al, q, qdot, qddot, state[0], state[1],
                         dict(model.joint_types), measures, singular, residual, iterations,
                         dict(p), model)


def _floors(model: Model, p: Mapping[str, Any], om: Any, al: Any) -> dict[str, Any]:
    """Per kind of value, the largest of the least scales each driver sets (1 rad for angles).

    At mpmath's working precision where called (:func:`scales`'s caller's).
    """
    floors: dict[str, Any] = dict.fromkeys(KINDS, mpmath.mpf(0))
    floors['angle'] = 1
    rates = zip((om,) if model.single else om, (al,) if model.single else al, strict=True)
    for (driver, equations), (w, a) in zip(model.drivers, rates, strict=True):
        mine = equations.floors(model, driver, p, abs(w), abs(a))
        floors.update((kind, max(floors[kind], value)) for kind, value in mine.items())
    return floors


def _each(given: Any, n: int) -> list[Any]:
    """Return one value per driver: ``None`` for each, a sequence, or one value (n = 1)."""
    if given is None:
        return [None] * n
    if isinstance(given, (list, tuple)):
        return list(given)
    return [given]


def _jet(th: Any, om: Any, al: Any) -> Any:
    """Return the drivers' motion as jets: one, or a tuple of one per driver."""
    if isinstance(th, tuple):
        return tuple(Jet(x, v, a / 2) for x, v, a in zip(th, om, al, strict=True))
    return Jet(th, om, al / 2)


def _state(model: Model, p: Mapping[str, Any], q: list[Any], qdot: list[Any] | None,
           qddot: list[Any] | None, th: Any, om: Any,
           al: Any) -> tuple[dict[str, Any], dict[str, Any]]:
    """Points and joints with derivatives from the jets of q (or positions only)."""
    drivers = model.scene.drivers
    if qdot is None or qddot is None:
        points, _ = model.evaluate(p, q, th)
        point_states = {name: (z, None, None) for name, z in points.items()}
        joints: dict[str, Any] = {}
        for driver, x in zip(drivers, (th,) if model.single else th, strict=True):
            angular = model.joint_types[driver.name].angular
            joints[driver.name] = (_wrap(x) if angular else x, None, None)
        for name, index in model.links.items():
            if index is not None:
                joints[name] = (_wrap(q[index]), None, None)
        for name, index in model.sliders.items():
            joints[name] = (q[index], None, None)
        for name, (parent, motor) in model.derived.items():
            joints[name] = (_wrap(joints[parent][0] + joints[motor][0]), None, None)
        return point_states, joints
    jets = [Jet(x, v, a / 2) for x, v, a in zip(q, qdot, qddot, strict=True)]
    theta_jet = _jet(th, om, al)
    points, _ = model.evaluate(p, jets, theta_jet)
    point_states = {name: (z.derivatives() if isinstance(z, Jet) else (z, 0 * z, 0 * z))
                    for name, z in points.items()}
    joints = {}
    for driver, jet in zip(drivers, (theta_jet,) if model.single else theta_jet, strict=True):
        x, v, a = jet.derivatives()
        joints[driver.name] = (_wrap(x) if model.joint_types[driver.name].angular else x, v, a)
    for name, index in model.links.items():
        if index is not None:
            x, v, a = jets[index].derivatives()
            joints[name] = (_wrap(x), v, a)
    for name, index in model.sliders.items():
        joints[name] = jets[index].derivatives()
    for name, (parent, motor) in model.derived.items():
        (x, v, a), (y, w, b) = joints[parent], joints[motor]
        joints[name] = (_wrap(x + y), v + w, a + b)
    return point_states, joints


# --- the second route: differences in time ------------------------------------


def check_by_differences(scene: Scene | Model, ref: Reference,
                         step_angle: Any = FD_STEP_ANGLE) -> dict[str, float]:
    """Differentiate 50-digit positions in time and compare with ``ref``.

    The crank angle follows ``theta(t) = theta + omega t + alpha t**2 / 2``;
    positions are solved by Newton-Raphson at ``t = -2h .. 2h`` with
    ``|omega| h = step_angle`` and differentiated by five-point central
    differences (error ``O(h**4)``, rounding ``10**-DPS / h**2``).

    Returns
    -------
    dict of str to float
        Per kind of value (velocity, angular velocity, acceleration, angular
        acceleration), the largest difference between the two routes over the
        kind's largest magnitude (:func:`compare`'s normalisation).
    """
    model = scene if isinstance(scene, Model) else Model(scene)
    if not model.single:
        msg = f'Expected a scene driven by one crank, got {len(model.scene.drivers)} drivers'
        raise ValueError(msg)
    if ref.qdot is None:
        msg = 'Expected a regular pose, got a singular one (no velocities to check)'
        raise ValueError(msg)
    with _precision(DPS):
        p = {k: mpmath.mpf(v) for k, v in ref.inputs.items()}
        rate = abs(ref.omega) if ref.omega != 0 else mpmath.sqrt(abs(ref.alpha))
        h = mpmath.mpf(step_angle) / (rate if rate != 0 else 1)
        samples = []
        for k in (-2, -1, 0, 1, 2):
            t = k * h
            th = ref.theta + ref.omega * t + ref.alpha * t * t / 2
            seed = [x + v * t for x, v in zip(ref.q, ref.qdot, strict=True)]
            q, _ = _newton(model, p, seed, th)
            points, _ = model.evaluate(p, q, th)
            angles = {name: (th if index is None else q[index])
                      for name, index in model.links.items()}
            sliders = {name: q[index] for name, index in model.sliders.items()}
            samples.append((points, angles, sliders))

        def d1(f: Callable[[Any], Any]) -> Any:
            m2, m1, _, p1, p2 = (f(s) for s in samples)
            return (m2 - 8 * m1 + 8 * p1 - p2) / (12 * h)

        def d2(f: Callable[[Any], Any]) -> Any:
            m2, m1, z, p1, p2 = (f(s) for s in samples)
            return (-m2 + 16 * m1 - 30 * z + 16 * p1 - p2) / (12 * h * h)

        got: dict[str, dict[str, Any]] = {kind: {} for kind in KINDS}
        for name in ref.points:
            got['velocity'][name] = d1(lambda s, n=name: s[0][n])
            got['acceleration'][name] = d2(lambda s, n=name: s[0][n])
        for name in model.links:
            got['angular velocity'][name] = d1(lambda s, n=name: s[1][n])
            got['angular acceleration'][name] = d2(lambda s, n=name: s[1][n])
        for name in model.sliders:
            got['velocity'][name] = d1(lambda s, n=name: s[2][n])
            got['acceleration'][name] = d2(lambda s, n=name: s[2][n])
        expected = _by_kind(ref)
        out = {}
        for kind in ('velocity', 'angular velocity', 'acceleration', 'angular acceleration'):
            scale = max((abs(v) for v in expected[kind].values()), default=0) or 1
            out[kind] = float(max((abs(got[kind][k] - v) for k, v in expected[kind].items()),
                                  default=0) / scale)
        return out


# --- comparisons ---------------------------------------------------------------


def _by_kind(ref: Reference) -> dict[str, dict[str, Any]]:
    """Group the reference's values by kind (complex numbers for points)."""
    out: dict[str, dict[str, Any]] = {kind: {} for kind in KINDS}
    for name, (x, v, a) in ref.points.items():
        out['position'][name] = x
        if v is not None:
            out['velocity'][name], out['acceleration'][name] = v, a
    for name, values in ref.joints.items():
        position, velocity, acceleration = ref.joint_types[name].quantities
        out[position][name] = values[0]
        if values[1] is not None:
            out[velocity][name], out[acceleration][name] = values[1:]
    return out


def _solver_by_kind(state: Any, index: int | None = None) -> dict[str, dict[str, Any]]:
    """Group a solver State's values (entry ``index`` of an array state) like ``_by_kind``."""
    def pick(x: Any) -> Any:
        return x if index is None else x[index]

    out: dict[str, dict[str, Any]] = {kind: {} for kind in KINDS}
    for name, (x, v, a) in state.complex_points.items():
        out['position'][name] = complex(pick(x))
        out['velocity'][name] = complex(pick(v))
        out['acceleration'][name] = complex(pick(a))
    for name, joint in state.joints.items():
        values = (float(pick(joint.position)), float(pick(joint.velocity)),
                  float(pick(joint.acceleration)))
        for kind, value in zip(joint_type(joint.type).quantities, values, strict=True):
            out[kind][name] = value
    return out


def scales(ref: Reference) -> dict[str, float]:
    """Per kind, the scale errors are relative to.

    The kind's largest magnitude in ``ref``, but at least what the crank
    itself sets: its length ``a`` for positions, ``a |omega|`` for
    velocities, ``a (omega**2 + |alpha|)`` for accelerations, ``|omega|`` and
    ``omega**2 + |alpha|`` for angular ones (a parallelogram's links have no
    angular acceleration at all); 1 rad for angles; 1 if all that is zero.
    With several drivers, the largest of what each sets: each crank's as
    above, an actuator's rate ``|v|`` and ``|a|`` (each driver's model says,
    :data:`DRIVER_MODELS`).
    """
    if ref.model is None:
        msg = 'Expected a reference computed by reference(), got one without its model'
        raise ValueError(msg)
    expected = _by_kind(ref)
    floors = _floors(ref.model, ref.inputs, ref.omega, ref.alpha)
    out = {}
    for kind, values in expected.items():
        largest = max([abs(v) for v in values.values()] + [floors[kind]])
        out[kind] = 1.0 if kind == 'angle' else (float(largest) if largest > 0 else 1.0)
    return out


def compare(state: Any, ref: Reference, index: int | None = None,
            kinds: tuple[str, ...] = KINDS) -> dict[str, float]:
    """Return, per kind, the solver's largest error against ``ref`` over that kind's scale.

    Kinds: ``position`` (points and sliders, m), ``angle`` (revolute joints,
    rad, modulo 2 pi, scale 1 rad), ``velocity``, ``angular velocity``,
    ``acceleration``, ``angular acceleration``. The scale is the kind's
    largest magnitude in the reference state, so each number is a relative
    error of the state as a whole. Only the values the solver reports are
    compared, and only the ``kinds`` asked for.
    """
    got = _solver_by_kind(state, index)
    expected = _by_kind(ref)
    norms = scales(ref)
    out = {}
    with _precision(DPS):
        for kind in kinds:
            worst = 0.0
            for name, value in got[kind].items():
                if name not in expected[kind]:
                    continue
                exact = mpmath.mpc(value) if isinstance(value, complex) else mpmath.mpf(value)
                diff = exact - expected[kind][name]
                if kind == 'angle':
                    diff = _wrap(diff)
                worst = max(worst, float(abs(diff)))
            out[kind] = worst / norms[kind]
    return out


def value_errors(state: Any, ref: Reference) -> dict[str, tuple[str, float]]:
    """Return the absolute error of every value a single-angle ``state`` reports.

    Keyed by the value's path in ``State.as_dict()`` (``joints.rocker.velocity``,
    ``points.C.acceleration``), as ``(kind, error)``: the kind of
    :data:`KINDS` and the error in SI units, ``|solver - exact|``: the length
    of the error vector for a point, modulo 2 pi for a joint angle, exactly
    what ``state.error_bound`` bounds. Values the reference leaves undefined
    (the derivatives at a singular pose) are left out.
    """
    out: dict[str, tuple[str, float]] = {}
    quantities = ('position', 'velocity', 'acceleration')
    with _precision(DPS):
        for name, values in state.complex_points.items():
            for index, quantity in enumerate(quantities):
                exact = ref.points[name][index]
                if exact is not None:
                    error = abs(mpmath.mpc(values[index]) - exact)
                    out[f'points.{name}.{quantity}'] = (quantity, float(error))
        for name, joint in state.joints.items():
            kind = joint_type(joint.type)
            kinds = kind.quantities
            for index, quantity in enumerate(quantities):
                exact = ref.joints[name][index]
                if exact is None:
                    continue
                error = mpmath.mpf(getattr(joint, quantity)) - exact
                if index == 0 and kind.angular:
                    error = _wrap(error)
                out[f'joints.{name}.{quantity}'] = (kinds[index], float(abs(error)))
    return out


def condition(scene: Scene | Model, ref: Reference,
              step: str = '1e-25') -> dict[str, float]:
    """Return, per kind, the condition number of the state in its inputs.

    ``kappa = max over outputs of sum over inputs |d out / d x| |x| / scale``
    (componentwise relative perturbations of every geometry value and of the
    crank's angle, speed and acceleration; :func:`scales`). An error of
    ``eps * kappa`` is what rounding the inputs alone would cause, so a
    backward-stable solver stays within a small multiple of it.
    """
    model = scene if isinstance(scene, Model) else Model(scene)
    if ref.singular:
        return dict.fromkeys(KINDS, math.inf)
    # Near a singular pose the state moves by ~ delta / measure**2: keep the
    # perturbation far below measure**2 and the digits to resolve it.
    with _precision(DPS):
        measure = ref.min_measure
        extra = max(0, int(mpmath.ceil(-2 * mpmath.log10(measure))) - 6) if measure > 0 else 0
        eta = mpmath.mpf(step) * min(1, measure * measure * 10**6)
    dps = DPS + extra
    with _precision(dps):
        if extra:
            ref = reference(model, ref.theta, ref.omega, ref.alpha, values=ref.inputs,
                            seed=ref.q, dps=dps)
        base = _by_kind(ref)
        norms = scales(ref)
        totals: dict[str, dict[str, Any]] = {
            kind: dict.fromkeys(v, mpmath.mpf(0)) for kind, v in base.items()}
        inputs: list[tuple[str, Any]] = [(key, value) for key, value in ref.inputs.items()]
        several = isinstance(ref.theta, tuple)  # one value per driver: each perturbed
        for label, given in (('@theta', ref.theta), ('@omega', ref.omega),
                             ('@alpha', ref.alpha)):
            inputs += ([(f'{label}{k}', x) for k, x in enumerate(given)] if several
                       else [(label, given)])
        for key, value in inputs:
            if value == 0:
                continue
            values = dict(ref.inputs)
            motion = {'@theta': ref.theta, '@omega': ref.omega, '@alpha': ref.alpha}
            delta = value * eta
            which = key.rstrip('0123456789')
            if which in motion:
                given = motion[which]
                if several:
                    k = int(key[len(which):])
                    given = (*given[:k], given[k] + delta, *given[k + 1:])
                else:
                    given = given + delta
                motion[which] = given
            else:
                values[key] = value + delta
            th, om, al = motion['@theta'], motion['@omega'], motion['@alpha']
            moved = _by_kind(reference(model, th, om, al, values=values, seed=ref.q, dps=dps))
            for kind, items in base.items():
                for name, x in items.items():
                    diff = moved[kind][name] - x
                    if kind == 'angle':
                        diff = _wrap(diff)
                    totals[kind][name] += abs(diff) / eta
        return {kind: float(max(items.values(), default=0) / norms[kind])
                for kind, items in totals.items()}


def as_float_dict(ref: Reference) -> dict[str, Any]:
    """Return ``ref`` rounded to doubles, in the structure of ``State.as_dict()``."""
    def f(x: Any) -> float:
        return float(x) if x is not None else math.nan

    def pair(z: Any) -> list[float]:
        return [math.nan, math.nan] if z is None else [float(z.real), float(z.imag)]

    return {
        'scene': ref.scene,
        'input': {'angle': f(ref.theta), 'speed': f(ref.omega), 'accel': f(ref.alpha)},
        'joints': {name: {'type': ref.joint_types[name], 'position': f(x), 'velocity': f(v),
                          'acceleration': f(a)} for name, (x, v, a) in ref.joints.items()},
        'points': {name: {'position': pair(x), 'velocity': pair(v), 'acceleration': pair(a)}
                   for name, (x, v, a) in ref.points.items()},
    }


#: Reads a document with every scalar left as the text written (no numbers resolved).
_TEXT_LOADER: Any = getattr(yaml, 'CBaseLoader', yaml.BaseLoader)
#: A decimal number as YAML 1.2 writes one: its digits are taken as written.
_DECIMAL = re.compile(r'[-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)?')


def decimal_values(path: str | os.PathLike[str], model: Model) -> dict[str, Any]:
    """Return the geometry of a scene file as exact decimals (mpmath), keyed like ``values``.

    The scene loader rounds ``40 mm`` to the double nearest 0.04 m; published
    50-digit values are computed from the decimal numbers as written, so to
    reproduce them bit for bit the reference must start from those. The file
    is read by the scene loader's own YAML reader
    (:func:`mech_kinematics.scene.read_scene_yaml`: YAML 1.2 numbers such as
    ``1.5e2``, duplicate keys refused), so both read the same numbers; each
    number written as a decimal is then taken at every digit written (a
    20-digit length keeps its 20 digits), any other (``0x10``, ``!!float 3``)
    at its exact value. The units are :mod:`mech_kinematics.units`' (the
    scene loader's). Which values are read, whether each is a length or an
    angle and where the file writes it, each kind's model says
    (:attr:`Model.parameters`): every value of ``model.values``, of every
    kind, is read so.

    Raises
    ------
    SceneError
        If the file cannot be read, is not a scene file the loader reads
        (naming the line and column), holds a value that is not a number where
        a number belongs, lacks a value of the model's scene, or has a
        ``units.length`` or ``units.angle`` that is not one a scene may use.
    """
    try:
        text = Path(path).read_text(encoding='utf-8').removeprefix('\ufeff')
        data = read_scene_yaml(text)
    except (OSError, UnicodeDecodeError) as error:
        raise SceneError(f'{path}: cannot read: {error}') from None
    except SceneError as error:
        raise SceneError(f'{path}: {error}') from None
    written = yaml.load(text, Loader=_TEXT_LOADER)  # noqa: S506 - resolves no tags at all
    units = data.get('units') or {}
    length_unit = units.get('length', 'm')
    if length_unit not in LENGTH_UNITS:
        msg = (f'{path}: units.length: expected one of {", ".join(LENGTH_UNITS)}, '
               f'got {length_unit!r}')
        raise SceneError(msg)
    angle_unit = units.get('angle', 'deg')
    if angle_unit not in ANGLE_UNITS:
        msg = (f'{path}: units.angle: expected one of {", ".join(ANGLE_UNITS)}, '
               f'got {angle_unit!r}')
        raise SceneError(msg)
    out: dict[str, Any] = {}
    with _precision(DPS):
        per_metre = mpmath.mpf(LENGTH_UNITS[length_unit])
        for key, parameter in model.parameters.items():
            value, text = _written(data, written, parameter, path)
            if type(value) is int:
                x = mpmath.mpf(value)
            elif type(value) is float and math.isfinite(value):
                decimal = isinstance(text, str) and _DECIMAL.fullmatch(text) is not None
                x = mpmath.mpf(text if decimal and float(text) == value else value)
            else:
                msg = f'{path}: {key}: expected a number, got {value!r}'
                raise SceneError(msg)
            if not parameter.angle:
                out[key] = x / per_metre
            else:
                out[key] = radians_from_degrees(x, mpmath.pi) if angle_unit == 'deg' else x
    if set(out) != set(model.values):
        msg = f'Expected the keys {sorted(model.values)}, got {sorted(out)}'
        raise ValueError(msg)
    return out


#: A path that a scene file does not have.
_ABSENT = object()


def _at(tree: Any, path: tuple[str | int, ...]) -> Any:
    """Return the value at ``path`` (keys and list indices) in a scene file's tree."""
    for step in path:
        if isinstance(step, int):
            if not isinstance(tree, list) or not -len(tree) <= step < len(tree):
                return _ABSENT
        elif not isinstance(tree, dict) or step not in tree:
            return _ABSENT
        tree = tree[step]
    return tree


def _written(data: Any, written: Any, parameter: Parameter,
             path: str | os.PathLike[str]) -> tuple[Any, Any]:
    """Return a parameter's number as the loader reads it and its text as written."""
    for where in parameter.paths:
        value = _at(data, where)
        if value is not _ABSENT:
            return value, _at(written, where)
    if parameter.default is not None:
        return parameter.default, str(parameter.default)
    places = ' or '.join('.'.join(str(step) for step in where) for where in parameter.paths)
    msg = (f'{path}: {places}: expected the number of {parameter.key} (of the model), '
           'got none')
    raise SceneError(msg)
