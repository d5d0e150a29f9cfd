"""What a student's own check prints (exam_lab.grader.publish.student_view) on synthetic records: each
setting shows what it says, and the threshold run (its hidden value, its flight, its problems) never
shows. The real check, as an unprivileged user, is lab/test/grader/test_nonroot.py."""
import html
import json
import os
import re

import pytest

from exam_lab.grader.publish import report, student_view
from exam_lab.grader.score.sheets import ITEMS

LAB = os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
#: The value the threshold run flew at: the student is never told it.
HIDDEN = '1040'
Q14A = 'launch file /threshold = 1300; set to %s, the node warned 5.00 s after reaching 1170.0' % HIDDEN
RUNS = ('builds (2 s); but: main run: node exam died (exit code 1); threshold run: the probe failed: exit 1; '
        'plan %s\nlast lines of its launch:\nthreshold %s' % (HIDDEN, HIDDEN))


def record(q14a=(1.0, Q14A), runs=(2.0, 'builds (2 s); node up in 0.4 s'), reason='', threshold_run=True,
           others=None):
    evidence = dict({'runs': runs, 'Q14a': q14a}, **(others or {}))
    items = [{'id': i, 'points': evidence[i][0] if i in evidence else top,
              'evidence': evidence[i][1] if i in evidence else 'measured %s' % i, 'max': top}
             for i, (top, _) in ITEMS.items()]
    return report.grade_record('your package', 'altitude', items, ['threshold parameter: set to %s' % HIDDEN],
                               {'threshold_run': {'value': float(HIDDEN)} if threshold_run else None},
                               ('needs a hand grade' if reason else 'graded', reason))


def test_points_show_the_items_and_points_only():
    shown = '\n'.join(student_view.lines(record(reason='in the main run the node died'), 'points', True))
    for item_id in ITEMS:
        assert item_id in shown
    assert 'Q11    4 / 4' in shown and 'total  17 / 17' in shown
    assert 'measured' not in shown and 'the node died' not in shown
    assert 'status: needs a hand grade' in shown
    assert HIDDEN not in shown and 'threshold parameter' not in shown


def test_evidence_shows_the_evidence_but_never_the_threshold_run():
    lines = student_view.lines(record(runs=(1.0, RUNS), reason='in the threshold run the node\'s own value '
                                      'never reached the side of the threshold of its step above'), 'evidence', True)
    shown = '\n'.join(lines)
    assert 'measured Q11' in shown and 'measured Q13' in shown
    q14a = [l for l in lines if l.startswith('Q14a')][0]
    assert q14a.endswith(student_view.Q14A_WORDS[0])
    runs = [l for l in lines if l.startswith('runs')][0]
    assert 'main run: node exam died (exit code 1)' in runs and 'a problem in the threshold run' in runs
    assert HIDDEN not in shown and 'set to' not in shown
    assert 'status: needs a hand grade' in lines and 'never reached' not in shown


@pytest.mark.parametrize('points, words', [(1.0, 0), (0.5, 1), (0.0, 2)])
def test_q14a_after_a_threshold_run_names_no_value(points, words):
    lines = student_view.lines(record(q14a=(points, Q14A)), 'evidence', True)
    assert [l for l in lines if l.startswith('Q14a')][0].endswith(student_view.Q14A_WORDS[words])


def test_without_a_threshold_run_every_evidence_is_shown():
    """No threshold run, no hidden value: Q14a's own words help the student (no parameter found...),
    and so does the status's reason."""
    lines = student_view.lines(record(q14a=(0.0, 'no threshold parameter in the launch file'),
                                      runs=(1.0, 'builds (2 s); but: main run: node exam died (exit code 1)'),
                                      reason='the node died: KeyError at exam/scripts/exam_node.py:26',
                                      threshold_run=False), 'evidence')
    shown = '\n'.join(lines)
    assert 'no threshold parameter in the launch file' in shown
    assert 'main run: node exam died (exit code 1)' in shown
    assert 'status: needs a hand grade - the node died: KeyError at exam/scripts/exam_node.py:26' in lines


def test_the_setting_is_read_from_one_file(tmp_path):
    assert student_view.read_setting(os.path.join(LAB, 'check_visibility.ini')) in student_view.SHOW
    setting = tmp_path / 'check.ini'
    for show in student_view.SHOW:
        setting.write_text('[check]\nshow = %s\n' % show)
        assert student_view.read_setting(str(setting)) == show
    setting.write_text('[check]\nshow = everything\n')
    with pytest.raises(ValueError) as bad:
        student_view.read_setting(str(setting))
    assert str(setting) in str(bad.value) and 'everything' in str(bad.value) and 'points, evidence' in str(bad.value)
    with pytest.raises(ValueError) as missing:
        student_view.read_setting(str(tmp_path / 'none.ini'))
    assert 'none.ini' in str(missing.value)


@pytest.mark.parametrize('show', student_view.SHOW)
def test_no_output_a_student_reads_shows_the_threshold_run_value(show):
    """Issue 36 point 7: the value drawn for the threshold run is in no output a student reads: the
    check (either setting, the run's presence taken from the record), Moodle's feedback, Gradescope's
    results; not even where another item's words happen to write it (a Q11 check point, a log line),
    in any of the ways the grader writes a number."""
    from exam_lab.grader.publish import gradescope, moodle
    q11 = (2.5, 'values: 1 of 3 disagree: pressure 89000 -> 1040.00, expected 1040.0 (error +0.00 m)\nat 1040')
    runs = (1.0, 'builds (2 s); but: threshold run: node exam died (exit code 1)\nlast lines:\nthreshold 1040.0')
    reason = 'in the threshold run the node\'s own value never went above the threshold 1040'
    graded = record(q14a=(0.0, Q14A), runs=runs, reason=reason, others={'Q11': q11})
    outputs = ['\n'.join(student_view.lines(graded, show)), moodle.feedback(graded),
               json.dumps(gradescope.results(graded))]
    for text in outputs:
        assert not re.search(r'(?<![\d.])1040(?![\d])', text), text
    assert student_view.NOT_SHOWN in outputs[2] and 'expected %s' % student_view.NOT_SHOWN in outputs[2]
    assert student_view.Q14A_WORDS[2] in html.unescape(outputs[1]), 'the feedback gives Q14a\'s words for a student'
    # Without a threshold run, nothing is hidden: the words are the grader's own.
    plain = record(q14a=(0.0, 'no threshold parameter in the launch file'), others={'Q11': q11}, threshold_run=False)
    assert '1040.00' in moodle.feedback(plain) and '1040.00' in json.dumps(gradescope.results(plain))


def test_scrub_replaces_the_value_in_every_form_and_nothing_else():
    text = 'set to 877.5 (877.50), 877.500, not 1877.5 nor 877.55 nor 2877.5; 880 stays'
    assert student_view.scrub(text, [877.5]) == ('set to %s (%s), %s, not 1877.5 nor 877.55 nor 2877.5; 880 stays'
                                                 % ((student_view.NOT_SHOWN,) * 3))
    assert student_view.scrub('at 900 or 900.0 m, 9000', [900.0]) == 'at %s or %s m, 9000' % ((student_view.NOT_SHOWN,) * 2)
