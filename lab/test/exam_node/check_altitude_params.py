#!/usr/bin/env python3
"""rostest: the exam node honours ``~threshold``, ``~delay`` and ``~timeout`` given in the launch file.

Launched by ``altitude_params.test`` beside an exam node with threshold 1500 m, delay 2 s, timeout 2 s:
values a node stuck on its defaults (1300 m, 5 s, 5 s) would betray.

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

THRESHOLD = 1500.0  # m, as in altitude_params.test
DELAY = 2.0         # s
TIMEOUT = 2.0       # s
LOW = 1200.0        # m, below both the default threshold and THRESHOLD
BETWEEN = 1400.0    # m, above the default threshold, below THRESHOLD
HIGH = 1600.0       # m, above both


class ParamScenarios(fake_drone.DroneScenario):
    MODE = 'altitude'
    REST = LOW

    def test_threshold_and_delay(self):
        t0 = self.drone.fly_to(BETWEEN)
        time.sleep(DELAY + 1.5)
        t1 = self.drone.fly_to(HIGH)
        self.assertIsNotNone(self.drone.output.wait_for(lambda v: abs(v - BETWEEN) < 1.0, 0.0, t0))
        calls = self.drone.service.wait_for_calls(1, DELAY + 2.0)
        self.assertEqual([s for _, s in calls], ['WARNING'],
                         'expected only the WARNING above %.0f m, none at %.0f m' % (THRESHOLD, BETWEEN))
        elapsed = calls[0][0] - t1
        self.assertTrue(DELAY - 0.5 <= elapsed <= DELAY + 1.0,
                        'WARNING %.2f s after crossing %.0f m; expected about %.1f s'
                        % (elapsed, THRESHOLD, DELAY))
        time.sleep(0.5)
        t2 = self.drone.fly_to(BETWEEN)
        calls = self.drone.service.wait_for_calls(2, 2.0)
        self.assertEqual([s for _, s in calls], ['WARNING', 'NORMAL'])
        self.assertLess(calls[1][0] - t2, 0.5)

    def test_stale_input_never_changes_the_led(self):
        """While the temperature is stale, no value is computed from old data, so the pressure alone
        changes nothing: above the threshold for longer than the delay, no WARNING; back below after a
        WARNING, no NORMAL until a fresh temperature comes (then at once)."""
        made = len(self.drone.service.calls())
        last = self.drone.feeder.stop('temperature')
        time.sleep(max(0.0, last + TIMEOUT + 1.0 - rospy.get_time()))  # older than ~timeout: stale
        self.drone.fly_to(HIGH)
        time.sleep(DELAY + 2.0)
        self.assertEqual(self.drone.service.calls()[made:], [],
                         'a WARNING from a pressure above the threshold while the temperature was stale')
        self.drone.feeder.set('temperature', fake_drone.AIR_TEMPERATURE)
        calls = self.drone.service.wait_for_calls(made + 1, DELAY + 3.0)
        self.assertEqual([s for _, s in calls[made:]], ['WARNING'], 'no WARNING once the temperature was fresh')
        last = self.drone.feeder.stop('temperature')
        time.sleep(max(0.0, last + TIMEOUT + 1.0 - rospy.get_time()))
        self.drone.fly_to(LOW)
        time.sleep(2.0)
        self.assertEqual([s for _, s in self.drone.service.calls()[made:]], ['WARNING'],
                         'a NORMAL from a pressure back below while the temperature was stale')
        resumed = self.drone.feeder.set('temperature', fake_drone.AIR_TEMPERATURE)
        calls = self.drone.service.wait_for_calls(made + 2, 2.0)
        self.assertEqual([s for _, s in calls[made:]], ['WARNING', 'NORMAL'])
        self.assertLess(calls[-1][0] - resumed, 0.5, 'NORMAL not at once on the fresh temperature')

    def test_stale_input_stops_publishing_until_fresh_data(self):
        for topic, fresh in (('temperature', fake_drone.AIR_TEMPERATURE),
                             ('pressure', self.drone.input_for(LOW))):
            last = self.drone.feeder.stop(topic)
            output = self.drone.output
            # Still publishing a while after the last reading: only older than TIMEOUT is stale.
            self.assertTrue(wait_until(lambda: output.samples(last + TIMEOUT - 0.7), TIMEOUT + 1.0),
                            'publishing stopped before %s was %.1f s old' % (topic, TIMEOUT))
            # Then silent: no value computed from old data.
            quiet_from = last + TIMEOUT + 1.0
            time.sleep(max(0.0, quiet_from + 1.5 - rospy.get_time()))
            late = output.samples(quiet_from)
            self.assertEqual(late, [], 'still publishing %.1f s after %s went silent'
                             % (late[0][0] - last if late else 0.0, topic))
            resumed = self.drone.feeder.set(topic, fresh)
            self.assertIsNotNone(output.wait_for(lambda v: abs(v - LOW) < 1.0, 1.0, resumed),
                                 'publishing did not resume on fresh %s' % topic)


if __name__ == '__main__':
    rospy.init_node('param_scenarios')
    rostest.rosrun('exam_lab', 'param_scenarios', ParamScenarios, sys.argv)
