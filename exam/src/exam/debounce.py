"""The warning state machine (exam question 14b): WARNING only after a sustained excess, NORMAL at once.

Pure logic, no rospy and no clock: every method takes ``now`` (seconds, any monotonic origin; the node
passes ROS time) so the unit tests drive it with synthetic timestamps.

The rule, for a value compared with a threshold::

              reading > threshold            reading <= threshold
    (start) --------------------> pending  ----------------------> NORMAL
       |                             |  delay elapsed since the first
       | reading <= threshold        |  reading above, no reading <= in between
       v                             v
     NORMAL <--- reading <= ----- WARNING

- The excess is timed from the *first* reading above the threshold, so the 5 s are a duration, not a
  count of loop iterations: the grader's "500 iterations at 10 ms" in the seed is wrong twice (a 10 Hz
  loop has a 100 ms period, and a count drifts with the loop's real rate).
- Any reading at or below the threshold cancels the pending excess and turns the state back to NORMAL
  immediately; the LED must turn green as soon as the drone is back within limits.
- The delay expires at a known instant (:attr:`deadline`): the node arms a timer for it instead of
  waiting for the next reading or publishing tick, which is what keeps the WARNING latency low.
- An excess counts only if it was observed continuously: when an input goes stale the node calls
  :meth:`interrupt`, which cancels the pending excess (the state itself is kept).
- The state is unknown until the first reading: the node does not claim NORMAL before it has seen a
  value (a restarted node must not turn a red LED green while the drone is still too high).
- Each transition is reported exactly once; a method returns the new state, or None when nothing
  changed, so the caller can never send the same state twice in a row.
"""

NORMAL = 'NORMAL'
WARNING = 'WARNING'


class Debouncer(object):
    """Turns a stream of timestamped values into NORMAL/WARNING transitions.

    :param threshold: the limit; only values strictly above it are an excess.
    :param delay: how long [s] the excess must last without interruption before WARNING (>= 0).
    """

    def __init__(self, threshold, delay):
        self.threshold = threshold
        self.delay = delay
        #: NORMAL, WARNING, or None before the first reading.
        self.state = None
        #: Time of the first reading of the current uninterrupted excess, None when there is none.
        self.excess_since = None

    @property
    def deadline(self):
        """When the current excess turns into WARNING, or None when no WARNING is pending."""
        if self.excess_since is None or self.state == WARNING:
            return None
        return self.excess_since + self.delay

    def update(self, value, now):
        """Feed one reading taken at ``now``; return the new state if this reading changed it."""
        if value > self.threshold:
            if self.excess_since is None:
                self.excess_since = now
            # With delay 0 (or a reading arriving after the deadline) the excess is already long enough.
            return self.poll(now)
        self.excess_since = None
        return self._enter(NORMAL)

    def poll(self, now):
        """Check the pending excess against the clock; return WARNING if its delay has just expired."""
        deadline = self.deadline
        if deadline is not None and now >= deadline:
            return self._enter(WARNING)
        return None

    def interrupt(self):
        """Forget the pending excess: the input went silent, so the excess was not seen continuously.

        The state itself is kept: a gap in the data says nothing about where the drone is.
        """
        self.excess_since = None

    def _enter(self, state):
        if state == self.state:
            return None
        self.state = state
        return state


def excess_news(before, after, change):
    """What one step of the debouncer did to the pending WARNING, for the node's log (once per excess).

    :param before: :attr:`Debouncer.deadline` before the step; ``after``: after it.
    :param change: the new state the step returned, or None.
    :returns: ``'pending'`` when a WARNING became due at ``after`` (an excess began), ``'cancelled'``
        when the pending one ended without a WARNING (a reading back within the limit, or stale
        inputs), else None (nothing new; a WARNING that fires is logged as a change of state).
    """
    if after is not None and after != before:
        return 'pending'
    if before is not None and after is None and change != WARNING:
        return 'cancelled'
    return None
