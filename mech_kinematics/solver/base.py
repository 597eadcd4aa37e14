# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""What every step kind provides: the protocol between a kind and the rest of the solver.

A mechanism is a driving crank followed by *items* solved one after another
in closed form: dyads (``RRR``, ``RRP``, ``RPR``, ...) and points carried by
links. Each kind of item is one module of this package holding two classes:

- the **item**, a frozen dataclass whose fields are the scene's keys for it
  (:class:`Item`): it validates them, says which names it defines and which
  it needs, and builds its step (:meth:`Item.place`);
- the **step** (:class:`Step`), run once per solve: it reads the values known
  so far from the solve's context and writes what it defines, each value with
  its error bound (:mod:`mech_kinematics.bounds`).

The plan compiler, the rescaling, the solver and the tools only call these
methods; none of them tests which kind an item is. ``KINDS`` maps the
scene's ``type:`` to the item class
(:mod:`.registry`).

The kernel subset of ``Step.run``
---------------------------------
The compiler (:mod:`.compiler`: the node's tick and ``mk.solve``'s compiled
paths) partially evaluates the bodies of every step's kernels
(:meth:`Step.kernels`: ``run`` itself unless the step names its scalar path)
into one straight-line function, so they must be written in the subset that
it understands. Anything else makes the scene fall back to the general
solver, with the reason (:class:`.compiler.NotCompiled`), and
``test_compiler`` fails for a kind that falls back:

- a kernel is a plain function of ``(self, ctx)`` (a driver's, a crank's or
  an actuator's, of ``(self, ctx, position, speed, accel)``): no ``for``/``while`` loop,
  ``return``, ``try``, ``with``, ``yield``, nested ``def``, ``global`` or
  ``nonlocal``; lambdas only without arguments (deferred messages);
- the context is used only as ``ctx.vector``, ``ctx.angle``, ``ctx.turns``,
  ``ctx.shown``, ``ctx.points[...]``, ``ctx.links[...]``,
  ``ctx.sliders[...]``, ``ctx.measures[...]`` (read or assigned whole),
  ``ctx.check(...)``, ``ctx.check_margin(...)``, and ``ctx.engage(...)``
  and ``ctx.note(...)`` as statements (side facts: the tick drops them);
  table keys are ``self.<attribute>`` (a name fixed when the step is built);
- ``self.<attribute>`` is read only (it becomes a constant); helpers whose
  body is one ``return <expression>`` (as ``_dot`` of :mod:`.context`) are
  written out in place; other names are the kernel module's globals;
- a kernel may call a method of its step that takes ``(self, ctx, ...)``, in
  the same subset, as a statement (``r1, r2 = self._meet(ctx, d, ...)``, or
  on its own): it is written out in place, and may end with one ``return``
  (the two RRR kinds share their kernel so).

``ctx.vector`` is ``False`` in the tick function: a branch it decides is
dropped before the rest is specialized (the array path may use anything), so
a step keeps its scalar and array paths in one ``run``.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Collection, Iterator, Mapping
import math
from typing import Any, ClassVar, Protocol, TYPE_CHECKING

import numpy as np

from ..errors import SceneError

if TYPE_CHECKING:
    from .context import _Context
    from .model import Branch, Link, SceneUnits, Where
    from .state import Engagement

#: A body at a pin, for rubbing: ``('link', name)``, ``('still', name)`` or ``('block', lever)``.
Body = tuple[str, str]
#: Where a joint's frame sits: (joint, origin point, joint whose position is its angle or
#: ``None``, fixed angle in rad when that is ``None``); see :mod:`mech_kinematics.geometry.frames`.
Frame = tuple[str, str, str | None, float]
#: A body an item adds: (name, kind: ``'link'``, ``'lever'`` or ``'slider'``, the points
#: fixed on it, and for a slider block the body it slides on, ``ground`` standing for
#: the ground; else ``None``); see :mod:`mech_kinematics.geometry.instant_centres`.
Member = tuple[str, str, tuple[str, ...], str | None]
#: A relative motion on a body, for the polygons: (body, start point, end point, slider):
#: the end moves on the body about the start; with a slider, the end is a pin sliding in
#: the body and the motion is that of the body's point coinciding with it (b'), then the
#: slider's sliding to the pin; see :mod:`mech_kinematics.geometry.diagrams`.
Edge = tuple[str, str, str, str | None]


class Step(ABC):
    """The part of a step kind that runs in every solve.

    Attributes
    ----------
    label : str
        The dyad's label in messages and failures, e.g. ``'RRR C'``.
    key : str
        The key of its near-singularity measure (``State.singularity``).
    uses : tuple of str
        The points (and links) its ``run`` reads.
    defines : tuple of str
        The names it computes (points, links, sliders).
    new_points : tuple of str
        The points among ``defines``, in the order they are reported.
    unit : float
        Metres per length unit of the plan, for messages (the solver sets it
        for a rescaled scene).
    owner : str or None
        For a step that moves no link of its own (a carried point): the link
        whose dyad's label its values carry; else ``None``.
    dyad : object
        The scene item it was built from.
    intermittent : bool
        Whether it is an intermittent lever (``State.intermittent``).
    """

    label: str = ''
    key: str = ''
    uses: tuple[str, ...] = ()
    defines: tuple[str, ...] = ()
    new_points: tuple[str, ...] = ()
    unit: float = 1.0
    owner: str | None = None
    dyad: Any = None
    intermittent: ClassVar[bool] = False

    @abstractmethod
    def run(self, ctx: _Context) -> None:
        """Compute what the step defines into ``ctx`` (see the module's kernel subset)."""

    @classmethod
    def kernels(cls) -> tuple[Callable[..., None], ...]:
        """Return the functions whose bodies, in order, are ``run`` on one crank angle.

        The tick compiles these (the kernel subset above); by default ``run``
        itself. A step whose ``run`` dispatches to a scalar path of its own
        names that path here instead.
        """
        return (cls.run,)

    def margins(self, points: Mapping[str, tuple[Any, ...]]) -> tuple[tuple[Any, Any], ...]:
        """Return (margin, rate) of each condition under which it closes, from its inputs.

        ``points`` is a solve's table of points (:class:`._Context`: position
        and velocity first, velocities at unit crank speed). A margin is
        positive where the step closes and crosses zero where it stops closing
        (``run`` refuses where one is not positive, and within rounding of
        zero); its rate is its derivative per radian of crank angle. Complex
        scalars or arrays in, floats or arrays out. Default: none (the step
        closes wherever its inputs are known, or fails at isolated angles).
        """
        return ()

    def crank_margins(self, tip: str, center: complex, radius: float,
                      ground: Mapping[str, complex]
                      ) -> Callable[[Any], tuple[tuple[Any, Any], ...]] | None:
        """Return its margins as closed forms in the crank angle, if it has them.

        For a step fed directly by the crank's ``tip`` (a crank of ``radius``
        about ``center``) and ground points (``ground``: name -> position):
        a function of the crank angle (rad, float or array) returning what
        :meth:`margins` does (a margin may be scaled by a positive factor),
        computed without the cancellation of positions near a limit. ``None``
        where it has none (then :meth:`margins` is used).
        """
        return None

    @property
    def requires(self) -> tuple[str, ...]:
        """Names whose steps must run before this one (its uses and its owner)."""
        return self.uses if self.owner is None else (*self.uses, self.owner)


class Intermittent(Protocol):
    """A step whose ``intermittent`` is true: it reports where its lever is in its cycle."""

    def engagement(self, ctx: _Context, omega: Any, finish: Any) -> Engagement:
        """Return its :class:`~.state.Engagement` from a solve's context."""

    def jumps_at(self, angle: float, turns: int) -> bool:
        """Return whether one crank angle (plus whole turns) is within rounding of a jump."""


class Names(Protocol):
    """What the plan compiler lets an item check its references against."""

    kinds: Mapping[str, str]

    def point(self, name: str, what: str, where: Where) -> str:
        """Return ``name`` if it is a known point, else raise a :class:`SceneError`."""

    def ground(self, name: str, what: str, where: Where) -> str:
        """Return ``name`` if it is a ground point, else raise a :class:`SceneError`."""

    def link(self, name: str, what: str, where: Where) -> str:
        """Return ``name`` if it is a known link, else raise a :class:`SceneError`."""


class Placing(Protocol):
    """What the plan compiler lets an item build its step from.

    ``ground`` maps ground points to positions; ``local[link]`` the points
    fixed on each link to their coordinates in the link's frame (origin at its
    start, x along it; an item adds its own links); ``carriers[point]`` the
    links a point is fixed on, in the order they were added to ``local``;
    ``slot[lever]`` a slotted lever's (pivot, pin); ``size`` the mechanism's
    size, m; ``scene`` the scene; ``intermittent(placing, item)`` the step of
    an RPR whose lever has slots (a Geneva wheel's, :mod:`.geneva`, which
    builds on :mod:`.rpr`: lent here so that the base kind imports none of its
    variants).
    """

    ground: Mapping[str, complex]
    local: dict[str, dict[str, complex]]
    slot: dict[str, tuple[str, str]]
    size: float
    scene: Any
    carriers: Mapping[str, list[str]]

    @property
    def intermittent(self) -> Callable[[Placing, Any], Step]:
        """Return the function building an RPR's step whose lever has slots."""


class Reading(Protocol):
    """What the scene reader lends a kind to read its keys (:meth:`Item.from_scene`).

    Each method names the file's key in its :class:`SceneError`; lengths come
    back in m and angles in rad (the scene's ``units`` applied).
    """

    def get(self, mapping: Any, key: str, where: str, default: Any = ...) -> Any:
        """Return ``mapping[key]``, or ``default`` where given and the key is absent."""

    def name(self, mapping: Any, key: str, where: str) -> str:
        """Return the name at ``key``."""

    def length(self, mapping: Any, key: str, where: str, positive: bool = True) -> float:
        """Return the length at ``key``, m."""

    def number(self, mapping: Any, key: str, where: str, default: Any = ...) -> float:
        """Return the finite number at ``key``, as written (no unit applied)."""

    def angle(self, mapping: Any, key: str, where: str, default: Any = ...) -> float:
        """Return the angle at ``key``, rad."""

    def branch(self, mapping: Any, where: str) -> Branch:
        """Return the ``branch`` key (default +1)."""

    def actuator_length(self, name: str, where: str) -> float:
        """Return the length at time zero, m, of the scene's actuator ``name``."""

    def check_keys(self, mapping: Any, allowed: set[str], where: str) -> None:
        """Refuse any key of ``mapping`` outside ``allowed``."""

    def brief(self, value: Any) -> str:
        """Return ``value`` shortened for a message."""

    def link(self, raw: Any, where: str) -> Link:
        """Return the link ``{name, from, length}`` at ``where``."""

    def build(self, where: str, fields: dict[str, str], factory: Callable[..., Any],
              **kwargs: Any) -> Any:
        """Return ``factory(**kwargs)``, its errors named by the file key of each field.

        ``fields`` maps a field of ``factory`` to its key under ``where``
        where the two differ.
        """


class Item(ABC):
    """A scene item (a dyad or a carried point): what the solver and the geometry ask of its kind.

    A kind's item is a frozen dataclass deriving from this class. The abstract
    methods say what it is (the solver's part); the others say what geometry/
    and the reference need to know of it, and default to "nothing": a kind
    with no slider, no locked body, no drawing of its own keeps them.

    ``kind`` is the scene's ``type:`` of the item (``'RRR'``, ...; ``'point'``
    for a carried point): the reference solver and the registry key on it.
    """

    kind: ClassVar[str]

    @classmethod
    def from_scene(cls, read: Reading, raw: Any, where: str) -> Item:
        """Return the item written at ``where`` in a scene file (its keys, checked)."""
        msg = f'{where}: expected a dyad, got a {cls.kind}'
        raise SceneError(msg)

    @property
    @abstractmethod
    def key(self) -> str:
        """Return the name the item is known by in messages (its new point or its lever)."""

    @abstractmethod
    def defined(self) -> Iterator[tuple[str, str, Where]]:
        """Yield (name, ``'point'``/``'link'``/``'slider'``, where) of every name it defines."""

    @abstractmethod
    def joint_types(self) -> dict[str, str]:
        """Return joint name -> ``'revolute'`` or ``'prismatic'`` of the joints it moves."""

    @abstractmethod
    def prerequisites(self, names: Names) -> set[str]:
        """Check the names it refers to; return those its step waits for."""

    @abstractmethod
    def place(self, plan: Placing) -> Step:
        """Return its step, its prerequisites known; record the points fixed on its links."""

    @abstractmethod
    def scaled(self, scale: Callable[[float], float]) -> Item:
        """Return it with every length ``x`` replaced by ``scale(x)``."""

    def lengths(self) -> tuple[float, ...]:
        """Return its link lengths, m, which count in the mechanism's size."""
        return ()

    @staticmethod
    def fact_texts() -> dict[str, Callable[[dict[str, Any], SceneUnits], str]]:
        """Return, per ``kind`` of the facts its step's errors carry, their text in scene units.

        See :class:`~mech_kinematics.errors.AssemblyError` and
        :func:`~.mechanism.assembly_text`.
        """
        return {}

    def bodies(self) -> Iterator[tuple[str, str, Body]]:
        """Yield (point, body name, body) of every body besides links it puts at a point."""
        yield from ()

    def frames(self) -> Iterator[Frame]:
        """Yield the frame of every joint it moves (:data:`Frame`, for ``/tf``)."""
        yield from ()

    def members(self, ground: str) -> Iterator[Member]:
        """Yield every body it adds to the mechanism (:data:`Member`, for instant centres)."""
        yield from ()

    def slide_angle(self, slider: str, scene: Any, state: Any) -> float:
        """Return the direction, rad, in which its block ``slider`` slides, in a solved state."""
        msg = f'Expected a slider block of "{self.key}", got "{slider}"'
        raise KeyError(msg)

    def locked(self, state: Any) -> tuple[str, ...]:
        """Return its bodies that move with the ground in a solved state (a locked wheel)."""
        return ()

    def edges(self) -> Iterator[Edge]:
        """Yield the relative motions it adds to the velocity and acceleration polygons."""
        yield from ()

    def slips(self) -> Iterator[tuple[str, str, str, float]]:
        """Yield (slider, from point, to point, angle): sliding along a fixed direction, rad.

        The motion of ``to`` relative to ``from`` is the slider's rate along
        that direction (a translating body's slot; no Coriolis component).
        """
        yield from ()

    def link_lengths(self) -> dict[str, float | None]:
        """Return the length, m, of every link it moves (``None`` where it varies)."""
        return {}

    def outline(self, body: str, scene: Any, state: Any, points: Mapping[str, Any]
                ) -> tuple[tuple[str, ...], tuple[tuple[Any, Any], ...]]:
        """Return the points besides its own that ``body``'s drawing runs through, and its slots.

        Asked only of a body it adds (:meth:`members`). ``points`` maps every
        point to its position (an array of shape (2,), m); a slot is (inner end,
        mouth), positions likewise.
        """
        return (), ()

    def blocks(self, state: Any, points: Mapping[str, Any], ground: str,
               locked: set[str]) -> Iterator[tuple[str, str, Any, float, str]]:
        """Yield (name, point, position, sliding angle in rad, guide body) of its slider blocks."""
        yield from ()

    def guides(self, state: Any, points: Mapping[str, Any],
               strokes: Mapping[str, tuple[float, float]], size: float
               ) -> Iterator[tuple[str, Any, Any]]:
        """Yield (slider, start, end) of every fixed guide it draws, over the slider's stroke."""
        yield from ()

    def toggle(self) -> tuple[str, str, tuple[str, ...]] | None:
        """Return (measure key, label, links) if its measure is a transmission angle's sine."""
        return None

    def dead_centre_joints(self, ground: Collection[str]) -> dict[str, str]:
        """Return its output joints that can reverse (dead centres): name -> joint type."""
        return {}

    def tip_links(self, point: str) -> Iterator[tuple[str, tuple[str, ...]]]:
        """Yield (link, the joints it moves) for each of its links starting at ``point``."""
        yield from ()

    def pivots(self, ground: Collection[str]) -> dict[str, str]:
        """Return link -> ground pivot of its links that turn about a ground point."""
        return {}

    def pin_links(self, pivots: Mapping[str, str]) -> Iterator[tuple[str, str, bool]]:
        """Yield (its new pin, a link it is on, whether that link is preferred)."""
        yield from ()

    def four_bar(self) -> tuple[str, Any, Any] | None:
        """Return its new pin and two links (:class:`~.model.Link`) if it can close a four-bar."""
        return None


def fixed_guide(slider: str, through: Any, angle: float, state: Any,
                strokes: Mapping[str, tuple[float, float]], size: float
                ) -> tuple[str, Any, Any]:
    """Return (slider, start, end) of a fixed guide through ``through`` at ``angle`` (rad).

    The guide is drawn over the slider's stroke (or around its place, where no
    stroke is known), padded by 8 % of the drawing's ``size``: what
    :meth:`Item.guides` yields for a slider on a fixed straight guide.
    """
    u = np.array([math.cos(angle), math.sin(angle)])
    s = float(state.joints[slider].position)
    low, high = strokes.get(slider, (s, s))
    pad = 0.08 * size
    return slider, through + (min(low, s) - pad) * u, through + (max(high, s) + pad) * u
