#!/usr/bin/env python3
# Exam node: the altitude of mydrone, computed only from a fresh pair of readings.
# The temperature comes less often (0.78 Hz, rostopic hz) than the pressure (2 Hz): to never mix an
# old temperature with a new pressure, we wait until both have a new reading since the last altitude.
import math
import rospy
from std_msgs.msg import Float32
from mydrone.srv import AltitudeWarning

R, MU, G, P0 = 8.31432, 0.0289644, 9.80665, 101325.0

latest = {'temperature': None, 'pressure': None}   # last reading of each topic
fresh = {'temperature': False, 'pressure': False}  # a new reading since the last altitude?
altitude = None                                     # the last altitude computed (m)
above_since = None                                  # time the altitude went above the threshold


def reading(topic):
    def callback(msg):
        global altitude, above_since
        latest[topic] = msg.data
        fresh[topic] = True
        if all(fresh.values()):                     # a new pair: a new altitude
            fresh['temperature'] = fresh['pressure'] = False
            altitude = R * (latest['temperature'] + 273.15) / (MU * G) * math.log(P0 / latest['pressure'])
            if altitude > threshold and above_since is None:
                above_since = rospy.get_time()      # start of the 5 s
            elif altitude <= threshold:
                above_since = None
    return callback


rospy.init_node('exam_node')
threshold = rospy.get_param('threshold', 1300.0)
pub = rospy.Publisher('/altitude', Float32, queue_size=10)
rospy.wait_for_service('/altitude_warning')
led = rospy.ServiceProxy('/altitude_warning', AltitudeWarning)
rospy.Subscriber('/temperature', Float32, reading('temperature'))
rospy.Subscriber('/pressure', Float32, reading('pressure'))
warning = False
rate = rospy.Rate(10)
while not rospy.is_shutdown():
    if altitude is not None:
        pub.publish(altitude)
        since = above_since
        if since is not None and rospy.get_time() - since >= 5.0 and not warning:
            led('WARNING')                          # 5 s above: red
            warning = True
        elif since is None and warning:
            led('NORMAL')                           # back below: green at once
            warning = False
    rate.sleep()
