#!/usr/bin/env python3
"""Exam node written as a class: altitude from temperature and pressure, ALT WARN led."""
import math

import rospy
from std_msgs.msg import Float32
from mydrone.srv import AltitudeWarning


class AltitudeNode:
    """Keeps the last sensor values, publishes the altitude and drives the led."""

    def __init__(self):
        # private parameter given in the launch file
        self.threshold = float(rospy.get_param('~threshold'))
        self.temperature = None  # degC
        self.pressure = None     # Pa
        self.above_since = None  # time when the altitude went above the threshold
        self.pub = rospy.Publisher('altitude', Float32, queue_size=1)
        rospy.wait_for_service('altitude_warning')
        self.led = rospy.ServiceProxy('altitude_warning', AltitudeWarning)
        rospy.Subscriber('temperature', Float32, self.on_temperature)
        rospy.Subscriber('pressure', Float32, self.on_pressure)

    def on_temperature(self, msg):
        self.temperature = msg.data

    def on_pressure(self, msg):
        self.pressure = msg.data

    def altitude(self):
        # h = R T / (mu g) ln(P0 / P), T in kelvin
        return 8.31432 * (self.temperature + 273.15) / (0.0289644 * 9.80665) * math.log(101325.0 / self.pressure)

    def spin(self):
        rate = rospy.Rate(10)
        while not rospy.is_shutdown():
            if self.temperature is not None and self.pressure is not None:
                h = self.altitude()
                self.pub.publish(h)
                now = rospy.get_time()
                if h > self.threshold:
                    if self.above_since is None:
                        self.above_since = now
                else:
                    self.above_since = None
                # the led follows the state at every cycle
                if self.above_since is not None and now - self.above_since >= 5.0:
                    self.led('WARNING')
                else:
                    self.led('NORMAL')
            rate.sleep()


if __name__ == '__main__':
    rospy.init_node('exam')
    AltitudeNode().spin()
