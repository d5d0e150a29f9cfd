#!/usr/bin/env python3
# -*- coding: utf-8 -*-
# Exam node: computes the altitude of mydrone from its temperature and pressure,
# publishes it on /altitude at 10 Hz and sets the ALT WARN led with /altitude_warning.

import math                              # for the logarithm
import rospy                             # the ROS python client
from std_msgs.msg import Float32         # message type of the topics
from mydrone.srv import AltitudeWarning  # the service of the drone

# Constants of equation (1)
P0 = 101325.0      # standard pressure at sea level (Pa)
MU = 0.0289644     # mean molecular mass of air (kg/mol)
G = 9.80665        # gravity (m/s^2)
R = 8.31432        # perfect gas constant (J/K.mol)


def compute_altitude(t_celsius, p):
    """Equation (1) solved for h: h = R*T/(mu*g) * ln(P0/P), with T in Kelvin."""
    t_kelvin = t_celsius + 273.15             # degrees Celsius to Kelvin
    return R * t_kelvin / (MU * G) * math.log(P0 / p)


def main():
    # Initialisation of the node
    rospy.init_node('exam_node')
    # The threshold comes from the launch file (initialised to 1300 if absent)
    threshold = rospy.get_param('threshold', 1300.0)
    # The publisher of the altitude
    pub = rospy.Publisher('/altitude', Float32, queue_size=10)
    # The service to change the color of the led
    rospy.wait_for_service('/altitude_warning')
    set_led = rospy.ServiceProxy('/altitude_warning', AltitudeWarning)

    rate = rospy.Rate(10)   # 10 Hz loop
    above_since = None      # time the altitude went above the threshold
    warning = False         # True when the led is red
    while not rospy.is_shutdown():
        # wait for a new reading of each sensor, then compute
        temperature = rospy.wait_for_message('/temperature', Float32).data
        pressure = rospy.wait_for_message('/pressure', Float32).data
        altitude = compute_altitude(temperature, pressure)
        pub.publish(altitude)              # publish the altitude
        now = rospy.get_time()
        if altitude > threshold:
            if above_since is None:
                above_since = now          # it just went above
        else:
            above_since = None             # reset as soon as we are below
        # 5 s above the threshold
        if above_since is not None and now - above_since >= 5.0 and not warning:
            set_led('WARNING')             # call the service only at the frontier
            warning = True
        elif above_since is None and warning:
            set_led('NORMAL')              # back to green at once
            warning = False
        rate.sleep()                       # wait for the next loop


if __name__ == '__main__':
    try:
        main()
    except rospy.ROSInterruptException:
        pass
