# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``python -m mech_kinematics check SCENE``: what a scene does over one crank turn.

Prints where the mechanism assembles, its toggle and dead-centre positions,
its minimum transmission angle and the Grashof class of every four-bar loop,
from :func:`mech_kinematics.geometry.assembly.assembly_from_scene`: text in
the scene's own units, or ``--json`` in SI units (rad, m). A scene with
several drivers (or an actuator) gets its assembly region instead
(:func:`mech_kinematics.geometry.region.region_from_scene`): the fraction of a
grid over two drivers that assembles, each driver's ranges with the others
at their start positions, stroke limits, and on request a map of the grid
(``--map`` as text, ``--png FILE`` as a picture). ``--workspace POINT`` on a
scene with two drivers maps where the point can go instead, with its singular
curves (:mod:`mech_kinematics.geometry.workspace`); on a URDF,
``--workspace FRAME`` maps a link frame's origin in the root frame
(:func:`mech_kinematics.robot.targets.frame_workspace`).

A scene with forces (``masses``, ``gravity`` or ``loads``) gets its
turning-moment diagram too (:mod:`mech_kinematics.geometry.turning`): each
driver's mean effort and extremes over a turn of the (first) crank, the
fluctuation of energy, and with ``--flywheel CS`` the flywheel's moment of
inertia for that coefficient of fluctuation of speed; each figure with its
error. A scene without forces prints nothing more.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Mapping, Sequence
import json
import math
from pathlib import Path
import sys
from typing import Any

import numpy as np

from .cli import (add_branch_argument, add_gravity_argument, add_robot_arguments,
                  add_scene_argument, add_units_argument, branches_of, finite_float,
                  gravity_of, is_urdf, link_loads_of, load_robot_argument,
                  load_scene_argument, named_value, run_tool, targets_in_si)
from ..errors import SceneError
from ..geometry.region import GRID
from ..solver.graph import JointType
from ..solver.solve import paths

__all__ = ['add_parser', 'coefficient', 'draw_workspace', 'grid_size', 'main', 'map_text',
           'region_json', 'region_text', 'report_json', 'report_text', 'turning_json',
           'turning_text', 'workspace_json', 'workspace_of', 'workspace_text', 'write_region_png',
           'write_workspace_png']

#: The text map's largest size, characters.
MAP_COLUMNS = 72
MAP_ROWS = 36
#: The largest grid: N x N points are solved at once.
GRID_MOST = 2000


def grid_size(text: str) -> int:
    """Parse a grid size (2 to :data:`GRID_MOST` points per driver), or tell argparse why not."""
    try:
        value = int(text)
    except ValueError:
        value = 0
    if not 2 <= value <= GRID_MOST:
        msg = f'expected a whole number of grid points from 2 to {GRID_MOST}, got {text!r}'
        raise argparse.ArgumentTypeError(msg)
    return value


def coefficient(text: str) -> float:
    """Parse a coefficient of fluctuation of speed (above 0, below 2), or tell argparse why not."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0.0 < value < 2.0:
        msg = (f'expected a coefficient of fluctuation of speed (w_max - w_min) / w_mean above 0 '
               f'and below 2 (e.g. 0.02), got {text!r}')
        raise argparse.ArgumentTypeError(msg)
    return value


CHECK_HELP = """\
Study one full turn of a scene's crank (angles 0 to 360 deg, CCW from +x) and
print:
  - the crank-angle ranges where the mechanism assembles and where it does
    not, however narrow (their ends the roots of the dyads' assembly margins,
    to 1e-12 rad);
  - its toggle positions (a dyad's links in line: the mechanism locks there);
  - its dead centres (an output link or slider reverses: for a four-bar's
    rocker the crank and coupler are in line, for a slider-crank the piston
    is at an end of its stroke);
  - the minimum transmission angle of every RRR and RRP dyad, and where;
  - the Grashof class of every four-bar loop (crank-rocker, rocker-crank,
    double-crank, double-rocker, change point, triple-rocker);
  - the strokes of every output that reverses, in the order the crank meets
    them turning at the scene's own speed, and its time ratio (the slower
    stroke's crank travel over the quicker's: a quick return's);
  - the arc of each crank turn in which an intermittent (Geneva) lever
    indexes, by how much, and the arc in which it is locked.
Text uses the scene's units; --json prints SI (rad, m). Exit status 2 on a
scene that cannot be read.

A scene with several drivers (inputs:) or a linear actuator gets instead:
  - the fraction of a grid over two drivers (the first two, or --pair A,B;
    each crank over a turn, each actuator over its stroke, --grid N points
    each, limits included; other drivers at their start positions) at which
    the mechanism assembles;
  - each driver's ranges where it assembles with the others at their start
    positions, their ends exact (the last position solve answers at, found
    by bisection to adjacent doubles after sampling 3600 positions: a window
    narrower than the stated step between two samples is not seen), and what
    stops each end (a stroke limit or the dyad that stops closing);
  - the stroke limits of every actuator (one without is swept over lengths
    up to a length no closing position can exceed);
  - with --map, the grid drawn in text (# assembles, . does not, + partly);
    with --png FILE, as a picture.

A scene with forces (masses, gravity or loads) also gets its turning-moment
diagram: the (first) crank turns once at its speed with no acceleration (any
other driver held at its start), and check prints each driver's mean effort
and its largest and least values and where, the fluctuation of energy (the
largest swing of the energy given beyond the mean, J) and where the energy is
least and most; with --flywheel CS the moment of inertia of a flywheel for the
coefficient of fluctuation of speed CS = (w_max - w_min) / w_mean, I = dE /
(w_mean^2 CS) (one crank only). Each figure with its error; efforts in N m (a
crank) or N (an actuator), SI in --json too.
"""


def _loop_text(loop: Any, units: Any) -> str:
    ground, input_, coupler, output = loop.lengths
    names = loop.names
    o1, q, c, o2 = loop.points
    length = units.length_text
    lengths = sorted(loop.lengths)
    s_l, p_q = lengths[0] + lengths[3], lengths[1] + lengths[2]
    relation = '<' if loop.grashof not in ('change point', 'triple-rocker') else (
        '=' if loop.grashof == 'change point' else '>')
    kind = 'Grashof' if relation != '>' else 'non-Grashof'
    return (f'{o1}-{q}-{c}-{o2} (ground {names[0]} {length(ground)}, {names[1]} '
            f'{length(input_)}, {names[2]} {length(coupler)}, {names[3]} {length(output)}): '
            f'{loop.grashof} ({kind}: s + l = {length(s_l, p_q)} {relation} p + q = '
            f'{length(p_q, s_l)})')


def report_text(assembly: Any, scene: Any) -> str:
    """Return the report of ``check`` as lines of text, in the scene's units."""
    from ..geometry.assembly import angle_text

    units = assembly.units
    unit = units.angle

    def angle(theta: float) -> str:
        return f'{angle_text(units, theta)} {unit}'

    crank = scene.input
    lines = [f'{assembly.scene}: one turn of crank "{crank.link}" about {crank.center} '
             f'(angles in {unit}, CCW from +x; lengths in {units.length})']
    if assembly.everywhere:
        lines.append('assembles: at every crank angle')
    else:
        ranges = ', '.join(f'{angle_text(units, a)}..{angle_text(units, b)}'
                           for a, b in assembly.ranges)
        lines.append(f'assembles: for crank angles {ranges} {unit}')
        lines.append(f'{assembly.summary()}')
    toggles = [f'{angle(t.angle)} ({t.dyad}: {" and ".join(t.links)} in line)'
               for t in assembly.toggles]
    lines.append(f'toggle positions: {", ".join(toggles) if toggles else "none"}')
    centres = []
    for centre in assembly.dead_centres:
        where = (f'{angle_text(units, centre.position)} {unit}' if centre.kind.angular
                 else f's = {units.length_text(centre.position)}')
        text = f'{angle(centre.angle)} ({centre.joint} reverses at {where}'
        if centre.in_line is not None:
            text += f'; {centre.in_line[0]} and {centre.in_line[1]} in line'
        centres.append(text + ')')
    lines.append(f'dead centres: {", ".join(centres) if centres else "none"}')
    if assembly.transmission:
        def where(t: Any) -> str:
            return 'at every crank angle' if t.constant else f'at crank angle {angle(t.angle)}'

        worst = min(assembly.transmission, key=lambda t: t.minimum)
        lines.append(f'minimum transmission angle: {angle(worst.minimum)} {where(worst)} '
                     f'({worst.dyad}: {" and ".join(worst.links)})')
        for other in assembly.transmission:
            if other is not worst:
                lines.append(f'  {other.dyad}: {angle(other.minimum)} {where(other)}')
    else:
        lines.append('minimum transmission angle: no RRR or RRP dyad')
    loops = [_loop_text(loop, units) for loop in assembly.loops]
    lines.append(f'four-bar loops: {"; ".join(loops) if loops else "none"}')
    lines.extend(_strokes_text(scene, assembly, angle))
    return '\n'.join(lines)


def _strokes_text(scene: Any, assembly: Any, angle: Any) -> list[str]:
    from ..geometry.assembly import angle_text
    from ..geometry.strokes import intermittent_from_scene, strokes_from_assembly
    units = assembly.units
    unit = units.angle
    lines = []
    outputs = strokes_from_assembly(scene, assembly)
    if outputs:
        way = 'CCW' if scene.input.speed >= 0.0 else 'CW'
        lines.append(f'strokes (the crank turning {way}; time ratio = slower stroke / quicker):')
    for output in outputs:
        def where(x: float) -> str:
            return (f'{angle_text(units, x)} {unit}' if output.kind.angular  # noqa: B023
                    else units.length_text(x))
        parts = [f'{where(s.start_position)} -> {where(s.end_position)} over crank '
                 f'{angle_text(units, s.start)}..{angle_text(units, s.end)} {unit} '
                 f'({angle(s.crank_travel)})' for s in output.strokes]
        ratio = '' if output.time_ratio is None else f'; time ratio {output.time_ratio:.6g}'
        lines.append(f'  {output.joint}: {", then ".join(parts)}{ratio}')
    for lever in intermittent_from_scene(scene):
        start, end = lever.engaged
        lines.append(f'intermittent: {lever.lever} '
                     f'indexes {angle(lever.index)} while the crank turns CCW from '
                     f'{angle_text(units, start)} to {angle(end)} ({angle(lever.engaged_travel)} '
                     f'of each turn); locked for the other {angle(lever.locked_travel)}')
    return lines


def report_json(assembly: Any, scene: Any) -> dict[str, Any]:
    """Return the report of ``check --json``: SI units (rad, m)."""
    from ..geometry.strokes import intermittent_from_scene, strokes_from_assembly
    return {
        'scene': assembly.scene,
        'assembles_everywhere': assembly.everywhere,
        'ranges': [list(r) for r in assembly.ranges],
        'gaps': [list(g) for g in assembly.gaps],
        'summary': assembly.summary(),
        'toggles': [{'angle': t.angle, 'dyad': t.dyad, 'links': list(t.links)}
                    for t in assembly.toggles],
        'dead_centres': [{'angle': c.angle, 'joint': c.joint, 'type': str(c.kind),
                          'position': c.position,
                          'in_line': None if c.in_line is None else list(c.in_line)}
                         for c in assembly.dead_centres],
        'transmission': [{'dyad': t.dyad, 'links': list(t.links), 'minimum': t.minimum,
                          'angle': t.angle, 'constant': t.constant}
                         for t in assembly.transmission],
        'loops': [{'names': dict(zip(('ground', 'input', 'coupler', 'output'), loop.names,
                                     strict=True)),
                   'points': list(loop.points),
                   'lengths': dict(zip(('ground', 'input', 'coupler', 'output'), loop.lengths,
                                       strict=True)),
                   'class': loop.grashof} for loop in assembly.loops],
        'strokes': [{'joint': s.joint, 'type': str(s.kind), 'time_ratio': s.time_ratio,
                     'strokes': [{'from_angle': x.start, 'to_angle': x.end,
                                  'crank_travel': x.crank_travel,
                                  'from_position': x.start_position,
                                  'to_position': x.end_position} for x in s.strokes]}
                    for s in strokes_from_assembly(scene, assembly)],
        'intermittent': [{'lever': i.lever, 'index': i.index, 'engaged': list(i.engaged),
                          'engaged_travel': i.engaged_travel, 'locked_travel': i.locked_travel}
                         for i in intermittent_from_scene(scene)],
    }


def _position_text(units: Any, kind: JointType, value: float) -> str:
    """Return a driver's position (rad or m) in the scene's units, with the unit."""
    return f'{_number_text(units, kind, value)} {_unit(units, kind)}'


def _number_text(units: Any, kind: JointType, value: float) -> str:
    """Return a driver's position (rad or m) in the scene's units, 6 digits, no unit."""
    from ..geometry.assembly import angle_text
    if kind.angular:
        return angle_text(units, value)
    return units.length_text(value).split()[0]


def _unit(units: Any, kind: JointType) -> str:
    return units.angle if kind.angular else units.length


def _span_text(units: Any, kind: JointType, low: float, high: float) -> str:
    """Return ``low..high unit``."""
    return (f'{_number_text(units, kind, low)}..{_number_text(units, kind, high)} '
            f'{_unit(units, kind)}')


def _domain_text(units: Any, scene: Any, name: str, kind: JointType,
                 domain: tuple[float, float]) -> str:
    if kind.angular:
        return 'over a turn'
    driver = next(d for d in scene.drivers if d.name == name)
    if driver.stroke is None and domain[0] < 0.0:
        return f'over positions {_span_text(units, kind, *domain)} (no stroke limits)'
    if driver.stroke is None:
        return f'over lengths up to {_position_text(units, kind, domain[1])} (no stroke limits)'
    return f'over its stroke {_span_text(units, kind, *domain)}'


def _end_text(why: str) -> str:
    return {'stroke': 'its stroke limit', 'turn': 'a full turn'}.get(
        why, f'{why} stops closing' if why else 'the end of what was swept')


def map_text(region: Any, width: int = MAP_COLUMNS, height: int = MAP_ROWS) -> list[str]:
    """Return the grid drawn in text: ``#`` assembles, ``.`` does not, ``+`` partly.

    The first grid driver runs left to right, the second bottom to top; each
    character stands for a block of grid points when the grid is larger than
    ``width`` by ``height``.
    """
    grid = region.assembles if region.assembles.ndim == 2 else region.assembles[:, None]
    columns = min(width, grid.shape[0])
    rows = min(height, grid.shape[1])
    xs = np.array_split(np.arange(grid.shape[0]), columns)
    ys = np.array_split(np.arange(grid.shape[1]), rows)
    lines = []
    for y in reversed(ys):
        line = ''
        for x in xs:
            block = grid[np.ix_(x, y)]
            line += '#' if block.all() else ('.' if not block.any() else '+')
        lines.append(line)
    return lines


def region_text(region: Any, scene: Any, show_map: bool = False) -> str:
    """Return the report of ``check`` on several drivers as lines of text, scene's units."""
    units = region.units
    kinds = {d.name: d.joint_type for d in scene.drivers}
    described = []
    for driver in scene.drivers:
        described.append(f'{driver.name} ({driver.described})')
    count = len(scene.drivers)
    lines = [f'{region.scene}: {count} driver{"s" if count > 1 else ""}: '
             f'{", ".join(described)} (angles in {units.angle}, CCW from +x; lengths in '
             f'{units.length})']
    slices = {s.driver: s for s in region.slices}
    axes = ' x '.join(
        f'{name} {_domain_text(units, scene, name, kinds[name], slices[name].domain)}'
        for name in region.grid)
    size = ' x '.join(str(len(a)) for a in region.axes)
    held = ', '.join(f'{name} at {_position_text(units, kinds[name], x)}'
                     for name, x in region.at.items())
    total = region.assembles.size
    lines.append(f'grid: {axes} ({size} points{"; " + held if held else ""}): assembles at '
                 f'{100.0 * region.fraction:.4g}% ({int(region.assembles.sum())} of {total})')
    for piece in region.slices:
        others = ', '.join(f'{name} at {_position_text(units, kinds[name], x)}'
                           for name, x in piece.at.items())
        head = f'{piece.driver}' + (f' (with {others})' if others else '')
        step = _position_text(units, piece.kind, piece.step)
        if piece.everywhere:
            where = ('at every angle' if piece.kind.angular else
                     f'over its whole stroke {_span_text(units, piece.kind, *piece.domain)}')
            lines.append(f'{head}: assembles {where}')
            continue
        if not piece.ranges:
            lines.append(f'{head}: assembles nowhere (sampled every {step})')
            continue
        parts = []
        for (a, b), (why_a, why_b) in zip(piece.ranges, piece.ends, strict=True):
            parts.append(f'{_span_text(units, piece.kind, a, b)} (from {_end_text(why_a)} '
                         f'to {_end_text(why_b)})')
        lines.append(f'{head}: assembles for {", ".join(parts)}; sampled every {step}, ends '
                     f'exact')
    strokes = []
    for driver in scene.drivers:
        if driver.joint_type.angular:
            continue
        if driver.stroke is None:
            strokes.append(f'{driver.name} none')
        else:
            strokes.append(f'{driver.name} {_span_text(units, driver.joint_type, *driver.stroke)}')
    lines.append(f'stroke limits: {", ".join(strokes) if strokes else "none (no actuator)"}')
    if show_map:
        across = region.grid[0]
        up = f', {region.grid[1]} upward' if len(region.grid) > 1 else ''
        lines.append(f'map (# assembles, . does not, + partly; {across} rightward{up}):')
        lines.extend(map_text(region))
    return '\n'.join(lines)


def region_json(region: Any, scene: Any, show_map: bool = False) -> dict[str, Any]:
    """Return the report of ``check --json`` on several drivers: SI units (rad, m)."""
    slices = {s.driver: s for s in region.slices}
    data: dict[str, Any] = {
        'scene': region.scene,
        'drivers': [{'name': d.name, 'type': d.joint_type, 'start': d.start,
                     'stroke': None if d.stroke is None else list(d.stroke)}
                    for d in scene.drivers],
        'grid': {'drivers': list(region.grid), 'points': [len(a) for a in region.axes],
                 'domains': [list(slices[name].domain) for name in region.grid],
                 'held': dict(region.at), 'assembling': int(region.assembles.sum()),
                 'fraction': region.fraction},
        'slices': [{'driver': s.driver, 'type': s.kind, 'domain': list(s.domain),
                    'at': dict(s.at), 'everywhere': s.everywhere,
                    'ranges': [list(r) for r in s.ranges], 'ends': [list(e) for e in s.ends],
                    'step': s.step} for s in region.slices],
    }
    if show_map:
        data['map'] = map_text(region)
    return data


def write_region_png(region: Any, path: str) -> None:
    """Write the grid as a PNG picture (the scene's units on the axes)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    units = region.units
    kinds = {s.driver: s.kind for s in region.slices}

    def shown(name: str, values: Any) -> Any:
        if kinds[name].angular:
            return np.array([units.angle_value(float(v)) for v in values])
        return np.asarray(values) * (1000.0 if units.length == 'mm' else 1.0)

    def label(name: str) -> str:
        unit = units.angle if kinds[name].angular else units.length
        return f'{name} ({unit})'

    figure = Figure(figsize=(6.0, 5.0))
    FigureCanvasAgg(figure)
    axes = figure.add_subplot()
    grid = region.assembles if region.assembles.ndim == 2 else region.assembles[:, None]
    x = shown(region.grid[0], region.axes[0])
    y = shown(region.grid[1], region.axes[1]) if len(region.grid) > 1 else np.array([0.0, 1.0])
    axes.pcolormesh(x, y if len(region.grid) > 1 else y[:1], grid.T.astype(float),
                    cmap='Greens', vmin=-0.2, vmax=1.0, shading='nearest')
    axes.set_xlabel(label(region.grid[0]))
    if len(region.grid) > 1:
        axes.set_ylabel(label(region.grid[1]))
    axes.set_title(f'{region.scene}: where it assembles (green), '
                   f'{100.0 * region.fraction:.4g}% of the grid')
    figure.savefig(path, dpi=100)


def _e(value: float) -> str:
    """Return an error estimate to 2 significant digits."""
    return f'{value:.2g}'


def turning_text(study: Any, scene: Any, flywheel: Any = None) -> list[str]:
    """Return the turning-moment lines of ``check`` (angles in the scene's unit, SI otherwise).

    ``study`` is a :class:`~mech_kinematics.geometry.turning.TurningMoment`,
    ``flywheel`` one of its :class:`~mech_kinematics.geometry.turning.Flywheel`.
    """
    from ..geometry.assembly import angle_text
    from ..units import rpm_from_rad_per_s

    units = scene.units

    def angle(theta: float) -> str:
        return f'{angle_text(units, theta)} {units.angle}'

    kinds = {d.name: d for d in scene.drivers}
    how = '' if study.accel == 0.0 else f', accelerating at {study.accel:.6g} rad/s^2'
    held = ''.join(f', {name} held at {kinds[name].position_text(x, units)}'
                   for name, x in study.held.items())
    lines = [f'turning moment (crank "{study.crank}" turning at '
             f'{rpm_from_rad_per_s(study.speed):.6g} rpm{how}{held}; efforts in N m for a '
             f'crank, N for an actuator, each +- its error):']
    for name, effort in study.drivers.items():
        top, low = effort.maximum, effort.minimum
        lines.append(f'  {name}: mean {effort.mean:.6g} {effort.unit} '
                     f'(+-{_e(effort.mean_error)}), largest {top.value:.6g} at '
                     f'{angle(top.angle)} (+-{_e(top.bound)}), least '
                     f'{low.value:.6g} at {angle(low.angle)} (+-{_e(low.bound)})')
    if study.energy_max is None:
        where = 'the effort stays at its mean'
    else:
        count = len(study.crossings)
        where = (f'energy least at crank {angle(study.energy_min)}, most at '
                 f'{angle(study.energy_max)} ({count} crossing{"s" if count != 1 else ""} of '
                 f'the mean)')
    lines.append(f'fluctuation of energy ({study.crank}): {study.fluctuation:.6g} J '
                 f'(+-{_e(study.fluctuation_error)}); {where}')
    if flywheel is not None:
        lines.append(f'flywheel for Cs = {flywheel.cs:.6g} (Cs = (w_max - w_min) / w_mean, '
                     f'w_mean = {flywheel.speed:.6g} rad/s): I = dE / (w_mean^2 Cs) = '
                     f'{flywheel.inertia:.6g} kg m^2 (+-{_e(flywheel.error)})')
    return lines


def turning_json(study: Any, flywheel: Any = None) -> dict[str, Any]:
    """Return the ``"turning_moment"`` object of ``check --json``: SI (rad, N m, N, J)."""
    def extreme(x: Any) -> dict[str, float]:
        return {'value': x.value, 'angle': x.angle, 'bound': x.bound}

    data: dict[str, Any] = {
        'crank': study.crank, 'speed': study.speed, 'accel': study.accel,
        'held': dict(study.held),
        'efforts': {name: {'unit': e.unit, 'mean': e.mean, 'mean_error': e.mean_error,
                           'max': extreme(e.maximum), 'min': extreme(e.minimum)}
                    for name, e in study.drivers.items()},
        'power': study.power,
        'crossings': list(study.crossings),
        'loops': [{'start': x.start, 'end': x.end, 'area': x.area, 'error': x.error}
                  for x in study.loops],
        'fluctuation': study.fluctuation, 'fluctuation_error': study.fluctuation_error,
        'energy_max_angle': study.energy_max, 'energy_min_angle': study.energy_min,
        'panels': study.panels,
    }
    if flywheel is not None:
        data['flywheel'] = {'cs': flywheel.cs, 'speed': flywheel.speed,
                            'inertia': flywheel.inertia, 'error': flywheel.error}
    return data


def _refuse_unless_turning(scene: Any, flag: str) -> None:
    """Refuse ``flag`` in one line where there is no one crank's turning moment to give it to."""
    if scene.dynamics is None:
        msg = (f'Expected a scene with masses, gravity or loads for {flag}, got {scene.name} '
               f'without')
        raise SceneError(msg)
    if not scene.single_crank:
        msg = (f'Expected a scene driven by one crank for {flag}, got {scene.name}, driven by '
               f'{", ".join(d.name for d in scene.drivers)}')
        raise SceneError(msg)


def _at_speed(scene: Any, rpm: float) -> Any:
    """Return ``scene`` with its crank turning at ``rpm`` (``--speed-rpm``), or a one-line refusal.

    For a scene with forces and one crank only (the turning moment's); the
    whole report (the strokes' sense too) is then the scene's at that speed.
    """
    from dataclasses import replace

    from ..units import rad_per_s_from_rpm

    _refuse_unless_turning(scene, '--speed-rpm')
    crank = replace(scene.input, speed=rad_per_s_from_rpm(rpm), rpm=float(rpm))
    if scene.inputs:
        return replace(scene, input=crank, inputs=(crank,))
    return replace(scene, input=crank)


def _turning(scene: Any, cs: float | None) -> tuple[Any, Any, str]:
    """Return the scene's turning-moment study, its flywheel for ``cs``, or why there is none.

    ``(None, None, '')`` for a scene without forces. Asked for a flywheel
    (``cs``), a scene that cannot give one is refused in one line.
    """
    from ..geometry.turning import turning_moment_from_scene

    if cs is not None:
        _refuse_unless_turning(scene, '--flywheel')
    if scene.dynamics is None:
        return None, None, ''
    try:
        study = turning_moment_from_scene(scene)
    except SceneError as error:
        if cs is not None:
            raise
        return None, None, str(error)
    if cs is None:
        return study, None, ''
    try:
        return study, study.flywheel(cs), ''
    except ValueError as error:
        hint = '; give the crank a speed with --speed-rpm N' if study.speed == 0.0 else ''
        raise SceneError(f'{error}{hint}') from None


def _print_report(args: argparse.Namespace, scene: Any, data: dict[str, Any], text: str,
                  robot: Any = None) -> None:
    """Print the report (text or JSON) with the scene's turning moment, if it has forces.

    A robot described in URDF with ``<inertial>``s: its actuated joints'
    efforts at rest over each one's range instead (:func:`sweeps_text`).
    """
    study, flywheel, refused, sweeps = None, None, '', None
    if robot is None:
        study, flywheel, refused = _turning(scene, args.flywheel)
    elif robot.forces is not None:
        from ..robot.forces import effort_sweeps

        sweeps = effort_sweeps(robot, gravity=gravity_of(args), loads=link_loads_of(args))
    if args.json:
        if study is not None:
            data['turning_moment'] = turning_json(study, flywheel)
        elif refused:
            data['turning_moment'] = {'refused': refused}
        if sweeps is not None:
            data['efforts_at_rest'] = sweeps_json(sweeps)
        data['paths'] = paths(scene)   # which path served each solve, after the check's
        print(json.dumps(data, indent=1, allow_nan=False))
        return
    lines = [text]
    if study is not None:
        lines.extend(turning_text(study, scene, flywheel))
    elif refused:
        lines.append(f'turning moment: none ({refused})')
    if sweeps is not None:
        lines.extend(sweeps_text(sweeps))
    print('\n'.join(lines))


def sweeps_text(sweeps: Sequence[Any]) -> list[str]:
    """Return the lines of a robot's efforts at rest over each actuated joint's range (SI)."""
    g = ', '.join(f'{x:.6g}' for x in sweeps[0].gravity)
    lines = [f'efforts at rest (gravity [{g}] m/s^2 in the root frame; N m for a revolute '
             'joint, N for a prismatic one, positive along its axis, each +- its bound):']
    for sweep in sweeps:
        q = sweep.positions
        unit = 'rad' if sweep.angular else 'm'
        held = ''.join(f', {n} held at {x:.6g}' for n, x in sweep.held.items())
        solved = int(sweep.valid.sum())
        head = (f'  {sweep.joint} from {q[0]:.6g} to {q[-1]:.6g} {unit} ({len(q)} positions'
                f'{held}; solved at {solved})')
        if not solved:
            lines.append(f'{head}: none solved ({sweep.refused})')
            continue
        parts = []
        for name in sweep.efforts:
            (top, at_top, b_top), (low, at_low, b_low) = sweep.extremes(name)
            parts.append(f'{name} largest {top:.6g} at {at_top:.6g} {unit} (+-{_e(b_top)}), '
                         f'least {low:.6g} at {at_low:.6g} {unit} (+-{_e(b_low)})')
        tail = f'; not solved {sweep.refused}' if sweep.refused else ''
        lines.append(f'{head}: {"; ".join(parts)}{tail}')
    return lines


def sweeps_json(sweeps: Sequence[Any]) -> list[dict[str, Any]]:
    """Return ``"efforts_at_rest"`` of ``check --json`` on a robot: SI (rad or m, N m or N)."""
    out = []
    for sweep in sweeps:
        efforts = {name: {key: {'value': v, 'at': at, 'bound': b}
                          for key, (v, at, b) in zip(('max', 'min'), sweep.extremes(name),
                                                     strict=True)}
                   for name in sweep.efforts} if sweep.valid.any() else {}
        out.append({'joint': sweep.joint, 'range': [float(sweep.positions[0]),
                                                    float(sweep.positions[-1])],
                    'positions': len(sweep.positions), 'solved': int(sweep.valid.sum()),
                    'held': dict(sweep.held), 'gravity': list(sweep.gravity),
                    'efforts': efforts, 'refused': sweep.refused or None})
    return out


def workspace_text(ws: Any) -> str:
    """Return the report of ``check --workspace`` as lines of text, in the scene's units."""
    units = ws.units

    def length(value: float) -> str:
        return units.length_text(value)

    total = ws.assembles.size
    ranges = ', '.join(f'{axis} from {length(lo)} to {length(hi)}'
                       for axis, (lo, hi) in zip('xyz', ws.extent))
    told = '' if ws.lift is None else ' (in the root frame)'
    what = ws.point if ws.lift is None else f'frame {ws.point}'
    lines = [f'{ws.scene}: workspace of {what} over {ws.drivers[0]} x {ws.drivers[1]} '
             f'({len(ws.axes[0])} x {len(ws.axes[1])} points; assembles at '
             f'{100.0 * float(ws.assembles.mean()):.4g}%, {int(ws.assembles.sum())} of {total})',
             f'{ws.point}{told}: {ranges}',
             f'the drivers lose control (det J = 0): {len(ws.inverse_singular)} points, solved '
             'on the grid edges where det J changes sign',
             f'the loop locks (the edge of where it assembles): {len(ws.locks)} points, at the '
             'grid',
             f'a singular pose between grid neighbours (no curve read across): '
             f'{len(ws.jumps)} edges',
             f'the point moves up to {length(ws.resolution)} between smoothly joined '
             'neighbours']
    return '\n'.join(lines)


def workspace_json(ws: Any) -> dict[str, Any]:
    """Return the report of ``check --workspace --json``: SI units (m, rad)."""
    out = {
        'scene': ws.scene, 'point': ws.point, 'drivers': list(ws.drivers),
        'grid': {'points': [len(a) for a in ws.axes], 'assembling': int(ws.assembles.sum()),
                 'fraction': float(ws.assembles.mean())},
        'extent': {axis: list(span) for axis, span in zip('xyz', ws.extent)},
        'inverse_singular': {'positions': ws.told(ws.inverse_singular).tolist(),
                             'drivers': ws.singular_drivers.tolist()},
        'locks': {'positions': ws.told(ws.locks).tolist(), 'drivers': ws.lock_drivers.tolist()},
        'jumps': ws.told(ws.jumps).tolist(),
        'resolution': ws.resolution,
        'start': ws.told(ws.start)[0].tolist() if np.isfinite(ws.start).all() else None,
    }
    if ws.lift is not None:     # a URDF frame: told in the root frame, with the loop's plane
        e, o = ws.lift
        out['frame'] = 'root'
        out['plane'] = {'origin': o.tolist(), 'x': e[:, 0].tolist(), 'y': e[:, 1].tolist()}
    return out


def write_workspace_png(ws: Any, path: str, space: Any = None) -> None:
    """Write the workspace as a PNG picture: where the point goes and its singular curves.

    ``space``: the mechanism to draw under it (a
    :class:`~mech_kinematics.geometry.diagrams.SpaceDiagram`, in the plane).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    scale = 1000.0 if ws.units.length == 'mm' else 1.0
    figure = Figure(figsize=(6.0, 6.0))
    FigureCanvasAgg(figure)
    axes = figure.add_subplot()
    # A URDF frame: drawn in the loop's plane, at the root frame's coordinates along its axes.
    e = np.eye(2) if ws.lift is None else ws.lift[0]

    def drawn(points: Any) -> Any:
        return ws.told(points) @ e * scale

    if space is not None:   # the mechanism where its drivers start, under the map
        for link in space.links:
            outline = drawn(link.outline if len(link.outline) <= 2
                            else np.vstack([link.outline, link.outline[:1]]))
            axes.plot(*outline.T, c='0.3', lw=1.5, zorder=3)
        for pivot in space.pivots:
            axes.plot(*drawn(pivot.xy).T, 'k^', ms=6, zorder=4)
    reach = drawn(ws.positions[ws.assembles])
    axes.scatter(reach[:, 0], reach[:, 1], s=1, c='0.75', label=f'{ws.point} reaches')
    for points, colour, label in ((ws.inverse_singular, 'tab:red', 'det J = 0'),
                                  (ws.locks, 'tab:blue', 'the loop locks')):
        if len(points):
            axes.scatter(*drawn(points).T, s=3, c=colour, label=label)
    if np.isfinite(ws.start).all():
        axes.plot(*drawn(ws.start).T, '*', c='tab:orange', ms=10, zorder=5,
                  label=f'{ws.point} where the drivers start')
    axes.set_aspect('equal')
    if ws.lift is None:
        axes.set_xlabel(f'x ({ws.units.length})')
        axes.set_ylabel(f'y ({ws.units.length})')
    else:
        for label, k in ((axes.set_xlabel, 0), (axes.set_ylabel, 1)):
            axis = ', '.join(f'{round(float(v), 12) + 0.0:.3g}' for v in e[:, k])
            label(f'along ({axis}) of the root frame ({ws.units.length})')
    axes.legend(loc='upper right', fontsize='small')
    axes.set_title(f'{ws.scene}: the workspace of {ws.point}')
    figure.savefig(path, dpi=100)


def _handle_workspace(args: argparse.Namespace, scene: Any, robot: Any = None) -> int:
    given = [flag for flag, value in (('--pair', args.pair), ('--map', args.map),
                                      ('--flywheel', args.flywheel)) if value]
    if given:
        msg = f'Expected --workspace without {", ".join(given)}, got both'
        raise SceneError(msg)
    ws = workspace_of(scene, args.workspace, args.grid, robot)
    if args.json:
        print(json.dumps(workspace_json(ws), indent=1, allow_nan=False))
    else:
        print(workspace_text(ws))
    if args.png is not None:
        draw_workspace(ws, scene, args.png)
    return 0


def workspace_of(scene: Any, name: str, grid: int, robot: Any = None) -> Any:
    """Return the workspace of a scene's point ``name``, or of a robot's link frame origin.

    A URDF robot's ``name`` that is not a point of its scene is a link frame,
    mapped in the root frame (:func:`~mech_kinematics.robot.targets.frame_workspace`).
    """
    from ..geometry.workspace import workspace_from_scene

    if robot is not None and name not in scene.output_points:
        from ..robot.targets import frame_workspace     # a link frame, in the root frame

        return frame_workspace(robot, name, grid)
    return workspace_from_scene(scene, name, grid)


def draw_workspace(ws: Any, scene: Any, path: str | Path) -> None:
    """Write ``ws`` as a PNG over ``scene``'s mechanism where its drivers start.

    What ``check --workspace --png`` and ``plot --workspace`` draw.
    """
    from ..geometry.diagrams import space_from_state
    from ..geometry.instant_centres import full_scene
    from ..geometry.urdf import _assembled

    full = full_scene(scene)
    write_workspace_png(ws, str(path), space_from_state(full, _assembled(full)))


def target_report(inverse: Any, tmap: Any, singularity: Mapping[str, float]) -> dict[str, Any]:
    """Return how well the drivers control the targets at an inverse's answer (SI).

    The Jacobian scaled to be dimensionless (targets over their scales, drivers
    over theirs: 1 rad, or the mechanism's size), its singular values and
    condition number; the forward loop's least singularity measure (0
    singular, 1 best) and where; the drivers' bounds against the exact inverse.
    """
    scaled = (inverse.jacobian / np.array(tmap.target_scales)[:, None]
              * np.array(tmap.driver_scales)[None, :])
    sigma = np.linalg.svd(scaled, compute_uv=False)
    worst = min(singularity, key=lambda k: singularity[k]) if singularity else None
    return {
        'targets': {n: float(g) for n, g in zip(inverse.targets, inverse.given[:, 0],
                                                strict=True)},
        'drivers': {n: float(q) for n, q in zip(inverse.drivers, inverse.motion[:, 0],
                                                strict=True)},
        'continued_from': {n: float(q) for n, q in zip(inverse.drivers, inverse.start,
                                                       strict=True)},
        'steps': inverse.steps,
        'det_jacobian': float(np.linalg.det(inverse.jacobian)),
        'scaled_singular_values': [float(x) for x in sigma],
        'condition': float(sigma[0] / sigma[-1]) if sigma[-1] > 0.0 else math.inf,
        'least_singularity': None if worst is None else {
            'dyad': worst, 'measure': float(singularity[worst])},
        'error_bound': {n: float(b) for n, b in zip(inverse.drivers, inverse.motion_bound[:, 0],
                                                    strict=True)},
    }


def target_text(report: dict[str, Any], tmap: Any, name: str,
                driver_text: Callable[[int, float], str],
                start: Sequence[float] | None = None) -> str:
    """Return :func:`target_report` as lines of text (targets and drivers in their units).

    ``start``: the start pose asked; an answer continued from another (a
    working mode asked, found from the grid of start poses) says which.
    """
    goal = ', '.join(f'{n} = {tmap.text(i, v)}'
                     for i, (n, v) in enumerate(report['targets'].items()))
    drivers = ', '.join(f'{n} = {driver_text(i, v)}'
                        for i, (n, v) in enumerate(report['drivers'].items()))
    bounds = ', '.join(f'{b:.2g}' for b in report['error_bound'].values())
    sigma = ', '.join(f'{x:.6g}' for x in report['scaled_singular_values'])
    origin = list(report['continued_from'].values())
    where = 'the start pose'
    if start is not None and origin != [float(x) for x in start]:
        where = ('the nearest start pose in the working mode asked (' + ', '.join(
            f'{n} = {driver_text(i, v)}'
            for i, (n, v) in enumerate(report['continued_from'].items())) + ')')
    lines = [f'{name}: {goal}: reached from {where} in {report["steps"]} step'
             f'{"s" if report["steps"] != 1 else ""}',
             f'drivers: {drivers} (error bounds {bounds}, rad or m)',
             f'jacobian: det J = {report["det_jacobian"]:.6g} (SI); scaled (targets and '
             f'drivers over their scales) singular values {sigma}, condition number '
             f'{report["condition"]:.6g}']
    least = report['least_singularity']
    if least is not None:
        lines.append(f'the loop: least singularity measure {least["measure"]:.4g} at '
                     f'{least["dyad"]} (0 singular, 1 best)')
    return '\n'.join(lines)


def _handle_target(args: argparse.Namespace) -> int:
    """Check how well the drivers control targets at the pose that reaches them."""
    from ..solver.inverse import continue_to, scene_targets
    from ..units import LENGTH_UNITS

    given: dict[str, dict[str, float]] = {'--target': {}}
    for name, value in args.target:
        if name is None:
            msg = (f'Expected --target NAME=VALUE (a joint, POINT.x|y or, for a URDF, '
                   f'FRAME.x|y|z), got {value:g}')
            raise SceneError(msg)
        given['--target'][name] = value
    names = tuple(given['--target'])
    if is_urdf(args.scene):
        from ..robot.targets import robot_targets

        robot = load_robot_argument(args)
        tmap = robot_targets(robot, names)
        start = [robot.start(n) for n in robot.actuated]
        per_metre = 1.0
        answer_of = (lambda inverse: inverse.answer.state)  # noqa: E731

        def driver_text(i: int, value: float) -> str:
            return f'{value:.6g} {"rad" if tmap.driver_angular[i] else "m"}'
    else:
        scene = load_scene_argument(args)
        tmap = scene_targets(scene, names)
        start = [d.start for d in scene.drivers]
        per_metre = 1.0 if args.units == 'si' else LENGTH_UNITS[scene.units.length]
        answer_of = (lambda inverse: inverse.answer)  # noqa: E731

        def driver_text(i: int, value: float) -> str:
            return scene.units.angle_text(value) if tmap.driver_angular[i] else \
                scene.units.length_text(value)
    goal, _, _ = targets_in_si(given, tmap.target_angular, args, per_metre)
    inverse = continue_to(tmap, goal, start, branch=branches_of(args))
    report = target_report(inverse, tmap, dict(answer_of(inverse).singularity))
    if args.json:
        print(json.dumps(report, indent=1, allow_nan=False))
    else:
        print(target_text(report, tmap, args.scene, driver_text, start))
    return 0


def _handle_region(args: argparse.Namespace, scene: Any, robot: Any = None) -> int:
    from ..geometry.region import region_from_scene
    pair = None if args.pair is None else [p.strip() for p in args.pair.split(',')]
    region = region_from_scene(scene, args.grid, pair)
    _print_report(args, scene, region_json(region, scene, args.map) if args.json else {},
                  '' if args.json else region_text(region, scene, args.map), robot)
    if args.png is not None:
        write_region_png(region, args.png)
    return 0


def _handle(args: argparse.Namespace) -> int:
    from ..geometry.assembly import assembly_from_scene

    given = [flag for flag, key in (('--gravity', 'gravity'), ('--payload', 'payload'),
                                    ('--link-force', 'link_force'),
                                    ('--link-torque', 'link_torque')) if getattr(args, key)]
    if args.target:
        if given:
            msg = (f'Expected --target without {", ".join(given)} (check --target reports how '
                   f'well the drivers control the targets, no efforts), got both')
            raise SceneError(msg)
        return _handle_target(args)
    # A scene, or a URDF's loops as a scene; a SceneError is one line, exit 2 (cli.run_handler).
    robot = load_robot_argument(args) if is_urdf(args.scene) else None
    scene = load_scene_argument(args) if robot is None else robot.scene
    if given and (robot is None or robot.forces is None):
        what = (f'scene {args.scene}' if robot is None else
                f'{robot.name}, whose links carry no <inertial>: there are no forces')
        msg = (f'Expected {", ".join(given)} with a robot described in URDF whose links carry '
               f'<inertial>s (its efforts at rest), got {what}')
        raise SceneError(msg)
    turning = [flag for flag, value in (('--speed-rpm', args.speed_rpm),
                                        ('--flywheel', args.flywheel)) if value is not None]
    if robot is not None and robot.forces is not None and turning:
        msg = (f'Expected {", ".join(turning)} with a scene driven by one crank (a '
               f'turning-moment diagram), got {robot.name}, a robot described in URDF: its '
               "efforts at rest over each actuated joint's range are given instead (a URDF "
               "crank's turning moment is not built)")
        raise SceneError(msg)
    if args.speed_rpm is not None:
        scene = _at_speed(scene, args.speed_rpm)
    if args.workspace is not None:
        return _handle_workspace(args, scene, robot)
    if not scene.single_crank:
        return _handle_region(args, scene, robot)
    given = [flag for flag, value in (('--grid', args.grid != GRID), ('--pair', args.pair),
                                      ('--map', args.map), ('--png', args.png)) if value]
    if given:
        msg = (f'Expected a scene with several drivers or an actuator for {", ".join(given)}, '
               f'got {scene.name}, driven by one crank: drop {", ".join(given)}')
        raise SceneError(msg)
    assembly = assembly_from_scene(scene)
    _print_report(args, scene, report_json(assembly, scene) if args.json else {},
                  '' if args.json else report_text(assembly, scene), robot)
    return 0


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register the ``check`` command on ``subparsers``; return its parser."""
    parser: argparse.ArgumentParser = subparsers.add_parser(
        'check', help='where a scene assembles over a crank turn, toggles, dead centres, '
                      'transmission angle, Grashof class', description=CHECK_HELP,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    add_scene_argument(parser)
    add_robot_arguments(parser)
    add_gravity_argument(parser)
    add_units_argument(parser, ('--reference',))
    parser.add_argument('--json', action='store_true',
                        help='print one JSON object, in SI units (rad, m)')
    parser.add_argument('--grid', type=grid_size, default=GRID, metavar='N',
                        help=f'several drivers: grid points per driver (default {GRID}; a '
                             f'crank every {360 // GRID} deg)')
    parser.add_argument('--pair', metavar='A,B',
                        help='several drivers: the two drivers of the grid (default the first '
                             'two)')
    parser.add_argument('--map', action='store_true',
                        help='several drivers: draw the grid in text (also in --json)')
    parser.add_argument('--png', metavar='FILE',
                        help='several drivers: write the grid as a PNG picture')
    parser.add_argument('--target', type=named_value, action='append', metavar='NAME=VALUE',
                        help='how well the drivers control targets (as solve --target takes '
                             'them) at the pose that reaches them, continued from the start '
                             "pose: the Jacobian, its condition, the loop's singularity")
    add_branch_argument(parser)
    parser.add_argument('--workspace', metavar='POINT',
                        help='a scene with two drivers: map where POINT can go over the grid, '
                             'with its singular curves (det J = 0, where the drivers lose '
                             'control, and where the loop locks); a URDF: POINT may be a '
                             'link frame (its origin, in the root frame); --png draws it over '
                             'the mechanism')
    parser.add_argument('--flywheel', type=coefficient, metavar='CS',
                        help='a scene with forces and one crank: the moment of inertia of a '
                             'flywheel for the coefficient of fluctuation of speed CS = (w_max - '
                             'w_min) / w_mean, e.g. 0.02')
    parser.add_argument('--speed-rpm', type=finite_float, metavar='N',
                        help="a scene with forces and one crank: the crank's speed for the "
                             'turning moment and the flywheel, rpm, + CCW (default: the '
                             "scene's; a crank at rest, as a URDF's scene, needs one for "
                             '--flywheel)')
    parser.set_defaults(handler=_handle)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``check``; return the exit status."""
    return run_tool(add_parser, argv)


if __name__ == '__main__':
    sys.exit(main())
