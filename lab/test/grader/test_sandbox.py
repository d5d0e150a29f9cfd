"""The grader's sandbox against hostile students (issue 16): one class run with ``JOBS=2``.

The class: ``a_saboteur`` (kills, reads and writes its classmate graded beside it), ``b_victim`` (the
good student's package: it must keep its 17 points), ``c_forger`` (an idle node that writes a real
probe result where the grader used to read its own), ``d_escapee`` (prints its environment and a
root-only file, leaves links and a FIFO where the grader copies logs from, starts detached children at
build and run time). Their payloads live in lab/test/grader/hostile/ and do nothing as root. About 2
minutes on two cores; the copy and refusal checks need no ROS.
"""
import json
import os
import secrets
import shutil
import signal
import subprocess
import tempfile

import pytest

from exam_lab.grader import runner

from exam_lab.grader.host import sandbox
from exam_lab.grader.score.sheets import ITEMS
from exam_lab.harness.wait import wait_until

HERE = os.path.dirname(os.path.abspath(__file__))
HOSTILE = os.path.join(HERE, 'hostile')
VICTIM = os.path.join(HERE, 'submissions', 'good_student', 'exam')
FULL = {item: points for item, (points, _) in ITEMS.items()}
#: Where the escapee looks for the root-only file (its payload names it).
SECRET_DIR = '/tmp/exam-hostile-secret'
#: In the command line of the escapee's detached children.
DETACHED = 'exam-hostile-detached'
CLASS = [('a_saboteur', os.path.join(HOSTILE, 'saboteur', 'exam')), ('b_victim', VICTIM),
         ('c_forger', os.path.join(HOSTILE, 'forger', 'exam')), ('d_escapee', os.path.join(HOSTILE, 'escapee', 'exam'))]


def detached_children():
    found = []
    for entry in os.listdir('/proc'):
        try:
            with open('/proc/%s/cmdline' % entry, 'rb') as f:
                if DETACHED.encode() in f.read():
                    found.append(int(entry))
        except (OSError, ValueError):
            continue
    return [pid for pid in found if pid != os.getpid()]


def files_under(folder):
    for dirpath, _, filenames in os.walk(folder):
        for name in filenames:
            path = os.path.join(dirpath, name)
            if os.path.isfile(path) and not os.path.islink(path):
                with open(path, 'rb') as f:
                    yield path, f.read().decode('utf-8', 'replace')


@pytest.fixture(scope='module')
def hostile_class(tmp_path_factory):
    """Grade the class once, a secret file (root, mode 600) and a secret variable of the grader in
    place; note the escapee's detached children still alive right after; clean everything up."""
    if os.geteuid() != 0:
        pytest.skip('the sandbox is made by root (docs/grading.md, "Isolation")')
    root = tmp_path_factory.mktemp('hostile')
    klass = root / 'class'
    for name, package in CLASS:
        shutil.copytree(package, str(klass / name / 'exam'), ignore=shutil.ignore_patterns('__pycache__'))
    shutil.rmtree(SECRET_DIR, ignore_errors=True)
    os.makedirs(SECRET_DIR)
    os.chmod(SECRET_DIR, 0o755)
    secret_file = 'root-only-%s' % secrets.token_hex(8)
    path = os.path.join(SECRET_DIR, 'secret.txt')
    with open(os.open(path, os.O_WRONLY | os.O_CREAT, 0o600), 'w') as f:
        f.write(secret_file)
    secret_var = 'grader-env-%s' % secrets.token_hex(8)
    saved = {k: os.environ.get(k) for k in ('EXAM_HOSTILE_SECRET', 'EXAM_HOSTILE_CLASS')}
    os.environ.update(EXAM_HOSTILE_SECRET=secret_var, EXAM_HOSTILE_CLASS='1')
    out = root / 'out'
    try:
        try:
            records, error = {r['student']: r for r in runner.grade_class(str(klass), str(out), jobs=2)}, None
        except Exception as err:  # today's grader: one student's links stop the class
            records, error = {}, err
        survivors = detached_children()
        yield {'out': str(out), 'records': records, 'error': error, 'survivors': survivors,
               'secrets': (secret_file, secret_var)}
    finally:
        for pid in detached_children():
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
        shutil.rmtree(SECRET_DIR, ignore_errors=True)


def test_links_and_fifos_do_not_stop_the_class(hostile_class):
    assert hostile_class['error'] is None, repr(hostile_class['error'])
    with open(os.path.join(hostile_class['out'], 'grades.csv')) as f:
        rows = f.read().splitlines()[1:]
    assert sorted(row.split(',')[0] for row in rows) == [name for name, _ in CLASS]


def test_every_student_runs_in_a_box_of_its_own(hostile_class):
    boxes = []
    for name, record in sorted(hostile_class['records'].items()):
        ran = [hint for hint in record['for_the_teacher'] if hint.startswith('ran ') and ' as ' in hint]
        assert len(ran) == 1 and ran[0].startswith('ran in a bubblewrap sandbox as uid '), (name, ran)
        boxes.append(int(ran[0].split('as uid ')[1].split(':')[0]))
    assert boxes[0] != boxes[1], 'the saboteur and its classmate, graded side by side, share a uid'
    assert all(uid >= sandbox.BOX_UID_BASE for uid in boxes)


def test_the_classmate_of_a_saboteur_keeps_its_points(hostile_class):
    record = hostile_class['records']['b_victim']
    got = {i['id']: i['points'] for i in record['items']}
    assert got == FULL, '\n'.join('%s: %s' % (i['id'], i['evidence']) for i in record['items'])
    victim_files = dict(files_under(os.path.join(hostile_class['out'], 'b_victim')))
    assert not [p for p, text in victim_files.items() if 'HACKED' in text]
    with open(os.path.join(VICTIM, 'scripts', 'exam_node.py')) as f:
        victim_line = f.read().splitlines()[2]
    saboteur_files = dict(files_under(os.path.join(hostile_class['out'], 'a_saboteur')))
    assert not [p for p, text in saboteur_files.items() if victim_line in text]
    assert not [p for p, text in saboteur_files.items() if 'KILLED' in text]


def test_a_forged_probe_file_changes_nothing(hostile_class):
    record = hostile_class['records']['c_forger']
    got = {i['id']: i['points'] for i in record['items']}
    assert got['Q11'] == 0.0 and got['Q13'] == 0.0 and got['Q14b'] == 0.0, got
    assert record['total'] <= 3.0
    for path, text in files_under(hostile_class['out']):
        assert 'FORGER usercustomize ran' not in text, path


def test_no_detached_child_survives(hostile_class):
    assert hostile_class['survivors'] == []
    assert [uid for uid in range(sandbox.BOX_UID_BASE, sandbox.BOX_UID_BASE + sandbox.SLOTS)
            if sandbox.pids_of_uid(uid)] == []


def test_secrets_never_reach_the_results(hostile_class):
    escapee = hostile_class['records']['d_escapee']
    assert escapee['items'][0]['points'] >= 1.0, 'the escapee built: its payload ran'
    for path, text in files_under(hostile_class['out']):
        for secret in hostile_class['secrets']:
            assert secret not in text, path


def test_the_results_take_only_regular_files_capped(tmp_path):
    """What the session leaves is data: a link (even to a root-only file), a dangling link and a FIFO
    are skipped without blocking; a long log keeps its first and last part and says so."""
    source, target = tmp_path / 'logs', tmp_path / 'out'
    source.mkdir()
    secret = tmp_path / 'secret.txt'
    secret.write_text('root-only')
    secret.chmod(0o600)
    os.symlink(str(secret), str(source / 'leak.log'))
    os.symlink('/nonexistent', str(source / 'dangling.log'))
    os.mkfifo(str(source / 'fifo.log'))
    (source / 'long.log').write_text('first\n' + 'x' * (3 * sandbox.LOG_PART) + '\nlast\n')
    (source / 'probe-main.json').write_text(json.dumps({'ok': True}))
    skipped = sandbox.copy_results(str(source), str(target))
    assert sorted(skipped) == ['dangling.log', 'fifo.log', 'leak.log']
    assert sorted(os.listdir(str(target))) == ['long.log', 'probe-main.json']
    text = (target / 'long.log').read_text()
    assert text.startswith('first\n') and text.endswith('\nlast\n')
    assert 'bytes cut by the grader' in text and len(text) < 2 * sandbox.LOG_PART + 200


def test_no_sandbox_no_grading_unless_the_risk_is_named(monkeypatch, tmp_path):
    monkeypatch.setattr(sandbox, 'check', lambda: 'bubblewrap is missing')
    with pytest.raises(sandbox.SandboxUnavailable) as refused:
        runner.grade_submission(VICTIM, str(tmp_path / 'out'))
    assert 'bubblewrap is missing' in str(refused.value)
    assert '--unsandboxed-student-code-can-read-and-damage-my-files' in str(refused.value)
    assert not os.path.exists(str(tmp_path / 'out'))
    assert runner.sandbox_refusal(unsandboxed=True) is None


def test_probe_results_must_belong_to_the_run():
    from exam_lab.grader.judge.session import probe_problem
    plan = {'kind': 'main', 'delay': 5.0}
    real = {'t0': 100.0, 'schedule': {'rest': 110.0, 'long_up': 120.0, 'long_down': 127.5, 'end': 130.0},
            'clock': {'use_sim_time': [None, None], 'messages': 0, 'publishers': []}}
    assert probe_problem(real, plan, 99.0, 131.0) is None
    assert 'not within' in probe_problem(real, plan, 200.0, 240.0)       # an old run's file
    short = dict(real, schedule=dict(real['schedule'], long_down=121.0))
    assert 'less than' in probe_problem(short, plan, 99.0, 131.0)        # the flight did not last
    assert 'no times' in probe_problem({}, plan, 99.0, 131.0)


def test_a_box_is_another_user_and_sees_only_its_own():
    """A box as root's process tree makes it: not root, no /root, no host /tmp, a read-only package,
    none of the grader's variables (not even in its pid 1's environment); its detached child dies with
    it."""
    if os.geteuid() != 0 or sandbox.check() is not None:
        pytest.skip('boxes need root and bubblewrap: %s' % sandbox.check())
    work = tempfile.mkdtemp(prefix='exam-box-test-')  # as the runner's: in /tmp, which the box must not see
    os.makedirs(os.path.join(work, 'ws', 'src', 'exam'))
    for folder in (work, os.path.join(work, 'ws'), os.path.join(work, 'ws', 'src'), os.path.join(work, 'ws', 'src', 'exam')):
        os.chmod(folder, 0o755)
    host_file = os.path.join(work, 'host-file')
    shown = os.path.join(work, 'underlay')  # a grader's folder under the host's /tmp, bound read-only
    os.makedirs(shown)
    os.chmod(shown, 0o755)
    with open(host_file, 'w') as f:
        f.write('host')
    script = ('id -u; test -e /root && echo ROOT_VISIBLE; test -e %s && echo HOST_TMP_VISIBLE; '
              'touch /box/ws/src/exam/x 2>/dev/null && echo PACKAGE_WRITABLE; touch /box/ws/devel/x && echo OK; '
              'env; tr "\\0" "\\n" < /proc/1/environ; (setsid sh -c "sleep 77; true" &) ; '
              'test -d %s && echo BOUND; cat /proc/self/limits; head -c %d /dev/zero > /box/ws/devel/big; echo "BIG $(wc -c < /box/ws/devel/big)"'
              % (host_file, shown, sandbox.FILE_BYTES + 4096))
    try:
        with sandbox.Box(work, [shown]) as box:
            grader_env = dict(os.environ, GRADER_SECRET='leak')
            done = subprocess.run(box.argv(['sh', '-c', script], grader_env), env=grader_env,
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=60)
            output, uid = done.stdout.decode(), box.uid
            assert wait_until(lambda: not box.leftovers(), 10.0, period=0.1), box.leftovers()
    finally:
        shutil.rmtree(work, ignore_errors=True)
    lines = output.splitlines()
    assert lines[0] == str(uid) and uid != 0
    assert 'OK' in lines and 'BOUND' in lines
    assert 'BIG %d' % sandbox.FILE_BYTES in lines, 'a file stops growing at the limit'
    limits = dict((line[:26].strip(), line[26:].split()) for line in lines if line.startswith('Max '))
    assert limits['Max processes'][0] == str(sandbox.PROCESSES)
    assert limits['Max cpu time'][0] == str(sandbox.CPU_SECONDS)
    assert limits['Max address space'][0] == str(sandbox.ADDRESS_SPACE_BYTES)
    for bad in ('ROOT_VISIBLE', 'HOST_TMP_VISIBLE', 'PACKAGE_WRITABLE', 'GRADER_SECRET', 'EXAM_LAB'):
        assert bad not in output
