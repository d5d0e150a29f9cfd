"""The exam node's log lines about the warning, worded per drone. No rospy: unit-tested as text.

The sheets differ in their words: the aerial drone (sheet 000) warns *above* an altitude, the
underwater drone (sheet 001) when it is *deeper than* a depth (:attr:`exam.modes.Mode.above`,
:attr:`exam.modes.Mode.within`). Times are ROS times in seconds, as in rospy's log prefix.
"""
from exam.debounce import WARNING


def excess_began(mode, value, threshold, since, deadline):
    """An excess began: once per excess, with the instant its WARNING is due."""
    return '%s %.1f %s %s the threshold %.1f %s since %.3f, WARNING due at %.3f' % (
        mode.output, value, mode.unit, mode.above, threshold, mode.unit, since, deadline)


def excess_cancelled(mode, value, why):
    """The pending WARNING ended before its deadline; ``why``: back within the limit, or stale inputs."""
    return '%s %.1f %s: the pending WARNING is cancelled (%s)' % (mode.output, value, mode.unit, why)


def back_within(mode):
    """The reason of a cancellation by a reading back within the limit."""
    return 'back %s it' % mode.within


def state_changed(mode, state, value, threshold, delay):
    """The warning state changed to ``state`` on ``value``."""
    if state == WARNING:
        why = '%s the threshold %.1f %s for %.1f s' % (mode.above, threshold, mode.unit, delay)
    else:
        why = '%s the threshold %.1f %s' % (mode.within, threshold, mode.unit)
    return '%s %.1f %s %s: %s' % (mode.output, value, mode.unit, why, state)
