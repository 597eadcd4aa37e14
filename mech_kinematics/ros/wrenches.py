# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""What the node publishes of the forces through the loop: efforts, reactions, shaking.

A scene with ``masses``, ``gravity`` or ``loads`` has a
:class:`~mech_kinematics.solver.forces.Dynamics`. On such a scene the node's
tick is a :class:`ForcesTick`: the kinematics solved as the general tick
solves them (the same bits), then the forces at that state
(:meth:`Dynamics.forces <mech_kinematics.solver.forces.Dynamics.forces>`,
bounded like every value), appended to the tick's values in the order of
:func:`forces_values`: each published joint's effort (a driver's; 0 for a
passive joint, frictionless), each reaction's ``(fx, fy, tz)``, the shaking
``(fx, fy, mz)``. An instant whose forces cannot be bounded keeps its
kinematics and leaves the forces out (its ``effort`` empty, no reaction or
shaking message), never a guess: :attr:`ForcesTick.refusal` says why.

Each reaction is a ``geometry_msgs/msg/WrenchStamped`` (:class:`ForceMessages`,
rendered from pre-serialized templates like the state's): the force on the
joint's child body (``Joint.body``, the body its kind adds) from its parent
(``Joint.on``), in ``frame_id``'s axes, applied at the joint's point; a pin
carries no moment (``torque`` 0), a prismatic joint's normal force is the
vector ``normal * n`` (``n`` its line's direction turned +90 deg) with the
moment the line exerts about the point as ``torque.z``, a Geneva lock only its
holding moment. ``shaking`` is the resultant force the joints put on the
frame and its moment about the scene's origin (``frame_id``'s origin).

``gravity`` and the loads are the node's parameters; :func:`dynamics_with`
makes the Dynamics of new values over the same graph and masses (the scene
is not rebuilt), which the tick reads at its next instant.

No rclpy here except the message classes; tested in ``test/ros/test_wrenches.py``.
"""

from __future__ import annotations

import cmath
from collections.abc import Mapping, Sequence
from dataclasses import replace
import math
from typing import Any, TYPE_CHECKING

from geometry_msgs.msg import WrenchStamped

from .cdr import marker, MessageTemplate, STAMP_MARKER
from .parameters import DYNAMIC, INPUT_DRIVES, ParameterSpec, STATIC
from .solver_path import BACKGROUND_STEPS
from .ticker import NOT_IN_THE_TICK, values_from_state
from .topics import reaction_topic, SHAKING
from .. import solver as lk
from ..errors import AssemblyError
from ..solver.compiler import NotCompiled
from ..solver.forces import Dynamics, given_forces_refusal, Load

if TYPE_CHECKING:
    from ..solver.compiler import FrameSpec
    from ..solver.forces import Forces
    from ..solver.graph import Joint
    from ..solver.mechanism import Scene

__all__ = ['ForceMessages', 'ForcesTick', 'dynamics_with', 'effort_status',
           'force_parameters', 'forces_refusal', 'forces_tick', 'forces_values', 'gravity_of',
           'reaction_joints', 'reaction_wrench', 'scene_forces_refusal', 'wrench_stamped']


def reaction_joints(dynamics: Dynamics) -> tuple[Joint, ...]:
    """Return the joints whose reactions are published, in the graph's order (all of them)."""
    return tuple(dynamics.graph.joints)


def _normal(joint: Joint, state: Any) -> complex:
    """Return the unit normal of a prismatic joint's line at ``state`` (direction + 90 deg)."""
    line = joint.line
    assert line is not None
    if joint.copies > 1:     # one of several slots: the one its point is in
        d = state.complex_points[joint.at][0] - state.complex_points[line.through][0]
        return 1j * d / abs(d)
    angle = line.angle if line.angle_of is None else \
        float(state.joints[line.angle_of].position) + line.angle
    return 1j * cmath.exp(1j * angle)


def reaction_wrench(joint: Joint, forces: Forces, state: Any) -> tuple[float, float, float]:
    """Return ``(fx, fy, tz)`` of the reaction at ``joint``: N, N, N m (see the module)."""
    r = forces.reactions[joint.name]
    if r.force is not None:
        return float(r.force.real), float(r.force.imag), 0.0
    moment = float(r.moment) if r.moment is not None else 0.0
    if r.normal is None:     # a lock: its holding moment
        return 0.0, 0.0, moment
    f = float(r.normal) * _normal(joint, state)
    return f.real, f.imag, moment


def forces_values(forces: Forces, state: Any, joints: Sequence[str],
                  reactions: Sequence[Joint]) -> list[float]:
    """Return the forces of a state in the order the node's templates read them.

    Each of ``joints``' effort (a driver's; 0 for another joint), then
    ``(fx, fy, tz)`` of each reaction (:func:`reaction_wrench`), then the
    shaking force and moment ``(fx, fy, mz)``.
    """
    efforts = forces.efforts
    values = [float(efforts[n]) if n in efforts else 0.0 for n in joints]
    for joint in reactions:
        values += reaction_wrench(joint, forces, state)
    shaking = forces.shaking_force
    values += (float(shaking.real), float(shaking.imag), float(forces.shaking_moment))
    return values


def _refusal(forces: Forces, max_error: float) -> str:
    """Return why an instant's forces were not bounded, one line."""
    if forces.worst is None:
        return f'the forces cannot be bounded here ({next(iter(forces.failures), "forces")})'
    name, bound, limit = forces.worst
    return (f'the error bound of {name} ({bound:.3g}) exceeds max_relative_error '
            f'{max_error:g} of its scale ({limit / max_error:.6g})')


#: Positions over a crank's turn at which the forces are solved before the ticks.
WARM_SAMPLES = 64


def compiled_motion(kinematics: Scene) -> NotCompiled | None:
    """Compile the motion a forces tick solves its forces at, now; None, or why not.

    ``mk.solve``'s single-angle path, where the scene compiles (one crank) and
    is small enough to compile before the ticks (:data:`.solver_path.BACKGROUND_STEPS`
    dyads and points, as the node's own tick); otherwise the general path,
    kept so that no tick ever compiles in its thread.
    """
    steps = len(kinematics.dyads) + len(kinematics.points)
    why = (lk.compile_now(kinematics) if steps <= BACKGROUND_STEPS else NotCompiled(
        f'{steps} dyads and points: compiling would hold the start (more than '
        f'{BACKGROUND_STEPS})'))
    lk.keep_general_path(kinematics, NOT_IN_THE_TICK)
    return why


class ForcesTick:
    """The node's tick on a scene with forces: its kinematics' values, then its forces'.

    Parameters
    ----------
    scene : Scene
        The scene the ticks solve (with its :attr:`~Scene.dynamics`).
    joints, points : sequence of str
        The joints and points whose values the tick returns (the state topics').
    frames : sequence of FrameSpec
        The frames whose poses follow them (``/tf``).
    static : bool, keyword-only
        ``effort: static``: the forces of gravity and the loads alone, solved
        at the same positions with every velocity and acceleration zero.

    Attributes
    ----------
    dynamics : Dynamics
        What the forces are solved with; replaced whole when ``gravity`` or a
        load changes (:func:`dynamics_with`), read once per instant.
    reactions : tuple of Joint
        The joints whose reactions follow the efforts, in order.
    forces_first : int
        Where the forces start in the values (after the frames' poses).
    refusal : str
        Why the forces of the last instant left out were (``''`` until one is).
    refused : int
        How many instants' forces were left out.
    """

    def __init__(self, scene: Scene, joints: Sequence[str], points: Sequence[str],
                 frames: Sequence[FrameSpec], *, static: bool) -> None:
        assert scene.dynamics is not None
        self.dynamics: Dynamics = scene.dynamics
        # The motion alone (the forces' own bounds are judged below, where a refusal leaves
        # the kinematics published): the same bits as the dynamics scene's motion.
        self.kinematics = replace(scene, gravity=None, masses=(), loads=(),
                                  outputs_joints=scene.output_joints,
                                  outputs_points=scene.output_points)
        #: Why the motion is not solved on mk.solve's compiled path, or None.
        self.motion = compiled_motion(self.kinematics)
        self.joints, self.points, self.frames = tuple(joints), tuple(points), tuple(frames)
        self.static = static
        self.drivers = len(scene.drivers)
        self.reactions = reaction_joints(self.dynamics)
        self.forces_first = 3 * len(self.joints) + 6 * len(self.points) + 3 * len(self.frames)
        self.refusal = ''
        self.refused = 0
        self._samples: list[Any] | None = None

    #: Whether the reactions are the scene's graph joints in ``frame_id`` (drawn as markers).
    scene_reactions = True
    #: With ``drive: topic``, the input's drivers as given, set before each solve (a
    #: robot's forces read its actuated joints there; a scene's need nothing more).
    inputs: Any = None

    def parameters(self) -> tuple[ParameterSpec, ...]:
        """Return the forces' parameters (:func:`force_parameters`), the scene's defaults."""
        return force_parameters(self.dynamics)

    def parameters_refusal(self, values: Mapping[str, Any]) -> str | None:
        """Return why the forces' parameters' ``values`` are refused, or None (forces_refusal).

        ``values``: every one of :meth:`parameters` as it would be.
        """
        return forces_refusal(self.dynamics, values)

    def apply(self, values: Mapping[str, Any]) -> None:
        """Solve the next instants with accepted parameter values (written out first, warm)."""
        self.dynamics = self.warm(dynamics_with(self.dynamics, values))

    def gravity(self) -> list[float]:
        """Return the gravity the forces are solved with, for ``diagnostics`` (m/s^2)."""
        return gravity_of(self.dynamics)

    def path(self) -> str:
        """Return which path solves an instant's statics, for ``diagnostics`` (one line)."""
        return self.dynamics.path()['single']

    def topics(self) -> list[str]:
        """Return the topics of the wrenches, in the order :meth:`messages` renders them."""
        return [*(reaction_topic(joint.name) for joint in self.reactions), SHAKING]

    def messages(self, frame_id: str, tf_prefix: str) -> ForceMessages:
        """Return the wrenches' messages: each reaction's, then the shaking's, in ``frame_id``."""
        return ForceMessages(frame_id, len(self.joints), len(self.reactions))

    def warm(self, dynamics: Dynamics | None = None) -> Dynamics:
        """Solve ``dynamics`` (the tick's by default) at positions the drivers take; return it.

        The forces of one instant are written out as straight-line code per
        pivot sequence once a scene has had a few instants on the general path
        (``Dynamics._write``, recorded from the general path), milliseconds each: done
        here, before the ticks (and before a changed ``gravity`` or load takes
        effect), no instant waits for it. The pivots follow the positions
        alone: one crank is sampled over a turn, several drivers at their start.
        """
        dynamics = self.dynamics if dynamics is None else dynamics
        if self._samples is None:
            self._samples = self._sample_states()
        for state in self._samples:
            dynamics.forces(state, math.inf)
        return dynamics

    def _sample_states(self) -> list[Any]:
        drivers = self.kinematics.drivers
        starts = [d.start for d in drivers]
        if len(drivers) == 1 and self.kinematics.input is not None:
            positions = [starts[0] + math.tau * k / WARM_SAMPLES for k in range(WARM_SAMPLES)]
            rest: Any = 0.0
        else:
            positions = [starts[0] if len(starts) == 1 else starts] * (WARM_SAMPLES // 4)
            rest = 0.0 if len(starts) == 1 else (0.0,) * len(starts)
        states = []
        for position in positions:
            try:
                states.append(lk.solve(self.kinematics, position, rest, rest))
            except AssemblyError:
                continue        # a position where it does not assemble: nothing to warm
        return states

    def _motion(self, theta: Any, omega: Any, alpha: Any, tol: float,
                turns: Any) -> tuple[list[float], float, Any]:
        """Return the motion's values and measure, and the state the forces are solved at.

        That state is the motion's, or with ``effort: static`` the same
        positions at rest.
        """
        kinematics = self.kinematics
        state = lk.solve(kinematics, theta, omega, alpha, turns=turns, max_error=tol)
        values = values_from_state(state, self.joints, self.points, self.frames)
        measures = state.singularity.values()
        measure = float(min(measures)) if measures else math.inf
        at = state
        if self.static:
            rest = 0.0 if self.drivers == 1 else (0.0,) * self.drivers
            at = lk.solve(kinematics, theta, rest, rest, turns=turns, max_error=tol)
        return values, measure, at

    def __call__(self, theta: Any, omega: Any, alpha: Any, tol: float,
                 turns: Any = 0) -> tuple[list[float], float]:
        """Return ``(values, measure)`` as a tick function does, the forces after the motion."""
        values, measure, at = self._motion(theta, omega, alpha, tol, turns)
        forces = self.dynamics.forces(at, tol)
        if forces.valid:
            values += forces_values(forces, at, self.joints, self.reactions)
        else:
            self.refusal = _refusal(forces, tol)
            self.refused += 1
        return values, measure


def forces_tick(scene: Scene, tick_scene: Scene, frames: Sequence[FrameSpec], *, drive: str,
                effort: str) -> ForcesTick | None:
    """Return the forces tick of ``scene`` on the node, or ``None`` where none is published.

    None for a scene without masses, gravity or loads (it computes nothing
    new), and with ``drive: topic`` unless ``effort: static``: the input gives
    no accelerations, so the efforts of the motion are not determined.
    """
    if scene.dynamics is None or (drive in INPUT_DRIVES and effort == DYNAMIC):
        return None
    return ForcesTick(tick_scene, scene.output_joints, scene.output_points, frames,
                      static=effort == STATIC)


def scene_forces_refusal(has_forces: bool, drive: str, effort: str, given: Sequence[str],
                         sensors: bool = False) -> str | None:
    """Return why a forces parameter given to the node with a scene is refused, or None.

    ``has_forces``: the scene has masses, gravity or loads; ``given``: the
    parameters given at start. Refused in one line rather than accepted and
    ignored (as in URDF mode, :func:`~.robot_mode.robot_forces_refusal`):
    ``effort`` other than ``dynamic``, ``gravity`` and ``loads.*`` on a scene
    with nothing to weigh; ``gravity`` and ``loads.*`` where the efforts are
    left out (``drive: topic`` without ``effort: static``), but ``gravity``
    on a scene with inertial sensors (``sensors``: those of the scene's
    gravity follow it).
    """
    named = [name for name in given if name == 'gravity' or name.startswith('loads.')]
    if not has_forces:
        if effort != DYNAMIC:
            named.insert(0, f'effort:={effort}')
        if not named:
            return None
        return ('Expected no forces parameters for this scene (it has no masses, gravity or '
                f'loads: there are no forces to publish), got {", ".join(named)}')
    if sensors:
        named = [name for name in named if name != 'gravity']
    if named and drive in INPUT_DRIVES and effort == DYNAMIC:
        return (f'Expected effort:=static with drive: {drive} for {", ".join(named)} (the input '
                f'gives no accelerations: the efforts are left out), got effort:={effort}')
    return None


def effort_status(scene: Scene | bool, drive: str, effort: str) -> str:
    """Return what the node's efforts are, for ``diagnostics`` ('' for a scene without forces).

    ``scene``: the scene, or whether what the node loaded has forces (a robot
    whose URDF has ``<inertial>``s).
    """
    if not (scene if isinstance(scene, bool) else scene.dynamics is not None):
        return ''
    if effort == STATIC:
        return 'static: gravity and loads only, inertia neglected'
    if drive in INPUT_DRIVES:
        return ('left out: the input gives no accelerations (effort: static publishes the '
                'statics)')
    return 'dynamic: inertia, gravity and loads'


def wrench_stamped(force: Sequence[float], frame_id: str, sec: int,
                   nanosec: int) -> WrenchStamped:
    """Return ``geometry_msgs/WrenchStamped`` of ``(fx, fy, tz)`` in ``frame_id``.

    Six values are the whole wrench, ``(fx, fy, fz, tx, ty, tz)``.
    """
    msg = WrenchStamped()
    msg.header.stamp.sec, msg.header.stamp.nanosec = sec, nanosec
    msg.header.frame_id = frame_id
    if len(force) == 6:
        w = msg.wrench
        w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y, w.torque.z = force
        return msg
    msg.wrench.force.x, msg.wrench.force.y = force[0], force[1]
    msg.wrench.torque.z = force[2]
    return msg


class ForceMessages:
    """Each reaction's (and the shaking's) ``WrenchStamped``, rendered from templates.

    Parameters
    ----------
    frame_id : str or sequence of str
        ``header.frame_id`` of every message, or of each in order (a robot's
        reactions: each in its child link's frame).
    joints : int
        How many efforts precede the reactions in the forces' values.
    reactions : int
        How many reactions follow them.
    width : int, keyword-only
        The values of each: 3, ``(fx, fy, tz)`` in the scene's plane, or 6,
        ``(fx, fy, fz, tx, ty, tz)``.
    shaking : bool, keyword-only
        Whether the shaking's ``(fx, fy, mz)`` follows the reactions.
    """

    def __init__(self, frame_id: str | Sequence[str], joints: int, reactions: int, *,
                 width: int = 3, shaking: bool = True) -> None:
        count = reactions + shaking
        frames = [frame_id] * count if isinstance(frame_id, str) else list(frame_id)
        assert len(frames) == count
        templates: dict[str, MessageTemplate] = {}
        for frame in frames:
            if frame not in templates:
                templates[frame] = MessageTemplate(wrench_stamped(
                    [marker(i) for i in range(width)], frame, *STAMP_MARKER), width)
        self._renders = [templates[frame].render for frame in frames]
        self.joints, self.reactions, self.width = joints, reactions, width
        self._widths = [width] * reactions + [3] * shaking

    def render(self, values: Sequence[float], first: int, sec: int,
               nanosec: int) -> list[bytes]:
        """Return the reactions' messages, then the shaking's, of the forces at ``first``."""
        start = first + self.joints
        out = []
        for render, width in zip(self._renders, self._widths, strict=True):
            out.append(render(sec, nanosec, values, start))
            start += width
        return out


def gravity_of(dynamics: Dynamics) -> list[float]:
    """Return the gravity of ``dynamics`` as ``[gx, gy]``, m/s^2."""
    return [dynamics.gravity.real, dynamics.gravity.imag]


def force_parameters(dynamics: Dynamics) -> tuple[ParameterSpec, ...]:
    """Return the parameters of a scene's forces, defaulting to the scene's values.

    ``gravity`` ([gx, gy], m/s^2), and for each load NAME ``loads.NAME.force``
    ([fx, fy], N, scene frame) or ``loads.NAME.torque`` (N m, + CCW): each
    changeable while the node runs. A load given as a table over a joint's
    position has none: its table is the scene's.
    """
    specs = [ParameterSpec('gravity', 'xy', gravity_of(dynamics),
                           "Gravity [gx, gy] in the scene's frame, from the next instant "
                           "published. Defaults to the scene's", 'm/s^2')]
    for load in dynamics.loads:
        if load.force is not None:
            specs.append(ParameterSpec(
                f'loads.{load.name}.force', 'xy', list(load.force),
                f'Force [fx, fy] of load {load.name} at {load.point}, scene frame, from the '
                "next instant published. Defaults to the scene's", 'N'))
        elif load.torque is not None:
            specs.append(ParameterSpec(
                f'loads.{load.name}.torque', 'double', float(load.torque),
                f'Torque of load {load.name} on {load.link}, + CCW, from the next instant '
                "published. Defaults to the scene's", 'N m'))
    return tuple(specs)


def _given(dynamics: Dynamics, changes: Mapping[str, Any]) -> tuple[tuple[float, float],
                                                                    list[Load]]:
    """Return the gravity and the loads of ``dynamics`` with accepted parameter values."""
    gravity = changes.get('gravity')
    g = (dynamics.gravity.real, dynamics.gravity.imag) if gravity is None else (
        float(gravity[0]), float(gravity[1]))
    loads = []
    for load in dynamics.loads:
        force = changes.get(f'loads.{load.name}.force')
        torque = changes.get(f'loads.{load.name}.torque')
        if force is not None:
            load = replace(load, force=(float(force[0]), float(force[1])))
        if torque is not None:
            load = replace(load, torque=float(torque))
        loads.append(load)
    return g, loads


def forces_refusal(dynamics: Dynamics, values: Mapping[str, Any]) -> str | None:
    """Return why ``values`` of :func:`force_parameters` give forces beyond the doubles, or None.

    ``values``: the parameters' values as they would be (each already a pair
    or a number of finite doubles). The rule is the scene's
    (:func:`~mech_kinematics.solver.forces.given_forces_refusal`): the weights
    and the loads' forces, each and in all, finite; the reason names the
    parameter at fault (``gravity`` or ``loads.NAME.force``).
    """
    gravity, loads = _given(dynamics, values)
    refused = given_forces_refusal(tuple(dynamics.masses.values()), loads, gravity)
    if refused is None:
        return None
    element, _, reason = refused
    name = f'loads.{element.name}.force' if isinstance(element, Load) else 'gravity'
    return f'{name}: {reason}'


def dynamics_with(dynamics: Dynamics, changes: Mapping[str, Any]) -> Dynamics:
    """Return ``dynamics`` with accepted parameter values (:func:`force_parameters`' names).

    The graph and the masses are kept; only the gravity and the loads' values
    change, so nothing of the scene is rebuilt.
    """
    gravity, loads = _given(dynamics, changes)
    graph = dynamics.graph
    points = {p for body in graph.bodies.values() for p in body.points}
    points.update(load.point for load in loads if load.point is not None)
    return Dynamics(graph, tuple(dynamics.masses.values()), loads, gravity,
                    tuple(points), dynamics.size)
