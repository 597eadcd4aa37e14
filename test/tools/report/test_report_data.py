# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""One source for every number (issue 19): the data file, and README and docs against it.

Every figure that README.md and docs/*.md quote from the report carries its
key (``2.8e-7<!--=clock.naive_1h.min-->``) or lies in a generated block;
:func:`check_text` must find nothing wrong with them against the committed
docs/report/data.json, and must catch a figure that differs.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from mech_kinematics.tools.report import data as data_mod

ROOT = Path(__file__).resolve().parents[3]
DATA = ROOT / 'docs' / 'report' / 'data.json'
#: Keys docs/accuracy.md must quote (its "Accuracy and speed" headline and tables).
REQUIRED_KEYS = ('summary.ours_acceleration', 'summary.golden_max',
                 'summary.newton_cost_ratio.min', 'summary.single_over_newton.max',
                 'clock.timebase_year.max', 'clock.naive_1h.min', 'clock.naive_year.max',
                 'bounds.values', 'bounds.min', 'bounds.median', 'bounds.tightness',
                 'cost.batch_slope', 'long_run.run_time_s', 'elapsed_s',
                 'node_rates.seconds', 'node_chains.node_pct_per_dyad',
                 'node_chains.node_us_per_dyad_tick', 'node_chains.floor_pct_per_dyad')

#: Keys other docs must quote, each from the script that measures it (bench/node_bench.py,
#: bench/docs_bench.py): doc -> keys.
REQUIRED_ELSEWHERE = {
    'bags.md': ('recorder.witness_mb_per_minute', 'recorder.mcap.cpu_pct',
                'recorder.sqlite3.cpu_pct', 'recorder.mcap.older_than_1s_pct',
                'recorder.sqlite3.older_than_1s_pct', 'recorder.mcap.recovered_pct',
                'recorder.sqlite3.recovered_pct', 'recorder.mcap.newest_ms',
                'recorder.sqlite3.newest_ms', 'recorder.mcap.reindex_s',
                'recorder.sqlite3.reindex_s'),
    'install.md': ('tf2_build.s', 'tf2_build.repeat'),
    'view.md': ('viewer.median_ms', 'viewer.p90_ms', 'viewer.kb', 'viewer.requests'),
    'commands.md': ('check_grid.five_bar.ms', 'check_grid.excavator.ms', 'check_grid.repeat'),
    'robustness.md': ('reindex.messages', 'reindex.mcap.mb', 'reindex.mcap.s',
                      'reindex.mcap.kept', 'reindex.mcap.dropped', 'reindex.sqlite3.mb',
                      'reindex.sqlite3.s', 'reindex.sqlite3.kept', 'reindex.sqlite3.dropped'),
}

SAMPLE = {'a': {'b': 2.83e-7, 'n': 2886}, 't': [0.30, 0.32, 0.36],
          'bench': {'angles': 10, 'repeat': 3, 'rows': [
              {'scene': 's', 'single_us': [1.0, 2.0, 3.0], 'array_us': [0.1, 0.2, 0.3],
               'single_ratio': 2.0, 'array_ratio': 2.0},
              {'scene': 's (hand-written)', 'single_us': [1.0] * 3, 'array_us': [0.1] * 3,
               'baseline_of': 's'}]}}


@pytest.fixture(scope='module')
def committed():
    """Return the committed data file."""
    return data_mod.read_data(DATA)


@pytest.mark.parametrize('path', [ROOT / 'README.md', *sorted((ROOT / 'docs').glob('*.md')),
                                  ROOT / 'bench' / 'README.md'],
                         ids=lambda p: str(p.relative_to(ROOT)))
def test_docs_agree_with_the_data_file(path, committed):
    """Every quoted figure and generated block of README and docs matches docs/report/data.json."""
    assert data_mod.check_text(path.read_text(encoding='utf-8'), committed, path.name) == []


def test_accuracy_doc_quotes_the_data_file(committed):
    """docs/accuracy.md quotes its headline figures from the data file, and its tables."""
    text = (ROOT / 'docs' / 'accuracy.md').read_text(encoding='utf-8')
    for key in REQUIRED_KEYS:
        assert f'<!--={key}-->' in text, key
        data_mod.lookup(committed, key)
    for block in ('bench', 'refused', 'long_run', 'node_rates', 'node_chains'):
        assert f'<!--data:{block}-->' in text, block


@pytest.mark.parametrize('doc', sorted(REQUIRED_ELSEWHERE))
def test_measured_docs_keep_their_keys(doc, committed):
    """Docs whose measured figures come from a bench script keep quoting them from the data."""
    text = (ROOT / 'docs' / doc).read_text(encoding='utf-8')
    for key in REQUIRED_ELSEWHERE[doc]:
        assert f'<!--={key}-->' in text, key
        data_mod.lookup(committed, key)


def test_the_real_run_of_the_node_is_recorded(committed):
    """The data file holds one real run of the node of at least ten minutes, with its date."""
    run = committed['long_run']
    assert run['run_time_s'] >= 600 and run['date'].startswith('20')
    assert run['received'] <= run['owed'] and run['samples'] >= 600


def test_a_figure_that_differs_is_caught():
    """A plain value must round to the figure as written; the line and the key are named."""
    good = 'off by 2.8e-7<!--=a.b--> rad; 2,886<!--=a.n--> values'
    assert data_mod.check_text(good, SAMPLE) == []
    assert data_mod.check_text('2.83e-7<!--=a.b-->', SAMPLE) == []
    problems = data_mod.check_text('x\n2.9e-7<!--=a.b-->', SAMPLE, 'doc.md')
    assert len(problems) == 1 and problems[0].startswith('doc.md:2: 2.9e-7 quotes a.b')
    assert data_mod.check_text('2885<!--=a.n-->', SAMPLE) != []
    assert 'lacks' in data_mod.check_text('1<!--=a.c-->', SAMPLE)[0]
    assert data_mod.check_text('3<!--=a-->', SAMPLE) != []


def test_a_timing_passes_within_its_spread():
    """A timing quoted from [min, median, max] passes between min and max, at its precision."""
    for figure in ('0.30', '0.3', '0.33', '0.36', '0.4'):
        assert data_mod.check_text(f'{figure}<!--=t-->', SAMPLE) == [], figure
    for figure in ('0.28', '0.37', '0.5'):
        assert data_mod.check_text(f'{figure}<!--=t-->', SAMPLE) != [], figure


def test_generated_blocks_are_checked_and_rewritten():
    """A block that differs from its rendering is caught; update_text rewrites it."""
    stale = 'before\n<!--data:bench-->\n| old |\n<!--data:end-->\nafter\n'
    problems = data_mod.check_text(stale, SAMPLE, 'doc.md')
    assert problems == ['doc.md:2: block bench differs from the data file (rewrite it with '
                        'data.update_text)']
    fresh = data_mod.update_text(stale, SAMPLE)
    assert data_mod.check_text(fresh, SAMPLE) == []
    assert fresh.startswith('before\n<!--data:bench-->\n| scene |') and fresh.endswith(
        '<!--data:end-->\nafter\n')
    assert '| s | 1.00 / 2.00 / 3.00 | 2.00× | 0.100 / 0.200 / 0.300 | 2.00× |' in fresh
    assert 'block nope needs' in data_mod.check_text('<!--data:nope-->\n<!--data:end-->',
                                                     SAMPLE)[0]


def test_the_node_blocks_list_each_rate_and_size_in_order():
    """The node-against-floor tables: every run's CPU, the medians' ratio, the worst delivery."""
    row = {'floor_cpu_pct': [10.0, 11.0, 12.0], 'node_cpu_pct': [13.0, 13.2, 14.0],
           'ratio': 1.2, 'floor_delivered_pct': 99.998, 'node_delivered_pct': 100.0}
    data = {'node_rates': {'repeat': 3, 'rows': {'5000': row, '1000': row}},
            'node_chains': {'repeat': 1, 'rows': {'16': row, '4': row}}}
    rates = data_mod.render_block('node_rates', data).splitlines()
    assert rates[0].startswith('| rate | floor CPU, % (3 runs) | node CPU, % |')
    assert rates[2] == ('| 1 kHz | 10.0 / 11.0 / 12.0 | 13.0 / 13.2 / 14.0 | 1.20 | '
                        '99.998 % / 100.000 % |')
    assert rates[3].startswith('| 5 kHz |')
    chains = data_mod.render_block('node_chains', data).splitlines()
    assert chains[0].startswith('| dyads | floor CPU, % (1 run) |')
    assert [line.split(' |')[0] for line in chains[2:]] == ['| 4', '| 16']


def test_write_data_keeps_the_long_run(tmp_path):
    """A new report keeps the folder's real run of the node unless given a new one."""
    run = tmp_path / 'run.json'
    run.write_text(json.dumps({'date': '2026-11-24', 'run_time_s': 600.0}))
    data_mod.write_data(tmp_path, {'x': 1}, run)
    data_mod.write_data(tmp_path, {'x': 2})
    written = data_mod.read_data(tmp_path / data_mod.DATA_FILE)
    assert written == {'x': 2, 'long_run': {'date': '2026-11-24', 'run_time_s': 600.0}}


def test_store_section_writes_one_key_and_a_report_keeps_it(tmp_path):
    """A bench script's section goes in beside the rest; a later report keeps it."""
    path = tmp_path / data_mod.DATA_FILE
    path.write_text(json.dumps({'x': 1, 'reindex': {'old': True}}))
    data_mod.store_section(path, 'reindex', {'mcap': {'mb': 13.9}})
    data_mod.store_section(path, 'check_grid', {'repeat': 7})
    assert data_mod.read_data(path) == {'x': 1, 'reindex': {'mcap': {'mb': 13.9}},
                                        'check_grid': {'repeat': 7}}
    data_mod.write_data(tmp_path, {'x': 2})
    assert data_mod.read_data(path) == {'x': 2, 'reindex': {'mcap': {'mb': 13.9}},
                                        'check_grid': {'repeat': 7}}


def test_store_section_refuses_a_key_a_report_would_drop(tmp_path):
    """Only the sections a report keeps may be stored (one line naming the key)."""
    with pytest.raises(ValueError, match="got 'summary'"):
        data_mod.store_section(tmp_path / data_mod.DATA_FILE, 'summary', {})
    assert not (tmp_path / data_mod.DATA_FILE).exists()


def test_write_data_keeps_the_topic_drive_figures(tmp_path):
    """A new report keeps the topic drive's figures (bench/topic_bench.py) unless given anew."""
    first, second = tmp_path / 'a.json', tmp_path / 'b.json'
    first.write_text(json.dumps({'date': '2026-11-24', 'rates': {}}))
    second.write_text(json.dumps({'date': '2026-11-25', 'rates': {}}))
    data_mod.write_data(tmp_path, {'x': 1}, topic_drive=first)
    data_mod.write_data(tmp_path, {'x': 2})
    assert data_mod.read_data(tmp_path / data_mod.DATA_FILE)['topic_drive']['date'] == \
        '2026-11-24'
    data_mod.write_data(tmp_path, {'x': 3}, topic_drive=second)
    assert data_mod.read_data(tmp_path / data_mod.DATA_FILE) == {
        'x': 3, 'topic_drive': {'date': '2026-11-25', 'rates': {}}}


def test_the_topic_drive_is_recorded_and_quoted(committed):
    """Latency and CPU of topic drive at 100 Hz and 1 kHz, node and floor, quoted in node.md."""
    rates = committed['topic_drive']['rates']
    assert set(rates) == {'100', '1000'}
    for row in rates.values():
        for kind in ('floor', 'node'):
            assert row[kind]['latency_median_us'] > 0 and row[kind]['cpu_pct'] > 0
            assert len(row[kind]['runs']) == committed['topic_drive']['repeat']
        assert row['cpu_ratio'] == row['node']['cpu_pct'] / row['floor']['cpu_pct']
    text = (ROOT / 'docs' / 'node.md').read_text(encoding='utf-8')
    assert '<!--data:topic_drive-->' in text
    for key in ('topic_drive.rates.1000.node.latency_median_us',
                'topic_drive.rates.1000.cpu_ratio', 'topic_drive.rates.100.cpu_ratio'):
        assert f'<!--={key}-->' in text, key


def test_the_topic_drive_block():
    """The generated table has a row per input rate with floor / node figures and ratios."""
    side = {'latency_median_us': 600.0, 'latency_p99_us': 3000.0, 'cpu_pct': 40.0,
            'answered_min': 1.0}
    node = {**side, 'latency_median_us': 650.0, 'cpu_pct': 52.0, 'answered_min': 0.9995}
    data = {'topic_drive': {'rates': {'1000': {'floor': side, 'node': node,
                                               'latency_ratio': 650 / 600, 'cpu_ratio': 1.3}}}}
    block = data_mod.render_block('topic_drive', data)
    assert block.splitlines()[2] == ('| 1000 Hz | 600 / 650 µs | 1.08 | 3000 / 3000 µs | '
                                     '40.0 / 52.0 % | 1.30 | 99.95 % |')


def test_update_text_rewrites_figures_in_their_written_form():
    """Figures keep their decimals, exponent and separators; timings become their median."""
    text = 'a 9.9e-9<!--=a.b--> b 1<!--=a.n--> c 1,000<!--=a.n--> d 0.000<!--=t-->'
    assert data_mod.update_text(text, SAMPLE) == ('a 2.8e-7<!--=a.b--> b 2886<!--=a.n--> c '
                                                  '2,886<!--=a.n--> d 0.320<!--=t-->')


def test_examples_in_inline_code_are_not_figures():
    """The form shown in backticks is an example: neither checked nor rewritten."""
    text = 'write `2.8e-7<!--=key-->` after 2.8e-7<!--=a.b-->'
    assert data_mod.check_text(text, SAMPLE) == []
    assert data_mod.update_text(text, SAMPLE) == text
