"""A record's value read by attributes: ``probe.output.topic`` for ``probe['output']['topic']``. Pure,
no rospy.

:func:`view` follows the record's schema (:mod:`exam_lab.grader.score.records`): an object of fixed
keys (``{key: schema}``) reads as attributes, and a key it lacks reads None (an optional key, or one a
measurement kept from before did not have); a name the schema does not have raises AttributeError, so
a misspelt key is an error, never a silent None. An object whose keys are data (a
:class:`~exam_lab.grader.score.schema.Map`: topics, nodes, legs) stays a mapping; a list is a tuple.
Nothing of a view can be set: a reader cannot change what the next one reads.
"""
from collections.abc import Mapping

from exam_lab.grader.score.schema import Items, Map, Maybe, Optional, Record, Row


class Fields(object):
    """An object of fixed keys, read by attributes (see :func:`view`): each field is made a view the first
    time it is read, so a reader pays only for what it reads (a probe's trace of 100000 values is never
    copied by a rule that reads its rate)."""
    __slots__ = ('_value', '_schema', '_read')

    def __init__(self, value, schema):
        object.__setattr__(self, '_value', value)
        object.__setattr__(self, '_schema', schema)
        object.__setattr__(self, '_read', {})

    def __getattr__(self, name):
        if name.startswith('_'):  # no field's name: an attribute of its own not yet set (a copy being made)
            raise AttributeError(name)
        read = self._read
        if name not in read:
            if name not in self._schema:
                raise AttributeError('no field %r (fields: %s)' % (name, ', '.join(sorted(self._schema))))
            read[name] = view(self._value.get(name), self._schema[name])
        return read[name]

    def __bool__(self):
        """False for an empty object, as its dict is (``probe or ...`` reads as it did on the dict)."""
        return any(key in self._schema for key in self._value)

    def __setattr__(self, name, value):
        raise AttributeError('a record is read-only: cannot set %r' % name)

    def __delattr__(self, name):
        raise AttributeError('a record is read-only: cannot delete %r' % name)

    def __copy__(self):
        return self  # nothing of it can change: its copy is itself, as a tuple's is

    def __deepcopy__(self, memo):
        return self

    def __repr__(self):
        return 'Fields(%s)' % ', '.join(sorted(key for key in self._value if key in self._schema))


class Table(Mapping):
    """An object whose keys are data (a schema's :class:`~exam_lab.grader.score.schema.Map`), read-only."""
    __slots__ = ('_items',)

    def __init__(self, items):
        object.__setattr__(self, '_items', items)

    def __getitem__(self, key):
        return self._items[key]

    def __iter__(self):
        return iter(self._items)

    def __len__(self):
        return len(self._items)

    def __setattr__(self, name, value):
        raise AttributeError('a record is read-only: cannot set %r' % name)

    def __repr__(self):
        return 'Table(%r)' % (self._items,)


def view(value, schema=None):
    """The read-only view of ``value``, a record's value (or a part of one) of ``schema``, or a
    :class:`~exam_lab.grader.score.schema.Record` (of its own schema by default); None stays
    None, and a view is its own view. A value whose shape is not the schema's (an object where a list
    is expected) is given as it is: the schema's check is the record's, not the reader's. The view
    reads ``value`` as it is when a field is first read: nothing is copied before."""
    if value is None or isinstance(value, (Fields, Table)):
        return value
    if isinstance(value, Record):
        return view(value.value, value.SCHEMA if schema is None else schema)
    while isinstance(schema, (Maybe, Optional)):
        schema = schema.schema
    if isinstance(schema, tuple):  # one of several schemas: the first of the value's shape
        schema = next((inner for inner in schema if _shape(inner) == _shape_of(value)), None)
    shape = _shape(schema)
    if shape != _shape_of(value):
        return value
    if isinstance(schema, dict):
        return Fields(value, schema)
    if isinstance(schema, Map):
        return Table({key: view(inner, schema.schema) for key, inner in value.items()})
    if isinstance(schema, Row):
        if _flat(schema):
            return tuple(value)
        return tuple(view(item, schema.schemas[index]) if index < len(schema.schemas) else item
                     for index, item in enumerate(value))
    if shape == 'list':
        inner = schema[0] if isinstance(schema, list) else schema.schema
        if _shape(inner) == 'scalar':
            return tuple(value)
        if isinstance(inner, Row) and _flat(inner):  # calls, answers, a trace: rows of numbers and text
            return tuple(tuple(row) if isinstance(row, list) else row for row in value)
        return tuple(view(item, inner) for item in value)
    return value


def _flat(row):
    """True when every item of a :class:`~exam_lab.grader.score.schema.Row` is a scalar."""
    return all(_shape(inner) == 'scalar' for inner in row.schemas)


def _shape(schema):
    """'object', 'list' or 'scalar': the kind of value ``schema`` describes."""
    while isinstance(schema, (Maybe, Optional)):
        schema = schema.schema
    if isinstance(schema, (dict, Map)):
        return 'object'
    if isinstance(schema, (list, Items, Row)):
        return 'list'
    return 'scalar'


def _shape_of(value):
    if isinstance(value, dict):
        return 'object'
    if isinstance(value, (list, tuple)):
        return 'list'
    return 'scalar'
