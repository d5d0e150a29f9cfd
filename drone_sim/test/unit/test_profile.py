"""Profiles: interpolation, looping, validation messages, parsing."""

import math

import pytest
from hypothesis import given, strategies as st

from drone_sim.profile import Profile, parse_profile, validate_waypoints

TRIANGLE = [[0, 0], [10, 100], [20, 0]]


def test_interpolates_between_waypoints():
    p = Profile(TRIANGLE)
    assert p.period == 20.0
    assert p.value_at(0) == 0.0
    assert p.value_at(2.5) == 25.0
    assert p.value_at(10) == 100.0
    assert p.value_at(15) == 50.0


def test_loops_after_the_last_waypoint_and_before_zero():
    p = Profile(TRIANGLE)
    assert p.value_at(20) == 0.0
    assert p.value_at(22.5) == 25.0
    assert p.value_at(1000 * 20 + 10) == 100.0
    # Time running backwards (a bag looping under sim time) still lands in the loop.
    assert p.value_at(-5) == 50.0
    # A tiny negative time rounds to the period under the modulo (hypothesis found it).
    assert p.value_at(-4.440892098500626e-16) == pytest.approx(0.0, abs=1e-9)


@given(st.floats(min_value=-1e6, max_value=1e6, allow_nan=False))
def test_value_stays_within_the_waypoint_range(t):
    p = Profile([[0, 3], [1.5, -7], [4, 12], [9, 3]])
    assert -7.0 - 1e-9 <= p.value_at(t) <= 12.0 + 1e-9


@pytest.mark.parametrize('waypoints, words', [
    ([[0, 1]], 'at least 2 waypoints'),
    ('default', 'list of [time_s, value]'),
    (42, 'list of [time_s, value]'),
    ([[0, 1], [5]], 'waypoint 1 must be a pair'),
    ([[0, 1], 'ab'], 'waypoint 1 must be a pair'),
    ([[0, 1], [5, 'x'], [9, 1]], 'waypoint 1 must hold two finite numbers'),
    ([[0, 1], [5, math.nan], [9, 1]], 'finite'),
    ([[0, 1], [math.inf, 2], [9, 1]], 'finite'),
    ([[0, True], [9, True]], 'finite numbers'),
    ([[1, 0], [9, 0]], 'first waypoint must be at time 0'),
    ([[0, 0], [5, 1], [5, 0]], 'increase strictly: waypoint 2 at 5.0 s follows 5.0 s'),
    ([[0, 0], [5, 1], [3, 0]], 'increase strictly'),
    ([[0, 0], [5, 1]], 'last value 1.0 must equal the first 0.0'),
    # Each message names the offending values themselves, not their neighbours.
    ([[1, 0], [9, 0]], 'at time 0, got 1.0'),
    ([[0, 3], [5, 1], [9, 2]], 'last value 2.0 must equal the first 3.0'),
    ([[0, 0], [0, 1], [9, 0]], 'waypoint 1 at 0.0 s follows 0.0 s'),
    ([[0, 0], [5, 1], [3, 0]], 'waypoint 2 at 3.0 s follows 5.0 s'),
])
def test_validation_names_the_problem(waypoints, words):
    with pytest.raises(ValueError, match='.*' + words.replace('[', r'\[').replace(']', r'\]')
                       .replace('(', r'\(').replace('.', r'\.')):
        validate_waypoints(waypoints)


def test_bounds_are_checked():
    assert validate_waypoints([[0, 0], [1, 10], [2, 0]], lower=0, upper=10)
    with pytest.raises(ValueError, match=r'waypoint 1 value -1 is outside \[0, 10\]'):
        validate_waypoints([[0, 0], [1, -1], [2, 0]], lower=0, upper=10)
    with pytest.raises(ValueError, match='outside'):
        validate_waypoints([[0, 0], [1, 11], [2, 0]], lower=0, upper=10)


def test_parse_builtin_name_or_waypoints():
    builtins = {'default': TRIANGLE, 'flat': [[0, 5], [1, 5]]}
    p = parse_profile('flat', builtins)
    assert (p.name, p.value_at(0.3)) == ('flat', 5.0)
    p = parse_profile([[0, 1], [2, 3], [4, 1]], builtins)
    assert (p.name, p.value_at(1)) == ('custom', 2.0)
    with pytest.raises(ValueError, match="unknown profile 'nope': use one of default, flat, or a list"):
        parse_profile('nope', builtins)
    with pytest.raises(ValueError, match='outside'):
        parse_profile('default', builtins, upper=50)

