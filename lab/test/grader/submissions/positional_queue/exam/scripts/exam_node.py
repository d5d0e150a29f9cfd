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

# Global variables: the last values received on each topic
# (the two topics do not publish at the same rate, so we store them)
temperature = None   # in degrees Celsius
pressure = None      # in Pa


def callback_temperature(msg):
    """Called each time a temperature is received."""
    global temperature
    temperature = msg.data   # store the value


def callback_pressure(msg):
    """Called each time a pressure is received."""
    global pressure
    pressure = msg.data      # store the value


def compute_altitude(t_celsius, p):
    """Equation (1) solved for h: h = R*T/(mu*g) * ln(P0/P), with T in Kelvin."""
    t_kelvin = t_celsius + 273.15             # degrees Celsius to Kelvin
    return R * t_kelvin / (MU * G) * math.log(P0 / p)


def main():
    # Initialisation of the node
    rospy.init_node('exam_node')
    # The threshold comes from the launch file (initialised to 1300 if absent)
    threshold = rospy.get_param('threshold', 1300.0)
    # Two subscribers, one for each topic
    rospy.Subscriber('/temperature', Float32, callback_temperature)
    rospy.Subscriber('/pressure', Float32, callback_pressure)
    # The publisher of the altitude
    pub = rospy.Publisher('/altitude', Float32, 10)
    # The service to change the color of the led
    rospy.wait_for_service('/altitude_warning')
    set_led = rospy.ServiceProxy('/altitude_warning', AltitudeWarning)

    rate = rospy.Rate(10)   # 10 Hz loop
    counter = 0             # number of loops spent above the threshold
    warning = False         # True when the led is red
    while not rospy.is_shutdown():
        # we need both values before computing anything
        if temperature is not None and pressure is not None:
            altitude = compute_altitude(temperature, pressure)
            pub.publish(altitude)          # publish the altitude
            if altitude > threshold:
                counter = counter + 1      # one more loop above
            else:
                counter = 0                # reset as soon as we are below
            # 5 s at 10 Hz = 50 loops above the threshold
            if counter >= 50 and not warning:
                set_led('WARNING')         # call the service only at the frontier
                warning = True
            elif counter == 0 and warning:
                set_led('NORMAL')          # back to green at once
                warning = False
        rate.sleep()                       # wait for the next loop


if __name__ == '__main__':
    try:
        main()
    except rospy.ROSInterruptException:
        pass
