"""The judge's time, master and CPU are its own (issue 26 points 2 and 3), read from the session's one
hostile class (conftest.py ``hostile_class``, hostile_run.py: graded once with ``JOBS=2``).

This module's students of that class: ``a_burner`` (140 busy processes, each ``setsid``, for 60 s while
it builds), ``b_victim`` (the good student's package, graded beside the burner, the first two of the
class starting together: it keeps its 17 points and its node comes up in a few seconds), ``g_clock``
(sets ``/use_sim_time`` and publishes a ``/clock`` 5/7 as fast as the wall's, so its node warns 7 s late
while a grader on that clock sees 5 s: refused, a hand grade), and ``h_param_flood`` (ten ``setParam``
calls of 64 MB: the master stays within its memory bound, the run is refused and the class goes on).
``l_hooked`` (a launch file roslaunch refuses, and a catkin environment hook that answers for roslaunch's
check when the student's workspace is sourced for it: issue 36 point 4), ``m_respawner`` (a chatty node
that dies once, started again by roslaunch's ``respawn``: its death lies in the middle of the launch log
the grader cuts; issue 36 point 4). All but ``a_burner`` run the good student's node beside their
payload. Payloads in
lab/test/grader/hostile/, doing nothing as root. And one submission, ``sleeper``, graded alone with a
budget of BUDGET_S (issue 36 point 6), a minute of sleep.
"""
import json
import os
import re
import time

import pytest

from exam_lab.grader import runner
from exam_lab.grader.host import limits, uids, underlay
from exam_lab.grader.host import run as host_run
from exam_lab.grader.score import rubric, runs
from exam_lab.grader.score.sheets import ITEMS
from hostile_run import HOSTILE, JOBS, NAMES, VICTIM_NAME

FULL = {item: points for item, (points, _) in ITEMS.items()}
BURNER, CLOCK, PARAM_FLOOD, HOOKED, RESPAWNER = 'a_burner', 'g_clock', 'h_param_flood', 'l_hooked', 'm_respawner'
#: The budget the sleeper is graded with (its build sleeps 120 s).
BUDGET_S = 45.0
#: How far the burner's CPU time may pass its box's quota times its wall clock: the kernel enforces the
#: quota per period (100 ms) and counts CPU time in ticks. Measured 2026-11-27, two cores, JOBS=2: 37.8 s
#: of CPU in 60.1 s with the quota of one core; 81.2 s in 60.0 s with it turned off (this test fails).
QUOTA_SLACK = 1.1


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
    """A burner must not starve its classmate (beside 140 burners, before each box had a CPU quota,
    the good student's node never started). What shows it whatever the machine's load: the burner's
    processes got at most its box's quota (cores / JOBS) by the kernel's own accounting, the rest of
    the machine left to the others; and the victim, graded beside it, keeps every point, its timing
    items judged from its own values. (The victim's start-up in seconds measures the machine's load
    too: 11.3 s once at a load of 30, beside a burner held to its quota.)"""
    build = logs_of(judged_class, BURNER, 'build.log')
    assert 'burner: 140 processes burning' in build, 'the burner did not burn: this test proves nothing'
    used = re.search(r'burner: its processes used ([\d.]+) s of CPU in ([\d.]+) s', build)
    assert used, build[-3000:]
    cpu, wall = float(used.group(1)), float(used.group(2))
    quota = limits.box_cpus(JOBS)
    assert cpu <= quota * wall * QUOTA_SLACK, \
        'the burner used %.1f s of CPU in %.1f s: more than its quota of %.2f cores' % (cpu, wall, quota)
    record = judged_class['records'][VICTIM_NAME]
    assert {i['id']: i['points'] for i in record['items']} == FULL, evidence(record)
    main = json.loads(logs_of(judged_class, VICTIM_NAME, 'probe-main.json'))
    # The node's start counts from roslaunch's (its /roslaunch/uris/ parameter on the master), never before.
    assert main['launch_seen_s'] is not None and main['node_seen_s'] is not None, main
    assert main['launch_seen_s'] <= main['node_seen_s'] < main['launch_seen_s'] + runner.START_TIMEOUT, main


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
    assert master['memory']['limit'] == limits.MASTER_MEMORY_BYTES, master
    assert master['memory']['peak'] <= limits.MASTER_MEMORY_BYTES and master['memory']['oom_kills'] >= 1, master


def test_the_judge_is_neither_root_nor_the_box(judged_class):
    for student in (VICTIM_NAME, CLOCK):
        runs = session_of(judged_class, student)['runs']
        assert runs, student
        for run in runs:
            judge = run['master']['uid']
            assert uids.JUDGE_UID_BASE <= judge < uids.JUDGE_UID_BASE + uids.SLOTS, (student, run['master'])
            assert run['probe_uid'] == judge, (student, run['probe_uid'], judge)
    probe = json.loads(logs_of(judged_class, VICTIM_NAME, 'probe-main.json'))
    assert probe['judge_uid'] >= uids.JUDGE_UID_BASE and probe['clock']['ros_time_is_wall'] is True


def test_no_judge_process_is_left(judged_class, all_class_runs_done):
    """Of the judge's uids (test_sandbox checks the boxes'), none whose slot no grader holds has a
    process left once the class is graded (and the session's other class runs: conftest.py)."""
    assert uids.left_behind(uids.JUDGE_UID_BASE) == []


def points_of(record):
    return {i['id']: i['points'] for i in record['items']}


def test_an_environment_hook_cannot_answer_for_roslaunch(judged_class):
    """Its launch file names two nodes /exam: roslaunch refuses it, whatever the hook (sourced with the
    student's workspace) would have said; Q12 is lost and the teacher told. The run itself, without the
    drone's node, keeps every other point."""
    check = session_of(judged_class, HOOKED)['launch_check']
    assert check['status'] == 1 and 'multiple nodes named [/exam]' in check['refused'], check
    record = judged_class['records'][HOOKED]
    assert points_of(record) == dict(FULL, Q12=0.0), evidence(record)
    assert [d for d in record['doubts'] if 'roslaunch refuses' in d], record['doubts']


def test_a_death_lost_in_the_cut_log_is_seen_by_the_judge(judged_class):
    """The chatter's death and respawn: roslaunch's words lie in the middle cut from the log, the probe's
    watch saw its pid change; it costs the runs point and a hand grade, like any death."""
    assert 'bytes cut by the grader' in logs_of(judged_class, RESPAWNER, 'launch-main.log'), \
        'the chatter did not fill the log: this test proves nothing'
    main = runs.judged_run(session_of(judged_class, RESPAWNER)['runs'][0])  # the deaths as the rubric counts them
    watched = [e for e in main['launch']['ended'] if e['detail'].startswith('seen by the judge')]
    assert [e['node'] for e in watched] == ['/chatter'], main['launch']['ended']
    record = judged_class['records'][RESPAWNER]
    assert points_of(record)['runs'] == 1.0 and record['status'] == rubric.HAND_GRADE, evidence(record)
    assert 'died' in record['status_reason'], record['status_reason']


def test_a_grading_past_its_budget_ends_at_it_and_says_so(tmp_path, monkeypatch):
    """The sleeper's build sleeps past a budget of BUDGET_S: its grading ends within the budget and
    what follows it, the build stopped, and its row says which budget, how large, and what it stopped."""
    if os.geteuid() != 0:
        pytest.skip('the sandbox is made by root (docs/grading.md, "Isolation")')
    underlay.ensure_underlay(underlay.default_underlay())  # built before the student's time starts
    monkeypatch.setattr(runner, 'STUDENT_BUDGET', BUDGET_S)
    start = time.monotonic()
    record = runner.grade_submission(os.path.join(HOSTILE, 'sleeper', 'exam'), str(tmp_path / 'out'), student='sleeper')
    took = time.monotonic() - start
    with open(str(tmp_path / 'out' / 'logs' / 'build.log')) as f:
        assert 'sleeper: sleeping through the build' in f.read(), 'the build did not sleep: this test proves nothing'
    assert took <= BUDGET_S + runner.AFTER_BUDGET_S, took
    assert record['status'] == rubric.HAND_GRADE, evidence(record)
    assert record['status_reason'].startswith('its grading used up its budget of %.0f s' % BUDGET_S), record['status_reason']
    assert 'catkin_make was stopped after' in record['status_reason'], record['status_reason']
    assert took >= BUDGET_S - 2 * host_run.STEP_STOP_S - 10, took  # stopped at the budget, not before
