#!/usr/bin/env python3
"""Hostile: a chatty node that dies once and is started again by roslaunch (``respawn="true"``), so
roslaunch's "process has died" lands in the middle of the launch log, which the grader cuts (it keeps
the first and last 256 KB). Prints LINE_BYTES-byte lines at RATE_HZ; DIES_AFTER_S after its first
start it raises, once per box (a marker in the box's private /tmp). Bounded: one process, at most
LIFETIME_S of chatter a life (under 10 MB). As root it prints nothing and never dies."""
import os
import time

LINE_BYTES = 1000
RATE_HZ = 100.0
DIES_AFTER_S = 4.0
LIFETIME_S = 90.0
MARKER = '/tmp/exam-chatter-died-once'


def main():
    import rospy
    rospy.init_node('chatter', disable_signals=True)
    if os.geteuid() == 0:
        print('root: the chatter does nothing', flush=True)
        rospy.spin()
        return
    first_life = not os.path.exists(MARKER)
    start = time.time()
    line = 'chatter ' + 'x' * (LINE_BYTES - 9)
    while time.time() - start < LIFETIME_S and not rospy.is_shutdown():
        if first_life and time.time() - start > DIES_AFTER_S:
            with open(MARKER, 'w'):
                pass
            raise RuntimeError('chatter: dying once')
        print(line, flush=True)
        time.sleep(1.0 / RATE_HZ)
    rospy.spin()


if __name__ == '__main__':
    main()
