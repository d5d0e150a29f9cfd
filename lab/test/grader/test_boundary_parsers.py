"""The grader's parsers against hostile students (issue 26 point 1), read from the session's one
hostile class (conftest.py ``hostile_class``, hostile_run.py: graded once with ``JOBS=2`` by
``grade.py --class`` in a child process with a deadline, so that a parser that never ends fails the
test instead of hanging it).

This module's students of that class: ``i_leaker`` (its launch file names a variable of the grader's,
the drone's launch file through a path of the grader's workspace, an include and a root-only YAML
outside the package) and ``j_bomber`` (a second launch file loads a YAML alias bomb; a crafted PDF
report of 2 MB beside the package). Each is the good student's package with the files of
lab/test/grader/hostile/leaker or bomber copied over it: nothing of theirs runs as root, the grader
only reads them.
"""
import os

import pytest

from hostile_run import NAMES, files_under

LEAKER, BOMBER = 'i_leaker', 'j_bomber'


@pytest.fixture
def parsed_class(hostile_class):
    """The class with this module's secrets: the outside files' token and the grader's variable."""
    return dict(hostile_class, secrets=hostile_class['parser_secrets'])


def notes_of(record):
    return '\n'.join(record['for_the_teacher'])


def test_the_class_finishes(parsed_class):
    assert parsed_class['finished'], parsed_class['output']
    with open(os.path.join(parsed_class['out'], 'grades.csv')) as f:
        rows = f.read().splitlines()[1:]
    assert sorted(row.split(',')[0] for row in rows) == NAMES


def test_no_secret_of_the_grader_reaches_the_results(parsed_class):
    assert parsed_class['finished'], parsed_class['output']
    for path, text in files_under(parsed_class['out']):
        for secret in parsed_class['secrets']:
            assert secret not in text, path


def test_nothing_outside_the_package_is_read_or_written(parsed_class):
    assert parsed_class['finished'], parsed_class['output']
    assert parsed_class['new_derived'] == [], 'derived copies written outside the work folder'
    assert parsed_class['outside'] == ['outside.launch', 'secret.yaml']
    notes = notes_of(parsed_class['records'][LEAKER])
    for written in ('$(optenv EXAM_WS /nonexistent)/../mydrone/launch/mydrone.launch',
                    '/tmp/exam-hostile-parsers/outside.launch', '/tmp/exam-hostile-parsers/secret.yaml'):
        assert 'file outside the package: ' in notes and written in notes, notes


def test_the_bomb_and_the_pdf_say_why(parsed_class):
    assert parsed_class['finished'], parsed_class['output']
    record = parsed_class['records'][BOMBER]
    assert 'config/bomb.yaml not read: YAML anchors and aliases (&name, *name) are refused' in notes_of(record)
    assert record['documents'] == [{'name': 'report.pdf', 'pages': None}], 'the page says "pages unknown"'
