#!/usr/bin/env python3
# Exam node: altitude of mydrone at 10 Hz; the delay counts pressure messages.
# rostopic hz /pressure gives 2 Hz, so 5 s above the threshold are 10 pressure messages above it.
import math
import rospy
from std_msgs.msg import Float32
from mydrone.srv import AltitudeWarning

R, MU, G, P0 = 8.31432, 0.0289644, 9.80665, 101325.0

temperature = None
altitude = None
count = 0            # pressure messages in a row above the threshold
warning = False


def on_temperature(msg):
    global temperature
    temperature = msg.data


def on_pressure(msg):
    global altitude, count, warning
    if temperature is None:
        return
    altitude = R * (temperature + 273.15) / (MU * G) * math.log(P0 / msg.data)
    if altitude > threshold:
        count += 1
        if count >= 10 and not warning:      # 10 messages at 2 Hz = 5 s
            led('WARNING')
            warning = True
    else:
        count = 0
        if warning:
            led('NORMAL')
            warning = False


rospy.init_node('exam_node')
threshold = rospy.get_param('threshold', 1300.0)
pub = rospy.Publisher('/altitude', Float32, queue_size=10)
rospy.wait_for_service('/altitude_warning')
led = rospy.ServiceProxy('/altitude_warning', AltitudeWarning)
rospy.Subscriber('/temperature', Float32, on_temperature)
rospy.Subscriber('/pressure', Float32, on_pressure)
rate = rospy.Rate(10)
while not rospy.is_shutdown():
    if altitude is not None:
        pub.publish(altitude)
    rate.sleep()
