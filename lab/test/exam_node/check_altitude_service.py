#!/usr/bin/env python3
"""rostest: the exam node facing a warning service that is absent, failing or slow.

Launched by ``altitude_service.test`` beside an exam node with its defaults (threshold 1300 m, delay
5 s). The fake drone starts *without* its service, so ``test_01`` sees a node that has never found it;
the tests run in the order of their names and each later one starts from
:meth:`fake_drone.Drone.settle` with the service up and healthy.

Subscribed Topics: ``altitude`` (std_msgs/Float32, m).
Published Topics: ``temperature`` (std_msgs/Float32, degC), ``pressure`` (std_msgs/Float32, Pa),
``alt_warn_led`` (std_msgs/String, latched).
Services: ``altitude_warning`` (mydrone/AltitudeWarning), the fake drone's.
"""
import sys
import time

import rospy
import rostest

from exam_lab.harness import fake_drone
from exam_lab.harness.wait import wait_until

DELAY = 5.0         # s, the node's default
LOW = 1200.0        # m, below the default threshold 1300 m
HIGH = 1400.0       # m, above it
# Once the service is back, the node's retry must reach it within this many seconds.
DELIVERY = 3.0
# Longest silence on /altitude while a call is stuck: a node that calls from its publishing loop
# would be silent for the whole 2 s call.
MAX_GAP = 0.3


class ServiceScenarios(fake_drone.DroneScenario):
    MODE = 'altitude'
    ADVERTISE = False
    REST = LOW
    FIRST = 'test_01_absent_service_gets_the_state_once_it_appears'

    def tearDown(self):
        self.drone.service.configure(delay=0.0, failing=False)

    def test_01_absent_service_gets_the_state_once_it_appears(self):
        t0 = self.drone.start(LOW)
        self.assertIsNotNone(self.drone.output.wait_for(lambda v: abs(v - LOW) < 1.0, 5.0, t0),
                             'no altitude published while the service is absent')
        t1 = self.drone.fly_to(HIGH)
        time.sleep(DELAY + 1.5)
        # WARNING is wanted since ~t1 + 5 s, and nobody could take it.
        self.assertLess(self.drone.output.max_gap(t1, rospy.get_time()), 0.5,
                        'publishing stalled while the service was absent')
        appeared = rospy.get_time()
        self.drone.service.advertise()
        calls = self.drone.service.wait_for_calls(1, DELIVERY)
        self.assertEqual([s for _, s in calls], ['WARNING'], 'state not delivered once the service appeared')
        self.assertLess(calls[0][0] - appeared, DELIVERY)
        self.assertEqual(len(self.drone.service.wait_for_calls(2, 1.5)), 1, 'WARNING delivered twice')
        end = self.drone.fly_to(LOW)
        calls = self.drone.service.wait_for_calls(2, 2.0)
        self.assertEqual([s for _, s in calls], ['WARNING', 'NORMAL'])
        self.assertLess(calls[1][0] - end, 0.5)

    def test_02_state_flipped_and_back_while_absent_sends_nothing(self):
        self.drone.service.withdraw()
        self.drone.fly([(HIGH, DELAY + 1.0)])  # WARNING wanted...
        self.drone.fly_to(LOW)                  # ...and NORMAL again: the LED, still GREEN, is right.
        time.sleep(0.5)
        self.drone.service.advertise()
        self.assertEqual(self.drone.service.wait_for_calls(1, DELIVERY), [],
                         'a state the LED already shows was sent after the service came back')
        # The node does use the service again: a new excursion is delivered.
        t0 = self.drone.fly_to(HIGH)
        calls = self.drone.service.wait_for_calls(1, DELAY + 2.0)
        self.assertEqual([s for _, s in calls], ['WARNING'])
        self.assertGreater(calls[0][0] - t0, DELAY - 0.5)

    def test_03_failing_service_gets_the_state_when_it_recovers(self):
        self.drone.service.configure(failing=True)
        t0 = self.drone.fly_to(HIGH)
        time.sleep(DELAY + 2.5)
        attempts = self.drone.service.attempts()
        self.assertGreater(len(attempts), 0, 'the node never called the failing service')
        self.assertEqual(set(s for _, s in attempts), {'WARNING'})
        self.assertGreater(attempts[0][0] - t0, DELAY - 0.5)
        self.assertEqual(self.drone.service.calls(), [])
        recovered = rospy.get_time()
        self.drone.service.configure(failing=False)
        calls = self.drone.service.wait_for_calls(1, DELIVERY)
        self.assertEqual([s for _, s in calls], ['WARNING'], 'state not delivered after recovery')
        self.assertLess(calls[0][0] - recovered, DELIVERY)
        self.assertEqual(len(self.drone.service.wait_for_calls(2, 1.5)), 1, 'WARNING delivered twice')

    def test_04_slow_service_never_stalls_publishing(self):
        self.drone.service.configure(delay=2.0)
        service = self.drone.service
        t0 = self.drone.fly_to(HIGH)
        # A slow call is listed once answered: its arrival shows in the attempts at once.
        wait_until(service.attempts, DELAY + 2.0)
        self.assertEqual([s for _, s in service.attempts()], ['WARNING'])
        # Back below while the WARNING call is still in the fake's hands.
        time.sleep(0.5)
        back = self.drone.fly_to(LOW)
        self.assertEqual(service.calls(), [], 'the WARNING call did not last its 2 s')
        # NORMAL may only start once WARNING is answered, and takes 2 s more.
        calls = service.wait_for_calls(2, 6.0)
        end = rospy.get_time()
        self.assertEqual([s for _, s in calls], ['WARNING', 'NORMAL'])
        self.assertGreater(calls[1][0], back)
        gap = self.drone.output.max_gap(t0, end)
        rospy.loginfo('longest silence on altitude during the 2 s calls: %.3f s', gap)
        self.assertLess(gap, MAX_GAP, 'altitude silent for %.2f s during 2 s service calls' % gap)
        # The published value followed the drone during the call, not after it.
        first_low = self.drone.output.wait_for(lambda v: abs(v - LOW) < 1.0, 0.0, back)
        self.assertIsNotNone(first_low, 'the altitude never came back down')
        self.assertLess(first_low[0] - back, 0.5)


if __name__ == '__main__':
    rospy.init_node('service_scenarios')
    rostest.rosrun('exam_lab', 'service_scenarios', ServiceScenarios, sys.argv)
