"""Issue 47 end to end, as the teacher and a student run it: ``make grade`` on a small class whose
reports are reader47's fixtures (lab/test/unit/data/reports, made by lab/test/reports/make_reports.py)
writes OUT/proposals.csv (exactly its columns, 8 rows a student), each student's report.json and the
read-only copies of its report and code; ``make rescore`` writes proposals.csv again, identically, from
the kept records; ``make check`` tells a student which of its report's answers were not found, or that
it was not read and why."""
import csv
import json
import os
import shutil
import stat
import subprocess

import pytest

from exam_lab.grader.publish import proposals
from exam_lab.grader.score.records import MEASUREMENTS, ReportRecord

HERE = os.path.dirname(os.path.realpath(__file__))
REPO = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
DATA = os.path.join(HERE, '..', 'unit', 'data', 'reports')
GOOD = os.path.join(HERE, 'submissions', 'good_student', 'exam')
#: Generous: the machine is shared, a scan is read by OCR (about 100 s under load).
WINDOW = 1800
STATES = ('proposed', 'to check', 'no answer found', 'not read')


def make(*args, timeout=WINDOW):
    done = subprocess.run(['make', '--no-print-directory'] + list(args), cwd=REPO, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, universal_newlines=True, timeout=timeout)
    assert done.returncode == 0, done.stdout[-6000:]
    return done.stdout


def writable(path):
    """The files below ``path`` that anyone may write (the copies are read-only files; their folders are
    the grader's, written again by the next make grade)."""
    found = []
    for top, dirs, files in os.walk(path):
        for name in [os.path.join(top, f) for f in files]:
            if os.lstat(name).st_mode & (stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH):
                found.append(name)
    return found


@pytest.fixture(scope='module')
def small_class(tmp_path_factory):
    """Three students graded by make grade: ann (a package, a good text report: LibreOffice's PDF with
    screenshots), bob (a package, an image-only scan), zoe (only a report, in a table, question 6
    missing)."""
    root = tmp_path_factory.mktemp('report-class')
    klass = root / 'class'
    handed = {'Ann Good_301_assignsubmission_file_': ('fr_odt.pdf', True),
              'Bob Scan_302_assignsubmission_file_': ('scan.pdf', True),
              'Zoe Report_303_assignsubmission_file_': ('en_docx_table.pdf', False)}
    for folder, (report, package) in handed.items():
        (klass / folder).mkdir(parents=True)
        shutil.copyfile(os.path.join(DATA, report), str(klass / folder / report))
        if package:
            shutil.copytree(GOOD, str(klass / folder / 'exam'), ignore=shutil.ignore_patterns('__pycache__'))
    out = root / 'out'
    shown = make('grade', 'CLASS=%s' % klass, 'OUT=%s' % out, 'JOBS=2')
    return out, shown


def students(out):
    with open(str(out / proposals.FILE), newline='') as f:
        rows = list(csv.reader(f))
    return rows


def test_make_grade_writes_the_proposals_the_reports_and_their_copies(small_class):
    out, shown = small_class
    rows = students(out)
    assert tuple(rows[0]) == ('participant', 'student', 'item', 'points', 'max', 'state', 'evidence'), rows[0]
    by_student = {}
    for row in rows[1:]:
        by_student.setdefault(row[1], []).append(dict(zip(rows[0], row)))
    assert sorted(by_student) == ['Ann Good', 'Bob Scan', 'Zoe Report'], sorted(by_student)
    for name, mine in by_student.items():
        assert [r['item'] for r in mine] == ['Q4', 'Q5', 'Q6', 'Q7', 'Q8', 'Q9', 'comments', 'quality'], (name, mine)
        assert all(r['state'] in STATES and '\n' not in r['evidence'] and r['evidence'] for r in mine), (name, mine)
        assert [r for r in mine if r['state'] in ('no answer found', 'not read') and r['points'] != ''] == [], name
        assert [r for r in mine if r['state'] == 'proposed' and r['points'] == ''] == [], name
    by_item = {name: {r['item']: r for r in mine} for name, mine in by_student.items()}
    assert by_item['Ann Good']['Q4']['state'] in ('proposed', 'to check'), by_item['Ann Good']['Q4']
    assert by_item['Zoe Report']['Q6']['state'] == 'no answer found', by_item['Zoe Report']['Q6']
    assert by_item['Zoe Report']['Q4']['state'] in ('proposed', 'to check'), by_item['Zoe Report']['Q4']
    assert 'proposals: %s' % (out / proposals.FILE) in shown, shown[-3000:]
    for name, package in (('Ann Good', True), ('Bob Scan', True), ('Zoe Report', False)):
        folder = out / name
        record = proposals.kept_report(str(folder))
        assert record.state == 'read', (name, record.why)
        assert json.loads((folder / 'report.json').read_text())['state'] == 'read'
        assert record.pages[0].source == ('ocr' if name == 'Bob Scan' else 'text'), (name, record.pages[0])
        copies = [f.copy for f in record.files]
        assert copies and all(c and (folder / c).is_file() for c in copies), (name, record.files)
        assert writable(str(folder / 'report')) == [], name
        assert (folder / 'code').is_dir() == package, name
        if package:
            assert (folder / 'code' / 'exam' / 'package.xml').is_file() or \
                any(p.name == 'package.xml' for p in (folder / 'code').rglob('package.xml')), name
            assert writable(str(folder / 'code')) == [], name


def test_make_rescore_writes_the_same_proposals_from_the_kept_reports(small_class):
    out, _ = small_class
    before = (out / proposals.FILE).read_bytes()
    reports = {n: (out / n / 'report.json').read_bytes() for n in ('Ann Good', 'Bob Scan', 'Zoe Report')}
    (out / proposals.FILE).unlink()
    make('rescore', 'OUT=%s' % out)
    assert (out / proposals.FILE).read_bytes() == before
    assert {n: (out / n / 'report.json').read_bytes() for n in reports} == reports  # never read again


def test_the_reports_time_beside_the_students(small_class):
    """Measured, not bounded: each student's grading and the part of it its report took (printed for
    the bench's notes; the bound is lab/bench/report_bench.py's)."""
    out, _ = small_class
    for name in ('Ann Good', 'Bob Scan', 'Zoe Report'):
        measured = json.loads((out / name / MEASUREMENTS).read_text())
        seconds = (measured.get('extra') or {}).get('seconds')
        report = proposals.kept_report(str(out / name)).seconds
        print('%s: graded in %s s, of which the report %.1f s' % (name, seconds, report))
        assert report > 0


@pytest.mark.parametrize('report, said', [
    ('en_docx_table.pdf', ['  Q4: found', '  Q6: no answer found']),
    ('encrypted.pdf', ['your report: not read (']),
])
def test_make_check_says_which_answers_were_not_found_or_not_read(tmp_path, report, said):
    package = tmp_path / 'exam'
    shutil.copytree(GOOD, str(package), ignore=shutil.ignore_patterns('__pycache__'))
    shutil.copyfile(os.path.join(DATA, report), str(tmp_path / report))
    shown = make('check', 'PACKAGE=%s' % package, 'REPORT=%s' % (tmp_path / report))
    lines = shown.splitlines()
    for line in said:
        assert any(l.startswith(line) for l in lines), (line, shown[-3000:])
    assert not any('points' in l for l in lines if l.startswith('  Q')), shown[-3000:]
