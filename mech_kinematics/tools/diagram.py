# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Draw the diagrams of :mod:`mech_kinematics.geometry.diagrams` with matplotlib.

:func:`figure_from_diagram`, :func:`write_diagram` and :func:`write_animation`
import matplotlib inside their functions and draw on an Agg canvas, so this
module imports with NumPy alone. Diagrams are drawn to a true scale at the
figure's nominal size (``1 cm = 0.1 m/s``), as in a textbook.
``python -m mech_kinematics diagram`` is :func:`main`; with ``--force-polygon
BODY`` it draws the force polygon of one body of a scene with forces instead
(:func:`figure_from_force_polygon`, from
:mod:`mech_kinematics.geometry.force_polygon`).
"""

from __future__ import annotations

import argparse
from collections.abc import Mapping, Sequence
import math
from pathlib import Path
import sys
import textwrap
from typing import Any
import warnings

import numpy as np
import numpy.typing as npt

from .cli import (add_driver_arguments, add_robot_arguments, add_scene_argument,
                  add_units_argument, drive_from_args, finite_float, load_scene_argument,
                  positive_int, run_tool, values_by_driver)
from ..errors import AssemblyError, NearSingularWarning, SceneError
from ..geometry.diagrams import (arrows_from_state, colours_from_scene, Diagram,
                                 diagram_from_scene, fmt_sense, fmt_value, nice_scale, POLE,
                                 Polygon, scale_text, space_from_state, SpaceDiagram,
                                 strokes_from_scene, Table, tables_from_diagram, VectorKind)
from ..geometry.instant_centres import (bodies_from_scene, BodyKind, full_scene,
                                        instant_centres_from_state)
from ..solver import Scene, solve
from ..units import (rad_per_s_from_rpm, radians_from_degrees, rpm_from_rad_per_s,
                     turns_from_degrees)

__all__ = ['add_parser', 'figure_from_diagram', 'figure_from_force_polygon', 'main',
           'title_from_diagram', 'write_animation', 'write_diagram']

Array = npt.NDArray[np.float64]


# --- rendering (matplotlib, imported inside the functions) ----------------

CM = 1.0 / 2.54          # inches per cm
PT_CM = 2.54 / 72.0      # cm per typographic point
PANEL_W = 11.5           # cm, each of the three panels
PANEL_H = 10.0           # cm
PANEL_GAP = 0.9          # cm between panels
MARGIN = 0.6             # cm, left and right
TITLE_H = 1.8            # cm above the panels
FOOT_H = 1.0             # cm reserved at the bottom of a panel for its scale bar
LABEL_PAD = 0.9          # cm kept free around a drawing for its labels
ROW_H = 0.44             # cm per table row
TABLE_ROWS = 60          # rows drawn of a table at most
DPI = 110
FONT = 8.5               # pt, labels
TABLE_FONT = 7.5         # pt
BARREL = 0.55            # of an actuator's length drawn as its barrel

STYLE = {
    VectorKind.RELATIVE: ('-', 1.7), VectorKind.NORMAL: ('-', 1.5),
    VectorKind.TANGENTIAL: ('--', 1.5), VectorKind.CORIOLIS: ('-.', 1.5),
    VectorKind.SLIP: (':', 1.8), VectorKind.ABSOLUTE: ('-', 1.1),
}


def _math_letter(letter: str) -> str:
    base, _, sub = letter.partition('_')
    return f'{base}_{{{sub}}}' if sub else base


def _math_quantity(text: str) -> str:
    """``'a_CB^n = a_C'`` -> mathtext ``'$a_{CB}^{n} = a_{C}$'``."""
    parts = []
    for token in text.split(' = '):
        symbol, _, rest = token.partition('_')
        sub, _, sup = rest.partition('^')
        parts.append(f'{symbol}_{{{sub}}}' + (f'^{{{sup}}}' if sup else ''))
    return '$' + ' = '.join(parts) + '$'


def _math_pair(cell: str) -> str:
    import re
    letters = cell.split(' ') if ' ' in cell else re.findall(r"[^']'*", cell)
    return '$' + r'\,'.join(_math_letter(x) for x in letters) + '$'


def _text_cm(text: str, size: float) -> tuple[float, float]:
    """Approximate width and height of a label, cm."""
    visible = sum(1 for ch in text if ch not in '${}\\_^') - 3 * text.count('\\,')
    return max(visible, 1) * 0.58 * size * PT_CM + 0.1, 1.25 * size * PT_CM + 0.08


class _Placer:
    """Greedy placement of labels next to their anchors, avoiding lines and other labels."""

    def __init__(self, ax: Any, origin: Array, scale: float, size_cm: tuple[float, float],
                 segments: Sequence[tuple[Array, Array]], anchors: Sequence[Array]) -> None:
        self.ax = ax
        self.origin = origin
        self.scale = scale
        self.size = size_cm
        samples = []
        for a, b in segments:
            a_cm, b_cm = self.cm(a), self.cm(b)
            n = max(2, int(np.hypot(*(b_cm - a_cm)) / 0.12) + 1)
            t = np.linspace(0.0, 1.0, n)[:, None]
            samples.append(a_cm + t * (b_cm - a_cm))
        self.lines = np.concatenate(samples) if samples else np.zeros((0, 2))
        self.dots = np.array([self.cm(a) for a in anchors]) if anchors else np.zeros((0, 2))
        self.boxes = np.zeros((0, 4))     # x0, x1, y0, y1 of every label placed

    def cm(self, xy: Array) -> Array:
        return (np.asarray(xy, dtype=np.float64) - self.origin) / self.scale

    def place(self, text: str, anchor: Array, prefer: Array | None = None,
              size: float = FONT, gap: float = 0.1, **kwargs: Any) -> None:
        w, h = _text_cm(text, size)
        a = self.cm(anchor)
        best: tuple[float, Array] | None = None
        for k in range(16):
            angle = 2.0 * math.pi * k / 16.0
            d = np.array([math.cos(angle), math.sin(angle)])
            # centre of a box that clears the anchor by ``gap`` in direction d
            reach = min(abs(w / 2 / d[0]) if d[0] else math.inf,
                        abs(h / 2 / d[1]) if d[1] else math.inf)
            c = a + d * (reach + gap)
            x0, x1, y0, y1 = c[0] - w / 2, c[0] + w / 2, c[1] - h / 2, c[1] + h / 2
            cost = 0.0
            if len(self.boxes):
                boxes = self.boxes
                ox = np.minimum(x1, boxes[:, 1]) - np.maximum(x0, boxes[:, 0])
                oy = np.minimum(y1, boxes[:, 3]) - np.maximum(y0, boxes[:, 2])
                hit = (ox > 0) & (oy > 0)
                cost += float(np.sum(200.0 * (ox[hit] * oy[hit] + 0.1)))
            if len(self.lines):
                inside = ((self.lines[:, 0] > x0) & (self.lines[:, 0] < x1)
                          & (self.lines[:, 1] > y0) & (self.lines[:, 1] < y1))
                cost += 1.0 * float(inside.sum())
            if len(self.dots):
                inside = ((self.dots[:, 0] > x0 - 0.05) & (self.dots[:, 0] < x1 + 0.05)
                          & (self.dots[:, 1] > y0 - 0.05) & (self.dots[:, 1] < y1 + 0.05))
                cost += 6.0 * float(inside.sum())
            width, height = self.size
            out = max(0.0, -x0) + max(0.0, x1 - width) + max(0.0, FOOT_H - y0) \
                + max(0.0, y1 - height)
            cost += 30.0 * out
            if prefer is not None and np.any(prefer):
                cost += 0.8 * (1.0 - float(d @ prefer) / float(np.hypot(*prefer)))
            else:
                cost += 0.05 * k / 16.0
            if best is None or cost < best[0]:
                best = (cost, c)
        assert best is not None
        c = best[1]
        self.boxes = np.vstack([self.boxes, [c[0] - w / 2, c[0] + w / 2, c[1] - h / 2,
                                             c[1] + h / 2]])
        xy = self.origin + c * self.scale
        self.ax.text(xy[0], xy[1], text, ha='center', va='center', fontsize=size, zorder=6,
                     **kwargs)


def _frame(ax: Any, lo: Array, hi: Array, scale: float, width: float = PANEL_W,
           height: float = PANEL_H) -> Array:
    """Set limits for ``scale`` (units per cm) centring lo..hi; return the lower-left corner."""
    centre = (lo + hi) / 2.0
    centre[1] -= FOOT_H / 2.0 * scale
    origin = centre - np.array([width, height]) / 2.0 * scale
    ax.set_xlim(origin[0], origin[0] + width * scale)
    ax.set_ylim(origin[1], origin[1] + height * scale)
    ax.set_xticks([])
    ax.set_yticks([])
    for spine in ax.spines.values():
        spine.set_color('#999999')
        spine.set_linewidth(0.6)
    return origin


def _fit_scale(lo: Array, hi: Array, minimum: float = 0.0) -> float:
    span = hi - lo
    need = max(span[0] / (PANEL_W - 2 * LABEL_PAD),
               span[1] / (PANEL_H - 2 * LABEL_PAD - FOOT_H), minimum)
    return nice_scale(need)


def _scale_bar(ax: Any, origin: Array, scale: float, unit: str, length_cm: float = 2.0) -> None:
    x0 = origin + np.array([0.5, 0.45]) * scale
    x1 = x0 + np.array([length_cm * scale, 0.0])
    ax.plot([x0[0], x1[0]], [x0[1], x1[1]], color='black', lw=1.2, solid_capstyle='butt')
    for i in range(int(length_cm) + 1):
        x = x0[0] + i * scale
        ax.plot([x, x], [x0[1] - 0.08 * scale, x0[1] + 0.08 * scale], color='black', lw=0.8)
    ax.text(x1[0] + 0.25 * scale, x0[1], f'scale {scale_text(scale, unit)}', fontsize=FONT,
            va='center', ha='left')


def _arrow(ax: Any, start: Array, end: Array, colour: str, style: str, lw: float,
           scale: float, zorder: float = 3) -> None:
    """Draw a straight arrow with a solid head whatever the line style (``scale``: 1 cm)."""
    from matplotlib.patches import Polygon as Patch

    d = end - start
    length = float(np.hypot(*d))
    if length <= 1e-9 * scale:
        return
    u = d / length
    head = min(0.28 * scale, 0.45 * length)
    neck = end - u * head
    n = np.array([-u[1], u[0]]) * head * 0.36
    ax.plot([start[0], neck[0]], [start[1], neck[1]], color=colour, lw=lw, ls=style,
            zorder=zorder, solid_capstyle='butt')
    ax.add_patch(Patch([end, neck + n, neck - n], closed=True, facecolor=colour,
                       edgecolor=colour, lw=0.5, zorder=zorder + 0.1))


def _draw_pivot(ax: Any, xy: Array, unit: float) -> None:
    from matplotlib.patches import Polygon as Patch, Rectangle

    h = 0.42 * unit
    ax.add_patch(Patch([xy, xy + [-0.3 * unit, -h], xy + [0.3 * unit, -h]], closed=True,
                       facecolor='white', edgecolor='black', lw=0.9, zorder=1.5))
    ax.add_patch(Rectangle((xy[0] - 0.45 * unit, xy[1] - h - 0.16 * unit), 0.9 * unit,
                           0.16 * unit, facecolor='white', edgecolor='black', hatch='////',
                           lw=0.6, zorder=1.5))


def _block(xy: Array, angle: float, length: float, height: float) -> Array:
    u = np.array([math.cos(angle), math.sin(angle)])
    n = np.array([-u[1], u[0]])
    return np.array([xy + sx * length / 2 * u + sy * height / 2 * n
                     for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))])


def _draw_mechanism(ax: Any, scene: Scene, space: SpaceDiagram, colours: Mapping[str, str],
                    unit: float) -> None:
    """Draw links, pins, ground pivots, sliders and guides; ``unit`` is the data size of 1 cm."""
    from matplotlib.patches import Polygon as Patch

    lengths = [float(np.hypot(*(link.outline[1] - link.outline[0]))) for link in space.links]
    short = min([x for x in lengths if x > 0.0] or [unit])
    block_l, block_h = min(0.9 * unit, 0.45 * short), min(0.5 * unit, 0.25 * short)
    for guide in space.guides:
        slider = next(s for s in space.sliders if s.name == guide.slider)
        n = np.array([-math.sin(slider.angle), math.cos(slider.angle)])
        for side in (-1, 1):
            offset = side * (block_h / 2 + 0.01 * unit) * n
            ax.plot([guide.start[0] + offset[0], guide.end[0] + offset[0]],
                    [guide.start[1] + offset[1], guide.end[1] + offset[1]], color='#555555',
                    lw=0.9, zorder=1)
        length = float(np.hypot(*(guide.end - guide.start)))
        u = (guide.end - guide.start) / length
        ticks = int(length / (0.3 * unit))
        for i in range(ticks + 1):
            p = guide.start + u * i * 0.3 * unit - (block_h / 2 + 0.01 * unit) * n
            q = p - 0.18 * unit * (n + u)
            ax.plot([p[0], q[0]], [p[1], q[1]], color='#555555', lw=0.6, zorder=1)
    for link in space.links:
        colour = colours[link.name]
        xy = link.outline
        for inner, mouth in link.slots:  # a Geneva wheel: its slots, open at the rim
            ax.plot([inner[0], mouth[0]], [inner[1], mouth[1]], color=colour, lw=6.0,
                    zorder=2.2, solid_capstyle='round')
            ax.plot([inner[0], mouth[0]], [inner[1], mouth[1]], color='white', lw=3.6,
                    zorder=2.3, solid_capstyle='butt')
        if len(xy) > 2:
            ax.add_patch(Patch(xy, closed=True, facecolor=colour, alpha=0.22, edgecolor=colour,
                               lw=2.0, zorder=2))
        elif link.kind is BodyKind.LEVER:
            ax.plot(xy[:, 0], xy[:, 1], color=colour, lw=5.0, zorder=2, solid_capstyle='round')
            ax.plot(xy[:, 0], xy[:, 1], color='white', lw=1.4, zorder=2.1)
        else:
            ax.plot(xy[:, 0], xy[:, 1], color=colour, lw=3.0, zorder=2, solid_capstyle='round')
    for actuator in space.actuators:  # a cylinder: its barrel over the rod, from its base pin
        start, end = actuator.start, actuator.end
        barrel = start + BARREL * (end - start)
        ax.plot([start[0], barrel[0]], [start[1], barrel[1]], color=colours[actuator.link],
                lw=8.0, alpha=0.55, zorder=2.2, solid_capstyle='butt')
    for slider in space.sliders:
        corners = _block(slider.xy, slider.angle, block_l, block_h)
        ax.add_patch(Patch(corners, closed=True, facecolor=colours.get(slider.name, 'white'),
                           alpha=0.85, edgecolor='black', lw=0.9, zorder=3))
    for pivot in space.pivots:
        _draw_pivot(ax, pivot.xy, unit)
    topology = bodies_from_scene(scene)
    pinned = {point for _, _, point in topology.pins}
    for name, xy in space.points.items():
        if name in pinned:
            ax.plot(*xy, marker='o', ms=5.5, mfc='white', mec='black', mew=1.0, zorder=5)
        elif name not in space.ground:
            ax.plot(*xy, marker='o', ms=3.5, color='black', zorder=5)
        else:
            ax.plot(*xy, marker='+', ms=6, color='#555555', zorder=5)


def _crank_senses(ax: Any, scene: Scene, diagram: Diagram,
                  unit: float) -> list[tuple[Array, Array]]:
    """Draw an arc arrow at each crank's pivot in its sense of rotation; return the chords."""
    graph = scene.graph
    speeds = {d.name: d.speed for d in diagram.drivers}
    chords = []
    for joint in graph.joints:  # a driven pin: a crank, from its centre to its tip
        if joint.driver and joint.line is None:
            crank = next(m for m in graph.motions if m.body == joint.body)
            chords += _crank_sense(ax, diagram.space, crank.start, crank.end,
                                   speeds.get(joint.name, diagram.speed), unit)
    return chords


def _crank_sense(ax: Any, space: SpaceDiagram, centre: str, tip: str, speed: float,
                 unit: float) -> list[tuple[Array, Array]]:
    """Draw an arc arrow at a crank's pivot in its sense of rotation; return its chords."""
    from matplotlib.patches import FancyArrowPatch

    if speed == 0.0:
        return []
    c = space.points[centre]
    p = space.points[tip]
    theta = math.atan2(p[1] - c[1], p[0] - c[0])
    sign = 1.0 if speed > 0 else -1.0
    r = 0.75 * unit
    arc = [c + r * np.array([math.cos(a), math.sin(a)])
           for a in np.linspace(theta + sign * 0.45, theta + sign * 1.6, 6)]
    ax.add_patch(FancyArrowPatch(tuple(arc[0]), tuple(arc[-1]),
                                 connectionstyle=f'arc3,rad={0.45 * sign}',
                                 arrowstyle='-|>,head_length=5,head_width=2.5', color='black',
                                 lw=0.9, zorder=5))
    return list(zip(arc[:-1], arc[1:], strict=True))


def _space_panel(ax: Any, scene: Scene, diagram: Diagram, colours: Mapping[str, str]) -> float:
    space = diagram.space
    lo, hi = space.extent()
    centres = diagram.instant_centres
    near: list[Any] = []
    far: list[Any] = []
    if centres is not None:
        # Show the finite centres that fit at no less than 2/5 of the mechanism's own scale;
        # point at the others (and at those at infinity) from the edge of the panel.
        middle = (lo + hi) / 2
        base = _fit_scale(lo, hi)
        finite = sorted((c for c in centres if c.point is not None),
                        key=lambda c: float(np.hypot(*(np.asarray(c.point) - middle))))
        for centre in finite:
            assert centre.point is not None
            low, high = np.minimum(lo, centre.point), np.maximum(hi, centre.point)
            if _fit_scale(low, high) <= 2.5 * base:
                near.append(centre)
                lo, hi = low, high
        far = [c for c in centres if c not in near]
    # room for pivots below the ground points
    scale = _fit_scale(lo, hi)
    scale = _fit_scale(lo - [0, 0.7 * scale], hi)
    origin = _frame(ax, lo - [0, 0.7 * scale], hi, scale)
    _draw_mechanism(ax, scene, space, colours, scale)
    sense = _crank_senses(ax, scene, diagram, scale)
    segments = sense + [(link.outline[i], link.outline[(i + 1) % len(link.outline)])
                        for link in space.links
                        for i in range(len(link.outline) - (len(link.outline) == 2))]
    segments += [(g.start, g.end) for g in space.guides]
    placer = _Placer(ax, origin, scale, (PANEL_W, PANEL_H), segments, list(space.points.values()))
    centre_xy = (lo + hi) / 2
    for name, xy in space.points.items():
        placer.place(name, xy, xy - centre_xy, size=FONT + 1, fontweight='bold')
    for link in space.links:
        xy = link.outline
        mid = (xy[0] + xy[1]) / 2 if len(xy) == 2 else xy.mean(axis=0)
        placer.place(link.name, mid, None, size=FONT - 1, color=colours[link.name],
                     style='italic', gap=0.05)
    for slider in space.sliders:
        placer.place(slider.name, slider.xy, None, size=FONT - 1, color='#333333',
                     style='italic', gap=0.35)
    if centres is not None:
        for centre in near:
            assert centre.point is not None
            ax.plot(*centre.point, marker='o', ms=5, mfc='none', mec='#b00000', mew=1.1,
                    zorder=6)
            placer.place(f'$I_{{{centres.label(centre)[1:]}}}$', centre.point, None,
                         size=FONT, color='#b00000')
        middle = origin + np.array([PANEL_W, PANEL_H + FOOT_H]) / 2 * scale
        for centre in far:
            if centre.point is not None:
                d = centre.point - middle
                d = d / np.hypot(*d)
                tag = f'$I_{{{centres.label(centre)[1:]}}}$'
            else:
                assert centre.direction is not None
                d = centre.direction
                tag = f'$I_{{{centres.label(centre)[1:]}}} \\to \\infty$'
            half = np.array([PANEL_W - 1.6, PANEL_H - FOOT_H - 1.2]) / 2 * scale
            t = min(half[0] / abs(d[0]) if d[0] else math.inf,
                    half[1] / abs(d[1]) if d[1] else math.inf)
            tip = middle + d * t
            _arrow(ax, tip - d * 0.7 * scale, tip, '#b00000', '-', 1.0, scale, zorder=6)
            placer.place(tag, tip - d * 0.35 * scale, None, size=FONT, color='#b00000')
    _scale_bar(ax, origin, scale, 'm')
    ax.set_title('Space diagram', fontsize=FONT + 2)
    return scale


def _polygon_panel(ax: Any, polygon: Polygon, colours: Mapping[str, str]) -> float:
    from matplotlib.lines import Line2D

    xy = np.array(list(polygon.letters.values()))
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    scale = _fit_scale(lo, hi)
    origin = _frame(ax, lo, hi, scale)
    segments = []
    components: list[float] = []
    for vector in polygon.vectors:
        style, lw = STYLE[vector.kind]
        if vector.kind in (VectorKind.NORMAL, VectorKind.TANGENTIAL):
            components.append(vector.value)
        if vector.kind is VectorKind.RELATIVE and polygon.quantity == 'acceleration':
            # the closing line of a link's two components; nothing new if one is zero
            done, components = components[-2:], []
            if len(done) == 2 and min(done) <= 1e-9 * max(done):
                segments.append((vector.start, vector.end))
                continue
        if vector.kind is VectorKind.ABSOLUTE or vector.also:
            colour = 'black'
            if vector.also and vector.kind is VectorKind.RELATIVE:
                style, lw = '-', 1.7
                colour = colours.get(vector.body or '', 'black') \
                    if polygon.quantity == 'velocity' else 'black'
        elif vector.kind is VectorKind.RELATIVE and polygon.quantity == 'acceleration':
            colour, style, lw = '#666666', '-', 0.9
        else:
            colour = colours.get(vector.body or '', 'black')
        _arrow(ax, vector.start, vector.end, colour, style, lw, scale)
        segments.append((vector.start, vector.end))
    # Labels: one per position, the point letters first; hide a component's end
    # letter where it coincides with a point's letter.
    # Labels: one per position, the points' letters first. The end of a
    # component (c_b) that falls on or next to a point's letter is named in the
    # same label, or not at all if it coincides exactly.
    middles = {v.head for v in polygon.vectors
               if v.kind in (VectorKind.NORMAL, VectorKind.CORIOLIS)}
    used = {polygon.pole}
    for vector in polygon.vectors:
        used.update((vector.tail, vector.head))
    groups: list[tuple[Array, list[str]]] = []
    pole_names = [polygon.pole, *(g for g in polygon.ground if g in used)]
    order = pole_names + [n for n in polygon.letters if n not in pole_names and n not in middles]
    order += [n for n in polygon.letters if n in middles]
    for name in order:
        if name not in used:
            continue
        at = polygon.letters[POLE] if name in polygon.ground else polygon.letters[name]
        near = 0.3 * scale if name in middles else 0.06 * scale
        for where, names in groups:
            gap = float(np.hypot(*(where - at)))
            if gap <= near:
                if not (name in middles and gap <= 0.06 * scale):
                    names.append(name)
                break
        else:
            groups.append((at, [name]))
    placer = _Placer(ax, origin, scale, (PANEL_W, PANEL_H), segments,
                     [where for where, _ in groups])
    centre = (lo + hi) / 2
    for where, names in groups:
        text = ', '.join(f'${_math_letter(n)}$' for n in dict.fromkeys(names))
        component = all(n in middles for n in names)
        placer.place(text, where, where - centre, size=FONT + (0 if component else 1.5),
                     color='#444444' if component else 'black')
    ax.plot(0.0, 0.0, marker='o', ms=3.5, color='black', zorder=5)
    unit = 'm/s' if polygon.quantity == 'velocity' else 'm/s\u00b2'
    _scale_bar(ax, origin, scale, unit)
    kinds = {v.kind for v in polygon.vectors}
    handles = []
    for kind, text in ((VectorKind.NORMAL, 'normal'), (VectorKind.TANGENTIAL, 'tangential'),
                       (VectorKind.CORIOLIS, 'Coriolis'), (VectorKind.SLIP, 'sliding')):
        if kind in kinds:
            style, lw = STYLE[kind]
            handles.append(Line2D([], [], color='#333333', ls=style, lw=lw, label=text))
    if handles:
        ax.legend(handles=handles, loc='lower right', fontsize=FONT - 1, frameon=False,
                  ncol=len(handles) if len(handles) < 3 else 2, handlelength=2.2,
                  borderaxespad=0.2, columnspacing=1.0, labelspacing=0.2)
    title = 'Velocity diagram' if polygon.quantity == 'velocity' else 'Acceleration diagram'
    ax.set_title(title, fontsize=FONT + 2)
    return scale


def _shown(tables: dict[str, Table]) -> dict[str, Table]:
    """Return ``tables`` with at most :data:`TABLE_ROWS` rows each; a cut one's title says so.

    A long chain's tables would make a figure metres tall (and minutes to draw).
    """
    return {key: table if len(table.rows) <= TABLE_ROWS else Table(
        f'{table.title} (the first {TABLE_ROWS} of {len(table.rows)} rows; solve gives every '
        'value)', table.columns, table.rows[:TABLE_ROWS]) for key, table in tables.items()}


def _table(ax: Any, table: Table, mathcols: Sequence[int] = ()) -> None:
    ax.axis('off')
    rows = [list(row) for row in table.rows]
    for row in rows:
        for i in mathcols:
            if i == 0:
                row[i] = _math_pair(row[i])
            elif i == 1:
                row[i] = _math_quantity(row[i])
    widths = [max([len(table.columns[i])] + [len(r[i]) for r in table.rows]) + 2
              for i in range(len(table.columns))]
    total = float(sum(widths))
    drawn = ax.table(cellText=rows or [[''] * len(table.columns)], colLabels=table.columns,
                     colWidths=[w / total for w in widths], cellLoc='center',
                     bbox=[0.0, 0.0, 1.0, 1.0])
    drawn.auto_set_font_size(False)
    drawn.set_fontsize(TABLE_FONT)
    for (r, _), cell in drawn.get_celld().items():
        cell.set_linewidth(0.4)
        cell.set_edgecolor('#aaaaaa')
        if r == 0:
            cell.set_facecolor('#eeeeee')
    ax.set_title(table.title, fontsize=FONT, loc='left', pad=2)


def figure_from_diagram(diagram: Diagram, scene: Scene) -> Any:
    """Draw the three panels and the value tables on a new matplotlib figure (Agg canvas).

    Parameters
    ----------
    diagram : Diagram
        The diagrams (:func:`diagram_from_scene`).
    scene : Scene
        The scene they were built from.

    Returns
    -------
    matplotlib.figure.Figure
        Drawn to scale at its nominal size: 1 cm of the figure is what each
        panel's scale bar says.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    scene = full_scene(scene)
    colours = colours_from_scene(scene)
    tables = _shown(tables_from_diagram(diagram))  # row counts; drawn again with scales
    space_rows = len(tables['space'].rows) + (len(tables['centres'].rows) + 2
                                              if 'centres' in tables else 0)
    rows = max([space_rows] + [len(tables[key].rows) for key in ('velocity', 'acceleration')
                               if key in tables]) + 1
    table_h = rows * ROW_H + 0.6
    width = 2 * MARGIN + 3 * PANEL_W + 2 * PANEL_GAP
    height = TITLE_H + PANEL_H + 0.5 + table_h + 0.3
    fig = Figure(figsize=(width * CM, height * CM), dpi=DPI)
    FigureCanvasAgg(fig)

    def axes(x: float, y: float, w: float, h: float) -> Any:
        return fig.add_axes((x / width, y / height, w / width, h / height))

    panel_y = height - TITLE_H - PANEL_H
    xs = [MARGIN + i * (PANEL_W + PANEL_GAP) for i in range(3)]
    scales = {'space': _space_panel(axes(xs[0], panel_y, PANEL_W, PANEL_H), scene, diagram,
                                    colours)}
    for x, key, polygon in ((xs[1], 'velocity', diagram.velocity),
                            (xs[2], 'acceleration', diagram.acceleration)):
        ax = axes(x, panel_y, PANEL_W, PANEL_H)
        if polygon is None:  # refused: say why where it would be
            ax.set_axis_off()
            ax.set_title(f'{key.capitalize()} polygon', fontsize=FONT + 2)
            ax.text(0.5, 0.5, '\n'.join(textwrap.wrap(diagram.refused, 48)),
                    transform=ax.transAxes, ha='center', va='center', fontsize=FONT + 1)
        else:
            scales[key] = _polygon_panel(ax, polygon, colours)
    tables = _shown(tables_from_diagram(diagram, scales))
    top = panel_y - 0.55
    n = len(tables['space'].rows) + 1
    _table(axes(xs[0], top - n * ROW_H, PANEL_W, n * ROW_H), tables['space'])
    if 'centres' in tables:
        m = len(tables['centres'].rows) + 1
        _table(axes(xs[0] + 1.5, top - (n + m) * ROW_H - 0.9, PANEL_W - 3.0, m * ROW_H),
               tables['centres'])
    for x, key in ((xs[1], 'velocity'), (xs[2], 'acceleration')):
        if key not in tables:
            continue
        n = len(tables[key].rows) + 1
        _table(axes(x, top - n * ROW_H, PANEL_W, n * ROW_H), tables[key], mathcols=(0, 1))
    fig.text(MARGIN / width, 1.0 - 0.5 / height, title_from_diagram(diagram),
             fontsize=FONT + 3, va='center', ha='left')
    return fig


def title_from_diagram(diagram: Diagram) -> str:
    """Return the figure's title: the scene and where its drivers stand, SI units.

    One crank: its angle (deg), speed (rad/s and rpm) and acceleration;
    several drivers (or an actuator, a motor): each one's position, speed and
    acceleration, by its name.
    """
    drivers = diagram.drivers
    if len(drivers) <= 1 and all(d.joint_type.angular and d.crank for d in drivers):
        rpm = rpm_from_rad_per_s(diagram.speed)
        return (f'{diagram.scene}: crank angle {fmt_value(math.degrees(diagram.angle))}\u00b0, '
                f'\u03c9 = {fmt_value(diagram.speed)} rad/s{fmt_sense(diagram.speed)} '
                f'({fmt_value(rpm)} rpm), \u03b1 = {fmt_value(diagram.accel)} rad/s\u00b2   '
                f'(SI units; angles CCW from +x)')
    parts = []
    for d in drivers:
        if d.joint_type.angular:
            parts.append(f'{d.name} {fmt_value(math.degrees(d.position))}\u00b0, '
                         f'{fmt_value(d.speed)} rad/s, {fmt_value(d.accel)} rad/s\u00b2')
        else:
            parts.append(f'{d.name} {fmt_value(d.position)} m, {fmt_value(d.speed)} m/s, '
                         f'{fmt_value(d.accel)} m/s\u00b2')
    return f'{diagram.scene}: {"; ".join(parts)}   (SI units; angles CCW from +x)'


def write_diagram(diagram: Diagram, scene: Scene, path: str | Path) -> Path:
    """Draw ``diagram`` and save it to ``path`` (.png, .svg or .pdf by its suffix)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in ('.png', '.svg', '.pdf'):
        msg = f'Expected an output file ending in .png, .svg or .pdf, got {str(path)!r}'
        raise ValueError(msg)
    fig = figure_from_diagram(diagram, scene)
    fig.savefig(path, dpi=DPI, format=suffix[1:])
    return path


def _cycle_angles(scene: Scene, frames: int, start: float | None = None) -> Array:
    sense = -1.0 if scene.input.speed < 0 else 1.0
    theta0 = scene.input.angle if start is None else start
    return theta0 + sense * np.linspace(0.0, 2.0 * math.pi, frames, endpoint=False)


def write_animation(scene: Scene, path: str | Path, *, frames: int = 72, fps: int = 12,
                    speed: float | None = None, accel: float | None = None,
                    instant_centres: bool = False, dpi: float = 100.0) -> int:
    """Write an animated GIF of one crank turn with velocity and acceleration arrows.

    Parameters
    ----------
    scene : Scene
        The mechanism.
    path : str or Path
        Output file, ``.gif``.
    frames : int, keyword-only
        Crank angles over the turn, from the scene's angle in its sense of
        rotation; angles at which the mechanism cannot be assembled are
        skipped.
    fps : int, keyword-only
        Frames per second.
    speed, accel : float, optional, keyword-only
        Crank angular velocity (rad/s) and acceleration (rad/s^2); default the
        scene's.
    instant_centres : bool, keyword-only
        Whether to mark the finite instant centres that fall in the view.
    dpi : float, keyword-only
        Resolution of the frame, 12 cm high and 11 cm to 18 cm wide.

    Returns
    -------
    int
        The number of frames written.

    Raises
    ------
    ValueError
        If ``path`` does not end in ``.gif``, or the mechanism assembles at
        none of the angles.
    """
    from matplotlib.animation import PillowWriter
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    path = Path(path)
    if path.suffix.lower() != '.gif':
        msg = f'Expected an animation file ending in .gif, got {str(path)!r}'
        raise ValueError(msg)
    if frames < 1:
        msg = f'Expected at least 1 frame, got {frames}'
        raise ValueError(msg)
    scene = full_scene(scene)
    states = []
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', NearSingularWarning)
        for theta in _cycle_angles(scene, frames):
            try:
                states.append(solve(scene, float(theta), speed, accel,
                                    turns=scene.input.turns))
            except AssemblyError:
                continue
    if not states:
        msg = f'Expected scene "{scene.name}" to assemble at some crank angle, got none'
        raise ValueError(msg)
    strokes = strokes_from_scene(scene)
    spaces = [space_from_state(scene, state, strokes) for state in states]
    moving = [n for n in states[0].complex_points if n not in scene.ground]
    v_max = max(abs(complex(st.complex_points[n][1])) for st in states for n in moving)
    a_max = max(abs(complex(st.complex_points[n][2])) for st in states for n in moving)
    corners = [np.array(sp.extent()) for sp in spaces]
    lo = np.min([c[0] for c in corners], axis=0)
    hi = np.max([c[1] for c in corners], axis=0)
    size = float(np.hypot(*(hi - lo))) or 1.0
    # arrow lengths: the largest velocity and acceleration of the cycle span 30 % of the size
    v_ref = nice_scale(v_max / 3.0) if v_max > 0 else 1.0
    a_ref = nice_scale(a_max / 3.0) if a_max > 0 else 1.0
    k_v = 0.3 * size / (3.0 * v_ref) if v_max > 0 else 0.0
    k_a = 0.3 * size / (3.0 * a_ref) if a_max > 0 else 0.0
    tips = [arrow.end for st in states for arrow in arrows_from_state(scene, st, k_v, k_a)]
    if tips:
        lo = np.minimum(lo, np.min(tips, axis=0))
        hi = np.maximum(hi, np.max(tips, axis=0))
    height = 12.0
    extent = np.maximum(hi - lo, 1e-9 * size)
    width = min(max(extent[0] / extent[1] * (height - 3.4) + 1.5, 11.0), 18.0)
    span = max((hi[0] - lo[0]) / (width - 1.5), (hi[1] - lo[1]) / (height - 3.4))
    unit = span if span > 0 else 1.0   # data length of 1 cm of the frame
    fig = Figure(figsize=(width * CM, height * CM), dpi=dpi)
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    colours = colours_from_scene(scene)
    centre = (lo + hi) / 2 + np.array([0.0, 0.6 * unit])
    origin = centre - np.array([width, height]) / 2 * unit
    writer = PillowWriter(fps=fps)
    with writer.saving(fig, str(path), dpi):
        for state, space in zip(states, spaces, strict=True):
            ax.clear()
            ax.set_xlim(origin[0], origin[0] + width * unit)
            ax.set_ylim(origin[1], origin[1] + height * unit)
            ax.axis('off')
            _draw_mechanism(ax, scene, space, colours, 0.8 * unit)
            for arrow in arrows_from_state(scene, state, k_v, k_a):
                colour = '#1a9641' if arrow.quantity.startswith('v') else '#d7191c'
                _arrow(ax, arrow.start, arrow.end, colour, '-', 1.4, 0.8 * unit, zorder=6)
            for name, xy in space.points.items():
                ax.text(xy[0] + 0.2 * unit, xy[1] + 0.2 * unit, name, fontsize=9,
                        fontweight='bold', zorder=7)
            if instant_centres:
                centres = instant_centres_from_state(scene, state)
                for ic in centres:
                    if ic.point is None:
                        continue
                    p = ic.point
                    if origin[0] < p[0] < origin[0] + width * unit and \
                            origin[1] < p[1] < origin[1] + height * unit:
                        ax.plot(*p, marker='o', ms=4, mfc='none', mec='#b00000', zorder=7)
                        ax.text(p[0] + 0.15 * unit, p[1] - 0.35 * unit,
                                f'$I_{{{centres.label(ic)[1:]}}}$', fontsize=7,
                                color='#b00000')
            theta = math.degrees(float(state.angle)) % 360.0
            ax.text(origin[0] + 0.4 * unit, origin[1] + (height - 0.6) * unit,
                    f'{scene.name}   crank {theta:5.1f}\u00b0', fontsize=10, va='top')
            key = origin + np.array([0.4, 0.5]) * unit
            _arrow(ax, key, key + [k_v * v_ref, 0.0], '#1a9641', '-', 1.4, 0.8 * unit)
            ax.text(key[0] + k_v * v_ref + 0.2 * unit, key[1], f'v {v_ref:g} m/s',
                    fontsize=8, va='center')
            key = key + np.array([width / 2 * unit, 0.0])
            _arrow(ax, key, key + [k_a * a_ref, 0.0], '#d7191c', '-', 1.4, 0.8 * unit)
            ax.text(key[0] + k_a * a_ref + 0.2 * unit, key[1], f'a {a_ref:g} m/s\u00b2',
                    fontsize=8, va='center')
            writer.grab_frame()
    return len(states)


# --- the force polygon of one body -----------------------------------------

#: Colours of the forces on a body, by what they are.
FORCE_COLOURS = {'joint': '#1f4e9c', 'effort': '#1f4e9c', 'weight': '#2a7a2a',
                 'inertia': '#c0392b', 'load': '#8e44ad'}
#: The longest force arrow of the free body, as a fraction of the mechanism's size.
FREE_BODY_REACH = 0.4


def _free_body_panel(ax: Any, scene: Scene, diagram: Diagram, polygon: Any,
                     colours: Mapping[str, str]) -> float:
    """Draw the mechanism with the forces on the body at their points; return the scale."""
    space = diagram.space
    lo, hi = space.extent()
    size = float(np.hypot(*(hi - lo))) or 1.0
    largest = max((f.magnitude for f in polygon.forces), default=0.0)
    k = FREE_BODY_REACH * size / largest if largest > 0.0 else 0.0     # m per N
    arrows = [(np.asarray(f.xy, dtype=np.float64),
               np.asarray(f.xy, dtype=np.float64) + k * np.asarray(f.force, dtype=np.float64), f)
              for f in polygon.forces]
    for tail, head, _ in arrows:
        lo, hi = np.minimum(lo, np.minimum(tail, head)), np.maximum(hi, np.maximum(tail, head))
    scale = _fit_scale(lo, hi)
    scale = _fit_scale(lo - [0, 0.7 * scale], hi)
    origin = _frame(ax, lo - [0, 0.7 * scale], hi, scale)
    if k > 0.0:     # a round number of N per cm, the arrows no longer than framed
        per_cm = nice_scale(scale / k)
        k = scale / per_cm
        arrows = [(tail, tail + k * np.asarray(f.force, dtype=np.float64), f)
                  for tail, _, f in arrows]
    _draw_mechanism(ax, scene, space, colours, scale)
    segments = [(tail, head) for tail, head, _ in arrows]
    segments += [(link.outline[i], link.outline[(i + 1) % len(link.outline)])
                 for link in space.links
                 for i in range(len(link.outline) - (len(link.outline) == 2))]
    placer = _Placer(ax, origin, scale, (PANEL_W, PANEL_H), segments,
                     list(space.points.values()))
    for name, xy in space.points.items():
        placer.place(name, xy, None, size=FONT, fontweight='bold')
    for tail, head, force in arrows:
        colour = FORCE_COLOURS[force.kind.value]
        _arrow(ax, tail, head, colour, '-', 1.6, scale, zorder=7)
        if force.magnitude > 0.0:
            placer.place(force.label, head, head - tail, size=FONT + 0.5, color=colour)
    _scale_bar(ax, origin, scale, 'm')
    if k > 0.0:
        ax.text(origin[0] + 0.5 * scale, origin[1] + 1.0 * scale,
                f'forces: {scale_text(per_cm, "N")}', fontsize=FONT, va='center', ha='left')
    ax.set_title(f'Free body: {polygon.body}', fontsize=FONT + 2)
    return scale


def _force_polygon_panel(ax: Any, polygon: Any) -> float:
    """Draw the forces head to tail, to scale; return the scale (N per cm)."""
    xy = polygon.vertices
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    scale = _fit_scale(lo, hi)
    origin = _frame(ax, lo, hi, scale)
    segments = list(zip(xy[:-1], xy[1:], strict=True))
    placer = _Placer(ax, origin, scale, (PANEL_W, PANEL_H), segments, [xy[0]])
    for force, start, end in zip(polygon.forces, xy[:-1], xy[1:], strict=True):
        colour = FORCE_COLOURS[force.kind.value]
        _arrow(ax, start, end, colour, '-', 1.6, scale)
    for force, start, end in zip(polygon.forces, xy[:-1], xy[1:], strict=True):
        if force.magnitude > 0.0:
            d = (end - start) / force.magnitude
            placer.place(force.label, (start + end) / 2, np.array([-d[1], d[0]]),
                         size=FONT + 1, color=FORCE_COLOURS[force.kind.value])
    ax.plot(0.0, 0.0, marker='o', ms=4.0, color='black', zorder=5)
    if polygon.closure > 1e-9 * max(f.magnitude for f in polygon.forces):
        ax.plot([xy[-1][0], 0.0], [xy[-1][1], 0.0], color='black', ls=':', lw=1.0)
    _scale_bar(ax, origin, scale, 'N')
    ax.set_title(f'Force polygon of {polygon.body}', fontsize=FONT + 2)
    return scale


def _force_tables(polygon: Any) -> tuple[Table, Table]:
    """Return the tables of the forces (N, deg CCW from +x) and couples (N m) on the body."""
    from ..units import degrees_from_radians

    forces = Table(f'Forces on {polygon.body} (SI; directions CCW from +x)',
                   ('', 'force', '|F| [N]', 'dir. [deg]', 'at', 'bound [N]'),
                   tuple((f.label, f.text, fmt_value(f.magnitude),
                          fmt_value(degrees_from_radians(f.direction)), f.at or 'G',
                          f'{f.bound:.2g}') for f in polygon.forces))
    couples = Table(f'Couples on {polygon.body} (+ CCW)', ('', 'couple', 'M [N m]', 'bound [N m]'),
                    tuple((c.label, c.text, fmt_value(c.moment), f'{c.bound:.2g}')
                          for c in polygon.couples))
    return forces, couples


def figure_from_force_polygon(polygon: Any, diagram: Diagram, scene: Scene) -> Any:
    """Draw one body's forces: on the mechanism, head to tail, and in a table (Agg figure).

    Parameters
    ----------
    polygon : ForcePolygon
        The body's forces
        (:func:`~mech_kinematics.geometry.force_polygon.force_polygon_from_state`).
    diagram : Diagram
        The mechanism at the same instant (its space diagram is drawn).
    scene : Scene
        The scene.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    scene = full_scene(scene)
    colours = colours_from_scene(scene)
    forces, couples = _force_tables(polygon)
    rows = len(forces.rows) + 1 + (len(couples.rows) + 2 if couples.rows else 0)
    width = 2 * MARGIN + 3 * PANEL_W + 2 * PANEL_GAP
    height = TITLE_H + 0.5 + max(PANEL_H, rows * ROW_H + 1.0) + 0.3
    fig = Figure(figsize=(width * CM, height * CM), dpi=DPI)
    FigureCanvasAgg(fig)

    def axes(x: float, y: float, w: float, h: float) -> Any:
        return fig.add_axes((x / width, y / height, w / width, h / height))

    panel_y = height - TITLE_H - PANEL_H
    xs = [MARGIN + i * (PANEL_W + PANEL_GAP) for i in range(3)]
    _free_body_panel(axes(xs[0], panel_y, PANEL_W, PANEL_H), scene, diagram, polygon, colours)
    _force_polygon_panel(axes(xs[1], panel_y, PANEL_W, PANEL_H), polygon)
    top = height - TITLE_H
    n = len(forces.rows) + 1
    _table(axes(xs[2], top - n * ROW_H, PANEL_W, n * ROW_H), forces)
    if couples.rows:
        m = len(couples.rows) + 1
        _table(axes(xs[2], top - (n + m) * ROW_H - 0.9, PANEL_W, m * ROW_H), couples)
    closes = (f'forces on {polygon.body}: they close within {polygon.closure:.2g} N (bound '
              f'{polygon.closure_bound:.2g} N); moments about {polygon.origin} sum to '
              f'{polygon.moment:.2g} N m (bound {polygon.moment_bound:.2g} N m); W weight, '
              f'-ma inertia force at the centre of mass G')
    fig.text(MARGIN / width, 1.0 - 0.5 / height, title_from_diagram(diagram),
             fontsize=FONT + 3, va='center', ha='left')
    fig.text(MARGIN / width, 1.0 - 1.1 / height, closes, fontsize=FONT, va='center', ha='left')
    return fig


# --- command line ---------------------------------------------------------

DIAGRAM_HELP = """\
Draw the space, velocity and acceleration diagrams of a scene at one crank
angle, to scale and side by side, with a table of every value drawn (SI
units; directions in degrees CCW from +x). The output format follows the
file name: .png, .svg or .pdf. With --animate, write an animated GIF of one
crank turn with the velocity and acceleration of every point drawn on the
mechanism instead. With --force-polygon BODY (a scene with masses, gravity or
loads), draw that body's forces at the instant instead: on the mechanism (a
free body), head to tail (the force polygon, to scale: it closes, the body
being in dynamic equilibrium) and in a table, with its couples. Exits with
status 2 on a scene or position that cannot be solved.
"""


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    add_scene_argument(parser)
    parser.add_argument('-o', '--output', required=True, metavar='FILE',
                        help='output file: .png, .svg or .pdf (.gif with --animate)')
    parser.add_argument('--angle-deg', type=finite_float, metavar='X',
                        help="crank angle in degrees CCW from +x (default: the scene's); "
                             'with --animate, the first frame')
    parser.add_argument('--speed-rpm', type=finite_float, metavar='N',
                        help="signed crank speed in rpm, + CCW (default: the scene's)")
    add_driver_arguments(parser)
    add_robot_arguments(parser)
    add_units_argument(parser)
    parser.add_argument('--instant-centres', action='store_true',
                        help='also compute the instant centres, mark them on the space '
                             'diagram and list them')
    parser.add_argument('--animate', action='store_true',
                        help='write an animated GIF of one crank turn instead')
    parser.add_argument('--frames', type=positive_int, default=72, metavar='N',
                        help='frames of the animation (default 72, every 5 degrees)')
    parser.add_argument('--force-polygon', metavar='BODY',
                        help='a scene with forces: draw the force polygon of the moving body '
                             'BODY (a link or slider) at the instant instead')


def add_parser(commands: Any) -> argparse.ArgumentParser:
    """Register the ``diagram`` command on ``commands`` (an argparse subparsers object).

    Parameters
    ----------
    commands : argparse._SubParsersAction
        What ``ArgumentParser.add_subparsers()`` returned.

    Returns
    -------
    argparse.ArgumentParser
        The command's parser; its ``handler`` default is :func:`_handle`.
    """
    parser: argparse.ArgumentParser = commands.add_parser(
        'diagram', help='draw velocity and acceleration diagrams',
        description=DIAGRAM_HELP, formatter_class=argparse.RawDescriptionHelpFormatter)
    _add_arguments(parser)
    parser.set_defaults(handler=_handle)
    return parser


def _handle(args: argparse.Namespace) -> int:
    """Run the ``diagram`` command on parsed arguments; return the exit status."""
    output = Path(args.output)
    suffixes = ('.gif',) if args.animate else ('.png', '.svg', '.pdf')
    if output.suffix.lower() not in suffixes:
        expected = suffixes[0] if len(suffixes) == 1 else \
            f'{", ".join(suffixes[:-1])} or {suffixes[-1]}'
        print(f'error: expected -o FILE ending in {expected}, got {str(output)!r}',
              file=sys.stderr)
        return 2
    speed = None if args.speed_rpm is None else rad_per_s_from_rpm(args.speed_rpm)
    try:
        scene = load_scene_argument(args)   # a scene, or a URDF's loops as a scene
        drivers = scene.drivers
        if args.force_polygon is not None:
            return _handle_force_polygon(args, scene, output)
        if not scene.single_crank or args.input or args.speed:
            return _handle_drivers(args, scene, output)
        accel = values_by_driver(scene, '--accel', args.accel).get(drivers[0].name)
        if args.animate:
            if args.angle_deg is not None:
                scene = _with_angle(scene, args.angle_deg)
            count = write_animation(scene, output, frames=args.frames, speed=speed,
                                    accel=accel, instant_centres=args.instant_centres)
            print(f'wrote {output} ({count} frames)')
        else:
            diagram = diagram_from_scene(scene, args.angle_deg, speed, accel,
                                         degrees=True, instant_centres=args.instant_centres)
            write_diagram(diagram, scene, output)
            print(f'wrote {output}')
    except (SceneError, AssemblyError, ValueError, OSError) as error:
        print(f'error: {error}', file=sys.stderr)
        return 2
    return 0


def _handle_drivers(args: argparse.Namespace, scene: Scene, output: Path) -> int:
    """Draw a scene at ``--input``, ``--speed`` and ``--accel NAME=VALUE`` (as ``solve``)."""
    if args.animate:
        names = ', '.join(d.name for d in scene.drivers)
        msg = (f'Expected no --animate for {scene.name} with --input or --speed, or with '
               f'several drivers or an actuator ({names}): --animate turns one crank')
        raise ValueError(msg)
    positions, rates, accels, turns, _ = drive_from_args(scene, args)
    drivers = scene.drivers
    if len(drivers) == 1:  # one driver: drive_from_args's scalars
        positions, rates, accels, turns = [positions], [rates], [accels], [turns]
    inputs = {d.name: float(x) + (2.0 * math.pi * int(t) if t else 0.0)
              for d, x, t in zip(drivers, positions, turns, strict=True)}
    speeds = {d.name: float(v) for d, v in zip(drivers, rates, strict=True) if v is not None}
    accel = {d.name: float(a) for d, a in zip(drivers, accels, strict=True) if a is not None}
    diagram = diagram_from_scene(scene, inputs=inputs, speeds=speeds, accels=accel,
                                 instant_centres=args.instant_centres)
    write_diagram(diagram, scene, output)
    if diagram.refused:
        print(f'{scene.name}: {diagram.refused}')
    print(f'wrote {output}')
    return 0


def _handle_force_polygon(args: argparse.Namespace, scene: Scene, output: Path) -> int:
    """Draw the force polygon of ``--force-polygon BODY`` at the instant the options give."""
    from ..geometry.force_polygon import force_polygon_from_state, moving_bodies

    if args.animate:
        msg = 'Expected --force-polygon or --animate, got both: the polygon is of one instant'
        raise ValueError(msg)
    if scene.dynamics is None:
        msg = (f'Expected a scene with masses, gravity or loads for --force-polygon, got '
               f'{scene.name} without')
        raise ValueError(msg)
    if args.force_polygon not in moving_bodies(scene):
        got = ('the ground' if args.force_polygon == scene.graph.ground
               else repr(args.force_polygon))
        msg = (f'Expected --force-polygon BODY, a moving body of {scene.name} '
               f'({", ".join(moving_bodies(scene))}), got {got}')
        raise ValueError(msg)
    scene = full_scene(scene)
    drivers = scene.drivers
    if not scene.single_crank or args.input or args.speed:
        positions, rates, accels, turns, _ = drive_from_args(scene, args)
        if len(drivers) == 1:
            positions, rates, accels, turns = [positions], [rates], [accels], [turns]
        inputs = {d.name: float(x) + (2.0 * math.pi * int(t) if t else 0.0)
                  for d, x, t in zip(drivers, positions, turns, strict=True)}
        speeds = {d.name: float(v) for d, v in zip(drivers, rates, strict=True) if v is not None}
        accel = {d.name: float(a) for d, a in zip(drivers, accels, strict=True) if a is not None}
        diagram = diagram_from_scene(scene, inputs=inputs, speeds=speeds, accels=accel)
        xs = [inputs.get(d.name, d.start) for d in drivers]
        vs = [speeds.get(d.name, d.speed) for d in drivers]
        acs = [accel.get(d.name, d.accel) for d in drivers]
        state = (solve(scene, xs[0], vs[0], acs[0]) if len(drivers) == 1
                 else solve(scene, xs, vs, acs))
    else:
        speed = None if args.speed_rpm is None else rad_per_s_from_rpm(args.speed_rpm)
        alpha = values_by_driver(scene, '--accel', args.accel).get(drivers[0].name)
        if args.angle_deg is None:
            theta, turns = scene.input.angle, scene.input.turns
        elif abs(args.angle_deg) > 360.0:
            theta, turns = turns_from_degrees(args.angle_deg)
        else:
            theta, turns = radians_from_degrees(args.angle_deg), 0
        diagram = diagram_from_scene(scene, args.angle_deg, speed, alpha, degrees=True)
        state = solve(scene, theta, speed, alpha, turns=turns)
    polygon = force_polygon_from_state(scene, state, args.force_polygon)
    fig = figure_from_force_polygon(polygon, diagram, scene)
    fig.savefig(output, dpi=DPI, format=output.suffix.lower()[1:])
    print(f'{scene.name}: forces on {polygon.body} close within {polygon.closure:.2g} N '
          f'(bound {polygon.closure_bound:.2g} N)')
    print(f'wrote {output}')
    return 0


def _with_angle(scene: Scene, degrees: float) -> Scene:
    """Return ``scene`` started at ``degrees``, whole turns beyond one read exactly."""
    from dataclasses import replace

    angle, turns = (turns_from_degrees(degrees) if abs(degrees) > 360.0
                    else (math.radians(degrees), 0))
    return replace(scene, input=replace(scene.input, angle=angle, turns=turns))


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``diagram``; return the exit status."""
    return run_tool(add_parser, argv)


if __name__ == '__main__':
    sys.exit(main())
