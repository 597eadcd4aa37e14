# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The report's figures: work precision per mechanism, the clock, extreme cases, cost, bounds.

Every function draws one section's computed results; matplotlib (Agg) is
imported inside :func:`_figure`, so importing this module does not load it.
"""

from __future__ import annotations

from collections.abc import Callable
import math
from pathlib import Path
from typing import Any

import numpy as np

from .baselines import WorkPrecision
from .bounds import CaseBounds, RefusedFractions
from .clock import ClockRow, TICK_HZ
from .common import DURATIONS, EPS, ERROR_FLOOR
from .cost import CHUNK, CostGrowth
from ...verify.extreme import BOUND_FACTOR, CaseResult

__all__ = ['plot_bounds', 'plot_clock', 'plot_cost', 'plot_extreme', 'plot_refused',
           'plot_work_precision']


def _figure(path: Path, draw: Callable[[Any], None], size: tuple[float, float]) -> None:
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig = plt.figure(figsize=size, dpi=110)
    try:
        draw(fig)
        fig.savefig(path)
    finally:
        plt.close(fig)


_STYLE = {'ours': ('C0', 'o'), 'newton': ('C1', 's'), 'differences': ('C2', '^'),
          'solve_ivp': ('C3', 'D'), 'printed': ('k', '*')}
_FAMILY = {'ours': 'our solver (closed form)', 'newton': 'Newton-Raphson, tol on step',
           'differences': 'central differences of positions, step in crank angle',
           'solve_ivp': 'solve_ivp DOP853 on the velocity equations, rtol',
           'printed': "the seed's printed answer (own angle only)"}


def plot_work_precision(result: WorkPrecision, path: Path) -> None:
    """Draw the log-log error against time per configuration, two panels."""
    def draw(fig: Any) -> None:
        axes = fig.subplots(1, 2, sharex=True, sharey=True)
        for ax, attr, title in zip(axes, ('point_acc', 'angular_acc'),
                                   ('point accelerations', 'link angular accelerations'),
                                   strict=True):
            for family, (color, marker) in _STYLE.items():
                pts = [p for p in result.points if p.family == family
                       and math.isfinite(getattr(p, attr))]
                if not pts:
                    continue
                xs = [p.seconds for p in pts]
                ys = [max(getattr(p, attr), ERROR_FLOOR) for p in pts]
                if family == 'ours':
                    for p, x, y in zip(pts, xs, ys, strict=True):
                        ax.plot(x, y, marker=marker, color=color, ms=9, ls='none',
                                mfc='none' if 'one angle' in p.label else color,
                                label=p.label)
                    continue
                if family == 'printed':
                    stated = result.printed['stated']
                    ax.plot(xs, ys, marker=marker, color=color, ms=10, ls='none',
                            label="seed's printed answer: its miss (own angle only)")
                    ax.plot(xs, [stated], marker='_', color=color, ms=16, mew=2, ls='none',
                            label=f'  its stated accuracy ({pts[0].note.split()[-1]})')
                    ax.vlines(xs, ys, [stated], color=color, lw=0.8)
                    ax.annotate('drawing time\nassumed 10 min', (xs[0], ys[0]),
                                textcoords='offset points', xytext=(-62, -14), fontsize=6.5)
                    continue
                ax.plot(xs, ys, marker=marker, color=color, ms=6, ls='-', label=_FAMILY[family])
                placed: list[tuple[float, float]] = []
                for p, x, y in zip(pts, xs, ys, strict=True):
                    if any(abs(math.log10(x / u)) < 0.3 and abs(math.log10(y / v)) < 0.6
                           for u, v in placed):
                        continue  # a label is there already
                    placed.append((x, y))
                    ax.annotate(p.label.split(' ')[1], (x, y), textcoords='offset points',
                                xytext=(4, 3), fontsize=6.5, color=color)
            ax.axhline(EPS, color='0.6', lw=0.8, ls=':')
            ax.set_xscale('log')
            ax.set_yscale('log')
            ax.set_title(f'{result.mechanism}: {title}', fontsize=10)
            ax.set_xlabel('time per configuration [s]')
            ax.grid(True, which='major', alpha=0.3)
        axes[0].set_ylabel('worst relative error over the configurations [-]')
        axes[0].text(0.02, 0.02, f'dotted: machine epsilon {EPS:.1e}; errors below '
                     f'{ERROR_FLOOR:.0e} drawn at it', transform=axes[0].transAxes, fontsize=7)
        handles, labels = axes[1].get_legend_handles_labels()
        h0, l0 = axes[0].get_legend_handles_labels()
        merged = dict(zip(l0 + labels, h0 + handles, strict=True))
        fig.legend(merged.values(), merged.keys(), loc='lower center', ncol=2, fontsize=7.5,
                   frameon=False)
        fig.suptitle(f'Work-precision, {result.mechanism} ({result.scene}, '
                     f'{result.configs} configurations)', fontsize=11)
        fig.subplots_adjust(bottom=0.25, top=0.89, wspace=0.08, left=0.08, right=0.98)

    _figure(path, draw, (11.0, 5.4))


def plot_clock(rows: list[ClockRow], path: Path) -> None:
    """Draw angle error against run time per speed and method."""
    def draw(fig: Any) -> None:
        axes = fig.subplots(1, 2)
        rpms = sorted({r.rpm for r in rows})
        styles = {'timebase': '-', 'naive': '--', 'naive, wrapped': ':'}
        markers = {'timebase': 'o', 'naive': 's', 'naive, wrapped': '^'}
        for ax, attr, ylabel in zip(axes, ('angle_error', 'state_error'),
                                    ('crank angle error [rad]',
                                     'worst relative error of the published state [-]'),
                                    strict=True):
            for i, rpm in enumerate(rpms):
                sub = [r for r in rows if r.rpm == rpm]
                for method, ls in styles.items():
                    xs = [r.seconds for r in sub]
                    ys = [max(getattr(r, attr)[method], ERROR_FLOOR) for r in sub]
                    ax.plot(xs, ys, ls=ls, marker=markers[method], color=f'C{i}', ms=5,
                            label=f'{method}, {rpm:g} rpm')
            ax.set_xscale('log')
            ax.set_yscale('log')
            ax.set_xlabel('simulated run time [s]')
            ax.set_ylabel(ylabel)
            ax.grid(True, alpha=0.3)
            for label, seconds in DURATIONS:
                ax.axvline(seconds, color='0.85', lw=0.6, zorder=0)
                ax.text(seconds, 1.02, label, transform=ax.get_xaxis_transform(),
                        fontsize=7, ha='center')
        handles, labels = axes[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc='lower center', ncol=3, fontsize=7.5, frameon=False)
        fig.suptitle(f'Crank angle from the clock, {TICK_HZ} Hz ticks: exact time base '
                     'against accumulation', fontsize=11, y=0.99)
        fig.subplots_adjust(wspace=0.3, left=0.08, right=0.98, top=0.86, bottom=0.25)

    _figure(path, draw, (11.0, 6.0))


def plot_extreme(results: list[CaseResult], path: Path) -> None:
    """Draw each case's error against eps * kappa, with the bound."""
    def draw(fig: Any) -> None:
        ax = fig.subplots()
        colors = {'none': 'C0', 'warned': 'C1', 'untrusted': 'C2', 'refused': 'C3'}
        seen = set()
        for i, r in enumerate(results):
            if not r.errors:
                continue
            kind = max(r.errors, key=lambda k: r.errors[k] / (EPS * max(1.0, r.kappa[k])))
            x = EPS * max(1.0, r.kappa[kind])
            y = max(r.errors[kind], ERROR_FLOOR)
            label = f'solver flag: {r.flag}' if r.flag not in seen else None
            seen.add(r.flag)
            ax.plot(x, y, 'o', color=colors[r.flag], ms=6, label=label)
            ax.annotate(str(i + 1), (x, y), textcoords='offset points', xytext=(4, 2),
                        fontsize=7)
        lo, hi = 1e-17, 1.0
        xs = np.array([lo, hi])
        ax.plot(xs, xs, color='0.5', lw=0.8, label='error = eps * kappa')
        ax.plot(xs, BOUND_FACTOR * xs, color='k', lw=1.0, ls='--',
                label=f'bound {BOUND_FACTOR:g} eps * kappa')
        ax.set_xscale('log')
        ax.set_yscale('log')
        ax.set_xlim(lo, hi)
        ax.set_ylim(lo, hi)
        ax.set_xlabel('machine epsilon x condition number, eps * kappa [-]')
        ax.set_ylabel('worst relative error against the 50-digit reference [-]')
        ax.set_title('Stiff and extreme cases (numbers: rows of the table; worst kind)',
                     fontsize=10)
        refused = [str(i + 1) for i, r in enumerate(results) if not r.errors]
        if refused:
            ax.text(0.98, 0.02, f'refused by the solver, not drawn: {", ".join(refused)}',
                    transform=ax.transAxes, ha='right', fontsize=8)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc='upper left')
        fig.subplots_adjust(left=0.13, right=0.97, bottom=0.11, top=0.93)

    _figure(path, draw, (6.4, 5.6))


def plot_cost(cost: CostGrowth, path: Path) -> None:
    """Draw time per configuration against batch size and against chain length."""
    def draw(fig: Any) -> None:
        left, right = fig.subplots(1, 2)
        ns = [n for n, _ in cost.batch]
        left.plot(ns, [s for _, s in cost.batch], 'o-', color='C0',
                  label='array path, one call')
        if cost.chunked:
            left.plot([n for n, _ in cost.chunked], [s for _, s in cost.chunked], 's--',
                      color='C2', label=f'array path, in calls of {CHUNK} angles')
        left.axhline(cost.single, color='C1', ls='--',
                     label=f'scalar path, one angle ({cost.single * 1e6:.1f} us)')
        left.set_xscale('log')
        left.set_yscale('log')
        left.set_xlabel('angles per call (batch size) [-]')
        left.set_ylabel('time per configuration [s]')
        left.set_title(f'khurmi four-bar; total time ~ N^{cost.batch_slope:.2f} '
                       '(N >= 1e3)', fontsize=10)
        left.grid(True, which='both', alpha=0.3)
        left.legend(fontsize=8)
        ds = [n for n, _ in cost.chain_array]
        right.plot(ds, [s for _, s in cost.chain_array], 'o-', color='C0',
                   label=f'array path (slope {cost.chain_slope_array:.2f})')
        right.plot(ds, [s for _, s in cost.chain_single], 's-', color='C1',
                   label=f'scalar path, one angle (slope {cost.chain_slope_single:.2f})')
        right.set_xscale('log')
        right.set_yscale('log')
        right.set_xticks(ds, [str(n) for n in ds])
        right.minorticks_off()
        right.set_xlabel('RRR dyads in the chain (four-bar stages) [-]')
        right.set_ylabel('time per configuration [s]')
        right.set_title('chained four-bars; slopes fitted from 4 dyads on', fontsize=10)
        right.grid(True, which='both', alpha=0.3)
        right.legend(fontsize=8)
        fig.subplots_adjust(wspace=0.3, left=0.08, right=0.98, top=0.9, bottom=0.12)

    _figure(path, draw, (11.0, 4.8))


_MARKERS = ('o', 's', '^', 'D', 'v', 'P', 'X')


def plot_bounds(results: list[CaseBounds], path: Path) -> None:
    """Draw every value's error bound against its actual error, both over its kind's scale.

    Log-log, one colour and marker per case, the line y = x (every point must
    lie above it) and the default tolerance; values with no error at all (or
    one below the range of doubles relative to the scale) are drawn at the
    left edge, values whose bound is 0 (ground points, exact) are left out.
    """
    from ...bounds import MAX_ERROR

    def draw(fig: Any) -> None:
        import matplotlib
        ax = fig.subplots()
        values = [v for r in results for v in r.values if v.bound > 0 and v.scale > 0]
        ratios = [v.actual / v.scale for v in values] + [v.bound / v.scale for v in values]
        positive = [x for x in ratios if x > 0]
        lo = 10.0 ** (math.floor(math.log10(min(positive, default=1e-17))) - 1)
        hi = 10.0 ** (math.ceil(math.log10(max(positive, default=1.0))) + 1)
        zero = lo * 3
        colours = matplotlib.colormaps['tab20'].colors
        for i, r in enumerate(results):
            drawn = [v for v in r.values if v.bound > 0 and v.scale > 0]
            if not drawn:
                continue
            colour, marker = colours[i % len(colours)], _MARKERS[i % len(_MARKERS)]
            for accepted in (True, False):
                sub = [v for v in drawn if v.accepted is accepted]
                if not sub:
                    continue
                ax.scatter([max(v.actual / v.scale, zero) for v in sub],
                           [v.bound / v.scale for v in sub], s=14, marker=marker,
                           color=colour if accepted else 'none', edgecolors=colour,
                           linewidths=0.8, label=r.case.name if accepted or all(
                               not v.accepted for v in drawn) else None, zorder=3)
        line = np.array([lo, hi])
        ax.plot(line, line, color='k', lw=1.0, label='bound = actual error')
        ax.axhline(MAX_ERROR, color='C3', lw=0.8, ls=':',
                   label=f'default tolerance {MAX_ERROR:g} (states above it are refused)')
        ax.axvspan(lo, lo * 10, color='0.92', zorder=0)
        ax.text(lo * 1.3, hi / 3, 'actual\nerror 0', fontsize=6.5, va='top')
        ax.set_xscale('log')
        ax.set_yscale('log')
        ax.set_xlim(lo, hi)
        ax.set_ylim(lo, hi)
        ax.set_xlabel("actual error against the 50-digit reference / the kind's scale [-]")
        ax.set_ylabel("error bound / the kind's scale [-]")
        ax.set_title('Error bound against actual error, every value of every extreme case\n'
                     '(filled: the instant is answered at the default tolerance; hollow: '
                     'refused by it)', fontsize=9)
        ax.grid(True, which='major', alpha=0.3)
        ax.legend(fontsize=6.5, loc='upper center', bbox_to_anchor=(0.5, -0.09), ncol=3,
                  frameon=False)
        fig.subplots_adjust(left=0.1, right=0.97, top=0.93, bottom=0.25)

    _figure(path, draw, (8.0, 8.2))


def plot_refused(fractions: list[RefusedFractions], path: Path) -> None:
    """Draw the fraction of a crank turn refused per tolerance and case (log axis).

    Cases never refused anywhere are left out (the caller names them); a zero
    fraction is marked 0 at the left edge.
    """
    shown = [f for f in fractions if f.no_assembly > 0 or any(v > 0 for v in f.refused.values())]

    def draw(fig: Any) -> None:
        ax = fig.subplots()
        tolerances = sorted(next(iter(shown)).refused) if shown else []
        bars = [(f'refused at max_error = {t:g}' if math.isfinite(t) else
                 'refused at any tolerance (within rounding of a limit)', t)
                for t in tolerances] + [('cannot assemble', None)]
        height = 0.8 / len(bars)
        lo = 1e-16
        for j, (label, tol) in enumerate(bars):
            ys = [i - 0.4 + (j + 0.5) * height for i in range(len(shown))]
            ws = [f.no_assembly if tol is None else f.refused[tol] for f in shown]
            colour = '0.55' if tol is None else f'C{j}'
            ax.barh(ys, [max(w, lo) if w > 0 else 0 for w in ws], height=height, left=lo,
                    color=colour, label=label)
            for y, w in zip(ys, ws, strict=True):
                if w == 0:
                    ax.text(lo * 1.5, y, '0', va='center', fontsize=6.5, color=colour)
        ax.set_xscale('log')
        ax.set_xlim(lo, 1.0)
        ax.set_yticks(range(len(shown)), [f.case.name for f in shown], fontsize=7.5)
        ax.invert_yaxis()
        ax.set_xlabel('fraction of a full crank turn [-]')
        ax.set_title('Where the solver refuses, per tolerance (single-angle path)', fontsize=10)
        ax.grid(True, axis='x', which='major', alpha=0.3)
        ax.legend(fontsize=7, loc='upper center', bbox_to_anchor=(0.4, -0.07), ncol=2,
                  frameon=False)
        fig.subplots_adjust(left=0.3, right=0.97, top=1 - 0.5 / height_in,
                            bottom=1.3 / height_in)

    height_in = 2.0 + 0.6 * max(len(shown), 1)
    _figure(path, draw, (9.0, height_in))
