"""What a box puts into its record, bounded where it is made. No rospy here.

A record a box writes (``inspect.json``, ``intake.json``, ``similarity.json``) is checked by root
against its schema (:mod:`exam_lab.grader.score.records`): a list over its cap, a text over its
length or a file over its bytes would make the whole record that box's failure, and the student (or
the class's check) would not be graded for being large. So a box never hands back more than fits:
each list a student's files make is cut where it is made (:func:`kept`: its first items, those that
matter to the rubric first), each text cut in its middle (:func:`cut`), with a sentence for the
teacher naming the cap and the value ("501 Python files (at most 500): the first 500 are read"), and
the student is graded on what fits. :func:`fit` is the last step before a record is written, for
whatever was not cut where it was made (and for a list added later without its cap): it cuts by the
record's own schema and, when the whole is over the record's bytes, cuts its lists of text further,
each cut said in a sentence.
"""
import json
import os

from exam_lab.grader.score.records import (MAX_ITEMS, MAX_TEXT, Items, Map, Maybe, OneOf, Optional, Row,
                                           Text)
# A text cut in its middle and a list of notes closed within its cap: shared with root (score.schema).
from exam_lab.grader.score.schema import CUT_MARK, closed, cut  # noqa: F401

#: The tighter caps :func:`fit` tries in turn on lists of text when a record is over its bytes:
#: (items, characters of one).
TIGHTER = ((100, 500), (20, 200), (5, 100), (1, 100))


def kept(items, what, notes, limit=MAX_ITEMS, first=None, verb='kept', text=MAX_TEXT):
    """The first ``limit`` of ``items``, each text among them cut to ``text`` characters; when some
    are left out, a sentence in ``notes``: ``"501 Python files (at most 500): the first 500 are read"``.

    :param what: the items' plural noun ("Python files").
    :param first: a predicate: when some are left out, the items it holds for go before the others
        (what the rubric reads: the parameter the launch file sets), in their order.
    :param text: the most characters of one item (None: items are not cut, they are paths to read).
    :param verb: what is done with those kept ("kept", "read", "listed").
    """
    items = list(items)
    if first is not None and len(items) > limit:
        items = [i for i in items if first(i)] + [i for i in items if not first(i)]
    out = [cut(i, text) if isinstance(i, str) and text else i for i in items[:limit]]
    if len(items) > limit:
        notes.append('%d %s (at most %d): the first %d %s' % (len(items), what, limit, limit,
                                                           'are %s' % verb if limit != 1 else 'is %s' % verb))
    return out


def fit(value, record_type, notes_key='notes'):
    """``value`` cut to what ``record_type`` (a :class:`~exam_lab.grader.score.records.Record`) holds:
    every list and text within its schema's caps, the whole within the record's bytes (its lists of
    text cut further, :data:`TIGHTER`). Each cut is a sentence in ``value[notes_key]`` (a list of
    texts of the record; with None, nowhere: the caller says what it cut)."""
    cuts = []
    value = _fit(value, record_type.SCHEMA, record_type.FILE, cuts, None)
    notes = value.get(notes_key) if notes_key else None
    budget = record_type.MAX_BYTES - 64 * 1024  # the sentences of the cuts, and JSON's own spacing
    for caps in TIGHTER:
        if _size(value) <= budget:
            break
        before = _size(value)
        value = _fit(value, record_type.SCHEMA, record_type.FILE, [], caps)
        cuts.append('%s: %d bytes (at most %d): its lists of text cut to their first %d items of at most %d '
                    'characters' % (record_type.FILE, before, record_type.MAX_BYTES, caps[0], caps[1]))
    if notes is not None and cuts:
        value[notes_key] = closed(value[notes_key] + cuts, keep=cuts)
    return value


def _size(value):
    return len(json.dumps(value, sort_keys=True).encode('utf-8', 'surrogateescape'))


def _texts(schema):
    """Whether a list's items are texts (the lists :data:`TIGHTER` cuts)."""
    return schema is str or isinstance(schema, Text)


def _fit(value, schema, where, cuts, caps):
    if isinstance(schema, (Maybe, Optional)):
        return value if value is None else _fit(value, schema.schema, where, cuts, caps)
    if isinstance(schema, tuple):
        text = [s for s in schema if _texts(s)]
        return _fit(value, text[0], where, cuts, caps) if text and isinstance(value, str) else value
    if _texts(schema):
        limit = schema.limit if isinstance(schema, Text) else MAX_TEXT
        if isinstance(value, str) and len(value) > limit:
            cuts.append('%s: a text of %d characters (at most %d): cut in its middle' % (where, len(value), limit))
            return cut(value, limit)
        return value
    if isinstance(schema, list):
        schema = Items(schema[0])
    if isinstance(schema, Items) and isinstance(value, list):
        limit, inner = schema.limit, schema.schema
        if caps is not None and _texts(inner):
            limit = min(limit, caps[0])
            inner = Text(min(inner.limit if isinstance(inner, Text) else MAX_TEXT, caps[1]))
        if len(value) > limit:
            cuts.append('%s: %d items (at most %d): the first %d kept' % (where, len(value), limit, limit))
        within = []
        out = [_fit(v, inner, '%s[%d]' % (where, i), within, caps) for i, v in enumerate(value[:limit])]
        if within and caps is None:  # one sentence for the list, not one per item
            cuts.append(within[0] if len(within) == 1 else '%s (and %d more cuts inside %s)' % (within[0], len(within) - 1, where))
        return out
    if isinstance(schema, Row) and isinstance(value, list):
        return [_fit(v, s, '%s[%d]' % (where, i), cuts, caps) for i, (v, s) in enumerate(zip(value, schema.schemas))]
    if isinstance(schema, Map) and isinstance(value, dict):
        keys = sorted(value)[:schema.limit]
        if len(value) > schema.limit:
            cuts.append('%s: %d keys (at most %d): the first %d kept' % (where, len(value), schema.limit, schema.limit))
        return {k: _fit(value[k], schema.schema, '%s[%s]' % (where, k), cuts, caps) for k in keys}
    if isinstance(schema, dict) and isinstance(value, dict):
        return {k: _fit(v, schema[k], '%s.%s' % (where, k), cuts, caps) if k in schema else v
                for k, v in value.items()}
    if isinstance(schema, OneOf):
        return value
    return value


def found_deeper(folders, wanted):
    """The first file below ``folders`` (those a search left out at its depth) that is ``wanted`` (a
    predicate on its path), or None: what a cap on depth left out, for its sentence. Links are not
    followed; the folders are the box's own unpacked upload, bounded by its budget."""
    for folder in folders:
        for dirpath, dirnames, filenames in os.walk(folder):
            dirnames.sort()
            for name in sorted(filenames):
                full = os.path.join(dirpath, name)
                if not os.path.islink(full) and os.path.isfile(full) and wanted(full):
                    return full
    return None
