"""The built-in dives: valid, looping within 120 s; calm stays shallower than 150 m, deep deeper.

Where the default dive crosses 150 m, and its depth seen through the exam formula, are checked in
lab/test/unit with the lab's span finder.
"""

import pytest

from drone_sim.profile import Profile
from submarinedrone import hydrostatics
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


def test_calm_never_crosses_and_deep_never_leaves():
    assert max(sampled('calm')[1]) < THRESHOLD - 25.0
    assert min(sampled('deep')[1]) > THRESHOLD + 25.0
