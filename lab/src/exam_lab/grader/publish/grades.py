"""The grade record from what a run measured (:data:`~exam_lab.grader.score.records.MEASUREMENTS`):
:func:`score`, the one place the rubric is applied, by a run and by a rescore alike; the session's
record of a grading whose session did not run (:func:`no_session`); the record of a submission that
could not be graded; and the rescore of a run's OUT with today's rubric.
"""
import os
import traceback

from exam_lab.grader import contract
from exam_lab.grader.publish import provenance, report, teacher
from exam_lab.grader.score import kept, records, rubric


def score(measured, how='run'):
    """The grade record of one submission from what its run measured (a
    :class:`~exam_lab.grader.score.kept.MeasurementsRecord`, or the value of one: checked here): the
    one place the rubric is applied, by a run and by a rescore alike. ``how`` goes into its provenance."""
    if not isinstance(measured, kept.MeasurementsRecord):
        measured = kept.MeasurementsRecord.make(measured)
    measured = measured.value
    static, session = measured['static'], measured['session']
    run_value = rubric.threshold_run_value(static, session)
    extra = dict(measured['extra'], doubts=rubric.doubts(static, session), provenance=provenance.stamp(how),
                 threshold_run={'value': run_value} if run_value is not None else None)
    return report.grade_record(measured['student'], measured['sheet'], rubric.score(measured['sheet'], static, session),
                               teacher.hints(static, session, measured['notes'] + measured['fixes'],
                                             measured['comments'], measured['isolate'], measured['how_run']),
                               extra, rubric.status(static, session, measured['fixes']))


def keep_and_score(out_dir, measured):
    """Keep what a grading measured in ``out_dir`` (``measured``, the value of a
    :class:`~exam_lab.grader.score.kept.MeasurementsRecord` of today's version, checked first: a
    grader's bug shows here, not at the rescore), score it (:func:`score`), write grade.json and
    grade.md; return the grade record."""
    record = kept.MeasurementsRecord.make(dict(measured, version=kept.VERSION))
    contract.write_record(os.path.join(out_dir, records.MEASUREMENTS), record)
    grade = score(record)
    report.write_grade(out_dir, grade)
    return grade


def graded_folders(out):
    """The folders of a run's OUT holding a grade made from measurements: OUT itself for one
    submission, else one per student (in the order of their names): the folders listed in OUT (a link
    is none: :func:`~exam_lab.grader.contract.folders`), each holding an entry of that name (a FIFO
    or a link there is one, for its reader to refuse: that student's line)."""
    if contract.exists(os.path.join(out, records.MEASUREMENTS)):
        return [out]
    return [os.path.join(out, name) for name in contract.folders(out)
            if contract.exists(os.path.join(out, name, records.MEASUREMENTS))]


#: The words of a line of :func:`rescore` for a student it did not rescore.
NOT_RESCORED = 'not rescored'


def rescore(out):
    """Apply today's rubric to the measurements a run kept in ``out``: no ROS, no box, seconds for a
    class. Each grade.json/grade.md is written again, with the points it had (``previous``); a class's
    grades.csv too. Both files are read as records (:mod:`exam_lab.grader.score.kept`: capped, checked,
    one of an older grader refused: "graded by an older grader: grade again"): a student whose
    measurements.json or grade.json does not match is not rescored (its files stay as they were) and
    the others are.

    :returns: ``(records, changes)``; ``changes``: one line per student whose points or status moved,
        saying which items moved and from what to what, and one per student not rescored
        (``<student>: not rescored ...: <file>.<field>: why``). A student not rescored keeps its
        grade in ``records`` (and grades.csv) when its grade.json could be read.
    """
    graded, changes = [], []
    folders = graded_folders(out)
    for folder in folders:
        name = os.path.basename(folder.rstrip('/'))
        try:
            old = read_grade(out, folder) if contract.exists(os.path.join(folder, 'grade.json')) else {}
        except records.RecordError as err:
            changes.append('%s: %s (its grade.json kept as it is, not in grades.csv): %s' % (name, NOT_RESCORED, err))
            continue
        try:
            measured = contract.read_record(os.path.join(folder, records.MEASUREMENTS), kept.MeasurementsRecord,
                                            under=out)
            if folder != out and measured.student != name:
                raise records.RecordError('%s: the measurements of %s, in the folder %s (a student\'s folder '
                                          'holds its own)' % (records.MEASUREMENTS, records.shown(measured.student),
                                                              records.shown(name)))
        except records.RecordError as err:
            changes.append('%s: %s (its grade kept as it was): %s' % (name, NOT_RESCORED, err))
            if old:
                graded.append(old)
            continue
        record = score(measured, how='rescore')
        before = {i['id']: i['points'] for i in old.get('items', [])}
        record = dict(record, previous={'total': old.get('total'), 'status': old.get('status'), 'items': before,
                                        'provenance': old.get('provenance')})
        moved = ['%s %s -> %s' % (i['id'], report.points_text(before.get(i['id'])), report.points_text(i['points']))
                 for i in record['items'] if before.get(i['id']) != i['points']]
        if old.get('status') != record['status']:
            moved.append('status %s -> %s' % (old.get('status'), record['status']))
        if moved:
            changes.append('%s: %s -> %s (%s)' % (record['student'], report.points_text(old.get('total')),
                                                 report.points_text(record['total']), '; '.join(moved)))
        graded.append(report.write_grade(folder, record))
    if folders and folders != [out]:
        report.write_csv(os.path.join(out, 'grades.csv'), graded)
    return graded, changes


def read_grade(out, folder):
    """The grade kept in ``folder`` of ``out`` (``grade.json``), read through the contract (no link,
    a regular file, capped, :class:`~exam_lab.grader.score.kept.GradeRecord`'s checks: its total the
    sum of its items, its status the rubric's); in a class's folder, the grade of the student of that
    folder (one naming another student is not this folder's). Raises RecordError naming the file and
    what is wrong."""
    record = contract.read_record(os.path.join(folder, kept.GradeRecord.FILE), kept.GradeRecord, under=out).value
    name = os.path.basename(folder.rstrip('/'))
    if folder != out and record['student'] != name:
        raise records.RecordError('%s: the grade of %s, in the folder %s (a student\'s folder holds its own)'
                                  % (kept.GradeRecord.FILE, records.shown(record['student']), records.shown(name)))
    return record


def no_session(outcome, error, **more):
    """The session's record (a :class:`~exam_lab.grader.score.records.SessionRecord`) of a grading
    whose session did not run or failed: its ``outcome`` (an
    :class:`~exam_lab.grader.score.records.Outcome`), ``error`` (why, for the teacher) and ``more``
    (``refused``, ``no_node``, ``budget_used``, ``survivors``)."""
    return records.SessionRecord.make(dict(more, outcome=outcome, build=None, runs=[],
                                           error=error[:records.MAX_LOG_TEXT]))


def could_not_grade(student, sheet, why, notes=()):
    """The record of a submission the grader could not grade: every item 0, and why."""
    sheet = sheet or 'altitude'
    session = no_session(records.Outcome.GRADER_FAILED, 'could not grade: %s' % why)
    return report.grade_record(student, sheet, rubric.score(sheet, {}, session),
                               list(notes) + [session.error], {'seconds': 0.0, 'provenance': provenance.stamp()},
                               rubric.status({}, session))


def bug_note():
    """The teacher's note of a grader bug being handled: its traceback on one line, its last
    MAX_LOG_TEXT characters (a deep recursion's would outgrow any record)."""
    return 'grader error, please report: %s' % traceback.format_exc().replace('\n', ' | ')[-records.MAX_LOG_TEXT:]


def graded_in(out):
    """The folders of a run's OUT holding a grade.json: one per student folder (a folder listed, never a
    link: :func:`~exam_lab.grader.contract.folders`), or OUT itself for the single submission."""
    folders = [os.path.join(out, name) for name in contract.folders(out)
               if contract.exists(os.path.join(out, name, kept.GradeRecord.FILE))]
    if folders:
        return folders
    return [out] if contract.exists(os.path.join(out, kept.GradeRecord.FILE)) else []


def records_in(out, with_folders=False, older=None):
    """The grade records of a run's OUT: one per student folder, or the single submission's, each read
    through the contract (:func:`read_grade`: no link, a regular file, capped, checked: its total the
    sum of its items, its status the rubric's, the student of its folder); raises RecordError naming
    the file of one that is not a grade. ``with_folders``: ``(its folder, record)`` each (the
    student's files beside its grade). ``older``: a list that takes, instead of the error, the line
    of each grade.json of an older grader (:class:`~exam_lab.grader.score.kept.OlderRecord`, whose
    student is named by its folder: that student's matter, never the class's)."""
    found = []
    for folder in graded_in(out):
        try:
            found.append((folder, read_grade(out, folder)))
        except records.RecordError as err:
            where = os.path.relpath(os.path.join(folder, kept.GradeRecord.FILE), out)
            why = str(err)  # named by its place in OUT, once
            for said in (where + ': ', kept.GradeRecord.FILE + ': '):
                if why.startswith(said):
                    why = why[len(said):]
            if older is None or not isinstance(err, kept.OlderRecord):
                raise records.RecordError('%s: %s' % (where, why))
            older.append('%s: %s' % (where, why))
    return found if with_folders else [record for _, record in found]
