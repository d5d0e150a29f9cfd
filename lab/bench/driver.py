"""The ROS side of the benchmark: scripted sensor readings, a fake warning service, stream monitors.

One rospy node (``/bench``) plays the drone for the node under test: it publishes ``temperature`` and
``pressure`` in that node's namespace, serves ``altitude_warning`` and records each call, and subscribes
``altitude`` with ``tcp_nodelay`` so Nagle's algorithm does not bunch messages and fake jitter.

Every stamp is ``rospy.get_time()`` (ROS time) taken right before a publish or on entry to a callback, so
latencies compare stamps of one clock. Each stage uses a fresh namespace, so a node of an earlier stage
that is still shutting down cannot feed or call this one.
"""

import os
import threading
import time

import rospy
from mydrone.srv import AltitudeWarning, AltitudeWarningResponse
from std_msgs.msg import Float32

from stats import pressure_at

TEMPERATURE_C = 15.0
# mydrone's default sensor rates (0.778 Hz and 2 Hz): the node under test sees the same input load as
# with the simulator; scripted steps are published at once on top of them.
TEMPERATURE_PERIOD = 1.0 / 0.778
PRESSURE_PERIOD = 0.5


def init(uri):
    """Join the master at ``uri``; signals stay with the benchmark so Ctrl-C reaches its cleanup."""
    os.environ['ROS_MASTER_URI'] = uri
    rospy.init_node('bench', anonymous=True, disable_signals=True)


class StreamMonitor:
    """Receive stamps of a Float32 topic."""

    def __init__(self, topic):
        self._lock = threading.Lock()
        self._stamps = []
        self._first = threading.Event()
        self._sub = rospy.Subscriber(topic, Float32, self._on_message, tcp_nodelay=True,
                                     queue_size=None)

    def _on_message(self, _msg):
        now = rospy.get_time()
        with self._lock:
            self._stamps.append(now)
        self._first.set()

    def wait_first(self, timeout):
        """True once a message arrived; False after ``timeout`` seconds without one."""
        return self._first.wait(timeout)

    def reset(self):
        with self._lock:
            self._stamps = []

    def stamps(self):
        with self._lock:
            return list(self._stamps)

    def close(self):
        self._sub.unregister()


class FakeWarningService:
    """``altitude_warning`` that records ``(stamp, status)`` on entry and can take ``slow`` seconds."""

    def __init__(self, name, slow=0.0):
        self.slow = slow
        self._lock = threading.Lock()
        self._calls = []
        self._srv = rospy.Service(name, AltitudeWarning, self._handle)

    def _handle(self, req):
        now = rospy.get_time()
        with self._lock:
            self._calls.append((now, req.status))
        if self.slow > 0:
            time.sleep(self.slow)
        return AltitudeWarningResponse(success=True, message='bench: recorded %s' % req.status)

    def calls(self):
        with self._lock:
            return list(self._calls)

    def close(self):
        self._srv.shutdown('stage over')


class Player:
    """Publishes temperature and pressure in ``ns`` along a script of altitude steps.

    Between steps both sensors repeat their last value at their own period, as a drone does, so the
    node's inputs never go stale. A step is published the moment it is due, stamped right before the
    publish: that stamp is the "reading" the latencies are measured from.
    """

    def __init__(self, ns, steps):
        self.steps = steps
        self.step_stamps = []
        self._temperature = rospy.Publisher(ns + '/temperature', Float32, queue_size=10,
                                            tcp_nodelay=True)
        self._pressure = rospy.Publisher(ns + '/pressure', Float32, queue_size=10, tcp_nodelay=True)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def start(self):
        self._thread.start()

    def connected(self):
        """True once the node under test subscribes to both inputs."""
        return (self._temperature.get_num_connections() > 0
                and self._pressure.get_num_connections() > 0)

    def stop(self):
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join()
        self._temperature.unregister()
        self._pressure.unregister()

    def _run(self):
        t0 = rospy.get_time()
        next_temperature = next_pressure = t0
        index = 0
        altitude = self.steps[0][1]
        while not self._stop.is_set():
            now = rospy.get_time()
            if index < len(self.steps) and now >= t0 + self.steps[index][0]:
                altitude = self.steps[index][1]
                stamp = rospy.get_time()
                self._pressure.publish(Float32(pressure_at(altitude, TEMPERATURE_C)))
                self.step_stamps.append(stamp)
                next_pressure = stamp + PRESSURE_PERIOD
                index += 1
                continue
            if now >= next_temperature:
                self._temperature.publish(Float32(TEMPERATURE_C))
                next_temperature += TEMPERATURE_PERIOD
            if now >= next_pressure:
                self._pressure.publish(Float32(pressure_at(altitude, TEMPERATURE_C)))
                next_pressure += PRESSURE_PERIOD
            due = min(next_temperature, next_pressure)
            if index < len(self.steps):
                due = min(due, t0 + self.steps[index][0])
            # No busy-wait to be punctual: a spinning thread holds the GIL for up to the 5 ms switch
            # interval and would delay the monitor's receive stamps, faking jitter. A late wake-up
            # costs nothing, since every reading is stamped when it is actually published.
            wait = due - rospy.get_time()
            if wait > 0:
                self._stop.wait(wait)
