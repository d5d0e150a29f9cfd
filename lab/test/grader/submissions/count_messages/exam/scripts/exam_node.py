#!/usr/bin/env python3
"""Depth of the submarine drone at 10 Hz; the delay counts /pressure_robot messages (2 Hz, rostopic hz):
the first reading deeper than the limit starts the count, 10 periods later (the 11th reading) is 5 s."""
import rospy
from std_msgs.msg import Float32
from submarinedrone.srv import DepthWarning


class DepthNode(object):
    def __init__(self):
        self.limit = float(rospy.get_param('~depth_limit'))
        self.remote = None
        self.depth = None
        self.deep_readings = 0       # consecutive robot readings deeper than the limit
        self.warned = False
        self.pub = rospy.Publisher('depth', Float32, queue_size=10)
        rospy.wait_for_service('depth_warning')
        self.led = rospy.ServiceProxy('depth_warning', DepthWarning)
        rospy.Subscriber('pressure_remote', Float32, self.on_remote)
        rospy.Subscriber('pressure_robot', Float32, self.on_robot)

    def on_remote(self, msg):
        self.remote = msg.data

    def on_robot(self, msg):
        if self.remote is None:
            return
        self.depth = (msg.data - self.remote) / (1030.0 * 9.80665)
        if self.depth > self.limit:
            self.deep_readings += 1
            if self.deep_readings >= 11 and not self.warned:   # 10 periods of 0.5 s after the first
                self.led('WARNING')
                self.warned = True
        else:
            self.deep_readings = 0
            if self.warned:
                self.led('NORMAL')
                self.warned = False

    def spin(self):
        rate = rospy.Rate(10)
        while not rospy.is_shutdown():
            if self.depth is not None:
                self.pub.publish(self.depth)
            rate.sleep()


if __name__ == '__main__':
    rospy.init_node('depth_node')
    DepthNode().spin()
