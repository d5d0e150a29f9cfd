"""Waiting with deadlines: the one polling helper of the lab. No rospy here.

Tests wait for a condition with a deadline, never with a fixed sleep. A condition is *met* when the
predicate returns anything but ``None`` or ``False``: a value of 0 (an altitude of 0 m, a count of
zero) is a result, not a failure to wait for.
"""
import time


def met(value):
    """True when a predicate's result counts as the condition being met."""
    return value is not None and value is not False


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
