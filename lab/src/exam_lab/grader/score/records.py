"""The typed records that cross the trust boundary: what a box hands back to root. Pure, no rospy.

A box (:mod:`exam_lab.grader.boxed.inspect`, :mod:`~exam_lab.grader.boxed.intake`, the similarity
check) writes one JSON object; root reads it only through :func:`exam_lab.grader.host.egress.read_record`,
which gives the bytes to a record's ``from_json``. That checks every field against the record's
schema (types, ranges, string lengths, list lengths, no unknown keys) and raises :class:`RecordError`
on anything unexpected: a record of an unexpected shape is a crash of that box, never data to use.

Schemas are plain values: a type (``str``, ``int``, ``float``, ``bool``), :class:`Text` (a string of at
most ``n`` characters), :class:`Number` (finite, within bounds), ``[schema]`` (a list of at most
:data:`MAX_ITEMS`; :class:`Items` for another limit), ``{key: schema}`` (an object; :class:`Optional` keys may be missing), :class:`Maybe`
(None or the schema), :class:`OneOf` (one of fixed values), a tuple of schemas (any one of them).
"""
import json
import math
import os
import re

from exam_lab.grader.score.sheets import SHEETS

#: Longest string of a record (a note, a path) and most items of one list.
MAX_TEXT = 2000
MAX_ITEMS = 500


class RecordError(ValueError):
    """A box's record that does not match its schema: the message says where and why."""


class Text(object):
    def __init__(self, limit=MAX_TEXT):
        self.limit = limit


class Number(object):
    def __init__(self, low=-1e12, high=1e12, integer=False):
        self.low, self.high, self.integer = low, high, integer


class Items(object):
    """A list of at most ``limit`` items, each matching ``schema``."""

    def __init__(self, schema, limit=MAX_ITEMS):
        self.schema, self.limit = schema, limit


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
        if not (math.isfinite(value) and schema.low <= value <= schema.high):
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


def parse(raw, schema, what):
    """The JSON object in ``raw`` (bytes), checked against ``schema``."""
    try:
        value = json.loads(raw.decode('utf-8'), parse_constant=_no_constant)
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
    checked object."""
    FILE = MAX_BYTES = SCHEMA = None

    def __init__(self, value):
        self.value = value
        self.__dict__.update({key: value.get(key) for key in self.SCHEMA})

    @classmethod
    def from_json(cls, raw, max_bytes):
        """The record in ``raw`` (bytes); raises :class:`RecordError` on anything unexpected."""
        if len(raw) > max_bytes:
            raise RecordError('%s: %d bytes (at most %d)' % (cls.FILE, len(raw), max_bytes))
        record = cls(parse(raw, cls.SCHEMA, cls.FILE))
        record.validate()
        return record

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
