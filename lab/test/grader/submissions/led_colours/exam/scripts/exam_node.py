#!/usr/bin/env python3
# Exam ROS, questions 10 to 14 (submarine): depth = (P_robot - P_remote) / (rho g)
#
# (test package of the grader: everything right, but the service is called with the colour of the
# DEPTH WARN led, "RED" / "GREEN", instead of "WARNING" / "NORMAL". The drone refuses both; what the
# node meant is clear, so the calls are judged on their times and the words cost Q13's half once.)
import rospy
from std_msgs.msg import Float32
from submarinedrone.srv import DepthWarning

RHO = 1030.0  # kg/m3, sea water (sheet)
G = 9.80665   # m/s2


class Depth(object):
    def __init__(self):
        self.p_robot = None
        self.p_remote = None
        self.max_depth = float(rospy.get_param('~max_depth', 150.0))
        self.pub = rospy.Publisher('/depth', Float32, queue_size=10)
        rospy.Subscriber('/pressure_robot', Float32, self.robot)
        rospy.Subscriber('/pressure_remote', Float32, self.remote)
        rospy.wait_for_service('/depth_warning')
        self.led = rospy.ServiceProxy('/depth_warning', DepthWarning)
        self.deep_since = None   # when the depth went over max_depth
        self.red = False         # the led is red

    def robot(self, msg):
        self.p_robot = msg.data

    def remote(self, msg):
        self.p_remote = msg.data

    def tick(self, event):
        if self.p_robot is None or self.p_remote is None:
            return
        depth = (self.p_robot - self.p_remote) / (RHO * G)
        self.pub.publish(Float32(depth))
        now = rospy.get_time()
        if depth > self.max_depth:
            if self.deep_since is None:
                self.deep_since = now
            elif not self.red and now - self.deep_since >= 5.0:
                self.led('RED')      # too deep for 5 s: led red
                self.red = True
        else:
            self.deep_since = None
            if self.red:
                self.led('GREEN')    # back: led green
                self.red = False


if __name__ == '__main__':
    rospy.init_node('exam')
    node = Depth()
    rospy.Timer(rospy.Duration(0.1), node.tick)  # 10 Hz
    rospy.spin()
