"""The submarine_drone node: an underwater drone diving a profile, and its remote at the surface.

ROS Parameters
  ~profile (str or list of [time_s, depth_m], default "default")
    A built-in dive of submarinedrone.dives ("default", "calm", "deep") or looping waypoints; depths
    within [0, 11000] m.
  ~seed (int, default 0)
    Seed of the sensor noise: the same seed gives the same readings.
  ~pressure_robot_rate (float, Hz, default 2.0)
    Rate of ``pressure_robot``.
  ~pressure_robot_noise (float, Pa, default 20.0)
    Standard deviation of the robot's pressure sensor noise (about 2 mm of water).
  ~pressure_remote_rate (float, Hz, default 1.0)
    Rate of ``pressure_remote``.
  ~pressure_remote_noise (float, Pa, default 3.0)
    Standard deviation of the remote's barometer noise.

Published Topics
  pressure_robot (std_msgs/Float32, Pa)
    Water pressure at the robot: surface pressure + rho*g*depth.
  pressure_remote (std_msgs/Float32, Pa)
    Atmospheric pressure at the remote, at sea level, drifting slowly with the weather.
  ~true_depth (std_msgs/Float32, m)
    The profile's depth, published with every ``pressure_robot`` reading, for evaluation.
  depth_warn_led (std_msgs/String, latched)
    The DEPTH WARN LED of the remote: "GREEN" (at start) or "RED".

Services
  depth_warning (submarinedrone/DepthWarning)
    status "NORMAL" sets the LED GREEN, "WARNING" sets it RED; anything else is refused
    (success false, LED unchanged).
"""

from drone_sim.simulator import DroneSpec, Sensor, run
from submarinedrone import hydrostatics
from submarinedrone.dives import DIVES
from submarinedrone.srv import DepthWarning

SPEC = DroneSpec(
    node_name='submarine_drone',
    sensors=[
        Sensor(topic='pressure_robot', default_rate=2.0, default_noise=20.0, unit='Pa',
               read=lambda depth, t: hydrostatics.pressure_at_depth_pa(
                   hydrostatics.surface_pressure_pa(t), depth),
               publishes_truth=True),
        Sensor(topic='pressure_remote', default_rate=1.0, default_noise=3.0, unit='Pa',
               read=lambda depth, t: hydrostatics.surface_pressure_pa(t), publishes_truth=False),
    ],
    profiles=DIVES, lower=0.0, upper=hydrostatics.DEEPEST,
    truth_topic='true_depth',
    service_name='depth_warning', service_type=DepthWarning,
    led_topic='depth_warn_led', led_label='DEPTH WARN')


def main():
    """Run the submarine_drone node until shutdown."""
    run(SPEC)
