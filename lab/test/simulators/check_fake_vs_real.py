#!/usr/bin/env python3
"""rostest node of lab/test/simulators/fake_vs_real.test: the grader's fake drone cannot be told from the
real one by a node under test.

For each sheet, the real drone (in ``/real_<sheet>``) and the harness's fake drone as the grader's probe
builds it (in ``/fake_<sheet>``, ``on_ticks``) are compared on what a student's node can see: the topics
each advertises in its namespace and their types, the service's type, each input's measured rate (the
fake's values changed in the middle of the window: the change must not add a message), the service's
answer to NORMAL, WARNING, a refused word and a repeated request, and the LED's messages.
"""
import unittest

import rosgraph
import rospy
import rostest
import rosservice
from std_msgs.msg import Float32, String

from exam_lab.harness import fake_drone
from exam_lab.harness.fake_drone import Drone, TopicRecorder

DEADLINE = 30.0
#: Messages of the slowest input (0.778 Hz) the rates are measured over.
MESSAGES = 6
#: Measured rates agree within this share (the real drone's rospy.Timer and the fake's thread).
RATE_TOLERANCE = 0.05
REQUESTS = ('NORMAL', 'WARNING', 'warning', 'WARNING', 'BOOM', 'NORMAL')


def advertised(namespace):
    """{topic relative to ``namespace``: type} of every topic published there, private ones excepted."""
    prefix = namespace + '/'
    out = {}
    for topic, kind in rospy.get_published_topics(namespace):
        relative = topic[len(prefix):]
        if topic.startswith(prefix) and '/' not in relative:
            out[relative] = kind
    return out


def rate(samples):
    times = [t for t, _ in samples]
    return (len(times) - 1) / (times[-1] - times[0]) if len(times) >= 2 and times[-1] > times[0] else None


class FakeIsTheRealDrone(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.drones = {}
        for sheet in ('altitude', 'depth'):
            drone = Drone(sheet, namespace='/fake_%s' % sheet, on_ticks=True)
            drone.feeder.set(drone.fixed_topic, drone.fixed_value)
            drone.fly_to(150.0)
            cls.drones[sheet] = drone

    @classmethod
    def tearDownClass(cls):
        for drone in cls.drones.values():
            drone.close()

    def sheet(self, sheet):
        spec = fake_drone.SHEETS[sheet]
        return spec, '/real_%s' % sheet, '/fake_%s' % sheet

    def test_topics_and_types(self):
        for sheet in ('altitude', 'depth'):
            spec, real, fake = self.sheet(sheet)
            wanted = set(spec['rates']) | {spec['led']}
            rospy.wait_for_service(real + '/' + spec['service'], timeout=DEADLINE)
            self.assertTrue(rospy.wait_for_message(real + '/' + spec['moving'], Float32, timeout=DEADLINE) is not None)
            theirs = advertised(real)
            ours = {topic: kind for topic, kind in advertised(fake).items() if topic != spec['output']}
            self.assertEqual(set(theirs), wanted, theirs)
            self.assertEqual(ours, theirs)
            self.assertEqual(rosservice.get_service_type(fake + '/' + spec['service']),
                             rosservice.get_service_type(real + '/' + spec['service']))

    def test_rates_and_no_extra_message_at_a_change(self):
        recorders = {}
        for sheet in ('altitude', 'depth'):
            spec, real, fake = self.sheet(sheet)
            for topic in spec['rates']:
                for side in (real, fake):
                    recorders[side, topic] = TopicRecorder('%s/%s' % (side, topic), Float32)
        slowest = min(min(fake_drone.SHEETS[s]['rates'].values()) for s in ('altitude', 'depth'))
        rospy.sleep(0.5 * MESSAGES / slowest)
        for drone in self.drones.values():
            drone.fly_to(160.0)
        rospy.sleep(0.5 * MESSAGES / slowest + 0.5)
        measured = {key: rate(r.samples()) for key, r in recorders.items()}
        for recorder in recorders.values():
            recorder.close()
        for sheet in ('altitude', 'depth'):
            spec, real, fake = self.sheet(sheet)
            for topic, hz in spec['rates'].items():
                theirs, ours = measured[real, topic], measured[fake, topic]
                self.assertIsNotNone(theirs, '%s/%s: too few messages' % (real, topic))
                self.assertIsNotNone(ours, '%s/%s: too few messages' % (fake, topic))
                self.assertAlmostEqual(theirs, hz, delta=RATE_TOLERANCE * hz, msg='%s/%s' % (real, topic))
                self.assertAlmostEqual(ours, theirs, delta=RATE_TOLERANCE * hz,
                                       msg='%s/%s %.3f Hz, %s/%s %.3f Hz' % (fake, topic, ours, real, topic, theirs))
            moving = [t for t, _ in recorders[fake, spec['moving']].samples()]
            hz = spec['rates'][spec['moving']]
            self.assertGreater(min(b - a for a, b in zip(moving, moving[1:])), 0.5 / hz,
                               'the change went out as an extra message, not on a tick')

    def test_service_answers_and_led(self):
        for sheet in ('altitude', 'depth'):
            spec, real, fake = self.sheet(sheet)
            answers, recorders = {}, {}
            for side in (real, fake):
                led = recorders[side] = TopicRecorder('%s/%s' % (side, spec['led']), String)
                self.assertEqual(led.wait_for_count(1, DEADLINE), ['GREEN'], side)
                service = '%s/%s' % (side, spec['service'])
                rospy.wait_for_service(service, timeout=DEADLINE)
                call = rospy.ServiceProxy(service, spec['srv'])
                answers[side] = [(r.success, r.message) for r in (call(word) for word in REQUESTS)]
                led.wait_for_count(3, DEADLINE)
            # Read after both: the first side's LED had the other side's calls' time to say more.
            leds = {side: recorder.values() for side, recorder in recorders.items()}
            for recorder in recorders.values():
                recorder.close()
            self.assertEqual(answers[fake], answers[real])
            self.assertEqual([ok for ok, _ in answers[real]], [True, True, False, True, False, True])
            self.assertEqual(leds[fake], leds[real])
            self.assertEqual(leds[real], ['GREEN', 'RED', 'GREEN'])


if __name__ == '__main__':
    rospy.init_node('check_fake_vs_real')
    rostest.rosrun('exam_lab', 'check_fake_vs_real', FakeIsTheRealDrone)
