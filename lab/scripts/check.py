#!/usr/bin/env python3
"""A student's own check: grade one's exam package as the teacher's grader does, on one's own machine.

    check.py --package DIR_OR_ZIP [--sheet altitude|depth] [--report PDF]

(``make check PACKAGE=<dir|zip> [SHEET=...]``; docs/grading.md, "A student's own check".) The same code
as the teacher's grade (``runner.grade_submission``): the package built on top of the same drones'
simulators, run against the same probe, scored by the same rubric, as an ordinary user without root
or sudo, in about a minute (plus about a minute, once, to build the simulators). Prints only what the
teacher chose to show (lab/check_visibility.ini: the points, or the points and the evidence; never the
threshold run nor its hidden value) and keeps nothing of the grade. The report (in the package's
folder or zip, or ``--report``) is read as the teacher's grader reads it, and the check says which of
questions 4-9 have an answer found by its question's number and which have none, or why the report
was not read (never the points proposed: the teacher confirms them).

No sandbox is needed for one's own code on one's own machine: the grader's box is used where it can be
made without root (bubblewrap, with unprivileged user namespaces, as on Debian 12 and Ubuntu 20.04),
otherwise the package runs as you, with the box's limits, without asking for the teacher's flag.

Exits 0 when the check ran, whatever the points; 1 when it could not (a missing package, the
simulators not building, a bad setting file).
"""
import argparse
import os
import shutil
import sys
import tempfile

from exam_lab.grader import runner
from exam_lab.grader.host import sandbox
from exam_lab.grader.host.underlay import default_underlay, ensure_underlay

from exam_lab.grader.publish import progress, student_view

try:  # the report reader (issue 47 point 1)
    from exam_lab.grader.host import reports
except ImportError:  # a grader without it: the check says nothing of the report
    reports = None
from exam_lab.grader.score.sheets import SHEETS
from exam_lab.harness import supervisor

#: The teacher's choice of what the check shows.
SETTING = os.path.join(os.path.dirname(os.path.dirname(os.path.realpath(__file__))), 'check_visibility.ini')


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--package', required=True, help='your exam package: its folder, or the zip you upload')
    parser.add_argument('--sheet', choices=list(SHEETS), help='default: detected from the package')
    parser.add_argument('--report', help='your report (its PDF), when it is not in the package\'s folder or zip')
    args = parser.parse_args(argv)
    if not os.path.exists(args.package):
        sys.stderr.write('check: %s does not exist\n' % args.package)
        return 1
    try:
        show = student_view.read_setting(SETTING)
    except ValueError as err:
        sys.stderr.write('check: %s\n' % err)
        return 1
    why = sandbox.check()
    if why is None:
        print('check: your package runs in the grader\'s sandbox (bubblewrap), as on the teacher\'s machine.')
    else:
        print('check: your package runs as you, without the grader\'s sandbox (%s): none is needed for your '
              'own code on your own machine.' % why)
    out = tempfile.mkdtemp(prefix='exam-check-')
    try:
        print('check: building the simulators (once: about a minute the first time)...')
        underlay = ensure_underlay(default_underlay())
        print('check: grading %s (about a minute)...' % args.package)
        record = runner.grade_submission(args.package, out, sheet=args.sheet, student='your package', underlay=underlay,
                                         on_step=progress.StepProgress(), unsandboxed=why is not None)
        report = None
        if reports is not None:
            print('check: reading your report...')
            report = reports.read_report(args.report or args.package, os.path.join(out, 'report')).value
    except RuntimeError as err:
        sys.stderr.write('check: %s\n' % err)
        return 1
    finally:
        shutil.rmtree(out, ignore_errors=True)
    print('\nyour package, sheet %s (%s):' % (SHEETS[record['sheet']].seed, record['sheet']))
    for line in student_view.lines(record, show):  # the threshold run, if any, is the record's
        print(line)
    if reports is not None:
        print('')
        for line in student_view.report_lines(report, show):
            print(line)
    return 0


if __name__ == '__main__':
    supervisor.own_processes()  # what it starts ends with it, however it ends (the supervisor's "Lifetime")
    sys.exit(main())
