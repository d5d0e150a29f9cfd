#!/usr/bin/env python3
"""The whole grade into Moodle's worksheet: the machine's points (OUT's grade.json files) and the
teacher's hand points (OUT/hand.csv), on the worksheet's own scale (docs/grading.md).

    worksheet.py --out OUT --worksheet WORKSHEET.csv     (make worksheet OUT=... WORKSHEET=...)

Writes OUT/<worksheet>-whole.csv, each grade out of the worksheet's maximum grade (30 points scaled),
each feedback comment listing every item, the machine's and the teacher's; and OUT/moodle-feedback.zip,
each released student's page with the whole grade (publish/feedback.py). A student whose hand
points are not all given, or whose status waits for the teacher, is left as it was and listed. A
student's hand points are the row of hand.csv with its participant number (the name only where the
class has no numbers): a row that could be another student's stops it, naming both. Exits 0 when the
file was written, 1 when it could not be (hand.csv, its rows or the worksheet unusable: every problem
is printed). No ROS, no sandbox, no root: it reads records only.
"""
import argparse
import os
import sys

from exam_lab.grader import contract
from exam_lab.grader.publish import feedback, grades, hand, moodle
from exam_lab.grader.score import safe_text
from exam_lab.grader.score.schema import RecordError


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--out', required=True, help='the folder make grade wrote (grade.json files, hand.csv)')
    parser.add_argument('--worksheet', required=True, help="Moodle's offline grading worksheet (CSV)")
    args = parser.parse_args(argv)
    args.out = os.path.realpath(args.out)  # the teacher's path, followed once; nothing below it is
    try:
        records = grades.records_in(args.out)
    except RecordError as err:
        # Filled from a grade that is not one, a row could be wrong: nothing is written until it is
        # graded or rescored again.
        print('worksheet: NOT filled: %s (make rescore, or make grade for that student)'
              % safe_text.clean(str(err)), file=sys.stderr)
        return 1
    if not records:
        print('worksheet: no grade.json in %s: run make grade first' % args.out, file=sys.stderr)
        return 1
    records, twice = hand.newest(records)  # one participant graded twice: its newest, said; never the class's
    for line in twice:
        print(safe_text.one_line(line))
    path = os.path.join(args.out, hand.FILE)
    try:
        hands = hand.read(path) if contract.exists(path) else {}
    except hand.HandError as err:
        print('worksheet: %s' % safe_text.clean(str(err)), file=sys.stderr)
        return 1
    if not contract.exists(path):
        print('worksheet: no %s: every student\'s hand points are missing (make grade writes it)' % path)
    try:
        rows, notes = hand.match(hands, records)
    except hand.HandError as err:
        print('worksheet: NOT filled: %s' % safe_text.clean(str(err)), file=sys.stderr)
        return 1
    for line in notes:
        print(safe_text.one_line(line))
    whole = [hand.combine(record, row) for record, row in zip(records, rows)]
    target = os.path.join(args.out, '%s-whole.csv' % os.path.splitext(os.path.basename(args.worksheet))[0])
    try:
        summary = moodle.fill_file(args.worksheet, target, whole, scale=True)
    except (moodle.WorksheetError, OSError) as err:
        print('worksheet: NOT filled: %s' % safe_text.clean(str(err)), file=sys.stderr)
        return 1
    for line in moodle.summary_lines(summary, target):
        print(line)
    missing = [r for r in whole if r['missing']]
    if missing:
        print('%d student(s) without all their hand points (left without a grade; fill %s and run this again):'
              % (len(missing), path))
        for record in missing:
            print('  %s: %s' % (safe_text.one_line(record['student']), ', '.join(record['missing'])))
    for line in feedback.write(args.out, records, single=grades.graded_in(args.out) == [args.out]):
        print(line)
    return 0


if __name__ == '__main__':
    sys.exit(main())
