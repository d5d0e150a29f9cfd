"""A record read by attributes (score/fields.py): nested objects as attributes, a missing optional key
None, a misspelt one an error, data-keyed objects mappings, lists tuples, nothing settable. And the
rubric reads a session the same whether it is given as kept (dicts) or as its view."""
import keyword

import pytest

from exam_lab.grader.score import fields, inspection, records, rubric

from test_grader_rubric import STATIC, measured

SCHEMA = {'name': str, 'note': records.Optional(str), 'where': records.Maybe({'file': str, 'line': int}),
          'topics': records.Map(str, [str]), 'calls': records.Items(records.Row(float, str)), 'tags': [str]}


def test_a_view_reads_nested_objects_as_attributes():
    value = {'name': 'exam', 'where': {'file': 'a.py', 'line': 3}, 'topics': {'/p': ['/exam']},
             'calls': [[1.5, 'WARNING']], 'tags': ['x', 'y']}
    view = fields.view(value, SCHEMA)
    assert view.name == 'exam' and view.where.file == 'a.py' and view.where.line == 3
    assert view.note is None, 'an optional key that is missing reads None'
    assert dict(view.topics) == {'/p': ('/exam',)} and view.topics.get('/q') is None
    assert view.calls == ((1.5, 'WARNING'),) and view.tags == ('x', 'y')
    assert fields.view(view, SCHEMA) is view and fields.view(None, SCHEMA) is None


def test_a_misspelt_field_is_an_error_never_none():
    view = fields.view({'name': 'exam'}, SCHEMA)
    with pytest.raises(AttributeError, match='nmae'):
        view.nmae
    with pytest.raises(TypeError):
        view['name']  # no reading by string keys: attributes only


def test_nothing_of_a_view_can_be_set():
    view = fields.view({'name': 'exam', 'where': {'file': 'a.py', 'line': 3}, 'topics': {'/p': []}}, SCHEMA)
    for target, name in ((view, 'name'), (view.where, 'file'), (view, 'other')):
        with pytest.raises(AttributeError):
            setattr(target, name, 'x')
    with pytest.raises(AttributeError):
        del view.name
    with pytest.raises(TypeError):
        view.topics['/q'] = []
    with pytest.raises(AttributeError):
        view.tags.append('z')


def test_an_empty_object_is_false_as_its_dict_is():
    assert not fields.view({}, SCHEMA) and fields.view({'name': ''}, SCHEMA)
    assert not fields.view({'name': 'exam', 'topics': {}}, SCHEMA).topics


def test_a_record_is_viewed_with_its_own_schema():
    record = records.SessionRecord.make({'outcome': 'not_run', 'build': None, 'runs': [], 'error': 'no node'})
    view = fields.view(record)
    assert view.outcome == 'not_run' and view.error == 'no node' and view.runs == () and view.refused is None
    with pytest.raises(AttributeError):
        view.probe


def test_a_view_copies_nothing_before_a_field_is_read():
    import copy
    trace = [[float(t), 1.0] for t in range(5)]
    view = fields.view({'trace': {'published': trace, 'oracle': []}}, records.ProbeRecord.SCHEMA)
    trace.append([5.0, 2.0])  # read after: the view reads the value as it is then
    assert view.trace.published[-1] == (5.0, 2.0) and len(view.trace.published) == 6
    assert copy.copy(view) is view and copy.deepcopy(view) is view


def test_a_value_not_of_the_schemas_shape_is_given_as_it_is():
    assert fields.view({'where': 'nowhere', 'tags': 'x'}, SCHEMA).where == 'nowhere'


@pytest.mark.parametrize('schema', [records.SessionRecord.SCHEMA, records.ProbeRecord.SCHEMA, inspection.STATIC,
                                    inspection.InspectRecord.SCHEMA])
def test_every_field_of_the_records_reads_as_an_attribute(schema):
    def keys(schema):
        while isinstance(schema, (records.Maybe, records.Optional)):
            schema = schema.schema
        if isinstance(schema, dict):
            for key, inner in schema.items():
                yield key
                yield from keys(inner)
        elif isinstance(schema, (records.Map, records.Items)):
            yield from keys(schema.schema)
        elif isinstance(schema, list):
            yield from keys(schema[0])
        elif isinstance(schema, (tuple, records.Row)):
            for inner in (schema.schemas if isinstance(schema, records.Row) else schema):
                yield from keys(inner)
    bad = sorted(k for k in set(keys(schema)) if not k.isidentifier() or keyword.iskeyword(k)
                 or k in fields.Fields.__slots__)
    assert bad == []


def test_the_rubric_reads_a_session_as_kept_or_as_its_view():
    session, static = measured(calls=[[13.55, 'WARNING']]), dict(STATIC, code={'service_calls': [], 'publishes': [],
                                                                              'timers': []})
    viewed = fields.view(session, records.SessionRecord.SCHEMA), fields.view(static, inspection.STATIC)
    assert rubric.score('altitude', viewed[1], viewed[0]) == rubric.score('altitude', static, session)
    assert rubric.status(viewed[1], viewed[0]) == rubric.status(static, session)
    assert rubric.doubts(viewed[1], viewed[0]) == rubric.doubts(static, session)


def _session():
    return records.SessionRecord.make({'outcome': 'ran', 'build': None, 'runs': [], 'error': 'x',
                                       'launch_check': {'file': 'a.launch', 'status': 0, 'refused': '', 'warnings': ['w'],
                                                        'nodes': ['/exam']}})


def test_a_record_is_frozen_as_a_frozen_dataclass_is_and_deeper():
    """What a stage hands on is what the next one reads: no field set, no object or list of it changed."""
    import copy
    import pickle
    record = _session()
    with pytest.raises(AttributeError, match='read-only'):
        record.error = 'other'
    with pytest.raises(AttributeError, match='read-only'):
        del record.error
    with pytest.raises(AttributeError, match='no field'):
        record.eror  # a misspelt field is an error, as on a view
    changes = (lambda v: v.__setitem__('error', 'y'), lambda v: v.update(error='y'), lambda v: v.pop('error'),
               lambda v: v.setdefault('refused', True), lambda v: v['launch_check'].__setitem__('status', 1),
               lambda v: v['launch_check']['warnings'].append('more'), lambda v: v['runs'].extend([{}]),
               lambda v: v['launch_check']['nodes'].__setitem__(0, '/x'), lambda v: v.clear())
    for change in changes:
        with pytest.raises(TypeError, match='read-only'):
            change(record.value)
    assert record == _session() and record.launch_check['warnings'] == ['w']
    # Read as plain data: a new dict of it, a deep copy, JSON, a pickle (a thread pool's) are plain or equal.
    assert dict(record.value, error='y')['error'] == 'y' and record.error == 'x'
    thawed = copy.deepcopy(record.value)
    thawed['launch_check']['warnings'].append('more')
    assert type(thawed) is dict and record.launch_check['warnings'] == ['w']
    assert pickle.loads(pickle.dumps(record.value)) == record.value
    assert records.SessionRecord.from_json(record.to_json().encode()) == record


def test_a_record_replaced_is_a_new_record_checked_again():
    record = _session()
    other = record.replaced(survivors=3)
    assert other.survivors == 3 and record.survivors is None and other.outcome is records.Outcome.RAN
    with pytest.raises(records.RecordError, match='survivors'):
        record.replaced(survivors=-1)
    with pytest.raises(records.RecordError, match='unexpected key'):
        record.replaced(surviviors=3)
