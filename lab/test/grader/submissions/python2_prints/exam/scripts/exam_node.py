#!/usr/bin/env python3
# Altitude node, written from a Python 2 tutorial.
import math
import rospy
from std_msgs.msg import Float32
from mydrone.srv import AltitudeWarning

values = {'t': None, 'p': None}


def store(key):
    def callback(msg):
        values[key] = msg.data
    return callback


rospy.init_node('exam')
threshold = rospy.get_param('~threshold')
print "threshold is", threshold
rospy.Subscriber('/temperature', Float32, store('t'))
rospy.Subscriber('/pressure', Float32, store('p'))
pub = rospy.Publisher('/altitude', Float32, queue_size=10)
led = rospy.ServiceProxy('/altitude_warning', AltitudeWarning)
rate = rospy.Rate(10)
ticks = 0
while not rospy.is_shutdown():
    if values['t'] is not None and values['p'] is not None:
        h = 8.31432 * (values['t'] + 273.15) / (0.0289644 * 9.80665) * math.log(101325.0 / values['p'])
        pub.publish(h)
        ticks = ticks + 1 if h > threshold else 0
        if ticks == 50:
            print "WARNING at", h
            led('WARNING')
        elif ticks == 0:
            led('NORMAL')
    rate.sleep()
