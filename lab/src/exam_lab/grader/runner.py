"""Grading one submission (:func:`grade_submission`).

Theory of operation

We want to run a student's package and measure it from the outside, as root never runs, reads or
parses the student's bytes. So one grading runs as three kinds of processes:

  - root (this module, :mod:`~exam_lab.grader.class_run`, ``host/``): copies the upload into the box's
    work folder byte for byte, never opening an archive (:mod:`~exam_lab.grader.host.staging`); opens
    the box (:class:`~exam_lab.grader.host.sandbox.Box`: a uid of its own, bubblewrap, cgroups,
    limits); starts what runs in it; and reads back only what the contract lets it read
    (:mod:`~exam_lab.grader.contract`). It never imports the box's code (``boxed/``, ``judge/``): it
    runs it, as ``python -m`` in the box, and reads its record.
  - the box's uid (``boxed/``, on the student's bytes, without network): the inspection unpacks the
    upload, finds the package, reads its launch files and sources, writes the derived launch files,
    and hands back one record (:class:`~exam_lab.grader.score.inspection.InspectRecord`); then the
    student's build and nodes run as the same uid in the session's network namespace of loopback only.
  - the judge's uid (``judge/``, never root, never reading the student's files): the master and the
    probe, which plays the drone, flies the plan and measures the node from the ROS graph.

What crosses, and how:

  - down, into the box: the upload (bytes), and a job root computed from the inspection's record, once
    (:func:`plan_job`: a :class:`~exam_lab.grader.score.job.JobRecord`, each run's plan in it, which
    reaches the judge as it was made);
  - up, out of the box: one record per step (the inspection's, the session's
    :class:`~exam_lab.grader.score.records.SessionRecord`), each read through the contract (no link,
    a regular file, capped, checked by its type, its text cleaned once) and the logs, copied as capped
    text (:func:`keep_logs`); nothing else of the box is read;
  - into OUT: the measurements kept (what ``make rescore`` scores again), then the grade made from them
    by the rubric (pure: :func:`~exam_lab.grader.publish.grades.score`), each written by the contract's
    writer (a temporary file, then ``os.replace``).

Who a submission is (Moodle's participant number and folder) is read by root from the listed entry's
name, once, and carried in the records from there: never as a box says it. A fault of the grader (a
bug, a box that cannot open) is "the grader failed" with its traceback for the teacher; a fault of the
student's bytes (refused, no node, a build that fails) is what the record says: one student's row
either way, never the class's. The simulators are an underlay built once
(:mod:`~exam_lab.grader.host.underlay`); each student's package is built alone in an overlay on top.
"""
import contextlib
import os
import random
import shutil
import sys
import time

from exam_lab.grader import contract
from exam_lab.grader.host import bwrap, cgroups, limits, reports, sandbox, staging, timings
from exam_lab.grader.host.boxed_run import INSPECT_BOUNDS, Boxed, InspectionFailed, session_tail
from exam_lab.grader.host.bwrap import can_isolate
from exam_lab.grader.host.run import budget_sentence
from exam_lab.grader.host.side_by_side import markers
from exam_lab.grader.host.underlay import box_binds, default_underlay, ensure_underlay, package_path
from exam_lab.grader.publish import grades, progress, teacher
from exam_lab.grader.score import identity, records
from exam_lab.grader.score.job import JobRecord
from exam_lab.grader.score.inspection import InspectRecord
from exam_lab.grader.score.records import Outcome
from exam_lab.grader.score.schema import plain
from exam_lab.grader.score.boxenv import BOX_WS, CODE_COPY
from exam_lab.grader.score.sheets import DELAY, LATE_WARNING_S, SHEETS, margin_of
from exam_lab.harness.supervisor import Supervisor, end_pids, marked

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
#: (:func:`~exam_lab.grader.class_run.worst_case`).
AFTER_BUDGET_S = 20.0
SESSION_KILL_S = 5.0


def grade_submission(submission, out_dir, *, sheet=None, student=None, underlay=None, isolate=None, keep=False,
                     on_step=None, extra=None, unsandboxed=False, jobs=1, side_by_side=True):
    """Grade one submission; write grade.json and grade.md in ``out_dir``; return the record.

    :param on_step: called with each step's name as it starts (unpack, build, main flight...).
    :param extra: added to the record, over the inspection's facts (participant, folder, documents).
    :param unsandboxed: run it even where no sandbox can be made (the teacher's flag that names the
        risk); otherwise :class:`~exam_lab.grader.host.sandbox.SandboxUnavailable` is raised there.
    :param jobs: how many submissions are graded side by side: the box's part of the CPU.
    :param side_by_side: fly the main and the threshold run at once, each in a box, a network namespace
        and on a master of its own (where the session is isolated and a second box can be had); else
        one after the other in the one box (:func:`run_session`).

    Each stage's wall and CPU time goes to ``out_dir/logs/timings.json`` (:mod:`~exam_lab.grader.host.timings`).
    """
    start = time.monotonic()
    watch = timings.Stopwatch(cpu=time.thread_time)  # a class grades in threads: this one's, and its box's
    prepared = watch.now()
    student = student or identity.student_name(os.path.basename(os.path.abspath(submission).rstrip('/')))
    refusal = sandbox.sandbox_refusal(unsandboxed)
    if refusal:
        raise sandbox.SandboxUnavailable(refusal)
    isolate = can_isolate() if isolate is None else isolate
    underlay = underlay or ensure_underlay(default_underlay())  # raises: the grader cannot run
    contract.make_folder(out_dir)  # a folder of OUT that is a link is refused here, before anything is run
    deadline = time.monotonic() + STUDENT_BUDGET  # the student's own time starts here, the simulators built
    work = staging.new_work('exam-grade-')
    watch.record('prepare', *prepared)  # the sandbox's check and the underlay, once a process
    folder = os.path.basename(os.path.abspath(submission).rstrip('/'))
    notes, fixes, static, session, chosen_sheet, comments, how_run = [], [], {}, None, sheet, None, None
    facts = {'participant': identity.participant_number(folder), 'folder': folder, 'documents': []}
    try:
        try:
            progress.report(on_step, 'unpack')
            # The teacher's path, followed: a link given on the command line is the upload it names.
            with watch.stage('staging'):
                (upload,) = staging.stage_work(work, [(folder, os.path.realpath(submission))])
            with sandbox.Box(work, box_binds(underlay), bwrap=sandbox.check() is None,
                             cpus=limits.box_cpus(jobs)) as box:
                notes.extend(box.notes)
                with watch.stage('inspection'):
                    counted = cgroups.cpu_use(box.cgroups)
                    found = inspect(box, work, upload, sheet, timeout=deadline - time.monotonic())
                    if counted is not None:
                        watch.add_cpu(cgroups.cpu_use(box.cgroups) - counted)
                notes.append(teacher.how_read(box, found.uid, INSPECT_BOUNDS))
                notes.extend(found.notes)
                fixes.extend(found.fixes)
                # Who it is, as root read it from the listed entry's name: never as the box says.
                facts = dict(plain(found.facts), participant=facts['participant'], folder=facts['folder'])
                comments = plain(found.comments)
                if found.refused is not None:
                    raise records.UnpackError(found.refused)
                notes.extend(reports.keep_code(os.path.join(work, 'out', CODE_COPY), out_dir))
                chosen_sheet, static = found.sheet, plain(found.static)
                job = plan_job(found)
                if job is None:
                    session = grades.no_session(Outcome.NO_NODE, 'no script of the package starts a ROS node', no_node=True)
                elif deadline - time.monotonic() < START_TIMEOUT:
                    why = budget_sentence(STUDENT_BUDGET, 'nothing was run (%.0f s left after the inspection)'
                                          % (deadline - time.monotonic()))
                    session = grades.no_session(Outcome.NOT_RUN, why, budget_used=why)
                else:
                    how_run = teacher.how_run(box)
                    with twin_box(job, work, underlay, box, isolate and side_by_side and cpu_allows_two_runs(),
                                  jobs) as twin, \
                            watch.stage('session'):
                        session = run_session(job, work=work, underlay=underlay, isolate=isolate, box=box, twin=twin,
                                              on_step=on_step, left=deadline - time.monotonic())
                    ran = timings.read(os.path.join(work, 'logs'))
                    wall = watch.stages['session']['wall']  # the session's own CPU, the runner's wall clock
                    watch.stages.update(ran.get('stages', {}))
                    watch.stages['session']['wall'] = wall
                    watch.extra['side_by_side'] = bool(ran.get('side_by_side'))
        except (records.UnpackError, staging.UploadRefused) as err:
            session = grades.no_session(Outcome.REFUSED, 'submission refused: %s' % err, refused=True)
        except InspectionFailed as err:
            session = grades.no_session(Outcome.INSPECTION_FAILED, 'the inspection of the upload failed: %s' % err)
        except Exception as err:  # a grader bug must not stop the class: say so and carry on
            session = grades.no_session(Outcome.GRADER_FAILED, 'the grader failed on this submission: %r' % err)
            notes.append(grades.bug_note())
        with watch.stage('logs'):
            notes.extend(keep_logs(work, out_dir))
        # The report, read after the flights in a box of its own: its time is not the student's budget.
        progress.report(on_step, 'report')
        with watch.stage('report'):
            reports.read_report(submission, out_dir, jobs=jobs, watch=watch)
        measured = {'student': student, 'sheet': chosen_sheet or 'altitude', 'static': static, 'session': session.value,
                    'notes': notes, 'fixes': fixes, 'comments': comments, 'isolate': isolate, 'how_run': how_run,
                    'extra': dict(facts, **dict(extra or {}, seconds=round(time.monotonic() - start, 1)))}
        with watch.stage('grade'):
            graded = publish(out_dir, measured)
        watch.extra.update(jobs=jobs, wall=round(time.monotonic() - start, 3))
        os.makedirs(os.path.join(out_dir, 'logs'), exist_ok=True)
        watch.write(os.path.join(out_dir, 'logs'))
        return graded
    finally:
        if not keep:
            shutil.rmtree(work, ignore_errors=True)  # never follows a link the box left (rmtree does not)


def inspect(box, work, upload, wanted_sheet, timeout=None):
    """Run :mod:`exam_lab.grader.boxed.inspect` on the staged ``upload`` (a path below ``<work>/upload``)
    in ``box`` (:class:`Boxed`), bounded by INSPECT_BOUNDS (its wall clock by ``timeout`` if less); return its checked
    :class:`~exam_lab.grader.score.inspection.InspectRecord`. The package is written, as the box's uid, to
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
            '--toplevel', os.path.join(package_path('catkin'), 'cmake', 'toplevel.cmake'),
            '--draw', repr(random.SystemRandom().random())]
    return boxed.run('exam_lab.grader.boxed.inspect', args + (['--sheet', wanted_sheet] if wanted_sheet else []),
                     InspectRecord, (min(INSPECT_BOUNDS[0], timeout or INSPECT_BOUNDS[0]),) + INSPECT_BOUNDS[1:])


def plan_job(record):
    """The session's job (a :class:`~exam_lab.grader.score.job.JobRecord`) from a checked inspection
    record: the runs' plans are computed here, from its numbers; the launch files stay relative to the
    workspace. None when there is nothing to run."""
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
    return JobRecord.make({'namespace': record.namespace, 'build_timeout': BUILD_TIMEOUT,
                                   'run_timeout': RUN_TIMEOUT, 'runs': runs, 'handed_in_launch': record.handed_in_launch})


def cpu_allows_two_runs(cores=None, load=None):
    """Whether the machine has the CPU to fly a student's two runs at once: its load average over the
    last minute (``load``) below its ``cores``. Two runs start two roslaunches at once; on a machine
    already busy (measured 2026-12-01: a test session's classes at a load of 5 to 18 on two cores) their
    nodes then missed START_TIMEOUT, so there the runs fly one after the other, as before."""
    cores = cores or (len(os.sched_getaffinity(0)) if hasattr(os, 'sched_getaffinity') else os.cpu_count() or 1)
    load = os.getloadavg()[0] if load is None else load
    return load < cores


@contextlib.contextmanager
def twin_box(job, work, underlay, box, wanted, jobs):
    """The submission's second box, where one of its two runs flies beside the other (:func:`run_session`),
    or None: not ``wanted`` (not isolated, or the teacher's choice), one run only, no sandbox (nothing to
    isolate the runs from each other), or no free slot."""
    if not wanted or job is None or len(job.runs) != 2 or not box.bwrap:
        yield None
        return
    try:
        twin = sandbox.Box(work, box_binds(underlay), bwrap=True, cpus=limits.box_cpus(jobs), name='box-twin').open()
    except sandbox.SandboxUnavailable:
        yield None
        return
    try:
        yield twin
    finally:
        twin.close()


def run_session(job, *, work, underlay, isolate, box, twin=None, on_step=None, left=STUDENT_BUDGET):
    """Run the session of one submission, its student steps in ``box``; return what it measured (or
    why it could not): its :class:`~exam_lab.grader.score.records.SessionRecord`.

    :param left: seconds left of the student's budget: the session's own (it stops its steps in time),
        and killed SESSION_KILL_S after.

    :param isolate: in a network namespace of its own with only loopback
        (:func:`~exam_lab.grader.host.bwrap.network_namespace`).
    :param on_step: called with each step's name as the session starts it (:mod:`~exam_lab.grader.publish.progress`).
    :param twin: a second box (:func:`twin_box`): the two runs fly side by side, each in a network
        namespace of its own, one of them (drawn here: which one tells a node nothing) in ``twin`` with
        a judge of its own.
    """
    log_dir = os.path.join(work, 'logs')
    judge_home = os.path.join(work, 'judge')
    for folder in (log_dir, judge_home):
        os.makedirs(folder, mode=0o700, exist_ok=True)
    runs = [dict(plain(run), launch=os.path.join(box.workspace, run.launch)) for run in job.runs]
    if twin is not None:
        os.makedirs(os.path.join(work, 'judge-twin'), mode=0o700, exist_ok=True)
        drawn = random.SystemRandom().randrange(2)
        runs[drawn].update(box=twin.describe(), judge_home=os.path.join(work, 'judge-twin'))
    job = job.replaced(workspace=box.workspace, runs=runs, underlay=underlay, log_dir=log_dir, judge_home=judge_home,
                       box=box.describe(), budget=left, student_budget=STUDENT_BUDGET, side_by_side=twin is not None)
    job_path = os.path.join(work, JobRecord.FILE)
    with open(job_path, 'w') as f:
        f.write(job.to_json())
    argv = [sys.executable, '-m', 'exam_lab.grader.host.session', job_path]
    if isolate:
        argv = bwrap.network_namespace(argv)
    try:
        with progress.watching(log_dir, on_step), Supervisor(os.path.join(work, 'outer')) as sup:
            status, output, _ = sup.run('session', argv, timeout=left + SESSION_KILL_S,
                                        env=dict(os.environ, HOME=judge_home))
    finally:
        for marker in markers(log_dir):  # anything the session started and left, whatever happened to it (Ctrl-C)
            end_pids(marked(marker))
    survivors = box.end() + (twin.end() if twin is not None else 0)  # nothing may be left of the boxes' uids
    return session_outcome(log_dir, status, output, left, survivors)


def session_outcome(log_dir, status, output, left, survivors):
    """The session's record (a :class:`~exam_lab.grader.score.records.SessionRecord`): the one
    it wrote in ``log_dir`` when it ended well (``status`` 0), read through
    :func:`~exam_lab.grader.host.contract.read_record` (capped, checked), else why there is none;
    ``survivors`` (processes of the box's uid found after it) added to its count."""
    if status == 0:
        try:
            result = contract.read_record(os.path.join(log_dir, records.SessionRecord.FILE), records.SessionRecord,
                                        records.SessionRecord.MAX_BYTES)
        except records.RecordError as err:
            return grades.no_session(Outcome.SESSION_FAILED, 'the session\'s record was refused: %s' % err,
                                     survivors=survivors)
        return result.replaced(survivors=(result.survivors or 0) + survivors)
    if status is None:
        why = budget_sentence(STUDENT_BUDGET, 'the session was killed after %.0f s' % (left + SESSION_KILL_S))
        return grades.no_session(Outcome.SESSION_KILLED, why, budget_used=why, survivors=survivors)
    return grades.no_session(Outcome.SESSION_FAILED, 'the session failed (exit %s): %s' % (status, session_tail(output)),
                             survivors=survivors)


def keep_logs(work, out_dir):
    """Copy the session's logs into ``out_dir/logs`` as data (:func:`~exam_lab.grader.host.contract.copy_results`);
    return the notes on what was not copied."""
    logs = os.path.join(out_dir, 'logs')
    shutil.rmtree(logs, ignore_errors=True)
    if os.path.isdir(os.path.join(work, 'logs')):
        skipped = contract.copy_results(os.path.join(work, 'logs'), logs)
        if skipped:
            return ['not copied to logs/ (not a regular file): %s' % ', '.join(skipped)]
    return []


def publish(out_dir, measured):
    """Keep what a grading measured (a :class:`~exam_lab.grader.score.kept.MeasurementsRecord`, what a
    rescore reads), score it, write grade.json and grade.md; return the grade record."""
    return grades.keep_and_score(out_dir, measured)
