"""Unit tests of the soak check's matching and memory trend (lab/soak/soak_check.py), no master."""
import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.realpath(__file__)), '..', '..', 'soak'))
from soak_check import NORMAL, WARNING, changes, match, repeats, rss_trend  # noqa: E402


def test_changes_and_repeats():
    events = [(0, NORMAL), (1, WARNING), (2, WARNING), (3, NORMAL)]
    assert changes(events) == [(0, NORMAL), (1, WARNING), (3, NORMAL)]
    assert repeats(events) == [(2, WARNING)]


def test_match_reports_lost_late_wrong_and_unexpected_transitions():
    expected = [(10.0, WARNING), (20.0, NORMAL)]
    assert match(expected, [(10.2, WARNING), (20.1, NORMAL)])[1] == []
    assert 'lost' in match(expected, [(10.2, WARNING)])[1][0]
    assert 'from the rule' in match(expected, [(12.5, WARNING), (20.1, NORMAL)])[1][0]
    assert 'wants' in match(expected, [(10.0, NORMAL), (20.0, NORMAL)])[1][0]
    assert 'unexpected' in match(expected, expected + [(30.0, WARNING)])[1][0]
    errors, _ = match(expected, [(10.5, WARNING), (19.75, NORMAL)])
    assert errors == pytest.approx([0.5, -0.25])


def test_rss_trend_ignores_start_up_and_flags_growth():
    flat = [(t, 30000 + (t % 3) * 10) for t in range(100)]
    assert rss_trend(flat)[3] is False
    leaking = [(t, 30000 + 100 * t) for t in range(100)]
    start, end, growth, leak = rss_trend(leaking)
    assert leak is True and growth == end - start > 2048
    with pytest.raises(ValueError):
        rss_trend([(0, 1), (1, 1)])
