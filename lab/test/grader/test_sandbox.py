"""The grader's sandbox against hostile students (issue 16): one class run with ``JOBS=2``.

The class: ``a_saboteur`` (kills, reads and writes its classmate graded beside it), ``b_victim`` (the
good student's package: it must keep its 17 points), ``c_forger`` (an idle node that writes a real
probe result where the grader used to read its own), ``d_escapee`` (prints its environment and a
root-only file, leaves links and a FIFO where the grader copies logs from, starts detached children at
build and run time), ``e_snoop`` (no code: its launch file includes a root-only launch file whose node
and parameter names carry a secret; issue 26 point 1). Their payloads live in lab/test/grader/hostile/
and do nothing as root. About 2 minutes on two cores; the copy and refusal checks need no ROS.
"""
import json
import os
import secrets
import shutil
import signal
import subprocess
import tempfile
import time

import pytest

from exam_lab.grader import runner

from exam_lab.grader.host import egress, limits, sandbox, staging, uids
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
         ('c_forger', os.path.join(HOSTILE, 'forger', 'exam')), ('d_escapee', os.path.join(HOSTILE, 'escapee', 'exam')),
         ('e_snoop', os.path.join(HOSTILE, 'snoop', 'exam'))]
#: The root-only launch file the snoop includes (its launch file names it).
SECRET_LAUNCH = os.path.join(SECRET_DIR, 'secret.launch')


def write_secrets(token):
    """SECRET_DIR (readable) with secret.txt and secret.launch (root's, mode 600), each carrying ``token``."""
    shutil.rmtree(SECRET_DIR, ignore_errors=True)
    os.makedirs(SECRET_DIR)
    os.chmod(SECRET_DIR, 0o755)
    for path, text in ((os.path.join(SECRET_DIR, 'secret.txt'), token),
                       (SECRET_LAUNCH, '<launch><node pkg="exam" type="exam_node_%s.py" name="exam">'
                                       '<param name="threshold_%s" value="1300"/></node></launch>\n' % (token, token))):
        with open(os.open(path, os.O_WRONLY | os.O_CREAT, 0o600), 'w') as f:
            f.write(text)


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
    secret_file = 'root-only-%s' % secrets.token_hex(8)
    write_secrets(secret_file)
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
        if name == 'e_snoop':
            continue  # no code: nothing of it runs (its upload is read in a box: test_a_snoop_reads_nothing_root_can)
        ran = [hint for hint in record['for_the_teacher'] if hint.startswith('ran ') and ' as ' in hint]
        assert len(ran) == 1 and ran[0].startswith('ran in a bubblewrap sandbox as uid '), (name, ran)
        boxes.append(int(ran[0].split('as uid ')[1].split(':')[0]))
    assert boxes[0] != boxes[1], 'the saboteur and its classmate, graded side by side, share a uid'
    assert all(uid >= uids.BOX_UID_BASE for uid in boxes)


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
    assert [uid for uid in range(uids.BOX_UID_BASE, uids.BOX_UID_BASE + uids.SLOTS)
            if uids.pids_of_uid(uid)] == []


def test_secrets_never_reach_the_results(hostile_class):
    escapee = hostile_class['records']['d_escapee']
    assert escapee['items'][0]['points'] >= 1.0, 'the escapee built: its payload ran'
    for path, text in files_under(hostile_class['out']):
        for secret in hostile_class['secrets']:
            assert secret not in text, path


def read_as(record):
    """The uids the grade record says its upload was read as."""
    return [int(hint.split(' as uid ')[1].split(',')[0]) for hint in record['for_the_teacher']
            if hint.startswith('the upload was read ') and ' as uid ' in hint]


def test_a_snoop_reads_nothing_root_can(hostile_class):
    """Its include of a root-only launch file is not there for the box that reads it: no node, no
    parameter, nothing to run; the class went on around it."""
    record = hostile_class['records']['e_snoop']
    assert [uid for uid in read_as(record) if uid >= uids.BOX_UID_BASE] == read_as(record) != []
    # Two walls, either enough: the analysis reads no file outside the package, and the box sees none.
    assert [h for h in record['for_the_teacher'] if 'include' in h and ('not found' in h or 'outside the package'
                                                                       in h)], record['for_the_teacher']
    assert record['total'] == 0.0


def test_the_upload_is_read_as_the_box_uid(tmp_path):
    """grade_submission of the snoop alone: the inspection runs as the box's uid, so the root-only
    launch file it includes is never read (today's grader read it as root: the secret in its node's
    type and parameter name reached the grade)."""
    if os.geteuid() != 0 or sandbox.check() is not None:
        pytest.skip('boxes need root and bubblewrap: %s' % sandbox.check())
    token = 'root-only-%s' % secrets.token_hex(8)
    write_secrets(token)
    try:
        record = runner.grade_submission(os.path.join(HOSTILE, 'snoop', 'exam'), str(tmp_path / 'out'), student='snoop')
    finally:
        shutil.rmtree(SECRET_DIR, ignore_errors=True)
    assert token not in json.dumps(record)
    for path, text in files_under(str(tmp_path / 'out')):
        assert token not in text, path
    assert read_as(record) and all(uid >= uids.BOX_UID_BASE for uid in read_as(record)), record['for_the_teacher']


def test_reading_student_bytes_is_bounded(tmp_path):
    """What reads a student's bytes is stopped at its bounds, and its record is one regular file:
    a loop at the CPU bound, a sleeper at the wall clock, a memory hog at its address space, a link
    where the record should be; each is that student's failure (InspectionFailed), never root's."""
    from exam_lab.grader.score import records
    if os.geteuid() != 0 or sandbox.check() is not None:
        pytest.skip('boxes need root and bubblewrap: %s' % sandbox.check())
    cases = [('while True: pass', (60.0, 2, 1 << 30), 'killed by signal'),
             ('time.sleep(600)', (3.0, 60, 1 << 30), 'did not finish within 3 s'),
             ('bytearray(2 << 30)', (60.0, 60, 1 << 30), 'MemoryError'),
             ('os.symlink("/etc/shadow", "inspect.json")', (60.0, 60, 1 << 30), 'a link, not followed')]
    for statement, bounds, words in cases:
        work = tempfile.mkdtemp(prefix='exam-bounds-test-')
        try:
            os.chmod(work, 0o711)
            for sub in ('upload', 'ws', 'ws/src'):
                os.mkdir(os.path.join(work, sub), 0o755)
            start = time.monotonic()
            with sandbox.Box(work) as box:
                boxed = runner.Boxed(box, work)
                with pytest.raises(runner.InspectionFailed) as failed:
                    boxed.run('timeit', ['-n', '1', '-r', '1', '-s', 'import os, time', statement],
                              records.InspectRecord, bounds)
                assert not box.leftovers()
            assert words in str(failed.value), (statement, str(failed.value))
            assert time.monotonic() - start < bounds[0] + 30.0
        finally:
            shutil.rmtree(work, ignore_errors=True)


def test_a_class_archive_is_unpacked_in_a_box(tmp_path):
    """A class zip is opened by a box's uid (boxed/intake), never root: its students come back as names
    and folders inside the intake's own folder; an archive that climbs out is refused as a whole."""
    if os.geteuid() != 0 or sandbox.check() is not None:
        pytest.skip('boxes need root and bubblewrap: %s' % sandbox.check())
    import zipfile
    from exam_lab.grader.boxed import archives
    archive = str(tmp_path / 'class.zip')
    with zipfile.ZipFile(archive, 'w') as zf:
        for folder in ('Jane Doe_12_assignsubmission_file_', 'Bob_13_assignsubmission_file_'):
            zf.writestr('%s/exam/package.xml' % folder, '<package><name>exam</name></package>')
    work_dirs = []
    try:
        students = runner.class_students(archive, work_dirs)
        assert [name for name, _ in students] == ['Bob', 'Jane Doe']
        for _, folder in students:
            assert folder.startswith(work_dirs[0] + '/') and os.stat(folder).st_uid >= uids.BOX_UID_BASE
            assert os.path.isfile(os.path.join(folder, 'exam', 'package.xml'))
        with zipfile.ZipFile(archive, 'a') as zf:
            zf.writestr('../outside.txt', 'x')
        with pytest.raises(archives.UnpackError, match='unpacking it in its box failed'):
            runner.class_students(archive, work_dirs)
    finally:
        for work in work_dirs:
            shutil.rmtree(work, ignore_errors=True)


def test_an_upload_is_staged_as_bytes_never_followed(tmp_path):
    """What root does with an upload before its box reads it: a copy of its regular files, folders and
    links (as links: never followed, even to a root-only file), no FIFO, within a size budget."""
    upload, staged = tmp_path / 'upload', tmp_path / 'staged'
    (upload / 'exam' / 'launch').mkdir(parents=True)
    (upload / 'exam' / 'launch' / 'exam.launch').write_text('<launch/>')
    (upload / 'exam' / 'node.py').write_text('#!/usr/bin/env python3\n')
    (upload / 'exam' / 'node.py').chmod(0o700)
    secret = tmp_path / 'secret.txt'
    secret.write_text('root-only')
    secret.chmod(0o600)
    os.symlink(str(secret), str(upload / 'exam' / 'leak.txt'))
    os.mkfifo(str(upload / 'exam' / 'fifo'))
    staging.stage_upload(str(upload), str(staged))
    assert sorted(os.listdir(str(staged / 'exam'))) == ['launch', 'leak.txt', 'node.py']
    assert oct(os.stat(str(staged / 'exam' / 'node.py')).st_mode & 0o777) == '0o755', 'a script stays executable'
    assert os.readlink(str(staged / 'exam' / 'leak.txt')) == str(secret)
    assert (staged / 'exam' / 'launch' / 'exam.launch').read_text() == '<launch/>'
    assert oct(os.stat(str(staged / 'exam' / 'launch' / 'exam.launch')).st_mode & 0o777) == '0o644'
    with pytest.raises(staging.UploadRefused, match='larger than the grader takes'):
        staging.stage_upload(str(upload), str(tmp_path / 'capped'), max_bytes=4)


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
    (source / 'long.log').write_text('first\n' + 'x' * (3 * egress.LOG_PART) + '\nlast\n')
    (source / 'probe-main.json').write_text(json.dumps({'ok': True}))
    skipped = egress.copy_results(str(source), str(target))
    assert sorted(skipped) == ['dangling.log', 'fifo.log', 'leak.log']
    assert sorted(os.listdir(str(target))) == ['long.log', 'probe-main.json']
    text = (target / 'long.log').read_text()
    assert text.startswith('first\n') and text.endswith('\nlast\n')
    assert 'bytes cut by the grader' in text and len(text) < 2 * egress.LOG_PART + 200


def test_no_sandbox_no_grading_unless_the_risk_is_named(monkeypatch, tmp_path):
    monkeypatch.setattr(sandbox, 'check', lambda: 'bubblewrap is missing')
    with pytest.raises(sandbox.SandboxUnavailable) as refused:
        runner.grade_submission(VICTIM, str(tmp_path / 'out'))
    assert 'bubblewrap is missing' in str(refused.value)
    assert '--unsandboxed-student-code-can-read-and-damage-my-files' in str(refused.value)
    assert not os.path.exists(str(tmp_path / 'out'))
    assert runner.sandbox_refusal(unsandboxed=True) is None


def test_probe_results_must_belong_to_the_run():
    from exam_lab.grader.host.session import probe_problem
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
              % (host_file, shown, limits.FILE_BYTES + 4096))
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
    assert 'BIG %d' % limits.FILE_BYTES in lines, 'a file stops growing at the limit'
    seen = dict((line[:26].strip(), line[26:].split()) for line in lines if line.startswith('Max '))
    assert seen['Max processes'][0] == str(limits.PROCESSES)
    assert seen['Max cpu time'][0] == str(limits.CPU_SECONDS)
    assert seen['Max address space'][0] == str(limits.ADDRESS_SPACE_BYTES)
    for bad in ('ROOT_VISIBLE', 'HOST_TMP_VISIBLE', 'PACKAGE_WRITABLE', 'GRADER_SECRET', 'EXAM_LAB'):
        assert bad not in output
