"""The built-in flights: valid, and crossing 1300 m as the debounce demo needs, true and estimated."""

import pytest

from drone_sim.profile import Profile, spans_above
from drone_sim.testing import documented_profiles
from mydrone import atmosphere, flights
from mydrone.flights import FLIGHTS
from test_atmosphere import isothermal_altitude

THRESHOLD = 1300.0  # m
STEP = 0.01  # s


def sampled(name):
    """(times, true altitudes, altitudes the exam node estimates from noiseless readings)."""
    profile = Profile(FLIGHTS[name], name, atmosphere.BOTTOM, atmosphere.TOP)
    times = [i * STEP for i in range(int(profile.period / STEP) + 1)]
    true = [profile.value_at(t) for t in times]
    estimated = [isothermal_altitude(atmosphere.temperature_c(h), atmosphere.pressure_pa(h)) for h in true]
    return profile, times, true, estimated


@pytest.mark.parametrize('name', sorted(FLIGHTS))
def test_builtins_are_valid_and_loop_within_120_s(name):
    assert Profile(FLIGHTS[name], name, atmosphere.BOTTOM, atmosphere.TOP).period <= 120.0


@pytest.mark.parametrize('series', ['true', 'estimated'])
def test_default_has_a_short_excursion_then_a_long_stay(series):
    _, times, true, estimated = sampled('default')
    values = true if series == 'true' else estimated
    spans = spans_above(times, values, THRESHOLD)
    assert len(spans) == 2, spans
    (a0, a1), (b0, b1) = spans
    assert 2.0 <= a1 - a0 <= 4.0  # under the 5 s delay with a 1 s margin
    assert b1 - b0 >= 20.0  # over 15 s, so the warning holds for a while after the delay
    # Clearly past the threshold and clearly back: 20 m more or less changes no span count.
    assert len(spans_above(times, values, THRESHOLD + 20.0)) == 2
    assert len(spans_above(times, values, THRESHOLD - 20.0)) == 2


def test_default_crossing_instants_match_the_docstring():
    _, times, true, estimated = sampled('default')
    spans = spans_above(times, true, THRESHOLD)
    assert [(round(a, 1), round(b, 1)) for a, b in spans] == [(21.0, 24.0), (42.0, 70.0)]
    spans = spans_above(times, estimated, THRESHOLD)
    assert [(round(a, 1), round(b, 1)) for a, b in spans] == [(21.2, 23.8), (42.4, 69.6)]


def test_calm_never_crosses_and_high_never_leaves():
    _, times, true, estimated = sampled('calm')
    assert max(estimated) < THRESHOLD - 100.0 and max(true) < THRESHOLD - 100.0
    _, times, true, estimated = sampled('high')
    assert min(estimated) > THRESHOLD + 100.0


def test_the_docstring_gives_every_flight_exactly():
    # The docstring is what a user reads to pick a flight: every waypoint must be the one flown.
    assert documented_profiles(flights.__doc__) == FLIGHTS
