"""Unit tests of lab/bench/stats.py: synthetic stamps, no master, no clock."""

import os
import random
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.realpath(__file__)), '..', '..', 'bench'))

import stats  # noqa: E402


def test_interval_stats_of_a_perfect_10hz_stream():
    stamps = [100.0 + 0.1 * i for i in range(101)]
    s = stats.interval_stats(stamps)
    assert s['count'] == 101
    assert s['rate_hz'] == pytest.approx(10.0)
    assert s['sd_ms'] == pytest.approx(0.0, abs=1e-6)
    assert s['max_gap_ms'] == pytest.approx(100.0)


def test_interval_stats_sees_one_missing_message():
    stamps = [0.1 * i for i in range(50) if i != 20]
    s = stats.interval_stats(stamps)
    assert s['max_gap_ms'] == pytest.approx(200.0)
    # 48 intervals over 4.9 s: the lost message lowers the mean rate.
    assert s['rate_hz'] == pytest.approx(48 / 4.9)
    assert s['sd_ms'] > 10.0


def test_interval_stats_sd_matches_a_known_jitter():
    rng = random.Random(1)
    stamps = [0.01 * i + rng.gauss(0.0, 0.0005) for i in range(20000)]
    # Independent jitter of sd j on each stamp gives intervals of sd j * sqrt(2).
    assert stats.interval_stats(stamps)['sd_ms'] == pytest.approx(0.5 * 2 ** 0.5, rel=0.05)


def test_interval_stats_tells_rare_hiccups_from_steady_wobble():
    hiccups = [0.1 * i for i in range(1001)]
    hiccups[500] += 0.008  # one message 8 ms late: two intervals off by 8 ms
    s = stats.interval_stats(hiccups)
    assert s['dev_p50_ms'] == pytest.approx(0.0, abs=1e-6)
    assert s['dev_p99_ms'] < 1.0
    assert s['sd_ms'] > 0.3
    wobble = [0.1 * i + (0.001 if i % 2 else 0.0) for i in range(1001)]
    w = stats.interval_stats(wobble)
    assert w['dev_p50_ms'] == pytest.approx(1.0, abs=1e-6)
    assert w['dev_p99_ms'] == pytest.approx(1.0, abs=1e-6)


def test_interval_stats_needs_three_messages():
    s = stats.interval_stats([1.0, 1.1])
    assert s['count'] == 2
    assert all(s[k] is None for k in ('rate_hz', 'sd_ms', 'max_gap_ms', 'dev_p50_ms', 'dev_p99_ms'))


def test_percentile_interpolates_like_numpy():
    values = list(range(1, 21))
    assert stats.percentile(values, 50) == pytest.approx(10.5)
    assert stats.percentile(values, 99) == pytest.approx(19.81)
    assert stats.percentile(values, 100) == 20
    assert stats.percentile(values, 0) == 1
    assert stats.percentile([], 50) is None


def test_summarize_ms_converts_and_keeps_signs():
    s = stats.summarize_ms([-0.002, 0.001, 0.004])
    assert s['n'] == 3
    assert s['median_ms'] == pytest.approx(1.0)
    assert s['min_ms'] == pytest.approx(-2.0)
    assert s['max_ms'] == pytest.approx(4.0)


def test_match_warning_calls_measures_both_latencies():
    cycles = [(10.0, 16.0), (20.0, 26.0)]
    calls = [(15.004, 'WARNING'), (16.010, 'NORMAL'), (25.002, 'WARNING'), (26.001, 'NORMAL')]
    warning, normal, anomalies = stats.match_warning_calls(cycles, calls, delay=5.0)
    assert warning == pytest.approx([0.004, 0.002])
    assert normal == pytest.approx([0.010, 0.001])
    assert anomalies == []


def test_match_warning_calls_keeps_an_early_warning_negative():
    warning, _, anomalies = stats.match_warning_calls([(10.0, 16.0)],
                                                      [(14.93, 'WARNING'), (16.05, 'NORMAL')], 5.0)
    assert warning == pytest.approx([-0.07])
    assert anomalies == []


def test_match_warning_calls_reports_missing_repeated_and_spurious_calls():
    cycles = [(10.0, 16.0), (20.0, 26.0), (30.0, 36.0)]
    calls = [(1.0, 'NORMAL'),                                   # before any excursion
             (15.0, 'WARNING'), (15.5, 'WARNING'), (16.0, 'NORMAL'),  # repeated WARNING
             (26.0, 'NORMAL')]                                  # second excursion never warned
    warning, normal, anomalies = stats.match_warning_calls(cycles, calls, 5.0)
    assert warning == pytest.approx([0.0])
    assert normal == pytest.approx([0.0])
    assert len(anomalies) == 4
    assert 'before the first excursion' in anomalies[0]
    assert "['WARNING', 'WARNING', 'NORMAL']" in anomalies[1]
    assert "['NORMAL']" in anomalies[2]
    assert '[]' in anomalies[3]


def test_crossing_script_alternates_and_leaves_time_to_warn():
    steps = stats.crossing_script(20, delay=1.0, hold=0.6, rng=stats.new_rng(3))
    assert steps[0] == (0.0, 1000.0)
    assert len(steps) == 41
    times = [t for t, _ in steps]
    assert times == sorted(times)
    for (t_up, up), (t_down, down) in zip(steps[1::2], steps[2::2]):
        assert up == 1600.0 and down == 1000.0
        assert t_down - t_up >= 1.6
    # Every later excursion starts at least `hold` after the previous one came back.
    for (t_down, _), (t_up, _) in zip(steps[2::2], steps[3::2]):
        assert t_up - t_down >= 0.6


def test_within_and_cpu_percent():
    assert stats.within(9.995, 10.0, 0.001)
    assert not stats.within(9.98, 10.0, 0.001)
    assert not stats.within(None, 10.0, 0.001)
    assert stats.cpu_percent(50, 10.0, 100) == pytest.approx(5.0)


def test_profile_summary_ranks_self_and_inclusive_time(tmp_path):
    raw = tmp_path / 'raw.txt'
    raw.write_text('main (a.py:1);loop (a.py:5);sleep (t.py:9) 6\n'
                   'main (a.py:1);loop (a.py:7);publish (p.py:3) 3\n'
                   'worker (w.py:2);call (s.py:4) 1\n')
    top = stats.summarize_collapsed(str(raw))
    assert top['samples'] == 10
    rows = {name: (self_pct, incl) for name, self_pct, incl in top['functions']}
    assert rows['sleep (t.py)'] == pytest.approx((60.0, 60.0))
    assert rows['publish (p.py)'] == pytest.approx((30.0, 30.0))
    assert 'loop (a.py)' not in rows  # never a leaf: no self time
