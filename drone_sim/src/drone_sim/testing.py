"""Checks shared by the simulators' tests (imported by tests only, never by a node).

Both drones come from the same generic node, so one test case checks both; each package's test node
subclasses SimulatorNodeCase and fills in its names and expected readings. The rostest file runs the
node with zero noise and a constant profile, so every reading has an exact expected value.
:func:`documented_profiles` reads the built-in profiles back from the docstring that describes them,
so the unit tests can hold each package's table to its documentation; :func:`accepts_profile_at` tells
whether a drone takes a profile at a given value.
"""

import re
import subprocess
import threading
import time
import unittest

import rospy
import rosservice
from std_msgs.msg import Float32, String

from drone_sim.profile import parse_profile

DEADLINE = 30.0  # s; generous, the test machine is shared


class Recorder:
    """Collects the messages of one topic, thread-safely, and waits for them with a deadline."""

    def __init__(self, topic, msg_type):
        self._lock = threading.Lock()
        self._messages = []
        self._sub = rospy.Subscriber(topic, msg_type, self._on_message)

    def _on_message(self, msg):
        with self._lock:
            self._messages.append(msg.data)

    def messages(self):
        with self._lock:
            return list(self._messages)

    def wait_for(self, count, deadline=DEADLINE):
        """The first ``count`` messages, or the fewer received by the deadline."""
        end = time.monotonic() + deadline
        while time.monotonic() < end and len(self.messages()) < count and not rospy.is_shutdown():
            time.sleep(0.05)
        return self.messages()[:count]

    def close(self):
        self._sub.unregister()


class SimulatorNodeCase(unittest.TestCase):
    """Subclasses set the class attributes below and implement check_readings."""

    PACKAGE = None  # e.g. 'mydrone'
    SCRIPT = None  # e.g. 'mydrone_node.py'
    NODE = None  # the node's default name, e.g. 'mydrone'
    SENSOR_TOPICS = ()  # absolute names of the Float32 sensor topics
    TRUTH_TOPIC = None  # absolute name of the private truth topic
    TRUE_VALUE = None  # the constant profile value of the .test file
    SERVICE = None  # absolute service name
    SERVICE_TYPE = None  # the service class
    LED_TOPIC = None  # absolute name of the latched LED topic
    # (private param, value as given on a command line): each must stop the node with a fatal log
    # naming the resolved parameter
    BAD_PARAMS = ()

    def check_readings(self, readings):
        """Assert the first reading of each sensor topic; ``readings`` maps topic -> value."""
        raise NotImplementedError

    def test_advertised_types(self):
        expected = {topic: 'std_msgs/Float32' for topic in self.SENSOR_TOPICS + (self.TRUTH_TOPIC,)}
        expected[self.LED_TOPIC] = 'std_msgs/String'
        end = time.monotonic() + DEADLINE
        while True:
            published = dict(rospy.get_published_topics())
            if all(published.get(t) == kind for t, kind in expected.items()) or time.monotonic() > end:
                break
            time.sleep(0.1)
        self.assertEqual({t: published.get(t) for t in expected}, expected)
        rospy.wait_for_service(self.SERVICE, timeout=DEADLINE)
        self.assertEqual(rosservice.get_service_type(self.SERVICE), self.SERVICE_TYPE._type)

    def test_readings_and_truth(self):
        recorders = {t: Recorder(t, Float32) for t in self.SENSOR_TOPICS + (self.TRUTH_TOPIC,)}
        readings = {t: r.wait_for(1) for t, r in recorders.items()}
        for recorder in recorders.values():
            recorder.close()
        for topic, values in readings.items():
            self.assertEqual(len(values), 1, 'no message on %s within %.0f s' % (topic, DEADLINE))
        self.assertAlmostEqual(readings[self.TRUTH_TOPIC][0], self.TRUE_VALUE, places=3)
        self.check_readings({t: v[0] for t, v in readings.items()})

    def test_service_drives_latched_led(self):
        led = Recorder(self.LED_TOPIC, String)
        self.assertEqual(led.wait_for(1), ['GREEN'], 'the latched LED must start GREEN')
        rospy.wait_for_service(self.SERVICE, timeout=DEADLINE)
        call = rospy.ServiceProxy(self.SERVICE, self.SERVICE_TYPE)
        responses = [call(status) for status in ('warning', 'WARNING', 'WARNING', 'BOOM', 'NORMAL')]
        self.assertEqual([r.success for r in responses], [False, True, True, False, True])
        for refused in (responses[0], responses[3]):
            self.assertIn("'NORMAL'", refused.message)
            self.assertIn("'WARNING'", refused.message)
        self.assertIn('RED', responses[1].message)
        self.assertIn('GREEN', responses[4].message)
        # One message per change: a refused or repeated request publishes nothing. The node publishes
        # before it answers, so all three are on their way by now.
        self.assertEqual(led.wait_for(3), ['GREEN', 'RED', 'GREEN'])
        led.close()
        # A late subscriber gets the current colour from the latch.
        late = Recorder(self.LED_TOPIC, String)
        self.assertEqual(late.wait_for(1), ['GREEN'])
        late.close()

    def test_bad_params_exit_nonzero(self):
        # One namespace per case: `_name:=value` stays on the parameter server after the node exits,
        # and would otherwise be the first bad value the next case's node meets.
        # No subTest: rosunit's XML runner drops subtest failures and reports the test as passed.
        outcomes = []
        for i, (param, value) in enumerate(self.BAD_PARAMS):
            namespace = '/bad%d' % i
            resolved = '%s/%s/%s' % (namespace, self.NODE, param)
            try:
                done = subprocess.run(['rosrun', self.PACKAGE, self.SCRIPT, '__ns:=' + namespace,
                                       '_%s:=%s' % (param, value)],
                                      stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                      universal_newlines=True, timeout=DEADLINE)
            finally:
                rospy.delete_param(namespace)
            outcomes.append((param, value, done.returncode != 0, resolved in done.stdout, done.stdout))
        # Compared as a whole, so a failure shows every case with the node's output.
        self.assertEqual([o[:4] for o in outcomes], [o[:2] + (True, True) for o in outcomes],
                         '\n'.join(o[4] for o in outcomes))


def documented_profiles(docstring):
    """The waypoints ``[[time_s, value], ...]`` that a profile module's docstring gives, by name.

    Three forms, as mydrone.flights and submarinedrone.dives write them (values in m)::

        ``name`` (loop T s)::           followed by a row "time s ..." and a row "<quantity> m ..."
        ``name`` (loop T s): v0 m -> v1 m -> ... -> vN m at t0, t1, ..., tN s
        ``name`` (loop T s): v m all the time
    """
    number = r'-?[0-9.]+'
    profiles = {}
    table = r'``(\w+)`` \(loop %s s\)::\s*\n\s*time +s +([-0-9. ]+)\n\s*\w+ +m +([-0-9. ]+)' % number
    for name, times, values in re.findall(table, docstring):
        profiles[name] = [[float(t), float(v)] for t, v in zip(times.split(), values.split())]
    chain = r'``(\w+)`` \(loop %s s\): ((?:%s m -> )+%s m) at ([-0-9., ]+) s' % (number, number, number)
    for name, values, times in re.findall(chain, docstring):
        values = [float(v) for v in re.findall(number, values)]
        profiles[name] = [[float(t), v] for t, v in zip(times.split(','), values)]
    constant = r'``(\w+)`` \(loop (%s) s\): (%s) m all the time' % (number, number)
    for name, period, value in re.findall(constant, docstring):
        profiles[name] = [[0.0, float(value)], [float(period), float(value)]]
    return profiles


def accepts_profile_at(spec, value):
    """Whether the drone of DroneSpec ``spec`` takes, as its ~profile, a constant profile at ``value``."""
    try:
        parse_profile([[0.0, value], [10.0, value]], spec.profiles, spec.lower, spec.upper)
    except ValueError:
        return False
    return True
