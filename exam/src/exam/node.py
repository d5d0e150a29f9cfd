"""The exam node: altitude (or depth) from the drone's sensors at 10 Hz, and a debounced warning LED.

This module is the ROS wiring only: it reads the parameters, creates the publishers, subscribers and
timers, and hands every event to pure logic: the physics in :mod:`exam.formulas`, the latest reading of
each input in :mod:`exam.inputs`, the warning rule in :mod:`exam.debounce`, the service calls in
:mod:`exam.warning_link`, what differs between the two drones in :mod:`exam.modes`. The parameter checks
are :mod:`node_kit.params` (shared with the simulators), and /diagnostics is :mod:`exam.diagnostics`.

How one reading travels (each step runs on the thread rospy gives it):

1. A sensor callback validates the reading and caches it (exam question 11: inputs arrive at different
   rates, so the latest value of each is kept). If every input is fresh, it computes the value and feeds
   the debouncer *right away*, so a crossing back below the threshold is acted on within the callback.
2. The debouncer says whether the state changed; if so, the new state is handed to the warning link,
   whose own thread calls the service (question 13). While a WARNING is pending, a one-shot timer is
   armed for the debouncer's ``deadline`` (question 14b), so the WARNING is not late by a reading.
3. A periodic timer publishes the latest value at ``~rate`` Hz, only while every input is fresh; a stale
   input interrupts a pending excess.
4. A timer of :mod:`node_kit.lifecycle` publishes /diagnostics, every ``~diagnostic_period`` s.
5. A thread of :mod:`node_kit.master_link` keeps the node registered across a master restart, and the
   connection to the warning service (:func:`exam.warning_link.service_link`) is opened ahead
   of the first call and kept, so a state decided while the master is down still reaches the drone.

Every timer and callback goes through :mod:`node_kit.lifecycle`, so a stop at any moment ends them
all before rospy closes the publishers: no traceback at Ctrl-C.

State shared by these threads (the caches, the value, the debouncer) is guarded by one lock, held only
for short computations, never across a publish or a service call.

ROS Parameters (private; a value that is given but unusable stops the node with a fatal log naming it):
    ~mode (str, default "altitude"): "altitude" (aerial drone, sheet 000) or "depth" (underwater, 001).
    ~threshold (float, m, default 1300 in altitude mode, 150 in depth mode): the warning limit; only
        values strictly above it are an excess.
    ~delay (float, s, default 5.0, >= 0): how long the excess must last before WARNING.
    ~rate (float, Hz, default 10.0, > 0): publishing rate of the output topic.
    ~timeout (float, s, default 5.0, > 0): an input older than this is stale; nothing is published and
        no excess is timed until it is fresh again.
    ~diagnostic_period (float, s, default 1.0, > 0): seconds between two publications of
        /diagnostics (diagnostic_updater's parameter, read by :func:`node_kit.lifecycle.run`).

Subscribed Topics:
    altitude mode: temperature (std_msgs/Float32, degC), pressure (std_msgs/Float32, Pa),
        alt_warn_led (std_msgs/String, "GREEN"/"RED", latched by the drone).
    depth mode: pressure_robot (std_msgs/Float32, Pa), pressure_remote (std_msgs/Float32, Pa),
        depth_warn_led (std_msgs/String, "GREEN"/"RED", latched by the drone).

Published Topics:
    altitude mode: altitude (std_msgs/Float32, m). depth mode: depth (std_msgs/Float32, m).
    /diagnostics (diagnostic_msgs/DiagnosticArray): "<node>: inputs", "<node>: warning" and
        "<node>: master" statuses.

Services called:
    altitude mode: altitude_warning (mydrone/AltitudeWarning) with "NORMAL" or "WARNING".
    depth mode: depth_warning (submarinedrone/DepthWarning) with "NORMAL" or "WARNING".
"""
import collections
import threading

import rospy
from std_msgs.msg import Float32, String

from exam import diagnostics, messages
from exam.debounce import Debouncer, excess_news
from exam.inputs import InputCache
from exam.modes import MODES
from exam.warning_link import LED_STATES, service_link
from node_kit import lifecycle, master_link, params

#: Seconds between two identical warnings on a 10 Hz path, so a fault does not flood /rosout.
THROTTLE_S = 5.0
#: Seconds between two attempts while the warning service is absent or failing.
RETRY_PERIOD_S = 1.0
#: Seconds the shutdown waits for a service call in progress.
LINK_STOP_S = 1.0
#: Shortest timer rospy can arm [s] (a period of 0 divides by zero in rospy.Rate).
MIN_TIMER_S = 0.001

#: The node's parameters, checked (see the module docstring); ``mode`` is an :class:`exam.modes.Mode`.
Params = collections.namedtuple('Params', 'mode threshold delay rate timeout')


def _param(name, default):
    """(resolved name, value) of the private parameter ``name``, so an error names what was read."""
    return rospy.resolve_name('~' + name), rospy.get_param('~' + name, default)


def read_params():
    """Every parameter, checked before anything is created.

    A value that is given but unusable stops the node: a typo in a launch file must not fly with a
    threshold nobody chose. :raises node_kit.params.ParamError: naming the parameter and the value.
    """
    mode = MODES[params.one_of(*_param('mode', 'altitude'), choices=MODES)]
    return Params(mode=mode,
                  threshold=params.finite_float(*_param('threshold', mode.default_threshold),
                                                unit=mode.unit),
                  delay=params.non_negative_float(*_param('delay', 5.0), unit='s'),
                  rate=params.positive_float(*_param('rate', 10.0), unit='Hz'),
                  timeout=params.positive_float(*_param('timeout', 5.0), unit='s'))


def _names(caches):
    """The resolved topic names of ``caches``, for a log line."""
    return ', '.join(rospy.resolve_name(c.topic) for c in caches)


class ExamNode(object):
    """Computes, publishes and watches one value (altitude or depth); see the module docstring.

    :raises node_kit.params.ParamError: a parameter is unusable (nothing has been created then).
    """

    def __init__(self):
        p = read_params()
        self._mode = mode = p.mode
        self._timeout = p.timeout
        self._lock = threading.Lock()
        self._inputs = [InputCache(spec.topic, spec.why_unusable) for spec in mode.inputs]
        self._debouncer = Debouncer(p.threshold, p.delay)
        self._value = None
        self._armed_deadline = None

        # Outputs and the service link first, inputs and timers last: no callback sees a half-built node.
        self._pub = rospy.Publisher(mode.output, Float32, queue_size=10)
        self._output = rospy.resolve_name(mode.output)
        service = rospy.resolve_name(mode.service)
        self._link = service_link(
            service, lambda: master_link.open_persistent(service, mode.service_type), RETRY_PERIOD_S,
            log=rospy.loginfo, warn=lambda text: rospy.logwarn_throttle(THROTTLE_S, text))
        self._link.start()
        lifecycle.on_stop(lambda: self._link.stop(timeout=LINK_STOP_S))
        rospy.loginfo('%s: mode %s, %s > %.1f %s for %.1f s -> WARNING via %s; publishing %s at %.1f Hz; '
                      'inputs %s stale after %.1f s', rospy.get_name(), mode.name, mode.output,
                      p.threshold, mode.unit, p.delay, service, self._output, p.rate,
                      _names(self._inputs), p.timeout)

        for spec, cache in zip(mode.inputs, self._inputs):
            rospy.Subscriber(spec.topic, Float32, lifecycle.guarded(self._on_reading),
                             callback_args=(spec, cache), queue_size=10)
        rospy.Subscriber(mode.led_topic, String, lifecycle.guarded(self._on_led), queue_size=10)
        lifecycle.timer(1.0 / p.rate, self._on_publish_tick)
        diagnostics.start(self._snapshot, self._link.snapshot, mode, service, p.timeout)

    def _on_reading(self, msg, args):
        """A sensor reading: validate, cache, compute, and let the debouncer judge it at once."""
        spec, cache = args
        now = rospy.get_time()
        change = news = value = None
        with self._lock:
            reason = cache.offer(msg.data, now)
            if reason is None and not self._stale(now):
                value = self._value = self._mode.compute(*(c.value for c in self._inputs))
                before = self._debouncer.deadline
                change = self._debouncer.update(value, now)
                news = excess_news(before, self._debouncer.deadline, change)
        if reason is not None:
            # Never cached, never published, never seen by the debouncer: just reported.
            rospy.logwarn_throttle(THROTTLE_S, 'ignoring %s = %r %s: %s'
                                   % (rospy.resolve_name(spec.topic), msg.data, spec.unit, reason))
            return
        self._report(news, value, messages.back_within(self._mode))
        if change is not None:
            self._announce(change, value)

    def _stale(self, now):
        """The inputs older than ~timeout (or missing), or []. Call under the lock."""
        return [cache for cache in self._inputs if not cache.is_fresh(now, self._timeout)]

    def _interrupt_if_stale(self, now):
        """(stale inputs, news): a stale input interrupts a pending excess, which was not observed
        continuously. Call under the lock."""
        stale = self._stale(now)
        news = None
        if stale:
            news = excess_news(self._debouncer.deadline, None, None)
            self._debouncer.interrupt()
        return stale, news

    def _report(self, news, value, why):
        """Log an excess that began (and arm its deadline) or a pending WARNING cancelled (``why``)."""
        debouncer = self._debouncer
        if news == 'pending':
            rospy.loginfo(messages.excess_began(self._mode, value, debouncer.threshold,
                                                debouncer.excess_since, debouncer.deadline))
            self._arm(debouncer.deadline)
        elif news == 'cancelled':
            rospy.loginfo(messages.excess_cancelled(self._mode, value, why))

    def _arm(self, deadline):
        """Arm a one-shot timer for the debouncer's ``deadline`` (once per deadline)."""
        with self._lock:
            if deadline == self._armed_deadline:
                return
            self._armed_deadline = deadline
        lifecycle.timer(max(deadline - rospy.get_time(), MIN_TIMER_S), self._on_deadline, oneshot=True)

    def _on_deadline(self, event):
        """The timer armed for the deadline fired: the debouncer judges the excess at this instant."""
        now = rospy.get_time()
        change = None
        with self._lock:
            stale, news = self._interrupt_if_stale(now)
            if not stale:
                before = self._debouncer.deadline
                change = self._debouncer.poll(now)
                news = excess_news(before, self._debouncer.deadline, change)
            deadline = self._debouncer.deadline
            value = self._value
            if change is None and deadline is not None:
                self._armed_deadline = None  # a timer woke a little early: arm it again for the rest
        self._report(news, value, 'no fresh reading of %s' % _names(stale))
        if change is not None:
            self._announce(change, value)
        elif deadline is not None:
            self._arm(deadline)

    def _announce(self, state, value):
        """Log a change of the warning state and hand it to the link, which calls the service."""
        rospy.loginfo(messages.state_changed(self._mode, state, value, self._debouncer.threshold,
                                             self._debouncer.delay))
        self._link.want(state)

    def _on_led(self, msg):
        """The drone's LED report: lets the link re-send the wanted state after a drone restart."""
        state = LED_STATES.get(msg.data)
        if state is None:
            rospy.logwarn_throttle(THROTTLE_S, 'ignoring %s = %r: expected GREEN or RED'
                                   % (rospy.resolve_name(self._mode.led_topic), msg.data))
            return
        self._link.led_reported(state)

    def _on_publish_tick(self, event):
        """Publish the latest value, unless an input is missing or stale (then say which, throttled)."""
        now = rospy.get_time()
        with self._lock:
            stale, news = self._interrupt_if_stale(now)
            value = self._value
        if not stale:
            self._pub.publish(Float32(value))
            return
        self._report(news, value, 'no fresh reading of %s' % _names(stale))
        if all(cache.stamp is None for cache in stale):
            rospy.loginfo_throttle(THROTTLE_S, 'waiting for the first reading of %s' % _names(stale))
        else:
            rospy.logwarn_throttle(THROTTLE_S, 'not publishing %s: no fresh reading of %s for more than '
                                   '%.1f s' % (self._output, _names(stale), self._timeout))

    def _snapshot(self):
        """A copy of the state /diagnostics shows, taken under the lock (see exam.diagnostics)."""
        now = rospy.get_time()
        with self._lock:
            return diagnostics.Snapshot(
                inputs=[diagnostics.InputRow(c.topic, c.rate(now), c.age(now), c.rejected)
                        for c in self._inputs],
                value=self._value, state=self._debouncer.state, threshold=self._debouncer.threshold,
                deadline=self._debouncer.deadline)


def main():
    lifecycle.run('exam', ExamNode)
