"""Grading a submission or a class: inspect (boxed), run the session (sandboxed), score, write.

Root never parses a student's bytes. It stages the upload byte for byte (regular files, folders, links
as links: :func:`~exam_lab.grader.host.staging.stage_upload`), opens the submission's
:class:`~exam_lab.grader.host.sandbox.Box`, and runs :mod:`~exam_lab.grader.boxed.inspect` in it, as the
box's uid, without network, within INSPECT_BOUNDS: unpacking, the package copied into the workspace,
the teacher's fixes, launch and YAML analysis, the derived launch files (at the paths the run box sees),
the source scan, PDF facts and comment statistics. Root reads back one capped, schema-checked record
(:mod:`~exam_lab.grader.host.egress`, :mod:`~exam_lab.grader.score.records`) and plans the runs from it;
the workspace stays the box uid's, read-only in the build and run box. A class archive is unpacked by
:mod:`~exam_lab.grader.boxed.intake`, the similarity check runs in a box too. Then
:mod:`exam_lab.grader.host.session` runs in a network namespace with only loopback
(:func:`~exam_lab.grader.host.bwrap.network_namespace`: ``unshare --net`` as root, a user namespace of
its own too otherwise), under a :class:`~exam_lab.harness.supervisor.Supervisor` with an overall time
limit;
:mod:`~exam_lab.grader.score.rubric` scores and :mod:`~exam_lab.grader.publish.report` writes; what reaches
the results from the session's folder is copied as data (regular files only, each capped:
:func:`~exam_lab.grader.host.egress.copy_results`).

The simulators (``node_kit``, ``drone_sim``, ``mydrone``, ``submarinedrone``) are built once as an underlay
workspace (cached under ``$EXAM_WS/grader/underlay``, rebuilt when their sources change); each student's
package is built alone in an overlay of its own on top of it, so a student's ``exam`` never meets ours.
"""
import concurrent.futures
import fcntl
import hashlib
import json
import os
import pwd
import random
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import traceback

from exam_lab.grader import workspace
from exam_lab.grader.boxed import archives, classlist, similarity

from exam_lab.grader.host import bwrap, egress, limits, sandbox, staging
from exam_lab.grader.host.session import budget_sentence
from exam_lab.grader.score.boxenv import BOX_WS

from exam_lab.grader.score import identity, records, rubric

from exam_lab.grader.publish import progress, provenance, report
from exam_lab.grader.score.sheets import DELAY, LATE_WARNING_S, SHEETS, margin_of
from exam_lab.harness.supervisor import WORKSPACE_VARS, Supervisor, end_pids, marked

#: Time limits, s: the student's catkin_make, the node's start (to registering with the master),
#: the probe of one run (a late WARNING is waited for up to LATE_WARNING_S).
BUILD_TIMEOUT = 180.0
START_TIMEOUT = 20.0
RUN_TIMEOUT = 90.0 + LATE_WARNING_S
#: One student's whole grading, s: staging, inspection, roslaunch's check, build and runs together;
#: every step's limit (above, INSPECT_BOUNDS) is also bounded by what is left of it. A usual grading
#: takes about 45 s, the slowest honest one measured (a WARNING 50 s late) 134 s: docs/grading.md, "Speed".
STUDENT_BUDGET = 280.0
#: What a grading may take past its budget: the session's kill if it overran (SESSION_KILL_S), ending
#: the box, copying the logs and scoring. STUDENT_BUDGET + AFTER_BUDGET_S is a student's worst case
#: (:func:`worst_case`).
AFTER_BUDGET_S = 20.0
SESSION_KILL_S = 5.0
#: The simulator packages of the underlay.
SIMULATORS = ('node_kit', 'drone_sim', 'mydrone', 'submarinedrone')
#: Bounds of the boxes that read student bytes: (wall clock s, CPU s, address space bytes). One upload's
#: inspection (measured: 0.2 s a package, box included); a class archive's intake; the class's similarity check.
INSPECT_BOUNDS = (60.0, 60, 1 << 30)
INTAKE_BOUNDS = (300.0, 300, 1 << 30)
SIMILARITY_BOUNDS = (900.0, 300, 3 << 30)

#: Log lines worth the teacher's eye: warnings, errors, tracebacks.
_ODD = re.compile(r'\[(WARN|ERROR|FATAL)\]|Traceback|Error\b|Exception\b')

_isolation = {}
_isolation_lock = threading.Lock()
_underlay_lock = threading.Lock()


def can_isolate():
    """True when this process may run a session in a network namespace of its own (as root with
    unshare, otherwise with bubblewrap where ordinary users may make user namespaces)."""
    with _isolation_lock:
        return _can_isolate()


def _can_isolate():
    if 'ok' not in _isolation:
        try:
            _isolation['ok'] = subprocess.run(bwrap.network_namespace(['true']), stdout=subprocess.DEVNULL,
                                              stderr=subprocess.DEVNULL, timeout=10).returncode == 0
        except (OSError, subprocess.SubprocessError):
            _isolation['ok'] = False
    return _isolation['ok']


def sandbox_refusal(unsandboxed=False):
    """None when student code may run here: boxes can be made, or the teacher passed the flag that
    names the risk (``unsandboxed``); otherwise the refusal, for the teacher."""
    why = sandbox.check()
    if why is None or unsandboxed:
        return None
    return ('refusing to run student code without its sandbox: %s. Run the grader on a machine with '
            'bubblewrap and unprivileged user namespaces, as root or as yourself (docs/grading.md, '
            '"Isolation" and "Without root"), or pass --unsandboxed-student-code-can-read-and-damage-my-files '
            'to accept that risk' % why)


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


class InspectionFailed(Exception):
    """The inspection of an upload crashed, overran its bounds or handed back no valid record."""


def _grader_source():
    """The folder that holds the grader's own Python package (``exam_lab``), which a box sees read-only."""
    import exam_lab.grader
    return os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(exam_lab.grader.__file__))))


class Boxed(object):
    """One of the grader's own modules run on student bytes in ``box``, as its uid, without network:
    ``<work>/upload`` (staged by root, :func:`~exam_lab.grader.host.staging.stage_upload`) read-only at
    ``/box/upload``, ``<work>/out`` writable at ``/box/out``, the grader's source read-only; its one
    record is read back through :func:`~exam_lab.grader.host.egress.read_record`. Unsandboxed, the same
    folders are used at their host paths.

    :param mounts: more ``(host, in the box, writable)``; ``(host, None, ...)`` keeps the host path.
    """

    def __init__(self, box, work, mounts=()):
        self.box, self.work = box, work
        self.out = os.path.join(work, 'out')
        os.mkdir(self.out, 0o700)
        if box.slot is not None:
            os.chown(self.out, box.uid, box.uid)
        self.source = _grader_source()
        self.places = [(os.path.join(work, 'upload'), '/box/upload', False), (self.out, '/box/out', True),
                       (self.source, self.source, False)] + [(h, b or h, w) for h, b, w in mounts]

    def path(self, host):
        """``host`` (below one of the mounted folders) as the box's process sees it."""
        if not self.box.bwrap:
            return host
        for outside, inside, _ in self.places:
            if host == outside or host.startswith(outside + '/'):
                return inside + host[len(outside):]
        raise ValueError('%s is not visible in the box' % host)

    def run(self, module, args, record, bounds, python=sys.executable):
        """Run ``python -m module args`` bounded by ``bounds`` (wall clock s, CPU s, address space
        bytes); return the checked record ``record`` (a type of :mod:`~exam_lab.grader.score.records`)
        it wrote as ``/box/out/<record.FILE>``.

        :raises InspectionFailed: with the reason and the end of its log.
        """
        timeout, cpu, memory = bounds
        # Only lowered: a box's process cannot raise its hard limits (sandbox.Box.argv's prlimit).
        cpu, memory = min(cpu, limits.CPU_SECONDS), min(memory, limits.ADDRESS_SPACE_BYTES)
        command = ['prlimit', '--as=%d' % memory, '--cpu=%d' % cpu, '--', python, '-m', module] + list(args)
        env = {'PATH': '/usr/bin:/bin', 'PYTHONPATH': self.source, 'PYTHONDONTWRITEBYTECODE': '1'}
        log = os.path.join(self.work, '%s.log' % module.rsplit('.', 1)[-1])
        status, why = self.box.run(command, env, log, timeout, cwd=self.path(self.out),
                                   mounts=self.places if self.box.bwrap else None, network=False)
        if status == 0:
            try:
                return egress.read_record(os.path.join(self.out, record.FILE), record, record.MAX_BYTES)
            except records.RecordError as err:
                why = 'its record was refused: %s' % err
        elif why is None:  # bwrap reports its child's death by signal N as exit 128 + N
            signum = -status if status < 0 else status - 128 if status > 128 else None
            why = 'it failed (exit %d)' % status if signum is None else \
                'it was killed by signal %d (its bounds: %d s of CPU, %d MB of address space)' % (signum, cpu, memory >> 20)
        tail = session_tail(egress.read_capped(log, 4096) or '')
        raise InspectionFailed('%s%s' % (why, ': %s' % tail if tail else ''))


def inspect(box, work, upload, wanted_sheet, timeout=None):
    """Run :mod:`exam_lab.grader.boxed.inspect` on the staged ``upload`` (a path below ``<work>/upload``)
    in ``box`` (:class:`Boxed`), bounded by INSPECT_BOUNDS (its wall clock by ``timeout`` if less); return its checked
    :class:`~exam_lab.grader.score.records.InspectRecord`. The package is written, as the box's uid, to
    the workspace the build box sees: ``<work>/ws/src`` (read-only there), or unsandboxed the box's
    own copy.

    :raises InspectionFailed: with the reason and the end of its log.
    """
    if box.bwrap:
        os.chown(os.path.join(work, 'ws', 'src'), box.uid, box.uid)
        boxed = Boxed(box, work, [(os.path.join(work, 'ws'), BOX_WS, True)])
        ws = BOX_WS
    else:
        boxed, ws = Boxed(box, work), box.workspace
    # Where the threshold run's value lies in its range, drawn now, by the grader (issue 36 point 7).
    args = ['--upload', boxed.path(upload), '--ws', ws, '--out', boxed.path(boxed.out),
            '--toplevel', os.path.join(_package_path('catkin'), 'cmake', 'toplevel.cmake'),
            '--draw', repr(random.SystemRandom().random())]
    return boxed.run('exam_lab.grader.boxed.inspect', args + (['--sheet', wanted_sheet] if wanted_sheet else []),
                     records.InspectRecord, (min(INSPECT_BOUNDS[0], timeout or INSPECT_BOUNDS[0]),) + INSPECT_BOUNDS[1:])


def plan_job(record):
    """The session's job (:mod:`exam_lab.grader.host.session`) from a checked inspection record: the
    runs' plans are computed here, from its numbers; the launch files stay relative to the workspace.
    None when there is nothing to run."""
    if record.main_launch is None:
        return None
    sheet, threshold = record.sheet, record.threshold_value
    margin = margin_of(threshold)
    plan = {'kind': 'main', 'sheet': sheet, 'threshold': threshold, 'margin': margin, 'delay': DELAY,
            'start_timeout': START_TIMEOUT, 'output': SHEETS[sheet].output,
            'late_warning': LATE_WARNING_S if record.calls_service else 0.0}
    runs = [{'tag': 'main', 'launch': record.main_launch, 'plan': plan}]
    if record.threshold_launch is not None:
        # The value the inspection wrote into the derived launch file (drawn at grading time,
        # sheets.threshold_run_value), flown as the main run around it, with the main run's margin.
        runs.append({'tag': 'threshold', 'launch': record.threshold_launch,
                     'plan': dict(plan, kind='threshold', threshold=record.threshold_run_value)})
    return {'namespace': record.namespace, 'build_timeout': BUILD_TIMEOUT, 'run_timeout': RUN_TIMEOUT, 'runs': runs,
            'handed_in_launch': record.handed_in_launch}


def worst_case(students, jobs):
    """Seconds a class of ``students`` takes at most, ``jobs`` side by side, when every grading uses
    its whole budget: ceil(students / jobs) gradings one after the other, each STUDENT_BUDGET +
    AFTER_BUDGET_S (the class's own steps, its intake and similarity check, aside: INTAKE_BOUNDS,
    SIMILARITY_BOUNDS)."""
    return -(-students // max(1, jobs)) * (STUDENT_BUDGET + AFTER_BUDGET_S)


def run_session(job, work, underlay, isolate, box, on_step=None, left=STUDENT_BUDGET):
    """Run the session of one submission, its student steps in ``box``; return what it measured (or
    why it could not).

    :param left: seconds left of the student's budget: the session's own (it stops its steps in time),
        and killed SESSION_KILL_S after.

    :param isolate: in a network namespace of its own with only loopback
        (:func:`~exam_lab.grader.host.bwrap.network_namespace`).
    :param on_step: called with each step's name as the session starts it (:mod:`~exam_lab.grader.publish.progress`).
    """
    log_dir = os.path.join(work, 'logs')
    judge_home = os.path.join(work, 'judge')
    for folder in (log_dir, judge_home):
        os.makedirs(folder, mode=0o700, exist_ok=True)
    runs = [dict(run, launch=os.path.join(box.workspace, run['launch'])) for run in job['runs']]
    job = dict(job, workspace=box.workspace, runs=runs, underlay=underlay, log_dir=log_dir,
               judge_home=judge_home, box=box.describe(), budget=left, student_budget=STUDENT_BUDGET)
    job_path = os.path.join(work, 'job.json')
    with open(job_path, 'w') as f:
        json.dump(job, f, indent=1, sort_keys=True)
    argv = [sys.executable, '-m', 'exam_lab.grader.host.session', job_path]
    if isolate:
        argv = bwrap.network_namespace(argv)
    with progress.watching(log_dir, on_step), Supervisor(os.path.join(work, 'outer')) as sup:
        status, output, _ = sup.run('session', argv, timeout=left + SESSION_KILL_S, env=dict(os.environ, HOME=judge_home))
    end_pids(marked(log_dir))  # anything the session started and left, whatever happened to it
    survivors = box.end()  # the box's uid: nothing may be left once its PID namespaces are gone
    return session_outcome(log_dir, status, output, left, survivors)


def session_outcome(log_dir, status, output, left, survivors):
    """The session's record (a :class:`~exam_lab.grader.score.records.SessionRecord`'s value): the one
    it wrote in ``log_dir`` when it ended well (``status`` 0), read through
    :func:`~exam_lab.grader.host.egress.read_record` (capped, checked), else why there is none;
    ``survivors`` (processes of the box's uid found after it) added to its count."""
    if status == 0:
        try:
            result = egress.read_record(os.path.join(log_dir, records.SessionRecord.FILE), records.SessionRecord,
                                        records.SessionRecord.MAX_BYTES).value
        except records.RecordError as err:
            return no_session('session_failed', 'the session\'s record was refused: %s' % err, survivors=survivors)
        result['survivors'] = result.get('survivors', 0) + survivors
        return result
    if status is None:
        why = budget_sentence(STUDENT_BUDGET, 'the session was killed after %.0f s' % (left + SESSION_KILL_S))
        return no_session('session_killed', why, budget_used=why, survivors=survivors)
    return no_session('session_failed', 'the session failed (exit %s): %s' % (status, session_tail(output)),
                      survivors=survivors)


def no_session(outcome, error, **more):
    """The session's record (:class:`~exam_lab.grader.score.records.SessionRecord`'s value) of a grading
    whose session did not run or failed: its ``outcome`` (one of
    :data:`~exam_lab.grader.score.records.OUTCOMES`), ``error`` (why, for the teacher) and ``more``
    (``refused``, ``no_node``, ``budget_used``, ``survivors``)."""
    return records.SessionRecord.make(dict(more, outcome=outcome, build=None, runs=[],
                                           error=error[:records.MAX_LOG_TEXT])).value


def session_tail(output):
    return '\n'.join(output.strip().splitlines()[-10:])


def hints(static, session, notes, comments, isolate, how_run=None):
    """The for_the_teacher list: what the machine saw but does not score.

    :param comments: the inspection's comment statistics (``{"comments", "code", "files"}``) or None.
    """
    out = list(notes)
    if comments:
        out.append('comments (not scored): %d comment lines for %d lines of code (%.0f %%) in %s'
                   % (comments['comments'], comments['code'], 100.0 * comments['comments'] / max(comments['code'], 1),
                      ', '.join(comments['files'])))
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
                   'ran WITHOUT network isolation (no network namespace could be made): the student code could '
                   'reach the network')
        out.append(how_run or 'not run')
    if (session or {}).get('budget_used'):
        out.append(session['budget_used'])
    if (session or {}).get('survivors'):
        out.append('%d processes of the student were still alive after its steps ended: killed'
                   % session['survivors'])
    out.append('not scored by the machine: %s' % report.NOT_SCORED)
    return out


def _how_run(box):
    if box.rootless:
        return ('ran in a bubblewrap sandbox WITHOUT ROOT, as the grading user (uid %d): its own user, PID, '
                'mount, IPC and UTS namespaces, a clean environment, only its workspace writable, none of '
                'that user\'s files visible; limited per process in memory, CPU time and file size. Unlike '
                'a box made by root: no uid of its own (boxes told apart by their PID namespaces and mounts), '
                '%s, no size limit on its work folder (docs/grading.md, "Without root")'
                % (box.uid, 'a cgroup delegated to the user' if box.cgroups else
                   'no memory or process cgroup (processes counted in the session\'s user namespace)'))
    if box.bwrap:
        return ('ran in a bubblewrap sandbox as uid %d: its own user, PID, mount, IPC and UTS namespaces, '
                'a clean environment, only its workspace writable; limited in memory, processes, CPU time '
                'and file size%s; the master and the probe ran as the judge\'s uid %d, not root'
                % (box.uid, ', %g core(s) of CPU' % box.cpus if box.cpus and box.cgroups else '', box.judge_uid))
    if box.slot is not None:
        return 'ran WITHOUT its sandbox (the teacher\'s flag) as uid %d, with resource limits only' % box.uid
    try:
        user = pwd.getpwuid(os.geteuid()).pw_name
    except KeyError:  # a uid without an account (a container's, a test's)
        user = 'uid %d' % os.geteuid()
    return ('ran WITHOUT its sandbox (the teacher\'s flag) as the grading user %s: it could read and change '
            'that user\'s files' % user)


def _how_read(box, uid):
    """What read the upload, as which uid (the one the inspection saw itself run as), within which bounds."""
    timeout, _, memory = INSPECT_BOUNDS
    where = 'in a bubblewrap box without network' if box.bwrap else \
        'WITHOUT its sandbox (the teacher\'s flag), in a subprocess'
    return ('the upload was read (unpacked, its launch files, code and PDFs analysed) %s as uid %d, within %.0f s '
            'and %d MB' % (where, uid, timeout, memory >> 20))


def _box_binds(underlay):
    """What the box sees of the grader (read-only): the underlay and the simulators' sources it links."""
    cache = os.path.dirname(os.path.dirname(underlay))
    sources = os.path.join(cache, 'src')
    return [cache] + [os.path.realpath(os.path.join(sources, name)) for name in sorted(os.listdir(sources))
                      if os.path.islink(os.path.join(sources, name))]


#: What a run measured, kept beside grade.json: all the rubric reads, so a grade can be made again
#: from it with today's rubric (:func:`rescore`) without running the package again.
MEASUREMENTS = records.MEASUREMENTS


def score(measured, how='run'):
    """The grade record of one submission from what its run measured (:data:`MEASUREMENTS`): the one
    place the rubric is applied, by a run and by a rescore alike. ``how`` goes into its provenance."""
    static, session = measured['static'], measured['session']
    run_value = rubric.threshold_run_value(static, session)
    extra = dict(measured['extra'], doubts=rubric.doubts(static, session), provenance=provenance.stamp(how),
                 threshold_run={'value': run_value} if run_value is not None else None)
    return report.grade_record(measured['student'], measured['sheet'], rubric.score(measured['sheet'], static, session),
                               hints(static, session, measured['notes'] + measured['fixes'], measured['comments'],
                                     measured['isolate'], measured['how_run']),
                               extra, rubric.status(static, session, measured['fixes']))


def graded_folders(out):
    """The folders of a run's OUT holding a grade made from measurements: OUT itself for one
    submission, else one per student (in the order of their names)."""
    if os.path.isfile(os.path.join(out, MEASUREMENTS)):
        return [out]
    return sorted(os.path.join(out, name) for name in os.listdir(out)
                  if os.path.isfile(os.path.join(out, name, MEASUREMENTS)))


def rescore(out):
    """Apply today's rubric to the measurements a run kept in ``out``: no ROS, no box, seconds for a
    class. Each grade.json/grade.md is written again, with the points it had (``previous``); a class's
    grades.csv too.

    :returns: ``(records, changes)``; ``changes``: one line per student whose points or status moved,
        saying which items moved and from what to what.
    """
    records, changes = [], []
    folders = graded_folders(out)
    for folder in folders:
        with open(os.path.join(folder, MEASUREMENTS)) as f:
            measured = json.load(f)
        old = {}
        if os.path.isfile(os.path.join(folder, 'grade.json')):
            with open(os.path.join(folder, 'grade.json')) as f:
                old = json.load(f)
        record = score(measured, how='rescore')
        before = {i['id']: i['points'] for i in old.get('items', [])}
        record['previous'] = {'total': old.get('total'), 'status': old.get('status'), 'items': before,
                              'provenance': old.get('provenance')}
        moved = ['%s %s -> %s' % (i['id'], report.points_text(before.get(i['id'])), report.points_text(i['points']))
                 for i in record['items'] if before.get(i['id']) != i['points']]
        if old.get('status') != record['status']:
            moved.append('status %s -> %s' % (old.get('status'), record['status']))
        if moved:
            changes.append('%s: %s -> %s (%s)' % (record['student'], report.points_text(old.get('total')),
                                                 report.points_text(record['total']), '; '.join(moved)))
        report.write_grade(folder, record)
        records.append(record)
    if folders and folders != [out]:
        report.write_csv(os.path.join(out, 'grades.csv'), records)
    return records, changes


def could_not_grade(student, sheet, why, notes=()):
    """The record of a submission the grader could not grade: every item 0, and why."""
    sheet = sheet or 'altitude'
    session = no_session('grader_failed', 'could not grade: %s' % why)
    return report.grade_record(student, sheet, rubric.score(sheet, {}, session),
                               list(notes) + [session['error']], {'seconds': 0.0, 'provenance': provenance.stamp()},
                               rubric.status({}, session))


def grade_submission(submission, out_dir, sheet=None, student=None, underlay=None, isolate=None, keep=False,
                     on_step=None, extra=None, unsandboxed=False, jobs=1):
    """Grade one submission; write grade.json and grade.md in ``out_dir``; return the record.

    :param on_step: called with each step's name as it starts (unpack, build, main flight...).
    :param extra: added to the record, over the inspection's facts (participant, folder, documents).
    :param unsandboxed: run it even where no sandbox can be made (the teacher's flag that names the
        risk); otherwise :class:`~exam_lab.grader.host.sandbox.SandboxUnavailable` is raised there.
    :param jobs: how many submissions are graded side by side: the box's part of the CPU.
    """
    start = time.monotonic()
    student = student or identity.student_name(os.path.basename(os.path.abspath(submission).rstrip('/')))
    refusal = sandbox_refusal(unsandboxed)
    if refusal:
        raise sandbox.SandboxUnavailable(refusal)
    isolate = can_isolate() if isolate is None else isolate
    underlay = underlay or ensure_underlay(default_underlay())  # raises: the grader cannot run
    os.makedirs(out_dir, exist_ok=True)
    deadline = time.monotonic() + STUDENT_BUDGET  # the student's own time starts here, the simulators built
    # In the system's temp folder, not under OUT (which may be private): the box's user must reach
    # <work>/upload, <work>/ws and <work>/box, and may not list <work>.
    work = tempfile.mkdtemp(prefix='exam-grade-')
    os.chmod(work, 0o711)
    folder = os.path.basename(os.path.abspath(submission).rstrip('/'))
    notes, fixes, static, session, chosen_sheet, comments, how_run = [], [], {}, None, sheet, None, None
    facts = {'participant': identity.participant_number(folder), 'folder': folder, 'documents': []}
    try:
        try:
            progress.report(on_step, 'unpack')
            upload = os.path.join(work, 'upload', folder if folder not in ('', '.', '..') else 'upload')
            os.mkdir(os.path.dirname(upload), 0o755)
            staging.stage_upload(os.path.realpath(submission), upload)  # the teacher's path: followed
            for sub in ('ws', 'ws/src'):
                os.mkdir(os.path.join(work, sub), 0o755)
            with sandbox.Box(work, _box_binds(underlay), bwrap=sandbox.check() is None,
                             cpus=limits.box_cpus(jobs)) as box:
                notes.extend(box.notes)
                found = inspect(box, work, upload, sheet, timeout=deadline - time.monotonic())
                notes.append(_how_read(box, found.uid))
                notes.extend(found.notes)
                fixes.extend(found.fixes)
                facts, comments = found.facts, found.comments
                if found.refused is not None:
                    raise archives.UnpackError(found.refused)
                chosen_sheet, static = found.sheet, found.static
                job = plan_job(found)
                if job is None:
                    session = no_session('no_node', 'no script of the package starts a ROS node', no_node=True)
                elif deadline - time.monotonic() < START_TIMEOUT:
                    why = budget_sentence(STUDENT_BUDGET, 'nothing was run (%.0f s left after the inspection)'
                                          % (deadline - time.monotonic()))
                    session = no_session('not_run', why, budget_used=why)
                else:
                    how_run = _how_run(box)
                    session = run_session(job, work, underlay, isolate, box, on_step,
                                          left=deadline - time.monotonic())
        except (archives.UnpackError, staging.UploadRefused) as err:
            session = no_session('refused', 'submission refused: %s' % err, refused=True)
        except InspectionFailed as err:
            session = no_session('inspection_failed', 'the inspection of the upload failed: %s' % err)
        except Exception as err:  # a grader bug must not stop the class: say so and carry on
            session = no_session('grader_failed', 'the grader failed on this submission: %r' % err)
            notes.append('grader error, please report: %s' % traceback.format_exc().replace('\n', ' | '))
        logs = os.path.join(out_dir, 'logs')
        shutil.rmtree(logs, ignore_errors=True)
        if os.path.isdir(os.path.join(work, 'logs')):
            skipped = egress.copy_results(os.path.join(work, 'logs'), logs)
            if skipped:
                notes.append('not copied to logs/ (not a regular file): %s' % ', '.join(skipped))
        measured = {'student': student, 'sheet': chosen_sheet or 'altitude', 'static': static, 'session': session,
                    'notes': notes, 'fixes': fixes, 'comments': comments, 'isolate': isolate, 'how_run': how_run,
                    'extra': dict(facts, **dict(extra or {}, seconds=round(time.monotonic() - start, 1)))}
        with open(os.path.join(out_dir, MEASUREMENTS), 'w') as f:
            json.dump(measured, f, indent=1, sort_keys=True)
        record = score(measured)
        report.write_grade(out_dir, record)
        return record
    finally:
        if not keep:
            shutil.rmtree(work, ignore_errors=True)  # never follows a link the box left (rmtree does not)


def _staged_work(prefix, sources, parent=None, bounds=None, refused=None):
    """A work folder for a box (in ``parent``, by default the system's temp folder: the box's user must
    reach it), with each ``(name, path)`` of ``sources`` staged read-only as
    ``<work>/upload/<index>/<name>``, within ``bounds`` (``(bytes, files)``; one upload's when None);
    returns ``(work, [staged paths])``. With ``refused`` (a dict), a source over its bounds is not
    staged (None in its place) and ``refused`` receives ``{its path: why}``; otherwise it raises
    :class:`~exam_lab.grader.host.staging.UploadRefused`."""
    work = tempfile.mkdtemp(prefix=prefix, dir=parent)
    os.chmod(work, 0o711)
    staged = []
    for sub in ('upload', 'ws', 'ws/src'):
        os.mkdir(os.path.join(work, sub), 0o755)
    for index, (name, path) in enumerate(sources):
        os.mkdir(os.path.join(work, 'upload', str(index)), 0o755)
        staged.append(os.path.join(work, 'upload', str(index), name if name not in ('', '.', '..') else 'upload'))
        try:
            staging.stage_upload(path, staged[-1], *(bounds or ()))
        except staging.UploadRefused as err:
            if refused is None:
                raise
            refused[path] = str(err)
            shutil.rmtree(os.path.dirname(staged[-1]), ignore_errors=True)
            staged[-1] = None
    return work, staged


def class_students(class_path, work_dirs, scratch=None, refused=None, out=None):
    """``[(student, folder or archive)]`` of a class, each name unique (``Jane Doe``, ``Jane Doe_2``):
    the students both engines grade (:func:`grade_class`, :mod:`exam_lab.grader.engine.slurm`); with
    ``out``, the folder of an earlier run of the class, each student keeps the name (the folder in OUT)
    that run gave its participant number (:func:`kept_folders`). A
    folder is listed by root, by its entries' names only (:func:`~exam_lab.grader.boxed.classlist.list_students`
    opens no file of a folder); an archive is unpacked by :mod:`exam_lab.grader.boxed.intake` in a box of
    its own (INTAKE_BOUNDS), in a work folder made in ``scratch`` (default: the system's temp folder) and
    appended to ``work_dirs`` (the caller removes it once the students are graded). ``refused`` (a
    dict) receives ``{folder: why}`` of the students whose files the intake refused by their own
    bounds (:func:`grade_student`'s ``refused``).

    :raises archives.UnpackError: the archive could not be unpacked (why, and the end of the box's log).
    """
    class_path = os.path.abspath(class_path)
    if not os.path.isfile(class_path):
        return _unique(classlist.list_students(class_path, None), kept_folders(out))
    if scratch:
        os.makedirs(scratch, mode=0o711, exist_ok=True)
    # One file, bounded as a class (a class of 60 with its PDFs is more than one upload may be).
    work, (staged,) = _staged_work('exam-intake-', [(os.path.basename(class_path), class_path)], scratch,
                                   (classlist.CLASS_BYTES, 1))
    work_dirs.append(work)
    with sandbox.Box(work, bwrap=sandbox.check() is None) as box:
        boxed = Boxed(box, work)
        try:
            found = boxed.run('exam_lab.grader.boxed.intake', ['--class', boxed.path(staged), '--out',
                                                                 boxed.path(boxed.out)], records.IntakeRecord,
                              INTAKE_BOUNDS)
        except InspectionFailed as err:
            raise archives.UnpackError('unpacking it in its box failed: %s' % err)
    students = []
    for student in found.students:
        path = os.path.join(boxed.out, student['path'])
        if os.path.realpath(path) != os.path.normpath(path) or not os.path.lexists(path):
            raise archives.UnpackError('the intake named %s, which is a link or missing' % student['path'])
        if student.get('refused') is not None and refused is not None:
            refused[path] = student['refused']
        students.append((student['name'], path))
    return _unique(students, kept_folders(out))


def kept_folders(out):
    """``{participant number: folder name}`` of the students an earlier run graded into ``out`` (from
    each folder's measurements.json, else its grade.json; written by the grader, never by a box)."""
    kept = {}
    if not out or not os.path.isdir(out):
        return kept
    for name in sorted(os.listdir(out)):
        for kept_file in (MEASUREMENTS, 'grade.json'):
            path = os.path.join(out, name, kept_file)
            if not os.path.isfile(path):
                continue
            try:
                with open(path) as f:
                    facts = json.load(f)
            except (OSError, ValueError):
                continue
            facts = facts.get('extra', {}) if kept_file == MEASUREMENTS else facts
            number = facts.get('participant')
            if number is None:
                number = identity.participant_number(str(facts.get('folder') or ''))
            if isinstance(number, int):
                kept.setdefault(number, name)
            break
    return kept


def _unique(students, kept=None):
    """Each student's name made unique (``Jane Doe``, ``Jane Doe_2``): it is the student's folder in
    OUT, which never ends like one of the class's files (:func:`~exam_lab.grader.score.identity.student_name`).
    A participant that ``kept`` (:func:`kept_folders`) gives a folder keeps it, and no other
    student takes a folder of OUT that is a participant's: a classmate whose name cleans to the same
    (``Jane Doe.``) submitting late never takes the first one's folder, its kept measurements or its
    row (the rows of hand.csv and the worksheet are keyed by the number anyway)."""
    kept = kept or {}
    held = set(kept.values())
    named, seen = [None] * len(students), set()
    for index, (name, folder) in enumerate(students):
        previous = kept.get(identity.participant_number(os.path.basename(folder.rstrip('/'))))
        if previous is not None and previous not in seen and \
                (previous == name or re.match(r'^%s_\d+$' % re.escape(name), previous)):
            named[index] = previous
            seen.add(previous)
    for index, (name, _) in enumerate(students):
        if named[index] is None:
            unique, n = name, 2
            while unique in seen or unique in held:
                unique, n = '%s_%d' % (name, n), n + 1
            named[index] = unique
            seen.add(unique)
    return [(named[index], folder) for index, (_, folder) in enumerate(students)]


def grade_student(name, folder, out_dir, sheet=None, underlay=None, isolate=None, on_step=None,
                  unsandboxed=False, jobs=1, refused=None):
    """Grade one student of a class into ``out_dir/name``; return the record. Anything the grader
    raises is this student's record ("could not grade"), never the class's. Both engines grade a
    student with it: a local pool's thread and a Slurm task.

    :param refused: why the class's intake did not unpack this student's files (its own bounds): the
        student is not graded, with that sentence, and its measurements are kept for a rescore.
    """
    if refused is not None:
        return _refused_at_intake(name, folder, os.path.join(out_dir, name), sheet, refused)
    try:
        return grade_submission(folder, os.path.join(out_dir, name), sheet, name, underlay, isolate,
                                on_step=on_step, unsandboxed=unsandboxed, jobs=jobs)
    except Exception as err:  # anything: this student's row says so, the class goes on
        record = could_not_grade(name, sheet, '%r' % err,
                                 ['grader error, please report: %s' % traceback.format_exc().replace('\n', ' | ')])
        moodle_name = os.path.basename(os.path.abspath(folder).rstrip('/'))
        record.update(participant=identity.participant_number(moodle_name), folder=moodle_name)  # who, even so
        try:
            report.write_grade(os.path.join(out_dir, name), record)
        except OSError:
            pass
        return record


def _refused_at_intake(name, folder, out_dir, sheet, why):
    """The record of a student whose files the class's intake refused: nothing of it ran."""
    folder_name = os.path.basename(folder)
    measured = {'student': name, 'sheet': sheet or 'altitude', 'static': {}, 'notes': [], 'fixes': [],
                'comments': None, 'isolate': None, 'how_run': None,
                'session': no_session('refused', 'submission refused: %s' % why, refused=True),
                'extra': {'participant': identity.participant_number(folder_name), 'folder': folder_name,
                          'documents': [], 'seconds': 0.0}}
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, MEASUREMENTS), 'w') as f:
        json.dump(measured, f, indent=1, sort_keys=True)
    record = score(measured)
    report.write_grade(out_dir, record)
    return record


def class_similarity(klass, out, records_):
    """The similarity check over a class's submissions, each named as its grade record names it, run in
    a box (:mod:`exam_lab.grader.boxed.similarity` ``--class``: unpacking and comparing, SIMILARITY_BOUNDS)
    and read back as a :class:`~exam_lab.grader.score.records.SimilarityRecord`; written to
    ``out/similarity.json``. ``{"error"}`` when it could not run (the grades stand)."""
    work_dirs, refused = [], {}
    try:
        by_folder = {r.get('folder'): r['student'] for r in records_}
        listed = [(by_folder.get(os.path.basename(folder), name), folder)
                  for name, folder in class_students(klass, work_dirs, refused=refused)]
        intake = [(name, folder) for name, folder in listed if folder not in refused]
        python = similarity.ensure_venv()  # as root: an installation, from PyPI, of no student's bytes
        # Each student staged by its own bounds: one over them is not compared, the others are.
        work, staged = _staged_work('exam-similarity-', [(os.path.basename(f), f) for _, f in intake],
                                    refused=refused)
        work_dirs.append(work)
        kept = [(student, path) for student, path in zip(intake, staged) if path is not None]
        submissions, staged = [student for student, _ in kept], [path for _, path in kept]
        similarity.boilerplate(os.path.join(work, 'upload', 'boilerplate'))
        venv = os.path.dirname(os.path.dirname(python))
        with sandbox.Box(work, [venv], bwrap=sandbox.check() is None) as box:
            # copydetect imports matplotlib, which wants Debian's /etc/matplotlibrc
            boxed = Boxed(box, work, [(path, None, False) for path in ('/etc/matplotlibrc',) if os.path.isfile(path)])
            job = {'submissions': [[name, boxed.path(path)] for (name, _), path in zip(submissions, staged)],
                   'boilerplate': boxed.path(os.path.join(work, 'upload', 'boilerplate')), 'python': python,
                   'out': boxed.path(boxed.out)}
            with open(os.path.join(work, 'upload', 'job.json'), 'w') as f:
                json.dump(job, f)
            result = boxed.run('exam_lab.grader.boxed.similarity', ['--class', boxed.path(f.name)],
                               records.SimilarityRecord, SIMILARITY_BOUNDS, python=python).value
        result['notes'] = ['%s: not compared (its files were refused: %s)' % (name, refused[folder])
                           for name, folder in listed if folder in refused] + result.get('notes', [])
    except Exception as err:  # a bug of the check, or its box failing, must not cost the class its page
        result = {'error': str(err) if isinstance(err, (InspectionFailed, archives.UnpackError)) else repr(err)}
    finally:
        for work in work_dirs:
            shutil.rmtree(work, ignore_errors=True)
    with open(os.path.join(out, 'similarity.json'), 'w') as f:
        json.dump(result, f, indent=1, sort_keys=True)
    return result


def default_underlay():
    return os.path.join(workspace(), 'grader', 'underlay')


#: Gradings side by side per core when JOBS is not given. A grading mostly waits (its flight is timed),
#: and each box's CPU is bounded to cores/JOBS, so two per core keep every point: measured by `make
#: bench`'s grader stage on a class of 60 (docs/benchmarks.md, "The grader").
JOBS_PER_CORE = 2
#: Memory one grading is counted for when JOBS is not given: its processes use a few hundred MB (the
#: bounds are higher: the box 2 GB, the master 384 MB, the probe 512 MB).
JOB_MEMORY_BYTES = 1 << 30


def default_jobs(cores=None, memory=None):
    """JOBS when the teacher gives none: JOBS_PER_CORE per core this process may run on, no more than
    the memory holds at JOB_MEMORY_BYTES each, at least 1."""
    if cores is None:
        cores = len(os.sched_getaffinity(0)) if hasattr(os, 'sched_getaffinity') else (os.cpu_count() or 1)
    if memory is None:
        try:
            memory = os.sysconf('SC_PAGE_SIZE') * os.sysconf('SC_PHYS_PAGES')
        except (ValueError, OSError):
            memory = JOB_MEMORY_BYTES * JOBS_PER_CORE * cores
    return max(1, min(JOBS_PER_CORE * cores, memory // JOB_MEMORY_BYTES))


def grade_class(class_path, out_dir, sheet=None, jobs=None, isolate=None, progress=None, unsandboxed=False):
    """Grade every student of a class, ``jobs`` side by side (default :func:`default_jobs`); write each
    one's grade and grades.csv. One student the grader cannot grade is that student's row ("could not
    grade"), never the class's.

    :param progress: told of the run as it goes (:class:`exam_lab.grader.publish.progress.ClassProgress`).
    """
    refusal = sandbox_refusal(unsandboxed)
    if refusal:
        raise sandbox.SandboxUnavailable(refusal)
    os.makedirs(out_dir, exist_ok=True)
    jobs = jobs or default_jobs()
    work_dirs, refused = [], {}
    try:
        students = class_students(class_path, work_dirs, refused=refused, out=out_dir)
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
                                   jobs=jobs, refused=refused.get(folder))
            if progress:
                progress.finished(record)
            return record

        with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
            for index, record in zip(range(len(students)), pool.map(one, range(len(students)))):
                records[index] = record
        report.write_csv(os.path.join(out_dir, 'grades.csv'), records)
        return records
    finally:
        for work in work_dirs:
            shutil.rmtree(work, ignore_errors=True)
