"""The latest reading of one sensor topic (exam question 11: the inputs arrive at different rates).

Pure logic, no rospy and no clock: callers pass ``now`` (seconds of ROS time).

The drones publish their sensors at different rates, all slower than the 10 Hz output, so the node
cannot wait for "one message of each" before computing: it keeps the latest valid value of each input
and computes from those. A cached value is only trusted while it is younger than a timeout: after that
the sensor is considered silent, and nothing is computed from it.
"""
import collections


class InputCache(object):
    """Latest valid value of one input, its age, and its recent arrival rate.

    :param topic: the topic name, used in messages.
    :param why_unusable: function value -> why the value is unusable (a string), None when usable.
    :param rate_window: how far back [s] arrivals count for the measured rate.
    """

    def __init__(self, topic, why_unusable, rate_window=10.0):
        self.topic = topic
        self._why_unusable = why_unusable
        self._rate_window = rate_window
        self._arrivals = collections.deque()
        #: Latest usable value, None before the first one.
        self.value = None
        #: When the latest usable value arrived, None before the first one.
        self.stamp = None
        #: How many unusable readings were rejected since start.
        self.rejected = 0

    def offer(self, value, now):
        """Cache ``value`` if usable. Return None when it was cached, else the reason it was not."""
        reason = self._why_unusable(value)
        if reason is not None:
            self.rejected += 1
            return reason
        self.value = value
        self.stamp = now
        self._arrivals.append(now)
        self._forget_before(now - self._rate_window)
        return None

    def age(self, now):
        """Seconds since the latest usable value, None if there never was one."""
        return None if self.stamp is None else now - self.stamp

    def is_fresh(self, now, timeout):
        """True when a usable value arrived within the last ``timeout`` seconds."""
        age = self.age(now)
        return age is not None and age <= timeout

    def rate(self, now):
        """Measured arrival rate [Hz] over the rate window (0 when fewer than two arrivals)."""
        self._forget_before(now - self._rate_window)
        if len(self._arrivals) < 2:
            return 0.0
        span = self._arrivals[-1] - self._arrivals[0]
        return (len(self._arrivals) - 1) / span if span > 0 else 0.0

    def _forget_before(self, limit):
        while self._arrivals and self._arrivals[0] < limit:
            self._arrivals.popleft()
