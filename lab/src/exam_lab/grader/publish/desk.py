"""The teacher's desk: what a class run leaves besides the grades. No rospy here.

After grading, :func:`finish` writes, in ``OUT``: each student's Gradescope ``results.json`` and
flight plot, the hand points proposed (``proposals.csv``, :mod:`exam_lab.grader.publish.proposals`),
the similarity check across the class, the Moodle worksheet filled (when one is given),
each released student's feedback page in ``moodle-feedback.zip`` (:mod:`exam_lab.grader.publish.feedback`)
and ``index.html`` (:mod:`exam_lab.grader.publish.page`).

The desk survives any one student: each student's results.json, flight plot and page section are
made apart, and one that fails (a bug, a probe file no plot can be drawn from) is a note in that
student's section, on the page's top and on the terminal; the rest is written. The grades are
already written by then (grade.json, grades.csv): nothing here may lose them.
"""
import html
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


def finish(out, records, single=False, similar=None, worksheet=None, scale=False, title=None, show=None):
    """Write the desk's files for ``records`` graded into ``out``; return lines for the terminal.

    :param single: one submission (its results are in ``out`` itself, not ``out/<student>``).
    :param similar: the similarity check's record (a :class:`~exam_lab.grader.score.records.SimilarityRecord`:
        :func:`exam_lab.grader.class_run.class_similarity`, :func:`read_similarity`) or None; a plain
        dict is refused (TypeError): its text would reach the page uncleaned.
    :param worksheet: the Moodle worksheet to fill, or None.
    :param scale: scale the grades to the worksheet's maximum grade (:func:`moodle.fill`).
    :param title: the class's name (:func:`moodle.class_name`); the output folder's name when None.
    :param show: what the students' feedback pages show (:func:`feedback.write`); None: lab/check_visibility.ini.
    """
    if similar is not None and not isinstance(similar, SimilarityRecord):
        raise TypeError('the similarity check is given as its record (records.SimilarityRecord), not a %s'
                        % type(similar).__name__)
    lines, notes, entries = [], [], {}
    records, refused = _grade_records(records)
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
        lines.append('hand points: %s (%d new row(s)): fill in the %d points the machine does not judge, '
                     'then make worksheet OUT=%s WORKSHEET=<Moodle worksheet>' % (
                         os.path.join(out, hand.FILE), added, hand.HAND_MAX, out))
    except (hand.HandError, OSError) as err:  # the teacher's file as it is: never overwritten blindly
        lines.append('hand.csv NOT written: %s' % err)
    try:
        lines += proposals.write(out, records, single)
    except OSError as err:
        lines.append('proposals.csv NOT written: %s' % err)
    if worksheet:
        base = os.path.splitext(os.path.basename(worksheet))[0]
        target = os.path.join(out, '%s-filled.csv' % base)
        try:
            summary = moodle.fill_file(worksheet, target, newest, scale)
            lines += moodle.summary_lines(summary, target)
            contract.write_text(os.path.join(out, 'worksheet.json'), json.dumps(summary, indent=1, sort_keys=True))
        except (moodle.WorksheetError, OSError) as err:
            lines.append('worksheet NOT filled: %s' % err)
        except Exception as err:  # a bug on one record's text: the page must still say so
            lines.append('worksheet NOT filled (a grader bug, please report): %s' % _failure(err))
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


def _plain_page(title, records, problem):
    """index.html when the page itself failed: the problem, and each student's total, status and folder."""
    def e(value):
        return html.escape(safe_text.one_line(value), quote=True)

    rows = ''.join('<li><a href="%s/grade.md">%s</a>: %s / %s, %s</li>' % (
        e(r.get('student')), e(r.get('student')), e(r.get('total')), e(r.get('max')), e(r.get('status')))
        for r in records)
    return ('<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8"><title>%s</title></head><body>'
            '<h1>%s</h1><p>%s</p><ul>%s</ul></body></html>\n' % (e(title), e(title), e(problem), rows))
