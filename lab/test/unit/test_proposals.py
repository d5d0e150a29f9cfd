"""OUT/proposals.csv and OUT/<student>/proposals.json, written by the desk at the end of make grade and
again by make rescore from the kept files (publish/proposals.py, issue 47 point 7)."""
import csv
import json
import os
import shutil

import pytest

from exam_lab.grader.boxed import code_quality, source
from exam_lab.grader.publish import desk, grades, proposals
from exam_lab.grader.score import records
from exam_lab.grader.score.records import MEASUREMENTS

from test_answers import DATA, english_report
from test_code_quality import package
from test_grader_kept import kept_copy


def student(out, name, report, code='every_cycle'):
    """A student graded into ``out``: real kept measurements, with the comments the inspection measures
    of a real submission's code, and the report's record as the reader keeps it."""
    folder = os.path.join(str(out), name)
    os.makedirs(folder)
    measured = dict(kept_copy('version-1'), student=name)
    pkg = package(code)
    files = source.student_code(pkg)
    lines = source.comment_ratio(files)
    measured['comments'] = {'comments': lines[0], 'code': lines[1], 'files': [os.path.relpath(p, pkg) for p in files],
                            'units': code_quality.comment_units(files, pkg), 'quality': code_quality.quality_signals(files, pkg)}
    with open(os.path.join(folder, MEASUREMENTS), 'w') as f:
        json.dump(measured, f)
    with open(os.path.join(folder, 'grade.json'), 'w') as f:
        json.dump(grades.score(measured), f)
    if report is not None:
        report = dict(report, seconds=0.5, files=[dict(f, state='read', copy=None) for f in report['files']],
                      pages=[dict(p, pictures=0) for p in report['pages']])
        with open(os.path.join(folder, 'report.json'), 'w') as f:
            json.dump(report, f)
    return grades.score(measured)


@pytest.fixture
def kept_reports(monkeypatch):
    """report.json read as the grader reads it: its ReportRecord once the reader is in, else as the
    contract's JSON (REPORT_CONTRACT.md) until it is merged."""
    if getattr(records, 'ReportRecord', None) is None:
        def read(folder):
            path = os.path.join(folder, 'report.json')
            if not os.path.isfile(path):
                return {'state': 'not read', 'why': 'no report.json kept'}
            with open(path) as f:
                return json.load(f)
        monkeypatch.setattr(proposals, 'read_report', read)


def test_the_desk_writes_eight_rows_a_student_with_the_contracts_columns(tmp_path, kept_reports):
    shutil.copy(os.path.join(DATA, 'reference-altitude.json'), str(tmp_path))
    graded = [student(tmp_path, 'alice', english_report()), student(tmp_path, 'bob', None, 'good_student')]
    lines = desk.finish(str(tmp_path), graded)
    with open(str(tmp_path / 'proposals.csv'), newline='') as f:
        rows = list(csv.reader(f))
    assert rows[0] == ['participant', 'student', 'item', 'points', 'max', 'state', 'evidence']
    assert len(rows) == 1 + 16
    by = {(r[1], r[2]): r for r in rows[1:]}
    assert [by['alice', q][3] for q in ('Q4', 'Q5', 'Q6', 'Q7', 'Q8', 'Q9')] == ['1', '2', '1', '1', '1', '1']
    assert by['alice', 'Q4'][5] == 'proposed' and by['alice', 'Q4'][0] == '101'
    assert by['alice', 'quality'][5] == 'to check' and 'service in a loop' in by['alice', 'quality'][6]
    assert by['alice', 'comments'][5] == 'to check' and by['alice', 'comments'][4] == '4'
    assert [by['bob', q][5] for q in ('Q4', 'Q9')] == ['not read', 'not read'] and by['bob', 'Q4'][3] == ''
    assert all('\n' not in r[6] for r in rows[1:])
    kept = json.loads((tmp_path / 'alice' / 'proposals.json').read_text())
    assert [p['item'] for p in kept] == ['Q4', 'Q5', 'Q6', 'Q7', 'Q8', 'Q9', 'comments', 'quality']
    assert set(kept[0]) == {'item', 'points', 'max', 'state', 'evidence', 'checks', 'page', 'passage'}
    assert kept[0]['page'] == 1 and '/mydrone' in kept[0]['passage']
    assert any('proposals.csv' in line for line in lines)


def test_rescore_writes_them_again_from_the_kept_files(tmp_path, kept_reports):
    shutil.copy(os.path.join(DATA, 'reference-altitude.json'), str(tmp_path))
    student(tmp_path, 'alice', english_report())
    rescored, _ = grades.rescore(str(tmp_path))
    desk.finish(str(tmp_path), rescored)
    first = (tmp_path / 'proposals.csv').read_text()
    (tmp_path / 'proposals.csv').unlink()
    rescored, _ = grades.rescore(str(tmp_path))
    desk.finish(str(tmp_path), rescored)
    assert (tmp_path / 'proposals.csv').read_text() == first


def test_without_the_reference_the_answers_are_to_check_and_said(tmp_path, kept_reports):
    graded = [student(tmp_path, 'alice', english_report())]
    lines = desk.finish(str(tmp_path), graded)
    rows = proposals.read(str(tmp_path / 'proposals.csv'))
    assert {r['state'] for r in rows if r['item'].startswith('Q')} == {'to check'}
    assert all('reference-altitude.json' in r['evidence'] for r in rows if r['item'].startswith('Q'))
    assert any('not compared with the drone' in line for line in lines)


def test_the_proposals_line_pastes_an_out_with_spaces(tmp_path, kept_reports):
    """The terminal's "make review OUT=..." of the proposals line runs as pasted, as the next commands do."""
    import shlex
    out = tmp_path / 'ROS Exam (groupe D)'
    out.mkdir()
    graded = [student(out, 'alice', english_report())]
    line = [l for l in desk.finish(str(out), graded) if l.startswith('proposals: ')][0]
    pasted = shlex.split(line.split('confirms them on ', 1)[1])
    assert pasted == ['make', 'review', 'OUT=%s' % out]


def test_a_cell_a_spreadsheet_would_run_is_quoted(tmp_path, kept_reports):
    shutil.copy(os.path.join(DATA, 'reference-altitude.json'), str(tmp_path))
    graded = [student(tmp_path, '=HYPERLINK', english_report())]
    desk.finish(str(tmp_path), graded)
    with open(str(tmp_path / 'proposals.csv'), newline='') as f:
        names = {r[1] for r in list(csv.reader(f))[1:]}
    assert names == {"'=HYPERLINK"}
    assert {r['student'] for r in proposals.read(str(tmp_path / 'proposals.csv'))} == {'=HYPERLINK'}


# --- make check: which answers the grader found, under the teacher's visibility setting ---------------

def test_the_check_says_which_answers_were_not_found_never_their_points():
    from exam_lab.grader.publish import student_view
    from test_answers import out, page, report
    text = 'Question 4\n%s\nDeux nœuds tournent, le drone et rosout.\nQuestion 6\n%s' % (
        out('altitude', 'rosnode_list'), out('altitude', 'rostopic_list'))
    shown = student_view.report_lines(report(page(text, number=2, unsure=['rosout'], confidence=80.0)), 'points')
    assert shown[1:] == ['  Q4: found', '  Q5: no answer found (start it with "5." or "Question 5" on a line of its own)',
                         '  Q6: found'] + ['  Q%d: no answer found (start it with "%d." or "Question %d" on a line of '
                                           'its own)' % (n, n, n) for n in (7, 8, 9)]
    evidence = student_view.report_lines(report(page(text, number=2, unsure=['rosout'], confidence=80.0)), 'evidence')
    assert evidence[1] == '  Q4: found (p.2); read by OCR with low confidence: rosout'
    assert not any('point' in line for line in shown + evidence)


def test_the_check_says_why_a_report_was_not_read():
    from exam_lab.grader.publish import student_view
    (line,) = student_view.report_lines({'state': 'not read', 'why': 'encrypted PDF'}, 'points')
    assert 'not read (encrypted PDF)' in line
