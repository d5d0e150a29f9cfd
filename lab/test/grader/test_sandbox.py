"""The grader's sandbox against hostile students (issue 16), read from the session's one hostile class
(conftest.py ``hostile_class``, hostile_run.py: graded once with ``JOBS=2`` for this module and the
three test_boundary_* ones).

This module's students of that class: ``c_saboteur`` (kills, reads and writes the classmates graded
beside it), ``b_victim`` (the good student's package: it must keep its 17 points), ``d_forger`` (an idle
node that writes a real probe result where the grader used to read its own), ``e_escapee`` (prints its
environment and a root-only file, leaves links and a FIFO where the grader copies logs from, starts
detached children at build and run time), ``f_snoop`` (no code: its launch file includes a root-only
launch file whose node and parameter names carry a secret; issue 26 point 1). Their payloads live in
lab/test/grader/hostile/ and do nothing as root. A new hostile student of this kind: a line in
hostile_run.CLASS and its name in STUDENTS below. The copy and refusal checks need no ROS.
"""
import json
import os
import secrets
import shutil
import subprocess
import tempfile
import time

import pytest

from exam_lab.grader import class_run, runner
from exam_lab.grader.host import boxed_run

from exam_lab.grader import contract
from exam_lab.grader.host import limits, sandbox, staging, uids
from exam_lab.grader.score.inspection import InspectRecord
from exam_lab.grader.score.sheets import ITEMS
from exam_lab.harness.wait import wait_until
from hostile_run import GOOD as VICTIM, HOSTILE, NAMES, SECRET_DIR, VICTIM_NAME, files_under, write_secrets

FULL = {item: points for item, (points, _) in ITEMS.items()}
#: This module's students of the hostile class (the saboteur's victim is the class's one victim).
SABOTEUR, FORGER, ESCAPEE, SNOOP = 'c_saboteur', 'd_forger', 'e_escapee', 'f_snoop'
STUDENTS = (SABOTEUR, VICTIM_NAME, FORGER, ESCAPEE, SNOOP)


def test_links_and_fifos_do_not_stop_the_class(hostile_class):
    assert hostile_class['finished'], hostile_class['output']
    with open(os.path.join(hostile_class['out'], 'grades.csv')) as f:
        rows = f.read().splitlines()[1:]
    assert sorted(row.split(',')[0] for row in rows) == NAMES


def test_every_student_runs_in_a_box_of_its_own(hostile_class):
    """Each of its own box's uid; the class's first two, which start together (JOBS=2), two uids (the
    others start as a slot frees: one may take the uid of a classmate already done)."""
    boxes = {}
    for name in sorted(set(STUDENTS) | set(NAMES[:2])):
        if name == SNOOP:
            continue  # no code: nothing of it runs (its upload is read in a box: test_a_snoop_reads_nothing_root_can)
        record = hostile_class['records'][name]
        ran = [hint for hint in record['for_the_teacher'] if hint.startswith('ran ') and ' as ' in hint]
        assert len(ran) == 1 and ran[0].startswith('ran in a bubblewrap sandbox as uid '), (name, ran)
        boxes[name] = int(ran[0].split('as uid ')[1].split(':')[0])
    assert boxes[NAMES[0]] != boxes[NAMES[1]], 'two students graded side by side share a uid'
    assert all(uid >= uids.BOX_UID_BASE for uid in boxes.values())


def test_the_classmate_of_a_saboteur_keeps_its_points(hostile_class):
    """The victim keeps its points; no classmate's file says HACKED (the saboteur writes into every
    classmate's logs it can reach: whoever is graded beside it); the saboteur read no code of the good
    student (the victim's, and that of the classmates running its node) and killed nothing."""
    record = hostile_class['records'][VICTIM_NAME]
    got = {i['id']: i['points'] for i in record['items']}
    assert got == FULL, '\n'.join('%s: %s' % (i['id'], i['evidence']) for i in record['items'])
    victim_files = dict(files_under(os.path.join(hostile_class['out'], VICTIM_NAME)))
    assert not [p for p, text in victim_files.items() if 'HACKED' in text]
    for name in NAMES:
        if name != SABOTEUR:
            assert not [p for p, text in files_under(os.path.join(hostile_class['out'], name)) if 'HACKED' in text], name
    with open(os.path.join(VICTIM, 'scripts', 'exam_node.py')) as f:
        victim_line = f.read().splitlines()[2]
    saboteur_files = dict(files_under(os.path.join(hostile_class['out'], SABOTEUR)))
    assert not [p for p, text in saboteur_files.items() if victim_line in text]
    assert not [p for p, text in saboteur_files.items() if 'KILLED' in text]


def test_a_forged_probe_file_changes_nothing(hostile_class):
    record = hostile_class['records'][FORGER]
    got = {i['id']: i['points'] for i in record['items']}
    assert got['Q11'] == 0.0 and got['Q13'] == 0.0 and got['Q14b'] == 0.0, got
    assert record['total'] <= 3.0
    for path, text in files_under(hostile_class['out']):
        assert 'FORGER usercustomize ran' not in text, path


def test_no_detached_child_survives(hostile_class, all_class_runs_done):
    """Nor any process of a box's uid, of a slot no grader holds, once the session's classes are graded."""
    assert hostile_class['survivors'] == []
    assert uids.left_behind(uids.BOX_UID_BASE) == []


def test_secrets_never_reach_the_results(hostile_class):
    escapee = hostile_class['records'][ESCAPEE]
    assert escapee['items'][0]['points'] >= 1.0, 'the escapee built: its payload ran'
    for path, text in files_under(hostile_class['out']):
        for secret in hostile_class['sandbox_secrets']:
            assert secret not in text, path


def read_as(record):
    """The uids the grade record says its upload was read as."""
    return [int(hint.split(' as uid ')[1].split(',')[0]) for hint in record['for_the_teacher']
            if hint.startswith('the upload was read ') and ' as uid ' in hint]


def test_a_snoop_reads_nothing_root_can(hostile_class):
    """Its include of a root-only launch file is not there for the box that reads it: no node, no
    parameter, nothing to run; the class went on around it."""
    record = hostile_class['records'][SNOOP]
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
             ('bytearray(2 << 30)', (60.0, 60, 1 << 30), 'it ran out of memory: its bound is 1024 MB of address space'),
             ('os.symlink("/etc/shadow", "inspect.json")', (60.0, 60, 1 << 30), 'a link, not followed')]
    for statement, bounds, words in cases:
        work = staging.new_work('exam-bounds-test-')
        try:
            staging.stage_work(work, [])
            start = time.monotonic()
            with sandbox.Box(work) as box:
                boxed = boxed_run.Boxed(box, work)
                with pytest.raises(boxed_run.InspectionFailed) as failed:
                    boxed.run('timeit', ['-n', '1', '-r', '1', '-s', 'import os, time', statement],
                              InspectRecord, bounds)
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
        students = class_run.class_students(archive, work_dirs)
        assert [name for name, _ in students] == ['Bob', 'Jane Doe']
        for _, folder in students:
            assert folder.startswith(work_dirs[0] + '/') and os.stat(folder).st_uid >= uids.BOX_UID_BASE
            assert os.path.isfile(os.path.join(folder, 'exam', 'package.xml'))
        # The teacher's CLASS= may be a link to the zip (a download kept elsewhere): the zip it names.
        os.symlink(archive, str(tmp_path / 'latest.zip'))
        assert [name for name, _ in class_run.class_students(str(tmp_path / 'latest.zip'), work_dirs)] == ['Bob', 'Jane Doe']
        with zipfile.ZipFile(archive, 'a') as zf:
            zf.writestr('../outside.txt', 'x')
        with pytest.raises(archives.UnpackError, match='unpacking it in its box failed'):
            class_run.class_students(archive, work_dirs)
    finally:
        for work in work_dirs:
            shutil.rmtree(work, ignore_errors=True)


def test_a_class_zipped_by_info_zip_is_listed_by_its_box_as_named(tmp_path):
    """Issue 45 point 4, through the intake's box: a class folder zipped again by Info-ZIP's ``zip -r``
    where it finds no UTF-8 locale (its folders' own entries, UTF-8 names unflagged) gives every
    student, each named as Moodle's folder says ("Zoé DArc", not "Zo├⌐ DArc" nor "Zo__ DArc"), none
    refused (test_grader_unpack.py has the other tools and locales)."""
    if os.geteuid() != 0 or sandbox.check() is not None:
        pytest.skip('boxes need root and bubblewrap: %s' % sandbox.check())
    import zipfile
    klass = tmp_path / 'Robotique-Examen-1234'
    for folder in ('Zoé DArc_42_assignsubmission_file', 'Bob Late_43_assignsubmission_file'):
        (klass / folder).mkdir(parents=True)
        with zipfile.ZipFile(str(klass / folder / 'exam.zip'), 'w') as zf:
            zf.writestr('exam/package.xml', '<package><name>exam</name></package>')
    (tmp_path / 'no-locale').mkdir()
    subprocess.run(['zip', '-q', '-r', 'class.zip', klass.name], cwd=str(tmp_path), check=True, timeout=60,
                   env={'PATH': os.environ['PATH'], 'LC_ALL': 'C', 'LOCPATH': str(tmp_path / 'no-locale')})
    with zipfile.ZipFile(str(tmp_path / 'class.zip')) as zf:
        assert "Robotique-Examen-1234/Zo\u251c\u2310 DArc_42_assignsubmission_file/" in zf.namelist()
    work_dirs, refused = [], {}
    try:
        students = class_run.class_students(str(tmp_path / 'class.zip'), work_dirs, refused=refused)
        assert [name for name, _ in students] == ['Bob Late', 'Zoé DArc'] and refused == {}
        for _, folder in students:
            assert os.listdir(folder) == ['exam.zip']
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
    (source / 'long.log').write_text('first\n' + 'x' * (3 * contract.LOG_PART) + '\nlast\n')
    (source / 'probe-main.json').write_text(json.dumps({'ok': True}))
    skipped = contract.copy_results(str(source), str(target))
    assert sorted(skipped) == ['dangling.log', 'fifo.log', 'leak.log']
    assert sorted(os.listdir(str(target))) == ['long.log', 'probe-main.json']
    text = (target / 'long.log').read_text()
    assert text.startswith('first\n') and text.endswith('\nlast\n')
    assert 'bytes cut by the grader' in text and len(text) < 2 * contract.LOG_PART + 200


def test_no_sandbox_no_grading_unless_the_risk_is_named(monkeypatch, tmp_path):
    monkeypatch.setattr(sandbox, 'check', lambda: 'bubblewrap is missing')
    with pytest.raises(sandbox.SandboxUnavailable) as refused:
        runner.grade_submission(VICTIM, str(tmp_path / 'out'))
    assert 'bubblewrap is missing' in str(refused.value)
    assert '--unsandboxed-student-code-can-read-and-damage-my-files' in str(refused.value)
    assert not os.path.exists(str(tmp_path / 'out'))
    assert sandbox.sandbox_refusal(unsandboxed=True) is None


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

