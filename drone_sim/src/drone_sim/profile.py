"""Piecewise-linear, looping waypoint profiles (altitude or depth against time).

A profile is a list of ``[time_s, value]`` waypoints. Between two waypoints the value is interpolated
linearly; after the last waypoint the profile starts again at the first, so a simulator can run for
hours on a two-minute script. The loop must close (last value equal to the first) so the looped
trajectory never teleports the drone.

No rospy here: the simulators, the unit tests and the docs' plots all use this module.
"""

import bisect
import math
import numbers


class Profile:
    """A validated, looping, piecewise-linear profile.

    :param waypoints: sequence of ``(time_s, value)`` pairs; see :func:`validate_waypoints`.
    :param name: label used in logs (a built-in name, or ``"custom"``).
    :param lower: smallest allowed value, or None.
    :param upper: largest allowed value, or None.
    :raises ValueError: invalid waypoints.
    """

    def __init__(self, waypoints, name='custom', lower=None, upper=None):
        self.waypoints = validate_waypoints(waypoints, lower, upper)
        self.name = name
        self._times = [t for t, _ in self.waypoints]
        self._values = [v for _, v in self.waypoints]

    @property
    def period(self):
        """Duration of one loop in seconds (the last waypoint's time)."""
        return self._times[-1]

    def value_at(self, t):
        """Value at time ``t`` seconds since the start; any real ``t`` maps into the loop."""
        t = t % self.period
        # bisect_right finds the segment [i-1, i] holding t. Clamped at both ends: t == 0 belongs to the
        # first segment, and a tiny negative t rounds to t == period under the modulo.
        i = min(len(self._times) - 1, max(1, bisect.bisect_right(self._times, t)))
        t0, t1 = self._times[i - 1], self._times[i]
        v0, v1 = self._values[i - 1], self._values[i]
        return v0 + (v1 - v0) * (t - t0) / (t1 - t0)

    def __repr__(self):
        return 'Profile(%r, name=%r)' % (self.waypoints, self.name)


def _is_number(x):
    # bool is an int subclass, but ``[0, true]`` in YAML is a typo, not an altitude.
    return isinstance(x, numbers.Real) and not isinstance(x, bool) and math.isfinite(x)


def validate_waypoints(waypoints, lower=None, upper=None):
    """Check a waypoint list and return it as a list of ``(float, float)`` tuples.

    :param waypoints: sequence of ``[time_s, value]`` pairs.
    :param lower: smallest allowed value (inclusive), or None for no bound.
    :param upper: largest allowed value (inclusive), or None for no bound.
    :raises ValueError: with a message naming the offending waypoint and the rule it breaks.
    """
    if isinstance(waypoints, (str, bytes)) or not hasattr(waypoints, '__len__'):
        raise ValueError('a profile must be a list of [time_s, value] waypoints, got %r' % (waypoints,))
    if len(waypoints) < 2:
        raise ValueError('a profile needs at least 2 waypoints, got %d' % len(waypoints))
    points = []
    for i, point in enumerate(waypoints):
        if isinstance(point, (str, bytes)) or not hasattr(point, '__len__') or len(point) != 2:
            raise ValueError('waypoint %d must be a pair [time_s, value], got %r' % (i, point))
        t, v = point
        if not (_is_number(t) and _is_number(v)):
            raise ValueError('waypoint %d must hold two finite numbers, got %r' % (i, point))
        if lower is not None and v < lower or upper is not None and v > upper:
            raise ValueError('waypoint %d value %r is outside [%s, %s]' % (i, v, lower, upper))
        points.append((float(t), float(v)))
    if points[0][0] != 0.0:
        raise ValueError('the first waypoint must be at time 0, got %r' % points[0][0])
    for i in range(1, len(points)):
        if points[i][0] <= points[i - 1][0]:
            raise ValueError('waypoint times must increase strictly: waypoint %d at %r s follows %r s'
                             % (i, points[i][0], points[i - 1][0]))
    if points[-1][1] != points[0][1]:
        raise ValueError('the profile loops, so the last value %r must equal the first %r'
                         % (points[-1][1], points[0][1]))
    return points


def parse_profile(spec, builtins, lower=None, upper=None):
    """Build a Profile from a ``~profile`` parameter value.

    :param spec: a built-in name (key of ``builtins``) or a list of ``[time_s, value]`` waypoints.
    :param builtins: dict name -> waypoint list.
    :param lower: smallest allowed value, or None.
    :param upper: largest allowed value, or None.
    :raises ValueError: unknown name or invalid waypoints, with the accepted names in the message.
    """
    if isinstance(spec, str):
        if spec not in builtins:
            raise ValueError('unknown profile %r: use one of %s, or a list of [time_s, value] waypoints'
                             % (spec, ', '.join(sorted(builtins))))
        return Profile(builtins[spec], spec, lower, upper)
    return Profile(spec, 'custom', lower, upper)

