# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Where a point of a two-driver scene can go: its workspace and its singular curves.

A scene with two drivers moves a point over a region of the plane, its
*workspace*. :func:`workspace_from_scene` samples the drivers' space on the
grid :mod:`.region` uses (each driver over a turn or its stroke) and solves
it on the array path, positions and the velocities at a unit speed of each
driver (the columns of the Jacobian ``J = d point / d driver``, exact to their
bounds). It gives

- the point's positions at every grid point where the mechanism assembles,
  and their extent;
- the **singular points of the inverse map**, where ``det J = 0``: the
  drivers lose control of the point (a five-bar's leg stretched or folded),
  the edge of the workspace of that assembly. Found on every grid edge
  (between neighbours, a turn wrapping round) whose two ends assemble and
  whose ``det J`` changes sign, at the drivers' values where ``det J``
  interpolated linearly along the edge is zero, solved there (a sign change
  through a pole, where ``|det J|`` there exceeds :data:`ZERO` of the ends',
  is not one);
- the points **where the loop locks**, the forward singularity (a dyad's
  links in line: the drivers cannot move on): the edge of the assembly
  region, at the last assembling end of every grid edge whose other end does
  not assemble;
- the grid edges that assemble at both ends but are not joined smoothly
  (the point moves more than :data:`SMOOTH` times the larger of the ends'
  first-order steps, a Jacobian column times the grid step): a singular pose lies
  between them, such as a dyad whose two pivots meet (the packaged five-bar's
  cranks crossing with B on D), and no curve is read across them.

Both curves are at the grid's resolution, stated with them (the point moves
at most ``step`` times the largest ``|J|`` column between neighbours). NumPy
only: the solver does the geometry.

:func:`workspace` is the same map of any point a state gives (a reader of its
position and velocity): a URDF link frame's origin, fixed in a scene body's
frame (:func:`mech_kinematics.robot.targets.frame_workspace`), with ``lift``,
the affine map of the loop's plane into the root frame the answer is told in.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
import math
from typing import Any
import warnings

import numpy as np
import numpy.typing as npt

from .region import _samples, domain, GRID
from ..errors import NearSingularWarning, SceneError
from ..solver import Scene, SceneUnits, solve, State

__all__ = ['Workspace', 'workspace', 'workspace_from_scene']

Array = npt.NDArray[np.float64]
#: A point's position and velocity (complex, m and m/s) in a state (one or arrays).
Reader = Callable[[State], tuple[Any, Any]]

#: Neighbours are joined smoothly when the point moves between them at most this many times
#: the larger of their first-order steps (Jacobian column times the grid step).
SMOOTH = 1.5
#: A sign change of det J on a smooth edge is a zero where, at the drivers' values its
#: linear interpolation gives, |det J| is at most this share of the smaller end's (a pole,
#: where the point's speed is unbounded, gives more).
ZERO = 0.5
#: An absolute floor of that test, a share of the mechanism's size (a point at rest).
_TINY = 1e-9


@dataclass(frozen=True)
class Workspace:
    """What :func:`workspace_from_scene` finds (m, rad).

    Attributes
    ----------
    scene, point : str
        The scene's and the point's names.
    units : SceneUnits
        The scene's units, to show the numbers in.
    drivers : tuple of str
        The two drivers, the grid's axes.
    axes : tuple of ndarray
        Their sampled positions (rad or m).
    assembles : ndarray of bool, shape (n0, n1)
        Whether the mechanism assembles at each grid point.
    positions : ndarray, shape (n0, n1, 2)
        The point's position at each grid point (NaN where it does not assemble).
    det : ndarray, shape (n0, n1)
        ``det J`` at each grid point (m^2 per driver unit^2; NaN where it does not assemble).
    inverse_singular : ndarray, shape (k, 2)
        Where ``det J = 0``, the point's positions (interpolated on grid edges).
    singular_drivers : ndarray, shape (k, 2)
        The drivers' values there.
    locks : ndarray, shape (l, 2)
        The point's positions at the assembling end of the region's edges.
    lock_drivers : ndarray, shape (l, 2)
        The drivers' values there.
    jumps : ndarray, shape (j, 2)
        The point's positions at the first end of grid edges whose two ends
        assemble but are not joined smoothly: a singular pose lies between
        them (a dyad whose two pivots meet), no curve is read across them.
    resolution : float
        The largest move of the point between smoothly joined grid neighbours,
        m: what both curves are good to.
    start : ndarray, shape (2,)
        The point where the drivers start (NaN where it does not assemble).
    lift : (ndarray, ndarray) or None
        ``(E, o)``: the point of the plane ``z`` is ``E @ z + o`` in the frame
        the answer is told in (a URDF's root frame, ``E`` 3x2); ``None``: the
        scene's plane itself.
    """

    scene: str
    point: str
    units: SceneUnits
    drivers: tuple[str, str]
    axes: tuple[Array, Array]
    assembles: npt.NDArray[np.bool_]
    positions: Array
    det: Array
    inverse_singular: Array
    singular_drivers: Array
    locks: Array
    lock_drivers: Array
    jumps: Array
    resolution: float
    start: Array
    lift: tuple[Array, Array] | None = None

    def told(self, points: Array) -> Array:
        """Return points of the plane (shape (k, 2)) in the frame the answer is told in."""
        if self.lift is None:
            return points
        e, o = self.lift
        return np.asarray(points, dtype=np.float64).reshape(-1, 2) @ e.T + o

    @property
    def extent(self) -> tuple[tuple[float, float], ...]:
        """Each coordinate's (min, max) told (x, y; a URDF frame's z) over the grid, m."""
        p = self.told(self.positions[self.assembles])
        return tuple((float(p[:, k].min()), float(p[:, k].max())) for k in range(p.shape[1]))


def workspace_from_scene(scene: Scene, point: str, grid: int = GRID) -> Workspace:
    """Map the workspace of ``point`` over the grid of ``scene``'s two drivers (module text).

    Raises
    ------
    SceneError
        A scene without two drivers, a point it does not report, or one that
        assembles nowhere on the grid.
    """
    _two_drivers(scene)
    if point not in scene.output_points:
        msg = (f'Expected --workspace to name a point {scene.name} reports '
               f'({", ".join(scene.output_points)}), got {point!r}')
        raise SceneError(msg)
    return workspace(scene, point, lambda state: state.complex_points[point][:2], grid)


def workspace(scene: Scene, point: str, read: Reader, grid: int = GRID,
              lift: tuple[Array, Array] | None = None) -> Workspace:
    """Map the workspace of the point ``read`` gives over ``scene``'s two drivers' grid.

    ``read`` returns a state's position and velocity of the point (complex, m
    and m/s; arrays for arrays), ``point`` is its name in the answer and
    ``lift`` the map of the plane into the frame the answer is told in
    (:attr:`Workspace.lift`). Raises :class:`SceneError` for a scene without
    two drivers or where it assembles nowhere on the grid.
    """
    drivers = _two_drivers(scene)
    axes = tuple(_samples(d.joint_type, *domain(scene, d), grid) for d in drivers)
    grids = np.meshgrid(*axes, indexing='ij')
    shape = (len(axes[0]), len(axes[1]))
    first, second = _columns(scene, [g.ravel() for g in grids])
    valid = np.asarray(first.valid, dtype=bool).reshape(shape)
    if not valid.any():
        msg = f'Expected {scene.name} to assemble somewhere on the grid, got nowhere'
        raise SceneError(msg)
    p, j0 = (_xy(z, shape) for z in read(first))
    j1 = _xy(read(second)[1], shape)
    det = j0[..., 0] * j1[..., 1] - j0[..., 1] * j1[..., 0]
    p = np.where(valid[..., None], p, np.nan)
    det = np.where(valid, det, np.nan)
    crossings: list[Any] = []      # (q at one end, q at the other, t, |det| at the ends' least)
    locks: list[Any] = []
    jumps: list[Any] = []
    lock_q: list[Any] = []
    moves = [0.0]
    size = float(first.error_bound.size)
    for axis, driver in enumerate(drivers):
        wrap = driver.joint_type.angular         # a turn: the last sample's neighbour is 0
        step = float(axes[axis][1] - axes[axis][0])
        a_det, b_det = _pairs(det, axis, wrap)
        a_p, b_p = _pairs(p, axis, wrap)
        a_j, b_j = _pairs((j0, j1)[axis] * step, axis, wrap)
        a_valid, b_valid = _pairs(valid, axis, wrap)
        a_q = [_pairs(g, axis, wrap)[0] for g in grids]
        b_q = [q + step if k == axis else q for k, q in enumerate(a_q)]
        both = a_valid & b_valid
        # Smooth: the chord of a smooth edge is at most the largest |J column| along it times
        # the step, near the ends' (1.0004 of them at most on the five-bar's 180 x 180 grid);
        # a dyad whose pivots meet is jumped across (2.2 there).
        move = np.hypot(*np.moveaxis(b_p - a_p, -1, 0))
        reach = np.maximum(np.hypot(*np.moveaxis(a_j, -1, 0)),
                           np.hypot(*np.moveaxis(b_j, -1, 0)))
        smooth = both & (move <= SMOOTH * reach + _TINY * size)
        jumps.extend(a_p[both & ~smooth])
        if smooth.any():
            moves.append(float(np.max(move[smooth])))
        crossing = smooth & (np.sign(a_det) != np.sign(b_det))
        t = a_det[crossing] / (a_det[crossing] - b_det[crossing])
        crossings.append((np.stack([q[crossing] for q in a_q], axis=1),
                          np.stack([q[crossing] for q in b_q], axis=1), t,
                          np.minimum(np.abs(a_det[crossing]), np.abs(b_det[crossing]))))
        for end_p, end_q, edge in ((a_p, a_q, a_valid & ~b_valid), (b_p, b_q, b_valid & ~a_valid)):
            locks.extend(end_p[edge])
            lock_q.extend(np.stack([q[edge] for q in end_q], axis=1))
    singular = singular_q = np.zeros((0, 2))
    if crossings:   # det J at the zero interpolated: small at a zero, large at a pole
        qa, qb, t, least = (np.concatenate(parts) for parts in zip(*crossings, strict=True))
        q = qa + t[:, None] * (qb - qa)
        one, two = _columns(scene, [q[:, 0], q[:, 1]])
        here, k0 = (_xy(z, (-1,)) for z in read(one))
        k1 = _xy(read(two)[1], (-1,))
        det_here = np.abs(k0[:, 0] * k1[:, 1] - k0[:, 1] * k1[:, 0])
        zero = np.asarray(one.valid, dtype=bool).reshape(-1) & (det_here <= ZERO * least)
        singular, singular_q = here[zero], q[zero]
        jumps.extend(here[~zero])
    at_rest = [np.zeros(1)] * 2
    start = _xy(read(_at(scene, [np.array([d.start]) for d in drivers], at_rest))[0], ())
    return Workspace(scene.name, point, scene.units, (drivers[0].name, drivers[1].name),
                     (axes[0], axes[1]), valid, p, det,
                     singular, singular_q,
                     np.array(locks, dtype=np.float64).reshape(-1, 2),
                     np.array(lock_q, dtype=np.float64).reshape(-1, 2),
                     np.array(jumps, dtype=np.float64).reshape(-1, 2), max(moves), start, lift)


def _xy(z: Any, shape: tuple[int, ...]) -> Array:
    """Return complex values as (x, y) pairs of ``shape + (2,)``."""
    z = np.asarray(z, dtype=np.complex128)
    return np.stack((z.real, z.imag), axis=-1).reshape(shape + (2,))


def _two_drivers(scene: Scene) -> Any:
    """Return the scene's drivers, two, or refuse: a point in the plane has two coordinates."""
    drivers = scene.drivers
    if len(drivers) != 2:
        msg = (f'Expected a scene with two drivers for --workspace (a point has two '
               f'coordinates), got {scene.name} with {len(drivers)}: '
               f'{", ".join(d.name for d in drivers)}')
        raise SceneError(msg)
    return drivers


def _pairs(x: Any, axis: int, wrap: bool) -> tuple[Any, Any]:
    """Return (each grid point's value, its next neighbour's along ``axis``): every edge once."""
    if wrap:
        return x, np.roll(x, -1, axis=axis)
    head = tuple(slice(0, -1) if k == axis else slice(None) for k in range(2))
    tail = tuple(slice(1, None) if k == axis else slice(None) for k in range(2))
    return x[head], x[tail]


def _columns(scene: Scene, q: list[Any]) -> tuple[Any, Any]:
    """Return the states at drivers' values ``q`` at a unit speed of each driver (J's columns)."""
    zeros = np.zeros(q[0].shape)
    ones = np.ones(q[0].shape)
    return _at(scene, q, [ones, zeros]), _at(scene, q, [zeros, ones])


def _at(scene: Scene, q: list[Any], speeds: list[Any]) -> Any:
    """Return the state at drivers' values ``q`` and ``speeds``, at no acceleration, any bound."""
    zeros = np.zeros(q[0].shape)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', NearSingularWarning)
        return solve(scene, q, speeds, [zeros, zeros], max_error=math.inf)
