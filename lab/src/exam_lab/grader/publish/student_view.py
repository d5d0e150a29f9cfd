"""What a student's own check (``make check``, lab/scripts/check.py) prints of a grade record, and what
a student's feedback page shows (:mod:`~exam_lab.grader.publish.feedback`): what the teacher chose to
show, in one setting (lab/check_visibility.ini, ``[check] show``):

- ``points``: each item and its points, the total and the status;
- ``evidence``: also each item's evidence (its first line: the measured numbers) and the status's reason.

Never shown, whatever the setting, nor in any other output a student reads (the Moodle feedback, the
Gradescope results: :func:`item_words`): the threshold run. For question 14a the grader runs the node a
second time with its launch file's threshold lowered to a value drawn at grading time, which the
student is not told (the record's ``threshold_run``); when there is one, Q14a's evidence (which names
the value and what was flown) gives way to a sentence that names none, the ``runs`` item's words about
that run are left out, and so is a status reason about it; and any number written as that value is
replaced (:func:`scrub`), whatever item's words it is in. The teacher's notes (``for_the_teacher``)
are the teacher's. No rospy here.
"""
import configparser
import re

from exam_lab.grader.publish.report import NOT_SCORED, _points
from exam_lab.grader.score import answers

#: The values of the setting.
SHOW = ('points', 'evidence')

#: Q14a when the threshold run took place, by its points (full, part, none): no value, no flight.
Q14A_WORDS = ('the node obeyed its launch file\'s threshold parameter: run again with the parameter changed '
              '(to a value not shown), it warned',
              'part of the point: the code reads the launch file\'s threshold parameter, but the node was not '
              'seen obeying it when the grader changed it (to a value not shown)',
              'the node was not seen obeying its launch file\'s threshold parameter when the grader changed it '
              '(to a value not shown)')
#: How the grader's words name the threshold run (rubric: '<tag> run: ...', 'in the <tag> run ...').
THRESHOLD_RUN = 'threshold run'
#: What a number that is the hidden value is written as.
NOT_SHOWN = '(a value not shown)'


def hidden(record):
    """The values a student must never read in ``record``: the threshold run's (``[]`` when none)."""
    run = record.get('threshold_run') or {}
    return [run['value']] if run.get('value') is not None else []


def scrub(text, values):
    """``text`` with every way the grader writes one of ``values`` (``%g``, one or two decimals, the
    integer) replaced by :data:`NOT_SHOWN`."""
    for value in values:
        forms = {'%g' % value, '%.1f' % value, '%.2f' % value, '%.3f' % value, repr(float(value))}
        if float(value).is_integer():
            forms.add('%d' % value)
        for form in sorted(forms, key=len, reverse=True):
            text = re.sub(r'(?<![\d.])%s(?![\d])' % re.escape(form), NOT_SHOWN, text)
    return text


def item_words(entry, record, first_line=True):
    """An item's evidence as any output a student reads gives it (the check, Moodle's feedback,
    Gradescope's results): without the threshold run (:func:`student_evidence`) and its value."""
    threshold_run = bool(hidden(record))
    if first_line or (threshold_run and entry['id'] in ('Q14a', 'runs')):
        words = student_evidence(entry, threshold_run)  # a launch's log may print the value: first line only
    else:
        words = entry['evidence']
    return scrub(words, hidden(record))


def read_setting(path):
    """The ``show`` value of the setting file ``path``; ValueError naming the file and the value when it
    is missing or not one of :data:`SHOW`."""
    parser = configparser.ConfigParser()
    try:
        with open(path) as f:
            parser.read_file(f)
    except (OSError, configparser.Error) as err:
        raise ValueError('cannot read the check\'s setting %s: %s' % (path, err))
    show = parser.get('check', 'show', fallback=None)
    if show not in SHOW:
        raise ValueError('%s: [check] show = %s; expected one of %s' % (path, show, ', '.join(SHOW)))
    return show


def _runs_words(evidence):
    """The ``runs`` item's first line without the threshold run's problems: ``builds (2 s); but: main
    run: ...; threshold run: ...``, the runs in order, so everything from the first problem of the
    threshold run on is its own (a probe's log tail included)."""
    head, _, problems = evidence.partition('; but: ')
    parts = problems.split('; ') if problems else []
    cut = [i for i, part in enumerate(parts) if part.startswith(THRESHOLD_RUN)]
    if not cut:
        return evidence
    kept = parts[:cut[0]] + ['a problem in the threshold run (its details are the teacher\'s)']
    return '%s; but: %s' % (head, '; '.join(kept))


def student_evidence(entry, threshold_run):
    """The first line of an item's evidence as the student may read it."""
    first = entry['evidence'].split('\n', 1)[0]
    if not threshold_run:
        return first
    if entry['id'] == 'Q14a':
        if entry['points'] >= entry['max']:
            return Q14A_WORDS[0]
        return Q14A_WORDS[1] if entry['points'] > 0 else Q14A_WORDS[2]
    if entry['id'] == 'runs':
        return _runs_words(first)
    return first


def student_reason(record, show, threshold_run):
    """The status's reason as the student may read it: only with ``evidence``, and never one about the
    threshold run; '' otherwise."""
    reason = record.get('status_reason') or ''
    if show != 'evidence' or (threshold_run and THRESHOLD_RUN in reason):
        return ''
    return scrub(reason, hidden(record))


def lines(record, show, threshold_run=None):
    """The lines to print for ``record`` with the setting ``show``.

    :param threshold_run: True when the grader ran the threshold run; by default, when the record
        has one (:func:`hidden`).
    """
    threshold_run = bool(hidden(record)) if threshold_run is None else threshold_run
    if show not in SHOW:
        raise ValueError('show = %r; expected one of %s' % (show, ', '.join(SHOW)))
    rows = [['item', 'points'] + (['evidence'] if show == 'evidence' else [])]
    for entry in record['items']:
        row = [entry['id'], '%s / %s' % (_points(entry['points']), _points(entry['max']))]
        if show == 'evidence':
            row.append(scrub(student_evidence(entry, threshold_run), hidden(record)))
        rows.append(row)
    rows.append(['total', '%s / %s' % (_points(record['total']), _points(record['max']))] +
                ([''] if show == 'evidence' else []))
    widths = [max(len(r[c]) for r in rows) for c in range(len(rows[0]) - 1)]
    out = ['  '.join([cell.ljust(w) for cell, w in zip(r, widths)] + [r[-1]]).rstrip() for r in rows]
    status = 'status: %s' % record.get('status', '')
    reason = student_reason(record, show, threshold_run)
    if reason:
        status += ' - %s' % reason
    out += ['', status, 'not scored by the machine (the teacher grades them): %s' % NOT_SCORED]
    return out


def report_lines(report, show):
    """What the check says of the student's report (a ReportRecord's value, or None: none was read):
    which of questions 4-9 have an answer the grader found by its heading, which have none ("no
    answer found": the teacher looks for it by hand), or that the report was not read and why. Never
    the points proposed (the teacher's to confirm). With ``evidence``, also the page each answer was
    found on and the words the OCR was unsure of."""
    if show not in SHOW:
        raise ValueError('show = %r; expected one of %s' % (show, ', '.join(SHOW)))
    if report is None or report.get('state') != 'read':
        why = (report or {}).get('why') or 'no report was read'
        return ['your report: not read (%s): the teacher reads it by hand; a PDF with its text (exported from '
                'LibreOffice or Word) is read by the grader' % why]
    files = report.get('files') or []
    found = answers.find_answers(report.get('pages') or [], files)
    names = ', '.join(f.get('name', '?') for f in files if f.get('state', 'read') == 'read') or 'report'
    out = ['your report (%s, %d page(s) read): the grader looks for each answer by its question\'s number'
           % (names, len(report.get('pages') or []))]
    for item in answers.QUESTIONS:
        passage = found[item]
        if passage is None:
            out.append('  %s: no answer found (start it with "%s." or "Question %s" on a line of its own)'
                       % (item, item[1:], item[1:]))
            continue
        line = '  %s: found' % item
        if show == 'evidence':
            line += ' (%s%s)' % (passage['label'], ', in a table' if passage['how'] == 'table' else '')
            if passage['unsure']:
                line += '; read by OCR with low confidence: %s' % ', '.join(passage['unsure'][:8])
        out.append(line)
    return out
