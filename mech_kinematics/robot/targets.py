# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""A robot described in URDF driven from its output: targets in the URDF's names and frames.

A *target* of a robot is a joint's value (any joint :meth:`.Robot.solve`
answers: an actuated one, a passive joint of a loop, a mimic joint; rad or m
from its zero, as the URDF writes it) or one coordinate of a link's frame
origin in the root frame, ``FRAME.x``, ``FRAME.y`` or ``FRAME.z`` (m). A
robot with ``n`` actuated joints takes ``n`` targets; :func:`robot_targets`
builds the map the inverse of :mod:`mech_kinematics.solver.inverse` solves
(the same Newton continuation from the reference pose as a scene's), and
:meth:`.Robot.solve_targets` answers the actuated joints' values and rates,
every joint, and with ``<inertial>`` the efforts of that motion.

A frame's origin is the URDF's own tree kinematics, walked from the root as
:meth:`.Description.transforms` walks it (the same products: the position
is that function's to the bit), with the joints' values the robot answers
(a joint no loop moves and no rule sets stands at 0, as joint_state_publisher
draws it). Its velocity and acceleration are carried down the chain in
closed form, each joint adding its rate about (or along) its axis:

- revolute about ``e``: ``w += e qd``, ``alpha += e qdd + w x e qd``, the
  origin not moved;
- prismatic along ``e`` by ``d = e q``: ``v += e qd + w x d``,
  ``a += e qdd + alpha x d + w x (w x d) + 2 w x e qd``;
- each ``<origin>`` offset ``r`` (rotated into the root frame): ``v += w x r``,
  ``a += alpha x r + w x (w x r)``.

Bounds, to first order, from the joints' own bounds ``b`` (rad, m): with
``R`` the chain's reach (its offsets' and prismatic values' lengths summed,
at least the loops' size: no origin in the chain is farther from the frame)
and ``c`` = ``R`` for a revolute joint, 1 for a prismatic one,
``|dp/dq| <= c``, ``|d2p/dq dq'| <= 2 c c' / R`` and ``|d3p/dq3| <= 4 c c' c'' / R^2``;
so ``bp = sum c b_q``, ``bv = sum c b_qd + 2 S1 bp / R``,
``ba = sum c b_qdd + 2 S2 bp / R + 4 S1 (sum c b_qd) / R + 4 S1^2 bp / R^2`` with
``S1 = sum c |qd|``, ``S2 = sum c |qdd|``, each plus the rounding of the
walk (``16 (k + 1) eps`` of the terms' scale over ``k`` joints).

:func:`frame_workspace` maps where a link frame's origin goes over the grid
of a two-driver robot's actuated joints (``check ROBOT.urdf --workspace
FRAME``): the origin is fixed in its scene body's frame
(:meth:`.Planar.link_frame`), so the scene's array path solves it
(:func:`mech_kinematics.geometry.workspace.workspace`, with its singular
curves), and the loop's plane is lifted into the root frame
(:attr:`.Planar.lifts`, through the ground link's pose); the drivers' axes
are the URDF joints' values.

Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace
import math
from typing import Any, TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from ..bounds import MAX_ERROR
from ..errors import AssemblyError, SceneError, TargetError
from ..solver.inverse import continue_to, Inverse, TargetMap

if TYPE_CHECKING:
    from .description import Description
    from .robot import Robot, RobotState
    from ..geometry.workspace import Workspace

__all__ = ['AXES', 'frame_motion', 'frame_workspace', 'joint_sweep', 'robot_targets',
           'solve_robot_targets']

#: A frame target's coordinates, in the root frame.
AXES = ('x', 'y', 'z')
_EPS = float(np.finfo(np.float64).eps)


def frame_motion(description: Description, link: str, values: Mapping[str, float],
                 rates: Mapping[str, tuple[float, float]],
                 bounds: Mapping[str, tuple[float, float, float]], size: float
                 ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Return ``link``'s origin in the root frame: (position, velocity, acceleration) and bounds.

    ``values``: every moving joint's value (:meth:`.Description.pose`);
    ``rates``: a joint's (speed, acceleration), 0 where left out; ``bounds``:
    a joint's (position, speed, acceleration) bounds, 0 where left out (a
    value that is exact); ``size``: the loops' size, the least reach. Returns
    two arrays of shape (3, 3): rows position, velocity, acceleration.
    """
    m = np.eye(4)
    w = alpha = v = a = (0.0, 0.0, 0.0)     # in plain floats: 3-vectors cost NumPy calls
    chain = description.chain(link)
    moving = []     # (angular, |qd|, |qdd|, b_q, b_qd, b_qdd)
    reach = 0.0
    for joint in chain:
        mj = m @ joint.origin
        r = tuple((mj[:3, 3] - m[:3, 3]).tolist())
        v = _add(v, _cross(w, r))
        a = _add(a, _cross(alpha, r), _cross(w, _cross(w, r)))
        reach += math.hypot(*joint.origin[:3, 3].tolist())
        if joint.type is None:
            m = mj
            continue
        x = float(values.get(joint.name, 0.0))
        xd, xdd = rates.get(joint.name, (0.0, 0.0))
        e = tuple((mj[:3, :3] @ np.asarray(joint.axis, dtype=np.float64)).tolist())
        if joint.type.angular:
            alpha = _add(alpha, _scaled(e, xdd), _scaled(_cross(w, e), xd))
            w = _add(w, _scaled(e, xd))
        else:
            d = _scaled(e, x)
            v = _add(v, _scaled(e, xd), _cross(w, d))
            a = _add(a, _scaled(e, xdd), _cross(alpha, d), _cross(w, _cross(w, d)),
                     _scaled(_cross(w, e), 2.0 * xd))
            reach += abs(x)
        m = m @ joint.motion(x)
        moving.append((joint.type.angular, abs(xd), abs(xdd),
                       *bounds.get(joint.name, (0.0, 0.0, 0.0))))
    motion = np.array((m[:3, 3], v, a), dtype=np.float64)
    big_r = max(reach, size)
    c = np.array([big_r if item[0] else 1.0 for item in moving])
    table = np.array([item[1:] for item in moving]).reshape(-1, 5)
    s1, s2 = float(c @ table[:, 0]), float(c @ table[:, 1])
    bq, bqd, bqdd = (float(c @ table[:, k]) for k in (2, 3, 4))
    rounding = 16.0 * (len(chain) + 1) * _EPS
    bp = bq + rounding * big_r
    bv = bqd + 2.0 * s1 * bp / big_r + rounding * s1
    ba = (bqdd + 2.0 * s2 * bp / big_r + 4.0 * s1 * bqd / big_r
          + 4.0 * s1 * s1 * bp / big_r ** 2 + rounding * (s2 + 2.0 * s1 * s1 / big_r))
    return motion, np.repeat([[bp], [bv], [ba]], 3, axis=1)


def robot_targets(robot: Robot, names: Sequence[str]) -> TargetMap:
    """Return the target map of ``robot`` for ``names`` (its joints and ``FRAME.x|y|z``).

    Raises :class:`~mech_kinematics.errors.TargetError` for a name the robot
    does not answer, a frame that is not one of its links, or a count other
    than its actuated joints'.
    """
    description = robot.description
    drivers = tuple(robot.actuated)
    if len(names) != len(drivers):
        msg = (f'Expected as many targets as {robot.name} has actuated joints '
               f'({len(drivers)}: {", ".join(drivers)}), got {len(names)}: '
               f'{", ".join(names) or "none"}')
        raise TargetError(msg)
    if len(set(names)) != len(names):
        msg = f'Expected each target once, got {", ".join(names)}'
        raise TargetError(msg)
    readers: list[tuple[str, str, int]] = []    # ('joint', name, 0) or ('frame', link, axis)
    angular: list[bool] = []
    for name in names:
        link, dot, axis = name.rpartition('.')
        if robot.knows(name):
            readers.append(('joint', name, 0))
            angular.append(robot.joint_type(name).angular)
        elif dot and link in description.links and axis in AXES:
            readers.append(('frame', link, AXES.index(axis)))
            angular.append(False)
        else:
            msg = (f'Expected a target to be a joint {robot.name} answers '
                   f'({", ".join(robot.joint_names)}) or a coordinate of a link frame\'s '
                   f'origin in the root frame (FRAME.x, FRAME.y, FRAME.z), got {name!r}')
            raise TargetError(msg)
    probe = robot.solve(max_error=math.inf, forces=False)
    size = float(probe.state.error_bound.size)

    def evaluate(q: Sequence[float], qd: Sequence[float], qdd: Sequence[float],
                 max_error: float) -> tuple[RobotState, Any, Any]:
        answer = robot.solve(dict(zip(drivers, q, strict=True)),
                             dict(zip(drivers, qd, strict=True)),
                             dict(zip(drivers, qdd, strict=True)),
                             max_error=max_error, forces=False)
        values = np.empty((len(readers), 3))
        bounds = np.empty((len(readers), 3))
        frames: dict[str, tuple[Any, Any]] = {}
        for i, (table, key, axis) in enumerate(readers):
            if table == 'joint':
                j = answer.joints[key]
                values[i] = (j.position, j.velocity, j.acceleration)
                bounds[i] = answer.bounds[key]
                continue
            if key not in frames:
                frames[key] = frame_motion(
                    description, key,
                    description.pose({n: float(j.position) for n, j in answer.joints.items()}),
                    {n: (float(j.velocity), float(j.acceleration))
                     for n, j in answer.joints.items()},
                    {n: tuple(float(x) for x in b) for n, b in answer.bounds.items()}, size)
            motion, motion_bound = frames[key]
            values[i] = motion[:, axis]
            bounds[i] = motion_bound[:, axis]
        return answer, values, bounds

    def text(index: int, value: float) -> str:
        return f'{value:.6g} rad' if angular[index] else f'{value:.6g} m'

    def elbow(answer: RobotState, name: str) -> float:
        """Return joint ``name``'s value wrapped to (-pi, pi], rad."""
        return float(math.remainder(float(answer.joints[name].position), math.tau))

    return TargetMap(
        targets=tuple(names), drivers=drivers, target_angular=tuple(angular),
        driver_angular=tuple(robot.joint_type(d).angular for d in drivers),
        target_scales=tuple(1.0 if a else size for a in angular),
        driver_scales=tuple(1.0 if robot.joint_type(d).angular else size for d in drivers),
        evaluate=evaluate, text=text,
        elbows=tuple(n for n in probe.joints if n not in drivers
                     and robot.joint_type(n).angular and not _constant(robot, n)),
        elbow=elbow, driver_domains=tuple(joint_sweep(robot, d, size) for d in drivers))


def joint_sweep(robot: Robot, name: str, size: float) -> tuple[float, float]:
    """Return where an actuated joint's start poses are sought: a turn, or its limits.

    A revolute joint: a turn about its reference value; a prismatic one: its
    limits, else ``size`` (the loops' size) either way of its reference value.
    """
    start = float(robot.start(name))
    if robot.joint_type(name).angular:
        return (start - math.pi, start + math.pi)
    limits = robot.description.joints[name].limits
    return limits if limits is not None else (start - size, start + size)


def solve_robot_targets(robot: Robot, targets: Mapping[str, float],
                        speeds: Mapping[str, float] | None = None,
                        accels: Mapping[str, float] | None = None, *,
                        start: Mapping[str, float] | None = None,
                        max_error: float = MAX_ERROR,
                        forces: Mapping[str, float] | None = None,
                        gravity: Sequence[float] | None = None,
                        loads: Sequence[Any] = (),
                        branch: Mapping[str, int] | None = None) -> Inverse:
    """Solve ``robot`` driven from its targets: :meth:`.Robot.solve_targets`."""
    names = tuple(targets)
    tmap = robot_targets(robot, names)
    for what, given in (('speeds', speeds), ('accels', accels)):
        unknown = [name for name in given or () if name not in names]
        if unknown:
            msg = f'Expected {what} of the targets ({", ".join(names)}), got {", ".join(unknown)}'
            raise TargetError(msg)
    stray = [name for name in start or () if name not in robot.actuated]
    if stray:
        msg = (f'Expected a start of the actuated joints ({", ".join(robot.actuated)}), got '
               f'{", ".join(stray)}')
        raise TargetError(msg)
    first = [(start or {}).get(name, robot.start(name)) for name in robot.actuated]
    inverse = continue_to(tmap, [targets[n] for n in names], first,
                          [(speeds or {}).get(n, 0.0) for n in names],
                          [(accels or {}).get(n, 0.0) for n in names],
                          max_error=max_error, forces=forces, branch=branch)
    if robot.forces is None:
        return inverse
    q, qd, qdd = (dict(zip(robot.actuated, (float(x) for x in inverse.motion[:, k]),
                           strict=True)) for k in range(3))
    try:       # the efforts of that motion, and its reactions
        answer = robot.solve(q, qd, qdd, max_error=max_error, gravity=gravity, loads=loads)
    except AssemblyError as error:
        msg = f'Expected an answer whose forces can be trusted, got {error}'
        raise TargetError(msg) from None
    return replace(inverse, answer=answer)


def frame_workspace(robot: Robot, link: str, grid: int | None = None) -> Workspace:
    """Map the workspace of ``link``'s frame origin in the root frame (module text).

    Over the grid of the robot's two actuated joints (``grid`` points each,
    default :data:`~mech_kinematics.geometry.region.GRID`), told in the root
    frame with the drivers under their URDF names and values (rad or m).

    Raises
    ------
    SceneError
        A link that is not the robot's or that its loops do not move, a robot
        whose loops are not driven by two actuated joints of their own (a
        mimic among the drivers), a link of a loop only one of them drives, or
        one that assembles nowhere on the grid.
    """
    from ..geometry.frames import carried_motion, frames_from_scene
    from ..geometry.region import GRID
    from ..geometry.workspace import workspace

    description, planar = robot.description, robot.planar
    if link not in planar.planes:
        moved = ', '.join(list(planar.planes)[:8]) + (', ...' if len(planar.planes) > 8 else '')
        what = ('which its loops do not move' if link in description.links
                else 'which is not one of its links')
        msg = (f'Expected --workspace to name a link frame the loops of {robot.name} move '
               f'({moved}) or a point of its scene, got {link!r}, {what}')
        raise SceneError(msg)
    drivers = planar.drivers
    if len(drivers) != 2 or any(d.mimic is not None for d in drivers):
        msg = (f'Expected a robot whose loops two actuated joints drive for --workspace (a '
               f'point of the plane has two coordinates), got {robot.name} driven by '
               f'{", ".join(d.name + (" (mimic)" if d.mimic else "") for d in drivers)}')
        raise SceneError(msg)
    body, _, local = planar.link_frame(link)
    index, e, o = planar.lifts[link]
    mine = planar.mechanisms[index]['drivers']
    if set(mine) != {d.name for d in drivers}:
        msg = (f'Expected --workspace to name a link of the loop both actuated joints drive, '
               f'got {link!r}, on a loop driven by {", ".join(mine)} alone')
        raise SceneError(msg)
    probe = robot.solve(max_error=math.inf, forces=False)
    frames = description.transforms(description.pose(
        {n: float(j.position) for n, j in probe.joints.items()}))
    ground = frames[planar.mechanisms[index]['ground']]
    rotation = ground[:3, :3]
    spec = frames_from_scene(robot.scene, [body])[0]
    at = (float(local[0]), float(local[1]))
    ws = workspace(robot.scene, link, lambda state: carried_motion(spec, at, state),
                   GRID if grid is None else grid, (rotation @ e, rotation @ o + ground[:3, 3]))
    # The scene's drivers are the URDF joints (DriverMap.joint_value), d joint = d scene / sigma.

    def joints(values: Any) -> Any:
        q = np.asarray(values, dtype=np.float64).reshape(-1, 2)
        return np.stack([d.joint_value(q[:, k]) for k, d in enumerate(drivers)], axis=1)

    return replace(ws, scene=robot.name, drivers=(drivers[0].name, drivers[1].name),
                   axes=tuple(d.joint_value(ws.axes[k]) for k, d in enumerate(drivers)),
                   det=ws.det * float(drivers[0].sigma * drivers[1].sigma),
                   singular_drivers=joints(ws.singular_drivers),
                   lock_drivers=joints(ws.lock_drivers))


def _constant(robot: Robot, joint: str) -> bool:
    """Return whether a loop joint's value cannot change: both its links turn as one body.

    A URDF joint closing a loop between two links the scene welds (Gepetto's
    ``closedloop1_A``, a 6d closure's joint) follows one coordinate minus
    itself: no working mode reads it.
    """
    item = robot.planar.joints.get(joint)
    return item is not None and item.child is not None and item.child == item.parent \
        and item.child_ref == item.parent_ref


def _cross(p: tuple[float, ...], q: tuple[float, ...]) -> tuple[float, float, float]:
    return (p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0])


def _add(*vectors: tuple[float, ...]) -> tuple[float, float, float]:
    return (sum(u[0] for u in vectors), sum(u[1] for u in vectors),
            sum(u[2] for u in vectors))


def _scaled(p: tuple[float, ...], k: float) -> tuple[float, float, float]:
    return (p[0] * k, p[1] * k, p[2] * k)
