#!/usr/bin/env python3
# exam_node.py -- altitude of mydrone, and the ALT WARN led after 5 s above the limit
import math
import rospy
from std_msgs.msg import Float32
from mydrone.srv import AltitudeWarning

THRESHOLD = 1300.0   # altitude limit of the remote (m)
LOOPS_5S = 50        # 5 s at 10 Hz

last = {'temperature': None, 'pressure': None}   # last readings of the sensors


def store(name):
    # returns a callback that stores the reading under its name
    def callback(msg):
        last[name] = msg.data
    return callback


def main():
    rospy.init_node('exam')
    rospy.Subscriber('/temperature', Float32, store('temperature'))
    rospy.Subscriber('/pressure', Float32, store('pressure'))
    publisher = rospy.Publisher('/altitude', Float32, queue_size=10)
    rospy.wait_for_service('/altitude_warning')
    alt_warn = rospy.ServiceProxy('/altitude_warning', AltitudeWarning)
    loop = rospy.Rate(10)
    above = 0        # loops above the threshold
    red = False      # led state
    while not rospy.is_shutdown():
        if None not in last.values():
            kelvin = last['temperature'] + 273.15
            altitude = 8.31432 * kelvin / (0.0289644 * 9.80665) * math.log(101325.0 / last['pressure'])
            publisher.publish(altitude)
            above = above + 1 if altitude > THRESHOLD else 0
            if above >= LOOPS_5S and not red:
                alt_warn('WARNING')
                red = True
            elif above == 0 and red:
                alt_warn('NORMAL')
                red = False
        loop.sleep()


if __name__ == '__main__':
    main()
