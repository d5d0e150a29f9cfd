#!/usr/bin/env python3
# exam node (question 10 to 14): altitude of the drone from /temperature and /pressure
import math
import rospy
from std_msgs.msg import Float32, Float64
from mydrone.srv import AltitudeWarning


class AltitudeNode:
    def __init__(self):
        # last measures, with a room temperature until the first message comes
        self.temp = 20.0
        self.press = None
        self.threshold = rospy.get_param('threshold')
        self.count = 0          # cycles above the threshold
        self.warned = False     # led is red
        # publisher and service first, subscribers last
        self.pub = rospy.Publisher('/altitude', Float32, queue_size=10)
        rospy.wait_for_service('/altitude_warning')
        self.warn = rospy.ServiceProxy('/altitude_warning', AltitudeWarning)
        rospy.Subscriber('/temperature', Float64, self.on_temp)   # temperature in degC
        rospy.Subscriber('/pressure', Float32, self.on_press)     # pressure in Pa

    def on_temp(self, msg):
        self.temp = msg.data

    def on_press(self, msg):
        self.press = msg.data

    def step(self):
        if self.press is None:
            return
        T = self.temp + 273.15  # Kelvin
        h = 8.31432 * T / (0.0289644 * 9.80665) * math.log(101325.0 / self.press)
        self.pub.publish(h)
        self.count = self.count + 1 if h > self.threshold else 0
        if self.count >= 50 and not self.warned:  # 5 s at 10 Hz
            self.warn('WARNING')
            self.warned = True
        if self.count == 0 and self.warned:
            self.warn('NORMAL')
            self.warned = False


if __name__ == '__main__':
    rospy.init_node('exam')
    node = AltitudeNode()
    r = rospy.Rate(10)
    while not rospy.is_shutdown():
        node.step()
        r.sleep()
