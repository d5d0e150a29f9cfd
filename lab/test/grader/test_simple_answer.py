"""The simple answer of docs/report.md (docs/simple_answer/exam, what a student can write in three
hours) gets full marks on both sheets from the grader, and stays out of every catkin build of this
repository (it is a second package named ``exam``). About 45 s per sheet.
"""
import os

import pytest
from catkin_pkg.packages import find_packages

from exam_lab.grader import runner
from exam_lab.grader.score.sheets import ITEMS

REPO = os.path.realpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', '..'))
SIMPLE = os.path.join(REPO, 'docs', 'simple_answer', 'exam')


@pytest.mark.parametrize('sheet', ['altitude', 'depth'])
def test_the_simple_answer_gets_full_marks(tmp_path, sheet):
    record = runner.grade_submission(SIMPLE, str(tmp_path / sheet), sheet=sheet)
    got = {i['id']: i['points'] for i in record['items']}
    evidence = '\n'.join('%s %s/%s: %s' % (i['id'], i['points'], i['max'], i['evidence']) for i in record['items'])
    assert got == {item: points for item, (points, _) in ITEMS.items()}, evidence
    assert record['total'] == record['max'] == 17.0


def test_the_simple_answer_is_no_package_of_the_repository():
    # catkin_make in a workspace holding this repository (README: "In your own catkin workspace")
    # finds packages the way catkin_pkg does: the simple answer's CATKIN_IGNORE keeps it out.
    names = [package.name for package in find_packages(REPO).values()]
    assert names.count('exam') == 1, names
    assert os.path.isfile(os.path.join(SIMPLE, 'package.xml'))
