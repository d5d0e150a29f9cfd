"""Grading one submission, stage by stage (:func:`grade_submission`); each stage a call, a record in and a
record out:

1. **stage** (:func:`~exam_lab.grader.host.staging.stage_work`): root copies the upload byte for byte
   into the box's work folder (regular files, folders, links as links:
   :func:`~exam_lab.grader.host.staging.stage_upload`), never parsing a student's bytes;
2. **inspect** (:func:`inspect`): :mod:`~exam_lab.grader.boxed.inspect` runs in the submission's
   :class:`~exam_lab.grader.host.sandbox.Box`, as the box's uid, without network, within
   :data:`~exam_lab.grader.host.boxed_run.INSPECT_BOUNDS` (unpacking, the package copied into the
   workspace, the teacher's fixes, launch and YAML analysis, the derived launch files, the source scan,
   PDF facts, comment statistics); root reads back one capped, checked
   :class:`~exam_lab.grader.score.records.InspectRecord` (:class:`~exam_lab.grader.host.boxed_run.Boxed`);
3. **plan** (:func:`plan_job`): the session's job, a :class:`~exam_lab.grader.score.records.JobRecord`
   computed once from that record (each run's :class:`~exam_lab.grader.score.records.PlanRecord` the judge reads);
4. **session** (:func:`run_session`): :mod:`exam_lab.grader.host.session` builds and runs the package in a
   network namespace with only loopback (:func:`~exam_lab.grader.host.bwrap.network_namespace`) under a
   :class:`~exam_lab.harness.supervisor.Supervisor` with the student's time limit; root reads back its
   :class:`~exam_lab.grader.score.records.SessionRecord` (:func:`session_outcome`);
5. **report** (:func:`~exam_lab.grader.host.reports.read_report`): the student's report read in a box
   of its own (:mod:`~exam_lab.grader.boxed.report_reader`), kept as ``report.json`` with the files
   handed in and the pages' images (``report/``); the package's source as handed in is kept in ``code/``
   (:func:`~exam_lab.grader.host.reports.keep_code`, from the inspection's copy);
6. **score** and **publish** (:func:`publish`): the measurements kept, the grade made from them by
   :func:`~exam_lab.grader.publish.grades.score` (the rubric; a rescore does the same), grade.json and
   grade.md written; the session's logs copied as data (regular files only, each capped:
   :func:`keep_logs`).

A class is graded by :mod:`~exam_lab.grader.class_run`, each student by :func:`grade_submission`. The
simulators are an underlay built once (:mod:`~exam_lab.grader.host.underlay`); each student's package
is built alone in an overlay of its own on top of it.
"""
import os
import random
import shutil
import sys
import time

from exam_lab.grader.boxed import archives
from exam_lab.grader.boxed.inspect import CODE_COPY
from exam_lab.grader.host import bwrap, egress, limits, reports, sandbox, staging
from exam_lab.grader.host.boxed_run import INSPECT_BOUNDS, Boxed, InspectionFailed, session_tail
from exam_lab.grader.host.bwrap import can_isolate
from exam_lab.grader.host.session import budget_sentence
from exam_lab.grader.host.underlay import box_binds, default_underlay, ensure_underlay, package_path
from exam_lab.grader.publish import grades, progress, teacher
from exam_lab.grader.score import identity, records
from exam_lab.grader.score.records import Outcome
from exam_lab.grader.score.boxenv import BOX_WS
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
    refusal = sandbox.sandbox_refusal(unsandboxed)
    if refusal:
        raise sandbox.SandboxUnavailable(refusal)
    isolate = can_isolate() if isolate is None else isolate
    underlay = underlay or ensure_underlay(default_underlay())  # raises: the grader cannot run
    os.makedirs(out_dir, exist_ok=True)
    deadline = time.monotonic() + STUDENT_BUDGET  # the student's own time starts here, the simulators built
    work = staging.new_work('exam-grade-')
    folder = os.path.basename(os.path.abspath(submission).rstrip('/'))
    notes, fixes, static, session, chosen_sheet, comments, how_run = [], [], {}, None, sheet, None, None
    facts = {'participant': identity.participant_number(folder), 'folder': folder, 'documents': []}
    try:
        try:
            progress.report(on_step, 'unpack')
            # The teacher's path, followed: a link given on the command line is the upload it names.
            (upload,) = staging.stage_work(work, [(folder, os.path.realpath(submission))])
            with sandbox.Box(work, box_binds(underlay), bwrap=sandbox.check() is None,
                             cpus=limits.box_cpus(jobs)) as box:
                notes.extend(box.notes)
                found = inspect(box, work, upload, sheet, timeout=deadline - time.monotonic())
                notes.append(teacher.how_read(box, found.uid, INSPECT_BOUNDS))
                notes.extend(found.notes)
                fixes.extend(found.fixes)
                facts, comments = found.facts, found.comments
                if found.refused is not None:
                    raise archives.UnpackError(found.refused)
                notes.extend(reports.keep_code(os.path.join(work, 'out', CODE_COPY), out_dir))
                chosen_sheet, static = found.sheet, found.static
                job = plan_job(found)
                if job is None:
                    session = grades.no_session(Outcome.NO_NODE, 'no script of the package starts a ROS node', no_node=True)
                elif deadline - time.monotonic() < START_TIMEOUT:
                    why = budget_sentence(STUDENT_BUDGET, 'nothing was run (%.0f s left after the inspection)'
                                          % (deadline - time.monotonic()))
                    session = grades.no_session(Outcome.NOT_RUN, why, budget_used=why)
                else:
                    how_run = teacher.how_run(box)
                    session = run_session(job, work=work, underlay=underlay, isolate=isolate, box=box, on_step=on_step,
                                          left=deadline - time.monotonic())
        except (archives.UnpackError, staging.UploadRefused) as err:
            session = grades.no_session(Outcome.REFUSED, 'submission refused: %s' % err, refused=True)
        except InspectionFailed as err:
            session = grades.no_session(Outcome.INSPECTION_FAILED, 'the inspection of the upload failed: %s' % err)
        except Exception as err:  # a grader bug must not stop the class: say so and carry on
            session = grades.no_session(Outcome.GRADER_FAILED, 'the grader failed on this submission: %r' % err)
            notes.append(grades.bug_note())
        notes.extend(keep_logs(work, out_dir))
        # The report, read after the flights in a box of its own: its time is not the student's budget.
        progress.report(on_step, 'report')
        reports.read_report(submission, out_dir, jobs=jobs)
        measured = {'student': student, 'sheet': chosen_sheet or 'altitude', 'static': static, 'session': session.value,
                    'notes': notes, 'fixes': fixes, 'comments': comments, 'isolate': isolate, 'how_run': how_run,
                    'extra': dict(facts, **dict(extra or {}, seconds=round(time.monotonic() - start, 1)))}
        return publish(out_dir, measured)
    finally:
        if not keep:
            shutil.rmtree(work, ignore_errors=True)  # never follows a link the box left (rmtree does not)


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
            '--toplevel', os.path.join(package_path('catkin'), 'cmake', 'toplevel.cmake'),
            '--draw', repr(random.SystemRandom().random())]
    return boxed.run('exam_lab.grader.boxed.inspect', args + (['--sheet', wanted_sheet] if wanted_sheet else []),
                     records.InspectRecord, (min(INSPECT_BOUNDS[0], timeout or INSPECT_BOUNDS[0]),) + INSPECT_BOUNDS[1:])


def plan_job(record):
    """The session's job (a :class:`~exam_lab.grader.score.records.JobRecord`) from a checked inspection
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
    return records.JobRecord.make({'namespace': record.namespace, 'build_timeout': BUILD_TIMEOUT,
                                   'run_timeout': RUN_TIMEOUT, 'runs': runs, 'handed_in_launch': record.handed_in_launch})


def run_session(job, *, work, underlay, isolate, box, on_step=None, left=STUDENT_BUDGET):
    """Run the session of one submission, its student steps in ``box``; return what it measured (or
    why it could not): its :class:`~exam_lab.grader.score.records.SessionRecord`.

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
    runs = [dict(run, launch=os.path.join(box.workspace, run['launch'])) for run in job.runs]
    job = job.replaced(workspace=box.workspace, runs=runs, underlay=underlay, log_dir=log_dir, judge_home=judge_home,
                       box=box.describe(), budget=left, student_budget=STUDENT_BUDGET)
    job_path = os.path.join(work, records.JobRecord.FILE)
    with open(job_path, 'w') as f:
        f.write(job.to_json())
    argv = [sys.executable, '-m', 'exam_lab.grader.host.session', job_path]
    if isolate:
        argv = bwrap.network_namespace(argv)
    with progress.watching(log_dir, on_step), Supervisor(os.path.join(work, 'outer')) as sup:
        status, output, _ = sup.run('session', argv, timeout=left + SESSION_KILL_S, env=dict(os.environ, HOME=judge_home))
    end_pids(marked(log_dir))  # anything the session started and left, whatever happened to it
    survivors = box.end()  # the box's uid: nothing may be left once its PID namespaces are gone
    return session_outcome(log_dir, status, output, left, survivors)


def session_outcome(log_dir, status, output, left, survivors):
    """The session's record (a :class:`~exam_lab.grader.score.records.SessionRecord`): the one
    it wrote in ``log_dir`` when it ended well (``status`` 0), read through
    :func:`~exam_lab.grader.host.egress.read_record` (capped, checked), else why there is none;
    ``survivors`` (processes of the box's uid found after it) added to its count."""
    if status == 0:
        try:
            result = egress.read_record(os.path.join(log_dir, records.SessionRecord.FILE), records.SessionRecord,
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
    """Copy the session's logs into ``out_dir/logs`` as data (:func:`~exam_lab.grader.host.egress.copy_results`);
    return the notes on what was not copied."""
    logs = os.path.join(out_dir, 'logs')
    shutil.rmtree(logs, ignore_errors=True)
    if os.path.isdir(os.path.join(work, 'logs')):
        skipped = egress.copy_results(os.path.join(work, 'logs'), logs)
        if skipped:
            return ['not copied to logs/ (not a regular file): %s' % ', '.join(skipped)]
    return []


def publish(out_dir, measured):
    """Keep what a grading measured (a :class:`~exam_lab.grader.score.kept.MeasurementsRecord`, what a
    rescore reads), score it, write grade.json and grade.md; return the grade record."""
    return grades.keep_and_score(out_dir, measured)
