"""A record's value read by attributes: ``probe.output.topic`` for ``probe['output']['topic']``. Pure,
no rospy.

:func:`view` follows the record's schema (:mod:`exam_lab.grader.score.records`): an object of fixed
keys (``{key: schema}``) reads as attributes, and a key it lacks reads None (an optional key, or one a
measurement kept from before did not have); a name the schema does not have raises AttributeError, so
a misspelt key is an error, never a silent None. An object whose keys are data (a
:class:`~exam_lab.grader.score.records.Map`: topics, nodes, legs) stays a mapping; a list is a tuple.
Nothing of a view can be set: a reader cannot change what the next one reads.
"""
from collections.abc import Mapping

from exam_lab.grader.score.records import Items, Map, Maybe, Optional, Row


class Fields(object):
    """An object of fixed keys, read by attributes (see :func:`view`)."""
    __slots__ = ('_values', '_keys')

    def __init__(self, values, keys):
        object.__setattr__(self, '_values', values)
        object.__setattr__(self, '_keys', keys)

    def __getattr__(self, name):
        if name in self._values:
            return self._values[name]
        if name in self._keys:
            return None
        raise AttributeError('no field %r (fields: %s)' % (name, ', '.join(sorted(self._keys))))

    def __bool__(self):
        """False for an empty object, as its dict is (``probe or ...`` reads as it did on the dict)."""
        return bool(self._values)

    def __setattr__(self, name, value):
        raise AttributeError('a record is read-only: cannot set %r' % name)

    def __delattr__(self, name):
        raise AttributeError('a record is read-only: cannot delete %r' % name)

    def __repr__(self):
        return 'Fields(%s)' % ', '.join('%s=%r' % item for item in sorted(self._values.items()))


class Table(Mapping):
    """An object whose keys are data (a schema's :class:`~exam_lab.grader.score.records.Map`), read-only."""
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


def view(value, schema):
    """The read-only view of ``value``, a record's value (or a part of one) of ``schema``; None stays
    None, and a view is its own view. A value whose shape is not the schema's (an object where a list
    is expected) is given as it is: the schema's check is the record's, not the reader's."""
    if value is None or isinstance(value, (Fields, Table)):
        return value
    while isinstance(schema, (Maybe, Optional)):
        schema = schema.schema
    if isinstance(schema, tuple):  # one of several schemas: the first of the value's shape
        schema = next((inner for inner in schema if _shape(inner) == _shape_of(value)), None)
    shape = _shape(schema)
    if shape != _shape_of(value):
        return value
    if isinstance(schema, dict):
        return Fields({key: view(inner, schema[key]) for key, inner in value.items() if key in schema},
                      frozenset(schema))
    if isinstance(schema, Map):
        return Table({key: view(inner, schema.schema) for key, inner in value.items()})
    if isinstance(schema, Row):
        return tuple(view(item, schema.schemas[index]) if index < len(schema.schemas) else item
                     for index, item in enumerate(value))
    if shape == 'list':
        inner = schema[0] if isinstance(schema, list) else schema.schema
        return tuple(view(item, inner) for item in value)
    return value


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
