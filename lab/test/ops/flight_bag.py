#!/usr/bin/env python3
"""Writes a deterministic flight bag with the rosbag Python API, and computes its altitudes offline.

A recorded bag (`rosbag record /temperature /pressure`) would do as well, but a generated one is exact,
takes no wall time, and its crossing instants are known in advance. The flight lasts 36 s: it climbs
from 1000 m to 1500 m in 12 s, holds 1500 m for 16 s and is down to 1100 m at 32 s, so it is above
1300 m from 9.3 s to 30.0 s (about 21 s; the readings, at their own instants, from 9.5 s to 30.0 s).
Temperature and pressure are written at different rates (1 Hz and 2 Hz), offset so that no two
readings share a timestamp.

No /clock in the bag: `rosbag play --clock` publishes the clock from the message times itself.

Usage: flight_bag.py OUT.bag   (then `rosbag play --clock -r 5 OUT.bag` with use_sim_time=true)
"""
import math
import struct
import sys

from exam_lab.harness.oracle import altitude_of, pressure_at as oracle_pressure_at

#: Bag time [s] of the first message; any value works, a realistic epoch keeps logs readable.
START = 1700000000.0
#: (bag time from START [s], altitude [m]) waypoints, linear in between.
WAYPOINTS = ((0.0, 1000.0), (8.0, 1200.0), (12.0, 1500.0), (28.0, 1500.0), (32.0, 1100.0), (36.0, 1100.0))
TEMPERATURE_PERIOD = 1.0
TEMPERATURE_OFFSET = 0.25
PRESSURE_PERIOD = 0.5


def profile(t):
    """Altitude [m] at t seconds after START."""
    for (t0, h0), (t1, h1) in zip(WAYPOINTS, WAYPOINTS[1:]):
        if t0 <= t <= t1:
            return h0 + (h1 - h0) * (t - t0) / (t1 - t0)
    return WAYPOINTS[-1][1]


def temperature_at(t):
    """Air temperature [degC]: a standard lapse rate plus a slow deterministic wiggle."""
    return 15.0 - 0.0065 * profile(t) + 0.3 * math.sin(t / 3.0)


def pressure_at(t):
    """Pressure [Pa] from the exam's isothermal law at the profile's altitude, with a tiny wiggle so
    that no two computed altitudes are equal."""
    return oracle_pressure_at(profile(t), temperature_at(t)) + 0.5 * math.sin(7.0 * t)


def readings():
    """The flight as (bag time from START [s], topic, value), in time order."""
    end = WAYPOINTS[-1][0]
    items = []
    t = TEMPERATURE_OFFSET
    while t <= end:
        items.append((t, 'temperature', temperature_at(t)))
        t += TEMPERATURE_PERIOD
    t = 0.0
    while t <= end:
        items.append((t, 'pressure', pressure_at(t)))
        t += PRESSURE_PERIOD
    return sorted(items)


def float32(value):
    """The value as a std_msgs/Float32 carries it, since the exam node computes from that."""
    return struct.unpack('f', struct.pack('f', value))[0]


def states(items):
    """The altitudes the exam node may publish: [(from bag time [s], altitude [m])], one per reading
    from the moment both inputs are known, each computed from the latest temperature and pressure."""
    latest = {}
    result = []
    for t, topic, value in items:
        latest[topic] = float32(value)
        if len(latest) == 2:
            result.append((t, altitude_of(latest['temperature'], latest['pressure'])))
    return result


def crossings(state_list, threshold):
    """Bag times [s] of the first reading above threshold and of the first one back at or below it."""
    up = next(t for t, h in state_list if h > threshold)
    down = next(t for t, h in state_list if t > up and h <= threshold)
    return up, down


def write(path):
    """Write the flight to the bag at path; returns the readings written."""
    import rosbag
    import rospy
    from std_msgs.msg import Float32
    items = readings()
    with rosbag.Bag(path, 'w') as bag:
        for t, topic, value in items:
            bag.write('/' + topic, Float32(data=value), rospy.Time.from_sec(START + t))
    return items


if __name__ == '__main__':
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    write(sys.argv[1])
