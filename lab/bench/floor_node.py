#!/usr/bin/env python3
"""REFERENCE ONLY: the cheapest rospy node with the exam node's topics. Never launched by the product.

It subscribes ``temperature`` and ``pressure`` and publishes one constant std_msgs/Float32 on
``altitude`` at 10 Hz from a ``rospy.Timer``, nothing else: no formula, no debounce, no service. Its CPU and RSS are the floor
of any rospy node doing this job, which is what bounds the exam node's own cost (see
docs/benchmarks.md).
"""

import rospy
from std_msgs.msg import Float32


def main():
    rospy.init_node('exam')
    # ~synchronous (bool, default false): publish from the timer thread itself (queue_size=None)
    # instead of handing each message to rospy's per-connection writer thread, to measure what that
    # thread hand-off adds to the interval jitter. rospy logs a warning about queue_size=None.
    synchronous = bool(rospy.get_param('~synchronous', False))
    pub = rospy.Publisher('altitude', Float32, queue_size=None if synchronous else 10)
    rospy.Subscriber('temperature', Float32, lambda msg: None)
    rospy.Subscriber('pressure', Float32, lambda msg: None)
    rospy.Timer(rospy.Duration(0.1), lambda event: pub.publish(Float32(0.0)))
    rospy.spin()


if __name__ == '__main__':
    main()
