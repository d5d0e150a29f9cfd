"""The schema machinery of the grader's records (:mod:`exam_lab.grader.score.records`,
:mod:`exam_lab.grader.score.kept`): a schema, the check of a value against it, the base of every
record type. Pure, no rospy.

Schemas are plain values: a type (``str``, ``int``, ``float``, ``bool``), :class:`Text` (a string of at
most ``n`` characters), :class:`Number` (finite, within bounds), ``[schema]`` (a list of at most
:data:`MAX_ITEMS`; :class:`Items` for another limit), ``{key: schema}`` (an object; :class:`Optional` keys may be missing), :class:`Maybe`
(None or the schema), :class:`OneOf` (one of fixed values), :class:`Map` (an object whose keys are data),
:class:`Row` (a list of fixed length, each item its own schema), a tuple of schemas (any one of them).
"""
import collections.abc
import dataclasses
import json
import math
import os
import re
import types
import typing

from exam_lab.grader.score.safe_text import cleaned

#: Longest string of a record (a note, a path) and most items of one list.
MAX_TEXT = 2000
MAX_ITEMS = 500


#: What stands for the middle of a text that was cut.
CUT_MARK = ' [...] '


def cut(text, limit=MAX_TEXT):
    """``text`` in at most ``limit`` characters: its middle replaced by CUT_MARK (a ``file:line``
    keeps its file's start and its line)."""
    if len(text) <= limit:
        return text
    head = (limit - len(CUT_MARK)) // 2
    return text[:head] + CUT_MARK + text[len(text) - (limit - len(CUT_MARK) - head):]


def closed(notes, what='notes', limit=MAX_ITEMS, keep=()):
    """``notes`` (texts for the teacher) within ``limit`` items, the last saying how many more there
    were, each cut to MAX_TEXT; those in ``keep`` (the sentences of caps) are never left out."""
    if len(notes) <= limit:
        return [cut(n) for n in notes]
    keep = set(keep)
    room = limit - 1 - sum(1 for n in notes if n in keep)
    out = []
    for note in notes:
        if note in keep or room > 0:
            room -= note not in keep
            out.append(cut(note))
    return out[:limit - 1] + ['%d %s (at most %d): the first %d kept' % (len(notes), what, limit, min(len(out), limit - 1))]


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
            raise RecordError('%s: %s is not one of %s' % (where, shown(value), ', '.join(map(str, schema.values))))
        return value
    if isinstance(schema, tuple):  # the first that matches; else why the last did not
        why = None
        for inner in schema:
            try:
                return check(value, inner, where)
            except RecordError as err:
                why = err
        raise RecordError('%s: %s is of none of the expected types (%s)' % (where, shown(value), why))
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
            raise RecordError('%s: %s is outside [%g, %g]' % (where, shown(value), schema.low, schema.high))
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
            raise RecordError('%s: a list of %d items expected, got %s' % (where, len(schema.schemas), shown(value)))
        return [check(item, inner, '%s[%d]' % (where, index))
                for index, (item, inner) in enumerate(zip(value, schema.schemas))]
    if isinstance(schema, Map):
        if not isinstance(value, dict):
            raise RecordError('%s: an object expected, got %s' % (where, type(value).__name__))
        if len(value) > schema.limit:
            raise RecordError('%s: %d keys (at most %d)' % (where, len(value), schema.limit))
        return {check(key, schema.key, '%s key' % where): check(inner, schema.schema, '%s[%s]' % (where, shown(key)))
                for key, inner in value.items()}
    if isinstance(schema, dict):
        if not isinstance(value, dict):
            raise RecordError('%s: an object expected, got %s' % (where, type(value).__name__))
        unknown = sorted(set(value) - set(schema))
        if unknown:
            raise RecordError('%s: unexpected key(s) %s' % (where, ', '.join(shown(k) for k in unknown[:5])))
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


def shown(value):
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + '...'


def parse(raw, schema, what, constants=False):
    """The JSON object in ``raw`` (bytes), checked against ``schema``; with ``constants``, NaN and
    Infinity are numbers (Python's json writes them for a non-finite float)."""
    return check(load(raw, what, constants), schema, what)


def load(raw, what, constants=False):
    """The JSON value in ``raw`` (bytes), unchecked; raises :class:`RecordError` naming ``what``."""
    try:
        return json.loads(raw.decode('utf-8'), parse_constant=None if constants else _no_constant)
    except (UnicodeDecodeError, ValueError) as err:
        raise RecordError('%s: not JSON: %s' % (what, err))


def _no_constant(name):
    raise ValueError('%s is not a number JSON allows' % name)


def relative(path, where):
    """A path inside the workspace: relative, without '..' (root joins it to a folder of its own)."""
    if path.startswith('/') or '\0' in path or '..' in path.split('/'):
        raise RecordError('%s: %s is not a path inside the workspace' % (where, shown(path)))
    return path


class _ReadOnly(object):
    """What :class:`Frozen` and :class:`FrozenList` share: every change refused, a copy itself, a deep
    copy plain (:func:`thawed`), a pickle of the plain value."""
    __slots__ = ()

    def _refuse(self, *args, **kwargs):
        raise TypeError('a record is read-only: make a new value (dict(value, key=...)) and a new record')

    def __copy__(self):
        return self

    def __deepcopy__(self, memo):
        return thawed(self)

    def __reduce__(self):
        return type(self), (self._PLAIN(self),)


class Frozen(_ReadOnly, dict):
    """An object of a record: read as a dict is (``json`` writes it, ``isinstance(x, dict)`` holds,
    ``dict(x, key=...)`` is a new plain one), changed by nothing: a record made is the record every
    later reader sees. ``copy.deepcopy`` gives a plain, changeable copy (:func:`thawed`)."""
    __slots__ = ()
    _PLAIN = dict
    __setitem__ = __delitem__ = __ior__ = clear = pop = popitem = setdefault = update = _ReadOnly._refuse


class FrozenList(_ReadOnly, list):
    """A list of a record, read-only as :class:`Frozen` is (``list(x)`` or ``x + [...]`` is a new plain one)."""
    __slots__ = ()
    _PLAIN = list
    __setitem__ = __delitem__ = __iadd__ = __imul__ = append = clear = extend = insert = pop = remove = reverse = \
        sort = _ReadOnly._refuse


def frozen(value):
    """``value`` (JSON data) with every object a :class:`Frozen` and every list a :class:`FrozenList`."""
    if isinstance(value, dict):
        return value if isinstance(value, Frozen) and _all_frozen(value.values()) else \
            Frozen((key, frozen(inner)) for key, inner in value.items())
    if isinstance(value, (list, tuple)):
        return FrozenList(frozen(inner) for inner in value)
    return value


def _all_frozen(values):
    return all(not isinstance(v, (dict, list, tuple)) or isinstance(v, (Frozen, FrozenList)) for v in values)


def thawed(value):
    """A plain, changeable deep copy of ``value`` (a record's value or a part of one)."""
    if isinstance(value, dict):
        return {key: thawed(inner) for key, inner in value.items()}
    if isinstance(value, (list, tuple)):
        return [thawed(inner) for inner in value]
    return value


class _Readable(object):
    """What every record type shares: its file (``FILE``), its cap (``MAX_BYTES``), its ``SCHEMA``;
    read from JSON (:meth:`from_json`, :meth:`read`) through the type's own :meth:`make`. With
    ``CLEAN``, every string of the record, keys too, is :func:`~exam_lab.grader.score.safe_text.clean`
    once it matched its schema (:meth:`cleaned`): the one place where a student's text (node and topic
    names, log lines, a request) is made safe, whoever reads the record later; ``CLEAN`` a tuple of keys
    cleans those fields only (the others are paths to open, or names kept exactly). ``NON_FINITE``:
    NaN and Infinity may be read from its JSON (measured values)."""
    FILE = MAX_BYTES = SCHEMA = None
    CLEAN = NON_FINITE = False
    __slots__ = ()

    @classmethod
    def from_json(cls, raw, max_bytes=None):
        """The record in ``raw`` (bytes), at most ``max_bytes`` (the type's ``MAX_BYTES`` when None);
        raises :class:`RecordError` on anything unexpected."""
        max_bytes = cls.MAX_BYTES if max_bytes is None else max_bytes
        if len(raw) > max_bytes:
            raise RecordError('%s: %d bytes (at most %d)' % (cls.FILE, len(raw), max_bytes))
        return cls.make(load(raw, cls.FILE, constants=cls.NON_FINITE))

    @classmethod
    def read(cls, path):
        """The record in the file ``path``, for a reader that is not root (the judge reads its job) and
        for the tests: read up to ``MAX_BYTES``, then as :meth:`from_json`; raises :class:`RecordError`
        naming the file when it cannot be read. Root reads every file it did not write in this process
        (a box's, the judge's, one kept in OUT) through :func:`exam_lab.grader.contract.read_record`
        (no link, regular files only, never waited on): test_layers holds it to that."""
        try:
            with open(path, 'rb') as f:
                raw = f.read(cls.MAX_BYTES + 1)
        except OSError as err:
            raise RecordError('%s: %s' % (os.path.basename(path), err.strerror or err))
        return cls.from_json(raw)

    @classmethod
    def cleaned(cls, value):
        """The checked ``value`` with its text made safe as ``CLEAN`` says (True: every string, keys
        too; a tuple of keys: those fields only)."""
        if cls.CLEAN is True:
            return cleaned(value)
        if cls.CLEAN:
            return dict(value, **{key: cleaned(value[key]) for key in cls.CLEAN if key in value})
        return value

    def to_json(self):
        """The record's JSON text (its ``value``): :meth:`from_json` of it gives an equal record."""
        return json.dumps(self.value, indent=1, sort_keys=True)

    def validate(self):
        """Checks across fields, beyond the schema's."""


class DataRecord(_Readable):
    """The base of a record type that is a frozen dataclass (``@dataclass(frozen=True)``): its fields
    the schema's keys, each a plain value, a tuple or a frozen dataclass of its own, so nothing of it
    can be changed (``dataclasses.replace`` makes another); a field whose default is None and that is
    None is a key its JSON leaves out (an :class:`Optional` one). :meth:`make` checks a value against
    ``SCHEMA``, cleans it (``CLEAN``), builds the record from it by the fields' types (an object their
    dataclass, a list a tuple) and checks across fields (:meth:`validate`); :attr:`value` is its JSON
    data, which :meth:`make` reads back to an equal record."""
    __slots__ = ()

    @classmethod
    def make(cls, value):
        """The record of ``value`` (JSON data), checked; raises :class:`RecordError`."""
        record = _built(cls, cls.cleaned(check(value, cls.SCHEMA, cls.FILE)))
        record.validate()
        return record

    @property
    def value(self):
        """The record as JSON data: what :meth:`make` reads back."""
        return plain(self)

    def replaced(self, **changes):
        """A new record of this type: this one's fields with ``changes`` (JSON data or the fields'
        own types), checked as :meth:`make` checks (``dataclasses.replace``, checked)."""
        return self.make(dict(self.value, **{key: plain(value) for key, value in changes.items()}))


def _built(hint, value):
    """The checked JSON ``value`` as a field of the type ``hint`` holds it: an object its dataclass
    (``Optional[X]`` an X or None), a list a tuple (``Tuple[X, ...]`` of X), an object whose keys
    are data (``Mapping[str, X]``) a read-only mapping of X."""
    origin, args = getattr(hint, '__origin__', None), getattr(hint, '__args__', ())
    if value is None:
        return None
    if origin is typing.Union:
        return _built(next(arg for arg in args if arg is not type(None)), value)
    if dataclasses.is_dataclass(hint):
        hints = typing.get_type_hints(hint)
        return hint(**{key: _built(hints[key], inner) for key, inner in value.items()})
    if origin is tuple or hint is tuple:
        return tuple(_built(args[0] if args[-1:] == (Ellipsis,) else None, item) for item in value)
    if origin in (collections.abc.Mapping, dict):
        return types.MappingProxyType({key: _built(args[1] if args else None, inner) for key, inner in value.items()})
    return value


def plain(value):
    """JSON data of a frozen dataclass record or of one of its fields (a tuple a list, a mapping an
    object); JSON data stays as it is."""
    if dataclasses.is_dataclass(value):
        return {field.name: plain(getattr(value, field.name)) for field in dataclasses.fields(value)
                if not (field.default is None and getattr(value, field.name) is None)}
    if isinstance(value, (tuple, list)):
        return [plain(item) for item in value]
    if isinstance(value, collections.abc.Mapping):
        return {key: plain(inner) for key, inner in value.items()}
    return value


class Record(_Readable):
    """A record type: its file's name (``FILE``), its cap (``MAX_BYTES``), its ``SCHEMA``; a record's
    attributes are the schema's keys (None when an optional one is missing), ``value`` the whole
    checked object; two records are equal when their JSON is (NaN included). A record is frozen, as a
    frozen dataclass is and deeper: no attribute can be set, and its objects and lists
    (:class:`Frozen`, :class:`FrozenList`) refuse every change, so what a stage hands on is what the
    next one reads; :meth:`replaced` makes a new record of changed fields, checked again."""
    __slots__ = ('value',)

    def __init__(self, value):
        object.__setattr__(self, 'value', frozen(value))

    def __getattr__(self, name):
        if name in self.SCHEMA:
            return self.value.get(name)
        raise AttributeError('%s has no field %r' % (type(self).__name__, name))

    def __setattr__(self, name, value):
        raise AttributeError('a record is read-only: cannot set %r (replaced() makes a new one)' % name)

    def __delattr__(self, name):
        raise AttributeError('a record is read-only: cannot delete %r' % name)

    def replaced(self, **changes):
        """A new record of this type: this one's fields with ``changes``, checked as :meth:`make` checks
        (as ``dataclasses.replace`` does for a dataclass)."""
        return self.make(dict(self.value, **changes))

    def __eq__(self, other):
        return type(self) is type(other) and self.to_json() == other.to_json()

    def __ne__(self, other):
        return not self == other

    __hash__ = None

    @classmethod
    def make(cls, value):
        """The record of ``value`` (made by the grader itself from what it read): checked as one read
        from a file is; raises :class:`RecordError`."""
        return cls._made(check(value, cls.SCHEMA, cls.FILE))

    @classmethod
    def _made(cls, value):
        record = cls(cls.converted(cls.cleaned(value)))
        record.validate()
        return record

    @classmethod
    def converted(cls, value):
        """``value``, checked, with a field of its type made its Python type (a string its enum)."""
        return value


def write(folder, record_type, value):
    """Write ``value`` as ``folder/<record_type.FILE>`` (checked first: a box's own bug shows there),
    atomically: the reader finds the whole record or none."""
    check(value, record_type.SCHEMA, record_type.FILE)
    partial = os.path.join(folder, record_type.FILE + '.part')
    with open(partial, 'w') as f:
        json.dump(value, f, sort_keys=True)
    os.rename(partial, os.path.join(folder, record_type.FILE))
