#!/usr/bin/env python3
import math
import rospy
from std_msgs.msg import Float32
from mydrone.srv import AltitudeWarning

T = None  # temperature (C)
P = None  # pressure (Pa)


def temp_cb(data):
    global T
    T = data.data


def press_cb(data):
    global P
    P = data.data


def altitude_node():
    rospy.init_node('exam_node', anonymous=True)
    alt_max = rospy.get_param('/altitude_max', 1300)
    rospy.Subscriber('temperature', Float32, temp_cb)
    rospy.Subscriber('pressure', Float32, press_cb)
    pub = rospy.Publisher('altitude', Float32, queue_size=10)
    warning = rospy.ServiceProxy('altitude_warning', AltitudeWarning)
    state = 'NORMAL'
    r = rospy.Rate(10)
    while not rospy.is_shutdown():
        if T is not None and P is not None:
            h = -(8.31432 * (T + 273.15)) / (0.0289644 * 9.80665) * math.log(P / 101325.0)
            pub.publish(Float32(h))
            # new state of the led
            new_state = 'WARNING' if h > alt_max else 'NORMAL'
            if new_state != state:
                warning(new_state)
                state = new_state
        r.sleep()


if __name__ == '__main__':
    altitude_node()
