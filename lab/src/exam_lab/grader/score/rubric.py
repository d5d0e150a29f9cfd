"""The rubric: points for each item from what was measured, and why. Pure functions, no rospy.

Input: ``static`` (what the runner read in the package: the launch file, the threshold parameter,
the parameters the code reads) and ``session`` (what :mod:`exam_lab.grader.host.session` measured: the
build, the main run and the threshold run, each with the probe's result). Output: one
``{"id", "points", "max", "evidence"}`` per item of :data:`exam_lab.grader.score.sheets.ITEMS`, the
grade's status and its doubts.

Both are read through their records' views (:mod:`~exam_lab.grader.score.fields`), taken here at the
entry: a caller passes the dicts as kept (``measurements.json``, a test) or the views. The rubric's parts:

- :mod:`~exam_lab.grader.score.tolerances`: each tolerance and weight, one constant (docs/grading.md
  says why each is what it is);
- :mod:`~exam_lab.grader.score.measured`: the session's runs and probes as the items read them;
- :mod:`~exam_lab.grader.score.node_items`: runs, Q10, Q11, Q12 (the node, its output, its launch file);
- :mod:`~exam_lab.grader.score.flight`: the flight's calls, legs and lags, the WARNING's window;
- :mod:`~exam_lab.grader.score.timing_items`: Q13, Q14a, Q14b (the warning service on the flight);
- :mod:`~exam_lab.grader.score.verdict`: the status, the doubts, the rules not observed, a crash's line.
"""
from exam_lab.grader.score.measured import session_of, static_of, threshold_run_value
from exam_lab.grader.score.node_items import score_q10, score_q11, score_q12, score_runs
from exam_lab.grader.score.timing_items import score_q13, score_q14a, score_q14b
from exam_lab.grader.score.verdict import GRADED, GRADED_WITH_FIXES, HAND_GRADE, NOT_GRADED, STATUSES, doubts, status

#: What the grader's callers use (publish/grades.py, the tests): the items, the status and its doubts.
__all__ = ['score', 'status', 'doubts', 'threshold_run_value',
           'GRADED', 'GRADED_WITH_FIXES', 'HAND_GRADE', 'NOT_GRADED', 'STATUSES']


def score(sheet, static, session):
    """Every item of the rubric, in order."""
    static, session = static_of(static), session_of(session)
    return [score_runs(session), score_q10(sheet, session), score_q11(sheet, session),
            score_q12(sheet, static, session), score_q13(sheet, session), score_q14a(sheet, static, session),
            score_q14b(sheet, session)]
