"""Fixtures shared by the grader's test modules: each class run here is graded once a session and
read by several modules (a grading costs about 45 s of a slot; issue 37 point 6)."""
import os

import pytest

import hostile_run


@pytest.fixture(scope='session')
def hostile_class(tmp_path_factory):
    """The one class of every hostile student and one victim (:mod:`hostile_run`), graded once."""
    if os.geteuid() != 0:
        pytest.skip('the sandbox is made by root (docs/grading.md, "Isolation")')
    yield from hostile_run.grade(str(tmp_path_factory.mktemp('hostile')))


@pytest.fixture(scope='session')
def main_class(tmp_path_factory):
    """test_grade's main class (:func:`test_grade.grade_main_class`) graded once, its desk written as
    ``make grade`` writes it (the page, the feedback zip, the similarity check): test_grade reads its
    records, test_page_browser opens its pages. ``{'out', 'klass', 'records' (graded order), 'by_name',
    'lines' (what the desk printed)}``."""
    import test_grade
    from exam_lab.grader import class_run
    from exam_lab.grader.publish import desk
    out, records, klass = test_grade.grade_main_class(tmp_path_factory.mktemp('grader'))
    lines = desk.finish(str(out), records, similar=class_run.class_similarity(str(klass), str(out), records))
    return {'out': str(out), 'klass': str(klass), 'records': records, 'by_name': {r['student']: r for r in records},
            'lines': lines}
