#!/usr/bin/env python3
"""The sleeper's node: never run (its build sits past the budget)."""
import rospy

if __name__ == '__main__':
    rospy.init_node('exam')
    rospy.spin()
