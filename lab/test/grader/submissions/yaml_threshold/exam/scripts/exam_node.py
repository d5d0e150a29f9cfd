#!/usr/bin/env python3
"""Exam node (depth sheet): the submarine's depth from its two pressures, on /depth at 10 Hz.

DEPTH WARN turns red once the depth has stayed beyond the limit for 5 s, and green as soon as it is
back within it. The limit is the private parameter max_depth, which the launch file loads from
config/params.yaml.
"""
import rospy
from std_msgs.msg import Float32
from submarinedrone.srv import DepthWarning

RHO_G = 1030.0 * 9.80665   # sea water density (kg/m^3) times gravity (m/s^2)
DELAY = 5.0                # seconds beyond the limit before the warning


class DepthWatch(object):
    """Keeps the last pressures, publishes the depth and drives the DEPTH WARN led."""

    def __init__(self):
        self.limit = float(rospy.get_param('~max_depth'))   # from config/params.yaml
        self.robot = None          # pressure at the robot (Pa)
        self.remote = None         # pressure at the remote, at the surface (Pa)
        self.beyond_since = None   # when the depth went beyond the limit; None while within
        self.red = False           # the colour asked last
        self.publisher = rospy.Publisher('/depth', Float32, queue_size=10)
        rospy.wait_for_service('/depth_warning')
        self.led = rospy.ServiceProxy('/depth_warning', DepthWarning)
        rospy.Subscriber('/pressure_robot', Float32, self.on_robot)
        rospy.Subscriber('/pressure_remote', Float32, self.on_remote)

    def on_robot(self, msg):
        self.robot = msg.data

    def on_remote(self, msg):
        self.remote = msg.data

    def tick(self):
        """One 10 Hz step: the depth by equation (1), then the led, changed only at a crossing."""
        if self.robot is None or self.remote is None:
            return
        depth = (self.robot - self.remote) / RHO_G
        self.publisher.publish(depth)
        now = rospy.get_time()
        if depth <= self.limit:
            self.beyond_since = None
            if self.red:
                self.led('NORMAL')
                self.red = False
            return
        if self.beyond_since is None:
            self.beyond_since = now
        if not self.red and now - self.beyond_since >= DELAY:
            self.led('WARNING')
            self.red = True


def main():
    rospy.init_node('exam')
    watch = DepthWatch()
    rate = rospy.Rate(10)
    while not rospy.is_shutdown():
        watch.tick()
        rate.sleep()


if __name__ == '__main__':
    try:
        main()
    except rospy.ROSInterruptException:
        pass
