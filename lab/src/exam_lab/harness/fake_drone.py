"""The lab's one fake drone: scripted sensors, a recording warning service, the LED topic.

It plays the drone for an exam node under test (ours in the rostests and the bench, a student's in the
grader): it publishes the two sensor inputs of either sheet with the values a script sets, serves the
warning service and records every call with the time it arrived, and publishes the LED colour on a
latched topic as the real drones do. It also records what the exam node publishes.

It is the sheet's drone, taken from one place: the topics, their rates, the service's name and type
come from the drone packages' own ``SPEC`` (``mydrone.simulator``, ``submarinedrone.simulator``), the
service's answers and refusals from their LED (:class:`drone_sim.led.WarningLed`), the LED topic's queue
from :data:`drone_sim.simulator.LED_QUEUE`. ``lab/test/simulators/fake_vs_real.test`` flies both side by
side and compares them. With ``on_ticks`` (the grader's probe) a new value goes out at the sensor's next
tick, as a real drone's reading does, never as an extra message; without it (the exam node's rostests,
which also say when they fly faster than the drone: :data:`TEST_RATES`) it goes out at once. Times are ROS time
(``rospy.get_time()``), the clock the exam node counts its delay in, unless a ``clock`` is given: the
grader's probe passes ``time.time`` so that a student's ``/clock`` can never become the judge's.

The values come from :mod:`exam_lab.harness.oracle`, never from the ``exam`` package.

Used in-process, after ``rospy.init_node`` (a rostest test node, the bench driver, the grader's probe)::

    drone = Drone('altitude')            # temperature + pressure, altitude_warning, alt_warn_led
    drone.start(1200.0)                  # waits for the node under test to subscribe, then feeds
    t = drone.fly_to(1500.0)             # ROS time of the first reading at 1500 m
    drone.service.wait_for_calls(1, 10.0)

or as a node of its own: ``rosrun exam_lab fake_drone_node.py`` (a drone process a test can kill).
"""
import math
import struct
import threading
import time
import unittest

import rospy
from std_msgs.msg import Float32, Float64, String

from drone_sim.led import WarningLed
from drone_sim.simulator import LED_QUEUE
from mydrone.simulator import SPEC as MYDRONE
from submarinedrone.simulator import SPEC as SUBMARINEDRONE

from exam_lab.harness import oracle
from exam_lab.harness.wait import wait_until

#: The smallest positive normal number a std_msgs/Float32 carries: a pressure below it is none.
FLOAT32_TINY = 1.1754943508222875e-38

#: Temperature the fake aerial drone flies in, degC (any valid value would do).
AIR_TEMPERATURE = 15.0
#: Pressure the fake remote measures at sea level, Pa.
REMOTE_PRESSURE = oracle.P0
#: What the drone answers a refused request when a test scripts a broken LED driver.
SCRIPTED_REFUSAL = 'LED driver fault (scripted)'


#: The message types whose ``data`` is a float; every other numeric std_msgs type holds an integer.
_FLOAT_TYPES = (Float32, Float64)


def _alive():
    return not rospy.is_shutdown()


class SensorFeeder(object):
    """Publishes each input topic from its own thread at its own rate, with the value the test sets.

    The rates differ and are below the exam node's 10 Hz on purpose: the node must cache the latest
    value of each input rather than wait for a pair. Each topic ticks on a fixed schedule (a late tick
    does not shift the next ones), as a ``rospy.Timer`` of the real drone does. A new value is published
    by :meth:`set` at once, or with ``on_ticks`` at the topic's next tick (no extra message: the
    stream is the real drone's); either way :meth:`set` returns the time of its first message, so a
    test knows when the node saw its first reading of it. Publishing happens under one lock, so a
    periodic message can never overtake a newer value.

    :param rates: dict topic name -> publishing rate in Hz.
    :param tcp_nodelay: ask subscribers for TCP_NODELAY (the bench: no Nagle batching in the stamps).
    :param clock: the function that gives the times returned (default ``rospy.get_time``).
    :param on_ticks: a new value waits for its topic's next tick (the grader's probe).
    """

    def __init__(self, rates, tcp_nodelay=False, clock=None, on_ticks=False):
        self._clock = clock or rospy.get_time
        self._lock = threading.Lock()
        self._ticked = threading.Condition(self._lock)
        self._on_ticks = on_ticks
        self._ticks = {topic: 0 for topic in rates}
        self._tcp_nodelay = tcp_nodelay
        self._pubs = {}
        self._types = {}
        self._values = {}
        self._quiet_until = {}
        self._last_sent = {}
        for topic in rates:
            self._pubs[topic] = rospy.Publisher(topic, Float32, queue_size=10, tcp_nodelay=tcp_nodelay)
            self._types[topic] = Float32
            self._values[topic] = None
            self._quiet_until[topic] = 0.0
        self._stopped = threading.Event()
        self._threads = [threading.Thread(target=self._run, args=(topic, 1.0 / rate))
                         for topic, rate in rates.items()]
        for thread in self._threads:
            thread.daemon = True
            thread.start()

    def connected(self):
        """True when every input topic has a subscriber (the node under test is up and connected)."""
        return all(pub.get_num_connections() > 0 for pub in self._pubs.values())

    def connections(self, topic):
        """How many subscribers ``topic``'s publisher is connected to (rospy refuses one that asked
        for another message type: the master lists it, but it has no connection)."""
        return self._pubs[topic].get_num_connections()

    def wait_for_subscribers(self, timeout):
        return wait_until(self.connected, timeout, alive=_alive)

    def set(self, topic, value):
        """Publish ``value`` from now on; return the time of its first message (now, or with
        ``on_ticks`` the topic's next tick, waited for)."""
        with self._lock:
            self._values[topic] = value
            self._quiet_until[topic] = 0.0
            if not self._on_ticks:
                return self._publish(topic, value)
            tick = self._ticks[topic]
            while self._ticks[topic] == tick and not self._stopped.is_set() and not rospy.is_shutdown():
                self._ticked.wait(0.1)
            return self._last_sent.get(topic)

    def stop(self, topic):
        """Stop publishing ``topic`` (a sensor gone silent); return the ROS time of its last message.
        :meth:`set` starts it again."""
        with self._lock:
            self._values[topic] = None
            return self._last_sent.get(topic)

    def inject(self, topic, value, quiet):
        """Publish one ``value`` (a bad reading) without keeping it, then stay silent ``quiet`` s.

        The silence makes a bad value that the node wrongly cached visible: it would be the latest
        input for several of the node's 10 Hz ticks.
        """
        with self._lock:
            self._quiet_until[topic] = time.monotonic() + quiet
            return self._publish(topic, value)

    def retype(self, topic, msg_class):
        """Publish ``topic`` as ``msg_class`` from now on (a numeric std_msgs type: integer types get the
        value rounded), with the value it had; return the time of its first message.

        The grader's probe does this when rospy refused a node's subscription for another type: the
        publisher is replaced (unregistered, then registered anew), so the master tells the node's
        subscriber about a publisher of its own type and rospy connects it.
        """
        with self._lock:
            self._pubs[topic].unregister()
            self._pubs[topic] = rospy.Publisher(topic, msg_class, queue_size=10, tcp_nodelay=self._tcp_nodelay)
            self._types[topic] = msg_class
            value = self._values[topic]
            return self._publish(topic, value) if value is not None else None

    def close(self):
        """Stop every feeding thread and unregister the publishers."""
        self._stopped.set()
        for thread in self._threads:
            thread.join(2.0)
        for pub in self._pubs.values():
            pub.unregister()

    def _run(self, topic, period):
        due = time.monotonic() + period
        while not rospy.is_shutdown() and not self._stopped.wait(max(0.0, due - time.monotonic())):
            # The next tick on the schedule; one missed entirely (a stalled process) is skipped.
            due = max(due + period, time.monotonic())
            with self._lock:
                value = self._values[topic]
                if value is None or time.monotonic() < self._quiet_until[topic]:
                    continue
                try:
                    self._publish(topic, value)
                except rospy.ROSException:
                    return  # the publisher closed: the node is shutting down
                self._ticks[topic] += 1
                self._ticked.notify_all()

    def _publish(self, topic, value):
        """Publish one message (the caller holds the lock); return its ROS time."""
        self._last_sent[topic] = self._clock()
        kind = self._types[topic]
        self._pubs[topic].publish(kind(value if kind in _FLOAT_TYPES else int(round(value))))
        return self._last_sent[topic]


class FakeWarningService(object):
    """The drone's warning service: sets a fake LED and records every call with its arrival time.

    Like the real drone it answers with the drone's own LED (:class:`drone_sim.led.WarningLed`: its
    success and its words, its refusal of any other request) and publishes the colour on a latched
    topic, GREEN at start, once per change; with ``led_topic`` None it publishes none (a drone without
    LED reports). It can
    be absent (:meth:`withdraw`, or ``advertise=False``), slow (``delay`` s per call), failing (the
    handler raises, so the caller gets a ServiceException) or refusing (answers success false, as a
    broken LED driver would).

    :param on_call: optional function(status, success) called after each answered call.
    :param clock: the function that times the calls (default ``rospy.get_time``).
    """

    def __init__(self, name, srv_class, led_topic, advertise=True, on_call=None, clock=None, label='ALT WARN'):
        self._clock = clock or rospy.get_time
        self._name = name
        self._srv_class = srv_class
        self._on_call = on_call
        self._lock = threading.Lock()
        self._calls = []
        self._answers = []
        self._attempts = []
        self._delay = 0.0
        self._failing = False
        self._refusing = False
        self._service = None
        self._withdrawn = False
        self._led = None
        self._state = WarningLed(label)
        self.colour = self._state.colour
        if led_topic is not None:
            self._led = rospy.Publisher(led_topic, String, queue_size=LED_QUEUE, latch=True)
            self._led.publish(String(self.colour))
        if advertise:
            self.advertise()

    def advertise(self):
        with self._lock:
            self._withdrawn = False
        self._service = rospy.Service(self._name, self._srv_class, self._handle)

    def close(self):
        """Unregister the service, if advertised, without waiting for the master to forget it
        (:meth:`withdraw` waits): the end of a drone, not a scripted failure."""
        if self._service is not None:
            self._service.shutdown('fake drone closed')
            self._service = None

    def withdraw(self):
        """Unregister the service: the node's calls fail as if the drone were gone, also on a
        persistent connection opened before (rospy keeps serving those after a shutdown)."""
        with self._lock:
            self._withdrawn = True
        self._service.shutdown('withdrawn by the test')
        # The master must have forgotten the service, or the caller would still find it.
        resolved = rospy.resolve_name(self._name)
        if wait_until(lambda: not _service_registered(resolved), 5.0) is None:
            raise AssertionError('the master still lists %s 5 s after its shutdown' % resolved)

    def configure(self, delay=0.0, failing=False, refusing=False):
        with self._lock:
            self._delay = delay
            self._failing = failing
            self._refusing = refusing

    def calls(self):
        """Answered calls so far, as (ROS time of arrival in s, status string).

        A status other than NORMAL/WARNING is answered (success false) and listed too, so that a test
        comparing call sequences sees it.
        """
        with self._lock:
            return list(self._calls)

    def answers(self):
        """Every answered call with the drone's answer: (ROS time of arrival, request, success, message).

        A refused request (a status the drone does not know, or a scripted refusal) is a call all the
        same: the grader judges when the node called, and says what the drone answered.
        """
        with self._lock:
            return list(self._answers)

    def statuses(self):
        return [status for _, status in self.calls()]

    def attempts(self):
        """Every call that reached the handler, failed ones included: (time, status)."""
        with self._lock:
            return list(self._attempts)

    def clear(self):
        with self._lock:
            del self._calls[:]
            del self._answers[:]
            del self._attempts[:]

    def wait_for_calls(self, count, timeout):
        """The answered calls once there are at least ``count`` of them, or all there are at timeout."""
        wait_until(lambda: len(self.calls()) >= count, timeout, alive=_alive)
        return self.calls()

    def _handle(self, request):
        now = self._clock()
        with self._lock:
            if self._withdrawn:
                raise rospy.ServiceException('the fake drone is gone (withdrawn by the test)')
            self._attempts.append((now, request.status))
            delay, failing, refusing = self._delay, self._failing, self._refusing
        if delay > 0.0:
            time.sleep(delay)
        if failing:
            raise rospy.ServiceException('the fake drone was told to fail')
        with self._lock:
            if refusing:
                success, message, changed = False, SCRIPTED_REFUSAL, False
            else:
                success, message, changed = self._state.apply(request.status)
            self.colour = self._state.colour
            self._calls.append((now, request.status))
            if changed and self._led is not None:
                self._led.publish(String(self.colour))
        if self._on_call is not None:
            self._on_call(request.status, success)
        with self._lock:
            self._answers.append((now, request.status, success, message))
        return self._srv_class._response_class(success, message)


def _service_registered(resolved_name):
    state = rospy.get_master().getSystemState()[2]
    return any(name == resolved_name for name, _ in state[2])


class TopicRecorder(object):
    """Records every message on ``topic`` as (ROS time of arrival, ``msg.data``).

    :param msg_type: a message type with a ``data`` field (std_msgs/Float32 by default, String for an
        LED topic).
    :param queue_size: messages rospy may hold for the recorder when it falls behind, the oldest
        dropped beyond; None keeps every one (the bench, measuring rates up to 1 kHz on a loaded machine).
    :param clock: the function that times the messages (default ``rospy.get_time``).
    """

    def __init__(self, topic, msg_type=Float32, tcp_nodelay=False, queue_size=100, clock=None):
        self._clock = clock or rospy.get_time
        self._lock = threading.Lock()
        self._samples = []
        self._sub = rospy.Subscriber(topic, msg_type, self._callback, queue_size=queue_size,
                                     tcp_nodelay=tcp_nodelay)

    def samples(self, since=0.0, until=float('inf')):
        with self._lock:
            return [(t, v) for t, v in self._samples if since <= t <= until]

    def values(self):
        """Every value received so far, in order."""
        with self._lock:
            return [v for _, v in self._samples]

    def wait_for_count(self, count, timeout):
        """The first ``count`` values, or the fewer received by ``timeout`` s."""
        wait_until(lambda: len(self.values()) >= count, timeout, alive=_alive)
        return self.values()[:count]

    def clear(self):
        with self._lock:
            del self._samples[:]

    def wait_for(self, predicate, timeout, since=0.0):
        """The first sample after ``since`` whose value satisfies ``predicate``, or None at timeout."""
        def first():
            return next((s for s in self.samples(since) if predicate(s[1])), None)
        return wait_until(first, timeout, alive=_alive)

    def max_gap(self, since, until):
        """Longest interval in s without a sample within [since, until], edges included."""
        times = [since] + [t for t, _ in self.samples(since, until)] + [until]
        return max(b - a for a, b in zip(times, times[1:]))

    def close(self):
        self._sub.unregister()

    def _callback(self, msg):
        now = self._clock()
        with self._lock:
            self._samples.append((now, msg.data))


def _sheet(spec, output, fixed, moving):
    """A sheet's drone from its package's SPEC: inputs and their default rates, the service, the LED;
    plus what the lab adds: the output the exam node publishes, which input stays fixed (at which
    value) and which one moves."""
    return dict(rates={sensor.topic: sensor.default_rate for sensor in spec.sensors},
                service=spec.service_name, srv=spec.service_type, led=spec.led_topic, label=spec.led_label,
                output=output, fixed=fixed, moving=moving)


#: What differs between the two sheets' drones, the drone's part read from its package's SPEC.
SHEETS = {
    'altitude': _sheet(MYDRONE, 'altitude', ('temperature', AIR_TEMPERATURE), 'pressure'),
    'depth': _sheet(SUBMARINEDRONE, 'depth', ('pressure_remote', REMOTE_PRESSURE), 'pressure_robot'),
}
#: Faster inputs than the sheets' drones (0.778 / 2 Hz, 1 / 2 Hz), said so where used: the exam node's
#: scenario rostests (:class:`DroneScenario`), so each waits less for a fresh reading. Never the judge's.
TEST_RATES = {'altitude': {'temperature': 2.0, 'pressure': 5.0},
              'depth': {'pressure_remote': 2.0, 'pressure_robot': 5.0}}


class Drone(object):
    """One fake drone of either sheet: its inputs, its warning service, and the node's output.

    :meth:`fly_to` moves the drone to an altitude (aerial) or depth (underwater) by changing the one
    input that carries it; the other input stays at its constant value.

    :param mode: ``'altitude'`` (sheet 000) or ``'depth'`` (sheet 001).
    :param advertise: start with the warning service advertised.
    :param led: publish the LED topic.
    :param rates: dict topic -> Hz, to override the sheet's drone's rates (say why where you do).
    :param tcp_nodelay: see :class:`SensorFeeder`.
    :param on_call: see :class:`FakeWarningService`.
    :param namespace: where the node under test lives (``'/latency_ours_3'``): every topic and the
        service are resolved in it rather than in this node's namespace, so one process can play the
        drone of several nodes (the bench). ``rates`` still takes the sheet's relative topic names;
        :attr:`fixed_topic` and :attr:`moving_topic` are the resolved ones.
    :param queue_size: of the output recorder, see :class:`TopicRecorder`.
    :param clock: the function every time is read from (default ``rospy.get_time``).
    :param on_ticks: see :class:`SensorFeeder` (the grader's probe: the sheet's drone exactly).
    """

    def __init__(self, mode='altitude', advertise=True, led=True, rates=None, tcp_nodelay=False,
                 on_call=None, namespace='', queue_size=100, clock=None, on_ticks=False):
        sheet = SHEETS[mode]
        self.mode = mode

        def name(relative):
            return namespace.rstrip('/') + '/' + relative if namespace else relative

        #: The input rates flown, Hz, by the sheet's relative topic names.
        self.rates = dict(sheet['rates'], **(rates or {}))
        self.feeder = SensorFeeder({name(topic): rate for topic, rate in self.rates.items()}, tcp_nodelay, clock,
                                   on_ticks)
        self.service = FakeWarningService(name(sheet['service']), sheet['srv'],
                                          name(sheet['led']) if led else None, advertise, on_call, clock,
                                          sheet['label'])
        self.output = TopicRecorder(name(sheet['output']), tcp_nodelay=tcp_nodelay, queue_size=queue_size,
                                    clock=clock)
        fixed_topic, self.fixed_value = sheet['fixed']
        self.fixed_topic = name(fixed_topic)
        self.moving_topic = name(sheet['moving'])

    def input_for(self, value):
        """The moving input that puts the drone at ``value`` m."""
        if self.mode == 'altitude':
            return oracle.pressure_at(value, self.fixed_value)
        return oracle.pressure_robot_at(value, self.fixed_value)

    def can_give(self, value):
        """Whether the drone can be put at ``value`` m: its moving input a positive pressure a
        std_msgs/Float32 carries (a normal number, neither 0 nor infinite), turned back by the oracle
        into a finite value. Any such pressure is flown, however far from the sheet's flights: a node
        whose own values are off by a factor (degrees Celsius for kelvin) is timed where its own value
        crosses the threshold. A fit to a wild value may ask for 586 km (a pressure of 0): never flown."""
        try:
            carried = struct.unpack('f', struct.pack('f', self.input_for(value)))[0]
            back = self.expected(self.fixed_value, carried)
        except (ArithmeticError, ValueError, struct.error):
            return False
        return math.isfinite(carried) and carried >= FLOAT32_TINY and math.isfinite(back)

    def expected(self, fixed, moving):
        """What the exam node must publish for these two input values."""
        if self.mode == 'altitude':
            return oracle.altitude_of(fixed, moving)
        return oracle.depth_of(moving, fixed)

    def start(self, value, timeout=30.0):
        """Wait for the node under test to connect, then feed both inputs at ``value`` m."""
        if not self.feeder.wait_for_subscribers(timeout):
            raise AssertionError('the exam node never subscribed to both inputs within %.0f s' % timeout)
        self.feeder.set(self.fixed_topic, self.fixed_value)
        return self.fly_to(value)

    def fly_to(self, value):
        """Move to ``value`` m now; return the ROS time of the first reading there."""
        return self.feeder.set(self.moving_topic, self.input_for(value))

    def fly(self, schedule):
        """Fly a list of (value in m, seconds to stay); return the start time of each leg.

        The stays are the schedule of the scripted flight, not waits for a result.
        """
        starts = []
        for value, seconds in schedule:
            starts.append(self.fly_to(value))
            time.sleep(seconds)
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
        if not wait_until(lambda: self.service.statuses()[-1:] in ([], ['NORMAL']), timeout,
                          alive=_alive):
            raise AssertionError('the exam node did not return to NORMAL at %.1f m: calls %s'
                                 % (value, self.service.calls()))
        self.service.clear()

    def close(self):
        self.feeder.close()
        self.output.close()
        self.service.close()


class DroneScenario(unittest.TestCase):
    """Base of the exam node's scenario tests: one fake drone per class, each test from a settled state.

    Subclasses set ``MODE`` and ``REST`` (a value in m on the safe side of the threshold), and may name
    in ``FIRST`` the test that must meet the exam node before it ever had an input; unittest runs the
    tests in the order of their names, so that one is named ``test_01_...``. ``ADVERTISE`` False starts
    the drone without its warning service, ``LED`` False without its LED topic. ``RATES`` are the
    input rates: :data:`TEST_RATES` unless a subclass says otherwise, faster than the sheet's drone so
    that the scenarios wait less (the grader's probe flies the drone's own rates).
    """
    MODE = 'altitude'
    ADVERTISE = True
    LED = True
    RATES = None
    REST = None
    FIRST = None

    @classmethod
    def setUpClass(cls):
        cls.drone = Drone(cls.MODE, cls.ADVERTISE, cls.LED, TEST_RATES[cls.MODE] if cls.RATES is None else cls.RATES)

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
        time.sleep(1.5)  # the observation window: nothing may be published in it
        self.assertEqual(drone.output.samples(), [], '%s published with only %s known'
                         % (drone.mode, first_topic))
        if first_topic == drone.fixed_topic:
            both = drone.fly_to(self.REST)
        else:
            both = drone.feeder.set(drone.fixed_topic, drone.fixed_value)
        first = drone.output.wait_for(lambda v: True, 3.0)
        self.assertIsNotNone(first, 'no %s within 3 s of the second input' % drone.mode)
        self.assertGreaterEqual(first[0], both, '%s published before the second input came' % drone.mode)
