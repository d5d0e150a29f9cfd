"""The harness's oracle against the sheets' numbers typed here by hand, and the debounce rule's text."""
import math

import pytest

from exam_lab.harness import oracle


def test_pressure_at_inverts_the_seed_formula():
    p = oracle.pressure_at(1300.0, 15.0)
    altitude = 8.31432 * (15.0 + 273.15) / (0.0289644 * 9.80665) * math.log(101325.0 / p)
    assert altitude == pytest.approx(1300.0, abs=1e-6)
    assert oracle.pressure_at(0.0, 15.0) == pytest.approx(101325.0)


def series(*segments, period=0.1):
    """Readings [(t, value)] at `period` from (duration s, value) segments."""
    readings, t = [], 0.0
    for duration, value in segments:
        for _ in range(int(round(duration / period))):
            readings.append((round(t, 6), value))
            t += period
    return readings


def test_short_excursion_gives_nothing():
    assert oracle.debounce_transitions(series((2, 1000), (3, 1400), (5, 1000)), 1300, 5) == []


def test_long_stay_warns_at_the_delay_and_returns_at_the_first_reading_back():
    transitions = oracle.debounce_transitions(series((2, 1000), (7, 1400), (2, 1000)), 1300, 5)
    assert [s for _t, s in transitions] == [oracle.WARNING, oracle.NORMAL]
    assert transitions[0][0] == pytest.approx(7.0)
    assert transitions[1][0] == pytest.approx(9.0)


def test_a_reading_at_the_threshold_cancels_the_count():
    readings = series((1, 1000), (3, 1301), (0.1, 1300), (4.5, 1301), (1, 1000))
    assert oracle.debounce_transitions(readings, 1300, 5) == []


def test_warning_is_due_at_the_deadline_even_between_readings():
    # Readings every 2 s: above from t=0, the delay expires at t=5 and the rule says 5, not 6.
    readings = [(0.0, 1400), (2.0, 1400), (4.0, 1400), (6.0, 1400), (8.0, 1000)]
    assert oracle.debounce_transitions(readings, 1300, 5) == [(5.0, oracle.WARNING), (8.0, oracle.NORMAL)]
