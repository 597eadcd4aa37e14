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
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import Any, ClassVar, NamedTuple, Protocol, TYPE_CHECKING

from ..errors import SceneError

if TYPE_CHECKING:
    from .context import _Context
    from .graph import Fragment, JointType
    from .model import Branch, Link, SceneUnits, Where
    from .state import Engagement


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

    def jumps_over(self, angle: Any, turns: Any) -> Any:
        """Return where an array of crank angles (plus whole turns) are within rounding of one."""


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
    variants); ``trace(positions)`` the context of the steps placed so far run on an
    array of the first driver's positions at unit speed (what a triad follows its
    branch along, :mod:`.triad`).
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

    @property
    def trace(self) -> Callable[[Any], _Context] | None:
        """Return the function running the steps placed so far on an array of positions."""


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
        """Return the direction at ``key``, rad (whole turns reduced exactly)."""

    def start_angle(self, mapping: Any, key: str, where: str) -> tuple[float, int]:
        """Return a crank's angle at ``key`` as (rad within a turn, whole turns)."""

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

    def links(self, raw: Any, where: str, count: int, what: str) -> tuple[Link, ...]:
        """Return ``raw['links']``: ``count`` links (``what`` they are, for a refusal)."""

    def build(self, where: str, fields: dict[str, str], factory: Callable[..., Any],
              **kwargs: Any) -> Any:
        """Return ``factory(**kwargs)``, its errors named by the file key of each field.

        ``fields`` maps a field of ``factory`` to its key under ``where``
        where the two differ.
        """


class Item(ABC):
    """A scene item (a dyad or a carried point): what the rest of the package asks of its kind.

    A kind's item is a frozen dataclass deriving from this class, and answers
    only what the kind alone knows: its scene keys (:meth:`from_scene`), the
    names it defines and needs, its step (the kernel with its bounds), its
    scaling, its part of the mechanism's graph (:meth:`fragment`: every other
    concern reads the graph), the words of its failures and what its
    near-singularity measure means. Every method is abstract: a kind that
    leaves one out cannot be built (``test_base`` names it).

    ``kind`` is the scene's ``type:`` of the item (``'RRR'``, ...; ``'point'``
    for a carried point): the registry keys on it.
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
    def prerequisites(self, names: Names) -> set[str]:
        """Check the names it refers to; return those its step waits for."""

    @abstractmethod
    def place(self, plan: Placing) -> Step:
        """Return its step, its prerequisites known; record the points fixed on its links."""

    @abstractmethod
    def scaled(self, scale: Callable[[float], float]) -> Item:
        """Return it with every length ``x`` replaced by ``scale(x)``."""

    @abstractmethod
    def fragment(self) -> Fragment:
        """Return its part of the mechanism's graph (:mod:`.graph`): bodies, joints, motions."""

    @abstractmethod
    def lengths(self) -> tuple[float, ...]:
        """Return its link lengths, m, which count in the mechanism's size (``()``: none)."""

    @staticmethod
    @abstractmethod
    def fact_texts() -> dict[str, Callable[[dict[str, Any], SceneUnits], str]]:
        """Return, per ``kind`` of the facts its step's errors carry, their text in scene units.

        See :class:`~mech_kinematics.errors.AssemblyError` and
        :func:`~.mechanism.assembly_text` (``{}``: its errors carry none).
        """

    @abstractmethod
    def toggle(self) -> tuple[str, str, tuple[str, ...]] | None:
        """Return (measure key, label, links) if its measure is a transmission angle's sine.

        ``None`` where its near-singularity measure means something else, or
        where it has none.
        """

    def joint_types(self) -> dict[str, JointType]:
        """Return the output joints it moves and their types (its fragment's coordinates)."""
        return dict(self.fragment().coordinates)


class Rate(NamedTuple):
    """A driver's rate as it was given: its ``key``, its ``value`` in its own ``unit``.

    A crank's ``speed_rpm: 7`` is ``Rate('speed_rpm', 7.0, 'rpm')``: it stays 7.0
    rpm (never 7 pi / 30 rad/s and back) from the scene to the node's time base,
    which converts it once (:func:`~mech_kinematics.units.si_from_rate`). The
    key is the scene's and the time base's keyword for that unit.
    """

    key: str
    value: float
    unit: str


class RateParameter(NamedTuple):
    """The last part of the name and the unit of the parameter that sets a driver's rate."""

    key: str
    unit: str


class Driver(ABC):
    """A driver of the mechanism (a crank, a linear actuator): what the rest asks of its kind.

    A driver's kind is a frozen dataclass deriving from this class, in a
    module of its own (:mod:`.crank`, :mod:`.actuator`), registered in
    :data:`~.registry.DRIVERS`; every method is abstract. Its fields
    ``speed`` and ``accel`` are its default rates in SI (rad/s and rad/s^2,
    or m/s and m/s^2), what the solver takes; :attr:`rate` is its speed as
    the scene gave it, in the unit it was given in.
    """

    speed: float
    accel: float
    #: The scene key of its position at time zero (``'angle'``, ``'length'``), for messages.
    position_key: ClassVar[str]
    #: The key that names it in an entry of the scene's ``inputs:`` (``'link'``, ...).
    scene_key: ClassVar[str]
    #: Whether it is the crank of a v1 scene's ``input:`` (``Scene.input``): a crank's
    #: kind says True; another turning driver (a motor) is no crank.
    v1_crank: ClassVar[bool]

    @classmethod
    @abstractmethod
    def from_scene(cls, read: Reading, raw: Any, where: str) -> Driver:
        """Return the driver written at ``where`` in a scene file (its keys, checked)."""

    @property
    @abstractmethod
    def link_length(self) -> float | None:
        """The length, m, it gives a dyad link at time zero (an actuator's); else ``None``."""

    @property
    @abstractmethod
    def name(self) -> str:
        """Its name: the output joint it moves (a crank's link, an actuator)."""

    @property
    @abstractmethod
    def joint_type(self) -> JointType:
        """The type of the joint it moves (:mod:`.graph`): what its position is."""

    @property
    @abstractmethod
    def start(self) -> float:
        """Its position at time zero, rad or m (a crank's within its turn)."""

    @property
    @abstractmethod
    def stroke(self) -> tuple[float, float] | None:
        """Its inclusive limits, m, or ``None`` where its position may be anything."""

    @property
    @abstractmethod
    def turns(self) -> int:
        """Whole turns to add to :attr:`start` (a crank's start far out); 0 if it does not turn."""

    @property
    @abstractmethod
    def rate(self) -> Rate:
        """Its default speed as the scene gave it: key, value and unit (:class:`Rate`)."""

    @property
    @abstractmethod
    def rate_parameter(self) -> RateParameter:
        """The key and unit its speed is set in (``inputs.NAME.<key>``, the node's parameter)."""

    @property
    @abstractmethod
    def reach(self) -> float:
        """The length, m, it adds to the mechanism's size."""

    @property
    @abstractmethod
    def described(self) -> str:
        """What it is, for a report: ``'crank about A'``, ``'actuator'``, ..."""

    @abstractmethod
    def sweep(self, free: float) -> tuple[float, float]:
        """Return the positions a study sweeps it over, rad or m: a turn, or its stroke.

        ``free`` is a length no closing position of the mechanism can exceed,
        m: the sweep of a linear driver without stroke limits.
        """

    @abstractmethod
    def position_text(self, value: float, units: SceneUnits) -> str:
        """Return a position of it (rad or m) as text in the scene's unit."""

    @abstractmethod
    def scaled(self, scale: Callable[[float], float]) -> Driver:
        """Return it with every length ``x`` replaced by ``scale(x)``."""

    @abstractmethod
    def fragment(self) -> Fragment:
        """Return its part of the mechanism's graph (:mod:`.graph`)."""

    @abstractmethod
    def defined(self) -> tuple[tuple[str, str], ...]:
        """Return (name, ``'point'``/``'link'``/``'actuator'``) of every name it defines."""

    @abstractmethod
    def local(self, ground: Mapping[str, complex]) -> dict[str, dict[str, complex]]:
        """Return the points fixed on the links it moves, in each link's frame."""

    @abstractmethod
    def step(self, ground: Mapping[str, complex]) -> Any:
        """Return its step: ``run(ctx, position, speed, accel)`` at the head of every solve."""

    @abstractmethod
    def check_used(self, users: Sequence[Item]) -> None:
        """Refuse it where the items that read it (``users``, in plan order) cannot be driven."""

    @staticmethod
    @abstractmethod
    def fact_texts() -> dict[str, Callable[[dict[str, Any], SceneUnits], str]]:
        """Return, per ``kind`` of the facts its step's errors carry, their text in scene units."""
