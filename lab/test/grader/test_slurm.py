"""The Slurm engine on a two-node Slurm started on this machine by ``tools/slurm_local.sh start --nodes
2`` (issue 38), as a university runs it: a teacher who is not root grades a Moodle class zip with
``grade.py --class <zip> --engine slurm``.

- The cluster: one slurmctld and two slurmd, each slurmd in a network and UTS namespace of its own
  (exam-node1 at 10.213.78.2, exam-node2 at 10.213.78.3), the controller in a third (exam-ctl, the
  bridge), one munge key; the daemons in the foreground, stopped at the end, nothing left running.
- The teacher: an account this module makes (and removes), with its own copy of the repository and its
  own workspace, as on a cluster's shared file system; it submits from the controller's namespace (the
  login node). Every process of every task but Slurm's own slurmd and slurmstepd runs as the teacher,
  each student's code in the box without root.
- The class: seven students, copies of good_student and no_delay under different names. The same zip
  is graded first by root with the local engine: the six graded on Slurm get the same grades.csv rows,
  their grade.json names the node that graded them and the bounds that differ without root.
- A node lost mid-class: once exam-node1 has graded a student and is grading another, its slurmd and
  every process of its tasks are killed; the controller declares it DOWN (SlurmdTimeout, 20 s here),
  its tasks end NODE_FAIL and are graded again on exam-node2, each student once in grades.csv.
- The first student's task is cancelled with scancel while it runs, submitted once more, cancelled
  again, and is then "not graded" with what Slurm said.

About 6 to 10 minutes (377 and 603 s measured) on the shared two cores (the teacher's workspace
built, seven students graded locally, six and the lost ones on Slurm, as many at once as locally). Needs root (the daemons, the account, the
namespaces); installs Slurm when missing.
"""
import csv
import json
import os
import pwd
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import zipfile

import pytest

from exam_lab.grader import class_run
from exam_lab.grader.host import similarity_setup
from exam_lab.grader.host import uids
from exam_lab.harness.wait import wait_until
from test_grade import EXPECTED, FULL, STATUS
from test_nonroot import User, _chown_tree

HERE = os.path.dirname(os.path.realpath(__file__))
REPO = os.path.realpath(os.path.join(HERE, '..', '..', '..'))
SLURM_LOCAL = os.path.join(REPO, 'tools', 'slurm_local.sh')
GRADE = os.path.join(REPO, 'lab', 'scripts', 'grade.py')
SUBMISSIONS = os.path.join(HERE, 'submissions')
#: The class: (student, its package in submissions/). Sorted first, the cancelled one is task 0.
CLASS = (('a_cancelled', 'good_student'), ('b_good', 'good_student'), ('c_no_delay', 'no_delay'),
         ('d_good', 'good_student'), ('e_no_delay', 'no_delay'), ('f_good', 'good_student'),
         ('g_no_delay', 'no_delay'))
SOURCE = dict(CLASS)
NODES = ('exam-node1', 'exam-node2')
LOST = NODES[0]
#: Uids tried for the teacher's account (test_nonroot.py's uid without an account uses 65000-65099;
#: Slurm needs an account: slurmd looks the job's user up to start its task).
UIDS = range(65200, 65300)
ACCOUNT_PREFIX = 'exam-slurm-'
#: Each node's CPUs: the two run as many tasks at once (a task takes one) as the local run grades
#: students side by side (the default JOBS), within what each slurmd finds on this machine.
NODE_CPUS = max(1, min(os.cpu_count() or 1, class_run.default_jobs() // len(NODES)))
#: Generous: the machine is shared; the class takes about 6 minutes on Slurm, 4 locally.
WAIT_S = 1800.0


def _slurm_local(args, state):
    done = subprocess.run([SLURM_LOCAL] + list(args), env=dict(os.environ, EXAM_SLURM_DIR=state),
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=600)
    return done.returncode, done.stdout.decode('utf-8', 'replace')


def _proc(pid, name):
    with open('/proc/%s/%s' % (pid, name), 'rb') as f:
        return f.read().decode('utf-8', 'replace')


def _left_running(state):
    """Processes of our Slurm still alive: its daemons (named by the state folder) and any job step."""
    left = []
    for pid in filter(str.isdigit, os.listdir('/proc')):
        try:
            cmdline = _proc(pid, 'cmdline').replace('\0', ' ')
            comm = _proc(pid, 'comm').strip()
        except OSError:
            continue  # gone meanwhile
        if state in cmdline or comm == 'slurmstepd':
            left.append('%s %s' % (pid, cmdline))
    return left


def _processes():
    """``{pid: (ppid, comm, net namespace, [real, effective, saved, fs uid])}`` of every living process."""
    found = {}
    for pid in filter(str.isdigit, os.listdir('/proc')):
        try:
            status = dict(line.split(':', 1) for line in _proc(pid, 'status').splitlines() if ':' in line)
            net = os.readlink('/proc/%s/ns/net' % pid)
        except (OSError, ValueError):
            continue
        if status.get('State', '').strip().startswith('Z'):
            continue
        found[int(pid)] = (int(status['PPid']), status['Name'].strip(), net,
                           [int(u) for u in status['Uid'].split()])
    return found


def _node_processes(netns):
    """The processes of the nodes whose network namespaces are named: those in them (slurmd, slurmstepd,
    the tasks) and all their descendants (the boxes, in namespaces of their own)."""
    inodes = set('net:[%d]' % os.stat('/run/netns/%s' % ns).st_ino for ns in netns)
    procs = _processes()
    mine = set(pid for pid, (_, _, net, _) in procs.items() if net in inodes)
    grew = True
    while grew:
        grew = False
        for pid, (ppid, _, _, _) in procs.items():
            if ppid in mine and pid not in mine:
                mine.add(pid)
                grew = True
    return dict((pid, procs[pid]) for pid in mine)


def _signal_node(netns, sig):
    for _ in range(3):  # what forked meanwhile
        for pid in _node_processes([netns]):
            try:
                os.kill(pid, sig)
            except OSError:
                pass


def _class_zip(path):
    """The class as Moodle's "Download all submissions" gives it: a folder per student
    (``<full name>_<participant>_assignsubmission_file_``) holding what the student uploaded."""
    with zipfile.ZipFile(path, 'w', zipfile.ZIP_DEFLATED) as zf:
        for number, (name, source) in enumerate(CLASS):
            package = os.path.join(SUBMISSIONS, source, 'exam')
            for dirpath, dirnames, filenames in os.walk(package):
                dirnames[:] = [d for d in dirnames if d != '__pycache__' and not d.startswith('.grader-')]
                for filename in filenames:
                    full = os.path.join(dirpath, filename)
                    info = zipfile.ZipInfo('%s_%d_assignsubmission_file_/exam/%s' % (
                        name, 1000 + number, os.path.relpath(full, package)), (2026, 6, 12, 14, 0, 0))
                    info.external_attr = (os.stat(full).st_mode & 0o777) << 16
                    with open(full, 'rb') as f:
                        zf.writestr(info, f.read())


def _remove_orphan_accounts():
    """Accounts a killed run of this module left (their pid is gone)."""
    for entry in pwd.getpwall():
        suffix = entry.pw_name[len(ACCOUNT_PREFIX):]
        if entry.pw_name.startswith(ACCOUNT_PREFIX) and suffix.isdigit() and not os.path.exists('/proc/' + suffix):
            subprocess.run(['userdel', entry.pw_name], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


@pytest.fixture(scope='module')
def teacher():
    """An ordinary user with an account, its folder (0700), its copy of the repository and its built
    workspace (test_nonroot.py's User); the account is removed at the end."""
    if os.geteuid() != 0:
        pytest.skip('a local Slurm cluster needs root (its daemons, the teacher\'s account, the namespaces)')
    for command in ('useradd', 'userdel', 'ip', 'nsenter', 'unshare', 'setpriv'):
        if shutil.which(command) is None:
            pytest.skip('%s is not installed' % command)
    _remove_orphan_accounts()
    uid = next((u for u in UIDS if not uids.pids_of_uid(u) and not _has_account(u)), None)
    if uid is None:
        pytest.skip('no unused uid in %d-%d' % (UIDS[0], UIDS[-1]))
    root = tempfile.mkdtemp(prefix='exam-slurm-teacher-')
    user = User(uid, root)
    name = '%s%d' % (ACCOUNT_PREFIX, os.getpid())
    made = subprocess.run(['useradd', '--uid', str(uid), '--user-group', '--no-create-home', '--home-dir', user.home,
                           '--shell', '/bin/bash', name], stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    assert made.returncode == 0, made.stdout
    try:
        os.makedirs(user.home)
        os.makedirs(os.path.join(root, 'tmp'))
        shutil.copytree(REPO, user.repo, symlinks=True,
                        ignore=shutil.ignore_patterns('.ws', '.git', '__pycache__', '.pytest_cache', '.hypothesis'))
        _chown_tree(root, uid)
        os.chmod(root, 0o711)  # the tasks' slurmstepd (root) and the nodes reach it; nobody lists it
        user.env['TMPDIR'] = os.path.join(root, 'tmp')  # the boxes' work folders, removed with the rest
        status, output = user.run(['bwrap', '--unshare-user', '--ro-bind', '/', '/', 'true'], 30)
        if status != 0:
            pytest.skip('this kernel does not let an ordinary user make a user namespace: %s' % output.strip())
        status, output = user.run(['tools/build_ws.sh'], 900)
        assert status == 0, output[-3000:]
        yield user
    finally:
        for pid in uids.pids_of_uid(uid):
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
        subprocess.run(['userdel', name], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        shutil.rmtree(root, ignore_errors=True)


def _has_account(uid):
    try:
        pwd.getpwuid(uid)
        return True
    except KeyError:
        return False


@pytest.fixture(scope='module')
def klass(teacher):
    path = os.path.join(teacher.root, 'ros-exam-all-submissions.zip')
    _class_zip(path)
    os.chown(path, teacher.uid, teacher.uid)
    return path


@pytest.fixture(scope='module')
def local(klass, tmp_path_factory):
    """The zip graded by root with the local engine (the default JOBS): ``(OUT, rows of grades.csv)``.
    It also makes root's similarity venv, which the teacher's copy of the workspace is given."""
    out = str(tmp_path_factory.mktemp('slurm-local') / 'out')
    done = subprocess.run([sys.executable, GRADE, '--class', klass, '--out', out], stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, timeout=WAIT_S)
    assert done.returncode == 0, done.stdout.decode('utf-8', 'replace')[-3000:]
    with open(os.path.join(out, 'grades.csv')) as f:
        return out, dict((r['student'], r) for r in csv.DictReader(f))


@pytest.fixture(scope='module')
def cluster():
    """The two-node Slurm: ``(its state folder, SLURM_CONF, the controller's namespace, the nodes'
    namespaces)``; stopped at the end (the test below checks that nothing is left)."""
    state = tempfile.mkdtemp(prefix='exam-slurm-')  # not in pytest's folder: the teacher reads slurm.conf
    started = time.monotonic()
    code, output = _slurm_local(['start', '--nodes', '2', '--cpus', str(NODE_CPUS)], state)
    try:
        assert code == 0, output
        conf = [l.split('=', 1)[1] for l in output.splitlines() if l.startswith('export SLURM_CONF=')]
        ctl = [l.split(None, 1)[1] for l in output.splitlines() if l.startswith('netns ')]
        assert conf and ctl, output
        nodes = [ctl[0][:-len('_ctl')] + '_n%d' % i for i in (1, 2)]
        print('two-node Slurm started in %.1f s' % (time.monotonic() - started))
        yield state, conf[0], ctl[0], nodes
    finally:
        _slurm_local(['stop'], state)
        shutil.rmtree(state, ignore_errors=True)


class _Watch(object):
    """What the test does while the class runs, one look every half second: cancel task 0 twice, lose
    exam-node1 once it has graded a student and grades another, and note any process of a task that
    runs as root."""

    def __init__(self, cluster, out, grading, log):
        self.state, self.conf, self.ctl, self.nodes = cluster
        self.out, self.grading, self.log = out, grading, log
        self.cancelled = []  # the jobs whose task 0 was cancelled
        self.lost = None  # {(job, index)} running on the lost node when it was lost
        self.lost_at = None
        self.as_root = {}

    def slurm(self, *argv):
        return subprocess.run(['nsenter', '--net=/run/netns/%s' % self.ctl, '--'] + list(argv),
                              env=dict(os.environ, SLURM_CONF=self.conf), stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, timeout=60).stdout.decode('utf-8', 'replace')

    def queue(self):
        """``[(job, index, state, node)]`` of the class's tasks."""
        out = self.slurm('squeue', '-h', '-r', '--name', 'exam-grade-out', '-o', '%F %K %T %N')
        return [tuple(l.split()) + ('',) * (4 - len(l.split())) for l in out.splitlines() if len(l.split()) >= 3]

    def results(self):
        """``{task index: the node that graded it}`` of the records written so far."""
        results, found = os.path.join(self.out, '.slurm', 'results'), {}
        for name in os.listdir(results) if os.path.isdir(results) else ():
            try:
                if name.endswith('.json'):
                    with open(os.path.join(results, name)) as f:  # written whole, then renamed
                        found[name[:-len('.json')]] = json.load(f).get('graded_on')
            except OSError:
                pass  # the class is over: OUT/.slurm removed
        return found

    def check_uids(self):
        for pid, (_, comm, _, owners) in _node_processes(self.nodes).items():
            if 0 in owners and comm not in ('slurmd', 'slurmstepd'):
                self.as_root[pid] = (comm, owners)

    def look(self):
        tasks = self.queue()
        running = [(job, index, node) for job, index, state, node in tasks if state == 'RUNNING']
        for job, index, _ in running:
            if index == '0' and job not in self.cancelled and len(self.cancelled) < 2:
                self.slurm('scancel', '%s_0' % job)
                self.cancelled.append(job)
        on_lost = set((job, index) for job, index, node in running if node == LOST)
        # Task 0 is cancelled twice: a node lost under it would end it otherwise.
        if self.lost is None and on_lost and '0' not in [i for _, i in on_lost] and \
                LOST in self.results().values():
            self.lose()
        self.check_uids()

    def lose(self):
        """exam-node1 as if its machine died: every process of it stopped, then killed. Its tasks that
        were running and had written no record once stopped (none can write one then) are lost."""
        _signal_node(self.nodes[0], signal.SIGSTOP)
        done = self.results()
        lost = set((job, index) for job, index, state, node in self.queue()
                   if state == 'RUNNING' and node == LOST and index not in done)
        if not lost or '0' in [i for _, i in lost]:  # a record just written, task 0 just started: later
            _signal_node(self.nodes[0], signal.SIGCONT)
            return
        self.lost, self.lost_at = lost, time.monotonic()
        _signal_node(self.nodes[0], signal.SIGKILL)
        assert wait_until(lambda: not _node_processes(self.nodes[:1]), 30.0, period=0.2), \
            _node_processes(self.nodes[:1])

    def follow(self, deadline):
        while self.grading.poll() is None:
            if time.monotonic() > deadline:
                pytest.fail('the class was not graded within %.0f s' % WAIT_S)
            self.look()
            time.sleep(0.5)


@pytest.fixture(scope='module')
def graded(teacher, klass, local, cluster):
    """The class graded on the cluster by the teacher: ``(OUT, exit code, terminal output, the watch)``."""
    state, conf, ctl, _ = cluster
    # The similarity check runs on the login node, which has no network to install its venv: the
    # teacher's copy of root's (made by the local run; its python a link to the system's).
    venv, copy = similarity_setup.venv_dir(), os.path.join(teacher.ws, os.path.basename(similarity_setup.venv_dir()))
    if os.path.isdir(venv) and not os.path.isdir(copy):
        shutil.copytree(venv, copy, symlinks=True)
        _chown_tree(copy, teacher.uid)
    out = os.path.join(teacher.root, 'out')
    log = os.path.join(teacher.root, 'grade.log')
    argv = ['nsenter', '--net=/run/netns/%s' % ctl, '--', 'setpriv', '--reuid=%d' % teacher.uid,
            '--regid=%d' % teacher.uid, '--clear-groups', '--', 'bash', '-c', 'source tools/env.sh && exec "$@"',
            'bash', 'python3', 'lab/scripts/grade.py', '--class', klass, '--out', out, '--engine', 'slurm']
    started = time.monotonic()
    with open(log, 'w') as f:
        grading = subprocess.Popen(argv, cwd=teacher.repo, env=dict(teacher.env, SLURM_CONF=conf), stdout=f,
                                   stderr=subprocess.STDOUT)
    watch = _Watch(cluster, out, grading, log)
    try:
        watch.follow(started + WAIT_S)
    finally:
        if grading.poll() is None:  # Ctrl-C: grade.py cancels its jobs
            grading.send_signal(signal.SIGINT)
            grading.wait(timeout=120)
    took = time.monotonic() - started
    with open(log) as f:
        output = f.read()
    print('graded on two nodes as uid %d in %.0f s; exam-node1 lost %.0f s in, running %s'
          % (teacher.uid, took, (watch.lost_at or started) - started, sorted(watch.lost or ())))
    return out, grading.returncode, output, watch


def _rows(out):
    with open(os.path.join(out, 'grades.csv')) as f:
        return list(csv.DictReader(f))


def _record(out, name):
    with open(os.path.join(out, name, 'grade.json')) as f:
        return json.load(f)


def test_each_student_gets_the_points_of_a_local_run(graded, local):
    out, code, output, _ = graded
    assert code == 0, output
    rows = _rows(out)
    assert sorted(r['student'] for r in rows) == sorted(name for name, _ in CLASS), 'each student once: %s' % rows
    rows = dict((r['student'], r) for r in rows)
    _, local_rows = local
    for name, source in CLASS[1:]:
        record = _record(out, name)
        assert dict((i['id'], i['points']) for i in record['items']) == dict(FULL, **EXPECTED[source]), output
        assert record['status'] == STATUS.get(source, 'graded') == rows[name]['status'], (name, record['status_reason'])
        assert float(rows[name]['total']) == record['total']
        assert rows[name] == local_rows[name], 'the same row in grades.csv as the local run\'s'
        for made in ('grade.md', 'results.json', 'flight.png', os.path.join('logs', 'build.log')):
            assert os.path.isfile(os.path.join(out, name, made)), made
    assert os.path.isfile(os.path.join(out, 'index.html'))
    assert 'similarity: ' in output and 'similarity: not run' not in output, output


def test_the_class_is_spread_over_both_nodes_each_grade_names_its_node(graded):
    out, _, output, _ = graded
    nodes = dict((name, _record(out, name).get('graded_on')) for name, _ in CLASS[1:])
    assert set(nodes.values()) == set(NODES), nodes


def test_graded_as_the_teacher_in_the_box_without_root(graded, teacher, local):
    out, _, output, watch = graded
    assert watch.as_root == {}, 'processes of the tasks ran as root: %s' % watch.as_root
    local_out, _ = local
    for name, _ in CLASS[1:]:
        hints = _record(out, name)['for_the_teacher']
        ran = [h for h in hints if h.startswith('ran in a bubblewrap sandbox')]
        assert len(ran) == 1 and ran[0].startswith('ran in a bubblewrap sandbox WITHOUT ROOT, as the grading '
                                                   'user (uid %d)' % teacher.uid), hints
        for differs in ('no uid of its own', 'no memory or process cgroup', 'no size limit on its work folder'):
            assert differs in ran[0], ran[0]
        assert os.stat(os.path.join(out, name, 'grade.json')).st_uid == teacher.uid
        local_hints = _record(local_out, name)['for_the_teacher']
        assert [h for h in local_hints if h.startswith('ran in a bubblewrap sandbox')] and \
            not [h for h in local_hints if 'WITHOUT ROOT' in h], local_hints


def test_a_lost_node_s_students_are_graded_again_on_the_other(graded):
    out, _, output, watch = graded
    assert watch.lost, 'exam-node1 was never lost while grading a student'
    students = [name for name, _ in CLASS]
    for job, index in sorted(watch.lost):
        name = students[int(index)]
        assert _record(out, name).get('graded_on') == NODES[1], name
        assert '%s (task %s_%s) ended without a grade: NODE_FAIL on node %s' % (name, job, index, LOST) in output, output
    assert output.count('ended without a grade: NODE_FAIL') == len(watch.lost), output
    states = [l for l in output.splitlines() if l.startswith('slurm job ')]
    assert any('(%d tasks submitted again)' % (len(watch.lost) + 1) in l for l in states), states


def test_a_cancelled_task_is_retried_once_then_not_graded_with_slurms_reason(graded):
    out, _, output, watch = graded
    assert len(watch.cancelled) == 2, watch.cancelled
    record = _record(out, 'a_cancelled')
    assert record['status'] == 'not graded'
    assert record['status_reason'].startswith('could not grade: Slurm said: CANCELLED'), record['status_reason']
    assert output.count('a_cancelled (task') == 1 and 'submitting it again' in output, output
    assert 'a_cancelled: not graded - could not grade: Slurm said: CANCELLED' in output, output


def test_progress_shows_the_arrays_state(graded):
    _, _, output, _ = graded
    states = [l for l in output.splitlines() if l.startswith('slurm job ')]
    assert any(' pending, ' in l for l in states) and any(' 1 running' in l or ' 2 running' in l for l in states)
    assert states[-1].endswith('7 done of 7 (1 not graded)'), states


def test_slurm_stops_and_leaves_nothing_running(cluster, graded, teacher):
    state = cluster[0]
    code, output = _slurm_local(['stop'], state)
    assert code == 0, output
    assert _left_running(state) == []
    assert wait_until(lambda: not uids.pids_of_uid(teacher.uid), 30.0, period=0.2), \
        uids.pids_of_uid(teacher.uid)
    namespaces = subprocess.run(['ip', 'netns', 'list'], stdout=subprocess.PIPE).stdout.decode()
    assert cluster[2][:-len('_ctl')] not in namespaces, namespaces
