# Copyright 2026 mech_kinematics contributors
# SPDX-License-Identifier: Apache-2.0
"""The report as a whole (issue 5): its command line, its package and REPORT.md.

Each section's numbers come from the functions tested in
``test_report_<module>.py``; here the package's shape (light import, the
re-exported names), the command and the generated report are checked.
"""

from __future__ import annotations

import argparse
import importlib
from pathlib import Path
import re
import subprocess
import sys

import pytest

from mech_kinematics.tools import report
from mech_kinematics.verify.extreme import extreme_cases

SECTIONS = ('## 1. The 50-digit reference', '## 2. Work-precision',
            '## 3. Error against run time of the node', '## 4. Stiff and extreme cases',
            '## 5. Cost growth', '## 6. Error bounds against the truth')
#: The modules of the report package, one per concern.
MODULES = ('baselines', 'bounds', 'checks', 'clock', 'common', 'cost', 'data', 'figures',
           'markdown')
#: What common.py shares with the section modules only (not re-exported).
SHARED_HELPERS = {'median_time', 'quiet_solve', 'slug'}


def test_add_parser_registers_report():
    """add_parser adds `report -o DIR [--quick | --smoke]` with a handler."""
    parser = argparse.ArgumentParser()
    report.add_parser(parser.add_subparsers(dest='command'))
    args = parser.parse_args(['report', '-o', 'out', '--quick'])
    assert args.mode == 'quick' and args.output == 'out' and callable(args.handler)
    assert parser.parse_args(['report', '-o', 'x']).mode == 'full'
    with pytest.raises(SystemExit):
        parser.parse_args(['report', '-o', 'x', '--quick', '--smoke'])


def test_registered_as_the_report_command():
    """`python -m mech_kinematics report ...` is this package's parser and handler."""
    from mech_kinematics.__main__ import build_parser
    args = build_parser().parse_args(['report', '-o', 'x', '--smoke', '--no-progress'])
    assert args.command == 'report' and args.mode == 'smoke' and args.no_progress
    assert args.handler.__module__ == report.__name__


def test_import_is_light():
    """Importing the report package and every module loads no matplotlib, SciPy, mpmath, tqdm."""
    modules = ', '.join(f'mech_kinematics.tools.report.{name}' for name in MODULES)
    code = (f'import sys, mech_kinematics.tools.report, {modules}; '
            "heavy = {'matplotlib', 'scipy', 'mpmath', 'tqdm'} & set(sys.modules); "
            'assert not heavy, heavy')
    subprocess.run([sys.executable, '-c', code], check=True, timeout=60)


def test_package_reexports_its_modules_public_names():
    """Every name of every module's __all__ is the package's same object, listed in its __all__."""
    for name in MODULES:
        module = importlib.import_module(f'mech_kinematics.tools.report.{name}')
        assert module.__doc__ and module.__all__, name
        for public in set(module.__all__) - SHARED_HELPERS:
            assert getattr(report, public) is getattr(module, public), (name, public)
            assert public in report.__all__, (name, public)
    assert all(hasattr(report, public) for public in report.__all__)


@pytest.fixture(scope='module')
def quick_report(tmp_path_factory):
    """`python -m mech_kinematics.tools.report -o DIR --quick` in a temporary folder: the folder.

    The one end-to-end run of the command (a subprocess): it exits 0 and prints
    the report's path. Every test of the generated report reads this run.
    """
    out = tmp_path_factory.mktemp('report')
    result = subprocess.run([sys.executable, '-m', 'mech_kinematics.tools.report', '-o',
                             str(out), '--quick', '--no-progress'],
                            capture_output=True, text=True, timeout=900, check=False)
    assert result.returncode == 0, result.stderr
    assert Path(result.stdout.strip()) == out / 'REPORT.md'
    return out


def test_quick_report_has_every_section(quick_report):
    """REPORT.md has the six sections and every figure it links exists."""
    text = (quick_report / 'REPORT.md').read_text()
    for section in SECTIONS:
        assert section in text
    figures = re.findall(r'!\[[^\]]*\]\(([^)]+)\)', text)
    assert len(figures) >= 9 and {'bounds.png', 'refused.png'} <= set(figures)
    for name in figures:
        assert (quick_report / name).stat().st_size > 10_000, name


def test_quick_report_has_no_failures(quick_report):
    """The extreme-case table has a verdict on every row and no FAIL."""
    text = (quick_report / 'REPORT.md').read_text()
    table = text.split('## 4.')[1].split('###')[0]
    rows = [line for line in table.splitlines() if re.match(r'\| \d+ \|', line)]
    assert len(rows) == len(extreme_cases(report.MODES['quick'].extreme_angles))
    assert all(re.search(r'\*\*(meets bound|flagged|refused \(no assembly\))\*\*', r)
               for r in rows)
    assert 'FAIL' not in text


def test_cli_main_writes_section_6_and_its_figures(quick_report):
    """`... report -o DIR --quick` (the fixture's subprocess) writes section 6 and its figures.

    The bounds table's "all cases" row has no bound below its actual error.
    (One run of the command serves here and above: the --smoke run this test
    made besides cost half a minute; --smoke is run by --bench-only below and
    its sections in ``test_report_<module>.py``.)
    """
    text = (quick_report / 'REPORT.md').read_text()
    assert '## 5. Cost growth' in text
    bounds_section = text.split('## 6. Error bounds against the truth')[1]
    assert re.search(r'\| \| \*\*all cases\*\* \| \d+ / \d+ / \d+ \| \d+ \| \d+ \| \*\*0\*\* \|',
                     bounds_section)
    assert 'No bound is below its actual error' in bounds_section
    for name in ('bounds.png', 'refused.png'):
        assert f']({name})' in bounds_section
        assert (quick_report / name).stat().st_size > 10_000, name


def test_quick_report_writes_its_data_file(quick_report):
    """data.json beside REPORT.md: every figure the docs quote, timings as [min, median, max]."""
    from mech_kinematics.scene import scene_names
    data = report.read_data(quick_report / report.DATA_FILE)
    assert data['mode'] == 'quick' and data['elapsed_s'] > 0
    for key in ('summary.ours_position', 'summary.ours_velocity', 'summary.ours_acceleration',
                'summary.single_over_newton.max', 'clock.naive_year.max', 'bounds.tightness',
                'cost.batch_slope', 'extreme.cases'):
        assert report.lookup(data, key) > 0, key
    low, mid, high = report.lookup(data, 'work_precision.four_bar.ours_single_us')
    assert 0 < low <= mid <= high
    assert [r['scene'] for r in data['bench']['rows'] if 'baseline_of' not in r] \
        == scene_names()
    text = (quick_report / 'REPORT.md').read_text()
    assert '## 7. Against hand-written closed forms' in text
    assert '| mechanism | positions | velocities | accelerations |' in text
    assert "The node's single-angle path (one call per tick) costs" in text


def test_quick_report_has_the_peer_side_by_side(quick_report):
    """With pylinkage installed, section 7 and the data file hold the side-by-side table."""
    data = report.read_data(quick_report / report.DATA_FILE)
    peer = data['peer']
    assert [row['scene'] for row in peer['rows']] == ['khurmi_four_bar_ad150',
                                                      'slider_crank_150_600']
    assert [key for key, _ in peer['work']] == ['single', 'batch_360',
                                                f'batch_{data["bench"]["angles"]}']
    text = (quick_report / 'REPORT.md').read_text()
    assert 'Side by side with pylinkage 1.3.0 (numba)' in text
    assert report.render_block('peer', data) in text


def test_bench_only_measures_section_7_again_and_keeps_the_rest(quick_report, tmp_path):
    """`report -o DIR --bench-only --smoke`: new bench and peer tables, every other figure kept."""
    for name in (report.DATA_FILE, 'REPORT.md'):
        (tmp_path / name).write_bytes((quick_report / name).read_bytes())
    before = report.read_data(tmp_path / report.DATA_FILE)
    text = (tmp_path / 'REPORT.md').read_text()
    assert report.main(['-o', str(tmp_path), '--smoke', '--bench-only']) == 0
    after = report.read_data(tmp_path / report.DATA_FILE)
    assert {k: v for k, v in after.items() if k not in ('bench', 'peer')} == \
        {k: v for k, v in before.items() if k not in ('bench', 'peer')}
    assert after['bench']['angles'] == report.MODES['smoke'].bench_angles \
        != before['bench']['angles']
    new_text = (tmp_path / 'REPORT.md').read_text()
    head = text.split('## 7. ')[0]
    assert new_text.startswith(head) and new_text != text
    assert report.render_block('bench', after) in new_text
    assert report.render_block('peer', after) in new_text


def test_bench_only_needs_a_report_there(tmp_path, capsys):
    """--bench-only in a folder with no data file: one line saying so, exit 2."""
    assert report.main(['-o', str(tmp_path), '--bench-only']) == 2
    assert 'expected --bench-only to find the data file' in capsys.readouterr().err
