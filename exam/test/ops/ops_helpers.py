"""Waiting and process helpers shared by the operations rostest checkers (imported, not a node).

Tests wait on conditions with deadlines, never with fixed sleeps; `stays` is the one deliberate
observation window, for properties such as "no call in steady state" that only time can show.
"""
import json
import os
import signal
import threading
import time

import rosgraph
import rospy
from std_msgs.msg import String

try:
    from xmlrpc.client import ServerProxy
except ImportError:  # Python 2
    from xmlrpclib import ServerProxy


def wait_for(predicate, timeout, period=0.05):
    """Poll predicate until it returns something not None/False or timeout [s] passes; return it."""
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value is not None and value is not False:
            return value
        if time.monotonic() >= deadline or rospy.is_shutdown():
            return None
        time.sleep(period)


def stays(predicate, duration, period=0.05):
    """True when predicate holds on every poll for duration [s]."""
    deadline = time.monotonic() + duration
    while time.monotonic() < deadline:
        if not predicate():
            return False
        time.sleep(period)
    return bool(predicate())


class Latest(object):
    """Keeps the latest message of a topic and its arrival time (wall clock, s), under a lock."""

    def __init__(self, topic, msg_type):
        self._lock = threading.Lock()
        self._msg = None
        self._stamp = None
        self._count = 0
        self.sub = rospy.Subscriber(topic, msg_type, self._on_msg)

    def _on_msg(self, msg):
        with self._lock:
            self._msg = msg
            self._stamp = time.time()
            self._count += 1

    def get(self):
        """(message, arrival time, messages so far); message None until one arrived."""
        with self._lock:
            return self._msg, self._stamp, self._count


class DroneRecord(Latest):
    """The latched JSON record of fake_drone.py (pid, started, led, calls)."""

    def __init__(self, topic='fake_drone/record'):
        super(DroneRecord, self).__init__(topic, String)

    def record(self):
        msg = self.get()[0]
        return None if msg is None else json.loads(msg.data)


def node_pid(name):
    """Pid of a running node (via its XML-RPC getPid), or None when it is not reachable."""
    try:
        uri = rosgraph.Master(rospy.get_name()).lookupNode(name)
        code, _msg, pid = ServerProxy(uri).getPid(rospy.get_name())
        return pid if code == 1 else None
    except (IOError, OSError, rosgraph.MasterException):
        return None


def kill_node(name):
    """SIGKILL a node (a crash, not a clean shutdown) and return the pid it had."""
    pid = node_pid(name)
    if pid is None:
        raise AssertionError('node %s is not running' % name)
    os.kill(pid, signal.SIGKILL)
    return pid


def process_start_time(pid):
    """Wall-clock start time (s since the epoch) of a local process, from /proc (10 ms resolution)."""
    with open('/proc/%d/stat' % pid) as stat:
        # Field 22 is the start time in clock ticks after boot; count fields after the ')' of the name.
        start_ticks = int(stat.read().rsplit(')', 1)[1].split()[19])
    age = time.clock_gettime(time.CLOCK_BOOTTIME) - start_ticks / float(os.sysconf('SC_CLK_TCK'))
    return time.time() - age
