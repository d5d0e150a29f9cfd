#!/usr/bin/env python3
"""REFERENCE ONLY: the cheapest rospy node with the exam node's topics. Never launched by the product.

It subscribes ``temperature`` and ``pressure`` and publishes one constant std_msgs/Float32 on
``altitude`` at 10 Hz, nothing else: no formula, no debounce, no service. Its CPU and RSS are the floor
of any rospy node doing this job, which is what bounds the exam node's own cost (see
docs/benchmarks.md).
"""

import rospy
from std_msgs.msg import Float32


def main():
    rospy.init_node('exam')
    pub = rospy.Publisher('altitude', Float32, queue_size=10)
    rospy.Subscriber('temperature', Float32, lambda msg: None)
    rospy.Subscriber('pressure', Float32, lambda msg: None)
    rospy.Timer(rospy.Duration(0.1), lambda event: pub.publish(Float32(0.0)))
    rospy.spin()


if __name__ == '__main__':
    main()
