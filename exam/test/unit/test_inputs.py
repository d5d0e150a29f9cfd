"""The input cache: only usable values are kept; age, freshness and rate from synthetic times."""
import pytest

from exam.formulas import why_unusable_pressure
from exam.inputs import InputCache


def test_nothing_cached_before_the_first_reading():
    cache = InputCache('pressure', why_unusable_pressure)
    assert cache.value is None
    assert cache.age(10.0) is None
    assert not cache.is_fresh(10.0, 5.0)
    assert cache.rate(10.0) == 0.0


def test_usable_reading_is_cached_with_its_time():
    cache = InputCache('pressure', why_unusable_pressure)
    assert cache.offer(90000.0, 2.0) is None
    assert cache.value == 90000.0
    assert cache.age(3.5) == 1.5
    assert cache.is_fresh(7.0, 5.0)
    assert not cache.is_fresh(7.01, 5.0)


@pytest.mark.parametrize('bad', [float('nan'), float('inf'), 0.0, -5.0])
def test_unusable_reading_is_rejected_and_the_previous_value_kept(bad):
    cache = InputCache('pressure', why_unusable_pressure)
    cache.offer(90000.0, 1.0)
    assert cache.offer(bad, 2.0) is not None
    assert cache.value == 90000.0
    assert cache.stamp == 1.0
    assert cache.rejected == 1


def test_rate_counts_arrivals_within_the_window():
    cache = InputCache('pressure', why_unusable_pressure, rate_window=10.0)
    for i in range(21):
        cache.offer(90000.0, i * 0.5)  # 2 Hz for 10 s
    assert cache.rate(10.0) == pytest.approx(2.0)
    # 30 s later every arrival has left the window.
    assert cache.rate(40.0) == 0.0


def test_rate_is_measured_from_the_first_to_the_last_arrival_kept():
    cache = InputCache('pressure', why_unusable_pressure, rate_window=10.0)
    for t in (100.0, 101.0, 104.0):
        cache.offer(90000.0, t)
    # Two intervals in 4 s; an arrival exactly one window old still counts.
    assert cache.rate(104.0) == pytest.approx(0.5)
    assert cache.rate(110.0) == pytest.approx(0.5)
    assert cache.rate(110.01) == pytest.approx(1.0 / 3.0)  # 100.0 has left: one interval in 3 s
    assert cache.rate(111.01) == 0.0  # only 104.0 is left


def test_rate_of_arrivals_with_one_timestamp_is_zero():
    # Two readings stamped alike (a bag replayed, a coarse clock) give no interval to divide by.
    cache = InputCache('pressure', why_unusable_pressure)
    cache.offer(90000.0, 5.0)
    cache.offer(90001.0, 5.0)
    assert cache.rate(5.0) == 0.0


def test_the_default_rate_window_is_10_s():
    cache = InputCache('pressure', why_unusable_pressure)
    for t in (0.0, 1.0, 3.0):
        cache.offer(90000.0, t)
    assert cache.rate(10.0) == pytest.approx(2.0 / 3.0)
    assert cache.rate(10.5) == pytest.approx(0.5)  # 0.0 has left the window: one interval in 2 s
    assert cache.rate(11.5) == 0.0


def test_rate_of_readings_less_than_a_second_apart():
    cache = InputCache('pressure', why_unusable_pressure)
    cache.offer(90000.0, 5.0)
    cache.offer(90000.0, 5.5)
    assert cache.rate(5.5) == pytest.approx(2.0)
