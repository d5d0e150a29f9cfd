#!/usr/bin/env python3
"""rostest node of lab/test/simulators/mydrone.test: the node runs a constant 1500 m flight with zero noise."""

import rospy
import rostest

from simulator_checks import SimulatorNodeCase  # beside this script

from mydrone import atmosphere
from mydrone.srv import AltitudeWarning

ALTITUDE = 1500.0  # m, the waypoints of mydrone.test


class TestMydroneNode(SimulatorNodeCase):
    PACKAGE = 'mydrone'
    NODE = 'mydrone'
    SCRIPT = 'mydrone_node.py'
    SENSOR_TOPICS = ('/temperature', '/pressure')
    TRUTH_TOPIC = '/mydrone/true_altitude'
    TRUE_VALUE = ALTITUDE
    SERVICE = '/altitude_warning'
    SERVICE_TYPE = AltitudeWarning
    LED_TOPIC = '/alt_warn_led'
    BAD_PARAMS = (('temperature_rate', '0'),
                  ('pressure_rate', '-2'),
                  ('pressure_noise', 'loud'),
                  ('seed', '1.5'),
                  ('profile', 'nosuch'),
                  ('profile', '[[0,1000],[10,20000],[20,1000]]'))

    def check_readings(self, readings):
        # Float32 keeps about 7 significant digits: 0.01 Pa of 85 kPa, 1e-6 degC of 5 degC.
        self.assertAlmostEqual(readings['/temperature'], atmosphere.temperature_c(ALTITUDE), places=4)
        self.assertAlmostEqual(readings['/pressure'], atmosphere.pressure_pa(ALTITUDE), delta=0.02)


if __name__ == '__main__':
    rospy.init_node('test_mydrone_node')
    rostest.rosrun('exam_lab', 'check_mydrone_node', TestMydroneNode)
