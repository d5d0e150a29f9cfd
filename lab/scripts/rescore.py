#!/usr/bin/env python3
"""Grade a class again with today's rubric, from the measurements its run kept: nothing is run again.

    rescore.py --out OUT [--worksheet WORKSHEET.csv]     (make rescore OUT=...)

For each student of OUT (or the one submission graded there), the rubric is applied to the
measurements.json that ``make grade`` kept beside its grade.json; grade.json (with the points it had,
``previous``, and its provenance), grade.md, grades.csv, the page, results.json, moodle-feedback.zip, hand.csv (the
teacher's points kept) and moodle-worksheet.csv (from the worksheet kept in OUT) are written again, each
student's report.json read back as its record (the report is never read again: a student whose report
was not read, or whose report.json is not a record of the grader, is said), and each student whose
points or status moved is printed
with the items that moved; a student whose measurements.json or grade.json is not a record of the
grader is listed as not rescored (its files left as they were; the exit status is 1). No ROS, no
sandbox, no root. A change of the rubric that needs measurements
the run did not make (a new flight, another input) needs make grade again (docs/grading.md).
"""
import argparse
import os
import sys

from exam_lab.grader.publish import desk, grades, proposals, report
from exam_lab.grader.score import safe_text


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--out', required=True, help='the folder make grade wrote')
    parser.add_argument('--worksheet', help="Moodle's offline grading worksheet (CSV); default: the one kept in OUT")
    args = parser.parse_args(argv)
    out = os.path.realpath(args.out)  # the teacher's path, followed once; nothing below it is
    if not os.path.isdir(out) or not grades.graded_folders(out):
        print('rescore: no measurements.json in %s (graded before measurements were kept? run make grade '
              'again)' % out, file=sys.stderr)
        return 1
    records, lines = grades.rescore(out)
    refused = [line for line in lines if grades.NOT_RESCORED in line]
    changes = [line for line in lines if line not in refused]
    print(report.table(records))
    print('%d of %d student(s) changed:' % (len(changes), len(records)) if changes else
          'no point changed for any of the %d student(s)' % len(records))
    for line in changes:
        print('  ' + safe_text.one_line(line))
    if refused:  # the others are rescored; these keep their files as they were
        print('%d student(s) NOT rescored (a kept file that is not a record of the grader):' % len(refused))
        for line in refused:
            print('  ' + safe_text.one_line(line))
    # Each student's report as its run read it (report.json, checked as a box's record is): never read
    # again from the PDF, no box here. One not read, or a kept file refused, is said.
    for folder in grades.graded_folders(out):
        kept = proposals.kept_report(folder)
        if kept.state != 'read':
            print('  report of %s not read: %s' % (safe_text.one_line(os.path.basename(folder)), safe_text.one_line(kept.why)))
    single = grades.graded_folders(out) == [out]
    # The run's similarity check, read as its record (capped, checked, its text clean); one that is
    # not is said where its pairs would be.
    similar = None if single else desk.read_similarity(out)
    for line in desk.finish(out, records, single=single, similar=similar, worksheet=args.worksheet):
        print(line)
    for line in desk.next_commands(out, records):
        print(line)
    return 1 if refused else 0


if __name__ == '__main__':
    sys.exit(main())
