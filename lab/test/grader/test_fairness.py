"""Fairness on generated student answers (issue 35 point 7), the sample of `make test`: 10 answers drawn
from `make fairness`'s matrix (lab/src/exam_lab/fairness/generator.py: half correct, half one-mistake,
both sheets) graded in ONE class run at the default JOBS, each held to what it must get: a correct
answer 17/17 "graded", a one-mistake answer its rule's loss only, or flagged for the teacher.

GRADED_WRONG_TODAY names the drawn answers the judge grades wrong on the code this test was written
against (the whole matrix's table: docs/grading.md, "Generated answers"): each is a strict xfail, so
the test fails as soon as the judge grades it right too, and the entry must then go. About 5 minutes.
"""
import pytest

from exam_lab.fairness import generator
from exam_lab.grader import runner

SAMPLE = generator.sample(10)

#: Answer -> how the judge grades it wrong today (from `make fairness` on that code); empty once the
#: judge is fair to every drawn answer.
GRADED_WRONG_TODAY = {}


@pytest.fixture(scope='module')
def graded(tmp_path_factory):
    root = tmp_path_factory.mktemp('fairness')
    klass = generator.write_class(SAMPLE, str(root / 'class'))
    records = runner.grade_class(klass, str(root / 'out'), jobs=runner.default_jobs())
    return {r['student']: r for r in records}


def _cases():
    for answer in SAMPLE:
        marks = [pytest.mark.xfail(strict=True, reason=GRADED_WRONG_TODAY[answer.name])] \
            if answer.name in GRADED_WRONG_TODAY else []
        yield pytest.param(answer, id=answer.name, marks=marks)


@pytest.mark.parametrize('answer', list(_cases()))
def test_each_drawn_answer_gets_what_it_must(graded, answer):
    record = graded[answer.name]
    fair, how = generator.verdict(answer, record)
    evidence = '\n'.join('%s %s/%s: %s' % (i['id'], i['points'], i['max'], i['evidence']) for i in record['items'])
    assert fair, '%s (%s)\n%s' % (how, generator.MISTAKES[answer.mistake].words if answer.mistake else 'correct',
                                  evidence)


def test_the_sample_is_mixed():
    assert len(SAMPLE) == 10
    assert 0 < len([a for a in SAMPLE if a.mistake]) < 10
    assert set(a.style.sheet for a in SAMPLE) == {'altitude', 'depth'}
