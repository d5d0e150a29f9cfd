#!/usr/bin/env python3
"""BASELINE ONLY: the naive exam node the seed's grader solution describes. Never launched by the product.

lab/bench/run.sh measures the real exam node (exam/scripts/exam_node.py) against this one, so the
benchmark shows what the real node's design buys. It is written the obvious way on purpose:

- global variables cache the latest readings (the grader's own solution does this);
- one ``rospy.Rate(10)`` loop computes, publishes and calls the service synchronously, so a slow
  service stalls publishing, and a crossing is only noticed at the next 10 Hz tick;
- the delay is a count of loop iterations ("500 fois au dessus" in the seed, here ``~delay`` x 10),
  reset as soon as a tick sees the altitude back at or below the threshold.

The formula is the exam node's own (``exam.formulas.altitude``), so the two differ in design only.

It keeps the drop-in interface of the real node so the same harness drives both: relative names,
private params, the same initial NORMAL state without a call, and a call only on a change of state.

ROS Parameters
  ~threshold (float, m, default 1300): altitude above which the LED should turn red.
  ~delay (float, s, default 5.0): time above the threshold before warning, as loop iterations.

Subscribed Topics
  temperature (std_msgs/Float32, degC), pressure (std_msgs/Float32, Pa)

Published Topics
  altitude (std_msgs/Float32, m), at 10 Hz once both inputs arrived

Services Called
  altitude_warning (mydrone/AltitudeWarning): "WARNING" or "NORMAL", synchronously in the loop.
"""

import rospy
from exam.formulas import altitude as altitude_of
from mydrone.srv import AltitudeWarning
from std_msgs.msg import Float32

LOOP_HZ = 10

temperature = None
pressure = None


def temperature_callback(msg):
    global temperature
    temperature = msg.data


def pressure_callback(msg):
    global pressure
    pressure = msg.data


def main():
    rospy.init_node('exam')
    threshold = float(rospy.get_param('~threshold', 1300.0))
    delay_ticks = int(round(float(rospy.get_param('~delay', 5.0)) * LOOP_HZ))
    pub = rospy.Publisher('altitude', Float32, queue_size=10)
    rospy.wait_for_service('altitude_warning')
    warn = rospy.ServiceProxy('altitude_warning', AltitudeWarning)
    rospy.Subscriber('temperature', Float32, temperature_callback)
    rospy.Subscriber('pressure', Float32, pressure_callback)

    state = 'NORMAL'
    ticks_above = 0
    rate = rospy.Rate(LOOP_HZ)
    while not rospy.is_shutdown():
        if temperature is not None and pressure is not None:
            altitude = altitude_of(temperature, pressure)
            pub.publish(Float32(altitude))
            if altitude > threshold:
                ticks_above += 1
                if ticks_above >= delay_ticks and state != 'WARNING':
                    state = 'WARNING'
                    warn(state)
            else:
                ticks_above = 0
                if state != 'NORMAL':
                    state = 'NORMAL'
                    warn(state)
        try:
            rate.sleep()
        except rospy.ROSInterruptException:
            break


if __name__ == '__main__':
    main()
