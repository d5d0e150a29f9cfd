"""The mydrone node's configuration: names, default rates and the physics each sensor reads."""

import pytest

from drone_sim.profile import parse_profile
from mydrone import atmosphere
from mydrone.simulator import SPEC


def test_names_and_default_rates():
    sensors = {s.topic: s for s in SPEC.sensors}
    assert sorted(sensors) == ['pressure', 'temperature']
    assert sensors['temperature'].default_rate == pytest.approx(0.778, abs=0.001)  # seed: 0.777 Hz
    assert sensors['pressure'].default_rate == 2.0
    assert [s.topic for s in SPEC.sensors if s.publishes_truth] == ['pressure']
    assert (SPEC.node_name, SPEC.service_name, SPEC.led_topic, SPEC.truth_topic) == \
        ('mydrone', 'altitude_warning', 'alt_warn_led', 'true_altitude')
    assert SPEC.service_type._type == 'mydrone/AltitudeWarning'


def test_sensors_read_the_isa_atmosphere():
    sensors = {s.topic: s for s in SPEC.sensors}
    assert sensors['temperature'].read(1300.0, 12.0) == pytest.approx(6.55)
    assert sensors['pressure'].read(1300.0, 12.0) == pytest.approx(86651.9, abs=0.1)


def test_default_noises_are_the_documented_ones():
    # docs/architecture.md: 0.1 degC for the thermometer, 3.0 Pa for the barometer.
    sensors = {s.topic: s for s in SPEC.sensors}
    assert (sensors['temperature'].default_noise, sensors['pressure'].default_noise) == (0.1, 3.0)


def test_profiles_stay_within_the_documented_troposphere():
    # The ~profile parameter takes altitudes within [-500, 11000] m (mydrone.simulator's docstring).
    for value in (-500.0, 11000.0):
        parse_profile([[0.0, value], [10.0, value]], SPEC.profiles, SPEC.lower, SPEC.upper)
    for value in (-500.5, 11000.5):
        with pytest.raises(ValueError, match='outside'):
            parse_profile([[0.0, value], [10.0, value]], SPEC.profiles, SPEC.lower, SPEC.upper)

