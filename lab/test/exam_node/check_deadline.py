#!/usr/bin/env python3
"""rostest: the WARNING comes from the deadline timer, not from the next reading.

Launched by ``deadline.test`` beside an exam node with delay 2 s and timeout 30 s. The fake drone here
publishes a reading only when the test says so, 5 s apart or more: far slower than the delay, and the
long timeout keeps such slow inputs fresh. Between two readings the only thing that can turn a pending
excess into WARNING is the one-shot timer the node arms for its deadline (``ExamNode._arm``). A node
that judged the excess only when a reading arrives would send the WARNING at the next reading, 3 s
late: no timing window on a loaded machine is that wide, so these tests fail without the timer and
pass with it however slow the machine is.

Subscribed Topics: ``altitude`` (std_msgs/Float32, m).
Published Topics: ``temperature`` (std_msgs/Float32, degC), ``pressure`` (std_msgs/Float32, Pa),
``alt_warn_led`` (std_msgs/String, latched).
Services: ``altitude_warning`` (mydrone/AltitudeWarning), the fake drone's.
"""
import sys
import time
import unittest

import rospy
import rostest

from mydrone.srv import AltitudeWarning

from exam_lab.harness import fake_drone, oracle
from exam_lab.harness.wait import wait_until

DELAY = 2.0      # s, as in deadline.test
GAP = 5.0        # s between two readings of the slow sensor: the next reading comes 3 s after the deadline
LOW = 1200.0     # m, below the default threshold of 1300 m
HIGH = 1400.0    # m, above it
# After the first reading above. Late by up to 1.5 s on a loaded machine; the next reading, which a node
# without the timer would wait for, comes at GAP.
WARNING_WINDOW = (DELAY - 0.25, DELAY + 1.5)
#: A rate so slow the feeder never repeats a value during the test: every reading is one the test sends.
NO_REPEAT_HZ = 1.0 / 3600.0


class DeadlineScenarios(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.feeder = fake_drone.SensorFeeder({'temperature': NO_REPEAT_HZ, 'pressure': NO_REPEAT_HZ})
        cls.service = fake_drone.FakeWarningService('altitude_warning', AltitudeWarning, 'alt_warn_led')
        cls.output = fake_drone.TopicRecorder('altitude')
        if not cls.feeder.wait_for_subscribers(30.0):
            raise AssertionError('the exam node never subscribed to temperature and pressure')

    def setUp(self):
        """Both inputs fresh (one reading each), the node at LOW and NORMAL, no call recorded."""
        self.feeder.set('temperature', fake_drone.AIR_TEMPERATURE)
        since = self.reading(LOW)
        if self.output.wait_for(lambda v: abs(v - LOW) < 1.0, 10.0, since) is None:
            raise AssertionError('the exam node published no altitude near %.0f m' % LOW)
        if not wait_until(lambda: self.service.statuses()[-1:] in ([], ['NORMAL']), 10.0):
            raise AssertionError('the exam node did not return to NORMAL: calls %s' % self.service.calls())
        self.service.clear()

    def reading(self, altitude):
        """Publish one pressure reading at ``altitude`` m; return its ROS time."""
        return self.feeder.set('pressure', oracle.pressure_at(altitude, fake_drone.AIR_TEMPERATURE))

    def wait_for_warning(self, since):
        """The calls up to GAP s after ``since``, the instant the next reading of a slow sensor is due."""
        return self.service.wait_for_calls(1, since + GAP - rospy.get_time())

    def assert_warning_after(self, calls, start, what):
        self.assertEqual([s for _, s in calls], ['WARNING'],
                         'no WARNING within %.0f s of %s though no reading came since: the node waits '
                         'for the next reading instead of its %.0f s deadline' % (GAP, what, DELAY))
        elapsed = calls[0][0] - start
        rospy.loginfo('WARNING %.3f s after %s (delay %.1f s)', elapsed, what, DELAY)
        low, high = WARNING_WINDOW
        self.assertTrue(low <= elapsed <= high, 'WARNING %.2f s after %s; expected %.2f..%.2f s'
                        % (elapsed, what, low, high))

    def test_warning_at_the_deadline_between_two_slow_readings(self):
        t0 = self.reading(HIGH)
        calls = self.wait_for_warning(t0)
        self.assert_warning_after(calls, t0, 'the only reading above')
        # The next reading, still above, changes nothing; the first one below is NORMAL at once.
        self.reading(HIGH)
        back = self.reading(LOW)
        calls = self.service.wait_for_calls(2, 2.0)
        self.assertEqual([s for _, s in calls], ['WARNING', 'NORMAL'])
        self.assertLess(calls[1][0] - back, 0.5)

    def test_interrupted_excess_warns_at_the_deadline_of_the_new_one(self):
        # Above, below, above again before the first deadline: the timer armed for the first excess
        # wakes on an excess that no longer exists; the WARNING comes at the second one's deadline.
        t0 = self.reading(HIGH)
        time.sleep(0.5)
        self.reading(LOW)
        time.sleep(1.0)
        t2 = self.reading(HIGH)
        calls = self.wait_for_warning(t2)
        self.assertGreater(calls[0][0] if calls else float('inf'), t0 + DELAY + 0.5,
                           'WARNING at the deadline of an excess that was interrupted')
        self.assert_warning_after(calls, t2, 'the reading above after the interruption')

    def test_excess_ended_between_readings_gives_no_call(self):
        t0 = self.reading(HIGH)
        time.sleep(DELAY - 1.0)
        self.reading(LOW)
        # The timer armed at t0 still wakes at t0 + DELAY: it must find the excess gone.
        self.assertEqual(self.service.wait_for_calls(1, t0 + DELAY + 2.0 - rospy.get_time()), [],
                         'WARNING for an excess that lasted %.1f s of the %.1f s delay'
                         % (DELAY - 1.0, DELAY))


if __name__ == '__main__':
    rospy.init_node('deadline_scenarios')
    rostest.rosrun('exam_lab', 'deadline_scenarios', DeadlineScenarios, sys.argv)
