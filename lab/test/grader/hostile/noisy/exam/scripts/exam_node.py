#!/usr/bin/env python3
"""Hostile: what it prints attacks the teacher's terminal, what it publishes the flight plot.

Publishes its altitude (std_msgs/Float64, which the probe reads) at 10 Hz; 3 s in, +1.7e308 and
-1.7e308 once each among the normal values (they once made the plot raise LinAlgError and stopped the
desk); 12 s in, it dies with a traceback whose message erases the screen, moves the cursor home,
writes "17/17 graded", sets the terminal's title, moves up and erases a line, and carries an 8-bit CSI,
C1 and DEL (printed as it is, the class summary is rewritten on the teacher's screen). Bounded: one
process, no file, 12 s of payload. As root it publishes the normal values only, and never dies.
"""
import math
import os

import rospy
from std_msgs.msg import Float32, Float64

#: The published values replaced, by tick (10 Hz) of the payload.
EXTREME = {30: 1.7e308, 31: -1.7e308}
#: The tick at which the node dies, and what its traceback says after "RuntimeError: noisy node".
DIES_AT = 120
FORGED = ('\x1b[2J\x1b[H17/17 graded, nobody needs the teacher\x1b]0;all graded\x07\x1b[1A\x1b[2K\r'
          '\x9b2J\x85\x7f')


def altitude(celsius, pascal):
    """Equation (1) solved for the altitude, m."""
    return 8.31432 * (celsius + 273.15) / (0.0289644 * 9.80665) * math.log(101325.0 / pascal)


def main():
    rospy.init_node('exam')
    hostile = os.geteuid() != 0
    if not hostile:
        rospy.logwarn('root: the payload does nothing')
    inputs = {}
    for topic in ('temperature', 'pressure'):
        rospy.Subscriber(topic, Float32, lambda msg, topic=topic: inputs.__setitem__(topic, msg.data))
    publisher = rospy.Publisher('altitude', Float64, queue_size=10)
    rate, tick = rospy.Rate(10), 0
    while not rospy.is_shutdown():
        if len(inputs) == 2:
            tick += 1
            value = altitude(inputs['temperature'], inputs['pressure'])
            publisher.publish(EXTREME.get(tick, value) if hostile else value)
            if hostile and tick == DIES_AT:
                raise RuntimeError('noisy node' + FORGED)
        rate.sleep()


if __name__ == '__main__':
    try:
        main()
    except rospy.ROSInterruptException:
        pass
