#!/usr/bin/env python3
"""rostest: the exam node in depth mode (the underwater sheet) with its depth defaults.

Launched by ``depth.test`` beside an exam node given only ``mode: depth``, so threshold 150 m and
delay 5 s come from the node's defaults for that mode. The tests run in the order of their names and
share the node: ``test_01`` must see it before it ever had an input. This fake drone publishes no
LED topic: the exam node must drive the LED from its own record of the calls it made.

Subscribed Topics: ``depth`` (std_msgs/Float32, m).
Published Topics: ``pressure_robot`` (std_msgs/Float32, Pa), ``pressure_remote`` (std_msgs/Float32, Pa).
Services: ``depth_warning`` (submarinedrone/DepthWarning), the fake drone's.
"""
import sys
import time

import rospy
import rostest

from exam_lab.harness import fake_drone

THRESHOLD = 150.0  # m, the node's default in depth mode
DELAY = 5.0        # s
SHALLOW = 100.0    # m
NEAR = 145.0       # m, just shallower than the threshold
DEEP = 160.0       # m, beyond the threshold


class DepthScenarios(fake_drone.DroneScenario):
    MODE = 'depth'
    LED = False
    REST = SHALLOW
    FIRST = 'test_01_nothing_before_both_inputs'

    def test_01_nothing_before_both_inputs(self):
        # The robot's own pressure first this time (the altitude test starts with the other input).
        self.assert_nothing_before_both_inputs('pressure_robot')

    def test_02_formula(self):
        # (P_remote, P_robot) in Pa; float32 carries ~1e-5 m here, rho = 1000 instead of 1030 is metres off.
        self.assert_formula([(101325.0, 1200000.0), (99000.0, 2500000.0), (101325.0, 101325.0)], 0.01)

    def test_03_default_threshold_and_delay(self):
        t0 = self.drone.fly_to(NEAR)
        time.sleep(DELAY + 0.5)
        self.assertIsNotNone(self.drone.output.wait_for(lambda v: abs(v - NEAR) < 1.0, 0.0, t0))
        self.assertEqual(self.drone.service.calls(), [], 'WARNING at %.0f m, above %.0f m deep'
                         % (NEAR, THRESHOLD))
        t1 = self.drone.fly_to(DEEP)
        time.sleep(DELAY + 1.5)
        t2 = self.drone.fly_to(NEAR)
        calls = self.drone.service.wait_for_calls(2, 2.0)
        self.assertEqual([s for _, s in calls], ['WARNING', 'NORMAL'])
        elapsed = calls[0][0] - t1
        self.assertTrue(DELAY - 0.5 <= elapsed <= DELAY + 1.5,
                        'WARNING %.2f s after going below %.0f m' % (elapsed, THRESHOLD))
        self.assertLess(calls[1][0] - t2, 0.5)
        self.assertEqual(len(self.drone.service.wait_for_calls(3, 1.0)), 2)


if __name__ == '__main__':
    rospy.init_node('depth_scenarios')
    rostest.rosrun('exam_lab', 'depth_scenarios', DepthScenarios, sys.argv)
