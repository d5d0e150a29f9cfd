"""The hand points proposed: ``OUT/proposals.csv`` and each student's ``OUT/<student>/proposals.json``.
No rospy here.

The 13 points the machine does not score by running (the report's questions 4-9, the comments, the
code quality: :data:`~exam_lab.grader.score.sheets.HAND_ITEMS`) are proposed from what a run kept:
each student's ``report.json`` (the report as its box read it), the ``comments`` of its
``measurements.json`` (what the inspection's box measured of the code) and the class's
``reference-<sheet>.json`` (what the sheet's drone printed, :mod:`exam_lab.grader.host.reference`).
:mod:`exam_lab.grader.score.answers` decides; here they are read and written, by ``make grade`` and
again by ``make rescore`` (from the kept files only). A proposal is never a point: the review page
(review.json, hand.csv) writes a point only once the teacher confirmed it.

proposals.csv has exactly the columns :data:`COLUMNS`, 8 rows a student (:data:`ITEMS` order), each
cell safe in a spreadsheet (:mod:`~exam_lab.grader.publish.cells`), the evidence on one line.
"""
import csv
import io
import json
import os

from exam_lab.grader import contract
from exam_lab.grader.publish import cells, moodle
from exam_lab.grader.score import answers, code_items, kept, records, safe_text
from exam_lab.grader.score.records import ReportRecord
from exam_lab.grader.score.reference import ReferenceRecord, facts, reference_file
from exam_lab.grader.score.sheets import HAND_ITEMS

FILE = 'proposals.csv'
STUDENT_FILE = 'proposals.json'
COLUMNS = ('participant', 'student', 'item', 'points', 'max', 'state', 'evidence')
ITEMS = tuple(HAND_ITEMS)
#: Longest evidence in the CSV (the whole is in proposals.json's checks).
MAX_EVIDENCE = 1500


def read_reference(out, sheet):
    """``(facts, why)``: the class's reference outputs for ``sheet`` (kept in OUT, read through the
    contract) as :func:`~exam_lab.grader.score.reference.facts`, or ``(None, why not)``."""
    path = os.path.join(out, reference_file(sheet))
    if not contract.exists(path):
        return None, 'no %s in OUT (the drone was not run for the reference)' % reference_file(sheet)
    try:
        return facts(contract.read_record(path, ReferenceRecord)), None
    except records.RecordError as err:
        return None, '%s is not a reference record: %s' % (reference_file(sheet), err)


def kept_report(folder):
    """The :class:`~exam_lab.grader.score.records.ReportRecord` kept in a student's ``folder`` of OUT,
    read through the contract (capped, checked, no link followed, never waited on): what make rescore,
    the proposals and the review page read, never the box again. A file missing or refused is a
    report "not read" saying so (the student's report is then the teacher's to read)."""
    path = os.path.join(folder, ReportRecord.FILE)
    if not contract.exists(path):
        return ReportRecord.not_read('no report.json kept (graded before reports were read: make grade again)')
    try:
        return contract.read_record(path, ReportRecord)
    except records.RecordError as err:
        return ReportRecord.not_read('the kept report.json is not a record of the grader: %s' % err)


def read_report(folder):
    """The report the run kept for one student (:func:`kept_report`'s value)."""
    return kept_report(folder).value


def report_text(folder):
    """The text of every page of the report the run kept for one student ('' when none was read)."""
    return '\n'.join(page.get('text') or '' for page in read_report(folder).get('pages') or ())


def read_comments(folder):
    """The code's ``comments`` as the inspection measured them (measurements.json's, read through the
    contract), or None."""
    path = os.path.join(folder, kept.MeasurementsRecord.FILE)
    if not contract.exists(path):
        return None
    try:
        return contract.read_record(path, kept.MeasurementsRecord).comments
    except records.RecordError:
        return None


def student_proposals(folder, sheet, reference):
    """The 8 proposals of the student graded in ``folder`` (``reference``: :func:`read_reference`'s pair)."""
    ref, why = reference
    made = code_items.student_proposals(read_report(folder), ref, read_comments(folder))
    if ref is None:
        made = [dict(p, evidence='%s (%s)' % (p['evidence'], why)) if p['item'] in answers.QUESTIONS
                and p['state'] == answers.TO_CHECK else p for p in made]
    return safe_text.cleaned([dict(p, evidence=safe_text.one_line(p['evidence'])) for p in made])


def write(out, grade_records, single=False):
    """Write proposals.csv and each student's proposals.json for ``grade_records`` graded into ``out``;
    return lines for the terminal. One student's failure (a bug) is a line, and its rows say so."""
    rows, lines, references = [], [], {}
    states = {}
    for record in grade_records:
        sheet = record.get('sheet') or 'altitude'
        if sheet not in references:
            references[sheet] = read_reference(out, sheet)
        try:
            folder = out if single else contract.student_folder(out, record['student'])
            made = student_proposals(folder, sheet, references[sheet])
            contract.write_text(os.path.join(folder, STUDENT_FILE),
                                json.dumps(made, indent=1, sort_keys=True, ensure_ascii=False))
        except Exception as err:  # one student's bug: its rows say so, the class goes on
            why = safe_text.one_line('%s: %s' % (type(err).__name__, err))[:300]
            lines.append('%s: proposals not made (a grader bug, please report): %s' % (record['student'], why))
            made = [answers.proposal(item, answers.TO_CHECK, None, 'no proposal: %s' % why) for item in ITEMS]
        for p in made:
            states[p['state']] = states.get(p['state'], 0) + 1
            rows.append([record.get('participant'), record['student'], p['item'],
                         '' if p['points'] is None else _num(p['points']), _num(p['max']), p['state'],
                         p['evidence'][:MAX_EVIDENCE]])
    table = io.StringIO(newline='')
    writer = csv.writer(table)
    writer.writerow(COLUMNS)
    for row in rows:
        writer.writerow(cells.row(row))
    contract.write_text(os.path.join(out, FILE), table.getvalue())
    for sheet, (ref, why) in sorted(references.items()):
        if ref is None:
            lines.append('proposals of sheet %s: the answers were not compared with the drone: %s' % (sheet, why))
    lines.append('proposals: %s (%s): the teacher confirms them on make review OUT=%s' % (
        os.path.join(out, FILE), ', '.join('%d %s' % (n, s) for s, n in sorted(states.items())) or 'none',
        moodle.shell_quoted(out)))
    return lines


def _num(value):
    return ('%.2f' % value).rstrip('0').rstrip('.')


def read(path):
    """proposals.csv's rows as dicts (each cell read back as written): what make check and a test read."""
    with open(path, newline='') as f:
        return rows(f.read())


def rows(text):
    """The rows of proposals.csv's ``text`` as dicts, each cell read back as written (the review page
    reads the file's bytes itself, never through a link)."""
    return [{key: cells.read_cell(value) if isinstance(value, str) else value for key, value in row.items()}
            for row in csv.DictReader(io.StringIO(text, newline=''))]
