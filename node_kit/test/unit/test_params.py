"""Parameter checks (simulators and exam node): cast, range, and an error message naming the resolved
parameter and its value."""

import math

import pytest

from node_kit.params import ParamError, finite_float, non_negative_float, one_of, positive_float, seed


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


def test_finite_float_takes_any_finite_number():
    assert finite_float('/exam/threshold', -12, 'm') == -12.0
    assert isinstance(finite_float('/exam/threshold', 1300, 'm'), float)


@pytest.mark.parametrize('value', [math.nan, math.inf, -math.inf, 'abc', '1300', True, None, [1300]])
def test_finite_float_refuses(value):
    # A numeric string is refused too: the parameter server types unquoted numbers itself.
    with pytest.raises(ParamError) as err:
        finite_float('/exam/threshold', value, 'm')
    assert str(err.value) == 'parameter /exam/threshold = %r: must be a finite number (m)' % (value,)


def test_zero_is_the_bound_of_both_ranges():
    assert non_negative_float('/exam/delay', 0.0, 's') == 0.0
    with pytest.raises(ParamError, match=r'/exam/timeout = 0\.0: must be a finite number > 0 \(s\)'):
        positive_float('/exam/timeout', 0.0, 's')


def test_one_of():
    assert one_of('/exam/mode', 'depth', ['altitude', 'depth']) == 'depth'
    for bad in ('foo', 'Depth', ' depth', 1, None, ['depth']):
        with pytest.raises(ParamError) as err:
            one_of('/exam/mode', bad, ['depth', 'altitude'])
        assert str(err.value) == 'parameter /exam/mode = %r: must be one of altitude, depth' % (bad,)
