# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""One source for every number: the report's measurements as a data file, and the check.

``report -o DIR`` writes ``DIR/data.json`` (:data:`DATA_FILE`) beside
``REPORT.md``: every figure the documentation quotes, under a stable dotted
key (:func:`collect`). Timings are ``[min, median, max]`` of repeated runs.
Measurements that take longer than a report run (:data:`KEPT`: ``long_run``,
one real run of the node, ``bench/long_run.py``; ``topic_drive``, the
latency and CPU of the node driven from a topic, ``bench/topic_bench.py``)
are copied in from a file (``report --long-run FILE``, ``--topic-drive
FILE``) or kept from the folder's previous data file. Scripts that measure
on their own (:data:`STORED`: the node against the rclpy floor,
``bench/node_bench.py --data FILE``; the recorder, the viewer, ``check``'s
grid study, ``reindex`` and the build of tf2_msgs, ``bench/docs_bench.py``)
write their section into the data file with :func:`store_section`; a report
keeps them too.

The documentation quotes them in two forms that :func:`check_text` checks:

- a figure followed by its key in an HTML comment, ``2.8e-7<!--=clock.naive_1h.min-->``
  (invisible once rendered; not inside inline code, where it is an example).
  A plain value passes when it rounds to the figure as written (``2.8e-7``
  holds 2.75e-7 to 2.85e-7); a timing ``[min, median, max]`` when the figure
  lies between its min and max (at the figure's precision): :data:`SPREAD_RULE`.
- a generated block between ``<!--data:NAME-->`` and ``<!--data:end-->``: a
  table that :func:`render_block` writes from the data, checked line for line
  (:func:`update_text` rewrites the blocks of a file).
"""

from __future__ import annotations

from collections.abc import Sequence
import datetime
import json
import math
import os
from pathlib import Path
import re
from typing import Any

__all__ = ['BLOCKS', 'DATA_FILE', 'KEPT', 'SPREAD_RULE', 'STORED', 'check_text', 'collect',
           'lookup', 'read_data', 'render_block', 'store_section', 'update_text', 'write_data']

#: The data file's name in the report's folder.
DATA_FILE = 'data.json'
#: Keys measured outside a report run: copied in from a file, else kept from the last one.
KEPT = ('long_run', 'topic_drive')
#: Sections that scripts of bench/ write with :func:`store_section`: a report keeps them.
STORED = ('node_rates', 'node_chains', 'recorder', 'viewer', 'check_grid', 'reindex',
          'tf2_build')
#: How a quoted timing is checked (also in docs/accuracy.md).
SPREAD_RULE = ('a timing quoted from [min, median, max] of repeated runs passes when it lies '
               'between the min and the max, at the precision it is written with')

_FIGURE = re.compile(r'(-?[0-9][0-9,]*(?:\.[0-9]+)?(?:e[-+]?[0-9]+)?)<!--=([A-Za-z0-9_.\-]+)-->')
_BLOCK = re.compile(r'(<!--data:([a-z_]+)-->\n)(.*?)(<!--data:end-->)', re.S)
_CODE = re.compile(r'`[^`\n]*`')


def _in_code(text: str) -> Any:
    """Return a test of whether a position of ``text`` lies in an inline code span."""
    spans = [m.span() for m in _CODE.finditer(text)]
    return lambda position: any(start < position < end for start, end in spans)


# --- collecting -----------------------------------------------------------------


def _spread(seconds: Sequence[float] | None, unit: float) -> list[float] | None:
    return None if seconds is None else [float(s) / unit for s in seconds]


def _range(values: Sequence[float]) -> dict[str, float]:
    return {'min': float(min(values)), 'max': float(max(values))}


def collect(mode: Any, elapsed: float, load: Sequence[float], checks: Any, golden: Any,
            wp: Any, clock: Any, clock_check: Any, extreme: Any, cost: Any, bounds: Any,
            refused: Any, bench: dict[str, Any] | None = None,
            peer: dict[str, Any] | None = None) -> dict[str, Any]:
    """Return the data file's figures from the report's computed sections.

    ``peer``: ``bench --peer``'s side-by-side table, where the peer is installed.
    """
    from .baselines import headline
    from .bounds import bound_statistics, TOLERANCES
    from .common import slug
    data: dict[str, Any] = {
        'generated': datetime.datetime.now(datetime.timezone.utc).strftime('%Y-%m-%d'),
        'mode': mode.name, 'repeat': mode.repeat, 'elapsed_s': float(elapsed),
        'load': _range(load), 'cpus': os.cpu_count(),
    }
    hl = headline(wp)
    mechanisms: dict[str, Any] = {}
    for name, h in hl.items():
        row: dict[str, Any] = {f'ours_{k}': v for k, v in h['ours_by_order'].items()}
        row['ours_array_ns'] = _spread(h['ours_spread'], 1e-9)
        row['ours_single_us'] = _spread(h['single_spread'], 1e-6)
        for family, alt in h['alternatives'].items():
            row[family] = {'setting': alt['label'], 'error': alt['error'],
                           'error_ratio': alt['error_ratio'], 'cost_ratio': alt['cost_ratio'],
                           'single_over_it': 1.0 / alt['cost_ratio_single'],
                           'time_us': _spread(alt['spread'], 1e-6)}
        mechanisms[slug(name)] = row
    for result in wp:
        mechanisms[slug(result.mechanism)]['printed_miss_pct'] = 100 * result.printed['miss']
    data['work_precision'] = mechanisms
    rows = list(mechanisms.values())

    def over(key: str, field: str | None = None) -> dict[str, float]:
        return _range([r[key][field] if field else r[key] for r in rows
                       if key in r and (field is None or field in r[key])])

    data['summary'] = {
        'ours_position': over('ours_position')['max'],
        'ours_velocity': over('ours_velocity')['max'],
        'ours_acceleration': over('ours_acceleration')['max'],
        'golden_max': max((g.max_rel_double for g in golden), default=math.nan),
        'golden_ulps_decimal': max((g.max_ulps_decimal for g in golden), default=math.nan),
        'newton_cost_ratio': over('newton', 'cost_ratio'),
        'single_over_newton': over('newton', 'single_over_it'),
        'differences_error_ratio': over('differences', 'error_ratio'),
        'solve_ivp_error': over('solve_ivp', 'error'),
        'solve_ivp_cost_ratio': over('solve_ivp', 'cost_ratio'),
        'printed_miss_pct': over('printed_miss_pct'),
    }
    data['clock'] = _clock(clock, clock_check)
    data['extreme'] = {'cases': len(extreme),
                       'failures': sum(r.verdict == 'FAIL' for r in extreme)}
    stats = bound_statistics([v for r in bounds for v in r.values])
    data['bounds'] = {
        'cases': len(bounds), 'values': stats.values, 'below': stats.below,
        'instants': sum(r.answered for r in bounds), 'min': stats.min,
        'median': stats.median, 'p90': stats.p90, 'tightness': stats.tightness,
        'refused': {f.case.name: {f'{tol:g}': f.refused[tol] for tol in TOLERANCES}
                    for f in refused},
    }
    data['cost'] = {'batch_slope': cost.batch_slope, 'chain_slope_array': cost.chain_slope_array,
                    'chain_slope_single': cost.chain_slope_single}
    if bench is not None:
        data['bench'] = bench
    if peer is not None:
        data['peer'] = peer
    return data


def _clock(clock: Any, check: dict[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {'rows': [
        {'duration': r.duration, 'rpm': r.rpm, 'angle_error': r.angle_error,
         'state_error': r.state_error, 'wrapped_model': r.wrapped_model} for r in clock]}
    for label, key in (('1 h', '1h'), ('1 day', 'day'), ('1 year', 'year')):
        rows = [r for r in clock if r.duration == label]
        if not rows:
            continue
        for method in ('timebase', 'naive', 'naive, wrapped'):
            name = method.replace(', ', '_')
            out[f'{name}_{key}'] = _range([r.angle_error[method] for r in rows])
    out['turns_equal'] = bool(check.get('turns_equal', False))
    return out


# --- files ------------------------------------------------------------------------


def read_data(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Return the data file at ``path``."""
    data: dict[str, Any] = json.loads(Path(path).read_text(encoding='utf-8'))
    return data


def write_data(outdir: str | os.PathLike[str], data: dict[str, Any],
               long_run: str | os.PathLike[str] | None = None,
               topic_drive: str | os.PathLike[str] | None = None) -> Path:
    """Write ``outdir/data.json``; keep the previous file's :data:`KEPT` keys unless given anew.

    ``long_run``, ``topic_drive``: JSON files of ``bench/long_run.py`` and
    ``bench/topic_bench.py`` to store under those keys. Likewise its ``peer``
    (``bench --peer``'s table) where this run had no peer installed, and
    every :data:`STORED` section (measured by its own script).
    """
    path = Path(outdir) / DATA_FILE
    given = {'long_run': long_run, 'topic_drive': topic_drive}
    previous = read_data(path) if path.exists() else {}
    for key in KEPT:
        if given[key] is not None:
            data[key] = read_data(given[key])   # type: ignore[arg-type]
        elif key in previous:
            data[key] = previous[key]
    if data.get('peer') is None:
        data.pop('peer', None)
        if 'peer' in previous:
            data['peer'] = previous['peer']
    for key in STORED:
        if key in previous:
            data[key] = previous[key]
    path.write_text(json.dumps(data, indent=1, sort_keys=True) + '\n', encoding='utf-8')
    return path


def store_section(path: str | os.PathLike[str], key: str, section: dict[str, Any]) -> Path:
    """Write ``section`` under top-level ``key`` of the data file at ``path``; keep the rest.

    ``key`` must be one of :data:`STORED` (a report keeps only those).
    """
    if key not in STORED:
        raise ValueError(f'Expected a section a report keeps ({", ".join(STORED)}), '
                         f'got {key!r}')
    path = Path(path)
    data = read_data(path) if path.exists() else {}
    data[key] = section
    path.write_text(json.dumps(data, indent=1, sort_keys=True) + '\n', encoding='utf-8')
    return path


# --- checking ---------------------------------------------------------------------


def lookup(data: dict[str, Any], key: str) -> Any:
    """Return the value at dotted ``key`` (``KeyError`` naming the key if absent)."""
    value: Any = data
    for part in key.split('.'):
        if not isinstance(value, dict) or part not in value:
            raise KeyError(key)
        value = value[part]
    return value


def _half_unit(figure: str) -> float:
    """Return half a unit in the last place of ``figure`` as written."""
    mantissa, _, exponent = figure.lower().partition('e')
    decimals = len(mantissa.partition('.')[2])
    return 0.5 * 10.0 ** (int(exponent or 0) - decimals)


def _figure_matches(figure: str, value: Any) -> bool:
    number = float(figure.replace(',', ''))
    slack = _half_unit(figure.replace(',', '')) * (1 + 1e-9)
    if isinstance(value, list) and len(value) == 3:
        low, _, high = (float(v) for v in value)
        return low - slack <= number <= high + slack
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    return abs(number - float(value)) <= slack


def check_text(text: str, data: dict[str, Any], name: str = 'text') -> list[str]:
    """Return one line per figure or block of ``text`` that disagrees with ``data``."""
    problems = []
    in_code = _in_code(text)
    for match in _FIGURE.finditer(text):
        if in_code(match.start()):
            continue        # an example of the form, not a figure
        figure, key = match.groups()
        line = text.count('\n', 0, match.start()) + 1
        try:
            value = lookup(data, key)
        except KeyError:
            problems.append(f'{name}:{line}: {figure} quotes {key}, which the data file lacks')
            continue
        if not _figure_matches(figure, value):
            problems.append(f'{name}:{line}: {figure} quotes {key} = {value!r}: expected the '
                            'figure as measured (update the text from the data file)')
    for match in _BLOCK.finditer(text):
        block = match.group(2)
        line = text.count('\n', 0, match.start()) + 1
        try:
            expected = render_block(block, data)
        except KeyError as error:
            problems.append(f'{name}:{line}: block {block} needs {error}, which the data '
                            'file lacks')
            continue
        if match.group(3) != expected:
            problems.append(f'{name}:{line}: block {block} differs from the data file '
                            '(rewrite it with data.update_text)')
    return problems


def update_text(text: str, data: dict[str, Any]) -> str:
    """Return ``text`` with every quoted figure and generated block rewritten from ``data``.

    A figure keeps the form it is written in (decimals, exponent, thousands
    separators); a timing is rewritten to its median. The words around it are
    the author's to check.
    """
    in_code = _in_code(text)

    def figure(match: re.Match[str]) -> str:
        if in_code(match.start()):
            return match.group(0)
        written, key = match.groups()
        value = lookup(data, key)
        if isinstance(value, list):
            value = value[1]
        return f'{_format_like(written, float(value))}<!--={key}-->'

    text = _FIGURE.sub(figure, text)
    return _BLOCK.sub(lambda m: m.group(1) + render_block(m.group(2), data) + m.group(4), text)


def _format_like(written: str, value: float) -> str:
    """Return ``value`` in the form of ``written`` (its decimals, exponent and separators)."""
    mantissa, e, _ = written.lower().partition('e')
    decimals = len(mantissa.partition('.')[2])
    if e:
        text = f'{value:.{decimals}e}'
        digits, exponent = text.split('e')
        return f'{digits}e{int(exponent)}'
    if ',' in written:
        return f'{round(value):,}'
    return f'{value:.{decimals}f}'


# --- generated blocks -------------------------------------------------------------


def _g(x: float, digits: int = 2) -> str:
    if x == 0:
        return '0'
    if math.isnan(x):
        return '-'
    text = f'{x:.{digits}g}'
    if 'e' in text:
        mantissa, exponent = text.split('e')
        text = f'{mantissa}e{int(exponent)}'
    return text


def _refused_block(data: dict[str, Any]) -> str:
    refused = lookup(data, 'bounds.refused')
    tolerances = list(next(iter(refused.values())))
    lines = ['| case | ' + ' | '.join(f'max_error {t}' for t in tolerances) + ' |',
             '|---|' + '---|' * len(tolerances)]
    for case, fractions in refused.items():
        lines.append(f'| {case} | ' + ' | '.join(_g(fractions[t]) for t in tolerances) + ' |')
    return '\n'.join(lines) + '\n'


def _bench_block(data: dict[str, Any]) -> str:
    bench = lookup(data, 'bench')
    lines = ['| scene | single angle, µs (min / median / max) | ratio | array, per '
             'configuration, µs (min / median / max) | ratio |', '|---|---|---|---|---|']
    for row in bench['rows']:
        single = ' / '.join(f'{t:.2f}' for t in row['single_us'])
        array = ' / '.join(f'{t:.3f}' for t in row['array_us'])
        if 'baseline_of' in row:
            ratios = ('1', '1')
        elif 'single_ratio' in row:
            ratios = (f'{row["single_ratio"]:.2f}×', f'{row["array_ratio"]:.2f}×')
        else:
            ratios = ('-', '-')
        lines.append(f'| {row["scene"]} | {single} | {ratios[0]} | {array} | {ratios[1]} |')
    return '\n'.join(lines) + '\n'


def _clock_block(data: dict[str, Any]) -> str:
    lines = ['| run time | rpm | time base [rad] | `angle += omega * dt`, never wrapped | '
             'the same, wrapped every tick |', '|---|---|---|---|---|']
    for row in lookup(data, 'clock.rows'):
        error = row['angle_error']
        star = '*' if row['wrapped_model'] else ''
        lines.append(f'| {row["duration"]} | {row["rpm"]:g} | {_g(error["timebase"])} | '
                     f'{_g(error["naive"])} | {_g(error["naive, wrapped"])}{star} |')
    return '\n'.join(lines) + '\n'


def _long_run_block(data: dict[str, Any]) -> str:
    run = lookup(data, 'long_run')
    return '\n'.join([
        '| date | scene | rate | crank speed | run time | turns | instants received / owed | '
        'crank angle error, max | joint positions and velocities, max error |',
        '|---|---|---|---|---|---|---|---|---|',
        f'| {run["date"]} | {run["scene"]} | {run["rate_hz"]:g} Hz | '
        f'{run["crank_speed_rpm"]:g} rpm | {run["run_time_s"]:.0f} s | {run["turns"]:.0f} | '
        f'{run["received"]:,} / {run["owed"]:,} | {_g(run["max_angle_error_rad"])} rad | '
        f'{_g(run["max_state_error"])} |']) + '\n'


def _topic_drive_block(data: dict[str, Any]) -> str:
    run = lookup(data, 'topic_drive')
    lines = ['| input rate | latency, median: floor / node | node / floor | latency, p99: '
             'floor / node | CPU: floor / node | node / floor | answered (worst run) |',
             '|---:|---:|---:|---:|---:|---:|---:|']
    for rate, row in run['rates'].items():
        f, n = row['floor'], row['node']
        answered = 100 * min(f['answered_min'], n['answered_min'])
        lines.append(
            f'| {rate} Hz | {f["latency_median_us"]:.0f} / {n["latency_median_us"]:.0f} µs | '
            f'{row["latency_ratio"]:.2f} | {f["latency_p99_us"]:.0f} / '
            f'{n["latency_p99_us"]:.0f} µs | {f["cpu_pct"]:.1f} / {n["cpu_pct"]:.1f} % | '
            f'{row["cpu_ratio"]:.2f} | {answered:.2f} % |')
    return '\n'.join(lines) + '\n'


def _peer_block(data: dict[str, Any]) -> str:
    peer = lookup(data, 'peer')
    lines = [f'| scene | work | ours, µs (min / median / max) | {peer["peer"]}, µs '
             '(min / median / max) | theirs / ours (medians) |', '|---|---|---|---|---|']
    for row in peer['rows']:
        for key, label in peer['work']:
            ours, theirs = row[key]['ours_us'], row[key]['theirs_us']
            lines.append(f'| {row["scene"]} | {label} | {" / ".join(f"{t:.3g}" for t in ours)} '
                         f'| {" / ".join(f"{t:.3g}" for t in theirs)} | '
                         f'{theirs[1] / ours[1]:.2f} |')
        lines.append(f'| {row["scene"]} | their cold start (first calls) | | '
                     f'{row["cold_s"]:.2f} s | |')
    return '\n'.join(lines) + '\n'


def _node_block(data: dict[str, Any], key: str, label: str) -> str:
    section = lookup(data, key)
    runs = section['repeat']
    lines = [f'| {label} | floor CPU, % ({runs} run{"s" * (runs > 1)}) | node CPU, % | '
             'node / floor (medians) | grid instants delivered, floor / node (worst run) |',
             '|---:|---:|---:|---:|---:|']
    for value, row in sorted(section['rows'].items(), key=lambda item: float(item[0])):
        shown = f'{float(value) / 1000:g} kHz' if key == 'node_rates' else value
        floor, node = (' / '.join(f'{c:.1f}' for c in row[f'{kind}_cpu_pct'])
                       for kind in ('floor', 'node'))
        lines.append(f'| {shown} | {floor} | {node} | {row["ratio"]:.2f} | '
                     f'{row["floor_delivered_pct"]:.3f} % / {row["node_delivered_pct"]:.3f} % |')
    return '\n'.join(lines) + '\n'


def _node_rates_block(data: dict[str, Any]) -> str:
    return _node_block(data, 'node_rates', 'rate')


def _node_chains_block(data: dict[str, Any]) -> str:
    return _node_block(data, 'node_chains', 'dyads')


#: The generated blocks: name -> function of the data returning the block's text.
BLOCKS = {'refused': _refused_block, 'bench': _bench_block, 'clock': _clock_block,
          'long_run': _long_run_block, 'topic_drive': _topic_drive_block, 'peer': _peer_block,
          'node_rates': _node_rates_block, 'node_chains': _node_chains_block}


def render_block(name: str, data: dict[str, Any]) -> str:
    """Return the text of generated block ``name`` from ``data``."""
    if name not in BLOCKS:
        raise KeyError(f'block {name} (known: {", ".join(BLOCKS)})')
    return BLOCKS[name](data)
