"""The submarine_drone node's configuration: names, default rates and the physics each sensor reads."""

import pytest

from drone_sim.profile import parse_profile
from submarinedrone import hydrostatics
from submarinedrone.simulator import SPEC


def test_names_and_default_rates():
    sensors = {s.topic: s for s in SPEC.sensors}
    assert sorted(sensors) == ['pressure_remote', 'pressure_robot']
    assert sensors['pressure_robot'].default_rate != sensors['pressure_remote'].default_rate
    assert all(0.0 < s.default_rate < 10.0 for s in SPEC.sensors)
    assert [s.topic for s in SPEC.sensors if s.publishes_truth] == ['pressure_robot']
    assert (SPEC.node_name, SPEC.service_name, SPEC.led_topic, SPEC.truth_topic) == \
        ('submarine_drone', 'depth_warning', 'depth_warn_led', 'true_depth')
    assert SPEC.service_type._type == 'submarinedrone/DepthWarning'


def test_robot_reads_the_same_instants_surface_plus_the_water_column():
    sensors = {s.topic: s for s in SPEC.sensors}
    for t in (0.0, 37.5, 250.0):
        surface = sensors['pressure_remote'].read(150.0, t)
        assert surface == hydrostatics.surface_pressure_pa(t)
        assert sensors['pressure_robot'].read(150.0, t) == pytest.approx(surface + 1030 * 9.80665 * 150.0)


def test_default_rates_and_noises_are_the_documented_ones():
    # docs/architecture.md: the robot's sensor at 2 Hz with 20 Pa of noise, the remote's at 1 Hz with 3 Pa.
    sensors = {s.topic: s for s in SPEC.sensors}
    assert (sensors['pressure_robot'].default_rate, sensors['pressure_robot'].default_noise) == (2.0, 20.0)
    assert (sensors['pressure_remote'].default_rate, sensors['pressure_remote'].default_noise) == (1.0, 3.0)


def test_profiles_stay_within_the_documented_depths():
    # The ~profile parameter takes depths within [0, 11000] m (submarinedrone.simulator's docstring).
    for value in (0.0, 11000.0):
        parse_profile([[0.0, value], [10.0, value]], SPEC.profiles, SPEC.lower, SPEC.upper)
    for value in (-0.5, 11000.5):
        with pytest.raises(ValueError, match='outside'):
            parse_profile([[0.0, value], [10.0, value]], SPEC.profiles, SPEC.lower, SPEC.upper)

