"""The simulators' built-in flights and dives: exactly the waypoints their docstrings give, and seen
through the exam's threshold and delay, each default profile has a short excursion (no warning) and a
long stay (a warning), located with the oracle's spans_above; and the oracle's own helpers. No master
needed.

What the exam node estimates is computed with exam.formulas itself: these tests are about the profiles,
not the formula (the formula is checked against the oracle in exam's unit tests and the lab's rostests).
"""

import re

import pytest
from hypothesis import given, strategies as st

from drone_sim.profile import Profile
from exam import formulas
from exam_lab.harness.oracle import depth_of, spans_above
from mydrone import atmosphere, flights
from mydrone.flights import FLIGHTS
from submarinedrone import dives, hydrostatics
from submarinedrone.dives import DIVES

STEP = 0.01  # s, sampling step of a profile
ALTITUDE_THRESHOLD = 1300.0  # m, the default of exam.launch
DEPTH_THRESHOLD = 150.0  # m, the default of exam_submarine.launch


def test_spans_above():
    times = [0, 1, 2, 3, 4, 5, 6]
    values = [0, 5, 6, 0, 5, 0, 7]
    assert spans_above(times, values, 4) == [(1, 2), (4, 4), (6, 6)]
    assert spans_above(times, values, 10) == []
    # At the threshold is not above.
    assert spans_above(times, values, 5) == [(2, 2), (6, 6)]


@given(st.floats(min_value=90000.0, max_value=110000.0), st.floats(min_value=0.0, max_value=11000.0))
def test_depth_formula_inverts_the_pressure(surface, depth):
    robot = hydrostatics.pressure_at_depth_pa(surface, depth)
    assert depth_of(robot, surface) == pytest.approx(depth, abs=1e-6)


# --- mydrone's built-in flights ---------------------------------------------------------------------

def sampled_flight(name):
    """(times, true altitudes, altitudes the exam node estimates from noiseless readings)."""
    profile = Profile(FLIGHTS[name], name, atmosphere.BOTTOM, atmosphere.TOP)
    times = [i * STEP for i in range(int(profile.period / STEP) + 1)]
    true = [profile.value_at(t) for t in times]
    estimated = [formulas.altitude(atmosphere.temperature_c(h), atmosphere.pressure_pa(h)) for h in true]
    return times, true, estimated


@pytest.mark.parametrize('series', ['true', 'estimated'])
def test_default_flight_has_a_short_excursion_then_a_long_stay(series):
    times, true, estimated = sampled_flight('default')
    values = true if series == 'true' else estimated
    spans = spans_above(times, values, ALTITUDE_THRESHOLD)
    assert len(spans) == 2, spans
    (a0, a1), (b0, b1) = spans
    assert 2.0 <= a1 - a0 <= 4.0  # under the 5 s delay with a 1 s margin
    assert b1 - b0 >= 20.0  # over 15 s, so the warning holds for a while after the delay
    # Clearly past the threshold and clearly back: 20 m more or less changes no span count.
    assert len(spans_above(times, values, ALTITUDE_THRESHOLD + 20.0)) == 2
    assert len(spans_above(times, values, ALTITUDE_THRESHOLD - 20.0)) == 2


def test_default_flight_crossing_instants_match_the_docstring():
    times, true, estimated = sampled_flight('default')
    spans = spans_above(times, true, ALTITUDE_THRESHOLD)
    assert [(round(a, 1), round(b, 1)) for a, b in spans] == [(21.0, 24.0), (42.0, 70.0)]
    spans = spans_above(times, estimated, ALTITUDE_THRESHOLD)
    assert [(round(a, 1), round(b, 1)) for a, b in spans] == [(21.2, 23.8), (42.4, 69.6)]


# --- submarinedrone's built-in dives ----------------------------------------------------------------

def sampled_dive(name):
    """(times, depths) of one loop."""
    profile = Profile(DIVES[name], name, 0.0, hydrostatics.DEEPEST)
    times = [i * STEP for i in range(int(profile.period / STEP) + 1)]
    return times, [profile.value_at(t) for t in times]


def test_default_dive_has_a_short_excursion_then_a_long_stay():
    times, depths = sampled_dive('default')
    spans = spans_above(times, depths, DEPTH_THRESHOLD)
    assert [(round(a, 1), round(b, 1)) for a, b in spans] == [(21.5, 24.5), (42.0, 70.0)]
    (a0, a1), (b0, b1) = spans
    assert a1 - a0 <= 4.0 and b1 - b0 >= 20.0
    # Clearly past the threshold and clearly back: 5 m more or less changes no span count.
    assert len(spans_above(times, depths, DEPTH_THRESHOLD + 5.0)) == 2
    assert len(spans_above(times, depths, DEPTH_THRESHOLD - 5.0)) == 2


def test_default_dive_seen_through_the_exam_formula():
    # What the exam node computes from noiseless readings of the same instant is the true depth.
    times, depths = sampled_dive('default')
    for t, depth in zip(times[::50], depths[::50]):
        surface = hydrostatics.surface_pressure_pa(t)
        robot = hydrostatics.pressure_at_depth_pa(surface, depth)
        assert formulas.depth(robot, surface) == pytest.approx(depth, abs=1e-6)


def documented_profiles(docstring):
    """The waypoints ``[[time_s, value], ...]`` that a profile module's docstring gives, by name.

    Three forms, as mydrone.flights and submarinedrone.dives write them (values in m)::

        ``name`` (loop T s)::           followed by a row "time s ..." and a row "<quantity> m ..."
        ``name`` (loop T s): v0 m -> v1 m -> ... -> vN m at t0, t1, ..., tN s
        ``name`` (loop T s): v m all the time
    """
    number = r'-?[0-9.]+'
    profiles = {}
    table = r'``(\w+)`` \(loop %s s\)::\s*\n\s*time +s +([-0-9. ]+)\n\s*\w+ +m +([-0-9. ]+)' % number
    for name, times, values in re.findall(table, docstring):
        profiles[name] = [[float(t), float(v)] for t, v in zip(times.split(), values.split())]
    chain = r'``(\w+)`` \(loop %s s\): ((?:%s m -> )+%s m) at ([-0-9., ]+) s' % (number, number, number)
    for name, values, times in re.findall(chain, docstring):
        values = [float(v) for v in re.findall(number, values)]
        profiles[name] = [[float(t), v] for t, v in zip(times.split(','), values)]
    constant = r'``(\w+)`` \(loop (%s) s\): (%s) m all the time' % (number, number)
    for name, period, value in re.findall(constant, docstring):
        profiles[name] = [[0.0, float(value)], [float(period), float(value)]]
    return profiles


def test_the_docstrings_give_every_flight_and_dive_exactly():
    # The docstring is what a user reads to pick a flight or a dive: every waypoint must be the one flown.
    assert documented_profiles(flights.__doc__) == FLIGHTS
    assert documented_profiles(dives.__doc__) == DIVES
