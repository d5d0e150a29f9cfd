"""The ROS side of the benchmark: the harness's fake drone, flown along a script of altitude steps.

One rospy node (``/bench``) plays the drone for each node under test with
:class:`exam_lab.harness.fake_drone.Drone` resolved in that node's namespace: it publishes
``temperature`` and ``pressure`` at mydrone's default rates, serves ``altitude_warning`` and records each
call on arrival, and records ``altitude``. Everything uses ``tcp_nodelay``, so Nagle's algorithm does not
bunch messages and fake jitter, and the recorder keeps every message (``queue_size=None``).

Every stamp is ``rospy.get_time()`` (ROS time) taken right before a publish or on entry to a callback, so
latencies compare stamps of one clock. Each stage uses a fresh namespace, so a node of an earlier stage
that is still shutting down cannot feed or call this one.
"""

import os
import threading

import rospy

from exam_lab.harness.fake_drone import Drone, TopicRecorder

# The fake drone flies mydrone's default sensor rates (its SPEC's): the node under test sees the same
# input load as with the simulator; scripted steps are published at once on top of them.


def init(uri):
    """Join the master at ``uri``; signals stay with the benchmark so Ctrl-C reaches its cleanup."""
    os.environ['ROS_MASTER_URI'] = uri
    rospy.init_node('bench', anonymous=True, disable_signals=True)


def drone(ns, slow=0.0):
    """The fake aerial drone of the node in ``ns``, without LED topic; each call takes ``slow`` s."""
    fake = Drone('altitude', led=False, tcp_nodelay=True, namespace=ns,
                 queue_size=None)
    fake.service.configure(delay=slow)
    return fake


def recorder(topic):
    """A recorder of a node's output with the drone's measurement settings (no drone around it)."""
    return TopicRecorder(topic, tcp_nodelay=True, queue_size=None)


def stamps(recording):
    """Receive stamps of every message a :class:`TopicRecorder` recorded so far."""
    return [t for t, _ in recording.samples()]


class Player:
    """Flies a fake drone along a script of ``(t s, altitude m)`` steps, from its own thread.

    Between steps the drone's feeder repeats the last readings at the drone's rates, so the node's
    inputs never go stale. A step is published the moment it is due, stamped right before the publish:
    that stamp is the "reading" the latencies are measured from.
    """

    def __init__(self, drone, steps):
        self.drone = drone
        self.steps = steps
        self.step_stamps = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def start(self):
        self.drone.feeder.set(self.drone.fixed_topic, self.drone.fixed_value)
        self._thread.start()

    def stop(self):
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join()

    def _run(self):
        t0 = rospy.get_time()
        for due, altitude in self.steps:
            # No busy-wait to be punctual: a spinning thread holds the GIL for up to the 5 ms switch
            # interval and would delay the recorder's receive stamps, faking jitter. A late wake-up
            # costs nothing, since every reading is stamped when it is actually published.
            wait = t0 + due - rospy.get_time()
            if wait > 0 and self._stop.wait(wait):
                return
            self.step_stamps.append(self.drone.fly_to(altitude))
