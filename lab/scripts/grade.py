#!/usr/bin/env python3
"""Grade a student's exam package, or a class of them, by running it (docs/grading.md).

    grade.py --submission DIR_OR_ZIP [--sheet altitude|depth] [--out DIR]
    grade.py --class DIR_OR_ZIP [--sheet altitude|depth] [--out DIR] [--jobs N] [--worksheet CSV]
             [--engine local|slurm [--slurm-args '--partition=... --account=...']]

Besides the grades, OUT/index.html (the page for the teacher), each student's results.json
(Gradescope) and flight.png, the hand points proposed (OUT/proposals.csv, from the reference outputs
of the sheet's drone, run once: OUT/reference-<sheet>.json), for a class the similarity check and,
with --worksheet, Moodle's offline grading worksheet with the whole grades once the hand points are
given (the teacher's desk: lab/src/exam_lab/grader/publish/desk.py). The last lines are the commands
that come next, OUT quoted.

Prints the score table (every line cleaned of control characters: it carries students' text);
exits 0 whenever grading completed, whatever the scores, and 1 when the
grader itself could not run (a missing input, the simulators not building, no sandbox: student code
runs only in its sandbox, unless --unsandboxed-student-code-can-read-and-damage-my-files is given).
Ctrl-C, SIGTERM and SIGHUP (a closed terminal) stop it, exit 130: every process the grading started
ends with it, as it does when it is killed (exam_lab.harness.supervisor's "Lifetime").
"""
import argparse
import os
import shlex
import sys

from exam_lab.grader import class_run, runner, workspace

from exam_lab.grader.engine import slurm
from exam_lab.grader.host import reference

from exam_lab.grader.publish import desk, moodle, progress, report
from exam_lab.grader.score import records, safe_text
from exam_lab.grader.score.sheets import SHEETS
from exam_lab.harness import supervisor


def say(line, stream=None):
    """Print ``line`` for the teacher with no control character in it (a student's escape sequence
    could move the cursor and rewrite the summary above)."""
    (stream or sys.stdout).write(safe_text.clean(line) + '\n')


def main(argv=None):
    try:
        return grade(argv)
    except KeyboardInterrupt as err:
        say('grade: stopped (%s): nothing more is graded; what was written in OUT stays' % (err or 'Ctrl-C'),
            sys.stderr)
        sys.stdout.flush()
        sys.stderr.flush()
        # A class's gradings still going on in their threads are not waited for (exit would join them):
        # their processes end with this one.
        os._exit(130)


def grade(argv):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    what = parser.add_mutually_exclusive_group(required=True)
    what.add_argument('--submission', help='a folder holding the exam package, or its zip')
    what.add_argument('--class', dest='klass', help='a folder (or zip) with one sub-folder per student')
    parser.add_argument('--sheet', choices=list(SHEETS), help='default: detected from the package')
    parser.add_argument('--out', help='output folder (default: $EXAM_WS/grades/<name without its archive ending, '
                        'spaces and parentheses as _>)')
    parser.add_argument('--jobs', type=int, default=None,
                        help='students graded side by side (class; default: from the cores, the memory and '
                        'the CPU a grading takes, %d here)' % class_run.default_jobs())
    parser.add_argument('--unsandboxed-student-code-can-read-and-damage-my-files', dest='unsandboxed',
                        action='store_true', help='grade even where no sandbox can be made (never as root: '
                        'as root the code runs as a user of its own, with limits)')
    parser.add_argument('--worksheet', help="Moodle's offline grading worksheet (CSV), kept in OUT and filled "
                        "with the whole grades (machine + hand points) as they are given")
    parser.add_argument('--no-similarity', action='store_true', help='skip the similarity check (class)')
    parser.add_argument('--engine', choices=['local', 'slurm'], default='local',
                        help='where a class is graded: here, JOBS at a time, or one Slurm array task per student')
    parser.add_argument('--slurm-args', default='', help="sbatch's options for the cluster, e.g. "
                        "'--partition=short --account=ros101' (with --engine slurm)")
    args = parser.parse_args(argv)
    if args.jobs is not None and args.jobs < 1:
        parser.error('--jobs (JOBS) must be 1 or more, not %d' % args.jobs)
    if args.engine == 'slurm' and not args.klass:
        parser.error('--engine slurm grades a class (--class): one array task per student')
    target = args.submission or args.klass
    if not os.path.exists(target):
        say('grade: %s does not exist' % target, sys.stderr)
        return 1
    out = os.path.abspath(args.out or os.path.join(workspace(), 'grades', moodle.out_name(os.path.abspath(target))))
    try:
        if args.submission:
            record = runner.grade_submission(args.submission, out, sheet=args.sheet, on_step=progress.StepProgress(),
                                             unsandboxed=args.unsandboxed)
            say(report.table([record]))
            if record.get('status_reason'):
                say('%s: %s' % (record['status'], record['status_reason']))
            for doubt in record.get('doubts') or []:
                say('look at: %s' % doubt)
            for line in report.evidence_lines(record):
                say('  ' + line)
            say('grade.json and grade.md in %s' % out)
            for line in reference.keep_for(out, [record.get('sheet') or 'altitude']):
                say(line)
            for line in desk.finish(out, [record], single=True, worksheet=args.worksheet) + \
                    desk.next_commands(out, [record]):
                say(line)
        else:
            jobs = args.jobs or class_run.default_jobs()
            shown = progress.ClassProgress(jobs)
            try:
                if args.engine == 'slurm':
                    graded = slurm.grade_class(args.klass, out, sheet=args.sheet, progress=shown,
                                               unsandboxed=args.unsandboxed, sbatch_args=shlex.split(args.slurm_args))
                else:
                    graded = class_run.grade_class(args.klass, out, sheet=args.sheet, jobs=jobs, progress=shown,
                                                   unsandboxed=args.unsandboxed)
            finally:
                shown.close()
            say(report.table(graded))
            waiting = report.needing_the_teacher(graded)
            if waiting:
                say('\n%d student(s) need the teacher (their points are not a grade yet):' % len(waiting))
                for line in waiting:
                    say('  ' + line)
            say('grades.csv and one folder per student in %s' % out)
            for line in reference.keep_for(out, [r.get('sheet') or 'altitude' for r in graded]):
                say(line)
            for line in desk.finish(out, graded, similar=None if args.no_similarity else
                                    class_run.class_similarity(args.klass, out, graded), worksheet=args.worksheet,
                                    title=moodle.class_name(args.klass)) + desk.next_commands(out, graded):
                say(line)
    except RuntimeError as err:
        say('grade: %s' % err, sys.stderr)
        return 1
    except records.UnpackError as err:  # the class archive itself (one student's upload never gets here)
        say('grade: the class archive cannot be opened safely: %s' % err, sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    supervisor.own_processes()  # what it starts ends with it, however it ends (the supervisor's "Lifetime")
    sys.exit(main())
