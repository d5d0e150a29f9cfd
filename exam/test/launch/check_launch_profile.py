#!/usr/bin/env python3
"""rostest: a waypoint list given as a launch file's `profile` argument is flown by the drone.

Launched by ``launch_profile.test`` (exam.launch) and ``launch_profile_submarine.test``
(exam_submarine.launch), which pass the same list to the launch file and to this node. The drone's
``~profile`` must be that list (a string would be refused), and the drone's true value must follow it:
the samples of the truth topic, shifted by the one unknown (when the drone's clock started), lie on
the looping piecewise-linear profile.

ROS Parameters:
    ~drone (str): the drone's node name (``mydrone`` or ``submarine_drone``).
    ~truth (str): the drone's private truth topic (``true_altitude`` or ``true_depth``).
    ~waypoints (list of [time_s, value]): what the launch file was given.

Subscribed Topics:
    /<drone>/<truth> (std_msgs/Float32, m): the drone's true altitude or depth, with each reading.
"""
import sys
import threading
import time
import unittest

import rospy
import rostest
from std_msgs.msg import Float32

from drone_sim.profile import Profile

#: Arrival jitter the fit tolerates (s): a reading is stamped by the drone when due and seen here later.
JITTER = 0.3
#: Step of the search for the drone's start time (s).
STEP = 0.01
#: Wall time the launch may take to bring the drone up (s).
START_WITHIN = 20.0


class TruthRecorder(object):
    """Every value of a topic with its arrival time (monotonic clock, s); ``spanned`` is set once the
    values cover ``span`` seconds."""

    def __init__(self, topic, span):
        self._lock = threading.Lock()
        self._samples = []
        self._span = span
        self.spanned = threading.Event()
        self._sub = rospy.Subscriber(topic, Float32, self._callback)

    def samples(self):
        with self._lock:
            return list(self._samples)

    def _callback(self, msg):
        now = time.monotonic()
        with self._lock:
            self._samples.append((now, msg.data))
            if now - self._samples[0][0] >= self._span:
                self.spanned.set()


def best_fit(profile, samples):
    """(offset, worst error) of the start offset that puts ``samples`` closest to ``profile``."""
    first = samples[0][0]
    best = None
    for k in range(int(round(profile.period / STEP))):
        offset = k * STEP
        error = max(abs(profile.value_at(t - first + offset) - v) for t, v in samples)
        if best is None or error < best[1]:
            best = (offset, error)
    return best


class LaunchProfile(unittest.TestCase):

    def test_waypoints_argument_is_flown(self):
        drone = rospy.get_param('~drone')
        truth = rospy.get_param('~truth')
        waypoints = rospy.get_param('~waypoints')
        profile = Profile(waypoints)

        given = rospy.get_param('/%s/profile' % drone)
        self.assertEqual(given, waypoints, '/%s/profile is %r' % (drone, given))

        # A little more than one loop, so every waypoint is passed; the drone may take a while to start.
        recorder = TruthRecorder('/%s/%s' % (drone, truth), 1.2 * profile.period)
        self.assertTrue(recorder.spanned.wait(START_WITHIN + 1.2 * profile.period),
                        '%d samples on /%s/%s' % (len(recorder.samples()), drone, truth))
        samples = recorder.samples()
        start = samples[0][0]

        values = [v for _, v in waypoints]
        slopes = [abs(v1 - v0) / (t1 - t0) for (t0, v0), (t1, v1) in zip(waypoints, waypoints[1:])]
        tolerance = JITTER * max(slopes)
        offset, error = best_fit(profile, samples)
        rospy.loginfo('%d samples of /%s/%s over %.1f s; start offset %.2f s, worst error %.2f m '
                      '(tolerance %.1f m)', len(samples), drone, truth, samples[-1][0] - start, offset,
                      error, tolerance)
        self.assertLessEqual(error, tolerance, 'the drone does not fly %r: worst error %.1f m'
                             % (waypoints, error))
        # Both ends of the profile are reached, so a constant or a wrong profile cannot pass.
        seen = [v for _, v in samples]
        self.assertLessEqual(min(seen), min(values) + tolerance)
        self.assertGreaterEqual(max(seen), max(values) - tolerance)


if __name__ == '__main__':
    rospy.init_node('check_launch_profile')
    rostest.rosrun('exam', 'launch_profile', LaunchProfile, sys.argv)
