#!/usr/bin/env python3
"""The clock hostile: sets /use_sim_time and publishes /clock at SPEED times the wall clock's pace, so
that its exam node (the good student's, which counts 50 ticks of 10 Hz) warns 7 s after the crossing
while a grader timing on this clock sees 5 s. Does nothing as root; ends by itself after LIFETIME_S."""
import os
import time

SPEED = 5.0 / 7.0
PERIOD_S = 0.01
LIFETIME_S = 240.0


def main():
    if os.geteuid() == 0:
        print('root: the clock does nothing', flush=True)
        return
    import rospy
    from rosgraph_msgs.msg import Clock
    rospy.init_node('clock', disable_signals=True)
    rospy.set_param('/use_sim_time', True)  # the launch file set it too, before any node started
    pub = rospy.Publisher('/clock', Clock, queue_size=1)
    start = time.time()
    while time.time() - start < LIFETIME_S:
        pub.publish(Clock(clock=rospy.Time.from_sec(start + (time.time() - start) * SPEED)))
        time.sleep(PERIOD_S)  # the wall's: this node's own ROS time is the clock it publishes


if __name__ == '__main__':
    main()
