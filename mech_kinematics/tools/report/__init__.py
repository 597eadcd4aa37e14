# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""Error against cost, and stability on stiff and extreme cases (issue 5).

``python -m mech_kinematics report -o DIR [--quick | --smoke]`` writes
``DIR/REPORT.md`` and its PNG figures:

1. the 50-digit reference (:mod:`mech_kinematics.verify.reference`, the
   verification room's) and its checks (:mod:`.checks`);
2. work-precision diagrams: our solver against Newton-Raphson, finite
   differences, ``solve_ivp`` and the textbooks' printed answers
   (:mod:`.baselines`);
3. the error of the node's crank angle against run time, for the exact time
   base and for naive ``angle += omega * dt`` accumulation (:mod:`.clock`);
4. stiff and extreme cases against the reference, with the solver's flags,
   digits lost and the formula audit (the verification room's extreme suite,
   :mod:`mech_kinematics.verify.extreme`);
5. cost growth with the batch size and the number of dyads (:mod:`.cost`);
6. the solver's error bounds against the actual errors over an extreme suite,
   and the fraction of a turn refused at each tolerance (:mod:`.bounds`).

Beside it, ``DIR/data.json`` holds every figure the documentation quotes
(:mod:`.data`), with ``bench``'s table (:mod:`mech_kinematics.tools.bench`)
and the figures of one real run of the node (``--long-run FILE``, from
``bench/long_run.py``) and of the node driven from a topic (``--topic-drive
FILE``, from ``bench/topic_bench.py``), each kept from the folder's previous
data file otherwise.

:mod:`.common` holds the run sizes (:data:`MODES`) and the shared timer,
:mod:`.figures` draws, :mod:`.markdown` writes ``REPORT.md``; this module
runs them in order (:func:`run`) and is the command line (:func:`add_parser`,
:func:`main`).

Every number in the report comes from the functions of these modules, which
the tests call too. Times are min / median / max of repeated runs on a shared
machine (the tables give medians): compare ratios, not absolute times.
matplotlib, SciPy, mpmath and tqdm are imported inside the functions that need
them, so the solver and the command line stay importable without them.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
import os
from pathlib import Path
import sys
import time
from typing import Any

from .baselines import (by_order, Configurations, configurations, HAND_TIME, headline,
                        newton_positions, NEWTON_TRACKING_STEP, ORDERS, work_precision,
                        WorkPoint, WorkPrecision, WP_PRINTED, WP_RANGES)
from .bounds import (bound_cases, bound_statistics, bound_values, BoundCase, BoundStats,
                     BoundValue, CaseBounds, KAPPA_WELL, OFFSETS, refused_fractions,
                     RefusedFractions, TOLERANCES)
from .checks import golden_checks, golden_folder, GoldenCheck, reference_checks, ReferenceCheck
from .clock import (clock_errors, CLOCK_TICKS, ClockRow, EPOCH_NS, naive_accumulate,
                    naive_cumsum, naive_wrapped, naive_wrapped_trace, node_clock, TICK_HZ)
from .common import DURATIONS, EPS, ERROR_FLOOR, Mode, MODES, slug, spread_time, WP_SCENES
from .cost import CHUNK, cost_growth, CostGrowth
from .data import (BLOCKS, check_text, collect, DATA_FILE, KEPT, lookup, read_data,
                   render_block, SPREAD_RULE, store_section, STORED, update_text, write_data)
from .figures import (plot_bounds, plot_clock, plot_cost, plot_extreme, plot_refused,
                      plot_work_precision)
from .markdown import bench_text, write_report
from ..cli import run_tool
from ...verify.extreme import evaluate_case, extreme_cases, formula_audit

__all__ = [
    'BLOCKS', 'DATA_FILE', 'EPOCH_NS', 'KEPT', 'ORDERS', 'SPREAD_RULE', 'STORED', 'by_order',
    'check_text', 'collect', 'lookup', 'node_clock', 'read_data', 'render_block', 'spread_time',
    'store_section', 'update_text', 'write_data',
    'BoundCase', 'BoundStats', 'BoundValue', 'CHUNK', 'CLOCK_TICKS',
    'CaseBounds', 'ClockRow', 'Configurations', 'CostGrowth', 'DURATIONS',
    'EPS', 'ERROR_FLOOR', 'GoldenCheck', 'HAND_TIME', 'KAPPA_WELL', 'MODES',
    'Mode', 'NEWTON_TRACKING_STEP', 'OFFSETS', 'ReferenceCheck', 'RefusedFractions', 'TICK_HZ',
    'TOLERANCES', 'WP_PRINTED', 'WP_RANGES', 'WP_SCENES', 'WorkPoint', 'WorkPrecision',
    'add_parser', 'bench_section', 'bound_cases', 'bound_statistics', 'bound_values',
    'clock_errors', 'refresh_bench',
    'configurations', 'cost_growth',
    'golden_checks', 'golden_folder', 'headline', 'main',
    'naive_accumulate', 'naive_cumsum', 'naive_wrapped', 'naive_wrapped_trace', 'newton_positions',
    'plot_bounds', 'plot_clock', 'plot_cost', 'plot_extreme', 'plot_refused',
    'plot_work_precision', 'reference_checks', 'refused_fractions', 'run', 'work_precision',
    'write_report',
]


def _progress(total: int, enabled: bool) -> Any:
    from tqdm import tqdm
    return tqdm(total=total, disable=not enabled, unit='task', file=sys.stderr,
                dynamic_ncols=True)


def run(outdir: str | os.PathLike[str], mode: str | Mode = 'full',
        progress: bool = True,
        long_run: str | os.PathLike[str] | None = None,
        topic_drive: str | os.PathLike[str] | None = None) -> dict[str, Any]:
    """Compute every section, draw the figures, write ``outdir/REPORT.md`` and its data file.

    ``long_run``, ``topic_drive``: JSON files of ``bench/long_run.py`` and
    ``bench/topic_bench.py`` to store in the data file. Returns the computed
    sections and the data (the tests read them).
    """
    mode = MODES[mode] if isinstance(mode, str) else mode
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    load = [os.getloadavg()[0]]
    from ...scene import scene_names
    n_checks = len(mode.check_scenes or scene_names())  # at most: the crank scenes
    cases = bound_cases(mode)
    total = (n_checks + 1 + 5 * len(mode.wp_mechanisms) + len(mode.clock_rpms) + 1
             + len(mode.batch_sizes) + len(mode.chain_lengths) + len(cases) + 2)
    with _progress(total, progress) as bar:
        def tick() -> None:
            bar.update(1)

        bar.set_description('reference')
        checks = reference_checks(mode, tick)
        golden = golden_checks()
        tick()
        wp = []
        for mechanism in mode.wp_mechanisms:
            bar.set_description(f'work-precision {mechanism}')
            wp.append(work_precision(mechanism, mode, tick))
        bar.set_description('clock')
        clock, clock_check = clock_errors(mode, tick=tick)
        bar.set_description('extreme cases')
        extreme = [evaluate_case(case) for case in extreme_cases(mode.extreme_angles)]
        audit = formula_audit()
        tick()
        bar.set_description('cost growth')
        cost = cost_growth(mode, tick)
        bar.set_description('error bounds')
        bounds, refused = [], []
        for case in cases:
            bounds.append(bound_values(case))
            refused.append(refused_fractions(case, mode))
            tick()
        bar.set_description('bench')
        bench, peer = bench_section(mode)
        tick()
        bar.set_description('figures')
        for result in wp:
            plot_work_precision(result, out / f'wp_{slug(result.mechanism)}.png')
        plot_clock(clock, out / 'clock.png')
        plot_extreme(extreme, out / 'extreme.png')
        plot_cost(cost, out / 'cost.png')
        plot_bounds(bounds, out / 'bounds.png')
        plot_refused(refused, out / 'refused.png')
        tick()
    elapsed = time.perf_counter() - start
    load.append(os.getloadavg()[0])
    data = collect(mode, elapsed, load, checks, golden, wp, clock, clock_check, extreme, cost,
                   bounds, refused, bench, peer)
    write_data(out, data, long_run, topic_drive)
    write_report(out, mode, checks, golden, wp, clock, clock_check, extreme, audit, cost,
                 bounds, refused, elapsed, data)
    return {'checks': checks, 'golden': golden, 'work_precision': wp, 'clock': clock,
            'clock_check': clock_check, 'extreme': extreme, 'audit': audit, 'cost': cost,
            'bounds': bounds, 'refused': refused, 'elapsed': elapsed, 'data': data}


def bench_section(mode: Mode) -> tuple[dict[str, Any], dict[str, Any] | None]:
    """Return section 7's measurements: ``bench``'s table, and the peer's where installed.

    The peer (pylinkage, ``bench --peer``) is a development dependency: without
    it the second is None (and the data file keeps its previous table).
    """
    from ..bench import ARRAY_TARGET, measure, measure_peers, SINGLE_TARGET
    from ..peer import available, work_items
    from ...scene import scene_names
    rows = measure(scene_names(), mode.bench_angles, mode.bench_repeat)
    # Per scene with a hand-written form, and over them, the median ratios (for the docs).
    ratios = {row['scene']: {'single': row['single_ratio'], 'array': row['array_ratio']}
              for row in rows if 'single_ratio' in row}
    # and how many scenes are within each target.
    targets = {'single': SINGLE_TARGET, 'array': ARRAY_TARGET}
    bench = {'angles': mode.bench_angles, 'repeat': mode.bench_repeat, 'rows': rows,
             'ratios': ratios, 'ratio_range': {
                 kind: {'min': min(r[kind] for r in ratios.values()),
                        'max': max(r[kind] for r in ratios.values())}
                 for kind in targets},
             'scenes': len(ratios),
             'within': {kind: sum(r[kind] <= target for r in ratios.values())
                        for kind, target in targets.items()}}
    if not available():
        return bench, None
    batches = (360, mode.bench_angles)
    work = work_items(batches)
    rows = measure_peers(mode.bench_repeat, batches=batches)
    # Their median over ours per scene and work item (> 1: ours faster), for the docs to quote.
    ratios = {row['scene']: {key: row[key]['theirs_us'][1] / row[key]['ours_us'][1]
                             for key, _ in work} for row in rows}
    return bench, {'peer': 'pylinkage 1.3.0 (numba)', 'repeat': mode.bench_repeat,
                   'work': work, 'rows': rows, 'ratios': ratios}


def refresh_bench(outdir: str | os.PathLike[str], mode: str | Mode = 'full') -> Path:
    """Measure section 7 again into ``outdir``'s data file and REPORT.md; keep the rest.

    ``bench``'s timings change with the solver's code and nothing else of the
    report does: this reruns :func:`bench_section` alone, stores it in
    ``outdir/data.json`` and rewrites section 7 of ``outdir/REPORT.md`` from it.
    Returns the data file's path.
    """
    mode = MODES[mode] if isinstance(mode, str) else mode
    out = Path(outdir)
    data = read_data(out / DATA_FILE)
    data['bench'], data['peer'] = bench_section(mode)
    path = write_data(out, data)
    report = out / 'REPORT.md'
    text = report.read_text(encoding='utf-8')
    start = text.index('## 7. ')    # the last section (markdown.write_report)
    report.write_text(text[:start] + bench_text(data), encoding='utf-8')
    return path


# --- command line ------------------------------------------------------------------

REPORT_HELP = """\
Measure the solver's error against its cost and its stability on stiff and
extreme cases, and write DIR/REPORT.md with PNG figures: the 50-digit
reference and its checks, work-precision diagrams against Newton-Raphson,
finite differences and solve_ivp, the node's crank-angle error over long runs,
the extreme-case table, cost growth, and the error bounds against the actual
errors with the fraction of a turn refused; DIR/data.json holds every figure the
documentation quotes. A few minutes; --quick in under one.
"""


def _handle(args: argparse.Namespace) -> int:
    for given, option, script in ((args.long_run, '--long-run', 'bench/long_run.py'),
                                  (args.topic_drive, '--topic-drive', 'bench/topic_bench.py')):
        if given is not None and not Path(given).is_file():
            print(f'report: expected {option} to name the JSON file of {script}, got '
                  f'{given!r} (no such file)', file=sys.stderr)
            return 2
    if args.bench_only:
        if not (Path(args.output) / DATA_FILE).is_file():
            print(f'report: expected --bench-only to find the data file of a report in '
                  f'{args.output!r}, got none (run the report there first)', file=sys.stderr)
            return 2
        print(refresh_bench(args.output, args.mode))
        return 0
    run(args.output, args.mode, progress=not args.no_progress, long_run=args.long_run,
        topic_drive=args.topic_drive)
    print(Path(args.output) / 'REPORT.md')
    return 0


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register the ``report`` command on ``python -m mech_kinematics``'s subparsers."""
    parser = subparsers.add_parser('report', help='error against cost, extreme cases: '
                                                  'write DIR/REPORT.md and figures',
                                   description=REPORT_HELP,
                                   formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('-o', '--output', required=True, metavar='DIR',
                        help='folder for REPORT.md and the PNG figures (created)')
    size = parser.add_mutually_exclusive_group()
    size.add_argument('--quick', dest='mode', action='store_const', const='quick',
                      help='a subset, under a minute')
    size.add_argument('--smoke', dest='mode', action='store_const', const='smoke',
                      help='the smallest run that fills every section (for tests)')
    parser.add_argument('--no-progress', action='store_true', help='no progress bar')
    parser.add_argument('--long-run', metavar='FILE',
                        help="store FILE (bench/long_run.py's JSON: one real run of the node) "
                             "in DIR/data.json; without it the folder's previous one is kept")
    parser.add_argument('--topic-drive', metavar='FILE',
                        help="store FILE (bench/topic_bench.py's JSON: latency and CPU of the "
                             'node driven from a topic) in DIR/data.json; without it the '
                             "folder's previous one is kept")
    parser.add_argument('--bench-only', action='store_true',
                        help="measure section 7 alone (make bench's table, and pylinkage side "
                             "by side where installed) into DIR's data file and REPORT.md, "
                             'keeping the rest')
    parser.set_defaults(handler=_handle, mode='full')
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``report``; return the exit status."""
    return run_tool(add_parser, argv)
