#!/usr/bin/env python3
"""Question 10's first step: log each value the drone's two sensor topics bring, nothing more.
``~mode``: "altitude" (sheet 000: temperature, pressure; the default) or "depth" (001: two pressures)."""
import rospy
from std_msgs.msg import Float32

# The two input topics of each sheet, with their units.
INPUTS = {'altitude': [('temperature', 'degC'), ('pressure', 'Pa')],
          'depth': [('pressure_robot', 'Pa'), ('pressure_remote', 'Pa')]}


def on_reading(msg, topic_and_unit):
    """Called by rospy for each message of one topic: log the value."""
    topic, unit = topic_and_unit
    rospy.loginfo('received %s = %.2f %s', topic, msg.data, unit)


if __name__ == '__main__':
    rospy.init_node('exam')
    for topic, unit in INPUTS[rospy.get_param('~mode', 'altitude')]:
        # One subscriber per topic; callback_args tells the shared callback which topic it is.
        rospy.Subscriber(topic, Float32, on_reading, callback_args=(topic, unit))
    rospy.spin()  # wait for messages until Ctrl-C
