"""The typed records that cross the trust boundary: what a box hands back to root. Pure, no rospy.

A box (:mod:`exam_lab.grader.boxed.inspect`, :mod:`~exam_lab.grader.boxed.intake`, the similarity
check) writes one JSON object; root reads it only through :func:`exam_lab.grader.host.egress.read_record`,
which gives the bytes to a record's ``from_json``. That checks every field against the record's
schema (types, ranges, string lengths, list lengths, no unknown keys) and raises :class:`RecordError`
on anything unexpected: a record of an unexpected shape is a crash of that box, never data to use.

Schemas are plain values: a type (``str``, ``int``, ``float``, ``bool``), :class:`Text` (a string of at
most ``n`` characters), :class:`Number` (finite, within bounds), ``[schema]`` (a list of at most
:data:`MAX_ITEMS`; :class:`Items` for another limit), ``{key: schema}`` (an object; :class:`Optional` keys may be missing), :class:`Maybe`
(None or the schema), :class:`OneOf` (one of fixed values), :class:`Map` (an object whose keys are data),
:class:`Row` (a list of fixed length, each item its own schema), a tuple of schemas (any one of them).
"""
import json
import math
import os
import re

from exam_lab.grader.score.safe_text import cleaned
from exam_lab.grader.score.sheets import SHEETS

#: What a grading measured, kept beside grade.json by the runner (its session a :class:`SessionRecord`):
#: a rescore scores it again, the flight plot draws from it.
MEASUREMENTS = 'measurements.json'
#: Longest string of a record (a note, a path) and most items of one list.
MAX_TEXT = 2000
MAX_ITEMS = 500


class RecordError(ValueError):
    """A box's record that does not match its schema: the message says where and why."""


class Text(object):
    def __init__(self, limit=MAX_TEXT):
        self.limit = limit


class Number(object):
    """A number within ``[low, high]``; with ``finite=False`` any float, NaN and infinities too (a value a
    student's node published, which the rubric judges)."""

    def __init__(self, low=-1e12, high=1e12, integer=False, finite=True):
        self.low, self.high, self.integer, self.finite = low, high, integer, finite


class Items(object):
    """A list of at most ``limit`` items, each matching ``schema``."""

    def __init__(self, schema, limit=MAX_ITEMS):
        self.schema, self.limit = schema, limit


class Map(object):
    """An object whose keys are data (node or topic names): at most ``limit`` keys matching ``key``,
    each value matching ``schema``."""

    def __init__(self, key, schema, limit=MAX_ITEMS):
        self.key, self.schema, self.limit = key, schema, limit


class Row(object):
    """A list of exactly ``len(schemas)`` items, each matching its own schema (``[t, request]``)."""

    def __init__(self, *schemas):
        self.schemas = schemas


class Maybe(object):
    def __init__(self, schema):
        self.schema = schema


class Optional(object):
    """A key of an object that may be missing."""

    def __init__(self, schema):
        self.schema = schema


class OneOf(object):
    def __init__(self, *values):
        self.values = values


def check(value, schema, where='record'):
    """``value`` when it matches ``schema``; raises :class:`RecordError` naming ``where`` otherwise."""
    if isinstance(schema, (Maybe, Optional)):
        return None if value is None and isinstance(schema, Maybe) else check(value, schema.schema, where)
    if isinstance(schema, OneOf):
        if isinstance(value, bool) or value not in schema.values:
            raise RecordError('%s: %s is not one of %s' % (where, _shown(value), ', '.join(map(str, schema.values))))
        return value
    if isinstance(schema, tuple):  # the first that matches
        for inner in schema:
            try:
                return check(value, inner, where)
            except RecordError:
                continue
        raise RecordError('%s: %s is of none of the expected types' % (where, _shown(value)))
    if schema is str:
        schema = Text()
    if isinstance(schema, Text):
        if not isinstance(value, str):
            raise RecordError('%s: a string expected, got %s' % (where, type(value).__name__))
        if len(value) > schema.limit:
            raise RecordError('%s: a string of %d characters (at most %d)' % (where, len(value), schema.limit))
        return value
    if schema is bool:
        if not isinstance(value, bool):
            raise RecordError('%s: true or false expected, got %s' % (where, type(value).__name__))
        return value
    if schema in (int, float):
        schema = Number(integer=schema is int)
    if isinstance(schema, Number):
        wanted = int if schema.integer else (int, float)
        if isinstance(value, bool) or not isinstance(value, wanted):
            raise RecordError('%s: %s expected, got %s' % (where, 'an integer' if schema.integer else 'a number',
                                                           type(value).__name__))
        if schema.finite and not (math.isfinite(value) and schema.low <= value <= schema.high):
            raise RecordError('%s: %s is outside [%g, %g]' % (where, _shown(value), schema.low, schema.high))
        return value
    if isinstance(schema, list):
        schema = Items(schema[0])
    if isinstance(schema, Items):
        if not isinstance(value, list):
            raise RecordError('%s: a list expected, got %s' % (where, type(value).__name__))
        if len(value) > schema.limit:
            raise RecordError('%s: %d %s (at most %d)' % (where, len(value), _noun(where), schema.limit))
        return [check(item, schema.schema, '%s[%d]' % (where, index)) for index, item in enumerate(value)]
    if isinstance(schema, Row):
        if not isinstance(value, list) or len(value) != len(schema.schemas):
            raise RecordError('%s: a list of %d items expected, got %s' % (where, len(schema.schemas), _shown(value)))
        return [check(item, inner, '%s[%d]' % (where, index))
                for index, (item, inner) in enumerate(zip(value, schema.schemas))]
    if isinstance(schema, Map):
        if not isinstance(value, dict):
            raise RecordError('%s: an object expected, got %s' % (where, type(value).__name__))
        if len(value) > schema.limit:
            raise RecordError('%s: %d keys (at most %d)' % (where, len(value), schema.limit))
        return {check(key, schema.key, '%s key' % where): check(inner, schema.schema, '%s[%s]' % (where, _shown(key)))
                for key, inner in value.items()}
    if isinstance(schema, dict):
        if not isinstance(value, dict):
            raise RecordError('%s: an object expected, got %s' % (where, type(value).__name__))
        unknown = sorted(set(value) - set(schema))
        if unknown:
            raise RecordError('%s: unexpected key(s) %s' % (where, ', '.join(_shown(k) for k in unknown[:5])))
        checked = {}
        for key, inner in schema.items():
            if key not in value:
                if isinstance(inner, Optional):
                    continue
                raise RecordError('%s: %s is missing' % (where, key))
            checked[key] = check(value[key], inner, '%s.%s' % (where, key))
        return checked
    raise TypeError('not a schema: %r' % (schema,))


def _noun(where):
    """What a list at ``where`` holds, for its cap's sentence: ``inspect.json.comments.files`` holds files."""
    key = where.rsplit('.', 1)[-1]
    return key.replace('_', ' ') if re.match(r'^[a-z_]+s$', key) else 'items'


def _shown(value):
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + '...'


def parse(raw, schema, what, constants=False):
    """The JSON object in ``raw`` (bytes), checked against ``schema``; with ``constants``, NaN and
    Infinity are numbers (Python's json writes them for a non-finite float)."""
    try:
        value = json.loads(raw.decode('utf-8'), parse_constant=None if constants else _no_constant)
    except (UnicodeDecodeError, ValueError) as err:
        raise RecordError('%s: not JSON: %s' % (what, err))
    return check(value, schema, what)


def _no_constant(name):
    raise ValueError('%s is not a number JSON allows' % name)


def _relative(path, where):
    """A path inside the workspace: relative, without '..' (root joins it to a folder of its own)."""
    if path.startswith('/') or '\0' in path or '..' in path.split('/'):
        raise RecordError('%s: %s is not a path inside the workspace' % (where, _shown(path)))
    return path


class Record(object):
    """A record type: its file's name (``FILE``), its cap (``MAX_BYTES``), its ``SCHEMA``; a record's
    attributes are the schema's keys (None when an optional one is missing), ``value`` the whole
    checked object. With ``CLEAN``, every string of the record, keys too, is
    :func:`~exam_lab.grader.score.safe_text.clean` once it matched its schema: the one place where
    a student's text (node and topic names, log lines, a request) is made safe, whoever reads the
    record later. ``NON_FINITE``: NaN and Infinity may be read from its JSON (measured values)."""
    FILE = MAX_BYTES = SCHEMA = None
    CLEAN = NON_FINITE = False

    def __init__(self, value):
        self.value = value
        self.__dict__.update({key: value.get(key) for key in self.SCHEMA})

    @classmethod
    def from_json(cls, raw, max_bytes):
        """The record in ``raw`` (bytes); raises :class:`RecordError` on anything unexpected."""
        if len(raw) > max_bytes:
            raise RecordError('%s: %d bytes (at most %d)' % (cls.FILE, len(raw), max_bytes))
        return cls._made(parse(raw, cls.SCHEMA, cls.FILE, constants=cls.NON_FINITE))

    @classmethod
    def make(cls, value):
        """The record of ``value`` (made by the grader itself from what it read): checked as one read
        from a file is; raises :class:`RecordError`."""
        return cls._made(check(value, cls.SCHEMA, cls.FILE))

    @classmethod
    def _made(cls, value):
        record = cls(cleaned(value) if cls.CLEAN else value)
        record.validate()
        return record

    def to_json(self):
        """The record's JSON text: :meth:`from_json` of it gives the same record."""
        return json.dumps(self.value, indent=1, sort_keys=True)

    def validate(self):
        """Checks across fields, beyond the schema's."""


def write(folder, record_type, value):
    """Write ``value`` as ``folder/<record_type.FILE>`` (checked first: a box's own bug shows there),
    atomically: the reader finds the whole record or none."""
    check(value, record_type.SCHEMA, record_type.FILE)
    partial = os.path.join(folder, record_type.FILE + '.part')
    with open(partial, 'w') as f:
        json.dump(value, f, sort_keys=True)
    os.rename(partial, os.path.join(folder, record_type.FILE))


#: What the inspection read of the package for the rubric (``static`` of :func:`~exam_lab.grader.score.rubric.score`).
STATIC = {
    'launch_files': [str], 'package': Text(255), 'python2': [str], 'params_in_code': [str],
    'args_in_code': Optional([str]),
    'code': Optional({'service_calls': [str], 'publishes': [str], 'timers': [str],
                      'private_before_init': Optional([str])}),
    'launch': Maybe({'file': str, 'starts_drone': bool, 'exam_type': str, 'exam_name': str, 'package': Text(255),
                     'comments': Number(0, 1e9, integer=True), 'exam_type_found': bool}),
    'threshold': Maybe({'name': str, 'value': Maybe((str, Number(), bool)), 'where': str,
                        'how': Optional(OneOf('param', 'args')), 'run_value': Optional(float),
                        'not_rewritable': Optional(str)}),
    'threshold_reason': str,
    'uploads': Optional(Items({'files': [str], 'chosen': str, 'why': str, 'ambiguous': bool}, 20)),
}


class InspectRecord(Record):
    """What :mod:`exam_lab.grader.boxed.inspect` read in one submission (``inspect.json``).

    ``refused``: why the upload could not be opened (then only ``notes``, ``fixes``, ``facts`` and
    ``uid`` mean anything). ``main_launch`` / ``threshold_launch``: the derived launch files, relative
    to the workspace (None: no threshold run; ``main_launch`` None: no node to run). ``comments``:
    ``{"comments", "code", "files"}`` of the student's code. ``facts``: participant, folder, documents.
    """
    FILE = 'inspect.json'
    MAX_BYTES = 1 << 20
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
                           'files': [str]}),
        'facts': {'participant': Maybe(Number(0, 1e15, integer=True)), 'folder': Text(255),
                  'documents': [{'name': str, 'pages': Maybe(Number(0, 1e6, integer=True))}]},
    }

    def validate(self):
        for key in ('main_launch', 'threshold_launch', 'handed_in_launch'):
            if getattr(self, key) is not None:
                _relative(getattr(self, key), 'inspect.json.%s' % key)
        if self.threshold_launch is not None and self.main_launch is None:
            raise RecordError('inspect.json: a threshold run without a main run')
        if self.threshold_launch is not None and self.threshold_run_value is None:
            raise RecordError('inspect.json: a threshold run without its value')


class IntakeRecord(Record):
    """A class archive unpacked by :mod:`exam_lab.grader.boxed.intake` (``intake.json``): ``students``,
    each ``{"name", "path"}`` with ``path`` relative to the intake's output folder, and ``refused``
    (why) when that student's files were not unpacked. A class may be larger than any other list's cap."""
    FILE = 'intake.json'
    MAX_BYTES = 16 << 20
    MAX_STUDENTS = 10000
    SCHEMA = {'uid': Number(0, 2 ** 32, integer=True),
              'students': Items({'name': Text(255), 'path': Text(4096), 'refused': Optional(Text())}, MAX_STUDENTS)}

    def validate(self):
        for index, student in enumerate(self.students):
            where = 'intake.json.students[%d]' % index
            _relative(student['path'], where + '.path')
            name = student['name']
            if name in ('', '.', '..') or name != name.strip(' .') or \
                    not all(c.isalnum() or c in ' -._' for c in name):
                raise RecordError('%s.name: %s is not a student\'s name (a folder name of letters, digits, '
                                  'space and -._)' % (where, _shown(name)))


#: A share of code (0..1, a little more by rounding).
_SHARE = Number(0, 10)


class SimilarityRecord(Record):
    """The class's similarity check (:func:`exam_lab.grader.boxed.similarity.check`,
    ``similarity.json``): flagged ``pairs`` with their best files' highlighted HTML (escaped by the
    detector; the page escapes nothing more), every pair's ``scores``, ``notes``; or ``error``."""
    FILE = 'similarity.json'
    MAX_BYTES = 32 << 20
    SCHEMA = {
        'error': Optional(Text(20000)), 'notes': [str],
        'pairs': Optional(Items({'a': Text(255), 'b': Text(255), 'score_a': _SHARE, 'score_b': _SHARE,
                                 'files': [{'file_a': str, 'file_b': str, 'sim_a': _SHARE, 'sim_b': _SHARE,
                                            'html_a': Text(1 << 20), 'html_b': Text(1 << 20)}]}, 5000)),
        'students': Optional(Number(0, 1e5, integer=True)), 'threshold': Optional(_SHARE),
        'detector': Optional(Text(100)), 'scores': Optional(Items(Items((Text(255), _SHARE), 4), 200000)),
    }

    def validate(self):
        for index, pair in enumerate(self.pairs or []):
            for inner, match in enumerate(pair['files']):
                for key in ('html_a', 'html_b'):
                    if '<' in _HIGHLIGHT.sub('', match[key]):
                        raise RecordError('similarity.json.pairs[%d].files[%d].%s: markup other than the '
                                          "detector's highlight" % (index, inner, key))


#: The only markup of the detector's HTML (the page shows it as is): its highlight spans.
_HIGHLIGHT = re.compile(r"<span class='highlight-(?:red|green)'>|</span>")


#: A value the student's node published or the flight was computed from: any float (NaN, infinities).
_VALUE = Number(finite=False)
#: A ROS name (node, topic, service, type) as the master gave it: the student's node chose it.
_NAME = Text(1000)
#: A time (the wall clock's seconds, the judge's own).
_TIME = Number()
_COUNT = Number(0, 1e12, integer=True)
#: Most service calls (and answers) of one run: a node that calls in a loop is judged for it, not
#: refused (the probe's result is read up to egress.FILE_CAP bytes: fewer than this many calls fit).
MAX_CALLS = 200000
#: Most node deaths the judge's watch lists in one run (a node respawned in a loop).
MAX_DEATHS = 20000
#: Longest request of a service call the node made; the drone's answer quotes it (repr: each
#: character at most 4), with its own words around.
MAX_REQUEST = MAX_TEXT
_REQUEST = Text(MAX_REQUEST)
_ANSWER = Text(4 * MAX_REQUEST + 500)

#: One leg of the flight checked on the node's own values (:func:`exam_lab.grader.judge.probe.leg_check`).
LEG = {'side': OneOf('above', 'below'), 'reached': Maybe(_TIME), 'stays': Maybe(_TIME), 'off_side': _COUNT,
       'first': Maybe(_VALUE), 'last': Maybe(_VALUE), 'samples': _COUNT}


class ProbeRecord(Record):
    """The probe's result (:mod:`exam_lab.grader.judge.probe`, ``probe-<tag>.json``): what it measured of
    the student's node in one run, as the rubric reads it. Written by the judge's uid, of names and
    values the student's node chose (node and topic names, requests, published values): root reads it
    through :func:`~exam_lab.grader.host.egress.read_record` and takes a result that does not match for
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
        'nodes': Optional([_NAME]), 'node_seen_s': Optional(Maybe(Number())),
        'subscribed': Optional(Map(_NAME, [_NAME], 10)),
        'input_types': Optional(Map(_NAME, {'type': Maybe(_NAME), 'connected': bool, 'refused': Maybe(Text()),
                                            'adapted': Maybe(_NAME), 'published': Optional(_NAME)}, 10)),
        'output': Optional({'expected': _NAME, 'topic': Maybe(_NAME), 'type': Maybe(_NAME), 'candidates': [_NAME]}),
        'formula': Optional(Items({'inputs': Map(Text(100), _VALUE, 4), 'expected': _VALUE,
                                   'published': Maybe(_VALUE), 'samples': _COUNT}, 20)),
        'calibration': Optional(dict({'by': OneOf('own', 'oracle'), 'reason': Text(), 'fit': Maybe(Row(_VALUE, _VALUE))},
                                     **{side: {'x': _VALUE, 'target': _VALUE, 'value': Maybe(_VALUE)}
                                        for side in ('lo', 'hi', 'near')})),
        'schedule': Optional(Map(Text(50), _TIME, 20)),
        'legs': Optional(Maybe(Map(Text(50), LEG, 20))),
        'rate': Optional({'samples': _COUNT, 'hz': Maybe(Number()), 'max_gap': Maybe(Number()),
                          'non_finite': Optional(_COUNT)}),
        'node_watch': {'deaths': Items({'node': _NAME, 't': Maybe(_TIME), 'detail': Text()}, MAX_DEATHS),
                       'nodes': [_NAME]},
        'calls': Items(Row(_TIME, _REQUEST), MAX_CALLS),
        'answers': Items(Row(_TIME, _REQUEST, bool, _ANSWER), MAX_CALLS),
        'graph': Map(_NAME, {'publishes': Items(Row(_NAME, _NAME)), 'subscribes': Items(Row(_NAME, _NAME)),
                             'services': [_NAME]}),
        'alive_at_end': bool, 't0': _TIME,
        'clock': {'use_sim_time': Items(Maybe((bool, _VALUE, Text())), 2), 'messages': _COUNT,
                  'publishers': [_NAME], 'ros_time_is_wall': bool},
        'judge_uid': Number(0, 2 ** 32, integer=True),
        'trace': {'published': Items(Row(_TIME, Maybe(_VALUE)), 100000), 'oracle': Items(Row(_TIME, _VALUE), 1000)},
    }


#: How one grading ended (``outcome`` of :class:`SessionRecord`): the session's own ('ran': built,
#: the runs tried; 'build_failed', 'build_stopped': by its limit or the budget; 'check_stopped':
#: roslaunch's check stopped by the budget), and the runner's when no session ran or it failed.
OUTCOMES = ('ran', 'build_failed', 'build_stopped', 'check_stopped',
            'session_failed', 'session_killed', 'not_run', 'no_node', 'refused', 'inspection_failed', 'grader_failed')
#: Most characters of a log excerpt (a build's or roslaunch's last lines) in the session's record.
MAX_LOG_TEXT = 20000
#: Most ended nodes roslaunch's output reports in one run (a node respawned in a loop).
MAX_ENDED = 500

_RUN = {
    'tag': OneOf('main', 'threshold'), 'probe': Maybe(ProbeRecord.SCHEMA), 'refused_probe': Optional(ProbeRecord.SCHEMA),
    'probe_error': Optional(Text(MAX_LOG_TEXT)), 'probe_refused': Optional(Text()),
    'probe_status': Optional(Maybe(Number(-1e6, 1e6, integer=True))),
    'master': {'uid': Maybe(Number(0, 2 ** 32, integer=True)),
               'memory': Optional(Maybe({'limit': Maybe(_COUNT), 'peak': Maybe(_COUNT), 'oom_kills': Number(integer=True)}))},
    'probe_uid': Optional(Maybe(Number(0, 2 ** 32, integer=True))),
    'launch': {'ended': Items({'node': _NAME, 'how': OneOf('died', 'finished cleanly'), 'detail': Text()}, MAX_ENDED),
               'not_started': Items(Text(), 50), 'tail': Text(MAX_LOG_TEXT)},
    'launch_running': Optional(bool), 'seconds': Optional(Number(0)), 'budget': Optional(Text()),
    'survivors': Optional(_COUNT),
}


class SessionRecord(Record):
    """How one grading's session went (:mod:`exam_lab.grader.host.session`, ``session.json``): roslaunch's
    check of the launch file, the build, each run (its probe's :class:`ProbeRecord` or why there is none,
    roslaunch's words about the nodes), the processes left, the budget; ``outcome``, one of
    :data:`OUTCOMES`. The runner makes one too when no session ran (``error``, ``refused``,
    ``no_node``): the measurements a rescore reads hold this record."""
    FILE = 'session.json'
    MAX_BYTES = 24 << 20
    CLEAN = NON_FINITE = True
    SCHEMA = {
        'outcome': OneOf(*OUTCOMES),
        'build': Maybe({'status': Maybe(Number(-1e6, 1e6, integer=True)), 'seconds': Number(0), 'tail': Text(MAX_LOG_TEXT),
                        'timeout': Number(0), 'stopped': Optional(Text())}),
        'runs': Items(_RUN, 2),
        'survivors': Optional(_COUNT),
        'launch_check': Optional(Maybe({'file': Text(4096), 'status': Maybe(Number(-1e6, 1e6, integer=True)),
                                        'refused': Text(MAX_LOG_TEXT), 'warnings': Items(Text(), 20),
                                        'nodes': Items(_NAME, 20)})),
        'budget_used': Optional(Maybe(Text())), 'error': Optional(Text(MAX_LOG_TEXT)),
        'threshold_skipped': Optional(Text()), 'refused': Optional(bool), 'no_node': Optional(bool),
    }
