"""Unit tests of lab/bench/report.py: docs/benchmarks.md as one `make bench` run renders it, with
every figure from that run (issue 28: the file was edited by hand after the last run). Fed the raw
results that docs/benchmarks.md was rendered from; no master, no clock."""

import copy
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, '..', '..', 'bench'))

import report  # noqa: E402

RESULTS = os.path.join(HERE, '..', '..', 'bench', 'results.json')


def results():
    with open(RESULTS) as f:
        return json.load(f)


def row(markdown, metric):
    """The cells of the table row whose first cell starts with ``metric``."""
    for line in markdown.splitlines():
        cells = [cell.strip() for cell in line.strip('|').split('|')]
        if cells[0].startswith(metric):
            return cells
    raise AssertionError('no row %r' % metric)


def test_memory_goal_is_relative_to_the_bare_rospy_node_of_the_same_run_in_mib():
    r = results()
    r['ours']['rate']['rss_mb'] = r['floor']['rss_mb'] + 0.5
    cells = row(report.render(r, 'f.png'), 'RSS at 10 Hz (MiB)')
    assert cells[4] == 'within 1 MiB of the bare rospy node (%.2f MiB)' % r['floor']['rss_mb']
    assert cells[5] == 'met (+0.50 MiB)'
    r['ours']['rate']['rss_mb'] = r['floor']['rss_mb'] + 1.5
    assert row(report.render(r, 'f.png'), 'RSS at 10 Hz (MiB)')[5] == '**missed** (+1.50 MiB)'


def test_machine_load_has_no_ratio_and_memory_sizes_give_the_kb_measured():
    text = report.render(results(), 'f.png')
    assert row(text, 'machine busy during that window')[3] == ''
    floor = results()['floor']['rss_mb']
    assert '%.2f MiB (%.0f kB)' % (floor, floor * 1024) in text
    assert 'GiB memory' in text and 'Do not edit by hand' in text


def test_the_fleet_table_has_the_master_cpu_and_skips_fleet_sizes_not_flown():
    r = copy.deepcopy(results())
    r['ours']['fleet'].pop('100', None)  # a run that flew no 100 pairs
    r['ours']['fleet']['20']['master_cpu_percent'] = 1.84
    text = report.render(r, 'f.png')
    header = row(text, 'node')
    assert header[-2] == 'CPU master'
    ours_20 = [cells for cells in (line.strip('|').split('|') for line in text.splitlines())
               if [c.strip() for c in cells[:2]] == ['ours', '20']][0]
    assert ours_20[-2].strip() == '1.8'
    assert 'fleet of 100' not in text  # this run flew no 100 pairs: no row of n/a
    r['ours']['fleet']['100'] = dict(r['ours']['fleet']['20'], master_cpu_percent=5.5)
    assert row(report.render(r, 'f.png'), 'fleet of 100: master CPU')[1] == '5.5'


def test_the_hand_written_analysis_says_when_it_quotes_another_run():
    r = results()
    r['analysis'] = '<!-- run: %s (note) -->\nText.\n' % r['date']
    text = report.render(r, 'f.png')
    assert 'Text.' in text and 'Written from the run of' not in text and '<!-- run:' not in text
    r['date'] = '2026-12-01 10:00'
    assert 'Written from the run of %s, not from this one (2026-12-01 10:00)' % results()['date'] in \
        report.render(r, 'f.png')
