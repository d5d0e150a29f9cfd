"""Unit tests of the soak check's oracle, matching and memory trend (lab/soak/soak_check.py), no master."""
import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'soak'))
from soak_check import (NORMAL, WARNING, changes, debounce_oracle, match,  # noqa: E402
                        repeats, rss_trend)


def series(*segments, period=0.1):
    """Readings [(t, value)] at `period` from (duration s, value) segments."""
    readings, t = [], 0.0
    for duration, value in segments:
        for _ in range(int(round(duration / period))):
            readings.append((round(t, 6), value))
            t += period
    return readings


def test_short_excursion_gives_nothing():
    assert debounce_oracle(series((2, 1000), (3, 1400), (5, 1000)), 1300, 5) == []


def test_long_stay_warns_at_the_delay_and_returns_at_the_first_reading_back():
    transitions = debounce_oracle(series((2, 1000), (7, 1400), (2, 1000)), 1300, 5)
    assert [s for _t, s in transitions] == [WARNING, NORMAL]
    assert transitions[0][0] == pytest.approx(7.0)
    assert transitions[1][0] == pytest.approx(9.0)


def test_a_reading_at_the_threshold_cancels_the_count():
    readings = series((1, 1000), (3, 1301), (0.1, 1300), (4.5, 1301), (1, 1000))
    assert debounce_oracle(readings, 1300, 5) == []


def test_warning_is_due_at_the_deadline_even_between_readings():
    # Readings every 2 s: above from t=0, the delay expires at t=5 and the rule says 5, not 6.
    readings = [(0.0, 1400), (2.0, 1400), (4.0, 1400), (6.0, 1400), (8.0, 1000)]
    assert debounce_oracle(readings, 1300, 5) == [(5.0, WARNING), (8.0, NORMAL)]


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
