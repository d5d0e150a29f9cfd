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


def test_weather_drift_by_hand():
    # P_ATM + 40*sin(2*pi*t/600) + 15*sin(2*pi*t/173 + 1.3) Pa, term by term:
    # t = 0 s: 0 + 15*sin(1.3) = 14.45337; t = 150 s: 40*sin(pi/2) = 40, 15*sin(6.74785) = 6.72183;
    # t = 300 s: 40*sin(pi) = 0, 15*sin(12.19570) = -5.43365.
    assert hydrostatics.surface_pressure_pa(0.0) == pytest.approx(101325.0 + 14.45337, abs=1e-4)
    assert hydrostatics.surface_pressure_pa(150.0) == pytest.approx(101325.0 + 40.0 + 6.72183, abs=1e-4)
    assert hydrostatics.surface_pressure_pa(300.0) == pytest.approx(101325.0 - 5.43365, abs=1e-4)
