#!/usr/bin/env python3
"""Exam node. The delay of the warning is a sleep in the pressure callback: wait 5 s, then check."""
import math
import time

import rospy
from std_msgs.msg import Float32
from mydrone.srv import AltitudeWarning

temp = 15.0          # last temperature (degC)
alt = None           # last altitude computed (m)
warned = False


def on_temperature(msg):
    global temp
    temp = msg.data


def on_pressure(msg):
    global alt, warned
    alt = 8.31432 * (temp + 273.15) / (0.0289644 * 9.80665) * math.log(101325.0 / msg.data)
    if alt > threshold and not warned:
        time.sleep(5)                 # 5 s above the threshold?
        if alt > threshold:           # still above: warn
            warning('WARNING')
            warned = True
    elif alt <= threshold and warned:
        warning('NORMAL')
        warned = False


rospy.init_node('exam')
threshold = rospy.get_param('~threshold')
pub = rospy.Publisher('/altitude', Float32, queue_size=10)
rospy.wait_for_service('/altitude_warning')
warning = rospy.ServiceProxy('/altitude_warning', AltitudeWarning)
rospy.Subscriber('/temperature', Float32, on_temperature)
rospy.Subscriber('/pressure', Float32, on_pressure)
rate = rospy.Rate(10)
while not rospy.is_shutdown():
    if alt is not None:
        pub.publish(alt)      # the last altitude, 10 times a second
    rate.sleep()
