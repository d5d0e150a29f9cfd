"""The judge's time, master and CPU are its own (issue 26 points 2 and 3), read from the session's one
hostile class (conftest.py ``hostile_class``, hostile_run.py: graded once with ``JOBS=2``).

This module's students of that class: ``a_burner`` (140 busy processes, each ``setsid``, for 60 s while
it builds), ``b_victim`` (the good student's package, graded beside the burner, the first two of the
class starting together: it keeps its 17 points and its node comes up in a few seconds), ``g_clock``
(sets ``/use_sim_time`` and publishes a ``/clock`` 5/7 as fast as the wall's, so its node warns 7 s late
while a grader on that clock sees 5 s: refused, a hand grade), and ``h_param_flood`` (ten ``setParam``
calls of 64 MB: the master stays within its memory bound, the run is refused and the class goes on).
``g_clock`` and ``h_param_flood`` run the good student's node beside their payload. Payloads in
lab/test/grader/hostile/, doing nothing as root.
"""
import json
import os

import pytest

from exam_lab.grader.host import sandbox
from exam_lab.grader.score import rubric
from exam_lab.grader.score.sheets import ITEMS
from hostile_run import NAMES, VICTIM_NAME

FULL = {item: points for item, (points, _) in ITEMS.items()}
BURNER, CLOCK, PARAM_FLOOD = 'a_burner', 'g_clock', 'h_param_flood'
#: The most seconds the good student's node may take to register beside the burner (it took 15.9 s of
#: the 20 s limit beside 60 burners, and never started beside 140, before each box had a CPU quota).
NODE_UP_S = 10.0


@pytest.fixture
def judged_class(hostile_class):
    return hostile_class


def logs_of(judged_class, student, name):
    with open(os.path.join(judged_class['out'], student, 'logs', name)) as f:
        return f.read()


def session_of(judged_class, student):
    return json.loads(logs_of(judged_class, student, 'session.json'))


def evidence(record):
    return '%s: %s\n%s' % (record['status'], record['status_reason'],
                           '\n'.join('%s: %s' % (i['id'], i['evidence']) for i in record['items']))


def test_the_classmate_of_a_burner_keeps_its_points_and_its_timing(judged_class):
    assert 'burner: 140 processes burning' in logs_of(judged_class, BURNER, 'build.log'), \
        'the burner did not burn: this test proves nothing'
    record = judged_class['records'][VICTIM_NAME]
    assert {i['id']: i['points'] for i in record['items']} == FULL, evidence(record)
    main = json.loads(logs_of(judged_class, VICTIM_NAME, 'probe-main.json'))
    assert main['node_seen_s'] is not None and main['node_seen_s'] < NODE_UP_S, main['node_seen_s']


def test_a_node_on_a_clock_of_its_own_is_refused(judged_class):
    record = judged_class['records'][CLOCK]
    assert record['total'] < 17.0, evidence(record)
    assert record['status'] == rubric.HAND_GRADE, evidence(record)
    assert '/use_sim_time was set' in record['status_reason'] and '/clock was published' in record['status_reason'], \
        record['status_reason']


def test_a_parameter_flood_stays_within_the_masters_bound(judged_class):
    with open(os.path.join(judged_class['out'], 'grades.csv')) as f:
        assert sorted(row.split(',')[0] for row in f.read().splitlines()[1:]) == NAMES
    record = judged_class['records'][PARAM_FLOOD]
    assert record['status'] == rubric.HAND_GRADE and 'memory bound' in record['status_reason'], evidence(record)
    master = session_of(judged_class, PARAM_FLOOD)['runs'][0]['master']
    assert master['memory']['limit'] == sandbox.MASTER_MEMORY_BYTES, master
    assert master['memory']['peak'] <= sandbox.MASTER_MEMORY_BYTES and master['memory']['oom_kills'] >= 1, master


def test_the_judge_is_neither_root_nor_the_box(judged_class):
    for student in (VICTIM_NAME, CLOCK):
        runs = session_of(judged_class, student)['runs']
        assert runs, student
        for run in runs:
            judge = run['master']['uid']
            assert sandbox.JUDGE_UID_BASE <= judge < sandbox.JUDGE_UID_BASE + sandbox.SLOTS, (student, run['master'])
            assert run['probe_uid'] == judge, (student, run['probe_uid'], judge)
    probe = json.loads(logs_of(judged_class, VICTIM_NAME, 'probe-main.json'))
    assert probe['judge_uid'] >= sandbox.JUDGE_UID_BASE and probe['clock']['ros_time_is_wall'] is True


def test_no_judge_process_is_left(judged_class):
    """Of the judge's uids (only this grader uses them; a box's uid may already be another grading's,
    test_sandbox checks those), no process is left once the class is graded."""
    assert [uid for uid in range(sandbox.JUDGE_UID_BASE, sandbox.JUDGE_UID_BASE + sandbox.SLOTS)
            if sandbox.pids_of_uid(uid)] == []
