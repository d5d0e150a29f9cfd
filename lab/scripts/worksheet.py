#!/usr/bin/env python3
"""The whole grade into Moodle's worksheet: the machine's points (OUT's grade.json files) and the
teacher's hand points (OUT/hand.csv), on the worksheet's own scale (docs/grading.md).

    worksheet.py --out OUT [--worksheet WORKSHEET.csv]     (make worksheet OUT=... [WORKSHEET=...])

Writes OUT/moodle-worksheet.csv, the one file to upload into Moodle: each grade out of the worksheet's
maximum grade (30 points scaled), each feedback comment listing every item, the machine's and the
teacher's; and OUT/moodle-feedback.zip, each released student's page (publish/feedback.py). The
worksheet is the one given, else the one make grade or an earlier make worksheet kept in OUT
(worksheet-as-downloaded.csv). A student whose hand points are not all given, or whose status waits
for the teacher, is left blank and listed; with no whole grade at all, no file is written. A
student's hand points are the row of hand.csv with its participant number (the name only where the
class has no numbers): a row that could be another student's stops it, naming both. A student whose
grade.json an older grader wrote is left out (its row as it was), said: "graded by an older grader:
grade again"; a grade.json that is no grade at all stops it, named. Exits 0 when the
worksheet was filled, 1 when it could not be (hand.csv, its rows or the worksheet unusable: every
problem is printed). No ROS, no sandbox, no root: it reads records only.
"""
import argparse
import os
import sys

from exam_lab.grader import contract
from exam_lab.grader.publish import desk, feedback, grades, hand, moodle
from exam_lab.grader.score import safe_text
from exam_lab.grader.score.schema import RecordError


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--out', required=True, help='the folder make grade wrote (grade.json files, hand.csv)')
    parser.add_argument('--worksheet', help="Moodle's offline grading worksheet (CSV); default: the one kept in OUT")
    args = parser.parse_args(argv)
    args.out = os.path.realpath(args.out)  # the teacher's path, followed once; nothing below it is
    older = []
    try:
        records = grades.records_in(args.out, older=older)
    except RecordError as err:
        # Filled from a grade that is not one, a row could be wrong: nothing is written until it is
        # graded or rescored again.
        print('worksheet: NOT filled: %s (make rescore, or make grade for that student)'
              % safe_text.clean(str(err)), file=sys.stderr)
        return 1
    for line in older:  # a grade of an older grader: that student's row is left as it was, the class filled
        print('worksheet: left out: %s' % safe_text.one_line(line))
    if not records:
        print('worksheet: no grade.json%s in %s: run make grade first'
              % (' of today\'s grader' if older else '', args.out), file=sys.stderr)
        return 1
    records, twice = hand.newest(records)  # one participant graded twice: its newest, said; never the class's
    for line in twice:
        print(safe_text.one_line(line))
    if not args.worksheet and not contract.exists(os.path.join(args.out, moodle.DOWNLOADED)):
        print('worksheet: no worksheet kept in %s: give the one downloaded from Moodle, WORKSHEET="..." '
              '(Assignment > View all submissions > Grading action: Download grading worksheet)' % args.out,
              file=sys.stderr)
        return 1
    records = desk.with_sheets(args.out, records, single=grades.graded_in(args.out) == [args.out])
    path = os.path.join(args.out, hand.FILE)
    if not contract.exists(path):
        print('worksheet: no %s: every student\'s hand points are missing (make grade writes it)' % path)
    try:
        lines = desk.worksheet_lines(args.out, records, args.worksheet)
    except (hand.HandError, moodle.WorksheetError, OSError) as err:
        print('worksheet: NOT filled: %s' % safe_text.clean(str(err)), file=sys.stderr)
        return 1
    for line in lines:
        print(line)
    for line in feedback.write(args.out, records, single=grades.graded_in(args.out) == [args.out]):
        print(line)
    return 0


if __name__ == '__main__':
    sys.exit(main())
