"""Waiting with deadlines: the one polling helper of the lab. No rospy here.

Tests wait for a condition with a deadline, never with a fixed sleep. A condition is *met* when the
predicate returns a true value or any number: ``None``, ``False`` and an empty list (no sample, no
call yet) mean "not yet", while 0 or 0.0 (an altitude of 0 m, a first stamp at time 0 under sim time)
is a result, not a failure to wait for.
"""
import numbers
import time


def met(value):
    """True when a predicate's result counts as the condition being met (see the module docstring)."""
    if isinstance(value, bool):
        return value
    return isinstance(value, numbers.Number) or bool(value)


def wait_until(predicate, timeout, period=0.02, alive=None):
    """Poll ``predicate`` until it is met or ``timeout`` s of wall time pass.

    :param alive: optional function; polling also ends as soon as it returns False (e.g.
        ``lambda: not rospy.is_shutdown()``), so a test cannot hang on a node that is gone.
    :returns: the predicate's value once met, else ``None``.
    Wall time, so a wait cannot hang when ROS time stops.
    """
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if met(value):
            return value
        if time.monotonic() >= deadline or (alive is not None and not alive()):
            return None
        time.sleep(period)


def stays(predicate, duration, period=0.05):
    """True when ``predicate`` is met on every poll for ``duration`` s: "nothing happens" can only be
    shown by watching for a while, so this is the one deliberate observation window."""
    deadline = time.monotonic() + duration
    while time.monotonic() < deadline:
        if not met(predicate()):
            return False
        time.sleep(period)
    return met(predicate())
