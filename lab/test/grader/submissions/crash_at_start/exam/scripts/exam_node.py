#!/usr/bin/env python3
# exam node (question 10 to 14)
import math
import rospy
from std_msgs.msg import Float32
from mydrone.srv import AltitudeWarning

# constants of equation (1)
P0, MU, G, R = 101325.0, 0.0289644, 9.80665, 8.31432

temperature = 0.0   # last temperature (degC)
pressure = 0.0      # last pressure (Pa)


def on_temperature(msg):
    global temperature
    temperature = msg.data


def on_pressure(msg):
    global pressure
    pressure = msg.data


rospy.init_node('exam')
threshold = rospy.get_param('~threshold')   # private parameter of the node
rospy.Subscriber('/temperature', Float32, on_temperature)
rospy.Subscriber('/pressure', Float32, on_pressure)
pub = rospy.Publisher('/altitude', Float32, queue_size=10)
led = rospy.ServiceProxy('/altitude_warning', AltitudeWarning)
rate = rospy.Rate(10)
count = 0
warning = False
while not rospy.is_shutdown():
    if pressure > 0:
        altitude = R * (temperature + 273.15) / (MU * G) * math.log(P0 / pressure)
        pub.publish(altitude)
        if altitude > threshold:
            count += 1
        else:
            count = 0
        if count == 50:
            led('WARNING')
            warning = True
        if count == 0 and warning:
            led('NORMAL')
            warning = False
    rate.sleep()
