#!/usr/bin/env python3
# Question 10, first step (sheet 001): scripts/exam_submarine_node.py as it is before question 11.
# It only displays the values it receives on /pressure_robot and /pressure_remote.

import rospy                       # the ROS client library for Python
from std_msgs.msg import Float32   # the message type of both sensor topics


def pressure_robot_callback(msg):  # rospy calls it for each message on /pressure_robot
    rospy.loginfo('pressure_robot %.2f Pa', msg.data)


def pressure_remote_callback(msg):  # the same for /pressure_remote
    rospy.loginfo('pressure_remote %.2f Pa', msg.data)


if __name__ == '__main__':
    rospy.init_node('exam')   # register with the master as the node /exam
    # One subscriber per topic: topic name, message type, and the function rospy calls for each message.
    rospy.Subscriber('/pressure_robot', Float32, pressure_robot_callback)
    rospy.Subscriber('/pressure_remote', Float32, pressure_remote_callback)
    rospy.spin()              # nothing else to do: wait for messages until Ctrl-C
