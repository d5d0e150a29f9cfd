#!/usr/bin/env python3
"""A scripted aerial drone for the operations rostests: steady sensors and a recording LED service.

It hovers at one altitude, so the exam node's wanted state never changes, and it keeps an exact record
of the warning calls it received. A test kills and respawns this process to play a drone that reboots:
the new process starts GREEN and with an empty record, as a real drone would. A checker may also run a
FakeDrone in its own process and script it (set_altitude, silence, refuse).

ROS Parameters:
    ~altitude (float, m, default 1500.0): altitude the sensor readings correspond to.
    ~temperature (float, degC, default 5.0): temperature reading.
    ~rate (float, Hz, default 5.0): publishing rate of both sensors.

Published Topics:
    temperature (std_msgs/Float32, degC)
    pressure (std_msgs/Float32, Pa): barometric law of the exam sheet at ~altitude and ~temperature.
    alt_warn_led (std_msgs/String, latched): "GREEN" at start, "RED" after WARNING, as mydrone.
    ~record (std_msgs/String, latched): JSON {"pid", "started" (ROS time, s, when GREEN was published),
        "led", "calls": [[ROS time (s), status], ...]} (refused calls included), republished after
        every call, so a subscriber that connects late still sees every call of this process.

Services:
    altitude_warning (mydrone/AltitudeWarning): "NORMAL" -> GREEN, "WARNING" -> RED, else refused;
        everything refused while refuse() is on.
"""
import json
import math
import os
import threading

import rospy
from mydrone.srv import AltitudeWarning, AltitudeWarningResponse
from std_msgs.msg import Float32, String

# Constants of the exam sheet's barometric law, written out here rather than imported from the exam
# package, so a mistake in the node's formula is not mirrored by its test input.
P0_PA = 101325.0
MU_G_OVER_R = 0.0289644 * 9.80665 / 8.31432


def pressure_at(altitude_m, temperature_c):
    """Pressure [Pa] the exam sheet's isothermal law gives at altitude_m [m] and temperature_c [degC]."""
    return P0_PA * math.exp(-MU_G_OVER_R * altitude_m / (temperature_c + 273.15))


class FakeDrone(object):
    """Publishes the readings and records the service calls; see the module docstring."""

    COLOURS = {'NORMAL': 'GREEN', 'WARNING': 'RED'}

    def __init__(self):
        altitude = float(rospy.get_param('~altitude', 1500.0))
        self._temperature = float(rospy.get_param('~temperature', 5.0))
        rate = float(rospy.get_param('~rate', 5.0))
        self._lock = threading.Lock()
        self._pressure = pressure_at(altitude, self._temperature)
        self._silent = set()
        self._refusing = False
        self._record = {'pid': os.getpid(), 'started': None, 'led': 'GREEN', 'calls': []}

        self._temperature_pub = rospy.Publisher('temperature', Float32, queue_size=1)
        self._pressure_pub = rospy.Publisher('pressure', Float32, queue_size=1)
        self._led_pub = rospy.Publisher('alt_warn_led', String, queue_size=1, latch=True)
        self._record_pub = rospy.Publisher('~record', String, queue_size=1, latch=True)
        self._service = rospy.Service('altitude_warning', AltitudeWarning, self._on_warning)
        with self._lock:
            self._record['started'] = rospy.get_time()
            self._led_pub.publish(String(data='GREEN'))
            self._publish_record()
        self._timer = rospy.Timer(rospy.Duration(1.0 / rate), self._on_timer, reset=True)
        rospy.loginfo('fake_drone: pid %d at %.1f m, %.2f degC, %.0f Pa, %.1f Hz',
                      os.getpid(), altitude, self._temperature, self._pressure, rate)

    def set_altitude(self, altitude_m):
        """Fly to altitude_m [m] at once (the next readings correspond to it)."""
        with self._lock:
            self._pressure = pressure_at(altitude_m, self._temperature)

    def silence(self, topic, silent=True):
        """Stop (or resume) publishing one sensor topic ("temperature" or "pressure")."""
        with self._lock:
            (self._silent.add if silent else self._silent.discard)(topic)

    def refuse(self, refusing=True):
        """Make the warning service answer success=false (a broken LED driver), or work again."""
        with self._lock:
            self._refusing = refusing

    def record(self):
        """A copy of what ~record publishes (for a checker running this drone in-process)."""
        with self._lock:
            return json.loads(json.dumps(self._record))

    def _on_timer(self, _event):
        with self._lock:
            readings = {'temperature': self._temperature, 'pressure': self._pressure}
            silent = set(self._silent)
        for topic, pub in (('temperature', self._temperature_pub), ('pressure', self._pressure_pub)):
            if topic not in silent:
                pub.publish(Float32(data=readings[topic]))

    def _on_warning(self, request):
        colour = self.COLOURS.get(request.status)
        with self._lock:
            self._record['calls'].append([rospy.get_time(), request.status])
            if self._refusing:
                self._publish_record()
                return AltitudeWarningResponse(success=False, message='LED driver fault (scripted)')
            if colour is not None and colour != self._record['led']:
                self._record['led'] = colour
                self._led_pub.publish(String(data=colour))
            self._publish_record()
        if colour is None:
            return AltitudeWarningResponse(success=False, message='refused %r' % request.status)
        return AltitudeWarningResponse(success=True, message='LED %s' % colour)

    def _publish_record(self):
        """Publish the record; the caller holds the lock, so records go out in call order."""
        self._record_pub.publish(String(data=json.dumps(self._record)))


def main():
    rospy.init_node('fake_drone')
    FakeDrone()
    rospy.spin()


if __name__ == '__main__':
    main()
