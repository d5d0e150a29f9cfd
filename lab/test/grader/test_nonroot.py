"""Grading without root (issue 30 point 2) and a student's own check (issue 29 point 3), as an
unprivileged user: CI runs as root, so the module drops to a fresh uid (no account, no process) with
setpriv; run as another user, it is that user.

The user gets a folder of its own (0700): a HOME holding a secret file (0600), the build workspace
(``EXAM_WS``, shared by every test here: the workspace and the simulators are built once) and a copy of
the repository (a checkout may be private to root, and the check's setting is changed in the copy).
Then, as that user:

- the teacher's command grades a class of two side by side (``JOBS=2``) in boxes without root: the
  saboteur of test_sandbox.py, whose boxes now share the teacher's uid with its classmate's, cannot
  kill, read or write its classmate (PID namespaces and mounts alone keep them apart); the classmate,
  the good student, gets 17/17, and its grade says each bound that differs from root's box;
- ``make check`` prints the items and points, with the evidence when the setting says so, never the
  threshold run's hidden value nor its words; without the evidence when the setting says points;
- inside a box without root, the teacher's HOME, processes, variables and network are out of reach.

About 2.5 minutes on two cores (151 s measured: a class of two side by side, one more graded run, a
build that fails at once, the workspace and the simulators built).
"""
import json
import os
import pwd
import secrets
import shutil
import signal
import subprocess
import tempfile

import pytest

from exam_lab.grader.host import sandbox, uids
from exam_lab.grader.publish import student_view
from exam_lab.grader.score.sheets import ITEMS
from exam_lab.harness.wait import wait_until
from test_sandbox import files_under  # this folder's: the files of a student's results, as text

HERE = os.path.dirname(os.path.realpath(__file__))  # the repository's, not the workspace's src/ link
REPO = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
GOOD = os.path.join('lab', 'test', 'grader', 'submissions', 'good_student', 'exam')
SABOTEUR = os.path.join('lab', 'test', 'grader', 'hostile', 'saboteur', 'exam')
FULL = {item: points for item, (points, _) in ITEMS.items()}
#: Uids tried for the user, first unused one taken (the boxes of root's grader use 61000-61063).
UIDS = range(65000, 65100)


def unused_uid():
    for uid in UIDS:
        try:
            pwd.getpwuid(uid)
        except KeyError:
            if not uids.pids_of_uid(uid):
                return uid
    pytest.skip('no unused uid in %d-%d' % (UIDS[0], UIDS[-1]))


class User(object):
    """An unprivileged user with a folder of its own; runs commands as itself, in a clean environment."""

    def __init__(self, uid, root):
        self.uid, self.root = uid, root
        self.home, self.ws, self.repo = (os.path.join(root, name) for name in ('home', 'ws', 'repo'))
        self.secret = 'teacher-secret-%s' % secrets.token_hex(8)
        self.secret_file = os.path.join(self.home, 'secret.txt')
        # EXAM_HOSTILE_CLASS marks the grader's processes for the saboteur, as in test_sandbox.py.
        self.env = {'PATH': '/usr/local/bin:/usr/bin:/bin', 'HOME': self.home, 'LANG': 'C.UTF-8',
                    'EXAM_WS': self.ws, 'TEACHER_SECRET': self.secret, 'EXAM_HOSTILE_CLASS': '1'}

    def run(self, argv, timeout, cwd=None):
        """``argv`` as the user (in the copy of the repository); ``(exit code, output)``. Nothing of the
        user may be left running after it."""
        drop = ['setpriv', '--reuid=%d' % self.uid, '--regid=%d' % self.uid, '--clear-groups', '--'] \
            if os.geteuid() == 0 else []
        done = subprocess.run(drop + list(argv), cwd=cwd or self.repo, env=self.env, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, timeout=timeout)
        if os.geteuid() == 0:
            assert wait_until(lambda: not uids.pids_of_uid(self.uid), 30.0, period=0.2), \
                'processes of uid %d left: %s' % (self.uid, uids.pids_of_uid(self.uid))
        return done.returncode, done.stdout.decode('utf-8', 'replace')

    def sourced(self, command, timeout):
        """A command run with the user's workspace sourced, as the Makefile's recipes run theirs."""
        return self.run(['bash', '-c', 'source tools/env.sh && exec "$@"', 'bash'] + list(command), timeout)

    def set_show(self, show):
        with open(os.path.join(self.repo, 'lab', 'check_visibility.ini'), 'w') as f:
            f.write('[check]\nshow = %s\n' % show)


def _chown_tree(folder, uid):
    for dirpath, dirnames, filenames in os.walk(folder):
        for name in [dirpath] + [os.path.join(dirpath, n) for n in dirnames + filenames]:
            os.lchown(name, uid, uid)


@pytest.fixture(scope='module')
def user():
    """The user, its folder and the workspace built by it (tools/build_ws.sh, as ``make check`` does)."""
    uid = unused_uid() if os.geteuid() == 0 else os.geteuid()
    root = tempfile.mkdtemp(prefix='exam-nonroot-')
    someone = User(uid, root)
    try:
        os.makedirs(someone.home)
        shutil.copytree(REPO, someone.repo, symlinks=True,
                        ignore=shutil.ignore_patterns('.ws', '.git', '__pycache__', '.pytest_cache', '.hypothesis'))
        with open(os.open(someone.secret_file, os.O_WRONLY | os.O_CREAT, 0o600), 'w') as f:
            f.write(someone.secret)
        if os.geteuid() == 0:
            _chown_tree(root, uid)
        os.chmod(root, 0o700)
        status, output = someone.run(['bwrap', '--unshare-user', '--ro-bind', '/', '/', 'true'], 30)
        if status != 0:
            pytest.skip('this kernel does not let an ordinary user make a user namespace: %s' % output.strip())
        status, output = someone.run(['tools/build_ws.sh'], 900)
        assert status == 0, output[-3000:]
        yield someone
    finally:
        if os.geteuid() == 0:
            for pid in uids.pids_of_uid(uid):
                try:
                    os.kill(pid, signal.SIGKILL)
                except OSError:
                    pass
        shutil.rmtree(root, ignore_errors=True)


@pytest.fixture(scope='module')
def graded(user):
    """The teacher's command, as the user: a class of the saboteur and the good student with JOBS=2;
    each one's folder of results, the good student's record and its threshold run's plan."""
    klass, out = os.path.join(user.root, 'class'), os.path.join(user.root, 'out')
    for name, package in (('a_saboteur', SABOTEUR), ('b_victim', GOOD)):
        shutil.copytree(os.path.join(user.repo, package), os.path.join(klass, name, 'exam'))
    if os.geteuid() == 0:
        _chown_tree(klass, user.uid)
    status, output = user.sourced(['python3', 'lab/scripts/grade.py', '--class', klass, '--out', out, '--jobs', '2',
                                   '--no-similarity'], 900)
    assert status == 0, output[-3000:]
    with open(os.path.join(out, 'b_victim', 'grade.json')) as f:
        record = json.load(f)
    with open(os.path.join(out, 'b_victim', 'logs', 'plan-threshold.json')) as f:
        plan = json.load(f)
    return {'record': record, 'hidden': '%g' % plan['threshold'], 'output': output,
            'victim': os.path.join(out, 'b_victim'), 'saboteur': os.path.join(out, 'a_saboteur')}


def test_graded_without_root_full_points_and_the_bounds_that_differ(graded, user):
    record = graded['record']
    got = {i['id']: i['points'] for i in record['items']}
    assert got == FULL, '\n'.join('%s: %s' % (i['id'], i['evidence']) for i in record['items'])
    hints = record['for_the_teacher']
    ran = [h for h in hints if h.startswith('ran in a bubblewrap sandbox')]
    assert len(ran) == 1 and ran[0].startswith('ran in a bubblewrap sandbox WITHOUT ROOT, as the grading user '
                                               '(uid %d)' % user.uid), hints
    for differs in ('no uid of its own', 'no memory or process cgroup', 'no size limit on its work folder'):
        assert differs in ran[0], ran[0]
    assert 'ran in a network namespace with only loopback' in hints
    assert [h for h in hints if h.startswith('without root, no cgroup')], hints
    assert user.secret not in json.dumps(record)


def test_boxes_without_root_keep_classmates_apart(graded, user):
    """Both boxes run as the teacher's uid: only their PID namespaces and mounts keep the saboteur
    from killing its classmate's processes, reading its code and writing into its logs."""
    with open(os.path.join(user.repo, GOOD, 'scripts', 'exam_node.py')) as f:
        victim_line = f.read().splitlines()[2]
    with open(os.path.join(graded['saboteur'], 'grade.json')) as f:
        assert json.load(f)['items'][0]['points'] == 2.0, 'the saboteur built and its node ran: its payload too'
    saboteur = dict(files_under(graded['saboteur']))
    assert not [p for p, text in saboteur.items() if victim_line in text or 'KILLED' in text]
    assert not [p for p, text in files_under(graded['victim']) if 'HACKED' in text]


def test_make_check_shows_the_evidence_never_the_threshold_run(graded, user):
    user.set_show('evidence')
    status, output = user.run(['make', 'check', 'PACKAGE=%s' % GOOD], 900)
    assert status == 0, output[-3000:]
    lines = output.splitlines()
    assert "check: your package runs in the grader's sandbox (bubblewrap), as on the teacher's machine." in lines
    table = {line.split()[0]: line for line in lines if line.split() and line.split()[0] in list(ITEMS) + ['total']}
    assert sorted(table) == sorted(list(ITEMS) + ['total']), output
    assert table['total'].split()[1:4] == ['17', '/', '17'], output
    assert 'subscribes to /pressure (std_msgs/Float32), /temperature' in table['Q10'], 'the evidence is shown'
    assert table['Q14a'].endswith(student_view.Q14A_WORDS[0]), table['Q14a']
    # The value is drawn for each grading (this one is the class run's): no line has it, not even Q11's.
    assert [line for line in lines if graded['hidden'] in line] == [], output
    assert 'threshold run' not in output and 'set to' not in output
    assert 'For the teacher' not in output and 'comments (not scored)' not in output and 'WITHOUT ROOT' not in output
    assert 'status: graded' in lines


def test_make_check_shows_points_only_when_the_teacher_says_so(user):
    """A package that does not build (graded in seconds): the points, the status, and not one word of
    the evidence (catkin's failure) nor of the status's reason."""
    broken = os.path.join(user.root, 'broken', 'exam')
    shutil.copytree(os.path.join(user.repo, GOOD), broken)
    with open(os.path.join(broken, 'CMakeLists.txt'), 'a') as f:
        f.write('this_is_not_cmake(\n')
    if os.geteuid() == 0:
        _chown_tree(os.path.dirname(broken), user.uid)
    user.set_show('points')
    status, output = user.run(['make', 'check', 'PACKAGE=%s' % broken], 900)
    assert status == 0, output[-3000:]
    lines = output.splitlines()
    assert 'item   points' in lines and 'runs   0 / 2' in lines, output
    assert 'status: needs a hand grade' in lines, output
    assert 'catkin_make' not in output and 'does not build' not in output and 'evidence' not in output


#: Run inside a box by the user: what of the teacher it reaches (each line a finding; none expected).
PAYLOAD = r'''
[ "$(id -u)" = 0 ] && { echo "ROOT: the payload does nothing as root"; exit 99; }
echo "UID $(id -u)"
cat "$1" 2>/dev/null && echo READ_SECRET
test -e "$(dirname "$1")" && echo SAW_HOME
kill -0 "$2" 2>/dev/null && echo SIGNALLED_TEACHER
test -e "/proc/$2" && echo SAW_TEACHER_PROCESS
env | grep -q TEACHER_SECRET && echo ENV_LEAK
tail -n +3 /proc/net/dev | cut -d: -f1 | tr -d ' ' | sed 's/^/NET /'
touch /box/ws/devel/ok && echo WROTE_WORKSPACE
touch /usr/x 2>/dev/null && echo WROTE_USR
'''
#: The user's side: a process of the teacher outside, a box, the payload in it.
BOX_TEST = r'''
import os, shutil, subprocess, sys, tempfile
from exam_lab.grader.host import sandbox
why = sandbox.check()
if why is not None:
    sys.exit('no box: %s' % why)
work = tempfile.mkdtemp(prefix='exam-box-test-')
os.makedirs(os.path.join(work, 'ws', 'src'))
outside = subprocess.Popen(['sleep', '300'])
try:
    with sandbox.Box(work) as box:
        done = subprocess.run(box.argv(['sh', '-c', sys.argv[1], 'payload', sys.argv[2], str(outside.pid)],
                                       dict(os.environ)), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=60)
        sys.stdout.write(done.stdout.decode())
finally:
    outside.kill()
    outside.wait()
    shutil.rmtree(work, ignore_errors=True)
'''


def test_a_box_without_root_reaches_nothing_of_the_teacher(user):
    """The teacher's HOME (its secret file 0600), its processes, its variables and its network: none of
    them from inside a box made by the teacher's own uid."""
    status, output = user.sourced(['python3', '-c', BOX_TEST, PAYLOAD, user.secret_file], 120)
    assert status == 0, output
    lines = output.splitlines()
    assert 'UID %d' % user.uid in lines, output
    assert 'WROTE_WORKSPACE' in lines, output
    assert [line for line in lines if line.startswith('NET ')] == ['NET lo'], output
    for finding in ('READ_SECRET', 'SAW_HOME', 'SIGNALLED_TEACHER', 'SAW_TEACHER_PROCESS', 'ENV_LEAK', 'WROTE_USR',
                    'ROOT:'):
        assert finding not in output, output
    assert user.secret not in output


def test_unsandboxed_as_a_uid_without_an_account_says_so(monkeypatch):
    """The check runs a student's package unsandboxed where no box can be made; the grade's note names
    the user even when its uid has no account (a container's, this module's): it used to raise."""
    from exam_lab.grader.publish import teacher
    uid = UIDS[-1]
    monkeypatch.setattr(os, 'geteuid', lambda: uid)
    with pytest.raises(KeyError):
        pwd.getpwuid(uid)
    note = teacher.how_run(sandbox.Box('/nonexistent', bwrap=False))
    assert note.startswith('ran WITHOUT its sandbox') and 'uid %d' % uid in note
