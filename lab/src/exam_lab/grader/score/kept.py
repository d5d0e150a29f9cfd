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
shape is no grade of today's grader: it stops that student's rescore and worksheet row with
"graded by an older grader: grade again" (:data:`OLDER`), the file named; one of no shape at all
with a sentence naming the file and the field.
"""
from exam_lab.grader.score.inspection import STATIC, InspectRecord
from exam_lab.grader.score.records import (
    MEASUREMENTS, Items, Map, Maybe, Number, OneOf, Optional, Record, RecordError, SessionRecord, Text, shown)
from exam_lab.grader.score.sheets import ITEMS, SHEETS
from exam_lab.grader.score.verdict import STATUSES

#: The current shape of measurements.json and of grade.json. Version 1 (2026-11-27): the first with a
#: version; the shapes before it have none.
VERSION = 1
#: A teacher's note, a hint or an item's evidence (a build's tail, a traceback): long, but bounded.
_LONG = Text(1 << 16)
_NOTES = Items(_LONG, 2000)
#: What the inspection found of the upload (``extra`` of the measurements, the grade's facts), and
#: the time the grading took. A grading refused early has the seconds only.
_FACTS = {key: Optional(schema) for key, schema in InspectRecord.SCHEMA['facts'].items()}


#: What a kept file of a shape before :data:`VERSION` is, for the teacher (with the file named).
OLDER = 'graded by an older grader: grade again'


class OlderRecord(RecordError):
    """A kept file of an older shape than today's (:data:`OLDER`): that student's, to grade again."""


class _Kept(Record):
    """A file the grader keeps in OUT for a later grader to read (the measurements, the grade). One of a
    version before :data:`VERSION` (the first shapes had none) is refused as such, never converted: a
    conversion guesses what an older grader meant, and grading again measures it
    (:class:`OlderRecord`, its file named). A later version is of no shape this grader knows: the
    check names it."""

    @classmethod
    def make(cls, value):
        if isinstance(value, dict) and ('version' not in value or type(value['version']) is int
                                        and value['version'] < VERSION):
            raise OlderRecord('%s: %s' % (cls.FILE, OLDER))
        return super().make(value)


class MeasurementsRecord(_Kept):
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


_POINTS = Number(-1000, 1000)
_PROVENANCE = {'grader': Text(200), 'rubric': Text(200), 'how': OneOf('run', 'rescore'), 'machine': Text(1000),
               'date': Text(100)}


class GradeRecord(_Kept):
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

