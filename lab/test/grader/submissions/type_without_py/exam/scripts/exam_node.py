#!/usr/bin/env python3
"""exam_node: the altitude of mydrone by equation (1), published on /altitude at 10 Hz.

ALT WARN (service /altitude_warning) turns red after 5 s spent above the threshold given by the
launch file, and green as soon as the altitude is back below it.
"""
import math

import rospy
from std_msgs.msg import Float32
from mydrone.srv import AltitudeWarning

last = {}                                    # 'temperature' / 'pressure' -> last value received
state = {'above_since': None, 'led': 'NORMAL'}


def keeper(key):
    """A subscriber callback that keeps the last value of its topic under ``key``."""
    def keep(msg):
        last[key] = msg.data
    return keep


def altitude(celsius, pascals):
    """Equation (1) solved for h (T in kelvin, P0 = 101325 Pa at sea level)."""
    kelvin = celsius + 273.15
    return 8.31432 * kelvin / (0.0289644 * 9.80665) * math.log(101325.0 / pascals)


def on_timer(_event):
    """Every 100 ms: publish the altitude, and ask for a colour only when it must change."""
    if len(last) < 2:
        return
    height = altitude(last['temperature'], last['pressure'])
    publisher.publish(height)
    wanted = state['led']
    if height > threshold:
        state['above_since'] = state['above_since'] or rospy.get_time()
        if rospy.get_time() - state['above_since'] >= 5.0:
            wanted = 'WARNING'
    else:
        state['above_since'] = None
        wanted = 'NORMAL'
    if wanted != state['led']:
        set_led(wanted)
        state['led'] = wanted


rospy.init_node('exam_node')
threshold = float(rospy.get_param('threshold', 1300.0))   # set by the launch file
publisher = rospy.Publisher('/altitude', Float32, queue_size=10)
rospy.wait_for_service('/altitude_warning')
set_led = rospy.ServiceProxy('/altitude_warning', AltitudeWarning)
rospy.Subscriber('/temperature', Float32, keeper('temperature'))
rospy.Subscriber('/pressure', Float32, keeper('pressure'))
rospy.Timer(rospy.Duration(0.1), on_timer)
rospy.spin()
