"""The grader's outputs: grade.json, grade.md (for the teacher and the student), grades.csv, and the
table printed on the terminal. No rospy here.

A record's text is student-derived (evidence, log lines, names): :func:`grade_record` makes it a
:class:`~exam_lab.grader.score.kept.GradeRecord`, which cleans it (:mod:`exam_lab.grader.score.safe_text`)
where it is made; grade.json is written and read back through that type too, so grade.md is made of
clean text as it is. A line for the terminal or a cell of grades.csv is put on one line
(:func:`~exam_lab.grader.score.safe_text.one_line`), which cleans it on the way for any caller.
"""
import collections
import csv
import io
import os

from exam_lab.grader import contract
from exam_lab.grader.publish import cells
from exam_lab.grader.score import kept, safe_text
from exam_lab.grader.score.sheets import ITEMS, SHEETS, sheet_named_in

#: What no machine scores, with the rubric's points (sheet 000's notes).
NOT_SCORED = ('comments (4 points), code quality (2 points), and the report: questions 1-9 and the '
              'explanations of every answer')


def _points(x):
    return ('%.1f' % x).rstrip('0').rstrip('.')


def points_text(x):
    """Points as the teacher reads them (``15.5``, ``17``); ``-`` for none."""
    return '-' if x is None else _points(x)


def grade_record(student, sheet, items, for_the_teacher, extra=None, status=('graded', '')):
    """The content of grade.json (a :class:`~exam_lab.grader.score.kept.GradeRecord`'s value: checked,
    its text made safe); ``status`` is ``(status, reason)`` (see :func:`rubric.status`)."""
    record = {'version': kept.VERSION, 'student': student, 'sheet': sheet, 'total': sum(i['points'] for i in items),
              'max': sum(i['max'] for i in items), 'items': items, 'for_the_teacher': for_the_teacher,
              'status': status[0], 'status_reason': status[1]}
    record.update(extra or {})
    return kept.GradeRecord.make(record).value


def _status_line(record):
    status = record.get('status', 'graded')
    reason = record.get('status_reason', '')
    return '**Status: %s**%s' % (status, ' - %s' % reason.replace('\n', ' ') if reason else '')


def markdown(record):
    """grade.md: the score table, each lost point's reason, the hints for the teacher, of a grade
    record as :func:`grade_record` made it (its text clean)."""
    sheet = SHEETS.get(record['sheet'])
    title = sheet and 'sheet %s (%s, %s)' % (sheet.seed, sheet.name, sheet.drone_pkg) or 'no sheet'
    if record.get('status') == 'not graded':
        how = 'Not graded: the package could not be run, so no point below was measured. %s.' % (
            'Not scored by the machine either: %s' % NOT_SCORED)
    else:
        how = 'Graded by running the package: %s. Not scored by the machine: %s.' % (title, NOT_SCORED)
    lines = ['# %s: %s / %s' % (record['student'], _points(record['total']), _points(record['max'])),
             '',
             _status_line(record),
             '']
    if record.get('doubts'):
        lines += ['**Look at:** %s' % '; '.join(d.replace('\n', ' ') for d in record['doubts']), '']
    lines += [how,
              '',
              '| item | what is checked | points | evidence |',
              '|---|---|---|---|']
    for entry in record['items']:
        what = ITEMS[entry['id']][1]
        evidence = entry['evidence'].split('\n', 1)[0].replace('|', '\\|')
        lines.append('| %s | %s | %s / %s | %s |' % (entry['id'], what, _points(entry['points']),
                                                     _points(entry['max']), evidence))
    lines.append('| **total** | | **%s / %s** | |' % (_points(record['total']), _points(record['max'])))
    details = [e for e in record['items'] if '\n' in e['evidence']]
    for entry in details:
        lines += ['', '### %s: details' % entry['id'], '', '```', entry['evidence'].split('\n', 1)[1], '```']
    made = record.get('provenance')
    if made:
        lines += ['', '%s by the grader %s, rubric %s, on %s, %s.' % (
            'Rescored' if made.get('how') == 'rescore' else 'Graded', made.get('grader'), made.get('rubric'),
            made.get('machine'), made.get('date'))]
        previous = record.get('previous')
        if previous and previous.get('total') is not None and previous.get('total') != record['total']:
            lines[-1] += ' Before: %s / %s (%s).' % (_points(previous['total']), _points(record['max']),
                                                   previous.get('status'))
    lines += ['', '## For the teacher', '']
    lines += ['- %s' % hint.replace('\n', ' ') for hint in record['for_the_teacher']]
    return '\n'.join(lines) + '\n'


def write_grade(out_dir, record):
    """Write ``grade.json`` and ``grade.md`` into ``out_dir``; return the grade as written (the value
    of its :class:`~exam_lab.grader.score.kept.GradeRecord`: checked, read-only)."""
    record = kept.GradeRecord.make(record)
    contract.write_record(os.path.join(out_dir, kept.GradeRecord.FILE), record)
    contract.write_text(os.path.join(out_dir, 'grade.md'), markdown(record.value))
    return record.value


def write_csv(path, records):
    """grades.csv: one row per student (its Moodle participant number beside the name, the key that
    stays when names clash), each item's points, the total; every cell one no spreadsheet runs
    (:mod:`~exam_lab.grader.publish.cells`)."""
    text = io.StringIO(newline='')
    writer = csv.writer(text)
    writer.writerow(['student', 'participant', 'sheet', 'status'] + list(ITEMS) + ['total', 'max'])
    for record in records:
        points = {e['id']: e['points'] for e in record['items']}
        writer.writerow(cells.row([safe_text.one_line(record['student']), record.get('participant'),
                                   record['sheet'], safe_text.one_line(record.get('status', 'graded'))] +
                                  [_points(points.get(i, 0)) for i in ITEMS] +
                                  [_points(record['total']), _points(record['max'])]))
    contract.write_text(path, text.getvalue())


def table(records):
    """The score table printed on the terminal: one row per student (one row for one submission)."""
    header = ['student', 'sheet'] + list(ITEMS) + ['total', 'status']
    rows = [header]
    for record in records:
        points = {e['id']: e['points'] for e in record['items']}
        rows.append([safe_text.one_line(record['student']), record['sheet'] or '-'] +
                    [_points(points.get(i, 0)) for i in ITEMS] +
                    ['%s/%s' % (_points(record['total']), _points(record['max'])),
                     safe_text.one_line(record.get('status', ''))])
    widths = [max(len(str(r[c])) for r in rows) for c in range(len(header))]
    return '\n'.join('  '.join(str(cell).ljust(w) for cell, w in zip(r, widths)).rstrip() for r in rows)


def doubts_beyond_reason(record):
    """The record's doubts that its status reason does not already say (a doubt is often the reason
    itself: several uploads, a launch file refused), so that no line says one thing twice."""
    reason = record.get('status_reason') or ''
    return [d for d in record.get('doubts') or [] if d not in reason and reason not in d or not reason]


def needing_the_teacher(records):
    """Lines for the terminal: each student whose grade the teacher must look at, and why (all but
    'graded' and 'graded with fixes', and any grade with a doubt: refused calls, a launch file roslaunch
    refuses, several uploads...), each reason once."""
    return [safe_text.one_line('%s: %s%s%s' % (r['student'], r.get('status'),
                                                ' - %s' % r['status_reason'] if r.get('status_reason') else '',
                                                ''.join('; %s' % d for d in doubts_beyond_reason(r))))
            for r in records if r.get('status') not in ('graded', 'graded with fixes') or r.get('doubts')]


def ran_nothing(record):
    """Whether nothing of the student's package ran (not graded: refused, no package, a report only):
    its sheet was not detected, its points measure nothing of the machine's statistics."""
    return record.get('status') == 'not graded'


def with_class_sheet(records, report_text=lambda record: ''):
    """``records``, each one that ran nothing (:func:`ran_nothing`: its sheet is the runner's default,
    not detected) given the sheet its report is about (``report_text(record)``, its pages' text, naming
    one sheet's ROS names: :func:`~exam_lab.grader.score.sheets.sheet_named_in`), else the class's sheet:
    the one most of the others were detected on (when any ran), so that hand.csv, the page, the
    proposals and the worksheet show the sheet her report answers; how, in her notes for the teacher."""
    counts = collections.Counter(r['sheet'] for r in records if not ran_nothing(r) and r.get('sheet'))
    common = counts.most_common(1)[0][0] if counts else None
    sheeted = []
    for r in records:
        named, words = sheet_named_in(report_text(r)) if ran_nothing(r) else (None, '')
        sheet = named or common
        if not ran_nothing(r) or sheet is None or (sheet == r.get('sheet') and not named):
            sheeted.append(r)
            continue
        how = 'sheet %s: its report is about it (%s)' % (sheet, words) if named else \
            'sheet %s: the class\'s, most of its packages ran on it (its report is about no sheet: %s)' % (sheet, words)
        sheeted.append(dict(r, sheet=sheet, for_the_teacher=list(r.get('for_the_teacher') or []) + [how]))
    return sheeted


def evidence_lines(record):
    """Each item with points lost, and why (printed under the table for one submission)."""
    return [safe_text.one_line('%s %s/%s: %s' % (e['id'], _points(e['points']), _points(e['max']),
                                                 e['evidence'].split('\n', 1)[0]))
            for e in record['items'] if e['points'] < e['max']]
