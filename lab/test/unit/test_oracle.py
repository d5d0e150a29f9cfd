"""The harness's oracle against the sheets' numbers typed here by hand, and the debounce rule's text."""
import math

import pytest

from exam_lab.harness import oracle


def test_pressure_at_inverts_the_seed_formula():
    p = oracle.pressure_at(1300.0, 15.0)
    altitude = 8.31432 * (15.0 + 273.15) / (0.0289644 * 9.80665) * math.log(101325.0 / p)
    assert altitude == pytest.approx(1300.0, abs=1e-6)
    assert oracle.pressure_at(0.0, 15.0) == pytest.approx(101325.0)
