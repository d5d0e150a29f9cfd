#!/usr/bin/env python3
"""exam_node: altitude of mydrone on /altitude (10 Hz), ALT WARN led through /altitude_warning.

A rospy.Timer does the work at 10 Hz; the sensor callbacks only keep the last readings.
"""
import math

import rospy
from std_msgs.msg import Float32
from mydrone.srv import AltitudeWarning

readings = {}  # topic name -> last value received


def altitude(temperature, pressure):
    """Equation (1) solved for h (temperature in degC, converted to K)."""
    return 8.31432 * (temperature + 273.15) / (0.0289644 * 9.80665) * math.log(101325.0 / pressure)


class Led(object):
    """Remembers the colour asked for, so the service is only called when it changes."""

    def __init__(self, threshold):
        self.threshold = threshold
        self.proxy = rospy.ServiceProxy('/altitude_warning', AltitudeWarning)
        self.status = 'NORMAL'
        self.above_since = None   # time of the first reading above the threshold

    def update(self, h, now):
        if h <= self.threshold:
            self.above_since = None
            wanted = 'NORMAL'
        else:
            self.above_since = self.above_since or now
            wanted = 'WARNING' if now - self.above_since >= 5.0 else self.status
        if wanted != self.status:
            self.proxy(wanted)
            self.status = wanted


def main():
    rospy.init_node('exam_node')
    led = Led(float(rospy.get_param('~threshold', 1300)))  # threshold from the launch file
    rospy.wait_for_service('/altitude_warning')
    publisher = rospy.Publisher('/altitude', Float32, queue_size=1)

    def tick(event):
        if 'temperature' in readings and 'pressure' in readings:
            h = altitude(readings['temperature'], readings['pressure'])
            publisher.publish(h)
            led.update(h, event.current_real.to_sec())

    for name in ('temperature', 'pressure'):
        rospy.Subscriber('/' + name, Float32, lambda msg, name=name: readings.__setitem__(name, msg.data))
    rospy.Timer(rospy.Duration(0.1), tick)
    rospy.spin()


if __name__ == '__main__':
    main()
