"""The teacher's desk: what a class run leaves besides the grades. No rospy here.

After grading, :func:`finish` writes, in ``OUT``: each student's Gradescope ``results.json`` and
flight plot, the hand points proposed (``proposals.csv``, :mod:`exam_lab.grader.publish.proposals`),
the similarity check across the class, hand.csv (the teacher's points), the Moodle worksheet
with the whole grades (``moodle-worksheet.csv``, when a worksheet is given or kept: :func:`worksheet_lines`),
each released student's feedback page in ``moodle-feedback.zip`` (:mod:`exam_lab.grader.publish.feedback`)
and ``index.html`` (:mod:`exam_lab.grader.publish.page`).

The desk survives any one student: each student's results.json, flight plot and page section are
made apart, and one that fails (a bug, a probe file no plot can be drawn from) is a note in that
student's section, on the page's top and on the terminal; the rest is written. The grades are
already written by then (grade.json, grades.csv): nothing here may lose them.
"""
import html
import importlib.util
import json
import os

from exam_lab.grader import contract
from exam_lab.grader.publish import feedback, flightplot, gradescope, hand, moodle, page, proposals, report
from exam_lab.grader.score import kept, safe_text
from exam_lab.grader.score.records import RecordError, SimilarityRecord


def _grade_md(record):
    """grade.md's text as the page shows it (its title left out: the section has its own), made from
    the grade record the desk was given, never from the file read back."""
    return '\n'.join(l for l in report.markdown(record).splitlines() if not l.startswith('# '))


def _failure(err):
    """One line for the teacher: what went wrong, capped (a message may quote a student's bytes)."""
    why = safe_text.one_line('%s: %s' % (type(err).__name__, err))
    return why if len(why) <= 300 else why[:297] + '...'


def _grade_records(records):
    """``(records, refused)``: each grade read through its type (a
    :class:`~exam_lab.grader.score.kept.GradeRecord`: checked, its text made safe; what grade_record
    and a rescore made is one already, and the outputs take it as it is, escaping only for their own
    format). One that is not (a grader's bug) is shown all the same, its text cleaned here, and
    ``refused`` (by the record's id) says why, for its section."""
    made, refused = [], {}
    for record in records:
        try:
            made.append(kept.GradeRecord.make(record).value)
        except RecordError as err:
            made.append(safe_text.cleaned(record))
            refused[id(made[-1])] = ['its grade is not a grade record (a grader bug, please report): %s' % _failure(err)]
    return made, refused


def similarity_failed(why):
    """The :class:`~exam_lab.grader.score.records.SimilarityRecord` of a check that could not run or
    cannot be read: ``why``, its end kept when longer than the record holds (a traceback's last words)."""
    limit = SimilarityRecord.SCHEMA['error'].schema.limit
    return SimilarityRecord.make({'error': why if len(why) <= limit else '...' + why[3 - limit:], 'notes': []})


def read_similarity(out):
    """The class's similarity check as its run kept it (``out/similarity.json``, read as its
    :class:`~exam_lab.grader.score.records.SimilarityRecord`: capped, checked, its text clean), for a
    desk made again (``make rescore``); None when there is none. A file that is not that record (cut
    short, edited) is the record of why: the page says so where its pairs would be."""
    path = os.path.join(out, SimilarityRecord.FILE)
    if not contract.exists(path):
        return None
    try:
        return contract.read_record(path, SimilarityRecord)
    except RecordError as err:
        return similarity_failed('the run\'s %s cannot be read (make grade checks the class again): %s'
                                 % (SimilarityRecord.FILE, err))


def _title(out, title):
    """The class's name for the page, one line: the one given (the class's file name, the teacher's
    choice: :func:`moodle.class_name`) kept in ``out/page.json`` for a page made again, else the one
    kept there (the desk's own small file, read up to a few KB; one of another shape is no name), else
    the output folder's name."""
    named = os.path.join(out, 'page.json')
    if title:
        contract.write_text(named, json.dumps({'title': title}))
    elif contract.exists(named):
        try:
            kept_title = json.loads(contract.read_text(named, 8192)).get('title')
        except (ValueError, AttributeError):  # ContractError is a ValueError: a link, a FIFO, too long
            kept_title = None
        title = kept_title if isinstance(kept_title, str) else None
    return safe_text.one_line(title or os.path.basename(out))


def _student(out, record, single):
    """Write one student's results.json and flight plot; return its page entry, whose ``problems``
    say what could not be made."""
    folder = out if single else contract.student_folder(out, record['student'])
    relative = '.' if single else os.path.relpath(folder, out)
    entry = {'plot': None, 'grade_md': '', 'folder': relative, 'documents': record.get('documents'),
             'problems': []}
    try:
        gradescope.write(folder, record)
    except Exception as err:
        entry['problems'].append('results.json (Gradescope) not written: %s' % _failure(err))
    try:
        if flightplot.draw(flightplot.load_runs(folder), os.path.join(folder, 'flight.png'),
                           record['student']):
            entry['plot'] = os.path.join(relative, 'flight.png')
    except Exception as err:
        entry['problems'].append('flight plot not drawn: %s' % _failure(err))
        entry['plot_failed'] = True
    try:
        entry['grade_md'] = _grade_md(record)
    except Exception as err:  # a bug on one record's text: the page says so and goes on
        entry['problems'].append('grade.md not shown: %s' % _failure(err))
    return entry


def with_sheets(out, records, single=False):
    """``records`` as :func:`report.with_class_sheet` gives them, the sheet of a student whose package
    ran nothing read from the report kept in her folder of ``out``."""
    def report_text(record):
        try:
            return proposals.report_text(out if single else contract.student_folder(out, record['student']))
        except contract.ContractError:  # no folder of hers to read: the class's sheet
            return ''
    return report.with_class_sheet(records, report_text)


def finish(out, records, single=False, similar=None, worksheet=None, title=None, show=None):
    """Write the desk's files for ``records`` graded into ``out``; return lines for the terminal.

    :param single: one submission (its results are in ``out`` itself, not ``out/<student>``).
    :param similar: the similarity check's record (a :class:`~exam_lab.grader.score.records.SimilarityRecord`:
        :func:`exam_lab.grader.class_run.class_similarity`, :func:`read_similarity`) or None; a plain
        dict is refused (TypeError): its text would reach the page uncleaned.
    :param worksheet: the Moodle worksheet the teacher downloaded, or None (the one kept in OUT, if
        any: :func:`worksheet_lines`).
    :param title: the class's name (:func:`moodle.class_name`); the output folder's name when None.
    :param show: what the students' feedback pages show (:func:`feedback.write`); None: lab/check_visibility.ini.
    """
    if similar is not None and not isinstance(similar, SimilarityRecord):
        raise TypeError('the similarity check is given as its record (records.SimilarityRecord), not a %s'
                        % type(similar).__name__)
    lines, notes, entries = [], [], {}
    records, refused = _grade_records(records)
    sheeted = with_sheets(out, records, single)
    if not single and any(a is not b for a, b in zip(records, sheeted)) and \
            os.path.isfile(os.path.join(out, 'grades.csv')):
        report.write_csv(os.path.join(out, 'grades.csv'), sheeted)
    records = sheeted
    for record in records:
        entry = entries[record['student']] = _student(out, record, single)
        entry['problems'][:0] = refused.get(id(record), [])
        lines += ['%s: %s' % (record['student'], problem) for problem in entry['problems']]
    # One participant graded twice (two archives, two folders) is that participant's matter: its newest
    # grade goes to the worksheet and the feedback zip, said here; everyone else's as always.
    newest, twice = hand.newest(records)
    lines += twice
    try:
        added = hand.write(os.path.join(out, hand.FILE), records)
        lines += hand_lines(out, records, added)
    except (hand.HandError, OSError) as err:  # the teacher's file as it is: never overwritten blindly
        lines.append('hand.csv NOT written: %s' % err)
    try:
        lines += proposals.write(out, records, single)
    except OSError as err:
        lines.append('proposals.csv NOT written: %s' % err)
    try:
        lines += worksheet_lines(out, records, worksheet)
    except (hand.HandError, moodle.WorksheetError, OSError) as err:
        lines.append('worksheet: %s NOT written: %s' % (moodle.UPLOAD, err))
    except Exception as err:  # a bug on one record's text: the page must still say so
        lines.append('worksheet: %s NOT written (a grader bug, please report): %s' % (moodle.UPLOAD, _failure(err)))
    try:
        lines += feedback.write(out, newest, single, show)
    except Exception as err:  # the grades are written; the page must still say why the zip is not
        lines.append('moodle feedback NOT written (a grader bug, please report): %s' % _failure(err))
    # The desk's lines quote a worksheet's cells, hand.csv's, an error's words: one line each, made
    # safe here, where they are made, for the terminal and the page alike.
    notes += [safe_text.one_line(line) for line in lines]
    if similar is not None:
        if similar.error:
            notes.append('similarity check not run: %s' % similar.error)
            lines.append('similarity: not run: %s' % similar.error)
        else:
            notes += similar.notes  # who was not compared, what was left out: the check's record's words
            lines.append('similarity: %d pair(s) flagged of %d student(s) (%s)'
                         % (len(similar.pairs or []), similar.students or 0, os.path.join(out, 'index.html#similarity')))
    title = _title(out, title)
    title = 'Exam grades: %s' % (records[0]['student'] if single and records else title)
    try:
        content = page.render(records, title, entries, similar, notes)
    except Exception as err:  # not one student's: the page shrinks to what cannot fail, and says why
        problem = 'the page could not be made (a grader bug, please report): %s' % _failure(err)
        lines.append(problem)
        content = _plain_page(title, records, problem)
    contract.write_text(os.path.join(out, 'index.html'), content)
    lines.append('page: %s' % os.path.join(out, 'index.html'))
    return [safe_text.one_line(line) for line in lines]


def hand_lines(out, records, added=0):
    """What the teacher reads of hand.csv: where it is, and whose hand points are still missing (all of
    them, or the items), so that a run after the teacher gave them never asks for them again."""
    path = os.path.join(out, hand.FILE)
    try:
        rows, _ = hand.match(hand.read(path), records)
    except hand.HandError as err:
        return ['hand points: %s written, but cannot be matched to the students: %s' % (path, err)]
    missing = [(r['student'], hand.combine(r, row)['missing']) for r, row in zip(records, rows)]
    none_given = [s for s, items in missing if len(items) == len(hand.HAND_ITEMS)]
    some = [(s, items) for s, items in missing if items and len(items) < len(hand.HAND_ITEMS)]
    head = 'hand points: %s (%d new row(s)): ' % (path, added)
    if not none_given and not some:
        return [head + 'all %d given for each of the %d student(s)' % (hand.HAND_MAX, len(records))]
    lines = [head + 'the %d points the machine does not judge are missing for %d of %d student(s)'
             % (hand.HAND_MAX, len(none_given) + len(some), len(records))]
    if none_given:
        lines.append('  none given yet: %s' % ', '.join(none_given))
    for student, items in some:
        lines.append('  %s: %s not given yet' % (student, ', '.join(items)))
    return lines


def worksheet_lines(out, records, worksheet=None):
    """Fill Moodle's worksheet with the whole grades: ``records`` (the machine's) with their hand points
    of ``out/hand.csv``, scaled, into ``out/moodle-worksheet.csv`` (:data:`moodle.UPLOAD`), the one file
    to upload; return the lines for the terminal and the page. ``worksheet`` (the file the teacher
    downloaded) is kept in OUT as :data:`moodle.DOWNLOADED`, which a later run fills again when none is
    given; with neither, nothing is done ([]). make grade, make rescore and make worksheet all fill it
    here, so the file, its name and its lines are the same whichever ran last.

    :raises hand.HandError: hand.csv unreadable, or a row that could be another student's.
    :raises moodle.WorksheetError: the worksheet lacks what Moodle's importer needs.
    """
    kept = os.path.join(out, moodle.DOWNLOADED)
    if not worksheet and not contract.exists(kept):
        return []
    records, _ = hand.newest(records)  # one participant graded twice: its newest (said by the caller)
    path = os.path.join(out, hand.FILE)
    hands = hand.read(path) if contract.exists(path) else {}
    if worksheet and (not contract.exists(kept) or not os.path.samefile(worksheet, kept)):
        with open(worksheet, 'rb') as f:  # the teacher's own file, named on the command line
            contract.write_bytes(kept, f.read(moodle.MAX_WORKSHEET_BYTES + 1))
    rows, notes = hand.match(hands, records)
    whole = [hand.combine(record, row) for record, row in zip(records, rows)]
    target = os.path.join(out, moodle.UPLOAD)
    summary = moodle.fill_file(kept, target, whole)
    contract.write_text(os.path.join(out, 'worksheet.json'), json.dumps(summary, indent=1, sort_keys=True))
    return [safe_text.one_line(n) for n in notes] + moodle.summary_lines(summary, target)


def next_commands(out, records):
    """The commands that come next, for the terminal, ready to paste (OUT quoted): review and confirm
    the hand points, fill the worksheet, what to upload; and for later, a rescore."""
    where = moodle.shell_quoted(out)
    lines = ['next (each command ready to paste; docs/grading.md, "Quick start"):']
    path = os.path.join(out, hand.FILE)
    try:
        rows, _ = hand.match(hand.read(path), records)
        missing = any(hand.combine(r, row)['missing'] for r, row in zip(records, rows))
    except (hand.HandError, OSError):
        missing = True
    if missing:
        if importlib.util.find_spec('exam_lab.grader.publish.review') is not None:
            lines.append('  make review OUT=%s    # the hand points, reviewed and confirmed' % where)
        else:
            lines.append('  # give the hand points in %s (any spreadsheet, saved as CSV)' % path)
    if os.path.isfile(os.path.join(out, moodle.DOWNLOADED)):
        lines.append('  make worksheet OUT=%s' % where)
    else:
        lines.append('  make worksheet OUT=%s WORKSHEET="<the grading worksheet downloaded from Moodle>"' % where)
    lines.append('  # then upload %s (Grading action: Upload grading worksheet) and %s (Upload multiple '
                 'feedback files in a zip)' % (os.path.join(out, moodle.UPLOAD), os.path.join(out, 'moodle-feedback.zip')))
    lines.append('  make rescore OUT=%s    # later: today\'s rubric on the kept measurements' % where)
    return lines


def _plain_page(title, records, problem):
    """index.html when the page itself failed: the problem, and each student's total, status and folder."""
    def e(value):
        return html.escape(safe_text.one_line(value), quote=True)

    rows = ''.join('<li><a href="%s/grade.md">%s</a>: %s / %s, %s</li>' % (
        e(r.get('student')), e(r.get('student')), e(r.get('total')), e(r.get('max')), e(r.get('status')))
        for r in records)
    return ('<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8"><title>%s</title></head><body>'
            '<h1>%s</h1><p>%s</p><ul>%s</ul></body></html>\n' % (e(title), e(title), e(problem), rows))
