"""The scripted fake drone that the exam node's rostests play against.

Each rostest test node *is* the drone: it publishes the two sensor inputs on a schedule the test
writes, serves the warning service the exam node calls, and records what the exam node publishes and
calls, with the time each arrived. Times are ROS time (``rospy.get_time()``), the clock the exam node
counts its delay in.

The physics here is written again from the exam sheets on purpose, not imported from the ``exam``
package: a test that reuses the code under test cannot catch a wrong constant.

Not a node by itself: the test scripts beside it import it (the directory of a script is on its
``sys.path``) after ``rospy.init_node``.
"""
import math
import threading
import time
import unittest

import rospy
from std_msgs.msg import Float32, String

from mydrone.srv import AltitudeWarning
from submarinedrone.srv import DepthWarning

# Equation (1) of the aerial sheet and its constants (SI units).
P0 = 101325.0
MU = 0.0289644
G = 9.80665
R = 8.31432
# The underwater sheet: salt water density, kg/m^3.
RHO = 1030.0

#: Temperature the fake aerial drone flies in, degC (any valid value would do).
AIR_TEMPERATURE = 15.0
#: Pressure the fake remote measures at sea level, Pa.
REMOTE_PRESSURE = P0


def altitude_of(temperature_c, pressure_pa):
    """Altitude in m from equation (1): h = R*T/(mu*g) * ln(P0/P), T in K."""
    return R * (temperature_c + 273.15) / (MU * G) * math.log(P0 / pressure_pa)


def pressure_at(altitude_m, temperature_c=AIR_TEMPERATURE):
    """Pressure in Pa that equation (1) gives at this altitude and temperature."""
    return P0 * math.exp(-MU * G * altitude_m / (R * (temperature_c + 273.15)))


def depth_of(pressure_robot, pressure_remote):
    """Depth in m of the underwater sheet: (P_robot - P_remote) / (rho*g)."""
    return (pressure_robot - pressure_remote) / (RHO * G)


def wait_until(predicate, timeout, step=0.02):
    """Poll ``predicate`` until it is true or ``timeout`` s of wall time pass; return its last value.

    Wall time, so a test cannot hang when ROS time stops; the polling step keeps the reaction to an
    event far below the timing windows the tests assert.
    """
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value or time.monotonic() >= deadline or rospy.is_shutdown():
            return value
        time.sleep(step)


def hold(seconds):
    """Let the scenario run for ``seconds``: the drone keeps flying as it was told meanwhile.

    This is the schedule of the scripted flight (e.g. stay above the threshold for 3 s), not a wait
    for a result: results are awaited with :func:`wait_until` deadlines.
    """
    time.sleep(seconds)


class SensorFeeder(object):
    """Publishes each input topic from its own thread at its own rate, with the value the test sets.

    The rates differ and are below the exam node's 10 Hz on purpose: the node must cache the latest
    value of each input rather than wait for a pair. A new value is published at once by :meth:`set`
    and the time returned, so a test knows when the exam node saw its first reading of it. Publishing
    happens under one lock, so a periodic message can never overtake a newer value.
    """

    def __init__(self, rates):
        """:param rates: dict topic name -> publishing rate in Hz."""
        self._lock = threading.Lock()
        self._pubs = {}
        self._values = {}
        self._quiet_until = {}
        self._last_sent = {}
        for topic in rates:
            self._pubs[topic] = rospy.Publisher(topic, Float32, queue_size=10)
            self._values[topic] = None
            self._quiet_until[topic] = 0.0
        self._threads = [threading.Thread(target=self._run, args=(topic, 1.0 / rate))
                         for topic, rate in rates.items()]
        for thread in self._threads:
            thread.daemon = True
            thread.start()

    def wait_for_subscribers(self, timeout):
        """True once every input topic has a subscriber (the exam node is up and connected)."""
        return wait_until(lambda: all(pub.get_num_connections() > 0 for pub in self._pubs.values()),
                          timeout)

    def set(self, topic, value):
        """Publish ``value`` now and keep publishing it; return the ROS time of the first message."""
        with self._lock:
            self._values[topic] = value
            self._quiet_until[topic] = 0.0
            return self._publish(topic, value)

    def stop(self, topic):
        """Stop publishing ``topic`` (a sensor gone silent); return the ROS time of its last message.

        :meth:`set` starts it again.
        """
        with self._lock:
            self._values[topic] = None
            return self._last_sent.get(topic)

    def inject(self, topic, value, quiet):
        """Publish one ``value`` (a bad reading) without caching it, then stay silent ``quiet`` s.

        The silence makes a bad value that the exam node wrongly cached visible: it would be the
        latest input for several of the node's 10 Hz ticks.
        """
        with self._lock:
            self._quiet_until[topic] = time.monotonic() + quiet
            return self._publish(topic, value)

    def _run(self, topic, period):
        while not rospy.is_shutdown():
            time.sleep(period)
            with self._lock:
                value = self._values[topic]
                if value is None or time.monotonic() < self._quiet_until[topic]:
                    continue
                try:
                    self._publish(topic, value)
                except rospy.ROSException:
                    return  # the publisher closed: the test node is shutting down

    def _publish(self, topic, value):
        """Publish one message (the caller holds the lock); return its ROS time."""
        self._pubs[topic].publish(Float32(value))
        self._last_sent[topic] = rospy.get_time()
        return self._last_sent[topic]


class FakeWarningService(object):
    """The drone's warning service: sets a fake LED and records every call with its arrival time.

    Like the real drone it publishes the LED colour on a latched topic, GREEN at start, following the
    calls it accepts; with ``led_topic`` None it publishes none (a drone without LED reports). It can
    be absent (:meth:`withdraw`, or ``advertise=False``), slow (``delay`` s
    per call) or failing (the handler raises, so the caller gets a ServiceException).
    """

    def __init__(self, name, srv_class, led_topic, advertise=True):
        self._name = name
        self._srv_class = srv_class
        self._lock = threading.Lock()
        self._calls = []
        self._attempts = []
        self._delay = 0.0
        self._failing = False
        self._service = None
        self._led = None
        if led_topic is not None:
            self._led = rospy.Publisher(led_topic, String, queue_size=1, latch=True)
            self._led.publish(String('GREEN'))
        if advertise:
            self.advertise()

    def advertise(self):
        self._service = rospy.Service(self._name, self._srv_class, self._handle)

    def withdraw(self):
        """Unregister the service: the exam node's calls fail as if the drone were gone."""
        self._service.shutdown('withdrawn by the test')
        # The master must have forgotten the service, or the caller would still find it.
        resolved = rospy.resolve_name(self._name)
        if not wait_until(lambda: not _service_registered(resolved), 5.0):
            raise AssertionError('the master still lists %s 5 s after its shutdown' % resolved)

    def configure(self, delay=0.0, failing=False):
        with self._lock:
            self._delay = delay
            self._failing = failing

    def calls(self):
        """Answered calls so far, as (ROS time of arrival in s, status string).

        A status other than NORMAL/WARNING is answered (success false) and listed too, so that a test
        comparing call sequences sees it.
        """
        with self._lock:
            return list(self._calls)

    def statuses(self):
        return [status for _, status in self.calls()]

    def attempts(self):
        """Every call that reached the handler, failed ones included: (time, status)."""
        with self._lock:
            return list(self._attempts)

    def clear(self):
        with self._lock:
            del self._calls[:]
            del self._attempts[:]

    def wait_for_calls(self, count, timeout):
        """The answered calls once there are at least ``count`` of them, or all there are at timeout."""
        wait_until(lambda: len(self.calls()) >= count, timeout)
        return self.calls()

    def _handle(self, request):
        now = rospy.get_time()
        with self._lock:
            self._attempts.append((now, request.status))
            delay, failing = self._delay, self._failing
        if delay > 0.0:
            time.sleep(delay)
        if failing:
            raise rospy.ServiceException('the fake drone was told to fail')
        valid = request.status in ('NORMAL', 'WARNING')
        with self._lock:
            self._calls.append((now, request.status))
        if valid and self._led is not None:
            self._led.publish(String('RED' if request.status == 'WARNING' else 'GREEN'))
        return self._srv_class._response_class(valid, 'LED set' if valid else 'unknown status')


def _service_registered(resolved_name):
    state = rospy.get_master().getSystemState()[2]
    return any(name == resolved_name for name, _ in state[2])


class TopicRecorder(object):
    """Records every Float32 the exam node publishes on ``topic`` as (ROS time of arrival, value)."""

    def __init__(self, topic):
        self._lock = threading.Lock()
        self._samples = []
        self._sub = rospy.Subscriber(topic, Float32, self._callback, queue_size=100)

    def samples(self, since=0.0, until=float('inf')):
        with self._lock:
            return [(t, v) for t, v in self._samples if since <= t <= until]

    def wait_for(self, predicate, timeout, since=0.0):
        """The first sample after ``since`` whose value satisfies ``predicate``, or None at timeout."""
        def first():
            return next((s for s in self.samples(since) if predicate(s[1])), None)
        return wait_until(first, timeout)

    def max_gap(self, since, until):
        """Longest interval in s without a sample within [since, until], edges included."""
        times = [since] + [t for t, _ in self.samples(since, until)] + [until]
        return max(b - a for a, b in zip(times, times[1:]))

    def _callback(self, msg):
        now = rospy.get_time()
        with self._lock:
            self._samples.append((now, msg.data))


class Drone(object):
    """One fake drone of either sheet: its inputs, its warning service, and the exam node's output.

    :meth:`fly_to` moves the drone to an altitude (aerial) or depth (underwater) by changing the one
    input that carries it; the other input stays at its constant value.
    """

    def __init__(self, mode='altitude', advertise=True, led=True):
        self.mode = mode
        if mode == 'altitude':
            self.feeder = SensorFeeder({'temperature': 2.0, 'pressure': 5.0})
            self.service = FakeWarningService('altitude_warning', AltitudeWarning,
                                              'alt_warn_led' if led else None, advertise)
            self.output = TopicRecorder('altitude')
            self.fixed_topic, self.fixed_value = 'temperature', AIR_TEMPERATURE
            self.moving_topic = 'pressure'
        else:
            self.feeder = SensorFeeder({'pressure_remote': 2.0, 'pressure_robot': 5.0})
            self.service = FakeWarningService('depth_warning', DepthWarning,
                                              'depth_warn_led' if led else None, advertise)
            self.output = TopicRecorder('depth')
            self.fixed_topic, self.fixed_value = 'pressure_remote', REMOTE_PRESSURE
            self.moving_topic = 'pressure_robot'

    def input_for(self, value):
        """The moving input that puts the drone at ``value`` m."""
        if self.mode == 'altitude':
            return pressure_at(value)
        return REMOTE_PRESSURE + value * RHO * G

    def expected(self, fixed, moving):
        """What the exam node must publish for these two input values."""
        if self.mode == 'altitude':
            return altitude_of(fixed, moving)
        return depth_of(moving, fixed)

    def start(self, value, timeout=30.0):
        """Wait for the exam node to connect, then feed both inputs at ``value`` m."""
        if not self.feeder.wait_for_subscribers(timeout):
            raise AssertionError('the exam node never subscribed to both inputs within %.0f s' % timeout)
        self.feeder.set(self.fixed_topic, self.fixed_value)
        return self.fly_to(value)

    def fly_to(self, value):
        """Move to ``value`` m now; return the ROS time of the first reading there."""
        return self.feeder.set(self.moving_topic, self.input_for(value))

    def fly(self, schedule):
        """Fly a list of (value in m, seconds to stay); return the start time of each leg."""
        starts = []
        for value, seconds in schedule:
            starts.append(self.fly_to(value))
            hold(seconds)
        return starts

    def settle(self, value, timeout=15.0):
        """Bring the node to NORMAL at ``value`` m (below threshold) and forget what was recorded.

        Each test starts from the same state: inputs fresh, the last call (if any) NORMAL.
        """
        since = self.fly_to(value)
        published = self.output.wait_for(lambda v: abs(v - value) < 1.0, timeout, since)
        if published is None:
            raise AssertionError('the exam node published no %s near %.1f m within %.0f s'
                                 % (self.mode, value, timeout))
        if not wait_until(lambda: self.service.statuses()[-1:] in ([], ['NORMAL']), timeout):
            raise AssertionError('the exam node did not return to NORMAL at %.1f m: calls %s'
                                 % (value, self.service.calls()))
        self.service.clear()


class DroneScenario(unittest.TestCase):
    """Base of the scenario tests: one fake drone per class, and each test from a settled state.

    Subclasses set ``MODE`` and ``REST`` (a value in m on the safe side of the threshold), and may name
    in ``FIRST`` the test that must meet the exam node before it ever had an input; unittest runs the
    tests in the order of their names, so that one is named ``test_01_...``. ``ADVERTISE`` False starts
    the drone without its warning service, ``LED`` False without its LED topic.
    """
    MODE = 'altitude'
    ADVERTISE = True
    LED = True
    REST = None
    FIRST = None

    @classmethod
    def setUpClass(cls):
        cls.drone = Drone(cls.MODE, cls.ADVERTISE, cls.LED)

    def setUp(self):
        if self._testMethodName != self.FIRST:
            self.drone.start(self.REST)
            self.drone.settle(self.REST)

    def assert_formula(self, cases, tolerance):
        """Each (fixed input, moving input) pair makes the node publish the sheet's value, within
        ``tolerance`` m; the fixed input is set back afterwards."""
        drone = self.drone
        for fixed, moving in cases:
            expected = drone.expected(fixed, moving)
            drone.feeder.set(drone.fixed_topic, fixed)
            since = drone.feeder.set(drone.moving_topic, moving)
            sample = drone.output.wait_for(lambda v: abs(v - expected) < tolerance, 3.0, since)
            self.assertIsNotNone(sample, '%s=%r, %s=%r: expected %.4f m, published %s'
                                 % (drone.fixed_topic, fixed, drone.moving_topic, moving, expected,
                                    [v for _, v in drone.output.samples(since)][-5:]))
        drone.feeder.set(drone.fixed_topic, drone.fixed_value)

    def assert_nothing_before_both_inputs(self, first_topic):
        """Feed ``first_topic`` alone for a while: no output; then the other one: output at once."""
        drone = self.drone
        self.assertTrue(drone.feeder.wait_for_subscribers(30.0), 'the exam node never subscribed')
        if first_topic == drone.fixed_topic:
            drone.feeder.set(first_topic, drone.fixed_value)
        else:
            drone.fly_to(self.REST)
        hold(1.5)
        self.assertEqual(drone.output.samples(), [], '%s published with only %s known'
                         % (drone.mode, first_topic))
        if first_topic == drone.fixed_topic:
            both = drone.fly_to(self.REST)
        else:
            both = drone.feeder.set(drone.fixed_topic, drone.fixed_value)
        first = drone.output.wait_for(lambda v: True, 3.0)
        self.assertIsNotNone(first, 'no %s within 3 s of the second input' % drone.mode)
        self.assertGreaterEqual(first[0], both, '%s published before the second input came' % drone.mode)
