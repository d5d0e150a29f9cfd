"""hand.csv: the teacher's 13 points beside the machine's 17, written, filled in a spreadsheet, read
back; nothing the teacher wrote is lost, and nothing missing counts as 0 silently."""
import csv

import pytest

from exam_lab.grader.publish import hand, moodle, report
from exam_lab.grader.score.sheets import HAND_ITEMS, ITEMS


def record(student, total, participant=None):
    """A grade record as the grader makes it (:func:`report.grade_record`): the machine's items, the
    last ones short of ``17 - total`` (each from 0 to its maximum, as the rubric gives them)."""
    items = [{'id': item, 'points': top, 'max': top, 'evidence': 'ok'} for item, (top, _) in ITEMS.items()]
    short = 17.0 - total
    for item in reversed(items):
        taken = min(short, item['points'])
        item['points'] -= taken
        short -= taken
    return report.grade_record(student, 'altitude', items, [], {'participant': participant})


def fill(path, cells, delimiter=','):
    """Fill cells {(student, column): text} as a spreadsheet would save the file."""
    with open(path, newline='', encoding='utf-8-sig') as f:
        rows = list(csv.DictReader(f))
    for row in rows:
        for (student, column), text in cells.items():
            if row['student'] == student:
                row[column] = text
    with open(path, 'w', newline='', encoding='utf-8-sig') as f:
        writer = csv.DictWriter(f, list(rows[0]), delimiter=delimiter)
        writer.writeheader()
        writer.writerows(rows)


def test_the_sheets_thirty_points():
    assert sum(p for p, _ in ITEMS.values()) + sum(p for p, _ in HAND_ITEMS.values()) == 30.0


def test_written_empty_with_the_maxima_and_the_machines_subtotal(tmp_path):
    path = str(tmp_path / hand.FILE)
    assert hand.write(path, [record('Jane Doe', 17.0, 101), record('Paul Martin', 15.5, 102)]) == 2
    with open(path, newline='') as f:
        rows = list(csv.DictReader(f))
    assert rows[0]['student'] == hand.MAX_ROW and rows[0]['comments'] == '4' and rows[0]['machine'] == '17'
    assert [(r['student'], r['participant'], r['machine']) for r in rows[1:]] == \
        [('Jane Doe', '101', '17'), ('Paul Martin', '102', '15.5')]
    assert all(r[item] == '' for r in rows[1:] for item in HAND_ITEMS)
    hands = hand.read(path)
    assert all(value is None for h in hands.values() for value in h.points.values())


def test_filled_in_a_spreadsheet_with_a_decimal_comma_and_semicolons(tmp_path):
    path = str(tmp_path / hand.FILE)
    hand.write(path, [record('Jane Doe', 17.0)])
    cells = {('Jane Doe', item): str(top).replace('.', ',') for item, (top, _) in HAND_ITEMS.items()}
    cells[('Jane Doe', 'Q5')] = '1,5'
    cells[('Jane Doe', 'remark')] = 'report in French; Q5: two lines unexplained'
    fill(path, cells, delimiter=';')
    jane = hand.read(path)['Jane Doe']
    assert jane.points['Q5'] == 1.5 and jane.points['comments'] == 4.0
    combined = hand.combine(record('Jane Doe', 17.0), jane)
    assert combined['total'] == 29.5 and combined['max'] == 30.0 and combined['missing'] == []
    assert combined['machine_total'] == 17.0 and combined['remark'].startswith('report in French')
    assert [i['id'] for i in combined['items']] == list(ITEMS) + list(HAND_ITEMS)


def test_a_point_not_filled_in_is_missing_not_zero(tmp_path):
    path = str(tmp_path / hand.FILE)
    hand.write(path, [record('Jane Doe', 15.5)])
    fill(path, {('Jane Doe', 'Q4'): '1', ('Jane Doe', 'comments'): '0'})
    combined = hand.combine(record('Jane Doe', 15.5), hand.read(path)['Jane Doe'])
    assert combined['total'] == 16.5
    assert combined['missing'] == ['Q5', 'Q6', 'Q7', 'Q8', 'Q9', 'quality']  # comments: a real 0
    no_row = hand.combine(record('Paul Martin', 12.0), None)
    assert no_row['missing'] == list(HAND_ITEMS) and no_row['total'] == 12.0


@pytest.mark.parametrize('cell', ['5', '-1', 'abc', '1.5.2', '4,5'])
def test_a_cell_out_of_range_or_not_a_number_is_refused_with_its_place(tmp_path, cell):
    path = str(tmp_path / hand.FILE)
    hand.write(path, [record('Jane Doe', 17.0)])
    fill(path, {('Jane Doe', 'comments'): cell})
    with pytest.raises(hand.HandError) as caught:
        hand.read(path)
    assert 'line 3 (Jane Doe), column comments' in str(caught.value) and repr(cell) in str(caught.value)


def test_writing_again_keeps_everything_the_teacher_wrote(tmp_path):
    path = str(tmp_path / hand.FILE)
    hand.write(path, [record('Jane Doe', 15.5), record('Paul Martin', 10.0)])
    fill(path, {('Jane Doe', 'Q6'): '1', ('Jane Doe', 'remark'): 'seen'})
    with open(path) as f:
        text = f.read().replace('remark', 'remark,my column', 1).replace('seen', 'seen,kept', 1)
    with open(path, 'w') as f:
        f.write(text)
    # A rescore: Jane's machine points changed, Ada is new, Paul is no longer in the run.
    assert hand.write(path, [record('Jane Doe', 17.0), record('Ada Lovelace', 9.0)]) == 1
    with open(path, newline='') as f:
        rows = {r['student']: r for r in csv.DictReader(f)}
    assert rows['Jane Doe']['Q6'] == '1' and rows['Jane Doe']['remark'] == 'seen'
    assert rows['Jane Doe']['my column'] == 'kept' and rows['Jane Doe']['machine'] == '17'
    assert set(rows) == {hand.MAX_ROW, 'Jane Doe', 'Paul Martin', 'Ada Lovelace'}


def test_a_student_twice_or_a_renamed_column_is_refused(tmp_path):
    path = str(tmp_path / hand.FILE)
    hand.write(path, [record('Jane Doe', 17.0)])
    with open(path) as f:
        lines = f.read().splitlines()
    with open(path, 'w') as f:
        f.write('\n'.join(lines + [lines[-1]]) + '\n')
    with pytest.raises(hand.HandError, match='Jane Doe is already on another line'):
        hand.read(path)
    with open(path, 'w') as f:
        f.write('\n'.join([lines[0].replace('quality', 'Quality')] + lines[1:]) + '\n')
    with pytest.raises(hand.HandError, match='no column quality'):
        hand.read(path)


def worksheet_script():
    import importlib.util
    import os
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__)))))
    spec = importlib.util.spec_from_file_location('worksheet_script', os.path.join(repo, 'lab', 'scripts',
                                                                                    'worksheet.py'))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def write_worksheet(path, text):
    """``text`` into ``path`` as Moodle's download holds it: its CRLFs kept as they are (Path.write_text
    takes ``newline`` from Python 3.10 only)."""
    with open(str(path), 'w', encoding='utf-8', newline='') as f:
        f.write(text)


WORKSHEET = '\ufeff' + '\r\n'.join([
    'Identifier,"Full name",Status,Grade,"Maximum grade","Grade can be changed","Last modified (grade)",'
    '"Feedback comments"',
    '"Participant 101","Jane Doe","Submitted for grading",,20.00,Yes,-,',
    '"Participant 102","Paul Martin","Submitted for grading",,20.00,Yes,-,',
]) + '\r\n'


def test_the_whole_grade_on_the_worksheets_scale_and_nothing_missing_taken_as_zero(tmp_path, capsys):
    out = tmp_path / 'out'
    jane, paul = record('Jane Doe', 17.0, 101), record('Paul Martin', 15.5, 102)
    write_run(out, [jane, paul])
    cells = {('Jane Doe', item): str(top) for item, (top, _) in HAND_ITEMS.items()}
    cells[('Jane Doe', 'quality')] = '1'
    cells[('Paul Martin', 'Q4')] = '1'
    fill(str(out / hand.FILE), cells)
    write_worksheet(tmp_path / 'ws.csv', WORKSHEET)
    assert worksheet_script().main(['--out', str(out), '--worksheet', str(tmp_path / 'ws.csv')]) == 0
    printed = capsys.readouterr().out
    filled = (out / moodle.UPLOAD).read_text(encoding='utf-8-sig')
    rows = {r['Full name']: r for r in csv.DictReader(filled.splitlines())}
    # Jane: 17 + 12 = 29 of 30 on a worksheet out of 20.
    assert rows['Jane Doe']['Grade'] == '19.33'
    comment = rows['Jane Doe']['Feedback comments']
    assert '29 / 30 points: 17 of 17 by the machine' in comment and 'quality 1/2 (by hand)' in comment
    # Paul's hand points are not all given: no grade, and he is named with what is missing.
    assert rows['Paul Martin']['Grade'] == '' and rows['Paul Martin']['Feedback comments'] == ''
    assert 'Paul Martin (hand points not given yet in hand.csv: Q5, Q6, Q7, Q8, Q9, comments, quality)' in printed
    assert 'hand points not given yet' in printed


def test_a_badly_filled_hand_csv_stops_the_worksheet_with_every_problem(tmp_path, capsys):
    import json
    out = tmp_path / 'out'
    (out / 'Jane Doe').mkdir(parents=True)
    (out / 'Jane Doe' / 'grade.json').write_text(json.dumps(record('Jane Doe', 17.0, 101)))
    hand.write(str(out / hand.FILE), [record('Jane Doe', 17.0, 101)])
    fill(str(out / hand.FILE), {('Jane Doe', 'Q5'): 'two', ('Jane Doe', 'comments'): '9'})
    (tmp_path / 'ws.csv').write_text(WORKSHEET, encoding='utf-8')
    assert worksheet_script().main(['--out', str(out), '--worksheet', str(tmp_path / 'ws.csv')]) == 1
    err = capsys.readouterr().err
    assert "column Q5: 'two'" in err and "column comments: '9'" in err
    assert not (out / moodle.UPLOAD).exists()


def test_a_grade_json_that_is_no_grade_stops_the_worksheet_naming_it(tmp_path, capsys):
    """make worksheet reads each grade.json as the grader's record (capped, checked): one edited by
    hand or cut short stops it, naming the file and the field, and nothing is written."""
    import json
    out = tmp_path / 'out'
    jane, paul = record('Jane Doe', 17.0, 101), record('Paul Martin', 15.5, 102)
    write_run(out, [jane, paul])
    write_worksheet(tmp_path / 'ws.csv', WORKSHEET)
    (out / 'Paul Martin' / 'grade.json').write_text(json.dumps(dict(paul, total='15.5 points')))
    assert worksheet_script().main(['--out', str(out), '--worksheet', str(tmp_path / 'ws.csv')]) == 1
    err = capsys.readouterr().err
    assert 'NOT filled: Paul Martin/grade.json: grade.json.total' in err, err
    assert not (out / moodle.UPLOAD).exists()
    (out / 'Paul Martin' / 'grade.json').write_text(json.dumps(paul)[:40])
    assert worksheet_script().main(['--out', str(out), '--worksheet', str(tmp_path / 'ws.csv')]) == 1
    assert 'NOT filled: Paul Martin/grade.json' in capsys.readouterr().err



def moodle_record(folder, total):
    """A class student's record as a run makes it: the name cleaned from Moodle's folder name (the
    intake's own rule), the participant number read from it."""
    from exam_lab.grader.score import identity
    return dict(record(identity.student_name(folder), total, identity.participant_number(folder)), folder=folder)


def named_as_a_run_names_them(records):
    """Each record's name made unique as a class run does (class_run._unique, in the folders' order)."""
    from exam_lab.grader import class_run
    records = sorted(records, key=lambda r: r['folder'])
    names = class_run._unique([(r['student'], r['folder']) for r in records])
    return [dict(r, student=name) for r, (name, _) in zip(records, names)]


WORKSHEET_TWO_JANES = '\ufeff' + '\r\n'.join([
    'Identifier,"Full name",Status,Grade,"Maximum Grade","Grade can be changed","Last modified (grade)",'
    '"Feedback comments"',
    '"Participant 1001","Jane Doe.","Submitted for grading",,30.00,Yes,-,',
    '"Participant 1002","Jane Doe","Submitted for grading",,30.00,Yes,-,',
]) + '\r\n'


def write_run(out, records):
    import json
    for r in records:
        (out / r['student']).mkdir(parents=True, exist_ok=True)
        (out / r['student'] / 'grade.json').write_text(json.dumps(r))
    hand.write(str(out / hand.FILE), records)


def test_a_name_differing_by_a_trailing_dot_never_takes_a_classmates_hand_points(tmp_path, capsys):
    """Issue 36's case. Jane Doe (participant 1002) is graded, the teacher gives her 13 hand points
    and a remark; Jane Doe. (participant 1001, cleaned to the same name) submits late, make grade
    runs again and sorts her first (she takes the name "Jane Doe", the first Jane becomes "Jane
    Doe_2"). make worksheet: the points and the remark stay participant 1002's; 1001 has none yet."""
    import shutil
    out = tmp_path / 'out'
    first = named_as_a_run_names_them([moodle_record('Jane Doe_1002_assignsubmission_file_', 15.0)])
    assert [r['student'] for r in first] == ['Jane Doe']
    write_run(out, first)
    cells = {('Jane Doe', item): str(top) for item, (top, _) in HAND_ITEMS.items()}
    cells[('Jane Doe', 'remark')] = 'a clear report'
    fill(str(out / hand.FILE), cells)
    late = named_as_a_run_names_them([moodle_record('Jane Doe_1002_assignsubmission_file_', 15.0),
                                       moodle_record('Jane Doe._1001_assignsubmission_file_', 11.0)])
    assert [(r['student'], r['participant']) for r in late] == [('Jane Doe', 1001), ('Jane Doe_2', 1002)]
    shutil.rmtree(str(out / 'Jane Doe'))
    write_run(out, late)
    hands = hand.read(str(out / hand.FILE))
    assert hands[1002].remark == 'a clear report' and hands[1002].points['comments'] == 4.0
    assert hands[1002].student == 'Jane Doe_2' and all(v is None for v in hands[1001].points.values())
    write_worksheet(tmp_path / 'ws.csv', WORKSHEET_TWO_JANES)
    assert worksheet_script().main(['--out', str(out), '--worksheet', str(tmp_path / 'ws.csv')]) == 0
    filled = (out / moodle.UPLOAD).read_text(encoding='utf-8-sig')
    rows = {r['Identifier']: r for r in csv.DictReader(filled.splitlines())}
    assert rows['Participant 1002']['Grade'] == '28'  # 15 + 13 of 30
    assert 'a clear report' in rows['Participant 1002']['Feedback comments']
    assert rows['Participant 1001']['Grade'] == '' and rows['Participant 1001']['Feedback comments'] == ''
    assert 'Jane Doe (hand points not given yet in hand.csv: Q4, Q5' in capsys.readouterr().out  # 1001's: none yet


def test_a_kept_row_whose_participant_no_longer_matches_stops_the_worksheet(tmp_path, capsys):
    """The row of Jane Doe (participant 1002) was filled; now the only Jane Doe graded is 1001 (1002's
    folder went): the row is not hers, and make worksheet stops naming both."""
    out = tmp_path / 'out'
    write_run(out, [moodle_record('Jane Doe_1002_assignsubmission_file_', 15.0)])
    fill(str(out / hand.FILE), {('Jane Doe', item): str(top) for item, (top, _) in HAND_ITEMS.items()})
    import shutil
    shutil.rmtree(str(out / 'Jane Doe'))
    write_run(out, [moodle_record('Jane Doe._1001_assignsubmission_file_', 11.0)])
    write_worksheet(tmp_path / 'ws.csv', WORKSHEET_TWO_JANES)
    assert worksheet_script().main(['--out', str(out), '--worksheet', str(tmp_path / 'ws.csv')]) == 1
    err = capsys.readouterr().err
    assert 'hand.csv line 3 (Jane Doe, participant 1002)' in err
    assert 'Jane Doe (participant 1001, folder Jane Doe._1001_assignsubmission_file_)' in err
    assert not (out / moodle.UPLOAD).exists()


def test_a_row_without_a_number_is_not_given_to_a_student_who_has_one(tmp_path, capsys):
    """A row written when the class had no participant numbers (a folder of plain names) meets a
    Moodle class with the same name: not guessed."""
    out = tmp_path / 'out'
    hand.write(str(out.mkdir() or out / hand.FILE), [record('Jane Doe', 15.0)])
    fill(str(out / hand.FILE), {('Jane Doe', 'Q4'): '1'})
    jane = moodle_record('Jane Doe_1002_assignsubmission_file_', 15.0)
    write_run(out, [jane])
    with pytest.raises(hand.HandError, match='no participant number'):
        hand.match(hand.read(str(out / hand.FILE)), [jane])


def graded_on(grade, date):
    return dict(grade, provenance=dict(grade.get('provenance') or {}, date=date))


def test_one_participant_in_two_folders_has_the_row_of_its_newest_grade_and_the_class_its_own(tmp_path):
    """A student renamed in Moodle between two runs (two folders of OUT, one number), or a flat download
    with exam.zip and exam_v2.zip: that participant's matter. hand.csv is written for everyone, the
    participant's row is its newest grade's, and the notes say which grade is used and which not
    (it used to refuse the whole class's hand.csv)."""
    path = str(tmp_path / hand.FILE)
    twice = [graded_on(record('Jane Doe', 15.0, 1002), '2026-12-01T10:00:00Z'),
             graded_on(record('Jane Doe_2', 12.0, 1002), '2026-12-01T11:00:00Z'), record('Paul Martin', 10.0, 7)]
    assert hand.write(path, twice) == 2
    hands = hand.read(path)
    assert sorted(hands) == [7, 1002] and hands[1002].student == 'Jane Doe_2'
    chosen, notes = hand.newest(twice)
    assert [r['student'] for r in chosen] == ['Jane Doe_2', 'Paul Martin']
    assert notes == ["participant 1002 has 2 grades (Jane Doe, Jane Doe_2): the newest, Jane Doe_2's, is used; "
                     "Jane Doe not (two archives or two folders of one participant: remove the stale one and "
                     "run make rescore)"]
    fill(path, {('Jane Doe_2', 'Q4'): '1'})
    rows, _ = hand.match(hand.read(path), twice)
    assert [r.points['Q4'] if r else None for r in rows] == [None, 1.0, None]


def test_two_students_sharing_a_name_keep_their_own_rows(tmp_path):
    """Two Moodle users really named Jane Doe: two rows, each with its number; filling one leaves the
    other empty, and a rescore with their names swapped keeps each row with its participant."""
    path = str(tmp_path / hand.FILE)
    a, b = record('Jane Doe', 15.0, 1), record('Jane Doe_2', 12.0, 2)
    assert hand.write(path, [a, b]) == 2
    fill(path, {('Jane Doe_2', 'Q4'): '1'})
    assert hand.write(path, [dict(a, student='Jane Doe_2'), dict(b, student='Jane Doe')]) == 0
    hands = hand.read(path)
    assert hands[2].points['Q4'] == 1.0 and hands[2].student == 'Jane Doe' and hands[1].points['Q4'] is None
    rows, notes = hand.match(hands, [dict(a, student='Jane Doe_2'), dict(b, student='Jane Doe')])
    assert [r.participant for r in rows] == [1, 2] and notes == []


@pytest.mark.parametrize('name', ['=cmd|"/c calc"!A1', '+1', '-Jane', '@SUM(A1)', '\tJane', '\rJane', "'t Hooft",
                                  "''", 'Jane -= Doe'])
def test_a_name_no_spreadsheet_runs_and_read_back_exactly(tmp_path, name):
    """OWASP's rule in hand.csv and grades.csv: a cell beginning with = + - @ tab or CR begins with a
    quote; the grader reads back exactly what it was given (a name beginning with a quote too), and
    writing again does not add a second quote. The teacher's remark is kept the same way."""
    from exam_lab.grader.publish import cells, report
    from exam_lab.grader.score import safe_text
    path = str(tmp_path / hand.FILE)
    student = dict(record('Jane', 15.0, 7), student=name)  # the name as given, before any cleaning
    hand.write(path, [student])
    fill(path, {(cells.cell(name), 'remark'): '=1+1'})  # typed in a spreadsheet, saved as text
    for _ in range(2):
        hand.write(path, [student])
        with open(path, newline='') as f:
            raw = dict(zip(hand.COLUMNS, [r for r in csv.reader(f)][2]))
        assert raw['student'] == (name if name == 'Jane -= Doe' else "'" + name)
        assert raw['remark'] == "'=1+1"
        assert hand.read(path)[7].student == name.strip() and hand.read(path)[7].remark == '=1+1'
    report.write_csv(str(tmp_path / 'grades.csv'), [dict(student, status='-graded')])
    with open(str(tmp_path / 'grades.csv'), newline='') as f:
        rows = list(csv.DictReader(f))
    assert rows[0]['student'][:1] not in cells.FORMULA_STARTS
    assert cells.read_cell(rows[0]['student']) == safe_text.one_line(name)
    assert rows[0]['participant'] == '7' and rows[0]['status'] == "'-graded"


@pytest.mark.parametrize('value, written', [('=1+1', "'=1+1"), ('+33 6', "'+33 6"), ('-x', "'-x"), ('@a', "'@a"),
                                            ('\tx', "'\tx"), ('\rx', "'\rx"), ("'x", "''x"), ('-', '-'), ('', ''),
                                            ('x=1', 'x=1'), ('12.5', '12.5'), (None, '')])
def test_the_one_cell_rule(value, written):
    from exam_lab.grader.publish import cells
    assert cells.cell(value) == written
    assert cells.read_cell(written) == ('' if value is None else value)


def test_a_late_classmate_of_the_same_name_never_takes_the_first_ones_folder(tmp_path):
    """The folders of OUT (kept measurements, grade.json, logs) stay with their participant: run 1
    graded Jane Doe (1002) into OUT/Jane Doe; run 2, with Jane Doe. (1001) sorted before her, keeps
    1002 in OUT/Jane Doe and gives 1001 a folder of her own. A folder of OUT that is a participant's
    not in this run is not given to anyone either."""
    import json
    from exam_lab.grader import class_run
    from exam_lab.grader.score.records import MEASUREMENTS
    out = tmp_path / 'out'
    (out / 'Jane Doe').mkdir(parents=True)
    (out / 'Jane Doe' / MEASUREMENTS).write_text(json.dumps({'extra': {'participant': 1002}}))
    (out / 'Paul').mkdir()
    (out / 'Paul' / 'grade.json').write_text(json.dumps({'folder': 'Paul_7_assignsubmission_file_'}))
    (out / 'Paul' / 'logs').mkdir()
    assert class_run.kept_folders(str(out)) == {1002: 'Jane Doe', 7: 'Paul'}
    class_ = [('Jane Doe', '/c/Jane Doe._1001_assignsubmission_file_'),
              ('Jane Doe', '/c/Jane Doe_1002_assignsubmission_file_'), ('Paul', '/c/Paul_8_assignsubmission_file_')]
    assert class_run._unique(class_, class_run.kept_folders(str(out))) == [
        ('Jane Doe_2', class_[0][1]), ('Jane Doe', class_[1][1]), ('Paul_2', class_[2][1])]
    assert class_run._unique(class_) == [('Jane Doe', class_[0][1]), ('Jane Doe_2', class_[1][1]), ('Paul', class_[2][1])]
    folders = tmp_path / 'class'
    for _, path in class_:
        (folders / path.split('/')[-1]).mkdir(parents=True)
    assert [name for name, _ in class_run.class_students(str(folders), [], out=str(out))] == ['Jane Doe_2', 'Jane Doe', 'Paul_2']


def test_a_kept_file_of_any_shape_never_stops_the_class_nor_frees_a_folder_it_names(tmp_path):
    """kept_folders is lenient on purpose (its docstring): a measurements.json that is no object (cut,
    edited) gives way to the folder's grade.json; NaN (a measured value) is read; a number that is
    true or a string is none; no kept file of any shape stops the class's listing."""
    import json
    from exam_lab.grader import class_run
    from exam_lab.grader.score.records import MEASUREMENTS
    out = tmp_path / 'out'
    for name, measured, grade in (
            ('Ann', '["not", "an", "object"]', {'participant': 11}),
            ('Bob', '{"extra": {"participant": 12}, "session": {"value": NaN}}', None),
            ('Cy', '{"extra": "no facts"}', {'folder': 'Cy_13_assignsubmission_file_'}),
            ('Di', '{"extra": {"participant": true}}', None), ('Ed', '{"extra": {"participant": "14"}}', None),
            ('Flo', '{"version": 1, "ext', {'participant': 16})):
        (out / name).mkdir(parents=True)
        (out / name / MEASUREMENTS).write_text(measured)
        if grade is not None:
            (out / name / 'grade.json').write_text(json.dumps(grade))
    assert class_run.kept_folders(str(out)) == {11: 'Ann', 12: 'Bob', 13: 'Cy', 16: 'Flo'}
