#!/usr/bin/env python3
"""The harness's fake drone as a node of its own: a drone process that a test can kill and respawn.

It hovers at one altitude (or depth), so the exam node's wanted state never changes, and it keeps an
exact record of the warning calls it received. Killed and respawned, the new process starts GREEN and
with an empty record, as a real drone that reboots. The drone itself is
:class:`exam_lab.harness.fake_drone.Drone`; this script only adds the parameters and the record topic.

ROS Parameters:
    ~mode (str, default "altitude"): "altitude" (sheet 000) or "depth" (sheet 001).
    ~value (float, m, default 1500.0): the altitude (or depth) the readings correspond to.

Published Topics:
    the drone's two sensor topics, its LED topic (latched), as exam_lab.harness.fake_drone.Drone.
    ~record (std_msgs/String, latched): JSON {"pid", "started" (ROS time, s, when GREEN was published),
        "led", "calls": [[ROS time (s), status], ...]} (refused calls included), republished after
        every call, so a subscriber that connects late still sees every call of this process.

Services:
    the drone's warning service ("NORMAL" -> GREEN, "WARNING" -> RED, anything else refused).
"""
import json
import os
import threading

import rospy
from std_msgs.msg import String

from exam_lab.harness.fake_drone import TEST_RATES, Drone


def main():
    rospy.init_node('fake_drone')
    mode = rospy.get_param('~mode', 'altitude')
    value = float(rospy.get_param('~value', 1500.0))
    lock = threading.Lock()
    record_pub = rospy.Publisher('~record', String, queue_size=1, latch=True)
    holder = {}

    def publish_record(_status=None, _success=None):
        # Under the lock, so records go out in call order.
        with lock:
            drone = holder['drone']
            record = {'pid': os.getpid(), 'started': holder['started'], 'led': drone.service.colour,
                      'calls': [list(call) for call in drone.service.calls()]}
            record_pub.publish(String(json.dumps(record)))

    holder['started'] = rospy.get_time()
    holder['drone'] = drone = Drone(mode, rates=TEST_RATES[mode], on_call=publish_record)  # the rostests' faster inputs
    publish_record()
    drone.feeder.set(drone.fixed_topic, drone.fixed_value)
    drone.fly_to(value)
    rospy.loginfo('fake_drone: pid %d, %s %.1f m', os.getpid(), mode, value)
    rospy.spin()


if __name__ == '__main__':
    main()
