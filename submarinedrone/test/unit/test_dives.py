"""The built-in dives: valid, and crossing 150 m as the debounce demo needs."""

import pytest

from drone_sim.profile import Profile, spans_above
from drone_sim.testing import documented_profiles
from submarinedrone import dives, hydrostatics
from submarinedrone.dives import DIVES

THRESHOLD = 150.0  # m
STEP = 0.01  # s


def sampled(name):
    """(times, depths) of one loop."""
    profile = Profile(DIVES[name], name, 0.0, hydrostatics.DEEPEST)
    times = [i * STEP for i in range(int(profile.period / STEP) + 1)]
    return times, [profile.value_at(t) for t in times]


@pytest.mark.parametrize('name', sorted(DIVES))
def test_builtins_are_valid_and_loop_within_120_s(name):
    assert Profile(DIVES[name], name, 0.0, hydrostatics.DEEPEST).period <= 120.0


def test_default_has_a_short_excursion_then_a_long_stay():
    times, depths = sampled('default')
    spans = spans_above(times, depths, THRESHOLD)
    assert [(round(a, 1), round(b, 1)) for a, b in spans] == [(21.5, 24.5), (42.0, 70.0)]
    (a0, a1), (b0, b1) = spans
    assert a1 - a0 <= 4.0 and b1 - b0 >= 20.0
    # Clearly past the threshold and clearly back: 5 m more or less changes no span count.
    assert len(spans_above(times, depths, THRESHOLD + 5.0)) == 2
    assert len(spans_above(times, depths, THRESHOLD - 5.0)) == 2


def test_default_seen_through_the_exam_formula():
    # What the exam node computes from noiseless readings of the same instant is the true depth.
    times, depths = sampled('default')
    for t, depth in zip(times[::50], depths[::50]):
        surface = hydrostatics.surface_pressure_pa(t)
        robot = hydrostatics.pressure_at_depth_pa(surface, depth)
        assert hydrostatics.depth_m(robot, surface) == pytest.approx(depth, abs=1e-6)


def test_calm_never_crosses_and_deep_never_leaves():
    assert max(sampled('calm')[1]) < THRESHOLD - 25.0
    assert min(sampled('deep')[1]) > THRESHOLD + 25.0


def test_the_docstring_gives_every_dive_exactly():
    # The docstring is what a user reads to pick a dive: every waypoint must be the one dived.
    assert documented_profiles(dives.__doc__) == DIVES
