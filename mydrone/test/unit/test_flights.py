"""The built-in flights: valid, looping within 120 s; calm stays below 1300 m, high above it.

Where the default flight crosses 1300 m (true and estimated) is checked in lab/test/unit with the lab's
span finder.
"""

import pytest

from drone_sim.profile import Profile
from mydrone import atmosphere
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


def test_calm_never_crosses_and_high_never_leaves():
    _, times, true, estimated = sampled('calm')
    assert max(estimated) < THRESHOLD - 100.0 and max(true) < THRESHOLD - 100.0
    _, times, true, estimated = sampled('high')
    assert min(estimated) > THRESHOLD + 100.0
