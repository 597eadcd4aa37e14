# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Draw the figures of ``docs/scene_format.md`` from the solver (run from the repository root).

- ``docs/scene_format_branches.png``: the two assembly branches of an RRR
  dyad (the new pin left or right of the directed line between the links'
  starts) and of an RRP dyad (the larger or smaller slider coordinate), each
  solved by :func:`mech_kinematics.solve` from a small scene;
- ``docs/diagram_geneva_dwell.png``: the packaged Geneva wheel locked in a
  dwell (``diagram geneva --angle-deg 300``).

Run it again after a change to the branch conventions or to the diagrams.
"""

from __future__ import annotations

from pathlib import Path
import sys

import numpy as np

import mech_kinematics as mk
from mech_kinematics.geometry.diagrams import diagram_from_scene
from mech_kinematics.tools.diagram import write_diagram

DOCS = Path(__file__).resolve().parent.parent / 'docs'


def _rrr(branch: mk.Branch) -> tuple[dict[str, complex], float, float]:
    links = (mk.Link('first', 'B', 0.13), mk.Link('second', 'D', 0.09))
    scene = mk.Scene('rrr', {'A': (0.0, 0.0), 'D': (0.15, 0.0)},
                     mk.Crank('crank', 'A', 'B', 0.04, np.radians(60.0)),
                     (mk.RRR('C', links, branch),))
    state = mk.solve(scene, scene.input.angle)
    return {n: complex(p[0]) for n, p in state.complex_points.items()}, 0.13, 0.09


def _rrp(branch: mk.Branch) -> tuple[dict[str, complex], float]:
    dyad = mk.RRP('P', mk.Link('rod', 'B', 0.1), 'O', 0.0, 'slider', branch)
    scene = mk.Scene('rrp', {'A': (0.0, 0.04), 'O': (0.0, 0.0)},
                     mk.Crank('crank', 'A', 'B', 0.03, np.radians(20.0)), (dyad,))
    state = mk.solve(scene, scene.input.angle)
    return ({n: complex(p[0]) for n, p in state.complex_points.items()},
            float(state.joints['slider'].position))


def draw_branches(path: Path) -> Path:
    """Draw the RRR and RRP branch conventions to ``path``."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11.0, 4.6), layout='constrained')
    left, right = fig.subplots(1, 2)
    colours = {mk.Branch.PLUS: '#1f77b4', mk.Branch.MINUS: '#d62728'}
    for branch in (mk.Branch.PLUS, mk.Branch.MINUS):
        p, l1, l2 = _rrr(branch)
        b, d, c = p['B'], p['D'], p['C']
        colour = colours[branch]
        left.plot([b.real, c.real, d.real], [b.imag, c.imag, d.imag], '-o', color=colour,
                  lw=2.5, label=f'branch: {int(branch):+d}')
        left.annotate(f'C (branch {int(branch):+d})', (c.real, c.imag), xytext=(6, 4),
                      textcoords='offset points', color=colour)
    t = np.linspace(0, 2 * np.pi, 200)
    for centre, radius in ((b, l1), (d, l2)):
        left.plot(centre.real + radius * np.cos(t), centre.imag + radius * np.sin(t), ':',
                  color='0.6', lw=0.8)
    left.annotate('', (d.real, d.imag), (b.real, b.imag),
                  arrowprops={'arrowstyle': '-|>', 'color': 'black', 'lw': 1.2})
    for name in ('B', 'D'):
        left.annotate(name, (p[name].real, p[name].imag), xytext=(-12, -14),
                      textcoords='offset points', fontweight='bold')
    left.set_title('RRR: links [{name: first, from: B}, {name: second, from: D}]\n'
                   '+1: C left of the directed line B → D; -1: right', fontsize=10)
    for branch in (mk.Branch.PLUS, mk.Branch.MINUS):
        p, s = _rrp(branch)
        b, q = p['B'], p['P']
        colour = colours[branch]
        right.plot([b.real, q.real], [b.imag, q.imag], '-o', color=colour, lw=2.5)
        right.annotate(f'P (branch {int(branch):+d}, s = {s * 1000:.1f} mm)', (q.real, q.imag),
                       xytext=(-40, -20), textcoords='offset points', color=colour)
    right.plot([-0.075, 0.13], [0.0, 0.0], color='0.45', lw=1.0, zorder=0)
    right.annotate('', (0.135, 0.0), (0.11, 0.0),
                   arrowprops={'arrowstyle': '-|>', 'color': '0.45', 'lw': 1.0})
    right.plot([0.0], [0.0], 'k^')
    right.annotate('O (guide: through O, angle 0)', (0.0, 0.0), xytext=(4, 8),
                   textcoords='offset points')
    right.annotate('B', (b.real, b.imag), xytext=(4, 6), textcoords='offset points',
                   fontweight='bold')
    right.set_title('RRP: link {name: rod, from: B}, guide {through: O, angle: 0}\n'
                    '+1: the larger slider coordinate s along the guide; -1: the smaller',
                    fontsize=10)
    for ax in (left, right):
        ax.set_aspect('equal', adjustable='datalim')
        ax.grid(True, alpha=0.3)
        ax.set_xlabel('x [m]')
        ax.set_ylabel('y [m]')
    left.legend(loc='lower right', fontsize=9)
    fig.savefig(path, dpi=110)
    return path


def main() -> int:
    """Write both figures into ``docs/``."""
    print(draw_branches(DOCS / 'scene_format_branches.png'))
    scene = mk.load_scene('geneva')
    print(write_diagram(diagram_from_scene(scene, 300.0, degrees=True), scene,
                        DOCS / 'diagram_geneva_dwell.png'))
    return 0


if __name__ == '__main__':
    sys.exit(main())
