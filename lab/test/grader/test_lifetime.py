"""Every process a grading starts ends when grade.py ends, however it ends (harness.supervisor's
"Lifetime"): the good student graded alone by grade.py (and by ``make grade``), stopped once its main
run flies (the judge's master, rosout and probe up as the slot's judge uid, the student's roslaunch
in its box as the box's uid), by SIGKILL, SIGTERM, SIGINT or SIGHUP (a closed terminal) to grade.py
alone, or Ctrl-C to the process group of ``make grade``; a class; a reference capture. Then none of
the grading's processes may be left, within a generous deadline (the watch's rounds, the sessions'
grace periods on a shared machine): none carrying grade.py's mark, none carrying a Supervisor's mark
of a folder of the grading's (its work folders lie in a temp folder of the test's own: TMPDIR), none
of its boxes (a bubblewrap that binds one of those folders, and what runs in its PID namespace). And
the grading went no further once grade.py was gone: no session wrote its record, no capture its
reference (left alone, they would go to their end, then stop their processes themselves, within the
deadline: the processes' end alone does not tell a grader that ends them from one that does not).
"""
import glob
import os
import shutil
import signal
import subprocess
import sys
import tempfile

import pytest

from exam_lab.harness.supervisor import MARKER, OWNER, cmdline, descendants, marked, owner_mark
from exam_lab.harness.wait import wait_until

HERE = os.path.dirname(os.path.realpath(__file__))
REPO = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
GRADE = os.path.join(REPO, 'lab', 'scripts', 'grade.py')
GOOD = os.path.join(HERE, 'submissions', 'good_student')
#: Seconds until the main run flies (staging, inspection, roslaunch's check, the build, the master),
#: and until what was left of a stopped grading is gone.
FLYING_S = 400.0
GONE_S = 90.0
#: As a terminal starts it: Ctrl-C and SIGHUP not ignored, whatever this test process ignores
#: (``make test`` runs the grader's tests as a background job).
AS_FROM_A_TERMINAL = ['env', '--default-signal=INT,HUP']

pytestmark = pytest.mark.skipif(os.geteuid() != 0, reason='the judge\'s and the boxes\' uids are root\'s to see '
                                '(docs/grading.md, "Isolation")')


def flying(temp):
    """Whether the grading whose folders lie in ``temp`` flies its main run: its probe runs (after its
    master and the student's launch)."""
    return any('exam_lab.grader.judge.probe' in cmdline(pid) for pid in run_marked(temp))


def _status(pid, field):
    """The first value of ``field`` in the status of process ``pid``, or None."""
    try:
        with open('/proc/%d/status' % pid) as f:
            return next(line for line in f if line.startswith(field + ':')).split()[1]
    except (OSError, StopIteration, IndexError):
        return None


@pytest.fixture
def temp():
    """The grading's TMPDIR: a folder of /tmp the boxes' uids may traverse (as the system's, 0711)."""
    folder = tempfile.mkdtemp(prefix='exam-lifetime-')
    os.chmod(folder, 0o711)
    yield folder
    with open('/proc/self/mounts') as f:  # a killed grading leaves its box's tmpfs mounted: not a process
        mounts = [line.split()[1] for line in f if line.split()[1].startswith(folder + '/')]
    for mount in reversed(mounts):
        subprocess.run(['umount', '-l', mount], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=30)
    shutil.rmtree(folder, ignore_errors=True)


def run_marked(temp):
    """Pids of the processes a Supervisor started for a run whose folder lies in ``temp``."""
    prefix = ('\0%s=%s/' % (MARKER, temp)).encode()
    found = []
    for entry in os.listdir('/proc'):
        try:
            with open('/proc/%s/environ' % entry, 'rb') as f:
                if entry.isdigit() and prefix in b'\0' + f.read():
                    found.append(int(entry))
        except OSError:
            pass
    return found


def left(mark, temp):
    """What is left of the grading: the processes of its marks (its owner's, its Supervisors'), and
    its boxes (a bubblewrap that binds a folder of ``temp``) with every process in them."""
    found = set(marked(mark, OWNER) + run_marked(temp))
    for entry in os.listdir('/proc'):
        if entry.isdigit() and cmdline(int(entry)).startswith('bwrap ') and temp + '/' in cmdline(int(entry)):
            found.update([int(entry)] + descendants(int(entry)))
    return sorted(found)


def grading_of(argv, tmp_path, temp, find_grade, ready=flying):
    """Start ``argv`` (a session of its own, its TMPDIR ``temp``), wait until its grading's main run flies
    (``ready(temp)``); ``(process, log, mark)``. ``find_grade``: grade.py's pid from the process started."""
    log = open(str(tmp_path / 'grade.log'), 'w+')
    proc = subprocess.Popen(argv, cwd=REPO, stdout=log, stderr=subprocess.STDOUT, start_new_session=True,
                            env=dict(os.environ, TMPDIR=temp))
    grade = wait_until(lambda: find_grade(proc), 60.0, period=0.1)
    assert grade, 'grade.py did not start'
    mark = owner_mark(grade)
    if not wait_until(lambda: ready(temp) or proc.poll() is not None, FLYING_S, period=0.2) or not ready(temp):
        os.killpg(proc.pid, signal.SIGKILL)
        log.seek(0)
        pytest.fail('the main run did not fly (exit %s):\n%s' % (proc.poll(), log.read()[-3000:]))
    return proc, log, mark


def assert_nothing_left(proc, log, mark, temp, why):
    try:
        status = proc.wait(GONE_S)
    except subprocess.TimeoutExpired:
        status = None
    gone = wait_until(lambda: not left(mark, temp), GONE_S, period=0.2)
    remaining = ['%d (parent %s, uid %s) %s' % (pid, _status(pid, 'PPid'), _status(pid, 'Uid'), cmdline(pid)[:150])
                 for pid in left(mark, temp)]
    for pid in left(mark, temp):  # a failure leaves nothing behind either
        try:
            os.kill(pid, signal.SIGKILL)
        except OSError:
            pass
    log.seek(0)
    output = log.read()
    assert gone, 'left running %.0f s after %s:\n%s\n%s' % (GONE_S, why, '\n'.join(remaining), output[-2000:])
    records = glob.glob(os.path.join(temp, 'exam-grade-*', 'logs', 'session.json')) + \
        glob.glob(os.path.join(temp, 'exam-reference-*', 'reference.json'))
    assert not records, 'the grading went on after %s: %s' % (why, records)
    return status, output


@pytest.mark.parametrize('sig', [signal.SIGKILL, signal.SIGTERM, signal.SIGINT, signal.SIGHUP],
                         ids=lambda s: signal.Signals(s).name)
def test_a_grading_stopped_by_a_signal_leaves_no_process(tmp_path, temp, sig):
    argv = AS_FROM_A_TERMINAL + [sys.executable, GRADE, '--submission', GOOD, '--out', str(tmp_path / 'out')]
    proc, log, mark = grading_of(argv, tmp_path, temp, lambda proc: proc.pid)
    os.kill(proc.pid, sig)  # grade.py alone
    status, output = assert_nothing_left(proc, log, mark, temp, 'grade.py got %s' % signal.Signals(sig).name)
    if sig == signal.SIGKILL:
        assert status == -signal.SIGKILL
    else:
        assert status == 130 and 'grade: stopped' in output, output[-2000:]


def test_make_grade_stopped_by_ctrl_c_leaves_no_process(tmp_path, temp):
    """Ctrl-C in the terminal: SIGINT to make's whole process group (grade.py is make's child there)."""
    argv = AS_FROM_A_TERMINAL + ['make', '-s', 'grade', 'SUBMISSION=%s' % GOOD, 'OUT=%s' % (tmp_path / 'out')]

    def grade(proc):
        return next((pid for pid in descendants(proc.pid) if 'lab/scripts/grade.py' in cmdline(pid)), None)
    proc, log, mark = grading_of(argv, tmp_path, temp, grade)
    os.killpg(proc.pid, signal.SIGINT)
    status, output = assert_nothing_left(proc, log, mark, temp, 'Ctrl-C to make grade')
    assert status != 0 and 'grade: stopped' in output, output[-2000:]


def test_a_class_stopped_by_ctrl_c_leaves_no_process(tmp_path, temp):
    """Two students graded side by side (``--jobs 2``, each in a thread of grade.py's pool), Ctrl-C to
    grade.py once one flies: grade.py does not wait for the gradings going on, and they end with it."""
    klass = tmp_path / 'class'
    for name in ('Ann Lee_101_assignsubmission_file_', 'Bob Ray_102_assignsubmission_file_'):
        shutil.copytree(GOOD, str(klass / name))
    argv = AS_FROM_A_TERMINAL + [sys.executable, GRADE, '--class', str(klass), '--out', str(tmp_path / 'out'),
                                 '--jobs', '2', '--no-similarity']
    proc, log, mark = grading_of(argv, tmp_path, temp, lambda proc: proc.pid)
    os.kill(proc.pid, signal.SIGINT)
    status, output = assert_nothing_left(proc, log, mark, temp, 'Ctrl-C to grade.py --class')
    assert status == 130 and 'grade: stopped' in output, output[-2000:]


def capture_master(temp):
    """Whether the reference capture's master runs (its Supervisor's folder in ``temp``): rosmaster itself,
    not the shell that starts it (whose script names it)."""
    return any('rosmaster' in [os.path.basename(arg) for arg in cmdline(pid).split()[:2]] for pid in run_marked(temp))


#: An owner as grade.py is, capturing the reference outputs of the altitude sheet's drone (what
#: grade.py does after its gradings: host/reference.py), not kept beside the underlay.
CAPTURE = (
    'from exam_lab.harness import supervisor\n'
    'supervisor.own_processes()\n'
    'from exam_lab.grader.host import reference, underlay\n'
    'reference.captured("altitude", underlay.ensure_underlay(underlay.default_underlay()))\n')


def test_a_reference_capture_killed_leaves_no_process(tmp_path, temp):
    """The capture runs the real drone on a master of its own, in a process of its own: SIGKILL of its
    owner once that master is up ends them all, and the capture goes no further."""
    argv = AS_FROM_A_TERMINAL + [sys.executable, '-c', CAPTURE]
    proc, log, mark = grading_of(argv, tmp_path, temp, lambda proc: proc.pid, ready=capture_master)
    os.kill(proc.pid, signal.SIGKILL)
    status, _ = assert_nothing_left(proc, log, mark, temp, 'its owner got SIGKILL')
    assert status == -signal.SIGKILL
