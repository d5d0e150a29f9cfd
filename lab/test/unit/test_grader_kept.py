"""What the grader keeps of a grading, as records (issue 37 points 1, 2; issue 46 point 2):
measurements.json and grade.json carry a version and are read back through their types (capped,
checked); a file an older grader kept is refused as such ("graded by an older grader: grade again"),
never converted, for that student only, in make rescore and make worksheet; one that does not match
stops that student's rescore, never the class's; the session's outcome an enum whose members are
their strings."""
import copy
import csv
import json
import math
import os

import pytest

from exam_lab.grader.publish import flightplot, grades
from exam_lab.grader.score import kept, rubric
from exam_lab.grader.score.kept import GradeRecord, MeasurementsRecord
from exam_lab.grader.score.records import MEASUREMENTS, OUTCOMES, Outcome, RecordError, SessionRecord

#: Real outputs, copied as the grader left them (measurements.json and grade.json of one student).
#: Today's shape (version 1), both of a class graded 2026-12-02 06:33 (lab/test/grader/submissions'
#: good_student with a two-page report.pdf; its package.xml and CMakeLists.txt alone, a package that
#: starts no node): ``version-1``: good_student; ``no-node-version-1``: no_node.
#: Older shapes, no version: ``before-records``: a fairness run's student, 2026-11-26 18:36 (its
#: session without an outcome, its probes without input_rates, node_watch, a leg's stays, the
#: calibration's near point); ``before-version``: good_student of a grader run, 2026-11-26 22:09 (the
#: session a record, no version); ``no-node-before-records``: a class's student whose package starts no
#: node, 2026-11-26 18:31.
KEPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'data', 'kept')
SHAPES = ('version-1', 'no-node-version-1')
OLDER = ('before-records', 'before-version', 'no-node-before-records')


def kept_copy(name, file=MEASUREMENTS):
    """The JSON of a real kept file (``name``: one of SHAPES or OLDER)."""
    with open(os.path.join(KEPT, name, file)) as f:
        return json.load(f)


def kept_folder(out, shape, student):
    """A student's folder in ``out`` holding the real files of ``shape``, named ``student`` in both."""
    folder = os.path.join(str(out), student)
    os.makedirs(folder)
    for file in (MEASUREMENTS, 'grade.json'):
        with open(os.path.join(folder, file), 'w') as f:
            json.dump(dict(kept_copy(shape, file), student=student), f)
    return folder


def read(path):
    with open(path, 'rb') as f:
        return f.read()


def test_a_file_of_an_older_grader_is_refused_as_such_never_converted():
    """Each older shape, read by its type, is "graded by an older grader: grade again", its file named;
    today's is read, and the rubric gives it what it gives the file read as plain JSON."""
    for shape in OLDER:
        for record_type in (MeasurementsRecord, GradeRecord):
            with pytest.raises(kept.OlderRecord) as err:
                record_type.read(os.path.join(KEPT, shape, record_type.FILE))
            assert str(err.value) == '%s: graded by an older grader: grade again' % record_type.FILE
    raw = kept_copy('version-1')
    record = MeasurementsRecord.read(os.path.join(KEPT, 'version-1', MEASUREMENTS))
    assert record.version == kept.VERSION and record.session['outcome'] is Outcome.RAN
    assert raw == kept_copy('version-1')  # read, not changed
    items = [(i['id'], i['points'], i['evidence']) for i in rubric.score(raw['sheet'], raw['static'], raw['session'])]
    assert items == [(i['id'], i['points'], i['evidence'])
                     for i in rubric.score(record.sheet, record.static, record.session)]
    with pytest.raises(kept.OlderRecord):  # a version before today's is as old as none
        MeasurementsRecord.make(dict(raw, version=kept.VERSION - 1))


def test_a_rescore_refuses_each_older_students_files_and_rescores_the_others(tmp_path):
    """A class kept by graders of three ages: each student whose files an older grader kept is one
    line, "graded by an older grader: grade again" (its grade.json first: it is not in grades.csv),
    its files as they were; the others are rescored and written in today's shape."""
    out = tmp_path / 'out'
    for shape in SHAPES + OLDER:
        kept_folder(out, shape, shape)
    before = {shape: {f: read(str(out / shape / f)) for f in (MEASUREMENTS, 'grade.json')} for shape in SHAPES + OLDER}
    records, changes = grades.rescore(str(out))
    assert sorted(line for line in changes if grades.NOT_RESCORED in line) == sorted(
        '%s: not rescored (its grade.json kept as it is, not in grades.csv): grade.json: graded by an older '
        'grader: grade again' % shape for shape in OLDER)
    assert [r['student'] for r in records] == sorted(SHAPES)
    for shape in SHAPES:
        assert GradeRecord.read(str(out / shape / 'grade.json')).version == kept.VERSION
        assert read(str(out / shape / MEASUREMENTS)) == before[shape][MEASUREMENTS]  # read, never rewritten
    for shape in OLDER:
        assert {f: read(str(out / shape / f)) for f in (MEASUREMENTS, 'grade.json')} == before[shape]
    outcomes = [MeasurementsRecord.read(str(out / shape / MEASUREMENTS)).session['outcome'] for shape in SHAPES]
    assert outcomes == [Outcome.RAN, Outcome.NO_NODE]
    with open(str(out / 'grades.csv')) as f:
        assert [row.split(',')[0] for row in f.read().splitlines()[1:]] == sorted(SHAPES)
    # Measurements of an older grader beside a grade of today's: its grade kept, the line names the measurements.
    with open(str(out / 'before-version' / 'grade.json'), 'w') as f:
        json.dump(dict(kept_copy('version-1', 'grade.json'), student='before-version'), f)
    records, changes = grades.rescore(str(out))
    assert 'before-version: not rescored (its grade kept as it was): measurements.json: graded by an older ' \
        'grader: grade again' in changes, changes
    assert 'before-version' in [r['student'] for r in records]


def test_make_worksheet_leaves_out_a_grade_of_an_older_grader_and_fills_the_others(tmp_path, capsys):
    """Paul's grade.json an older grader kept: his row is left as it was and he is named with the
    sentence; Jane's whole grade is written."""
    from exam_lab.grader.publish import hand, moodle
    from exam_lab.grader.score.sheets import HAND_ITEMS
    from test_grader_hand import WORKSHEET, fill, worksheet_script, write_worksheet
    out = tmp_path / 'out'
    for name, shape, number in (('Jane Doe', 'version-1', 101), ('Paul Martin', 'before-version', 102)):
        folder = kept_folder(out, shape, name)
        grade = dict(kept_copy(shape, 'grade.json'), student=name, participant=number)
        with open(os.path.join(folder, 'grade.json'), 'w') as f:
            json.dump(grade, f)
    hand.write(str(out / hand.FILE), [GradeRecord.read(str(out / 'Jane Doe' / 'grade.json')).value])
    fill(str(out / hand.FILE), {('Jane Doe', item): str(top) for item, (top, _) in HAND_ITEMS.items()})
    write_worksheet(tmp_path / 'ws.csv', WORKSHEET)
    assert worksheet_script().main(['--out', str(out), '--worksheet', str(tmp_path / 'ws.csv')]) == 0
    printed = capsys.readouterr().out
    assert 'worksheet: left out: Paul Martin/grade.json: graded by an older grader: grade again' in printed, printed
    filled = (out / moodle.UPLOAD).read_text(encoding='utf-8-sig')
    rows = {r['Full name']: r for r in csv.DictReader(filled.splitlines())}
    assert rows['Jane Doe']['Grade'] == '20' and rows['Paul Martin']['Grade'] == ''
    assert rows['Paul Martin']['Feedback comments'] == ''


def test_a_kept_record_round_trips_through_json():
    for shape in SHAPES:
        for record_type in (MeasurementsRecord, GradeRecord):
            record = record_type.read(os.path.join(KEPT, shape, record_type.FILE))
            assert record_type.from_json(record.to_json().encode()) == record
    value = copy.deepcopy(MeasurementsRecord.read(os.path.join(KEPT, 'version-1', MEASUREMENTS)).value)
    value['session']['runs'][0]['probe']['formula'][0]['published'] = float('nan')
    record = MeasurementsRecord.make(value)
    again = MeasurementsRecord.from_json(record.to_json().encode())
    assert again == record and math.isnan(again.session['runs'][0]['probe']['formula'][0]['published'])
    assert again.session['outcome'] is Outcome.RAN
    assert MeasurementsRecord.make(dict(value, notes=['another note'])) != record  # equality can fail


def test_a_file_that_does_not_match_stops_that_students_rescore_only(tmp_path):
    """Bob's measurements and Cy's grade.json do not match: each is a line naming the file and the
    field, its files stay as they were, and Ann is rescored; Bob keeps his row in grades.csv."""
    out = tmp_path / 'out'
    for name in ('Ann', 'Bob', 'Cy'):
        kept_folder(out, 'version-1', name)
    bob = dict(kept_copy('version-1'), student='Bob', version=kept.VERSION)
    bob['session']['outcome'] = 'exploded'
    (out / 'Bob' / MEASUREMENTS).write_text(json.dumps(bob))
    (out / 'Cy' / 'grade.json').write_text(json.dumps(dict(kept_copy('version-1', 'grade.json'), total='lots')))
    files = {name: {f: read(str(out / name / f)) for f in (MEASUREMENTS, 'grade.json')} for name in ('Bob', 'Cy')}
    records, changes = grades.rescore(str(out))
    assert changes == [
        "Bob: not rescored (its grade kept as it was): measurements.json.session.outcome: 'exploded' is not one of "
        + ', '.join(OUTCOMES),
        'Cy: not rescored (its grade.json kept as it is, not in grades.csv): grade.json.total: a number expected, got str']
    assert [r['student'] for r in records] == ['Ann', 'Bob'] and records[0]['previous']['total'] == 17.0
    assert records[1] == GradeRecord.read(str(out / 'Bob' / 'grade.json')).value  # as it was
    for name in ('Bob', 'Cy'):
        assert {f: read(str(out / name / f)) for f in (MEASUREMENTS, 'grade.json')} == files[name]
    with open(str(out / 'grades.csv')) as f:
        assert [row.split(',')[0] for row in f.read().splitlines()[1:]] == ['Ann', 'Bob']
    with pytest.raises(RecordError) as err:  # the flight plot reads the measurements through the same type
        flightplot.load_runs(str(out / 'Bob'))
    assert str(err.value).startswith("measurements.json.session.outcome: 'exploded'")
    (out / 'Bob' / MEASUREMENTS).write_text(json.dumps(dict(bob, version=kept.VERSION + 1)))
    assert 'measurements.json.version: %d is not one of 1' % (kept.VERSION + 1) in grades.rescore(str(out))[1][0]


def test_the_grader_keeps_versioned_records_and_refuses_its_own_bad_one(tmp_path):
    measured = kept_copy('version-1')
    grade = grades.keep_and_score(str(tmp_path), measured)
    assert grade['version'] == kept.VERSION and grade['total'] == 17.0
    assert MeasurementsRecord.read(str(tmp_path / MEASUREMENTS)) == MeasurementsRecord.make(measured)
    assert json.loads((tmp_path / MEASUREMENTS).read_text())['version'] == kept.VERSION
    assert GradeRecord.read(str(tmp_path / 'grade.json')).value == grade
    bad = dict(measured, session=dict(measured['session'], outcome='fine'))
    with pytest.raises(RecordError):
        grades.keep_and_score(str(tmp_path / 'bad'), bad)
    assert not os.path.exists(str(tmp_path / 'bad'))  # nothing written for a record that is not one


def test_the_outcome_is_an_enum_whose_members_are_their_strings():
    assert Outcome.RAN == 'ran' and 'build_failed' == Outcome.BUILD_FAILED and 'ran' in OUTCOMES
    assert json.dumps({'outcome': Outcome.NO_NODE}, indent=1) == json.dumps({'outcome': 'no_node'}, indent=1)
    assert '%s' % Outcome.REFUSED == 'refused' and '{}'.format(Outcome.REFUSED) == 'refused'
    assert {Outcome.RAN: 1}['ran'] == 1
    assert grades.no_session(Outcome.REFUSED, 'why').outcome is Outcome.REFUSED
    made = SessionRecord.make(dict(MeasurementsRecord.read(os.path.join(KEPT, 'version-1', MEASUREMENTS)).session))
    assert made.outcome is Outcome.RAN and made.value['outcome'] is Outcome.RAN
    assert SessionRecord.from_json(made.to_json().encode()).outcome is Outcome.RAN


def test_the_kept_files_are_copies_of_real_outputs():
    """Each shape is what its name says (a fixture edited into another shape would test nothing)."""
    assert [('version' in kept_copy(s), 'outcome' in kept_copy(s)['session']) for s in OLDER] == [
        (False, False), (False, True), (False, False)]
    assert [(kept_copy(s)['version'], kept_copy(s, 'grade.json')['version'], kept_copy(s)['session']['outcome'])
            for s in SHAPES] == [(1, 1, 'ran'), (1, 1, 'no_node')]
    assert kept_copy('no-node-before-records')['session']['no_node'] is True
    assert kept_copy('no-node-version-1')['session']['no_node'] is True
    assert all(os.path.isfile(os.path.join(KEPT, s, f)) for s in SHAPES + OLDER for f in (MEASUREMENTS, 'grade.json'))


def test_make_rescore_says_who_was_not_rescored_and_fails(tmp_path, capsys):
    import runpy
    out = tmp_path / 'out'
    for name in ('Ann', 'Bob'):
        kept_folder(out, 'version-1', name)
    (out / 'Bob' / MEASUREMENTS).write_text('{"version": 1')
    script = runpy.run_path(os.path.join(os.path.dirname(KEPT), '..', '..', '..', 'scripts', 'rescore.py'))
    assert script['main'](['--out', str(out)]) == 1
    said = capsys.readouterr().out
    assert 'no point changed for any of the 2 student(s)' in said
    assert '1 student(s) NOT rescored' in said and '  Bob: not rescored (its grade kept as it was): ' \
        'measurements.json: not JSON: ' in said
    assert os.path.isfile(str(out / 'index.html'))  # the desk written for the class all the same


def test_the_desk_reads_each_grade_through_its_type_and_survives_one_that_is_not(tmp_path):
    from exam_lab.grader.publish import desk
    out = tmp_path / 'out'
    for name in ('Ann', 'Bob'):
        kept_folder(out, 'version-1', name)
    ann, bob = [GradeRecord.read(str(out / name / 'grade.json')).value for name in ('Ann', 'Bob')]
    lines = desk.finish(str(out), [ann, dict(bob, remark='a key no grade has', student='Bob\x1b[2J')])
    assert [line for line in lines if line.startswith('Bob')][0] == \
        "Bob: its grade is not a grade record (a grader bug, please report): RecordError: grade.json: unexpected " \
        "key(s) 'remark'"
    assert [line for line in lines if line.startswith('Ann')] == []
    page = (out / 'index.html').read_text()
    assert 'its grade is not a grade record' in page and '\x1b' not in page



def test_the_measurements_keep_names_exactly_and_their_session_clean(tmp_path):
    """A file name in bytes that are not UTF-8 stays as the run kept it; a session edited by hand
    (an escape sequence in a request) is made safe as it is read, for the plot and the rubric."""
    measured = kept_copy('version-1')
    measured['comments']['files'] = ['scripts/n\udcff.py']
    probe = measured['session']['runs'][0]['probe']
    probe['calls'][0][1] = 'WARNING\x1b]0;owned\x07'
    measured['notes'].append('bell\x07')
    record = MeasurementsRecord.make(measured)
    assert record.comments['files'] == ['scripts/n\udcff.py'] and record.notes[-1] == 'bell'
    assert record.session['runs'][0]['probe']['calls'][0][1] == 'WARNING'
    kept_folder(tmp_path, 'version-1', 'Ann')
    (tmp_path / 'Ann' / MEASUREMENTS).write_text(json.dumps(measured))
    assert flightplot.load_runs(str(tmp_path / 'Ann'))[0][1]['calls'][0][1] == 'WARNING'


def test_a_grader_bug_with_a_huge_message_is_still_one_students_record(tmp_path, monkeypatch):
    """The note of a bug (its traceback) and the error in the session are cut to a record's bounds:
    the student's grade is written, the class goes on."""
    from exam_lab.grader import class_run, runner

    def fails(*args, **kwargs):
        raise RuntimeError('x' * 200000)
    monkeypatch.setattr(runner, 'grade_submission', fails)
    record = class_run.grade_student('Jane', str(tmp_path / 'Jane_1001_assignsubmission_file_'), str(tmp_path))
    assert record['status'] == 'not graded' and record['participant'] == 1001
    assert GradeRecord.read(str(tmp_path / 'Jane' / 'grade.json')).value == record
    assert any(note.startswith('grader error, please report: ') for note in record['for_the_teacher'])
