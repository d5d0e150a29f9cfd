"""Checks of the simulators' parameter values. No rospy here: the wiring module reads each value and
its resolved name from the parameter server and passes both in, so every rule is unit-tested.

Each check returns the value cast to its type, or raises ParamError naming the resolved parameter,
the value given and the rule it breaks, which the node logs as fatal before exiting.
"""

import math
import numbers


class ParamError(ValueError):
    """A parameter value the node refuses to start with."""

    def __init__(self, name, value, rule):
        super().__init__('parameter %s = %r: %s' % (name, value, rule))


def _finite_float(name, value, rule):
    # bool is an int subclass; ``true`` for a rate is a mistake, never 1 Hz.
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value):
        raise ParamError(name, value, rule)
    return float(value)


def positive_float(name, value, unit):
    """A finite number > 0, e.g. a rate in Hz."""
    rule = 'must be a finite number > 0 (%s)' % unit
    result = _finite_float(name, value, rule)
    if result <= 0.0:
        raise ParamError(name, value, rule)
    return result


def non_negative_float(name, value, unit):
    """A finite number >= 0, e.g. a noise standard deviation."""
    rule = 'must be a finite number >= 0 (%s)' % unit
    result = _finite_float(name, value, rule)
    if result < 0.0:
        raise ParamError(name, value, rule)
    return result


def seed(name, value):
    """An integer seed for the noise generators."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ParamError(name, value, 'must be an integer')
    return int(value)
