#!/usr/bin/env python3
"""Diagnostics levels (issue 6): the exam node's /diagnostics through health, a stale input and a
failing warning service, and back.

Runs in diagnostics.test. This checker is the drone itself (the harness's fake Drone, scripted
in-process) and watches the two statuses the exam node publishes: "<node>: inputs" (each input's rate
and age) and "<node>: warning" (value, threshold, state, service failures), and that they travel with
"<node>: master" in one array: the node has one Updater (issue 31).

ROS Parameters:
    ~node (str, default "exam"): the exam node's name, prefix of its status names.
    ~timeout (float, s) and ~delay (float, s): the exam node's, to bound how long each level may take.

Subscribed Topics:
    /diagnostics (diagnostic_msgs/DiagnosticArray)
The drone's topics and service are those of exam_lab.harness.fake_drone.Drone (altitude mode).
"""
import sys
import threading
import time
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus

from exam_lab.harness.fake_drone import TEST_RATES, Drone
from exam_lab.harness.wait import wait_until as wait_for

PKG = 'exam_lab'
OK, WARN, ERROR = DiagnosticStatus.OK, DiagnosticStatus.WARN, DiagnosticStatus.ERROR
LEVEL_NAMES = {OK: 'OK', WARN: 'WARN', ERROR: 'ERROR'}
# The node publishes diagnostics at 1 Hz; a level change must show within its cause's own time
# (timeout, delay, retry period) plus a few periods on a loaded machine.
SLACK = 10.0


class DiagnosticsTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        rospy.init_node('check_diagnostics')
        node = rospy.get_param('~node', 'exam')
        cls.timeout = float(rospy.get_param('~timeout'))
        cls.delay = float(rospy.get_param('~delay'))
        cls.inputs_name = node + ': inputs'
        cls.warning_name = node + ': warning'
        cls.master_name = node + ': master'
        cls.prefix = node + ': '
        cls.lock = threading.Lock()
        cls.statuses = {}
        # The names of the node's statuses in each array it published, less diagnostic_updater's
        # "Node starting up" (an array of one status as each is added).
        cls.arrays = []
        cls.sub = rospy.Subscriber('/diagnostics', DiagnosticArray, cls.on_diagnostics)
        cls.drone = Drone('altitude', rates=TEST_RATES['altitude'])  # faster than mydrone: shorter waits
        cls.drone.start(1000.0)

    @classmethod
    def on_diagnostics(cls, msg):
        now = time.monotonic()
        names = {s.name for s in msg.status
                 if s.name.startswith(cls.prefix) and s.message != 'Node starting up'}
        with cls.lock:
            for status in msg.status:
                cls.statuses[status.name] = (now, status)
            if names:
                cls.arrays.append(names)

    def fresh_status(self, name, since, levels):
        """The status `name` received after `since` (monotonic s) if its level is in `levels`."""
        with self.lock:
            arrival, status = self.statuses.get(name, (None, None))
        if status is None or arrival <= since or status.level not in levels:
            return None
        return status

    def wait_level(self, name, levels, within):
        since = time.monotonic()
        status = wait_for(lambda: self.fresh_status(name, since, levels), within)
        if status is None:
            with self.lock:
                last = self.statuses.get(name, (None, None))[1]
            self.fail('%r did not reach %s within %.0f s; last: %s' % (
                name, '/'.join(LEVEL_NAMES[level] for level in levels), within,
                None if last is None else '%s %r' % (LEVEL_NAMES.get(last.level), last.message)))
        return status

    def test_0_every_status_of_the_node_travels_in_one_array(self):
        def with_master():
            with self.lock:
                found = [names for names in self.arrays if self.master_name in names]
            return found if len(found) >= 3 else None
        arrays = wait_for(with_master, SLACK + 10.0)
        self.assertIsNotNone(arrays, 'fewer than 3 arrays with %r within %.0f s' % (self.master_name,
                                                                                     SLACK + 10.0))
        for names in arrays:
            self.assertEqual(names, {self.inputs_name, self.warning_name, self.master_name})

    def test_1_healthy_is_ok_with_rates_ages_value_and_threshold(self):
        self.wait_level(self.inputs_name, (OK,), SLACK + 10.0)
        status = self.wait_level(self.warning_name, (OK,), SLACK)
        inputs = self.wait_level(self.inputs_name, (OK,), SLACK)
        keys = [value.key for value in inputs.values]
        for topic in ('temperature', 'pressure'):
            self.assertTrue(any(topic in key and 'rate' in key for key in keys), keys)
            self.assertTrue(any(topic in key and 'age' in key for key in keys), keys)
        values = {value.key: value.value for value in status.values}
        self.assertIn('threshold [m]', values)
        self.assertAlmostEqual(float(values['threshold [m]']), 1300.0)
        self.assertAlmostEqual(float(values['altitude [m]']), 1000.0, delta=1.0)

    def test_2_stale_input_is_flagged_then_clears(self):
        pressure = self.drone.input_for(1000.0)
        self.drone.feeder.stop('pressure')
        status = self.wait_level(self.inputs_name, (WARN, ERROR), self.timeout + SLACK)
        self.assertIn('pressure', status.message)
        self.drone.feeder.set('pressure', pressure)
        self.wait_level(self.inputs_name, (OK,), SLACK)

    def test_3_failing_service_is_flagged_then_clears(self):
        self.drone.service.configure(refusing=True)
        self.drone.fly_to(1500.0)
        status = self.wait_level(self.warning_name, (WARN, ERROR), self.delay + SLACK)
        rospy.loginfo('failing service: %s %r', LEVEL_NAMES[status.level], status.message)
        self.drone.service.configure(refusing=False)
        # The node retries every second; the next attempt succeeds and the status clears.
        self.wait_level(self.warning_name, (OK,), SLACK)
        self.assertEqual(self.drone.service.colour, 'RED')
        self.assertEqual(self.drone.service.statuses()[-1], 'WARNING')


if __name__ == '__main__':
    rostest.rosrun(PKG, 'diagnostics', DiagnosticsTest, sys.argv)
