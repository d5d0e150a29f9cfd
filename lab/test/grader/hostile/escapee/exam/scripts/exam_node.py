#!/usr/bin/env python3
"""Hostile: leaks and escapes, at build time (CMake runs ``payload.py build``) and at run time.

Prints its environment (the grading user's variables?) and the root-only secret file it can read;
leaves in the run's log folder a link to that file, a dangling link and a FIFO; starts a detached child
(double fork, setsid, empty environment) that lives 90 s. Does nothing as root.
"""
import os
import sys

import rospy

sys.path.insert(0, os.path.dirname(os.path.realpath(__file__)))
import payload  # noqa: E402


def main():
    rospy.init_node('exam')
    payload.run('node')
    rospy.spin()


if __name__ == '__main__':
    main()
