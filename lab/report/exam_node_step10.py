#!/usr/bin/env python3
# Question 10, first step (sheet 000): scripts/exam_node.py as it is before question 11.
# It only displays the values it receives on /temperature and /pressure.

import rospy                       # the ROS client library for Python
from std_msgs.msg import Float32   # the message type of both sensor topics


def temperature_callback(msg):  # rospy calls it for each message on /temperature
    rospy.loginfo('temperature %.2f degC', msg.data)


def pressure_callback(msg):  # the same for /pressure
    rospy.loginfo('pressure %.2f Pa', msg.data)


if __name__ == '__main__':
    rospy.init_node('exam')   # register with the master as the node /exam
    # One subscriber per topic: topic name, message type, and the function rospy calls for each message.
    rospy.Subscriber('/temperature', Float32, temperature_callback)
    rospy.Subscriber('/pressure', Float32, pressure_callback)
    rospy.spin()              # nothing else to do: wait for messages until Ctrl-C
