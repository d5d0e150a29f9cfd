"""An OUT folder restored from an archive or handed over by a colleague is as foreign as a box's output:
make rescore and make worksheet read it through the contract (grader/contract.py) and write in it only
through its writer. Each hostile entry is that student's line, never a write elsewhere, never a hang
(each script runs in a child process with a timeout: a regression fails, it cannot hang the suite).
The kept files are copies of a real grading (data/kept/version-1). No ROS, no box."""
import json
import os
import subprocess
import sys

import pytest

from exam_lab.grader import contract
from exam_lab.grader.publish import grades, hand
from exam_lab.grader.score.records import MEASUREMENTS, RecordError

KEPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'data', 'kept', 'version-1')
SCRIPTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'scripts')
#: Seconds a script may take on two students (it takes about one): past them it hangs.
TIMEOUT = 60


def kept(name, file):
    with open(os.path.join(KEPT, file)) as f:
        return json.load(f)


def student(out, name, participant, **changes):
    """A student's folder of OUT as make grade leaves it (the real kept files, named ``name``, of
    ``participant``); ``changes`` to its grade.json."""
    folder = out / name
    folder.mkdir(parents=True)
    facts = {'participant': participant, 'folder': '%s_%d_assignsubmission_file_' % (name, participant)}
    measured = kept(name, MEASUREMENTS)
    measured.update(student=name, extra=dict(measured['extra'], **facts))
    (folder / MEASUREMENTS).write_text(json.dumps(measured))
    (folder / 'grade.json').write_text(json.dumps(dict(kept(name, 'grade.json'), student=name, **dict(facts, **changes))))
    return folder


def run(script, *args):
    done = subprocess.run([sys.executable, os.path.join(SCRIPTS, script)] + list(args), stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, timeout=TIMEOUT, env=os.environ)
    return done.returncode, done.stdout.decode('utf-8', 'replace')


@pytest.fixture
def out(tmp_path):
    out = tmp_path / 'out'
    student(out, 'Ann', 101)
    student(out, 'Bob', 102)
    return out


def test_a_fifo_as_grade_json_is_that_students_line_never_a_hang(out, tmp_path):
    (out / 'Bob' / 'grade.json').unlink()
    os.mkfifo(str(out / 'Bob' / 'grade.json'))
    status, said = run('rescore.py', '--out', str(out))
    assert status == 1 and "Bob: not rescored (its grade.json kept as it is, not in grades.csv): " \
        "Bob/grade.json: not a regular file" in said, said
    assert json.loads((out / 'Ann' / 'grade.json').read_text())['provenance']['how'] == 'rescore'
    status, said = run('worksheet.py', '--out', str(out), '--worksheet', str(tmp_path / 'ws.csv'))
    assert status == 1 and 'worksheet: NOT filled: Bob/grade.json: not a regular file' in said, said


def test_a_fifo_as_hand_csv_or_measurements_never_hangs(out, tmp_path):
    os.mkfifo(str(out / hand.FILE))
    (out / 'Bob' / MEASUREMENTS).unlink()
    os.mkfifo(str(out / 'Bob' / MEASUREMENTS))
    status, said = run('rescore.py', '--out', str(out))
    assert status == 1 and 'Bob: not rescored (its grade kept as it was): Bob/measurements.json: not a regular ' \
        'file' in said, said
    assert 'hand.csv NOT written: ' in said and 'hand.csv: not a regular file' in said, said
    status, said = run('worksheet.py', '--out', str(out), '--worksheet', str(tmp_path / 'ws.csv'))
    assert status == 1 and 'hand.csv: not a regular file' in said, said


def test_grade_md_as_a_link_is_replaced_never_written_through(out, tmp_path):
    teachers = tmp_path / 'teachers-notes.md'
    teachers.write_text('my notes\n')
    os.symlink(str(teachers), str(out / 'Ann' / 'grade.md'))
    os.symlink(str(teachers), str(out / 'index.html'))
    records, changes = grades.rescore(str(out))
    assert [r['student'] for r in records] == ['Ann', 'Bob']
    assert teachers.read_text() == 'my notes\n'
    assert not os.path.islink(str(out / 'Ann' / 'grade.md')) and (out / 'Ann' / 'grade.md').read_text().startswith('# Ann')
    status, said = run('rescore.py', '--out', str(out))
    assert status == 0 and teachers.read_text() == 'my notes\n' and not os.path.islink(str(out / 'index.html'))


def test_a_student_folder_that_is_a_link_is_no_student_and_nothing_is_written_through_it(out, tmp_path):
    elsewhere = tmp_path / 'elsewhere'
    student(elsewhere, 'Cy', 103)
    before = {name: (elsewhere / 'Cy' / name).read_bytes() for name in os.listdir(str(elsewhere / 'Cy'))}
    os.symlink(str(elsewhere / 'Cy'), str(out / 'Cy'))
    status, said = run('rescore.py', '--out', str(out))
    assert status == 0 and 'Cy' not in said.split('\n', 1)[1].split('page:')[0], said
    assert {name: (elsewhere / 'Cy' / name).read_bytes() for name in os.listdir(str(elsewhere / 'Cy'))} == before
    with pytest.raises(RecordError, match='not followed'):
        contract.write_text(str(out / 'Cy' / 'grade.md'), 'x')
    with pytest.raises(RecordError, match='not followed'):
        contract.read_bytes(str(out / 'Cy' / 'grade.json'), 1 << 20, under=str(out))
    assert (elsewhere / 'Cy' / 'grade.md').exists() is False


def test_a_record_whose_student_is_a_path_writes_nothing_outside_out(out, tmp_path):
    measured = json.loads((out / 'Bob' / MEASUREMENTS).read_text())
    (out / 'Bob' / MEASUREMENTS).write_text(json.dumps(dict(measured, student='../../x')))
    (out / 'Bob' / 'grade.json').write_text(json.dumps(dict(json.loads((out / 'Bob' / 'grade.json').read_text()),
                                                          student='../../x')))
    status, said = run('rescore.py', '--out', str(out))
    assert status == 1 and "Bob: not rescored (its grade.json kept as it is, not in grades.csv): grade.json: the " \
        "grade of '../../x', in the folder 'Bob'" in said, said
    assert not (tmp_path / 'x').exists() and not (tmp_path.parent / 'x').exists()
    assert sorted(p for p in os.listdir(str(tmp_path)) if p != 'out') == []
    status, said = run('worksheet.py', '--out', str(out), '--worksheet', str(tmp_path / 'ws.csv'))
    assert status == 1 and "Bob/grade.json: the grade of '../../x', in the folder 'Bob'" in said, said


@pytest.mark.parametrize('changes, words', [
    ({'items': [], 'total': 17.0}, 'grade.json.total: 17.0, but its 0 item(s) come to 0'),
    ({'status': 'graded by me'}, "grade.json.status: 'graded by me' is no status the rubric gives"),
    ({'total': 20.0}, 'grade.json.total: 20.0, but its 7 item(s) come to 17.0'),
])
def test_a_grade_that_is_not_the_rubrics_stops_make_worksheet_naming_the_file(tmp_path, changes, words):
    out = tmp_path / 'out'
    student(out, 'Ann', 101)
    student(out, 'Bob', 102, **changes)
    status, said = run('worksheet.py', '--out', str(out), '--worksheet', str(tmp_path / 'ws.csv'))
    assert status == 1 and 'worksheet: NOT filled: Bob/grade.json' in said and words in said, said
    records, lines = grades.rescore(str(out))
    assert [r['student'] for r in records] == ['Ann'] and words in lines[0] and lines[0].startswith('Bob: not rescored')


def test_one_participant_in_two_folders_is_its_own_line_and_hand_csv_is_written_for_everyone(tmp_path):
    """Renamed in Moodle between two runs: Bob and Robert are one participant (102)."""
    out = tmp_path / 'out'
    student(out, 'Ann', 101)
    student(out, 'Bob', 102)
    student(out, 'Robert', 102)
    status, said = run('rescore.py', '--out', str(out))
    assert status == 0 and 'participant 102 has 2 grades (Bob, Robert): the newest, ' in said, said
    assert 'hand.csv NOT written' not in said
    rows = hand.read(str(out / hand.FILE))
    assert sorted(rows) == [101, 102]
