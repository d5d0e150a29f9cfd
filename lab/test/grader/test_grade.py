"""The grader end to end: our exam node gets full marks on both sheets; each flawed student package
loses exactly the points the rubric takes for its flaw. One class run (two students side by side, one
of them uploaded as a zip) and one submission run; about four minutes on two cores.
"""
import csv
import json
import os
import shutil
import zipfile

import pytest

from exam_lab.grader import runner
from exam_lab.grader.sheets import ITEMS

HERE = os.path.dirname(os.path.abspath(__file__))
SUBMISSIONS = os.path.join(HERE, 'submissions')
OUR_EXAM = os.path.realpath(os.path.join(HERE, '..', '..', '..', 'exam'))
FULL = {item: points for item, (points, _) in ITEMS.items()}

#: Points each package must get where it differs from full marks.
EXPECTED = {
    'good_student': {},
    'every_cycle': {'Q13': 2.0},                       # service called every cycle: half of 13
    'no_kelvin': {'Q11': 2.5},                         # formula in degC: the values' 1.5 of 11
    'no_delay': {'Q14b': 0.0},                         # WARNING at once: no delay at all
    'hard_threshold': {'Q14a': 0.0},                   # the launch file's threshold is ignored
    'crash_at_start': {'runs': 1.0, 'Q10': 0.0, 'Q11': 0.0, 'Q13': 0.0, 'Q14a': 0.0, 'Q14b': 0.0},
    'wrong_topic': {'Q11': 2.5},                       # /profondeur instead of /depth: the publisher's 1.5
    'one_subscriber': {'Q10': 1.0, 'Q11': 2.5},        # no /pressure_remote: one subscriber, values wrong
    'ours': {},
}
SHEETS = {'wrong_topic': 'depth', 'one_subscriber': 'depth'}


@pytest.fixture(scope='module')
def graded(tmp_path_factory):
    """Grade the whole class once: the fixture packages, ours (its sheet detected: altitude)."""
    root = tmp_path_factory.mktemp('grader')
    klass = root / 'class'
    for name in EXPECTED:
        folder = klass / ('%s_%d_assignsubmission_file_' % (name, len(name)))
        folder.mkdir(parents=True)
        source = OUR_EXAM if name == 'ours' else os.path.join(SUBMISSIONS, name, 'exam')
        if name == 'good_student':  # uploaded as a zip, next to the report
            (folder / 'report.pdf').write_bytes(b'%PDF-1.4\n')
            with zipfile.ZipFile(str(folder / 'exam.zip'), 'w') as zf:
                for dirpath, _, filenames in os.walk(source):
                    for filename in filenames:
                        full = os.path.join(dirpath, filename)
                        zf.write(full, os.path.join('exam', os.path.relpath(full, source)))
        else:
            shutil.copytree(source, str(folder / 'exam'), symlinks=True,
                            ignore=shutil.ignore_patterns('__pycache__', '.grader-*'))
    out = root / 'out'
    records = runner.grade_class(str(klass), str(out), jobs=2)
    return out, {r['student']: r for r in records}


@pytest.mark.parametrize('name', sorted(EXPECTED))
def test_each_package_gets_exactly_its_points(graded, name):
    _, records = graded
    record = records[name]
    got = {i['id']: i['points'] for i in record['items']}
    wanted = dict(FULL, **EXPECTED[name])
    evidence = '\n'.join('%s %s/%s: %s' % (i['id'], i['points'], i['max'], i['evidence']) for i in record['items'])
    assert got == wanted, evidence
    assert record['sheet'] == SHEETS.get(name, 'altitude')
    assert record['max'] == 17.0
    for entry in record['items']:
        if entry['points'] < entry['max']:
            assert entry['evidence'], 'every point lost says why'


def test_class_outputs(graded):
    out, records = graded
    with open(os.path.join(str(out), 'grades.csv')) as f:
        rows = list(csv.DictReader(f))
    assert sorted(r['student'] for r in rows) == sorted(EXPECTED)
    for row in rows:
        assert float(row['total']) == records[row['student']]['total']
        with open(os.path.join(str(out), row['student'], 'grade.json')) as f:
            record = json.load(f)
        assert set(record) >= {'sheet', 'total', 'max', 'items', 'for_the_teacher'}
        assert [i['id'] for i in record['items']] == list(ITEMS)
        assert os.path.isfile(os.path.join(str(out), row['student'], 'grade.md'))
    assert any('made executable' in hint for hint in records['no_kelvin']['for_the_teacher'])
    assert any('KeyError' in hint for hint in records['crash_at_start']['for_the_teacher'])


def test_our_node_on_the_depth_sheet(tmp_path):
    record = runner.grade_submission(OUR_EXAM, str(tmp_path / 'depth'), sheet='depth')
    got = {i['id']: i['points'] for i in record['items']}
    assert got == FULL, '\n'.join(i['evidence'] for i in record['items'])
