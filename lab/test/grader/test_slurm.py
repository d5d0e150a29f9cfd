"""The Slurm engine on a single-node Slurm started on this machine by tools/slurm_local.sh (as a teacher
would try it): ``grade.py --class ... --engine slurm`` grades a class of three. Two students get the
points a local run gives them (test_grade.py's EXPECTED) in the same OUT; the third one's task is
cancelled with scancel while it runs, is submitted once more, is cancelled again, and is then "not
graded" with what Slurm said. Then Slurm is stopped and nothing of it is left running.
Two gradings side by side: 80 to 154 s measured on the shared two cores. Needs root (the daemons); installs Slurm when missing.
"""
import csv
import json
import os
import shutil
import subprocess
import sys
import time

import pytest

from test_grade import EXPECTED, FULL, STATUS

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.realpath(os.path.join(HERE, '..', '..', '..'))
SLURM_LOCAL = os.path.join(REPO, 'tools', 'slurm_local.sh')
GRADE = os.path.join(REPO, 'lab', 'scripts', 'grade.py')
SUBMISSIONS = os.path.join(HERE, 'submissions')
#: The class: each student's package in submissions/. Sorted first, the cancelled one is task 0.
CLASS = (('a_cancelled', 'good_student'), ('good_student', 'good_student'), ('no_delay', 'no_delay'))
#: Generous: the machine is shared, and a class of two is about 45 s of CPU per student.
WAIT_S = 900.0


def _slurm_local(command, state):
    done = subprocess.run([SLURM_LOCAL, command], env=dict(os.environ, EXAM_SLURM_DIR=state),
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=600)
    return done.returncode, done.stdout.decode('utf-8', 'replace')


def _left_running(state):
    """Processes of our Slurm still alive: its daemons (named by the state folder) and any job step."""
    left = []
    for pid in filter(str.isdigit, os.listdir('/proc')):
        try:
            with open('/proc/%s/cmdline' % pid, 'rb') as f:
                cmdline = f.read().replace(b'\0', b' ').decode('utf-8', 'replace')
            with open('/proc/%s/comm' % pid) as f:
                comm = f.read().strip()
        except OSError:
            continue  # gone meanwhile
        if state in cmdline or comm == 'slurmstepd':
            left.append('%s %s' % (pid, cmdline))
    return left


@pytest.fixture(scope='module')
def slurm(tmp_path_factory):
    """A single-node Slurm for this module: ``(environment with SLURM_CONF, its state folder)``."""
    if os.geteuid() != 0:
        missing = '' if shutil.which('slurmctld') else '; and Slurm is not installed (apt-get install ' \
            'slurmctld slurmd slurm-client munge)'
        pytest.skip('a local Slurm needs root to start its daemons%s' % missing)
    state = str(tmp_path_factory.mktemp('slurm'))
    code, output = _slurm_local('start', state)
    try:
        assert code == 0, output
        conf = [l.split('=', 1)[1] for l in output.splitlines() if l.startswith('export SLURM_CONF=')]
        assert conf, output
        yield dict(os.environ, SLURM_CONF=conf[0]), state
    finally:
        _slurm_local('stop', state)


def _wait_running(env, job_name, index, not_in, grading, log, deadline):
    """The array job id of task ``index`` once it runs, in a job not in ``not_in``."""
    while time.monotonic() < deadline:
        if grading.poll() is not None:
            with open(log) as f:
                pytest.fail('grade.py ended before task %d ran:\n%s' % (index, f.read()))
        out = subprocess.run(['squeue', '-h', '-r', '--name', job_name, '-o', '%F %K %T'], env=env,
                             stdout=subprocess.PIPE, timeout=60).stdout.decode()
        for job, task, state in (l.split() for l in out.splitlines() if len(l.split()) == 3):
            if task == str(index) and state == 'RUNNING' and job not in not_in:
                return job
        time.sleep(0.5)
    pytest.fail('task %d never ran in a job other than %s' % (index, not_in))


@pytest.fixture(scope='module')
def graded(slurm, tmp_path_factory):
    """The class graded on Slurm, its first task cancelled twice: ``(OUT, exit code, terminal output)``."""
    env, _ = slurm
    root = tmp_path_factory.mktemp('slurm-class')
    for name, source in CLASS:
        shutil.copytree(os.path.join(SUBMISSIONS, source, 'exam'),
                        str(root / 'class' / ('%s_%d_assignsubmission_file_' % (name, len(name))) / 'exam'),
                        ignore=shutil.ignore_patterns('__pycache__', '.grader-*'))
    out = root / 'out'
    log = str(root / 'grade.log')
    with open(log, 'w') as f:
        grading = subprocess.Popen([sys.executable, GRADE, '--class', str(root / 'class'), '--out', str(out),
                                    '--engine', 'slurm'], env=env, stdout=f, stderr=subprocess.STDOUT)
    try:
        deadline = time.monotonic() + WAIT_S
        first = _wait_running(env, 'exam-grade-out', 0, (), grading, log, deadline)
        subprocess.run(['scancel', '%s_0' % first], env=env, check=True, timeout=60)
        again = _wait_running(env, 'exam-grade-out', 0, (first,), grading, log, deadline)
        subprocess.run(['scancel', '%s_0' % again], env=env, check=True, timeout=60)
        code = grading.wait(timeout=max(1.0, deadline - time.monotonic()))
    finally:
        if grading.poll() is None:  # Ctrl-C: grade.py cancels its jobs
            grading.send_signal(2)
            grading.wait(timeout=120)
    with open(log) as f:
        return str(out), code, f.read()


def test_each_student_gets_the_points_of_a_local_run(graded):
    out, code, output = graded
    assert code == 0, output
    with open(os.path.join(out, 'grades.csv')) as f:
        rows = dict((r['student'], r) for r in csv.DictReader(f))
    assert sorted(rows) == sorted(name for name, _ in CLASS), output
    for name in ('good_student', 'no_delay'):
        with open(os.path.join(out, name, 'grade.json')) as f:
            record = json.load(f)
        assert dict((i['id'], i['points']) for i in record['items']) == dict(FULL, **EXPECTED[name]), output
        assert record['status'] == STATUS.get(name, 'graded') == rows[name]['status']
        assert float(rows[name]['total']) == record['total']
        for made in ('grade.md', 'results.json', 'flight.png', os.path.join('logs', 'build.log')):
            assert os.path.isfile(os.path.join(out, name, made)), made
    assert os.path.isfile(os.path.join(out, 'index.html'))
    assert 'similarity: ' in output, output


def test_a_cancelled_task_is_retried_once_then_not_graded_with_slurms_reason(graded):
    out, _, output = graded
    with open(os.path.join(out, 'a_cancelled', 'grade.json')) as f:
        record = json.load(f)
    assert record['status'] == 'not graded'
    assert record['status_reason'].startswith('could not grade: Slurm said: CANCELLED'), record['status_reason']
    assert output.count('a_cancelled (task') == 1 and 'submitting it again' in output, output
    assert 'a_cancelled: not graded - could not grade: Slurm said: CANCELLED' in output, output


def test_progress_shows_the_arrays_state(graded):
    _, _, output = graded
    states = [l for l in output.splitlines() if l.startswith('slurm job ')]
    assert any(' pending, ' in l for l in states) and any(' 1 running' in l or ' 2 running' in l for l in states)
    assert states[-1].endswith('3 done of 3 (1 not graded)'), states


def test_slurm_stops_and_leaves_nothing_running(slurm, graded):
    _, state = slurm
    code, output = _slurm_local('stop', state)
    assert code == 0, output
    assert _left_running(state) == []
