"""Gradescope's autograder format: each student's ``results.json``. No rospy here.

Gradescope runs an autograder's ``run_autograder`` and reads ``/autograder/results/results.json``:
``{"score", "output", "tests": [{"name", "score", "max_score", "output", "status"}], ...}`` (their
"Autograder specifications"). A course on Gradescope wraps ``grade.py --submission`` in that script and
copies this file; a class graded here gets one per student, to upload with Gradescope's API tools.
"""
import json
import os

from exam_lab.grader import contract
from exam_lab.grader.publish import student_view
from exam_lab.grader.score.sheets import ITEMS

#: Statuses whose score is the grade; the others are shown to the teacher only until a hand grade.
GRADED = ('graded', 'graded with fixes')


def results(record):
    """The results.json of one grade record: a :class:`~exam_lab.grader.score.kept.GradeRecord`'s value
    (the desk's, :func:`exam_lab.grader.publish.desk.finish`), its text made safe where the record was
    made; what is added here is the grader's own words, and the threshold run's value taken out."""
    status = record.get('status', 'graded')
    tests = []
    for entry in record['items']:
        tests.append({'name': '%s: %s' % (entry['id'], ITEMS[entry['id']][1]) if entry['id'] in ITEMS
                      else entry['id'],
                      'score': entry['points'], 'max_score': entry['max'],
                      'status': 'passed' if entry['points'] >= entry['max'] else 'failed',
                      'output': student_view.item_words(entry, record, first_line=False)
                      if entry.get('evidence') else ''})
    output = 'Graded by running the package (sheet %s): %s / %s. Not scored by the machine: comments, code ' \
             'quality and the report.' % (record.get('sheet') or '-', record['total'], record['max'])
    out = {'score': record['total'], 'output': output, 'tests': tests, 'stdout_visibility': 'hidden',
           'extra_data': {'status': status,
                          'status_reason': student_view.scrub(record.get('status_reason', ''), student_view.hidden(record)),
                          'student': record['student']}}
    if status not in GRADED:
        out['output'] = 'Needs the teacher (%s): %s' % (status, out['extra_data']['status_reason'])
        out['visibility'] = 'hidden'  # a grade only the teacher sees until it is settled by hand
    return out


def write(out_dir, record):
    """Write ``out_dir/results.json``; return its path."""
    path = os.path.join(out_dir, 'results.json')
    contract.write_text(path, json.dumps(results(record), indent=1, sort_keys=True) + '\n')
    return path
