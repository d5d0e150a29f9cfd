"""Parameter checks: cast, range, and an error message naming the resolved parameter and value."""

import math

import pytest

from drone_sim.params import ParamError, non_negative_float, positive_float, seed


def test_positive_float_accepts_and_casts():
    assert positive_float('/d/rate', 2, 'Hz') == 2.0
    assert isinstance(positive_float('/d/rate', 2, 'Hz'), float)
    assert positive_float('/d/rate', 0.778, 'Hz') == 0.778


@pytest.mark.parametrize('value', [0, -1.0, math.nan, math.inf, '2', 'fast', True, None, [1]])
def test_positive_float_refuses(value):
    with pytest.raises(ParamError) as err:
        positive_float('/mydrone/pressure_rate', value, 'Hz')
    assert str(err.value) == ('parameter /mydrone/pressure_rate = %r: must be a finite number > 0 (Hz)'
                              % (value,))


def test_non_negative_float():
    assert non_negative_float('/d/noise', 0, 'Pa') == 0.0
    with pytest.raises(ParamError, match=r'/d/noise = -0\.5: must be a finite number >= 0 \(Pa\)'):
        non_negative_float('/d/noise', -0.5, 'Pa')


def test_seed():
    assert seed('/d/seed', 42) == 42
    for bad in (1.5, '3', True, None):
        with pytest.raises(ParamError, match='/d/seed = .*: must be an integer'):
            seed('/d/seed', bad)
