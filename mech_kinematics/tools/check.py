# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""``python -m mech_kinematics check SCENE``: what a scene does over one crank turn.

Prints where the mechanism assembles, its toggle and dead-centre positions,
its minimum transmission angle and the Grashof class of every four-bar loop,
from :func:`mech_kinematics.geometry.assembly.assembly_from_scene`: text in
the scene's own units, or ``--json`` in SI units (rad, m).
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
import json
import sys
from typing import Any

from .cli import add_scene_argument, run_tool

__all__ = ['add_parser', 'main', 'report_text', 'report_json']

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
        where = (f'{angle_text(units, centre.position)} {unit}' if centre.kind == 'revolute'
                 else f's = {units.length_text(centre.position)}')
        text = f'{angle(centre.angle)} ({centre.joint} reverses at {where}'
        if centre.in_line is not None:
            text += f'; {centre.in_line[0]} and {centre.in_line[1]} in line'
        centres.append(text + ')')
    lines.append(f'dead centres: {", ".join(centres) if centres else "none"}')
    if assembly.transmission:
        worst = min(assembly.transmission, key=lambda t: t.minimum)
        lines.append(f'minimum transmission angle: {angle(worst.minimum)} at crank angle '
                     f'{angle(worst.angle)} ({worst.dyad}: {" and ".join(worst.links)})')
        for other in assembly.transmission:
            if other is not worst:
                lines.append(f'  {other.dyad}: {angle(other.minimum)} at crank angle '
                             f'{angle(other.angle)}')
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
            return (f'{angle_text(units, x)} {unit}' if output.kind == 'revolute'  # noqa: B023
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
        'dead_centres': [{'angle': c.angle, 'joint': c.joint, 'type': c.kind,
                          'position': c.position,
                          'in_line': None if c.in_line is None else list(c.in_line)}
                         for c in assembly.dead_centres],
        'transmission': [{'dyad': t.dyad, 'links': list(t.links), 'minimum': t.minimum,
                          'angle': t.angle} for t in assembly.transmission],
        'loops': [{'names': dict(zip(('ground', 'input', 'coupler', 'output'), loop.names,
                                     strict=True)),
                   'points': list(loop.points),
                   'lengths': dict(zip(('ground', 'input', 'coupler', 'output'), loop.lengths,
                                       strict=True)),
                   'class': loop.grashof} for loop in assembly.loops],
        'strokes': [{'joint': s.joint, 'type': s.kind, 'time_ratio': s.time_ratio,
                     'strokes': [{'from_angle': x.start, 'to_angle': x.end,
                                  'crank_travel': x.crank_travel,
                                  'from_position': x.start_position,
                                  'to_position': x.end_position} for x in s.strokes]}
                    for s in strokes_from_assembly(scene, assembly)],
        'intermittent': [{'lever': i.lever, 'index': i.index, 'engaged': list(i.engaged),
                          'engaged_travel': i.engaged_travel, 'locked_travel': i.locked_travel}
                         for i in intermittent_from_scene(scene)],
    }


def _handle(args: argparse.Namespace) -> int:
    from ..geometry.assembly import assembly_from_scene
    from ..scene import load_scene

    scene = load_scene(args.scene)  # a SceneError is one line, exit 2 (cli.run_handler)
    assembly = assembly_from_scene(scene)
    if args.json:
        print(json.dumps(report_json(assembly, scene), indent=1, allow_nan=False))
    else:
        print(report_text(assembly, scene))
    return 0


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register the ``check`` command on ``subparsers``; return its parser."""
    parser: argparse.ArgumentParser = subparsers.add_parser(
        'check', help='where a scene assembles over a crank turn, toggles, dead centres, '
                      'transmission angle, Grashof class', description=CHECK_HELP,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    add_scene_argument(parser)
    parser.add_argument('--json', action='store_true',
                        help='print one JSON object, in SI units (rad, m)')
    parser.set_defaults(handler=_handle)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``check``; return the exit status."""
    return run_tool(add_parser, argv)


if __name__ == '__main__':
    sys.exit(main())
