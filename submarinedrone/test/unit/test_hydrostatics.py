"""Hydrostatics and the weather drift against hand-computed values."""

import pytest

from submarinedrone import hydrostatics


def test_pressure_at_depth():
    # rho*g = 1030*9.80665 = 10100.8495 Pa per metre.
    assert hydrostatics.pressure_at_depth_pa(101325.0, 0.0) == 101325.0
    assert hydrostatics.pressure_at_depth_pa(101325.0, 1.0) == pytest.approx(111425.8495)
    assert hydrostatics.pressure_at_depth_pa(101325.0, 150.0) == pytest.approx(1616452.425)


def test_weather_drift_is_small_and_slow():
    values = [hydrostatics.surface_pressure_pa(t * 0.5) for t in range(2 * 3600)]
    assert max(abs(v - hydrostatics.P_ATM) for v in values) <= 55.0
    # At most about 1 Pa/s, so the two pressure topics sampled a second apart differ by 0.1 mm of depth.
    assert max(abs(b - a) for a, b in zip(values, values[1:])) <= 0.5
    assert max(values) - min(values) > 40.0  # it does drift
