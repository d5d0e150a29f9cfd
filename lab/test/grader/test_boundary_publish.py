"""What reaches the teacher from a noisy student (issue 26, points 4 and 5), read from the session's
one hostile class (conftest.py ``hostile_class``, hostile_run.py), graded as ``make grade`` grades a
class: ``grade.py --class`` with a Moodle worksheet and ``JOBS=2``.

This module's students of that class: ``k_noisy`` (lab/test/grader/hostile/noisy: publishes +-1.7e308
once among normal values, then dies with a traceback that erases the screen and writes "17/17
graded"; does nothing as root) and ``b_victim`` (the good student's package). grade.py must exit 0,
print a class summary without a control character, and write grades.csv, index.html and the
worksheet, the noisy student's flight plot drawn.
"""
import json
import os
import re

import pytest

from hostile_run import VICTIM_NAME

NOISY = 'k_noisy'
#: Control characters (newline and tab aside) and bidi controls, written out here.
CONTROL = re.compile('[\x00-\x08\x0b-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]')
#: The same in JSON as json.dump writes it (ASCII only: every control character as \u00XX).
ESCAPED_CONTROL = re.compile(r'\\u(?:00[01][0-9a-fA-F]|007[fF]|00[89][0-9a-fA-F]|202[a-eA-E]|206[6-9])')


@pytest.fixture
def graded(hostile_class):
    """``grade.py --class`` once: its exit status, what it printed, its output folder."""
    return hostile_class


def _read(path):
    with open(path, encoding='utf-8') as f:
        return f.read()


def test_the_desk_is_written_and_make_grade_succeeds(graded):
    assert graded['status'] == 0, graded['stderr'][-3000:]
    out = graded['out']
    for name in ('grades.csv', 'index.html', 'worksheet-as-downloaded.csv', 'worksheet.json', 'hand.csv'):
        assert os.path.isfile(os.path.join(out, name)), name
    # No hand point given: no file to upload (the machine's points alone are no grade).
    assert not os.path.exists(os.path.join(out, 'moodle-worksheet.csv'))
    for student in (NOISY, VICTIM_NAME):
        assert os.path.isfile(os.path.join(out, student, 'results.json')), student
        assert os.path.isfile(os.path.join(out, student, 'flight.png')), student


def test_the_extreme_values_reached_the_plot_drawn(graded):
    """The probe recorded +-1.7e308 (the payload ran), and the plot was drawn all the same."""
    with open(os.path.join(graded['out'], NOISY, 'logs', 'probe-main.json')) as f:
        published = [v for _, v in json.load(f)['trace']['published']]
    assert 1.7e308 in published and -1.7e308 in published
    assert 'src="%s/flight.png"' % NOISY in _read(os.path.join(graded['out'], 'index.html'))


def test_the_class_summary_has_no_control_character(graded):
    assert 'need the teacher' in graded['stdout'] and '17/17 graded' in graded['stdout']  # the payload's text
    assert sorted({repr(c) for c in CONTROL.findall(graded['stdout'] + graded['stderr'])}) == []


def test_no_output_for_the_teacher_has_a_control_character(graded):
    out = graded['out']
    paths = [os.path.join(out, name) for name in ('grades.csv', 'index.html', 'worksheet.json', 'hand.csv')]
    for student in (NOISY, VICTIM_NAME):
        paths += [os.path.join(out, student, name) for name in ('grade.md', 'grade.json', 'results.json')]
    found = {}
    for path in paths:
        text = _read(path)
        bad = CONTROL.findall(text) + (ESCAPED_CONTROL.findall(text) if path.endswith('.json') else [])
        if bad:
            found[os.path.relpath(path, out)] = sorted(set(bad))
    assert found == {}
    record = json.loads(_read(os.path.join(out, NOISY, 'grade.json')))
    assert record['status'] == 'needs a hand grade' and '17/17 graded' in record['status_reason']

