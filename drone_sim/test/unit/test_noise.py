"""Seeded noise: reproducible per (seed, channel), independent across channels, right spread."""

import statistics

from hypothesis import given, strategies as st

from drone_sim.noise import GaussianNoise, channel_rng


@given(st.integers(min_value=-2**63, max_value=2**63), st.text(min_size=1, max_size=20))
def test_same_seed_and_channel_give_the_same_sequence(seed, channel):
    a = GaussianNoise(seed, channel, 2.0)
    b = GaussianNoise(seed, channel, 2.0)
    assert [a(10.0) for _ in range(20)] == [b(10.0) for _ in range(20)]


def test_sequences_differ_across_seeds_and_channels():
    def first(seed, channel):
        noise = GaussianNoise(seed, channel, 1.0)
        return [noise(0.0) for _ in range(5)]
    assert first(0, 'pressure') != first(1, 'pressure')
    assert first(0, 'pressure') != first(0, 'temperature')


def test_known_values_do_not_change_between_runs():
    # String seeds are hashed with SHA-512, not hash() (salted per process): a recorded run can be
    # reproduced later by another interpreter. These values were drawn once and written down.
    assert channel_rng(0, 'pressure').random() == 0.4978564184439018
    assert channel_rng(7, 'x').gauss(0.0, 1.0) == -1.0449274870852954


def test_spread_matches_sigma_and_mean_is_the_value():
    noise = GaussianNoise(3, 'pressure', 3.0)
    samples = [noise(1000.0) for _ in range(20000)]
    assert abs(statistics.mean(samples) - 1000.0) < 0.1
    assert abs(statistics.pstdev(samples) - 3.0) < 0.1


def test_zero_sigma_is_noiseless():
    noise = GaussianNoise(0, 'temperature', 0.0)
    assert [noise(6.55) for _ in range(3)] == [6.55] * 3
