#!/usr/bin/env python3
"""rostest: in ``<group ns="drone7">`` every name of the exam node lives under /drone7.

Launched by ``namespace.test`` inside the same group as an exam node with delay 1 s (to keep the
excursion short). This node uses relative names too, so its fake drone is /drone7's; the test then
checks the master for the absolute names, and that nothing leaked to the global namespace.

Subscribed Topics: ``altitude`` (std_msgs/Float32, m).
Published Topics: ``temperature`` (std_msgs/Float32, degC), ``pressure`` (std_msgs/Float32, Pa),
``alt_warn_led`` (std_msgs/String, latched).
Services: ``altitude_warning`` (mydrone/AltitudeWarning), the fake drone's.
"""
import sys
import unittest

import rosgraph
import rospy
import rostest

from exam_lab.harness import fake_drone
from exam_lab.harness.wait import wait_until

DELAY = 1.0  # s, as in namespace.test
LOW = 1200.0
HIGH = 1400.0


class NamespaceScenario(unittest.TestCase):

    def test_names_and_warning_under_namespace(self):
        self.assertEqual(rospy.get_namespace(), '/drone7/', 'namespace.test must run this node in /drone7')
        drone = fake_drone.Drone('altitude', rates=fake_drone.TEST_RATES['altitude'])  # faster than mydrone: shorter waits
        drone.start(LOW)
        drone.settle(LOW)
        master = rosgraph.Master(rospy.get_name())

        def exam_node_names():
            publishers, subscribers, _ = master.getSystemState()
            published = {topic for topic, nodes in publishers if '/drone7/exam' in nodes}
            subscribed = {topic for topic, nodes in subscribers if '/drone7/exam' in nodes}
            return published, subscribed

        published, subscribed = exam_node_names()
        self.assertIn('/drone7/altitude', published)
        self.assertTrue({'/drone7/temperature', '/drone7/pressure'} <= subscribed, subscribed)
        self.assertNotIn('/altitude', published)
        self.assertFalse({'/temperature', '/pressure', '/alt_warn_led'} & subscribed, subscribed)

        t0 = drone.fly_to(HIGH)
        calls = drone.service.wait_for_calls(1, DELAY + 3.0)
        self.assertEqual([s for _, s in calls], ['WARNING'],
                         'no WARNING on /drone7/altitude_warning')
        self.assertTrue(DELAY - 0.5 <= calls[0][0] - t0 <= DELAY + 1.5)
        self.assertTrue(wait_until(lambda: drone.output.samples(t0), 2.0))


if __name__ == '__main__':
    rospy.init_node('namespace_scenario')
    rostest.rosrun('exam_lab', 'namespace_scenario', NamespaceScenario, sys.argv)
