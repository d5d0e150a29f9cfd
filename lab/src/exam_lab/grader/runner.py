"""Grading a submission or a class: prepare, run the session (sandboxed), score, write.

The runner itself never runs a student's code: it unpacks and reads (:mod:`~exam_lab.grader.boxed.unpack`,
:mod:`~exam_lab.grader.boxed.launch`, :mod:`~exam_lab.grader.boxed.source`) a copy of the package that no
student code can write, writes the derived launch files and the job, opens the submission's
:class:`~exam_lab.grader.host.sandbox.Box`, and starts :mod:`exam_lab.grader.judge.session` as root inside
``unshare --net`` (only loopback), under a :class:`~exam_lab.harness.supervisor.Supervisor` with an
overall time limit. Then :mod:`~exam_lab.grader.score.rubric` scores and :mod:`~exam_lab.grader.publish.report`
writes; what reaches the results from the session's folder is copied as data (regular files only,
each capped: :func:`~exam_lab.grader.host.sandbox.copy_results`).

The simulators (``drone_sim``, ``mydrone``, ``submarinedrone``) are built once as an underlay
workspace (cached under ``$EXAM_WS/grader/underlay``, rebuilt when their sources change); each student's
package is built alone in an overlay of its own on top of it, so a student's ``exam`` never meets ours.
"""
import concurrent.futures
import fcntl
import hashlib
import json
import os
import pwd
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import traceback

from exam_lab.grader import workspace
from exam_lab.grader.boxed import documents, launch, similarity, source, unpack

from exam_lab.grader.host import sandbox

from exam_lab.grader.score import rubric

from exam_lab.grader.publish import progress, report
from exam_lab.grader.score.sheets import DELAY, LATE_WARNING_S, PACKAGE, SHEETS
from exam_lab.harness.supervisor import WORKSPACE_VARS, Supervisor, end_pids, marked

#: Time limits, s: the student's catkin_make, the node's start (to registering with the master),
#: the probe of one run (a late WARNING is waited for up to LATE_WARNING_S), the whole session.
BUILD_TIMEOUT = 180.0
START_TIMEOUT = 20.0
RUN_TIMEOUT = 90.0 + LATE_WARNING_S
SESSION_TIMEOUT = 420.0 + 2 * LATE_WARNING_S
#: The simulator packages of the underlay.
SIMULATORS = ('drone_sim', 'mydrone', 'submarinedrone')

#: Log lines worth the teacher's eye: warnings, errors, tracebacks.
_ODD = re.compile(r'\[(WARN|ERROR|FATAL)\]|Traceback|Error\b|Exception\b')

_isolation = {}
_isolation_lock = threading.Lock()
_underlay_lock = threading.Lock()


def can_isolate():
    """True when this process may run a session in a network namespace of its own (root, unshare)."""
    with _isolation_lock:
        return _can_isolate()


def _can_isolate():
    if 'ok' not in _isolation:
        try:
            _isolation['ok'] = os.geteuid() == 0 and shutil.which('unshare') is not None and \
                subprocess.run(['unshare', '--net', 'true'], timeout=10).returncode == 0
        except (OSError, subprocess.SubprocessError):
            _isolation['ok'] = False
    return _isolation['ok']


def sandbox_refusal(unsandboxed=False):
    """None when student code may run here: boxes can be made, or the teacher passed the flag that
    names the risk (``unsandboxed``); otherwise the refusal, for the teacher."""
    why = sandbox.check()
    if why is None or unsandboxed:
        return None
    return ('refusing to run student code without its sandbox: %s. Run the grader as root on a machine '
            'with bubblewrap and unprivileged user namespaces (docs/grading.md, "Isolation"), or pass '
            '--unsandboxed-student-code-can-read-and-damage-my-files to accept that risk' % why)


def _package_path(name):
    import rospkg
    return rospkg.RosPack().get_path(name)


def ensure_underlay(cache_dir):
    """The setup.bash of the simulators' workspace, built (or rebuilt) when their sources changed."""
    with _underlay_lock:
        os.makedirs(cache_dir, exist_ok=True)
        with open(os.path.join(cache_dir, '.lock'), 'w') as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)  # another grader on this machine may be building it
            sources = [os.path.realpath(_package_path(p)) for p in SIMULATORS]
            digest = hashlib.sha256()
            for src in sources:
                for dirpath, dirnames, filenames in os.walk(src):
                    dirnames[:] = sorted(d for d in dirnames if d not in ('__pycache__', '.pytest_cache'))
                    for filename in sorted(filenames):
                        full = os.path.join(dirpath, filename)
                        digest.update(full.encode())
                        with open(full, 'rb') as f:
                            digest.update(f.read())
            key = digest.hexdigest()
            setup = os.path.join(cache_dir, 'devel', 'setup.bash')
            stamp = os.path.join(cache_dir, 'sources.sha256')
            if os.path.isfile(setup) and os.path.isfile(stamp) and open(stamp).read() == key:
                return setup
            for sub in ('src', 'build', 'devel'):
                shutil.rmtree(os.path.join(cache_dir, sub), ignore_errors=True)
            os.makedirs(os.path.join(cache_dir, 'src'))
            for src in sources:
                os.symlink(src, os.path.join(cache_dir, 'src', os.path.basename(src)))
            env = {k: v for k, v in os.environ.items() if k not in WORKSPACE_VARS}
            env['PATH'] = '/usr/bin:/bin:/usr/sbin:/sbin:/usr/local/bin'
            env.pop('PWD', None)
            done = subprocess.run(['catkin_make', '--directory', cache_dir, '-DPYTHON_EXECUTABLE=/usr/bin/python3',
                                   '-DCATKIN_ENABLE_TESTING=OFF'], cwd=cache_dir, env=env,
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=600)
            if done.returncode != 0:
                raise RuntimeError('building the simulators for the grader failed:\n%s'
                                   % done.stdout.decode('utf-8', 'replace')[-3000:])
            with open(stamp, 'w') as f:
                f.write(key)
            return setup


def detect_sheet(wanted, package_dir, analyses):
    """``(sheet, how it was chosen)``: given, else from package.xml, else the launch files, else the
    topics the code names; altitude when nothing decides."""
    if wanted:
        return wanted, 'sheet %s given' % wanted
    deps = [d for d in source.dependencies(package_dir) if d in (s.drone_pkg for s in SHEETS.values())]
    by_deps = [name for name, s in SHEETS.items() if s.drone_pkg in deps]
    if len(by_deps) == 1:
        return by_deps[0], 'sheet %s: package.xml depends on %s' % (by_deps[0], SHEETS[by_deps[0]].drone_pkg)
    by_launch = sorted(set(s for a in analyses for s in a.drone_sheets()))
    if len(by_launch) == 1:
        return by_launch[0], 'sheet %s: the launch files start %s' % (by_launch[0], SHEETS[by_launch[0]].drone_pkg)
    by_code = source.sheets_in_code(package_dir)
    if len(by_code) == 1:
        return by_code[0], 'sheet %s: the code names its topics' % by_code[0]
    return 'altitude', ('sheet altitude by default: the package could be either (depends on %s); '
                        'give SHEET=depth to grade the other' % (', '.join(deps) or 'neither drone'))


def margin_of(threshold):
    """How far beyond the threshold the probe flies (student units): 10 %, at least 10 m."""
    return max(0.1 * abs(threshold), 10.0)


def prepare(submission, work, wanted_sheet, notes, fixes=None):
    """Unpack and read a submission; write the workspace, the derived launch files and the job.
    ``fixes`` receives what the grader changed in what the student uploaded (``notes`` when None).

    :returns: ``(sheet, static, job)``; ``job`` is None when nothing can be run (no node script).
    """
    fixes = notes if fixes is None else fixes
    uploads = []
    pkg_source = unpack.open_submission(submission, os.path.join(work, 'unpacked'), notes, fixes, uploads=uploads)
    name = unpack.package_name(os.path.join(pkg_source, 'package.xml')) or PACKAGE
    workspace = os.path.join(work, 'ws')
    pkg = os.path.join(workspace, 'src', name if re.match(r'^[A-Za-z][\w-]*$', name) else PACKAGE)
    unpack.copy_package(pkg_source, pkg, fixes)
    fixes.extend(source.fix_text(pkg))
    box_env = sandbox.box_env({'PATH': os.environ.get('PATH', '/usr/bin:/bin')})  # $(env) sees the box's, not ours
    analyses = [launch.analyse(path, pkg, name, box_env) for path in launch.launch_files(pkg)]
    sheet, how = detect_sheet(wanted_sheet, pkg, analyses)
    notes.insert(0, how)
    chosen = launch.choose(analyses, sheet)
    scripts = source.node_scripts(pkg)
    types, type_fixes = source.node_type_fixes(pkg, chosen.exam_nodes if chosen else [])
    fixes.extend(type_fixes)
    launched = [types.get(n.type_origin, n.type) for n in chosen.exam_nodes] if chosen \
        else [os.path.basename(p) for p in scripts[:1]]
    fixes.extend(source.make_runnable(pkg, launched))
    static = {'launch_files': [os.path.relpath(a.path, pkg) for a in analyses], 'package': name,
              'package_dir': pkg, 'python2': source.python2_evidence(pkg),
              'params_in_code': source.param_names(pkg), 'launch': None, 'threshold': None,
              'uploads': uploads}
    if static['python2']:
        notes.append('Python 2 code, which ROS Noetic cannot run: %s' % ', '.join(static['python2']))
    for analysis in analyses:
        for problem in analysis.problems:
            notes.append('launch: %s' % problem)
    threshold_value = SHEETS[sheet].threshold
    runs = []
    if chosen is not None:
        exam = chosen.exam_nodes[0]
        static['launch'] = {'file': os.path.relpath(chosen.path, pkg), 'starts_drone': chosen.starts_drone(sheet),
                            'exam_type': exam.type, 'exam_name': exam.name, 'package': name,
                            'comments': chosen.comments(), 'exam_type_found': _executable_in(pkg, exam.type)}
        param, why = launch.threshold_param(chosen, sheet)
        static['threshold_reason'] = why
        if param is not None:
            threshold_value = launch.as_number(param.value)
            static['threshold'] = {'name': param.name, 'value': param.value,
                                   'where': param.origin.describe(pkg) if param.origin else '?'}
            notes.append('threshold parameter: %s, set in %s' % (why, static['threshold']['where']))
        main_launch = launch.derive(chosen, 'main', types)
        namespace = chosen.drone_namespace(sheet)
    else:
        static['threshold_reason'] = 'no launch file starts an exam node, so no parameter'
        if not scripts:
            return sheet, static, None
        notes.append('no launch file starts an exam node: ran %s alone, without parameters'
                     % os.path.relpath(scripts[0], pkg))
        main_launch = os.path.join(pkg, '.grader-main-minimal.launch')
        with open(main_launch, 'w') as f:
            f.write('<launch><node pkg="%s" type="%s" name="exam" output="screen"/></launch>\n'
                    % (name, os.path.basename(scripts[0])))
        namespace = '/'
        param = None
    margin = margin_of(threshold_value)
    plan = {'kind': 'main', 'sheet': sheet, 'threshold': threshold_value, 'margin': margin, 'delay': DELAY,
            'start_timeout': START_TIMEOUT, 'output': SHEETS[sheet].output,
            'late_warning': LATE_WARNING_S if source.calls_a_service(pkg) else 0.0}
    runs.append({'tag': 'main', 'launch': main_launch, 'plan': plan})
    if param is not None and param.origin is not None:
        lowered = threshold_value - 2 * margin
        threshold_changes = dict(types)
        threshold_changes[param.origin] = lowered
        runs.append({'tag': 'threshold', 'launch': launch.derive(chosen, 'threshold', threshold_changes),
                     'plan': dict(plan, kind='threshold', threshold=lowered,
                                  targets={'start': lowered - margin, 'step': threshold_value - margin})})
    elif param is not None:
        static['threshold']['not_rewritable'] = 'its value comes from no literal the grader can change'
    job = {'workspace': workspace, 'namespace': namespace, 'build_timeout': BUILD_TIMEOUT,
           'run_timeout': RUN_TIMEOUT, 'runs': runs,
           'handed_in_launch': os.path.relpath(chosen.path, os.path.join(workspace, 'src')) if chosen else None}
    return sheet, static, job


def _executable_in(pkg, name):
    for dirpath, _, filenames in os.walk(pkg):
        if name in filenames and os.access(os.path.join(dirpath, name), os.X_OK):
            return True
    return False


def run_session(job, work, underlay, isolate, box, on_step=None):
    """Run the session of one submission, its student steps in ``box``; return what it measured (or
    why it could not).

    :param isolate: in a network namespace of its own with only loopback (needs root).
    :param on_step: called with each step's name as the session starts it (:mod:`~exam_lab.grader.publish.progress`).
    """
    log_dir = os.path.join(work, 'logs')
    judge_home = os.path.join(work, 'judge')
    for folder in (log_dir, judge_home):
        os.makedirs(folder, mode=0o700, exist_ok=True)
    ws = os.path.join(work, 'ws')
    runs = [dict(run, launch=os.path.join(box.workspace, os.path.relpath(run['launch'], ws)))
            for run in job['runs']]
    job = dict(job, workspace=box.workspace, runs=runs, underlay=underlay, log_dir=log_dir,
               judge_home=judge_home, box=box.describe())
    job_path = os.path.join(work, 'job.json')
    with open(job_path, 'w') as f:
        json.dump(job, f, indent=1, sort_keys=True)
    argv = [sys.executable, '-m', 'exam_lab.grader.judge.session', job_path]
    if isolate:
        argv = ['unshare', '--net', '--', 'sh', '-c', 'ip link set lo up && exec "$@"', 'sh'] + argv
    with progress.watching(log_dir, on_step), Supervisor(os.path.join(work, 'outer')) as sup:
        status, output, _ = sup.run('session', argv, timeout=SESSION_TIMEOUT, env=dict(os.environ, HOME=judge_home))
    end_pids(marked(log_dir))  # anything the session started and left, whatever happened to it
    survivors = box.end()  # the box's uid: nothing may be left once its PID namespaces are gone
    path = os.path.join(log_dir, 'session.json')
    if status == 0 and os.path.isfile(path):
        with open(path) as f:
            result = json.load(f)
        result['survivors'] = result.get('survivors', 0) + survivors
        return result
    why = 'the session did not finish within %.0f s' % SESSION_TIMEOUT if status is None else \
        'the session failed (exit %s): %s' % (status, session_tail(output))
    return {'build': None, 'runs': [], 'error': why, 'survivors': survivors}


def _share_read_only(folder):
    """Make the pristine package readable (never writable) by the box's user, which sees it read-only."""
    for dirpath, dirnames, filenames in os.walk(folder):
        os.chmod(dirpath, 0o755)
        for name in filenames:
            full = os.path.join(dirpath, name)
            if os.path.isfile(full) and not os.path.islink(full):
                os.chmod(full, 0o755 if os.stat(full).st_mode & 0o100 else 0o644)


def session_tail(output):
    return '\n'.join(output.strip().splitlines()[-10:])


def hints(static, session, notes, pkg, isolate, how_run=None):
    """The for_the_teacher list: what the machine saw but does not score."""
    out = list(notes)
    scripts = source.student_code(pkg) if pkg and os.path.isdir(pkg) else []
    if scripts:
        comments, code = source.comment_ratio(scripts)
        out.append('comments (not scored): %d comment lines for %d lines of code (%.0f %%) in %s'
                   % (comments, code, 100.0 * comments / max(code, 1),
                      ', '.join(os.path.relpath(p, pkg) for p in scripts)))
    probe = rubric.main_probe(session)
    if probe:
        for node, info in sorted(probe.get('graph', {}).items()):
            out.append('node %s: publishes %s; subscribes %s; serves %s' % (
                node, ', '.join('%s (%s)' % tuple(p) for p in info['publishes'] if p[0] != '/rosout') or 'nothing',
                ', '.join('%s (%s)' % tuple(s) for s in info['subscribes']) or 'nothing',
                ', '.join(info['services']) or 'nothing'))
        calibration = probe.get('calibration') or {}
        if calibration.get('by') == 'oracle' and calibration.get('reason'):
            out.append('Q13/Q14 flown by the oracle\'s values: %s' % calibration['reason'])
    for run in (session or {}).get('runs', []):
        odd = [l for l in run.get('launch', {}).get('tail', '').splitlines() if _ODD.search(l)]
        if odd:
            out.append('%s run, odd lines in the log: %s' % (run['tag'], ' | '.join(odd[:4])))
    if static and static.get('launch') and static['launch']['file'] and len(static.get('launch_files', [])) > 1:
        out.append('launch file graded: %s (of %s)' % (static['launch']['file'], ', '.join(static['launch_files'])))
    if (session or {}).get('build') is not None:  # something of the student's ran
        out.append('ran in a network namespace with only loopback' if isolate else
                   'ran WITHOUT network isolation (needs root and unshare): the student code could reach the network')
        out.append(how_run or 'not run')
    if (session or {}).get('survivors'):
        out.append('%d processes of the student were still alive after its steps ended: killed'
                   % session['survivors'])
    out.append('not scored by the machine: %s' % report.NOT_SCORED)
    return out


def _how_run(box):
    if box.bwrap:
        return ('ran in a bubblewrap sandbox as uid %d: its own user, PID, mount, IPC and UTS namespaces, '
                'a clean environment, only its workspace writable; limited in memory, processes, CPU time '
                'and file size' % box.uid)
    if box.slot is not None:
        return 'ran WITHOUT its sandbox (the teacher\'s flag) as uid %d, with resource limits only' % box.uid
    return ('ran WITHOUT its sandbox (the teacher\'s flag) as the grading user %s: it could read and change '
            'that user\'s files' % pwd.getpwuid(os.geteuid()).pw_name)


def _box_binds(underlay):
    """What the box sees of the grader (read-only): the underlay and the simulators' sources it links."""
    cache = os.path.dirname(os.path.dirname(underlay))
    sources = os.path.join(cache, 'src')
    return [cache] + [os.path.realpath(os.path.join(sources, name)) for name in sorted(os.listdir(sources))
                      if os.path.islink(os.path.join(sources, name))]


def _prepare_workspace(work):
    """The pristine workspace the box sees read-only: catkin's top-level CMakeLists.txt linked (catkin_make
    cannot write src/ in the box), everything readable by the box's user, nothing writable by it."""
    src = os.path.join(work, 'ws', 'src')
    top = os.path.join(src, 'CMakeLists.txt')
    if not os.path.lexists(top):
        os.symlink(os.path.join(_package_path('catkin'), 'cmake', 'toplevel.cmake'), top)
    _share_read_only(os.path.join(work, 'ws'))
    if os.path.isdir(os.path.join(work, 'unpacked')):
        os.chmod(os.path.join(work, 'unpacked'), 0o700)


def could_not_grade(student, sheet, why, notes=()):
    """The record of a submission the grader could not grade: every item 0, and why."""
    sheet = sheet or 'altitude'
    session = {'build': None, 'runs': [], 'error': 'could not grade: %s' % why}
    return report.grade_record(student, sheet, rubric.score(sheet, {}, session),
                               list(notes) + [session['error']], {'seconds': 0.0}, rubric.status({}, session))


def grade_submission(submission, out_dir, sheet=None, student=None, underlay=None, isolate=None, keep=False,
                     on_step=None, extra=None, unsandboxed=False, jobs=1):
    """Grade one submission; write grade.json and grade.md in ``out_dir``; return the record.

    :param on_step: called with each step's name as it starts (unpack, build, main flight...).
    :param extra: added to the record (:func:`exam_lab.grader.boxed.documents.submission_facts`).
    :param unsandboxed: run it even where no sandbox can be made (the teacher's flag that names the
        risk); otherwise :class:`~exam_lab.grader.host.sandbox.SandboxUnavailable` is raised there.
    :param jobs: how many submissions are graded side by side: the box's part of the CPU.
    """
    start = time.monotonic()
    student = student or unpack.student_name(os.path.basename(os.path.abspath(submission).rstrip('/')))
    refusal = sandbox_refusal(unsandboxed)
    if refusal:
        raise sandbox.SandboxUnavailable(refusal)
    isolate = can_isolate() if isolate is None else isolate
    underlay = underlay or ensure_underlay(default_underlay())  # raises: the grader cannot run
    os.makedirs(out_dir, exist_ok=True)
    # In the system's temp folder, not under OUT (which may be private): the box's user must reach
    # <work>/ws and <work>/box, and may not list <work>.
    work = tempfile.mkdtemp(prefix='exam-grade-')
    os.chmod(work, 0o711)
    notes, fixes, static, session, chosen_sheet, pkg, how_run = [], [], {}, None, sheet, None, None
    try:
        try:
            progress.report(on_step, 'unpack')
            chosen_sheet, static, job = prepare(submission, work, sheet, notes, fixes)
            pkg = static['package_dir']
            if job is None:
                session = {'build': None, 'runs': [], 'no_node': True,
                           'error': 'no script of the package starts a ROS node'}
            else:
                _prepare_workspace(work)
                with sandbox.Box(work, _box_binds(underlay), bwrap=sandbox.check() is None,
                                 cpus=sandbox.box_cpus(jobs)) as box:
                    notes.extend(box.notes)
                    how_run = _how_run(box)
                    session = run_session(job, work, underlay, isolate, box, on_step)
        except unpack.UnpackError as err:
            session = {'build': None, 'runs': [], 'refused': True, 'error': 'submission refused: %s' % err}
        except Exception as err:  # a grader bug must not stop the class: say so and carry on
            session = {'build': None, 'runs': [], 'error': 'the grader failed on this submission: %r' % err}
            notes.append('grader error, please report: %s' % traceback.format_exc().replace('\n', ' | '))
        chosen_sheet = chosen_sheet or 'altitude'
        items = rubric.score(chosen_sheet, static, session)
        logs = os.path.join(out_dir, 'logs')
        shutil.rmtree(logs, ignore_errors=True)
        if os.path.isdir(os.path.join(work, 'logs')):
            skipped = sandbox.copy_results(os.path.join(work, 'logs'), logs)
            if skipped:
                notes.append('not copied to logs/ (not a regular file): %s' % ', '.join(skipped))
        record = report.grade_record(student, chosen_sheet, items,
                                     hints(static, session, notes + fixes, pkg, isolate, how_run),
                                     dict(extra or {}, seconds=round(time.monotonic() - start, 1),
                                          doubts=rubric.doubts(static, session)),
                                     rubric.status(static, session, fixes))
        report.write_grade(out_dir, record)
        return record
    finally:
        if not keep:
            shutil.rmtree(work, ignore_errors=True)


def class_similarity(klass, out, records):
    """The similarity check over a class's submissions (unpacked anew, as the runner did), each
    named as its grade record names it; ``{"error"}`` when it could not run (the grades stand)."""
    scratch = os.path.join(out, '.similarity-class')
    try:
        by_folder = {r.get('folder'): r['student'] for r in records}
        submissions = [(by_folder.get(os.path.basename(folder), name), folder)
                       for name, folder in unpack.list_students(klass, scratch)]
        return similarity.check(submissions, out)
    except Exception as err:  # a bug of the check must not cost the class its page
        return {'error': repr(err)}
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


def default_underlay():
    return os.path.join(workspace(), 'grader', 'underlay')


def class_students(class_path, scratch):
    """``[(name, folder or archive)]`` of a class, each name unique (``Jane Doe``, ``Jane Doe_2``): the
    students both engines grade (:func:`grade_class`, :mod:`exam_lab.grader.engine.slurm`). A class
    archive is unpacked below ``scratch``."""
    names, seen = [], set()
    for name, folder in unpack.list_students(class_path, scratch):
        unique, n = name, 2
        while unique in seen:
            unique, n = '%s_%d' % (name, n), n + 1
        seen.add(unique)
        names.append((unique, folder))
    return names


def grade_student(name, folder, out_dir, sheet=None, underlay=None, isolate=None, on_step=None,
                  unsandboxed=False, jobs=1):
    """Grade one student of a class into ``out_dir/name``; return the record. Anything the grader
    raises is this student's record ("could not grade"), never the class's. Both engines grade a
    student with it: a local pool's thread and a Slurm task."""
    try:
        return grade_submission(folder, os.path.join(out_dir, name), sheet, name, underlay, isolate,
                                on_step=on_step, extra=documents.submission_facts(folder), unsandboxed=unsandboxed,
                                jobs=jobs)
    except Exception as err:  # anything: this student's row says so, the class goes on
        record = could_not_grade(name, sheet, '%r' % err,
                                 ['grader error, please report: %s' % traceback.format_exc().replace('\n', ' | ')])
        try:
            report.write_grade(os.path.join(out_dir, name), record)
        except OSError:
            pass
        return record


def grade_class(class_path, out_dir, sheet=None, jobs=2, isolate=None, progress=None, unsandboxed=False):
    """Grade every student of a class, ``jobs`` side by side; write each one's grade and grades.csv.
    One student the grader cannot grade is that student's row ("could not grade"), never the class's.

    :param progress: told of the run as it goes (:class:`exam_lab.grader.publish.progress.ClassProgress`).
    """
    refusal = sandbox_refusal(unsandboxed)
    if refusal:
        raise sandbox.SandboxUnavailable(refusal)
    os.makedirs(out_dir, exist_ok=True)
    scratch = tempfile.mkdtemp(prefix='class-', dir=out_dir)
    try:
        students = class_students(class_path, scratch)
        underlay = ensure_underlay(default_underlay())
        isolate = can_isolate() if isolate is None else isolate
        records = [None] * len(students)
        if progress:
            progress.begin([name for name, _ in students])

        def one(index):
            name, folder = students[index]
            if progress:
                progress.started(name)
            record = grade_student(name, folder, out_dir, sheet, underlay, isolate,
                                   (lambda step: progress.step(name, step)) if progress else None, unsandboxed,
                                   jobs=jobs)
            if progress:
                progress.finished(record)
            return record

        with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
            for index, record in zip(range(len(students)), pool.map(one, range(len(students)))):
                records[index] = record
        report.write_csv(os.path.join(out_dir, 'grades.csv'), records)
        return records
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
