#!/usr/bin/env python3
# Exam node for the submarine drone: depth = (P_robot - P_remote) / (rho * g)
import rospy
from std_msgs.msg import Float32
from submarinedrone.srv import DepthWarning

RHO = 1030.0    # density of salt water (kg/m3)
G = 9.80665     # gravity (N/kg)

p_robot = None   # last pressure of the robot (Pa)
p_remote = None  # last pressure of the remote (Pa)


def robot_callback(msg):
    global p_robot
    p_robot = msg.data


def remote_callback(msg):
    global p_remote
    p_remote = msg.data


def main():
    rospy.init_node('exam')
    threshold = rospy.get_param('~threshold')       # depth limit (m)
    rospy.Subscriber('/pressure_robot', Float32, robot_callback)
    rospy.Subscriber('/pressure_remote', Float32, remote_callback)
    pub = rospy.Publisher('/profondeur', Float32, queue_size=10)   # the depth in m
    warn = rospy.ServiceProxy('/depth_warning', DepthWarning)
    rate = rospy.Rate(10)
    ticks_below = 0     # loops spent deeper than the threshold
    warning = False
    while not rospy.is_shutdown():
        if p_robot is not None and p_remote is not None:
            depth = (p_robot - p_remote) / (RHO * G)
            pub.publish(depth)
            ticks_below = ticks_below + 1 if depth > threshold else 0
            if ticks_below >= 50 and not warning:    # 5 seconds
                warn('WARNING')
                warning = True
            elif ticks_below == 0 and warning:
                warn('NORMAL')
                warning = False
        rate.sleep()


if __name__ == '__main__':
    main()
