# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The plan compiler: a scene's items ordered by dependency, as steps, keeping what is needed.

It asks each item (:class:`~.base.Item`) what it defines, what it needs and
for its step; it never tests which kind an item is.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
import heapq
import math
from typing import Any, TYPE_CHECKING

import numpy as np

from .base import Item, Step
from .context import _Context
from .geneva import _index_step
from .graph import build_graph, Graph, JointType
from .model import _check_finite, _check_name, _names, Where
from .rubbing import _rub_steps, _RubStep
from ..bounds import U
from ..errors import SceneError

if TYPE_CHECKING:
    from .mechanism import Scene


@dataclass(frozen=True)
class _Plan:
    """A scene compiled to an ordered list of steps.

    ``crank`` is the first driver's step (a crank's, in a scene with one crank)
    and ``extra`` the other drivers' steps, in scene order: each runs as
    ``run(ctx, position, speed, accel)`` before the steps.
    """

    crank: Any
    steps: tuple[Step, ...]
    ground: dict[str, complex]
    joint_types: dict[str, JointType]
    output_joints: tuple[str, ...]
    output_points: tuple[str, ...]
    graph: Graph
    rubs: tuple[_RubStep, ...] = ()
    extra: tuple[Any, ...] = ()

    @property
    def drivers(self) -> tuple[Any, ...]:
        """Every driver's step, in scene order."""
        return (self.crank, *self.extra)


class _Names:
    """The names defined so far, for items to check their references (:class:`~.base.Names`)."""

    def __init__(self, kinds: Mapping[str, str], ground: Mapping[str, complex]) -> None:
        self.kinds = kinds
        self._ground = ground

    def point(self, name: str, what: str, where: Where) -> str:
        """Return ``name`` if it is a known point, else raise a :class:`SceneError`."""
        kinds = self.kinds
        if name not in kinds:
            msg = f'Expected {what} to be a known point, got unknown "{name}"'
            raise SceneError(msg, where)
        if kinds[name] != 'point':
            msg = f'Expected {what} to be a point, got {kinds[name]} "{name}"'
            raise SceneError(msg, where)
        return name

    def ground(self, name: str, what: str, where: Where) -> str:
        """Return ``name`` if it is a ground point, else raise a :class:`SceneError`."""
        self.point(name, what, where)
        if name not in self._ground:
            msg = f'Expected {what} to be a ground point, got moving point "{name}"'
            raise SceneError(msg, where)
        return name

    def link(self, name: str, what: str, where: Where) -> str:
        """Return ``name`` if it is a known link, else raise a :class:`SceneError`."""
        kinds = self.kinds
        if name not in kinds or kinds[name] != 'link':
            got = f'unknown "{name}"' if name not in kinds else f'{kinds[name]} "{name}"'
            msg = f'Expected {what} to be a link, got {got}'
            raise SceneError(msg, where)
        return name


class _Local(dict[str, dict[str, complex]]):
    """:attr:`~.base.Placing.local`, which also keeps the links each point is fixed on.

    Items write a link's points as a plain dict (``local[link] = {...}``) and add
    carried points to it (``local[link][point] = ...``); ``carriers[point]``
    lists, in that order, the links a point was fixed on: what an RRR asks to
    find a link carrying both its starts without reading every link.
    """

    def __init__(self) -> None:
        super().__init__()
        self.carriers: dict[str, list[str]] = {}

    def __setitem__(self, link: str, fixed: dict[str, complex]) -> None:
        super().__setitem__(link, _Fixed(self.carriers, link, fixed))

    def update(self, *others: Any, **more: dict[str, complex]) -> None:
        for link, fixed in dict(*others, **more).items():
            self[link] = fixed


class _Fixed(dict[str, complex]):
    """The points fixed on one link (:class:`_Local`): adding one records its carrier."""

    def __init__(self, carriers: dict[str, list[str]], link: str,
                 fixed: Mapping[str, complex]) -> None:
        super().__init__()
        self._carriers, self._link = carriers, link
        for point, where in fixed.items():
            self[point] = where

    def __setitem__(self, point: str, where: complex) -> None:
        if point not in self:
            self._carriers.setdefault(point, []).append(self._link)
        super().__setitem__(point, where)


@dataclass
class _Placing:
    """What items build their steps from (:class:`~.base.Placing`)."""

    ground: Mapping[str, complex]
    local: dict[str, dict[str, complex]]    # a _Local
    slot: dict[str, tuple[str, str]]
    size: float
    scene: Any
    carriers: Mapping[str, list[str]]       # the _Local's
    intermittent: Callable[[Any, Any], Step] = _index_step
    #: The steps placed so far run on an array of the first driver's positions (at unit
    #: speed): what a step that follows its branch along the crank's turn reads (a triad's).
    trace: Callable[[Any], Any] | None = None


def _compile(scene: Scene, joints: tuple[str, ...] | None,
             points: tuple[str, ...] | None) -> _Plan:
    """Order the scene's steps by dependency and keep those the outputs need."""
    kinds: dict[str, str] = {}

    def define(name: str, kind: str, where: Where) -> None:
        if name in kinds:
            msg = f'Expected every name to be used once, got "{name}" twice'
            raise SceneError(msg, where)
        kinds[name] = kind

    ground = {}
    for name, (x, y) in scene.ground.items():
        _check_name(name, 'a ground point name', (scene, f'ground.{name}'))
        _check_finite(x, f'ground point "{name}" x', (scene, f'ground.{name}'))
        _check_finite(y, f'ground point "{name}" y', (scene, f'ground.{name}'))
        define(name, 'point', (scene, f'ground.{name}'))
        ground[name] = complex(x, y)
    drivers = scene.drivers
    driver_steps = tuple(driver.step(ground) for driver in drivers)
    joint_types: dict[str, JointType] = {}
    for driver in drivers:
        for name, kind in driver.defined():
            define(name, kind, (driver, {'point': 'point', 'link': 'link'}.get(kind, kind)))
        joint_types[driver.name] = driver.joint_type
    for dyad in scene.dyads:
        for name, kind, where in dyad.defined():
            define(name, kind, where)
        joint_types.update(dyad.joint_types())
    for carried in scene.points:
        for name, kind, where in carried.defined():
            define(name, kind, where)

    size = max([*(driver.reach for driver in drivers), diameter(ground.values())]
               + [length for d in scene.dyads for length in d.lengths()])

    # Local coordinates of the points fixed on each link, in the frame at the
    # link's start with x along the link; and the slot pin of each RPR lever.
    local = _Local()
    for driver in drivers:
        local.update(driver.local(ground))
    steps: list[Step] = []

    def trace(positions: Any) -> _Context:
        ctx = _Context(positions, True)
        ctx.points.update({name: (z, 0j, 0j, U * abs(z), 0.0, 0.0) for name, z in ground.items()})
        driver_steps[0].run(ctx, positions, np.float64(1.0), np.float64(0.0))
        for step in steps:
            step.run(ctx)
        return ctx

    placing = _Placing(ground, local, {}, size, scene, local.carriers, trace=trace)
    names = _Names(kinds, ground)
    owners: list[Item] = []  # the item of each step
    produces: dict[str, int] = {}  # point, link or slider -> index of its step

    def place(item: Item) -> tuple[str, ...]:
        """Append the step of ``item``, whose prerequisites are known; return what it adds."""
        index = len(steps)
        step = item.place(placing)
        steps.append(step)
        owners.append(item)
        for name in step.defines:
            produces[name] = index
        return step.defines

    # Place each item as soon as what it starts from is known, the earliest in
    # the file first (file order wherever it is free): a heap of the ready
    # items and, per name, the items waiting for it. O(n log n) in all.
    pending: list[Item] = [*scene.dyads, *scene.points]
    known = {*ground, *(name for step in driver_steps for name in step.defines)}
    waiting: dict[str, list[int]] = {}
    missing = [0] * len(pending)
    for index, item in enumerate(pending):
        for name in item.prerequisites(names) - known:
            waiting.setdefault(name, []).append(index)
            missing[index] += 1
    ready = [index for index, count in enumerate(missing) if count == 0]  # sorted: a heap
    placed = 0
    while ready:
        for name in place(pending[heapq.heappop(ready)]):
            known.add(name)
            for index in waiting.pop(name, ()):
                missing[index] -= 1
                if missing[index] == 0:
                    heapq.heappush(ready, index)
        placed += 1
    if placed < len(pending):
        left = [item for index, item in enumerate(pending) if missing[index]]
        keys = [item.key for item in left]
        msg = f'Expected dyads and points solvable in order, got a cycle among [{_names(keys)}]'
        raise SceneError(msg, (left[0], ''))

    users: dict[str, list[Item]] = {driver.name: [] for driver in drivers}
    for item, step in zip(owners, steps, strict=True):
        for name in users.keys() & set(step.uses):
            users[name].append(item)
    for driver in drivers:
        driver.check_used(users[driver.name])
    order = [*ground, *(name for driver in drivers for name, kind in driver.defined()
                        if kind == 'point'),
             *(name for step in steps for name in step.new_points)]
    all_joints = tuple(joint_types)
    out_joints = all_joints if joints is None else tuple(joints)
    out_points = tuple(order) if points is None else tuple(points)
    for name in out_joints:
        if kinds.get(name) not in ('link', 'slider', 'actuator', 'motor'):
            got = f'unknown "{name}"' if name not in kinds else f'{kinds[name]} "{name}"'
            msg = f'Expected outputs.joints to list links and sliders, got {got}'
            raise SceneError(msg, (scene, 'outputs.joints'))
    for name in out_points:
        if kinds.get(name) != 'point':
            got = f'unknown "{name}"' if name not in kinds else f'{kinds[name]} "{name}"'
            msg = f'Expected outputs.points to list points, got {got}'
            raise SceneError(msg, (scene, 'outputs.points'))

    fragments = tuple(item.fragment() for item in (*drivers, *scene.dyads, *scene.points))
    graph = build_graph(fragments, kinds, ground, (driver.name for driver in drivers))
    rubs = _rub_steps(scene, kinds, graph)

    # Keep only the steps that the outputs (and the pins' rubbing) depend on.
    needed: set[int] = set()
    todo = [produces[name] for name in (*out_joints, *out_points) if name in produces]
    todo += [produces[name] for rub in rubs for name in rub.uses if name in produces]
    while todo:
        index = todo.pop()
        if index in needed:
            continue
        needed.add(index)
        step = steps[index]
        # (the drivers are no steps: their names are produced by none)
        todo.extend(produces[name] for name in step.requires if name in produces)
    kept = tuple(step for index, step in enumerate(steps) if index in needed)
    return _Plan(driver_steps[0], kept, ground,
                 {name: joint_types[name] for name in out_joints}, out_joints, out_points,
                 graph, rubs, driver_steps[1:])


def diameter(points: Iterable[complex]) -> float:
    """Return the largest distance between two of ``points``, m (0 for fewer than two).

    The farthest pair is a pair of vertices of the convex hull (Andrew's
    monotone chain), found among its antipodal pairs (rotating calipers, as in
    KACTL's ``hullDiameter``): O(n log n) instead of all n^2 pairs, and the
    same value, each candidate being the same ``abs(a - b)``. The orientation
    tests run on the points scaled by a power of two (exact) to at most 2**500,
    so that their products cannot overflow.
    """
    unique = sorted({(z.real, z.imag) for z in points})
    if len(unique) < 2:
        return 0.0
    largest = max(max(abs(x), abs(y)) for x, y in unique)
    scale = 2.0 ** (500 - math.frexp(largest)[1]) if largest > 2.0**500 else 1.0
    scaled = [(x * scale, y * scale) for x, y in unique]

    def turn(o: int, a: int, b: int) -> float:
        (ox, oy), (ax, ay), (bx, by) = scaled[o], scaled[a], scaled[b]
        return (ax - ox) * (by - oy) - (ay - oy) * (bx - ox)

    hull: list[int] = []  # indices into unique, counter-clockwise
    for run in (range(len(unique)), range(len(unique) - 1, -1, -1)):
        chain: list[int] = []
        for k in run:
            while len(chain) >= 2 and turn(chain[-2], chain[-1], k) <= 0:
                chain.pop()
            chain.append(k)
        hull += chain[:-1]
    at = [complex(*unique[k]) for k in hull]
    edge = [complex(*scaled[k]) for k in hull]
    n = len(hull)
    if n < 3:  # all on one line: its two ends
        return abs(at[0] - at[-1])
    best, i, j = 0.0, 0, 1
    while i < j:
        for _ in range(n):  # advance j while the edge from it turns away from edge i
            best = max(best, abs(at[i] - at[j]))
            u, v = edge[i + 1] - edge[i], edge[(j + 1) % n] - edge[j]
            if v.real * u.imag - v.imag * u.real >= 0:
                break
            j = (j + 1) % n
        i += 1
    return best
