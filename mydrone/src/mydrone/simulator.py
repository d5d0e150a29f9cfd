"""The mydrone node: an aerial drone flying a profile through the ISA atmosphere.

ROS Parameters
  ~profile (str or list of [time_s, altitude_m], default "default")
    A built-in flight of mydrone.flights ("default", "calm", "high") or looping waypoints; altitudes
    within [-500, 11000] m (the ISA troposphere).
  ~seed (int, default 0)
    Seed of the sensor noise: the same seed gives the same readings.
  ~temperature_rate (float, Hz, default 0.778)
    Rate of ``temperature`` (the exam sheet's ``rostopic hz`` shows 0.777 Hz).
  ~temperature_noise (float, degC, default 0.1)
    Standard deviation of the thermometer's noise.
  ~pressure_rate (float, Hz, default 2.0)
    Rate of ``pressure``.
  ~pressure_noise (float, Pa, default 3.0)
    Standard deviation of the barometer's noise.

Published Topics
  temperature (std_msgs/Float32, degC)
    Air temperature at the drone.
  pressure (std_msgs/Float32, Pa)
    Static air pressure at the drone.
  ~true_altitude (std_msgs/Float32, m)
    The profile's altitude, published with every ``pressure`` reading, for evaluation.
  alt_warn_led (std_msgs/String, latched)
    The ALT WARN LED of the remote: "GREEN" (at start) or "RED".

Services
  altitude_warning (mydrone/AltitudeWarning)
    status "NORMAL" sets the LED GREEN, "WARNING" sets it RED; anything else is refused
    (success false, LED unchanged).
"""

from drone_sim.simulator import DroneSpec, Sensor, run
from mydrone import atmosphere
from mydrone.flights import FLIGHTS
from mydrone.srv import AltitudeWarning

SPEC = DroneSpec(
    node_name='mydrone',
    sensors=[
        Sensor(topic='temperature', default_rate=0.778, default_noise=0.1, unit='degC',
               read=lambda altitude, t: atmosphere.temperature_c(altitude), publishes_truth=False),
        Sensor(topic='pressure', default_rate=2.0, default_noise=3.0, unit='Pa',
               read=lambda altitude, t: atmosphere.pressure_pa(altitude), publishes_truth=True),
    ],
    profiles=FLIGHTS, lower=atmosphere.BOTTOM, upper=atmosphere.TOP,
    truth_topic='true_altitude',
    service_name='altitude_warning', service_type=AltitudeWarning,
    led_topic='alt_warn_led', led_label='ALT WARN')


def main():
    """Run the mydrone node until shutdown."""
    run(SPEC)
