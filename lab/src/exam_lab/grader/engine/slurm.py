"""Grading a class on a Slurm cluster: one array job, one task per student (docs/grading.md, "Grading
on a Slurm cluster"). No rospy here.

Two halves, both run as whoever submits (the teacher; root only on a local try-out):

- On the host that submits (a cluster's login node), :func:`grade_class` lists the students with the
  local run's own function (:func:`~exam_lab.grader.class_run.class_students`; a Moodle archive's students
  are then copied onto OUT for the nodes: :func:`shared_students`), builds the simulators' underlay
  once, writes into ``OUT/.slurm/`` a manifest (one JSON line per student: name, submission) and the
  task's batch script, submits ``sbatch --array=0-(N-1) --no-requeue`` and follows the array with
  ``squeue`` (a line each time the pending, running and done counts change). A task that leaves the
  queue without a grade (failed, cancelled, timed out, its node lost: NODE_FAIL) is resubmitted once,
  said with Slurm's words and the node; after a second such end, that student's record is "not
  graded" with what ``scontrol show job`` said. Then grades.csv, exactly as
  :func:`~exam_lab.grader.class_run.grade_class` writes it; the caller writes the rest of OUT (the desk).
- On the node, each task runs ``python3 -m exam_lab.grader.engine.slurm task ...``: :func:`run_task`
  grades its manifest line with :func:`~exam_lab.grader.class_run.grade_student`, the local run's own code
  path, names the node in the record (``graded_on``) and leaves it in ``OUT/.slurm/results/<index>.json``
  (written whole, then renamed: the host never reads half a record).

The nodes must see OUT, the class, this repository and its workspace at the same paths as the host (a
shared file system), and have what a local run needs: ROS from Debian, bubblewrap, the build.
Without accounting (``sacct``), why a task ended is read from ``scontrol show job``, which forgets a
job MinJobAge (default 300 s) after its end: the host asks as soon as the task leaves the queue.
"""
import argparse
import json
import os
import re
import shlex
import shutil
import signal
import socket
import subprocess
import sys
import time

from exam_lab.grader import class_run, contract, workspace
from exam_lab.grader.host import sandbox, staging, underlay
from exam_lab.grader.publish import grades, report
from exam_lab.grader.score import identity, kept, safe_text
from exam_lab.grader.score.records import RecordError, shown

#: Seconds between two looks at the queue: light on a shared controller, quick enough for a class.
POLL_S = 5.0
#: Seconds one Slurm command (sbatch, squeue, scontrol, scancel) may take.
CALL_TIMEOUT = 60.0
#: Seconds a task that ended COMPLETED is given for its record to appear (a shared file system's lag).
RESULT_GRACE_S = 30.0
#: A task's time limit, minutes: the session's limit, the student's build and, on a node whose copy of
#: the simulators is stale, their build, with room to spare.
TASK_MINUTES = 60
#: How many times a student's task is submitted at most: once, and once more when it ended without a grade.
ATTEMPTS = 2
#: Job states of a task that is over (squeue no longer lists it; scontrol still knows it for a while).
ENDED = ('COMPLETED', 'FAILED', 'CANCELLED', 'TIMEOUT', 'NODE_FAIL', 'OUT_OF_MEMORY', 'BOOT_FAIL',
         'DEADLINE', 'PREEMPTED')
PENDING = ('PENDING', 'REQUEUED', 'CONFIGURING', 'RESV_DEL_HOLD', 'REQUEUE_HOLD', 'REQUEUE_FED', 'SUSPENDED')


def array_spec(indices):
    """sbatch's ``--array`` for these task indices: ``0-59`` for a whole class, ``3,17-18`` for retries."""
    runs = []
    for index in sorted(set(indices)):
        if runs and index == runs[-1][1] + 1:
            runs[-1][1] = index
        else:
            runs.append([index, index])
    return ','.join('%d' % a if a == b else '%d-%d' % (a, b) for a, b in runs)


def _indices(text):
    """The task indices of squeue's ``%K``: ``4``, or a pending range such as ``[2-5,7]`` or ``2-5%3``."""
    text = text.strip('[]').split('%')[0]
    found = []
    for part in text.split(','):
        bounds = part.split('-')
        if all(b.isdigit() for b in bounds) and len(bounds) in (1, 2):
            found.extend(range(int(bounds[0]), int(bounds[-1]) + 1))
    return found


def parse_squeue(text):
    """``{(array job id, task index): (state, reason)}`` from ``squeue -h -r -o '%F %K %T %r'``."""
    tasks = {}
    for line in text.splitlines():
        parts = line.split(None, 3)
        if len(parts) < 3:
            continue
        for index in _indices(parts[1]):
            tasks[(parts[0], index)] = (parts[2], parts[3].strip() if len(parts) > 3 else '')
    return tasks


def parse_scontrol(text):
    """The ``Key=Value`` fields of one job in ``scontrol show job`` ({} when Slurm does not know it)."""
    fields = {}
    for token in text.split():
        key, sep, value = token.partition('=')
        if sep and key not in fields:
            fields[key] = value
    return fields


def slurm_said(fields, last_seen=None):
    """Why a task ended without a grade, in Slurm's words: its state, reason and exit code (exit
    status:signal); when Slurm keeps no record of it, the state it was last seen in."""
    if not fields.get('JobState'):
        seen = ' (last seen %s)' % ', '.join(w for w in last_seen if w and w != 'None') if last_seen else ''
        return 'the task left the queue and Slurm keeps no record of it%s' % seen
    words = [fields['JobState']]
    if fields.get('NodeList', '(null)') not in ('', '(null)', 'None'):
        words[0] += ' on node %s' % fields['NodeList']
    if fields['JobState'] == 'NODE_FAIL':
        words[0] += ' (the node stopped answering the controller: its task is lost)'
    if fields.get('Reason', 'None') != 'None':
        words.append('reason %s' % fields['Reason'])
    if fields.get('ExitCode', '0:0') != '0:0':
        words.append('exit code %s' % fields['ExitCode'])
    return ', '.join(words)


def state_line(jobs, tasks, graded, not_graded, total, again=0):
    """The array's state for the terminal: ``slurm job 12: 3 pending, 2 running, 5 done of 10``, and
    what went wrong so far: ``slurm job 12+13 (2 tasks submitted again): ... (1 not graded)``."""
    pending = sum(1 for state, _ in tasks.values() if state in PENDING)
    running = len(tasks) - pending
    failed = ' (%d not graded)' % not_graded if not_graded else ''
    retried = ' (%d task%s submitted again)' % (again, '' if again == 1 else 's') if again else ''
    return 'slurm job %s%s: %d pending, %d running, %d done of %d%s' % (
        '+'.join(jobs), retried, pending, running, graded + not_graded, total, failed)


def job_name(out_dir):
    """The jobs' name, from OUT: a teacher's squeue tells the classes apart; the host follows its own
    job ids only."""
    return 'exam-grade-%s' % re.sub(r'[^\w.-]', '_', os.path.basename(os.path.abspath(out_dir)))[:60]


def _call(argv):
    """Run a Slurm command; ``(returncode, stdout, stderr)``, a command that hangs counted as failing."""
    try:
        done = subprocess.run(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=CALL_TIMEOUT)
    except subprocess.TimeoutExpired:
        return 124, '', '%s did not answer within %.0f s' % (argv[0], CALL_TIMEOUT)
    return done.returncode, done.stdout.decode('utf-8', 'replace'), done.stderr.decode('utf-8', 'replace')


def _repo():
    """This repository (the nodes see it at the same path): tools/env.sh is sourced by each task."""
    here = os.path.dirname(os.path.realpath(__file__))
    repo = os.path.normpath(os.path.join(here, '..', '..', '..', '..', '..'))
    if not os.path.isfile(os.path.join(repo, 'tools', 'env.sh')):
        raise RuntimeError('the Slurm engine runs from this repository\'s lab/src; no tools/env.sh in %s' % repo)
    return repo


def write_task_script(path, manifest, out_dir, sheet, unsandboxed):
    """The batch script of every task: the repository's environment, then :func:`run_task` on the line
    of the manifest named by ``$SLURM_ARRAY_TASK_ID``."""
    options = ['--out', out_dir] + (['--sheet', sheet] if sheet else []) + (['--unsandboxed'] if unsandboxed else [])
    contract.write_text(path, '#!/bin/bash\n'
                        '# One student of the class, graded on the node this task landed on '
                        '(written by exam_lab.grader.engine.slurm).\n'
                        'set -eo pipefail\n'
                        'export EXAM_WS=%s\n'
                        'source %s\n'
                        'exec python3 -m exam_lab.grader.engine.slurm task %s "$SLURM_ARRAY_TASK_ID" %s\n'
                        % (shlex.quote(workspace()), shlex.quote(os.path.join(_repo(), 'tools', 'env.sh')),
                           shlex.quote(manifest), ' '.join(shlex.quote(o) for o in options)))
    os.chmod(path, 0o755)


#: Most bytes of the manifest read by a task: a line per student, a class of thousands fits.
MANIFEST_BYTES = 16 << 20


def manifest_entry(manifest, index):
    """Line ``index`` of the manifest: ``{"student", "submission", "participant", "folder"[, "refused"]}``
    (who it is as the listing read it: what the host checks the task's grade against). The host wrote it
    itself (:func:`_grade`, as whoever submits), of names it made (the class's listing) and folders it
    chose: no box's record, so it is read as the host's own file, but a line that is missing, cut
    short or of another shape (a manifest of another grader, a shared file system's error) stops
    the task with a sentence naming the file and the line, never a bare traceback."""
    where = '%s, line %d' % (manifest, index + 1)
    try:
        lines = contract.read_text(manifest, MANIFEST_BYTES).splitlines()
        entry = json.loads(lines[index]) if 0 <= index < len(lines) else None
    except (OSError, ValueError) as err:  # ContractError is a ValueError
        raise RuntimeError('the Slurm manifest %s cannot be read: %s' % (where, err))
    if entry is None:
        raise RuntimeError('the Slurm manifest %s has no such line (%d line(s))' % (where, len(lines)))
    if not (isinstance(entry, dict) and isinstance(entry.get('student'), str) and
            isinstance(entry.get('submission'), str) and isinstance(entry.get('refused', ''), str) and
            isinstance(entry.get('folder', ''), str) and
            (entry.get('participant') is None or type(entry.get('participant')) is int)):
        raise RuntimeError('the Slurm manifest %s is not a student\'s line ({"student", "submission"}): %s'
                           % (where, safe_text.one_line(lines[index])[:200]))
    return entry


def run_task(manifest, index, out_dir, sheet=None, unsandboxed=False):
    """Grade line ``index`` of the manifest into ``out_dir/<name>``, as a local class run does, and leave
    the record for the host in ``results/<index>.json`` beside the manifest."""
    entry = manifest_entry(manifest, index)
    # scancel and the time limit send SIGTERM: exit through the finally blocks, which end the
    # session's processes and remove the work folder.
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    record = class_run.grade_student(entry['student'], entry['submission'], out_dir, sheet=sheet, unsandboxed=unsandboxed,
                                  refused=entry.get('refused'))
    # Which node graded it (a lost node's students are graded again elsewhere): in grade.json too.
    record = report.write_grade(os.path.join(out_dir, entry['student']),
                                dict(record, graded_on=os.environ.get('SLURMD_NODENAME') or socket.gethostname()))
    # Whole or not at all (the contract's writer): the host may look at any moment.
    contract.write_text(os.path.join(os.path.dirname(manifest), 'results', '%d.json' % index), json.dumps(record))
    return record


class _Array(object):
    """The class's tasks on Slurm: submitted, followed, retried once; the records as they come."""

    def __init__(self, students, base, script, name, sbatch_args, sheet, out_dir, say, progress):
        self.students, self.base, self.script, self.name = students, base, script, name
        self.sbatch_args, self.sheet, self.out_dir = list(sbatch_args), sheet, out_dir
        self.say, self.progress = say, progress
        self.jobs = []
        self.where = {}  # index -> the array job id of its current attempt
        self.attempts = dict((i, 0) for i in range(len(students)))
        self.last_seen = {}  # index -> (state, reason) squeue last gave
        self.gone_at = {}  # index -> when it left the queue without a record
        self.records = [None] * len(students)
        self.not_graded = 0

    def submit(self, indices):
        argv = ['sbatch', '--parsable', '--job-name', self.name, '--array', array_spec(indices),
                '--output', os.path.join(self.base, 'logs', '%A_%a.out'), '--time', str(TASK_MINUTES),
                '--ntasks', '1', '--cpus-per-task', '1', '--chdir', self.base,
                # A task whose node is lost ends NODE_FAIL rather than being requeued by Slurm
                # unseen: the retry below is the only one, counted and said.
                '--no-requeue'] + self.sbatch_args + [self.script]
        code, out, err = _call(argv)
        if code != 0 or not out.strip():
            raise RuntimeError('sbatch refused the class\'s array job (exit %d): %s' % (code, (err or out).strip()))
        job = out.strip().split(';')[0]
        self.jobs.append(job)
        for index in indices:
            self.where[index] = job
            self.attempts[index] += 1
            self.last_seen.pop(index, None)
            self.gone_at.pop(index, None)
        return job

    def cancel(self):
        if self.jobs:
            _call(['scancel'] + self.jobs)

    def queue(self):
        """This run's tasks in the queue, or None when squeue did not answer (nothing concluded then)."""
        code, out, err = _call(['squeue', '--me', '-h', '-r', '--name', self.name, '-o', '%F %K %T %r'])
        if code != 0:
            self.say('slurm: squeue failed (exit %d): %s; asking again' % (code, err.strip()))
            return None
        return dict((key, value) for key, value in parse_squeue(out).items() if key[0] in self.jobs)

    def _result(self, index):
        """The grade the task left in ``results/<index>.json``, None while there is none, read through the
        contract as the grader's record (:class:`~exam_lab.grader.score.kept.GradeRecord`): it holds a
        student's text, written on a node. One that is not that student's grade (its name, participant
        and Moodle's folder those of its manifest line) raises :class:`RecordError` saying why (that
        student is not graded, the class goes on: :meth:`look`)."""
        path = os.path.join(self.base, 'results', '%d.json' % index)
        if not contract.exists(path, self.base):
            return None
        record = contract.read_record(path, kept.GradeRecord, under=self.base)
        # Its name compared as it is cleaned when made (a listing's name cleans to itself: identity.student_name).
        name, entry = self.students[index][0], os.path.basename(os.path.abspath(self.students[index][1]))
        if record.student != safe_text.clean(name):
            raise RecordError('%s: the grade of %s, not of %s' % (kept.GradeRecord.FILE, shown(record.student),
                                                                 shown(name)))
        if (record.participant, record.folder) != (identity.participant_number(entry), entry):
            raise RecordError('%s: the grade of participant %s (folder %s), not of participant %s (folder %s)' % (
                kept.GradeRecord.FILE, record.participant, shown(record.folder), identity.participant_number(entry),
                shown(entry)))
        return record.value

    def _finished(self, index, record):
        self.records[index] = record
        if self.progress:
            self.progress.finished(record)

    def give_up(self, index, why, said='Slurm said'):
        name = self.students[index][0]
        log = os.path.join(self.base, 'logs', '%s_%d.out' % (self.where[index], index))
        record = grades.could_not_grade(name, self.sheet, '%s: %s' % (said, why),
                                        ['the task\'s output: %s' % log if os.path.isfile(log) else
                                         'the task left no output'])
        report.write_grade(os.path.join(self.out_dir, name), record)
        self.not_graded += 1
        self._finished(index, record)

    def look(self, now):
        """One look at the queue and the results; resubmit what ended without a grade. The state line."""
        tasks = self.queue()
        if tasks is None:
            return None
        retry = []
        for index, (name, _) in enumerate(self.students):
            if self.records[index] is not None:
                continue
            try:
                record = self._result(index)
            except RecordError as err:
                # Written whole on the node, then renamed: a grade that does not match is no lag of
                # the file system, and grading again would write the same. This student only.
                self.say('slurm: %s (task %s_%d) left a grade that is not one: %s'
                         % (name, self.where[index], index, err))
                self.give_up(index, err, said='its results/%d.json is not its grade record' % index)
                continue
            if record is not None:
                self._finished(index, record)
                continue
            seen = tasks.get((self.where[index], index))
            if seen is not None:
                if seen[0] not in PENDING and self.last_seen.get(index, ('PENDING',))[0] in PENDING and self.progress:
                    self.progress.started(name)
                self.last_seen[index] = seen
                continue
            why = self._ended_without_record(index, now)
            if why is None:
                continue
            if self.attempts[index] < ATTEMPTS:
                self.say('slurm: %s (task %s_%d) ended without a grade: %s; submitting it again'
                         % (name, self.where[index], index, why))
                retry.append(index)
            else:
                self.give_up(index, why)
        if retry:
            job = self.submit(retry)
            self.say('slurm: job %s: %d task(s) submitted again (%s)' % (job, len(retry), array_spec(retry)))
        graded = sum(1 for r in self.records if r is not None) - self.not_graded
        again = sum(1 for n in self.attempts.values() if n > 1)
        return state_line(self.jobs, tasks, graded, self.not_graded, len(self.students), again)

    def _ended_without_record(self, index, now):
        """Why the task is over without a record, or None while it may still be alive or its record on
        its way (squeue and the shared file system each lag a little)."""
        self.gone_at.setdefault(index, now)
        code, out, _ = _call(['scontrol', 'show', 'job', '%s_%d' % (self.where[index], index)])
        fields = parse_scontrol(out) if code == 0 else {}
        state = fields.get('JobState')
        if state and state not in ENDED:
            return None
        if state in (None, 'COMPLETED') and now - self.gone_at[index] < RESULT_GRACE_S:
            return None
        if state == 'COMPLETED':
            return 'COMPLETED, but the task left no grade'
        return slurm_said(fields, self.last_seen.get(index))

    def expire(self, seconds):
        """Out of time: cancel what is left; each student not done is not graded, with its last state."""
        self.cancel()
        for index in range(len(self.students)):
            if self.records[index] is None:
                seen = self.last_seen.get(index)
                self.give_up(index, 'no grade within %.0f s; last seen %s' % (
                    seconds, ', '.join(w for w in seen if w and w != 'None') if seen else 'never'))


def grade_class(class_path, out_dir, *, sheet=None, progress=None, unsandboxed=False, sbatch_args=(),
                poll_s=POLL_S, timeout=None):
    """Grade every student of a class on Slurm; write each one's grade and grades.csv as
    :func:`~exam_lab.grader.class_run.grade_class` does; return the records in the same order.

    :param progress: a :class:`~exam_lab.grader.publish.progress.ClassProgress`; it is also told the
        array's state and the retries (its ``say``).
    :param sbatch_args: added to sbatch's (``--partition``, ``--account``, ``--mem``: the cluster's own).
    :param timeout: seconds after which what is left is cancelled and not graded (None: wait).
    """
    refusal = sandbox.sandbox_refusal(unsandboxed)
    if refusal:
        raise sandbox.SandboxUnavailable(refusal)
    missing = [c for c in ('sbatch', 'squeue', 'scontrol', 'scancel') if shutil.which(c) is None]
    if missing:
        raise RuntimeError('the Slurm engine needs %s on PATH (Debian: slurm-client; the cluster\'s own '
                           'client elsewhere)' % ', '.join(missing))
    out_dir = os.path.abspath(out_dir)
    base = os.path.join(out_dir, '.slurm')
    shutil.rmtree(base, ignore_errors=True)
    for folder in ('results', 'logs'):
        os.makedirs(os.path.join(base, folder))
    say = progress.say if progress else (lambda line: None)
    work_dirs, refused = [], {}  # refused: students whose files the intake refused by their own bounds
    try:
        students = class_run.class_students(class_path, work_dirs, refused=refused, out=out_dir)
        students, refused = shared_students(students, work_dirs, os.path.join(base, 'class'), refused)
        records, array = _grade(students, refused, base, out_dir, sheet, progress, unsandboxed, sbatch_args,
                                poll_s, timeout, say)
    finally:
        for work in work_dirs:
            shutil.rmtree(work, ignore_errors=True)
    report.write_csv(os.path.join(out_dir, 'grades.csv'), records)
    if array is not None and array.not_graded:
        shutil.rmtree(os.path.join(base, 'class'), ignore_errors=True)
        say('slurm: the tasks\' output is kept in %s' % os.path.join(base, 'logs'))
    else:
        shutil.rmtree(base, ignore_errors=True)
    return records


def shared_students(students, work_dirs, shared, refused):
    """The students as the nodes must see them. A folder class is read where it is (the class is on the
    shared file system). An archive was unpacked by the intake's box in this host's temp folder (as a
    local run does: a box's uid may not reach a private OUT): each student's folder is copied into
    ``shared`` (under OUT), as an upload is staged for a box (links kept as links, never followed;
    FIFOs and devices left out), the class's size already bounded by the intake's box. Returns the
    students and ``refused`` (folder -> why the intake refused it) at the folders the nodes see."""
    if not work_dirs:
        return students, refused
    os.makedirs(shared, mode=0o711, exist_ok=True)
    copied, refused_there = [], {}
    for index, (name, folder) in enumerate(students):
        target = os.path.join(shared, str(index), os.path.basename(folder))
        os.makedirs(os.path.dirname(target), mode=0o711)
        if folder in refused:
            # Refused by its own bounds: nothing of it is read again (its row says why).
            os.makedirs(target, mode=0o711)
            refused_there[target] = refused[folder]
        else:
            staging.stage_upload(folder, target, max_bytes=1 << 62, max_files=1 << 62)
        copied.append((name, target))
    for work in work_dirs:
        shutil.rmtree(work, ignore_errors=True)
    del work_dirs[:]
    return copied, refused_there


def _grade(students, refused, base, out_dir, sheet, progress, unsandboxed, sbatch_args, poll_s, timeout, say):
    """The array of these students, followed to its end: ``(records, the array or None)``."""
    records, array = [], None
    if students:
        underlay.ensure_underlay(underlay.default_underlay())  # here, once, rather than by the first tasks at once
        manifest = os.path.join(base, 'manifest.jsonl')
        entries = [os.path.basename(os.path.abspath(folder).rstrip('/')) for _, folder in students]
        contract.write_text(manifest, ''.join(json.dumps(dict(
            {'student': name, 'submission': os.path.abspath(folder), 'participant': identity.participant_number(entry),
             'folder': entry}, **({'refused': refused[folder]} if folder in refused else {}))) + '\n'
            for (name, folder), entry in zip(students, entries)))
        script = os.path.join(base, 'task.sh')
        write_task_script(script, manifest, out_dir, sheet, unsandboxed)
        if progress:
            progress.begin([name for name, _ in students])
        array = _Array(students, base, script, job_name(out_dir), sbatch_args, sheet, out_dir, say, progress)
        records = _follow(array, poll_s, timeout, say)
    return records, array


def _follow(array, poll_s, timeout, say):
    """Submit the array and follow it to its end; on any way out but the end (Ctrl-C), cancel it."""
    start = time.monotonic()
    try:
        job = array.submit(range(len(array.students)))
        say('slurm: job %s submitted: %d tasks, one per student' % (job, len(array.students)))
        shown = None
        while True:
            now = time.monotonic()
            line = array.look(now)
            if line is not None and line != shown:
                say(line)
                shown = line
            if all(r is not None for r in array.records):
                return array.records
            if timeout is not None and now - start > timeout:
                array.expire(timeout)
                return array.records
            time.sleep(poll_s)
    except BaseException:
        array.cancel()
        raise


def main(argv=None):
    """The task's entry point (the batch script written by :func:`write_task_script`)."""
    parser = argparse.ArgumentParser(description='grade one line of a Slurm manifest (a task of the array)')
    parser.add_argument('command', choices=['task'])
    parser.add_argument('manifest')
    parser.add_argument('index', type=int)
    parser.add_argument('--out', required=True)
    parser.add_argument('--sheet')
    parser.add_argument('--unsandboxed', action='store_true')
    args = parser.parse_args(argv)
    try:
        run_task(args.manifest, args.index, args.out, args.sheet, args.unsandboxed)
    except RuntimeError as err:  # the manifest's line unusable: one sentence in the task's log
        print('exam_lab.grader.engine.slurm task %d: %s' % (args.index, err), file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
