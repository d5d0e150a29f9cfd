"""What a box hands back is data root checks: one regular file, capped, never followed, of the record's
schema. No ROS, no box: the records are written here as a hostile box would."""
import dataclasses
import json
import os

import pytest

from exam_lab.grader import contract
from exam_lab.grader.score import records
from exam_lab.grader.score.inspection import InspectRecord
from exam_lab.grader.score.schema import plain


def inspect_record(**changes):
    record = {'uid': 61003, 'refused': None, 'sheet': 'altitude', 'notes': ['sheet altitude given'], 'fixes': [],
              'static': {'launch_files': ['launch/exam.launch'], 'package': 'exam', 'python2': [],
                         'params_in_code': ['threshold'], 'threshold_reason': 'threshold = 1300',
                         'launch': {'file': 'launch/exam.launch', 'starts_drone': True, 'exam_type': 'exam_node.py',
                                    'exam_name': 'exam', 'package': 'exam', 'comments': 2, 'exam_type_found': True},
                         'threshold': {'name': '/threshold', 'value': 1300, 'where': 'launch/exam.launch'}},
              'threshold_value': 1300.0, 'calls_service': True, 'namespace': '/',
              'main_launch': 'src/exam/launch/.grader-main-exam.launch',
              'threshold_launch': 'src/exam/launch/.grader-threshold-exam.launch', 'threshold_run_value': 912.4,
              'handed_in_launch': 'exam/launch/exam.launch',
              'comments': {'comments': 3, 'code': 40, 'files': ['scripts/exam_node.py']},
              'facts': {'participant': 1234, 'folder': 'Jane Doe_1234_assignsubmission_file_', 'documents': []}}
    record.update(changes)
    return record


def write(tmp_path, value, name='inspect.json'):
    path = tmp_path / name
    path.write_bytes(value if isinstance(value, bytes) else json.dumps(value).encode())
    return str(path)


def test_a_good_record_is_read(tmp_path):
    record = contract.read_record(write(tmp_path, inspect_record()), InspectRecord)
    assert record.uid == 61003 and record.threshold_value == 1300.0
    assert record.static.launch.exam_type == 'exam_node.py'
    assert record.main_launch == 'src/exam/launch/.grader-main-exam.launch'


@pytest.mark.parametrize('change, words', [
    ({'uid': '0'}, 'uid: an integer expected'),
    ({'sheet': 'rm -rf'}, 'sheet:'),
    ({'notes': 'one note'}, 'notes: a list expected'),
    ({'notes': ['x'] * (records.MAX_ITEMS + 1)}, 'notes: 501 notes (at most 500)'),
    ({'notes': ['x' * (records.MAX_TEXT + 1)]}, 'characters'),
    ({'threshold_value': True}, 'threshold_value: a number expected'),
    ({'calls_service': 1}, 'calls_service: true or false'),
    ({'main_launch': '/etc/shadow'}, 'not a path inside the workspace'),
    ({'threshold_launch': 'src/../../../root/x.launch'}, 'not a path inside the workspace'),
    ({'main_launch': None}, 'a threshold run without a main run'),
    ({'threshold_run_value': None}, 'a threshold run without its value'),
    ({'extra': 1}, "unexpected key(s) 'extra'"),
    ({'facts': {'participant': None, 'folder': 'x'}}, 'documents is missing'),
])
def test_a_record_of_an_unexpected_shape_is_refused(tmp_path, change, words):
    with pytest.raises(records.RecordError) as refused:
        contract.read_record(write(tmp_path, inspect_record(**change)), InspectRecord)
    assert words in str(refused.value)


def test_nested_fields_are_checked_too(tmp_path):
    record = inspect_record()
    record['static']['launch']['comments'] = -1
    with pytest.raises(records.RecordError, match=r'static\.launch\.comments: -1 is outside'):
        contract.read_record(write(tmp_path, record), InspectRecord)
    del record['static']['launch']
    with pytest.raises(records.RecordError, match='launch is missing'):
        contract.read_record(write(tmp_path, record), InspectRecord)


def test_not_json_and_non_numbers_are_refused(tmp_path):
    for raw in (b'{"uid": 1', b'\xff\xfe', b'[]', json.dumps(inspect_record()).replace('1300.0', 'NaN').encode()):
        with pytest.raises(records.RecordError):
            contract.read_record(write(tmp_path, raw), InspectRecord)


def test_an_oversized_record_is_refused_unread(tmp_path):
    path = write(tmp_path, inspect_record(notes=['x' * 1000] * 200))
    with pytest.raises(records.RecordError, match='bytes \\(at most 100000\\)'):
        contract.read_record(path, InspectRecord, max_bytes=100000)


def test_links_fifos_and_missing_files_are_refused(tmp_path):
    secret = write(tmp_path, inspect_record(), name='root-only.json')
    os.chmod(secret, 0o600)
    os.symlink(secret, str(tmp_path / 'inspect.json'))
    with pytest.raises(records.RecordError, match='a link, not followed'):
        contract.read_record(str(tmp_path / 'inspect.json'), InspectRecord)
    os.mkfifo(str(tmp_path / 'fifo.json'))
    with pytest.raises(records.RecordError, match='not a regular file'):  # and never blocks
        contract.read_record(str(tmp_path / 'fifo.json'), InspectRecord)
    with pytest.raises(records.RecordError, match='missing'):
        contract.read_record(str(tmp_path / 'none.json'), InspectRecord)


def test_an_intake_names_only_students_inside_its_folder(tmp_path):
    good = {'uid': 61000, 'students': [{'name': 'Jane Doe', 'path': 'class/Jane Doe_1_assignsubmission_file_'}]}
    read = contract.read_record(write(tmp_path, good, 'intake.json'), records.IntakeRecord)
    assert read.students[0].name == 'Jane Doe'
    # A frozen dataclass: its JSON reads back to an equal record, and nothing of it can be set.
    assert records.IntakeRecord.from_json(read.to_json().encode()) == read and read.value == good
    with pytest.raises(dataclasses.FrozenInstanceError):
        read.students[0].name = 'x'
    for student in ({'name': '../../etc', 'path': 'class/x'}, {'name': 'x/y', 'path': 'class/x'},
                    {'name': '..', 'path': 'class/x'}, {'name': 'Jane', 'path': '/root'},
                    {'name': 'Jane', 'path': 'class/../../x'}):
        with pytest.raises(records.RecordError):
            contract.read_record(write(tmp_path, dict(good, students=[student]), 'intake.json'), records.IntakeRecord)


def test_similarity_html_holds_only_the_highlight(tmp_path):
    match = {'file_a': 'a.py', 'file_b': 'b.py', 'sim_a': 0.9, 'sim_b': 0.8,
             'html_a': "x = 1 <span class='highlight-red'>y &lt;= 2</span>", 'html_b': 'z'}
    good = {'pairs': [{'a': 'A', 'b': 'B', 'score_a': 0.9, 'score_b': 0.8, 'files': [match]}], 'students': 2,
            'threshold': 0.5, 'detector': 'copydetect 0.5.0', 'scores': [['A', 'B', 0.9, 0.8]], 'notes': []}
    read = contract.read_record(write(tmp_path, good, 'similarity.json'), records.SimilarityRecord)
    assert read.value['pairs'][0]['files'][0]['html_a'] == match['html_a']
    match['html_b'] = '<script>alert(1)</script>'
    with pytest.raises(records.RecordError, match='markup other than'):
        contract.read_record(write(tmp_path, good, 'similarity.json'), records.SimilarityRecord)
    assert contract.read_record(write(tmp_path, {'error': 'no venv', 'notes': []}, 'similarity.json'),
                              records.SimilarityRecord).value == {'error': 'no venv', 'notes': []}
    # The students' file names and code are made safe where the record is made; the highlight stays.
    match.update(file_a='a\x1b[2J.py', html_b="w\x07 <span class='highlight-green'>v\u202e</span>")
    read = contract.read_record(write(tmp_path, good, 'similarity.json'), records.SimilarityRecord)
    assert read.pairs[0].files[0].file_a == 'a.py'
    assert read.pairs[0].files[0].html_b == "w <span class='highlight-green'>v</span>"


def test_a_cap_hit_is_a_sentence_naming_the_cap_and_the_value(tmp_path):
    """Issue 36: a list over its cap reads "501 files (at most 500)", where it is; a box that would
    write such a record says that sentence (and no traceback) when it stops."""
    files = ['scripts/n%d.py' % i for i in range(records.MAX_ITEMS + 1)]
    record = inspect_record(comments={'comments': 1, 'code': 2, 'files': files})
    with pytest.raises(records.RecordError) as refused:
        contract.read_record(write(tmp_path, record), InspectRecord)
    assert str(refused.value) == 'inspect.json.comments.files: 501 files (at most 500)'
    with pytest.raises(records.RecordError, match=r'^inspect.json.notes: 501 notes \(at most 500\)$'):
        records.write(str(tmp_path), InspectRecord, inspect_record(notes=['n'] * 501))
    with pytest.raises(records.RecordError, match=r'inspect.json: 1048577 bytes \(at most 1048576\)$'):
        contract.read_record(write(tmp_path, b' ' * ((1 << 20) + 1)), InspectRecord)


def test_a_class_larger_than_a_list_cap_is_one_intake(tmp_path):
    """A class of more students than any other list may hold, one of them refused with its reason."""
    students = [{'name': 'S %d' % i, 'path': 'class/S %d' % i} for i in range(records.MAX_ITEMS + 100)]
    students[7]['refused'] = 'the files of S 7: 5001 more files, beyond the 5000 a submission may unpack'
    got = contract.read_record(write(tmp_path, {'uid': 61000, 'students': students}, 'intake.json'),
                             records.IntakeRecord, records.IntakeRecord.MAX_BYTES)
    assert len(got.students) == 600 and got.students[7].refused.startswith('the files of S 7')


def test_the_inspections_text_is_made_safe_where_its_record_is_made(tmp_path):
    """A student's words in the inspection's record (a note quoting a file name, the launch file's
    words, a document's name) lose their escape sequences as root reads the record; the paths the
    session opens and the code's file names are kept exactly."""
    odd = 'scripts/n\udcff\x1b[2J.py'
    found = inspect_record(notes=['link %s dropped' % odd, 'bell\x07'], fixes=['\u202eevil'],
                           static=dict(inspect_record()['static'], threshold_reason='reads \x1b]0;owned\x07it'),
                           facts={'participant': 1, 'folder': 'F\x1b[31m', 'documents': [{'name': 'r\x07.pdf', 'pages': 1}]},
                           handed_in_launch='exam/launch/\udcfe.launch', comments={'comments': 1, 'code': 2, 'files': [odd]})
    record = contract.read_record(write(tmp_path, json.dumps(found).encode()), InspectRecord)
    assert record.notes == ('link scripts/n\\xff.py dropped', 'bell') and record.fixes == ('evil',)
    assert record.static.threshold_reason == 'reads it' and record.facts.folder == 'F'
    assert plain(record.facts.documents) == [{'name': 'r.pdf', 'pages': 1}]
    assert record.handed_in_launch == 'exam/launch/\udcfe.launch' and record.comments.files == (odd,)
