"""The typed records that cross the trust boundary: what a box hands back to root. Pure, no rospy.

A box (:mod:`exam_lab.grader.boxed.inspect`, :mod:`~exam_lab.grader.boxed.intake`, the similarity
check) writes one JSON object; root reads it only through :func:`exam_lab.grader.contract.read_record`,
which gives the bytes to a record's ``from_json``. That checks every field against the record's
schema (types, ranges, string lengths, list lengths, no unknown keys; :mod:`exam_lab.grader.score.schema`)
and raises :class:`RecordError` on anything unexpected: a record of an unexpected shape is a crash of
that box, never data to use. What the grader keeps of a grading (its measurements, its grade) are
records too: :mod:`exam_lab.grader.score.kept`.
"""
import enum
import re
import typing
from dataclasses import dataclass

# The schema machinery, importable from here as well (records.check, records.Text...).
from exam_lab.grader.score.schema import (  # noqa: F401
    MAX_ITEMS, MAX_TEXT, DataRecord, Items, Map, Maybe, Number, OneOf, Optional, Record, RecordError, Row, Text, check,
    parse, relative, shown, write)
from exam_lab.grader.score.sheets import SHEETS

#: What a grading measured, kept beside grade.json by the runner (:class:`~exam_lab.grader.score.kept.MeasurementsRecord`,
#: its session a :class:`SessionRecord`): a rescore scores it again, the flight plot draws from it.
MEASUREMENTS = 'measurements.json'


class UnpackError(Exception):
    """A submission (or a class archive) that cannot be opened safely; the message says why, for the
    teacher. Raised in the box (boxed/archives.py) and by root of what a box said (the class's intake):
    one type for both sides."""


@dataclass(frozen=True)
class IntakeStudent(object):
    """A student of the class archive as the intake unpacked it: ``name`` (its folder's), ``path``
    (relative to the intake's output folder), ``refused`` (why its files were not unpacked, or None)."""
    name: str
    path: str
    refused: typing.Optional[str] = None


@dataclass(frozen=True)
class IntakeRecord(DataRecord):
    """A class archive unpacked by :mod:`exam_lab.grader.boxed.intake` (``intake.json``): the box's
    ``uid`` and its ``students`` (:class:`IntakeStudent`). A class may be larger than any other list's cap."""
    FILE = 'intake.json'
    MAX_BYTES = 16 << 20
    MAX_STUDENTS = 10000
    SCHEMA = {'uid': Number(0, 2 ** 32, integer=True),
              'students': Items({'name': Text(255), 'path': Text(4096), 'refused': Optional(Text())}, MAX_STUDENTS)}
    uid: int
    students: typing.Tuple[IntakeStudent, ...]

    def validate(self):
        for index, student in enumerate(self.students):
            where = 'intake.json.students[%d]' % index
            relative(student.path, where + '.path')
            name = student.name
            if name in ('', '.', '..') or name != name.strip(' .') or \
                    not all(c.isalnum() or c in ' -._' for c in name):
                raise RecordError('%s.name: %s is not a student\'s name (a folder name of letters, digits, '
                                  'space and -._)' % (where, shown(name)))


#: A share of code (0..1, a little more by rounding).
_SHARE = Number(0, 10)


@dataclass(frozen=True)
class SimilarFiles(object):
    """The two files of a flagged pair that are most alike: their names, each one's share alike, and
    each one's HTML with the detector's highlight spans (escaped by the detector: shown as it is)."""
    file_a: str
    file_b: str
    sim_a: float
    sim_b: float
    html_a: str
    html_b: str


@dataclass(frozen=True)
class SimilarPair(object):
    """Two students whose code is alike (``a``, ``b``: their names), each one's share alike, and
    their best ``files`` (:class:`SimilarFiles`)."""
    a: str
    b: str
    score_a: float
    score_b: float
    files: typing.Tuple[SimilarFiles, ...]


@dataclass(frozen=True)
class SimilarityRecord(DataRecord):
    """The class's similarity check (:func:`exam_lab.grader.boxed.similarity.check`,
    ``similarity.json``): flagged ``pairs`` (:class:`SimilarPair`) with their best files' highlighted
    HTML (escaped by the detector; the page escapes nothing more), every pair's ``scores`` (``(a, b,
    score_a, score_b)``), ``notes``; or ``error``."""
    FILE = 'similarity.json'
    MAX_BYTES = 32 << 20
    #: Its file names and the code in its HTML are the students': made safe here (no markup is added).
    CLEAN = True
    SCHEMA = {
        'error': Optional(Text(20000)), 'notes': [str],
        'pairs': Optional(Items({'a': Text(255), 'b': Text(255), 'score_a': _SHARE, 'score_b': _SHARE,
                                 'files': [{'file_a': str, 'file_b': str, 'sim_a': _SHARE, 'sim_b': _SHARE,
                                            'html_a': Text(1 << 20), 'html_b': Text(1 << 20)}]}, 5000)),
        'students': Optional(Number(0, 1e5, integer=True)), 'threshold': Optional(_SHARE),
        'detector': Optional(Text(100)), 'scores': Optional(Items(Items((Text(255), _SHARE), 4), 200000)),
    }
    notes: typing.Tuple[str, ...]
    error: typing.Optional[str] = None
    pairs: typing.Optional[typing.Tuple[SimilarPair, ...]] = None
    students: typing.Optional[int] = None
    threshold: typing.Optional[float] = None
    detector: typing.Optional[str] = None
    scores: typing.Optional[typing.Tuple[tuple, ...]] = None

    def validate(self):
        for index, pair in enumerate(self.pairs or ()):
            for inner, match in enumerate(pair.files):
                for key in ('html_a', 'html_b'):
                    if '<' in _HIGHLIGHT.sub('', getattr(match, key)):
                        raise RecordError('similarity.json.pairs[%d].files[%d].%s: markup other than the '
                                          "detector's highlight" % (index, inner, key))


#: The only markup of the detector's HTML (the page shows it as is): its highlight spans.
_HIGHLIGHT = re.compile(r"<span class='highlight-(?:red|green)'>|</span>")


#: A value the student's node published or the flight was computed from: any float (NaN, infinities).
_VALUE = Number(finite=False)
#: A ROS name (node, topic, service, type) as the master gave it: the student's node chose it.
NAME = Text(1000)
#: A time (the wall clock's seconds, the judge's own).
_TIME = Number()
_COUNT = Number(0, 1e12, integer=True)
#: Most service calls (and answers) of one run: a node that calls in a loop is judged for it, not
#: refused (the probe's result is read up to contract.FILE_CAP bytes: fewer than this many calls fit).
MAX_CALLS = 200000
#: Most node deaths the judge's watch lists in one run (a node respawned in a loop).
MAX_DEATHS = 20000
#: Longest request of a service call the node made; the drone's answer quotes it (repr: each
#: character at most 4), with its own words around.
MAX_REQUEST = MAX_TEXT
_REQUEST = Text(MAX_REQUEST)
_ANSWER = Text(4 * MAX_REQUEST + 500)

#: One leg of the flight checked on the node's own values (:func:`exam_lab.grader.judge.legs.leg_check`).
LEG = {'side': OneOf('above', 'below'), 'reached': Maybe(_TIME), 'stays': Maybe(_TIME), 'off_side': _COUNT,
       'first': Maybe(_VALUE), 'last': Maybe(_VALUE), 'samples': _COUNT}


class ProbeRecord(Record):
    """The probe's result (:mod:`exam_lab.grader.judge.probe`, ``probe-<tag>.json``): what it measured of
    the student's node in one run, as the rubric reads it. Written by the judge's uid, of names and
    values the student's node chose (node and topic names, requests, published values): root reads it
    through :func:`~exam_lab.grader.contract.read_record` and takes a result that does not match for
    the run's crash. The keys after ``start_timeout`` up to ``rate`` are there as far as the flight got
    (a node that never started has no ``output``); the flight's legs are named by the probe
    (``schedule`` and ``legs`` keys)."""
    FILE = 'probe.json'
    MAX_BYTES = 4 << 20
    CLEAN = NON_FINITE = True
    SCHEMA = {
        'kind': OneOf('main', 'threshold'), 'sheet': OneOf(*sorted(SHEETS)), 'threshold': Number(),
        'margin': Number(), 'delay': Number(), 'start_timeout': Number(),
        'input_rates': Map(Text(100), Number(0, 1e6), 10),
        'nodes': Optional([NAME]), 'node_seen_s': Optional(Maybe(Number())), 'launch_seen_s': Optional(Maybe(Number())),
        'subscribed': Optional(Map(NAME, [NAME], 10)),
        'input_types': Optional(Map(NAME, {'type': Maybe(NAME), 'connected': bool, 'refused': Maybe(Text()),
                                            'adapted': Maybe(NAME), 'published': Optional(NAME)}, 10)),
        'output': Optional({'expected': NAME, 'topic': Maybe(NAME), 'type': Maybe(NAME), 'candidates': [NAME]}),
        # A probe of before issue 45 kept the last value of each row only: no 'before', 'changes', 'values'.
        'formula': Optional(Items({'inputs': Map(Text(100), _VALUE, 4), 'expected': _VALUE,
                                   'published': Maybe(_VALUE), 'samples': _COUNT,
                                   'before': Optional(Map(Text(100), _VALUE, 4)),
                                   'changes': Optional(Map(Text(100), _TIME, 4)),
                                   'values': Optional(Items(Row(_TIME, _VALUE), 100))}, 20)),
        # A probe of before 2026-11-26 18:20 calibrated on lo and hi only: measurements kept then have no 'near'.
        'calibration': Optional(dict({'by': OneOf('own', 'oracle'), 'reason': Text(), 'fit': Maybe(Row(_VALUE, _VALUE))},
                                     **{side: schema({'x': _VALUE, 'target': _VALUE, 'value': Maybe(_VALUE)})
                                        for side, schema in (('lo', dict), ('hi', dict), ('near', Optional))})),
        'schedule': Optional(Map(Text(50), _TIME, 20)),
        'legs': Optional(Maybe(Map(Text(50), LEG, 20))),
        # A probe of before issue 45 held each leg for a value of a silent output: no 'silent' then.
        'silent': Optional(bool),
        'rate': Optional({'samples': _COUNT, 'hz': Maybe(Number()), 'max_gap': Maybe(Number()),
                          'non_finite': Optional(_COUNT)}),
        'node_watch': {'deaths': Items({'node': NAME, 't': Maybe(_TIME), 'detail': Text()}, MAX_DEATHS),
                       'nodes': [NAME]},
        'calls': Items(Row(_TIME, _REQUEST), MAX_CALLS),
        'answers': Items(Row(_TIME, _REQUEST, bool, _ANSWER), MAX_CALLS),
        'graph': Map(NAME, {'publishes': Items(Row(NAME, NAME)), 'subscribes': Items(Row(NAME, NAME)),
                             'services': [NAME]}),
        'alive_at_end': bool, 't0': _TIME,
        'clock': {'use_sim_time': Items(Maybe((bool, _VALUE, Text())), 2), 'messages': _COUNT,
                  'publishers': [NAME], 'ros_time_is_wall': bool},
        'judge_uid': Number(0, 2 ** 32, integer=True),
        'trace': {'published': Items(Row(_TIME, Maybe(_VALUE)), 100000), 'oracle': Items(Row(_TIME, _VALUE), 1000)},
    }


class Outcome(str, enum.Enum):
    """How one grading ended (``outcome`` of :class:`SessionRecord`). A member is its string too: the
    JSON holds ``"ran"``, and ``Outcome.RAN == 'ran'``, so a reader of the old strings reads it the same."""
    #: The session's own: built, the runs tried.
    RAN = 'ran'
    #: The build failed; stopped by its time limit or the student's budget.
    BUILD_FAILED = 'build_failed'
    BUILD_STOPPED = 'build_stopped'
    #: roslaunch's check of the launch file stopped by the budget.
    CHECK_STOPPED = 'check_stopped'
    #: The runner's, when no session ran or it failed: the session's process failed or its record was
    #: refused; it was killed past the budget; the budget was spent before it; no script starts a node;
    #: the upload refused; the inspection's box failed; the grader's own bug.
    SESSION_FAILED = 'session_failed'
    SESSION_KILLED = 'session_killed'
    NOT_RUN = 'not_run'
    NO_NODE = 'no_node'
    REFUSED = 'refused'
    INSPECTION_FAILED = 'inspection_failed'
    GRADER_FAILED = 'grader_failed'

    def __str__(self):  # '%s' and str() give the value, as format() does: the text the JSON holds
        return self.value


#: Every outcome (their strings, in the order above).
OUTCOMES = tuple(Outcome)
#: Most characters of a log excerpt (a build's or roslaunch's last lines) in the session's record.
MAX_LOG_TEXT = 20000
#: Most ended nodes roslaunch's output reports in one run (a node respawned in a loop).
MAX_ENDED = 500

_RUN = {
    'tag': OneOf('main', 'threshold'), 'probe': Maybe(ProbeRecord.SCHEMA), 'refused_probe': Optional(ProbeRecord.SCHEMA),
    'probe_error': Optional(Text(MAX_LOG_TEXT)), 'probe_refused': Optional(Text()),
    'probe_status': Optional(Maybe(Number(-1e6, 1e6, integer=True))),
    'master': {'uid': Maybe(Number(0, 2 ** 32, integer=True)),
               'memory': Optional(Maybe({'limit': Maybe(_COUNT), 'peak': Maybe(_COUNT), 'oom_kills': Number(integer=True)})),
               'died': Optional(bool)},
    # The raw facts the rubric judges the run on (score/runs.py); a run kept without them was judged
    # by its session (probe_refused, refused_probe).
    'probe_wall': Optional(Row(_TIME, _TIME)),
    'probe_uid': Optional(Maybe(Number(0, 2 ** 32, integer=True))),
    'launch': {'ended': Items({'node': NAME, 'how': OneOf('died', 'finished cleanly'), 'detail': Text()}, MAX_ENDED),
               'not_started': Items(Text(), 50), 'tail': Text(MAX_LOG_TEXT)},
    'launch_running': Optional(bool), 'seconds': Optional(Number(0)), 'budget': Optional(Text()),
    'survivors': Optional(_COUNT),
}


class SessionRecord(Record):
    """How one grading's session went (:mod:`exam_lab.grader.host.session`, ``session.json``): roslaunch's
    check of the launch file, the build, each run (its probe's :class:`ProbeRecord` or why there is none,
    when the probe ran, its master, roslaunch's words about the nodes: facts, which the rubric judges,
    :mod:`~exam_lab.grader.score.runs`), the processes left, the budget; ``outcome``, an
    :class:`Outcome` (a member, the record made). The runner makes one too when no session ran (``error``, ``refused``,
    ``no_node``): the measurements a rescore reads hold this record."""
    FILE = 'session.json'
    MAX_BYTES = 24 << 20
    CLEAN = NON_FINITE = True
    SCHEMA = {
        'outcome': OneOf(*(o.value for o in Outcome)),
        'build': Maybe({'status': Maybe(Number(-1e6, 1e6, integer=True)), 'seconds': Number(0), 'tail': Text(MAX_LOG_TEXT),
                        'timeout': Number(0), 'stopped': Optional(Text())}),
        'runs': Items(_RUN, 2),
        'survivors': Optional(_COUNT),
        'launch_check': Optional(Maybe({'file': Text(4096), 'status': Maybe(Number(-1e6, 1e6, integer=True)),
                                        'refused': Text(MAX_LOG_TEXT), 'warnings': Items(Text(), 20),
                                        'nodes': Items(NAME, 20)})),
        'budget_used': Optional(Maybe(Text())), 'error': Optional(Text(MAX_LOG_TEXT)),
        'threshold_skipped': Optional(Text()), 'refused': Optional(bool), 'no_node': Optional(bool),
    }

    @classmethod
    def converted(cls, value):
        return dict(value, outcome=Outcome(value['outcome']))


#: What the report reader reads at most (:mod:`exam_lab.grader.boxed.report_reader`): files of one
#: student, pages of one file, and of the whole report; the characters of one page's text.
REPORT_FILES = 10
REPORT_FILE_PAGES = 40
REPORT_PAGES = 80
REPORT_PAGE_TEXT = 20000
#: Words of one page read by OCR with a confidence under the reader's floor, listed at most.
REPORT_UNSURE = 200
#: The kinds of file a student hands in as a report (``other``: not read, said in its note).
REPORT_KINDS = ('pdf', 'odt', 'docx', 'doc', 'rtf', 'image', 'other')
#: The version of report.json (it is kept in OUT and read again by make rescore).
REPORT_VERSION = 1
_REPORT_TEXT = Text(REPORT_PAGE_TEXT)
#: A file of OUT/<student>/report/ as the record names it: one name, no folder.
_REPORT_NAME = re.compile(r'^[A-Za-z0-9][A-Za-z0-9._ -]{0,199}$')


@dataclass(frozen=True)
class ReportFile(object):
    """A file handed in as a report (see :class:`ReportRecord`)."""
    name: str
    kind: str
    converted: bool
    pages: int
    note: str
    state: str
    copy: typing.Optional[str]


@dataclass(frozen=True)
class ReportPage(object):
    """A page read of a report (see :class:`ReportRecord`)."""
    file: int
    number: int
    source: str
    text: str
    layout: str
    confidence: typing.Optional[float]
    unsure: typing.Tuple[str, ...]
    pictures: int
    image: typing.Optional[str]


@dataclass(frozen=True)
class ReportRecord(DataRecord):
    """A student's report as read in a box (:mod:`exam_lab.grader.boxed.report_reader`,
    ``report.json``; root reads it back with :func:`exam_lab.grader.host.reports.read_report` and keeps
    it as ``OUT/<student>/report.json``; make rescore reads the kept one again, never the box).

    ``state`` "read" when at least one page of one file was read, else "not read" with ``why`` (one
    sentence: "no report handed in", "report.pdf: an encrypted PDF"...): a report not read is never
    zero points, it is the teacher's to read. ``files``: each file handed in as a report, ``{name``
    (as handed in, cleaned), ``kind``, ``converted`` (made a PDF by LibreOffice in the box), ``pages``
    (read), ``note`` (why not read, or what was left out), ``state``, ``copy`` (the file as handed in,
    relative to OUT/<student>/, or None when it was not kept)``}``. ``pages``: each page read, ``{file``
    (index into files), ``number`` (1-based), ``source`` ("text": the PDF's text layer; "ocr": the page
    had none and was read from its image), ``text`` (in reading order; on a text page the OCR of its
    pictures, a terminal's screenshot, is put where the picture stands, between lines ``[picture N,
    OCR]`` and ``[end of picture N]``), ``layout`` (``pdftotext -layout`` of the page, columns kept, for
    tables; "" for an OCR page), ``confidence`` (the OCR's mean word confidence 0-100 of what was read
    by OCR on the page, None when nothing was), ``unsure`` (OCR words under the confidence floor),
    ``pictures`` (how many pictures were read by OCR on a text page), ``image`` (the page's PNG relative
    to OUT/<student>/, ``report/page-<file>-<number>.png``, None when not rendered)``}``. ``seconds``:
    how long the reading took, box included."""
    FILE = 'report.json'
    MAX_BYTES = 8 << 20
    CLEAN = ('why', 'files', 'pages', 'notes')
    SCHEMA = {
        'version': OneOf(REPORT_VERSION),
        'state': OneOf('read', 'not read'),
        'why': Text(),
        'files': Items({'name': Text(255), 'kind': OneOf(*REPORT_KINDS), 'converted': bool,
                        'pages': Number(0, REPORT_FILE_PAGES, integer=True), 'note': Text(),
                        'state': OneOf('read', 'not read'), 'copy': Maybe(Text(255))}, REPORT_FILES),
        'pages': Items({'file': Number(0, REPORT_FILES - 1, integer=True),
                        'number': Number(1, 1e6, integer=True), 'source': OneOf('text', 'ocr'),
                        'text': _REPORT_TEXT, 'layout': _REPORT_TEXT,
                        'confidence': Maybe(Number(0, 100)), 'unsure': Items(Text(100), REPORT_UNSURE),
                        'pictures': Number(0, 1000, integer=True), 'image': Maybe(Text(255))}, REPORT_PAGES),
        'notes': [str],
        'seconds': Number(0, 1e6),
    }
    version: int
    state: str
    why: str
    files: typing.Tuple[ReportFile, ...]
    pages: typing.Tuple[ReportPage, ...]
    notes: typing.Tuple[str, ...]
    seconds: float

    def validate(self):
        if (self.state == 'read') != bool(self.pages):
            raise RecordError('report.json: state %s with %d page(s) read' % (self.state, len(self.pages)))
        if (self.state == 'read') == bool(self.why):
            raise RecordError('report.json: state %s %s a why' % (self.state, 'with' if self.why else 'without'))
        for index, page in enumerate(self.pages):
            if page.file >= len(self.files):
                raise RecordError('report.json.pages[%d].file: %d of %d file(s)' % (index, page.file, len(self.files)))
        for where, path in [('files[%d].copy' % i, f.copy) for i, f in enumerate(self.files)] + \
                [('pages[%d].image' % i, p.image) for i, p in enumerate(self.pages)]:
            if path is not None and not (path.startswith('report/') and _REPORT_NAME.match(path[len('report/'):])):
                raise RecordError('report.json.%s: %s is not a file of report/' % (where, shown(path)))

    @classmethod
    def not_read(cls, why, files=(), notes=(), seconds=0.0):
        """The record of a report that was not read, and why (one sentence)."""
        return cls.make({'version': REPORT_VERSION, 'state': 'not read', 'why': why, 'files': list(files),
                         'pages': [], 'notes': list(notes), 'seconds': seconds})
