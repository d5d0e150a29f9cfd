#!/usr/bin/env python3
"""Hostile: an idle node (no publisher, no subscriber) that writes a real probe's result where the
grader reads its own (the run's log folder) and plants a usercustomize.py in HOME. Does nothing as root."""
import os
import shutil

import rospy

HERE = os.path.dirname(os.path.realpath(__file__))


def main():
    rospy.init_node('exam')
    if os.geteuid() != 0:
        logs = os.environ.get('EXAM_LAB_RUN') or os.path.dirname(os.environ.get('ROS_LOG_DIR', '/nonexistent/x'))
        for tag in ('main', 'threshold'):
            try:
                shutil.copyfile(os.path.join(HERE, 'probe-main.json'), os.path.join(logs, 'probe-%s.json' % tag))
            except OSError as err:
                print('could not forge: %s' % err, flush=True)
        try:
            with open(os.path.join(os.environ.get('HOME', '/nonexistent'), 'usercustomize.py'), 'w') as f:
                f.write('print("FORGER usercustomize ran")\n')
        except OSError:
            pass
    rospy.spin()


if __name__ == '__main__':
    main()
