"""What reaches the teacher from a noisy student (issue 26, points 4 and 5): one class run with ``JOBS=2``.

The class: ``a_noisy`` (lab/test/grader/hostile/noisy: publishes +-1.7e308 once among normal values,
then dies with a traceback that erases the screen and writes "17/17 graded"; does nothing as root)
and ``b_good`` (the good student's package). ``grade.py --class`` runs as ``make grade`` runs it, with
a Moodle worksheet: it must exit 0, print a class summary without a control character, and write
grades.csv, index.html and the worksheet, the noisy student's flight plot drawn. About 2 minutes on
two cores.
"""
import json
import os
import re
import shutil
import subprocess
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
GRADE = os.path.join(REPO, 'lab', 'scripts', 'grade.py')
#: Student folders as Moodle's "download all submissions" names them (the participant numbers).
CLASS = [('a_noisy_101_assignsubmission_file_', os.path.join(HERE, 'hostile', 'noisy', 'exam')),
         ('b_good_102_assignsubmission_file_', os.path.join(HERE, 'submissions', 'good_student', 'exam'))]
WORKSHEET = ('\ufeffIdentifier,Full name,Grade,Maximum grade,Last modified (grade),Feedback comments\n'
             '"Participant 101","a noisy",,17.00,-,\n"Participant 102","b good",,17.00,-,\n')
#: Control characters (newline and tab aside) and bidi controls, written out here.
CONTROL = re.compile('[\x00-\x08\x0b-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]')
#: The same in JSON as json.dump writes it (ASCII only: every control character as \u00XX).
ESCAPED_CONTROL = re.compile(r'\\u(?:00[01][0-9a-fA-F]|007[fF]|00[89][0-9a-fA-F]|202[a-eA-E]|206[6-9])')
#: The whole class run's limit, s: two students side by side take about 2 minutes on a busy machine.
CLASS_TIMEOUT = 1200


@pytest.fixture(scope='module')
def graded(tmp_path_factory):
    """``grade.py --class`` once: its exit status, what it printed, its output folder."""
    if os.geteuid() != 0:
        pytest.skip('the sandbox is made by root (docs/grading.md, "Isolation")')
    root = tmp_path_factory.mktemp('noisy')
    for name, package in CLASS:
        shutil.copytree(package, str(root / 'class' / name / 'exam'), ignore=shutil.ignore_patterns('__pycache__'))
    (root / 'worksheet.csv').write_text(WORKSHEET, encoding='utf-8')
    out = root / 'out'
    done = subprocess.run([sys.executable, GRADE, '--class', str(root / 'class'), '--out', str(out), '--jobs', '2',
                           '--worksheet', str(root / 'worksheet.csv'), '--no-similarity'],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=CLASS_TIMEOUT)
    return {'status': done.returncode, 'stdout': done.stdout.decode('utf-8', 'replace'),
            'stderr': done.stderr.decode('utf-8', 'replace'), 'out': str(out)}


def _read(path):
    with open(path, encoding='utf-8') as f:
        return f.read()


def test_the_desk_is_written_and_make_grade_succeeds(graded):
    assert graded['status'] == 0, graded['stderr'][-3000:]
    out = graded['out']
    for name in ('grades.csv', 'index.html', 'worksheet-filled.csv', 'worksheet.json'):
        assert os.path.isfile(os.path.join(out, name)), name
    for student in ('a_noisy', 'b_good'):
        assert os.path.isfile(os.path.join(out, student, 'results.json')), student
        assert os.path.isfile(os.path.join(out, student, 'flight.png')), student


def test_the_extreme_values_reached_the_plot_drawn(graded):
    """The probe recorded +-1.7e308 (the payload ran), and the plot was drawn all the same."""
    with open(os.path.join(graded['out'], 'a_noisy', 'logs', 'probe-main.json')) as f:
        published = [v for _, v in json.load(f)['trace']['published']]
    assert 1.7e308 in published and -1.7e308 in published
    assert 'src="a_noisy/flight.png"' in _read(os.path.join(graded['out'], 'index.html'))


def test_the_class_summary_has_no_control_character(graded):
    assert 'need the teacher' in graded['stdout'] and '17/17 graded' in graded['stdout']  # the payload's text
    assert sorted({repr(c) for c in CONTROL.findall(graded['stdout'] + graded['stderr'])}) == []


def test_no_output_for_the_teacher_has_a_control_character(graded):
    out = graded['out']
    paths = [os.path.join(out, name) for name in ('grades.csv', 'index.html', 'worksheet-filled.csv')]
    for student in ('a_noisy', 'b_good'):
        paths += [os.path.join(out, student, name) for name in ('grade.md', 'grade.json', 'results.json')]
    found = {}
    for path in paths:
        text = _read(path)
        bad = CONTROL.findall(text) + (ESCAPED_CONTROL.findall(text) if path.endswith('.json') else [])
        if bad:
            found[os.path.relpath(path, out)] = sorted(set(bad))
    assert found == {}
    record = json.loads(_read(os.path.join(out, 'a_noisy', 'grade.json')))
    assert record['status'] == 'needs a hand grade' and '17/17 graded' in record['status_reason']

