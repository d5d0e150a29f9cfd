#!/usr/bin/env python3
"""rostest node of lab/test/simulators/submarinedrone.test: the node runs a constant 200 m dive with zero noise."""

import rospy
import rostest

from simulator_checks import SimulatorNodeCase  # beside this script

from submarinedrone import hydrostatics
from submarinedrone.srv import DepthWarning

DEPTH = 200.0  # m, the waypoints of submarinedrone.test


class TestSubmarineDroneNode(SimulatorNodeCase):
    PACKAGE = 'submarinedrone'
    NODE = 'submarine_drone'
    SCRIPT = 'submarine_drone_node.py'
    SENSOR_TOPICS = ('/pressure_robot', '/pressure_remote')
    TRUTH_TOPIC = '/submarine_drone/true_depth'
    TRUE_VALUE = DEPTH
    SERVICE = '/depth_warning'
    SERVICE_TYPE = DepthWarning
    LED_TOPIC = '/depth_warn_led'
    BAD_PARAMS = (('pressure_robot_rate', '0.0'),
                  ('pressure_remote_rate', 'fast'),
                  ('pressure_remote_noise', '-1'),
                  ('seed', 'true'),
                  ('profile', '[[0,10],[5,-3],[10,10]]'))

    def check_readings(self, readings):
        # The weather drift stays within 55 Pa of the mean; it moves about 1 Pa/s, so two readings
        # taken up to a second apart still give the depth within a millimetre (plus Float32 rounding).
        self.assertAlmostEqual(readings['/pressure_remote'], hydrostatics.P_ATM, delta=60.0)
        # The robot's pressure is the remote's plus that of DEPTH metres of water, within 1 cm of water.
        expected = hydrostatics.pressure_at_depth_pa(readings['/pressure_remote'], DEPTH)
        one_cm_pa = hydrostatics.pressure_at_depth_pa(0.0, 0.01)
        self.assertAlmostEqual(readings['/pressure_robot'], expected, delta=one_cm_pa)


if __name__ == '__main__':
    rospy.init_node('test_submarine_drone_node')
    rostest.rosrun('exam_lab', 'check_submarine_drone_node', TestSubmarineDroneNode)
