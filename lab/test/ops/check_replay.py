#!/usr/bin/env python3
"""Replay under sim time (issue 6): a generated flight bag played with `rosbag play --clock -r 5`.

Runs in replay.test (use_sim_time=true) next to the exam node. This checker serves altitude_warning and
records every call and every /altitude message with the ROS (bag) time it arrived, then plays the bag
itself, so the bag is generated fresh and the same module computes the expected values offline.
Under sim time a correct node warns 5 s of BAG time after the crossing: 1 s of wall time at -r 5.

Subscribed Topics:
    altitude (std_msgs/Float32, m): what the exam node computes from the replayed readings.

Services:
    altitude_warning (mydrone/AltitudeWarning): records each status with the ROS (bag) time.
"""
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import unittest

import rospy
import rostest
from mydrone.srv import AltitudeWarning, AltitudeWarningResponse
from std_msgs.msg import Float32

import flight_bag
from exam_lab.harness.supervisor import node_pid
from exam_lab.harness.wait import wait_until as wait_for

PKG = 'exam_lab'
RATE = 5.0
THRESHOLD = 1300.0
DELAY = 5.0
# Bag seconds: the clock advances in steps of 5 bag-ms x RATE (rosbag's 100 Hz clock), and each
# 0.1 s of wall latency on a loaded machine costs 0.5 s of bag time.
EARLY = 0.2
LATE = 2.5
ALTITUDE_TOLERANCE = 0.01  # m: float32 carries ~1e-4 m at 1500 m
MIN_COVERAGE = 0.9         # share of the offline altitudes seen; a few may fall between ticks


class ReplayTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        rospy.init_node('check_replay')
        cls.lock = threading.Lock()
        cls.calls = []
        cls.altitudes = []
        cls.service = rospy.Service('altitude_warning', AltitudeWarning, cls.on_warning)
        cls.sub = rospy.Subscriber('altitude', Float32, cls.on_altitude, queue_size=1000)
        cls.workdir = tempfile.mkdtemp(prefix='exam_replay_')
        bag = os.path.join(cls.workdir, 'flight.bag')
        cls.readings = flight_bag.write(bag)
        if wait_for(lambda: node_pid('/exam'), 30.0) is None:
            raise AssertionError('the exam node did not come up')
        # -d: pause after advertising, so the exam node is connected before the first reading.
        cls.play = subprocess.Popen(['rosbag', 'play', '--clock', '-q', '-d', '1', '-r', str(RATE), bag],
                                    stdout=subprocess.DEVNULL)
        duration = flight_bag.WAYPOINTS[-1][0] / RATE
        try:
            cls.play.wait(timeout=duration + 60.0)
        except subprocess.TimeoutExpired:
            cls.play.kill()
            raise
        # The NORMAL call comes after the last reading the exam node needs: wait for it, bounded.
        wait_for(lambda: len(cls.copy()[0]) >= 2, 10.0)

    @classmethod
    def tearDownClass(cls):
        if cls.play.poll() is None:
            cls.play.kill()
        shutil.rmtree(cls.workdir, ignore_errors=True)

    @classmethod
    def on_warning(cls, request):
        with cls.lock:
            cls.calls.append((rospy.get_time(), request.status))
        return AltitudeWarningResponse(success=True, message='recorded')

    @classmethod
    def on_altitude(cls, msg):
        with cls.lock:
            cls.altitudes.append(msg.data)

    @classmethod
    def copy(cls):
        with cls.lock:
            return list(cls.calls), list(cls.altitudes)

    def test_altitudes_match_the_offline_computation(self):
        expected = [h for _t, h in flight_bag.states(self.readings)]
        altitudes = self.copy()[1]
        self.assertTrue(altitudes, 'no altitude published during the replay')
        seen = set()
        index = 0
        for value in altitudes:
            matches = [i for i in range(index, len(expected))
                       if abs(expected[i] - value) <= ALTITUDE_TOLERANCE]
            self.assertTrue(matches, 'published altitude %.4f m is no offline value at or after '
                                     'reading %d (out of order or wrong)' % (value, index))
            index = matches[0]
            seen.add(index)
        coverage = len(seen) / float(len(expected))
        rospy.loginfo('replay: %d altitudes published, %d of %d offline values seen (%.0f %%)',
                      len(altitudes), len(seen), len(expected), 100.0 * coverage)
        self.assertGreaterEqual(coverage, MIN_COVERAGE)

    def test_warning_5s_of_bag_time_after_the_crossing(self):
        up, down = flight_bag.crossings(flight_bag.states(self.readings), THRESHOLD)
        calls = self.copy()[0]
        self.assertEqual([status for _t, status in calls], ['WARNING', 'NORMAL'])
        warning_after = calls[0][0] - (flight_bag.START + up)
        normal_after = calls[1][0] - (flight_bag.START + down)
        rospy.loginfo('replay: WARNING %.2f s (bag) after the crossing, NORMAL %.2f s (bag) after the '
                      'return', warning_after, normal_after)
        self.assertGreaterEqual(warning_after, DELAY - EARLY)
        self.assertLessEqual(warning_after, DELAY + LATE)
        self.assertGreaterEqual(normal_after, -EARLY)
        self.assertLessEqual(normal_after, LATE)


if __name__ == '__main__':
    rostest.rosrun(PKG, 'replay', ReplayTest, sys.argv)
