"""The one class of hostile students the grader's boundary tests read (issue 37 point 6).

Every hostile package of lab/test/grader/hostile/ and one victim (the good student's package) are
graded together, once a pytest session, by ``grade.py --class`` as ``make grade`` runs it: a Moodle
worksheet, ``--jobs 2``, in a child process with a deadline (a parser that never ends fails the tests
instead of hanging them). Around the run, the union of what the four boundary modules put in place:
the root-only files each payload reaches for, the grader's secret variables, the class token the
saboteur looks for. A grading costs about 45 s of a slot: one class of eleven instead of four classes
of thirteen, each with its own victim, is what keeps ``make test`` short.

The modules reading it (each its own tests, no other class run): test_sandbox (issue 16),
test_boundary_judge, test_boundary_parsers, test_boundary_publish (issue 26). To add a hostile
student: a package in hostile/, a line in CLASS (its place in the order says who it is graded
beside), its setup in :func:`grade` if it needs one, its tests in the module of its kind.
"""
import json
import os
import secrets
import shutil
import signal
import subprocess
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
REPO = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
GRADE = os.path.join(REPO, 'lab', 'scripts', 'grade.py')
HOSTILE = os.path.join(HERE, 'hostile')
GOOD = os.path.join(HERE, 'submissions', 'good_student', 'exam')

#: Gradings side by side (the burner's box has a CPU quota of cores / JOBS: limits.box_cpus).
JOBS = 2
#: The victim: the good student's package, graded beside the burner (the first two start together
#: with JOBS=2), then beside whoever comes next; it must keep its 17 points.
VICTIM_NAME = 'b_victim'
#: ``(student, package, overlay)``: the student's folder is ``package`` with ``overlay`` copied over it
#: (None: nothing). Sorted by name, the order the class is graded in, two at a time.
CLASS = [
    ('a_burner', os.path.join(HOSTILE, 'burner', 'exam'), None),        # judge: 140 busy processes at build
    (VICTIM_NAME, GOOD, None),
    ('c_saboteur', os.path.join(HOSTILE, 'saboteur', 'exam'), None),    # sandbox: kills, reads, writes classmates
    ('d_forger', os.path.join(HOSTILE, 'forger', 'exam'), None),        # sandbox: writes a probe result
    ('e_escapee', os.path.join(HOSTILE, 'escapee', 'exam'), None),      # sandbox: env, root file, links, FIFO, children
    ('f_snoop', os.path.join(HOSTILE, 'snoop', 'exam'), None),          # sandbox: includes a root-only launch file
    ('g_clock', os.path.join(HOSTILE, 'clock', 'exam'), 'node'),        # judge: a /clock of its own
    ('h_param_flood', os.path.join(HOSTILE, 'param_flood', 'exam'), 'node'),  # judge: 64 MB parameters
    ('i_leaker', GOOD, os.path.join(HOSTILE, 'leaker', 'exam')),        # parsers: names the grader's files
    ('j_bomber', GOOD, os.path.join(HOSTILE, 'bomber', 'exam')),        # parsers: YAML bomb, crafted PDF
    ('k_noisy', os.path.join(HOSTILE, 'noisy', 'exam'), None),          # publish: +-1.7e308, a lying traceback
    ('l_hooked', os.path.join(HOSTILE, 'hooked', 'exam'), 'node'),      # judge: an env hook answers for roslaunch
    ('m_respawner', os.path.join(HOSTILE, 'respawner', 'exam'), 'node'),  # judge: a death hidden by respawn
]
NAMES = [name for name, _, _ in CLASS]
#: Moodle's "download all submissions" folder of each student (its participant number), and the
#: worksheet that names them.
FOLDERS = {name: '%s_%d_assignsubmission_file_' % (name, 101 + index) for index, name in enumerate(NAMES)}
WORKSHEET = ('\ufeffIdentifier,Full name,Grade,Maximum grade,Last modified (grade),Feedback comments\n' +
             ''.join('"Participant %d","%s",,17.00,-,\n' % (101 + index, name.replace('_', ' '))
                     for index, name in enumerate(NAMES)))
#: The whole class's deadline, s: about 5 minutes on two idle cores when nothing hangs (a
#: backtracking PDF reader once took hours).
CLASS_TIMEOUT = 1800

#: Where the escapee looks for the root-only file, and the snoop's root-only launch file (their
#: payloads name them).
SECRET_DIR = '/tmp/exam-hostile-secret'
SECRET_LAUNCH = os.path.join(SECRET_DIR, 'secret.launch')
#: In the command line of the escapee's detached children.
DETACHED = 'exam-hostile-detached'
#: Where the leaker's launch file points outside its package (its launch file names this folder).
OUTSIDE = '/tmp/exam-hostile-parsers'
#: Folders of the grader's side where a derived ``.grader-*`` copy was written beside an included file.
GRADER_FOLDERS = (OUTSIDE, os.path.join(REPO, 'mydrone'), os.path.join(REPO, 'submarinedrone'), HOSTILE)


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


def write_outside(token):
    """OUTSIDE with a root-only YAML and launch file (mode 600) carrying ``token``; their names."""
    shutil.rmtree(OUTSIDE, ignore_errors=True)
    os.makedirs(OUTSIDE)
    texts = {'secret.yaml': 'threshold_root_only_%s: 1300\n' % token,
             'outside.launch': '<launch><param name="outside_%s" value="1300"/></launch>\n' % token}
    for name, text in texts.items():
        with open(os.open(os.path.join(OUTSIDE, name), os.O_WRONLY | os.O_CREAT, 0o600), 'w') as f:
            f.write(text)


def crafted_pdf(path, size=2 << 20):
    """A PDF made for a backtracking reader: page tree nodes that never close, then ``stream`` lines
    with nothing to inflate; no real page tree, so its page count is unknown."""
    half = size // 2
    with open(path, 'wb') as f:
        f.write(b'%PDF-1.5\n<< /Type /Pages ' + b'/Type /Pages /Count 1 ' * (half // 22) + b'\n'
                + b'stream\n' * (half // 7))


def derived_files(folders):
    return sorted(os.path.join(dirpath, name) for folder in folders for dirpath, _, names in os.walk(folder)
                  for name in names if name.startswith('.grader-'))


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


#: The folders of a student's OUT that hold its own bytes as handed in, kept read-only for the teacher
#: (host/reports.py): its source's text is data there, never a sign that its code ran.
KEPT_AS_HANDED_IN = ('code', 'report')


def files_under(folder):
    for dirpath, dirnames, filenames in os.walk(folder):
        if folder.rstrip('/') in (dirpath, os.path.dirname(dirpath)):
            dirnames[:] = [d for d in dirnames if d not in KEPT_AS_HANDED_IN]
        for name in filenames:
            path = os.path.join(dirpath, name)
            if os.path.isfile(path) and not os.path.islink(path):
                with open(path, 'rb') as f:
                    yield path, f.read().decode('utf-8', 'replace')


def make_class(klass):
    for name, package, overlay in CLASS:
        target = os.path.join(klass, FOLDERS[name], 'exam')
        shutil.copytree(package, target, ignore=shutil.ignore_patterns('__pycache__', '.grader-*'))
        if overlay == 'node':  # the good student's node beside the payload
            os.makedirs(os.path.join(target, 'scripts'), exist_ok=True)
            shutil.copy2(os.path.join(GOOD, 'scripts', 'exam_node.py'), os.path.join(target, 'scripts', 'exam_node.py'))
        elif overlay:
            shutil.copytree(overlay, target, dirs_exist_ok=True)
    crafted_pdf(os.path.join(klass, FOLDERS['j_bomber'], 'report.pdf'))


def grade(root):
    """Grade the class in ``root`` once, everything in place; yield what the tests read; clean up.

    Yields a dict: ``out`` (the class's OUT), ``records`` (student: its grade.json), ``finished``
    (within the deadline, exit 0), ``status``/``stdout``/``stderr`` of grade.py, ``output`` (the end of
    both, for a message), ``survivors`` (the escapee's detached children alive right after),
    ``sandbox_secrets`` (the root-only file's token, the grader's variable EXAM_HOSTILE_SECRET),
    ``parser_secrets`` (the outside files' token, EXAM_HOSTILE_PARSERS_SECRET), ``new_derived`` and
    ``outside`` (derived copies written on the grader's side, OUTSIDE's listing after the run).
    """
    klass, out = os.path.join(root, 'class'), os.path.join(root, 'out')
    make_class(klass)
    worksheet = os.path.join(root, 'worksheet.csv')
    with open(worksheet, 'w', encoding='utf-8') as f:
        f.write(WORKSHEET)
    secret_file, outside_token = 'root-only-%s' % secrets.token_hex(8), secrets.token_hex(8)
    secret_var, parser_var = 'grader-env-%s' % secrets.token_hex(8), 'grader-env-%s' % secrets.token_hex(8)
    # The saboteur attacks the processes carrying the class token: the grader's environment must reach
    # none of its students' (so it finds none, and kills nothing).
    env = dict(os.environ, EXAM_HOSTILE_SECRET=secret_var, EXAM_HOSTILE_CLASS='1',
               EXAM_HOSTILE_PARSERS_SECRET=parser_var)
    env.setdefault('EXAM_WS', os.path.join(REPO, '.ws'))
    before = derived_files(GRADER_FOLDERS)
    try:
        write_secrets(secret_file)
        write_outside(outside_token)
        try:
            done = subprocess.run([sys.executable, GRADE, '--class', klass, '--out', out, '--jobs', str(JOBS),
                                   '--worksheet', worksheet, '--no-similarity'], env=env,
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=CLASS_TIMEOUT)
            status, stdout, stderr = (done.returncode, done.stdout.decode('utf-8', 'replace'),
                                      done.stderr.decode('utf-8', 'replace'))
        except subprocess.TimeoutExpired:
            status, stdout, stderr = None, '', 'the class did not finish within %d s' % CLASS_TIMEOUT
        survivors = detached_children()
        records = {}
        for name in NAMES:
            try:
                with open(os.path.join(out, name, 'grade.json')) as f:
                    records[name] = json.load(f)
            except (OSError, ValueError):
                pass
        yield {'out': out, 'records': records, 'finished': status == 0, 'status': status,
               'stdout': stdout, 'stderr': stderr, 'output': (stdout[-1500:] + '\n' + stderr[-1500:]),
               'survivors': survivors, 'sandbox_secrets': (secret_file, secret_var),
               'parser_secrets': (outside_token, parser_var),
               'new_derived': sorted(set(derived_files(GRADER_FOLDERS)) - set(before)),
               'outside': sorted(os.listdir(OUTSIDE))}
    finally:
        for pid in detached_children():
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
        shutil.rmtree(SECRET_DIR, ignore_errors=True)
        shutil.rmtree(OUTSIDE, ignore_errors=True)
        for path in set(derived_files(GRADER_FOLDERS)) - set(before):
            os.remove(path)
