"""The numbers docs/report.md states are computed by lab/report/analysis.py: its pure parts, checked on
synthetic series and against the formulas by hand."""
import os
import sys

import pytest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__)))))
sys.path.insert(0, os.path.join(REPO, 'lab', 'report'))

import analysis  # noqa: E402


class Msg(object):
    def __init__(self, data):
        self.data = data


def series(**topics):
    return {'/' + name: [(t, Msg(v)) for t, v in samples] for name, samples in topics.items()}


def test_excess_episodes_are_strictly_above_and_end_at_the_first_reading_back():
    samples = [(0, 10), (1, 20), (2, 15), (3, 21), (4, 20), (5, 25), (6, 30)]
    assert analysis.excess_episodes(samples, 20) == [(3, 4), (5, None)]


def test_led_changes_skip_the_initial_colour_and_repeats():
    bag = series(led=[(0, 'GREEN'), (5, 'RED'), (6, 'RED'), (9, 'GREEN')])
    assert analysis.led_changes(bag, '/led') == [(5, 'RED'), (9, 'GREEN')]


def test_recompute_uses_the_latest_of_each_input_from_when_both_arrived():
    bag = series(a=[(0.0, 1.0), (2.0, 3.0)], b=[(1.0, 10.0), (1.5, 20.0)])
    assert analysis.recompute(bag, ['/a', '/b'], lambda a, b: a + b) == [(1.0, 11.0), (1.5, 21.0), (2.0, 23.0)]


def test_summarise_measures_the_lags_from_the_delay_end_and_from_the_reading_back():
    readings = [(float(t), 0.0) for t in range(10)] + [(10.0, 5.0), (12.0, 5.0), (17.0, 5.0), (18.0, 0.0)]
    bag = series(x=readings, led=[(0.0, 'GREEN'), (15.02, 'RED'), (18.01, 'GREEN')],
                 out=[(0.0, 0.0), (20.0, 0.0)], truth=[(0.0, 0.0)])
    facts = analysis.summarise(bag, ['/x'], lambda x: x, '/out', '/truth', '/led', threshold=1.0,
                               delay=5.0, origin=0.0)
    assert facts['episodes'] == [(10.0, 18.0, 8.0)]
    assert facts['warning_lag'] == [pytest.approx(0.02)]
    assert facts['normal_lag'] == [pytest.approx(0.01)]
    assert facts['rate'] == pytest.approx(0.05)


def test_isothermal_model_reads_about_19_m_low_at_1300_m():
    assert analysis.isothermal_error(1300.0) == pytest.approx(-19.25, abs=0.1)
    assert analysis.isothermal_error(0.0) == pytest.approx(0.0, abs=1e-6)


def test_both_lapse_rate_fixes_recover_the_isa_altitude():
    for altitude in (0.0, 650.0, 1300.0, 3000.0):
        assert analysis.lapse_rate_error(altitude) == pytest.approx(0.0, abs=1e-6)
        p = analysis.atmosphere.pressure_pa(altitude)
        assert analysis.standard_altitude(p) == pytest.approx(altitude, abs=1e-6)


def test_mean_temperature_fix_is_close_but_not_exact():
    assert 0.0 < analysis.mean_temperature_error(1300.0) < 0.5


def test_true_altitude_read_as_inverts_the_model():
    true = analysis.true_altitude_read_as(1300.0)
    assert true == pytest.approx(1319.8, abs=0.1)
    assert analysis.isothermal_error(true) + true == pytest.approx(1300.0, abs=1e-6)
