"""Checks of parameter values, shared by the simulators and the exam node. No rospy here: each wiring
module reads a value and its resolved name from the parameter server and passes both in, so every rule
is unit-tested without a master.

Each check returns the value cast to its type, or raises ParamError naming the resolved parameter,
the value given and the rule it breaks; the node logs it as fatal and exits with status 1.

A number must arrive as a number. The parameter server already turns ``_threshold:=1300``,
``<param value="1300"/>`` and ``rosparam set ~threshold 1300`` into numbers, so a string such as
``"1300"`` means the value was quoted somewhere, and ``true`` for a rate is a typo, never 1 Hz.
"""

import math
import numbers


class ParamError(ValueError):
    """A parameter value the node refuses to start with; the message names it and its value."""

    def __init__(self, name, value, rule):
        super().__init__('parameter %s = %r: %s' % (name, value, rule))


def _checked_float(name, value, rule, in_range):
    """``value`` as a float if it is a finite number (bool excluded) and ``in_range(value)``."""
    if (isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value)
            or not in_range(value)):
        raise ParamError(name, value, rule)
    return float(value)


def finite_float(name, value, unit):
    """Any finite number, e.g. a threshold."""
    return _checked_float(name, value, 'must be a finite number (%s)' % unit, lambda x: True)


def positive_float(name, value, unit):
    """A finite number > 0, e.g. a rate in Hz or a timeout."""
    return _checked_float(name, value, 'must be a finite number > 0 (%s)' % unit, lambda x: x > 0)


def non_negative_float(name, value, unit):
    """A finite number >= 0, e.g. a noise standard deviation or a delay."""
    return _checked_float(name, value, 'must be a finite number >= 0 (%s)' % unit, lambda x: x >= 0)


def seed(name, value):
    """An integer seed for the noise generators."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ParamError(name, value, 'must be an integer')
    return int(value)


def one_of(name, value, choices):
    """One of the strings ``choices``, exactly (no other case, no spaces), e.g. a mode."""
    if not isinstance(value, str) or value not in choices:
        raise ParamError(name, value, 'must be one of %s' % ', '.join(sorted(choices)))
    return value
