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
