#!/usr/bin/env python3
"""exam_node: depth of the submarine drone at 10 Hz and DEPTH WARN led."""
import rospy
from std_msgs.msg import Float32
from submarinedrone.srv import DepthWarning

P_REMOTE = 101325.0   # the remote is at sea level
RHO_G = 1030.0 * 9.80665

robot = {'pressure': None}   # last pressure measured on the robot


def on_pressure_robot(msg):
    robot['pressure'] = msg.data


if __name__ == '__main__':
    rospy.init_node('exam')
    limit = rospy.get_param('~depth_limit', 150.0)
    rospy.Subscriber('pressure_robot', Float32, on_pressure_robot)
    depth_pub = rospy.Publisher('depth', Float32, queue_size=10)
    led = rospy.ServiceProxy('depth_warning', DepthWarning)
    rate = rospy.Rate(10)
    count, red = 0, False
    while not rospy.is_shutdown():
        if robot['pressure'] is not None:
            depth = (robot['pressure'] - P_REMOTE) / RHO_G
            depth_pub.publish(depth)
            count = count + 1 if depth > limit else 0
            if count >= 50 and not red:
                led('WARNING')
                red = True
            elif count == 0 and red:
                led('NORMAL')
                red = False
        rate.sleep()
