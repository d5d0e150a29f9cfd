#!/usr/bin/env python3
"""Restart re-sync (issue 6): a drone or exam node that crashes and respawns is brought back in line.

Runs in restart.test against fake_drone_node.py (hovering above the threshold, respawn="true") and the exam
node (respawn="true", ~delay from the test's ~delay param). Each phase kills processes with SIGKILL, as
a crash or power loss would, and reads the calls from the drone's own record.

ROS Parameters:
    ~delay (float, s): the exam node's ~delay, which the restarted pair must wait again.

Subscribed Topics:
    fake_drone/record (std_msgs/String, JSON): the drone's calls, see fake_drone_node.py.
    altitude (std_msgs/Float32, m): proof that a respawned exam node publishes again.
"""
import json
import os
import signal
import sys
import threading
import time
import unittest

import rospy
import rostest
from std_msgs.msg import Float32, String

from exam_lab.harness.supervisor import node_pid
from exam_lab.harness.wait import stays, wait_until as wait_for

PKG = 'exam_lab'
EXAM = '/exam'
DRONE = '/fake_drone'
# The bound from the drone's LED coming back GREEN to the WARNING being re-sent.
RESYNC_BOUND = 2.0
# Long enough to see a repeated call: the exam node retries every second and publishes at 10 Hz.
STEADY_WINDOW = 3.0
# Room for a respawn on a loaded 2-core machine (python start-up and rospy registration).
RESPAWN_TIMEOUT = 30.0


class Latest(object):
    """Keeps the latest message of a topic and its arrival time (wall clock, s), under a lock."""

    def __init__(self, topic, msg_type):
        self._lock = threading.Lock()
        self._msg = None
        self._stamp = None
        self.sub = rospy.Subscriber(topic, msg_type, self._on_msg)

    def _on_msg(self, msg):
        with self._lock:
            self._msg = msg
            self._stamp = time.time()

    def get(self):
        """(message, arrival time); both None until one arrived."""
        with self._lock:
            return self._msg, self._stamp


class DroneRecord(Latest):
    """The latched JSON record of fake_drone_node.py (pid, started, led, calls)."""

    def __init__(self, topic='fake_drone/record'):
        super(DroneRecord, self).__init__(topic, String)

    def record(self):
        msg = self.get()[0]
        return None if msg is None else json.loads(msg.data)


def kill_node(name):
    """SIGKILL a node (a crash, not a clean shutdown) and return the pid it had."""
    pid = node_pid(name)
    if pid is None:
        raise AssertionError('node %s is not running' % name)
    os.kill(pid, signal.SIGKILL)
    return pid


def process_start_time(pid):
    """Wall-clock start time (s since the epoch) of a local process, from /proc (10 ms resolution)."""
    with open('/proc/%d/stat' % pid) as stat:
        # Field 22 is the start time in clock ticks after boot; count fields after the ')' of the name.
        start_ticks = int(stat.read().rsplit(')', 1)[1].split()[19])
    age = time.clock_gettime(time.CLOCK_BOOTTIME) - start_ticks / float(os.sysconf('SC_CLK_TCK'))
    return time.time() - age


class RestartTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        rospy.init_node('check_restart')
        cls.delay = float(rospy.get_param('~delay'))
        cls.drone = DroneRecord()
        cls.altitude = Latest('altitude', Float32)

    def calls(self):
        record = self.drone.record()
        return None if record is None else [status for _stamp, status in record['calls']]

    def new_drone_record(self, old_pid):
        record = self.drone.record()
        return record if record is not None and record['pid'] != old_pid else None

    def record_with_calls(self):
        record = self.drone.record()
        return record if record is not None and record['calls'] else None

    @staticmethod
    def respawned(name, old_pid):
        """Pid of the process that replaced old_pid as node `name`, once it is registered."""
        return wait_for(lambda: (node_pid(name) if node_pid(name) not in (None, old_pid) else None),
                        RESPAWN_TIMEOUT)

    def assert_steady(self, expected):
        """The drone has received exactly `expected` and nothing more for STEADY_WINDOW."""
        self.assertTrue(stays(lambda: self.calls() == expected, STEADY_WINDOW),
                        'calls %s, expected exactly %s in steady state' % (self.calls(), expected))

    def test_1_one_warning_then_silence(self):
        self.assertIsNotNone(wait_for(self.drone.record, RESPAWN_TIMEOUT), 'no record from %s' % DRONE)
        self.assertIsNotNone(wait_for(lambda: self.calls() or None, self.delay + 20.0),
                             'no WARNING call while hovering above the threshold')
        self.assert_steady(['WARNING'])

    def test_2_drone_restart_gets_warning_again(self):
        old_pid = kill_node(DRONE)
        record = wait_for(lambda: self.new_drone_record(old_pid), RESPAWN_TIMEOUT)
        self.assertIsNotNone(record, 'the drone did not respawn within %.0f s' % RESPAWN_TIMEOUT)
        # The new drone published GREEN at `started`; the re-sync may already be in its first record.
        record = wait_for(self.record_with_calls, RESYNC_BOUND + 10.0)
        self.assertIsNotNone(record, 'WARNING was never re-sent to the restarted drone')
        first_stamp, first_status = record['calls'][0]
        self.assertEqual(first_status, 'WARNING')
        resync = first_stamp - record['started']
        rospy.loginfo('re-sync: WARNING %.3f s after the restarted drone published GREEN', resync)
        self.assertLessEqual(resync, RESYNC_BOUND, 'WARNING re-sent after %.3f s' % resync)
        self.assert_steady(['WARNING'])
        self.assertEqual(self.drone.record()['led'], 'RED')

    def test_3_exam_restart_alone_keeps_the_led_red(self):
        old_pid = kill_node(EXAM)
        self.assertIsNotNone(self.respawned(EXAM, old_pid),
                             'the exam node did not respawn within %.0f s' % RESPAWN_TIMEOUT)
        restarted = time.time()
        self.assertIsNotNone(wait_for(lambda: (self.altitude.get()[1] or 0.0) > restarted, 20.0),
                             'the respawned exam node publishes no altitude')
        # The respawned node reads RED from the latched LED and wants WARNING after the delay: nothing
        # to send, and above all no NORMAL that would flash the LED green for `delay` seconds.
        self.assertTrue(stays(lambda: self.calls() == ['WARNING'], self.delay + STEADY_WINDOW),
                        'calls after the exam node restarted: %s' % self.calls())
        self.assertEqual(self.drone.record()['led'], 'RED')

    def test_4_both_restart_warning_after_the_delay(self):
        old_drone = kill_node(DRONE)
        old_exam = kill_node(EXAM)
        exam_pid = self.respawned(EXAM, old_exam)
        self.assertIsNotNone(exam_pid, 'the exam node did not respawn')
        exam_started = process_start_time(exam_pid)
        self.assertIsNotNone(wait_for(lambda: self.new_drone_record(old_drone), RESPAWN_TIMEOUT),
                             'the drone did not respawn')
        record = wait_for(self.record_with_calls, self.delay + 20.0)
        self.assertIsNotNone(record, 'the respawned pair never reached WARNING')
        stamp, status = record['calls'][0]
        self.assertEqual(status, 'WARNING')
        after = stamp - exam_started
        rospy.loginfo('both restarted: WARNING %.3f s after the exam process started (delay %.1f s)',
                      after, self.delay)
        # Never before the delay (the debounce starts from the first reading, after start-up), and
        # within the delay plus a generous start-up allowance.
        self.assertGreaterEqual(after, self.delay)
        self.assertLessEqual(after, self.delay + 15.0)
        self.assert_steady(['WARNING'])


if __name__ == '__main__':
    rostest.rosrun(PKG, 'restart_resync', RestartTest, sys.argv)
