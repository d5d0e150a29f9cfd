"""What the grader keeps of a grading, as records: its measurements (``measurements.json``, what a
rescore scores again and the flight plot draws) and its grade (``grade.json``). Pure, no rospy.

Both are the grader's own files, written by root in OUT, but they hold a student's text (node names,
log lines, the name of a file) and they outlive the grader that wrote them: a rescore, run as the
teacher, reads a class graded months ago. So each is read as a box's record is (capped, checked
against its schema) and carries a ``version``. The grade's text is made safe where it is made
(``CLEAN``); the measurements' session and the teacher's notes are too (the session is a clean
record already: a file edited by hand is made so again as it is read, for the flight plot), and the
names they hold (the student's, its folder's, its code's files) are kept exactly, a name in bytes
that are not UTF-8 as its surrogate escapes: the grade made of them is clean. A file of an older
shape is brought to the current one by :meth:`MeasurementsRecord.upgraded` /
:meth:`GradeRecord.upgraded` before the check (one function per older shape, named for it); one that
matches neither stops that student's rescore with a sentence naming the file and the field.
"""
import copy

from exam_lab.grader.score.records import (
    MAX_LOG_TEXT, MEASUREMENTS, STATIC, InspectRecord, Items, Map, Maybe, Number, OneOf, Optional, Outcome, Record,
    RecordError, SessionRecord, Text, shown)
from exam_lab.grader.score.sheets import ITEMS, SHEETS
from exam_lab.grader.score.verdict import STATUSES

#: The current shape of measurements.json and of grade.json. Version 1 (2026-11-27): the first with a
#: version; the shapes before it have none (:func:`measurements_from_unversioned`).
VERSION = 1
#: A teacher's note, a hint or an item's evidence (a build's tail, a traceback): long, but bounded.
_LONG = Text(1 << 16)
_NOTES = Items(_LONG, 2000)
#: What the inspection found of the upload (``extra`` of the measurements, the grade's facts), and
#: the time the grading took. A grading refused early has the seconds only.
_FACTS = {key: Optional(schema) for key, schema in InspectRecord.SCHEMA['facts'].items()}


def _unversioned(value):
    """Whether ``value`` is a kept file of before the version (a value of another kind is the check's)."""
    return isinstance(value, dict) and 'version' not in value


class MeasurementsRecord(Record):
    """All a grading measured (``measurements.json``, :data:`~exam_lab.grader.score.records.MEASUREMENTS`):
    the inspection's ``static`` (``{}`` when it read nothing), the session's record (a
    :class:`~exam_lab.grader.score.records.SessionRecord`'s value), the teacher's ``notes`` and
    ``fixes``, the code's ``comments``, how the box ran (``isolate``, ``how_run``), and ``extra``, the
    facts the grade carries (participant, folder, documents, seconds). Written by the runner, read by
    :func:`exam_lab.grader.publish.grades.rescore` and the flight plot."""
    FILE = MEASUREMENTS
    MAX_BYTES = SessionRecord.MAX_BYTES + (8 << 20)
    CLEAN = ('session', 'notes', 'fixes', 'how_run', 'static')
    NON_FINITE = True
    SCHEMA = {
        'version': OneOf(VERSION),
        'student': Text(1000), 'sheet': OneOf(*sorted(SHEETS)),
        'static': Maybe(({}, STATIC)),
        'session': SessionRecord.SCHEMA,
        'notes': _NOTES, 'fixes': _NOTES,
        'comments': InspectRecord.SCHEMA['comments'],
        'isolate': Maybe(bool), 'how_run': Maybe(_LONG),
        'extra': dict(_FACTS, seconds=Number(0)),
    }

    @classmethod
    def converted(cls, value):
        return dict(value, session=SessionRecord.converted(value['session']))  # as the session's own record has it

    @classmethod
    def upgraded(cls, value):
        return measurements_from_unversioned(value) if _unversioned(value) else value


def measurements_from_unversioned(value):
    """measurements.json as the grader kept it before version 1 (no ``version``), in version 1's shape.

    The older shapes, all without a version: (1) the session had no ``outcome`` (before 2026-11-26
    22:00, when the session became a record): it is derived as the grader of then would have set it
    (:func:`outcome_of_unversioned`); (2) a probe's result without ``input_rates`` (before the probe
    recorded the inputs' rates, 2026-11-26 18:40): ``{}``, which the rubric reads as it read a missing
    key (the old 2 Hz drone's window); (3) nor ``node_watch`` (before the judge watched the nodes):
    no death seen, as then (roslaunch's words about the nodes are in the run's ``launch`` either way);
    (4) a leg without ``stays`` (before the rules were timed from the node's own value staying beyond):
    None, the time the rubric falls back from as it did for a missing one; (5) a calibration without
    ``near`` is a shape the current one allows (the probe's record says so); (6) a log's tail (the
    build's, roslaunch's) longer than the session keeps today (before 2026-11-26 22:00): its last
    MAX_LOG_TEXT characters, as the session keeps them. Anything else of another
    shape stays as it is, for the check to name."""
    value = copy.deepcopy(value)
    value['version'] = VERSION
    session = value.get('session')
    if isinstance(session, dict):
        if 'outcome' not in session:
            session['outcome'] = outcome_of_unversioned(session).value
        for part in [session.get('build')] + [run.get('launch') for run in session.get('runs') or [] if isinstance(run, dict)]:
            if isinstance(part, dict) and isinstance(part.get('tail'), str):
                part['tail'] = part['tail'][-MAX_LOG_TEXT:]
        for run in session.get('runs') or []:
            for key in ('probe', 'refused_probe'):
                probe = run.get(key) if isinstance(run, dict) else None
                if isinstance(probe, dict):
                    probe.setdefault('input_rates', {})
                    probe.setdefault('node_watch', {'deaths': [], 'nodes': []})
                    for leg in (probe.get('legs') or {}).values():
                        if isinstance(leg, dict):
                            leg.setdefault('stays', None)
    return value


#: The runner's sentences of before the outcome (``error`` of a session that did not run), each the
#: outcome it stood for.
_OLD_ERRORS = (('submission refused', Outcome.REFUSED), ('the inspection of the upload failed', Outcome.INSPECTION_FAILED),
               ('the grader failed', Outcome.GRADER_FAILED), ('could not grade', Outcome.GRADER_FAILED),
               ('the session failed', Outcome.SESSION_FAILED), ("the session's record was refused", Outcome.SESSION_FAILED))


def outcome_of_unversioned(session):
    """The :class:`~exam_lab.grader.score.records.Outcome` of a session kept before it had one: from
    its flags and its build as host.session and the runner set them then."""
    if session.get('refused'):
        return Outcome.REFUSED
    if session.get('no_node'):
        return Outcome.NO_NODE
    build = session.get('build')
    if isinstance(build, dict):
        status = build.get('status')
        return Outcome.BUILD_STOPPED if status is None else Outcome.RAN if status == 0 else Outcome.BUILD_FAILED
    error = str(session.get('error') or '')
    check = session.get('launch_check')
    if isinstance(check, dict) and check.get('status', 0) is None and session.get('budget_used'):
        return Outcome.CHECK_STOPPED
    for start, outcome in _OLD_ERRORS:
        if error.startswith(start):
            return outcome
    if session.get('budget_used'):
        return Outcome.SESSION_KILLED if 'the session was killed' in error else Outcome.NOT_RUN
    return Outcome.SESSION_FAILED


_POINTS = Number(-1000, 1000)
_PROVENANCE = {'grader': Text(200), 'rubric': Text(200), 'how': OneOf('run', 'rescore'), 'machine': Text(1000),
               'date': Text(100)}


class GradeRecord(Record):
    """A student's grade (``grade.json``, :func:`exam_lab.grader.publish.report.grade_record`): the
    items' points and evidence, the total, the status and why, the hints for the teacher, the doubts,
    what made it (``provenance``), the facts of the upload; after a rescore, the points it had
    (``previous``); on Slurm, the node that graded it (``graded_on``)."""
    FILE = 'grade.json'
    MAX_BYTES = 16 << 20
    CLEAN = NON_FINITE = True
    SCHEMA = dict(_FACTS, **{
        'version': OneOf(VERSION),
        'student': Text(1000), 'sheet': Maybe(Text(100)),
        'total': _POINTS, 'max': _POINTS,
        'items': Items({'id': Text(50), 'points': _POINTS, 'max': _POINTS, 'evidence': Text(1 << 20)}, 50),
        'for_the_teacher': _NOTES, 'status': Text(100), 'status_reason': _LONG,
        'seconds': Optional(Number(0)), 'doubts': Optional(Maybe(_NOTES)),
        'provenance': Optional(Maybe(_PROVENANCE)),
        'threshold_run': Optional(Maybe({'value': Number(finite=False)})),
        'previous': Optional({'total': Maybe(_POINTS), 'status': Maybe(Text(100)), 'items': Map(Text(50), Maybe(_POINTS), 50),
                              'provenance': Maybe(_PROVENANCE)}),
        'graded_on': Optional(Text(255)),
    })

    @classmethod
    def upgraded(cls, value):
        return grade_from_unversioned(value) if _unversioned(value) else value

    def validate(self):
        """A grade is the rubric's: each item one of the sheets' (once, out of its own maximum, its points
        from 0 to it), the total the sum of the items' points, the maximum the sum of theirs, the status
        one the rubric gives. A grade edited by hand (a total of 17 over no item) is no grade."""
        seen = set()
        for index, item in enumerate(self.items):
            where = 'grade.json.items[%d]' % index
            if item['id'] not in ITEMS or item['id'] in seen:
                raise RecordError('%s.id: %s is %s' % (where, shown(item['id']), 'an item twice' if item['id'] in seen
                                                       else 'no item of the rubric'))
            seen.add(item['id'])
            if item['max'] != ITEMS[item['id']][0] or not 0 <= item['points'] <= item['max']:
                raise RecordError('%s: %s points out of %s, where the rubric gives %s at most'
                                  % (where, item['points'], item['max'], ITEMS[item['id']][0]))
        for key, total in (('total', sum(i['points'] for i in self.items)), ('max', sum(i['max'] for i in self.items))):
            if abs(self.value[key] - total) > 1e-6:
                raise RecordError('grade.json.%s: %s, but its %d item(s) come to %s' % (key, self.value[key],
                                                                                       len(self.items), total))
        if self.status not in STATUSES:
            raise RecordError('grade.json.status: %s is no status the rubric gives (%s)'
                              % (shown(self.status), ', '.join(STATUSES)))


def grade_from_unversioned(value):
    """grade.json as the grader wrote it before version 1: the same keys (those it lacks, a grade of
    an older grader did not have: they are optional), no ``version``."""
    return dict(value, version=VERSION)
