#!/usr/bin/env python3
"""rostest: the exam node in altitude mode with its default parameters, against a scripted fake drone.

Launched by ``altitude.test`` beside an exam node with no parameter set (threshold 1300 m, delay 5 s,
rate 10 Hz, timeout 5 s). The tests run in the order of their names and share that one node:
``test_01`` must see it before it ever had an input; every later test starts from
:meth:`fake_drone.Drone.settle` (inputs fresh, below the threshold, LED state NORMAL).

Subscribed Topics: ``altitude`` (std_msgs/Float32, m).
Published Topics: ``temperature`` (std_msgs/Float32, degC), ``pressure`` (std_msgs/Float32, Pa),
``alt_warn_led`` (std_msgs/String, latched).
Services: ``altitude_warning`` (mydrone/AltitudeWarning), the fake drone's.
"""
import math
import sys
import time

import rospy
import rostest

from exam_lab.harness import fake_drone

THRESHOLD = 1300.0  # m, the node's default in altitude mode
DELAY = 5.0         # s, the node's default
LOW = 1200.0        # m, clearly below THRESHOLD
HIGH = 1400.0       # m, clearly above
# Windows, generous for a loaded 2-core machine; each is far from what a wrong node would do.
WARNING_WINDOW = (DELAY - 0.5, DELAY + 1.5)  # s after the first reading above the threshold
NORMAL_LATENCY = 0.5                         # s after the first reading back below


class AltitudeScenarios(fake_drone.DroneScenario):
    MODE = 'altitude'
    REST = LOW
    FIRST = 'test_01_nothing_before_both_inputs'

    def assert_saw(self, value, since, until):
        """Guard against a vacuous "no call": the node did publish ``value`` during the scenario."""
        values = [v for _, v in self.drone.output.samples(since, until)]
        self.assertTrue(any(abs(v - value) < 1.0 for v in values),
                        'the node never published %.1f m between the scenario times; got %s'
                        % (value, values[-10:]))

    def assert_no_call_until(self, deadline):
        calls = self.drone.service.wait_for_calls(1, deadline - rospy.get_time())
        self.assertEqual(calls, [], 'warning calls though never %.0f s above %.0f m' % (DELAY, THRESHOLD))

    def test_01_nothing_before_both_inputs(self):
        self.assert_nothing_before_both_inputs('temperature')

    def test_02_formula(self):
        # (degC, Pa) across the sheet's range, all below the threshold so that no call interferes.
        # 0.05 m: float32 carries ~1e-4 m here; 273 instead of 273.15 K is already ~0.6 m off.
        self.assert_formula([(15.0, 90000.0), (-10.0, 88000.0), (35.5, 89000.0)], 0.05)

    def test_03_short_excursion_gives_no_call(self):
        t0 = self.drone.fly_to(HIGH)
        time.sleep(3.0)
        t1 = self.drone.fly_to(LOW)
        self.assert_saw(HIGH, t0, t1)
        self.assert_no_call_until(t0 + WARNING_WINDOW[1])

    def test_04_long_excursion_warns_after_delay_then_normal_at_return(self):
        t0 = self.drone.fly_to(HIGH)
        time.sleep(7.0)
        t1 = self.drone.fly_to(LOW)
        calls = self.drone.service.wait_for_calls(2, 3.0)
        self.assertEqual([s for _, s in calls], ['WARNING', 'NORMAL'])
        self.assert_warning_time(calls[0][0] - t0)
        rospy.loginfo('WARNING %.3f s after the first reading above, NORMAL %.3f s after the return',
                      calls[0][0] - t0, calls[1][0] - t1)
        self.assertLess(calls[1][0] - t1, NORMAL_LATENCY, 'NORMAL late after the return below')
        # Once per change of state: nothing more while the state holds.
        self.assertEqual(len(self.drone.service.wait_for_calls(3, 1.5)), 2)

    def test_05_chattering_without_five_uninterrupted_seconds_gives_no_call(self):
        fast = [(HIGH, 0.2), (LOW, 0.2)] * 8
        slow = [(HIGH, 1.0), (LOW, 0.3)] * 3
        # The longest stay above is 4.3 s: no WARNING, though 9 s above in total.
        starts = self.drone.fly(fast + slow + [(HIGH, 4.3)])
        end = self.drone.fly_to(LOW)
        self.assert_saw(HIGH, starts[-1], end)
        self.assert_no_call_until(end + 1.5)

    def test_06_chattering_after_warning_alternates_states(self):
        t0 = self.drone.fly_to(HIGH)
        self.assertEqual(len(self.drone.service.wait_for_calls(1, DELAY + 2.5)), 1)
        dip, _, dip2 = self.drone.fly([(LOW, 0.3), (HIGH, 2.0), (LOW, 0.3)])
        t3 = self.drone.fly_to(HIGH)
        self.drone.service.wait_for_calls(3, DELAY + 2.5)
        end = self.drone.fly_to(LOW)
        calls = self.drone.service.wait_for_calls(5, 1.5)
        statuses = [s for _, s in calls]
        for first, second in zip(statuses, statuses[1:]):
            self.assertNotEqual(first, second, 'two equal calls in a row: %s' % statuses)
        self.assertEqual(statuses, ['WARNING', 'NORMAL', 'WARNING', 'NORMAL'])
        self.assert_warning_time(calls[0][0] - t0)
        self.assertLess(calls[1][0] - dip, NORMAL_LATENCY)
        # The 2 s back above between the dips is not enough: the second WARNING counts from t3.
        self.assertGreater(calls[2][0], dip2)
        self.assert_warning_time(calls[2][0] - t3)
        self.assertLess(calls[3][0] - end, NORMAL_LATENCY)

    def test_07_bad_temperature_is_ignored(self):
        self.check_bad_inputs('temperature', [float('nan'), float('inf'), float('-inf'), -273.2, -1000.0])

    def test_08_bad_pressure_is_ignored(self):
        self.check_bad_inputs('pressure', [float('nan'), float('inf'), float('-inf'), 0.0, -1000.0])

    def check_bad_inputs(self, topic, values):
        """Bad readings amid a long excursion: not published, and they neither reset nor end it.

        They come from 2 s to 4.5 s into the excursion: had one of them reset the debounce, the WARNING
        would come at least 7 s after the start, outside the window.
        """
        t0 = self.drone.fly_to(HIGH)
        time.sleep(2.0)
        for value in values:
            self.drone.feeder.inject(topic, value, 0.4)
            time.sleep(0.5)
        calls = self.drone.service.wait_for_calls(1, t0 + WARNING_WINDOW[1] - rospy.get_time())
        self.assertEqual([s for _, s in calls], ['WARNING'], 'bad %s values %s' % (topic, values))
        self.assert_warning_time(calls[0][0] - t0)
        now = rospy.get_time()
        published = [v for _, v in self.drone.output.samples(t0, now)]
        wrong = [v for v in published if not math.isfinite(v) or abs(v - HIGH) > 1.0]
        self.assertEqual(wrong, [], 'values published from bad %s input' % topic)
        # Still alive and publishing at its rate throughout.
        self.assertLess(self.drone.output.max_gap(t0, now), 0.5)

    def assert_warning_time(self, elapsed):
        low, high = WARNING_WINDOW
        self.assertTrue(low <= elapsed <= high,
                        'WARNING %.2f s after the first reading above; expected %.1f..%.1f s'
                        % (elapsed, low, high))


if __name__ == '__main__':
    rospy.init_node('altitude_scenarios')
    rostest.rosrun('exam_lab', 'altitude_scenarios', AltitudeScenarios, sys.argv)
