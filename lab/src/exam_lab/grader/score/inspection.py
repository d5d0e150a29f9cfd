"""What the inspection's box read of one submission (``inspect.json``): the package's facts for the
rubric (:data:`STATIC`), the code's comments, who handed it in, the derived launch files. Pure, no rospy.

:mod:`exam_lab.grader.boxed.inspect` writes it as the box's uid; root reads it through
:func:`exam_lab.grader.contract.read_record` as an :class:`InspectRecord`, a frozen dataclass, checked
and its text cleaned once; the runner makes the job from it (:func:`exam_lab.grader.runner.plan_job`)
and keeps its ``static``, ``comments`` and ``facts`` in the measurements as JSON data.
"""
import typing
from dataclasses import dataclass

from exam_lab.grader.score.schema import DataRecord, Items, Maybe, Number, OneOf, Optional, RecordError, Text, relative
from exam_lab.grader.score.sheets import SHEETS


#: What the inspection read of the package for the rubric (``static`` of :func:`~exam_lab.grader.score.rubric.score`).
STATIC = {
    'launch_files': [str], 'package': Text(255), 'python2': [str], 'params_in_code': [str],
    'args_in_code': Optional([str]),
    'code': Optional({'service_calls': [str], 'publishes': [str], 'timers': [str],
                      'private_before_init': Optional([str])}),
    'launch': Maybe({'file': str, 'starts_drone': bool, 'exam_type': str, 'exam_name': str, 'package': Text(255),
                     'comments': Number(0, 1e9, integer=True), 'exam_type_found': bool,
                     'repairs': Optional([str])}),
    'launch_unread': Optional(str),
    'threshold': Maybe({'name': str, 'value': Maybe((str, Number(), bool)), 'where': str,
                        'how': Optional(OneOf('param', 'args')), 'run_value': Optional(float),
                        'not_rewritable': Optional(str)}),
    'threshold_reason': str,
    'uploads': Optional(Items({'files': [str], 'chosen': str, 'why': str, 'ambiguous': bool}, 20)),
}


#: A function or block of the student's code, commented or not (:func:`~exam_lab.grader.boxed.source.comment_units`).
COMMENT_UNIT = {'file': Text(500), 'line': Number(0, 1e7, integer=True), 'kind': Text(20), 'name': Text(200),
                'commented': bool}
#: A sign of bad practice in the code (:func:`~exam_lab.grader.boxed.source.quality_signals`).
QUALITY_SIGNAL = {'file': Text(500), 'line': Number(0, 1e7, integer=True), 'kind': Text(50), 'detail': Text(500)}


@dataclass(frozen=True)
class Upload(object):
    """Files of one kind handed in, and the one graded (``uploads`` of :data:`STATIC`)."""
    files: typing.Tuple[str, ...]
    chosen: str
    why: str
    ambiguous: bool


@dataclass(frozen=True)
class CodeFacts(object):
    """What the code calls, publishes and times (``code`` of :data:`STATIC`)."""
    service_calls: typing.Tuple[str, ...]
    publishes: typing.Tuple[str, ...]
    timers: typing.Tuple[str, ...]
    private_before_init: typing.Optional[typing.Tuple[str, ...]] = None


@dataclass(frozen=True)
class LaunchFacts(object):
    """The launch file graded (``launch`` of :data:`STATIC`)."""
    file: str
    starts_drone: bool
    exam_type: str
    exam_name: str
    package: str
    comments: int
    exam_type_found: bool
    repairs: typing.Optional[typing.Tuple[str, ...]] = None


@dataclass(frozen=True)
class ThresholdFacts(object):
    """The threshold parameter as handed in (``threshold`` of :data:`STATIC`): its name, its value as
    written, where, how it is given, the value the threshold run flies."""
    name: str
    value: typing.Union[str, float, bool, None]
    where: str
    how: typing.Optional[str] = None
    run_value: typing.Optional[float] = None
    not_rewritable: typing.Optional[str] = None


@dataclass(frozen=True)
class StaticFacts(object):
    """What the inspection read of the package for the rubric (:data:`STATIC`)."""
    launch_files: typing.Tuple[str, ...]
    package: str
    python2: typing.Tuple[str, ...]
    params_in_code: typing.Tuple[str, ...]
    launch: typing.Optional[LaunchFacts]
    threshold: typing.Optional[ThresholdFacts]
    threshold_reason: str
    args_in_code: typing.Optional[typing.Tuple[str, ...]] = None
    code: typing.Optional[CodeFacts] = None
    launch_unread: typing.Optional[str] = None
    uploads: typing.Optional[typing.Tuple[Upload, ...]] = None


@dataclass(frozen=True)
class CommentUnit(object):
    """A function or block of the student's code, commented or not (:data:`COMMENT_UNIT`)."""
    file: str
    line: int
    kind: str
    name: str
    commented: bool


@dataclass(frozen=True)
class QualitySignal(object):
    """A sign of bad practice in the code (:data:`QUALITY_SIGNAL`)."""
    file: str
    line: int
    kind: str
    detail: str


@dataclass(frozen=True)
class Comments(object):
    """How much of the code is commented: comment and code lines, the files read, each unit, the
    quality signals found."""
    comments: int
    code: int
    files: typing.Tuple[str, ...]
    units: typing.Optional[typing.Tuple[CommentUnit, ...]] = None
    quality: typing.Optional[typing.Tuple[QualitySignal, ...]] = None


@dataclass(frozen=True)
class Document(object):
    """A PDF handed in, and its pages (None: not counted)."""
    name: str
    pages: typing.Optional[int]


@dataclass(frozen=True)
class Facts(object):
    """Who and what was handed in: the participant number (as the box read the entry's name; root
    uses its own), the folder's name, the documents."""
    participant: typing.Optional[int]
    folder: str
    documents: typing.Tuple[Document, ...]


@dataclass(frozen=True)
class InspectRecord(DataRecord):
    """What :mod:`exam_lab.grader.boxed.inspect` read in one submission (``inspect.json``).

    ``refused``: why the upload could not be opened (then only ``notes``, ``fixes``, ``facts`` and
    ``uid`` mean anything). ``main_launch`` / ``threshold_launch``: the derived launch files, relative
    to the workspace (None: no threshold run; ``main_launch`` None: no node to run). ``comments``:
    how much of the student's code is commented (:class:`Comments`). ``facts``: participant, folder,
    documents (:class:`Facts`). ``static``: what the rubric reads of the package (:class:`StaticFacts`).
    """
    FILE = 'inspect.json'
    MAX_BYTES = 1 << 20
    #: The student's text (notes and fixes quoting its files, the launch file's and the code's words,
    #: the documents' names) made safe here; the launch files' paths are opened by the session and
    #: the code's file names (``comments``) are kept exactly (the measurements keep them so).
    CLEAN = ('refused', 'notes', 'fixes', 'static', 'facts')
    SCHEMA = {
        'uid': Number(0, 2 ** 32, integer=True),
        'refused': Maybe(str),
        'sheet': OneOf(*sorted(SHEETS)),
        'notes': [str], 'fixes': [str],
        'static': Maybe(STATIC),
        'threshold_value': float,
        'calls_service': bool,
        'namespace': str,
        'main_launch': Maybe(str), 'threshold_launch': Maybe(str),
        'threshold_run_value': Optional(Maybe(float)),
        'handed_in_launch': Optional(Maybe(str)),
        'comments': Maybe({'comments': Number(0, 1e9, integer=True), 'code': Number(0, 1e9, integer=True),
                           'files': [str], 'units': Optional(Items(COMMENT_UNIT, 300)),
                           'quality': Optional(Items(QUALITY_SIGNAL, 100))}),
        'facts': {'participant': Maybe(Number(0, 1e15, integer=True)), 'folder': Text(255),
                  'documents': [{'name': str, 'pages': Maybe(Number(0, 1e6, integer=True))}]},
    }
    uid: int
    refused: typing.Optional[str]
    sheet: str
    notes: typing.Tuple[str, ...]
    fixes: typing.Tuple[str, ...]
    static: typing.Optional[StaticFacts]
    threshold_value: float
    calls_service: bool
    namespace: str
    main_launch: typing.Optional[str]
    threshold_launch: typing.Optional[str]
    comments: typing.Optional[Comments]
    facts: Facts
    threshold_run_value: typing.Optional[float] = None
    handed_in_launch: typing.Optional[str] = None

    def validate(self):
        for key in ('main_launch', 'threshold_launch', 'handed_in_launch'):
            if getattr(self, key) is not None:
                relative(getattr(self, key), 'inspect.json.%s' % key)
        if self.threshold_launch is not None and self.main_launch is None:
            raise RecordError('inspect.json: a threshold run without a main run')
        if self.threshold_launch is not None and self.threshold_run_value is None:
            raise RecordError('inspect.json: a threshold run without its value')
