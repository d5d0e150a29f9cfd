#!/usr/bin/env python3
"""Depth node publishing std_msgs/Float64 (the sheet names no type); delay by time stamps."""
import rospy
from std_msgs.msg import Float32, Float64
from submarinedrone.srv import DepthWarning

state = {'robot': None, 'remote': None, 'deep_since': None, 'status': 'NORMAL'}


def keep(key):
    return lambda msg: state.__setitem__(key, msg.data)


def step(_event):
    if state['robot'] is None or state['remote'] is None:
        return
    depth = (state['robot'] - state['remote']) / (1030.0 * 9.80665)
    pub.publish(Float64(depth))
    now = rospy.get_time()
    if depth > limit:
        state['deep_since'] = state['deep_since'] or now
        if now - state['deep_since'] >= 5.0 and state['status'] == 'NORMAL':
            state['status'] = 'WARNING'
            warn('WARNING')
    else:
        state['deep_since'] = None
        if state['status'] == 'WARNING':
            state['status'] = 'NORMAL'
            warn('NORMAL')


rospy.init_node('exam')
limit = float(rospy.get_param('~max_depth'))
pub = rospy.Publisher('/depth', Float64, queue_size=10)
rospy.wait_for_service('/depth_warning')
warn = rospy.ServiceProxy('/depth_warning', DepthWarning)
rospy.Subscriber('/pressure_robot', Float32, keep('robot'))
rospy.Subscriber('/pressure_remote', Float32, keep('remote'))
rospy.Timer(rospy.Duration(0.1), step)
rospy.spin()
