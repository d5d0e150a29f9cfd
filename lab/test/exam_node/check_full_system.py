#!/usr/bin/env python3
"""rostest: the real simulated drone and the exam node, as the product's launch file starts them.

Launched by ``full_system.test`` (exam.launch) and ``full_system_submarine.test``
(exam_submarine.launch), each giving the simulator a short custom profile: a brief excursion past the
threshold (no warning expected), then a long one (RED after the delay, GREEN at the return). This node
only watches: the LED must go GREEN -> RED -> GREEN exactly, never repeating a colour, with RED one
delay after the exam node's output crossed the threshold and GREEN as soon as it came back.

ROS Parameters:
    ~mode (str, "altitude" or "depth"): which drone is under test.
    ~threshold (float, m): the threshold the launch file gave the exam node.
    ~delay (float, s): the delay the launch file gave the exam node.
    ~duration (float, s): by when the long excursion is over, counted from this node's start.

Subscribed Topics:
    ``altitude`` or ``depth`` (std_msgs/Float32, m): the exam node's output.
    ``alt_warn_led`` or ``depth_warn_led`` (std_msgs/String, latched): the simulated drone's LED.
"""
import sys
import unittest

import rospy
import rostest
from std_msgs.msg import String

from exam_lab.harness.fake_drone import TopicRecorder
from exam_lab.harness.wait import wait_until

TOPICS = {'altitude': ('altitude', 'alt_warn_led'), 'depth': ('depth', 'depth_warn_led')}


def run_above(samples, index, threshold):
    """Time of the first sample of the run of samples above ``threshold`` that contains ``index``."""
    while index > 0 and samples[index - 1][1] > threshold:
        index -= 1
    return samples[index][0]


class FullSystem(unittest.TestCase):

    def test_led_goes_red_after_delay_and_back_green_once(self):
        mode = rospy.get_param('~mode')
        threshold = float(rospy.get_param('~threshold'))
        delay = float(rospy.get_param('~delay'))
        duration = float(rospy.get_param('~duration'))
        output_topic, led_topic = TOPICS[mode]
        output = TopicRecorder(output_topic)
        led = TopicRecorder(led_topic, String)
        start = rospy.get_time()

        wait_until(lambda: len(led.samples()) >= 3, duration)
        # A repeated or extra colour would show up within a few more readings.
        wait_until(lambda: len(led.samples()) >= 4, 2.0)
        colours = led.samples()
        names = [c for _, c in colours]
        for first, second in zip(names, names[1:]):
            self.assertNotEqual(first, second, 'the LED repeated a colour: %s' % names)
        self.assertEqual(names, ['GREEN', 'RED', 'GREEN'])

        samples = output.samples()
        self.assertGreater(len(samples), 0, 'no %s published' % output_topic)
        red, green = colours[1][0], colours[2][0]
        # The exam node's output while the LED turned red: above the threshold, since the delay.
        at_red = max(i for i, (t, _) in enumerate(samples) if t <= red)
        self.assertGreater(samples[at_red][1], threshold, 'RED while %s was %.1f m'
                           % (output_topic, samples[at_red][1]))
        excess = red - run_above(samples, at_red, threshold)
        self.assertTrue(delay - 0.5 <= excess <= delay + 1.5,
                        'RED %.2f s after %s went above %.0f m; expected about %.1f s'
                        % (excess, output_topic, threshold, delay))
        back = next(t for t, v in samples if t > red and v <= threshold)
        # GREEN comes from the same reading as the first published value back; either may arrive first.
        self.assertTrue(-0.3 <= green - back <= 0.5,
                        'GREEN %.2f s after %s came back' % (green - back, output_topic))

        # The 10 Hz output kept flowing throughout.
        end = rospy.get_time()
        rate = len(output.samples(start + 1.0, end)) / (end - start - 1.0)
        rospy.loginfo('LED %s; RED %.2f s after the crossing, GREEN %+.2f s from the return; %s at %.1f Hz',
                      names, excess, green - back, output_topic, rate)
        self.assertTrue(8.0 <= rate <= 12.0, '%s at %.1f Hz' % (output_topic, rate))


if __name__ == '__main__':
    rospy.init_node('full_system')
    rostest.rosrun('exam_lab', 'full_system', FullSystem, sys.argv)
