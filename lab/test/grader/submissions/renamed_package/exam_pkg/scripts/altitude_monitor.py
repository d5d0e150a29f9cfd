#!/usr/bin/env python3
"""Altitude monitor: a class, timestamps instead of a tick counter."""
import math

import rospy
from mydrone.srv import AltitudeWarning
from std_msgs.msg import Float32


class Monitor(object):
    """Keeps the latest inputs; a 10 Hz timer publishes the altitude and drives the LED."""

    def __init__(self):
        self.limit = float(rospy.get_param('~alt_threshold'))
        self.temp_c = None
        self.press_pa = None
        self.above_since = None   # ROS time the altitude first went above the limit
        self.led = 'NORMAL'
        self.pub = rospy.Publisher('altitude', Float32, queue_size=1)
        rospy.wait_for_service('altitude_warning')
        self.set_led = rospy.ServiceProxy('altitude_warning', AltitudeWarning)
        rospy.Subscriber('temperature', Float32, self.on_temp)
        rospy.Subscriber('pressure', Float32, self.on_press)
        rospy.Timer(rospy.Duration(0.1), self.tick)

    def on_temp(self, msg):
        self.temp_c = msg.data

    def on_press(self, msg):
        self.press_pa = msg.data

    def tick(self, _):
        if self.temp_c is None or self.press_pa is None:
            return
        h = 8.31432 * (self.temp_c + 273.15) / (0.0289644 * 9.80665) * math.log(101325.0 / self.press_pa)
        self.pub.publish(h)
        now = rospy.get_time()
        if h > self.limit:
            if self.above_since is None:
                self.above_since = now
            if now - self.above_since >= 5.0 and self.led != 'WARNING':
                self.led = 'WARNING'
                self.set_led(self.led)
        else:
            self.above_since = None
            if self.led != 'NORMAL':
                self.led = 'NORMAL'
                self.set_led(self.led)


if __name__ == '__main__':
    rospy.init_node('altitude_monitor')
    Monitor()
    rospy.spin()
