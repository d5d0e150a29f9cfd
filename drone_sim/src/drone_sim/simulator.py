"""The ROS wiring shared by the simulated drones: one generic node, configured by a DroneSpec.

Each drone package (mydrone, submarinedrone) describes its sensors, service and topics in a DroneSpec
and calls :func:`run`; the concrete names, defaults and units are listed in that package's simulator
module. The generic node's ROS API:

ROS Parameters
  ~profile (str or list of [time_s, value], default "default")
    A built-in profile name of the drone, or looping waypoints (s, drone's unit).
  ~seed (int, default 0)
    Seed of the sensor noise generators: the same seed gives the same noise.
  ~<sensor>_rate (float, Hz, > 0), one per sensor
    Publication rate of that sensor's topic.
  ~<sensor>_noise (float, sensor's unit, >= 0), one per sensor
    Standard deviation of that sensor's additive Gaussian noise.

Published Topics
  <sensor topic> (std_msgs/Float32), one per sensor
    The noisy reading, at ``~<sensor>_rate``.
  ~<truth topic> (std_msgs/Float32)
    The true profile value, published with every reading of the sensor marked ``publishes_truth``.
  <led topic> (std_msgs/String, latched)
    "GREEN" or "RED"; GREEN at start, then once per change.

Services
  <service> (the drone's warning type: request ``string status``; response ``bool success``,
  ``string message``)
    "NORMAL" sets the LED GREEN, "WARNING" sets it RED; anything else is refused (success false) and
    leaves the LED unchanged.

All times are ROS times, so the node follows ``/clock`` under ``use_sim_time``; the profile's time
counts from the node's start (or from the first clock message under sim time).

A master that restarts finds the node again within about a second, parameters included
(:mod:`node_kit.master_link`, whose "<node>: master" status :mod:`node_kit.lifecycle` publishes on
/diagnostics every ``~diagnostic_period`` s, default 1); the sensors and the service keep working
while it is down. Timers and the service handler go through :mod:`node_kit.lifecycle`: a stop at
any moment is quiet.
"""

import collections
import functools
import threading

import rospy
from std_msgs.msg import Float32, String

from drone_sim.led import WarningLed
from drone_sim.noise import GaussianNoise
from drone_sim.profile import parse_profile
from node_kit import lifecycle, params

Sensor = collections.namedtuple(
    'Sensor', 'topic default_rate default_noise unit read publishes_truth')
Sensor.__doc__ = """One simulated sensor.

topic: relative topic name; also names the params ``~<topic>_rate`` and ``~<topic>_noise`` and the
  noise channel. default_rate: Hz. default_noise: standard deviation in ``unit``. unit: for logs and
  error messages. read: ``read(true_value, t)`` -> noiseless reading, ``t`` in s since start.
publishes_truth: publish the true value on the truth topic with each reading.
"""

DroneSpec = collections.namedtuple(
    'DroneSpec', 'node_name sensors profiles lower upper truth_topic '
                 'service_name service_type led_topic led_label')
DroneSpec.__doc__ = """What makes one drone: default node name, list of Sensor, built-in profiles (name ->
waypoints), allowed profile range [lower, upper], private truth topic, warning service
name and type, LED topic and LED label for messages.
"""


#: Messages the LED topic's queue holds per subscriber: more changes than a writer thread can miss.
LED_QUEUE = 10


def _param(name, default):
    """(resolved name, value) of a private parameter, for error messages that name what was read."""
    return rospy.resolve_name('~' + name), rospy.get_param('~' + name, default)


class SimulatorNode:
    """A drone simulator; see the module docstring for its ROS API.

    :param spec: the DroneSpec of the drone.
    :raises node_kit.params.ParamError: a parameter is invalid.
    """

    def __init__(self, spec):
        self._spec = spec
        # Parameters first: a bad one stops the node before anything is advertised.
        name, value = _param('seed', 0)
        seed = params.seed(name, value)
        name, value = _param('profile', 'default')
        try:
            self._profile = parse_profile(value, spec.profiles, spec.lower, spec.upper)
        except ValueError as err:
            raise params.ParamError(name, value, str(err))
        rates = {}
        noises = {}
        for sensor in spec.sensors:
            rates[sensor.topic] = params.positive_float(
                *_param(sensor.topic + '_rate', sensor.default_rate), unit='Hz')
            sigma = params.non_negative_float(
                *_param(sensor.topic + '_noise', sensor.default_noise), unit=sensor.unit)
            noises[sensor.topic] = GaussianNoise(seed, sensor.topic, sigma)
        rospy.loginfo('%s: profile %s (loop %.1f s), seed %d, %s', rospy.get_name(), self._profile.name,
                      self._profile.period, seed,
                      ', '.join('%s %.3f Hz noise %g %s' % (s.topic, rates[s.topic],
                                                            noises[s.topic].sigma, s.unit)
                                for s in spec.sensors))

        # Publishers and state, before any callback can run.
        self._led = WarningLed(spec.led_label)
        # Serialises concurrent service calls, so the latched topic ends on the LED's final colour.
        self._led_lock = threading.Lock()
        # A queue of several messages: a RED followed within milliseconds by a GREEN (two calls in a
        # row) reaches every connected subscriber as RED then GREEN; a queue of 1 dropped the RED.
        self._led_pub = rospy.Publisher(spec.led_topic, String, latch=True, queue_size=LED_QUEUE)
        self._led_pub.publish(String(data=self._led.colour))
        self._truth_pub = rospy.Publisher('~' + spec.truth_topic, Float32, queue_size=10)
        self._pubs = {s.topic: rospy.Publisher(s.topic, Float32, queue_size=10) for s in spec.sensors}
        self._noises = noises
        # Each timer runs on its own thread; the lock guards the lazily set start time.
        self._start_lock = threading.Lock()
        self._start = rospy.Time.now()

        # Service and timers last.
        self._service = rospy.Service(spec.service_name, spec.service_type, lifecycle.guarded(
            self._on_warning_request, rospy.ServiceException('%s is shutting down' % rospy.get_name())))
        self._timers = [lifecycle.timer(1.0 / rates[s.topic], functools.partial(self._on_tick, s))
                        for s in spec.sensors]

    def _elapsed(self, now):
        """Seconds since the start; under sim time the start is the first clock seen (now is 0 before)."""
        with self._start_lock:
            if self._start.is_zero():
                self._start = now
            return (now - self._start).to_sec()

    def _on_tick(self, sensor, event):
        """Publish one reading of ``sensor`` at the event's time."""
        t = self._elapsed(event.current_real)
        true_value = self._profile.value_at(t)
        reading = self._noises[sensor.topic](sensor.read(true_value, t))
        self._pubs[sensor.topic].publish(Float32(data=reading))
        if sensor.publishes_truth:
            self._truth_pub.publish(Float32(data=true_value))

    def _on_warning_request(self, request):
        """Set the LED from ``request.status``; log and publish only on change."""
        with self._led_lock:
            success, message, changed = self._led.apply(request.status)
            if changed:
                self._led_pub.publish(String(data=self._led.colour))
        if changed:
            rospy.loginfo('%s: %s', self._spec.service_name, message)
        elif not success:
            rospy.logwarn_throttle(5.0, '%s: %s' % (self._spec.service_name, message))
        # rospy builds the response from the tuple of its fields, in .srv order.
        return success, message


def run(spec):
    """Entry point of a drone's node: init, build, spin; exit status 1 on a bad parameter."""
    lifecycle.run(spec.node_name, lambda: SimulatorNode(spec))
