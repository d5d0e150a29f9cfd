"""ISA troposphere against hand-computed values."""

import math

import pytest
from hypothesis import given, strategies as st

from mydrone import atmosphere


def test_sea_level():
    assert atmosphere.pressure_pa(0.0) == 101325.0
    assert atmosphere.temperature_c(0.0) == pytest.approx(15.0)


def test_1300_m():
    # T = 288.15 - 0.0065*1300 = 279.7 K = 6.55 degC; P = 101325*(279.7/288.15)^5.25588 = 86651.9 Pa.
    assert atmosphere.temperature_k(1300.0) == pytest.approx(279.7)
    assert atmosphere.temperature_c(1300.0) == pytest.approx(6.55)
    assert atmosphere.pressure_pa(1300.0) == pytest.approx(86651.9, abs=0.1)


def test_11000_m():
    # The tropopause: -56.5 degC and 22632 Pa in the ISA tables.
    assert atmosphere.temperature_c(11000.0) == pytest.approx(-56.5)
    assert atmosphere.pressure_pa(11000.0) == pytest.approx(22632, rel=1e-3)


@given(st.floats(min_value=atmosphere.BOTTOM, max_value=atmosphere.TOP - 1.0))
def test_pressure_and_temperature_fall_with_altitude(h):
    assert atmosphere.pressure_pa(h + 1.0) < atmosphere.pressure_pa(h)
    assert atmosphere.temperature_c(h + 1.0) < atmosphere.temperature_c(h)


@given(st.floats(min_value=0.0, max_value=3000.0))
def test_isothermal_estimate_of_the_exam_is_close_below(h):
    # The exam node's formula with the local temperature underestimates by about L*h^2/(2*T0): the
    # isothermal column above is warmer than the real one, so a given pressure drop means fewer metres.
    estimate = isothermal_altitude(atmosphere.temperature_c(h), atmosphere.pressure_pa(h))
    assert h - 1.2e-5 * h * h - 1e-6 <= estimate <= h + 1e-6


def test_isothermal_estimate_at_the_threshold():
    # The figure the flight profiles are designed around: 1300 m true reads as 1280.7 m.
    estimate = isothermal_altitude(atmosphere.temperature_c(1300.0), atmosphere.pressure_pa(1300.0))
    assert estimate == pytest.approx(1280.75, abs=0.01)


def isothermal_altitude(temperature_c, pressure_pa):
    """The exam sheet's equation (1) solved for h (the exam package owns the real one)."""
    t_k = temperature_c + atmosphere.KELVIN_OFFSET
    return atmosphere.R * t_k / (atmosphere.MU * atmosphere.G) * math.log(atmosphere.P0 / pressure_pa)
